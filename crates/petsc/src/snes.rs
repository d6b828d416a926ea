//! Nonlinear solvers (SNES) with residual and Jacobian callbacks written in Rust.
//!
//! The callbacks are the two methods of a [`NonlinearProblem`], borrowed only for the duration of
//! one [`Snes::solve`]; outside a solve the SNES holds no pointer to Rust data. Panics inside the
//! callbacks are caught at the FFI boundary and become errors; a [`CallbackError::Domain`] marks the
//! trial state as inadmissible (`SNESSetFunctionDomainError`), which makes the solve end as diverged
//! instead of failing, so the caller can cut the step.

use crate::callback::guarded;
use crate::fields::{FieldMonitor, FieldTest, Fields};
use crate::ksp::{KspOps, KspRef};
use crate::mat::{Mat, MatRef};
use crate::vector::{VecOps, VecRef, Vector};
use crate::{cstring, error, Comm, Int, Real, Result};
use petsc_sys as sys;
use std::ffi::{c_char, c_void, CStr};

/// Why a callback could not produce its result.
#[derive(Debug, Clone)]
pub enum CallbackError {
    /// The trial state is outside the domain of the problem (e.g. a particle's volume became
    /// negative): the solve stops as diverged and the caller may retry with a smaller step.
    Domain(String),
    /// Anything else: the solve fails with this message.
    Fatal(String),
}

/// The residual and Jacobian of a nonlinear system `F(x) = 0`.
pub trait NonlinearProblem {
    /// Evaluates `f = F(x)`.
    fn residual(&mut self, x: &VecRef, f: &mut VecRef) -> std::result::Result<(), CallbackError>;
    /// Assembles the Jacobian `J = dF/dx` at `x` into `j` (the matrix given to [`Snes::solve`])
    /// and, when [`Snes::solve`] was given a preconditioning matrix apart from it, that matrix at
    /// `x` into `p`.
    fn jacobian(
        &mut self,
        x: &VecRef,
        j: &mut MatRef,
        p: Option<&mut MatRef>,
    ) -> std::result::Result<(), CallbackError>;
}

/// What one [`Snes::solve`] did.
#[derive(Debug, Clone)]
pub struct SolveOutcome {
    /// Whether SNES reports convergence.
    pub converged: bool,
    /// PETSc's `SNESConvergedReason` (positive: converged).
    pub reason: i32,
    /// PETSc's name for the reason (`CONVERGED_FNORM_RELATIVE`, `DIVERGED_LINE_SEARCH`, ...).
    pub reason_text: String,
    /// Newton iterations.
    pub iterations: usize,
    /// Krylov iterations summed over the Newton iterations.
    pub linear_iterations: usize,
    /// Residual 2-norm before the first and after every Newton iteration.
    pub residual_history: Vec<Real>,
    /// The message of a [`CallbackError::Domain`] raised during the solve, if any.
    pub domain_error: Option<String>,
    /// The 2-norm of each component of the final residual (empty unless the residual vector has
    /// a block size above one).
    pub final_residual_components: Vec<Real>,
    /// The largest relative residual of each field over the linear solves (see
    /// [`crate::fields::relative_field_residuals`]; empty without [`Snes::monitor_fields`]).
    pub linear_field_residuals: Vec<Real>,
    /// After a linear solve that failed in a MUMPS factorisation, what MUMPS reported.
    pub factorisation: Option<crate::MumpsStatus>,
}

/// An owned SNES, destroyed on drop.
pub struct Snes {
    raw: sys::SNES,
    history: Box<[Real]>,
    history_its: Box<[Int]>,
    /// The per-field measurement of the linear solves (its address is the KSP's post-solve
    /// context, so it lives, boxed, as long as the SNES).
    fields: Option<Box<FieldMonitor>>,
    /// The field-wise Krylov convergence test (its address is the KSP's convergence context).
    field_test: Option<Box<FieldTest>>,
}

impl Drop for Snes {
    fn drop(&mut self) {
        // SAFETY: owned handle, destroyed once; the history buffers outlive it.
        unsafe { sys::SNESDestroy(&mut self.raw) };
    }
}

struct Context<'a> {
    problem: &'a mut dyn NonlinearProblem,
    domain_error: Option<String>,
}

fn panic_text(p: Box<dyn std::any::Any + Send>) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".into()
    }
}

