//! Analysis types (static, quasi-static and dynamic stages): each against an exact or analytical
//! answer, the pressures of stiff consolidation without persistent oscillation, and the state handed
//! from one analysis type to the next. Each run is the real binary in its own process.

mod common;

use common::{column, has_warning, metric};
use serde_json::Value;
use std::path::PathBuf;

/// Runs `case` (a path from the repository root) with `sets` into a fresh directory; returns the
/// summary and history.csv's header and rows. Panics unless the run completed.
fn run(case: &str, label: &str, sets: &[&str]) -> (Value, Vec<String>, Vec<Vec<f64>>) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("analysis").join(label);
    let r = common::run_case(case, &dir, &common::set_args(sets));
    assert!(r.completed(), "{label}: {}", r.stderr());
    (r.summary, r.header, r.rows)
}

/// The largest alternation |p_{k+1} − 2p_k + p_{k−1}| / q of the base pore pressure over the steps
/// after the first `skip` (steps of equal length only: a step shortened to land on an event time
/// is not an oscillation), q = 1 kPa.
fn alternation_after(header: &[String], rows: &[Vec<f64>], skip: usize) -> f64 {
    let (t, p) = (column(header, rows, "time"), column(header, rows, "base.p"));
    (skip.max(1)..p.len() - 1)
        .filter(|&k| ((t[k + 1] - t[k]) - (t[k] - t[k - 1])).abs() < 1e-9 * (t[k] - t[k - 1]))
        .map(|k| (p[k + 1] - 2.0 * p[k] + p[k - 1]).abs() / 1000.0)
        .fold(0.0, f64::max)
}

/// A one-phase column under its weight and a surcharge solved by two static steps is the exact
/// static answer of its discretisation: the same stress error as the dynamic run settles to
/// (0.6 %, the linear-in-cell strain), at 2 steps instead of 600, and in equilibrium to round-off.
#[test]
fn a_static_elastic_column_meets_the_static_solution_in_one_step_per_stage() {
    let sets = [
        "stages.self_weight.analysis=static",
        "stages.self_weight.dt=1.5",
        "stages.surcharge.analysis=static",
        "stages.surcharge.dt=1.5",
    ];
    let (s, _, _) = run("cases/elastic_column.toml", "static-column", &sets);
    assert_eq!(s["steps"], 2);
    let (settle, stress) = (metric(&s, "settlement_rel_error"), metric(&s, "stress_max_rel_error"));
    eprintln!("static column: settlement error {settle:.2e}, stress error {stress:.2e}");
    assert!(settle <= 1e-3 && stress <= 1e-2, "settlement {settle:e}, stress {stress:e}");
    let eq = s["equilibrium_error"].as_f64().unwrap();
    assert!(eq <= 1e-9, "equilibrium error {eq:e}");
}

/// Quasi-static Terzaghi (u–p with Darcy's law, backward Euler): the settlement and pressure errors
/// at T_v = 0.5 fall under h-refinement at a small Δt and under Δt-refinement at a fine grid, with
/// observed orders of at least 1 (the pressure RMS error is over particles, normalised by the load,
/// not divided by their number).
#[test]
fn quasi_static_terzaghi_converges_in_h_and_in_dt() {
    let qs = "stages.consolidation.analysis=quasi_static";
    let err = |n: usize, dt: f64| -> (f64, f64) {
        let label = format!("qs-terzaghi-{n}-{dt}");
        let cells = format!("grid.cells=[1,{n}]");
        let dts = format!("time.dt={dt}");
        let (s, _, _) = run("cases/terzaghi.toml", &label, &[qs, &cells, &dts]);
        (metric(&s, "settlement_rel_error_Tv0.5"), metric(&s, "p_rms_error_Tv0.5"))
    };
    // h: Δt = 2e-4 s keeps the time error below the space error of 40 cells.
    let h: Vec<(f64, f64)> = [5, 10, 20].iter().map(|&n| err(n, 2e-4)).collect();
    // Δt: 40 cells keep the space error below the time error of Δt = 5e-3 s.
    let t: Vec<(f64, f64)> = [2e-2, 1e-2, 5e-3].iter().map(|&dt| err(40, dt)).collect();
    eprintln!("h-refinement (settlement, p rms): {h:?}\nΔt-refinement: {t:?}");
    for (name, e) in [("h", &h), ("dt", &t)] {
        for w in e.windows(2) {
            let (o_s, o_p) = ((w[0].0 / w[1].0).log2(), (w[0].1 / w[1].1).log2());
            assert!(o_s >= 0.9 && o_p >= 0.9, "{name}-refinement orders {o_s:.2}, {o_p:.2} from {e:?}");
        }
    }
}

