//! The hollow cylinder of [001] §3.1 in axial symmetry: a thick-walled cylinder under internal
//! pressure with its outer wall held radially and plane strain along the axis (boundary
//! conditions that [001] does not state; they are the ones that reproduce its constants
//! A = 19.56 kN and C = 10.87 kPa).
//!
//! With inner radius a, outer radius b, pressure p, shear modulus μ, Poisson's ratio ν and
//! κ = 1/(1 − 2ν), compression positive:
//!   A = p/(1/a² + κ/b²),  C = κA/(2b²),
//!   Δσ_rr = A/r² + 2C,  Δσ_θθ = −A/r² + 2C,  Δσ_yy = 4νC,  Δσ_m = 4C(1 + ν)/3 (constant),
//!   u_r = (A/2μ)(1/r − r/b²).
//! Metrics after the first load step (the first increment of [001]), from the run: u_r at r = a
//! extrapolated linearly from the two innermost columns of points (exact for the linear basis,
//! whose displacement is linear between the nodes), Δσ_rr averaged over the innermost column
//! (the point mp1 of [001]) and the volume-weighted RMS over the body of the relative error of
//! Δσ_rr (weighted by volume, so that it does not shrink because more points are counted). The
//! reference is small-strain: a load of [001]'s 100 kPa strains the inner wall by 9 % and the
//! geometrically nonlinear answer differs by 3.6 % in u_r(a); the case applies a small
//! increment.

use super::{
    all_positive, linear_elastic, load_name, radii, BodyAndLoad, BuiltCheck, Check, CheckParameters, Findings,
    FormulationNeed, Metric,
};
use crate::case::{Case, Formulation, Geometry};
use crate::check::{at, positive, Checked};
use crate::model::loads::TimeFn;
use crate::model::Model;
use crate::parallel::Collective;
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "hollow_cylinder"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HollowCylinder {
    /// The name of the cylinder's body (linear elastic; the analysis axisymmetric).
    pub body: String,
    /// The name of the internal pressure (a `nodal_traction` or `particle_traction` whose x
    /// component is the pressure on the inner face, times its time function).
    pub load: String,
    /// Inner radius a [m], > 0.
    pub inner_radius: f64,
    /// Outer radius b [m] (held radially), > a.
    pub outer_radius: f64,
    /// Largest accepted relative error of u_r at the inner radius [-], in (0, 1] (default 0.05).
    #[serde(default = "default_displacement_tol")]
    pub displacement_tolerance: f64,
    /// Largest accepted relative error of Δσ_rr at the innermost points (mp1) and volume-weighted
    /// RMS of the relative error of Δσ_rr over the body [-], in (0, 1] (default 0.25).
    #[serde(default = "default_stress_tol")]
    pub stress_tolerance: f64,
    /// Checks every load step as an increment of the remaining cylinder ([001]'s 25 increments):
    /// by uniqueness, the closed form of the original cylinder restricted to [r_i, b] is the
    /// small-strain increment of the wall whose inner face has moved to r_i when the load applied
    /// there is the original Δσ_rr(r_i) (an `increment_factor` `A / x^2 + 2 * C`). Without it only
    /// the first step is checked.
    pub increments: Option<IncrementTolerances>,
}

/// Tolerances of the hollow cylinder's step-by-step comparison (the innermost column of points,
/// mp1, against the closed form at its radius at the start of each step).
#[derive(Debug, Clone, Copy, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct IncrementTolerances {
    /// Largest accepted relative error of Δq, the von Mises stress of the step's stress increment,
    /// over the steps ([001]: 10 %) [-], > 0.
    pub q: f64,
    /// Largest accepted error of Δσ_m over the steps, relative to the step's pressure at r = a
    /// ([001]: 5 kPa per 100 kPa) [-], > 0.
    pub mean_stress: f64,
    /// Largest accepted relative error of mp1's radius after the last step against the closed-form
    /// path r_{k+1} = r_k + u_r(r_k) ([001]: 5 %) [-], > 0.
    pub radius: f64,
}

