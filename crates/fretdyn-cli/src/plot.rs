//! PNG plots (plotters, bitmap backend). The font is embedded so that plots render on a
//! machine without system fonts.
//!
//! Every chart is set up by one helper ([`frame`]): its caption, a legend strip above the
//! plotting area (never over the data) and axes ticked by [`axis`]: the unit's SI prefix chosen
//! from the axis range (ms, µm, mW, kN, …) and every tick label of an axis written with the same
//! number of decimals. Axis labels are written `quantity (unit)`, the unit in base SI (`t (s)`,
//! `force (N)`); the prefix is the plot's business.

use std::error::Error;
use std::ops::Range;
use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::FontStyle;
use plotters::style::text_anchor::{HPos, Pos, VPos};

static FONT: &[u8] = include_bytes!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../assets/DejaVuSans.ttf"
));
static REGISTER: Once = Once::new();

fn register_font() {
    REGISTER.call_once(|| {
        // The embedded font is valid; should registration fail, text is simply not drawn.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// One curve: label, x values, y values (same length).
pub struct Series<'a> {
    pub label: String,
    pub x: &'a [f64],
    pub y: &'a [f64],
}

/// One bar: its label (on the x axis), value and standard error (drawn as a ± bar; 0: none).
pub struct Bar {
    pub label: String,
    pub value: f64,
    pub error: f64,
}

/// One bin of a histogram on a logarithmic axis: `[lo, hi)` (both > 0) and its count.
pub struct Bin {
    pub lo: f64,
    pub hi: f64,
    pub count: usize,
}

const WIDTH: u32 = 1000;
const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

// ---------------------------------------------------------------------------------------------
// Axes: SI prefix and tick labels

/// An axis: its title (the unit with its SI prefix) and its ticks (position in data units,
/// label in the prefixed unit).
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    pub title: String,
    pub ticks: Vec<(f64, String)>,
}

/// SI prefixes from pico to giga, by power of ten.
const PREFIXES: [(i32, &str); 8] = [
    (-12, "p"),
    (-9, "n"),
    (-6, "µ"),
    (-3, "m"),
    (0, ""),
    (3, "k"),
    (6, "M"),
    (9, "G"),
];

/// Units that take an SI prefix; in a compound unit (`N/m`, `m/s²`, `N·s/m`) the prefix goes on
/// the first symbol (`kN/m`).
const PREFIXED_UNITS: [&str; 7] = ["m", "s", "N", "W", "J", "Pa", "Hz"];

/// The axis of `label` (`quantity (unit)`, or a bare `quantity`) over `range`, with at most
/// about `max_ticks` intervals between ticks.
///
/// The prefix is the power of 1000 that brings the largest magnitude of the range into
/// [1, 1000) (pico to giga; none above 1 for seconds). A unit without prefixes (or no unit)
/// gets a common factor `×10ⁿ` in the title instead when the magnitude is outside
/// [0.01, 10⁴). The ticks are the multiples of the step 1, 2 or 5 × 10ᵏ (in the prefixed unit)
/// that fall in the range, every label written with the decimals of the step.
pub fn axis(label: &str, range: Range<f64>, max_ticks: usize) -> Axis {
    let magnitude = range.start.abs().max(range.end.abs());
    axis_scaled_for(label, range, magnitude, max_ticks)
}

/// [`axis`] with the prefix chosen for `magnitude` instead of the range's (axes drawn to the
/// same scale share their prefix).
fn axis_scaled_for(label: &str, range: Range<f64>, magnitude: f64, max_ticks: usize) -> Axis {
    let (title, factor) = unit_scale(label, magnitude);
    let (a, b) = (range.start / factor, range.end / factor);
    let raw = (b - a) / max_ticks.max(1) as f64;
    if !(raw > 0.0 && raw.is_finite()) {
        return Axis {
            title,
            ticks: Vec::new(),
        };
    }
    let mut exp = raw.log10().floor() as i32;
    let base = 10f64.powi(exp);
    // the smallest of 1, 2, 5 (× 10^exp) not below the raw step, else 10^(exp+1)
    let mantissa = match [1.0, 2.0, 5.0]
        .into_iter()
        .find(|m| m * base >= raw * (1.0 - 1e-9))
    {
        Some(m) => m,
        None => {
            exp += 1;
            1.0
        }
    };
    let step = mantissa * 10f64.powi(exp);
    let decimals = (-exp).max(0) as usize;
    let (first, last) = ((a / step - 1e-9).ceil(), (b / step + 1e-9).floor());
    // a range at the edge of the floating-point numbers (subnormal, or near f64::MAX) has a
    // step that underflows or overflows: no ticks rather than billions of them
    if !(first.is_finite() && last.is_finite() && last - first <= 4.0 * max_ticks.max(1) as f64) {
        return Axis {
            title,
            ticks: Vec::new(),
        };
    }
    let ticks = (first as i64..=last as i64)
        .map(|k| {
            let v = k as f64 * step;
            (v * factor, format!("{v:.decimals$}"))
        })
        .collect();
    Axis { title, ticks }
}

/// The title of the axis `label` with the unit's prefix (or a common factor) for values of
/// `magnitude`, and the factor the values are divided by.
fn unit_scale(label: &str, magnitude: f64) -> (String, f64) {
    let (name, unit) = split_label(label);
    let symbol = first_symbol(unit);
    let prefixed = PREFIXED_UNITS.contains(&symbol);
    let power = if magnitude > 0.0 && magnitude.is_finite() {
        3 * (magnitude.log10() / 3.0).floor() as i32
    } else {
        0
    };
    if prefixed {
        let top = if symbol == "s" { 0 } else { 9 };
        let power = power.clamp(-12, top);
        let prefix = PREFIXES
            .iter()
            .find(|(p, _)| *p == power)
            .map_or("", |(_, s)| s);
        (format!("{name} ({prefix}{unit})"), 10f64.powi(power))
    } else if (1e-2..1e4).contains(&magnitude) || power == 0 {
        (label.to_string(), 1.0)
    } else {
        let factor = format!("×10{}", superscript(power));
        let title = if unit.is_empty() {
            format!("{name} ({factor})")
        } else {
            format!("{name} ({factor} {unit})")
        };
        (title, 10f64.powi(power))
    }
}

/// `quantity (unit)` → (quantity, unit); a label without a unit → (label, "").
fn split_label(label: &str) -> (&str, &str) {
    match label.strip_suffix(')').and_then(|l| l.rsplit_once(" (")) {
        Some((name, unit)) => (name, unit),
        None => (label, ""),
    }
}

/// The first symbol of a unit, the one that takes the prefix: `N` of `N·s/m`.
fn first_symbol(unit: &str) -> &str {
    unit.split(['/', '·', ' ', '^']).next().unwrap_or("")
}

fn superscript(n: i32) -> String {
    n.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            _ => '⁹',
        })
        .collect()
}

