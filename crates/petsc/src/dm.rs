//! Structured grids (DMDA): distribution of nodes over ranks, ghost nodes, vectors with named fields,
//! and matrices preallocated for the grid's stencil.

use crate::mat::Mat;
use crate::vector::{VecOps, Vector};
use crate::{cstring, Comm, Error, Int, Result};
use petsc_sys as sys;

/// Layout of a 2D DMDA on this rank: owned and ghosted node ranges.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DmDaInfo {
    /// Global number of nodes in x and y.
    pub nodes: [usize; 2],
    /// Degrees of freedom per node.
    pub dof: usize,
    /// Ghost (stencil) width in nodes.
    pub stencil_width: usize,
    /// First owned node (i, j) and number of owned nodes in each direction.
    pub owned_start: [usize; 2],
    /// Number of owned nodes in each direction.
    pub owned_count: [usize; 2],
    /// The ghosted block of nodes held in local vectors.
    pub ghosted: GhostedRange,
}

/// The ghosted node block of this rank: local vectors store nodes `start..start+count` (row-major,
/// x fastest) with `dof` entries each.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GhostedRange {
    /// First node (i, j) of the block.
    pub start: [usize; 2],
    /// Nodes in x and y.
    pub count: [usize; 2],
    /// Degrees of freedom per node.
    pub dof: usize,
}

impl GhostedRange {
    /// Whether global node (i, j) is in the ghosted block.
    pub fn contains(&self, i: usize, j: usize) -> bool {
        i >= self.start[0]
            && j >= self.start[1]
            && i < self.start[0] + self.count[0]
            && j < self.start[1] + self.count[1]
    }

    /// Local (ghosted) node number of global node (i, j); `None` outside the block.
    pub fn node(&self, i: usize, j: usize) -> Option<usize> {
        self.contains(i, j).then(|| (j - self.start[1]) * self.count[0] + (i - self.start[0]))
    }

    /// Number of nodes in the block.
    pub fn len(&self) -> usize {
        self.count[0] * self.count[1]
    }

    /// Whether the block is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Global node (i, j) of local node `l`.
    pub fn ij(&self, l: usize) -> (usize, usize) {
        (self.start[0] + l % self.count[0], self.start[1] + l / self.count[0])
    }
}

/// An owned 2D DMDA, destroyed on drop.
pub struct DmDa {
    raw: sys::DM,
    info: DmDaInfo,
    local_to_global: Vec<Int>,
}

impl Drop for DmDa {
    fn drop(&mut self) {
        // SAFETY: owned handle, destroyed once (objects referencing it hold their own reference).
        unsafe { sys::DMDestroy(&mut self.raw) };
    }
}

impl DmDa {
    /// A 2D grid of `nodes[0] × nodes[1]` nodes with `field_names.len()` interlaced dofs per node,
    /// a box stencil of width `stencil_width`, and non-periodic boundaries. Matrices created from it
    /// are only preallocated (no zeros are stored), so their structure is what assembly puts in.
    pub fn new_2d(comm: Comm, nodes: [usize; 2], stencil_width: usize, field_names: &[&str]) -> Result<DmDa> {
        DmDa::new_2d_partitioned(comm, nodes, stencil_width, field_names, None)
    }

