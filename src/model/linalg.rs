//! Small dense linear algebra for the per-point kernels (systems of at most four unknowns).

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
}
