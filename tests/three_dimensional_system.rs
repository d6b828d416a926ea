//! The global system in three dimensions (issue «Three dimensions»), without the driver: steps of
//! a three-dimensional model prepared, solved by PETSc and taken back to its points through
//! `porompm::assembly::SolidSystem`, the same code as the plane `System`.
//!
//! * `a_slab_steps_as_its_plane_twin`: a slab one cell thick held between two smooth walls
//!   (u_z = 0 on both z faces) is a plane-strain body: a consolidating, yielding soil (the u–p
//!   system with Darcy flow, Mohr–Coulomb, B̄) compressed by a strip at its top steps exactly as
//!   the plane model of its section, point for point (positions, stresses, pore pressures,
//!   plastic strain), and its out-of-plane stresses are zero shears and the plane σ_zz.
//! * `a_slab_pressed_by_a_nodal_traction_steps_as_its_plane_twin`: so does the slab pressed by a
//!   nodal traction on its top face, the section by one on its top line.
//! * `a_slab_with_the_pressure_projection_steps_as_its_plane_twin`: so does the slab with the
//!   pressure projection, its cells' blocks over eight trilinear functions.
//! * `a_slab_with_moving_surfaces_steps_as_its_plane_twin`: so does the slab drained and pressed
//!   through moving surfaces on its top faces (Nitsche's drained faces in three dimensions).
//! * `a_two_phase_explicit_slab_steps_as_its_plane_twin`: the slab (standing, and lying in the
//!   (x, z) plane) in a two-phase explicit stage, with the points' own pore pressure and with the
//!   nodal one drained at the top, steps as its plane section point for point.
//! * `a_block_squeezed_from_three_sides_is_homogeneous`: an elastic block on three rollers
//!   pressed by a displaced face moves homogeneously, its stresses those of Hooke's law for the
//!   imposed strain, to round-off, in every point; and the reactions balance.
//!
//! Run: `cargo test --release --test three_dimensional_system` (harness-free: PETSc is
//! initialised once for all tests).

mod common;

use porompm::algebra::det;
use porompm::analysis::StageAnalysis;
use porompm::assembly::{StepDim, StepForces, System};
use porompm::case::Case;
use porompm::kernels::{MAX_NODES, MAX_NODES_3D};
use porompm::layout::Dim;
use porompm::layout::{MAX_DOF, MAX_DOF_3D};
use porompm::model::Model;
use porompm::parallel::Collective;
use porompm::validation::load as parse;

/// The plane section: a 0.2 m × 0.6 m column of Mohr–Coulomb soil on a fixed base between
/// smooth walls, drained at its top, pressed down by 3 mm over its left half (a strip footing
/// on the region x ∈ [0, 0.1]).
const PLANE: &str = r#"
[analysis]
formulation = "two_phase"
[stabilisation]
bbar = true
[grid]
size = [0.2, 0.8]
cells = [2, 8]
[[materials]]
name = "soil"
porosity = 0.4
solid_density = 2650.0
water_bulk_modulus = 2.2e9
solid_bulk_modulus = inf
hydraulic_conductivity = 1e-4
[materials.model]
type = "mohr_coulomb"
young_modulus = 1e7
poisson_ratio = 0.3
friction_angle = 25.0
cohesion = 5e3
[[bodies]]
name = "column"
material = "soil"
shape = { rectangle = { min = [0.0, 0.0], max = [0.2, 0.6] } }
[[boundaries]]
name = "base"
side = "y_min"
fix = ["ux", "uy"]
[[boundaries]]
name = "left"
side = "x_min"
fix = ["ux"]
[[boundaries]]
name = "right"
side = "x_max"
fix = ["ux"]
[[boundaries]]
name = "drained"
region = { min = [0.0, 0.6], max = [0.2, 0.6] }
fix = ["p"]
[[boundaries]]
name = "strip"
region = { min = [0.0, 0.6], max = [0.1, 0.6] }
fix = ["uy"]
displacement = [0.0, -3e-3]
time_function = "ramp"
[[stages]]
name = "press"
analysis = "quasi_static"
duration = 0.03
dt = 0.01
[[time_functions]]
name = "ramp"
type = "ramp"
duration = 0.03
"#;

/// The plane section extruded over z ∈ [0, 0.1] (one cell) between smooth, impermeable walls on
/// both z faces (u_z = U_z = 0: in the u–p–U system a face whose water is free is drained, p = 0
/// being its natural condition).
fn slab() -> String {
    slab_of(PLANE)
}

/// The plane section `plane` (the text of [`PLANE`], perhaps changed) extruded as [`slab`].
fn slab_of(plane: &str) -> String {
    plane
        .replace("size = [0.2, 0.8]", "size = [0.2, 0.8, 0.1]")
        .replace("cells = [2, 8]", "cells = [2, 8, 1]")
        .replace(
            "shape = { rectangle = { min = [0.0, 0.0], max = [0.2, 0.6] } }",
            "shape = { rectangle = { min = [0.0, 0.0], max = [0.2, 0.6] } }\nz = [0.0, 0.1]",
        )
        .replace("fix = [\"ux\", \"uy\"]", "fix = [\"ux\", \"uy\", \"uz\"]")
        .replace(
            "region = { min = [0.0, 0.6], max = [0.1, 0.6] }",
            "region = { min = [0.0, 0.6], max = [0.1, 0.6], z = [0.0, 0.1] }",
        )
        .replace(
            "region = { min = [0.0, 0.6], max = [0.2, 0.6] }",
            "region = { min = [0.0, 0.6], max = [0.2, 0.6], z = [0.0, 0.1] }",
        )
        .replace("displacement = [0.0, -3e-3]", "displacement = [0.0, -3e-3, 0.0]")
        .replace("traction = [0.0, -4e4]", "traction = [0.0, -4e4, 0.0]")
        + r#"
[[boundaries]]
name = "back"
side = "z_min"
fix = ["uz", "Uz"]
[[boundaries]]
name = "front"
side = "z_max"
fix = ["uz", "Uz"]
"#
}

/// The plane section in the (x, z) plane of a slab one cell thick along y, between smooth,
/// impermeable walls on both y faces: the plane's y is the slab's z, so that the slab's motion is
/// along x and z.
fn lying_slab() -> String {
    lying_slab_of(PLANE)
}

