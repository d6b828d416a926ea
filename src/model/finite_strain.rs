//! Finite-strain materials of [002] (`../shared/seeds-001-002.md` Part C4; the paper omits their
//! forms, so these are the standard ones it names): compressible neo-Hookean, Hencky elasticity
//! with J2 plasticity and exponential softening, and a Newtonian fluid. Plane strain: the
//! deformation is in-plane with F_zz = 1; stresses are 4-vectors [xx, yy, xy, zz] (Cauchy,
//! tension positive) as in [`super::soil`].
//!
//! They are total (hyperelastic) or multiplicative forms driven by the deformation gradient (with
//! [002]'s F̄, by F̄; [`super::fbar`]); they are used by the explicit integrator (issue «Seed
//! [002]»), which needs no tangent. Each is objective by construction: the neo-Hookean and Hencky
//! stresses are isotropic functions of b = F Fᵀ (or b^e), so a rotation R of the deformation turns
//! the stress into R σ Rᵀ.

use super::soil::principal::Principal;

/// An in-plane 2 × 2 matrix.
pub type M2 = [[f64; 2]; 2];

/// det of an in-plane matrix (the volume ratio in plane strain, F_zz = 1).
pub fn det(f: M2) -> f64 {
    f[0][0] * f[1][1] - f[0][1] * f[1][0]
}

/// A Aᵀ-like product F S Fᵀ for a symmetric S = [xx, yy, xy]: [xx, yy, xy] of the result.
fn push(f: M2, s: [f64; 3]) -> [f64; 3] {
    let sm = [[s[0], s[2]], [s[2], s[1]]];
    let mut fs = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            fs[i][j] = f[i][0] * sm[0][j] + f[i][1] * sm[1][j];
        }
    }
    let r = |i: usize, j: usize| fs[i][0] * f[j][0] + fs[i][1] * f[j][1];
    [r(0, 0), r(1, 1), r(0, 1)]
}

/// Compressible neo-Hookean elasticity (Cook's membrane, [002] §4.1): Kirchhoff stress
/// τ = μ(b − 1) + λ ln J 1 with b = F Fᵀ, σ = τ/J (Bonet & Wood 2008, Eq. 6.28). Its small-strain
/// limit is linear elasticity with the same λ, μ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NeoHookean {
    /// Shear modulus μ [Pa].
    pub shear: f64,
    /// Lamé's λ [Pa].
    pub lame: f64,
}

impl NeoHookean {
    /// From Young's modulus [Pa] and Poisson's ratio.
    pub fn new(e: f64, nu: f64) -> NeoHookean {
        NeoHookean { shear: e / (2.0 * (1.0 + nu)), lame: e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)) }
    }

    /// The Cauchy stress of the in-plane deformation gradient `f` (F_zz = 1). `None` when J ≤ 0.
    pub fn stress(&self, f: M2) -> Option<[f64; 4]> {
        let j = det(f);
        if j <= 0.0 {
            return None;
        }
        let b = push(f, [1.0, 1.0, 0.0]);
        let vol = self.lame * j.ln();
        let (mu, inv) = (self.shear, 1.0 / j);
        Some([(mu * (b[0] - 1.0) + vol) * inv, (mu * (b[1] - 1.0) + vol) * inv, mu * b[2] * inv, vol * inv])
    }
}

/// The state of a Hencky–J2 point: the elastic left Cauchy–Green tensor b^e ([xx, yy, xy, zz];
/// 1 at rest) and the accumulated equivalent plastic strain ε̄ = Σ √(2/3) |Δε^p|.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlasticState {
    /// b^e as [xx, yy, xy, zz].
    pub be: [f64; 4],
    /// ε̄ [-].
    pub eps: f64,
}

impl Default for PlasticState {
    fn default() -> Self {
        PlasticState { be: [1.0, 1.0, 0.0, 1.0], eps: 0.0 }
    }
}

