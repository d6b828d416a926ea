//! [001]'s 25 increments of the hollow cylinder (`cases/hollow_cylinder_increments.toml`,
//! `../shared/seeds-001-002.md` Part E item 9): the internal pressure re-evaluated at the inner
//! faces' current radius (`increment_factor`), geometrically linear steps
//! (`analysis.kinematics = "linear_increments"`), DM-GC against regular MPM, and the same answers
//! on two ranks and after a restart.

mod common;
use common::*;
use std::path::PathBuf;

const CASE: &str = "cases/hollow_cylinder_increments.toml";

fn out_dir(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("porompm-increments-{name}-{}", std::process::id()))
}

/// The three step metrics of a run: (largest relative error of Δq at mp1, largest error of Δσ_m
/// over the step's pressure, relative error of mp1's final radius).
fn errors(name: &str, sets: &[&str], ranks: usize) -> (f64, f64, f64, Run) {
    errors_with(name, sets, &[], ranks)
}

/// [`errors`] with PETSc options after `--`.
fn errors_with(name: &str, sets: &[&str], petsc: &[&str], ranks: usize) -> (f64, f64, f64, Run) {
    let mut args = set_args(sets);
    if !petsc.is_empty() {
        args.push("--".into());
        args.extend(petsc.iter().map(|s| s.to_string()));
    }
    let r = run_case_on(ranks, CASE, &out_dir(name), &args);
    assert!(r.completed(), "{name}: {}", r.stderr());
    assert_eq!(r.summary["results"]["steps_compared"].as_f64(), Some(25.0), "{name}");
    let m = |k: &str| metric(&r.summary, k);
    (m("dq_mp1_max_rel_error"), m("dsigma_m_mp1_max_error"), m("r_mp1_rel_error"), r)
}

const REGULAR_MPM: [&str; 3] =
    ["analysis.shape_functions=linear", "stabilisation.stiffness=particle", "stabilisation.stress_recovery=basis"];

/// Part E item 9: DM-GC (GIMP, [001]'s DM-G stiffness, CMPM recovery, one linear solve per
/// increment) keeps Δq at mp1 within 10 % and Δσ_m within 5 kPa per 100 kPa of the closed form at
/// every increment, and mp1's radius within 5 % of the closed-form path; its largest errors are at
/// most half those of regular MPM, which crosses cells with jumps of the stress.
#[test]
fn dm_gc_follows_the_closed_form_through_25_increments_and_halves_regular_mpm_s_errors() {
    let (q, m, r, run) = errors("dm-gc", &[], 1);
    println!("DM-GC: Δq {q:.4}, Δσ_m {m:.4}, r_mp1 {r:.2e}");
    assert!(q <= 0.10 && m <= 0.05 && r <= 0.05, "DM-GC: {q} {m} {r}");
    assert_eq!(run.summary["verification_passed"], true);
    // mp1 ends near [001]'s 1.077 m (the closed-form path: 1.0767 m).
    let end = run.summary["results"]["r_mp1_final"].as_f64().unwrap();
    let exact = run.summary["results"]["r_mp1_exact_final"].as_f64().unwrap();
    assert!((exact - 1.0767).abs() < 1e-3, "closed-form path {exact}");
    assert!((end / exact - 1.0).abs() < 0.01, "mp1 at {end} m");
    let (qm, mm, rm, _) = errors("mpm", &REGULAR_MPM, 1);
    println!("regular MPM: Δq {qm:.4}, Δσ_m {mm:.4}, r_mp1 {rm:.2e}");
    assert!(q <= 0.5 * qm && m <= 0.5 * mm && r <= 0.5 * rm, "DM-GC {q} {m} {r} vs MPM {qm} {mm} {rm}");
}

/// The step metrics converge under refinement, at least at first order in h (h = 0.2 → 0.05 m:
/// each error falls by more than 4): the comparison measures the method, not a modelling
/// difference.
#[test]
fn the_increments_converge_to_the_closed_form_under_refinement() {
    let coarse = errors("h-0.2", &[], 1);
    let fine = errors("h-0.05", &["parameters.h=0.05"], 1);
    println!("h = 0.05 m: Δq {:.2e}, Δσ_m {:.2e}, r_mp1 {:.2e}", fine.0, fine.1, fine.2);
    assert!(
        fine.0 < 0.25 * coarse.0 && fine.1 < 0.25 * coarse.1,
        "{:?} → {:?}",
        (coarse.0, coarse.1),
        (fine.0, fine.1)
    );
    assert!(fine.2 < 1e-3, "r_mp1 {}", fine.2);
}