/// A logarithmic axis: the coordinates are log10 of the values, over `decades`. Ticks at
/// 1, 2, 5 × 10ᵏ (only the powers of ten, thinned, when that would make more than
/// `max_ticks`). A log axis spans decades, so each label takes its own SI prefix and carries
/// the unit (`200 mN`, `1 N`, `10 N`); the title says `log scale`.
fn log_axis(label: &str, decades: Range<f64>, max_ticks: usize) -> Axis {
    let (name, unit) = split_label(label);
    let prefixed = PREFIXED_UNITS.contains(&first_symbol(unit));
    let (lo, hi) = (decades.start.floor() as i32, decades.end.ceil() as i32);
    let span = (decades.end - decades.start).max(0.0);
    let mantissas: &[f64] = if 3.0 * span <= max_ticks as f64 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let every = (span / max_ticks.max(1) as f64).ceil().max(1.0) as i32;
    let mut ticks = Vec::new();
    for k in lo..=hi {
        if mantissas.len() == 1 && k.rem_euclid(every) != 0 {
            continue;
        }
        for m in mantissas {
            let position = m.log10() + k as f64;
            if position < decades.start - 1e-9 || position > decades.end + 1e-9 {
                continue;
            }
            let label = if prefixed {
                let power = (3 * k.div_euclid(3)).clamp(-12, 9);
                let prefix = PREFIXES
                    .iter()
                    .find(|(p, _)| *p == power)
                    .map_or("", |(_, s)| s);
                let v = m * 10f64.powi(k - power);
                let decimals = (power - k).max(0) as usize;
                format!("{v:.decimals$} {prefix}{unit}")
            } else {
                let decimals = (-k).max(0) as usize;
                format!("{:.decimals$}", m * 10f64.powi(k))
            };
            ticks.push((position, label));
        }
    }
    Axis {
        title: format!("{name} (log scale)"),
        ticks,
    }
}

/// Categories at 0.5, 1.5, …: their names, every n-th when they would not fit in `pixels`.
fn names_axis(label: &str, names: &[String], pixels: u32) -> Axis {
    let widest = names.iter().map(|n| n.chars().count()).max().unwrap_or(1);
    // about 7 px a character at the tick font, and a gap
    let fit = (pixels as usize / (7 * widest + 16)).max(1);
    let every = names.len().div_ceil(fit).max(1);
    Axis {
        title: label.to_string(),
        ticks: names
            .iter()
            .enumerate()
            .step_by(every)
            .map(|(i, n)| (i as f64 + 0.5, n.clone()))
            .collect(),
    }
}

/// The label of the tick at (or nearest to) `v`.
fn label_at(ticks: &[(f64, String)], v: f64) -> String {
    ticks
        .iter()
        .min_by(|a, b| (a.0 - v).abs().total_cmp(&(b.0 - v).abs()))
        .map(|t| t.1.clone())
        .unwrap_or_default()
}

// ---------------------------------------------------------------------------------------------
// Chart set-up, shared by every chart

type Area<'p> = DrawingArea<BitMapBackend<'p>, Shift>;
type Chart<'p> = ChartContext<'static, BitMapBackend<'p>, Cartesian2d<Ticked, Ticked>>;

/// A linear coordinate whose mesh lines and labels are at the given ticks (no light lines).
struct Ticked {
    inner: RangedCoordf64,
    ticks: Vec<f64>,
}

impl Ranged for Ticked {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.inner.range()
    }
}
type DrawResult<T> = Result<T, Box<dyn Error>>;

/// How an axis is ticked.
enum Scale<'a> {
    /// Linear, in the unit of the label.
    Linear,
    /// Linear, with the prefix chosen for this magnitude.
    LinearFor(f64),
    /// The coordinates are log10 of the values.
    Log10,
    /// Categories at 0.5, 1.5, …
    Names(&'a [String]),
}

