//! Material points in struct-of-arrays storage, and their generation from the case geometry.
//!
//! One set of points carries both phases ([003] §3, single-layer MPM): it moves with the solid;
//! the water is described by its velocity, acceleration and mass n ρ_w V on the same points.

use super::grid::Grid;
use crate::case::{Case, Formulation};

/// All material points held by this rank, in `D` dimensions (two unless it says otherwise: plane
/// strain or axial symmetry).
#[derive(Debug, Clone)]
pub struct Particles<const D: usize = 2> {
    /// Global identifier (stable over the run, unique across ranks).
    pub id: Vec<u64>,
    /// Index of the body it was generated in.
    pub body: Vec<u16>,
    /// Index of its material.
    pub material: Vec<u16>,
    /// Position [m].
    pub x: Vec<[f64; D]>,
    /// Position at t = 0 [m].
    pub x0: Vec<[f64; D]>,
    /// Total solid displacement [m].
    pub disp: Vec<[f64; D]>,
    /// Half-widths of the GIMP domain l_p [m] (see `ShapeFunctions::Gimp` for how they follow the
    /// deformation).
    pub lp: Vec<[f64; D]>,
    /// Half-widths of the GIMP domain at t = 0 [m].
    pub lp0: Vec<[f64; D]>,
    /// Deformation gradient F = ∂x/∂X of the solid, rows first (in two dimensions the in-plane
    /// [[F_xx, F_xy], [F_yx, F_yy]]) [-].
    pub def_grad: Vec<[[f64; D]; D]>,
    /// Volume [m³; per metre of thickness in plane strain, of the ring in axial symmetry].
    pub volume: Vec<f64>,
    /// Porosity [-].
    pub porosity: Vec<f64>,
    /// Mass carried by the solid-displacement equation [kg]: the grains' (1 − n)ρ_s V in two-phase
    /// analyses (constant: solid mass is conserved), the mixture's ρV in one-phase analyses.
    pub mass: Vec<f64>,
    /// Solid velocity [m/s].
    pub vel: Vec<[f64; D]>,
    /// Solid acceleration [m/s²].
    pub acc: Vec<[f64; D]>,
    /// Water velocity [m/s] (two-phase).
    pub vel_w: Vec<[f64; D]>,
    /// Water acceleration [m/s²] (two-phase).
    pub acc_w: Vec<[f64; D]>,
    /// Effective stress [xx, yy, xy, zz, yz, zx] (total stress in one-phase analyses; yz = zx = 0 in
    /// plane strain and axial symmetry) [Pa].
    pub stress: Vec<crate::soils::Stress>,
    /// Pore pressure (compression positive) [Pa].
    pub p: Vec<f64>,
    /// Pore pressure at t = 0 [Pa] (the excess pore pressure is p − p₀).
    pub p0: Vec<f64>,
    /// Deviatoric plastic strain ε_p^d = sqrt(2/3 e_p : e_p) [-].
    pub eps_pd: Vec<f64>,
    /// Pore-pressure gradient [Pa/m] (two-phase), carried like p: it drives the Darcy flux of the
    /// u–p system from the start of a step.
    pub grad_p: Vec<[f64; D]>,
    /// [002]'s projected volume ratio J̄ = det F̄ (`stabilisation.fbar`, §3 Algorithm 1): the
    /// stress sees F̄ = (J̄/J)^{1/D} F, while the volume and F follow the point's own motion; 1 at
    /// t = 0 and without F̄ [-].
    pub jbar: Vec<f64>,
}

/// `[f(v) for every per-point vector v of the points]`, with `v` bound to `&` (or, after `mut`,
/// `&mut`) each vector in turn: one list of the fields for every pass over all of them.
macro_rules! per_point_vectors {
    ($s:expr, $v:ident => $body:expr) => {
        per_point_vectors!(@fields ref $s, $v, $body)
    };
    (mut $s:expr, $v:ident => $body:expr) => {
        per_point_vectors!(@fields mut $s, $v, $body)
    };
    (@fields $mode:tt $s:expr, $v:ident, $body:expr) => {
        per_point_vectors!(@each $mode $s, $v, $body; id, body, material, x, x0, disp, lp, lp0, def_grad, volume,
            porosity, mass, vel, acc, vel_w, acc_w, stress, p, p0, eps_pd, grad_p, jbar)
    };
    (@each ref $s:expr, $v:ident, $body:expr; $($f:ident),*) => {
        [$({ let $v = &$s.$f; $body }),*]
    };
    (@each mut $s:expr, $v:ident, $body:expr; $($f:ident),*) => {
        [$({ let $v = &mut $s.$f; $body }),*]
    };
}

impl<const D: usize> Default for Particles<D> {
    fn default() -> Self {
        Particles {
            id: Vec::new(),
            body: Vec::new(),
            material: Vec::new(),
            x: Vec::new(),
            x0: Vec::new(),
            disp: Vec::new(),
            lp: Vec::new(),
            lp0: Vec::new(),
            def_grad: Vec::new(),
            volume: Vec::new(),
            porosity: Vec::new(),
            mass: Vec::new(),
            vel: Vec::new(),
            acc: Vec::new(),
            vel_w: Vec::new(),
            acc_w: Vec::new(),
            stress: Vec::new(),
            p: Vec::new(),
            p0: Vec::new(),
            eps_pd: Vec::new(),
            grad_p: Vec::new(),
            jbar: Vec::new(),
        }
    }
}

