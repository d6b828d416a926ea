//! The physical model of a run: grid geometry, materials, material points, loads and Dirichlet
//! conditions, and the particle update after a converged step. Pure Rust; the global system lives in
//! [`crate::assembly`].

pub mod cmpm;
pub mod fbar;
pub mod finite_strain;
pub mod grid;
pub mod linalg;
pub mod loads;
pub mod material;
pub mod particles;
pub mod patch;
pub mod shape;
pub mod soil;

use crate::case::{Case, Formulation, ShapeFunctions, Side};
use crate::kernels::kinematics::det;
use crate::kernels::{ParticleInput, StepResult};
use grid::Grid;
use loads::{BoundaryDef, LoadDef, LoadTarget};
use material::Material;
use particles::Particles;
use shape::Basis;

/// Everything that describes the continuum and its discretisation on this rank, in `D` dimensions
/// (two unless it says otherwise). A three-dimensional model has face and nodal tractions and body
/// forces, side, region and moving-surface boundaries; the line pressures are plane (issue «Three
/// dimensions», docs/dimensions.md).
#[derive(Debug, Clone)]
pub struct Model<const D: usize = 2> {
    /// u–p–U (true) or u only.
    pub two_phase: bool,
    /// Basis functions.
    pub basis: Basis,
    /// Whether the points' domains follow the material stretch (`shape_functions = "gimp"` and the
    /// B-splines).
    pub stretch_domains: bool,
    /// Background grid.
    pub grid: Grid<D>,
    /// Materials, indexed by `particles.material`.
    pub materials: Vec<Material>,
    /// This rank's material points.
    pub particles: Particles<D>,
    /// Loads, in case order.
    pub loads: Vec<LoadDef<D>>,
    /// Dirichlet conditions, in case order.
    pub boundaries: Vec<BoundaryDef<D>>,
    /// g in Darcy's law [m/s²].
    pub g: f64,
    /// How the current stage treats time (set by the driver at the start of each stage).
    pub integration: crate::kernels::Integration,
    /// B̄ for GIMP ([000] §3).
    pub bbar: bool,
    /// [002]'s F̄ projection (explicit stages; `assembly::explicit`).
    pub fbar: bool,
    /// MLSA patch recovery of the pore-pressure increments ([003] §3.3).
    pub patch_recovery: bool,
    /// How the particles' pressure follows a converged step (two-phase).
    pub pressure_update: crate::case::PressureUpdate,
    /// Number of bodies of the case.
    pub n_bodies: usize,
    /// Factor α of the pressure-projection stabilisation τ = α/G (two-phase), if on.
    pub pressure_projection: Option<f64>,
    /// Plane strain or axial symmetry (with its particle weights), or three dimensions.
    pub geometry: shape::Geometry,
    /// The material stiffness of the Newton matrix ([001] §5).
    pub stiffness: crate::case::Stiffness,
    /// How a point's strain increment is recovered ([001] §5.5).
    pub stress_recovery: crate::case::StressRecovery,
    /// How the skeleton's internal force is integrated (at the points, or double-mapped).
    pub internal_force: crate::case::InternalForce,
    /// Geometrically linear steps (`analysis.kinematics = "linear_increments"`).
    pub linear_increments: bool,
    /// Whether the mapped `stiffness` is Newton's matrix (else it serves the K_mag diagnostic only).
    pub stiffness_in_jacobian: bool,
}

/// The geometry of a case.
pub fn geometry_of(case: &Case) -> shape::Geometry {
    if case.dimension() == 3 {
        return shape::Geometry::Solid;
    }
    match case.analysis.geometry {
        crate::case::Geometry::PlaneStrain => shape::Geometry::PlaneStrain,
        crate::case::Geometry::Axisymmetric => {
            shape::Geometry::Axisymmetric(match case.analysis.axisymmetric_weights {
                crate::case::AxisymmetricWeights::Planar => shape::AxisymmetricWeights::Planar,
                crate::case::AxisymmetricWeights::RWeighted => shape::AxisymmetricWeights::RWeighted,
            })
        }
    }
}

/// The name of the boundary an axisymmetric model adds on the axis (u_r = 0, U_r = 0 at r = 0).
pub const AXIS: &str = "axis";

/// Names of the nodal fields of a formulation's dynamic system, in dof order: ux, uy, p, Ux, Uy
/// (two-phase) or ux, uy.
pub fn field_names(two_phase: bool) -> &'static [&'static str] {
    if two_phase {
        crate::kernels::Layout::UPU.field_names()
    } else {
        crate::kernels::Layout::U.field_names()
    }
}

/// The background grid of a case of dimension `D`.
pub fn grid_of<const D: usize>(case: &Case) -> Grid<D> {
    Grid::new(case.origin_in(), case.cell_size_in(), case.cells_in())
}

/// Position of a dof component in the full two-phase order of dimension `D` (ux, uy, [uz,] p, Ux,
/// Uy[, Uz]: `Layout::UPU.in_dim(D)`, the order in which boundaries name what they fix); `None`
/// for a z component in two dimensions.
pub fn dof_index_in<const D: usize>(d: crate::case::Dof) -> Option<usize> {
    use crate::case::Dof;
    Some(match d {
        Dof::Ux => 0,
        Dof::Uy => 1,
        Dof::Uz if D == 3 => 2,
        Dof::P => D,
        Dof::WUx => D + 1,
        Dof::WUy => D + 2,
        Dof::WUz if D == 3 => D + 3,
        Dof::Uz | Dof::WUz => return None,
    })
}

