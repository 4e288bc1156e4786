//! Figures: line plots and heatmaps written as PNG and SVG.
//!
//! Rendering uses `plotters` without system font libraries: text is rasterised by `ab_glyph`
//! from DejaVu Sans, embedded from `assets/fonts/` and registered as "sans-serif" on first use.
//! The SVG files name the family "sans-serif" and leave glyphs to the viewer.
//!
//! Every figure is written twice, `STEM.png` and `STEM.svg`, each first to a temporary file in
//! the same folder and then renamed over the target, so a reader never sees half a file. The
//! bytes depend only on the inputs: ticks, colours and legend placement are computed here
//! without clocks, hashing or randomness, which the tests check by rendering twice.
//!
//! Each family draws its own figures on these primitives (`family::*::plot`).

mod colormap;
pub mod ticks;
pub mod user;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};
use ticks::Ticks;

/// Errors of the plotting functions; each names the file concerned.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    #[error("the embedded font assets/fonts/DejaVuSans.ttf could not be loaded")]
    Font,
    #[error("{path}: {message}")]
    Draw { path: PathBuf, message: String },
    /// (The source is the next link of the error chain: `{:#}` prints "path: source".)
    #[error("{path}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}")]
    Json {
        path: PathBuf,
        #[source]
        source: serde_json::Error,
    },
    #[error("{path}: invalid plot data: {message}")]
    Data { path: PathBuf, message: String },
}

impl PlotError {
    /// The file the error is about (none for the font).
    pub fn path(&self) -> Option<&Path> {
        match self {
            PlotError::Font => None,
            PlotError::Draw { path, .. } | PlotError::Io { path, .. } | PlotError::Json { path, .. } | PlotError::Data { path, .. } => Some(path),
        }
    }
}

/// The house style of a chart's axes: dark axis lines, tick labels and descriptions in the
/// embedded font, and the two descriptions.
pub fn axes_style<'m, 'a, 'b, X: Ranged, Y: Ranged, DB: DrawingBackend>(
    mesh: &'m mut plotters::chart::MeshStyle<'a, 'b, X, Y, DB>,
    x_desc: &str,
    y_desc: &str,
) -> &'m mut plotters::chart::MeshStyle<'a, 'b, X, Y, DB> {
    mesh.axis_style(RGBColor(60, 60, 60))
        .label_style((FONT_FAMILY, LABEL_SIZE))
        .axis_desc_style((FONT_FAMILY, DESC_SIZE))
        .x_desc(x_desc)
        .y_desc(y_desc)
}

/// How one series of a line plot is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SeriesStyle {
    /// Solid line through the points in order.
    Line,
    /// Dashed line through the points in order.
    Dashed,
    /// A small filled circle at each point.
    Points,
}

/// One labelled series of a line plot. An empty label keeps it out of the legend; a labelled
/// series without points is a legend key only (e.g. saying what a line style stands for).
#[derive(Clone, Debug)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub style: SeriesStyle,
    /// Index into the tab10 palette; `None` takes the series' position in the plot.
    pub color: Option<usize>,
}

impl Series {
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>, style: SeriesStyle) -> Self {
        Self { label: label.into(), points, style, color: None }
    }

    /// The same series drawn in tab10 colour `index` (mod 10), so that series belonging
    /// together (a quantity and its fits at one parameter value) share a colour.
    pub fn color(mut self, index: usize) -> Self {
        self.color = Some(index);
        self
    }

    /// The same series in the colour of an RGB channel ("red", "green" or "blue": tab10's red,
    /// green and blue), whatever its position in the plot; other names keep the position's.
    pub fn channel(self, name: &str) -> Self {
        match name {
            "red" => self.color(3),
            "green" => self.color(2),
            "blue" => self.color(0),
            _ => self,
        }
    }
}

/// One panel of [`grid_of_heatmaps`]: its title and its values (same layout as [`heatmap`]).
#[derive(Clone, Copy, Debug)]
pub struct Panel<'a> {
    pub title: &'a str,
    pub values: &'a [f64],
}

pub const FONT_FAMILY: &str = "sans-serif";
const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

pub const TITLE_SIZE: u32 = 26;
const PANEL_TITLE_SIZE: u32 = 21;
const LABEL_SIZE: u32 = 17;
const DESC_SIZE: u32 = 20;
const LEGEND_SIZE: u32 = 17;

