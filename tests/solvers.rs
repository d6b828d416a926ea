//! The linear solves see every field: a Krylov solve stopped at `-ksp_rtol` leaves the residual of
//! each field (u, p, U), relative to its own equations' terms, within 10 × rtol, on the u–p–U and
//! the u–p systems and under both residual norms PETSc offers (left-preconditioned, and right with
//! the true residual); a direct solve leaves it at round-off. Without porompm's field-wise test,
//! PETSc's one norm stops while a field lags far behind: the measure sees it.

mod common;
use common::{run_case, run_case_on, set_args, Run};
use std::path::PathBuf;

const RTOL: f64 = 1e-6;

fn dir(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("porompm-solvers-{name}-{}", std::process::id()))
}

/// The slumping block (u–p–U, dynamic, stabilised) for a few steps on a small grid.
fn upu() -> (&'static str, Vec<String>) {
    let sets = ["stages.slump.duration=0.005", "grid.cells=[24,18]", "stabilisation.pressure_projection=1.0"];
    ("cases/slumping_block.toml", set_args(&sets))
}

/// The consolidating layer (u–p, quasi-static) for its first steps on a small grid.
fn up() -> (&'static str, Vec<String>) {
    ("cases/consolidation_layer.toml", set_args(&["stages.consolidation.duration=0.01", "grid.cells=[20,20]"]))
}

/// Runs `system` with the Schur field split at RTOL and the extra PETSc options.
fn krylov(name: &str, system: (&str, Vec<String>), petsc: &[&str]) -> Run {
    let (case, mut args) = system;
    args.extend(["--options-file".into(), "petsc_options/fieldsplit-schur-amg.opts".into(), "--".into()]);
    args.extend(["-ksp_rtol".to_string(), RTOL.to_string()]);
    args.extend(petsc.iter().map(|s| s.to_string()));
    let run = run_case(case, &dir(name), &args);
    assert!(run.completed(), "{name}: {}", run.stderr());
    run
}

/// (field, value of `key`) of each entry of a run's summary's `field_residuals`.
fn per_field(run: &Run, key: &str) -> Vec<(String, f64)> {
    run.summary["field_residuals"]
        .as_array()
        .expect("field_residuals")
        .iter()
        .map(|r| (r["field"].as_str().unwrap().to_string(), r[key].as_f64().expect("measured")))
        .collect()
}

/// (field, linear_max) of a run's summary.
fn linear(run: &Run) -> Vec<(String, f64)> {
    per_field(run, "linear_max")
}

const RIGHT: [&str; 6] = ["-ksp_type", "fgmres", "-ksp_pc_side", "right", "-ksp_norm_type", "unpreconditioned"];

#[test]
fn a_krylov_solve_at_rtol_leaves_every_field_within_ten_rtol() {
    for (name, system, fields) in [("upu", upu(), 3), ("up", up(), 2)] {
        for (norm, petsc) in [("left", &[][..]), ("right", &RIGHT[..])] {
            let run = krylov(&format!("{name}-{norm}"), system.clone(), petsc);
            let eta = linear(&run);
            eprintln!("{name}, {norm} norm: {eta:?}");
            assert_eq!(eta.len(), fields, "{eta:?}");
            for (f, e) in &eta {
                assert!(*e <= 10.0 * RTOL, "{name}, {norm}: field {f} left at {e:.2e} > 10 × {RTOL:e}");
                assert!(*e > 0.0, "{name}, {norm}: field {f} not measured");
            }
        }
    }
}

#[test]
fn without_the_field_test_the_pressure_lags_and_the_measure_shows_it() {
    // The u–p system under PETSc's preconditioned norm alone: measured 2.4e-4 (u) and 8.7e-4 (p)
    // at rtol 1e-6.
    let run = krylov("up-nofield", up(), &["-porompm_ksp_field_test", "0"]);
    let eta = linear(&run);
    eprintln!("without the field test: {eta:?}");
    assert!(eta.iter().any(|(_, e)| *e > 10.0 * RTOL), "{eta:?}");
}

