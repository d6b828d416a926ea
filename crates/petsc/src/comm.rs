//! MPI communicators as PETSc sees them, and the few collective reductions the application needs.

use crate::{Error, Result};
use mpi::ffi;
use petsc_sys as sys;

/// An MPI communicator handle (not owned: the world communicator lives as long as [`crate::Petsc`]).
#[derive(Clone, Copy, Debug)]
pub struct Comm(pub(crate) sys::MPI_Comm);

fn mpi_check(rc: i32, what: &str) -> Result<()> {
    if rc == 0 {
        Ok(())
    } else {
        Err(Error::new(format!("MPI error {rc} in {what}")))
    }
}

impl Comm {
    /// `PETSC_COMM_WORLD` (MPI_COMM_WORLD unless PETSc was told otherwise).
    pub fn world() -> Comm {
        // SAFETY: PETSC_COMM_WORLD is a plain global handle set during initialisation; reading it is
        // a copy of a pointer-sized value.
        Comm(unsafe { sys::PETSC_COMM_WORLD })
    }

    /// `PETSC_COMM_SELF` (MPI_COMM_SELF).
    pub fn self_() -> Comm {
        // SAFETY: RSMPI_COMM_SELF is an immutable handle exported by rsmpi's C shim.
        Comm(unsafe { ffi::RSMPI_COMM_SELF })
    }

    /// The communicator of a raw MPI handle (e.g. rsmpi's `as_raw()` of the world communicator).
    pub fn from_raw(raw: sys::MPI_Comm) -> Comm {
        Comm(raw)
    }

    /// The communicator a PETSc object (a Mat, a DM, ...) lives on.
    pub(crate) fn of(object: sys::PetscObject) -> Result<Comm> {
        let mut comm = Comm::self_().raw();
        call!(PetscObjectGetComm(object, &mut comm))?;
        Ok(Comm(comm))
    }

    /// The raw handle, for `petsc-sys` calls.
    pub fn raw(&self) -> sys::MPI_Comm {
        self.0
    }

    /// This process's rank.
    pub fn rank(&self) -> usize {
        let mut r = 0;
        // SAFETY: valid communicator, out-pointer to a local.
        let rc = unsafe { ffi::MPI_Comm_rank(self.0, &mut r) };
        if rc != 0 {
            return 0;
        }
        r as usize
    }

    /// Number of ranks.
    pub fn size(&self) -> usize {
        let mut s = 1;
        // SAFETY: valid communicator, out-pointer to a local.
        let rc = unsafe { ffi::MPI_Comm_size(self.0, &mut s) };
        if rc != 0 {
            return 1;
        }
        s as usize
    }

    fn allreduce_f64(&self, data: &mut [f64], op: ffi::MPI_Op) -> Result<()> {
        if data.is_empty() {
            return Ok(());
        }
        let send = data.to_vec();
        // SAFETY: buffers of equal length `data.len()` doubles, valid datatype and op handles.
        let rc = unsafe {
            ffi::MPI_Allreduce(
                send.as_ptr() as *const _,
                data.as_mut_ptr() as *mut _,
                data.len() as i32,
                ffi::RSMPI_DOUBLE,
                op,
                self.0,
            )
        };
        mpi_check(rc, "MPI_Allreduce")
    }

    /// Element-wise sum over all ranks, in place.
    pub fn sum_f64(&self, data: &mut [f64]) -> Result<()> {
        // SAFETY: reading an immutable MPI_Op handle exported by rsmpi.
        self.allreduce_f64(data, unsafe { ffi::RSMPI_SUM })
    }

    /// Element-wise maximum over all ranks, in place.
    pub fn max_f64(&self, data: &mut [f64]) -> Result<()> {
        // SAFETY: reading an immutable MPI_Op handle exported by rsmpi.
        self.allreduce_f64(data, unsafe { ffi::RSMPI_MAX })
    }

    /// Element-wise minimum over all ranks, in place.
    pub fn min_f64(&self, data: &mut [f64]) -> Result<()> {
        // SAFETY: reading an immutable MPI_Op handle exported by rsmpi.
        self.allreduce_f64(data, unsafe { ffi::RSMPI_MIN })
    }

    /// Sum of a count over all ranks (exact for counts below 2^53).
    pub fn sum_usize(&self, v: usize) -> Result<usize> {
        let mut d = [v as f64];
        self.sum_f64(&mut d)?;
        Ok(d[0].round() as usize)
    }

    /// Gathers every rank's vector of doubles on every rank (concatenated in rank order).
    pub fn all_gather_f64(&self, local: &[f64]) -> Result<Vec<f64>> {
        let size = self.size();
        let mut counts = vec![0i32; size];
        let n = local.len() as i32;
        // SAFETY: one int sent, `size` ints received.
        let rc = unsafe {
            ffi::MPI_Allgather(
                &n as *const i32 as *const _,
                1,
                ffi::RSMPI_INT32_T,
                counts.as_mut_ptr() as *mut _,
                1,
                ffi::RSMPI_INT32_T,
                self.0,
            )
        };
        mpi_check(rc, "MPI_Allgather")?;
        let mut displs = vec![0i32; size];
        for i in 1..size {
            displs[i] = displs[i - 1] + counts[i - 1];
        }
        let total: i32 = counts.iter().sum();
        let mut out = vec![0.0; total as usize];
        // SAFETY: receive buffer holds `total` doubles laid out by `displs`/`counts`.
        let rc = unsafe {
            ffi::MPI_Allgatherv(
                local.as_ptr() as *const _,
                n,
                ffi::RSMPI_DOUBLE,
                out.as_mut_ptr() as *mut _,
                counts.as_ptr(),
                displs.as_ptr(),
                ffi::RSMPI_DOUBLE,
                self.0,
            )
        };
        mpi_check(rc, "MPI_Allgatherv")?;
        Ok(out)
    }

    /// Blocks until every rank has arrived.
    pub fn barrier(&self) -> Result<()> {
        // SAFETY: valid communicator.
        mpi_check(unsafe { ffi::MPI_Barrier(self.0) }, "MPI_Barrier")
    }
}
