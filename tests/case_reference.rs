//! docs/case_reference.md, the user's reference of every table and key of a case file, is the
//! case schema's doc comments rendered: its JSON Schema (`schemars`, which reads the doc comments
//! and follows the serde attributes: tags, defaults, optional keys) turned into tables of key,
//! type, default and meaning, in the order the keys are declared in src/case/schema/ and, for the
//! soil models' parameters, src/soils/. The case file keeps `[verification]` untyped; its kinds
//! and keys are the schema of the checks' registry (`porompm::verification::Verification`, the
//! parameters declared in src/verification/), put in its place ([`schema`]).
//!
//! The test fails, naming the first line that differs, when the file is not what the schema says;
//! `PORO_DOC_REFRESH=1 cargo test --release --test case_reference` rewrites it.

use serde_json::{Map, Value};
use std::collections::{BTreeMap, HashSet};
use std::fmt::Write;

const REFERENCE: &str = "docs/case_reference.md";

const HEADER: &str = "# Case file reference

<!-- Generated from the doc comments of src/case/schema/, src/soils/ and src/verification/ by
tests/case_reference.rs; do not edit by hand. After changing the schema, rewrite it with
`PORO_DOC_REFRESH=1 cargo test --release --test case_reference`. -->

A case is a TOML file with the tables below (`cases/` holds examples). Units are SI: m, s, kg, Pa,
m/s; an angle is in degrees where its key says so. Each table refuses a key it does not know, and
every message names the key. A number may be written `\"= expression\"` in terms of the
`[parameters]`, and `porompm run --set KEY=VALUE` (`time.dt=5e-4`, `materials.soil.porosity=0.3`)
changes any key before the file is checked. `porompm check CASE` shows what a case builds, or
the first thing wrong with it.

In the tables, *required* keys must be given; the others take the default shown (— means none:
the feature is off, or the text says what happens without it). Where a table is chosen by a tag
(`type` or `kind`), each choice lists its own keys beside the tag.
";

#[test]
fn the_case_reference_is_the_schema_s_doc_comments() {
    let schema = schema();
    let text = Reference::new(&schema).render();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(REFERENCE);
    if std::env::var_os("PORO_DOC_REFRESH").is_some() {
        std::fs::write(&path, &text).unwrap();
        return;
    }
    let file = std::fs::read_to_string(&path).unwrap_or_default();
    if let Some((i, (want, got))) = text.lines().zip(file.lines()).enumerate().find(|(_, (a, b))| a != b) {
        panic!(
            "{REFERENCE} line {} is not what the schema says:\n  file:   {got}\n  schema: {want}\n\
             rewrite it with PORO_DOC_REFRESH=1 cargo test --release --test case_reference",
            i + 1
        );
    }
    assert_eq!(
        text.lines().count(),
        file.lines().count(),
        "{REFERENCE} has another length than the schema's reference; rewrite it with PORO_DOC_REFRESH=1"
    );
}

/// Every table of the schema is in the reference, and every key of a table that the reference
/// lists is a key of the schema: the rendering drops nothing.
#[test]
fn the_reference_shows_every_table_and_key() {
    let schema = schema();
    let text = Reference::new(&schema).render();
    for (name, def) in schema["$defs"].as_object().unwrap() {
        for key in def["properties"].as_object().into_iter().flat_map(|p| p.keys()) {
            assert!(text.contains(&format!("| `{key}` |")), "the key `{key}` of {name} is missing");
        }
    }
    for (_, variant) in tagged_variants(&schema) {
        assert!(text.contains(&format!("= \"{variant}\"`")), "the variant `{variant}` is missing");
    }
    for needle in ["| `young_modulus` | number | required | Young's modulus E [Pa], in (0, 1e13]. |", "`[[stages]]`"] {
        assert!(text.contains(needle), "the reference does not say: {needle}");
    }
}

