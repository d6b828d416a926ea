//! Verification: analytical references and the checks that compare a run with them.
//!
//! A [`Check`] watches the run after every converged step and computes its metrics from the run's
//! own particles at the end; nothing is copied from a table. The analytical solutions live in
//! [`terzaghi`], [`biot_harmonic`] and [`waves`], each with its own unit tests.
//!
//! * Terzaghi ([003] §4.1.1): `e_p_Tv<T>` is [003] Eq. 33, sqrt(Σ (P*−P)²)/N over the particles of
//!   the column (note: divided by N, not √N), with P = p/q; `p_rms_error_Tv<T>` is the plain RMS
//!   sqrt(Σ (P*−P)²/N) at every T_v; `settlement_rel_error_Tv<T>` (at the last T_v) compares the
//!   settlement with Terzaghi's. The
//!   settlement of the laterally confined column is its loss of volume per unit width,
//!   (Σ V₀ − Σ V)/w, which follows every particle's J. The analytical P* is evaluated at each
//!   particle's initial depth below the drained top, at the time the run reaches T_v (the time
//!   stepping lands on it exactly).
//! * Harmonic column ([003] §4.1.2): over the last `measure_periods` whole load periods each
//!   particle's pressure is projected on cos ωt and sin ωt with a Hann window w(t) = sin²(π(t−t₀)/T_w),
//!   A = 2 |∫ w p e^{-iωt} dt| / ∫ w dt. For a pure tone at ω over whole periods this is exact; free
//!   vibrations at other frequencies ω' leak into it only like 1/((ω'−ω)T_w)³ (a rectangular window
//!   leaks like 1/((ω'−ω)T_w)). `p_amplitude_max_rel_error` is max_z |A − A*| / max_z A* over the
//!   depth profile (particles at the same depth averaged).
//! * Shock wave ([003] §4.1.3): see [`shock`] for how arrival times are picked.

pub mod bearing;
pub mod biot_harmonic;
pub mod checkerboard;
pub mod cook;
pub mod dam_break;
pub mod elastic_column;
pub mod figures;
pub mod hollow_cylinder;
pub mod lame;
pub mod patch;
pub mod runout;
pub mod shock;
pub mod stiffness_map;
pub mod terzaghi;
pub mod vertical_cut;
pub mod waves;
pub mod xie_leo;

use crate::case::{
    self, BodyAndLoad, BodyId, Case, ConductivityLaw, LinkedVerification, LoadId, SoilModel, TimeFunction,
};
use crate::layout::Dim;
use crate::model::loads::TimeFn;
use crate::model::Model;
use crate::parallel::Collective;
use serde::Serialize;

/// One verification metric as written to `summary.json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Metric {
    /// The value computed from the run.
    pub value: f64,
    /// What it is compared with (0 for error measures).
    pub reference: f64,
    /// Largest accepted |value − reference|.
    pub tolerance: f64,
    /// Whether |value − reference| ≤ tolerance.
    pub pass: bool,
    /// What was measured, in words and numbers.
    pub detail: String,
}

impl Metric {
    /// An error measure (reference 0).
    pub fn error(value: f64, tolerance: f64, detail: String) -> Metric {
        Metric { value, reference: 0.0, tolerance, pass: value.is_finite() && value.abs() <= tolerance, detail }
    }
}

/// A table a check writes next to the summary (e.g. `amplitude_profile.csv`).
#[derive(Debug, Clone)]
pub struct Table {
    /// File name.
    pub name: String,
    /// Column names.
    pub header: Vec<&'static str>,
    /// Rows.
    pub rows: Vec<Vec<f64>>,
}

/// What a check reports at the end: named metrics, and tables to write.
pub type Findings = (Vec<(String, Metric)>, Vec<Table>);

