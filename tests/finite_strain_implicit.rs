//! The finite-strain solids (neo-Hookean, Hencky–J2) in the implicit stages: a homogeneous
//! stretch in one static step carries the closed-form stress to round-off with Newton converging
//! quadratically, the assembled tangents match central differences of the residual block by block
//! (`porompm test-jacobian`), and the neo-Hookean solid meets the hypoelastic one where strains are
//! small. Each run is the real binary in its own process.

mod common;

use common::{assert_tangent_checked, metric, run_case, set_args};
use std::path::PathBuf;

fn out_dir(label: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("finite_strain_implicit").join(label)
}

/// The equilibrium patch test of a neo-Hookean block in one static step of 10 % stretch and shear
/// (F = exp(L), L = [[0.1, 0.03], [0.03, −0.05]]; in three dimensions a general L with spin): only
/// the block's surface is prescribed, its interior is free, so Newton solves for it. Every point
/// carries the neo-Hookean stress of F to round-off (measured 6e-16 to 9e-16 in the plane,
/// ν = 0.3 and 0.4999, with B̄ and without), and Newton converges quadratically (4 iterations to
/// 1e-12 at ν = 0.3: 6e5, 1e4, 1e1, 1e-5, 5e-10).
#[test]
fn a_neo_hookean_block_stretched_in_one_static_step_carries_its_stress_to_round_off() {
    let plane_flow = "boundaries[0]={name=\"flow\",surface={body=\"block\",faces=[\"x_min\",\"x_max\",\"y_min\",\"y_max\"]},fix=[\"ux\",\"uy\"],velocity_gradient=[[0.1,0.03],[0.03,-0.05]],center=[4.0,4.0]}";
    let solid_flow = "boundaries[0]={name=\"flow\",surface={body=\"block\",faces=[\"x_min\",\"x_max\",\"y_min\",\"y_max\",\"z_min\",\"z_max\"]},fix=[\"ux\",\"uy\",\"uz\"],velocity_gradient=[[0.1,0.05,-0.02],[0.01,-0.05,0.03],[-0.04,0.01,0.04]],center=[4.0,4.0,4.0]}";
    let runs = [
        ("cases/patch_test.toml", plane_flow, "0.3", "true", 6),
        ("cases/patch_test.toml", plane_flow, "0.3", "false", 6),
        ("cases/patch_test.toml", plane_flow, "0.4999", "true", 12),
        ("cases/patch_test.toml", plane_flow, "0.4999", "false", 8),
        ("cases/patch_test_3d.toml", solid_flow, "0.3", "true", 6),
    ];
    for (case, flow, nu, bbar, most) in runs {
        let label = format!("{}-{nu}-{bbar}", if case.contains("3d") { "3d" } else { "plane" });
        let model = format!("materials.solid.model={{type=\"neo_hookean\",young_modulus=1.0e6,poisson_ratio={nu}}}");
        let bbar = format!("stabilisation.bbar={bbar}");
        let mut args = set_args(&[flow, &model, &bbar, "stages.0.analysis=static", "time.dt=1.0"]);
        args.extend(["--", "-snes_rtol", "1e-12", "-snes_atol", "1e-30"].map(String::from));
        let r = run_case(case, &out_dir(&label), &args);
        assert!(r.completed(), "{label}: {}", r.stderr());
        let (spread, err) = (metric(&r.summary, "stress_spread"), metric(&r.summary, "stress_rel_error"));
        let newton = r.summary["snes_iterations"].as_u64().unwrap();
        eprintln!("{label}: spread {spread:.1e}, error {err:.1e}, {newton} Newton iterations");
        assert!(r.summary["dofs"].as_u64().unwrap() > 0, "{label}: the interior must be free");
        assert!(spread <= 1e-12 && err <= 1e-12, "{label}: spread {spread:e}, error {err:e}");
        assert!(newton <= most, "{label}: {newton} Newton iterations");
    }
}

