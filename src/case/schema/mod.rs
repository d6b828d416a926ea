//! The case-file schema: every table and key a case may contain, with its unit and range, one
//! file per section. SI units throughout: m, s, kg, Pa, m/s.
//!
//! Every table denies unknown keys, so a misspelt key is an error naming it. A table's own ranges
//! are checked by its `check` method, next to its definition; what several tables say together is
//! checked by [`crate::validation`]. The doc comments here, and those of the soil models'
//! parameters in [`crate::soils`], are the user's reference: docs/case_reference.md is generated
//! from them.

mod analysis;
mod bodies;
mod boundaries;
mod from_files;
mod loads;
mod materials;
mod output;
mod solids;
mod stabilisation;
mod stages;
mod verification;

pub use analysis::*;
pub use bodies::*;
pub use boundaries::*;
pub use from_files::*;
pub use loads::*;
pub use materials::*;
pub use output::*;
pub use solids::*;
pub use stabilisation::*;
pub use stages::*;
pub use verification::*;

use serde::{Deserialize, Serialize};

/// A case file as written: what is simulated, how, and what it is checked against. Validation
/// turns it into a [`crate::case::Case`], the form every other module takes.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CaseFile {
    /// Named numbers used by `"= expression"` values elsewhere in the file (`+ - * / ^`,
    /// parentheses, `pi` and the functions `sqrt`, `exp`, `ln`, `sin`, `cos`, `tan`, `atan`,
    /// `atan2(y, x)`, `radians`, `degrees`, `abs`, `min`, `max`) and by the expressions of position
    /// (a body's `initial` values, a load's `increment_factor`); `--set parameters.NAME=VALUE`
    /// changes them. `x`, `y` and `z` name a point's position and no parameter.
    #[serde(default)]
    pub parameters: std::collections::BTreeMap<String, f64>,
    /// Physics switches that shape the discrete system.
    pub analysis: Analysis,
    /// The background grid.
    pub grid: Grid,
    /// Materials, at least one, each named once; bodies name them.
    pub materials: Vec<Material>,
    /// Bodies filled with material points at t = 0, at least one, each named once.
    pub bodies: Vec<Body>,
    /// Named time functions that scale loads and boundaries' motions.
    #[serde(default)]
    pub time_functions: Vec<TimeFunction>,
    /// Dirichlet conditions on grid nodes.
    #[serde(default)]
    pub boundaries: Vec<Boundary>,
    /// Loads (tractions, pressures, body forces).
    #[serde(default)]
    pub loads: Vec<Load>,
    /// Stabilisation of the equal-order u–p–U discretisation and of volumetric locking.
    #[serde(default)]
    pub stabilisation: Stabilisation,
    /// Time-stepping defaults shared by the stages.
    #[serde(default)]
    pub time: Time,
    /// The analysis stages, run in order, at least one.
    pub stages: Vec<Stage>,
    /// The time integration of dynamic stages (each may give its own).
    #[serde(default)]
    pub time_integration: TimeIntegration,
    /// Solver strategy (a PETSc options file).
    #[serde(default)]
    pub solver: Solver,
    /// Output control.
    #[serde(default)]
    pub output: Output,
    /// Material points whose history is recorded.
    #[serde(default)]
    pub probes: Vec<Probe>,
    /// The analytical reference the run is checked against, if any.
    pub verification: Option<VerificationTable>,
    /// The key path each `--set` override reached (`verification.kind`) with the key as the command
    /// line gave it, so that a table deserialized after parsing names the override as parsing does.
    #[serde(skip)]
    pub(crate) overridden: Vec<(String, String)>,
}

impl CaseFile {
    /// Total analysis time [s].
    pub fn end_time(&self) -> f64 {
        self.stages.iter().map(|s| s.duration).sum()
    }

    /// The dimension of the case: the number of entries of `grid.size` (2 or 3, validated).
    pub fn dimension(&self) -> usize {
        self.grid.size.len()
    }

    /// The grid's origin in the first `D` directions [m] (zero where the case gives none).
    pub fn origin_in<const D: usize>(&self) -> [f64; D] {
        std::array::from_fn(|d| self.grid.origin.get(d).copied().unwrap_or(0.0))
    }

    /// The grid's cells in the first `D` directions.
    pub fn cells_in<const D: usize>(&self) -> [usize; D] {
        std::array::from_fn(|d| self.grid.cells.get(d).copied().unwrap_or(1))
    }

    /// The cell size in the first `D` directions [m].
    pub fn cell_size_in<const D: usize>(&self) -> [f64; D] {
        let cells = self.cells_in::<D>();
        std::array::from_fn(|d| self.grid.size.get(d).copied().unwrap_or(1.0) / cells[d] as f64)
    }

    /// The grid's origin in x and y [m].
    pub fn origin(&self) -> [f64; 2] {
        self.origin_in()
    }

    /// The grid's cells in x and y.
    pub fn cells(&self) -> [usize; 2] {
        self.cells_in()
    }

    /// Cell size in x and y [m].
    pub fn cell_size(&self) -> [f64; 2] {
        self.cell_size_in()
    }

    /// The extent [z_min, z_max] of `body` along z in a three-dimensional case [m]: its own, its
    /// solid's, or the grid's.
    pub fn body_depth(&self, body: &Body) -> [f64; 2] {
        body.z.or_else(|| body.shape.depth()).unwrap_or_else(|| {
            let z0 = self.grid.origin.get(2).copied().unwrap_or(0.0);
            [z0, z0 + self.grid.size.get(2).copied().unwrap_or(0.0)]
        })
    }

    /// Whether `body` holds the point `p` of a case of dimension `D`: its solid holds it, or its
    /// section holds (x, y) and, in three dimensions, its extent along z holds z (bounds included,
    /// as the section's).
    pub fn body_holds<const D: usize>(&self, body: &Body, p: [f64; D]) -> bool {
        if let Some(solid) = body.shape.solid() {
            return D == 3 && solid.holds([p[0], p[1], p[D - 1]]);
        }
        if !body.shape.contains([p[0], p[1]]) {
            return false;
        }
        D == 2 || {
            let [lo, hi] = self.body_depth(body);
            p[2] >= lo && p[2] <= hi
        }
    }

    /// The material stiffness of Newton's matrix (see [`Stabilisation::jacobian_stiffness`]).
    pub fn jacobian_stiffness(&self) -> Stiffness {
        self.stabilisation.jacobian_stiffness()
    }
}
