//! The explicit integrator (`analysis = "dynamic_explicit"`, [002] §2.2; `assembly::explicit`):
//! free fall reproduced to round-off as symplectic Euler, the CFL-limited step, the P-wave speed,
//! the elastic column settling to its static solution with the equilibrium identity of each
//! step, FLIP/PIC and local damping, and the same answers on two ranks.

mod common;
use common::*;
use std::path::PathBuf;

fn out_dir(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("porompm-explicit-{name}-{}", std::process::id()))
}

const EXPLICIT: [&str; 2] = ["stages.0.analysis=dynamic_explicit", "stages.1.analysis=dynamic_explicit"];

/// P-wave speed sqrt(E_c/ρ) of a linear elastic material.
fn p_wave_speed(e: f64, nu: f64, rho: f64) -> f64 {
    (e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu)) / rho).sqrt()
}

/// A block in free fall: every node has the same velocity, so the explicit step is symplectic
/// Euler exactly, v_{n+1} = v_n − g Δt and y_{n+1} = y_n + Δt v_{n+1}, to round-off; the step is
/// C h / c_p with the default C = 1/2.
/// So is it with the XPIC(5) transfer, whose filter S⁺S keeps a uniform velocity and whose
/// binomial weights sum to one (a wrong sign or weight breaks the fall).
#[test]
fn free_fall_is_symplectic_euler_to_round_off() {
    for xpic in [None, Some(5)] {
        free_fall(xpic);
    }
}

fn free_fall(xpic: Option<u8>) {
    let mut sets =
        vec!["stages.0.analysis=dynamic_explicit", "stages.0.duration=1.0", "probes=[{name=\"c\",point=[0.25,17.25]}]"];
    let transfer = xpic.map(|m| format!("stages.0.explicit={{xpic_order={m}}}"));
    sets.extend(transfer.as_deref());
    let r = run_case("tests/cases/falling_block.toml", &out_dir("fall"), &set_args(&sets));
    assert!(r.completed(), "{}", r.stderr());
    let (t, dt, y, vy) = (r.column("time"), r.column("dt"), r.column("c.y"), r.column("c.vy"));
    // h = 0.5 m, E = 10 MPa, ν = 0.3, ρ = 0.7 × 2000 + 0.3 × 1000 kg/m³.
    let limit = 0.5 * 0.5 / p_wave_speed(1e7, 0.3, 1700.0);
    assert!((dt[1] - limit).abs() <= 1e-12 * limit, "Δt {} vs C h/c_p {limit}", dt[1]);
    let (mut yr, mut vr, mut worst) = (y[0], 0.0, 0.0f64);
    for k in 1..t.len() {
        vr -= 9.81 * dt[k];
        yr += dt[k] * vr;
        worst = worst.max((y[k] - yr).abs());
        // history.csv keeps 11 significant digits.
        assert!(
            (vy[k] + 9.81 * t[k]).abs() <= 1e-10 * (1.0 + vy[k].abs()),
            "step {k}: v {} vs {}",
            vy[k],
            -9.81 * t[k]
        );
    }
    eprintln!("free fall ({xpic:?}): {} steps, worst |y − y_symplectic| {worst:.2e} m", t.len() - 1);
    assert!(worst <= 1e-9, "worst {worst}");
    assert_eq!(t.last().copied(), Some(1.0));
}

/// The elastic column (no gravity) loaded suddenly at the top: the stress front, taken where
/// σ_yy passes half the load, travels between two points 1 m apart at the P-wave speed
/// sqrt(E_c/ρ) = 260.1 m/s within 2.5 % (measured: −1.35 % at h = 5 cm; −0.88 % at 2.5 cm;
/// generalized-α at Δt = 0.1 ms: −1.48 %). A PIC share damps the front's overshoot, as does
/// local damping.
#[test]
fn a_stress_wave_travels_at_the_p_wave_speed() {
    let wave = |name: &str, extra: &[&str]| {
        let mut sets = vec![
            "time.dt=1e-4",
            "stages.0.loads=[\"surcharge\"]",
            "stages.1.loads=[\"surcharge\"]",
            "stages.0.duration=0.008",
            "stages.1.duration=0.0001",
            "time_functions.surcharge_ramp.start=0.0",
            "time_functions.surcharge_ramp.duration=0.0002",
            "probes=[{name=\"a\",point=[0.0125,1.5125]},{name=\"b\",point=[0.0125,0.5125]}]",
        ];
        sets.extend_from_slice(&EXPLICIT);
        sets.extend_from_slice(extra);
        let r = run_case("cases/elastic_column.toml", &out_dir(name), &set_args(&sets));
        assert!(r.completed(), "{name}: {}", r.stderr());
        let t = r.column("time");
        // The time at which probe `p`'s σ_yy first passes half the 5 kPa load (linear between rows).
        let cross = |p: &str| {
            let s = r.column(&format!("{p}.syy"));
            (1..t.len())
                .find(|&k| s[k - 1] > -2500.0 && s[k] <= -2500.0)
                .map(|k| t[k - 1] + (-2500.0 - s[k - 1]) * (t[k] - t[k - 1]) / (s[k] - s[k - 1]))
                .unwrap_or_else(|| panic!("{name}: the front never reached {p}"))
        };
        let distance = r.column("a.y")[0] - r.column("b.y")[0];
        let speed = distance / (cross("b") - cross("a"));
        let peak = r.column("b.syy").iter().fold(0.0f64, |m, &v| m.max(-v));
        (speed, peak)
    };
    let cp = p_wave_speed(1e8, 0.3, 1990.0);
    let (speed, peak) = wave("flip", &[]);
    eprintln!(
        "FLIP: front speed {speed:.2} m/s against c_p {cp:.2} ({:+.2} %), peak {peak:.0} Pa",
        100.0 * (speed / cp - 1.0)
    );
    assert!((speed / cp - 1.0).abs() <= 0.025, "speed {speed} vs {cp}");
    let (_, peak_pic) = wave("pic", &["stages.0.explicit={flip_blend=0.85}"]);
    let (_, peak_damped) = wave("damped", &["stages.0.explicit={local_damping=0.1}"]);
    eprintln!("peak |σ_yy| at the lower point: FLIP {peak:.0}, η = 0.85 {peak_pic:.0}, α = 0.1 {peak_damped:.0} Pa");
    assert!(peak_pic < peak && peak_damped < peak, "{peak} {peak_pic} {peak_damped}");
}

