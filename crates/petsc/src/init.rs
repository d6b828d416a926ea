//! The initialisation guard: MPI (through rsmpi) first, then PETSc; finalised in reverse on drop.

use crate::{cstring, error, Comm, Error, Result};
use petsc_sys as sys;
use std::ffi::{c_char, CString};
use std::path::Path;

/// What this PETSc is, for `--version` and run summaries.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PetscBuild {
    /// `major.minor.subminor` of the linked library (from `PetscGetVersionNumber`).
    pub version: String,
    /// External packages compiled into PETSc (`mumps`, `hypre`, `superlu_dist`, `hdf5`).
    pub packages: Vec<&'static str>,
}

impl PetscBuild {
    /// Version and packages, known without initialising PETSc.
    pub fn get() -> PetscBuild {
        let (mut major, mut minor, mut sub, mut patch) = (0, 0, 0, 0);
        // SAFETY: PetscGetVersionNumber only writes four integers; it needs no initialisation.
        let rc = unsafe { sys::PetscGetVersionNumber(&mut major, &mut minor, &mut sub, &mut patch) };
        let version = if rc == 0 { format!("{major}.{minor}.{sub}") } else { "unknown".into() };
        let packages = sys::EXTERNAL_PACKAGES.iter().filter(|(_, have)| *have).map(|(n, _)| *n).collect();
        PetscBuild { version, packages }
    }
}

/// The PETSc (and MPI) session of this process. Exactly one may exist; only `main` creates it.
///
/// Dropping it finalises PETSc and then MPI. PETSc objects must be dropped before it.
pub struct Petsc {
    // Field order matters only for documentation: `Drop::drop` finalises PETSc before the fields
    // (and hence the MPI universe) are dropped.
    _argv: Vec<CString>,
    _argv_ptrs: Box<[*mut c_char]>,
    universe: Option<mpi::environment::Universe>,
}

impl Petsc {
    /// Initialises MPI (through rsmpi) and then PETSc, for programs that leave MPI to this guard
    /// (the PETSc smoke tests, the benchmarks). See [`Petsc::initialize_on`] for the arguments.
    pub fn initialize(petsc_args: &[String], options_file: Option<&Path>, help: &str) -> Result<Petsc> {
        let universe = mpi::initialize().ok_or_else(|| {
            Error::new("MPI is already initialised in this process; PETSc can be initialised only once")
        })?;
        let mut guard = Self::start(None, petsc_args, options_file, help)?;
        guard.universe = Some(universe);
        Ok(guard)
    }

    /// Initialises PETSc on the communicator `world` of an MPI that the caller initialised (and
    /// will finalise after dropping this guard): PETSC_COMM_WORLD becomes `world`.
    ///
    /// `petsc_args` are PETSc command-line options exactly as the user gave them (e.g.
    /// `["-ksp_type", "gmres"]`); they reach PETSc's options database unchanged. `options_file`, if
    /// given, is read first, so command-line options override it. The file must exist (checked here,
    /// so that a missing file is a clear error rather than a PETSc traceback).
    pub fn initialize_on(world: Comm, petsc_args: &[String], options_file: Option<&Path>, help: &str) -> Result<Petsc> {
        Self::start(Some(world), petsc_args, options_file, help)
    }

    fn start(world: Option<Comm>, petsc_args: &[String], options_file: Option<&Path>, help: &str) -> Result<Petsc> {
        if let Some(f) = options_file {
            if !f.is_file() {
                return Err(Error::new(format!("PETSc options file {} does not exist", f.display())));
            }
        }
        let mut argv: Vec<CString> = vec![cstring("porompm")?];
        for a in petsc_args {
            argv.push(cstring(a)?);
        }
        let mut argv_ptrs: Box<[*mut c_char]> =
            argv.iter().map(|c| c.as_ptr() as *mut c_char).chain(std::iter::once(std::ptr::null_mut())).collect();
        let mut argc = argv.len() as i32;
        let mut argv_p = argv_ptrs.as_mut_ptr();
        let file = options_file.map(|p| cstring(&p.to_string_lossy())).transpose()?;
        let help = cstring(help)?;
        if let Some(w) = world {
            // SAFETY: PETSC_COMM_WORLD is a plain global that PETSc reads in PetscInitialize; it
            // may be set before, and nothing else touches it concurrently.
            unsafe { sys::PETSC_COMM_WORLD = w.raw() };
        }
        // SAFETY: argc/argv describe NUL-terminated strings owned by `argv`, which lives as long as
        // the returned guard (PETSc keeps the pointers). The file and help strings outlive the call.
        let rc = unsafe {
            sys::PetscInitialize(
                &mut argc,
                &mut argv_p,
                file.as_ref().map_or(std::ptr::null(), |f| f.as_ptr()),
                help.as_ptr(),
            )
        };
        if rc != 0 {
            return Err(Error { code: rc, message: format!("PetscInitialize failed (PETSc error {rc})") });
        }
        let guard = Petsc { _argv: argv, _argv_ptrs: argv_ptrs, universe: None };
        // From here on PETSc errors are recorded, not printed.
        call!(PetscPushErrorHandler(Some(error::record_error), std::ptr::null_mut()))?;
        Ok(guard)
    }

    /// `PETSC_COMM_WORLD`.
    pub fn world(&self) -> Comm {
        Comm::world()
    }
}

impl Drop for Petsc {
    fn drop(&mut self) {
        // SAFETY: PETSc was initialised by this guard, and all PETSc objects (which borrow nothing
        // from the guard but must not outlive it) have been dropped by their owners before.
        unsafe {
            sys::PetscPopErrorHandler();
            sys::PetscFinalize();
        }
        // A universe this guard created (MPI_Finalize) is dropped after this.
        self.universe.take();
    }
}
