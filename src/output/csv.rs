//! Tidy CSV writers.
//!
//! One observation per row, one header line, SI units in the column names:
//!
//! | writer | columns |
//! |---|---|
//! | [`write_sweep_poincare`] | `param, direction, x_m, v_m_s` — one row per stroboscopic point |
//! | [`write_sweep_intervals`] | `param, direction, interval_s` — one row per inter-impact interval $T_j$ |
//! | [`write_sweep_summary`] | `param, direction, period, impacts_per_period, grazing_margin_m` — one row per parameter value and branch |
//! | [`write_ramp_sections`] | `t_s, omega_rad_s, x_m, v_m_s` |
//! | [`write_ramp_impacts`] | `t_s, omega_rad_s, interval_s, velocity_m_s` |
//! | [`write_section_points`] | `t_s, x_m, v_m_s` (section points or trajectory samples) |
//! | [`write_impacts`] | `t_s, velocity_m_s, interval_s, max_penetration_m` |
//! | [`write_branch`] | `param, arclength, stable, <state>, max_multiplier, grazing_margin_m` — one row per point of a continued orbit branch |
//! | [`write_bifurcations`] | `param, kind, <state>, max_multiplier` — one row per located bifurcation |
//! | [`write_table`] | any header, any rows of [`Cell`]s |
//!
//! The parameter and state column names are configurable ([`SweepColumns`], the `state`
//! arguments); the defaults are those of the oscillators of this crate (position in m,
//! velocity in m/s). `direction` is `up` or `down`. A missing value (the period of a
//! non-periodic regime, the interval before the first impact) is an empty field, which
//! `pandas.read_csv` reads as `NaN`.
//!
//! Numbers are written in Rust's shortest round-trip form (`0.0123`, `1.5e-7`): reading a
//! file back gives the values written exactly. Non-finite values are written `NaN`, `inf`,
//! `-inf`, which pandas also reads.
//!
//! Each writer takes an [`std::io::Write`] (a `File`, a `Vec<u8>`, stdout) and has a `*_path`
//! twin that creates the file's parent directories; errors are
//! [`Error::Output`] and name the file.
//!
//! ```
//! use nonsmooth::output::csv::{write_table, Cell};
//!
//! let mut out = Vec::new();
//! write_table(&mut out, &["t_s", "x_m", "kind"], [
//!     [Cell::from(0.0), Cell::from(-2.08e-3), Cell::from("start")],
//!     [Cell::from(0.5), Cell::from(1.5e-7), Cell::Empty],
//! ])?;
//! assert_eq!(String::from_utf8(out).unwrap(), "t_s,x_m,kind\n0,-0.00208,start\n0.5,1.5e-7,\n");
//! # Ok::<(), nonsmooth::Error>(())
//! ```

use std::fmt;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::orbit::{BifurcationKind, Branch, modulus};
use crate::sample::{Impact, SectionPoint};
use crate::scalar::to_f64;
use crate::sweep::{RampRecord, SweepDirection, SweepResult};
use crate::{Error, Real, Result};

/// One field of a table row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cell<'a> {
    /// A real number (shortest round-trip form; `NaN`, `inf`, `-inf` if not finite).
    Number(f64),
    /// An integer.
    Integer(i128),
    /// Text (quoted by the CSV writer if needed).
    Text(&'a str),
    /// A missing value: an empty field.
    Empty,
}

impl fmt::Display for Cell<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Cell::Number(v) => write_number(f, v),
            Cell::Integer(i) => write!(f, "{i}"),
            Cell::Text(s) => f.write_str(s),
            Cell::Empty => Ok(()),
        }
    }
}

/// Shortest round-trip decimal form; scientific notation outside `[1e-4, 1e16)`.
fn write_number(f: &mut fmt::Formatter<'_>, v: f64) -> fmt::Result {
    if v.is_nan() {
        f.write_str("NaN")
    } else if v.is_infinite() {
        f.write_str(if v > 0.0 { "inf" } else { "-inf" })
    } else if v == 0.0 || (1e-4..1e16).contains(&v.abs()) {
        write!(f, "{v}")
    } else {
        write!(f, "{v:e}")
    }
}