/// tab10 (matplotlib's default cycle), for series in order.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

fn ensure_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| plotters::style::register_font(FONT_FAMILY, FontStyle::Normal, FONT).is_ok());
    if ok { Ok(()) } else { Err(PlotError::Font) }
}

/// `stem` with `.ext` appended (not substituted: stems may contain dots, as in "alpha_0.15").
fn with_ext(stem: &Path, ext: &str) -> PathBuf {
    let mut s: OsString = stem.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

/// A temporary sibling of `target` that keeps its extension (the PNG encoder picks the
/// format from it) and is unique within this process.
fn temp_sibling(target: &Path, ext: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = target.file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    target.with_file_name(format!(".{name}.{}-{n}.tmp.{ext}", std::process::id()))
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> PlotError + '_ {
    move |source| PlotError::Io { path: path.to_path_buf(), source }
}

/// Drawing errors carried as text until the file they belong to is known.
pub type DrawResult = Result<(), String>;

pub fn de<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// A figure that can be drawn on any plotters backend.
pub trait Figure {
    fn size(&self) -> (u32, u32);
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult;
}

/// Renders `fig` to STEM.png and STEM.svg (temporary file, then rename) and returns both paths.
pub fn write_figure(stem: &Path, fig: &impl Figure) -> Result<Vec<PathBuf>, PlotError> {
    ensure_font()?;
    if let Some(dir) = stem.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(io_err(dir))?;
    }
    let png = with_ext(stem, "png");
    let svg = with_ext(stem, "svg");

    let tmp = temp_sibling(&png, "png");
    let drawn = (|| -> DrawResult {
        let root = BitMapBackend::new(&tmp, fig.size()).into_drawing_area();
        fig.draw(&root)?;
        root.present().map_err(de)
    })();
    let renamed = drawn
        .map_err(|message| PlotError::Draw { path: png.clone(), message })
        .and_then(|()| std::fs::rename(&tmp, &png).map_err(io_err(&png)));
    if let Err(e) = renamed {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }

    let mut text = String::new();
    (|| -> DrawResult {
        let root = SVGBackend::with_string(&mut text, fig.size()).into_drawing_area();
        fig.draw(&root)?;
        root.present().map_err(de)
    })()
    .map_err(|message| PlotError::Draw { path: svg.clone(), message })?;
    let tmp = temp_sibling(&svg, "svg");
    let written = std::fs::write(&tmp, text.as_bytes())
        .map_err(io_err(&tmp))
        .and_then(|()| std::fs::rename(&tmp, &svg).map_err(io_err(&svg)));
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    Ok(vec![png, svg])
}

pub fn data_err(stem: &Path, message: impl Into<String>) -> PlotError {
    PlotError::Data { path: stem.to_path_buf(), message: message.into() }
}

// ---------------------------------------------------------------------------------------------
// Line plots

/// Line plot of `series` written to STEM.png and STEM.svg. With `log_y` the y axis is
/// logarithmic and points with y ≤ 0 (or non-finite) are left out; non-finite points are left
/// out in any case. Series take the tab10 colours in order; labelled ones enter a legend put in
/// the first corner (upper right, upper left, lower right, lower left) where it covers no data,
/// or, if there is none, above the data in headroom added to the y axis. Series with no
/// points are legend keys only; at least one series must have a plottable point.
pub fn line_plot(
    path_stem: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    log_y: bool,
) -> Result<Vec<PathBuf>, PlotError> {
    let ty = |y: f64| if log_y { y.log10() } else { y };
    let kept: Vec<Vec<(f64, f64)>> = series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .filter(|(x, y)| x.is_finite() && y.is_finite() && (!log_y || *y > 0.0))
                .map(|&(x, y)| (x, ty(y)))
                .collect()
        })
        .collect();
    let all = || kept.iter().flatten();
    if all().next().is_none() {
        return Err(data_err(path_stem, "no finite points to plot"));
    }
    let x = padded(min_max(all().map(|p| p.0)), 0.0);
    let y = if log_y {
        let (a, b) = min_max(all().map(|p| p.1));
        let (lo, hi) = (a.floor(), b.ceil());
        (lo, if hi > lo { hi } else { lo + 1.0 })
    } else {
        padded(min_max(all().map(|p| p.1)), 0.04)
    };
    let fig = LineFigure { title, x_label, y_label, series, kept, x, y, log_y };
    write_figure(path_stem, &fig)
}

