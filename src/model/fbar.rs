//! F̄ by volume-averaged projection ([002] §3, Eqs. 18–27, Algorithm 1): the volumetric part of
//! each point's deformation is replaced by a volume-weighted average over the supports of the basis
//! functions it shares with its neighbours, which relieves volumetric locking for any non-negative
//! basis (GIMP, B-splines).
//!
//! Per step, with ΔF_p the point's increment of the deformation gradient, ΔJ_p = det ΔF_p and
//! J̄_p^n = det F̄_p^n (Algorithm 1):
//! 1. P2G (Eq. 19, incremental form Eq. 26): V_i = Σ_p w_ip V_p^n and
//!    (V J̄)_i = Σ_p w_ip V_p^n J̄_p^n ΔJ_p ([`scatter`]);
//! 2. the nodal sums are added over ranks by the caller (they are sums of particle shares);
//! 3. G2P (Eq. 20): J̄_p^{n+1} = Σ_i w_ip (V J̄)_i / V_i ([`gather`]);
//! 4. ΔF̄_p = (J̄_p^{n+1}/(J̄_p^n ΔJ_p))^{1/dim} ΔF_p (Eq. 27, [`scaled_increment`]).
//!
//! These functions are the algorithm's pieces, tested as [002] states them. The explicit step
//! (`assembly::explicit`) projects the points' own J_p^n ΔJ_p rather than J̄_p^n ΔJ_p (one pass,
//! measured: repeating the projection of J̄ every step smooths it without end), and uses
//! [`scale`] both for the increment, (J̄^{n+1}/(J̄^n ΔJ))^{1/dim}, and for a hyperelastic
//! model's total F, (J̄^{n+1}/(J^n ΔJ))^{1/dim}.
//!
//! The weights w_ip are the step's, at x_p^n, in both passes. Only the stress sees F̄; the volume
//! stays det(F) V⁰ ([002] L237). ΔF̄ is ΔF times a scalar, so a pure shear or a rigid motion is
//! untouched and the in-plane deviator of log ΔF̄ is that of log ΔF. dim is 2 in plane strain (the
//! in-plane block is scaled, F_zz = 1 stays) and 3 in axial symmetry and in 3D.

/// A point's share of the nodes: (node index, w_ip).
pub type Shares<'a> = &'a [(usize, f64)];

/// The nodal sums of the projection: V_i = Σ_p w_ip V_p and (V J̄)_i = Σ_p w_ip V_p J̄_p ΔJ_p,
/// over `nodes` nodes. Each point gives its shares, its volume V_p^n and the value J̄_p^n ΔJ_p it
/// brings to the average ([002] Algorithm 1, step 3).
pub fn scatter<'a>(nodes: usize, points: impl IntoIterator<Item = (Shares<'a>, f64, f64)>) -> (Vec<f64>, Vec<f64>) {
    let mut volume = vec![0.0; nodes];
    let mut weighted = vec![0.0; nodes];
    for (shares, v, value) in points {
        for &(i, w) in shares {
            volume[i] += w * v;
            weighted[i] += w * v * value;
        }
    }
    (volume, weighted)
}

/// J̄_p^{n+1} = Σ_i w_ip (V J̄)_i / V_i ([002] Eq. 20 and Algorithm 1, step 4). A node that no point
/// gave volume (V_i = 0) carries no weight for this point either (its w_ip is zero). Since every
/// w_ip ≥ 0 and Σ_i w_ip = 1, the result is a convex combination of the points' values.
pub fn gather(shares: Shares, volume: &[f64], weighted: &[f64]) -> f64 {
    shares.iter().filter(|&&(i, _)| volume[i] > 0.0).map(|&(i, w)| w * weighted[i] / volume[i]).sum()
}

/// The factor c = (J̄_p^{n+1}/(J̄_p^n ΔJ_p))^{1/dim} by which ΔF̄_p = c ΔF_p ([002] Eq. 27):
/// `projected` is J̄_p^{n+1} from [`gather`], `own` the point's J̄_p^n ΔJ_p (or, for the scale of
/// a total F̄ = c F, its J_p^{n+1}: Eq. 18).
pub fn scale(projected: f64, own: f64, dim: usize) -> f64 {
    (projected / own).powf(1.0 / dim as f64)
}

