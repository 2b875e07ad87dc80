//! The validated [`TimeSeries`] and its CSV input/output.

use std::cell::RefCell;
use std::collections::VecDeque;
use std::io;
use std::path::Path;

use super::{
    Location, LowPass, PhaseSection, PoincarePoint, SignalError, ThresholdCrossing,
    validate_finite, validate_samples,
};
use crate::validate::ParameterError;

/// A column of a CSV file, by header name or by 0-based index.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Column {
    /// The column whose header field equals this name (after trimming spaces).
    Name(String),
    /// The column at this 0-based position.
    Index(usize),
}

impl From<&str> for Column {
    fn from(name: &str) -> Self {
        Column::Name(name.to_owned())
    }
}

impl From<String> for Column {
    fn from(name: String) -> Self {
        Column::Name(name)
    }
}

impl From<usize> for Column {
    fn from(index: usize) -> Self {
        Column::Index(index)
    }
}

impl std::fmt::Display for Column {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Column::Name(n) => write!(f, "`{n}`"),
            Column::Index(i) => write!(f, "#{i}"),
        }
    }
}

/// Whether and where to read a phase column.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum PhaseColumn {
    /// No phase is read.
    None,
    /// The phase is read from this column if the header has it, otherwise there is none.
    IfPresent(Column),
    /// The phase must be in this column ([`SignalError::MissingColumn`] otherwise).
    Required(Column),
}

/// How to read a CSV record into a [`TimeSeries`].
///
/// The defaults read what [`TimeSeries::write_csv`] writes: columns `t_s`, `x_m` and, if
/// present, `phase_rad`, comma separated, `#` starting a comment line, at least two rows.
/// Values are multiplied by the scales (e.g. `position_scale = 1e-3` for a file in mm,
/// `phase_scale = π/180` for degrees) so that the series is in SI units.
///
/// ```
/// use nonsmooth::signal::{Column, CsvOptions};
/// let opts = CsvOptions::default()
///     .with_time("time")
///     .with_position(Column::Index(2))
///     .with_position_scale(1e-3)
///     .with_phase("angle");
/// assert_eq!(opts.position, Column::Index(2));
/// ```
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CsvOptions {
    /// The time column (default `t_s`).
    pub time: Column,
    /// The position column (default `x_m`).
    pub position: Column,
    /// The phase column (default: `phase_rad` if present).
    pub phase: PhaseColumn,
    /// Factor turning the time column into seconds (default 1).
    pub time_scale: f64,
    /// Factor turning the position column into metres (default 1).
    pub position_scale: f64,
    /// Factor turning the phase column into radians (default 1).
    pub phase_scale: f64,
    /// The field delimiter (default `,`).
    pub delimiter: u8,
    /// Lines starting with this byte are skipped (default `#`; they still count for line
    /// numbers). A line inside a quoted multi-line field that starts with it is blanked too.
    pub comment: Option<u8>,
    /// The minimum number of data rows (default 2).
    pub min_samples: usize,
}

impl Default for CsvOptions {
    fn default() -> Self {
        Self {
            time: Column::from(TimeSeries::TIME_HEADER),
            position: Column::from(TimeSeries::POSITION_HEADER),
            phase: PhaseColumn::IfPresent(Column::from(TimeSeries::PHASE_HEADER)),
            time_scale: 1.0,
            position_scale: 1.0,
            phase_scale: 1.0,
            delimiter: b',',
            comment: Some(b'#'),
            min_samples: 2,
        }
    }
}

impl CsvOptions {
    /// Reads time from `column`.
    #[must_use]
    pub fn with_time(mut self, column: impl Into<Column>) -> Self {
        self.time = column.into();
        self
    }

    /// Reads the position from `column`.
    #[must_use]
    pub fn with_position(mut self, column: impl Into<Column>) -> Self {
        self.position = column.into();
        self
    }

    /// Requires the phase in `column`.
    #[must_use]
    pub fn with_phase(mut self, column: impl Into<Column>) -> Self {
        self.phase = PhaseColumn::Required(column.into());
        self
    }

    /// Reads no phase.
    #[must_use]
    pub fn without_phase(mut self) -> Self {
        self.phase = PhaseColumn::None;
        self
    }