/// The elastic column's two stages (gravity, then a surcharge, each ramped over some thirty
/// periods) run explicitly reach the static solution as the implicit run does (settlement and
/// stress within the case's 1 %: measured 7.7e-5 and 6.3e-3, implicit 7.3e-5 and 6.3e-3), and
/// every step's forces balance ∫σ dV at the step's start to round-off (measured 6e-15).
#[test]
fn the_explicit_column_settles_to_the_static_solution() {
    let r = run_case("cases/elastic_column.toml", &out_dir("column"), &set_args(&EXPLICIT));
    assert!(r.completed(), "{}", r.stderr());
    let (settle, stress) = (metric(&r.summary, "settlement_rel_error"), metric(&r.summary, "stress_max_rel_error"));
    eprintln!(
        "explicit column: settlement error {settle:.2e}, stress error {stress:.2e}, steps {}",
        r.summary["steps"]
    );
    assert!(settle <= 1e-3 && stress <= 1e-2, "{settle} {stress}");
    let eq = r.summary["equilibrium_error"].as_f64().unwrap();
    assert!(eq <= 1e-12, "equilibrium error {eq:e}");
    assert_eq!(r.summary["solver"], "none (explicit steps only)");
    assert_eq!(r.summary["snes_iterations"].as_u64(), Some(0));
}

/// An explicit stage followed by an implicit one: the particles pass from one to the other, and
/// the summary names the implicit stage's solver.
#[test]
fn an_explicit_stage_hands_over_to_an_implicit_one() {
    let sets = ["stages.0.analysis=dynamic_explicit", "stages.0.duration=0.05", "stages.1.duration=0.05"];
    let r = run_case("cases/elastic_column.toml", &out_dir("mixed"), &set_args(&sets));
    assert!(r.completed(), "{}", r.stderr());
    assert!(r.summary["solver"].as_str().unwrap().contains("Newton"), "{}", r.summary["solver"]);
    assert_eq!(r.summary["steps"].as_u64(), Some(521 + 10));
    assert!(r.summary["equilibrium_error"].as_f64().unwrap() <= 1e-6);
}

/// The same explicit steps on one and two ranks (the column split across its height): every
/// probe value of every row agrees to round-off.
#[test]
fn explicit_steps_give_the_same_answers_on_two_ranks() {
    let mut sets = vec!["stages.0.duration=0.2", "stages.1.duration=0.05"];
    sets.extend_from_slice(&EXPLICIT);
    let one = run_case_on(1, "cases/elastic_column.toml", &out_dir("one"), &set_args(&sets));
    let two = run_case_on(2, "cases/elastic_column.toml", &out_dir("two"), &set_args(&sets));
    assert!(one.completed() && two.completed(), "{}\n{}", one.stderr(), two.stderr());
    assert_eq!(one.rows.len(), two.rows.len());
    for name in ["top.uy", "top.syy", "base.syy", "top.vy"] {
        let (a, b) = (one.column(name), two.column(name));
        let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (k, (x, y)) in a.iter().zip(&b).enumerate() {
            assert!((x - y).abs() <= 1e-10 * scale, "{name} row {k}: {x} vs {y}");
        }
    }
}

