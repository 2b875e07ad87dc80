//! The merged study: the table, the sections, the attractor summary and the figure.

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::StudyError;
use super::attractor::{AttractorSummary, identify, regime_class};
use super::record::PointRecord;
use super::shard::{fmt_f64, read_shards, sections_csv, surface_columns, surface_values};
use super::spec::Study;

/// A merged study.
#[derive(Debug, Clone)]
pub struct Merged {
    /// The study.
    pub study: Study,
    /// Every point, in index order.
    pub records: Vec<PointRecord>,
    /// Attractor labels (per group of equal system parameters; `None` for failed points).
    pub labels: Vec<Option<usize>>,
    /// The attractors found.
    pub attractors: Vec<AttractorSummary>,
}

impl Merged {
    /// Merges the points of a study computed in any number of shards.
    ///
    /// # Errors
    /// [`StudyError::InvalidSpec`] for records that are not every point of `study` in
    /// index order.
    pub fn new(study: Study, records: Vec<PointRecord>) -> Result<Self, StudyError> {
        if records.len() != study.points() || records.iter().enumerate().any(|(i, r)| r.index != i)
        {
            return Err(StudyError::MissingShards(format!(
                "{} records for a study of {} points (every point once, in order)",
                records.len(),
                study.points()
            )));
        }
        let (labels, attractors) = identify(&study, &records);
        Ok(Self {
            study,
            records,
            labels,
            attractors,
        })
    }

    /// Reads and verifies the shards in `dir` ([`read_shards`]) and merges them.
    ///
    /// # Errors
    /// As [`read_shards`].
    pub fn from_dir(dir: &Path) -> Result<Self, StudyError> {
        let (study, records) = read_shards(dir)?;
        Self::new(study, records)
    }

    /// Points whose status is not `ok`.
    pub fn failed(&self) -> usize {
        self.records.iter().filter(|r| !r.is_ok()).count()
    }

    /// The merged table as CSV text: one row per point in index order.
    pub fn table(&self) -> Result<Vec<u8>, StudyError> {
        let spec = self.study.spec();
        let yname = spec
            .grid
            .y
            .as_ref()
            .map_or("y".to_string(), |y| y.parameter.clone());
        let mut w = csv::Writer::from_writer(Vec::new());
        let e = |e: csv::Error| StudyError::Io(e.to_string());
        let n = surface_columns(&self.study);
        let mut header: Vec<String> = [
            "index",
            "ix",
            "iy",
            spec.grid.x.parameter.as_str(),
            yname.as_str(),
            "period",
            "impacts_per_period",
        ]
        .map(String::from)
        .to_vec();
        header.extend((0..n).map(|k| format!("impacts_per_period_{k}")));
        header.extend(["tle", "tle_spread", "q", "label", "class", "status"].map(String::from));
        w.write_record(&header).map_err(e)?;
        for (r, l) in self.records.iter().zip(&self.labels) {
            let (ix, iy) = self.study.coordinates(r.index);
            let (x, y) = self.study.values(r.index);
            let mut row = vec![
                r.index.to_string(),
                ix.to_string(),
                iy.to_string(),
                fmt_f64(x),
                fmt_f64(y),
                r.period.to_string(),
                fmt_f64(r.impacts_per_period),
            ];
            row.extend(surface_values(r, n));
            row.extend([
                fmt_f64(r.tle),
                fmt_f64(r.tle_spread),
                fmt_f64(r.q),
                l.map_or(String::new(), |l| l.to_string()),
                regime_class(r),
                r.status.clone(),
            ]);
            w.write_record(row).map_err(e)?;
        }
        w.into_inner().map_err(|e| StudyError::Io(e.to_string()))
    }

