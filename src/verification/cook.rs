//! Cook's membrane of [002] §4.1: a tapered
//! plate clamped on its left edge and sheared on its right, run until it is at rest. What the run
//! says about itself:
//!
//! * the vertical displacement of the tip (the upper-right corner), against the case's
//!   `reference`. No material point sits on the corner (the nearest is a quarter cell inside it
//!   with 2 × 2 points per cell), and the membrane turns there, so the tip's displacement is the
//!   value at the corner of the linear least-squares fit u_y ≈ a + b (X − X_tip) + c (Y − Y_tip)
//!   over the points of the body whose initial positions X lie within `fit_radius` cells of it
//!   (the fit's normal equations are summed over the ranks). The nearest point's displacement is
//!   reported beside it (`results`);
//! * whether the membrane has come to rest: the change of the tip's displacement over the last
//!   tenth of the run, relative to the displacement (a metric with a tolerance of a tenth of the
//!   accuracy asked of the tip, so that a run stopped while still moving cannot pass);
//! * the chequerboard index of the mean stress σ_m over the body's points at the end
//!   (`checkerboard::fit_of`, every rank fitting the same gathered points), which `make study-cook`
//!   compares between F̄ and standard MPM, and the map of σ_m ([002] Figs. 3–5).

use super::{BuiltCheck, Check, CheckParameters, Findings, FormulationNeed, Metric};
use crate::case::{BodyId, Case, Formulation};
use crate::check::{at, finite2, positive, Checked};
use crate::model::Model;
use crate::parallel::Collective;
use crate::plot::MapPoints;
use crate::soils::invariants;
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "cook_membrane"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CookMembrane {
    /// The name of the membrane's body.
    pub body: String,
    /// The tip at t = 0 [m].
    pub tip: [f64; 2],
    /// The tip's vertical displacement at rest [m], > 0 (0.2765 for [002]'s membrane: plane-strain
    /// Q9 finite elements, `scripts/cook_membrane_neo_hookean.py`).
    pub reference: f64,
    /// Largest accepted relative error of the tip's displacement [-], in (0, 1) (default 0.03).
    #[serde(default = "default_cook_tol")]
    pub tolerance: f64,
    /// The radius around the tip within which the points' displacements are fitted [cells], in
    /// [1, 10] (default 2).
    #[serde(default = "default_cook_radius")]
    pub fit_radius: f64,
}

serde_defaults! { default_cook_tol: f64 = 0.03, default_cook_radius: f64 = 2.0 }

impl CheckParameters for CookMembrane {
    type Ids = BodyId;
    const FORMULATION: FormulationNeed = Some((Formulation::OnePhase, "Cook's membrane is for a one_phase analysis"));

    fn check(&self, key: &str) -> Checked {
        finite2(&at(key, "tip"), self.tip)?;
        positive(&at(key, "reference"), self.reference)?;
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(format!("key `{}`: must be in (0, 1), got {}", at(key, "tolerance"), self.tolerance));
        }
        if !(1.0..=10.0).contains(&self.fit_radius) {
            return Err(format!("key `{}`: must be in [1, 10] cells, got {}", at(key, "fit_radius"), self.fit_radius));
        }
        Ok(())
    }

    fn describe(&self) -> String {
        format!(
            "Cook's membrane ([002] §4.1): the tip ({}, {})'s vertical displacement at rest against {} m, the mean \
             stress's chequerboard index",
            self.tip[0], self.tip[1], self.reference
        )
    }

    fn link(&self, c: &Case) -> Result<BodyId, String> {
        c.body_named("verification.body", &self.body)
    }

    fn plane(&self, c: &Case, body: &BodyId, _model: &Model, _coll: &Collective) -> BuiltCheck {
        Ok(Box::new(CookCheck::new(c, self, *body)))
    }
}

/// The Cook's-membrane check of a case.
pub struct CookCheck {
    body: u16,
    tip: [f64; 2],
    reference: f64,
    tolerance: f64,
    fit_radius: f64,
    end: f64,
    /// (t, fitted tip u_y, nearest point's u_y) after every step.
    history: Vec<[f64; 3]>,
    /// σ_m at the points at the end, gathered, and a point's half size [m].
    map: (MapPoints, (f64, f64)),
    checkerboard: f64,
    points: usize,
}

