//! The explicit step ([002] §2.2, Eqs. 7–17; `../shared/seeds-001-002.md` Part C1):
//! update-stress-last with symplectic Euler on the lumped mass, over the same stencils, dof map,
//! loads and kernels as the implicit steps. It is the `solve` of a `dynamic_explicit` stage:
//!
//! 1. P2G (Eqs. 7–8): m_i = Σ_p S_ip m_p and m_i v_i^n = Σ_p S_ip m_p v_p^n over the points'
//!    effective stencils (a barely filled node's share goes to the nodes its motion is extended
//!    from, with the extension's coefficients, so that its motion is theirs as in the implicit
//!    steps);
//! 2. forces (Eq. 10): f_i = −r_i with r the residual at the step's start, f_int(σ_n) on x_n
//!    minus the body force and the loads of the step (those of t_{n+1}; prepared with the step,
//!    `start_residual`);
//! 3. local damping (Al-Kafaji 2013): f_i ← f_i − α |f_i| sign(v_i^n) per component;
//! 4. grid update (Eq. 9): v_i^{n+1} = v_i^n + Δt f_i/m_i at free dofs; a fixed dof moves by its
//!    prescribed increment (zero, or a boundary's motion);
//! 5. the step's nodal increments Δu_i = Δt v_i^{n+1}, from which the particle update (the same
//!    as the implicit steps': position, F, volume, the objective stress update from ∇Δu; Eqs.
//!    14–17) and the FLIP/PIC velocity update of `Model::update_particle` ([002] Eqs. 11–13)
//!    follow;
//! 6. with `stabilisation.fbar`, [002]'s projection between the two (Eqs. 19–21, 27): each
//!    point's J_p^n = det F_p and ΔJ_p of the step; the nodal sums of V_p^n, V_p^n J_p^n and
//!    V_p^n J_p^n ΔJ_p (`model::fbar::scatter`, summed over ranks); J̄_p^n = Π(J^n) and
//!    J̄_p^{n+1} = Π(J^n ΔJ) gathered back with the step's weights, and the scale
//!    c_p = (J̄_p^{n+1}/(J̄_p^n ΔJ_p))^{1/2} of the point's in-plane increment, which the kernels
//!    apply to the stress's volumetric strain (`Kinematics::with_volume_scale`). Only the stress
//!    sees F̄ ([002] L237): the volume stays det(F) V⁰ and the points keep F, so J̄^n is
//!    projected again each step from J^n rather than carried (the same weights in both
//!    projections: a uniform J^n gives J̄^n = J^n). Measured alternative, not kept: the volume
//!    following J̄ as with B̄ (F̄ carried as the point's F) made the tapered plate 2.4 times too
//!    soft at ν = 0.3.
//!
//! The nodal sums are local (each rank's points) and summed over ranks like every nodal vector.

use super::{callbacks, Error, GridSystem, StepSolve};
use crate::kernels::kinematics::Kinematics;
use crate::kernels::Integration;
use crate::model::{fbar, Model};

