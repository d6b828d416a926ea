//! Residual norms field by field, for interlaced systems (several unknowns per grid node).
//!
//! A Krylov solver stops on one norm of the whole residual. When the rows of one field are orders
//! of magnitude smaller than those of another (continuity rows against momentum rows), that norm
//! cannot see the small field, and a solve reported as converged may leave it unsolved. The
//! [`FieldMonitor`] measures every linear solve field by field after it ends
//! (`KSPSetPostSolve`), so that a run can report, and a test can check, that each field's
//! equation was solved to the tolerance asked for.

use crate::{Int, Real, Result, VecOps};
use petsc_sys as sys;
use std::ffi::c_void;

/// The components of each field of an interlaced vector whose block size is the number of
/// components, e.g. `[[0, 1], [2], [3, 4]]` for (ux, uy, p, Ux, Uy).
pub type Fields = Vec<Vec<usize>>;

/// The relative residual of each field of a linear system `A x = b` solved approximately:
///
/// η_f = ‖(b − A x)_f‖ / max(‖b_f‖, max_g ‖(A_fg x_g)‖),
///
/// the residual of field f's rows over the larger of their right-hand side and the largest term
/// of their equations (the block A_fg times the solution's field g). The second guards the case
/// where the right-hand side of a field is small against the terms that balance in it (a field
/// already converged by Newton while another is not): η_f then says how well the field's
/// equation balances its own terms. Scaling the rows of a field, or the unknowns of a field,
/// leaves η unchanged, so one tolerance means the same for every field.
pub fn relative_field_residuals(
    fields: &[Vec<usize>],
    residual: &[Real],
    rhs: &[Real],
    terms: &[Vec<Real>],
) -> Vec<Real> {
    let of = |sq: &[Real], f: &[usize]| f.iter().map(|&c| sq[c]).sum::<Real>().sqrt();
    fields
        .iter()
        .map(|f| {
            let largest_term = terms.iter().map(|t| of(t, f)).fold(0.0, Real::max);
            let den = of(rhs, f).max(largest_term);
            if den > 0.0 {
                of(residual, f) / den
            } else {
                0.0
            }
        })
        .collect()
}

/// Records the largest relative field residual (see [`relative_field_residuals`]) over the linear
/// solves of a KSP since the last [`FieldMonitor::reset`].
#[derive(Debug, Clone)]
pub struct FieldMonitor {
    fields: Fields,
    /// The largest η of each field since the last reset.
    pub worst: Vec<Real>,
    /// Mat-vecs with the whole operator timed over the monitor's life, and their total wall time [s]
    /// (the first product of each measurement: the cost of one mat-vec of the system).
    pub matvecs: (usize, f64),
}

impl FieldMonitor {
    /// A monitor of `fields` (components of the vectors' blocks).
    pub fn new(fields: Fields) -> FieldMonitor {
        let n = fields.len();
        FieldMonitor { fields, worst: vec![0.0; n], matvecs: (0, 0.0) }
    }

    /// Forgets the solves measured so far.
    pub fn reset(&mut self) {
        self.worst.iter_mut().for_each(|w| *w = 0.0);
    }

    /// Measures the solve `A x = b` of `ksp` just finished.
    fn record(&mut self, ksp: sys::KSP, b: sys::Vec, x: sys::Vec) -> Result<()> {
        let (eta, seconds) = measure(&self.fields, ksp, b, x)?;
        self.matvecs.0 += 1;
        self.matvecs.1 += seconds;
        for (w, e) in self.worst.iter_mut().zip(eta) {
            *w = w.max(e);
        }
        Ok(())
    }
}