/// The plane section `plane` (the text of [`PLANE`], perhaps changed) laid in the (x, z) plane as
/// [`lying_slab`]; moving surfaces on the section's top faces move to the slab's z_max faces.
fn lying_slab_of(plane: &str) -> String {
    plane
        .replace(
            "surface = { body = \"column\", faces = [\"y_max\"], region = { min = [0.0, 0.5], max = [0.1, 0.6] } }\n\
             fix = [\"uy\"]",
            "surface = { body = \"column\", faces = [\"z_max\"], region = { min = [0.0, 0.0], max = [0.1, 0.1], z = \
             [0.5, 0.6] } }\nfix = [\"uz\"]",
        )
        .replace("faces = [\"y_max\"]", "faces = [\"z_max\"]")
        .replace("size = [0.2, 0.8]", "size = [0.2, 0.1, 0.8]")
        .replace("cells = [2, 8]", "cells = [2, 1, 8]")
        .replace(
            "shape = { rectangle = { min = [0.0, 0.0], max = [0.2, 0.6] } }",
            "shape = { rectangle = { min = [0.0, 0.0], max = [0.2, 0.1] } }\nz = [0.0, 0.6]",
        )
        .replace("side = \"y_min\"\nfix = [\"ux\", \"uy\"]", "side = \"z_min\"\nfix = [\"ux\", \"uy\", \"uz\"]")
        .replace(
            "region = { min = [0.0, 0.6], max = [0.1, 0.6] }\nfix = [\"uy\"]",
            "region = { min = [0.0, 0.0], max = [0.1, 0.1], z = [0.6, 0.6] }\nfix = [\"uz\"]",
        )
        .replace(
            "region = { min = [0.0, 0.6], max = [0.2, 0.6] }",
            "region = { min = [0.0, 0.0], max = [0.2, 0.1], z = [0.6, 0.6] }",
        )
        .replace("displacement = [0.0, -3e-3]", "displacement = [0.0, 0.0, -3e-3]")
        + r#"
[[boundaries]]
name = "back"
side = "y_min"
fix = ["uy", "Uy"]
[[boundaries]]
name = "front"
side = "y_max"
fix = ["uy", "Uy"]
"#
}

fn case_of(text: &str) -> Result<Case, String> {
    parse(text, "three_dimensional_system", &[]).map_err(|e| e.to_string())
}

/// The history of a run's points after each step: positions, stresses (6 components), pore
/// pressures, plastic strains, and the step's volume balance of F̄'s projection, ids.
#[derive(Debug, Default)]
struct Run {
    x: Vec<Vec<[f64; 3]>>,
    stress: Vec<Vec<[f64; 6]>>,
    p: Vec<Vec<f64>>,
    plastic: Vec<Vec<f64>>,
    /// Per step, Σ_p V_p^n J̄_p^{n+1} and Σ_p V_p^n J_p^{n+1} (V^n the volumes at the step's start,
    /// the projection's weights; J the determinant of the points' deformation gradient).
    volume_balance: Vec<[f64; 2]>,
    id: Vec<u64>,
}

/// Runs every step of the first stage of a case of dimension D through `System<D, M, N>`
/// (positions kept with three components, z = 0 in the plane); returns the run, the model at its
/// end and the last step's forces.
fn run_in<const D: usize, const M: usize, const N: usize>(
    case: &Case,
    coll: &Collective,
) -> Result<(Run, Model<D>, StepForces<D>), String>
where
    Dim<D>: StepDim<D>,
{
    let stage = &case.stages[0];
    let analysis = StageAnalysis::of(case, stage);
    let grid = porompm::model::grid_of(case);
    let mut system = System::<D, M, N>::new(coll, &grid, analysis.layout.in_dim(D), None, case.jacobian_stiffness())
        .map_err(|e| e.to_string())?;
    let mut model = Model::<D>::of_case(case, |c| system.space().owns_cell_in(c));
    model.integration = analysis.integration;
    let active = model.active(stage);
    let (dt, steps) = (stage.dt(), (stage.duration / stage.dt()).round() as usize);
    let mut run = Run { id: model.particles.id.clone(), ..Run::default() };
    let mut forces = StepForces::default();
    for n in 1..=steps {
        let step = system.prepare(&model, &active, (n as f64 * dt, dt), false, coll)?;
        let (out, solution) = system.solve(&step, &model, coll).map_err(|e| e.to_string())?;
        if !out.converged {
            return Err(format!("step {n} in {D} dimensions did not converge: {}", out.reason));
        }
        system.accept_increment(dt).map_err(|e| e.to_string())?;
        forces = system.forces(&step, &solution, &model, coll, false, &forces.reactions_by_dof)?;
        let results: Vec<_> = (0..model.particles.len()).map(|k| step.result::<N>(&model, &solution, k)).collect();
        let start_volume = model.particles.volume.clone();
        for (k, r) in results.iter().enumerate() {
            porompm::update::update_particle(&mut model, k, r, r.interp.dp, dt).map_err(|e| e.0)?;
        }
        let ps = &model.particles;
        let weighted = |f: &dyn Fn(usize) -> f64| (0..ps.len()).map(|k| start_volume[k] * f(k)).sum::<f64>();
        run.volume_balance.push([weighted(&|k| ps.jbar[k]), weighted(&|k| det(&ps.def_grad[k]))]);
        run.x.push(ps.x.iter().map(|x| std::array::from_fn(|c| if c < D { x[c] } else { 0.0 })).collect());
        run.stress.push(ps.stress.clone());
        run.p.push(ps.p.clone());
        run.plastic.push(ps.eps_pd.clone());
    }
    Ok((run, model, forces))
}

/// [`run_in`] of a plane case.
fn run_plane(case: &Case, coll: &Collective) -> Result<(Run, Model, StepForces), String> {
    run_in::<2, { MAX_NODES }, { MAX_DOF }>(case, coll)
}

/// [`run_in`] of a three-dimensional case.
fn run_solid(case: &Case, coll: &Collective) -> Result<(Run, Model<3>, StepForces<3>), String> {
    run_in::<3, { MAX_NODES_3D }, { MAX_DOF_3D }>(case, coll)
}

