//! The stress and strain vectors [xx, yy, xy, zz, yz, zx] (tensor shear stresses, engineering
//! shear strains) and the 6 × 6 matrices on them, of which a plane-strain or axisymmetric point
//! uses the first four components.

/// Components of the stress and strain vectors.
pub const NS: usize = 6;

/// Components of the stress and strain vectors a plane-strain or axisymmetric point uses
/// ([xx, yy, xy, zz]; its yz and zx are zero).
pub const NS_PLANE: usize = 4;

/// A stress [xx, yy, xy, zz, yz, zx] (tensor shears) or strain (engineering shears) vector.
pub type Stress = [f64; NS];

/// A 6×6 matrix in the stress-vector basis.
pub type Mat6 = [[f64; NS]; NS];

/// The 6×6 identity.
pub const IDENTITY6: Mat6 = {
    let mut m = [[0.0; NS]; NS];
    let mut k = 0;
    while k < NS {
        m[k][k] = 1.0;
        k += 1;
    }
    m
};

/// The block of a 6×6 matrix a plane-strain or axisymmetric point uses ([xx, yy, xy, zz]).
pub fn plane_block(m: &Mat6) -> [[f64; NS_PLANE]; NS_PLANE] {
    std::array::from_fn(|r| std::array::from_fn(|c| m[r][c]))
}

/// The stress vector of a plane state [xx, yy, xy, zz] (yz = zx = 0).
pub fn plane(s: [f64; NS_PLANE]) -> Stress {
    [s[0], s[1], s[2], s[3], 0.0, 0.0]
}

/// σ_m and q = √(3J₂) of a stress [xx, yy, xy, zz, yz, zx].
pub fn invariants(s: &Stress) -> (f64, f64) {
    let m = (s[0] + s[1] + s[3]) / 3.0;
    let d = [s[0] - m, s[1] - m, s[3] - m];
    let shear = s[2] * s[2] + s[4] * s[4] + s[5] * s[5];
    (m, (1.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 2.0 * shear)).sqrt())
}
