//! Figures (PNG or SVG, chosen by the file extension) drawn with `plotters`, in the style of
//! the paper's figures.
//!
//! A figure is one or more [`Panel`]s (axes with labels and ranges) holding [`Series`]
//! (lines, dots, stems, bars) and reference lines (the stop). Panels are built by hand or
//! from records:
//!
//! | builder | draws | paper |
//! |---|---|---|
//! | [`bifurcation_panel`] | stroboscopic points $x(2\pi i/\omega)$, intervals $T_j$ or impact velocities against the parameter; increasing sweep red, decreasing green, small dots | Figs. 2c–d, 3, 4 |
//! | [`phase_portrait_panel`] | the orbit $(x, \dot x)$ in mm and mm/s, the stop as a red vertical line, stroboscopic points red, impacts blue | Fig. 8 |
//! | [`time_profile_panel`] | $x(t)$ in mm with the stop as a red horizontal line | Figs. 9a, 10 |
//! | [`Panel::new`] + [`Series`] | any lines, scatter, stems (spectra), bars (histograms) | Figs. 5, 6, 7, 9 |
//!
//! and written by [`render`] (several panels on a grid) or the one-panel shortcuts
//! [`plot_bifurcation`], [`plot_phase_portrait`], [`plot_time_profile`], [`plot_series`].
//!
//! Text is set in DejaVu Sans, bundled with the crate (`assets/fonts/DejaVuSans.ttf`,
//! embedded at compile time and registered with plotters' `ab_glyph` font table as
//! `sans-serif`): figures need no system fonts and look the same everywhere. SVG files
//! name the family `sans-serif` and leave the glyphs to the viewer.
//!
//! ```no_run
//! use nonsmooth::output::plot::{plot_series, Panel, Rgb, Series};
//!
//! let omega: Vec<f64> = (0..100).map(|i| 20.4 + 0.001 * i as f64).collect();
//! let panel = Panel::new("ω [rad/s]", "λ₁ [1/s]")
//!     .with(Series::line(omega.iter().map(|&w| (w, (w - 20.45).sin()))).color(Rgb::RED).label("increasing ω"))
//!     .hline(0.0, Rgb::GRAY);
//! plot_series("out/tle.png", &panel)?;
//! # Ok::<(), nonsmooth::Error>(())
//! ```

use std::ops::Range;
use std::path::Path;
use std::sync::OnceLock;

use plotters::chart::SeriesAnno;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::orbit::Branch;
use crate::sample::{Impact, SectionPoint};
use crate::sweep::{SweepDirection, SweepResult};
use crate::{Error, Result};

/// DejaVu Sans (see `assets/fonts/DejaVuSans-LICENSE.txt`).
static FONT_BYTES: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// The family name under which the bundled font is registered (plotters' default family).
const FAMILY: &str = "sans-serif";

/// Registers the bundled font once.
fn register_font() -> Result<()> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        plotters::style::register_font(FAMILY, FontStyle::Normal, FONT_BYTES).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(Error::Output(
            "the bundled font assets/fonts/DejaVuSans.ttf could not be loaded".into(),
        ))
    }
}

/// An RGB colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Rgb(pub u8, pub u8, pub u8);

impl Rgb {
    /// The paper's red (increasing sweeps, stop line, stroboscopic points).
    pub const RED: Rgb = Rgb(228, 26, 28);
    /// The paper's green (decreasing sweeps).
    pub const GREEN: Rgb = Rgb(0, 160, 0);
    /// Blue (impacts).
    pub const BLUE: Rgb = Rgb(30, 60, 220);
    /// Black (orbits, profiles).
    pub const BLACK: Rgb = Rgb(0, 0, 0);
    /// Gray (reference lines).
    pub const GRAY: Rgb = Rgb(140, 140, 140);
    /// Orange (a third series).
    pub const ORANGE: Rgb = Rgb(255, 127, 0);
    /// Purple (a fourth series).
    pub const PURPLE: Rgb = Rgb(152, 78, 163);

