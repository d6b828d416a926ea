//! Finite-strain kinematics of one material point over a step, in the updated Lagrangian frame of
//! the reset grid (plane strain).
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
//!   ω = ½(L_yx − L_xy),  R = (I − ½W)⁻¹(I + ½W), a rotation by θ = 2 atan(ω/2),
//! and the soil model starts from the rotated stress R σ_n Rᵀ. A rigid rotation by α gives
//! sym L = 0 and θ = α exactly, so the stress turns with the material to round-off.
//!
//! **Geometrically linear steps** (`linear = true`, `analysis.kinematics = "linear_increments"`,
//! [001] Eqs. 5, 7, 11): the step is small-strain on x_n. Δε = sym H − ⅓ tr H m + ⅓ tr H_v m (the
//! hoop component H_θθ), no rotation (θ = 0), and the gradients and hoop operators the forces use
//! stay those of x_n (F⁻ᵀ → I), so the step's residual is linear in Δu and its tangent is the
//! material part alone. J, J_v and F̄ are still those of the motion: the particle's volume, domain
//! and position follow it between steps.
//!
//! **Axial symmetry** (x ≡ r, `../shared/seeds-001-002.md` Part A2): F is block diagonal with the
//! hoop stretch F_θθ = 1 + H_θθ, H_θθ = Σ T_i Δu_r,i (T_i the node's hoop operator, S_i/r_p for the
//! planar weights: F_θθ = r_{n+1}/r_n), and F_v,θθ likewise with B̄'s T̄_i. Then J = det F_rz F_θθ,
//! J_v = det F_v,rz F_v,θθ, the mid-step hoop rate L_θθ = H_θθ/(1 + H_θθ/2) is the fourth strain
//! component (the zz slot of plane strain) and enters the traces of L and L_v; on x_{n+1} the hoop
//! operators are T'_i = T_i/F_θθ and T̄'_i = T̄_i/F_v,θθ. The rotation stays in the (r, y) plane. In
//! plane strain T = 0 and every hoop quantity drops out.

use super::NodeBasis;
use crate::model::soil::Stress;

/// A 2 × 2 matrix, rows first.
pub type M2 = [[f64; 2]; 2];

const I2: M2 = [[1.0, 0.0], [0.0, 1.0]];

fn det(a: &M2) -> f64 {
    a[0][0] * a[1][1] - a[0][1] * a[1][0]
}

fn inverse(a: &M2) -> M2 {
    let d = det(a);
    [[a[1][1] / d, -a[0][1] / d], [-a[1][0] / d, a[0][0] / d]]
}

fn mul(a: &M2, b: &M2) -> M2 {
    let mut c = [[0.0; 2]; 2];
    for (i, ci) in c.iter_mut().enumerate() {
        for (j, cij) in ci.iter_mut().enumerate() {
            *cij = a[i][0] * b[0][j] + a[i][1] * b[1][j];
        }
    }
    c
}

/// The product a b of two in-plane matrices.
pub fn product(a: &M2, b: &M2) -> M2 {
    mul(a, b)
}

/// det(a) a⁻ᵀ v, the cofactor matrix of `a` times `v`: a gradient pushed forward by `a` up to the
/// factor 1/det a (Nanson's normal, a material field's gradient on the new configuration).
pub fn cofactor_mul(a: &M2, v: [f64; 2]) -> [f64; 2] {
    [a[1][1] * v[0] - a[1][0] * v[1], -a[0][1] * v[0] + a[0][0] * v[1]]
}

/// aᵀ v.
fn mul_t(a: &M2, v: [f64; 2]) -> [f64; 2] {
    [a[0][0] * v[0] + a[1][0] * v[1], a[0][1] * v[0] + a[1][1] * v[1]]
}

