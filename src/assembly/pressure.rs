//! The pore pressure's part of a step: its scale in PETSc's unknowns, the drained faces and
//! nodes, the pressure-projection cells, the diagonal of the fixed-stress Schur preconditioner, and
//! the pressure increments a converged step gives its points (the L² projection of the total field,
//! or MLSA patch recovery).

use super::space::NodeSpace;
use super::splits::SchurNeeds;
use super::step::{ProjectionCell, Solution, Step};
use super::{Error, NITSCHE_PENALTY, STENCIL_WIDTH};
use crate::kernels::{self, DrainedFace};
use crate::layout::Layout;
use crate::model::loads::face_point;
use crate::model::{shape, Active, Model};
use crate::scheme::Scheme;
use petsc::ksp::KspOps;
use petsc::mat::MatOps;
use petsc::{DmDa, Ksp, VecOps};

/// The scale s of the pressure unknowns [Pa/m]: the largest constrained modulus of the skeleton
/// over the smallest cell size, M/h. PETSc solves for Δp / s, and the continuity rows are
/// multiplied by s (a symmetric diagonal scaling, so a symmetric tangent stays symmetric). A
/// momentum row's entries are of order M (stiffness) and its coupling to the pressure of order h,
/// so after scaling the coupling block is of order M as well, and a volume imbalance δV of a
/// continuity row weighs s δV, as much as the force M δV / h it would take to close it. Without
/// it the continuity rows are 1e-9…1e-20 of the momentum rows, and Newton's residual norm (and
/// its absolute tolerance) cannot see an unsolved pressure equation: a quasi-static step that
/// starts from the extrapolated increment was accepted with no iteration while its pore pressure
/// drifted by 0.1 % of the load per step (Terzaghi, Δt = 0.1 s).
pub fn scale<const D: usize>(model: &Model<D>) -> f64 {
    let m = model.materials.iter().map(|m| m.model.elastic().constrained_modulus()).fold(0.0, f64::max);
    let h = model.grid.h_min();
    if m > 0.0 && h > 0.0 {
        m / h
    } else {
        1.0
    }
}

/// The share c of the solid's fixed-stress term in the Schur preconditioner of the u–p–U system
/// (see [`fixed_stress_diagonal`]) for a step of `dt`: c = min(1, Cr / 108), Cr = c_p Δt / h the
/// Courant number of the fastest drained compression wave, c_p = √(M / ρ) with the drained
/// constrained modulus M and the mixture's density ρ = (1 − n) ρ_s + n ρ_w, h the smallest cell
/// size. Fitted on the spectra of the slumping block's tangents (docs/solvers.md): the best shares
/// 0.0625 at Δt = 4 ms and 0.25 at 16 ms on 64 × 48 cells (Cr = 6.7 and 27) lie on it, and at 1 ms
/// (Cr = 1.7; best share 0) it adds 0.016.
fn fixed_stress_share<const D: usize>(model: &Model<D>, dt: f64) -> f64 {
    let cp = model
        .materials
        .iter()
        .map(|m| {
            let rho = (1.0 - m.porosity) * m.solid_density + m.porosity * m.water_density;
            (m.model.elastic().constrained_modulus() / rho).sqrt()
        })
        .fold(0.0, f64::max);
    (cp * dt / model.grid.h_min() / FIXED_STRESS_COURANT).min(1.0)
}

/// The Courant number at which [`fixed_stress_share`] reaches 1.
const FIXED_STRESS_COURANT: f64 = 108.0;

/// Whether a step of `dt` imposes the drained moving surfaces weakly, on the particles' faces
/// ([`kernels::flow::drained_face`]): the u–p system with Darcy flow, whose drainage is an
/// essential condition. The u–p–U system drains through its water's motion (p = 0 is natural
/// there) and keeps the pressure fixed at the nodes beyond the surface, as a system without
/// flow does.
pub(super) fn drains_weakly<const D: usize>(layout: Layout, model: &Model<D>, dt: f64) -> bool {
    let flow = layout.p.is_some() && layout.w.is_none();
    flow && Scheme::of(&model.integration, dt, flow).flow_dt > 0.0
}

