//! What a run leaves behind besides summary.json: checkpoints and restarts, the field files read
//! back by ParaView's own XDMF reader (pvbatch, installed by scripts/setup.sh), `porompm report`,
//! and the quiet progress display. Every test runs the real binary.

mod common;

use hdf5_metno as h5;
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

/// The last output time's particle field `name` of `fields.h5`, sorted by particle id.
fn last_particle_field(dir: &Path, name: &str) -> Vec<f64> {
    let f = h5::File::open(dir.join("fields.h5")).expect("fields.h5 opens");
    let frames = f.group("particles").unwrap().member_names().unwrap();
    let last = frames.iter().map(|n| n.parse::<usize>().unwrap()).max().unwrap();
    f.dataset(&format!("particles/{last}/{name}")).unwrap().read_raw::<f64>().unwrap()
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
fn a_restart_from_the_middle_of_terzaghi_reproduces_the_uninterrupted_run() {
    // The uninterrupted run writes one checkpoint, at step 350 of 601 (t = 0.349 s).
    let full = out_dir("restart-full");
    run_terzaghi(&full, &["--checkpoint-every", "350"]);
    let cp = full.join("checkpoint.h5");
    assert!(cp.is_file() && !full.join("checkpoint.h5.tmp").exists());
    let again = out_dir("restart-continued");
    run_terzaghi(&again, &["--restart", cp.to_str().unwrap()]);

    let (a, b) = (summary(&full), summary(&again));
    assert_eq!(b["status"], "completed");
    assert_eq!(b["restarted_from"]["step"], 350);
    assert_eq!(a["steps"], b["steps"], "the restarted run counts the steps before the restart");
    assert_eq!(a["snes_iterations"], b["snes_iterations"]);

    let (pa, pb) = (last_particle_field(&full, "p"), last_particle_field(&again, "p"));
    assert_eq!(pa.len(), 40);
    let scale = pa.iter().fold(0.0f64, |m, p| m.max(p.abs()));
    let diff = pa.iter().zip(&pb).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale;
    println!("restart at step 350: max |p_restart − p_full| / max |p_full| = {diff:.3e} over {} particles", pa.len());
    assert!(diff <= 1e-10, "restart changed the final pore pressure by {diff:.3e} (relative)");

    // Both Terzaghi targets: T_v = 0.1 was passed before the checkpoint (restored), T_v = 0.5 after
    // (computed by the restarted run).
    for m in ["e_p_Tv0.1", "e_p_Tv0.5", "settlement_rel_error_Tv0.5"] {
        let (x, y) = (a["verification"][m]["value"].as_f64().unwrap(), b["verification"][m]["value"].as_f64().unwrap());
        assert!((x - y).abs() <= 1e-10 * x.abs(), "{m}: {x} vs {y}");
    }
    // history.csv of the restarted run starts at the checkpoint's time.
    let h = std::fs::read_to_string(again.join("history.csv")).unwrap();
    let first: f64 = h.lines().nth(1).unwrap().split(',').next().unwrap().parse().unwrap();
    assert!((first - b["restarted_from"]["time_s"].as_f64().unwrap()).abs() < 1e-9 && first > 0.3);
}

/// The vibrating bar restarted from the middle of its run (step 300 of 550, 1.7 periods in): the
/// free-vibration check keeps the modal displacement's history it had (without it, the restarted
/// run's period is 90 % off) and reports the uninterrupted run's period and amplitude.
#[test]
fn a_restart_of_the_vibrating_bar_keeps_its_free_vibration_check() {
    let full = out_dir("bar-full");
    let args = |dir: &Path| {
        vec![
            "run".to_string(),
            "cases/vibrating_bar.toml".into(),
            "--out".into(),
            dir.display().to_string(),
            "--quiet".into(),
        ]
    };
    let mut first = args(&full);
    first.extend(["--checkpoint-every".into(), "300".into()]);
    let o = porompm(&first.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", stderr(&o));
    let again = out_dir("bar-continued");
    let mut second = args(&again);
    second.extend(["--restart".into(), full.join("checkpoint.h5").display().to_string()]);
    let o = porompm(&second.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", stderr(&o));
    let (a, b) = (summary(&full), summary(&again));
    assert_eq!(b["restarted_from"]["step"], 300);
    for m in ["period_rel_error", "amplitude_rel_error"] {
        let (x, y) = (a["verification"][m]["value"].as_f64().unwrap(), b["verification"][m]["value"].as_f64().unwrap());
        assert!((x - y).abs() <= 1e-9 * x.abs() && b["verification"][m]["pass"] == true, "{m}: {x} vs {y}");
    }
}

#[test]
fn a_run_killed_while_checkpointing_leaves_a_checkpoint_that_restarts_right() {
    let full = out_dir("killed-full");
    run_terzaghi(&full, &[]);
    // Checkpoint after every step, and kill the run (SIGKILL) soon after its first checkpoint,
    // most likely in the middle of writing another one.
    let dir = out_dir("killed");
    let mut child = Command::new(bin())
        .args(["run", "cases/terzaghi.toml", "--out", dir.to_str().unwrap(), "--quiet", "--checkpoint-every", "1"])
        .current_dir(root())
        .spawn()
        .expect("porompm starts");
    let cp = dir.join("checkpoint.h5");
    let start = std::time::Instant::now();
    while !cp.exists() && start.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    std::thread::sleep(std::time::Duration::from_millis(37));
    child.kill().unwrap();
    let status = child.wait().unwrap();
    assert!(!status.success(), "the run was to be killed before its end");
    let torn = dir.join("checkpoint.h5.tmp").exists();
    let again = out_dir("killed-continued");
    run_terzaghi(&again, &["--restart", cp.to_str().unwrap()]);
    let step = summary(&again)["restarted_from"]["step"].as_u64().unwrap();
    assert!((1..601).contains(&step), "restarted at step {step}");
    println!("killed after step {step}; a partly written checkpoint.h5.tmp was left: {torn}");
    let (pa, pb) = (last_particle_field(&full, "p"), last_particle_field(&again, "p"));
    let scale = pa.iter().fold(0.0f64, |m, p| m.max(p.abs()));
    let diff = pa.iter().zip(&pb).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale;
    assert!(diff <= 1e-10, "restart at step {step} after a kill: relative difference {diff:.3e}");
}

#[test]
fn a_checkpoint_of_another_case_or_a_damaged_one_is_refused() {
    let dir = out_dir("refused");
    run_terzaghi(&dir, &["--checkpoint-every", "100", "--set", "stages.consolidation.duration=0.1"]);
    let cp = dir.join("checkpoint.h5");
    let other = out_dir("refused-other");
    fn args<'a>(other: &'a Path, extra: &[&'a str]) -> Vec<&'a str> {
        let mut a = vec!["run", "cases/terzaghi.toml", "--out", other.to_str().unwrap(), "--restart"];
        a.extend_from_slice(extra);
        a
    }
    // The checkpoint's case ran to 0.1 s; the case file as it is runs to 0.6 s.
    let o = porompm(&args(&other, &[cp.to_str().unwrap()]));
    assert_one_line_error(&o, "different case");
    let o = porompm(&args(
        &other,
        &[cp.to_str().unwrap(), "--set", "stages.consolidation.duration=0.1", "--set", "grid.cells=[1,20]"],
    ));
    assert_one_line_error(&o, "different case");
    // Same case, other output settings: accepted.
    let o = porompm(&args(
        &other,
        &[cp.to_str().unwrap(), "--set", "stages.consolidation.duration=0.1", "--set", "output.fields_every=0"],
    ));
    assert!(o.status.success(), "{}", stderr(&o));

    // A checkpoint cut short, as by a crash during a copy.
    let bytes = std::fs::read(&cp).unwrap();
    let cut = dir.join("cut.h5");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let o = porompm(&args(&other, &[cut.to_str().unwrap()]));
    assert_one_line_error(&o, "cut.h5");
    // One flipped byte in the particle data is caught by the checksum (or by HDF5 itself): a byte
    // of the first stored 0.025 m (the column's points sit at x = 0.025 m with half-widths of
    // 0.025 m), wherever the layout puts the particle datasets (a fixed offset from the end fell
    // into unused space once the records grew by a field).
    let mut flipped = bytes.clone();
    let at = bytes.windows(8).position(|w| w == 0.025f64.to_le_bytes()).expect("a point's x or half-width in the file");
    flipped[at + 3] ^= 0x40;
    let bad = dir.join("flipped.h5");
    std::fs::write(&bad, &flipped).unwrap();
    let o = porompm(&args(&other, &[bad.to_str().unwrap(), "--set", "stages.consolidation.duration=0.1"]));
    assert_one_line_error(&o, "flipped.h5");
    let o = porompm(&args(&other, &["no/such/checkpoint.h5"]));
    assert_one_line_error(&o, "does not exist");
}

#[test]
fn paraview_reads_the_fields_as_written() {
    let dir = out_dir("paraview");
    run_terzaghi(&dir, &["--set", "output.fields_every=200"]);
    let s = summary(&dir);
    let pvbatch = Command::new("pvbatch")
        .arg(root().join("tests/paraview/read_fields.py"))
        .arg(dir.join("fields.xdmf"))
        .current_dir(&dir)
        .output()
        .expect("pvbatch runs (Debian packages paraview and python3-paraview; scripts/setup.sh installs them)");
    let text = String::from_utf8_lossy(&pvbatch.stdout);
    assert!(pvbatch.status.success(), "pvbatch failed:\n{text}\n{}", String::from_utf8_lossy(&pvbatch.stderr));
    let pv_err = String::from_utf8_lossy(&pvbatch.stderr);
    assert!(!pv_err.contains("Error") && !pv_err.contains("ERR|"), "ParaView complained:\n{pv_err}");
    let v: serde_json::Value = serde_json::from_str(text.lines().last().unwrap()).expect("the script's JSON");
    println!("read back with ParaView {} ({})", v["paraview_version"], v["reader"]);

    // Output times: t = 0, every 200 steps, and the stage end.
    let times: Vec<f64> = v["times"].as_array().unwrap().iter().map(|t| t.as_f64().unwrap()).collect();
    assert_eq!(times.len(), 5, "{times:?}");
    assert_eq!(times[0], 0.0);
    assert!((times[4] - s["time_s"].as_f64().unwrap()).abs() < 1e-12);

    let n = s["particles"].as_u64().unwrap();
    let p = &v["blocks"]["particles"];
    assert_eq!(p["points"].as_u64(), Some(n));
    for (name, comps) in [
        ("displacement", 3),
        ("velocity", 3),
        ("stress_xx", 1),
        ("stress_yy", 1),
        ("stress_xy", 1),
        ("stress_zz", 1),
        ("mean_stress", 1),
        ("q", 1),
        ("eps_pd", 1),
        ("mass", 1),
        ("volume", 1),
        ("p", 1),
        ("p_excess", 1),
        ("material_id", 1),
        ("body_id", 1),
    ] {
        assert_eq!(p["arrays"][name], serde_json::json!([comps, n]), "particle array {name}");
    }
    let g = &v["blocks"]["grid"];
    assert_eq!(g["points"], 22, "2 × 11 nodes");
    for (name, comps) in [("active", 1), ("du", 3), ("dp", 1), ("dU", 3), ("K_mag", 1), ("Fint_mag", 1)] {
        assert_eq!(g["arrays"][name], serde_json::json!([comps, 22]), "grid array {name}");
    }
    let b: Vec<f64> = g["bounds"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    assert!(b[0].abs() < 1e-12 && (b[1] - 0.1).abs() < 1e-12 && b[2].abs() < 1e-12 && (b[3] - 1.0).abs() < 1e-12);

    // The pore pressure ParaView shows at the probe `middle` (the particle that started nearest to
    // (0.025, 0.525)) is the last value of history.csv's `middle.p`.
    let pos = p["position"].as_array().unwrap();
    let disp = p["displacement"].as_array().unwrap();
    let start = |k: usize, c: usize| pos[k][c].as_f64().unwrap() - disp[k][c].as_f64().unwrap();
    let k = (0..pos.len())
        .min_by(|&a, &b| {
            let d = |k| (start(k, 0) - 0.025).hypot(start(k, 1) - 0.525);
            d(a).total_cmp(&d(b))
        })
        .unwrap();
    let pv_p = p["p"][k][0].as_f64().unwrap();
    let h = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let header: Vec<&str> = h.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|c| *c == "middle.p").unwrap();
    let hist_p: f64 = h.lines().last().unwrap().split(',').nth(col).unwrap().parse().unwrap();
    assert!((pv_p - hist_p).abs() <= 1e-9 * hist_p.abs(), "ParaView p = {pv_p}, history.csv {hist_p}");
}

#[test]
fn report_prints_the_summary_and_names_a_bad_directory() {
    let dir = out_dir("report");
    run_terzaghi(&dir, &["--set", "output.fields_every=0"]);
    assert!(!dir.join("fields.h5").exists(), "fields_every = 0 writes no fields");
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
        "memory [MiB, B per point]".into(),
        "resident peak (rank 0) rose by, in".into(),
    ] {
        assert!(text.contains(&want), "`{want}` missing in:\n{text}");
    }
    // The points' state: 308 bytes a point in two dimensions (the types' sizes, no slack).
    let points = text.lines().find(|l| l.trim_start().starts_with("particles ")).expect("a particles line");
    assert!(points.trim_end().ends_with(" 308"), "{points}");
    assert!(
        s["memory"]["stencils_mib"].as_f64().unwrap() > 0.0 && s["memory"]["matrix_mib"].as_f64().unwrap() > 0.0,
        "{s}"
    );
    let o = porompm(&["report", "no/such/dir"]);
    assert_one_line_error(&o, "no/such/dir is not a directory");
    let o = porompm(&["report", "cases"]);
    assert_one_line_error(&o, "has no summary.json");
    // A summary.json of another shape is refused, naming its key, rather than shown in part.
    let other = out_dir("report-other-shape");
    std::fs::create_dir_all(&other).unwrap();
    std::fs::write(other.join("summary.json"), r#"{"status": "completed", "steps": "many", "timings": {}}"#).unwrap();
    let o = porompm(&["report", other.to_str().unwrap()]);
    assert_one_line_error(&o, "is not a porompm summary: `steps` is the string \"many\", expected a whole number");
    // Checkpoints every 0 steps is no count: refused at once, naming the option.
    let o = porompm(&["run", "cases/terzaghi.toml", "--out", other.to_str().unwrap(), "--checkpoint-every", "0"]);
    assert_one_line_error(&o, "--checkpoint-every");
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

/// The nodal diagnostic `K_mag` of [001] Eq. 25 in fields.h5: on [001] §6's unrotated block
/// (`tests/cases/stiffness_block.toml`, 2 × 2 quarter-point particles per 1 m cell, E = 1000 kN/m²,
/// ν = 0.3), every interior node carries the particle-integrated value 3059.60 kN/m with the linear
/// basis and with GIMP (`seeds-001-002.md` B2; 1e-10 relative), on one rank and on two; a node on
/// the block's edge, half of whose cells are empty, carries about half of it; `Fint_mag` is zero
/// (no load, no stress), and under gravity it balances each interior node's weight ρ g h² (1e-8);
/// both are zero at t = 0.
#[test]
fn k_mag_of_a_full_block_is_the_particle_integrated_stiffness() {
    let (e, nu) = (1.0e6, 0.3);
    let f = e / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let expected = (15.0 / 16.0) * (4.0 / 3.0) * (f * (1.0 - nu) + e / (2.0 * (1.0 + nu))) * 2f64.sqrt();
    assert!((expected / 1e3 - 3059.60).abs() < 5e-3, "{expected}");
    for (basis, ranks) in [("linear", 1), ("gimp", 1), ("gimp", 2)] {
        let dir = out_dir(&format!("stiffness-block-{basis}-{ranks}"));
        let set = format!("analysis.shape_functions={basis}");
        let r = common::run_case_on(ranks, "tests/cases/stiffness_block.toml", &dir, &common::set_args(&[&set]));
        assert!(r.completed(), "{basis}, {ranks} ranks: {}", r.stderr());
        let h = h5::File::open(dir.join("fields.h5")).expect("fields.h5 opens");
        let read =
            |frame: usize, name: &str| h.dataset(&format!("grid/{frame}/{name}")).unwrap().read_raw::<f64>().unwrap();
        let (k0, k, fint) = (read(0, "K_mag"), read(1, "K_mag"), read(1, "Fint_mag"));
        assert!(k0.iter().all(|&x| x == 0.0), "K_mag at t = 0: {k0:?}");
        let node = |i: usize, j: usize| j * 9 + i;
        for j in 1..8 {
            for i in 1..8 {
                let v = k[node(i, j)];
                assert!((v / expected - 1.0).abs() < 1e-10, "{basis}, {ranks} ranks: K_mag at ({i}, {j}) = {v}");
            }
        }
        let edge = k[node(0, 4)] / expected;
        assert!((edge - 0.5).abs() < 0.05, "{basis}: K_mag on the edge / interior = {edge}");
        assert!(fint.iter().all(|&x| x.abs() < 1e-6 * expected), "Fint_mag without a load: {fint:?}");
    }
    // Under gravity each free node's internal force balances its weight, ρ g h² in the interior
    // (ρ = (1 − n)ρ_s + nρ_w = 1400 kg/m³, h = 1 m).
    let dir = out_dir("stiffness-block-gravity");
    let sets = ["loads.0.acceleration=[0.0,-9.81]", "materials.0.solid_density=2000.0"];
    let r = common::run_case("tests/cases/stiffness_block.toml", &dir, &common::set_args(&sets));
    assert!(r.completed(), "{}", r.stderr());
    let h = h5::File::open(dir.join("fields.h5")).expect("fields.h5 opens");
    let fint = h.dataset("grid/1/Fint_mag").unwrap().read_raw::<f64>().unwrap();
    let weight = (0.7 * 2000.0 + 0.3 * 1.0e-3) * 9.81;
    for j in 1..8 {
        for i in 1..8 {
            let v = fint[j * 9 + i];
            assert!((v / weight - 1.0).abs() < 1e-8, "F^int_mag at ({i}, {j}) = {v}, weight {weight}");
        }
    }
}

/// The `plastic_dissipation` column of history.csv: a von Mises block in homogeneous isochoric
/// pure shear past its elastic limit dissipates √3 c ε̄ V (every point at q = √3 c, ε̄ the probe's
/// equivalent plastic strain, V the block's area), to round-off, at every row; nothing while it is
/// elastic; and a restart from the middle ends with the same total.
/// The nodal diagnostics are computed for the frames the schedule writes: every
/// `output.fields_every` steps and at the stage's end, here steps 2 and 3 of a three-step stage
/// written every two steps; both frames carry the full block's K_mag (the first test's), not the
/// NaN of a frame written between them.
#[test]
fn k_mag_is_computed_for_the_scheduled_frames_and_the_stage_end() {
    let dir = out_dir("stiffness-block-schedule");
    let sets = ["stages.hold.duration=3.0", "output.fields_every=2"];
    let r = common::run_case("tests/cases/stiffness_block.toml", &dir, &common::set_args(&sets));
    assert!(r.completed(), "{}", r.stderr());
    let h = h5::File::open(dir.join("fields.h5")).expect("fields.h5 opens");
    let frames = h.group("grid").unwrap().member_names().unwrap().iter().filter(|n| n.parse::<usize>().is_ok()).count();
    assert_eq!(frames, 3, "frames at t = 0, step 2 and step 3");
    let (e, nu) = (1.0e6, 0.3);
    let f = e / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let expected = (15.0 / 16.0) * (4.0 / 3.0) * (f * (1.0 - nu) + e / (2.0 * (1.0 + nu))) * 2f64.sqrt();
    for frame in [1, 2] {
        let k = h.dataset(&format!("grid/{frame}/K_mag")).unwrap().read_raw::<f64>().unwrap();
        let v = k[4 * 9 + 4];
        assert!((v / expected - 1.0).abs() < 1e-10, "frame {frame}: K_mag at the centre = {v}, {expected} expected");
    }
}

#[test]
fn the_plastic_dissipation_of_a_sheared_von_mises_block_is_its_closed_form() {
    let dir = out_dir("plastic_shear");
    let args = common::set_args(&["stages.shear.duration=1.0"]);
    let run = common::run_case("tests/cases/plastic_shear.toml", &dir, &args);
    assert!(run.completed(), "{}", run.stderr());
    let (w, eps) = (run.column("plastic_dissipation"), run.column("centre.eps_pd"));
    let (c, area) = (1.0e3, 16.0);
    assert!(eps.first() == Some(&0.0) && w.first() == Some(&0.0));
    assert!(eps[eps.len() - 1] > 0.01, "the block yields: ε̄ = {}", eps[eps.len() - 1]);
    for (k, (w, e)) in w.iter().zip(&eps).enumerate() {
        let exact = 3f64.sqrt() * c * e * area;
        assert!((w - exact).abs() <= 1e-9 * exact.max(1.0), "row {k}: W_p = {w}, √3 c ε̄ V = {exact}");
    }
    // The column restarts with the run (a checkpoint at step 13 of 20).
    let half = out_dir("plastic_shear_checkpoint");
    let mut args = common::set_args(&["stages.shear.duration=1.0"]);
    args.extend(["--checkpoint-every".into(), "13".into()]);
    let first = common::run_case("tests/cases/plastic_shear.toml", &half, &args);
    assert!(first.completed(), "{}", first.stderr());
    let restarted = out_dir("plastic_shear_restarted");
    let mut args = common::set_args(&["stages.shear.duration=1.0"]);
    args.extend(["--restart".into(), half.join("checkpoint.h5").display().to_string()]);
    let again = common::run_case("tests/cases/plastic_shear.toml", &restarted, &args);
    assert!(again.completed(), "{}", again.stderr());
    let (a, b) = (w[w.len() - 1], again.column("plastic_dissipation"));
    assert!((b[b.len() - 1] - a).abs() <= 1e-12 * a, "restarted {} against {a}", b[b.len() - 1]);
}

/// A checkpoint is written past the semaphore a killed run leaves behind. Open MPI's `sm`
/// shared-file-pointer component guards every MPI-I/O open with a POSIX semaphore named after the
/// file's base name and shared by the whole machine; a run killed while `checkpoint.h5.tmp` is open
/// leaves `/dev/shm/sem.OMPIO_checkpoint.h5.tmp` taken (32 zero bytes are such a semaphore), and
/// every later open of that name waited for ever (the CI run that hung two tests). porompm leaves
/// the component out, so the run ends in its usual fraction of a second; with
/// `OMPI_MCA_sharedfp=sm` in the environment it hangs until the limit.
#[test]
fn a_checkpoint_is_written_past_a_semaphore_a_killed_run_left_taken() {
    struct Taken(std::path::PathBuf);
    impl Drop for Taken {
        fn drop(&mut self) {
            let _ = std::fs::remove_file(&self.0);
        }
    }
    let sem = Taken("/dev/shm/sem.OMPIO_checkpoint.h5.tmp".into());
    std::fs::write(&sem.0, [0u8; 32]).expect("/dev/shm takes a file");
    let dir = out_dir("checkpoint_past_a_taken_semaphore");
    let mut args = common::set_args(&["stages.shear.duration=0.5"]);
    args.extend(["--checkpoint-every".into(), "5".into()]);
    let run = common::run_case_within(60, "tests/cases/plastic_shear.toml", &dir, &args);
    assert!(run.completed(), "{}", run.stderr());
    assert!(dir.join("checkpoint.h5").is_file());
    assert!(sem.0.is_file(), "the taken semaphore is left as it was");
}
