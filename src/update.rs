//! The particle update after a converged step ([003] Eq. 24, [000] Eq. 11): each material point
//! takes the step the converged residual computed for it ([`StepResult`]), after the checks that
//! it may ([`check_step`]: every quantity finite, a positive volume ratio, a porosity inside
//! (0, 1)).

use crate::algebra::{cofactor_mul, det, product};
use crate::kernels::StepResult;
use crate::model::{position_text, shape, Model};
use crate::scheme::Integration;
use crate::soils::finite_strain;

/// Why a particle update was refused.
#[derive(Debug, Clone, PartialEq)]
pub struct InadmissibleStep(pub String);

/// Whether particle `k` may take the converged step: every quantity it would take must be finite,
/// its volume ratio J positive and the porosity it implies ([`porosity_after`]) inside
/// (0, 1) in a two-phase analysis (a one-phase point keeps its porosity, which may be 0). The
/// message names the particle and the quantity.
pub fn check_step<const D: usize>(model: &Model<D>, k: usize, step: &StepResult<D>) -> Result<(), InadmissibleStep> {
    if let Some(e) = nonfinite(model, k, step) {
        return Err(e);
    }
    let j = step.jacobian;
    let ps = &model.particles;
    let n_new = porosity_after(model, k, j);
    // A one-phase point keeps its porosity, which may be zero (a fluid, a solid).
    let porous = !model.pore_water || (n_new > 0.0 && n_new < 1.0);
    if j <= 0.0 || n_new.is_nan() || !porous {
        return Err(InadmissibleStep(format!(
            "material point {} at {} m: volume ratio J = {j:.4} gives porosity {n_new:.4}",
            ps.id[k],
            position_text(&ps.x[k])
        )));
    }
    Ok(())
}

/// The first quantity of particle `k`'s step that is not finite (NaN or Inf), naming the
/// particle, if any.
pub fn nonfinite<const D: usize>(model: &Model<D>, k: usize, step: &StepResult<D>) -> Option<InadmissibleStep> {
    let ps = &model.particles;
    let it = &step.interp;
    let j = step.jacobian;
    let finite = [
        ("displacement increment", it.du.iter().all(|u| u.is_finite())),
        ("velocity", it.motion.v_u.iter().all(|v| v.is_finite()) && it.motion.a_u.iter().all(|a| a.is_finite())),
        ("effective stress", step.stress.iter().all(|s| s.is_finite())),
        ("pore pressure increment", it.dp.is_finite()),
        ("volume ratio", j.is_finite()),
    ];
    finite.iter().find(|f| !f.1).map(|(what, _)| {
        InadmissibleStep(format!(
            "material point {} at {} m: its {what} is not finite (NaN or Inf)",
            ps.id[k],
            position_text(&ps.x[k])
        ))
    })
}

