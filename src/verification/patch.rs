//! Patch tests: a body driven through a homogeneous deformation by its boundary nodes (a
//! boundary's `velocity_gradient`) must carry one uniform stress, the one linear elasticity gives
//! for the flow. The basis reproduces linear fields (also with B̄, also where barely filled nodes
//! are extended, also for perturbed particle arrangements), so every particle must see the same
//! deformation gradient, to round-off, whatever the step and however many steps.
//!
//! Metrics (computed from the body's particles after every step; the last are reported):
//! * `stress_spread` = max_p ‖σ_p − σ̄‖ / ‖σ̄‖ (tensor norms; σ̄ the particles' mean stress);
//! * `stress_rel_error` = ‖σ̄ − σ*‖ / ‖σ*‖ with σ* = R σ₀ Rᵀ + D ln V, F = exp(L s) = V R, s = ∫ f dt
//!   (exact for a pure stretch, where the Hughes–Winget increments sum to ln V up to O(Δt²) per
//!   step, and for a pure rotation, which it rotates exactly); for a neo-Hookean body σ* is its
//!   stress of F itself, exact to round-off.

use super::{all_positive, BuiltCheck, Check, CheckParameters, Findings, FormulationNeed, Metric};
use crate::case::{BodyId, BoundaryId, Case, Formulation, SoilModel};
use crate::check::Checked;
use crate::model::loads::Motion;
use crate::model::Model;
use crate::parallel::Collective;
use crate::soils::finite_strain::{embed, mul, M3};
use crate::soils::principal::{self, Principal};
use crate::soils::{Constitutive, LinearElastic, NeoHookeanLaw, Stress, NS};
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "patch"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Patch {
    /// The name of the body (linear elastic or neo-Hookean).
    pub body: String,
    /// The name of the boundary whose homogeneous flow (`velocity_gradient`) drives it.
    pub boundary: String,
    /// Largest accepted spread of the particles' stresses, max ‖σ_p − σ̄‖/‖σ̄‖ [-], in (0, 1] (default
    /// 1e-9).
    #[serde(default = "default_spread_tol")]
    pub spread_tolerance: f64,
    /// Largest accepted ‖σ̄ − σ*‖/‖σ*‖ against the linear-elastic stress of the flow [-], in (0, 1]
    /// (default 1e-6).
    #[serde(default = "default_patch_tol")]
    pub tolerance: f64,
}

serde_defaults! { default_spread_tol: f64 = 1e-9, default_patch_tol: f64 = 1e-6 }

/// What a patch test names.
#[derive(Debug, Clone, Copy)]
pub struct PatchIds {
    /// `body`.
    pub body: BodyId,
    /// `boundary`: it has a `velocity_gradient`.
    pub boundary: BoundaryId,
}

impl CheckParameters for Patch {
    type Ids = PatchIds;
    const FORMULATION: FormulationNeed =
        Some((Formulation::OnePhase, "the patch reference is for a one_phase analysis"));
    const SOLID: bool = true;

    fn check(&self, key: &str) -> Checked {
        all_positive(key, &[("spread_tolerance", self.spread_tolerance), ("tolerance", self.tolerance)])
    }

    fn describe(&self) -> String {
        format!("patch test: uniform stress under the homogeneous flow of boundary `{}`", self.boundary)
    }

    /// The body, linear elastic or neo-Hookean, and the boundary, with a `velocity_gradient`.
    fn link(&self, c: &Case) -> Result<PatchIds, String> {
        let ids = PatchIds {
            body: c.body_named("verification.body", &self.body)?,
            boundary: c.boundary_named("verification.boundary", &self.boundary)?,
        };
        if !matches!(c.material_of(ids.body).model, SoilModel::LinearElastic(_) | SoilModel::NeoHookean(_)) {
            return Err(format!(
                "key `verification.body`: the patch reference needs a linear elastic or neo-Hookean body, and `{}` is \
                 neither",
                c.body(ids.body).name
            ));
        }
        let b = c.boundary(ids.boundary);
        if b.velocity_gradient.is_none() {
            return Err(format!("key `verification.boundary`: `{}` has no `velocity_gradient`", b.name));
        }
        Ok(ids)
    }