/// The neo-Hookean material in explicit stages: the kinematic patch test (every node follows
/// F = exp(L t), up to 10 % stretch and shear) gives every point the model's stress of F itself,
/// to round-off (measured 1.5e-13 at ν = 0.3, 2.9e-12 at ν = 0.499 after 74 and 818 steps), with
/// GIMP and quadratic B-splines; and with [002]'s F̄ projection, which leaves a homogeneous
/// deformation as it is (Part E item 6: uniform ΔF ⇒ ΔF̄ = ΔF).
#[test]
fn a_neo_hookean_patch_carries_the_stress_of_its_deformation() {
    for (basis, fbar) in [("gimp", "false"), ("bspline2", "false"), ("gimp", "true"), ("bspline2", "true")] {
        for nu in ["0.3", "0.499"] {
            let fbar = format!("stabilisation.fbar={fbar}");
            let model =
                format!("materials.solid.model={{type=\"neo_hookean\",young_modulus=1.0e6,poisson_ratio={nu}}}");
            let shape = format!("analysis.shape_functions={basis}");
            let sets = [
                "stages.0.analysis=dynamic_explicit",
                "materials.solid.solid_density=1000.0",
                "materials.solid.water_density=1000.0",
                model.as_str(),
                shape.as_str(),
                "stabilisation.bbar=false",
                "bodies.block.perturbation=0.3",
                "boundaries.flow.velocity_gradient=[[0.1,0.03],[0.03,-0.05]]",
                fbar.as_str(),
            ];
            let r = run_case("cases/patch_test.toml", &out_dir(&format!("nh-{basis}-{nu}-{fbar}")), &set_args(&sets));
            assert!(r.completed(), "{basis} {nu}: {}", r.stderr());
            let (spread, err) = (metric(&r.summary, "stress_spread"), metric(&r.summary, "stress_rel_error"));
            assert!(spread <= 1e-12 && err <= 1e-10, "{basis} {nu}: spread {spread:e}, error {err:e}");
        }
    }
}

/// [002]'s F̄ projection relieves volumetric locking: the tapered plate (ν = 0.499, 14 × 17 cells of
/// 4 m, mass scaled to ρ = 1 kg/m³ with local damping 0.2 so that it settles in 3 s) gives a tip
/// deflection of 2.80e-4 m per Pa with F̄ against 2.12e-4 without (the same as the implicit GIMP
/// without B̄), where Q1 finite elements with B̄ converge to 3.10e-4 (`scripts/cook_membrane_fe.py`).
#[test]
fn fbar_relieves_the_locking_of_a_nearly_incompressible_plate() {
    let tip = |fbar: &str| {
        let set = format!("stabilisation.fbar={fbar}");
        let sets = [
            "stages.0.analysis=dynamic_explicit",
            "stages.0.duration=3.0",
            "stabilisation.bbar=false",
            set.as_str(),
            "materials.m.solid_density=1.0",
            "materials.m.water_density=1.0",
            "stages.0.explicit={local_damping=0.2}",
            "output.history_every=50",
        ];
        let r = run_case("tests/cases/tapered_plate.toml", &out_dir(&format!("plate-{fbar}")), &set_args(&sets));
        assert!(r.completed(), "F̄ {fbar}: {}", r.stderr());
        assert!(r.summary["equilibrium_error"].as_f64().unwrap() <= 1e-12);
        *r.column("tip.uy").last().unwrap()
    };
    let (plain, fbar) = (tip("false"), tip("true"));
    let reference = 3.10e-4;
    eprintln!("tip u_y: without F̄ {plain:.4e}, with F̄ {fbar:.4e}, finite elements {reference:.3e}");
    assert!(plain < 0.75 * reference, "without F̄: {plain}");
    assert!((fbar / reference - 1.0).abs() <= 0.12, "with F̄: {fbar}");
}

/// Cook's membrane (`cases/cook_membrane.toml`, neo-Hookean, ν = 0.499; [002] §4.1, Part E item
/// 13) on 4 m cells, the coarsest grid with a line on the clamp (364 points, 200 s to rest): with
/// F̄ the tip settles at 0.261 m (−5.5 % against 0.2765 m; −2.2 % on 2 m cells), without it the
/// membrane locks at 0.199 m (−28 %), and F̄'s mean stress is smooth where the standard one is
/// chequered (index 0.39 against 2.4; 0.27 against 2.6 on 2 m cells). Both runs are at rest at the end (the tip
/// moves less than 0.3 % over the last 20 s). The finer grids and both bases are `make study`'s
/// (`cook_membrane_item_13`).
#[test]
fn fbar_unlocks_cooks_neo_hookean_membrane() {
    let run = |fbar: &str| {
        let set = format!("stabilisation.fbar={fbar}");
        let r = run_case(
            "cases/cook_membrane.toml",
            &out_dir(&format!("cook-{fbar}")),
            &set_args(&["parameters.h=4", &set]),
        );
        assert!(r.completed(), "F̄ {fbar}: {}", r.stderr());
        // The identity at every recorded step once the tip has moved a millimetre: below that the
        // stress of the total form σ(F) carries the round-off of F (λ ε_machine against stresses
        // of 1e-13 Pa in the first steps of the ramp: 3.5e-5 relative at t = 0.1 s).
        let (tip, error) = (r.column("tip.uy"), r.column("equilibrium_error"));
        let worst = tip.iter().zip(&error).filter(|(u, _)| u.abs() > 1e-3).map(|(_, e)| *e).fold(0.0, f64::max);
        assert!(worst <= 1e-9, "F̄ {fbar}: equilibrium error {worst:e}");
        let s = &r.summary;
        assert!(s["verification"]["tip_uy_change_last_tenth"]["pass"] == true, "F̄ {fbar}: not at rest");
        (s["results"]["tip_uy"].as_f64().unwrap(), s["results"]["mean_stress_checkerboard"].as_f64().unwrap())
    };
    let ((tip, board), (tip_std, board_std)) = (run("true"), run("false"));
    eprintln!("Cook's membrane, 4 m cells: tip u_y {tip:.4} (F̄) and {tip_std:.4} m (standard); chequerboard index of σ_m {board:.3} and {board_std:.3}");
    let reference = 0.2765;
    assert!((tip / reference - 1.0).abs() <= 0.10, "F̄ tip {tip}");
    assert!(tip_std < 0.8 * tip, "standard {tip_std} against F̄ {tip}");
    assert!(board <= board_std / 3.0, "chequerboard {board} against {board_std}");
}

