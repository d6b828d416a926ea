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

use super::{Check, Findings, Metric};
use crate::case::{Case, SoilModel, Verification};
use crate::model::loads::{exp2, Motion};
use crate::model::soil::{self, LinearElastic, Stress, NS};
use crate::model::Model;
use crate::parallel::Collective;

/// The patch check of a case.
pub struct PatchCheck {
    body: u16,
    motion: Motion,
    elastic: LinearElastic,
    /// A neo-Hookean body's model (its σ* is the model's stress of F).
    hyperelastic: Option<crate::model::finite_strain::NeoHookean>,
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

/// Eigen-decomposition of a symmetric 2 × 2 matrix: (values, unit eigenvector of the first).
fn eig_sym(a: [[f64; 2]; 2]) -> ([f64; 2], [f64; 2]) {
    let m = 0.5 * (a[0][0] + a[1][1]);
    let r = (0.25 * (a[0][0] - a[1][1]).powi(2) + a[0][1] * a[0][1]).sqrt();
    let theta = 0.5 * (2.0 * a[0][1]).atan2(a[0][0] - a[1][1]);
    ([m + r, m - r], [theta.cos(), theta.sin()])
}

impl PatchCheck {
    /// The check of a `patch` verification.
    pub fn new(c: &Case, model: &Model) -> Result<PatchCheck, String> {
        let Some(Verification::Patch { body, boundary, spread_tolerance, tolerance }) = &c.verification else {
            return Err("not a patch verification".into());
        };
        let bi = c.body_index(body).ok_or(format!("no body `{body}`"))?;
        let b = &c.bodies[bi];
        let mat = &c.materials[c.material_index(&b.material).expect("validated")];
        let (elastic, hyperelastic) = match mat.model {
            SoilModel::LinearElastic { young_modulus, poisson_ratio } => {
                (LinearElastic::new(young_modulus, poisson_ratio), None)
            }
            SoilModel::NeoHookean { young_modulus, poisson_ratio } => (
                LinearElastic::new(young_modulus, poisson_ratio),
                Some(crate::model::finite_strain::NeoHookean::new(young_modulus, poisson_ratio)),
            ),
            _ => return Err(format!("body `{body}` is not elastic (linear or neo-Hookean)")),
        };
        let motion = model
            .boundaries
            .iter()
            .find(|x| &x.name == boundary)
            .and_then(|x| x.motion.clone())
            .ok_or(format!("boundary `{boundary}` has no motion"))?;
        Ok(PatchCheck {
            body: bi as u16,
            motion,
            elastic,
            hyperelastic,
            initial: soil::plane(b.uniform_stress.unwrap_or([0.0; 4])),
            spread_tolerance: *spread_tolerance,
            tolerance: *tolerance,
            last: (f64::NAN, f64::NAN, 0.0),
        })
    }

    /// σ* at time `t` (see the module documentation).
    pub fn theory(&self, t: f64) -> Stress {
        let Some((l, _)) = &self.motion.gradient else { return self.initial };
        let s = self.motion.flow_parameter(t);
        let f = exp2([[l[0][0] * s, l[0][1] * s], [l[1][0] * s, l[1][1] * s]]);
        if let Some(h) = &self.hyperelastic {
            return h.stress(crate::model::finite_strain::plane(f)).unwrap_or([f64::NAN; NS]);
        }
        // F Fᵀ = V², ln V from its eigen-decomposition; R = V⁻¹ F.
        let b = [
            [f[0][0] * f[0][0] + f[0][1] * f[0][1], f[0][0] * f[1][0] + f[0][1] * f[1][1]],
            [f[1][0] * f[0][0] + f[1][1] * f[0][1], f[1][0] * f[1][0] + f[1][1] * f[1][1]],
        ];
        let (lam, e) = eig_sym(b);
        let (l1, l2) = (0.5 * lam[0].ln(), 0.5 * lam[1].ln());
        let (v1, v2) = (lam[0].sqrt(), lam[1].sqrt());
        let p = [[e[0] * e[0], e[0] * e[1]], [e[0] * e[1], e[1] * e[1]]];
        let q = [[1.0 - p[0][0], -p[0][1]], [-p[1][0], 1.0 - p[1][1]]];
        let ln_v = [[l1 * p[0][0] + l2 * q[0][0], l1 * p[0][1] + l2 * q[0][1]], [0.0, l1 * p[1][1] + l2 * q[1][1]]];
        let v_inv = [
            [p[0][0] / v1 + q[0][0] / v2, p[0][1] / v1 + q[0][1] / v2],
            [p[1][0] / v1 + q[1][0] / v2, p[1][1] / v1 + q[1][1] / v2],
        ];
        let r = [
            [v_inv[0][0] * f[0][0] + v_inv[0][1] * f[1][0], v_inv[0][0] * f[0][1] + v_inv[0][1] * f[1][1]],
            [v_inv[1][0] * f[0][0] + v_inv[1][1] * f[1][0], v_inv[1][0] * f[0][1] + v_inv[1][1] * f[1][1]],
        ];
        let theta = r[1][0].atan2(r[0][0]);
        let mut s = crate::kernels::kinematics::rotate(&self.initial, theta);
        let eps = soil::plane([ln_v[0][0], ln_v[1][1], 2.0 * ln_v[0][1], 0.0]);
        for (i, si) in s.iter_mut().enumerate() {
            *si += (0..NS).map(|j| self.elastic.d[i][j] * eps[j]).sum::<f64>();
        }
        s
    }

