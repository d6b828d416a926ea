//! Three-dimensional runs through `porompm run` (issue «Three dimensions»): the driver over the
//! dimension-generic global system, on one and two ranks, and what a three-dimensional case cannot
//! do yet refused as bad input.

mod common;

use common::{metric, run_case, run_case_on, set_args};

/// The elastic cube in uniaxial stress (`tests/cases/cube_3d.toml`) on one and two ranks: the
/// walls' reactions are σ_xx L² with σ_xx = E δ/L (to 1e-10), the rollers across carry nothing, and
/// two ranks give the one-rank history to round-off; the field files hold the three-dimensional
/// grid. At finite strain on two ranks (Newton to 1e-12) the equilibrium identity holds on the
/// moved configuration (a geometrically linear step's forces are those of x_n, so its identity on
/// x_{n+1} is off by the strain, 3e-3 here).
#[test]
fn a_cube_in_uniaxial_stress_runs_on_one_and_two_ranks() {
    let (e, l, d) = (2e7, 0.3, -1.5e-3);
    let want = e * d / l * l * l;
    let mut histories = Vec::new();
    for ranks in [1, 2] {
        let dir = std::env::temp_dir().join(format!("porompm-cube3d-{ranks}"));
        let r = run_case_on(ranks, "tests/cases/cube_3d.toml", &dir, &[]);
        assert!(r.completed(), "{ranks} ranks: {}", r.stderr());
        let last = |name: &str| *r.column(name).last().expect("a row");
        let press = [last("press.reaction_x"), last("press.reaction_y"), last("press.reaction_z")];
        let roller = last("x_roller.reaction_x");
        let others = [last("y_roller.reaction_y"), last("z_roller.reaction_z")];
        assert!((press[0] - want).abs() < 1e-10 * want.abs(), "{ranks} ranks: {press:?} against {want}");
        assert!((roller + want).abs() < 1e-10 * want.abs(), "{ranks} ranks: the roller carries {roller}");
        assert!(press[1..].iter().chain(&others).all(|v| v.abs() < 1e-10 * want.abs()), "{press:?} {others:?}");
        assert_eq!(r.summary["particles"], 6 * 6 * 6 * 8);
        let xdmf = std::fs::read_to_string(dir.join("fields.xdmf")).expect("fields.xdmf");
        assert!(xdmf.contains("7 7 7"), "the grid of 7 × 7 × 7 nodes: {xdmf}");
        histories.push((r.header, r.rows));
    }
    let dir = std::env::temp_dir().join("porompm-cube3d-finite");
    let args: Vec<String> =
        ["--set", "analysis.kinematics=finite_strain", "--", "-snes_rtol", "1e-12"].map(String::from).to_vec();
    let r = run_case_on(2, "tests/cases/cube_3d.toml", &dir, &args);
    assert!(r.completed(), "{}", r.stderr());
    let error = *r.column("equilibrium_error").last().expect("a row");
    assert!(error < 1e-10, "the equilibrium identity at finite strain on two ranks: {error}");
    let ((header, one), (_, two)) = (&histories[0], &histories[1]);
    assert_eq!(one.len(), two.len());
    // Every column but the ranks' load imbalance.
    let skip = header.iter().position(|h| h == "load_imbalance");
    for (a, b) in one.iter().zip(two) {
        for (_, (x, y)) in a.iter().zip(b).enumerate().filter(|(c, _)| Some(*c) != skip) {
            assert!(
                (x - y).abs() <= 1e-9 * x.abs().max(1.0) || (x.is_nan() && y.is_nan()),
                "{x} on one rank, {y} on two"
            );
        }
    }
}

