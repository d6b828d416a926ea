//! The physical model of a run: grid geometry, bases, materials (their soil models are
//! [`crate::soils`]'), material points, loads and Dirichlet conditions. Pure Rust; the particle update after a converged step is
//! [`crate::update`]'s, the global system [`crate::assembly`]'s.

pub mod cmpm;
pub mod fbar;
pub mod grid;
pub mod loads;
pub mod material;
pub mod memory;
pub mod particles;
pub mod patch;
pub mod shape;

use crate::case::{Case, Formulation, ShapeFunctions, Side};
use grid::Grid;
use loads::{BoundaryDef, LoadDef, LoadTarget};
use material::Material;
use particles::Particles;
use shape::Basis;

/// Everything that describes the continuum and its discretisation on this rank, in `D` dimensions
/// (two unless it says otherwise). A three-dimensional model has face and nodal tractions and body
/// forces, side, region and moving-surface boundaries; the line pressures are plane
/// (docs/dimensions.md).
#[derive(Debug, Clone)]
pub struct Model<const D: usize = 2> {
    /// Whether the points carry pore water (the two-phase formulation; its stages solve u–p–U,
    /// u–p or u–U) rather than being one-phase (dry, or total stress).
    pub pore_water: bool,
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
    pub integration: crate::scheme::Integration,
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
    /// The bodies' names, in case order (for messages).
    pub body_names: Vec<String>,
    /// Factor α of the pressure-projection stabilisation τ = α/G (two-phase), if on.
    pub pressure_projection: Option<f64>,
    /// Plane strain or axial symmetry (with its particle weights), or three dimensions.
    pub geometry: shape::Geometry,
    /// The material stiffness of the Newton matrix ([001] §5).
    pub stiffness: crate::case::Stiffness,
    /// How a point's strain increment is recovered ([001] §5.5).
    pub stress_recovery: crate::case::StressRecovery,
    /// The factor α of the control of the modes CMPM's recovered strain filters (0: none).
    pub filtered_mode_control: f64,
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
pub fn field_names(pore_water: bool) -> &'static [&'static str] {
    if pore_water {
        crate::layout::Layout::UPU.field_names()
    } else {
        crate::layout::Layout::U.field_names()
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

/// When the loads that follow their faces are set ([`Model::set_load_increments`]).
#[derive(Clone, Copy)]
pub enum LoadsAt<'a> {
    /// The run's start.
    Start,
    /// The end of an accepted step.
    Accepted,
    /// A restart, with the checkpoint's sums of increments per load.
    Restart(&'a [f64]),
}

/// Which loads and boundaries a stage switches on.
#[derive(Debug, Clone)]
pub struct Active {
    /// Indices into `Model::loads`.
    pub loads: Vec<usize>,
    /// Indices into `Model::boundaries`.
    pub boundaries: Vec<usize>,
}

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
    /// Builds the plane model of `case`, generating particles only in the cells `owned(i, j)`
    /// ([`Model::of_case`] with the plane's cell indices).
    pub fn build(case: &Case, owned: impl Fn(usize, usize) -> bool) -> Model {
        Model::of_case(case, |c| owned(c[0], c[1]))
    }

    /// Dofs per node.
    pub fn ndof(&self) -> usize {
        if self.pore_water {
            5
        } else {
            2
        }
    }

    /// Names of the nodal fields, in dof order.
    pub fn field_names(&self) -> &'static [&'static str] {
        field_names(self.pore_water)
    }
}