/// [002]'s strip footing (`cases/footing_fbar.toml`, Part E item 14) on B/10 cells, pushed to
/// d/B = 0.01: with F̄ the Hencky–J2 clay (ν = 0.49) reaches a plateau of q near Prandtl's
/// (2 + π) s_u (measured 5.75 s_u, +12 % on these cells: the target tolerance at B/10 is 18 %);
/// standard MPM locks and "significantly overestimates" it ([002] L293; Part E: by more than
/// 10 %; measured 11.7 s_u). The equilibrium identity holds at every step's start to 1e-8 (measured
/// 5e-12 with F̄, 2e-9 without, the round-off of many steps; 1e-5 and 1.4e-3 before the grid
/// reached a cell beyond the base and the sides, where uGIMP domains pushed past the grid's edge
/// lost part of their weight).
#[test]
fn fbar_unlocks_a_rigid_footing_on_hencky_j2_clay() {
    let run = |fbar: &str| {
        let set = format!("stabilisation.fbar={fbar}");
        let r = run_case(
            "cases/footing_fbar.toml",
            &out_dir(&format!("footing-{fbar}")),
            &set_args(&[
                "parameters.h=0.1",
                "verification.plateau=[0.005,0.01]",
                "verification.stop_settlement=0.01",
                &set,
            ]),
        );
        assert!(r.completed(), "F̄ {fbar}: {}", r.stderr());
        let worst = r.column("equilibrium_error").iter().skip(1).copied().fold(0.0, f64::max);
        assert!(worst <= 1e-8, "F̄ {fbar}: equilibrium error {worst:e}");
        r.summary["verification"]["bearing_capacity_ratio"]["value"].as_f64().unwrap()
    };
    let (fbar, standard) = (run("true"), run("false"));
    eprintln!("footing on B/10 cells: q_ult/((2 + π) s_u) = {fbar:.4} with F̄, {standard:.4} without");
    assert!((fbar - 1.0).abs() <= 0.18, "F̄ {fbar}");
    assert!(standard > 1.10, "standard {standard}");
    assert!(standard > fbar + 0.5, "standard {standard} against F̄ {fbar}");
}

/// The footing of `cases/footing_fbar.toml` is a moving surface (`Model::surface_fixes`): its
/// prescribed nodes follow the soil's surface down past a grid line, so that the footing keeps
/// its grip after a settlement of more than a cell (the nodes of a fixed region lose the material
/// beneath them after three quarters of a cell, and with them the load: measured q/c from 5.1 to
/// 0.3 at d/B = 0.08 on B/10 cells). Here on B/5 cells to a cell and a quarter, with a third empty
/// row above the soil for its heave and a PIC share of 0.15 (pure FLIP on these coarse cells let a
/// point of the heave fly off at d ≈ 0.6 cells). Measured q/c at d/B = 0.05, 0.1, 0.15, 0.2, 0.25:
/// 6.97, 6.46, 6.03, 8.67 (the step after the grid line is passed), 6.97.
#[test]
fn a_rigid_footing_keeps_its_grip_past_a_grid_line() {
    let dir = out_dir("footing-grip");
    let r = run_case(
        "cases/footing_fbar.toml",
        &dir,
        &set_args(&[
            "parameters.h=0.2",
            "grid.size=[3.4,2.8]",
            "grid.cells=[17,14]",
            "stages.penetration.duration=30",
            "stages.penetration.explicit={cfl=0.4,flip_blend=0.85,local_damping=0.002}",
            "verification.plateau=[0.05,0.25]",
            "verification.stop_settlement=0.25",
            "verification.report_settlements=[0.05,0.1,0.15,0.2,0.25]",
        ]),
    );
    assert!(r.completed(), "{}", r.stderr());
    let res = &r.summary["results"];
    let q: Vec<f64> = ["0.05", "0.1", "0.15", "0.2", "0.25"]
        .iter()
        .map(|d| res[format!("q_over_c_at_dB{d}")].as_f64().unwrap())
        .collect();
    eprintln!("footing on B/5 cells: q/c at d/B = 0.05 … 0.25: {q:.3?}");
    for (k, v) in q.iter().enumerate() {
        let ratio = v / q[0];
        assert!((0.75..=1.5).contains(&ratio), "d/B = {:.2}: q/c {v} against {} at 0.05", 0.05 * (k + 1) as f64, q[0]);
    }
}