/// The cube's loads in three dimensions, on one and two ranks (`tests/cases/cube_3d.toml` without its
/// pushed face): a face traction of 100 kPa on the face x = 0.3 m over z ∈ [0, 0.1] whose increment
/// is scaled by `increment_factor = "2 + 10 * z"`, evaluated at the loaded faces' mean centre
/// (z̄ = 0.05 m, ȳ = 0.15 m: g = 2.5), and a nodal traction of 10 kPa on the nodes of the face
/// y = 0.3 m (each standing for its tributary area). The rollers carry them: 1e5 × 0.03 × 2.5 =
/// 7.5 kN along x and 1e4 × 0.09 = 900 N along y, to 1e-10.
#[test]
fn a_cube_carries_a_face_traction_with_increments_and_a_nodal_traction() {
    let text = std::fs::read_to_string("tests/cases/cube_3d.toml").expect("the cube's case");
    let press = "[[boundaries]]\nname = \"press\"\nside = \"x_max\"\nfix = [\"ux\"]\n\
                 displacement = [-1.5e-3, 0.0, 0.0]  # m\ntime_function = \"ramp\"\n";
    assert!(text.contains(press), "the cube's pushed face");
    let loads = r#"[[loads]]
name = "side"
kind = "particle_traction"
region = { min = [0.25, 0.0], max = [0.3, 0.3], z = [0.0, 0.1] }
face = "x_max"
traction = [-1.0e5, 0.0, 0.0]
time_function = "ramp"
increment_factor = "2 + 10 * z"

[[loads]]
name = "top"
kind = "nodal_traction"
region = { min = [0.0, 0.3], max = [0.3, 0.3] }
traction = [0.0, -1.0e4, 0.0]
time_function = "ramp"
"#;
    let case = std::env::temp_dir().join("porompm-cube3d-loads.toml");
    std::fs::write(&case, text.replace(press, loads)).expect("the case written");
    for ranks in [1, 2] {
        let dir = std::env::temp_dir().join(format!("porompm-cube3d-loads-{ranks}"));
        let r = run_case_on(ranks, &case.display().to_string(), &dir, &[]);
        assert!(r.completed(), "{ranks} ranks: {}", r.stderr());
        let last = |name: &str| *r.column(name).last().expect("a row");
        let (x, y) = (last("x_roller.reaction_x"), last("y_roller.reaction_y"));
        println!("{ranks} rank(s): the rollers carry {x:.10e} N along x and {y:.10e} N along y");
        assert!((x - 7500.0).abs() < 1e-10 * 7500.0, "{ranks} ranks: x_roller carries {x}, not 7500 N");
        assert!((y - 900.0).abs() < 1e-10 * 900.0, "{ranks} ranks: y_roller carries {y}, not 900 N");
    }
}

/// The square footing at its coarsest mesh (k = 2, h = B/5) with [002]'s implicit F̄ instead of B̄,
/// on two ranks: N_c = 5.808, within 2 % of 5.91 already at this mesh (B̄ 5.146, 13 % low; without
/// either the soil locks, 8.30; F̄ measured 5.805 and 5.800 at k = 3 and 4), with the equilibrium
/// identity to 1e-5 of the loads.
#[test]
fn the_square_footing_with_fbar_is_within_five_percent_at_the_coarsest_mesh() {
    let dir = std::env::temp_dir().join("porompm-footing3d-fbar");
    let sets = set_args(&["parameters.k=2", "stabilisation={fbar=true}"]);
    let r = run_case_on(2, "tests/cases/footing_square_3d.toml", &dir, &sets);
    assert!(r.completed(), "{}", r.stderr());
    let ratio = &r.summary["verification"]["bearing_capacity_ratio"];
    let nc = ratio["value"].as_f64().unwrap() * 5.91;
    eprintln!("square footing with F̄, k = 2, two ranks: N_c = {nc:.4}");
    assert!((nc - 5.808).abs() < 0.01 && ratio["pass"] == true, "{ratio}");
    assert!(r.summary["equilibrium_error"].as_f64().unwrap() < 1e-5, "{}", r.summary["equilibrium_error"]);
}

/// [002]'s implicit F̄ in three dimensions (the projected volume ratio as a nodal unknown,
/// `kernels::fbar`, scaling the increment by (J̄/J)^{1/3}) passes the patch test on two ranks: the
/// cube in uniaxial stress at finite strain deforms homogeneously, so J̄ = J at every point, and
/// its reactions with F̄ are those without it to the Newton tolerance, at ν = 0.3 and at ν = 0.499,
/// with the equilibrium identity on the moved configuration.
#[test]
fn the_implicit_fbar_passes_the_patch_test_in_three_dimensions() {
    for nu in ["0.3", "0.499"] {
        let reactions = |fbar: bool| {
            let dir = std::env::temp_dir().join(format!("porompm-cube3d-fbar-{nu}-{fbar}"));
            let mut args = set_args(&[
                "analysis.kinematics=finite_strain",
                &format!("materials.solid.model.poisson_ratio={nu}"),
                &format!("stabilisation.fbar={fbar}"),
                "stabilisation.bbar=false",
            ]);
            args.extend(["--", "-snes_rtol", "1e-12"].map(String::from));
            let r = run_case_on(2, "tests/cases/cube_3d.toml", &dir, &args);
            assert!(r.completed(), "ν = {nu}, F̄ {fbar}: {}", r.stderr());
            let error = *r.column("equilibrium_error").last().expect("a row");
            assert!(error < 1e-10, "ν = {nu}, F̄ {fbar}: the equilibrium identity {error}");
            ["press.reaction_x", "x_roller.reaction_x", "y_roller.reaction_y", "z_roller.reaction_z"]
                .map(|c| *r.column(c).last().expect("a row"))
        };
        let (with, without) = (reactions(true), reactions(false));
        eprintln!("cube at ν = {nu}: reactions with F̄ {with:?}, without {without:?}");
        let scale = without[0].abs();
        assert!(scale > 0.0);
        for (a, b) in with.iter().zip(&without) {
            assert!((a - b).abs() <= 1e-9 * scale, "ν = {nu}: {a} with F̄, {b} without");
        }
    }
}