/// Hencky elasticity with J2 (von Mises) plasticity and exponential softening (the footing and
/// the landslide of [002] §4.2, §4.4): multiplicative plasticity in principal logarithmic strains
/// (Simo 1992; de Souza Neto, Perić & Owen 2008, §14.5). Per step: b^e_trial = ΔF b^e_n ΔFᵀ,
/// ε^e = ½ ln b^e (principal), τ = K tr ε^e 1 + 2μ dev ε^e, radial return of dev τ onto
/// q = √3 c(ε̄) with c(ε̄) = c_r + (c_p − c_r) exp(−η ε̄) ([002] L357, κ read as the strength), then
/// b^e = exp(2ε^e) and σ = τ/J. c is the plane-strain shear strength (s_u: under plane strain and
/// incompressible flow q = √3 τ_max).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HenckyJ2 {
    /// Shear modulus μ [Pa].
    pub shear: f64,
    /// Bulk modulus K [Pa].
    pub bulk: f64,
    /// Peak shear strength c_p [Pa].
    pub cohesion: f64,
    /// Residual shear strength c_r [Pa] (c_p for no softening).
    pub residual_cohesion: f64,
    /// Softening rate η [-].
    pub softening_rate: f64,
}

/// The result of a Hencky–J2 update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HenckyUpdate {
    /// Cauchy stress [xx, yy, xy, zz] [Pa].
    pub stress: [f64; 4],
    /// The state after the step.
    pub state: PlasticState,
    /// Whether the step flowed plastically.
    pub plastic: bool,
}

impl HenckyJ2 {
    /// From Young's modulus, Poisson's ratio and the strengths.
    pub fn new(e: f64, nu: f64, cohesion: f64, residual_cohesion: f64, softening_rate: f64) -> HenckyJ2 {
        let shear = e / (2.0 * (1.0 + nu));
        HenckyJ2 { shear, bulk: e / (3.0 * (1.0 - 2.0 * nu)), cohesion, residual_cohesion, softening_rate }
    }

    /// The shear strength at ε̄ and its slope dc/dε̄.
    pub fn cohesion_at(&self, eps: f64) -> (f64, f64) {
        let e = (-self.softening_rate * eps).exp();
        let drop = self.cohesion - self.residual_cohesion;
        (self.residual_cohesion + drop * e, -self.softening_rate * drop * e)
    }

    /// Whether the return is unique: the softening never outpaces the elastic unloading,
    /// 3μ > √3 η (c_p − c_r) (otherwise the return equation has several roots).
    pub fn well_posed(&self) -> bool {
        3.0 * self.shear > 3f64.sqrt() * self.softening_rate * (self.cohesion - self.residual_cohesion)
    }

    /// The elastic left Cauchy–Green tensor b^e [xx, yy, xy, zz] of a point with Cauchy stress
    /// `stress` at volume ratio `j` (with F̄, J̄): τ = J σ determines the elastic logarithmic strain,
    /// ε^e = dev τ/(2μ) + tr τ/(9K) 1 (the inverse of Hencky's law, in τ's principal frame, which is
    /// b^e's), and b^e = exp(2ε^e). The inverse of [`HenckyJ2::update`]'s stress to round-off, so
    /// that a point's stress and J are its whole elastic state.
    pub fn elastic_left_cauchy_green(&self, stress: &[f64; 4], j: f64) -> [f64; 4] {
        let frame = Principal::of(stress);
        let tau = frame.values.map(|v| v * j);
        let mean = (tau[0] + tau[1] + tau[2]) / 3.0;
        let (mu2, k3) = (2.0 * self.shear, 3.0 * self.bulk);
        frame.compose(&tau.map(|t| (2.0 * ((t - mean) / mu2 + mean / k3)).exp()))
    }

