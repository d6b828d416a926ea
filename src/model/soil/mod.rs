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

pub mod mohr_coulomb;
pub mod principal;
pub mod stress;
pub mod von_mises;

pub use mohr_coulomb::MohrCoulomb;
pub use stress::{invariants, plane, plane_block, Mat6, Stress, IDENTITY6, NS, NS_PLANE};
pub use von_mises::VonMises;

use crate::model::finite_strain::M3;
use principal::Principal;

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

/// Isotropic linear elasticity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearElastic {
    /// Young's modulus [Pa].
    pub young: f64,
    /// Poisson's ratio [-].
    pub poisson: f64,
    /// Elastic matrix D^e.
    pub d: Mat6,
}

impl LinearElastic {
    /// Elasticity with Young's modulus `e` [Pa] and Poisson's ratio `nu`.
    pub fn new(e: f64, nu: f64) -> Self {
        let lam = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = e / (2.0 * (1.0 + nu));
        Self::of_lame(lam, mu, e, nu)
    }

    /// Elasticity with bulk modulus `k` and shear modulus `g` [Pa], which may be zero (a fluid's
    /// pressure–volume response: E = 0, ν = 1/2, D = K m mᵀ).
    pub fn from_bulk_shear(k: f64, g: f64) -> Self {
        let (e, nu) = (9.0 * k * g / (3.0 * k + g), (3.0 * k - 2.0 * g) / (2.0 * (3.0 * k + g)));
        Self::of_lame(k - 2.0 * g / 3.0, g, e, nu)
    }

    fn of_lame(lam: f64, mu: f64, e: f64, nu: f64) -> Self {
        let a = lam + 2.0 * mu;
        let d = [
            [a, lam, 0.0, lam, 0.0, 0.0],
            [lam, a, 0.0, lam, 0.0, 0.0],
            [0.0, 0.0, mu, 0.0, 0.0, 0.0],
            [lam, lam, 0.0, a, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, mu, 0.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, mu],
        ];
        LinearElastic { young: e, poisson: nu, d }
    }

    /// Constrained (oedometric) modulus E_c = E(1 − ν)/((1 + ν)(1 − 2ν)) [Pa].
    pub fn constrained_modulus(&self) -> f64 {
        self.d[0][0]
    }

    /// Shear modulus G [Pa].
    pub fn shear_modulus(&self) -> f64 {
        self.d[2][2]
    }

    /// Lamé's λ [Pa].
    pub fn lame(&self) -> f64 {
        self.d[0][1]
    }

    /// Drained bulk modulus of the skeleton in plane strain, K_dr = λ + μ [Pa]: the in-plane mean
    /// stress (σ_xx + σ_yy)/2 per unit of the in-plane volumetric strain ε_xx + ε_yy.
    pub fn plane_bulk_modulus(&self) -> f64 {
        self.lame() + self.shear_modulus()
    }

    /// Bulk modulus K = λ + 2G/3 [Pa]: the mean stress over the volumetric strain in three
    /// dimensions.
    pub fn bulk_modulus(&self) -> f64 {
        self.lame() + 2.0 * self.shear_modulus() / 3.0
    }

    /// σ + D Δε.
    pub fn trial(&self, stress: &Stress, deps: &Stress) -> Stress {
        let mut s = *stress;
        // D^e couples [xx, yy, xy, zz] among themselves; yz and zx each only with itself.
        for (r, sr) in s.iter_mut().enumerate().take(NS_PLANE) {
            *sr += (0..NS_PLANE).map(|c| self.d[r][c] * deps[c]).sum::<f64>();
        }
        for r in NS_PLANE..NS {
            s[r] += self.d[r][r] * deps[r];
        }
        s
    }

    /// m D^e, with D^e's structure (see [`LinearElastic::trial`]): the consistent tangent of a
    /// return whose dσ/dσ_trial is `m`.
    pub fn right_multiply(&self, m: &Mat6) -> Mat6 {
        std::array::from_fn(|r| {
            std::array::from_fn(|c| {
                if c < NS_PLANE {
                    (0..NS_PLANE).map(|k| m[r][k] * self.d[k][c]).sum()
                } else {
                    m[r][c] * self.d[c][c]
                }
            })
        })
    }
}

