//! Verification against analytical solutions, with stated tolerances (the case files' targets):
//! every case family meets its targets with the default solver, and the iterative strategy
//! (`fieldsplit-schur.opts`) gives the default solver's answer. Terzaghi's family runs whole with
//! `direct-lu.opts` and `fieldsplit-schur.opts`, the strategies agreeing on every metric within
//! solver tolerance; the longer two-phase families ([`FAMILIES`]) run with both solvers over a
//! window of their first steps and agree at every step of their histories, and their whole runs
//! with the iterative strategy are a study (`make study`). The default solver's whole run is the
//! one `tests/gold.rs` makes and pins (each metric's value and pass flag, [`common::gold_run`]),
//! so it is read from the gold file rather than run twice. `direct-lu.opts` factorises with
//! MUMPS, the default on several ranks, where `tests/gold.rs` compares every case with its gold
//! values; `make study` also runs every case with it on one rank
//! (`gold_values_hold_with_a_direct_solver`). Each run is the real binary in its own process.

mod common;

use serde_json::Value;
use std::collections::BTreeMap;
use std::path::PathBuf;

fn out_dir(label: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("verification").join(label)
}

/// Runs a case and returns its summary; panics with the run's error if it did not complete.
fn run(case: &str, label: &str, options: Option<&str>, sets: &[&str]) -> Value {
    let mut args = Vec::new();
    if let Some(o) = options {
        args.push("--options-file".into());
        args.push(format!("petsc_options/{o}.opts"));
    }
    args.extend(common::set_args(sets));
    let r = common::run_case(&format!("cases/{case}.toml"), &out_dir(label), &args);
    assert!(r.completed(), "{label}: {}", r.stderr());
    r.summary
}

fn metrics(s: &Value) -> BTreeMap<String, (f64, bool, f64)> {
    s["verification"]
        .as_object()
        .expect("verification metrics")
        .iter()
        .map(|(k, m)| {
            (
                k.clone(),
                (
                    m["value"].as_f64().unwrap_or(f64::NAN),
                    m["pass"].as_bool().unwrap(),
                    m["tolerance"].as_f64().unwrap(),
                ),
            )
        })
        .collect()
}

/// `case`'s default run as its gold file pins it: the metric names must be `expected` and every
/// metric must meet its target. Returns the metrics.
fn gold_metrics(case: &str, expected: &[&str]) -> BTreeMap<String, (f64, bool)> {
    let reference = common::gold_run(case).metrics;
    let names: Vec<&str> = reference.keys().map(String::as_str).collect();
    assert_eq!(names, expected, "{case}: metric names");
    for (name, (v, pass)) in &reference {
        assert!(*pass, "{case} (default solver, gold run): {name} = {v:e} misses its target");
    }
    reference
}

/// Checks `case` with the default run as the gold file pins it ([`gold_metrics`]) and with each of
/// `strategies` (options files of `petsc_options/`) over the whole run: every metric must meet its
/// target with each strategy and agree across strategies to `agree` (metrics are normalised
/// errors, so an absolute bound is the solver tolerance carried through). Returns the default's
/// metrics.
fn family(case: &str, expected: &[&str], strategies: &[&str], agree: f64) -> BTreeMap<String, (f64, bool)> {
    let reference = gold_metrics(case, expected);
    for &strategy in strategies {
        let m = metrics(&run(case, &format!("{case}-{strategy}"), Some(strategy), &[]));
        assert_eq!(m.keys().collect::<Vec<_>>(), reference.keys().collect::<Vec<_>>(), "{case} ({strategy})");
        for (name, (v, pass, tol)) in &m {
            assert!(*pass, "{case} ({strategy}): {name} = {v:e} exceeds {tol:e}");
            let r = reference[name].0;
            assert!((v - r).abs() <= agree, "{case}: {name} = {v:e} with {strategy}, {r:e} with the default");
        }
    }
    reference
}

/// How closely two solvers' histories must agree, relative to the largest value of each kind of
/// column (stresses, pore pressures, displacements, …) in the default solver's history: the
/// iterative strategies solve to 1e-10, and over whole runs of the two-phase families their
/// histories agree with the direct solver's within 1e-8 (measured).
const HISTORY_RTOL: f64 = 1e-7;

