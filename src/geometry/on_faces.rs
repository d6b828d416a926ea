//! The nodes of a regular grid that lie on a boundary given by a mesh's curves (plane cases) or
//! faces (three dimensions): those within a small distance of a segment, a triangle or a
//! quadrangle (split into two triangles along its first diagonal).

/// A regular grid's nodes: `origin + i h` for i < `counts` (a plane grid has `counts[2]` = 1).
#[derive(Debug, Clone, Copy)]
pub struct NodeLattice {
    /// The first node [m].
    pub origin: [f64; 3],
    /// The spacing [m].
    pub h: [f64; 3],
    /// The number of nodes along each axis.
    pub counts: [usize; 3],
}

impl NodeLattice {
    /// The indices of the nodes within `tol` [m] of any of `polygons` (segments, triangles and
    /// quadrangles, by their corners), each once, in lexicographic order (z, then y, then x).
    pub fn nodes_on(&self, polygons: &[Vec<[f64; 3]>], tol: f64) -> Vec<[usize; 3]> {
        let mut out = Vec::new();
        for poly in polygons {
            let pieces: Vec<[[f64; 3]; 3]> = match poly.len() {
                2 => vec![[poly[0], poly[1], poly[1]]],
                3 => vec![[poly[0], poly[1], poly[2]]],
                _ => vec![[poly[0], poly[1], poly[2]], [poly[0], poly[2], poly[3]]],
            };
            // The index range of the nodes in the polygon's box widened by `tol`.
            let range = |d: usize| {
                let lo = poly.iter().map(|p| p[d]).fold(f64::INFINITY, f64::min) - tol;
                let hi = poly.iter().map(|p| p[d]).fold(f64::NEG_INFINITY, f64::max) + tol;
                let last = self.counts[d] as f64 - 1.0;
                let first = ((lo - self.origin[d]) / self.h[d]).ceil().clamp(0.0, last.max(0.0));
                let end = ((hi - self.origin[d]) / self.h[d]).floor().min(last);
                (first as usize, end)
            };
            let (rx, ry, rz) = (range(0), range(1), range(2));
            let span = |(first, end): (usize, f64)| (first..).take_while(move |&i| i as f64 <= end);
            for k in span(rz) {
                for j in span(ry) {
                    for i in span(rx) {
                        let p = [0, 1, 2].map(|d| self.origin[d] + [i, j, k][d] as f64 * self.h[d]);
                        if pieces.iter().any(|t| distance_to_triangle(p, t) <= tol) {
                            out.push([i, j, k]);
                        }
                    }
                }
            }
        }
        out.sort_by_key(|n| (n[2], n[1], n[0]));
        out.dedup();
        out
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// The distance from `p` to the segment from `a` to `b` (a point if they coincide).
fn distance_to_segment(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    let t = if len2 > 0.0 { (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    norm(sub(p, [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]]))
}

/// The distance from `p` to the triangle `t` (its interior or its edges; a degenerate triangle is
/// its edges).
fn distance_to_triangle(p: [f64; 3], t: &[[f64; 3]; 3]) -> f64 {
    let edges = distance_to_segment(p, t[0], t[1])
        .min(distance_to_segment(p, t[1], t[2]))
        .min(distance_to_segment(p, t[2], t[0]));
    let (u, v) = (sub(t[1], t[0]), sub(t[2], t[0]));
    let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    let n2 = dot(n, n);
    if n2 <= 0.0 {
        return edges;
    }
    // The projection onto the plane, inside if its barycentric coordinates are all non-negative.
    let w = sub(p, t[0]);
    let (uu, uv, vv, wu, wv) = (dot(u, u), dot(u, v), dot(v, v), dot(w, u), dot(w, v));
    let den = uu * vv - uv * uv;
    let (s, r) = ((vv * wu - uv * wv) / den, (uu * wv - uv * wu) / den);
    if s >= 0.0 && r >= 0.0 && s + r <= 1.0 {
        dot(w, n).abs() / n2.sqrt()
    } else {
        edges
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A segment on a grid line holds the nodes along it and no other; a square face on a grid plane
    /// (two triangles) the nodes on and inside it; a slanted segment only the nodes it passes
    /// through; a point's distance to a triangle's interior is its height above the plane.
    #[test]
    fn the_nodes_on_segments_and_faces() {
        let plane = NodeLattice { origin: [0.0; 3], h: [0.5, 0.5, 1.0], counts: [5, 5, 1] };
        let base = plane.nodes_on(&[vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]]], 1e-9);
        assert_eq!(base, (0..5).map(|i| [i, 0, 0]).collect::<Vec<_>>());
        let diagonal = plane.nodes_on(&[vec![[0.0, 0.0, 0.0], [1.0, 1.0, 0.0]]], 1e-9);
        assert_eq!(diagonal, vec![[0, 0, 0], [1, 1, 0], [2, 2, 0]]);
        let part = plane.nodes_on(&[vec![[0.2, 1.0, 0.0], [1.6, 1.0, 0.0]]], 1e-9);
        assert_eq!(part, vec![[1, 2, 0], [2, 2, 0], [3, 2, 0]]);
        let solid = NodeLattice { origin: [-1.0; 3], h: [1.0; 3], counts: [4, 4, 4] };
        let square = vec![[0.0, 0.0, 1.0], [2.0, 0.0, 1.0], [2.0, 2.0, 1.0], [0.0, 2.0, 1.0]];
        let on = solid.nodes_on(&[square], 1e-9);
        assert_eq!(on.len(), 9, "{on:?}");
        assert!(on.iter().all(|n| n[2] == 2 && n[0] >= 1 && n[1] >= 1));
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert!((distance_to_triangle([0.25, 0.25, 0.3], &t) - 0.3).abs() < 1e-15);
        assert!((distance_to_triangle([2.0, 0.0, 0.0], &t) - 1.0).abs() < 1e-15);
    }
}
