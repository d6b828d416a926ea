//! The explicit step ([002] §2.2, Eqs. 7–17):
//! update-stress-last with symplectic Euler on the lumped mass, over the same stencils, dof map,
//! loads and kernels as the implicit steps. It is the `solve` of a `dynamic_explicit` stage:
//!
//! 1. P2G (Eqs. 7–8): m_i = Σ_p S_ip m_p and m_i v_i^n = Σ_p S_ip m_p v_p^n over the points'
//!    effective stencils (a barely filled node's share goes to the nodes its motion is extended
//!    from, with the extension's coefficients, so that its motion is theirs as in the implicit
//!    steps);
//! 2. forces (Eq. 10): f_i = −r_i with r the residual at the step's start, f_int(σ_n) on x_n
//!    minus the body force and the loads of the step (those of t_{n+1}); its terms are prepared
//!    with the step (`StartTerms`, by the same pass as the implicit step's balance,
//!    `Points::nodal_terms` at Δd = 0), and serve the step's equilibrium identity too;
//! 3. local damping (Al-Kafaji 2013): f_i ← f_i − α |f_i| sign(v_i^n) per component;
//! 4. grid update (Eq. 9): v_i^{n+1} = v_i^n + Δt f_i/m_i at free dofs; a fixed dof moves by its
//!    prescribed increment (zero, or a boundary's motion);
//! 5. the step's nodal increments Δu_i = Δt v_i^{n+1}, from which the particle update (the same
//!    as the implicit steps': position, F, volume, the objective stress update from ∇Δu; Eqs.
//!    14–17) and the FLIP/PIC velocity update of `Model::update_particle` ([002] Eqs. 11–13)
//!    follow. The FLIP increment Σ S_ip (v_i^{n+1} − v_i^n) takes the v_i^n of this update (the
//!    lumped momentum over the lumped mass, zero where a boundary holds the component still,
//!    `Solution::start_velocity`), not the predictors' nodal velocities of the raw projection:
//!    the two differ at the nodes to which barely filled nodes hand their shares, and a FLIP
//!    increment formed with the raw ones added that difference to the points' velocities at every
//!    step, an instability that grew faster the smaller the step (the landslide's inclined face
//!    at ν = 0.499 with F̄ blew up within 0.1 s in three dimensions, and in two with a well-filled
//!    threshold of 0.03);
//! 6. with `stabilisation.fbar`, [002]'s projection between the two (Eqs. 18–21, 27): each
//!    point's own volume ratio J_p^n ΔJ_p (J_p^n = det F_p, ΔJ_p of the step) is projected,
//!    J̄_p^{n+1} = Π(J^n ΔJ)_p (the nodal sums of V_p^n and V_p^n J_p^n ΔJ_p, `model::fbar`,
//!    summed over ranks, gathered back with the step's weights). A rate-form model's stress
//!    update sees the increment scaled by c_p = (J̄_p^{n+1}/(J̄_p^n ΔJ_p))^{1/2}, J̄_p^n the point's
//!    stored value (`Kinematics::with_volume_scale`, on the stress's volumetric strain only); a
//!    hyperelastic one the total F̄ = s_p F_{n+1} with s_p = (J̄_p^{n+1}/(J_p^n ΔJ_p))^{1/2}
//!    (`ParticleInput::fbar_total`), Hencky–J2 the increment c_p ΔF and the volume ratio
//!    det(s_p F_{n+1}) = J̄_p^{n+1} (`soils::Constitutive::finite`). The point stores J̄_p^{n+1} (`Particles::jbar`), so that the
//!    next step's start sees the stress it was left with (to round-off), and the rate form's
//!    volumetric increments telescope to ln J̄. Only the stress sees F̄ ([002] L237): the volume stays
//!    det(F) V⁰ and the points keep F. Two departures from [002] Algorithm 1, each measured:
//!    (i) Algorithm 1 projects J̄^n ΔJ, not J^n ΔJ; repeated every step that smooths J̄ without
//!    end (at rest J̄ ← Π(J̄)), and its pressure loses the volume changes it should resist: the
//!    tapered plate at ν = 0.499 came out at 5.64e-4 against 3.10e-4 from finite elements, Cook's
//!    membrane on 4 m cells at 0.485 m against 0.2765 m (this projection: 2.80e-4 and 0.261 m);
//!    (ii) the volume following J̄ as with B̄ (F̄ carried as the point's F) made the tapered
//!    plate 2.4 times too soft at ν = 0.3.
//!
//! 7. with `[explicit] xpic_order = m`, XPIC(m) (Hammerquist & Nairn 2017) instead of the
//!    FLIP/PIC blend: the points' velocities become v_p^{n+1} = S(v^{n+1} − v^n + w) with
//!    w = Σ_{k=1..m} (−1)^{k+1} C(m, k) (S⁺S)^{k−1} v^n, where S interpolates nodal velocities to
//!    the points and S⁺ maps the points' momenta back (divided by the lumped mass). This is
//!    [I − (I − SS⁺)^m] V^n + S a Δt: for m = 1 PIC, and as m grows FLIP without the part of the
//!    points' velocities that the grid cannot see (SS⁺'s null space, where pure FLIP's noise lives
//!    unchecked). The field w − v^n (zero at fixed dofs) is kept for the particle update
//!    (`StepResult::velocity`). Each order above 1 costs one more pass over the points.
//!
//! 8. two-phase (the u–U system, `crate::layout::Layout::UW`; docs/analysis.md "Two-phase explicit"):
//!    step 1 maps the water's mass nρ_w V and momentum too, and the drag C_i = Σ S_ip c_p
//!    (c = n²γ_w V/k, [003] Eqs. 16c–e); step 2's forces are the u–p–U kernels' at Δd = 0 (the
//!    effective stress, (1 − n)p on the skeleton and np on the water, [003] Eqs. 23a, c) without
//!    the drag; step 4 takes the drag at the new velocities, node by node and direction by
//!    direction ([`nodal_velocities`]: a 2 × 2 solve, stable at any permeability); the pore
//!    pressure's increment follows from the continuity equation of the step ([003] Eq. 23b) at
//!    each point (`kernels::flow::continuity::pointwise_increment`), or, with
//!    `explicit.pore_pressure = "nodal"`, from its lumped form per node,
//!    Δp_i = Σ_p S_ip (V/Q)_p Δp_p / Σ_p S_ip (V/Q)_p, zero at drained nodes
//!    (`pressure::drained_nodes`), each point taking Σ_i S_ip Δp_i
//!    (`nodal_pressure_increments`). The lumped inertia the balance counts includes
//!    each phase's drag.
//!
//! The nodal sums are local (each rank's points) and summed over ranks like every nodal vector.