    fn plane(&self, c: &Case, ids: &PatchIds, model: &Model, _coll: &Collective) -> BuiltCheck {
        Ok(Box::new(PatchCheck::new(c, model, self, ids)?))
    }

    fn solid(&self, c: &Case, ids: &PatchIds, model: &Model<3>, _coll: &Collective) -> BuiltCheck<3> {
        Ok(Box::new(PatchCheck::new(c, model, self, ids)?))
    }
}

/// The patch check of a case of dimension `D`.
pub struct PatchCheck<const D: usize = 2> {
    body: u16,
    motion: Motion<D>,
    elastic: LinearElastic,
    /// A neo-Hookean body's model (its σ* is the model's stress of F).
    hyperelastic: Option<NeoHookeanLaw>,
    initial: Stress,
    spread_tolerance: f64,
    tolerance: f64,
    /// (stress spread, error against σ*, t) after the last step.
    last: (f64, f64, f64),
}

/// ‖s‖ of a stress vector as a tensor (the shears counted twice).
fn norm(s: &Stress) -> f64 {
    (s[0] * s[0] + s[1] * s[1] + s[3] * s[3] + 2.0 * (s[2] * s[2] + s[4] * s[4] + s[5] * s[5])).sqrt()
}

/// ln V and R of the polar decomposition F = V R: V² = F Fᵀ diagonalised (its principal values
/// and directions), ln V = Σ ½ ln λ_i e_i e_iᵀ and R = V⁻¹ F with V⁻¹ = Σ λ_i^{−1/2} e_i e_iᵀ.
fn log_stretch_and_rotation(f: &M3) -> (Stress, M3) {
    let ft: M3 = std::array::from_fn(|i| std::array::from_fn(|k| f[k][i]));
    let b = Principal::of(&principal::vector(&mul(*f, ft)));
    let ln_v = b.compose(&b.values.map(|l| 0.5 * l.ln()));
    let v_inv = principal::tensor(&b.compose(&b.values.map(|l| 1.0 / l.sqrt())));
    (ln_v, mul(v_inv, *f))
}

impl<const D: usize> PatchCheck<D> {
    /// The check of a `patch` verification `spec`, whose names resolve to `ids`.
    pub fn new(c: &Case, model: &Model<D>, spec: &Patch, ids: &PatchIds) -> Result<PatchCheck<D>, String> {
        let (elastic, hyperelastic) = match c.material_of(ids.body).model.law() {
            Constitutive::LinearElastic(el) => (el, None),
            Constitutive::NeoHookean(nh) => (nh.elastic, Some(nh)),
            _ => return Err(format!("body `{}` is not elastic (linear or neo-Hookean)", spec.body)),
        };
        let motion = model.boundaries[ids.boundary.index()]
            .motion
            .clone()
            .ok_or(format!("boundary `{}` has no motion", spec.boundary))?;
        Ok(PatchCheck {
            body: ids.body.index() as u16,
            motion,
            elastic,
            hyperelastic,
            initial: c.body(ids.body).uniform_stress_vector().unwrap_or([0.0; NS]),
            spread_tolerance: spec.spread_tolerance,
            tolerance: spec.tolerance,
            last: (f64::NAN, f64::NAN, 0.0),
        })
    }

    /// σ* at time `t` (see the module documentation): the initial stress turned by R, plus the
    /// elastic stress of the logarithmic strain ln V (engineering shears), F = exp(L s) = V R.
    pub fn theory(&self, t: f64) -> Stress {
        let Some(f) = self.motion.flow(self.motion.flow_parameter(t)) else { return self.initial };
        let f = embed(&f);
        if let Some(h) = &self.hyperelastic {
            return h.stress(f).unwrap_or([f64::NAN; NS]);
        }
        let (ln_v, r) = log_stretch_and_rotation(&f);
        let mut s = principal::rotate(&r, &self.initial);
        let eps: Stress = std::array::from_fn(|c| {
            if principal::TENSOR_INDEX[c].0 == principal::TENSOR_INDEX[c].1 {
                ln_v[c]
            } else {
                2.0 * ln_v[c]
            }
        });
        for (i, si) in s.iter_mut().enumerate() {
            *si += (0..NS).map(|j| self.elastic.d[i][j] * eps[j]).sum::<f64>();
        }
        s
    }