    /// Sets the factor turning the time column into seconds.
    #[must_use]
    pub fn with_time_scale(mut self, scale: f64) -> Self {
        self.time_scale = scale;
        self
    }

    /// Sets the factor turning the position column into metres.
    #[must_use]
    pub fn with_position_scale(mut self, scale: f64) -> Self {
        self.position_scale = scale;
        self
    }

    /// Sets the factor turning the phase column into radians.
    #[must_use]
    pub fn with_phase_scale(mut self, scale: f64) -> Self {
        self.phase_scale = scale;
        self
    }

    /// Sets the field delimiter.
    #[must_use]
    pub fn with_delimiter(mut self, delimiter: u8) -> Self {
        self.delimiter = delimiter;
        self
    }

    /// Sets the comment byte (`None`: no comments).
    #[must_use]
    pub fn with_comment(mut self, comment: Option<u8>) -> Self {
        self.comment = comment;
        self
    }

    /// Sets the minimum number of data rows.
    #[must_use]
    pub fn with_min_samples(mut self, min_samples: usize) -> Self {
        self.min_samples = min_samples;
        self
    }

    fn validate(&self) -> Result<(), SignalError> {
        for (name, v) in [
            ("time_scale", self.time_scale),
            ("position_scale", self.position_scale),
            ("phase_scale", self.phase_scale),
        ] {
            if !(v.is_finite() && v != 0.0) {
                return Err(ParameterError::new(name, v, "finite and non-zero").into());
            }
        }
        if self.time_scale < 0.0 {
            return Err(ParameterError::new("time_scale", self.time_scale, "> 0").into());
        }
        Ok(())
    }
}

/// A measured (or simulated) record `x(t)`, optionally with a phase `φ(t)`: equal lengths,
/// strictly increasing finite times, finite values, at least a minimum number of samples.
///
/// Units are SI (s, m, rad) by convention; [`CsvOptions`] scales other units on input.
///
/// # Examples
/// ```
/// use nonsmooth::signal::{CsvOptions, TimeSeries};
/// let csv = "t_s,x_m\n0.0,1e-3\n0.001,1.5e-3\n0.002,1.2e-3\n";
/// let s = TimeSeries::from_csv_reader(csv.as_bytes(), &CsvOptions::default())?;
/// assert_eq!(s.len(), 3);
/// assert_eq!(s.x()[1], 1.5e-3);
/// // A bad field is reported with its line (the header is line 1).
/// let bad = "t_s,x_m\n0.0,1e-3\n0.001,oops\n";
/// let err = TimeSeries::from_csv_reader(bad.as_bytes(), &CsvOptions::default()).unwrap_err();
/// assert_eq!(err.to_string(), "line 3: cannot parse `oops` in column `x_m` as a number");
/// # Ok::<(), nonsmooth::signal::SignalError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TimeSeries {
    t: Vec<f64>,
    x: Vec<f64>,
    phase: Option<Vec<f64>>,
}

/// The columns of a CSV file a [`TimeSeries`] reads: index and name of each.
struct Columns {
    time: (usize, String),
    position: (usize, String),
    phase: Option<(usize, String)>,
}

impl Columns {
    /// The columns `options` names, found in `header`.
    fn find(header: &csv::StringRecord, options: &CsvOptions) -> Result<Self, SignalError> {
        let find = |col: &Column| -> Option<(usize, String)> {
            match col {
                Column::Name(n) => header
                    .iter()
                    .position(|h| h == n.trim())
                    .map(|i| (i, n.clone())),
                Column::Index(i) => header.get(*i).map(|h| (*i, h.to_owned())),
            }
        };
        let missing = |col: &Column| SignalError::MissingColumn {
            column: col.to_string(),
            available: header.iter().collect::<Vec<_>>().join(","),
        };
        Ok(Self {
            time: find(&options.time).ok_or_else(|| missing(&options.time))?,
            position: find(&options.position).ok_or_else(|| missing(&options.position))?,
            phase: match &options.phase {
                PhaseColumn::None => None,
                PhaseColumn::IfPresent(c) => find(c),
                PhaseColumn::Required(c) => Some(find(c).ok_or_else(|| missing(c))?),
            },
        })
    }
}