/// The kinematics of a point for given nodal increments (see the module documentation).
#[derive(Debug, Clone, Copy)]
pub struct Kinematics {
    /// F = I + H.
    pub f: M2,
    /// J = det F.
    pub j: f64,
    /// J − 1, formed from H without the cancellation of det F − 1 (what an implicit F̄ step's
    /// projection and volumetric strain take: at small strains det F − 1 keeps only the digits
    /// of J beyond 1, and the residual's round-off then swamps its changes).
    pub dj: f64,
    /// F_v = I + H_v.
    pub fv: M2,
    /// J_v = det F_v: the volume ratio of the step.
    pub jv: f64,
    /// F⁻¹ (the transpose pushes gradients forward).
    f_inv: M2,
    /// F_v⁻¹.
    fv_inv: M2,
    /// F_h⁻¹ = (I + H/2)⁻¹.
    fh_inv: M2,
    /// (I + H_v/2)⁻¹.
    fvh_inv: M2,
    /// L = H F_h⁻¹.
    l: M2,
    /// L_v = H_v F_vh⁻¹.
    lv: M2,
    /// Strain increment Δε [xx, yy, γxy, zz].
    pub deps: [f64; 4],
    /// ω = ½(L_yx − L_xy).
    pub omega: f64,
    /// Rotation angle of the step θ = 2 atan(ω/2) [rad].
    pub theta: f64,
    /// The hoop stretch F_θθ = 1 + Σ T_i Δu_r,i (1 in plane strain).
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
    /// c = (r/J)^{1/2}, ΔF̄ = c ΔF (r = J̄_{n+1}/J̄_n, the volume ratio of the step the stress sees).
    c: f64,
    /// a = tr ΔF̄ = c tr ΔF.
    a: f64,
    /// ∂ tr L̄/∂a at fixed r.
    dtr_da: f64,
    /// d tr L̄/dr at fixed ΔF (through a = (r/J)^{1/2} tr ΔF as well).
    dtr_dr: f64,
}

impl Kinematics {
    /// The kinematics for displacement increments `du[k]` at the nodes of `basis`, finite strain
    /// or (`linear`) a geometrically linear step.
    pub fn new(basis: &[NodeBasis], du: impl Iterator<Item = [f64; 2]>, linear: bool) -> Kinematics {
        let (mut h, mut hv) = ([[0.0; 2]; 2], [[0.0; 2]; 2]);
        let (mut ht, mut hvt) = (0.0, 0.0);
        for (b, u) in basis.iter().zip(du) {
            for a in 0..2 {
                for c in 0..2 {
                    h[a][c] += u[a] * b.g[c];
                    hv[a][c] += u[a] * b.gv[c];
                }
            }
            ht += b.t * u[0];
            hvt += b.tv * u[0];
        }
        let add = |a: &M2, s: f64| [[1.0 + s * a[0][0], s * a[0][1]], [s * a[1][0], 1.0 + s * a[1][1]]];
        let (f, fv) = (add(&h, 1.0), add(&hv, 1.0));
        // J − 1 = (1 + d)(1 + H_θθ) − 1 with d = det(I + H) − 1 = tr H + det H.
        let d = h[0][0] + h[1][1] + (h[0][0] * h[1][1] - h[0][1] * h[1][0]);
        let dj = d + ht + d * ht;
        if linear {
            let tr = h[0][0] + h[1][1] + ht;
            let trv = hv[0][0] + hv[1][1] + hvt;
            let vol = (trv - tr) / 3.0;
            return Kinematics {
                f,
                j: det(&f) * (1.0 + ht),
                dj,
                fv,
                jv: det(&fv) * (1.0 + hvt),
                f_hoop: 1.0 + ht,
                fv_hoop: 1.0 + hvt,
                deps: [h[0][0] + vol, h[1][1] + vol, h[0][1] + h[1][0], ht + vol],
                linear,
                ..Kinematics::rest()
            };
        }
        let (fh_inv, fvh_inv) = (inverse(&add(&h, 0.5)), inverse(&add(&hv, 0.5)));
        let l = mul(&h, &fh_inv);
        let lv = mul(&hv, &fvh_inv);
        let (lt, lvt) = (ht / (1.0 + 0.5 * ht), hvt / (1.0 + 0.5 * hvt));
        let tr = l[0][0] + l[1][1] + lt;
        let trv = lv[0][0] + lv[1][1] + lvt;
        let vol = (trv - tr) / 3.0;
        let deps = [l[0][0] + vol, l[1][1] + vol, l[0][1] + l[1][0], lt + vol];
        let omega = 0.5 * (l[1][0] - l[0][1]);
        Kinematics {
            f,
            j: det(&f) * (1.0 + ht),
            dj,
            fv,
            jv: det(&fv) * (1.0 + hvt),
            f_hoop: 1.0 + ht,
            fv_hoop: 1.0 + hvt,
            f_inv: inverse(&f),
            fv_inv: inverse(&fv),
            fh_inv,
            fvh_inv,
            l,
            lv,
            deps,
            omega,
            theta: 2.0 * (0.5 * omega).atan(),
            linear,
            projected: None,
        }
    }

