//! Every PETSc error code becomes a [`Result`] here, and only here.
//!
//! At initialisation an error handler is pushed that records PETSc's own message (function and
//! text) instead of printing a traceback. [`check`] turns a non-zero code into an [`Error`]
//! carrying that message. Callbacks written in Rust (SNES residual and Jacobian) report their own
//! errors through [`set_pending`] so that the message that reaches the caller is the Rust one.

use petsc_sys as sys;
use std::cell::RefCell;
use std::ffi::{c_char, c_int, c_void, CStr};
use std::fmt;

/// A PETSc failure: the error code and PETSc's (or our callback's) message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Error {
    /// The `PetscErrorCode` (0 never appears here).
    pub code: i32,
    /// The message recorded by the error handler, e.g. `MatSetValues(): Argument out of range ...`.
    pub message: String,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.message)
    }
}

impl std::error::Error for Error {}

/// Result of every fallible call of this crate.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// An error raised on the Rust side of the binding (bad argument, failed conversion).
    pub fn new(message: impl Into<String>) -> Self {
        Error { code: sys::PETSC_ERR_ARG_WRONG as i32, message: message.into() }
    }
}

thread_local! {
    /// The message of the error currently propagating through PETSc, if any.
    static PENDING: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// Records the message that the next failing [`check`] reports (used by Rust callbacks).
pub(crate) fn set_pending(message: String) {
    PENDING.with(|p| *p.borrow_mut() = Some(message));
}

fn take_pending() -> Option<String> {
    PENDING.with(|p| p.borrow_mut().take())
}

/// PETSc's generic text for an error code (`"Out of memory"`, ...).
fn generic_message(code: i32) -> String {
    let mut text: *const c_char = std::ptr::null();
    // SAFETY: PetscErrorMessage only writes a pointer to a static string (or leaves it null).
    let rc = unsafe { sys::PetscErrorMessage(code, &mut text, std::ptr::null_mut()) };
    if rc == 0 && !text.is_null() {
        // SAFETY: PETSc returned a pointer to a NUL-terminated static string.
        unsafe { CStr::from_ptr(text) }.to_string_lossy().into_owned()
    } else {
        format!("PETSc error code {code}")
    }
}

/// Converts a `PetscErrorCode` into a `Result`: the one place where error codes are interpreted.
pub fn check(code: sys::PetscErrorCode) -> Result<()> {
    if code == 0 {
        return Ok(());
    }
    let message = take_pending().unwrap_or_else(|| generic_message(code));
    Err(Error { code, message })
}

/// The error handler pushed at initialisation. It keeps the first (initial) message of an error
/// and lets the error code propagate; nothing is printed.
///
/// # Safety
/// Called by PETSc with valid (possibly null) C strings.
pub(crate) unsafe extern "C" fn record_error(
    _comm: sys::MPI_Comm,
    line: c_int,
    func: *const c_char,
    file: *const c_char,
    code: sys::PetscErrorCode,
    kind: sys::PetscErrorType,
    mess: *const c_char,
    _ctx: *mut c_void,
) -> sys::PetscErrorCode {
    let text = |p: *const c_char| {
        if p.is_null() {
            String::new()
        } else {
            // SAFETY: PETSc passes NUL-terminated strings.
            unsafe { CStr::from_ptr(p) }.to_string_lossy().trim().to_string()
        }
    };
    if kind == sys::PetscErrorType::PETSC_ERROR_INITIAL {
        let mut msg = text(mess);
        if msg.is_empty() {
            msg = generic_message(code);
        }
        let f = text(func);
        // PETSc's source file and line are internals a user cannot act on: left out of the message
        // (a debugger, `-on_error_attach_debugger`, finds them).
        let _ = (line, file);
        let full = if f.is_empty() { msg } else { format!("{f}(): {msg}") };
        set_pending(full);
    } else {
        PENDING.with(|p| {
            let mut p = p.borrow_mut();
            if p.is_none() {
                *p = Some(generic_message(code));
            }
        });
    }
    code
}
