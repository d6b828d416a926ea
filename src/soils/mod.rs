//! Soil models: the stress update of a material point and its consistent tangent.
//!
//! Stress and strain are 6-vectors [xx, yy, xy, zz, yz, zx] ([`Stress`]; engineering shear strains
//! γ = 2ε, tensor shear stresses; tension positive): the full three-dimensional state, of which a
//! plane-strain or axisymmetric point uses the first four (its yz and zx stay zero, exactly). A
//! model maps the stress σ_n, its internal variables and a strain increment Δε to σ_{n+1}, the new
//! internal variables and the consistent tangent dσ_{n+1}/dΔε (6×6), the exact derivative of the
//! algorithm, which gives Newton's method its quadratic convergence. The models are isotropic, so
//! they are the same in two and in three dimensions.
//!
//! The elastoplastic models are isotropic: the elastic trial stress σ_trial = σ_n + D Δε is returned
//! in its principal frame ([`principal`]), and the tangent is dσ/dσ_trial · D with dσ/dσ_trial from
//! the principal-space derivative of the return and the spin terms of the principal directions.
//! Internal variable: the accumulated deviatoric plastic strain ε̄ = Σ sqrt(2/3 Δe_p : Δe_p)
//! ([000] §4.1.2's e_p^d), which drives softening and dilatancy.
//!
//! A new soil model is one file in this folder (its parameters with their checks, and its law) and
//! one line in the registry [`soil_models!`] (with the `pub mod` line that compiles the file: a
//! module declared by a macro would escape `cargo fmt`). The file holds the parameters as a case
//! file gives them, a serde table whose doc comments the case reference renders, implementing
//! [`SoilParameters`], and the law the solver runs, implementing [`SoilLaw`]; the registry's line,
//! `Variant(file::Parameters) = "type",`, makes the model a `type` of [`SoilModel`] and a variant
//! of [`Constitutive`], and everything else asks the two traits. This module imports only
//! [`crate::algebra`] and [`crate::check`]: the case file's schema and the model both build on it.

pub mod bulk_shear;
pub mod elasticity;
pub mod finite_strain;
pub mod hencky_j2;
pub mod linear_elastic;
pub mod mohr_coulomb;
pub mod neo_hookean;
pub mod newtonian_fluid;
pub mod principal;
pub mod stress;
pub mod von_mises;

pub use elasticity::{Elasticity, LinearElastic};
pub use hencky_j2::{HenckyJ2, HenckyJ2Law};
pub use linear_elastic::LinearElasticParameters;
pub use mohr_coulomb::{MohrCoulomb, MohrCoulombLaw};
pub use neo_hookean::{NeoHookeanLaw, NeoHookeanParameters};
pub use newtonian_fluid::{NewtonianFluid, NewtonianFluidLaw};
pub use stress::{invariants, plane, plane_block, Mat6, Stress, IDENTITY6, NS, NS_PLANE};
pub use von_mises::{VonMises, VonMisesLaw};

use crate::check::Checked;
use finite_strain::{FiniteTangent, M3};
use principal::Principal;
use serde::{Deserialize, Serialize};

/// Where a return mapping ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Region {
    /// No plastic flow.
    Elastic,
    /// One yield plane (Mohr–Coulomb main plane, or the von Mises cylinder).
    Plane,
    /// Mohr–Coulomb edge σ₂ = σ₃ (triaxial compression).
    EdgeLeft,
    /// Mohr–Coulomb edge σ₁ = σ₂ (triaxial extension).
    EdgeRight,
    /// The apex of the Mohr–Coulomb cone.
    Apex,
    /// Tension cut-off planes only.
    Tension,
    /// The main plane together with tension planes.
    TensionCorner,
}

/// A return in principal space: stresses, ∂σ_i/∂λ_j, ε̄ after the step, and the region.
#[derive(Debug, Clone, Copy)]
pub struct ReturnResult {
    /// Returned principal stresses.
    pub stress: [f64; 3],
    /// ∂σ_i/∂σ_trial,j in principal space.
    pub tangent: [[f64; 3]; 3],
    /// ε̄ at the end of the step.
    pub eps: f64,
    /// Region of the return.
    pub region: Region,
}

impl ReturnResult {
    fn elastic(trial: [f64; 3], eps: f64) -> ReturnResult {
        ReturnResult {
            stress: trial,
            tangent: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            eps,
            region: Region::Elastic,
        }
    }
}

