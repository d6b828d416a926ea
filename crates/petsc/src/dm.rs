//! Structured grids (DMDA): distribution of nodes over ranks, ghost nodes, vectors with named fields,
//! and matrices preallocated for the grid's stencil.

use crate::mat::Mat;
use crate::vector::{VecOps, Vector};
use crate::{cstring, Comm, Error, Int, Result};
use petsc_sys as sys;

/// Layout of a DMDA on this rank (two-dimensional unless `D` says otherwise): owned and ghosted
/// node ranges.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DmDaInfo<const D: usize = 2> {
    /// Global number of nodes in each direction.
    pub nodes: [usize; D],
    /// Degrees of freedom per node.
    pub dof: usize,
    /// Ghost (stencil) width in nodes.
    pub stencil_width: usize,
    /// First owned node in each direction.
    pub owned_start: [usize; D],
    /// Number of owned nodes in each direction.
    pub owned_count: [usize; D],
    /// The ghosted block of nodes held in local vectors.
    pub ghosted: GhostedRange<D>,
}

/// The ghosted node block of this rank: local vectors store nodes `start..start+count` (x fastest,
/// then y, then z) with `dof` entries each.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GhostedRange<const D: usize = 2> {
    /// First node of the block in each direction.
    pub start: [usize; D],
    /// Nodes in each direction.
    pub count: [usize; D],
    /// Degrees of freedom per node.
    pub dof: usize,
}

impl<const D: usize> GhostedRange<D> {
    /// Whether the global node with indices `n` is in the ghosted block.
    pub fn holds(&self, n: [usize; D]) -> bool {
        (0..D).all(|d| n[d] >= self.start[d] && n[d] < self.start[d] + self.count[d])
    }

    /// Local (ghosted) node number of the global node with indices `n`; `None` outside the block.
    pub fn local(&self, n: [usize; D]) -> Option<usize> {
        self.holds(n).then(|| (0..D).rev().fold(0, |acc, d| acc * self.count[d] + (n[d] - self.start[d])))
    }

    /// The global node indices of local node `l`.
    pub fn indices(&self, mut l: usize) -> [usize; D] {
        std::array::from_fn(|d| {
            let i = l % self.count[d];
            l /= self.count[d];
            self.start[d] + i
        })
    }

    /// Number of nodes in the block.
    pub fn len(&self) -> usize {
        self.count.iter().product()
    }

    /// Whether the block is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The two-dimensional forms with (i, j) indices.
impl GhostedRange<2> {
    /// Whether global node (i, j) is in the ghosted block.
    pub fn contains(&self, i: usize, j: usize) -> bool {
        self.holds([i, j])
    }

    /// Local (ghosted) node number of global node (i, j); `None` outside the block.
    pub fn node(&self, i: usize, j: usize) -> Option<usize> {
        self.local([i, j])
    }

    /// Global node (i, j) of local node `l`.
    pub fn ij(&self, l: usize) -> (usize, usize) {
        let [i, j] = self.indices(l);
        (i, j)
    }
}

/// An owned DMDA (two-dimensional unless `D` says otherwise), destroyed on drop.
pub struct DmDa<const D: usize = 2> {
    raw: sys::DM,
    info: DmDaInfo<D>,
    local_to_global: Vec<Int>,
}

impl<const D: usize> Drop for DmDa<D> {
    fn drop(&mut self) {
        // SAFETY: owned handle, destroyed once (objects referencing it hold their own reference).
        unsafe { sys::DMDestroy(&mut self.raw) };
    }
}

impl DmDa<2> {
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
        DmDa::new_partitioned(comm, nodes, stencil_width, field_names, ranges.map(|(x, y)| [x, y]))
    }

    /// Which ranks own the nodes: the number of owned node columns (x) and rows (y) of each rank
    /// along each direction.
    pub fn ownership_ranges(&self) -> Result<(Vec<usize>, Vec<usize>)> {
        let [x, y] = self.ownership()?;
        Ok((x, y))
    }
}

impl DmDa<3> {
    /// A 3D grid of `nodes[0] × nodes[1] × nodes[2]` nodes, as [`DmDa::new_2d_partitioned`]: the
    /// number of node layers of each process slab in x, y and z (their product of counts the
    /// communicator's size; rank a + b m + c m n owns slabs a, b, c), or `None` for PETSc's choice.
    pub fn new_3d(
        comm: Comm,
        nodes: [usize; 3],
        stencil_width: usize,
        field_names: &[&str],
        ranges: Option<[&[usize]; 3]>,
    ) -> Result<DmDa<3>> {
        DmDa::new_partitioned(comm, nodes, stencil_width, field_names, ranges)
    }
}

