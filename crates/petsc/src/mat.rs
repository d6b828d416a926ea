//! PETSc matrices: [`Mat`] owns its handle, [`MatRef`] borrows one (inside Jacobian callbacks).

use crate::vector::VecOps;
use crate::{Comm, Error, Int, Real, Result};
use petsc_sys as sys;
use std::marker::PhantomData;

/// An owned PETSc `Mat`, destroyed on drop.
pub struct Mat {
    pub(crate) raw: sys::Mat,
}

/// A borrowed PETSc `Mat`.
pub struct MatRef<'a> {
    pub(crate) raw: sys::Mat,
    _life: PhantomData<&'a mut ()>,
}

impl MatRef<'_> {
    pub(crate) fn new(raw: sys::Mat) -> Self {
        MatRef { raw, _life: PhantomData }
    }
}

impl Drop for Mat {
    fn drop(&mut self) {
        // SAFETY: owned handle, destroyed once.
        unsafe { sys::MatDestroy(&mut self.raw) };
    }
}

/// Sparsity statistics of this rank's part of an assembled matrix.
#[derive(Debug, Clone, Copy, Default)]
pub struct MatStats {
    /// Stored nonzeros in use.
    pub nonzeros: f64,
    /// The bytes of its compressed-row storage: a value and a column index per allocated nonzero
    /// (per stored one where PETSc reports none allocated, as for a distributed matrix built from
    /// coordinate lists) and a row offset per row (what PETSc reports as the matrix's memory is
    /// not tracked in optimised builds; this is what AIJ storage takes).
    pub memory_bytes: f64,
}

/// Operations on matrices, shared by owned and borrowed handles.
pub trait MatOps {
    /// The raw handle.
    fn raw(&self) -> sys::Mat;

    /// Global (rows, cols).
    fn size(&self) -> Result<(usize, usize)> {
        let (mut m, mut n): (Int, Int) = (0, 0);
        call!(MatGetSize(self.raw(), &mut m, &mut n))?;
        Ok((m as usize, n as usize))
    }

    /// Rows `[start, end)` owned by this rank.
    fn ownership_range(&self) -> Result<(usize, usize)> {
        let (mut lo, mut hi): (Int, Int) = (0, 0);
        call!(MatGetOwnershipRange(self.raw(), &mut lo, &mut hi))?;
        Ok((lo as usize, hi as usize))
    }

    /// Inserts or adds a dense row-major block `vals` (rows.len() × cols.len()) by global indices.
    /// Negative indices are ignored by PETSc (used for constrained dofs).
    fn set_values(&mut self, rows: &[Int], cols: &[Int], vals: &[Real], add: bool) -> Result<()> {
        if rows.len() * cols.len() != vals.len() {
            return Err(Error::new("MatSetValues: block size does not match index arrays"));
        }
        let mode = if add { sys::InsertMode::ADD_VALUES } else { sys::InsertMode::INSERT_VALUES };
        call!(MatSetValues(
            self.raw(),
            rows.len() as Int,
            rows.as_ptr(),
            cols.len() as Int,
            cols.as_ptr(),
            vals.as_ptr(),
            mode
        ))
    }

    /// As [`MatOps::set_values`], with indices in the local (ghosted) numbering of the matrix's
    /// local-to-global mapping (set by `DMCreateMatrix`).
    fn set_values_local(&mut self, rows: &[Int], cols: &[Int], vals: &[Real], add: bool) -> Result<()> {
        if rows.len() * cols.len() != vals.len() {
            return Err(Error::new("MatSetValuesLocal: block size does not match index arrays"));
        }
        let mode = if add { sys::InsertMode::ADD_VALUES } else { sys::InsertMode::INSERT_VALUES };
        call!(MatSetValuesLocal(
            self.raw(),
            rows.len() as Int,
            rows.as_ptr(),
            cols.len() as Int,
            cols.as_ptr(),
            vals.as_ptr(),
            mode
        ))
    }

    /// Sets all values of a matrix created with a coordinate list (see
    /// [`crate::DmDa::create_matrix_coo`]), in the list's order; entries listed more than once
    /// (also on other ranks) are summed, and the matrix is assembled. `add` adds to the current
    /// values instead of replacing them.
    fn set_values_coo(&mut self, vals: &[Real], add: bool) -> Result<()> {
        let mode = if add { sys::InsertMode::ADD_VALUES } else { sys::InsertMode::INSERT_VALUES };
        call!(MatSetValuesCOO(self.raw(), vals.as_ptr(), mode))
    }

    /// Final assembly (communicates off-rank entries, compresses storage).
    fn assemble(&mut self) -> Result<()> {
        call!(MatAssemblyBegin(self.raw(), sys::MatAssemblyType::MAT_FINAL_ASSEMBLY))?;
        call!(MatAssemblyEnd(self.raw(), sys::MatAssemblyType::MAT_FINAL_ASSEMBLY))
    }

    /// Zeroes all stored entries (keeps the structure).
    fn zero_entries(&mut self) -> Result<()> {
        call!(MatZeroEntries(self.raw()))
    }

    /// `y = A x`.
    fn mult(&self, x: &dyn VecOps, y: &mut dyn VecOps) -> Result<()> {
        call!(MatMult(self.raw(), x.raw(), y.raw()))
    }

    /// Sets a boolean matrix option.
    fn set_option(&mut self, op: sys::MatOption, flag: bool) -> Result<()> {
        call!(MatSetOption(self.raw(), op, crate::to_bool(flag)))
    }

    /// Frobenius norm.
    fn norm_frobenius(&self) -> Result<Real> {
        let mut n = 0.0;
        call!(MatNorm(self.raw(), sys::NormType::NORM_FROBENIUS, &mut n))?;
        Ok(n)
    }

