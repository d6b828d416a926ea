//! The case-file schema: every table and key a case may contain, with units.
//!
//! All structs deny unknown fields, so a misspelt key is an error naming it. Ranges are checked
//! in [`super::validate`]. SI units throughout: m, s, kg, Pa, m/s.

use serde::{Deserialize, Serialize};

/// A whole case: what is simulated, how, and what it is checked against.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Named numbers used by `"= expression"` values elsewhere in the file (see
    /// [`super::parameters`]); `--set parameters.NAME=VALUE` changes them.
    #[serde(default)]
    pub parameters: std::collections::BTreeMap<String, f64>,
    /// Physics switches that shape the discrete system.
    pub analysis: Analysis,
    /// The background grid.
    pub grid: Grid,
    /// Materials, referred to by name from bodies.
    pub materials: Vec<Material>,
    /// Bodies filled with material points at t = 0.
    pub bodies: Vec<Body>,
    /// Named time functions that scale loads.
    #[serde(default)]
    pub time_functions: Vec<TimeFunction>,
    /// Dirichlet conditions on grid nodes.
    #[serde(default)]
    pub boundaries: Vec<Boundary>,
    /// Loads (tractions, body forces).
    #[serde(default)]
    pub loads: Vec<Load>,
    /// Stabilisation of the equal-order u–p–U discretisation and of volumetric locking.
    #[serde(default)]
    pub stabilisation: Stabilisation,
    /// Time-stepping defaults shared by the stages.
    #[serde(default)]
    pub time: Time,
    /// The analysis stages, run in order.
    pub stages: Vec<Stage>,
    /// Newmark parameters.
    #[serde(default)]
    pub time_integration: TimeIntegration,
    /// Solver strategy (PETSc options file).
    #[serde(default)]
    pub solver: Solver,
    /// Output control.
    #[serde(default)]
    pub output: Output,
    /// Material points whose history is recorded.
    #[serde(default)]
    pub probes: Vec<Probe>,
    /// The analytical solution the run is checked against, if any.
    #[serde(default)]
    pub verification: Option<Verification>,
}

/// Physics switches.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Analysis {
    /// `two_phase`: the u–p–U system (5 dofs per node); `one_phase`: total-stress u system (2 dofs).
    pub formulation: Formulation,
    /// Basis functions: `gimp` (GIMP, [003] Eqs. 13–15, with particle domains that follow the
    /// material stretch as in iGIMP), `ugimp` (GIMP with the undeformed domains) or `linear`
    /// (standard MPM).
    #[serde(default = "default_shape")]
    pub shape_functions: ShapeFunctions,
    /// Gravitational acceleration g [m/s²] used in Darcy's law (γ_w = ρ_w g). It is a material
    /// constant here; gravity as a load is a `body_force` load.
    #[serde(default = "default_g")]
    pub g: f64,
    /// `plane_strain` (the default) or `axisymmetric`: x is then the radius r ≥ 0 and y the axis of
    /// revolution; the hoop strain u_r/r enters every strain and divergence, and volumes, masses
    /// and loads are those of the full ring (2πr times the area in the (r, y) plane). Nodes on the
    /// axis (r = 0) have u_r = 0 (and U_r = 0) without a boundary saying so.
    #[serde(default)]
    pub geometry: Geometry,
    /// How an axisymmetric GIMP analysis weights a particle in r (`../shared/seeds-001-002.md` Part
    /// A2): `r_weighted` (the default; the particle's characteristic function integrated with the
    /// measure r dr, Option B, which distributes mass and volume with the ring's weight and is exact
    /// next to the axis) or `planar` (the planar GIMP functions with the hoop operator S_i/r_p,
    /// Option A). Both reproduce the strains of u_r = α + βr exactly; the linear basis and the
    /// B-splines have one form (their functions at the point with the hoop operator S_i/r_p).
    #[serde(default)]
    pub axisymmetric_weights: AxisymmetricWeights,
    /// The kinematics of a step: `finite_strain` (the default: forces on the configuration at the
    /// step's end, the objective Hughes–Winget update, the exact tangent with its geometric terms)
    /// or `linear_increments` ([001] Eqs. 5, 7, 11: each step is geometrically linear on the
    /// configuration at its start, Δε = sym ∇Δu, σ_{n+1} = σ_n + Δσ without rotation, forces
    /// Bᵀσ V_n; the points still move and their volumes and domains update between steps, an
    /// updated Lagrangian of small-strain increments). One-phase only.
    #[serde(default)]
    pub kinematics: KinematicsKind,
}

/// The kinematics of a step (see `Analysis::kinematics`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum KinematicsKind {
    /// Finite strain on the step's end configuration.
    #[default]
    FiniteStrain,
    /// Geometrically linear steps on the step's start configuration ([001]).
    LinearIncrements,
}

/// The geometry of the (x, y) plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Geometry {
    /// Plane strain: ε_zz = 0, volumes per metre of thickness.
    #[default]
    PlaneStrain,
    /// Axial symmetry about the y axis: x ≡ r ≥ 0, hoop strain u_r/r, ring volumes 2πrA.
    Axisymmetric,
}

/// How an axisymmetric GIMP analysis weights a particle in r.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AxisymmetricWeights {
    /// Option A: planar GIMP functions, hoop operator S_i / r_p.
    Planar,
    /// Option B: GIMP functions integrated with the measure r dr.
    #[default]
    RWeighted,
}

fn default_shape() -> ShapeFunctions {
    ShapeFunctions::Gimp
}
fn default_g() -> f64 {
    9.81
}

/// The discrete system to build.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Formulation {
    /// Solid displacement, pore pressure, water displacement per node (u–p–U).
    TwoPhase,
    /// Solid displacement only (total stress, or dry material).
    OnePhase,
}

/// Material-point basis functions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
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
    /// fields and are interpolatory there (`model::shape::bspline_1d`). The points' domains (used
    /// for cell fractions and B̄) follow the stretch as with `gimp`.
    Bspline2,
    /// Cubic B-splines centred on the nodes (C², 4 × 4 nodes per particle), with the same edge
    /// treatment.
    Bspline3,
}

/// A uniform structured background grid: two entries per key for a plane (or axisymmetric) case,
/// three for a three-dimensional one (y is vertical in every dimension: gravity acts along −y, z
/// is the second horizontal direction).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Grid {
    /// Lower-left (-back) corner [m]; default: the origin.
    #[serde(default)]
    pub origin: Vec<f64>,
    /// Extent in x, y (and z) [m].
    pub size: Vec<f64>,
    /// Number of cells in x, y (and z).
    pub cells: Vec<usize>,
}

/// A material: phase densities, porosity, the water and grain compressibility, the permeability,
/// and the constitutive model of the skeleton.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Name used by bodies.
    pub name: String,
    /// Initial porosity n [-], in (0, 1) (in [0, 1) in a one-phase analysis, whose density is the
    /// mixture's (1 − n) ρ_s + n ρ_w).
    pub porosity: f64,
    /// Density of the solid grains ρ_s [kg/m³], in (0, 1e5].
    pub solid_density: f64,
    /// Density of the pore water ρ_w [kg/m³], in (0, 1e5].
    #[serde(default = "default_rho_w")]
    pub water_density: f64,
    /// Bulk modulus of the pore water K_w [Pa] (two-phase), in (0, 1e13].
    #[serde(default)]
    pub water_bulk_modulus: Option<f64>,
    /// Bulk modulus of the solid grains K_s [Pa], in (0, 1e13]; `inf` for incompressible grains
    /// (two-phase).
    #[serde(default)]
    pub solid_bulk_modulus: Option<f64>,
    /// Hydraulic conductivity k [m/s] (two-phase) at the initial porosity, in (0, 1].
    #[serde(default)]
    pub hydraulic_conductivity: Option<f64>,
    /// How the conductivity changes with the void ratio (default: constant).
    #[serde(default)]
    pub hydraulic_conductivity_law: ConductivityLaw,
    /// The constitutive model of the solid skeleton.
    pub model: SoilModel,
}