use super::points::{node_displacements, node_states, particle_input, Points};
use super::prepare::start_value;
use super::space::NodeSpace;
use super::stencils::Stencils;
use super::step::{Solution, Step};
use super::{Error, StepSolve};
use crate::algebra::det;
use crate::kernels::{self, Kinematics};
use crate::model::{fbar, Model};
use crate::scheme::Integration;

/// The explicit step's nodal update (see the module documentation), in any dimension; always
/// "converged".
pub(super) fn update<const D: usize, const M: usize, const N: usize>(
    space: &mut NodeSpace<D>,
    step: &Step<D, M>,
    model: &Model<D>,
) -> Result<(StepSolve, Solution), Error> {
    let t0 = std::time::Instant::now();
    let Integration::Explicit { damping, xpic, .. } = model.integration else {
        return Err(Error::new("an explicit update of a step that is not explicit"));
    };
    let nd = space.layout.nd;
    let ng = space.ghost.len() * nd;
    let ps = &model.particles;
    let points = Points::<D, M, N>::new(model, step);
    let water = space.layout.w.map(|_| ps.vel_w.as_slice());
    let mut lumped = points.lumped_mass_and_momentum(&ps.vel, water);
    let start = &step.start_terms;
    let mut residual: Vec<f64> = start.all.iter().zip(&step.fext).map(|(a, e)| a - e).collect();
    for v in [&mut lumped.mass, &mut lumped.momentum, &mut lumped.drag, &mut residual] {
        if !v.is_empty() {
            space.sum_over_ranks(v)?;
        }
    }
    let dt = step.dt;
    let dofs = &step.dofs;
    let (mass, momentum) = (&lumped.mass, &lumped.momentum);
    let mut solution = Solution { increments: vec![0.0; ng], explicit_inertia: vec![0.0; ng], ..Solution::default() };
    // (solid dof, water dof) of each node and direction: the phases' updates are coupled by
    // the drag; one-phase nodes have no water dof.
    let water_offset = space.layout.w;
    let pairs =
        (0..space.ghost.len()).flat_map(|l| (0..D).map(move |c| (l * nd + c, water_offset.map(|w| l * nd + w + c))));
    for (qs, qw) in pairs {
        let phase = |q: usize| {
            let v0 = if mass[q] > 0.0 { momentum[q] / mass[q] } else { 0.0 };
            NodalPhase {
                fixed: dofs.fixed[q].then(|| dofs.value[q] / dt),
                mass: mass[q],
                v0,
                force: damped(-residual[q], damping, v0),
            }
        };
        let solid = phase(qs);
        let fluid = qw.map(phase);
        let drag = qw.map_or(0.0, |_| lumped.drag[qs]);
        let (vs, vw) = nodal_velocities(&solid, fluid.as_ref(), drag, dt);
        // The inertia with the damping force and the drag (forces the balance must count).
        for (q, ph, v, sign) in [(Some(qs), Some(&solid), vs, 1.0), (qw, fluid.as_ref(), vw, -1.0)] {
            let (Some(q), Some(ph)) = (q, ph) else { continue };
            solution.increments[q] = dt * v;
            if ph.fixed.is_none() && ph.mass > 0.0 {
                solution.explicit_inertia[q] = ph.mass * (v - ph.v0) / dt + ph.force.1 + sign * drag * (vs - vw);
            }
        }
    }
    // The velocities of the step's start the FLIP update subtracts: the lumped ones, zero
    // where a boundary holds the component still.
    solution.start_velocity = (0..ng).map(|q| start_value(model, dofs, q, mass, momentum)).collect();
    if xpic > 0 {
        solution.xpic_correction = xpic_correction(space, step, &points, xpic, &lumped.mass, &lumped.momentum)?;
    }
    if model.fbar {
        solution.fbar_scale = fbar_scales::<D, M, N>(space, step, model, &solution)?;
    }
    if !step.drained.is_empty() {
        solution.pressure_increment = nodal_pressure_increments::<D, M, N>(space, step, model, &solution)?;
    }
    let seconds = t0.elapsed().as_secs_f64();
    let solve = StepSolve {
        converged: true,
        reason: "EXPLICIT".into(),
        newton_iterations: 0,
        linear_iterations: 0,
        residual_history: Vec::new(),
        domain_error: None,
        nonfinite: None,
        assembly: super::callbacks::AssemblyTime { seconds, ..Default::default() },
        solve_seconds: seconds,
        field_residuals: Vec::new(),
        field_scales: step.field_scales.clone(),
        linear_field_residuals: Vec::new(),
        solver_used: false,
        line_search_retry: false,
        workspace_retry: None,
    };
    Ok((solve, solution))
}

