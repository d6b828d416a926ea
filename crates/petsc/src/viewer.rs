//! Viewers: where PETSc objects print themselves.

use crate::{cstring, Comm, Result};
use petsc_sys as sys;

/// A PETSc viewer. The standard-output viewer is shared and never destroyed; file viewers are
/// owned and destroyed on drop.
pub struct Viewer {
    raw: sys::PetscViewer,
    owned: bool,
}

impl Viewer {
    /// The ASCII viewer on standard output of `comm` (what `-snes_view` uses).
    pub fn stdout(comm: Comm) -> Viewer {
        // SAFETY: returns PETSc's persistent viewer for the communicator (not to be destroyed).
        Viewer { raw: unsafe { sys::PETSC_VIEWER_STDOUT_(comm.raw()) }, owned: false }
    }

    /// An ASCII viewer writing to `path`.
    pub fn ascii_file(comm: Comm, path: &std::path::Path) -> Result<Viewer> {
        let c = cstring(&path.to_string_lossy())?;
        let mut raw = std::ptr::null_mut();
        call!(PetscViewerASCIIOpen(comm.raw(), c.as_ptr(), &mut raw))?;
        Ok(Viewer { raw, owned: true })
    }

    pub(crate) fn raw(&self) -> sys::PetscViewer {
        self.raw
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        if self.owned {
            // SAFETY: owned file viewer, destroyed once.
            unsafe { sys::PetscViewerDestroy(&mut self.raw) };
        }
    }
}
