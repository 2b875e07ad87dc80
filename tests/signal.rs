//! Integration tests of the measured-data pipeline (`nonsmooth::signal`).

use std::f64::consts::PI;

use nonsmooth::signal::{
    Column, CsvOptions, Direction, InitialState, Location, LowPass, PhaseInput, PhaseSection,
    SignalError, ThresholdCrossing, TimeSeries, intervals, section_frequencies, unwrap_phase,
};
use nonsmooth::systems::paper::{IMPACT_OFFSET, impact_detector, low_pass};

/// SplitMix64: deterministic pseudo-noise in [-1, 1).
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

fn grid(n: usize, h: f64) -> Vec<f64> {
    (0..n).map(|i| i as f64 * h).collect()
}

// ---------------------------------------------------------------- filter

#[test]
fn step_response_is_one_minus_exp_at_the_samples() {
    let theta = 1e-3;
    let f = LowPass::new(theta)
        .unwrap()
        .with_initial(InitialState::Zero);
    // Uniform grid.
    let t = grid(2000, 1e-5);
    let y = f.filter(&t, &vec![1.0; t.len()]).unwrap();
    let worst = t
        .iter()
        .zip(&y)
        .map(|(&t, &y)| (y - (1.0 - (-t / theta).exp())).abs())
        .fold(0.0, f64::max);
    assert!(worst < 5e-15, "uniform: {worst:e}");
    // Non-uniform grid: steps cycling through 3 different lengths, plus one long gap.
    let mut t = vec![0.0];
    for i in 0..3000 {
        let h = [7e-6, 1.3e-5, 2.9e-5][i % 3] * if i == 1500 { 40.0 } else { 1.0 };
        t.push(t[t.len() - 1] + h);
    }
    let y = f.filter(&t, &vec![1.0; t.len()]).unwrap();
    let worst = t
        .iter()
        .zip(&y)
        .map(|(&t, &y)| (y - (1.0 - (-t / theta).exp())).abs())
        .fold(0.0, f64::max);
    assert!(worst < 5e-15, "non-uniform: {worst:e}");
}

#[test]
fn delayed_step_response() {
    // u = 0 before sample 50, 1 from then on: y_n = 1 − exp(−(t_n − t_50)/θ).
    let theta = 2e-4;
    let t = grid(500, 1e-5);
    let u: Vec<f64> = (0..t.len())
        .map(|n| if n >= 50 { 1.0 } else { 0.0 })
        .collect();
    let y = LowPass::new(theta).unwrap().filter(&t, &u).unwrap();
    for n in 0..t.len() {
        let want = if n < 50 {
            0.0
        } else {
            1.0 - (-(t[n] - t[50]) / theta).exp()
        };
        assert!((y[n] - want).abs() < 1e-14, "n = {n}: {} vs {want}", y[n]);
    }
}

#[test]
fn zoh_filter_converges_to_the_continuous_response_at_first_order() {
    // θẏ = sin(ωt) − y, y(0) = 0 has the closed form below; zero-order hold is O(h).
    let (theta, w) = (1e-3, 2.0 * PI * 50.0);
    let wt = w * theta;
    let exact =
        |t: f64| ((w * t).sin() - wt * (w * t).cos() + wt * (-t / theta).exp()) / (1.0 + wt * wt);
    let f = LowPass::new(theta)
        .unwrap()
        .with_initial(InitialState::Zero);
    let err = |h: f64| {
        let n = (0.04 / h).round() as usize;
        let t: Vec<f64> = (0..=n).map(|i| i as f64 * h).collect();
        let u: Vec<f64> = t.iter().map(|&t| (w * t).sin()).collect();
        let y = f.filter(&t, &u).unwrap();
        t.iter()
            .zip(&y)
            .map(|(&t, &y)| (y - exact(t)).abs())
            .fold(0.0, f64::max)
    };
    let errors: Vec<f64> = [4e-5, 2e-5, 1e-5, 5e-6].iter().map(|&h| err(h)).collect();
    for w2 in errors.windows(2) {
        let order = (w2[0] / w2[1]).log2();
        assert!(
            (order - 1.0).abs() < 0.05,
            "order {order}, errors {errors:?}"
        );
    }
    // The first-order error constant: a delay of h/2 on an amplitude-1/√(1+ω²θ²) sine.
    let predicted = w * 5e-6 / 2.0 / (1.0 + wt * wt).sqrt();
    assert!(
        (errors[3] / predicted - 1.0).abs() < 0.05,
        "{errors:?} vs {predicted:e}"
    );
}