/// A checkpoint of an F̄ run carries each point's projected J̄ (`Particles::jbar`): the run
/// restarted from the middle ends where the uninterrupted one does, to round-off (measured: equal
/// to the last digit of history.csv; without J̄ in the checkpoint the tip differs in the sixth
/// digit). The projection's nodal sums are summed over the ranks: two ranks give the same run.
#[test]
fn an_fbar_run_restarts_from_its_checkpoint_and_runs_on_two_ranks() {
    let sets = ["parameters.h=4", "stages.0.duration=20", "output.history_every=1"];
    let full = out_dir("cook-full");
    let mut args = set_args(&sets);
    // 1803 steps: the checkpoint is rewritten at step 1000 and kept (none at 2000).
    args.extend(["--checkpoint-every".to_string(), "1000".to_string()]);
    let a = run_case("cases/cook_membrane.toml", &full, &args);
    assert!(a.completed(), "{}", a.stderr());
    let cp = full.join("checkpoint.h5");
    let mut args = set_args(&sets);
    args.extend(["--restart".to_string(), cp.display().to_string()]);
    let b = run_case("cases/cook_membrane.toml", &out_dir("cook-restart"), &args);
    assert!(b.completed(), "{}", b.stderr());
    assert_eq!(b.summary["restarted_from"]["step"].as_u64(), Some(1000));
    let two = run_case_on(2, "cases/cook_membrane.toml", &out_dir("cook-two"), &set_args(&sets));
    assert!(two.completed(), "{}", two.stderr());
    for name in ["tip.uy", "tip.sxx", "tip.syy", "tip.sxy"] {
        let (x, y, z) =
            (*a.column(name).last().unwrap(), *b.column(name).last().unwrap(), *two.column(name).last().unwrap());
        assert!((x - y).abs() <= 1e-9 * x.abs(), "{name}: {x} against {y} after the restart");
        assert!((x - z).abs() <= 1e-9 * x.abs(), "{name}: {x} on one rank, {z} on two");
    }
}

/// A displacement-controlled footing restarts where it stopped: the check keeps its baseline, its
/// curve and the footing's last reaction in the checkpoint (a repeated observation of the restored
/// step must not reset the settlement's zero, nor read q as 0 there). Several ranks sum the
/// footing's reaction to the one-rank load in the gold sweep (`tests/gold.rs`: `footing_fbar` on
/// three ranks).
#[test]
fn a_footing_run_restarts_from_its_checkpoint() {
    let sets = [
        "parameters.h=0.2",
        "verification.plateau=[0.005,0.01]",
        "verification.stop_settlement=0.01",
        "output.history_every=1",
    ];
    let full = out_dir("footing-full");
    let mut args = set_args(&sets);
    // About 2040 steps: the checkpoint is written at step 1900 and kept.
    args.extend(["--checkpoint-every".to_string(), "1900".to_string()]);
    let a = run_case("cases/footing_fbar.toml", &full, &args);
    assert!(a.completed(), "{}", a.stderr());
    let mut args = set_args(&sets);
    args.extend(["--restart".to_string(), full.join("checkpoint.h5").display().to_string()]);
    let b = run_case("cases/footing_fbar.toml", &out_dir("footing-restart"), &args);
    assert!(b.completed(), "{}", b.stderr());
    assert_eq!(b.summary["restarted_from"]["step"].as_u64(), Some(1900));
    let metric = |r: &Run| r.summary["verification"]["bearing_capacity_ratio"]["value"].as_f64().unwrap();
    let (x, y) = (metric(&a), metric(&b));
    assert!(x.is_finite() && (x - y).abs() <= 1e-9 * x, "{x}, restarted {y}");
    // The restart's first row repeats the restored step, with its load.
    let (ta, t0) = (a.column("time"), b.column("time")[0]);
    let k = ta.iter().position(|&t| t == t0).expect("the restored step in the full run's history");
    assert_eq!(b.column("bearing.q")[0], a.column("bearing.q")[k], "q at the restored step t = {t0}");
    for name in ["bearing.q", "bearing.d_over_B"] {
        let (x, y) = (*a.column(name).last().unwrap(), *b.column(name).last().unwrap());
        assert!((x - y).abs() <= 1e-9 * x.abs(), "{name}: {x} against {y} after the restart");
    }
}