/// The square footing at its coarsest mesh (k = 2, h = B/5; `tests/cases/footing_square_3d.toml`)
/// on one and two ranks: the bearing check's pressure is the footing's reaction over its quarter
/// area (q_over_c_max = max −R_y/((B/2)² c) from history.csv, to its ten digits), its N_c is where the
/// mesh puts it (5.146: 13 % below 5.91, a failed metric at this mesh; the finest mesh is
/// `make study-footing-3d`'s), no warning, and two ranks give one rank's history to the Newton
/// tolerance.
#[test]
fn the_square_footing_runs_alike_on_one_and_two_ranks() {
    let mut histories = Vec::new();
    for ranks in [1, 2] {
        let dir = std::env::temp_dir().join(format!("porompm-footing3d-{ranks}"));
        let r =
            run_case_on(ranks, "tests/cases/footing_square_3d.toml", &dir, &["--set".into(), "parameters.k=2".into()]);
        assert!(r.completed(), "{ranks} ranks: {}", r.stderr());
        let from_history = r.column("footing.reaction_y").iter().map(|ry| -ry / (0.25 * 1e4)).fold(f64::MIN, f64::max);
        let reported = r.summary["results"]["q_over_c_max"].as_f64().unwrap();
        assert!((reported - from_history).abs() < 1e-9 * from_history, "{reported} against {from_history}");
        let ratio = &r.summary["verification"]["bearing_capacity_ratio"];
        let nc = ratio["value"].as_f64().unwrap() * 5.91;
        eprintln!("square footing, k = 2, {ranks} rank(s): N_c = {nc:.4} (peak {reported:.4})");
        assert!((nc - 5.146).abs() < 0.01 && ratio["pass"] == false, "{ratio}");
        assert!(r.summary["warnings"].as_array().unwrap().is_empty(), "{}", r.summary["warnings"]);
        histories.push(r.column("footing.reaction_y"));
    }
    for (a, b) in histories[0].iter().zip(&histories[1]) {
        assert!((a - b).abs() <= 1e-6 * a.abs().max(1.0), "{a} on one rank, {b} on two");
    }
}

/// The consolidating prism of `cases/terzaghi_3d.toml` by explicit steps (the u–U system with the
/// nodal pore pressure, the stage of `cases/terzaghi_explicit.toml`) on two ranks: its sides hold
/// plane strain, so its Terzaghi metrics are the plane explicit column's (one rank) to round-off
/// (e_p's over √2: [003] Eq. 33 divides by the number of points, and the prism has two layers),
/// over the same 24 411 steps, and so are its probes' histories (their z motion and shear
/// stresses zero) and the checkerboard and oscillation indices of its pore pressure; its pore pressure at T_v = 0.5 is within 1e-2 of the series.
#[test]
fn the_prism_consolidates_by_explicit_steps_as_the_plane_column() {
    let plane =
        run_case("cases/terzaghi_explicit.toml", &std::env::temp_dir().join("porompm-terzaghi-explicit-2d"), &[]);
    assert!(plane.completed(), "{}", plane.stderr());
    let sets = [
        "stages.0.analysis=dynamic_explicit",
        "stages.0.explicit={cfl=0.5, pore_pressure=\"nodal\"}",
        "output.history_every=100",
    ];
    let dir = std::env::temp_dir().join("porompm-terzaghi-explicit-3d");
    let solid = run_case_on(2, "cases/terzaghi_3d.toml", &dir, &set_args(&sets));
    assert!(solid.completed(), "{}", solid.stderr());
    assert_eq!(solid.summary["steps"], plane.summary["steps"]);
    let names: Vec<String> =
        plane.summary["verification"].as_object().expect("the plane metrics").keys().cloned().collect();
    assert!(names.iter().any(|n| n == "e_p_Tv0.5"), "{names:?}");
    // [003] Eq. 33 divides the root of the sum of squares by the number of points, and the prism
    // has two layers of the plane's points: its e_p is the plane's over √2.
    let points = |r: &common::Run| r.summary["particles"].as_f64().expect("a count");
    let layers = points(&solid) / points(&plane);
    assert_eq!(layers, 2.0);
    for name in &names {
        let (a, b) = (metric(&plane.summary, name), metric(&solid.summary, name));
        let b = if name.starts_with("e_p_") { b * layers.sqrt() } else { b };
        eprintln!("{name}: plane {a:.6e}, prism {b:.6e}");
        // The settlement's relative error is a difference of nearly equal settlements, which the
        // two ranks' sums in another order leave equal to 1e-9 of themselves.
        let tol = if name.starts_with("settlement") { 1e-9 } else { 1e-9 * a.abs() };
        assert!((a - b).abs() <= tol, "{name}: plane {a}, prism {b}");
    }
    assert!(metric(&solid.summary, "e_p_Tv0.5") < 1e-2);
    // The checkerboard fit of the pore pressure (3 × 3 × 3 cells; the prism's two layers of points
    // do not spread across a cell along z, so its fit is the plane's with every point twice).
    for column in ["checkerboard_index", "pressure_oscillation_index"] {
        let (a, b) = (plane.column(column), solid.column(column));
        assert!(a.iter().any(|&v| v > 0.0) && a.len() == b.len(), "{column}: {a:?}");
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() <= 1e-9 * x.abs().max(1e-12), "{column}: plane {x}, prism {y}");
        }
    }
    // The probes follow the same points: the plane's columns row for row, the z ones at rest.
    for probe in ["base", "middle"] {
        for column in ["p_excess", "uy", "vy", "syy", "y"] {
            let (a, b) = (plane.column(&format!("{probe}.{column}")), solid.column(&format!("{probe}.{column}")));
            assert_eq!(a.len(), b.len(), "{probe}.{column}");
            let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(scale > 0.0, "{probe}.{column} moves");
            for (x, y) in a.iter().zip(&b) {
                assert!((x - y).abs() <= 1e-9 * scale, "{probe}.{column}: plane {x}, prism {y}");
            }
        }
        for column in ["uz", "vz", "syz", "szx"] {
            let worst = solid.column(&format!("{probe}.{column}")).iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(worst < 1e-12, "{probe}.{column}: {worst}");
        }
    }
}