    /// As [`DmDa::new_2d`], with the nodes distributed as `ranges` says: the number of node columns
    /// of each of the m process columns and of node rows of each of the n process rows (m n must be
    /// the communicator's size; rank a + b m owns column slab a and row slab b). `None`: PETSc decides.
    pub fn new_2d_partitioned(
        comm: Comm,
        nodes: [usize; 2],
        stencil_width: usize,
        field_names: &[&str],
        ranges: Option<(&[usize], &[usize])>,
    ) -> Result<DmDa> {
        if field_names.is_empty() {
            return Err(Error::new("a DMDA needs at least one field"));
        }
        let lx: Option<Vec<Int>> = ranges.map(|r| r.0.iter().map(|&v| v as Int).collect());
        let ly: Option<Vec<Int>> = ranges.map(|r| r.1.iter().map(|&v| v as Int).collect());
        let (m, n) = match (&lx, &ly) {
            (Some(x), Some(y)) => (x.len() as Int, y.len() as Int),
            _ => (sys::PETSC_DECIDE as Int, sys::PETSC_DECIDE as Int),
        };
        let mut raw = std::ptr::null_mut();
        call!(DMDACreate2d(
            comm.raw(),
            sys::DMBoundaryType::DM_BOUNDARY_NONE,
            sys::DMBoundaryType::DM_BOUNDARY_NONE,
            sys::DMDAStencilType::DMDA_STENCIL_BOX,
            nodes[0] as Int,
            nodes[1] as Int,
            m,
            n,
            field_names.len() as Int,
            stencil_width as Int,
            lx.as_ref().map_or(std::ptr::null(), |v| v.as_ptr()),
            ly.as_ref().map_or(std::ptr::null(), |v| v.as_ptr()),
            &mut raw
        ))?;
        let mut dm = DmDa {
            raw,
            info: DmDaInfo {
                nodes,
                dof: field_names.len(),
                stencil_width,
                owned_start: [0; 2],
                owned_count: [0; 2],
                ghosted: GhostedRange { start: [0; 2], count: [0; 2], dof: field_names.len() },
            },
            local_to_global: Vec::new(),
        };
        call!(DMSetMatrixPreallocateOnly(dm.raw, sys::PetscBool::PETSC_TRUE))?;
        call!(DMSetUp(dm.raw))?;
        for (k, name) in field_names.iter().enumerate() {
            let c = cstring(name)?;
            call!(DMDASetFieldName(dm.raw, k as Int, c.as_ptr()))?;
        }
        let (mut xs, mut ys, mut zs, mut xm, mut ym, mut zm): (Int, Int, Int, Int, Int, Int) = (0, 0, 0, 0, 0, 0);
        call!(DMDAGetCorners(dm.raw, &mut xs, &mut ys, &mut zs, &mut xm, &mut ym, &mut zm))?;
        dm.info.owned_start = [xs as usize, ys as usize];
        dm.info.owned_count = [xm as usize, ym as usize];
        call!(DMDAGetGhostCorners(dm.raw, &mut xs, &mut ys, &mut zs, &mut xm, &mut ym, &mut zm))?;
        dm.info.ghosted.start = [xs as usize, ys as usize];
        dm.info.ghosted.count = [xm as usize, ym as usize];
        let mut ltog = std::ptr::null_mut();
        call!(DMGetLocalToGlobalMapping(dm.raw, &mut ltog))?;
        let mut n: Int = 0;
        call!(ISLocalToGlobalMappingGetSize(ltog, &mut n))?;
        let mut idx: *const Int = std::ptr::null();
        call!(ISLocalToGlobalMappingGetIndices(ltog, &mut idx))?;
        // SAFETY: the mapping holds `n` indices, valid until RestoreIndices.
        dm.local_to_global = unsafe { std::slice::from_raw_parts(idx, n as usize) }.to_vec();
        call!(ISLocalToGlobalMappingRestoreIndices(ltog, &mut idx))?;
        Ok(dm)
    }

    /// The layout on this rank.
    pub fn info(&self) -> &DmDaInfo {
        &self.info
    }

    /// Global (PETSc-ordered) index of each local (ghosted) dof: node-major, dof fastest.
    pub fn local_to_global(&self) -> &[Int] {
        &self.local_to_global
    }

    /// Which ranks own the nodes: the number of owned node columns (x) and rows (y) of each rank
    /// along each direction.
    pub fn ownership_ranges(&self) -> Result<(Vec<usize>, Vec<usize>)> {
        let (mut m, mut n, mut p): (Int, Int, Int) = (0, 0, 0);
        call!(DMDAGetInfo(
            self.raw,
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            &mut m,
            &mut n,
            &mut p,
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut()
        ))?;
        let (mut lx, mut ly, mut lz): (*const Int, *const Int, *const Int) =
            (std::ptr::null(), std::ptr::null(), std::ptr::null());
        call!(DMDAGetOwnershipRanges(self.raw, &mut lx, &mut ly, &mut lz))?;
        // SAFETY: PETSc returns arrays of length m (x) and n (y).
        let (x, y) = unsafe {
            (
                std::slice::from_raw_parts(lx, m as usize).iter().map(|&v| v as usize).collect(),
                std::slice::from_raw_parts(ly, n as usize).iter().map(|&v| v as usize).collect(),
            )
        };
        Ok((x, y))
    }