impl From<f64> for Cell<'_> {
    fn from(v: f64) -> Self {
        Cell::Number(v)
    }
}

impl From<f32> for Cell<'_> {
    fn from(v: f32) -> Self {
        // Through the decimal form, so that 0.1f32 is written 0.1, not 0.10000000149011612.
        Cell::Number(v.to_string().parse().unwrap_or(f64::from(v)))
    }
}

macro_rules! cell_from_int {
    ($($t:ty),*) => {$(
        impl From<$t> for Cell<'_> {
            fn from(v: $t) -> Self {
                Cell::Integer(v as i128)
            }
        }
    )*};
}
cell_from_int!(i32, i64, u32, u64, usize);

impl<'a> From<&'a str> for Cell<'a> {
    fn from(v: &'a str) -> Self {
        Cell::Text(v)
    }
}

impl<'a> From<&'a String> for Cell<'a> {
    fn from(v: &'a String) -> Self {
        Cell::Text(v)
    }
}

impl<'a, C: Into<Cell<'a>>> From<Option<C>> for Cell<'a> {
    fn from(v: Option<C>) -> Self {
        v.map_or(Cell::Empty, Into::into)
    }
}

/// A streaming table writer: a header, then rows of exactly as many fields.
///
/// ```
/// use nonsmooth::output::csv::TableWriter;
///
/// let mut table = TableWriter::new(Vec::new(), &["omega_rad_s", "impacts"])?;
/// table.row([17.5, 3.0])?;
/// table.row([18.0, 4.0])?;
/// let bytes = table.finish()?;
/// assert_eq!(String::from_utf8(bytes).unwrap(), "omega_rad_s,impacts\n17.5,3\n18,4\n");
/// # Ok::<(), nonsmooth::Error>(())
/// ```
#[derive(Debug)]
pub struct TableWriter<W: Write> {
    inner: ::csv::Writer<W>,
    columns: usize,
    rows: u64,
    buf: String,
}

fn csv_error(e: impl fmt::Display) -> Error {
    Error::Output(format!("writing CSV: {e}"))
}

impl<W: Write> TableWriter<W> {
    /// Writes the header to `out`.
    ///
    /// # Errors
    /// [`Error::Output`] for an empty header, an empty column name, or a failed write.
    pub fn new(out: W, header: &[&str]) -> Result<Self> {
        if header.is_empty() {
            return Err(Error::Output("a table needs at least one column".into()));
        }
        if let Some(i) = header.iter().position(|h| h.is_empty()) {
            return Err(Error::Output(format!("column {i} has an empty name")));
        }
        let mut inner = ::csv::WriterBuilder::new()
            .has_headers(false)
            .from_writer(out);
        inner.write_record(header).map_err(csv_error)?;
        Ok(Self {
            inner,
            columns: header.len(),
            rows: 0,
            buf: String::new(),
        })
    }

    /// Writes one row.
    ///
    /// # Errors
    /// [`Error::Output`] if the row does not have as many fields as the header (nothing is
    /// written then), or if the write fails.
    pub fn row<'a, I, C>(&mut self, cells: I) -> Result<()>
    where
        I: IntoIterator<Item = C>,
        C: Into<Cell<'a>>,
    {
        let cells: Vec<Cell<'a>> = cells.into_iter().map(Into::into).collect();
        if cells.len() != self.columns {
            return Err(Error::Output(format!(
                "row {} has {} fields, the header has {}",
                self.rows + 1,
                cells.len(),
                self.columns
            )));
        }
        for c in &cells {
            self.buf.clear();
            fmt::write(&mut self.buf, format_args!("{c}")).map_err(csv_error)?;
            self.inner
                .write_field(self.buf.as_bytes())
                .map_err(csv_error)?;
        }
        self.inner
            .write_record(std::iter::empty::<&[u8]>())
            .map_err(csv_error)?;
        self.rows += 1;
        Ok(())
    }

    /// Rows written so far.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Flushes and returns the underlying writer.
    ///
    /// # Errors
    /// [`Error::Output`] if the flush fails.
    pub fn finish(self) -> Result<W> {
        self.inner.into_inner().map_err(|e| csv_error(e.error()))
    }
}

