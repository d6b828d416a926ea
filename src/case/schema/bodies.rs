//! `[[bodies]]`: the regions filled with material points at t = 0, their initial stress, and the
//! planar shapes and boxes the case uses to select points and nodes.

use super::super::expression::{Expr, COORDINATES};
use super::from_files::{MeshRegion, PointsRegion, SurfaceRegion};
use super::solids::{Cuboid, Cylinder, Solid, Sphere};
use crate::check::{at, finite, finite2, finite_points, positive, Checked};
use serde::{Deserialize, Serialize};

/// A body filled with material points.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Body {
    /// The name probes, loads, boundaries and the verification give to use it.
    pub name: String,
    /// The name of its material.
    pub material: String,
    /// Material points per cell and direction, in [1, 8] (2 gives 2 × 2 per cell in the plane,
    /// 2 × 2 × 2 in three dimensions).
    #[serde(default = "default_ppc")]
    pub particles_per_cell: usize,
    /// The region it occupies at t = 0: in three dimensions its section in the x–y plane,
    /// extruded along z over `z`.
    pub shape: Shape,
    /// The body's extent [z_min, z_max] along z [m], inside the grid (three-dimensional cases
    /// only; default: the grid's).
    pub z: Option<[f64; 2]>,
    /// A geostatic initial stress (default: stress-free).
    pub initial_stress: Option<InitialStress>,
    /// A uniform initial effective stress [xx, yy, xy, zz] [Pa] (tension positive), instead of a
    /// geostatic one (e.g. for patch tests and rigid-rotation checks); a three-dimensional case may
    /// give the two other shears too, [xx, yy, xy, zz, yz, zx].
    pub uniform_stress: Option<Vec<f64>>,
    /// Displacement of every material point from the centre of its sub-cell, as a fraction of the
    /// point spacing in each direction, drawn from a fixed pseudo-random sequence keyed by the
    /// point's id (the same on any number of ranks) [-], in [0, 0.5) (default 0: a regular
    /// arrangement).
    #[serde(default)]
    pub perturbation: f64,
    /// Its initial velocity, effective stress and pore pressure as functions of position
    /// (default: at rest, with the stress of `initial_stress` or `uniform_stress`, or none).
    pub initial: Option<InitialFields>,
    /// Where it overlaps a body listed before it: `"refuse"` (the default: an error, since a
    /// material point belongs to one body) or `"yield"` (the earlier bodies keep their points
    /// there and this one fills the rest, e.g. a block around a wedge listed first).
    #[serde(default)]
    pub overlap: Overlap,
}

/// A body's initial fields. Each component is a number or an expression of the point's position
/// `x`, `y` (and `z` in three dimensions; `x` is the radius in axial symmetry) [m] and the case's
/// parameters, written without the leading `=`: it is evaluated at every material point when the
/// points are made, e.g. `velocity = [0.0, "v0 * sin(pi * y / (2 * L))"]`, with the functions and
/// the constant `pi` of `[parameters]`' expressions.
#[derive(Debug, Clone, Default, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InitialFields {
    /// Velocity [m/s]: two components in a plane case, three in a three-dimensional one. A
    /// two-phase body's water starts with the same velocity (no relative flow).
    pub velocity: Option<Vec<Field>>,
    /// Effective stress [Pa] (tension positive): [xx, yy, xy, zz], in three dimensions also
    /// [xx, yy, xy, zz, yz, zx]; instead of `initial_stress` and `uniform_stress`. The body's
    /// equilibrium is the case's to give.
    pub stress: Option<Vec<Field>>,
    /// Pore pressure [Pa] (compression positive; two-phase), instead of a geostatic
    /// `initial_stress`'s; its gradient, which a point carries, is the expression's exact one.
    pub pore_pressure: Option<Field>,
}

/// A number, or an expression of position written without the leading `=`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(untagged)]
pub enum Field {
    /// A number, the same at every point.
    Value(f64),
    /// An expression of `x`, `y`, `z` and the parameters.
    Expression(String),
}

