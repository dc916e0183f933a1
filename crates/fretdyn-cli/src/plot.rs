//! PNG line plots (plotters, bitmap backend). The font is embedded so that plots render on a
//! machine without system fonts.

use std::path::Path;
use std::sync::Once;

use plotters::prelude::*;
use plotters::style::FontStyle;

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

const WIDTH: u32 = 1000;
const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

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
    panels(
        path,
        title,
        x_label,
        y_label,
        &[(String::new(), series)],
        dashed_last,
        600,
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
    let borrowed: Vec<(String, &[Series])> = panels_in
        .iter()
        .map(|(t, s)| (t.clone(), s.as_slice()))
        .collect();
    let height = 60 + 300 * borrowed.len().max(1) as u32;
    panels(path, title, x_label, y_label, &borrowed, false, height)
}

fn panels(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    panels: &[(String, &[Series])],
    dashed_last: bool,
    height: u32,
) -> Result<(), String> {
    register_font();
    let err = |e: &dyn std::fmt::Display| format!("{}: cannot draw the plot: {e}", path.display());
    let root = BitMapBackend::new(path, (WIDTH, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root
        .titled(title, ("sans-serif", 22))
        .map_err(|e| err(&e))?;
    let areas = root.split_evenly((panels.len().max(1), 1));
    for ((panel_title, series), area) in panels.iter().zip(areas) {
        let (x_range, y_range) = ranges(series);
        let mut chart = ChartBuilder::on(&area)
            .caption(panel_title.as_str(), ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d(x_range, y_range)
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .draw()
            .map_err(|e| err(&e))?;
        for (k, s) in series.iter().enumerate() {
            let points = decimate(s.x, s.y, 4 * WIDTH as usize);
            let reference = dashed_last && k + 1 == series.len();
            let colour = if reference {
                BLACK
            } else {
                COLOURS[k % COLOURS.len()]
            };
            // Width 1: plotters draws wider lines as polygons whose miter joins spike on
            // zig-zag data (an alternating force).
            let style = colour.stroke_width(1);
            let drawn = if reference {
                chart.draw_series(DashedLineSeries::new(points, 6, 4, style))
            } else {
                chart.draw_series(LineSeries::new(points, style))
            };
            drawn
                .map_err(|e| err(&e))?
                .label(s.label.clone())
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], style));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))?;
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
    register_font();
    let err = |e: &dyn std::fmt::Display| format!("{}: cannot draw the plot: {e}", path.display());
    let columns = panels.len().clamp(1, 2);
    let rows = panels.len().div_ceil(columns).max(1);
    let side = WIDTH / columns as u32;
    let root = BitMapBackend::new(path, (WIDTH, 40 + side * rows as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root
        .titled(title, ("sans-serif", 22))
        .map_err(|e| err(&e))?;
    let areas = root.split_evenly((rows, columns));
    for ((panel_title, series), area) in panels.iter().zip(areas) {
        let (xr, yr) = ranges(series);
        // equal scales: the larger half-span on both axes, about the centre
        let half = 0.5 * (xr.end - xr.start).max(yr.end - yr.start);
        let (cx, cy) = (0.5 * (xr.start + xr.end), 0.5 * (yr.start + yr.end));
        let mut chart = ChartBuilder::on(&area)
            .caption(panel_title.as_str(), ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d(cx - half..cx + half, cy - half..cy + half)
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_labels(6)
            .y_labels(6)
            .x_desc(x_label)
            .y_desc(y_label)
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .draw()
            .map_err(|e| err(&e))?;
        for (k, s) in series.iter().enumerate() {
            let outline = k + 1 == series.len();
            let colour = if outline {
                BLACK
            } else {
                COLOURS[k % COLOURS.len()]
            };
            let style = colour.stroke_width(1);
            let n = s.x.len().min(s.y.len());
            // at most 20 000 points of the orbit, evenly taken
            let stride = n.div_ceil(20_000).max(1);
            let points = (0..n).step_by(stride).map(|i| (s.x[i], s.y[i]));
            chart
                .draw_series(LineSeries::new(points, style))
                .map_err(|e| err(&e))?
                .label(s.label.clone())
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], style));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// One bar: its label (on the x axis) and value.
pub struct Bar {
    pub label: String,
    pub value: f64,
}

/// Stacked panels of bar charts, one per entry (panel title, bars); 300 px each.
pub fn bar_panels(
    path: &Path,
    title: &str,
    y_label: &str,
    panels: &[(String, Vec<Bar>)],
) -> Result<(), String> {
    register_font();
    let err = |e: &dyn std::fmt::Display| format!("{}: cannot draw the plot: {e}", path.display());
    let height = 60 + 300 * panels.len().max(1) as u32;
    let root = BitMapBackend::new(path, (WIDTH, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root
        .titled(title, ("sans-serif", 22))
        .map_err(|e| err(&e))?;
    let areas = root.split_evenly((panels.len().max(1), 1));
    for ((panel_title, bars), area) in panels.iter().zip(areas) {
        let n = bars.len().max(1);
        let top = bars
            .iter()
            .map(|b| b.value)
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        let top = if top > 0.0 { 1.1 * top } else { 1.0 };
        let mut chart = ChartBuilder::on(&area)
            .caption(panel_title.as_str(), ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d((0..n).into_segmented(), 0.0..top)
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(n)
            .x_label_formatter(&|v| match v {
                SegmentValue::CenterOf(i) => {
                    bars.get(*i).map(|b| b.label.clone()).unwrap_or_default()
                }
                _ => String::new(),
            })
            .y_desc(y_label)
            .y_label_formatter(&|v| tick(*v))
            .draw()
            .map_err(|e| err(&e))?;
        chart
            .draw_series(bars.iter().enumerate().map(|(i, b)| {
                let v = if b.value.is_finite() { b.value } else { 0.0 };
                let mut bar = Rectangle::new(
                    [
                        (SegmentValue::Exact(i), 0.0),
                        (SegmentValue::Exact(i + 1), v),
                    ],
                    COLOURS[0].filled(),
                );
                bar.set_margin(0, 0, 6, 6);
                bar
            }))
            .map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// Tick label: plain for moderate magnitudes, scientific otherwise.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a < 1e-12 {
        "0".into()
    } else if (1e-2..1e5).contains(&a) {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.3e}")
    }
}

/// Axis ranges from the finite data, with 5 % margins; never empty.
fn ranges(series: &[Series]) -> (std::ops::Range<f64>, std::ops::Range<f64>) {
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
        } else {
            0.5 * lo.abs().max(1e-12)
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
        std::fs::remove_dir_all(&dir).ok();
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