pub fn min_max(it: impl Iterator<Item = f64>) -> (f64, f64) {
    it.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)))
}

/// Range widened by `frac` of its span on each side; a degenerate range gets a unit-ish width.
pub fn padded((lo, hi): (f64, f64), frac: f64) -> (f64, f64) {
    if hi > lo {
        let pad = (hi - lo) * frac;
        (lo - pad, hi + pad)
    } else {
        let w = if lo == 0.0 { 1.0 } else { lo.abs() * 0.1 };
        (lo - w, hi + w)
    }
}

struct LineFigure<'a> {
    title: &'a str,
    x_label: &'a str,
    y_label: &'a str,
    series: &'a [Series],
    /// Finite points of each series, y already in axis coordinates (log10 on a log axis).
    kept: Vec<Vec<(f64, f64)>>,
    x: (f64, f64),
    /// Data extent of y (padded, or whole decades on a log axis), before legend headroom.
    y: (f64, f64),
    log_y: bool,
}

const LINE_MARGIN: u32 = 18;
const LINE_X_LABEL_AREA: u32 = 58;
const LEGEND_MARGIN: u32 = 12;
const LEGEND_GLYPH_AREA: u32 = 34;
/// plotters insets the legend box this far from the plotting area's edges.
const LEGEND_INSET: u32 = 5;

impl LineFigure<'_> {
    fn y_ticks(&self, (lo, hi): (f64, f64)) -> Ticks {
        if self.log_y { ticks::log_decades(lo.ceil() as i32, hi.floor() as i32) } else { ticks::linear(lo, hi, 7) }
    }

    /// Legend box size in pixels (as plotters lays it out), if any series is labelled.
    fn legend_size(&self) -> Option<(u32, u32)> {
        let labels: Vec<&str> = self.series.iter().map(|s| s.label.as_str()).filter(|l| !l.is_empty()).collect();
        if labels.is_empty() {
            return None;
        }
        let text_w = labels.iter().map(|l| text_width(l, LEGEND_SIZE)).max().unwrap_or(0);
        let line_h = (LEGEND_SIZE as f64 / 1.24 * 1.25).ceil() as u32;
        Some((text_w + LEGEND_GLYPH_AREA + 2 * LEGEND_MARGIN, labels.len() as u32 * line_h + 2 * LEGEND_MARGIN))
    }

    /// How many data points (lines sampled between points too) a legend box of `size` pixels at
    /// `corner` would cover, for a plotting area of `plot` pixels and y range `y`.
    fn covered(&self, corner: (bool, bool), size: (u32, u32), plot: (u32, u32), y: (f64, f64)) -> usize {
        let (right, upper) = corner;
        let pad = 6.0;
        let (w, h) = ((size.0 + LEGEND_INSET) as f64 + pad, (size.1 + LEGEND_INSET) as f64 + pad);
        let (pw, ph) = (plot.0 as f64, plot.1 as f64);
        let inside = |(px, py): (f64, f64)| {
            let u = (px - self.x.0) / (self.x.1 - self.x.0) * pw;
            let v = (y.1 - py) / (y.1 - y.0) * ph; // pixels from the top
            let in_x = if right { u >= pw - w } else { u <= w };
            let in_y = if upper { v <= h } else { v >= ph - h };
            in_x && in_y
        };
        let mut n = 0;
        for (s, pts) in self.series.iter().zip(&self.kept) {
            n += pts.iter().filter(|&&p| inside(p)).count();
            if s.style != SeriesStyle::Points {
                for w in pts.windows(2) {
                    n += (1..8)
                        .map(|k| {
                            let t = k as f64 / 8.0;
                            (w[0].0 + (w[1].0 - w[0].0) * t, w[0].1 + (w[1].1 - w[0].1) * t)
                        })
                        .filter(|&p| inside(p))
                        .count();
                }
            }
        }
        n
    }

    /// Legend corner and final y range for a plotting area of `plot` pixels.
    fn layout(&self, plot: (u32, u32)) -> (Option<SeriesLabelPosition>, (f64, f64)) {
        let Some(size) = self.legend_size() else { return (None, self.y) };
        let corners = [
            (SeriesLabelPosition::UpperRight, (true, true)),
            (SeriesLabelPosition::UpperLeft, (false, true)),
            (SeriesLabelPosition::LowerRight, (true, false)),
            (SeriesLabelPosition::LowerLeft, (false, false)),
        ];
        for (pos, corner) in &corners {
            if self.covered(*corner, size, plot, self.y) == 0 {
                return (Some(pos.clone()), self.y);
            }
        }
        // Headroom: stretch the top so the data stays below the legend band.
        let band = ((size.1 + LEGEND_INSET + 8) as f64 / plot.1.max(1) as f64).min(0.6);
        let (lo, hi) = self.y;
        let y = (lo, lo + (hi - lo) / (1.0 - band));
        let pos = if self.covered((true, true), size, plot, y) <= self.covered((false, true), size, plot, y) {
            SeriesLabelPosition::UpperRight
        } else {
            SeriesLabelPosition::UpperLeft
        };
        (Some(pos), y)
    }
}

