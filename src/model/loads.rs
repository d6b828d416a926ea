//! Time functions, loads and Dirichlet conditions, resolved against the grid and the particles.

use super::grid::Grid;
use super::particles::Particles;
use crate::case::{self, BoundaryId, Dof, LoadId, Region, Side, TimeFunction};
use std::sync::Arc;

/// A scalar function of time.
#[derive(Debug, Clone)]
pub enum TimeFn {
    /// f = value.
    Constant(f64),
    /// Linear from 0 at `start` to 1 at `start + duration`.
    Ramp { start: f64, duration: f64 },
    /// C² smoothstep from 0 at `start` to 1 at `start + duration`.
    SmoothRamp { start: f64, duration: f64 },
    /// cos(ωt + φ) times a smooth start over `ramp`.
    Harmonic { omega: f64, phase: f64, ramp: f64 },
    /// Piecewise linear.
    Table { t: Vec<f64>, v: Vec<f64> },
}

/// The smoothstep 6s⁵ − 15s⁴ + 10s³ clamped to [0, 1].
pub fn smoothstep(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * s * (10.0 + s * (-15.0 + 6.0 * s))
}

impl TimeFn {
    /// From the case's definition.
    pub fn from_case(f: &TimeFunction) -> TimeFn {
        match f {
            TimeFunction::Constant(c) => TimeFn::Constant(c.value),
            TimeFunction::Ramp(r) => TimeFn::Ramp { start: r.start, duration: r.duration },
            TimeFunction::SmoothRamp(r) => TimeFn::SmoothRamp { start: r.start, duration: r.duration },
            TimeFunction::Harmonic(h) => {
                TimeFn::Harmonic { omega: h.angular_frequency, phase: h.phase, ramp: h.ramp_duration }
            }
            TimeFunction::Table(t) => TimeFn::Table { t: t.times.clone(), v: t.values.clone() },
        }
    }

    /// The function scaling a load or a motion: the case's `f`, or a constant 1 without one.
    pub fn scaling(f: Option<&TimeFunction>) -> TimeFn {
        f.map_or(TimeFn::Constant(1.0), TimeFn::from_case)
    }

    /// f(t).
    pub fn eval(&self, t: f64) -> f64 {
        match self {
            TimeFn::Constant(v) => *v,
            TimeFn::Ramp { start, duration } => ((t - start) / duration).clamp(0.0, 1.0),
            TimeFn::SmoothRamp { start, duration } => smoothstep((t - start) / duration),
            TimeFn::Harmonic { omega, phase, ramp } => {
                let env = if *ramp > 0.0 { smoothstep(t / ramp) } else { 1.0 };
                env * (omega * t + phase).cos()
            }
            TimeFn::Table { t: ts, v } => {
                if t <= ts[0] {
                    return v[0];
                }
                for k in 1..ts.len() {
                    if t <= ts[k] {
                        let s = (t - ts[k - 1]) / (ts[k] - ts[k - 1]);
                        return v[k - 1] + s * (v[k] - v[k - 1]);
                    }
                }
                *v.last().unwrap()
            }
        }
    }
}

/// A load ready to be applied (two-dimensional unless `D` says otherwise).
#[derive(Debug, Clone)]
pub struct LoadDef<const D: usize = 2> {
    /// Name from the case.
    pub name: String,
    /// Its time function (constant 1 if none).
    pub time_fn: TimeFn,
    /// What it acts on.
    pub target: LoadTarget<D>,
    /// The state of a load whose increments follow the loaded faces (`increment_factor`).
    pub increments: Option<Increments>,
}

/// A load whose increment over each step is scaled by g(x̄_n, ȳ_n), an expression evaluated at the
/// loaded faces' mean centre at the start of the step: its factor at t in the step from t_n is
/// `total + (f(t) − f(t_n)) g_n`.
#[derive(Debug, Clone)]
pub struct Increments {
    /// The expression g (in `x`, `y` and the case's parameters).
    pub expr: String,
    /// The case's parameters.
    pub params: std::collections::BTreeMap<String, f64>,
    /// The factor reached at t_n: the sum of the increments so far.
    pub total: f64,
    /// t_n [s].
    pub t_n: f64,
    /// g at the loaded faces' mean centre at t_n.
    pub g_n: f64,
}

/// Where [`LoadDef::set_increments`] takes a load's total from.
#[derive(Debug, Clone, Copy)]
pub enum IncrementsFrom {
    /// The run starts: f(t) g.
    Start,
    /// A checkpoint's total.
    Checkpoint(f64),
    /// An accepted step ends: the step's factor.
    Accepted,
}