/// Opens `path` for writing (creating parent directories), runs `f` on it, and adds the
/// path to any error.
fn to_path<P: AsRef<Path>>(path: P, f: impl FnOnce(File) -> Result<()>) -> Result<()> {
    let path = path.as_ref();
    super::create_parent(path)?;
    let file = File::create(path)
        .map_err(|e| Error::Output(format!("{}: cannot create file: {e}", path.display())))?;
    f(file).map_err(|e| match e {
        Error::Output(m) => Error::Output(format!("{}: {m}", path.display())),
        other => other,
    })
}

/// Writes a table: a header and rows of fields ([`Cell`]s or anything convertible: `f64`,
/// integers, `&str`, `Option`s of these).
///
/// # Errors
/// [`Error::Output`] for an empty header, a row of the wrong length, or a failed write.
pub fn write_table<'a, W, R, C>(
    out: W,
    header: &[&str],
    rows: impl IntoIterator<Item = R>,
) -> Result<()>
where
    W: Write,
    R: IntoIterator<Item = C>,
    C: Into<Cell<'a>>,
{
    let mut t = TableWriter::new(out, header)?;
    for r in rows {
        t.row(r)?;
    }
    t.finish().map(|_| ())
}

/// [`write_table`] to a file (parent directories are created).
///
/// # Errors
/// As [`write_table`], and if the file cannot be created; the message names the file.
pub fn write_table_path<'a, P, R, C>(
    path: P,
    header: &[&str],
    rows: impl IntoIterator<Item = R>,
) -> Result<()>
where
    P: AsRef<Path>,
    R: IntoIterator<Item = C>,
    C: Into<Cell<'a>>,
{
    to_path(path, |f| write_table(f, header, rows))
}

/// The column names of a sweep's tables: the parameter and the state components.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SweepColumns<'a, const N: usize> {
    /// The parameter column, e.g. `omega_rad_s`.
    pub param: &'a str,
    /// The state components of the stroboscopic points, e.g. `["x_m", "v_m_s"]`.
    pub state: [&'a str; N],
}

impl<'a, const N: usize> SweepColumns<'a, N> {
    /// Column names.
    pub const fn new(param: &'a str, state: [&'a str; N]) -> Self {
        Self { param, state }
    }
}

impl SweepColumns<'static, 2> {
    /// `param`, `x_m`, `v_m_s`: a 1-DOF oscillator with an unnamed parameter.
    pub const OSCILLATOR: Self = Self::new("param", STATE_XV);
    /// `omega_rad_s`, `x_m`, `v_m_s`: a 1-DOF oscillator swept in forcing frequency.
    pub const OSCILLATOR_OMEGA: Self = Self::new("omega_rad_s", STATE_XV);
}

/// The state columns of a 1-DOF oscillator: position in m, velocity in m/s.
pub const STATE_XV: [&str; 2] = ["x_m", "v_m_s"];

/// `up`, `down` or `both`.
pub fn direction_name(d: SweepDirection) -> &'static str {
    match d {
        SweepDirection::Up => "up",
        SweepDirection::Down => "down",
        SweepDirection::Both => "both",
    }
}

/// The stroboscopic (Poincaré) points of a sweep: `param, direction, <state…>`, one row per
/// point, branches in order (up, then down), points in the order computed.
///
/// # Errors
/// [`Error::Output`] if the write fails.
pub fn write_sweep_poincare<W: Write, const N: usize>(
    out: W,
    result: &SweepResult<N>,
    columns: &SweepColumns<'_, N>,
) -> Result<()> {
    let mut header = vec![columns.param, "direction"];
    header.extend_from_slice(&columns.state);
    let mut t = TableWriter::new(out, &header)?;
    for b in &result.branches {
        let dir = direction_name(b.direction);
        for p in &b.points {
            for y in &p.poincare {
                let row = [Cell::Number(p.param), Cell::Text(dir)]
                    .into_iter()
                    .chain(y.iter().map(|&v| Cell::Number(v)));
                t.row(row)?;
            }
        }
    }
    t.finish().map(|_| ())
}