/// Which ghosted nodes are drained in a two-phase explicit step with the nodal pore pressure
/// (see [`super::explicit`]), in any dimension: a side or region boundary of the stage fixes `p`
/// there, a moving surface that fixes `p` reaches it (marks summed over the ranks, a collective
/// every rank takes when a moving surface is active), or the material barely fills it (the
/// drained value of implicit stages' barely filled nodes).
pub(super) fn drained_nodes<const D: usize, const M: usize>(
    space: &mut NodeSpace<D>,
    step: &Step<D, M>,
    model: &Model<D>,
    active: &Active,
) -> Result<Vec<bool>, Error> {
    let nd = space.layout.nd;
    let p = crate::model::dof_index_in::<D>(crate::case::Dof::P).unwrap_or(D);
    let mut marks = Vec::new();
    // Whether a boundary is a moving surface is the case's: every rank takes the same branch.
    if active.boundaries.iter().any(|&b| model.boundaries[b].surface.is_some()) {
        marks = vec![0.0; space.ghost.len() * nd];
        for (n, _, comps) in model.surface_fixes(active, false) {
            if let Some(l) = space.ghost.local(n.map(|v| v as usize)).filter(|_| comps[p]) {
                marks[l * nd] = 1.0;
            }
        }
        space.sum_over_ranks(&mut marks)?;
    }
    Ok((0..space.ghost.len())
        .map(|l| {
            marks.get(l * nd).is_some_and(|&m| m > 0.0)
                || !step.dofs.well[l]
                || model.fixing_boundaries(active, space.ghost.indices(l))[p].is_some()
        })
        .collect())
}

/// The drained faces of this rank's particles with their geometry and the grid's multilinear
/// shape functions at the face point, ordered by particle (see [`kernels::DrainedFace`]). The
/// gradient is the one on the material's side of a grid line through the face point.
pub(super) fn drained_faces<const D: usize, const M: usize>(
    space: &NodeSpace<D>,
    step: &Step<D, M>,
    model: &Model<D>,
    active: &Active,
) -> Vec<(usize, DrainedFace<D, M>)> {
    let (g, ps) = (&model.grid, &model.particles);
    let penalty = NITSCHE_PENALTY / g.h_min();
    model
        .drained_faces(active)
        .into_iter()
        .map(|(k, face)| {
            let normal = model.face_normal(k, face);
            let (xf, measure) = face_point(face, ps.x[k], ps.lp[k]);
            let area = measure * model.geometry.measure(xf[0]);
            let inside: [f64; D] = std::array::from_fn(|d| xf[d] - 1e-9 * g.h[d] * normal[d]);
            let mut basis = [(0.0, [0.0; D]); M];
            let (nodes, _) = step.stencils.get(k);
            for (b, &node) in basis.iter_mut().zip(nodes) {
                let n = space.ghost.indices(node as usize);
                *b = shape::multilinear(g.position(n), xf, inside, g.h);
            }
            let offset = std::array::from_fn(|d| xf[d] - ps.x[k][d]);
            (k, DrainedFace { offset, normal, area, penalty, basis })
        })
        .collect()
}

/// The pressure-projection cells, over this rank's particles grouped by the cell holding their
/// centre (`kernels::pressure_projection` with the cell's 2^D multilinear functions at the points,
/// weights α/G V); none without a pressure or a projection, and none for a cell whose corners are
/// not all ghosted.
pub(super) fn projection_cells<const D: usize>(space: &NodeSpace<D>, model: &Model<D>) -> Vec<ProjectionCell> {
    let mut out = Vec::new();
    let (Some(_), Some(alpha)) = (space.layout.p, model.pressure_projection) else { return out };
    let g = &model.grid;
    let ps = &model.particles;
    let mut cells: std::collections::BTreeMap<[usize; D], Vec<usize>> = Default::default();
    for k in 0..ps.len() {
        if let Some(c) = g.cell_containing(ps.x[k]) {
            cells.entry(c).or_default().push(k);
        }
    }
    let corners = 1usize << D;
    // Corner m of a cell: its bit d says whether the corner is the upper node along d.
    let upper = |m: usize, d: usize| (m >> d) & 1 == 1;
    for (c, members) in cells {
        let Some(nodes) = (0..corners)
            .map(|m| {
                let n: [usize; D] = std::array::from_fn(|d| c[d] + upper(m, d) as usize);
                space.ghost.local(n).map(|l| l as u32)
            })
            .collect::<Option<Vec<u32>>>()
        else {
            continue;
        };
        let o = g.position(c);
        // The multilinear functions at each point (the unused corners of a plane cell zero).
        let n: Vec<[f64; 8]> = members
            .iter()
            .map(|&k| {
                let x: [f64; D] = std::array::from_fn(|d| (ps.x[k][d] - o[d]) / g.h[d]);
                std::array::from_fn(|m| {
                    if m >= corners {
                        return 0.0;
                    }
                    (0..D).fold(1.0, |acc, d| acc * if upper(m, d) { x[d] } else { 1.0 - x[d] })
                })
            })
            .collect();
        let w: Vec<f64> = members
            .iter()
            .map(|&k| {
                let shear = model.materials[ps.material[k] as usize].model.elastic().shear_modulus();
                alpha / shear * ps.volume[k]
            })
            .collect();
        let s = kernels::pressure_projection(&n, &w);
        let s = (0..corners).flat_map(|a| (0..corners).map(move |b| s[a][b])).collect();
        out.push(ProjectionCell { nodes, s });
    }
    out
}

