//! PETSc options databases: the global one (what `-ksp_type` on the command line feeds) and private
//! ones that can be pushed as the default for a while (used by tests to run several option files in
//! one process).

use crate::{cstring, from_bool, Comm, Error, Result};
use petsc_sys as sys;
use std::ffi::{c_char, CStr};
use std::path::Path;

/// An option as stored in a database: name without the leading dash, value if any.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OptionEntry {
    /// Name without the leading `-`, e.g. `ksp_type`.
    pub name: String,
    /// Value, if the option has one.
    pub value: Option<String>,
}

impl std::fmt::Display for OptionEntry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.value {
            Some(v) => write!(f, "-{} {}", self.name, v),
            None => write!(f, "-{}", self.name),
        }
    }
}

/// A PETSc options database. [`Options::global`] refers to the default database (not owned);
/// [`Options::new`] creates a private one, destroyed on drop.
pub struct Options {
    raw: sys::PetscOptions,
    owned: bool,
    pushed: bool,
}

fn c_text(p: *const c_char) -> Option<String> {
    if p.is_null() {
        None
    } else {
        // SAFETY: PETSc returns NUL-terminated strings.
        Some(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
    }
}

impl Options {
    /// The default (global) options database.
    pub fn global() -> Options {
        Options { raw: std::ptr::null_mut(), owned: false, pushed: false }
    }

    /// A new, empty, private database.
    pub fn new() -> Result<Options> {
        let mut raw = std::ptr::null_mut();
        call!(PetscOptionsCreate(&mut raw))?;
        Ok(Options { raw, owned: true, pushed: false })
    }

    /// Inserts options from a string in command-line form (`"-ksp_type cg -pc_type jacobi"`).
    pub fn insert_string(&self, s: &str) -> Result<()> {
        let c = cstring(s)?;
        call!(PetscOptionsInsertString(self.raw, c.as_ptr()))
    }

    /// Inserts options from a PETSc options file (one option per line, `#` comments).
    /// A missing file is an error naming the file.
    pub fn insert_file(&self, comm: Comm, path: &Path) -> Result<()> {
        if !path.is_file() {
            return Err(Error::new(format!("PETSc options file {} does not exist", path.display())));
        }
        let c = cstring(&path.to_string_lossy())?;
        call!(PetscOptionsInsertFile(comm.raw(), self.raw, c.as_ptr(), sys::PetscBool::PETSC_TRUE))
    }

    /// Sets one option (`name` with its leading dash), with or without a value.
    pub fn set_value(&self, name: &str, value: Option<&str>) -> Result<()> {
        let n = cstring(name)?;
        let v = value.map(cstring).transpose()?;
        call!(PetscOptionsSetValue(self.raw, n.as_ptr(), v.as_ref().map_or(std::ptr::null(), |v| v.as_ptr())))
    }

    /// Removes one option (`name` with its leading dash).
    pub fn clear_value(&self, name: &str) -> Result<()> {
        let n = cstring(name)?;
        call!(PetscOptionsClearValue(self.raw, n.as_ptr()))
    }

    /// Whether an option (`name` with its leading dash) is present. Querying marks it as used.
    pub fn has_name(&self, name: &str) -> Result<bool> {
        let n = cstring(name)?;
        let mut set = sys::PetscBool::PETSC_FALSE;
        call!(PetscOptionsHasName(self.raw, std::ptr::null(), n.as_ptr(), &mut set))?;
        Ok(from_bool(set))
    }

    /// The string value of an option (`name` with its leading dash), if set.
    pub fn get_string(&self, name: &str) -> Result<Option<String>> {
        let n = cstring(name)?;
        let mut buf = vec![0 as c_char; 4096];
        let mut set = sys::PetscBool::PETSC_FALSE;
        call!(PetscOptionsGetString(self.raw, std::ptr::null(), n.as_ptr(), buf.as_mut_ptr(), buf.len(), &mut set))?;
        if !from_bool(set) {
            return Ok(None);
        }
        Ok(c_text(buf.as_ptr()))
    }

    /// The boolean value of an option (`name` with its leading dash), if set (a bare name means
    /// true); a value that is not a boolean is an error.
    pub fn get_bool(&self, name: &str) -> Result<Option<bool>> {
        let n = cstring(name)?;
        let mut value = sys::PetscBool::PETSC_FALSE;
        let mut set = sys::PetscBool::PETSC_FALSE;
        call!(PetscOptionsGetBool(self.raw, std::ptr::null(), n.as_ptr(), &mut value, &mut set))?;
        Ok(from_bool(set).then(|| from_bool(value)))
    }

    /// Every option currently in the database, in insertion order.
    pub fn all(&self) -> Result<Vec<OptionEntry>> {
        let mut p: *mut c_char = std::ptr::null_mut();
        call!(PetscOptionsGetAll(self.raw, &mut p))?;
        let text = c_text(p).unwrap_or_default();
        // SAFETY: PetscOptionsGetAll allocated the string with PetscMalloc; PetscTrFree releases it.
        unsafe {
            if let Some(free) = sys::PetscTrFree {
                free(p as *mut _, line!() as i32, c"Options::all".as_ptr(), c"options.rs".as_ptr());
            }
        }
        Ok(parse_option_string(&text))
    }

    /// Options that were set but never queried by any PETSc object (what `-options_left` reports).
    pub fn unused(&self) -> Result<Vec<OptionEntry>> {
        let mut n: sys::PetscInt = 0;
        let mut names: *mut *mut c_char = std::ptr::null_mut();
        let mut values: *mut *mut c_char = std::ptr::null_mut();
        call!(PetscOptionsLeftGet(self.raw, &mut n, &mut names, &mut values))?;
        let mut out = Vec::with_capacity(n as usize);
        for i in 0..n as usize {
            // SAFETY: PETSc returned arrays of `n` string pointers (values may be null).
            let (name, value) = unsafe { (c_text(*names.add(i)), c_text(*values.add(i))) };
            out.push(OptionEntry { name: name.unwrap_or_default(), value });
        }
        call!(PetscOptionsLeftRestore(self.raw, &mut n, &mut names, &mut values))?;
        Ok(out)
    }

    /// Makes this (private) database the default one until [`Options::pop`] or drop.
    pub fn push(&mut self) -> Result<()> {
        if !self.owned {
            return Err(Error::new("only a private options database can be pushed"));
        }
        call!(PetscOptionsPush(self.raw))?;
        self.pushed = true;
        Ok(())
    }

    /// Restores the previous default database.
    pub fn pop(&mut self) -> Result<()> {
        if self.pushed {
            self.pushed = false;
            call!(PetscOptionsPop())?;
        }
        Ok(())
    }
}

impl Drop for Options {
    fn drop(&mut self) {
        let _ = self.pop();
        if self.owned {
            // SAFETY: the database was created by PetscOptionsCreate and is no longer the default.
            unsafe { sys::PetscOptionsDestroy(&mut self.raw) };
        }
    }
}

/// Splits PETSc's `-a 1 -b -c x` form into entries. A token that does not start with `-` (or is a
/// negative number) is the value of the preceding option.
pub fn parse_option_string(text: &str) -> Vec<OptionEntry> {
    let mut out: Vec<OptionEntry> = Vec::new();
    for tok in text.split_whitespace() {
        let is_name = tok.starts_with('-') && tok.len() > 1 && tok.parse::<f64>().is_err();
        if is_name {
            out.push(OptionEntry { name: tok[1..].to_string(), value: None });
        } else if let Some(last) = out.last_mut() {
            last.value = Some(match last.value.take() {
                Some(v) => format!("{v} {tok}"),
                None => tok.to_string(),
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn option_strings_split_into_names_and_values() {
        let v = parse_option_string("-ksp_type gmres -snes_monitor -snes_lag_jacobian -2 -pc_type lu");
        assert_eq!(v.len(), 4);
        assert_eq!(v[0], OptionEntry { name: "ksp_type".into(), value: Some("gmres".into()) });
        assert_eq!(v[1], OptionEntry { name: "snes_monitor".into(), value: None });
        assert_eq!(v[2].value.as_deref(), Some("-2"));
        assert_eq!(v[3].to_string(), "-pc_type lu");
    }
}
