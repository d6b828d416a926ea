//! `--set KEY=VALUE` overrides applied to the parsed TOML document before it is typed.
//!
//! KEY is a dotted path (`time.dt`, `grid.cells`, `materials[0].porosity`); an array of tables may
//! also be indexed by the `name` of an element (`materials.soil.porosity`). VALUE is a TOML value
//! (`5e-4`, `[20, 1]`, `true`, `"linear"`); a bare word that is not valid TOML is taken as a string.

use super::CaseError;
use toml::Value;

/// One override from the command line.
#[derive(Debug, Clone, PartialEq)]
pub struct Override {
    /// The key as the user wrote it.
    pub key: String,
    /// The parsed value.
    pub value: Value,
}

impl Override {
    /// Parses `KEY=VALUE`.
    pub fn parse(s: &str) -> Result<Override, CaseError> {
        let (k, v) = s.split_once('=').ok_or_else(|| CaseError::new(format!("--set {s}: expected KEY=VALUE")))?;
        let key = k.trim();
        if key.is_empty() {
            return Err(CaseError::new(format!("--set {s}: empty key")));
        }
        let raw = v.trim();
        let value = match toml::from_str::<toml::Table>(&format!("v = {raw}")) {
            Ok(mut t) => t.remove("v").unwrap_or(Value::String(raw.to_string())),
            Err(_) => Value::String(raw.to_string()),
        };
        Ok(Override { key: key.to_string(), value })
    }
}

enum Segment {
    Key(String),
    Index(usize),
}

fn segments(key: &str) -> Result<Vec<Segment>, String> {
    let mut out = Vec::new();
    for part in key.split('.') {
        if part.is_empty() {
            return Err("empty path segment".into());
        }
        let mut rest = part;
        if let Some(b) = rest.find('[') {
            let name = &rest[..b];
            if !name.is_empty() {
                out.push(Segment::Key(name.to_string()));
            }
            rest = &rest[b..];
            while let Some(stripped) = rest.strip_prefix('[') {
                let close = stripped.find(']').ok_or("unclosed `[`")?;
                let idx: usize =
                    stripped[..close].parse().map_err(|_| format!("bad index `{}`", &stripped[..close]))?;
                out.push(Segment::Index(idx));
                rest = &stripped[close + 1..];
            }
            if !rest.is_empty() {
                return Err(format!("unexpected `{rest}` after index"));
            }
        } else if let Ok(i) = part.parse::<usize>() {
            out.push(Segment::Index(i));
        } else {
            out.push(Segment::Key(part.to_string()));
        }
    }
    Ok(out)
}

