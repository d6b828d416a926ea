//! A closed triangulated surface (an STL file's) as a body's region: a point is inside where a
//! ray from it crosses the surface an odd number of times. The ray runs along +z from the point
//! moved by an infinitesimal (ε, ε², ε³) (simulation of simplicity, Edelsbrunner & Mücke 1990):
//! with the exact predicates, a ray through an edge or a vertex, or along a face, is counted once
//! by exactly one of the triangles there, so the answer is exact for a watertight surface, wherever
//! the point lies.

use super::buckets::Buckets;
use super::{c2, c3};
use robust::{orient2d, orient3d};

/// Triangles as a file gives them: vertices and, for each triangle, the indices of its three.
#[derive(Debug, Clone, Default)]
pub struct Triangles {
    /// The vertices.
    pub vertices: Vec<[f64; 3]>,
    /// The triangles' vertices.
    pub triangles: Vec<[usize; 3]>,
}

/// A closed surface of triangles.
#[derive(Clone)]
pub struct Surface {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    lo: [f64; 3],
    hi: [f64; 3],
    buckets: Buckets<2>,
}

impl std::fmt::Debug for Surface {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Surface {{ triangles: {}, bounds: {:?} .. {:?} }}", self.triangles.len(), self.lo, self.hi)
    }
}

/// The sign of x (0 for 0).
fn sign(x: f64) -> i8 {
    (x > 0.0) as i8 - (x < 0.0) as i8
}

/// The side of the directed line u → v the point p + (ε, ε²) lies on: +1 left, −1 right, 0 only
/// where u = v.
fn side(u: [f64; 2], v: [f64; 2], p: [f64; 2]) -> i8 {
    let o = sign(orient2d(c2(u), c2(v), c2(p)));
    if o != 0 {
        o
    } else if v[1] != u[1] {
        sign(u[1] - v[1])
    } else {
        sign(v[0] - u[0])
    }
}