/// Patch recovery in two-phase analyses when the case does not say. Off, because on the
/// small-deformation verification cases it costs accuracy (measured: harmonic column zone II
/// amplitude error 4.9e-3 → 8.9e-3, zone III 1.2e-2 → 1.6e-2, Terzaghi e_p at T_v = 0.5 1.5e-5 →
/// 4.2e-5) although it lowers their checkerboard index four- to sevenfold; large-deformation cases
/// need it (the large-strain column fails without it) and switch it on.
pub const DEFAULT_PATCH_RECOVERY: bool = false;

/// Which loads and boundaries a stage switches on.
#[derive(Debug, Clone)]
pub struct Active {
    /// Indices into `Model::loads`.
    pub loads: Vec<usize>,
    /// Indices into `Model::boundaries`.
    pub boundaries: Vec<usize>,
}

/// Why a particle update was refused.
#[derive(Debug, Clone, PartialEq)]
pub struct InadmissibleStep(pub String);

/// The components a moving surface can fix at a node: the full two-phase layout of three
/// dimensions (ux, uy, uz, p, Ux, Uy, Uz; a plane surface uses the first five, ux, uy, p, Ux, Uy).
pub const SURFACE_COMPONENTS: usize = 7;

/// A node a moving surface fixes ([`Model::surface_fixes`]): its grid indices, the boundary's
/// index and the components fixed there (in the order of [`dof_index_in`]).
pub type SurfaceFix<const D: usize> = ([u32; D], usize, [bool; SURFACE_COMPONENTS]);

/// Whether the node at `node` lies within the surface region `r` along the directions of `face`
/// other than its normal (x for a y face in the plane; in three dimensions also z, within the
/// region's `z` range if it has one), with tolerance `tol`.
fn spans_along_face<const D: usize>(r: &crate::case::Region, face: Side, node: [f64; D], tol: f64) -> bool {
    (0..D).filter(|&t| t != face.axis()).all(|t| match (t, r.z) {
        (2, None) => true,
        (2, Some([lo, hi])) => node[2] >= lo - tol && node[2] <= hi + tol,
        _ => node[t] >= r.min[t] - tol && node[t] <= r.max[t] + tol,
    })
}

impl Model {
    /// Builds the model of `case`, generating particles only in the cells `owned(i, j)`.
    pub fn build(case: &Case, owned: impl Fn(usize, usize) -> bool) -> Model {
        let grid = grid_of(case);
        let particles = Particles::generate(case, &grid, |c| owned(c[0], c[1]));
        let loads = case.load_ids().map(|l| LoadDef::from_case(l, case, &grid, &particles)).collect();
        let mut boundaries: Vec<BoundaryDef> =
            case.boundary_ids().map(|b| BoundaryDef::from_case(b, case, &particles)).collect();
        let geometry = geometry_of(case);
        if geometry.axisymmetric() && grid.origin[0].abs() <= 1e-12 * grid.h[0] {
            boundaries.push(BoundaryDef::axis());
        }
        Model { loads, boundaries, ..Model::bare(case, grid, particles) }
    }

    /// Dofs per node.
    pub fn ndof(&self) -> usize {
        if self.two_phase {
            5
        } else {
            2
        }
    }

    /// Names of the nodal fields, in dof order.
    pub fn field_names(&self) -> &'static [&'static str] {
        field_names(self.two_phase)
    }
}

impl Model<3> {
    /// Builds the model of a three-dimensional `case`, generating particles only in the cells
    /// `owned(cell)`, with its side and region boundaries and its loads.
    pub fn build_solid(case: &Case, owned: impl Fn([usize; 3]) -> bool) -> Model<3> {
        let grid = grid_of(case);
        let particles = Particles::generate(case, &grid, owned);
        let boundaries = case.boundary_ids().map(|b| BoundaryDef::from_case(b, case, &particles)).collect();
        let loads = case.load_ids().filter_map(|l| LoadDef::from_case_in(l, case, &grid, &particles)).collect();
        Model { loads, boundaries, ..Model::bare(case, grid, particles) }
    }
}

/// `x` as the two-dimensional type `P` when it is one (the same value): dimension-generic code
/// reaches the features that exist only in the plane through it (see [`Model::as_plane`]).
pub fn plane<T: 'static, P: 'static>(x: &T) -> Option<&P> {
    (x as &dyn std::any::Any).downcast_ref::<P>()
}

/// [`plane`] for a mutable value.
pub fn plane_mut<T: 'static, P: 'static>(x: &mut T) -> Option<&mut P> {
    (x as &mut dyn std::any::Any).downcast_mut::<P>()
}

/// The position `x` as "(x, y)" or "(x, y, z)" with four decimals, for messages.
pub(crate) fn position_text<const D: usize>(x: &[f64; D]) -> String {
    format!("({})", x.iter().map(|v| format!("{v:.4}")).collect::<Vec<_>>().join(", "))
}

/// The grid indices `n` as "(i, j)" or "(i, j, k)", for messages.
pub(crate) fn index_text<const D: usize>(n: &[usize; D]) -> String {
    format!("({})", n.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(", "))
}

impl<const D: usize> Model<D> {
    /// Resolves the case's moving surfaces again on this rank's points (see
    /// [`Model::resolve_targets`]).
    fn resolve_surfaces(&mut self, case: &Case) {
        for (b, c) in self.boundaries.iter_mut().zip(case.boundary_ids()) {
            if b.surface.is_some() {
                *b = BoundaryDef::from_case(c, case, &self.particles);
            }
        }
    }