#[test]
fn a_direct_solve_leaves_every_field_at_round_off() {
    for (name, (case, args)) in [("upu-lu", upu()), ("up-lu", up())] {
        let run = run_case(case, &dir(name), &args);
        assert!(run.completed(), "{name}: {}", run.stderr());
        for (f, e) in linear(&run) {
            assert!(e < 1e-11, "{name}: field {f} at {e:.2e}");
        }
        // The Newton residual of every field within the SNES tolerance (1e-6) of its own scale.
        for r in run.summary["field_residuals"].as_array().unwrap() {
            let n = r["newton_final_max"].as_f64().unwrap();
            assert!(n < 1e-6, "{name}: Newton left field {} at {n:.2e}", r["field"]);
        }
    }
}

/// Krylov iterations per Newton iteration of the consolidating layer's first three steps (u–p,
/// stabilised) on an n × n grid, under `opts` and the extra PETSc options.
fn krylov_per_newton(name: &str, n: usize, opts: &str, petsc: &[&str]) -> f64 {
    let cells = format!("grid.cells=[{n},{n}]");
    let sets = ["stages.consolidation.duration=0.0003", cells.as_str(), "stabilisation.pressure_projection=1.0"];
    let mut args = set_args(&sets);
    args.extend(["--options-file".into(), opts.into(), "--".into()]);
    args.extend(petsc.iter().map(|s| s.to_string()));
    let run = run_case("cases/consolidation_layer.toml", &dir(&format!("{name}-{n}")), &args);
    assert!(run.completed(), "{name} at {n} x {n}: {}", run.stderr());
    let newton = run.summary["snes_iterations"].as_f64().expect("snes_iterations");
    run.summary["ksp_iterations"].as_f64().expect("ksp_iterations") / newton
}

#[test]
fn the_fixed_stress_schur_preconditioner_keeps_the_iterations_flat_where_selfp_grows() {
    // Measured per Newton iteration at 20 × 20, 40 × 40, 80 × 80 cells (1.2e3 to 1.9e4 unknowns):
    // fixed stress 28.0, 22.6, 17.4; selfp with the same blocks otherwise 33.6 at 20 × 20, 51.6 at 80 × 80.
    let fixed = "petsc_options/fieldsplit-fixed-stress.opts";
    let selfp = ["-pc_fieldsplit_schur_precondition", "selfp"];
    let f: Vec<f64> = [20, 80].iter().map(|&n| krylov_per_newton("fixed-stress", n, fixed, &[])).collect();
    let s: Vec<f64> = [20, 80].iter().map(|&n| krylov_per_newton("selfp", n, fixed, &selfp)).collect();
    eprintln!("Krylov per Newton at 20 x 20 and 80 x 80: fixed stress {f:?}, selfp {s:?}");
    assert!(f[1] <= 1.1 * f[0], "fixed stress grows: {f:?}");
    assert!(f[1] <= 25.0, "fixed stress needs {} Krylov iterations per Newton at 80 x 80", f[1]);
    assert!(s[1] >= 1.3 * s[0], "selfp does not grow, so this grid sequence proves nothing: {s:?}");
}

/// The slumping block (u–p–U, stabilised) at 64 × 48 cells for one step of 4 ms.
const SLUMP_4MS: [&str; 5] = [
    "grid.cells=[64,48]",
    "time.dt=0.004",
    "stages.slump.duration=0.004",
    "stabilisation.pressure_projection=1.0",
    "output.fields_every=0",
];

