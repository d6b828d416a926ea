//! The consolidating column, against Terzaghi ([003] §4.1.1, `kind = "terzaghi"`) or, at large
//! strain, against Xie & Leo (2004; [003] §4.2, `kind = "large_strain_consolidation"`).
//!
//! `e_p_Tv<T>` is [003] Eq. 33, sqrt(Σ (P*−P)²)/N over the particles of the column (note: divided
//! by N, not √N), with P = p/q; `p_rms_error_Tv<T>` is the plain RMS sqrt(Σ (P*−P)²/N) at every
//! T_v; `settlement_rel_error_Tv<T>` (at the last T_v) compares the settlement with Terzaghi's.
//! The settlement of the laterally confined column is its loss of volume per unit width,
//! (Σ V₀ − Σ V)/w, which follows every particle's J. The analytical P* is evaluated at each
//! particle's initial depth below the drained top, at the time the run reaches T_v (the time
//! stepping lands on it exactly). The large-strain column reports the same metrics at degrees of
//! consolidation U_s (`e_p_Us<U>`, ...).

use super::{
    all_positive, figures, load_factor, terzaghi, xie_leo, BodyAndLoad, BuiltCheck, Check, CheckParameters, Column,
    Findings, FormulationNeed, Metric,
};
use crate::case::{Case, ConductivityLaw, Formulation};
use crate::check::{at, Checked};
use crate::model::Model;
use crate::parallel::Collective;
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "terzaghi"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TerzaghiConsolidation {
    /// The name of the consolidating body (its height is the drainage length; drained at its top).
    pub body: String,
    /// The name of the surface load, a particle or nodal traction (its final magnitude is q).
    pub load: String,
    /// Time factors T_v [-] at which e_p is evaluated, each > 0 (the last one also gives the RMS
    /// and settlement errors; default [0.1, 0.5]).
    #[serde(default = "default_tv")]
    pub time_factors: Vec<f64>,
    /// Pass threshold for e_p ([003] Eq. 33) [-], in (0, 1] (default 0.01).
    #[serde(default = "default_ep_tol")]
    pub e_p_tolerance: f64,
    /// Pass threshold for the plain RMS of the normalised pressure error [-], in (0, 1] (default 0.05).
    #[serde(default = "default_rms_tol")]
    pub p_rms_tolerance: f64,
    /// Pass threshold for the relative settlement error [-], in (0, 1] (default 0.05).
    #[serde(default = "default_settle_tol")]
    pub settlement_tolerance: f64,
}

/// The parameters of `kind = "large_strain_consolidation"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LargeStrainConsolidation {
    /// The name of the consolidating column (drained at its top; its material has
    /// `hydraulic_conductivity_law = "xie_leo"`).
    pub body: String,
    /// The name of the surface load, a particle or nodal traction (its final magnitude is q).
    pub load: String,
    /// Degrees of consolidation U_s [-], each in (0, 1), at which the metrics are evaluated
    /// (default [0.5]).
    #[serde(default = "default_us")]
    pub degrees: Vec<f64>,
    /// Pass threshold for e_p ([003] Eq. 33) [-], in (0, 1] (default 0.01).
    #[serde(default = "default_ep_tol")]
    pub e_p_tolerance: f64,
    /// Pass threshold for the plain RMS of the normalised pressure error [-], in (0, 1] (default 0.05).
    #[serde(default = "default_rms_tol")]
    pub p_rms_tolerance: f64,
    /// Pass threshold for the relative settlement error [-], in (0, 1] (default 0.03).
    #[serde(default = "default_ls_settle_tol")]
    pub settlement_tolerance: f64,
}

serde_defaults! {
    default_tv: Vec<f64> = vec![0.1, 0.5],
    default_ep_tol: f64 = 1e-2,
    default_rms_tol: f64 = 5e-2,
    default_settle_tol: f64 = 5e-2,
    default_us: Vec<f64> = vec![0.5],
    default_ls_settle_tol: f64 = 0.03,
}

/// What the consolidation and wave references need of the analysis.
pub(super) const TWO_PHASE: FormulationNeed =
    Some((Formulation::TwoPhase, "the consolidation and wave references need a two_phase analysis"));

impl CheckParameters for TerzaghiConsolidation {
    type Ids = BodyAndLoad;
    const FORMULATION: FormulationNeed = TWO_PHASE;
    const SOLID: bool = true;
    const AXISYMMETRIC: bool = true;

