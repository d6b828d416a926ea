//! `[solver]`, `[output]` and `[[probes]]`: the solver's options file and what a run writes.

use crate::check::Checked;
use serde::{Deserialize, Serialize};

/// Solver strategy.
#[derive(Debug, Clone, Default, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Solver {
    /// A PETSc options file applied before the command line's, relative to the case file (default:
    /// the built-in strategy).
    pub options_file: Option<String>,
}

/// Output control.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Output {
    /// Write a history row every this many steps [steps], ≥ 1 (default 1; the last step of a
    /// stage is always written).
    #[serde(default = "default_every")]
    pub history_every: usize,
    /// Write the particle and grid fields to `fields.h5`/`fields.xdmf` every this many steps
    /// [steps], and always at t = 0 (or the restart time) and at the end of every stage; 0 writes
    /// no fields (default 100).
    #[serde(default = "default_fields_every")]
    pub fields_every: usize,
}

serde_defaults! { default_every: usize = 1 }

/// Field output every 100 steps unless the case says otherwise.
pub const DEFAULT_FIELDS_EVERY: usize = 100;

serde_defaults! { default_fields_every: usize = DEFAULT_FIELDS_EVERY }

impl Default for Output {
    fn default() -> Self {
        Output { history_every: 1, fields_every: DEFAULT_FIELDS_EVERY }
    }
}

impl Output {
    /// Checks the history's interval; `key` is the table (`output`).
    pub fn check(&self, key: &str) -> Checked {
        if self.history_every == 0 {
            return Err(format!("key `{key}.history_every`: must be at least 1"));
        }
        Ok(())
    }
}

/// A probe: follows the material point nearest to `point` at t = 0.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Probe {
    /// The column prefix in history.csv, used by one probe only.
    pub name: String,
    /// Position at t = 0 [m], inside the grid: one component per dimension of the case (x, y[, z]).
    pub point: Vec<f64>,
}