    /// Writes the merged table to `out` and, beside it, `STEM.sections.csv`,
    /// `STEM.attractors.csv` and the figure `STEM.png`; returns the paths written.
    ///
    /// # Errors
    /// [`StudyError::Io`] if a file cannot be written.
    pub fn write(&self, out: &Path) -> Result<Vec<PathBuf>, StudyError> {
        let io =
            |p: &Path, e: &dyn std::fmt::Display| StudyError::Io(format!("{}: {e}", p.display()));
        if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(parent).map_err(|e| io(parent, &e))?;
        }
        let stem = out.with_extension("");
        let side = |suffix: &str| PathBuf::from(format!("{}{suffix}", stem.display()));
        let mut written = Vec::new();
        std::fs::write(out, self.table()?).map_err(|e| io(out, &e))?;
        written.push(out.to_path_buf());

        let p = side(".sections.csv");
        std::fs::write(&p, sections_csv(&self.study, &self.records)?).map_err(|e| io(&p, &e))?;
        written.push(p);

        let ce = |e: csv::Error| StudyError::Io(e.to_string());
        let mut w = csv::Writer::from_writer(Vec::new());
        let mut header: Vec<String> = [
            "group_ix",
            "group_iy",
            "label",
            "representative",
            "points",
            "fraction",
            "period",
            "impacts_per_period",
            "tle_mean",
        ]
        .map(String::from)
        .to_vec();
        header.extend(
            self.study
                .system()
                .state_names()
                .iter()
                .map(|n| format!("centroid_{n}")),
        );
        w.write_record(&header).map_err(ce)?;
        let opt = |o: Option<usize>| o.map_or(String::new(), |v| v.to_string());
        for a in &self.attractors {
            let mut row = vec![
                opt(a.group.0),
                opt(a.group.1),
                a.label.to_string(),
                a.representative.to_string(),
                a.points.to_string(),
                fmt_f64(a.fraction),
                a.period.to_string(),
                fmt_f64(a.impacts_per_period),
                fmt_f64(a.tle_mean),
            ];
            row.extend(a.centroid.iter().map(|&c| fmt_f64(c)));
            w.write_record(row).map_err(ce)?;
        }
        let p = side(".attractors.csv");
        std::fs::write(
            &p,
            w.into_inner().map_err(|e| StudyError::Io(e.to_string()))?,
        )
        .map_err(|e| io(&p, &e))?;
        written.push(p);

