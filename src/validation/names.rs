//! Names: every array of named tables is there and names each table once, and every name a table
//! gives resolves, once, to the id of the table it names.

use crate::case::ids::{BoundaryLinks, LoadLinks};
use crate::case::{BodyId, BoundaryId, CaseFile, LoadId, MaterialId, StageId, TimeFunctionId};
use crate::check::{unique, Checked};

/// The names of a file's tables, to resolve the names its other tables give.
pub(super) struct Names<'a> {
    file: &'a CaseFile,
}

impl<'a> Names<'a> {
    /// The names of `file`, after checking that the arrays that must have a table have one and
    /// that no name is used twice in an array.
    pub fn of(file: &'a CaseFile) -> Result<Names<'a>, String> {
        if file.materials.is_empty() {
            return Err("at least one [[materials]] table is needed".into());
        }
        unique("materials", file.materials.iter().map(|m| m.name.as_str()))?;
        if file.bodies.is_empty() {
            return Err("at least one [[bodies]] table is needed".into());
        }
        unique("bodies", file.bodies.iter().map(|b| b.name.as_str()))?;
        unique("time_functions", file.time_functions.iter().map(|f| f.name()))?;
        unique("boundaries", file.boundaries.iter().map(|b| b.name.as_str()))?;
        unique("loads", file.loads.iter().map(|l| l.name()))?;
        if file.stages.is_empty() {
            return Err("at least one [[stages]] table is needed".into());
        }
        unique("stages", file.stages.iter().map(|s| s.name.as_str()))?;
        unique("probes", file.probes.iter().map(|p| p.name.as_str()))?;
        Ok(Names { file })
    }

    /// The material called `name`, or the message of `key` that gives it.
    pub fn material(&self, key: &str, name: &str) -> Result<MaterialId, String> {
        find(key, "material", name, self.file.materials.iter().map(|m| m.name.as_str())).map(MaterialId::new)
    }

    /// The body called `name`.
    pub fn body(&self, key: &str, name: &str) -> Result<BodyId, String> {
        find(key, "body", name, self.file.bodies.iter().map(|b| b.name.as_str())).map(BodyId::new)
    }

    /// The load called `name`.
    pub fn load(&self, key: &str, name: &str) -> Result<LoadId, String> {
        find(key, "load", name, self.file.loads.iter().map(|l| l.name())).map(LoadId::new)
    }

    /// The boundary called `name`.
    pub fn boundary(&self, key: &str, name: &str) -> Result<BoundaryId, String> {
        find(key, "boundary", name, self.file.boundaries.iter().map(|b| b.name.as_str())).map(BoundaryId::new)
    }

    /// The time function called `name`.
    pub fn time_function(&self, key: &str, name: &str) -> Result<TimeFunctionId, String> {
        find(key, "time function", name, self.file.time_functions.iter().map(|f| f.name())).map(TimeFunctionId::new)
    }

    /// The stage called `name`.
    pub fn stage(&self, key: &str, name: &str) -> Result<StageId, String> {
        find(key, "stage", name, self.file.stages.iter().map(|s| s.name.as_str())).map(StageId::new)
    }

    /// The material of each body.
    pub fn body_materials(&self) -> Result<Vec<MaterialId>, String> {
        let bodies = self.file.bodies.iter().enumerate();
        bodies.map(|(i, b)| self.material(&format!("bodies[{i}].material"), &b.material)).collect()
    }

    /// What each boundary names: the body of its surface, its time function.
    pub fn boundaries(&self) -> Result<Vec<BoundaryLinks>, String> {
        let boundaries = self.file.boundaries.iter().enumerate();
        boundaries
            .map(|(i, b)| {
                let surface_body =
                    b.surface.as_ref().map(|sf| self.body(&format!("boundaries[{i}].surface.body"), &sf.body));
                let time_function =
                    b.time_function.as_ref().map(|f| self.time_function(&format!("boundaries[{i}].time_function"), f));
                Ok(BoundaryLinks { surface_body: surface_body.transpose()?, time_function: time_function.transpose()? })
            })
            .collect()
    }

    /// What each load names: its time function, the bodies it is limited to.
    pub fn loads(&self) -> Result<Vec<LoadLinks>, String> {
        let loads = self.file.loads.iter().enumerate();
        loads
            .map(|(i, l)| {
                let key = format!("loads[{i}]");
                let time_function = l.time_function().map(|f| self.time_function(&format!("{key}.time_function"), f));
                let bodies = l.body_names().map(|names| names.iter().map(|b| self.body(&key, b)).collect());
                Ok(LoadLinks { time_function: time_function.transpose()?, bodies: bodies.transpose()? })
            })
            .collect()
    }

    /// That the boundaries and loads each stage lists exist.
    pub fn check_stages(&self) -> Checked {
        for (i, s) in self.file.stages.iter().enumerate() {
            for n in s.boundaries.iter().flatten() {
                self.boundary(&format!("stages[{i}].boundaries"), n)?;
            }
            for n in s.loads.iter().flatten() {
                self.load(&format!("stages[{i}].loads"), n)?;
            }
            // A name listed twice would act once (or twice): either way not what the list says.
            unique(&format!("key `stages[{i}].boundaries`"), s.boundaries.iter().flatten().map(String::as_str))?;
            unique(&format!("key `stages[{i}].loads`"), s.loads.iter().flatten().map(String::as_str))?;
        }
        Ok(())
    }
}

/// The index of `name` among `names`, or `key `KEY`: no WHAT named `NAME``.
fn find<'n>(key: &str, what: &str, name: &str, mut names: impl Iterator<Item = &'n str>) -> Result<usize, String> {
    names.position(|n| n == name).ok_or_else(|| format!("key `{key}`: no {what} named `{name}`"))
}
