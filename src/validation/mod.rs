//! Validation: a parsed [`CaseFile`] becomes the [`Case`] every other module takes, or one line
//! that names the file, the key and what is wrong.
//!
//! Each table of the schema checks its own values next to its definition (`check` methods in
//! [`crate::case::schema`]); this module checks what tables say together, one file per section,
//! in the order a reader meets them: the analysis switches and their stabilisation
//! ([`analysis`]), the grid and what its dimension allows ([`grid`], [`dimensions`]), then the
//! materials, bodies, boundaries, loads, stages, probes and the verification, whose checks are
//! its registry's ([`crate::verification::Verification::validate`]: the table's kind and keys,
//! their ranges, what the check needs of the case and of what it names). Before the checks, every
//! name the other sections give is resolved once ([`names`]) into the typed ids the `Case` keeps,
//! so no module past this one looks those up again. It may ask the physics: the analysis of a
//! stage (`analysis::StageAnalysis`), whether an increment factor evaluates, whether a softening
//! model has a unique return. It sits above the checks it asks, below the commands that load a
//! case.

mod analysis;
mod bodies;
mod boundaries;
mod dimensions;
mod grid;
mod loads;
mod materials;
mod names;
mod stages;

use crate::case::ids::Links;
use crate::case::{self, Case, CaseError, CaseFile, InitialValues, Override};
use crate::check::{components, Checked};
use names::Names;

/// Parses and validates a case: [`case::parse`], then [`validate`]. `origin` names the file in
/// messages.
pub fn load(text: &str, origin: &str, overrides: &[Override]) -> Result<Case, CaseError> {
    validate(case::parse(text, origin, overrides)?, origin)
}

/// Reads the files its bodies are made from (relative to `origin`'s directory), checks every
/// range, combination and name of a parsed case file and resolves its names: the only way to a
/// [`Case`]. `origin` is the case file's path, and names it in messages.
pub fn validate(mut file: CaseFile, origin: &str) -> Result<Case, CaseError> {
    let err = |e: String| CaseError::new(format!("{origin}: {e}"));
    bodies::read_files(&mut file, origin).map_err(err)?;
    default_steps(&mut file).map_err(err)?;
    let links = resolve(&file).map_err(err)?;
    let case = Case::new(file, links);
    check(&case).map_err(err)?;
    Ok(case)
}

/// Gives each stage without its own `dt` the case's `time.dt`.
fn default_steps(file: &mut CaseFile) -> Checked {
    let default = file.time.dt;
    for (i, st) in file.stages.iter_mut().enumerate() {
        st.dt = st.dt.or(default);
        if st.dt.is_none() {
            return Err(format!("key `stages[{i}].dt`: give the stage a Δt, or a default in [time] dt"));
        }
    }
    Ok(())
}

/// Every name of the file resolved to the id of the table it names.
fn resolve(file: &CaseFile) -> Result<Links, String> {
    let names = Names::of(file)?;
    let params: Vec<(String, f64)> = file.parameters.iter().map(|(k, v)| (k.clone(), *v)).collect();
    let body_initial = (file.bodies.iter().enumerate())
        .map(|(i, b)| InitialValues::of(b, &format!("bodies[{i}]"), file.dimension(), &params))
        .collect::<Result<_, _>>()?;
    let links = Links {
        body_materials: names.body_materials()?,
        boundaries: names.boundaries()?,
        loads: names.loads()?,
        body_initial,
    };
    names.check_stages()?;
    Ok(links)
}

/// The sections' checks, in the file's order.
fn check(c: &Case) -> Checked {
    analysis::check(c)?;
    grid::check(c)?;
    materials::check(c)?;
    bodies::check(c)?;
    for (i, f) in c.time_functions.iter().enumerate() {
        f.check(&format!("time_functions[{i}]"))?;
    }
    boundaries::check(c)?;
    loads::check(c)?;
    stages::check(c)?;
    c.output.check("output")?;
    probes(c)?;
    crate::verification::Verification::validate(c)
}

/// Each probe's point: one coordinate per dimension, inside the grid.
fn probes(c: &Case) -> Checked {
    let bounds = grid::Bounds::of(c);
    for (i, p) in c.probes.iter().enumerate() {
        components(&format!("probes[{i}].point"), &p.point, c.dimension())?;
        if !bounds.contains(&p.point) {
            return Err(format!("key `probes[{i}].point`: {:?} is outside the grid", p.point));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::load;
    use crate::case::tests_support::MINIMAL;
    use crate::case::{Override, ShapeFunctions};

    #[test]
    fn a_minimal_case_validates_with_defaults() {
        let c = load(MINIMAL, "t.toml", &[]).unwrap();
        assert_eq!(c.analysis.shape_functions, ShapeFunctions::Gimp);
        assert_eq!(c.cell_size(), [0.1, 0.1]);
        let column = c.body_ids().next().unwrap();
        assert_eq!(c.material_of(column).name, "soil");
    }

    /// A stage without its own step takes `time.dt`; without either the key is named.
    #[test]
    fn a_stage_without_a_step_takes_the_default() {
        let no_dt =
            MINIMAL.replace("dt = 1e-3", "").replace("[[stages]]", "[time]\n        dt = 2e-3\n        [[stages]]");
        let c = load(&no_dt, "t.toml", &[Override::parse("time.dt=4e-3").unwrap()]).unwrap();
        assert_eq!(c.stages[0].dt(), 4e-3);
        let e = load(&MINIMAL.replace("dt = 1e-3", ""), "t.toml", &[]).unwrap_err();
        assert!(e.to_string().contains("t.toml: key `stages[0].dt`"), "{e}");
    }

    /// A name that names nothing is refused with its key, before any other check.
    #[test]
    fn names_resolve_or_are_named() {
        let e = load(MINIMAL, "t.toml", &[Override::parse("bodies.0.material=clay").unwrap()]).unwrap_err();
        assert_eq!(e.to_string(), "t.toml: key `bodies[0].material`: no material named `clay`");
        let twice = format!("{MINIMAL}\n[[stages]]\nname = \"x\"\nduration = 0.1\ndt = 0.01\nloads = [\"g\"]\n");
        let e = load(&twice, "t.toml", &[]).unwrap_err();
        assert_eq!(e.to_string(), "t.toml: key `stages[1].loads`: no load named `g`");
    }
}
