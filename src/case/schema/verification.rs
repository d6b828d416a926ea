//! `[verification]`: the analytical reference a run is checked against, chosen by its `kind`,
//! each kind's parameters in their own table with the checks of their ranges.

use crate::check::{at, at_most, finite2, positive, Checked};
use serde::{Deserialize, Serialize};

/// The analytical reference of a case.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Verification {
    /// One-dimensional consolidation ([003] §4.1.1, Eqs. 31–33); two-phase.
    Terzaghi(Terzaghi),
    /// Steady-state harmonic column (Zienkiewicz, Chang & Bettess 1980; [003] §4.1.2); two-phase.
    HarmonicColumn(HarmonicColumn),
    /// Elastic column under its self-weight and a surcharge, at rest at the end of the run: the
    /// vertical stress is −(ρ g d + q) at depth d and the settlement ρ g H²/(2 E_c) + q H/E_c;
    /// one-phase.
    ElasticColumn(ElasticColumn),
    /// Load–settlement of a strip (or, in three dimensions, a rectangular) footing and its bearing
    /// capacity ([000] §4.1, §4.3).
    BearingCapacity(BearingCapacity),
    /// Large-strain one-dimensional consolidation (Xie & Leo 2004; [003] §4.2); two-phase.
    LargeStrainConsolidation(LargeStrainConsolidation),
    /// A homogeneous deformation (patch test, rigid rotation): a body whose boundary nodes follow a
    /// boundary's `velocity_gradient` must carry one uniform stress, equal to the linear-elastic
    /// one of the flow, R σ₀ Rᵀ + D ln V with F = exp(L ∫f) = V R (exact for a pure stretch and for
    /// a pure rotation); one-phase.
    Patch(Patch),
    /// A thick-walled cylinder under internal pressure in plane strain (Lamé): a quarter of it
    /// (symmetry on the axes through `center`), linear elastic, loaded by a `line_pressure` on its
    /// inner circle. Metrics: the relative L2 errors (weighted by the points' volumes) of the radial
    /// displacement and of σ_rr and σ_θθ over the body's points against
    /// u_r = (1 + ν) p a² ((1 − 2ν) r + b²/r) / (E (b² − a²)),
    /// σ_rr = p a² (1 − b²/r²)/(b² − a²), σ_θθ = p a² (1 + b²/r²)/(b² − a²); one-phase.
    Lame(Lame),
    /// A thick-walled hollow cylinder under internal pressure in axial symmetry, its outer wall held
    /// radially and plane strain along the axis ([001] §3.1): Lamé's closed form with u_r(b) = 0,
    /// compared after the first load step (the first increment of [001]); one-phase.
    HollowCylinder(HollowCylinder),
    /// The nodal stiffness diagnostic K_mag = √(K_x² + K_y²) ([001] Eq. 25, §6) of a block of
    /// material points in plane strain against the finite-element value of an interior node of a
    /// uniform Q4 mesh of square cells, (4/3)(D₁₁ + G)√2, over the nodes within `radius` of
    /// `center`, after the last step.
    StiffnessMap(StiffnessMap),
    /// The vertical cut of [001] §3.2 and §7.2: no closed form; the run stops when the toe has
    /// moved `stop_displacement`, and reports the constitutive check q ≤ √3 c(ε̄) at every point
    /// and step, the largest ε̄, the smoothness of the nodal K_mag and F^int_mag when the toe passes
    /// each of `snapshots`, and the total variation of σ_m at the points `b` and `c`.
    VerticalCut(VerticalCut),
    /// Cook's membrane of [002] §4.1: the tapered plate clamped on its left edge and sheared on its
    /// right, brought to rest. The vertical displacement of the tip (the upper-right corner), by a
    /// linear least-squares fit of the points' displacements around it, against `reference`; the
    /// chequerboard index of the mean stress over the body's points; one-phase.
    CookMembrane(CookMembrane),
    /// The collapse of a water column after a gate is removed ([002] §4.3). A settling stage brings
    /// the water to rest behind the gate (the stage names it; the gate is a boundary the next
    /// stages leave out); at its end the pressure must be hydrostatic. After it, the front and the
    /// centre of mass are followed, the front's advance is bounded by the shallow-water (Ritter)
    /// speed 2√(gH), and the mass must not change. With `experiment`, the front is compared with a
    /// laboratory series; one-phase.
    DamBreak(DamBreak),
    /// The run-out of a slope that fails after a trigger ([002] §4.4, the landslide). Before the
    /// trigger stage the slope must stand (its front advances by at most `standing_advance` and no
    /// point moves faster than `standing_speed` at the trigger); the body's mass must keep. From the
    /// trigger on, the front (the leading edge along +x with at most `spray_fraction` of the mass
    /// ahead of it, as the dam break's), its advance R(t) (the run-out), the foremost point, the
    /// centre of mass, the largest accumulated plastic strain and the rearmost point that has failed
    /// are followed. There is no reference solution: the run-out is a result, compared between
    /// runs; one-phase.
    Runout(Runout),
    /// Shock wave in a saturated column ([003] §4.1.3, Eqs. 34–35); two-phase.
    ShockWave(ShockWave),
}