/// Explicit settings that cannot work are refused, naming the key.
#[test]
fn bad_explicit_settings_are_named() {
    let dir = out_dir("bad");
    // A two-phase explicit stage holds its pore pressure at the points by default: a drained
    // boundary cannot fix it (tests/explicit_two_phase.rs has the rest).
    assert_refused(
        "cases/terzaghi.toml",
        &dir,
        &["stages.0.analysis=dynamic_explicit"],
        "key `boundaries` (`drained_top`): stage `consolidation` is explicit two-phase",
    );
    assert_refused(
        "cases/elastic_column.toml",
        &dir,
        &["stages.0.analysis=dynamic_explicit", "stages.0.explicit={cfl=1.5}"],
        "key `stages.self_weight.explicit.cfl`",
    );
    assert_refused(
        "cases/elastic_column.toml",
        &dir,
        &["stages.0.analysis=dynamic_explicit", "stages.0.explicit={flip_blend=-0.1}"],
        "key `stages.self_weight.explicit.flip_blend`",
    );
    assert_refused(
        "cases/elastic_column.toml",
        &dir,
        &["stages.0.analysis=dynamic_explicit", "stages.0.explicit={local_damping=1.0}"],
        "key `stages.self_weight.explicit.local_damping`",
    );
    assert_refused(
        "cases/elastic_column.toml",
        &dir,
        &["stages.0.explicit={cfl=0.3}"],
        "key `stages.self_weight.explicit`: only a dynamic_explicit stage",
    );
    assert_refused(
        "cases/elastic_column.toml",
        &dir,
        &["stages.0.analysis=dynamic_explicit", "stages.0.explicit={courant=0.3}"],
        "courant",
    );
    // F̄ runs in explicit stages and in the implicit u and u–p systems (`kernels::fbar`), not in
    // the u–p–U system of a two-phase dynamic stage, nor in geometrically linear steps.
    assert_refused(
        "cases/terzaghi.toml",
        &dir,
        &["stabilisation.fbar=true", "stabilisation.bbar=false"],
        "the F̄ projection is built for the u and u–p systems",
    );
    assert_refused(
        "cases/hollow_cylinder_increments.toml",
        &dir,
        &[
            "stabilisation.fbar=true",
            "stabilisation.stiffness=particle",
            "stabilisation.stress_recovery=basis",
            "analysis.geometry=\"plane_strain\"",
        ],
        "`analysis.kinematics = \"linear_increments\"` has none",
    );
    assert_refused(
        "cases/patch_test.toml",
        &dir,
        &["stabilisation.fbar=true", "stages.0.analysis=dynamic_explicit"],
        "`stabilisation.fbar` and `stabilisation.bbar` exclude each other",
    );
    assert_refused(
        "tests/cases/lame_sphere_axisymmetric.toml",
        &dir,
        &["analysis.kinematics=\"finite_strain\"", "stabilisation.bbar=false", "stabilisation.fbar=true"],
        "key `stabilisation.fbar`: plane strain only (in axial symmetry the projected J would need each point's hoop",
    );
    let neo = "materials.soil.model={type=\"neo_hookean\",young_modulus=1.0e8,poisson_ratio=0.3}";
    let fluid = "materials.soil.model={type=\"newtonian_fluid\",bulk_modulus=2.0e9,viscosity=1.0e-3}";
    assert_refused(
        "cases/elastic_column.toml",
        &dir,
        &[fluid, "stages.0.analysis=dynamic_explicit"],
        "`newtonian_fluid` runs in dynamic_explicit stages only",
    );
    assert_refused(
        "cases/elastic_column.toml",
        &dir,
        &[
            neo,
            "stages.0.analysis=dynamic_explicit",
            "stages.1.analysis=dynamic_explicit",
            "bodies.column.uniform_stress=[-1.0,-1.0,0.0,-1.0]",
        ],
        "a neo_hookean body takes no initial stress",
    );
    let patch_neo = "materials.solid.model={type=\"neo_hookean\",young_modulus=1.0e6,poisson_ratio=0.3}";
    assert_refused(
        "cases/patch_test.toml",
        &dir,
        &[patch_neo, "stages.0.analysis=static", "analysis.kinematics=\"linear_increments\""],
        "`neo_hookean` follows the total deformation, and `analysis.kinematics = \"linear_increments\"`",
    );
    let hencky = "materials.solid.model={type=\"hencky_j2\",young_modulus=1.0e6,poisson_ratio=0.3,cohesion=1.0e4}";
    assert_refused(
        "cases/patch_test.toml",
        &dir,
        &[hencky, "stages.0.analysis=static", "stabilisation.bbar=false", "stabilisation.fbar=true"],
        "`hencky_j2` in the implicit stage `stretch` does not take the implicit F̄ projection",
    );
    assert_refused(
        "cases/footing_fbar.toml",
        &dir,
        &["stabilisation={stress_recovery=\"cmpm\"}"],
        "a `hencky_j2` point recovers its elastic strain b^e from its stress and its volume ratio",
    );
    assert_refused(
        "cases/footing_fbar.toml",
        &dir,
        &["materials.clay.model.residual_cohesion=10.0", "materials.clay.model.softening_rate=1.0e5"],
        "key `materials[0].model.softening_rate`: the softening outpaces the elastic unloading",
    );
    assert_refused(
        "cases/footing_fbar.toml",
        &dir,
        &["materials.clay.model.residual_cohesion=200.0"],
        "key `materials[0].model.residual_cohesion`: must be in [0, cohesion = 100]",
    );
    assert_refused(
        "cases/footing_fbar.toml",
        &dir,
        &["verification.footing=\"base\""],
        "the boundary `base` must fix `uy` and move it vertically",
    );
    assert_refused(
        "cases/footing_fbar.toml",
        &dir,
        &["verification.footing=\"lid\""],
        "key `verification.footing`: no boundary named `lid`",
    );
    assert_refused(
        "cases/footing_fbar.toml",
        &dir,
        &["verification.failure_settlement=0.01"],
        "give `plateau` or `failure_settlement`, not both",
    );
    assert_refused(
        "cases/footing_fbar.toml",
        &dir,
        &["verification.plateau=[0.02,0.01]"],
        "key `verification.plateau`: give 0 ≤ d/B_from < d/B_to",
    );
}

