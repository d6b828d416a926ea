//! Renders [`Figure`]s as PNG files with plotters (bitmap backend; text through fontconfig and
//! FreeType, which find a sans-serif font such as DejaVu Sans from `fonts-dejavu-core`).
//!
//! A figure is 1000 × 650 pixels: the title on top, labelled axes with their units, a light grid,
//! and a legend in the corner of the chart that holds the fewest data points. Reversed axes are
//! drawn by negating the values and printing the ticks without the sign; logarithmic axes leave out
//! non-positive values. A figure with a [`crate::plot::ColourMap`] draws it under its series on axes
//! of equal scale, with a colour bar on the right (the viridis colour scale).

use crate::plot::{Axis, ColourMap, Figure, Series, Style};
use plotters::coord::combinators::{LogCoord, WithKeyPoints};
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Width and height of every figure [px].
pub const SIZE: (u32, u32) = (1000, 650);

/// Colours of the series (RGB), by [`crate::plot::Series::colour`] (cycled); public so that tests
/// can find the drawn series in a figure's pixels.
pub const SERIES_COLOURS: [[u8; 3]; 8] = [
    [0, 114, 178],
    [213, 94, 0],
    [0, 158, 115],
    [204, 121, 167],
    [86, 180, 233],
    [230, 159, 0],
    [0, 0, 0],
    [120, 120, 120],
];

fn colour(i: usize) -> RGBColor {
    let [r, g, b] = SERIES_COLOURS[i % SERIES_COLOURS.len()];
    RGBColor(r, g, b)
}

/// The size of a figure's PNG file at most [B], about.
const FIGURE_BYTES: u64 = 256 * 1024;

/// Writes every figure that has data as `<dir>/<figure.file>` (the directory is created if needed)
/// and returns the paths written. A figure the disk has no room for is not started.
pub fn write_figures(dir: &Path, figures: &[Figure]) -> Result<Vec<PathBuf>, String> {
    let mut written = Vec::new();
    for f in figures.iter().filter(|f| f.has_data()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        let path = dir.join(&f.file);
        super::check_room(&path, FIGURE_BYTES)?;
        if let Err(e) = render(&path, f) {
            let _ = std::fs::remove_file(&path);
            return Err(format!("cannot draw {}: {e}", path.display()));
        }
        written.push(path);
    }
    Ok(written)
}

/// A value as drawn on an axis (negated on a reversed axis).
fn to_axis(a: &Axis, v: f64) -> f64 {
    if a.reversed {
        -v
    } else {
        v
    }
}

/// Whether a value can be drawn on the axis.
fn drawable(a: &Axis, v: f64) -> bool {
    v.is_finite() && (!a.log || v > 0.0)
}

/// The drawn range of the values on an axis, with a margin (multiplicative on log axes).
fn range(a: &Axis, values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = values
        .filter(|&v| drawable(a, v))
        .map(|v| to_axis(a, v))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)));
    if !lo.is_finite() {
        return if a.log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if a.log {
        if hi / lo < 1.5 {
            lo /= 1.5;
            hi *= 1.5;
        }
        (lo / 1.25, hi * 1.25)
    } else {
        if hi - lo <= 1e-12 * hi.abs().max(lo.abs()).max(1e-300) {
            let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
            lo -= d;
            hi += d;
        }
        let m = 0.04 * (hi - lo);
        (lo - m, hi + m)
    }
}

/// Tick text: plain decimals for ordinary magnitudes, else scientific notation.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if (1e-4..1e5).contains(&a) {
        let s = format!("{v:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    } else {
        format!("{v:.1e}")
    }
}

/// The corner of the chart with the fewest points (in fractions of the drawn ranges).
fn legend_corner(f: &Figure, xr: (f64, f64), yr: (f64, f64)) -> SeriesLabelPosition {
    let frac = |a: &Axis, v: f64, r: (f64, f64)| {
        let v = to_axis(a, v);
        if a.log {
            (v.ln() - r.0.ln()) / (r.1.ln() - r.0.ln())
        } else {
            (v - r.0) / (r.1 - r.0)
        }
    };
    let mut counts = [0usize; 4]; // upper left, upper right, lower left, lower right
    for s in &f.series {
        for &(x, y) in &s.points {
            if !(drawable(&f.x, x) && drawable(&f.y, y)) {
                continue;
            }
            let (fx, fy) = (frac(&f.x, x, xr), frac(&f.y, y, yr));
            if fy > 0.55 {
                counts[if fx < 0.45 { 0 } else { 1 }] += 1;
            } else if fy < 0.45 {
                counts[if fx < 0.45 { 2 } else { 3 }] += 1;
            }
        }
    }
    let best = (0..4).min_by_key(|&i| (counts[i], [1, 0, 3, 2][i])).unwrap_or(1);
    match best {
        0 => SeriesLabelPosition::UpperLeft,
        1 => SeriesLabelPosition::UpperRight,
        2 => SeriesLabelPosition::LowerLeft,
        _ => SeriesLabelPosition::LowerRight,
    }
}