/// The value of an `increment_factor` expression at `at` = (x, y) or (x, y, z) [m].
pub fn increment_factor(
    expr: &str,
    params: &std::collections::BTreeMap<String, f64>,
    at: &[f64],
) -> Result<f64, String> {
    let params: Vec<(String, f64)> = params.iter().map(|(k, v)| (k.clone(), *v)).collect();
    crate::case::parameters::eval_at(expr, &params, at)
}

/// The centre of a particle's `face` and the face's measure: its length in two dimensions (per
/// metre of thickness), its area in three.
pub fn face_point<const D: usize>(face: Side, x: [f64; D], lp: [f64; D]) -> ([f64; D], f64) {
    let a = face.axis();
    if a >= D {
        // A z face: none in a plane case (validated).
        return (x, 0.0);
    }
    let mut p = x;
    p[a] += face.sign() * lp[a];
    let measure = if D == 2 { 2.0 * lp[1 - a] } else { (0..D).filter(|&d| d != a).map(|d| 2.0 * lp[d]).product() };
    (p, measure)
}

/// What a load acts on (in D dimensions; the line pressures are plane).
#[derive(Debug, Clone)]
pub enum LoadTarget<const D: usize = 2> {
    /// Face tractions on the listed particles (local indices), applied at the face centre.
    ParticleTraction { particles: Vec<usize>, face: Side, traction: [f64; D] },
    /// Forces on grid nodes: their indices and the measure of the loaded line (plane, [m]) or
    /// surface (three dimensions, [m²]) each stands for ([`tributary_nodes`]).
    NodalTraction { nodes: Vec<([usize; D], f64)>, traction: [f64; D] },
    /// Body acceleration on the particles of the listed bodies (all if None).
    BodyForce { acceleration: [f64; D], bodies: Option<Vec<u16>> },
    /// A pressure on a fixed polyline (plane) or surface (three dimensions): its Gauss points
    /// with the force per unit pressure there (weight × length × the unit normal to the left of a
    /// line [m]; weight × area × the unit normal into the material of a surface [m²]).
    Pressure { points: PressurePoints<D>, pressure: f64 },
}

impl<const D: usize> LoadDef<D> {
    /// Resolves the case's load `id` of any dimension on this rank's particles and the grid: a
    /// face traction, a nodal traction, a body force or, in the plane, a line pressure (`None`
    /// for a line pressure in three dimensions, which validation refuses).
    pub fn from_case_in(id: LoadId, c: &case::Case, grid: &Grid<D>, particles: &Particles<D>) -> Option<LoadDef<D>> {
        let vector = |v: &[f64]| -> [f64; D] { std::array::from_fn(|d| v.get(d).copied().unwrap_or(0.0)) };
        let bodies = c.load_bodies(id);
        let target = match c.load(id) {
            case::Load::ParticleTraction(t) => LoadTarget::ParticleTraction {
                particles: (0..particles.len())
                    .filter(|&k| {
                        let in_body =
                            bodies.is_none_or(|bs| bs.iter().any(|b| b.index() == particles.body[k] as usize));
                        in_body
                            && t.region.contains_in(particles.x0[k])
                            && face_is_exposed(c, particles.x0[k], particles.lp0[k], t.face)
                    })
                    .collect(),
                face: t.face,
                traction: vector(&t.traction),
            },
            case::Load::NodalTraction(t) => {
                LoadTarget::NodalTraction { nodes: tributary_nodes(grid, &t.region), traction: vector(&t.traction) }
            }
            case::Load::BodyForce(f) => LoadTarget::BodyForce {
                acceleration: vector(&f.acceleration),
                bodies: bodies.map(|bs| bs.iter().map(|b| b.index() as u16).collect()),
            },
            // A pressure on a polyline of the plane, or on a surface in three dimensions (validation
            // keeps each out of the other's dimension).
            case::Load::LinePressure(l) if D == 2 => LoadTarget::Pressure {
                points: line_gauss_points(&l.points).into_iter().map(|(x, f)| (vector(&x), vector(&f))).collect(),
                pressure: l.pressure,
            },
            case::Load::SurfacePressure(l) if D == 3 => LoadTarget::Pressure {
                points: surface_pressure_points(c, l.surface.points(), grid.h)
                    .expect("validation orients every point of a surface pressure"),
                pressure: l.pressure,
            },
            case::Load::LinePressure(_) | case::Load::SurfacePressure(_) => return None,
        };
        Some(LoadDef::with_target(id, c, target))
    }

