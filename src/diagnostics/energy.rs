//! The energy balance of dynamic stages: the work of the loads, the reactions and the body forces
//! against the stress work, the kinetic energy and the Darcy dissipation.
//!
//! Multiplying the mixture's momentum balance by the solid velocity and the water's by the
//! relative velocity w = v_w − v_s ([003] Eqs. 1–3) and integrating gives
//!   P_ext + ∫ b·(ρ_s(1−n) v_s + nρ_w v_w) dV = dK/dt + ∫ σ':D dV
//!       − ∫ p [(1−n) ∇·v_s + n ∇·v_w] dV + ∫ n²γ_w/k |w|² dV,
//! with K = ½ ∫ (ρ_s(1−n)|v_s|² + nρ_w|v_w|²) dV. The stress work holds the stored elastic energy,
//! the plastic dissipation and, through the mass balance, the energy stored in the compressed
//! water, ∫ p ṗ/Q dV. Over a step every term is taken with its step means (trapezoidal in time):
//! the stress work of a particle is V̄ (σ̄' : Δε − p̄ [(1−n̄) Δε_v,s + n̄ Δε_v,w]) with Δε the
//! objective strain increment of its stress update (zero in a rigid rotation; B̄ where on), its
//! Darcy dissipation Δt d |w|² with w the relative velocity at t_{n+1} interpolated from the grid
//! (as the drag term of the residual sees it; the particles' own velocities carry the noise of
//! the grid-to-particle update, which at the slope's failure counted 14 times the work done), the drag
//! coefficient d = n²γ_w V/k, its body-force work b̄·(m Δu + m_w ΔU) with b̄ the mean of the body
//! accelerations of t_n and t_{n+1} (the trapezoidal product the integrator's energy identity
//! holds with: for Newmark's average acceleration Δu = Δt (v_n + v_{n+1})/2, so Δu·M(a_n + a_{n+1})/2
//! is exactly the change of the kinetic energy, and the forces a_n and a_{n+1} balance are those of
//! t_n and t_{n+1}; a pulse booked at t_{n+1} alone misses a share of its work). The loads' and reactions'
//! work comes from the nodes (`assembly::StepForces::work`). The porosity gradient's term of the
//! mass balance, ∇n·(ΔU − Δu), joins the volumetric terms beside p̄ ([003] Eq. 3; `kernels::flow`).
//! The work of a prescribed non-zero boundary pressure is not counted.
//! The relative error is the imbalance over the largest of the terms; a time integration that
//! dissipates (generalized-α with ρ∞ < 1, grid-to-particle mapping) shows in it.

use crate::kernels::{ParticleInput, StepResult};

/// A particle's share of a step's energy terms [J per m].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ParticleStep {
    /// Stress work V̄ (σ̄' : Δε − p̄ [(1−n̄) Δε_v,s + n̄ Δε_v,w]).
    pub internal: f64,
    /// Work of the body forces b·(m Δu + m_w ΔU).
    pub body: f64,
}

/// The stress and body-force work of one particle over a converged step: `before` is its kernel
/// input at t_n (with the body acceleration of t_n), `step` the converged result, `dp` its
/// pressure increment, `v_after` its volume and `body_after` its body acceleration at t_{n+1}.
pub fn particle_step<const D: usize>(
    before: &ParticleInput<D>,
    step: &StepResult<D>,
    dp: f64,
    (v_after, body_after): (f64, [f64; D]),
) -> ParticleStep {
    // Δε = [xx, yy, γxy, zz, γyz, γzx] (engineering shears) and the stress [xx, yy, xy, zz, yz, zx]:
    // the first four in two dimensions.
    let de = step.deps;
    let (s0, s1) = (before.stress, step.stress);
    let mean = |a: f64, b: f64| 0.5 * (a + b);
    let v = mean(before.volume, v_after);
    let effective = (0..crate::kernels::strain_rows::<D>()).map(|c| mean(s0[c], s1[c]) * de[c]).sum::<f64>();
    let n = before.porosity;
    let p = before.p + 0.5 * dp;
    let it = &step.interp;
    let g = step.grad_n;
    let gradient = (0..D).map(|d| g[d] * (it.dw[d] - it.du[d])).sum::<f64>();
    let water = if before.water_mass > 0.0 { p * ((1.0 - n) * it.dvol_u + n * it.dvol_w + gradient) } else { 0.0 };
    let b: [f64; D] = std::array::from_fn(|d| mean(before.body_acc[d], body_after[d]));
    let dot = |u: &[f64; D]| (0..D).map(|d| b[d] * u[d]).sum::<f64>();
    let body = before.mass * dot(&it.du) + before.water_mass * dot(&it.dw);
    ParticleStep { internal: v * (effective - water), body }
}

