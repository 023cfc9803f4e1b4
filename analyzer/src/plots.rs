//! Plots as PNG and SVG with plotters, headless: no system font is needed (DejaVu Sans
//! is embedded and registered once), the bitmap and SVG backends draw the same code.
//!
//! Axes of the map: East horizontal, North vertical, one metre the same length on both
//! (`paper/NOTES.md` section 1; the paper's Fig. 8).

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;

use crate::error::{AnalyzerError, Result};
use crate::geometry::{body_to_ned, circle, ellipse, hull_outline};
use crate::plot_clip::{axis, range_of, Window};
use crate::plot_sink::{ObstacleTrack, PlotData};

/// DejaVu Sans (Bitstream Vera license, `assets/DejaVuSans-LICENSE.txt`).
static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
const FAMILY: &str = "sans-serif";

/// Registers the embedded font once.
fn ensure_font() -> Result<(), String> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        plotters::style::register_font(FAMILY, FontStyle::Normal, FONT)
            .map_err(|_| "the embedded DejaVu Sans font does not load".to_owned())?;
        plotters::style::register_font(FAMILY, FontStyle::Bold, FONT)
            .map_err(|_| "the embedded DejaVu Sans font does not load".to_owned())
    })
    .clone()
}

/// Size of the states plot (Fig. 12), px.
pub const STATES_SIZE: (u32, u32) = (1500, 900);
/// Size of the towing angle and force plot (Fig. 13), px.
pub const TOWING_SIZE: (u32, u32) = (1400, 900);
/// Size of the rates plot (Fig. 14), px.
pub const RATES_SIZE: (u32, u32) = (1400, 900);
/// Size of the ADMM plot, px.
pub const ADMM_SIZE: (u32, u32) = (1400, 900);
/// Size of the compute-time histogram, px.
pub const HISTOGRAM_SIZE: (u32, u32) = (1000, 600);
/// Width of the map, px (its height follows the data for an equal aspect).
pub const MAP_WIDTH: u32 = 1600;
/// Width of the distance plot, px; its height is [`DISTANCE_ROW_HEIGHT`] per row of two
/// obstacles.
pub const DISTANCES_WIDTH: u32 = 1400;
/// Height of one row of the distance plot, px.
pub const DISTANCE_ROW_HEIGHT: u32 = 320;

/// Target-ship positions farther than this from the ship (m) do not widen the map.
const MAP_TARGET_RANGE: f64 = 12.0;

/// Most points drawn per line (min/max per bucket beyond that).
const MAX_POINTS: usize = 4000;

const SHIP: RGBColor = RGBColor(200, 30, 30);
const TUG1: RGBColor = RGBColor(20, 140, 40);
const TUG2: RGBColor = RGBColor(30, 70, 200);
const TARGET: RGBColor = RGBColor(150, 60, 160);
const HAZARD: RGBColor = RGBColor(90, 90, 90);
const BOUND: RGBColor = RGBColor(220, 60, 20);
const ROUTE: RGBColor = RGBColor(120, 120, 120);
const ALTERED: RGBColor = RGBColor(240, 150, 0);
/// Ship, tug 1, tug 2.
const TOW_COLORS: [RGBColor; 3] = [SHIP, TUG1, TUG2];

/// One written plot.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotFile {
    /// File stem (`map`, `states`, ...).
    pub stem: String,
    /// Caption for the report.
    pub title: String,
    /// The PNG.
    pub png: PathBuf,
    /// The SVG.
    pub svg: PathBuf,
    /// Size, px.
    pub size: (u32, u32),
}

type DrawResult = std::result::Result<(), Box<dyn std::error::Error>>;

/// The map's chart: East horizontal, North vertical, m.
type MapChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Line styles of a series.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Dash {
    Solid,
    Dashed,
    Dotted,
}

#[derive(Debug, Clone)]
struct Line {
    label: String,
    pts: Vec<(f64, f64)>,
    color: RGBColor,
    width: u32,
    dash: Dash,
}

#[derive(Debug, Clone)]
struct Panel {
    title: String,
    y_desc: String,
    lines: Vec<Line>,
    /// Horizontal bound lines (value, label).
    bounds: Vec<(f64, String)>,
}

