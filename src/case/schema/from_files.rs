//! Bodies made from files: the cells of a Gmsh mesh, filled by their quadrature points, and a
//! closed STL surface, filled like the other shapes at the grid's sub-cell centres it encloses.
//! Validation reads the files (relative to the case file) into the shape before any other check.

use super::solids::Solid;
use crate::check::{at, finite, positive, Checked};
use crate::geometry::{FacePoints, Mesh, PointCloud, Surface};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// A body filled from the cells of a Gmsh mesh.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MeshRegion {
    /// The mesh file, Gmsh's MSH 4.1 (ASCII or binary), relative to the case file [m]. The
    /// body is its first-order cells of the case's dimension: triangles and quadrangles in a plane
    /// or axisymmetric case (x the radius), tetrahedra, hexahedra and prisms in three dimensions.
    pub file: String,
    /// The physical group whose cells the body is, by name (`"soil"`) or tag (default: every cell
    /// of the case's dimension).
    pub group: Option<GroupName>,
    /// The quadrature rule whose points are the body's material points [-]: 1, one point at each
    /// cell's centroid; 2 (the default), three per triangle, four per quadrangle and tetrahedron,
    /// six per prism, eight per hexahedron. Each point carries its weight w |det J| (times the
    /// radius in axial symmetry) as its volume, so that the points' volumes sum to the mesh's;
    /// its GIMP domain is the cube of that volume.
    #[serde(default = "default_order")]
    pub order: usize,
    /// The cells, read by validation.
    #[serde(skip)]
    #[schemars(skip)]
    pub loaded: Option<Arc<Mesh>>,
}

/// A body whose material points a particle file gives one by one.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PointsRegion {
    /// The particle file, relative to the case file: a CSV table whose header names its
    /// columns, `x`, `y` (and `z` in three dimensions) [m] and `volume` [m³; per metre of thickness
    /// in plane strain; the ring's 2πrA in axial symmetry, so r > 0], one row per point, in any
    /// order among other columns (skipped); `#` starts a comment line. Optional columns give each
    /// point its initial velocity `vx`, `vy` (`vz`) [m/s], effective stress `sxx`, `syy`, `sxy`,
    /// `szz` (`syz`, `szx`) [Pa] and pore pressure `p` [Pa] (two-phase; its gradient starts at
    /// zero), instead of the body's own. Each point's GIMP domain is the square (cube) of its area
    /// (volume), and the body's region is the union of those domains; the body's material applies
    /// to every point. An HDF5 file (told by its signature) gives the same columns as
    /// one-dimensional datasets of numbers in its root group, all of one length.
    pub file: String,
    /// The points, read by validation.
    #[serde(skip)]
    #[schemars(skip)]
    pub loaded: Option<Arc<PointCloud>>,
}

impl PointsRegion {
    /// The points (validation has read them).
    pub fn cloud(&self) -> &PointCloud {
        self.loaded.as_deref().expect("validation reads a body's particle file")
    }
}

impl Solid for PointsRegion {
    fn check(&self, _key: &str) -> Checked {
        Ok(())
    }
    fn bounds3(&self) -> ([f64; 3], [f64; 3]) {
        self.cloud().bounds()
    }
    fn holds(&self, p: [f64; 3]) -> bool {
        self.cloud().holds(p)
    }
}

/// A physical group's name or tag.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(untagged)]
pub enum GroupName {
    /// Its tag.
    Tag(i32),
    /// Its name.
    Name(String),
}

/// An STL file (ASCII or binary), scaled and moved into the case's frame: a body's closed surface
/// or the triangles a surface pressure loads.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
#[serde(bound = "")]
#[schemars(bound = "")]
pub struct StlFile<T> {
    /// The STL file, relative to the case file; a body's triangles must close it (every edge
    /// shared by two of them).
    pub file: String,
    /// The length of the file's unit [m] (default 1; 0.001 for a file in millimetres), > 0.
    #[serde(default = "default_scale")]
    pub scale: f64,
    /// Added to every vertex after scaling [m] (default [0, 0, 0]).
    #[serde(default)]
    pub offset: [f64; 3],
    /// What validation reads from it.
    #[serde(skip)]
    #[schemars(skip)]
    pub loaded: Option<Arc<T>>,
}

/// A body bounded by a closed STL surface (three dimensions).
pub type SurfaceRegion = StlFile<Surface>;

impl<T> StlFile<T> {
    /// The file's vertices [file units] scaled and moved into the case's frame [m].
    pub fn placed(&self, vertices: &[[f64; 3]]) -> Vec<[f64; 3]> {
        vertices.iter().map(|v| std::array::from_fn(|d| v[d] * self.scale + self.offset[d])).collect()
    }