    /// The kinematics with [002]'s F̄ (plane strain, without B̄): the strain increment's
    /// volumetric part is the mid-step rate of ΔF̄ = c ΔF (F_v = c F, Eq. 27), its deviatoric part
    /// and the rotation are ΔF's; only the stress sees F̄ ([002] L237): the volume ratio J_v and the
    /// deformation gradient the point keeps stay ΔF's. c = 1 leaves the kinematics as they are.
    pub fn with_volume_scale(self, c: f64) -> Kinematics {
        if c == 1.0 || self.linear {
            return self;
        }
        let fv = [[c * self.f[0][0], c * self.f[0][1]], [c * self.f[1][0], c * self.f[1][1]]];
        let hv = [[fv[0][0] - 1.0, fv[0][1]], [fv[1][0], fv[1][1] - 1.0]];
        let fvh_inv = inverse(&[[1.0 + 0.5 * hv[0][0], 0.5 * hv[0][1]], [0.5 * hv[1][0], 1.0 + 0.5 * hv[1][1]]]);
        let lv = mul(&hv, &fvh_inv);
        let (tr, trv) = (self.l[0][0] + self.l[1][1], lv[0][0] + lv[1][1]);
        let vol = (trv - tr) / 3.0;
        let l = &self.l;
        Kinematics {
            fv,
            fv_inv: inverse(&fv),
            fvh_inv,
            lv,
            deps: [l[0][0] + vol, l[1][1] + vol, l[0][1] + l[1][0], vol],
            ..self
        }
    }

    /// The kinematics of a step without motion.
    pub fn rest() -> Kinematics {
        Kinematics {
            f: I2,
            j: 1.0,
            dj: 0.0,
            fv: I2,
            jv: 1.0,
            f_inv: I2,
            fv_inv: I2,
            fh_inv: I2,
            fvh_inv: I2,
            l: [[0.0; 2]; 2],
            lv: [[0.0; 2]; 2],
            deps: [0.0; 4],
            omega: 0.0,
            theta: 0.0,
            f_hoop: 1.0,
            fv_hoop: 1.0,
            linear: false,
            projected: None,
        }
    }

    /// The kinematics of an implicit step with [002]'s F̄ (`stabilisation.fbar`, plane strain,
    /// without B̄, finite strain): the stress sees ΔF̄ = c ΔF whose determinant is the projected
    /// volume ratio of the step, r = J̄_{n+1}/J̄_n (c = (r/J)^{1/2}, [002] Eq. 27). As in
    /// [`Kinematics::with_volume_scale`], the strain increment's volumetric part is the mid-step
    /// rate of ΔF̄, its deviatoric part and the rotation are ΔF's, and the volume ratio, the
    /// gradients on x_{n+1} and the deformation gradient the point keeps stay ΔF's ([002] L237).
    /// For a 2 × 2 ΔF̄ with a = tr ΔF̄ the mid-step rate's trace has the closed form
    /// tr L̄ = tr(H̄ (I + H̄/2)⁻¹) = 4 − 4 (2 + a)/(1 + a + r) = 4 (r − 1)/(1 + a + r) (H̄ = ΔF̄ − I,
    /// det ΔF̄ = r), which [`Kinematics::deps_derivative`] and
    /// [`Kinematics::deps_volume_derivative`] differentiate. The caller passes `r_minus_one` = r − 1,
    /// formed without cancellation, so that the volumetric strain keeps its relative precision at
    /// small strains. r = J gives c = 1 and the step's own kinematics.
    pub fn with_projected_volume(self, r_minus_one: f64) -> Kinematics {
        debug_assert!(!self.linear && self.f_hoop == 1.0, "F̄ is built for finite-strain plane-strain steps");
        let r = 1.0 + r_minus_one;
        let c = (r / self.j).sqrt();
        let a = c * (self.f[0][0] + self.f[1][1]);
        let den = 1.0 + a + r;
        let tr_bar = 4.0 * r_minus_one / den;
        let l = &self.l;
        let vol = (tr_bar - (l[0][0] + l[1][1])) / 3.0;
        // ∂ tr L̄/∂a = −4(r − 1)/den², ∂ tr L̄/∂r|_a = 4(2 + a)/den² and ∂a/∂r = a/(2r).
        let dtr_da = -4.0 * r_minus_one / (den * den);
        let dtr_dr = dtr_da * a / (2.0 * r) + 4.0 * (2.0 + a) / (den * den);
        Kinematics {
            deps: [l[0][0] + vol, l[1][1] + vol, l[0][1] + l[1][0], vol],
            projected: Some(Projected { c, a, dtr_da, dtr_dr }),
            ..self
        }
    }

