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
}

impl Figure {
    /// An empty figure.
    pub fn new(file: impl Into<String>, title: impl Into<String>, x: Axis, y: Axis) -> Figure {
        Figure { file: file.into(), title: title.into(), x, y, series: Vec::new(), vertical_lines: Vec::new() }
    }

    /// Adds a series (builder style).
    pub fn with(mut self, s: Series) -> Figure {
        self.series.push(s);
        self
    }

    /// Whether there is anything to draw.
    pub fn has_data(&self) -> bool {
        self.series.iter().any(|s| s.points.iter().any(|p| p.0.is_finite() && p.1.is_finite()))
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
