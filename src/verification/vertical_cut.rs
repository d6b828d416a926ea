//! The vertical cut of [001] §3.2 and §7.2. There is no closed form; what the run can say about
//! itself:
//!
//! * the toe's horizontal displacement (the material point nearest `toe` at t = 0), which ends the
//!   run at `stop_displacement` ([001] shows the fields up to 1.0 m);
//! * the constitutive check: q ≤ √3 c(ε̄) at every point of the body and every step
//!   (q = √(3J₂) of the effective stress, c(ε̄) the softened strength of the von Mises model), as
//!   the excess max(q/√3c − 1, 0) with a tolerance of 1e-8, and the largest ε̄ (the residual
//!   strength is reached at ε̄ = (c_p − c_r)/|H_s|);
//! * the smoothness of the fields when the toe passes each of `snapshots`: the roughness of the
//!   nodal diagnostics K_mag and F^int_mag ([001] Eqs. 25–26), rms of the discrete Laplacian
//!   K_{i+1,j} + K_{i−1,j} + K_{i,j+1} + K_{i,j−1} − 4K_{i,j} over the mean, over the nodes whose
//!   stencil has whole supports in the material ([`INSIDE_DEPTH`]), the chequerboard index of σ_m
//!   over the body's points (`checkerboard::fit_of`), and the maps of σ_m and K_mag (`figures`;
//!   every rank gathers the body's points at a snapshot);
//! * the total variation Σ|Δσ_m| over the run of the mean stress at the points nearest `b` (in
//!   the shear band) and `c` (in the sliding block), [001]'s p–q paths of Figs. 30–31 in one number.

use super::{each_positive, BuiltCheck, Check, CheckParameters, Findings, Metric};
use crate::assembly::{NodeBlock, NODE_VALUES};
use crate::case::{BodyId, Case, SoilModel};
use crate::check::{at, finite2, positive, Checked};
use crate::model::Model;
use crate::parallel::Collective;
use crate::plot::MapPoints;
use crate::soils::invariants;
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "vertical_cut"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VerticalCut {
    /// The name of the soil (von Mises).
    pub body: String,
    /// The toe's point at t = 0 (the nearest material point is followed) [m].
    pub toe: [f64; 2],
    /// The point B (in the shear band) at t = 0 [m].
    pub b: [f64; 2],
    /// The point C (in the sliding block) at t = 0 [m].
    pub c: [f64; 2],
    /// The toe's horizontal displacement that ends the run [m], > 0.
    pub stop_displacement: f64,
    /// Toe displacements at which the nodal fields' smoothness is measured [m], each > 0.
    #[serde(default)]
    pub snapshots: Vec<f64>,
}

impl CheckParameters for VerticalCut {
    type Ids = BodyId;

    fn check(&self, key: &str) -> Checked {
        for (f, v) in [("toe", self.toe), ("b", self.b), ("c", self.c)] {
            finite2(&at(key, f), v)?;
        }
        positive(&at(key, "stop_displacement"), self.stop_displacement)?;
        each_positive(&at(key, "snapshots"), &self.snapshots)
    }

    fn describe(&self) -> String {
        format!(
            "vertical cut ([001] §7.2) to a toe displacement of {} m: yield check, smoothness of K_mag and \
             F^int_mag",
            self.stop_displacement
        )
    }

    /// A von Mises body.
    fn link(&self, c: &Case) -> Result<BodyId, String> {
        let body = c.body_named("verification.body", &self.body)?;
        if !matches!(c.material_of(body).model, SoilModel::VonMises(_)) {
            return Err(format!(
                "key `verification.body`: the vertical cut's checks need a von_mises body, and `{}` is not",
                c.body(body).name
            ));
        }
        Ok(body)
    }

    fn plane(&self, c: &Case, body: &BodyId, _model: &Model, _coll: &Collective) -> BuiltCheck {
        Ok(Box::new(VerticalCutCheck::new(c, self, *body)?))
    }
}