/// Result of a stress update.
#[derive(Debug, Clone, Copy)]
pub struct StressUpdate {
    /// The updated stress [Pa].
    pub stress: Stress,
    /// Consistent tangent dσ/dΔε [Pa].
    pub tangent: Mat6,
    /// dσ/dσ_trial of the return (identity for an elastic step), with σ_trial = σ_n + D Δε; the
    /// derivative with respect to the stress the step starts from (rotated by the objective
    /// update) is the same, and `tangent` = `trial_tangent` · D.
    pub trial_tangent: Mat6,
    /// Accumulated deviatoric plastic strain ε̄ after the step [-].
    pub eps_pd: f64,
    /// Where the return ended.
    pub region: Region,
}

/// A soil model's parameters as the case file gives them (the table `materials.model` with its
/// `type`): their checks, their description, and the law they make.
pub trait SoilParameters: Clone {
    /// Whether the model follows the total deformation gradient (and its rate) rather than strain
    /// increments ([`SoilLaw::finite`]).
    const FINITE_STRAIN: bool = false;

    /// What the stress is a function of, for a model whose stress is not a state its point carries
    /// ("its deformation"): a body of such a model takes no initial stress. `None` for the models
    /// whose stress is their state.
    const STRESS_FUNCTION_OF: Option<&'static str> = None;

    /// Whether the model runs in the implicit stages: every incremental model, and a
    /// finite-strain one whose law has its consistent tangent ([`SoilLaw::finite_tangent`]).
    const IMPLICIT: bool = true;

    /// The model as the solver runs it.
    type Law: SoilLaw;

    /// The solver's law of these parameters (angles from degrees to radians).
    fn law(&self) -> Self::Law;

    /// Checks the ranges of the parameters and what they require of each other; `key` is the
    /// model's table (`materials[0].model`).
    fn check(&self, key: &str) -> Checked;

    /// The model in words and numbers, for `porompm check`.
    fn describe(&self) -> String;

    /// The peak cohesion c_p [Pa] of a model with a strength (none for the elastic models and the
    /// fluid).
    fn cohesion(&self) -> Option<f64> {
        None
    }

    /// The parameters with the peak strength divided by the strength reduction factor `f` (see
    /// [`SoilModel::with_strength_reduced`]); a model without a strength is returned as it is.
    fn with_strength_reduced(&self, _f: f64) -> Self {
        self.clone()
    }
}

/// A soil model as the solver runs it: the stress update of a material point and its tangent.
/// The kernels call it for every point at every Newton iteration, through [`Constitutive`]'s
/// inlined dispatch.
pub trait SoilLaw: Copy + std::fmt::Debug + PartialEq {
    /// Whether the model has no return mapping (linear elastic, hyperelastic, a fluid).
    const ELASTIC: bool = false;

    /// Whether the plastic work of the model's points is counted (`plastic_dissipation`): a small
    /// strain elastoplastic model, whose elasticity is its [`SoilLaw::elastic`].
    const DISSIPATES: bool = false;

    /// New stress, internal variable and consistent tangent for the strain increment `deps` from
    /// `stress` and ε̄ = `eps_pd` ([003] Eq. 24c, [000] Eq. 11d with D^ep).
    fn update(&self, stress: &Stress, eps_pd: f64, deps: &Stress) -> StressUpdate;

    /// A finite-strain model's stress after a step (`None` for the incremental models, whose
    /// stress follows [`SoilLaw::update`]), with the small-strain elasticity of its moduli as the
    /// update's `tangent` (what the estimates take; Newton's consistent tangent is
    /// [`SoilLaw::finite_tangent`]). `df` is the step's deformation
    /// gradient ΔF (with F̄, ΔF̄; a plane-strain point's has F_zz = 1), `f` the total one after the
    /// step (F_{n+1}, or F̄_{n+1}), `stress` the Cauchy stress the point starts from, unrotated,
    /// `dt` the step [s]. The stress is NaN when the step is inadmissible (det F ≤ 0).
    fn finite(&self, _df: &M3, _f: &M3, _stress: &Stress, _eps_pd: f64, _dt: f64) -> Option<StressUpdate> {
        None
    }

    /// The consistent tangent of [`SoilLaw::finite`]'s stress, ∂σ_{n+1}/∂ΔF at fixed F_n and
    /// σ_n (the same arguments), which the implicit stages' Newton method takes; `None` for the
    /// incremental models and for a finite-strain model that runs in explicit stages only
    /// ([`SoilParameters::IMPLICIT`]), or when the step is inadmissible.
    fn finite_tangent(&self, _df: &M3, _f: &M3, _stress: &Stress, _eps_pd: f64, _dt: f64) -> Option<FiniteTangent> {
        None
    }

