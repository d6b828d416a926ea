//! `[stabilisation]`: the stabilisation of the equal-order u–p–U discretisation, the remedies of
//! volumetric locking, and [001]'s mapped stiffnesses and strain recoveries.

use crate::check::{magnitude, Checked, MAX_PROJECTION};
use serde::{Deserialize, Serialize};

/// Stabilisation switches.
#[derive(Debug, Clone, Default, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Stabilisation {
    /// MLSA patch recovery of the pore-pressure increments ([003] §3.3, Eqs. 26–30). Default: off
    /// (`DEFAULT_PATCH_RECOVERY` in the model says what was measured for that choice); cases with
    /// large deformations need it.
    pub patch_recovery: Option<bool>,
    /// B̄ for GIMP ([000] §3, Eqs. 12–16): the volumetric part of B from cell-centre gradients weighted
    /// by the share of the particle domain in each cell. Default: off.
    pub bbar: bool,
    /// [002]'s F̄ by volume-averaged projection ([002] §3, Algorithm 1): each point's step scales
    /// its in-plane deformation increment so that its volume ratio is the volume-weighted average
    /// of the points sharing its nodes, which relieves volumetric locking for any non-negative
    /// basis. In plane strain, without B̄, with the particle stiffness and the basis's strain, in
    /// one-phase explicit stages and in implicit stages that solve u or u–p. Default: off.
    pub fbar: bool,
    /// Pressure-projection stabilisation of the equal-order pressure (Bochev & Dohrmann 2006): the
    /// factor α of τ = α/G (G the skeleton's shear modulus) in the cell-wise penalty on the
    /// non-constant part of the pressure increment [-], in (0, 1e3]. Default: none.
    pub pressure_projection: Option<f64>,
    /// How a particle's pore pressure follows a converged step (two-phase): `increments` (the
    /// default: p += the interpolated, or patch-recovered, increment) or `projected_total` (p is
    /// the interpolation of the total nodal field P + Δp, P the consistent L² projection of the
    /// particles' pressures onto the nodal functions, so that whatever the nodes cannot represent
    /// does not accumulate on the particles). Not with `patch_recovery`.
    pub pressure_update: PressureUpdate,
    /// How the skeleton's material stiffness enters the Newton matrix ([001] §5,
    /// docs/axisymmetry.md): `particle` (the default: the exact tangent, integrated at the points),
    /// `w_star` (points weighted as if their cell were exactly full, [001] Eq. 15),
    /// `gauss_mapping` (the points' moduli mapped to the cell's nodes and from there to its 2 × 2
    /// Gauss points, Eq. 19 with W), `double_mapping` (the same with W*, Eq. 19) or
    /// `double_mapping_gimp` (with the local GIMP weights, Eq. 20; GIMP bases only). Every
    /// option but `particle` is an approximate Jacobian: Newton converges to the same answer, at a
    /// linear rate; with `-snes_type ksponly` a step is [001]'s single linear solve. Plane cases
    /// with the linear or GIMP bases only.
    pub stiffness: Stiffness,
    /// Where a mapped `stiffness` serves: `jacobian` (the default: it is Newton's matrix, [001]'s
    /// scheme, converging linearly) or `diagnostics` (only the nodal K_mag diagnostic is computed
    /// with it; Newton keeps the exact tangent and converges quadratically to the same answer,
    /// since the residual is the same).
    pub mapped_stiffness: MappedStiffnessUse,
    /// How a point's strain increment is recovered from the nodal displacements ([001] §5.5):
    /// `basis` (the default: with the gradients of the point's basis functions, as its forces are
    /// integrated) or `cmpm` (composite MPM: the higher-order Lagrange patch functions of [001]
    /// Eqs. 22–23 (corrected) over the point's cell and its well-filled neighbours, cubic, quadratic
    /// or linear per direction; one-phase plane cases, without B̄) or `mapped` (with the
    /// double-mapped operators of `internal_force = "mapped"`, which it needs: each point's strain
    /// is the finite-element strain of the cells it maps to, averaged over their Gauss points with
    /// the point's weights there, the transpose of its forces, so that the point's force and strain
    /// are one Galerkin pair and its tangent is symmetric). The residual keeps the basis for the
    /// forces unless `internal_force` says otherwise, and its tangent stays exact.
    pub stress_recovery: StressRecovery,
    /// How the skeleton's internal force is integrated: `particle` (the default: at the points with
    /// the basis's gradients, F_i = Σ_p B_i(x_p)ᵀ σ_p V_p) or `mapped` (double-mapped like the
    /// stiffness: each point's stress goes to the nodes of the cells it maps to with the weights
    /// of `stabilisation.stiffness`, σ_i^e = Σ_p w_ip W_p σ_p, from there to the cell's 2 × 2 Gauss
    /// points, σ_g = Σ_i N_i(x_g) σ_i^e, and F_e = Σ_g B_gᵀ σ_g |J|, as [001] Eqs. 16–20 map D_p).
    /// Needs a mapped `stiffness` (`gauss_mapping`, `double_mapping` or `double_mapping_gimp`), a
    /// one-phase plane case without B-splines; the residual and its exact tangent change together.
    pub internal_force: InternalForce,
    /// The control of the modes CMPM's recovered strain filters (`stress_recovery = "cmpm"`): a
    /// factor α ≥ 0 [-] of a stiffness on the difference between the strain of each
    /// step's increment by the point's basis and by its patch, α V e : C : e / 2 with C the
    /// material's elastic stiffness (docs/stiffness.md). 0, the default, adds nothing; a field
    /// both reproduce (every linear one) is not touched.
    pub filtered_mode_control: f64,
}