/// Dependence of the hydraulic conductivity on the void ratio e.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ConductivityLaw {
    /// k = k₀.
    #[default]
    Constant,
    /// k = k₀ ((1 + e)/(1 + e₀))², the law under which the large-strain consolidation of Xie & Leo
    /// (2004) has a closed form (with 1 + e = 1/(1 − n)).
    XieLeo,
}

fn default_rho_w() -> f64 {
    1000.0
}

/// Constitutive model of the skeleton (effective stress in two-phase analyses, total stress in
/// one-phase analyses).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum SoilModel {
    /// Isotropic linear elasticity, plane strain.
    LinearElastic {
        /// Young's modulus E [Pa], in (0, 1e13].
        young_modulus: f64,
        /// Poisson's ratio ν [-].
        poisson_ratio: f64,
    },
    /// Mohr–Coulomb, non-associated, with linear cohesion softening, a dilation angle decaying with
    /// plastic strain and an optional tension cut-off ([000] §4; Tresca with `friction_angle = 0`,
    /// the cohesion being the undrained strength).
    MohrCoulomb {
        /// Young's modulus E [Pa], in (0, 1e13].
        young_modulus: f64,
        /// Poisson's ratio ν [-].
        poisson_ratio: f64,
        /// Friction angle φ [degrees], 0 ≤ φ < 90.
        friction_angle: f64,
        /// Peak cohesion c_p [Pa].
        cohesion: f64,
        /// Residual cohesion c_r [Pa] (default: no softening).
        #[serde(default)]
        residual_cohesion: Option<f64>,
        /// Accumulated deviatoric plastic strain ε_p^r at which c_r is reached [-].
        #[serde(default)]
        softening_strain: Option<f64>,
        /// Initial dilation angle ψ_ini [degrees] (default 0).
        #[serde(default)]
        dilation_angle: f64,
        /// Critical-state dilation angle ψ_crit [degrees] (default: ψ_ini, i.e. constant).
        #[serde(default)]
        critical_dilation_angle: Option<f64>,
        /// Decay rate η ≥ 0 of ψ = ψ_crit + (ψ_ini − ψ_crit) exp(−η ε̄) [-] (default 0).
        #[serde(default)]
        dilation_decay: f64,
        /// Tensile strength of a cut-off σ_i ≤ t [Pa] (default: none).
        #[serde(default)]
        tension_cutoff: Option<f64>,
    },
    /// Von Mises with linear softening ([001] §3.2): q ≤ √3 c(ε̄), c = max(c_p + H_s ε̄, c_r).
    VonMises {
        /// Young's modulus E [Pa], in (0, 1e13].
        young_modulus: f64,
        /// Poisson's ratio ν [-].
        poisson_ratio: f64,
        /// Peak shear strength c_p [Pa].
        cohesion: f64,
        /// Residual shear strength c_r [Pa] (default: c_p).
        #[serde(default)]
        residual_cohesion: Option<f64>,
        /// Softening modulus H_s = dc/dε̄ ≤ 0 [Pa] (default 0).
        #[serde(default)]
        softening_modulus: f64,
    },
    /// Compressible neo-Hookean hyperelasticity ([002] §4.1, Cook's membrane;
    /// `model::finite_strain::NeoHookean`): Kirchhoff stress τ = μ(b − 1) + λ ln J 1 of the
    /// point's total deformation gradient, σ = τ/J. Only in `dynamic_explicit` stages (the
    /// implicit stages need its consistent tangent, which is not built), without an initial stress.
    NeoHookean {
        /// Young's modulus E [Pa], in (0, 1e13].
        young_modulus: f64,
        /// Poisson's ratio ν [-].
        poisson_ratio: f64,
    },
    /// Hencky elasticity with J2 (von Mises) plasticity and exponential softening ([002] §4.2 and
    /// §4.4, the strip footing and the landslide; `model::finite_strain::HenckyJ2`): multiplicative
    /// plasticity in principal logarithmic strains, τ = K tr ε^e 1 + 2μ dev ε^e with ε^e = ½ ln b^e,
    /// radial return of dev τ onto q = √3 c(ε̄), c(ε̄) = c_r + (c_p − c_r) exp(−η ε̄), σ = τ/J (with
    /// F̄, J̄). c is the plane-strain shear strength (the undrained strength s_u). The point's b^e is
    /// not stored: it is recovered from its stress and J, which determine it (so an initial stress
    /// is an initial elastic strain). Only in `dynamic_explicit` stages (no consistent tangent for
    /// the implicit ones), in plane strain.
    HenckyJ2 {
        /// Young's modulus E [Pa], in (0, 1e13].
        young_modulus: f64,
        /// Poisson's ratio ν [-].
        poisson_ratio: f64,
        /// Peak shear strength c_p [Pa], > 0.
        cohesion: f64,
        /// Residual shear strength c_r [Pa], in [0, c_p] (default: c_p, no softening).
        #[serde(default)]
        residual_cohesion: Option<f64>,
        /// Softening rate η of c(ε̄) [-], ≥ 0 (default 0).
        #[serde(default)]
        softening_rate: f64,
    },
    /// A weakly compressible Newtonian fluid ([002] §4.3, the dam break;
    /// `model::finite_strain::NewtonianFluid`): σ = −p 1 + 2μ_v dev d with the pressure of the
    /// equation of state p = K(1 − J) (with F̄, J̄) and d the step's rate of deformation. Its density
    /// is the material's (`porosity = 0`, `solid_density` = ρ). The stress is a function of J and the
    /// rate, so the body takes no initial stress: a hydrostatic state is reached by a settling
    /// stage. Only in `dynamic_explicit` stages, in plane strain.
    NewtonianFluid {
        /// Bulk modulus K [Pa], in (0, 1e13] (water: 2.0e9 Pa; a smaller K is the usual weakly
        /// compressible substitute when the flow's Mach number v/√(K/ρ) stays below 0.1).
        bulk_modulus: f64,
        /// Dynamic viscosity μ_v [Pa s], ≥ 0 (water: 1.0e-3 Pa s).
        viscosity: f64,
        /// Bulk viscosity ζ [Pa s], ≥ 0 (default 0): σ gains ζ tr d 1. Water has none (Stokes);
        /// explicit codes add ζ = b₁ ρ c_p h (Abaqus/Explicit: b₁ = 0.06) to damp the volumetric
        /// ringing of a stiff fluid at the grid's scale.
        #[serde(default)]
        bulk_viscosity: f64,
    },
}

/// A body filled with material points.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Body {
    /// Name used by probes and verification.
    pub name: String,
    /// Name of its material.
    pub material: String,
    /// Material points per cell and direction (2 gives 2×2 per cell).
    #[serde(default = "default_ppc")]
    pub particles_per_cell: usize,
    /// The region it occupies at t = 0: in three dimensions its section in the x–y plane,
    /// extruded along z over `z`.
    pub shape: Shape,
    /// The body's extent [z_min, z_max] along z [m] (three-dimensional cases; default the grid's).
    #[serde(default)]
    pub z: Option<[f64; 2]>,
    /// Geostatic initial stress (default: stress-free).
    #[serde(default)]
    pub initial_stress: Option<InitialStress>,
    /// A uniform initial effective stress [xx, yy, xy, zz] [Pa] (tension positive), instead of a
    /// geostatic one (e.g. for patch tests and rigid-rotation checks); a three-dimensional case may
    /// give the two other shears too, [xx, yy, xy, zz, yz, zx].
    #[serde(default)]
    pub uniform_stress: Option<Vec<f64>>,
    /// Displacement of every material point from the centre of its sub-cell, as a fraction of the
    /// point spacing in each direction, drawn from a fixed pseudo-random sequence keyed by the
    /// point's id (the same on any number of ranks); 0 ≤ value < 0.5 (default 0: a regular
    /// arrangement) [-].
    #[serde(default)]
    pub perturbation: f64,
}

