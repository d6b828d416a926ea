//! What a kernel knows of one material point at the start of a step ([`ParticleInput`]).

use super::Motion;
use crate::algebra::det;
use crate::model::{fbar, Model};
use crate::soils::Stress;

/// The particle quantities the kernels need (at t_n), in `D` dimensions (two unless it says
/// otherwise).
#[derive(Debug, Clone, Copy)]
pub struct ParticleInput<const D: usize = 2> {
    /// Volume V [m³ per m in two dimensions, m³ in three].
    pub volume: f64,
    /// Porosity n.
    pub porosity: f64,
    /// Mass of the u equation (grains, or mixture in one-phase) [kg].
    pub mass: f64,
    /// Water mass n ρ_w V [kg] (two-phase).
    pub water_mass: f64,
    /// Drag coefficient n² γ_w V / k [N s/m] (two-phase).
    pub drag: f64,
    /// 1/Q [1/Pa] (two-phase).
    pub inv_q: f64,
    /// Mobility k/γ_w of Darcy's law [m²/(Pa s)] (two-phase).
    pub mobility: f64,
    /// Water density ρ_w [kg/m³] (two-phase).
    pub water_density: f64,
    /// Pore-pressure gradient at t_n [Pa/m] (two-phase), carried by the particle.
    pub grad_p: [f64; D],
    /// Effective stress at t_n [Pa].
    pub stress: Stress,
    /// Deformation gradient at t_n (in-plane in two dimensions; what a hyperelastic model's
    /// stress follows).
    pub def_grad: [[f64; D]; D],
    /// Accumulated deviatoric plastic strain ε̄ at t_n (the soil model's internal variable).
    pub eps_pd: f64,
    /// Pore pressure at t_n [Pa].
    pub p: f64,
    /// Body acceleration at t_{n+1} [m/s²].
    pub body_acc: [f64; D],
    /// Porosity gradient ∇n at t_n [1/m] (two-phase).
    pub grad_n: [f64; D],
    /// Newmark predictors of the point.
    pub pred: Motion<D>,
    /// A geometrically linear step (`analysis.kinematics = "linear_increments"`, [001] Eqs. 5, 7,
    /// 11): see [`kinematics`].
    pub linear: bool,
    /// The F̄ projection's scale c of the step's in-plane deformation, ΔF̄ = c ΔF ([002] Eq. 27;
    /// 1 without it), which the rate-form stress updates see: see
    /// [`kinematics::Kinematics::with_volume_scale`].
    pub fbar: f64,
    /// The F̄ projection's scale of the point's total deformation, F̄ = s F with s = (J̄/J)^{1/D}
    /// ([002] Eq. 18; 1 without it), which a hyperelastic model sees: at the step's start that
    /// of the point's stored J̄ (its stress σ_n), at its end that of the projected J̄_{n+1}.
    pub fbar_total: f64,
    /// The step's Δt [s], which a rate-dependent model (the Newtonian fluid's viscosity) divides
    /// the step's deformation by; 0 where no step is being taken.
    pub dt: f64,
    /// [002]'s projected volume ratio J̄_p^n the point carries (1 without F̄): an implicit F̄
    /// step's stress sees the volume ratio J̄_{n+1}/J̄_n ([`fbar`]).
    pub jbar: f64,
    /// The scale κ [Pa/m] of an implicit F̄ step's projection rows ([`fbar`]; 0 otherwise).
    pub fbar_rows: f64,
    /// The factor α of the control of the modes a recovered strain filters
    /// ([`super::control`]; 0: none).
    pub control: f64,
}

#[cfg(test)]
impl<const D: usize> ParticleInput<D> {
    /// A point of unit volume and mass at rest: dry, unstressed, undeformed, without body force,
    /// for tests to fill in what they need.
    pub fn at_rest() -> ParticleInput<D> {
        ParticleInput {
            volume: 1.0,
            porosity: 0.0,
            mass: 1.0,
            water_mass: 0.0,
            drag: 0.0,
            inv_q: 0.0,
            mobility: 0.0,
            water_density: 1000.0,
            grad_p: [0.0; D],
            stress: [0.0; crate::soils::NS],
            def_grad: crate::algebra::identity(),
            eps_pd: 0.0,
            p: 0.0,
            body_acc: [0.0; D],
            grad_n: [0.0; D],
            pred: Motion::default(),
            linear: false,
            fbar: 1.0,
            fbar_total: 1.0,
            dt: 0.0,
            jbar: 1.0,
            fbar_rows: 0.0,
            control: 0.0,
        }
    }
}

impl<const D: usize> ParticleInput<D> {
    /// The kernel input of particle `idx` of `model` at the start of the step, with the body
    /// acceleration of its body from `body_acc` (no predictors, Δt or porosity gradient yet: the
    /// step sets them).
    #[inline]
    pub fn of(model: &Model<D>, idx: usize, body_acc: &[[f64; D]]) -> ParticleInput<D> {
        let ps = &model.particles;
        let mat = &model.materials[ps.material[idx] as usize];
        let (v, n) = (ps.volume[idx], ps.porosity[idx]);
        let (water_mass, drag, inv_q, mobility) = if model.pore_water {
            let gw = mat.water_density * model.g;
            (model.water_mass(idx), model.drag(idx), mat.inv_q_at(n), mat.conductivity_at(n) / gw)
        } else {
            (0.0, 0.0, 0.0, 0.0)
        };
        ParticleInput {
            volume: v,
            porosity: n,
            mass: ps.mass[idx],
            water_mass,
            drag,
            inv_q,
            mobility,
            water_density: mat.water_density,
            grad_p: ps.grad_p[idx],
            stress: ps.stress[idx],
            def_grad: ps.def_grad[idx],
            eps_pd: ps.eps_pd[idx],
            p: ps.p[idx],
            body_acc: body_acc[ps.body[idx] as usize],
            grad_n: [0.0; D],
            pred: Default::default(),
            linear: model.linear_increments,
            fbar: 1.0,
            fbar_total: if model.fbar { fbar::scale(ps.jbar[idx], det(&ps.def_grad[idx]), D) } else { 1.0 },
            dt: 0.0,
            jbar: ps.jbar[idx],
            fbar_rows: 0.0,
            control: model.filtered_mode_control,
        }
    }
}