    /// Number of particles or nodes it acts on (for `check`).
    pub fn size(&self) -> usize {
        match &self.target {
            LoadTarget::ParticleTraction { particles, .. } => particles.len(),
            LoadTarget::NodalTraction { nodes, .. } => nodes.len(),
            LoadTarget::Pressure { points, .. } => points.len(),
            LoadTarget::BodyForce { .. } => 0,
        }
    }

    /// The load `id` of case `c` acting on `target`, with its time function and increments.
    fn with_target(id: LoadId, c: &case::Case, target: LoadTarget<D>) -> LoadDef<D> {
        let l = c.load(id);
        let time_fn = TimeFn::scaling(c.load_time_function(id));
        let increments = l.increment_factor().map(|e| Increments {
            expr: e.to_string(),
            params: c.parameters.clone(),
            total: 0.0,
            t_n: 0.0,
            g_n: 0.0,
        });
        LoadDef { name: l.name().to_string(), time_fn, target, increments }
    }

    /// The load's factor at time t (in the step from the last accepted time on): f(t), or for a
    /// load with increments the sum of those accepted plus the current step's.
    pub fn factor(&self, t: f64) -> f64 {
        match &self.increments {
            None => self.time_fn.eval(t),
            Some(s) => s.total + (self.time_fn.eval(t) - self.time_fn.eval(s.t_n)) * s.g_n,
        }
    }
    /// This rank's moments of the loaded faces: [Σ a x, Σ a y, (Σ a z,) Σ a] with a the face's
    /// area (its length in the plane, times 2πr in axial symmetry); zero unless it is a face
    /// traction.
    pub fn face_moments(&self, particles: &Particles<D>, geometry: &super::shape::Geometry) -> Vec<f64> {
        let mut m = vec![0.0; D + 1];
        if let LoadTarget::ParticleTraction { particles: ks, face, .. } = &self.target {
            for &k in ks {
                let (point, measure) = face_point(*face, particles.x[k], particles.lp[k]);
                let a = measure * geometry.measure(point[0]);
                for d in 0..D {
                    m[d] += a * point[d];
                }
                m[D] += a;
            }
        }
        m
    }

    /// Sets a load with increments at time `t`, with g evaluated anew at `centre`, the loaded
    /// faces' mean centre now (from all ranks' [`Self::face_moments`]); `total` becomes f(t) g at
    /// the run's start, the checkpoint's total on a restart, or the step's factor at t at the end
    /// of an accepted step.
    pub fn set_increments(&mut self, t: f64, centre: [f64; D], from: IncrementsFrom) -> Result<(), String> {
        let Some(s) = &self.increments else { return Ok(()) };
        let g = increment_factor(&s.expr, &s.params, &centre)
            .map_err(|e| format!("load `{}`: increment_factor `{}` at {centre:?}: {e}", self.name, s.expr))?;
        let total = match from {
            IncrementsFrom::Start => self.time_fn.eval(t) * g,
            IncrementsFrom::Checkpoint(total) => total,
            IncrementsFrom::Accepted => self.factor(t),
        };
        let s = self.increments.as_mut().expect("checked");
        s.total = total;
        s.t_n = t;
        s.g_n = g;
        Ok(())
    }
}

/// Whether the `face` of a particle domain centred at `x` lies on the surface of the material:
/// the point just beyond the face centre is outside every body. This selects the outer row of
/// particles whatever the particle spacing, so a traction region need not be adjusted when the
/// grid is refined.
pub fn face_is_exposed<const D: usize>(c: &case::Case, x: [f64; D], lp: [f64; D], face: Side) -> bool {
    let e = 1.0 + 1e-6;
    let a = face.axis();
    if a >= D {
        // A z face: none in a plane case (validated).
        return false;
    }
    let mut p = x;
    p[a] += face.sign() * e * lp[a];
    !c.bodies.iter().any(|b| c.body_holds(b, p))
}

/// A pressure's Gauss points, each with the force per unit pressure there [m, m or m²].
pub type PressurePoints<const D: usize> = Vec<([f64; D], [f64; D])>;