/// The plane point of each slab point: the one whose initial (x, y) is the slab point's initial x
/// and its coordinate `vertical` (1 for a slab thin along z, 2 for one thin along y).
fn twins(plane: &Model, solid: &Model<3>, vertical: usize) -> Result<Vec<usize>, String> {
    let (p0, s0) = (&plane.particles.x0, &solid.particles.x0);
    (0..s0.len())
        .map(|k| {
            (0..p0.len())
                .find(|&q| (p0[q][0] - s0[k][0]).abs() < 1e-12 && (p0[q][1] - s0[k][vertical]).abs() < 1e-12)
                .ok_or_else(|| format!("slab point {} has no plane twin", solid.particles.id[k]))
        })
        .collect()
}

/// The largest stress and pore-pressure magnitudes of a run, the scales of its differences.
fn scales(run: &Run) -> (f64, f64) {
    let stress = run.stress.iter().flatten().flat_map(|s| s.iter()).fold(0.0f64, |m, v| m.max(v.abs()));
    (stress, run.p.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs())))
}

/// The largest difference between a slab point's stress [xx, yy, xy, zz, yz, zx] and its plane
/// twin's [xx, yy, xy, zz] [Pa]: for a slab thin along z (`vertical` 1) component for component, its
/// yz and zx zero; for one thin along y (`vertical` 2) the plane's [xx, yy, xy, zz] is the slab's
/// [xx, zz, zx, yy], its xy and yz zero.
fn stress_difference(a: &[f64; 6], b: &[f64; 6], vertical: usize) -> f64 {
    let pairs = if vertical == 1 {
        [(a[0], b[0]), (a[1], b[1]), (a[2], b[2]), (a[3], b[3]), (a[4], 0.0), (a[5], 0.0)]
    } else {
        [(a[0], b[0]), (a[3], b[1]), (a[5], b[2]), (a[1], b[3]), (a[2], 0.0), (a[4], 0.0)]
    };
    pairs.iter().map(|(u, v)| (u - v).abs()).fold(0.0, f64::max)
}

/// The slab against its plane section: three steps without B̄, and the first step with B̄. After a
/// step with B̄ the deformation gradient a point keeps differs by design, F̄ = (J_v/J)^{1/3} F in
/// three dimensions (its zz stretch not 1) and (J_v/J)^{1/2} F of the in-plane deformation in the
/// plane, and so do what follows it: the stretched GIMP domains and the pressure gradient carried
/// with the material (measured on this slab: 3e-5 of the stresses after three steps).
fn a_slab_steps_as_its_plane_twin(coll: &Collective) -> Result<(), String> {
    let without = |t: &str| t.replace("bbar = true", "bbar = false");
    let first = |t: &str| t.replace("duration = 0.03\ndt", "duration = 0.01\ndt");
    compare_slab(&without(PLANE), &without(&slab()), coll)?;
    compare_slab(&first(PLANE), &first(&slab()), coll)
}

/// The plane section pressed by a nodal traction of 40 kPa over the strip's line of nodes (ramped
/// over the three steps) instead of the strip's displacement.
fn pressed_by_nodes() -> String {
    PLANE.replace(
        "[[boundaries]]\nname = \"strip\"\nregion = { min = [0.0, 0.6], max = [0.1, 0.6] }\nfix = [\"uy\"]\n\
         displacement = [0.0, -3e-3]\ntime_function = \"ramp\"\n",
        "[[loads]]\nname = \"strip\"\nkind = \"nodal_traction\"\nregion = { min = [0.0, 0.6], max = [0.1, 0.6] }\n\
         traction = [0.0, -4e4]\ntime_function = \"ramp\"\n",
    )
}

/// The slab pressed by a nodal traction on its top face steps as its plane section pressed by one
/// on its top line (B̄ off, three steps): the nodes of the slab's loaded face each stand for the
/// product of their tributary lengths along x and z (`model::loads::tributary_nodes`), so the
/// slab's loads are the section's times its thickness, and so are its first moments and
/// reactions.
fn a_slab_pressed_by_a_nodal_traction_steps_as_its_plane_twin(coll: &Collective) -> Result<(), String> {
    let plane = pressed_by_nodes().replace("bbar = true", "bbar = false");
    if !plane.contains("nodal_traction") {
        return Err("the strip's displacement was not replaced by a nodal traction".into());
    }
    compare_slab(&plane, &slab_of(&plane), coll)
}

/// The slab with the pressure projection (`stabilisation.pressure_projection = 2`, B̄ off, three
/// steps) steps as its plane section with it: a cell's block S over its eight trilinear functions
/// (`pressure::projection_cells`) sees in the slab's pressure, constant along z, what the four
/// bilinear ones see in the section's. The projection moves the section's pore pressures (by more
/// than 1e-3 of their largest), so the comparison sees it.
fn a_slab_with_the_pressure_projection_steps_as_its_plane_twin(coll: &Collective) -> Result<(), String> {
    let without = PLANE.replace("bbar = true", "bbar = false");
    let with = without.replace("bbar = false", "bbar = false\npressure_projection = 2.0");
    let (plain, _, _) = run_plane(&case_of(&without)?, coll)?;
    let (projected, _, _) = run_plane(&case_of(&with)?, coll)?;
    let (_, scale_p) = scales(&plain);
    let moved =
        plain.p.iter().flatten().zip(projected.p.iter().flatten()).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
            / scale_p;
    println!("    the projection moves the section's pore pressures by {moved:.2e} of {scale_p:.3e} Pa");
    if moved.is_nan() || moved < 1e-3 {
        return Err(format!("the pressure projection barely moves the section's pore pressures: {moved:e}"));
    }
    compare_slab(&with, &slab_of(&with), coll)
}

/// The plane section with its top drained and pressed through moving surfaces instead of grid
/// regions: `p = 0` on the exposed top faces of the column (imposed weakly, by Nitsche's terms on
/// the faces, in these quasi-static steps of the u–p system with flow), and the strip's
/// displacement on the top faces of the points under x ∈ [0, 0.1] (fixed at the nodes of their
/// stencils on the face's side, within the region's extent along x).
fn with_moving_surfaces() -> String {
    PLANE
        .replace(
            "name = \"drained\"\nregion = { min = [0.0, 0.6], max = [0.2, 0.6] }",
            "name = \"drained\"\nsurface = { body = \"column\", faces = [\"y_max\"] }",
        )
        .replace(
            "name = \"strip\"\nregion = { min = [0.0, 0.6], max = [0.1, 0.6] }",
            "name = \"strip\"\nsurface = { body = \"column\", faces = [\"y_max\"], region = { min = [0.0, 0.5], max = [0.1, 0.6] } }",
        )
}

