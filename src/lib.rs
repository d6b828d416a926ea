//! porompm: the implicit three-field (u–p–U) GIMP material point method for large-deformation
//! saturated soils, on PETSc. See ARCHITECTURE.md for the map of the code.
//!
//! Local and global stay apart: [`kernels`] and [`model`] are pure Rust (one material point, one
//! small dense block at a time); [`assembly`] is the only module that talks to PETSc; [`io`] is the
//! only module that touches files; [`driver`] is the algorithm on one page.

/// Defines the functions that serde's `#[serde(default = "name")]` calls for a field's default:
/// `serde_defaults! { default_cfl: f64 = 0.5, default_cuts: usize = 4 }`.
macro_rules! serde_defaults {
    ($($name:ident: $t:ty = $value:expr),* $(,)?) => {
        $(fn $name() -> $t { $value })*
    };
}

pub mod algebra;
pub mod analysis;
pub mod assembly;
pub mod case;
pub mod check;
pub mod describe;
pub mod diagnostics;
pub mod distribution;
pub mod driver;
pub mod element_test;
pub mod fields;
pub mod geometry;
pub mod io;
pub mod kernels;
pub mod layout;
pub mod model;
pub mod parallel;
pub mod plot;
pub mod progress;
pub mod recorders;
pub mod report;
pub mod scheme;
pub mod soils;
pub mod state;
pub mod summary;
pub mod sweep;
pub mod update;
pub mod validation;
pub mod verification;

/// porompm's version and git revision.
pub const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), " (git ", env!("POROMPM_GIT_REV"), ")");

/// What `porompm --version` prints after the program name.
pub const VERSION_LONG: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (git ",
    env!("POROMPM_GIT_REV"),
    ")\nPETSc ",
    env!("POROMPM_PETSC_VERSION"),
    " with ",
    env!("POROMPM_PETSC_PACKAGES")
);
