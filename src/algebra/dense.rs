//! Small dense linear algebra for the preconditioners' local blocks.

/// Replaces the row-major `n × n` matrix `a` by its inverse (Gauss–Jordan elimination with
/// partial pivoting). Fails on a pivot below `1e-14` of the largest entry of the matrix.
pub fn invert_in_place(a: &mut [f64], n: usize) -> Result<(), String> {
    if a.len() != n * n {
        return Err(format!("{} values for a {n} × {n} matrix", a.len()));
    }
    let scale = a.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return Err(format!("the matrix's largest entry is {scale}"));
    }
    // The row each step swapped into place: A⁻¹'s columns are swapped back in reverse order.
    let mut swaps: Vec<usize> = (0..n).collect();
    for k in 0..n {
        let pivot = (k..n).max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs())).expect("k < n");
        if a[pivot * n + k].abs() <= 1e-14 * scale {
            return Err(format!("singular at column {k} (pivot {:e}, largest entry {scale:e})", a[pivot * n + k]));
        }
        if pivot != k {
            for c in 0..n {
                a.swap(k * n + c, pivot * n + c);
            }
            swaps[k] = pivot;
        }
        let d = 1.0 / a[k * n + k];
        a[k * n + k] = 1.0;
        for c in 0..n {
            a[k * n + c] *= d;
        }
        for r in (0..n).filter(|&r| r != k) {
            let f = a[r * n + k];
            if f != 0.0 {
                a[r * n + k] = 0.0;
                for c in 0..n {
                    a[r * n + c] -= f * a[k * n + c];
                }
            }
        }
    }
    for k in (0..n).rev() {
        if swaps[k] != k {
            for r in 0..n {
                a.swap(r * n + k, r * n + swaps[k]);
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_inverse_times_the_matrix_is_the_identity() {
        // A non-symmetric matrix whose first pivot is zero (so rows are swapped).
        let n = 5;
        let a: Vec<f64> = (0..n * n)
            .map(|k| {
                let (i, j) = (k / n, k % n);
                if i == 0 && j == 0 {
                    0.0
                } else {
                    ((3 * i + 7 * j) % 11) as f64 - 4.0 + if i == j { 9.0 } else { 0.0 }
                }
            })
            .collect();
        let mut inv = a.clone();
        invert_in_place(&mut inv, n).unwrap();
        for i in 0..n {
            for j in 0..n {
                let p: f64 = (0..n).map(|k| a[i * n + k] * inv[k * n + j]).sum();
                assert!((p - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12, "({i}, {j}): {p}");
            }
        }
    }

    #[test]
    fn a_singular_matrix_is_refused() {
        let mut a = vec![1.0, 2.0, 2.0, 4.0];
        assert!(invert_in_place(&mut a, 2).unwrap_err().contains("singular"));
    }
}