/// A geostatic initial state in equilibrium with gravity g = `analysis.g` acting from t = 0 (the
/// case must apply that gravity in full from the start): at a point at height y under a column of
/// material reaching y_top at its x, the total vertical stress is σ_v = −g ∫_y^{y_top} ρ dy (the
/// densities of the bodies met along the column), the pore pressure p = ρ_w g (y_w − y) below the
/// water table y_w (two-phase), the effective stresses σ'_yy = σ_v + p, σ'_xx = σ'_zz = K₀ σ'_yy,
/// σ'_xy = 0. Near a slope this is not in equilibrium; the first steps redistribute it.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct InitialStress {
    /// Coefficient of earth pressure at rest K₀ = σ'_h/σ'_v [-].
    pub k0: f64,
    /// The water table (two-phase): `"surface"` (the top of the material in each column, the
    /// default) or a height [m].
    #[serde(default)]
    pub water_table: WaterTable,
}

/// Where the pore pressure of a geostatic state is zero.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum WaterTable {
    /// `"surface"`: the top of the material in each column.
    #[default]
    #[serde(with = "surface_word")]
    Surface,
    /// A height [m].
    Level(f64),
}

mod surface_word {
    use serde::{Deserialize, Deserializer, Serializer};
    pub fn serialize<S: Serializer>(s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str("surface")
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<(), D::Error> {
        let w = String::deserialize(d)?;
        if w == "surface" {
            Ok(())
        } else {
            Err(serde::de::Error::custom(format!("expected \"surface\" or a height, got \"{w}\"")))
        }
    }
}

fn default_ppc() -> usize {
    2
}

/// A planar region.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Shape {
    /// Axis-aligned rectangle.
    Rectangle {
        /// Lower-left corner [m].
        min: [f64; 2],
        /// Upper-right corner [m].
        max: [f64; 2],
    },
    /// Simple polygon, vertices in order [m].
    Polygon {
        /// Vertices.
        vertices: Vec<[f64; 2]>,
    },
}

/// An axis-aligned box [m] used to select nodes or particles.
#[derive(Debug, Clone, Copy, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Region {
    /// Lower-left corner [m].
    pub min: [f64; 2],
    /// Upper-right corner [m].
    pub max: [f64; 2],
    /// Its extent [z_min, z_max] along z in a three-dimensional case [m] (default: all of it).
    #[serde(default)]
    pub z: Option<[f64; 2]>,
}

/// A side of the background grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// x = origin_x.
    XMin,
    /// x = origin_x + size_x.
    XMax,
    /// y = origin_y.
    YMin,
    /// y = origin_y + size_y.
    YMax,
    /// z = origin_z (three-dimensional cases).
    ZMin,
    /// z = origin_z + size_z (three-dimensional cases).
    ZMax,
}

impl Body {
    /// The `uniform_stress` as a stress vector [xx, yy, xy, zz, yz, zx] [Pa] (the shears it does
    /// not give are zero).
    pub fn uniform_stress_vector(&self) -> Option<[f64; 6]> {
        self.uniform_stress.as_ref().map(|s| std::array::from_fn(|c| s.get(c).copied().unwrap_or(0.0)))
    }
}

impl Side {
    /// The direction the side is normal to (0: x, 1: y, 2: z).
    pub fn axis(&self) -> usize {
        match self {
            Side::XMin | Side::XMax => 0,
            Side::YMin | Side::YMax => 1,
            Side::ZMin | Side::ZMax => 2,
        }
    }

    /// The sign of its outward normal along [`Side::axis`].
    pub fn sign(&self) -> f64 {
        match self {
            Side::XMin | Side::YMin | Side::ZMin => -1.0,
            Side::XMax | Side::YMax | Side::ZMax => 1.0,
        }
    }
}

/// A nodal degree of freedom.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize, Serialize)]
pub enum Dof {
    /// Solid displacement, x.
    #[serde(rename = "ux")]
    Ux,
    /// Solid displacement, y.
    #[serde(rename = "uy")]
    Uy,
    /// Pore pressure.
    #[serde(rename = "p")]
    P,
    /// Water displacement, x.
    #[serde(rename = "Ux")]
    WUx,
    /// Water displacement, y.
    #[serde(rename = "Uy")]
    WUy,
    /// Solid displacement, z (three-dimensional cases).
    #[serde(rename = "uz")]
    Uz,
    /// Water displacement, z (three-dimensional cases).
    #[serde(rename = "Uz")]
    WUz,
}

impl std::fmt::Display for Dof {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Dof::Ux => "ux",
            Dof::Uy => "uy",
            Dof::P => "p",
            Dof::WUx => "Ux",
            Dof::WUy => "Uy",
            Dof::Uz => "uz",
            Dof::WUz => "Uz",
        })
    }
}

/// Dirichlet conditions on the grid nodes of a side, of a box or of a body's moving surface: the
/// listed components are fixed, to zero (drained p = 0, a fixed or sliding wall), or moving with a
/// prescribed displacement or velocity (a loading platen, a displacement-driven rigid footing: all
/// its nodes move together, and the boundary's reaction is the force that drives it).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Boundary {
    /// Name used by stages.
    pub name: String,
    /// A side of the grid (give `side` or `region`).
    #[serde(default)]
    pub side: Option<Side>,
    /// Nodes inside this box (give one of `side`, `region`, `surface`).
    #[serde(default)]
    pub region: Option<Region>,
    /// The moving surface of a body: the nodes on or beyond the exposed faces of its boundary
    /// particles, found again every step (a drained free surface: `fix = ["p"]`; in the
    /// quasi-static u–p system p = 0 is imposed on the faces themselves, by Nitsche's method).
    #[serde(default)]
    pub surface: Option<Surface>,
    /// Components fixed: `ux`, `uy`, `Ux`, `Uy`, and `p` (drained). In a one_phase analysis the
    /// water-phase components have no dofs and are ignored. Fixed to zero unless `displacement` or
    /// `velocity` moves them.
    pub fix: Vec<Dof>,
    /// Prescribed displacement [m] of the fixed displacement components: at time t the nodes have
    /// moved by `displacement` × f(t) (f the time function; constant 1 without one). Fixed water
    /// components move with the solid (the boundary is impermeable to flow across it).
    /// Two components in a plane case, three in a three-dimensional one.
    #[serde(default)]
    pub displacement: Option<Vec<f64>>,
    /// Prescribed velocity [m/s] of the fixed displacement components, scaled by the time function:
    /// the nodes move by ∫ `velocity` f(t) dt.
    #[serde(default)]
    pub velocity: Option<Vec<f64>>,
    /// A velocity gradient L [1/s] of a homogeneous flow about `center`, scaled by the time
    /// function with `velocity` (its translation part, default zero): over a step the node at x moves
    /// by (exp(L s) − I)(x − c) + v s with s = ∫ f dt — exactly the step of a uniform deformation
    /// (e.g. a rigid rotation ω: L = [[0, −ω], [ω, 0]]). Rows L_ij = ∂v_i/∂x_j: two rows of two in a
    /// plane case, three rows of three in a three-dimensional one.
    #[serde(default)]
    pub velocity_gradient: Option<Vec<Vec<f64>>>,
    /// Centre c of the `velocity_gradient`'s flow [m] (default: the origin); one coordinate per
    /// dimension.
    #[serde(default)]
    pub center: Option<Vec<f64>>,
    /// Name of the time function scaling `displacement`, `velocity` or `velocity_gradient`.
    #[serde(default)]
    pub time_function: Option<String>,
}

/// The faces of a body's surface.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Surface {
    /// The body.
    pub body: String,
    /// Which faces: the particles whose face in one of these directions is exposed at t = 0.
    pub faces: Vec<Side>,
    /// Only the particles whose centres lie in this box at t = 0 (default: all of the body's), e.g.
    /// the part of the ground under a footing [m]. The box also bounds the nodes fixed along each
    /// face (x for a y face, y for an x face; the box stays where it is at t = 0), so that a
    /// footing's edge stays at the box's edge; put that edge on a grid line (a boundary fixes whole
    /// nodes).
    #[serde(default)]
    pub region: Option<Region>,
}

