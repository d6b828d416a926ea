//! Stability diagnostics of every run and the warnings they raise.
//!
//! Every history row carries, in two-phase runs, the checkerboard index and the pressure
//! oscillation index of the particles' pore pressures (see [`crate::verification::checkerboard`])
//! and their range; in runs with dynamic stages the running energy balance ([`energy`]). When one
//! crosses its threshold the run warns once, in the terminal and in `summary.json.warnings`, with
//! what to change. The case itself is checked before the run for parameter combinations known to
//! lock or to oscillate ([`physics`]). Non-finite values are caught where they arise (the residual
//! and the particle update name the material point and the quantity) and end the step or the run.

pub mod energy;
pub mod physics;

use crate::model::Model;
use crate::parallel::Collective;
use crate::soils::{principal::Principal, Stress};
use serde::{Deserialize, Serialize};

/// A warning of the run: a diagnostic past its threshold, or a case that is known to misbehave.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Warning {
    /// What it is about: `pressure_oscillation`, `energy_balance` (from the run), or
    /// `equal_order_near_undrained`, `locking`, `single_point_cells`, `unresolved_consolidation`,
    /// `undamped_large_step`, `patch_recovery_quasi_static` (from the case).
    pub kind: String,
    /// What was seen, and what to change.
    pub message: String,
    /// Simulated time at which the threshold was first crossed [s] (run diagnostics).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_s: Option<f64>,
    /// The value that crossed it (the first; `summary.json` keeps the worst of the run beside it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<f64>,
    /// The threshold.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threshold: Option<f64>,
}

/// The pressure oscillation index above which a run warns when it persists: the largest deviation
/// of a particle's pore pressure from its local smooth fit, over the stress scale of the run (see
/// [`Monitor::row`]). Measured (docs/extreme.md): the shipped Terzaghi column peaks at 0.25 on
/// the first step of its sudden load and is below 0.05 from the fourth; the unstabilised
/// near-undrained column stays at 0.34.
pub const OSCILLATION_LIMIT: f64 = 0.1;

/// How many history rows in a row the oscillation index must exceed [`OSCILLATION_LIMIT`] (or be
/// above it at the end of the run) before the run warns: a sudden load's first steps may ring
/// near a drained boundary and settle.
pub const OSCILLATION_ROWS: usize = 5;

/// The relative energy imbalance of the dynamic stages at the end of a run above which it warns.
/// Measured (docs/extreme.md): the shipped dynamic cases end within 0.06 (the Terzaghi column,
/// whose sudden load's first wave the generalized-α method damps), the waves within 0.035. The
/// first steps of a run can show any ratio of tiny energies, so only the end counts.
pub const ENERGY_LIMIT: f64 = 0.1;

/// What the diagnostics of one history row found (two-phase fields NaN in one-phase runs, energy
/// fields NaN without a dynamic step).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// Checkerboard index of the pore pressures.
    pub checkerboard: f64,
    /// Largest deviation from the smooth fit over the stress scale.
    pub oscillation: f64,
    /// Smallest and largest particle pore pressure [Pa].
    pub p_range: [f64; 2],
    /// The energy balance so far.
    pub energy: Option<energy::Balance>,
}

/// The running diagnostics of a run.
#[derive(Debug, Clone, Default)]
pub struct Monitor {
    pore_water: bool,
    dynamic: bool,
    /// The energy ledger of the dynamic steps.
    pub ledger: energy::Ledger,
    kinetic_max: f64,
    /// History rows in a row with the oscillation index above its limit.
    streak: usize,
    /// The last row's oscillation index and energy imbalance (NaN: none).
    last: [f64; 2],
    /// Kinds already warned about.
    warned: Vec<String>,
    /// Worst values of the run: oscillation index, checkerboard index, p_min, p_max, energy error.
    pub worst: Worst,
}

/// The extremes of the diagnostics over a run's history rows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Worst {
    /// Largest pressure oscillation index.
    pub oscillation: f64,
    /// Largest checkerboard index.
    pub checkerboard: f64,
    /// Smallest and largest particle pore pressure [Pa].
    pub p_range: [f64; 2],
    /// The relative energy imbalance at the last history row.
    pub energy: f64,
}

impl Default for Worst {
    fn default() -> Worst {
        Worst { oscillation: f64::NAN, checkerboard: f64::NAN, p_range: [f64::NAN; 2], energy: f64::NAN }
    }
}

