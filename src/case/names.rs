//! Names: the id of the table a name of the case file gives, or one line naming the key that
//! gives it. Validation resolves the names of every section with these lookups, and a verification
//! check ([`crate::verification`]) the names of its own table.

use super::ids::{BodyId, BoundaryId, LoadId, MaterialId, StageId, TimeFunctionId};
use super::schema::CaseFile;

impl CaseFile {
    /// The material called `name`, or ``key `KEY`: no material named `NAME` `` with `key` the key
    /// that gives the name (`bodies[0].material`).
    pub fn material_named(&self, key: &str, name: &str) -> Result<MaterialId, String> {
        find(key, "material", name, self.materials.iter().map(|m| m.name.as_str())).map(MaterialId::new)
    }

    /// The body called `name` (see [`CaseFile::material_named`]).
    pub fn body_named(&self, key: &str, name: &str) -> Result<BodyId, String> {
        find(key, "body", name, self.bodies.iter().map(|b| b.name.as_str())).map(BodyId::new)
    }

    /// The load called `name` (see [`CaseFile::material_named`]).
    pub fn load_named(&self, key: &str, name: &str) -> Result<LoadId, String> {
        find(key, "load", name, self.loads.iter().map(|l| l.name())).map(LoadId::new)
    }

    /// The boundary called `name` (see [`CaseFile::material_named`]).
    pub fn boundary_named(&self, key: &str, name: &str) -> Result<BoundaryId, String> {
        find(key, "boundary", name, self.boundaries.iter().map(|b| b.name.as_str())).map(BoundaryId::new)
    }

    /// The time function called `name` (see [`CaseFile::material_named`]).
    pub fn time_function_named(&self, key: &str, name: &str) -> Result<TimeFunctionId, String> {
        find(key, "time function", name, self.time_functions.iter().map(|f| f.name())).map(TimeFunctionId::new)
    }

    /// The stage called `name` (see [`CaseFile::material_named`]).
    pub fn stage_named(&self, key: &str, name: &str) -> Result<StageId, String> {
        find(key, "stage", name, self.stages.iter().map(|s| s.name.as_str())).map(StageId::new)
    }
}

/// The index of `name` among `names`, or ``key `KEY`: no WHAT named `NAME` ``.
fn find<'n>(key: &str, what: &str, name: &str, mut names: impl Iterator<Item = &'n str>) -> Result<usize, String> {
    names.position(|n| n == name).ok_or_else(|| format!("key `{key}`: no {what} named `{name}`"))
}