    /// A fluid point's volume ratio after a step (`None` for the other models, whose points keep
    /// F_{n+1} = ΔF F_n and V_{n+1} = det ΔF V_n): with `f` = F_{n+1} and `jbar` the projected
    /// J̄_{n+1} of F̄.
    fn fluid_volume_ratio(&self, _f: M3, _jbar: Option<f64>) -> Option<f64> {
        None
    }

    /// Elastic part (for the reference solutions and time-step estimates).
    fn elastic(&self) -> &LinearElastic;
}

/// [`Constitutive`], the soil models as the solver runs them, from the registry's variants and
/// parameters' types ([`soil_models!`]): one variant per model holding its
/// [`SoilParameters::Law`], whose methods ask that law through an inlined `match`.
macro_rules! laws {
    ($($variant:ident($params:ty),)*) => {
        /// The constitutive model of the skeleton as the solver runs it: the law of each
        /// [`SoilModel`].
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub enum Constitutive {
            $(
                #[doc = concat!("The law of [`SoilModel::", stringify!($variant), "`].")]
                $variant(<$params as SoilParameters>::Law),
            )*
        }

        impl Constitutive {
            /// See [`SoilLaw::update`].
            #[inline]
            pub fn update(&self, stress: &Stress, eps_pd: f64, deps: &Stress) -> StressUpdate {
                match self {
                    $(Constitutive::$variant(m) => SoilLaw::update(m, stress, eps_pd, deps),)*
                }
            }

            /// See [`SoilLaw::finite`].
            #[inline]
            pub fn finite(&self, df: &M3, f: &M3, stress: &Stress, eps_pd: f64, dt: f64) -> Option<StressUpdate> {
                match self {
                    $(Constitutive::$variant(m) => SoilLaw::finite(m, df, f, stress, eps_pd, dt),)*
                }
            }

            /// See [`SoilLaw::finite_tangent`].
            #[inline]
            pub fn finite_tangent(&self, df: &M3, f: &M3, stress: &Stress, eps_pd: f64, dt: f64) -> Option<FiniteTangent> {
                match self {
                    $(Constitutive::$variant(m) => SoilLaw::finite_tangent(m, df, f, stress, eps_pd, dt),)*
                }
            }

            /// See [`SoilLaw::fluid_volume_ratio`].
            #[inline]
            pub fn fluid_volume_ratio(&self, f: M3, jbar: Option<f64>) -> Option<f64> {
                match self {
                    $(Constitutive::$variant(m) => SoilLaw::fluid_volume_ratio(m, f, jbar),)*
                }
            }

            /// See [`SoilLaw::elastic`].
            #[inline]
            pub fn elastic(&self) -> &LinearElastic {
                match self {
                    $(Constitutive::$variant(m) => SoilLaw::elastic(m),)*
                }
            }

            /// Whether the law follows the total deformation gradient ([`SoilParameters::FINITE_STRAIN`]).
            #[inline]
            pub fn is_finite_strain(&self) -> bool {
                match self {
                    $(Constitutive::$variant(_) => <$params as SoilParameters>::FINITE_STRAIN,)*
                }
            }

            /// See [`SoilLaw::ELASTIC`].
            pub fn is_elastic(&self) -> bool {
                match self {
                    $(Constitutive::$variant(_) => <<$params as SoilParameters>::Law as SoilLaw>::ELASTIC,)*
                }
            }

            /// See [`SoilLaw::DISSIPATES`].
            pub fn dissipates(&self) -> bool {
                match self {
                    $(Constitutive::$variant(_) => <<$params as SoilParameters>::Law as SoilLaw>::DISSIPATES,)*
                }
            }
        }
    };
}

