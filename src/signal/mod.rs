//! Measured data: time series, CSV input/output, the first-order smoothing filter,
//! threshold-crossing (impact) detection, phase-triggered Poincaré sampling and synthetic
//! records of any model.
//!
//! The processing chain of an impact experiment that records a position `x(t)` and,
//! optionally, an encoder phase `φ(t)`:
//!
//! 1. **Read** the record into a validated [`TimeSeries`] ([`TimeSeries::from_csv_path`],
//!    [`CsvOptions`]); every malformed field is reported with its 1-based line number.
//! 2. **Smooth** with the first-order filter `(θs + 1)^{-1}` ([`LowPass`]).
//!    Its exact zero-order-hold discretization for a step `h_n = t_{n+1} − t_n` is
//!    $$ y_{n+1} = a_n\,y_n + (1 - a_n)\,u_n,\qquad a_n = e^{-h_n/\theta}, $$
//!    so a unit step gives `y(t_n) = 1 − e^{−t_n/θ}` exactly at the samples.
//! 3. **Detect impacts** as upward crossings of a level `L` slightly below the stop
//!    ([`ThresholdCrossing`]), the crossing time linearly interpolated inside the sample
//!    interval,
//!    $$ t_c = t_n + \frac{L - x_n}{x_{n+1} - x_n}\,(t_{n+1} - t_n), $$
//!    with a hysteresis band and a minimum separation as debounce; the inter-impact
//!    intervals `T_j = t_{j+1} − t_j` follow from [`intervals`].
//! 4. **Sample the Poincaré section** `φ = 2πi` from the encoder phase
//!    ([`PhaseSection`]): the phase is unwrapped, each level `2πi + φ_0` located by linear
//!    interpolation of `φ`, and `x` interpolated with the same fraction; the forcing
//!    frequency at each point follows from [`section_frequencies`] (exact for a constant
//!    frequency or a linear ramp, where `φ(t)` is quadratic).
//!
//! Everything works on plain slices too (generic over [`Real`](crate::Real)), so simulated
//! trajectories ([`ModelExperiment`]) go through exactly the same code as measured ones.
//! The paper's configuration (its filter constant, impact threshold and synthetic
//! experiment) is in [`systems::paper`](crate::systems::paper).
//!
//! # Example
//! ```
//! use nonsmooth::signal::{LowPass, ThresholdCrossing, TimeSeries, intervals};
//!
//! // 1 s of a 5 Hz sine sampled at 1 kHz.
//! let t: Vec<f64> = (0..1000).map(|i| i as f64 * 1e-3).collect();
//! let x: Vec<f64> = t.iter().map(|&t| (2.0 * std::f64::consts::PI * 5.0 * t).sin()).collect();
//! let series = TimeSeries::new(t, x, None)?;
//! let smooth = series.filtered(&LowPass::new(1e-3)?)?;
//! let up = ThresholdCrossing::new(0.5)?.with_hysteresis(0.1)?;
//! let times = smooth.crossings(&up)?;
//! assert_eq!(times.len(), 5);
//! for dt in intervals(&times) {
//!     assert!((dt - 0.2).abs() < 1e-4);
//! }
//! # Ok::<(), nonsmooth::signal::SignalError>(())
//! ```

mod crossing;
mod filter;
mod phase;
mod series;
mod synthetic;

pub use crossing::{Crossing, Direction, ThresholdCrossing, intervals, intervals_into};
pub use filter::{InitialState, LowPass};
pub use phase::{
    PhaseInput, PhaseSection, PoincarePoint, section_frequencies, unwrap_phase,
    unwrap_phase_inplace,
};
pub use series::{Column, CsvOptions, PhaseColumn, TimeSeries};
pub use synthetic::{ModelExperiment, ModelRecord, NormalNoise};

use crate::drive::RunError;
use crate::scalar::to_f64;
use crate::validate::ParameterError;

/// Where in the data a problem was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// A line of a CSV file, 1-based, counting the header line (line 1 is the header).
    Line(u64),
    /// A sample of an in-memory series, 0-based.
    Sample(usize),
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Location::Line(l) => write!(f, "line {l}"),
            Location::Sample(i) => write!(f, "sample {i}"),
        }
    }
}