    fn check(&self, key: &str) -> Checked {
        if self.time_factors.is_empty() || self.time_factors.iter().any(|t| !(*t > 0.0 && t.is_finite())) {
            return Err(format!("key `{}`: give positive time factors", at(key, "time_factors")));
        }
        let (e, r, s) = (self.e_p_tolerance, self.p_rms_tolerance, self.settlement_tolerance);
        all_positive(key, &[("e_p_tolerance", e), ("p_rms_tolerance", r), ("settlement_tolerance", s)])
    }

    fn describe(&self) -> String {
        format!("Terzaghi consolidation at T_v = {:?}", self.time_factors)
    }

    fn link(&self, c: &Case) -> Result<BodyAndLoad, String> {
        BodyAndLoad::plain(c, &self.body, &self.load)
    }

    fn plane(&self, c: &Case, ids: &BodyAndLoad, model: &Model, coll: &Collective) -> BuiltCheck {
        Ok(Box::new(self.column(c, ids, model, coll)?))
    }

    fn solid(&self, c: &Case, ids: &BodyAndLoad, model: &Model<3>, coll: &Collective) -> BuiltCheck<3> {
        Ok(Box::new(self.column(c, ids, model, coll)?))
    }
}

impl TerzaghiConsolidation {
    /// The consolidating column of the case, in any dimension (collective).
    fn column<const D: usize>(
        &self,
        c: &Case,
        ids: &BodyAndLoad,
        model: &Model<D>,
        coll: &Collective,
    ) -> Result<ConsolidationCheck, String> {
        let col = Column::from_case(c, model, ids)?;
        let theory = terzaghi::Terzaghi::new(
            col.load * load_factor(c, ids.load, c.end_time()).abs(),
            col.height,
            col.constrained_modulus,
            col.inv_q,
            col.conductivity,
            col.water_density * col.g,
        );
        theory.validate()?;
        let last = self.time_factors.len();
        let targets = (self.time_factors.iter().enumerate())
            .map(|(i, &tv)| Target::new(format!("Tv{}", tv_name(tv)), theory.time_for(tv), i + 1 == last))
            .collect();
        let tol = (self.e_p_tolerance, self.p_rms_tolerance, self.settlement_tolerance);
        ConsolidationCheck::new(col, Theory::Terzaghi(theory), targets, tol, model, coll)
    }
}

impl CheckParameters for LargeStrainConsolidation {
    type Ids = BodyAndLoad;
    const FORMULATION: FormulationNeed = TWO_PHASE;

    fn check(&self, key: &str) -> Checked {
        if self.degrees.is_empty() || self.degrees.iter().any(|u| !(*u > 0.0 && *u < 1.0)) {
            return Err(format!("key `{}`: give degrees of consolidation in (0, 1)", at(key, "degrees")));
        }
        let (e, r, s) = (self.e_p_tolerance, self.p_rms_tolerance, self.settlement_tolerance);
        all_positive(key, &[("e_p_tolerance", e), ("p_rms_tolerance", r), ("settlement_tolerance", s)])
    }

    fn describe(&self) -> String {
        format!("large-strain consolidation (Xie & Leo 2004) at U_s = {:?}", self.degrees)
    }

    fn link(&self, c: &Case) -> Result<BodyAndLoad, String> {
        let ids = BodyAndLoad::plain(c, &self.body, &self.load)?;
        if c.material_of(ids.body).hydraulic_conductivity_law != ConductivityLaw::XieLeo {
            return Err(format!(
                "key `verification.body`: the large-strain reference assumes hydraulic_conductivity_law = \"xie_leo\" \
                 for the material of `{}`",
                c.body(ids.body).name
            ));
        }
        Ok(ids)
    }

    fn plane(&self, c: &Case, ids: &BodyAndLoad, model: &Model, coll: &Collective) -> BuiltCheck {
        let col = Column::from_case(c, model, ids)?;
        let theory = xie_leo::XieLeo {
            load: col.load * load_factor(c, ids.load, c.end_time()).abs(),
            height: col.height,
            m_v: 1.0 / col.constrained_modulus,
            conductivity: col.conductivity,
            water_unit_weight: col.water_density * col.g,
        };
        theory.validate()?;
        let targets = (self.degrees.iter())
            .map(|&u| Target::new(format!("Us{}", tv_name(u)), theory.time_for_degree(u), true))
            .collect();
        let tol = (self.e_p_tolerance, self.p_rms_tolerance, self.settlement_tolerance);
        Ok(Box::new(ConsolidationCheck::new(col, Theory::XieLeo(theory), targets, tol, model, coll)?))
    }
}

/// Format of a time factor in metric names (`0.1`, `0.5`).
fn tv_name(tv: f64) -> String {
    format!("{tv}")
}

/// The consolidation theory a [`ConsolidationCheck`] compares with.
enum Theory {
    /// Small strain, compressible pore fluid.
    Terzaghi(terzaghi::Terzaghi),
    /// Large strain (Xie & Leo 2004).
    XieLeo(xie_leo::XieLeo),
}