    /// A new global vector (owned nodes only, PETSc ordering).
    pub fn create_global_vector(&self) -> Result<Vector> {
        let mut raw = std::ptr::null_mut();
        call!(DMCreateGlobalVector(self.raw, &mut raw))?;
        Ok(Vector { raw })
    }

    /// A new local vector (ghosted block, natural node order within the block).
    pub fn create_local_vector(&self) -> Result<Vector> {
        let mut raw = std::ptr::null_mut();
        call!(DMCreateLocalVector(self.raw, &mut raw))?;
        Ok(Vector { raw })
    }

    /// Copies owned values of `global` and fills ghosts from their owners into `local`.
    pub fn global_to_local(&self, global: &dyn VecOps, local: &mut Vector) -> Result<()> {
        call!(DMGlobalToLocalBegin(self.raw, global.raw(), sys::InsertMode::INSERT_VALUES, local.raw()))?;
        call!(DMGlobalToLocalEnd(self.raw, global.raw(), sys::InsertMode::INSERT_VALUES, local.raw()))
    }

    /// Adds every local entry (ghosts included) into `global`; entries on ghosts go to their owners.
    pub fn local_to_global_add(&self, local: &Vector, global: &mut dyn VecOps) -> Result<()> {
        call!(DMLocalToGlobalBegin(self.raw, local.raw(), sys::InsertMode::ADD_VALUES, global.raw()))?;
        call!(DMLocalToGlobalEnd(self.raw, local.raw(), sys::InsertMode::ADD_VALUES, global.raw()))
    }

    /// Creates an AIJ matrix of the DMDA's layout whose nonzero pattern is exactly the given
    /// coordinate list (`rows[k]`, `cols[k]` global indices; repeated pairs are summed by
    /// [`crate::mat::MatOps::set_values_coo`], negative ones ignored): the DMDA's own box
    /// preallocation is skipped, so any reach of the particles' stencils fits. The values follow
    /// the list's order in every later `set_values_coo`.
    pub fn create_matrix_coo(&self, rows: &[Int], cols: &[Int]) -> Result<Mat> {
        if rows.len() != cols.len() {
            return Err(Error::new("COO preallocation: row and column lists differ in length"));
        }
        let aij = cstring("aij")?;
        call!(DMSetMatType(self.raw, aij.as_ptr()))?;
        call!(DMSetMatrixPreallocateSkip(self.raw, sys::PetscBool::PETSC_TRUE))?;
        let mut raw = std::ptr::null_mut();
        call!(DMCreateMatrix(self.raw, &mut raw))?;
        let m = Mat { raw };
        // PETSc may reorder the index arrays in place: hand it copies.
        let (mut i, mut j) = (rows.to_vec(), cols.to_vec());
        call!(MatSetPreallocationCOO(m.raw, i.len() as sys::PetscCount, i.as_mut_ptr(), j.as_mut_ptr()))?;
        Ok(m)
    }

    /// A new AIJ matrix preallocated for the grid's box stencil, with the local-to-global mapping
    /// set (so `set_values_local` works). Nothing is stored until values are set; entries outside
    /// the stencil are an error.
    pub fn create_matrix(&self) -> Result<Mat> {
        let mut raw = std::ptr::null_mut();
        call!(DMCreateMatrix(self.raw, &mut raw))?;
        let m = Mat { raw };
        // PETSc 3.18's DMDA matrix creation leaves MAT_SORTED_FULL on when it only preallocates;
        // with it, every MatSetValues call replaces the whole row instead of adding to it.
        call!(MatSetOption(m.raw, sys::MatOption::MAT_SORTED_FULL, sys::PetscBool::PETSC_FALSE))?;
        Ok(m)
    }

    pub(crate) fn raw(&self) -> sys::DM {
        self.raw
    }
}
