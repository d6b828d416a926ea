//! The pore water's mass balance: the continuity equation ([`continuity`], [003] Eq. 23b), the
//! Darcy flux of the u–p system ([`darcy`]) and the porosity-gradient terms that [003]'s
//! uniform-porosity equations drop ([`porosity_gradient`]).

use super::Point;

/// The share of the solid's volumetric strain in the water's balance: 1 − n where the water's
/// motion is an unknown (u–p–U, [003] Eq. 23b), 1 where the water follows the solid plus its Darcy
/// flux (u–p, Biot's storage equation).
fn solid_share<const D: usize, const M: usize>(pt: &Point<D, M>) -> f64 {
    if pt.layout.w.is_some() {
        1.0 - pt.part.porosity
    } else {
        1.0
    }
}

/// Continuity ([003] Eq. 23b for the step's increments, on x_n):
/// R_p,i = −S_i [(1 − n) ∇̄·Δu + n ∇̄·ΔU + Δp/Q] V (u–p–U) or −S_i [∇̄·Δu + Δp/Q] V (u–p);
/// tangent −G₁ᵀ, −G₂ᵀ and −P, weighted by w_mass. In axial symmetry the divergences include the
/// hoop term, ∇̄·Δu + Σ T̄_j Δu_r,j ([`super::super::Interp::dvol_u`]).
pub mod continuity {
    use super::super::{Interp, ParticleInput, Point, Scheme};

    /// Adds the continuity residual (layouts with a pressure).
    pub fn residual<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
        let Some(p) = pt.layout.p else { return };
        let (nd, it, part) = (pt.layout.nd, &pt.interp, pt.part);
        let n = part.porosity;
        let water = if pt.layout.w.is_some() { n * it.dvol_w } else { 0.0 };
        let rate = super::solid_share(pt) * it.dvol_u + water + it.dp * part.inv_q;
        for (k, b) in pt.basis.iter().enumerate() {
            out[k * nd + p] -= nm.w_mass * b.s * rate * part.volume;
        }
    }

    /// The pore-pressure increment that holds the continuity equation at the point itself, the
    /// explicit two-phase system's (u–U, no nodal pressure): the residual's integrand
    /// (1 − n) ∇̄·Δu + n ∇̄·ΔU + ∇n·(ΔU − Δu) + Δp/Q = 0 ([003] Eq. 23b with the porosity-gradient
    /// term of [`super::porosity_gradient`]) solved for Δp, with the divergences of the step's
    /// increments on x_n (B̄'s cell-centre divergences where the case asks for B̄).
    pub fn pointwise_increment<const D: usize>(it: &Interp<D>, part: &ParticleInput<D>) -> f64 {
        let n = part.porosity;
        let relative: f64 = (0..D).map(|c| part.grad_n[c] * (it.dw[c] - it.du[c])).sum();
        -((1.0 - n) * it.dvol_u + n * it.dvol_w + relative) / part.inv_q
    }

    /// Adds −G₁ᵀ (p–u), −G₂ᵀ (p–U) and −P (p–p, [003] 16i with the sign of Eq. 23b).
    pub fn tangent<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
        let Some(p) = pt.layout.p else { return };
        let (nd, m, part) = (pt.layout.nd, pt.size(), pt.part);
        let (n, v) = (part.porosity, part.volume * nm.w_mass);
        let fs = super::solid_share(pt);
        for (k, bk) in pt.basis.iter().enumerate() {
            let row = (k * nd + p) * m;
            for (l, bl) in pt.basis.iter().enumerate() {
                let mut div = bl.gv;
                div[0] += bl.tv;
                for c in 0..D {
                    out[row + l * nd + c] -= fs * bk.s * div[c] * v;
                    if let Some(w) = pt.layout.w {
                        out[row + l * nd + w + c] -= n * bk.s * div[c] * v;
                    }
                }
                out[row + l * nd + p] -= bk.s * bl.s * v * part.inv_q;
            }
        }
    }
}

