//! The vertical cut of [001] §3.2 and §7.2 (`../shared/seeds-001-002.md` Part B3, Part E items
//! 10–12). There is no closed form; what the run can say about itself:
//!
//! * the toe's horizontal displacement (the material point nearest `toe` at t = 0), which ends the
//!   run at `stop_displacement` ([001] shows the fields up to 1.0 m);
//! * the constitutive check of item 12: q ≤ √3 c(ε̄) at every point of the body and every step
//!   (q = √(3J₂) of the effective stress, c(ε̄) the softened strength of the von Mises model), as
//!   the excess max(q/√3c − 1, 0) with a tolerance of 1e-8, and the largest ε̄ (the residual
//!   strength is reached at ε̄ = (c_p − c_r)/|H_s|);
//! * the smoothness of item 11 when the toe passes each of `snapshots`: the roughness of the nodal
//!   diagnostics K_mag and F^int_mag ([001] Eqs. 25–26), rms of the discrete Laplacian
//!   K_{i+1,j} + K_{i−1,j} + K_{i,j+1} + K_{i,j−1} − 4K_{i,j} over the mean, over the nodes that
//!   are well filled with their four neighbours (the inside of the material);
//! * the total variation Σ|Δσ_m| over the run of the mean stress at the points nearest `b` (in
//!   the shear band) and `c` (in the sliding block), [001]'s p–q paths of Figs. 30–31 in one number.

use super::{Check, Findings, Metric};
use crate::assembly::{NodeBlock, NODE_VALUES};
use crate::case::{Case, SoilModel, Verification};
use crate::model::Model;
use crate::parallel::Collective;

/// The vertical-cut check of a case.
pub struct VerticalCutCheck {
    body: u16,
    points: [[f64; 2]; 3],
    stop_at: f64,
    snapshots: Vec<f64>,
    /// (c_p, c_r, H_s) of the soil.
    strength: (f64, f64, f64),
    /// The toe's displacement after the last step.
    toe: f64,
    /// Largest q/√3c(ε̄) and ε̄ seen.
    yield_ratio: f64,
    eps_max: f64,
    /// σ_m at B and C after the last step and their total variations.
    mean_stress: Option<[f64; 2]>,
    variation: [f64; 2],
    /// (snapshot, K_mag roughness, F^int_mag roughness, nodes) taken.
    taken: Vec<[f64; 4]>,
}

impl VerticalCutCheck {
    /// The check of a `vertical_cut` verification.
    pub fn new(c: &Case) -> Result<VerticalCutCheck, String> {
        let Some(Verification::VerticalCut { body, toe, b, c: cpoint, stop_displacement, snapshots }) = &c.verification
        else {
            return Err("not a vertical-cut verification".into());
        };
        let bi = c.body_index(body).ok_or(format!("no body `{body}`"))?;
        let mat = &c.materials[c.material_index(&c.bodies[bi].material).expect("validated")];
        let SoilModel::VonMises { cohesion, residual_cohesion, softening_modulus, .. } = mat.model else {
            return Err(format!("body `{body}` is not von Mises"));
        };
        let mut snapshots = snapshots.clone();
        snapshots.sort_by(f64::total_cmp);
        Ok(VerticalCutCheck {
            body: bi as u16,
            points: [*toe, *b, *cpoint],
            stop_at: *stop_displacement,
            snapshots,
            strength: (cohesion, residual_cohesion.unwrap_or(cohesion), softening_modulus),
            toe: 0.0,
            yield_ratio: 0.0,
            eps_max: 0.0,
            mean_stress: None,
            variation: [0.0; 2],
            taken: Vec::new(),
        })
    }