serde_defaults! { default_displacement_tol: f64 = 0.05, default_stress_tol: f64 = 0.25 }

impl CheckParameters for HollowCylinder {
    type Ids = BodyAndLoad;
    const FORMULATION: FormulationNeed =
        Some((Formulation::OnePhase, "the hollow cylinder's reference is for a one_phase analysis"));
    const AXISYMMETRIC: bool = true;

    fn check(&self, key: &str) -> Checked {
        positive(&at(key, "inner_radius"), self.inner_radius)?;
        radii(key, self.inner_radius, self.outer_radius)?;
        let (d, s) = (self.displacement_tolerance, self.stress_tolerance);
        all_positive(key, &[("displacement_tolerance", d), ("stress_tolerance", s)])?;
        match self.increments {
            Some(t) => {
                let k = at(key, "increments");
                all_positive(&k, &[("q", t.q), ("mean_stress", t.mean_stress), ("radius", t.radius)])
            }
            None => Ok(()),
        }
    }

    fn describe(&self) -> String {
        format!(
            "axisymmetric hollow cylinder with a fixed outer wall ([001] §3.1), a = {} m, b = {} m: u_r(a) and \
             Δσ_rr after the first load step{}",
            self.inner_radius,
            self.outer_radius,
            if self.increments.is_some() {
                "; every step's Δq and Δσ_m at mp1 and mp1's radius against the closed form of the remaining cylinder"
            } else {
                ""
            }
        )
    }

    /// A traction on a linear elastic body, in an axisymmetric analysis.
    fn link(&self, c: &Case) -> Result<BodyAndLoad, String> {
        let ids = BodyAndLoad::named(c, &self.body, &self.load)?;
        if c.load(ids.load).traction().is_none() {
            return Err(format!(
                "key `verification.load`: `{}` must be a nodal_traction or particle_traction load",
                load_name(c, ids.load)
            ));
        }
        linear_elastic(c, ids.body, "the hollow cylinder's reference")?;
        if c.analysis.geometry != Geometry::Axisymmetric {
            return Err("key `verification`: the hollow cylinder's reference needs `analysis.geometry = \
                        \"axisymmetric\"`"
                .into());
        }
        Ok(ids)
    }

    fn plane(&self, c: &Case, ids: &BodyAndLoad, _model: &Model, _coll: &Collective) -> BuiltCheck {
        Ok(Box::new(HollowCylinderCheck::new(c, self, ids)?))
    }
}

/// The closed-form solution (compression positive).
#[derive(Debug, Clone, Copy)]
pub struct FixedWallLame {
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

impl FixedWallLame {
    /// The constants (A [N/m… Pa m²], C [Pa]).
    pub fn constants(&self) -> (f64, f64) {
        let kappa = 1.0 / (1.0 - 2.0 * self.nu);
        let a = self.p / (1.0 / (self.a * self.a) + kappa / (self.b * self.b));
        (a, kappa * a / (2.0 * self.b * self.b))
    }

    /// (u_r, Δσ_rr, Δσ_θθ, Δσ_yy) at radius r, stresses compression positive.
    pub fn at(&self, r: f64) -> (f64, f64, f64, f64) {
        let (a, c) = self.constants();
        let mu = self.e / (2.0 * (1.0 + self.nu));
        (
            a / (2.0 * mu) * (1.0 / r - r / (self.b * self.b)),
            a / (r * r) + 2.0 * c,
            -a / (r * r) + 2.0 * c,
            4.0 * self.nu * c,
        )
    }

