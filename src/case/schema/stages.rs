//! `[[stages]]`, `[time]` and `[time_integration]`: what each stage solves, its steps, and the
//! time schemes of dynamic and explicit stages.

use crate::check::{at, in_open, positive, Checked};
use crate::layout::Layout;
use serde::{Deserialize, Serialize};

/// Time-stepping defaults (`--set time.dt=5e-4` changes the step of every stage that has none
/// of its own).
#[derive(Debug, Clone, Default, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Time {
    /// Time step of the stages that do not give their own `dt` [s], > 0.
    pub dt: Option<f64>,
}

/// One analysis stage.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Stage {
    /// The name shown in progress and history, and that the verification gives to use it.
    pub name: String,
    /// Duration [s], > 0.
    pub duration: f64,
    /// Time step Δt [s], in (0, duration], at most 1e8 steps in the stage (default: `time.dt`;
    /// one of them is required).
    pub dt: Option<f64>,
    /// The names of the boundaries active in this stage (default: all).
    pub boundaries: Option<Vec<String>>,
    /// The names of the loads active in this stage (default: all).
    pub loads: Option<Vec<String>>,
    /// How many times in a row a step may be cut before the run fails [-], at most 30 (default 4).
    #[serde(default = "default_cuts")]
    pub max_step_cuts: usize,
    /// The factor applied to Δt at each cut [-], in (0, 1) (default 0.5).
    #[serde(default = "default_cut_factor")]
    pub cut_factor: f64,
    /// What the stage solves: `dynamic` (the default: inertia, the u–p–U system in two-phase
    /// cases), `quasi_static` (two-phase only: no inertia, the u–p Biot system with Darcy's law,
    /// θ-method in time), `static` (no inertia and no flow: one-phase, or two-phase with
    /// `drainage`) or `dynamic_explicit` (explicit MPM, update-stress-last, with the stage's
    /// `explicit` settings; [002] §2.2).
    #[serde(default)]
    pub analysis: AnalysisType,
    /// θ of a quasi-static stage's Darcy flux [-], in [1/2, 1] (default 1, backward Euler: no
    /// oscillation at large Δt; 1/2 is second order but rings when c_v Δt/h² ≫ 1). Only
    /// `quasi_static` stages take it.
    pub theta: Option<f64>,
    /// The water in a static stage of a two-phase case (required there, and taken nowhere else):
    /// `drained` (the pore pressure is held; the u system) or `undrained` (no flow: the u–p
    /// system without Darcy's law).
    pub drainage: Option<Drainage>,
    /// The largest step the stage may grow to after easy steps (at most 3 Newton iterations, a
    /// few in a row) [s], finite and at least `dt` (default: `dt`, no growth beyond it).
    pub dt_max: Option<f64>,
    /// The time integration of this stage (default: the case's `time_integration`); only
    /// `dynamic` stages take it. A settling stage can damp the transient of an unbalanced initial
    /// state numerically, e.g. `{ beta = 0.49, gamma = 0.9 }` with a Δt near the lowest period of
    /// the soil.
    pub time_integration: Option<TimeIntegration>,
    /// The explicit integrator's settings of a `dynamic_explicit` stage (defaults if absent); only
    /// such stages take it.
    pub explicit: Option<Explicit>,
    /// The strength reduction factor F of this stage [-], in (0, 100] (default 1: the case's
    /// strengths): from the stage's start every material's peak strength is the case's divided by
    /// F (c_p/F, and φ' = atan(tan φ/F) with ψ ≤ φ'), as in the strength reduction of slope
    /// analyses (Griffiths & Lane 1999; [002] §4.4 triggers its landslide with F = 1.65 on the
    /// peak strength). Residual strengths stay as given unless above the reduced peak, where they
    /// take it. Each stage reduces the case's strengths afresh (factors do not compound); the
    /// points keep their stress and accumulated plastic strain, so a point beyond the reduced
    /// strength returns to it in its next update.
    pub strength_reduction: Option<f64>,
}