/// Field `idx` (column `name`) of a record on `line`, times `scale`: present, a number,
/// finite after scaling.
fn parse_field(
    record: &csv::StringRecord,
    idx: usize,
    name: &str,
    scale: f64,
    line: u64,
) -> Result<f64, SignalError> {
    let text = record.get(idx).unwrap_or("");
    if text.is_empty() {
        return Err(SignalError::MissingField {
            line,
            column: format!("`{name}`"),
        });
    }
    let v: f64 = text.parse().map_err(|_| SignalError::ParseField {
        line,
        column: format!("`{name}`"),
        text: text.to_owned(),
    })?;
    let v = v * scale;
    if !v.is_finite() {
        return Err(SignalError::NonFinite {
            location: Location::Line(line),
            what: format!("column `{name}`"),
            value: v,
        });
    }
    Ok(v)
}

impl TimeSeries {
    /// Header of the time column written by [`write_csv`](Self::write_csv).
    pub const TIME_HEADER: &'static str = "t_s";
    /// Header of the position column.
    pub const POSITION_HEADER: &'static str = "x_m";
    /// Header of the phase column.
    pub const PHASE_HEADER: &'static str = "phase_rad";

    /// A validated series with at least two samples.
    ///
    /// # Errors
    /// As [`with_min_samples`](Self::with_min_samples) with `min_samples = 2`.
    pub fn new(t: Vec<f64>, x: Vec<f64>, phase: Option<Vec<f64>>) -> Result<Self, SignalError> {
        Self::with_min_samples(t, x, phase, 2)
    }

    /// A validated series with at least `min_samples` samples.
    ///
    /// # Errors
    /// [`SignalError::LengthMismatch`] for unequal lengths, [`SignalError::TooFewSamples`],
    /// [`SignalError::NonIncreasingTime`] / [`SignalError::NonFinite`] with the sample index.
    pub fn with_min_samples(
        t: Vec<f64>,
        x: Vec<f64>,
        phase: Option<Vec<f64>>,
        min_samples: usize,
    ) -> Result<Self, SignalError> {
        validate_samples(&t, &x, "x", min_samples)?;
        if let Some(p) = &phase {
            if p.len() != t.len() {
                return Err(SignalError::LengthMismatch {
                    what: "phase",
                    expected: t.len(),
                    found: p.len(),
                });
            }
            validate_finite(p, "phase")?;
        }
        Ok(Self { t, x, phase })
    }

    /// The sample times (s).
    pub fn t(&self) -> &[f64] {
        &self.t
    }

    /// The positions (m).
    pub fn x(&self) -> &[f64] {
        &self.x
    }

    /// The phase (rad), if recorded.
    pub fn phase(&self) -> Option<&[f64]> {
        self.phase.as_deref()
    }

    /// The number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// `true` for a series without samples (only possible with `min_samples = 0`).
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// `(t_first, t_last)`, `None` when empty.
    pub fn span(&self) -> Option<(f64, f64)> {
        Some((*self.t.first()?, *self.t.last()?))
    }

    /// The vectors `(t, x, phase)`.
    pub fn into_parts(self) -> (Vec<f64>, Vec<f64>, Option<Vec<f64>>) {
        (self.t, self.x, self.phase)
    }

    /// A copy with `x` passed through `filter` (the phase is not filtered).
    ///
    /// # Errors
    /// [`SignalError::TooFewSamples`] for an empty series or a non-finite initial value of
    /// the filter.
    pub fn filtered(&self, filter: &LowPass<f64>) -> Result<TimeSeries, SignalError> {
        let x = filter.filter(&self.t, &self.x)?;
        Ok(Self {
            t: self.t.clone(),
            x,
            phase: self.phase.clone(),
        })
    }

    /// The crossing times of `x` found by `detector`.
    ///
    /// # Errors
    /// None in practice (the series is valid); the signature matches
    /// [`ThresholdCrossing::times`].
    pub fn crossings(&self, detector: &ThresholdCrossing<f64>) -> Result<Vec<f64>, SignalError> {
        detector.times(&self.t, &self.x)
    }

    /// The Poincaré points of `x` on the phase section.
    ///
    /// # Errors
    /// [`SignalError::MissingPhase`] if the series has no phase.
    pub fn poincare(
        &self,
        section: &PhaseSection<f64>,
    ) -> Result<Vec<PoincarePoint<f64>>, SignalError> {
        let phase = self.phase.as_deref().ok_or(SignalError::MissingPhase)?;
        section.sample(&self.t, phase, &self.x)
    }