#[test]
fn filter_variants_agree() {
    let t = grid(1000, 3e-5);
    let mut rng = SplitMix64(7);
    let u: Vec<f64> = t.iter().map(|_| rng.next_f64()).collect();
    let f = LowPass::new(5e-4).unwrap();
    let a = f.filter(&t, &u).unwrap();
    let mut b = u.clone();
    f.filter_inplace(&t, &mut b).unwrap();
    let mut c = vec![123.0; 3];
    f.filter_into(&t, &u, &mut c).unwrap();
    assert_eq!(a, b);
    assert_eq!(a, c);
    // Streaming with `advance` gives the same numbers.
    let mut y = u[0];
    for n in 1..t.len() {
        y = f.advance(y, u[n - 1], t[n] - t[n - 1]);
        assert!((y - a[n]).abs() < 1e-15);
    }
}

// ---------------------------------------------------------------- crossings

#[test]
fn sine_crossings_match_the_closed_form() {
    let f = 5.0;
    let h = 1e-4;
    let t = grid(10_001, h);
    let x: Vec<f64> = t.iter().map(|&t| (2.0 * PI * f * t).sin()).collect();
    let times = ThresholdCrossing::new(0.5).unwrap().times(&t, &x).unwrap();
    assert_eq!(times.len(), 5);
    // Interpolation error ≤ h²·max|ẍ|/(8·|ẋ|) at the crossing.
    let xdd = (2.0 * PI * f).powi(2);
    let xd = 2.0 * PI * f * (PI / 6.0).cos();
    let bound = h * h * xdd / (8.0 * xd);
    for (k, tc) in times.iter().enumerate() {
        let exact = (1.0 / 12.0 + k as f64) / f;
        assert!(
            (tc - exact).abs() <= bound,
            "{tc} vs {exact} (bound {bound:e})"
        );
    }
    for dt in intervals(&times) {
        assert!((dt - 0.2).abs() <= 2.0 * bound);
    }
    // Falling crossings of 0.5 are at 5/12 + k periods.
    let down = ThresholdCrossing::new(0.5)
        .unwrap()
        .with_direction(Direction::Falling)
        .times(&t, &x)
        .unwrap();
    for (k, tc) in down.iter().enumerate() {
        assert!((tc - (5.0 / 12.0 + k as f64) / f).abs() <= bound);
    }
}

fn noisy_sine(seed: u64, noise: f64) -> (Vec<f64>, Vec<f64>) {
    let t = grid(20_000, 1e-4);
    let mut rng = SplitMix64(seed);
    let x = t
        .iter()
        .map(|&t| (2.0 * PI * 5.0 * t - 0.5).sin() + noise * rng.next_f64())
        .collect();
    (t, x)
}

#[test]
fn hysteresis_and_min_separation_debounce_noise() {
    let (t, x) = noisy_sine(42, 0.05);
    let plain = ThresholdCrossing::new(0.0).unwrap();
    let raw = plain.times(&t, &x).unwrap();
    assert!(raw.len() > 10, "noise should chatter: {}", raw.len());
    // Hysteresis wider than the noise band: exactly one crossing per period (the signal
    // starts at sin(−0.5) < −0.15, so the detector is armed; crossings at 0.016 + 0.2k s).
    let debounced = plain.with_hysteresis(0.15).unwrap().times(&t, &x).unwrap();
    assert_eq!(debounced.len(), 10);
    for (k, tc) in debounced.iter().enumerate() {
        // The noise (±0.05 on slope 2π·5) shifts the crossing by at most 0.05/31.4 s.
        let exact = 0.5 / (2.0 * PI * 5.0) + k as f64 * 0.2;
        // |sin| ≤ 0.05 at the interpolated crossing.
        assert!(
            (tc - exact).abs() <= 0.05_f64.asin() / (2.0 * PI * 5.0),
            "{tc} vs {exact}"
        );
    }
    // A minimum separation of 3/4 period does the same (half a period is not enough: the
    // noisy *falling* passage through 0, half a period later, has upward micro-crossings).
    let separated = plain
        .with_min_separation(0.15)
        .unwrap()
        .times(&t, &x)
        .unwrap();
    assert_eq!(separated.len(), 10);
    // The first crossing of each burst is kept.
    assert_eq!(separated[0], raw[0]);
}

