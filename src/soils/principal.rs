//! Stresses in their principal frame, and the derivative of an isotropic stress function through
//! it.
//!
//! A stress vector [xx, yy, xy, zz, yz, zx] (tensor shear components; [`super::Stress`]) has the
//! principal values λ_1, λ_2, λ_3 with orthonormal directions e_1, e_2, e_3. An isotropic return map
//! σ = F(σ_trial) keeps the principal directions and maps the principal values,
//! σ_i = f_i(λ_1, λ_2, λ_3). Its derivative (de Souza Neto, Perić & Owen 2008, Appendix A) is, in
//! the principal frame,
//!   dσ_ii = Σ_j (∂f_i/∂λ_j) dλ_j,   dσ_ij = (σ_i − σ_j)/(λ_i − λ_j) dσ_trial,ij  (i ≠ j),
//! where the spin factor tends to ½(∂f_i/∂λ_i − ∂f_i/∂λ_j − ∂f_j/∂λ_i + ∂f_j/∂λ_j) when λ_i = λ_j.
//!
//! A plane stress state (yz = zx = 0: every plane-strain and axisymmetric point) is decomposed in
//! closed form: the in-plane values λ_A ≥ λ_B with e_A = (cos θ, sin θ, 0), e_B = (−sin θ, cos θ, 0),
//! and λ_Z = σ_zz with e_Z = (0, 0, 1). A general one is diagonalised by cyclic Jacobi rotations,
//! which keep every eigenvalue to relative round-off.

use super::stress::{Mat6, Stress, NS};

/// The (row, column) of each stress-vector component in the symmetric tensor.
pub const TENSOR_INDEX: [(usize, usize); NS] = [(0, 0), (1, 1), (0, 1), (2, 2), (1, 2), (2, 0)];

/// The symmetric 3 × 3 tensor of a stress vector.
pub fn tensor(s: &Stress) -> [[f64; 3]; 3] {
    [[s[0], s[2], s[5]], [s[2], s[1], s[4]], [s[5], s[4], s[3]]]
}

/// The stress vector of a symmetric 3 × 3 tensor (its upper triangle's shears).
pub fn vector(t: &[[f64; 3]; 3]) -> Stress {
    TENSOR_INDEX.map(|(a, b)| t[a][b])
}

/// Principal values and directions of a stress.
#[derive(Debug, Clone, Copy)]
pub struct Principal {
    /// λ_1, λ_2, λ_3; for a plane state λ_A ≥ λ_B (in plane) and λ_Z (out of plane).
    pub values: [f64; 3],
    /// The unit directions e_1, e_2, e_3, one per row.
    pub vectors: [[f64; 3]; 3],
}

impl Principal {
    /// The principal decomposition of `s`.
    pub fn of(s: &Stress) -> Principal {
        if s[4] == 0.0 && s[5] == 0.0 {
            Principal::of_plane(s)
        } else {
            Principal::of_general(s)
        }
    }

    /// The closed form of a plane state (yz = zx = 0).
    fn of_plane(s: &Stress) -> Principal {
        let m = 0.5 * (s[0] + s[1]);
        let d = 0.5 * (s[0] - s[1]);
        let r = d.hypot(s[2]);
        let theta = 0.5 * s[2].atan2(d);
        Principal::in_plane([m + r, m - r, s[3]], theta)
    }

    /// The frame of a plane state with values `values` (A, B, Z) whose e_A makes the angle
    /// `theta` with x.
    pub fn in_plane(values: [f64; 3], theta: f64) -> Principal {
        let (sn, c) = theta.sin_cos();
        Principal { values, vectors: [[c, sn, 0.0], [-sn, c, 0.0], [0.0, 0.0, 1.0]] }
    }

    /// Cyclic Jacobi rotations (Golub & Van Loan, Algorithm 8.4.3) until the off-diagonal part is
    /// below round-off of the diagonal.
    fn of_general(s: &Stress) -> Principal {
        Principal::jacobi(s).0
    }

    /// [`Principal::of_general`] and the number of sweeps it took (at most 50).
    fn jacobi(s: &Stress) -> (Principal, usize) {
        let mut a = tensor(s);
        let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let mut sweeps = 0;
        while sweeps < 50 {
            let off = a[0][1] * a[0][1] + a[1][2] * a[1][2] + a[2][0] * a[2][0];
            let diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
            if off <= 1e-34 * diag || off == 0.0 {
                break;
            }
            sweeps += 1;
            for (p, q) in [(0, 1), (1, 2), (0, 2)] {
                if a[p][q] == 0.0 {
                    continue;
                }
                // The rotation that zeroes a_pq: t = tan of its angle, the smaller root.
                let tau = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = tau.signum() / (tau.abs() + (1.0 + tau * tau).sqrt());
                let c = 1.0 / (1.0 + t * t).sqrt();
                let sn = t * c;
                // A ← Jᵀ A J, V ← V J (columns of V are the directions).
                for row in a.iter_mut() {
                    let (akp, akq) = (row[p], row[q]);
                    row[p] = c * akp - sn * akq;
                    row[q] = sn * akp + c * akq;
                }
                let (rp, rq) = (a[p], a[q]);
                for k in 0..3 {
                    a[p][k] = c * rp[k] - sn * rq[k];
                    a[q][k] = sn * rp[k] + c * rq[k];
                }
                // The rotation zeroes a_pq exactly; its round-off left in place would keep the
                // off-diagonal part at about 1e-16 of the diagonal, above the sweeps' stopping
                // test, and a nearly isotropic stress would take all 50 sweeps.
                a[p][q] = 0.0;
                a[q][p] = 0.0;
                for row in v.iter_mut() {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - sn * vq;
                    row[q] = sn * vp + c * vq;
                }
            }
        }
        let vectors = [0, 1, 2].map(|i| [v[0][i], v[1][i], v[2][i]]);
        (Principal { values: [a[0][0], a[1][1], a[2][2]], vectors }, sweeps)
    }

