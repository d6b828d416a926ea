//! The elastic column under its self-weight and a surcharge (one-phase), at rest at the end of
//! the run.

use super::{
    all_positive, figures, load_factor, load_name, plain_load, BuiltCheck, Check, CheckParameters, Findings,
    FormulationNeed, Metric,
};
use crate::case::{BodyId, Case, Formulation, Load, LoadId};
use crate::check::Checked;
use crate::model::Model;
use crate::parallel::Collective;
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "elastic_column"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ElasticColumn {
    /// The name of the column body (laterally confined, fixed base).
    pub body: String,
    /// The name of the body-force load carrying gravity.
    pub gravity: String,
    /// The name of the surface load (a particle or nodal traction), if any.
    pub surcharge: Option<String>,
    /// Pass threshold for max |σ_yy − σ*| / max |σ*| over the column [-], in (0, 1] (default 0.01).
    #[serde(default = "default_column_tol")]
    pub stress_tolerance: f64,
    /// Pass threshold for the relative settlement error [-], in (0, 1] (default 0.01).
    #[serde(default = "default_column_tol")]
    pub settlement_tolerance: f64,
}

serde_defaults! { default_column_tol: f64 = 0.01 }

/// What an elastic column names.
#[derive(Debug, Clone, Copy)]
pub struct ElasticColumnIds {
    /// `body`.
    pub body: BodyId,
    /// `gravity`: a body force.
    pub gravity: LoadId,
    /// `surcharge`: a particle or nodal traction.
    pub surcharge: Option<LoadId>,
}

impl CheckParameters for ElasticColumn {
    type Ids = ElasticColumnIds;
    const FORMULATION: FormulationNeed =
        Some((Formulation::OnePhase, "the elastic column reference is for a one_phase analysis"));
    const AXISYMMETRIC: bool = true;

    fn check(&self, key: &str) -> Checked {
        let (st, se) = (self.stress_tolerance, self.settlement_tolerance);
        all_positive(key, &[("stress_tolerance", st), ("settlement_tolerance", se)])
    }

    fn describe(&self) -> String {
        "static elastic column under self-weight and surcharge".into()
    }

    /// The names, gravity a body force and a surcharge a traction.
    fn link(&self, c: &Case) -> Result<ElasticColumnIds, String> {
        let ids = ElasticColumnIds {
            body: c.body_named("verification.body", &self.body)?,
            gravity: c.load_named("verification.gravity", &self.gravity)?,
            surcharge: self.surcharge.as_ref().map(|s| c.load_named("verification.surcharge", s)).transpose()?,
        };
        plain_load(c, ids.gravity)?;
        if !matches!(c.load(ids.gravity), Load::BodyForce(_)) {
            return Err(format!(
                "key `verification.gravity`: `{}` must be a body_force load",
                load_name(c, ids.gravity)
            ));
        }
        match ids.surcharge {
            Some(s) if c.load(s).traction().is_none() => {
                Err(format!("key `verification.surcharge`: no traction load named `{}`", load_name(c, s)))
            }
            _ => Ok(ids),
        }
    }

    fn plane(&self, c: &Case, ids: &ElasticColumnIds, model: &Model, coll: &Collective) -> BuiltCheck {
        Ok(Box::new(ElasticColumnCheck::new(c, model, coll, self, ids)?))
    }
}

/// Elastic column under self-weight and surcharge (one-phase), checked against the static solution
/// at the end of the run: σ_yy = −(ρ g d + q) at initial depth d, settlement ρ g H²/(2E_c) + q H/E_c
/// (small strain), the settlement measured as (Σ V₀ − Σ V)/width like Terzaghi's.
pub struct ElasticColumnCheck {
    body: u16,
    top: f64,
    width: f64,
    density: f64,
    gravity: f64,
    surcharge: f64,
    settlement: f64,
    tolerances: (f64, f64),
    volume0: f64,
    last_settlement: f64,
    /// (t, settlement) after every step.
    history: Vec<(f64, f64)>,
    /// (initial depth, σ_yy) of the column's particles after [`Check::finish`].
    stress_profile: Vec<(f64, f64)>,
    height: f64,
}

