//! Output: tidy CSV writers (default features) and figures (feature `plot`).

use std::path::PathBuf;

use nalgebra::{Vector2, Vector3};
use nonsmooth::Error;
use nonsmooth::output::csv::{
    Cell, STATE_XV, SweepColumns, TableWriter, write_impacts, write_ramp_impacts,
    write_ramp_sections, write_section_points, write_sweep_files, write_sweep_intervals,
    write_sweep_poincare, write_sweep_summary, write_table, write_table_path,
};
use nonsmooth::sample::{Impact, Regime, SectionPoint};
use nonsmooth::sweep::{
    RampImpact, RampRecord, RampSection, SweepBranch, SweepDirection, SweepPoint, SweepResult,
};

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("nonsmooth-output-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Parses CSV text into its header and records (with the csv crate's reader, as a
/// consumer would).
fn parse(bytes: &[u8]) -> (Vec<String>, Vec<Vec<String>>) {
    let mut r = csv::Reader::from_reader(bytes);
    let header = r.headers().unwrap().iter().map(str::to_string).collect();
    let rows = r
        .records()
        .map(|rec| rec.unwrap().iter().map(str::to_string).collect())
        .collect();
    (header, rows)
}

fn num(s: &str) -> f64 {
    s.parse().unwrap()
}

fn point(
    param: f64,
    poincare: Vec<Vector2<f64>>,
    intervals: Vec<f64>,
    regime: Regime,
) -> SweepPoint<2> {
    let n = poincare.len().max(1) as f64;
    SweepPoint {
        param,
        impacts: intervals.len() as u64 + 1,
        impacts_per_period: (intervals.len() as f64 + 1.0) / n,
        impact_velocities: vec![0.01; intervals.len() + 1],
        intervals,
        regime,
        grazing_margin: -1.5e-5,
        end_state: poincare.last().copied().unwrap_or_else(Vector2::zeros),
        poincare,
    }
}

/// Two branches, three values each, with known contents.
fn sample_result() -> SweepResult<2> {
    let up = SweepBranch {
        direction: SweepDirection::Up,
        points: vec![
            point(
                20.0,
                vec![Vector2::new(-2.1e-3, 0.012); 2],
                vec![0.3, 0.31],
                Regime::Periodic(1),
            ),
            point(
                20.005,
                vec![Vector2::new(-2.2e-3, 0.011), Vector2::new(-2.3e-3, -0.01)],
                vec![0.1],
                Regime::Periodic(2),
            ),
            point(
                20.01,
                vec![Vector2::new(-2.4e-3, 1e-7)],
                vec![],
                Regime::NotPeriodic,
            ),
        ],
    };
    let mut down = up.clone();
    down.direction = SweepDirection::Down;
    down.points.reverse();
    SweepResult {
        branches: vec![up, down],
    }
}

#[test]
fn table_round_trips_values_and_marks_missing_ones() {
    let mut out = Vec::new();
    let values = [
        std::f64::consts::PI,
        -2.086e-3,
        1.0 / 3.0,
        6.02214076e23,
        5e-324,
        0.0,
    ];
    write_table(
        &mut out,
        &["i", "value_m", "note"],
        values.iter().enumerate().map(|(i, &v)| {
            [
                Cell::from(i),
                Cell::from(v),
                if i % 2 == 0 {
                    Cell::from("even, quoted")
                } else {
                    Cell::Empty
                },
            ]
        }),
    )
    .unwrap();
    let (h, rows) = parse(&out);
    assert_eq!(h, ["i", "value_m", "note"]);
    assert_eq!(rows.len(), values.len());
    for (i, (r, &v)) in rows.iter().zip(&values).enumerate() {
        assert_eq!(r[0], i.to_string());
        assert_eq!(
            num(&r[1]).to_bits(),
            v.to_bits(),
            "value {v} written as {}",
            r[1]
        );
        assert_eq!(r[2], if i % 2 == 0 { "even, quoted" } else { "" });
    }
    // Non-finite values in the forms pandas reads.
    let mut out = Vec::new();
    write_table(
        &mut out,
        &["a", "b", "c"],
        [[f64::NAN, f64::INFINITY, f64::NEG_INFINITY]],
    )
    .unwrap();
    assert_eq!(String::from_utf8(out).unwrap(), "a,b,c\nNaN,inf,-inf\n");
}

#[test]
fn table_rejects_malformed_input() {
    let err = write_table(&mut Vec::new(), &["a", "b"], [vec![1.0, 2.0], vec![3.0]]).unwrap_err();
    match err {
        Error::Output(m) => assert!(m.contains("row 2") && m.contains("1 fields"), "{m}"),
        e => panic!("unexpected error {e:?}"),
    }
    assert!(matches!(
        write_table(&mut Vec::new(), &[], Vec::<Vec<f64>>::new()),
        Err(Error::Output(_))
    ));
    assert!(matches!(
        TableWriter::new(Vec::new(), &["a", ""]),
        Err(Error::Output(_))
    ));
    // A rejected row writes nothing: the table stays well formed.
    let mut t = TableWriter::new(Vec::new(), &["a", "b"]).unwrap();
    t.row([1.0, 2.0]).unwrap();
    assert!(t.row([1.0]).is_err());
    t.row([3.0, 4.0]).unwrap();
    assert_eq!(t.rows(), 2);
    assert_eq!(
        String::from_utf8(t.finish().unwrap()).unwrap(),
        "a,b\n1,2\n3,4\n"
    );
}

#[test]
fn sweep_tables_hold_every_record_once() {
    let res = sample_result();
    let cols = SweepColumns::OSCILLATOR_OMEGA;

    let mut out = Vec::new();
    write_sweep_poincare(&mut out, &res, &cols).unwrap();
    let (h, rows) = parse(&out);
    assert_eq!(h, ["omega_rad_s", "direction", "x_m", "v_m_s"]);
    let expected: Vec<(String, f64, f64, f64)> = res
        .branches
        .iter()
        .flat_map(|b| {
            let d = if b.direction == SweepDirection::Up {
                "up"
            } else {
                "down"
            };
            b.points.iter().flat_map(move |p| {
                p.poincare
                    .iter()
                    .map(move |y| (d.to_string(), p.param, y[0], y[1]))
            })
        })
        .collect();
    assert_eq!(rows.len(), expected.len());
    assert_eq!(rows.len(), 10);
    for (r, e) in rows.iter().zip(&expected) {
        assert_eq!(
            (r[1].clone(), num(&r[0]), num(&r[2]), num(&r[3])),
            e.clone()
        );
    }

    let mut out = Vec::new();
    write_sweep_intervals(&mut out, &res, &cols).unwrap();
    let (h, rows) = parse(&out);
    assert_eq!(h, ["omega_rad_s", "direction", "interval_s"]);
    assert_eq!(rows.len(), 6);
    assert_eq!(rows[0], ["20", "up", "0.3"]);
    assert_eq!(rows[2], ["20.005", "up", "0.1"]);
    assert_eq!(rows[3], ["20.005", "down", "0.1"]);

    let mut out = Vec::new();
    write_sweep_summary(&mut out, &res, &SweepColumns::OSCILLATOR).unwrap();
    let (h, rows) = parse(&out);
    assert_eq!(
        h,
        [
            "param",
            "direction",
            "period",
            "impacts_per_period",
            "grazing_margin_m"
        ]
    );
    assert_eq!(rows.len(), 6);
    assert_eq!(rows[0], ["20", "up", "1", "1.5", "-1.5e-5"]);
    assert_eq!(rows[1][2], "2");
    // Not periodic: an empty field (NaN in pandas).
    assert_eq!(rows[2][2], "");
    assert_eq!(rows[3][..3], ["20.01", "down", ""]);
}

#[test]
fn sweep_files_are_written_into_new_directories() {
    let base = scratch("sweep");
    let dir = base.join("nested/deeper");
    let paths = write_sweep_files(
        &dir,
        "fig",
        &sample_result(),
        &SweepColumns::OSCILLATOR_OMEGA,
    )
    .unwrap();
    let names: Vec<_> = paths
        .iter()
        .map(|p| p.file_name().unwrap().to_str().unwrap().to_string())
        .collect();
    assert_eq!(
        names,
        ["fig_poincare.csv", "fig_intervals.csv", "fig_summary.csv"]
    );
    let mut mem = Vec::new();
    write_sweep_poincare(&mut mem, &sample_result(), &SweepColumns::OSCILLATOR_OMEGA).unwrap();
    assert_eq!(std::fs::read(&paths[0]).unwrap(), mem);
    std::fs::remove_dir_all(&base).unwrap();
}

#[test]
fn path_errors_name_the_file() {
    let dir = scratch("errors");
    std::fs::create_dir_all(&dir).unwrap();
    let blocker = dir.join("a_file");
    std::fs::write(&blocker, b"x").unwrap();
    let target = blocker.join("sub/table.csv");
    let err = write_table_path(&target, &["a"], [[1.0]]).unwrap_err();
    match err {
        Error::Output(m) => assert!(m.contains("table.csv"), "{m}"),
        e => panic!("unexpected error {e:?}"),
    }
    // A bad row in a file: the message names the file and the row.
    let err = write_table_path(dir.join("bad.csv"), &["a", "b"], [vec![1.0]]).unwrap_err();
    match err {
        Error::Output(m) => assert!(m.contains("bad.csv") && m.contains("row 1"), "{m}"),
        e => panic!("unexpected error {e:?}"),
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn ramp_tables() {
    let rec = RampRecord {
        sections: vec![
            RampSection {
                index: 0,
                t: 0.0,
                omega: 10.0,
                y: Vector2::new(-2.08e-3, 0.0),
            },
            RampSection {
                index: 1,
                t: 0.628,
                omega: 10.005,
                y: Vector2::new(-2.09e-3, 1e-3),
            },
        ],
        impacts: vec![
            RampImpact {
                t: 1.0,
                omega: 10.01,
                interval: None,
                velocity: 0.02,
            },
            RampImpact {
                t: 1.4,
                omega: 10.012,
                interval: Some(0.4),
                velocity: 0.021,
            },
        ],
        dropped_sections: 0,
        dropped_impacts: 0,
    };
    let mut out = Vec::new();
    write_ramp_sections(&mut out, &rec, STATE_XV).unwrap();
    assert_eq!(
        String::from_utf8(out).unwrap(),
        "t_s,omega_rad_s,x_m,v_m_s\n0,10,-0.00208,0\n0.628,10.005,-0.00209,0.001\n"
    );
    let mut out = Vec::new();
    write_ramp_impacts(&mut out, &rec).unwrap();
    assert_eq!(
        String::from_utf8(out).unwrap(),
        "t_s,omega_rad_s,interval_s,velocity_m_s\n1,10.01,,0.02\n1.4,10.012,0.4,0.021\n"
    );
}

#[test]
fn section_points_and_impacts_in_f32_and_f64() {
    let pts = [
        SectionPoint {
            index: 0,
            t: 0.5f32,
            y: Vector3::new(1.0f32, 0.1, -2.5),
        },
        SectionPoint {
            index: 1,
            t: 1.0f32,
            y: Vector3::new(2.0f32, 0.2, 1e-7),
        },
    ];
    let mut out = Vec::new();
    write_section_points(&mut out, &pts, ["x_m", "v_m_s", "phase_rad"]).unwrap();
    let (h, rows) = parse(&out);
    assert_eq!(h, ["t_s", "x_m", "v_m_s", "phase_rad"]);
    assert_eq!(rows.len(), 2);
    // f32 values are converted exactly to f64.
    assert_eq!(num(&rows[0][2]), f64::from(0.1f32));
    assert_eq!(num(&rows[1][3]), f64::from(1e-7f32));

    let imp = [
        Impact {
            t: 2.0,
            velocity: 0.03,
            interval: None,
            max_penetration: Some(4e-5),
        },
        Impact {
            t: 2.25,
            velocity: 0.01,
            interval: Some(0.25),
            max_penetration: None,
        },
    ];
    let mut out = Vec::new();
    write_impacts(&mut out, &imp).unwrap();
    assert_eq!(
        String::from_utf8(out).unwrap(),
        "t_s,velocity_m_s,interval_s,max_penetration_m\n2,0.03,,4e-5\n2.25,0.01,0.25,\n"
    );
}

/// End to end: a short sweep of the paper's oscillator, written and read back.
#[test]
fn paper_sweep_written_and_read_back() {
    use nonsmooth::integrate::{Dopri5, Tolerances};
    use nonsmooth::sweep::{Stop, SweepConfig, SweepSystem, sweep};
    use nonsmooth::systems::paper::PAPER;

    let config = SweepConfig::grid(19.0, 19.1, 0.05)
        .unwrap()
        .transients(40, 20)
        .record(10)
        .unwrap();
    let make = |w: f64| -> nonsmooth::Result<SweepSystem<_>> {
        Ok(SweepSystem {
            system: PAPER.oscillator::<f64>(w)?,
            period: std::f64::consts::TAU / w,
            stop: Some(Stop {
                position: 0,
                velocity: 1,
                level: PAPER.x_i,
            }),
        })
    };
    let tol = Tolerances::per_component(1e-8, [1e-12, 1e-10]).unwrap();
    let x0 = PAPER.static_equilibrium().unwrap();
    let res = sweep(&config, make, || Dopri5::new(tol), Vector2::new(x0, 0.0)).unwrap();
    assert_eq!(res.branches.len(), 2);

    let dir = scratch("paper");
    let paths = write_sweep_files(&dir, "s", &res, &SweepColumns::OSCILLATOR_OMEGA).unwrap();
    let (_, rows) = parse(&std::fs::read(&paths[0]).unwrap());
    let n_points: usize = res
        .branches
        .iter()
        .flat_map(|b| &b.points)
        .map(|p| p.poincare.len())
        .sum();
    assert_eq!(rows.len(), n_points);
    assert_eq!(n_points, 2 * 3 * 10);
    let (_, rows) = parse(&std::fs::read(&paths[1]).unwrap());
    let intervals: Vec<f64> = res
        .branches
        .iter()
        .flat_map(|b| &b.points)
        .flat_map(|p| p.intervals.iter().copied())
        .collect();
    assert!(
        !intervals.is_empty(),
        "the paper's oscillator impacts at ω = 19 rad/s"
    );
    let read: Vec<f64> = rows.iter().map(|r| num(&r[2])).collect();
    assert_eq!(read, intervals);
    let (_, rows) = parse(&std::fs::read(&paths[2]).unwrap());
    assert_eq!(rows.len(), 6);
    for (r, p) in rows.iter().zip(res.branches.iter().flat_map(|b| &b.points)) {
        assert_eq!(num(&r[0]), p.param);
        assert_eq!(num(&r[3]), p.impacts_per_period);
        assert_eq!(num(&r[4]), p.grazing_margin);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(feature = "plot")]
mod plot {
    use super::*;
    use nonsmooth::output::plot::{
        Layout, Legend, Panel, Quantity, Rgb, Series, bifurcation_panel, plot_bifurcation,
        plot_phase_portrait, plot_series, plot_time_profile, render,
    };

    const PNG_MAGIC: &[u8] = b"\x89PNG\r\n\x1a\n";

    fn assert_png(p: &std::path::Path) {
        let bytes = std::fs::read(p).unwrap();
        assert!(bytes.len() > 1000, "{} is too small", p.display());
        assert_eq!(&bytes[..8], PNG_MAGIC, "{} is not a PNG", p.display());
    }

    fn assert_svg(p: &std::path::Path) {
        let text = std::fs::read_to_string(p).unwrap();
        assert!(
            text.contains("<svg") && text.trim_end().ends_with("</svg>"),
            "{}",
            p.display()
        );
        // Text is drawn, in the registered family.
        assert!(
            text.contains("<text") && text.contains("sans-serif"),
            "{}",
            p.display()
        );
    }

    type Orbit = (
        Vec<SectionPoint<f64, 2>>,
        Vec<SectionPoint<f64, 2>>,
        Vec<Impact<f64>>,
    );

    fn orbit() -> Orbit {
        let w = 15.0f64;
        let curve: Vec<_> = (0..400)
            .map(|i| {
                let t = i as f64 * 0.001;
                SectionPoint {
                    index: i,
                    t,
                    y: Vector2::new(-2.1e-3 + 3e-5 * (w * t).sin(), 3e-5 * w * (w * t).cos()),
                }
            })
            .collect();
        let strobe = vec![curve[0]];
        let impacts = vec![Impact {
            t: 0.1,
            velocity: 2e-4,
            interval: None,
            max_penetration: None,
        }];
        (curve, strobe, impacts)
    }

    #[test]
    fn figures_in_png_and_svg() {
        let dir = scratch("plot");
        let res = sample_result();
        let (curve, strobe, impacts) = orbit();
        for ext in ["png", "svg"] {
            let check = |name: &str| {
                let p = dir.join(format!("{name}.{ext}"));
                if ext == "png" {
                    assert_png(&p)
                } else {
                    assert_svg(&p)
                }
            };
            plot_bifurcation(
                dir.join(format!("bif.{ext}")),
                &res,
                Quantity::POSITION_MM,
                "ω [rad/s]",
            )
            .unwrap();
            check("bif");
            plot_bifurcation(
                dir.join(format!("tj.{ext}")),
                &res,
                Quantity::Intervals,
                "ω [rad/s]",
            )
            .unwrap();
            check("tj");
            plot_phase_portrait(
                dir.join(format!("phase.{ext}")),
                &curve,
                &strobe,
                &impacts,
                Some(-2.086e-3),
            )
            .unwrap();
            check("phase");
            plot_time_profile(dir.join(format!("profile.{ext}")), &curve, Some(-2.086e-3)).unwrap();
            check("profile");
            let generic = Panel::new("ω [rad/s]", "q [-]")
                .title("series")
                .with(
                    Series::line((0..50).map(|i| (i as f64, (i as f64 * 0.2).sin())))
                        .color(Rgb::RED)
                        .label("line"),
                )
                .with(
                    Series::dots((0..50).map(|i| (i as f64, 0.5)))
                        .color(Rgb::GREEN)
                        .label("dots"),
                )
                .with(
                    Series::stems((0..10).map(|i| (i as f64 * 5.0, 0.8)))
                        .color(Rgb::BLUE)
                        .label("stems"),
                )
                .with(
                    Series::bars([(10.0, -0.5), (20.0, 0.3)], 2.0)
                        .color(Rgb::ORANGE)
                        .label("bars"),
                )
                .with(Series::line([(0.0, 1.0), (f64::NAN, 0.0), (49.0, 1.0)]))
                .hline(0.0, Rgb::GRAY)
                .vline(25.0, Rgb::RED)
                .legend(Some(Legend::LowerRight));
            plot_series(dir.join(format!("series.{ext}")), &generic).unwrap();
            check("series");
            let panels = vec![
                bifurcation_panel(&res, Quantity::POSITION_MM).unwrap(),
                bifurcation_panel(&res, Quantity::ImpactVelocities { factor: 1e3 }).unwrap(),
                generic.clone(),
            ];
            render(
                dir.join(format!("grid.{ext}")),
                &panels,
                &Layout::grid(2, 400, 300).title("grid"),
            )
            .unwrap();
            check("grid");
        }
        // PNG dimensions: 2 columns × 2 rows of 400 × 300, plus the title band.
        let png = std::fs::read(dir.join("grid.png")).unwrap();
        let w = u32::from_be_bytes(png[16..20].try_into().unwrap());
        let h = u32::from_be_bytes(png[20..24].try_into().unwrap());
        assert_eq!(w, 800);
        assert!(h > 600 && h < 700, "{h}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn figure_errors() {
        let dir = scratch("plot-errors");
        let p = Panel::new("x", "y").with(Series::line([(0.0, 0.0), (1.0, 1.0)]));
        for bad in ["fig.jpg", "fig"] {
            match plot_series(dir.join(bad), &p) {
                Err(Error::Output(m)) => assert!(m.contains(bad) && m.contains(".png"), "{m}"),
                r => panic!("unexpected {r:?}"),
            }
        }
        assert!(matches!(
            render(dir.join("none.png"), &[], &Layout::default()),
            Err(Error::Output(_))
        ));
        assert!(matches!(
            render(
                dir.join("zero.png"),
                std::slice::from_ref(&p),
                &Layout::grid(1, 0, 10)
            ),
            Err(Error::Output(_))
        ));
        assert!(matches!(
            bifurcation_panel(
                &sample_result(),
                Quantity::Poincare {
                    component: 2,
                    factor: 1.0
                }
            ),
            Err(Error::Output(_))
        ));
        // An empty panel still draws (default ranges).
        plot_series(dir.join("empty.png"), &Panel::new("x", "y")).unwrap();
        assert_png(&dir.join("empty.png"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