/// A surface's Gauss points `faces` (position, area vector) turned into the material: the force
/// per unit pressure at each is its area vector, flipped where the material lies on the other side
/// of its face. The side is where a body holds the point a quarter of the smallest cell size `h`
/// away along the normal; material on both sides or on neither is an error naming the point.
pub fn surface_pressure_points<const D: usize>(
    c: &case::Case,
    faces: &[([f64; 3], [f64; 3])],
    h: [f64; D],
) -> Result<PressurePoints<D>, String> {
    let reach = 0.25 * h.iter().copied().fold(f64::INFINITY, f64::min);
    let mut out = Vec::with_capacity(faces.len());
    for (x, a) in faces {
        let length = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        if length == 0.0 {
            continue;
        }
        let probe = |s: f64| -> [f64; D] { std::array::from_fn(|d| x[d] + s * reach * a[d] / length) };
        let (ahead, behind) = (c.body_at(probe(1.0)).is_some(), c.body_at(probe(-1.0)).is_some());
        let sign = match (ahead, behind) {
            (true, false) => 1.0,
            (false, true) => -1.0,
            (both, _) => {
                return Err(format!(
                    "its surface at {x:?} has material on {} (within {reach:e} m along its normal); a pressure \
                     pushes material that lies on one side of it",
                    if both { "both sides" } else { "neither side" }
                ))
            }
        };
        out.push((std::array::from_fn(|d| x[d]), std::array::from_fn(|d| sign * a[d])));
    }
    Ok(out)
}

/// The two Gauss points of each segment of a polyline, with the force per unit pressure there:
/// (half the segment's length) × the unit normal to the left of the direction of travel.
pub fn line_gauss_points(points: &[[f64; 2]]) -> Vec<([f64; 2], [f64; 2])> {
    let g = 0.5 / 3f64.sqrt();
    let mut out = Vec::new();
    for w in points.windows(2) {
        let d = [w[1][0] - w[0][0], w[1][1] - w[0][1]];
        let len = d[0].hypot(d[1]);
        if len == 0.0 {
            continue;
        }
        let normal = [-d[1] / len, d[0] / len];
        for s in [0.5 - g, 0.5 + g] {
            out.push(([w[0][0] + s * d[0], w[0][1] + s * d[1]], [0.5 * len * normal[0], 0.5 * len * normal[1]]));
        }
    }
    out
}

/// Grid nodes inside `region`, each with the measure of the loaded line or surface it stands for:
/// the line (plane) or surface (three dimensions) spreads along the D − 1 directions in which the
/// nodes spread most, and along each of them a node takes half the distance to its neighbours
/// (the nodes of a box form a block of the grid, so the surface's share is the product of the
/// lines'). The nodes are ordered along the direction of largest spread.
pub fn tributary_nodes<const D: usize>(grid: &Grid<D>, region: &Region) -> Vec<([usize; D], f64)> {
    let mut sel: Vec<[usize; D]> = (0..grid.node_count())
        .map(|k| grid.node_indices(k))
        .filter(|&n| region.contains_in(grid.position(n)))
        .collect();
    if sel.is_empty() {
        return Vec::new();
    }
    // The indices the nodes take along each direction, and the spread of their positions.
    let lines: [Vec<usize>; D] = std::array::from_fn(|d| {
        let mut v: Vec<usize> = sel.iter().map(|n| n[d]).collect();
        v.sort_unstable();
        v.dedup();
        v
    });
    let position = |d: usize, i: usize| grid.origin[d] + i as f64 * grid.h[d];
    let spread = |d: usize| position(d, *lines[d].last().expect("a node")) - position(d, lines[d][0]);
    // The directions by decreasing spread (the lower direction first on a tie).
    let mut dirs: Vec<usize> = (0..D).collect();
    dirs.sort_by(|&a, &b| spread(b).total_cmp(&spread(a)));
    let along = &dirs[..D - 1];
    let share = |d: usize, i: usize| {
        let line = &lines[d];
        let k = line.binary_search(&i).expect("a selected index");
        let left = if k > 0 { (position(d, line[k]) - position(d, line[k - 1])) / 2.0 } else { 0.0 };
        let right = if k + 1 < line.len() { (position(d, line[k + 1]) - position(d, line[k])) / 2.0 } else { 0.0 };
        left + right
    };
    let main = along[0];
    sel.sort_by(|a, b| position(main, a[main]).total_cmp(&position(main, b[main])));
    sel.into_iter().map(|n| (n, along.iter().map(|&d| share(d, n[d])).product())).collect()
}

/// A prescribed motion of a boundary's fixed displacement components, in `D` dimensions.
#[derive(Debug, Clone)]
pub struct Motion<const D: usize = 2> {
    /// Whether `vector` is a displacement [m] (true) or a velocity [m/s].
    pub is_displacement: bool,
    /// The displacement or velocity at time-function value 1.
    pub vector: [f64; D],
    /// The velocity gradient L of a homogeneous flow [1/s] and its centre [m].
    pub gradient: Option<([[f64; D]; D], [f64; D])>,
    /// The time function.
    pub time_fn: TimeFn,
}

