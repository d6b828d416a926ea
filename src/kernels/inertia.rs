//! Inertia and body force of both phases ([003] Eqs. 16a, 16b), and the drag between them
//! ([`drag`], [003] Eqs. 16c–e).
//!
//! Residual at stencil node i: S_i m_s (a_u − b) in the u rows and S_i m_w (a_U − b) in the U rows,
//! with a = a₀ Σ S_j Δd_j + ã_n (Newmark); tangent a₀ S_i S_j m (the consistent mass).

use super::{Newmark, Point};

/// Adds the inertia and body-force residual.
pub fn residual(pt: &Point, out: &mut [f64]) {
    let (nd, part, it) = (pt.layout.nd, pt.part, &pt.interp);
    for (k, b) in pt.basis.iter().enumerate() {
        for c in 0..2 {
            out[k * nd + c] += b.s * part.mass * (it.a_u[c] - part.body_acc[c]);
            if let Some(w) = pt.layout.w {
                out[k * nd + w + c] += b.s * part.water_mass * (it.a_w[c] - part.body_acc[c]);
            }
        }
    }
}

/// Adds a₀ M_u and a₀ M_U.
pub fn tangent(pt: &Point, nm: &Newmark, out: &mut [f64]) {
    let (nd, m) = (pt.layout.nd, pt.size());
    for (k, bk) in pt.basis.iter().enumerate() {
        for (l, bl) in pt.basis.iter().enumerate() {
            let ss = bk.s * bl.s * nm.a0;
            for c in 0..2 {
                out[(k * nd + c) * m + l * nd + c] += ss * pt.part.mass;
                if let Some(w) = pt.layout.w {
                    out[(k * nd + w + c) * m + l * nd + w + c] += ss * pt.part.water_mass;
                }
            }
        }
    }
}

/// Drag between the phases: S_i c (v_u − v_U) in the u rows and S_i c (v_U − v_u) in the U rows,
/// c = n² γ_w V / k ([003] Eqs. 16c–e with the coefficient of the spec).
pub mod drag {
    use super::super::{Newmark, Point};

    /// Adds the drag residual (two-phase layouts only).
    pub fn residual(pt: &Point, out: &mut [f64]) {
        let Some(w) = pt.layout.w else { return };
        let (nd, it) = (pt.layout.nd, &pt.interp);
        for (k, b) in pt.basis.iter().enumerate() {
            for c in 0..2 {
                let f = b.s * pt.part.drag * (it.v_u[c] - it.v_w[c]);
                out[k * nd + c] += f;
                out[k * nd + w + c] -= f;
            }
        }
    }

    /// Adds a₁ C in the u–u, u–U, U–u and U–U blocks.
    pub fn tangent(pt: &Point, nm: &Newmark, out: &mut [f64]) {
        let Some(w) = pt.layout.w else { return };
        let (nd, m) = (pt.layout.nd, pt.size());
        for (k, bk) in pt.basis.iter().enumerate() {
            for (l, bl) in pt.basis.iter().enumerate() {
                let c1 = bk.s * bl.s * nm.a1 * pt.part.drag;
                for c in 0..2 {
                    let (ru, rw) = ((k * nd + c) * m, (k * nd + w + c) * m);
                    let (cu, cw) = (l * nd + c, l * nd + w + c);
                    out[ru + cu] += c1;
                    out[ru + cw] -= c1;
                    out[rw + cu] -= c1;
                    out[rw + cw] += c1;
                }
            }
        }
    }
}
