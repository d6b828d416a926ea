//! Lamé's thick-walled cylinder under internal pressure, plane strain: the nearly incompressible
//! elastic benchmark with a closed-form answer (Timoshenko & Goodier, §33).
//!
//! With inner radius a, outer radius b, internal pressure p, Young's modulus E and Poisson's ratio
//! ν (plane strain, free outer surface):
//!   u_r = (1 + ν) p a² ((1 − 2ν) r + b²/r) / (E (b² − a²)),
//!   σ_rr = p a² (1 − b²/r²)/(b² − a²),   σ_θθ = p a² (1 + b²/r²)/(b² − a²).
//! Metrics: relative L2 errors over the body's points, weighted by their volumes (so that an error
//! does not shrink because more points are counted), of u_r (the displacement along the point's
//! initial radial direction), σ_rr and σ_θθ (the stress projected on the radial and hoop directions
//! there), at the end of the run.

use super::{
    all_positive, linear_elastic, load_name, radii, BodyAndLoad, BuiltCheck, Check, CheckParameters, Findings,
    FormulationNeed, Metric,
};
use crate::case::{Case, Formulation, Load};
use crate::check::{at, finite2, Checked};
use crate::model::loads::TimeFn;
use crate::model::Model;
use crate::parallel::Collective;
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "lame"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LameCylinder {
    /// The name of the cylinder's body (linear elastic).
    pub body: String,
    /// The name of the internal pressure (a `line_pressure`; p at the run's end).
    pub load: String,
    /// The cylinder's axis [m] (default: the origin).
    #[serde(default)]
    pub center: [f64; 2],
    /// Inner radius a [m], > 0.
    pub inner_radius: f64,
    /// Outer radius b [m], > a.
    pub outer_radius: f64,
    /// Largest accepted relative L2 error of u_r [-], in (0, 1] (default 0.05).
    #[serde(default = "default_lame_tol")]
    pub displacement_tolerance: f64,
    /// Largest accepted relative L2 error of σ_rr and of σ_θθ [-], in (0, 1] (default 0.05).
    #[serde(default = "default_lame_tol")]
    pub stress_tolerance: f64,
}

serde_defaults! { default_lame_tol: f64 = 0.05 }

impl CheckParameters for LameCylinder {
    type Ids = BodyAndLoad;
    const FORMULATION: FormulationNeed =
        Some((Formulation::OnePhase, "the Lamé reference is for a one_phase analysis"));

    fn check(&self, key: &str) -> Checked {
        finite2(&at(key, "center"), self.center)?;
        all_positive(key, &[("inner_radius", self.inner_radius), ("outer_radius", self.outer_radius)])?;
        radii(key, self.inner_radius, self.outer_radius)?;
        let (d, s) = (self.displacement_tolerance, self.stress_tolerance);
        all_positive(key, &[("displacement_tolerance", d), ("stress_tolerance", s)])
    }

    fn describe(&self) -> String {
        format!("Lamé cylinder, a = {} m, b = {} m: u_r, σ_rr, σ_θθ", self.inner_radius, self.outer_radius)
    }

    /// A linear elastic body and a line pressure.
    fn link(&self, c: &Case) -> Result<BodyAndLoad, String> {
        let ids = BodyAndLoad::named(c, &self.body, &self.load)?;
        if !matches!(c.load(ids.load), Load::LinePressure(_)) {
            return Err(format!("key `verification.load`: `{}` must be a line_pressure load", load_name(c, ids.load)));
        }
        linear_elastic(c, ids.body, "the Lamé reference")?;
        Ok(ids)
    }

    fn plane(&self, c: &Case, ids: &BodyAndLoad, _model: &Model, _coll: &Collective) -> BuiltCheck {
        Ok(Box::new(LameCheck::new(c, self, ids)?))
    }
}

/// The closed-form solution.
#[derive(Debug, Clone, Copy)]
pub struct Lame {
    /// Inner radius a [m].
    pub a: f64,
    /// Outer radius b [m].
    pub b: f64,
    /// Internal pressure p [Pa].
    pub p: f64,
    /// Young's modulus [Pa].
    pub e: f64,
    /// Poisson's ratio.
    pub nu: f64,
}

impl Lame {
    /// (u_r, σ_rr, σ_θθ) at radius r.
    pub fn at(&self, r: f64) -> (f64, f64, f64) {
        let (a2, b2) = (self.a * self.a, self.b * self.b);
        let k = self.p * a2 / (b2 - a2);
        let u = (1.0 + self.nu) * k * ((1.0 - 2.0 * self.nu) * r + b2 / r) / self.e;
        (u, k * (1.0 - b2 / (r * r)), k * (1.0 + b2 / (r * r)))
    }
}

/// The Lamé check of a case.
pub struct LameCheck {
    body: u16,
    center: [f64; 2],
    theory: Lame,
    time_fn: TimeFn,
    tolerances: (f64, f64),
    /// (e_u, e_rr, e_θθ, t) after the last step.
    last: [f64; 4],
}