/// Maps a callback's outcome to a PETSc error code (0 = success or domain error already flagged).
fn finish(
    outcome: std::thread::Result<std::result::Result<(), CallbackError>>,
    what: &str,
    ctx: &mut Context,
    flag_domain: impl FnOnce(),
) -> sys::PetscErrorCode {
    match outcome {
        Ok(Ok(())) => 0,
        Ok(Err(CallbackError::Domain(msg))) => {
            if ctx.domain_error.is_none() {
                ctx.domain_error = Some(msg);
            }
            flag_domain();
            0
        }
        Ok(Err(CallbackError::Fatal(msg))) => {
            error::set_pending(format!("{what}: {msg}"));
            sys::PETSC_ERR_USER as sys::PetscErrorCode
        }
        Err(p) => {
            error::set_pending(format!("{what} panicked: {}", panic_text(p)));
            sys::PETSC_ERR_USER as sys::PetscErrorCode
        }
    }
}

unsafe extern "C" fn residual_trampoline(
    snes: sys::SNES,
    x: sys::Vec,
    f: sys::Vec,
    ctx: *mut c_void,
) -> sys::PetscErrorCode {
    if ctx.is_null() {
        error::set_pending("SNES residual evaluated outside Snes::solve".into());
        return sys::PETSC_ERR_ORDER as sys::PetscErrorCode;
    }
    // SAFETY: `ctx` points to the Context living on the stack of `Snes::solve` during the solve.
    let ctx = unsafe { &mut *(ctx as *mut Context) };
    let outcome = guarded(|| ctx.problem.residual(&VecRef::new(x), &mut VecRef::new(f)));
    finish(outcome, "residual evaluation", ctx, || {
        // SAFETY: valid SNES handle passed by PETSc.
        unsafe { sys::SNESSetFunctionDomainError(snes) };
    })
}

unsafe extern "C" fn jacobian_trampoline(
    snes: sys::SNES,
    x: sys::Vec,
    a: sys::Mat,
    p: sys::Mat,
    ctx: *mut c_void,
) -> sys::PetscErrorCode {
    if ctx.is_null() {
        error::set_pending("SNES Jacobian evaluated outside Snes::solve".into());
        return sys::PETSC_ERR_ORDER as sys::PetscErrorCode;
    }
    // SAFETY: as in `residual_trampoline`.
    let ctx = unsafe { &mut *(ctx as *mut Context) };
    let outcome = guarded(|| {
        let mut pre = MatRef::new(p);
        ctx.problem.jacobian(&VecRef::new(x), &mut MatRef::new(a), (p != a).then_some(&mut pre))
    });
    finish(outcome, "Jacobian assembly", ctx, || {
        // SAFETY: valid SNES handle passed by PETSc.
        unsafe { sys::SNESSetJacobianDomainError(snes) };
    })
}

impl Snes {
    /// A new nonlinear solver on `comm`.
    pub fn new(comm: Comm) -> Result<Snes> {
        let mut raw = std::ptr::null_mut();
        call!(SNESCreate(comm.raw(), &mut raw))?;
        let mut s = Snes {
            raw,
            history: vec![0.0; 1000].into_boxed_slice(),
            history_its: vec![0; 1000].into_boxed_slice(),
            fields: None,
            field_test: None,
        };
        call!(SNESSetConvergenceHistory(
            s.raw,
            s.history.as_mut_ptr(),
            s.history_its.as_mut_ptr(),
            s.history.len() as Int,
            sys::PetscBool::PETSC_TRUE
        ))?;
        Ok(s)
    }

    /// Attaches a DM (its field names drive `-pc_fieldsplit_*_fields`).
    pub fn set_dm<const D: usize>(&mut self, dm: &crate::DmDa<D>) -> Result<()> {
        call!(SNESSetDM(self.raw, dm.raw()))
    }

    /// Sets the SNES method by PETSc name (`"newtonls"`, ...).
    pub fn set_type(&mut self, name: &str) -> Result<()> {
        let c = cstring(name)?;
        call!(SNESSetType(self.raw, c.as_ptr()))
    }

    /// Absolute, relative and step tolerances and the iteration limit (`None` keeps PETSc's).
    pub fn set_tolerances(
        &mut self,
        atol: Option<Real>,
        rtol: Option<Real>,
        stol: Option<Real>,
        max_it: Option<usize>,
    ) -> Result<()> {
        let d = sys::PETSC_DEFAULT as Real;
        call!(SNESSetTolerances(
            self.raw,
            atol.unwrap_or(d),
            rtol.unwrap_or(d),
            stol.unwrap_or(d),
            max_it.map_or(sys::PETSC_DEFAULT as Int, |m| m as Int),
            sys::PETSC_DEFAULT as Int
        ))
    }