/// A comparison of a run with an analytical solution, on a model of dimension D (two unless it
/// says otherwise; in three dimensions the checks of [`for_case_in`]).
pub trait Check<const D: usize = 2> {
    /// Extra `history.csv` columns this check fills after every step.
    fn columns(&self) -> Vec<String>;
    /// Times the time stepping must land on exactly.
    fn event_times(&self) -> Vec<f64>;
    /// Called after every converged step at time `t`; returns the values of [`Check::columns`].
    fn observe(&mut self, t: f64, dt: f64, model: &Model<D>, coll: &Collective) -> Result<Vec<f64>, String>;
    /// The metrics (name, metric) and tables at the end of the run.
    fn finish(&mut self, model: &Model<D>, coll: &Collective) -> Result<Findings, String>;
    /// Whether the check reads the nodal diagnostics K_mag and F^int_mag
    /// ([`Check::observe_nodes`]); the run then computes them after every step.
    fn needs_nodes(&self) -> bool {
        false
    }
    /// Called after every converged step, before [`Check::observe`], with each boundary's reaction
    /// on the material (D components per `Model::boundaries` entry, summed over ranks) [N per m in
    /// two dimensions, N in three].
    fn observe_reactions(&mut self, _reactions: &[[f64; D]]) {}
    /// Called after every converged step, before the particle update, with this rank's owned
    /// nodes (`crate::assembly::NodeBlock`, values per node as `crate::assembly::NODE_VALUES`
    /// says) when [`Check::needs_nodes`]; collective.
    fn observe_nodes(
        &mut self,
        _block: &crate::assembly::NodeBlock,
        _model: &Model<D>,
        _coll: &Collective,
    ) -> Result<(), String> {
        Ok(())
    }
    /// Some(reason) once the run has shown what the check needs and should end (completed).
    fn stop(&self) -> Option<String> {
        None
    }
    /// Quantities without a reference (summary.json `results`), available after [`Check::finish`].
    fn results(&self) -> Vec<(String, f64)> {
        Vec::new()
    }
    /// Figures comparing the run with the reference (drawn into `plots/`), available after
    /// [`Check::finish`].
    fn figures(&self) -> Vec<crate::plot::Figure> {
        Vec::new()
    }

    /// What the check has gathered so far, the same on every rank (a collective call), for a
    /// checkpoint; `None` if the check cannot keep it (a run restarted from the checkpoint then
    /// computes the check from the restart time on only).
    fn checkpoint_state(&self, _model: &Model<D>, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        Ok(None)
    }
    /// Continues from a [`Check::checkpoint_state`] of the same case, with this rank's particles
    /// already restored.
    fn restore_state(&mut self, _state: &[f64], _model: &Model<D>) -> Result<(), String> {
        Ok(())
    }
}

/// The Young's modulus [Pa] and Poisson's ratio of a linear elastic `body`, for the elastic
/// closed forms.
pub(crate) fn elastic_body(c: &Case, body: BodyId) -> Result<(f64, f64), String> {
    match &c.material_of(body).model {
        SoilModel::LinearElastic(e) => Ok((e.0.young_modulus, e.0.poisson_ratio)),
        _ => Err(format!("body `{}` is not linear elastic", c.body(body).name)),
    }
}

/// The time function of a load (a constant 1 if it names none).
pub(crate) fn load_time_fn(c: &Case, load: LoadId) -> TimeFn {
    TimeFn::scaling(c.load_time_function(load))
}

/// The value of a load's time function at time `t` (1 without one).
fn load_factor(c: &Case, load: LoadId, t: f64) -> f64 {
    load_time_fn(c, load).eval(t)
}

/// Geometry and soil of a loaded one-dimensional column, taken from the case.
#[derive(Debug, Clone)]
pub(crate) struct Column {
    pub body: u16,
    pub top: f64,
    pub height: f64,
    pub width: f64,
    pub x_centre: f64,
    pub load: f64,
    pub constrained_modulus: f64,
    pub inv_q: f64,
    pub porosity: f64,
    pub solid_density: f64,
    pub water_density: f64,
    pub water_bulk_modulus: f64,
    pub conductivity: f64,
    pub g: f64,
}