/// A load, scaled in time by a named time function (default: constant 1).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Load {
    /// A traction [Pa] on one face of the particle domains whose centres lie in `region` at t = 0
    /// and whose face is on the surface of the material (the point just beyond it is outside every
    /// body), applied at the face centre (force = traction × the face's length per metre of
    /// thickness in two dimensions, × its area in three).
    ParticleTraction {
        /// Name used by stages and verification.
        name: String,
        /// Particles carrying it (centres inside at t = 0).
        region: Region,
        /// Only particles of this body (default: any).
        #[serde(default)]
        body: Option<String>,
        /// Which face of each particle domain carries it.
        face: Side,
        /// Traction vector [Pa]: two components in a plane case, three in a three-dimensional one.
        traction: Vec<f64>,
        /// Name of the time function scaling it.
        #[serde(default)]
        time_function: Option<String>,
        /// An expression in `x` and `y` [m] (and `z` in a three-dimensional case, and the case's
        /// parameters) that scales each step's increment of the load by where the loaded faces are
        /// at the start of the step: over the step from t_n to t_{n+1} the traction grows by
        /// `traction` × (f(t_{n+1}) − f(t_n)) × g(x̄_n, ȳ_n[, z̄_n]), with (x̄_n, ȳ_n[, z̄_n]) the
        /// area-weighted mean centre of the loaded faces at t_n.
        /// The total is the sum of the increments, each applied where the surface was (e.g.
        /// [001]'s internal pressure re-evaluated at the current inner radius,
        /// `"A / x^2 + 2 * C"`). Written without the leading `=` (it is evaluated during the run,
        /// not when the case is read). Without it the traction is `traction` × f(t).
        #[serde(default)]
        increment_factor: Option<String>,
    },
    /// A traction [Pa] on the line (plane) or surface (three dimensions) of grid nodes inside
    /// `region`, each node taking its tributary length of the line or the product of its tributary
    /// lengths along the surface. The load stays on that grid line: when the loaded surface moves
    /// off it by δ, the stress of the particles in the cell below is too large by about h/(h − δ)
    /// (the force passes through a partly filled cell). Use a `particle_traction`, which follows the
    /// surface, when the surface moves by more than a small fraction of a cell.
    NodalTraction {
        /// Name used by stages and verification.
        name: String,
        /// Nodes carrying it: a row or column of nodes in the plane, a layer of nodes in three
        /// dimensions (one node thick in one direction, validated).
        region: Region,
        /// Traction vector [Pa]: two components in a plane case, three in a three-dimensional one.
        traction: Vec<f64>,
        /// Name of the time function scaling it.
        #[serde(default)]
        time_function: Option<String>,
    },
    /// A pressure [Pa] on a polyline fixed in space (e.g. the inside of a cylinder; plane and
    /// axisymmetric cases only), pushing the
    /// material that lies on the left of the direction of travel along `points`: the force per
    /// metre is p n with n the unit normal to the left. It is integrated along each segment with
    /// two Gauss points and distributed with the bilinear hat functions of the cell holding each
    /// point (nodes the material does not fill pass their share to filled ones). Fixed in space:
    /// for small deformations.
    LinePressure {
        /// Name used by stages and verification.
        name: String,
        /// The polyline's points [m], at least two.
        points: Vec<[f64; 2]>,
        /// The pressure [Pa].
        pressure: f64,
        /// Name of the time function scaling it.
        #[serde(default)]
        time_function: Option<String>,
    },
    /// A body acceleration [m/s²] on every particle (gravity: [0, -9.81], or [0, -9.81, 0] in three
    /// dimensions), acting on both phases.
    BodyForce {
        /// Name used by stages.
        name: String,
        /// Acceleration vector [m/s²]: two components in a plane case, three in a three-dimensional
        /// one.
        acceleration: Vec<f64>,
        /// The bodies it acts on (default: all), e.g. a footing whose unit weight is ramped up.
        #[serde(default)]
        bodies: Option<Vec<String>>,
        /// Name of the time function scaling it.
        #[serde(default)]
        time_function: Option<String>,
    },
}

impl Load {
    /// The `kind` the case file names.
    pub fn kind(&self) -> &'static str {
        match self {
            Load::ParticleTraction { .. } => "particle_traction",
            Load::NodalTraction { .. } => "nodal_traction",
            Load::LinePressure { .. } => "line_pressure",
            Load::BodyForce { .. } => "body_force",
        }
    }

    /// The load's name.
    pub fn name(&self) -> &str {
        match self {
            Load::ParticleTraction { name, .. }
            | Load::NodalTraction { name, .. }
            | Load::LinePressure { name, .. }
            | Load::BodyForce { name, .. } => name,
        }
    }

    /// The expression scaling its increments by the loaded faces' position, if any (see
    /// `ParticleTraction::increment_factor`).
    pub fn increment_factor(&self) -> Option<&str> {
        match self {
            Load::ParticleTraction { increment_factor, .. } => increment_factor.as_deref(),
            _ => None,
        }
    }

    /// The name of its time function, if any.
    pub fn time_function(&self) -> Option<&str> {
        match self {
            Load::ParticleTraction { time_function, .. }
            | Load::NodalTraction { time_function, .. }
            | Load::LinePressure { time_function, .. }
            | Load::BodyForce { time_function, .. } => time_function.as_deref(),
        }
    }
}

/// A scalar function of the analysis time t [s] multiplying a load.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum TimeFunction {
    /// f = value.
    Constant {
        /// Name used by loads.
        name: String,
        /// The value.
        value: f64,
    },
    /// f rises linearly from 0 at `start` to 1 at `start + duration` [s], then stays 1.
    Ramp {
        /// Name used by loads.
        name: String,
        /// Start [s].
        #[serde(default)]
        start: f64,
        /// Duration [s].
        duration: f64,
    },
    /// As `ramp` but with the C² smoothstep 6s⁵ − 15s⁴ + 10s³ (no jump in rate or acceleration).
    SmoothRamp {
        /// Name used by loads.
        name: String,
        /// Start [s].
        #[serde(default)]
        start: f64,
        /// Duration [s].
        duration: f64,
    },
    /// f = cos(ω t + φ), multiplied by a smooth ramp over `ramp_duration` [s] if it is positive.
    Harmonic {
        /// Name used by loads.
        name: String,
        /// ω [rad/s].
        angular_frequency: f64,
        /// φ [rad].
        #[serde(default)]
        phase: f64,
        /// Duration of the smooth start [s].
        #[serde(default)]
        ramp_duration: f64,
    },
    /// Piecewise linear through (times[i], values[i]); constant outside.
    Table {
        /// Name used by loads.
        name: String,
        /// Increasing times [s].
        times: Vec<f64>,
        /// Values.
        values: Vec<f64>,
    },
}

impl TimeFunction {
    /// The function's name.
    pub fn name(&self) -> &str {
        match self {
            TimeFunction::Constant { name, .. }
            | TimeFunction::Ramp { name, .. }
            | TimeFunction::SmoothRamp { name, .. }
            | TimeFunction::Harmonic { name, .. }
            | TimeFunction::Table { name, .. } => name,
        }
    }
}

