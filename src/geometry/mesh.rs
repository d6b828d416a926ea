//! The cells of a finite-element mesh as a body's region: its points are the cells' quadrature
//! points, each with the volume its weight carries (the Gauss rule's w |det J|, so that the points'
//! volumes sum to the mesh's), and a point belongs to it where a cell holds the point.

use super::buckets::Buckets;

/// A first-order cell, with Gmsh's numbering of its nodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellKind {
    /// A two-node line (a plane case's boundary curve).
    Line,
    /// A three-node triangle.
    Triangle,
    /// A four-node quadrangle.
    Quadrangle,
    /// A four-node tetrahedron.
    Tetrahedron,
    /// An eight-node hexahedron.
    Hexahedron,
    /// A six-node prism (a triangle swept along its third coordinate).
    Prism,
}

impl CellKind {
    /// Its dimension.
    pub fn dim(self) -> usize {
        match self {
            CellKind::Line => 1,
            CellKind::Triangle | CellKind::Quadrangle => 2,
            _ => 3,
        }
    }

    /// Its number of nodes.
    pub fn nodes(self) -> usize {
        match self {
            CellKind::Line => 2,
            CellKind::Triangle => 3,
            CellKind::Quadrangle | CellKind::Tetrahedron => 4,
            CellKind::Hexahedron => 8,
            CellKind::Prism => 6,
        }
    }

    /// Its quadrature rule of `order` (1: one point at the centroid; 2: the degree-2 rule, three
    /// points on a triangle, four on a tetrahedron, 2 × 2 Gauss points on a quadrangle, 2 × 2 × 2 on a
    /// hexahedron, three times two on a prism): the points in reference coordinates and their weights
    /// (summing to the reference cell's measure).
    fn rule(self, order: usize) -> Vec<([f64; 3], f64)> {
        let g = 1.0 / 3f64.sqrt();
        let line: &[(f64, f64)] = if order == 1 { &[(0.0, 2.0)] } else { &[(-g, 1.0), (g, 1.0)] };
        let triangle: &[([f64; 2], f64)] = if order == 1 {
            &[([1.0 / 3.0, 1.0 / 3.0], 0.5)]
        } else {
            &[
                ([1.0 / 6.0, 1.0 / 6.0], 1.0 / 6.0),
                ([2.0 / 3.0, 1.0 / 6.0], 1.0 / 6.0),
                ([1.0 / 6.0, 2.0 / 3.0], 1.0 / 6.0),
            ]
        };
        match self {
            CellKind::Line => line.iter().map(|&(a, w)| ([a, 0.0, 0.0], w)).collect(),
            CellKind::Triangle => triangle.iter().map(|&([a, b], w)| ([a, b, 0.0], w)).collect(),
            CellKind::Quadrangle => {
                line.iter().flat_map(|&(b, wb)| line.iter().map(move |&(a, wa)| ([a, b, 0.0], wa * wb))).collect()
            }
            CellKind::Hexahedron => line
                .iter()
                .flat_map(|&(c, wc)| {
                    line.iter().flat_map(move |&(b, wb)| line.iter().map(move |&(a, wa)| ([a, b, c], wa * wb * wc)))
                })
                .collect(),
            CellKind::Prism => {
                line.iter().flat_map(|&(c, wc)| triangle.iter().map(move |&([a, b], w)| ([a, b, c], w * wc))).collect()
            }
            CellKind::Tetrahedron if order == 1 => vec![([0.25; 3], 1.0 / 6.0)],
            CellKind::Tetrahedron => {
                let (a, b) = (0.585_410_196_624_968_5, 0.138_196_601_125_010_5);
                [[b, b, b], [a, b, b], [b, a, b], [b, b, a]].into_iter().map(|x| (x, 1.0 / 24.0)).collect()
            }
        }
    }