/// The consolidating prism with the projected total pressure update
/// (`stabilisation.pressure_update = "projected_total"`: each point's pressure the interpolation of
/// the L² projection of the points' pressures plus the step's increment, a CG solve on a DMDA of
/// the system's dimension and distribution) on two ranks consolidates as the plane column with it
/// on one (see [`prism_as_column`]). The update moves the prism's p_rms_error at T_v = 0.5 by 1.2 %
/// from the default update's.
#[test]
fn the_prism_with_the_projected_total_pressure_update_consolidates_as_the_plane_column() {
    prism_as_column("stabilisation.pressure_update=projected_total", "projected");
}

/// The consolidating prism with [003]'s MLSA patch recovery of the pore-pressure increments
/// (`stabilisation.patch_recovery = true`: linear fits over the active cells around each node,
/// `model::patch` in D dimensions; the prism, one cell wide along x and z, fits along y only, as
/// the column does) on two ranks consolidates as the plane column with it on one (see
/// [`prism_as_column`]).
#[test]
fn the_prism_with_patch_recovery_consolidates_as_the_plane_column() {
    prism_as_column("stabilisation.patch_recovery=true", "recovered");
}

/// `cases/terzaghi_3d.toml` with the override `set` on two ranks against `cases/terzaghi.toml` with
/// it on one: the Terzaghi metrics equal to 1e-10 (errors relative to the load's pressure or the
/// settlement; e_p's over √2: [003] Eq. 33 divides by the number of points, and the prism has two
/// layers of the column's) and the probes' pore pressures row for row to 1e-8 of their largest;
/// and `set` moves the prism's p_rms_error at T_v = 0.5 by more than 1e-3 of itself, so the
/// comparison sees it.
fn prism_as_column(set: &str, label: &str) {
    let sets = set_args(&[set]);
    let dir = |d: &str| std::env::temp_dir().join(format!("porompm-terzaghi-{label}-{d}"));
    let plane = run_case("cases/terzaghi.toml", &dir("2d"), &sets);
    assert!(plane.completed(), "{}", plane.stderr());
    let solid = run_case_on(2, "cases/terzaghi_3d.toml", &dir("3d"), &sets);
    assert!(solid.completed(), "{}", solid.stderr());
    let default = run_case("cases/terzaghi_3d.toml", &dir("default"), &[]);
    assert!(default.completed(), "{}", default.stderr());
    let names: Vec<String> =
        plane.summary["verification"].as_object().expect("the plane metrics").keys().cloned().collect();
    assert!(names.iter().any(|n| n == "p_rms_error_Tv0.5"), "{names:?}");
    for name in &names {
        let (a, b) = (metric(&plane.summary, name), metric(&solid.summary, name));
        let b = if name.starts_with("e_p_") { b * 2f64.sqrt() } else { b };
        eprintln!("{label}: {name}: plane {a:.10e}, prism {b:.10e}");
        assert!((a - b).abs() <= 1e-10, "{set}: {name}: plane {a}, prism {b}");
    }
    let (with, without) = (metric(&solid.summary, "p_rms_error_Tv0.5"), metric(&default.summary, "p_rms_error_Tv0.5"));
    eprintln!("{label}: p_rms_error_Tv0.5 {with:.6e} with `{set}`, {without:.6e} without");
    assert!((with - without).abs() > 1e-3 * without, "`{set}` does not move the prism's pressures");
    for probe in ["base", "middle"] {
        let (a, b) = (plane.column(&format!("{probe}.p_excess")), solid.column(&format!("{probe}.p_excess")));
        assert_eq!(a.len(), b.len(), "{probe}.p_excess");
        let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() <= 1e-8 * scale, "{set}: {probe}.p_excess: plane {x}, prism {y}");
        }
    }
}