/// Every number a case gives says its unit in brackets (`[Pa]`, `[m/s]`, `[-]` for a ratio or a
/// count), in the doc comment the reference shows.
#[test]
fn every_number_has_its_unit() {
    let schema = schema();
    let mut tables: Vec<(String, &Value)> = vec![("the top level".into(), &schema)];
    for (name, def) in schema["$defs"].as_object().unwrap() {
        tables.push((name.clone(), def));
        tables.extend(def["oneOf"].as_array().into_iter().flatten().map(|v| (name.clone(), v)));
    }
    for (table, def) in tables {
        for (key, p) in def["properties"].as_object().into_iter().flatten() {
            let numeric = |t: &Value| matches!(type_name(t), "number" | "integer");
            if numeric(p) || (type_name(p) == "array" && numeric(&p["items"])) {
                let doc = p["description"].as_str().unwrap_or("");
                assert!(doc.contains('['), "the doc comment of {table}'s `{key}` gives no unit: {doc}");
            }
        }
    }
}

/// The case file's JSON Schema with the schema of the checks' registry, every kind with its keys,
/// as the definition `Verification` in place of the untyped table `[verification]` the case file
/// keeps (`VerificationTable`, whose schema takes that name). The registry's own definitions (the
/// tables its kinds name) join the case file's, whose names they must not take.
fn schema() -> Value {
    let mut root = serde_json::to_value(schemars::schema_for!(porompm::case::CaseFile)).unwrap();
    let mut checks = serde_json::to_value(schemars::schema_for!(porompm::verification::Verification)).unwrap();
    let checks_table = checks.as_object_mut().unwrap();
    let named = checks_table.remove("$defs").unwrap_or_default();
    checks_table.remove("$schema");
    checks_table.remove("title");
    let defs = root["$defs"].as_object_mut().unwrap();
    assert!(defs.contains_key("Verification"), "the case file's schema has no `Verification` table to replace");
    for (name, def) in named.as_object().into_iter().flatten() {
        assert!(
            defs.insert(name.clone(), def.clone()).is_none(),
            "the table `{name}` is the case file's and a check's"
        );
    }
    defs.insert("Verification".into(), checks);
    root
}

/// The tags of the tagged tables (`type = "mohr_coulomb"`, `kind = "terzaghi"`, ...).
fn tagged_variants(schema: &Value) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for def in schema["$defs"].as_object().unwrap().values() {
        for v in def["oneOf"].as_array().into_iter().flatten() {
            for (key, p) in v["properties"].as_object().into_iter().flatten() {
                if let Some(c) = p["const"].as_str() {
                    out.push((key.clone(), c.to_string()));
                }
            }
        }
    }
    out
}

/// The reference being written: the schema's definitions, the order of each struct's keys in the
/// sources, and the sections still to write.
struct Reference<'a> {
    defs: &'a Map<String, Value>,
    order: BTreeMap<String, Vec<String>>,
    variants: BTreeMap<String, String>,
    queue: Vec<(String, bool)>,
    /// Every key path at which each table is used (`Region`: `boundaries.region`, ...), complete
    /// after a first walk.
    paths: BTreeMap<String, Vec<String>>,
    /// The paths of the first walk, which title the sections of the second.
    known: BTreeMap<String, Vec<String>>,
}

impl<'a> Reference<'a> {
    fn new(schema: &'a Value) -> Self {
        let (order, variants) = declaration_order();
        Reference {
            defs: schema["$defs"].as_object().unwrap(),
            order,
            variants,
            queue: Vec::new(),
            paths: BTreeMap::new(),
            known: BTreeMap::new(),
        }
    }

    /// The file: a first walk finds every path at which a table is used, the second writes each
    /// table's section with them.
    fn render(mut self) -> String {
        self.walk();
        self.queue.clear();
        self.known = std::mem::take(&mut self.paths);
        self.walk()
    }

    /// The whole file: the top level, then every table after the one that first names it.
    fn walk(&mut self) -> String {
        let mut out = String::from(HEADER);
        let root = schema();
        out += "\n<a id=\"top-level\"></a>\n\n## The top level\n\n";
        out += &self.table(&root, "CaseFile", "");
        let mut i = 0;
        while i < self.queue.len() {
            let before = self.queue.len();
            let (name, array) = self.queue[i].clone();
            out += &self.section(&name, array);
            // The tables this one names come right after it.
            let named: Vec<_> = self.queue.drain(before..).collect();
            self.queue.splice(i + 1..i + 1, named);
            i += 1;
        }
        out
    }

