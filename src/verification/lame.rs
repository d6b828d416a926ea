//! Lamé's thick-walled cylinder and sphere under internal pressure: the nearly incompressible
//! elastic benchmarks with a closed-form answer (Timoshenko & Goodier, §33 and §141).
//!
//! With inner radius a, outer radius b, internal pressure p, Young's modulus E and Poisson's ratio
//! ν, free outer surface; the cylinder in plane strain (a plane section, or in three dimensions
//! along z between rollers):
//!   u_r = (1 + ν) p a² ((1 − 2ν) r + b²/r) / (E (b² − a²)),
//!   σ_rr = p a² (1 − b²/r²)/(b² − a²),   σ_θθ = p a² (1 + b²/r²)/(b² − a²);
//! the sphere (in axial symmetry about an axis through its centre, or in three dimensions):
//!   u_r = p a³ ((1 − 2ν) r + (1 + ν) b³/(2r²)) / (E (b³ − a³)),
//!   σ_rr = p a³ (1 − b³/r³)/(b³ − a³),   σ_θθ = p a³ (1 + b³/(2r³))/(b³ − a³).
//! Metrics: relative L2 errors over the body's points, weighted by their volumes (so that an error
//! does not shrink because more points are counted), of u_r (the displacement along the point's
//! initial radial direction), σ_rr and σ_θθ (the stress projected on the radial direction, and on
//! the hoop direction of a cylinder or the mean of the two tangential normal stresses of a sphere),
//! at the end of the run.

use super::{
    all_positive, linear_elastic, load_name, radii, BodyAndLoad, BuiltCheck, Check, CheckParameters, Findings,
    FormulationNeed, Metric,
};
use crate::case::{Case, Formulation, Geometry, Load};
use crate::check::{at, Checked};
use crate::model::loads::TimeFn;
use crate::model::Model;
use crate::parallel::Collective;
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "lame"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LameCylinder {
    /// `"cylinder"` (the default; plane strain, or in three dimensions along z) or `"sphere"`
    /// (in axial symmetry, its centre on the axis, or in three dimensions).
    #[serde(default)]
    pub shape: LameShape,
    /// The name of the shell's body (linear elastic).
    pub body: String,
    /// The name of the internal pressure (p at the run's end): a `line_pressure` in a plane or
    /// axisymmetric case, a `surface_pressure` in three dimensions.
    pub load: String,
    /// The centre [m]: the cylinder's axis (x, y), the sphere's centre (x, y, z in three
    /// dimensions; (0, y) in axial symmetry) (default: the origin; entries not given are 0).
    #[serde(default)]
    pub center: Vec<f64>,
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

/// The shell of a `lame` check.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum LameShape {
    /// A cylinder in plane strain.
    #[default]
    Cylinder,
    /// A sphere.
    Sphere,
}

impl CheckParameters for LameCylinder {
    type Ids = BodyAndLoad;
    const FORMULATION: FormulationNeed =
        Some((Formulation::OnePhase, "the Lamé reference is for a one_phase analysis"));
    const SOLID: bool = true;
    const AXISYMMETRIC: bool = true;

    fn check(&self, key: &str) -> Checked {
        if self.center.len() > 3 || self.center.iter().any(|v| !v.is_finite()) {
            return Err(format!("key `{}`: at most three finite entries, got {:?}", at(key, "center"), self.center));
        }
        all_positive(key, &[("inner_radius", self.inner_radius), ("outer_radius", self.outer_radius)])?;
        radii(key, self.inner_radius, self.outer_radius)?;
        let (d, s) = (self.displacement_tolerance, self.stress_tolerance);
        all_positive(key, &[("displacement_tolerance", d), ("stress_tolerance", s)])
    }

    fn describe(&self) -> String {
        let what = if self.shape == LameShape::Sphere { "sphere" } else { "cylinder" };
        format!("Lamé {what}, a = {} m, b = {} m: u_r, σ_rr, σ_θθ", self.inner_radius, self.outer_radius)
    }

    /// A linear elastic body and a line pressure (a surface pressure in three dimensions); a
    /// cylinder in plane strain or three dimensions, a sphere in axial symmetry or three dimensions.
    fn link(&self, c: &Case) -> Result<BodyAndLoad, String> {
        let ids = BodyAndLoad::named(c, &self.body, &self.load)?;
        let (solid, axisymmetric) = (c.dimension() == 3, c.analysis.geometry == Geometry::Axisymmetric);
        match (self.shape, solid, axisymmetric) {
            (LameShape::Cylinder, _, true) => {
                return Err(
                    "key `verification.shape`: a cylinder in axial symmetry is the `hollow_cylinder` check's".into()
                )
            }
            (LameShape::Sphere, false, false) => {
                return Err("key `verification.shape`: a sphere needs axial symmetry or three dimensions".into())
            }
            _ => {}
        }
        let pressed = match c.load(ids.load) {
            Load::LinePressure(_) => !solid,
            Load::SurfacePressure(_) => solid,
            _ => false,
        };
        if !pressed {
            let kind = if solid { "surface_pressure" } else { "line_pressure" };
            return Err(format!("key `verification.load`: `{}` must be a {kind} load", load_name(c, ids.load)));
        }
        linear_elastic(c, ids.body, "the Lamé reference")?;
        Ok(ids)
    }

    fn plane(&self, c: &Case, ids: &BodyAndLoad, _model: &Model, _coll: &Collective) -> BuiltCheck {
        Ok(Box::new(LameCheck::new(c, self, ids)?))
    }