/// The inter-impact intervals of a sweep: `param, direction, interval_s`, one row per
/// interval `T_j`.
///
/// # Errors
/// [`Error::Output`] if the write fails.
pub fn write_sweep_intervals<W: Write, const N: usize>(
    out: W,
    result: &SweepResult<N>,
    columns: &SweepColumns<'_, N>,
) -> Result<()> {
    let mut t = TableWriter::new(out, &[columns.param, "direction", "interval_s"])?;
    for b in &result.branches {
        let dir = direction_name(b.direction);
        for p in &b.points {
            for &iv in &p.intervals {
                t.row([Cell::Number(p.param), Cell::Text(dir), Cell::Number(iv)])?;
            }
        }
    }
    t.finish().map(|_| ())
}

/// One row per parameter value and branch: `param, direction, period, impacts_per_period,
/// grazing_margin_m` (period in forcing periods, empty if not periodic; the grazing margin
/// `level − max x` in the units of the position, negative when the stop is reached).
///
/// # Errors
/// [`Error::Output`] if the write fails.
pub fn write_sweep_summary<W: Write, const N: usize>(
    out: W,
    result: &SweepResult<N>,
    columns: &SweepColumns<'_, N>,
) -> Result<()> {
    let mut t = TableWriter::new(
        out,
        &[
            columns.param,
            "direction",
            "period",
            "impacts_per_period",
            "grazing_margin_m",
        ],
    )?;
    for b in &result.branches {
        let dir = direction_name(b.direction);
        for p in &b.points {
            t.row([
                Cell::Number(p.param),
                Cell::Text(dir),
                p.regime.period().into(),
                Cell::Number(p.impacts_per_period),
                Cell::Number(p.grazing_margin),
            ])?;
        }
    }
    t.finish().map(|_| ())
}

/// The name of a bifurcation kind in tables: `fold`, `period_doubling`, `neimark_sacker`,
/// `grazing`.
pub fn bifurcation_name(kind: BifurcationKind) -> &'static str {
    match kind {
        BifurcationKind::Fold => "fold",
        BifurcationKind::PeriodDoubling => "period_doubling",
        BifurcationKind::NeimarkSacker => "neimark_sacker",
        BifurcationKind::Grazing => "grazing",
    }
}

/// One row per point of a continued branch ([`crate::orbit::follow`]): parameter,
/// arclength, stability (`1`/`0`), the orbit's state at the section, the largest
/// multiplier modulus and the grazing margin (empty if not tested).
///
/// # Errors
/// [`Error::Output`] if a write fails.
pub fn write_branch<W: Write, const N: usize>(
    out: W,
    branch: &Branch<N>,
    columns: &SweepColumns<'_, N>,
) -> Result<()> {
    let mut header = vec![columns.param, "arclength", "stable"];
    header.extend(columns.state);
    header.extend(["max_multiplier", "grazing_margin_m"]);
    let mut t = TableWriter::new(out, &header)?;
    for q in &branch.points {
        let mut row = vec![
            Cell::Number(q.p),
            Cell::Number(q.arclength),
            Cell::Integer(i128::from(q.stable)),
        ];
        row.extend(q.state.iter().map(|&v| Cell::Number(v)));
        row.push(Cell::Number(
            q.multipliers.first().map_or(f64::NAN, modulus),
        ));
        row.push(q.grazing_margin.map_or(Cell::Empty, Cell::Number));
        t.row(row)?;
    }
    t.finish().map(|_| ())
}

/// One row per located bifurcation of a branch: parameter, kind
/// ([`bifurcation_name`]), the orbit's state, the largest multiplier modulus.
///
/// # Errors
/// [`Error::Output`] if a write fails.
pub fn write_bifurcations<W: Write, const N: usize>(
    out: W,
    branch: &Branch<N>,
    columns: &SweepColumns<'_, N>,
) -> Result<()> {
    let mut header = vec![columns.param, "kind"];
    header.extend(columns.state);
    header.push("max_multiplier");
    let mut t = TableWriter::new(out, &header)?;
    for b in &branch.bifurcations {
        let mut row = vec![Cell::Number(b.p), Cell::Text(bifurcation_name(b.kind))];
        row.extend(b.state.iter().map(|&v| Cell::Number(v)));
        row.push(Cell::Number(
            b.multipliers.first().map_or(f64::NAN, modulus),
        ));
        t.row(row)?;
    }
    t.finish().map(|_| ())
}