    /// The section of definition `name` (an array of such tables if `array`), titled by the keys
    /// that use it.
    fn section(&mut self, name: &str, array: bool) -> String {
        let def = &self.defs[name];
        let paths = self.known.get(name).unwrap_or(&self.paths[name]).clone();
        let titles: Vec<String> = paths.iter().map(|p| title(p, array)).collect();
        let path = paths[0].clone();
        let mut out = format!("\n<a id=\"{}\"></a>\n\n## {}\n\n", anchor(name), titles.join(", "));
        if let Some(d) = def["description"].as_str() {
            let _ = writeln!(out, "{}\n", prose(d));
        }
        match def["oneOf"].as_array() {
            Some(variants) if variants.iter().all(|v| v["type"] == "object") => {
                for v in variants {
                    out += &self.variant(v, name, &path);
                }
                out = out.trim_end().to_string() + "\n";
            }
            _ => out += &self.table(def, name, &path),
        }
        out
    }

    /// One choice of a tagged table (`type = "..."`) or of a shape (`{ rectangle = ... }`).
    fn variant(&mut self, v: &Value, name: &str, path: &str) -> String {
        let props = v["properties"].as_object().unwrap();
        let tag = props.iter().find_map(|(k, p)| p["const"].as_str().map(|c| (k.clone(), c.to_string())));
        let mut out = String::new();
        match tag {
            Some((key, value)) => {
                let _ = writeln!(out, "### `{path}` with `{key} = \"{value}\"`\n");
                if let Some(d) = v["description"].as_str() {
                    let _ = writeln!(out, "{}\n", prose(d));
                }
                let owner = self.variants.get(&format!("{name}::{value}")).cloned().unwrap_or_default();
                out += &self.table(v, &owner, path);
                out += "\n";
            }
            None => {
                // An externally tagged choice: one key naming a table.
                let (key, inner) = props.iter().next().unwrap();
                let target = self.link(inner, &format!("{path}.{key}"));
                let d = v["description"].as_str().map(prose).unwrap_or_default();
                let keys = target.trim_start_matches("table, ");
                let _ = writeln!(out, "- `{{ {key} = {{ ... }} }}`: {d} For its keys {keys}.");
            }
        }
        out
    }

    /// The table of an object's keys (`owner` the struct whose declaration orders them; `path`
    /// where the table stands).
    fn table(&mut self, def: &Value, owner: &str, path: &str) -> String {
        let Some(props) = def["properties"].as_object() else {
            return String::new();
        };
        let required: HashSet<&str> =
            def["required"].as_array().into_iter().flatten().filter_map(Value::as_str).collect();
        let mut keys: Vec<&String> = props.keys().filter(|k| props[*k]["const"].is_null()).collect();
        let order = self.order.get(owner).cloned().unwrap_or_default();
        keys.sort_by_key(|k| (order.iter().position(|o| o == *k).unwrap_or(usize::MAX), k.to_string()));
        let mut out = String::from("| key | type | default | meaning |\n|---|---|---|---|\n");
        for key in keys {
            let p = &props[key];
            let at = if path.is_empty() { key.clone() } else { format!("{path}.{key}") };
            let ty = self.type_of(p, &at);
            let default = if required.contains(key.as_str()) { "required".to_string() } else { default_of(p) };
            let meaning = p["description"].as_str().map(prose).unwrap_or_default();
            let _ = writeln!(out, "| `{key}` | {ty} | {default} | {} |", meaning.replace('|', "\\|"));
        }
        out
    }