    /// The stress with principal values `v` in this frame.
    pub fn compose(&self, v: &[f64; 3]) -> Stress {
        let e = &self.vectors;
        TENSOR_INDEX.map(|(a, b)| v[0] * e[0][a] * e[0][b] + v[1] * e[1][a] * e[1][b] + v[2] * e[2][a] * e[2][b])
    }

    /// dσ/dσ_trial (stress-vector components with tensor shear) of an isotropic map whose
    /// principal values are `returned` with derivatives `m[i][j]` = ∂σ_i/∂λ_j (in the order of
    /// `values`); `self` is the trial stress's decomposition.
    pub fn derivative(&self, returned: &[f64; 3], m: &[[f64; 3]; 3]) -> Mat6 {
        let e = &self.vectors;
        let scale = self.values.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(f64::MIN_POSITIVE);
        const PAIRS: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];
        let spin = PAIRS.map(|(i, j)| {
            let gap = self.values[i] - self.values[j];
            if gap.abs() > 1e-9 * scale {
                (returned[i] - returned[j]) / gap
            } else {
                0.5 * (m[i][i] - m[i][j] - m[j][i] + m[j][j])
            }
        });
        // uᵀ E_c v for the symmetric unit tensor E_c of stress component c.
        let quad = |u: &[f64; 3], c: usize, v: &[f64; 3]| -> f64 {
            let (a, b) = TENSOR_INDEX[c];
            if a == b {
                u[a] * v[a]
            } else {
                u[a] * v[b] + u[b] * v[a]
            }
        };
        let mut out = [[0.0; NS]; NS];
        #[allow(clippy::needless_range_loop)] // c is a component of the stress and a column of out.
        for c in 0..NS {
            let dl = [quad(&e[0], c, &e[0]), quad(&e[1], c, &e[1]), quad(&e[2], c, &e[2])];
            let ds: [f64; 3] = [0, 1, 2].map(|i| (0..3).map(|k| m[i][k] * dl[k]).sum());
            let dt: [f64; 3] = [0, 1, 2].map(|k| {
                let (i, j) = PAIRS[k];
                spin[k] * quad(&e[i], c, &e[j])
            });
            // dS = Σ_i dσ_i e_i e_iᵀ + Σ_{i<j} dσ_ij (e_i e_jᵀ + e_j e_iᵀ).
            for (r, &(a, b)) in TENSOR_INDEX.iter().enumerate() {
                let mut v = ds[0] * e[0][a] * e[0][b] + ds[1] * e[1][a] * e[1][b] + ds[2] * e[2][a] * e[2][b];
                for (k, &(i, j)) in PAIRS.iter().enumerate() {
                    v += dt[k] * (e[i][a] * e[j][b] + e[j][a] * e[i][b]);
                }
                out[r][c] = v;
            }
        }
        out
    }
}

/// R σ Rᵀ of a stress vector under the rotation (or any matrix) `r`.
pub fn rotate(r: &[[f64; 3]; 3], s: &Stress) -> Stress {
    let t = tensor(s);
    let mut out = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            out[a][b] = (0..3).map(|k| (0..3).map(|l| r[a][k] * t[k][l] * r[b][l]).sum::<f64>()).sum();
        }
    }
    vector(&out)
}