/// The slab drained and pressed through moving surfaces on its top faces steps as its plane
/// section drained and pressed through the same surfaces (B̄ off, three steps): the surfaces'
/// fixed nodes (`Model::surface_fixes`: the faces' normals turned with the material, the nodes on
/// the face's side, the region's extent along x and, in the slab, along z) and Nitsche's drained
/// faces (`pressure::drained_faces`: the trilinear functions at the face points, the faces'
/// areas) in three dimensions; and so does the slab lying in the (x, z) plane, whose surfaces are
/// its z_max faces (normals along z, the strip's region with a z range).
fn a_slab_with_moving_surfaces_steps_as_its_plane_twin(coll: &Collective) -> Result<(), String> {
    let plane = with_moving_surfaces().replace("bbar = true", "bbar = false");
    if plane.matches("surface = ").count() != 2 {
        return Err("the drained top and the strip were not both replaced by moving surfaces".into());
    }
    compare_slab(&plane, &slab_of(&plane), coll)?;
    let lying = lying_slab_of(&plane);
    if lying.matches("faces = [\"z_max\"]").count() != 2 {
        return Err("the lying slab's surfaces are not its z_max faces".into());
    }
    compare_lying(&plane, &lying, "moving surfaces", coll)
}

/// The slab lying in the (x, z) plane, `solid`, steps as the plane section of `plane`, point for
/// point: stresses, pore pressures and positions (the plane's y the slab's z, its y at rest), to
/// 1e-9 of their largest (of a cell for positions).
fn compare_lying(plane: &str, solid: &str, label: &str, coll: &Collective) -> Result<(), String> {
    let (plane, plane_model, _) = run_plane(&case_of(plane)?, coll)?;
    let (solid, model, _) = run_solid(&case_of(solid)?, coll)?;
    let twin = twins(&plane_model, &model, 2)?;
    let (scale_s, scale_p) = scales(&plane);
    let mut worst = [0.0f64; 3];
    for step in 0..plane.x.len() {
        for (k, &q) in twin.iter().enumerate() {
            worst[0] = worst[0].max(stress_difference(&solid.stress[step][k], &plane.stress[step][q], 2) / scale_s);
            worst[1] = worst[1].max((solid.p[step][k] - plane.p[step][q]).abs() / scale_p);
            let (xs, xp) = (solid.x[step][k], plane.x[step][q]);
            let across = (xs[1] - model.particles.x0[k][1]).abs();
            worst[2] = worst[2].max((xs[0] - xp[0]).abs().max((xs[2] - xp[1]).abs()).max(across) / 0.1);
        }
    }
    println!(
        "    lying slab against plane ({label}): {} steps; largest differences: stress {:.1e} (of {scale_s:.3e} Pa), \
         pore pressure {:.1e} (of {scale_p:.3e} Pa), position {:.1e} (of a cell)",
        plane.x.len(),
        worst[0],
        worst[1],
        worst[2]
    );
    if worst.iter().any(|&w| w > 1e-9 || w.is_nan()) || scale_p <= 0.0 {
        return Err(format!("the lying slab departs from its plane twin: {worst:?}"));
    }
    Ok(())
}

/// The slab of `solid` steps as the plane section of `plane`, point for point.
fn compare_slab(plane: &str, solid: &str, coll: &Collective) -> Result<(), String> {
    let plane_case = case_of(plane)?;
    let solid_case = case_of(solid)?;
    let (plane, plane_model, plane_forces) = run_plane(&plane_case, coll)?;
    let (solid, model, forces) = run_solid(&solid_case, coll)?;
    let (in_plane, zz) = forces_against_plane(&model, &forces, &plane_forces, 0.1);
    let n2 = plane.id.len();
    if solid.id.len() != 2 * n2 {
        return Err(format!("{} points in the slab for {n2} in the plane (two layers expected)", solid.id.len()));
    }
    let x0 = &model.particles.x0;
    let twin = twins(&plane_model, &model, 1)?;
    let (scale_s, scale_p) = scales(&plane);
    let yielded = plane.plastic.last().map_or(0, |e| e.iter().filter(|&&v| v > 0.0).count());
    if yielded == 0 || scale_p <= 0.0 {
        return Err(format!("the plane run must yield and build pore pressure (yielded {yielded}, p {scale_p})"));
    }
    let mut worst = [0.0f64; 4];
    for step in 0..plane.x.len() {
        for (k, &q) in twin.iter().enumerate() {
            worst[0] = worst[0].max(stress_difference(&solid.stress[step][k], &plane.stress[step][q], 1) / scale_s);
            worst[1] = worst[1].max((solid.p[step][k] - plane.p[step][q]).abs() / scale_p);
            for c in 0..2 {
                worst[2] = worst[2].max((solid.x[step][k][c] - plane.x[step][q][c]).abs() / 0.1);
            }
            worst[2] = worst[2].max((solid.x[step][k][2] - x0[k][2]).abs() / 0.1);
            worst[3] = worst[3].max((solid.plastic[step][k] - plane.plastic[step][q]).abs());
        }
    }
    println!(
        "    slab against plane (B̄ {}): {} steps, {yielded} of {n2} plane points yielded; largest differences: stress \
         {:.1e} (of {scale_s:.3e} Pa), pore pressure {:.1e} (of {scale_p:.3e} Pa), position {:.1e} (of a cell), \
         plastic strain {:.1e}",
        plane_case.stabilisation.bbar,
        plane.x.len(),
        worst[0],
        worst[1],
        worst[2],
        worst[3]
    );
    println!(
        "    the slab's forces: first moments and reactions in the plane against the section's times its \
         thickness {in_plane:.1e}; Σ z ⊗ R_z against ∫(σ_zz − p) dV {zz:.1e}"
    );
    if worst.iter().any(|&w| w > 1e-9 || w.is_nan()) || !(in_plane < 1e-10 && zz < 1e-9) {
        return Err(format!("the slab departs from its plane twin: {worst:?}, forces {in_plane:e}, zz {zz:e}"));
    }
    Ok(())
}

