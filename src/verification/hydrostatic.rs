//! A saturated body at rest under gravity (`kind = "hydrostatic"`): once the excess pore pressure
//! has drained (after a geostatic or a consolidation stage), the water carries its own weight
//! alone, ∇p = ρ_w b with b = (0, −g) the gravity of the body force, so that
//!
//!   p* = ρ_w g (h_w − y)
//!
//! at every point of the body, h_w the water table (where p = 0) and y the point's height at the
//! end of the run (pore pressure positive in compression, as in [003] Eq. 31 and the Terzaghi
//! check; gravity pulls along −y, as the acceleration [0, −9.81] of the cases). The metric
//! `p_rel_error` is max_p |p_p − p*_p| / max_p |p*_p| over the body's points and ranks; each
//! point's (y, p) goes to the figure of the profile.

use super::{figures, load_factor, tolerance, BuiltCheck, Check, CheckParameters, Findings, FormulationNeed, Metric};
use crate::case::{BodyId, Case, Formulation, Load, LoadId};
use crate::check::{at, finite, Checked};
use crate::model::Model;
use crate::parallel::Collective;
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "hydrostatic"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Hydrostatic {
    /// The name of the saturated body.
    pub body: String,
    /// The name of the body-force load carrying gravity (vertical, along −y; g is its magnitude
    /// times its time function at the run's end).
    pub gravity: String,
    /// The water table h_w, the height at which p = 0 [m] (default: the body's top at t = 0).
    pub water_table: Option<f64>,
    /// Largest accepted max |p − p*| / max |p*| over the body's points [-], in (0, 1] (default
    /// 0.01).
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

serde_defaults! { default_tolerance: f64 = 0.01 }

/// What a hydrostatic check names.
#[derive(Debug, Clone, Copy)]
pub struct HydrostaticIds {
    /// `body`.
    pub body: BodyId,
    /// `gravity`: a vertical body force acting on the body.
    pub gravity: LoadId,
}

impl CheckParameters for Hydrostatic {
    type Ids = HydrostaticIds;
    const FORMULATION: FormulationNeed =
        Some((Formulation::TwoPhase, "the hydrostatic pore pressure needs a two_phase analysis"));
    const SOLID: bool = true;
    const AXISYMMETRIC: bool = true;

    fn check(&self, key: &str) -> Checked {
        if let Some(h) = self.water_table {
            finite(&at(key, "water_table"), h)?;
        }
        tolerance(&at(key, "tolerance"), self.tolerance)
    }

    fn describe(&self) -> String {
        let table = self.water_table.map_or("the body's top".to_string(), |h| format!("{h} m"));
        format!("hydrostatic pore pressure ρ_w g (h_w − y) of body `{}` at rest, water table at {table}", self.body)
    }

    /// The body, and gravity a body force that pulls along −y at the run's end and acts on it.
    fn link(&self, c: &Case) -> Result<HydrostaticIds, String> {
        let ids = HydrostaticIds {
            body: c.body_named("verification.body", &self.body)?,
            gravity: c.load_named("verification.gravity", &self.gravity)?,
        };
        let Load::BodyForce(f) = c.load(ids.gravity) else {
            return Err(format!("key `verification.gravity`: `{}` must be a body_force load", self.gravity));
        };
        let a = &f.acceleration;
        if !(a.len() > 1 && a[1] < 0.0 && a.iter().enumerate().all(|(d, &x)| d == 1 || x == 0.0)) {
            return Err(format!(
                "key `verification.gravity`: the hydrostatic pressure is for gravity along −y, and `{}` accelerates \
                 by {a:?}",
                self.gravity
            ));
        }
        let end = c.end_time();
        let factor = load_factor(c, ids.gravity, end);
        if factor.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Err(format!(
                "key `verification.gravity`: `{}` does not pull at the run's end (t = {end} s): its time function is \
                 {factor} there",
                self.gravity
            ));
        }
        if c.load_bodies(ids.gravity).is_some_and(|bodies| !bodies.contains(&ids.body)) {
            return Err(format!("key `verification.gravity`: `{}` does not act on `{}`", self.gravity, self.body));
        }
        Ok(ids)
    }

    fn plane(&self, c: &Case, ids: &HydrostaticIds, _model: &Model, _coll: &Collective) -> BuiltCheck {
        Ok(Box::new(HydrostaticCheck::new(c, self, ids)?))
    }

    fn solid(&self, c: &Case, ids: &HydrostaticIds, _model: &Model<3>, _coll: &Collective) -> BuiltCheck<3> {
        Ok(Box::new(HydrostaticCheck::new(c, self, ids)?))
    }
}