    /// A key's type in words, queueing the section of a table it names.
    fn type_of(&mut self, p: &Value, at: &str) -> String {
        if let Some(any) = p["anyOf"].as_array() {
            let kinds: Vec<String> = any.iter().filter(|a| a["type"] != "null").map(|a| self.type_of(a, at)).collect();
            return kinds.join(" or ");
        }
        if p["$ref"].is_string() {
            return self.link(p, at);
        }
        match type_name(p) {
            "array" => {
                let item = self.type_of(&p["items"], &format!("{at}[]"));
                match (p["minItems"].as_u64(), p["maxItems"].as_u64()) {
                    (Some(n), Some(m)) if n == m => format!("[{}]", vec![item; n as usize].join(", ")),
                    _ if item.starts_with("tables") => item,
                    _ => format!("array of {item}"),
                }
            }
            "object" => format!("table of {}s", self.type_of(&p["additionalProperties"], at)),
            "string" => match p["const"].as_str() {
                Some(c) => format!("`\"{c}\"`"),
                None => "string".into(),
            },
            other => other.into(),
        }
    }

    /// A reference to a definition: the values of a word list, or a link to a table's section
    /// (queued at its first use, at key `at`).
    fn link(&mut self, p: &Value, at: &str) -> String {
        let name = p["$ref"].as_str().unwrap().trim_start_matches("#/$defs/").to_string();
        let def = &self.defs[&name];
        if let Some(words) = word_list(def) {
            return words;
        }
        if def["anyOf"].is_array() {
            return self.type_of(def, at);
        }
        let path = at.trim_end_matches("[]").to_string();
        let seen = self.paths.entry(name.clone()).or_default();
        if !seen.contains(&path) {
            seen.push(path.clone());
        }
        if !self.queue.iter().any(|(n, _)| *n == name) {
            self.queue.push((name.clone(), at.ends_with("[]")));
        }
        let tag = def["oneOf"]
            .as_array()
            .and_then(|v| v.first())
            .and_then(|v| v["properties"].as_object())
            .and_then(|p| p.iter().find(|(_, x)| x["const"].is_string()).map(|(k, _)| k.clone()));
        let array = at.ends_with("[]");
        let what = match (tag, array) {
            (Some(t), true) => format!("tables, each chosen by `{t}`,"),
            (Some(t), false) => format!("table chosen by `{t}`,"),
            (None, true) => "tables,".into(),
            (None, false) => "table,".into(),
        };
        format!("{what} see [{}](#{})", title(&path, array), anchor(&name))
    }
}

/// How a table at key `path` is written: `[analysis]`, `[[materials]]` at the top level, a
/// dotted key below it (`materials.model`).
fn title(path: &str, array: bool) -> String {
    match (path.contains('.'), array) {
        (false, true) => format!("`[[{path}]]`"),
        (false, false) => format!("`[{path}]`"),
        (true, _) => format!("`{path}`"),
    }
}

/// The anchor of a table's section.
fn anchor(name: &str) -> String {
    name.to_lowercase()
}

/// The JSON type of a schema, `null` aside.
fn type_name(p: &Value) -> &str {
    match &p["type"] {
        Value::String(s) => s,
        Value::Array(a) => a.iter().filter_map(Value::as_str).find(|t| *t != "null").unwrap_or("any"),
        _ => "any",
    }
}

/// The values of an enumeration of words (`"gimp"`, `"linear"`, ...), if `def` is one.
fn word_list(def: &Value) -> Option<String> {
    let variants = def["oneOf"].as_array().or(def["enum"].as_array())?;
    let words: Option<Vec<String>> = variants
        .iter()
        .map(|v| v.as_str().or(v["const"].as_str()).filter(|_| v["type"] != "object").map(|w| format!("`\"{w}\"`")))
        .collect();
    words.map(|w| w.join(", "))
}

/// A default value as the case file would write it; — where the key has none.
fn default_of(p: &Value) -> String {
    match &p["default"] {
        Value::Null => "—".into(),
        Value::Object(o) if o.is_empty() => "empty".into(),
        Value::Array(a) if a.is_empty() => "`[]`".into(),
        Value::Object(_) => "per key".into(),
        v => format!("`{}`", v.to_string().replace(',', ", ")),
    }
}