/// Stabilisation switches.
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Stabilisation {
    /// MLSA patch recovery of the pore-pressure increments ([003] §3.3, Eqs. 26–30). Default: off
    /// (see `DEFAULT_PATCH_RECOVERY` in crate::model for the measurements behind that choice); cases
    /// with large deformations need it.
    #[serde(default)]
    pub patch_recovery: Option<bool>,
    /// B̄ for GIMP ([000] §3, Eqs. 12–16): the volumetric part of B from cell-centre gradients weighted
    /// by the share of the particle domain in each cell. Default: off.
    #[serde(default)]
    pub bbar: bool,
    /// [002]'s F̄ by volume-averaged projection ([002] §3, Algorithm 1; `model::fbar`): each
    /// point's step scales its in-plane deformation increment so that its volume ratio is the
    /// volume-weighted average of the points sharing its nodes, which relieves volumetric locking
    /// for any non-negative basis. In `dynamic_explicit` stages, plane strain, without B̄.
    /// Default: off.
    #[serde(default)]
    pub fbar: bool,
    /// Pressure-projection stabilisation of the equal-order pressure (Bochev & Dohrmann 2006): the
    /// factor α of τ = α/G (G the skeleton's shear modulus) in the cell-wise penalty on the
    /// non-constant part of the pressure increment (see `kernels::pressure_projection`). Default:
    /// none.
    #[serde(default)]
    pub pressure_projection: Option<f64>,
    /// How a particle's pore pressure follows a converged step (two-phase): `increments` (the
    /// default: p += the interpolated, or patch-recovered, increment) or `projected_total` (p is
    /// the interpolation of the total nodal field P + Δp, P the consistent L² projection of the
    /// particles' pressures onto the nodal functions, so that whatever the nodes cannot represent
    /// does not accumulate on the particles). Not with `patch_recovery`.
    #[serde(default)]
    pub pressure_update: PressureUpdate,
    /// How the skeleton's material stiffness enters the Newton matrix ([001] §5,
    /// `../shared/seeds-001-002.md` Parts A4–A6, docs/axisymmetry.md): `particle` (the default:
    /// the exact tangent, integrated at the points), `w_star` (points weighted as if their cell
    /// were exactly full, [001] Eq. 15), `gauss_mapping` (the points' moduli mapped to the cell's
    /// nodes and from there to its 2 × 2 Gauss points, Eq. 19 with W), `double_mapping` (the same
    /// with W*, Eq. 19) or `double_mapping_gimp` (with the local GIMP weights, Eq. 20). Every
    /// option but `particle` is an approximate Jacobian: Newton converges to the same answer, at a
    /// linear rate; with `-snes_type ksponly` a step is [001]'s single linear solve.
    #[serde(default)]
    pub stiffness: Stiffness,
    /// Where a mapped `stiffness` serves: `jacobian` (the default: it is Newton's matrix, [001]'s
    /// scheme, converging linearly) or `diagnostics` (only the nodal K_mag diagnostic is computed
    /// with it; Newton keeps the exact tangent and converges quadratically to the same answer,
    /// since the residual is the same).
    #[serde(default)]
    pub mapped_stiffness: MappedStiffnessUse,
    /// How a point's strain increment is recovered from the nodal displacements ([001] §5.5):
    /// `basis` (the default: with the gradients of the point's basis functions, as its forces are
    /// integrated) or `cmpm` (composite MPM: the higher-order Lagrange patch functions of [001]
    /// Eqs. 22–23 (corrected) over the point's cell and its well-filled neighbours, cubic, quadratic
    /// or linear per direction; one-phase, without B̄) or `mapped` (with the double-mapped
    /// operators of `internal_force = "mapped"`, which it needs: each point's strain is the
    /// finite-element strain of the cells it maps to, averaged over their Gauss points with the
    /// point's weights there, the transpose of its forces, so that the point's force and strain
    /// are one Galerkin pair and its tangent is symmetric). The residual keeps the basis for the
    /// forces unless `internal_force` says otherwise, and its tangent stays exact.
    #[serde(default)]
    pub stress_recovery: StressRecovery,
    /// How the skeleton's internal force is integrated (`../shared/seeds-001-002.md` Part A8,
    /// step 2): `particle` (the default: at the points with the basis's gradients, F_i = Σ_p
    /// B_i(x_p)ᵀ σ_p V_p) or `mapped` (double-mapped like the stiffness: each point's stress goes to
    /// the nodes of the cells it maps to with the weights of `stabilisation.stiffness`, σ_i^e =
    /// Σ_p w_ip W_p σ_p, from there to the cell's 2 × 2 Gauss points, σ_g = Σ_i N_i(x_g) σ_i^e, and
    /// F_e = Σ_g B_gᵀ σ_g |J|, as [001] Eqs. 16–20 map D_p). Needs a mapped `stiffness`
    /// (`gauss_mapping`, `double_mapping` or `double_mapping_gimp`), a one-phase plane case
    /// without B-splines; the residual and its exact tangent change together.
    #[serde(default)]
    pub internal_force: InternalForce,
}

/// How the skeleton's internal force is integrated (see [`Stabilisation::internal_force`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InternalForce {
    /// At the material points with the basis's gradients.
    #[default]
    Particle,
    /// Double-mapped to the cells' Gauss points with the mapped stiffness's weights.
    Mapped,
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
}

/// How a point's strain is recovered (see [`Stabilisation::stress_recovery`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
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
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MappedStiffnessUse {
    /// Newton's matrix and the K_mag diagnostic.
    #[default]
    Jacobian,
    /// The K_mag diagnostic only.
    Diagnostics,
}

/// The material stiffness of the Newton matrix (see [`Stabilisation::stiffness`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
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

/// How a particle's pore pressure follows a converged step (see [`Stabilisation::pressure_update`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PressureUpdate {
    /// p_{n+1} = p_n + Σ S_i Δp_i (or its MLSA recovery).
    #[default]
    Increments,
    /// p_{n+1} = Σ S_i (P_i + Δp_i), M P = Σ_p V_p S p_n with the consistent M.
    ProjectedTotal,
}

/// Time-stepping defaults (`--set time.dt=5e-4` changes the step of every stage that has none
/// of its own).
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Time {
    /// Time step of the stages that do not give their own `dt` [s].
    #[serde(default)]
    pub dt: Option<f64>,
}

/// One analysis stage.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Stage {
    /// Name shown in progress and history.
    pub name: String,
    /// Duration [s].
    pub duration: f64,
    /// Time step [s]; default: `time.dt`.
    #[serde(default)]
    pub dt: Option<f64>,
    /// Boundaries active in this stage (default: all).
    #[serde(default)]
    pub boundaries: Option<Vec<String>>,
    /// Loads active in this stage (default: all).
    #[serde(default)]
    pub loads: Option<Vec<String>>,
    /// How many times in a row a step may be cut before the run fails.
    #[serde(default = "default_cuts")]
    pub max_step_cuts: usize,
    /// Factor applied to Δt at each cut.
    #[serde(default = "default_cut_factor")]
    pub cut_factor: f64,
    /// What the stage solves: `dynamic` (the default: inertia, the u–p–U system in two-phase
    /// cases), `quasi_static` (two-phase only: no inertia, the u–p Biot system with Darcy's law,
    /// θ-method in time), `static` (no inertia and no flow: one-phase, or two-phase with
    /// `drainage`) or `dynamic_explicit` (one-phase: explicit MPM, update-stress-last, with the
    /// stage's `explicit` settings; [002] §2.2).
    #[serde(default)]
    pub analysis: AnalysisType,
    /// θ of the quasi-static stage's Darcy flux, 1/2 ≤ θ ≤ 1 (default 1, backward Euler: no
    /// oscillation at large Δt; 1/2 is second order but rings when c_v Δt/h² ≫ 1) [-].
    #[serde(default)]
    pub theta: Option<f64>,
    /// The water in a static stage of a two-phase case: `drained` (the pore pressure is held;
    /// 2 dofs per node) or `undrained` (no flow: the u–p system without Darcy's law).
    #[serde(default)]
    pub drainage: Option<Drainage>,
    /// The largest step the stage may grow to after easy steps (at most 3 Newton iterations,
    /// [`GROW_AFTER`](crate::driver) of them in a row) [s]; default: `dt` (no growth beyond it).
    #[serde(default)]
    pub dt_max: Option<f64>,
    /// Newmark parameters of this stage (default: the case's `time_integration`). A settling
    /// stage can damp the transient of an unbalanced initial state numerically, e.g.
    /// `{ beta = 0.49, gamma = 0.9 }` with a Δt near the lowest period of the soil.
    #[serde(default)]
    pub time_integration: Option<TimeIntegration>,
    /// The explicit integrator's settings of a `dynamic_explicit` stage (defaults if absent).
    #[serde(default)]
    pub explicit: Option<Explicit>,
    /// The strength reduction factor F of this stage, ≥ 1 (default 1: the case's strengths): from
    /// the stage's start every material's peak strength is the case's divided by F (c_p/F, and
    /// φ' = atan(tan φ/F) with ψ ≤ φ'), as in the strength reduction of slope analyses (Griffiths &
    /// Lane 1999; [002] §4.4 triggers its landslide with F = 1.65 on the peak strength). Residual
    /// strengths stay as given unless above the reduced peak, where they take it. Each stage
    /// reduces the case's strengths afresh (factors do not compound); the points keep their stress
    /// and accumulated plastic strain, so a point beyond the reduced strength returns to it in its
    /// next update [-].
    #[serde(default)]
    pub strength_reduction: Option<f64>,
}

