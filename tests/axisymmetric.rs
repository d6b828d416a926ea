//! Axisymmetric analyses (`analysis.geometry = "axisymmetric"`, issue «Seed [001]»): the hollow
//! cylinder of [001] §3.1 against the independent 1D computation of `../shared/seeds-001-002.md`
//! Part B1 and against Lamé's solution under h-refinement, the nearly incompressible cylinder with
//! and without B̄, the axisymmetric oedometer against Terzaghi in the u–p and u–p–U systems, and the
//! same answers on two ranks.

mod common;
use common::*;
use std::path::PathBuf;

const CYLINDER: &str = "cases/hollow_cylinder.toml";

fn out_dir(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("porompm-axisymmetric-{name}-{}", std::process::id()))
}

/// The first increment of the hollow cylinder under a small pressure p (its linear response),
/// scaled to 100 kPa: (u_r at r_i extrapolated linearly from the two innermost points, Δσ_rr at
/// the innermost point [Pa], compression positive, the run's equilibrium error).
fn first_increment(name: &str, sets: &[&str], ranks: usize) -> (f64, f64, f64) {
    let p = 1.0;
    let mut all = vec![format!("parameters.p={p}")];
    all.extend(sets.iter().map(|s| s.to_string()));
    let all: Vec<&str> = all.iter().map(|s| s.as_str()).collect();
    let r = run_case_on(ranks, CYLINDER, &out_dir(name), &set_args(&all));
    assert!(r.completed(), "{name}: {}", r.stderr());
    let last = |c: &str| *r.column(c).last().unwrap();
    let (x1, x2) = (last("mp1.x"), last("mp2.x"));
    let (u1, u2) = (last("mp1.ux"), last("mp2.ux"));
    let scale = 1.0e5 / p;
    let u_inner = (u1 + (u2 - u1) * (0.5 - x1) / (x2 - x1)) * scale;
    (u_inner, -last("mp1.sxx") * scale, r.summary["equilibrium_error"].as_f64().unwrap())
}

/// The shear modulus of the cylinders, E/(2(1 + ν)) with E = 1 MPa and ν = 0.3 [Pa].
const SHEAR: f64 = 1.0e6 / 2.6;

/// Lamé's cylinder with a fixed outer wall (plane strain along the axis) of shear modulus `mu` and
/// Poisson's ratio `nu`: u_r(a) for p = 100 kPa and Δσ_rr(r), from A = p/(1/a² + κ/b²),
/// C = κA/(2b²), κ = 1/(1 − 2ν) (Part B1).
fn lame(mu: f64, nu: f64) -> (f64, impl Fn(f64) -> f64) {
    let (p, a, b) = (1.0e5, 0.5, 1.5);
    let kappa = 1.0 / (1.0 - 2.0 * nu);
    let big_a = p / (1.0 / (a * a) + kappa / (b * b));
    let c = kappa * big_a / (2.0 * b * b);
    (big_a / (2.0 * mu) * (1.0 / a - a / (b * b)), move |r: f64| big_a / (r * r) + 2.0 * c)
}

/// Part E item 7: regular MPM (linear basis, particle integration, 2 × 2 points per cell, h = 0.2 m)
/// gives u_r(0.5) = 0.044583 m and Δσ_rr(0.55) = 68.605 kPa per 100 kPa in the independent 1D
/// computation of Part B1; the equilibrium identity (moments about the axis, with the hoop stress)
/// holds to round-off.
#[test]
fn the_hollow_cylinder_s_first_increment_is_the_independent_1d_computation() {
    let (u, s, eq) = first_increment("mpm", &[], 1);
    assert!((u / 0.044583 - 1.0).abs() < 1e-4, "u_r(0.5) = {u} m, expected 0.044583 m");
    assert!((s / 68.605e3 - 1.0).abs() < 1e-4, "Δσ_rr(0.55) = {s} Pa, expected 68.605 kPa");
    assert!(eq < 1e-12, "equilibrium error {eq:e}");
}

