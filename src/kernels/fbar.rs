//! [002]'s F̄ in an implicit step (`stabilisation.fbar` in a `static`, `quasi_static` or one-phase
//! `dynamic` stage): the projection of the explicit step ([002] §3, Algorithm 1; `model::fbar`)
//! written as equations of the Newton system, so that the residual is [002]'s and its tangent is
//! exact.
//!
//! Each node i carries one more unknown, ϑ_i = J̄_i − 1, the nodal value of the projected volume
//! ratio, with the equation of the projection's P2G ([002] Eqs. 19 and 26),
//!   R_i = κ Σ_p S_ip V_p^n (ϑ_i − (J_p^n ΔJ_p − 1)) = 0,
//! i.e. (1 + ϑ_i) Σ_p S_ip V_p^n = Σ_p S_ip V_p^n J_p^{n+1}: the volume-weighted average of the
//! points' own J_p^{n+1} = J_p^n ΔJ_p over the node's support, as the explicit step projects it.
//! Each point takes J̄_p^{n+1} = 1 + Σ_i S_ip ϑ_i (the G2P of Eq. 20) and its stress sees ΔF̄ = c ΔF
//! with det ΔF̄ = J̄_p^{n+1}/J̄_p^n ([002] Eq. 27; [`super::kinematics::Kinematics::with_projected_volume`]);
//! the forces keep the standard gradients on x_{n+1} and the volume J V_n ([002] L237). The
//! projection rows are linear in ϑ with a diagonal block, so eliminating ϑ gives back [002]'s
//! F̄ residual in the displacements alone; its tangent couples each point with every point that
//! shares a node with it (two rings of nodes), which the nodal unknown keeps in the pattern of
//! one point's stencil. Summed over the nodes, the rows say Σ_p V_p^n J̄_p^{n+1} = Σ_p V_p^n J_p^{n+1}
//! (Σ_i S_ip = 1): the projection conserves the volume.
//!
//! κ (`ParticleInput::fbar_rows`, the largest constrained modulus over the smallest cell size, as
//! the pressure's scale) gives a row the magnitude of the force that a volume misfit of the same
//! size would take, so that Newton's residual norm sees it.

use super::{Point, Scheme};
use crate::soils::finite_strain::{det, embed};

/// Adds the projection rows R_i of one point (see the module documentation), weighted as the
/// water's mass balance (1; the generalized-α history has none).
pub fn residual<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
    let Some(j) = pt.layout.jbar else { return };
    let nd = pt.layout.nd;
    let part = pt.part;
    // J_p^n ΔJ_p − 1 = (J_p^n − 1) ΔJ_p + (ΔJ_p − 1), the step's part without cancellation.
    let own = (det(embed(&part.def_grad)) - 1.0) * pt.kin.j + pt.kin.dj;
    let w = part.fbar_rows * part.volume * nm.w_mass;
    for (i, b) in pt.basis.iter().enumerate() {
        out[i * nd + j] += w * b.s * (pt.jbar_nodes[i] - own);
    }
}