    /// The value `f(k)` of the body's point nearest `point` at t = 0 (collective).
    fn nearest(
        &self,
        model: &Model,
        coll: &Collective,
        point: [f64; 2],
        f: impl Fn(usize) -> f64,
    ) -> Result<f64, String> {
        let ps = &model.particles;
        let dist = |k: usize| (ps.x0[k][0] - point[0]).hypot(ps.x0[k][1] - point[1]);
        let mine: Vec<usize> = (0..ps.len()).filter(|&k| ps.body[k] == self.body).collect();
        let best = -coll.max(&[mine.iter().map(|&k| -dist(k)).fold(f64::NEG_INFINITY, f64::max)])?[0];
        let (mut sum, mut n) = (0.0, 0.0);
        for &k in mine.iter().filter(|&&k| dist(k) == best) {
            sum += f(k);
            n += 1.0;
        }
        let s = coll.sum(&[sum, n])?;
        Ok(s[0] / s[1].max(1.0))
    }

    /// The roughness of nodal value `v` (index into a node's values) over the inside nodes of
    /// `all` (every node's values, x fastest, `nx` per row): rms of the discrete Laplacian over
    /// the mean, and the number of nodes.
    fn roughness(all: &[f64], nx: usize, v: usize) -> (f64, f64) {
        let ny = all.len() / NODE_VALUES / nx;
        let at = |i: usize, j: usize, c: usize| all[(j * nx + i) * NODE_VALUES + c];
        let (mut sq, mut sum, mut n) = (0.0, 0.0, 0.0);
        for j in 1..ny.saturating_sub(1) {
            for i in 1..nx.saturating_sub(1) {
                let inside =
                    [(i, j), (i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1)].iter().all(|&(a, b)| at(a, b, 0) > 0.5);
                if !inside {
                    continue;
                }
                let lap = at(i + 1, j, v) + at(i - 1, j, v) + at(i, j + 1, v) + at(i, j - 1, v) - 4.0 * at(i, j, v);
                sq += lap * lap;
                sum += at(i, j, v);
                n += 1.0;
            }
        }
        if n == 0.0 || sum == 0.0 {
            return (0.0, n);
        }
        ((sq / n).sqrt() / (sum / n), n)
    }
}

/// σ_m and q = √(3J₂) of a stress [xx, yy, xy, zz].
fn invariants(s: &[f64; 4]) -> (f64, f64) {
    let m = (s[0] + s[1] + s[3]) / 3.0;
    let d = [s[0] - m, s[1] - m, s[3] - m];
    (m, (1.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 2.0 * s[2] * s[2])).sqrt())
}

impl Check for VerticalCutCheck {
    fn columns(&self) -> Vec<String> {
        vec!["cut.toe_displacement".into(), "cut.yield_ratio".into()]
    }

    fn event_times(&self) -> Vec<f64> {
        Vec::new()
    }

    fn observe(&mut self, _t: f64, _dt: f64, model: &Model, coll: &Collective) -> Result<Vec<f64>, String> {
        let ps = &model.particles;
        self.toe = self.nearest(model, coll, self.points[0], |k| ps.disp[k][0])?;
        let (cp, cr, hs) = self.strength;
        let (mut ratio, mut eps) = (0.0f64, 0.0f64);
        for k in (0..ps.len()).filter(|&k| ps.body[k] == self.body) {
            let c = (cp + hs * ps.eps_pd[k]).max(cr);
            ratio = ratio.max(invariants(&ps.stress[k]).1 / (3f64.sqrt() * c));
            eps = eps.max(ps.eps_pd[k]);
        }
        let worst = coll.max(&[ratio, eps])?;
        let step_ratio = worst[0];
        self.yield_ratio = self.yield_ratio.max(step_ratio);
        self.eps_max = self.eps_max.max(worst[1]);
        let now = [
            self.nearest(model, coll, self.points[1], |k| invariants(&ps.stress[k]).0)?,
            self.nearest(model, coll, self.points[2], |k| invariants(&ps.stress[k]).0)?,
        ];
        if let Some(before) = self.mean_stress {
            for c in 0..2 {
                self.variation[c] += (now[c] - before[c]).abs();
            }
        }
        self.mean_stress = Some(now);
        Ok(vec![self.toe, step_ratio])
    }

    fn needs_nodes(&self) -> bool {
        !self.snapshots.is_empty()
    }