struct AxisSpec<'a> {
    label: &'a str,
    range: Range<f64>,
    scale: Scale<'a>,
}

impl<'a> AxisSpec<'a> {
    fn new(label: &'a str, range: Range<f64>, scale: Scale<'a>) -> Self {
        Self {
            label,
            range,
            scale,
        }
    }

    /// The ticks for an axis `pixels` long, a tick every `spacing` pixels at most.
    fn ticks(&self, pixels: u32, spacing: u32) -> Axis {
        let max = (pixels / spacing).max(2) as usize;
        match self.scale {
            Scale::Linear => axis(self.label, self.range.clone(), max),
            Scale::LinearFor(m) => axis_scaled_for(self.label, self.range.clone(), m, max),
            Scale::Log10 => log_axis(self.label, self.range.clone(), max),
            Scale::Names(names) => names_axis(self.label, names, pixels),
        }
    }
}

/// A legend entry: a short line in the series' style and its label.
struct Key {
    label: String,
    colour: RGBColor,
    dashed: bool,
}

const MARGIN: u32 = 12;
/// Series of at most this many points have their points marked.
const MARKED_POINTS: usize = 60;
const X_LABEL_AREA: u32 = 40;
const Y_LABEL_AREA: u32 = 80;
const KEY_ROW: u32 = 18;

/// A white canvas of `size` with the plot's title on top, and its panels: a grid of
/// (rows, columns) below the title.
fn canvas<'p>(
    path: &'p Path,
    size: (u32, u32),
    title: &str,
    grid: (usize, usize),
) -> DrawResult<(Area<'p>, Vec<Area<'p>>)> {
    canvas_on(BitMapBackend::new(path, size), title, grid)
}

/// [`canvas`] on a backend (a file or a buffer of pixels).
fn canvas_on<'p>(
    backend: BitMapBackend<'p>,
    title: &str,
    grid: (usize, usize),
) -> DrawResult<(Area<'p>, Vec<Area<'p>>)> {
    register_font();
    let root = backend.into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 22))?;
    let panels = root.split_evenly(grid);
    Ok((root, panels))
}

/// Size of a canvas of `n` stacked panels.
fn stacked_size(n: usize) -> (u32, u32) {
    (WIDTH, 60 + 300 * n.max(1) as u32)
}

/// Sets up a chart on `area`: caption, legend strip (the entries flowing in rows above the
/// plotting area), axes with their titles and ticks ([`axis`]) and the mesh.
fn frame<'p>(
    area: &Area<'p>,
    caption: &str,
    keys: &[Key],
    x: AxisSpec,
    y: AxisSpec,
) -> DrawResult<Chart<'p>> {
    let (width, height) = area.dim_in_pixel();
    let font = ("sans-serif", 13).into_font();
    // legend rows: (x offset, key) flowing from the left edge of the plotting area
    let left = MARGIN + Y_LABEL_AREA;
    let mut rows: Vec<Vec<(u32, &Key)>> = Vec::new();
    let mut cursor = u32::MAX;
    for key in keys {
        let (w, _) = area.estimate_text_size(&key.label, &TextStyle::from(font.clone()))?;
        let entry = 26 + w + 24;
        if cursor == u32::MAX || cursor + entry > width.saturating_sub(MARGIN) {
            rows.push(Vec::new());
            cursor = left;
        }
        if let Some(row) = rows.last_mut() {
            row.push((cursor, key));
        }
        cursor += entry;
    }
    let caption_height = if caption.is_empty() { 6 } else { 24 };
    let head = caption_height + KEY_ROW * rows.len() as u32;
    let (top, body) = area.split_vertically(head);
    if !caption.is_empty() {
        let style =
            TextStyle::from(("sans-serif", 16).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
        top.draw_text(caption, &style, (width as i32 / 2, 4))?;
    }
    for (r, row) in rows.iter().enumerate() {
        let y = (caption_height + KEY_ROW * r as u32) as i32;
        let mid = y + KEY_ROW as i32 / 2;
        for &(x0, key) in row {
            let x0 = x0 as i32;
            let style = key.colour.stroke_width(2);
            if key.dashed {
                for d in [0, 8, 16] {
                    top.draw(&PathElement::new([(x0 + d, mid), (x0 + d + 5, mid)], style))?;
                }
            } else {
                top.draw(&PathElement::new([(x0, mid), (x0 + 20, mid)], style))?;
            }
            let text = TextStyle::from(font.clone()).pos(Pos::new(HPos::Left, VPos::Center));
            top.draw_text(&key.label, &text, (x0 + 26, mid))?;
        }
    }
    let plot_width = width.saturating_sub(Y_LABEL_AREA + 2 * MARGIN);
    let plot_height = height.saturating_sub(head + X_LABEL_AREA + 2 * MARGIN);
    let (xa, ya) = (x.ticks(plot_width, 75), y.ticks(plot_height, 32));
    let coord = |range: &Range<f64>, a: &Axis| Ticked {
        inner: range.clone().into(),
        ticks: a.ticks.iter().map(|t| t.0).collect(),
    };
    let mut chart = ChartBuilder::on(&body)
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(coord(&x.range, &xa), coord(&y.range, &ya))?;
    let x_label = |v: &f64| label_at(&xa.ticks, *v);
    let y_label = |v: &f64| label_at(&ya.ticks, *v);
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(xa.title.as_str())
        .y_desc(ya.title.as_str())
        .x_label_formatter(&x_label)
        .y_label_formatter(&y_label)
        .bold_line_style(BLACK.mix(0.15));
    if matches!(x.scale, Scale::Names(_)) {
        mesh.disable_x_mesh();
    }
    mesh.draw()?;
    Ok(chart)
}

