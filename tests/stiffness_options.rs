//! The material stiffness options of [001] §5 (`stabilisation.stiffness`, issue «Seed [001]»):
//! the nodal diagnostic K_mag of [001]'s full block with each option (Part E item 3 through the
//! program), the first increment of the hollow cylinder with the double-mapped stiffness as one
//! linear solve (`-snes_type ksponly`, Part E item 7), and Newton with an approximate Jacobian
//! converging to the answer of the exact one.

mod common;
use common::*;
use std::path::PathBuf;

fn out_dir(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("porompm-stiffness-{name}-{}", std::process::id()))
}

/// K_mag of the interior nodes of `tests/cases/stiffness_block.toml` (7 × 7 nodes) with `sets`.
fn interior_k_mag(name: &str, sets: &[&str], ranks: usize) -> Vec<f64> {
    let dir = out_dir(name);
    let r = run_case_on(ranks, "tests/cases/stiffness_block.toml", &dir, &set_args(sets));
    assert!(r.completed(), "{name}: {}", r.stderr());
    let h = hdf5_metno::File::open(dir.join("fields.h5")).expect("fields.h5 opens");
    let k = h.dataset("grid/1/K_mag").unwrap().read_raw::<f64>().unwrap();
    (1..8).flat_map(|j| (1..8).map(move |i| j * 9 + i)).map(|n| k[n]).collect()
}

/// Part E item 3 through the program: on the full, unrotated block the mapped stiffnesses (GM, DM,
/// DM-G, with the linear basis and DM-G with GIMP) give the finite-element K_mag = (4/3)(D₁₁ + G)√2
/// (3263.57 kN/m for E = 1000 kN/m², ν = 0.3) at every interior node to 1e-10, and on two ranks
/// (DM-G with GIMP, whose domains it maps with);
/// W* keeps regular MPM's 3059.60 (all cells are full: omp = cmp).
#[test]
fn the_mapped_stiffnesses_give_the_finite_element_k_mag_of_a_full_block() {
    let (e, nu) = (1.0e6, 0.3);
    let f = e / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let fem = (4.0 / 3.0) * (f * (1.0 - nu) + e / (2.0 * (1.0 + nu))) * 2f64.sqrt();
    assert!((fem / 1e3 - 3263.57).abs() < 5e-3, "{fem}");
    for (name, option, basis, ranks, expected) in [
        ("gm", "gauss_mapping", "linear", 1, fem),
        ("dm", "double_mapping", "linear", 1, fem),
        ("dmg-gimp", "double_mapping_gimp", "gimp", 1, fem),
        ("dmg-gimp-2", "double_mapping_gimp", "gimp", 2, fem),
        ("wstar", "w_star", "linear", 1, fem * 15.0 / 16.0),
    ] {
        let sets = [format!("stabilisation.stiffness={option}"), format!("analysis.shape_functions={basis}")];
        let sets: Vec<&str> = sets.iter().map(|s| s.as_str()).collect();
        for (n, k) in interior_k_mag(name, &sets, ranks).iter().enumerate() {
            assert!(
                (k / expected - 1.0).abs() < 1e-10,
                "{name}: K_mag of interior node {n} = {k}, expected {expected}"
            );
        }
    }
}