    /// Its shape functions and their derivatives in reference coordinates at `r`.
    fn shape(self, r: [f64; 3]) -> ([f64; 8], [[f64; 3]; 8]) {
        let (mut n, mut dn) = ([0.0; 8], [[0.0; 3]; 8]);
        let [a, b, c] = r;
        match self {
            CellKind::Triangle => {
                n[..3].copy_from_slice(&[1.0 - a - b, a, b]);
                dn[..3].copy_from_slice(&[[-1.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
            }
            CellKind::Tetrahedron => {
                n[..4].copy_from_slice(&[1.0 - a - b - c, a, b, c]);
                dn[..4].copy_from_slice(&[[-1.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
            }
            CellKind::Line | CellKind::Quadrangle | CellKind::Hexahedron => {
                let corners = [[-1.0, -1.0, -1.0], [1.0, -1.0, -1.0], [1.0, 1.0, -1.0], [-1.0, 1.0, -1.0]];
                let dims = self.dim();
                for i in 0..self.nodes() {
                    let s = [corners[i % 4][0], corners[i % 4][1], if i < 4 { -1.0 } else { 1.0 }];
                    let f: [f64; 3] = std::array::from_fn(|d| if d < dims { 0.5 * (1.0 + s[d] * r[d]) } else { 1.0 });
                    n[i] = f[0] * f[1] * f[2];
                    for d in 0..dims {
                        let others: f64 = (0..3).filter(|&e| e != d).map(|e| f[e]).product();
                        dn[i][d] = 0.5 * s[d] * others;
                    }
                }
            }
            CellKind::Prism => {
                let t = [1.0 - a - b, a, b];
                let dt = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
                for i in 0..6 {
                    let (k, s) = (i % 3, if i < 3 { -1.0 } else { 1.0 });
                    let h = 0.5 * (1.0 + s * c);
                    n[i] = t[k] * h;
                    dn[i] = [dt[k][0] * h, dt[k][1] * h, t[k] * 0.5 * s];
                }
            }
        }
        (n, dn)
    }

    /// The tetrahedra (or, in the plane, triangles) its region splits into, by local node: exact
    /// for cells with plane faces (Gmsh's first-order cells of a straight-sided geometry).
    fn simplices(self) -> &'static [[usize; 4]] {
        match self {
            CellKind::Line => &[[0, 1, 1, 0]],
            CellKind::Triangle => &[[0, 1, 2, 0]],
            CellKind::Quadrangle => &[[0, 1, 2, 0], [0, 2, 3, 0]],
            CellKind::Tetrahedron => &[[0, 1, 2, 3]],
            CellKind::Hexahedron => {
                &[[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]
            }
            CellKind::Prism => &[[0, 1, 2, 5], [0, 1, 5, 4], [0, 4, 5, 3]],
        }
    }
}

/// A cell as read from a mesh file: its kind, its nodes (indices into the file's node list) and
/// the physical groups of the entity it belongs to.
#[derive(Debug, Clone)]
pub struct FileCell {
    /// Its kind.
    pub kind: CellKind,
    /// Its nodes, in the kind's order.
    pub nodes: Vec<usize>,
    /// The physical group tags of its entity.
    pub groups: Vec<i32>,
}

/// What a mesh file holds, as read (`crate::io::geometry`).
#[derive(Debug, Clone, Default)]
pub struct MeshFile {
    /// Node coordinates [m].
    pub nodes: Vec<[f64; 3]>,
    /// The first-order cells of dimension 1 to 3.
    pub cells: Vec<FileCell>,
    /// The physical groups' names: (dimension, tag, name).
    pub names: Vec<(usize, i32, String)>,
    /// Cells of dimension 1 to 3 of a kind no body or boundary is made from: (dimension, kind, count).
    pub other_cells: Vec<(usize, String, usize)>,
}

impl MeshFile {
    /// The tag of `group` among the physical groups of dimension `dim` (none for no group); an
    /// unknown name is an error listing the groups there are.
    fn group_tag(&self, dim: usize, group: Option<Group>) -> Result<Option<i32>, String> {
        match group {
            None => Ok(None),
            Some(Group::Tag(t)) => Ok(Some(t)),
            Some(Group::Name(name)) => {
                let found = self.names.iter().find(|(d, _, n)| *d == dim && n == name);
                found.map(|&(_, t, _)| Some(t)).ok_or_else(|| {
                    let known: Vec<String> = self
                        .names
                        .iter()
                        .filter(|(d, _, _)| *d == dim)
                        .map(|(_, t, n)| format!("\"{n}\" ({t})"))
                        .collect();
                    format!(
                        "it has no physical group of dimension {dim} named \"{name}\"; it has {}",
                        if known.is_empty() { "none".to_string() } else { known.join(", ") }
                    )
                })
            }
        }
    }

    /// Its cells of dimension `dim` in the physical group of tag `tag` (all without one).
    fn cells_of(&self, dim: usize, tag: Option<i32>) -> impl Iterator<Item = &FileCell> {
        self.cells.iter().filter(move |c| c.kind.dim() == dim && tag.is_none_or(|t| c.groups.contains(&t)))
    }

    /// The cells of dimension `dim` in `group` (all without one) as the positions of their
    /// corners: segments, triangles and quadrangles (a boundary's curves or faces); an error if
    /// there are none.
    pub fn polygons(&self, dim: usize, group: Option<Group>) -> Result<Vec<Vec<[f64; 3]>>, String> {
        let tag = self.group_tag(dim, group)?;
        let out: Vec<Vec<[f64; 3]>> =
            self.cells_of(dim, tag).map(|c| c.nodes.iter().map(|&n| self.nodes[n]).collect()).collect();
        if out.is_empty() {
            let what = if dim == 1 { "line" } else { "triangle or quadrangle" };
            return Err(match tag {
                Some(t) => format!("its physical group {t} of dimension {dim} holds no {what}"),
                None => format!("it holds no {what}"),
            });
        }
        Ok(out)
    }

    /// The Gauss points of its two-dimensional cells in `group` (all without one), each with the
    /// area vector it stands for ([`face_points`]); an error if there are none.
    pub fn face_points(&self, group: Option<Group>) -> Result<FacePoints, String> {
        let tag = self.group_tag(2, group)?;
        let points = face_points(&self.nodes, self.cells_of(2, tag).map(|c| (c.kind, c.nodes.as_slice())));
        if points.is_empty() {
            return Err(match tag {
                Some(t) => format!("its physical group {t} holds no triangle or quadrangle"),
                None => "it holds no triangle or quadrangle".into(),
            });
        }
        Ok(points)
    }
}

/// The Gauss points of a surface, each with the area vector it stands for [m, m²].
pub type FacePoints = Vec<([f64; 3], [f64; 3])>;

/// The Gauss points of order 2 of surface cells (triangles, quadrangles) in space, each with the
/// area vector it stands for, w (∂x/∂ξ × ∂x/∂η): its length is the point's share of the cell's
/// area, its direction the cell's normal by the right-hand rule on its nodes' order.
pub fn face_points<'a>(nodes: &[[f64; 3]], faces: impl Iterator<Item = (CellKind, &'a [usize])>) -> FacePoints {
    let mut out = Vec::new();
    for (kind, local) in faces {
        for (r, w) in kind.rule(2) {
            let (n, dn) = kind.shape(r);
            let (mut x, mut t1, mut t2) = ([0.0; 3], [0.0; 3], [0.0; 3]);
            for (k, &node) in local.iter().enumerate().take(kind.nodes()) {
                for a in 0..3 {
                    x[a] += n[k] * nodes[node][a];
                    t1[a] += dn[k][0] * nodes[node][a];
                    t2[a] += dn[k][1] * nodes[node][a];
                }
            }
            let area = [t1[1] * t2[2] - t1[2] * t2[1], t1[2] * t2[0] - t1[0] * t2[2], t1[0] * t2[1] - t1[1] * t2[0]];
            out.push((x, area.map(|v| w * v)));
        }
    }
    out
}

/// A physical group, by name or by tag.
#[derive(Debug, Clone, PartialEq)]
pub enum Group<'a> {
    /// Its name.
    Name(&'a str),
    /// Its tag.
    Tag(i32),
}

/// The cells of one dimension of a mesh (one physical group's, or all), ready to give a body's
/// points and to say whether it holds a point.
#[derive(Clone)]
pub struct Mesh {
    dim: usize,
    nodes: Vec<[f64; 3]>,
    cells: Vec<(CellKind, [u32; 8])>,
    lo: [f64; 3],
    hi: [f64; 3],
    buckets: Buckets<3>,
}

impl std::fmt::Debug for Mesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Mesh {{ dim: {}, cells: {}, bounds: {:?} .. {:?} }}", self.dim, self.cells.len(), self.lo, self.hi)
    }
}

impl Mesh {
    /// The cells of dimension `dim` of `file` in `group` (all of them without one); an error says
    /// what the file has instead.
    pub fn select(file: &MeshFile, dim: usize, group: Option<Group>) -> Result<Mesh, String> {
        if let Some((_, kind, count)) = file.other_cells.iter().find(|(d, _, _)| *d == dim) {
            return Err(format!(
                "it holds {count} cells of type {kind}, which no body is filled from: mesh with first-order \
                 triangles, quadrangles, tetrahedra, hexahedra or prisms (Gmsh's Mesh.ElementOrder = 1)"
            ));
        }
        let tag = file.group_tag(dim, group)?;
        let mut cells = Vec::new();
        let mut used = vec![u32::MAX; file.nodes.len()];
        let mut nodes = Vec::new();
        for (i, c) in file.cells_of(dim, tag).enumerate() {
            let mut local = [0u32; 8];
            for (k, &n) in c.nodes.iter().enumerate() {
                if dim == 2 && file.nodes[n][2] != 0.0 {
                    return Err(format!(
                        "its cell {i} of dimension 2 lies off the plane z = 0 (a node at z = {}): a plane case \
                         takes a mesh drawn in the (x, y) plane",
                        file.nodes[n][2]
                    ));
                }
                if used[n] == u32::MAX {
                    used[n] = nodes.len() as u32;
                    nodes.push(file.nodes[n]);
                }
                local[k] = used[n];
            }
            cells.push((c.kind, local));
        }
        if cells.is_empty() {
            return Err(match tag {
                Some(t) => format!("its physical group {t} holds no cell of dimension {dim}"),
                None => format!("it holds no cell of dimension {dim}"),
            });
        }
        Ok(Mesh::new(dim, nodes, cells))
    }

    fn new(dim: usize, nodes: Vec<[f64; 3]>, cells: Vec<(CellKind, [u32; 8])>) -> Mesh {
        let boxes: Vec<([f64; 3], [f64; 3])> = cells.iter().map(|c| cell_box(&nodes, c)).collect();
        let lo = std::array::from_fn(|d| boxes.iter().map(|b| b.0[d]).fold(f64::INFINITY, f64::min));
        let hi = std::array::from_fn(|d| boxes.iter().map(|b| b.1[d]).fold(f64::NEG_INFINITY, f64::max));
        let buckets = Buckets::new(lo, hi, &boxes);
        Mesh { dim, nodes, cells, lo, hi, buckets }
    }

    /// Its dimension.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Its number of cells.
    pub fn cells(&self) -> usize {
        self.cells.len()
    }

    /// Its bounding box [m].
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        (self.lo, self.hi)
    }

    /// The largest number of quadrature points of `order` in one cell.
    pub fn points_per_cell(&self, order: usize) -> usize {
        self.cells.iter().map(|c| c.0).fold(1, |m, k| m.max(k.rule(order).len()))
    }

    /// Calls `f(number, x, weight)` for every quadrature point of `order` of every cell: its
    /// number (cell × [`Mesh::points_per_cell`] + its index in the cell, the same on every rank), its
    /// position [m] and its weight w |det J| [m², or m³ in three dimensions]. A cell of zero
    /// measure at a point is an error naming the cell.
    pub fn for_each_point(&self, order: usize, mut f: impl FnMut(u64, [f64; 3], f64)) -> Result<(), String> {
        let per = self.points_per_cell(order) as u64;
        for (i, (kind, nodes)) in self.cells.iter().enumerate() {
            for (q, (r, w)) in kind.rule(order).into_iter().enumerate() {
                let (n, dn) = kind.shape(r);
                let mut x = [0.0; 3];
                let mut jac = [[0.0; 3]; 3];
                for k in 0..kind.nodes() {
                    let p = self.nodes[nodes[k] as usize];
                    for a in 0..3 {
                        x[a] += n[k] * p[a];
                        for b in 0..self.dim {
                            jac[a][b] += dn[k][b] * p[a];
                        }
                    }
                }
                let det = if self.dim == 2 { jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0] } else { super::det3(&jac) };
                if det == 0.0 || !det.is_finite() {
                    return Err(format!("its cell {i} ({kind:?}) has no measure (its nodes are {nodes:?})"));
                }
                f(i as u64 * per + q as u64, x, w * det.abs());
            }
        }
        Ok(())
    }