/// A body's initial fields parsed, ready to be evaluated at a point ([`InitialFields`]); empty
/// where the body gives none.
#[derive(Debug, Clone, Default)]
pub struct InitialValues {
    /// The velocity's components.
    pub velocity: Vec<Expr>,
    /// The effective stress's components.
    pub stress: Vec<Expr>,
    /// The pore pressure.
    pub pore_pressure: Option<Expr>,
}

impl InitialValues {
    /// The fields of `body` (`key` its table, `bodies[0]`) in a case of dimension `dim` with the
    /// parameters `params`; an error names the component and what is wrong.
    pub fn of(body: &Body, key: &str, dim: usize, params: &[(String, f64)]) -> Result<InitialValues, String> {
        let Some(init) = &body.initial else {
            return Ok(InitialValues::default());
        };
        let vars = &COORDINATES[..dim.clamp(2, 3)];
        let parse = |f: &Field, at: String| match f {
            Field::Value(v) => Ok(Expr::constant(*v, vars.len())),
            Field::Expression(t) => Expr::parse(t, vars, params).map_err(|e| format!("key `{at}`: `{t}`: {e}")),
        };
        let list = |fs: &Option<Vec<Field>>, name: &str| -> Result<Vec<Expr>, String> {
            let fs = fs.as_deref().unwrap_or_default();
            fs.iter().enumerate().map(|(i, f)| parse(f, format!("{key}.initial.{name}[{i}]"))).collect()
        };
        Ok(InitialValues {
            velocity: list(&init.velocity, "velocity")?,
            stress: list(&init.stress, "stress")?,
            pore_pressure: init
                .pore_pressure
                .as_ref()
                .map(|f| parse(f, format!("{key}.initial.pore_pressure")))
                .transpose()?,
        })
    }

    /// The velocity at `x` (zero in the components it does not give).
    pub fn velocity_at<const D: usize>(&self, x: [f64; D]) -> [f64; D] {
        std::array::from_fn(|d| self.velocity.get(d).map_or(0.0, |e| e.eval(&x)))
    }

    /// The effective stress [xx, yy, xy, zz, yz, zx] at `x`, if the body gives one.
    pub fn stress_at<const D: usize>(&self, x: [f64; D]) -> Option<[f64; 6]> {
        (!self.stress.is_empty()).then(|| std::array::from_fn(|c| self.stress.get(c).map_or(0.0, |e| e.eval(&x))))
    }

    /// The pore pressure and its gradient at `x`, if the body gives one.
    pub fn pore_pressure_at<const D: usize>(&self, x: [f64; D]) -> Option<(f64, [f64; D])> {
        self.pore_pressure.as_ref().map(|e| {
            let (p, g) = e.gradient(&x);
            (p, std::array::from_fn(|d| g[d]))
        })
    }

    /// The first of the fields whose value at `x` is not finite, named (`velocity[1]`), with the
    /// value.
    pub fn not_finite_at<const D: usize>(&self, x: [f64; D]) -> Option<(String, f64)> {
        let first = |name: &str, es: &[Expr]| {
            es.iter()
                .enumerate()
                .map(|(i, e)| (i, e.eval(&x)))
                .find(|(_, v)| !v.is_finite())
                .map(|(i, v)| (format!("{name}[{i}]"), v))
        };
        let pressure = || {
            let (p, g) = self.pore_pressure.as_ref()?.gradient(&x);
            std::iter::once(("pore_pressure", p))
                .chain(g[..D].iter().map(|&v| ("the gradient of pore_pressure", v)))
                .find(|(_, v)| !v.is_finite())
                .map(|(name, v)| (name.to_string(), v))
        };
        first("velocity", &self.velocity).or_else(|| first("stress", &self.stress)).or_else(pressure)
    }
}

/// What a body does where it overlaps a body listed before it.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Overlap {
    /// An error: bodies must not overlap.
    #[default]
    Refuse,
    /// The earlier bodies keep their points there.
    Yield,
}

serde_defaults! { default_ppc: usize = 2 }