/// A case of the plane section or of the slab as a one-phase explicit stage (`dynamic_explicit`,
/// without B̄): no pore pressure, no drained top, smooth walls on the slab's z faces, ten steps of
/// 2e-4 s (a fifth of the P wave's cell crossing time, 1.2e-3 s) while the strip pushes.
fn one_phase_explicit(text: &str) -> String {
    let mut t = text
        .replace("formulation = \"two_phase\"", "formulation = \"one_phase\"")
        .replace("bbar = true", "bbar = false")
        .replace("fix = [\"uz\", \"Uz\"]", "fix = [\"uz\"]")
        .replace("fix = [\"uy\", \"Uy\"]", "fix = [\"uy\"]")
        .replace(
            "analysis = \"quasi_static\"\nduration = 0.03\ndt = 0.01",
            "analysis = \"dynamic_explicit\"\nduration = 0.002\ndt = 0.0002",
        );
    let drained = t.find("name = \"drained\"").expect("the drained top");
    let start = t[..drained].rfind("[[boundaries]]").expect("its table");
    let end = drained + t[drained..].find("[[").expect("a table after it");
    t.replace_range(start..end, "");
    t
}

/// The slab in a one-phase explicit stage (the nodal update of `assembly::explicit` in three
/// dimensions: lumped masses and momenta, the forces of the step's start, the velocity update per
/// node and direction) steps as its plane section, point for point: stresses, positions and
/// velocities; so does the slab lying in the (x, z) plane, whose motion is along x and z.
fn an_explicit_slab_steps_as_its_plane_twin(coll: &Collective) -> Result<(), String> {
    explicit_twin(&slab(), 1, coll)?;
    explicit_twin(&lying_slab(), 2, coll)
}

/// The explicit one-phase run of the slab `solid` (thin along y when `vertical` is 2) against the
/// plane section's.
fn explicit_twin(solid: &str, vertical: usize, coll: &Collective) -> Result<(), String> {
    let plane_case = case_of(&one_phase_explicit(PLANE))?;
    let solid_case = case_of(&one_phase_explicit(solid))?;
    let (plane, plane_model, _) = run_plane(&plane_case, coll)?;
    let (solid, model, _) = run_solid(&solid_case, coll)?;
    let twin = twins(&plane_model, &model, vertical)?;
    let (scale_s, _) = scales(&plane);
    let speed = plane_model.particles.vel.iter().fold(0.0f64, |m, v| m.max(v[0].abs().max(v[1].abs())));
    // The slab's axes of the plane's x and y, and the one across it.
    let (ax, ay, across) = (0, vertical, 3 - vertical);
    let mut worst = [0.0f64; 3];
    for step in 0..plane.x.len() {
        for (k, &q) in twin.iter().enumerate() {
            let difference = stress_difference(&solid.stress[step][k], &plane.stress[step][q], vertical);
            worst[0] = worst[0].max(difference / scale_s);
            let (xs, xp) = (solid.x[step][k], plane.x[step][q]);
            worst[1] = worst[1].max(
                ((xs[ax] - xp[0])
                    .abs()
                    .max((xs[ay] - xp[1]).abs())
                    .max((xs[across] - model.particles.x0[k][across]).abs()))
                    / 0.1,
            );
        }
    }
    for (k, &q) in twin.iter().enumerate() {
        let (v, w) = (model.particles.vel[k], plane_model.particles.vel[q]);
        worst[2] = worst[2].max(((v[ax] - w[0]).abs().max((v[ay] - w[1]).abs()).max(v[across].abs())) / speed);
    }
    println!(
        "    explicit slab (thin along {}) against plane: {} steps; largest differences: stress {:.1e} (of \
         {scale_s:.3e} Pa), position {:.1e} (of a cell), velocity {:.1e} (of {speed:.3e} m/s)",
        ["x", "y", "z"][across],
        plane.x.len(),
        worst[0],
        worst[1],
        worst[2]
    );
    if worst.iter().any(|&w| w > 1e-12 || w.is_nan()) || scale_s <= 0.0 || speed <= 0.0 || plane.x.len() != 10 {
        return Err(format!("the explicit slab departs from its plane twin: {worst:?}"));
    }
    Ok(())
}

/// The slab in a one-phase explicit stage with [002]'s F̄ projection (Algorithm 1 with dim = 3):
/// the projection conserves the volume of every step, Σ_p V_p^n J̄_p^{n+1} = Σ_p V_p^n J_p^{n+1}
/// (the nodal average of J weighted by the points' volumes, interpolated back with a partition of
/// unity), F̄ changes the answer on this non-uniform push, and the projected volume ratio of each
/// point equals its plane twin's (J̄ is the same volume average in any dimension).
fn an_explicit_slab_with_fbar_conserves_the_projected_volume(coll: &Collective) -> Result<(), String> {
    let with_fbar = |t: &str| one_phase_explicit(t).replace("bbar = false", "bbar = false\nfbar = true");
    let (plain, _, _) = run_solid(&case_of(&one_phase_explicit(&slab()))?, coll)?;
    let (projected, model, _) = run_solid(&case_of(&with_fbar(&slab()))?, coll)?;
    let (_, plane, _) = run_plane(&case_of(&with_fbar(PLANE))?, coll)?;
    let balance = projected.volume_balance.iter().map(|[a, b]| (a - b).abs() / b).fold(0.0f64, f64::max);
    let spread = projected.volume_balance.iter().map(|[a, b]| (a - b).abs()).fold(0.0f64, f64::max);
    let twin = twins(&plane, &model, 1)?;
    let jbar = twin
        .iter()
        .enumerate()
        .map(|(k, &q)| (model.particles.jbar[k] - plane.particles.jbar[q]).abs())
        .fold(0.0f64, f64::max);
    let moved = model.particles.jbar.iter().map(|j| (j - 1.0).abs()).fold(0.0f64, f64::max);
    let changed = largest_stress_difference(&plain, &projected) / scales(&plain).0;
    println!(
        "    explicit slab with F̄: Σ V J̄ against Σ V J over {} steps {balance:.1e} (absolute {spread:.1e} m³); J̄ \
         against the plane twin's {jbar:.1e} (J̄ − 1 up to {moved:.1e}); F̄ moves the stresses by {changed:.1e} of \
         their largest",
        projected.x.len()
    );
    if balance > 1e-14 || balance.is_nan() || jbar > 1e-12 || moved < 1e-6 || changed < 1e-6 {
        return Err(format!("F̄ in 3D: balance {balance:e}, J̄ against the plane {jbar:e}, change {changed:e}"));
    }
    Ok(())
}

