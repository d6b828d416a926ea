//! Small dense linear algebra for the per-point kernels (systems of at most four unknowns) and
//! the matrix exponential of a boundary's homogeneous flow.

/// Solves the leading `n × n` block of `a x = b` by Gaussian elimination with partial pivoting.
/// None when a pivot is below 1e-12 × max|a| (numerically singular).
pub fn solve<const N: usize>(mut a: [[f64; N]; N], mut b: [f64; N], n: usize) -> Option<[f64; N]> {
    let scale = a[..n].iter().flat_map(|r| r[..n].iter()).fold(0.0f64, |m, v| m.max(v.abs()));
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs().partial_cmp(&(1e-12 * scale)) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        let pivot_row = a[col];
        for r in col + 1..n {
            let f = a[r][col] / pivot_row[col];
            for (arc, pc) in a[r][col..n].iter_mut().zip(&pivot_row[col..n]) {
                *arc -= f * pc;
            }
            b[r] -= f * b[col];
        }
    }
    let mut x = [0.0; N];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|c| a[r][c] * x[c]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    Some(x)
}

/// Like [`solve`], but for a singular `a` the minimum-norm-like solution of the regularised normal
/// equations (aᵀa + μI) x = aᵀb with μ = 1e-10 max|a|².
pub fn solve_regularised<const N: usize>(a: [[f64; N]; N], b: [f64; N], n: usize) -> Option<[f64; N]> {
    if let Some(x) = solve(a, b, n) {
        return Some(x);
    }
    let scale = a[..n].iter().flat_map(|r| r[..n].iter()).fold(0.0f64, |m, v| m.max(v.abs()));
    let mut ata = [[0.0; N]; N];
    let mut atb = [0.0; N];
    for i in 0..n {
        for j in 0..n {
            ata[i][j] = (0..n).map(|k| a[k][i] * a[k][j]).sum();
        }
        ata[i][i] += 1e-10 * scale * scale;
        atb[i] = (0..n).map(|k| a[k][i] * b[k]).sum();
    }
    solve(ata, atb, n)
}

/// exp(A) of a 2 × 2 matrix, in closed form: with s = tr A/2 and δ = ((a − d)/2)² + bc,
/// exp(A) = e^s (C I + S (A − sI)) with C = cosh √δ, S = sinh √δ/√δ (cos and sin for δ < 0).
pub fn exp2(a: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let s = 0.5 * (a[0][0] + a[1][1]);
    let delta = 0.25 * (a[0][0] - a[1][1]).powi(2) + a[0][1] * a[1][0];
    let (c, sn) = if delta.abs() < 1e-12 {
        (1.0 + 0.5 * delta, 1.0 + delta / 6.0)
    } else if delta > 0.0 {
        let q = delta.sqrt();
        (q.cosh(), q.sinh() / q)
    } else {
        let q = (-delta).sqrt();
        (q.cos(), q.sin() / q)
    };
    let e = s.exp();
    [[e * (c + sn * (a[0][0] - s)), e * sn * a[0][1]], [e * sn * a[1][0], e * (c + sn * (a[1][1] - s))]]
}