    fn solid(&self, c: &Case, ids: &BodyAndLoad, _model: &Model<3>, _coll: &Collective) -> BuiltCheck<3> {
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
    /// A sphere (else a cylinder in plane strain).
    pub sphere: bool,
}

impl Lame {
    /// (u_r, σ_rr, σ_θθ) at radius r.
    pub fn at(&self, r: f64) -> (f64, f64, f64) {
        let nu = self.nu;
        if self.sphere {
            let (a3, b3) = (self.a.powi(3), self.b.powi(3));
            let k = self.p * a3 / (b3 - a3);
            let u = k * ((1.0 - 2.0 * nu) * r + (1.0 + nu) * b3 / (2.0 * r * r)) / self.e;
            return (u, k * (1.0 - b3 / r.powi(3)), k * (1.0 + b3 / (2.0 * r.powi(3))));
        }
        let (a2, b2) = (self.a * self.a, self.b * self.b);
        let k = self.p * a2 / (b2 - a2);
        let u = (1.0 + nu) * k * ((1.0 - 2.0 * nu) * r + b2 / r) / self.e;
        (u, k * (1.0 - b2 / (r * r)), k * (1.0 + b2 / (r * r)))
    }
}

/// The Lamé check of a case.
pub struct LameCheck {
    body: u16,
    center: [f64; 3],
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
        let p = match c.load(ids.load) {
            Load::LinePressure(l) => l.pressure,
            Load::SurfacePressure(l) => l.pressure,
            _ => return Err(format!("`{}` is not a pressure", spec.load)),
        };
        let sphere = spec.shape == LameShape::Sphere;
        Ok(LameCheck {
            body: ids.body.index() as u16,
            center: std::array::from_fn(|d| spec.center.get(d).copied().unwrap_or(0.0)),
            theory: Lame { a: spec.inner_radius, b: spec.outer_radius, p, e, nu, sphere },
            time_fn: super::load_time_fn(c, ids.load),
            tolerances: (spec.displacement_tolerance, spec.stress_tolerance),
            last: [f64::NAN; 4],
        })
    }

    fn errors<const D: usize>(&self, t: f64, model: &Model<D>, coll: &Collective) -> Result<[f64; 3], String> {
        let ps = &model.particles;
        let theory = Lame { p: self.theory.p * self.time_fn.eval(t), ..self.theory };
        // Σ V e² and Σ V x*² for u_r, σ_rr, σ_θθ.
        let mut local = [0.0; 6];
        for k in (0..ps.len()).filter(|&k| ps.body[k] == self.body) {
            // The radial direction: in the section's plane for a cylinder (along z in three
            // dimensions), from the centre for a sphere.
            let along = D.min(if theory.sphere { 3 } else { 2 });
            let d: [f64; 3] = std::array::from_fn(|a| if a < along { ps.x0[k][a] - self.center[a] } else { 0.0 });
            let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if r == 0.0 {
                continue;
            }
            let n = d.map(|v| v / r);
            let (u, srr, stt) = theory.at(r);
            let st = crate::soils::principal::tensor(&ps.stress[k]);
            let ur: f64 = (0..D).map(|a| ps.disp[k][a] * n[a]).sum();
            let normal = |m: [f64; 3]| (0..3).map(|a| (0..3).map(|b| m[a] * st[a][b] * m[b]).sum::<f64>()).sum::<f64>();
            let rr = normal(n);
            // A cylinder's hoop direction; a sphere's two tangential directions, averaged.
            let tt =
                if theory.sphere { 0.5 * (st[0][0] + st[1][1] + st[2][2] - rr) } else { normal([-n[1], n[0], 0.0]) };
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

impl<const D: usize> Check<D> for LameCheck {
    fn columns(&self) -> Vec<String> {
        vec!["lame.u_r_error".into(), "lame.sigma_rr_error".into(), "lame.sigma_tt_error".into()]
    }

    fn observe(&mut self, t: f64, _dt: f64, model: &Model<D>, coll: &Collective) -> Result<Vec<f64>, String> {
        let e = self.errors(t, model, coll)?;
        self.last = [e[0], e[1], e[2], t];
        Ok(e.to_vec())
    }

    fn finish(&mut self, _model: &Model<D>, _coll: &Collective) -> Result<Findings, String> {
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

    fn checkpoint_state(&self, _model: &Model<D>, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        Ok(Some(self.last.to_vec()))
    }

    fn restore_state(&mut self, state: &[f64], _model: &Model<D>) -> Result<(), String> {
        self.last = state.try_into().map_err(|_| "the Lamé check's state has 4 values".to_string())?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_closed_form_meets_its_boundary_conditions() {
        let l = Lame { a: 1.0, b: 2.0, p: 1e3, e: 1e6, nu: 0.3, sphere: false };
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

    /// The sphere's closed form: σ_rr(a) = −p, σ_rr(b) = 0, and Hooke's law with ε_rr = du/dr
    /// and the two hoop strains u/r.
    #[test]
    fn the_sphere_s_closed_form_meets_its_boundary_conditions() {
        let l = Lame { a: 1.0, b: 2.0, p: 1e3, e: 1e6, nu: 0.3, sphere: true };
        assert!((l.at(1.0).1 + 1e3).abs() < 1e-9 && l.at(2.0).1.abs() < 1e-9);
        let (r, h) = (1.4, 1e-6);
        let (u, srr, stt) = l.at(r);
        let dudr = (l.at(r + h).0 - l.at(r - h).0) / (2.0 * h);
        let g = l.e / (2.0 * (1.0 + l.nu));
        let lam = l.e * l.nu / ((1.0 + l.nu) * (1.0 - 2.0 * l.nu));
        assert!(((lam + 2.0 * g) * dudr + 2.0 * lam * u / r - srr).abs() < 1e-6);
        assert!((lam * dudr + 2.0 * (lam + g) * u / r - stt).abs() < 1e-6);
    }
}