    /// Reads a CSV file.
    ///
    /// # Errors
    /// [`SignalError::Io`] if the file cannot be opened, and everything
    /// [`from_csv_reader`](Self::from_csv_reader) reports.
    pub fn from_csv_path(
        path: impl AsRef<Path>,
        options: &CsvOptions,
    ) -> Result<Self, SignalError> {
        let path = path.as_ref();
        let file = std::fs::File::open(path).map_err(|e| SignalError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        Self::from_csv_reader(io::BufReader::new(file), options)
    }

    /// Reads CSV text: a header row naming the columns, then one sample per row. Columns
    /// the options do not name are ignored, blank lines and comment lines skipped; nothing
    /// else is dropped. A row may be shorter than the header as long as the columns read
    /// are present; a row with more fields than the header is an error.
    ///
    /// # Errors
    /// Each with the 1-based line number (the header is line 1):
    /// [`SignalError::MissingField`] for a short row or an empty field,
    /// [`SignalError::ExtraFields`] for a row with more fields than the header,
    /// [`SignalError::ParseField`] for text that is not a number,
    /// [`SignalError::NonFinite`] for NaN/∞ (also after scaling),
    /// [`SignalError::NonIncreasingTime`] when time does not increase strictly,
    /// [`SignalError::Csv`] for malformed CSV (invalid UTF-8, I/O errors).
    /// Without line: [`SignalError::EmptyInput`] (no header),
    /// [`SignalError::MissingColumn`], [`SignalError::TooFewSamples`],
    /// [`SignalError::Parameter`] for a zero/non-finite scale.
    pub fn from_csv_reader<R: io::Read>(
        reader: R,
        options: &CsvOptions,
    ) -> Result<Self, SignalError> {
        options.validate()?;
        // The `csv` crate's record positions are not line-accurate (they point before skipped
        // blank lines and mis-count CRLF and comment lines), so lines are tracked here:
        // comment lines are blanked (newline kept), and `LineTracker` maps each record's byte
        // offset to the line where its first character is.
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(true)
            .flexible(true)
            .trim(csv::Trim::All)
            .delimiter(options.delimiter)
            .from_reader(LineTracker::new(CommentBlanker::new(
                reader,
                options.comment,
            )));
        let csv_error = |e: csv::Error, rdr: &csv::Reader<LineTracker<_>>| {
            let line = e.position().map(|p| rdr.get_ref().line_of(p.byte()));
            to_signal_error(e, line)
        };
        let header = match rdr.headers() {
            Ok(h) => h.clone(),
            Err(e) => return Err(csv_error(e, &rdr)),
        };
        if header.is_empty() {
            return Err(SignalError::EmptyInput { what: "header" });
        }
        let columns = Columns::find(&header, options)?;

        let mut t = Vec::new();
        let mut x = Vec::new();
        let mut phase = columns.phase.as_ref().map(|_| Vec::new());
        let mut record = csv::StringRecord::new();
        loop {
            match rdr.read_record(&mut record) {
                Ok(true) => {}
                Ok(false) => break,
                Err(e) => return Err(csv_error(e, &rdr)),
            }
            let line = rdr
                .get_ref()
                .line_of(record.position().map_or(u64::MAX, |p| p.byte()));
            if record.len() > header.len() {
                return Err(SignalError::ExtraFields {
                    line,
                    found: record.len(),
                    expected: header.len(),
                });
            }
            let (it, t_name) = &columns.time;
            let (ix, x_name) = &columns.position;
            let ti = parse_field(&record, *it, t_name, options.time_scale, line)?;
            let xi = parse_field(&record, *ix, x_name, options.position_scale, line)?;
            if let Some(&previous) = t.last() {
                if ti <= previous {
                    return Err(SignalError::NonIncreasingTime {
                        location: Location::Line(line),
                        previous,
                        t: ti,
                    });
                }
            }
            if let (Some((ip, p_name)), Some(ph)) = (&columns.phase, phase.as_mut()) {
                ph.push(parse_field(
                    &record,
                    *ip,
                    p_name,
                    options.phase_scale,
                    line,
                )?);
            }
            t.push(ti);
            x.push(xi);
        }
        if t.len() < options.min_samples {
            return Err(SignalError::TooFewSamples {
                found: t.len(),
                required: options.min_samples,
            });
        }
        Ok(Self { t, x, phase })
    }

    /// Writes the series as tidy CSV with SI units in the header: `t_s,x_m` and
    /// `phase_rad` when a phase is present. Numbers are written in their shortest form that
    /// reads back to the same `f64`, so a write–read round trip is exact.
    ///
    /// # Errors
    /// [`SignalError::Io`] / [`SignalError::Csv`] if writing fails.
    pub fn write_csv<W: io::Write>(&self, writer: W) -> Result<(), SignalError> {
        let mut w = csv::WriterBuilder::new().from_writer(writer);
        let mut header = vec![Self::TIME_HEADER, Self::POSITION_HEADER];
        if self.phase.is_some() {
            header.push(Self::PHASE_HEADER);
        }
        w.write_record(&header)
            .map_err(|e| to_signal_error(e, None))?;
        let mut row: Vec<String> = Vec::with_capacity(3);
        for n in 0..self.t.len() {
            row.clear();
            row.push(format_number(self.t[n]));
            row.push(format_number(self.x[n]));
            if let Some(p) = &self.phase {
                row.push(format_number(p[n]));
            }
            w.write_record(&row).map_err(|e| to_signal_error(e, None))?;
        }
        w.flush().map_err(|e| SignalError::Io {
            path: "<writer>".into(),
            message: e.to_string(),
        })
    }

    /// Writes the series to a CSV file (see [`write_csv`](Self::write_csv)); the parent
    /// directory must exist.
    ///
    /// # Errors
    /// [`SignalError::Io`] if the file cannot be created or written.
    pub fn write_csv_path(&self, path: impl AsRef<Path>) -> Result<(), SignalError> {
        let path = path.as_ref();
        let io_err = |e: io::Error| SignalError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        };
        let file = std::fs::File::create(path).map_err(io_err)?;
        let mut buf = io::BufWriter::new(file);
        self.write_csv(&mut buf).map_err(|e| match e {
            SignalError::Io { message, .. } => SignalError::Io {
                path: path.display().to_string(),
                message,
            },
            other => other,
        })?;
        io::Write::flush(&mut buf).map_err(io_err)
    }
}

