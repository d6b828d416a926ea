//! Krylov solvers and preconditioners.

use crate::mat::MatOps;
use crate::vector::VecOps;
use crate::{cstring, Comm, Int, Real, Result};
use petsc_sys as sys;
use std::ffi::{c_char, CStr};
use std::marker::PhantomData;

/// An owned KSP (linear solver), destroyed on drop.
pub struct Ksp {
    raw: sys::KSP,
}

/// A borrowed KSP (e.g. the one inside a SNES).
pub struct KspRef<'a> {
    raw: sys::KSP,
    _life: PhantomData<&'a mut ()>,
}

/// A borrowed preconditioner (always owned by its KSP).
pub struct PcRef<'a> {
    pub(crate) raw: sys::PC,
    _life: PhantomData<&'a mut ()>,
}

/// Result of a linear solve.
#[derive(Debug, Clone)]
pub struct LinearSolve {
    /// Positive: converged; negative: diverged (PETSc's `KSPConvergedReason`).
    pub reason: i32,
    /// PETSc's name of the reason (`CONVERGED_RTOL`, `DIVERGED_ITS`, ...).
    pub reason_text: String,
    /// Krylov iterations.
    pub iterations: usize,
}

fn c_str(p: *const c_char) -> String {
    if p.is_null() {
        String::new()
    } else {
        // SAFETY: PETSc returns NUL-terminated static strings.
        unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
    }
}

/// Operations shared by owned and borrowed KSPs.
pub trait KspOps {
    /// The raw handle.
    fn raw(&self) -> sys::KSP;

    /// Sets the operator and the matrix the preconditioner is built from.
    fn set_operators(&mut self, a: &dyn MatOps, p: &dyn MatOps) -> Result<()> {
        call!(KSPSetOperators(self.raw(), a.raw(), p.raw()))
    }

    /// Sets the Krylov method by PETSc name (`"gmres"`, `"preonly"`, ...).
    fn set_type(&mut self, name: &str) -> Result<()> {
        let c = cstring(name)?;
        call!(KSPSetType(self.raw(), c.as_ptr()))
    }

    /// The Krylov method's PETSc name.
    fn type_name(&self) -> Result<String> {
        let mut t: sys::KSPType = std::ptr::null();
        call!(KSPGetType(self.raw(), &mut t))?;
        Ok(c_str(t))
    }

    /// Relative, absolute and divergence tolerances and the iteration limit (`None` keeps PETSc's).
    fn set_tolerances(&mut self, rtol: Option<Real>, atol: Option<Real>, max_it: Option<usize>) -> Result<()> {
        let d = sys::PETSC_DEFAULT as Real;
        call!(KSPSetTolerances(
            self.raw(),
            rtol.unwrap_or(d),
            atol.unwrap_or(d),
            d,
            max_it.map_or(sys::PETSC_DEFAULT as Int, |m| m as Int)
        ))
    }

    /// Reads `-ksp_*` and `-pc_*` options (call after setting defaults in code).
    fn set_from_options(&mut self) -> Result<()> {
        call!(KSPSetFromOptions(self.raw()))
    }

    /// Sets the options prefix.
    fn set_prefix(&mut self, prefix: &str) -> Result<()> {
        crate::set_object_prefix(self.raw() as sys::PetscObject, prefix)
    }

    /// The preconditioner.
    fn pc(&mut self) -> Result<PcRef<'_>> {
        let mut pc = std::ptr::null_mut();
        call!(KSPGetPC(self.raw(), &mut pc))?;
        Ok(PcRef { raw: pc, _life: PhantomData })
    }

    /// Solves `A x = b`.
    fn solve(&mut self, b: &dyn VecOps, x: &mut dyn VecOps) -> Result<LinearSolve> {
        call!(KSPSolve(self.raw(), b.raw(), x.raw()))?;
        self.last_solve()
    }

    /// Outcome of the last solve.
    fn last_solve(&self) -> Result<LinearSolve> {
        let mut reason = sys::KSPConvergedReason(0);
        call!(KSPGetConvergedReason(self.raw(), &mut reason))?;
        let mut its: Int = 0;
        call!(KSPGetIterationNumber(self.raw(), &mut its))?;
        let mut text: *const c_char = std::ptr::null();
        call!(KSPGetConvergedReasonString(self.raw(), &mut text))?;
        Ok(LinearSolve { reason: reason.0, reason_text: c_str(text), iterations: its as usize })
    }
}

impl KspOps for Ksp {
    fn raw(&self) -> sys::KSP {
        self.raw
    }
}

impl KspOps for KspRef<'_> {
    fn raw(&self) -> sys::KSP {
        self.raw
    }
}

impl Drop for Ksp {
    fn drop(&mut self) {
        // SAFETY: owned handle, destroyed once.
        unsafe { sys::KSPDestroy(&mut self.raw) };
    }
}

impl Ksp {
    /// A new linear solver on `comm`.
    pub fn new(comm: Comm) -> Result<Ksp> {
        let mut raw = std::ptr::null_mut();
        call!(KSPCreate(comm.raw(), &mut raw))?;
        Ok(Ksp { raw })
    }
}

impl KspRef<'_> {
    pub(crate) fn new(raw: sys::KSP) -> Self {
        KspRef { raw, _life: PhantomData }
    }
}

