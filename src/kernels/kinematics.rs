//! Finite-strain kinematics of one material point over a step, in the updated Lagrangian frame of
//! the reset grid, in D dimensions (plane strain and axial symmetry with D = 2).
//!
//! The grid carries the step's displacement increments Δu_i. With ∇S_i the gradients of the
//! point's basis functions on the configuration x_n and ∇̄S_i those of B̄'s volumetric part ([000]
//! Eqs. 13–16; equal to ∇S_i without B̄), two incremental deformation gradients follow:
//!   F = I + H,  H = Σ Δu_i ⊗ ∇S_i,        F_v = I + H_v,  H_v = Σ Δu_i ⊗ ∇̄S_i,
//! with J = det F and J_v = det F_v. The point's volume at t_{n+1} is V_{n+1} = J_v V_n (the volume
//! follows the volumetric deformation the stress sees; an F̄ update, as Coombs et al. 2018 do).
//!
//! **Current configuration.** The residual is written on the configuration x_{n+1} = x_n + Δu, so
//! that a converged step is in equilibrium where the material is: the gradients there are
//! ∇'S_i = F⁻ᵀ ∇S_i and ∇̄'S_i = F_v⁻ᵀ ∇̄S_i (Σ_i (x_i + Δu_i) ⊗ ∇'S_i = I exactly), and the internal
//! force of the Cauchy stress σ_{n+1} is f_i = B̄'_iᵀ σ_{n+1} V_{n+1} with B̄' built from them
//! ([000] Eq. 16 on x_{n+1}).
//!
//! **Objective stress update (Hughes & Winget 1980).** The strain increment and the rotation are
//! taken on the mid-step configuration x_{n+1/2}: L = H F_h⁻¹ with F_h = I + H/2 (and L_v likewise
//! from H_v),
//!   Δε = sym L − ⅓ tr(L) m + ⅓ tr(L_v) m     (m = [1, 1, 0, 1]; B̄: the volumetric part from L_v),
//!   W = ½(L − Lᵀ),  R = (I − ½W)⁻¹(I + ½W)  (the Cayley transform of the mid-step spin),
//! and the soil model starts from the rotated stress R σ_n Rᵀ. In two dimensions R is the turn by
//! θ = 2 atan(ω/2), ω = ½(L_yx − L_xy), about z. A rigid rotation Q gives sym L = 0 and R = Q
//! exactly, so the stress turns with the material to round-off. The strain increment is the
//! 6-vector of [`crate::soils::Stress`] ([xx, yy, γxy, zz, γyz, γzx]); in two dimensions its
//! zz component is the hoop rate (axial symmetry) or zero, and yz, zx are zero.
//!
//! **Geometrically linear steps** (`linear = true`, `analysis.kinematics = "linear_increments"`,
//! [001] Eqs. 5, 7, 11): the step is small-strain on x_n. Δε = sym H − ⅓ tr H m + ⅓ tr H_v m (the
//! hoop component H_θθ), no rotation (θ = 0), and the gradients and hoop operators the forces use
//! stay those of x_n (F⁻ᵀ → I), so the step's residual is linear in Δu and its tangent is the
//! material part alone. J, J_v and F̄ are still those of the motion: the particle's volume, domain
//! and position follow it between steps.
//!
//! **Axial symmetry** (x ≡ r, docs/axisymmetry.md): F is block diagonal with the
//! hoop stretch F_θθ = 1 + H_θθ, H_θθ = Σ T_i Δu_r,i (T_i the node's hoop operator, S_i/r_p for the
//! planar weights: F_θθ = r_{n+1}/r_n), and F_v,θθ likewise with B̄'s T̄_i. Then J = det F_rz F_θθ,
//! J_v = det F_v,rz F_v,θθ, the mid-step hoop rate L_θθ = H_θθ/(1 + H_θθ/2) is the fourth strain
//! component (the zz slot of plane strain) and enters the traces of L and L_v; on x_{n+1} the hoop
//! operators are T'_i = T_i/F_θθ and T̄'_i = T̄_i/F_v,θθ. The rotation stays in the (r, y) plane. In
//! plane strain T = 0 and every hoop quantity drops out.

use super::NodeBasis;
use crate::algebra::{det, identity, inverse, mul, mul_t, Mat};
use crate::soils::{principal, Stress, NS};

/// I + s a.
fn plus_identity<const D: usize>(a: &Mat<D>, s: f64) -> Mat<D> {
    std::array::from_fn(|i| std::array::from_fn(|j| if i == j { 1.0 + s * a[i][j] } else { s * a[i][j] }))
}

/// tr a plus, in two dimensions, the out-of-plane (hoop) component `zz`.
fn trace<const D: usize>(a: &Mat<D>, zz: f64) -> f64 {
    match D {
        2 => a[0][0] + a[1][1] + zz,
        _ => (1..D).fold(a[0][0], |s, k| s + a[k][k]),
    }
}

/// The strain vector [xx, yy, γxy, zz, γyz, γzx] of a rate (or increment) `a` with `vol` added to
/// its normal components; in two dimensions `zz` is its out-of-plane component.
fn strain_of<const D: usize>(a: &Mat<D>, zz: f64, vol: f64) -> Stress {
    match D {
        2 => [a[0][0] + vol, a[1][1] + vol, a[0][1] + a[1][0], zz + vol, 0.0, 0.0],
        _ => [a[0][0] + vol, a[1][1] + vol, a[0][1] + a[1][0], a[2][2] + vol, a[1][2] + a[2][1], a[2][0] + a[0][2]],
    }
}