    /// The mean stress Δσ_m, the same at every radius (compression positive).
    pub fn mean_stress(&self) -> f64 {
        4.0 * self.constants().1 * (1.0 + self.nu) / 3.0
    }
}

/// What the first increment gave.
#[derive(Debug, Clone, Copy, Default)]
struct Increment {
    /// u_r at r = a [m].
    u_inner: f64,
    /// Δσ_rr, Δσ_m and Δq at the innermost points (compression positive) [Pa], and their radius [m].
    mp1: [f64; 4],
    /// Volume-weighted RMS of the relative error of Δσ_rr over the body.
    rms: f64,
    /// The pressure of the increment [Pa] and its time [s].
    p: f64,
    t: f64,
}

/// The innermost column of points (mp1) at one time: its mean stress (xx, yy, xy, zz, tension
/// positive) and its mean position.
#[derive(Debug, Clone, Copy, Default)]
struct Mp1 {
    stress: [f64; 4],
    x: [f64; 2],
}

/// The step-by-step comparison with [001]'s load increments.
#[derive(Debug, Clone, Copy)]
struct Steps {
    tolerances: IncrementTolerances,
    /// The last observed time, the load's f there and mp1 then.
    last: Option<(f64, f64, Mp1)>,
    /// The largest relative error of Δq and of Δσ_m (over the step's pressure), with their times.
    worst_q: (f64, f64),
    worst_m: (f64, f64),
    /// mp1's radius on the closed-form path r_{k+1} = r_k + u_r(r_k).
    r_exact: f64,
    /// Steps compared.
    count: usize,
}

/// The hollow-cylinder check of a case.
pub struct HollowCylinderCheck {
    body: u16,
    theory: FixedWallLame,
    time_fn: TimeFn,
    /// The load's `increment_factor` g and the case's parameters, if it has one.
    factor: Option<(String, std::collections::BTreeMap<String, f64>)>,
    tolerances: (f64, f64),
    first: Option<Increment>,
    steps: Option<Steps>,
    /// Values of the last step for `history.csv`: Δq, Δq*, Δσ_m at mp1 and mp1's radius.
    last_row: [f64; 4],
    /// The radii at t = 0 of the two innermost columns of points, once found.
    columns: Option<[f64; 2]>,
}

impl HollowCylinderCheck {
    /// The check of a `hollow_cylinder` verification `spec`, whose names resolve to `ids`.
    pub fn new(c: &Case, spec: &HollowCylinder, ids: &BodyAndLoad) -> Result<HollowCylinderCheck, String> {
        let (young_modulus, poisson_ratio) = super::elastic_body(c, ids.body)?;
        let load = c.load(ids.load);
        let Some(traction) = load.traction() else {
            return Err(format!("`{}` is not a nodal_traction or particle_traction load", spec.load));
        };
        Ok(HollowCylinderCheck {
            body: ids.body.index() as u16,
            theory: FixedWallLame {
                a: spec.inner_radius,
                b: spec.outer_radius,
                p: traction[0].abs(),
                e: young_modulus,
                nu: poisson_ratio,
            },
            time_fn: super::load_time_fn(c, ids.load),
            factor: load.increment_factor().map(|e| (e.to_string(), c.parameters.clone())),
            tolerances: (spec.displacement_tolerance, spec.stress_tolerance),
            first: None,
            steps: spec.increments.map(|tolerances| Steps {
                tolerances,
                last: None,
                worst_q: (0.0, 0.0),
                worst_m: (0.0, 0.0),
                r_exact: f64::NAN,
                count: 0,
            }),
            last_row: [f64::NAN; 4],
            columns: None,
        })
    }

    /// The pressure at r = a of the original cylinder whose increment the load applies from time
    /// `t0` (its f = `f0`) to `t`, loaded where the faces are at `x` (g(a, y) × traction ×
    /// Δf; g ≡ 1 without an `increment_factor`).
    fn pressure(&self, f0: f64, t: f64, x: [f64; 2]) -> Result<f64, String> {
        let g = match &self.factor {
            Some((e, params)) => crate::model::loads::increment_factor(e, params, &[self.theory.a, x[1]])?,
            None => 1.0,
        };
        Ok(self.theory.p * (self.time_fn.eval(t) - f0) * g)
    }