/// A geostatic initial state in equilibrium with gravity g = `analysis.g` acting from t = 0 (the
/// case must apply that gravity in full from the start): at a point at height y under a column of
/// material reaching y_top at its x, the total vertical stress is σ_v = −g ∫_y^{y_top} ρ dy (the
/// densities of the bodies met along the column), the pore pressure p = ρ_w g (y_w − y) below the
/// water table y_w (two-phase), the effective stresses σ'_yy = σ_v + p, σ'_xx = σ'_zz = K₀ σ'_yy,
/// σ'_xy = 0. Near a slope this is not in equilibrium; the first steps redistribute it.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InitialStress {
    /// Coefficient of earth pressure at rest K₀ = σ'_h/σ'_v [-], > 0.
    pub k0: f64,
    /// The water table (two-phase): `"surface"` (the top of the material in each column, the
    /// default) or a height y_w [m].
    #[serde(default)]
    pub water_table: WaterTable,
}

/// Where the pore pressure of a geostatic state is zero.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(untagged)]
pub enum WaterTable {
    /// `"surface"`: the top of the material in each column.
    #[default]
    #[serde(with = "surface_word")]
    #[schemars(with = "String")]
    Surface,
    /// A height [m].
    Level(f64),
}

mod surface_word {
    use serde::{Deserialize, Deserializer, Serializer};
    pub fn serialize<S: Serializer>(s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str("surface")
    }
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<(), D::Error> {
        let w = String::deserialize(d)?;
        if w == "surface" {
            Ok(())
        } else {
            Err(serde::de::Error::custom(format!("expected \"surface\" or a height, got \"{w}\"")))
        }
    }
}

/// The region a body fills: a planar section, written `{ rectangle = { ... } }` or
/// `{ polygon = { ... } }` (extruded along z over the body's `z` in three dimensions), in three
/// dimensions a solid, `{ box = { ... } }`, `{ sphere = { ... } }`, `{ cylinder = { ... } }` or
/// `{ surface = { file = "dam.stl" } }`, or in any dimension the cells of a Gmsh mesh,
/// `{ mesh = { file = "slope.msh", group = "soil" } }`, or the points of a particle file,
/// `{ points = { file = "points.csv" } }`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// An axis-aligned rectangle.
    Rectangle(Rectangle),
    /// A simple polygon.
    Polygon(Polygon),
    /// An axis-aligned box (three dimensions).
    #[serde(rename = "box")]
    Cuboid(Cuboid),
    /// A ball (three dimensions).
    Sphere(Sphere),
    /// A circular cylinder along a grid axis (three dimensions).
    Cylinder(Cylinder),
    /// The inside of a closed STL surface (three dimensions).
    Surface(SurfaceRegion),
    /// The cells of a Gmsh mesh, filled by their quadrature points.
    Mesh(MeshRegion),
    /// The points of a particle file.
    Points(PointsRegion),
}

/// An axis-aligned rectangle of the plane.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Rectangle {
    /// Lower-left corner [m].
    pub min: [f64; 2],
    /// Upper-right corner [m], above and right of `min`.
    pub max: [f64; 2],
}

/// A simple polygon of the plane.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Polygon {
    /// Its vertices in order [m], at least three.
    pub vertices: Vec<[f64; 2]>,
}

/// An axis-aligned box [m] used to select nodes or particles.
#[derive(Debug, Clone, Copy, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Region {
    /// Lower-left corner [m].
    pub min: [f64; 2],
    /// Upper-right corner [m].
    pub max: [f64; 2],
    /// Its extent [z_min, z_max] along z in a three-dimensional case [m] (default: all of it).
    pub z: Option<[f64; 2]>,
}

impl Body {
    /// The `uniform_stress` as a stress vector [xx, yy, xy, zz, yz, zx] [Pa] (the shears it does
    /// not give are zero).
    pub fn uniform_stress_vector(&self) -> Option<[f64; 6]> {
        self.uniform_stress.as_ref().map(|s| std::array::from_fn(|c| s.get(c).copied().unwrap_or(0.0)))
    }