/// Settings of the explicit integrator ([002] §2.2, §4; seeds-001-002.md Parts C1 and C5).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Explicit {
    /// Courant number C: the step is at most C h_min / c_p, with c_p = sqrt(E_c/ρ) the largest
    /// P-wave speed of the materials at rest ([002] uses 0.3 and 0.4) [-]. The stage's `dt` caps
    /// it further. In (0, 1].
    #[serde(default = "default_cfl")]
    pub cfl: f64,
    /// FLIP share η of the particle velocity update, v_p ← η FLIP + (1 − η) PIC ([002] Eq. 13;
    /// 1 is pure FLIP, [002]'s default; Cook's membrane used 0.85) [-]. In [0, 1].
    #[serde(default = "default_flip")]
    pub flip_blend: f64,
    /// Local damping α (Al-Kafaji 2013): each free nodal force component f is reduced by
    /// α |f| sign(v) ([002] used 0.002 for the footing) [-]. In [0, 1).
    #[serde(default)]
    pub local_damping: f64,
    /// The order m of the extended PIC transfer XPIC(m) of Hammerquist & Nairn (2017), which
    /// replaces the FLIP/PIC blend: v_p ← S(v^{n+1} − v^n + w) with
    /// w = Σ_{k=1..m} (−1)^{k+1} C(m, k) (S⁺S)^{k−1} v^n, S⁺S the map of nodal velocities to the
    /// points and back (mass-weighted). m = 1 is PIC; a larger m keeps more of FLIP's
    /// resolved motion while filtering the particle velocities the grid cannot see (the null
    /// space that lets pure FLIP ring), at m − 1 extra passes over the points per step. In
    /// [1, 8]; default: none (the blend). Hammerquist & Nairn suggest 2 to 5.
    #[serde(default)]
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
    #[serde(default)]
    pub pore_pressure: Option<ExplicitPressure>,
}

/// Where the pore pressure of a two-phase explicit stage lives (see [`Explicit::pore_pressure`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
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

fn default_cfl() -> f64 {
    0.5
}
fn default_flip() -> f64 {
    1.0
}

impl Stage {
    /// The stage's time step [s] (its own `dt`, else `time.dt`; resolved by [`super::parse`]).
    pub fn dt(&self) -> f64 {
        self.dt.unwrap_or(f64::NAN)
    }
}

/// What a stage solves (see [`Stage::analysis`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AnalysisType {
    /// Inertia; u–p–U (two-phase) or u.
    #[default]
    Dynamic,
    /// No inertia; u–p with Darcy's law (two-phase cases only).
    QuasiStatic,
    /// No inertia, no flow.
    Static,
    /// Explicit dynamics (one-phase; [002]).
    DynamicExplicit,
}

/// The water in a static stage of a two-phase case.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Drainage {
    /// The pore pressure is held at its value at the start of the stage (the skeleton alone
    /// carries the load change).
    Drained,
    /// No flow: the pore pressure changes with the volume (u–p without Darcy's law).
    Undrained,
}

fn default_cuts() -> usize {
    4
}
fn default_cut_factor() -> f64 {
    0.5
}

/// The time integration of dynamic stages: the generalized-α method of Chung & Hulbert (1993) with
/// spectral radius `rho_inf` (default [`DEFAULT_RHO_INF`]), or Newmark ([003] Eqs. 20–22) when
/// `scheme = "newmark"` or `beta`/`gamma` are given.
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TimeIntegration {
    /// `generalized_alpha` (default) or `newmark`.
    #[serde(default)]
    pub scheme: Option<TimeScheme>,
    /// Newmark β [-] (default 1/4: average acceleration); Newmark only.
    #[serde(default)]
    pub beta: Option<f64>,
    /// Newmark γ [-] (default 1/2: no numerical damping); Newmark only.
    #[serde(default)]
    pub gamma: Option<f64>,
    /// Spectral radius at infinite frequency ρ∞ ∈ [0, 1] of the generalized-α method [-]: 1 damps
    /// nothing, 0 annihilates the highest frequencies in one step.
    #[serde(default)]
    pub rho_inf: Option<f64>,
}

/// A dynamic time-integration scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
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
/// 4.3e-2 (0). 0.2 is the largest ρ∞ that meets the 20 steps (docs/analysis.md).
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

    /// The kernels' form of these parameters.
    pub fn integration(&self) -> crate::scheme::Integration {
        if self.is_newmark() {
            let (b, g) = self.newmark();
            crate::scheme::Integration::newmark(b, g)
        } else {
            crate::scheme::Integration::generalized_alpha(self.rho_inf.unwrap_or(DEFAULT_RHO_INF))
        }
    }
}

/// Solver strategy.
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Solver {
    /// A PETSc options file applied before the command line's, relative to the case file.
    #[serde(default)]
    pub options_file: Option<String>,
}

/// Output control.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Output {
    /// Write a history row every this many steps (the last step of a stage is always written).
    #[serde(default = "default_every")]
    pub history_every: usize,
    /// Write the particle and grid fields to `fields.h5`/`fields.xdmf` every this many steps
    /// [steps], and always at t = 0 (or the restart time) and at the end of every stage; 0 writes
    /// no fields.
    #[serde(default = "default_fields_every")]
    pub fields_every: usize,
}

fn default_every() -> usize {
    1
}

/// Field output every 100 steps unless the case says otherwise.
pub const DEFAULT_FIELDS_EVERY: usize = 100;

fn default_fields_every() -> usize {
    DEFAULT_FIELDS_EVERY
}

impl Default for Output {
    fn default() -> Self {
        Output { history_every: 1, fields_every: DEFAULT_FIELDS_EVERY }
    }
}

/// A probe: follows the material point nearest to `point` at t = 0.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Probe {
    /// Column prefix in history.csv.
    pub name: String,
    /// Position at t = 0 [m]: one component per dimension of the case (x, y[, z]).
    pub point: Vec<f64>,
}

