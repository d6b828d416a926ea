//! Names: every array of named tables is there and names each table once, and every name a table
//! gives resolves, once, to the id of the table it names (by the lookups of
//! [`CaseFile`], `material_named` and the like).

use crate::case::ids::{BoundaryLinks, LoadLinks};
use crate::case::{CaseFile, MaterialId};
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

    /// The material of each body.
    pub fn body_materials(&self) -> Result<Vec<MaterialId>, String> {
        let bodies = self.file.bodies.iter().enumerate();
        bodies.map(|(i, b)| self.file.material_named(&format!("bodies[{i}].material"), &b.material)).collect()
    }

    /// What each boundary names: the body of its surface, its time function.
    pub fn boundaries(&self) -> Result<Vec<BoundaryLinks>, String> {
        let file = self.file;
        file.boundaries
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let surface_body =
                    b.surface.as_ref().map(|sf| file.body_named(&format!("boundaries[{i}].surface.body"), &sf.body));
                let time_function = b
                    .time_function
                    .as_ref()
                    .map(|f| file.time_function_named(&format!("boundaries[{i}].time_function"), f));
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
                let time_function =
                    l.time_function().map(|f| self.file.time_function_named(&format!("{key}.time_function"), f));
                let bodies = l.body_names().map(|names| names.iter().map(|b| self.file.body_named(&key, b)).collect());
                Ok(LoadLinks { time_function: time_function.transpose()?, bodies: bodies.transpose()? })
            })
            .collect()
    }

    /// That the boundaries and loads each stage lists exist.
    pub fn check_stages(&self) -> Checked {
        for (i, s) in self.file.stages.iter().enumerate() {
            for n in s.boundaries.iter().flatten() {
                self.file.boundary_named(&format!("stages[{i}].boundaries"), n)?;
            }
            for n in s.loads.iter().flatten() {
                self.file.load_named(&format!("stages[{i}].loads"), n)?;
            }
            // A name listed twice would act once (or twice): either way not what the list says.
            unique(&format!("key `stages[{i}].boundaries`"), s.boundaries.iter().flatten().map(String::as_str))?;
            unique(&format!("key `stages[{i}].loads`"), s.loads.iter().flatten().map(String::as_str))?;
        }
        Ok(())
    }
}