    /// Whether a cell holds `p` (its boundary included).
    pub fn holds(&self, p: [f64; 3]) -> bool {
        let p = if self.dim == 2 { [p[0], p[1], 0.0] } else { p };
        self.buckets.near(p).iter().any(|&i| {
            let c = &self.cells[i as usize];
            let (lo, hi) = cell_box(&self.nodes, c);
            (0..self.dim).all(|d| p[d] >= lo[d] && p[d] <= hi[d]) && self.cell_holds(c, p)
        })
    }

    fn cell_holds(&self, (kind, nodes): &(CellKind, [u32; 8]), p: [f64; 3]) -> bool {
        let x = |k: usize| self.nodes[nodes[k] as usize];
        kind.simplices().iter().any(|s| {
            if self.dim == 2 {
                let q = |k: usize| [x(s[k])[0], x(s[k])[1]];
                super::triangle_holds([q(0), q(1), q(2)], [p[0], p[1]])
            } else {
                super::tetrahedron_holds([x(s[0]), x(s[1]), x(s[2]), x(s[3])], p)
            }
        })
    }
}

/// The bounding box of a cell.
fn cell_box(nodes: &[[f64; 3]], (kind, n): &(CellKind, [u32; 8])) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &k in &n[..kind.nodes()] {
        for d in 0..3 {
            lo[d] = lo[d].min(nodes[k as usize][d]);
            hi[d] = hi[d].max(nodes[k as usize][d]);
        }
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(nodes: Vec<[f64; 3]>, cells: Vec<(CellKind, Vec<usize>)>) -> MeshFile {
        MeshFile {
            nodes,
            cells: cells.into_iter().map(|(kind, nodes)| FileCell { kind, nodes, groups: vec![1] }).collect(),
            ..MeshFile::default()
        }
    }

    fn total(m: &Mesh, order: usize) -> f64 {
        let mut v = 0.0;
        m.for_each_point(order, |_, _, w| v += w).unwrap();
        v
    }

    /// A distorted hexahedron, the prism and the six tetrahedra it splits into: the quadrature
    /// of order 2 gives each its volume (the tetrahedra's by the determinant), and the cells hold
    /// their centroids and not a point beyond a face.
    #[test]
    fn cells_have_their_volume_and_hold_their_points() {
        let hex = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.5, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [2.0, 0.0, 1.3],
            [2.0, 1.5, 1.3],
            [0.0, 1.0, 1.0],
        ];
        let m = Mesh::select(&file(hex.clone(), vec![(CellKind::Hexahedron, (0..8).collect())]), 3, None).unwrap();
        let tets: f64 = CellKind::Hexahedron
            .simplices()
            .iter()
            .map(|s| {
                let e = |k: usize| std::array::from_fn::<f64, 3, _>(|d| hex[s[k]][d] - hex[s[0]][d]);
                crate::geometry::det3(&[e(1), e(2), e(3)]).abs() / 6.0
            })
            .sum();
        assert!((total(&m, 2) - tets).abs() < 1e-14 * tets, "{} {tets}", total(&m, 2));
        assert!(m.holds([1.0, 0.6, 0.5]) && !m.holds([1.0, 1.4, 0.5]) && !m.holds([1.0, 0.6, 1.2]));
        let prism =
            vec![[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0], [0.0, 0.0, 3.0], [1.0, 0.0, 3.0], [0.0, 1.0, 3.0]];
        let m = Mesh::select(&file(prism, vec![(CellKind::Prism, (0..6).collect())]), 3, None).unwrap();
        assert!((total(&m, 2) - 1.0).abs() < 1e-15 && (total(&m, 1) - 1.0).abs() < 1e-15);
        assert!(m.holds([0.2, 0.2, 2.9]) && !m.holds([0.6, 0.6, 2.0]) && !m.holds([0.2, 0.2, 0.9]));
    }

    /// A quadrangle and a triangle in the plane: the points' weights sum to the areas, and the
    /// moment Σ w x to ∫ x dA (what an axisymmetric volume needs) with order 2.
    #[test]
    fn plane_cells_integrate_area_and_first_moment() {
        let nodes = vec![[1.0, 0.0, 0.0], [3.0, 0.0, 0.0], [2.5, 2.0, 0.0], [1.0, 1.0, 0.0], [4.0, 0.0, 0.0]];
        let cells = vec![(CellKind::Quadrangle, vec![0, 1, 2, 3]), (CellKind::Triangle, vec![1, 4, 2])];
        let m = Mesh::select(&file(nodes.clone(), cells), 2, None).unwrap();
        let poly = [[1.0, 0.0], [3.0, 0.0], [4.0, 0.0], [2.5, 2.0], [1.0, 1.0]];
        let (mut area, mut moment) = (0.0, 0.0);
        for i in 0..poly.len() {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            let c = a[0] * b[1] - b[0] * a[1];
            area += 0.5 * c;
            moment += c * (a[0] + b[0]) / 6.0;
        }
        let (mut v, mut mx) = (0.0, 0.0);
        m.for_each_point(2, |_, x, w| {
            v += w;
            mx += w * x[0];
        })
        .unwrap();
        assert!((v - area).abs() < 1e-14 * area && (mx - moment).abs() < 1e-14 * moment, "{v} {area} {mx} {moment}");
        assert!(m.holds([3.5, 0.5, 7.0]) && !m.holds([3.5, 1.5, 0.0]) && m.holds([1.0, 0.5, 0.0]));
    }

    /// A group by name selects its cells; an unknown name lists the groups there are.
    #[test]
    fn groups_select_cells_or_are_named() {
        let mut f = file(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![(CellKind::Triangle, vec![0, 1, 2])]);
        f.names.push((2, 1, "soil".into()));
        assert_eq!(Mesh::select(&f, 2, Some(Group::Name("soil"))).unwrap().cells(), 1);
        let e = Mesh::select(&f, 2, Some(Group::Name("clay"))).unwrap_err();
        assert!(e.contains("no physical group of dimension 2 named \"clay\"; it has \"soil\" (1)"), "{e}");
        assert!(Mesh::select(&f, 2, Some(Group::Tag(4))).unwrap_err().contains("group 4 holds no cell"));
        assert!(Mesh::select(&f, 3, None).unwrap_err().contains("no cell of dimension 3"));
    }
}