impl Figure for LineFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (1000, 640)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        root.fill(&WHITE).map_err(de)?;
        let body = root.margin(8, 0, 0, 0).titled(self.title, (FONT_FAMILY, TITLE_SIZE)).map_err(de)?;
        let x_ticks = ticks::linear(self.x.0, self.x.1, 8);
        // The y tick labels' width depends on the range only weakly; size the label area from
        // the data range's labels plus slack for a longer label after headroom.
        let y_label_area = label_width(&self.y_ticks(self.y)) + 12 + 44;
        let (bw, bh) = body.dim_in_pixel();
        let plot =
            (bw.saturating_sub(2 * LINE_MARGIN + y_label_area), bh.saturating_sub(2 * LINE_MARGIN + LINE_X_LABEL_AREA));
        let (legend, y) = self.layout(plot);
        let y_ticks = self.y_ticks(y);
        let mut chart = ChartBuilder::on(&body)
            .margin(LINE_MARGIN)
            .x_label_area_size(LINE_X_LABEL_AREA)
            .y_label_area_size(y_label_area)
            .build_cartesian_2d(Axis::new(self.x, &x_ticks), Axis::new(y, &y_ticks))
            .map_err(de)?;
        let xf = |v: &f64| x_ticks.label(*v);
        let yf = |v: &f64| y_ticks.label(*v);
        axes_style(
            chart.configure_mesh().bold_line_style(RGBColor(222, 222, 222)).light_line_style(RGBColor(242, 242, 242)),
            self.x_label,
            self.y_label,
        )
        .x_label_formatter(&xf)
            .y_label_formatter(&yf)
            .draw()
            .map_err(de)?;

        for (i, (s, pts)) in self.series.iter().zip(&self.kept).enumerate() {
            let color = PALETTE[s.color.unwrap_or(i) % PALETTE.len()];
            let line = ShapeStyle { color: color.to_rgba(), filled: false, stroke_width: 2 };
            let anno = match s.style {
                SeriesStyle::Line => chart.draw_series(LineSeries::new(pts.iter().copied(), line)),
                SeriesStyle::Dashed => chart.draw_series(DashedLineSeries::new(pts.iter().copied(), 9, 6, line)),
                SeriesStyle::Points => {
                    chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, ShapeStyle { filled: true, ..line })))
                }
            }
            .map_err(de)?;
            if !s.label.is_empty() {
                let style = s.style;
                anno.label(s.label.as_str()).legend(move |(x, y)| -> DynElement<'static, DB, (i32, i32)> {
                    match style {
                        SeriesStyle::Line => PathElement::new(vec![(x, y), (x + 26, y)], line).into_dyn(),
                        SeriesStyle::Dashed => {
                            plotters::element::DashedPathElement::new(vec![(x, y), (x + 26, y)], 8, 5, line).into_dyn()
                        }
                        SeriesStyle::Points => {
                            Circle::new((x + 13, y), 4, ShapeStyle { filled: true, ..line }).into_dyn()
                        }
                    }
                });
            }
        }
        if let Some(position) = legend {
            chart
                .configure_series_labels()
                .position(position)
                .margin(LEGEND_MARGIN)
                .legend_area_size(LEGEND_GLYPH_AREA)
                .label_font((FONT_FAMILY, LEGEND_SIZE))
                .background_style(WHITE.mix(0.9))
                .border_style(RGBColor(160, 160, 160))
                .draw()
                .map_err(de)?;
        }
        Ok(())
    }
}