/// Keeps a line of finite points under [`MAX_POINTS`] points (the analysis' series, already
/// bounded by `crate::decimate`): beyond that, the first, min, max and last point of each
/// bucket, in time order.
fn decimate_points(pts: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    if pts.len() <= MAX_POINTS {
        return pts;
    }
    let buckets = MAX_POINTS / 4;
    let per = pts.len().div_ceil(buckets);
    let mut out = Vec::with_capacity(MAX_POINTS);
    for chunk in pts.chunks(per) {
        let (mut lo, mut hi) = (0, 0);
        for (k, p) in chunk.iter().enumerate() {
            if p.1 < chunk[lo].1 {
                lo = k;
            }
            if p.1 > chunk[hi].1 {
                hi = k;
            }
        }
        let mut idx = vec![0, lo, hi, chunk.len() - 1];
        idx.sort_unstable();
        idx.dedup();
        out.extend(idx.into_iter().map(|k| chunk[k]));
    }
    out
}

/// Dash and gap lengths, px, of a dashed line (`None`: solid).
type Dashes = Option<(i32, i32)>;

impl Dash {
    fn dashes(self) -> Dashes {
        match self {
            Dash::Solid => None,
            Dash::Dashed => Some((10, 5)),
            Dash::Dotted => Some((3, 4)),
        }
    }
}

/// Draws the polyline `pts`, clipped to `window` (the chart's, [`Window::around`]), solid
/// or with `dashes`, in `style`. With `legend` (label, style of its short line) the first
/// piece is labelled; when nothing of the line is in the window, an empty series carries
/// the label.
fn draw_clipped<DB: DrawingBackend>(
    chart: &mut MapChart<'_, DB>,
    window: &Window,
    pts: &[(f64, f64)],
    dashes: Dashes,
    style: ShapeStyle,
    legend: Option<(&str, ShapeStyle)>,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let mut pieces = window.polyline(pts);
    if pieces.is_empty() && legend.is_some() {
        pieces.push(Vec::new());
    }
    for (k, piece) in pieces.into_iter().enumerate() {
        let anno = match dashes {
            None => chart.draw_series(LineSeries::new(piece, style))?,
            Some((size, gap)) => {
                chart.draw_series(DashedLineSeries::new(piece, size, gap, style))?
            }
        };
        if let (0, Some((label, legend_style))) = (k, legend) {
            anno.label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], legend_style));
        }
    }
    Ok(())
}

/// Draws the polygon `pts` clipped to `window`, filled with `fill` (nothing when none of it
/// is in the window).
fn fill_clipped<DB: DrawingBackend>(
    chart: &mut MapChart<'_, DB>,
    window: &Window,
    pts: &[(f64, f64)],
    fill: ShapeStyle,
) -> std::result::Result<bool, Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    let poly = window.polygon(pts);
    if poly.is_empty() {
        return Ok(false);
    }
    chart.draw_series(std::iter::once(Polygon::new(poly, fill)))?;
    Ok(true)
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
    x_range: Range<f64>,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let y_range = range_of(
        panel
            .lines
            .iter()
            .flat_map(|l| l.pts.iter().map(|p| &p.1))
            .chain(panel.bounds.iter().map(|b| &b.0)),
    )
    .unwrap_or(-1.0..1.0);
    let x_range = axis(x_range.start, x_range.end);
    let window = Window::around(&x_range, &y_range);
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, (FAMILY, 18))
        .margin(8)
        .x_label_area_size(36)
        .y_label_area_size(64)
        .build_cartesian_2d(x_range.clone(), y_range)?;
    chart
        .configure_mesh()
        .x_desc("t (s)")
        .y_desc(panel.y_desc.as_str())
        .label_style((FAMILY, 13))
        .axis_desc_style((FAMILY, 14))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;
    for (value, label) in &panel.bounds {
        let style = BOUND.stroke_width(1);
        let bound = [(x_range.start, *value), (x_range.end, *value)];
        let legend = Some((label.as_str(), style));
        draw_clipped(&mut chart, &window, &bound, Some((8, 5)), style, legend)?;
    }
    let mut labelled = false;
    for line in &panel.lines {
        if line.pts.is_empty() {
            continue;
        }
        let style = line.color.stroke_width(line.width);
        let legend = (!line.label.is_empty()).then_some((line.label.as_str(), style));
        labelled |= legend.is_some();
        draw_clipped(
            &mut chart,
            &window,
            &line.pts,
            line.dash.dashes(),
            style,
            legend,
        )?;
    }
    if labelled || !panel.bounds.is_empty() {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(180, 180, 180))
            .label_font((FAMILY, 12))
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
    }
    Ok(())
}

