//! Verification: analytical references and the checks that compare a run with them.
//!
//! A [`Check`] watches the run after every converged step and computes its metrics from the run's
//! own particles at the end; nothing is copied from a table. The analytical solutions live in
//! [`terzaghi`], [`xie_leo`], [`biot_harmonic`] and [`waves`], each with its own unit tests; each
//! check's file says what it measures.
//!
//! A case asks for a check by its table `[verification]` and that table's `kind`. A new check is
//! one file in this folder and one line in the registry `verification_kinds!` (with the `pub mod`
//! line that compiles the file). The file holds the check's parameters as a case file gives them,
//! a serde table whose doc comments the case reference renders, implementing [`CheckParameters`]
//! (their ranges, their description, what the check needs of the analysis and of the bodies,
//! loads, boundaries and stages its names give, the ids of those, and the [`Check`] it builds in
//! two and, where it can, three dimensions), and the check itself. The registry's line
//! `Variant(file::Parameters) = "kind",` makes the check a variant of [`Verification`], through
//! which validation ([`Verification::validate`]) and the run ([`for_case_in`]) ask the trait. The
//! case file's schema keeps the table untyped ([`crate::case::VerificationTable`]): the checks
//! build on the model, which builds on the case.

pub mod bearing;
pub mod biot_harmonic;
pub mod checkerboard;
pub mod consolidation;
pub mod cook;
pub mod dam_break;
pub mod elastic_column;
pub mod figures;
pub mod free_vibration;
pub mod harmonic_column;
pub mod hollow_cylinder;
pub mod hydrostatic;
pub mod lame;
pub mod patch;
pub mod runout;
pub mod shock;
pub mod stiffness_map;
pub mod terzaghi;
pub mod undrained;
pub mod vertical_cut;
pub mod waves;
pub mod xie_leo;

use crate::case::{BodyId, Case, CaseFile, Formulation, Geometry, LoadId, SoilModel};
use crate::check::{at, at_most, positive, Checked};
use crate::layout::Dim;
use crate::model::loads::TimeFn;
use crate::model::Model;
use crate::parallel::Collective;
use serde::{Deserialize, Serialize};

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
    /// Times the time stepping must land on exactly (none unless the check says).
    fn event_times(&self) -> Vec<f64> {
        Vec::new()
    }
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

/// The Young's modulus [Pa] and Poisson's ratio of a linear elastic `body`, or of a neo-Hookean
/// one (whose small-strain limit is linear elasticity of the same moduli, so that a run at small
/// strains meets the closed form and its error includes the model's nonlinearity), for the
/// elastic closed forms.
pub(crate) fn elastic_body(c: &Case, body: BodyId) -> Result<(f64, f64), String> {
    match &c.material_of(body).model {
        SoilModel::LinearElastic(e) => Ok((e.0.young_modulus, e.0.poisson_ratio)),
        SoilModel::NeoHookean(e) => Ok((e.0.young_modulus, e.0.poisson_ratio)),
        _ => Err(format!("body `{}` is neither linear elastic nor neo-Hookean", c.body(body).name)),
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

/// The body a check follows and the load it compares with (the keys `body` and `load`).
#[derive(Debug, Clone, Copy)]
pub struct BodyAndLoad {
    /// `body`.
    pub body: BodyId,
    /// `load`.
    pub load: LoadId,
}

impl BodyAndLoad {
    /// The ids of the body called `body` and the load called `load`.
    fn named(c: &Case, body: &str, load: &str) -> Result<BodyAndLoad, String> {
        Ok(BodyAndLoad {
            body: c.body_named("verification.body", body)?,
            load: c.load_named("verification.load", load)?,
        })
    }

    /// [`BodyAndLoad::named`], the load one whose reference follows its time function
    /// ([`plain_load`]).
    fn plain(c: &Case, body: &str, load: &str) -> Result<BodyAndLoad, String> {
        let ids = BodyAndLoad::named(c, body, load)?;
        plain_load(c, ids.load)?;
        Ok(ids)
    }
}

/// The name of a load.
fn load_name(c: &Case, load: LoadId) -> &str {
    c.load(load).name()
}

/// A load whose reference follows its time function: without an `increment_factor` (only the
/// hollow cylinder's check follows one).
fn plain_load(c: &Case, load: LoadId) -> Checked {
    if c.load(load).increment_factor().is_some() {
        return Err(format!(
            "key `verification.load`: the check's reference follows the load's time function, and `{}` has an \
             `increment_factor` (only the hollow_cylinder check follows one)",
            load_name(c, load)
        ));
    }
    Ok(())
}

/// A linear elastic body, which `reference` needs.
fn linear_elastic(c: &Case, body: BodyId, reference: &str) -> Checked {
    if !matches!(c.material_of(body).model, SoilModel::LinearElastic(_)) {
        return Err(format!(
            "key `verification.body`: {reference} needs a linear elastic body, and `{}` is not",
            c.body(body).name
        ));
    }
    Ok(())
}

/// Each of `values` above zero, named `key[j]`.
fn each_positive(key: &str, values: &[f64]) -> Checked {
    values.iter().enumerate().try_for_each(|(j, &v)| positive(&format!("{key}[{j}]"), v))
}

/// Each `(name, value)` of a reference solution's parameters positive and finite, or a message naming
/// the first that is not.
fn positive_finite(fields: &[(&str, f64)]) -> Result<(), String> {
    match fields.iter().find(|(_, v)| !(v.is_finite() && *v > 0.0)) {
        Some((name, value)) => Err(format!("{name} must be positive and finite, got {value}")),
        None => Ok(()),
    }
}

/// A reference solution's parameter `name` finite, or a message naming it.
fn finite_parameter(name: &str, value: f64) -> Result<(), String> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(format!("{name} must be finite, got {value}"))
    }
}

