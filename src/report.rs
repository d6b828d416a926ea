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
    Ok(format(&v, &dir.display().to_string()))
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
    let total: f64 = t.values().filter_map(Value::as_f64).sum();
    for (k, x) in t {
        let name = k.strip_suffix("_s").unwrap_or(k);
        let x = x.as_f64().unwrap_or(f64::NAN);
        let share = if total > 0.0 { 100.0 * x / total } else { 0.0 };
        let _ = writeln!(s, "  {name:<20} {x:>10.4} {share:>5.1} %");
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
    fn a_failed_summary_shows_its_error_and_every_metric() {
        let v = serde_json::json!({
            "status": "failed",
            "error": "stage `load`: the step did not converge",
            "wall_time_s": 1.5,
            "steps": 12,
            "step_cuts": 3,
            "snes_iterations": 40,
            "ksp_iterations": 40,
            "timings": {"setup_s": 0.5, "assembly_s": 1.5},
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
            "verification (some FAIL)",
            "e_p       2.0000e-3            0    1.0000e-2  pass  d",
            "s               NaN     1.0000e0    1.0000e-1  FAIL  never",
            "top.displacement    1.2500e-2",
        ] {
            assert!(t.contains(want), "`{want}` missing in:\n{t}");
        }
    }
}