    /// The metrics of the step-by-step comparison, if the case asks for it.
    fn step_metrics(&self) -> Vec<(String, Metric)> {
        let Some(s) = self.steps else { return Vec::new() };
        let Some((_, _, mp1)) = s.last else { return Vec::new() };
        let t = s.tolerances;
        let n = s.count;
        vec![
            (
                "dq_mp1_max_rel_error".into(),
                Metric::error(
                    s.worst_q.0,
                    t.q,
                    format!(
                        "largest relative error of Δq at mp1 over {n} steps (at t = {:.4e} s), against the closed form \
                         of the remaining cylinder at mp1's radius at each step's start",
                        s.worst_q.1
                    ),
                ),
            ),
            (
                "dsigma_m_mp1_max_error".into(),
                Metric::error(
                    s.worst_m.0,
                    t.mean_stress,
                    format!(
                        "largest error of Δσ_m at mp1 over {n} steps (at t = {:.4e} s), over the step's pressure at r = a",
                        s.worst_m.1
                    ),
                ),
            ),
            (
                "r_mp1_rel_error".into(),
                Metric::error(
                    (mp1.x[0] - s.r_exact).abs() / s.r_exact,
                    t.radius,
                    format!(
                        "mp1's radius after {n} steps {:.5} m against the closed-form path r_(k+1) = r_k + u_r(r_k) {:.5} m",
                        mp1.x[0], s.r_exact
                    ),
                ),
            ),
        ]
    }

    /// The radii at t = 0 of the two innermost columns of points (collective; the same for the
    /// whole run, found once).
    fn find_columns(&mut self, model: &Model, coll: &Collective) -> Result<[f64; 2], String> {
        if let Some(c) = self.columns {
            return Ok(c);
        }
        let ps = &model.particles;
        let r0: Vec<f64> = (0..ps.len()).filter(|&k| ps.body[k] == self.body).map(|k| ps.x0[k][0]).collect();
        let tol = 1e-9 * self.theory.b;
        let first = -coll.max(&[r0.iter().map(|r| -r).fold(f64::NEG_INFINITY, f64::max)])?[0];
        let beyond = r0.iter().filter(|&&r| r > first + tol);
        let second = -coll.max(&[beyond.map(|r| -r).fold(f64::NEG_INFINITY, f64::max)])?[0];
        self.columns = Some([first, second]);
        Ok([first, second])
    }

    /// The innermost column of points (radius `first` at t = 0) now: mean stress and position
    /// (collective).
    fn mp1(&self, first: f64, model: &Model, coll: &Collective) -> Result<Mp1, String> {
        let ps = &model.particles;
        let mine: Vec<usize> = (0..ps.len()).filter(|&k| ps.body[k] == self.body).collect();
        let tol = 1e-9 * self.theory.b;
        let mut local = [0.0; 7];
        for &k in mine.iter().filter(|&&k| (ps.x0[k][0] - first).abs() <= tol) {
            for (l, v) in local.iter_mut().zip(ps.stress[k]) {
                *l += v;
            }
            local[4] += ps.x[k][0];
            local[5] += ps.x[k][1];
            local[6] += 1.0;
        }
        let s = coll.sum(&local)?;
        let n = s[6].max(1.0);
        Ok(Mp1 { stress: [s[0] / n, s[1] / n, s[2] / n, s[3] / n], x: [s[4] / n, s[5] / n] })
    }