/// How the skeleton's internal force is integrated (see [`Stabilisation::internal_force`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum InternalForce {
    /// At the material points with the basis's gradients.
    #[default]
    Particle,
    /// Double-mapped to the cells' Gauss points with the mapped stiffness's weights.
    Mapped,
}

/// How a point's strain is recovered (see [`Stabilisation::stress_recovery`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum StressRecovery {
    /// With the gradients of the point's basis functions.
    #[default]
    Basis,
    /// With [001]'s CMPM patch functions.
    Cmpm,
    /// With the double-mapped force operators (`internal_force = "mapped"`), so that the strain
    /// operator is the forces' transpose.
    Mapped,
}

/// Where a mapped stiffness serves (see [`Stabilisation::mapped_stiffness`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum MappedStiffnessUse {
    /// Newton's matrix and the K_mag diagnostic.
    #[default]
    Jacobian,
    /// The K_mag diagnostic only.
    Diagnostics,
}

/// The material stiffness of the Newton matrix (see [`Stabilisation::stiffness`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Stiffness {
    /// The exact tangent, integrated at the material points.
    #[default]
    Particle,
    /// Particle integration with the weights W* = W omp/cmp ([001] Eq. 15).
    WStar,
    /// Gauss mapping GM ([001] Eq. 19 with W_p).
    GaussMapping,
    /// Double mapping DM ([001] Eq. 19 with W*_p).
    DoubleMapping,
    /// Double mapping with local GIMP weights DM-G ([001] Eq. 20).
    DoubleMappingGimp,
}

impl Stiffness {
    /// The name the case file gives it.
    pub fn name(self) -> &'static str {
        match self {
            Stiffness::Particle => "particle",
            Stiffness::WStar => "w_star",
            Stiffness::GaussMapping => "gauss_mapping",
            Stiffness::DoubleMapping => "double_mapping",
            Stiffness::DoubleMappingGimp => "double_mapping_gimp",
        }
    }

    /// Whether it maps the points' moduli to the cells' Gauss points (GM, DM, DM-G), the
    /// stiffnesses whose weights a mapped internal force can use.
    pub fn is_mapped(self) -> bool {
        matches!(self, Stiffness::GaussMapping | Stiffness::DoubleMapping | Stiffness::DoubleMappingGimp)
    }
}

/// How a particle's pore pressure follows a converged step (see [`Stabilisation::pressure_update`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum PressureUpdate {
    /// p_{n+1} = p_n + Σ S_i Δp_i (or its MLSA recovery).
    #[default]
    Increments,
    /// p_{n+1} = Σ S_i (P_i + Δp_i), M P = Σ_p V_p S p_n with the consistent M.
    ProjectedTotal,
}

