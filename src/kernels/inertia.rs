//! Inertia and body force of both phases ([003] Eqs. 16a, 16b), and the drag between them
//! ([`drag`], [003] Eqs. 16c–e).
//!
//! Residual at stencil node i: S_i m_s (w_m a_u − w_f b) in the u rows and S_i m_w (w_m a_U − w_f b)
//! in the U rows, with a = a₀ Σ S_j Δd_j + ã_n (Newmark) and the weights w_m = 1 − α_m, w_f = 1 − α_f
//! of the generalized-α method (both 1 for Newmark; without inertia a = 0 and only the body force
//! remains); tangent w_m a₀ S_i S_j m (the consistent mass).

use super::{Point, Scheme};

/// Adds the inertia and body-force residual.
pub fn residual<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
    let (nd, part, it) = (pt.layout.nd, pt.part, &pt.interp);
    let (wm, wf) = (nm.w_inertia, nm.w_force);
    for (k, b) in pt.basis.iter().enumerate() {
        for c in 0..D {
            out[k * nd + c] += b.s * part.mass * (wm * it.motion.a_u[c] - wf * part.body_acc[c]);
            if let Some(w) = pt.layout.w {
                out[k * nd + w + c] += b.s * part.water_mass * (wm * it.motion.a_w[c] - wf * part.body_acc[c]);
            }
        }
    }
}

/// Adds w_m a₀ M_u and w_m a₀ M_U (nothing in a stage without inertia, a₀ w_m = 0).
pub fn tangent<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
    if nm.a0 * nm.w_inertia == 0.0 {
        return;
    }
    let (nd, m) = (pt.layout.nd, pt.size());
    for (k, bk) in pt.basis.iter().enumerate() {
        for (l, bl) in pt.basis.iter().enumerate() {
            let ss = bk.s * bl.s * nm.a0 * nm.w_inertia;
            for c in 0..D {
                out[(k * nd + c) * m + l * nd + c] += ss * pt.part.mass;
                if let Some(w) = pt.layout.w {
                    out[(k * nd + w + c) * m + l * nd + w + c] += ss * pt.part.water_mass;
                }
            }
        }
    }
}

/// Drag between the phases: w_f S_i c (v_u − v_U) in the u rows and w_f S_i c (v_U − v_u) in the U
/// rows, c = n² γ_w V / k ([003] Eqs. 16c–e with the coefficient of the spec). An explicit step
/// takes the drag at the nodes instead, lumped and implicit in the new velocities
/// (`assembly::explicit`), so that a low permeability does not limit its step; the kernels then
/// add none.
pub mod drag {
    use super::super::{Point, Scheme};

    /// Adds the drag residual (two-phase layouts only).
    pub fn residual<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
        let Some(w) = pt.layout.w else { return };
        if nm.is_explicit() {
            return;
        }
        let (nd, it) = (pt.layout.nd, &pt.interp);
        for (k, b) in pt.basis.iter().enumerate() {
            for c in 0..D {
                let f = nm.w_force * b.s * pt.part.drag * (it.motion.v_u[c] - it.motion.v_w[c]);
                out[k * nd + c] += f;
                out[k * nd + w + c] -= f;
            }
        }
    }

    /// Adds w_f a₁ C in the u–u, u–U, U–u and U–U blocks.
    pub fn tangent<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
        let Some(w) = pt.layout.w else { return };
        if nm.is_explicit() {
            return;
        }
        let (nd, m) = (pt.layout.nd, pt.size());
        for (k, bk) in pt.basis.iter().enumerate() {
            for (l, bl) in pt.basis.iter().enumerate() {
                let c1 = nm.w_force * bk.s * bl.s * nm.a1 * pt.part.drag;
                for c in 0..D {
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
