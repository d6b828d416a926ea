//! Case files: typed TOML with `deny_unknown_fields`, `--set` overrides, `[parameters]`.
//!
//! [`parse`] turns the text of a case file plus the command line's overrides into a
//! [`CaseFile`], the file as written; [`crate::validation`] checks it and makes the [`Case`] every
//! other module takes, its names resolved to typed ids ([`ids`]). Every error names the file, the
//! key and what is wrong, in one line. This module is the bottom of the house: of the physics it
//! imports only the soil models' parameters ([`crate::soils`], on its layer), the table
//! `materials.model`; the table `[verification]` it keeps untyped, for the checks' registry
//! ([`crate::verification`]) to read with [`CaseFile::table_as`].

pub mod expression;
pub mod ids;
mod names;
pub mod overrides;
pub mod parameters;
pub mod schema;
mod validated;

pub use expression::Expr;
pub use ids::{BodyId, BoundaryId, LoadId, MaterialId, StageId, TimeFunctionId};
pub use overrides::Override;
pub use schema::*;
pub use validated::Case;

use std::fmt;

/// A problem with a case file or an override, as one line of text.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseError(String);

impl CaseError {
    /// An error with the given message.
    pub fn new(msg: impl Into<String>) -> Self {
        CaseError(msg.into())
    }
}

impl fmt::Display for CaseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for CaseError {}

/// Line (1-based) of a byte offset in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}

/// Parses a case: the TOML, the overrides, the `[parameters]` and `"= expr"` values, the types of
/// every key. `origin` names the file in messages. What the values mean together is
/// [`crate::validation`]'s to check.
pub fn parse(text: &str, origin: &str, overrides: &[Override]) -> Result<CaseFile, CaseError> {
    let mut doc: toml::Value = toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| format!(" (line {})", line_of(text, s.start))).unwrap_or_default();
        CaseError::new(format!("{origin}{line}: {}", e.message().trim()))
    })?;
    let mut set_paths = Vec::new();
    for ov in overrides {
        let path = overrides::apply(&mut doc, ov).map_err(|e| CaseError::new(format!("{origin}: {e}")))?;
        set_paths.push((path, ov.key.clone()));
    }
    parameters::expand(&mut doc).map_err(|e| CaseError::new(format!("{origin}: {e}")))?;
    let mut file: CaseFile = serde_path_to_error::deserialize(doc).map_err(|e| {
        let msg = misfit(&set_paths, &e.path().to_string(), e.inner().message());
        CaseError::new(format!("{origin}: {msg}"))
    })?;
    file.overridden = set_paths;
    Ok(file)
}

/// The message of a value at key `path` that does not fit its type (`msg`): ``key `PATH`: MSG``,
/// or ``--set KEY: MSG`` where the override `KEY` of `set` (its path, its key as given) wrote it.
fn misfit(set: &[(String, String)], path: &str, msg: &str) -> String {
    let msg = msg.trim();
    let from_set = set
        .iter()
        .find(|(p, _)| path == *p || path.starts_with(&format!("{p}.")) || path.starts_with(&format!("{p}[")));
    match from_set {
        Some((_, key)) => format!("--set {key}: {msg}"),
        None if path == "." || path.is_empty() => msg.to_string(),
        None => format!("key `{path}`: {msg}"),
    }
}

impl CaseFile {
    /// `value`, the table at `key` of the file, deserialized as a `T`; a value that does not fit
    /// is one line naming its key (``key `verification.kind`: unknown variant ...``) or the
    /// override that gave it, as [`parse`] names the keys of the file's own tables.
    pub fn table_as<T: serde::de::DeserializeOwned>(&self, key: &str, value: toml::Value) -> Result<T, String> {
        serde_path_to_error::deserialize(value).map_err(|e| {
            let path = match e.path().to_string().as_str() {
                "" | "." => key.to_string(),
                inner => format!("{key}.{inner}"),
            };
            misfit(&self.overridden, &path, e.inner().message())
        })
    }
}

/// Case texts shared by unit tests.
#[cfg(test)]
pub(crate) mod tests_support {
    /// A small valid two-phase column.
    pub const MINIMAL: &str = r#"
        [analysis]
        formulation = "two_phase"
        [grid]
        size = [0.1, 1.0]
        cells = [1, 10]
        [[materials]]
        name = "soil"
        porosity = 0.3
        solid_density = 2650.0
        water_bulk_modulus = 2.2e9
        solid_bulk_modulus = inf
        hydraulic_conductivity = 1e-3
        [materials.model]
        type = "linear_elastic"
        young_modulus = 1e7
        poisson_ratio = 0.0
        [[bodies]]
        name = "column"
        material = "soil"
        shape = { rectangle = { min = [0.0, 0.0], max = [0.1, 1.0] } }
        [[stages]]
        name = "load"
        duration = 0.1
        dt = 1e-3
    "#;

    /// [`MINIMAL`] on a grid of `size` [m] and `cells` (TOML arrays: two entries, or three for a
    /// three-dimensional case).
    pub fn with_grid(size: &str, cells: &str) -> String {
        MINIMAL
            .replace("size = [0.1, 1.0]\n        cells = [1, 10]", &format!("size = {size}\n        cells = {cells}"))
    }