impl Stabilisation {
    /// The material stiffness of Newton's matrix: `stiffness`, or the exact tangent (`particle`)
    /// when the mapped stiffness serves the diagnostics only.
    pub fn jacobian_stiffness(&self) -> Stiffness {
        match self.mapped_stiffness {
            MappedStiffnessUse::Jacobian => self.stiffness,
            MappedStiffnessUse::Diagnostics => Stiffness::Particle,
        }
    }

    /// Checks the factor's range and the switches that exclude or need each other; `key` is the
    /// table (`stabilisation`). What depends on the formulation, the basis and the stages,
    /// validation checks.
    pub fn check(&self, key: &str) -> Checked {
        if let Some(alpha) = self.pressure_projection {
            let why = "beyond it the penalty swamps the coupling it stabilises";
            magnitude(&format!("{key}.pressure_projection"), alpha, MAX_PROJECTION, "times 1/G", why)?;
        }
        if self.pressure_update == PressureUpdate::ProjectedTotal && self.patch_recovery == Some(true) {
            return Err(format!(
                "keys `{key}.pressure_update = \"projected_total\"` and `{key}.patch_recovery = true` exclude each \
                 other: choose one way to update the particles' pressure"
            ));
        }
        if self.mapped_stiffness == MappedStiffnessUse::Diagnostics && self.stiffness == Stiffness::Particle {
            return Err(format!(
                "key `{key}.mapped_stiffness`: `diagnostics` computes K_mag with a mapped `{key}.stiffness`, and the \
                 case has `particle`"
            ));
        }
        if self.fbar {
            self.check_fbar(key)?;
        }
        if !(self.filtered_mode_control >= 0.0 && self.filtered_mode_control.is_finite()) {
            return Err(format!(
                "key `{key}.filtered_mode_control`: a factor of the elastic stiffness, finite and not negative; got {}",
                self.filtered_mode_control
            ));
        }
        if self.filtered_mode_control > 0.0 && self.stress_recovery != StressRecovery::Cmpm {
            return Err(format!(
                "key `{key}.filtered_mode_control`: controls the modes CMPM's recovered strain filters; set \
                 `{key}.stress_recovery = \"cmpm\"` (with the basis's own strain, or the mapped force's transpose, no mode \
                 is filtered)"
            ));
        }
        if self.stress_recovery == StressRecovery::Cmpm && self.bbar {
            return Err(format!(
                "keys `{key}.stress_recovery = \"cmpm\"` and `{key}.bbar = true` exclude each other: the CMPM patch \
                 recovers the whole strain, B̄ would replace its volumetric part"
            ));
        }
        match (self.internal_force, self.stress_recovery) {
            (InternalForce::Mapped, _) if !self.stiffness.is_mapped() => Err(format!(
                "key `{key}.internal_force`: `mapped` maps the points' stresses with the weights of a mapped \
                 stiffness, and `{key}.stiffness` is `{}`; choose `gauss_mapping`, `double_mapping` or \
                 `double_mapping_gimp`",
                self.stiffness.name()
            )),
            (InternalForce::Particle, StressRecovery::Mapped) => Err(format!(
                "key `{key}.stress_recovery`: `mapped` recovers the strain with the double-mapped force operators; \
                 set `{key}.internal_force = \"mapped\"` too"
            )),
            _ => Ok(()),
        }
    }

    /// What F̄ excludes among the other switches.
    fn check_fbar(&self, key: &str) -> Checked {
        if self.stiffness != Stiffness::Particle || self.stress_recovery == StressRecovery::Cmpm {
            return Err(format!(
                "key `{key}.fbar`: F̄ is built with the particle-integrated tangent and the basis's own strain; \
                 [001]'s stiffness options and CMPM recovery are for cases without it"
            ));
        }
        if self.bbar {
            return Err(format!(
                "keys `{key}.fbar` and `{key}.bbar` exclude each other: both replace the volumetric deformation"
            ));
        }
        Ok(())
    }
}