/// The diagonal d of porompm's Schur preconditioners (see [`super::splits`]), per owned pressure
/// row in the `p` split's order, in PETSc's scaling (s the pressure scale); 0 on fixed pressures,
/// whose rows stay the unit diagonal. Empty without such a preconditioner.
///
/// * u–p: Sp = A_pp + diag(d), d_i = −s² Σ_k N_i(x_k) V_k / K_dr,k, the lumped pressure mass of
///   the points over their skeleton's drained bulk modulus (λ + μ in plane strain, λ + 2μ/3 in
///   three dimensions). It is the volume change of the fixed-stress split, β = α²/K_dr with
///   Biot's α = 1 (incompressible grains, as the continuity equation assumes), with the sign of
///   A_pp's storage term.
/// * u–p–U: Sp = A_pp − A_pu B⁻¹ A_up + diag(d), d_i = −c s² Σ_k (1 − n_k)² N_i(x_k) V_k /
///   K_dr,k: the share c ([`fixed_stress_share`]) of the solid's part of that term.
///   B⁻¹'s diagonal captures the inertia, which dominates the long waves; the skeleton's
///   compressibility dominates the waves shorter than the distance a compression wave crosses
///   in a step, a share that grows with the step's Courant number.
pub(super) fn fixed_stress_diagonal<const D: usize, const M: usize>(
    space: &mut NodeSpace<D>,
    step: &Step<D, M>,
    model: &Model<D>,
    schur: &SchurNeeds,
) -> Result<Vec<f64>, Error> {
    let (Some(p), true) = (space.layout.p, schur.schur) else { return Ok(Vec::new()) };
    let dynamic = space.layout.w.is_some();
    let share = if dynamic { schur.tuning.share.unwrap_or_else(|| fixed_stress_share(model, step.dt)) } else { 1.0 };
    let nd = space.layout.nd;
    let mut mass = vec![0.0; space.ghost.len() * nd];
    let (st, ps) = (&step.stencils, &model.particles);
    for k in 0..st.len() {
        let elastic = model.materials[ps.material[k] as usize].model.elastic();
        let drained = if D == 3 { elastic.bulk_modulus() } else { elastic.plane_bulk_modulus() };
        let solid = if dynamic { (1.0 - ps.porosity[k]).powi(2) } else { 1.0 };
        let (nodes, basis) = st.get(k);
        for (&node, nb) in nodes.iter().zip(basis) {
            mass[node as usize * nd + p] += nb.s * ps.volume[k] * solid / drained;
        }
    }
    space.sum_over_ranks(&mut mass)?;
    let s2 = step.p_scale * step.p_scale;
    let fixed = &step.dofs.fixed;
    Ok(space
        .owned_nodes
        .iter()
        .map(|&a| a as usize * nd + p)
        .map(|q| if fixed[q] { 0.0 } else { -share * s2 * mass[q] })
        .collect())
}

/// The one-field DMDA and CG solver of the pressure's L² projection
/// (`stabilisation.pressure_update = "projected_total"`), built on a system's first use.
pub(super) struct L2Projection<const D: usize> {
    dm: DmDa<D>,
    ksp: Ksp,
}

impl<const D: usize> L2Projection<D> {
    /// The projection's solver on the same distribution of the nodes as `space`.
    pub(super) fn new(space: &NodeSpace<D>) -> Result<L2Projection<D>, Error> {
        let counts = space.owners().counts_in();
        let ranges: [&[usize]; D] = std::array::from_fn(|d| &counts[d][..]);
        let dm = DmDa::new_partitioned(space.comm, space.dm.info().nodes, STENCIL_WIDTH, &["p"], Some(ranges))?;
        let mut ksp = Ksp::new(space.comm)?;
        ksp.set_prefix("pressure_projection_")?;
        ksp.set_type("cg")?;
        ksp.pc()?.set_type("jacobi")?;
        ksp.set_tolerances(Some(1e-12), Some(0.0), Some(10_000))?;
        ksp.set_from_options()?;
        Ok(L2Projection { dm, ksp })
    }