/// The registry of the soil models: each line names a model's variant, its parameters' type and
/// the `type` a case file chooses it by (with the variant's doc comment, which the case reference
/// shows). It makes
///
/// * [`SoilModel`], the case file's table `materials.model`, internally tagged by `type`, whose
///   methods ask the variant's parameters;
/// * [`Constitutive`], the model as the solver runs it (`Copy`, made by [`laws!`]), one variant
///   per model holding its [`SoilParameters::Law`], whose methods ask that law through an inlined
///   `match`.
macro_rules! soil_models {
    ($($(#[$attr:meta])* $variant:ident($params:ty) = $kind:literal,)*) => {
        /// Constitutive model of the skeleton (effective stress in two-phase analyses, total stress
        /// in one-phase analyses), chosen by the table's `type`.
        #[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
        #[serde(tag = "type")]
        pub enum SoilModel {
            $($(#[$attr])* #[serde(rename = $kind)] $variant($params),)*
        }

        impl SoilModel {
            /// The `type` of every model, in the registry's order.
            pub const KINDS: &'static [&'static str] = &[$($kind),*];

            /// The `type` the case file names.
            pub fn kind(&self) -> &'static str {
                match self {
                    $(SoilModel::$variant(_) => $kind,)*
                }
            }

            /// Checks the ranges of the model's parameters; `key` is its table
            /// (`materials[0].model`).
            pub fn check(&self, key: &str) -> Checked {
                match self {
                    $(SoilModel::$variant(m) => SoilParameters::check(m, key),)*
                }
            }

            /// The model in words and numbers, for `porompm check`.
            pub fn describe(&self) -> String {
                match self {
                    $(SoilModel::$variant(m) => SoilParameters::describe(m),)*
                }
            }

            /// The peak cohesion c_p [Pa] of a model with a strength (none for the elastic models
            /// and the fluid).
            pub fn cohesion(&self) -> Option<f64> {
                match self {
                    $(SoilModel::$variant(m) => SoilParameters::cohesion(m),)*
                }
            }

            /// Whether the model follows the total deformation gradient (and its rate) rather than
            /// strain increments: the neo-Hookean solid, Hencky–J2 and the Newtonian fluid.
            pub fn is_finite_strain(&self) -> bool {
                match self {
                    $(SoilModel::$variant(_) => <$params as SoilParameters>::FINITE_STRAIN,)*
                }
            }

            /// Whether the model runs in the implicit stages ([`SoilParameters::IMPLICIT`]).
            pub fn runs_implicit(&self) -> bool {
                match self {
                    $(SoilModel::$variant(_) => <$params as SoilParameters>::IMPLICIT,)*
                }
            }

            /// What the stress is a function of, for a model whose stress is not a state its point
            /// carries (so a body of it takes no initial stress): see
            /// [`SoilParameters::STRESS_FUNCTION_OF`].
            pub fn stress_function_of(&self) -> Option<&'static str> {
                match self {
                    $(SoilModel::$variant(_) => <$params as SoilParameters>::STRESS_FUNCTION_OF,)*
                }
            }

            /// The model with its peak strength divided by the strength reduction factor `f` (a
            /// stage's `strength_reduction`): c_p/f, φ' = atan(tan φ/f) with the dilation angles at
            /// most φ', the residual strength at most the reduced peak; the stiffness unchanged.
            /// Models without a strength (elastic, neo-Hookean, fluid) are returned as they are.
            pub fn with_strength_reduced(&self, f: f64) -> SoilModel {
                match self {
                    $(SoilModel::$variant(m) => SoilModel::$variant(SoilParameters::with_strength_reduced(m, f)),)*
                }
            }

            /// The solver's soil model for the case's (angles from degrees to radians).
            pub fn law(&self) -> Constitutive {
                match self {
                    $(SoilModel::$variant(m) => Constitutive::$variant(SoilParameters::law(m)),)*
                }
            }
        }

        laws! { $($variant($params),)* }
    };
}

soil_models! {
    /// Isotropic linear elasticity.
    LinearElastic(linear_elastic::LinearElasticParameters) = "linear_elastic",
    /// Isotropic linear elasticity given by its bulk and shear moduli K and G (λ = K − 2G/3, μ = G).
    ElasticBulkShear(bulk_shear::BulkShear) = "elastic_bulk_shear",
    /// Mohr–Coulomb, non-associated, with linear cohesion softening, a dilation angle decaying with
    /// plastic strain and an optional tension cut-off ([000] §4; Tresca with `friction_angle = 0`,
    /// the cohesion being the undrained strength).
    MohrCoulomb(mohr_coulomb::MohrCoulomb) = "mohr_coulomb",
    /// Von Mises with linear softening ([001] §3.2): q ≤ √3 c(ε̄), c = max(c_p + H_s ε̄, c_r).
    VonMises(von_mises::VonMises) = "von_mises",
    /// Compressible neo-Hookean hyperelasticity ([002] §4.1, Cook's membrane): Kirchhoff stress
    /// τ = μ(b − 1) + λ ln J 1 of the point's total deformation gradient, σ = τ/J. In every
    /// stage (the implicit ones with its consistent tangent), without an initial stress.
    NeoHookean(neo_hookean::NeoHookeanParameters) = "neo_hookean",
    /// Hencky elasticity with J2 (von Mises) plasticity and exponential softening ([002] §4.2 and
    /// §4.4, the strip footing and the landslide): multiplicative plasticity in principal
    /// logarithmic strains, τ = K tr ε^e 1 + 2μ dev ε^e with ε^e = ½ ln b^e, radial return of
    /// dev τ onto q = √3 c(ε̄), c(ε̄) = c_r + (c_p − c_r) exp(−η ε̄), σ = τ/J (with F̄, J̄). c is
    /// the plane-strain shear strength (the undrained strength s_u). The point's b^e is not
    /// stored: it is recovered from its stress and J, which determine it (so an initial stress is
    /// an initial elastic strain). In every stage (the implicit ones with its consistent
    /// tangent), in plane strain and 3D.
    HenckyJ2(hencky_j2::HenckyJ2) = "hencky_j2",
    /// A weakly compressible Newtonian fluid ([002] §4.3, the dam break): σ = −p 1 + 2μ_v dev d
    /// with the pressure of the equation of state p = K(1 − J) (with F̄, J̄) and d the step's rate
    /// of deformation. Its density is the material's (`porosity = 0`, `solid_density` = ρ). The
    /// stress is a function of J and the rate, so the body takes no initial stress: a hydrostatic
    /// state is reached by a settling stage. Only in `dynamic_explicit` stages, in plane strain.
    NewtonianFluid(newtonian_fluid::NewtonianFluid) = "newtonian_fluid",
}

/// A soil law whose return maps the principal values of its elastic trial (an isotropic return,
/// [`isotropic_return`]).
trait PrincipalReturn: SoilLaw {
    /// Whether [`PrincipalReturn::map_principal`] surely finds the trial elastic, told from its
    /// invariants alone: never true where the return would not find it elastic. It spares the
    /// principal decomposition of the many points that stay elastic.
    fn surely_elastic(&self, trial: &Stress, eps: f64) -> bool;

    /// The return of the trial's principal values (in any order) from the state ε̄ = `eps`.
    fn map_principal(&self, values: &[f64; 3], eps: f64) -> ReturnResult;
}

/// Elastic trial, return of the principal values by the `law`, and the tangent through the
/// principal frame.
fn isotropic_return(law: &impl PrincipalReturn, stress: &Stress, eps: f64, deps: &Stress) -> StressUpdate {
    let el = law.elastic();
    let trial = el.trial(stress, deps);
    let elastic =
        StressUpdate { stress: trial, tangent: el.d, trial_tangent: IDENTITY6, eps_pd: eps, region: Region::Elastic };
    if law.surely_elastic(&trial, eps) {
        return elastic;
    }
    let p = Principal::of(&trial);
    let r = law.map_principal(&p.values, eps);
    if r.region == Region::Elastic {
        return elastic;
    }
    let dsdt = p.derivative(&r.stress, &r.tangent);
    StressUpdate {
        stress: p.compose(&r.stress),
        tangent: el.right_multiply(&dsdt),
        trial_tangent: dsdt,
        eps_pd: r.eps,
        region: r.region,
    }
}

/// The mean stress p and the norm R = |dev σ| (Frobenius, shears counted twice) of a stress: the
/// invariants that bound its principal values without finding them. With s_1 ≥ s_2 ≥ s_3 the
/// principal values of dev σ (Σ s_i = 0, Σ s_i² = R²): s_1 − s_3 ≤ √2 R (equality when s_2 = 0)
/// and |s_i| ≤ √(2/3) R.
fn mean_and_deviator_norm(s: &Stress) -> (f64, f64) {
    let p = (s[0] + s[1] + s[3]) / 3.0;
    let (a, b, c) = (s[0] - p, s[1] - p, s[3] - p);
    (p, (a * a + b * b + c * c + 2.0 * (s[2] * s[2] + s[4] * s[4] + s[5] * s[5])).sqrt())
}

/// The peak strength `peak` divided by the strength reduction factor `f`, and the residual
/// strength `residual` at most the reduced peak.
fn reduced_strength(peak: f64, residual: Option<f64>, f: f64) -> (f64, Option<f64>) {
    let peak = peak / f;
    (peak, residual.map(|cr| cr.min(peak)))
}

#[cfg(test)]
mod tests;