fn draw_panels<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    panels: &[Panel],
    cols: usize,
    x_range: Range<f64>,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let root = root.titled(title, (FAMILY, 22))?;
    let rows = panels.len().div_ceil(cols).max(1);
    let areas = root.split_evenly((rows, cols));
    for (panel, area) in panels.iter().zip(areas.iter()) {
        draw_panel(area, panel, x_range.clone())?;
    }
    Ok(())
}

fn x_range(span: Option<(f64, f64)>) -> Range<f64> {
    let (lo, hi) = span.unwrap_or((0.0, 1.0));
    if hi > lo {
        axis(lo, hi)
    } else {
        axis(lo, lo + 1.0)
    }
}

fn vessel_lines(d: &PlotData, channel: usize) -> Vec<Line> {
    let styles = [
        ("ship", SHIP, 2, Dash::Solid),
        ("tug 1 (aft)", TUG1, 1, Dash::Dashed),
        ("tug 2 (forward)", TUG2, 1, Dash::Dotted),
    ];
    styles
        .iter()
        .enumerate()
        .map(|(k, (label, color, width, dash))| Line {
            label: (*label).to_owned(),
            pts: decimate_points(d.states[k][channel].clone()),
            color: *color,
            width: *width,
            dash: *dash,
        })
        .collect()
}

fn states_panels(d: &PlotData) -> Vec<Panel> {
    // The analysis gives psi unwrapped (no jump at +-180 deg when heading South) and in
    // deg, r in deg/s.
    let panel = |title: &str, y_desc: &str, channel: usize| Panel {
        title: title.into(),
        y_desc: y_desc.into(),
        lines: vessel_lines(d, channel),
        bounds: vec![],
    };
    vec![
        panel("x (North)", "x (m)", 0),
        panel("y (East)", "y (m)", 1),
        panel("heading psi", "psi (deg)", 2),
        panel("surge u", "u (m/s)", 3),
        panel("sway v", "v (m/s)", 4),
        panel("yaw rate r", "r (deg/s)", 5),
    ]
}

/// The actual (plant, not for rates) and commanded lines of one towing channel of
/// `line`.
fn towing_lines(
    line: usize,
    rate: bool,
    actual: &[(f64, f64)],
    commanded: Option<&[(f64, f64)]>,
) -> Vec<Line> {
    let mut lines = Vec::new();
    if !rate {
        lines.push(Line {
            label: "actual (plant)".to_owned(),
            pts: decimate_points(actual.to_vec()),
            color: RGBColor(150, 150, 150),
            width: 1,
            dash: Dash::Solid,
        });
    }
    if let Some(c) = commanded {
        lines.push(Line {
            label: "commanded".to_owned(),
            pts: decimate_points(c.to_vec()),
            color: if line == 0 { TUG1 } else { TUG2 },
            width: 2,
            dash: Dash::Solid,
        });
    }
    lines
}

fn towing_panels(d: &PlotData, rate: bool) -> Vec<Panel> {
    let b = &d.bounds;
    let mut panels = Vec::new();
    for line in 0..2 {
        let commanded = d.command.as_ref().map(|c| {
            if rate {
                c.angle_rate_deg[line].as_slice()
            } else {
                c.angle_deg[line].as_slice()
            }
        });
        let lines = towing_lines(line, rate, &d.actual.angle_deg[line], commanded);
        let (lim, unit) = if rate {
            (b.angle_rate_rad_per_s.to_degrees(), "deg/s")
        } else {
            (b.max_towing_angle_rad.to_degrees(), "deg")
        };
        panels.push(Panel {
            title: format!(
                "towing angle alpha{}{}",
                line + 1,
                if rate { " rate" } else { "" }
            ),
            y_desc: if rate {
                format!("d alpha{}/dt ({unit})", line + 1)
            } else {
                format!("alpha{} ({unit})", line + 1)
            },
            lines,
            bounds: vec![
                (lim, format!("+{lim:.3} {unit}")),
                (-lim, format!("-{lim:.3} {unit}")),
            ],
        });
    }
    for line in 0..2 {
        let commanded = d.command.as_ref().map(|c| {
            if rate {
                c.tension_rate[line].as_slice()
            } else {
                c.tension[line].as_slice()
            }
        });
        let lines = towing_lines(line, rate, &d.actual.tension[line], commanded);
        let bounds = if rate {
            let r = b.tension_rate_n_per_s;
            vec![(r, format!("+{r} N/s")), (-r, format!("-{r} N/s"))]
        } else {
            vec![
                (b.max_tension_n, format!("{} N", b.max_tension_n)),
                (b.min_tension_n, format!("{} N", b.min_tension_n)),
            ]
        };
        panels.push(Panel {
            title: format!(
                "towing force F{}{}",
                line + 1,
                if rate { " rate" } else { "" }
            ),
            y_desc: if rate {
                format!("dF{}/dt (N/s)", line + 1)
            } else {
                format!("F{} (N)", line + 1)
            },
            lines,
            bounds,
        });
    }
    panels
}