/// The kinematics of a point for given nodal increments (see the module documentation).
#[derive(Debug, Clone, Copy)]
pub struct Kinematics<const D: usize = 2> {
    /// F = I + H.
    pub f: Mat<D>,
    /// J = det F.
    pub j: f64,
    /// J − 1, formed from H without the cancellation of det F − 1 (what an implicit F̄ step's
    /// projection and volumetric strain take: at small strains det F − 1 keeps only the digits
    /// of J beyond 1, and the residual's round-off then swamps its changes).
    pub dj: f64,
    /// F_v = I + H_v.
    pub fv: Mat<D>,
    /// J_v = det F_v: the volume ratio of the step.
    pub jv: f64,
    /// F⁻¹ (the transpose pushes gradients forward).
    f_inv: Mat<D>,
    /// F_v⁻¹.
    fv_inv: Mat<D>,
    /// F_h⁻¹ = (I + H/2)⁻¹.
    fh_inv: Mat<D>,
    /// (I + H_v/2)⁻¹.
    fvh_inv: Mat<D>,
    /// L = H F_h⁻¹.
    l: Mat<D>,
    /// L_v = H_v F_vh⁻¹.
    lv: Mat<D>,
    /// Strain increment Δε [xx, yy, γxy, zz, γyz, γzx].
    pub deps: Stress,
    /// ω = ½(L_yx − L_xy) (two dimensions).
    pub omega: f64,
    /// Rotation angle of the step about z, θ = 2 atan(ω/2) [rad] (two dimensions).
    pub theta: f64,
    /// (I − ½W)⁻¹ of the mid-step spin W = ½(L − Lᵀ) (three dimensions; the derivative of R needs it).
    half_spin_inv: Mat<D>,
    /// The rotation of the step R = (I − ½W)⁻¹(I + ½W) (three dimensions; in two, the turn by θ).
    pub rotation: Mat<D>,
    /// The hoop stretch F_θθ = 1 + Σ T_i Δu_r,i (1 in plane strain and in three dimensions).
    pub f_hoop: f64,
    /// B̄'s hoop stretch F_v,θθ = 1 + Σ T̄_i Δu_r,i.
    pub fv_hoop: f64,
    /// A geometrically linear step (see the module documentation).
    pub linear: bool,
    /// The volumetric part of the strain from [002]'s projected J̄ of an implicit step
    /// ([`Kinematics::with_projected_volume`]); `None` otherwise.
    projected: Option<Projected>,
}

/// What an implicit step's F̄ needs of its projected volume ratio (see
/// [`Kinematics::with_projected_volume`]).
#[derive(Debug, Clone, Copy)]
struct Projected {
    /// c = (r/J)^{1/D}, ΔF̄ = c ΔF (r = J̄_{n+1}/J̄_n, the volume ratio of the step the stress sees).
    c: f64,
    /// a = I₁(ΔF̄) = tr ΔF̄ = c tr ΔF.
    a: f64,
    /// b = I₂(ΔF̄) = c² I₂(ΔF) (three dimensions; zero in two).
    b: f64,
    /// ∂ tr L̄/∂a at fixed b and r.
    dtr_da: f64,
    /// ∂ tr L̄/∂b at fixed a and r (three dimensions).
    dtr_db: f64,
    /// d tr L̄/dr at fixed ΔF (through a and b as well).
    dtr_dr: f64,
}

impl<const D: usize> Kinematics<D> {
    /// The kinematics for displacement increments `du[k]` at the nodes of `basis`, finite strain
    /// or (`linear`) a geometrically linear step.
    pub fn new(basis: &[NodeBasis<D>], du: impl Iterator<Item = [f64; D]>, linear: bool) -> Kinematics<D> {
        let (mut h, mut hv) = ([[0.0; D]; D], [[0.0; D]; D]);
        let (mut ht, mut hvt) = (0.0, 0.0);
        for (b, u) in basis.iter().zip(du) {
            for a in 0..D {
                for c in 0..D {
                    h[a][c] += u[a] * b.g[c];
                    hv[a][c] += u[a] * b.gv[c];
                }
            }
            ht += b.t * u[0];
            hvt += b.tv * u[0];
        }
        let (f, fv) = (plus_identity(&h, 1.0), plus_identity(&hv, 1.0));
        // J − 1 = (1 + d)(1 + H_θθ) − 1 with d = det(I + H) − 1 = tr H + I₂(H) + det H (I₂, the sum
        // of the principal 2 × 2 minors, only in three dimensions: in two it is det H).
        let minors = if D == 3 {
            h[0][0] * h[1][1] - h[0][1] * h[1][0] + h[1][1] * h[2][2] - h[1][2] * h[2][1] + h[0][0] * h[2][2]
                - h[0][2] * h[2][0]
        } else {
            0.0
        };
        let d = trace(&h, 0.0) + minors + det(&h);
        let dj = d + ht + d * ht;
        let gradients = Kinematics {
            f,
            j: det(&f) * (1.0 + ht),
            dj,
            fv,
            jv: det(&fv) * (1.0 + hvt),
            f_hoop: 1.0 + ht,
            fv_hoop: 1.0 + hvt,
            linear,
            ..Kinematics::rest()
        };
        if linear {
            let tr = trace(&h, ht);
            let trv = trace(&hv, hvt);
            let vol = (trv - tr) / 3.0;
            return Kinematics { deps: strain_of(&h, ht, vol), ..gradients };
        }
        let (fh_inv, fvh_inv) = (inverse(&plus_identity(&h, 0.5)), inverse(&plus_identity(&hv, 0.5)));
        let l = mul(&h, &fh_inv);
        let lv = mul(&hv, &fvh_inv);
        let (lt, lvt) = (ht / (1.0 + 0.5 * ht), hvt / (1.0 + 0.5 * hvt));
        let tr = trace(&l, lt);
        let trv = trace(&lv, lvt);
        let vol = (trv - tr) / 3.0;
        let deps = strain_of(&l, lt, vol);
        let omega = 0.5 * (l[1][0] - l[0][1]);
        let (half_spin_inv, rotation) = if D == 3 {
            // W = ½(L − Lᵀ), R = (I − W/2)⁻¹(I + W/2).
            let w: Mat<D> = std::array::from_fn(|i| std::array::from_fn(|j| 0.5 * (l[i][j] - l[j][i])));
            let a_inv = inverse(&plus_identity(&w, -0.5));
            (a_inv, mul(&a_inv, &plus_identity(&w, 0.5)))
        } else {
            (identity(), identity())
        };
        Kinematics {
            f_inv: inverse(&f),
            fv_inv: inverse(&fv),
            fh_inv,
            fvh_inv,
            l,
            lv,
            deps,
            omega: if D == 2 { omega } else { 0.0 },
            theta: if D == 2 { 2.0 * (0.5 * omega).atan() } else { 0.0 },
            half_spin_inv,
            rotation,
            ..gradients
        }
    }

