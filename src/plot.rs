//! Plot specifications as plain data.
//!
//! The verification checks, the driver and the sweep describe what to plot with these types; only
//! `io::plot` turns a [`Figure`] into a PNG file (with plotters). So the physics modules never
//! depend on a plotting library, and every plotted number comes from the run that produced it.

/// One axis of a figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// The label, with the unit in brackets, e.g. `depth [m]`.
    pub label: String,
    /// Logarithmic scale (non-positive values are then left out of the plot).
    pub log: bool,
    /// Values grow downwards (y) or to the left (x), e.g. depth below a surface.
    pub reversed: bool,
}

impl Axis {
    /// A linear axis.
    pub fn linear(label: impl Into<String>) -> Axis {
        Axis { label: label.into(), log: false, reversed: false }
    }

    /// A logarithmic axis.
    pub fn log(label: impl Into<String>) -> Axis {
        Axis { label: label.into(), log: true, reversed: false }
    }

    /// A linear axis whose values grow downwards (or to the left).
    pub fn reversed(label: impl Into<String>) -> Axis {
        Axis { label: label.into(), log: false, reversed: true }
    }
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// A solid line through the points (e.g. an analytical solution).
    Line,
    /// A dashed line (e.g. a reference value).
    Dashed,
    /// Markers only (e.g. material point values).
    Markers,
    /// A line with a marker at each point (e.g. a convergence series).
    LineMarkers,
}

/// A named set of (x, y) points.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// The legend entry.
    pub label: String,
    /// The points, in drawing order.
    pub points: Vec<(f64, f64)>,
    /// How they are drawn.
    pub style: Style,
    /// Colour index: series with the same index share a colour (e.g. computed and analytical
    /// values at the same time).
    pub colour: usize,
    /// Optional text next to each point (same length as `points`, or empty).
    pub point_labels: Vec<String>,
}

impl Series {
    /// A series without point labels.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>, style: Style, colour: usize) -> Series {
        Series { label: label.into(), points, style, colour, point_labels: Vec::new() }
    }
}

/// A vertical line across the plot at `x`, with a legend entry (e.g. an expected arrival time).
#[derive(Debug, Clone, PartialEq)]
pub struct VerticalLine {
    /// Where it is drawn (x units).
    pub x: f64,
    /// The legend entry.
    pub label: String,
    /// Colour index, as in [`Series::colour`].
    pub colour: usize,
}

/// The (x, y, value) points of a [`ColourMap`].
pub type MapPoints = Vec<(f64, f64, f64)>;

/// A scalar field over the plane drawn as coloured rectangles, one per point, with a colour bar:
/// e.g. σ_m at the material points or K_mag at the nodes. Drawn under the series, on linear axes
/// with the same scale in x and y.
#[derive(Debug, Clone, PartialEq)]
pub struct ColourMap {
    /// (x, y, value) of each point.
    pub points: MapPoints,
    /// Half the width and height of each point's rectangle (x and y units).
    pub half_size: (f64, f64),
    /// What the colour shows, with its unit, e.g. `σ_m [kPa]`.
    pub label: String,
    /// The values at the ends of the colour bar (default: the values' range).
    pub range: Option<(f64, f64)>,
}

impl ColourMap {
    /// The range between the `lo` and `hi` quantiles of the finite values (e.g. 0.01 and 0.99, so
    /// that a few extreme points do not wash out the colours of the rest); `None` without values.
    pub fn quantiles(points: &[(f64, f64, f64)], lo: f64, hi: f64) -> Option<(f64, f64)> {
        let mut v: Vec<f64> = points.iter().map(|p| p.2).filter(|x| x.is_finite()).collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        let at = |q: f64| v[((q.clamp(0.0, 1.0) * (v.len() - 1) as f64).round() as usize).min(v.len() - 1)];
        let (a, b) = (at(lo), at(hi));
        (a < b).then_some((a, b))
    }