/// The parameters of `kind = "terzaghi"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Terzaghi {
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

/// The parameters of `kind = "harmonic_column"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HarmonicColumn {
    /// The name of the column body.
    pub body: String,
    /// The name of the harmonic surface load, a particle or nodal traction with a `harmonic` time
    /// function.
    pub load: String,
    /// Number of final load periods over which the amplitude is measured [-], ≥ 1 (default 3).
    #[serde(default = "default_periods")]
    pub measure_periods: usize,
    /// Pass threshold for the maximum amplitude error relative to the peak amplitude [-], in (0, 1].
    pub tolerance: f64,
}

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

/// The parameters of `kind = "bearing_capacity"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BearingCapacity {
    /// The name of the soil body (its cohesion normalises the pressure).
    pub soil: String,
    /// The name of the load: a traction (its pressure), or a body force on the footing body (its
    /// weight over `loaded_width`; the body force must name its bodies). Give `load` or `footing`.
    pub load: Option<String>,
    /// The name of a rigid footing pushed into the soil under displacement control: a boundary
    /// that fixes `uy` and moves it vertically (`velocity` or `displacement`); the pressure is its
    /// vertical reaction on the soil over `loaded_width` ([002] §4.2). Give `load` or `footing`.
    pub footing: Option<String>,
    /// Width carrying the load in the model [m], > 0 (the half-width in a half model).
    pub loaded_width: f64,
    /// In three dimensions, the loaded area's extent along z in the model [m], > 0 (the
    /// half-length of a footing in a quarter model): the pressure is the force over
    /// `loaded_width` × `loaded_depth`. Required in three dimensions; two-dimensional cases do not
    /// take it.
    pub loaded_depth: Option<f64>,
    /// Footing breadth B [m], > 0 (normalises the settlement).
    pub breadth: f64,
    /// The settlement is the downward displacement of the material point nearest to this point
    /// at t = 0 [m] (one coordinate per dimension).
    pub settlement_point: Vec<f64>,
    /// d/B [-], > 0, at which q_ult is read for the metric `bearing_capacity_ratio` (a
    /// load-controlled footing; give this or `plateau`, or neither for no metric).
    pub failure_settlement: Option<f64>,
    /// The range [d/B_from, d/B_to] [-], 0 ≤ d/B_from < d/B_to, over which the mean of q is q_ult
    /// for the metric `bearing_capacity_ratio` (a displacement-controlled footing, whose load
    /// levels off at the limit load).
    pub plateau: Option<[f64; 2]>,
    /// Reference q_ult/c [-], > 0 (default 2 + π, Prandtl).
    #[serde(default = "default_prandtl")]
    pub reference: f64,
    /// Largest accepted |(q_ult/c)/reference − 1| [-], in (0, 1] (default 0.03).
    #[serde(default = "default_bearing_tol")]
    pub tolerance: f64,
    /// d/B values [-], each > 0, at which q/c is reported in summary.json `results`.
    #[serde(default)]
    pub report_settlements: Vec<f64>,
    /// q/c values [-], each > 0, at which the settlement of the point d [m] is reported in
    /// summary.json `results` as `settlement_at_qc<value>`.
    #[serde(default)]
    pub report_loads: Vec<f64>,
    /// d/B [-], > 0, at which the run ends, completed (a load-controlled footing beyond its limit
    /// load runs away; default: run to the end).
    pub stop_settlement: Option<f64>,
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