    /// The kinematics with [002]'s F̄ (without B̄ and, in two dimensions, in plane strain): the
    /// strain increment's volumetric part is the mid-step rate of ΔF̄ = c ΔF (F_v = c F, Eq. 27),
    /// its deviatoric part and the rotation are ΔF's; only the stress sees F̄ ([002] L237): the
    /// volume ratio J_v and the deformation gradient the point keeps stay ΔF's. c = 1 leaves the
    /// kinematics as they are.
    pub fn with_volume_scale(self, c: f64) -> Kinematics<D> {
        if c == 1.0 || self.linear {
            return self;
        }
        let fv: Mat<D> = self.f.map(|r| r.map(|v| c * v));
        let hv: Mat<D> =
            std::array::from_fn(|i| std::array::from_fn(|j| if i == j { fv[i][j] - 1.0 } else { fv[i][j] }));
        let fvh_inv = inverse(&plus_identity(&hv, 0.5));
        let lv = mul(&hv, &fvh_inv);
        let (tr, trv) = (trace(&self.l, 0.0), trace(&lv, 0.0));
        let vol = (trv - tr) / 3.0;
        Kinematics { fv, fv_inv: inverse(&fv), fvh_inv, lv, deps: strain_of(&self.l, 0.0, vol), ..self }
    }

    /// The kinematics of a step without motion.
    pub fn rest() -> Kinematics<D> {
        Kinematics {
            f: identity(),
            j: 1.0,
            dj: 0.0,
            fv: identity(),
            jv: 1.0,
            f_inv: identity(),
            fv_inv: identity(),
            fh_inv: identity(),
            fvh_inv: identity(),
            l: [[0.0; D]; D],
            lv: [[0.0; D]; D],
            deps: [0.0; NS],
            omega: 0.0,
            theta: 0.0,
            half_spin_inv: identity(),
            rotation: identity(),
            f_hoop: 1.0,
            fv_hoop: 1.0,
            linear: false,
            projected: None,
        }
    }