/// The hydrostatic check of a case, in any dimension.
pub struct HydrostaticCheck {
    body: u16,
    /// ρ_w g [N/m³] at the end of the run.
    unit_weight: f64,
    /// h_w [m].
    water_table: f64,
    tolerance: f64,
    /// (y, p) of the body's points after [`Check::finish`].
    profile: Vec<(f64, f64)>,
}

impl HydrostaticCheck {
    /// The check of a `hydrostatic` verification `spec`, whose names resolve to `ids`.
    pub fn new(c: &Case, spec: &Hydrostatic, ids: &HydrostaticIds) -> Result<HydrostaticCheck, String> {
        let Load::BodyForce(f) = c.load(ids.gravity) else {
            return Err(format!("`{}` is not a body force", spec.gravity));
        };
        let g = -f.acceleration[1] * load_factor(c, ids.gravity, c.end_time());
        let top = c.body(ids.body).shape.bounds().1[1];
        Ok(HydrostaticCheck {
            body: ids.body.index() as u16,
            unit_weight: c.material_of(ids.body).water_density * g,
            water_table: spec.water_table.unwrap_or(top),
            tolerance: spec.tolerance,
            profile: Vec::new(),
        })
    }

    /// p* = ρ_w g (h_w − y) [Pa].
    fn pressure(&self, y: f64) -> f64 {
        self.unit_weight * (self.water_table - y)
    }
}

impl<const D: usize> Check<D> for HydrostaticCheck {
    fn columns(&self) -> Vec<String> {
        Vec::new()
    }

    fn observe(&mut self, _t: f64, _dt: f64, _model: &Model<D>, _coll: &Collective) -> Result<Vec<f64>, String> {
        Ok(Vec::new())
    }

    /// Its metric comes from the final state alone.
    fn checkpoint_state(&self, _model: &Model<D>, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        Ok(Some(Vec::new()))
    }

    fn finish(&mut self, model: &Model<D>, coll: &Collective) -> Result<Findings, String> {
        let ps = &model.particles;
        let local: Vec<f64> =
            (0..ps.len()).filter(|&k| ps.body[k] == self.body).flat_map(|k| [ps.x[k][1], ps.p[k]]).collect();
        self.profile = coll.gather(&local)?.chunks(2).map(|d| (d[0], d[1])).collect();
        let peak = self.profile.iter().map(|&(y, _)| self.pressure(y).abs()).fold(0.0, f64::max);
        let (worst, y_worst) = (self.profile.iter())
            .map(|&(y, p)| ((p - self.pressure(y)).abs(), y))
            .fold((0.0, f64::NAN), |a, b| if b.0 > a.0 { b } else { a });
        let detail = format!(
            "max |p − p*| = {worst:.4e} Pa at y = {y_worst:.4} m; max |p*| = {peak:.4e} Pa (ρ_w g = {:.6e} N/m³, h_w = {} m)",
            self.unit_weight, self.water_table
        );
        Ok((vec![("p_rel_error".into(), Metric::error(worst / peak, self.tolerance, detail))], Vec::new()))
    }

    fn figures(&self) -> Vec<crate::plot::Figure> {
        if self.profile.is_empty() {
            return Vec::new();
        }
        let kpa = |v: &[(f64, f64)]| v.iter().map(|&(d, p)| (d, 1e-3 * p)).collect::<Vec<_>>();
        let depth = |&(y, p): &(f64, f64)| (self.water_table - y, p);
        let (lo, hi) =
            self.profile.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &(y, _)| (a.min(y), b.max(y)));
        let exact: Vec<(f64, f64)> = [hi, lo].iter().map(|&y| (y, self.pressure(y))).map(|v| depth(&v)).collect();
        vec![figures::depth_profile(
            "hydrostatic_pressure.png",
            "Hydrostatic pore pressure at the end of the run",
            "pore pressure p [kPa]",
            "depth below the water table [m]",
            "MPM",
            &kpa(&self.profile.iter().map(depth).collect::<Vec<_>>()),
            "ρ_w g (h_w − y)",
            &kpa(&exact),
        )]
    }
}