/// Part E item 7: with the double-mapped stiffness each load step of [001] is one linear solve
/// (`-snes_type ksponly`); the hollow cylinder's first increment is then the independent 1D
/// computation's DM value, u_r(0.5) = 0.044374 m and Δσ_rr(0.55) = 68.140 kPa per 100 kPa (1e-4),
/// for GM (the same at t = 0: full cells) and DM-G (with GIMP's planar weights, whose domains lie
/// in one cell: the same at t = 0) too; the particle stiffness gives regular MPM's 0.044583 m.
#[test]
fn one_linear_solve_with_the_double_mapped_stiffness_is_the_papers_first_increment() {
    for (option, u_ref, s_ref) in [
        ("double_mapping", 0.044374, 68.140e3),
        ("gauss_mapping", 0.044374, 68.140e3),
        ("double_mapping_gimp", 0.044374, 68.140e3),
        ("particle", 0.044583, 68.605e3),
    ] {
        // DM-G maps with GIMP domains; GIMP with the planar weights in r is the linear basis for
        // domains inside one cell (Part B1: at t = 0 DM-G is DM).
        let basis = if option == "double_mapping_gimp" { "gimp" } else { "linear" };
        let sets = [
            "parameters.p=1".to_string(),
            format!("stabilisation.stiffness={option}"),
            format!("analysis.shape_functions={basis}"),
            "analysis.axisymmetric_weights=planar".to_string(),
        ];
        let mut args = set_args(&sets.iter().map(|s| s.as_str()).collect::<Vec<_>>());
        args.extend(["--".to_string(), "-snes_type".into(), "ksponly".into()]);
        let r = run_case("cases/hollow_cylinder.toml", &out_dir(&format!("ksponly-{option}")), &args);
        assert!(r.completed(), "{option}: {}", r.stderr());
        let u = r.summary["results"]["u_inner_per_100kPa"].as_f64().unwrap();
        let s = r.summary["results"]["sigma_rr_mp1_per_100kPa"].as_f64().unwrap();
        assert!((u / u_ref - 1.0).abs() < 1e-4, "{option}: u_r(0.5) = {u} m, expected {u_ref} m");
        assert!((s / s_ref - 1.0).abs() < 1e-4, "{option}: Δσ_rr(0.55) = {s} Pa, expected {s_ref} Pa");
    }
}

/// With Newton converged, the stiffness option changes the iterations, not the answer: the
/// hollow cylinder under [001]'s 100 kPa (geometrically nonlinear, GIMP) reaches the particle
/// stiffness's u_r(0.5) to 1e-6 with DM and DM-G, in more iterations; `test-jacobian` refuses an
/// approximate Jacobian with a message saying so.
#[test]
fn newton_with_a_mapped_stiffness_converges_to_the_exact_tangent_s_answer() {
    let run = |option: &str| {
        let sets = [
            "parameters.p=1e5".to_string(),
            format!("stabilisation.stiffness={option}"),
            "analysis.shape_functions=gimp".to_string(),
        ];
        let r = run_case(
            "cases/hollow_cylinder.toml",
            &out_dir(&format!("newton-{option}")),
            &set_args(&sets.iter().map(|s| s.as_str()).collect::<Vec<_>>()),
        );
        assert!(r.completed(), "{option}: {}", r.stderr());
        (r.summary["results"]["u_inner_per_100kPa"].as_f64().unwrap(), r.summary["snes_iterations"].as_u64().unwrap())
    };
    let (u0, n0) = run("particle");
    for option in ["double_mapping", "double_mapping_gimp"] {
        let (u, n) = run(option);
        assert!((u / u0 - 1.0).abs() < 1e-6, "{option}: u_r(0.5) = {u}, exact tangent {u0}");
        assert!(n > n0, "{option}: {n} Newton iterations, exact tangent {n0}");
    }
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_porompm"))
        .args(["test-jacobian", "cases/hollow_cylinder.toml", "--set", "stabilisation.stiffness=double_mapping"])
        .current_dir(root())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("test-jacobian checks the exact tangent"), "{err}");
}