    /// The nodes fixed by the active moving-surface boundaries on the current configuration, with
    /// the boundary's index and the components fixed there. For each surface particle the exposed
    /// face's outward normal turns with the material, n = F⁻ᵀn₀/|F⁻ᵀn₀| (Nanson), and among the
    /// nodes of its stencil with a non-zero weight:
    /// * the pore pressure (a drained surface) is fixed at the nodes on or beyond the face,
    ///   (x_i − x_p)·n ≥ l_p(n) (the domain's extent along n), so that no node inside the material is
    ///   drained (draining nodes up to l_p inside made the large-strain column fail);
    /// * the motion (a wall, a platen, a patch's boundary) is prescribed at the nodes on the face's
    ///   side of the particle, (x_i − x_p)·n ≥ 0: they include the well-filled node just inside a
    ///   face that has moved past a grid line, which carries the boundary's reaction (the nodes
    ///   beyond the face alone are barely filled and cannot);
    /// * with a region on the surface, only the nodes within the region's extent along the face:
    ///   the stencil of a point next to a footing's edge reaches the node beyond the edge, which
    ///   would otherwise widen the footing by a cell as soon as the point moves towards it.
    pub fn surface_fixes(&self, active: &Active, weak_drainage: bool) -> Vec<SurfaceFix<D>> {
        let mut out = Vec::new();
        let tol = 1e-9 * self.grid.h_min();
        let p = dof_index_in::<D>(crate::case::Dof::P).expect("p has a place in every dimension");
        let nc = 2 * D + 1;
        for &bi in &active.boundaries {
            let b = &self.boundaries[bi];
            let Some(list) = &b.surface else { continue };
            let mut comps = [false; SURFACE_COMPONENTS];
            for c in b.fix.iter().filter_map(|d| dof_index_in::<D>(*d)) {
                comps[c] = true;
            }
            comps[p] &= !weak_drainage;
            for &(k, face) in list {
                let (x, lp) = (self.particles.x[k], self.particles.lp[k]);
                let n = self.face_normal(k, face);
                let extent = (1..D).fold(n[0].abs() * lp[0], |e, d| e + n[d].abs() * lp[d]);
                let st: shape::Stencil<D, { crate::kernels::MAX_NODES_3D }> =
                    shape::stencil_in(self.basis, &self.grid, x, lp);
                for (node_indices, w, _) in st.iter() {
                    if w <= 0.0 {
                        continue;
                    }
                    let node = self.grid.position(node_indices.map(|v| v as usize));
                    if b.surface_span.is_some_and(|r| !spans_along_face(&r, face, node, tol)) {
                        continue;
                    }
                    let along = (1..D).fold((node[0] - x[0]) * n[0], |a, d| a + (node[d] - x[d]) * n[d]);
                    let mut c = [false; SURFACE_COMPONENTS];
                    for d in 0..nc {
                        c[d] = comps[d] && if d == p { along >= extent - tol } else { along >= -tol };
                    }
                    if c.iter().any(|&v| v) {
                        out.push((node_indices, bi, c));
                    }
                }
            }
        }
        out
    }

    /// The outward unit normal of particle `k`'s exposed `face` on the current configuration:
    /// the reference normal n₀ turned with the material, n = F⁻ᵀn₀/|F⁻ᵀn₀| (Nanson).
    pub fn face_normal(&self, k: usize, face: Side) -> [f64; D] {
        let f = self.particles.def_grad[k];
        // (A z face has no normal in the plane: validation keeps it out of plane cases.)
        let n0: [f64; D] = std::array::from_fn(|d| if d == face.axis() { face.sign() } else { 0.0 });
        // F⁻ᵀ n₀ up to the factor 1/det F.
        let m = crate::kernels::kinematics::cofactor_mul(&f, n0);
        let len = if D == 2 { m[0].hypot(m[1]) } else { m.iter().map(|v| v * v).sum::<f64>().sqrt() };
        if len > 0.0 {
            m.map(|v| v / len)
        } else {
            n0
        }
    }

    /// The exposed faces of the particles on the active moving surfaces that drain (fix `p`),
    /// each once, ordered by particle.
    pub fn drained_faces(&self, active: &Active) -> Vec<(usize, Side)> {
        let mut out: Vec<(usize, Side)> = active
            .boundaries
            .iter()
            .map(|&bi| &self.boundaries[bi])
            .filter(|b| b.fix.contains(&crate::case::Dof::P))
            .filter_map(|b| b.surface.as_ref())
            .flat_map(|list| list.iter().copied())
            .collect();
        out.sort_by_key(|&(k, face)| (k, face as u8));
        out.dedup();
        out
    }

    /// The model itself when it is two-dimensional: the features that exist only in the plane
    /// (line pressures, axial symmetry, [001]'s CMPM and mapped stiffnesses) are reached through it
    /// from dimension-generic code, and validation keeps them out of three-dimensional cases.
    pub fn as_plane(&self) -> Option<&Model> {
        plane(self)
    }

    /// The model of `case` in its dimension D ([`Model::build`] of a plane case,
    /// [`Model::build_solid`] of a three-dimensional one), generating particles only in the cells
    /// `owned(cell)`.
    pub fn of_case(case: &Case, owned: impl Fn([usize; D]) -> bool) -> Model<D> {
        // Grid indices of the model's dimension from those of the built one (the same D).
        fn same<const A: usize, const B: usize>(n: [usize; A]) -> [usize; B] {
            std::array::from_fn(|d| n[d])
        }
        let built: Box<dyn std::any::Any> = if D == 2 {
            Box::new(Model::build(case, |i, j| owned(same([i, j]))))
        } else {
            Box::new(Model::<3>::build_solid(case, |c| owned(same(c))))
        };
        *built.downcast::<Model<D>>().expect("a model of two or three dimensions")
    }