    fn color(self) -> RGBColor {
        RGBColor(self.0, self.1, self.2)
    }
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Mark {
    /// A polyline through the points, `width` pixels wide.
    Line {
        /// Stroke width in pixels.
        width: u32,
    },
    /// Filled dots of the given radius in pixels: single pixels below 1, squares of side
    /// `round(2r)` px below 2, circles above.
    Dots {
        /// Radius in pixels.
        radius: f64,
    },
    /// Vertical stems from `y = 0` to each point (spectra).
    Stems {
        /// Stroke width in pixels.
        width: u32,
    },
    /// Filled bars from `y = 0`, centred on each `x`, `width` wide in data units
    /// (histograms).
    Bars {
        /// Bar width in units of `x`.
        width: f64,
    },
}

/// A data series: points, a mark, a colour and an optional legend label.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend label (`None`: not in the legend).
    pub label: Option<String>,
    /// The points `(x, y)`; non-finite points are skipped (a line is broken there).
    pub points: Vec<(f64, f64)>,
    /// How the points are drawn.
    pub mark: Mark,
    /// Colour.
    pub color: Rgb,
}

impl Series {
    fn new(points: impl IntoIterator<Item = (f64, f64)>, mark: Mark) -> Self {
        Self {
            label: None,
            points: points.into_iter().collect(),
            mark,
            color: Rgb::BLACK,
        }
    }

    /// A black line, 1 px wide.
    pub fn line(points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Self::new(points, Mark::Line { width: 1 })
    }

    /// Black dots of radius 1.5 px.
    pub fn dots(points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Self::new(points, Mark::Dots { radius: 1.5 })
    }

    /// Black stems, 1 px wide.
    pub fn stems(points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Self::new(points, Mark::Stems { width: 1 })
    }

    /// Black bars `width` wide (in units of `x`).
    pub fn bars(points: impl IntoIterator<Item = (f64, f64)>, width: f64) -> Self {
        Self::new(points, Mark::Bars { width })
    }

    /// Sets the colour.
    pub fn color(mut self, color: Rgb) -> Self {
        self.color = color;
        self
    }

    /// Sets the legend label.
    pub fn label(mut self, label: impl Into<String>) -> Self {
        self.label = Some(label.into());
        self
    }

    /// Sets the mark.
    pub fn mark(mut self, mark: Mark) -> Self {
        self.mark = mark;
        self
    }
}

/// Where the legend goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Legend {
    /// Upper left corner.
    UpperLeft,
    /// Upper right corner.
    UpperRight,
    /// Lower left corner.
    LowerLeft,
    /// Lower right corner.
    LowerRight,
}

/// One set of axes: labels, ranges, series and reference lines.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Title above the axes.
    pub title: Option<String>,
    /// Label of the horizontal axis (with units).
    pub x_label: String,
    /// Label of the vertical axis (with units).
    pub y_label: String,
    /// Horizontal range; `None`: the data's range plus a margin.
    pub x_range: Option<(f64, f64)>,
    /// Vertical range; `None`: the data's range plus a margin.
    pub y_range: Option<(f64, f64)>,
    /// Series, drawn in order (later ones on top).
    pub series: Vec<Series>,
    /// Vertical reference lines `x = c`, drawn below the series.
    pub vlines: Vec<(f64, Rgb)>,
    /// Horizontal reference lines `y = c`, drawn below the series.
    pub hlines: Vec<(f64, Rgb)>,
    /// Legend position (`None`: no legend); only labelled series appear.
    pub legend: Option<Legend>,
}

impl Panel {
    /// Empty axes with the given labels; legend in the upper right corner.
    pub fn new(x_label: impl Into<String>, y_label: impl Into<String>) -> Self {
        Self {
            title: None,
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_range: None,
            y_range: None,
            series: Vec::new(),
            vlines: Vec::new(),
            hlines: Vec::new(),
            legend: Some(Legend::UpperRight),
        }
    }

    /// Sets the title.
    pub fn title(mut self, title: impl Into<String>) -> Self {
        self.title = Some(title.into());
        self
    }

    /// Sets the horizontal axis label.
    pub fn x_label(mut self, label: impl Into<String>) -> Self {
        self.x_label = label.into();
        self
    }

    /// Sets the vertical axis label.
    pub fn y_label(mut self, label: impl Into<String>) -> Self {
        self.y_label = label.into();
        self
    }

    /// Fixes the horizontal range.
    pub fn x_range(mut self, lo: f64, hi: f64) -> Self {
        self.x_range = Some((lo, hi));
        self
    }