/// The nodal pore pressure's increment at each point of a two-phase step (see the module
/// documentation): the points' own increments Δp_p of the step's solution, their lumped
/// continuity equation per node, Δp_i = Σ_p S_ip (V/Q)_p Δp_p / Σ_p S_ip (V/Q)_p (zero at
/// drained nodes), and Σ_i S_ip Δp_i at each point.
fn nodal_pressure_increments<const D: usize, const M: usize, const N: usize>(
    space: &mut NodeSpace<D>,
    step: &Step<D, M>,
    model: &Model<D>,
    solution: &Solution,
) -> Result<Vec<f64>, Error> {
    let st = &step.stencils;
    let mut storage = Vec::with_capacity(st.len());
    let own: Vec<f64> = (0..st.len())
        .map(|k| {
            let (nodes, basis) = st.get(k);
            let states = node_states::<D, M, N>(step, k, &solution.increments);
            let input = particle_input(model, step, k);
            storage.push(input.volume * input.inv_q);
            let it = kernels::interpolate(basis, &states[..nodes.len()], &Default::default(), step.layout);
            kernels::flow::continuity::pointwise_increment(&it, &input)
        })
        .collect();
    project_weighted(space, st, &storage, &own, &step.drained)
}

/// XPIC(m)'s nodal field w − v^n (see the module documentation) from the step's lumped mass and
/// momentum (summed over the ranks), per ghosted dof; zero at fixed dofs and where there is no
/// mass.
fn xpic_correction<const D: usize, const M: usize, const N: usize>(
    space: &mut NodeSpace<D>,
    step: &Step<D, M>,
    points: &Points<D, M, N>,
    m: u8,
    mass: &[f64],
    momentum: &[f64],
) -> Result<Vec<f64>, Error> {
    let velocity = |mass: &[f64], momentum: &[f64]| -> Vec<f64> {
        mass.iter().zip(momentum).map(|(m, p)| if *m > 0.0 { p / m } else { 0.0 }).collect()
    };
    let v0 = velocity(mass, momentum);
    let (mut u, mut w) = (v0.clone(), vec![0.0; v0.len()]);
    let mut binomial = 1.0;
    for k in 1..=m {
        binomial *= f64::from(m - k + 1) / f64::from(k);
        if k > 1 {
            // S⁺S u: u at the points, their momenta back to the nodes.
            let at_points: Vec<[f64; D]> =
                (0..step.stencils.len()).map(|p| step.interpolated_vector(p, &u, 0)).collect();
            let mut lumped = points.lumped_mass_and_momentum(&at_points, None);
            for v in [&mut lumped.mass, &mut lumped.momentum] {
                space.sum_over_ranks(v)?;
            }
            u = velocity(&lumped.mass, &lumped.momentum);
        }
        let sign = if k % 2 == 1 { 1.0 } else { -1.0 };
        for (wi, ui) in w.iter_mut().zip(&u) {
            *wi += sign * binomial * ui;
        }
    }
    let fixed = &step.dofs.fixed;
    Ok((0..w.len()).map(|q| if fixed[q] || mass[q] <= 0.0 { 0.0 } else { w[q] - v0[q] }).collect())
}