impl<const D: usize> Motion<D> {
    /// The increment over t0 → t1 of the node at `x` [m]: the uniform increment, plus
    /// (exp(L s) − I)(x − c) for a homogeneous flow, s = ∫ f dt.
    pub fn increment_at(&self, x: [f64; D], t0: f64, t1: f64) -> [f64; D] {
        let mut d = self.increment(t0, t1);
        if let (Some((_, c)), Some(e)) = (&self.gradient, self.flow(self.integral(t0, t1))) {
            let r: [f64; D] = std::array::from_fn(|b| x[b] - c[b]);
            for (a, da) in d.iter_mut().enumerate() {
                *da += (0..D).map(|b| (e[a][b] - if a == b { 1.0 } else { 0.0 }) * r[b]).sum::<f64>();
            }
        }
        d
    }

    /// exp(L s): the deformation gradient of the motion's homogeneous flow at flow parameter `s`
    /// (None without a velocity gradient).
    pub fn flow(&self, s: f64) -> Option<[[f64; D]; D]> {
        self.gradient.as_ref().map(|(l, _)| crate::algebra::linalg::expm(l.map(|row| row.map(|v| v * s))))
    }

    /// ∫₀ᵗ f dτ: the argument of the flow's exponential at `t`.
    pub fn flow_parameter(&self, t: f64) -> f64 {
        self.integral(0.0, t)
    }

    /// The prescribed displacement at time `t` [m]: d f(t), or ∫₀ᵗ v f dτ.
    pub fn displacement_at(&self, t: f64) -> [f64; D] {
        let s = if self.is_displacement { self.time_fn.eval(t) } else { self.integral(0.0, t) };
        self.vector.map(|v| v * s)
    }

    /// The prescribed displacement over t0 → t1 [m].
    pub fn increment(&self, t0: f64, t1: f64) -> [f64; D] {
        let s =
            if self.is_displacement { self.time_fn.eval(t1) - self.time_fn.eval(t0) } else { self.integral(t0, t1) };
        self.vector.map(|v| v * s)
    }

    /// ∫_{t0}^{t1} f dτ by the composite Simpson rule on 32 intervals (exact for piecewise linear
    /// and quadratic functions without kinks inside the interval).
    fn integral(&self, t0: f64, t1: f64) -> f64 {
        let n = 32;
        let h = (t1 - t0) / n as f64;
        if h == 0.0 {
            return 0.0;
        }
        let f = |k: usize| self.time_fn.eval(t0 + k as f64 * h);
        let inner: f64 = (1..n).map(|k| if k % 2 == 1 { 4.0 * f(k) } else { 2.0 * f(k) }).sum();
        h / 3.0 * (f(0) + inner + f(n))
    }
}

/// A set of Dirichlet conditions, in `D` dimensions.
#[derive(Debug, Clone)]
pub struct BoundaryDef<const D: usize = 2> {
    /// Name from the case.
    pub name: String,
    /// Where.
    pub side: Option<Side>,
    /// Or which box of nodes.
    pub region: Option<Region>,
    /// Or the moving surface of a body: (local particle index, exposed face) pairs.
    pub surface: Option<Vec<(usize, Side)>>,
    /// The surface's region, if it has one: only the nodes within its extent along each face
    /// (along the face's other directions: x for a y face in the plane, x and z in three
    /// dimensions) are fixed, so that a footing's edge stays where the region puts it when the
    /// points next to the edge move.
    pub surface_span: Option<Region>,
    /// Or the nodes on a mesh's boundary curves or faces, in the order of [`mesh_nodes`].
    pub mesh_nodes: Option<Arc<Vec<[usize; D]>>>,
    /// Components fixed.
    pub fix: Vec<Dof>,
    /// Water components that follow the solid's at its nodes (an impermeable moving surface).
    pub impermeable: Vec<Dof>,
    /// Their prescribed motion (none: fixed to zero, or tied to a rigid body under `force`).
    pub motion: Option<Motion<D>>,
    /// The load of a rigid body: the fixed displacement components (and the water's) of its nodes
    /// move together, by one unknown per direction that this force drives (and, with a point of
    /// application, by a small rotation about it).
    pub force: Option<RigidForce<D>>,
}

/// The load driving a rigid body ([`BoundaryDef::force`]), in `D` dimensions.
#[derive(Debug, Clone)]
pub struct RigidForce<const D: usize = 2> {
    /// The force at time-function value 1 [N per metre, on the full ring, or N].
    pub vector: [f64; D],
    /// Where it acts, if the body rotates about that point [m].
    pub point: Option<[f64; D]>,
    /// The time function.
    pub time_fn: TimeFn,
}

