//! A thin, safe layer over `petsc-sys`.
//!
//! * [`Petsc`] is the one initialisation guard: MPI through rsmpi first, then PETSc; on drop PETSc is
//!   finalised, then MPI.
//! * Objects ([`Vector`], [`Mat`], [`Ksp`], [`Snes`], [`DmDa`], [`IndexSet`], [`Viewer`]) own their PETSc
//!   handle and destroy it on `Drop`; borrowed handles (`VecRef`, `MatRef`, `KspRef`, `PcRef`) do not.
//! * Every error code becomes a [`Result`] in [`error::check`], carrying PETSc's own message.
//! * SNES residual and Jacobian callbacks are Rust closures; panics inside them are caught and turned
//!   into errors.
//!
//! This crate and `petsc-sys` are the only places in porompm that contain `unsafe`.

/// Calls a `petsc-sys` function and checks its error code (crate-internal).
macro_rules! call {
    ($f:ident ( $($arg:expr),* $(,)? )) => {
        $crate::error::check(unsafe { ::petsc_sys::$f($($arg),*) })
    };
}

pub mod blocks;
pub mod callback;
pub mod comm;
pub mod dm;
pub mod error;
pub mod fields;
pub mod init;
pub mod is;
pub mod ksp;
pub mod log;
pub mod mat;
pub mod options;
pub mod schur;
pub mod snes;
pub mod vector;
pub mod viewer;

pub use blocks::{BlockBand, BlockFill, BlockOps, BlockPlaces, RowPlaces, MAX_BS};
pub use comm::Comm;
pub use dm::{DmDa, DmDaInfo, GhostedRange};
pub use error::{Error, Result};
pub use fields::{FieldMonitor, Fields};
pub use init::{Petsc, PetscBuild};
pub use is::IndexSet;
pub use ksp::{Ksp, KspRef, MumpsStatus, PcRef};
pub use log::{LogStage, StageGuard};
pub use mat::{Mat, MatRef};
pub use options::{OptionEntry, Options};
pub use schur::SchurUser;
pub use snes::{CallbackError, Snes, SolveOutcome};
pub use vector::{VecOps, VecRef, Vector};
pub use viewer::Viewer;

/// `PetscInt` (32-bit on Debian's build; checked by `petsc-sys`'s build script).
pub type Int = petsc_sys::PetscInt;
/// `PetscReal` = `PetscScalar` = `f64`.
pub type Real = petsc_sys::PetscReal;

/// `PETSC_DECIDE`: let PETSc choose a local size.
pub const DECIDE: Int = petsc_sys::PETSC_DECIDE as Int;
/// `PETSC_DETERMINE`: let PETSc compute a global size.
pub const DETERMINE: Int = petsc_sys::PETSC_DETERMINE as Int;

pub(crate) fn cstring(s: &str) -> Result<std::ffi::CString> {
    std::ffi::CString::new(s).map_err(|_| Error::new(format!("string contains a NUL byte: {s:?}")))
}

pub(crate) fn to_bool(b: bool) -> petsc_sys::PetscBool {
    if b {
        petsc_sys::PetscBool::PETSC_TRUE
    } else {
        petsc_sys::PetscBool::PETSC_FALSE
    }
}

pub(crate) fn from_bool(b: petsc_sys::PetscBool) -> bool {
    b == petsc_sys::PetscBool::PETSC_TRUE
}

/// Sets the name of any PETSc object (shown by viewers and in `-log_view`).
pub(crate) fn set_object_name(obj: petsc_sys::PetscObject, name: &str) -> Result<()> {
    let c = cstring(name)?;
    call!(PetscObjectSetName(obj, c.as_ptr()))
}

/// Sets the options prefix of any PETSc object.
pub(crate) fn set_object_prefix(obj: petsc_sys::PetscObject, prefix: &str) -> Result<()> {
    let c = cstring(prefix)?;
    call!(PetscObjectSetOptionsPrefix(obj, c.as_ptr()))
}
