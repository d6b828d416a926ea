//! Mohr–Coulomb with cohesion softening, evolving dilatancy and an optional tension cut-off,
//! `type = "mohr_coulomb"`: its parameters ([`MohrCoulomb`]) and its law ([`MohrCoulombLaw`]), the
//! implicit return mapping in principal stresses and its consistent tangent.
//!
//! Tension is positive; with sorted principal stresses σ₁ ≥ σ₂ ≥ σ₃ the yield function and the
//! plastic potential of the main plane are ([000] §4; de Souza Neto, Perić & Owen 2008, Eqs. 8.72
//! and 8.78)
//!   f = (σ₁ − σ₃) + (σ₁ + σ₃) sin φ − 2 c(ε̄) cos φ,   g = (σ₁ − σ₃) + (σ₁ + σ₃) sin ψ,
//! φ = 0 giving Tresca (c the undrained strength). The cohesion falls linearly from c_p to c_r as the
//! accumulated deviatoric plastic strain ε̄ = Σ sqrt(2/3 Δe_p : Δe_p) reaches ε_r ([000] §4.2.1); the
//! dilation angle decays as ψ = ψ_crit + (ψ_ini − ψ_crit) exp(−η ε̄) ([000] Eq. 17, written with
//! η ≥ 0 for a decay; Table 3's η = −25 belongs to the sign convention e^{ηε̄}). An optional
//! tension cut-off adds the Rankine planes σ_i ≤ t with associated flow.
//!
//! Integration (backward Euler): σ = σ_trial − D Σ_j Δγ_j n_j over the active planes j, with the
//! cohesion at ε̄_{n+1} (implicit) and ψ at ε̄_n (explicit: the flow direction is fixed within a
//! step, which keeps the return well-posed; the tangent is the exact derivative of this algorithm).
//! The active set is found as in de Souza Neto §8.2: the main plane; then the edges σ₁ = σ₂ and
//! σ₂ = σ₃ (two planes); with a cut-off, the tension planes and their corners with the main plane;
//! the first candidate whose multipliers are non-negative, whose stress satisfies every yield plane
//! and keeps the principal order is taken. Otherwise the stress returns to the apex of the cone,
//! p = c cot φ, with ε̄ grown by sqrt(2/3)|dev σ_trial|/(2G) (the deviatoric plastic strain that
//! removes the whole trial deviator). Each candidate is a small Newton iteration in the multipliers
//! (the cohesion's softening makes it nonlinear). The principal-space tangent comes from the
//! implicit function theorem on that local system: dσ/dσ_trial = I + D N J⁻¹ Aᵀ with A, N the
//! yield and flow normals of the active planes and J the local Jacobian.

use super::elasticity::check_elastic;
use super::{
    isotropic_return, reduced_strength, LinearElastic, PrincipalReturn, Region, ReturnResult, SoilLaw, SoilParameters,
    Stress, StressUpdate,
};
use crate::algebra::linalg::solve;
use crate::check::{at, in_closed_open, non_negative, positive, strength, Checked};
use serde::{Deserialize, Serialize};

/// The parameters of `type = "mohr_coulomb"`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MohrCoulomb {
    /// Young's modulus E [Pa], in (0, 1e13].
    pub young_modulus: f64,
    /// Poisson's ratio ν [-], in (−1, 0.5).
    pub poisson_ratio: f64,
    /// Friction angle φ [degrees], in [0, 90).
    pub friction_angle: f64,
    /// Peak cohesion c_p [Pa], in [0, 1e13] (> 0 when φ = 0).
    pub cohesion: f64,
    /// Residual cohesion c_r [Pa], in [0, 1e13] (default: c_p, no softening).
    pub residual_cohesion: Option<f64>,
    /// Accumulated deviatoric plastic strain ε_p^r at which c_r is reached [-], > 0; required when
    /// c_r differs from c_p.
    pub softening_strain: Option<f64>,
    /// Initial dilation angle ψ_ini [degrees], in (−90, φ] (default 0).
    #[serde(default)]
    pub dilation_angle: f64,
    /// Critical-state dilation angle ψ_crit [degrees], in (−90, φ] (default: ψ_ini, a constant
    /// dilation angle).
    pub critical_dilation_angle: Option<f64>,
    /// Decay rate η of ψ = ψ_crit + (ψ_ini − ψ_crit) exp(−η ε̄) [-], ≥ 0 (default 0).
    #[serde(default)]
    pub dilation_decay: f64,
    /// Tensile strength t of a cut-off σ_i ≤ t [Pa], ≥ 0 (default: no cut-off).
    pub tension_cutoff: Option<f64>,
}

