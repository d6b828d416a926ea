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

/// What a three-dimensional run cannot do yet is refused before anything runs, naming it.
#[test]
fn three_dimensional_runs_refuse_what_they_cannot_do_yet() {
    let dir = std::env::temp_dir().join("porompm-cube3d-refused");
    let r = run_case("tests/cases/cube_3d.toml", &dir, &["--checkpoint-every".into(), "1".into()]);
    assert_eq!(r.output.status.code(), Some(2), "{}", r.stderr());
    assert!(r.stderr().contains("cannot write checkpoints or restart yet"), "{}", r.stderr());
    common::assert_refused(
        "cases/terzaghi_3d.toml",
        &dir,
        &["stages.0.analysis=dynamic_explicit"],
        "a two_phase `dynamic_explicit` stage is not available in a three-dimensional case yet",
    );
    common::assert_refused(
        "tests/cases/cube_3d.toml",
        &dir,
        &["stabilisation.fbar=true", "analysis.kinematics=finite_strain"],
        "the implicit F̄ of stage `press` is not available in a three-dimensional case yet",
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
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_porompm"))
        .args(["test-jacobian", "tests/cases/cube_3d.toml"])
        .current_dir(common::root())
        .output()
        .expect("porompm runs");
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("test-jacobian checks two-dimensional cases only"));
}

/// [002]'s landslide (cases/landslide_3d.toml) on a prism one 0.5 m cell wide: the first 0.1 s of
/// its settling stage, at peak strength with F̄ at ν = 0.499, and the first hundredths of a second
/// after the trigger. The inclined face relaxes at a few decimetres per second at most. Seen
/// failing: with the FLIP increment formed from the raw projection's nodal velocities instead of
/// the grid update's own (the barely filled nodes' shares moved to their masters), the face blew up
/// (15 m/s at 0.1 s, 91 m/s at 0.15 s).
#[test]
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