/// Part E item 7, DM-C: the double-mapped stiffness with [001]'s CMPM strain recovery
/// (`stabilisation.stress_recovery = "cmpm"`, the corrected Eq. 23 next to the walls) gives the
/// 1D computation's Δσ_rr(0.55) = 79.272 kPa, Δσ_m = 14.71 kPa and Δq = 108.12 kPa per 100 kPa
/// for the first increment; with the exact tangent and Newton, CMPM lowers the volume-weighted RMS
/// error of Δσ_rr over the wall from 10 % to 3 % (measured 0.102 → 0.027), and the patch test
/// (cases/patch_test.toml) still holds to round-off.
#[test]
fn cmpm_recovery_gives_the_papers_dm_c_stresses_and_passes_the_patch_test() {
    let mut args =
        set_args(&["parameters.p=1", "stabilisation.stiffness=double_mapping", "stabilisation.stress_recovery=cmpm"]);
    args.extend(["--".to_string(), "-snes_type".into(), "ksponly".into()]);
    let r = run_case("cases/hollow_cylinder.toml", &out_dir("dm-c"), &args);
    assert!(r.completed(), "{}", r.stderr());
    let result = |k: &str| r.summary["results"][k].as_f64().unwrap() / 1e3;
    let (s, m, q) = (result("sigma_rr_mp1_per_100kPa"), result("sigma_m_mp1_per_100kPa"), result("q_mp1_per_100kPa"));
    assert!((s / 79.272 - 1.0).abs() < 1e-4, "DM-C Δσ_rr(0.55) = {s} kPa, expected 79.272");
    assert!((m - 14.71).abs() < 5e-3 && (q - 108.12).abs() < 5e-3, "DM-C Δσ_m = {m}, Δq = {q} kPa");
    let rms = |recovery: &str| {
        let sets = ["parameters.p=1".to_string(), format!("stabilisation.stress_recovery={recovery}")];
        let r = run_case(
            "cases/hollow_cylinder.toml",
            &out_dir(&format!("rms-{recovery}")),
            &set_args(&sets.iter().map(|s| s.as_str()).collect::<Vec<_>>()),
        );
        assert!(r.completed(), "{recovery}: {}", r.stderr());
        metric(&r.summary, "sigma_rr_rms_rel_error")
    };
    let (plain, cmpm) = (rms("basis"), rms("cmpm"));
    assert!(cmpm < 0.05 && plain > 0.08, "RMS error of Δσ_rr: basis {plain}, cmpm {cmpm}");
    let sets = ["stabilisation.stress_recovery=cmpm", "stabilisation.bbar=false"];
    let r = run_case("cases/patch_test.toml", &out_dir("patch-cmpm"), &set_args(&sets));
    assert!(r.completed(), "{}", r.stderr());
    assert!(metric(&r.summary, "stress_spread") < 1e-12, "{}", r.summary["verification"]);
}

/// Part E item 4 through the program (cases/rotated_stiffness.toml, [001] §6): on the lattice
/// turned by 20°, DM-G's K_mag is within 1 % of the finite-element value at every node within 7 m
/// of the centre, GIMP's particle integration is below it at every node, and the RMS deviations
/// keep [001]'s order DM-G < DM < GM < MPM < W* (measured 0.17, 2.5, 4.0, 4.7, 7.4 %), each at
/// least 5 % below the next; unrotated, DM gives the finite-element value to 1e-10.
#[test]
fn the_rotated_lattice_keeps_the_papers_order_of_stiffness_errors() {
    let run = |name: &str, sets: &[&str]| {
        let r = run_case("cases/rotated_stiffness.toml", &out_dir(&format!("rotated-{name}")), &set_args(sets));
        assert!(r.completed(), "{name}: {}", r.stderr());
        (
            metric(&r.summary, "k_mag_max_rel_deviation"),
            metric(&r.summary, "k_mag_rms_rel_deviation"),
            r.summary["results"]["k_mag_max_ratio"].as_f64().unwrap(),
        )
    };
    let (dmg_max, dmg_rms, _) = run("dmg", &[]);
    assert!(dmg_max < 0.01, "DM-G: largest deviation {dmg_max}");
    let (_, _, gimp_max_ratio) = run("gimp", &["stabilisation.stiffness=particle"]);
    assert!(gimp_max_ratio < 1.0, "GIMP above the finite-element K_mag: ratio {gimp_max_ratio}");
    let mut order = vec![("DM-G", dmg_rms)];
    for (name, option) in [("DM", "double_mapping"), ("GM", "gauss_mapping"), ("MPM", "particle"), ("W*", "w_star")] {
        let option = format!("stabilisation.stiffness={option}");
        order.push((name, run(name, &[&option, "analysis.shape_functions=linear"]).1));
    }
    assert!(order.windows(2).all(|w| w[0].1 < 0.95 * w[1].1), "RMS order broken: {order:?}");
    let (dm0, _, _) = run("dm-unrotated", &["parameters.angle=0", "stabilisation.stiffness=double_mapping"]);
    assert!(dm0 < 1e-10, "DM on the unrotated lattice: largest deviation {dm0}");
}