impl SoilParameters for MohrCoulomb {
    type Law = MohrCoulombLaw;

    fn law(&self) -> MohrCoulombLaw {
        let elastic = LinearElastic::new(self.young_modulus, self.poisson_ratio);
        let psi = self.dilation_angle.to_radians();
        MohrCoulombLaw {
            elastic,
            phi: self.friction_angle.to_radians(),
            cohesion: self.cohesion,
            residual_cohesion: self.residual_cohesion.unwrap_or(self.cohesion),
            softening_strain: self.softening_strain.unwrap_or(f64::INFINITY),
            psi_ini: psi,
            psi_crit: self.critical_dilation_angle.map_or(psi, f64::to_radians),
            eta: self.dilation_decay,
            tension: self.tension_cutoff,
        }
    }

    fn check(&self, key: &str) -> Checked {
        let k = |f: &str| at(key, f);
        check_elastic(key, self.young_modulus, self.poisson_ratio)?;
        in_closed_open(&k("friction_angle"), self.friction_angle, 0.0, 90.0)?;
        strength(&k("cohesion"), self.cohesion, true)?;
        let phi = self.friction_angle;
        for (f, v) in
            [("dilation_angle", Some(self.dilation_angle)), ("critical_dilation_angle", self.critical_dilation_angle)]
        {
            if let Some(v) = v.filter(|&v| !(v > -90.0 && v <= phi)) {
                return Err(format!("key `{}`: must be in (-90, friction_angle = {phi}], got {v}", k(f)));
            }
        }
        non_negative(&k("dilation_decay"), self.dilation_decay)?;
        if let Some(r) = self.residual_cohesion {
            strength(&k("residual_cohesion"), r, true)?;
            if r != self.cohesion && self.softening_strain.is_none() {
                return Err(format!(
                    "key `{}`: required when residual_cohesion differs from cohesion",
                    k("softening_strain")
                ));
            }
        }
        if let Some(e) = self.softening_strain {
            positive(&k("softening_strain"), e)?;
        }
        if let Some(t) = self.tension_cutoff {
            non_negative(&k("tension_cutoff"), t)?;
        }
        if phi == 0.0 && self.cohesion == 0.0 {
            return Err(format!(
                "key `{}`: a Tresca material (friction_angle = 0) needs a positive cohesion",
                k("cohesion")
            ));
        }
        Ok(())
    }

    fn describe(&self) -> String {
        let mut t = format!(
            "{}, E = {:.4e} Pa, ν = {}, φ = {}°, c = {:.4e} Pa, ψ = {}°",
            if self.friction_angle == 0.0 { "Tresca (Mohr–Coulomb with φ = 0)" } else { "Mohr–Coulomb" },
            self.young_modulus,
            self.poisson_ratio,
            self.friction_angle,
            self.cohesion,
            self.dilation_angle
        );
        if let (Some(r), Some(e)) = (self.residual_cohesion, self.softening_strain) {
            t += &format!(", softening to c_r = {r:.4e} Pa at ε̄ = {e}");
        }
        if let Some(pc) = self.critical_dilation_angle {
            t += &format!(", ψ → {pc}° with η = {}", self.dilation_decay);
        }
        if let Some(tc) = self.tension_cutoff {
            t += &format!(", tension cut-off {tc:.4e} Pa");
        }
        t
    }

    fn cohesion(&self) -> Option<f64> {
        Some(self.cohesion)
    }

    fn with_strength_reduced(&self, f: f64) -> MohrCoulomb {
        let (cohesion, residual_cohesion) = reduced_strength(self.cohesion, self.residual_cohesion, f);
        let friction_angle = (self.friction_angle.to_radians().tan() / f).atan().to_degrees();
        MohrCoulomb {
            cohesion,
            friction_angle,
            dilation_angle: self.dilation_angle.min(friction_angle),
            critical_dilation_angle: self.critical_dilation_angle.map(|psi| psi.min(friction_angle)),
            residual_cohesion,
            ..self.clone()
        }
    }
}