    /// Compares the step from the last observed time to `t` (mp1 now `now`) with the closed form
    /// of the remaining cylinder at mp1's radius at the step's start.
    fn compare_step(&mut self, t: f64, now: Mp1) -> Result<(), String> {
        let Some(steps) = self.steps else { return Ok(()) };
        let f_now = self.time_fn.eval(t);
        // The same state seen again (a restart observes its checkpoint's state): nothing to compare.
        if steps.last.is_some_and(|(t0, _, _)| t <= t0) {
            return Ok(());
        }
        let Some((_, f0, before)) = steps.last else {
            self.steps = Some(Steps { last: Some((t, f_now, now)), r_exact: now.x[0], ..steps });
            return Ok(());
        };
        let p = self.pressure(f0, t, before.x)?;
        let theory = FixedWallLame { p, ..self.theory };
        let (_, rr_star, tt_star, yy_star) = theory.at(before.x[0]);
        let (u_path, ..) = theory.at(steps.r_exact);
        let q_star = von_mises(rr_star, tt_star, yy_star, 0.0);
        let d: Vec<f64> = (0..4).map(|c| now.stress[c] - before.stress[c]).collect();
        // Compression positive: radial xx, axial yy, shear xy, hoop zz.
        let (rr, yy, ry, tt) = (-d[0], -d[1], -d[2], -d[3]);
        let q = von_mises(rr, tt, yy, ry);
        let m = (rr + yy + tt) / 3.0;
        let mut next = steps;
        next.last = Some((t, f_now, now));
        next.r_exact = steps.r_exact + u_path;
        next.count += 1;
        if p.abs() > 0.0 {
            let eq = (q - q_star).abs() / q_star.abs();
            let em = (m - theory.mean_stress()).abs() / p.abs();
            if eq > next.worst_q.0 {
                next.worst_q = (eq, t);
            }
            if em > next.worst_m.0 {
                next.worst_m = (em, t);
            }
            self.last_row = [q, q_star, m, now.x[0]];
        }
        self.steps = Some(next);
        Ok(())
    }

    /// The increment of the state at time `t` from the unloaded start (collective); `y` is where
    /// the load's `increment_factor` is evaluated, at r = a.
    fn increment(&self, t: f64, y: f64, model: &Model, coll: &Collective) -> Result<Increment, String> {
        let ps = &model.particles;
        let theory = FixedWallLame { p: self.pressure(0.0, t, [self.theory.a, y])?, ..self.theory };
        let mine: Vec<usize> = (0..ps.len()).filter(|&k| ps.body[k] == self.body).collect();
        let tol = 1e-9 * theory.b;
        let [first, second] = self.columns.ok_or("the hollow cylinder's columns are not known yet")?;
        // [n₁, Σu₁, n₂, Σu₂, Σσ_rr, Σσ_m, Σq over column 1, Σ V e², Σ V]
        let mut local = [0.0; 9];
        for &k in &mine {
            let r0 = ps.x0[k][0];
            let s = ps.stress[k];
            let (rr, yy, tt) = (-s[0], -s[1], -s[3]);
            for (col, at) in [(0, first), (2, second)] {
                if (r0 - at).abs() <= tol {
                    local[col] += 1.0;
                    local[col + 1] += ps.disp[k][0];
                }
            }
            if (r0 - first).abs() <= tol {
                let m = (rr + yy + tt) / 3.0;
                let q = von_mises(rr, tt, yy, s[2]);
                local[4] += rr;
                local[5] += m;
                local[6] += q;
            }
            let (_, srr, _, _) = theory.at(r0);
            local[7] += ps.volume[k] * ((rr - srr) / srr).powi(2);
            local[8] += ps.volume[k];
        }
        let s = coll.sum(&local)?;
        if s[0] == 0.0 || s[2] == 0.0 {
            return Err("the hollow cylinder's check needs two columns of points in its body".into());
        }
        let (u1, u2) = (s[1] / s[0], s[3] / s[2]);
        let u_inner = u1 + (u2 - u1) * (theory.a - first) / (second - first);
        Ok(Increment {
            u_inner,
            mp1: [s[4] / s[0], s[5] / s[0], s[6] / s[0], first],
            rms: (s[7] / s[8]).sqrt(),
            p: theory.p,
            t,
        })
    }
}

impl Check for HollowCylinderCheck {
    fn columns(&self) -> Vec<String> {
        ["u_inner", "sigma_rr_mp1", "dq_mp1", "dq_mp1_exact", "dsigma_m_mp1", "r_mp1"]
            .map(|c| format!("cylinder.{c}"))
            .to_vec()
    }