/// A logarithmic axis over `r` with labelled ticks at 1, 2, 5 × 10^k (every integer multiple when
/// the range spans less than a decade and a half, powers of ten only beyond five decades) and
/// light grid lines at every integer multiple.
fn log_axis(r: (f64, f64)) -> WithKeyPoints<LogCoord<f64>> {
    let decades = (r.1 / r.0).log10();
    let bold: &[f64] = if decades < 1.5 {
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
    } else if decades <= 5.0 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let points = |ms: &[f64]| {
        let (k0, k1) = (r.0.log10().floor() as i32, r.1.log10().ceil() as i32);
        (k0..=k1)
            .flat_map(|k| ms.iter().map(move |m| m * 10f64.powi(k)))
            .filter(|v| *v >= r.0 && *v <= r.1)
            .collect::<Vec<f64>>()
    };
    LogCoord::from((r.0..r.1).log_scale())
        .with_key_points(points(bold))
        .with_light_points(points(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]))
}

/// Width of a colour map's colour bar [px].
const BAR_WIDTH: u32 = 130;

/// The viridis colour scale at s ∈ [0, 1] (piecewise linear through nine of its colours).
pub fn viridis(s: f64) -> RGBColor {
    const STOPS: [[f64; 3]; 9] = [
        [68.0, 1.0, 84.0],
        [71.0, 44.0, 122.0],
        [59.0, 81.0, 139.0],
        [44.0, 113.0, 142.0],
        [33.0, 144.0, 141.0],
        [39.0, 173.0, 129.0],
        [92.0, 200.0, 99.0],
        [170.0, 220.0, 50.0],
        [253.0, 231.0, 37.0],
    ];
    let t = if s.is_finite() { s.clamp(0.0, 1.0) * 8.0 } else { 0.0 };
    let k = (t.floor() as usize).min(7);
    let w = t - k as f64;
    let c = |i: usize| (STOPS[k][i] * (1.0 - w) + STOPS[k + 1][i] * w).round() as u8;
    RGBColor(c(0), c(1), c(2))
}

/// The (x, y) ranges of a colour map's figure: the points' rectangles with a margin, widened so
/// that a metre is as long in x as in y on the chart of `pixels` (width, height).
fn map_ranges(m: &ColourMap, pixels: (f64, f64)) -> ((f64, f64), (f64, f64)) {
    let finite = || m.points.iter().filter(|p| p.0.is_finite() && p.1.is_finite());
    let (hx, hy) = m.half_size;
    let fold = |f: &dyn Fn(&(f64, f64, f64)) -> f64, h: f64| {
        finite().map(f).fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), v| (l.min(v - h), u.max(v + h)))
    };
    let (mut xr, mut yr) = (fold(&|p| p.0, hx), fold(&|p| p.1, hy));
    if !xr.0.is_finite() || !yr.0.is_finite() {
        return ((0.0, 1.0), (0.0, 1.0));
    }
    let (w, h) = ((xr.1 - xr.0).max(1e-12), (yr.1 - yr.0).max(1e-12));
    let scale = (pixels.0 / w).min(pixels.1 / h);
    let grow = |r: &mut (f64, f64), span: f64| {
        let c = 0.5 * (r.0 + r.1);
        *r = (c - 0.5 * span, c + 0.5 * span);
    };
    grow(&mut xr, 1.04 * pixels.0 / scale);
    grow(&mut yr, 1.04 * pixels.1 / scale);
    (xr, yr)
}

