//! PETSc vectors: [`Vector`] owns its handle, [`VecRef`] borrows one (inside callbacks).
//! All operations live in the [`VecOps`] trait, implemented by both.

use crate::{cstring, Comm, Error, Int, Real, Result};
use petsc_sys as sys;
use std::marker::PhantomData;
use std::ops::{Deref, DerefMut};

/// An owned PETSc `Vec`, destroyed on drop.
pub struct Vector {
    pub(crate) raw: sys::Vec,
}

/// A borrowed PETSc `Vec` (e.g. the state handed to a SNES callback).
pub struct VecRef<'a> {
    pub(crate) raw: sys::Vec,
    _life: PhantomData<&'a mut ()>,
}

impl VecRef<'_> {
    pub(crate) fn new(raw: sys::Vec) -> Self {
        VecRef { raw, _life: PhantomData }
    }
}

impl Drop for Vector {
    fn drop(&mut self) {
        // SAFETY: the handle is owned and destroyed exactly once.
        unsafe { sys::VecDestroy(&mut self.raw) };
    }
}

/// Read-only view of a vector's local entries; restores the array on drop.
pub struct ArrayRead<'a> {
    vec: sys::Vec,
    ptr: *const Real,
    len: usize,
    _life: PhantomData<&'a ()>,
}

impl Deref for ArrayRead<'_> {
    type Target = [Real];
    fn deref(&self) -> &[Real] {
        if self.len == 0 {
            return &[];
        }
        // SAFETY: PETSc guarantees `len` valid entries until VecRestoreArrayRead.
        unsafe { std::slice::from_raw_parts(self.ptr, self.len) }
    }
}

impl Drop for ArrayRead<'_> {
    fn drop(&mut self) {
        let mut p = self.ptr;
        // SAFETY: restores the array obtained by VecGetArrayRead on the same vector.
        unsafe { sys::VecRestoreArrayRead(self.vec, &mut p) };
    }
}

/// Mutable view of a vector's local entries; restores the array on drop.
pub struct ArrayMut<'a> {
    vec: sys::Vec,
    ptr: *mut Real,
    len: usize,
    _life: PhantomData<&'a mut ()>,
}

impl Deref for ArrayMut<'_> {
    type Target = [Real];
    fn deref(&self) -> &[Real] {
        if self.len == 0 {
            return &[];
        }
        // SAFETY: PETSc guarantees `len` valid entries until VecRestoreArray.
        unsafe { std::slice::from_raw_parts(self.ptr, self.len) }
    }
}

impl DerefMut for ArrayMut<'_> {
    fn deref_mut(&mut self) -> &mut [Real] {
        if self.len == 0 {
            return &mut [];
        }
        // SAFETY: as above; the guard holds the only mutable access.
        unsafe { std::slice::from_raw_parts_mut(self.ptr, self.len) }
    }
}

impl Drop for ArrayMut<'_> {
    fn drop(&mut self) {
        let mut p = self.ptr;
        // SAFETY: restores the array obtained by VecGetArray on the same vector.
        unsafe { sys::VecRestoreArray(self.vec, &mut p) };
    }
}

/// Operations on PETSc vectors, shared by owned and borrowed handles.
pub trait VecOps {
    /// The raw handle.
    fn raw(&self) -> sys::Vec;

    /// Global length.
    fn global_size(&self) -> Result<usize> {
        let mut n: Int = 0;
        call!(VecGetSize(self.raw(), &mut n))?;
        Ok(n as usize)
    }

    /// Length of this rank's part.
    fn local_size(&self) -> Result<usize> {
        let mut n: Int = 0;
        call!(VecGetLocalSize(self.raw(), &mut n))?;
        Ok(n as usize)
    }

    /// Global index range `[start, end)` owned by this rank.
    fn ownership_range(&self) -> Result<(usize, usize)> {
        let (mut lo, mut hi): (Int, Int) = (0, 0);
        call!(VecGetOwnershipRange(self.raw(), &mut lo, &mut hi))?;
        Ok((lo as usize, hi as usize))
    }

    /// Sets every entry to `v`.
    fn set_all(&mut self, v: Real) -> Result<()> {
        call!(VecSet(self.raw(), v))
    }

    /// Sets (or adds) entries by global index; call [`VecOps::assemble`] afterwards.
    fn set_values(&mut self, idx: &[Int], vals: &[Real], add: bool) -> Result<()> {
        if idx.len() != vals.len() {
            return Err(Error::new("VecSetValues: index and value arrays differ in length"));
        }
        let mode = if add { sys::InsertMode::ADD_VALUES } else { sys::InsertMode::INSERT_VALUES };
        call!(VecSetValues(self.raw(), idx.len() as Int, idx.as_ptr(), vals.as_ptr(), mode))
    }