    /// How many holders the matrix has (PETSc's reference count): 1 when only this handle holds
    /// it, more while a solver or a preconditioner keeps it too.
    fn holders(&self) -> Result<usize> {
        let mut count: Int = 0;
        call!(PetscObjectGetReference(self.raw() as sys::PetscObject, &mut count))?;
        Ok(count.max(0) as usize)
    }

    /// Whether the matrix equals its transpose within `tol`.
    fn is_symmetric(&self, tol: Real) -> Result<bool> {
        let mut flg = sys::PetscBool::PETSC_FALSE;
        call!(MatIsSymmetric(self.raw(), tol, &mut flg))?;
        Ok(crate::from_bool(flg))
    }

    /// The values of this rank's rows as a dense row-major block `(end-start) × ncols`
    /// (for tests and diagnostics on small matrices).
    fn local_rows_dense(&self) -> Result<(usize, Vec<Real>)> {
        let (_, ncols) = self.size()?;
        let (lo, hi) = self.ownership_range()?;
        let mut out = vec![0.0; (hi - lo) * ncols];
        for r in lo..hi {
            let mut nz: Int = 0;
            let mut cols: *const Int = std::ptr::null();
            let mut vals: *const Real = std::ptr::null();
            call!(MatGetRow(self.raw(), r as Int, &mut nz, &mut cols, &mut vals))?;
            for k in 0..nz as usize {
                // SAFETY: MatGetRow returned `nz` column indices and values, valid until MatRestoreRow.
                let (c, v) = unsafe { (*cols.add(k), *vals.add(k)) };
                out[(r - lo) * ncols + c as usize] = v;
            }
            call!(MatRestoreRow(self.raw(), r as Int, &mut nz, &mut cols, &mut vals))?;
        }
        Ok((lo, out))
    }

    /// This rank's nonzeros and memory (not collective).
    fn stats(&self) -> Result<MatStats> {
        let mut info = sys::MatInfo::default();
        call!(MatGetInfo(self.raw(), sys::MatInfoType::MAT_LOCAL, &mut info))?;
        let (mut rows, mut cols): (Int, Int) = (0, 0);
        call!(MatGetLocalSize(self.raw(), &mut rows, &mut cols))?;
        let rows = rows as usize;
        let entry = (std::mem::size_of::<sys::PetscScalar>() + std::mem::size_of::<Int>()) as f64;
        let memory_bytes =
            info.nz_allocated.max(info.nz_used) * entry + ((rows + 1) * std::mem::size_of::<Int>()) as f64;
        Ok(MatStats { nonzeros: info.nz_used, memory_bytes })
    }

    /// Attaches a near-null space (e.g. the rigid-body modes of an elastic body), which algebraic
    /// multigrid (GAMG) uses to build its coarse spaces (`MatSetNearNullSpace`). The vectors must
    /// be orthonormal; the matrix keeps its own reference to the space.
    fn set_near_null_space(&mut self, comm: crate::Comm, vectors: &[crate::Vector]) -> Result<()> {
        let raw: Vec<sys::Vec> = vectors.iter().map(|v| v.raw).collect();
        let mut sp: sys::MatNullSpace = std::ptr::null_mut();
        call!(MatNullSpaceCreate(comm.raw(), sys::PetscBool::PETSC_FALSE, raw.len() as Int, raw.as_ptr(), &mut sp))?;
        let set = call!(MatSetNearNullSpace(self.raw(), sp));
        call!(MatNullSpaceDestroy(&mut sp))?;
        set
    }

    /// Gives the matrix a name.
    fn set_name(&mut self, name: &str) -> Result<()> {
        crate::set_object_name(self.raw() as sys::PetscObject, name)
    }
}

impl MatOps for Mat {
    fn raw(&self) -> sys::Mat {
        self.raw
    }
}

impl MatOps for MatRef<'_> {
    fn raw(&self) -> sys::Mat {
        self.raw
    }
}

impl Mat {
    /// A distributed AIJ matrix with `rows` local rows (of `global_rows`) and per-row preallocation
    /// for the diagonal (`d_nnz`) and off-diagonal (`o_nnz`) blocks of this rank.
    pub fn new_aij(comm: Comm, local_rows: usize, global_rows: usize, d_nnz: &[Int], o_nnz: &[Int]) -> Result<Mat> {
        if d_nnz.len() != local_rows || o_nnz.len() != local_rows {
            return Err(Error::new("Mat::new_aij: preallocation arrays must have one entry per local row"));
        }
        let mut raw = std::ptr::null_mut();
        call!(MatCreate(comm.raw(), &mut raw))?;
        let m = Mat { raw };
        call!(MatSetSizes(m.raw, local_rows as Int, local_rows as Int, global_rows as Int, global_rows as Int))?;
        call!(MatSetType(m.raw, sys::MATAIJ.as_ptr() as *const _))?;
        call!(MatSeqAIJSetPreallocation(m.raw, 0, d_nnz.as_ptr()))?;
        call!(MatMPIAIJSetPreallocation(m.raw, 0, d_nnz.as_ptr(), 0, o_nnz.as_ptr()))?;
        Ok(m)
    }

    /// A borrowed view of this matrix.
    pub fn as_ref(&mut self) -> MatRef<'_> {
        MatRef::new(self.raw)
    }

    /// A new vector compatible with the matrix's columns (`right`) or rows.
    pub fn create_vecs(&self) -> Result<(crate::Vector, crate::Vector)> {
        let (mut r, mut l) = (std::ptr::null_mut(), std::ptr::null_mut());
        call!(MatCreateVecs(self.raw, &mut r, &mut l))?;
        Ok((crate::Vector { raw: r }, crate::Vector { raw: l }))
    }
}