impl<const D: usize> RigidForce<D> {
    /// The axes it turns the body about (indices of x, y, z): none without a point of
    /// application; z in the plane; x, y and z in three dimensions.
    pub fn rotation_axes(&self) -> std::ops::Range<usize> {
        match (self.point, D) {
            (None, _) => 0..0,
            (Some(_), 2) => 2..3,
            (Some(_), _) => 0..3,
        }
    }

    /// The force at time `t`.
    pub fn at(&self, t: f64) -> [f64; D] {
        let f = self.time_fn.eval(t);
        self.vector.map(|v| v * f)
    }
}

/// The grid nodes on a boundary's mesh curves or faces ([`case::MeshBoundary`]): those within
/// 1e-6 of the smallest cell side of one of them, sorted by (z, y, x) index.
pub fn mesh_nodes<const D: usize>(grid: &Grid<D>, m: &case::MeshBoundary) -> Vec<[usize; D]> {
    let lattice = crate::geometry::NodeLattice {
        origin: std::array::from_fn(|d| if d < D { grid.origin[d] } else { 0.0 }),
        h: std::array::from_fn(|d| if d < D { grid.h[d] } else { 1.0 }),
        counts: std::array::from_fn(|d| if d < D { grid.cells[d] + 1 } else { 1 }),
    };
    let on = lattice.nodes_on(m.polygons(), 1e-6 * grid.h_min());
    on.into_iter().map(|n| std::array::from_fn(|d| n[d])).collect()
}

/// The (z, y, x) order of a node's indices that [`mesh_nodes`] sorts by.
fn mesh_order<const D: usize>(n: &[usize; D]) -> [usize; 3] {
    [if D == 3 { n[2] } else { 0 }, n[1], n[0]]
}

impl BoundaryDef {
    /// Whether node (i, j) belongs to it (sides and regions; surfaces are resolved per step from the
    /// particles, see [`crate::model::Model::surface_fixes`]).
    pub fn contains(&self, grid: &Grid, i: usize, j: usize) -> bool {
        self.holds_node(grid, [i, j])
    }
}

