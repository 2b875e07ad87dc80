//! Every engine's error converts into the crate's `Error` with `?`, keeping its message and
//! its source chain (`std::error::Error::source`).

use nonsmooth::Error;
use nonsmooth::ParameterError;
use nonsmooth::drive::RunError;
use nonsmooth::filippov::FilippovError;
use nonsmooth::timestep::TimeStepError;
use nonsmooth::timestep::lcp::{LcpError, Lemke};

/// The messages of `e` and its sources, outermost first.
fn chain(e: &dyn std::error::Error) -> Vec<String> {
    let mut out = vec![e.to_string()];
    let mut s = e.source();
    while let Some(x) = s {
        out.push(x.to_string());
        s = x.source();
    }
    out
}

fn lemke_on_mismatched_data() -> Result<(), LcpError> {
    let mut z = [0.0; 2];
    Lemke::<f64>::default().solve(&[1.0, 0.0, 0.0, 1.0], &[-1.0], &mut z)?;
    Ok(())
}

fn through_the_crate_error() -> nonsmooth::Result<()> {
    lemke_on_mismatched_data()?;
    Ok(())
}

#[test]
fn a_complementarity_error_keeps_its_message_through_question_mark() {
    let inner = lemke_on_mismatched_data().unwrap_err();
    assert!(matches!(inner, LcpError::Dimension { .. }), "{inner:?}");
    let outer = through_the_crate_error().unwrap_err();
    assert!(
        matches!(outer, Error::Lcp(LcpError::Dimension { .. })),
        "{outer:?}"
    );
    assert_eq!(chain(&outer), chain(&inner));
}

#[test]
fn a_time_stepping_error_keeps_its_source_chain() {
    let lcp = lemke_on_mismatched_data().unwrap_err();
    let e = TimeStepError::Contact {
        step: 7,
        t: 0.25,
        source: lcp.clone(),
    };
    let want = chain(&e);
    assert_eq!(want.len(), 2, "{want:?}");
    assert_eq!(want[1], lcp.to_string());
    let outer: Error = e.into();
    assert!(matches!(
        outer,
        Error::TimeStep(TimeStepError::Contact { step: 7, .. })
    ));
    assert_eq!(chain(&outer), want);
}

#[test]
fn a_filippov_error_keeps_its_message() {
    let p = ParameterError::new("tangency", 2.0, "in (0, 1)");
    let e = FilippovError::Run(RunError::Parameter(p.clone()));
    let outer: Error = e.clone().into();
    assert!(
        matches!(outer, Error::Filippov(FilippovError::Run(_))),
        "{outer:?}"
    );
    assert_eq!(outer.to_string(), p.to_string());
    assert_eq!(chain(&outer), chain(&e));
}

#[test]
fn input_output_errors_become_output_errors_naming_the_cause() {
    fn open() -> nonsmooth::Result<std::fs::File> {
        Ok(std::fs::File::open("/nonexistent/nonsmooth/error_paths")?)
    }
    let e = open().unwrap_err();
    let Error::Output(m) = &e else {
        panic!("{e:?}")
    };
    assert!(m.starts_with("input/output: "), "{m}");
    assert!(m.contains("No such file"), "{m}");
}
