//! The checkerboard index: how much of the pore-pressure field alternates from point to point.
//!
//! The equal-order u–p–U discretisation can let the nodal pressures alternate (±A from node to node,
//! [003] Fig. 12); interpolated to the material points this shows as a pattern that changes sign from
//! one point to the next within and across cells. To separate it from the smooth field, the pore
//! pressures of the particles in the 3 × 3 cells (3 × 3 × 3 in three dimensions) around each cell
//! are fitted by least squares with a quadratic polynomial in the offsets from the cell centre
//! (directions in which the particles do not spread, e.g. across a column one cell wide, get no
//! terms). For every particle of the centre cell the
//! fit gives its smooth part s_k and the residual its alternating part r_k = p_k − s_k. The index is
//!   I = sqrt( Σ r_k² / Σ s_k² )
//! over all particles whose neighbourhood has enough points for the fit. A field that is locally
//! quadratic scores 0, a smooth field O(h³ p‴/p), an alternating pattern of amplitude A about A/|p|.

use crate::algebra::pad3;
use crate::distribution::Owners;
use crate::model::Model;
use crate::parallel::Collective;
use std::cmp::Ordering;
use std::collections::BTreeMap;

/// How the pore pressures deviate from their local smooth fit.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Fit {
    /// The checkerboard index I (see the module's documentation).
    pub index: f64,
    /// The largest deviation |p_k − s_k| of a particle's pressure from its smooth part [Pa].
    pub max_deviation: f64,
}

/// A point of the fit: x, y, z (0 in the plane), its value and its body.
type FitPoint = [f64; 5];

/// A cell of the fit: (i, j, k) (k = 0 in the plane) and the body.
type FitCell = (i64, i64, i64, i64);

/// The checkerboard fit of the current pore pressures (zero when there is no pressure), in any
/// dimension (in three the neighbourhood is 3 × 3 × 3 cells and the polynomial quadratic in the
/// three offsets). Each body is fitted on its own: a jump of the pressure between bodies (a footing
/// on saturated soil) is not an oscillation. Collective and distributed: a rank fits the cells it
/// owns (`owners`), for which it receives the points of the neighbouring cells other ranks hold (a
/// halo one cell wide), and the sums are added over the ranks; no rank gathers the points of all.
pub fn pressure_fit<const D: usize>(model: &Model<D>, owners: &Owners<D>, coll: &Collective) -> Result<Fit, String> {
    let ps = &model.particles;
    let g = &model.grid;
    // In the plane the third direction is one cell of unit size at z = 0.
    let (origin, h) = (pad3(g.origin), std::array::from_fn(|d| if d < D { g.h[d] } else { 1.0 }));
    let cells: [i64; 3] = std::array::from_fn(|d| if d < D { g.cells[d] as i64 } else { 1 });
    let owner = |c: [i64; 3]| owners.rank_of_cell_in(std::array::from_fn(|d| c[d].clamp(0, cells[d] - 1) as usize));
    let me = coll.rank();
    let mut points: Vec<FitPoint> = (0..ps.len())
        .map(|k| {
            let x = pad3(ps.x[k]);
            [x[0], x[1], x[2], ps.p[k], ps.body[k] as f64]
        })
        .collect();
    if coll.size() > 1 {
        let mut outgoing = vec![Vec::new(); coll.size()];
        let mut to = Vec::with_capacity(27);
        let reach = if D == 3 { 1 } else { 0 };
        for p in &points {
            let (i, j, k, _) = cell_of(p, origin, h);
            to.clear();
            for dk in -reach..=reach {
                for dj in -1..=1 {
                    for di in -1..=1 {
                        let c = [i + di, j + dj, k + dk];
                        if (0..3).all(|d| c[d] >= 0 && c[d] < cells[d]) {
                            let r = owner(c);
                            if r != me && !to.contains(&r) {
                                to.push(r);
                            }
                        }
                    }
                }
            }
            for &r in &to {
                outgoing[r].extend_from_slice(p);
            }
        }
        points.extend(coll.exchange(&outgoing).chunks_exact(5).map(|c| [c[0], c[1], c[2], c[3], c[4]]));
    }
    let local = sums_of(&points, origin, h, |c| owner(c) == me);
    let sums = coll.sum(&[local.0, local.1])?;
    let worst = coll.max(&[local.2])?[0];
    Ok(Fit { index: if sums[1] <= 0.0 { 0.0 } else { (sums[0] / sums[1]).sqrt() }, max_deviation: worst })
}

/// The cell (i, j, k) of point `p` and its body (k = 0 in the plane, whose z and origin are 0
/// and whose `h[2]` is 1).
fn cell_of(p: &FitPoint, origin: [f64; 3], h: [f64; 3]) -> FitCell {
    let at = |d: usize| ((p[d] - origin[d]) / h[d]).floor() as i64;
    (at(0), at(1), at(2), p[4] as i64)
}