    fn observe_nodes(&mut self, block: &NodeBlock, model: &Model, coll: &Collective) -> Result<(), String> {
        // The nodal stiffness and force of a step are those of the points at its start, i.e. of the
        // state the last observation saw.
        let Some(&next) = self.snapshots.iter().find(|&&s| s <= self.toe && !self.taken.iter().any(|t| t[0] == s))
        else {
            return Ok(());
        };
        let [nx, ny] = model.grid.nodes();
        let mut all = vec![0.0; nx * ny * NODE_VALUES];
        for (o, v) in block.values.chunks_exact(NODE_VALUES).enumerate() {
            let (i, j) = (block.start[0] + o % block.count[0], block.start[1] + o / block.count[0]);
            all[(j * nx + i) * NODE_VALUES..(j * nx + i + 1) * NODE_VALUES].copy_from_slice(v);
        }
        let all = coll.sum(&all)?;
        let (k, n) = Self::roughness(&all, nx, 6);
        let (f, _) = Self::roughness(&all, nx, 7);
        self.taken.push([next, k, f, n]);
        Ok(())
    }

    /// Once the toe has moved `stop_displacement` and every snapshot it passed has been taken (the
    /// nodal fields of a state are measured at the next step's start, so the run takes one step
    /// more when the last snapshot coincides with the stop).
    fn stop(&self) -> Option<String> {
        let pending = self.snapshots.iter().any(|&s| s <= self.toe && !self.taken.iter().any(|t| t[0] == s));
        (self.toe >= self.stop_at && !pending).then(|| format!("the toe moved {:.4} m ≥ {} m", self.toe, self.stop_at))
    }

    fn finish(&mut self, _model: &Model, _coll: &Collective) -> Result<Findings, String> {
        let excess = (self.yield_ratio - 1.0).max(0.0);
        Ok((
            vec![(
                "yield_excess".into(),
                Metric::error(
                    excess,
                    1e-8,
                    format!("largest q/√3c(ε̄) − 1 over every point and step: q/√3c = {:.12}", self.yield_ratio),
                ),
            )],
            Vec::new(),
        ))
    }

    fn results(&self) -> Vec<(String, f64)> {
        let mut out = vec![
            ("toe_displacement".into(), self.toe),
            ("eps_pd_max".into(), self.eps_max),
            ("sigma_m_variation_B".into(), self.variation[0]),
            ("sigma_m_variation_C".into(), self.variation[1]),
        ];
        for t in &self.taken {
            out.push((format!("k_mag_roughness_at_{}", t[0]), t[1]));
            out.push((format!("fint_mag_roughness_at_{}", t[0]), t[2]));
        }
        out
    }

    fn checkpoint_state(&self, _model: &Model, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        // Restarting mid-run would lose the variations' history: the check says it cannot keep it.
        Ok(None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The roughness of a linear field is zero and a chequerboard's is large; border nodes and
    /// nodes next to empty ones are left out.
    #[test]
    fn roughness_sees_a_chequerboard_and_not_a_ramp() {
        let (nx, ny) = (6, 5);
        let field = |f: &dyn Fn(usize, usize) -> f64| -> Vec<f64> {
            let mut all = vec![0.0; nx * ny * NODE_VALUES];
            for j in 0..ny {
                for i in 0..nx {
                    let v = &mut all[(j * nx + i) * NODE_VALUES..(j * nx + i + 1) * NODE_VALUES];
                    v[0] = 1.0;
                    v[6] = f(i, j);
                }
            }
            all
        };
        let (r, n) = VerticalCutCheck::roughness(&field(&|i, j| 10.0 + i as f64 + 2.0 * j as f64), nx, 6);
        assert!(r.abs() < 1e-14 && n == 12.0, "{r} over {n}");
        let (r, _) =
            VerticalCutCheck::roughness(&field(&|i, j| 10.0 + if (i + j) % 2 == 0 { 1.0 } else { -1.0 }), nx, 6);
        assert!((r - 0.8).abs() < 1e-12, "{r}");
        let (s, q) = invariants(&[-3.0, -1.0, 0.5, -2.0]);
        assert!((s + 2.0).abs() < 1e-14 && (q - (1.5f64 * (1.0 + 1.0 + 0.0 + 0.5)).sqrt()).abs() < 1e-14);
    }
}