    /// The values at the ends of the colour bar: `range`, or the finite values' range (widened
    /// when they are all equal).
    pub fn limits(&self) -> (f64, f64) {
        if let Some(r) = self.range {
            return r;
        }
        let finite = self.points.iter().map(|p| p.2).filter(|v| v.is_finite());
        let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
        if lo > hi {
            return (0.0, 1.0);
        }
        if hi - lo <= 1e-12 * hi.abs().max(lo.abs()).max(f64::MIN_POSITIVE) {
            let pad = 0.5 * hi.abs().max(1.0);
            return (lo - pad, hi + pad);
        }
        (lo, hi)
    }
}

/// A figure: one chart written as one PNG file.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// File name inside the plots directory, e.g. `pressure_profiles.png`.
    pub file: String,
    /// The title above the chart.
    pub title: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// The data.
    pub series: Vec<Series>,
    /// Vertical marker lines.
    pub vertical_lines: Vec<VerticalLine>,
    /// A scalar field drawn under the series.
    pub map: Option<ColourMap>,
}

impl Figure {
    /// An empty figure.
    pub fn new(file: impl Into<String>, title: impl Into<String>, x: Axis, y: Axis) -> Figure {
        Figure {
            file: file.into(),
            title: title.into(),
            x,
            y,
            series: Vec::new(),
            vertical_lines: Vec::new(),
            map: None,
        }
    }

    /// A figure of one scalar field over the plane (x and y in metres).
    pub fn map(file: impl Into<String>, title: impl Into<String>, map: ColourMap) -> Figure {
        Figure { map: Some(map), ..Figure::new(file, title, Axis::linear("x [m]"), Axis::linear("y [m]")) }
    }

    /// Adds a series (builder style).
    pub fn with(mut self, s: Series) -> Figure {
        self.series.push(s);
        self
    }

    /// Whether there is anything to draw.
    pub fn has_data(&self) -> bool {
        self.series.iter().any(|s| s.points.iter().any(|p| p.0.is_finite() && p.1.is_finite()))
            || self.map.as_ref().is_some_and(|m| m.points.iter().any(|p| p.0.is_finite() && p.1.is_finite()))
    }
}

/// Time histories of the probes, from the rows of `history.csv` (`columns` names the values of each
/// row): for each probe field in `fields` present in the columns as `<probe>.<field>`, one figure
/// with one series per probe against `time`. `fields` holds (field, axis label, scale, file stem).
pub fn probe_histories(columns: &[String], rows: &[Vec<f64>], fields: &[(&str, &str, f64, &str)]) -> Vec<Figure> {
    let Some(it) = columns.iter().position(|c| c == "time") else {
        return Vec::new();
    };
    let mut figures = Vec::new();
    for &(field, label, scale, stem) in fields {
        let suffix = format!(".{field}");
        let mut fig = Figure::new(
            format!("probes_{stem}.png"),
            format!("Probe histories: {label}"),
            Axis::linear("time [s]"),
            Axis::linear(label),
        );
        for (c, name) in columns.iter().enumerate() {
            if let Some(probe) = name.strip_suffix(&suffix) {
                let points = rows.iter().filter(|r| r.len() > c).map(|r| (r[it], r[c] * scale)).collect();
                let colour = fig.series.len();
                fig.series.push(Series::new(format!("probe {probe}"), points, Style::Line, colour));
            }
        }
        if fig.has_data() {
            figures.push(fig);
        }
    }
    figures
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probe_histories_pick_each_probes_column() {
        let columns: Vec<String> = ["time", "step", "a.p_excess", "b.p_excess", "a.uy"].map(String::from).to_vec();
        let rows = vec![vec![0.0, 0.0, 1.0, 2.0, 0.0], vec![0.5, 1.0, 3.0, 4.0, -1e-3]];
        let figs = probe_histories(
            &columns,
            &rows,
            &[("p_excess", "excess pore pressure [kPa]", 1e-3, "p"), ("uy", "displacement [mm]", 1e3, "uy")],
        );
        assert_eq!(figs.len(), 2);
        assert_eq!(figs[0].series.len(), 2);
        assert_eq!(figs[0].series[1].label, "probe b");
        assert_eq!(figs[0].series[1].points, vec![(0.0, 2e-3), (0.5, 4e-3)]);
        assert_eq!(figs[1].series[0].points[1], (0.5, -1.0));
        // No time column: nothing to plot.
        assert!(probe_histories(&columns[1..], &rows, &[("uy", "u", 1.0, "uy")]).is_empty());
    }
}