impl Theory {
    fn load(&self) -> f64 {
        match self {
            Theory::Terzaghi(t) => t.load,
            Theory::XieLeo(x) => x.load,
        }
    }
    fn pressure(&self, depth: f64, t: f64) -> f64 {
        match self {
            Theory::Terzaghi(th) => th.pressure(depth, t),
            Theory::XieLeo(x) => x.pressure(depth, t),
        }
    }
    fn settlement(&self, t: f64) -> f64 {
        match self {
            Theory::Terzaghi(th) => th.settlement(t),
            Theory::XieLeo(x) => x.settlement(t),
        }
    }
    fn degree(&self, t: f64) -> f64 {
        match self {
            Theory::Terzaghi(th) => th.degree_of_consolidation(t),
            Theory::XieLeo(x) => x.degree_of_consolidation(t),
        }
    }
    fn time_factor(&self, t: f64) -> f64 {
        match self {
            Theory::Terzaghi(th) => th.time_factor(t),
            Theory::XieLeo(x) => x.cv() * t / (x.height * x.height),
        }
    }
    fn name(&self) -> &'static str {
        match self {
            Theory::Terzaghi(_) => "Terzaghi",
            Theory::XieLeo(_) => "Xie & Leo",
        }
    }
}

/// A time at which a consolidation check evaluates its metrics.
struct Target {
    /// Suffix of the metric names (`Tv0.1`, `Us0.5`).
    label: String,
    /// Time [s].
    t: f64,
    /// Whether the RMS and settlement errors are reported at this time too.
    full: bool,
    /// (e_p, rms, settlement error, settlement) once the run has passed the time.
    result: Option<(f64, f64, f64, f64)>,
    /// (initial depth, p/q) of every particle of the column at that time.
    profile: Vec<(f64, f64)>,
}

impl Target {
    /// The time `t` [s] labelled `label`, with the RMS and settlement errors if `full`.
    fn new(label: String, t: f64, full: bool) -> Target {
        Target { label, t, full, result: None, profile: Vec::new() }
    }
}

/// Consolidation of a column (Terzaghi, or large strain after Xie & Leo), compared at given times.
pub struct ConsolidationCheck {
    col: Column,
    theory: Theory,
    prefix: &'static str,
    targets: Vec<Target>,
    tolerances: (f64, f64, f64),
    volume0: f64,
    /// (t, settlement, reference settlement) after every step.
    history: Vec<(f64, f64, f64)>,
}

impl ConsolidationCheck {
    fn new<const D: usize>(
        col: Column,
        theory: Theory,
        targets: Vec<Target>,
        tolerances: (f64, f64, f64),
        model: &Model<D>,
        coll: &Collective,
    ) -> Result<Self, String> {
        let v0: f64 = col.particles(model).map(|k| model.particles.volume[k]).sum();
        let volume0 = coll.sum(&[v0])?[0];
        let prefix = match theory {
            Theory::Terzaghi(_) => "terzaghi",
            Theory::XieLeo(_) => "large_strain",
        };
        Ok(ConsolidationCheck { col, theory, prefix, targets, tolerances, volume0, history: Vec::new() })
    }

    fn settlement<const D: usize>(&self, model: &Model<D>, coll: &Collective) -> Result<f64, String> {
        let v: f64 = self.col.particles(model).map(|k| model.particles.volume[k]).sum();
        Ok((self.volume0 - coll.sum(&[v])?[0]) / self.col.width)
    }
}

impl<const D: usize> Check<D> for ConsolidationCheck {
    fn columns(&self) -> Vec<String> {
        ["Tv", "settlement", "settlement_analytical", "U_analytical"]
            .iter()
            .map(|c| format!("{}.{c}", self.prefix))
            .collect()
    }

    fn event_times(&self) -> Vec<f64> {
        self.targets.iter().map(|t| t.t).collect()
    }

    fn observe(&mut self, t: f64, _dt: f64, model: &Model<D>, coll: &Collective) -> Result<Vec<f64>, String> {
        let s = self.settlement(model, coll)?;
        let q = self.theory.load();
        for i in 0..self.targets.len() {
            let tt = self.targets[i].t;
            if (t - tt).abs() <= 1e-9 * tt {
                let local: Vec<f64> = self
                    .col
                    .particles(model)
                    .flat_map(|k| [self.col.top - model.particles.x0[k][1], model.particles.p[k]])
                    .collect();
                let all = coll.gather(&local)?;
                let n = all.len() / 2;
                let sq: f64 = all.chunks(2).map(|d| (self.theory.pressure(d[0], t) / q - d[1] / q).powi(2)).sum();
                let s_ana = self.theory.settlement(t);
                self.targets[i].result =
                    Some((sq.sqrt() / n as f64, (sq / n as f64).sqrt(), (s - s_ana).abs() / s_ana.abs(), s));
                self.targets[i].profile = all.chunks(2).map(|d| (d[0], d[1] / q)).collect();
            }
        }
        self.history.push((t, s, self.theory.settlement(t)));
        Ok(vec![self.theory.time_factor(t), s, self.theory.settlement(t), self.theory.degree(t)])
    }

