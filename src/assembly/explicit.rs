//! The explicit step ([002] §2.2, Eqs. 7–17; `../shared/seeds-001-002.md` Part C1):
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
//!    `Assembler::nodal_terms` at Δd = 0), and serve the step's equilibrium identity too;
//! 3. local damping (Al-Kafaji 2013): f_i ← f_i − α |f_i| sign(v_i^n) per component;
//! 4. grid update (Eq. 9): v_i^{n+1} = v_i^n + Δt f_i/m_i at free dofs; a fixed dof moves by its
//!    prescribed increment (zero, or a boundary's motion);
//! 5. the step's nodal increments Δu_i = Δt v_i^{n+1}, from which the particle update (the same
//!    as the implicit steps': position, F, volume, the objective stress update from ∇Δu; Eqs.
//!    14–17) and the FLIP/PIC velocity update of `Model::update_particle` ([002] Eqs. 11–13)
//!    follow;
//! 6. with `stabilisation.fbar`, [002]'s projection between the two (Eqs. 18–21, 27): each
//!    point's own volume ratio J_p^n ΔJ_p (J_p^n = det F_p, ΔJ_p of the step) is projected,
//!    J̄_p^{n+1} = Π(J^n ΔJ)_p (the nodal sums of V_p^n and V_p^n J_p^n ΔJ_p, `model::fbar`,
//!    summed over ranks, gathered back with the step's weights). A rate-form model's stress
//!    update sees the increment scaled by c_p = (J̄_p^{n+1}/(J̄_p^n ΔJ_p))^{1/2}, J̄_p^n the point's
//!    stored value (`Kinematics::with_volume_scale`, on the stress's volumetric strain only); a
//!    hyperelastic one the total F̄ = s_p F_{n+1} with s_p = (J̄_p^{n+1}/(J_p^n ΔJ_p))^{1/2}
//!    (`ParticleInput::fbar_total`), Hencky–J2 the increment c_p ΔF and the volume ratio
//!    det(s_p F_{n+1}) = J̄_p^{n+1} (`soil::Constitutive::finite`). The point stores J̄_p^{n+1} (`Particles::jbar`), so that the
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
//! The nodal sums are local (each rank's points) and summed over ranks like every nodal vector.

use super::{callbacks, Error, GridSystem, StepSolve};
use crate::kernels::kinematics::Kinematics;
use crate::kernels::Integration;
use crate::model::finite_strain::det;
use crate::model::{fbar, Model};

impl GridSystem {
    /// The explicit step's nodal update (see the module documentation); always "converged".
    pub(super) fn explicit_update(&mut self, model: &Model) -> Result<StepSolve, Error> {
        let t0 = std::time::Instant::now();
        let Integration::Explicit { damping, xpic, .. } = model.integration else {
            unreachable!("explicit_update is only called for explicit stages")
        };
        let nd = self.layout.nd;
        let ng = self.ghost.len() * nd;
        let velocities = &model.particles.vel;
        let (mut mass, mut momentum) = self.with_assembler(model, |asm| asm.lumped_mass_and_momentum(velocities));
        let start = self.step.start_terms.as_ref().expect("an explicit step's start terms");
        let mut residual: Vec<f64> = start.all.iter().zip(&self.step.fext).map(|(a, e)| a - e).collect();
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
        self.step.xpic_correction =
            if xpic > 0 { self.xpic_correction(model, xpic, &mass, &momentum)? } else { Vec::new() };
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

    /// XPIC(m)'s nodal field w − v^n (see the module documentation) from the step's lumped mass and
    /// momentum (summed over the ranks), per ghosted dof; zero at fixed dofs and where there is no
    /// mass.
    fn xpic_correction(&mut self, model: &Model, m: u8, mass: &[f64], momentum: &[f64]) -> Result<Vec<f64>, Error> {
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
                let at_points: Vec<[f64; 2]> =
                    (0..self.step.stencils.len()).map(|p| self.interpolated(p, &u)).collect();
                let (mut mk, mut pk) = self.with_assembler(model, |asm| asm.lumped_mass_and_momentum(&at_points));
                for v in [&mut mk, &mut pk] {
                    self.sum_over_ranks(v)?;
                }
                u = velocity(&mk, &pk);
            }
            let sign = if k % 2 == 1 { 1.0 } else { -1.0 };
            for (wi, ui) in w.iter_mut().zip(&u) {
                *wi += sign * binomial * ui;
            }
        }
        let fixed = &self.step.dofs.fixed;
        Ok((0..w.len()).map(|q| if fixed[q] || mass[q] <= 0.0 { 0.0 } else { w[q] - v0[q] }).collect())
    }

    /// [002]'s projection for the step's nodal increments (see the module documentation): the
    /// projection J̄_p^{n+1} = Π(J^n ΔJ)_p of the points' own volume ratios, the scale
    /// c_p = (J̄_p^{n+1}/(J̄_p^n ΔJ_p))^{1/2} of the in-plane increment (Eq. 27, J̄_p^n the point's
    /// stored value) and s_p = (J̄_p^{n+1}/(J_p^n ΔJ_p))^{1/2} of the total deformation (Eq. 18).
    fn fbar_scales(&mut self, model: &Model) -> Result<Vec<[f64; 3]>, Error> {
        let (st, ps) = (&self.step.stencils, &model.particles);
        // Per point: ΔJ.
        let dj: Vec<f64> = (0..st.len())
            .map(|k| {
                let (nodes, _) = st.get(k);
                let states = callbacks::node_states(&self.step, k, &self.step.solution);
                Kinematics::new(st.strain_of(k), states[..nodes.len()].iter().map(|s| [s.d[0], s.d[1]]), false).j
            })
            .collect();
        let own: Vec<f64> = (0..dj.len()).map(|k| det(ps.def_grad[k]) * dj[k]).collect();
        let projected = self.project_per_point(model, &own)?;
        Ok((0..own.len())
            .map(|k| {
                let p = projected[k];
                [fbar::scale(p, ps.jbar[k] * dj[k], 2), fbar::scale(p, own[k], 2), p]
            })
            .collect())
    }

    /// The volume-weighted projection Π(q) of a per-point quantity `q` (this rank's points) on the
    /// nodes and back to each point with the step's weights ([002] Eqs. 19–21; nodal sums over
    /// the ranks).
    fn project_per_point(&mut self, model: &Model, q: &[f64]) -> Result<Vec<f64>, Error> {
        let (nd, nn) = (self.layout.nd, self.ghost.len());
        let (st, ps) = (&self.step.stencils, &model.particles);
        let shares: Vec<Vec<(usize, f64)>> = (0..st.len())
            .map(|k| {
                let (nodes, basis) = st.get(k);
                nodes.iter().zip(basis).map(|(&n, b)| (n as usize, b.s)).collect()
            })
            .collect();
        let (volume, weighted) = fbar::scatter(nn, (0..q.len()).map(|k| (shares[k].as_slice(), ps.volume[k], q[k])));
        // The nodal sums over ranks (the first component's slot of each node).
        let mut sums = [vec![0.0; nn * nd], vec![0.0; nn * nd]];
        for (sum, local) in sums.iter_mut().zip([&volume, &weighted]) {
            for (l, v) in local.iter().enumerate() {
                sum[l * nd] = *v;
            }
            self.sum_over_ranks(sum)?;
        }
        let volume: Vec<f64> = (0..nn).map(|l| sums[0][l * nd]).collect();
        let weighted: Vec<f64> = (0..nn).map(|l| sums[1][l * nd]).collect();
        Ok(shares.iter().map(|sh| fbar::gather(sh, &volume, &weighted)).collect())
    }
}