fn distance_panels(d: &PlotData) -> Vec<Panel> {
    d.obstacles
        .iter()
        .map(|o| {
            let styles = [
                ("ship", SHIP, 2, Dash::Solid),
                ("tug 1", TUG1, 1, Dash::Dashed),
                ("tug 2", TUG2, 1, Dash::Dotted),
            ];
            let lines = styles
                .iter()
                .enumerate()
                .map(|(k, (label, color, width, dash))| Line {
                    label: (*label).to_owned(),
                    pts: decimate_points(o.distance[k].clone()),
                    color: *color,
                    width: *width,
                    dash: *dash,
                })
                .collect();
            let mut bounds = vec![(o.safe[0], format!("safe, ship {:.2} m", o.safe[0]))];
            if (o.safe[1] - o.safe[0]).abs() > 1e-9 {
                bounds.push((o.safe[1], format!("safe, tug {:.2} m", o.safe[1])));
            }
            Panel {
                title: format!(
                    "{} ({})",
                    o.name,
                    if o.kind == 2 {
                        "target ship"
                    } else {
                        "static hazard"
                    }
                ),
                y_desc: "centre distance (m)".into(),
                lines,
                bounds,
            }
        })
        .collect()
}

fn admm_panels(d: &PlotData) -> Vec<Panel> {
    let Some(s) = &d.solver else {
        return Vec::new();
    };
    let line = |label: &str, pts: &[(f64, f64)], color: RGBColor, dash: Dash| Line {
        label: label.into(),
        pts: decimate_points(pts.to_vec()),
        color,
        width: 1,
        dash,
    };
    vec![
        Panel {
            title: "ADMM iterations per sample".into(),
            y_desc: "iterations".into(),
            lines: vec![line("", &s.iterations, TUG2, Dash::Solid)],
            bounds: vec![],
        },
        Panel {
            title: "last residuals (eq. (29))".into(),
            y_desc: "log10 residual".into(),
            lines: vec![
                line("primal, tug 1", &s.log_r_pri[0], TUG1, Dash::Solid),
                line("primal, tug 2", &s.log_r_pri[1], TUG2, Dash::Solid),
                line("dual, tug 1", &s.log_r_dual[0], TUG1, Dash::Dotted),
                line("dual, tug 2", &s.log_r_dual[1], TUG2, Dash::Dotted),
            ],
            bounds: vec![],
        },
    ]
}

fn draw_histogram<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, d: &PlotData) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let hist = d
        .solver
        .as_ref()
        .map(|s| s.compute_time.clone())
        .unwrap_or_else(|| crate::plot_sink::Histogram::new(&[], 40));
    let hi = hist.hi;
    let width = hi / hist.counts.len().max(1) as f64;
    let counts = &hist.counts;
    let top = f64::from(counts.iter().copied().max().unwrap_or(1).max(1)) * 1.1;
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!(
                "computation time per control sample ({} samples)",
                hist.samples
            ),
            (FAMILY, 20),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..hi, 0.0..top)?;
    chart
        .configure_mesh()
        .x_desc("compute time (ms)")
        .y_desc("samples")
        .label_style((FAMILY, 13))
        .axis_desc_style((FAMILY, 14))
        .draw()?;
    chart.draw_series(counts.iter().enumerate().map(|(k, &c)| {
        let x0 = k as f64 * width;
        Rectangle::new(
            [(x0, 0.0), (x0 + width * 0.92, f64::from(c))],
            TUG2.filled(),
        )
    }))?;
    Ok(())
}