/// Part E items 10 and 12 (cases/vertical_cut.toml, [001] §7.2) with regular MPM: the cut fails
/// and runs to 1.0 m of toe displacement, every point stays on or inside its softened yield
/// surface at every step (q ≤ √3 c(ε̄)(1 + 1e-8)), the residual strength is reached somewhere
/// (ε̄ > 0.30), the smoothness of K_mag and F^int_mag is measured at 0.1 and 1.0 m (DM-GC
/// against MPM, item 11: the next test), and every converged step keeps the equilibrium identity
/// to 1e-6 with the case's Newton tolerance (measured 5.1e-8; 6.3e-2 before the held nodes beyond
/// the base took their share: tests/equilibrium.rs).
#[test]
#[ignore = "make study: the cut run to 1 m; the default suite runs it to 0.1 m against its gold values, yield excess and equilibrium among them, on one and two ranks"]
fn the_vertical_cut_runs_to_a_metre_of_toe_displacement() {
    let r = run_case("cases/vertical_cut.toml", &out_dir("cut"), &[]);
    assert!(r.completed(), "{}", r.stderr());
    let result = |k: &str| r.summary["results"][k].as_f64().unwrap_or(f64::NAN);
    assert!(result("toe_displacement") >= 1.0, "toe {}", result("toe_displacement"));
    assert_eq!(r.summary["verification"]["yield_excess"]["pass"], true, "{}", r.summary["verification"]);
    assert!(result("eps_pd_max") > 0.30, "ε̄ max {}", result("eps_pd_max"));
    let eq = r.summary["equilibrium_error"].as_f64().unwrap();
    assert!(eq <= 1e-6, "equilibrium error {eq:e}");
    for s in ["0.1", "1"] {
        for f in ["k_mag", "fint_mag"] {
            let v = result(&format!("{f}_roughness_at_{s}"));
            assert!(v.is_finite() && v > 0.0, "{f} roughness at {s} m: {v}");
        }
    }
}

