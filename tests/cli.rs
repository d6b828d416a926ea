//! Command-line behaviour: `--version`, `check`, bad input (one clear line, exit code 2, never a
//! panic or a PETSc traceback), a run that fails cleanly, MPI start-up under `mpirun -n 2`, and the
//! block-by-block finite-difference check of the assembled tangent. Every test runs the real
//! binary in its own process (PETSc and MPI can be initialised once per process).

mod common;

use common::{assert_tangent_agrees, root};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_porompm")
}

fn out_dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli").join(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn porompm(args: &[&str]) -> Output {
    Command::new(bin()).args(args).current_dir(root()).output().expect("the porompm binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Bad input ends with exit code 2 and exactly one line on stderr, `error: ...` containing `needle`.
fn assert_one_line_error(o: &Output, needle: &str) {
    let err = stderr(o);
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(o.status.code(), Some(2), "exit code of bad input; stderr:\n{err}");
    assert_eq!(lines.len(), 1, "one line expected, got:\n{err}");
    assert!(lines[0].starts_with("error: "), "{err}");
    assert!(lines[0].contains(needle), "`{needle}` not in: {err}");
    assert!(!err.contains("panicked") && !err.contains("PETSC ERROR") && !err.contains("[0]PETSC"), "{err}");
}

/// `porompm check CASE --set SET` refuses each `(SET, needle)` pair with one error line naming it.
fn assert_sets_refused(case: &str, pairs: &[(&str, &str)]) {
    for (set, needle) in pairs {
        let o = porompm(&["check", case, "--set", set]);
        assert_one_line_error(&o, needle);
    }
}

fn summary(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).expect("summary.json exists");
    serde_json::from_str(&text).expect("summary.json is valid JSON")
}

#[test]
fn version_shows_petsc_318_with_mumps_and_hypre() {
    let o = porompm(&["--version"]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("PETSc 3.18."), "{text}");
    assert!(text.contains("mumps") && text.contains("hypre"), "{text}");
    assert!(text.contains("git "), "{text}");
}

/// Every shipped case and every test fixture is accepted as it stands: a user who runs one gets a
/// run, not a refusal (the tests that override a fixture's keys do not show this).
#[test]
fn every_case_and_fixture_passes_the_check_as_it_stands() {
    let mut files = Vec::new();
    for dir in ["cases", "tests/cases"] {
        for entry in std::fs::read_dir(root().join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                files.push(format!("{dir}/{}", path.file_name().unwrap().to_string_lossy()));
            }
        }
    }
    assert!(files.len() >= 40, "{files:?}");
    let refused: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let o = porompm(&["check", f]);
            (!o.status.success()).then(|| format!("{f}: {}", stderr(&o).trim()))
        })
        .collect();
    assert!(refused.is_empty(), "refused as they stand:\n{}", refused.join("\n"));
}

