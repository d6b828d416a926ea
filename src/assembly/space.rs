//! The grid's nodes on this rank ([`NodeSpace`]): the DMDA that distributes them (dofs of the
//! layout interlaced per node), the ghosted block a rank's points reach, the owned block it
//! writes, and the sum of a ghosted array over the ranks. Every step is built on it.

use super::step::{Solution, Step};
use super::{Error, STENCIL_WIDTH};
use crate::distribution::Owners;
use crate::layout::Layout;
use crate::model::grid::{flat_number, Grid};
use crate::parallel::Collective;
use mpi::raw::AsRaw;
use petsc::{Comm, DmDa, GhostedRange, VecOps, Vector};

/// The grid's nodes as this rank sees them (a grid of dimension D).
pub struct NodeSpace<const D: usize = 2> {
    pub(super) comm: Comm,
    pub(super) dm: DmDa<D>,
    pub(super) layout: Layout,
    /// The ghosted nodes: every node this rank's points reach.
    pub(super) ghost: GhostedRange<D>,
    pub(super) owned_start: [usize; D],
    pub(super) owned_count: [usize; D],
    /// Ghosted indices of the owned nodes, x fastest.
    pub(super) owned_nodes: Vec<u32>,
    /// Which rank owns which cells (the DMDA's ownership ranges).
    owners: Owners<D>,
    /// Global index of every ghosted dof.
    pub(super) l2g: Vec<i32>,
    work_local: Vector,
    work_global: Vector,
}

impl<const D: usize> NodeSpace<D> {
    /// The nodes of `grid` with the dofs of `layout`, distributed over the run's ranks as
    /// `partition` says (None: PETSc's even split).
    pub fn new(
        coll: &Collective,
        grid: &Grid<D>,
        layout: Layout,
        partition: Option<&Owners<D>>,
    ) -> Result<NodeSpace<D>, Error> {
        if layout.dim != D {
            return Err(Error::new(format!(
                "a grid system of dimension {D} was given a layout of dimension {} (`Layout::in_dim`)",
                layout.dim
            )));
        }
        let comm = Comm::from_raw(coll.communicator().as_raw());
        let counts = partition.map(|o| o.counts_in());
        let ranges = counts.as_ref().map(|c| std::array::from_fn(|d| &c[d][..]));
        let dm = DmDa::new_partitioned(comm, grid.nodes(), STENCIL_WIDTH, layout.field_names(), ranges)
            .map_err(|e| explain_split(e, grid, coll.size()))?;
        let info = *dm.info();
        let l2g: Vec<i32> = dm.local_to_global().to_vec();
        if l2g.len() != info.ghosted.len() * layout.nd {
            return Err(Error::new(format!(
                "the DMDA's local-to-global map has {} entries for {} ghosted dofs",
                l2g.len(),
                info.ghosted.len() * layout.nd
            )));
        }
        let ranges = dm.ownership()?;
        let owners = Owners::from_counts(std::array::from_fn(|d| &ranges[d][..]));
        let owned_block = GhostedRange { start: info.owned_start, count: info.owned_count, dof: 1 };
        let owned_nodes = (0..owned_block.len())
            .map(|o| info.ghosted.local(owned_block.indices(o)).map(|l| l as u32))
            .collect::<Option<Vec<u32>>>()
            .ok_or_else(|| Error::new("an owned node is not among the ghosted ones"))?;
        Ok(NodeSpace {
            comm,
            work_local: dm.create_local_vector()?,
            work_global: dm.create_global_vector()?,
            dm,
            layout,
            ghost: info.ghosted,
            owned_start: info.owned_start,
            owned_count: info.owned_count,
            owned_nodes,
            owners,
            l2g,
        })
    }

    /// Which rank owns which cells (the DMDA's ownership ranges).
    pub fn owners(&self) -> &Owners<D> {
        &self.owners
    }

    /// Whether this rank owns the node with indices `n`, and with it the cell whose lowest corner
    /// it is.
    pub fn owns_cell_in(&self, n: [usize; D]) -> bool {
        (0..D).all(|d| n[d] >= self.owned_start[d] && n[d] < self.owned_start[d] + self.owned_count[d])
    }

    /// The dof layout.
    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// Total dofs of the grid (all nodes × dofs per node).
    pub fn total_dofs(&self) -> usize {
        self.dm.info().nodes.iter().product::<usize>() * self.layout.nd
    }

