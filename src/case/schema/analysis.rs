//! `[analysis]` and `[grid]`: the physics switches that shape the discrete system, and the
//! background grid.

use crate::check::{finite2, positive, Checked};
use serde::{Deserialize, Serialize};

/// Physics switches.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Analysis {
    /// `two_phase`: the soil's skeleton and its pore water (the u–p–U system of dynamic stages);
    /// `one_phase`: the total-stress u system (a dry or undrained material, a solid, a fluid).
    pub formulation: Formulation,
    /// Basis functions: `gimp` (the default; GIMP, [003] Eqs. 13–15, with particle domains that
    /// follow the material stretch as in iGIMP), `ugimp` (GIMP with the undeformed domains),
    /// `linear` (standard MPM), `bspline2` or `bspline3` (quadratic or cubic B-splines).
    #[serde(default = "default_shape")]
    pub shape_functions: ShapeFunctions,
    /// Gravitational acceleration g [m/s²], > 0 (default 9.81), used in Darcy's law (γ_w = ρ_w g)
    /// and by geostatic initial stresses. It is a material constant here; gravity as a load is a
    /// `body_force` load.
    #[serde(default = "default_g")]
    pub g: f64,
    /// `plane_strain` (the default) or `axisymmetric`: x is then the radius r ≥ 0 and y the axis of
    /// revolution; the hoop strain u_r/r enters every strain and divergence, and volumes, masses
    /// and loads are those of the full ring (2πr times the area in the (r, y) plane). Nodes on the
    /// axis (r = 0) have u_r = 0 (and U_r = 0) without a boundary saying so.
    #[serde(default)]
    pub geometry: Geometry,
    /// How an axisymmetric GIMP analysis weights a particle in r: `r_weighted` (the default; the
    /// particle's characteristic function integrated with the measure r dr, which distributes mass
    /// and volume with the ring's weight and is exact next to the axis) or `planar` (the planar
    /// GIMP functions with the hoop operator S_i/r_p). Both reproduce the strains of
    /// u_r = α + βr exactly; the linear basis and the B-splines have one form (their functions at
    /// the point with the hoop operator S_i/r_p). See docs/axisymmetry.md.
    #[serde(default)]
    pub axisymmetric_weights: AxisymmetricWeights,
    /// The kinematics of a step: `finite_strain` (the default: forces on the configuration at the
    /// step's end, the objective Hughes–Winget update, the exact tangent with its geometric terms)
    /// or `linear_increments` ([001] Eqs. 5, 7, 11: each step is geometrically linear on the
    /// configuration at its start, Δε = sym ∇Δu, σ_{n+1} = σ_n + Δσ without rotation, forces
    /// Bᵀσ V_n; the points still move and their volumes and domains update between steps, an
    /// updated Lagrangian of small-strain increments). `linear_increments` is for one-phase
    /// cases whose stages are all static.
    #[serde(default)]
    pub kinematics: KinematicsKind,
}

/// The kinematics of a step (see `Analysis::kinematics`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum KinematicsKind {
    /// Finite strain on the step's end configuration.
    #[default]
    FiniteStrain,
    /// Geometrically linear steps on the step's start configuration ([001]).
    LinearIncrements,
}

/// The geometry of the (x, y) plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Geometry {
    /// Plane strain: ε_zz = 0, volumes per metre of thickness.
    #[default]
    PlaneStrain,
    /// Axial symmetry about the y axis: x ≡ r ≥ 0, hoop strain u_r/r, ring volumes 2πrA.
    Axisymmetric,
}

/// How an axisymmetric GIMP analysis weights a particle in r.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum AxisymmetricWeights {
    /// Planar GIMP functions, hoop operator S_i / r_p.
    Planar,
    /// GIMP functions integrated with the measure r dr.
    #[default]
    RWeighted,
}

serde_defaults! { default_shape: ShapeFunctions = ShapeFunctions::Gimp, default_g: f64 = 9.81 }

/// The discrete system to build.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Formulation {
    /// Solid displacement, pore pressure, water displacement per node (u–p–U).
    TwoPhase,
    /// Solid displacement only (total stress, or dry material).
    OnePhase,
}

/// Material-point basis functions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ShapeFunctions {
    /// GIMP whose particle domains follow the deformation: the half-widths are
    /// l_p = l_p0 ⊙ diag(U) with U = sqrt(FᵀF) the right stretch tensor (Charlton, Coombs & Augarde
    /// 2017, iGIMP; as in AMPLE), starting from l_p0 = h / (2 × particles per cell). The domain then
    /// keeps the particle's volume under compression or extension along the grid axes, so a surface
    /// particle's domain ends at the material's surface.
    Gimp,
    /// Undeformed GIMP (uGIMP): the domains keep l_p0 for the whole run. Adequate for small strains;
    /// under large compression the domain outgrows the particle's volume.
    Ugimp,
    /// Standard MPM: bilinear hat functions evaluated at the particle.
    Linear,
    /// Quadratic B-splines centred on the nodes ([002] §2.2.1; C¹, 3 × 3 nodes per particle),
    /// modified at the grid's edges so that they stay a partition of unity, reproduce linear
    /// fields and are interpolatory there. The points' domains (used for cell fractions and B̄)
    /// follow the stretch as with `gimp`.
    Bspline2,
    /// Cubic B-splines centred on the nodes (C², 4 × 4 nodes per particle), with the same edge
    /// treatment.
    Bspline3,
}

impl Analysis {
    /// Checks g; `key` is the table (`analysis`).
    pub fn check(&self, key: &str) -> Checked {
        positive(&format!("{key}.g"), self.g)
    }
}

/// A uniform structured background grid: two entries per key for a plane (or axisymmetric) case,
/// three for a three-dimensional one (y is vertical in every dimension: gravity acts along −y, z
/// is the second horizontal direction).
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Grid {
    /// Lower-left (-back) corner [m], finite (default: the origin).
    #[serde(default)]
    pub origin: Vec<f64>,
    /// Extent in x, y (and z) [m], each > 0; its number of entries is the case's dimension.
    pub size: Vec<f64>,
    /// Number of cells in x, y (and z), each in [1, 100000].
    pub cells: Vec<usize>,
}

impl Grid {
    /// Checks the number of entries of each key and their ranges; `key` is the table (`grid`).
    pub fn check(&self, key: &str) -> Checked {
        let dim = self.size.len();
        if dim != 2 && dim != 3 {
            return Err(format!(
                "key `{key}.size`: two entries (a plane or axisymmetric case) or three (a three-dimensional one), \
                 got {dim}"
            ));
        }
        for (field, n) in [("origin", self.origin.len()), ("cells", self.cells.len())] {
            if n != dim && !(field == "origin" && n == 0) {
                return Err(format!("key `{key}.{field}`: {dim} entries, as `{key}.size` has, got {n}"));
            }
        }
        finite2(&format!("{key}.origin"), std::array::from_fn(|d| self.origin.get(d).copied().unwrap_or(0.0)))?;
        for d in 0..dim {
            positive(&format!("{key}.size[{d}]"), self.size[d])?;
            if self.cells[d] == 0 || self.cells[d] > 100_000 {
                return Err(format!("key `{key}.cells[{d}]`: must be between 1 and 100000, got {}", self.cells[d]));
            }
        }
        Ok(())
    }
}