/// The colour bar of `m` in `area`: the scale from its low to its high value with ticks, and its
/// label above.
fn colour_bar(area: &DrawingArea<BitMapBackend, Shift>, m: &ColourMap) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<_>| e.to_string();
    let (lo, hi) = m.limits();
    let mut bar = ChartBuilder::on(area)
        .caption(&m.label, ("sans-serif", 17))
        .margin_top(40)
        .margin_bottom(73)
        .margin_right(8)
        .y_label_area_size(80)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(err)?;
    bar.configure_mesh()
        .disable_x_mesh()
        .disable_x_axis()
        .disable_y_mesh()
        .y_label_formatter(&|v: &f64| tick(*v))
        .label_style(("sans-serif", 15))
        .draw()
        .map_err(err)?;
    let n = 100;
    bar.draw_series((0..n).map(|k| {
        let (a, b) = (lo + (hi - lo) * k as f64 / n as f64, lo + (hi - lo) * (k + 1) as f64 / n as f64);
        Rectangle::new([(0.0, a), (1.0, b)], viridis((k as f64 + 0.5) / n as f64).filled())
    }))
    .map_err(err)?;
    Ok(())
}

fn render(path: &Path, f: &Figure) -> Result<(), String> {
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    if let Some(m) = &f.map {
        let (chart, bar) = root.split_horizontally(SIZE.0 - BAR_WIDTH);
        colour_bar(&bar, m)?;
        // The plotting area of `draw`: the chart less its margins, label areas and caption.
        let pixels = ((SIZE.0 - BAR_WIDTH) as f64 - 36.0 - 95.0, SIZE.1 as f64 - 36.0 - 55.0 - 40.0);
        let (xr, yr) = map_ranges(m, pixels);
        let (xa, ya) = ((to_axis(&f.x, xr.0), to_axis(&f.x, xr.1)), (to_axis(&f.y, yr.0), to_axis(&f.y, yr.1)));
        let (xa, ya) = ((xa.0.min(xa.1), xa.0.max(xa.1)), (ya.0.min(ya.1), ya.0.max(ya.1)));
        draw(&chart, f, xa.0..xa.1, ya.0..ya.1, xa, ya)?;
        return root.present().map_err(|e| e.to_string());
    }
    let xs = f.series.iter().flat_map(|s| s.points.iter().map(|p| p.0)).chain(f.vertical_lines.iter().map(|v| v.x));
    let xr = range(&f.x, xs);
    let yr = range(&f.y, f.series.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
    match (f.x.log, f.y.log) {
        (false, false) => draw(&root, f, xr.0..xr.1, yr.0..yr.1, xr, yr)?,
        (true, false) => draw(&root, f, log_axis(xr), yr.0..yr.1, xr, yr)?,
        (false, true) => draw(&root, f, xr.0..xr.1, log_axis(yr), xr, yr)?,
        (true, true) => draw(&root, f, log_axis(xr), log_axis(yr), xr, yr)?,
    }
    root.present().map_err(|e| e.to_string())
}

fn draw<X, Y>(
    root: &DrawingArea<BitMapBackend, Shift>,
    f: &Figure,
    x_spec: X,
    y_spec: Y,
    xr: (f64, f64),
    yr: (f64, f64),
) -> Result<(), String>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let err = |e: DrawingAreaErrorKind<_>| e.to_string();
    let mut chart = ChartBuilder::on(root)
        .caption(&f.title, ("sans-serif", 26))
        .margin(18)
        .x_label_area_size(55)
        .y_label_area_size(95)
        .build_cartesian_2d(x_spec, y_spec)
        .map_err(err)?;
    // Ticks within round-off of zero (relative to the drawn range) print as 0.
    let label = |a: &Axis, r: (f64, f64)| {
        let (sign, span) = (if a.reversed { -1.0 } else { 1.0 }, if a.log { 0.0 } else { r.1 - r.0 });
        move |v: &f64| tick(if v.abs() < 1e-9 * span { 0.0 } else { sign * v })
    };
    let (xfmt, yfmt) = (label(&f.x, xr), label(&f.y, yr));
    chart
        .configure_mesh()
        .x_desc(f.x.label.as_str())
        .y_desc(f.y.label.as_str())
        .x_label_formatter(&xfmt)
        .y_label_formatter(&yfmt)
        .label_style(("sans-serif", 17))
        .axis_desc_style(("sans-serif", 20))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(205, 205, 205))
        .draw()
        .map_err(err)?;
    if let Some(m) = &f.map {
        draw_map(&mut chart, f, m)?;
    }
    for s in &f.series {
        draw_series(&mut chart, f, s)?;
    }
    for v in f.vertical_lines.iter().filter(|v| drawable(&f.x, v.x)) {
        let c = colour(v.colour);
        let x = to_axis(&f.x, v.x);
        chart
            .draw_series(DashedLineSeries::new(vec![(x, yr.0), (x, yr.1)], 8, 5, c.stroke_width(2)))
            .map_err(err)?
            .label(&v.label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y - 6), (x + 20, y + 6)], c.stroke_width(2)));
    }
    if f.series.is_empty() && f.vertical_lines.is_empty() {
        return Ok(());
    }
    chart
        .configure_series_labels()
        .position(legend_corner(f, xr, yr))
        .label_font(("sans-serif", 17))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;
    Ok(())
}

