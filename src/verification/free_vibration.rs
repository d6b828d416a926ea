//! The free vibration of an elastic bar in its first mode (`kind = "free_vibration"`): a bar of
//! height H fixed at its base y_b and free at its top, its sides held laterally, so that its
//! waves are one-dimensional at c = √(M/ρ) (M the constrained modulus E(1 − ν)/((1 + ν)(1 − 2ν)),
//! ρ the mixture's density), set moving by an initial velocity field and then left alone (no
//! load). Its first mode is φ(y) = sin(π (y − y_b)/(2H)) at ω = π c/(2H), period T = 4H/c.
//!
//! The check projects the points' vertical displacements on the mode with their masses,
//! q(t) = Σ m φ(y₀) u_y / Σ m φ(y₀)² (y₀ a point's initial height), which filters the grid's
//! higher modes, and compares q with the closed form q = (v₀/ω) sin ωt, where
//! v₀ = Σ m φ v_y(0) / Σ m φ² is the projection of the points' initial velocities (an initial
//! field whose remainder v_y − v₀ φ is more than 1e-3 of it is refused: its higher modes would
//! belong in the reference). Over the first `periods` periods: the period from the zero crossings
//! of q (linear interpolation between steps; a least-squares line through the crossing times,
//! t = 0 included, whose slope is T/2), and the amplitude of each half cycle (the largest |q| of the
//! half cycle with a parabola through it and its neighbours), each against the closed form:
//! `period_rel_error` = |T − T*|/T* and `amplitude_rel_error` = max |A_k − A*|/A*.