/// A linear f64 axis whose ticks are ours (plotters' own key points are replaced), labelled
/// through the mesh's label formatter.
pub struct Axis {
    inner: plotters::coord::types::RangedCoordf64,
    ticks: Vec<f64>,
    minor: Vec<f64>,
}

impl Axis {
    pub fn new((lo, hi): (f64, f64), ticks: &Ticks) -> Self {
        Self { inner: (lo..hi).into(), ticks: ticks.values.clone(), minor: ticks.minor.clone() }
    }
}

impl Ranged for Axis {
    type ValueType = f64;
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;

    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<H: plotters::coord::ranged1d::KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() { self.minor.clone() } else { self.ticks.clone() }
    }
}

/// Width in pixels of `text` in the embedded font at `size` (a rough estimate if the font
/// cannot lay it out).
fn text_width(text: &str, size: u32) -> u32 {
    (FONT_FAMILY, size as f64)
        .into_font()
        .box_size(text)
        .map(|(w, _)| w)
        .unwrap_or(text.chars().count() as u32 * size * 6 / 10)
}

/// Pixel width of the widest tick label, to size the label area.
pub fn label_width(t: &Ticks) -> u32 {
    t.values.iter().map(|&v| text_width(&t.label(v), LABEL_SIZE)).max().unwrap_or(0)
}

// ---------------------------------------------------------------------------------------------
// Heatmaps

/// Heatmap of `values` over the grid `xs` × `ys` (`values[j * xs.len() + i]` at `(xs[i], ys[j])`,
/// x fastest) with a colour bar, written to STEM.png and STEM.svg. Grid coordinates must
/// increase strictly; each value fills the cell reaching halfway to its neighbours. The colour
/// range is the finite values' [min, max] on a viridis map or, if `diverging`, [−m, m] with
/// m = max |value| on a blue–white–red map for signed errors. Non-finite values are grey.
#[allow(clippy::too_many_arguments)]
pub fn heatmap(
    path_stem: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    xs: &[f64],
    ys: &[f64],
    values: &[f64],
    colorbar_label: &str,
    diverging: bool,
) -> Result<Vec<PathBuf>, PlotError> {
    heatmap_with_range(path_stem, title, x_label, y_label, xs, ys, values, colorbar_label, diverging, None)
}

/// [`heatmap`] with the colour range fixed to `range` = (lo, hi) when given (values outside it
/// take the end colours), so that several figures share one scale.
#[allow(clippy::too_many_arguments)]
pub fn heatmap_with_range(
    path_stem: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    xs: &[f64],
    ys: &[f64],
    values: &[f64],
    colorbar_label: &str,
    diverging: bool,
    range: Option<(f64, f64)>,
) -> Result<Vec<PathBuf>, PlotError> {
    let panels = [Panel { title: "", values }];
    let fig =
        HeatmapFigure::new(path_stem, title, x_label, y_label, xs, ys, &panels, 1, colorbar_label, diverging, range)?;
    write_figure(path_stem, &fig)
}

/// Panels of heatmaps on one grid `xs` × `ys`, `columns` per row, sharing one colour range
/// (computed over all panels as in [`heatmap`], or `range` when given) and one colour bar:
/// e.g. 2×2 or 1×N comparisons of a quantity and its approximation.
#[allow(clippy::too_many_arguments)]
pub fn grid_of_heatmaps(
    path_stem: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    xs: &[f64],
    ys: &[f64],
    panels: &[Panel<'_>],
    columns: usize,
    colorbar_label: &str,
    diverging: bool,
    range: Option<(f64, f64)>,
) -> Result<Vec<PathBuf>, PlotError> {
    let fig = HeatmapFigure::new(
        path_stem,
        title,
        x_label,
        y_label,
        xs,
        ys,
        panels,
        columns,
        colorbar_label,
        diverging,
        range,
    )?;
    write_figure(path_stem, &fig)
}

/// Symmetric range [−m, m], m = max |v| over the finite values (1 if there are none or all are 0).
pub fn symmetric_range<'a>(values: impl IntoIterator<Item = &'a f64>) -> (f64, f64) {
    let m = values.into_iter().filter(|v| v.is_finite()).fold(0.0_f64, |m, v| m.max(v.abs()));
    let m = if m > 0.0 { m } else { 1.0 };
    (-m, m)
}

