// The dependent crate of `scripts/build-times.sh`: the prelude's example, a system built
// from the parts and run with events and a sampler, as a new user's first program.
use nalgebra::SVector;
use nonsmooth::prelude::*;

fn main() -> Result<(), nonsmooth::Error> {
    let model = Mechanical::with_masses([1.0])?
        .with_elements((
            Element::on_dof(0, (LinearSpring::new(1.0)?, ViscousDamper::new(0.05)?))?,
            Element::on_dof(0, HertzContact::new(0.2, 1e3)?)?,
        ))
        .with_loads(Load::on_dof(0, Harmonic::cosine(0.5, 0.8)?)?);
    let stop = Gap::below(Coordinate::<f64, 1>::dof(0)?.with_offset(-0.2)?, ());
    let mut impacts = ImpactSequence::on_surface(0, stop, 50.0, 1000)?;
    let tol = Tolerances::<f64, 2>::new(1e-9, 1e-11)?;
    let out = Simulation::new(model, Dopri5::new(tol))
        .with_events(Event::new(stop, Direction::Rising))
        .run(0.0, SVector::zeros(), 200.0, &mut impacts)?;
    println!("{:?}: {} impacts", out.termination, impacts.count());
    Ok(())
}
