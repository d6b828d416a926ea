//! [001] §6's stiffness test (docs/stiffness.md): the nodal diagnostic
//! K_mag = √(K_x² + K_y²) ([001] Eq. 25; `K_x`, `K_y` the diagonal entries of the assembled
//! material stiffness, field `K_mag`) of a block of material points, against the value of an
//! interior node of a uniform finite-element mesh of square Q4 cells with 2 × 2 Gauss points,
//! K_FEM = (4/3)(D₁₁ + G)√2 (plane strain, D₁₁ = E(1 − ν)/((1 + ν)(1 − 2ν)), G = E/(2(1 + ν));
//! independent of the cell size). Metrics after the last step over the grid nodes within
//! `radius` of `center`: the largest and the RMS relative deviation |K_mag/K_FEM − 1| (each node
//! counted once, so that neither shrinks with more points); `results` has the smallest and largest
//! ratio and the number of nodes.

use super::{all_positive, linear_elastic, BuiltCheck, Check, CheckParameters, Findings, Metric};
use crate::assembly::{NodeBlock, NODE_VALUES};
use crate::case::{BodyId, Case, Geometry};
use crate::check::{at, finite2, Checked};
use crate::model::Model;
use crate::parallel::Collective;
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "stiffness_map"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct StiffnessMap {
    /// The name of the block (linear elastic, on square cells, in plane strain).
    pub body: String,
    /// The centre of the evaluated nodes [m].
    pub center: [f64; 2],
    /// The radius within which nodes are evaluated [m], > 0.
    pub radius: f64,
    /// Largest accepted relative deviation of K_mag at any of those nodes [-], in (0, 1] (default 0.01).
    #[serde(default = "default_stiffness_map_tol")]
    pub tolerance: f64,
}

serde_defaults! { default_stiffness_map_tol: f64 = 0.01 }

impl CheckParameters for StiffnessMap {
    type Ids = BodyId;

    fn check(&self, key: &str) -> Checked {
        finite2(&at(key, "center"), self.center)?;
        all_positive(key, &[("radius", self.radius), ("tolerance", self.tolerance)])
    }

    fn describe(&self) -> String {
        format!(
            "nodal stiffness K_mag ([001] Eq. 25) within {} m of ({}, {}) against the finite-element value",
            self.radius, self.center[0], self.center[1]
        )
    }

    /// A linear elastic block on square cells in plane strain.
    fn link(&self, c: &Case) -> Result<BodyId, String> {
        let body = c.body_named("verification.body", &self.body)?;
        linear_elastic(c, body, "the stiffness map's reference")?;
        let h = c.cell_size();
        if (h[0] - h[1]).abs() > 1e-9 * h[0] {
            return Err(format!(
                "key `grid`: the stiffness map's reference is for square cells, got {} × {} m",
                h[0], h[1]
            ));
        }
        if c.analysis.geometry != Geometry::PlaneStrain {
            return Err("key `verification`: the stiffness map's reference is for plane strain".into());
        }
        Ok(body)
    }

    fn plane(&self, c: &Case, body: &BodyId, _model: &Model, _coll: &Collective) -> BuiltCheck {
        Ok(Box::new(StiffnessMapCheck::new(c, self, *body)?))
    }
}

/// The stiffness-map check of a case.
pub struct StiffnessMapCheck {
    center: [f64; 2],
    radius: f64,
    reference: f64,
    tolerance: f64,
    /// [max |dev|, Σ dev², count, min ratio, max ratio] of the last step.
    last: Option<[f64; 5]>,
    /// K_mag / K_FE at this rank's nodes inside the material (filled more than half) after the
    /// last step, (x, y, ratio) flat; gathered over the ranks by `finish` into `map`.
    local_map: Vec<f64>,
    /// The map of [001] Fig. 20 over all ranks, and half a cell [m].
    map: (crate::plot::MapPoints, (f64, f64)),
}

impl StiffnessMapCheck {
    /// The check of a `stiffness_map` verification `spec` of `body`.
    pub fn new(c: &Case, spec: &StiffnessMap, body: BodyId) -> Result<StiffnessMapCheck, String> {
        let (e, nu) = super::elastic_body(c, body)?;
        Ok(StiffnessMapCheck {
            center: spec.center,
            radius: spec.radius,
            reference: fem_k_mag(e, nu),
            tolerance: spec.tolerance,
            last: None,
            local_map: Vec::new(),
            map: (Vec::new(), (0.0, 0.0)),
        })
    }
}