#[test]
fn either_is_the_union_of_rising_and_falling() {
    for seed in 0..5 {
        let (t, x) = noisy_sine(seed, 0.05);
        let base = ThresholdCrossing::new(0.3)
            .unwrap()
            .with_hysteresis(0.02)
            .unwrap()
            .with_min_separation(0.003)
            .unwrap();
        let up = base.detect(&t, &x).unwrap();
        let down = base
            .with_direction(Direction::Falling)
            .detect(&t, &x)
            .unwrap();
        let both = base
            .with_direction(Direction::Either)
            .detect(&t, &x)
            .unwrap();
        let mut merged = [up.clone(), down.clone()].concat();
        merged.sort_by(|a, b| a.t.total_cmp(&b.t));
        assert_eq!(both, merged);
        assert!(up.iter().all(|c| c.direction == Direction::Rising));
        assert!(both.windows(2).all(|w| w[0].t < w[1].t));
        for c in &both {
            assert!(t[c.index] <= c.t && c.t <= t[c.index + 1]);
        }
    }
}

#[test]
fn paper_impact_threshold() {
    // The cart pressed on a stop at x_I = −2.0807 mm with bumps; only those reaching
    // x_I − 0.01 mm count.
    let x_i = -2.0807e-3;
    let t = grid(1000, 1e-3);
    let bump = |t: f64, c: f64, a: f64| a * (-((t - c) / 0.01).powi(2)).exp();
    let x: Vec<f64> = t
        .iter()
        .map(|&t| x_i - 1e-4 + bump(t, 0.2, 1.5e-4) + bump(t, 0.5, 0.5e-4) + bump(t, 0.8, 2e-4))
        .collect();
    let det = impact_detector(x_i).unwrap();
    assert_eq!(det.level(), x_i - IMPACT_OFFSET);
    let times = det.times(&t, &x).unwrap();
    assert_eq!(times.len(), 2);
    // Analytic crossing: bump = 0.9e-4 → (t − c) = −0.01·√ln(a/0.9e-4).
    for (tc, (c, a)) in times.iter().zip([(0.2, 1.5e-4), (0.8, 2e-4)]) {
        let exact = c - 0.01 * (f64::ln(a / 0.9e-4)).sqrt();
        assert!((tc - exact).abs() < 2e-5, "{tc} vs {exact}");
    }
}

// ---------------------------------------------------------------- phase section

#[test]
fn ramp_section_matches_the_closed_form() {
    // The paper's ramp: ω(t) = ω0 + αt, α = 8.0905e-3 rad/s², so φ = ω0 t + αt²/2.
    let (w0, alpha) = (14.0, 8.0905e-3);
    let h = 5e-4;
    let t = grid(80_001, h); // 40 s
    let phi = |t: f64| w0 * t + 0.5 * alpha * t * t;
    let wrapped: Vec<f64> = t.iter().map(|&t| phi(t).rem_euclid(2.0 * PI)).collect();
    let xf = |t: f64| 1e-3 * (phi(t) + 0.3).sin();
    let x: Vec<f64> = t.iter().map(|&t| xf(t)).collect();
    let s = TimeSeries::new(t.clone(), x, Some(wrapped)).unwrap();
    let pts = s.poincare(&PhaseSection::new()).unwrap();
    let last = phi(40.0) / (2.0 * PI);
    assert_eq!(pts.len(), last.floor() as usize);
    let w = section_frequencies(&pts).unwrap();
    for (p, wk) in pts.iter().zip(&w) {
        let exact_t = (-w0 + (w0 * w0 + 2.0 * alpha * 2.0 * PI * p.i as f64).sqrt()) / alpha;
        // Linear interpolation of the quadratic phase: error ≤ α h²/(8ω) in time.
        assert!(
            (p.t - exact_t).abs() < 1e-10,
            "i = {}: {} vs {exact_t}",
            p.i,
            p.t
        );
        // x is interpolated linearly: error ≤ h²·max|ẍ|/8 = h²·ω²·1e-3/8.
        assert!((p.x - 1e-3 * 0.3_f64.sin()).abs() < h * h * 15.0 * 15.0 * 1e-3 / 8.0);
        assert!((wk - (w0 + alpha * p.t)).abs() < 1e-7, "{wk}");
    }
    assert_eq!(pts[0].i, 1);
    assert!(pts.windows(2).all(|p| p[1].i == p[0].i + 1));
}