/// The slab's step forces against its plane section's: the largest difference of the in-plane
/// first moments and of the boundaries' in-plane reactions from the section's times the slab's
/// `thickness` (relative to the largest of them), and of the zz moment (every z force is a
/// wall's reaction) from ∫(σ_zz − p) dV (relative to the largest moment).
fn forces_against_plane(model: &Model<3>, forces: &StepForces<3>, plane: &StepForces, thickness: f64) -> (f64, f64) {
    let scale = plane.moment.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs())) * thickness;
    let mut in_plane = 0.0f64;
    for a in 0..2 {
        for b in 0..2 {
            in_plane = in_plane.max((forces.moment[a][b] - thickness * plane.moment[a][b]).abs() / scale);
        }
    }
    let r_scale = plane.reactions.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs())) * thickness;
    for (r3, r2) in forces.reactions.iter().zip(&plane.reactions) {
        for c in 0..2 {
            in_plane = in_plane.max((r3[c] - thickness * r2[c]).abs() / r_scale);
        }
    }
    let ps = &model.particles;
    let zz: f64 = (0..ps.len()).map(|k| (ps.stress[k][3] - ps.p[k]) * ps.volume[k]).sum();
    (in_plane, (forces.moment[2][2] - zz).abs() / scale)
}

/// An elastic cube of 0.3 m on rollers at x_min, y_min and z_min, its x_max face displaced by
/// δ = −1.5 mm, the others free: uniaxial stress, σ_xx = E δ/L, every other stress zero, the
/// lateral strains −ν δ/L.
const CUBE: &str = r#"
[analysis]
formulation = "one_phase"
kinematics = "linear_increments"
[grid]
size = [0.3, 0.3, 0.3]
cells = [3, 3, 3]
[[materials]]
name = "steel"
porosity = 0.0
solid_density = 2000.0
[materials.model]
type = "linear_elastic"
young_modulus = 2e7
poisson_ratio = 0.3
[[bodies]]
name = "cube"
material = "steel"
shape = { rectangle = { min = [0.0, 0.0], max = [0.3, 0.3] } }
z = [0.0, 0.3]
[[boundaries]]
name = "x_roller"
side = "x_min"
fix = ["ux"]
[[boundaries]]
name = "y_roller"
side = "y_min"
fix = ["uy"]
[[boundaries]]
name = "z_roller"
side = "z_min"
fix = ["uz"]
[[boundaries]]
name = "press"
side = "x_max"
fix = ["ux"]
displacement = [-1.5e-3, 0.0, 0.0]
time_function = "ramp"
[[stages]]
name = "press"
analysis = "static"
duration = 1.0
dt = 1.0
[[time_functions]]
name = "ramp"
type = "ramp"
duration = 1.0
"#;

fn a_block_squeezed_from_three_sides_is_homogeneous(coll: &Collective) -> Result<(), String> {
    // Geometrically linear: Hooke's law for the imposed strain, exactly.
    let (run, model, _) = run_solid(&case_of(CUBE)?, coll)?;
    let (e, nu, l, d) = (2e7, 0.3, 0.3, -1.5e-3);
    let strain = d / l;
    let sxx = e * strain;
    let last = run.stress.len() - 1;
    let mut worst = [0.0f64; 2];
    for (k, s) in run.stress[last].iter().enumerate() {
        let want = [sxx, 0.0, 0.0, 0.0, 0.0, 0.0];
        for c in 0..6 {
            worst[0] = worst[0].max((s[c] - want[c]).abs() / sxx.abs());
        }
        let x0 = model.particles.x0[k];
        let u: [f64; 3] = std::array::from_fn(|c| run.x[last][k][c] - x0[c]);
        let want_u = [strain * x0[0], -nu * strain * x0[1], -nu * strain * x0[2]];
        for c in 0..3 {
            worst[1] = worst[1].max((u[c] - want_u[c]).abs() / d.abs());
        }
    }
    println!(
        "    cube in uniaxial stress: {} points, largest stress error {:.1e} of σ_xx = {sxx:.4e} Pa, displacement \
         error {:.1e} of δ",
        run.id.len(),
        worst[0],
        worst[1]
    );
    if worst.iter().any(|&w| w > 1e-10 || w.is_nan()) {
        return Err(format!("the cube is not homogeneous: {worst:?}"));
    }
    // At finite strain, on the moved configuration: the same homogeneous uniaxial state (σ_xx the
    // same at every point, the other components zero), the first moment of the loads and
    // reactions about the grid's centre equal to ∫σ dV (Σ V σ over the points), and the walls'
    // reactions σ_xx times the face's current area.
    let (run, model, forces) = run_solid(&case_of(&CUBE.replace("kinematics = \"linear_increments\"\n", ""))?, coll)?;
    let ps = &model.particles;
    let sxx = ps.stress[0][0];
    let spread = ps
        .stress
        .iter()
        .flat_map(|s| (0..6).map(move |c| (s[c] - if c == 0 { sxx } else { 0.0 }).abs()))
        .fold(0.0, f64::max)
        / sxx.abs();
    let mut integral = [[0.0; 3]; 3];
    for (s, v) in ps.stress.iter().zip(&ps.volume) {
        let t = [[s[0], s[2], s[5]], [s[2], s[1], s[4]], [s[5], s[4], s[3]]];
        for a in 0..3 {
            for b in 0..3 {
                integral[a][b] += v * t[a][b];
            }
        }
    }
    let volume: f64 = ps.volume.iter().sum();
    let scale = (sxx * volume).abs();
    let moment_error =
        (0..9).map(|e| (forces.moment[e / 3][e % 3] - integral[e / 3][e % 3]).abs() / scale).fold(0.0, f64::max);
    // The lateral stretches from a point's motion (homogeneous: x = λ x0 in y and z).
    let k = ps.len() - 1;
    let stretch = |c: usize| ps.x[k][c] / ps.x0[k][c];
    let area = l * stretch(1) * l * stretch(2);
    let want = [[-sxx * area, 0.0, 0.0], [0.0; 3], [0.0; 3], [sxx * area, 0.0, 0.0]];
    let reaction_error = forces
        .reactions
        .iter()
        .zip(&want)
        .flat_map(|(r, w)| (0..3).map(move |c| (r[c] - w[c]).abs() / (sxx * area).abs()))
        .fold(0.0, f64::max);
    println!(
        "    at finite strain: σ_xx = {sxx:.4e} Pa ({:+.2} % from Hooke's), spread {spread:.1e}; Σ x ⊗ (F + R) \
         against ∫σ dV {moment_error:.1e} of σ_xx V; the walls' reactions {reaction_error:.1e} of σ_xx A",
        100.0 * (sxx / (e * strain) - 1.0)
    );
    if [spread, moment_error, reaction_error].iter().any(|&w| w > 1e-10 || w.is_nan()) || run.id.is_empty() {
        return Err(format!(
            "the cube at finite strain: spread {spread:e}, moment {moment_error:e}, reactions {reaction_error:e}"
        ));
    }
    Ok(())
}

