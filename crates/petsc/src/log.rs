//! Log stages: named phases that `-log_view` reports separately.

use crate::{cstring, Result};
use petsc_sys as sys;

/// A registered log stage.
#[derive(Debug, Clone, Copy)]
pub struct LogStage(sys::PetscLogStage);

/// Pops its stage when dropped.
pub struct StageGuard(());

impl LogStage {
    /// Registers a stage (the name appears in `-log_view`), or returns the stage already
    /// registered under that name (PETSc refuses a second registration).
    pub fn register(name: &str) -> Result<LogStage> {
        let c = cstring(name)?;
        let mut s: sys::PetscLogStage = -1;
        call!(PetscLogStageGetId(c.as_ptr(), &mut s))?;
        if s < 0 {
            call!(PetscLogStageRegister(c.as_ptr(), &mut s))?;
        }
        Ok(LogStage(s))
    }

    /// Enters the stage until the guard is dropped.
    pub fn push(&self) -> Result<StageGuard> {
        call!(PetscLogStagePush(self.0))?;
        Ok(StageGuard(()))
    }
}

impl Drop for StageGuard {
    fn drop(&mut self) {
        // SAFETY: pops the stage pushed when the guard was created.
        unsafe { sys::PetscLogStagePop() };
    }
}