/// The analytical reference of a case.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Verification {
    /// One-dimensional consolidation ([003] §4.1.1, Eqs. 31–33).
    Terzaghi {
        /// The consolidating body (its height is the drainage length; drained at its top).
        body: String,
        /// The surface load (its final magnitude is q).
        load: String,
        /// Time factors T_v at which e_p is evaluated (the last one also gives the RMS and settlement errors).
        #[serde(default = "default_tv")]
        time_factors: Vec<f64>,
        /// Pass threshold for e_p ([003] Eq. 33).
        #[serde(default = "default_ep_tol")]
        e_p_tolerance: f64,
        /// Pass threshold for the plain RMS of the normalised pressure error.
        #[serde(default = "default_rms_tol")]
        p_rms_tolerance: f64,
        /// Pass threshold for the relative settlement error.
        #[serde(default = "default_settle_tol")]
        settlement_tolerance: f64,
    },
    /// Steady-state harmonic column (Zienkiewicz, Chang & Bettess 1980; [003] §4.1.2).
    HarmonicColumn {
        /// The column body.
        body: String,
        /// The harmonic surface load.
        load: String,
        /// Number of final load periods over which the amplitude is measured.
        #[serde(default = "default_periods")]
        measure_periods: usize,
        /// Pass threshold for the maximum amplitude error relative to the peak amplitude.
        tolerance: f64,
    },
    /// Elastic column under its self-weight and a surcharge, at rest at the end of the run: the
    /// vertical stress is −(ρ g d + q) at depth d and the settlement ρ g H²/(2 E_c) + q H/E_c.
    ElasticColumn {
        /// The column body (laterally confined, fixed base).
        body: String,
        /// The body-force load carrying gravity.
        gravity: String,
        /// The surface load (particle or nodal traction), if any.
        #[serde(default)]
        surcharge: Option<String>,
        /// Pass threshold for max |σ_yy − σ*| / max |σ*| over the column.
        #[serde(default = "default_column_tol")]
        stress_tolerance: f64,
        /// Pass threshold for the relative settlement error.
        #[serde(default = "default_column_tol")]
        settlement_tolerance: f64,
    },
    /// Load–settlement of a strip (or, in three dimensions, a rectangular) footing and its bearing
    /// capacity ([000] §4.1, §4.3; see `verification::bearing`).
    BearingCapacity {
        /// The soil body (its cohesion normalises the pressure).
        soil: String,
        /// The load: a traction (its pressure), or a body force on the footing body (its weight
        /// over `loaded_width`). Give `load` or `footing`.
        #[serde(default)]
        load: Option<String>,
        /// A rigid footing pushed into the soil under displacement control: a boundary that moves
        /// its nodes (`velocity` or `displacement`); the pressure is its vertical reaction on the
        /// soil over `loaded_width` ([002] §4.2). Give `load` or `footing`.
        #[serde(default)]
        footing: Option<String>,
        /// Width carrying the load in the model [m] (the half-width in a half model).
        loaded_width: f64,
        /// In three dimensions, the loaded area's extent along z in the model [m] (the half-length
        /// of a footing in a quarter model): the pressure is the force over
        /// `loaded_width` × `loaded_depth`. Two-dimensional cases do not take it.
        #[serde(default)]
        loaded_depth: Option<f64>,
        /// Footing breadth B [m] (normalises the settlement).
        breadth: f64,
        /// The settlement is the downward displacement of the material point nearest to this point
        /// at t = 0 [m] (one coordinate per dimension).
        settlement_point: Vec<f64>,
        /// d/B at which q_ult is read for the metric `bearing_capacity_ratio` (a load-controlled
        /// footing; give this or `plateau`, or neither for no metric).
        #[serde(default)]
        failure_settlement: Option<f64>,
        /// The range [d/B_from, d/B_to] over which the mean of q is q_ult for the metric
        /// `bearing_capacity_ratio` (a displacement-controlled footing, whose load levels off at the
        /// limit load).
        #[serde(default)]
        plateau: Option<[f64; 2]>,
        /// Reference q_ult/c (default 2 + π, Prandtl).
        #[serde(default = "default_prandtl")]
        reference: f64,
        /// Largest accepted |(q_ult/c)/reference − 1|.
        #[serde(default = "default_bearing_tol")]
        tolerance: f64,
        /// d/B values at which q/c is reported in summary.json `results`.
        #[serde(default)]
        report_settlements: Vec<f64>,
        /// q/c values at which the settlement of the point d [m] is reported in summary.json
        /// `results` as `settlement_at_qc<value>`.
        #[serde(default)]
        report_loads: Vec<f64>,
        /// d/B at which the run ends, completed (a load-controlled footing beyond its limit load
        /// runs away; default: run to the end).
        #[serde(default)]
        stop_settlement: Option<f64>,
    },
    /// Large-strain one-dimensional consolidation (Xie & Leo 2004; [003] §4.2).
    LargeStrainConsolidation {
        /// The consolidating column (drained at its top).
        body: String,
        /// The surface load (its final magnitude is q).
        load: String,
        /// Degrees of consolidation U_s at which the metrics are evaluated.
        #[serde(default = "default_us")]
        degrees: Vec<f64>,
        /// Pass threshold for e_p ([003] Eq. 33).
        #[serde(default = "default_ep_tol")]
        e_p_tolerance: f64,
        /// Pass threshold for the plain RMS of the normalised pressure error.
        #[serde(default = "default_rms_tol")]
        p_rms_tolerance: f64,
        /// Pass threshold for the relative settlement error.
        #[serde(default = "default_ls_settle_tol")]
        settlement_tolerance: f64,
    },
    /// A homogeneous deformation (patch test, rigid rotation): a body whose boundary nodes follow a
    /// boundary's `velocity_gradient` must carry one uniform stress, equal to the linear-elastic
    /// one of the flow, R σ₀ Rᵀ + D ln V with F = exp(L ∫f) = V R (exact for a pure stretch and for
    /// a pure rotation).
    Patch {
        /// The body (linear elastic).
        body: String,
        /// The boundary whose homogeneous flow drives it.
        boundary: String,
        /// Largest accepted spread of the particles' stresses, max ‖σ_p − σ̄‖/‖σ̄‖.
        #[serde(default = "default_spread_tol")]
        spread_tolerance: f64,
        /// Largest accepted ‖σ̄ − σ*‖/‖σ*‖ against the linear-elastic stress of the flow.
        #[serde(default = "default_patch_tol")]
        tolerance: f64,
    },
    /// A thick-walled cylinder under internal pressure in plane strain (Lamé): a quarter of it
    /// (symmetry on the axes through `center`), linear elastic, loaded by a `line_pressure` on its
    /// inner circle. Metrics: the relative L2 errors (weighted by the points' volumes) of the radial
    /// displacement and of σ_rr and σ_θθ over the body's points against
    /// u_r = (1 + ν) p a² ((1 − 2ν) r + b²/r) / (E (b² − a²)),
    /// σ_rr = p a² (1 − b²/r²)/(b² − a²), σ_θθ = p a² (1 + b²/r²)/(b² − a²).
    Lame {
        /// The cylinder's body (linear elastic).
        body: String,
        /// The internal pressure (a `line_pressure`; p at the run's end).
        load: String,
        /// The cylinder's axis [m].
        #[serde(default)]
        center: [f64; 2],
        /// Inner radius a [m].
        inner_radius: f64,
        /// Outer radius b [m].
        outer_radius: f64,
        /// Largest accepted relative L2 error of u_r.
        #[serde(default = "default_lame_tol")]
        displacement_tolerance: f64,
        /// Largest accepted relative L2 error of σ_rr and of σ_θθ.
        #[serde(default = "default_lame_tol")]
        stress_tolerance: f64,
    },
    /// A thick-walled hollow cylinder under internal pressure in axial symmetry, its outer wall held
    /// radially and plane strain along the axis ([001] §3.1; `../shared/seeds-001-002.md` Part B1):
    /// Lamé's closed form with u_r(b) = 0, compared after the first load step (the first increment
    /// of [001]).
    HollowCylinder {
        /// The cylinder's body (linear elastic, one phase).
        body: String,
        /// The internal pressure (a `nodal_traction` or `particle_traction` whose x component is
        /// the pressure on the inner face, times its time function).
        load: String,
        /// Inner radius a [m].
        inner_radius: f64,
        /// Outer radius b [m] (held radially).
        outer_radius: f64,
        /// Largest accepted relative error of u_r at the inner radius.
        #[serde(default = "default_lame_tol")]
        displacement_tolerance: f64,
        /// Largest accepted relative error of Δσ_rr at the innermost points (mp1) and volume-weighted
        /// RMS of the relative error of Δσ_rr over the body.
        #[serde(default = "default_hollow_stress_tol")]
        stress_tolerance: f64,
        /// Checks every load step as an increment of the remaining cylinder ([001]'s 25
        /// increments, Part E item 9): by uniqueness, the closed form of the original cylinder
        /// restricted to [r_i, b] is the small-strain increment of the wall whose inner face has moved
        /// to r_i when the load applied there is the original Δσ_rr(r_i) (an `increment_factor`
        /// `A / x^2 + 2 * C`). Without it only the first step is checked.
        #[serde(default)]
        increments: Option<IncrementTolerances>,
    },
    /// The nodal stiffness diagnostic K_mag = √(K_x² + K_y²) ([001] Eq. 25, §6) of a block of
    /// material points in plane strain against the finite-element value of an interior node of a
    /// uniform Q4 mesh of square cells, (4/3)(D₁₁ + G)√2, over the nodes within `radius` of
    /// `center`, after the last step (`../shared/seeds-001-002.md` Part B2).
    StiffnessMap {
        /// The block (linear elastic).
        body: String,
        /// The centre of the evaluated nodes [m].
        center: [f64; 2],
        /// The radius within which nodes are evaluated [m].
        radius: f64,
        /// Largest accepted relative deviation of K_mag at any of those nodes.
        #[serde(default = "default_stiffness_map_tol")]
        tolerance: f64,
    },
    /// The vertical cut of [001] §3.2 and §7.2 (`../shared/seeds-001-002.md` Part B3, Part E items
    /// 10–12): no closed form; the run stops when the toe has moved `stop_displacement`, and reports
    /// the constitutive check q ≤ √3 c(ε̄) at every point and step, the largest ε̄, the smoothness of
    /// the nodal K_mag and F^int_mag when the toe passes each of `snapshots`, and the total
    /// variation of σ_m at the points `b` and `c`.
    VerticalCut {
        /// The soil (von Mises).
        body: String,
        /// The toe's point at t = 0 (the nearest material point is followed) [m].
        toe: [f64; 2],
        /// The points B (shear band) and C (sliding block) at t = 0 [m].
        b: [f64; 2],
        c: [f64; 2],
        /// The toe's horizontal displacement that ends the run [m].
        stop_displacement: f64,
        /// Toe displacements at which the nodal fields' smoothness is measured [m].
        #[serde(default)]
        snapshots: Vec<f64>,
    },
    /// Cook's membrane of [002] §4.1 (`../shared/seeds-001-002.md` Parts D1 and E item 13): the
    /// tapered plate clamped on its left edge and sheared on its right, brought to rest. The
    /// vertical displacement of the tip (the upper-right corner), by a linear least-squares fit of
    /// the points' displacements around it, against `reference`; the chequerboard index of the
    /// mean stress over the body's points.
    CookMembrane {
        /// The membrane.
        body: String,
        /// The tip at t = 0 [m].
        tip: [f64; 2],
        /// The tip's vertical displacement at rest [m] (0.2765 for [002]'s membrane: plane-strain
        /// Q9 finite elements, `scripts/cook_membrane_neo_hookean.py`).
        reference: f64,
        /// Largest accepted relative error of the tip's displacement (Part E item 13: 3 %).
        #[serde(default = "default_cook_tol")]
        tolerance: f64,
        /// The radius around the tip within which the points' displacements are fitted, in cells
        /// (default 2).
        #[serde(default = "default_cook_radius")]
        fit_radius: f64,
    },
    /// The collapse of a water column after a gate is removed ([002] §4.3; `verification::dam_break`,
    /// `../shared/seeds-001-002.md` Parts D3 and E item 15). A settling stage brings the water to
    /// rest behind the gate (the stage names it; the gate is a boundary the next stages leave out);
    /// at its end the pressure must be hydrostatic. After it, the front and the centre of mass are
    /// followed, the front's advance is bounded by the shallow-water (Ritter) speed 2√(gH), and the
    /// mass must not change. With `experiment`, the front is compared with a laboratory series.
    DamBreak {
        /// The water body (a rectangle at t = 0 against the back wall at its left).
        body: String,
        /// The body-force load carrying gravity.
        gravity: String,
        /// The settling stage, at whose end the water is checked for the hydrostatic pressure and
        /// after which it flows.
        settle_stage: String,
        /// Largest accepted |p − ρ g d| / (ρ g H) over the points more than one cell above the base
        /// at the end of the settling stage (Part E item 15: 2 %) [-].
        #[serde(default = "default_hydrostatic_tol")]
        hydrostatic_tolerance: f64,
        /// x of the wall the front runs into [m]; the front's speed bound applies while the front is
        /// more than a cell from it (default: no wall, the whole run).
        #[serde(default)]
        far_wall: Option<f64>,
        /// A measured front position to compare with: `"martin_moyce_1952"` (Martin & Moyce 1952,
        /// the column of height 2a on width a, n² = 2; the body must have that aspect ratio).
        #[serde(default)]
        experiment: Option<String>,
        /// Largest accepted mean |Z/Z_exp − 1| of the front against `experiment` [-].
        #[serde(default = "default_front_tol")]
        front_tolerance: f64,
        /// The share of the water's mass that may lie ahead of the front, as spray shed from its
        /// tip, in [0, 0.05] (default 0.005) [-].
        #[serde(default = "default_spray")]
        spray_fraction: f64,
    },
    /// The run-out of a slope that fails after a trigger ([002] §4.4, the landslide; Part E item
    /// 16 of `../shared/seeds-001-002.md`). Before the trigger stage the slope must stand (its
    /// front advances by at most `standing_advance` and no point moves faster than
    /// `standing_speed` at the trigger); the body's mass must keep. From the trigger on, the front
    /// (the leading edge along +x with at most `spray_fraction` of the mass ahead of it, as the
    /// dam break's), its advance R(t) (the run-out), the foremost point, the centre of mass, the
    /// largest accumulated plastic strain and the rearmost point that has failed are followed.
    /// There is no reference solution ([002]: "there is no reference solution"): the run-out is a
    /// result, compared between runs by `make study-landslide`.
    Runout {
        /// The sliding body (its material moves along +x).
        body: String,
        /// The stage whose start triggers the failure (e.g. by its `strength_reduction`); the
        /// run-out counts from the front's position then.
        trigger_stage: String,
        /// Largest accepted advance of the front before the trigger (the slope stands) [m].
        #[serde(default = "default_standing_advance")]
        standing_advance: f64,
        /// Largest accepted speed of any point of the body at the trigger [m/s].
        #[serde(default = "default_standing_speed")]
        standing_speed: f64,
        /// Times after the trigger at which the run-out is reported as a result (`runout_t<τ>`,
        /// the stepping lands on them) [s].
        #[serde(default)]
        snapshot_times: Vec<f64>,
        /// Accumulated plastic strain ε̄ beyond which a point counts as failed (the rearmost
        /// failed point marks the retrogression of the failure) [-].
        #[serde(default = "default_failed_strain")]
        failed_strain: f64,
        /// The share of the body's mass that may lie ahead of the front, in [0, 0.05] (default
        /// 1e-3) [-].
        #[serde(default = "default_runout_spray")]
        spray_fraction: f64,
    },
    /// Shock wave in a saturated column ([003] §4.1.3, Eqs. 34–35).
    ShockWave {
        /// The column body.
        body: String,
        /// The step surface load.
        load: String,
        /// Depth of the observation point below the initial surface [m].
        probe_depth: f64,
        /// Pass threshold for the fast (undrained) wave arrival error.
        #[serde(default = "default_fast_tol")]
        fast_tolerance: f64,
        /// Pass threshold for the slow (damped) wave arrival error.
        #[serde(default = "default_slow_tol")]
        slow_tolerance: f64,
    },
}