/// The slab's three steps (without B̄) with the iterative strategy of large quasi-static runs
/// (`petsc_options/fieldsplit-fixed-stress.opts`: GMRES with the Schur field split whose `u` block
/// carries the three-dimensional rigid-body modes to GAMG and whose Schur complement is the
/// fixed-stress approximation with the skeleton's bulk modulus) give the direct solver's answer.
fn the_slab_solves_alike_with_the_fixed_stress_field_split(coll: &Collective) -> Result<(), String> {
    let case = case_of(&slab().replace("bbar = true", "bbar = false"))?;
    let (direct, _, _) = run_solid(&case, coll)?;
    let (iterative, _, _) = with_options_file("fieldsplit-fixed-stress.opts", coll, || run_solid(&case, coll))??;
    let (scale, _) = scales(&direct);
    let worst = largest_stress_difference(&direct, &iterative) / scale;
    println!("    fixed-stress field split against LU: largest stress difference {worst:.1e} of {scale:.3e} Pa");
    if worst > 1e-9 || worst.is_nan() {
        return Err(format!("the iterative solve departs from the direct one by {worst:e}"));
    }
    Ok(())
}

/// The cube at finite strain (one phase, u only) with the iterative strategy of large solid runs
/// (`petsc_options/gamg-solid.opts`: GMRES with GAMG, whose aggregates come from the six rigid-body
/// modes attached to the tangent) gives the direct solver's answer.
fn the_cube_solves_alike_with_gamg(coll: &Collective) -> Result<(), String> {
    let case = case_of(&CUBE.replace("linear_increments", "finite_strain"))?;
    let (direct, _, _) = run_solid(&case, coll)?;
    let (iterative, _, _) = with_options_file("gamg-solid.opts", coll, || run_solid(&case, coll))??;
    let (scale, _) = scales(&direct);
    let worst = largest_stress_difference(&direct, &iterative) / scale;
    println!("    GAMG against LU: largest stress difference {worst:.1e} of {scale:.3e} Pa");
    if worst > 1e-9 || worst.is_nan() || scale == 0.0 {
        return Err(format!("the iterative solve departs from the direct one by {worst:e}"));
    }
    Ok(())
}

/// The largest difference between two runs' stresses, over steps, points and components [Pa].
fn largest_stress_difference(a: &Run, b: &Run) -> f64 {
    (0..a.stress.len())
        .flat_map(|n| (0..a.id.len()).map(move |k| (n, k)))
        .flat_map(|(n, k)| (0..6).map(move |c| (n, k, c)))
        .map(|(n, k, c)| (a.stress[n][k][c] - b.stress[n][k][c]).abs())
        .fold(0.0, f64::max)
}

/// Runs `f` with the options of `petsc_options/<name>` in PETSc's database, and takes them out
/// again afterwards.
fn with_options_file<T>(name: &str, coll: &Collective, f: impl FnOnce() -> T) -> Result<T, String> {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("petsc_options").join(name);
    let text = std::fs::read_to_string(&file).map_err(|e| e.to_string())?;
    let names: Vec<&str> =
        text.lines().filter_map(|l| l.split_whitespace().next()).filter(|w| w.starts_with('-')).collect();
    let options = petsc::Options::global();
    let comm = petsc::Comm::from_raw(mpi::traits::AsRaw::as_raw(coll.communicator()));
    options.insert_file(comm, &file).map_err(|e| e.to_string())?;
    let out = f();
    for n in &names {
        options.clear_value(n).map_err(|e| e.to_string())?;
    }
    Ok(out)
}

/// The slab lying in the (x, z) plane (its thin direction y, `lying_slab`) in a dynamic stage
/// (the u–p–U system, Newmark, Mohr–Coulomb, without B̄) steps as its plane section with y and z
/// swapped, point for point: the z components of the masses, momenta, predictors, drag and flow
/// carry its motion, which the slab between z walls leaves at zero.
fn a_lying_slab_moves_as_its_plane_twin_in_a_dynamic_stage(coll: &Collective) -> Result<(), String> {
    let dynamic = |t: &str| t.replace("bbar = true", "bbar = false").replace("quasi_static", "dynamic");
    compare_lying(&dynamic(PLANE), &dynamic(&lying_slab()), "dynamic", coll)
}

/// A case of the plane section or of a slab as a two-phase explicit stage (`dynamic_explicit`,
/// the u–U system, without B̄): ten steps of 2e-5 s (a third of the fast P wave's cell crossing
/// time, about 6e-5 s) while the strip pushes. With `nodal`, the pore pressure from the lumped
/// continuity equation at the nodes (`explicit.pore_pressure = "nodal"`, drained at the top);
/// otherwise each point's own increment, which fixes no pressure (no drained top).
fn two_phase_explicit(text: &str, nodal: bool) -> String {
    let explicit = if nodal { "\nexplicit = { pore_pressure = \"nodal\" }" } else { "" };
    let mut t = text.replace("bbar = true", "bbar = false").replace(
        "analysis = \"quasi_static\"\nduration = 0.03\ndt = 0.01",
        &format!("analysis = \"dynamic_explicit\"\nduration = 0.0002\ndt = 0.00002{explicit}"),
    );
    if !nodal {
        let drained = t.find("name = \"drained\"").expect("the drained top");
        let start = t[..drained].rfind("[[boundaries]]").expect("its table");
        let end = drained + t[drained..].find("[[").expect("a table after it");
        t.replace_range(start..end, "");
    }
    t
}