/// The slumping block (u–p–U) at 64 × 48 cells for one step of 4 ms, solved by GMRES with the
/// Schur field split whose blocks are both factorised (LU), so that its Krylov iterations measure
/// the Schur approximation alone; `petsc` chooses the approximation.
fn slumping_schur(name: &str, petsc: &[&str]) -> Run {
    let mut args = set_args(&SLUMP_4MS);
    args.push("--".into());
    let exact = "-ksp_type gmres -ksp_rtol 1e-8 -ksp_max_it 300 -ksp_gmres_restart 100 -pc_type fieldsplit \
                 -pc_fieldsplit_type schur -pc_fieldsplit_schur_fact_type lower -fieldsplit_u_ksp_type preonly \
                 -fieldsplit_u_pc_type lu -fieldsplit_p_ksp_type preonly -fieldsplit_p_pc_type lu";
    args.extend(exact.split_whitespace().chain(petsc.iter().copied()).map(String::from));
    let run = run_case("cases/slumping_block.toml", &dir(name), &args);
    assert!(run.completed(), "{name}: {}", run.stderr());
    run
}

#[test]
fn the_free_surface_schur_preconditioner_of_the_dynamic_system_is_selfp_without_aggregates_and_better_with() {
    // Measured: selfp 38 Krylov iterations; the free-surface approximation 20 (23 without the
    // fixed-stress share); without aggregates and share it is selfp, iteration for iteration.
    let user = ["-pc_fieldsplit_schur_precondition", "user"];
    let selfp = slumping_schur("schur-selfp", &["-pc_fieldsplit_schur_precondition", "selfp"]);
    let bare = slumping_schur(
        "schur-bare",
        &[&user[..], &["-porompm_schur_strip_depth", "0", "-porompm_schur_fixed_stress_share", "0", "-ksp_monitor"]]
            .concat(),
    );
    let selfp_monitored =
        slumping_schur("schur-selfp-monitored", &["-pc_fieldsplit_schur_precondition", "selfp", "-ksp_monitor"]);
    // The residual norms of every Krylov iteration, as printed by -ksp_monitor.
    let norms = |r: &Run| -> Vec<f64> {
        String::from_utf8_lossy(&r.output.stdout)
            .lines()
            .filter(|l| l.contains("KSP Residual norm"))
            .map(|l| l.split_whitespace().last().unwrap().parse().unwrap())
            .collect()
    };
    let (a, b) = (norms(&bare), norms(&selfp_monitored));
    assert!(!a.is_empty() && a.len() == b.len(), "{} against {} monitored iterations", a.len(), b.len());
    for (k, (x, y)) in a.iter().zip(&b).enumerate() {
        assert!((x - y).abs() <= 1e-9 * y.abs(), "iteration {k}: {x:e} without aggregates, {y:e} with selfp");
    }
    let surface = slumping_schur("schur-surface", &user);
    let no_share = slumping_schur("schur-no-share", &[&user[..], &["-porompm_schur_fixed_stress_share", "0"]].concat());
    let its = |r: &Run| r.summary["ksp_iterations"].as_f64().expect("ksp_iterations");
    eprintln!(
        "Krylov iterations: selfp {}, user without aggregates {}, user {}",
        its(&selfp),
        its(&bare),
        its(&surface)
    );
    assert_eq!(its(&bare), its(&selfp), "the block form without groups is not selfp");
    assert!(its(&surface) <= 0.7 * its(&selfp), "{} against selfp's {}", its(&surface), its(&selfp));
    assert!(
        its(&surface) < its(&no_share),
        "the share of fixed stress does not help: {} against {}",
        its(&surface),
        its(&no_share)
    );
    // The preconditioner changes the path, not the answer.
    let direct = run_case("cases/slumping_block.toml", &dir("schur-direct"), &set_args(&SLUMP_4MS));
    assert!(direct.completed(), "direct: {}", direct.stderr());
    for name in ["P1.uy", "P1.p", "p_max"] {
        let (a, b) = (surface.column(name), direct.column(name));
        let (a, b) = (a.last().expect("a row"), b.last().expect("a row"));
        assert!((a - b).abs() <= 1e-6 * b.abs().max(1e-12), "{name}: {a} against the direct {b}");
    }
}