/// The relative residual of each field (see [`relative_field_residuals`]) of the system of
/// `ksp` at the approximate solution `x` of `A x = b`: 1 + (number of fields) mat-vecs, the
/// first, with the whole `x`, timed [s].
fn measure(fields: &[Vec<usize>], ksp: sys::KSP, b: sys::Vec, x: sys::Vec) -> Result<(Vec<Real>, f64)> {
    let mut a: sys::Mat = std::ptr::null_mut();
    call!(KSPGetOperators(ksp, &mut a, std::ptr::null_mut()))?;
    let mut bs: Int = 0;
    call!(VecGetBlockSize(b, &mut bs))?;
    let nc = bs as usize;
    if fields.iter().flatten().any(|&c| c >= nc) {
        return Err(crate::Error::new(format!(
            "the vectors have {nc} components per block, fewer than the fields {fields:?} name"
        )));
    }
    let squares = |v: sys::Vec| -> Result<Vec<Real>> {
        let mut n = vec![0.0; nc];
        call!(VecStrideNormAll(v, sys::NormType::NORM_2, n.as_mut_ptr()))?;
        Ok(n.into_iter().map(|x| x * x).collect())
    };
    let (r, t, y) = (duplicate(b)?, duplicate(b)?, duplicate(b)?);
    let t0 = std::time::Instant::now();
    call!(MatMult(a, x, r.raw))?;
    let seconds = t0.elapsed().as_secs_f64();
    call!(VecAYPX(r.raw, -1.0, b))?;
    let residual = squares(r.raw)?;
    let rhs = squares(b)?;
    let mut terms = Vec::with_capacity(fields.len());
    for g in fields {
        call!(VecCopy(x, t.raw))?;
        for c in (0..nc).filter(|c| !g.contains(c)) {
            call!(VecStrideScale(t.raw, c as Int, 0.0))?;
        }
        call!(MatMult(a, t.raw, y.raw))?;
        terms.push(squares(y.raw)?);
    }
    Ok((relative_field_residuals(fields, &residual, &rhs, &terms), seconds))
}

/// The Krylov convergence test, field by field: PETSc's own test (kept, and asked first) says
/// when the whole residual is small enough; then every field's relative residual (see
/// [`relative_field_residuals`]) must be at most the KSP's relative tolerance as well, or the
/// iteration goes on. A solve whose small field lags is not checked at every iteration: the next
/// check waits until PETSc's norm has fallen by the factor the worst field still misses.
pub struct FieldTest {
    fields: Fields,
    inner: ConvergenceTest,
    /// PETSc's norm below which the next field check is made (after a failed one).
    next_check: Option<Real>,
}

type ConvergenceFn =
    unsafe extern "C" fn(sys::KSP, Int, Real, *mut sys::KSPConvergedReason, *mut c_void) -> sys::PetscErrorCode;
type DestroyFn = unsafe extern "C" fn(*mut c_void) -> sys::PetscErrorCode;

/// A KSP's own convergence test, taken from it with `KSPGetAndClearConvergenceTest`.
struct ConvergenceTest {
    test: Option<ConvergenceFn>,
    ctx: *mut c_void,
    destroy: Option<DestroyFn>,
}

impl Drop for ConvergenceTest {
    fn drop(&mut self) {
        if let Some(d) = self.destroy {
            // SAFETY: the context was handed over by KSPGetAndClearConvergenceTest with its destroy.
            unsafe { d(self.ctx) };
        }
    }
}

impl FieldTest {
    /// Replaces the convergence test of `ksp` by the field-wise one (boxed: its address is the
    /// test's context; keep the box alive as long as the KSP).
    pub(crate) fn install(ksp: sys::KSP, fields: Fields) -> Result<Box<FieldTest>> {
        let mut inner = ConvergenceTest { test: None, ctx: std::ptr::null_mut(), destroy: None };
        call!(KSPGetAndClearConvergenceTest(ksp, &mut inner.test, &mut inner.ctx, &mut inner.destroy))?;
        let mut t = Box::new(FieldTest { fields, inner, next_check: None });
        let ctx = t.as_mut() as *mut FieldTest as *mut c_void;
        call!(KSPSetConvergenceTest(ksp, Some(field_converged), ctx, None))?;
        Ok(t)
    }

    fn converged(&mut self, ksp: sys::KSP, n: Int, rnorm: Real, reason: &mut sys::KSPConvergedReason) -> Result<()> {
        if let Some(test) = self.inner.test {
            // SAFETY: PETSc's own test with the context it was installed with.
            crate::error::check(unsafe { test(ksp, n, rnorm, reason, self.inner.ctx) })?;
        }
        // Only a tolerance met is questioned (not a divergence, nor preonly's iteration count).
        let by_tolerance = [sys::KSPConvergedReason::KSP_CONVERGED_RTOL, sys::KSPConvergedReason::KSP_CONVERGED_ATOL];
        if n == 0 || !by_tolerance.contains(reason) {
            return Ok(());
        }
        if self.next_check.is_some_and(|t| rnorm > t) {
            *reason = sys::KSPConvergedReason::KSP_CONVERGED_ITERATING;
            return Ok(());
        }
        let (mut rtol, mut atol, mut dtol, mut maxits) = (0.0, 0.0, 0.0, 0 as Int);
        call!(KSPGetTolerances(ksp, &mut rtol, &mut atol, &mut dtol, &mut maxits))?;
        let mut b: sys::Vec = std::ptr::null_mut();
        call!(KSPGetRhs(ksp, &mut b))?;
        let solution = duplicate(b)?;
        let mut x = solution.raw;
        call!(KSPBuildSolution(ksp, solution.raw, &mut x))?;
        let worst = measure(&self.fields, ksp, b, x)?.0.into_iter().fold(0.0, Real::max);
        if worst > rtol {
            *reason = sys::KSPConvergedReason::KSP_CONVERGED_ITERATING;
            self.next_check = Some(rnorm * 0.5 * rtol / worst);
        } else {
            self.next_check = None;
        }
        Ok(())
    }
}