    /// ∂Δε/∂r, the strain increment's derivative with respect to the projected volume ratio of an
    /// implicit F̄ step ([`Kinematics::with_projected_volume`]; zero without it): ⅓ d(tr L̄)/dr m,
    /// m = [1, 1, 0, 1].
    pub fn deps_volume_derivative(&self) -> [f64; 4] {
        let Some(pj) = self.projected else { return [0.0; 4] };
        let d = pj.dtr_dr / 3.0;
        [d, d, 0.0, d]
    }

    /// The hoop operators of a node on x_{n+1}: (T', T̄') = (T/F_θθ, T̄/F_v,θθ).
    #[inline]
    pub fn hoop(&self, b: &NodeBasis) -> (f64, f64) {
        if self.linear {
            return (b.t, b.tv);
        }
        (b.t / self.f_hoop, b.tv / self.fv_hoop)
    }

    /// The gradients of a node's basis function on x_{n+1}: (∇'S, ∇̄'S) = (F⁻ᵀ∇S, F_v⁻ᵀ∇̄S).
    #[inline]
    pub fn spatial(&self, b: &NodeBasis) -> ([f64; 2], [f64; 2]) {
        (mul_t(&self.f_inv, b.g), mul_t(&self.fv_inv, b.gv))
    }

    /// ∂Δε/∂Δu_l (4 strain components × 2 displacement components) for a node with basis `b`.
    ///
    /// dL = (I − L/2) dH F_h⁻¹ with dH = e_d ⊗ ∇S_l, so dL_ab = (I − L/2)_ad (F_h⁻ᵀ∇S_l)_b; the
    /// same for L_v with ∇̄S_l. The hoop rate L_θθ = H_θθ/(1 + H_θθ/2) has
    /// dL_θθ/dΔu_l,r = T_l/(1 + H_θθ/2)², and L_v,θθ likewise with T̄_l.
    pub fn deps_derivative(&self, b: &NodeBasis) -> [[f64; 2]; 4] {
        let gh = mul_t(&self.fh_inv, b.g);
        let gvh = mul_t(&self.fvh_inv, b.gv);
        let gs = mul_t(&self.f_inv, b.g);
        let mid = |f: f64| if self.linear { 1.0 } else { 1.0 / (0.5 * (1.0 + f)).powi(2) };
        let (dlt, dlvt) = (b.t * mid(self.f_hoop), b.tv * mid(self.fv_hoop));
        // Column d: the strain increment of a unit increment of component d.
        let column = |d: usize| -> [f64; 4] {
            // dL[a][c] = (I − L/2)[a][d] gh[c].
            let dl = |a: usize, c: usize| (if a == d { 1.0 } else { 0.0 } - 0.5 * self.l[a][d]) * gh[c];
            let dlv = |a: usize, c: usize| (if a == d { 1.0 } else { 0.0 } - 0.5 * self.lv[a][d]) * gvh[c];
            let (lt, lvt) = if d == 0 { (dlt, dlvt) } else { (0.0, 0.0) };
            let tr = dl(0, 0) + dl(1, 1) + lt;
            // With an implicit F̄: d tr L̄ = ∂tr L̄/∂a (c ∂tr ΔF − (a/2J) ∂J), ∂tr ΔF/∂Δu_l,d = (∇S_l)_d
            // and ∂J/∂Δu_l,d = J (F⁻ᵀ∇S_l)_d.
            let trv = match self.projected {
                Some(pj) => pj.dtr_da * (pj.c * b.g[d] - 0.5 * pj.a * gs[d]),
                None => dlv(0, 0) + dlv(1, 1) + lvt,
            };
            let vol = (trv - tr) / 3.0;
            [dl(0, 0) + vol, dl(1, 1) + vol, dl(0, 1) + dl(1, 0), lt + vol]
        };
        let (c0, c1) = (column(0), column(1));
        std::array::from_fn(|r| [c0[r], c1[r]])
    }

    /// ∂θ/∂Δu_l (2 displacement components) for a node with basis `b`.
    pub fn theta_derivative(&self, b: &NodeBasis) -> [f64; 2] {
        if self.linear {
            return [0.0; 2];
        }
        let gh = mul_t(&self.fh_inv, b.g);
        let factor = 1.0 / (1.0 + 0.25 * self.omega * self.omega);
        let mut out = [0.0; 2];
        for (d, o) in out.iter_mut().enumerate() {
            let dl = |a: usize, c: usize| (if a == d { 1.0 } else { 0.0 } - 0.5 * self.l[a][d]) * gh[c];
            *o = factor * 0.5 * (dl(1, 0) - dl(0, 1));
        }
        out
    }