impl ElasticColumnCheck {
    /// The check of an `elastic_column` verification (collective).
    pub fn new(
        c: &Case,
        model: &Model,
        coll: &Collective,
        spec: &ElasticColumn,
        ids: &ElasticColumnIds,
    ) -> Result<ElasticColumnCheck, String> {
        let bi = ids.body.index();
        let (lo, hi) = c.body(ids.body).shape.bounds();
        let mat = &model.materials[c.material_id_of(ids.body).index()];
        let end = c.end_time();
        let g = match c.load(ids.gravity) {
            Load::BodyForce(f) => f.acceleration[1].abs() * load_factor(c, ids.gravity, end),
            l => return Err(format!("`{}` is not a body force", l.name())),
        };
        let q = match ids.surcharge.map(|s| (s, c.load(s))) {
            Some((s, l)) => match l.traction() {
                Some(traction) => traction[1].abs() * load_factor(c, s, end),
                None => return Err(format!("`{}` is not a traction", l.name())),
            },
            None => 0.0,
        };
        let density = mat.mixture_density(mat.porosity);
        let ec = mat.model.elastic().constrained_modulus();
        let height = hi[1] - lo[1];
        let v0: f64 = (0..model.particles.len())
            .filter(|&k| model.particles.body[k] as usize == bi)
            .map(|k| model.particles.volume[k])
            .sum();
        Ok(ElasticColumnCheck {
            body: bi as u16,
            top: hi[1],
            width: model.geometry.plan_area(lo[0], hi[0]),
            density,
            gravity: g,
            surcharge: q,
            settlement: density * g * height * height / (2.0 * ec) + q * height / ec,
            tolerances: (spec.stress_tolerance, spec.settlement_tolerance),
            volume0: coll.sum(&[v0])?[0],
            last_settlement: 0.0,
            history: Vec::new(),
            stress_profile: Vec::new(),
            height,
        })
    }
}

impl Check for ElasticColumnCheck {
    fn columns(&self) -> Vec<String> {
        vec!["column.settlement".into()]
    }

    /// Its metrics come from the final state alone.
    fn checkpoint_state(&self, _model: &Model, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        Ok(Some(Vec::new()))
    }

    fn observe(&mut self, t: f64, _dt: f64, model: &Model, coll: &Collective) -> Result<Vec<f64>, String> {
        let v: f64 = (0..model.particles.len())
            .filter(|&k| model.particles.body[k] == self.body)
            .map(|k| model.particles.volume[k])
            .sum();
        self.last_settlement = (self.volume0 - coll.sum(&[v])?[0]) / self.width;
        self.history.push((t, self.last_settlement));
        Ok(vec![self.last_settlement])
    }

    fn finish(&mut self, model: &Model, coll: &Collective) -> Result<Findings, String> {
        let ps = &model.particles;
        let local: Vec<f64> = (0..ps.len())
            .filter(|&k| ps.body[k] == self.body)
            .flat_map(|k| [self.top - ps.x0[k][1], ps.stress[k][1]])
            .collect();
        let all = coll.gather(&local)?;
        let exact = |d: f64| -(self.density * self.gravity * d + self.surcharge);
        let peak = all.chunks(2).map(|d| exact(d[0]).abs()).fold(0.0, f64::max);
        let worst = all.chunks(2).map(|d| (d[1] - exact(d[0])).abs()).fold(0.0, f64::max);
        self.stress_profile = all.chunks(2).map(|d| (d[0], d[1])).collect();
        let s = self.last_settlement;
        Ok((
            vec![
                (
                    "stress_max_rel_error".into(),
                    Metric::error(
                        worst / peak,
                        self.tolerances.0,
                        format!("max |σ_yy − σ*| = {worst:.4e} Pa; max |σ*| = {peak:.4e} Pa"),
                    ),
                ),
                (
                    "settlement_rel_error".into(),
                    Metric::error(
                        (s - self.settlement).abs() / self.settlement,
                        self.tolerances.1,
                        format!("settlement {s:.6e} m vs static {:.6e} m", self.settlement),
                    ),
                ),
            ],
            Vec::new(),
        ))
    }

    fn figures(&self) -> Vec<crate::plot::Figure> {
        let kpa = |v: &[(f64, f64)]| v.iter().map(|&(d, s)| (d, 1e-3 * s)).collect::<Vec<_>>();
        let exact: Vec<(f64, f64)> =
            [0.0, self.height].iter().map(|&d| (d, -(self.density * self.gravity * d + self.surcharge))).collect();
        let t_end = self.history.last().map_or(0.0, |r| r.0);
        let t_start = self.history.first().map_or(0.0, |r| r.0);
        let mut settle = figures::settlement_history(
            "elastic_column_settlement.png",
            "Elastic column: settlement under self-weight, then the surcharge",
            &self.history,
            Some(("static solution, final load", &[(t_start, self.settlement), (t_end, self.settlement)])),
        );
        settle.series[1].label = "static solution under the final load".into();
        vec![
            figures::depth_profile(
                "elastic_column_stress.png",
                "Elastic column: vertical stress at the end of the run",
                "vertical stress σ_yy [kPa]",
                "initial depth below the top [m]",
                "MPM",
                &kpa(&self.stress_profile),
                "static solution −(ρ g d + q)",
                &kpa(&exact),
            ),
            settle,
        ]
    }
}