/// ΔF̄ = c ΔF on the in-plane block ([002] Eq. 27 in plane strain, dim = 2; the out-of-plane
/// component of a plane-strain increment is 1 and stays 1).
pub fn scaled_increment(df: [[f64; 2]; 2], c: f64) -> [[f64; 2]; 2] {
    [[c * df[0][0], c * df[0][1]], [c * df[1][0], c * df[1][1]]]
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::model::grid::Grid;
    use crate::model::shape::{self, Basis};

    /// A small deterministic generator (no dependency): uniform in [0, 1).
    pub(crate) struct Lcg(pub u64);
    impl Lcg {
        pub(crate) fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn det(a: [[f64; 2]; 2]) -> f64 {
        a[0][0] * a[1][1] - a[0][1] * a[1][0]
    }

    /// The symmetric logarithm of a 2 × 2 matrix A with positive eigenvalues, through its
    /// symmetric part's eigen-decomposition (the tests use symmetric increments).
    fn log_sym(a: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
        let (p, q, r) = (a[0][0], 0.5 * (a[0][1] + a[1][0]), a[1][1]);
        let m = 0.5 * (p + r);
        let d = (0.25 * (p - r) * (p - r) + q * q).sqrt();
        let (l1, l2) = (m + d, m - d);
        let th = 0.5 * (2.0 * q).atan2(p - r);
        let (c, s) = (th.cos(), th.sin());
        let (g1, g2) = (l1.ln(), l2.ln());
        [[g1 * c * c + g2 * s * s, (g1 - g2) * c * s], [(g1 - g2) * c * s, g1 * s * s + g2 * c * c]]
    }

    struct Cloud {
        shares: Vec<Vec<(usize, f64)>>,
        volume: Vec<f64>,
        jbar: Vec<f64>,
        df: Vec<[[f64; 2]; 2]>,
    }

    /// Points scattered over a 6 × 5 grid (h = 0.5 × 0.4), two per cell on average, with volumes,
    /// J̄^n and symmetric increments ΔF that vary from point to point.
    fn cloud(basis: Basis, rng: &mut Lcg) -> (Grid, Cloud) {
        let grid = Grid::new([0.0, 0.0], [0.5, 0.4], [6, 5]);
        let n = 60;
        let mut c = Cloud { shares: vec![], volume: vec![], jbar: vec![], df: vec![] };
        for _ in 0..n {
            // GIMP domains stay inside the grid (beyond it a domain loses part of its weights).
            let lp = [0.125, 0.1];
            let x = [lp[0] + (3.0 - 2.0 * lp[0]) * rng.next(), lp[1] + (2.0 - 2.0 * lp[1]) * rng.next()];
            let st = shape::stencil(basis, &grid, x, lp);
            c.shares.push(st.iter().map(|([i, j], w, _)| (j as usize * 7 + i as usize, w)).collect());
            c.volume.push(0.05 * (0.5 + rng.next()));
            c.jbar.push(0.9 + 0.2 * rng.next());
            let (a, b, s) = (0.02 * (rng.next() - 0.5), 0.02 * (rng.next() - 0.5), 0.01 * (rng.next() - 0.5));
            c.df.push([[1.0 + a, s], [s, 1.0 + b]]);
        }
        (grid, c)
    }

    fn project(c: &Cloud) -> Vec<f64> {
        let own: Vec<f64> = (0..c.volume.len()).map(|p| c.jbar[p] * det(c.df[p])).collect();
        let (v, vj) = scatter(42, (0..c.volume.len()).map(|p| (c.shares[p].as_slice(), c.volume[p], own[p])));
        c.shares.iter().map(|s| gather(s, &v, &vj)).collect()
    }

    const BASES: [Basis; 3] = [Basis::Gimp, Basis::BSpline2, Basis::BSpline3];

    #[test]
    fn the_projection_conserves_the_volume_weighted_sum() {
        // Σ_p V_p^n J̄_p^{n+1} = Σ_p V_p^n J̄_p^n ΔJ_p (partition of unity, the same weights both
        // ways: the projection's conservation identity).
        let mut rng = Lcg(7);
        for basis in BASES {
            let (_, c) = cloud(basis, &mut rng);
            let projected = project(&c);
            let lhs: f64 = (0..c.volume.len()).map(|p| c.volume[p] * projected[p]).sum();
            let rhs: f64 = (0..c.volume.len()).map(|p| c.volume[p] * c.jbar[p] * det(c.df[p])).sum();
            assert!((lhs - rhs).abs() <= 1e-12 * rhs, "{basis:?}: {lhs} vs {rhs}");
        }
    }

    #[test]
    fn the_projected_value_lies_within_the_points_values() {
        let mut rng = Lcg(11);
        for basis in BASES {
            let (_, c) = cloud(basis, &mut rng);
            let own: Vec<f64> = (0..c.volume.len()).map(|p| c.jbar[p] * det(c.df[p])).collect();
            let (lo, hi) = own.iter().fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
            let projected = project(&c);
            for (p, &j) in projected.iter().enumerate() {
                assert!(
                    j >= lo * (1.0 - 1e-14) && j <= hi * (1.0 + 1e-14),
                    "{basis:?} point {p}: {j} not in [{lo}, {hi}]"
                );
            }
            // The projection smooths: the spread of the projected values is below the points'.
            let (plo, phi) = projected.iter().fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
            assert!(phi - plo < hi - lo, "{basis:?}");
        }
    }

    #[test]
    fn the_scale_takes_the_dim_th_root() {
        // Plane strain scales two axes, axial symmetry and 3D three: c^dim = J̄^{n+1}/(J̄^n ΔJ).
        assert!((scale(1.21, 1.0, 2) - 1.1).abs() < 1e-15);
        assert!((scale(8.0, 1.0, 3) - 2.0).abs() < 1e-15);
        assert!((scale(2.0, 2.0, 3) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn a_uniform_increment_is_left_as_it_is_and_only_the_volume_changes() {
        let mut rng = Lcg(5);
        for basis in BASES {
            let (_, mut c) = cloud(basis, &mut rng);
            // Uniform ΔF and J̄^n: ΔF̄ = ΔF exactly (to round-off).
            let df = [[1.01, 0.004], [-0.003, 0.995]];
            for p in 0..c.volume.len() {
                c.jbar[p] = 1.07;
                c.df[p] = df;
            }
            let projected = project(&c);
            for (p, &j) in projected.iter().enumerate() {
                let k = scale(j, c.jbar[p] * det(df), 2);
                assert!((k - 1.0).abs() < 1e-14, "{basis:?} point {p}: scale {k}");
            }
            // Varying increments: ΔF̄ = c ΔF changes the volume only — det ΔF̄ = J̄^{n+1}/J̄^n and the
            // in-plane deviator of log ΔF̄ equals that of log ΔF.
            let (_, c) = cloud(basis, &mut rng);
            let projected = project(&c);
            for (p, &jp) in projected.iter().enumerate() {
                let own = c.jbar[p] * det(c.df[p]);
                let k = scale(jp, own, 2);
                let dfb = scaled_increment(c.df[p], k);
                assert!((det(dfb) - jp / c.jbar[p]).abs() < 1e-14, "{basis:?} point {p}");
                let (a, b) = (log_sym(c.df[p]), log_sym(dfb));
                let dev = |m: [[f64; 2]; 2]| {
                    let t = 0.5 * (m[0][0] + m[1][1]);
                    [m[0][0] - t, m[0][1], m[1][0], m[1][1] - t]
                };
                let (da, db) = (dev(a), dev(b));
                for k in 0..4 {
                    assert!((da[k] - db[k]).abs() < 1e-14, "{basis:?} point {p}: {da:?} vs {db:?}");
                }
                // Some points do change their volume (the test is not vacuous).
                if p == 0 {
                    assert!((k - 1.0).abs() > 1e-5, "{basis:?}: scale {k}");
                }
            }
        }
    }
}
