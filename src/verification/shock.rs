//! Shock-wave check ([003] §4.1.3): arrival of the fast (undrained) and slow (damped) compression
//! waves at a point below the loaded surface.
//!
//! The pore pressure p(t) of the material point nearest to the observation depth is recorded after
//! every step. Expected arrivals are d/V_u with V_u = sqrt((E_c + Q)/ρ) ([003] Eq. 34) and d/V_d with
//! V_d from [003] Eq. 35, d being that particle's initial depth.
//!
//! How an arrival is picked from p(t) (a step smeared by the discretisation and followed by Gibbs
//! ringing) is documented at [`pick_arrival`].

use super::consolidation::TWO_PHASE;
use super::{all_positive, BodyAndLoad, BuiltCheck, Check, CheckParameters, Column, Findings, FormulationNeed, Metric};
use crate::case::Case;
use crate::check::Checked;
use crate::model::Model;
use crate::parallel::Collective;
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "shock_wave"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ShockWave {
    /// The name of the column body.
    pub body: String,
    /// The name of the step surface load, a particle or nodal traction.
    pub load: String,
    /// Depth of the observation point below the initial surface [m], > 0.
    pub probe_depth: f64,
    /// Pass threshold for the fast (undrained) wave arrival error [-], in (0, 1] (default 0.02).
    #[serde(default = "default_fast_tol")]
    pub fast_tolerance: f64,
    /// Pass threshold for the slow (damped) wave arrival error [-], in (0, 1] (default 0.05).
    #[serde(default = "default_slow_tol")]
    pub slow_tolerance: f64,
}

serde_defaults! { default_fast_tol: f64 = 0.02, default_slow_tol: f64 = 0.05 }

impl CheckParameters for ShockWave {
    type Ids = BodyAndLoad;
    const FORMULATION: FormulationNeed = TWO_PHASE;

    fn check(&self, key: &str) -> Checked {
        let (d, f, s) = (self.probe_depth, self.fast_tolerance, self.slow_tolerance);
        all_positive(key, &[("probe_depth", d), ("fast_tolerance", f), ("slow_tolerance", s)])
    }

    fn describe(&self) -> String {
        format!("shock-wave arrival at {} m depth", self.probe_depth)
    }

    fn link(&self, c: &Case) -> Result<BodyAndLoad, String> {
        BodyAndLoad::plain(c, &self.body, &self.load)
    }

    fn plane(&self, c: &Case, ids: &BodyAndLoad, model: &Model, coll: &Collective) -> BuiltCheck {
        let col = Column::from_case(c, model, ids)?;
        let (depth, fast, slow) = (self.probe_depth, self.fast_tolerance, self.slow_tolerance);
        Ok(Box::new(ShockCheck::new(col, depth, fast, slow, model, coll)?))
    }
}

/// Time at which a front passes, picked from samples `(t, p)` restricted to `[t0, t1]`:
/// the first time p crosses the mid-level between its value at `t0` and the level it settles at
/// after the front, where that level is the median of p over the second half of the window.
/// A front smeared symmetrically by numerical dispersion crosses its mid-level at the true arrival;
/// the median ignores the ringing behind the front. Linear interpolation between samples.
/// No front (`None`) unless the jump is at least 5 % of the largest |p| of the whole record, so
/// that noise before an arrival is never taken for one.
pub fn pick_arrival(samples: &[(f64, f64)], t0: f64, t1: f64) -> Option<f64> {
    let scale = samples.iter().map(|s| s.1.abs()).fold(0.0, f64::max);
    let win: Vec<(f64, f64)> = samples.iter().copied().filter(|s| s.0 >= t0 && s.0 <= t1).collect();
    if win.len() < 4 {
        return None;
    }
    let before = win[0].1;
    let mut tail: Vec<f64> = win[win.len() / 2..].iter().map(|s| s.1).collect();
    tail.sort_by(|a, b| a.total_cmp(b));
    let after = tail[tail.len() / 2];
    if (after - before).abs() < 0.05 * scale || scale == 0.0 {
        return None;
    }
    let mid = 0.5 * (before + after);
    let rising = after > before;
    for w in win.windows(2) {
        let (a, b) = (w[0], w[1]);
        let crossed = if rising { a.1 < mid && b.1 >= mid } else { a.1 > mid && b.1 <= mid };
        if crossed {
            return Some(a.0 + (mid - a.1) / (b.1 - a.1) * (b.0 - a.0));
        }
    }
    None
}