/// Writes the PNG; errors name the file.
fn finish(path: &Path, drawn: DrawResult<()>) -> Result<(), String> {
    drawn.map_err(|e| format!("{}: cannot draw the plot: {e}", path.display()))
}

fn keys(series: &[Series], dashed_last: bool) -> Vec<Key> {
    series
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let (colour, dashed) = style_of(k, series.len(), dashed_last);
            Key {
                label: s.label.clone(),
                colour,
                dashed,
            }
        })
        .collect()
}

/// Colour of series `k` of `n`, and whether it is drawn dashed (the last, in black, when it is
/// the reference).
fn style_of(k: usize, n: usize, black_last: bool) -> (RGBColor, bool) {
    if black_last && k + 1 == n {
        (BLACK, true)
    } else {
        (COLOURS[k % COLOURS.len()], false)
    }
}

// ---------------------------------------------------------------------------------------------
// Charts

/// Line plot to a 1000 × 600 PNG; with `dashed_last` the last series (the analytic reference)
/// is drawn dashed in black.
pub fn line_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    dashed_last: bool,
) -> Result<(), String> {
    finish(
        path,
        panels(
            path,
            title,
            x_label,
            y_label,
            &[(String::new(), series)],
            dashed_last,
            &[],
            600,
        ),
    )
}

/// A vertical error bar at `x` from `lo` to `hi`, with caps of half-width `cap` (in x units).
fn error_bar(x: f64, lo: f64, hi: f64, cap: f64, colour: RGBColor) -> [PathElement<(f64, f64)>; 3] {
    let style = colour.stroke_width(1);
    [
        PathElement::new(vec![(x, lo), (x, hi)], style),
        PathElement::new(vec![(x - cap, lo), (x + cap, lo)], style),
        PathElement::new(vec![(x - cap, hi), (x + cap, hi)], style),
    ]
}

/// [`panels_plot`] with ± error bars: `errors[p][s]` the standard errors of the points of
/// series `s` of panel `p` (empty: none).
pub fn panels_plot_with_errors(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    panels_in: &[(String, Vec<Series>)],
    errors: &[Vec<Vec<f64>>],
) -> Result<(), String> {
    let borrowed: Vec<(String, &[Series])> = panels_in
        .iter()
        .map(|(t, s)| (t.clone(), s.as_slice()))
        .collect();
    let height = 60 + 300 * borrowed.len().max(1) as u32;
    finish(
        path,
        panels(
            path, title, x_label, y_label, &borrowed, false, errors, height,
        ),
    )
}

/// Stacked panels, one per entry (panel title, series), sharing the x label; 300 px each.
pub fn panels_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    panels_in: &[(String, Vec<Series>)],
) -> Result<(), String> {
    panels_plot_with_errors(path, title, x_label, y_label, panels_in, &[])
}

/// Stacked panels; `errors[p][s][i]`, when given, is the ±error bar of point `i` of series `s`
/// of panel `p` (the y range then holds the bars).
#[allow(clippy::too_many_arguments)]
fn panels(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    panels: &[(String, &[Series])],
    dashed_last: bool,
    errors: &[Vec<Vec<f64>>],
    height: u32,
) -> DrawResult<()> {
    let (root, areas) = canvas(path, (WIDTH, height), title, (panels.len().max(1), 1))?;
    for (p, ((panel_title, series), area)) in panels.iter().zip(areas).enumerate() {
        let (x_range, mut y_range) = ranges(series);
        let cap = 0.01 * (x_range.end - x_range.start);
        let bars: Vec<(usize, f64, f64, f64)> = series
            .iter()
            .enumerate()
            .flat_map(|(k, s)| {
                let e = errors.get(p).and_then(|e| e.get(k));
                s.x.iter()
                    .zip(s.y)
                    .enumerate()
                    .filter_map(move |(i, (&x, &y))| {
                        let e = e.and_then(|e| e.get(i)).copied().unwrap_or(0.0);
                        (e.is_finite() && e > 0.0 && y.is_finite()).then_some((k, x, y - e, y + e))
                    })
            })
            .collect();
        for &(_, _, lo, hi) in &bars {
            y_range = y_range.start.min(lo)..y_range.end.max(hi);
        }
        let mut chart = frame(
            &area,
            panel_title,
            &keys(series, dashed_last),
            AxisSpec::new(x_label, x_range, Scale::Linear),
            AxisSpec::new(y_label, y_range, Scale::Linear),
        )?;
        for (k, s) in series.iter().enumerate() {
            let points = decimate(s.x, s.y, 4 * WIDTH as usize);
            let (colour, dashed) = style_of(k, series.len(), dashed_last);
            // Width 1: plotters draws wider lines as polygons whose miter joins spike on
            // zig-zag data (an alternating force).
            let style = colour.stroke_width(1);
            if dashed {
                chart.draw_series(DashedLineSeries::new(points, 6, 4, style))?;
            } else {
                // a few points (a study, a convergence): marked, the earlier series' marks
                // larger so that equal points of several series all show
                if points.len() <= MARKED_POINTS {
                    let radius = 3 + (series.len() - 1 - k).min(4) as i32;
                    let marks = points
                        .iter()
                        .map(|&p| Circle::new(p, radius, colour.filled()));
                    chart.draw_series(marks)?;
                }
                chart.draw_series(LineSeries::new(points, style))?;
            }
        }
        for &(k, x, lo, hi) in &bars {
            let (colour, _) = style_of(k, series.len(), dashed_last);
            chart.draw_series(error_bar(x, lo, hi, cap, colour))?;
        }
    }
    root.present()?;
    Ok(())
}

