//! The plastic work dissipated by the skeleton (`plastic_dissipation` in `history.csv`):
//! W_p = Σ_steps Σ_p V_p σ'_{n+1} : Δε^p with the plastic strain increment of the step's return
//! mapping, Δε^p = Δε − C⁻¹(σ'_{n+1} − σ'_n), C the point's linear
//! isotropic elasticity (Δε^e = Δs/2G + Δσ_m/3K per normal component, Δτ/G per engineering
//! shear), σ' the effective stress after the step and V_p the point's volume after it [J per m in
//! plane strain, J in axial symmetry and in three dimensions]. It is the dissipation of the
//! backward-Euler return itself (for von Mises, q Δε̄ per unit volume), exact for an unrotated
//! step and second order in the step's rotation otherwise (σ'_n is taken unrotated). Points of a
//! finite-strain model (neo-Hookean, Hencky–J2, the Newtonian fluid), whose elasticity is not C,
//! are not counted.

use super::{Converged, FromCheckpoint, Moment, Recorder, Restored, Sink};
use crate::soils::Stress;

/// Whether a model has points whose plastic work this recorder counts (a Mohr–Coulomb or von
/// Mises material).
pub fn applies<const D: usize>(model: &crate::model::Model<D>) -> bool {
    model.materials.iter().any(|m| m.model.dissipates())
}

/// The plastic dissipation so far.
#[derive(Default)]
pub struct Dissipation {
    /// Over the run, summed over the ranks, up to the last accepted step [J (per m)].
    total: f64,
    /// This rank's share of the last converged step (kept until the step is accepted).
    pending: f64,
}

/// σ'_{n+1} : Δε^p of one point: the stress `after` the step from `before`, the strain increment
/// `deps` (engineering shears), the elastic moduli `bulk` and `shear`.
fn dissipation_density(before: &Stress, after: &Stress, deps: &Stress, bulk: f64, shear: f64) -> f64 {
    let dmean = (after[0] - before[0] + after[1] - before[1] + after[3] - before[3]) / 3.0;
    let mut w = 0.0;
    for c in 0..6 {
        let ds = after[c] - before[c];
        let elastic = match c {
            0 | 1 | 3 => (ds - dmean) / (2.0 * shear) + dmean / (3.0 * bulk),
            _ => ds / shear,
        };
        w += after[c] * (deps[c] - elastic);
    }
    w
}

impl<const D: usize> Recorder<D> for Dissipation {
    fn name(&self) -> &'static str {
        "plastic_dissipation"
    }

    fn columns(&self) -> Vec<String> {
        vec!["plastic_dissipation".into()]
    }

    fn converged(&mut self, at: &Converged<D>) -> Result<(), String> {
        let ps = &at.model.particles;
        self.pending = 0.0;
        for (k, r) in at.results.iter().enumerate() {
            let model = &at.model.materials[ps.material[k] as usize].model;
            if !model.dissipates() {
                continue;
            }
            let e = model.elastic();
            let w = dissipation_density(&ps.stress[k], &r.stress, &r.deps, e.bulk_modulus(), e.shear_modulus());
            self.pending += w * ps.volume[k] * r.jacobian;
        }
        Ok(())
    }

    fn record(&mut self, at: &Moment<D>, _row: bool, _sink: &mut Sink) -> Result<Vec<f64>, String> {
        if at.step > 0 {
            self.total += at.coll.sum(&[std::mem::take(&mut self.pending)])?[0];
        }
        Ok(vec![self.total])
    }

    fn state(&self, _at: &Moment<D>) -> Result<Option<Vec<f64>>, String> {
        Ok(Some(vec![self.total]))
    }

    fn restore(&mut self, FromCheckpoint { state, .. }: FromCheckpoint<D>) -> Restored {
        self.total = state.and_then(|s| s.first().copied()).unwrap_or(0.0);
        Ok(None)
    }
}
