//! Named parameters and arithmetic in case files.
//!
//! A case may define `[parameters]` (name = number). Any value written as a string that starts with
//! `=` is an expression evaluated with them before the case is typed, e.g.
//! `min = ["= crest_x - (lambda + 1) * B", 5.0]`. `--set parameters.lambda=2` changes a parameter
//! and with it every expression that uses it, so one case file covers a parametric study.
//!
//! Expressions: numbers, parameter names, `+ - * / ^`, parentheses, unary minus, `pi` and the
//! functions of [`super::expression`] (`sqrt`, `exp`, `ln`, `sin`, `cos`, `tan`, `atan`, `atan2`,
//! `radians`, `degrees`, `abs`, `min`, `max`). The names `x`, `y` and `z` are a point's position in
//! the keys that take a field of position (written without the leading `=`), and no parameter's.

use super::expression::{Expr, COORDINATES};
use toml::Value;

/// Replaces every `"= expr"` string in `doc` (outside `[parameters]`) by its value. Errors name
/// the key and the problem.
pub fn expand(doc: &mut Value) -> Result<(), String> {
    let params: Vec<(String, f64)> = match doc.get("parameters") {
        None => Vec::new(),
        Some(Value::Table(t)) => t
            .iter()
            .map(|(k, v)| match v {
                _ if COORDINATES.contains(&k.as_str()) => Err(format!(
                    "key `parameters.{k}`: `{k}` names a point's position in the expressions of fields; give the \
                     parameter another name"
                )),
                Value::Float(f) => Ok((k.clone(), *f)),
                Value::Integer(i) => Ok((k.clone(), *i as f64)),
                _ => Err(format!("key `parameters.{k}`: must be a number")),
            })
            .collect::<Result<_, _>>()?,
        Some(_) => return Err("key `parameters`: must be a table of numbers".into()),
    };
    let Value::Table(t) = doc else { return Ok(()) };
    for (k, v) in t.iter_mut() {
        if k != "parameters" {
            walk(v, k, &params)?;
        }
    }
    Ok(())
}

fn walk(v: &mut Value, path: &str, params: &[(String, f64)]) -> Result<(), String> {
    match v {
        Value::String(s) => {
            if let Some(expr) = s.trim_start().strip_prefix('=') {
                let x = eval(expr, params).map_err(|e| format!("key `{path}`: expression `{}`: {e}", expr.trim()))?;
                // An integral value may fill an integer key (e.g. a number of cells); float keys take
                // integers too.
                *v = if x.fract() == 0.0 && x.abs() < 9.0e15 { Value::Integer(x as i64) } else { Value::Float(x) };
            }
        }
        Value::Array(a) => {
            for (i, e) in a.iter_mut().enumerate() {
                walk(e, &format!("{path}[{i}]"), params)?;
            }
        }
        Value::Table(t) => {
            for (k, e) in t.iter_mut() {
                walk(e, &format!("{path}.{k}"), params)?;
            }
        }
        _ => {}
    }
    Ok(())
}

/// Evaluates an arithmetic expression ([`super::expression`]) with the given parameters; a value
/// that is not finite is an error.
pub fn eval(text: &str, params: &[(String, f64)]) -> Result<f64, String> {
    eval_at(text, params, &[])
}

/// [`eval`] with the position `at` = (x, y) or (x, y, z) [m] for the coordinates' names.
pub fn eval_at(text: &str, params: &[(String, f64)], at: &[f64]) -> Result<f64, String> {
    let v = Expr::parse(text, &COORDINATES[..at.len()], params)?.eval(at);
    if !v.is_finite() {
        return Err(format!("the value {v} is not finite"));
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strings_starting_with_equals_are_replaced_everywhere_but_in_parameters() {
        let mut doc: Value = toml::from_str(
            r#"
            [parameters]
            w = 4.0
            [grid]
            size = ["= 2 * w", "= w / 3"]
            name = "plain"
            "#,
        )
        .unwrap();
        expand(&mut doc).unwrap();
        // An integral value becomes an integer (so that it may fill an integer key), others floats.
        assert_eq!(doc["grid"]["size"][0].as_integer(), Some(8));
        assert_eq!(doc["grid"]["size"][1].as_float(), Some(4.0 / 3.0));
        assert_eq!(doc["grid"]["name"].as_str(), Some("plain"));
        // A position has no value when the case is read; no parameter takes a coordinate's name.
        let mut pos: Value = toml::from_str("[grid]\nsize = [\"= 2 * y\", 1.0]\n").unwrap();
        let e = expand(&mut pos).unwrap_err();
        assert!(e.contains("grid.size[0]") && e.contains("`y` is a position"), "{e}");
        let mut named: Value = toml::from_str("[parameters]\nx = 1.0\n").unwrap();
        assert!(expand(&mut named).unwrap_err().contains("key `parameters.x`: `x` names a point's position"));
        let mut bad: Value = toml::from_str("[grid]\nsize = [\"= w\", 1.0]\n").unwrap();
        let e = expand(&mut bad).unwrap_err();
        assert!(e.contains("grid.size[0]") && e.contains("unknown parameter `w`"), "{e}");
    }
}
