//! `porompm report DIR`: a run's `summary.json` as a readable table (status, error, wall time,
//! counts, timings per phase, every verification metric and the results). Works on finished,
//! failed and running runs; keys that a summary does not have are left out.

use serde_json::Value;
use std::fmt::Write as _;
use std::path::Path;

/// Reads `DIR/summary.json` and formats it; an error names the directory or the file.
pub fn report(dir: &Path) -> Result<String, String> {
    if !dir.is_dir() {
        return Err(format!("{} is not a directory (expected a run's output directory)", dir.display()));
    }
    let path = dir.join("summary.json");
    if !path.is_file() {
        return Err(format!("{} has no summary.json (not a porompm output directory?)", dir.display()));
    }
    let text = crate::io::read_text(&path)?;
    let v: Value = serde_json::from_str(&text).map_err(|e| format!("{} is not valid JSON: {e}", path.display()))?;
    if !v.is_object() || v.get("status").is_none() {
        return Err(format!("{} is not a porompm summary (no `status`)", path.display()));
    }
    check_shape(&v).map_err(|e| format!("{} is not a porompm summary: {e}", path.display()))?;
    Ok(format(&v, &dir.display().to_string()))
}

/// The JSON kinds a summary's value may have where the report reads it.
#[derive(Clone, Copy)]
enum Kind {
    Text,
    Number,
    Count,
    Flag,
    Object,
}

impl Kind {
    fn holds(self, x: &Value) -> bool {
        match self {
            Kind::Text => x.is_string(),
            Kind::Number => x.is_number(),
            Kind::Count => x.is_u64(),
            Kind::Flag => x.is_boolean(),
            Kind::Object => x.is_object(),
        }
    }

    fn name(self) -> &'static str {
        match self {
            Kind::Text => "a string",
            Kind::Number => "a number",
            Kind::Count => "a whole number ≥ 0",
            Kind::Flag => "true or false",
            Kind::Object => "an object",
        }
    }

    /// The value `x` at `path` is of this kind, absent or null (which stands for "none" or a
    /// non-finite number anywhere); the error names the path.
    fn check(self, path: &str, x: Option<&Value>) -> Result<(), String> {
        match x {
            Some(x) if !x.is_null() && !self.holds(x) => {
                Err(format!("`{path}` is {}, expected {}", describe(x), self.name()))
            }
            _ => Ok(()),
        }
    }
}

/// Every value the report reads has its summary's kind; an error names the first key that does
/// not, so that a file of another shape is refused rather than shown in part.
fn check_shape(v: &Value) -> Result<(), String> {
    use Kind::*;
    let top = [
        ("status", Text),
        ("case", Text),
        ("error", Text),
        ("porompm_version", Text),
        ("wall_time_s", Number),
        ("time_s", Number),
        ("end_time_s", Number),
        ("steps", Count),
        ("step_cuts", Count),
        ("snes_iterations", Count),
        ("ksp_iterations", Count),
        ("dofs", Count),
        ("grid_dofs", Count),
        ("particles", Count),
        ("ranks", Count),
        ("solver", Text),
        ("matrix_structure_reuses", Count),
        ("checkerboard_index_max", Number),
        ("stopped", Text),
        ("verification_passed", Flag),
        ("restarted_from", Object),
    ];
    for (key, kind) in top {
        kind.check(key, v.get(key))?;
    }
    for key in ["timings", "results", "memory"] {
        numbers(key, v.get(key), "peak_rise")?;
    }
    numbers("memory.peak_rise", v.get("memory").and_then(|m| m.get("peak_rise")), "")?;
    for (name, m) in object("verification", v.get("verification"))?.into_iter().flatten() {
        let path = format!("verification.{name}");
        let m = object(&path, Some(m))?;
        for (key, kind) in
            [("value", Number), ("reference", Number), ("tolerance", Number), ("pass", Flag), ("detail", Text)]
        {
            kind.check(&format!("{path}.{key}"), m.and_then(|m| m.get(key)))?;
        }
    }
    if let Some(o) = v.get("overrides").filter(|o| !o.is_null()) {
        if !o.as_array().is_some_and(|a| a.iter().all(Value::is_string)) {
            return Err(format!("`overrides` is {}, expected a list of strings", describe(o)));
        }
    }
    Ok(())
}