/// The rotation by `angle` about the unit `axis` (Rodrigues).
pub fn rotation(axis: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
    let (s, c) = angle.sin_cos();
    let [x, y, z] = axis;
    [
        [c + x * x * (1.0 - c), x * y * (1.0 - c) - z * s, x * z * (1.0 - c) + y * s],
        [y * x * (1.0 - c) + z * s, c + y * y * (1.0 - c), y * z * (1.0 - c) - x * s],
        [z * x * (1.0 - c) - y * s, z * y * (1.0 - c) + x * s, c + z * z * (1.0 - c)],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Nearly isotropic stresses (a geostatic state with small shears, as most of a soil body
    /// holds) converge in a few sweeps to an exact decomposition: the sweeps stop once the
    /// off-diagonal part is below round-off of the diagonal, which the rotations reach only if the
    /// entry each zeroes is set to zero rather than left at its round-off.
    #[test]
    fn nearly_isotropic_stresses_converge_in_a_few_sweeps() {
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut most = 0;
        for i in 0..4000 {
            let shear = [1e3, 1.0, 1e-3, 1e-6][i % 4];
            let s = [
                -1e5 + 1e2 * next(),
                -1e5 + 1e2 * next(),
                shear * next(),
                -1e5 + 1e2 * next(),
                shear * next(),
                shear * next(),
            ];
            let (p, sweeps) = Principal::jacobi(&s);
            most = most.max(sweeps);
            let back = p.compose(&p.values);
            for (a, b) in back.iter().zip(&s) {
                assert!((a - b).abs() <= 1e-15 * 1e5 * 8.0, "{s:?} composed back as {back:?}");
            }
        }
        assert!(most <= 5, "a nearly isotropic stress took {most} sweeps");
    }

    /// A general rotation (axis not along a coordinate axis).
    fn tilt() -> [[f64; 3]; 3] {
        let n = (1.0f64 + 4.0 + 9.0).sqrt();
        rotation([1.0 / n, -2.0 / n, 3.0 / n], 0.83)
    }

    #[test]
    fn decomposition_and_composition_round_trip() {
        let plane =
            [[3.0, -1.0, 2.0, 0.5, 0.0, 0.0], [-5.0, -5.0, 0.0, -2.0, 0.0, 0.0], [1.0, 4.0, -3.0, 7.0, 0.0, 0.0]];
        let general =
            [[3.0, -1.0, 2.0, 0.5, 1.5, -0.7], [-5.0, -5.0, 0.0, -5.0, 1e-3, 0.0], [0.0, 0.0, 1.0, 0.0, 1.0, 1.0]];
        for s in plane.iter().chain(&general) {
            let p = Principal::of(s);
            let back = p.compose(&p.values);
            for k in 0..NS {
                assert!((back[k] - s[k]).abs() < 1e-12, "{s:?} -> {back:?}");
            }
            // Orthonormal directions.
            for i in 0..3 {
                for j in 0..3 {
                    let d: f64 = (0..3).map(|k| p.vectors[i][k] * p.vectors[j][k]).sum();
                    assert!((d - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14, "{s:?}: e{i}·e{j} = {d}");
                }
            }
        }
        // A plane state's values are A ≥ B then Z.
        let p = Principal::of(&plane[0]);
        assert!(p.values[0] >= p.values[1] && p.values[2] == 0.5);
    }

    #[test]
    fn a_rotated_state_has_the_same_principal_values() {
        let s = [3.0, -1.0, 2.0, 0.5, 0.0, 0.0];
        let r = rotate(&tilt(), &s);
        assert!(r[4].abs() > 0.1 && r[5].abs() > 0.1, "the rotation must leave the plane: {r:?}");
        let (mut a, mut b) = (Principal::of(&s).values, Principal::of(&r).values);
        a.sort_by(f64::total_cmp);
        b.sort_by(f64::total_cmp);
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() < 1e-13, "{a:?} against {b:?}");
        }
    }

    #[test]
    fn derivative_of_a_nonlinear_isotropic_map_matches_finite_differences() {
        // σ_i = λ_i³ + λ_1 λ_2 λ_3 + Σλ: isotropic (a symmetric function of the values).
        let f = |l: &[f64; 3]| {
            let (p, s) = (l[0] * l[1] * l[2], l[0] + l[1] + l[2]);
            l.map(|x| x.powi(3) + p + s)
        };
        let m = |l: &[f64; 3]| {
            std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    let others: f64 = (0..3).filter(|&k| k != j).map(|k| l[k]).product();
                    others + 1.0 + if i == j { 3.0 * l[i] * l[i] } else { 0.0 }
                })
            })
        };
        let states = [
            [1.2, -0.4, 0.7, 0.3, 0.0, 0.0],
            [0.5, 0.5, 0.0, -1.0, 0.0, 0.0],
            [1.2, -0.4, 0.7, 0.3, 0.45, -0.25],
            // Two equal values out of the plane.
            [0.5, 0.5, 0.0, 0.5, 0.0, 0.0],
            rotate(&tilt(), &[2.0, 1.0, -0.2, 0.8, 0.0, 0.0]),
        ];
        for s in states {
            let p = Principal::of(&s);
            let d = p.derivative(&f(&p.values), &m(&p.values));
            for j in 0..NS {
                let h = 1e-6;
                let (mut sp, mut sm) = (s, s);
                sp[j] += h;
                sm[j] -= h;
                let (pp, pm) = (Principal::of(&sp), Principal::of(&sm));
                let (up, um) = (pp.compose(&f(&pp.values)), pm.compose(&f(&pm.values)));
                for i in 0..NS {
                    let fd = (up[i] - um[i]) / (2.0 * h);
                    assert!((fd - d[i][j]).abs() < 1e-6, "{s:?} d{i}/d{j}: {fd} vs {}", d[i][j]);
                }
            }
        }
    }
}