    /// The positions of the owned nodes, x fastest.
    pub(super) fn owned_positions(&self, grid: &Grid<D>) -> Vec<[f64; D]> {
        self.owned_nodes.iter().map(|&a| grid.position(self.ghost.indices(a as usize))).collect()
    }

    /// Sums a ghosted per-dof array over ranks: afterwards every ghost holds the global total.
    pub(super) fn sum_over_ranks(&mut self, data: &mut [f64]) -> Result<(), Error> {
        self.work_local.write()?.copy_from_slice(data);
        self.work_global.set_all(0.0)?;
        self.dm.local_to_global_add(&self.work_local, &mut self.work_global)?;
        self.dm.global_to_local(&self.work_global, &mut self.work_local)?;
        data.copy_from_slice(&self.work_local.read()?);
        Ok(())
    }

    /// The motion components of the layout (u, and U if there is water).
    pub(super) fn motion(&self) -> Vec<usize> {
        let mut m: Vec<usize> = (0..D).collect();
        if let Some(w) = self.layout.w {
            m.extend(w..w + D);
        }
        m
    }

    /// The nodal values of the owned nodes ([`NodeBlock`]) over the whole grid (x fastest), summed
    /// over ranks: what a node space that replaces this one on another distribution of the nodes
    /// takes over ([`NodeSpace::block_of`]; collective).
    pub fn global_values(&self, block: &NodeBlock, coll: &Collective) -> Result<Vec<f64>, String> {
        let nodes = self.dm.info().nodes;
        let nv = node_values(D);
        let mut all = vec![0.0; nodes.iter().product::<usize>() * nv];
        let owned = GhostedRange { start: self.owned_start, count: self.owned_count, dof: 1 };
        for (o, v) in block.values.chunks_exact(nv).enumerate() {
            let g = flat_number(nodes, owned.indices(o)) * nv;
            all[g..g + nv].copy_from_slice(v);
        }
        coll.sum(&all)
    }

    /// A per-dof array of this rank's ghosted layout (its owned nodes' entries; a step's
    /// reactions) over the whole grid (x fastest, [`Layout::nd`] per node), summed over ranks: what
    /// a node space that replaces this one on another distribution takes over
    /// ([`NodeSpace::owned_dofs_of`]; collective).
    pub fn global_dofs(&self, local: &[f64], coll: &Collective) -> Result<Vec<f64>, String> {
        let nodes = self.dm.info().nodes;
        let nd = self.layout.nd;
        let mut all = vec![0.0; nodes.iter().product::<usize>() * nd];
        for &a in &self.owned_nodes {
            let (l, g) = (a as usize * nd, flat_number(nodes, self.ghost.indices(a as usize)) * nd);
            if let Some(v) = local.get(l..l + nd) {
                all[g..g + nd].copy_from_slice(v);
            }
        }
        coll.sum(&all)
    }

    /// This rank's ghosted per-dof array of the whole grid's `all` ([`NodeSpace::global_dofs`]):
    /// its owned nodes' entries, zero at the ghosts.
    pub fn owned_dofs_of(&self, all: &[f64]) -> Vec<f64> {
        let nodes = self.dm.info().nodes;
        let nd = self.layout.nd;
        let mut local = vec![0.0; self.ghost.len() * nd];
        for &a in &self.owned_nodes {
            let (l, g) = (a as usize * nd, flat_number(nodes, self.ghost.indices(a as usize)) * nd);
            if let Some(v) = all.get(g..g + nd) {
                local[l..l + nd].copy_from_slice(v);
            }
        }
        local
    }

    /// This rank's block of the nodal values `all` of the whole grid (x fastest; from
    /// [`NodeSpace::global_values`]), or zeros where `all` does not reach.
    pub fn block_of(&self, all: &[f64]) -> NodeBlock {
        let nodes = self.dm.info().nodes;
        let nv = node_values(D);
        let mut values = Vec::with_capacity(self.owned_nodes.len() * nv);
        for &a in &self.owned_nodes {
            let g = flat_number(nodes, self.ghost.indices(a as usize)) * nv;
            match all.get(g..g + nv) {
                Some(v) => values.extend(v),
                None => values.extend(std::iter::repeat_n(0.0, nv)),
            }
        }
        self.block(values)
    }

