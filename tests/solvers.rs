//! The linear solves see every field: a Krylov solve stopped at `-ksp_rtol` leaves the residual of
//! each field (u, p, U), relative to its own equations' terms, within 10 × rtol, on the u–p–U and
//! the u–p systems and under both residual norms PETSc offers (left-preconditioned, and right with
//! the true residual); a direct solve leaves it at round-off. Without porompm's field-wise test,
//! PETSc's one norm stops while a field lags far behind: the measure sees it.

mod common;
use common::{run_case, set_args, Run};
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

/// (field, linear_max) of a run's summary.
fn linear(run: &Run) -> Vec<(String, f64)> {
    run.summary["field_residuals"]
        .as_array()
        .expect("field_residuals")
        .iter()
        .map(|r| (r["field"].as_str().unwrap().to_string(), r["linear_max"].as_f64().expect("measured")))
        .collect()
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