/// Square panels of y against x with equal scales (orbits), two per row; in each panel the
/// last series (the outline) is drawn in black.
pub fn xy_panels(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    panels: &[(String, Vec<Series>)],
) -> Result<(), String> {
    let columns = panels.len().clamp(1, 2);
    let rows = panels.len().div_ceil(columns).max(1);
    let side = WIDTH / columns as u32;
    let size = (WIDTH, 40 + side * rows as u32);
    draw_panels(
        path,
        size,
        title,
        (rows, columns),
        panels,
        |(panel_title, series), area| {
            let (xr, yr) = ranges(series);
            // equal scales: the larger half-span on both axes, about the centre
            let half = 0.5 * (xr.end - xr.start).max(yr.end - yr.start);
            let (cx, cy) = (0.5 * (xr.start + xr.end), 0.5 * (yr.start + yr.end));
            let (xr, yr) = (cx - half..cx + half, cy - half..cy + half);
            // one prefix for both axes
            let magnitude = [xr.start, xr.end, yr.start, yr.end]
                .iter()
                .fold(0.0, |m: f64, v| m.max(v.abs()));
            let mut chart = frame(
                area,
                panel_title,
                &keys(series, false)
                    .into_iter()
                    .enumerate()
                    .map(|(k, key)| Key {
                        colour: if k + 1 == series.len() {
                            BLACK
                        } else {
                            key.colour
                        },
                        ..key
                    })
                    .collect::<Vec<_>>(),
                AxisSpec::new(x_label, xr, Scale::LinearFor(magnitude)),
                AxisSpec::new(y_label, yr, Scale::LinearFor(magnitude)),
            )?;
            for (k, s) in series.iter().enumerate() {
                let colour = if k + 1 == series.len() {
                    BLACK
                } else {
                    COLOURS[k % COLOURS.len()]
                };
                let n = s.x.len().min(s.y.len());
                // at most 20 000 points of the orbit, evenly taken
                let stride = n.div_ceil(20_000).max(1);
                let points = (0..n).step_by(stride).map(|i| (s.x[i], s.y[i]));
                chart.draw_series(LineSeries::new(points, colour.stroke_width(1)))?;
            }
            Ok(())
        },
    )
}

/// Stacked panels of bar charts, one per entry (panel title, bars, labelled under the x axis);
/// 300 px each.
pub fn bar_panels(
    path: &Path,
    title: &str,
    y_label: &str,
    panels: &[(String, Vec<Bar>)],
) -> Result<(), String> {
    let backend = BitMapBackend::new(path, stacked_size(panels.len()));
    finish(path, draw_bars(backend, title, y_label, panels))
}

fn draw_bars(
    backend: BitMapBackend,
    title: &str,
    y_label: &str,
    panels: &[(String, Vec<Bar>)],
) -> DrawResult<()> {
    let (root, areas) = canvas_on(backend, title, (panels.len().max(1), 1))?;
    for ((panel_title, bars), area) in panels.iter().zip(areas) {
        let names: Vec<String> = bars.iter().map(|b| b.label.clone()).collect();
        let value = |b: &Bar| if b.value.is_finite() { b.value } else { 0.0 };
        let error = |b: &Bar| {
            if b.error.is_finite() {
                b.error.abs()
            } else {
                0.0
            }
        };
        let top = bars.iter().map(|b| value(b) + error(b)).fold(0.0, f64::max);
        let bottom = bars.iter().map(|b| value(b) - error(b)).fold(0.0, f64::min);
        let (bottom, top) = if top > bottom {
            (1.1 * bottom, 1.1 * top)
        } else {
            (0.0, 1.0)
        };
        let mut chart = frame(
            &area,
            panel_title,
            &[],
            AxisSpec::new("", 0.0..bars.len().max(1) as f64, Scale::Names(&names)),
            AxisSpec::new(y_label, bottom..top, Scale::Linear),
        )?;
        chart.draw_series(bars.iter().enumerate().map(|(i, b)| {
            let x = i as f64;
            Rectangle::new([(x + 0.1, 0.0), (x + 0.9, value(b))], COLOURS[0].filled())
        }))?;
        // ± one standard error
        for (i, b) in bars.iter().enumerate().filter(|(_, b)| error(b) > 0.0) {
            let (x, lo, hi) = (i as f64 + 0.5, value(b) - error(b), value(b) + error(b));
            chart.draw_series(error_bar(x, lo, hi, 0.1, BLACK))?;
        }
    }
    root.present()?;
    Ok(())
}