/// Mohr–Coulomb as the solver runs it (angles in radians, stresses in Pa).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MohrCoulombLaw {
    /// The elasticity, D^e.
    pub elastic: LinearElastic,
    /// Friction angle φ.
    pub phi: f64,
    /// Peak cohesion c_p.
    pub cohesion: f64,
    /// Residual cohesion c_r.
    pub residual_cohesion: f64,
    /// ε̄ at which c_r is reached (infinite: no softening).
    pub softening_strain: f64,
    /// Initial dilation angle ψ_ini.
    pub psi_ini: f64,
    /// Critical-state dilation angle ψ_crit.
    pub psi_crit: f64,
    /// Decay rate η ≥ 0 of ψ with ε̄.
    pub eta: f64,
    /// Tensile strength t of the cut-off σ_i ≤ t (None: no cut-off).
    pub tension: Option<f64>,
}

/// A yield plane a·σ ≤ k(c) with flow direction n, in sorted principal space.
#[derive(Debug, Clone, Copy)]
struct Plane {
    a: [f64; 3],
    n: [f64; 3],
    /// dk/dc (2 cos φ for Mohr–Coulomb planes, 0 for tension planes).
    dk_dc: f64,
    /// k at c = 0 (the tensile strength for tension planes).
    k0: f64,
}

impl Plane {
    fn k(&self, c: f64) -> f64 {
        self.k0 + self.dk_dc * c
    }
    fn f(&self, s: &[f64; 3], c: f64) -> f64 {
        dot(&self.a, s) - self.k(c)
    }
}

/// The local system of a candidate return at given multipliers.
struct Local {
    /// Residuals of the active planes.
    r: [f64; 3],
    /// ∂r/∂Δγ.
    jac: [[f64; 3]; 3],
    /// The stress at these multipliers.
    stress: [f64; 3],
    /// Δε̄ at these multipliers.
    de: f64,
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Deviatoric part of a principal 3-vector.
fn dev(v: &[f64; 3]) -> [f64; 3] {
    let m = (v[0] + v[1] + v[2]) / 3.0;
    [v[0] - m, v[1] - m, v[2] - m]
}

fn norm(v: &[f64; 3]) -> f64 {
    dot(v, v).sqrt()
}

impl MohrCoulombLaw {
    /// Cohesion at ε̄ and its slope dc/dε̄.
    pub fn cohesion_at(&self, eps: f64) -> (f64, f64) {
        if self.softening_strain.is_finite() && eps < self.softening_strain {
            let slope = (self.residual_cohesion - self.cohesion) / self.softening_strain;
            (self.cohesion + slope * eps, slope)
        } else if self.softening_strain.is_finite() {
            (self.residual_cohesion, 0.0)
        } else {
            (self.cohesion, 0.0)
        }
    }

    /// Dilation angle at ε̄.
    pub fn dilation_at(&self, eps: f64) -> f64 {
        self.psi_crit + (self.psi_ini - self.psi_crit) * (-self.eta * eps).exp()
    }

    fn d_times(&self, v: &[f64; 3]) -> [f64; 3] {
        let tr = v[0] + v[1] + v[2];
        let (lame, shear) = (self.elastic.lame(), self.elastic.shear_modulus());
        [lame * tr + 2.0 * shear * v[0], lame * tr + 2.0 * shear * v[1], lame * tr + 2.0 * shear * v[2]]
    }

    /// The yield planes in sorted principal space for dilation angle `psi`: main, left edge
    /// (σ₂ = σ₃: planes 13 and 12), right edge (σ₁ = σ₂: planes 13 and 23), tension σ₁, σ₂, σ₃.
    fn planes(&self, psi: f64) -> [Plane; 6] {
        let (sp, ss, cp) = (self.phi.sin(), psi.sin(), self.phi.cos());
        let mc = |i: usize, j: usize| {
            let mut a = [0.0; 3];
            let mut n = [0.0; 3];
            a[i] = 1.0 + sp;
            a[j] = -(1.0 - sp);
            n[i] = 1.0 + ss;
            n[j] = -(1.0 - ss);
            Plane { a, n, dk_dc: 2.0 * cp, k0: 0.0 }
        };
        let t = self.tension.unwrap_or(f64::INFINITY);
        let ten = |i: usize| {
            let mut a = [0.0; 3];
            a[i] = 1.0;
            Plane { a, n: a, dk_dc: 0.0, k0: t }
        };
        [mc(0, 2), mc(0, 1), mc(1, 2), ten(0), ten(1), ten(2)]
    }