        let p = side(".png");
        self.figure(&p)?;
        written.push(p);
        Ok(written)
    }

    /// Whether every axis is an initial-condition component (a basin picture).
    fn is_basin(&self) -> bool {
        let g = &self.study.spec().grid;
        g.x.is_initial_condition() && g.y.as_ref().is_none_or(|y| y.is_initial_condition())
    }

    /// The figure (PNG): for a basin picture (every axis an initial condition) the plane
    /// coloured by attractor label; for a regime map two panels, the period (P1 … P8, longer,
    /// not periodic, chaotic) and the impacts per forcing period (a colour scale).
    ///
    /// # Errors
    /// [`StudyError::Io`] if drawing or writing fails.
    pub fn figure(&self, path: &Path) -> Result<(), StudyError> {
        let err = |e: &dyn std::fmt::Display| StudyError::Io(format!("{}: {e}", path.display()));
        register_font().map_err(|e| err(&e))?;
        let spec = self.study.spec();
        let n = self.records.len();
        if self.is_basin() {
            let root = BitMapBackend::new(path, (1000, 700)).into_drawing_area();
            root.fill(&WHITE).map_err(|e| err(&e))?;
            let (colours, legend) = self.basin_colours();
            let title = format!("{}: basins of attraction ({n} points)", spec.name);
            self.panel(&root, &title, &colours, &legend)
                .map_err(|e| err(&e))?;
            return root.present().map_err(|e| err(&e));
        }
        let root = BitMapBackend::new(path, (1800, 700)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let (left, right) = root.split_horizontally(900);
        let (colours, legend) = self.period_colours();
        self.panel(
            &left,
            &format!("{}: period ({n} points)", spec.name),
            &colours,
            &legend,
        )
        .map_err(|e| err(&e))?;
        let (colours, legend) = self.impact_colours();
        self.panel(&right, "impacts per forcing period", &colours, &legend)
            .map_err(|e| err(&e))?;
        root.present().map_err(|e| err(&e))
    }

    /// A basin picture's colours (by point: the attractor's label, black where the point
    /// failed) and its legend.
    fn basin_colours(&self) -> (Vec<RGBColor>, Vec<(String, RGBColor)>) {
        let mut legend = Vec::new();
        for a in &self.attractors {
            let what = if a.period > 0 {
                format!(
                    "P{}, {} imp.",
                    a.period,
                    (a.impacts_per_period * a.period as f64).round()
                )
            } else {
                format!("not periodic, {:.2} imp./T", a.impacts_per_period)
            };
            legend.push((
                format!("{}: {what} ({:.0} %)", a.label, 100.0 * a.fraction),
                palette(a.label),
            ));
        }
        if self.labels.iter().any(Option::is_none) {
            legend.push(("failed".into(), BLACK));
        }
        let colours: Vec<RGBColor> = self
            .labels
            .iter()
            .map(|l| l.map_or(BLACK, palette))
            .collect();
        (colours, legend)
    }

    /// The period panel's colours (P1 … P8, longer, not periodic, chaotic, failed) and
    /// its legend.
    fn period_colours(&self) -> (Vec<RGBColor>, Vec<(String, RGBColor)>) {
        let grey = RGBColor(150, 150, 150);
        let chaos = RGBColor(20, 20, 20);
        let period_class = |r: &PointRecord| -> (usize, String, RGBColor) {
            if !r.is_ok() && r.sections.is_empty() {
                (12, "failed".into(), RGBColor(255, 0, 255))
            } else if r.period > 8 {
                (9, "P > 8".into(), RGBColor(120, 60, 20))
            } else if r.period > 0 {
                (r.period, format!("P{}", r.period), palette(r.period - 1))
            } else if regime_class(r) == "chaotic" {
                (11, "chaotic (λ₁ > 0)".into(), chaos)
            } else {
                (10, "not periodic".into(), grey)
            }
        };
        let classes: Vec<(usize, String, RGBColor)> =
            self.records.iter().map(period_class).collect();
        let mut legend: Vec<(usize, String, RGBColor)> = classes.clone();
        legend.sort_by_key(|c| c.0);
        legend.dedup_by_key(|c| c.0);
        let legend: Vec<(String, RGBColor)> = legend.into_iter().map(|c| (c.1, c.2)).collect();
        let colours: Vec<RGBColor> = classes.iter().map(|c| c.2).collect();
        (colours, legend)
    }

    /// The impacts-per-period panel's colours (a ramp up to the largest finite value) and
    /// its legend.
    fn impact_colours(&self) -> (Vec<RGBColor>, Vec<(String, RGBColor)>) {
        let max = self
            .records
            .iter()
            .map(|r| r.impacts_per_period)
            .filter(|v| v.is_finite())
            .fold(0.0_f64, f64::max)
            .max(1.0);
        let colours: Vec<RGBColor> = self
            .records
            .iter()
            .map(|r| {
                if r.impacts_per_period.is_finite() {
                    ramp(r.impacts_per_period / max)
                } else {
                    RGBColor(255, 0, 255)
                }
            })
            .collect();
        let steps = 6;
        let legend: Vec<(String, RGBColor)> = (0..=steps)
            .map(|k| {
                let v = max * k as f64 / steps as f64;
                (format!("{v:.2}"), ramp(v / max))
            })
            .collect();
        (colours, legend)
    }

    /// One panel: the grid cells in `colours` (by point), a legend at the right.
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, plotters::coord::Shift>,
        title: &str,
        colours: &[RGBColor],
        legend: &[(String, RGBColor)],
    ) -> Result<(), String> {
        let e = |e: &dyn std::fmt::Display| e.to_string();
        let spec = self.study.spec();
        let gx = &spec.grid.x;
        let (ny, ylab, (y0, y1)) = match &spec.grid.y {
            Some(y) => (y.points, y.parameter.clone(), (y.start, y.end)),
            None => (1, String::new(), (0.0, 1.0)),
        };
        let ((xl, xh, dx), x_index, xlab) = chart_axis(gx.start, gx.end, gx.points, &gx.parameter);
        let ((yl, yh, dy), y_index, ylab) = chart_axis(y0, y1, ny, &ylab);
        let place = |index: usize| -> (f64, f64) {
            let (ix, iy) = self.study.coordinates(index);
            let (x, y) = self.study.values(index);
            let x = if x_index { ix as f64 } else { x };
            let y = match &spec.grid.y {
                None => 0.5,
                Some(_) if y_index => iy as f64,
                Some(_) => y,
            };
            (x, y)
        };
        let w = area.dim_in_pixel().0;
        let (plot, side) = area.split_horizontally(w.saturating_sub(300));
        let mut chart = ChartBuilder::on(&plot)
            .caption(title, ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(xl..xh, yl..yh)
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(xlab)
            .y_desc(ylab)
            .draw()
            .map_err(|x| e(&x))?;
        chart
            .draw_series(self.records.iter().zip(colours).map(|(r, c)| {
                let (x, y) = place(r.index);
                Rectangle::new(
                    [(x - 0.5 * dx, y - 0.5 * dy), (x + 0.5 * dx, y + 0.5 * dy)],
                    c.filled(),
                )
            }))
            .map_err(|x| e(&x))?;
        for (k, (name, c)) in legend.iter().enumerate().take(28) {
            let y = 40 + 22 * k as i32;
            side.draw(&Rectangle::new([(10, y), (26, y + 16)], c.filled()))
                .map_err(|x| e(&x))?;
            side.draw(&Text::new(name.clone(), (32, y), ("sans-serif", 15)))
                .map_err(|x| e(&x))?;
        }
        Ok(())
    }
}