/// Part E item 11 with [001]'s one linear solve per step (`-snes_type ksponly`) to 0.1 m of toe
/// displacement: DM-GC's K_mag is smooth where regular MPM's is mottled (roughness at most 1/5 of
/// MPM's, over the nodes whose stencil has whole supports in the material) and its σ_m has the
/// smaller chequerboard index; the σ_m maps of both are written (`plots/`). Not reached, measured
/// and reported in docs/stress_maps.md: F^int_mag's roughness (the forces are integrated at the
/// points with the basis in both) and σ_m's total variation at B and C.
#[test]
#[ignore = "make study: [001]'s comparison of DM-GC with MPM on the cut; DM-GC stays in the default suite through the cylinder's increments and the full block's K_mag"]
fn dm_gc_smooths_k_mag_and_sigma_m_on_the_vertical_cut() {
    let short = ["--set", "verification.stop_displacement=0.1", "--set", "verification.snapshots=[0.1]"];
    let run = |name: &str, sets: &[&str]| {
        let mut args: Vec<String> = short.iter().map(|s| s.to_string()).collect();
        args.extend(set_args(sets));
        args.extend(["--", "-snes_type", "ksponly"].map(String::from));
        let r = run_case("cases/vertical_cut.toml", &out_dir(name), &args);
        assert!(r.completed(), "{name}: {}", r.stderr());
        assert!(out_dir(name).join("plots/sigma_m_toe_0.1m.png").is_file(), "{name}: no σ_m map");
        let result = |k: &str| r.summary["results"][k].as_f64().unwrap_or(f64::NAN);
        (result("k_mag_roughness_at_0.1"), result("sigma_m_checkerboard_at_0.1"), result("fint_mag_roughness_at_0.1"))
    };
    let mpm = run("cut-mpm-one-solve", &[]);
    let dmgc = run(
        "cut-dmgc-one-solve",
        &["stabilisation.stiffness=double_mapping_gimp", "stabilisation.stress_recovery=cmpm"],
    );
    let pair = run("cut-dmg-mapped-one-solve", &MAPPED_PAIR);
    for (name, v) in [("DM-GC", dmgc), ("DM-G with the mapped pair", pair)] {
        println!(
            "K_mag roughness {:.4} vs {:.4}, σ_m chequerboard {:.4} vs {:.4}, F^int_mag roughness {:.4} vs {:.4} (MPM vs {name})",
            mpm.0, v.0, mpm.1, v.1, mpm.2, v.2
        );
        assert!(v.0 <= 0.2 * mpm.0, "K_mag roughness: {name} {} against MPM {}", v.0, mpm.0);
        assert!(v.1 < mpm.1, "σ_m chequerboard index: {name} {} against MPM {}", v.1, mpm.1);
    }
}

/// DM-G with the double-mapped internal force and the strain recovered by its transpose
/// (`stabilisation.internal_force = "mapped"`, `stabilisation.stress_recovery = "mapped"`).
const MAPPED_PAIR: [&str; 3] = [
    "stabilisation.stiffness=double_mapping_gimp",
    "stabilisation.internal_force=mapped",
    "stabilisation.stress_recovery=mapped",
];

/// The double-mapped pair with Newton on its exact tangent (`mapped_stiffness = "diagnostics"`)
/// to 0.1 m of toe displacement on cells of 0.25 m: the same answers on one and two ranks, and a
/// Galerkin pair on cell-clipped operators keeps the equilibrium identity (∫σ dV against the
/// moment of the loads, reactions and inertia forces) to 1e-3 (measured 1.6e-4: the mapped
/// operators of the points whose domains reach past the base have no cells beyond the grid, so
/// their share there is lost; regular MPM's basis keeps it, tests/equilibrium.rs).
#[test]
fn the_mapped_pair_gives_the_same_cut_on_two_ranks_and_keeps_its_balance() {
    let mut sets = MAPPED_PAIR.to_vec();
    sets.extend([
        "parameters.h=0.25",
        "stabilisation.mapped_stiffness=diagnostics",
        "verification.stop_displacement=0.1",
        "verification.snapshots=[0.1]",
    ]);
    let run = |ranks: usize| {
        let name = format!("cut-mapped-pair-{ranks}");
        let r = run_case_on(ranks, "cases/vertical_cut.toml", &out_dir(&name), &set_args(&sets));
        assert!(r.completed(), "{name}: {}", r.stderr());
        r
    };
    let (one, two) = (run(1), run(2));
    let results = |r: &Run| r.summary["results"].as_object().expect("results").clone();
    let (a, b) = (results(&one), results(&two));
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    for (k, v) in &a {
        let (x, y) = (v.as_f64().unwrap(), b[k].as_f64().unwrap());
        assert!((x - y).abs() <= 1e-9 * x.abs().max(1e-12), "{k}: {x} on one rank, {y} on two");
    }
    assert!(a["toe_displacement"].as_f64().unwrap() >= 0.1, "{a:?}");
    for r in [&one, &two] {
        let e = r.summary["equilibrium_error"].as_f64().unwrap();
        assert!(e < 1e-3, "equilibrium error {e}");
    }
}