    /// Fixes the vertical range.
    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = Some((lo, hi));
        self
    }

    /// Adds a series.
    pub fn with(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// Adds a vertical reference line.
    pub fn vline(mut self, x: f64, color: Rgb) -> Self {
        self.vlines.push((x, color));
        self
    }

    /// Adds a horizontal reference line.
    pub fn hline(mut self, y: f64, color: Rgb) -> Self {
        self.hlines.push((y, color));
        self
    }

    /// Sets the legend position (`None`: no legend).
    pub fn legend(mut self, legend: Option<Legend>) -> Self {
        self.legend = legend;
        self
    }

    /// The ranges to draw: fixed ones, or the data's (finite points, reference lines, the
    /// bases of stems and bars) plus 3 % on each side.
    fn ranges(&self) -> (Range<f64>, Range<f64>) {
        let mut bx = Bounds::default();
        let mut by = Bounds::default();
        for s in &self.series {
            for &(x, y) in &s.points {
                if !(x.is_finite() && y.is_finite()) {
                    continue;
                }
                match s.mark {
                    Mark::Bars { width } => {
                        bx.add(x - 0.5 * width);
                        bx.add(x + 0.5 * width);
                        by.add(0.0);
                    }
                    Mark::Stems { .. } => {
                        bx.add(x);
                        by.add(0.0);
                    }
                    _ => bx.add(x),
                }
                by.add(y);
            }
        }
        for &(x, _) in &self.vlines {
            bx.add(x);
        }
        for &(y, _) in &self.hlines {
            by.add(y);
        }
        let x = self.x_range.map_or_else(|| bx.padded(), |(a, b)| fix(a, b));
        let y = self.y_range.map_or_else(|| by.padded(), |(a, b)| fix(a, b));
        (x, y)
    }
}

/// A usable axis range from two numbers (ordered, non-degenerate, finite).
fn fix(a: f64, b: f64) -> Range<f64> {
    let mut bb = Bounds::default();
    bb.add(a);
    bb.add(b);
    let (lo, hi) = bb.get();
    lo..hi
}

#[derive(Debug, Clone, Copy, Default)]
struct Bounds(Option<(f64, f64)>);

impl Bounds {
    fn add(&mut self, v: f64) {
        if v.is_finite() {
            self.0 = Some(match self.0 {
                None => (v, v),
                Some((a, b)) => (a.min(v), b.max(v)),
            });
        }
    }
    /// Ordered, non-degenerate bounds.
    fn get(&self) -> (f64, f64) {
        match self.0 {
            None => (0.0, 1.0),
            Some((a, b)) if b > a => (a, b),
            Some((a, _)) => {
                let d = if a == 0.0 { 1.0 } else { 0.1 * a.abs() };
                (a - d, a + d)
            }
        }
    }
    fn padded(&self) -> Range<f64> {
        let (a, b) = self.get();
        let m = 0.03 * (b - a);
        (a - m)..(b + m)
    }
}

/// How panels are arranged in a figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Panels per row (≥ 1); panels fill rows left to right.
    pub columns: usize,
    /// Size of one panel in pixels (width, height).
    pub panel_size: (u32, u32),
    /// A title over the whole figure.
    pub title: Option<String>,
}

impl Default for Layout {
    /// One column of 900 × 600 px panels, no title.
    fn default() -> Self {
        Self {
            columns: 1,
            panel_size: (900, 600),
            title: None,
        }
    }
}

impl Layout {
    /// `columns` panels per row, each `width × height` pixels.
    pub fn grid(columns: usize, width: u32, height: u32) -> Self {
        Self {
            columns,
            panel_size: (width, height),
            title: None,
        }
    }

    /// Sets the figure title.
    pub fn title(mut self, title: impl Into<String>) -> Self {
        self.title = Some(title.into());
        self
    }
}

/// Height of the figure title band in pixels.
const TITLE_BAND: u32 = 40;