/// The constitutive model of the skeleton.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Constitutive {
    /// Linear elasticity (never calls a return mapping).
    LinearElastic(LinearElastic),
    /// Mohr–Coulomb (Tresca with φ = 0).
    MohrCoulomb(LinearElastic, MohrCoulomb),
    /// Von Mises.
    VonMises(LinearElastic, VonMises),
    /// Compressible neo-Hookean hyperelasticity (its stress from the total deformation gradient,
    /// [`Constitutive::finite`]; the elasticity of the same moduli serves the estimates).
    NeoHookean(LinearElastic, crate::model::finite_strain::NeoHookean),
    /// Hencky elasticity with J2 plasticity and exponential softening (a multiplicative
    /// finite-strain model, [`Constitutive::finite`]; the elasticity of the same moduli serves the
    /// estimates).
    HenckyJ2(LinearElastic, crate::model::finite_strain::HenckyJ2),
    /// A weakly compressible Newtonian fluid (the dam break, [002] §4.3; its stress from J and the
    /// step's rate of deformation, [`Constitutive::finite`]; the elasticity of its bulk modulus and
    /// no shear stiffness serves the estimates).
    NewtonianFluid(LinearElastic, crate::model::finite_strain::NewtonianFluid),
}

impl Constitutive {
    /// New stress, internal variable and consistent tangent for the strain increment `deps` from
    /// `stress` and ε̄ = `eps_pd` ([003] Eq. 24c, [000] Eq. 11d with D^ep).
    #[inline]
    pub fn update(&self, stress: &Stress, eps_pd: f64, deps: &Stress) -> StressUpdate {
        match self {
            Constitutive::LinearElastic(el) => StressUpdate {
                stress: el.trial(stress, deps),
                tangent: el.d,
                trial_tangent: IDENTITY6,
                eps_pd,
                region: Region::Elastic,
            },
            Constitutive::MohrCoulomb(el, mc) => {
                isotropic_return(el, stress, eps_pd, deps, |l, e| {
                    // Sort descending, return, and map back.
                    let mut order = [0usize, 1, 2];
                    order.sort_by(|&a, &b| l[b].total_cmp(&l[a]));
                    let sorted = [l[order[0]], l[order[1]], l[order[2]]];
                    let r = mc.return_sorted(&sorted, e);
                    let mut stress = [0.0; 3];
                    let mut tangent = [[0.0; 3]; 3];
                    for i in 0..3 {
                        stress[order[i]] = r.stress[i];
                        for j in 0..3 {
                            tangent[order[i]][order[j]] = r.tangent[i][j];
                        }
                    }
                    ReturnResult { stress, tangent, ..r }
                })
            }
            Constitutive::VonMises(el, vm) => {
                isotropic_return(el, stress, eps_pd, deps, |l, e| vm.return_principal(l, e))
            }
            // A hyperelastic model's stress comes from the total deformation (`finite`); its
            // increment here is the small-strain one of the same moduli, with their tangent (the
            // kernels' tests use it; a case runs it in explicit stages only, through `finite`).
            Constitutive::NeoHookean(el, _) => Constitutive::LinearElastic(*el).update(stress, eps_pd, deps),
            // Likewise Hencky–J2's small-strain limit, von Mises of the same strength with the
            // exponential softening linearised at ε̄ = 0 (H = −η (c_p − c_r), floored at c_r). A run
            // never takes this path: `finite` answers for Hencky–J2 in every kernel.
            Constitutive::HenckyJ2(el, hj) => {
                let vm = VonMises {
                    shear: hj.shear,
                    cohesion: hj.cohesion,
                    residual_cohesion: hj.residual_cohesion,
                    softening_modulus: -hj.softening_rate * (hj.cohesion - hj.residual_cohesion),
                };
                Constitutive::VonMises(*el, vm).update(stress, eps_pd, deps)
            }
            // The fluid's small-strain limit without viscosity: the pressure of its bulk modulus.
            // A run never takes this path either.
            Constitutive::NewtonianFluid(el, _) => Constitutive::LinearElastic(*el).update(stress, eps_pd, deps),
        }
    }