/// Updates particle `k` with the converged step ([003] Eq. 24, [000] Eq. 11): in a dynamic stage,
/// accelerations from the nodal Newmark accelerations ([003] Eq. 24a), velocities by the Newmark rule
/// v_{n+1} = v_n + Δt((1 − γ)a_n + γ a_{n+1}) on the point (a FLIP update, where [003] Eq. 24b
/// interpolates the nodal velocities: that PIC update damps the transients of the verification
/// cases measurably, e.g. the Terzaghi settlement error rises from 2e-5 to 1.5e-3), the
/// effective stress and ε̄ exactly as the converged residual computed them (objective update,
/// see [`crate::kernels::kinematics`]), pore pressure by `dp` (the interpolated or recovered
/// increment), position and displacement by the interpolated solid increment, deformation
/// gradient by F_{n+1} = F̄ F_n, volume by J_v, porosity by conservation of solid mass:
/// (1 − n_{n+1}) V_{n+1} = (1 − n_n) V_n, and (GIMP with stretching domains) the domain
/// half-widths by l_p = l_p0 ⊙ diag(sqrt(FᵀF)) (iGIMP), at most half a cell. In a static or
/// quasi-static stage there is no acceleration: the velocity is the step's mean, Δu/Δt, for
/// both phases (the Darcy flux is not a particle quantity). The pore-pressure gradient follows
/// the pressure and the material: ∇p ← ΔF⁻ᵀ(∇p + Σ ∇S Δp) (interpolated on x_n, then carried
/// to x_{n+1}; it drives the next step's Darcy flux).
pub fn update_particle<const D: usize>(
    model: &mut Model<D>,
    k: usize,
    step: &StepResult<D>,
    dp: f64,
    dt: f64,
) -> Result<(), InadmissibleStep> {
    check_step(model, k, step)?;
    let j = step.jacobian;
    let n_new = porosity_after(model, k, j);
    let ps = &mut model.particles;
    let it = &step.interp;
    match model.integration {
        Integration::Dynamic { gamma: g, .. } => {
            for c in 0..D {
                ps.vel[k][c] += dt * ((1.0 - g) * ps.acc[k][c] + g * it.motion.a_u[c]);
                ps.acc[k][c] = it.motion.a_u[c];
                if model.pore_water {
                    ps.vel_w[k][c] += dt * ((1.0 - g) * ps.acc_w[k][c] + g * it.motion.a_w[c]);
                    ps.acc_w[k][c] = it.motion.a_w[c];
                }
            }
        }
        Integration::Explicit { flip, .. } => {
            // [002] Eqs. 11–13: FLIP v_p + Σ S (v_i^{n+1} − v_i^n) blended with PIC Σ S v_i^{n+1};
            // Σ S v_i^{n+1} = Δu_p/Δt, and Σ S v_i^n is the interpolated nodal velocity of the
            // grid update's start (`interp.motion.v_u`, set by `Points::result` from the
            // lumped velocities, `assembly::explicit`); the water's likewise
            // (Δw_p/Δt and `interp.motion.v_w`). XPIC sets the solid's velocity itself
            // (`StepResult::velocity`; one-phase only).
            for c in 0..D {
                let pic = it.du[c] / dt;
                let blend = flip * (ps.vel[k][c] + pic - it.motion.v_u[c]) + (1.0 - flip) * pic;
                let v = step.velocity.map_or(blend, |v| v[c]);
                ps.acc[k][c] = (v - ps.vel[k][c]) / dt;
                ps.vel[k][c] = v;
                if model.pore_water {
                    let pic = it.dw[c] / dt;
                    let v = flip * (ps.vel_w[k][c] + pic - it.motion.v_w[c]) + (1.0 - flip) * pic;
                    ps.acc_w[k][c] = (v - ps.vel_w[k][c]) / dt;
                    ps.vel_w[k][c] = v;
                }
            }
        }
        _ => {
            for c in 0..D {
                ps.vel[k][c] = it.du[c] / dt;
                ps.acc[k][c] = 0.0;
                if model.pore_water {
                    ps.vel_w[k][c] = ps.vel[k][c];
                    ps.acc_w[k][c] = 0.0;
                }
            }
        }
    }
    if model.pore_water {
        // The gradient on x_n, Σ ∇S Δp added, then carried to x_{n+1} with the material:
        // ∇_{n+1} p = ΔF⁻ᵀ ∇_n p (the pressure is a material field between steps).
        let g: [f64; D] = std::array::from_fn(|c| ps.grad_p[k][c] + it.grad_dp[c]);
        let fi = &step.f_inc;
        let det = det(fi);
        let m = cofactor_mul(fi, g);
        ps.grad_p[k] = m.map(|v| v / det);
    }
    for c in 0..D {
        ps.x[k][c] += it.du[c];
        ps.disp[k][c] += it.du[c];
    }
    ps.stress[k] = step.stress;
    ps.eps_pd[k] = step.eps_pd;
    if let Some(jbar) = step.jbar {
        ps.jbar[k] = jbar;
    }
    ps.p[k] += dp;
    ps.porosity[k] = n_new;
    let f = &mut ps.def_grad[k];
    let f_new = product(&step.f_inc, f);
    match model.materials[ps.material[k] as usize].model.fluid_volume_ratio(finite_strain::embed(&f_new), step.jbar) {
        // A fluid point carries its volume ratio only (see `Constitutive::fluid_volume_ratio`).
        Some(jf) => {
            ps.volume[k] *= jf / det(f);
            let s = if D == 2 { jf.sqrt() } else { jf.cbrt() };
            *f = std::array::from_fn(|a| std::array::from_fn(|b| if a == b { s } else { 0.0 }));
        }
        None => {
            ps.volume[k] *= j;
            *f = f_new;
        }
    }
    if model.stretch_domains {
        let u = shape::stretch_diagonal(f);
        for (d, lp) in ps.lp[k].iter_mut().enumerate() {
            *lp = (ps.lp0[k][d] * u[d]).min(0.5 * model.grid.h[d]);
        }
    }
    Ok(())
}