/// The Darcy flux of the u–p system over the step, in the continuity rows (on x_n):
/// R_p,i −= Δt V (k/γ_w) ∇S_i·(∇p_θ − ρ_w b), ∇p_θ = ∇p_n + θ Σ ∇S_j Δp_j,
/// from ∇·u̇ + ∇·q + ṗ/Q = 0 with q = −(k/γ_w)(∇p − ρ_w b) integrated by parts (no flux across a
/// boundary where p is free: impermeable). ∇p_n is the particle's (carried from step to step like
/// p); b the body acceleration at t_{n+1}, so that a hydrostatic pressure drives no flow. Tangent
/// −θΔt V (k/γ_w) ∇S_i·∇S_j (p–p): with −P the negative semi-definite H of Biot's equations.
pub mod darcy {
    use super::super::{dot, Point, Scheme};

    /// Adds the flux residual (u–p layouts under a scheme with flow).
    pub fn residual<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
        let Some(p) = pt.layout.p else { return };
        if nm.flow_dt == 0.0 {
            return;
        }
        let (nd, it, part) = (pt.layout.nd, &pt.interp, pt.part);
        let drive: [f64; D] =
            std::array::from_fn(|c| part.grad_p[c] + nm.theta * it.grad_dp[c] - part.water_density * part.body_acc[c]);
        let f = nm.w_mass * nm.flow_dt * part.volume * part.mobility;
        for (k, b) in pt.basis.iter().enumerate() {
            out[k * nd + p] -= f * dot(b.g, drive);
        }
    }

    /// Adds −θΔt V (k/γ_w) ∇S_i·∇S_j in the p–p block.
    pub fn tangent<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
        let Some(p) = pt.layout.p else { return };
        if nm.flow_dt == 0.0 {
            return;
        }
        let (nd, m, part) = (pt.layout.nd, pt.size(), pt.part);
        let f = nm.w_mass * nm.flow_dt * nm.theta * part.volume * part.mobility;
        for (k, bk) in pt.basis.iter().enumerate() {
            for (l, bl) in pt.basis.iter().enumerate() {
                out[(k * nd + p) * m + l * nd + p] -= f * dot(bk.g, bl.g);
            }
        }
    }
}

/// The porosity-gradient terms (see the kernels' documentation): R_u,i += w_f S_i p ∇n V,
/// R_U,i −= w_f S_i p ∇n V, R_p,i −= w_mass S_i ∇n·(ΔU − Δu) V, with ∇n at t_n. The u–U system
/// (no nodal pressure) takes the momentum terms; its continuity equation holds at the points
/// ([`super::continuity::pointwise_increment`]).
pub mod porosity_gradient {
    use super::super::{Point, Scheme};

    /// Adds the ∇n residual (layouts with the water's motion).
    pub fn residual<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
        let Some(w) = pt.layout.w else { return };
        let (nd, it, part) = (pt.layout.nd, &pt.interp, pt.part);
        let gn = part.grad_n;
        let rel: f64 = (0..D).map(|c| gn[c] * (it.dw[c] - it.du[c])).sum();
        for (k, b) in pt.basis.iter().enumerate() {
            for c in 0..D {
                let f = nm.w_force * b.s * pt.p * gn[c] * part.volume;
                out[k * nd + c] += f;
                out[k * nd + w + c] -= f;
            }
            if let Some(p) = pt.layout.p {
                out[k * nd + p] -= nm.w_mass * b.s * rel * part.volume;
            }
        }
    }

    /// Adds ±S_k S_l ∇n V in u–p, U–p (weight w_f) and p–u, p–U (weight w_mass); without a nodal
    /// pressure (u–U) the momentum terms depend on no unknown.
    pub fn tangent<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
        let (Some(p), Some(w)) = (pt.layout.p, pt.layout.w) else { return };
        let (nd, m, part) = (pt.layout.nd, pt.size(), pt.part);
        for (k, bk) in pt.basis.iter().enumerate() {
            for (l, bl) in pt.basis.iter().enumerate() {
                for c in 0..D {
                    let g = bk.s * bl.s * part.grad_n[c] * part.volume;
                    out[(k * nd + c) * m + l * nd + p] += nm.w_force * g;
                    out[(k * nd + w + c) * m + l * nd + p] -= nm.w_force * g;
                    out[(k * nd + p) * m + l * nd + c] += nm.w_mass * g;
                    out[(k * nd + p) * m + l * nd + w + c] -= nm.w_mass * g;
                }
            }
        }
    }
}