    /// Sets the line search by PETSc name (`"basic"` takes full Newton steps, `"bt"` backtracks).
    pub fn set_line_search(&mut self, name: &str) -> Result<()> {
        let mut ls = std::ptr::null_mut();
        call!(SNESGetLineSearch(self.raw, &mut ls))?;
        let c = cstring(name)?;
        call!(SNESLineSearchSetType(ls, c.as_ptr()))
    }

    /// The line search's PETSc name (`"basic"`, `"bt"`, ...).
    pub fn line_search_type(&self) -> Result<String> {
        let mut ls = std::ptr::null_mut();
        call!(SNESGetLineSearch(self.raw, &mut ls))?;
        let mut t: sys::SNESLineSearchType = std::ptr::null();
        call!(SNESLineSearchGetType(ls, &mut t))?;
        // SAFETY: PETSc returns a NUL-terminated static string.
        Ok(if t.is_null() { String::new() } else { unsafe { CStr::from_ptr(t) }.to_string_lossy().into_owned() })
    }

    /// Current (atol, rtol, stol, max_it).
    pub fn tolerances(&self) -> Result<(Real, Real, Real, usize)> {
        let (mut a, mut r, mut s) = (0.0, 0.0, 0.0);
        let (mut it, mut mf): (Int, Int) = (0, 0);
        call!(SNESGetTolerances(self.raw, &mut a, &mut r, &mut s, &mut it, &mut mf))?;
        Ok((a, r, s, it as usize))
    }

    /// Rebuild the Jacobian every `lag` iterations within a solve (-1: never, -2: once more).
    pub fn set_lag_jacobian(&mut self, lag: i32) -> Result<()> {
        call!(SNESSetLagJacobian(self.raw, lag))
    }

    /// The current Jacobian lag.
    pub fn lag_jacobian(&self) -> Result<i32> {
        let mut l: Int = 0;
        call!(SNESGetLagJacobian(self.raw, &mut l))?;
        Ok(l)
    }

    /// Sets the options prefix.
    pub fn set_prefix(&mut self, prefix: &str) -> Result<()> {
        crate::set_object_prefix(self.raw as sys::PetscObject, prefix)
    }

    /// Reads `-snes_*`, `-ksp_*`, `-pc_*` options (call after the defaults set in code).
    pub fn set_from_options(&mut self) -> Result<()> {
        call!(SNESSetFromOptions(self.raw))
    }

    /// Whether the linear tolerance follows Eisenstat–Walker (`-snes_ksp_ew`).
    pub fn uses_eisenstat_walker(&self) -> Result<bool> {
        let mut flg = sys::PetscBool::PETSC_FALSE;
        call!(SNESKSPGetUseEW(self.raw, &mut flg))?;
        Ok(crate::from_bool(flg))
    }

    /// Measures every linear solve field by field from now on (`fields`: the components of each
    /// field in the vectors' blocks); each [`Snes::solve`] reports the largest relative residual
    /// of each field over its linear solves in [`SolveOutcome::linear_field_residuals`]. With
    /// `test`, a Krylov solve also converges only when every field's relative residual is within
    /// the KSP's relative tolerance (see [`FieldTest`]). Call after [`Snes::set_from_options`].
    pub fn monitor_fields(&mut self, fields: Fields, test: bool) -> Result<()> {
        let mut monitor = Box::new(FieldMonitor::new(fields.clone()));
        let ctx = monitor.as_mut() as *mut FieldMonitor as *mut c_void;
        let mut k = std::ptr::null_mut();
        call!(SNESGetKSP(self.raw, &mut k))?;
        call!(KSPSetPostSolve(k, Some(crate::fields::post_solve), ctx))?;
        self.fields = Some(monitor);
        if test {
            self.field_test = Some(FieldTest::install(k, fields)?);
        }
        Ok(())
    }

    /// Mat-vecs with the whole operator timed by the field monitor over the SNES's life, and their
    /// total wall time [s] (on this rank; PETSc's own mat-vecs inside the solvers are not counted).
    pub fn timed_matvecs(&self) -> (usize, f64) {
        self.fields.as_ref().map_or((0, 0.0), |m| m.matvecs)
    }