/// [002]'s projection for the step's nodal increments (see the module documentation): the
/// projection J̄_p^{n+1} = Π(J^n ΔJ)_p of the points' own volume ratios, the scale
/// c_p = (J̄_p^{n+1}/(J̄_p^n ΔJ_p))^{1/D} of the increment (Eq. 27, the in-plane block in
/// plane strain; J̄_p^n the point's stored value) and s_p = (J̄_p^{n+1}/(J_p^n ΔJ_p))^{1/D} of the
/// total deformation (Eq. 18).
fn fbar_scales<const D: usize, const M: usize, const N: usize>(
    space: &mut NodeSpace<D>,
    step: &Step<D, M>,
    model: &Model<D>,
    solution: &Solution,
) -> Result<Vec<[f64; 3]>, Error> {
    let (st, ps) = (&step.stencils, &model.particles);
    // Per point: ΔJ.
    let dj: Vec<f64> = (0..st.len())
        .map(|k| {
            let (nodes, _) = st.get(k);
            let d = node_displacements(step, k, &solution.increments);
            Kinematics::new(st.strain_of(k), d[..nodes.len()].iter().copied(), false).j
        })
        .collect();
    let own: Vec<f64> = (0..dj.len()).map(|k| det(&ps.def_grad[k]) * dj[k]).collect();
    // The volume-weighted projection ([002] Eqs. 19–21).
    let projected = project_weighted(space, st, &ps.volume[..own.len()], &own, &[])?;
    Ok((0..own.len())
        .map(|k| {
            let p = projected[k];
            [fbar::scale(p, ps.jbar[k] * dj[k], D), fbar::scale(p, own[k], D), p]
        })
        .collect())
}

