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
#[derive(Clone)]
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
// What a figure promises, recorded as it is drawn

/// An axis as drawn: title, ticks (position in plot coordinates, label), range, and whether
/// the coordinates are log10 of the values.
#[derive(Debug, Default, Clone)]
pub struct AxisRecord {
    pub title: String,
    pub ticks: Vec<(f64, String)>,
    pub range: (f64, f64),
    pub log: bool,
}

/// A panel as drawn: its caption (and its width in pixels, the panel's width), axes, legend
/// entries, curves, reference lines, error bars and bars.
#[derive(Debug, Default, Clone)]
pub struct PanelRecord {
    pub caption: String,
    pub caption_width: u32,
    pub width: u32,
    pub x: AxisRecord,
    pub y: AxisRecord,
    /// Legend entries, each drawn beside a short line of its style.
    pub keys: Vec<String>,
    /// Curves: label, points drawn, smallest and largest y (in the data's unit), points
    /// marked.
    pub series: Vec<(String, usize, f64, f64, bool)>,
    /// Reference lines: label, position, vertical (at an x) or horizontal (at a y).
    pub lines: Vec<(String, f64, bool)>,
    /// Error bars: (at, from, to), vertical (x, y₀, y₁) or horizontal (y, x₀, x₁).
    pub error_bars: Vec<(f64, f64, f64, bool)>,
    /// Shaded bands: label and number of points.
    pub bands: Vec<(String, usize)>,
    /// Bars: label, value drawn, ± error drawn (0: no bar), x from and to.
    pub bars: Vec<(String, f64, f64, f64, f64)>,
}

/// A figure as drawn: canvas size, title lines (text, width in pixels, font size), panels.
#[derive(Debug, Default, Clone)]
pub struct Figure {
    pub size: (u32, u32),
    pub title: Vec<(String, u32, u32)>,
    pub panels: Vec<PanelRecord>,
}