/// A doc comment as one paragraph of markdown: its lines joined, intra-doc links (`[`x`]`) as
/// plain code.
fn prose(doc: &str) -> String {
    let joined = doc.split('\n').map(str::trim).collect::<Vec<_>>().join(" ");
    let mut out = String::new();
    let mut rest = joined.as_str();
    while let Some(start) = rest.find("[`") {
        let Some(end) = rest[start..].find("`]") else { break };
        out += &rest[..start];
        out += &rest[start + 1..start + end + 1];
        rest = &rest[start + end + 2..];
    }
    out + rest
}

/// The declaration order of each struct's fields in src/case/schema/, src/soils/ (the soil
/// models' parameters) and src/verification/ (the checks' parameters), and the struct of each
/// tagged variant (`SoilModel::mohr_coulomb` → `MohrCoulomb`, from the enum's declaration or the
/// lines `Variant(module::Type) = "tag",` of the registries `soil_models!` and
/// `verification_kinds!`). A newtype
/// (`pub struct LinearElasticParameters(pub Elasticity);`, serde-transparent) takes the order of
/// the struct it wraps.
fn declaration_order() -> (BTreeMap<String, Vec<String>>, BTreeMap<String, String>) {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let (mut order, mut variants) = (BTreeMap::new(), BTreeMap::new());
    let mut newtypes = Vec::new();
    for dir in ["src/case/schema", "src/soils", "src/verification"] {
        for entry in std::fs::read_dir(root.join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            read_declarations(&std::fs::read_to_string(path).unwrap(), &mut order, &mut variants, &mut newtypes);
        }
    }
    for (name, inner) in newtypes {
        if let Some(fields) = order.get(&inner).cloned() {
            order.insert(name, fields);
        }
    }
    (order, variants)
}

/// The fields of each struct of one source file (into `order`), the struct of each tagged
/// variant (into `variants`) and the newtypes with the struct they wrap (into `newtypes`).
fn read_declarations(
    text: &str,
    order: &mut BTreeMap<String, Vec<String>>,
    variants: &mut BTreeMap<String, String>,
    newtypes: &mut Vec<(String, String)>,
) {
    let mut current: Option<(bool, String)> = None;
    for line in text.lines() {
        let t = line.trim();
        if t == "soil_models! {" {
            current = Some((false, "SoilModel".to_string()));
        } else if t == "verification_kinds! {" {
            current = Some((false, "Verification".to_string()));
        } else if let Some(rest) = t.strip_prefix("pub struct ").or(t.strip_prefix("pub enum ")) {
            let name = rest.split([' ', '{', '<', '(']).next().unwrap().to_string();
            if let Some(inner) = rest.strip_prefix(&format!("{name}(pub ")).and_then(|r| r.strip_suffix(");")) {
                newtypes.push((name, inner.to_string()));
                current = None;
            } else {
                current = Some((t.starts_with("pub struct"), name));
            }
        } else if t == "}" && !line.starts_with(' ') {
            current = None;
        } else if let Some((is_struct, name)) = &current {
            if *is_struct {
                if let Some(field) = t.strip_prefix("pub ").and_then(|f| f.split(':').next()) {
                    order.entry(name.clone()).or_default().push(field.to_string());
                }
            } else if let Some((variant, ty)) = t.strip_suffix("),").and_then(|v| v.split_once('(')) {
                variants.insert(format!("{name}::{}", snake(variant)), ty.to_string());
            } else if let Some((declared, tag)) = t.strip_suffix("\",").and_then(|v| v.split_once(") = \"")) {
                // A registry line: `Variant(module::Type) = "tag",`.
                let ty = declared.split_once('(').map_or("", |(_, ty)| ty).rsplit("::").next().unwrap();
                variants.insert(format!("{name}::{tag}"), ty.to_string());
            }
        }
    }
}

/// `HenckyJ2` → `hencky_j2`, as serde's `rename_all = "snake_case"`.
fn snake(name: &str) -> String {
    let mut out = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_uppercase() && i > 0 {
            out.push('_');
        }
        out.extend(c.to_lowercase());
    }
    out
}