    /// Checks the body's own values; `key` is its table (`bodies[0]`). Its material, its extent
    /// along z and the number of stress components depend on the rest of the case: validation
    /// checks them.
    pub fn check(&self, key: &str) -> Checked {
        if self.particles_per_cell == 0 || self.particles_per_cell > 8 {
            return Err(format!(
                "key `{}`: must be between 1 and 8, got {}",
                at(key, "particles_per_cell"),
                self.particles_per_cell
            ));
        }
        self.shape.check(&at(key, "shape"))?;
        if !(0.0..0.5).contains(&self.perturbation) {
            return Err(format!("key `{}`: must be in [0, 0.5), got {}", at(key, "perturbation"), self.perturbation));
        }
        if self.uniform_stress.is_some() && self.initial_stress.is_some() {
            return Err(format!("key `{key}`: give `initial_stress` or `uniform_stress`, not both"));
        }
        match &self.initial_stress {
            Some(init) => init.check(&at(key, "initial_stress")),
            None => Ok(()),
        }
    }
}

impl InitialStress {
    /// Checks K₀ and the water table; `key` is its table.
    pub fn check(&self, key: &str) -> Checked {
        positive(&at(key, "k0"), self.k0)?;
        match self.water_table {
            WaterTable::Level(y) => finite(&at(key, "water_table"), y),
            WaterTable::Surface => Ok(()),
        }
    }
}

impl Shape {
    /// Checks the corners or vertices; `key` is the shape's table (`bodies[0].shape`).
    pub fn check(&self, key: &str) -> Checked {
        match self {
            Shape::Rectangle(r) => r.check(&at(key, "rectangle")),
            Shape::Polygon(p) => p.check(&at(key, "polygon")),
            Shape::Cuboid(b) => b.check(&at(key, "box")),
            Shape::Sphere(b) => b.check(&at(key, "sphere")),
            Shape::Cylinder(b) => b.check(&at(key, "cylinder")),
            Shape::Surface(b) => b.check(&at(key, "surface")),
            Shape::Mesh(m) => m.check(&at(key, "mesh")),
            Shape::Points(_) => Ok(()),
        }
    }

    /// The particle file's points a body is made of, if it is one.
    pub fn points(&self) -> Option<&PointsRegion> {
        match self {
            Shape::Points(p) => Some(p),
            _ => None,
        }
    }

    /// The mesh a body is filled from, if it is one.
    pub fn mesh(&self) -> Option<&MeshRegion> {
        match self {
            Shape::Mesh(m) => Some(m),
            _ => None,
        }
    }

    /// The solid, if the shape is one.
    pub fn solid(&self) -> Option<&dyn Solid> {
        match self {
            Shape::Rectangle(_) | Shape::Polygon(_) => None,
            Shape::Cuboid(b) => Some(b),
            Shape::Sphere(b) => Some(b),
            Shape::Cylinder(b) => Some(b),
            Shape::Surface(b) => Some(b),
            Shape::Mesh(m) => (m.mesh().dim() == 3).then_some(m as &dyn Solid),
            Shape::Points(p) => (p.cloud().dim() == 3).then_some(p as &dyn Solid),
        }
    }

    /// A solid's extent along z [m] (none for a planar section).
    pub fn depth(&self) -> Option<[f64; 2]> {
        self.solid().map(|s| {
            let (lo, hi) = s.bounds3();
            [lo[2], hi[2]]
        })
    }