/// The stiffest corner of the Terzaghi family, c_v Δt / h² = 6.5 (80 cells, Δt = 1e-3 s): with
/// Newmark the base pressure alternates by 70 % of the load from step to step for the whole run.
/// The default dynamic scheme (generalized-α, ρ∞ = 0.2) and the quasi-static stage bring the
/// alternation below 1e-3 of the load within 20 steps, and Newmark, asked for, still rings (the
/// check can fail).
#[test]
fn stiff_consolidation_pressures_stop_ringing_within_twenty_steps() {
    let base = ["grid.cells=[1,80]", "output.history_every=1"];
    let runs = [
        ("dynamic-default", vec![]),
        ("quasi-static", vec!["stages.consolidation.analysis=quasi_static"]),
        ("newmark", vec!["time_integration.scheme=newmark"]),
    ];
    for (label, extra) in runs {
        let sets: Vec<&str> = base.iter().copied().chain(extra).collect();
        let (s, h, rows) = run("cases/terzaghi.toml", &format!("ringing-{label}"), &sets);
        let alt = alternation_after(&h, &rows, 20);
        let rms = metric(&s, "p_rms_error_Tv0.5");
        eprintln!("{label}: alternation after 20 steps {alt:.2e}, p rms error {rms:.2e}");
        if label == "newmark" {
            assert!(alt > 0.1, "Newmark was expected to ring: {alt:e}");
        } else {
            assert!(alt < 1e-3, "{label}: the base pressure still alternates by {alt:e} of the load");
            assert!(rms < 1e-3, "{label}: p rms error {rms:e}");
        }
    }
}

/// A static undrained loading step followed by a quasi-static consolidation stage: the state passes
/// from the u–p system without flow to the one with Darcy's law, and the result meets Terzaghi's
/// solution as closely as the quasi-static run loaded at t = 0.
#[test]
fn a_static_undrained_stage_hands_its_state_to_a_consolidation_stage() {
    let (s, _, _) = run("tests/cases/terzaghi_staged.toml", "staged", &[]);
    let (e01, e05) = (metric(&s, "e_p_Tv0.1"), metric(&s, "e_p_Tv0.5"));
    let settle = metric(&s, "settlement_rel_error_Tv0.5");
    eprintln!("staged: e_p {e01:.2e} / {e05:.2e}, settlement error {settle:.2e}");
    assert!(e01 <= 1e-3 && e05 <= 1e-3 && settle <= 2e-3, "{}", s["verification"]);
    assert!(s["verification_passed"].as_bool().unwrap());
}

/// The peer's strip footing, statically, on a coarse grid: it settles plastically at q = 4c
/// (below Prandtl's 5.14c), every load step is in equilibrium to the Newton tolerance, and the
/// steps take few Newton iterations.
#[test]
fn the_static_strip_footing_settles_plastically_in_equilibrium() {
    let (s, _, _) = run("cases/footing_peer.toml", "footing-peer-h0.25", &["parameters.h=0.25"]);
    let r = &s["results"];
    let (d3, d4) = (r["settlement_at_qc3"].as_f64().unwrap(), r["settlement_at_qc4"].as_f64().unwrap());
    let newton = s["snes_iterations"].as_u64().unwrap();
    eprintln!("footing h = 0.25: d(3c) = {d3:.3e} m, d(4c) = {d4:.3e} m, {newton} Newton iterations");
    // Elastic at 3c would be proportional: d(4c) > 4/3 d(3c) shows the plastic zone.
    assert!(d3 > 0.0 && d4 > 1.5 * d3, "d(3c) = {d3}, d(4c) = {d4}");
    // The identity holds to the Newton tolerance (a residual of 1e-6 of the step's first one).
    let eq = s["equilibrium_error"].as_f64().unwrap();
    assert!(eq <= 2e-5, "equilibrium error {eq:e}");
    assert!(newton <= 4 * 50, "{newton} Newton iterations for 50 load steps");
}