    /// [`MINIMAL`] in three dimensions (0.2 × 1.0 × 0.3 m, 2 × 10 × 3 cells) with a base on
    /// `y_min` fixing ux, uy and uz, a back wall on `z_min` fixing the components `back_fix`, and
    /// a region at the top (x ∈ [0, 0.1], z ∈ [0.1, 0.2]) fixing ux, uy, uz and p that moves as
    /// `motion` says (a `displacement` or `velocity` key).
    pub fn solid_with_boundaries(back_fix: &str, motion: &str) -> String {
        with_grid("[0.2, 1.0, 0.3]", "[2, 10, 3]")
            + &format!(
                r#"
            [[boundaries]]
            name = "base"
            side = "y_min"
            fix = ["ux", "uy", "uz"]
            [[boundaries]]
            name = "back"
            side = "z_min"
            fix = {back_fix}
            [[boundaries]]
            name = "top"
            region = {{ min = [0.0, 1.0], max = [0.1, 1.0], z = [0.1, 0.2] }}
            fix = ["ux", "uy", "uz", "p"]
            {motion}
        "#
            )
    }
}

#[cfg(test)]
mod tests {
    use super::tests_support::MINIMAL;
    use super::*;

    /// A line region holds the grid node round-off put a hair beside it (origin −8.4 m, 25 cells
    /// of 2.8 m: the node meant for x = 0 at −1.8e-15 m), and not the node a cell away.
    #[test]
    fn a_line_region_holds_the_node_on_its_line() {
        let clamp = Region { min: [0.0, -1.0], max: [0.0, 1.0], z: None };
        let (origin, h) = (-8.4f64, 2.8f64);
        let x = origin + 3.0 * h;
        assert!(x != 0.0 && x.abs() < 1e-14, "{x}");
        assert!(!clamp.contains([x, 0.0]));
        assert!(clamp.holds_node([x, 0.0], [h, h]));
        assert!(!clamp.holds_node([x + h, 0.0], [h, h]));
    }

    /// The names the messages use are the case file's.
    #[test]
    fn stiffness_names_are_the_case_file_s() {
        for s in [
            Stiffness::Particle,
            Stiffness::WStar,
            Stiffness::GaussMapping,
            Stiffness::DoubleMapping,
            Stiffness::DoubleMappingGimp,
        ] {
            assert_eq!(serde_json::to_value(s).unwrap(), s.name());
        }
    }

    #[test]
    fn a_minimal_case_parses_with_defaults() {
        let c = parse(MINIMAL, "t.toml", &[]).unwrap();
        assert_eq!(c.analysis.shape_functions, ShapeFunctions::Gimp);
        assert_eq!(c.time_integration.newmark().0, 0.25);
        assert_eq!(c.cell_size(), [0.1, 0.1]);
        assert!(c.materials[0].solid_bulk_modulus.unwrap().is_infinite());
    }

    #[test]
    fn unknown_keys_and_wrong_types_name_the_key() {
        let e = parse(&MINIMAL.replace("porosity = 0.3", "porosity = 0.3\nporosty = 1"), "t.toml", &[]).unwrap_err();
        assert!(e.to_string().contains("materials[0]") && e.to_string().contains("porosty"), "{e}");
        let e = parse(&MINIMAL.replace("cells = [1, 10]", "cells = [1, \"ten\"]"), "t.toml", &[]).unwrap_err();
        assert!(e.to_string().contains("grid.cells"), "{e}");
        let e = parse(MINIMAL, "t.toml", &[Override::parse("grid.cels=[2,20]").unwrap()]).unwrap_err();
        assert!(e.to_string().contains("--set grid.cels") && e.to_string().contains("unknown field"), "{e}");
    }

    #[test]
    fn overrides_change_values() {
        let sets = [Override::parse("grid.cells=[2,20]").unwrap(), Override::parse("stages[0].dt=5e-4").unwrap()];
        let c = parse(MINIMAL, "t.toml", &sets).unwrap();
        assert_eq!(c.cells(), [2, 20]);
        assert_eq!(c.stages[0].dt(), 5e-4);
    }

    /// An unknown key inside a table chosen by its `type` or `kind` is refused with its key named,
    /// and the tag itself is not taken for an unknown key.
    #[test]
    fn unknown_keys_inside_tagged_tables_are_named() {
        let e = parse(&MINIMAL.replace("poisson_ratio = 0.0", "poisson_ratio = 0.0\nyoung = 1"), "t.toml", &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("key `materials[0].model`") && e.contains("unknown field `young`"), "{e}");
        assert!(!e.contains("`type`"), "{e}");
        let with_load = format!(
            "{MINIMAL}\n[[loads]]\nkind = \"body_force\"\nname = \"g\"\nacceleration = [0.0, -9.81]\nbody = \"column\"\n"
        );
        let e = parse(&with_load, "t.toml", &[]).unwrap_err().to_string();
        assert!(e.contains("key `loads[0]`") && e.contains("unknown field `body`"), "{e}");
        assert!(!e.contains("`kind`"), "{e}");
        let c = parse(&with_load.replace("body = \"column\"\n", ""), "t.toml", &[]).unwrap();
        assert!(matches!(&c.loads[0], Load::BodyForce(f) if f.name == "g" && f.bodies.is_none()));
        let e = parse(&MINIMAL.replace("type = \"linear_elastic\"", "type = \"elastic\""), "t.toml", &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("key `materials[0].model.type`") && e.contains("unknown variant `elastic`"), "{e}");
    }

    #[test]
    fn shapes_contain_points() {
        let poly = Shape::Polygon(Polygon { vertices: vec![[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]] });
        assert!(poly.contains([0.5, 0.5]));
        assert!(!poly.contains([1.5, 1.5]));
        let r = Region { min: [0.0, 1.0], max: [1.0, 1.0], z: None };
        assert!(r.contains([0.5, 1.0 + 1e-12]));
        assert!(!r.contains([0.5, 1.01]));
    }
}
