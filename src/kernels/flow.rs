//! The pore water's mass balance: the continuity equation ([`continuity`], [003] Eq. 23b) and the
//! porosity-gradient terms that [003]'s uniform-porosity equations drop ([`porosity_gradient`]).

/// Continuity ([003] Eq. 23b for the step's increments, on x_n):
/// R_p,i = −S_i [(1 − n) ∇̄·Δu + n ∇̄·ΔU + Δp/Q] V; tangent −G₁ᵀ, −G₂ᵀ and −P.
pub mod continuity {
    use super::super::Point;

    /// Adds the continuity residual (layouts with a pressure).
    pub fn residual(pt: &Point, out: &mut [f64]) {
        let Some(p) = pt.layout.p else { return };
        let (nd, it, part) = (pt.layout.nd, &pt.interp, pt.part);
        let n = part.porosity;
        let water = if pt.layout.w.is_some() { n * it.dvol_w } else { 0.0 };
        let rate = (1.0 - n) * it.dvol_u + water + it.dp * part.inv_q;
        for (k, b) in pt.basis.iter().enumerate() {
            out[k * nd + p] -= b.s * rate * part.volume;
        }
    }

    /// Adds −G₁ᵀ (p–u), −G₂ᵀ (p–U) and −P (p–p, [003] 16i with the sign of Eq. 23b).
    pub fn tangent(pt: &Point, out: &mut [f64]) {
        let Some(p) = pt.layout.p else { return };
        let (nd, m, part) = (pt.layout.nd, pt.size(), pt.part);
        let (n, v) = (part.porosity, part.volume);
        for (k, bk) in pt.basis.iter().enumerate() {
            let row = (k * nd + p) * m;
            for (l, bl) in pt.basis.iter().enumerate() {
                for c in 0..2 {
                    out[row + l * nd + c] -= (1.0 - n) * bk.s * bl.gv[c] * v;
                    if let Some(w) = pt.layout.w {
                        out[row + l * nd + w + c] -= n * bk.s * bl.gv[c] * v;
                    }
                }
                out[row + l * nd + p] -= bk.s * bl.s * v * part.inv_q;
            }
        }
    }
}

/// The porosity-gradient terms (see the kernels' documentation): R_u,i += S_i p ∇n V,
/// R_U,i −= S_i p ∇n V, R_p,i −= S_i ∇n·(ΔU − Δu) V, with ∇n at t_n.
pub mod porosity_gradient {
    use super::super::Point;

    /// Adds the ∇n residual (u–p–U layouts only).
    pub fn residual(pt: &Point, out: &mut [f64]) {
        let (Some(p), Some(w)) = (pt.layout.p, pt.layout.w) else { return };
        let (nd, it, part) = (pt.layout.nd, &pt.interp, pt.part);
        let gn = part.grad_n;
        let rel: f64 = (0..2).map(|c| gn[c] * (it.dw[c] - it.du[c])).sum();
        for (k, b) in pt.basis.iter().enumerate() {
            for c in 0..2 {
                let f = b.s * pt.p * gn[c] * part.volume;
                out[k * nd + c] += f;
                out[k * nd + w + c] -= f;
            }
            out[k * nd + p] -= b.s * rel * part.volume;
        }
    }

    /// Adds ±S_k S_l ∇n V in u–p, U–p and p–u, p–U.
    pub fn tangent(pt: &Point, out: &mut [f64]) {
        let (Some(p), Some(w)) = (pt.layout.p, pt.layout.w) else { return };
        let (nd, m, part) = (pt.layout.nd, pt.size(), pt.part);
        for (k, bk) in pt.basis.iter().enumerate() {
            for (l, bl) in pt.basis.iter().enumerate() {
                for c in 0..2 {
                    let g = bk.s * bl.s * part.grad_n[c] * part.volume;
                    out[(k * nd + c) * m + l * nd + p] += g;
                    out[(k * nd + w + c) * m + l * nd + p] -= g;
                    out[(k * nd + p) * m + l * nd + c] += g;
                    out[(k * nd + p) * m + l * nd + w + c] -= g;
                }
            }
        }
    }
}