/// The double-mapped internal force and strain are refused where they do not apply, naming the
/// key: without a mapped stiffness (whose weights they take), the mapped strain without the mapped
/// force, and in a two-phase case.
#[test]
fn the_mapped_force_and_strain_are_refused_where_they_do_not_apply() {
    for (i, (case, sets, message)) in [
        ("cases/vertical_cut.toml", &["stabilisation.internal_force=mapped"][..], "key `stabilisation.internal_force`"),
        (
            "cases/vertical_cut.toml",
            &["stabilisation.stiffness=double_mapping_gimp", "stabilisation.stress_recovery=mapped"][..],
            "set `stabilisation.internal_force = \"mapped\"` too",
        ),
        (
            "cases/terzaghi.toml",
            &["stabilisation.stiffness=gauss_mapping", "stabilisation.internal_force=mapped"][..],
            "`mapped` is for one_phase analyses",
        ),
    ]
    .into_iter()
    .enumerate()
    {
        assert_refused(case, &out_dir(&format!("mapped-bad-{i}")), sets, message);
    }
}

/// `stabilisation.mapped_stiffness = "diagnostics"`: the mapped stiffness gives the nodal K_mag
/// (the rotated block's deviations are DM-G's, not the points' own) while Newton keeps the exact
/// tangent (the cylinder at 100 kPa converges in the exact tangent's iterations to its answer,
/// fewer than with DM-G as the Jacobian).
#[test]
fn a_mapped_stiffness_can_serve_the_diagnostics_only() {
    let rotated = |name: &str, sets: &[&str]| {
        let r = run_case("cases/rotated_stiffness.toml", &out_dir(name), &set_args(sets));
        assert!(r.completed(), "{name}: {}", r.stderr());
        metric(&r.summary, "k_mag_max_rel_deviation")
    };
    let jac = rotated("diag-rot-jacobian", &[]);
    let diag = rotated("diag-rot-diagnostics", &["stabilisation.mapped_stiffness=diagnostics"]);
    let own = rotated("diag-rot-particle", &["stabilisation.stiffness=particle"]);
    assert!(
        jac == diag && diag < 0.01 && own > 0.3,
        "K_mag deviation {jac} (Jacobian), {diag} (diagnostics), {own} (points)"
    );
    let cylinder = |name: &str, sets: &[&str]| {
        let mut all =
            vec!["parameters.p=1e5", "analysis.shape_functions=gimp", "stabilisation.stiffness=double_mapping_gimp"];
        all.extend(sets);
        let r = run_case("cases/hollow_cylinder.toml", &out_dir(name), &set_args(&all));
        assert!(r.completed(), "{name}: {}", r.stderr());
        (r.summary["snes_iterations"].as_u64().unwrap(), r.summary["results"]["u_inner_per_100kPa"].as_f64().unwrap())
    };
    let (n_jac, u_jac) = cylinder("diag-cyl-jacobian", &[]);
    let (n_diag, u_diag) = cylinder("diag-cyl-diagnostics", &["stabilisation.mapped_stiffness=diagnostics"]);
    let (n_exact, u_exact) = cylinder("diag-cyl-exact", &["stabilisation.stiffness=particle"]);
    assert_eq!(n_diag, n_exact, "Newton iterations with the diagnostics-only option");
    assert!(n_jac > n_exact, "DM-G as the Jacobian: {n_jac} iterations against {n_exact}");
    assert_eq!(u_diag, u_exact);
    assert!((u_jac - u_exact).abs() < 1e-6 * u_exact, "{u_jac} vs {u_exact}");
    assert_refused(
        "cases/hollow_cylinder.toml",
        &out_dir("diag-bad"),
        &["stabilisation.mapped_stiffness=diagnostics"],
        "`diagnostics` computes K_mag with a mapped",
    );
}
