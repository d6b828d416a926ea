//! The figures of the verification checks, built from data the checks recorded during the run
//! (plain [`Figure`] specifications; `io::plot` draws them into the run's `plots/` directory).
//!
//! Computed values are drawn as markers (one per material point) or lines (time histories); the
//! references as lines. Depths grow downwards.

use crate::plot::{Axis, Figure, Series, Style, VerticalLine};

/// Points of an analytical curve f on [a, b].
pub fn sample(a: f64, b: f64, n: usize, f: impl Fn(f64) -> f64) -> Vec<f64> {
    (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).map(f).collect()
}

/// A labelled profile: (label, computed (depth, value), analytical (depth, value)).
pub type Profile = (String, Vec<(f64, f64)>, Vec<(f64, f64)>);

/// Pore pressure profiles at given times: `profiles` holds, per time, its label, the computed
/// (depth, p/q) of the material points and the analytical (depth, p/q) curve.
pub fn pressure_profiles(file: &str, title: &str, depth_label: &str, theory: &str, profiles: &[Profile]) -> Figure {
    let mut fig =
        Figure::new(file, title, Axis::linear("normalised pore pressure p/q [-]"), Axis::reversed(depth_label));
    for (i, (label, computed, analytical)) in profiles.iter().enumerate() {
        let swap = |v: &Vec<(f64, f64)>| v.iter().map(|&(d, p)| (p, d)).collect::<Vec<_>>();
        fig.series.push(Series::new(format!("MPM, {label}"), swap(computed), Style::Markers, i));
        fig.series.push(Series::new(format!("{theory}, {label}"), swap(analytical), Style::Line, i));
    }
    fig
}

/// Settlement against time: computed and, if given, the reference (both in m, drawn in mm).
pub fn settlement_history(
    file: &str,
    title: &str,
    computed: &[(f64, f64)],
    reference: Option<(&str, &[(f64, f64)])>,
) -> Figure {
    let mm = |v: &[(f64, f64)]| v.iter().map(|&(t, s)| (t, 1e3 * s)).collect::<Vec<_>>();
    let mut fig = Figure::new(file, title, Axis::linear("time [s]"), Axis::linear("settlement [mm]"))
        .with(Series::new("MPM", mm(computed), Style::Line, 0));
    if let Some((label, r)) = reference {
        fig.series.push(Series::new(label, mm(r), Style::Dashed, 1));
    }
    fig
}

/// A depth profile of one quantity: computed (depth, value) markers against an analytical curve.
#[allow(clippy::too_many_arguments)]
pub fn depth_profile(
    file: &str,
    title: &str,
    value_label: &str,
    depth_label: &str,
    computed_label: &str,
    computed: &[(f64, f64)],
    reference_label: &str,
    reference: &[(f64, f64)],
) -> Figure {
    let swap = |v: &[(f64, f64)]| v.iter().map(|&(d, x)| (x, d)).collect::<Vec<_>>();
    Figure::new(file, title, Axis::linear(value_label), Axis::reversed(depth_label))
        .with(Series::new(computed_label, swap(computed), Style::Markers, 0))
        .with(Series::new(reference_label, swap(reference), Style::Line, 1))
}

/// The pore pressure history at the shock-wave probe, with the expected and picked arrivals.
pub fn shock_history(
    samples_over_q: &[(f64, f64)],
    depth: f64,
    expected: &[(&str, f64)],
    picked: &[(&str, Option<f64>)],
) -> Figure {
    let ms: Vec<(f64, f64)> = samples_over_q.iter().map(|&(t, p)| (1e3 * t, p)).collect();
    let mut fig = Figure::new(
        "shock_probe_pressure.png",
        format!("Shock wave: pore pressure at {depth:.4} m depth"),
        Axis::linear("time [ms]"),
        Axis::linear("normalised pore pressure p/q [-]"),
    )
    .with(Series::new("MPM at the probe", ms, Style::Line, 0));
    for (i, (label, t)) in expected.iter().enumerate() {
        fig.vertical_lines.push(VerticalLine { x: 1e3 * t, label: format!("expected {label}"), colour: 1 + i });
    }
    for (i, (label, t)) in picked.iter().enumerate() {
        if let Some(t) = t {
            fig.vertical_lines.push(VerticalLine { x: 1e3 * t, label: format!("picked {label}"), colour: 4 + i });
        }
    }
    fig
}

/// The load–settlement curve of a footing, (d/B, q/c), with the reference q_ult/c as a line.
pub fn load_settlement(curve: &[[f64; 3]], reference: f64) -> Figure {
    let pts: Vec<(f64, f64)> = curve.iter().map(|r| (r[1], r[2])).collect();
    let d_max = pts.iter().map(|p| p.0).fold(0.0, f64::max);
    let d_min = pts.iter().map(|p| p.0).fold(0.0, f64::min);
    let name = if (reference - (2.0 + std::f64::consts::PI)).abs() < 1e-9 {
        format!("2 + π = {reference:.3} (Prandtl)")
    } else {
        format!("reference q_ult/c = {reference:.3}")
    };
    Figure::new(
        "load_settlement.png",
        "Footing: load–settlement curve",
        Axis::linear("normalised settlement d/B [-]"),
        Axis::linear("normalised footing pressure q/c [-]"),
    )
    .with(Series::new("MPM", pts, Style::Line, 0))
    .with(Series::new(name, vec![(d_min, reference), (d_max, reference)], Style::Dashed, 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_put_depth_on_the_vertical_axis() {
        let f = pressure_profiles(
            "p.png",
            "t",
            "depth [m]",
            "Terzaghi",
            &[("T_v = 0.1".into(), vec![(0.05, 0.3)], vec![(0.0, 0.0), (1.0, 1.0)])],
        );
        assert_eq!(f.series.len(), 2);
        assert_eq!(f.series[0].points, vec![(0.3, 0.05)]);
        assert!(f.y.reversed);
        assert_eq!(sample(0.0, 1.0, 4, |x| 2.0 * x), vec![0.0, 0.5, 1.0, 1.5, 2.0]);
        let l = load_settlement(&[[0.0, 0.0, 0.0], [1.0, 0.5, 5.0]], 2.0 + std::f64::consts::PI);
        assert_eq!(l.series[1].points, vec![(0.0, 2.0 + std::f64::consts::PI), (0.5, 2.0 + std::f64::consts::PI)]);
        assert!(l.series[1].label.starts_with("2 + π"));
    }
}