/// Settings of the explicit integrator ([002] §2.2, §4).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Explicit {
    /// Courant number C [-], in (0, 1]: the step is at most C h_min / c_p, with c_p = sqrt(E_c/ρ)
    /// the largest P-wave speed of the materials at rest ([002] uses 0.3 and 0.4). The stage's
    /// `dt` caps it further.
    #[serde(default = "default_cfl")]
    pub cfl: f64,
    /// FLIP share η of the particle velocity update, v_p ← η FLIP + (1 − η) PIC ([002] Eq. 13;
    /// 1 is pure FLIP, [002]'s default; Cook's membrane used 0.85) [-], in [0, 1].
    #[serde(default = "default_flip")]
    pub flip_blend: f64,
    /// Local damping α (Al-Kafaji 2013): each free nodal force component f is reduced by
    /// α |f| sign(v) ([002] used 0.002 for the footing) [-], in [0, 1) (default 0).
    #[serde(default)]
    pub local_damping: f64,
    /// The order m of the extended PIC transfer XPIC(m) of Hammerquist & Nairn (2017), which
    /// replaces the FLIP/PIC blend: v_p ← S(v^{n+1} − v^n + w) with
    /// w = Σ_{k=1..m} (−1)^{k+1} C(m, k) (S⁺S)^{k−1} v^n, S⁺S the map of nodal velocities to the
    /// points and back (mass-weighted). m = 1 is PIC; a larger m keeps more of FLIP's
    /// resolved motion while filtering the particle velocities the grid cannot see (the null
    /// space that lets pure FLIP ring), at m − 1 extra passes over the points per step. In
    /// [1, 8], one-phase stages only; default: none (the blend). Hammerquist & Nairn suggest 2
    /// to 5.
    pub xpic_order: Option<u8>,
    /// Where a two-phase stage's pore pressure lives (the u–U system: both phases' motion at
    /// the nodes). `pointwise` (default): each point keeps its own increment Δp_p from its
    /// continuity equation (the "v–w" form of single-point explicit codes); a free surface drains
    /// by itself and no boundary may fix `p`. Stable however stiff the water and however low the
    /// permeability (Terzaghi's column at k = 1e-12 m/s: the undrained pressure within 0.05 %),
    /// but first order in h: about one pressure per cell (Terzaghi: RMS pressure error 1.4e-2 at
    /// 10 cells, 8.0e-3 at 20). `nodal`: the continuity equation ([003] Eq. 23b) with its storage
    /// lumped, solved node by node, Δp_i = Σ_p S_ip (V/Q)_p Δp_p / Σ_p S_ip (V/Q)_p, zero at
    /// drained nodes (a boundary fixing `p`, or a node the material barely fills, as in implicit
    /// stages), each point taking Σ_i S_ip Δp_i: the equal-order pressure of the implicit u–p–U
    /// system, second order where the water drains (Terzaghi: 1.1e-3 at 10 cells, 3.0e-4 at 20)
    /// but, like it without stabilisation, not inf–sup stable: near undrained conditions the
    /// pressure alternates (Terzaghi at k = 1e-12 m/s: 0.61 and 1.41 times the undrained
    /// pressure at two points). One-phase stages take neither.
    pub pore_pressure: Option<ExplicitPressure>,
}

/// Where the pore pressure of a two-phase explicit stage lives (see [`Explicit::pore_pressure`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ExplicitPressure {
    /// Each point's own increment (the default).
    Pointwise,
    /// Nodal increments from the lumped continuity equation.
    Nodal,
}

impl Default for Explicit {
    fn default() -> Self {
        Explicit {
            cfl: default_cfl(),
            flip_blend: default_flip(),
            local_damping: 0.0,
            xpic_order: None,
            pore_pressure: None,
        }
    }
}

serde_defaults! { default_cfl: f64 = 0.5, default_flip: f64 = 1.0 }

/// What a stage solves (see [`Stage::analysis`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum AnalysisType {
    /// Inertia; u–p–U (two-phase) or u.
    #[default]
    Dynamic,
    /// No inertia; u–p with Darcy's law (two-phase cases only).
    QuasiStatic,
    /// No inertia, no flow.
    Static,
    /// Explicit dynamics ([002]).
    DynamicExplicit,
}

/// The water in a static stage of a two-phase case.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Drainage {
    /// The pore pressure is held at its value at the start of the stage (the skeleton alone
    /// carries the load change).
    Drained,
    /// No flow: the pore pressure changes with the volume (u–p without Darcy's law).
    Undrained,
}

serde_defaults! { default_cuts: usize = 4, default_cut_factor: f64 = 0.5 }

/// The time integration of dynamic stages: the generalized-α method of Chung & Hulbert (1993) with
/// spectral radius `rho_inf` (default 0.2, [`DEFAULT_RHO_INF`]), or Newmark ([003] Eqs. 20–22)
/// when `scheme = "newmark"` or `beta`/`gamma` are given.
#[derive(Debug, Clone, Default, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TimeIntegration {
    /// `generalized_alpha` (the default) or `newmark`.
    pub scheme: Option<TimeScheme>,
    /// Newmark's β [-], with 2β ≥ γ and β ≤ 1 (default 1/4: average acceleration); Newmark only.
    pub beta: Option<f64>,
    /// Newmark's γ [-], ≥ 1/2 (default 1/2: no numerical damping); Newmark only.
    pub gamma: Option<f64>,
    /// Spectral radius at infinite frequency ρ∞ of the generalized-α method [-], in [0, 1]: 1
    /// damps nothing, 0 annihilates the highest frequencies in one step (default 0.2).
    pub rho_inf: Option<f64>,
}