/// K_mag of an interior node of a uniform plane-strain Q4 mesh of square cells (2 × 2 Gauss
/// points), per metre of thickness: (4/3)(D₁₁ + G)√2.
pub fn fem_k_mag(e: f64, nu: f64) -> f64 {
    let d11 = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    (4.0 / 3.0) * (d11 + e / (2.0 * (1.0 + nu))) * std::f64::consts::SQRT_2
}

impl Check for StiffnessMapCheck {
    fn columns(&self) -> Vec<String> {
        Vec::new()
    }

    fn observe(&mut self, _t: f64, _dt: f64, _model: &Model, _coll: &Collective) -> Result<Vec<f64>, String> {
        Ok(Vec::new())
    }

    fn needs_nodes(&self) -> bool {
        true
    }

    fn observe_nodes(&mut self, block: &NodeBlock, model: &Model, coll: &Collective) -> Result<(), String> {
        let mut local = [0.0, 0.0, 0.0];
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut map = Vec::new();
        for (o, v) in block.values.chunks_exact(NODE_VALUES).enumerate() {
            let (i, j) = (block.start[0] + o % block.count[0], block.start[1] + o / block.count[0]);
            let x = model.grid.node_position(i, j);
            if v[0] > 0.5 {
                map.extend([x[0], x[1], v[6] / self.reference]);
            }
            if (x[0] - self.center[0]).hypot(x[1] - self.center[1]) > self.radius {
                continue;
            }
            let ratio = v[6] / self.reference;
            local[0] = f64::max(local[0], (ratio - 1.0).abs());
            local[1] += (ratio - 1.0).powi(2);
            local[2] += 1.0;
            lo = lo.min(ratio);
            hi = hi.max(ratio);
        }
        let worst = coll.max(&[local[0], hi, -lo])?;
        let sums = coll.sum(&local[1..])?;
        self.last = Some([worst[0], sums[0], sums[1], -worst[2], worst[1]]);
        self.local_map = map;
        Ok(())
    }

    fn figures(&self) -> Vec<crate::plot::Figure> {
        use crate::plot::{ColourMap, Figure};
        vec![Figure::map(
            "k_mag_ratio.png",
            format!("K_mag / K_FE at the nodes inside the block, K_FE = {:.2} kN/m", self.reference / 1e3),
            ColourMap {
                points: self.map.0.clone(),
                half_size: self.map.1,
                label: "K_mag / K_FE".into(),
                range: Some((0.6, 1.1)),
            },
        )]
    }

    fn finish(&mut self, model: &Model, coll: &Collective) -> Result<Findings, String> {
        // The map of the last step, gathered once (every rank holds it; rank 0 draws it).
        let h = model.grid.h;
        let points = coll.gather(&self.local_map)?.chunks_exact(3).map(|c| (c[0], c[1], c[2])).collect();
        self.map = (points, (0.5 * h[0], 0.5 * h[1]));
        let Some([max, sq, n, _, _]) = self.last else {
            return Err("the stiffness map saw no step".into());
        };
        if n == 0.0 {
            return Err("the stiffness map found no grid node within its radius".into());
        }
        let detail = format!(
            "over {n} nodes within {} m of ({}, {}), against K_FEM = {:.6e} N/m",
            self.radius, self.center[0], self.center[1], self.reference
        );
        Ok((
            vec![
                ("k_mag_max_rel_deviation".into(), Metric::error(max, self.tolerance, detail.clone())),
                ("k_mag_rms_rel_deviation".into(), Metric::error((sq / n).sqrt(), self.tolerance, detail)),
            ],
            Vec::new(),
        ))
    }

    fn results(&self) -> Vec<(String, f64)> {
        let Some([_, _, n, lo, hi]) = self.last else { return Vec::new() };
        vec![("k_mag_min_ratio".into(), lo), ("k_mag_max_ratio".into(), hi), ("nodes".into(), n)]
    }

    fn checkpoint_state(&self, _model: &Model, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        Ok(Some(self.last.map(|l| l.to_vec()).unwrap_or_default()))
    }

    fn restore_state(&mut self, state: &[f64], _model: &Model) -> Result<(), String> {
        self.last = match state {
            [] => None,
            s => Some(s.try_into().map_err(|_| "the stiffness map's state has 5 values".to_string())?),
        };
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    /// [001] §6's value for E = 1000 kN/m², ν = 0.3.
    #[test]
    fn the_finite_element_reference_is_the_papers() {
        assert!((super::fem_k_mag(1000.0, 0.3) - 3263.57).abs() < 5e-3);
    }
}