/// Size and ranges of the map: `(size px, East range, North range)`, with the plotting
/// area's metres per pixel equal on both axes.
#[must_use]
pub fn map_layout(d: &PlotData) -> ((u32, u32), Range<f64>, Range<f64>) {
    let mut east: Vec<f64> = Vec::new();
    let mut north: Vec<f64> = Vec::new();
    for p in &d.route {
        north.push(p[0]);
        east.push(p[1]);
    }
    for v in &d.states {
        // Every extreme of x and y is kept in the plot series.
        north.extend(v[0].iter().map(|p| p.1));
        east.extend(v[1].iter().map(|p| p.1));
    }
    for o in &d.obstacles {
        // Static hazards always; target ships only where they come near the ship, so a
        // target's long run-in does not shrink the tow to a line.
        for i in 0..o.x.len() {
            let near = o
                .ship_distance
                .get(i)
                .is_some_and(|d| *d < MAP_TARGET_RANGE);
            if o.kind != 2 || near {
                north.push(o.x[i]);
                east.push(o.y[i]);
            }
        }
    }
    let pad = 2.0;
    let er = range_of(east.iter()).unwrap_or(-10.0..10.0);
    let nr = range_of(north.iter()).unwrap_or(-10.0..10.0);
    let (mut e0, mut e1) = (er.start - pad, er.end + pad);
    let (mut n0, mut n1) = (nr.start - pad, nr.end + pad);
    // Plot area: width minus label area and margins; height plus caption and labels.
    let plot_w = f64::from(MAP_WIDTH - 70 - 40);
    let extra_h = 40.0 + 50.0 + 40.0;
    let mut plot_h = plot_w * (n1 - n0) / (e1 - e0);
    let (min_h, max_h) = (500.0 - extra_h, 2400.0 - extra_h);
    if plot_h > max_h {
        // Too tall: widen East around its centre.
        let want = (n1 - n0) * plot_w / max_h;
        let c = 0.5 * (e0 + e1);
        e0 = c - want / 2.0;
        e1 = c + want / 2.0;
        plot_h = max_h;
    } else if plot_h < min_h {
        let want = (e1 - e0) * min_h / plot_w;
        let c = 0.5 * (n0 + n1);
        n0 = c - want / 2.0;
        n1 = c + want / 2.0;
        plot_h = min_h;
    }
    let h = (plot_h + extra_h).round() as u32;
    ((MAP_WIDTH, h), axis(e0, e1), axis(n0, n1))
}

/// Indices of `n` evenly spaced sample times (the paper's Fig. 8 shows ten states).
fn sample_indices(t: &[f64], n: usize) -> Vec<usize> {
    if t.is_empty() {
        return Vec::new();
    }
    let (t0, t1) = (t[0], t[t.len() - 1]);
    (0..n)
        .map(|k| {
            let target = t0 + (t1 - t0) * k as f64 / (n - 1).max(1) as f64;
            t.partition_point(|&v| v < target).min(t.len() - 1)
        })
        .collect()
}

fn en(p: [f64; 2]) -> (f64, f64) {
    (p[1], p[0])
}

/// Draws the map (the paper's Fig. 8 style) on `root`: East range `er`, North range `nr`, m.
/// Everything is clipped to the window around the chart ([`Window`]).
fn draw_map<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    d: &PlotData,
    er: Range<f64>,
    nr: Range<f64>,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let window = Window::around(&er, &nr);
    let mut chart = ChartBuilder::on(root)
        .caption(format!("map: {}", d.title), (FAMILY, 22))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(er, nr)?;
    chart
        .configure_mesh()
        .x_desc("East y (m)")
        .y_desc("North x (m)")
        .label_style((FAMILY, 14))
        .axis_desc_style((FAMILY, 16))
        .light_line_style(RGBColor(238, 238, 238))
        .draw()?;
    let mut map = Map {
        chart: &mut chart,
        window,
    };
    draw_route(&mut map, d)?;
    draw_hazards(&mut map, d)?;
    let samples = sample_indices(&d.poses.t, 10);
    let sample_times: Vec<f64> = samples.iter().map(|&i| d.poses.t[i]).collect();
    draw_targets(&mut map, d, &sample_times)?;
    // The tow: tracks, then hull outlines and towlines at the sampled times.
    draw_tow_tracks(&mut map, d)?;
    for &i in &samples {
        draw_tow_at(&mut map, d, i)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.9))
        .border_style(RGBColor(180, 180, 180))
        .label_font((FAMILY, 14))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()?;
    Ok(())
}

/// The map's chart and the window its geometry is clipped to.
struct Map<'c, 'a, DB: DrawingBackend> {
    chart: &'c mut MapChart<'a, DB>,
    window: Window,
}