    /// Body acceleration at time `t` of the particles of each body, from the active body-force loads
    /// [m/s²] (indexed by body).
    pub fn body_accelerations(&self, active: &Active, t: f64) -> Vec<[f64; D]> {
        let nb = self.particles.body.iter().map(|&b| b as usize + 1).max().unwrap_or(0).max(self.n_bodies);
        let mut out = vec![[0.0; D]; nb];
        for &i in &active.loads {
            if let LoadTarget::BodyForce { acceleration, bodies } = &self.loads[i].target {
                let f = self.loads[i].time_fn.eval(t);
                for (b, a) in out.iter_mut().enumerate() {
                    if bodies.as_ref().is_none_or(|l| l.contains(&(b as u16))) {
                        for d in 0..D {
                            a[d] += acceleration[d] * f;
                        }
                    }
                }
            }
        }
        out
    }

    /// Resolves the case's point-wise loads (face tractions) and moving surfaces again on
    /// this rank's points, after points moved between ranks. Both depend only on what travels with
    /// a point (its body, and its position and domain at t = 0), so every point keeps its loads.
    pub fn resolve_targets(&mut self, case: &Case) {
        for (l, c) in self.loads.iter_mut().zip(case.load_ids()) {
            if matches!(l.target, LoadTarget::ParticleTraction { .. }) {
                // The state of a load with increments is global (the same on every rank): kept.
                let increments = l.increments.take();
                if let Some(resolved) = LoadDef::from_case_in(c, case, &self.grid, &self.particles) {
                    *l = resolved;
                }
                l.increments = increments;
            }
        }
        self.resolve_surfaces(case);
    }

    /// For each dof component at the grid node with indices `n`, in the full two-phase order of
    /// the dimension (ux, uy, [uz,] p, Ux, Uy[, Uz]; [`dof_index_in`]), the first active side or
    /// region boundary (index into `boundaries`, in case order) that fixes it. Moving surfaces are
    /// in [`Model::surface_fixes`].
    pub fn fixing_boundaries(&self, active: &Active, n: [usize; D]) -> [Option<usize>; crate::kernels::MAX_DOF_3D] {
        let mut by = [None; crate::kernels::MAX_DOF_3D];
        for &bi in &active.boundaries {
            let b = &self.boundaries[bi];
            if b.surface.is_none() && b.holds_node(&self.grid, n) {
                for c in b.fix.iter().filter_map(|d| dof_index_in::<D>(*d)) {
                    by[c] = by[c].or(Some(bi));
                }
            }
        }
        by
    }

    /// Takes the materials of `stage`: the case's, with the stage's strength reduction factor
    /// (`strength_reduction`, default 1) applied to their peak strengths.
    pub fn take_stage_materials(&mut self, case: &Case, stage: &crate::case::Stage) {
        self.materials = materials_of(case, stage.strength_reduction.unwrap_or(1.0));
    }

    /// Loads and boundaries active in a stage (all when the stage does not list them).
    pub fn active(&self, stage: &crate::case::Stage) -> Active {
        let pick = |names: &Option<Vec<String>>, all: Vec<&str>| -> Vec<usize> {
            match names {
                None => (0..all.len()).collect(),
                Some(ns) => (0..all.len()).filter(|&i| ns.iter().any(|n| n == all[i])).collect(),
            }
        };
        let mut boundaries = pick(&stage.boundaries, self.boundaries.iter().map(|b| b.name.as_str()).collect());
        // The axis holds in every stage.
        if let Some(axis) = self.boundaries.iter().position(|b| b.is_axis()) {
            if !boundaries.contains(&axis) {
                boundaries.push(axis);
            }
        }
        Active { loads: pick(&stage.loads, self.loads.iter().map(|l| l.name.as_str()).collect()), boundaries }
    }

    /// The model of `case` on `grid` with `particles`, without loads or boundaries.
    fn bare(case: &Case, grid: Grid<D>, particles: Particles<D>) -> Model<D> {
        Model {
            two_phase: case.analysis.formulation == Formulation::TwoPhase,
            basis: match case.analysis.shape_functions {
                ShapeFunctions::Gimp | ShapeFunctions::Ugimp => Basis::Gimp,
                ShapeFunctions::Linear => Basis::Linear,
                ShapeFunctions::Bspline2 => Basis::BSpline2,
                ShapeFunctions::Bspline3 => Basis::BSpline3,
            },
            stretch_domains: matches!(
                case.analysis.shape_functions,
                ShapeFunctions::Gimp | ShapeFunctions::Bspline2 | ShapeFunctions::Bspline3
            ),
            grid,
            materials: materials_of(case, 1.0),
            particles,
            loads: Vec::new(),
            boundaries: Vec::new(),
            g: case.analysis.g,
            integration: crate::kernels::Integration::of(&case.time_integration),
            bbar: case.stabilisation.bbar,
            fbar: case.stabilisation.fbar,
            n_bodies: case.bodies.len(),
            pressure_projection: if case.analysis.formulation == Formulation::TwoPhase {
                case.stabilisation.pressure_projection
            } else {
                None
            },
            pressure_update: case.stabilisation.pressure_update,
            geometry: geometry_of(case),
            stiffness: case.stabilisation.stiffness,
            stress_recovery: case.stabilisation.stress_recovery,
            internal_force: case.stabilisation.internal_force,
            linear_increments: case.analysis.kinematics == crate::case::KinematicsKind::LinearIncrements,
            stiffness_in_jacobian: case.stabilisation.mapped_stiffness == crate::case::MappedStiffnessUse::Jacobian,
            patch_recovery: case.analysis.formulation == Formulation::TwoPhase
                && case.stabilisation.patch_recovery.unwrap_or(DEFAULT_PATCH_RECOVERY),
        }
    }
    /// The area of particle `k` in the (x, y) plane: its volume over the geometry's measure at its
    /// radius (the volume itself in plane strain and in three dimensions) [m² or m³].
    #[inline]
    pub fn area(&self, k: usize) -> f64 {
        self.particles.volume[k] / self.geometry.measure(self.particles.x[k][0])
    }