    fn observe(&mut self, t: f64, _dt: f64, model: &Model, coll: &Collective) -> Result<Vec<f64>, String> {
        let [first, _] = self.find_columns(model, coll)?;
        let mp1 = self.mp1(first, model, coll)?;
        let inc = self.increment(t, mp1.x[1], model, coll)?;
        // The initial state (t = 0) is observed too; the first increment is the first step's.
        if t > 0.0 {
            self.first.get_or_insert(inc);
        }
        self.compare_step(t, mp1)?;
        let r = self.last_row;
        Ok(vec![inc.u_inner, inc.mp1[0], r[0], r[1], r[2], r[3]])
    }

    fn finish(&mut self, _model: &Model, _coll: &Collective) -> Result<Findings, String> {
        let Some(inc) = self.first else {
            return Err("the hollow cylinder's check saw no load step".into());
        };
        let theory = FixedWallLame { p: inc.p, ..self.theory };
        let (u_star, ..) = theory.at(theory.a);
        let (_, srr_star, ..) = theory.at(inc.mp1[3]);
        let where_ = format!(
            "after the first load step (t = {:.4e} s, p = {:.4e} Pa; a = {} m, b = {} m, ν = {})",
            inc.t, inc.p, theory.a, theory.b, theory.nu
        );
        let rel = |x: f64, star: f64| (x - star).abs() / star.abs().max(f64::MIN_POSITIVE);
        Ok((
            vec![
                (
                    "u_inner_rel_error".into(),
                    Metric::error(
                        rel(inc.u_inner, u_star),
                        self.tolerances.0,
                        format!("u_r(a) = {:.6e} m vs Lamé {u_star:.6e} m {where_}", inc.u_inner),
                    ),
                ),
                (
                    "sigma_rr_mp1_rel_error".into(),
                    Metric::error(
                        rel(inc.mp1[0], srr_star),
                        self.tolerances.1,
                        format!(
                            "Δσ_rr at the innermost points (r = {:.4} m) {:.6e} Pa vs Lamé {srr_star:.6e} Pa {where_}",
                            inc.mp1[3], inc.mp1[0]
                        ),
                    ),
                ),
                (
                    "sigma_rr_rms_rel_error".into(),
                    Metric::error(inc.rms, self.tolerances.1, format!("volume-weighted RMS over the body {where_}")),
                ),
            ]
            .into_iter()
            .chain(self.step_metrics())
            .collect(),
            Vec::new(),
        ))
    }

    fn results(&self) -> Vec<(String, f64)> {
        let Some(inc) = self.first else { return Vec::new() };
        let steps: Vec<(String, f64)> = match self.steps {
            Some(Steps { last: Some((_, _, mp1)), r_exact, count, .. }) => vec![
                ("steps_compared".into(), count as f64),
                ("r_mp1_final".into(), mp1.x[0]),
                ("r_mp1_exact_final".into(), r_exact),
            ],
            _ => Vec::new(),
        };
        let theory = FixedWallLame { p: inc.p, ..self.theory };
        let per_100kpa = 1.0e5 / inc.p;
        vec![
            ("u_inner_per_100kPa".into(), inc.u_inner * per_100kpa),
            ("sigma_rr_mp1_per_100kPa".into(), inc.mp1[0] * per_100kpa),
            ("sigma_m_mp1_per_100kPa".into(), inc.mp1[1] * per_100kpa),
            ("q_mp1_per_100kPa".into(), inc.mp1[2] * per_100kpa),
            ("sigma_m_exact_per_100kPa".into(), theory.mean_stress() * per_100kpa),
        ]
        .into_iter()
        .chain(steps)
        .collect()
    }

