//! `porompm sweep` end to end (runs, failed rows, the three result files, bad input) and the PNG
//! figures a verification run draws into DIR/plots/. Every test runs the real binary.

mod common;
use common::csv_fields;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn out_dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("sweep_and_plots").join(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn porompm(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_porompm")).args(args).current_dir(root()).output().expect("porompm runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A PNG figure with `series` drawn series: it decodes, has the figure size, and at least
/// `series` of the series colours each cover more than 300 pixels (a line across the chart; the
/// legend's sample alone covers fewer), so a blank or half-drawn chart fails.
fn assert_png(path: &Path, series: usize) {
    use porompm::io::plot::{SERIES_COLOURS, SIZE};
    let img = image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb8();
    assert_eq!(img.dimensions(), SIZE, "{}", path.display());
    let counts: Vec<usize> =
        // Black and grey (the last two) also draw the frame and the text: not counted.
        SERIES_COLOURS[..6].iter().map(|c| img.pixels().filter(|p| p.0 == *c).count()).collect();
    let drawn = counts.iter().filter(|n| **n > 300).count();
    assert!(drawn >= series, "{}: {drawn} series drawn (pixels per colour {counts:?})", path.display());
}

#[test]
fn a_sweep_runs_every_combination_and_keeps_failed_runs_as_rows() {
    let out = out_dir("terzaghi");
    let o = porompm(&[
        "sweep",
        "cases/terzaghi.toml",
        "--out",
        out.to_str().unwrap(),
        "--options-file",
        "petsc_options/direct-lu-umfpack.opts",
        "--options-file",
        "petsc_options/direct-lu.opts",
        // -1e-3 is not a valid time step: those two runs end with an input error.
        "--vary",
        "time.dt=4e-3,2e-3,-1e-3",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 1 + 2 * 3, "{csv}");
    let header = csv_fields(lines[0]);
    let col = |name: &str| header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"));
    let rows: Vec<Vec<String>> = lines[1..].iter().map(|l| csv_fields(l)).collect();
    for name in
        ["time_assembly_s", "time_linear_solve_s", "snes_iterations", "ksp_iterations", "dofs", "peak_memory_mib"]
    {
        col(name);
    }
    let failed: Vec<&Vec<String>> = rows.iter().filter(|r| r[col("status")] != "completed").collect();
    assert_eq!(failed.len(), 2, "{csv}");
    for r in &failed {
        assert_eq!(r[col("time.dt")], "-1e-3");
        assert_eq!(r[col("status")], "input error");
        assert!(r[col("failure")].contains("dt"), "the reason names the key: {}", r[col("failure")]);
    }
    // The completed runs carry their metrics, and the smaller step is the more accurate.
    let e = |strategy: &str, dt: &str| -> f64 {
        let r = rows.iter().find(|r| r[col("strategy")] == strategy && r[col("time.dt")] == dt).unwrap();
        r[col("e_p_Tv0.1")].parse().unwrap()
    };
    for s in ["direct-lu-umfpack", "direct-lu"] {
        assert!(e(s, "2e-3") < e(s, "4e-3"), "{csv}");
    }
    let md = std::fs::read_to_string(out.join("sweep.md")).unwrap();
    assert_eq!(md.lines().filter(|l| l.starts_with("| ")).count(), 1 + 6, "{md}");
    assert_png(&out.join("work_precision.png"), 2);
    assert!(out.join("run_0").join("summary.json").is_file());
}

#[test]
fn bad_input_of_a_sweep_exits_with_2_and_a_sweep_whose_runs_all_fail_with_1() {
    let out = out_dir("bad");
    let o = porompm(&["sweep", "cases/terzaghi.toml", "--out", out.to_str().unwrap(), "--vary", "time.dt"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).starts_with("error: --vary `time.dt`"), "{}", stderr(&o));
    let o = porompm(&["sweep", "cases/terzaghi.toml", "--out", out.to_str().unwrap(), "--options-file", "nope.opts"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("nope.opts does not exist"), "{}", stderr(&o));
    assert!(!out.join("sweep.csv").exists());
    // A metric that no run reports is bad input, found once the runs are done.
    let o = porompm(&[
        "sweep",
        "cases/terzaghi.toml",
        "--out",
        out.to_str().unwrap(),
        "--vary",
        "time.dt=4e-3",
        "--metric",
        "no_such_metric",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--metric no_such_metric: no run reports it (metrics: e_p_Tv0.1"), "{}", stderr(&o));
    // Every run failing is a failure of the sweep (exit 1), with its table written.
    let o = porompm(&["sweep", "cases/terzaghi.toml", "--out", out.to_str().unwrap(), "--vary", "time.dt=-1"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(out.join("sweep.csv").is_file());
}

#[test]
fn a_verification_run_draws_its_figures() {
    let out = out_dir("terzaghi_plots");
    let o = porompm(&["run", "cases/terzaghi.toml", "--out", out.to_str().unwrap(), "--quiet"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let plots = out.join("plots");
    for (f, series) in
        [("terzaghi_pressure_profiles.png", 2), ("terzaghi_settlement.png", 2), ("probes_excess_pore_pressure.png", 2)]
    {
        assert_png(&plots.join(f), series);
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let peak = summary["peak_memory_mib"].as_f64().expect("peak_memory_mib");
    assert!(peak > 1.0 && peak < 1e5, "{peak}");
}