impl Surface {
    /// The surface of `triangles` (indices into `vertices` [m]); an error if it has no triangle or
    /// is not closed (an edge that an odd number of triangles share: a hole or a crack).
    pub fn new(vertices: Vec<[f64; 3]>, triangles: Vec<[usize; 3]>) -> Result<Surface, String> {
        if triangles.is_empty() {
            return Err("it holds no triangle".into());
        }
        let mut edges = std::collections::HashMap::new();
        for t in &triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0usize) += 1;
            }
        }
        let open = edges.values().filter(|&&n| n % 2 == 1).count();
        if open > 0 {
            return Err(format!(
                "it is not closed: {open} of its {} edges belong to an odd number of triangles (a hole or a crack); a \
                 body needs a watertight surface",
                edges.len()
            ));
        }
        let triangles: Vec<[u32; 3]> = triangles.iter().map(|t| t.map(|k| k as u32)).collect();
        let xy = |t: &[u32; 3]| -> ([f64; 2], [f64; 2]) {
            let p = t.map(|k| vertices[k as usize]);
            (
                std::array::from_fn(|d| p[0][d].min(p[1][d]).min(p[2][d])),
                std::array::from_fn(|d| p[0][d].max(p[1][d]).max(p[2][d])),
            )
        };
        let boxes: Vec<_> = triangles.iter().map(xy).collect();
        let lo = std::array::from_fn(|d| vertices.iter().map(|v| v[d]).fold(f64::INFINITY, f64::min));
        let hi = std::array::from_fn(|d| vertices.iter().map(|v| v[d]).fold(f64::NEG_INFINITY, f64::max));
        let buckets = Buckets::new([lo[0], lo[1]], [hi[0], hi[1]], &boxes);
        Ok(Surface { vertices, triangles, lo, hi, buckets })
    }

    /// Its number of triangles.
    pub fn triangles(&self) -> usize {
        self.triangles.len()
    }

    /// Its bounding box [m].
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        (self.lo, self.hi)
    }

    /// The volume it encloses [m³], by the divergence theorem (Σ a · (b × c) / 6 over its
    /// triangles, which a consistent orientation of them needs).
    pub fn volume(&self) -> f64 {
        let sum: f64 = self
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|k| self.vertices[k as usize]);
                super::det3(&[a, b, c])
            })
            .sum();
        (sum / 6.0).abs()
    }

    /// Whether it encloses `p`.
    pub fn holds(&self, p: [f64; 3]) -> bool {
        if (0..3).any(|d| !(p[d] >= self.lo[d] && p[d] <= self.hi[d])) {
            return false;
        }
        let mut inside = false;
        for &i in self.buckets.near([p[0], p[1]]) {
            let [a, b, c] = self.triangles[i as usize].map(|k| self.vertices[k as usize]);
            if self.crosses([a, b, c], p) {
                inside = !inside;
            }
        }
        inside
    }

    /// Whether the ray from p + (ε, ε², ε³) along +z crosses the triangle (a, b, c).
    fn crosses(&self, [a, b, c]: [[f64; 3]; 3], p: [f64; 3]) -> bool {
        let xy = |q: [f64; 3]| [q[0], q[1]];
        let s = side(xy(a), xy(b), xy(p));
        if s == 0 || side(xy(b), xy(c), xy(p)) != s || side(xy(c), xy(a), xy(p)) != s {
            return false;
        }
        // The triangle's normal N = (b − a) × (c − a) has N_z of sign s; p' lies on its −N side
        // (below the triangle) where orient3d(a, b, c, p') = (a − p') · N has the sign of N_z.
        let o = sign(orient3d(c3(a), c3(b), c3(c), c3(p)));
        let below = if o != 0 {
            o
        } else {
            let yz = |q: [f64; 3]| [q[1], q[2]];
            let zx = |q: [f64; 3]| [q[2], q[0]];
            let nx = sign(orient2d(c2(yz(a)), c2(yz(b)), c2(yz(c))));
            let ny = sign(orient2d(c2(zx(a)), c2(zx(b)), c2(zx(c))));
            -[nx, ny, s].into_iter().find(|&n| n != 0).unwrap_or(0)
        };
        below == s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube's surface, two triangles a face, outward.
    fn cube() -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
        let v: Vec<[f64; 3]> = (0..8).map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]).collect();
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let t = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        (v, t)
    }

    /// Points inside and outside the cube, and on its faces, edges and corners, which belong to it
    /// where the infinitesimal move (ε, ε², ε³) takes them inside (the faces x = 0, y = 0, z = 0):
    /// each ray is counted once, whatever edge, vertex or face it runs through; the volume is 1.
    #[test]
    fn a_ray_through_edges_and_vertices_counts_once() {
        let (v, t) = cube();
        let s = Surface::new(v, t).unwrap();
        assert_eq!(s.volume(), 1.0);
        let inside =
            [[0.5, 0.5, 0.5], [0.25, 0.25, 0.1], [0.3, 0.3, 0.9], [0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]];
        for p in inside.into_iter().chain([[0.0, 0.0, 0.0], [0.0, 0.0, 0.5], [0.5, 0.5, 1e-300]]) {
            assert!(s.holds(p), "{p:?}");
        }
        let outside =
            [[0.5, 0.5, 1.0], [1.0, 0.5, 0.5], [0.5, 1.0, 0.5], [1.0, 1.0, 0.5], [1.0, 1.0, 1.0], [0.0, 0.0, 1.0]];
        for p in outside.into_iter().chain([[0.5, 0.5, -0.1], [1.2, 0.5, 0.5], [0.5, -1e-300, 0.5], [0.5, 0.5, -1e-17]])
        {
            assert!(!s.holds(p), "{p:?}");
        }
        // A face on the other side of the cube in x, its triangles' shared diagonal under the point.
        let mut inside = 0;
        let n = 40;
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let p = [(i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64, (k as f64 + 0.5) / n as f64];
                    inside += s.holds(p) as usize;
                }
            }
        }
        assert_eq!(inside, n * n * n);
    }

    /// A surface with a hole, and one without triangles, are refused.
    #[test]
    fn an_open_surface_is_refused() {
        let (v, mut t) = cube();
        t.pop();
        let e = Surface::new(v.clone(), t).unwrap_err();
        assert!(e.contains("not closed: 3 of its 18 edges"), "{e}");
        assert!(Surface::new(v, vec![]).unwrap_err().contains("no triangle"));
    }
}