    /// Checks the scale and the offset; `key` is its table.
    pub fn check_placement(&self, key: &str) -> Checked {
        positive(&at(key, "scale"), self.scale)?;
        for (d, v) in self.offset.iter().enumerate() {
            finite(&format!("{}[{d}]", at(key, "offset")), *v)?;
        }
        Ok(())
    }
}

serde_defaults! { default_order: usize = 2, default_scale: f64 = 1.0 }

impl MeshRegion {
    /// The cells (validation has read them).
    pub fn mesh(&self) -> &Mesh {
        self.loaded.as_deref().expect("validation reads a body's mesh")
    }

    /// Checks the quadrature order; `key` is its table.
    pub fn check(&self, key: &str) -> Checked {
        if !(1..=2).contains(&self.order) {
            return Err(format!("key `{}`: 1 or 2, got {}", at(key, "order"), self.order));
        }
        Ok(())
    }
}

impl SurfaceRegion {
    /// The surface (validation has read it).
    pub fn surface(&self) -> &Surface {
        self.loaded.as_deref().expect("validation reads a body's surface")
    }
}

impl Solid for SurfaceRegion {
    fn check(&self, key: &str) -> Checked {
        self.check_placement(key)
    }
    fn bounds3(&self) -> ([f64; 3], [f64; 3]) {
        self.surface().bounds()
    }
    fn holds(&self, p: [f64; 3]) -> bool {
        self.surface().holds(p)
    }
}

impl Solid for MeshRegion {
    fn check(&self, key: &str) -> Checked {
        MeshRegion::check(self, key)
    }
    fn bounds3(&self) -> ([f64; 3], [f64; 3]) {
        self.mesh().bounds()
    }
    fn holds(&self, p: [f64; 3]) -> bool {
        self.mesh().holds(p)
    }
}

/// The surface a `surface_pressure` acts on: a Gmsh mesh's triangles and quadrangles or an STL
/// file's triangles, written `{ mesh = { ... } }` or `{ stl = { ... } }`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum LoadSurface {
    /// The two-dimensional cells of a Gmsh mesh.
    Mesh(MeshFaces),
    /// The triangles of an STL file (open or closed).
    Stl(StlFaces),
}

/// The triangles and quadrangles of a Gmsh mesh (of one physical group).
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MeshFaces {
    /// The mesh file, Gmsh's MSH 4.1, relative to the case file.
    pub file: String,
    /// The physical surface whose cells are loaded, by name or tag (default: every triangle and
    /// quadrangle of the mesh).
    pub group: Option<GroupName>,
    /// Their Gauss points, read by validation.
    #[serde(skip)]
    #[schemars(skip)]
    pub loaded: Option<Arc<FacePoints>>,
}

/// The triangles of an STL file (open or closed), as Gauss points with their area vectors.
pub type StlFaces = StlFile<FacePoints>;

/// A boundary's grid nodes from a Gmsh mesh: those on the cells of one physical group of the
/// boundary's dimension (its lines in a plane case, its triangles and quadrangles in three
/// dimensions), within 1e-6 of the smallest cell side of a line or face. The mesh's boundary must
/// lie on grid lines (planes) where it is to hold nodes: a node next to a slanted or curved face is
/// not on it.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MeshBoundary {
    /// The mesh file, Gmsh's MSH 4.1, relative to the case file.
    pub file: String,
    /// The physical curve (plane case) or surface (three dimensions), by name or tag (default:
    /// every line or every triangle and quadrangle of the mesh).
    pub group: Option<GroupName>,
    /// Its cells' corners, read by validation.
    #[serde(skip)]
    #[schemars(skip)]
    pub loaded: Option<Arc<Vec<Vec<[f64; 3]>>>>,
}

impl MeshBoundary {
    /// The cells' corners (validation has read them).
    pub fn polygons(&self) -> &[Vec<[f64; 3]>] {
        self.loaded.as_deref().map_or(&[], |v| v.as_slice())
    }
}

impl LoadSurface {
    /// The file it is read from.
    pub fn file(&self) -> &str {
        match self {
            LoadSurface::Mesh(m) => &m.file,
            LoadSurface::Stl(s) => &s.file,
        }
    }

    /// Its Gauss points with their area vectors (validation has read them).
    pub fn points(&self) -> &[([f64; 3], [f64; 3])] {
        let loaded = match self {
            LoadSurface::Mesh(m) => &m.loaded,
            LoadSurface::Stl(s) => &s.loaded,
        };
        loaded.as_deref().expect("validation reads a loaded surface")
    }

    /// Checks an STL file's scale and offset; `key` is its table.
    pub fn check(&self, key: &str) -> Checked {
        match self {
            LoadSurface::Stl(s) => s.check_placement(&at(key, "stl")),
            LoadSurface::Mesh(_) => Ok(()),
        }
    }
}