/// The closed form is the increment of a stress-free remaining cylinder. Finite-strain steps in
/// equilibrium on the moved configuration (the default kinematics, Newton to convergence) carry the stress of
/// earlier steps into every increment (of the order of E here): mp1 then moves about 5 % further
/// than the closed-form path, at every resolution, and the check says so.
#[test]
fn finite_strain_steps_carry_the_earlier_stress_and_leave_the_closed_form_path() {
    for h in ["0.2", "0.05"] {
        let h_set = format!("parameters.h={h}");
        let (_, _, r, run) = errors_with(
            &format!("finite-{h}"),
            &["analysis.kinematics=finite_strain", "stabilisation.stiffness=particle", &h_set],
            &["-snes_type", "newtonls"],
            1,
        );
        // Newton converged every step (more than one iteration: the steps are nonlinear).
        assert!(run.summary["snes_iterations"].as_u64().unwrap() > 25, "{}", run.summary["snes_iterations"]);
        assert!((0.045..0.07).contains(&r), "h = {h}: r_mp1 error {r}");
        assert_eq!(run.summary["verification_passed"], false);
    }
}

/// One and two ranks (the loaded faces' mean radius is a sum over ranks) give the same increments,
/// and a run restarted from a checkpoint of step 12 (the load's sum so far is in the checkpoint)
/// ends with the uninterrupted run's answers.
#[test]
fn the_increments_are_the_same_on_two_ranks_and_after_a_restart() {
    let sets = ["parameters.h=0.05"];
    let one = errors("ranks-1", &sets, 1);
    let two = errors("ranks-2", &sets, 2);
    for (a, b) in [(one.0, two.0), (one.1, two.1), (one.2, two.2)] {
        assert!((a - b).abs() <= 1e-9 * a.abs().max(1e-6), "{a} vs {b}");
    }
    let first = out_dir("restart-first");
    let mut args = set_args(&sets);
    args.extend(["--checkpoint-every".to_string(), "12".to_string()]);
    let r = run_case_on(1, CASE, &first, &args);
    assert!(r.completed(), "{}", r.stderr());
    let mut again = set_args(&sets);
    again.extend(["--restart".to_string(), first.join("checkpoint.h5").display().to_string()]);
    let r = run_case_on(2, CASE, &out_dir("restart-again"), &again);
    assert!(r.completed(), "{}", r.stderr());
    assert_eq!(r.summary["restarted_from"]["step"], 24);
    assert_eq!(r.summary["results"]["steps_compared"].as_f64(), Some(25.0), "steps compared after the restart");
    for (k, want) in [("dq_mp1_max_rel_error", one.0), ("dsigma_m_mp1_max_error", one.1), ("r_mp1_rel_error", one.2)] {
        let got = metric(&r.summary, k);
        assert!((got - want).abs() <= 1e-9 * want.abs().max(1e-6), "{k}: {got} after the restart, {want} without");
    }
}

/// Bad input around the new keys is refused with one message naming the key.
#[test]
fn bad_increment_input_is_refused_with_a_clear_message() {
    let cases: [(&str, &[&str], &str); 7] = [
        (CASE, &["loads.0.increment_factor=1 / q"], "key `loads[0].increment_factor`"),
        (CASE, &["loads.0.increment_factor=1 / (x - x)"], "is not finite"),
        // Valid at the region's centre, infinite where the faces are (x = 0.5 m) at the start.
        (CASE, &["loads.0.increment_factor=1 / (x - 0.5)"], "at [0.5, 0.1]: the value inf is not finite"),
        (
            CASE,
            &["loads.0.region.min=[1.0,0.0]", "loads.0.region.max=[1.1,0.2]"],
            "key `loads[0].region`: load `inner_pressure` acts on no material point",
        ),
        ("cases/terzaghi.toml", &["analysis.kinematics=linear_increments"], "is for a one_phase analysis"),
        ("cases/vertical_cut.toml", &["analysis.kinematics=linear_increments"], "steps are static"),
        ("cases/terzaghi.toml", &["loads.0.increment_factor=x"], "only the hollow_cylinder check follows one"),
    ];
    for (i, (case, sets, message)) in cases.iter().enumerate() {
        assert_refused(case, &out_dir(&format!("bad-{i}")), sets, message);
    }
}