/// The parameters of `kind = "patch"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Patch {
    /// The name of the body (linear elastic or neo-Hookean).
    pub body: String,
    /// The name of the boundary whose homogeneous flow (`velocity_gradient`) drives it.
    pub boundary: String,
    /// Largest accepted spread of the particles' stresses, max ‖σ_p − σ̄‖/‖σ̄‖ [-], in (0, 1] (default
    /// 1e-9).
    #[serde(default = "default_spread_tol")]
    pub spread_tolerance: f64,
    /// Largest accepted ‖σ̄ − σ*‖/‖σ*‖ against the linear-elastic stress of the flow [-], in (0, 1]
    /// (default 1e-6).
    #[serde(default = "default_patch_tol")]
    pub tolerance: f64,
}

/// The parameters of `kind = "lame"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Lame {
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
    #[serde(default = "default_lame_tol")]
    pub displacement_tolerance: f64,
    /// Largest accepted relative error of Δσ_rr at the innermost points (mp1) and volume-weighted
    /// RMS of the relative error of Δσ_rr over the body [-], in (0, 1] (default 0.25).
    #[serde(default = "default_hollow_stress_tol")]
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

/// The parameters of `kind = "vertical_cut"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VerticalCut {
    /// The name of the soil (von Mises).
    pub body: String,
    /// The toe's point at t = 0 (the nearest material point is followed) [m].
    pub toe: [f64; 2],
    /// The point B (in the shear band) at t = 0 [m].
    pub b: [f64; 2],
    /// The point C (in the sliding block) at t = 0 [m].
    pub c: [f64; 2],
    /// The toe's horizontal displacement that ends the run [m], > 0.
    pub stop_displacement: f64,
    /// Toe displacements at which the nodal fields' smoothness is measured [m], each > 0.
    #[serde(default)]
    pub snapshots: Vec<f64>,
}

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

/// The parameters of `kind = "dam_break"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DamBreak {
    /// The name of the water body (a rectangle at t = 0 against the back wall at its left).
    pub body: String,
    /// The name of the body-force load carrying gravity.
    pub gravity: String,
    /// The name of the settling stage (not the last), at whose end the water is checked for the
    /// hydrostatic pressure and after which it flows.
    pub settle_stage: String,
    /// Largest accepted |p − ρ g d| / (ρ g H) over the points more than one cell above the base
    /// at the end of the settling stage [-], in (0, 1] (default 0.02).
    #[serde(default = "default_hydrostatic_tol")]
    pub hydrostatic_tolerance: f64,
    /// x of the wall the front runs into [m]; the front's speed bound applies while the front is
    /// more than a cell from it (default: no wall, the whole run).
    pub far_wall: Option<f64>,
    /// A measured front position to compare with: `"martin_moyce_1952"` (Martin & Moyce 1952,
    /// the column of height 2a on width a, n² = 2; the body must have that aspect ratio).
    pub experiment: Option<String>,
    /// Largest accepted mean |Z/Z_exp − 1| of the front against `experiment` [-], in (0, 1] (default
    /// 0.1).
    #[serde(default = "default_front_tol")]
    pub front_tolerance: f64,
    /// The share of the water's mass that may lie ahead of the front, as spray shed from its
    /// tip [-], in [0, 0.05] (default 0.005).
    #[serde(default = "default_spray")]
    pub spray_fraction: f64,
}