/// Kinetic energy ½ (m |v_s|² + m_w |v_w|²) of a particle [J per m].
pub fn kinetic<const D: usize>(mass: f64, water_mass: f64, v: [f64; D], v_w: [f64; D]) -> f64 {
    let square = |u: [f64; D]| (0..D).map(|d| u[d] * u[d]).sum::<f64>();
    0.5 * (mass * square(v) + water_mass * square(v_w))
}

/// Darcy dissipation over a step Δt d |w|², w = v_w − v_s at t_{n+1} as interpolated from the
/// grid (`step.interp`), d = n²γ_w V/k the drag coefficient [J per m].
pub fn darcy<const D: usize>(drag: f64, dt: f64, step: &StepResult<D>) -> f64 {
    let it = &step.interp;
    dt * drag
        * (0..D).map(|d| (it.motion.v_w[d] - it.motion.v_u[d]) * (it.motion.v_w[d] - it.motion.v_u[d])).sum::<f64>()
}

/// The running energy balance of the dynamic steps of a run (every rank holds its particles'
/// sums; the nodal work is already summed over ranks).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Ledger {
    /// Work of the loads and the reactions (nodal) [J per m], summed over ranks.
    pub external: f64,
    /// This rank's: work of the body forces, stress work, change of kinetic energy and Darcy
    /// dissipation over the dynamic steps, and the largest kinetic energy seen [J per m].
    pub local: [f64; 5],
}

/// The balance summed over ranks.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Balance {
    /// Work of the loads, the reactions and the body forces.
    pub external: f64,
    /// Stress work (stored, plastic and water compression).
    pub internal: f64,
    /// Change of the kinetic energy over the dynamic steps.
    pub kinetic: f64,
    /// Darcy dissipation.
    pub dissipated: f64,
    /// |external − internal − kinetic − dissipated| over the largest of |external|, |internal|,
    /// the largest kinetic energy and the dissipation (0 before any work is done).
    pub error: f64,
}

impl Ledger {
    /// Adds one step of this rank's particle terms: body and stress work, the change of kinetic
    /// energy, the dissipation, and the kinetic energy at its end.
    pub fn add_particles(&mut self, body: f64, internal: f64, d_kinetic: f64, dissipated: f64, kinetic_now: f64) {
        self.local[0] += body;
        self.local[1] += internal;
        self.local[2] += d_kinetic;
        self.local[3] += dissipated;
        self.local[4] = kinetic_now;
    }

