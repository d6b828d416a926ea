//! The kinematics of the finite-strain models of [002]'s examples (§4.1–4.4; the paper names them
//! but omits their forms, so these are the standard ones): compressible neo-Hookean
//! ([`super::neo_hookean`]), Hencky elasticity with J2 plasticity and exponential softening
//! ([`super::hencky_j2`]), and a Newtonian fluid ([`super::newtonian_fluid`]). The deformation
//! gradient is 3 × 3 ([`M3`]; a plane-strain point's is [`plane`], F_zz = 1); stresses are the
//! 6-vectors [xx, yy, xy, zz, yz, zx] of [`super::stress`] (Cauchy, tension positive).
//!
//! They are total (hyperelastic) or multiplicative forms driven by the deformation gradient (with
//! [002]'s F̄, by F̄). The explicit integrator needs no tangent; the implicit stages take the
//! solids' consistent tangent ∂σ/∂ΔF ([`FiniteTangent`], [`left_tangent`]; the fluid stays
//! explicit). Each is objective by construction: the neo-Hookean and Hencky
//! stresses are isotropic functions of b = F Fᵀ (or b^e), so a rotation R of the deformation turns
//! the stress into R σ Rᵀ.

use super::principal::{self, Principal};
use super::stress::{Stress, IDENTITY6, NS};
use super::{LinearElastic, Region, StressUpdate};
use crate::algebra::right_stretch;

/// An in-plane 2 × 2 matrix.
pub type M2 = [[f64; 2]; 2];

/// A 3 × 3 matrix.
pub type M3 = [[f64; 3]; 3];

/// The identity.
pub const I3: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// The deformation gradient of a plane-strain point with in-plane part `f` (F_zz = 1).
pub fn plane(f: M2) -> M3 {
    [[f[0][0], f[0][1], 0.0], [f[1][0], f[1][1], 0.0], [0.0, 0.0, 1.0]]
}

/// The 3 × 3 deformation gradient of a point of dimension `D` (2 or 3): a plane point's
/// in-plane `f` with F_zz = 1 ([`plane`]), or `f` itself.
pub fn embed<const D: usize>(f: &[[f64; D]; D]) -> M3 {
    match D {
        2 => plane([[f[0][0], f[0][1]], [f[1][0], f[1][1]]]),
        _ => std::array::from_fn(|i| std::array::from_fn(|j| f[i][j])),
    }
}

/// Whether `f` is a plane deformation (F_zz = 1, no out-of-plane shear): what [`plane`] makes.
pub fn is_plane(f: &M3) -> bool {
    f[0][2] == 0.0 && f[1][2] == 0.0 && f[2][0] == 0.0 && f[2][1] == 0.0 && f[2][2] == 1.0
}

/// det F (the volume ratio).
pub fn det(f: M3) -> f64 {
    f[0][0] * (f[1][1] * f[2][2] - f[1][2] * f[2][1]) - f[0][1] * (f[1][0] * f[2][2] - f[1][2] * f[2][0])
        + f[0][2] * (f[1][0] * f[2][1] - f[1][1] * f[2][0])
}

/// det of a plane-strain point's in-plane deformation gradient (its volume ratio, F_zz = 1).
pub fn det2(f: M2) -> f64 {
    det(plane(f))
}

/// A B.
pub fn mul(a: M3, b: M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j]))
}

/// F S Fᵀ for a symmetric S given as a stress vector; the result as a stress vector.
pub(super) fn push(f: M3, s: &Stress) -> Stress {
    let sm = principal::tensor(s);
    let fs: M3 =
        std::array::from_fn(|i| std::array::from_fn(|j| f[i][0] * sm[0][j] + f[i][1] * sm[1][j] + f[i][2] * sm[2][j]));
    principal::TENSOR_INDEX.map(|(i, j)| fs[i][0] * f[j][0] + fs[i][1] * f[j][1] + fs[i][2] * f[j][2])
}

/// The stress vector of the identity.
pub(super) const UNIT: Stress = [1.0, 1.0, 0.0, 1.0, 0.0, 0.0];

/// Whether component `c` of a stress vector is a normal one (xx, yy, zz).
pub(super) fn normal(c: usize) -> bool {
    matches!(c, 0 | 1 | 3)
}