impl Column {
    /// The column of the body loaded by the load of `ids`; its cross-section is its width in the
    /// plane (per metre of thickness; a ring's area in axial symmetry) and its width times its
    /// depth along z in three dimensions.
    fn from_case<const D: usize>(c: &Case, model: &Model<D>, ids: &BodyAndLoad) -> Result<Column, String> {
        let b = c.body(ids.body);
        let (lo, hi) = b.shape.bounds();
        let load = c.load(ids.load);
        let Some(traction) = load.traction() else {
            return Err(format!("verification load `{}` must be a particle_traction or nodal_traction", load.name()));
        };
        let mat = &model.materials[c.material_id_of(ids.body).index()];
        Ok(Column {
            body: ids.body.index() as u16,
            top: hi[1],
            height: hi[1] - lo[1],
            width: model.geometry.plan_area(lo[0], hi[0])
                * if D == 3 {
                    let [z0, z1] = c.body_depth(b);
                    z1 - z0
                } else {
                    1.0
                },
            x_centre: 0.5 * (lo[0] + hi[0]),
            load: traction[1].abs(),
            constrained_modulus: mat.model.elastic().constrained_modulus(),
            inv_q: mat.inv_q,
            porosity: mat.porosity,
            solid_density: mat.solid_density,
            water_density: mat.water_density,
            water_bulk_modulus: mat.water_bulk_modulus,
            conductivity: mat.conductivity,
            g: model.g,
        })
    }

    /// Local indices of the column's particles.
    fn particles<'a, const D: usize>(&'a self, model: &'a Model<D>) -> impl Iterator<Item = usize> + 'a {
        (0..model.particles.len()).filter(move |&k| model.particles.body[k] == self.body)
    }
}

/// The checks a case of dimension D may ask for: every check in the plane ([`for_case`]); in
/// three dimensions those validation lets a three-dimensional case ask for (the consolidating
/// column against Terzaghi, the bearing capacity, the run-out and the patch test).
pub trait CaseChecks<const D: usize> {
    /// The check the case asks for, if any (collective).
    fn for_case(c: &Case, model: &Model<D>, coll: &Collective) -> Result<Option<Box<dyn Check<D>>>, String>;
}

impl CaseChecks<2> for Dim<2> {
    fn for_case(c: &Case, model: &Model, coll: &Collective) -> Result<Option<Box<dyn Check>>, String> {
        for_case(c, model, coll)
    }
}

impl CaseChecks<3> for Dim<3> {
    fn for_case(c: &Case, model: &Model<3>, coll: &Collective) -> Result<Option<Box<dyn Check<3>>>, String> {
        use LinkedVerification as V;
        Ok(Some(match c.linked_verification() {
            None => return Ok(None),
            Some(V::Terzaghi(t, ids)) => Box::new(terzaghi_check(c, model, coll, t, ids)?),
            Some(V::BearingCapacity(b, ids)) => Box::new(bearing::BearingCheck::new(c, model, coll, b, ids)?),
            Some(V::Runout(r, ids)) => Box::new(runout::RunoutCheck::new(c, model, coll, r, ids)?),
            Some(V::Patch(p, ids)) => Box::new(patch::PatchCheck::new(c, model, p, ids)?),
            Some(_) => {
                let kind = c.verification.as_ref().map_or("", |v| v.kind());
                return Err(format!("the `{kind}` check is two-dimensional"));
            }
        }))
    }
}

/// The check the case asks for in dimension D ([`CaseChecks`]).
pub fn for_case_in<const D: usize>(
    c: &Case,
    model: &Model<D>,
    coll: &Collective,
) -> Result<Option<Box<dyn Check<D>>>, String>
where
    Dim<D>: CaseChecks<D>,
{
    <Dim<D> as CaseChecks<D>>::for_case(c, model, coll)
}