/// Errors of the measured-data pipeline.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SignalError {
    /// A configuration value was rejected.
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// The simulation of a synthetic record failed ([`ModelExperiment`]).
    #[error(transparent)]
    Run(#[from] RunError),
    /// A file could not be opened, read or written.
    #[error("I/O error on `{path}`: {message}")]
    Io {
        /// The path (or `<reader>` / `<writer>` for streams).
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// The CSV layer itself failed (bad UTF-8, I/O while reading, quoting…).
    #[error("CSV error{}: {message}", line.map(|l| format!(" at line {l}")).unwrap_or_default())]
    Csv {
        /// 1-based line (counting the header), when the CSV reader knows it.
        line: Option<u64>,
        /// The CSV reader's message.
        message: String,
    },
    /// The file has no header row or no data rows.
    #[error("CSV input has no {what}")]
    EmptyInput {
        /// `"header"` or `"data rows"`.
        what: &'static str,
    },
    /// A requested column is not in the header.
    #[error("column {column} not found in the header ({available}); choose it with CsvOptions")]
    MissingColumn {
        /// The requested column (name or `#index`).
        column: String,
        /// The header's column names, comma separated.
        available: String,
    },
    /// A row has no (or an empty) field for a required column.
    #[error("line {line}: missing value in column {column}")]
    MissingField {
        /// 1-based line (counting the header).
        line: u64,
        /// The column's name.
        column: String,
    },
    /// A row has more fields than the header names (a misplaced delimiter or a shifted
    /// row: which field belongs to which column is ambiguous).
    #[error("line {line}: {found} fields but the header names {expected} columns")]
    ExtraFields {
        /// 1-based line (counting the header).
        line: u64,
        /// Fields in the row.
        found: usize,
        /// Columns in the header.
        expected: usize,
    },
    /// A field could not be parsed as a number.
    #[error("line {line}: cannot parse `{text}` in column {column} as a number")]
    ParseField {
        /// 1-based line (counting the header).
        line: u64,
        /// The column's name.
        column: String,
        /// The offending text.
        text: String,
    },
    /// A value is NaN or infinite.
    #[error("{location}: {what} is not finite ({value})")]
    NonFinite {
        /// Where.
        location: Location,
        /// Which quantity (`"t"`, `"x"`, `"phase"`, a column name…).
        what: String,
        /// The value.
        value: f64,
    },
    /// Time does not increase strictly from one sample to the next.
    #[error("{location}: time {t} does not increase strictly (previous sample at {previous})")]
    NonIncreasingTime {
        /// Where the later of the two samples is.
        location: Location,
        /// The previous time.
        previous: f64,
        /// This sample's time.
        t: f64,
    },
    /// Two arrays that must have equal lengths do not.
    #[error("length mismatch: {what} has {found} samples, expected {expected}")]
    LengthMismatch {
        /// Which array.
        what: &'static str,
        /// The length it must have.
        expected: usize,
        /// Its length.
        found: usize,
    },
    /// Not enough samples.
    #[error("{found} samples, at least {required} required")]
    TooFewSamples {
        /// Samples present.
        found: usize,
        /// Samples required.
        required: usize,
    },
    /// A phase section was requested from a series without phase data.
    #[error("the time series has no phase column; read it with CsvOptions::with_phase")]
    MissingPhase,
}

/// Checks equal lengths, `min` samples, strictly increasing finite `t`, finite `x`.
pub(crate) fn validate_samples<T: crate::Real>(
    t: &[T],
    x: &[T],
    what_x: &str,
    min: usize,
) -> Result<(), SignalError> {
    if x.len() != t.len() {
        return Err(SignalError::LengthMismatch {
            what: "x",
            expected: t.len(),
            found: x.len(),
        });
    }
    if t.len() < min {
        return Err(SignalError::TooFewSamples {
            found: t.len(),
            required: min,
        });
    }
    validate_time(t)?;
    validate_finite(x, what_x)
}

/// Checks that `t` is finite and strictly increasing.
pub(crate) fn validate_time<T: crate::Real>(t: &[T]) -> Result<(), SignalError> {
    let mut prev: Option<T> = None;
    for (i, &ti) in t.iter().enumerate() {
        if !ti.is_finite() {
            return Err(SignalError::NonFinite {
                location: Location::Sample(i),
                what: "t".into(),
                value: to_f64(ti),
            });
        }
        if let Some(p) = prev {
            if ti <= p {
                return Err(SignalError::NonIncreasingTime {
                    location: Location::Sample(i),
                    previous: to_f64(p),
                    t: to_f64(ti),
                });
            }
        }
        prev = Some(ti);
    }
    Ok(())
}

/// Checks that every value is finite.
pub(crate) fn validate_finite<T: crate::Real>(x: &[T], what: &str) -> Result<(), SignalError> {
    match x.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(SignalError::NonFinite {
            location: Location::Sample(i),
            what: what.into(),
            value: to_f64(x[i]),
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_sample() {
        let err = validate_samples(&[0.0, 1.0, 1.0], &[0.0; 3], "x", 2).unwrap_err();
        assert_eq!(
            err,
            SignalError::NonIncreasingTime {
                location: Location::Sample(2),
                previous: 1.0,
                t: 1.0
            }
        );
        let err = validate_samples(&[0.0, 1.0], &[0.0, f64::NAN], "x", 2).unwrap_err();
        assert!(matches!(
            err,
            SignalError::NonFinite {
                location: Location::Sample(1),
                ..
            }
        ));
        assert!(err.to_string().contains("sample 1"));
        let err = validate_samples(&[0.0_f32], &[0.0], "x", 2).unwrap_err();
        assert_eq!(
            err,
            SignalError::TooFewSamples {
                found: 1,
                required: 2
            }
        );
        let err = validate_samples(&[0.0, 1.0], &[0.0], "x", 1).unwrap_err();
        assert!(matches!(err, SignalError::LengthMismatch { found: 1, .. }));
    }

    #[test]
    fn types_are_send_sync_clone() {
        fn check<T: Send + Sync + Clone + 'static>() {}
        check::<SignalError>();
        check::<TimeSeries>();
        check::<LowPass<f64>>();
        check::<ThresholdCrossing<f32>>();
        check::<PhaseSection<f64>>();
        check::<CsvOptions>();
    }
}