    /// Bounding box (min, max) in x and y [m].
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        let planar = |(lo, hi): ([f64; 3], [f64; 3])| ([lo[0], lo[1]], [hi[0], hi[1]]);
        match self {
            Shape::Cuboid(b) => planar(b.bounds3()),
            Shape::Sphere(b) => planar(b.bounds3()),
            Shape::Cylinder(b) => planar(b.bounds3()),
            Shape::Surface(b) => planar(b.bounds3()),
            Shape::Mesh(m) => planar(m.mesh().bounds()),
            Shape::Points(p) => planar(p.cloud().bounds()),
            Shape::Rectangle(r) => (r.min, r.max),
            Shape::Polygon(p) => {
                let mut lo = [f64::INFINITY; 2];
                let mut hi = [f64::NEG_INFINITY; 2];
                for v in &p.vertices {
                    for d in 0..2 {
                        lo[d] = lo[d].min(v[d]);
                        hi[d] = hi[d].max(v[d]);
                    }
                }
                (lo, hi)
            }
        }
    }

    /// Whether a planar section holds point `p` (boundary points of a rectangle count as inside;
    /// polygons use the even–odd rule); a solid's section is not defined, and holds none.
    pub fn contains(&self, p: [f64; 2]) -> bool {
        match self {
            Shape::Cuboid(_) | Shape::Sphere(_) | Shape::Cylinder(_) | Shape::Surface(_) => false,
            Shape::Mesh(m) => m.mesh().dim() == 2 && m.mesh().holds([p[0], p[1], 0.0]),
            Shape::Points(c) => c.cloud().dim() == 2 && c.cloud().holds([p[0], p[1], 0.0]),
            Shape::Rectangle(Rectangle { min, max }) => {
                p[0] >= min[0] && p[0] <= max[0] && p[1] >= min[1] && p[1] <= max[1]
            }
            Shape::Polygon(Polygon { vertices }) => {
                let mut inside = false;
                let n = vertices.len();
                let mut j = n - 1;
                for i in 0..n {
                    let (a, b) = (vertices[i], vertices[j]);
                    if (a[1] > p[1]) != (b[1] > p[1]) && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0] {
                        inside = !inside;
                    }
                    j = i;
                }
                inside
            }
        }
    }
}

impl Rectangle {
    /// Checks that the corners are finite and ordered; `key` is the rectangle's table.
    pub fn check(&self, key: &str) -> Checked {
        finite2(&at(key, "min"), self.min)?;
        finite2(&at(key, "max"), self.max)?;
        if !(self.max[0] > self.min[0] && self.max[1] > self.min[1]) {
            return Err(format!("key `{key}`: max must exceed min in x and y, got {:?} .. {:?}", self.min, self.max));
        }
        Ok(())
    }
}

impl Polygon {
    /// Checks the number of vertices and that they are finite; `key` is the polygon's table.
    pub fn check(&self, key: &str) -> Checked {
        finite_points(key, "vertices", &self.vertices, 3, "a polygon")?;
        // A simple polygon: no two edges meet but neighbours at their shared vertex (even-odd
        // filling would otherwise give a crossed outline holes and double layers, silently).
        let n = self.vertices.len();
        let edge = |i: usize| (self.vertices[i], self.vertices[(i + 1) % n]);
        for i in 0..n {
            for j in i + 1..n {
                let neighbours = j == i + 1 || (i == 0 && j == n - 1);
                if segments_meet(edge(i), edge(j), neighbours) {
                    return Err(format!(
                        "key `{}`: the polygon crosses itself: its edges {i}–{} and {j}–{} meet; give the vertices \
                         of a simple polygon in order",
                        at(key, "vertices"),
                        (i + 1) % n,
                        (j + 1) % n
                    ));
                }
            }
        }
        Ok(())
    }
}

/// Whether the segments `a` and `b` share a point; for `neighbours` (edges with a common
/// vertex) whether they share more than that vertex (they overlap, folding back).
fn segments_meet(a: ([f64; 2], [f64; 2]), b: ([f64; 2], [f64; 2]), neighbours: bool) -> bool {
    let cross = |o: [f64; 2], p: [f64; 2], q: [f64; 2]| (p[0] - o[0]) * (q[1] - o[1]) - (p[1] - o[1]) * (q[0] - o[0]);
    let within = |o: [f64; 2], p: [f64; 2], q: [f64; 2]| {
        q[0] >= o[0].min(p[0]) && q[0] <= o[0].max(p[0]) && q[1] >= o[1].min(p[1]) && q[1] <= o[1].max(p[1])
    };
    let (d1, d2) = (cross(b.0, b.1, a.0), cross(b.0, b.1, a.1));
    let (d3, d4) = (cross(a.0, a.1, b.0), cross(a.0, a.1, b.1));
    if neighbours {
        // Collinear neighbours that fold back over each other.
        let folds =
            |o: [f64; 2], p: [f64; 2], q: [f64; 2]| (p[0] - o[0]) * (q[0] - o[0]) + (p[1] - o[1]) * (q[1] - o[1]) > 0.0;
        let shared = if a.1 == b.0 {
            Some((a.1, a.0, b.1))
        } else if b.1 == a.0 {
            Some((a.0, a.1, b.0))
        } else {
            None
        };
        return shared.is_some_and(|(v, p, q)| cross(v, p, q) == 0.0 && folds(v, p, q));
    }
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0)) {
        return true;
    }
    (d1 == 0.0 && within(b.0, b.1, a.0))
        || (d2 == 0.0 && within(b.0, b.1, a.1))
        || (d3 == 0.0 && within(a.0, a.1, b.0))
        || (d4 == 0.0 && within(a.0, a.1, b.1))
}