impl GridSystem {
    /// The explicit step's nodal update (see the module documentation); always "converged".
    pub(super) fn explicit_update(&mut self, model: &Model) -> Result<StepSolve, Error> {
        let t0 = std::time::Instant::now();
        let Integration::Explicit { damping, .. } = model.integration else {
            unreachable!("explicit_update is only called for explicit stages")
        };
        let nd = self.layout.nd;
        let ng = self.ghost.len() * nd;
        let (mut mass, mut momentum) = self.with_assembler(model, |asm| asm.lumped_mass_and_momentum());
        let mut residual = self.step.start_residual.clone();
        for v in [&mut mass, &mut momentum, &mut residual] {
            self.sum_over_ranks(v)?;
        }
        let dt = self.step.dt;
        let dofs = &self.step.dofs;
        let mut solution = vec![0.0; ng];
        let mut inertia = vec![0.0; ng];
        for q in 0..ng {
            if dofs.fixed[q] {
                solution[q] = dofs.value[q];
                continue;
            }
            if mass[q] <= 0.0 {
                continue;
            }
            let v0 = momentum[q] / mass[q];
            let force = -residual[q];
            let damped = if damping > 0.0 && v0 != 0.0 { force - damping * force.abs() * v0.signum() } else { force };
            let v1 = v0 + dt * damped / mass[q];
            solution[q] = dt * v1;
            // The inertia with the damping force (an applied force the balance must count).
            inertia[q] = mass[q] * (v1 - v0) / dt + (force - damped);
        }
        self.step.solution = solution;
        self.step.explicit_inertia = inertia;
        if model.fbar {
            self.step.fbar_scale = self.fbar_scales(model)?;
        }
        let seconds = t0.elapsed().as_secs_f64();
        Ok(StepSolve {
            converged: true,
            reason: "EXPLICIT".into(),
            newton_iterations: 0,
            linear_iterations: 0,
            residual_history: Vec::new(),
            domain_error: None,
            nonfinite: None,
            assembly_seconds: seconds,
            solve_seconds: seconds,
            field_residuals: Vec::new(),
            field_scales: self.step.field_scales.clone(),
            linear_field_residuals: Vec::new(),
            solver_used: false,
        })
    }

    /// [002]'s projection for the step's nodal increments (see the module documentation): the
    /// scale c_p of each particle's in-plane increment.
    fn fbar_scales(&mut self, model: &Model) -> Result<Vec<f64>, Error> {
        let (nd, nn) = (self.layout.nd, self.ghost.len());
        let (st, ps) = (&self.step.stencils, &model.particles);
        let count = st.len();
        // Per point: its shares of the nodes, J^n = det F and J^n ΔJ.
        let (mut shares, mut jn, mut own) =
            (Vec::with_capacity(count), Vec::with_capacity(count), Vec::with_capacity(count));
        for k in 0..count {
            let (nodes, basis) = st.get(k);
            let states = callbacks::node_states(&self.step, k, &self.step.solution);
            let kin = Kinematics::new(st.strain_of(k), states[..nodes.len()].iter().map(|s| [s.d[0], s.d[1]]), false);
            let f = ps.def_grad[k];
            jn.push(f[0][0] * f[1][1] - f[0][1] * f[1][0]);
            own.push(jn[k] * kin.j);
            shares.push(nodes.iter().zip(basis).map(|(&n, b)| (n as usize, b.s)).collect::<Vec<_>>());
        }
        let (volume, weighted) = fbar::scatter(nn, (0..count).map(|k| (shares[k].as_slice(), ps.volume[k], own[k])));
        let (_, weighted_n) = fbar::scatter(nn, (0..count).map(|k| (shares[k].as_slice(), ps.volume[k], jn[k])));
        // The nodal sums over ranks (the first component's slot of each node).
        let mut sums = [vec![0.0; nn * nd], vec![0.0; nn * nd], vec![0.0; nn * nd]];
        for (sum, local) in sums.iter_mut().zip([&volume, &weighted, &weighted_n]) {
            for (l, v) in local.iter().enumerate() {
                sum[l * nd] = *v;
            }
            self.sum_over_ranks(sum)?;
        }
        let volume: Vec<f64> = (0..nn).map(|l| sums[0][l * nd]).collect();
        let weighted: Vec<f64> = (0..nn).map(|l| sums[1][l * nd]).collect();
        let weighted_n: Vec<f64> = (0..nn).map(|l| sums[2][l * nd]).collect();
        Ok((0..count)
            .map(|k| {
                let ratio =
                    fbar::gather(&shares[k], &volume, &weighted) / fbar::gather(&shares[k], &volume, &weighted_n);
                fbar::scale(ratio * jn[k], own[k], 2)
            })
            .collect())
    }
}