impl LameCheck {
    /// The check of a `lame` verification `spec`, whose names resolve to `ids`.
    pub fn new(c: &Case, spec: &LameCylinder, ids: &BodyAndLoad) -> Result<LameCheck, String> {
        let (e, nu) = super::elastic_body(c, ids.body)?;
        let Load::LinePressure(load) = c.load(ids.load) else {
            return Err(format!("`{}` is not a line_pressure load", spec.load));
        };
        Ok(LameCheck {
            body: ids.body.index() as u16,
            center: spec.center,
            theory: Lame { a: spec.inner_radius, b: spec.outer_radius, p: load.pressure, e, nu },
            time_fn: super::load_time_fn(c, ids.load),
            tolerances: (spec.displacement_tolerance, spec.stress_tolerance),
            last: [f64::NAN; 4],
        })
    }

    fn errors(&self, t: f64, model: &Model, coll: &Collective) -> Result<[f64; 3], String> {
        let ps = &model.particles;
        let theory = Lame { p: self.theory.p * self.time_fn.eval(t), ..self.theory };
        // Σ V e² and Σ V x*² for u_r, σ_rr, σ_θθ.
        let mut local = [0.0; 6];
        for k in (0..ps.len()).filter(|&k| ps.body[k] == self.body) {
            let d = [ps.x0[k][0] - self.center[0], ps.x0[k][1] - self.center[1]];
            let r = d[0].hypot(d[1]);
            if r == 0.0 {
                continue;
            }
            let (c, s) = (d[0] / r, d[1] / r);
            let (u, srr, stt) = theory.at(r);
            let st = ps.stress[k];
            let ur = ps.disp[k][0] * c + ps.disp[k][1] * s;
            let rr = st[0] * c * c + st[1] * s * s + 2.0 * st[2] * c * s;
            let tt = st[0] * s * s + st[1] * c * c - 2.0 * st[2] * c * s;
            let v = ps.volume[k];
            for (i, (x, x_star)) in [(ur, u), (rr, srr), (tt, stt)].into_iter().enumerate() {
                local[2 * i] += v * (x - x_star).powi(2);
                local[2 * i + 1] += v * x_star * x_star;
            }
        }
        let s = coll.sum(&local)?;
        Ok(std::array::from_fn(|i| (s[2 * i] / s[2 * i + 1].max(f64::MIN_POSITIVE)).sqrt()))
    }
}

impl Check for LameCheck {
    fn columns(&self) -> Vec<String> {
        vec!["lame.u_r_error".into(), "lame.sigma_rr_error".into(), "lame.sigma_tt_error".into()]
    }

    fn observe(&mut self, t: f64, _dt: f64, model: &Model, coll: &Collective) -> Result<Vec<f64>, String> {
        let e = self.errors(t, model, coll)?;
        self.last = [e[0], e[1], e[2], t];
        Ok(e.to_vec())
    }

    fn finish(&mut self, _model: &Model, _coll: &Collective) -> Result<Findings, String> {
        let [eu, err, ett, t] = self.last;
        let l = &self.theory;
        let detail = |what: &str| {
            format!(
                "relative L2 error of {what} at t = {t:.6e} s (a = {} m, b = {} m, p = {:.4e} Pa, ν = {})",
                l.a,
                l.b,
                l.p * self.time_fn.eval(t),
                l.nu
            )
        };
        Ok((
            vec![
                ("u_r_rel_l2_error".into(), Metric::error(eu, self.tolerances.0, detail("u_r"))),
                ("sigma_rr_rel_l2_error".into(), Metric::error(err, self.tolerances.1, detail("σ_rr"))),
                ("sigma_tt_rel_l2_error".into(), Metric::error(ett, self.tolerances.1, detail("σ_θθ"))),
            ],
            Vec::new(),
        ))
    }

    fn checkpoint_state(&self, _model: &Model, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        Ok(Some(self.last.to_vec()))
    }

    fn restore_state(&mut self, state: &[f64], _model: &Model) -> Result<(), String> {
        self.last = state.try_into().map_err(|_| "the Lamé check's state has 4 values".to_string())?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_closed_form_meets_its_boundary_conditions() {
        let l = Lame { a: 1.0, b: 2.0, p: 1e3, e: 1e6, nu: 0.3 };
        let (_, srr_a, _) = l.at(1.0);
        let (_, srr_b, _) = l.at(2.0);
        assert!((srr_a + 1e3).abs() < 1e-9 && srr_b.abs() < 1e-9);
        // Plane strain compatibility: ε_θθ = u/r and ε_rr = du/dr from Hooke's law.
        let r = 1.4;
        let (u, srr, stt) = l.at(r);
        let h = 1e-6;
        let dudr = (l.at(r + h).0 - l.at(r - h).0) / (2.0 * h);
        let g = l.e / (2.0 * (1.0 + l.nu));
        let lam = l.e * l.nu / ((1.0 + l.nu) * (1.0 - 2.0 * l.nu));
        assert!(((lam + 2.0 * g) * dudr + lam * u / r - srr).abs() < 1e-6);
        assert!((lam * dudr + (lam + 2.0 * g) * u / r - stt).abs() < 1e-6);
    }
}