/// The shock-wave check.
pub struct ShockCheck {
    col: Column,
    probe: u64,
    depth: f64,
    fast_speed: f64,
    slow_speed: f64,
    slow_expected: bool,
    tolerances: (f64, f64),
    samples: Vec<(f64, f64)>,
    /// Picked (fast, slow) arrivals after [`Check::finish`].
    picked: (Option<f64>, Option<f64>),
}

impl ShockCheck {
    /// Follows the particle nearest to `probe_depth` below the top of the column on its axis.
    pub(crate) fn new(
        col: Column,
        probe_depth: f64,
        fast_tol: f64,
        slow_tol: f64,
        model: &Model,
        coll: &Collective,
    ) -> Result<ShockCheck, String> {
        let target = [col.x_centre, col.top - probe_depth];
        let local: Vec<f64> = col
            .particles(model)
            .flat_map(|k| {
                let x = model.particles.x0[k];
                [((x[0] - target[0]).powi(2) + (x[1] - target[1]).powi(2)).sqrt(), model.particles.id[k] as f64, x[1]]
            })
            .collect();
        let all = coll.gather(&local)?;
        let best = all.chunks(3).min_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
        let best = best.ok_or("the shock-wave column has no particles")?;
        let q_mod = if col.inv_q > 0.0 { 1.0 / col.inv_q } else { f64::INFINITY };
        let rho = (1.0 - col.porosity) * col.solid_density + col.porosity * col.water_density;
        let fast_speed = super::waves::undrained_wave_speed(col.constrained_modulus, q_mod, rho);
        let slow_speed = super::waves::damped_wave_speed(
            col.constrained_modulus,
            col.water_bulk_modulus,
            col.porosity,
            col.water_density,
        );
        let depth = col.top - best[2];
        // The slow wave is damped by drag at the rate ω_c = n g / k; it is visible at the probe if it
        // has not decayed by more than a factor 10 on the way: exp(−ω_c t_s / 2) > 0.1.
        let omega_c = col.porosity * col.g / col.conductivity;
        let slow_expected = (-omega_c * depth / slow_speed / 2.0).exp() > 0.1;
        Ok(ShockCheck {
            probe: best[1] as u64,
            depth,
            fast_speed,
            slow_speed,
            slow_expected,
            tolerances: (fast_tol, slow_tol),
            samples: vec![(0.0, 0.0)],
            picked: (None, None),
            col,
        })
    }

    /// The relative error of the arrival `picked` of the wave of speed `speed` (named `v`) at the
    /// probe, against depth / speed; NaN with `missing` where no front was picked.
    fn arrival(&self, picked: Option<f64>, speed: f64, v: &str, tol: f64, missing: String) -> Metric {
        let expected = self.depth / speed;
        match picked {
            Some(t) => Metric::error(
                (t - expected).abs() / expected,
                tol,
                format!("arrival {t:.5e} s vs depth/{v} = {:.4} m / {speed:.1} m/s = {expected:.5e} s", self.depth),
            ),
            None => Metric::error(f64::NAN, tol, missing),
        }
    }
}

impl Check for ShockCheck {
    fn columns(&self) -> Vec<String> {
        vec!["shock.p_probe".into(), "shock.p_probe_over_q".into()]
    }