/// Cell boundaries around strictly increasing centres: midpoints, ends extended by half a step.
pub fn cell_edges(c: &[f64]) -> Vec<f64> {
    if c.len() == 1 {
        return vec![c[0] - 0.5, c[0] + 0.5];
    }
    let n = c.len();
    let mut e = Vec::with_capacity(n + 1);
    e.push(c[0] - 0.5 * (c[1] - c[0]));
    e.extend(c.windows(2).map(|w| 0.5 * (w[0] + w[1])));
    e.push(c[n - 1] + 0.5 * (c[n - 1] - c[n - 2]));
    e
}

struct HeatmapFigure<'a> {
    title: &'a str,
    x_label: &'a str,
    y_label: &'a str,
    panels: &'a [Panel<'a>],
    columns: usize,
    rows: usize,
    colorbar_label: &'a str,
    diverging: bool,
    range: (f64, f64),
    x_edges: Vec<f64>,
    y_edges: Vec<f64>,
    x_ticks: Ticks,
    y_ticks: Ticks,
    bar_ticks: Ticks,
}

const BAR_WIDTH: u32 = 26;
const BAR_GAP: u32 = 14;

impl<'a> HeatmapFigure<'a> {
    #[allow(clippy::too_many_arguments)]
    fn new(
        stem: &Path,
        title: &'a str,
        x_label: &'a str,
        y_label: &'a str,
        xs: &'a [f64],
        ys: &'a [f64],
        panels: &'a [Panel<'a>],
        columns: usize,
        colorbar_label: &'a str,
        diverging: bool,
        range: Option<(f64, f64)>,
    ) -> Result<Self, PlotError> {
        let increasing =
            |c: &[f64]| !c.is_empty() && c.iter().all(|v| v.is_finite()) && c.windows(2).all(|w| w[0] < w[1]);
        if !increasing(xs) || !increasing(ys) {
            return Err(data_err(stem, "grid coordinates must be finite and strictly increasing"));
        }
        if panels.is_empty() || columns == 0 {
            return Err(data_err(stem, "no panels"));
        }
        for p in panels {
            if p.values.len() != xs.len() * ys.len() {
                return Err(data_err(stem, format!("{} values for a {}×{} grid", p.values.len(), xs.len(), ys.len())));
            }
        }
        let all = || panels.iter().flat_map(|p| p.values.iter()).filter(|v| v.is_finite());
        let range = match range {
            Some((lo, hi)) if lo.is_finite() && hi.is_finite() && lo < hi => (lo, hi),
            Some(r) => return Err(data_err(stem, format!("invalid colour range {r:?}"))),
            None if all().next().is_none() => return Err(data_err(stem, "no finite values")),
            None if diverging => symmetric_range(all()),
            None => padded(min_max(all().copied()), 0.0),
        };
        let x_edges = cell_edges(xs);
        let y_edges = cell_edges(ys);
        let x_ticks = ticks::linear(x_edges[0], x_edges[x_edges.len() - 1], 5);
        let y_ticks = ticks::linear(y_edges[0], y_edges[y_edges.len() - 1], 5);
        Ok(Self {
            title,
            x_label,
            y_label,
            panels,
            columns: columns.min(panels.len()),
            rows: panels.len().div_ceil(columns.min(panels.len())),
            colorbar_label,
            diverging,
            range,
            x_edges,
            y_edges,
            x_ticks,
            y_ticks,
            bar_ticks: ticks::linear(range.0, range.1, 8),
        })
    }

    /// Width of the colour bar column: gap, bar, tick labels, rotated description.
    fn bar_area(&self) -> u32 {
        BAR_GAP + BAR_WIDTH + self.bar_label_area()
    }

    fn bar_label_area(&self) -> u32 {
        let desc = if self.colorbar_label.is_empty() { 0 } else { DESC_SIZE + 16 };
        label_width(&self.bar_ticks) + 14 + desc + 8
    }

    fn color(&self, v: f64) -> RGBColor {
        colormap::color((v - self.range.0) / (self.range.1 - self.range.0), self.diverging)
    }
}