/// The larger of two values, NaN counting as "none yet" unless both are.
fn worse(a: f64, b: f64) -> f64 {
    if a.is_nan() {
        b
    } else if b.is_nan() {
        a
    } else {
        a.max(b)
    }
}

impl Monitor {
    /// The diagnostics of a run; `dynamic`: whether any stage is dynamic.
    pub fn new(pore_water: bool, dynamic: bool) -> Monitor {
        Monitor { pore_water, dynamic, last: [f64::NAN; 2], ..Monitor::default() }
    }

    /// The history columns of the diagnostics.
    pub fn columns(&self) -> Vec<String> {
        let mut c = Vec::new();
        if self.pore_water {
            c.extend(["checkerboard_index", "pressure_oscillation_index", "p_min", "p_max"].map(String::from));
        }
        if self.dynamic {
            c.extend(
                ["energy_external", "energy_internal", "energy_kinetic", "energy_dissipated", "energy_balance_error"]
                    .map(String::from),
            );
        }
        c
    }

    /// The diagnostics of the current state (collective), its history values and the warnings it
    /// raises for the first time. The stress scale of the oscillation index is the largest
    /// principal total stress magnitude |σ' − p I| over the particles (the load a footing or a
    /// column carries, the overburden of a slope), so a spurious pressure is measured against what
    /// the soil carries and not against itself. The checkerboard fit runs in any dimension.
    pub fn row<const D: usize>(
        &mut self,
        model: &Model<D>,
        owners: &crate::distribution::Owners<D>,
        coll: &Collective,
        t: f64,
    ) -> Result<(Vec<f64>, Vec<Warning>), String> {
        let mut values = Vec::new();
        let mut warnings = Vec::new();
        if self.pore_water {
            let fit = crate::verification::checkerboard::pressure_fit(model, owners, coll)?;
            let ps = &model.particles;
            let (mut lo, mut hi, mut scale) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
            for k in 0..ps.len() {
                lo = lo.min(ps.p[k]);
                hi = hi.max(ps.p[k]);
                scale = scale.max(principal_magnitude(ps.stress[k], ps.p[k]));
            }
            let m = coll.max(&[-lo, hi, scale])?;
            let (lo, hi, scale) = (-m[0], m[1], m[2]);
            let oscillation = if scale > 0.0 { fit.max_deviation / scale } else { 0.0 };
            values.extend([fit.index, oscillation, lo, hi]);
            let w = &mut self.worst;
            w.oscillation = worse(w.oscillation, oscillation);
            w.checkerboard = worse(w.checkerboard, fit.index);
            w.p_range = [-worse(-w.p_range[0], -lo), worse(w.p_range[1], hi)];
            self.last[0] = oscillation;
            self.streak = if oscillation > OSCILLATION_LIMIT { self.streak + 1 } else { 0 };
            if self.streak >= OSCILLATION_ROWS {
                warnings.extend(self.oscillation_warning(t));
            }
        }
        if self.dynamic {
            let summed = coll.sum(&self.ledger.local)?;
            self.kinetic_max = self.kinetic_max.max(summed[4]);
            let b = self.ledger.balance(&summed, self.kinetic_max);
            values.extend([b.external, b.internal, b.kinetic, b.dissipated, b.error]);
            self.worst.energy = b.error;
            self.last[1] = b.error;
        }
        Ok((values, warnings))
    }

    /// The warnings of the end of the run: an oscillation index above its limit at the last row,
    /// an energy imbalance above its limit.
    pub fn finish(&mut self, t: f64) -> Vec<Warning> {
        let mut out = Vec::new();
        if self.last[0] > OSCILLATION_LIMIT {
            out.extend(self.oscillation_warning(t));
        }
        let e = self.last[1];
        if e > ENERGY_LIMIT {
            out.extend(self.first("energy_balance", t, e, ENERGY_LIMIT, || {
                format!(
                    "the energy balance of the dynamic stages is off by {e:.3} of its largest term (limit {ENERGY_LIMIT}): the time integration dissipated (or created) that share of the work, \
                     so the time step does not resolve the motion; take smaller steps, or, for a slow process, a quasi_static or static stage"
                )
            }));
        }
        out
    }