impl<const D: usize> DmDa<D> {
    /// A grid of any dimension (2 or 3), as [`DmDa::new_2d_partitioned`] and [`DmDa::new_3d`]: the
    /// number of node layers of each process slab along each direction, or `None` for PETSc's
    /// choice.
    pub fn new_partitioned(
        comm: Comm,
        nodes: [usize; D],
        stencil_width: usize,
        field_names: &[&str],
        ranges: Option<[&[usize]; D]>,
    ) -> Result<DmDa<D>> {
        if field_names.is_empty() {
            return Err(Error::new("a DMDA needs at least one field"));
        }
        let lists: Option<[Vec<Int>; D]> = ranges.map(|r| r.map(|l| l.iter().map(|&v| v as Int).collect()));
        let procs: [Int; D] = match &lists {
            Some(l) => std::array::from_fn(|d| l[d].len() as Int),
            None => [sys::PETSC_DECIDE as Int; D],
        };
        let list = |d: usize| lists.as_ref().map_or(std::ptr::null(), |l| l[d].as_ptr());
        let none = sys::DMBoundaryType::DM_BOUNDARY_NONE;
        let mut raw = std::ptr::null_mut();
        match D {
            2 => call!(DMDACreate2d(
                comm.raw(),
                none,
                none,
                sys::DMDAStencilType::DMDA_STENCIL_BOX,
                nodes[0] as Int,
                nodes[1] as Int,
                procs[0],
                procs[1],
                field_names.len() as Int,
                stencil_width as Int,
                list(0),
                list(1),
                &mut raw
            ))?,
            3 => call!(DMDACreate3d(
                comm.raw(),
                none,
                none,
                none,
                sys::DMDAStencilType::DMDA_STENCIL_BOX,
                nodes[0] as Int,
                nodes[1] as Int,
                nodes[2] as Int,
                procs[0],
                procs[1],
                procs[2],
                field_names.len() as Int,
                stencil_width as Int,
                list(0),
                list(1),
                list(2),
                &mut raw
            ))?,
            _ => return Err(Error::new("a DMDA has two or three dimensions")),
        }
        let mut dm = DmDa {
            raw,
            info: DmDaInfo {
                nodes,
                dof: field_names.len(),
                stencil_width,
                owned_start: [0; D],
                owned_count: [0; D],
                ghosted: GhostedRange { start: [0; D], count: [0; D], dof: field_names.len() },
            },
            local_to_global: Vec::new(),
        };
        call!(DMSetMatrixPreallocateOnly(dm.raw, sys::PetscBool::PETSC_TRUE))?;
        call!(DMSetUp(dm.raw))?;
        for (k, name) in field_names.iter().enumerate() {
            let c = cstring(name)?;
            call!(DMDASetFieldName(dm.raw, k as Int, c.as_ptr()))?;
        }
        let mut c: [Int; 6] = [0; 6];
        let [xs, ys, zs, xm, ym, zm] = &mut c;
        call!(DMDAGetCorners(dm.raw, xs, ys, zs, xm, ym, zm))?;
        dm.info.owned_start = std::array::from_fn(|d| c[d] as usize);
        dm.info.owned_count = std::array::from_fn(|d| c[3 + d] as usize);
        let [xs, ys, zs, xm, ym, zm] = &mut c;
        call!(DMDAGetGhostCorners(dm.raw, xs, ys, zs, xm, ym, zm))?;
        dm.info.ghosted.start = std::array::from_fn(|d| c[d] as usize);
        dm.info.ghosted.count = std::array::from_fn(|d| c[3 + d] as usize);
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

    /// Which ranks own the nodes: the number of owned node layers of each process slab along each
    /// direction.
    pub fn ownership(&self) -> Result<[Vec<usize>; D]> {
        let mut procs: [Int; 3] = [0; 3];
        let [m, n, p] = &mut procs;
        call!(DMDAGetInfo(
            self.raw,
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            m,
            n,
            p,
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut()
        ))?;
        let mut lists: [*const Int; 3] = [std::ptr::null(); 3];
        let [lx, ly, lz] = &mut lists;
        call!(DMDAGetOwnershipRanges(self.raw, lx, ly, lz))?;
        // SAFETY: PETSc returns arrays of length m (x), n (y) and p (z, three dimensions).
        Ok(std::array::from_fn(|d| {
            unsafe { std::slice::from_raw_parts(lists[d], procs[d] as usize) }.iter().map(|&v| v as usize).collect()
        }))
    }

    /// The layout on this rank.
    pub fn info(&self) -> &DmDaInfo<D> {
        &self.info
    }

    /// Global (PETSc-ordered) index of each local (ghosted) dof: node-major, dof fastest.
    pub fn local_to_global(&self) -> &[Int] {
        &self.local_to_global
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
    /// node-pair blocks of `dof` × `dof` entries: block row r (this rank's r-th owned node in
    /// PETSc's order) holds the blocks of global block columns `cols[starts[r]..starts[r + 1]]`,
    /// sorted. Every block row of the matrix that any rank adds to must be listed by its owner.
    /// The matrix is assembled with zeros; fill it with [`crate::BlockOps::fill_blocks`]. Collective.
    pub fn create_matrix_blocks(&self, starts: &[Int], cols: &[Int]) -> Result<Mat> {
        let m = self.matrix_shell()?;
        let bs = self.info.dof;
        let owned = starts.len().saturating_sub(1);
        if owned != self.info.owned_count.iter().product::<usize>() || starts.first() != Some(&0) {
            return Err(Error::new("block preallocation: one row start per owned node and a leading zero are needed"));
        }
        // Every scalar row of block row r has bs columns per block, those of the owned rows in
        // the diagonal part; the pattern is then set by inserting zeros one block row at a time,
        // so that no scalar column list of the whole matrix is ever held.
        let (lo, hi) = crate::VecOps::ownership_range(&self.create_global_vector()?)?;
        let (first, end) = (lo / bs, hi / bs);
        let (mut d_nnz, mut o_nnz) = (Vec::with_capacity(owned * bs), Vec::with_capacity(owned * bs));
        for r in 0..owned {
            let blocks = &cols[starts[r] as usize..starts[r + 1] as usize];
            if blocks.windows(2).any(|w| w[0] >= w[1]) {
                return Err(Error::new("block preallocation: the columns of a block row must be sorted and distinct"));
            }
            let d = blocks.iter().filter(|&&c| c as usize >= first && (c as usize) < end).count();
            d_nnz.extend(std::iter::repeat_n((d * bs) as Int, bs));
            o_nnz.extend(std::iter::repeat_n(((blocks.len() - d) * bs) as Int, bs));
        }
        call!(MatSeqAIJSetPreallocation(m.raw, 0, d_nnz.as_ptr()))?;
        call!(MatMPIAIJSetPreallocation(m.raw, 0, d_nnz.as_ptr(), 0, o_nnz.as_ptr()))?;
        drop((d_nnz, o_nnz));
        let (mut rows, mut columns, mut zeros) = (vec![0 as Int; bs], Vec::new(), Vec::new());
        for r in 0..owned {
            let blocks = &cols[starts[r] as usize..starts[r + 1] as usize];
            for (i, row) in rows.iter_mut().enumerate() {
                *row = ((first + r) * bs + i) as Int;
            }
            columns.clear();
            columns.extend(blocks.iter().flat_map(|&c| (0..bs as Int).map(move |j| c * bs as Int + j)));
            zeros.resize(bs * columns.len(), 0.0);
            let (nr, nc) = (bs as Int, columns.len() as Int);
            call!(MatSetValues(
                m.raw,
                nr,
                rows.as_ptr(),
                nc,
                columns.as_ptr(),
                zeros.as_ptr(),
                sys::InsertMode::INSERT_VALUES
            ))?;
        }
        call!(MatAssemblyBegin(m.raw, sys::MatAssemblyType::MAT_FINAL_ASSEMBLY))?;
        call!(MatAssemblyEnd(m.raw, sys::MatAssemblyType::MAT_FINAL_ASSEMBLY))?;
        call!(MatSetOption(m.raw, sys::MatOption::MAT_NEW_NONZERO_LOCATION_ERR, sys::PetscBool::PETSC_TRUE))?;
        Ok(m)
    }

    /// An AIJ matrix of the DMDA's rows, block size and local-to-global mapping, with the DM
    /// attached as DMCreateMatrix attaches it, not yet preallocated.
    fn matrix_shell(&self) -> Result<Mat> {
        // The matrix is made here rather than by DMCreateMatrix, which in PETSc 3.18 preallocates
        // the DMDA's whole box stencil in three dimensions even when told to skip it, only for
        // the exact preallocation to replace it (18 MB of a 3D run's 83 MB heap peak at 4096
        // points).
        let comm = Comm::of(self.raw as sys::PetscObject)?;
        let dof = self.info.dof;
        let local = (self.info.owned_count.iter().product::<usize>() * dof) as Int;
        let global = (self.info.nodes.iter().product::<usize>() * dof) as Int;
        let mut raw = std::ptr::null_mut();
        call!(MatCreate(comm.raw(), &mut raw))?;
        let m = Mat { raw };
        call!(MatSetSizes(m.raw, local, local, global, global))?;
        call!(MatSetBlockSize(m.raw, dof as Int))?;
        call!(MatSetType(m.raw, sys::MATAIJ.as_ptr() as *const _))?;
        let mut ltog = std::ptr::null_mut();
        call!(DMGetLocalToGlobalMapping(self.raw, &mut ltog))?;
        call!(MatSetLocalToGlobalMapping(m.raw, ltog, ltog))?;
        call!(MatSetDM(m.raw, self.raw))?;
        Ok(m)
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
        let m = self.matrix_shell()?;
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