use super::{elastic_body, figures, tolerance, BuiltCheck, Check, CheckParameters, Findings, FormulationNeed, Metric};
use crate::case::{BodyId, Case, Formulation};
use crate::check::{at, Checked};
use crate::model::Model;
use crate::parallel::Collective;
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "free_vibration"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FreeVibration {
    /// The name of the bar body (linear elastic, fixed at its base, its sides held laterally,
    /// started by a `initial.velocity` of the first mode's shape).
    pub body: String,
    /// The number of periods from t = 0 over which the period and the amplitude are measured
    /// [-], ≥ 1 (default 3); the run must last them.
    #[serde(default = "default_periods")]
    pub periods: usize,
    /// Pass threshold for the period's and the amplitude's relative errors [-], in (0, 1]
    /// (default 0.005).
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

serde_defaults! { default_periods: usize = 3, default_tolerance: f64 = 0.005 }

impl CheckParameters for FreeVibration {
    type Ids = BodyId;
    const FORMULATION: FormulationNeed =
        Some((Formulation::OnePhase, "the free vibration reference is for a one_phase analysis"));
    const SOLID: bool = true;

    fn check(&self, key: &str) -> Checked {
        tolerance(&at(key, "tolerance"), self.tolerance)?;
        if self.periods == 0 {
            return Err(format!("key `{}`: must be at least 1", at(key, "periods")));
        }
        Ok(())
    }

    fn describe(&self) -> String {
        format!("free vibration of an elastic bar in its first mode, {} periods", self.periods)
    }

    fn link(&self, c: &Case) -> Result<BodyId, String> {
        let body = c.body_named("verification.body", &self.body)?;
        elastic_body(c, body).map_err(|e| format!("key `verification.body`: {e}"))?;
        Ok(body)
    }

    fn plane(&self, c: &Case, body: &BodyId, model: &Model, coll: &Collective) -> BuiltCheck {
        Ok(Box::new(VibrationCheck::new(self, c, *body, model, coll)?))
    }

    fn solid(&self, c: &Case, body: &BodyId, model: &Model<3>, coll: &Collective) -> BuiltCheck<3> {
        Ok(Box::new(VibrationCheck::new(self, c, *body, model, coll)?))
    }
}

/// The check of a run.
pub struct VibrationCheck {
    body: u16,
    /// The base y_b and the height H of the bar [m].
    base: f64,
    height: f64,
    /// Σ m φ² over the bar [kg].
    modal_mass: f64,
    /// The closed form's ω [rad/s] and amplitude v₀/ω [m].
    omega: f64,
    amplitude: f64,
    periods: usize,
    tolerance: f64,
    /// (t, q) after every step, (0, 0) first.
    history: Vec<(f64, f64)>,
}

impl VibrationCheck {
    fn new<const D: usize>(
        p: &FreeVibration,
        c: &Case,
        body: BodyId,
        model: &Model<D>,
        coll: &Collective,
    ) -> Result<VibrationCheck, String> {
        let mat = &model.materials[c.material_id_of(body).index()];
        let (density, modulus) = (mat.mixture_density(mat.porosity), mat.model.elastic().constrained_modulus());
        let (lo, hi) = c.body(body).shape.bounds();
        let (base, height) = (lo[1], hi[1] - lo[1]);
        let omega = std::f64::consts::PI * (modulus / density).sqrt() / (2.0 * height);
        let ps = &model.particles;
        let b = body.index() as u16;
        let mode = |k: usize| first_mode(base, height, ps.x0[k][1]);
        let mine = || (0..ps.len()).filter(|&k| ps.body[k] == b);
        // The body's initial vertical velocity at each point's initial place (the same when the
        // run restarts from a checkpoint, whose points move).
        let fields = c.initial_values(body);
        let start = |k: usize| fields.velocity_at(ps.x0[k])[1];
        let sums = coll.sum(&[
            mine().map(|k| ps.mass[k] * mode(k).powi(2)).sum(),
            mine().map(|k| ps.mass[k] * mode(k) * start(k)).sum(),
            mine().map(|k| ps.mass[k] * start(k).powi(2)).sum(),
        ])?;
        let (modal_mass, v0) = (sums[0], sums[1] / sums[0]);
        // Σ m (v − v₀ φ)² = Σ m v² − v₀² Σ m φ² (v₀ the projection).
        let remainder = (sums[2] - v0 * v0 * modal_mass).max(0.0).sqrt();
        let norm = sums[2].sqrt();
        if v0.is_nan() || v0 == 0.0 || remainder > 1e-3 * norm {
            return Err(format!(
                "the free vibration check needs body `{}` to start with an initial velocity of the first mode's shape \
                 v₀ sin(π (y − {base})/(2 × {height})) (`initial.velocity`): its projection on the mode is v₀ = {v0:.4e} \
                 m/s and the remainder {remainder:.3e} of {norm:.3e} (mass-weighted norms)",
                c.body(body).name
            ));
        }
        let period = 2.0 * std::f64::consts::PI / omega;
        if c.end_time() < p.periods as f64 * period * (1.0 - 1e-9) {
            return Err(format!(
                "the run ({} s) is shorter than the {} measured periods ({period:.4e} s each)",
                c.end_time(),
                p.periods
            ));
        }
        Ok(VibrationCheck {
            body: b,
            base,
            height,
            modal_mass,
            omega,
            amplitude: v0 / omega,
            periods: p.periods,
            tolerance: p.tolerance,
            history: vec![(0.0, 0.0)],
        })
    }

    /// The closed form's q at `t`.
    fn exact(&self, t: f64) -> f64 {
        self.amplitude * (self.omega * t).sin()
    }

    /// The zero crossings of q after t = 0.
    fn crossings(&self) -> Vec<f64> {
        let mut out = Vec::new();
        for w in self.history.windows(2) {
            let ((t0, q0), (t1, q1)) = (w[0], w[1]);
            if q0 != 0.0 && (q0 < 0.0) != (q1 < 0.0) {
                out.push(t0 + (t1 - t0) * q0 / (q0 - q1));
            }
        }
        out
    }

    /// The amplitude of each half cycle that ends at one of `crossings`: the largest |q| between
    /// its zero crossings, refined by the parabola through it and its two neighbours.
    fn amplitudes(&self, crossings: &[f64]) -> Vec<f64> {
        let h = &self.history;
        let mut out = Vec::new();
        let mut start = 0.0;
        for &end in crossings {
            let inside: Vec<usize> = (1..h.len() - 1).filter(|&i| h[i].0 > start && h[i].0 < end).collect();
            start = end;
            let Some(&i) = inside.iter().max_by(|&&a, &&b| h[a].1.abs().total_cmp(&h[b].1.abs())) else {
                continue;
            };
            let (a, b, c) = (h[i - 1].1.abs(), h[i].1.abs(), h[i + 1].1.abs());
            // The vertex of the parabola through three equally spaced samples.
            let curvature = a - 2.0 * b + c;
            let peak = if curvature < 0.0 { b - (c - a).powi(2) / (8.0 * curvature) } else { b };
            out.push(peak);
        }
        out
    }
}

/// The first mode's shape φ(y) = sin(π (y − y_b)/(2H)) of a bar of base `base` and height
/// `height`.
fn first_mode(base: f64, height: f64, y: f64) -> f64 {
    (std::f64::consts::PI * (y - base) / (2.0 * height)).sin()
}

/// The slope of the least-squares line through (k, t_k), k = 0, 1, ….
fn slope(t: &[f64]) -> f64 {
    let n = t.len() as f64;
    let mean_k = (n - 1.0) / 2.0;
    let mean_t = t.iter().sum::<f64>() / n;
    let (num, den) = t.iter().enumerate().fold((0.0, 0.0), |(num, den), (k, tk)| {
        let dk = k as f64 - mean_k;
        (num + dk * (tk - mean_t), den + dk * dk)
    });
    num / den
}

impl<const D: usize> Check<D> for VibrationCheck {
    fn columns(&self) -> Vec<String> {
        vec!["vibration.modal_displacement".into()]
    }

    fn observe(&mut self, t: f64, _dt: f64, model: &Model<D>, coll: &Collective) -> Result<Vec<f64>, String> {
        let ps = &model.particles;
        let local: f64 = (0..ps.len())
            .filter(|&k| ps.body[k] == self.body)
            .map(|k| ps.mass[k] * first_mode(self.base, self.height, ps.x0[k][1]) * ps.disp[k][1])
            .sum();
        let q = coll.sum(&[local])?[0] / self.modal_mass;
        // A restart observes its first time again.
        if self.history.last().is_none_or(|&(last, _)| t > last) {
            self.history.push((t, q));
        }
        Ok(vec![q])
    }

    fn finish(&mut self, _model: &Model<D>, _coll: &Collective) -> Result<Findings, String> {
        let period = 2.0 * std::f64::consts::PI / self.omega;
        // The first 2 × `periods` crossings; a run whose period is much too long has fewer by its
        // end, and is measured by those it has (none: the period's error is infinite).
        let all = self.crossings();
        let crossings = &all[..all.len().min(2 * self.periods)];
        let half_cycles = crossings.len();
        let times: Vec<f64> = std::iter::once(0.0).chain(crossings.iter().copied()).collect();
        let measured = if half_cycles > 0 { 2.0 * slope(&times) } else { f64::INFINITY };
        let amplitudes = self.amplitudes(crossings);
        let worst = amplitudes.iter().map(|a| (a - self.amplitude.abs()).abs()).fold(0.0, f64::max);
        let worst = if amplitudes.is_empty() { f64::INFINITY } else { worst };
        let (lo, hi) = amplitudes.iter().fold((f64::INFINITY, 0.0f64), |(l, h), &a| (l.min(a), h.max(a)));
        let a_ref = self.amplitude.abs();
        Ok((
            vec![
                (
                    "period_rel_error".into(),
                    Metric::error(
                        (measured - period).abs() / period,
                        self.tolerance,
                        format!(
                            "period {measured:.6e} s from {half_cycles} zero crossings (of {} in {} periods) vs 4H/c = \
                             {period:.6e} s",
                            2 * self.periods,
                            self.periods
                        ),
                    ),
                ),
                (
                    "amplitude_rel_error".into(),
                    Metric::error(
                        worst / a_ref,
                        self.tolerance,
                        format!(
                            "{} half cycles' amplitudes {lo:.6e} to {hi:.6e} m vs v₀/ω = {a_ref:.6e} m",
                            amplitudes.len()
                        ),
                    ),
                ),
            ],
            Vec::new(),
        ))
    }

    /// The modal displacement's history so far.
    fn checkpoint_state(&self, _model: &Model<D>, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        Ok(Some(self.history.iter().flat_map(|&(t, q)| [t, q]).collect()))
    }

    fn restore_state(&mut self, state: &[f64], _model: &Model<D>) -> Result<(), String> {
        if state.len() < 2 || !state.len().is_multiple_of(2) {
            return Err(format!("{} values are no history of (t, q) pairs", state.len()));
        }
        self.history = state.chunks(2).map(|r| (r[0], r[1])).collect();
        Ok(())
    }

    fn results(&self) -> Vec<(String, f64)> {
        vec![
            ("reference_period".into(), 2.0 * std::f64::consts::PI / self.omega),
            ("reference_amplitude".into(), self.amplitude),
        ]
    }

    fn figures(&self) -> Vec<crate::plot::Figure> {
        let exact: Vec<(f64, f64)> = self.history.iter().map(|&(t, _)| (t, self.exact(t))).collect();
        let mut fig = figures::settlement_history(
            "free_vibration.png",
            "Free vibration of the bar: its first mode's displacement",
            &self.history,
            Some(("closed form (v₀/ω) sin ωt", &exact)),
        );
        fig.y = crate::plot::Axis::linear("modal displacement q [mm]");
        vec![fig]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A check fed with q = A sin(ω' t) sampled every `dt`.
    fn fed(omega_run: f64, amplitude_run: f64, dt: f64) -> VibrationCheck {
        let mut c = VibrationCheck {
            body: 0,
            base: 0.0,
            height: 1.0,
            modal_mass: 1.0,
            omega: 10.0,
            amplitude: 0.5,
            periods: 3,
            tolerance: 0.005,
            history: vec![(0.0, 0.0)],
        };
        let n = (3.75 * 2.0 * std::f64::consts::PI / 10.0 / dt) as usize;
        c.history.extend((1..=n).map(|i| (i as f64 * dt, amplitude_run * (omega_run * i as f64 * dt).sin())));
        c
    }

    #[test]
    fn the_period_and_the_amplitude_come_from_the_samples() {
        // ωΔt = 0.1, as in a run: the crossings' interpolation and the peaks' parabolas leave
        // errors far below the tolerance.
        let c = fed(10.0, 0.5, 0.01);
        let crossings = c.crossings();
        assert_eq!(crossings.len(), 7, "{crossings:?}");
        let crossings = &crossings[..6];
        let times: Vec<f64> = std::iter::once(0.0).chain(crossings.iter().copied()).collect();
        let t = 2.0 * slope(&times);
        assert!((t - 2.0 * std::f64::consts::PI / 10.0).abs() < 1e-6, "{t}");
        let a = c.amplitudes(crossings);
        assert_eq!(a.len(), 6);
        assert!(a.iter().all(|a| (a - 0.5).abs() < 5e-5), "{a:?}");
        // A run 1 % slower, 1 % smaller: both errors seen.
        let c = fed(10.0 / 1.01, 0.495, 0.01);
        let crossings = c.crossings();
        let times: Vec<f64> = std::iter::once(0.0).chain(crossings[..6].iter().copied()).collect();
        let t = 2.0 * slope(&times);
        assert!(((t - 0.2 * std::f64::consts::PI) / (0.2 * std::f64::consts::PI) - 0.01).abs() < 1e-5, "{t}");
        assert!(c.amplitudes(&crossings[..6]).iter().all(|a| ((a - 0.5) / 0.5 + 0.01).abs() < 1e-4));
    }
}