    /// The balance from the sums over ranks of `local` (`summed`, five values: the last the
    /// kinetic energy now) and the largest kinetic energy seen so far.
    pub fn balance(&self, summed: &[f64], kinetic_max: f64) -> Balance {
        let external = self.external + summed[0];
        let (internal, kinetic, dissipated) = (summed[1], summed[2], summed[3]);
        let scale = external.abs().max(internal.abs()).max(kinetic_max).max(dissipated.abs());
        let imbalance = external - internal - kinetic - dissipated;
        Balance {
            external,
            internal,
            kinetic,
            dissipated,
            error: if scale > 0.0 { imbalance.abs() / scale } else { 0.0 },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::Interp;

    fn input(stress: [f64; 4], p: f64) -> ParticleInput {
        ParticleInput {
            volume: 2.0,
            porosity: 0.25,
            mass: 3.0,
            water_mass: 0.5,
            stress: crate::soils::plane(stress),
            p,
            body_acc: [0.0, -10.0],
            ..ParticleInput::at_rest()
        }
    }

    #[test]
    fn stress_work_is_the_trapezoidal_product_of_stress_and_strain_increment() {
        // Uniaxial: Δε_yy = −0.01, σ'_yy from −100 to −300, p from 10 to 30, Δε_v,s = −0.01 and
        // Δε_v,w = −0.02; V from 2 to 1.98.
        let it = Interp { du: [0.0, -0.1], dw: [0.0, -0.2], dvol_u: -0.01, dvol_w: -0.02, ..Interp::default() };
        let step = StepResult {
            interp: it,
            stress: crate::soils::plane([0.0, -300.0, 0.0, 0.0]),
            eps_pd: 0.0,
            f_inc: [[1.0, 0.0], [0.0, 0.99]],
            jacobian: 0.99,
            deps: [0.0, -0.01, 0.0, 0.0, 0.0, 0.0],
            grad_n: [0.0; 2],
            jbar: None,
            velocity: None,
        };
        let e = particle_step(&input([0.0, -100.0, 0.0, 0.0], 10.0), &step, 20.0, (1.98, [0.0, -10.0]));
        let v = 1.99;
        let expected = v * (-200.0 * -0.01 - 20.0 * (0.75 * -0.01 + 0.25 * -0.02));
        assert!((e.internal - expected).abs() < 1e-12, "{e:?} vs {expected}");
        // Body work: g = −10 on m Δu = 3 × −0.1 and m_w ΔU = 0.5 × −0.2.
        assert!((e.body - (3.0 * 1.0 + 0.5 * 2.0)).abs() < 1e-12, "{e:?}");
        // A body force that changes over the step does the work of its mean: −10 at t_n, −30 at t_{n+1}.
        let e = particle_step(&input([0.0, -100.0, 0.0, 0.0], 10.0), &step, 20.0, (1.98, [0.0, -30.0]));
        assert!((e.body - 2.0 * (3.0 * 1.0 + 0.5 * 2.0)).abs() < 1e-12, "{e:?}");
        // Shear: σ_xy Δγ_xy.
        let shear = StepResult {
            deps: [0.0, 0.0, 0.02, 0.0, 0.0, 0.0],
            stress: crate::soils::plane([0.0, 0.0, 50.0, 0.0]),
            ..step
        };
        let e = particle_step(&input([0.0, 0.0, 50.0, 0.0], 0.0), &shear, 0.0, (1.98, [0.0, -10.0]));
        assert!((e.internal - 1.99 * (50.0 * 0.02 - 0.0)).abs() < 1e-9, "{e:?}");
        // The porosity gradient's term: ∇n·(ΔU − Δu) = 0.5 × (−0.2 + 0.1) beside the volumetric ones.
        let graded = StepResult { grad_n: [0.0, 0.5], ..step };
        let e = particle_step(&input([0.0, -100.0, 0.0, 0.0], 10.0), &graded, 20.0, (1.98, [0.0, -10.0]));
        let expected = v * (-200.0 * -0.01 - 20.0 * (0.75 * -0.01 + 0.25 * -0.02 + 0.5 * -0.1));
        assert!((e.internal - expected).abs() < 1e-12, "{e:?} vs {expected}");
    }

    #[test]
    fn a_balanced_ledger_has_no_error_and_an_unbalanced_one_its_share() {
        let mut l = Ledger { external: 10.0, ..Ledger::default() };
        l.add_particles(2.0, 7.0, 4.0, 1.0, 4.0);
        assert_eq!(l.balance(&l.local, 4.0).error, 0.0);
        l.add_particles(0.0, 1.2, 0.0, 0.0, 4.0);
        let b = l.balance(&l.local, 4.0);
        assert!((b.error - 1.2 / 12.0).abs() < 1e-12, "{b:?}");
        assert_eq!(Ledger::default().balance(&[0.0; 5], 0.0).error, 0.0);
        let it = Interp {
            motion: crate::kernels::Motion { v_u: [1.0, 0.0], v_w: [3.0, 0.0], ..Default::default() },
            ..Interp::default()
        };
        let step = StepResult {
            interp: it,
            stress: [0.0; crate::soils::NS],
            eps_pd: 0.0,
            f_inc: [[1.0, 0.0], [0.0, 1.0]],
            jacobian: 1.0,
            deps: [0.0; crate::soils::NS],
            grad_n: [0.0; 2],
            jbar: None,
            velocity: None,
        };
        assert!((darcy(2.0, 0.5, &step) - 4.0).abs() < 1e-12);
        assert!((kinetic(2.0, 1.0, [1.0, 1.0], [0.0, 2.0]) - 4.0).abs() < 1e-12);
    }
}