    /// The pore water's mass n ρ_w V carried by particle `k` (zero in a one-phase run) [kg].
    #[inline]
    pub fn water_mass(&self, k: usize) -> f64 {
        let ps = &self.particles;
        if self.two_phase {
            ps.porosity[k] * self.materials[ps.material[k] as usize].water_density * ps.volume[k]
        } else {
            0.0
        }
    }

    /// The drag coefficient c = n² γ_w V/k between the phases of particle `k` ([003] Eqs. 16c–e;
    /// zero in a one-phase run) [N s/m].
    #[inline]
    pub fn drag(&self, k: usize) -> f64 {
        if !self.two_phase {
            return 0.0;
        }
        let ps = &self.particles;
        let (mat, n) = (&self.materials[ps.material[k] as usize], ps.porosity[k]);
        n * n * mat.water_density * self.g * ps.volume[k] / mat.conductivity_at(n)
    }

    /// The porosity of particle `k` after a step with volume ratio J, by conservation of solid mass,
    /// n = 1 − (1 − n₀)/J; a one-phase (total-stress) run has no porosity among its state variables
    /// and keeps the initial value.
    fn porosity_after(&self, k: usize, j: f64) -> f64 {
        let n = self.particles.porosity[k];
        if self.two_phase {
            1.0 - (1.0 - n) / j
        } else {
            n
        }
    }

    /// The kernel input of particle `k` at the start of the step.
    #[inline]
    pub fn particle_input(&self, idx: usize, body_acc: &[[f64; D]]) -> ParticleInput<D> {
        let ps = &self.particles;
        let mat = &self.materials[ps.material[idx] as usize];
        let (v, n) = (ps.volume[idx], ps.porosity[idx]);
        let (water_mass, drag, inv_q, mobility) = if self.two_phase {
            let gw = mat.water_density * self.g;
            (self.water_mass(idx), self.drag(idx), mat.inv_q_at(n), mat.conductivity_at(n) / gw)
        } else {
            (0.0, 0.0, 0.0, 0.0)
        };
        ParticleInput {
            volume: v,
            porosity: n,
            mass: ps.mass[idx],
            water_mass,
            drag,
            inv_q,
            mobility,
            water_density: mat.water_density,
            grad_p: ps.grad_p[idx],
            stress: ps.stress[idx],
            def_grad: ps.def_grad[idx],
            eps_pd: ps.eps_pd[idx],
            p: ps.p[idx],
            body_acc: body_acc[ps.body[idx] as usize],
            grad_n: [0.0; D],
            pred: Default::default(),
            linear: self.linear_increments,
            fbar: 1.0,
            fbar_total: if self.fbar { fbar::scale(ps.jbar[idx], det(&ps.def_grad[idx]), D) } else { 1.0 },
            dt: 0.0,
            jbar: ps.jbar[idx],
            fbar_rows: 0.0,
        }
    }

    /// Whether particle `k` may take the converged step: every quantity it would take must be finite,
    /// its volume ratio J positive and the porosity it implies ([`Model::porosity_after`]) inside
    /// (0, 1) in a two-phase analysis (a one-phase point keeps its porosity, which may be 0). The
    /// message names the particle and the quantity.
    pub fn check_step(&self, k: usize, step: &StepResult<D>) -> Result<(), InadmissibleStep> {
        if let Some(e) = self.nonfinite(k, step) {
            return Err(e);
        }
        let j = step.jacobian;
        let ps = &self.particles;
        let n_new = self.porosity_after(k, j);
        // A one-phase point keeps its porosity, which may be zero (a fluid, a solid).
        let porous = !self.two_phase || (n_new > 0.0 && n_new < 1.0);
        if j <= 0.0 || n_new.is_nan() || !porous {
            return Err(InadmissibleStep(format!(
                "material point {} at {} m: volume ratio J = {j:.4} gives porosity {n_new:.4}",
                ps.id[k],
                position_text(&ps.x[k])
            )));
        }
        Ok(())
    }

    /// The first quantity of particle `k`'s step that is not finite (NaN or Inf), naming the
    /// particle, if any.
    pub fn nonfinite(&self, k: usize, step: &StepResult<D>) -> Option<InadmissibleStep> {
        let ps = &self.particles;
        let it = &step.interp;
        let j = step.jacobian;
        let finite = [
            ("displacement increment", it.du.iter().all(|u| u.is_finite())),
            ("velocity", it.v_u.iter().all(|v| v.is_finite()) && it.a_u.iter().all(|a| a.is_finite())),
            ("effective stress", step.stress.iter().all(|s| s.is_finite())),
            ("pore pressure increment", it.dp.is_finite()),
            ("volume ratio", j.is_finite()),
        ];
        finite.iter().find(|f| !f.1).map(|(what, _)| {
            InadmissibleStep(format!(
                "material point {} at {} m: its {what} is not finite (NaN or Inf)",
                ps.id[k],
                position_text(&ps.x[k])
            ))
        })
    }