    /// One step: the increment `df` of the deformation gradient (in-plane, ΔF_zz = 1) from
    /// `state`, with `j` the volume ratio det F of the point after the step (with F̄, J̄) by which
    /// the Kirchhoff stress is divided. `None` when b^e or J is not positive definite.
    pub fn update(&self, df: M2, state: &PlasticState, j: f64) -> Option<HenckyUpdate> {
        if j <= 0.0 {
            return None;
        }
        let [bxx, byy, bxy, bzz] = state.be;
        let trial = push(df, [bxx, byy, bxy]);
        // b^e's principal values (A ≥ B in plane, Z) and frame.
        let frame = Principal::of(&[trial[0], trial[1], trial[2], bzz]);
        let lam = frame.values;
        if lam[1] <= 0.0 || bzz <= 0.0 {
            return None;
        }
        // Principal logarithmic elastic strains: the two in-plane ones and zz.
        let eps = [0.5 * lam[0].ln(), 0.5 * lam[1].ln(), 0.5 * lam[2].ln()];
        let tr = eps[0] + eps[1] + eps[2];
        let dev = [eps[0] - tr / 3.0, eps[1] - tr / 3.0, eps[2] - tr / 3.0];
        let mu2 = 2.0 * self.shear;
        let s_trial = [mu2 * dev[0], mu2 * dev[1], mu2 * dev[2]];
        let q_trial = (1.5 * (s_trial[0].powi(2) + s_trial[1].powi(2) + s_trial[2].powi(2))).sqrt();
        let r3 = 3f64.sqrt();
        let (c_n, _) = self.cohesion_at(state.eps);
        let mut out_eps = state.eps;
        let mut factor = 1.0;
        let plastic = q_trial - r3 * c_n > 1e-12 * (q_trial + c_n);
        if plastic {
            // g(Δ) = q_trial − 3μΔ − √3 c(ε̄_n + Δ) = 0 on [0, q_trial/3μ], where g(0) > 0 and the
            // upper end gives −√3 c < 0: Newton kept inside the bracket, bisection otherwise.
            let g3 = 3.0 * self.shear;
            let g = |d: f64| {
                let (c, dc) = self.cohesion_at(state.eps + d);
                (q_trial - g3 * d - r3 * c, -g3 - r3 * dc)
            };
            let (mut lo, mut hi) = (0.0, q_trial / g3);
            let mut d = (q_trial - r3 * c_n) / g3;
            for _ in 0..100 {
                let (r, dr) = g(d);
                if r > 0.0 {
                    lo = d;
                } else {
                    hi = d;
                }
                if r.abs() <= 1e-14 * q_trial || hi - lo <= 1e-16 * q_trial / g3 {
                    break;
                }
                let next = d - r / dr;
                d = if dr < 0.0 && next > lo && next < hi { next } else { 0.5 * (lo + hi) };
            }
            factor = 1.0 - g3 * d / q_trial;
            out_eps += d;
        }
        // The returned deviator is the trial one scaled (radial return); the volume is elastic.
        let e = [factor * dev[0] + tr / 3.0, factor * dev[1] + tr / 3.0, factor * dev[2] + tr / 3.0];
        let tau = frame.compose(&std::array::from_fn(|k| (self.bulk * tr + factor * s_trial[k]) / j));
        let be = frame.compose(&std::array::from_fn(|k| (2.0 * e[k]).exp()));
        Some(HenckyUpdate { stress: tau, state: PlasticState { be, eps: out_eps }, plastic })
    }
}

/// A weakly compressible Newtonian fluid (the dam break, [002] §4.3): σ = −p 1 + 2μ_v dev d + ζ tr d 1
/// with the pressure of the equation of state p = K max(1 − J, 0) (water takes no tension: a
/// stretched point is separating, not pulling) and the rate of deformation d = sym L
/// (seeds-001-002.md Part C4; for the |J − 1| ~ 1e-5 of water any equation of state is the same).
/// The bulk viscosity ζ is the explicit codes' damping of volumetric ringing (Abaqus/Explicit's
/// linear bulk viscosity ζ = b₁ ρ c h, b₁ = 0.06 by default; Stokes' hypothesis gives water none).
/// With F̄, the pressure sees J̄ and the bulk viscosity the rate of J̄.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonianFluid {
    /// Bulk modulus K [Pa].
    pub bulk: f64,
    /// Dynamic viscosity μ_v [Pa s].
    pub viscosity: f64,
    /// Bulk viscosity ζ [Pa s].
    pub bulk_viscosity: f64,
}