impl<DB: DrawingBackend> Map<'_, '_, DB>
where
    DB::ErrorType: 'static,
{
    /// A polyline ([`draw_clipped`]).
    fn line(
        &mut self,
        pts: &[(f64, f64)],
        dashes: Dashes,
        style: ShapeStyle,
        legend: Option<(&str, ShapeStyle)>,
    ) -> DrawResult {
        draw_clipped(self.chart, &self.window, pts, dashes, style, legend)
    }

    /// A closed outline: the polygon filled with `fill`, its edge drawn in `edge`.
    fn outline(&mut self, pts: &[(f64, f64)], fill: ShapeStyle, edge: ShapeStyle) -> DrawResult {
        fill_clipped(self.chart, &self.window, pts, fill)?;
        let mut closed = pts.to_vec();
        if let Some(&first) = pts.first() {
            closed.push(first);
        }
        self.line(&closed, None, edge, None)
    }

    /// `element`, placed at `at`, when `at` is in the window.
    fn at<E>(&mut self, at: (f64, f64), element: E) -> DrawResult
    where
        for<'b> &'b E: PointCollection<'b, (f64, f64)>,
        E: Drawable<DB>,
    {
        if self.window.contains(at) {
            self.chart.draw_series(std::iter::once(element))?;
        }
        Ok(())
    }
}

/// Route and waypoints, the destination, the altered waypoints.
fn draw_route<DB: DrawingBackend>(map: &mut Map<'_, '_, DB>, d: &PlotData) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let route: Vec<(f64, f64)> = d.route.iter().map(|p| (p[1], p[0])).collect();
    let style = ROUTE.stroke_width(2);
    map.line(&route, Some((10, 6)), style, Some(("route", style)))?;
    for &p in &route {
        map.at(p, Circle::new(p, 4, ROUTE.filled()))?;
    }
    if let Some(&dest) = route.last() {
        map.at(dest, Cross::new(dest, 9, BLACK.stroke_width(3)))?;
    }
    let altered: Vec<(f64, f64)> = d
        .altered_waypoints
        .iter()
        .map(|w| (w[1], w[0]))
        .filter(|&p| map.window.contains(p))
        .collect();
    if !d.altered_waypoints.is_empty() {
        map.chart
            .draw_series(
                altered
                    .into_iter()
                    .map(|p| TriangleMarker::new(p, 8, ALTERED.filled())),
            )?
            .label("altered waypoints")
            .legend(|(x, y)| TriangleMarker::new((x + 10, y), 6, ALTERED.filled()));
    }
    Ok(())
}

/// Static hazards with their safe circles (ship's safe distance, eq. (14)).
fn draw_hazards<DB: DrawingBackend>(map: &mut Map<'_, '_, DB>, d: &PlotData) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let mut hazard_legend = false;
    for o in d.obstacles.iter().filter(|o| o.kind != 2) {
        let (Some(&x), Some(&y)) = (o.x.first(), o.y.first()) else {
            continue;
        };
        let r = o.length.max(o.width) / 2.0;
        let body: Vec<(f64, f64)> = circle(x, y, r, 48).into_iter().map(en).collect();
        let body = map.window.polygon(&body);
        let a = map.chart.draw_series(
            (!body.is_empty()).then(|| Polygon::new(body, HAZARD.mix(0.6).filled())),
        )?;
        if !hazard_legend {
            a.label("static hazard")
                .legend(|(x, y)| Circle::new((x + 10, y), 5, HAZARD.filled()));
        }
        let mut safe: Vec<(f64, f64)> = circle(x, y, o.safe[0], 96).into_iter().map(en).collect();
        if let Some(&first) = safe.first() {
            safe.push(first);
        }
        let legend = (!hazard_legend).then_some(("safe distance (ship)", BOUND.into()));
        map.line(&safe, Some((6, 5)), BOUND.stroke_width(1), legend)?;
        hazard_legend = true;
        let label_at = (y + r * 0.9, x + r * 0.9);
        let font = (FAMILY, 18).into_font().color(&BLACK);
        map.at(label_at, Text::new(o.name.clone(), label_at, font))?;
    }
    Ok(())
}

/// Target ships: tracks, and outlines at the sampled times (`sample_times`, s) when
/// active.
fn draw_targets<DB: DrawingBackend>(
    map: &mut Map<'_, '_, DB>,
    d: &PlotData,
    sample_times: &[f64],
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let mut target_legend = false;
    for o in d.obstacles.iter().filter(|o| o.kind == 2) {
        let track: Vec<(f64, f64)> = o.x.iter().zip(&o.y).map(|(&x, &y)| (y, x)).collect();
        let track = if track.len() > MAX_POINTS {
            track
                .iter()
                .step_by(track.len() / MAX_POINTS + 1)
                .copied()
                .collect()
        } else {
            track
        };
        let style = TARGET.stroke_width(1);
        let legend = (!target_legend).then_some(("target ships", TARGET.into()));
        map.line(&track, None, style, legend)?;
        target_legend = true;
        // The track may be thinned (StreamOptions::track_rows): accept the nearest kept
        // row.
        let spacing = match (o.t.first(), o.t.last()) {
            (Some(a), Some(b)) if o.t.len() > 1 => (b - a) / (o.t.len() - 1) as f64,
            _ => 0.0,
        };
        let tolerance = (2.0 * spacing).max(1.0);
        for &ts in sample_times {
            let k = o.t.partition_point(|&v| v < ts);
            if k >= o.t.len() || (o.t[k] - ts).abs() > tolerance {
                continue;
            }
            draw_target_outline(map, o, k)?;
        }
        if let (Some(&x), Some(&y)) = (o.x.first(), o.y.first()) {
            let label_at = (y + 0.5, x);
            let font = (FAMILY, 18).into_font().color(&TARGET);
            map.at(label_at, Text::new(o.name.clone(), label_at, font))?;
        }
    }
    Ok(())
}