/// Draws `panels` on a grid into `path`: PNG for `.png`, SVG for `.svg` (parent directories
/// are created).
///
/// # Errors
/// [`Error::Output`] (naming the file) for another extension, no panels, a zero panel size,
/// or a failed drawing or write.
pub fn render<P: AsRef<Path>>(path: P, panels: &[Panel], layout: &Layout) -> Result<()> {
    let path = path.as_ref();
    let err = |m: String| Error::Output(format!("{}: {m}", path.display()));
    if panels.is_empty() {
        return Err(err("a figure needs at least one panel".into()));
    }
    let (w, h) = layout.panel_size;
    if w == 0 || h == 0 {
        return Err(err(format!("panel size {w}x{h} is empty")));
    }
    let cols = layout.columns.clamp(1, panels.len());
    let rows = panels.len().div_ceil(cols);
    let band = if layout.title.is_some() {
        TITLE_BAND
    } else {
        0
    };
    let size = (
        w.saturating_mul(cols as u32),
        h.saturating_mul(rows as u32).saturating_add(band),
    );
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("png" | "svg")) {
        return Err(err(
            "unknown figure format: the file name must end in .png or .svg".into(),
        ));
    }
    register_font()?;
    super::create_parent(path)?;
    let grid = (rows, cols);
    let title = layout.title.as_deref();
    match ext.as_deref() {
        Some("png") => draw_figure(
            BitMapBackend::new(path, size).into_drawing_area(),
            panels,
            grid,
            title,
        ),
        _ => draw_figure(
            SVGBackend::new(path, size).into_drawing_area(),
            panels,
            grid,
            title,
        ),
    }
    .map_err(err)
}

/// One panel, 900 × 600 px (see [`render`]).
///
/// # Errors
/// As [`render`].
pub fn plot_series<P: AsRef<Path>>(path: P, panel: &Panel) -> Result<()> {
    render(path, std::slice::from_ref(panel), &Layout::default())
}

fn draw_figure<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    panels: &[Panel],
    grid: (usize, usize),
    title: Option<&str>,
) -> std::result::Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let area = match title {
        Some(t) => root.titled(t, (FAMILY, 26).into_font()).map_err(e)?,
        None => root.clone(),
    };
    for (a, p) in area.split_evenly(grid).iter().zip(panels) {
        draw_panel(a, p)?;
    }
    root.present().map_err(e)
}

/// A panel's chart: linear axes over the panel's ranges.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The legend glyph of a series.
#[derive(Debug, Clone, Copy)]
enum Glyph {
    /// A short line (lines, stems).
    Line,
    /// A dot.
    Dot,
    /// A filled box (bars).
    Bar,
}

fn area_error<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> String {
    e.to_string()
}

fn finite_point(&(x, y): &(f64, f64)) -> bool {
    x.is_finite() && y.is_finite()
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
) -> std::result::Result<(), String> {
    let (xr, yr) = panel.ranges();
    let frame = (xr.start, xr.end, yr.start, yr.end);
    let mut chart = build_chart(area, panel, xr, yr)?;
    draw_reference_lines(&mut chart, panel, frame)?;
    for s in &panel.series {
        draw_one_series(&mut chart, s)?;
    }
    draw_legend(&mut chart, panel)
}

/// The chart over `xr × yr` with its caption, axis labels and ticks.
fn build_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    panel: &Panel,
    xr: Range<f64>,
    yr: Range<f64>,
) -> std::result::Result<Chart<'a, DB>, String> {
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(12)
        .margin_right(24)
        .x_label_area_size(52)
        .y_label_area_size(78);
    if let Some(t) = &panel.title {
        builder.caption(t, (FAMILY, 22).into_font());
    }
    let mut chart = builder.build_cartesian_2d(xr, yr).map_err(area_error)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .axis_desc_style((FAMILY, 19).into_font())
        .label_style((FAMILY, 15).into_font())
        .x_labels(8)
        .y_labels(8)
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .draw()
        .map_err(area_error)?;
    Ok(chart)
}

/// The frame `(x0, x1, y0, y1)` and the panel's vertical and horizontal reference lines.
fn draw_reference_lines<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    panel: &Panel,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
) -> std::result::Result<(), String> {
    // A frame around the plotting area (the mesh draws only the left and bottom axes).
    chart
        .draw_series(std::iter::once(PathElement::new(
            vec![(x0, y1), (x1, y1), (x1, y0)],
            BLACK.stroke_width(1),
        )))
        .map_err(area_error)?;
    for &(x, c) in &panel.vlines {
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(x, y0), (x, y1)],
                c.color().stroke_width(2),
            )))
            .map_err(area_error)?;
    }
    for &(y, c) in &panel.hlines {
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(x0, y), (x1, y)],
                c.color().stroke_width(2),
            )))
            .map_err(area_error)?;
    }
    Ok(())
}