    fn measure(&self, model: &Model<D>, coll: &Collective) -> Result<(f64, Stress), String> {
        let ps = &model.particles;
        let mine: Vec<usize> = (0..ps.len()).filter(|&k| ps.body[k] == self.body).collect();
        let mut local = [0.0; NS + 1];
        for &k in &mine {
            for (l, s) in local.iter_mut().zip(ps.stress[k]) {
                *l += s;
            }
            local[NS] += 1.0;
        }
        let sum = coll.sum(&local)?;
        let mean: Stress = std::array::from_fn(|c| sum[c] / sum[NS].max(1.0));
        let worst = mine.iter().fold(0.0f64, |w, &k| {
            let d: Stress = std::array::from_fn(|c| ps.stress[k][c] - mean[c]);
            w.max(norm(&d))
        });
        let worst = coll.max(&[worst])?[0];
        Ok((worst / norm(&mean).max(f64::MIN_POSITIVE), mean))
    }
}

impl<const D: usize> Check<D> for PatchCheck<D> {
    fn columns(&self) -> Vec<String> {
        vec!["patch.stress_spread".into(), "patch.stress_rel_error".into()]
    }

    fn observe(&mut self, t: f64, _dt: f64, model: &Model<D>, coll: &Collective) -> Result<Vec<f64>, String> {
        let (spread, mean) = self.measure(model, coll)?;
        let theory = self.theory(t);
        let d: Stress = std::array::from_fn(|c| mean[c] - theory[c]);
        let error = if norm(&theory) > 0.0 { norm(&d) / norm(&theory) } else { norm(&d) };
        self.last = (spread, error, t);
        Ok(vec![spread, error])
    }