/// The consolidating column of the case's `terzaghi` verification, in any dimension.
fn terzaghi_check<const D: usize>(
    c: &Case,
    model: &Model<D>,
    coll: &Collective,
    spec: &case::Terzaghi,
    ids: &BodyAndLoad,
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
    let targets = spec
        .time_factors
        .iter()
        .enumerate()
        .map(|(i, &tv)| Target {
            label: format!("Tv{}", tv_name(tv)),
            t: theory.time_for(tv),
            full: i + 1 == spec.time_factors.len(),
            result: None,
            profile: Vec::new(),
        })
        .collect();
    let tol = (spec.e_p_tolerance, spec.p_rms_tolerance, spec.settlement_tolerance);
    ConsolidationCheck::new(col, Theory::Terzaghi(theory), targets, tol, model, coll)
}

/// The large-strain column of the case's `large_strain_consolidation` verification.
fn large_strain_check(
    c: &Case,
    model: &Model,
    coll: &Collective,
    spec: &case::LargeStrainConsolidation,
    ids: &BodyAndLoad,
) -> Result<ConsolidationCheck, String> {
    let col = Column::from_case(c, model, ids)?;
    if c.material_of(ids.body).hydraulic_conductivity_law != ConductivityLaw::XieLeo {
        return Err(format!(
            "the large-strain reference assumes hydraulic_conductivity_law = \"xie_leo\" for the material of `{}`",
            c.body(ids.body).name
        ));
    }
    let theory = xie_leo::XieLeo {
        load: col.load * load_factor(c, ids.load, c.end_time()).abs(),
        height: col.height,
        m_v: 1.0 / col.constrained_modulus,
        conductivity: col.conductivity,
        water_unit_weight: col.water_density * col.g,
    };
    theory.validate()?;
    let targets = spec
        .degrees
        .iter()
        .map(|&u| Target {
            label: format!("Us{}", tv_name(u)),
            t: theory.time_for_degree(u),
            full: true,
            result: None,
            profile: Vec::new(),
        })
        .collect();
    let tol = (spec.e_p_tolerance, spec.p_rms_tolerance, spec.settlement_tolerance);
    ConsolidationCheck::new(col, Theory::XieLeo(theory), targets, tol, model, coll)
}