/// A rigid footing on grid nodes (the plane twin of the square footing, h = B/5) reaches Prandtl's
/// limit pressure before it has moved a tenth of a cell, without a warning; pushed on by half a
/// cell, the soil beneath moves away from the footing's nodes (the grid stays, the material goes)
/// and the run warns `boundary_detached` once their filled fraction has halved, with the time.
#[test]
fn a_footing_on_grid_nodes_warns_when_the_soil_leaves_them() {
    let (s, header, rows) = run("tests/cases/footing_strip_nodes.toml", "footing-nodes-k2", &["parameters.k=2"]);
    let nc = column(&header, &rows, "footing.reaction_y").iter().map(|r| -2.0 * r / 1e4).fold(0.0, f64::max);
    eprintln!("strip footing on nodes, h = B/5: N_c = {nc:.4} against 2 + π");
    assert!((nc / (2.0 + std::f64::consts::PI) - 1.0).abs() < 0.03, "N_c = {nc}");
    assert!(!has_warning(&s, "boundary_detached"), "{}", s["warnings"]);
    let (s, _, _) = run(
        "tests/cases/footing_strip_nodes.toml",
        "footing-nodes-k2-far",
        &["parameters.k=2", "boundaries.footing.displacement=[0,-0.1]"],
    );
    let w = s["warnings"].as_array().unwrap().iter().find(|w| w["kind"] == "boundary_detached").expect("the warning");
    let (t, ratio) = (w["time_s"].as_f64().unwrap(), w["value"].as_f64().unwrap());
    eprintln!("pushed to d = h/2: warned at d = {:.3} m (h = 0.2 m), filled fraction {ratio:.3} of the first", 0.1 * t);
    assert!(w["message"].as_str().unwrap().contains("boundary `footing`"), "{w}");
    // The first step below half: just below it.
    assert!(ratio < 0.5 && ratio > 0.45 && (0.1 * t) > 0.02 && (0.1 * t) < 0.1, "{w}");
}

/// The particle loops run on threads, each assembling a band of node rows from every particle that
/// reaches it, in particle order: the history is the same to the last digit on one thread and on
/// three, for a one-phase static footing (B̄, plasticity) and for the two-phase slumping block
/// (u–p–U, extended nodes along its free surface, moving particles).
#[test]
fn threads_do_not_change_the_answer() {
    for (case, label, sets) in [
        ("cases/footing_peer.toml", "footing", vec!["parameters.h=0.25"]),
        ("cases/slumping_block.toml", "slump", vec!["stages.0.duration=0.02"]),
    ] {
        let runs: Vec<common::Run> = [1, 3]
            .iter()
            .map(|t| {
                let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("threads").join(format!("{label}-{t}"));
                let mut args = common::set_args(&sets);
                args.extend(["--threads".to_string(), t.to_string()]);
                let r = common::run_case(case, &dir, &args);
                assert!(r.completed(), "{label} on {t} thread(s): {}", r.stderr());
                r
            })
            .collect();
        assert!(runs[0].rows.len() > 2, "{label}: too few history rows");
        assert_eq!(runs[0].header, runs[1].header);
        for (a, b) in runs[0].rows.iter().zip(&runs[1].rows) {
            for (h, (x, y)) in runs[0].header.iter().zip(a.iter().zip(b)) {
                assert!(x.to_bits() == y.to_bits(), "{label}: {h} differs between 1 and 3 threads: {x:e} vs {y:e}");
            }
        }
    }
}

/// `pressure_update = "projected_total"` takes each particle's pressure from the total nodal field
/// (the consistent L² projection of the particles' pressures plus the step's nodal increments). On
/// quasi-static Terzaghi, where the particles barely move, the pressures the nodes can represent
/// come back unchanged, so the metrics equal those of the running sum of increments to a few 1e-5
/// (a lumped projection instead smooths every step: p RMS 0.45 against 7.4e-4, docs/analysis.md).
/// It cannot be combined with patch recovery, nor used in a one-phase case.
#[test]
fn the_projected_total_pressure_keeps_what_the_nodes_represent() {
    let q = ["stages.0.analysis=quasi_static"];
    let (inc, _, _) = run("cases/terzaghi.toml", "pressure-increments", &q);
    let (tot, _, _) =
        run("cases/terzaghi.toml", "pressure-projected", &[q[0], "stabilisation.pressure_update=projected_total"]);
    for m in ["p_rms_error_Tv0.1", "p_rms_error_Tv0.5", "settlement_rel_error_Tv0.5"] {
        let (a, b) = (metric(&inc, m), metric(&tot, m));
        assert!((a - b).abs() <= 1e-3 * a, "{m}: increments {a:e}, projected total {b:e}");
    }
    for (case, sets, why) in [
        ("cases/slumping_block.toml", vec!["stabilisation.pressure_update=projected_total"], "exclude each other"),
        ("cases/elastic_column.toml", vec!["stabilisation.pressure_update=projected_total"], "needs a two-phase case"),
    ] {
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("analysis").join("pressure-update-bad");
        common::assert_refused(case, &dir, &sets, why);
    }
}