    fn oscillation_warning(&mut self, t: f64) -> Option<Warning> {
        let v = self.last[0];
        self.first("pressure_oscillation", t, v, OSCILLATION_LIMIT, || {
            format!(
                "the pore pressure oscillates from particle to particle: a particle deviates from its local smooth fit by {v:.2} of the largest total stress (limit {OSCILLATION_LIMIT}), \
                 for {OSCILLATION_ROWS} history rows in a row or at the end; equal-order pressures need stabilisation near undrained conditions: set stabilisation.pressure_projection = 2.0 \
                 (or, in a dynamic stage, patch_recovery = true), or take larger steps; in an explicit two-phase stage, use the point-wise pore pressure (the default), and write \
                 history rows less often than every step (a sudden load's wave front trips this check for a few steps)"
            )
        })
    }

    /// A warning of `kind`, unless one was given already.
    fn first(
        &mut self,
        kind: &str,
        t: f64,
        value: f64,
        threshold: f64,
        message: impl FnOnce() -> String,
    ) -> Option<Warning> {
        if self.warned.iter().any(|k| k == kind) {
            return None;
        }
        self.warned.push(kind.to_string());
        Some(Warning {
            kind: kind.into(),
            message: message(),
            time_s: Some(t),
            value: Some(value),
            threshold: Some(threshold),
        })
    }

    /// The state a checkpoint keeps (collective): the worst values, the energy ledger summed over
    /// ranks, the largest kinetic energy, the oscillation streak and the last row's values, and
    /// which run warnings were given.
    pub fn state(&self, coll: &Collective) -> Result<Vec<f64>, String> {
        let w = &self.worst;
        let mut v = vec![w.oscillation, w.checkerboard, w.p_range[0], w.p_range[1], w.energy, self.ledger.external];
        v.extend(coll.sum(&self.ledger.local)?);
        v.push(self.kinetic_max);
        v.extend([self.streak as f64, self.last[0], self.last[1]]);
        v.extend(RUN_KINDS.iter().map(|k| if self.warned.iter().any(|w| w == k) { 1.0 } else { 0.0 }));
        Ok(v)
    }

    /// Continues from a checkpoint's [`Monitor::state`]; the ledger's sums go to rank 0
    /// (`first`), so that their sum over any number of ranks is the checkpoint's.
    pub fn restore_state(&mut self, v: &[f64], first: bool) -> Result<(), String> {
        if v.len() != 15 + RUN_KINDS.len() {
            return Err(format!("its diagnostics hold {} values, not {}", v.len(), 15 + RUN_KINDS.len()));
        }
        self.worst = Worst { oscillation: v[0], checkerboard: v[1], p_range: [v[2], v[3]], energy: v[4] };
        self.ledger.external = v[5];
        self.ledger.local = if first { [v[6], v[7], v[8], v[9], v[10]] } else { [0.0, 0.0, 0.0, 0.0, 0.0] };
        self.kinetic_max = v[11];
        self.streak = v[12] as usize;
        self.last = [v[13], v[14]];
        for (k, &f) in RUN_KINDS.iter().zip(&v[15..]) {
            if f != 0.0 && !self.warned.iter().any(|w| w == k) {
                self.warned.push(k.to_string());
            }
        }
        Ok(())
    }
}

/// The warnings the run's diagnostics give (at most once each).
const RUN_KINDS: [&str; 2] = ["pressure_oscillation", "energy_balance"];

/// The largest principal magnitude of the total stress σ' − p I.
fn principal_magnitude(s: Stress, p: f64) -> f64 {
    let total = [s[0] - p, s[1] - p, s[2], s[3] - p, s[4], s[5]];
    Principal::of(&total).values.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stress_scale_is_the_largest_principal_total_stress() {
        // σ' = diag(−100, −300), p = 50: total diag(−150, −350).
        assert_eq!(principal_magnitude([-100.0, -300.0, 0.0, -80.0, 0.0, 0.0], 50.0), 350.0);
        // Pure shear 40 on zero: principal ±40.
        assert!((principal_magnitude([0.0, 0.0, 40.0, 0.0, 0.0, 0.0], 0.0) - 40.0).abs() < 1e-12);
        // Shear out of the plane: yz = 30, zx = 40 give principal ±50.
        assert!((principal_magnitude([0.0, 0.0, 0.0, 0.0, 30.0, 40.0], 0.0) - 50.0).abs() < 1e-12);
    }

    #[test]
    fn worst_values_skip_the_missing() {
        assert_eq!(worse(f64::NAN, 2.0), 2.0);
        assert_eq!(worse(3.0, f64::NAN), 3.0);
        assert_eq!(worse(3.0, 4.0), 4.0);
        assert!(worse(f64::NAN, f64::NAN).is_nan());
    }
}