/// The collapse of Martin & Moyce's n² = 2 water column (`cases/dam_break_martin_moyce.toml`,
/// weakly compressible here, K = 2e7 Pa, to keep the suite short: `make study-dam` runs the water's
/// 2 GPa): after the settling stage the pressure is hydrostatic within 2 % of ρ g H, the mass is
/// unchanged, the front stays behind Ritter's shallow-water front and within 10 % of the measured
/// one on average, and the equilibrium identity of every step holds. Without F̄ (standard MPM)
/// the pressure alternates from point to point ([002] L330–332): its chequerboard index is more
/// than three times F̄'s, settled and at the end (Part E item 15). Each check is seen to fail: a
/// settling stage a tenth as long leaves the pressure off the hydrostatic one, and XPIC(1) (PIC)
/// holds the front back.
#[test]
#[ignore = "make study: the whole collapse against the experiment; the default suite runs the case's first 0.15 s against its gold values on one and two ranks"]
fn the_collapsing_column_follows_martin_and_moyce() {
    let case = "cases/dam_break_martin_moyce.toml";
    let weak = [
        "materials.water.model.bulk_modulus=2e7",
        "stages.settle.duration=1.0",
        "stages.settle.explicit.local_damping=0.3",
    ];
    // The equilibrium identity holds to 2e-9 while the water settles; in the collapse it is off
    // by up to 2e-5 (measured), presumably at nodes that a point at the thinning tip reaches and
    // no well-filled node extends, which stay held (`assembly::stencils`) and keep a little force.
    let run = |name: &str, sets: &[&str]| {
        let all: Vec<&str> = weak.iter().chain(sets).copied().collect();
        let r = run_case(case, &out_dir(name), &set_args(&all));
        assert!(r.completed(), "{name}: {}", r.stderr());
        let worst = r.column("equilibrium_error").iter().skip(1).copied().fold(0.0, f64::max);
        assert!(worst <= 1e-4, "{name}: equilibrium error {worst:e}");
        r
    };
    let fbar = run("dam-fbar", &[]);
    for name in ["hydrostatic_pressure_error", "mass_change", "front_speed_ratio", "front_vs_experiment"] {
        assert_eq!(fbar.summary["verification"][name]["pass"], true, "{name}: {}", fbar.summary["verification"][name]);
    }
    let standard = run("dam-standard", &["stabilisation.fbar=false"]);
    let result = |r: &Run, name: &str| r.summary["results"][name].as_f64().unwrap();
    for name in ["pressure_checkerboard_settled", "pressure_checkerboard_end"] {
        let (f, s) = (result(&fbar, name), result(&standard, name));
        eprintln!("{name}: {f:.4e} with F̄, {s:.4e} without");
        assert!(f <= s / 3.0, "{name}: {f} with F̄ against {s} without");
    }
    let broken = run("dam-broken", &["stages.settle.duration=0.1", "stages.collapse.explicit.xpic_order=1"]);
    let (hydro, front) =
        (metric(&broken.summary, "hydrostatic_pressure_error"), metric(&broken.summary, "front_vs_experiment"));
    assert!(hydro > 0.02 && front > 0.1, "a short settling stage and PIC: hydrostatic {hydro}, front {front}");
}