/// A three-dimensional run restarts from its checkpoint as a plane one does: the consolidating
/// prism on two ranks writes a checkpoint at step 350 of 600 (its points' records with three
/// components per vector); restarted from it on one rank, it ends with the uninterrupted run's
/// Terzaghi metrics (T_v = 0.1 passed before the checkpoint, restored with the check's state;
/// T_v = 0.5 after it), Newton iterations and probes' final values, to 1e-10. The plane column's
/// checkpoint is refused by the prism.
#[test]
fn a_three_dimensional_run_restarts_from_its_checkpoint() {
    let full = std::env::temp_dir().join("porompm-terzaghi3d-restart-full");
    let a = run_case_on(2, "cases/terzaghi_3d.toml", &full, &["--checkpoint-every".into(), "350".into()]);
    assert!(a.completed(), "{}", a.stderr());
    let cp = full.join("checkpoint.h5");
    let x = hdf5_metno::File::open(&cp).expect("the checkpoint").dataset("particles/x").expect("x").shape();
    assert_eq!(x, [80, 3]);
    let again = std::env::temp_dir().join("porompm-terzaghi3d-restart-again");
    let b = run_case("cases/terzaghi_3d.toml", &again, &["--restart".into(), cp.display().to_string()]);
    assert!(b.completed(), "{}", b.stderr());
    assert_eq!(b.summary["restarted_from"]["step"], 350);
    assert_eq!(a.summary["steps"], b.summary["steps"]);
    assert_eq!(a.summary["snes_iterations"], b.summary["snes_iterations"]);
    for m in ["e_p_Tv0.1", "e_p_Tv0.5", "p_rms_error_Tv0.5"] {
        let (x, y) = (metric(&a.summary, m), metric(&b.summary, m));
        assert!((x - y).abs() <= 1e-10 * x.abs(), "{m}: {x} uninterrupted, {y} restarted");
    }
    // The settlement's relative error, a difference of nearly equal settlements: to 1e-10 of the
    // settlement (the two ranks' sums and the one rank's run in another order).
    let (x, y) = (metric(&a.summary, "settlement_rel_error_Tv0.5"), metric(&b.summary, "settlement_rel_error_Tv0.5"));
    assert!((x - y).abs() <= 1e-10, "the settlement's error: {x} uninterrupted, {y} restarted");
    for r in ["middle.excess_p_final", "base.displacement"] {
        let (x, y) = (a.summary["results"][r].as_f64().unwrap(), b.summary["results"][r].as_f64().unwrap());
        assert!((x - y).abs() <= 1e-10 * x.abs(), "{r}: {x} uninterrupted, {y} restarted");
    }
    let plane = std::env::temp_dir().join("porompm-terzaghi2d-for-3d-restart");
    let p = run_case("cases/terzaghi.toml", &plane, &["--checkpoint-every".into(), "350".into()]);
    assert!(p.completed(), "{}", p.stderr());
    let wrong = run_case(
        "cases/terzaghi_3d.toml",
        &std::env::temp_dir().join("porompm-terzaghi3d-wrong-restart"),
        &["--restart".into(), plane.join("checkpoint.h5").display().to_string()],
    );
    assert_eq!(wrong.output.status.code(), Some(2), "{}", wrong.stderr());
    assert!(wrong.stderr().contains("written by a different case"), "{}", wrong.stderr());
}

/// The cube's case as a bar of 1 × 1 × 6 cells in uniaxial stress along x, on a grid of 1 × 2 × 12
/// cells (its points in the lower half along z): only z can be split over two ranks (the other
/// directions have too few nodes for two slabs of the stencil width), and PETSc's even split leaves
/// one rank without a point (imbalance 2). With the default threshold the run repartitions the
/// grid after its first step (`distribution::balanced` in three dimensions, from the points per
/// cell in all three directions: a split that ignored z would give a rank two of the six cell
/// layers), the imbalance is 1 after it, and the reactions are those of the run that never
/// repartitions.
#[test]
fn a_three_dimensional_grid_is_repartitioned_when_the_points_crowd_onto_one_rank() {
    let sets = [
        "grid.size=[0.05,0.1,0.6]",
        "grid.cells=[1,2,12]",
        "bodies[0].shape={rectangle={min=[0.0,0.0],max=[0.05,0.05]}}",
        "bodies[0].z=[0.0,0.3]",
        "stages.0.dt=0.25",
        "output.fields_every=0",
    ];
    let run = |label: &str, extra: &[&str]| {
        let mut args = set_args(&sets);
        args.extend(extra.iter().map(|a| a.to_string()));
        let r = run_case_on(2, "tests/cases/cube_3d.toml", &std::env::temp_dir().join(label), &args);
        assert!(r.completed(), "{label}: {}", r.stderr());
        r
    };
    let fixed = run("porompm-cube3d-balance-never", &["--balance-threshold", "inf"]);
    let balanced = run("porompm-cube3d-balance-default", &[]);
    let (never, after) = (fixed.column("load_imbalance"), balanced.column("load_imbalance"));
    eprintln!("cube on two ranks: imbalance {never:?} without repartitioning, {after:?} with");
    assert_eq!(fixed.summary["repartitions"], 0);
    assert!(never.iter().all(|&i| i >= 1.9), "PETSc's split leaves a rank idle: {never:?}");
    assert!(balanced.summary["repartitions"].as_u64().unwrap() >= 1);
    assert!(after[1..].iter().all(|&i| i <= 1.2), "after the first step: {after:?}");
    // Every reaction against the load's scale (the rollers across carry nothing but round-off).
    let scale = fixed.column("press.reaction_x").iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0);
    for name in ["press.reaction_x", "x_roller.reaction_x", "y_roller.reaction_y", "z_roller.reaction_z"] {
        let (a, b) = (fixed.column(name), balanced.column(name));
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() <= 1e-9 * scale, "{name}: {x} without, {y} with repartitioning");
        }
    }
}