/// The CI subset of the Terzaghi family (docs/terzaghi_family.md), beside the stiff corner above:
/// the dynamic u–p–U system on the shipped column converges at order ≥ 1 for each halving of h at
/// Δt = 2e-4 s (measured p RMS 1.42e-3 → 3.42e-4 → 1.29e-4 for N = 5, 10, 20), and the quasi-static
/// u–p system at the soft corner, E = 1e5 Pa, k = 1e-4 m/s (a skeleton 10⁴ times softer than the
/// water; load 1 Pa, a strain of 1e-5) on 40 cells converges at order ≥ 1 for each halving of Δt
/// (backward Euler: p RMS 3.41e-4 → 1.42e-4 → 4.26e-5 for 600, 1 200, 2 400 steps to T_v = 0.6;
/// at 600 steps the time error is the larger, so h-refinement alone stalls there: 4.6e-4 →
/// 1.8e-4 → 3.4e-4 for N = 10, 20, 40), and its base pressure does not alternate by more than
/// 1e-3 of the load after step 20.
#[test]
fn the_terzaghi_family_subset_converges_in_both_analysis_types() {
    let order = |e: &[f64]| -> Vec<f64> { e.windows(2).map(|w| (w[0] / w[1]).log2()).collect() };
    let dynamic: Vec<(f64, f64)> = [5, 10, 20]
        .iter()
        .map(|n| {
            let cells = format!("grid.cells=[1,{n}]");
            let (s, _, _) = run("cases/terzaghi.toml", &format!("family-dynamic-{n}"), &[&cells, "time.dt=2e-4"]);
            (metric(&s, "p_rms_error_Tv0.5"), metric(&s, "settlement_rel_error_Tv0.5"))
        })
        .collect();
    for (name, e) in [
        ("p RMS", dynamic.iter().map(|x| x.0).collect::<Vec<_>>()),
        ("settlement", dynamic.iter().map(|x| x.1).collect()),
    ] {
        assert!(order(&e).iter().all(|&o| o >= 1.0), "dynamic {name} errors {e:?}: orders {:?}", order(&e));
    }
    // c_v = k / (γ_w (1/E_c + n/K_w)); 600 steps to T_v = 0.6.
    let (k, e, q) = (1e-4, 1e5, 1.0);
    let cv = k / (9810.0 * (1.0 / e + 0.3 / 2.2e9));
    let t_end = 0.6 / cv;
    let mut rms = Vec::new();
    for steps in [600, 1200, 2400] {
        let sets = [
            "grid.cells=[1,40]".to_string(),
            format!("time.dt={}", t_end / steps as f64),
            format!("stages.consolidation.duration={t_end}"),
            format!("materials.soil.hydraulic_conductivity={k}"),
            format!("materials.soil.model.young_modulus={e}"),
            format!("loads.surface.traction=[0.0,{}]", -q),
            "stages.consolidation.analysis=quasi_static".to_string(),
            "output.history_every=1".to_string(),
        ];
        let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
        let (s, header, rows) = run("cases/terzaghi.toml", &format!("family-soft-{steps}"), &sets);
        rms.push(metric(&s, "p_rms_error_Tv0.5"));
        let alternation = alternation_after(&header, &rows, 20) * 1000.0 / q;
        assert!(alternation < 1e-3, "soft corner, {steps} steps: the base pressure alternates by {alternation:e} q");
    }
    assert!(order(&rms).iter().all(|&o| o >= 1.0), "quasi-static soft corner p RMS {rms:?}: orders {:?}", order(&rms));
}