    /// The kinematics of an implicit step with [002]'s F̄ (`stabilisation.fbar`, without B̄, finite
    /// strain; in two dimensions plane strain): the stress sees ΔF̄ = c ΔF whose determinant is the
    /// projected volume ratio of the step, r = J̄_{n+1}/J̄_n (c = (r/J)^{1/D}, [002] Eq. 27). As in
    /// [`Kinematics::with_volume_scale`], the strain increment's volumetric part is the mid-step
    /// rate of ΔF̄, its deviatoric part and the rotation are ΔF's, and the volume ratio, the
    /// gradients on x_{n+1} and the deformation gradient the point keeps stay ΔF's ([002] L237).
    /// With μ_i = λ_i + 1 for the eigenvalues λ_i of ΔF̄, the mid-step rate's trace is
    /// tr L̄ = Σ 2(λ_i − 1)/(λ_i + 1) = 2D − 4 e_{D−1}(μ)/e_D(μ), a function of ΔF̄'s invariants
    /// a = tr ΔF̄, b = I₂(ΔF̄) (three dimensions) and r, which [`Kinematics::deps_derivative`] and
    /// [`Kinematics::deps_volume_derivative`] differentiate:
    /// in two dimensions tr L̄ = 4 − 4 (2 + a)/(1 + a + r) = 4 (r − 1)/(1 + a + r); in three
    /// tr L̄ = 6 − 4 (3 + 2a + b)/(1 + a + b + r), its value formed from H̄ = ΔF̄ − I (small at small
    /// strains). The caller passes `r_minus_one` = r − 1, formed without cancellation, so that the
    /// volumetric strain keeps its relative precision at small strains. r = J gives c = 1 and the
    /// step's own kinematics.
    pub fn with_projected_volume(self, r_minus_one: f64) -> Kinematics<D> {
        debug_assert!(!self.linear && self.f_hoop == 1.0, "F̄ is built for finite-strain steps without hoop");
        let r = 1.0 + r_minus_one;
        let l = &self.l;
        if D == 2 {
            let c = (r / self.j).sqrt();
            let a = c * (self.f[0][0] + self.f[1][1]);
            let den = 1.0 + a + r;
            let tr_bar = 4.0 * r_minus_one / den;
            let vol = (tr_bar - (l[0][0] + l[1][1])) / 3.0;
            // ∂ tr L̄/∂a = −4(r − 1)/den², ∂ tr L̄/∂r|_a = 4(2 + a)/den² and ∂a/∂r = a/(2r).
            let dtr_da = -4.0 * r_minus_one / (den * den);
            let dtr_dr = dtr_da * a / (2.0 * r) + 4.0 * (2.0 + a) / (den * den);
            let projected = Projected { c, a, b: 0.0, dtr_da, dtr_db: 0.0, dtr_dr };
            return Kinematics { deps: strain_of(l, 0.0, vol), projected: Some(projected), ..self };
        }
        // c − 1 from r/J − 1 = (r − 1 − (J − 1))/J without cancellation: c³ − 1 = x.
        let x = (r_minus_one - self.dj) / self.j;
        let c = (1.0 + x).cbrt();
        let cm1 = x / (c * c + c + 1.0);
        // H̄ = ΔF̄ − I = (c − 1) I + c H, and tr L̄ = tr(H̄ (I + H̄/2)⁻¹).
        let hbar: Mat<D> = std::array::from_fn(|i| {
            std::array::from_fn(|k| {
                c * (self.f[i][k] - if i == k { 1.0 } else { 0.0 }) + if i == k { cm1 } else { 0.0 }
            })
        });
        let tr_bar = trace(&mul(&hbar, &inverse(&plus_identity(&hbar, 0.5))), 0.0);
        let vol = (tr_bar - trace(l, 0.0)) / 3.0;
        let t = trace(&self.f, 0.0);
        let minors = |m: &Mat<D>| {
            m[0][0] * m[1][1] - m[0][1] * m[1][0] + m[1][1] * m[2][2] - m[1][2] * m[2][1] + m[0][0] * m[2][2]
                - m[0][2] * m[2][0]
        };
        let (a, b) = (c * t, c * c * minors(&self.f));
        // e₂(μ) = 3 + 2a + b, e₃(μ) = 1 + a + b + r.
        let (n, q) = (3.0 + 2.0 * a + b, 1.0 + a + b + r);
        let q2 = q * q;
        let (dtr_da, dtr_db, dtr_dr_ab) = (-4.0 * (2.0 * q - n) / q2, -4.0 * (q - n) / q2, 4.0 * n / q2);
        // ∂c/∂r = c/(3r): ∂a/∂r = a/(3r), ∂b/∂r = 2b/(3r).
        let dtr_dr = dtr_dr_ab + (dtr_da * a + 2.0 * dtr_db * b) / (3.0 * r);
        let projected = Projected { c, a, b, dtr_da, dtr_db, dtr_dr };
        Kinematics { deps: strain_of(l, 0.0, vol), projected: Some(projected), ..self }
    }

    /// The stress `s` turned by the step's rotation, R s Rᵀ (the start of the objective update).
    pub fn rotate(&self, s: &Stress) -> Stress {
        if D == 2 {
            rotate(s, self.theta)
        } else {
            principal::rotate(&std::array::from_fn(|i| std::array::from_fn(|j| self.rotation[i][j])), s)
        }
    }

    /// ∂Δε/∂r, the strain increment's derivative with respect to the projected volume ratio of an
    /// implicit F̄ step ([`Kinematics::with_projected_volume`]; zero without it): ⅓ d(tr L̄)/dr m,
    /// m = [1, 1, 0, 1, 0, 0].
    pub fn deps_volume_derivative(&self) -> Stress {
        let Some(pj) = self.projected else { return [0.0; NS] };
        let d = pj.dtr_dr / 3.0;
        [d, d, 0.0, d, 0.0, 0.0]
    }

    /// The hoop operators of a node on x_{n+1}: (T', T̄') = (T/F_θθ, T̄/F_v,θθ).
    #[inline]
    pub fn hoop(&self, b: &NodeBasis<D>) -> (f64, f64) {
        if self.linear {
            return (b.t, b.tv);
        }
        (b.t / self.f_hoop, b.tv / self.fv_hoop)
    }

    /// The gradients of a node's basis function on x_{n+1}: (∇'S, ∇̄'S) = (F⁻ᵀ∇S, F_v⁻ᵀ∇̄S).
    #[inline]
    pub fn spatial(&self, b: &NodeBasis<D>) -> ([f64; D], [f64; D]) {
        (mul_t(&self.f_inv, b.g), mul_t(&self.fv_inv, b.gv))
    }

    /// dL/dΔu_l,d for a node whose basis has F_h⁻ᵀ∇S_l = `gh`: dL = (I − L/2) dH F_h⁻¹ with
    /// dH = e_d ⊗ ∇S_l, so dL_ac = (I − L/2)_ad gh_c.
    #[inline]
    fn rate_derivative_at(&self, gh: &[f64; D], d: usize) -> Mat<D> {
        std::array::from_fn(|a| std::array::from_fn(|c| (if a == d { 1.0 } else { 0.0 } - 0.5 * self.l[a][d]) * gh[c]))
    }

