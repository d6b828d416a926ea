//! Named parameters and arithmetic in case files.
//!
//! A case may define `[parameters]` (name = number). Any value written as a string that starts with
//! `=` is an expression evaluated with them before the case is typed, e.g.
//! `min = ["= crest_x - (lambda + 1) * B", 5.0]`. `--set parameters.lambda=2` changes a parameter
//! and with it every expression that uses it, so one case file covers a parametric study.
//!
//! Expressions: numbers, parameter names, `+ - * / ^`, parentheses, unary minus, and the functions
//! `sqrt`, `sin`, `cos`, `tan` (radians), `radians`, `degrees`, `min`, `max`, `abs`.

use toml::Value;

/// Replaces every `"= expr"` string in `doc` (outside `[parameters]`) by its value. Errors name
/// the key and the problem.
pub fn expand(doc: &mut Value) -> Result<(), String> {
    let params: Vec<(String, f64)> = match doc.get("parameters") {
        None => Vec::new(),
        Some(Value::Table(t)) => t
            .iter()
            .map(|(k, v)| match v {
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

/// Evaluates an arithmetic expression with the given parameters.
pub fn eval(text: &str, params: &[(String, f64)]) -> Result<f64, String> {
    let mut p = Parser { s: text.as_bytes(), i: 0, params };
    let v = p.sum()?;
    p.skip();
    if p.i != p.s.len() {
        return Err(format!("unexpected `{}`", &text[p.i..]));
    }
    if !v.is_finite() {
        return Err(format!("the value {v} is not finite"));
    }
    Ok(v)
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
    params: &'a [(String, f64)],
}

impl Parser<'_> {
    fn skip(&mut self) {
        while self.i < self.s.len() && self.s[self.i].is_ascii_whitespace() {
            self.i += 1;
        }
    }
    fn peek(&mut self) -> Option<u8> {
        self.skip();
        self.s.get(self.i).copied()
    }
    /// A left-associative chain `operand (op operand)*` of the two operators `ops`, `apply`
    /// combining the value so far with the next operand.
    fn chain(
        &mut self,
        ops: [u8; 2],
        operand: fn(&mut Self) -> Result<f64, String>,
        apply: fn(u8, f64, f64) -> f64,
    ) -> Result<f64, String> {
        let mut v = operand(self)?;
        while let Some(c) = self.peek().filter(|c| ops.contains(c)) {
            self.i += 1;
            v = apply(c, v, operand(self)?);
        }
        Ok(v)
    }
    fn sum(&mut self) -> Result<f64, String> {
        self.chain([b'+', b'-'], Self::product, |op, a, b| if op == b'+' { a + b } else { a - b })
    }
    fn product(&mut self) -> Result<f64, String> {
        self.chain([b'*', b'/'], Self::unary, |op, a, b| if op == b'*' { a * b } else { a / b })
    }
    /// `^` binds tighter than a unary sign on its left (−2^2 = −4) and is right-associative.
    fn power(&mut self) -> Result<f64, String> {
        let base = self.atom()?;
        if self.peek() == Some(b'^') {
            self.i += 1;
            let e = self.unary()?;
            return Ok(base.powf(e));
        }
        Ok(base)
    }
    fn unary(&mut self) -> Result<f64, String> {
        match self.peek() {
            Some(b'-') => {
                self.i += 1;
                Ok(-self.unary()?)
            }
            Some(b'+') => {
                self.i += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }
    fn atom(&mut self) -> Result<f64, String> {
        match self.peek() {
            Some(b'(') => {
                self.i += 1;
                let v = self.sum()?;
                if self.peek() != Some(b')') {
                    return Err("missing `)`".into());
                }
                self.i += 1;
                Ok(v)
            }
            Some(c) if c.is_ascii_digit() || c == b'.' => {
                let start = self.i;
                while self.i < self.s.len() {
                    let c = self.s[self.i];
                    let exp_sign = (c == b'+' || c == b'-') && matches!(self.s[self.i - 1], b'e' | b'E');
                    if c.is_ascii_digit() || c == b'.' || c == b'e' || c == b'E' || exp_sign {
                        self.i += 1;
                    } else {
                        break;
                    }
                }
                let t = std::str::from_utf8(&self.s[start..self.i]).unwrap_or("");
                t.parse().map_err(|_| format!("bad number `{t}`"))
            }
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {
                let start = self.i;
                while self.i < self.s.len() && (self.s[self.i].is_ascii_alphanumeric() || self.s[self.i] == b'_') {
                    self.i += 1;
                }
                let name = std::str::from_utf8(&self.s[start..self.i]).unwrap_or("");
                if self.peek() == Some(b'(') {
                    self.i += 1;
                    let mut args = vec![self.sum()?];
                    while self.peek() == Some(b',') {
                        self.i += 1;
                        args.push(self.sum()?);
                    }
                    if self.peek() != Some(b')') {
                        return Err(format!("missing `)` after the arguments of `{name}`"));
                    }
                    self.i += 1;
                    return call(name, &args);
                }
                self.params
                    .iter()
                    .find(|(n, _)| n == name)
                    .map(|(_, v)| *v)
                    .ok_or_else(|| format!("unknown parameter `{name}` (define it in [parameters])"))
            }
            Some(c) => Err(format!("unexpected `{}`", c as char)),
            None => Err("unexpected end".into()),
        }
    }
}

fn call(name: &str, a: &[f64]) -> Result<f64, String> {
    let one = |f: fn(f64) -> f64| {
        if a.len() == 1 {
            Ok(f(a[0]))
        } else {
            Err(format!("`{name}` takes one argument"))
        }
    };
    match name {
        "sqrt" => one(f64::sqrt),
        "sin" => one(f64::sin),
        "cos" => one(f64::cos),
        "tan" => one(f64::tan),
        "abs" => one(f64::abs),
        "radians" => one(f64::to_radians),
        "degrees" => one(f64::to_degrees),
        "min" | "max" if !a.is_empty() => {
            Ok(a.iter().copied().fold(if name == "min" { f64::INFINITY } else { f64::NEG_INFINITY }, |m, v| {
                if name == "min" {
                    m.min(v)
                } else {
                    m.max(v)
                }
            }))
        }
        _ => Err(format!("unknown function `{name}`")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expressions_follow_the_usual_precedence() {
        let p = vec![("lambda".to_string(), 2.0), ("B".to_string(), 1.0)];
        assert_eq!(eval("13 - (lambda + 1) * B", &p).unwrap(), 10.0);
        assert_eq!(eval("-2^2", &p).unwrap(), -4.0);
        assert_eq!(eval("2^3^2", &p).unwrap(), 512.0);
        assert_eq!(eval("1.5e-3 * 2", &p).unwrap(), 3e-3);
        assert_eq!(eval("max(1, lambda, 0.5) + min(3, 4)", &p).unwrap(), 5.0);
        assert!((eval("tan(radians(45))", &p).unwrap() - 1.0).abs() < 1e-15);
        assert!(eval("lambda +", &p).is_err());
        assert!(eval("mu * 2", &p).unwrap_err().contains("unknown parameter `mu`"));
        assert!(eval("1 / 0", &p).is_err());
    }

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
        let mut bad: Value = toml::from_str("[grid]\nsize = [\"= w\", 1.0]\n").unwrap();
        let e = expand(&mut bad).unwrap_err();
        assert!(e.contains("grid.size[0]") && e.contains("unknown parameter `w`"), "{e}");
    }
}