/// The kind of a history column, whose largest value in the run scales its differences: the
/// quantity after the probe's name, with the pore pressure's columns (`p`, `p_excess`, `p_min`,
/// `p_max`) as one kind and the components of a tensor or vector as one.
fn column_kind(name: &str) -> String {
    let q = name.rsplit('.').next().unwrap_or(name);
    let kind = match q {
        "p" | "p_excess" | "p_min" | "p_max" => "pore pressure",
        "sxx" | "syy" | "szz" | "sxy" | "syz" | "szx" => "stress",
        "ux" | "uy" | "uz" => "displacement",
        "vx" | "vy" | "vz" => "velocity",
        "x" | "y" | "z" => "position",
        "reaction_x" | "reaction_y" | "reaction_z" => "reaction",
        _ => return name.to_string(),
    };
    kind.to_string()
}

/// The largest difference between the histories of runs `a` (the reference) and `b` at the same
/// steps, relative to the largest value of its kind in `a` ([`column_kind`]), and its column. The
/// step columns, the iteration counts and the equilibrium error (a measure of how far each solve
/// went, not of the answer) are not compared.
fn largest_history_difference(a: &str, b: &str) -> (f64, String) {
    let ((ha, ra), (hb, rb)) = (common::read_history(&out_dir(a)), common::read_history(&out_dir(b)));
    assert_eq!(ha, hb, "{a} and {b}: history columns");
    assert!(ra.len() > 1 && ra.len() == rb.len(), "{a}: {} rows, {b}: {} rows", ra.len(), rb.len());
    let skipped = ["time", "step", "dt", "newton_iterations", "linear_iterations", "equilibrium_error"];
    let compared: Vec<usize> = (0..ha.len()).filter(|&j| !skipped.contains(&ha[j].as_str())).collect();
    let mut scale = BTreeMap::<String, f64>::new();
    for &j in &compared {
        let s = scale.entry(column_kind(&ha[j])).or_default();
        *s = ra.iter().fold(*s, |m, r| m.max(r[j].abs()));
    }
    let mut worst = (0.0, String::new());
    for &j in &compared {
        let s = scale[&column_kind(&ha[j])].max(f64::MIN_POSITIVE);
        for (x, y) in ra.iter().zip(&rb) {
            // A NaN difference counts as the largest.
            let d = (x[j] - y[j]).abs() / s;
            if d.is_nan() || d > worst.0 {
                worst = (d, ha[j].clone());
            }
        }
    }
    worst
}

/// Runs `case` over its first `window` (the `--set`s of a stage's duration and what a shorter run
/// needs) with the default solver and with `strategy` (an options file of `petsc_options/`): both
/// must complete and their histories agree at every step within [`HISTORY_RTOL`]
/// ([`largest_history_difference`]). The whole run with `strategy` is the
/// [`every_two_phase_family_meets_its_targets_with_fieldsplit_schur`] study.
fn strategy_agrees_over(case: &str, window: &[&str], strategy: &str) {
    let (a, b) = (format!("{case}-window"), format!("{case}-window-{strategy}"));
    run(case, &a, None, window);
    run(case, &b, Some(strategy), window);
    let (d, column) = largest_history_difference(&a, &b);
    assert!(d <= HISTORY_RTOL, "{case} over {window:?}: {column} differs by {d:e} (relative) with {strategy}");
}

/// The harmonic columns' verification over the one load period of their windows.
const ONE_PERIOD: &str = "verification.measure_periods=1";

/// The two-phase families whose runs with `fieldsplit-schur.opts` the default suite compares with
/// the default solver's over a window of their first steps ([`strategy_agrees_over`]), and whose
/// whole runs with it are a study
/// ([`every_two_phase_family_meets_its_targets_with_fieldsplit_schur`]): the case, its metrics and
/// the window's overrides.
const FAMILIES: [(&str, &[&str], &[&str]); 5] = [
    // One of its six periods (900 of 5 332 steps), its amplitude measured over that one.
    ("harmonic_column_zone1", &["p_amplitude_max_rel_error"], &["stages.harmonic.duration=0.9", ONE_PERIOD]),
    // One of its eight periods (400 of 3 180 steps).
    ("harmonic_column_zone2", &["p_amplitude_max_rel_error"], &["stages.harmonic.duration=0.04", ONE_PERIOD]),
    // Ten of its 70 periods (1 300 of 8 797 steps).
    ("harmonic_column_zone3", &["p_amplitude_max_rel_error"], &["stages.harmonic.duration=0.13", ONE_PERIOD]),
    // The fast wave past the probe, 0.4 m deep (200 of 600 steps).
    ("shock_wave", &["fast_wave_arrival_rel_error", "slow_wave_arrival_rel_error"], &["stages.shock.duration=2e-4"]),
    // A tenth of the consolidation (2 000 of 20 000 steps).
    (
        "large_strain_consolidation",
        &["e_p_Us0.5", "p_rms_error_Us0.5", "settlement_rel_error_Us0.5"],
        &["stages.consolidation.duration=0.2"],
    ),
];