/// The porosity of particle `k` after a step with volume ratio J, by conservation of solid mass,
/// n = 1 − (1 − n₀)/J; a one-phase (total-stress) run has no porosity among its state variables
/// and keeps the initial value.
fn porosity_after<const D: usize>(model: &Model<D>, k: usize, j: f64) -> f64 {
    let n = model.particles.porosity[k];
    if model.pore_water {
        1.0 - (1.0 - n) / j
    } else {
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::Interp;
    use crate::model::grid;
    use crate::model::particles::Particles;
    use crate::soils;

    /// The two-phase column of the case tests, with gravity's pore-pressure gradient on its points.
    fn column() -> Model {
        let c = crate::validation::load(crate::case::tests_support::MINIMAL, "t", &[]).unwrap();
        let mut m = Model::build(&c, |_, _| true);
        m.integration = crate::scheme::Integration::QuasiStatic { theta: 1.0 };
        for g in m.particles.grad_p.iter_mut() {
            *g = [300.0, -9.81e3];
        }
        m
    }

    /// The model `m` in three dimensions: its grid, points and domains extruded by one cell of
    /// `hz` along z, with F_zz = 1 (its loads and boundaries dropped).
    fn lift(m: &Model, hz: f64) -> Model<3> {
        let v = |a: [f64; 2], z: f64| [a[0], a[1], z];
        let ps = &m.particles;
        let n = ps.len();
        let mut q = Particles::<3>::default();
        for k in 0..n {
            q.push_blank(ps.id[k], ps.body[k], ps.material[k]);
            q.x[k] = v(ps.x[k], 0.5 * hz);
            q.x0[k] = v(ps.x0[k], 0.5 * hz);
            q.lp[k] = v(ps.lp[k], 0.25 * hz);
            q.lp0[k] = v(ps.lp0[k], 0.25 * hz);
            let f = ps.def_grad[k];
            q.def_grad[k] = [[f[0][0], f[0][1], 0.0], [f[1][0], f[1][1], 0.0], [0.0, 0.0, 1.0]];
            q.volume[k] = ps.volume[k];
            q.porosity[k] = ps.porosity[k];
            q.mass[k] = ps.mass[k];
            q.stress[k] = ps.stress[k];
            q.p[k] = ps.p[k];
            q.grad_p[k] = v(ps.grad_p[k], 0.0);
        }
        Model {
            pore_water: m.pore_water,
            basis: m.basis,
            stretch_domains: m.stretch_domains,
            grid: grid::Grid::new(v(m.grid.origin, 0.0), v(m.grid.h, hz), [m.grid.cells[0], m.grid.cells[1], 1]),
            materials: m.materials.clone(),
            particles: q,
            loads: Vec::new(),
            boundaries: Vec::new(),
            g: m.g,
            integration: m.integration,
            bbar: m.bbar,
            fbar: m.fbar,
            patch_recovery: m.patch_recovery,
            pressure_update: m.pressure_update,
            n_bodies: m.n_bodies,
            body_names: m.body_names.clone(),
            pressure_projection: m.pressure_projection,
            geometry: shape::Geometry::Solid,
            stiffness: m.stiffness,
            stress_recovery: m.stress_recovery,
            filtered_mode_control: m.filtered_mode_control,
            internal_force: m.internal_force,
            linear_increments: m.linear_increments,
            stiffness_in_jacobian: m.stiffness_in_jacobian,
        }
    }

    /// A converged step of `D` dimensions with the incremental deformation gradient `f_inc`
    /// (constant over the body, so Δu = (ΔF − I) x), the pressure gradient's increment `grad_dp`
    /// and the stress `stress`.
    fn step<const D: usize>(
        f_inc: [[f64; D]; D],
        x: [f64; D],
        grad_dp: [f64; D],
        stress: soils::Stress,
    ) -> StepResult<D> {
        let du = std::array::from_fn(|a| (0..D).map(|b| f_inc[a][b] * x[b]).sum::<f64>() - x[a]);
        StepResult {
            interp: Interp { du, grad_dp, dp: 40.0, ..Interp::default() },
            stress,
            eps_pd: 0.01,
            f_inc,
            jacobian: det(&f_inc),
            deps: [0.0; soils::NS],
            grad_n: [0.0; D],
            jbar: None,
            velocity: None,
        }
    }

    /// A plane point's update is a three-dimensional point's with F_zz = 1 and Δu_z = 0: position,
    /// volume, porosity, deformation gradient, domain, velocity and pressure gradient agree to
    /// round-off.
    #[test]
    fn a_plane_update_is_a_three_dimensional_update_without_z() {
        let mut m2 = column();
        let mut m3 = lift(&m2, 0.2);
        let f2 = [[1.01, 0.03], [-0.02, 0.97]];
        let f3 = [[1.01, 0.03, 0.0], [-0.02, 0.97, 0.0], [0.0, 0.0, 1.0]];
        let s = soils::plane([-1.0e3, -2.0e3, 150.0, -1.2e3]);
        for k in 0..m2.particles.len() {
            let x2 = m2.particles.x[k];
            update_particle(&mut m2, k, &step(f2, x2, [10.0, -20.0], s), 40.0, 0.5).unwrap();
            let x3 = m3.particles.x[k];
            update_particle(&mut m3, k, &step(f3, x3, [10.0, -20.0, 0.0], s), 40.0, 0.5).unwrap();
            let (p2, p3) = (&m2.particles, &m3.particles);
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * a.abs().max(1.0);
            for c in 0..2 {
                assert!(close(p2.x[k][c], p3.x[k][c]) && close(p2.vel[k][c], p3.vel[k][c]), "point {k}");
                assert!(close(p2.lp[k][c], p3.lp[k][c]) && close(p2.grad_p[k][c], p3.grad_p[k][c]), "point {k}");
                for d in 0..2 {
                    assert!(close(p2.def_grad[k][c][d], p3.def_grad[k][c][d]), "point {k}");
                }
            }
            assert!(close(p2.volume[k], p3.volume[k]) && close(p2.porosity[k], p3.porosity[k]), "point {k}");
            assert_eq!((p3.x[k][2], p3.lp[k][2], p3.def_grad[k][2][2]), (0.1, 0.05, 1.0), "point {k}");
        }
    }

    /// A general three-dimensional step: x and the displacement move by Δu, F_{n+1} = ΔF F_n, the
    /// volume by det ΔF, the porosity by conservation of the grains, the pressure gradient is
    /// carried with the material (ΔFᵀ ∇p_{n+1} = ∇p_n + Σ∇S Δp), and the domain stretches by the
    /// diagonal of U = sqrt(FᵀF); a rotation about a tilted axis leaves the domain as it was.
    #[test]
    fn a_three_dimensional_update_follows_the_deformation() {
        let m2 = column();
        let mut m3 = lift(&m2, 0.2);
        let df = [[1.02, 0.01, -0.03], [0.015, 0.98, 0.02], [-0.01, 0.025, 1.03]];
        let s = [-1.0e3, -2.0e3, 150.0, -1.2e3, 80.0, -120.0];
        let k = 3;
        let before = m3.particles.clone();
        let x = before.x[k];
        let grad_dp = [10.0, -20.0, 30.0];
        let st = step(df, x, grad_dp, s);
        update_particle(&mut m3, k, &st, 40.0, 0.5).unwrap();
        let ps = &m3.particles;
        let j = det(&df);
        for c in 0..3 {
            assert!((ps.x[k][c] - (x[c] + st.interp.du[c])).abs() < 1e-15);
            // ΔFᵀ ∇p_{n+1} = ∇p_n + Σ ∇S Δp.
            let back: f64 = (0..3).map(|a| df[a][c] * ps.grad_p[k][a]).sum();
            assert!((back - (before.grad_p[k][c] + grad_dp[c])).abs() < 1e-9, "∇p: {back}");
            for d in 0..3 {
                let want: f64 = (0..3).map(|e| df[c][e] * before.def_grad[k][e][d]).sum();
                assert!((ps.def_grad[k][c][d] - want).abs() < 1e-15);
            }
        }
        assert!((ps.volume[k] - before.volume[k] * j).abs() < 1e-15 * before.volume[k]);
        let n0 = before.porosity[k];
        assert!(((1.0 - ps.porosity[k]) * ps.volume[k] - (1.0 - n0) * before.volume[k]).abs() < 1e-15);
        assert_eq!(ps.stress[k], s);
        // The domain: lp0 times the diagonal of U (U² = FᵀF).
        let u = shape::stretch_diagonal(&ps.def_grad[k]);
        let c: [[f64; 3]; 3] = std::array::from_fn(|a| {
            std::array::from_fn(|b| (0..3).map(|e| ps.def_grad[k][e][a] * ps.def_grad[k][e][b]).sum())
        });
        for d in 0..3 {
            assert!((ps.lp[k][d] - before.lp0[k][d] * u[d]).abs() < 1e-15);
            // U_dd² ≤ C_dd (U_dd² + Σ_{e≠d} U_de² = C_dd) and U_dd is near the stretch's square root.
            assert!(u[d] * u[d] <= c[d][d] + 1e-14 && (u[d] * u[d] - c[d][d]).abs() < 1e-3, "{u:?} {c:?}");
        }
        // A rigid rotation about a tilted axis: U = I.
        let axis: [f64; 3] = [0.3, -0.5, 0.81];
        let len: f64 = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        let r = soils::principal::rotation(axis.map(|a| a / len), 0.7);
        let u = shape::stretch_diagonal(&r);
        assert!(u.iter().all(|v| (v - 1.0).abs() < 1e-14), "{u:?}");
    }
}