/// What a three-dimensional run cannot do yet is refused before anything runs, naming it.
#[test]
fn three_dimensional_runs_refuse_what_they_cannot_do_yet() {
    let dir = std::env::temp_dir().join("porompm-cube3d-refused");
    // A probe takes one coordinate per dimension, inside the grid.
    common::assert_refused(
        "cases/terzaghi_3d.toml",
        &dir,
        &["probes=[{name=\"top\", point=[0.05, 0.95]}]"],
        "key `probes[0].point`: 3 components in a case of 3 dimensions, got 2",
    );
    common::assert_refused(
        "cases/terzaghi_3d.toml",
        &dir,
        &["probes=[{name=\"top\", point=[0.05, 0.95, 0.2]}]"],
        "key `probes[0].point`: [0.05, 0.95, 0.2] is outside the grid",
    );
    common::assert_refused(
        "cases/terzaghi_3d.toml",
        &dir,
        &["stabilisation.stiffness=\"gauss_mapping\""],
        "key `stabilisation.stiffness`: not available in a three-dimensional case yet",
    );
    common::assert_refused(
        "cases/terzaghi_3d.toml",
        &dir,
        &["loads=[{name=\"surface\", kind=\"line_pressure\", points=[[0.0, 1.0], [0.1, 1.0]], pressure=1.0}]"],
        "a line pressure acts on a plane polyline",
    );
    // The footing's bearing check: a 3D loaded area needs its extent along z; a plane one has none.
    common::assert_refused(
        "tests/cases/footing_square_3d.toml",
        &dir,
        &["verification.loaded_depth=-0.5"],
        "key `verification.loaded_depth`: must be a positive number",
    );
    common::assert_refused(
        "tests/cases/footing_strip_nodes.toml",
        &dir,
        &[
            "verification.kind=bearing_capacity",
            "verification.soil=soil",
            "verification.footing=footing",
            "verification.loaded_width=0.5",
            "verification.loaded_depth=0.5",
            "verification.breadth=1",
            "verification.settlement_point=[0,2]",
        ],
        "key `verification.loaded_depth`: only a three-dimensional case takes it",
    );
    common::assert_refused(
        "tests/cases/footing_square_3d.toml",
        &dir,
        &["verification.settlement_point=[0,1]"],
        "key `verification.settlement_point`: 3 components",
    );
}

/// The assembled three-dimensional tangents against central differences of the assembled residual,
/// block by block (`porompm test-jacobian`, one rank): a consolidating block's u–p–U system after
/// three steps (7 × 7 blocks, every one of them exercised), the square footing's plastic Tresca soil
/// (h = B/3) with B̄ after six steps (3 × 3 blocks, points yielded) and with the implicit F̄ after
/// nine (4 × 4 blocks with the projected volume ratio); each within 1e-6. A flipped sign in one
/// block of each (p–ux, uy–ux, Jbar–uz) is caught.
#[test]
fn the_three_dimensional_tangents_match_finite_differences_block_by_block() {
    // A block of consolidating soil in a corner of a larger grid (walls at x_min and z_min only),
    // loaded on a quarter of its top: it deforms in three dimensions.
    let prism = [
        "cases/terzaghi_3d.toml",
        "--steps",
        "3",
        "--set",
        "probes=[]",
        "--set",
        "grid.size=[0.3,0.5,0.3]",
        "--set",
        "grid.cells=[3,5,3]",
        "--set",
        "bodies[0].shape={rectangle={min=[0.0,0.0],max=[0.2,0.4]}}",
        "--set",
        "bodies[0].z=[0.0,0.2]",
        "--set",
        "loads[0].region={min=[0.0,0.2],max=[0.1,0.4],z=[0.0,0.1]}",
        "--set",
        "stages.0.boundaries=[\"base\",\"left\",\"back\",\"drained_top\"]",
    ];
    common::assert_tangent_checked(&prism, 49, "p,ux");

    let coarse = ["tests/cases/footing_square_3d.toml", "--set", "parameters.k=1"];
    let text = common::assert_tangent_checked(&[&coarse[..], &["--steps", "6"]].concat(), 9, "uy,ux");
    let yielded = common::yielded_points(&text);
    assert!(yielded > 0, "the plastic tangent takes part: {text}");

    // After nine steps (269 points yielded): after three the u–Jbar columns differ from the central
    // differences by 1.2e-6 of their scale, after six by 1.3e-6, where the differences' own noise
    // is (the elastic soil's u–Jbar columns: 4e-7; the plane F̄'s: 2.5e-7).
    let fbar = [&coarse[..], &["--steps", "9", "--set", "stabilisation={fbar=true}"]].concat();
    common::assert_tangent_checked(&fbar, 16, "Jbar,uz");
}