/// The `i`th of the [`FAMILIES`]: the default run's metrics as its gold file pins them
/// ([`gold_metrics`]), after checking that `fieldsplit-schur.opts` gives the default solver's
/// answer over the family's window.
fn two_phase_family(i: usize) -> BTreeMap<String, (f64, bool)> {
    let (case, expected, window) = FAMILIES[i];
    strategy_agrees_over(case, window, "fieldsplit-schur");
    gold_metrics(case, expected)
}

#[test]
fn terzaghi_consolidation_meets_its_targets_with_every_strategy() {
    let m = family(
        "terzaghi",
        &["e_p_Tv0.1", "e_p_Tv0.5", "p_rms_error_Tv0.1", "p_rms_error_Tv0.5", "settlement_rel_error_Tv0.5"],
        &["direct-lu", "fieldsplit-schur"],
        1e-6,
    );
    // The target at 10 cells and Δt = 1e-3 s.
    assert!(m["e_p_Tv0.1"].0 <= 1e-2 && m["e_p_Tv0.5"].0 <= 1e-2);
}

#[test]
fn harmonic_column_zone1_meets_five_percent() {
    let m = two_phase_family(0);
    assert!(m["p_amplitude_max_rel_error"].0 <= 0.05);
}

#[test]
fn harmonic_column_zone2_meets_five_percent() {
    let m = two_phase_family(1);
    assert!(m["p_amplitude_max_rel_error"].0 <= 0.05);
}

#[test]
fn harmonic_column_zone3_meets_ten_percent() {
    let m = two_phase_family(2);
    assert!(m["p_amplitude_max_rel_error"].0 <= 0.10);
}

#[test]
fn shock_wave_at_high_permeability_shows_both_waves_on_time() {
    let m = two_phase_family(3);
    assert!(m["fast_wave_arrival_rel_error"].0 <= 0.02);
    assert!(m["slow_wave_arrival_rel_error"].0 <= 0.05);
}

#[test]
fn large_strain_consolidation_meets_three_percent_at_ten_cells() {
    // [003] §4.2 against Xie & Leo (2004): the target is a settlement error at U_s = 0.5 of at
    // most 3 % at 10 cells (the refinement to 20 and 40 cells is in `make study`).
    let m = two_phase_family(4);
    assert!(m["settlement_rel_error_Us0.5"].0 <= 0.03);
}

/// Every one of the [`FAMILIES`] meets its targets with `fieldsplit-schur.opts` over its whole
/// run, agreeing with the default solver's metrics within 1e-5 (`make study`).
#[test]
#[ignore = "whole runs with the iterative strategy (make study)"]
fn every_two_phase_family_meets_its_targets_with_fieldsplit_schur() {
    for (case, expected, _) in FAMILIES {
        family(case, expected, &["fieldsplit-schur"], 1e-5);
    }
}

#[test]
fn shock_wave_at_low_permeability_shows_the_fast_wave_only() {
    // The fast wave passes the probe at 1.8e-4 s; over the first 3e-4 s the picked arrival is the
    // whole run's to the last digit (measured), at half its cost.
    let sets = ["materials.soil.hydraulic_conductivity=1e-5", "stages.shock.duration=3e-4"];
    let s = run("shock_wave", "shock_wave-k1e-5", None, &sets);
    let m = metrics(&s);
    assert!(m["fast_wave_arrival_rel_error"].1, "{m:?}");
    assert!(m["fast_wave_arrival_rel_error"].0 <= 0.02);
    assert!(!m.contains_key("slow_wave_arrival_rel_error"), "no slow wave is expected at k = 1e-5 m/s: {m:?}");
}