/// The check the case asks for, if any.
pub fn for_case(c: &Case, model: &Model, coll: &Collective) -> Result<Option<Box<dyn Check>>, String> {
    use LinkedVerification as V;
    let Some(v) = c.linked_verification() else {
        return Ok(None);
    };
    Ok(Some(match v {
        V::Patch(p, ids) => Box::new(patch::PatchCheck::new(c, model, p, ids)?),
        V::Lame(l, ids) => Box::new(lame::LameCheck::new(c, l, ids)?),
        V::HollowCylinder(h, ids) => Box::new(hollow_cylinder::HollowCylinderCheck::new(c, h, ids)?),
        V::StiffnessMap(s, body) => Box::new(stiffness_map::StiffnessMapCheck::new(c, s, *body)?),
        V::VerticalCut(v, body) => Box::new(vertical_cut::VerticalCutCheck::new(c, v, *body)?),
        V::CookMembrane(m, body) => Box::new(cook::CookCheck::new(c, m, *body)),
        V::DamBreak(d, ids) => Box::new(dam_break::DamBreakCheck::new(c, model, coll, d, ids)?),
        V::Runout(r, ids) => Box::new(runout::RunoutCheck::new(c, model, coll, r, ids)?),
        V::Terzaghi(t, ids) => Box::new(terzaghi_check(c, model, coll, t, ids)?),
        V::LargeStrainConsolidation(x, ids) => Box::new(large_strain_check(c, model, coll, x, ids)?),
        V::HarmonicColumn(h, ids) => {
            let col = Column::from_case(c, model, ids)?;
            let Some(TimeFunction::Harmonic(f)) = c.load_time_function(ids.load) else {
                let name = c.load(ids.load).name();
                return Err(format!("verification load `{name}` must have a harmonic time function"));
            };
            Box::new(HarmonicCheck::new(col, f.angular_frequency, c.end_time(), h.measure_periods, h.tolerance)?)
        }
        V::ElasticColumn(e, ids) => Box::new(elastic_column::ElasticColumnCheck::new(c, model, coll, e, ids)?),
        V::BearingCapacity(b, ids) => Box::new(bearing::BearingCheck::new(c, model, coll, b, ids)?),
        V::ShockWave(s, ids) => {
            let col = Column::from_case(c, model, ids)?;
            Box::new(shock::ShockCheck::new(col, s.probe_depth, s.fast_tolerance, s.slow_tolerance, model, coll)?)
        }
    }))
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

/// Steady-state harmonic column check.
pub struct HarmonicCheck {
    col: Column,
    omega: f64,
    window: (f64, f64),
    tolerance: f64,
    theory: biot_harmonic::BiotSolution,
    /// Per local particle: (∫ w p cos ωt, ∫ w p sin ωt) over the window.
    sums: Vec<(f64, f64)>,
    /// ∫ w dt.
    weight: f64,
    /// (depth, computed |p|/q) after [`Check::finish`].
    profile: Vec<(f64, f64)>,
}

impl HarmonicCheck {
    fn new(col: Column, omega: f64, end: f64, periods: usize, tolerance: f64) -> Result<HarmonicCheck, String> {
        if col.inv_q <= 0.0 {
            return Err("the harmonic column needs a compressible pore fluid (finite water_bulk_modulus)".into());
        }
        let period = 2.0 * std::f64::consts::PI / omega;
        let start = end - periods as f64 * period;
        if start <= 0.0 {
            return Err(format!(
                "the run ({end} s) is shorter than the {periods} measured load periods ({period:.4e} s each)"
            ));
        }
        let theory = biot_harmonic::BiotColumn {
            height: col.height,
            constrained_modulus: col.constrained_modulus,
            q_modulus: 1.0 / col.inv_q,
            porosity: col.porosity,
            solid_density: col.solid_density,
            water_density: col.water_density,
            conductivity: col.conductivity,
            gravity: col.g,
            omega,
            load_amplitude: col.load,
        }
        .solve()?;
        Ok(HarmonicCheck {
            col,
            omega,
            window: (start, end),
            tolerance,
            theory,
            sums: Vec::new(),
            weight: 0.0,
            profile: Vec::new(),
        })
    }
}

impl Check for HarmonicCheck {
    fn columns(&self) -> Vec<String> {
        Vec::new()
    }

    fn event_times(&self) -> Vec<f64> {
        vec![self.window.0]
    }

    fn observe(&mut self, t: f64, dt: f64, model: &Model, _coll: &Collective) -> Result<Vec<f64>, String> {
        if self.sums.len() != model.particles.len() {
            self.sums = vec![(0.0, 0.0); model.particles.len()];
        }
        // Right-endpoint sums (the window vanishes at both ends, so this is the trapezoidal rule).
        if t > self.window.0 + 1e-9 * dt && t <= self.window.1 + 1e-9 * dt {
            let tw = self.window.1 - self.window.0;
            let w = (std::f64::consts::PI * (t - self.window.0) / tw).sin().powi(2);
            self.weight += w * dt;
            let (c, s) = ((self.omega * t).cos(), (self.omega * t).sin());
            for k in self.col.particles(model) {
                self.sums[k].0 += w * model.particles.p[k] * c * dt;
                self.sums[k].1 += w * model.particles.p[k] * s * dt;
            }
        }
        Ok(Vec::new())
    }

    /// ∫ w dt, then (particle id, ∫ w p cos ωt dt, ∫ w p sin ωt dt) of every particle of the column.
    fn checkpoint_state(&self, model: &Model, coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        let local: Vec<f64> = self
            .col
            .particles(model)
            .flat_map(|k| {
                let (c, s) = self.sums.get(k).copied().unwrap_or((0.0, 0.0));
                [model.particles.id[k] as f64, c, s]
            })
            .collect();
        let mut state = vec![self.weight];
        state.extend(coll.gather(&local)?);
        Ok(Some(state))
    }

    fn restore_state(&mut self, state: &[f64], model: &Model) -> Result<(), String> {
        if state.is_empty() || !(state.len() - 1).is_multiple_of(3) {
            return Err(format!("{} values do not make the harmonic sums", state.len()));
        }
        self.weight = state[0];
        let sums: std::collections::HashMap<u64, (f64, f64)> =
            state[1..].chunks(3).map(|r| (r[0] as u64, (r[1], r[2]))).collect();
        self.sums = (0..model.particles.len())
            .map(|k| sums.get(&model.particles.id[k]).copied().unwrap_or((0.0, 0.0)))
            .collect();
        Ok(())
    }

    fn finish(&mut self, model: &Model, coll: &Collective) -> Result<Findings, String> {
        if self.weight <= 0.0 {
            return Err("the measurement window of the harmonic column was never reached".into());
        }
        let norm = 2.0 / self.weight;
        let local: Vec<f64> = self
            .col
            .particles(model)
            .flat_map(|k| {
                let (c, s) = self.sums.get(k).copied().unwrap_or((0.0, 0.0));
                [self.col.top - model.particles.x0[k][1], norm * (c * c + s * s).sqrt()]
            })
            .collect();
        let all = coll.gather(&local)?;
        // Average the particles at the same depth.
        let mut rows: Vec<(f64, f64, usize)> = Vec::new();
        for d in all.chunks(2) {
            match rows.iter_mut().find(|r| (r.0 - d[0]).abs() < 1e-9 * self.col.height) {
                Some(r) => {
                    r.1 += d[1];
                    r.2 += 1;
                }
                None => rows.push((d[0], d[1], 1)),
            }
        }
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        let q = self.col.load;
        let table: Vec<Vec<f64>> =
            rows.iter().map(|r| vec![r.0, r.1 / r.2 as f64 / q, self.theory.pressure_amplitude(r.0) / q]).collect();
        let peak = table.iter().map(|r| r[2]).fold(0.0, f64::max);
        let (worst, at) =
            table.iter().map(|r| ((r[1] - r[2]).abs(), r[0])).fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a });
        let err = worst / peak;
        self.profile = table.iter().map(|r| (r[0], r[1])).collect();
        let metric = Metric::error(
            err,
            self.tolerance,
            format!(
                "largest |A - A*| = {worst:.4e} q at depth {at:.3} m; peak A* = {peak:.4e} q; ω = {:.4e} rad/s",
                self.omega
            ),
        );
        Ok((
            vec![("p_amplitude_max_rel_error".into(), metric)],
            vec![Table {
                name: "amplitude_profile.csv".into(),
                header: vec!["depth_m", "computed_p_amplitude_over_q", "analytical_p_amplitude_over_q"],
                rows: table,
            }],
        ))
    }

    fn figures(&self) -> Vec<crate::plot::Figure> {
        let q = self.col.load;
        let h = self.col.height;
        let reference: Vec<(f64, f64)> = figures::sample(0.0, h, 400, |d| d)
            .into_iter()
            .map(|d| (d, self.theory.pressure_amplitude(d) / q))
            .collect();
        vec![figures::depth_profile(
            "harmonic_amplitude_profile.png",
            &format!("Harmonic column: pore pressure amplitude (ω = {:.4e} rad/s)", self.omega),
            "pore pressure amplitude |p|/q [-]",
            "depth below the loaded top [m]",
            "MPM (particles at one depth averaged)",
            &self.profile,
            "Biot, steady state",
            &reference,
        )]
    }
}