/// [002]'s landslide (cases/landslide_3d.toml) on a prism one 0.5 m cell wide: the first 0.1 s of
/// its settling stage, at peak strength with F̄ at ν = 0.499, and the first hundredths of a second
/// after the trigger. The inclined face relaxes at a few decimetres per second at most. Seen
/// failing: with the FLIP increment formed from the raw projection's nodal velocities instead of
/// the grid update's own (the barely filled nodes' shares moved to their masters), the face blew up
/// (15 m/s at 0.1 s, 91 m/s at 0.15 s).
#[test]
#[ignore = "make study: the default suite runs the same prism's settling and failure stages against their gold values on one and two ranks, which a blow-up changes"]
fn the_landslide_face_settles_without_blowing_up() {
    let dir = std::env::temp_dir().join("porompm-landslide-settle");
    let mut sets: Vec<String> =
        ["parameters.W=0.5", "time.dt=0.001", "stages.settle.duration=0.1", "verification.snapshot_times=[]"]
            .map(String::from)
            .into();
    for s in ["failure", "failure_to_2s5", "failure_to_3s5", "failure_to_5s5"] {
        sets.push(format!("stages.{s}.duration=0.005"));
    }
    let r = run_case("cases/landslide_3d.toml", &dir, &set_args(&sets.iter().map(String::as_str).collect::<Vec<_>>()));
    assert!(r.completed(), "{}", r.stderr());
    let speed = r.column("max_speed").into_iter().fold(0.0, f64::max);
    assert!(speed > 0.05 && speed < 0.5, "largest speed {speed} m/s");
    assert_eq!(metric(&r.summary, "mass_change"), 0.0);
    let strain = r.column("max_plastic_strain").into_iter().fold(0.0, f64::max);
    assert!(strain < 0.05, "largest plastic strain {strain}");
}

/// The kinematic patch test in three dimensions (`cases/patch_test_3d.toml`): every grid node
/// follows the homogeneous flow exp(L s) of a boundary's 3 × 3 velocity gradient (stretch and
/// shear in all three planes), and every point must carry the same stress, that of linear
/// elasticity for the flow: for GIMP, uGIMP, linear MPM and quadratic and cubic B-splines, with B̄
/// (not with B-splines, which refuse it), with the implicit F̄ and with neither, at ν = 0.3 on the
/// regular arrangement and at ν = 0.4999 on a perturbed one, on one rank and (GIMP with B̄,
/// perturbed) on two.
#[test]
fn the_kinematic_patch_test_holds_in_three_dimensions() {
    let mut worst: (f64, f64) = (0.0, 0.0);
    let mut runs = Vec::new();
    for basis in ["gimp", "ugimp", "linear", "bspline2", "bspline3"] {
        for (bbar, fbar) in [(true, false), (false, true), (false, false)] {
            if bbar && basis.starts_with("bspline") {
                continue;
            }
            for (nu, pert) in [("0.3", "0"), ("0.4999", "0.3")] {
                runs.push((1, basis, bbar, fbar, nu, pert));
            }
        }
    }
    runs.push((2, "gimp", true, false, "0.3", "0.3"));
    for (ranks, basis, bbar, fbar, nu, pert) in runs {
        let label = format!("{basis}-{bbar}-{fbar}-{nu}-{pert}-{ranks}");
        let sets = set_args(&[
            &format!("analysis.shape_functions={basis}"),
            &format!("stabilisation.bbar={bbar}"),
            &format!("stabilisation.fbar={fbar}"),
            &format!("materials.solid.model.poisson_ratio={nu}"),
            &format!("bodies.block.perturbation={pert}"),
        ]);
        let dir = std::env::temp_dir().join(format!("porompm-patch3d-{label}"));
        let r = run_case_on(ranks, "cases/patch_test_3d.toml", &dir, &sets);
        assert!(r.completed(), "{label}: {}", r.stderr());
        assert_eq!(r.summary["particles"], 512, "{label}");
        let (spread, err) = (metric(&r.summary, "stress_spread"), metric(&r.summary, "stress_rel_error"));
        // With F̄ every node that a point reaches at all carries ϑ (`dofs::carries_unknown`): with a
        // threshold of 1e-12 of a cell instead, a corner node beyond the cube, reached by a sliver
        // ∝ δ³, carried none although its S_ip was not zero, and the spread of the regular GIMP and
        // uGIMP arrangements grew step by step to 3.2e-12–3.9e-12.
        let bound = 1e-12;
        assert!(spread <= bound, "{label}: stress spread {spread:e}");
        // The Hughes–Winget increments sum to ln V up to (|L|Δt)²/12 per step.
        assert!(err <= 2e-7, "{label}: stress error {err:e}");
        worst = (worst.0.max(spread), worst.1.max(err));
    }
    eprintln!("3D kinematic patch tests: worst spread {:.2e}, worst error against ln V {:.2e}", worst.0, worst.1);
}