/// Replaces every line that starts with the comment byte by an empty line (keeping its
/// newline), so that the CSV reader skips it but still counts it.
struct CommentBlanker<R> {
    inner: R,
    comment: Option<u8>,
    at_line_start: bool,
    in_comment: bool,
}

impl<R> CommentBlanker<R> {
    fn new(inner: R, comment: Option<u8>) -> Self {
        Self {
            inner,
            comment,
            at_line_start: true,
            in_comment: false,
        }
    }
}

impl<R: io::Read> io::Read for CommentBlanker<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let Some(c) = self.comment else {
            return self.inner.read(buf);
        };
        loop {
            let n = self.inner.read(buf)?;
            if n == 0 {
                return Ok(0);
            }
            let mut w = 0;
            for r in 0..n {
                let b = buf[r];
                if self.at_line_start && b == c {
                    self.in_comment = true;
                }
                self.at_line_start = b == b'\n';
                if self.in_comment && b != b'\n' {
                    continue;
                }
                self.in_comment = false;
                buf[w] = b;
                w += 1;
            }
            // A chunk made only of comment text yields nothing: read on (0 means EOF).
            if w > 0 {
                return Ok(w);
            }
        }
    }
}

/// Counts lines (terminated by `\n`, `\r` or `\r\n`) in the byte stream the CSV reader
/// consumes, remembering where each non-blank line's first character is.
struct LineTracker<R> {
    inner: R,
    /// Byte offset of the next byte.
    offset: u64,
    /// 1-based number of the current line.
    line: u64,
    line_has_content: bool,
    previous_was_cr: bool,
    /// `(line, offset of its first character)` of non-blank lines not yet passed.
    starts: RefCell<VecDeque<(u64, u64)>>,
}

impl<R> LineTracker<R> {
    fn new(inner: R) -> Self {
        Self {
            inner,
            offset: 0,
            line: 1,
            line_has_content: false,
            previous_was_cr: false,
            starts: RefCell::new(VecDeque::new()),
        }
    }