#[test]
fn elastic_column_one_phase_two_stages_meets_the_static_solution() {
    // One-phase (ux, uy) layout: the fieldsplit strategy, which splits the two-phase fields, does not
    // apply; the direct ones must agree with the default run (as its gold file pins it).
    let reference = common::gold_run("elastic_column").metrics;
    assert_eq!(
        reference.keys().map(String::as_str).collect::<Vec<_>>(),
        ["settlement_rel_error", "stress_max_rel_error"]
    );
    assert!(reference.values().all(|m| m.1), "the default run misses a target: {reference:?}");
    for strategy in ["direct-lu", "direct-ldlt"] {
        let m = metrics(&run("elastic_column", &format!("elastic_column-{strategy}"), Some(strategy), &[]));
        assert_eq!(m.len(), reference.len(), "{strategy}");
        for (name, (v, pass, tol)) in &m {
            assert!(*pass, "{strategy}: {name} = {v:e} exceeds {tol:e}");
            assert!((v - reference[name].0).abs() <= 1e-6, "{strategy}: {name} differs");
        }
    }
    assert!(reference["stress_max_rel_error"].0 <= 0.01 && reference["settlement_rel_error"].0 <= 0.01);
}

/// Column `name` of a run's history.csv with its time column.
fn history(label: &str, name: &str) -> Vec<(f64, f64)> {
    let (header, rows) = common::read_history(&out_dir(label));
    let (t, v) = (common::column(&header, &rows, "time"), common::column(&header, &rows, name));
    t.into_iter().zip(v).collect()
}

#[test]
fn slumping_block_stays_smooth_with_patch_recovery_and_shows_the_mandel_cryer_rise() {
    // [003] §4.3: with patch recovery the pore pressure stays free of checkerboards to t = 0.5 s;
    // without it the checkerboard index is at least three times larger (or the run fails); at P3 the
    // pressure keeps rising after the gravity ramp has ended (t = 0.2 s) and then falls.
    let patched = run("slumping_block", "slumping_block-patch", None, &[]);
    let ci = patched["checkerboard_index_max"].as_f64().unwrap();
    assert!(ci <= 0.03, "checkerboard_index_max with patch recovery: {ci}");
    let p3 = history("slumping_block-patch", "P3.p");
    let (t_peak, peak) = p3.iter().cloned().fold((0.0, f64::MIN), |a, b| if b.1 > a.1 { b } else { a });
    let last = p3.last().unwrap().1;
    assert!(t_peak > 0.25 && last < 0.99 * peak, "P3 peaks at t = {t_peak} s ({peak} Pa), ends at {last} Pa");

    // Without patch recovery the run completes (measured 2026-11-24) with a checkerboard index
    // of 0.147 against 0.0087 with it; both must hold, a failed run fails this test.
    let unpatched = run("slumping_block", "slumping_block-nopatch", None, &["stabilisation.patch_recovery=false"]);
    let unpatched = unpatched["checkerboard_index_max"].as_f64().unwrap();
    assert!(unpatched >= 3.0 * ci, "checkerboard index {unpatched} without patch recovery, {ci} with it");
}

/// A number from summary.json `results` (NaN when absent).
fn result(s: &Value, name: &str) -> f64 {
    s["results"][name].as_f64().unwrap_or(f64::NAN)
}

#[test]
fn footing_sd_converges_towards_prandtl_with_bbar_and_locks_without() {
    // The small-deformation undrained footing ([000] §4.1.1) with B̄ fails at a q_ult/c that
    // approaches 2 + π under refinement: measured (q_ult/c)/(2 + π) = 1.183 / 1.098 / 1.057 at
    // h = 0.5 / 0.25 / 0.1 m (order ≈ 0.9 then 0.6; the case's target, 6 % at h = 0.25 m, is not
    // met and the run reports it as FAIL; see docs/verification.md). Here: the error must fall by
    // at least 1.6× from h = 0.5 to 0.25 m (1.87× measured) and the coarse run's pass flag must
    // agree with its value; the default run's value and flag are pinned by the gold test. Without
    // B̄ the nearly incompressible plastic flow locks: no failure up to q/c = 7.
    let coarse = run("footing_sd", "footing_sd-h0.5", None, &["parameters.h=0.5"]);
    let b = &coarse["verification"]["bearing_capacity_ratio"];
    let (r05, tol) = (b["value"].as_f64().unwrap(), b["tolerance"].as_f64().unwrap());
    assert_eq!(b["pass"].as_bool().unwrap(), (r05 - 1.0).abs() <= tol, "pass flag of {r05}");
    // The default run (h = 0.25 m), as its gold file pins it (its pass flag too).
    let r025 = common::gold_run("footing_sd").metrics["bearing_capacity_ratio"].0;
    assert!(r025 > 1.0 && (r05 - 1.0) >= 1.6 * (r025 - 1.0), "q_ult/c/(2 + π) = {r05} at h = 0.5 m, {r025} at 0.25 m");
    let without = run("footing_sd", "footing_sd-nobbar", None, &["stabilisation.bbar=false"]);
    let q_max = result(&without, "q_over_c_max");
    let at_fail = result(&without, "q_over_c_at_dB0.01");
    assert!(
        at_fail.is_nan() || at_fail > 1.2 * r025 * (2.0 + std::f64::consts::PI),
        "without B̄ q/c at d/B = 0.01 is {at_fail} (max {q_max}): not locked"
    );
    assert!(q_max > 6.9, "without B̄ the load reaches q/c = {q_max} only");
}