    /// Returns the sorted trial principal stresses `trial` (σ₁ ≥ σ₂ ≥ σ₃) to the yield surface from
    /// the state ε̄ = `eps`.
    pub fn return_sorted(&self, trial: &[f64; 3], eps: f64) -> ReturnResult {
        let planes = self.planes(self.dilation_at(eps));
        let (c_n, _) = self.cohesion_at(eps);
        let scale = trial.iter().fold(self.cohesion.abs() + self.residual_cohesion.abs(), |a, v| a.max(v.abs()));
        let tol = 1e-10 * scale.max(f64::MIN_POSITIVE);
        let n_planes = if self.tension.is_some() { 6 } else { 3 };
        let f_max = planes[..n_planes].iter().map(|p| p.f(trial, c_n)).fold(f64::NEG_INFINITY, f64::max);
        if f_max <= tol {
            return ReturnResult::elastic(*trial, eps);
        }
        // Candidate active sets (indices into `planes`) with their region.
        let mut candidates: Vec<(&[usize], Region)> =
            vec![(&[0], Region::Plane), (&[0, 1], Region::EdgeLeft), (&[0, 2], Region::EdgeRight)];
        if self.tension.is_some() {
            candidates.extend_from_slice(&[
                (&[3][..], Region::Tension),
                (&[3, 4], Region::Tension),
                (&[3, 4, 5], Region::Tension),
                (&[0, 3], Region::TensionCorner),
                (&[0, 3, 4], Region::TensionCorner),
                (&[0, 1, 3], Region::TensionCorner),
            ]);
        }
        for (set, region) in candidates {
            if let Some(r) = self.try_set(trial, eps, &planes, set, region) {
                let ok_order = r.stress[0] >= r.stress[1] - tol && r.stress[1] >= r.stress[2] - tol;
                let (c, _) = self.cohesion_at(r.eps);
                let ok_yield = planes[..n_planes].iter().all(|p| p.f(&r.stress, c) <= 1e-8 * scale);
                if ok_order && ok_yield {
                    return r;
                }
            }
        }
        if self.phi > 0.0 {
            self.apex(trial, eps)
        } else {
            // A Tresca prism has no apex; the main plane always has a solution.
            self.try_set(trial, eps, &planes, &[0], Region::Plane).unwrap_or_else(|| ReturnResult::elastic(*trial, eps))
        }
    }

    /// The return onto the planes `set`; None if the local Newton fails or a multiplier is negative.
    fn try_set(
        &self,
        trial: &[f64; 3],
        eps: f64,
        planes: &[Plane; 6],
        set: &[usize],
        region: Region,
    ) -> Option<ReturnResult> {
        let m = set.len();
        let dn: Vec<[f64; 3]> = set.iter().map(|&j| self.d_times(&planes[j].n)).collect();
        // Local system r_i(Δγ) = a_i·(σ_tr − Σ_j Δγ_j D n_j) − k_i(c(ε̄_n + Δε̄(Δγ))).
        let eval = |g: &[f64; 3]| -> Local {
            let mut s = *trial;
            let mut ep = [0.0; 3];
            for (jj, &j) in set.iter().enumerate() {
                for k in 0..3 {
                    s[k] -= g[jj] * dn[jj][k];
                    ep[k] += g[jj] * planes[j].n[k];
                }
            }
            let d = dev(&ep);
            let dnorm = norm(&d);
            let de = (2.0f64 / 3.0).sqrt() * dnorm;
            // ∂Δε̄/∂Δγ_j (at Δγ = 0 the norm has no derivative; the length of the flow's
            // deviator is used there).
            let mut dde = [0.0; 3];
            for (jj, &j) in set.iter().enumerate() {
                let dj = dev(&planes[j].n);
                dde[jj] = if dnorm > 0.0 {
                    (2.0f64 / 3.0).sqrt() * dot(&d, &dj) / dnorm
                } else {
                    (2.0f64 / 3.0).sqrt() * norm(&dj)
                };
            }
            let (c, dc) = self.cohesion_at(eps + de);
            let mut r = [0.0; 3];
            let mut jac = [[0.0; 3]; 3];
            for (ii, &i) in set.iter().enumerate() {
                r[ii] = planes[i].f(&s, c);
                for jj in 0..m {
                    jac[ii][jj] = -dot(&planes[i].a, &dn[jj]) - planes[i].dk_dc * dc * dde[jj];
                }
            }
            Local { r, jac, stress: s, de }
        };
        let mut g = [0.0; 3];
        let mut converged = false;
        for _ in 0..30 {
            let l = eval(&g);
            let step = solve(l.jac, l.r, m)?;
            for k in 0..m {
                g[k] -= step[k];
            }
            let l2 = eval(&g);
            let rs = l2.stress.iter().fold(self.cohesion.abs(), |a, v| a.max(v.abs())).max(f64::MIN_POSITIVE);
            if l2.r[..m].iter().all(|v| v.abs() <= 1e-12 * rs) {
                converged = true;
                break;
            }
        }
        if !converged || g[..m].iter().any(|&v| v < -1e-12) {
            return None;
        }
        let l = eval(&g);
        // dσ/dσ_tr = I + D N J⁻¹ Aᵀ, column by column: y = J⁻¹ (Aᵀ e_b).
        let mut tangent = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        for b in 0..3 {
            let mut rhs = [0.0; 3];
            for (ii, &i) in set.iter().enumerate() {
                rhs[ii] = planes[i].a[b];
            }
            let y = solve(l.jac, rhs, m)?;
            for (a, row) in tangent.iter_mut().enumerate() {
                row[b] += (0..m).map(|jj| dn[jj][a] * y[jj]).sum::<f64>();
            }
        }
        Some(ReturnResult { stress: l.stress, tangent, eps: eps + l.de, region })
    }