impl Model<3> {
    /// Builds the model of a three-dimensional `case` ([`Model::of_case`]).
    pub fn build_solid(case: &Case, owned: impl Fn([usize; 3]) -> bool) -> Model<3> {
        Model::of_case(case, owned)
    }
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
            for c in b.held().filter_map(dof_index_in::<D>) {
                comps[c] = true;
            }
            comps[p] &= !weak_drainage;
            for &(k, face) in list {
                let (x, lp) = (self.particles.x[k], self.particles.lp[k]);
                let n = self.face_normal(k, face);
                let extent = (1..D).fold(n[0].abs() * lp[0], |e, d| e + n[d].abs() * lp[d]);
                let st: shape::Stencil<D, { shape::MAX_STENCIL_3D }> = shape::stencil_in(self.basis, &self.grid, x, lp);
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
        let m = crate::algebra::cofactor_mul(&f, n0);
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

    /// The model of `case` in its dimension D, generating particles only in the cells
    /// `owned(cell)`: its points, its loads and boundaries, and in axial symmetry the axis's
    /// boundary (u_r = U_r = 0 at r = 0) when the grid starts on the axis.
    pub fn of_case(case: &Case, owned: impl Fn([usize; D]) -> bool) -> Model<D> {
        let grid = grid_of(case);
        let particles = Particles::generate(case, &grid, owned);
        let loads = case.load_ids().filter_map(|l| LoadDef::from_case_in(l, case, &grid, &particles)).collect();
        let mut boundaries: Vec<BoundaryDef<D>> =
            case.boundary_ids().map(|b| BoundaryDef::from_case(b, case, &particles)).collect();
        if geometry_of(case).axisymmetric() && grid.origin[0].abs() <= 1e-12 * grid.h[0] {
            boundaries.push(BoundaryDef::axis());
        }
        Model { loads, boundaries, ..Model::bare(case, grid, particles) }
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
    pub fn fixing_boundaries(&self, active: &Active, n: [usize; D]) -> [Option<usize>; crate::layout::MAX_DOF_3D] {
        self.first_holders(active, n, |_| true)
    }

    /// For each dof component at the grid node with indices `n` (as [`Model::fixing_boundaries`]),
    /// the first active side, region or mesh boundary that holds it among those `which` selects.
    fn first_holders(
        &self,
        active: &Active,
        n: [usize; D],
        which: impl Fn(&BoundaryDef<D>) -> bool,
    ) -> [Option<usize>; crate::layout::MAX_DOF_3D] {
        let mut by = [None; crate::layout::MAX_DOF_3D];
        for &bi in &active.boundaries {
            let b = &self.boundaries[bi];
            if which(b) && b.surface.is_none() && b.holds_node(&self.grid, n) {
                for c in b.held().filter_map(dof_index_in::<D>) {
                    by[c] = by[c].or(Some(bi));
                }
            }
        }
        by
    }

    /// A component that a rigid body (a boundary under a force) and another boundary both hold at
    /// the grid node with indices `n`: (the body, the other, the component's [`dof_index_in`]
    /// index), if any (side, region and mesh boundaries; the first such component).
    pub fn rigid_conflict(&self, active: &Active, n: [usize; D]) -> Option<(usize, usize, usize)> {
        let rigid = self.first_holders(active, n, |b| b.force.is_some());
        let other = self.first_holders(active, n, |b| b.force.is_none());
        (0..crate::layout::MAX_DOF_3D).find_map(|c| Some((rigid[c]?, other[c]?, c)))
    }

    /// Takes the materials of `stage`: the case's, with the stage's strength reduction factor
    /// (`strength_reduction`, default 1) applied to their peak strengths.
    pub fn take_stage_materials(&mut self, case: &Case, stage: &crate::case::Stage) {
        self.materials = materials_of(case, stage.strength_reduction.unwrap_or(1.0));
    }

    /// Sets every load whose increments follow its loaded faces at time `t`
    /// ([`loads::LoadDef::set_increments`]), at the faces' mean centre over all ranks: at the run's
    /// start, after an accepted step, or from a checkpoint's sums of increments per load
    /// (collective). At the start a load that cannot be evaluated is the case's fault.
    pub fn set_load_increments(
        &mut self,
        t: f64,
        at: LoadsAt,
        coll: &crate::parallel::Collective,
    ) -> Result<(), String> {
        for li in 0..self.loads.len() {
            // Whether a load has increments is the case's: every rank takes the same branch.
            if self.loads[li].increments.is_none() {
                continue;
            }
            let local = self.loads[li].face_moments(&self.particles, &self.geometry);
            let m = coll.sum(&local)?;
            let load = &mut self.loads[li];
            if m[D] <= 0.0 {
                return Err(format!(
                    "load `{}`: no loaded face is left to evaluate its increment_factor at",
                    load.name
                ));
            }
            let from = match at {
                LoadsAt::Start => loads::IncrementsFrom::Start,
                LoadsAt::Accepted => loads::IncrementsFrom::Accepted,
                LoadsAt::Restart(totals) => loads::IncrementsFrom::Checkpoint(totals[li]),
            };
            load.set_increments(t, std::array::from_fn(|d| m[d] / m[D]), from)?;
        }
        Ok(())
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
            pore_water: case.analysis.formulation == Formulation::TwoPhase,
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
            integration: case.time_integration.integration(),
            bbar: case.stabilisation.bbar,
            fbar: case.stabilisation.fbar,
            n_bodies: case.bodies.len(),
            body_names: case.bodies.iter().map(|b| b.name.clone()).collect(),
            pressure_projection: if case.analysis.formulation == Formulation::TwoPhase {
                case.stabilisation.pressure_projection
            } else {
                None
            },
            pressure_update: case.stabilisation.pressure_update,
            geometry: geometry_of(case),
            stiffness: case.stabilisation.stiffness,
            stress_recovery: case.stabilisation.stress_recovery,
            filtered_mode_control: case.stabilisation.filtered_mode_control,
            internal_force: case.stabilisation.internal_force,
            linear_increments: case.analysis.kinematics == crate::case::KinematicsKind::LinearIncrements,
            stiffness_in_jacobian: case.stabilisation.mapped_stiffness == crate::case::MappedStiffnessUse::Jacobian,
            patch_recovery: case.analysis.formulation == Formulation::TwoPhase
                && case.stabilisation.patch_recovery.unwrap_or(DEFAULT_PATCH_RECOVERY),
        }
    }
    /// The identifier of the material point nearest to `point` at t = 0 over all ranks, the lowest
    /// identifier among equally near ones; None without material points (collective).
    pub fn nearest_point(&self, coll: &crate::parallel::Collective, point: &[f64]) -> Result<Option<u64>, String> {
        let ps = &self.particles;
        let local: Vec<f64> = (0..ps.len())
            .flat_map(|k| {
                let distance = (0..D).map(|d| (ps.x0[k][d] - point[d]).powi(2)).sum::<f64>().sqrt();
                [distance, ps.id[k] as f64]
            })
            .collect();
        let all = coll.gather(&local)?;
        let best = all.chunks(2).min_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
        Ok(best.map(|b| b[1] as u64))
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
        if self.pore_water {
            ps.porosity[k] * self.materials[ps.material[k] as usize].water_density * ps.volume[k]
        } else {
            0.0
        }
    }

    /// The drag coefficient c = n² γ_w V/k between the phases of particle `k` ([003] Eqs. 16c–e;
    /// zero in a one-phase run) [N s/m].
    #[inline]
    pub fn drag(&self, k: usize) -> f64 {
        if !self.pore_water {
            return 0.0;
        }
        let ps = &self.particles;
        let (mat, n) = (&self.materials[ps.material[k] as usize], ps.porosity[k]);
        n * n * mat.water_density * self.g * ps.volume[k] / mat.conductivity_at(n)
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
            crate::soils::Constitutive::MohrCoulomb(mc) => (mc.cohesion, mc.phi.tan()),
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
}