#[test]
fn slope_clay_runs_out_with_bbar_and_locks_without() {
    // [000] §4.2.1: released after the gravity stage, the softening clay slope fails; with B̄ its toe
    // runs out about twice as far as without (0.36 and 0.17 m measured), where the isochoric plastic
    // flow locks.
    // With B̄: the default run, as its gold file pins it.
    let with = common::gold_run("slope_clay").results["toe.displacement"];
    let without =
        result(&run("slope_clay", "slope_clay-nobbar", None, &["stabilisation.bbar=false"]), "toe.displacement");
    assert!(with > 0.25, "toe run-out with B̄: {with} m");
    assert!(with > 1.8 * without, "toe run-out with B̄ {with} m, without {without} m");
}

/// One and 4 × 4 material points per cell: GIMP's 4 × 4-node stencils at one point per cell and
/// the 16 points of a cell fit the matrix pattern (built from the stencils, not from a box of
/// width 2). The undrained footing completes with both; the slumping block completes with 4 × 4,
/// and at one point per cell ends cleanly when a step diverges (one quadrature point per cell
/// leaves the equal-order u–p–U pressure and GIMP's hourglass modes unconstrained).
#[test]
fn one_and_sixteen_points_per_cell_run() {
    for ppc in [1, 4] {
        let s = run(
            "footing_sd",
            &format!("footing_sd-ppc{ppc}"),
            None,
            &[
                &format!("bodies.soil.particles_per_cell={ppc}"),
                "parameters.h=0.5",
                "verification.settlement_point=[0.05,4.95]",
            ],
        );
        let ratio = s["verification"]["bearing_capacity_ratio"]["value"].as_f64().unwrap();
        assert!(ratio.is_finite() && ratio > 1.0, "{ppc} per cell: q_ult/c/(2 + π) = {ratio}");
    }
    let s = run(
        "slumping_block",
        "slumping-ppc4",
        None,
        &["bodies.block.particles_per_cell=4", "stages.slump.duration=0.05"],
    );
    assert_eq!(s["steps"], 50);
    let r = common::run_case(
        "cases/slumping_block.toml",
        &out_dir("slumping-ppc1"),
        &common::set_args(&["bodies.block.particles_per_cell=1", "stages.slump.duration=0.05"]),
    );
    let s = r.summary;
    assert_eq!(r.output.status.code(), Some(1));
    let err = s["error"].as_str().unwrap();
    assert!(s["status"] == "failed" && err.contains("did not converge") && !err.contains("malloc"), "{err}");
    assert!(s["steps"].as_u64().unwrap() >= 10, "{}", s["steps"]);
}

/// A saturated column at rest under its own weight (tests/cases/hydrostatic_column.toml): once the
/// excess pore pressure of the sudden gravity has drained (T_v = 3), the check `hydrostatic` finds
/// p = ρ_w g (H − y) at every point within its 1 %; stopped while the column still consolidates
/// (T_v = 0.1), the same check fails, so the metric sees the excess.
#[test]
fn a_drained_column_carries_the_hydrostatic_pore_pressure() {
    let case = "tests/cases/hydrostatic_column.toml";
    let r = common::run_case(case, &out_dir("hydrostatic_column"), &[]);
    assert!(r.completed(), "{}", r.stderr());
    let m = metrics(&r.summary);
    assert_eq!(m.keys().map(String::as_str).collect::<Vec<_>>(), ["p_rel_error"]);
    let (error, pass, tolerance) = m["p_rel_error"];
    assert!(pass && error <= tolerance && tolerance == 0.01, "drained: p_rel_error = {error:e} against {tolerance:e}");
    let early =
        common::run_case(case, &out_dir("hydrostatic_column-early"), &common::set_args(&["stages.0.duration=0.1"]));
    assert!(early.completed(), "{}", early.stderr());
    let (error, pass, _) = metrics(&early.summary)["p_rel_error"];
    assert!(!pass && error > 0.1, "still consolidating: p_rel_error = {error:e} passes");
}