    /// The incremental deformation gradient the particle keeps: F̄ = (J_v/J)^{1/2} F, whose
    /// determinant is J_v (so that the domain and the volume follow the same volume change; in
    /// axial symmetry its in-plane determinant is J_v/F_θθ, the area change of a ring whose
    /// radius grew by F_θθ).
    pub fn f_bar(&self) -> M2 {
        let s = if self.j > 0.0 && self.jv > 0.0 { (self.jv / self.j).sqrt() } else { 1.0 };
        [[self.f[0][0] * s, self.f[0][1] * s], [self.f[1][0] * s, self.f[1][1] * s]]
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

    /// Asserts that ∂Δε/∂Δu_l and ∂θ/∂Δu_l of the kinematics `at(u)` match central differences at
    /// the nodal increments `u`, for every node of `b` and both components.
    fn check_derivatives(b: &[NodeBasis], u: &[[f64; 2]], at: impl Fn(&[[f64; 2]]) -> Kinematics) {
        let k0 = at(u);
        let h = 1e-7;
        for l in 0..b.len() {
            let de = k0.deps_derivative(&b[l]);
            let dt = k0.theta_derivative(&b[l]);
            for d in 0..2 {
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
                let fd = (p.theta - m.theta) / (2.0 * h);
                assert!((fd - dt[d]).abs() < 1e-7 * (1.0 + fd.abs()), "theta node {l} comp {d}: {fd} vs {}", dt[d]);
            }
        }
    }

    /// The basis of an F̄ step: plane strain, no B̄ (∇̄S = ∇S, no hoop operators).
    fn plane_basis() -> Vec<NodeBasis> {
        basis().into_iter().map(|b| NodeBasis { gv: b.g, t: 0.0, tv: 0.0, ..b }).collect()
    }

    #[test]
    fn the_projected_volume_is_the_explicit_scale_of_the_increment() {
        // with_projected_volume(r) is ΔF̄ = c ΔF with c = (r/J)^{1/2}: the same strain increment as
        // the explicit step's with_volume_scale(c), whose trace is formed by matrix products; and
        // r = J leaves the step's own kinematics.
        let b = plane_basis();
        let u: Vec<[f64; 2]> = (0..b.len()).map(|k| du(k, 0.03)).collect();
        let k0 = Kinematics::new(&b, u.iter().copied(), false);
        for r in [0.93, 1.0, 1.08] {
            let proj = k0.with_projected_volume(r - 1.0);
            let scaled = k0.with_volume_scale((r / k0.j).sqrt());
            for (a, e) in proj.deps.iter().zip(&scaled.deps) {
                assert!((a - e).abs() < 1e-14, "{:?} vs {:?}", proj.deps, scaled.deps);
            }
            assert_eq!(proj.jv, k0.jv, "the volume stays the step's own");
        }
        let own = k0.with_projected_volume(k0.dj);
        for (a, e) in own.deps.iter().zip(&k0.deps) {
            assert!((a - e).abs() < 1e-14);
        }
    }

    #[test]
    fn projected_derivatives_match_central_differences() {
        let b = plane_basis();
        let u: Vec<[f64; 2]> = (0..b.len()).map(|k| du(k, 0.03)).collect();
        let r0 = 1.04;
        let at = |v: &[[f64; 2]], r: f64| Kinematics::new(&b, v.iter().copied(), false).with_projected_volume(r - 1.0);
        check_derivatives(&b, &u, |v| at(v, r0));
        let (k0, h) = (at(&u, r0), 1e-7);
        let dr = k0.deps_volume_derivative();
        let (p, m) = (at(&u, r0 + h), at(&u, r0 - h));
        for (row, der) in dr.iter().enumerate() {
            let fd = (p.deps[row] - m.deps[row]) / (2.0 * h);
            assert!((fd - der).abs() < 1e-7 * (1.0 + fd.abs()), "deps[{row}] in r: {fd} vs {der}");
        }
        assert!(dr[0].abs() > 0.1, "the strain sees r: {dr:?}");
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
        let rz = crate::model::soil::principal::rotation([0.0, 0.0, 1.0], 0.3);
        let full = crate::model::soil::principal::rotate(&rz, &s);
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