    /// ∂Δε/∂Δu_l (6 strain components × D displacement components) for a node with basis `b`.
    ///
    /// dL = (I − L/2) dH F_h⁻¹ with dH = e_d ⊗ ∇S_l, so dL_ab = (I − L/2)_ad (F_h⁻ᵀ∇S_l)_b; the
    /// same for L_v with ∇̄S_l. The hoop rate L_θθ = H_θθ/(1 + H_θθ/2) has
    /// dL_θθ/dΔu_l,r = T_l/(1 + H_θθ/2)², and L_v,θθ likewise with T̄_l.
    pub fn deps_derivative(&self, b: &NodeBasis<D>) -> [[f64; D]; NS] {
        let gh = mul_t(&self.fh_inv, b.g);
        let gvh = mul_t(&self.fvh_inv, b.gv);
        let gs = mul_t(&self.f_inv, b.g);
        let mid = |f: f64| if self.linear { 1.0 } else { 1.0 / (0.5 * (1.0 + f)).powi(2) };
        let (dlt, dlvt) = (b.t * mid(self.f_hoop), b.tv * mid(self.fv_hoop));
        // Column d: the strain increment of a unit increment of component d.
        let column = |d: usize| -> Stress {
            let dl = self.rate_derivative_at(&gh, d);
            let dlv = |a: usize, c: usize| (if a == d { 1.0 } else { 0.0 } - 0.5 * self.lv[a][d]) * gvh[c];
            let (lt, lvt) = if d == 0 { (dlt, dlvt) } else { (0.0, 0.0) };
            let tr = trace(&dl, lt);
            // With an implicit F̄: d tr L̄ = ∂tr L̄/∂a (c ∂tr ΔF − (a/2J) ∂J), ∂tr ΔF/∂Δu_l,d = (∇S_l)_d
            // and ∂J/∂Δu_l,d = J (F⁻ᵀ∇S_l)_d.
            let trv = match self.projected {
                // ∂c/∂Δu_l,d = −(c/D) ∂J/J; in three dimensions b = c² I₂(ΔF) with
                // ∂I₂/∂Δu_l,d = tr ΔF (∇S_l)_d − Σ_k ΔF_kd (∇S_l)_k.
                Some(pj) if D == 3 => {
                    let f = &self.f;
                    let dm = trace(f, 0.0) * b.g[d] - (0..D).map(|k| f[k][d] * b.g[k]).sum::<f64>();
                    pj.dtr_da * (pj.c * b.g[d] - pj.a * gs[d] / 3.0)
                        + pj.dtr_db * (pj.c * pj.c * dm - 2.0 * pj.b * gs[d] / 3.0)
                }
                Some(pj) => pj.dtr_da * (pj.c * b.g[d] - 0.5 * pj.a * gs[d]),
                None => (1..D).fold(dlv(0, 0), |s, a| s + dlv(a, a)) + lvt,
            };
            let vol = (trv - tr) / 3.0;
            strain_of(&dl, lt, vol)
        };
        // (A loop rather than `from_fn`, whose call of the closure is not inlined.)
        let mut cols = [[0.0; NS]; D];
        for (d, col) in cols.iter_mut().enumerate() {
            *col = column(d);
        }
        std::array::from_fn(|r| std::array::from_fn(|d| cols[d][r]))
    }

    /// ∂(R σ_n Rᵀ)/∂Δu_l (6 stress components × D displacement components) for a node with basis
    /// `b`, at the rotated stress `rotated` = R σ_n Rᵀ: dR = (I − W/2)⁻¹ (dW/2)(I + R), so
    /// d(R σ_n Rᵀ) = Ω σ' − σ' Ω with the spin Ω = dR Rᵀ = (I − W/2)⁻¹ (dW/2)(I + Rᵀ) and
    /// dW = ½(dL − dLᵀ). (In two dimensions the same is dθ times the derivative of the turn about
    /// z, [`rotate_derivative`].)
    pub fn rotated_derivative(&self, b: &NodeBasis<D>, rotated: &Stress) -> [[f64; D]; NS] {
        let mut out = [[0.0; D]; NS];
        // (Zero without the step's rotation, and for operators without a gradient ∇S.)
        if self.linear || b.g.iter().all(|&g| g == 0.0) {
            return out;
        }
        if D == 2 {
            let (drot, dt) = (rotate_derivative(rotated), self.theta_derivative(b));
            for (row, v) in out.iter_mut().zip(drot) {
                for (o, t) in row.iter_mut().zip(dt) {
                    *o = v * t;
                }
            }
            return out;
        }
        let s = principal::tensor(rotated);
        let r_t: Mat<D> = std::array::from_fn(|i| std::array::from_fn(|j| self.rotation[j][i]));
        let i_rt = plus_identity(&r_t, 1.0);
        let gh = mul_t(&self.fh_inv, b.g);
        for d in 0..D {
            let dl = self.rate_derivative_at(&gh, d);
            let half_dw: Mat<D> = std::array::from_fn(|i| std::array::from_fn(|j| 0.25 * (dl[i][j] - dl[j][i])));
            let omega = mul(&mul(&self.half_spin_inv, &half_dw), &i_rt);
            let ds = principal::vector(&std::array::from_fn(|i| {
                std::array::from_fn(|j| (0..3).map(|k| omega[i][k] * s[k][j] - s[i][k] * omega[k][j]).sum::<f64>())
            }));
            for (row, v) in out.iter_mut().zip(ds) {
                row[d] = v;
            }
        }
        out
    }