/// exp(A) of a D × D matrix: [`exp2`]'s closed form in two dimensions; otherwise scaling and
/// squaring (Moler & Van Loan 2003, method 3): A/2^j with ‖A‖₁/2^j ≤ 1/2, its Taylor series summed
/// until a term no longer changes the sum, then squared j times. At ‖A/2^j‖₁ ≤ 1/2 the truncated
/// series is exact to round-off; each squaring at most doubles the relative error, and a boundary's
/// flow over one step has ‖L s‖ of order one, so j stays small.
pub fn expm<const D: usize>(a: [[f64; D]; D]) -> [[f64; D]; D] {
    if D == 2 {
        let e = exp2([[a[0][0], a[0][1]], [a[1][0], a[1][1]]]);
        return std::array::from_fn(|i| std::array::from_fn(|k| e[i][k]));
    }
    let norm = (0..D).map(|k| (0..D).map(|i| a[i][k].abs()).sum::<f64>()).fold(0.0f64, f64::max);
    if !norm.is_finite() {
        return [[f64::NAN; D]; D];
    }
    let mut squarings = 0;
    while norm / f64::powi(2.0, squarings) > 0.5 {
        squarings += 1;
    }
    let scale = f64::powi(2.0, -squarings);
    let x: [[f64; D]; D] = a.map(|row| row.map(|v| v * scale));
    let mul = super::product::<D>;
    let mut sum: [[f64; D]; D] = std::array::from_fn(|i| std::array::from_fn(|k| if i == k { 1.0 } else { 0.0 }));
    let mut term = sum;
    for n in 1..=30 {
        term = mul(&term, &x).map(|row| row.map(|v| v / n as f64));
        let before = sum;
        for (s, t) in sum.iter_mut().flatten().zip(term.iter().flatten()) {
            *s += t;
        }
        if sum == before {
            break;
        }
    }
    for _ in 0..squarings {
        sum = mul(&sum, &sum);
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_pivoting_system_and_refuses_a_singular_one() {
        let a = [[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [3.0, 0.0, 1.0]];
        let x = solve(a, [5.0, 3.0, 6.0], 3).unwrap();
        for (r, row) in a.iter().enumerate() {
            let lhs: f64 = row.iter().zip(&x).map(|(p, q)| p * q).sum();
            assert!((lhs - [5.0, 3.0, 6.0][r]).abs() < 1e-12);
        }
        let s = [[1.0, 2.0, 0.0], [2.0, 4.0, 0.0], [0.0, 0.0, 0.0]];
        assert!(solve(s, [1.0, 2.0, 0.0], 2).is_none());
        // The regularised solve gives the minimum-norm solution of the consistent singular system.
        let x = solve_regularised(s, [1.0, 2.0, 0.0], 2).unwrap();
        assert!((x[0] - 0.2).abs() < 1e-6 && (x[1] - 0.4).abs() < 1e-6, "{x:?}");
    }

    fn max_diff(p: &[[f64; 3]; 3], q: &[[f64; 3]; 3]) -> f64 {
        p.iter().flatten().zip(q.iter().flatten()).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
    }

    /// The exponential of a rotation's generator is Rodrigues' rotation, of a diagonal matrix the
    /// exponentials of its entries, of a matrix with a zero third row and column the plane closed
    /// form; exp(A) exp(−A) = I and det exp(A) = e^{tr A} for a general matrix (stretch, shear and
    /// spin together, ‖A‖₁ = 1.9: two squarings).
    #[test]
    fn the_matrix_exponential_is_exact_on_known_flows() {
        let axis = [1.0f64, -2.0, 2.0].map(|v| v / 3.0);
        let angle = 1.3;
        let w = [[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]];
        let e = expm(w.map(|r| r.map(|v| v * angle)));
        // Rodrigues' formula: R = I + sin θ W + (1 − cos θ) W².
        let w2 = super::super::product(&w, &w);
        let r: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|k| {
                f64::from(u8::from(i == k)) + angle.sin() * w[i][k] + (1.0 - angle.cos()) * w2[i][k]
            })
        });
        assert!(max_diff(&e, &r) < 1e-15, "{e:?} against {r:?}");

        let d = expm([[0.7, 0.0, 0.0], [0.0, -1.1, 0.0], [0.0, 0.0, 2.5]]);
        for (i, v) in [0.7f64, -1.1, 2.5].iter().enumerate() {
            assert!((d[i][i] - v.exp()).abs() < 2e-16 * v.exp().max(1.0) * 4.0, "{} against {}", d[i][i], v.exp());
        }

        let plane = [[0.3, -0.8], [0.5, -0.2]];
        let e2 = exp2(plane);
        let e3 = expm([[0.3, -0.8, 0.0], [0.5, -0.2, 0.0], [0.0, 0.0, 0.0]]);
        for i in 0..2 {
            for k in 0..2 {
                assert!((e2[i][k] - e3[i][k]).abs() < 1e-15, "{e2:?} against {e3:?}");
            }
        }
        assert!((e3[2][2] - 1.0).abs() < 1e-15 && e3[0][2] == 0.0 && e3[2][1] == 0.0);
        assert_eq!(expm(plane), e2, "the plane's closed form");

        let a = [[0.4, 1.2, -0.3], [-0.9, 0.1, 0.8], [0.6, -0.5, -0.7]];
        let (p, m) = (expm(a), expm(a.map(|r| r.map(|v| -v))));
        let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let pm = super::super::product(&p, &m);
        assert!(max_diff(&pm, &id) < 1e-14, "{pm:?}");
        let det = super::super::det(&p);
        assert!((det - (0.4f64 + 0.1 - 0.7).exp()).abs() < 1e-14, "det {det}");
    }
}