/// A fluid and a dam break that cannot work are refused, naming the key.
#[test]
fn bad_fluid_and_dam_break_input_is_named() {
    let dir = out_dir("bad-fluid");
    let case = "cases/dam_break_martin_moyce.toml";
    assert_refused(case, &dir, &["verification.experiment=\"ritter\""], "unknown experiment `ritter`");
    assert_refused(
        case,
        &dir,
        &["bodies.water.shape={rectangle={min=[0.0,0.0],max=[1.0,1.0]}}"],
        "Martin & Moyce's series is for a column twice as high as wide",
    );
    assert_refused(
        case,
        &dir,
        &["verification.settle_stage=\"collapse\""],
        "is the last stage, so the water never flows",
    );
    assert_refused(case, &dir, &["verification.settle_stage=\"rest\""], "no stage named `rest`");
    assert_refused(case, &dir, &["verification.spray_fraction=0.2"], "key `verification.spray_fraction`");
    assert_refused(case, &dir, &["materials.water.model.viscosity=-1.0"], "key `materials[0].model.viscosity`");
    assert_refused(
        case,
        &dir,
        &["bodies.water.uniform_stress=[-1.0,-1.0,0.0,-1.0]"],
        "a newtonian_fluid body takes no initial stress",
    );
    assert_refused(
        case,
        &dir,
        &["stages.settle.analysis=dynamic"],
        "`newtonian_fluid` runs in dynamic_explicit stages only",
    );
    assert_refused("cases/terzaghi.toml", &dir, &["materials.soil.porosity=0.0"], "key `materials[0].porosity`");
    assert_refused(case, &dir, &["stages.collapse.explicit.xpic_order=9"], "m = 9 must lie in [1, 8]");
    assert_refused(
        case,
        &dir,
        &["stages.collapse.explicit.flip_blend=0.9"],
        "XPIC (`xpic_order`) replaces the FLIP/PIC blend",
    );
}

/// A dam-break run restarted from a checkpoint taken during the collapse ends where the full run
/// ends: the settled state, the front's history (which the comparison with the experiment reads)
/// and the speed bound come back with the checkpoint.
#[test]
fn a_dam_break_run_restarts_from_its_checkpoint() {
    let case = "cases/dam_break_martin_moyce.toml";
    let full = out_dir("dam-full");
    // Weakly compressible (K = 2e7 Pa) for speed: about 7100 steps (3540 settling), the
    // checkpoint written at step 5000 and kept.
    let weak = set_args(&["materials.water.model.bulk_modulus=2e7", "stages.settle.duration=1.0"]);
    let mut args = weak.clone();
    args.extend(["--checkpoint-every".to_string(), "5000".to_string()]);
    let a = run_case(case, &full, &args);
    assert!(a.completed(), "{}", a.stderr());
    let mut args = weak;
    args.extend(["--restart".to_string(), full.join("checkpoint.h5").display().to_string()]);
    let b = run_case(case, &out_dir("dam-restart"), &args);
    assert!(b.completed(), "{}", b.stderr());
    assert_eq!(b.summary["restarted_from"]["step"].as_u64(), Some(5000));
    for name in ["hydrostatic_pressure_error", "front_speed_ratio", "front_vs_experiment", "mass_change"] {
        let (x, y) = (metric(&a.summary, name), metric(&b.summary, name));
        assert!(x.is_finite() && (x - y).abs() <= 1e-9 * x.abs().max(1e-12), "{name}: {x}, restarted {y}");
    }
    let points = |r: &Run| r.summary["results"]["front_vs_experiment_points"].as_f64().unwrap();
    assert_eq!(points(&a), points(&b));
}

/// The fluid's viscous stress reaches the forces of the next step: an explicit step's forces are
/// those of the stress each point carries from its last update (update-stress-last), not of the
/// model evaluated again at the step's start, where a fluid's rate of deformation is zero and its
/// viscous stress would vanish (which made μ_v act on nothing: the column's centre of mass was
/// the same to 1e-12 m at μ_v = 0, 1e-3 and 20 Pa s). At μ_v = 20 Pa s (Re ≈ 200) the collapse is
/// slower (measured: x_c 4.1 mm behind at 0.5 s, 2.6 cm at 1 s).
#[test]
fn a_fluids_viscosity_slows_its_flow() {
    let run = |name: &str, mu: &str| {
        let sets = [
            "materials.water.model.bulk_modulus=2e7",
            "stages.settle.duration=1.0",
            "stages.settle.explicit.local_damping=0.3",
            "stages.collapse.duration=0.5",
        ];
        let mut all = sets.to_vec();
        let viscosity = format!("materials.water.model.viscosity={mu}");
        all.push(&viscosity);
        let r = run_case("cases/dam_break_martin_moyce.toml", &out_dir(name), &set_args(&all));
        assert!(r.completed(), "{name}: {}", r.stderr());
        *r.column("dam_break.centre_x").last().unwrap()
    };
    let (inviscid, viscous) = (run("inviscid", "0.0"), run("viscous", "20.0"));
    eprintln!("x_c at 0.5 s: {inviscid:.5} m inviscid, {viscous:.5} m at 20 Pa s");
    assert!(inviscid - viscous > 2e-3, "x_c {inviscid} inviscid against {viscous} viscous");
}