    fn finish(&mut self, _model: &Model<D>, _coll: &Collective) -> Result<Findings, String> {
        let (spread, error, t) = self.last;
        let theory = self.theory(t);
        Ok((
            vec![
                (
                    "stress_spread".into(),
                    Metric::error(spread, self.spread_tolerance, format!("max ‖σ_p − σ̄‖/‖σ̄‖ at t = {t:.6e} s")),
                ),
                (
                    "stress_rel_error".into(),
                    Metric::error(
                        error,
                        self.tolerance,
                        format!(
                            "‖σ̄ − σ*‖/‖σ*‖ at t = {t:.6e} s, σ* = [{}] Pa",
                            theory[..if D == 3 { NS } else { 4 }]
                                .iter()
                                .map(|v| format!("{v:.6e}"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    ),
                ),
            ],
            Vec::new(),
        ))
    }

    fn checkpoint_state(&self, _model: &Model<D>, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        Ok(Some(vec![self.last.0, self.last.1, self.last.2]))
    }

    fn restore_state(&mut self, state: &[f64], _model: &Model<D>) -> Result<(), String> {
        if let [a, b, c] = state {
            self.last = (*a, *b, *c);
            Ok(())
        } else {
            Err("the patch check's state has 3 values".into())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::loads::TimeFn;
    use crate::soils;

    fn check<const D: usize>(l: [[f64; D]; D], initial: Stress) -> PatchCheck<D> {
        PatchCheck {
            body: 0,
            motion: Motion {
                is_displacement: false,
                vector: [0.0; D],
                gradient: Some((l, [0.0; D])),
                time_fn: TimeFn::Constant(1.0),
            },
            elastic: LinearElastic::new(1e6, 0.3),
            hyperelastic: None,
            initial,
            spread_tolerance: 1e-9,
            tolerance: 1e-6,
            last: (0.0, 0.0, 0.0),
        }
    }

    fn close(a: &Stress, b: &Stress, tol: f64) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
    }

    #[test]
    fn the_reference_of_a_rotation_and_of_a_stretch() {
        // A quarter turn turns the stress.
        let w = std::f64::consts::FRAC_PI_2;
        let s = check([[0.0, -w], [w, 0.0]], soils::plane([3.0, 1.0, 0.5, 2.0])).theory(1.0);
        assert!((s[0] - 1.0).abs() < 1e-12 && (s[1] - 3.0).abs() < 1e-12 && (s[2] + 0.5).abs() < 1e-12);
        // A stretch along x: ε_xx = ln λ, plane strain.
        let s = check([[1e-3, 0.0], [0.0, 0.0]], [0.0; NS]).theory(1.0);
        let el = LinearElastic::new(1e6, 0.3);
        assert!((s[0] - el.d[0][0] * 1e-3).abs() < 1e-9 && (s[1] - el.d[1][0] * 1e-3).abs() < 1e-9);
    }

    /// In three dimensions: a turn about a skew axis turns the full stress (R σ₀ Rᵀ with Rodrigues'
    /// R), a stretch along z gives ε_zz = ln λ, a plane flow embedded in three dimensions gives the
    /// plane reference, and a flow of stretch and spin together is R σ₀ Rᵀ + D ln V (checked
    /// against V and R rebuilt: V R = F, V symmetric, R orthogonal).
    #[test]
    fn the_reference_in_three_dimensions() {
        let sigma0: Stress = [3.0, 1.0, 0.5, 2.0, -0.7, 0.4];
        let axis = [2.0f64, -1.0, 2.0].map(|v| v / 3.0);
        let angle = 0.9;
        let w = [[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]];
        let s = check(w.map(|r| r.map(|v| v * angle)), sigma0).theory(1.0);
        let turned = principal::rotate(&principal::rotation(axis, angle), &sigma0);
        // ln V of a rotation is round-off (1e-16), times E = 1e6 Pa.
        assert!(close(&s, &turned, 1e-8), "{s:?} against {turned:?}");

        let s = check([[0.0; 3], [0.0; 3], [0.0, 0.0, 2e-3]], [0.0; NS]).theory(1.0);
        let el = LinearElastic::new(1e6, 0.3);
        let expected: Stress = std::array::from_fn(|c| el.d[c][3] * 2e-3);
        assert!(close(&s, &expected, 1e-9), "{s:?} against {expected:?}");

        let plane = [[1e-3, 3e-4], [-2e-4, -5e-4]];
        let s2 = check(plane, soils::plane([3.0, 1.0, 0.5, 2.0])).theory(0.7);
        let s3 =
            check([[1e-3, 3e-4, 0.0], [-2e-4, -5e-4, 0.0], [0.0; 3]], soils::plane([3.0, 1.0, 0.5, 2.0])).theory(0.7);
        assert!(close(&s2, &s3, 1e-9), "{s2:?} against {s3:?}");

        let l = [[0.02, -0.3, 0.1], [0.25, -0.01, 0.05], [-0.08, 0.15, 0.03]];
        let f = embed(&crate::algebra::linalg::expm(l));
        let (ln_v, r) = log_stretch_and_rotation(&f);
        let rt: M3 = std::array::from_fn(|i| std::array::from_fn(|k| r[k][i]));
        let rrt = mul(r, rt);
        let v = Principal::of(&ln_v);
        let v = principal::tensor(&v.compose(&v.values.map(f64::exp)));
        let vr = mul(v, r);
        for i in 0..3 {
            for k in 0..3 {
                assert!((rrt[i][k] - if i == k { 1.0 } else { 0.0 }).abs() < 1e-14, "R Rᵀ {rrt:?}");
                assert!((vr[i][k] - f[i][k]).abs() < 1e-14, "V R {vr:?} against F {f:?}");
            }
        }
        let s = check(l, sigma0).theory(1.0);
        let eps: Stress = [ln_v[0], ln_v[1], 2.0 * ln_v[2], ln_v[3], 2.0 * ln_v[4], 2.0 * ln_v[5]];
        let turned = principal::rotate(&r, &sigma0);
        let expected: Stress = std::array::from_fn(|c| turned[c] + (0..NS).map(|j| el.d[c][j] * eps[j]).sum::<f64>());
        assert!(close(&s, &expected, 1e-9), "{s:?} against {expected:?}");
    }
}