/// A block under a full uniform stress (all six components) turned rigidly by a quarter turn about
/// the skew axis (2, −1, 2)/3 (the boundary's velocity gradient ω W, its nodes moved by Rodrigues'
/// rotation exp(ω W s)): at every step size every point's stress is R σ₀ Rᵀ to round-off (the
/// Hughes–Winget rotation of the increments is exact for a rigid spin: the error grows with the
/// number of steps, 2.8e-13 after 10 and 1.2e-12 after 40, not with their size), on one and two
/// ranks.
#[test]
fn a_rigid_rotation_about_a_skew_axis_turns_the_full_stress() {
    let w = std::f64::consts::FRAC_PI_2;
    let a = [2.0 / 3.0, -1.0 / 3.0, 2.0 / 3.0];
    let l = [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]].map(|r| r.map(|v: f64| v * w));
    let gradient = format!("boundaries.flow.velocity_gradient={l:?}");
    for (ranks, dt) in [(1, "0.1"), (1, "0.025"), (2, "0.1")] {
        let sets = set_args(&[
            &gradient,
            "bodies.block.uniform_stress=[-3.0e4, -1.0e4, 4.0e3, -2.0e4, 2.5e3, -1.5e3]",
            "stages.0.analysis=static",
            "materials.solid.model.young_modulus=1.0e7",
            &format!("time.dt={dt}"),
        ]);
        let dir = std::env::temp_dir().join(format!("porompm-rotation3d-{dt}-{ranks}"));
        let r = run_case_on(ranks, "cases/patch_test_3d.toml", &dir, &sets);
        assert!(r.completed(), "Δt = {dt}, {ranks} ranks: {}", r.stderr());
        let (spread, err) = (metric(&r.summary, "stress_spread"), metric(&r.summary, "stress_rel_error"));
        eprintln!("rigid rotation about a skew axis, Δt = {dt}, {ranks} rank(s): spread {spread:.2e}, error {err:.2e}");
        assert!(spread <= 1e-12 && err <= 1e-11, "Δt = {dt}, {ranks} ranks: spread {spread:e}, error {err:e}");
    }
}

/// A neo-Hookean block in explicit steps follows a finite flow of stretch, shear and spin
/// (‖L‖ ≈ 0.1 /s for 1 s) and carries the neo-Hookean stress of F = exp(L) at every point, to
/// round-off: GIMP and quadratic B-splines, with and without [002]'s F̄ projection (a homogeneous
/// deformation leaves J̄ = J), at ν = 0.3 and 0.499, on a perturbed arrangement.
#[test]
fn a_neo_hookean_block_carries_the_stress_of_its_deformation_in_three_dimensions() {
    for basis in ["gimp", "bspline2"] {
        for fbar in ["false", "true"] {
            for nu in ["0.3", "0.499"] {
                let label = format!("{basis}-{fbar}-{nu}");
                let sets = set_args(&[
                    "stages.0.analysis=dynamic_explicit",
                    "materials.solid.solid_density=1000.0",
                    "materials.solid.water_density=1000.0",
                    &format!("materials.solid.model={{type=\"neo_hookean\",young_modulus=1.0e6,poisson_ratio={nu}}}"),
                    &format!("analysis.shape_functions={basis}"),
                    "stabilisation.bbar=false",
                    &format!("stabilisation.fbar={fbar}"),
                    "bodies.block.perturbation=0.3",
                    "boundaries.flow.velocity_gradient=[[0.1,0.05,-0.02],[0.01,-0.05,0.03],[-0.04,0.01,0.04]]",
                ]);
                let dir = std::env::temp_dir().join(format!("porompm-nh3d-{label}"));
                let r = run_case("cases/patch_test_3d.toml", &dir, &sets);
                assert!(r.completed(), "{label}: {}", r.stderr());
                let (spread, err) = (metric(&r.summary, "stress_spread"), metric(&r.summary, "stress_rel_error"));
                assert!(spread <= 1e-12 && err <= 1e-10, "{label}: spread {spread:e}, error {err:e}");
            }
        }
    }
}