/// The outline of target ship `o` at its row `k`, with a dot at the bow.
fn draw_target_outline<DB: DrawingBackend>(
    map: &mut Map<'_, '_, DB>,
    o: &ObstacleTrack,
    k: usize,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let outline: Vec<(f64, f64)> =
        ellipse(o.x[k], o.y[k], o.psi[k], o.length / 2.0, o.width / 2.0, 40)
            .into_iter()
            .map(en)
            .collect();
    map.outline(&outline, TARGET.mix(0.25).filled(), TARGET.into())?;
    let bow = en(body_to_ned(o.x[k], o.y[k], o.psi[k], o.length / 2.0, 0.0));
    map.at(bow, Circle::new(bow, 2, TARGET.filled()))
}

/// The tracks of ship, tug 1 and tug 2, with their legend entries.
fn draw_tow_tracks<DB: DrawingBackend>(map: &mut Map<'_, '_, DB>, d: &PlotData) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let labels = ["ship", "tug 1 (aft)", "tug 2 (forward)"];
    for k in 0..3 {
        // decimate_points() keeps the samples' order, so the track stays a path.
        let pts = decimate_points(d.tracks[k].clone());
        let color = TOW_COLORS[k];
        let style = color.stroke_width(if k == 0 { 2 } else { 1 });
        map.line(&pts, None, style, Some((labels[k], color.stroke_width(2))))?;
    }
    Ok(())
}

/// The towlines and hull outlines of the tow at pose sample `i`, labelled with its time
/// (nothing when the ship's pose is not finite).
fn draw_tow_at<DB: DrawingBackend>(map: &mut Map<'_, '_, DB>, d: &PlotData, i: usize) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let pose = |k: usize| {
        let [x, y, psi] = d.poses.pose[i][k];
        (x, y, psi)
    };
    let (sx, sy, sp) = pose(0);
    if !(sx.is_finite() && sy.is_finite() && sp.is_finite()) {
        return Ok(());
    }
    // Towlines: ship stern to tug 1 bow, ship bow to tug 2 stern (attachment points
    // approximated by the hull ends).
    let ls = d.sizes[0][0] / 2.0;
    for (k, ship_end, tug_end) in [
        (1usize, -ls, d.sizes[1][0] / 2.0),
        (2, ls, -d.sizes[2][0] / 2.0),
    ] {
        let (tx, ty, tp) = pose(k);
        if !(tx.is_finite() && ty.is_finite() && tp.is_finite()) {
            continue;
        }
        let a = body_to_ned(sx, sy, sp, ship_end, 0.0);
        let b = body_to_ned(tx, ty, tp, tug_end, 0.0);
        map.line(&[en(a), en(b)], None, BLACK.stroke_width(1), None)?;
    }
    for (k, color) in TOW_COLORS.iter().enumerate() {
        let (x, y, p) = pose(k);
        if !(x.is_finite() && y.is_finite() && p.is_finite()) {
            continue;
        }
        let hull: Vec<(f64, f64)> = hull_outline(x, y, p, d.sizes[k][0], d.sizes[k][1])
            .into_iter()
            .map(en)
            .collect();
        map.outline(&hull, color.mix(0.35).filled(), color.stroke_width(1))?;
    }
    let label_at = (sy + 0.9, sx + 0.4);
    let font = (FAMILY, 13).into_font().color(&BLACK);
    map.at(
        label_at,
        Text::new(format!("{:.0} s", d.poses.t[i]), label_at, font),
    )
}

fn plot_error(path: &Path, e: impl std::fmt::Display) -> AnalyzerError {
    AnalyzerError::Plot {
        path: path.to_owned(),
        reason: e.to_string(),
    }
}