/// A dynamic time-integration scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum TimeScheme {
    /// Chung & Hulbert (1993).
    GeneralizedAlpha,
    /// Newmark (1959).
    Newmark,
}

/// ρ∞ of the generalized-α method when a case gives none. Measured on the Terzaghi column with 80
/// cells (c_v Δt/h² = 6.5), where Newmark's pore pressure alternates by 0.7 of the load from step
/// to step for the whole run: the alternation falls below 1e-3 of the load after 43 steps with
/// ρ∞ = 0.5, 24 with 0.3, 17 with 0.2, 11 with 0; the harmonic column of zone III (short waves)
/// loses accuracy as ρ∞ falls: amplitude error 1.2e-2 (Newmark), 1.4e-2 (0.5), 2.6e-2 (0.2),
/// 4.3e-2 (0). 0.2 is the largest ρ∞ that damps the alternation within 20 steps
/// (docs/analysis.md).
pub const DEFAULT_RHO_INF: f64 = 0.2;

impl TimeIntegration {
    /// Whether the parameters ask for Newmark.
    pub fn is_newmark(&self) -> bool {
        self.scheme == Some(TimeScheme::Newmark) || self.beta.is_some() || self.gamma.is_some()
    }

    /// Newmark's (β, γ) (defaults 1/4, 1/2).
    pub fn newmark(&self) -> (f64, f64) {
        (self.beta.unwrap_or(0.25), self.gamma.unwrap_or(0.5))
    }

    /// The generalized-α method's ρ∞ (default [`DEFAULT_RHO_INF`]).
    pub fn spectral_radius(&self) -> f64 {
        self.rho_inf.unwrap_or(DEFAULT_RHO_INF)
    }

    /// The kernels' form of these parameters: Newmark's method when the table names it or gives
    /// β or γ, else the generalized-α method.
    pub fn integration(&self) -> crate::scheme::Integration {
        if self.is_newmark() {
            let (beta, gamma) = self.newmark();
            crate::scheme::Integration::newmark(beta, gamma)
        } else {
            crate::scheme::Integration::generalized_alpha(self.spectral_radius())
        }
    }

    /// Checks that the scheme is one and unconditionally stable (Newmark's average-acceleration
    /// family needs 2β ≥ γ ≥ 1/2); `key` is the table (`time_integration`).
    pub fn check(&self, key: &str) -> Checked {
        if let Some(r) = self.rho_inf {
            if !(0.0..=1.0).contains(&r) {
                return Err(format!("key `{key}.rho_inf`: ρ∞ = {r} must lie in [0, 1]"));
            }
            if self.is_newmark() {
                return Err(format!(
                    "key `{key}`: give either `rho_inf` (generalized-α, which sets β and γ) or `beta`/`gamma` (Newmark), not both"
                ));
            }
        }
        if self.scheme == Some(TimeScheme::GeneralizedAlpha) && (self.beta.is_some() || self.gamma.is_some()) {
            return Err(format!("key `{key}`: the generalized-α method takes `rho_inf`, not `beta`/`gamma`"));
        }
        let (beta, gamma) = self.newmark();
        if self.is_newmark() && !(gamma >= 0.5 && 2.0 * beta >= gamma && beta <= 1.0) {
            return Err(format!(
                "key `{key}`: β = {beta}, γ = {gamma} is not unconditionally stable; use 2β ≥ γ ≥ 1/2 (default β = 1/4, γ = 1/2)"
            ));
        }
        Ok(())
    }
}

impl Stage {
    /// The unknowns per node of the stage (in two dimensions; [`Layout::in_dim`] gives the others):
    /// u, u–p (quasi-static, undrained static) or u–p–U (dynamic two-phase), each with the
    /// projected volume ratio of an implicit F̄ step where it has that form (u and u–p), or u–U in
    /// an explicit two-phase stage. `pore_water` and `fbar` are the case's formulation and
    /// `stabilisation.fbar`.
    pub fn layout(&self, pore_water: bool, fbar: bool) -> Layout {
        let layout = match self.analysis {
            AnalysisType::Dynamic if pore_water => Layout::UPU,
            AnalysisType::QuasiStatic => Layout::UP,
            AnalysisType::Static if pore_water && self.drainage == Some(Drainage::Undrained) => Layout::UP,
            AnalysisType::DynamicExplicit if pore_water => return Layout::UW,
            AnalysisType::DynamicExplicit => return Layout::U,
            _ => Layout::U,
        };
        match layout.with_fbar() {
            Some(with) if fbar => with,
            _ => layout,
        }
    }