/// Each `(field, value)` above zero, and a tolerance at most 1 ([`tolerance`]).
fn all_positive(key: &str, fields: &[(&str, f64)]) -> Checked {
    fields.iter().try_for_each(|&(f, v)| {
        if f.ends_with("tolerance") {
            tolerance(&at(key, f), v)
        } else {
            positive(&at(key, f), v)
        }
    })
}

/// A verification tolerance: every one bounds a normalised error, so it is positive and at most 1
/// (a tolerance of 100 % or more lets any answer pass).
fn tolerance(key: &str, v: f64) -> Checked {
    positive(key, v)?;
    at_most(key, v, 1.0, "", "it bounds a normalised error, and 100 % or more lets any answer pass")
}

/// The spray fraction's range [0, 0.05].
fn spray(key: &str, v: f64) -> Checked {
    if !(0.0..=0.05).contains(&v) {
        return Err(format!("key `{}`: must be in [0, 0.05], got {v}", at(key, "spray_fraction")));
    }
    Ok(())
}

/// An outer radius beyond the inner one.
fn radii(key: &str, inner: f64, outer: f64) -> Checked {
    if outer <= inner {
        return Err(format!("key `{}`: must exceed `inner_radius`", at(key, "outer_radius")));
    }
    Ok(())
}