    /// Updates particle `k` with the converged step ([003] Eq. 24, [000] Eq. 11): in a dynamic stage,
    /// accelerations from the nodal Newmark accelerations ([003] Eq. 24a), velocities by the Newmark rule
    /// v_{n+1} = v_n + Δt((1 − γ)a_n + γ a_{n+1}) on the point (a FLIP update, where [003] Eq. 24b
    /// interpolates the nodal velocities: that PIC update damps the transients of the verification
    /// cases measurably, e.g. the Terzaghi settlement error rises from 2e-5 to 1.5e-3), the
    /// effective stress and ε̄ exactly as the converged residual computed them (objective update,
    /// see [`crate::kernels::kinematics`]), pore pressure by `dp` (the interpolated or recovered
    /// increment), position and displacement by the interpolated solid increment, deformation
    /// gradient by F_{n+1} = F̄ F_n, volume by J_v, porosity by conservation of solid mass:
    /// (1 − n_{n+1}) V_{n+1} = (1 − n_n) V_n, and (GIMP with stretching domains) the domain
    /// half-widths by l_p = l_p0 ⊙ diag(sqrt(FᵀF)) (iGIMP), at most half a cell. In a static or
    /// quasi-static stage there is no acceleration: the velocity is the step's mean, Δu/Δt, for
    /// both phases (the Darcy flux is not a particle quantity). The pore-pressure gradient follows
    /// the pressure and the material: ∇p ← ΔF⁻ᵀ(∇p + Σ ∇S Δp) (interpolated on x_n, then carried
    /// to x_{n+1}; it drives the next step's Darcy flux).
    pub fn update_particle(
        &mut self,
        k: usize,
        step: &StepResult<D>,
        dp: f64,
        dt: f64,
    ) -> Result<(), InadmissibleStep> {
        self.check_step(k, step)?;
        let j = step.jacobian;
        let n_new = self.porosity_after(k, j);
        let ps = &mut self.particles;
        let it = &step.interp;
        match self.integration {
            crate::kernels::Integration::Dynamic { gamma: g, .. } => {
                for c in 0..D {
                    ps.vel[k][c] += dt * ((1.0 - g) * ps.acc[k][c] + g * it.a_u[c]);
                    ps.acc[k][c] = it.a_u[c];
                    if self.two_phase {
                        ps.vel_w[k][c] += dt * ((1.0 - g) * ps.acc_w[k][c] + g * it.a_w[c]);
                        ps.acc_w[k][c] = it.a_w[c];
                    }
                }
            }
            crate::kernels::Integration::Explicit { flip, .. } => {
                // [002] Eqs. 11–13: FLIP v_p + Σ S (v_i^{n+1} − v_i^n) blended with PIC Σ S v_i^{n+1};
                // Σ S v_i^{n+1} = Δu_p/Δt, and Σ S v_i^n is the interpolated nodal velocity of the
                // grid update's start (`interp.v_u`, set by `GridSystem::step_result` from the
                // lumped velocities, `assembly::explicit`); the water's likewise
                // (Δw_p/Δt and `interp.v_w`). XPIC sets the solid's velocity itself
                // (`StepResult::velocity`; one-phase only).
                for c in 0..D {
                    let pic = it.du[c] / dt;
                    let blend = flip * (ps.vel[k][c] + pic - it.v_u[c]) + (1.0 - flip) * pic;
                    let v = step.velocity.map_or(blend, |v| v[c]);
                    ps.acc[k][c] = (v - ps.vel[k][c]) / dt;
                    ps.vel[k][c] = v;
                    if self.two_phase {
                        let pic = it.dw[c] / dt;
                        let v = flip * (ps.vel_w[k][c] + pic - it.v_w[c]) + (1.0 - flip) * pic;
                        ps.acc_w[k][c] = (v - ps.vel_w[k][c]) / dt;
                        ps.vel_w[k][c] = v;
                    }
                }
            }
            _ => {
                for c in 0..D {
                    ps.vel[k][c] = it.du[c] / dt;
                    ps.acc[k][c] = 0.0;
                    if self.two_phase {
                        ps.vel_w[k][c] = ps.vel[k][c];
                        ps.acc_w[k][c] = 0.0;
                    }
                }
            }
        }
        if self.two_phase {
            // The gradient on x_n, Σ ∇S Δp added, then carried to x_{n+1} with the material:
            // ∇_{n+1} p = ΔF⁻ᵀ ∇_n p (the pressure is a material field between steps).
            let g: [f64; D] = std::array::from_fn(|c| ps.grad_p[k][c] + it.grad_dp[c]);
            let fi = &step.f_inc;
            let det = det(fi);
            let m = crate::kernels::kinematics::cofactor_mul(fi, g);
            ps.grad_p[k] = m.map(|v| v / det);
        }
        for c in 0..D {
            ps.x[k][c] += it.du[c];
            ps.disp[k][c] += it.du[c];
        }
        ps.stress[k] = step.stress;
        ps.eps_pd[k] = step.eps_pd;
        if let Some(jbar) = step.jbar {
            ps.jbar[k] = jbar;
        }
        ps.p[k] += dp;
        ps.porosity[k] = n_new;
        let f = &mut ps.def_grad[k];
        let f_new = crate::kernels::kinematics::product(&step.f_inc, f);
        match self.materials[ps.material[k] as usize].model.fluid_volume_ratio(finite_strain::embed(&f_new), step.jbar)
        {
            // A fluid point carries its volume ratio only (see `Constitutive::fluid_volume_ratio`).
            Some(jf) => {
                ps.volume[k] *= jf / det(f);
                let s = if D == 2 { jf.sqrt() } else { jf.cbrt() };
                *f = std::array::from_fn(|a| std::array::from_fn(|b| if a == b { s } else { 0.0 }));
            }
            None => {
                ps.volume[k] *= j;
                *f = f_new;
            }
        }
        if self.stretch_domains {
            let u = shape::stretch_diagonal(f);
            for (d, lp) in ps.lp[k].iter_mut().enumerate() {
                *lp = (ps.lp0[k][d] * u[d]).min(0.5 * self.grid.h[d]);
            }
        }
        Ok(())
    }
}