impl CookCheck {
    /// The check of a `cook_membrane` verification `spec` of `body`.
    pub fn new(c: &Case, spec: &CookMembrane, body: BodyId) -> CookCheck {
        CookCheck {
            body: body.index() as u16,
            tip: spec.tip,
            reference: spec.reference,
            tolerance: spec.tolerance,
            fit_radius: spec.fit_radius,
            end: c.end_time(),
            history: Vec::new(),
            map: (Vec::new(), (0.0, 0.0)),
            checkerboard: f64::NAN,
            points: 0,
        }
    }

    /// The fitted vertical displacement of the tip and the nearest point's (collective).
    fn tip_displacement(&self, model: &Model, coll: &Collective) -> Result<(f64, f64), String> {
        let ps = &model.particles;
        let radius = self.fit_radius * model.grid.h[0].max(model.grid.h[1]);
        let mine = (0..ps.len()).filter(|&k| ps.body[k] == self.body).map(|k| {
            ([ps.x[k][0] - ps.disp[k][0] - self.tip[0], ps.x[k][1] - ps.disp[k][1] - self.tip[1]], ps.disp[k][1])
        });
        let (sums, nearest) = fit_sums(mine, radius);
        let sums = coll.sum(&sums)?;
        // The nearest point over the ranks: the smallest distance wins.
        let all = coll.gather(&[nearest.0, nearest.1])?;
        let near = all.chunks_exact(2).min_by(|a, b| a[0].total_cmp(&b[0])).map_or(f64::NAN, |c| c[1]);
        Ok((fitted(&sums), near))
    }

    /// The tip's displacement at the end and its change over the last tenth of the run (NaN if
    /// the observations do not cover it: a run restarted within the last tenth keeps no earlier
    /// history).
    fn settled(&self) -> (f64, f64) {
        let Some(last) = self.history.last() else { return (f64::NAN, f64::NAN) };
        let from = last[0] - 0.1 * self.end;
        if self.history[0][0] > from {
            return (last[1], f64::NAN);
        }
        let change = self.history.iter().filter(|h| h[0] >= from).map(|h| (h[1] - last[1]).abs()).fold(0.0, f64::max);
        (last[1], change / last[1].abs())
    }
}

/// The sums of the tip's fit over points (offset of the initial position from the tip, u_y): the
/// normal equations A = Σ φ φᵀ (upper triangle, row by row) and r = Σ φ u_y with φ = (1, dX, dY)
/// over the points within `radius` of the tip, and the nearest point (distance, u_y).
fn fit_sums(points: impl Iterator<Item = ([f64; 2], f64)>, radius: f64) -> ([f64; 9], (f64, f64)) {
    let mut sums = [0.0; 9];
    let mut nearest = (f64::INFINITY, f64::NAN);
    for (d, u) in points {
        let r = d[0].hypot(d[1]);
        if r < nearest.0 {
            nearest = (r, u);
        }
        if r > radius {
            continue;
        }
        let phi = [1.0, d[0], d[1]];
        let mut s = 0;
        for a in 0..3 {
            for b in a..3 {
                sums[s] += phi[a] * phi[b];
                s += 1;
            }
        }
        for a in 0..3 {
            sums[6 + a] += phi[a] * u;
        }
    }
    (sums, nearest)
}

/// The fit's value at the tip from the (rank-summed) sums of [`fit_sums`]; NaN if the points
/// do not determine a plane.
fn fitted(sums: &[f64]) -> f64 {
    let a = [[sums[0], sums[1], sums[2]], [sums[1], sums[3], sums[4]], [sums[2], sums[4], sums[5]]];
    crate::algebra::linalg::solve(a, [sums[6], sums[7], sums[8]], 3).map_or(f64::NAN, |c| c[0])
}

impl Check for CookCheck {
    fn columns(&self) -> Vec<String> {
        vec!["cook.tip_uy".into()]
    }