    fn observe(&mut self, t: f64, _dt: f64, model: &Model, coll: &Collective) -> Result<Vec<f64>, String> {
        let local: f64 = (0..model.particles.len())
            .filter(|&k| model.particles.id[k] == self.probe)
            .map(|k| model.particles.p[k])
            .sum();
        let p = coll.sum(&[local])?[0];
        self.samples.push((t, p));
        Ok(vec![p, p / self.col.load])
    }

    fn checkpoint_state(&self, _model: &Model, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        Ok(Some(self.samples.iter().flat_map(|&(t, p)| [t, p]).collect()))
    }

    /// The last sample (at the checkpoint's time) is left out: the restarted run observes it again.
    fn restore_state(&mut self, state: &[f64], _model: &Model) -> Result<(), String> {
        if state.len() < 2 || !state.len().is_multiple_of(2) {
            return Err(format!("{} values do not make (t, p) samples", state.len()));
        }
        self.samples = state.chunks(2).map(|r| (r[0], r[1])).collect();
        self.samples.pop();
        Ok(())
    }

    fn finish(&mut self, _model: &Model, _coll: &Collective) -> Result<Findings, String> {
        let t_fast = self.depth / self.fast_speed;
        let t_slow = self.depth / self.slow_speed;
        let (tf, ts) = self.tolerances;
        let mut out = Vec::new();
        // Fast front: between the start and halfway to the slow front.
        let split = 0.5 * (t_fast + t_slow);
        let fast = pick_arrival(&self.samples, 0.0, split);
        self.picked.0 = fast;
        let missing = "no fast front found in p(t) (run too short?)".to_string();
        out.push(("fast_wave_arrival_rel_error".to_string(), self.arrival(fast, self.fast_speed, "V_u", tf, missing)));
        if self.slow_expected {
            let end = split + 2.0 * (t_slow - split);
            let slow = pick_arrival(&self.samples, split, end);
            self.picked.1 = slow;
            let missing = format!("no slow front found in p(t) up to {end:.4e} s (run too short?)");
            out.push((
                "slow_wave_arrival_rel_error".to_string(),
                self.arrival(slow, self.slow_speed, "V_d", ts, missing),
            ));
        }
        Ok((out, Vec::new()))
    }

    fn figures(&self) -> Vec<crate::plot::Figure> {
        let q = self.col.load;
        let over_q: Vec<(f64, f64)> = self.samples.iter().map(|&(t, p)| (t, p / q)).collect();
        let mut expected = vec![("fast arrival d/V_u", self.depth / self.fast_speed)];
        let mut picked = vec![("fast arrival", self.picked.0)];
        if self.slow_expected {
            expected.push(("slow arrival d/V_d", self.depth / self.slow_speed));
            picked.push(("slow arrival", self.picked.1));
        }
        vec![super::figures::shock_history(&over_q, self.depth, &expected, &picked)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_smeared_step_with_ringing_is_picked_at_its_midpoint() {
        let t0 = 2.0e-4;
        let samples: Vec<(f64, f64)> = (0..400)
            .map(|i| {
                let t = i as f64 * 1e-6;
                let x = (t - t0) / 3e-6;
                let step = 0.5 * (1.0 + (x).tanh());
                let ring = if x > 2.0 { 0.15 * (x * 1.3).sin() * (-(x - 2.0) / 20.0).exp() } else { 0.0 };
                (t, 0.5 * (step + ring))
            })
            .collect();
        let t = pick_arrival(&samples, 0.0, 3.9e-4).unwrap();
        assert!((t - t0).abs() < 1e-6, "picked {t}");
        assert!(pick_arrival(&samples[..3], 0.0, 1.0).is_none());
        // Before the front there is only noise: no arrival.
        let noisy: Vec<(f64, f64)> = samples.iter().map(|&(t, p)| (t, p + 1e-6 * (t * 1e7).sin())).collect();
        assert!(pick_arrival(&noisy, 0.0, 1.5e-4).is_none());
    }
}