/// The solver's materials of `case` with their peak strengths divided by the strength reduction
/// factor `f` ([`crate::case::SoilModel::with_strength_reduced`]; 1 gives the case's).
pub fn materials_of(case: &Case, f: f64) -> Vec<Material> {
    case.materials
        .iter()
        .map(|m| {
            if f == 1.0 {
                Material::from_case(m, case.analysis.formulation)
            } else {
                let reduced = crate::case::Material { model: m.model.with_strength_reduced(f), ..m.clone() };
                Material::from_case(&reduced, case.analysis.formulation)
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::Interp;

    /// The two-phase column of the case tests, with gravity's pore-pressure gradient on its points.
    fn column() -> Model {
        let c = crate::validation::load(crate::case::tests_support::MINIMAL, "t", &[]).unwrap();
        let mut m = Model::build(&c, |_, _| true);
        m.integration = crate::kernels::Integration::QuasiStatic { theta: 1.0 };
        for g in m.particles.grad_p.iter_mut() {
            *g = [300.0, -9.81e3];
        }
        m
    }

    /// A stage's strength reduction factor divides the peak strength of the model's materials from
    /// its start, and a stage without one takes the case's strength back (factors do not compound).
    #[test]
    fn a_stage_takes_its_strength_reduction_and_the_next_gives_it_back() {
        let sets: Vec<crate::case::Override> = [
            "materials.soil.model={ type = \"mohr_coulomb\", young_modulus = 1.0e7, poisson_ratio = 0.3, \
             friction_angle = 30.0, cohesion = 1.0e4 }",
            "stages.load.strength_reduction=2.0",
        ]
        .iter()
        .map(|s| crate::case::Override::parse(s).unwrap())
        .collect();
        let c = crate::validation::load(crate::case::tests_support::MINIMAL, "t", &sets).unwrap();
        let mut m = Model::build(&c, |_, _| true);
        let strength = |m: &Model| match &m.materials[0].model {
            crate::model::soil::Constitutive::MohrCoulomb(_, mc) => (mc.cohesion, mc.phi.tan()),
            _ => unreachable!(),
        };
        assert_eq!(strength(&m), (1.0e4, 30f64.to_radians().tan()));
        m.take_stage_materials(&c, &c.stages[0]);
        let (cu, tan_phi) = strength(&m);
        assert_eq!(cu, 5.0e3);
        assert!((tan_phi - 30f64.to_radians().tan() / 2.0).abs() < 1e-15);
        for _ in 0..2 {
            m.take_stage_materials(&c, &c.stages[0]);
        }
        assert_eq!(strength(&m).0, 5.0e3, "the factor does not compound");
        let plain = crate::case::Stage { strength_reduction: None, ..c.stages[0].clone() };
        m.take_stage_materials(&c, &plain);
        assert_eq!(strength(&m).0, 1.0e4);
    }

    /// The model `m` in three dimensions: its grid, points and domains extruded by one cell of
    /// `hz` along z, with F_zz = 1 (its loads and boundaries dropped).
    fn lift(m: &Model, hz: f64) -> Model<3> {
        let v = |a: [f64; 2], z: f64| [a[0], a[1], z];
        let ps = &m.particles;
        let n = ps.len();
        let mut q = Particles::<3>::default();
        for k in 0..n {
            q.push_blank(ps.id[k], ps.body[k], ps.material[k]);
            q.x[k] = v(ps.x[k], 0.5 * hz);
            q.x0[k] = v(ps.x0[k], 0.5 * hz);
            q.lp[k] = v(ps.lp[k], 0.25 * hz);
            q.lp0[k] = v(ps.lp0[k], 0.25 * hz);
            let f = ps.def_grad[k];
            q.def_grad[k] = [[f[0][0], f[0][1], 0.0], [f[1][0], f[1][1], 0.0], [0.0, 0.0, 1.0]];
            q.volume[k] = ps.volume[k];
            q.porosity[k] = ps.porosity[k];
            q.mass[k] = ps.mass[k];
            q.stress[k] = ps.stress[k];
            q.p[k] = ps.p[k];
            q.grad_p[k] = v(ps.grad_p[k], 0.0);
        }
        Model {
            two_phase: m.two_phase,
            basis: m.basis,
            stretch_domains: m.stretch_domains,
            grid: grid::Grid::new(v(m.grid.origin, 0.0), v(m.grid.h, hz), [m.grid.cells[0], m.grid.cells[1], 1]),
            materials: m.materials.clone(),
            particles: q,
            loads: Vec::new(),
            boundaries: Vec::new(),
            g: m.g,
            integration: m.integration,
            bbar: m.bbar,
            fbar: m.fbar,
            patch_recovery: m.patch_recovery,
            pressure_update: m.pressure_update,
            n_bodies: m.n_bodies,
            pressure_projection: m.pressure_projection,
            geometry: shape::Geometry::Solid,
            stiffness: m.stiffness,
            stress_recovery: m.stress_recovery,
            internal_force: m.internal_force,
            linear_increments: m.linear_increments,
            stiffness_in_jacobian: m.stiffness_in_jacobian,
        }
    }

    /// A converged step of `D` dimensions with the incremental deformation gradient `f_inc`
    /// (constant over the body, so Δu = (ΔF − I) x), the pressure gradient's increment `grad_dp`
    /// and the stress `stress`.
    fn step<const D: usize>(
        f_inc: [[f64; D]; D],
        x: [f64; D],
        grad_dp: [f64; D],
        stress: soil::Stress,
    ) -> StepResult<D> {
        let du = std::array::from_fn(|a| (0..D).map(|b| f_inc[a][b] * x[b]).sum::<f64>() - x[a]);
        StepResult {
            interp: Interp { du, grad_dp, dp: 40.0, ..Interp::default() },
            stress,
            eps_pd: 0.01,
            f_inc,
            jacobian: det(&f_inc),
            deps: [0.0; soil::NS],
            grad_n: [0.0; D],
            jbar: None,
            velocity: None,
        }
    }

    /// A plane point's update is a three-dimensional point's with F_zz = 1 and Δu_z = 0: position,
    /// volume, porosity, deformation gradient, domain, velocity and pressure gradient agree to
    /// round-off.
    #[test]
    fn a_plane_update_is_a_three_dimensional_update_without_z() {
        let mut m2 = column();
        let mut m3 = lift(&m2, 0.2);
        let f2 = [[1.01, 0.03], [-0.02, 0.97]];
        let f3 = [[1.01, 0.03, 0.0], [-0.02, 0.97, 0.0], [0.0, 0.0, 1.0]];
        let s = soil::plane([-1.0e3, -2.0e3, 150.0, -1.2e3]);
        for k in 0..m2.particles.len() {
            let x2 = m2.particles.x[k];
            m2.update_particle(k, &step(f2, x2, [10.0, -20.0], s), 40.0, 0.5).unwrap();
            let x3 = m3.particles.x[k];
            m3.update_particle(k, &step(f3, x3, [10.0, -20.0, 0.0], s), 40.0, 0.5).unwrap();
            let (p2, p3) = (&m2.particles, &m3.particles);
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * a.abs().max(1.0);
            for c in 0..2 {
                assert!(close(p2.x[k][c], p3.x[k][c]) && close(p2.vel[k][c], p3.vel[k][c]), "point {k}");
                assert!(close(p2.lp[k][c], p3.lp[k][c]) && close(p2.grad_p[k][c], p3.grad_p[k][c]), "point {k}");
                for d in 0..2 {
                    assert!(close(p2.def_grad[k][c][d], p3.def_grad[k][c][d]), "point {k}");
                }
            }
            assert!(close(p2.volume[k], p3.volume[k]) && close(p2.porosity[k], p3.porosity[k]), "point {k}");
            assert_eq!((p3.x[k][2], p3.lp[k][2], p3.def_grad[k][2][2]), (0.1, 0.05, 1.0), "point {k}");
        }
    }

    /// A general three-dimensional step: x and the displacement move by Δu, F_{n+1} = ΔF F_n, the
    /// volume by det ΔF, the porosity by conservation of the grains, the pressure gradient is
    /// carried with the material (ΔFᵀ ∇p_{n+1} = ∇p_n + Σ∇S Δp), and the domain stretches by the
    /// diagonal of U = sqrt(FᵀF); a rotation about a tilted axis leaves the domain as it was.
    #[test]
    fn a_three_dimensional_update_follows_the_deformation() {
        let m2 = column();
        let mut m3 = lift(&m2, 0.2);
        let df = [[1.02, 0.01, -0.03], [0.015, 0.98, 0.02], [-0.01, 0.025, 1.03]];
        let s = [-1.0e3, -2.0e3, 150.0, -1.2e3, 80.0, -120.0];
        let k = 3;
        let before = m3.particles.clone();
        let x = before.x[k];
        let grad_dp = [10.0, -20.0, 30.0];
        let st = step(df, x, grad_dp, s);
        m3.update_particle(k, &st, 40.0, 0.5).unwrap();
        let ps = &m3.particles;
        let j = det(&df);
        for c in 0..3 {
            assert!((ps.x[k][c] - (x[c] + st.interp.du[c])).abs() < 1e-15);
            // ΔFᵀ ∇p_{n+1} = ∇p_n + Σ ∇S Δp.
            let back: f64 = (0..3).map(|a| df[a][c] * ps.grad_p[k][a]).sum();
            assert!((back - (before.grad_p[k][c] + grad_dp[c])).abs() < 1e-9, "∇p: {back}");
            for d in 0..3 {
                let want: f64 = (0..3).map(|e| df[c][e] * before.def_grad[k][e][d]).sum();
                assert!((ps.def_grad[k][c][d] - want).abs() < 1e-15);
            }
        }
        assert!((ps.volume[k] - before.volume[k] * j).abs() < 1e-15 * before.volume[k]);
        let n0 = before.porosity[k];
        assert!(((1.0 - ps.porosity[k]) * ps.volume[k] - (1.0 - n0) * before.volume[k]).abs() < 1e-15);
        assert_eq!(ps.stress[k], s);
        // The domain: lp0 times the diagonal of U (U² = FᵀF).
        let u = shape::stretch_diagonal(&ps.def_grad[k]);
        let c: [[f64; 3]; 3] = std::array::from_fn(|a| {
            std::array::from_fn(|b| (0..3).map(|e| ps.def_grad[k][e][a] * ps.def_grad[k][e][b]).sum())
        });
        for d in 0..3 {
            assert!((ps.lp[k][d] - before.lp0[k][d] * u[d]).abs() < 1e-15);
            // U_dd² ≤ C_dd (U_dd² + Σ_{e≠d} U_de² = C_dd) and U_dd is near the stretch's square root.
            assert!(u[d] * u[d] <= c[d][d] + 1e-14 && (u[d] * u[d] - c[d][d]).abs() < 1e-3, "{u:?} {c:?}");
        }
        // A rigid rotation about a tilted axis: U = I.
        let axis: [f64; 3] = [0.3, -0.5, 0.81];
        let len: f64 = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        let r = soil::principal::rotation(axis.map(|a| a / len), 0.7);
        let u = shape::stretch_diagonal(&r);
        assert!(u.iter().all(|v| (v - 1.0).abs() < 1e-14), "{u:?}");
    }
}