/// The fit of plane point values `[x, y, p, body]` binned on cells of size `h` from `origin`, each
/// body's points apart.
pub fn fit_of(points: &[[f64; 4]], origin: [f64; 2], h: [f64; 2]) -> Fit {
    let points: Vec<FitPoint> = points.iter().map(|p| [p[0], p[1], 0.0, p[2], p[3]]).collect();
    let (r2, s2, worst) = sums_of(&points, pad3(origin), [h[0], h[1], 1.0], |_| true);
    Fit { index: if s2 <= 0.0 { 0.0 } else { (r2 / s2).sqrt() }, max_deviation: worst }
}

/// Σ r_k², Σ s_k² and max |r_k| over the points of the cells for which `evaluate` holds. The
/// polynomial of a cell has, for each direction in which its neighbourhood's points spread, a
/// linear and a quadratic term, and a cross term for each pair of such directions (in the plane:
/// 1, x, x², y, y², xy).
fn sums_of(points: &[FitPoint], origin: [f64; 3], h: [f64; 3], evaluate: impl Fn([i64; 3]) -> bool) -> (f64, f64, f64) {
    // The cells in order and each cell's points sorted by position (then value and body), so that
    // the sums, and the index to its last bit, do not depend on the order the points came in
    // (a hash map's order changes from run to run; the ranks' halos arrive in any order).
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| {
        points[a].iter().zip(&points[b]).map(|(x, y)| x.total_cmp(y)).find(|o| o.is_ne()).unwrap_or(Ordering::Equal)
    });
    let mut bins: BTreeMap<FitCell, Vec<usize>> = BTreeMap::new();
    for k in order {
        bins.entry(cell_of(&points[k], origin, h)).or_default().push(k);
    }
    let (mut r2, mut s2, mut worst) = (0.0, 0.0, 0.0f64);
    // Scratch reused from cell to cell: the neighbourhood's points, the normal equations (at most
    // ten terms: 1, three linear, three quadratic, three cross).
    let mut nb: Vec<usize> = Vec::new();
    let (mut a, mut rhs) = ([0.0; MAX_TERMS * MAX_TERMS], [0.0; MAX_TERMS]);
    for (&(i, j, k, body), members) in bins.iter().filter(|((i, j, k, _), _)| evaluate([*i, *j, *k])) {
        let centre: [f64; 3] = std::array::from_fn(|d| origin[d] + ([i, j, k][d] as f64 + 0.5) * h[d]);
        let local = |p: &FitPoint| -> [f64; 3] { std::array::from_fn(|d| (p[d] - centre[d]) / h[d]) };
        nb.clear();
        for dk in -1..=1 {
            for dj in -1..=1 {
                for di in -1..=1 {
                    if let Some(v) = bins.get(&(i + di, j + dj, k + dk, body)) {
                        nb.extend(v);
                    }
                }
            }
        }
        // The directions in which the neighbourhood's points spread over more than a cell.
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for &n in &nb {
            let q = local(&points[n]);
            for d in 0..3 {
                (lo[d], hi[d]) = (lo[d].min(q[d]), hi[d].max(q[d]));
            }
        }
        let mut spreads = [0usize; 3];
        let mut directions = 0;
        for d in (0..3).filter(|&d| hi[d] - lo[d] > 1.0) {
            spreads[directions] = d;
            directions += 1;
        }
        let spreads = &spreads[..directions];
        let m = basis([0.0; 3], spreads).1;
        if nb.len() < m + 2 {
            continue;
        }
        let (a, rhs) = (&mut a[..m * m], &mut rhs[..m]);
        a.fill(0.0);
        rhs.fill(0.0);
        // The normal matrix is symmetric: its upper triangle is summed and mirrored (the same
        // products in the same order as the full matrix, so the same values to the last bit).
        for &n in &nb {
            let (q, _) = basis(local(&points[n]), spreads);
            for r in 0..m {
                rhs[r] += q[r] * points[n][3];
                for c in r..m {
                    a[r * m + c] += q[r] * q[c];
                }
            }
        }
        for r in 0..m {
            for c in 0..r {
                a[r * m + c] = a[c * m + r];
            }
        }
        let Some(coef) = solve(a, rhs, m) else { continue };
        for &n in members {
            let s: f64 = basis(local(&points[n]), spreads).0[..m].iter().zip(&coef).map(|(q, c)| q * c).sum();
            r2 += (points[n][3] - s).powi(2);
            s2 += s * s;
            worst = worst.max((points[n][3] - s).abs());
        }
    }
    (r2, s2, worst)
}

/// The most terms of a cell's polynomial: 1 and, in three directions, three linear, three
/// quadratic and three cross terms.
const MAX_TERMS: usize = 10;