/// The parameters of `kind = "runout"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Runout {
    /// The name of the sliding body (its material moves along +x).
    pub body: String,
    /// The name of the stage whose start triggers the failure (e.g. by its
    /// `strength_reduction`); the run-out counts from the front's position then.
    pub trigger_stage: String,
    /// Largest accepted advance of the front before the trigger (the slope stands) [m], > 0
    /// (default 0.05).
    #[serde(default = "default_standing_advance")]
    pub standing_advance: f64,
    /// Largest accepted speed of any point of the body at the trigger [m/s], > 0 (default 0.01).
    #[serde(default = "default_standing_speed")]
    pub standing_speed: f64,
    /// Times after the trigger at which the run-out is reported as a result (`runout_t<τ>`,
    /// the stepping lands on them) [s], each in (0, the time from the trigger to the end].
    #[serde(default)]
    pub snapshot_times: Vec<f64>,
    /// Accumulated plastic strain ε̄ beyond which a point counts as failed (the rearmost
    /// failed point marks the retrogression of the failure) [-], > 0 (default 0.5).
    #[serde(default = "default_failed_strain")]
    pub failed_strain: f64,
    /// The share of the body's mass that may lie ahead of the front [-], in [0, 0.05] (default
    /// 1e-3).
    #[serde(default = "default_runout_spray")]
    pub spray_fraction: f64,
}

/// The parameters of `kind = "shock_wave"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ShockWave {
    /// The name of the column body.
    pub body: String,
    /// The name of the step surface load, a particle or nodal traction.
    pub load: String,
    /// Depth of the observation point below the initial surface [m], > 0.
    pub probe_depth: f64,
    /// Pass threshold for the fast (undrained) wave arrival error [-], in (0, 1] (default 0.02).
    #[serde(default = "default_fast_tol")]
    pub fast_tolerance: f64,
    /// Pass threshold for the slow (damped) wave arrival error [-], in (0, 1] (default 0.05).
    #[serde(default = "default_slow_tol")]
    pub slow_tolerance: f64,
}

impl Verification {
    /// The `kind` the case file names.
    pub fn kind(&self) -> &'static str {
        match self {
            Verification::Terzaghi(_) => "terzaghi",
            Verification::HarmonicColumn(_) => "harmonic_column",
            Verification::ElasticColumn(_) => "elastic_column",
            Verification::BearingCapacity(_) => "bearing_capacity",
            Verification::LargeStrainConsolidation(_) => "large_strain_consolidation",
            Verification::Patch(_) => "patch",
            Verification::Lame(_) => "lame",
            Verification::HollowCylinder(_) => "hollow_cylinder",
            Verification::StiffnessMap(_) => "stiffness_map",
            Verification::VerticalCut(_) => "vertical_cut",
            Verification::ShockWave(_) => "shock_wave",
            Verification::CookMembrane(_) => "cook_membrane",
            Verification::DamBreak(_) => "dam_break",
            Verification::Runout(_) => "runout",
        }
    }

    /// Checks the ranges of the reference's own parameters; `key` is its table (`verification`).
    /// Its names, and what it asks of the bodies, loads and stages it names, validation checks.
    pub fn check(&self, key: &str) -> Checked {
        match self {
            Verification::Terzaghi(v) => v.check(key),
            Verification::HarmonicColumn(v) => v.check(key),
            Verification::ElasticColumn(v) => v.check(key),
            Verification::BearingCapacity(v) => v.check(key),
            Verification::LargeStrainConsolidation(v) => v.check(key),
            Verification::Patch(v) => v.check(key),
            Verification::Lame(v) => v.check(key),
            Verification::HollowCylinder(v) => v.check(key),
            Verification::StiffnessMap(v) => v.check(key),
            Verification::VerticalCut(v) => v.check(key),
            Verification::ShockWave(v) => v.check(key),
            Verification::CookMembrane(v) => v.check(key),
            Verification::DamBreak(v) => v.check(key),
            Verification::Runout(v) => v.check(key),
        }
    }

    /// The reference in words and numbers, for `porompm check`.
    pub fn describe(&self) -> String {
        match self {
            Verification::Terzaghi(v) => format!("Terzaghi consolidation at T_v = {:?}", v.time_factors),
            Verification::HarmonicColumn(v) => {
                format!("harmonic column (Zienkiewicz et al. 1980), last {} periods", v.measure_periods)
            }
            Verification::ShockWave(v) => format!("shock-wave arrival at {} m depth", v.probe_depth),
            Verification::ElasticColumn(_) => "static elastic column under self-weight and surcharge".into(),
            Verification::LargeStrainConsolidation(v) => {
                format!("large-strain consolidation (Xie & Leo 2004) at U_s = {:?}", v.degrees)
            }
            Verification::Lame(v) => {
                format!("Lamé cylinder, a = {} m, b = {} m: u_r, σ_rr, σ_θθ", v.inner_radius, v.outer_radius)
            }
            Verification::HollowCylinder(v) => v.describe(),
            Verification::CookMembrane(v) => format!(
                "Cook's membrane ([002] §4.1): the tip ({}, {})'s vertical displacement at rest against {} m, \
                 the mean stress's chequerboard index",
                v.tip[0], v.tip[1], v.reference
            ),
            Verification::DamBreak(v) => v.describe(),
            Verification::Runout(v) => format!(
                "run-out of a slope failing from stage `{}` on ([002] §4.4): the slope standing before it, the \
                 mass, the front's advance (no reference solution)",
                v.trigger_stage
            ),
            Verification::StiffnessMap(v) => format!(
                "nodal stiffness K_mag ([001] Eq. 25) within {} m of ({}, {}) against the finite-element value",
                v.radius, v.center[0], v.center[1]
            ),
            Verification::VerticalCut(v) => format!(
                "vertical cut ([001] §7.2) to a toe displacement of {} m: yield check, smoothness of K_mag and \
                 F^int_mag",
                v.stop_displacement
            ),
            Verification::Patch(v) => {
                format!("patch test: uniform stress under the homogeneous flow of boundary `{}`", v.boundary)
            }
            Verification::BearingCapacity(v) => v.describe(),
        }
    }
}

