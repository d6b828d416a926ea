//! Callbacks from PETSc into Rust: each runs counted (so that a panic hook can tell a caught
//! panic from a fatal one) and with its panic caught, which the caller turns into a PETSc error.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Callbacks running now in this process (their panics are caught and become SNES errors).
static IN_CALLBACK: AtomicUsize = AtomicUsize::new(0);

/// Whether a residual or Jacobian callback is running in this process (on any thread, so also
/// on the worker threads a callback starts): a panic then is caught and becomes an error that
/// every rank agrees on, and a panic hook must not end the process for it.
pub fn in_callback() -> bool {
    IN_CALLBACK.load(Ordering::SeqCst) > 0
}

/// Runs `f` counted as a callback (see [`in_callback`]), catching its panic.
pub(crate) fn guarded<T>(f: impl FnOnce() -> T) -> std::thread::Result<T> {
    IN_CALLBACK.fetch_add(1, Ordering::SeqCst);
    let r = catch_unwind(AssertUnwindSafe(f));
    IN_CALLBACK.fetch_sub(1, Ordering::SeqCst);
    r
}