/// The assembled tangents of the finite-strain solids against central differences of the
/// assembled residual, block by block, each within 1e-6: Cook's neo-Hookean membrane
/// (ν = 0.45, B̄) in a static stage after three steps (at ν = 0.499 the differences' round-off
/// reaches 1.4e-6 of the scaled blocks: the kernels' own check shows the tangent exact there, its
/// differences falling from 6e-8 to 5e-11 as their step grows from 1e-9 to 1e-6), the same on a perturbed arrangement in
/// three dimensions (the patch block with its interior free), and [002]'s Hencky–J2 footing
/// (B̄, h = B/10) after eight static steps, when 822 of its points have yielded. A flipped
/// block is caught in each.
#[test]
fn the_finite_strain_tangents_match_finite_differences_block_by_block() {
    let cook = [
        "cases/cook_membrane.toml",
        "--set",
        "parameters.h=4.0",
        "--set",
        "stages.0={name=\"load\",duration=60.0,analysis=\"static\"}",
        "--set",
        "stabilisation={bbar=true}",
        "--set",
        "time.dt=4.0",
        "--set",
        "materials.rubber.model.poisson_ratio=0.45",
    ];
    assert_tangent_checked(&[&cook[..], &["--steps", "3"]].concat(), 4, "uy,ux");

    let block = [
        "cases/patch_test_3d.toml",
        "--set",
        "boundaries[0]={name=\"flow\",surface={body=\"block\",faces=[\"x_min\",\"y_min\",\"z_min\"]},fix=[\"ux\",\"uy\",\"uz\"],velocity_gradient=[[0.1,0.05,-0.02],[0.01,-0.05,0.03],[-0.04,0.01,0.04]],center=[4.0,4.0,4.0]}",
        "--set",
        "materials.solid.model={type=\"neo_hookean\",young_modulus=1.0e6,poisson_ratio=0.3}",
        "--set",
        "materials.solid.solid_density=1000.0",
        "--set",
        "bodies.block.perturbation=0.3",
        "--set",
        "stages.0.analysis=static",
        "--set",
        "grid.cells=[4,4,4]",
        "--steps",
        "2",
    ];
    assert_tangent_checked(&block, 9, "uz,ux");

    let footing = [
        "cases/footing_fbar.toml",
        "--set",
        "parameters.h=0.1",
        "--set",
        "stages.0={name=\"push\",duration=3.0,analysis=\"static\"}",
        "--set",
        "stabilisation={bbar=true}",
        "--set",
        "time.dt=0.05",
        "--steps",
        "8",
    ];
    let text = assert_tangent_checked(&footing, 4, "ux,uy");
    let yielded = common::yielded_points(&text);
    assert!(yielded > 100, "the plastic tangent takes part: {text}");
}

/// Where strains are small the neo-Hookean solid is the linear elastic one of the same moduli:
/// Cook's membrane at ν = 0.3 on 2 m cells without B̄, loaded in a static stage (tip strains of
/// about 1 %, a finite rotation), gives a tip deflection within 0.1 % of the hypoelastic linear
/// material's (the tip probe's u_y; the fitted tip on 1 m cells: 0.32489 m against 0.32494 m).
#[test]
fn the_neo_hookean_membrane_meets_the_linear_elastic_one_at_small_strains() {
    let tip = |model: &str| {
        let m = format!("materials.rubber.model={{type=\"{model}\",young_modulus=70.0,poisson_ratio=0.3}}");
        let sets = [
            "parameters.h=2.0",
            "stages.0={name=\"load\",duration=60.0,analysis=\"static\"}",
            "stabilisation={}",
            "time.dt=4.0",
            m.as_str(),
        ];
        let r = run_case("cases/cook_membrane.toml", &out_dir(&format!("cook-{model}")), &set_args(&sets));
        assert!(r.completed(), "{model}: {}", r.stderr());
        *r.column("tip.uy").last().unwrap()
    };
    let (neo, linear) = (tip("neo_hookean"), tip("linear_elastic"));
    eprintln!("Cook's membrane at ν = 0.3, 2 m cells: tip u_y {neo:.5} m neo-Hookean, {linear:.5} m linear elastic");
    assert!((neo / linear - 1.0).abs() <= 1e-3, "neo-Hookean {neo} against linear elastic {linear}");
}

/// A dynamic implicit stage: the vibrating bar of `cases/vibrating_bar.toml` (average-acceleration
/// Newmark, started by its first mode's velocity) made of a neo-Hookean solid of the same E and
/// ν = 0, whose small-strain limit it is (strains of 4e-4): the period and the amplitude over three
/// periods within 0.5 % of the closed form, and within 1e-3 of the linear elastic bar's errors.
#[test]
fn a_neo_hookean_bar_vibrates_with_the_closed_form_period_in_a_dynamic_implicit_stage() {
    let errors = |model: &str| {
        let m = format!("materials.soil.model={{type=\"{model}\",young_modulus=1.0e8,poisson_ratio=0.0}}");
        let r = run_case("cases/vibrating_bar.toml", &out_dir(&format!("bar-{model}")), &set_args(&[&m]));
        assert!(r.completed(), "{model}: {}", r.stderr());
        (metric(&r.summary, "period_rel_error"), metric(&r.summary, "amplitude_rel_error"))
    };
    let (neo, linear) = (errors("neo_hookean"), errors("linear_elastic"));
    eprintln!(
        "vibrating bar: neo-Hookean period {:.2e}, amplitude {:.2e}; linear {:.2e}, {:.2e}",
        neo.0, neo.1, linear.0, linear.1
    );
    assert!(neo.0 <= 5e-3 && neo.1 <= 5e-3, "neo-Hookean: {neo:?}");
    assert!((neo.0 - linear.0).abs() <= 1e-3 && (neo.1 - linear.1).abs() <= 1e-3, "{neo:?} against {linear:?}");
}