/// One series in its mark, with its legend entry if it has a label.
fn draw_one_series<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    s: &Series,
) -> std::result::Result<(), String> {
    let color = s.color.color();
    let (anno, glyph) = draw_marks(chart, s)?;
    if let Some(label) = &s.label {
        let anno = anno.label(label.as_str());
        match glyph {
            Glyph::Dot => anno.legend(move |(x, y)| Circle::new((x + 10, y), 4, color.filled())),
            Glyph::Bar => anno.legend(move |(x, y)| {
                Rectangle::new([(x + 4, y - 5), (x + 16, y + 5)], color.filled())
            }),
            Glyph::Line => anno.legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            }),
        };
    }
    Ok(())
}

/// Draws the finite points of a series in its mark; returns the series' annotation and
/// its legend glyph.
fn draw_marks<'a, 'c, DB: DrawingBackend>(
    chart: &'c mut Chart<'a, DB>,
    s: &Series,
) -> std::result::Result<(&'c mut SeriesAnno<'a, DB>, Glyph), String> {
    let color = s.color.color();
    let points = s.points.iter().copied().filter(finite_point);
    match s.mark {
        Mark::Line { width } => {
            let style = color.stroke_width(width.max(1));
            let segments = line_segments(&s.points);
            let anno = chart
                .draw_series(segments.into_iter().map(|seg| PathElement::new(seg, style)))
                .map_err(area_error)?;
            Ok((anno, Glyph::Line))
        }
        Mark::Dots { radius } => Ok((draw_dots(chart, &s.points, radius, color)?, Glyph::Dot)),
        Mark::Stems { width } => {
            let style = color.stroke_width(width.max(1));
            let anno = chart
                .draw_series(points.map(|(x, y)| PathElement::new(vec![(x, 0.0), (x, y)], style)))
                .map_err(area_error)?;
            Ok((anno, Glyph::Line))
        }
        Mark::Bars { width } => {
            let anno = chart
                .draw_series(points.map(|(x, y)| {
                    Rectangle::new(
                        [(x - 0.5 * width, 0.0), (x + 0.5 * width, y)],
                        color.filled(),
                    )
                }))
                .map_err(area_error)?;
            Ok((anno, Glyph::Bar))
        }
    }
}

/// The runs of finite points of a line (the line is broken at non-finite points), each
/// non-empty.
fn line_segments(points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let mut segments: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for p in points {
        if finite_point(p) {
            if let Some(last) = segments.last_mut() {
                last.push(*p);
            }
        } else if segments.last().is_some_and(|l| !l.is_empty()) {
            segments.push(Vec::new());
        }
    }
    segments.retain(|s| !s.is_empty());
    segments
}

/// Dots of the given radius in pixels: single pixels below 1, squares of side
/// `round(2r)` px below 2, circles above.
fn draw_dots<'a, 'c, DB: DrawingBackend>(
    chart: &'c mut Chart<'a, DB>,
    points: &[(f64, f64)],
    radius: f64,
    color: RGBColor,
) -> std::result::Result<&'c mut SeriesAnno<'a, DB>, String> {
    let pts = points.iter().copied().filter(finite_point);
    if radius < 1.0 {
        chart
            .draw_series(pts.map(|p| Pixel::new(p, color)))
            .map_err(area_error)
    } else if radius < 2.0 {
        // Small dots as filled squares of side round(2r) px: crisper than
        // rasterized circles, which come out as crosses at this size.
        let side = (2.0 * radius).round() as i32;
        let lo = -(side / 2);
        let hi = lo + side;
        chart
            .draw_series(pts.map(|p| {
                EmptyElement::at(p) + Rectangle::new([(lo, lo), (hi, hi)], color.filled())
            }))
            .map_err(area_error)
    } else {
        chart
            .draw_series(pts.map(|p| Circle::new(p, radius, color.filled())))
            .map_err(area_error)
    }
}