    /// Completes `set_values` (communicates off-rank entries).
    fn assemble(&mut self) -> Result<()> {
        call!(VecAssemblyBegin(self.raw()))?;
        call!(VecAssemblyEnd(self.raw()))
    }

    /// 2-norm.
    fn norm2(&self) -> Result<Real> {
        let mut n = 0.0;
        call!(VecNorm(self.raw(), sys::NormType::NORM_2, &mut n))?;
        Ok(n)
    }

    /// Max-norm.
    fn norm_inf(&self) -> Result<Real> {
        let mut n = 0.0;
        call!(VecNorm(self.raw(), sys::NormType::NORM_INFINITY, &mut n))?;
        Ok(n)
    }

    /// Dot product with `other`.
    fn dot(&self, other: &dyn VecOps) -> Result<Real> {
        let mut d = 0.0;
        call!(VecDot(self.raw(), other.raw(), &mut d))?;
        Ok(d)
    }

    /// `self += alpha * x`.
    fn axpy(&mut self, alpha: Real, x: &dyn VecOps) -> Result<()> {
        call!(VecAXPY(self.raw(), alpha, x.raw()))
    }

    /// `self *= alpha`.
    fn scale(&mut self, alpha: Real) -> Result<()> {
        call!(VecScale(self.raw(), alpha))
    }

    /// Copies `self` into `dst` (same layout).
    fn copy_to(&self, dst: &mut dyn VecOps) -> Result<()> {
        call!(VecCopy(self.raw(), dst.raw()))
    }

    /// A new vector with the same layout (entries not copied).
    fn duplicate(&self) -> Result<Vector> {
        let mut raw = std::ptr::null_mut();
        call!(VecDuplicate(self.raw(), &mut raw))?;
        Ok(Vector { raw })
    }

    /// Read-only access to this rank's entries.
    fn read(&self) -> Result<ArrayRead<'_>> {
        let mut ptr: *const Real = std::ptr::null();
        call!(VecGetArrayRead(self.raw(), &mut ptr))?;
        let len = self.local_size()?;
        Ok(ArrayRead { vec: self.raw(), ptr, len, _life: PhantomData })
    }

    /// Mutable access to this rank's entries.
    fn write(&mut self) -> Result<ArrayMut<'_>> {
        let mut ptr: *mut Real = std::ptr::null_mut();
        call!(VecGetArray(self.raw(), &mut ptr))?;
        let len = self.local_size()?;
        Ok(ArrayMut { vec: self.raw(), ptr, len, _life: PhantomData })
    }

    /// Gives the vector a name (shown by viewers).
    fn set_name(&mut self, name: &str) -> Result<()> {
        crate::set_object_name(self.raw() as sys::PetscObject, name)
    }
}

impl VecOps for Vector {
    fn raw(&self) -> sys::Vec {
        self.raw
    }
}

impl VecOps for VecRef<'_> {
    fn raw(&self) -> sys::Vec {
        self.raw
    }
}

impl Vector {
    /// A distributed vector with the given local (or [`crate::DECIDE`]) and global sizes.
    pub fn new_mpi(comm: Comm, local: Int, global: Int) -> Result<Vector> {
        let mut raw = std::ptr::null_mut();
        call!(VecCreateMPI(comm.raw(), local, global, &mut raw))?;
        Ok(Vector { raw })
    }

    /// A sequential vector of length `n` on this rank.
    pub fn new_seq(n: usize) -> Result<Vector> {
        let mut raw = std::ptr::null_mut();
        call!(VecCreateSeq(crate::Comm::self_().raw(), n as Int, &mut raw))?;
        Ok(Vector { raw })
    }

    /// A sequential vector holding a copy of `data`.
    pub fn from_slice(data: &[Real]) -> Result<Vector> {
        let mut v = Vector::new_seq(data.len())?;
        v.write()?.copy_from_slice(data);
        Ok(v)
    }

    /// A borrowed view of this vector.
    pub fn as_ref(&mut self) -> VecRef<'_> {
        VecRef::new(self.raw)
    }

    /// Sets the options prefix (for `VecSetFromOptions`-style queries).
    pub fn set_prefix(&mut self, prefix: &str) -> Result<()> {
        let _ = cstring(prefix)?;
        crate::set_object_prefix(self.raw as sys::PetscObject, prefix)
    }
}