/// The slab in a two-phase explicit stage (the u–U system of `assembly::explicit` in three
/// dimensions: both phases' lumped masses and momenta, the drag per node and direction, the pore
/// pressure of each point or of the nodes' lumped continuity equation with the drained nodes of
/// the top) steps as its plane section, point for point: stresses, pore pressures, positions and
/// both phases' velocities; so does the slab lying in the (x, z) plane.
fn a_two_phase_explicit_slab_steps_as_its_plane_twin(coll: &Collective) -> Result<(), String> {
    for nodal in [false, true] {
        for (solid, vertical) in [(slab(), 1), (lying_slab(), 2)] {
            let (plane, plane_model, _) = run_plane(&case_of(&two_phase_explicit(PLANE, nodal))?, coll)?;
            let (run, model, _) = run_solid(&case_of(&two_phase_explicit(&solid, nodal))?, coll)?;
            let twin = twins(&plane_model, &model, vertical)?;
            let (scale_s, scale_p) = scales(&plane);
            let (ax, ay, across) = (0, vertical, 3 - vertical);
            let speed = |v: &[[f64; 2]]| v.iter().fold(0.0f64, |m, v| m.max(v[0].abs().max(v[1].abs())));
            let (ps, pp) = (&model.particles, &plane_model.particles);
            let speeds = [speed(&pp.vel), speed(&pp.vel_w)];
            let mut worst = [0.0f64; 4];
            for step in 0..plane.x.len() {
                for (k, &q) in twin.iter().enumerate() {
                    let difference = stress_difference(&run.stress[step][k], &plane.stress[step][q], vertical);
                    worst[0] = worst[0].max(difference / scale_s);
                    worst[1] = worst[1].max((run.p[step][k] - plane.p[step][q]).abs() / scale_p);
                    let (xs, xp) = (run.x[step][k], plane.x[step][q]);
                    let off = (xs[across] - ps.x0[k][across]).abs();
                    worst[2] = worst[2].max((xs[ax] - xp[0]).abs().max((xs[ay] - xp[1]).abs()).max(off) / 0.1);
                }
            }
            for (k, &q) in twin.iter().enumerate() {
                for (v, w, s) in [(ps.vel[k], pp.vel[q], speeds[0]), (ps.vel_w[k], pp.vel_w[q], speeds[1])] {
                    let d = (v[ax] - w[0]).abs().max((v[ay] - w[1]).abs()).max(v[across].abs());
                    worst[3] = worst[3].max(d / s);
                }
            }
            println!(
                "    two-phase explicit slab (thin along {}, {} pore pressure) against plane: {} steps; largest \
                 differences: stress {:.1e} (of {scale_s:.3e} Pa), pore pressure {:.1e} (of {scale_p:.3e} Pa), \
                 position {:.1e} (of a cell), velocities {:.1e} (of {:.3e} and {:.3e} m/s)",
                ["x", "y", "z"][across],
                if nodal { "nodal" } else { "pointwise" },
                plane.x.len(),
                worst[0],
                worst[1],
                worst[2],
                worst[3],
                speeds[0],
                speeds[1]
            );
            if worst.iter().any(|&w| w > 1e-12 || w.is_nan())
                || scale_s <= 0.0
                || scale_p <= 0.0
                || speeds.iter().any(|&s| s <= 0.0)
                || plane.x.len() != 10
            {
                return Err(format!("the two-phase explicit slab departs from its plane twin: {worst:?}"));
            }
        }
    }
    Ok(())
}

type TestFn = fn(&Collective) -> Result<(), String>;

/// The tests of this file, in the order they run.
const TESTS: &[(&str, TestFn)] = &[
    ("a_slab_steps_as_its_plane_twin", a_slab_steps_as_its_plane_twin),
    (
        "a_slab_pressed_by_a_nodal_traction_steps_as_its_plane_twin",
        a_slab_pressed_by_a_nodal_traction_steps_as_its_plane_twin,
    ),
    (
        "a_slab_with_the_pressure_projection_steps_as_its_plane_twin",
        a_slab_with_the_pressure_projection_steps_as_its_plane_twin,
    ),
    ("a_slab_with_moving_surfaces_steps_as_its_plane_twin", a_slab_with_moving_surfaces_steps_as_its_plane_twin),
    ("a_block_squeezed_from_three_sides_is_homogeneous", a_block_squeezed_from_three_sides_is_homogeneous),
    (
        "a_lying_slab_moves_as_its_plane_twin_in_a_dynamic_stage",
        a_lying_slab_moves_as_its_plane_twin_in_a_dynamic_stage,
    ),
    (
        "the_slab_solves_alike_with_the_fixed_stress_field_split",
        the_slab_solves_alike_with_the_fixed_stress_field_split,
    ),
    ("the_cube_solves_alike_with_gamg", the_cube_solves_alike_with_gamg),
    ("an_explicit_slab_steps_as_its_plane_twin", an_explicit_slab_steps_as_its_plane_twin),
    (
        "an_explicit_slab_with_fbar_conserves_the_projected_volume",
        an_explicit_slab_with_fbar_conserves_the_projected_volume,
    ),
    ("a_two_phase_explicit_slab_steps_as_its_plane_twin", a_two_phase_explicit_slab_steps_as_its_plane_twin),
];

fn main() {
    let Some(chosen) = common::harness::selected(TESTS) else { return };
    let petsc = match petsc::Petsc::initialize(&[], None, "porompm three-dimensional system tests") {
        Ok(p) => p,
        Err(err) => {
            eprintln!("cannot initialise PETSc: {err}");
            std::process::exit(1);
        }
    };
    // Newton to the round-off of the forces (the identities below are checked to 1e-10).
    if let Err(err) = petsc::Options::global().set_value("-snes_rtol", Some("1e-13")) {
        eprintln!("cannot set -snes_rtol: {err}");
        std::process::exit(1);
    }
    let coll = Collective::world();
    let ok = common::harness::run(&chosen, |t| t(&coll));
    drop(petsc);
    std::process::exit(if ok { 0 } else { 101 });
}
