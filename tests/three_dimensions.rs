//! Three-dimensional runs through `porompm run` (issue «Three dimensions»): the driver over the
//! dimension-generic global system, on one and two ranks, and what a three-dimensional case cannot
//! do yet refused as bad input.

mod common;

use common::{run_case, run_case_on};

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

/// What a three-dimensional run cannot do yet is refused before anything runs, naming it.
#[test]
fn three_dimensional_runs_refuse_what_they_cannot_do_yet() {
    let dir = std::env::temp_dir().join("porompm-cube3d-refused");
    let r = run_case("tests/cases/cube_3d.toml", &dir, &["--checkpoint-every".into(), "1".into()]);
    assert_eq!(r.output.status.code(), Some(2), "{}", r.stderr());
    assert!(r.stderr().contains("cannot write checkpoints or restart yet"), "{}", r.stderr());
    let r = run_case(
        "tests/cases/cube_3d.toml",
        &dir,
        &[
            "--set".into(),
            "stages.0.analysis=dynamic_explicit".into(),
            "--set".into(),
            "analysis.kinematics=finite_strain".into(),
        ],
    );
    assert_eq!(r.output.status.code(), Some(2), "{}", r.stderr());
    assert!(r.stderr().contains("stages[0].analysis = \"dynamic_explicit\"`: not available"), "{}", r.stderr());
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_porompm"))
        .args(["test-jacobian", "tests/cases/cube_3d.toml"])
        .current_dir(common::root())
        .output()
        .expect("porompm runs");
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("test-jacobian checks two-dimensional cases only"));
}