/// A chart of the bitmap backend on coordinates `X` × `Y`.
type Chart<'a, X, Y> = ChartContext<'a, BitMapBackend<'a>, Cartesian2d<X, Y>>;

/// The colour map `m` of figure `f`: a filled rectangle per point.
fn draw_map<X, Y>(chart: &mut Chart<'_, X, Y>, f: &Figure, m: &ColourMap) -> Result<(), String>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let (lo, hi) = m.limits();
    let (hx, hy) = m.half_size;
    let cells = m.points.iter().filter(|p| p.0.is_finite() && p.1.is_finite()).map(|&(x, y, v)| {
        let corner = |dx: f64, dy: f64| (to_axis(&f.x, x + dx), to_axis(&f.y, y + dy));
        Rectangle::new([corner(-hx, -hy), corner(hx, hy)], viridis((v - lo) / (hi - lo)).filled())
    });
    chart.draw_series(cells).map_err(|e| e.to_string())?;
    Ok(())
}

/// One series of figure `f` in its style, with its legend entry and its points' labels.
fn draw_series<X, Y>(chart: &mut Chart<'_, X, Y>, f: &Figure, s: &Series) -> Result<(), String>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let err = |e: DrawingAreaErrorKind<_>| e.to_string();
    let c = colour(s.colour);
    let on_axes = |p: &(f64, f64)| drawable(&f.x, p.0) && drawable(&f.y, p.1);
    let pts: Vec<(f64, f64)> =
        s.points.iter().filter(|p| on_axes(p)).map(|p| (to_axis(&f.x, p.0), to_axis(&f.y, p.1))).collect();
    if pts.is_empty() {
        return Ok(());
    }
    let line = ShapeStyle::from(&c).stroke_width(2);
    let anno = match s.style {
        Style::Line => chart.draw_series(LineSeries::new(pts.clone(), line)).map_err(err)?,
        Style::Dashed => chart.draw_series(DashedLineSeries::new(pts.clone(), 10, 6, line)).map_err(err)?,
        Style::Markers => chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 4, ShapeStyle::from(&c).stroke_width(1))))
            .map_err(err)?,
        Style::LineMarkers => {
            chart.draw_series(LineSeries::new(pts.clone(), line)).map_err(err)?;
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, c.filled()))).map_err(err)?
        }
    };
    match s.style {
        Style::Markers => anno.label(&s.label).legend(move |(x, y)| Circle::new((x + 10, y), 4, c)),
        Style::Dashed => anno.label(&s.label).legend(move |(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (7, 0)], c.stroke_width(2))
                + PathElement::new(vec![(13, 0), (20, 0)], c.stroke_width(2))
        }),
        _ => anno.label(&s.label).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))),
    };
    if s.point_labels.is_empty() {
        return Ok(());
    }
    let labelled = s
        .points
        .iter()
        .zip(&s.point_labels)
        .filter(|(p, _)| on_axes(p))
        .map(|(p, l)| (to_axis(&f.x, p.0), to_axis(&f.y, p.1), l.clone()));
    chart
        .draw_series(
            labelled.map(|(x, y, l)| {
                EmptyElement::at((x, y)) + Text::new(l, (7, 5), ("sans-serif", 15).into_font().color(&c))
            }),
        )
        .map_err(err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::Series;

    #[test]
    fn ticks_are_short_and_ranges_have_margins() {
        assert_eq!(tick(0.25), "0.25");
        assert_eq!(tick(2.0), "2");
        assert_eq!(tick(1.5e-5), "1.5e-5");
        let (lo, hi) = range(&Axis::linear("x"), [1.0, 3.0].into_iter());
        assert!(lo < 1.0 && hi > 3.0);
        // Log axes drop non-positive values.
        let (lo, hi) = range(&Axis::log("x"), [0.0, 1e-3, 1e-1].into_iter());
        assert!(lo > 0.0 && lo < 1e-3 && hi > 1e-1);
        // Reversed axes hold negated values.
        let (lo, hi) = range(&Axis::reversed("d"), [0.0, 2.0].into_iter());
        assert!(lo < -2.0 && hi > 0.0);
    }

    #[test]
    fn a_figure_is_written_as_a_png() {
        let dir = std::env::temp_dir().join(format!("porompm-plot-test-{}", std::process::id()));
        let fig = Figure::new("t.png", "Test", Axis::log("time [s]"), Axis::reversed("depth [m]"))
            .with(Series::new("a", vec![(1e-3, 0.0), (1e-2, 1.0), (1e-1, 2.0)], Style::LineMarkers, 0))
            .with(Series::new("b", vec![(2e-3, 0.5), (2e-2, 1.5)], Style::Markers, 1));
        let empty = Figure::new("none.png", "Empty", Axis::linear("x"), Axis::linear("y"));
        let written = write_figures(&dir, &[fig, empty]).unwrap();
        assert_eq!(written.len(), 1);
        let bytes = std::fs::read(&written[0]).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        assert!(bytes.len() > 10_000, "{} bytes", bytes.len());
        assert!(!dir.join("none.png").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A colour map draws each point's rectangle in the colour of its value: a field rising from
    /// left to right shows viridis' low end (dark purple) left of its high end (yellow), the
    /// colour bar holds both, and a square block of points is drawn square (equal scales).
    #[test]
    fn a_colour_map_is_drawn_in_the_colours_of_its_values() {
        use crate::plot::ColourMap;
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        let dir = std::env::temp_dir().join(format!("porompm-map-test-{}", std::process::id()));
        let points: Vec<(f64, f64, f64)> =
            (0..400).map(|k| ((k % 20) as f64 * 0.1 + 0.05, (k / 20) as f64 * 0.1 + 0.05, (k % 20) as f64)).collect();
        let m = ColourMap { points, half_size: (0.05, 0.05), label: "v [-]".into(), range: None };
        assert_eq!(m.limits(), (0.0, 19.0));
        let written = write_figures(&dir, &[Figure::map("m.png", "Map", m)]).unwrap();
        let img = image::open(&written[0]).unwrap().to_rgb8();
        let find = |c: RGBColor| -> Vec<(u32, u32)> {
            img.enumerate_pixels().filter(|(_, _, p)| p.0 == [c.0, c.1, c.2]).map(|(x, y, _)| (x, y)).collect()
        };
        let (low, high) = (viridis(0.0), viridis(1.0));
        let chart = |v: &[(u32, u32)]| v.iter().copied().filter(|&(x, _)| x < SIZE.0 - BAR_WIDTH).collect::<Vec<_>>();
        let (l, h) = (chart(&find(low)), chart(&find(high)));
        assert!(!l.is_empty() && !h.is_empty(), "low {} and high {} pixels", l.len(), h.len());
        let mean_x = |v: &[(u32, u32)]| v.iter().map(|p| p.0 as f64).sum::<f64>() / v.len() as f64;
        assert!(mean_x(&l) < mean_x(&h), "the low end is drawn left of the high end");
        // The bar shows the scale's ends; the block (all drawn cells) is as wide as it is tall.
        let in_bar = |c: RGBColor| find(c).iter().any(|&(x, _)| x >= SIZE.0 - BAR_WIDTH);
        assert!(in_bar(viridis(0.005)) && in_bar(viridis(0.995)));
        let cells: Vec<(u32, u32)> = img
            .enumerate_pixels()
            .filter(|(x, _, p)| {
                *x < SIZE.0 - BAR_WIDTH
                    && (0..20).any(|k| {
                        p.0 == {
                            let c = viridis(k as f64 / 19.0);
                            [c.0, c.1, c.2]
                        }
                    })
            })
            .map(|(x, y, _)| (x, y))
            .collect();
        let span = |f: &dyn Fn(&(u32, u32)) -> u32| {
            cells.iter().map(f).max().unwrap() as f64 - cells.iter().map(f).min().unwrap() as f64
        };
        let (w, h) = (span(&|p| p.0), span(&|p| p.1));
        assert!((w / h - 1.0).abs() < 0.03, "the square block is drawn {w} × {h} px");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