impl<const D: usize> Particles<D> {
    /// The bytes the points' state holds on the heap (every vector at its capacity).
    pub fn heap_bytes(&self) -> usize {
        per_point_vectors!(self, v => crate::algebra::heap::capacity(v)).iter().sum()
    }

    /// Frees what the vectors hold beyond their points (growing by pushes leaves up to as much
    /// again).
    pub fn shrink_to_fit(&mut self) {
        per_point_vectors!(mut self, v => v.shrink_to_fit());
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Appends a point with the given id, body and material and every other array zero (to be
    /// filled by the caller).
    pub fn push_blank(&mut self, id: u64, body: u16, material: u16) {
        self.id.push(id);
        self.body.push(body);
        self.material.push(material);
        self.x.push([0.0; D]);
        self.x0.push([0.0; D]);
        self.disp.push([0.0; D]);
        self.lp.push([0.0; D]);
        self.lp0.push([0.0; D]);
        self.def_grad.push([[0.0; D]; D]);
        self.volume.push(0.0);
        self.porosity.push(0.0);
        self.mass.push(0.0);
        self.vel.push([0.0; D]);
        self.acc.push([0.0; D]);
        self.vel_w.push([0.0; D]);
        self.acc_w.push([0.0; D]);
        self.stress.push([0.0; crate::soils::NS]);
        self.p.push(0.0);
        self.p0.push(0.0);
        self.eps_pd.push(0.0);
        self.grad_p.push([0.0; D]);
        self.jbar.push(1.0);
    }
}

impl<const D: usize> Particles<D> {
    /// Fills the bodies of the case with their points ([`for_each_point`]), keeping those whose
    /// cell satisfies `owned(cell)` (the cells of this rank); a point belongs to the first body that
    /// contains it (validation refuses overlaps unless the later body says `overlap = "yield"`).
    pub fn generate(case: &Case, grid: &Grid<D>, owned: impl Fn([usize; D]) -> bool) -> Particles<D> {
        let mut ps = Particles::default();
        let pore_water = case.analysis.formulation == Formulation::TwoPhase;
        let geometry = super::geometry_of(case);
        for id in case.body_ids() {
            let (b, mat_index) = (id.index(), case.material_id_of(id).index());
            for_each_point(case, grid, b, |p| {
                if owned(p.cell) {
                    let vol = p.measure * geometry.measure(p.x[0]);
                    ps.push_point(case, grid, (p.id, b, mat_index), (p.x, p.lp, vol), pore_water);
                }
            });
        }
        ps.shrink_to_fit();
        ps
    }

    /// Appends the point `id` of body `b` (material `mat_index`) at `x` with domain half-widths
    /// `lp` and volume `vol`, with the body's initial velocity, stress and pore pressure.
    fn push_point(
        &mut self,
        case: &Case,
        grid: &Grid<D>,
        (id, b, mat_index): (u64, usize, usize),
        (x, lp, vol): ([f64; D], [f64; D], f64),
        pore_water: bool,
    ) {
        let (body, mat) = (&case.bodies[b], &case.materials[mat_index]);
        let mass = if pore_water {
            (1.0 - mat.porosity) * mat.solid_density * vol
        } else {
            ((1.0 - mat.porosity) * mat.solid_density + mat.porosity * mat.water_density) * vol
        };
        let ps = self;
        ps.id.push(id);
        ps.body.push(b as u16);
        ps.material.push(mat_index as u16);
        ps.x.push(x);
        ps.x0.push(x);
        ps.disp.push([0.0; D]);
        ps.lp.push(lp);
        ps.lp0.push(lp);
        ps.def_grad.push(std::array::from_fn(|a| std::array::from_fn(|c| if a == c { 1.0 } else { 0.0 })));
        ps.volume.push(vol);
        ps.porosity.push(mat.porosity);
        ps.mass.push(mass);
        let fields = case.initial_values(crate::case::BodyId::new(b));
        let v = fields.velocity_at(x);
        let (stress, p, grad_p) = match (&body.initial_stress, body.uniform_stress_vector()) {
            (Some(init), _) => {
                let (s, p, grad_p) = geostatic(case, grid, init, x, pore_water);
                (crate::soils::plane(s), p, grad_p)
            }
            (None, Some(s)) => (s, 0.0, [0.0; D]),
            (None, None) => (fields.stress_at(x).unwrap_or([0.0; 6]), 0.0, [0.0; D]),
        };
        let (p, grad_p) = fields.pore_pressure_at(x).unwrap_or((p, grad_p));
        // A particle file's own columns, where it gives them (its row is the id's low bits).
        let (v, stress, p) = match body.shape.points().map(|f| (&f.cloud().fields, id_number(id) as usize)) {
            Some((f, row)) => (
                f.velocity.as_ref().map_or(v, |u| std::array::from_fn(|d| u[row][d])),
                f.stress.as_ref().map_or(stress, |s| s[row]),
                f.pore_pressure.as_ref().map_or(p, |q| q[row]),
            ),
            None => (v, stress, p),
        };
        ps.vel.push(v);
        ps.acc.push([0.0; D]);
        // A two-phase body's water starts with its skeleton's velocity.
        ps.vel_w.push(if pore_water { v } else { [0.0; D] });
        ps.acc_w.push([0.0; D]);
        ps.grad_p.push(grad_p);
        ps.stress.push(stress);
        ps.p.push(p);
        ps.p0.push(p);
        ps.eps_pd.push(0.0);
        ps.jbar.push(1.0);
    }
}

/// The global id of body `b`'s point `number` (its sub-cell, its cell's quadrature point or its
/// particle file's row): the body in the top 16 bits, the number in the 48 below.
fn point_id(b: usize, number: u64) -> u64 {
    ((b as u64) << 48) | number
}

/// The number [`point_id`] packed into `id`.
fn id_number(id: u64) -> u64 {
    id & ((1 << 48) - 1)
}

/// A place where a body may put a material point.
#[derive(Debug, Clone, Copy)]
pub struct Candidate<const D: usize> {
    /// The grid cell holding it.
    pub cell: [usize; D],
    /// The point's global id (the same on any number of ranks).
    pub id: u64,
    /// Its position [m].
    pub x: [f64; D],
    /// Its area (plane and axisymmetric cases, before the ring's factor) or volume [m², m³].
    pub measure: f64,
    /// The half-widths of its GIMP domain [m].
    pub lp: [f64; D],
}

/// Calls `f` for every place body `b` of `case` may put a material point: for a body filled from
/// a mesh, its cells' quadrature points, numbered by cell and point; for a particle file's, its
/// rows, numbered in order; for any other, the centres of
/// the n^D sub-cells (n its `particles_per_cell`) of the cells its bounding box touches, moved by
/// its `perturbation`, numbered by sub-cell and visited x fastest. Whether the body holds the
/// place is the caller's question.
pub fn for_each_candidate<const D: usize>(case: &Case, grid: &Grid<D>, b: usize, mut f: impl FnMut(Candidate<D>)) {
    let body = &case.bodies[b];
    if let Some(m) = body.shape.mesh() {
        let mesh = m.mesh();
        let found = mesh.for_each_point(m.order, |number, x3, w| {
            let x: [f64; D] = std::array::from_fn(|d| x3[d]);
            let Some(cell) = grid.cell_containing(x) else { return };
            let lp = [crate::geometry::half_side(w, D); D];
            f(Candidate { cell, id: point_id(b, number), x, measure: w, lp });
        });
        found.expect("validation integrates every cell of a body's mesh");
        return;
    }
    if let Some(p) = body.shape.points() {
        let cloud = p.cloud();
        cloud.for_each(|k, x3, measure| {
            let x: [f64; D] = std::array::from_fn(|d| x3[d]);
            if let Some(cell) = grid.cell_containing(x) {
                let lp = [cloud.half_width(k); D];
                f(Candidate { cell, id: point_id(b, k as u64), x, measure, lp });
            }
        });
        return;
    }
    let n = body.particles_per_cell;
    let lp: [f64; D] = std::array::from_fn(|d| grid.h[d] / (2.0 * n as f64));
    let measure = grid.h.iter().product::<f64>() / n.pow(D as u32) as f64;
    let (lo2, hi2) = body.shape.bounds();
    let depth = case.body_depth(body);
    let (lo, hi): ([f64; D], [f64; D]) = (
        std::array::from_fn(|d| if d < 2 { lo2[d] } else { depth[0] }),
        std::array::from_fn(|d| if d < 2 { hi2[d] } else { depth[1] }),
    );
    let c0 = grid.cell_containing(lo).unwrap_or([0; D]);
    let c1 = grid.cell_containing(hi).unwrap_or(grid.cells.map(|c| c - 1));
    let counts = std::array::from_fn(|d| c1[d] - c0[d] + 1);
    let mut offset = [0; D];
    loop {
        let cell: [usize; D] = std::array::from_fn(|d| c0[d] + offset[d]);
        let mut sub = [0usize; D];
        loop {
            let number =
                (0..D).rev().fold(0u64, |acc, d| acc * (grid.cells[d] * 8) as u64 + (cell[d] * n + sub[d]) as u64);
            let id = point_id(b, number);
            let x: [f64; D] = std::array::from_fn(|d| {
                let shake = body.perturbation * (2.0 * jitter(id, d as u64) - 1.0);
                grid.origin[d] + (cell[d] as f64 + (sub[d] as f64 + 0.5 + shake) / n as f64) * grid.h[d]
            });
            f(Candidate { cell, id, x, measure, lp });
            if !super::shape::next_combination(&mut sub, [n; D]) {
                break;
            }
        }
        if !super::shape::next_combination(&mut offset, counts) {
            break;
        }
    }
}

/// [`for_each_candidate`] for the places where body `b` puts its material points: those it holds
/// and no body listed before it holds ([`Case::body_at`]), on any rank.
pub fn for_each_point<const D: usize>(case: &Case, grid: &Grid<D>, b: usize, mut f: impl FnMut(Candidate<D>)) {
    for_each_candidate(case, grid, b, |p| {
        if case.body_at(p.x).is_some_and(|at| at.index() == b) {
            f(p);
        }
    });
}

/// A pseudo-random number in [0, 1) from a point's id and a stream (SplitMix64): the same point
/// gets the same number on any rank.
fn jitter(id: u64, stream: u64) -> f64 {
    let mut z = id.wrapping_mul(2).wrapping_add(stream).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// The geostatic effective stress, pore pressure and pore-pressure gradient at `x` (see
/// [`crate::case::InitialStress`]).
fn geostatic<const D: usize>(
    case: &Case,
    grid: &Grid<D>,
    init: &crate::case::InitialStress,
    x: [f64; D],
    pore_water: bool,
) -> ([f64; 4], f64, [f64; D]) {
    let g = case.analysis.g;
    let (surface, mass) = case.column_above(x, grid.h[1] / 50.0);
    let sigma_v = -g * mass;
    let (p, grad_p) = if pore_water {
        let rho_w = case.body_at(x).map_or(1000.0, |b| case.material_of(b).water_density);
        let level = match init.water_table {
            crate::case::WaterTable::Surface => surface,
            crate::case::WaterTable::Level(y) => y,
        };
        let below = level > x[1];
        let mut grad = [0.0; D];
        grad[1] = if below { -rho_w * g } else { 0.0 };
        (rho_w * g * (level - x[1]).max(0.0), grad)
    } else {
        (0.0, [0.0; D])
    };
    let sv = sigma_v + p;
    ([init.k0 * sv, sv, 0.0, init.k0 * sv], p, grad_p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_column_is_filled_with_two_by_two_points_per_cell_of_the_right_volume() {
        let c = crate::validation::load(crate::case::tests_support::MINIMAL, "t", &[]).unwrap();
        let g = Grid::new([0.0, 0.0], c.cell_size(), c.cells());
        let ps = Particles::generate(&c, &g, |_| true);
        assert_eq!(ps.len(), 40);
        let v: f64 = ps.volume.iter().sum();
        assert!((v - 0.1).abs() < 1e-12);
        assert!((ps.lp[0][0] - 0.025).abs() < 1e-15);
        let mut ids = ps.id.clone();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), 40, "ids are unique");
        // Only the cells a rank owns.
        let half = Particles::generate(&c, &g, |c| c[1] < 5);
        assert_eq!(half.len(), 20);
        assert!(half.x.iter().all(|x| x[1] < 0.5));
    }

    /// [`tests_support::MINIMAL`](crate::case::tests_support::MINIMAL) with the column's
    /// `initial` table `initial` and the parameter v = 0.5.
    fn with_initial(initial: &str) -> Result<Case, String> {
        let text = crate::case::tests_support::MINIMAL.replace(
            "shape = { rectangle = { min = [0.0, 0.0], max = [0.1, 1.0] } }",
            &format!("shape = {{ rectangle = {{ min = [0.0, 0.0], max = [0.1, 1.0] }} }}\n        initial = {initial}"),
        ) + "\n[parameters]\nv = 0.5\n";
        crate::validation::load(&text, "t", &[]).map_err(|e| e.to_string())
    }

    #[test]
    fn initial_fields_are_expressions_of_the_points_position() {
        let c = with_initial(
            r#"{ velocity = ["2 * x", "v * sin(pi * y)"], stress = ["-1e4 * (1 - y)", -2.0, 0, "-3 * x"], pore_pressure = "9810 * (1 - y) + x^2" }"#,
        )
        .unwrap();
        let g = Grid::new([0.0, 0.0], c.cell_size(), c.cells());
        let ps = Particles::generate(&c, &g, |_| true);
        assert_eq!(ps.len(), 40);
        for k in 0..ps.len() {
            let [x, y] = ps.x[k];
            let v = [2.0 * x, 0.5 * (std::f64::consts::PI * y).sin()];
            assert_eq!(ps.vel[k], v);
            // The water of a two-phase body moves with its skeleton.
            assert_eq!(ps.vel_w[k], v);
            assert_eq!(ps.stress[k], [-1e4 * (1.0 - y), -2.0, 0.0, -3.0 * x, 0.0, 0.0]);
            let p = 9810.0 * (1.0 - y) + x * x;
            assert_eq!((ps.p[k], ps.p0[k]), (p, p));
            assert_eq!(ps.grad_p[k], [2.0 * x, -9810.0]);
        }
        let refused = [
            (r#"{ velocity = [0.0, 1.0, 2.0] }"#, "key `bodies[0].initial.velocity`: 2 components"),
            (r#"{ velocity = [0.0, "z"] }"#, "key `bodies[0].initial.velocity[1]`: `z`: `z` is no coordinate"),
            (r#"{ velocity = [0.0, "w * y"] }"#, "unknown parameter `w`"),
            (r#"{ stress = [1.0, 2.0, 3.0] }"#, "key `bodies[0].initial.stress`: four entries"),
            (
                r#"{ velocity = [0.0, "ln(y - 0.5)"] }"#,
                "key `bodies[0].initial.velocity[1]`: body `column` has the value NaN at its material point [0.025, 0.025]",
            ),
            (r#"{ pore_pressure = "1 / (x - 0.025)" }"#, "key `bodies[0].initial.pore_pressure`: body `column` has the value inf"),
        ];
        for (initial, message) in refused {
            let e = with_initial(initial).unwrap_err();
            assert!(e.contains(message), "{initial}: {e}");
        }
        let one_phase = crate::case::tests_support::MINIMAL.replace("two_phase", "one_phase").replace(
            "shape = { rectangle = { min = [0.0, 0.0], max = [0.1, 1.0] } }",
            "shape = { rectangle = { min = [0.0, 0.0], max = [0.1, 1.0] } }\n        initial = { pore_pressure = 1.0 }",
        );
        let e = crate::validation::load(&one_phase, "t", &[]).unwrap_err().to_string();
        assert!(e.contains("a one_phase analysis has no pore pressure"), "{e}");
        let twice = crate::case::tests_support::MINIMAL.replace(
            "shape = { rectangle = { min = [0.0, 0.0], max = [0.1, 1.0] } }",
            "shape = { rectangle = { min = [0.0, 0.0], max = [0.1, 1.0] } }\n        uniform_stress = [0.0, 0.0, 0.0, 0.0]\n        initial = { stress = [0.0, 0.0, 0.0, 0.0] }",
        );
        let e = crate::validation::load(&twice, "t", &[]).unwrap_err().to_string();
        assert!(e.contains("give the body's stress once"), "{e}");
    }

    /// A box aligned with the cells is filled exactly; a ball and a cylinder to within the point
    /// spacing's staircase, closer on finer grids; solids are refused in the plane and with a `z`.
    #[test]
    fn solid_shapes_fill_their_volume_to_the_point_spacing() {
        let pi = std::f64::consts::PI;
        let shapes = [
            ("{ box = { min = [0.1, 0.2, 0.3], max = [0.7, 0.8, 0.9] } }", 0.216),
            ("{ sphere = { center = [0.5, 0.5, 0.5], radius = 0.3 } }", 4.0 / 3.0 * pi * 0.027),
            ("{ cylinder = { center = [0.5, 0.5, 0.5], axis = \"x\", radius = 0.3, length = 0.6 } }", pi * 0.09 * 0.6),
        ];
        for (shape, exact) in shapes {
            let errors: Vec<f64> = [10, 20, 40]
                .iter()
                .map(|n| {
                    let text = crate::case::tests_support::with_grid("[1.0, 1.0, 1.0]", &format!("[{n}, {n}, {n}]"))
                        .replace("{ rectangle = { min = [0.0, 0.0], max = [0.1, 1.0] } }", shape);
                    let c = crate::validation::load(&text, "t", &[]).unwrap();
                    let ps = Particles::<3>::generate(&c, &crate::model::grid_of(&c), |_| true);
                    (ps.volume.iter().sum::<f64>() - exact).abs() / exact
                })
                .collect();
            if shape.contains("box") {
                // Exact but for the sum's round-off over up to 1.1e5 points.
                assert!(errors.iter().all(|e| *e < 1e-11), "{shape}: {errors:?}");
            } else {
                assert!(errors[2] < 0.01 && errors[2] < errors[0], "{shape}: {errors:?}");
            }
        }
        let sphere = "{ sphere = { center = [0.05, 0.5, 0.0], radius = 0.05 } }";
        let plane = crate::case::tests_support::MINIMAL
            .replace("{ rectangle = { min = [0.0, 0.0], max = [0.1, 1.0] } }", sphere);
        let e = crate::validation::load(&plane, "t", &[]).unwrap_err().to_string();
        assert!(
            e.contains(
                "key `bodies[0].shape`: a box, sphere, cylinder or surface is a shape of a three-dimensional case"
            ),
            "{e}"
        );
        let with_z = crate::case::tests_support::with_grid("[1.0, 1.0, 1.0]", "[4, 4, 4]").replace(
            "{ rectangle = { min = [0.0, 0.0], max = [0.1, 1.0] } }",
            "{ sphere = { center = [0.5, 0.5, 0.5], radius = 0.3 } }\n        z = [0.0, 1.0]",
        );
        let e = crate::validation::load(&with_z, "t", &[]).unwrap_err().to_string();
        assert!(e.contains("a solid shape has its own extent along z"), "{e}");
    }

    #[test]
    fn the_heap_count_covers_every_vector_and_generation_leaves_no_slack() {
        // Every field is a vector (a 24-byte header): the list the passes share names them all.
        let none = Particles::<2>::default();
        assert_eq!(std::mem::size_of::<Particles<2>>(), 24 * per_point_vectors!(none, v => v.len()).len());
        let c = crate::validation::load(crate::case::tests_support::MINIMAL, "t", &[]).unwrap();
        let g = Grid::new([0.0, 0.0], c.cell_size(), c.cells());
        let ps = Particles::generate(&c, &g, |_| true);
        // In two dimensions: id 8, body and material 2 + 2, ten [f64; 2] 160, F 32, seven scalars
        // 56, the stress 48.
        assert_eq!(ps.heap_bytes(), ps.len() * 308);
    }

    #[test]
    fn polygons_and_several_bodies_are_filled_without_overlap() {
        let text = crate::case::tests_support::MINIMAL
            .replace("size = [0.1, 1.0]\n        cells = [1, 10]", "size = [1.0, 1.0]\n        cells = [10, 10]")
            .replace(
                "shape = { rectangle = { min = [0.0, 0.0], max = [0.1, 1.0] } }",
                "shape = { polygon = { vertices = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]] } }\n        [[bodies]]\n        name = \"block\"\n        material = \"soil\"\n        particles_per_cell = 1\n        overlap = \"yield\"\n        shape = { rectangle = { min = [0.0, 0.0], max = [1.0, 1.0] } }",
            );
        let c = crate::validation::load(&text, "t", &[]).unwrap();
        let g = Grid::new([0.0, 0.0], c.cell_size(), c.cells());
        let ps = Particles::generate(&c, &g, |_| true);
        let tri: f64 = (0..ps.len()).filter(|&k| ps.body[k] == 0).map(|k| ps.volume[k]).sum();
        // The 2×2 points of the triangle cover half the square up to the staircase along the hypotenuse.
        assert!((tri - 0.5).abs() < 0.05, "triangle area {tri}");
        // The block takes only the points the triangle left (one per cell, where the cell centre is
        // not in the triangle): the 45 cells above the diagonal, and those whose centre lies on it
        // if the even-odd rule leaves them out of the triangle.
        let block: Vec<usize> = (0..ps.len()).filter(|&k| ps.body[k] == 1).collect();
        assert!((45..=55).contains(&block.len()), "{} block points", block.len());
        assert!(block.iter().all(|&k| !c.bodies[0].shape.contains(ps.x[k])));
        assert!((0..ps.len()).filter(|&k| ps.body[k] == 0).all(|k| c.bodies[0].shape.contains(ps.x[k])));
        let mut ids = ps.id.clone();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), ps.len());
    }

    /// A three-dimensional variant of the case tests' column: a 0.4 × 1.0 × 0.3 m grid of
    /// 4 × 10 × 3 cells, a body over z ∈ [0, 0.2] and a second one over the whole grid, behind it.
    fn solid_case(extra: &str) -> Case {
        let text = crate::case::tests_support::with_grid("[0.4, 1.0, 0.3]", "[4, 10, 3]")
            .replace(
                "shape = { rectangle = { min = [0.0, 0.0], max = [0.1, 1.0] } }",
                &format!(
                    "shape = {{ rectangle = {{ min = [0.0, 0.0], max = [0.4, 1.0] }} }}\n        z = [0.0, 0.2]\n        \
                     initial_stress = {{ k0 = 0.5 }}\n        {extra}\n        [[bodies]]\n        name = \"rest\"\n        \
                     material = \"soil\"\n        particles_per_cell = 1\n        overlap = \"yield\"\n        \
                     shape = {{ polygon = {{ vertices = [[0.0, 0.0], [0.4, 0.0], [0.4, 0.5], [0.0, 1.0]] }} }}"
                ),
            );
        crate::validation::load(&text, "t", &[]).unwrap()
    }

    /// A three-dimensional case's bodies are their sections extruded along z: 2 × 2 × 2 points per
    /// cell of the box (4 × 10 × 2 cells), volumes h_x h_y h_z / 8 that sum to the box's, the domain
    /// h/4, unique identifiers; the second body (one point per cell, a trapezoid section over the
    /// whole depth) fills only the cells the first left; only the owned cells are filled; the
    /// geostatic stress has σ'_zz = σ'_xx = K₀ σ'_yy and the pore-pressure gradient along −y.
    #[test]
    fn a_three_dimensional_case_extrudes_its_bodies_along_z() {
        let c = solid_case("");
        assert_eq!(c.dimension(), 3);
        let m = crate::model::Model::build_solid(&c, |_| true);
        let ps = &m.particles;
        let first: Vec<usize> = (0..ps.len()).filter(|&k| ps.body[k] == 0).collect();
        assert_eq!(first.len(), 4 * 10 * 2 * 8);
        let v: f64 = first.iter().map(|&k| ps.volume[k]).sum();
        assert!((v - 0.4 * 1.0 * 0.2).abs() < 1e-14, "{v}");
        assert!(first.iter().all(|&k| ps.x[k][2] < 0.2 && (ps.lp[k][2] - 0.025).abs() < 1e-15));
        // The second body: cells of z ∈ [0.2, 0.3] under its sloping top (points at the cell centres).
        let second: Vec<usize> = (0..ps.len()).filter(|&k| ps.body[k] == 1).collect();
        let expected = (0..4)
            .map(|i| (0..10).filter(|&j| (j as f64 + 0.5) * 0.1 <= 1.0 - (i as f64 + 0.5) * 0.125).count())
            .sum::<usize>();
        assert_eq!(second.len(), expected);
        assert!(second.iter().all(|&k| ps.x[k][2] > 0.2 && (ps.volume[k] - 0.1 * 0.1 * 0.1).abs() < 1e-16));
        let mut ids = ps.id.clone();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), ps.len(), "ids are unique");
        // The geostatic state of a point of the box at y = 0.025 under 0.975 m of saturated soil.
        let k = first.iter().copied().find(|&k| (ps.x[k][1] - 0.025).abs() < 1e-12).unwrap();
        let s = ps.stress[k];
        assert!(s[1] < 0.0 && (s[0] - 0.5 * s[1]).abs() < 1e-9 * s[1].abs() && s[0] == s[3], "{s:?}");
        assert!(s[2] == 0.0 && s[4] == 0.0 && s[5] == 0.0);
        assert!(ps.grad_p[k][0] == 0.0 && ps.grad_p[k][1] < 0.0 && ps.grad_p[k][2] == 0.0);
        assert!((ps.p[k] - 1000.0 * 9.81 * 0.975).abs() < 1e-6, "{}", ps.p[k]);
        // Only the owned cells.
        let front = crate::model::Model::build_solid(&c, |cell| cell[2] == 0);
        assert!(front.particles.len() == 4 * 10 * 8 && front.particles.x.iter().all(|x| x[2] < 0.1));
    }

    /// What a three-dimensional case may not have yet is refused with a message naming the key,
    /// as are a body's `z` in a plane case and grids of the wrong shape.
    #[test]
    fn three_dimensional_cases_refuse_what_they_cannot_have_yet() {
        let base = crate::case::tests_support::MINIMAL;
        let solid = crate::case::tests_support::with_grid("[0.1, 1.0, 0.1]", "[1, 10, 1]");
        let cases = [
            (
                solid.clone()
                    + "[[boundaries]]\nname = \"top\"\nside = \"y_max\"\nfix = [\"ux\"]\nvelocity_gradient = [[0.0, 1.0], [0.0, 0.0]]\n",
                "key `boundaries[0].velocity_gradient`: 3 rows of 3 entries (∂v_i/∂x_j) in a case of 3 dimensions",
            ),
            (
                solid.clone()
                    + "[[boundaries]]\nname = \"top\"\nside = \"y_max\"\nfix = [\"ux\", \"uy\"]\nvelocity_gradient = [[0.0, 1.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]\n",
                "key `boundaries[0].velocity_gradient`: moves every displacement component, so `fix` must list `ux`, \
                 `uy`, `uz`",
            ),
            (
                solid.clone()
                    + "[[boundaries]]\nname = \"top\"\nside = \"y_max\"\nfix = [\"ux\", \"uy\", \"uz\"]\nvelocity_gradient = [[0.0, 1.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]\ncenter = [0.0, 0.5]\n",
                "key `boundaries[0].center`: 3 finite coordinates in a case of 3 dimensions, got [0.0, 0.5]",
            ),
            (
                base.to_string() + "[[boundaries]]\nname = \"top\"\nside = \"y_max\"\nfix = [\"ux\"]\ncenter = [0.0, 0.5]\n",
                "key `boundaries[0].center`: is the centre of a `velocity_gradient`, not given",
            ),
            (
                base.replace("shape = { rectangle", "uniform_stress = [1.0, 2.0, 0.0, 1.0, 0.5, 0.0]\n        shape = { rectangle"),
                "key `bodies[0].uniform_stress`: four entries [xx, yy, xy, zz] in a plane case, got 6",
            ),
            (
                solid.replace("shape = { rectangle", "uniform_stress = [1.0, 2.0, 0.0]\n        shape = { rectangle"),
                "key `bodies[0].uniform_stress`: four entries [xx, yy, xy, zz] or six [xx, yy, xy, zz, yz, zx], got 3",
            ),
            (
                base.to_string()
                    + "[[boundaries]]\nname = \"front\"\nsurface = { body = \"column\", faces = [\"z_max\"] }\nfix = [\"ux\"]\n",
                "key `boundaries[0].surface.faces`: z",
            ),
            (
                solid.clone() + "[[boundaries]]\nname = \"top\"\nside = \"y_max\"\nfix = [\"ux\", \"uy\"]\ndisplacement = [0.0, -0.1]\n",
                "key `boundaries[0].displacement`: 3 components in a case of 3 dimensions, got 2",
            ),
            (
                base.to_string() + "[[boundaries]]\nname = \"back\"\nside = \"z_min\"\nfix = [\"ux\"]\n",
                "key `boundaries[0].side`: z (a `z_min`/`z_max` side or face, `uz`/`Uz`, a region's `z`) belongs to \
                 three-dimensional cases only",
            ),
            (
                base.to_string() + "[[boundaries]]\nname = \"base\"\nside = \"y_min\"\nfix = [\"uz\"]\n",
                "key `boundaries[0].fix`: z",
            ),
            (
                solid.clone() + "[[loads]]\nname = \"g\"\nkind = \"body_force\"\nacceleration = [0.0, -9.81]\n",
                "key `loads[0].acceleration`: 3 components in a case of 3 dimensions, got 2",
            ),
            (
                solid.clone()
                    + "[[loads]]\nname = \"q\"\nkind = \"nodal_traction\"\nregion = { min = [0.0, 1.0], max = [0.1, 1.0] }\ntraction = [0.0, -1.0]\n",
                "key `loads[0].traction`: 3 components in a case of 3 dimensions, got 2",
            ),
            (
                solid.clone()
                    + "[[loads]]\nname = \"q\"\nkind = \"nodal_traction\"\nregion = { min = [0.0, 1.0], max = [0.1, 1.0], z = [0.0, 0.0] }\ntraction = [0.0, -1.0, 0.0]\n",
                "key `loads[0].region`: the grid nodes inside it must form a surface of the grid (one node thick in one \
                 direction), but it holds 2, 1, 1 nodes along x, y, z (a line)",
            ),
            (
                base.to_string()
                    + "[[loads]]\nname = \"q\"\nkind = \"nodal_traction\"\nregion = { min = [0.0, 0.9], max = [0.1, 1.0] }\ntraction = [0.0, -1.0]\n",
                "key `loads[0].region`: the grid nodes inside it must form a line of the grid (one node thick in one \
                 direction), but it holds 2, 2 nodes along x, y (a block)",
            ),
            (
                base.to_string()
                    + "[[loads]]\nname = \"q\"\nkind = \"nodal_traction\"\nregion = { min = [0.02, 0.9], max = [0.08, 1.0] }\ntraction = [0.0, -1.0]\n",
                "key `loads[0].region`: holds no grid node",
            ),
            (
                solid.clone() + "[[loads]]\nname = \"q\"\nkind = \"line_pressure\"\npoints = [[0.0, 1.0], [0.1, 1.0]]\npressure = 1.0\n",
                "key `loads[0].kind = \"line_pressure\"`: a line pressure acts on a plane polyline",
            ),
            (
                base.to_string() + "[[loads]]\nname = \"g\"\nkind = \"body_force\"\nacceleration = [0.0, -9.81, 0.0]\n",
                "key `loads[0].acceleration`: 2 components in a case of 2 dimensions, got 3",
            ),
            (base.replace("cells = [1, 10]", "cells = [1, 10, 2]"), "key `grid.cells`: 2 entries"),
            (base.replace("size = [0.1, 1.0]", "size = [0.1, 1.0, 1.0, 1.0]"), "key `grid.size`: two entries"),
            (
                base.replace("max = [0.1, 1.0] } }", "max = [0.1, 1.0] } }\n        z = [0.0, 1.0]"),
                "key `bodies[0].z`: only a three-dimensional case",
            ),
            (
                solid.replace("max = [0.1, 1.0] } }", "max = [0.1, 1.0] } }\n        z = [0.0, 0.2]"),
                "key `bodies[0].z`: body `column` needs z_min < z_max inside the grid's [0, 0.1]",
            ),
        ];
        for (text, want) in cases {
            let e = crate::validation::load(&text, "t", &[]).unwrap_err().to_string();
            assert!(e.contains(want), "{e}\n  does not say: {want}");
        }
        assert!(crate::validation::load(&solid, "t", &[]).is_ok());
        // A nodal traction on the top face, and a face traction whose increments follow the
        // loaded faces with an expression in z, are three-dimensional loads.
        let loaded = solid.clone()
            + "[[loads]]\nname = \"q\"\nkind = \"nodal_traction\"\nregion = { min = [0.0, 1.0], max = [0.1, 1.0] }\ntraction = [0.0, -1.0, 0.0]\n"
            + "[[loads]]\nname = \"t\"\nkind = \"particle_traction\"\nregion = { min = [0.0, 0.9], max = [0.1, 1.0] }\nface = \"y_max\"\ntraction = [0.0, -1.0, 0.0]\nincrement_factor = \"1 + z\"\n";
        assert!(
            crate::validation::load(&loaded, "t", &[]).is_ok(),
            "{:?}",
            crate::validation::load(&loaded, "t", &[]).err()
        );
        let plane_z = base.to_string()
            + "[[loads]]\nname = \"t\"\nkind = \"particle_traction\"\nregion = { min = [0.0, 0.9], max = [0.1, 1.0] }\nface = \"y_max\"\ntraction = [0.0, -1.0]\nincrement_factor = \"1 + z\"\n";
        let e = crate::validation::load(&plane_z, "t", &[]).unwrap_err().to_string();
        assert!(e.contains("key `loads[0].increment_factor`: `1 + z`"), "{e}");
    }

    /// A three-dimensional case's side and region boundaries: each grid node is fixed by the first
    /// boundary (in case order) that holds it and fixes the component (ux, uy, uz, p, Ux, Uy, Uz),
    /// a region's z range bounds it along z, and a moving boundary's three components move.
    #[test]
    fn three_dimensional_boundaries_fix_their_nodes() {
        let text = crate::case::tests_support::solid_with_boundaries(
            r#"["uz", "Uz"]"#,
            "displacement = [0.001, -0.01, 0.002]",
        );
        let c = crate::validation::load(&text, "t", &[]).unwrap();
        let m = crate::model::Model::build_solid(&c, |_| true);
        let active = m.active(&c.stages[0]);
        // The full order of three dimensions: ux, uy, uz, p, Ux, Uy, Uz.
        assert_eq!(m.fixing_boundaries(&active, [1, 0, 0]), [Some(0), Some(0), Some(0), None, None, None, Some(1)]);
        assert_eq!(m.fixing_boundaries(&active, [1, 4, 0]), [None, None, Some(1), None, None, None, Some(1)]);
        assert_eq!(m.fixing_boundaries(&active, [1, 10, 2]), [Some(2), Some(2), Some(2), Some(2), None, None, None]);
        // Outside the region's z range, or beyond its x extent.
        assert_eq!(m.fixing_boundaries(&active, [1, 10, 3]), [None; 7]);
        assert_eq!(m.fixing_boundaries(&active, [2, 10, 1]), [None; 7]);
        let motion = m.boundaries[2].motion.as_ref().unwrap();
        assert_eq!(motion.displacement_at(0.05), [0.001, -0.01, 0.002]);
        assert_eq!(crate::layout::Layout::UPU.in_dim(3).canonical(6), Some(6));
        assert_eq!(crate::layout::Layout::UP.in_dim(3).canonical(3), Some(3));
    }
}