impl Verification {
    /// The `kind` the case file names.
    pub fn kind(&self) -> &'static str {
        match self {
            Verification::Terzaghi { .. } => "terzaghi",
            Verification::HarmonicColumn { .. } => "harmonic_column",
            Verification::ElasticColumn { .. } => "elastic_column",
            Verification::BearingCapacity { .. } => "bearing_capacity",
            Verification::LargeStrainConsolidation { .. } => "large_strain_consolidation",
            Verification::Patch { .. } => "patch",
            Verification::Lame { .. } => "lame",
            Verification::HollowCylinder { .. } => "hollow_cylinder",
            Verification::StiffnessMap { .. } => "stiffness_map",
            Verification::VerticalCut { .. } => "vertical_cut",
            Verification::ShockWave { .. } => "shock_wave",
            Verification::CookMembrane { .. } => "cook_membrane",
            Verification::DamBreak { .. } => "dam_break",
            Verification::Runout { .. } => "runout",
        }
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

/// Tolerances of the hollow cylinder's step-by-step comparison (the innermost column of points,
/// mp1, against the closed form at its radius at the start of each step).
#[derive(Debug, Clone, Copy, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct IncrementTolerances {
    /// Largest accepted relative error of Δq, the von Mises stress of the step's stress increment,
    /// over the steps ([001]: 10 %).
    pub q: f64,
    /// Largest accepted error of Δσ_m over the steps, relative to the step's pressure at r = a
    /// ([001]: 5 kPa per 100 kPa).
    pub mean_stress: f64,
    /// Largest accepted relative error of mp1's radius after the last step against the closed-form
    /// path r_{k+1} = r_k + u_r(r_k) ([001]: 5 %).
    pub radius: f64,
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