impl Region {
    /// Checks that the corners are finite and ordered (a box may be flat: a line of nodes); `key`
    /// is the region's table.
    pub fn check(&self, key: &str) -> Checked {
        finite2(&at(key, "min"), self.min)?;
        finite2(&at(key, "max"), self.max)?;
        if self.max[0] < self.min[0] || self.max[1] < self.min[1] {
            return Err(format!("key `{key}`: max must not be below min"));
        }
        Ok(())
    }

    /// Whether point `p` lies in the box (boundary included, with a tolerance of 1e-9 of the box's
    /// size and coordinates, so that points on a grid line are not lost to round-off, also when the
    /// box is a line).
    pub fn contains(&self, p: [f64; 2]) -> bool {
        (0..2).all(|d| self.spans(d, p[d], 0.0))
    }

    /// Whether point `p` of a case of dimension `D` lies in the box: [`Region::contains`] in x and
    /// y and, in three dimensions, its `z` range (all of z without one) with the same tolerance.
    pub fn contains_in<const D: usize>(&self, p: [f64; D]) -> bool {
        if !self.contains([p[0], p[1]]) {
            return false;
        }
        D < 3 || self.spans_z(p[2])
    }

    /// Whether `z` lies in the box's `z` range (all of z without one), with the tolerance of
    /// [`Region::contains`].
    pub fn spans_z(&self, z: f64) -> bool {
        match self.z {
            Some([lo, hi]) => {
                let tol = 1e-9 * ((hi - lo).abs() + lo.abs() + hi.abs()) + 1e-15;
                z >= lo - tol && z <= hi + tol
            }
            None => true,
        }
    }

    /// Whether the grid node at `p` lies in the box: as [`Region::contains`], with a further
    /// 1e-9 of the cell size `h`, the round-off of origin + i h (a line at x = 0 holds the node
    /// computed at −2e-15).
    pub fn holds_node(&self, p: [f64; 2], h: [f64; 2]) -> bool {
        (0..2).all(|d| self.spans(d, p[d], 1e-9 * h[d]))
    }

    /// Whether the grid node at `p` of a case of dimension `D` lies in the box: [`Region::holds_node`]
    /// in x and y and, in three dimensions, its `z` range (all of z without one) with the same
    /// tolerance.
    pub fn holds_node_in<const D: usize>(&self, p: [f64; D], h: [f64; D]) -> bool {
        if !self.holds_node([p[0], p[1]], [h[0], h[1]]) {
            return false;
        }
        match (D, self.z) {
            (3, Some([lo, hi])) => {
                let tol = 1e-9 * ((hi - lo).abs() + lo.abs() + hi.abs()) + 1e-15 + 1e-9 * h[2];
                p[2] >= lo - tol && p[2] <= hi + tol
            }
            _ => true,
        }
    }

    /// Whether coordinate `x` of direction `d` lies in the box's range, with `slack` beyond the
    /// tolerance of [`Region::contains`].
    pub fn spans(&self, d: usize, x: f64, slack: f64) -> bool {
        let tol = 1e-9 * ((self.max[d] - self.min[d]).abs() + self.min[d].abs() + self.max[d].abs()) + 1e-15 + slack;
        x >= self.min[d] - tol && x <= self.max[d] + tol
    }
}