/// The legend box, if the panel has one and a labelled series.
fn draw_legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    panel: &Panel,
) -> std::result::Result<(), String> {
    let Some(pos) = panel.legend else {
        return Ok(());
    };
    if !panel.series.iter().any(|s| s.label.is_some()) {
        return Ok(());
    }
    chart
        .configure_series_labels()
        .position(match pos {
            Legend::UpperLeft => SeriesLabelPosition::UpperLeft,
            Legend::UpperRight => SeriesLabelPosition::UpperRight,
            Legend::LowerLeft => SeriesLabelPosition::LowerLeft,
            Legend::LowerRight => SeriesLabelPosition::LowerRight,
        })
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FAMILY, 15).into_font())
        .draw()
        .map_err(area_error)
}

/// A tick label: short decimal form, no trailing zeros, scientific outside `[1e-3, 1e5)`.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || a < 1e-12 {
        "0".into()
    } else if (1e-3..1e5).contains(&a) {
        let s = format!("{v:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    } else {
        format!("{v:.2e}")
    }
}

/// What a bifurcation diagram shows against the parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Quantity {
    /// The stroboscopic points' component `component`, multiplied by `factor` (e.g. `1e3`
    /// for a position in mm).
    Poincare {
        /// State component.
        component: usize,
        /// Display factor.
        factor: f64,
    },
    /// The inter-impact intervals `T_j` in s.
    Intervals,
    /// The impact velocities, multiplied by `factor`.
    ImpactVelocities {
        /// Display factor.
        factor: f64,
    },
}

impl Quantity {
    /// The position (component 0) in mm.
    pub const POSITION_MM: Quantity = Quantity::Poincare {
        component: 0,
        factor: 1e3,
    };
}

/// A bifurcation diagram of a sweep: one dot per recorded value against the parameter,
/// increasing branch red, decreasing green (drawn on top, in smaller dots, so that both
/// show where they coincide), as in the paper's Figs. 3–4.
/// Labels: `parameter` and the quantity (`x [mm]` for [`Quantity::POSITION_MM`],
/// `Tⱼ [s]`, …); set your own with [`Panel::x_label`] / [`Panel::y_label`]. The horizontal
/// range is the parameter range (also where there are no values, e.g. no impacts); the
/// series are labelled `increasing` / `decreasing` but the legend is off (it would hide
/// dots; turn it on with [`Panel::legend`]).
///
/// # Errors
/// [`Error::Output`] if a Poincaré component is out of range.
pub fn bifurcation_panel<const N: usize>(
    result: &SweepResult<N>,
    quantity: Quantity,
) -> Result<Panel> {
    let y_label = match quantity {
        Quantity::Poincare { component, factor } => {
            if component >= N {
                return Err(Error::Output(format!(
                    "component {component} out of range for a state of dimension {N}"
                )));
            }
            if component == 0 && factor == 1e3 {
                "x(2πi/ω) [mm]".to_string()
            } else if component == 0 && factor == 1.0 {
                "x(2πi/ω) [m]".to_string()
            } else {
                format!("y{component}(2πi/ω) × {factor}")
            }
        }
        Quantity::Intervals => "Tⱼ [s]".to_string(),
        Quantity::ImpactVelocities { factor } => {
            if factor == 1e3 {
                "impact velocity [mm/s]".to_string()
            } else if factor == 1.0 {
                "impact velocity [m/s]".to_string()
            } else {
                format!("impact velocity [m/s] × {factor}")
            }
        }
    };
    // The whole parameter range, also where a quantity has no values (no impacts).
    let mut span = Bounds::default();
    for b in &result.branches {
        for p in &b.points {
            span.add(p.param);
        }
    }
    let (lo, hi) = span.get();
    let margin = 0.01 * (hi - lo);
    let mut panel = Panel::new("parameter", y_label)
        .legend(None)
        .x_range(lo - margin, hi + margin);
    let mut branches: Vec<_> = result.branches.iter().collect();
    // Increasing first, decreasing on top, so that green shows where the branches differ
    // and coincide alike (as in the paper's figures).
    branches.sort_by_key(|b| b.direction != SweepDirection::Up);
    for b in branches {
        let (color, label) = match b.direction {
            SweepDirection::Up => (Rgb::RED, "increasing"),
            SweepDirection::Down => (Rgb::GREEN, "decreasing"),
            SweepDirection::Both => (Rgb::BLACK, "sweep"),
        };
        let mut pts = Vec::new();
        for p in &b.points {
            match quantity {
                Quantity::Poincare { component, factor } => {
                    pts.extend(p.poincare.iter().map(|y| (p.param, y[component] * factor)));
                }
                Quantity::Intervals => pts.extend(p.intervals.iter().map(|&t| (p.param, t))),
                Quantity::ImpactVelocities { factor } => {
                    pts.extend(p.impact_velocities.iter().map(|&v| (p.param, v * factor)));
                }
            }
        }
        // The increasing branch's dots are larger, so that it shows as a red rim where
        // the decreasing branch lies on it.
        let radius = if b.direction == SweepDirection::Up {
            1.6
        } else {
            1.0
        };
        panel = panel.with(
            Series::dots(pts)
                .mark(Mark::Dots { radius })
                .color(color)
                .label(label),
        );
    }
    Ok(panel)
}