impl<const D: usize> BoundaryDef<D> {
    /// The components it holds at its nodes: those it fixes and the water's it makes follow the
    /// solid's.
    pub fn held(&self) -> impl Iterator<Item = Dof> + '_ {
        self.fix.iter().chain(&self.impermeable).copied()
    }

    /// The axis of an axisymmetric model: u_r = 0 and U_r = 0 on the grid side r = 0 (named
    /// [`super::AXIS`]; it is not a case boundary and holds in every stage).
    pub fn axis() -> BoundaryDef<D> {
        BoundaryDef {
            name: super::AXIS.to_string(),
            side: Some(Side::XMin),
            region: None,
            surface: None,
            surface_span: None,
            mesh_nodes: None,
            fix: vec![Dof::Ux, Dof::WUx],
            impermeable: Vec::new(),
            motion: None,
            force: None,
        }
    }

    /// Whether this is the axis of an axisymmetric model.
    pub fn is_axis(&self) -> bool {
        self.name == super::AXIS && self.side == Some(Side::XMin) && self.surface.is_none()
    }

    /// From the case's boundary `id`; a surface is resolved on this rank's particles (those of the
    /// body, inside the surface's region if it has one, whose face in a listed direction is exposed
    /// at t = 0).
    pub fn from_case(id: BoundaryId, c: &case::Case, particles: &Particles<D>) -> BoundaryDef<D> {
        let surface = c.boundary(id).surface.as_ref().zip(c.surface_body(id)).map(|(sf, body)| {
            let body = body.index() as u16;
            let mut v = Vec::new();
            for k in (0..particles.len()).filter(|&k| particles.body[k] == body) {
                if sf.region.is_some_and(|r| !r.contains_in(particles.x0[k])) {
                    continue;
                }
                for &f in &sf.faces {
                    if face_is_exposed(c, particles.x0[k], particles.lp0[k], f) {
                        v.push((k, f));
                    }
                }
            }
            v
        });
        BoundaryDef::from_case_in(id, c, surface)
    }

    /// From the case's boundary `id`, with its moving `surface` resolved on this rank's particles.
    pub fn from_case_in(id: BoundaryId, c: &case::Case, surface: Option<Vec<(usize, Side)>>) -> BoundaryDef<D> {
        let b = c.boundary(id);
        let time_fn = || TimeFn::scaling(c.boundary_time_function(id));
        let vector = |v: &Vec<f64>| -> [f64; D] { std::array::from_fn(|d| v.get(d).copied().unwrap_or(0.0)) };
        // A velocity gradient (D × D, validated) about its centre (default the origin).
        let gradient = b.velocity_gradient.as_ref().map(|l| {
            let centre = b.center.clone().unwrap_or_default();
            (std::array::from_fn(|a| vector(&l[a])), std::array::from_fn(|d| centre.get(d).copied().unwrap_or(0.0)))
        });
        let motion = match (&b.displacement, &b.velocity, gradient) {
            (Some(d), _, _) => {
                Some(Motion { is_displacement: true, vector: vector(d), gradient: None, time_fn: time_fn() })
            }
            (None, Some(v), g) => {
                Some(Motion { is_displacement: false, vector: vector(v), gradient: g, time_fn: time_fn() })
            }
            (None, None, Some(g)) => {
                Some(Motion { is_displacement: false, vector: [0.0; D], gradient: Some(g), time_fn: time_fn() })
            }
            _ => None,
        };
        BoundaryDef {
            name: b.name.clone(),
            side: b.side,
            region: b.region,
            surface,
            surface_span: b.surface.as_ref().and_then(|sf| sf.region),
            mesh_nodes: b.mesh.as_ref().map(|m| Arc::new(mesh_nodes(&super::grid_of(c), m))),
            fix: b.fix.clone(),
            impermeable: b.impermeable.clone(),
            motion,
            force: b.force.as_ref().map(|f| RigidForce {
                vector: vector(f),
                point: b.force_point.as_ref().map(vector),
                time_fn: time_fn(),
            }),
        }
    }

    /// Whether the grid node with indices `n` belongs to it (sides and regions; surfaces are
    /// resolved per step from the particles, see [`crate::model::Model::surface_fixes`]).
    pub fn holds_node(&self, grid: &Grid<D>, n: [usize; D]) -> bool {
        if let Some(side) = self.side {
            let axis = side.axis();
            // (A z side in a plane case is refused by validation: it holds no node.)
            return axis < D && n[axis] == if side.sign() < 0.0 { 0 } else { grid.cells[axis] };
        }
        if let Some(nodes) = &self.mesh_nodes {
            return nodes.binary_search_by_key(&mesh_order(&n), mesh_order).is_ok();
        }
        self.region.is_some_and(|r| r.holds_node_in(grid.position(n), grid.h))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A load with increments sums f's increments, each times g where the faces were at the step's
    /// start: with f = t and g = 10 x, faces at x = 1, then 2, then 4, the factor after three unit
    /// steps is 10 + 20 + 40; within a step it is linear in f; a checkpoint's total is taken as it
    /// is; without increments the factor is f(t).
    #[test]
    fn a_load_with_increments_sums_them_where_the_faces_were() {
        let mut l = LoadDef {
            name: "p".into(),
            time_fn: TimeFn::Table { t: vec![0.0, 10.0], v: vec![0.0, 10.0] },
            target: LoadTarget::BodyForce { acceleration: [0.0; 2], bodies: None },
            increments: Some(Increments {
                expr: "k * x + 0 * y".into(),
                params: [("k".to_string(), 10.0)].into_iter().collect(),
                total: f64::NAN,
                t_n: f64::NAN,
                g_n: f64::NAN,
            }),
        };
        l.set_increments(0.0, [1.0, 5.0], IncrementsFrom::Start).unwrap();
        assert_eq!(l.factor(0.0), 0.0);
        assert_eq!(l.factor(0.5), 5.0);
        assert_eq!(l.factor(1.0), 10.0);
        l.set_increments(1.0, [2.0, 5.0], IncrementsFrom::Accepted).unwrap();
        assert_eq!(l.factor(2.0), 30.0);
        l.set_increments(2.0, [4.0, 5.0], IncrementsFrom::Accepted).unwrap();
        assert_eq!(l.factor(3.0), 70.0);
        l.set_increments(3.0, [4.0, 5.0], IncrementsFrom::Checkpoint(12.5)).unwrap();
        assert_eq!(l.factor(3.0), 12.5);
        assert_eq!(l.factor(4.0), 52.5);
        // A constant f loads at the start: f(0) g.
        let mut c = LoadDef { time_fn: TimeFn::Constant(2.0), ..l.clone() };
        c.set_increments(0.0, [3.0, 0.0], IncrementsFrom::Start).unwrap();
        assert_eq!(c.factor(0.0), 60.0);
        assert_eq!(c.factor(7.0), 60.0);
        // An expression that cannot be evaluated there is an error naming the load.
        let mut bad = l.clone();
        bad.increments.as_mut().unwrap().expr = "1 / (x - 4)".into();
        let e = bad.set_increments(4.0, [4.0, 0.0], IncrementsFrom::Accepted).unwrap_err();
        assert!(e.contains("load `p`") && e.contains("not finite"), "{e}");
        let plain = LoadDef { increments: None, ..l };
        assert_eq!(plain.factor(3.5), 3.5);
    }

    #[test]
    fn time_functions_take_their_values() {
        assert_eq!(TimeFn::Constant(2.0).eval(5.0), 2.0);
        let r = TimeFn::Ramp { start: 1.0, duration: 2.0 };
        assert_eq!((r.eval(0.0), r.eval(2.0), r.eval(9.0)), (0.0, 0.5, 1.0));
        let s = TimeFn::SmoothRamp { start: 0.0, duration: 1.0 };
        assert!((s.eval(0.5) - 0.5).abs() < 1e-15 && s.eval(-1.0) == 0.0 && s.eval(2.0) == 1.0);
        // The smoothstep has zero slope at both ends.
        assert!((s.eval(1e-4) / 1e-4) < 1e-6);
        let h = TimeFn::Harmonic { omega: 2.0, phase: 0.0, ramp: 0.0 };
        assert!((h.eval(0.3) - (0.6f64).cos()).abs() < 1e-15);
        let hr = TimeFn::Harmonic { omega: 2.0, phase: 0.0, ramp: 1.0 };
        assert_eq!(hr.eval(0.0), 0.0);
        assert!((hr.eval(3.0) - (6.0f64).cos()).abs() < 1e-15);
        let t = TimeFn::Table { t: vec![0.0, 1.0, 3.0], v: vec![0.0, 2.0, 0.0] };
        assert_eq!((t.eval(-1.0), t.eval(0.5), t.eval(2.0), t.eval(5.0)), (0.0, 1.0, 1.0, 0.0));
    }

    #[test]
    fn tributary_lengths_sum_to_the_loaded_line() {
        let g = Grid::new([0.0, 0.0], [0.25, 0.25], [8, 4]);
        let nodes = tributary_nodes(&g, &Region { min: [0.0, 1.0], max: [0.5, 1.0], z: None });
        assert_eq!(nodes.len(), 3);
        let total: f64 = nodes.iter().map(|n| n.1).sum();
        assert!((total - 0.5).abs() < 1e-12);
        assert_eq!(nodes[0], ([0, 4], 0.125));
        assert_eq!(nodes[1], ([1, 4], 0.25));
    }

    /// In three dimensions a nodal traction's nodes stand for a surface: a node's share is the
    /// product of its tributary lengths along the surface's two directions (a quarter cell face at a
    /// corner, half at an edge, a whole face inside), whichever direction the surface faces.
    #[test]
    fn tributary_areas_sum_to_the_loaded_surface() {
        let g = Grid::new([0.0, 0.0, 0.0], [0.25, 0.5, 0.125], [8, 4, 8]);
        // The top (y = 2) over x ∈ [0, 0.5] and z ∈ [0, 0.25]: 3 × 3 nodes.
        let top = tributary_nodes(&g, &Region { min: [0.0, 2.0], max: [0.5, 2.0], z: Some([0.0, 0.25]) });
        assert_eq!(top.len(), 9);
        let share = |n: [usize; 3]| top.iter().find(|(m, _)| *m == n).map(|(_, a)| *a);
        assert_eq!(share([0, 4, 0]), Some(0.125 * 0.0625));
        assert_eq!(share([1, 4, 0]), Some(0.25 * 0.0625));
        assert_eq!(share([1, 4, 1]), Some(0.25 * 0.125));
        let total: f64 = top.iter().map(|n| n.1).sum();
        assert!((total - 0.5 * 0.25).abs() < 1e-15, "{total}");
        // Ordered along x, the direction of largest spread.
        assert!(top.windows(2).all(|w| w[0].0[0] <= w[1].0[0]));
        // A side face x = 2 over y ∈ [0, 1] and z ∈ [0.5, 1]: 3 × 5 nodes, area 0.5.
        let side = tributary_nodes(&g, &Region { min: [2.0, 0.0], max: [2.0, 1.0], z: Some([0.5, 1.0]) });
        assert_eq!(side.len(), 15);
        let total: f64 = side.iter().map(|n| n.1).sum();
        assert!((total - 0.5).abs() < 1e-15, "{total}");
    }
}