    /// Pore-pressure increments that make each particle's pressure the interpolation of the total
    /// nodal field, p_{n+1} = Σ S_i (P_i + Δp_i) (`stabilisation.pressure_update =
    /// "projected_total"`). P is the consistent L² projection of the particles' pressures p_n onto
    /// the nodal functions: M P = b with M_ij = Σ_p V_p S_ip S_jp and b_i = Σ_p V_p S_ip p_p, solved
    /// by CG with Jacobi (options prefix `pressure_projection_`, relative tolerance 1e-12). A
    /// pressure field the nodes represent comes back unchanged (no smoothing, unlike a lumped
    /// projection), and what they cannot represent is dropped instead of accumulating on the
    /// particles. Nodes no particle reaches get P = 0 (a regularisation of 1e-12 of a cell's area
    /// on every diagonal). Collective; in any dimension.
    pub(super) fn increments<const M: usize>(
        &mut self,
        space: &NodeSpace<D>,
        step: &Step<D, M>,
        solution: &Solution,
        model: &Model<D>,
    ) -> Result<Vec<f64>, Error> {
        let nd = space.layout.nd;
        let pc = space.layout.p.ok_or_else(|| Error::new("the L² projection of a layout without pressure"))?;
        let (dm1, ksp) = (&self.dm, &mut self.ksp);
        let pattern = &step.pattern;
        let (rows, cols) = pattern.coo(1, dm1.local_to_global());
        let mut mat = dm1.create_matrix_coo(&rows, &cols)?;
        let mut values = vec![0.0; pattern.len()];
        let ng = space.ghost.len();
        let mut b = vec![0.0; ng];
        let ps = &model.particles;
        let st = &step.stencils;
        for k in 0..st.len() {
            let (nodes, basis) = st.get(k);
            for (&a, ba) in nodes.iter().zip(basis).filter(|(_, nb)| nb.s != 0.0) {
                let w = ps.volume[k] * ba.s;
                b[a as usize] += w * ps.p[k];
                let ia = pattern.indices(a);
                for (&c, bc) in nodes.iter().zip(basis).filter(|(_, nb)| nb.s != 0.0) {
                    values[pattern.block_of(a, ia, c, pattern.indices(c)) as usize] += w * bc.s;
                }
            }
        }
        let eps = model.grid.h.iter().fold(1e-12, |e, h| e * h);
        for &a in &space.owned_nodes {
            let block = pattern.block(a, a).ok_or_else(|| Error::new("an owned diagonal block is not listed"))?;
            values[block as usize] += eps;
        }
        mat.set_values_coo(&values, false)?;
        let mut b_local = dm1.create_local_vector()?;
        b_local.write()?.copy_from_slice(&b);
        let mut b_global = dm1.create_global_vector()?;
        b_global.set_all(0.0)?;
        dm1.local_to_global_add(&b_local, &mut b_global)?;
        let mut p_global = dm1.create_global_vector()?;
        ksp.set_operators(&mat, &mat)?;
        let out = ksp.solve(&b_global, &mut p_global)?;
        if out.reason <= 0 {
            return Err(Error::new(format!(
                "the L² projection of the pore pressure (stabilisation.pressure_update = \"projected_total\") did not \
                 converge: {} after {} CG iterations",
                out.reason_text, out.iterations
            )));
        }
        let mut p_local = dm1.create_local_vector()?;
        dm1.global_to_local(&p_global, &mut p_local)?;
        let total: Vec<f64> = {
            let pl = p_local.read()?;
            (0..ng).map(|l| pl[l] + solution.increments[l * nd + pc]).collect()
        };
        Ok((0..st.len())
            .map(|k| {
                let (nodes, basis) = st.get(k);
                nodes.iter().zip(basis).map(|(&n, nb)| nb.s * total[n as usize]).sum::<f64>() - ps.p[k]
            })
            .collect())
    }
}

/// Pore-pressure increments of the converged step recovered at every particle by MLSA patches
/// ([003] §3.3; see [`crate::model::patch`]); a particle without any active cell near it keeps the
/// interpolated increment (`interpolated(k)`).
pub(super) fn recovered_increments<const D: usize, const M: usize>(
    space: &NodeSpace<D>,
    step: &Step<D, M>,
    solution: &Solution,
    model: &Model<D>,
    interpolated: impl Fn(usize) -> f64,
) -> Vec<f64> {
    let nd = space.layout.nd;
    let Some(p) = space.layout.p else { return (0..model.particles.len()).map(interpolated).collect() };
    let dp: Vec<f64> = (0..space.ghost.len()).map(|l| solution.increments[l * nd + p]).collect();
    let field = crate::model::patch::PatchField {
        grid: &model.grid,
        start: space.ghost.start,
        count: space.ghost.count,
        dp: &dp,
        active: &step.dofs.well,
    };
    (0..model.particles.len()).map(|k| field.recover(model.particles.x[k]).unwrap_or_else(|| interpolated(k))).collect()
}