#[test]
fn a_user_schur_preconditioner_with_splits_of_the_options_own_is_refused_by_name() {
    let (case, mut args) = up();
    args.extend(["--options-file".into(), "petsc_options/fieldsplit-fixed-stress.opts".into(), "--".into()]);
    args.extend(["-pc_fieldsplit_0_fields", "0,1", "-pc_fieldsplit_1_fields", "2"].map(String::from));
    let run = run_case(case, &dir("user-own-splits"), &args);
    assert!(!run.output.status.success(), "a user Schur preconditioner ran on splits of the options' own");
    let err = run.stderr();
    assert!(err.contains("pc_fieldsplit_schur_precondition") && err.contains("_fields"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn an_iterative_strategy_on_an_unstabilised_case_warns_and_only_then() {
    let short = "stages.consolidation.duration=0.0002";
    let opts = |file: &str| vec!["--options-file".to_string(), format!("petsc_options/{file}.opts")];
    for (name, stabilised, file, expected) in [
        ("warn-iterative", false, "fieldsplit-fixed-stress", true),
        ("warn-stabilised", true, "fieldsplit-fixed-stress", false),
        ("warn-direct", false, "direct-lu", false),
    ] {
        let mut sets = vec![short, "grid.cells=[16,16]"];
        if stabilised {
            sets.push("stabilisation.pressure_projection=1.0");
        }
        let mut args = set_args(&sets);
        args.extend(opts(file));
        let run = run_case("cases/consolidation_layer.toml", &dir(name), &args);
        assert!(run.completed(), "{name}: {}", run.stderr());
        assert_eq!(
            common::has_warning(&run.summary, "iterative_unstabilised"),
            expected,
            "{name}: {}",
            run.summary["warnings"]
        );
    }
}

#[test]
fn the_final_newton_residual_of_each_field_shows_what_newton_left() {
    // The slumping block with one lagged-Jacobian Newton iteration per step, then with four
    // (`-snes_convergence_test skip`: every step takes exactly that many). Measured: u 8.1e-11 and
    // 8.3e-17, U 6.6e-11 and 8.5e-17 (p stays at round-off, 6e-15, both times).
    let sets = ["stages.slump.duration=0.005", "grid.cells=[24,18]"];
    let runs: Vec<Vec<(String, f64)>> = [1, 4]
        .iter()
        .map(|its| {
            let mut args = set_args(&sets);
            args.extend(["--options-file".into(), "petsc_options/newton-modified.opts".into(), "--".into()]);
            args.extend(["-snes_max_it".into(), its.to_string(), "-snes_convergence_test".into(), "skip".into()]);
            let run = run_case("cases/slumping_block.toml", &dir(&format!("newton-final-{its}")), &args);
            assert!(run.completed(), "{its} iteration(s): {}", run.stderr());
            per_field(&run, "newton_final_max")
        })
        .collect();
    eprintln!("one Newton iteration per step: {:?}; four: {:?}", runs[0], runs[1]);
    for field in ["u", "U"] {
        let get = |r: &Vec<(String, f64)>| r.iter().find(|(f, _)| f == field).expect("field").1;
        let (one, four) = (get(&runs[0]), get(&runs[1]));
        assert!(one > 1e-12, "field {field}: one lagged Newton iteration left only {one:.2e}");
        assert!(four < 1e-14 && one > 1e3 * four, "field {field}: {one:.2e} after one, {four:.2e} after four");
    }
}

/// The square footing (three-dimensional GIMP, Tresca) at k = 2 for its first four steps on `ranks`
/// ranks under gamg-solid-inexact.opts at a tight linear tolerance, the preconditioner built from
/// `pc_matrix` (`-porompm_pc_matrix`).
fn square_footing(pc_matrix: &str, ranks: usize) -> Run {
    let name = format!("square-{pc_matrix}-{ranks}");
    let mut args = set_args(&["parameters.k=2", "stages.push.duration=0.3333333333333333"]);
    args.extend(["--threads", "1", "--options-file", "petsc_options/gamg-solid-inexact.opts", "--"].map(String::from));
    args.extend(["-ksp_rtol", "1e-8", "-porompm_pc_matrix", pc_matrix].map(String::from));
    let run = run_case_on(ranks, "tests/cases/footing_square_3d.toml", &dir(&name), &args);
    assert!(run.completed(), "{name}: {}", run.stderr());
    run
}

#[test]
fn the_multilinear_preconditioning_matrix_leaves_the_answers_and_keeps_the_krylov_iterations_near() {
    // The Krylov method multiplies by the same Jacobian whichever matrix the preconditioner is built
    // from: the Newton iterations and the footing's pressure are the Jacobian's to the linear
    // tolerance. The multilinear matrix couples a node with 27 neighbours instead of 125 and costs
    // Krylov iterations for it (measured here: 496 against 293, 1.69 times; 1.27 times at k = 3
    // and 1.41 at k = 10 over whole runs at 1e-4); a matrix that were not a stiffness of the same
    // operator costs far more or fails.
    let jac = square_footing("jacobian", 1);
    let ml = square_footing("multilinear", 1);
    let ml2 = square_footing("multilinear", 2);
    let get = |r: &Run, k: &str| r.summary[k].as_f64().unwrap_or_else(|| panic!("{k} in the summary"));
    let q = |r: &Run| r.summary["results"]["q_over_c_max"].as_f64().expect("q_over_c_max");
    let (its_jac, its_ml) = (get(&jac, "ksp_iterations"), get(&ml, "ksp_iterations"));
    eprintln!("Krylov iterations: Jacobian {its_jac}, multilinear {its_ml}; q/c {} {} {}", q(&jac), q(&ml), q(&ml2));
    assert_eq!(get(&jac, "snes_iterations"), get(&ml, "snes_iterations"));
    assert!((q(&ml) / q(&jac) - 1.0).abs() < 1e-6, "{} against {}", q(&ml), q(&jac));
    assert!((q(&ml2) / q(&ml) - 1.0).abs() < 1e-6, "two ranks {} against one {}", q(&ml2), q(&ml));
    assert!(its_ml <= 2.0 * its_jac, "{its_ml} Krylov iterations against the Jacobian's {its_jac}");
    assert!(ml.summary["solver"].as_str().unwrap_or_default().contains("gamg"));
}

#[test]
fn the_multilinear_preconditioning_matrix_is_refused_where_it_does_not_apply_or_with_the_jacobian_in_the_multigrid_and_a_misspelt_one_always(
) {
    let refused = |name: &str, case: &str, value: &str, message: &str| {
        let mut args = set_args(&["stages.consolidation.duration=0.0003", "grid.cells=[8,8]"]);
        if case.contains("footing") {
            args = set_args(&["parameters.k=1", "stages.push.duration=0.08333333333333333"]);
        }
        args.extend(["--", "-porompm_pc_matrix"].map(String::from));
        args.extend(value.split(' ').map(String::from));
        let r = run_case(case, &dir(name), &args);
        assert_ne!(r.output.status.code(), Some(0), "{name}: {}", r.stderr());
        assert!(r.stderr().contains(message), "{name}: `{message}` not in: {}", r.stderr());
        assert!(!r.completed(), "{name}");
    };
    refused("pcm-up", "cases/consolidation_layer.toml", "multilinear", "one-phase solid's displacements only");
    refused(
        "pcm-typo",
        "tests/cases/footing_square_3d.toml",
        "multilinar",
        "`jacobian` (the default) or `multilinear`",
    );
    // PETSc 3.18's multigrid would keep the first Jacobian as its finest residual's operator.
    refused(
        "pcm-amat",
        "tests/cases/footing_square_3d.toml",
        "multilinear -pc_type gamg -pc_use_amat true",
        "-pc_use_amat true with -porompm_pc_matrix multilinear",
    );
}