    /// The return to the apex p = c cot φ (φ > 0).
    fn apex(&self, trial: &[f64; 3], eps: f64) -> ReturnResult {
        let d = dev(trial);
        let dn = norm(&d);
        let k = (2.0f64 / 3.0).sqrt() / (2.0 * self.elastic.shear_modulus());
        let de = k * dn;
        let (c, dc) = self.cohesion_at(eps + de);
        let cot = 1.0 / self.phi.tan();
        let p = c * cot;
        // dp/dσ_tr = c' cot φ · k · dev(σ_tr)/|dev σ_tr|.
        let mut tangent = [[0.0; 3]; 3];
        if dn > 0.0 {
            for row in tangent.iter_mut() {
                for (b, v) in row.iter_mut().enumerate() {
                    *v = dc * cot * k * d[b] / dn;
                }
            }
        }
        ReturnResult { stress: [p, p, p], tangent, eps: eps + de, region: Region::Apex }
    }
}

impl SoilLaw for MohrCoulombLaw {
    const DISSIPATES: bool = true;

    #[inline]
    fn update(&self, stress: &Stress, eps_pd: f64, deps: &Stress) -> StressUpdate {
        isotropic_return(self, stress, eps_pd, deps)
    }

    fn elastic(&self) -> &LinearElastic {
        &self.elastic
    }
}

impl PrincipalReturn for MohrCoulombLaw {
    /// Whether [`Self::return_sorted`] surely finds `trial` elastic, from its invariants p and R
    /// ([`super::mean_and_deviator_norm`]): the largest plane function is the one of σ₁ and σ₃,
    /// (σ₁ − σ₃) + sin φ (σ₁ + σ₃) − 2c cos φ ≤ √2 R + sin φ (2p + √(2/3) R) − 2c cos φ (φ ≥ 0), and
    /// σ₁ ≤ p + √(2/3) R for the tension cut-off. The bound is tested against half the return's
    /// smallest tolerance (1e-10 (c_p + c_r)), so that round-off cannot tip a point the return
    /// would find plastic.
    fn surely_elastic(&self, trial: &Stress, eps: f64) -> bool {
        let (p, r) = super::mean_and_deviator_norm(trial);
        let (c_n, _) = self.cohesion_at(eps);
        let (sp, cp) = self.phi.sin_cos();
        let top = p + (2.0f64 / 3.0).sqrt() * r;
        let shear = std::f64::consts::SQRT_2 * r + sp * (p + top) - 2.0 * c_n * cp;
        let margin = 0.5e-10 * (self.cohesion.abs() + self.residual_cohesion.abs());
        sp >= 0.0 && shear <= margin && self.tension.is_none_or(|t| top - t <= margin)
    }

    /// Sorts the values descending, returns them ([`MohrCoulombLaw::return_sorted`]) and maps
    /// them back.
    fn map_principal(&self, l: &[f64; 3], eps: f64) -> ReturnResult {
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| l[b].total_cmp(&l[a]));
        let sorted = [l[order[0]], l[order[1]], l[order[2]]];
        let r = self.return_sorted(&sorted, eps);
        let mut stress = [0.0; 3];
        let mut tangent = [[0.0; 3]; 3];
        for i in 0..3 {
            stress[order[i]] = r.stress[i];
            for j in 0..3 {
                tangent[order[i]][order[j]] = r.tangent[i][j];
            }
        }
        ReturnResult { stress, tangent, ..r }
    }
}