    /// ∂θ/∂Δu_l (D displacement components) for a node with basis `b`: the angle about z of a
    /// two-dimensional step (θ = 2 atan(ω/2), dθ = dω/(1 + ω²/4), dω = ½(dL_yx − dL_xy)).
    pub fn theta_derivative(&self, b: &NodeBasis<D>) -> [f64; D] {
        if self.linear {
            return [0.0; D];
        }
        let gh = mul_t(&self.fh_inv, b.g);
        let factor = 1.0 / (1.0 + 0.25 * self.omega * self.omega);
        // dL_ac = (I − L/2)_ad gh_c, of which dω takes dL_yx and dL_xy.
        let dl = |a: usize, c: usize, d: usize| (if a == d { 1.0 } else { 0.0 } - 0.5 * self.l[a][d]) * gh[c];
        std::array::from_fn(|d| factor * 0.5 * (dl(1, 0, d) - dl(0, 1, d)))
    }

    /// The incremental deformation gradient the particle keeps: F̄ = (J_v/J)^{1/D} F, whose
    /// determinant is J_v (so that the domain and the volume follow the same volume change; in
    /// axial symmetry its in-plane determinant is J_v/F_θθ, the area change of a ring whose
    /// radius grew by F_θθ).
    pub fn f_bar(&self) -> Mat<D> {
        let s = self.volume_scale();
        self.f.map(|r| r.map(|v| v * s))
    }

    /// The scale s = (J_v/J)^{1/D} of [`Kinematics::f_bar`] (1 where J or J_v is not positive).
    pub fn volume_scale(&self) -> f64 {
        if self.j > 0.0 && self.jv > 0.0 {
            let ratio = self.jv / self.j;
            if D == 2 {
                ratio.sqrt()
            } else {
                ratio.cbrt()
            }
        } else {
            1.0
        }
    }
}

/// The stress σ rotated about z by θ: R σ Rᵀ (σ_zz unchanged; the out-of-plane shears
/// (σ_zx, σ_yz) turn as a vector).
pub fn rotate(s: &Stress, theta: f64) -> Stress {
    if theta == 0.0 {
        return *s;
    }
    let (c, sn) = (theta.cos(), theta.sin());
    let r = [[c, -sn], [sn, c]];
    let m = [[s[0], s[2]], [s[2], s[1]]];
    let rm = mul(&r, &m);
    let rt = [[c, sn], [-sn, c]];
    let out = mul(&rm, &rt);
    let (zx, yz) = if s[4] == 0.0 && s[5] == 0.0 { (0.0, 0.0) } else { (c * s[5] - sn * s[4], sn * s[5] + c * s[4]) };
    [out[0][0], out[1][1], 0.5 * (out[0][1] + out[1][0]), s[3], yz, zx]
}

