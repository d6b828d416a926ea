//! Arithmetic expressions of case files, parsed once into a tree and evaluated many times.
//!
//! An expression has numbers, names, `+ - * / ^` (`^` right-associative and binding tighter than a
//! unary sign on its left: −2^2 = −4), parentheses, the constant `pi` and the functions `sqrt`,
//! `exp`, `ln` (natural logarithm), `sin`, `cos`, `tan` (radians), `atan`, `atan2(y, x)`,
//! `radians`, `degrees`, `abs`, `min` and `max` (one argument or more). A name is one of the
//! expression's variables (a point's position `x`, `y`, `z` where the key takes a field of
//! position), else one of the case's `[parameters]`, else `pi`. [`Expr::gradient`] evaluates
//! the value and its exact derivatives with respect to the variables (forward-mode
//! differentiation), which the initial pore pressure's gradient takes.

/// The names of a point's coordinates in the expressions of fields of position.
pub const COORDINATES: [&str; 3] = ["x", "y", "z"];

/// A parsed expression.
#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    node: Node,
    /// How many variables it was parsed with (the length [`Expr::eval`] takes).
    vars: usize,
}

#[derive(Debug, Clone, PartialEq)]
enum Node {
    Number(f64),
    /// The variable of that index.
    Var(usize),
    Neg(Box<Node>),
    Binary(Op, Box<Node>, Box<Node>),
    Call(Func, Vec<Node>),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Op {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Func {
    Sqrt,
    Exp,
    Ln,
    Sin,
    Cos,
    Tan,
    Atan,
    Atan2,
    Radians,
    Degrees,
    Abs,
    Min,
    Max,
}

/// The functions by name, with the number of arguments each takes (`None`: one or more).
const FUNCTIONS: [(&str, Func, Option<usize>); 13] = [
    ("sqrt", Func::Sqrt, Some(1)),
    ("exp", Func::Exp, Some(1)),
    ("ln", Func::Ln, Some(1)),
    ("sin", Func::Sin, Some(1)),
    ("cos", Func::Cos, Some(1)),
    ("tan", Func::Tan, Some(1)),
    ("atan", Func::Atan, Some(1)),
    ("atan2", Func::Atan2, Some(2)),
    ("radians", Func::Radians, Some(1)),
    ("degrees", Func::Degrees, Some(1)),
    ("abs", Func::Abs, Some(1)),
    ("min", Func::Min, None),
    ("max", Func::Max, None),
];

/// A value and its derivatives with respect to up to three variables.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Dual {
    v: f64,
    d: [f64; 3],
}

impl Dual {
    fn constant(v: f64) -> Dual {
        Dual { v, d: [0.0; 3] }
    }
    /// f(v) with the derivative f'(v) applied to the derivatives by the chain rule; a derivative
    /// that is zero stays zero where f' is infinite (√ at 0, a constant argument).
    fn chain(self, v: f64, slope: f64) -> Dual {
        Dual { v, d: self.d.map(|d| if d == 0.0 { 0.0 } else { slope * d }) }
    }
    fn combine(a: Dual, b: Dual, v: f64, da: f64, db: f64) -> Dual {
        let term = |s: f64, d: f64| if d == 0.0 { 0.0 } else { s * d };
        Dual { v, d: std::array::from_fn(|i| term(da, a.d[i]) + term(db, b.d[i])) }
    }
}

impl Expr {
    /// Parses `text` with the named variables `vars` (at most three) and the case's `params`;
    /// errors say what is wrong and where.
    pub fn parse(text: &str, vars: &[&str], params: &[(String, f64)]) -> Result<Expr, String> {
        debug_assert!(vars.len() <= 3);
        let mut p = Parser { s: text.as_bytes(), i: 0, vars, params };
        let node = p.sum()?;
        p.skip();
        if p.i != p.s.len() {
            return Err(format!("unexpected `{}`", &text[p.i..]));
        }
        Ok(Expr { node, vars: vars.len() })
    }