unsafe extern "C" fn field_converged(
    ksp: sys::KSP,
    n: Int,
    rnorm: Real,
    reason: *mut sys::KSPConvergedReason,
    ctx: *mut c_void,
) -> sys::PetscErrorCode {
    // SAFETY: `ctx` is the boxed FieldTest installed with this function; `reason` is PETSc's.
    let (test, reason) = unsafe { (&mut *(ctx as *mut FieldTest), &mut *reason) };
    if n == 0 {
        test.next_check = None;
    }
    code(crate::callback::guarded(|| test.converged(ksp, n, rnorm, reason)), "field-wise convergence test")
}

/// The PETSc error code of a callback's outcome, its message recorded for the caller.
fn code(outcome: std::thread::Result<Result<()>>, what: &str) -> sys::PetscErrorCode {
    match outcome {
        Ok(Ok(())) => 0,
        Ok(Err(e)) => {
            crate::error::set_pending(format!("{what}: {}", e.message));
            e.code as sys::PetscErrorCode
        }
        Err(_) => {
            crate::error::set_pending(format!("{what} panicked"));
            sys::PETSC_ERR_USER as sys::PetscErrorCode
        }
    }
}

/// A new vector shaped like `like` (owned: destroyed on drop).
fn duplicate(like: sys::Vec) -> Result<crate::Vector> {
    crate::VecRef::new(like).duplicate()
}

/// `KSPSetPostSolve` callback: `ctx` is the `FieldMonitor` boxed inside the owning `Snes`.
pub(crate) unsafe extern "C" fn post_solve(
    ksp: sys::KSP,
    b: sys::Vec,
    x: sys::Vec,
    ctx: *mut c_void,
) -> sys::PetscErrorCode {
    if ctx.is_null() {
        return 0;
    }
    // SAFETY: `ctx` is the address of the Box<FieldMonitor> owned by the Snes, which outlives its KSP.
    let monitor = unsafe { &mut *(ctx as *mut FieldMonitor) };
    code(crate::callback::guarded(|| monitor.record(ksp, b, x)), "per-field residuals of the linear solve")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_field_is_measured_against_its_own_rhs_or_largest_term() {
        // Two fields: u = components 0, 1; p = component 2 (squares of stride norms).
        let fields = vec![vec![0, 1], vec![2]];
        let residual = [9.0, 16.0, 1e-6];
        let rhs = [1e4, 0.0, 0.0];
        // Terms: A_·u x_u and A_·p x_p.
        let terms = vec![vec![1e4, 0.0, 4.0], vec![0.0, 0.0, 1.0]];
        let eta = relative_field_residuals(&fields, &residual, &rhs, &terms);
        assert!((eta[0] - 5.0 / 100.0).abs() < 1e-15, "{eta:?}");
        assert!((eta[1] - 1e-3 / 2.0).abs() < 1e-15, "{eta:?}");
        // Scaling the p rows by s scales residual, rhs and terms of p by s²: η unchanged.
        let s2 = 1e12;
        let scaled = |v: &[Real]| vec![v[0], v[1], v[2] * s2];
        let eta2 = relative_field_residuals(
            &fields,
            &scaled(&residual),
            &scaled(&rhs),
            &terms.iter().map(|t| scaled(t)).collect::<Vec<_>>(),
        );
        assert!((eta2[1] - eta[1]).abs() < 1e-15 && (eta2[0] - eta[0]).abs() < 1e-15);
    }

    #[test]
    fn a_field_with_nothing_to_solve_has_no_residual() {
        let eta = relative_field_residuals(&[vec![0]], &[0.0], &[0.0], &[vec![0.0]]);
        assert_eq!(eta, vec![0.0]);
    }
}