/// Adds the projection rows' derivatives: ϑ_i: κ S_ip V_p^n; Δu_l: −κ S_ip V_p^n J_p^n ∂ΔJ/∂Δu_l
/// with ∂ΔJ/∂Δu_l,d = ΔJ (F⁻ᵀ∇S_l)_d. (The forces' derivatives with respect to ϑ are the effective
/// stress term's, [`super::stress::tangent_with`].)
pub fn tangent<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
    let Some(j) = pt.layout.jbar else { return };
    let (nd, m) = (pt.layout.nd, pt.size());
    let part = pt.part;
    let w = part.fbar_rows * part.volume * nm.w_mass;
    let j_new = det(embed(&part.def_grad)) * pt.kin.j;
    for (i, b) in pt.basis.iter().enumerate() {
        let row = (i * nd + j) * m;
        out[row + i * nd + j] += w * b.s;
        for l in 0..pt.basis.len() {
            let g = pt.motion_operators().0[l].0;
            for d in 0..D {
                out[row + l * nd + d] -= w * b.s * j_new * g[d];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{plain_basis, Layout, NodeBasis, NodeState, ParticleInput, Point, Scheme};
    use crate::model::fbar::tests::Lcg;
    use crate::model::fbar::{gather, scatter};
    use crate::model::grid::Grid;
    use crate::model::shape::{self, Basis};
    use crate::scheme::Integration;
    use crate::soils::{Constitutive, LinearElastic};

    /// The kernels' sample particle with the volume, deformation gradient and J̄ of a point of
    /// the cloud, and the projection rows' scale.
    fn input(volume: f64, def_grad: [[f64; 2]; 2], jbar: f64) -> ParticleInput {
        ParticleInput { volume, def_grad, jbar, fbar_rows: 3.0e7, ..super::super::tests::part() }
    }

    /// The converged projection rows are [002]'s Algorithm 1: for random nodal motions of points
    /// scattered over a grid (GIMP and B-splines, J_p^n ≠ 1, J̄_p^n ≠ J_p^n), solving R_i = 0 for ϑ
    /// (one Newton step: the rows are linear in ϑ with a diagonal block) gives each point the
    /// J̄_p^{n+1} = 1 + Σ_i S_ip ϑ_i of `model::fbar::{scatter, gather}` applied to its own
    /// J_p^n ΔJ_p, and Σ_p V_p J̄_p^{n+1} = Σ_p V_p J_p^n ΔJ_p (the projection's conservation
    /// identity, here of the implicit form).
    #[test]
    fn the_converged_rows_are_algorithm_1_and_conserve_the_volume() {
        let grid = Grid::new([0.0, 0.0], [0.5, 0.4], [6, 5]);
        let nodes = 7 * 6;
        let layout = Layout::U_FBAR;
        let nd = layout.nd;
        let nm = Scheme::of(&Integration::Static, 1.0, false);
        let model = Constitutive::LinearElastic(LinearElastic::new(1e7, 0.45));
        let mut rng = Lcg(3);
        for basis_kind in [Basis::Gimp, Basis::BSpline2, Basis::BSpline3] {
            // The nodal motion: a smooth field plus noise (strains of about 1 %).
            let du: Vec<[f64; 2]> = (0..nodes)
                .map(|n| {
                    let (x, y) = ((n % 7) as f64 * 0.5, (n / 7) as f64 * 0.4);
                    [0.01 * (x * 1.3 + y).sin() + 1e-3 * rng.next(), -0.008 * (x - 0.7 * y).cos() + 1e-3 * rng.next()]
                })
                .collect();
            let mut points = Vec::new();
            for _ in 0..50 {
                let lp = [0.125, 0.1];
                let x = [lp[0] + (3.0 - 2.0 * lp[0]) * rng.next(), lp[1] + (2.0 - 2.0 * lp[1]) * rng.next()];
                let st = shape::stencil(basis_kind, &grid, x, lp);
                let mut basis: Vec<NodeBasis> = Vec::new();
                plain_basis(&st, &[0.0; shape::MAX_STENCIL], &mut basis);
                let ids: Vec<usize> = st.iter().map(|([i, j], _, _)| j as usize * 7 + i as usize).collect();
                let a = 0.03 * (rng.next() - 0.5);
                let part =
                    input(0.02 * (0.5 + rng.next()), [[1.0 + a, 0.01], [0.0, 1.0 - 0.5 * a]], 0.95 + 0.1 * rng.next());
                points.push((basis, ids, part));
            }
            // R_i(ϑ = 0) and the diagonal ∂R_i/∂ϑ_i, summed over the points.
            let (mut r0, mut diag) = (vec![0.0; nodes], vec![0.0; nodes]);
            let states = |ids: &[usize], theta: &[f64]| -> Vec<NodeState> {
                ids.iter().map(|&n| NodeState::new(&[du[n][0], du[n][1], theta[n]], &nm)).collect()
            };
            let zero = vec![0.0; nodes];
            for (basis, ids, part) in &points {
                let st = states(ids, &zero);
                let pt = Point::<2>::with_recovery(basis, basis, &st, part, &model, layout);
                let m = pt.size();
                let (mut r, mut t) = (vec![0.0; m], vec![0.0; m * m]);
                super::residual(&pt, &nm, &mut r);
                super::tangent(&pt, &nm, &mut t);
                for (k, &n) in ids.iter().enumerate() {
                    let q = k * nd + 2;
                    r0[n] += r[q];
                    diag[n] += t[q * m + q];
                }
            }
            let theta: Vec<f64> = (0..nodes).map(|n| if diag[n] > 0.0 { -r0[n] / diag[n] } else { 0.0 }).collect();
            // Each point's J̄ from ϑ, its own J^n ΔJ, and Algorithm 1 on the same values.
            let (mut own, mut jbar) = (Vec::new(), Vec::new());
            let mut shares = Vec::new();
            for (basis, ids, part) in &points {
                let st = states(ids, &theta);
                let pt = Point::<2>::with_recovery(basis, basis, &st, part, &model, layout);
                own.push(crate::soils::finite_strain::det2(part.def_grad) * pt.kin.j);
                jbar.push(super::super::StepResult::of(&pt).jbar.expect("an F̄ layout carries J̄"));
                shares.push(ids.iter().zip(basis).map(|(&n, b)| (n, b.s)).collect::<Vec<_>>());
            }
            let (v, vj) = scatter(nodes, (0..points.len()).map(|p| (shares[p].as_slice(), points[p].2.volume, own[p])));
            let (mut lhs, mut rhs) = (0.0, 0.0);
            for p in 0..points.len() {
                let reference = gather(&shares[p], &v, &vj);
                assert!((jbar[p] - reference).abs() < 1e-13, "{basis_kind:?} point {p}: {} vs {reference}", jbar[p]);
                lhs += points[p].2.volume * jbar[p];
                rhs += points[p].2.volume * own[p];
            }
            assert!((lhs - rhs).abs() <= 1e-13 * rhs, "{basis_kind:?}: Σ V J̄ = {lhs}, Σ V J = {rhs}");
            // And the points' J̄ differ from their own J (the projection did something).
            let spread = (0..points.len()).map(|p| (jbar[p] - own[p]).abs()).fold(0.0, f64::max);
            assert!(spread > 1e-4, "{basis_kind:?}: {spread}");
        }
    }
}