/// Writes a one-panel bifurcation diagram (see [`bifurcation_panel`]) with the given
/// parameter label, e.g. `ω [rad/s]`.
///
/// # Errors
/// As [`bifurcation_panel`] and [`render`].
pub fn plot_bifurcation<P: AsRef<Path>, const N: usize>(
    path: P,
    result: &SweepResult<N>,
    quantity: Quantity,
    param_label: &str,
) -> Result<()> {
    let panel = bifurcation_panel(result, quantity)?.x_label(param_label);
    plot_series(path, &panel)
}

/// A phase portrait `(x, ẋ)` in mm and mm/s (the paper's Fig. 8): the orbit `curve` as a
/// black line, the stop `x = stop` (in m) as a red vertical line, the stroboscopic points
/// `poincare` as red dots and the impacts (at the stop, with their impact velocities) as
/// blue dots. States are `(x [m], ẋ [m/s])`.
pub fn phase_portrait_panel(
    curve: &[SectionPoint<f64, 2>],
    poincare: &[SectionPoint<f64, 2>],
    impacts: &[Impact<f64>],
    stop: Option<f64>,
) -> Panel {
    let mm = |p: &SectionPoint<f64, 2>| (p.y[0] * 1e3, p.y[1] * 1e3);
    let mut panel = Panel::new("x [mm]", "ẋ [mm/s]").legend(None);
    if let Some(s) = stop {
        panel = panel.vline(s * 1e3, Rgb::RED);
    }
    panel = panel.with(Series::line(curve.iter().map(mm)).color(Rgb::BLACK));
    if let Some(s) = stop {
        panel = panel.with(
            Series::dots(impacts.iter().map(|i| (s * 1e3, i.velocity * 1e3)))
                .mark(Mark::Dots { radius: 3.5 })
                .color(Rgb::BLUE)
                .label("impacts"),
        );
    }
    panel.with(
        Series::dots(poincare.iter().map(mm))
            .mark(Mark::Dots { radius: 4.0 })
            .color(Rgb::RED)
            .label("t = 2πi/ω"),
    )
}

/// Writes a one-panel phase portrait (see [`phase_portrait_panel`]).
///
/// # Errors
/// As [`render`].
pub fn plot_phase_portrait<P: AsRef<Path>>(
    path: P,
    curve: &[SectionPoint<f64, 2>],
    poincare: &[SectionPoint<f64, 2>],
    impacts: &[Impact<f64>],
    stop: Option<f64>,
) -> Result<()> {
    plot_series(path, &phase_portrait_panel(curve, poincare, impacts, stop))
}

/// A time profile `x(t)` in mm against `t` in s (the paper's Figs. 9a and 10) from samples
/// `(x [m], ẋ [m/s])`, with the stop (in m) as a red horizontal line.
pub fn time_profile_panel(samples: &[SectionPoint<f64, 2>], stop: Option<f64>) -> Panel {
    let mut panel = Panel::new("t [s]", "x [mm]").legend(None);
    if let Some(s) = stop {
        panel = panel.hline(s * 1e3, Rgb::RED);
    }
    panel.with(Series::line(samples.iter().map(|p| (p.t, p.y[0] * 1e3))).color(Rgb::BLACK))
}