impl PcRef<'_> {
    /// Sets the preconditioner by PETSc name (`"lu"`, `"fieldsplit"`, `"hypre"`, ...).
    pub fn set_type(&mut self, name: &str) -> Result<()> {
        let c = cstring(name)?;
        call!(PCSetType(self.raw, c.as_ptr()))
    }

    /// The preconditioner's PETSc name.
    pub fn type_name(&self) -> Result<String> {
        let mut t: sys::PCType = std::ptr::null();
        call!(PCGetType(self.raw, &mut t))?;
        Ok(c_str(t))
    }

    /// Reads the preconditioner's options from the options database (`PCSetFromOptions`).
    pub fn set_from_options(&mut self) -> Result<()> {
        call!(PCSetFromOptions(self.raw))
    }

    /// For factorisation preconditioners: which package factorises (`"mumps"`, `"petsc"`, ...).
    pub fn set_factor_solver_type(&mut self, name: &str) -> Result<()> {
        let c = cstring(name)?;
        call!(PCFactorSetMatSolverType(self.raw, c.as_ptr()))
    }

    /// For a redundant preconditioner (`"redundant"`): the solver each rank runs on its own copy
    /// of the whole system (options prefix `-redundant_`; preonly with LU unless set), created
    /// here if it is not yet (`PCRedundantGetKSP`; collective).
    pub fn redundant_ksp(&mut self) -> Result<KspRef<'_>> {
        let mut raw: sys::KSP = std::ptr::null_mut();
        call!(PCRedundantGetKSP(self.raw, &mut raw))?;
        Ok(KspRef::new(raw))
    }

    /// For a field split: defines the split `name` (options prefix `-fieldsplit_<name>_`) as the
    /// rows of `is`. Splits are added in call order.
    pub fn field_split_set_is(&mut self, name: &str, is: &crate::IndexSet) -> Result<()> {
        let c = cstring(name)?;
        call!(PCFieldSplitSetIS(self.raw, c.as_ptr(), is.raw()))
    }

    /// Frees what the preconditioner built (a factorisation's factors, a multigrid's levels) and
    /// the operators it holds, so that its next setup builds everything anew (`PCReset`;
    /// collective).
    pub fn reset(&mut self) -> Result<()> {
        call!(PCReset(self.raw))
    }

    /// For factorisation preconditioners: the package doing it (`"mumps"`, `"petsc"`, ...).
    pub fn factor_solver_type(&self) -> Result<Option<String>> {
        let mut t: sys::MatSolverType = std::ptr::null();
        call!(PCFactorGetMatSolverType(self.raw, &mut t))?;
        Ok((!t.is_null()).then(|| c_str(t)))
    }

    /// The state of this preconditioner's MUMPS factorisation, once it has been set up (`None`
    /// for another preconditioner or package).
    pub fn mumps_status(&self) -> Result<Option<MumpsStatus>> {
        if !matches!(self.type_name()?.as_str(), "lu" | "cholesky")
            || self.factor_solver_type()?.as_deref() != Some("mumps")
        {
            return Ok(None);
        }
        let mut f: sys::Mat = std::ptr::null_mut();
        call!(PCFactorGetMatrix(self.raw, &mut f))?;
        if f.is_null() {
            return Ok(None);
        }
        let (mut infog1, mut infog2, mut icntl14): (Int, Int, Int) = (0, 0, 0);
        call!(MatMumpsGetInfog(f, 1, &mut infog1))?;
        call!(MatMumpsGetInfog(f, 2, &mut infog2))?;
        call!(MatMumpsGetIcntl(f, 14, &mut icntl14))?;
        Ok(Some(MumpsStatus { infog1, infog2, icntl14 }))
    }

    /// The options prefix of the preconditioner (empty without one).
    pub fn prefix(&self) -> Result<String> {
        let mut p: *const c_char = std::ptr::null();
        call!(PCGetOptionsPrefix(self.raw, &mut p))?;
        Ok(if p.is_null() { String::new() } else { c_str(p) })
    }
}

/// What MUMPS reports of its last factorisation ([`PcRef::mumps_status`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MumpsStatus {
    /// INFOG(1): 0 on success, negative on an error (MUMPS users' guide, §8).
    pub infog1: Int,
    /// INFOG(2): the error's detail.
    pub infog2: Int,
    /// ICNTL(14): the percentage by which the workspace exceeds the analysis' estimate.
    pub icntl14: Int,
}

impl MumpsStatus {
    /// Whether the factorisation failed for a workspace or buffer that ICNTL(14) sizes (INFOG(1)
    /// = −8, −9, −11, −12, −14, −15, −17 or −20).
    pub fn workspace_too_small(&self) -> bool {
        matches!(self.infog1, -8 | -9 | -11 | -12 | -14 | -15 | -17 | -20)
    }

    /// What an error INFOG(1) means, in a few words (empty on success).
    pub fn cause(&self) -> String {
        let what = match self.infog1 {
            0.. => return String::new(),
            -8 | -14 | -15 => "its integer workspace was too small",
            -9 | -11 | -12 => "its real workspace was too small",
            -17 | -20 => "its communication buffers were too small",
            -10 => "the matrix is numerically singular",
            -13 => "it could not allocate memory",
            -19 => "the memory allowed by ICNTL(23) was too small",
            _ => "it failed",
        };
        format!("MUMPS: {what} (INFOG(1) = {}, INFOG(2) = {})", self.infog1, self.infog2)
    }
}