    fn checkpoint_state(&self, _model: &Model, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        // [8 values of the first increment, or 8 NaN] [18 values of the step comparison, if any].
        let mut v = match self.first {
            Some(i) => vec![i.u_inner, i.mp1[0], i.mp1[1], i.mp1[2], i.mp1[3], i.rms, i.p, i.t],
            None => vec![f64::NAN; 8],
        };
        if let Some(s) = self.steps {
            let (t, f, m) = s.last.unwrap_or((f64::NAN, f64::NAN, Mp1::default()));
            v.extend([t, f]);
            v.extend(m.stress);
            v.extend(m.x);
            v.extend([s.worst_q.0, s.worst_q.1, s.worst_m.0, s.worst_m.1, s.r_exact, s.count as f64]);
            v.extend(self.last_row);
        }
        Ok(Some(v))
    }

    fn restore_state(&mut self, state: &[f64], _model: &Model) -> Result<(), String> {
        let expected = if self.steps.is_some() { 26 } else { 8 };
        if state.len() != expected {
            return Err(format!("the hollow cylinder's check state has {expected} values, not {}", state.len()));
        }
        self.first = match state[..8] {
            [u, a, b, c, d, rms, p, t] if !u.is_nan() => Some(Increment { u_inner: u, mp1: [a, b, c, d], rms, p, t }),
            _ => None,
        };
        if let Some(steps) = self.steps.as_mut() {
            let v = &state[8..];
            let mp1 = Mp1 { stress: [v[2], v[3], v[4], v[5]], x: [v[6], v[7]] };
            steps.last = (!v[0].is_nan()).then_some((v[0], v[1], mp1));
            steps.worst_q = (v[8], v[9]);
            steps.worst_m = (v[10], v[11]);
            steps.r_exact = v[12];
            steps.count = v[13] as usize;
            self.last_row = [v[14], v[15], v[16], v[17]];
        }
        Ok(())
    }
}

/// The von Mises stress √(3 J₂) of (σ_rr, σ_θθ, σ_yy, σ_ry).
fn von_mises(rr: f64, tt: f64, yy: f64, ry: f64) -> f64 {
    (0.5 * ((rr - tt).powi(2) + (tt - yy).powi(2) + (yy - rr).powi(2)) + 3.0 * ry * ry).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [001]'s constants A and C follow, with the closed form's values at r = a and its mean
    /// stress, and the solution meets its boundary conditions and Hooke's law in axial symmetry
    /// with ε_yy = 0.
    #[test]
    fn the_closed_form_has_the_paper_s_constants_and_meets_its_conditions() {
        let l = FixedWallLame { a: 0.5, b: 1.5, p: 100.0, e: 1000.0, nu: 0.3 };
        let (a, c) = l.constants();
        assert!((a - 19.5652).abs() < 1e-4 && (c - 10.8696).abs() < 1e-4, "A = {a}, C = {c}");
        assert!((l.at(0.5).0 - 0.045217).abs() < 1e-6);
        assert!((l.at(0.5).1 - 100.0).abs() < 1e-9 && l.at(1.5).0.abs() < 1e-12);
        assert!((l.mean_stress() - 18.841).abs() < 1e-3);
        let lam = l.e * l.nu / ((1.0 + l.nu) * (1.0 - 2.0 * l.nu));
        let g = l.e / (2.0 * (1.0 + l.nu));
        let (r, h) = (0.8, 1e-6);
        let (u, srr, stt, syy) = l.at(r);
        let dudr = (l.at(r + h).0 - l.at(r - h).0) / (2.0 * h);
        // Compression positive: σ = −(λ tr ε I + 2μ ε).
        assert!((-(lam * (dudr + u / r) + 2.0 * g * dudr) - srr).abs() < 1e-6);
        assert!((-(lam * (dudr + u / r) + 2.0 * g * u / r) - stt).abs() < 1e-6);
        assert!((-(lam * (dudr + u / r)) - syy).abs() < 1e-6);
    }
}