    /// The line of the first character at or after byte `offset` (a record's start as the
    /// CSV reader reports it may lie before skipped terminators and blank lines). Offsets
    /// must not decrease between calls.
    fn line_of(&self, offset: u64) -> u64 {
        let mut starts = self.starts.borrow_mut();
        while starts.front().is_some_and(|&(_, o)| o < offset) {
            starts.pop_front();
        }
        starts.front().map_or(self.line, |&(l, _)| l)
    }
}

impl<R: io::Read> io::Read for LineTracker<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        let mut starts = self.starts.borrow_mut();
        for &b in &buf[..n] {
            match b {
                b'\n' if self.previous_was_cr => {}
                b'\n' | b'\r' => {
                    self.line += 1;
                    self.line_has_content = false;
                }
                _ if !self.line_has_content => {
                    self.line_has_content = true;
                    starts.push_back((self.line, self.offset));
                }
                _ => {}
            }
            self.previous_was_cr = b == b'\r';
            self.offset += 1;
        }
        Ok(n)
    }
}

/// Shortest round-trip text: plain decimals for ordinary magnitudes, exponent otherwise.
fn format_number(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || (1e-4..1e15).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

fn to_signal_error(e: csv::Error, line: Option<u64>) -> SignalError {
    if let csv::ErrorKind::Io(io) = e.kind() {
        return SignalError::Io {
            path: "<stream>".into(),
            message: io.to_string(),
        };
    }
    SignalError::Csv {
        line,
        message: e.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn number_format_round_trips() {
        for v in [
            0.0,
            -0.0,
            1e-300,
            -2.0807e-3,
            1.0 / 3.0,
            123456.789,
            6.02e23,
            5e-324,
            f64::MAX,
        ] {
            let s = format_number(v);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
        }
        assert_eq!(format_number(1e-3), "0.001");
        assert_eq!(format_number(1e-5), "1e-5");
    }

    #[test]
    fn comment_blanker_keeps_newlines() {
        use std::io::Read;
        let text = b"# a\r\nt,x\n#b,c\n1,2\n#";
        // Read through a 1-byte buffer to exercise the chunk boundaries.
        let mut out = Vec::new();
        let mut r = CommentBlanker::new(&text[..], Some(b'#'));
        let mut one = [0u8; 1];
        while r.read(&mut one).unwrap() == 1 {
            out.push(one[0]);
        }
        assert_eq!(out, b"\nt,x\n\n1,2\n");
        let mut all = String::new();
        CommentBlanker::new(&b"a#\n#"[..], None)
            .read_to_string(&mut all)
            .unwrap();
        assert_eq!(all, "a#\n#");
    }

    #[test]
    fn line_numbers_survive_blank_lines_crlf_comments_and_quotes() {
        let o = CsvOptions::default();
        for (text, line) in [
            ("t_s,x_m\n0,1\n\n\n1,x\n", 5),
            ("t_s,x_m\r\n0,1\r\n\r\n1,x\r\n", 4),
            ("\n# c\nt_s,x_m\n0,1\n# c\n1,x\n", 6),
            ("t_s,x_m,note\n0,1,\"a\nb\"\n1,x,c\n", 4),
            ("t_s,x_m\r0,1\r1,x\r", 3),
            ("t_s,x_m\n0,1\n   \n", 3),
        ] {
            let e = TimeSeries::from_csv_reader(text.as_bytes(), &o).unwrap_err();
            let got = match e {
                SignalError::ParseField { line, .. } | SignalError::MissingField { line, .. } => {
                    line
                }
                other => panic!("{text:?}: {other:?}"),
            };
            assert_eq!(got, line, "{text:?}");
        }
    }

    #[test]
    fn scales_are_validated() {
        let o = CsvOptions::default().with_position_scale(0.0);
        assert!(matches!(
            TimeSeries::from_csv_reader("t_s,x_m\n0,0\n1,1\n".as_bytes(), &o),
            Err(SignalError::Parameter(_))
        ));
        let o = CsvOptions::default().with_time_scale(-1.0);
        assert!(TimeSeries::from_csv_reader("t_s,x_m\n0,0\n1,1\n".as_bytes(), &o).is_err());
    }
}