/// Stacked panels of histograms on a logarithmic x axis (`x_label` in the unit of the bins'
/// edges), one per entry (panel title, bins); 300 px each.
pub fn histogram_panels(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    panels: &[(String, Vec<Bin>)],
) -> Result<(), String> {
    let log_bins = |bins: &[Bin]| -> Vec<(f64, f64, usize)> {
        bins.iter()
            .filter(|b| b.lo > 0.0 && b.hi > b.lo && b.hi.is_finite())
            .map(|b| (b.lo.log10(), b.hi.log10(), b.count))
            .collect()
    };
    // one x range for every panel (they compare), with 3 % margins
    let all: Vec<_> = panels.iter().flat_map(|(_, b)| log_bins(b)).collect();
    let lo = all.iter().map(|b| b.0).fold(f64::INFINITY, f64::min);
    let hi = all.iter().map(|b| b.1).fold(f64::NEG_INFINITY, f64::max);
    let x_range = if lo < hi {
        let pad = 0.03 * (hi - lo);
        lo - pad..hi + pad
    } else {
        0.0..1.0
    };
    let (size, grid) = (stacked_size(panels.len()), (panels.len().max(1), 1));
    draw_panels(
        path,
        size,
        title,
        grid,
        panels,
        |(panel_title, bins), area| {
            let bins = log_bins(bins);
            let most = bins.iter().map(|b| b.2).max().unwrap_or(0);
            // counts: at least 0..5, so that the ticks are whole numbers
            let y_range = 0.0..(1.1 * most as f64).max(5.0);
            let mut chart = frame(
                area,
                panel_title,
                &[],
                AxisSpec::new(x_label, x_range.clone(), Scale::Log10),
                AxisSpec::new(y_label, y_range, Scale::Linear),
            )?;
            chart.draw_series(bins.iter().map(|&(a, b, count)| {
                let gap = 0.04 * (b - a);
                Rectangle::new(
                    [(a + gap, 0.0), (b - gap, count as f64)],
                    COLOURS[0].filled(),
                )
            }))?;
            Ok(())
        },
    )
}

/// A canvas of `size` with `title` and a grid of panels, one drawn by `draw` per entry of
/// `panels`, written as a PNG at `path`.
fn draw_panels<P>(
    path: &Path,
    size: (u32, u32),
    title: &str,
    grid: (usize, usize),
    panels: &[P],
    mut draw: impl FnMut(&P, &Area) -> DrawResult<()>,
) -> Result<(), String> {
    let mut drawn = || -> DrawResult<()> {
        let (root, areas) = canvas(path, size, title, grid)?;
        for (panel, area) in panels.iter().zip(&areas) {
            draw(panel, area)?;
        }
        root.present()?;
        Ok(())
    };
    finish(path, drawn())
}

/// Axis ranges from the finite data, with 5 % margins; never empty.
fn ranges(series: &[Series]) -> (Range<f64>, Range<f64>) {
    let bounds = |vals: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = vals
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        if !lo.is_finite() {
            return 0.0..1.0;
        }
        let span = hi - lo;
        let pad = if span > 0.0 {
            0.05 * span
        } else if lo != 0.0 {
            0.5 * lo.abs()
        } else {
            1.0
        };
        (lo - pad)..(hi + pad)
    };
    (
        bounds(&mut series.iter().flat_map(|s| s.x.iter().copied())),
        bounds(&mut series.iter().flat_map(|s| s.y.iter().copied())),
    )
}

