//! Small dense algebra shared by the model and the kernels: D × D matrices (D = 2 or 3) and
//! their determinant, cofactors, inverse and products; small linear solves and the matrix
//! exponential ([`linalg`]); the inverse of a dense block ([`dense`]); the heap bytes of a
//! container ([`heap`]); the right stretch of a 2 × 2 deformation gradient.

pub mod dense;
pub mod heap;
pub mod linalg;

/// A D-vector with three components (zero beyond D).
pub fn pad3<const D: usize>(v: [f64; D]) -> [f64; 3] {
    std::array::from_fn(|d| if d < D { v[d] } else { 0.0 })
}

/// A 2 × 2 matrix, rows first.
pub type M2 = [[f64; 2]; 2];

/// A D × D matrix, rows first.
pub type Mat<const D: usize> = [[f64; D]; D];

/// The identity.
pub fn identity<const D: usize>() -> Mat<D> {
    std::array::from_fn(|i| std::array::from_fn(|j| if i == j { 1.0 } else { 0.0 }))
}

/// det a (D = 2 or 3).
pub fn det<const D: usize>(a: &Mat<D>) -> f64 {
    match D {
        2 => a[0][0] * a[1][1] - a[0][1] * a[1][0],
        3 => {
            a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
        }
        _ => unreachable!("two or three dimensions"),
    }
}

/// The cofactor matrix of a (det a a⁻ᵀ; D = 2 or 3).
pub fn cofactor<const D: usize>(a: &Mat<D>) -> Mat<D> {
    match D {
        2 => std::array::from_fn(|i| std::array::from_fn(|j| if i == j { a[1 - i][1 - j] } else { -a[1 - i][1 - j] })),
        3 => std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
                a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1]
            })
        }),
        _ => unreachable!("two or three dimensions"),
    }
}

/// a⁻¹.
pub fn inverse<const D: usize>(a: &Mat<D>) -> Mat<D> {
    let d = det(a);
    let c = cofactor(a);
    std::array::from_fn(|i| std::array::from_fn(|j| c[j][i] / d))
}

/// a b.
pub fn mul<const D: usize>(a: &Mat<D>, b: &Mat<D>) -> Mat<D> {
    std::array::from_fn(|i| std::array::from_fn(|j| (1..D).fold(a[i][0] * b[0][j], |s, k| s + a[i][k] * b[k][j])))
}

/// The product a b of two matrices.
pub fn product<const D: usize>(a: &Mat<D>, b: &Mat<D>) -> Mat<D> {
    mul(a, b)
}

/// det(a) a⁻ᵀ v, the cofactor matrix of `a` times `v`: a gradient pushed forward by `a` up to the
/// factor 1/det a (Nanson's normal, a material field's gradient on the new configuration).
pub fn cofactor_mul<const D: usize>(a: &Mat<D>, v: [f64; D]) -> [f64; D] {
    let c = cofactor(a);
    std::array::from_fn(|i| (1..D).fold(c[i][0] * v[0], |s, k| s + c[i][k] * v[k]))
}

/// aᵀ v.
pub fn mul_t<const D: usize>(a: &Mat<D>, v: [f64; D]) -> [f64; D] {
    std::array::from_fn(|j| (1..D).fold(a[0][j] * v[0], |s, k| s + a[k][j] * v[k]))
}

/// The right stretch tensor U = sqrt(FᵀF) of an in-plane deformation gradient F (polar
/// decomposition F = RU), in closed form for 2 × 2: with C = FᵀF, s = sqrt(det C) and
/// t = sqrt(tr C + 2s), U = (C + s I)/t. Its diagonal scales the GIMP domains (iGIMP, Charlton et
/// al. 2017): a rigid rotation leaves them unchanged, a stretch along an axis scales that axis.
pub fn right_stretch(f: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let c = [
        [f[0][0] * f[0][0] + f[1][0] * f[1][0], f[0][0] * f[0][1] + f[1][0] * f[1][1]],
        [f[0][1] * f[0][0] + f[1][1] * f[1][0], f[0][1] * f[0][1] + f[1][1] * f[1][1]],
    ];
    let s = (c[0][0] * c[1][1] - c[0][1] * c[1][0]).max(0.0).sqrt();
    let t = (c[0][0] + c[1][1] + 2.0 * s).sqrt();
    [[(c[0][0] + s) / t, c[0][1] / t], [c[1][0] / t, (c[1][1] + s) / t]]
}