/// How far inside the material (in cells from the outermost well-filled nodes) a node of the
/// roughness must be: 3, so that every node of its Laplacian's stencil has its whole support (a
/// cell and a GIMP domain on each side) in the material. The nodes nearer the edge have a stiffness
/// and a force of their partly empty supports, a boundary layer that is not roughness (with depth
/// 1 it dominated the measure: DM-GC's uniform inside scored 0.156 against MPM's 0.198).
const INSIDE_DEPTH: usize = 3;

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
    /// The maps of each snapshot taken: σ_m at the body's points and K_mag at the nodes inside the
    /// material, (x, y, value).
    maps: Vec<(f64, MapPoints, MapPoints)>,
    /// Half the size of a point's rectangle and of a node's in the maps [m].
    map_sizes: [(f64, f64); 2],
    /// The chequerboard index of σ_m at each snapshot taken.
    sigma_m_checkerboard: Vec<(f64, f64)>,
}

impl VerticalCutCheck {
    /// The check of a `vertical_cut` verification `spec` of `body`.
    pub fn new(c: &Case, spec: &VerticalCut, body: BodyId) -> Result<VerticalCutCheck, String> {
        let SoilModel::VonMises(m) = &c.material_of(body).model else {
            return Err(format!("body `{}` is not von Mises", spec.body));
        };
        let mut snapshots = spec.snapshots.clone();
        snapshots.sort_by(f64::total_cmp);
        Ok(VerticalCutCheck {
            body: body.index() as u16,
            points: [spec.toe, spec.b, spec.c],
            stop_at: spec.stop_displacement,
            snapshots,
            strength: (m.cohesion, m.residual_cohesion.unwrap_or(m.cohesion), m.softening_modulus),
            toe: 0.0,
            yield_ratio: 0.0,
            eps_max: 0.0,
            mean_stress: None,
            variation: [0.0; 2],
            taken: Vec::new(),
            maps: Vec::new(),
            map_sizes: [(0.0, 0.0); 2],
            sigma_m_checkerboard: Vec::new(),
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
    /// the mean, and the number of nodes. A node is inside when every node within `depth` cells of
    /// it (a square of side 2 depth + 1) is well filled: depth 1 takes the nodes next to the
    /// material's edge, whose supports are partly empty; depth 3 keeps the Laplacian's stencil
    /// two cells from the edge.
    fn roughness(all: &[f64], nx: usize, v: usize, depth: usize) -> (f64, f64) {
        let ny = all.len() / NODE_VALUES / nx;
        let at = |i: usize, j: usize, c: usize| all[(j * nx + i) * NODE_VALUES + c];
        let (mut sq, mut sum, mut n) = (0.0, 0.0, 0.0);
        for j in depth..ny.saturating_sub(depth) {
            for i in depth..nx.saturating_sub(depth) {
                let inside = (j - depth..=j + depth).all(|b| (i - depth..=i + depth).all(|a| at(a, b, 0) > 0.5));
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

impl Check for VerticalCutCheck {
    fn columns(&self) -> Vec<String> {
        vec!["cut.toe_displacement".into(), "cut.yield_ratio".into()]
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
        let (k, n) = Self::roughness(&all, nx, 6, INSIDE_DEPTH);
        let (f, _) = Self::roughness(&all, nx, 7, INSIDE_DEPTH);
        self.taken.push([next, k, f, n]);
        // The maps of [001] Figs. 27–29: σ_m over the body and K_mag at the nodes inside it.
        let g = &model.grid;
        let nodes: MapPoints = (0..nx * ny)
            .filter(|&a| all[a * NODE_VALUES] > 0.5)
            .map(|a| {
                let p = g.node_position(a % nx, a / nx);
                (p[0], p[1], all[a * NODE_VALUES + 6] / 1e3)
            })
            .collect();
        let ps = &model.particles;
        let mine: Vec<f64> = (0..ps.len())
            .filter(|&k| ps.body[k] == self.body)
            .flat_map(|k| [ps.x[k][0], ps.x[k][1], invariants(&ps.stress[k]).0 / 1e3])
            .collect();
        let points: MapPoints = coll.gather(&mine)?.chunks_exact(3).map(|c| (c[0], c[1], c[2])).collect();
        // Item 11's chequerboard index of σ_m (the pore pressures' index, `checkerboard::fit_of`,
        // applied to σ_m over the body's points; every rank fits the same gathered points).
        let fitted: Vec<[f64; 4]> = points.iter().map(|p| [p.0, p.1, p.2, 0.0]).collect();
        let index = super::checkerboard::fit_of(&fitted, g.origin, g.h).index;
        self.sigma_m_checkerboard.push((next, index));
        // A point's rectangle: its initial domain, a fifth larger, so that sheared material shows
        // no gaps between its points.
        let lp = (0..ps.len()).find(|&k| ps.body[k] == self.body).map(|k| ps.lp0[k]);
        let lp = coll.max(&lp.map_or([0.0; 2], |l| l))?;
        self.map_sizes = [(1.2 * lp[0], 1.2 * lp[1]), (0.5 * g.h[0], 0.5 * g.h[1])];
        self.maps.push((next, points, nodes));
        Ok(())
    }

    fn figures(&self) -> Vec<crate::plot::Figure> {
        use crate::plot::{ColourMap, Figure};
        let mut out = Vec::new();
        for (snap, points, nodes) in &self.maps {
            let maps = [
                ("sigma_m", "Mean stress σ_m", points, self.map_sizes[0], "σ_m [kPa]"),
                ("k_mag", "K_mag ([001] Eq. 25)", nodes, self.map_sizes[1], "K_mag [kN/m]"),
            ];
            for (file, what, values, half_size, label) in maps {
                out.push(Figure::map(
                    format!("{file}_toe_{snap}m.png"),
                    format!("{what}, toe moved {snap} m (colours: 1–99 % of the values)"),
                    ColourMap {
                        points: values.clone(),
                        half_size,
                        label: label.into(),
                        range: ColourMap::quantiles(values, 0.01, 0.99),
                    },
                ));
            }
        }
        out
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
        for (snap, index) in &self.sigma_m_checkerboard {
            out.push((format!("sigma_m_checkerboard_at_{snap}"), *index));
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
        let (r, n) = VerticalCutCheck::roughness(&field(&|i, j| 10.0 + i as f64 + 2.0 * j as f64), nx, 6, 1);
        assert!(r.abs() < 1e-14 && n == 12.0, "{r} over {n}");
        let (r, _) =
            VerticalCutCheck::roughness(&field(&|i, j| 10.0 + if (i + j) % 2 == 0 { 1.0 } else { -1.0 }), nx, 6, 1);
        assert!((r - 0.8).abs() < 1e-12, "{r}");
        // A uniform inside with a soft edge ring two nodes deep (partly empty supports): depth 1
        // sees the ring, depth 3 does not; a chequerboard deep inside is seen at depth 3.
        let (nx, ny) = (12, 11);
        let ring = |cheq: bool| {
            let mut all = vec![0.0; nx * ny * NODE_VALUES];
            for j in 0..ny {
                for i in 0..nx {
                    let v = &mut all[(j * nx + i) * NODE_VALUES..(j * nx + i + 1) * NODE_VALUES];
                    let edge = i.min(j).min(nx - 1 - i).min(ny - 1 - j);
                    v[0] = 1.0;
                    v[6] = if edge < 2 { 5.0 } else { 10.0 + if cheq && (i + j) % 2 == 0 { 1.0 } else { 0.0 } };
                }
            }
            all
        };
        assert!(VerticalCutCheck::roughness(&ring(false), nx, 6, 1).0 > 0.1);
        let (r, n) = VerticalCutCheck::roughness(&ring(false), nx, 6, INSIDE_DEPTH);
        assert!(r == 0.0 && n == 30.0, "{r} over {n}");
        assert!(VerticalCutCheck::roughness(&ring(true), nx, 6, INSIDE_DEPTH).0 > 0.2);
        let (s, q) = invariants(&[-3.0, -1.0, 0.5, -2.0, 0.0, 0.0]);
        assert!((s + 2.0).abs() < 1e-14 && (q - (1.5f64 * (1.0 + 1.0 + 0.0 + 0.5)).sqrt()).abs() < 1e-14);
    }
}