/// At most `2 × columns` points: min and max of y in each of `columns` x-bins, in x order, so
/// that peaks stay visible.
fn decimate(x: &[f64], y: &[f64], columns: usize) -> Vec<(f64, f64)> {
    let n = x.len().min(y.len());
    if n <= 2 * columns {
        return (0..n).map(|i| (x[i], y[i])).collect();
    }
    let per = n.div_ceil(columns);
    let mut out = Vec::with_capacity(2 * columns);
    for start in (0..n).step_by(per) {
        let end = (start + per).min(n);
        let (mut imin, mut imax) = (start, start);
        for i in start..end {
            if y[i] < y[imin] {
                imin = i;
            }
            if y[i] > y[imax] {
                imax = i;
            }
        }
        let (a, b) = if imin <= imax {
            (imin, imax)
        } else {
            (imax, imin)
        };
        out.push((x[a], y[a]));
        if b != a {
            out.push((x[b], y[b]));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png_size(path: &Path) -> (u32, u32) {
        let bytes = std::fs::read(path).expect("png written");
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
        let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
        (w, h)
    }

    /// Ranges at the edges of the floating-point numbers (a wear depth of 5e-324 m from a
    /// mutated case panicked allocating ticks): at most a few ticks, no panic.
    #[test]
    fn ranges_at_the_edges_of_the_floats_have_few_ticks() {
        for range in [
            0.0..5e-324,
            0.0..1e-320,
            -1e-310..1e-310,
            0.0..f64::MAX,
            -f64::MAX..f64::MAX,
            1e300..1.0000000001e300,
        ] {
            let a = axis("depth (m)", range.clone(), 5);
            assert!(a.ticks.len() <= 21, "{range:?}: {a:?}");
        }
    }

    fn labels(a: &Axis) -> Vec<&str> {
        a.ticks.iter().map(|t| t.1.as_str()).collect()
    }

    /// Every tick of an axis: inside the range, its label the position divided by the prefix's
    /// factor, all labels with the same number of decimals.
    fn check_ticks(a: &Axis, range: Range<f64>, factor: f64) {
        assert!(a.ticks.len() >= 2, "{a:?}");
        let decimals = |s: &str| s.split_once('.').map_or(0, |(_, d)| d.len());
        let d0 = decimals(&a.ticks[0].1);
        for (x, label) in &a.ticks {
            assert!(
                range.start - 1e-12 <= *x && *x <= range.end + 1e-12,
                "{x} {range:?}"
            );
            let v: f64 = label.parse().unwrap();
            assert!(
                (v * factor - x).abs() <= 1e-9 * factor.max(x.abs()),
                "{v} {x}"
            );
            assert_eq!(decimals(label), d0, "{a:?}");
        }
    }

    #[test]
    fn axes_take_the_si_prefix_of_their_range_and_alike_tick_labels() {
        // the wear axis that mixed "0.01" and "8.000e-3"
        let a = axis("wear work rate (W)", 0.0..8e-3, 8);
        assert_eq!(a.title, "wear work rate (mW)");
        assert_eq!(labels(&a), ["0", "1", "2", "3", "4", "5", "6", "7", "8"]);
        check_ticks(&a, 0.0..8e-3, 1e-3);
        let a = axis("wear work rate (W)", 0.0..0.021, 5);
        assert_eq!(a.title, "wear work rate (mW)");
        assert_eq!(labels(&a), ["0", "5", "10", "15", "20"]);
        // times that printed as 5.000e-4 s
        let a = axis("t (s)", 0.0..5e-4, 5);
        assert_eq!(a.title, "t (µs)");
        assert_eq!(labels(&a), ["0", "100", "200", "300", "400", "500"]);
        check_ticks(&a, 0.0..5e-4, 1e-6);
        let a = axis("t (s)", 0.0..4e-3, 8);
        assert_eq!(a.title, "t (ms)");
        assert_eq!(
            labels(&a),
            [
                "0.0", "0.5", "1.0", "1.5", "2.0", "2.5", "3.0", "3.5", "4.0"
            ]
        );
        // no kiloseconds
        let a = axis("t (s)", 0.0..2000.0, 4);
        assert_eq!(a.title, "t (s)");
        assert_eq!(labels(&a), ["0", "500", "1000", "1500", "2000"]);
        // a displacement about zero
        let a = axis("e1 (m)", -2e-4..2e-4, 4);
        assert_eq!(a.title, "e1 (µm)");
        assert_eq!(labels(&a), ["-200", "-100", "0", "100", "200"]);
        check_ticks(&a, -2e-4..2e-4, 1e-6);
        // forces
        let a = axis("force (N)", 0.0..1200.0, 6);
        assert_eq!(a.title, "force (kN)");
        assert_eq!(
            labels(&a),
            ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0", "1.2"]
        );
        check_ticks(&a, 0.0..1200.0, 1e3);
        let a = axis("force (N)", -5.0..290.0, 6);
        assert_eq!(a.title, "force (N)");
        assert_eq!(labels(&a), ["0", "50", "100", "150", "200", "250"]);
        // compound units: the prefix on the first symbol
        let a = axis("normal stiffness (N/m)", 0.0..5e6, 5);
        assert_eq!(a.title, "normal stiffness (MN/m)");
        assert_eq!(labels(&a), ["0", "1", "2", "3", "4", "5"]);
        // a padded range: the ticks stay inside it
        let a = axis("t (s)", -0.1..2.1, 10);
        assert_eq!(a.title, "t (s)");
        assert_eq!(a.ticks.first().map(|t| t.1.as_str()), Some("0.0"));
        assert_eq!(a.ticks.last().map(|t| t.1.as_str()), Some("2.0"));
        check_ticks(&a, -0.1..2.1, 1.0);
    }

    #[test]
    fn axes_without_a_prefixed_unit_take_a_common_factor() {
        let a = axis("displacement", -3e-5..3e-5, 6);
        assert_eq!(a.title, "displacement (×10⁻⁶)");
        assert_eq!(labels(&a), ["-30", "-20", "-10", "0", "10", "20", "30"]);
        check_ticks(&a, -3e-5..3e-5, 1e-6);
        let a = axis("impacts", 0.0..35.0, 7);
        assert_eq!(a.title, "impacts");
        assert_eq!(labels(&a), ["0", "5", "10", "15", "20", "25", "30", "35"]);
        let a = axis("log10(relative error)", -6.2..-0.5, 6);
        assert_eq!(a.title, "log10(relative error)");
        assert_eq!(labels(&a), ["-6", "-5", "-4", "-3", "-2", "-1"]);
        let a = axis("fraction of the time", 0.0..0.85, 5);
        assert_eq!(labels(&a), ["0.0", "0.2", "0.4", "0.6", "0.8"]);
    }

    #[test]
    fn log_axes_tick_at_1_2_5_each_label_with_its_prefix() {
        // peak forces from 0.15 N to 100 N
        let a = log_axis("peak force (N)", 0.15f64.log10()..2.0, 12);
        assert_eq!(a.title, "peak force (log scale)");
        assert_eq!(
            labels(&a),
            [
                "200 mN", "500 mN", "1 N", "2 N", "5 N", "10 N", "20 N", "50 N", "100 N"
            ]
        );
        let prefix = |l: &str| match l.split_once(' ').map(|(_, u)| u) {
            Some("mN") => 1e-3,
            Some("N") => 1.0,
            Some("kN") => 1e3,
            other => panic!("{other:?}"),
        };
        for (x, label) in &a.ticks {
            let v: f64 = label.split(' ').next().unwrap().parse().unwrap();
            assert!(
                ((v * prefix(label)).log10() - x).abs() < 1e-9,
                "{label} {x}"
            );
        }
        // many decades: powers of ten only
        let a = log_axis("peak force (N)", -3.0..3.5, 8);
        assert_eq!(
            labels(&a),
            ["1 mN", "10 mN", "100 mN", "1 N", "10 N", "100 N", "1 kN"]
        );
        // no unit: plain numbers
        let a = log_axis("ratio", -1.0..1.0, 8);
        assert_eq!(labels(&a), ["0.1", "0.2", "0.5", "1", "2", "5", "10"]);
    }

    #[test]
    fn category_names_are_thinned_to_fit() {
        let names: Vec<String> = (1..=40).map(|i| format!("plate{i}")).collect();
        let a = names_axis("", &names, 900);
        // 7 characters: about 65 px each, 13 fit in 900 px → every 4th
        assert!(a.ticks.len() * (7 * 7 + 16) <= 900, "{}", a.ticks.len());
        assert_eq!(a.ticks[0], (0.5, "plate1".to_string()));
        assert_eq!(a.ticks[1].1, "plate5");
        let few = names_axis("", &names[..5], 900);
        assert_eq!(few.ticks.len(), 5);
    }

    #[test]
    fn plots_are_pngs_of_the_expected_size() {
        let dir = std::env::temp_dir().join(format!("fretdyn-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let x: Vec<f64> = (0..100_000).map(|i| i as f64 * 1e-5).collect();
        let y: Vec<f64> = x.iter().map(|t| (50.0 * t).sin()).collect();
        let flat = vec![2.0; x.len()];
        let s = || {
            vec![
                Series {
                    label: "sin".into(),
                    x: &x,
                    y: &y,
                },
                Series {
                    label: "flat".into(),
                    x: &x,
                    y: &flat,
                },
            ]
        };
        let line = dir.join("line.png");
        line_plot(&line, "title", "t (s)", "y", &s(), true).unwrap();
        assert_eq!(png_size(&line), (1000, 600));
        let stacked = dir.join("panels.png");
        panels_plot(
            &stacked,
            "title",
            "t",
            "y",
            &[("a".into(), s()), ("b".into(), vec![])],
        )
        .unwrap();
        assert_eq!(png_size(&stacked), (1000, 660));
        let hist = dir.join("hist.png");
        let bins = (0..30)
            .map(|i| Bin {
                lo: 10f64.powf(i as f64 / 5.0),
                hi: 10f64.powf((i + 1) as f64 / 5.0),
                count: i,
            })
            .collect();
        histogram_panels(&hist, "t", "peak (N)", "impacts", &[("a".into(), bins)]).unwrap();
        assert_eq!(png_size(&hist), (1000, 360));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn bars_fill_the_axis_without_an_empty_slot() {
        // five bars of equal height, drawn into a buffer of pixels: in a row across the bars,
        // the last bar ends within a slot's margin of the plotting area's right edge
        let (w, h) = stacked_size(1);
        let mut pixels = vec![0u8; 3 * (w * h) as usize];
        let bars: Vec<Bar> = (1..=5)
            .map(|i| Bar {
                label: format!("plate{i}"),
                value: 1.0,
                error: 0.0,
            })
            .collect();
        let backend = BitMapBackend::with_buffer(&mut pixels, (w, h));
        draw_bars(backend, "t", "rate (W)", &[("p".into(), bars)]).unwrap();
        let row = (h / 2) as usize;
        let bar_colour = |x: usize| {
            let i = 3 * (row * w as usize + x);
            pixels[i..i + 3] == [COLOURS[0].0, COLOURS[0].1, COLOURS[0].2]
        };
        let columns: Vec<usize> = (0..w as usize).filter(|&x| bar_colour(x)).collect();
        let (first, last) = (columns[0], columns[columns.len() - 1]);
        // the plotting area spans [MARGIN + Y_LABEL_AREA, w - MARGIN]; 5 slots
        let (left, right) = ((MARGIN + Y_LABEL_AREA) as usize, (w - MARGIN) as usize);
        let slot = (right - left) as f64 / 5.0;
        assert!(
            (first - left) as f64 <= 0.15 * slot,
            "{first} {left} {slot}"
        );
        assert!(
            (right - last) as f64 <= 0.15 * slot,
            "{last} {right} {slot}"
        );
        // five separate bars
        let runs = columns.windows(2).filter(|p| p[1] > p[0] + 1).count() + 1;
        assert_eq!(runs, 5);
    }

    #[test]
    fn decimation_keeps_the_extremes() {
        let x: Vec<f64> = (0..10_000).map(f64::from).collect();
        let mut y = vec![0.0; 10_000];
        y[5_003] = 7.0;
        y[777] = -3.0;
        let d = decimate(&x, &y, 100);
        assert!(d.len() <= 200);
        assert!(d.contains(&(5_003.0, 7.0)) && d.contains(&(777.0, -3.0)));
    }
}