#[test]
fn section_offset_and_unwrapped_input_agree() {
    let t = grid(4001, 1e-3);
    let phi: Vec<f64> = t.iter().map(|&t| 10.0 * t + 1.0).collect();
    let x = t.clone();
    let off = PI / 3.0;
    let a = PhaseSection::new()
        .with_offset(off)
        .unwrap()
        .with_input(PhaseInput::Unwrapped)
        .sample(&t, &phi, &x)
        .unwrap();
    let wrapped: Vec<f64> = phi
        .iter()
        .map(|p| (p + PI).rem_euclid(2.0 * PI) - PI)
        .collect();
    let b = PhaseSection::new()
        .with_offset(off)
        .unwrap()
        .sample(&t, &wrapped, &x)
        .unwrap();
    assert_eq!(a.len(), b.len());
    for (p, q) in a.iter().zip(&b) {
        assert!((p.t - q.t).abs() < 1e-12);
        assert_eq!(p.i, q.i);
        assert!((p.t - (2.0 * PI * p.i as f64 + off - 1.0) / 10.0).abs() < 1e-12);
    }
    let u = unwrap_phase(&wrapped).unwrap();
    for (p, q) in u.iter().zip(&phi) {
        assert!((p - q).abs() < 1e-12);
    }
}

// ---------------------------------------------------------------- TimeSeries + CSV

fn read(text: &str) -> Result<TimeSeries, SignalError> {
    TimeSeries::from_csv_reader(text.as_bytes(), &CsvOptions::default())
}

#[test]
fn constructor_validates() {
    let e = TimeSeries::new(vec![0.0, 1.0], vec![0.0], None).unwrap_err();
    assert!(matches!(e, SignalError::LengthMismatch { what: "x", .. }));
    let e = TimeSeries::new(vec![0.0, 1.0], vec![0.0, 1.0], Some(vec![0.0])).unwrap_err();
    assert!(matches!(
        e,
        SignalError::LengthMismatch { what: "phase", .. }
    ));
    let e = TimeSeries::new(vec![0.0], vec![0.0], None).unwrap_err();
    assert_eq!(
        e,
        SignalError::TooFewSamples {
            found: 1,
            required: 2
        }
    );
    let e = TimeSeries::new(vec![0.0, 2.0, 1.0], vec![0.0; 3], None).unwrap_err();
    assert!(matches!(
        e,
        SignalError::NonIncreasingTime {
            location: Location::Sample(2),
            ..
        }
    ));
    let e = TimeSeries::new(vec![0.0, 1.0], vec![0.0, 1.0], Some(vec![0.0, f64::NAN]));
    assert!(matches!(
        e,
        Err(SignalError::NonFinite {
            location: Location::Sample(1),
            ..
        })
    ));
    let s = TimeSeries::with_min_samples(vec![0.0], vec![1.0], None, 1).unwrap();
    assert_eq!(s.span(), Some((0.0, 0.0)));
    assert_eq!(
        s.poincare(&PhaseSection::new()),
        Err(SignalError::MissingPhase)
    );
}

#[test]
fn csv_round_trip_is_exact() {
    let t = grid(100, 1.0 / 3.0 * 1e-3);
    let mut rng = SplitMix64(3);
    let x: Vec<f64> = t.iter().map(|_| 1e-3 * rng.next_f64()).collect();
    let p: Vec<f64> = t.iter().map(|_| PI * (1.0 + rng.next_f64())).collect();
    let s = TimeSeries::new(t, x, Some(p)).unwrap();
    let mut buf = Vec::new();
    s.write_csv(&mut buf).unwrap();
    let text = String::from_utf8(buf).unwrap();
    assert!(text.starts_with("t_s,x_m,phase_rad\n"));
    assert_eq!(read(&text).unwrap(), s);
    // Without phase the header has two columns and the reader finds no phase.
    let s2 = TimeSeries::new(s.t().to_vec(), s.x().to_vec(), None).unwrap();
    let mut buf = Vec::new();
    s2.write_csv(&mut buf).unwrap();
    assert!(buf.starts_with(b"t_s,x_m\n"));
    assert_eq!(read(std::str::from_utf8(&buf).unwrap()).unwrap(), s2);
}