#[test]
fn check_describes_what_the_case_builds() {
    let o = porompm(&["check", "cases/terzaghi.toml"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    for want in [
        "5 dofs per node: ux, uy, p, Ux, Uy",
        "material points: 40",
        "unknowns of the first step: 60",
        "particle traction on 2",
        "Terzaghi",
    ] {
        assert!(text.contains(want), "`{want}` missing in:\n{text}");
    }
    // Overrides change what is built.
    let o = porompm(&["check", "cases/terzaghi.toml", "--set", "grid.cells=[1,20]"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("material points: 80"));
}

#[test]
fn a_missing_case_file_is_one_clear_error() {
    let o = porompm(&["run", "cases/no_such_case.toml", "--out", out_dir("missing").to_str().unwrap()]);
    assert_one_line_error(&o, "cannot read cases/no_such_case.toml");
}

#[test]
fn an_unknown_key_is_named() {
    let dir = out_dir("unknown_key");
    std::fs::create_dir_all(&dir).unwrap();
    let case = dir.join("case.toml");
    let text = std::fs::read_to_string(root().join("cases/terzaghi.toml"))
        .unwrap()
        .replace("porosity = 0.3", "porosity = 0.3\nporosty = 0.3");
    std::fs::write(&case, text).unwrap();
    let o = porompm(&["run", case.to_str().unwrap(), "--out", dir.join("out").to_str().unwrap()]);
    assert_one_line_error(&o, "key `materials[0].porosty`: unknown field `porosty`");
    // The same through --set.
    let o = porompm(&["check", "cases/terzaghi.toml", "--set", "stages[0].tdt=1e-3"]);
    assert_one_line_error(&o, "--set stages[0].tdt");
}

#[test]
fn an_out_of_range_value_is_named_with_its_range() {
    let o = porompm(&[
        "run",
        "cases/terzaghi.toml",
        "--out",
        out_dir("range").to_str().unwrap(),
        "--set",
        "materials.soil.porosity=1.5",
    ]);
    assert_one_line_error(&o, "key `materials[0].porosity`: must be in (0, 1), got 1.5");
    let o = porompm(&["check", "cases/terzaghi.toml", "--set", "materials.soil.hydraulic_conductivity=-1e-3"]);
    assert_one_line_error(&o, "hydraulic_conductivity`: must be a positive number");
    let o = porompm(&["check", "cases/terzaghi.toml", "--set", "time_integration.gamma=0.4"]);
    assert_one_line_error(&o, "not unconditionally stable");
    // Absurd magnitudes: each named with its bound.
    assert_sets_refused(
        "cases/terzaghi.toml",
        &[
            ("materials.soil.model.young_modulus=1e308", "young_modulus`: must be at most 1e13 Pa"),
            ("materials.soil.water_bulk_modulus=1e20", "water_bulk_modulus`: must be at most 1e13 Pa"),
            ("materials.soil.solid_bulk_modulus=1e14", "solid_bulk_modulus`: must be at most 1e13 Pa"),
            ("materials.soil.hydraulic_conductivity=5", "hydraulic_conductivity`: must be at most 1e0 m/s"),
            ("materials.soil.solid_density=1e6", "solid_density`: must be at most 1e5 kg/m³"),
        ],
    );
}

#[test]
fn particles_outside_the_grid_are_refused() {
    let o = porompm(&[
        "check",
        "cases/terzaghi.toml",
        "--set",
        "bodies[0].shape={rectangle={min=[0.0,0.0],max=[0.1,1.2]}}",
    ]);
    assert_one_line_error(&o, "reaches outside the grid");
}

#[test]
fn a_missing_options_file_is_one_clear_error() {
    let dir = out_dir("options_missing");
    let o = porompm(&[
        "run",
        "cases/terzaghi.toml",
        "--out",
        dir.to_str().unwrap(),
        "--options-file",
        "petsc_options/nope.opts",
    ]);
    assert_one_line_error(&o, "PETSc options file petsc_options/nope.opts does not exist");
    assert!(!dir.join("summary.json").exists(), "nothing is written for input that fails before the run");
}

#[test]
fn an_unused_petsc_option_fails_the_run_and_says_which() {
    let dir = out_dir("unused_option");
    let o =
        porompm(&["run", "cases/terzaghi.toml", "--out", dir.to_str().unwrap(), "--quiet", "--", "-ksp_tyep", "gmres"]);
    assert_one_line_error(&o, "-ksp_tyep gmres");
    let s = summary(&dir);
    assert_eq!(s["status"], "failed");
    assert!(s["error"].as_str().unwrap().contains("not used"));
}

#[test]
fn a_malformed_override_is_one_clear_error() {
    let o = porompm(&["check", "cases/terzaghi.toml", "--set", "grid.cells"]);
    assert_one_line_error(&o, "expected KEY=VALUE");
    let o = porompm(&["check", "cases/terzaghi.toml", "--set", "materials.clay.porosity=0.3"]);
    assert_one_line_error(&o, "no element named `clay`");
}

#[test]
fn a_completed_run_writes_its_summary_and_history() {
    let dir = out_dir("completed");
    let o = porompm(&[
        "run",
        "cases/terzaghi.toml",
        "--out",
        dir.to_str().unwrap(),
        "--quiet",
        "--set",
        "stages[0].duration=0.01",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = summary(&dir);
    assert_eq!(s["status"], "completed");
    assert_eq!(s["steps"], 10);
    for key in [
        "wall_time_s",
        "snes_iterations",
        "ksp_iterations",
        "dofs",
        "particles",
        "ranks",
        "petsc_options",
        "timings",
        "verification",
    ] {
        assert!(s.get(key).is_some(), "summary lacks `{key}`");
    }
    let history = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    assert_eq!(history.lines().count(), 12, "header, t = 0 and ten steps");
    assert!(history.starts_with("time,step,dt,newton_iterations,linear_iterations,base.x"));
}

#[test]
fn a_step_that_never_converges_is_cut_then_the_run_fails_cleanly() {
    let dir = out_dir("diverges");
    // One Newton iteration can never meet an unattainable tolerance.
    let o = porompm(&[
        "run",
        "cases/terzaghi.toml",
        "--out",
        dir.to_str().unwrap(),
        "--quiet",
        "--",
        "-snes_max_it",
        "1",
        "-snes_rtol",
        "1e-300",
        "-snes_stol",
        "0",
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("did not converge after 4 cuts of Δt (last Δt = 6.250e-5 s)"), "{err}");
    let s = summary(&dir);
    assert_eq!(s["status"], "failed");
    assert_eq!(s["step_cuts"], 5);
    // Running out of iterations is not a divergence: no try was solved again with a line search.
    assert_eq!(s["line_search_retries"], 0);
    assert_eq!(s["steps"], 0);
    // What was written stays readable: the header and the initial state.
    let history = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    assert_eq!(history.lines().count(), 2);
}

fn mpirun(n: usize, args: &[&str]) -> Option<Output> {
    let which = Command::new("mpirun").arg("--version").output().ok()?;
    if !which.status.success() {
        return None;
    }
    let np = n.to_string();
    let mut all = vec!["--oversubscribe", "-n", np.as_str(), bin()];
    all.extend_from_slice(args);
    Some(common::mpi_env(&mut Command::new("mpirun")).args(&all).current_dir(root()).output().expect("mpirun runs"))
}

#[test]
fn mpi_starts_with_two_ranks() {
    let o = mpirun(2, &["info"]).expect("mpirun is installed by the set-up (openmpi-bin)");
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(text.contains("ranks: 2"), "{text}");
    assert!(text.contains("collective sum over ranks: 2"), "{text}");
}

#[test]
fn the_assembled_tangent_matches_finite_differences_block_by_block() {
    // A small two-dimensional two-phase case: every block (ux, uy, p, Ux, Uy)² is exercised.
    assert_tangent_agrees(
        &[
            "cases/terzaghi.toml",
            "--steps",
            "3",
            "--set",
            "grid.cells=[2,4]",
            "--set",
            "grid.size=[0.2,0.4]",
            "--set",
            "bodies[0].shape={rectangle={min=[0.0,0.0],max=[0.2,0.4]}}",
            "--set",
            "loads[0].region={min=[0.0,0.2],max=[0.2,0.4]}",
            "--set",
            "probes=[]",
        ],
        25,
    );
}

/// The small slumping block of the tangent checks: 6 × 5 cells, a 0.5 m block, no probes.
const SMALL_BLOCK: [&str; 8] = [
    "--set",
    "grid.cells=[6,5]",
    "--set",
    "grid.size=[0.75,0.625]",
    "--set",
    "bodies[0].shape={rectangle={min=[0.0,0.0],max=[0.5,0.5]}}",
    "--set",
    "probes=[]",
];

/// A non-associated Mohr–Coulomb soil with evolving dilatancy, for the plastic tangent checks.
const PLASTIC_SOIL: &str = "materials[0].model={type=\"mohr_coulomb\",young_modulus=1e6,poisson_ratio=0.3,\
                            friction_angle=20.0,cohesion=2000.0,dilation_angle=-5.0,critical_dilation_angle=0.0,\
                            dilation_decay=25.0}";

#[test]
fn the_tangent_with_bbar_matches_finite_differences_on_a_two_dimensional_block() {
    // A small slumping block after five steps under gravity: a genuinely two-dimensional
    // deformation, B̄ on ([000] §3), moving drained surfaces and GIMP domains that follow the stretch.
    let head = ["cases/slumping_block.toml", "--steps", "5", "--set", "stabilisation.bbar=true"];
    assert_tangent_agrees(&[&head[..], &SMALL_BLOCK, &["--set", "time.dt=0.01"]].concat(), 25);
}

/// At rest (the vertical cut's held gravity stage, elastic: the increments are near zero) the
/// finite-difference step keeps its floor of 1e-9 of a cell and the tangent agrees to 1e-6
/// (measured 8.7e-9; a step of 1e-12 of a cell left the residual's round-off at 7.3e-6).
#[test]
fn the_tangent_check_holds_at_rest() {
    let args = [
        "cases/vertical_cut.toml",
        "--steps",
        "60",
        "--set",
        "parameters.h=0.25",
        "--set",
        "materials.clay.model.cohesion=1e5",
    ];
    assert_tangent_agrees(&args, 4);
}

#[test]
fn the_one_phase_tangent_matches_finite_differences_too() {
    assert_tangent_agrees(
        &[
            "cases/elastic_column.toml",
            "--steps",
            "5",
            "--set",
            "grid.cells=[2,6]",
            "--set",
            "grid.size=[0.1,0.3]",
            "--set",
            "bodies[0].shape={rectangle={min=[0.0,0.0],max=[0.1,0.3]}}",
            "--set",
            "loads.surcharge.region={min=[0.0,0.3],max=[0.1,0.3]}",
            "--set",
            "probes=[]",
            "--set",
            "time.dt=0.05",
        ],
        4,
    );
}

/// The element test drives loose sand through plane-strain compression at constant lateral stress:
/// the CSV has a row per increment, the lateral stress stays at its control value and the final
/// state lies on the Mohr–Coulomb surface (σ₁ − σ₃) + (σ₁ + σ₃) sin φ = 2c cos φ (tension positive).
#[test]
fn the_element_test_writes_a_plane_strain_path_ending_on_the_mohr_coulomb_surface() {
    let dir = out_dir("element_test");
    let o = porompm(&[
        "element-test",
        "element_tests/loose_sand.toml",
        "--path",
        "element_tests/plane_strain.toml",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(dir.join("element_test.csv")).expect("element_test.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 200, "one row per increment");
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}"));
    let last = rows.last().unwrap();
    let v = |name: &str| last[col(name)].parse::<f64>().unwrap();
    assert!((v("sig_xx") + 100e3).abs() < 1e-3, "lateral stress held: {}", v("sig_xx"));
    let mut s = [v("sig_xx"), v("sig_yy"), v("sig_zz")];
    s.sort_by(f64::total_cmp);
    let (s1, s3) = (s[2], s[0]);
    let (phi, c) = (25f64.to_radians(), 3.0e3);
    let f = (s1 - s3) + (s1 + s3) * phi.sin() - 2.0 * c * phi.cos();
    assert!(f.abs() < 1e-6 * s3.abs(), "yield function at the end: {f} Pa");
    assert!(v("eps_pd") > 0.01, "the sand has yielded");
    assert_eq!(last[col("region")], "plane");
}

#[test]
fn an_element_test_with_a_missing_path_file_is_one_clear_error() {
    let dir = out_dir("element_test_missing");
    let o = porompm(&[
        "element-test",
        "element_tests/loose_sand.toml",
        "--path",
        "element_tests/no_such_path.toml",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_one_line_error(&o, "no_such_path.toml");
}

/// Case parameters: a `"= expr"` value that names an unknown parameter is refused with its key.
#[test]
fn an_expression_with_an_unknown_parameter_is_named() {
    let o = porompm(&["check", "cases/slope_sand.toml", "--set", "materials.sand.model.cohesion== 2 * nonesuch"]);
    assert_one_line_error(&o, "nonesuch");
}

/// The tangent of plastic, non-associated Mohr–Coulomb points (ψ ≠ φ, evolving dilatancy) with B̄
/// and the pressure-projection block, on the small slumping block after ten steps under gravity:
/// most points have yielded and every block still matches central differences.
#[test]
fn the_plastic_tangent_with_pressure_projection_matches_finite_differences() {
    let head = ["cases/slumping_block.toml", "--steps", "10", "--set", "stabilisation.bbar=true"];
    let projection = ["--set", "stabilisation.pressure_projection=1.0", "--set", "time.dt=0.02", "--set", PLASTIC_SOIL];
    let text = assert_tangent_agrees(&[&head[..], &SMALL_BLOCK, &projection].concat(), 25);
    let yielded: usize = text
        .lines()
        .find_map(|l| l.strip_prefix("material points that have yielded: "))
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or_else(|| panic!("no yield count in:\n{text}"));
    assert!(yielded >= 10, "only {yielded} points have yielded:\n{text}");
}

/// The tangent of the implicit F̄ (`kernels::fbar`: the projected volume ratio J̄ as a nodal
/// unknown, its projection rows, the forces' dependence on it): on the small slumping block as a
/// one-phase body of non-associated Mohr–Coulomb soil after ten steps under gravity (points have
/// yielded), and as the quasi-static u–p system, every block (ux, uy, [p,] Jbar)² matches central
/// differences; negating the ux–Jbar block is seen.
#[test]
fn the_fbar_tangent_matches_finite_differences_for_u_and_u_p() {
    let small = [&SMALL_BLOCK[..], &["--set", "stabilisation={fbar=true}", "--set", "time.dt=0.02"]].concat();
    let plastic = ["--set", "analysis.formulation=one_phase", "--set", PLASTIC_SOIL];
    let quasi_static = ["--set", "stages.0.analysis=quasi_static"];
    let check = |extra: &[&'static str], flip: Option<&'static str>| -> Vec<&'static str> {
        let mut args = vec!["cases/slumping_block.toml", "--steps", "10"];
        args.extend_from_slice(&small);
        args.extend_from_slice(extra);
        if let Some(f) = flip {
            args.extend_from_slice(&["--flip-block", f]);
        }
        args
    };
    let mut texts = Vec::new();
    for (extra, blocks) in [(&plastic[..], 9), (&quasi_static[..], 16)] {
        let text = assert_tangent_agrees(&check(extra, None), blocks);
        assert!(text.lines().any(|l| l.trim_start().starts_with("Jbar   ux")), "{text}");
        texts.push(text);
    }
    let yielded: usize = texts[0]
        .lines()
        .find_map(|l| l.strip_prefix("material points that have yielded: ").and_then(|v| v.trim().parse().ok()))
        .expect("a yield count");
    assert!(yielded >= 5, "only {yielded} points have yielded");
    let (code, text, _) = common::test_jacobian(&check(&plastic, Some("ux,Jbar")));
    assert_eq!(code, Some(1), "a negated ux–Jbar block must be seen: {text}");
}

/// A load that overflows the Newton update (NaN in the solve) ends the run `failed` on every rank
/// of a 2-rank run, with one error line and no panic; nothing aborts.
#[test]
fn a_nan_in_the_solve_ends_every_rank_failed() {
    let dir = out_dir("nan_2ranks");
    let o = mpirun(
        2,
        &[
            "run",
            "cases/terzaghi.toml",
            "--out",
            dir.to_str().unwrap(),
            "--quiet",
            "--set",
            "loads.surface.traction=[0,-1e150]",
        ],
    )
    .expect("mpirun");
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let s = summary(&dir);
    assert_eq!(s["status"], "failed");
    assert!(s["error"].as_str().unwrap().contains("DIVERGED_FNORM_NAN"), "{}", s["error"]);
    let err = stderr(&o);
    assert_eq!(err.lines().filter(|l| l.starts_with("error:")).count(), 1, "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// Sends `signal` (`INT` or `TERM`) to a `porompm run` once its running summary counts `after`
/// steps, and returns its exit status.
fn interrupt_run(args: &[&str], dir: &Path, signal: &str, after: u64) -> std::process::ExitStatus {
    let mut child = Command::new(bin())
        .args(args)
        .current_dir(root())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("the porompm binary runs");
    let t0 = std::time::Instant::now();
    loop {
        let steps = std::fs::read_to_string(dir.join("summary.json"))
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .and_then(|s| s["steps"].as_u64())
            .unwrap_or(0);
        if steps >= after {
            break;
        }
        assert!(t0.elapsed().as_secs() < 120, "the run never reached {after} steps");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let sent = Command::new("kill").args([&format!("-{signal}"), &child.id().to_string()]).status().unwrap();
    assert!(sent.success());
    child.wait().unwrap()
}

/// SIGINT (and SIGTERM) stop a run after a complete step: exit code 130, `summary.json` says
/// `interrupted` with the steps done and how to continue, the last step's fields and a checkpoint
/// are written, and `--restart` from it ends with the metrics of an uninterrupted run; the running
/// summary counts the steps while the run goes.
#[test]
fn an_interrupted_run_leaves_a_checkpoint_and_its_restart_matches_the_uninterrupted_run() {
    // 6 000 steps (3 s on an idle machine): the running summary is rewritten at most once a
    // second, so the signal comes a second into the run at the earliest; with 2 000 steps (1 s
    // idle) the run had sometimes ended before it.
    let full = out_dir("interrupt-full");
    let base =
        ["run", "cases/terzaghi.toml", "--quiet", "--set", "stages.0.duration=6", "--set", "output.history_every=1"];
    let o = porompm(&[&base[..], &["--out", full.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    for signal in ["INT", "TERM"] {
        let dir = out_dir(&format!("interrupt-{signal}"));
        let args = [&base[..], &["--out", dir.to_str().unwrap()]].concat();
        let status = interrupt_run(&args, &dir, signal, 50);
        assert_eq!(status.code(), Some(130), "SIG{signal}: exit status {status:?}");
        let s = summary(&dir);
        assert_eq!(s["status"], "interrupted", "SIG{signal}: {s}");
        let steps = s["steps"].as_u64().unwrap();
        assert!((50..6000).contains(&steps), "SIG{signal}: {steps} steps");
        assert!(s["error"].as_str().unwrap().contains("--restart"), "{s}");
        for f in ["checkpoint.h5", "fields.h5", "fields.xdmf", "history.csv"] {
            assert!(dir.join(f).is_file(), "SIG{signal}: {f} missing");
        }
        let cp = dir.join("checkpoint.h5");
        let o = porompm(&[&args[..], &["--restart", cp.to_str().unwrap()]].concat());
        assert!(o.status.success(), "restart after SIG{signal}: {}", stderr(&o));
        let (a, b) = (summary(&dir), summary(&full));
        assert_eq!(a["steps"], b["steps"]);
        for (name, m) in b["verification"].as_object().unwrap() {
            let (x, y) = (a["verification"][name]["value"].as_f64().unwrap(), m["value"].as_f64().unwrap());
            assert!(
                (x - y).abs() <= 1e-9 * y.abs(),
                "SIG{signal}: {name} {x:e} after the restart, {y:e} uninterrupted"
            );
        }
    }
}

/// Garbage in a PETSc options file is one clear porompm error naming the file and line, never
/// PETSc's traceback: text that is not an option, a token left over after an option's value, two
/// options on a line, binary content, an incomplete `alias`, and a nested `-options_file` that does
/// not exist. Every shipped options file passes the same check.
#[test]
fn garbage_in_an_options_file_is_one_clear_error() {
    let dir = out_dir("garbage-options");
    std::fs::create_dir_all(&dir).unwrap();
    let cases: [(&str, &[u8], &str); 7] = [
        ("text.opts", b"# a comment\n-ksp_type preonly\nthis is not an option\n", "line 3: `this` is not an option"),
        ("extra.opts", b"-ksp_rtol 1e-4\n-pc_use_amat false; see docs\n", "line 2: `see` is left over"),
        ("two.opts", b"-snes_monitor -ksp_monitor\n", "line 1: two options on one line"),
        ("quoted.opts", b"-snes_view_pre \"ascii:x.txt\" tail\n", "line 1: `tail` is left over"),
        ("binary.opts", &[0xff, 0xfe, 0x00, 0x13, 0x37, 0x80], "is not a text file"),
        ("alias.opts", b"alias -only_one\n", "line 1: `alias` needs two option names"),
        ("nested.opts", b"-options_file /nonexistent/porompm.opts\n", "/nonexistent/porompm.opts does not exist"),
    ];
    for (name, content, needle) in cases {
        let f = dir.join(name);
        std::fs::write(&f, content).unwrap();
        let out = dir.join(format!("run-{name}"));
        let o = porompm(&[
            "run",
            "cases/terzaghi.toml",
            "--out",
            out.to_str().unwrap(),
            "--options-file",
            f.to_str().unwrap(),
        ]);
        assert_one_line_error(&o, needle);
    }
    for entry in std::fs::read_dir(root().join("petsc_options")).unwrap() {
        let f = entry.unwrap().path();
        porompm::io::check_petsc_options_file(&f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
    }
}

/// Bad settings of the analysis types and of the run: each one error naming the key or flag.
#[test]
fn bad_analysis_settings_are_named() {
    for (case, set, needle) in [
        ("cases/terzaghi.toml", "stages.0.theta=0.3", "key `stages.consolidation.theta`: only a quasi_static stage"),
        ("cases/elastic_column.toml", "stages.0.analysis=quasi_static", "needs `analysis.formulation = \"two_phase\"`"),
        ("cases/terzaghi.toml", "stages.0.analysis=static", "key `stages.consolidation.drainage`"),
        ("cases/terzaghi.toml", "stages.0.dt_max=-1", "key `stages.consolidation.dt_max`"),
        ("cases/terzaghi.toml", "time_integration.rho_inf=1.5", "key `time_integration.rho_inf`"),
        ("cases/terzaghi.toml", "stabilisation.pressure_update=bogus", "expected `increments` or `projected_total`"),
    ] {
        let o = porompm(&["check", case, "--set", set]);
        assert_one_line_error(&o, needle);
    }
    let out = out_dir("threads-zero");
    let o = porompm(&["run", "cases/terzaghi.toml", "--out", out.to_str().unwrap(), "--threads", "0"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--threads"), "{}", stderr(&o));
}

/// What the B-spline bases do not combine with, each refused naming the key: B̄ (too soft with
/// them), [001]'s mapped stiffnesses and CMPM recovery, and a quasi-static stage's weak drainage.
#[test]
fn bspline_bases_refuse_what_they_do_not_support() {
    for (case, sets, needle) in [
        ("cases/patch_test.toml", &["analysis.shape_functions=bspline2"][..], "key `stabilisation.bbar`"),
        (
            "cases/hollow_cylinder_increments.toml",
            &["analysis.shape_functions=bspline3"][..],
            "key `stabilisation.stiffness`",
        ),
        (
            "cases/hollow_cylinder_increments.toml",
            &["analysis.shape_functions=bspline3", "stabilisation.stiffness=particle"][..],
            "key `stabilisation.stress_recovery`",
        ),
        (
            "cases/terzaghi.toml",
            &["analysis.shape_functions=bspline2", "stages.0.analysis=quasi_static"][..],
            "key `stages.consolidation.analysis`",
        ),
    ] {
        let mut args = vec!["check", case];
        for s in sets {
            args.extend(["--set", s]);
        }
        assert_one_line_error(&porompm(&args), needle);
    }
    let o = porompm(&["check", "cases/terzaghi.toml", "--set", "analysis.shape_functions=bspline3"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// More bad values, each one error naming its key: the grid, bodies, stages, probes, the
/// verification, the time integration, the output, the stabilisation and the loads.
#[test]
fn bad_values_across_the_case_are_named() {
    assert_sets_refused(
        "cases/terzaghi.toml",
        &[
            ("grid.size=[-1.0,1.0]", "key `grid.size[0]`: must be a positive number"),
            ("grid.origin=[nan,0.0]", "key `grid.origin`: must be finite"),
            ("bodies.0.particles_per_cell=0", "key `bodies[0].particles_per_cell`: must be between 1 and 8"),
            ("bodies.0.material=nonesuch", "key `bodies[0].material`: no material named `nonesuch`"),
            ("bodies.0.perturbation=-1", "key `bodies[0].perturbation`: must be in [0, 0.5)"),
            ("stages.0.duration=0", "key `stages[0].duration`: must be a positive number"),
            ("stages.0.dt=-1", "key `stages[0].dt`: must be a positive number"),
            ("stages.0.cut_factor=1.5", "key `stages[0].cut_factor`: must be in (0, 1)"),
            ("stages.0.max_step_cuts=1000", "key `stages[0].max_step_cuts`: at most 30"),
            ("stages.0.loads=[\"nonesuch\"]", "key `stages[0].loads`: no load named `nonesuch`"),
            ("stages.0.boundaries=[\"nonesuch\"]", "key `stages[0].boundaries`: no boundary named `nonesuch`"),
            ("probes.0.point=[5.0,5.0]", "key `probes[0].point`: [5.0, 5.0] is outside the grid"),
            ("verification.time_factors=[-1.0]", "key `verification.time_factors`: give positive time factors"),
            ("verification.body=nonesuch", "key `verification.body`: no body named `nonesuch`"),
            ("verification.load=nonesuch", "key `verification.load`: no load named `nonesuch`"),
            ("time_integration.beta=0.1", "key `time_integration`: β = 0.1, γ = 0.5 is not unconditionally stable"),
            ("output.history_every=0", "key `output.history_every`: must be at least 1"),
            ("materials.0.model.poisson_ratio=0.5", "key `materials[0].model.poisson_ratio`: must be in (-1, 0.5)"),
            ("materials.0.water_density=0", "key `materials[0].water_density`: must be a positive number"),
            (
                "stabilisation.pressure_projection=-1",
                "key `stabilisation.pressure_projection`: must be a positive number",
            ),
            ("stabilisation.pressure_projection=1e9", "key `stabilisation.pressure_projection`: must be at most 1e3"),
            ("boundaries.0.side=nowhere", "--set boundaries.0.side: unknown variant `nowhere`"),
            ("boundaries.0.fix=[\"uw\"]", "--set boundaries.0.fix: unknown variant `uw`"),
            (
                "boundaries.0.fix=[\"uz\"]",
                "key `boundaries[0].fix`: z (a `z_min`/`z_max` side or face, `uz`/`Uz`, a region's `z`) belongs to \
                 three-dimensional cases only",
            ),
            ("loads.0.face=top", "key `loads[0]`: unknown variant `top`"),
            ("loads.0.traction=[nan,0.0]", "key `loads[0].traction`: must be finite"),
            ("analysis.g=-1", "key `analysis.g`: must be a positive number"),
        ],
    );
    // A clamp on a line the grid does not have (x = 0 with nodes at x = −4.5 + i) would hold nothing.
    assert_sets_refused(
        "cases/cook_membrane.toml",
        &[
            ("grid.origin=[-4.5,-4.5]", "key `boundaries[0].region`: holds no grid node"),
            ("verification.tolerance=1.5", "key `verification.tolerance`: must be in (0, 1)"),
            ("verification.fit_radius=0.5", "key `verification.fit_radius`: must be in [1, 10] cells"),
            ("verification.body=nonesuch", "key `verification.body`: no body named `nonesuch`"),
        ],
    );
    // Xie & Leo's reference needs their conductivity law.
    assert_sets_refused(
        "cases/large_strain_consolidation.toml",
        &[(
            "materials.0.hydraulic_conductivity_law=constant",
            "key `verification.body`: the large-strain reference assumes hydraulic_conductivity_law = \"xie_leo\"",
        )],
    );
}

/// `porompm check` lists the physics warnings of a case (what would lock or oscillate), and a
/// shipped case has none.
#[test]
fn check_lists_the_physics_warnings() {
    let o = porompm(&["check", "cases/terzaghi.toml"]);
    assert!(o.status.success());
    assert!(!String::from_utf8_lossy(&o.stdout).contains("warning"), "{}", String::from_utf8_lossy(&o.stdout));
    for (sets, kind) in [
        (&["materials.0.model.poisson_ratio=0.495"][..], "warning [locking]"),
        (&["materials.0.hydraulic_conductivity=1e-12"][..], "warning [equal_order_near_undrained]"),
        (
            &["time_integration.rho_inf=1.0", "time.dt=1e-2", "stages.0.duration=1.0"][..],
            "warning [undamped_large_step]",
        ),
    ] {
        let mut args = vec!["check", "cases/terzaghi.toml"];
        for s in sets {
            args.extend(["--set", s]);
        }
        let o = porompm(&args);
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success() && out.contains(kind), "{sets:?}: {out}");
    }
}

/// A stage's strength reduction and the run-out check refuse what they cannot use, naming the key.
#[test]
fn strength_reduction_and_runout_input_is_refused_with_a_clear_message() {
    assert_sets_refused(
        "cases/landslide_3d.toml",
        &[
            (
                "stages.failure.strength_reduction=0",
                "key `stages.failure.strength_reduction`: the strength reduction factor F = 0",
            ),
            ("stages.failure.strength_reduction=1000", "must lie in (0, 100]"),
            ("verification.trigger_stage=nowhere", "key `verification.trigger_stage`: no stage named `nowhere`"),
            ("verification.snapshot_times=[9.0]", "key `verification.snapshot_times`: 9 s is not within"),
            ("verification.spray_fraction=0.5", "key `verification.spray_fraction`: must be in [0, 0.05]"),
            ("verification.standing_speed=0", "verification.standing_speed"),
            ("verification.body=rock", "key `verification.body`: no body named `rock`"),
        ],
    );
}

/// Input that used to run silently to a wrong answer, each now one error naming the key: a body
/// that holds no material point, two bodies that overlap, a polygon that crosses itself, a plane
/// load region with a z extent, a `--set` of a parameter the case does not declare, two stages of
/// one name, a PETSc option without its dash.
#[test]
fn geometry_and_names_that_would_be_ignored_are_named() {
    assert_sets_refused(
        "cases/terzaghi.toml",
        &[
            (
                "bodies.0.shape={rectangle={min=[0.0,0.0],max=[0.1,0.01]}}",
                "key `bodies[0].shape`: body `column` holds no material point",
            ),
            (
                "bodies.0.shape={polygon={vertices=[[0.0,0.0],[0.1,1.0],[0.1,0.0],[0.0,1.0]]}}",
                "the polygon crosses itself: its edges 0–1 and 2–3 meet",
            ),
            (
                "bodies.0.shape={polygon={vertices=[[0.0,0.0],[0.1,0.0],[0.05,0.0],[0.05,1.0]]}}",
                "the polygon crosses itself",
            ),
            (
                "loads.0.region={min=[0.0,0.5],max=[0.1,1.0],z=[0.0,1.0]}",
                "key `loads[0].region.z`: only a three-dimensional case",
            ),
            ("parameters.h=0.5", "--set parameters.h: the case declares no parameters, so none named `h`"),
        ],
    );
    assert_sets_refused(
        "cases/footing_ld.toml",
        &[(
            "bodies.1.shape={rectangle={min=[0.0,0.0],max=[5.0,5.25]}}",
            "key `bodies[1].shape`: body `soil` overlaps body `footing` (bodies[0]): 8 of its",
        )],
    );
    assert_sets_refused(
        "cases/footing_sd.toml",
        &[("parameters.H=0.5", "--set parameters.H: the case declares no parameter `H` (it declares: ")],
    );
    assert_sets_refused(
        "cases/elastic_column.toml",
        &[("stages.1.name=self_weight", "stages: the name `self_weight` is used twice")],
    );
    for (words, needle) in [
        (&["snes_type", "newtonls"][..], "PETSc option `snes_type` (after `--`): an option's name begins with `-`"),
        (&["-snes_type", "newtonls", "basic"][..], "PETSc option `basic` (after `--`)"),
    ] {
        let out = out_dir("petsc-words");
        let mut args = vec!["run", "cases/terzaghi.toml", "--out", out.to_str().unwrap(), "--"];
        args.extend(words);
        assert_one_line_error(&porompm(&args), needle);
    }
}

/// A face traction whose region holds no loaded face (here the column's top is at y = 1 m, the
/// region below it) ends the run at its set-up, naming the load's key, and leaves an earlier
/// run's results in the directory as they were.
#[test]
fn a_load_that_acts_on_nothing_is_named_and_a_run_that_fails_to_start_changes_nothing() {
    let out = out_dir("load-on-nothing");
    let o = porompm(&["run", "cases/terzaghi.toml", "--out", out.to_str().unwrap(), "--quiet"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let before = std::fs::read(out.join("summary.json")).unwrap();
    let o = porompm(&[
        "run",
        "cases/terzaghi.toml",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--set",
        "loads.0.region={min=[0.0,0.0],max=[0.1,0.4]}",
    ]);
    assert_one_line_error(&o, "key `loads[0].region`: load `surface` acts on no material point");
    assert_eq!(std::fs::read(out.join("summary.json")).unwrap(), before, "the finished run's summary is kept");
    assert!(out.join("history.csv").exists());
}

/// A case too large for this machine (a 6000 × 6000 grid: about 10¹² B) is refused before
/// anything is allocated, with one line giving what it needs and what the machine has, by `run`
/// and by `check`; `check` prints the estimate of a case that fits.
#[test]
fn a_case_too_large_for_the_machine_is_refused_at_once() {
    let out = out_dir("too-large");
    let out = out.to_str().unwrap();
    let big = "grid.cells=[6000,6000]";
    for args in [
        vec!["check", "cases/terzaghi.toml", "--set", big],
        vec!["run", "cases/terzaghi.toml", "--out", out, "--set", big],
    ] {
        assert_one_line_error(&porompm(&args), "of memory on this machine (");
    }
    let o = porompm(&["check", "cases/terzaghi.toml"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success() && text.contains("\nmemory: about "), "{text}");
}

/// A sweep of bad values (NaN, ∞, −1, 0, 1e300, a string, an empty array for the numeric keys of
/// eight cases) and of bad geometry: each one error line on `check` naming the key it concerns
/// (for a derived value, the key the expression lands in; for a value of the wrong type, the
/// `--set` that gave it).
#[test]
fn a_sweep_of_bad_values_names_each_key() {
    let table: &[(&str, &[&str], &str)] = &[
        ("cases/terzaghi.toml", &["time.dt=nan"][..], "key `stages[0].dt`"),
        ("cases/terzaghi.toml", &["time.dt=inf"][..], "key `stages[0].dt`"),
        ("cases/terzaghi.toml", &["time.dt=-1"][..], "key `stages[0].dt`"),
        ("cases/terzaghi.toml", &["time.dt=0"][..], "key `stages[0].dt`"),
        ("cases/terzaghi.toml", &["time.dt=1e300"][..], "key `stages[0].dt`"),
        ("cases/terzaghi.toml", &["time.dt=\"abc\""][..], "--set time.dt:"),
        ("cases/terzaghi.toml", &["time.dt=[]"][..], "--set time.dt:"),
        ("cases/terzaghi.toml", &["materials.soil.porosity=nan"][..], "key `materials[0].porosity`"),
        ("cases/terzaghi.toml", &["materials.soil.porosity=inf"][..], "key `materials[0].porosity`"),
        ("cases/terzaghi.toml", &["materials.soil.porosity=-1"][..], "key `materials[0].porosity`"),
        ("cases/terzaghi.toml", &["materials.soil.porosity=0"][..], "key `materials[0].porosity`"),
        ("cases/terzaghi.toml", &["materials.soil.porosity=1e300"][..], "key `materials[0].porosity`"),
        ("cases/terzaghi.toml", &["materials.soil.porosity=\"abc\""][..], "--set materials.soil.porosity:"),
        ("cases/terzaghi.toml", &["materials.soil.porosity=[]"][..], "--set materials.soil.porosity:"),
        (
            "cases/terzaghi.toml",
            &["materials.soil.hydraulic_conductivity=nan"][..],
            "key `materials[0].hydraulic_conductivity`",
        ),
        (
            "cases/terzaghi.toml",
            &["materials.soil.hydraulic_conductivity=inf"][..],
            "key `materials[0].hydraulic_conductivity`",
        ),
        (
            "cases/terzaghi.toml",
            &["materials.soil.hydraulic_conductivity=-1"][..],
            "key `materials[0].hydraulic_conductivity`",
        ),
        (
            "cases/terzaghi.toml",
            &["materials.soil.hydraulic_conductivity=0"][..],
            "key `materials[0].hydraulic_conductivity`",
        ),
        (
            "cases/terzaghi.toml",
            &["materials.soil.hydraulic_conductivity=1e300"][..],
            "key `materials[0].hydraulic_conductivity`",
        ),
        (
            "cases/terzaghi.toml",
            &["materials.soil.hydraulic_conductivity=\"abc\""][..],
            "--set materials.soil.hydraulic_conductivity:",
        ),
        (
            "cases/terzaghi.toml",
            &["materials.soil.hydraulic_conductivity=[]"][..],
            "--set materials.soil.hydraulic_conductivity:",
        ),
        (
            "cases/terzaghi.toml",
            &["materials.soil.model.young_modulus=nan"][..],
            "key `materials[0].model.young_modulus`",
        ),
        (
            "cases/terzaghi.toml",
            &["materials.soil.model.young_modulus=inf"][..],
            "key `materials[0].model.young_modulus`",
        ),
        (
            "cases/terzaghi.toml",
            &["materials.soil.model.young_modulus=-1"][..],
            "key `materials[0].model.young_modulus`",
        ),
        (
            "cases/terzaghi.toml",
            &["materials.soil.model.young_modulus=0"][..],
            "key `materials[0].model.young_modulus`",
        ),
        (
            "cases/terzaghi.toml",
            &["materials.soil.model.young_modulus=1e300"][..],
            "key `materials[0].model.young_modulus`",
        ),
        ("cases/terzaghi.toml", &["materials.soil.model.young_modulus=\"abc\""][..], "key `materials[0].model`"),
        ("cases/terzaghi.toml", &["materials.soil.model.young_modulus=[]"][..], "key `materials[0].model`"),
        (
            "cases/terzaghi.toml",
            &["bodies.column.particles_per_cell=nan"][..],
            "--set bodies.column.particles_per_cell:",
        ),
        (
            "cases/terzaghi.toml",
            &["bodies.column.particles_per_cell=inf"][..],
            "--set bodies.column.particles_per_cell:",
        ),
        (
            "cases/terzaghi.toml",
            &["bodies.column.particles_per_cell=-1"][..],
            "--set bodies.column.particles_per_cell:",
        ),
        ("cases/terzaghi.toml", &["bodies.column.particles_per_cell=0"][..], "key `bodies[0].particles_per_cell`"),
        (
            "cases/terzaghi.toml",
            &["bodies.column.particles_per_cell=1e300"][..],
            "--set bodies.column.particles_per_cell:",
        ),
        (
            "cases/terzaghi.toml",
            &["bodies.column.particles_per_cell=\"abc\""][..],
            "--set bodies.column.particles_per_cell:",
        ),
        (
            "cases/terzaghi.toml",
            &["bodies.column.particles_per_cell=[]"][..],
            "--set bodies.column.particles_per_cell:",
        ),
        ("cases/terzaghi.toml", &["stages.consolidation.duration=nan"][..], "key `stages[0].duration`"),
        ("cases/terzaghi.toml", &["stages.consolidation.duration=inf"][..], "key `stages[0].duration`"),
        ("cases/terzaghi.toml", &["stages.consolidation.duration=-1"][..], "key `stages[0].duration`"),
        ("cases/terzaghi.toml", &["stages.consolidation.duration=0"][..], "key `stages[0].duration`"),
        ("cases/terzaghi.toml", &["stages.consolidation.duration=1e300"][..], "key `stages[0].dt`"),
        ("cases/terzaghi.toml", &["stages.consolidation.duration=\"abc\""][..], "--set stages.consolidation.duration:"),
        ("cases/terzaghi.toml", &["stages.consolidation.duration=[]"][..], "--set stages.consolidation.duration:"),
        ("cases/terzaghi.toml", &["loads.surface.traction=nan"][..], "key `loads[0]`"),
        ("cases/terzaghi.toml", &["loads.surface.traction=inf"][..], "key `loads[0]`"),
        ("cases/terzaghi.toml", &["loads.surface.traction=-1"][..], "key `loads[0]`"),
        ("cases/terzaghi.toml", &["loads.surface.traction=0"][..], "key `loads[0]`"),
        ("cases/terzaghi.toml", &["loads.surface.traction=1e300"][..], "key `loads[0]`"),
        ("cases/terzaghi.toml", &["loads.surface.traction=\"abc\""][..], "key `loads[0]`"),
        ("cases/terzaghi.toml", &["loads.surface.traction=[]"][..], "key `loads[0].traction`"),
        ("cases/terzaghi.toml", &["grid.size=nan"][..], "--set grid.size:"),
        ("cases/terzaghi.toml", &["grid.size=inf"][..], "--set grid.size:"),
        ("cases/terzaghi.toml", &["grid.size=-1"][..], "--set grid.size:"),
        ("cases/terzaghi.toml", &["grid.size=0"][..], "--set grid.size:"),
        ("cases/terzaghi.toml", &["grid.size=1e300"][..], "--set grid.size:"),
        ("cases/terzaghi.toml", &["grid.size=\"abc\""][..], "--set grid.size:"),
        ("cases/terzaghi.toml", &["grid.size=[]"][..], "key `grid.size`"),
        ("cases/terzaghi.toml", &["grid.cells=nan"][..], "--set grid.cells:"),
        ("cases/terzaghi.toml", &["grid.cells=inf"][..], "--set grid.cells:"),
        ("cases/terzaghi.toml", &["grid.cells=-1"][..], "--set grid.cells:"),
        ("cases/terzaghi.toml", &["grid.cells=0"][..], "--set grid.cells:"),
        ("cases/terzaghi.toml", &["grid.cells=1e300"][..], "--set grid.cells:"),
        ("cases/terzaghi.toml", &["grid.cells=\"abc\""][..], "--set grid.cells:"),
        ("cases/terzaghi.toml", &["grid.cells=[]"][..], "key `grid.cells`"),
        ("cases/footing_sd.toml", &["materials.clay.model.cohesion=1e300"][..], "key `materials[0].model.cohesion`"),
        ("cases/footing_sd.toml", &["verification.tolerance=1e300"][..], "key `verification.tolerance`"),
        ("cases/footing_sd.toml", &["verification.tolerance=2"][..], "key `verification.tolerance`"),
        ("cases/dam_break.toml", &["materials.water.model.viscosity=1e300"][..], "key `materials[0].model.viscosity`"),
        ("cases/footing_sd.toml", &["parameters.h=nan"][..], "key `grid.cells[0]`"),
        ("cases/footing_sd.toml", &["parameters.h=inf"][..], "key `grid.size[1]`"),
        ("cases/footing_sd.toml", &["parameters.h=-1"][..], "key `grid.cells[0]`"),
        ("cases/footing_sd.toml", &["parameters.h=0"][..], "key `grid.cells[0]`"),
        ("cases/footing_sd.toml", &["parameters.h=1e300"][..], "key `grid.cells[0]`"),
        ("cases/footing_sd.toml", &["parameters.h=\"abc\""][..], "key `parameters.h`"),
        ("cases/footing_sd.toml", &["parameters.h=[]"][..], "key `parameters.h`"),
        ("cases/footing_sd.toml", &["materials.clay.model.cohesion=nan"][..], "key `materials[0].model.cohesion`"),
        ("cases/footing_sd.toml", &["materials.clay.model.cohesion=inf"][..], "key `materials[0].model.cohesion`"),
        ("cases/footing_sd.toml", &["materials.clay.model.cohesion=-1"][..], "key `materials[0].model.cohesion`"),
        ("cases/footing_sd.toml", &["materials.clay.model.cohesion=0"][..], "key `materials[0].model.cohesion`"),
        ("cases/footing_sd.toml", &["materials.clay.model.cohesion=\"abc\""][..], "key `materials[0].model`"),
        ("cases/footing_sd.toml", &["materials.clay.model.cohesion=[]"][..], "key `materials[0].model`"),
        ("cases/footing_sd.toml", &["bodies.soil.perturbation=nan"][..], "key `bodies[0].perturbation`"),
        ("cases/footing_sd.toml", &["bodies.soil.perturbation=inf"][..], "key `bodies[0].perturbation`"),
        ("cases/footing_sd.toml", &["bodies.soil.perturbation=-1"][..], "key `bodies[0].perturbation`"),
        ("cases/footing_sd.toml", &["bodies.soil.perturbation=1e300"][..], "key `bodies[0].perturbation`"),
        ("cases/footing_sd.toml", &["bodies.soil.perturbation=\"abc\""][..], "--set bodies.soil.perturbation:"),
        ("cases/footing_sd.toml", &["bodies.soil.perturbation=[]"][..], "--set bodies.soil.perturbation:"),
        ("cases/footing_sd.toml", &["verification.tolerance=nan"][..], "key `verification.tolerance`"),
        ("cases/footing_sd.toml", &["verification.tolerance=inf"][..], "key `verification.tolerance`"),
        ("cases/footing_sd.toml", &["verification.tolerance=-1"][..], "key `verification.tolerance`"),
        ("cases/footing_sd.toml", &["verification.tolerance=0"][..], "key `verification.tolerance`"),
        ("cases/footing_sd.toml", &["verification.tolerance=\"abc\""][..], "key `verification`"),
        ("cases/footing_sd.toml", &["verification.tolerance=[]"][..], "key `verification`"),
        ("cases/dam_break.toml", &["materials.water.model.viscosity=nan"][..], "key `materials[0].model.viscosity`"),
        ("cases/dam_break.toml", &["materials.water.model.viscosity=inf"][..], "key `materials[0].model.viscosity`"),
        ("cases/dam_break.toml", &["materials.water.model.viscosity=-1"][..], "key `materials[0].model.viscosity`"),
        ("cases/dam_break.toml", &["materials.water.model.viscosity=\"abc\""][..], "key `materials[0].model`"),
        ("cases/dam_break.toml", &["materials.water.model.viscosity=[]"][..], "key `materials[0].model`"),
        ("cases/dam_break.toml", &["time.dt=nan"][..], "key `stages[0].dt`"),
        ("cases/dam_break.toml", &["time.dt=inf"][..], "key `stages[0].dt`"),
        ("cases/dam_break.toml", &["time.dt=-1"][..], "key `stages[0].dt`"),
        ("cases/dam_break.toml", &["time.dt=0"][..], "key `stages[0].dt`"),
        ("cases/dam_break.toml", &["time.dt=1e300"][..], "key `stages[0].dt`"),
        ("cases/dam_break.toml", &["time.dt=\"abc\""][..], "--set time.dt:"),
        ("cases/dam_break.toml", &["time.dt=[]"][..], "--set time.dt:"),
        ("cases/landslide_3d.toml", &["grid.cells=nan"][..], "--set grid.cells:"),
        ("cases/landslide_3d.toml", &["grid.cells=inf"][..], "--set grid.cells:"),
        ("cases/landslide_3d.toml", &["grid.cells=-1"][..], "--set grid.cells:"),
        ("cases/landslide_3d.toml", &["grid.cells=0"][..], "--set grid.cells:"),
        ("cases/landslide_3d.toml", &["grid.cells=1e300"][..], "--set grid.cells:"),
        ("cases/landslide_3d.toml", &["grid.cells=\"abc\""][..], "--set grid.cells:"),
        ("cases/landslide_3d.toml", &["grid.cells=[]"][..], "key `grid.cells`"),
        ("cases/landslide_3d.toml", &["bodies.0.z=nan"][..], "--set bodies.0.z:"),
        ("cases/landslide_3d.toml", &["bodies.0.z=inf"][..], "--set bodies.0.z:"),
        ("cases/landslide_3d.toml", &["bodies.0.z=-1"][..], "--set bodies.0.z:"),
        ("cases/landslide_3d.toml", &["bodies.0.z=0"][..], "--set bodies.0.z:"),
        ("cases/landslide_3d.toml", &["bodies.0.z=1e300"][..], "--set bodies.0.z:"),
        ("cases/landslide_3d.toml", &["bodies.0.z=\"abc\""][..], "--set bodies.0.z:"),
        ("cases/landslide_3d.toml", &["bodies.0.z=[]"][..], "--set bodies.0.z:"),
        (
            "cases/terzaghi.toml",
            &["bodies.column.shape={rectangle={min=[0.0,0.0],max=[0.1,0.01]}}"][..],
            "key `bodies[0].shape`",
        ),
        (
            "cases/terzaghi.toml",
            &["bodies.column.shape={rectangle={min=[0.05,0.0],max=[0.05,1.0]}}"][..],
            "key `bodies[0].shape.rectangle`",
        ),
        (
            "cases/terzaghi.toml",
            &["bodies.column.shape={polygon={vertices=[[0.0,0.0],[0.1,1.0],[0.1,0.0],[0.0,1.0]]}}"][..],
            "key `bodies[0].shape.polygon.vertices`",
        ),
        (
            "cases/terzaghi.toml",
            &["bodies.column.shape={polygon={vertices=[[0.0,0.0],[0.1,0.0],[0.1,0.0],[0.0,1.0]]}}"][..],
            "key `bodies[0].shape.polygon.vertices`",
        ),
        (
            "cases/terzaghi.toml",
            &["bodies.column.shape={polygon={vertices=[[0.0,0.0],[0.1,0.0]]}}"][..],
            "key `bodies[0].shape.polygon.vertices`",
        ),
        (
            "cases/terzaghi.toml",
            &["bodies.column.shape={rectangle={min=[0.0,0.0],max=[0.2,1.0]}}"][..],
            "key `bodies[0].shape`",
        ),
        (
            "cases/terzaghi.toml",
            &["bodies.column.shape={rectangle={min=[0.1,0.0],max=[0.0,1.0]}}"][..],
            "key `bodies[0].shape.rectangle`",
        ),
        (
            "cases/terzaghi.toml",
            &["loads.surface.region={min=[0.0,0.5],max=[0.1,1.0],z=[0.0,1.0]}"][..],
            "key `loads[0].region.z`",
        ),
        ("cases/terzaghi.toml", &["loads.surface.region={min=[0.0,2.0],max=[0.1,3.0]}"][..], "key `loads[0].region`"),
        ("cases/terzaghi.toml", &["probes.0.point=[0.05,1.5]"][..], "key `probes[0].point`"),
        (
            "cases/footing_ld.toml",
            &["bodies.soil.shape={rectangle={min=[0.0,0.0],max=[5.0,5.25]}}"][..],
            "key `bodies[1].shape`",
        ),
        (
            "cases/footing_ld.toml",
            &["bodies.footing.shape={rectangle={min=[0.0,4.0],max=[0.5,4.5]}}"][..],
            "key `bodies[1].shape`",
        ),
        (
            "cases/footing_ld.toml",
            &["bodies.footing.shape={rectangle={min=[0.0,5.0],max=[0.5,5.01]}}"][..],
            "key `bodies[0].shape`",
        ),
        (
            "cases/slope_clay.toml",
            &["bodies.0.shape={polygon={vertices=[[0.0,0.0],[1.0,1.0],[1.0,0.0],[0.0,1.0]]}}"][..],
            "key `bodies[0].shape.polygon.vertices`",
        ),
        ("cases/terzaghi.toml", &["parameters.h=0.5"][..], "--set parameters.h:"),
        ("cases/footing_sd.toml", &["parameters.H=0.5"][..], "--set parameters.H:"),
        ("cases/terzaghi.toml", &["stages.0.loads=[\"surface\",\"surface\"]"][..], "key `stages[0].loads`"),
        ("cases/landslide_3d.toml", &["bodies.0.z=[0.5,0.1]"][..], "key `bodies[0].z`"),
        ("cases/hollow_cylinder.toml", &["loads.0.points=[[0.0,0.0]]"][..], "key `loads[0]`"),
    ];
    assert!(table.len() >= 100, "the sweep has {} inputs", table.len());
    for (case, sets, needle) in table {
        let mut args = vec!["check", *case];
        for s in *sets {
            args.extend(["--set", s]);
        }
        println!("{args:?}");
        assert_one_line_error(&porompm(&args), needle);
    }
}