/// Draws `$draw(&root, args...)` into `DIR/STEM.png` and `DIR/STEM.svg`.
macro_rules! render {
    ($dir:expr, $stem:expr, $title:expr, $size:expr, $draw:ident $(, $arg:expr)*) => {{
        let png = $dir.join(format!("{}.png", $stem));
        let svg = $dir.join(format!("{}.svg", $stem));
        {
            let root = BitMapBackend::new(&png, $size).into_drawing_area();
            $draw(&root $(, $arg)*).map_err(|e| plot_error(&png, e))?;
            root.present().map_err(|e| plot_error(&png, e))?;
        }
        {
            let root = SVGBackend::new(&svg, $size).into_drawing_area();
            $draw(&root $(, $arg)*).map_err(|e| plot_error(&svg, e))?;
            root.present().map_err(|e| plot_error(&svg, e))?;
        }
        PlotFile {
            stem: $stem.to_owned(),
            title: $title.to_owned(),
            png,
            svg,
            size: $size,
        }
    }};
}

/// Writes every plot into `dir` (PNG and SVG each) and lists them.
///
/// # Errors
/// The font does not load, or a file cannot be drawn or written.
pub fn write_plots(dir: &Path, d: &PlotData) -> Result<Vec<PlotFile>> {
    ensure_font().map_err(|e| plot_error(dir, e))?;
    let mut out = Vec::new();
    let (map_size, er, nr) = map_layout(d);
    out.push(render!(
        dir,
        "map",
        "Map (Fig. 8 style): tracks, hulls every tenth of the run, hazards with the ship's safe distance, target ships, route and altered waypoints",
        map_size,
        draw_map,
        d,
        er.clone(),
        nr.clone()
    ));
    let xr = x_range(d.t_span);
    let states = states_panels(d);
    let title = format!("vessel states (Fig. 12 style): {}", d.title);
    out.push(render!(
        dir,
        "states",
        "Vessel states x, y, psi, u, v, r (Fig. 12 style)",
        STATES_SIZE,
        draw_panels,
        &title,
        &states,
        3,
        xr.clone()
    ));
    let towing = towing_panels(d, false);
    let title = format!("towing angles and forces (Fig. 13 style): {}", d.title);
    out.push(render!(
        dir,
        "towing",
        "Towing angles and forces with their bounds (Fig. 13 style)",
        TOWING_SIZE,
        draw_panels,
        &title,
        &towing,
        2,
        xr.clone()
    ));
    let rate_panels = towing_panels(d, true);
    let title = format!(
        "rates of the commanded towing angles and forces (Fig. 14 style): {}",
        d.title
    );
    out.push(render!(
        dir,
        "rates",
        "Rates of the commanded towing angles and forces with the rate bounds (Fig. 14 style)",
        RATES_SIZE,
        draw_panels,
        &title,
        &rate_panels,
        2,
        xr.clone()
    ));
    let dist = distance_panels(d);
    if !dist.is_empty() {
        let rows = u32::try_from(dist.len().div_ceil(2)).unwrap_or(1);
        let size = (DISTANCES_WIDTH, DISTANCE_ROW_HEIGHT * rows + 40);
        let title = format!(
            "distance to each obstacle (centre distance, eq. (30)): {}",
            d.title
        );
        out.push(render!(
            dir,
            "distances",
            "Distance of each vessel to each obstacle with the safe distances",
            size,
            draw_panels,
            &title,
            &dist,
            2,
            xr.clone()
        ));
    }
    let admm = admm_panels(d);
    if !admm.is_empty() {
        let title = format!("ADMM: {}", d.title);
        out.push(render!(
            dir,
            "admm",
            "ADMM iterations and last residuals per control sample",
            ADMM_SIZE,
            draw_panels,
            &title,
            &admm,
            1,
            xr.clone()
        ));
        out.push(render!(
            dir,
            "compute_time",
            "Histogram of the computation time per control sample",
            HISTOGRAM_SIZE,
            draw_histogram,
            d
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimation_keeps_extremes_and_order() {
        let t: Vec<f64> = (0..100_000).map(f64::from).collect();
        let mut v: Vec<f64> = t.iter().map(|x| (x * 0.001).sin()).collect();
        v[54_321] = 10.0;
        let d = decimate_points(t.iter().copied().zip(v.iter().copied()).collect());
        assert!(d.len() <= MAX_POINTS);
        assert!(d.iter().any(|p| p.1 == 10.0));
        assert!(d.windows(2).all(|w| w[0].0 <= w[1].0));
    }
}