/// The formulation a check is for, with the message for a case of the other; `None` where either
/// will do.
pub type FormulationNeed = Option<(Formulation, &'static str)>;

/// A check built for a case of dimension `D`, or why it cannot be.
pub type BuiltCheck<const D: usize = 2> = Result<Box<dyn Check<D>>, String>;

/// A check's parameters as the case file gives them (the table `[verification]` beside its
/// `kind`): their ranges, their description, what the check needs of the case, the names they give
/// resolved to ids, and the check they make.
pub trait CheckParameters {
    /// The ids of the bodies, loads, boundaries and stages the parameters name.
    type Ids;

    /// The formulation the check is for, with the message of a case of the other (after
    /// ``key `verification`: ``); `None` where either will do.
    const FORMULATION: FormulationNeed = None;

    /// Whether a three-dimensional case may ask for the check ([`CheckParameters::solid`] builds
    /// it there).
    const SOLID: bool = false;

    /// Whether an axisymmetric case may ask for the check (a plane-strain reference cannot check
    /// one).
    const AXISYMMETRIC: bool = false;

    /// Checks the ranges of the parameters and what they require of each other; `key` is the
    /// table (`verification`).
    fn check(&self, key: &str) -> Checked;

    /// The check in words and numbers, for `porompm check`.
    fn describe(&self) -> String;

    /// The ids of what the parameters name (``key `verification.body`: no body named `x` ``
    /// otherwise), after checking what the check needs of those tables and of the case beyond
    /// its formulation and dimension (a linear elastic body, a body-force load, ...). Validation
    /// asks it, and the run again to build the check.
    fn link(&self, c: &Case) -> Result<Self::Ids, String>;

    /// The check of a plane or axisymmetric case whose names resolve to `ids` (collective).
    fn plane(&self, c: &Case, ids: &Self::Ids, model: &Model, coll: &Collective) -> BuiltCheck;

    /// The check of a three-dimensional case whose names resolve to `ids` (collective); a check
    /// with [`CheckParameters::SOLID`] builds it, and validation refuses the others' cases.
    fn solid(&self, _c: &Case, _ids: &Self::Ids, _model: &Model<3>, _coll: &Collective) -> BuiltCheck<3> {
        Err("the check is two-dimensional".into())
    }
}

/// What a check needs of a case's analysis: [`CheckParameters`]'s constants.
#[derive(Debug, Clone, Copy)]
struct Needs {
    formulation: FormulationNeed,
    solid: bool,
    axisymmetric: bool,
}

impl Needs {
    /// The needs of the check of parameters `P`.
    const fn of<P: CheckParameters>() -> Needs {
        Needs { formulation: P::FORMULATION, solid: P::SOLID, axisymmetric: P::AXISYMMETRIC }
    }

    /// Whether case `c`'s dimension, geometry and formulation are the check's (`kind` names it).
    fn check(&self, c: &Case, kind: &str) -> Checked {
        if c.dimension() == 3 && !self.solid {
            return Err(format!(
                "key `verification.kind = \"{kind}\"`: not available in a three-dimensional case yet \
                 (docs/dimensions.md)"
            ));
        }
        if c.analysis.geometry == Geometry::Axisymmetric && !self.axisymmetric {
            let can: Vec<String> =
                Verification::NEEDS.iter().filter(|(_, n)| n.axisymmetric).map(|(k, _)| format!("`{k}`")).collect();
            let can = match can.split_last() {
                Some((last, [])) => last.clone(),
                Some((last, rest)) => format!("{} and {last}", rest.join(", ")),
                None => "none".into(),
            };
            return Err(format!(
                "key `verification`: the `{kind}` reference is a plane-strain solution and cannot check an \
                 axisymmetric analysis (of the checks, {can} can)"
            ));
        }
        match self.formulation {
            Some((f, message)) if f != c.analysis.formulation => Err(format!("key `verification`: {message}")),
            _ => Ok(()),
        }
    }
}

/// The registry of the checks: each line names a check's variant, its parameters' type and the
/// `kind` a case file chooses it by (with the variant's doc comment, which the case reference
/// shows). It makes [`Verification`], the case file's table `[verification]` typed, internally
/// tagged by `kind`, whose methods ask the variant's [`CheckParameters`].
macro_rules! verification_kinds {
    ($($(#[$attr:meta])* $variant:ident($params:ty) = $kind:literal,)*) => {
        /// The analytical reference of a case.
        #[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
        #[serde(tag = "kind")]
        pub enum Verification {
            $($(#[$attr])* #[serde(rename = $kind)] $variant($params),)*
        }

        impl Verification {
            /// The `kind` of every check with what it needs of the analysis, in the registry's
            /// order.
            const NEEDS: &'static [(&'static str, Needs)] = &[$(($kind, Needs::of::<$params>()),)*];

            /// The `kind` the case file names.
            pub fn kind(&self) -> &'static str {
                match self {
                    $(Verification::$variant(_) => $kind,)*
                }
            }

            /// Checks the ranges of the check's parameters; `key` is its table (`verification`).
            pub fn check(&self, key: &str) -> Checked {
                match self {
                    $(Verification::$variant(p) => CheckParameters::check(p, key),)*
                }
            }

            /// The check in words and numbers, for `porompm check`.
            pub fn describe(&self) -> String {
                match self {
                    $(Verification::$variant(p) => CheckParameters::describe(p),)*
                }
            }

            /// What the check needs of the analysis.
            fn needs(&self) -> Needs {
                match self {
                    $(Verification::$variant(_) => Needs::of::<$params>(),)*
                }
            }

            /// Whether the names resolve and the tables they name are what the check needs
            /// ([`CheckParameters::link`]).
            fn link(&self, c: &Case) -> Checked {
                match self {
                    $(Verification::$variant(p) => CheckParameters::link(p, c).map(drop),)*
                }
            }

            /// The check of a plane or axisymmetric case (collective).
            fn plane(&self, c: &Case, model: &Model, coll: &Collective) -> BuiltCheck {
                match self {
                    $(Verification::$variant(p) => p.plane(c, &p.link(c)?, model, coll),)*
                }
            }

            /// The check of a three-dimensional case (collective).
            fn solid(&self, c: &Case, model: &Model<3>, coll: &Collective) -> BuiltCheck<3> {
                if !self.needs().solid {
                    return Err(format!("the `{}` check is two-dimensional", self.kind()));
                }
                match self {
                    $(Verification::$variant(p) => p.solid(c, &p.link(c)?, model, coll),)*
                }
            }
        }
    };
}

verification_kinds! {
    /// One-dimensional consolidation ([003] §4.1.1, Eqs. 31–33); two-phase.
    Terzaghi(consolidation::TerzaghiConsolidation) = "terzaghi",
    /// Steady-state harmonic column (Zienkiewicz, Chang & Bettess 1980; [003] §4.1.2); two-phase.
    HarmonicColumn(harmonic_column::HarmonicColumn) = "harmonic_column",
    /// The free vibration of an elastic bar fixed at its base, its sides held laterally, started by
    /// an initial velocity of its first mode's shape v₀ sin(π (y − y_b)/(2H)): the period of its
    /// first mode's displacement against 4H/c and the amplitude against v₀/ω, ω = π c/(2H),
    /// c = √(M/ρ); one-phase.
    FreeVibration(free_vibration::FreeVibration) = "free_vibration",
    /// Elastic column under its self-weight and a surcharge, at rest at the end of the run: the
    /// vertical stress is −(ρ g d + q) at depth d and the settlement ρ g H²/(2 E_c) + q H/E_c;
    /// one-phase.
    ElasticColumn(elastic_column::ElasticColumn) = "elastic_column",
    /// Load–settlement of a strip (or, in three dimensions, a rectangular) footing and its bearing
    /// capacity ([000] §4.1, §4.3).
    BearingCapacity(bearing::BearingCapacity) = "bearing_capacity",
    /// Large-strain one-dimensional consolidation (Xie & Leo 2004; [003] §4.2); two-phase.
    LargeStrainConsolidation(consolidation::LargeStrainConsolidation) = "large_strain_consolidation",
    /// A homogeneous deformation (patch test, rigid rotation): a body whose boundary nodes follow a
    /// boundary's `velocity_gradient` must carry one uniform stress, equal to the linear-elastic
    /// one of the flow, R σ₀ Rᵀ + D ln V with F = exp(L ∫f) = V R (exact for a pure stretch and for
    /// a pure rotation); one-phase.
    Patch(patch::Patch) = "patch",
    /// A thick-walled cylinder under internal pressure in plane strain (Lamé): a quarter of it
    /// (symmetry on the axes through `center`), linear elastic, loaded by a `line_pressure` on its
    /// inner circle. Metrics: the relative L2 errors (weighted by the points' volumes) of the radial
    /// displacement and of σ_rr and σ_θθ over the body's points against
    /// u_r = (1 + ν) p a² ((1 − 2ν) r + b²/r) / (E (b² − a²)),
    /// σ_rr = p a² (1 − b²/r²)/(b² − a²), σ_θθ = p a² (1 + b²/r²)/(b² − a²); one-phase.
    Lame(lame::LameCylinder) = "lame",
    /// A thick-walled hollow cylinder under internal pressure in axial symmetry, its outer wall held
    /// radially and plane strain along the axis ([001] §3.1): Lamé's closed form with u_r(b) = 0,
    /// compared after the first load step (the first increment of [001]); one-phase.
    HollowCylinder(hollow_cylinder::HollowCylinder) = "hollow_cylinder",
    /// The nodal stiffness diagnostic K_mag = √(K_x² + K_y²) ([001] Eq. 25, §6) of a block of
    /// material points in plane strain against the finite-element value of an interior node of a
    /// uniform Q4 mesh of square cells, (4/3)(D₁₁ + G)√2, over the nodes within `radius` of
    /// `center`, after the last step.
    StiffnessMap(stiffness_map::StiffnessMap) = "stiffness_map",
    /// The vertical cut of [001] §3.2 and §7.2: no closed form; the run stops when the toe has
    /// moved `stop_displacement`, and reports the constitutive check q ≤ √3 c(ε̄) at every point
    /// and step, the largest ε̄, the smoothness of the nodal K_mag and F^int_mag when the toe passes
    /// each of `snapshots`, and the total variation of σ_m at the points `b` and `c`.
    VerticalCut(vertical_cut::VerticalCut) = "vertical_cut",
    /// Cook's membrane of [002] §4.1: the tapered plate clamped on its left edge and sheared on its
    /// right, brought to rest. The vertical displacement of the tip (the upper-right corner), by a
    /// linear least-squares fit of the points' displacements around it, against `reference`; the
    /// chequerboard index of the mean stress over the body's points; one-phase.
    CookMembrane(cook::CookMembrane) = "cook_membrane",
    /// The collapse of a water column after a gate is removed ([002] §4.3). A settling stage brings
    /// the water to rest behind the gate (the stage names it; the gate is a boundary the next
    /// stages leave out); at its end the pressure must be hydrostatic. After it, the front and the
    /// centre of mass are followed, the front's advance is bounded by the shallow-water (Ritter)
    /// speed 2√(gH), and the mass must not change. With `experiment`, the front is compared with a
    /// laboratory series; one-phase.
    DamBreak(dam_break::DamBreak) = "dam_break",
    /// The run-out of a slope that fails after a trigger ([002] §4.4, the landslide). Before the
    /// trigger stage the slope must stand (its front advances by at most `standing_advance` and no
    /// point moves faster than `standing_speed` at the trigger); the body's mass must keep. From the
    /// trigger on, the front (the leading edge along +x with at most `spray_fraction` of the mass
    /// ahead of it, as the dam break's), its advance R(t) (the run-out), the foremost point, the
    /// centre of mass, the largest accumulated plastic strain and the rearmost point that has failed
    /// are followed. There is no reference solution: the run-out is a result, compared between
    /// runs; one-phase.
    Runout(runout::Runout) = "runout",
    /// Shock wave in a saturated column ([003] §4.1.3, Eqs. 34–35); two-phase.
    ShockWave(shock::ShockWave) = "shock_wave",
    /// A saturated body at rest under gravity (after a geostatic or a consolidation stage has
    /// drained): its pore pressure must be hydrostatic, p* = ρ_w g (h_w − y) below the water table
    /// h_w; the metric `p_rel_error` is the largest |p − p*| over the body's points relative to the
    /// largest |p*|; two-phase.
    Hydrostatic(hydrostatic::Hydrostatic) = "hydrostatic",
}

impl Verification {
    /// The case's `[verification]` as its check's typed parameters, if it has one; a table that
    /// does not fit is one line naming its key (``key `verification.kind`: unknown variant ...``,
    /// ``key `verification`: unknown field ...``).
    pub fn of(c: &CaseFile) -> Result<Option<Verification>, String> {
        let Some(table) = &c.verification else {
            return Ok(None);
        };
        c.table_as("verification", table.as_value()).map(Some)
    }

    /// Validation's checks of the case's verification, if it has one: the table fits its kind,
    /// the parameters' ranges, the case's dimension, geometry and formulation, and the names with
    /// what the check needs of the tables they name.
    pub fn validate(c: &Case) -> Checked {
        let Some(v) = Verification::of(c)? else {
            return Ok(());
        };
        v.check("verification")?;
        v.needs().check(c, v.kind())?;
        v.link(c)
    }
}

/// The case's verification in words and numbers (`none` without one), for `porompm check`.
pub fn describe(c: &Case) -> String {
    match Verification::of(c) {
        Ok(Some(v)) => v.describe(),
        Ok(None) => "none".into(),
        Err(e) => e,
    }
}

/// The checks a case of dimension D may ask for: every check in the plane; in three dimensions
/// those whose parameters say [`CheckParameters::SOLID`].
pub trait CaseChecks<const D: usize> {
    /// The check the case asks for, if any (collective).
    fn for_case(c: &Case, model: &Model<D>, coll: &Collective) -> Result<Option<Box<dyn Check<D>>>, String>;
}

impl CaseChecks<2> for Dim<2> {
    fn for_case(c: &Case, model: &Model, coll: &Collective) -> Result<Option<Box<dyn Check>>, String> {
        Verification::of(c)?.map(|v| v.plane(c, model, coll)).transpose()
    }
}

impl CaseChecks<3> for Dim<3> {
    fn for_case(c: &Case, model: &Model<3>, coll: &Collective) -> Result<Option<Box<dyn Check<3>>>, String> {
        Verification::of(c)?.map(|v| v.solid(c, model, coll)).transpose()
    }
}

/// The check the case asks for in dimension D ([`CaseChecks`]), its parameters typed and its names
/// resolved by the registry from the case's table.
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