    /// The stage's time step [s]: its own `dt`, else `time.dt` (validation fills it in).
    pub fn dt(&self) -> f64 {
        self.dt.unwrap_or(f64::NAN)
    }

    /// Checks the stage's own values and what its analysis type takes; `key` is its table
    /// (`stages[0]`), and the keys of its analysis's settings are named by the stage's name
    /// (`stages.consolidation.theta`). What depends on the formulation, validation checks.
    pub fn check(&self, key: &str) -> Checked {
        let k = |f: &str| at(key, f);
        positive(&k("duration"), self.duration)?;
        positive(&k("dt"), self.dt())?;
        if self.dt() > self.duration * (1.0 + 1e-12) {
            return Err(format!("key `{}`: Δt = {} exceeds the stage duration {}", k("dt"), self.dt(), self.duration));
        }
        if self.duration / self.dt() > 1e8 {
            return Err(format!("key `{}`: more than 1e8 steps in the stage", k("dt")));
        }
        in_open(&k("cut_factor"), self.cut_factor, 0.0, 1.0)?;
        if self.max_step_cuts > 30 {
            return Err(format!("key `{}`: at most 30, got {}", k("max_step_cuts"), self.max_step_cuts));
        }
        self.check_settings(&format!("stages.{}", self.name))
    }

    /// The settings of the stage's analysis type: each taken only by the type it belongs to, and
    /// in its range; `key` names the stage by its name.
    fn check_settings(&self, key: &str) -> Checked {
        let k = |f: &str| at(key, f);
        if let Some(th) = self.theta {
            if self.analysis != AnalysisType::QuasiStatic {
                return Err(format!("key `{}`: only a quasi_static stage takes `theta`", k("theta")));
            }
            if !(0.5..=1.0).contains(&th) {
                return Err(format!("key `{}`: θ = {th} must lie in [1/2, 1] (1: backward Euler)", k("theta")));
            }
        }
        match (self.analysis, &self.explicit) {
            (AnalysisType::DynamicExplicit, e) => e.unwrap_or_default().check(&k("explicit"))?,
            (_, Some(_)) => {
                return Err(format!("key `{}`: only a dynamic_explicit stage takes `explicit`", k("explicit")))
            }
            (_, None) => {}
        }
        if let Some(f) = self.strength_reduction.filter(|&f| !(f > 0.0 && f <= 100.0)) {
            return Err(format!(
                "key `{}`: the strength reduction factor F = {f} must lie in (0, 100] (the strengths are divided \
                 by F)",
                k("strength_reduction")
            ));
        }
        if let Some(ti) = &self.time_integration {
            ti.check(&k("time_integration"))?;
            if self.analysis != AnalysisType::Dynamic {
                return Err(format!("key `{}`: only a dynamic stage takes `time_integration`", k("time_integration")));
            }
        }
        match self.dt_max {
            Some(m) if !(m.is_finite() && m >= self.dt()) => Err(format!(
                "key `{}`: {m} s must be finite and at least the stage's Δt = {} s",
                k("dt_max"),
                self.dt()
            )),
            _ => Ok(()),
        }
    }
}

impl Explicit {
    /// Checks the ranges of the explicit settings; `key` is their table
    /// (`stages.NAME.explicit`).
    pub fn check(&self, key: &str) -> Checked {
        let k = |f: &str| at(key, f);
        if !(self.cfl > 0.0 && self.cfl <= 1.0) {
            return Err(format!(
                "key `{}`: C = {} must lie in (0, 1] (the explicit step's stability limit is C = 1)",
                k("cfl"),
                self.cfl
            ));
        }
        if !(0.0..=1.0).contains(&self.flip_blend) {
            return Err(format!("key `{}`: η = {} must lie in [0, 1]", k("flip_blend"), self.flip_blend));
        }
        if let Some(m) = self.xpic_order {
            if !(1..=8).contains(&m) {
                return Err(format!("key `{}`: m = {m} must lie in [1, 8]", k("xpic_order")));
            }
            if self.flip_blend != 1.0 {
                return Err(format!(
                    "key `{}`: XPIC (`xpic_order`) replaces the FLIP/PIC blend; leave flip_blend out",
                    k("flip_blend")
                ));
            }
        }
        if !(0.0..1.0).contains(&self.local_damping) {
            return Err(format!("key `{}`: α = {} must lie in [0, 1)", k("local_damping"), self.local_damping));
        }
        Ok(())
    }
}
