//! Index sets.

use crate::{Comm, Int, Result};
use petsc_sys as sys;

/// An owned index set, destroyed on drop.
pub struct IndexSet {
    raw: sys::IS,
}

impl Drop for IndexSet {
    fn drop(&mut self) {
        // SAFETY: owned handle, destroyed once.
        unsafe { sys::ISDestroy(&mut self.raw) };
    }
}

impl IndexSet {
    /// An index set holding a copy of `idx` (global indices owned by this rank).
    pub fn new_general(comm: Comm, idx: &[Int]) -> Result<IndexSet> {
        let mut raw = std::ptr::null_mut();
        call!(ISCreateGeneral(
            comm.raw(),
            idx.len() as Int,
            idx.as_ptr(),
            sys::PetscCopyMode::PETSC_COPY_VALUES,
            &mut raw
        ))?;
        Ok(IndexSet { raw })
    }

    /// Number of indices on this rank.
    pub fn local_len(&self) -> Result<usize> {
        let mut n: Int = 0;
        call!(ISGetLocalSize(self.raw, &mut n))?;
        Ok(n as usize)
    }

    /// Number of indices over all ranks.
    pub fn global_len(&self) -> Result<usize> {
        let mut n: Int = 0;
        call!(ISGetSize(self.raw, &mut n))?;
        Ok(n as usize)
    }

    /// The indices on this rank.
    pub fn indices(&self) -> Result<Vec<Int>> {
        let n = self.local_len()?;
        let mut p: *const Int = std::ptr::null();
        call!(ISGetIndices(self.raw, &mut p))?;
        // SAFETY: ISGetIndices returned `n` indices, valid until ISRestoreIndices.
        let v = if n == 0 { Vec::new() } else { unsafe { std::slice::from_raw_parts(p, n) }.to_vec() };
        call!(ISRestoreIndices(self.raw, &mut p))?;
        Ok(v)
    }

    /// Declares that the indices come in blocks of `bs` consecutive entries of one node (the
    /// block size reaches the sub-matrix a field split extracts with it, and from there
    /// BoomerAMG's number of functions).
    pub fn set_block_size(&mut self, bs: usize) -> Result<()> {
        call!(ISSetBlockSize(self.raw, bs as Int))
    }

    /// Attaches the near-null space spanned by `vectors` (laid out like the rows this index set
    /// selects; orthonormal) under the name a field split looks for, so that the split's
    /// sub-matrix carries it to its preconditioner (GAMG's aggregates; BoomerAMG's interpolation
    /// with nodal coarsening).
    pub fn compose_near_null_space(&mut self, comm: Comm, vectors: &[crate::Vector]) -> Result<()> {
        let raw: Vec<sys::Vec> = vectors.iter().map(|v| v.raw).collect();
        let mut sp: sys::MatNullSpace = std::ptr::null_mut();
        call!(MatNullSpaceCreate(comm.raw(), sys::PetscBool::PETSC_FALSE, raw.len() as Int, raw.as_ptr(), &mut sp))?;
        let name = crate::cstring("nearnullspace")?;
        let composed = call!(PetscObjectCompose(self.raw as sys::PetscObject, name.as_ptr(), sp as sys::PetscObject));
        // The index set holds its own reference now.
        call!(MatNullSpaceDestroy(&mut sp))?;
        composed
    }

    pub(crate) fn raw(&self) -> sys::IS {
        self.raw
    }
}