    /// The linear solver inside the SNES.
    pub fn ksp(&mut self) -> Result<KspRef<'_>> {
        let mut k = std::ptr::null_mut();
        call!(SNESGetKSP(self.raw, &mut k))?;
        Ok(KspRef::new(k))
    }

    /// The SNES method's PETSc name.
    pub fn type_name(&self) -> Result<String> {
        let mut t: sys::SNESType = std::ptr::null();
        call!(SNESGetType(self.raw, &mut t))?;
        // SAFETY: PETSc returns a NUL-terminated static string.
        Ok(if t.is_null() { String::new() } else { unsafe { CStr::from_ptr(t) }.to_string_lossy().into_owned() })
    }

    /// Prints the solver configuration (what `-snes_view` prints).
    pub fn view(&self, viewer: &crate::Viewer) -> Result<()> {
        call!(SNESView(self.raw, viewer.raw()))
    }

    /// What MUMPS reported of a factorisation that failed in the last linear solve (`None`
    /// unless the solve failed in its preconditioner and that was a MUMPS factorisation).
    fn failed_factorisation(&mut self) -> Result<Option<crate::MumpsStatus>> {
        let mut ksp = self.ksp()?;
        if ksp.last_solve()?.reason != sys::KSPConvergedReason::KSP_DIVERGED_PC_FAILED.0 {
            return Ok(None);
        }
        Ok(ksp.pc()?.mumps_status()?.filter(|m| m.infog1 < 0))
    }

    /// The options prefix of the SNES's preconditioner (empty without one).
    pub fn pc_prefix(&mut self) -> Result<String> {
        self.ksp()?.pc()?.prefix()
    }

    /// Drops the factors of a factorisation preconditioner (`lu`, `cholesky`) whose last
    /// factorisation failed, so that the next solve analyses and factorises the matrix anew.
    ///
    /// PETSc 3.18's MUMPS interface, after a numerical factorisation that failed (INFOG(1) = −10,
    /// a numerically singular matrix), clears the error at the next setup with the same nonzero
    /// pattern, takes the stored negative INFOG(1) for a failed analysis, skips the factorisation
    /// without flagging it, and then fails hard in the solve (INFOG(1) = −3: no factors): a Δt cut
    /// after a singular Jacobian would end the run with that error instead of trying the smaller
    /// step. Called after a solve that ended in `SNES_DIVERGED_LINEAR_SOLVE`; acts only when the
    /// linear solve failed in the preconditioner (`KSP_DIVERGED_PC_FAILED`, a reason every rank
    /// shares, since the reset is collective). Costs a new symbolic factorisation at the next
    /// solve.
    fn forget_failed_factorisation(&mut self) -> Result<()> {
        let mut ksp = self.ksp()?;
        if ksp.last_solve()?.reason != sys::KSPConvergedReason::KSP_DIVERGED_PC_FAILED.0 {
            return Ok(());
        }
        let mut pc = ksp.pc()?;
        if matches!(pc.type_name()?.as_str(), "lu" | "cholesky") {
            pc.reset()?;
        }
        Ok(())
    }

    /// Lets the solver let go of its matrices and of everything its preconditioner built from
    /// them (a factorisation's factors, a multigrid's hierarchy), so that matrices of a new nonzero
    /// pattern are not allocated while the old ones and their preconditioner still sit in memory
    /// (the next solve's setup would free them only then). Returns whether it did: only
    /// preconditioners whose whole state is built from the matrix are reset (`none`, `jacobi`,
    /// `sor`, `ilu`, `icc`, `lu`, `cholesky`, `gamg`); the others keep definitions of their own
    /// (a field split's splits, a redundant solver's inner solver), which a reset would lose, and
    /// keep everything until the next setup replaces it. Collective.
    pub fn release_operators(&mut self) -> Result<bool> {
        {
            let mut ksp = self.ksp()?;
            let mut pc = ksp.pc()?;
            match pc.type_name()?.as_str() {
                "none" | "jacobi" | "sor" | "ilu" | "icc" | "lu" | "cholesky" => {}
                // PETSc 3.18's PCReset of GAMG keeps the multigrid's levels with their old
                // operators, whose sizes the next setup then refuses to change; setting the type
                // anew destroys the whole hierarchy, and the options are read again.
                "gamg" => {
                    pc.set_type("none")?;
                    pc.set_type("gamg")?;
                    pc.set_from_options()?;
                }
                _ => return Ok(false),
            }
        }
        call!(SNESReset(self.raw))?;
        Ok(true)
    }

    /// Makes `pmat`, the matrix the preconditioner is built from, also the operator the solver
    /// holds, so that the old Jacobian is freed before a new one (of another nonzero pattern) is
    /// allocated, while the preconditioner keeps what it built from `pmat`. The next
    /// [`Snes::solve`] sets the new Jacobian. Collective.
    pub fn release_jacobian(&mut self, pmat: &Mat) -> Result<()> {
        call!(SNESSetJacobian(self.raw, pmat.raw, pmat.raw, Some(jacobian_trampoline), std::ptr::null_mut()))?;
        let ksp = self.ksp()?;
        call!(KSPSetOperators(ksp.raw(), pmat.raw, pmat.raw))
    }

    /// The 2-norm of each component of the SNES's residual vector (empty if it has none yet or
    /// its block size is one).
    fn residual_components(&self) -> Result<Vec<Real>> {
        let mut f: sys::Vec = std::ptr::null_mut();
        call!(SNESGetFunction(self.raw, &mut f, std::ptr::null_mut(), std::ptr::null_mut()))?;
        if f.is_null() {
            return Ok(Vec::new());
        }
        let mut bs: Int = 0;
        call!(VecGetBlockSize(f, &mut bs))?;
        if bs <= 1 {
            return Ok(Vec::new());
        }
        let mut n = vec![0.0; bs as usize];
        call!(VecStrideNormAll(f, sys::NormType::NORM_2, n.as_mut_ptr()))?;
        Ok(n)
    }

    /// Solves `F(x) = 0` starting from `x`, with `jac` as Jacobian matrix and `pmat` as the
    /// matrix the preconditioner is built from (`None`: `jac` itself).
    ///
    /// Solver failures that PETSc reports as divergence (line search, iteration limit, domain
    /// error) come back as `Ok` with `converged == false`; only genuine errors are `Err`.
    pub fn solve(
        &mut self,
        x: &mut Vector,
        jac: &mut Mat,
        pmat: Option<&mut Mat>,
        problem: &mut dyn NonlinearProblem,
    ) -> Result<SolveOutcome> {
        let pre = pmat.map_or(jac.raw, |p| p.raw);
        if let Some(m) = self.fields.as_mut() {
            m.reset();
        }
        let mut ctx = Context { problem, domain_error: None };
        let ctx_ptr = &mut ctx as *mut Context as *mut c_void;
        call!(SNESSetFunction(self.raw, std::ptr::null_mut(), Some(residual_trampoline), ctx_ptr))?;
        call!(SNESSetJacobian(self.raw, jac.raw, pre, Some(jacobian_trampoline), ctx_ptr))?;
        let solved = call!(SNESSolve(self.raw, std::ptr::null_mut(), x.raw()));
        // Never leave a pointer to this stack frame inside the SNES.
        let unset_f =
            call!(SNESSetFunction(self.raw, std::ptr::null_mut(), Some(residual_trampoline), std::ptr::null_mut()));
        let unset_j = call!(SNESSetJacobian(self.raw, jac.raw, pre, Some(jacobian_trampoline), std::ptr::null_mut()));
        solved?;
        unset_f?;
        unset_j?;

        let mut reason = sys::SNESConvergedReason(0);
        call!(SNESGetConvergedReason(self.raw, &mut reason))?;
        let mut text: *const c_char = std::ptr::null();
        call!(SNESGetConvergedReasonString(self.raw, &mut text))?;
        // SAFETY: PETSc returns a NUL-terminated static string.
        let reason_text =
            if text.is_null() { String::new() } else { unsafe { CStr::from_ptr(text) }.to_string_lossy().into_owned() };
        let mut its: Int = 0;
        call!(SNESGetIterationNumber(self.raw, &mut its))?;
        let mut lits: Int = 0;
        call!(SNESGetLinearSolveIterations(self.raw, &mut lits))?;
        let mut hist: *mut Real = std::ptr::null_mut();
        let mut hist_its: *mut Int = std::ptr::null_mut();
        let mut nhist: Int = 0;
        call!(SNESGetConvergenceHistory(self.raw, &mut hist, &mut hist_its, &mut nhist))?;
        let n = (nhist.max(0) as usize).min(self.history.len());
        let final_residual_components = self.residual_components()?;
        let mut factorisation = None;
        if reason == sys::SNESConvergedReason::SNES_DIVERGED_LINEAR_SOLVE {
            factorisation = self.failed_factorisation()?;
            self.forget_failed_factorisation()?;
        }
        Ok(SolveOutcome {
            converged: reason.0 > 0,
            reason: reason.0,
            reason_text,
            iterations: its as usize,
            linear_iterations: lits as usize,
            residual_history: self.history[..n].to_vec(),
            domain_error: ctx.domain_error,
            final_residual_components,
            linear_field_residuals: self.fields.as_ref().map(|m| m.worst.clone()).unwrap_or_default(),
            factorisation,
        })
    }
}
