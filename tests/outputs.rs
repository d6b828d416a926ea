//! `porompm report` and the quiet progress display. Every test runs the real binary.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_porompm")
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn out_dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("outputs").join(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn porompm(args: &[&str]) -> Output {
    Command::new(bin()).args(args).current_dir(root()).output().expect("the porompm binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn summary(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).expect("summary.json exists");
    serde_json::from_str(&text).expect("summary.json is valid JSON")
}

fn run_terzaghi(dir: &Path, extra: &[&str]) {
    let mut args = vec!["run", "cases/terzaghi.toml", "--out", dir.to_str().unwrap(), "--quiet"];
    args.extend_from_slice(extra);
    let o = porompm(&args);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Bad input: exit code 2 and one line `error: ...` containing `needle`, without HDF5 diagnostics.
fn assert_one_line_error(o: &Output, needle: &str) {
    let err = stderr(o);
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(o.status.code(), Some(2), "exit code of bad input; stderr:\n{err}");
    assert_eq!(lines.len(), 1, "one line expected, got:\n{err}");
    assert!(lines[0].starts_with("error: ") && lines[0].contains(needle), "`{needle}` not in: {err}");
}

#[test]
fn report_prints_the_summary_and_names_a_bad_directory() {
    let dir = out_dir("report");
    run_terzaghi(&dir, &[]);
    let o = porompm(&["report", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    let s = summary(&dir);
    for want in [
        "status                 completed".to_string(),
        format!("material points        {}", s["particles"]),
        format!("steps                  {} (0 cuts)", s["steps"]),
        "verification (all pass)".into(),
        "e_p_Tv0.5".into(),
        "settlement_rel_error_Tv0.5".into(),
        "linear_solve".into(),
        "middle.excess_p_final".into(),
    ] {
        assert!(text.contains(&want), "`{want}` missing in:\n{text}");
    }
    let o = porompm(&["report", "no/such/dir"]);
    assert_one_line_error(&o, "no/such/dir is not a directory");
    let o = porompm(&["report", "cases"]);
    assert_one_line_error(&o, "has no summary.json");
}

#[test]
fn a_quiet_run_prints_nothing_and_a_piped_one_draws_no_bar() {
    let dir = out_dir("quiet");
    let o = porompm(&["run", "cases/terzaghi.toml", "--out", dir.to_str().unwrap(), "--quiet"]);
    assert!(o.status.success());
    assert_eq!(stderr(&o), "", "--quiet");
    let o = porompm(&["run", "cases/terzaghi.toml", "--out", dir.to_str().unwrap()]);
    assert!(o.status.success());
    let err = stderr(&o);
    assert!(err.contains("stage `consolidation`") && err.contains("completed: 601 steps"), "{err}");
    assert!(!err.contains("ETA") && !err.contains('\r'), "no progress bar when stderr is not a terminal:\n{err}");
}