/// The object `x` at `path`, if there is one (an error names the path if `x` is something else).
fn object<'a>(path: &str, x: Option<&'a Value>) -> Result<Option<&'a serde_json::Map<String, Value>>, String> {
    Kind::Object.check(path, x)?;
    Ok(x.and_then(Value::as_object))
}

/// Every entry of the object `x` at `path` but `except` is a number (or null).
fn numbers(path: &str, x: Option<&Value>, except: &str) -> Result<(), String> {
    for (name, x) in object(path, x)?.into_iter().flatten().filter(|(k, _)| *k != except) {
        Kind::Number.check(&format!("{path}.{name}"), Some(x))?;
    }
    Ok(())
}

/// A JSON value's kind, for a message.
fn describe(x: &Value) -> String {
    match x {
        Value::Null => "null".into(),
        Value::Bool(b) => format!("{b}"),
        Value::Number(n) => format!("the number {n}"),
        Value::String(s) if s.chars().count() <= 40 => format!("the string \"{s}\""),
        Value::String(_) => "a string".into(),
        Value::Array(_) => "a list".into(),
        Value::Object(_) => "an object".into(),
    }
}

fn num(v: &Value) -> String {
    match v {
        Value::Number(n) if n.is_u64() || n.is_i64() => n.to_string(),
        Value::Number(n) => {
            let x = n.as_f64().unwrap_or(f64::NAN);
            if x == 0.0 {
                "0".into()
            } else {
                format!("{x:.4e}")
            }
        }
        Value::Null => "NaN".into(),
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// The table of a summary.
pub fn format(v: &Value, dir: &str) -> String {
    let mut s = String::new();
    run_lines(&mut s, v, dir);
    let get = |k: &str| v.get(k).filter(|x| !x.is_null());
    if let Some(t) = get("timings").and_then(Value::as_object) {
        timings(&mut s, t);
    }
    if let Some(m) = get("memory").and_then(Value::as_object).filter(|m| !m.is_empty()) {
        memory(
            &mut s,
            m,
            get("peak_memory_total_mib").and_then(Value::as_f64),
            get("particles").and_then(Value::as_u64),
        );
    }
    if let Some(m) = get("verification").and_then(Value::as_object).filter(|m| !m.is_empty()) {
        verification(&mut s, m, get("verification_passed").and_then(Value::as_bool));
    }
    if let Some(r) = get("results").and_then(Value::as_object).filter(|r| !r.is_empty()) {
        s.push_str("\nresults\n");
        let w = r.keys().map(String::len).max().unwrap_or(0);
        for (name, x) in r {
            let _ = writeln!(s, "  {name:<w$} {:>12}", num(x));
        }
    }
    s
}

/// The run's lines: what ran, how long, how many steps and unknowns, where it restarted from.
fn run_lines(s: &mut String, v: &Value, dir: &str) {
    let get = |k: &str| v.get(k).filter(|x| !x.is_null());
    let line = |s: &mut String, label: &str, value: String| {
        let _ = writeln!(s, "{label:<22} {value}");
    };
    line(s, "run", dir.to_string());
    for (label, key) in [("case", "case"), ("status", "status"), ("error", "error"), ("porompm", "porompm_version")] {
        if let Some(x) = get(key) {
            line(s, label, num(x));
        }
    }
    if let Some(o) = get("overrides").and_then(Value::as_array).filter(|o| !o.is_empty()) {
        line(s, "overrides", o.iter().map(num).collect::<Vec<_>>().join(" "));
    }
    if let Some(x) = get("wall_time_s").and_then(Value::as_f64) {
        line(s, "wall time", format!("{x:.3} s"));
    }
    if let (Some(t), Some(e)) = (get("time_s"), get("end_time_s")) {
        line(s, "simulated time", format!("{} s of {} s", num(t), num(e)));
    }
    if let Some(x) = get("steps") {
        let cuts = get("step_cuts").map(num).unwrap_or_else(|| "0".into());
        line(s, "steps", format!("{} ({cuts} cuts)", num(x)));
    }
    if let Some(x) = get("snes_iterations") {
        let k = get("ksp_iterations").map(num).unwrap_or_else(|| "-".into());
        line(s, "iterations", format!("{} Newton, {k} Krylov", num(x)));
    }
    if let Some(x) = get("dofs") {
        let g = get("grid_dofs").map(num).unwrap_or_else(|| "-".into());
        line(s, "unknowns", format!("{} (grid dofs {g})", num(x)));
    }
    for (label, key) in [
        ("material points", "particles"),
        ("ranks", "ranks"),
        ("solver", "solver"),
        ("matrix reuses", "matrix_structure_reuses"),
        ("checkerboard max", "checkerboard_index_max"),
        ("stopped", "stopped"),
    ] {
        if let Some(x) = get(key).filter(|x| x.as_str() != Some("")) {
            line(s, label, num(x));
        }
    }
    if let Some(r) = get("restarted_from") {
        let mut text = format!(
            "{} at t = {} s, step {}",
            r.get("checkpoint").map(num).unwrap_or_default(),
            r.get("time_s").map(num).unwrap_or_default(),
            r.get("step").map(num).unwrap_or_default()
        );
        if let Some(n) = r.get("note").and_then(Value::as_str) {
            let _ = write!(text, " ({n})");
        }
        line(s, "restarted from", text);
    }
}

/// The timings in seconds with their shares of the total.
fn timings(s: &mut String, t: &serde_json::Map<String, Value>) {
    s.push_str("\ntimings [s]\n");
    // The phases add up to the run; the Jacobians are a part of the assembly, the mat-vec a unit.
    const PARTS: [&str; 3] = ["jacobian_s", "jacobians", "tangent_matvec_s"];
    let phases = || t.iter().filter(|(k, _)| !PARTS.contains(&k.as_str()));
    let total: f64 = phases().filter_map(|(_, x)| x.as_f64()).sum();
    for (k, x) in phases() {
        let name = k.strip_suffix("_s").unwrap_or(k);
        let x = x.as_f64().unwrap_or(f64::NAN);
        let share = if total > 0.0 { 100.0 * x / total } else { 0.0 };
        let _ = writeln!(s, "  {name:<20} {x:>10.4} {share:>5.1} %");
    }
    if let (Some(j), Some(n)) =
        (t.get("jacobian_s").and_then(Value::as_f64), t.get("jacobians").and_then(Value::as_u64))
    {
        let _ = writeln!(s, "  of the assembly, {n} Jacobians: {j:.4} s");
    }
    if let Some(m) = t.get("tangent_matvec_s").and_then(Value::as_f64) {
        let _ = writeln!(s, "  one tangent mat-vec: {m:.3e} s");
    }
}

/// Memory by structure [MiB] and per material point [B], beside the resident peak (summed over
/// ranks) and what the structures listed leave of it (PETSc's solver, MPI, HDF5, the program's
/// code and the allocator).
fn memory(s: &mut String, m: &serde_json::Map<String, Value>, resident: Option<f64>, points: Option<u64>) {
    let per_point =
        |mib: f64| points.filter(|&n| n > 0).map_or("-".into(), |n| format!("{:.0}", mib * 1048576.0 / n as f64));
    s.push_str("\nmemory [MiB, B per point]\n");
    let mut listed = 0.0;
    for (k, x) in m.iter().filter_map(|(k, x)| Some((k, x.as_f64()?))) {
        let name = k.strip_suffix("_mib").unwrap_or(k);
        listed += x;
        let _ = writeln!(s, "  {name:<20} {x:>10.1} {:>8}", per_point(x));
    }
    if let Some(r) = resident {
        let _ = writeln!(s, "  {:<20} {:>10.1} {:>8}", "other", r - listed, per_point(r - listed));
        let _ = writeln!(s, "  {:<20} {:>10.1} {:>8}", "resident peak", r, per_point(r));
    }
    if let Some(rise) = m.get("peak_rise").and_then(Value::as_object) {
        s.push_str("  resident peak (rank 0) rose by, in\n");
        for (k, x) in rise.iter().filter_map(|(k, x)| Some((k, x.as_f64()?))) {
            let name = k.strip_suffix("_mib").unwrap_or(k);
            let _ = writeln!(s, "    {name:<18} {x:>10.1}");
        }
    }
}

/// The verification metrics, one a line, with the verdict `passed` of them all.
fn verification(s: &mut String, m: &serde_json::Map<String, Value>, passed: Option<bool>) {
    let verdict = match passed {
        Some(true) => " (all pass)",
        Some(false) => " (some FAIL)",
        None => "",
    };
    let _ = writeln!(s, "\nverification{verdict}");
    let w = m.keys().map(String::len).max().unwrap_or(6).max(6);
    let _ = writeln!(
        s,
        "  {:<w$} {:>12} {:>12} {:>12}  {:<4}  detail",
        "metric", "value", "reference", "tolerance", "pass"
    );
    for (name, x) in m {
        let f = |k: &str| x.get(k).map(num).unwrap_or_else(|| "-".into());
        let pass = match x.get("pass").and_then(Value::as_bool) {
            Some(true) => "pass",
            Some(false) => "FAIL",
            None => "-",
        };
        let detail = x.get("detail").and_then(Value::as_str).unwrap_or("");
        let _ = writeln!(
            s,
            "  {name:<w$} {:>12} {:>12} {:>12}  {pass:<4}  {detail}",
            f("value"),
            f("reference"),
            f("tolerance")
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_summary_of_another_shape_is_refused_naming_its_key() {
        let ok = serde_json::json!({"status": "completed", "steps": 3, "timings": {"setup_s": 0.5},
                                     "verification": {"e": {"value": null, "pass": true}}, "overrides": ["a=1"]});
        assert_eq!(check_shape(&ok), Ok(()));
        for (bad, key) in [
            (serde_json::json!({"status": 3}), "`status` is the number 3, expected a string"),
            (serde_json::json!({"status": "x", "steps": "many"}), "`steps` is the string \"many\""),
            (serde_json::json!({"status": "x", "steps": -1}), "`steps` is the number -1, expected a whole number"),
            (serde_json::json!({"status": "x", "timings": 5}), "`timings` is the number 5, expected an object"),
            (serde_json::json!({"status": "x", "timings": {"a_s": "1"}}), "`timings.a_s` is the string"),
            (serde_json::json!({"status": "x", "verification": {"e": 1}}), "`verification.e` is the number 1"),
            (serde_json::json!({"status": "x", "verification": {"e": {"pass": 1}}}), "`verification.e.pass`"),
            (serde_json::json!({"status": "x", "results": {"r": [1]}}), "`results.r` is a list"),
            (serde_json::json!({"status": "x", "overrides": "a=1"}), "`overrides` is the string"),
        ] {
            let e = check_shape(&bad).unwrap_err();
            assert!(e.contains(key), "{e} lacks {key}");
        }
    }

    #[test]
    fn a_failed_summary_shows_its_error_and_every_metric() {
        let v = serde_json::json!({
            "status": "failed",
            "error": "stage `load`: the step did not converge",
            "wall_time_s": 1.5,
            "steps": 12,
            "step_cuts": 3,
            "snes_iterations": 40,
            "ksp_iterations": 40,
            "timings": {"setup_s": 0.5, "assembly_s": 1.5, "jacobian_s": 1.0, "jacobians": 7},
            "verification": {"e_p": {"value": 2e-3, "reference": 0.0, "tolerance": 1e-2, "pass": true, "detail": "d"},
                             "s": {"value": null, "reference": 1.0, "tolerance": 0.1, "pass": false, "detail": "never"}},
            "verification_passed": false,
            "results": {"top.displacement": 0.0125}
        });
        let t = format(&v, "out/x");
        for want in [
            "status                 failed",
            "error                  stage `load`",
            "steps                  12 (3 cuts)",
            "assembly                 1.5000  75.0 %",
            "of the assembly, 7 Jacobians: 1.0000 s",
            "verification (some FAIL)",
            "e_p       2.0000e-3            0    1.0000e-2  pass  d",
            "s               NaN     1.0000e0    1.0000e-1  FAIL  never",
            "top.displacement    1.2500e-2",
        ] {
            assert!(t.contains(want), "`{want}` missing in:\n{t}");
        }
    }
}