/// Part E item 8: under h-refinement (h = 0.2, 0.1, 0.05 m, one element row) u_r(0.5) converges to
/// Lamé's 0.045217 m at second order, within 0.2 % at h = 0.05 m (measured: −1.40, −0.37, −0.094 %).
#[test]
fn the_hollow_cylinder_converges_to_lame_at_second_order() {
    let (exact, _) = lame(SHEAR, 0.3);
    let errors: Vec<f64> = [0.2, 0.1, 0.05]
        .iter()
        .map(|h| {
            let (u, _, _) = first_increment(&format!("h{h}"), &[&format!("parameters.h={h}")], 1);
            (u / exact - 1.0).abs()
        })
        .collect();
    for w in errors.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!(order > 1.8, "order {order:.2} from errors {errors:?}");
    }
    assert!(errors[2] < 2e-3, "error at h = 0.05 m: {:.3} %", 100.0 * errors[2]);
}

/// Near ν = 0.5 the hoop strain must enter B̄'s volumetric average: with B̄ the radial stress next
/// to the inner wall is Lamé's within 1 %, without it the elements lock and it is off by more than
/// half (measured at ν = 0.4999: 99.955 kPa with B̄, 38.3 kPa without, Lamé 99.97 kPa).
#[test]
fn the_nearly_incompressible_cylinder_needs_the_hoop_strain_in_bbar() {
    let nu = 0.4999;
    let (u_exact, srr) = lame(1.0e6 / (2.0 * (1.0 + nu)), nu);
    let exact = srr(0.55);
    let material = format!("materials.0.model.poisson_ratio={nu}");
    for (name, sets) in [
        ("bbar-linear", vec![material.as_str(), "stabilisation.bbar=true"]),
        ("bbar-gimp", vec![material.as_str(), "stabilisation.bbar=true", "analysis.shape_functions=gimp"]),
    ] {
        let (u, s, _) = first_increment(name, &sets, 1);
        assert!((s / exact - 1.0).abs() < 1e-2, "{name}: Δσ_rr(0.55) = {s} Pa, Lamé {exact} Pa");
        assert!((u / u_exact - 1.0).abs() < 3e-2, "{name}: u_r(0.5) = {u} m, Lamé {u_exact} m");
    }
    let (_, s, _) = first_increment("locked", &[material.as_str()], 1);
    assert!((s / exact - 1.0).abs() > 0.5, "without B̄: Δσ_rr(0.55) = {s} Pa should lock (Lamé {exact} Pa)");
}

/// Undrained (a static undrained stage of the u–p system), the saturated cylinder responds as an
/// elastic one with the undrained bulk modulus K_u = K + K_w/n (ν_u = 0.45 here): the hoop strain
/// must enter the continuity equation and the pore pressure must push radially through the hoop
/// term. u_r(0.5) is Lamé's with ν_u within 0.3 % at h = 0.05 m (measured 0.07 %) in the u–p
/// system (a static undrained stage); without the hoop term in the continuity equation it is 26 %
/// too small.
#[test]
fn the_undrained_cylinder_responds_with_the_undrained_poisson_ratio() {
    let (exact, _) = lame(SHEAR, 0.45);
    let r = run_case(
        "tests/cases/hollow_cylinder_undrained.toml",
        &out_dir("undrained"),
        &set_args(&["parameters.p=1", "parameters.h=0.05"]),
    );
    assert!(r.completed(), "{}", r.stderr());
    let last = |c: &str| *r.column(c).last().unwrap();
    let (x1, x2, u1, u2) = (last("mp1.x"), last("mp2.x"), last("mp1.ux"), last("mp2.ux"));
    let u = (u1 + (u2 - u1) * (0.5 - x1) / (x2 - x1)) * 1.0e5;
    assert!((u / exact - 1.0).abs() < 3e-3, "u_r(0.5) = {u} m, Lamé with ν_u: {exact} m");
    assert!(last("mp1.p") > 0.3, "the pore pressure carries part of the load: p = {}", last("mp1.p"));
}