/// A finite-strain model's update ([`super::SoilLaw::finite`]): its stress after the step (NaN
/// when the step is inadmissible, `None`), ε̄ and region, with the small-strain elasticity
/// `elastic` of its moduli as the tangent.
pub(super) fn finite_update(
    elastic: &LinearElastic,
    stress: Option<Stress>,
    eps_pd: f64,
    region: Region,
) -> StressUpdate {
    StressUpdate {
        stress: stress.unwrap_or([f64::NAN; NS]),
        tangent: elastic.d,
        trial_tangent: IDENTITY6,
        eps_pd,
        region,
    }
}

/// ∂σ/∂ΔF of a finite-strain model's Cauchy stress after a step at fixed F_n and σ_n
/// ([`super::SoilLaw::finite_tangent`]): `t[r][a][b]` = ∂σ_r/∂ΔF_ab for the stress-vector
/// component r.
pub type FiniteTangent = [M3; NS];

/// ∂σ/∂ΔF of a Cauchy stress σ = τ(b)/J whose Kirchhoff stress is a function of the left
/// Cauchy–Green tensor b = ΔF b_n ΔFᵀ (b^e_trial for an elastoplastic model) and J = det ΔF J_n,
/// at fixed b_n and J_n. A change δΔF has ℓ = δΔF ΔF⁻¹, δb = ℓ b + b ℓᵀ and δJ/J = tr ℓ, so
/// δσ = δτ/J − σ tr ℓ with δτ = `dtau`(δb, tr ℓ) (δb a stress vector, tensor shears). For the
/// unit change of ΔF_ab, ℓ = e_a ⊗ w with w the row b of ΔF⁻¹: δb = e_a ⊗ bw + bw ⊗ e_a and
/// tr ℓ = w_a. `b` is b after the step, `sigma` σ and `j` J after it.
pub(super) fn left_tangent(
    df: &M3,
    b: &Stress,
    sigma: &Stress,
    j: f64,
    dtau: impl Fn(&Stress, f64) -> Stress,
) -> FiniteTangent {
    let inv = crate::algebra::inverse(df);
    let bm = principal::tensor(b);
    let mut out = [[[0.0; 3]; 3]; NS];
    for a in 0..3 {
        for (k, w) in inv.iter().enumerate() {
            let bw: [f64; 3] = std::array::from_fn(|i| bm[i][0] * w[0] + bm[i][1] * w[1] + bm[i][2] * w[2]);
            let delta = |i: usize, m: usize| if i == m { 1.0 } else { 0.0 };
            let db: Stress = principal::TENSOR_INDEX.map(|(i, m)| delta(i, a) * bw[m] + bw[i] * delta(m, a));
            let tr = w[a];
            let dt = dtau(&db, tr);
            for r in 0..NS {
                out[r][a][k] = dt[r] / j - sigma[r] * tr;
            }
        }
    }
    out
}