/// [`write_sweep_poincare`] to a file.
///
/// # Errors
/// As [`write_sweep_poincare`], and if the file cannot be created.
pub fn write_sweep_poincare_path<P: AsRef<Path>, const N: usize>(
    path: P,
    result: &SweepResult<N>,
    columns: &SweepColumns<'_, N>,
) -> Result<()> {
    to_path(path, |f| write_sweep_poincare(f, result, columns))
}

/// [`write_sweep_intervals`] to a file.
///
/// # Errors
/// As [`write_sweep_intervals`], and if the file cannot be created.
pub fn write_sweep_intervals_path<P: AsRef<Path>, const N: usize>(
    path: P,
    result: &SweepResult<N>,
    columns: &SweepColumns<'_, N>,
) -> Result<()> {
    to_path(path, |f| write_sweep_intervals(f, result, columns))
}

/// [`write_sweep_summary`] to a file.
///
/// # Errors
/// As [`write_sweep_summary`], and if the file cannot be created.
pub fn write_sweep_summary_path<P: AsRef<Path>, const N: usize>(
    path: P,
    result: &SweepResult<N>,
    columns: &SweepColumns<'_, N>,
) -> Result<()> {
    to_path(path, |f| write_sweep_summary(f, result, columns))
}

/// Writes the three tables of a sweep into `dir`: `<stem>_poincare.csv`,
/// `<stem>_intervals.csv` and `<stem>_summary.csv`; returns their paths in that order.
///
/// # Errors
/// As the single writers.
pub fn write_sweep_files<P: AsRef<Path>, const N: usize>(
    dir: P,
    stem: &str,
    result: &SweepResult<N>,
    columns: &SweepColumns<'_, N>,
) -> Result<[PathBuf; 3]> {
    let dir = dir.as_ref();
    let paths = [
        dir.join(format!("{stem}_poincare.csv")),
        dir.join(format!("{stem}_intervals.csv")),
        dir.join(format!("{stem}_summary.csv")),
    ];
    write_sweep_poincare_path(&paths[0], result, columns)?;
    write_sweep_intervals_path(&paths[1], result, columns)?;
    write_sweep_summary_path(&paths[2], result, columns)?;
    Ok(paths)
}

/// The stroboscopic points of a ramped run: `t_s, omega_rad_s, <state…>`.
///
/// # Errors
/// [`Error::Output`] if the write fails.
pub fn write_ramp_sections<W: Write, const N: usize>(
    out: W,
    record: &RampRecord<N>,
    state: [&str; N],
) -> Result<()> {
    let mut header = vec!["t_s", "omega_rad_s"];
    header.extend_from_slice(&state);
    let mut t = TableWriter::new(out, &header)?;
    for s in &record.sections {
        let row = [Cell::Number(s.t), Cell::Number(s.omega)]
            .into_iter()
            .chain(s.y.iter().map(|&v| Cell::Number(v)));
        t.row(row)?;
    }
    t.finish().map(|_| ())
}

/// The impacts of a ramped run: `t_s, omega_rad_s, interval_s, velocity_m_s` (the interval
/// is empty for the first impact).
///
/// # Errors
/// [`Error::Output`] if the write fails.
pub fn write_ramp_impacts<W: Write, const N: usize>(out: W, record: &RampRecord<N>) -> Result<()> {
    let mut t = TableWriter::new(out, &["t_s", "omega_rad_s", "interval_s", "velocity_m_s"])?;
    for i in &record.impacts {
        t.row([
            Cell::Number(i.t),
            Cell::Number(i.omega),
            i.interval.into(),
            Cell::Number(i.velocity),
        ])?;
    }
    t.finish().map(|_| ())
}

/// [`write_ramp_sections`] to a file.
///
/// # Errors
/// As [`write_ramp_sections`], and if the file cannot be created.
pub fn write_ramp_sections_path<P: AsRef<Path>, const N: usize>(
    path: P,
    record: &RampRecord<N>,
    state: [&str; N],
) -> Result<()> {
    to_path(path, |f| write_ramp_sections(f, record, state))
}

