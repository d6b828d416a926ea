//! Regions read from files: the cells of a finite-element mesh (a body filled by their quadrature
//! points), a closed triangulated surface (a body bounded by it) and points given one by one (a
//! particle file's). Pure geometry: reading the
//! files is `crate::io::geometry`'s. The tests of which side of a line or plane a point lies on are
//! Shewchuk's exact predicates (Shewchuk 1997; the `robust` crate), so a point on a shared face or edge is decided
//! the same way by every cell and every rank.

mod buckets;
pub mod mesh;
pub mod on_faces;
pub mod points;
pub mod surface;

pub use mesh::{face_points, CellKind, FacePoints, FileCell, Group, Mesh, MeshFile};
pub use on_faces::NodeLattice;
pub use points::{PointCloud, PointFields, PointRows};
pub use surface::{Surface, Triangles};

use robust::{orient2d, orient3d, Coord, Coord3D};

fn c2(p: [f64; 2]) -> Coord<f64> {
    Coord { x: p[0], y: p[1] }
}

fn c3(p: [f64; 3]) -> Coord3D<f64> {
    Coord3D { x: p[0], y: p[1], z: p[2] }
}

/// Half the side of the square (`dim` = 2) or cube (3) of area or volume `measure`: the GIMP
/// half-width of a point given by its measure alone.
pub fn half_side(measure: f64, dim: usize) -> f64 {
    0.5 * measure.powf(1.0 / dim as f64)
}

/// The determinant of a 3 × 3 matrix.
pub(crate) fn det3(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Whether the triangle `t` of the plane holds `p`, its edges included (none if it has no area).
fn triangle_holds(t: [[f64; 2]; 3], p: [f64; 2]) -> bool {
    let s = orient2d(c2(t[0]), c2(t[1]), c2(t[2]));
    s != 0.0 && (0..3).all(|k| orient2d(c2(t[k]), c2(t[(k + 1) % 3]), c2(p)) * s >= 0.0)
}

/// Whether the tetrahedron `t` holds `p`, its faces included (none if it has no volume).
fn tetrahedron_holds(t: [[f64; 3]; 4], p: [f64; 3]) -> bool {
    let s = orient3d(c3(t[0]), c3(t[1]), c3(t[2]), c3(t[3]));
    s != 0.0
        && (0..4).all(|k| {
            let mut q = t;
            q[k] = p;
            orient3d(c3(q[0]), c3(q[1]), c3(q[2]), c3(q[3])) * s >= 0.0
        })
}