    /// A finite-strain model's stress after a step (`None` for the incremental models, whose
    /// stress follows [`Constitutive::update`]), with the small-strain elasticity of its moduli as
    /// the tangent (no consistent tangent: explicit stages only). `df` is the step's
    /// deformation gradient ΔF (with F̄, ΔF̄; a plane-strain point's has F_zz = 1), `f` the total one after the step
    /// (F_{n+1}, or F̄_{n+1}), `stress` the Cauchy stress the point starts from, unrotated. The
    /// neo-Hookean stress is a function of `f` alone. Hencky–J2 needs b^e_n, which is not stored
    /// but recovered: the Kirchhoff stress τ_n = J_n σ_n, J_n = det f / det ΔF, determines the
    /// elastic logarithmic strain (ε^e = dev τ/2μ + tr τ/(9K) 1, in τ's principal frame), and
    /// b^e_n = exp(2ε^e). The stress is NaN when det F ≤ 0 or b^e is not positive (an
    /// inadmissible step). The Newtonian fluid's pressure follows J = det `f` and its viscous
    /// stress the step's rate of deformation, ΔF over `dt` [s]
    /// (`finite_strain::rate_of_deformation`).
    pub fn finite(&self, df: &M3, f: &M3, stress: &Stress, eps_pd: f64, dt: f64) -> Option<StressUpdate> {
        let (el, stress, eps_pd, region) = match self {
            Constitutive::NeoHookean(el, nh) => (el, nh.stress(*f), eps_pd, Region::Elastic),
            Constitutive::NewtonianFluid(el, fl) => {
                let admissible = crate::model::finite_strain::det(*f) > 0.0;
                (el, admissible.then(|| fl.stress_after(*df, *f, dt)), eps_pd, Region::Elastic)
            }
            Constitutive::HenckyJ2(el, hj) => {
                use crate::model::finite_strain::{det, PlasticState};
                let (j_new, dj) = (det(*f), det(*df));
                let state = PlasticState { be: hj.elastic_left_cauchy_green(stress, j_new / dj), eps: eps_pd };
                match hj.update(*df, &state, j_new) {
                    Some(u) => {
                        (el, Some(u.stress), u.state.eps, if u.plastic { Region::Plane } else { Region::Elastic })
                    }
                    None => (el, None, eps_pd, Region::Elastic),
                }
            }
            _ => return None,
        };
        Some(StressUpdate {
            stress: stress.unwrap_or([f64::NAN; NS]),
            tangent: el.d,
            trial_tangent: IDENTITY6,
            eps_pd,
            region,
        })
    }

    /// A fluid point's volume ratio after a step (`None` for the other models, whose points keep
    /// F_{n+1} = ΔF F_n and V_{n+1} = det ΔF V_n). A fluid remembers only its volume: its stress is
    /// a function of J and the rate alone, and the shear a flow piles into F would only make det F
    /// lose digits (Taichi's MPM fluids, [002]'s platform, keep √J 1 likewise). Its point keeps
    /// F = √J 1 and V = J V⁰ with J the volume ratio its pressure follows: det F_{n+1} (`f`), or
    /// with F̄ the projected J̄_{n+1} (`jbar`). So with F̄ a fluid point carries J̄ and the next
    /// step projects J̄_n ΔJ, [002] Algorithm 1 exactly: the points' own volume ratios, which
    /// nothing in a fluid holds in place, cannot drift apart beneath the projection.
    pub fn fluid_volume_ratio(&self, f: M3, jbar: Option<f64>) -> Option<f64> {
        match self {
            Constitutive::NewtonianFluid(..) => Some(jbar.unwrap_or_else(|| crate::model::finite_strain::det(f))),
            _ => None,
        }
    }

    /// Elastic part (for the reference solutions and time-step estimates).
    pub fn elastic(&self) -> &LinearElastic {
        match self {
            Constitutive::LinearElastic(el)
            | Constitutive::MohrCoulomb(el, _)
            | Constitutive::VonMises(el, _)
            | Constitutive::NeoHookean(el, _)
            | Constitutive::HenckyJ2(el, _)
            | Constitutive::NewtonianFluid(el, _) => el,
        }
    }

    /// Whether the model is linear (its tangent never changes).
    pub fn is_linear(&self) -> bool {
        matches!(self, Constitutive::LinearElastic(_))
    }

    /// Whether the model has no return mapping (linear elastic, hyperelastic, a fluid).
    pub fn is_elastic(&self) -> bool {
        matches!(self, Constitutive::LinearElastic(_) | Constitutive::NeoHookean(..) | Constitutive::NewtonianFluid(..))
    }
}

/// Elastic trial, return of the principal values by `ret`, and the tangent through the principal
/// frame.
fn isotropic_return(
    el: &LinearElastic,
    stress: &Stress,
    eps: f64,
    deps: &Stress,
    ret: impl Fn(&[f64; 3], f64) -> ReturnResult,
) -> StressUpdate {
    let trial = el.trial(stress, deps);
    let p = Principal::of(&trial);
    let r = ret(&p.values, eps);
    if r.region == Region::Elastic {
        return StressUpdate {
            stress: trial,
            tangent: el.d,
            trial_tangent: IDENTITY6,
            eps_pd: eps,
            region: Region::Elastic,
        };
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

#[cfg(test)]
mod tests;
