//! Plane-strain stresses in their principal frame, and the derivative of an isotropic stress
//! function through it.
//!
//! A stress vector [xx, yy, xy, zz] (tensor shear component) has the in-plane principal values
//! λ_A ≥ λ_B with unit directions e_A = (cos θ, sin θ), e_B = (−sin θ, cos θ), and λ_Z = σ_zz. An
//! isotropic return map σ = F(σ_trial) keeps the principal directions and maps the principal values,
//! σ_i = f_i(λ_A, λ_B, λ_Z). Its derivative (de Souza Neto, Perić & Owen 2008, Appendix A, for two
//! in-plane eigenvalues) is, in the principal frame,
//!   dσ_ii = Σ_j (∂f_i/∂λ_j) dλ_j,   dσ_AB = (σ_A − σ_B)/(λ_A − λ_B) dσ_trial,AB,
//! where the spin factor tends to ½(∂f_A/∂λ_A − ∂f_A/∂λ_B − ∂f_B/∂λ_A + ∂f_B/∂λ_B) when λ_A = λ_B.

/// Principal values and in-plane directions of a plane-strain stress.
#[derive(Debug, Clone, Copy)]
pub struct Principal {
    /// λ_A ≥ λ_B (in plane), λ_Z (out of plane).
    pub values: [f64; 3],
    /// cos θ, sin θ of e_A.
    pub dir: [f64; 2],
}

impl Principal {
    /// The principal decomposition of `s` = [xx, yy, xy, zz].
    pub fn of(s: &[f64; 4]) -> Principal {
        let m = 0.5 * (s[0] + s[1]);
        let d = 0.5 * (s[0] - s[1]);
        let r = d.hypot(s[2]);
        let theta = 0.5 * s[2].atan2(d);
        Principal { values: [m + r, m - r, s[3]], dir: [theta.cos(), theta.sin()] }
    }

    /// The stress with principal values `v` (A, B, Z) in this frame.
    pub fn compose(&self, v: &[f64; 3]) -> [f64; 4] {
        let [c, s] = self.dir;
        [v[0] * c * c + v[1] * s * s, v[0] * s * s + v[1] * c * c, (v[0] - v[1]) * c * s, v[2]]
    }

    /// dσ/dσ_trial (4 × 4, stress-vector components with tensor shear) of an isotropic map whose
    /// principal values are `returned` with derivatives `m[i][j]` = ∂σ_i/∂λ_j (A, B, Z order); `self`
    /// is the trial stress's decomposition.
    pub fn derivative(&self, returned: &[f64; 3], m: &[[f64; 3]; 3]) -> [[f64; 4]; 4] {
        let [c, s] = self.dir;
        let (ea, eb) = ([c, s], [-s, c]);
        let gap = self.values[0] - self.values[1];
        let scale = self.values.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(f64::MIN_POSITIVE);
        let spin = if gap.abs() > 1e-9 * scale {
            (returned[0] - returned[1]) / gap
        } else {
            0.5 * (m[0][0] - m[0][1] - m[1][0] + m[1][1])
        };
        let quad = |u: [f64; 2], t: &[[f64; 2]; 2], v: [f64; 2]| -> f64 {
            u[0] * (t[0][0] * v[0] + t[0][1] * v[1]) + u[1] * (t[1][0] * v[0] + t[1][1] * v[1])
        };
        let mut out = [[0.0; 4]; 4];
        for (j, col) in [[[1.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 1.0]], [[0.0, 1.0], [1.0, 0.0]], [[0.0; 2]; 2]]
            .iter()
            .enumerate()
        {
            let dl = [quad(ea, col, ea), quad(eb, col, eb), if j == 3 { 1.0 } else { 0.0 }];
            let dt = quad(ea, col, eb);
            let ds: Vec<f64> = (0..3).map(|i| (0..3).map(|k| m[i][k] * dl[k]).sum()).collect();
            let dab = spin * dt;
            // dS = dσ_A e_A e_Aᵀ + dσ_B e_B e_Bᵀ + dσ_AB (e_A e_Bᵀ + e_B e_Aᵀ).
            out[0][j] = ds[0] * ea[0] * ea[0] + ds[1] * eb[0] * eb[0] + 2.0 * dab * ea[0] * eb[0];
            out[1][j] = ds[0] * ea[1] * ea[1] + ds[1] * eb[1] * eb[1] + 2.0 * dab * ea[1] * eb[1];
            out[2][j] = ds[0] * ea[0] * ea[1] + ds[1] * eb[0] * eb[1] + dab * (ea[0] * eb[1] + eb[0] * ea[1]);
            out[3][j] = ds[2];
        }
        out
    }
}

/// A · B for 4 × 4 matrices.
pub fn mul4(a: &[[f64; 4]; 4], b: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut out = [[0.0; 4]; 4];
    for (r, row) in out.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[r][k] * b[k][c]).sum();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decomposition_and_composition_round_trip() {
        for s in [[3.0, -1.0, 2.0, 0.5], [-5.0, -5.0, 0.0, -2.0], [1.0, 4.0, -3.0, 7.0], [0.0, 0.0, 1.0, 0.0]] {
            let p = Principal::of(&s);
            assert!(p.values[0] >= p.values[1]);
            let back = p.compose(&p.values);
            for k in 0..4 {
                assert!((back[k] - s[k]).abs() < 1e-12, "{s:?} -> {back:?}");
            }
        }
    }

    #[test]
    fn derivative_of_a_nonlinear_isotropic_map_matches_finite_differences() {
        // σ_i = λ_i³ + λ_A λ_B (A, B), λ_Z² (Z): isotropic in the plane.
        let f = |l: &[f64; 3]| [l[0].powi(3) + l[0] * l[1], l[1].powi(3) + l[0] * l[1], l[2] * l[2]];
        let m = |l: &[f64; 3]| {
            [[3.0 * l[0] * l[0] + l[1], l[0], 0.0], [l[1], 3.0 * l[1] * l[1] + l[0], 0.0], [0.0, 0.0, 2.0 * l[2]]]
        };
        for s in [[1.2, -0.4, 0.7, 0.3], [0.5, 0.5, 0.0, -1.0], [2.0, 1.0, -0.2, 0.8]] {
            let p = Principal::of(&s);
            let d = p.derivative(&f(&p.values), &m(&p.values));
            for j in 0..4 {
                let h = 1e-6;
                let (mut sp, mut sm) = (s, s);
                sp[j] += h;
                sm[j] -= h;
                let (pp, pm) = (Principal::of(&sp), Principal::of(&sm));
                let (up, um) = (pp.compose(&f(&pp.values)), pm.compose(&f(&pm.values)));
                for i in 0..4 {
                    let fd = (up[i] - um[i]) / (2.0 * h);
                    assert!((fd - d[i][j]).abs() < 1e-6, "{s:?} d{i}/d{j}: {fd} vs {}", d[i][j]);
                }
            }
        }
    }
}