/// The polynomial's terms at the offsets `q` (in cells) for the directions `spreads`: 1, then each
/// direction's linear and quadratic term, then the cross terms of each pair (zero beyond them),
/// and how many there are.
fn basis(q: [f64; 3], spreads: &[usize]) -> ([f64; MAX_TERMS], usize) {
    let mut b = [0.0; MAX_TERMS];
    b[0] = 1.0;
    let mut n = 1;
    for &d in spreads {
        b[n] = q[d];
        b[n + 1] = q[d] * q[d];
        n += 2;
    }
    for (a, &d) in spreads.iter().enumerate() {
        for &e in &spreads[a + 1..] {
            b[n] = q[d] * q[e];
            n += 1;
        }
    }
    (b, n)
}

/// Solves the m × m system by Gaussian elimination with partial pivoting; `None` if singular.
fn solve(a: &mut [f64], b: &mut [f64], m: usize) -> Option<Vec<f64>> {
    let scale = a.iter().fold(0.0f64, |x, v| x.max(v.abs()));
    for col in 0..m {
        let piv = (col..m).max_by(|&x, &y| a[x * m + col].abs().total_cmp(&a[y * m + col].abs()))?;
        if a[piv * m + col].abs() <= 1e-12 * scale {
            return None;
        }
        for c in 0..m {
            a.swap(col * m + c, piv * m + c);
        }
        b.swap(col, piv);
        for r in col + 1..m {
            let f = a[r * m + col] / a[col * m + col];
            for c in col..m {
                a[r * m + c] -= f * a[col * m + c];
            }
            b[r] -= f * b[col];
        }
    }
    let mut x = vec![0.0; m];
    for r in (0..m).rev() {
        let s: f64 = (r + 1..m).map(|c| a[r * m + c] * x[c]).sum();
        x[r] = (b[r] - s) / a[r * m + r];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fit of point values `[x, y, p]` of one body.
    fn fit_of3(points: &[[f64; 3]], origin: [f64; 2], h: [f64; 2]) -> Fit {
        let with_body: Vec<[f64; 4]> = points.iter().map(|p| [p[0], p[1], p[2], 0.0]).collect();
        fit_of(&with_body, origin, h)
    }

    /// The index of point values `[x, y, p]` of one body.
    fn index_of(points: &[[f64; 3]], origin: [f64; 2], h: [f64; 2]) -> f64 {
        fit_of3(points, origin, h).index
    }

    /// 2 × 2 points per cell on 10 × 8 cells of 0.5 × 0.25, values from `f`.
    fn points(f: impl Fn(f64, f64, i64, i64) -> f64) -> Vec<[f64; 3]> {
        let mut v = Vec::new();
        for j in 0..16i64 {
            for i in 0..20i64 {
                let (x, y) = ((i as f64 + 0.5) * 0.25, (j as f64 + 0.5) * 0.125);
                v.push([x, y, f(x, y, i, j)]);
            }
        }
        v
    }

    #[test]
    fn smooth_fields_score_nearly_zero_and_alternating_patterns_their_amplitude() {
        let (o, h) = ([0.0, 0.0], [0.5, 0.25]);
        assert!(index_of(&points(|x, y, _, _| 5.0 + 2.0 * x - 3.0 * y + x * y), o, h) < 1e-12);
        // A steep exponential boundary layer (decay length 1.5 cells) still scores small.
        let bl = index_of(&points(|_, y, _, _| 10.0 * (1.0 - (-(2.0 - y) / 0.375).exp())), o, h);
        assert!(bl < 2e-2, "boundary layer {bl}");
        // ±1 alternating from point to point on a uniform 10.
        let cb = index_of(&points(|_, _, i, j| 10.0 + if (i + j) % 2 == 0 { 1.0 } else { -1.0 }), o, h);
        assert!((cb - 0.1).abs() < 0.01, "{cb}");
        assert_eq!(index_of(&[], o, h), 0.0);
    }

    #[test]
    fn the_largest_deviation_is_the_amplitude_of_the_pattern() {
        let (o, h) = ([0.0, 0.0], [0.5, 0.25]);
        let smooth = fit_of3(&points(|x, y, _, _| 5.0 + 2.0 * x - 3.0 * y), o, h);
        assert!(smooth.max_deviation < 1e-12, "{smooth:?}");
        // ±1 alternating on 10 + x: the interior points deviate by about 1 from their fit (a fit
        // over 3 × 3 cells takes up a little of the pattern at the edges).
        let cb = fit_of3(&points(|x, _, i, j| 10.0 + x + if (i + j) % 2 == 0 { 1.0 } else { -1.0 }), o, h);
        assert!(cb.max_deviation > 0.9 && cb.max_deviation < 1.5, "{cb:?}");
        // One particle off by 3 in a smooth field stands out.
        let spike = fit_of3(&points(|_, _, i, j| 10.0 + if (i, j) == (9, 7) { 3.0 } else { 0.0 }), o, h);
        assert!(spike.max_deviation > 2.0 && spike.max_deviation <= 3.0, "{spike:?}");
        // Two bodies with different uniform pressures side by side: no oscillation.
        let two: Vec<[f64; 4]> = points(|x, _, _, _| if x < 2.5 { 10.0 } else { 0.0 })
            .iter()
            .map(|p| [p[0], p[1], p[2], if p[0] < 2.5 { 0.0 } else { 1.0 }])
            .collect();
        assert!(fit_of(&two, o, h).max_deviation < 1e-12);
        // The same jump inside one body is one.
        let one: Vec<[f64; 4]> = two.iter().map(|p| [p[0], p[1], p[2], 0.0]).collect();
        assert!(fit_of(&one, o, h).max_deviation > 1.0);
    }

    /// In three dimensions (2 points per cell and direction on 6 × 5 × 4 cells of 0.5 × 0.25 × 0.4):
    /// a quadratic field in x, y and z (with all three cross terms) scores 0, ±1 alternating from
    /// point to point on 10 about 0.1.
    #[test]
    fn three_dimensional_fields_are_fitted_over_their_neighbourhood_of_cells() {
        let (o, h) = ([0.0; 3], [0.5, 0.25, 0.4]);
        let field = |f: &dyn Fn([f64; 3], i64) -> f64| -> Vec<FitPoint> {
            let mut v = Vec::new();
            for k in 0..8i64 {
                for j in 0..10i64 {
                    for i in 0..12i64 {
                        let x = [(i as f64 + 0.5) * 0.25, (j as f64 + 0.5) * 0.125, (k as f64 + 0.5) * 0.2];
                        v.push([x[0], x[1], x[2], f(x, i + j + k), 0.0]);
                    }
                }
            }
            v
        };
        let index = |pts: &[FitPoint]| {
            let (r2, s2, _) = sums_of(pts, o, h, |_| true);
            (r2 / s2).sqrt()
        };
        let smooth =
            field(&|x, _| 5.0 + 2.0 * x[0] - 3.0 * x[1] + x[2] * x[2] + 0.5 * x[0] * x[1] + x[0] * x[2] - x[1] * x[2]);
        assert!(index(&smooth) < 1e-12, "{}", index(&smooth));
        let cb = index(&field(&|_, n| 10.0 + if n % 2 == 0 { 1.0 } else { -1.0 }));
        assert!((cb - 0.1).abs() < 0.01, "{cb}");
        // Binned without z (one layer of huge cells along z: no z terms) the xz and yz parts remain.
        let (r2, s2, _) = sums_of(&smooth, o, [0.5, 0.25, 1e9], |_| true);
        assert!((r2 / s2).sqrt() > 1e-3);
    }

    #[test]
    fn the_fit_does_not_depend_on_the_order_of_the_points() {
        // A field with a boundary layer and a pattern, so that the sums carry round-off.
        let (o, h) = ([0.0, 0.0], [0.5, 0.25]);
        let field = points(|x, y, i, j| {
            10.0 * (1.0 - (-(2.0 - y) / 0.375).exp()) + 0.3 * x * x + if (i + j) % 2 == 0 { 0.1 } else { -0.1 }
        });
        let first = fit_of3(&field, o, h);
        let mut shuffled = field.clone();
        for k in 0..shuffled.len() {
            shuffled.swap(k, (k * 7919 + 13) % field.len());
        }
        let reversed: Vec<[f64; 3]> = field.iter().rev().copied().collect();
        for (name, other) in [("shuffled", &shuffled), ("reversed", &reversed), ("again", &field)] {
            let fit = fit_of3(other, o, h);
            assert_eq!(fit.index.to_bits(), first.index.to_bits(), "{name}: {fit:?} against {first:?}");
            assert_eq!(fit.max_deviation.to_bits(), first.max_deviation.to_bits(), "{name}");
        }
    }

    #[test]
    fn a_column_one_cell_wide_is_measured_along_its_axis() {
        let col: Vec<[f64; 3]> = (0..40)
            .map(|j| {
                let y = (j as f64 + 0.5) * 0.025;
                [0.025 + 0.05 * (j % 2) as f64, y, 10.0 + y + if j % 2 == 0 { 0.5 } else { -0.5 }]
            })
            .collect();
        let ci = index_of(&col, [0.0, 0.0], [0.1, 0.05]);
        assert!(ci > 0.03 && ci < 0.06, "{ci}");
        let smooth: Vec<[f64; 3]> = col.iter().map(|p| [p[0], p[1], 10.0 + p[1] * p[1]]).collect();
        assert!(index_of(&smooth, [0.0, 0.0], [0.1, 0.05]) < 1e-12);
    }
}