    fn checkpoint_state(&self, _model: &Model<D>, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        Ok(Some(
            self.targets
                .iter()
                .flat_map(|t| match t.result {
                    Some((a, b, c, d)) => [1.0, a, b, c, d],
                    None => [0.0; 5],
                })
                .collect(),
        ))
    }

    fn restore_state(&mut self, state: &[f64], _model: &Model<D>) -> Result<(), String> {
        if state.len() != 5 * self.targets.len() {
            return Err(format!("{} values for {} consolidation targets", state.len(), self.targets.len()));
        }
        for (t, r) in self.targets.iter_mut().zip(state.chunks(5)) {
            t.result = (r[0] > 0.5).then_some((r[1], r[2], r[3], r[4]));
        }
        Ok(())
    }

    fn finish(&mut self, _model: &Model<D>, _coll: &Collective) -> Result<Findings, String> {
        let (ep_tol, rms_tol, s_tol) = self.tolerances;
        let mut out = Vec::new();
        for tg in &self.targets {
            let missing = || format!("{} (t = {:.6e} s) was not reached by the run", tg.label, tg.t);
            let (e_p, rms, se) = match tg.result {
                Some((e_p, rms, se, s)) => (
                    Metric::error(
                        e_p,
                        ep_tol,
                        format!("[003] Eq. 33 over the column's particles at t = {:.6e} s", tg.t),
                    ),
                    Metric::error(rms, rms_tol, "RMS of (P* - P) over particles, P = p/q".into()),
                    Metric::error(
                        se,
                        s_tol,
                        format!(
                            "settlement {s:.6e} m vs {} {:.6e} m",
                            self.theory.name(),
                            self.theory.settlement(tg.t)
                        ),
                    ),
                ),
                None => (
                    Metric::error(f64::NAN, ep_tol, missing()),
                    Metric::error(f64::NAN, rms_tol, missing()),
                    Metric::error(f64::NAN, s_tol, missing()),
                ),
            };
            out.push((format!("e_p_{}", tg.label), e_p));
            // The RMS over the particles (not divided by their number) beside e_p at every time:
            // e_p falls as 1/√N with the particle count for the same pointwise error.
            out.push((format!("p_rms_error_{}", tg.label), rms));
            if tg.full {
                out.push((format!("settlement_rel_error_{}", tg.label), se));
            }
        }
        Ok((out, Vec::new()))
    }

    fn figures(&self) -> Vec<crate::plot::Figure> {
        let q = self.theory.load();
        let h = self.col.height;
        let (what, stem, depth) = match self.theory {
            Theory::Terzaghi(_) => ("Terzaghi consolidation", "terzaghi", "depth below the drained top [m]"),
            Theory::XieLeo(_) => {
                ("Large-strain consolidation", "large_strain", "initial depth below the drained top [m]")
            }
        };
        let profiles: Vec<_> = self
            .targets
            .iter()
            .filter(|tg| !tg.profile.is_empty())
            .map(|tg| {
                let label = format!(
                    "{} (t = {:.4e} s)",
                    tg.label.replacen("Tv", "T_v = ", 1).replacen("Us", "U_s = ", 1),
                    tg.t
                );
                let depths = figures::sample(0.0, h, 200, |d| d);
                let ana = depths.iter().map(|&d| (d, self.theory.pressure(d, tg.t) / q)).collect();
                (label, tg.profile.clone(), ana)
            })
            .collect();
        let computed: Vec<(f64, f64)> = self.history.iter().map(|r| (r.0, r.1)).collect();
        let reference: Vec<(f64, f64)> = self.history.iter().map(|r| (r.0, r.2)).collect();
        vec![
            figures::pressure_profiles(
                &format!("{stem}_pressure_profiles.png"),
                &format!("{what}: pore pressure profiles"),
                depth,
                self.theory.name(),
                &profiles,
            ),
            figures::settlement_history(
                &format!("{stem}_settlement.png"),
                &format!("{what}: settlement of the column"),
                &computed,
                Some((self.theory.name(), &reference)),
            ),
        ]
    }
}