#[test]
fn csv_file_round_trip_and_io_errors() {
    let dir = std::env::temp_dir().join(format!("nonsmooth-signal-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("series.csv");
    let s = TimeSeries::new(vec![0.0, 1e-3, 2e-3], vec![1.0, -2.5e-7, 3.0], None).unwrap();
    s.write_csv_path(&path).unwrap();
    let back = TimeSeries::from_csv_path(&path, &CsvOptions::default()).unwrap();
    assert_eq!(back, s);
    std::fs::remove_dir_all(&dir).unwrap();
    let e = TimeSeries::from_csv_path(&path, &CsvOptions::default()).unwrap_err();
    match e {
        SignalError::Io { path: p, .. } => assert!(p.ends_with("series.csv")),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        s.write_csv_path(&path),
        Err(SignalError::Io { .. })
    ));
}

#[test]
fn csv_errors_name_the_line() {
    // Line 1 is the header; a comment line still counts.
    let cases: Vec<(&str, SignalError)> = vec![
        (
            "t_s,x_m\n0,1\n# comment\n1,oops\n",
            SignalError::ParseField {
                line: 4,
                column: "`x_m`".into(),
                text: "oops".into(),
            },
        ),
        (
            // A shifted row (decimal comma): silently reading "1" and "5" would be wrong.
            "t_s,x_m\n0,1\n1,5,3\n",
            SignalError::ExtraFields {
                line: 3,
                found: 3,
                expected: 2,
            },
        ),
        (
            "t_s,x_m\n0,1\n1\n",
            SignalError::MissingField {
                line: 3,
                column: "`x_m`".into(),
            },
        ),
        (
            "t_s,x_m\n0,1\n,2\n",
            SignalError::MissingField {
                line: 3,
                column: "`t_s`".into(),
            },
        ),
        (
            "t_s,x_m\n0,1\n1,NaN\n",
            SignalError::NonFinite {
                location: Location::Line(3),
                what: "column `x_m`".into(),
                value: f64::NAN,
            },
        ),
        (
            "t_s,x_m\n0,1\n1,2\n1,3\n",
            SignalError::NonIncreasingTime {
                location: Location::Line(4),
                previous: 1.0,
                t: 1.0,
            },
        ),
        (
            "t_s,x_m\n0,1\n2,2\n\n1,3\n",
            SignalError::NonIncreasingTime {
                location: Location::Line(5),
                previous: 2.0,
                t: 1.0,
            },
        ),
        (
            "t_s,x_m\n0,1\n1,inf\n",
            SignalError::NonFinite {
                location: Location::Line(3),
                what: "column `x_m`".into(),
                value: f64::INFINITY,
            },
        ),
    ];
    for (text, want) in cases {
        let got = read(text).unwrap_err();
        match (&got, &want) {
            // NaN != NaN: compare the rest.
            (
                SignalError::NonFinite {
                    location: a,
                    what: wa,
                    value: va,
                },
                SignalError::NonFinite {
                    location: b,
                    what: wb,
                    value: vb,
                },
            ) => {
                assert_eq!((a, wa), (b, wb));
                assert!(va.is_nan() == vb.is_nan());
            }
            _ => assert_eq!(got, want, "input {text:?}"),
        }
        let line = match &want {
            SignalError::ParseField { line, .. }
            | SignalError::MissingField { line, .. }
            | SignalError::ExtraFields { line, .. } => *line,
            SignalError::NonFinite {
                location: Location::Line(l),
                ..
            }
            | SignalError::NonIncreasingTime {
                location: Location::Line(l),
                ..
            } => *l,
            _ => unreachable!(),
        };
        assert!(got.to_string().contains(&format!("line {line}")), "{got}");
    }
}

#[test]
fn csv_structure_errors() {
    assert_eq!(
        read("").unwrap_err(),
        SignalError::EmptyInput { what: "header" }
    );
    assert_eq!(
        read("t_s,x_m\n").unwrap_err(),
        SignalError::TooFewSamples {
            found: 0,
            required: 2
        }
    );
    match read("time,x_m\n0,1\n1,2\n").unwrap_err() {
        SignalError::MissingColumn { column, available } => {
            assert_eq!(column, "`t_s`");
            assert_eq!(available, "time,x_m");
        }
        e => panic!("{e:?}"),
    }
    let o = CsvOptions::default().with_phase("angle");
    let e = TimeSeries::from_csv_reader("t_s,x_m\n0,1\n1,2\n".as_bytes(), &o).unwrap_err();
    assert!(matches!(e, SignalError::MissingColumn { .. }));
    let o = CsvOptions::default().with_position(Column::Index(5));
    let e = TimeSeries::from_csv_reader("t_s,x_m\n0,1\n1,2\n".as_bytes(), &o).unwrap_err();
    assert!(matches!(e, SignalError::MissingColumn { column, .. } if column == "#5"));
    // Unterminated quote or invalid UTF-8 is a CSV error with a line.
    let e = TimeSeries::from_csv_reader(&b"t_s,x_m\n0,1\n1,\xff\n"[..], &CsvOptions::default())
        .unwrap_err();
    assert!(matches!(e, SignalError::Csv { line: Some(3), .. }), "{e:?}");
}

#[test]
fn csv_columns_scales_and_delimiters() {
    // A lab export: semicolons, time in ms, position in mm, angle in degrees, extra column.
    let text = "sample;time_ms;angle_deg;pos_mm\n\
                0;0.0;0;-2.08\n\
                1;0.5;90;-2.07\n\
                2;1.0;180;-2.09\n";
    let o = CsvOptions::default()
        .with_delimiter(b';')
        .with_time("time_ms")
        .with_time_scale(1e-3)
        .with_position(Column::Index(3))
        .with_position_scale(1e-3)
        .with_phase("angle_deg")
        .with_phase_scale(PI / 180.0)
        .with_min_samples(3);
    let s = TimeSeries::from_csv_reader(text.as_bytes(), &o).unwrap();
    assert_eq!(s.t(), &[0.0, 0.5e-3, 1.0e-3]);
    assert!((s.x()[1] + 2.07e-3).abs() < 1e-18);
    assert!((s.phase().unwrap()[2] - PI).abs() < 1e-15);
    // Fewer rows than required.
    let e = TimeSeries::from_csv_reader(text.as_bytes(), &o.clone().with_min_samples(4));
    assert!(matches!(
        e,
        Err(SignalError::TooFewSamples { found: 3, .. })
    ));
    // Phase column optional by default and absent → no phase; `without_phase` ignores it.
    let s = read("t_s,x_m,phase_rad\n0,1,0.5\n1,2,0.7\n").unwrap();
    assert_eq!(s.phase(), Some(&[0.5, 0.7][..]));
    let s = TimeSeries::from_csv_reader(
        "t_s,x_m,phase_rad\n0,1,0.5\n1,2,0.7\n".as_bytes(),
        &CsvOptions::default().without_phase(),
    )
    .unwrap();
    assert_eq!(s.phase(), None);
}

#[test]
fn filtered_series_and_crossings() {
    let (t, x) = noisy_sine(11, 0.0);
    let s = TimeSeries::new(t, x, None).unwrap();
    let f = s.filtered(&low_pass().unwrap()).unwrap();
    assert_eq!(f.t(), s.t());
    // The filter delays a 5 Hz sine by atan(ωθ)/ω ≈ θ and scales it by 1/√(1+ω²θ²).
    let c = f.crossings(&ThresholdCrossing::new(0.0).unwrap()).unwrap();
    let raw = s.crossings(&ThresholdCrossing::new(0.0).unwrap()).unwrap();
    assert_eq!(raw.len(), 10);
    assert_eq!(c.len(), raw.len());
    let w = 2.0 * PI * 5.0;
    let delay = (w * 1e-3).atan() / w;
    // Zero-order hold adds half a sample (0.05 ms) of delay.
    for (a, b) in c.iter().zip(&raw) {
        assert!(((a - b) - (delay + 0.5e-4)).abs() < 2e-6, "{}", a - b);
    }
}
