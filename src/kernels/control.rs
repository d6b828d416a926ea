//! The control of the modes a recovered strain filters (`stabilisation.filtered_mode_control`).
//!
//! Where the stress sees a recovered strain ([001]'s CMPM patch functions, [`Point::with_recovery`])
//! the point's forces are still integrated with its basis: a motion of the point's own basis that
//! the smoother patch filters out (Σ_i Δu_i ⊗ ∇P_i = 0 while Σ_i Δu_i ⊗ ∇S_i ≠ 0) changes no
//! stress, so only inertia resists it. The control is the stiffness of stabilised nodal
//! integration and of reduced integration's hourglass control, on the difference of the two
//! strains (Puso, Chen, Zywicz & Elmer 2008, docs/references.md): with h_i = ∇S_i − ∇P_i (and
//! h_θ,i = T_i − T^P_i in axial symmetry) and the step's difference e = sym Σ_i Δu_i ⊗ h_i
//! (e_θθ = Σ_i h_θ,i Δu_r,i), the point stores the energy ½ α V_n e : C : e, C the isotropic
//! elastic stiffness of its material (λ, G), so that its forces are f_i = α V_n (s h_i + s_θθ h_θ,i
//! e_r) with s = λ tr e I + 2 G e, and its tangent the symmetric α V_n h_i · C · h_j. The
//! difference is taken over each step's increment, not accumulated: the control resists a
//! filtered mode's growth in a step, not its amplitude (over a run it acts as a viscosity
//! α C Δt). A field both operators reproduce (every linear one: the basis's partition of unity,
//! the patch's polynomial reproduction) has e = 0, so the patch test and the solution of a smooth
//! problem are not changed at first order; and Σ_i x_i ⊗ h_i = 0, so its forces have no moment and
//! the equilibrium identity holds as without it.

use super::{NodeBasis, Point};
use crate::scheme::Scheme;

/// The control's α λ and α G [Pa] at `pt`, if it has a control and a recovered strain.
fn moduli<const D: usize, const M: usize>(pt: &Point<D, M>) -> Option<(f64, f64)> {
    let alpha = pt.part.control;
    if alpha == 0.0 || std::ptr::eq(pt.strain, pt.basis) {
        return None;
    }
    let model = pt.model.as_ref()?;
    let elastic = model.elastic();
    let g = elastic.shear_modulus();
    Some((alpha * (elastic.bulk_modulus() - 2.0 * g / 3.0), alpha * g))
}

/// The operators' difference at a node: (∇S_i − ∇P_i, T_i − T^P_i).
#[inline]
fn difference<const D: usize>(b: &NodeBasis<D>, r: &NodeBasis<D>) -> ([f64; D], f64) {
    (std::array::from_fn(|c| b.g[c] - r.g[c]), b.t - r.t)
}

/// The control stress s = λ tr e I + 2 G e of a strain difference (e, e_θθ).
#[inline]
fn stress<const D: usize>(e: &[[f64; D]; D], e_hoop: f64, (lambda, g): (f64, f64)) -> ([[f64; D]; D], f64) {
    let tr = (0..D).map(|a| e[a][a]).sum::<f64>() + e_hoop;
    let s =
        std::array::from_fn(|a| std::array::from_fn(|b| 2.0 * g * e[a][b] + if a == b { lambda * tr } else { 0.0 }));
    (s, 2.0 * g * e_hoop + lambda * tr)
}

/// Adds `scale` (s h + s_θθ h_θ e_r), a node's force of the control stress (s, s_θθ), to the
/// node's first D entries of `out`.
#[inline]
fn add_force<const D: usize>(
    out: &mut [f64],
    (s, s_hoop): &([[f64; D]; D], f64),
    (h, h_hoop): ([f64; D], f64),
    scale: f64,
) {
    for a in 0..D {
        let f = (0..D).map(|b| s[a][b] * h[b]).sum::<f64>() + if a == 0 { s_hoop * h_hoop } else { 0.0 };
        out[a] += scale * f;
    }
}

/// Adds the control's forces to a residual block (node-major, nd per node).
pub fn residual<const D: usize, const M: usize>(pt: &Point<D, M>, _nm: &Scheme, out: &mut [f64]) {
    let Some(c) = moduli(pt) else { return };
    let (fb, fr) = (&pt.kin.f, &pt.strain_kin().f);
    let e: [[f64; D]; D] =
        std::array::from_fn(|a| std::array::from_fn(|b| 0.5 * ((fb[a][b] - fr[a][b]) + (fb[b][a] - fr[b][a]))));
    let e_hoop = pt.kin.f_hoop - pt.strain_kin().f_hoop;
    let s = stress(&e, e_hoop, c);
    let nd = pt.layout.nd;
    for (i, (b, r)) in pt.basis.iter().zip(pt.strain).enumerate() {
        add_force(&mut out[i * nd..], &s, difference(b, r), pt.part.volume);
    }
}

/// Adds the control's tangent α V_n h_i · C · h_j to a tangent block (row-major (nn·nd)²).
pub fn tangent<const D: usize, const M: usize>(pt: &Point<D, M>, _nm: &Scheme, out: &mut [f64]) {
    let Some(c) = moduli(pt) else { return };
    let nd = pt.layout.nd;
    let m = pt.size();
    let mut column = [0.0; 3];
    for (j, (bj, rj)) in pt.basis.iter().zip(pt.strain).enumerate() {
        let (hj, hj_hoop) = difference(bj, rj);
        for k in 0..D {
            // The strain difference of a unit Δu_{j,k}: e = sym(e_k ⊗ h_j), e_θθ = δ_k0 h_θ,j.
            let e: [[f64; D]; D] = std::array::from_fn(|a| {
                std::array::from_fn(|b| 0.5 * (if a == k { hj[b] } else { 0.0 } + if b == k { hj[a] } else { 0.0 }))
            });
            let s = stress(&e, if k == 0 { hj_hoop } else { 0.0 }, c);
            let col = j * nd + k;
            for (i, (bi, ri)) in pt.basis.iter().zip(pt.strain).enumerate() {
                column[..D].fill(0.0);
                add_force(&mut column[..D], &s, difference(bi, ri), pt.part.volume);
                for a in 0..D {
                    out[(i * nd + a) * m + col] += column[a];
                }
            }
        }
    }
}