impl Figure for HeatmapFigure<'_> {
    fn size(&self) -> (u32, u32) {
        let (pw, ph) = if self.panels.len() == 1 { (660, 600) } else { (520, 490) };
        (self.columns as u32 * pw + self.bar_area(), 72 + self.rows as u32 * ph)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        root.fill(&WHITE).map_err(de)?;
        let body = root.margin(8, 0, 0, 0).titled(self.title, (FONT_FAMILY, TITLE_SIZE)).map_err(de)?;
        let (w, _) = body.dim_in_pixel();
        let (plots, bar) = body.split_horizontally(w.saturating_sub(self.bar_area()));
        let cells = plots.split_evenly((self.rows, self.columns));
        let nx = self.x_edges.len() - 1;
        let xf = |v: &f64| self.x_ticks.label(*v);
        let yf = |v: &f64| self.y_ticks.label(*v);
        let (mut top, mut bottom) = (i32::MAX, i32::MIN);
        for (area, panel) in cells.iter().zip(self.panels) {
            let mut builder = ChartBuilder::on(area);
            builder.margin(12).x_label_area_size(58).y_label_area_size(label_width(&self.y_ticks) + 12 + 44);
            if !panel.title.is_empty() {
                builder.caption(panel.title, (FONT_FAMILY, PANEL_TITLE_SIZE));
            }
            let (x0, x1) = (self.x_edges[0], self.x_edges[nx]);
            let (y0, y1) = (self.y_edges[0], self.y_edges[self.y_edges.len() - 1]);
            let mut chart = builder
                .build_cartesian_2d(Axis::new((x0, x1), &self.x_ticks), Axis::new((y0, y1), &self.y_ticks))
                .map_err(de)?;
            chart
                .draw_series(panel.values.iter().enumerate().map(|(k, &v)| {
                    let (i, j) = (k % nx, k / nx);
                    Rectangle::new(
                        [(self.x_edges[i], self.y_edges[j]), (self.x_edges[i + 1], self.y_edges[j + 1])],
                        self.color(v).filled(),
                    )
                }))
                .map_err(de)?;
            axes_style(chart.configure_mesh().disable_mesh(), self.x_label, self.y_label)
                .x_label_formatter(&xf)
                .y_label_formatter(&yf)
                .draw()
                .map_err(de)?;
            let (_, yr) = chart.plotting_area().get_pixel_range();
            top = top.min(yr.start);
            bottom = bottom.max(yr.end);
        }

        // Colour bar, spanning the panels' plotting areas vertically.
        let (_, by) = bar.get_pixel_range();
        let (lo, hi) = self.range;
        let mut chart = ChartBuilder::on(&bar)
            .margin_top((top - by.start).max(0) as u32)
            .margin_bottom((by.end - bottom).max(0) as u32)
            .margin_left(BAR_GAP)
            .set_label_area_size(LabelAreaPosition::Right, self.bar_label_area())
            .build_cartesian_2d(0.0..1.0, Axis::new((lo, hi), &self.bar_ticks))
            .map_err(de)?;
        const STRIPS: usize = 256;
        chart
            .draw_series((0..STRIPS).map(|k| {
                let a = lo + (hi - lo) * k as f64 / STRIPS as f64;
                let b = lo + (hi - lo) * (k + 1) as f64 / STRIPS as f64;
                let t = (k as f64 + 0.5) / STRIPS as f64;
                Rectangle::new([(0.0, a), (1.0, b)], colormap::color(t, self.diverging).filled())
            }))
            .map_err(de)?;
        chart.draw_series(std::iter::once(Rectangle::new([(0.0, lo), (1.0, hi)], RGBColor(60, 60, 60)))).map_err(de)?;
        let bf = |v: &f64| self.bar_ticks.label(*v);
        chart
            .configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .set_all_tick_mark_size(6)
            .axis_style(RGBColor(60, 60, 60))
            .label_style((FONT_FAMILY, LABEL_SIZE))
            .y_label_formatter(&bf)
            .draw()
            .map_err(de)?;
        // The description, drawn here rather than by the mesh (which puts a right-hand
        // description at the outer edge, partly outside the figure): rotated to read upwards,
        // centred beside the tick labels.
        if !self.colorbar_label.is_empty() {
            let (xr, yr) = chart.plotting_area().get_pixel_range();
            let x = xr.end + 14 + label_width(&self.bar_ticks) as i32 + 12 + DESC_SIZE as i32 / 2;
            let style = TextStyle::from((FONT_FAMILY, DESC_SIZE).into_font())
                .transform(FontTransform::Rotate270)
                .pos(Pos::new(HPos::Center, VPos::Center));
            root.draw(&Text::new(self.colorbar_label, (x, (yr.start + yr.end) / 2), style)).map_err(de)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn render_both(dir: &Path) -> Vec<PathBuf> {
        let xs: Vec<f64> = (0..=40).map(|i| i as f64 / 40.0).collect();
        let series = vec![
            Series::new("x²", xs.iter().map(|&x| (x, x * x)).collect(), SeriesStyle::Line),
            Series::new("x³ (dashed)", xs.iter().map(|&x| (x, x * x * x)).collect(), SeriesStyle::Dashed),
            Series::new("samples", xs.iter().step_by(5).map(|&x| (x, 0.5 * x)).collect(), SeriesStyle::Points),
        ];
        let mut out = line_plot(&dir.join("line"), "Test ‖n‖ plot", "x", "y", &series, false).unwrap();
        let log_series = vec![Series::new(
            "1e-6·10^(4x)",
            xs.iter().map(|&x| (x, 1e-6 * 10f64.powf(4.0 * x))).collect(),
            SeriesStyle::Line,
        )];
        out.extend(line_plot(&dir.join("log"), "log axis", "x", "value", &log_series, true).unwrap());
        let g: Vec<f64> = (0..12).map(|i| i as f64 / 11.0).collect();
        let v: Vec<f64> = g.iter().flat_map(|&y| g.iter().map(move |&x| (x - y) * 1e-3)).collect();
        out.extend(heatmap(&dir.join("heat"), "signed", "x", "y", &g, &g, &v, "error", true).unwrap());
        out
    }

    #[test]
    fn renders_deterministic_png_and_svg() {
        let dir = tempfile::tempdir().unwrap();
        let first = render_both(dir.path());
        assert_eq!(first.len(), 6);
        let bytes: Vec<Vec<u8>> = first.iter().map(|p| std::fs::read(p).unwrap()).collect();
        for (p, b) in first.iter().zip(&bytes) {
            let ext = p.extension().unwrap().to_str().unwrap();
            assert!(b.len() > 5_000, "{} is only {} bytes", p.display(), b.len());
            match ext {
                "png" => assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n"),
                "svg" => {
                    let s = std::str::from_utf8(b).unwrap();
                    assert!(s.contains("<svg") && s.contains("</svg>"));
                }
                _ => panic!("unexpected {ext}"),
            }
        }
        // No temporary files left behind.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 6);
        let second = render_both(dir.path());
        assert_eq!(first, second);
        for (p, b) in second.iter().zip(&bytes) {
            assert!(std::fs::read(p).unwrap() == *b, "{} differs between renders", p.display());
        }
    }

    #[test]
    fn rgb_channels_are_drawn_in_their_own_colours() {
        // Series named red, green, blue in that order: by position they would take tab10's
        // blue, orange and green; by channel they take its red, green and blue.
        let dir = tempfile::tempdir().unwrap();
        let xs: Vec<f64> = (0..8).map(|i| i as f64).collect();
        let series: Vec<Series> = ["red", "green", "blue"]
            .iter()
            .enumerate()
            .map(|(k, n)| Series::new(*n, xs.iter().map(|&x| (x, x + k as f64)).collect(), SeriesStyle::Line).channel(n))
            .collect();
        let files = line_plot(&dir.path().join("rgb"), "rgb", "x", "y", &series, false).unwrap();
        let svg = std::fs::read_to_string(files.iter().find(|p| p.extension().unwrap() == "svg").unwrap()).unwrap().to_uppercase();
        let hex = |c: RGBColor| format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2);
        for want in [PALETTE[3], PALETTE[2], PALETTE[0]] {
            assert!(svg.contains(&hex(want)), "{} missing", hex(want));
        }
        assert!(!svg.contains(&hex(PALETTE[1])), "orange (position 1) drawn");
    }

    #[test]
    fn rejects_bad_shapes_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let stem = dir.path().join("bad");
        let e = heatmap(&stem, "t", "x", "y", &[0.0, 1.0], &[0.0, 1.0], &[1.0; 3], "v", false).unwrap_err();
        assert!(e.to_string().contains("bad"), "{e}");
        let e = line_plot(&stem, "t", "x", "y", &[Series::new("", vec![(0.0, -1.0)], SeriesStyle::Line)], true)
            .unwrap_err();
        assert!(matches!(e, PlotError::Data { .. }));
    }
}