/// A drained surface of the u–p system imposed on the material's own faces by Nitsche's method
/// (the non-symmetric, penalty-stabilised variant: Burman 2012, SIAM J. Numer. Anal. 50(4)), in the
/// continuity rows, for each exposed face of the particle on a drained moving surface:
/// R_p,i −= w_mass Δt κ A [−N_i (∇p_θ − ρ_w b)·n + (∇N_i·n + γ/h N_i) p_θ(x_f)],
/// the flux across the face that the integration by parts of [`darcy`] leaves out (consistency),
/// plus the weak condition p = 0 at the face (its antisymmetric and penalty terms; γ in
/// `assembly::NITSCHE_PENALTY`). N_i and ∇N_i are
/// the grid's bilinear shape functions at the face point x_f, A the face's length, n its outward
/// normal, κ = k/γ_w, ∇p_θ the particle's gradient as in [`darcy`] and
/// p_θ(x_f) = p_n + ∇p_n·(x_f − x_p) + θ Σ N_j(x_f) Δp_j. With the boundary terms of the
/// non-symmetric variant the flux form stays coercive, ∫κ|∇v|², for any γ ≥ 0, so that a face
/// that cuts a node's support to a sliver needs no larger penalty. Fixing the pressure at the
/// nodes beyond the face instead puts the drained boundary up to a cell above the material, and
/// its drainage vanishes as the surface comes near a grid line. Tangent
/// −w_mass θΔt κ A [−N_i ∇S_j·n + (∇N_i·n + γ/h N_i) N_j] (p–p).
pub mod drained_face {
    use super::super::{dot, Point, Scheme};

    /// Adds the Nitsche terms of the particle's drained faces (u–p layouts under a scheme with flow).
    pub fn residual<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
        let Some(p) = pt.layout.p else { return };
        if nm.flow_dt == 0.0 || pt.faces.is_empty() {
            return;
        }
        let (nd, it, part) = (pt.layout.nd, &pt.interp, pt.part);
        let drive: [f64; D] =
            std::array::from_fn(|c| part.grad_p[c] + nm.theta * it.grad_dp[c] - part.water_density * part.body_acc[c]);
        for (face, &dp_face) in pt.faces.iter().zip(&pt.face_dp) {
            let n = face.normal;
            let flux = dot(drive, n);
            let off = face.offset;
            let p_face = (0..D).fold(part.p, |s, c| s + part.grad_p[c] * off[c]) + nm.theta * dp_face;
            let f = nm.w_mass * nm.flow_dt * part.mobility * face.area;
            for (k, (s, g)) in face.basis.iter().take(pt.basis.len()).enumerate() {
                let dn = dot(*g, n);
                out[k * nd + p] -= f * (-s * flux + (dn + face.penalty * s) * p_face);
            }
        }
    }

    /// Adds the p–p tangent of the Nitsche terms.
    pub fn tangent<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
        let Some(p) = pt.layout.p else { return };
        if nm.flow_dt == 0.0 || pt.faces.is_empty() {
            return;
        }
        let (nd, m, part) = (pt.layout.nd, pt.size(), pt.part);
        let nn = pt.basis.len();
        for face in pt.faces {
            let n = face.normal;
            let f = nm.w_mass * nm.flow_dt * nm.theta * part.mobility * face.area;
            for (k, (sk, gk)) in face.basis.iter().take(nn).enumerate() {
                let dn = dot(*gk, n);
                for (l, bl) in pt.basis.iter().enumerate() {
                    let gn = dot(bl.g, n);
                    let sl = face.basis[l].0;
                    out[(k * nd + p) * m + l * nd + p] -= f * (-sk * gn + (dn + face.penalty * sk) * sl);
                }
            }
        }
    }
}