/// The projection of a per-point quantity `q` with the per-point weights `weight` (a volume):
/// q_i = Σ_p S_ip w_p q_p / Σ_p S_ip w_p on the nodes (sums over the ranks), zero at the
/// ghosted nodes `zero` marks (none if it is empty), and Σ_i S_ip q_i back at each point.
fn project_weighted<const D: usize>(
    space: &mut NodeSpace<D>,
    st: &Stencils<D>,
    weight: &[f64],
    q: &[f64],
    zero: &[bool],
) -> Result<Vec<f64>, Error> {
    let (nd, nn) = (space.layout.nd, space.ghost.len());
    // Each point's (node, S) pairs, flat like the stencils (`offsets[k]..offsets[k + 1]`).
    let flat: Vec<(usize, f64)> = st.nodes.iter().zip(&st.basis).map(|(&n, b)| (n as usize, b.s)).collect();
    let shares = |k: usize| &flat[st.offsets[k]..st.offsets[k + 1]];
    let (volume, weighted) = fbar::scatter(nn, (0..q.len()).map(|k| (shares(k), weight[k], q[k])));
    // The nodal sums over ranks (the first component's slot of each node).
    let mut sums = [vec![0.0; nn * nd], vec![0.0; nn * nd]];
    for (sum, local) in sums.iter_mut().zip([&volume, &weighted]) {
        for (l, v) in local.iter().enumerate() {
            sum[l * nd] = *v;
        }
        space.sum_over_ranks(sum)?;
    }
    let volume: Vec<f64> = (0..nn).map(|l| sums[0][l * nd]).collect();
    let weighted: Vec<f64> = (0..nn).map(|l| if zero.get(l) == Some(&true) { 0.0 } else { sums[1][l * nd] }).collect();
    Ok((0..st.len()).map(|k| fbar::gather(shares(k), &volume, &weighted)).collect())
}

/// One phase of one nodal direction in an explicit step (summed over the ranks).
#[derive(Debug, Clone, Copy)]
struct NodalPhase {
    /// The prescribed velocity of a fixed dof (its increment over Δt).
    fixed: Option<f64>,
    /// The lumped mass m_i.
    mass: f64,
    /// The velocity of the step's start, the lumped momentum over the mass (0 without mass).
    v0: f64,
    /// The force of the step's start after local damping, and what the damping took off.
    force: (f64, f64),
}

/// A force `f` after local damping α (Al-Kafaji 2013), f − α |f| sign(v) at velocity `v`, with what
/// the damping took off.
fn damped(f: f64, alpha: f64, v: f64) -> (f64, f64) {
    if alpha > 0.0 && v != 0.0 {
        let d = alpha * f.abs() * v.signum();
        (f - d, d)
    } else {
        (f, 0.0)
    }
}