/// The quasi-static u–p system drains through a moving surface: the large-strain column (settling
/// by 18 % of its height, so that its top passes grid lines) at 10 and 20 cells, Δt = 1e-3 s,
/// without patch recovery, settles within 2 % of Xie & Leo's answer at U_s = 0.5, and closer on the
/// finer grid (measured 0.83 % and 0.57 %; p RMS 5.4e-3 and 4.7e-3). With the pressure fixed at the
/// nodes beyond the surface instead of Nitsche's weak condition on the particles' faces, the
/// drainage vanished each time the surface neared a grid line: 20 % and 46 %, worse under
/// refinement.
#[test]
fn quasi_static_large_strain_consolidation_drains_through_the_moving_surface() {
    let errors: Vec<(f64, f64)> = [10, 20]
        .iter()
        .map(|n| {
            let cells = format!("grid.cells=[1,{n}]");
            let sets = [
                cells.as_str(),
                "stages.consolidation.analysis=quasi_static",
                "stabilisation.patch_recovery=false",
                "time.dt=1e-3",
                "output.fields_every=0",
            ];
            let (s, _, _) = run("cases/large_strain_consolidation.toml", &format!("large-strain-qs-{n}"), &sets);
            assert!(!has_warning(&s, "patch_recovery_quasi_static"), "{n} cells: {}", s["warnings"]);
            (metric(&s, "settlement_rel_error_Us0.5"), metric(&s, "p_rms_error_Us0.5"))
        })
        .collect();
    eprintln!("quasi-static large strain, 10 and 20 cells: (settlement, p RMS) {errors:?}");
    assert!(errors.iter().all(|e| e.0 <= 0.02 && e.1 <= 0.015), "errors {errors:?}");
    assert!(errors[1].0 < errors[0].0 && errors[1].1 < errors[0].1, "no convergence: {errors:?}");
    // The case's own patch recovery in a quasi-static stage is warned about.
    let sets =
        ["stages.consolidation.analysis=quasi_static", "stages.consolidation.duration=0.01", "output.fields_every=0"];
    let (s, _, _) = run("cases/large_strain_consolidation.toml", "large-strain-qs-patch", &sets);
    assert!(has_warning(&s, "patch_recovery_quasi_static"), "{}", s["warnings"]);
}

/// A step that full Newton steps cannot take is solved again with a line search before its Δt is
/// cut (`assembly::LINE_SEARCH_RETRY`): [002]'s strip footing (cases/footing_fbar.toml) as an
/// implicit static stage (von Mises clay, B̄, B/20, load steps of 0.01 s) at d/B ≈ 0.014, where a
/// node beside the footing that the heave has barely reached (1 % filled) takes unknowns of its
/// own. With the retry turned off (`-porompm_snes_line_search_retry false`) Newton diverges at
/// every cut of Δt and the run fails there (measured: the step from t = 1.43 s, the 144th); with it
/// the run goes on to d/B = 0.0145. The run without the retry restarts from the checkpoint the run
/// with it wrote at step 140 (restarts reproduce a run to round-off), so that the 140 steps both
/// take alike are solved once.
#[test]
fn a_step_that_full_newton_steps_cannot_take_is_taken_with_a_line_search() {
    let sets = [
        "parameters.h=0.05",
        "stages.penetration={name=\"penetration\",analysis=\"static\",duration=3.0,dt=0.01}",
        "materials.clay.model={type=\"von_mises\",young_modulus=1e6,poisson_ratio=0.49,cohesion=100.0}",
        "stabilisation={bbar=true}",
        "verification.plateau=[0.005,0.01]",
        "verification.stop_settlement=0.0145",
        "output.history_every=10",
    ];
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("analysis");
    let args = common::set_args(&sets);
    let checkpointed = [&args[..], &["--checkpoint-every".to_string(), "140".into()]].concat();
    let with = common::run_case("cases/footing_fbar.toml", &dir.join("retry"), &checkpointed);
    assert!(with.completed(), "{}", with.stderr());
    let retries = with.summary["line_search_retries"].as_u64().unwrap();
    assert!(retries >= 1, "line-search retries: {retries}");
    let checkpoint = dir.join("retry/checkpoint.h5");
    let mut args = [&args[..], &["--restart".to_string(), checkpoint.to_str().unwrap().into()]].concat();
    args.extend(["--".to_string(), "-porompm_snes_line_search_retry".into(), "false".into()]);
    let without = common::run_case("cases/footing_fbar.toml", &dir.join("no-retry"), &args);
    assert_eq!(without.summary["status"], "failed", "{}", without.stderr());
    assert!(without.stderr().contains("DIVERGED"), "{}", without.stderr());
    assert_eq!(without.summary["line_search_retries"], 0);
    let t = |r: &common::Run| r.summary["time_s"].as_f64().unwrap();
    eprintln!(
        "footing: {retries} retries, reached t = {:.2} s; without them failed at t = {:.2} s",
        t(&with),
        t(&without)
    );
    assert!(t(&with) > t(&without), "the retry carried the run past the failure");
}
