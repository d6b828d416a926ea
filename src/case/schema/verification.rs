//! `[verification]`: the check a run is compared against, chosen by its `kind`. The case file keeps
//! the table as written; the kinds, their parameters and their checks are the registry's in
//! [`crate::verification`], which builds on the model, and which validation asks.

use schemars::{json_schema, JsonSchema, Schema, SchemaGenerator};
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

/// The table `[verification]` as written: its `kind` and the kind's parameters, untyped.
#[derive(Debug, Clone, Deserialize, Serialize)]
pub struct VerificationTable {
    /// The check's kind (`terzaghi`, `lame`, ...).
    pub kind: String,
    /// The kind's parameters, every key of the table but `kind`.
    #[serde(flatten)]
    pub parameters: toml::Table,
}

impl VerificationTable {
    /// The whole table, `kind` included, as a TOML value (what the registry deserializes).
    pub fn as_value(&self) -> toml::Value {
        let mut table = self.parameters.clone();
        table.insert("kind".into(), toml::Value::String(self.kind.clone()));
        toml::Value::Table(table)
    }
}

/// The schema of a table with a string `kind` and any other keys, named `Verification`: the
/// case reference (tests/case_reference.rs) puts the registry's schema of every kind in its place.
impl JsonSchema for VerificationTable {
    fn schema_name() -> Cow<'static, str> {
        "Verification".into()
    }

    fn json_schema(_: &mut SchemaGenerator) -> Schema {
        json_schema!({
            "description": "The analytical reference of a case, chosen by its `kind`.",
            "type": "object",
            "properties": { "kind": { "type": "string" } },
            "required": ["kind"],
        })
    }
}