/// [`write_ramp_impacts`] to a file.
///
/// # Errors
/// As [`write_ramp_impacts`], and if the file cannot be created.
pub fn write_ramp_impacts_path<P: AsRef<Path>, const N: usize>(
    path: P,
    record: &RampRecord<N>,
) -> Result<()> {
    to_path(path, |f| write_ramp_impacts(f, record))
}

/// Section points or trajectory samples ([`Stroboscopic`](crate::sample::Stroboscopic),
/// [`Section`](crate::sample::Section), [`Trajectory`](crate::sample::Trajectory)):
/// `t_s, <state…>`.
///
/// # Errors
/// [`Error::Output`] if the write fails.
pub fn write_section_points<W: Write, T: Real, const N: usize>(
    out: W,
    points: &[SectionPoint<T, N>],
    state: [&str; N],
) -> Result<()> {
    let mut header = vec!["t_s"];
    header.extend_from_slice(&state);
    let mut t = TableWriter::new(out, &header)?;
    for p in points {
        let row = std::iter::once(Cell::Number(to_f64(p.t)))
            .chain(p.y.iter().map(|&v| Cell::Number(to_f64(v))));
        t.row(row)?;
    }
    t.finish().map(|_| ())
}

/// [`write_section_points`] to a file.
///
/// # Errors
/// As [`write_section_points`], and if the file cannot be created.
pub fn write_section_points_path<P: AsRef<Path>, T: Real, const N: usize>(
    path: P,
    points: &[SectionPoint<T, N>],
    state: [&str; N],
) -> Result<()> {
    to_path(path, |f| write_section_points(f, points, state))
}

/// An impact sequence ([`ImpactSequence`](crate::sample::ImpactSequence)):
/// `t_s, velocity_m_s, interval_s, max_penetration_m` (interval empty for the first impact,
/// penetration empty while a contact lasts at the end of the run).
///
/// # Errors
/// [`Error::Output`] if the write fails.
pub fn write_impacts<W: Write, T: Real>(out: W, impacts: &[Impact<T>]) -> Result<()> {
    let mut t = TableWriter::new(
        out,
        &["t_s", "velocity_m_s", "interval_s", "max_penetration_m"],
    )?;
    for i in impacts {
        t.row([
            Cell::Number(to_f64(i.t)),
            Cell::Number(to_f64(i.velocity)),
            i.interval.map(to_f64).into(),
            i.max_penetration.map(to_f64).into(),
        ])?;
    }
    t.finish().map(|_| ())
}

/// [`write_impacts`] to a file.
///
/// # Errors
/// As [`write_impacts`], and if the file cannot be created.
pub fn write_impacts_path<P: AsRef<Path>, T: Real>(path: P, impacts: &[Impact<T>]) -> Result<()> {
    to_path(path, |f| write_impacts(f, impacts))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(c: Cell<'_>) -> String {
        c.to_string()
    }

    #[test]
    fn number_forms() {
        assert_eq!(s(0.0.into()), "0");
        assert_eq!(s(20.465.into()), "20.465");
        assert_eq!(s((-2.0807e-3).into()), "-0.0020807");
        assert_eq!(s(1.5e-7.into()), "1.5e-7");
        assert_eq!(s(1e20.into()), "1e20");
        assert_eq!(s(f64::NAN.into()), "NaN");
        assert_eq!(s(f64::INFINITY.into()), "inf");
        assert_eq!(s(f64::NEG_INFINITY.into()), "-inf");
        assert_eq!(s(0.1f32.into()), "0.1");
        assert_eq!(s(7usize.into()), "7");
        assert_eq!(s(None::<f64>.into()), "");
        assert_eq!(s("up".into()), "up");
        // Round trip, bit for bit.
        for v in [
            std::f64::consts::PI,
            1.0 / 3.0,
            -2.086e-3,
            6.02214076e23,
            5e-324,
        ] {
            assert_eq!(s(v.into()).parse::<f64>().unwrap().to_bits(), v.to_bits());
        }
    }
}