    fn measure(&self, model: &Model, coll: &Collective) -> Result<(f64, Stress), String> {
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

impl Check for PatchCheck {
    fn columns(&self) -> Vec<String> {
        vec!["patch.stress_spread".into(), "patch.stress_rel_error".into()]
    }

    fn event_times(&self) -> Vec<f64> {
        Vec::new()
    }

    fn observe(&mut self, t: f64, _dt: f64, model: &Model, coll: &Collective) -> Result<Vec<f64>, String> {
        let (spread, mean) = self.measure(model, coll)?;
        let theory = self.theory(t);
        let d: Stress = std::array::from_fn(|c| mean[c] - theory[c]);
        let error = if norm(&theory) > 0.0 { norm(&d) / norm(&theory) } else { norm(&d) };
        self.last = (spread, error, t);
        Ok(vec![spread, error])
    }

    fn finish(&mut self, _model: &Model, _coll: &Collective) -> Result<Findings, String> {
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
                            "‖σ̄ − σ*‖/‖σ*‖ at t = {t:.6e} s, σ* = [{:.6e}, {:.6e}, {:.6e}, {:.6e}] Pa",
                            theory[0], theory[1], theory[2], theory[3]
                        ),
                    ),
                ),
            ],
            Vec::new(),
        ))
    }

    fn checkpoint_state(&self, _model: &Model, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        Ok(Some(vec![self.last.0, self.last.1, self.last.2]))
    }

    fn restore_state(&mut self, state: &[f64], _model: &Model) -> Result<(), String> {
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

    fn check(l: [[f64; 2]; 2], initial: [f64; 4]) -> PatchCheck {
        PatchCheck {
            body: 0,
            motion: Motion {
                is_displacement: false,
                vector: [0.0; 2],
                gradient: Some((l, [0.0; 2])),
                time_fn: TimeFn::Constant(1.0),
            },
            elastic: LinearElastic::new(1e6, 0.3),
            hyperelastic: None,
            initial: soil::plane(initial),
            spread_tolerance: 1e-9,
            tolerance: 1e-6,
            last: (0.0, 0.0, 0.0),
        }
    }

    #[test]
    fn the_reference_of_a_rotation_and_of_a_stretch() {
        // A quarter turn turns the stress.
        let w = std::f64::consts::FRAC_PI_2;
        let s = check([[0.0, -w], [w, 0.0]], [3.0, 1.0, 0.5, 2.0]).theory(1.0);
        assert!((s[0] - 1.0).abs() < 1e-12 && (s[1] - 3.0).abs() < 1e-12 && (s[2] + 0.5).abs() < 1e-12);
        // A stretch along x: ε_xx = ln λ, plane strain.
        let s = check([[1e-3, 0.0], [0.0, 0.0]], [0.0; 4]).theory(1.0);
        let el = LinearElastic::new(1e6, 0.3);
        assert!((s[0] - el.d[0][0] * 1e-3).abs() < 1e-9 && (s[1] - el.d[1][0] * 1e-3).abs() < 1e-9);
    }
}