/// d(R σ Rᵀ)/dθ at the rotated stress `s`: [−2σ_xy, 2σ_xy, σ_xx − σ_yy, 0, σ_zx, −σ_yz].
pub fn rotate_derivative(s: &Stress) -> Stress {
    [-2.0 * s[2], 2.0 * s[2], s[0] - s[1], 0.0, s[5], -s[4]]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn basis() -> Vec<NodeBasis> {
        (0..5)
            .map(|k| {
                let x = k as f64;
                NodeBasis {
                    s: 0.2,
                    g: [(x * 1.3).cos() * 3.0, (x * 0.9).sin() * 2.0],
                    gv: [(x * 1.1).cos() * 2.5, (x * 0.4).sin() * 1.5],
                    t: 0.2 + 0.1 * x,
                    tv: 0.3 - 0.05 * x,
                }
            })
            .collect()
    }

    fn du(k: usize, scale: f64) -> [f64; 2] {
        let x = k as f64;
        [scale * (0.3 + x * 0.7).sin(), scale * (1.1 * x - 0.2).cos()]
    }

    #[test]
    fn derivatives_match_central_differences() {
        let b = basis();
        let u: Vec<[f64; 2]> = (0..b.len()).map(|k| du(k, 0.02)).collect();
        check_derivatives(&b, &u, |v| Kinematics::new(&b, v.iter().copied(), false));
    }

    /// Asserts that ∂Δε/∂Δu_l, ∂θ/∂Δu_l (two dimensions) and ∂(R σ Rᵀ)/∂Δu_l of the kinematics
    /// `at(u)` match central differences at the nodal increments `u`, for every node of `b` and
    /// every component.
    fn check_derivatives<const D: usize>(
        b: &[NodeBasis<D>],
        u: &[[f64; D]],
        at: impl Fn(&[[f64; D]]) -> Kinematics<D>,
    ) {
        let k0 = at(u);
        let sigma = [3.0, -1.0, 0.7, 2.0, if D == 3 { 0.4 } else { 0.0 }, if D == 3 { -1.3 } else { 0.0 }];
        let rotated = k0.rotate(&sigma);
        let h = 1e-7;
        for l in 0..b.len() {
            let de = k0.deps_derivative(&b[l]);
            let dt = k0.theta_derivative(&b[l]);
            let dr = k0.rotated_derivative(&b[l], &rotated);
            for d in 0..D {
                let shifted = |s: f64| {
                    let mut v = u.to_vec();
                    v[l][d] += s;
                    at(&v)
                };
                let (p, m) = (shifted(h), shifted(-h));
                for (r, der) in de.iter().enumerate() {
                    let fd = (p.deps[r] - m.deps[r]) / (2.0 * h);
                    assert!(
                        (fd - der[d]).abs() < 1e-7 * (1.0 + fd.abs()),
                        "deps[{r}] node {l} comp {d}: {fd} vs {}",
                        der[d]
                    );
                }
                if D == 2 {
                    let fd = (p.theta - m.theta) / (2.0 * h);
                    assert!((fd - dt[d]).abs() < 1e-7 * (1.0 + fd.abs()), "theta node {l} comp {d}: {fd} vs {}", dt[d]);
                }
                let (sp, sm) = (p.rotate(&sigma), m.rotate(&sigma));
                for (r, der) in dr.iter().enumerate() {
                    let fd = (sp[r] - sm[r]) / (2.0 * h);
                    assert!(
                        (fd - der[d]).abs() < 1e-6 * (1.0 + fd.abs()),
                        "R σ Rᵀ [{r}] node {l} comp {d}: {fd} vs {}",
                        der[d]
                    );
                }
            }
        }
    }

    /// A basis of five nodes in three dimensions (distinct deviatoric and volumetric gradients).
    fn basis_3d() -> Vec<NodeBasis<3>> {
        (0..5)
            .map(|k| {
                let x = k as f64;
                NodeBasis {
                    s: 0.2,
                    g: [(x * 1.3).cos() * 3.0, (x * 0.9).sin() * 2.0, (x * 0.6 + 0.3).cos() * 2.2],
                    gv: [(x * 1.1).cos() * 2.5, (x * 0.4).sin() * 1.5, (x * 0.8 - 0.2).sin() * 1.8],
                    t: 0.0,
                    tv: 0.0,
                }
            })
            .collect()
    }

    fn du_3d(k: usize, scale: f64) -> [f64; 3] {
        let x = k as f64;
        [scale * (0.3 + x * 0.7).sin(), scale * (1.1 * x - 0.2).cos(), scale * (0.5 * x + 0.9).sin()]
    }

    #[test]
    fn derivatives_match_central_differences_in_three_dimensions() {
        let b = basis_3d();
        for scale in [0.02, 0.2] {
            let u: Vec<[f64; 3]> = (0..b.len()).map(|k| du_3d(k, scale)).collect();
            let k = Kinematics::new(&b, u.iter().copied(), false);
            assert!(k.deps[4].abs() > 1e-3 && k.deps[5].abs() > 1e-3, "{:?}", k.deps);
            check_derivatives(&b, &u, |v| Kinematics::new(&b, v.iter().copied(), false));
            // J − 1 without cancellation is det F − 1.
            assert!((k.dj - (k.j - 1.0)).abs() < 1e-14, "{} vs {}", k.dj, k.j - 1.0);
            // Geometrically linear: the derivatives are those of sym H, and there is no rotation.
            check_derivatives(&b, &u, |v| Kinematics::new(&b, v.iter().copied(), true));
        }
    }

    /// A rigid rotation Q about a tilted axis: no strain, R = Q to round-off (the Cayley transform
    /// of the mid-step spin is exact for it), J = 1, and the stress turns with the material.
    #[test]
    fn a_rigid_rotation_in_three_dimensions_has_no_strain_and_turns_the_stress() {
        let corners: Vec<[f64; 3]> =
            (0..8).map(|c| [(c & 1) as f64, ((c >> 1) & 1) as f64, ((c >> 2) & 1) as f64]).collect();
        // Trilinear gradients of the cube's centre reproduce a linear field.
        let b: Vec<NodeBasis<3>> = corners
            .iter()
            .map(|x| {
                let g: [f64; 3] = std::array::from_fn(|d| if x[d] == 0.0 { -0.25 } else { 0.25 });
                NodeBasis { s: 0.125, g, gv: g, t: 0.0, tv: 0.0 }
            })
            .collect();
        let n = 14f64.sqrt();
        for alpha in [0.1f64, 0.9, -1.4] {
            let q = principal::rotation([1.0 / n, -2.0 / n, 3.0 / n], alpha);
            let u = corners.iter().map(|x| std::array::from_fn(|i| (0..3).map(|k| q[i][k] * x[k]).sum::<f64>() - x[i]));
            let k = Kinematics::new(&b, u, false);
            assert!(k.deps.iter().all(|e| e.abs() < 1e-14), "{:?}", k.deps);
            assert!((k.j - 1.0).abs() < 1e-14 && (k.jv - 1.0).abs() < 1e-14);
            let s = [3.0, -1.0, 0.7, 2.0, 0.4, -1.3];
            let (turned, expected) = (k.rotate(&s), principal::rotate(&q, &s));
            assert!(turned.iter().zip(&expected).all(|(a, b)| (a - b).abs() < 1e-13), "{turned:?} vs {expected:?}");
            // F̄ keeps the rotation and the volume.
            let fb = k.f_bar();
            assert!((0..3).all(|i| (0..3).all(|j| (fb[i][j] - q[i][j]).abs() < 1e-14)));
        }
    }

    /// The basis of an F̄ step: plane strain, no B̄ (∇̄S = ∇S, no hoop operators).
    fn plane_basis() -> Vec<NodeBasis> {
        basis().into_iter().map(|b| NodeBasis { gv: b.g, t: 0.0, tv: 0.0, ..b }).collect()
    }

    /// Asserts that the implicit F̄ step's projected strain at the increments `u` is the explicit
    /// scaling's by c = (r/J)^{1/D} for each r of `rs` (to `tol`), with the step's own volume; that
    /// r = J gives the step's own strain; and that its derivatives in Δu and r at r = 1.04 match
    /// central differences.
    fn check_projected<const D: usize>(b: &[NodeBasis<D>], u: &[[f64; D]], rs: &[f64], tol: f64) {
        let k0 = Kinematics::new(b, u.iter().copied(), false);
        for &r in rs {
            let proj = k0.with_projected_volume(r - 1.0);
            let scaled = k0.with_volume_scale((r / k0.j).powf(1.0 / D as f64));
            for (p, e) in proj.deps.iter().zip(&scaled.deps) {
                assert!((p - e).abs() < tol, "r {r}: {:?} vs {:?}", proj.deps, scaled.deps);
            }
            assert_eq!(proj.jv, k0.jv, "the volume stays the step's own");
        }
        let own = k0.with_projected_volume(k0.dj);
        for (p, e) in own.deps.iter().zip(&k0.deps) {
            assert!((p - e).abs() < 1e-14 * (1.0 + e.abs()), "{:?} vs {:?}", own.deps, k0.deps);
        }
        let r0 = 1.04;
        let at = |v: &[[f64; D]], r: f64| Kinematics::new(b, v.iter().copied(), false).with_projected_volume(r - 1.0);
        check_derivatives(b, u, |v| at(v, r0));
        let (k1, h) = (at(u, r0), 1e-7);
        let dr = k1.deps_volume_derivative();
        let (p, m) = (at(u, r0 + h), at(u, r0 - h));
        for (row, der) in dr.iter().enumerate() {
            let fd = (p.deps[row] - m.deps[row]) / (2.0 * h);
            assert!((fd - der).abs() < 1e-7 * (1.0 + fd.abs()), "deps[{row}] in r: {fd} vs {der}");
        }
        assert!(dr[0].abs() > 0.1, "the strain sees r: {dr:?}");
    }

    /// The implicit F̄ in two dimensions (plane strain): with_projected_volume(r) is ΔF̄ = c ΔF
    /// with c = (r/J)^{1/2}, the same strain increment as the explicit step's
    /// with_volume_scale(c), whose trace is formed by matrix products; exact derivatives.
    #[test]
    fn the_projected_volume_is_the_explicit_scale_of_the_increment_with_exact_derivatives() {
        let b = plane_basis();
        let u: Vec<[f64; 2]> = (0..b.len()).map(|k| du(k, 0.03)).collect();
        check_projected(&b, &u, &[0.93, 1.0, 1.08], 1e-14);
    }

    /// The implicit F̄ in three dimensions, at small and finite increments, r near 1 included.
    #[test]
    fn the_projected_volume_in_three_dimensions_is_the_scaled_increment_with_exact_derivatives() {
        let b: Vec<NodeBasis<3>> = basis_3d().into_iter().map(|n| NodeBasis { gv: n.g, ..n }).collect();
        for scale in [1e-4, 0.03] {
            let u: Vec<[f64; 3]> = (0..b.len()).map(|k| du_3d(k, scale)).collect();
            check_projected(&b, &u, &[0.93, 1.0, 1.08, 1.0 + 1e-6], 1e-13);
        }
    }

    #[test]
    fn a_rigid_rotation_has_no_strain_and_its_exact_angle() {
        // Nodes of a unit square moved by a rigid rotation α about the origin; bilinear gradients
        // of a point at its centre reproduce the linear field exactly.
        let pts = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
        let b: Vec<NodeBasis> = pts
            .iter()
            .map(|&(x, y): &(f64, f64)| {
                let g = [if x == 0.0 { -0.5 } else { 0.5 }, if y == 0.0 { -0.5 } else { 0.5 }];
                NodeBasis { s: 0.25, g, gv: g, t: 0.0, tv: 0.0 }
            })
            .collect();
        for alpha in [0.1f64, 0.9, -1.4] {
            let (c, s) = (alpha.cos(), alpha.sin());
            let u = pts.iter().map(|&(x, y)| [c * x - s * y - x, s * x + c * y - y]);
            let k = Kinematics::new(&b, u, false);
            assert!(k.deps.iter().all(|e| e.abs() < 1e-14), "{:?}", k.deps);
            assert!((k.theta - alpha).abs() < 1e-14, "{} vs {alpha}", k.theta);
            assert!((k.j - 1.0).abs() < 1e-14 && (k.jv - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn rotation_of_stress_and_its_derivative() {
        let s = [3.0, -1.0, 0.7, 2.0, 0.4, -1.3];
        let r = rotate(&s, 0.3);
        // It is R σ Rᵀ with R the turn about z.
        let rz = crate::soils::principal::rotation([0.0, 0.0, 1.0], 0.3);
        let full = crate::soils::principal::rotate(&rz, &s);
        assert!(r.iter().zip(&full).all(|(a, b)| (a - b).abs() < 1e-14), "{r:?} vs {full:?}");
        // Invariants in the plane are kept.
        assert!(((r[0] + r[1]) - (s[0] + s[1])).abs() < 1e-14);
        assert!(((r[0] * r[1] - r[2] * r[2]) - (s[0] * s[1] - s[2] * s[2])).abs() < 1e-13);
        let h = 1e-6;
        let (p, m) = (rotate(&s, 0.3 + h), rotate(&s, 0.3 - h));
        let d = rotate_derivative(&r);
        for c in 0..6 {
            assert!(((p[c] - m[c]) / (2.0 * h) - d[c]).abs() < 1e-8, "component {c}");
        }
        // Four quarter turns are the identity; one is the swap of xx and yy with σ_xy negated.
        let q = rotate(&s, std::f64::consts::FRAC_PI_2);
        assert!((q[0] - s[1]).abs() < 1e-14 && (q[1] - s[0]).abs() < 1e-14 && (q[2] + s[2]).abs() < 1e-14);
    }
}