    /// The block of nodes this rank owns and, per node (x fastest), [`node_values`] values: the
    /// active (well-filled) flag (1 or 0) of `step`, its nodal increments Δd (ux, uy, [uz,] p,
    /// Ux, Uy[, Uz]; zeros beyond the dofs of the layout), and the nodal diagnostics K_mag and
    /// F^int_mag (`diagnostics`, per owned node; NaN, not computed, where it is empty).
    pub fn node_block<const M: usize>(
        &self,
        step: &Step<D, M>,
        solution: &Solution,
        diagnostics: &[[f64; 2]],
    ) -> NodeBlock {
        let nd = step.layout.nd;
        let nv = node_values(D);
        let names = Layout::UPU.in_dim(D).field_names();
        let own = step.layout.field_names();
        let mut values = Vec::with_capacity(self.owned_nodes.len() * nv);
        for (o, &a) in self.owned_nodes.iter().enumerate() {
            let l = a as usize;
            values.push(if step.dofs.well.get(l).copied().unwrap_or(false) { 1.0 } else { 0.0 });
            for name in names {
                let v = own[..nd].iter().position(|n| n == name).map_or(0.0, |c| solution.increments[l * nd + c]);
                values.push(v);
            }
            values.extend(diagnostics.get(o).copied().unwrap_or([f64::NAN; 2]));
        }
        self.block(values)
    }

    /// The norm of each field (`Layout::fields`) of `step`'s ghosted, rank-summed dof values `v`
    /// over its free owned dofs, in PETSc's scaling (pressure rows times s) (collective).
    pub(super) fn field_norms<const M: usize>(
        &self,
        step: &Step<D, M>,
        v: &[f64],
        coll: &Collective,
    ) -> Result<Vec<f64>, String> {
        let nd = step.layout.nd;
        let mut local = vec![0.0; nd];
        for &a in &self.owned_nodes {
            for (c, l) in local.iter_mut().enumerate() {
                let q = a as usize * nd + c;
                if !step.dofs.fixed[q] {
                    let m = v[q] * step.unit(q);
                    *l += m * m;
                }
            }
        }
        let squares = coll.sum(&local)?;
        Ok(step.layout.fields().iter().map(|(_, cs)| cs.iter().map(|&c| squares[c]).sum::<f64>().sqrt()).collect())
    }

    /// The owned block holding `values` ([`node_values`] per owned node, x fastest).
    pub(super) fn block(&self, values: Vec<f64>) -> NodeBlock {
        NodeBlock { start: lift3(self.owned_start, 0), count: lift3(self.owned_count, 1), values }
    }
}

/// The DMDA's refusal to split a grid too small for the ranks, said in the case's terms.
fn explain_split<const D: usize>(e: Error, grid: &Grid<D>, ranks: usize) -> Error {
    if !e.message.contains("smaller than stencil width") {
        return e;
    }
    Error {
        message: format!(
            "the grid of {} nodes cannot be split over {ranks} ranks: each rank needs at least \
             {STENCIL_WIDTH} node layers along every direction the grid is split in (the ghost width a \
             GIMP point's support needs); run on fewer ranks or refine the grid (PETSc: {})",
            grid.nodes().map(|n| n.to_string()).join(" × "),
            e.message
        ),
        ..e
    }
}

/// Values per node of a two-dimensional [`NodeBlock`]: whether it is well filled, the step's
/// increments of ux, uy, p, Ux, Uy (0 where the layout has none), K_mag and F^int_mag.
pub const NODE_VALUES: usize = node_values(2);

/// Values per node of a [`NodeBlock`] in `d` dimensions: the well-filled flag, the increments of
/// the full two-phase layout (ux, uy, [uz,] p, Ux, Uy[, Uz]), K_mag and F^int_mag.
pub const fn node_values(d: usize) -> usize {
    2 * d + 4
}

/// The nodes a rank owns: the box of grid nodes `start .. start + count` (i, j, k; k = 0 and one
/// layer in two dimensions) and [`node_values`] values per node, x fastest (see
/// [`super::Step::node_block`]).
#[derive(Debug, Clone, Default)]
pub struct NodeBlock {
    /// The first owned node (i, j, k).
    pub start: [usize; 3],
    /// The owned nodes along x, y and z.
    pub count: [usize; 3],
    /// The values, node by node.
    pub values: Vec<f64>,
}

/// Grid indices of dimension D as three, `fill` for the missing ones.
fn lift3<const D: usize>(n: [usize; D], fill: usize) -> [usize; 3] {
    std::array::from_fn(|d| if d < D { n[d] } else { fill })
}