/// Each of `values` above zero, named `key[j]`.
fn each_positive(key: &str, values: &[f64]) -> Checked {
    values.iter().enumerate().try_for_each(|(j, &v)| positive(&format!("{key}[{j}]"), v))
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

impl Terzaghi {
    /// Checks the time factors and tolerances; `key` is the table (`verification`).
    pub fn check(&self, key: &str) -> Checked {
        if self.time_factors.is_empty() || self.time_factors.iter().any(|t| !(*t > 0.0 && t.is_finite())) {
            return Err(format!("key `{}`: give positive time factors", at(key, "time_factors")));
        }
        let (e, r, s) = (self.e_p_tolerance, self.p_rms_tolerance, self.settlement_tolerance);
        all_positive(key, &[("e_p_tolerance", e), ("p_rms_tolerance", r), ("settlement_tolerance", s)])
    }
}

impl HarmonicColumn {
    /// Checks the tolerance and the periods; `key` is the table (`verification`).
    pub fn check(&self, key: &str) -> Checked {
        tolerance(&at(key, "tolerance"), self.tolerance)?;
        if self.measure_periods == 0 {
            return Err(format!("key `{}`: must be at least 1", at(key, "measure_periods")));
        }
        Ok(())
    }
}

impl ElasticColumn {
    /// Checks the tolerances; `key` is the table (`verification`).
    pub fn check(&self, key: &str) -> Checked {
        let (st, se) = (self.stress_tolerance, self.settlement_tolerance);
        all_positive(key, &[("stress_tolerance", st), ("settlement_tolerance", se)])
    }
}

impl BearingCapacity {
    /// Checks the geometry, the settlements and loads to report, and that the footing is loaded
    /// one way; `key` is the table (`verification`).
    pub fn check(&self, key: &str) -> Checked {
        positive(&at(key, "loaded_width"), self.loaded_width)?;
        if let Some(d) = self.loaded_depth {
            positive(&at(key, "loaded_depth"), d)?;
        }
        if let Some([from, to]) = self.plateau {
            if !(from >= 0.0 && to > from && to.is_finite()) {
                return Err(format!("key `{}`: give 0 ≤ d/B_from < d/B_to, got [{from}, {to}]", at(key, "plateau")));
            }
            if self.failure_settlement.is_some() {
                return Err(format!("key `{}`: give `plateau` or `failure_settlement`, not both", at(key, "plateau")));
            }
        }
        for (f, v) in [("stop_settlement", self.stop_settlement), ("failure_settlement", self.failure_settlement)] {
            if let Some(v) = v {
                positive(&at(key, f), v)?;
            }
        }
        all_positive(key, &[("breadth", self.breadth), ("reference", self.reference), ("tolerance", self.tolerance)])?;
        each_positive(&at(key, "report_settlements"), &self.report_settlements)?;
        each_positive(&at(key, "report_loads"), &self.report_loads)?;
        if self.load.is_some() == self.footing.is_some() {
            return Err(Self::loading_refused(key));
        }
        Ok(())
    }

    /// The message of a footing given both or neither of `load` and `footing`; `key` is the table.
    pub fn loading_refused(key: &str) -> String {
        format!(
            "key `{key}`: a bearing_capacity check takes either `load` (load control) or `footing` (a moving boundary)"
        )
    }

    /// The check in words and numbers.
    pub fn describe(&self) -> String {
        match (self.failure_settlement, self.plateau) {
            (Some(f), _) => format!("bearing capacity: q_ult/c at d/B = {f} against {:.4}", self.reference),
            (None, Some([a, b])) => {
                format!("bearing capacity: q_ult/c, the mean q/c over d/B in [{a}, {b}], against {:.4}", self.reference)
            }
            (None, None) => "load–settlement curve of a footing".into(),
        }
    }
}

impl LargeStrainConsolidation {
    /// Checks the degrees of consolidation and the tolerances; `key` is the table
    /// (`verification`).
    pub fn check(&self, key: &str) -> Checked {
        if self.degrees.is_empty() || self.degrees.iter().any(|u| !(*u > 0.0 && *u < 1.0)) {
            return Err(format!("key `{}`: give degrees of consolidation in (0, 1)", at(key, "degrees")));
        }
        let (e, r, s) = (self.e_p_tolerance, self.p_rms_tolerance, self.settlement_tolerance);
        all_positive(key, &[("e_p_tolerance", e), ("p_rms_tolerance", r), ("settlement_tolerance", s)])
    }
}

impl Patch {
    /// Checks the tolerances; `key` is the table (`verification`).
    pub fn check(&self, key: &str) -> Checked {
        all_positive(key, &[("spread_tolerance", self.spread_tolerance), ("tolerance", self.tolerance)])
    }
}

impl Lame {
    /// Checks the axis, the radii and the tolerances; `key` is the table (`verification`).
    pub fn check(&self, key: &str) -> Checked {
        finite2(&at(key, "center"), self.center)?;
        all_positive(key, &[("inner_radius", self.inner_radius), ("outer_radius", self.outer_radius)])?;
        radii(key, self.inner_radius, self.outer_radius)?;
        let (d, s) = (self.displacement_tolerance, self.stress_tolerance);
        all_positive(key, &[("displacement_tolerance", d), ("stress_tolerance", s)])
    }
}

impl HollowCylinder {
    /// Checks the radii and the tolerances; `key` is the table (`verification`).
    pub fn check(&self, key: &str) -> Checked {
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

    /// The check in words and numbers.
    pub fn describe(&self) -> String {
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
}

impl StiffnessMap {
    /// Checks the centre, the radius and the tolerance; `key` is the table (`verification`).
    pub fn check(&self, key: &str) -> Checked {
        finite2(&at(key, "center"), self.center)?;
        all_positive(key, &[("radius", self.radius), ("tolerance", self.tolerance)])
    }
}

impl VerticalCut {
    /// Checks the points and displacements; `key` is the table (`verification`).
    pub fn check(&self, key: &str) -> Checked {
        for (f, v) in [("toe", self.toe), ("b", self.b), ("c", self.c)] {
            finite2(&at(key, f), v)?;
        }
        positive(&at(key, "stop_displacement"), self.stop_displacement)?;
        each_positive(&at(key, "snapshots"), &self.snapshots)
    }
}

impl CookMembrane {
    /// Checks the tip, the reference and the fit; `key` is the table (`verification`).
    pub fn check(&self, key: &str) -> Checked {
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
}

/// The laboratory series a dam break's front can be compared with.
pub const DAM_BREAK_EXPERIMENTS: [&str; 1] = ["martin_moyce_1952"];

impl DamBreak {
    /// Checks the tolerances, the wall and the experiment; `key` is the table (`verification`).
    pub fn check(&self, key: &str) -> Checked {
        tolerance(&at(key, "hydrostatic_tolerance"), self.hydrostatic_tolerance)?;
        spray(key, self.spray_fraction)?;
        tolerance(&at(key, "front_tolerance"), self.front_tolerance)?;
        if let Some(x) = self.far_wall {
            finite2(&at(key, "far_wall"), [x, 0.0])?;
        }
        match &self.experiment {
            Some(e) if !DAM_BREAK_EXPERIMENTS.contains(&e.as_str()) => Err(format!(
                "key `{}`: unknown experiment `{e}` (known: {})",
                at(key, "experiment"),
                DAM_BREAK_EXPERIMENTS.join(", ")
            )),
            _ => Ok(()),
        }
    }

    /// The check in words and numbers.
    pub fn describe(&self) -> String {
        format!(
            "dam break ([002] §4.3): the hydrostatic pressure at the end of stage `{}`, the mass, the front's \
             advance against the shallow-water speed 2√(gH){}",
            self.settle_stage,
            self.experiment.as_ref().map_or(String::new(), |e| format!(", the front against `{e}`"))
        )
    }
}

impl Runout {
    /// Checks the standing limits, the failed strain and the spray; `key` is the table
    /// (`verification`).
    pub fn check(&self, key: &str) -> Checked {
        let (a, s, f) = (self.standing_advance, self.standing_speed, self.failed_strain);
        all_positive(key, &[("standing_advance", a), ("standing_speed", s), ("failed_strain", f)])?;
        spray(key, self.spray_fraction)
    }
}

impl ShockWave {
    /// Checks the depth and the tolerances; `key` is the table (`verification`).
    pub fn check(&self, key: &str) -> Checked {
        let (d, f, s) = (self.probe_depth, self.fast_tolerance, self.slow_tolerance);
        all_positive(key, &[("probe_depth", d), ("fast_tolerance", f), ("slow_tolerance", s)])
    }
}

fn default_standing_advance() -> f64 {
    0.05
}
fn default_standing_speed() -> f64 {
    0.01
}
fn default_failed_strain() -> f64 {
    0.5
}
fn default_runout_spray() -> f64 {
    1.0e-3
}
fn default_hydrostatic_tol() -> f64 {
    0.02
}
fn default_front_tol() -> f64 {
    0.1
}
fn default_spray() -> f64 {
    0.005
}
fn default_lame_tol() -> f64 {
    0.05
}
fn default_stiffness_map_tol() -> f64 {
    0.01
}
fn default_hollow_stress_tol() -> f64 {
    0.25
}
fn default_spread_tol() -> f64 {
    1e-9
}
fn default_patch_tol() -> f64 {
    1e-6
}
fn default_tv() -> Vec<f64> {
    vec![0.1, 0.5]
}
fn default_ep_tol() -> f64 {
    1e-2
}
fn default_rms_tol() -> f64 {
    5e-2
}
fn default_settle_tol() -> f64 {
    5e-2
}
fn default_periods() -> usize {
    3
}
fn default_us() -> Vec<f64> {
    vec![0.5]
}
fn default_ls_settle_tol() -> f64 {
    0.03
}
fn default_prandtl() -> f64 {
    2.0 + std::f64::consts::PI
}
fn default_bearing_tol() -> f64 {
    0.03
}
fn default_column_tol() -> f64 {
    0.01
}
fn default_cook_tol() -> f64 {
    0.03
}
fn default_cook_radius() -> f64 {
    2.0
}
fn default_fast_tol() -> f64 {
    0.02
}
fn default_slow_tol() -> f64 {
    0.05
}