/// Applies one override to the document and returns the path in index form
/// (`materials[0].porosity`), which is how deserialisation errors name keys.
pub fn apply(doc: &mut Value, ov: &Override) -> Result<String, CaseError> {
    let err = |m: String| CaseError::new(format!("--set {}: {m}", ov.key));
    let segs = segments(&ov.key).map_err(err)?;
    if let [Segment::Key(table), Segment::Key(name)] = &segs[..] {
        // `[parameters]` is free-form: a name it does not declare would be set and never read.
        let declared = doc.get("parameters").and_then(Value::as_table);
        if table == "parameters" && !declared.is_some_and(|t| t.contains_key(name)) {
            let names: Vec<&str> = declared.map(|t| t.keys().map(String::as_str).collect()).unwrap_or_default();
            return Err(err(match names.is_empty() {
                true => format!("the case declares no parameters, so none named `{name}`"),
                false => format!("the case declares no parameter `{name}` (it declares: {})", names.join(", ")),
            }));
        }
    }
    let mut path = String::new();
    let mut cur = doc;
    for (k, seg) in segs.iter().enumerate() {
        let last = k + 1 == segs.len();
        match seg {
            Segment::Key(name) => {
                match cur {
                    Value::Table(t) => {
                        if !path.is_empty() {
                            path.push('.');
                        }
                        path.push_str(name);
                        if last {
                            t.insert(name.clone(), ov.value.clone());
                            return Ok(path);
                        }
                        cur = t.entry(name.clone()).or_insert_with(|| Value::Table(toml::Table::new()));
                    }
                    Value::Array(a) => {
                        // Select an element of an array of tables by its `name`.
                        let idx = a
                            .iter()
                            .position(|e| e.get("name").and_then(|n| n.as_str()) == Some(name.as_str()))
                            .ok_or_else(|| err(format!("no element named `{name}` in `{path}`")))?;
                        path.push_str(&format!("[{idx}]"));
                        if last {
                            a[idx] = ov.value.clone();
                            return Ok(path);
                        }
                        cur = &mut a[idx];
                    }
                    _ => return Err(err(format!("`{path}` is a value, it has no key `{name}`"))),
                }
            }
            Segment::Index(i) => match cur {
                Value::Array(a) => {
                    if *i >= a.len() {
                        return Err(err(format!("index {i} out of range: `{path}` has {} elements", a.len())));
                    }
                    path.push_str(&format!("[{i}]"));
                    if last {
                        a[*i] = ov.value.clone();
                        return Ok(path);
                    }
                    cur = &mut a[*i];
                }
                _ => return Err(err(format!("`{path}` is not an array"))),
            },
        }
    }
    Err(err("empty key".into()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc() -> Value {
        toml::from_str::<Value>(
            r#"
            [grid]
            cells = [1, 10]
            [[materials]]
            name = "soil"
            porosity = 0.3
            [[materials]]
            name = "rock"
            porosity = 0.1
        "#,
        )
        .unwrap()
    }

    #[test]
    fn values_parse_as_toml_or_fall_back_to_strings() {
        assert_eq!(Override::parse("time.dt=5e-4").unwrap().value, Value::Float(5e-4));
        assert_eq!(
            Override::parse("grid.cells=[20,1]").unwrap().value,
            Value::Array(vec![Value::Integer(20), Value::Integer(1)])
        );
        assert_eq!(Override::parse("analysis.shape_functions=linear").unwrap().value, Value::String("linear".into()));
        assert!(Override::parse("no_equals_sign").is_err());
    }

    #[test]
    fn paths_by_key_index_and_name() {
        let mut d = doc();
        let p = apply(&mut d, &Override::parse("grid.cells=[2,20]").unwrap()).unwrap();
        assert_eq!(p, "grid.cells");
        assert_eq!(d["grid"]["cells"][1].as_integer(), Some(20));
        let p = apply(&mut d, &Override::parse("materials[1].porosity=0.2").unwrap()).unwrap();
        assert_eq!(p, "materials[1].porosity");
        assert_eq!(d["materials"][1]["porosity"].as_float(), Some(0.2));
        let p = apply(&mut d, &Override::parse("materials.soil.porosity=0.4").unwrap()).unwrap();
        assert_eq!(p, "materials[0].porosity");
        assert_eq!(d["materials"][0]["porosity"].as_float(), Some(0.4));
        // A missing table is created (its key may be optional in the schema).
        let p = apply(&mut d, &Override::parse("time_integration.beta=0.3").unwrap()).unwrap();
        assert_eq!(p, "time_integration.beta");
    }

    #[test]
    fn bad_paths_name_the_key() {
        let mut d = doc();
        let e = apply(&mut d, &Override::parse("materials.clay.porosity=0.4").unwrap()).unwrap_err();
        assert!(e.to_string().contains("no element named `clay`"), "{e}");
        let e = apply(&mut d, &Override::parse("materials[5].porosity=0.4").unwrap()).unwrap_err();
        assert!(e.to_string().contains("out of range"), "{e}");
        let e = apply(&mut d, &Override::parse("grid.cells.x=3").unwrap()).unwrap_err();
        assert!(e.to_string().starts_with("--set grid.cells.x"), "{e}");
    }

    #[test]
    fn only_declared_parameters_can_be_set() {
        let mut d = doc();
        let e = apply(&mut d, &Override::parse("parameters.h=0.5").unwrap()).unwrap_err();
        assert!(e.to_string().contains("declares no parameters, so none named `h`"), "{e}");
        d.as_table_mut().unwrap().insert("parameters".into(), toml::from_str::<Value>("h = 1.0\nb = 2.0").unwrap());
        assert_eq!(apply(&mut d, &Override::parse("parameters.h=0.5").unwrap()).unwrap(), "parameters.h");
        let e = apply(&mut d, &Override::parse("parameters.H=0.5").unwrap()).unwrap_err();
        assert!(e.to_string().contains("no parameter `H` (it declares: b, h)"), "{e}");
    }
}