/// Writes a one-panel time profile (see [`time_profile_panel`]).
///
/// # Errors
/// As [`render`].
pub fn plot_time_profile<P: AsRef<Path>>(
    path: P,
    samples: &[SectionPoint<f64, 2>],
    stop: Option<f64>,
) -> Result<()> {
    plot_series(path, &time_profile_panel(samples, stop))
}

/// A continued branch ([`crate::orbit::follow`]) as series of component `component` of
/// the orbit's section state over the parameter: stable stretches as solid lines,
/// unstable stretches as dashed lines, bifurcations as large dots, in `color`.
pub fn branch_series<const N: usize>(
    branch: &Branch<N>,
    component: usize,
    color: Rgb,
) -> Vec<Series> {
    let mut out = Vec::new();
    let mut start = 0;
    let points = &branch.points;
    for i in 1..=points.len() {
        if i == points.len() || points[i].stable != points[start].stable {
            // Each stretch includes the next point so the curve is unbroken.
            let end = (i + 1).min(points.len());
            let xy = points[start..end]
                .iter()
                .map(|q| (q.p, q.state.get(component).copied().unwrap_or(f64::NAN)));
            let series = if points[start].stable {
                Series::line(xy).mark(Mark::Line { width: 2 })
            } else {
                Series::line(dashed(&xy.collect::<Vec<_>>())).mark(Mark::Line { width: 1 })
            };
            out.push(series.color(color));
            start = i;
        }
    }
    if !branch.bifurcations.is_empty() {
        out.push(
            Series::dots(
                branch
                    .bifurcations
                    .iter()
                    .map(|b| (b.p, b.state.get(component).copied().unwrap_or(f64::NAN))),
            )
            .mark(Mark::Dots { radius: 4.0 })
            .color(color),
        );
    }
    out
}

/// A polyline cut into dashes: each segment in six parts, every other one drawn (the gaps
/// are non-finite points, which break a line series).
fn dashed(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for w in points.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        for k in (0..6).step_by(2) {
            let (a, b) = (k as f64 / 6.0, (k + 1) as f64 / 6.0);
            out.push((x0 + a * (x1 - x0), y0 + a * (y1 - y0)));
            out.push((x0 + b * (x1 - x0), y0 + b * (y1 - y0)));
            out.push((f64::NAN, f64::NAN));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_segments_break_at_non_finite_points() {
        let nan = f64::NAN;
        let pts = [
            (nan, 0.0),
            (0.0, 1.0),
            (1.0, 2.0),
            (2.0, f64::INFINITY),
            (3.0, nan),
            (4.0, 5.0),
            (nan, nan),
        ];
        assert_eq!(
            line_segments(&pts),
            vec![vec![(0.0, 1.0), (1.0, 2.0)], vec![(4.0, 5.0)]]
        );
        assert!(line_segments(&[(nan, 1.0)]).is_empty());
    }

    #[test]
    fn ranges_and_ticks() {
        let p = Panel::new("x", "y").with(Series::line([(0.0, 1.0), (10.0, 3.0), (f64::NAN, 1e9)]));
        let (x, y) = p.ranges();
        assert!((x.start + 0.3).abs() < 1e-12 && (x.end - 10.3).abs() < 1e-12);
        assert!((y.start - 0.94).abs() < 1e-12 && (y.end - 3.06).abs() < 1e-12);
        // Bars and stems include y = 0; a degenerate range is widened.
        let p = Panel::new("x", "y").with(Series::bars([(1.0, 2.0)], 0.5));
        let (x, y) = p.ranges();
        assert!(x.start < 0.75 && x.end > 1.25 && y.start < 0.0 && y.end > 2.0);
        let p = Panel::new("x", "y").with(Series::dots([(5.0, 5.0)]));
        let (x, _) = p.ranges();
        assert!(x.start < 5.0 && x.end > 5.0);
        assert_eq!(fix(2.0, 1.0), 1.0..2.0);
        assert_eq!(tick(0.0), "0");
        assert_eq!(tick(20.5), "20.5");
        assert_eq!(tick(-2.08), "-2.08");
        assert_eq!(tick(1e-6), "1.00e-6");
    }
}