/// The new velocities (v_s, v_w) of a node's solid and, with `water`, its water in one direction
/// (symplectic Euler on the lumped masses), the drag `c` (the lumped Σ S_ip c_p) taken at the new
/// velocities, so that it is stable however small the permeability:
///   m_s (v_s − v_s⁰)/Δt = f_s − c (v_s − v_w),   m_w (v_w − v_w⁰)/Δt = f_w + c (v_s − v_w).
/// A fixed dof keeps its prescribed velocity and the other phase feels the drag against it; a
/// free dof without mass keeps velocity 0 (nothing reaches it). Without water, v_w = 0.
fn nodal_velocities(solid: &NodalPhase, water: Option<&NodalPhase>, c: f64, dt: f64) -> (f64, f64) {
    // The explicit velocity of a phase that feels no drag (or none is left to solve for).
    let free = |p: &NodalPhase, other: Option<f64>| -> f64 {
        match (p.fixed, p.mass > 0.0, other) {
            (Some(v), _, _) => v,
            (None, false, _) => 0.0,
            (None, true, None) => p.v0 + dt * p.force.0 / p.mass,
            // The drag at the new velocity against a known one: (m/Δt + c) v = m v⁰/Δt + f + c v_o.
            (None, true, Some(vo)) => (p.mass * p.v0 / dt + p.force.0 + c * vo) / (p.mass / dt + c),
        }
    };
    let Some(w) = water else { return (free(solid, None), 0.0) };
    match (solid.fixed.or((solid.mass <= 0.0).then_some(0.0)), w.fixed.or((w.mass <= 0.0).then_some(0.0))) {
        (Some(vs), Some(vw)) => (vs, vw),
        (Some(vs), None) => (vs, free(w, Some(vs))),
        (None, Some(vw)) => (free(solid, Some(vw)), vw),
        (None, None) => {
            // [[m_s/Δt + c, −c], [−c, m_w/Δt + c]] (v_s, v_w) = (m_s v_s⁰/Δt + f_s, m_w v_w⁰/Δt + f_w).
            let (a, d) = (solid.mass / dt + c, w.mass / dt + c);
            let (bs, bw) = (solid.mass * solid.v0 / dt + solid.force.0, w.mass * w.v0 / dt + w.force.0);
            // a d − c², without the cancellation of c² that a large drag (a low permeability)
            // would bring.
            let det = solid.mass * w.mass / (dt * dt) + c * (solid.mass + w.mass) / dt;
            ((d * bs + c * bw) / det, (c * bs + a * bw) / det)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn phase(mass: f64, v0: f64, f: f64) -> NodalPhase {
        NodalPhase { fixed: None, mass, v0, force: (f, 0.0) }
    }

    #[test]
    fn the_nodal_update_balances_momentum_and_drag() {
        let (dt, c) = (1e-3, 50.0);
        let (s, w) = (phase(2.0, 0.3, 4.0), phase(0.5, -0.1, 1.0));
        let (vs, vw) = nodal_velocities(&s, Some(&w), c, dt);
        // Each phase's balance with the drag at the new velocities.
        assert!((s.mass * (vs - s.v0) / dt - (4.0 - c * (vs - vw))).abs() < 1e-9);
        assert!((w.mass * (vw - w.v0) / dt - (1.0 + c * (vs - vw))).abs() < 1e-9);
        // The mixture's momentum does not see the drag.
        let total = s.mass * (vs - s.v0) + w.mass * (vw - w.v0);
        assert!((total - dt * 5.0).abs() < 1e-12);
        // Without drag each phase is symplectic Euler; an enormous drag locks them together at the
        // mixture's velocity.
        let (a, b) = nodal_velocities(&s, Some(&w), 0.0, dt);
        assert!((a - (0.3 + dt * 2.0)).abs() < 1e-12 && (b - (-0.1 + dt * 2.0)).abs() < 1e-12);
        let (a, b) = nodal_velocities(&s, Some(&w), 1e15, dt);
        let mixture = (2.0 * 0.3 + 0.5 * -0.1 + dt * 5.0) / 2.5;
        assert!((a - mixture).abs() < 1e-9 && (b - mixture).abs() < 1e-9);
    }

    #[test]
    fn a_fixed_phase_drags_the_other() {
        let (dt, c) = (1e-3, 50.0);
        let s = NodalPhase { fixed: Some(0.0), ..phase(2.0, 0.0, 0.0) };
        let w = phase(0.5, 1.0, 0.0);
        let (vs, vw) = nodal_velocities(&s, Some(&w), c, dt);
        assert_eq!(vs, 0.0);
        // Backward Euler on m v' = −c v: v = v⁰/(1 + cΔt/m), never past zero however large c Δt.
        assert!((vw - 1.0 / (1.0 + c * dt / 0.5)).abs() < 1e-12);
        let (_, vw) = nodal_velocities(&s, Some(&w), 1e12, dt);
        assert!((0.0..1e-6).contains(&vw));
        // A free dof without mass stays at rest; a one-phase node has no water.
        assert_eq!(nodal_velocities(&phase(0.0, 0.0, 3.0), None, 0.0, dt), (0.0, 0.0));
        assert_eq!(nodal_velocities(&phase(1.0, 0.0, 3.0), None, 0.0, dt), (3.0 * dt, 0.0));
    }

    #[test]
    fn local_damping_opposes_the_motion() {
        assert_eq!(damped(10.0, 0.1, 2.0), (9.0, 1.0));
        assert_eq!(damped(10.0, 0.1, -2.0), (11.0, -1.0));
        assert_eq!(damped(-10.0, 0.1, 2.0), (-11.0, 1.0));
        assert_eq!(damped(10.0, 0.1, 0.0), (10.0, 0.0));
    }
}