    fn observe(&mut self, t: f64, _dt: f64, model: &Model, coll: &Collective) -> Result<Vec<f64>, String> {
        let (fit, near) = self.tip_displacement(model, coll)?;
        self.history.push([t, fit, near]);
        Ok(vec![fit])
    }

    fn finish(&mut self, model: &Model, coll: &Collective) -> Result<Findings, String> {
        let ps = &model.particles;
        let mine: Vec<f64> = (0..ps.len())
            .filter(|&k| ps.body[k] == self.body)
            .flat_map(|k| [ps.x[k][0], ps.x[k][1], invariants(&ps.stress[k]).0])
            .collect();
        let points: MapPoints = coll.gather(&mine)?.chunks_exact(3).map(|c| (c[0], c[1], c[2])).collect();
        let g = &model.grid;
        let fitted: Vec<[f64; 4]> = points.iter().map(|p| [p.0, p.1, p.2, 0.0]).collect();
        self.checkerboard = super::checkerboard::fit_of(&fitted, g.origin, g.h).index;
        self.points = points.len();
        let lp = (0..ps.len()).find(|&k| ps.body[k] == self.body).map(|k| ps.lp0[k]);
        let lp = coll.max(&lp.map_or([0.0; 2], |l| l))?;
        self.map = (points, (1.2 * lp[0], 1.2 * lp[1]));
        let (tip, change) = self.settled();
        let mut metrics = vec![(
            "tip_uy_rel_error".to_string(),
            Metric::error(
                (tip / self.reference - 1.0).abs(),
                self.tolerance,
                format!(
                    "tip u_y {tip:.5} m (fit over the points within {} cells of ({}, {})) against {} m",
                    self.fit_radius, self.tip[0], self.tip[1], self.reference
                ),
            ),
        )];
        metrics.push((
            "tip_uy_change_last_tenth".to_string(),
            Metric::error(
                change,
                0.1 * self.tolerance,
                "largest change of the tip's u_y over the last tenth of the run, relative to its final value".into(),
            ),
        ));
        Ok((metrics, Vec::new()))
    }

    fn results(&self) -> Vec<(String, f64)> {
        let last = self.history.last().copied().unwrap_or([f64::NAN; 3]);
        vec![
            ("tip_uy".into(), last[1]),
            ("tip_uy_nearest_point".into(), last[2]),
            ("mean_stress_checkerboard".into(), self.checkerboard),
            ("points".into(), self.points as f64),
        ]
    }

    fn figures(&self) -> Vec<crate::plot::Figure> {
        use crate::plot::{ColourMap, Figure};
        vec![Figure::map(
            "mean_stress.png",
            "Mean stress σ_m at the end (colours: 1–99 % of the values)",
            ColourMap {
                points: self.map.0.clone(),
                half_size: self.map.1,
                label: "σ_m [Pa]".into(),
                range: ColourMap::quantiles(&self.map.0, 0.01, 0.99),
            },
        )]
    }
}

#[cfg(test)]
mod tests {
    use super::{fit_sums, fitted};

    /// The fit reproduces a linear field at the tip exactly, from points on one side of it, and
    /// ignores the points beyond its radius.
    #[test]
    fn the_tip_fit_is_exact_for_a_linear_field() {
        let field = |d: [f64; 2]| 0.27 + 0.004 * d[0] - 0.0015 * d[1];
        let mut points = Vec::new();
        for i in 0..8 {
            for j in 0..8 {
                let d = [-0.25 - 0.5 * i as f64, -0.25 - 0.5 * j as f64];
                // Far points carry a wrong value the fit must not see.
                let far = d[0].hypot(d[1]) > 2.0;
                points.push((d, if far { 99.0 } else { field(d) }));
            }
        }
        let (sums, nearest) = fit_sums(points.iter().copied(), 2.0);
        assert!((fitted(&sums) - 0.27).abs() < 1e-14, "{}", fitted(&sums));
        assert_eq!(nearest, ([-0.25f64, -0.25].iter().map(|v| v * v).sum::<f64>().sqrt(), field([-0.25, -0.25])));
        // Two points do not determine a plane.
        let (few, _) = fit_sums(points.iter().copied().take(2), 2.0);
        assert!(fitted(&few).is_nan());
    }
}