impl NewtonianFluid {
    /// The Cauchy stress at volume ratio `j` and in-plane velocity gradient `l` [1/s].
    pub fn stress(&self, j: f64, l: M2) -> [f64; 4] {
        let p = self.bulk * (1.0 - j).max(0.0);
        let d = [l[0][0], l[1][1], 0.5 * (l[0][1] + l[1][0])];
        let m = (d[0] + d[1]) / 3.0;
        let mu2 = 2.0 * self.viscosity;
        [-p + mu2 * (d[0] - m), -p + mu2 * (d[1] - m), mu2 * d[2], -p - mu2 * m]
    }

    /// The fluid's pressure at volume ratio `j` [Pa].
    pub fn pressure(&self, j: f64) -> f64 {
        self.bulk * (1.0 - j)
    }

    /// The stress after a step of deformation gradient `df` over `dt` seconds that leaves the
    /// fluid at the in-plane total deformation `f`: the pressure of J = det f and the viscous
    /// stress of the step's rate of deformation ([`rate_of_deformation`]).
    pub fn stress_after(&self, df: M2, f: M2, dt: f64) -> [f64; 4] {
        let mut s = self.stress(det(f), rate_of_deformation(df, dt));
        // ζ tr d with tr d = ln(det ΔF)/Δt (with F̄, det ΔF̄ = J̄_{n+1}/J̄_n).
        let dj = det(df);
        if dt > 0.0 && dj > 0.0 && self.bulk_viscosity > 0.0 {
            let q = self.bulk_viscosity * dj.ln() / dt;
            for c in [0, 1, 3] {
                s[c] += q;
            }
        }
        s
    }
}