impl Figure {
    /// The figure as JSON (what the tests read back).
    pub fn to_json(&self) -> serde_json::Value {
        let axis = |a: &AxisRecord| {
            serde_json::json!({
                "title": a.title,
                "ticks": a.ticks.iter().map(|(p, l)| serde_json::json!([p, l])).collect::<Vec<_>>(),
                "range": [a.range.0, a.range.1],
                "log": a.log,
            })
        };
        serde_json::json!({
            "size": [self.size.0, self.size.1],
            "title": self.title.iter().map(|(t, w, f)| serde_json::json!({"text": t, "width": w, "font": f})).collect::<Vec<_>>(),
            "panels": self.panels.iter().map(|p| serde_json::json!({
                "caption": p.caption,
                "caption_width": p.caption_width,
                "width": p.width,
                "x": axis(&p.x),
                "y": axis(&p.y),
                "keys": p.keys,
                "series": p.series.iter().map(|(l, n, lo, hi, marked)| serde_json::json!({"label": l, "points": n, "min_y": lo, "max_y": hi, "marked": marked})).collect::<Vec<_>>(),
                "lines": p.lines.iter().map(|(l, at, v)| serde_json::json!({"label": l, "at": at, "vertical": v})).collect::<Vec<_>>(),
                "error_bars": p.error_bars.iter().map(|(at, a, b, v)| serde_json::json!({"at": at, "from": a, "to": b, "vertical": v})).collect::<Vec<_>>(),
                "bands": p.bands.iter().map(|(l, n)| serde_json::json!({"label": l, "points": n})).collect::<Vec<_>>(),
                "bars": p.bars.iter().map(|(l, v, e, x0, x1)| serde_json::json!({"label": l, "value": v, "error": e, "from": x0, "to": x1})).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
        })
    }
}

/// Environment variable: when set, every PNG is written with `<file>.png.json` beside it, the
/// [`Figure`] as drawn, for the tests to read back what a figure promises.
pub const RECORD_VARIABLE: &str = "FRETDYN_FIGURE_RECORD";

thread_local! {
    static RECORD: std::cell::RefCell<Option<Figure>> = const { std::cell::RefCell::new(None) };
}

fn start_record(size: (u32, u32), title: Vec<(String, u32, u32)>) {
    RECORD.with(|r| {
        *r.borrow_mut() = Some(Figure {
            size,
            title,
            panels: Vec::new(),
        })
    });
}

/// Adds to the record of the panel being drawn.
fn record(f: impl FnOnce(&mut PanelRecord)) {
    RECORD.with(|r| {
        if let Some(p) = r
            .borrow_mut()
            .as_mut()
            .and_then(|fig| fig.panels.last_mut())
        {
            f(p);
        }
    });
}

/// The record of the figure drawn last on this thread.
pub fn take_record() -> Option<Figure> {
    RECORD.with(|r| r.borrow_mut().take())
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
/// (rows, columns) below the title. A title wider than the canvas is wrapped (and its font
/// shrunk when a word would not fit), the canvas taller by the extra lines ([`titled_size`]).
fn canvas<'p>(
    path: &'p Path,
    size: (u32, u32),
    title: &str,
    grid: (usize, usize),
) -> DrawResult<(Area<'p>, Vec<Area<'p>>)> {
    canvas_on(
        BitMapBackend::new(path, titled_size(size, title)),
        title,
        grid,
    )
}

/// Font size of a figure's title.
const TITLE_FONT: u32 = 22;
/// Smallest font a title is shrunk to before it is wrapped on more than two lines.
const TITLE_FONT_MIN: u32 = 14;

/// The width in pixels of `text` in the embedded font at `size` px.
pub fn text_width(text: &str, size: u32) -> u32 {
    register_font();
    ("sans-serif", size)
        .into_font()
        .box_size(text)
        .map_or(0, |(w, _)| w)
}

/// The lines of a title on a canvas `width` wide, and their font size: one line when it fits;
/// else wrapped at spaces (after an em dash or a colon where one is near), in at most two
/// lines at [`TITLE_FONT`] or in a font shrunk down to [`TITLE_FONT_MIN`], else in as many
/// lines as it takes.
pub fn title_lines(title: &str, width: u32) -> (Vec<String>, u32) {
    let room = width.saturating_sub(2 * MARGIN);
    let wrap = |size: u32| -> Vec<String> {
        let mut lines: Vec<String> = Vec::new();
        let mut line = String::new();
        for word in title.split(' ') {
            let candidate = if line.is_empty() {
                word.to_string()
            } else {
                format!("{line} {word}")
            };
            if !line.is_empty() && text_width(&candidate, size) > room {
                lines.push(std::mem::take(&mut line));
                line = word.to_string();
            } else {
                line = candidate;
            }
        }
        lines.push(line);
        lines
    };
    let fits = |lines: &[String], size: u32| lines.iter().all(|l| text_width(l, size) <= room);
    if fits(&[title.to_string()], TITLE_FONT) {
        return (vec![title.to_string()], TITLE_FONT);
    }
    // the case's title, then what the figure shows
    if let Some((case, what)) = title.rsplit_once(" — ") {
        let lines = [case.to_string(), format!("— {what}")];
        if fits(&lines, TITLE_FONT) {
            return (lines.to_vec(), TITLE_FONT);
        }
    }
    let mut size = TITLE_FONT;
    loop {
        let lines = wrap(size);
        if (lines.len() <= 2 && fits(&lines, size)) || size <= TITLE_FONT_MIN {
            return (lines, size);
        }
        size -= 2;
    }
}

/// Height of the title band of a canvas `width` wide.
fn title_height(title: &str, width: u32) -> u32 {
    let (lines, size) = title_lines(title, width);
    10 + lines.len() as u32 * (size + 8)
}

/// The size of a canvas meant as `size` with a one-line title, grown by the extra lines of
/// `title`.
pub fn titled_size(size: (u32, u32), title: &str) -> (u32, u32) {
    let one = 10 + TITLE_FONT + 8;
    (
        size.0,
        size.1 + title_height(title, size.0).saturating_sub(one),
    )
}

/// [`canvas`] on a backend (a file or a buffer of pixels) already of [`titled_size`].
fn canvas_on<'p>(
    backend: BitMapBackend<'p>,
    title: &str,
    grid: (usize, usize),
) -> DrawResult<(Area<'p>, Vec<Area<'p>>)> {
    register_font();
    let root = backend.into_drawing_area();
    root.fill(&WHITE)?;
    let (width, height) = root.dim_in_pixel();
    let (lines, size) = title_lines(title, width);
    let style =
        TextStyle::from(("sans-serif", size).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
    for (i, line) in lines.iter().enumerate() {
        root.draw_text(
            line,
            &style,
            (width as i32 / 2, 8 + i as i32 * (size as i32 + 8)),
        )?;
    }
    start_record(
        (width, height),
        lines
            .iter()
            .map(|l| (l.clone(), text_width(l, size), size))
            .collect(),
    );
    let (_, body) = root.split_vertically(title_height(title, width));
    let panels = body.split_evenly(grid);
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
    // a caption wider than the panel: a smaller font
    let mut caption_font = 16;
    while caption_font > 9 && text_width(caption, caption_font) > width.saturating_sub(2 * MARGIN) {
        caption_font -= 1;
    }
    if !caption.is_empty() {
        let style = TextStyle::from(("sans-serif", caption_font).into_font())
            .pos(Pos::new(HPos::Center, VPos::Top));
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
    let axis_record = |spec: &AxisSpec, a: &Axis| AxisRecord {
        title: a.title.clone(),
        ticks: a.ticks.clone(),
        range: (spec.range.start, spec.range.end),
        log: matches!(spec.scale, Scale::Log10),
    };
    RECORD.with(|r| {
        if let Some(fig) = r.borrow_mut().as_mut() {
            fig.panels.push(PanelRecord {
                caption: caption.to_string(),
                caption_width: text_width(caption, caption_font),
                width,
                x: axis_record(&x, &xa),
                y: axis_record(&y, &ya),
                keys: keys.iter().map(|k| k.label.clone()).collect(),
                ..PanelRecord::default()
            });
        }
    });
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

/// Writes the PNG (and, with [`RECORD_VARIABLE`] set, its record); errors name the file.
fn finish(path: &Path, drawn: DrawResult<()>) -> Result<(), String> {
    drawn.map_err(|e| format!("{}: cannot draw the plot: {e}", path.display()))?;
    if let Some(figure) = take_record()
        && std::env::var_os(RECORD_VARIABLE).is_some()
    {
        let mut name = path.as_os_str().to_owned();
        name.push(".json");
        std::fs::write(&name, format!("{:#}\n", figure.to_json()))
            .map_err(|e| format!("{}: {e}", Path::new(&name).display()))?;
    }
    Ok(())
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
    let panel = Panel {
        title: String::new(),
        series: series.to_vec(),
        errors: Vec::new(),
        marks: Vec::new(),
    };
    let layout = Layout {
        dashed_last,
        height: Some(600),
        ..Layout::default()
    };
    stacked(path, title, x_label, y_label, &[panel], &layout)
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
    let panels: Vec<Panel> = panels_in
        .iter()
        .enumerate()
        .map(|(p, (t, series))| Panel {
            title: t.clone(),
            series: series.clone(),
            errors: errors.get(p).cloned().unwrap_or_default(),
            marks: Vec::new(),
        })
        .collect();
    stacked(path, title, x_label, y_label, &panels, &Layout::default())
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

/// A reference drawn over a panel's curves, with its legend entry (one per label).
#[derive(Debug, Clone, PartialEq)]
pub enum Mark {
    /// A horizontal dashed line across the panel at `y` (a criterion).
    Level { label: String, y: f64 },
    /// A vertical dashed line across the panel at `x` (a support, the face of an obstacle).
    At { label: String, x: f64 },
    /// A percentile: a vertical segment at `x` from 0 up to `level`, and its interval
    /// `[low, high]` at `level` as a horizontal error bar (a missing bound: to the panel's
    /// edge, without a cap).
    Percentile {
        label: String,
        x: f64,
        level: f64,
        low: Option<f64>,
        high: Option<f64>,
    },
}

impl Mark {
    fn label(&self) -> &str {
        match self {
            Mark::Level { label, .. } | Mark::At { label, .. } | Mark::Percentile { label, .. } => {
                label
            }
        }
    }
}

/// One panel of [`stacked`]: its title, curves, the ± standard error of every point of each
/// curve (`errors[s][i]`; empty: none) and reference marks.
pub struct Panel<'a> {
    pub title: String,
    pub series: Vec<Series<'a>>,
    pub errors: Vec<Vec<f64>>,
    pub marks: Vec<Mark>,
}

/// How the y axes are scaled.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub enum YScale {
    /// Linear, unless every value is positive and they span [`LOG_DECADES`] decades or more.
    #[default]
    Auto,
    Linear,
    Log,
}

/// Positive values spanning this many decades are drawn on a log axis by [`YScale::Auto`].
pub const LOG_DECADES: f64 = 2.0;

/// How the panels of [`stacked`] are drawn together.
#[derive(Debug, Clone, Copy, Default)]
pub struct Layout {
    /// The last series of each panel is the reference, dashed in black.
    pub dashed_last: bool,
    /// One SI prefix on the y axes of every panel (panels that are compared).
    pub same_y_unit: bool,
    /// One y range for every panel.
    pub same_y_limits: bool,
    pub y_scale: YScale,
    /// The x axes' prefix chosen for this magnitude (values in legends written alike).
    pub x_magnitude: Option<f64>,
    /// The errors drawn as a shaded band about each curve rather than bars.
    pub bands: bool,
    /// Height of the canvas (default: 60 px and 300 px a panel).
    pub height: Option<u32>,
}

/// Whether `values`, none negative, have positive ones spanning at least [`LOG_DECADES`]
/// decades (zeros are left out: a log axis does not draw them, and says so).
pub fn spans_decades(values: impl IntoIterator<Item = f64>) -> bool {
    let (mut lo, mut hi, mut any) = (f64::INFINITY, 0.0f64, false);
    for v in values.into_iter().filter(|v| v.is_finite()) {
        if v < 0.0 {
            return false;
        }
        if v == 0.0 {
            continue;
        }
        any = true;
        lo = lo.min(v);
        hi = hi.max(v);
    }
    any && (hi / lo).log10() >= LOG_DECADES
}

/// The SI prefix's factor that [`axis`] gives an axis `label` of values up to `magnitude`,
/// and the prefixed unit (`("mW", 1e-3)`); a unit without prefixes: itself and 1.
pub fn unit_for(label: &str, magnitude: f64) -> (String, f64) {
    let (title, factor) = unit_scale(label, magnitude);
    (split_label(&title).1.to_string(), factor)
}

/// `v` with `digits` significant digits, no exponent (`436`, `0.0123`).
pub fn significant(v: f64, digits: usize) -> String {
    if !(v.is_finite() && v != 0.0) {
        return format!("{v}");
    }
    let decimals = (digits as i32 - 1 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.decimals$}")
}

/// Stacked panels sharing the x label, with error bars or bands, reference marks and the y
/// axes as `layout` says; the PNG at `path`.
pub fn stacked(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    panels: &[Panel],
    layout: &Layout,
) -> Result<(), String> {
    let height = layout
        .height
        .unwrap_or_else(|| stacked_size(panels.len()).1);
    finish(
        path,
        draw_stacked(
            path,
            (WIDTH, height),
            title,
            x_label,
            y_label,
            panels,
            layout,
        ),
    )
}

/// The points of a panel's error bars: (series, x, y − e, y + e) for every point with an
/// error; on a `log` axis a bar reaching below a tenth of its point stops there.
fn error_points(panel: &Panel, log: bool) -> Vec<(usize, f64, f64, f64)> {
    panel
        .series
        .iter()
        .enumerate()
        .flat_map(|(k, s)| {
            let e = panel.errors.get(k);
            s.x.iter()
                .zip(s.y)
                .enumerate()
                .filter_map(move |(i, (&x, &y))| {
                    let e = e.and_then(|e| e.get(i)).copied().unwrap_or(0.0);
                    let lo = if log { (y - e).max(0.1 * y) } else { y - e };
                    (e.is_finite() && e > 0.0 && y.is_finite()).then_some((k, x, lo, y + e))
                })
        })
        .collect()
}

#[allow(clippy::too_many_arguments)]
fn draw_stacked(
    path: &Path,
    size: (u32, u32),
    title: &str,
    x_label: &str,
    y_label: &str,
    panels: &[Panel],
    layout: &Layout,
) -> DrawResult<()> {
    let log = match layout.y_scale {
        YScale::Log => true,
        YScale::Linear => false,
        YScale::Auto => spans_decades(
            panels
                .iter()
                .flat_map(|p| p.series.iter().flat_map(|s| s.y.iter().copied())),
        ),
    };
    // every y value and error bound, per panel: the ranges, the unit, the scale
    let y_values = |p: &Panel| -> Vec<f64> {
        let mut v: Vec<f64> = p.series.iter().flat_map(|s| s.y.iter().copied()).collect();
        for (_, _, lo, hi) in error_points(p, log) {
            v.extend([lo, hi]);
        }
        for m in &p.marks {
            if let Mark::Level { y, .. } = m {
                v.push(*y);
            }
        }
        v.retain(|v| v.is_finite());
        v
    };
    let all_y: Vec<f64> = panels.iter().flat_map(y_values).collect();
    let ty = |v: f64| if log { v.log10() } else { v };
    let y_range_of = |values: &[f64]| {
        let t: Vec<f64> = values
            .iter()
            .filter(|v| !log || **v > 0.0)
            .map(|&v| ty(v))
            .collect();
        padded(
            t.iter().copied().fold(f64::INFINITY, f64::min),
            t.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    };
    let magnitude = all_y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let (root, areas) = canvas(path, size, title, (panels.len().max(1), 1))?;
    for (panel, area) in panels.iter().zip(areas) {
        let series = &panel.series;
        let (mut x_range, _) = ranges(series);
        for m in &panel.marks {
            let xs: Vec<f64> = match m {
                Mark::At { x, .. } => vec![*x],
                Mark::Percentile { x, low, high, .. } => {
                    [Some(*x), *low, *high].into_iter().flatten().collect()
                }
                Mark::Level { .. } => vec![],
            };
            for x in xs.into_iter().filter(|x| x.is_finite()) {
                x_range = x_range.start.min(x)..x_range.end.max(x);
            }
        }
        let y_range = if layout.same_y_limits {
            y_range_of(&all_y)
        } else {
            y_range_of(&y_values(panel))
        };
        let cap = 0.01 * (x_range.end - x_range.start);
        let mut keys = keys(series, layout.dashed_last);
        let mut mark_labels: Vec<&str> = Vec::new();
        for m in &panel.marks {
            if !m.label().is_empty() && !mark_labels.contains(&m.label()) {
                mark_labels.push(m.label());
            }
        }
        let mark_style = |label: &str| -> (RGBColor, bool) {
            let i = mark_labels.iter().position(|l| *l == label).unwrap_or(0);
            match panel.marks.iter().find(|m| m.label() == label) {
                Some(Mark::Level { .. }) => (RGBColor(200, 0, 0), true),
                Some(Mark::At { .. }) => {
                    // the vertical lines' kinds told apart: grey, then brown, purple
                    let kind = mark_labels[..i]
                        .iter()
                        .filter(|l| {
                            matches!(
                                panel.marks.iter().find(|m| m.label() == **l),
                                Some(Mark::At { .. })
                            )
                        })
                        .count();
                    let colours = [RGBColor(110, 110, 110), COLOURS[5], COLOURS[4]];
                    (colours[kind % colours.len()], true)
                }
                _ => (COLOURS[(series.len() + i) % COLOURS.len()], false),
            }
        };
        for label in &mark_labels {
            let (colour, dashed) = mark_style(label);
            keys.push(Key {
                label: label.to_string(),
                colour,
                dashed,
            });
        }
        let x_scale = match layout.x_magnitude {
            Some(m) => Scale::LinearFor(m),
            None => Scale::Linear,
        };
        let y_scale = if log {
            Scale::Log10
        } else if layout.same_y_unit {
            Scale::LinearFor(magnitude)
        } else {
            Scale::Linear
        };
        let zeros = log && series.iter().any(|s| s.y.contains(&0.0));
        let caption = if zeros {
            format!("{} (values of 0 not drawn on the log axis)", panel.title)
        } else {
            panel.title.clone()
        };
        let mut chart = frame(
            &area,
            &caption,
            &keys,
            AxisSpec::new(x_label, x_range.clone(), x_scale),
            AxisSpec::new(y_label, y_range.clone(), y_scale),
        )?;
        let bars = error_points(panel, log);
        if layout.bands {
            for k in 0..series.len() {
                let (colour, _) = style_of(k, series.len(), layout.dashed_last);
                let band: Vec<(f64, f64, f64)> = bars
                    .iter()
                    .filter(|b| b.0 == k && (!log || b.2 > 0.0))
                    .map(|b| (b.1, ty(b.2), ty(b.3)))
                    .collect();
                if band.len() >= 2 {
                    let outline: Vec<(f64, f64)> = band
                        .iter()
                        .map(|b| (b.0, b.2))
                        .chain(band.iter().rev().map(|b| (b.0, b.1)))
                        .collect();
                    chart.draw_series(std::iter::once(Polygon::new(
                        outline,
                        colour.mix(0.2).filled(),
                    )))?;
                    record(|r| r.bands.push((series[k].label.clone(), band.len())));
                }
            }
        }
        for (k, s) in series.iter().enumerate() {
            let points: Vec<(f64, f64)> = decimate(s.x, s.y, 4 * WIDTH as usize)
                .into_iter()
                .filter(|p| !log || p.1 > 0.0)
                .map(|(x, y)| (x, ty(y)))
                .collect();
            let (colour, dashed) = style_of(k, series.len(), layout.dashed_last);
            let finite = || s.y.iter().copied().filter(|v| v.is_finite());
            let (lo, hi) = (
                finite().fold(f64::INFINITY, f64::min),
                finite().fold(f64::NEG_INFINITY, f64::max),
            );
            let marked = !dashed && points.len() <= MARKED_POINTS;
            record(|r| {
                r.series
                    .push((s.label.clone(), points.len(), lo, hi, marked))
            });
            // Width 1: plotters draws wider lines as polygons whose miter joins spike on
            // zig-zag data (an alternating force).
            let style = colour.stroke_width(1);
            if dashed {
                chart.draw_series(DashedLineSeries::new(points, 6, 4, style))?;
            } else {
                // a few points (a study, a convergence): marked, the earlier series' marks
                // larger so that equal points of several series all show
                if marked {
                    let radius = 3 + (series.len() - 1 - k).min(4) as i32;
                    let marks = points
                        .iter()
                        .map(|&p| Circle::new(p, radius, colour.filled()));
                    chart.draw_series(marks)?;
                }
                chart.draw_series(LineSeries::new(points, style))?;
            }
        }
        if !layout.bands {
            for &(k, x, lo, hi) in &bars {
                let (colour, _) = style_of(k, series.len(), layout.dashed_last);
                // on a log axis a bar reaching zero or below stops a decade under the point
                let lo = if log && lo <= 0.0 {
                    (lo + hi) / 20.0
                } else {
                    lo
                };
                chart.draw_series(error_bar(x, ty(lo), ty(hi), cap, colour))?;
                record(|r| r.error_bars.push((x, lo, hi, true)));
            }
        }
        for m in &panel.marks {
            let (colour, _) = mark_style(m.label());
            match m {
                Mark::Level { label, y } => {
                    let y = ty(*y);
                    let line = [(x_range.start, y), (x_range.end, y)];
                    chart.draw_series(DashedLineSeries::new(line, 8, 5, colour.stroke_width(2)))?;
                    let at = if log { 10f64.powf(y) } else { y };
                    record(|r| r.lines.push((label.clone(), at, false)));
                }
                Mark::At { label, x } => {
                    let line = [(*x, y_range.start), (*x, y_range.end)];
                    chart.draw_series(DashedLineSeries::new(line, 6, 4, colour.stroke_width(1)))?;
                    record(|r| r.lines.push((label.clone(), *x, true)));
                }
                Mark::Percentile {
                    label,
                    x,
                    level,
                    low,
                    high,
                } => {
                    let style = colour.stroke_width(2);
                    let level_y = ty(*level);
                    chart.draw_series(std::iter::once(PathElement::new(
                        vec![(*x, if log { y_range.start } else { 0.0 }), (*x, level_y)],
                        style,
                    )))?;
                    record(|r| r.lines.push((label.clone(), *x, true)));
                    let (a, b) = (low.unwrap_or(x_range.start), high.unwrap_or(x_range.end));
                    let h = 0.02 * (y_range.end - y_range.start);
                    chart.draw_series(std::iter::once(PathElement::new(
                        vec![(a, level_y), (b, level_y)],
                        style,
                    )))?;
                    for (bound, at) in [(low, a), (high, b)] {
                        if bound.is_some() {
                            chart.draw_series(std::iter::once(PathElement::new(
                                vec![(at, level_y - h), (at, level_y + h)],
                                style,
                            )))?;
                        }
                    }
                    record(|r| r.error_bars.push((*level, a, b, false)));
                }
            }
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
/// 300 px each. The panels are compared: one unit and one range on their y axes.
pub fn bar_panels(
    path: &Path,
    title: &str,
    y_label: &str,
    panels: &[(String, Vec<Bar>)],
) -> Result<(), String> {
    let backend = BitMapBackend::new(path, titled_size(stacked_size(panels.len()), title));
    finish(path, draw_bars(backend, title, y_label, panels))
}

/// Below this fraction of the largest value of a bar chart a value is round-off (a sum of
/// products over up to 10⁸ steps accumulates ~10⁻⁸ of its terms' size; a bar that short is
/// under a pixel): it reads 0, without an error bar.
pub const ROUND_OFF: f64 = 1e-8;

/// A bar's value and error as drawn: non-finite → 0; round-off ([`ROUND_OFF`] of `largest`)
/// → 0 without an error bar.
pub fn bar_as_drawn(b: &Bar, largest: f64) -> (f64, f64) {
    let value = if b.value.is_finite() { b.value } else { 0.0 };
    let error = if b.error.is_finite() {
        b.error.abs()
    } else {
        0.0
    };
    if value.abs() <= ROUND_OFF * largest {
        (0.0, 0.0)
    } else {
        (value, error)
    }
}

fn draw_bars(
    backend: BitMapBackend,
    title: &str,
    y_label: &str,
    panels: &[(String, Vec<Bar>)],
) -> DrawResult<()> {
    let (root, areas) = canvas_on(backend, title, (panels.len().max(1), 1))?;
    let largest = panels
        .iter()
        .flat_map(|(_, bars)| bars.iter().map(|b| b.value.abs()))
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    let drawn: Vec<Vec<(f64, f64)>> = panels
        .iter()
        .map(|(_, bars)| bars.iter().map(|b| bar_as_drawn(b, largest)).collect())
        .collect();
    let top = drawn
        .iter()
        .flatten()
        .map(|(v, e)| v + e)
        .fold(0.0, f64::max);
    let bottom = drawn
        .iter()
        .flatten()
        .map(|(v, e)| v - e)
        .fold(0.0, f64::min);
    let (bottom, top) = if top > bottom {
        (1.1 * bottom, 1.1 * top)
    } else {
        (0.0, 1.0)
    };
    let magnitude = bottom.abs().max(top.abs());
    for (((panel_title, bars), values), area) in panels.iter().zip(&drawn).zip(areas) {
        let names: Vec<String> = bars.iter().map(|b| b.label.clone()).collect();
        let mut chart = frame(
            &area,
            panel_title,
            &[],
            AxisSpec::new("", 0.0..bars.len().max(1) as f64, Scale::Names(&names)),
            AxisSpec::new(y_label, bottom..top, Scale::LinearFor(magnitude)),
        )?;
        chart.draw_series(values.iter().enumerate().map(|(i, &(v, _))| {
            let x = i as f64;
            Rectangle::new([(x + 0.1, 0.0), (x + 0.9, v)], COLOURS[0].filled())
        }))?;
        for (i, (b, &(v, e))) in bars.iter().zip(values).enumerate() {
            record(|r| {
                r.bars
                    .push((b.label.clone(), v, e, i as f64 + 0.1, i as f64 + 0.9))
            });
            if v == 0.0 {
                // a bar of zero height: its value written
                let style = TextStyle::from(("sans-serif", 13).into_font())
                    .pos(Pos::new(HPos::Center, VPos::Bottom));
                chart.draw_series(std::iter::once(Text::new(
                    "0",
                    (i as f64 + 0.5, 0.0),
                    style,
                )))?;
            }
        }
        // ± one standard error
        for (i, &(v, e)) in values.iter().enumerate().filter(|(_, (_, e))| *e > 0.0) {
            chart.draw_series(error_bar(i as f64 + 0.5, v - e, v + e, 0.1, BLACK))?;
            record(|r| r.error_bars.push((i as f64 + 0.5, v - e, v + e, true)));
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
    // at least a decade, so that a single bin is a bar among ticks, not the whole axis
    let x_range = if lo < hi {
        let pad = (0.03 * (hi - lo)).max(0.5 * (1.0 - (hi - lo)));
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
            for &(a, b, count) in &bins {
                record(|r| r.bars.push((String::new(), count as f64, 0.0, a, b)));
            }
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

/// `lo..hi` with 5 % margins (a single value: ±50 % of it, or ±1 for 0); 0..1 when not
/// finite.
fn padded(lo: f64, hi: f64) -> Range<f64> {
    if !(lo.is_finite() && hi.is_finite()) {
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
}

/// Axis ranges from the finite data, with 5 % margins; never empty.
fn ranges(series: &[Series]) -> (Range<f64>, Range<f64>) {
    let bounds = |vals: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = vals
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        padded(lo, hi)
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