/// A chart axis over `n` grid values from `a` to `b`: its range widened by half a cell and
/// the cell width, or, where that range is not finite or its width overflows (plotters
/// computes its tick marks in a loop that never ends on such a range; an axis across most
/// of the f64 range), the grid index instead, said in the label.
fn chart_axis(a: f64, b: f64, n: usize, label: &str) -> ((f64, f64, f64), bool, String) {
    let d = if n > 1 {
        let m = (n - 1) as f64;
        let d = (b - a) / m;
        if d.is_finite() { d } else { b / m - a / m }
    } else {
        1.0
    };
    let (lo, hi) = (a - 0.5 * d, b + 0.5 * d);
    if [d, lo, hi, hi - lo].iter().all(|v| v.is_finite()) && hi > lo {
        ((lo, hi, d), false, label.to_owned())
    } else {
        (
            (-0.5, n as f64 - 0.5, 1.0),
            true,
            format!("{label} (grid index)"),
        )
    }
}

/// A qualitative palette (cycled).
fn palette(k: usize) -> RGBColor {
    const P: [(u8, u8, u8); 10] = [
        (31, 119, 180),
        (255, 127, 14),
        (44, 160, 44),
        (214, 39, 40),
        (148, 103, 189),
        (140, 86, 75),
        (227, 119, 194),
        (188, 189, 34),
        (23, 190, 207),
        (174, 199, 232),
    ];
    let (r, g, b) = P[k % P.len()];
    RGBColor(r, g, b)
}

/// A sequential colour scale on `[0, 1]` (dark blue → green → yellow).
fn ramp(t: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (STOPS.len() - 1) as f64;
    let k = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - k as f64;
    let (a, b) = (STOPS[k], STOPS[k + 1]);
    let mix = |p: f64, q: f64| (p + (q - p) * f).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// DejaVu Sans, bundled with the crate (as in [`crate::output::plot`]).
static FONT_BYTES: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

fn register_font() -> Result<(), String> {
    static DONE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        plotters::style::register_font("sans-serif", plotters::style::FontStyle::Normal, FONT_BYTES)
            .is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err("the bundled font could not be loaded".into())
    }
}