/// A one-dimensional column is the same problem in axial symmetry (an oedometer: the load covers
/// the whole circular sample, u_r = 0 on both walls): Terzaghi's consolidation in the quasi-static
/// u–p and the dynamic u–p–U systems, with the column on the axis (GIMP weighted in r, the axis's
/// own u_r = 0) and two cells wide (one free node column), and away from it at r ∈ [1, 1.2] m with
/// the planar weights.
#[test]
fn the_axisymmetric_oedometer_consolidates_as_terzaghi() {
    let wide = [
        "grid.size=[0.2,1.0]",
        "grid.cells=[2,10]",
        "bodies.0.shape.rectangle.max=[0.2,1.0]",
        "loads.0.region.max=[0.2,1.0]",
        "analysis.geometry=axisymmetric",
    ];
    let far = [
        "grid.origin=[1.0,0.0]",
        "grid.size=[0.2,1.0]",
        "grid.cells=[2,10]",
        "bodies.0.shape.rectangle.min=[1.0,0.0]",
        "bodies.0.shape.rectangle.max=[1.2,1.0]",
        "loads.0.region.min=[1.0,0.5]",
        "loads.0.region.max=[1.2,1.0]",
        "probes.0.point=[1.025,0.025]",
        "probes.1.point=[1.025,0.525]",
        "analysis.geometry=axisymmetric",
        "analysis.axisymmetric_weights=planar",
    ];
    for (name, geometry) in [("axis", &wide[..]), ("far", &far[..])] {
        for analysis in ["dynamic", "quasi_static"] {
            let stage = format!("stages.0.analysis={analysis}");
            let mut sets: Vec<&str> = geometry.to_vec();
            sets.push(&stage);
            let tag = format!("oedometer-{name}-{analysis}");
            let r = run_case("cases/terzaghi.toml", &out_dir(&tag), &set_args(&sets));
            assert!(r.completed(), "{tag}: {}", r.stderr());
            assert_eq!(r.summary["verification_passed"], true, "{tag}: {}", r.summary["verification"]);
            let settlement = metric(&r.summary, "settlement_rel_error_Tv0.5");
            let ep = metric(&r.summary, "e_p_Tv0.5");
            assert!(settlement < 1e-3 && ep < 2e-4, "{tag}: settlement error {settlement:e}, e_p {ep:e}");
            let eq = r.summary["equilibrium_error"].as_f64().unwrap();
            assert!(eq < 1e-6, "{tag}: equilibrium error {eq:e}");
        }
    }
}

/// The same answers on one and two ranks (a 40-cell cylinder split along r).
#[test]
fn the_hollow_cylinder_gives_the_same_answers_on_two_ranks() {
    let sets = ["parameters.h=0.025", "analysis.shape_functions=gimp", "stabilisation.bbar=true"];
    let one = first_increment("ranks-1", &sets, 1);
    let two = first_increment("ranks-2", &sets, 2);
    assert!((one.0 - two.0).abs() <= 1e-10 * one.0.abs(), "u_r(0.5): {} vs {}", one.0, two.0);
    assert!((one.1 - two.1).abs() <= 1e-8 * one.1.abs(), "Δσ_rr: {} vs {}", one.1, two.1);
}

/// Bad axisymmetric input stops before the run with a message naming the key: a grid reaching
/// r < 0, a boundary taking the axis's name, the plane-strain Lamé cylinder on an axisymmetric case, the
/// hollow cylinder's reference on a plane-strain one, and [001]'s CMPM recovery with B̄ or in a
/// two-phase case.
#[test]
fn bad_axisymmetric_input_is_refused_with_a_clear_message() {
    let cases: [(&str, &[&str], &str); 6] = [
        (CYLINDER, &["grid.origin=[-0.1,0.0]"], "grid must start at x ≥ 0"),
        (CYLINDER, &["boundaries.0.name=axis"], "the name `axis` is taken"),
        (CYLINDER, &["analysis.geometry=plane_strain"], "needs `analysis.geometry = \"axisymmetric\"`"),
        (
            "cases/lame_cylinder.toml",
            &["analysis.geometry=axisymmetric"],
            "a cylinder in axial symmetry is the `hollow_cylinder` check's",
        ),
        (CYLINDER, &["stabilisation.stress_recovery=cmpm", "stabilisation.bbar=true"], "exclude each other"),
        ("cases/terzaghi.toml", &["stabilisation.stress_recovery=cmpm"], "`cmpm` is for one_phase analyses"),
    ];
    for (i, (case, sets, message)) in cases.iter().enumerate() {
        assert_refused(case, &out_dir(&format!("bad-{i}")), sets, message);
    }
}