/// The rate of deformation of a step of deformation gradient ΔF over Δt [1/s]:
/// d = (V_iso − 1)/Δt, with V_iso the left stretch of the isochoric part ΔF/√det ΔF (polar
/// decomposition ΔF = V R; for a plane step, of its in-plane part ΔF/√det ΔF, whose own plane is
/// where it is isochoric). It is objective (a rigid rotation of the step gives d = 0 whatever its
/// angle), it is the same for ΔF and for F̄'s c ΔF (only the pressure sees J̄), and it is sym L + O(Δt)
/// for a step of velocity gradient L. Zero when `dt` is not positive or ΔF is inadmissible
/// (det ΔF ≤ 0, which the pressure's J then reports).
pub fn rate_of_deformation(df: M3, dt: f64) -> M3 {
    let j = det(df);
    if dt <= 0.0 || j.is_nan() || j <= 0.0 {
        return [[0.0; 3]; 3];
    }
    if is_plane(&df) {
        let s = j.sqrt();
        // V = sqrt(ΔF ΔFᵀ) is the right stretch of ΔFᵀ.
        let v = right_stretch([[df[0][0] / s, df[1][0] / s], [df[0][1] / s, df[1][1] / s]]);
        return [[(v[0][0] - 1.0) / dt, v[0][1] / dt, 0.0], [v[1][0] / dt, (v[1][1] - 1.0) / dt, 0.0], [0.0; 3]];
    }
    // V_iso = (ΔF ΔFᵀ)^½ / J^⅓, in the principal frame of ΔF ΔFᵀ.
    let b = push(df, &UNIT);
    let frame = Principal::of(&b);
    let scale = j.cbrt();
    let v = principal::tensor(&frame.compose(&frame.values.map(|l| l.max(0.0).sqrt() / scale)));
    std::array::from_fn(|a| std::array::from_fn(|c| (v[a][c] - if a == c { 1.0 } else { 0.0 }) / dt))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::soils::hencky_j2::PlasticState;
    use crate::soils::{Constitutive, HenckyJ2Law, LinearElastic, NeoHookeanLaw, NewtonianFluidLaw, VonMisesLaw};

    /// The rotation by `a` about z.
    fn rot(a: f64) -> M3 {
        plane([[a.cos(), -a.sin()], [a.sin(), a.cos()]])
    }

    /// A rotation about a tilted axis (out of every coordinate plane).
    fn tilt(a: f64) -> M3 {
        let n = 14f64.sqrt();
        principal::rotation([1.0 / n, -2.0 / n, 3.0 / n], a)
    }

    /// R σ Rᵀ.
    fn rotate(r: M3, s: Stress) -> Stress {
        principal::rotate(&r, &s)
    }

    /// A plane velocity gradient (no zz rate).
    fn gradient(l: M2) -> M3 {
        [[l[0][0], l[0][1], 0.0], [l[1][0], l[1][1], 0.0], [0.0; 3]]
    }

    /// A plane deformation with its in-plane part scaled by `c` (2D F̄'s ΔF̄ = c ΔF, F_zz = 1).
    fn scale_plane(f: M3, c: f64) -> M3 {
        std::array::from_fn(|i| std::array::from_fn(|j| if i < 2 && j < 2 { f[i][j] * c } else { f[i][j] }))
    }

    fn transpose(a: M3) -> M3 {
        std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
    }

    fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
        let scale = a.iter().chain(b).fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol * scale)
    }

    fn q_of(s: Stress) -> f64 {
        crate::soils::invariants(&s).1
    }

    #[test]
    fn neo_hooke_is_objective_and_linear_elastic_for_small_strains() {
        let m = NeoHookeanLaw::new(70.0, 0.499);
        let f = plane([[1.12, 0.31], [-0.05, 0.93]]);
        let s = m.stress(f).unwrap();
        for a in [0.3, 1.7, -2.2] {
            let r = rot(a);
            let sr = m.stress(mul(r, f)).unwrap();
            assert!(close(&sr, &rotate(r, s), 1e-13), "{sr:?} vs {:?}", rotate(r, s));
        }
        // At rest: no stress. Small strains: σ = D ε to O(ε²).
        assert!(m.stress(I3).unwrap().iter().all(|v| v.abs() < 1e-15));
        let e = 1e-7;
        let f = plane([[1.0 + 2.0 * e, 0.5 * e], [0.5 * e, 1.0 - e]]);
        let lin = LinearElastic::new(70.0, 0.499).trial(&[0.0; NS], &[2.0 * e, -e, e, 0.0, 0.0, 0.0]);
        assert!(close(&m.stress(f).unwrap(), &lin, 1e-5), "{:?} vs {lin:?}", m.stress(f));
        assert!(m.stress(plane([[0.5, 0.0], [0.0, -0.1]])).is_none());
    }

    #[test]
    fn hencky_j2_is_objective_and_leaves_a_rigidly_rotated_stress_unrotated_in_the_material_frame() {
        let m = HenckyJ2Law::new(25e6, 0.3, 40e3, 2.45e3, 5.0);
        // A state with stress and plastic history from a plastic shearing step.
        let first = m.step(plane([[1.0, 0.01], [0.0, 1.0]]), &PlasticState::default(), 1.0).unwrap();
        assert!(first.plastic);
        let df = plane([[1.003, 0.004], [-0.002, 0.999]]);
        let j = det(df);
        let base = m.step(df, &first.state, j).unwrap();
        for a in [0.4, -1.3, 3.0] {
            let r = rot(a);
            let turned = m.step(mul(r, df), &first.state, j).unwrap();
            assert!(close(&turned.stress, &rotate(r, base.stress), 1e-12), "{a}");
            assert!((turned.state.eps - base.state.eps).abs() <= 1e-14);
            let be = rotate(r, base.state.be);
            assert!(close(&turned.state.be, &be, 1e-12));
            // A rigid rotation alone: the stress turns with the material, Rᵀ σ R = σ_n.
            let spun = m.step(r, &first.state, 1.0).unwrap();
            assert!(!spun.plastic);
            assert!(close(&rotate(rot(-a), spun.stress), &first.stress, 1e-12), "{a}");
            assert_eq!(spun.state.eps, first.state.eps);
        }
    }

    #[test]
    fn hencky_j2_returns_onto_the_softened_yield_surface() {
        let m = HenckyJ2Law::new(25e6, 0.45, 40.82e3, 2.45e3, 5.0);
        assert!(m.well_posed());
        let mut state = PlasticState::default();
        let mut j = 1.0;
        let mut plastic_steps = 0;
        for k in 0..200 {
            let df = plane([[1.0 + 2e-4, 3e-3], [1e-3, 1.0 - 1.5e-4]]);
            j *= det(df);
            let u = m.step(df, &state, j).unwrap();
            let q = q_of(u.stress) * j; // q of the Kirchhoff stress
            let (c, _) = m.cohesion_at(u.state.eps);
            if u.plastic {
                plastic_steps += 1;
                assert!((q - 3f64.sqrt() * c).abs() <= 1e-10 * q, "step {k}: q {q} vs √3 c {}", 3f64.sqrt() * c);
                assert!(u.state.eps > state.eps);
            } else {
                assert!(q <= 3f64.sqrt() * c * (1.0 + 1e-12), "step {k}");
                assert_eq!(u.state.eps, state.eps);
            }
            // The plastic flow is isochoric: det b^e = J² (b^e's volume is the whole volume).
            let be = u.state.be;
            let det_be = (be[0] * be[1] - be[2] * be[2]) * be[3];
            assert!((det_be - j * j).abs() <= 1e-12, "step {k}: det b^e {det_be} vs J² {}", j * j);
            state = u.state;
        }
        assert!(plastic_steps > 100);
        // Softened far towards the residual strength.
        assert!(m.cohesion_at(state.eps).0 < 0.2 * m.cohesion, "ε̄ = {}", state.eps);
    }

    #[test]
    fn hencky_j2_agrees_with_small_strain_von_mises_for_small_strains() {
        // Perfect plasticity (c_r = c_p): a small-strain shear path against the small-strain von
        // Mises model of porompm's soil models, to O(ε) relative (strains up to 2e-3).
        let (e, nu, c) = (1e7, 0.3, 5e3);
        let m = HenckyJ2Law::new(e, nu, c, c, 0.0);
        let el = LinearElastic::new(e, nu);
        let vm = Constitutive::VonMises(VonMisesLaw {
            elastic: el,
            cohesion: c,
            residual_cohesion: c,
            softening_modulus: 0.0,
        });
        let (mut state, mut small, mut eps_small, mut j) = (PlasticState::default(), [0.0; NS], 0.0, 1.0);
        for _ in 0..20 {
            let (a, g) = (5e-5, 1e-4);
            let df = plane([[1.0 + a, g], [0.0, 1.0]]);
            j *= det(df);
            let u = m.step(df, &state, j).unwrap();
            state = u.state;
            let up = vm.update(&small, eps_small, &[a, 0.0, g, 0.0, 0.0, 0.0]);
            small = up.stress;
            eps_small = up.eps_pd;
            assert!(close(&u.stress, &small, 5e-3), "{:?} vs {small:?}", u.stress);
        }
        assert!(eps_small > 0.0 && state.eps > 0.0);
        assert!((state.eps - eps_small).abs() <= 5e-3 * eps_small + 1e-9, "{} vs {eps_small}", state.eps);
    }

    #[test]
    fn a_hencky_points_stress_and_volume_ratio_determine_its_elastic_state() {
        // After elastic and plastic steps (with softening), b^e recovered from σ and J is the b^e
        // the update left, to round-off.
        let m = HenckyJ2Law::new(25e6, 0.45, 40.82e3, 2.45e3, 5.0);
        let (mut state, mut j) = (PlasticState::default(), 1.0);
        let mut plastic = 0;
        for k in 0..60 {
            let df = plane([[1.0 + 4e-4 * (k as f64 * 0.3).cos(), 2e-3], [-1e-3, 1.0 - 1e-4]]);
            j *= det(df);
            let u = m.step(df, &state, j).unwrap();
            plastic += usize::from(u.plastic);
            let be = m.elastic_left_cauchy_green(&u.stress, j);
            assert!(close(&be, &u.state.be, 1e-13), "step {k}: {be:?} vs {:?}", u.state.be);
            state = u.state;
        }
        assert!(plastic > 20 && state.eps > 0.0);
        // And the path run through `Constitutive::finite`, which stores only σ, F and ε̄ (F̄ = F
        // here), is the path run with the stored b^e.
        let model = Constitutive::HenckyJ2(m);
        let (mut stress, mut f, mut eps) = ([0.0; NS], plane([[1.0, 0.0], [0.0, 1.0]]), 0.0);
        let (mut state, mut j) = (PlasticState::default(), 1.0);
        for k in 0..60 {
            let df = plane([[1.0 - 3e-4, 1.5e-3 * (k as f64 * 0.2).sin()], [2e-3, 1.0 + 1e-4]]);
            f = mul(df, f);
            j *= det(df);
            let u = model.finite(&df, &f, &stress, eps, 1e-3).unwrap();
            let direct = m.step(df, &state, j).unwrap();
            assert!(close(&u.stress, &direct.stress, 1e-11), "step {k}: {:?} vs {:?}", u.stress, direct.stress);
            assert!((u.eps_pd - direct.state.eps).abs() <= 1e-12 * direct.state.eps.max(1e-300) + 1e-18);
            (stress, eps, state) = (u.stress, u.eps_pd, direct.state);
        }
        assert!(eps > 0.0);
        // With F̄: the kernel passes ΔF̄ = c ΔF and F̄_{n+1} = s ΔF F_n with c = (J̄^{n+1}/(J̄^n ΔJ))^½
        // and s = (J̄^{n+1}/(J^n ΔJ))^½, and the stored σ_n = τ(b^e_n)/J̄^n; `finite` must recover
        // J̄^n = det F̄_{n+1}/det ΔF̄ and give the direct update with ΔF̄ divided by J̄^{n+1}.
        let f_n = plane([[1.02, 0.03], [-0.01, 0.97]]);
        let (jbar_n, jbar_new) = (0.9981, 0.9975);
        let pre = m.step(plane([[1.0, 0.004], [0.002, 1.0]]), &PlasticState::default(), jbar_n).unwrap();
        let df = plane([[1.001, 0.0015], [0.0005, 0.9985]]);
        let (j_n, dj) = (det(f_n), det(df));
        let c = (jbar_new / (jbar_n * dj)).sqrt();
        let s = (jbar_new / (j_n * dj)).sqrt();
        assert!((c - s).abs() > 1e-4, "c and s must differ here: {c} {s}");
        let dfbar = scale_plane(df, c);
        let fbar_new = scale_plane(mul(df, f_n), s);
        let u = model.finite(&dfbar, &fbar_new, &pre.stress, pre.state.eps, 1e-3).unwrap();
        let direct = m.step(dfbar, &pre.state, jbar_new).unwrap();
        assert!(close(&u.stress, &direct.stress, 1e-11), "{:?} vs {:?}", u.stress, direct.stress);
        // The incremental models have no finite-strain stress.
        assert!(Constitutive::LinearElastic(LinearElastic::new(1.0, 0.3)).finite(&f, &f, &stress, 0.0, 1e-3).is_none());
    }

    #[test]
    fn the_newtonian_fluid_has_its_pressure_and_viscous_shear() {
        let w = NewtonianFluidLaw::new(2e9, 1e-3, 0.0);
        let s = w.stress(1.0 - 1e-5, gradient([[0.0, 0.0], [0.0, 0.0]]));
        assert!(close(&s, &[-2e4, -2e4, 0.0, -2e4], 1e-9), "{s:?}");
        // Simple shear v_x = γ̇ y: σ_xy = μ γ̇, no normal stress; a rigid spin carries no stress.
        let s = w.stress(1.0, gradient([[0.0, 10.0], [0.0, 0.0]]));
        assert!(close(&s, &[0.0, 0.0, 1e-2, 0.0], 1e-12), "{s:?}");
        let s = w.stress(1.0, gradient([[0.0, 3.0], [-3.0, 0.0]]));
        assert!(s.iter().all(|v| v.abs() < 1e-15), "{s:?}");
        // Objective: σ(R L Rᵀ) = R σ(L) Rᵀ for the symmetric part.
        let l = gradient([[0.2, 0.5], [0.1, -0.7]]);
        let r = rot(0.8);
        let lr = mul(mul(r, l), rot(-0.8));
        assert!(close(&w.stress(0.99, lr), &rotate(r, w.stress(0.99, l)), 1e-12));
        assert!((w.pressure(0.99) - 2e7).abs() < 1e-6);
    }

    /// The fluid through `Constitutive::finite`: a step that only rotates (by a finite angle)
    /// leaves the pressure of J and no viscous stress; a small simple-shear step gives μ_v γ̇ and
    /// the same viscous stress when F̄ scales the step (c ΔF), only the pressure following J̄.
    #[test]
    fn the_fluid_step_is_objective_and_its_viscosity_does_not_see_fbar() {
        let w = NewtonianFluidLaw::new(2e9, 0.5, 0.0);
        let model = Constitutive::NewtonianFluid(w);
        let dt = 1e-3;
        let f = plane([[0.99999, 0.0], [0.0, 1.0]]);
        let spin = model.finite(&rot(0.7), &f, &[0.0; NS], 0.0, dt).unwrap();
        assert!(close(&spin.stress, &[-2e4, -2e4, 0.0, -2e4], 1e-9), "{:?}", spin.stress);
        // Simple shear at γ̇ = 10/s over the step: σ_xy = μ_v γ̇ to first order in γ̇ Δt.
        let df = plane([[1.0, 10.0 * dt], [0.0, 1.0]]);
        let u = model.finite(&df, &df, &[0.0; NS], 0.0, dt).unwrap();
        assert!((u.stress[2] - 0.5 * 10.0).abs() < 1e-3 * 5.0, "{:?}", u.stress);
        // Normal viscous stresses are of the next order, γ̇Δt σ_xy.
        assert!(u.stress.iter().take(2).all(|v| v.abs() < 10.0 * dt * 5.0), "{:?}", u.stress);
        // F̄: c ΔF changes the pressure (through J̄ = det F̄), not the viscous part.
        let c = 1.0 - 3e-6;
        let dfc = scale_plane(df, c);
        let ub = model.finite(&dfc, &dfc, &[0.0; NS], 0.0, dt).unwrap();
        let p = w.pressure(det(dfc));
        assert!((ub.stress[2] - u.stress[2]).abs() < 1e-14, "{} vs {}", ub.stress[2], u.stress[2]);
        let mean = (ub.stress[0] + ub.stress[1] + ub.stress[3]) / 3.0;
        assert!((mean + p).abs() < 1e-9 * p.abs() && p > 0.0, "{:?} p = {p}", ub.stress);
        // The estimates see the bulk modulus as the constrained modulus, no shear stiffness.
        assert_eq!(model.elastic().constrained_modulus(), 2e9);
        assert_eq!(model.elastic().shear_modulus(), 0.0);
        // A bulk viscosity adds ζ tr d = ζ ln(det ΔF)/Δt to the mean stress, nothing to the shear.
        let zeta = NewtonianFluidLaw { bulk_viscosity: 300.0, ..w };
        let squeeze = plane([[1.0 - 2e-4, 0.0], [0.0, 1.0]]);
        let (plain, damped) = (w.stress_after(squeeze, squeeze, dt), zeta.stress_after(squeeze, squeeze, dt));
        let expected = 300.0 * (1.0f64 - 2e-4).ln() / dt;
        for c in [0, 1, 3] {
            assert!((damped[c] - plain[c] - expected).abs() < 1e-9 * expected.abs(), "{damped:?} vs {plain:?}");
        }
        assert_eq!(damped[2], plain[2]);
        // Inadmissible: det F ≤ 0 gives NaN.
        let bad = model.finite(&df, &plane([[-1.0, 0.0], [0.0, 1.0]]), &[0.0; NS], 0.0, dt).unwrap();
        assert!(bad.stress.iter().all(|v| v.is_nan()));
    }

    /// The three models under a general three-dimensional deformation (no plane of symmetry):
    /// objective under a rotation about a tilted axis, Hencky–J2 on its softened yield surface with
    /// det b^e = J², its elastic state recovered from σ and J, and the fluid's rate of a rigid spin
    /// zero.
    #[test]
    fn the_models_are_objective_and_consistent_in_three_dimensions() {
        let f = [[1.05, 0.12, -0.04], [0.03, 0.96, 0.08], [-0.06, 0.02, 1.02]];
        let nh = NeoHookeanLaw::new(70.0, 0.45);
        let s = nh.stress(f).unwrap();
        assert!(s[4].abs() > 1e-3 && s[5].abs() > 1e-3, "{s:?}");
        for a in [0.4, -1.9] {
            let r = tilt(a);
            assert!(close(&nh.stress(mul(r, f)).unwrap(), &rotate(r, s), 1e-13));
        }
        // Hencky–J2 along a 3D path with out-of-plane shears.
        let m = HenckyJ2Law::new(25e6, 0.3, 40e3, 2.45e3, 5.0);
        let (mut state, mut j, mut plastic) = (PlasticState::default(), 1.0, 0);
        for k in 0..80 {
            let df = [[1.0 + 2e-4, 1e-3, 5e-4], [2e-4, 1.0 - 1e-4, 2e-3 * (k as f64 * 0.1).cos()], [-1e-3, 4e-4, 1.0]];
            j *= det(df);
            let u = m.step(df, &state, j).unwrap();
            let (c, _) = m.cohesion_at(u.state.eps);
            let q = q_of(u.stress) * j;
            if u.plastic {
                plastic += 1;
                assert!((q - 3f64.sqrt() * c).abs() <= 1e-9 * q, "step {k}: q {q} vs √3 c {}", 3f64.sqrt() * c);
            }
            let be = principal::tensor(&u.state.be);
            assert!((det(be) - j * j).abs() <= 1e-12, "step {k}: det b^e {} vs J² {}", det(be), j * j);
            let back = m.elastic_left_cauchy_green(&u.stress, j);
            assert!(close(&back, &u.state.be, 1e-12), "step {k}");
            // Objective: the same step turned by R gives R σ Rᵀ and R b^e Rᵀ from R b^e_n Rᵀ.
            let r = tilt(0.7);
            let turned_state = PlasticState { be: rotate(r, state.be), eps: state.eps };
            let turned = m.step(mul(mul(r, df), transpose(r)), &turned_state, j).unwrap();
            assert!(close(&turned.stress, &rotate(r, u.stress), 1e-11), "step {k}");
            state = u.state;
        }
        assert!(plastic > 30, "{plastic} plastic steps");
        // The fluid: a rigid spin about a tilted axis has no rate of deformation; a shear in yz
        // gives μ_v γ̇ in σ_yz.
        let spin = rate_of_deformation(tilt(0.3), 1e-3);
        assert!(spin.iter().flatten().all(|v| v.abs() < 1e-9), "{spin:?}");
        let w = NewtonianFluidLaw::new(2e9, 0.5, 0.0);
        let dt = 1e-3;
        let shear = [[1.0, 0.0, 0.0], [0.0, 1.0, 10.0 * dt], [0.0, 0.0, 1.0]];
        let st = w.stress_after(shear, shear, dt);
        assert!((st[4] - 5.0).abs() < 1e-2, "{st:?}");
        assert!(st[2].abs() < 1e-9 && st[5].abs() < 1e-9, "{st:?}");
        // A volume change is not a rate of deformation of the viscous stress (ζ takes it): a 1 %
        // growth with a small yz shear leaves the normal rates at second order.
        let grow = [[1.01, 0.0, 0.0], [0.0, 1.01, 1e-3], [0.0, 0.0, 1.01]];
        let d = rate_of_deformation(grow, dt);
        assert!((0..3).all(|k| d[k][k].abs() < 1e-3), "{d:?}");
        assert!((d[1][2] - 0.5 / 1.01).abs() < 1e-3, "{d:?}");
    }

    /// The consistent tangent ∂σ/∂ΔF of the finite-strain laws against central differences of
    /// their stress, at fixed F_n and σ_n: neo-Hookean in three dimensions and in plane strain,
    /// Hencky–J2 elastic, plastic with softening, and plastic from a state with history.
    #[test]
    fn the_finite_strain_tangents_match_central_differences() {
        let neo = Constitutive::NeoHookean(NeoHookeanLaw::new(2e7, 0.45));
        let hencky = Constitutive::HenckyJ2(HenckyJ2Law::new(25e6, 0.3, 40e3, 2.45e3, 5.0));
        let f_n = mul(tilt(0.4), [[1.05, 0.02, -0.03], [0.01, 0.96, 0.04], [-0.02, 0.03, 1.02]]);
        let f_plane = plane([[1.04, 0.05], [-0.03, 0.97]]);
        // A Hencky–J2 stress with plastic history: a plastic shearing step from rest.
        let first = HenckyJ2Law::new(25e6, 0.3, 40e3, 2.45e3, 5.0)
            .step(plane([[1.0, 0.008], [0.0, 1.0]]), &PlasticState::default(), 1.0)
            .unwrap();
        assert!(first.plastic);
        let small = [[1.0004, 0.0003, -0.0002], [0.0001, 0.9997, 0.0005], [0.0002, -0.0003, 1.0001]];
        let shear = [[1.0, 0.006, 0.001], [0.0, 1.0, 0.002], [0.0, 0.0, 1.0]];
        let cases: [(&str, Constitutive, M3, M3, Stress, f64, bool); 6] = [
            (
                "neo-Hookean 3D",
                neo,
                mul(tilt(-0.2), [[1.1, 0.05, 0.0], [0.02, 0.9, 0.03], [0.0, -0.04, 1.05]]),
                f_n,
                [0.0; NS],
                0.0,
                false,
            ),
            ("neo-Hookean plane", neo, plane([[1.08, -0.04], [0.06, 0.93]]), f_plane, [0.0; NS], 0.0, false),
            ("Hencky-J2 elastic", hencky, small, I3, [0.0; NS], 0.0, false),
            ("Hencky-J2 plastic", hencky, shear, I3, [0.0; NS], 0.0, true),
            ("Hencky-J2 history", hencky, mul(rot(0.1), shear), I3, first.stress, first.state.eps, true),
            ("Hencky-J2 plane", hencky, plane([[1.0, 0.006], [0.001, 1.0]]), I3, first.stress, first.state.eps, true),
        ];
        for (name, law, df, f_n, stress, eps, plastic) in cases {
            let sigma = |df: M3| law.finite(&df, &mul(df, f_n), &stress, eps, 1e-3).unwrap();
            let t = law.finite_tangent(&df, &mul(df, f_n), &stress, eps, 1e-3).unwrap();
            let upd = sigma(df);
            assert_eq!(upd.region != Region::Elastic, plastic, "{name}: {:?}", upd.region);
            let scale = upd.stress.iter().chain(&law.elastic().d[0]).fold(0.0f64, |m, v| m.max(v.abs()));
            let h = 1e-6;
            for a in 0..3 {
                for b in 0..3 {
                    let (mut up, mut down) = (df, df);
                    up[a][b] += h;
                    down[a][b] -= h;
                    let (sp, sm) = (sigma(up).stress, sigma(down).stress);
                    for r in 0..NS {
                        let fd = (sp[r] - sm[r]) / (2.0 * h);
                        assert!(
                            (t[r][a][b] - fd).abs() <= 1e-6 * scale,
                            "{name}: dσ_{r}/dΔF_{a}{b} = {:e} against {fd:e}",
                            t[r][a][b]
                        );
                    }
                }
            }
        }
    }
}