    /// The constant `v`, an expression of `vars` variables.
    pub fn constant(v: f64, vars: usize) -> Expr {
        Expr { node: Node::Number(v), vars }
    }

    /// Its value at the variables' values `at` (not checked for finiteness).
    pub fn eval(&self, at: &[f64]) -> f64 {
        self.gradient(at).0
    }

    /// Its value and its derivatives with respect to the variables at `at` (the derivatives of
    /// `min` and `max` are those of the argument they pick, that of `abs` at 0 is zero).
    pub fn gradient(&self, at: &[f64]) -> (f64, [f64; 3]) {
        assert_eq!(at.len(), self.vars, "an expression of {} variables evaluated at {:?}", self.vars, at);
        let r = value(&self.node, at);
        (r.v, r.d)
    }
}

fn value(n: &Node, at: &[f64]) -> Dual {
    match n {
        Node::Number(v) => Dual::constant(*v),
        Node::Var(i) => {
            let mut d = [0.0; 3];
            d[*i] = 1.0;
            Dual { v: at[*i], d }
        }
        Node::Neg(a) => {
            let a = value(a, at);
            Dual { v: -a.v, d: a.d.map(|d| -d) }
        }
        Node::Binary(op, a, b) => binary(*op, value(a, at), value(b, at)),
        Node::Call(f, args) => {
            let args: Vec<Dual> = args.iter().map(|a| value(a, at)).collect();
            call(*f, &args)
        }
    }
}

fn binary(op: Op, a: Dual, b: Dual) -> Dual {
    match op {
        Op::Add => Dual::combine(a, b, a.v + b.v, 1.0, 1.0),
        Op::Sub => Dual::combine(a, b, a.v - b.v, 1.0, -1.0),
        Op::Mul => Dual::combine(a, b, a.v * b.v, b.v, a.v),
        Op::Div => Dual::combine(a, b, a.v / b.v, 1.0 / b.v, -a.v / (b.v * b.v)),
        Op::Pow => {
            let v = a.v.powf(b.v);
            // d(a^b) = b a^(b−1) da + a^b ln(a) db; the second term only where b varies.
            Dual::combine(a, b, v, b.v * a.v.powf(b.v - 1.0), v * a.v.ln())
        }
    }
}

fn call(f: Func, a: &[Dual]) -> Dual {
    let x = a[0];
    match f {
        Func::Sqrt => x.chain(x.v.sqrt(), 0.5 / x.v.sqrt()),
        Func::Exp => x.chain(x.v.exp(), x.v.exp()),
        Func::Ln => x.chain(x.v.ln(), 1.0 / x.v),
        Func::Sin => x.chain(x.v.sin(), x.v.cos()),
        Func::Cos => x.chain(x.v.cos(), -x.v.sin()),
        Func::Tan => x.chain(x.v.tan(), 1.0 + x.v.tan().powi(2)),
        Func::Atan => x.chain(x.v.atan(), 1.0 / (1.0 + x.v * x.v)),
        Func::Atan2 => {
            let (y, xx) = (a[0], a[1]);
            let r2 = y.v * y.v + xx.v * xx.v;
            Dual::combine(y, xx, y.v.atan2(xx.v), xx.v / r2, -y.v / r2)
        }
        Func::Radians => x.chain(x.v.to_radians(), 1f64.to_radians()),
        Func::Degrees => x.chain(x.v.to_degrees(), 1f64.to_degrees()),
        Func::Abs => x.chain(
            x.v.abs(),
            if x.v > 0.0 {
                1.0
            } else if x.v < 0.0 {
                -1.0
            } else {
                0.0
            },
        ),
        Func::Min => *a.iter().reduce(|m, v| if v.v < m.v { v } else { m }).unwrap_or(&x),
        Func::Max => *a.iter().reduce(|m, v| if v.v > m.v { v } else { m }).unwrap_or(&x),
    }
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
    vars: &'a [&'a str],
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
    /// A left-associative chain `operand (op operand)*` of the two operators `ops`.
    fn chain(&mut self, ops: [(u8, Op); 2], operand: fn(&mut Self) -> Result<Node, String>) -> Result<Node, String> {
        let mut v = operand(self)?;
        while let Some(&(_, op)) = self.peek().and_then(|c| ops.iter().find(|(o, _)| *o == c)) {
            self.i += 1;
            v = Node::Binary(op, Box::new(v), Box::new(operand(self)?));
        }
        Ok(v)
    }
    fn sum(&mut self) -> Result<Node, String> {
        self.chain([(b'+', Op::Add), (b'-', Op::Sub)], Self::product)
    }
    fn product(&mut self) -> Result<Node, String> {
        self.chain([(b'*', Op::Mul), (b'/', Op::Div)], Self::unary)
    }
    /// `^` binds tighter than a unary sign on its left (−2^2 = −4) and is right-associative.
    fn power(&mut self) -> Result<Node, String> {
        let base = self.atom()?;
        if self.peek() == Some(b'^') {
            self.i += 1;
            let e = self.unary()?;
            return Ok(Node::Binary(Op::Pow, Box::new(base), Box::new(e)));
        }
        Ok(base)
    }
    fn unary(&mut self) -> Result<Node, String> {
        match self.peek() {
            Some(b'-') => {
                self.i += 1;
                Ok(Node::Neg(Box::new(self.unary()?)))
            }
            Some(b'+') => {
                self.i += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }
    fn atom(&mut self) -> Result<Node, String> {
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
            Some(c) if c.is_ascii_digit() || c == b'.' => self.number(),
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {
                let start = self.i;
                while self.i < self.s.len() && (self.s[self.i].is_ascii_alphanumeric() || self.s[self.i] == b'_') {
                    self.i += 1;
                }
                let name = std::str::from_utf8(&self.s[start..self.i]).unwrap_or("");
                if self.peek() == Some(b'(') {
                    self.i += 1;
                    return self.function(name);
                }
                self.name(name)
            }
            Some(c) => Err(format!("unexpected `{}`", c as char)),
            None => Err("unexpected end".into()),
        }
    }
    fn number(&mut self) -> Result<Node, String> {
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
        t.parse().map(Node::Number).map_err(|_| format!("bad number `{t}`"))
    }
    /// A variable, else a parameter, else `pi`.
    fn name(&self, name: &str) -> Result<Node, String> {
        if let Some(i) = self.vars.iter().position(|v| *v == name) {
            return Ok(Node::Var(i));
        }
        if let Some((_, v)) = self.params.iter().find(|(n, _)| n == name) {
            return Ok(Node::Number(*v));
        }
        if name == "pi" {
            return Ok(Node::Number(std::f64::consts::PI));
        }
        if COORDINATES.contains(&name) && !self.vars.is_empty() {
            return Err(format!("`{name}` is no coordinate of this case (a plane one: `x`, `y`)"));
        }
        if COORDINATES.contains(&name) {
            return Err(format!(
                "`{name}` is a position, which only the keys that take a field of position have (a body's \
                 `initial` values and a load's `increment_factor`, written without the leading `=`)"
            ));
        }
        Err(format!("unknown parameter `{name}` (define it in [parameters])"))
    }
    /// The arguments of the function `name` (its `(` read) and its call.
    fn function(&mut self, name: &str) -> Result<Node, String> {
        let mut args = vec![self.sum()?];
        while self.peek() == Some(b',') {
            self.i += 1;
            args.push(self.sum()?);
        }
        if self.peek() != Some(b')') {
            return Err(format!("missing `)` after the arguments of `{name}`"));
        }
        self.i += 1;
        let Some(&(_, func, arity)) = FUNCTIONS.iter().find(|(n, _, _)| *n == name) else {
            let known: Vec<&str> = FUNCTIONS.iter().map(|(n, _, _)| *n).collect();
            return Err(format!("unknown function `{name}` (the functions: {})", known.join(", ")));
        };
        match arity {
            Some(1) if args.len() != 1 => Err(format!("`{name}` takes one argument, got {}", args.len())),
            Some(n) if args.len() != n => Err(format!("`{name}` takes {n} arguments, got {}", args.len())),
            _ => Ok(Node::Call(func, args)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const XYZ: [&str; 3] = COORDINATES;

    /// The value at `at` and the central differences of the derivatives (step 1e-6).
    fn check(text: &str, at: [f64; 3], value: f64) {
        let e = Expr::parse(text, &XYZ, &[]).unwrap();
        let (v, d) = e.gradient(&at);
        assert!((v - value).abs() <= 1e-14 * value.abs().max(1.0), "{text}: {v} against {value}");
        for i in 0..3 {
            let (mut lo, mut hi) = (at, at);
            lo[i] -= 1e-6;
            hi[i] += 1e-6;
            let fd = (e.eval(&hi) - e.eval(&lo)) / 2e-6;
            assert!((d[i] - fd).abs() <= 1e-7 * fd.abs().max(1.0), "{text}: ∂/∂{} {} against {fd}", XYZ[i], d[i]);
        }
    }

    #[test]
    fn every_function_has_its_value_and_its_derivative() {
        let at = [0.3, -1.7, 2.5];
        let (x, y, z) = (at[0], at[1], at[2]);
        check("sqrt(z * x)", at, (z * x).sqrt());
        check("exp(x * y)", at, (x * y).exp());
        check("ln(z + x)", at, (z + x).ln());
        check("sin(x * z)", at, (x * z).sin());
        check("cos(y / z)", at, (y / z).cos());
        check("tan(x + y)", at, (x + y).tan());
        check("atan(y * z)", at, (y * z).atan());
        check("atan2(y, x)", at, y.atan2(x));
        check("atan2(x - 1, y)", at, (x - 1.0).atan2(y));
        check("radians(x * 30)", at, (x * 30.0).to_radians());
        check("degrees(y)", at, y.to_degrees());
        check("abs(y * z)", at, (y * z).abs());
        check("min(x, y, z)", at, y);
        check("max(x, y * z, z)", at, z);
        check("x ^ 2.5", at, x.powf(2.5));
        check("z ^ x", at, z.powf(x));
        check("2 * pi * x - y / z + (-z)", at, 2.0 * std::f64::consts::PI * x - y / z - z);
        check("-x^2", at, -(x * x));
    }

    #[test]
    fn precedence_parameters_and_errors() {
        let p = vec![("lambda".to_string(), 2.0), ("B".to_string(), 1.0)];
        let v = |t: &str| Expr::parse(t, &[], &p).map(|e| e.eval(&[]));
        assert_eq!(v("13 - (lambda + 1) * B"), Ok(10.0));
        assert_eq!(v("-2^2"), Ok(-4.0));
        assert_eq!(v("2^3^2"), Ok(512.0));
        assert_eq!(v("1.5e-3 * 2"), Ok(3e-3));
        assert_eq!(v("max(1, lambda, 0.5) + min(3, 4)"), Ok(5.0));
        assert_eq!(v("exp(ln(lambda))"), Ok(2.0));
        assert!((v("tan(radians(45))").unwrap() - 1.0).abs() < 1e-15);
        assert!(v("lambda +").is_err());
        assert!(v("mu * 2").unwrap_err().contains("unknown parameter `mu`"));
        assert!(v("y * 2").unwrap_err().contains("`y` is a position"));
        assert!(v("sin(1, 2)").unwrap_err().contains("`sin` takes one argument, got 2"));
        assert!(v("atan2(1)").unwrap_err().contains("`atan2` takes 2 arguments, got 1"));
        assert!(v("log(2)").unwrap_err().contains("unknown function `log`"));
        // A variable hides a parameter of its name, a parameter hides `pi`.
        let q = vec![("x".to_string(), 5.0), ("pi".to_string(), 3.0)];
        let e = Expr::parse("x + pi", &XYZ, &q).unwrap();
        assert_eq!(e.eval(&[1.0, 0.0, 0.0]), 4.0);
    }
}