/// The rate of deformation of a step of deformation gradient ΔF over Δt [1/s]:
/// d = (V_iso − 1)/Δt, with V_iso the left stretch of the isochoric part ΔF/√det ΔF (polar
/// decomposition ΔF = V R). It is objective (a rigid rotation of the step gives d = 0 whatever its
/// angle), it is the same for ΔF and for F̄'s c ΔF (only the pressure sees J̄), and it is sym L + O(Δt)
/// for a step of velocity gradient L. Zero when `dt` is not positive or ΔF is inadmissible
/// (det ΔF ≤ 0, which the pressure's J then reports).
pub fn rate_of_deformation(df: M2, dt: f64) -> M2 {
    let j = det(df);
    if dt <= 0.0 || j.is_nan() || j <= 0.0 {
        return [[0.0; 2]; 2];
    }
    let s = j.sqrt();
    // V = sqrt(ΔF ΔFᵀ) is the right stretch of ΔFᵀ.
    let v = super::shape::right_stretch([[df[0][0] / s, df[1][0] / s], [df[0][1] / s, df[1][1] / s]]);
    [[(v[0][0] - 1.0) / dt, v[0][1] / dt], [v[1][0] / dt, (v[1][1] - 1.0) / dt]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::soil::{Constitutive, LinearElastic, VonMises};

    fn rot(a: f64) -> M2 {
        [[a.cos(), -a.sin()], [a.sin(), a.cos()]]
    }

    fn mul(a: M2, b: M2) -> M2 {
        let mut c = [[0.0; 2]; 2];
        for i in 0..2 {
            for j in 0..2 {
                c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j];
            }
        }
        c
    }

    /// R σ Rᵀ of a stress 4-vector (zz unchanged).
    fn rotate(r: M2, s: [f64; 4]) -> [f64; 4] {
        let t = push(r, [s[0], s[1], s[2]]);
        [t[0], t[1], t[2], s[3]]
    }

    fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
        let scale = a.iter().chain(b).fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol * scale)
    }

    fn q_of(s: [f64; 4]) -> f64 {
        let p = (s[0] + s[1] + s[3]) / 3.0;
        let d = [s[0] - p, s[1] - p, s[3] - p];
        (1.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 2.0 * s[2] * s[2])).sqrt()
    }

    #[test]
    fn neo_hooke_is_objective_and_linear_elastic_for_small_strains() {
        let m = NeoHookean::new(70.0, 0.499);
        let f = [[1.12, 0.31], [-0.05, 0.93]];
        let s = m.stress(f).unwrap();
        for a in [0.3, 1.7, -2.2] {
            let r = rot(a);
            let sr = m.stress(mul(r, f)).unwrap();
            assert!(close(&sr, &rotate(r, s), 1e-13), "{sr:?} vs {:?}", rotate(r, s));
        }
        // At rest: no stress. Small strains: σ = D ε to O(ε²).
        assert!(m.stress([[1.0, 0.0], [0.0, 1.0]]).unwrap().iter().all(|v| v.abs() < 1e-15));
        let e = 1e-7;
        let f = [[1.0 + 2.0 * e, 0.5 * e], [0.5 * e, 1.0 - e]];
        let lin = LinearElastic::new(70.0, 0.499).trial(&[0.0; 4], &[2.0 * e, -e, e, 0.0]);
        assert!(close(&m.stress(f).unwrap(), &lin, 1e-5), "{:?} vs {lin:?}", m.stress(f));
        assert!(m.stress([[0.5, 0.0], [0.0, -0.1]]).is_none());
    }

    #[test]
    fn hencky_j2_is_objective_and_leaves_a_rigidly_rotated_stress_unrotated_in_the_material_frame() {
        let m = HenckyJ2::new(25e6, 0.3, 40e3, 2.45e3, 5.0);
        // A state with stress and plastic history from a plastic shearing step.
        let first = m.update([[1.0, 0.01], [0.0, 1.0]], &PlasticState::default(), 1.0).unwrap();
        assert!(first.plastic);
        let df = [[1.003, 0.004], [-0.002, 0.999]];
        let j = det(df);
        let base = m.update(df, &first.state, j).unwrap();
        for a in [0.4, -1.3, 3.0] {
            let r = rot(a);
            let turned = m.update(mul(r, df), &first.state, j).unwrap();
            assert!(close(&turned.stress, &rotate(r, base.stress), 1e-12), "{a}");
            assert!((turned.state.eps - base.state.eps).abs() <= 1e-14);
            let be = rotate(r, base.state.be);
            assert!(close(&turned.state.be, &be, 1e-12));
            // A rigid rotation alone: the stress turns with the material, Rᵀ σ R = σ_n.
            let spun = m.update(r, &first.state, 1.0).unwrap();
            assert!(!spun.plastic);
            assert!(close(&rotate(rot(-a), spun.stress), &first.stress, 1e-12), "{a}");
            assert_eq!(spun.state.eps, first.state.eps);
        }
    }

    #[test]
    fn hencky_j2_returns_onto_the_softened_yield_surface() {
        let m = HenckyJ2::new(25e6, 0.45, 40.82e3, 2.45e3, 5.0);
        assert!(m.well_posed());
        let mut state = PlasticState::default();
        let mut j = 1.0;
        let mut plastic_steps = 0;
        for k in 0..200 {
            let df = [[1.0 + 2e-4, 3e-3], [1e-3, 1.0 - 1.5e-4]];
            j *= det(df);
            let u = m.update(df, &state, j).unwrap();
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
        let m = HenckyJ2::new(e, nu, c, c, 0.0);
        let el = LinearElastic::new(e, nu);
        let vm = Constitutive::VonMises(
            el,
            VonMises { shear: el.shear_modulus(), cohesion: c, residual_cohesion: c, softening_modulus: 0.0 },
        );
        let (mut state, mut small, mut eps_small, mut j) = (PlasticState::default(), [0.0; 4], 0.0, 1.0);
        for _ in 0..20 {
            let (a, g) = (5e-5, 1e-4);
            let df = [[1.0 + a, g], [0.0, 1.0]];
            j *= det(df);
            let u = m.update(df, &state, j).unwrap();
            state = u.state;
            let up = vm.update(&small, eps_small, &[a, 0.0, g, 0.0]);
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
        let m = HenckyJ2::new(25e6, 0.45, 40.82e3, 2.45e3, 5.0);
        let (mut state, mut j) = (PlasticState::default(), 1.0);
        let mut plastic = 0;
        for k in 0..60 {
            let df = [[1.0 + 4e-4 * (k as f64 * 0.3).cos(), 2e-3], [-1e-3, 1.0 - 1e-4]];
            j *= det(df);
            let u = m.update(df, &state, j).unwrap();
            plastic += usize::from(u.plastic);
            let be = m.elastic_left_cauchy_green(&u.stress, j);
            assert!(close(&be, &u.state.be, 1e-13), "step {k}: {be:?} vs {:?}", u.state.be);
            state = u.state;
        }
        assert!(plastic > 20 && state.eps > 0.0);
        // And the path run through `Constitutive::finite`, which stores only σ, F and ε̄ (F̄ = F
        // here), is the path run with the stored b^e.
        let model = Constitutive::HenckyJ2(LinearElastic::new(25e6, 0.45), m);
        let (mut stress, mut f, mut eps) = ([0.0; 4], [[1.0, 0.0], [0.0, 1.0]], 0.0);
        let (mut state, mut j) = (PlasticState::default(), 1.0);
        for k in 0..60 {
            let df = [[1.0 - 3e-4, 1.5e-3 * (k as f64 * 0.2).sin()], [2e-3, 1.0 + 1e-4]];
            f = mul(df, f);
            j *= det(df);
            let u = model.finite(&df, &f, &stress, eps, 1e-3).unwrap();
            let direct = m.update(df, &state, j).unwrap();
            assert!(close(&u.stress, &direct.stress, 1e-11), "step {k}: {:?} vs {:?}", u.stress, direct.stress);
            assert!((u.eps_pd - direct.state.eps).abs() <= 1e-12 * direct.state.eps.max(1e-300) + 1e-18);
            (stress, eps, state) = (u.stress, u.eps_pd, direct.state);
        }
        assert!(eps > 0.0);
        // With F̄: the kernel passes ΔF̄ = c ΔF and F̄_{n+1} = s ΔF F_n with c = (J̄^{n+1}/(J̄^n ΔJ))^½
        // and s = (J̄^{n+1}/(J^n ΔJ))^½, and the stored σ_n = τ(b^e_n)/J̄^n; `finite` must recover
        // J̄^n = det F̄_{n+1}/det ΔF̄ and give the direct update with ΔF̄ divided by J̄^{n+1}.
        let f_n = [[1.02, 0.03], [-0.01, 0.97]];
        let (jbar_n, jbar_new) = (0.9981, 0.9975);
        let pre = m.update([[1.0, 0.004], [0.002, 1.0]], &PlasticState::default(), jbar_n).unwrap();
        let df = [[1.001, 0.0015], [0.0005, 0.9985]];
        let (j_n, dj) = (det(f_n), det(df));
        let c = (jbar_new / (jbar_n * dj)).sqrt();
        let s = (jbar_new / (j_n * dj)).sqrt();
        assert!((c - s).abs() > 1e-4, "c and s must differ here: {c} {s}");
        let dfbar = df.map(|r| r.map(|v| v * c));
        let fbar_new = mul(df, f_n).map(|r| r.map(|v| v * s));
        let u = model.finite(&dfbar, &fbar_new, &pre.stress, pre.state.eps, 1e-3).unwrap();
        let direct = m.update(dfbar, &pre.state, jbar_new).unwrap();
        assert!(close(&u.stress, &direct.stress, 1e-11), "{:?} vs {:?}", u.stress, direct.stress);
        // The incremental models have no finite-strain stress.
        assert!(Constitutive::LinearElastic(LinearElastic::new(1.0, 0.3)).finite(&f, &f, &stress, 0.0, 1e-3).is_none());
    }

    #[test]
    fn the_newtonian_fluid_has_its_pressure_and_viscous_shear() {
        let w = NewtonianFluid { bulk: 2e9, viscosity: 1e-3, bulk_viscosity: 0.0 };
        let s = w.stress(1.0 - 1e-5, [[0.0, 0.0], [0.0, 0.0]]);
        assert!(close(&s, &[-2e4, -2e4, 0.0, -2e4], 1e-9), "{s:?}");
        // Simple shear v_x = γ̇ y: σ_xy = μ γ̇, no normal stress; a rigid spin carries no stress.
        let s = w.stress(1.0, [[0.0, 10.0], [0.0, 0.0]]);
        assert!(close(&s, &[0.0, 0.0, 1e-2, 0.0], 1e-12), "{s:?}");
        let s = w.stress(1.0, [[0.0, 3.0], [-3.0, 0.0]]);
        assert!(s.iter().all(|v| v.abs() < 1e-15), "{s:?}");
        // Objective: σ(R L Rᵀ) = R σ(L) Rᵀ for the symmetric part.
        let l = [[0.2, 0.5], [0.1, -0.7]];
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
        use crate::model::soil::Constitutive;
        let w = NewtonianFluid { bulk: 2e9, viscosity: 0.5, bulk_viscosity: 0.0 };
        let model = Constitutive::NewtonianFluid(LinearElastic::from_bulk_shear(2e9, 0.0), w);
        let dt = 1e-3;
        let f = [[0.99999, 0.0], [0.0, 1.0]];
        let spin = model.finite(&rot(0.7), &f, &[0.0; 4], 0.0, dt).unwrap();
        assert!(close(&spin.stress, &[-2e4, -2e4, 0.0, -2e4], 1e-9), "{:?}", spin.stress);
        // Simple shear at γ̇ = 10/s over the step: σ_xy = μ_v γ̇ to first order in γ̇ Δt.
        let df = [[1.0, 10.0 * dt], [0.0, 1.0]];
        let u = model.finite(&df, &df, &[0.0; 4], 0.0, dt).unwrap();
        assert!((u.stress[2] - 0.5 * 10.0).abs() < 1e-3 * 5.0, "{:?}", u.stress);
        // Normal viscous stresses are of the next order, γ̇Δt σ_xy.
        assert!(u.stress.iter().take(2).all(|v| v.abs() < 10.0 * dt * 5.0), "{:?}", u.stress);
        // F̄: c ΔF changes the pressure (through J̄ = det F̄), not the viscous part.
        let c = 1.0 - 3e-6;
        let dfc = df.map(|r| r.map(|v| v * c));
        let ub = model.finite(&dfc, &dfc, &[0.0; 4], 0.0, dt).unwrap();
        let p = w.pressure(det(dfc));
        assert!((ub.stress[2] - u.stress[2]).abs() < 1e-14, "{} vs {}", ub.stress[2], u.stress[2]);
        let mean = (ub.stress[0] + ub.stress[1] + ub.stress[3]) / 3.0;
        assert!((mean + p).abs() < 1e-9 * p.abs() && p > 0.0, "{:?} p = {p}", ub.stress);
        // The estimates see the bulk modulus as the constrained modulus, no shear stiffness.
        assert_eq!(model.elastic().constrained_modulus(), 2e9);
        assert_eq!(model.elastic().shear_modulus(), 0.0);
        // A bulk viscosity adds ζ tr d = ζ ln(det ΔF)/Δt to the mean stress, nothing to the shear.
        let zeta = NewtonianFluid { bulk_viscosity: 300.0, ..w };
        let squeeze = [[1.0 - 2e-4, 0.0], [0.0, 1.0]];
        let (plain, damped) = (w.stress_after(squeeze, squeeze, dt), zeta.stress_after(squeeze, squeeze, dt));
        let expected = 300.0 * (1.0f64 - 2e-4).ln() / dt;
        for c in [0, 1, 3] {
            assert!((damped[c] - plain[c] - expected).abs() < 1e-9 * expected.abs(), "{damped:?} vs {plain:?}");
        }
        assert_eq!(damped[2], plain[2]);
        // Inadmissible: det F ≤ 0 gives NaN.
        let bad = model.finite(&df, &[[-1.0, 0.0], [0.0, 1.0]], &[0.0; 4], 0.0, dt).unwrap();
        assert!(bad.stress.iter().all(|v| v.is_nan()));
    }
}
