//! Range and consistency checks of a typed case. Messages name the key (`materials[0].porosity`)
//! and say what is wrong and what was found.

use super::schema::*;
use std::collections::HashSet;

type R = Result<(), String>;

fn positive(key: &str, v: f64) -> R {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be a positive number, got {v}"))
    }
}

/// Largest modulus accepted [Pa]: ten times diamond's Young's modulus. Beyond it a soil tangent
/// holds no digits of the load (E = 1e308 overflowed to NaN before the run failed).
pub const MAX_MODULUS: f64 = 1e13;
/// Largest hydraulic conductivity accepted [m/s] (open gravel is about 1e-1).
pub const MAX_CONDUCTIVITY: f64 = 1.0;
/// Largest pressure-projection factor α accepted (τ = α/G; the values that work are of order 1).
pub const MAX_PROJECTION: f64 = 1e3;
/// Largest density accepted [kg/m³] (osmium is 22 590).
pub const MAX_DENSITY: f64 = 1e5;

/// A positive physical magnitude of at most `hi` (in `unit`), with the reason for the bound.
fn magnitude(key: &str, v: f64, hi: f64, unit: &str, why: &str) -> R {
    positive(key, v)?;
    if v > hi {
        return Err(format!("key `{key}`: must be at most {hi:e} {unit} ({why}), got {v:e}"));
    }
    Ok(())
}

/// A modulus in (0, MAX_MODULUS] Pa.
fn modulus(key: &str, v: f64) -> R {
    magnitude(key, v, MAX_MODULUS, "Pa", "stiffer than any geomaterial: the tangent would hold no digits of the load")
}

fn positive_or_inf(key: &str, v: f64) -> R {
    if v > 0.0 && !v.is_nan() {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be positive (or inf), got {v}"))
    }
}

fn in_open(key: &str, v: f64, lo: f64, hi: f64) -> R {
    if v > lo && v < hi {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be in ({lo}, {hi}), got {v}"))
    }
}

fn in_closed_open(key: &str, v: f64, lo: f64, hi: f64) -> R {
    if v >= lo && v < hi {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be in [{lo}, {hi}), got {v}"))
    }
}

fn non_negative(key: &str, v: f64) -> R {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be a non-negative number, got {v}"))
    }
}

fn finite2(key: &str, v: [f64; 2]) -> R {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be finite, got {v:?}"))
    }
}

/// A vector of `dim` finite components (one per direction of the grid).
fn components(key: &str, v: &[f64], dim: usize) -> R {
    if v.len() != dim {
        return Err(format!("key `{key}`: {dim} components in a case of {dim} dimensions, got {}", v.len()));
    }
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be finite, got {v:?}"))
    }
}

fn unique<'a>(what: &str, names: impl Iterator<Item = &'a str>) -> R {
    let mut seen = HashSet::new();
    for n in names {
        if n.is_empty() {
            return Err(format!("{what}: names must not be empty"));
        }
        if !seen.insert(n) {
            return Err(format!("{what}: the name `{n}` is used twice"));
        }
    }
    Ok(())
}

/// Checks every range and reference of the case.
/// The conditions of an axisymmetric case: x is the radius, so the grid starts at r ≥ 0 (the
/// material then lies at r > 0, and nodes on the axis get u_r = 0 from the model's own `axis`
/// boundary, a name no case boundary may take); the verification references that assume plane
/// strain are refused.
/// What the B-spline bases do not combine with (yet): B̄'s volumetric operator is built from the
/// bilinear cell-centre gradients, which see only the bilinear part of the splines' nodal values,
/// so the splines' other modes lose their volumetric stiffness (the tapered plate at ν = 0.3 on
/// 4 m cells came out 9.5 % (quadratic) and 19 % (cubic) softer than converged finite elements,
/// GIMP with B̄ 3 % stiffer; [002]'s F̄ projection is the B-splines' answer to locking); [001]'s
/// mapped stiffnesses and CMPM recovery are built on the linear and GIMP cell functions; the weak
/// drainage of a quasi-static stage's free faces evaluates the grid's bilinear functions at the
/// face.
fn bspline_options(c: &Case) -> R {
    let name = if c.analysis.shape_functions == ShapeFunctions::Bspline2 { "bspline2" } else { "bspline3" };
    if c.stabilisation.bbar {
        return Err(format!(
            "key `stabilisation.bbar`: B̄'s volumetric strain comes from bilinear cell-centre gradients, which \
             leave the B-splines' (`analysis.shape_functions = \"{name}\"`) other modes without volumetric \
             stiffness (too soft); set `bbar = false`"
        ));
    }
    if c.stabilisation.stiffness != Stiffness::Particle {
        return Err(format!(
            "key `stabilisation.stiffness`: [001]'s mapped stiffnesses are defined on the linear and GIMP cell \
             functions; with `analysis.shape_functions = \"{name}\"` use `particle`"
        ));
    }
    if c.stabilisation.stress_recovery == StressRecovery::Cmpm {
        return Err(format!(
            "key `stabilisation.stress_recovery`: CMPM recovers the strain of the linear and GIMP cell functions; \
             with `analysis.shape_functions = \"{name}\"` use `basis`"
        ));
    }
    if let Some(s) = c.stages.iter().find(|s| s.analysis == AnalysisType::QuasiStatic) {
        return Err(format!(
            "key `stages.{}.analysis`: a quasi_static stage drains its free faces weakly with the grid's bilinear \
             functions at the face, which B-splines (`analysis.shape_functions = \"{name}\"`) do not provide yet; \
             use `dynamic` (u–p–U) or a GIMP or linear basis",
            s.name
        ));
    }
    Ok(())
}

/// Where a finite-strain material (`neo_hookean`, `hencky_j2`, `newtonian_fluid`) may be used: in
/// explicit stages only (the implicit stages need its consistent tangent, not built), in plane
/// strain (its kinematics have F_zz = 1), and, for the hyperelastic neo-Hookean and the fluid,
/// without an initial stress (their stress is a function of the deformation and rate alone; a
/// Hencky–J2 point's initial stress is its initial elastic strain).
fn finite_strain_materials(c: &Case) -> R {
    for (i, m) in c.materials.iter().enumerate() {
        let name = match m.model {
            SoilModel::NeoHookean { .. } => "neo_hookean",
            SoilModel::HenckyJ2 { .. } => "hencky_j2",
            SoilModel::NewtonianFluid { .. } => "newtonian_fluid",
            _ => continue,
        };
        if let Some(s) = c.stages.iter().find(|s| s.analysis != AnalysisType::DynamicExplicit) {
            return Err(format!(
                "key `materials[{i}].model`: `{name}` runs in dynamic_explicit stages only (its consistent \
                 tangent for the implicit stages is not built), and stage `{}` is not one",
                s.name
            ));
        }
        if c.analysis.geometry == crate::case::Geometry::Axisymmetric {
            return Err(format!(
                "key `materials[{i}].model`: `{name}` is written for plane strain (F_zz = 1) and the analysis is \
                 axisymmetric"
            ));
        }
        if name == "hencky_j2" {
            continue;
        }
        if let Some(b) =
            c.bodies.iter().find(|b| b.material == m.name && (b.initial_stress.is_some() || b.uniform_stress.is_some()))
        {
            return Err(format!(
                "key `bodies.{}`: a {name} body takes no initial stress (its stress is a function of its \
                 deformation{}; reach a stressed state with a settling stage)",
                b.name,
                if name == "newtonian_fluid" { " and its rate" } else { "" }
            ));
        }
    }
    Ok(())
}

/// What of boundary `i` belongs to three dimensions only (z sides, `uz`/`Uz`, a region's z range, a
/// surface's z faces).
fn dimension_of_boundary(c: &Case, i: usize, dim: usize) -> R {
    let b = &c.boundaries[i];
    let z_side = b.side.is_some_and(|s| s.axis() == 2);
    let z_dof = b.fix.iter().any(|d| matches!(d, Dof::Uz | Dof::WUz));
    let z_region = b.region.is_some_and(|r| r.z.is_some());
    let z_face = b.surface.as_ref().is_some_and(|sf| sf.faces.iter().any(|f| f.axis() == 2));
    let z_surface_region = b.surface.as_ref().and_then(|sf| sf.region).is_some_and(|r| r.z.is_some());
    if dim == 2 {
        for (bad, key) in [
            (z_side, "side"),
            (z_dof, "fix"),
            (z_region, "region.z"),
            (z_face, "surface.faces"),
            (z_surface_region, "surface.region.z"),
        ] {
            if bad {
                return Err(format!(
                    "key `boundaries[{i}].{key}`: z (a `z_min`/`z_max` side or face, `uz`/`Uz`, a region's `z`) \
                     belongs to three-dimensional cases only"
                ));
            }
        }
        return Ok(());
    }
    for (r, key) in [(b.region, "region.z"), (b.surface.as_ref().and_then(|sf| sf.region), "surface.region.z")] {
        if let Some([z0, z1]) = r.and_then(|r| r.z) {
            if !(z0.is_finite() && z1.is_finite() && z0 <= z1) {
                return Err(format!("key `boundaries[{i}].{key}`: needs finite z_min ≤ z_max, got [{z0}, {z1}]"));
            }
        }
    }
    Ok(())
}

/// What a three-dimensional case may not ask for (line pressures, which are plane by nature) or
/// not yet (issue «Three dimensions»: the plane benchmarks' checks, [001]'s CMPM and mapped
/// stiffnesses), and the space of its points' identifiers.
fn three_dimensional(c: &Case) -> R {
    let not_yet = |key: &str| {
        Err(format!(
            "key `{key}`: not available in a three-dimensional case yet (issue «Three dimensions», \
             docs/dimensions.md)"
        ))
    };
    if c.analysis.geometry == Geometry::Axisymmetric {
        return Err("key `analysis.geometry`: a three-dimensional case has no axial symmetry (give two entries \
                    per grid key for an axisymmetric one)"
            .into());
    }
    for (i, l) in c.loads.iter().enumerate() {
        if matches!(l, Load::LinePressure { .. }) {
            return Err(format!(
                "key `loads[{i}].kind = \"line_pressure\"`: a line pressure acts on a plane polyline; a \
                 three-dimensional case loads a surface with a `particle_traction` or a `nodal_traction`"
            ));
        }
    }
    match &c.verification {
        None
        | Some(
            Verification::Terzaghi { .. }
            | Verification::BearingCapacity { .. }
            | Verification::Runout { .. }
            | Verification::Patch { .. },
        ) => {}
        Some(v) => return not_yet(&format!("verification.kind = \"{}\"", v.kind())),
    }
    if c.stabilisation.stress_recovery == crate::case::StressRecovery::Cmpm {
        return Err("key `stabilisation.stress_recovery`: [001]'s CMPM recovery is two-dimensional".into());
    }
    let st = &c.stabilisation;
    if st.stiffness != crate::case::Stiffness::Particle {
        return not_yet("stabilisation.stiffness");
    }
    // A point's identifier numbers its sub-cell below bit 48 (at most 8 points per cell and
    // direction, `Particles::generate`).
    let sub_cells: f64 = c.grid.cells.iter().map(|&n| 8.0 * n as f64).product();
    if sub_cells >= (1u64 << 48) as f64 {
        return Err(format!(
            "key `grid.cells`: {:?} cells are too many to number the material points of (at most 2^48 / 512 cells)",
            c.grid.cells
        ));
    }
    Ok(())
}

/// Whether the grid nodes inside a nodal traction's `region` form what it loads: a line of the
/// plane's grid or a surface of a three-dimensional one (the nodes of a box are a block of the grid;
/// it must be one node thick in exactly one direction, and more than one node wide in the others,
/// or the tributary measures of `model::loads::tributary_nodes` would be zero or counted twice).
fn nodal_layer(c: &Case, region: &crate::case::Region) -> R {
    let dim = c.dimension();
    let counts: Vec<usize> = (0..dim).map(|d| grid_lines_in(c, region, d, 0.0)).collect();
    let what = if dim == 2 { "a line" } else { "a surface" };
    if counts.contains(&0) {
        return Err("holds no grid node".into());
    }
    let thin = counts.iter().filter(|&&n| n == 1).count();
    if thin != 1 {
        return Err(format!(
            "the grid nodes inside it must form {what} of the grid (one node thick in one direction), but it holds \
             {} nodes along x, y{} ({})",
            counts.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", "),
            if dim == 3 { ", z" } else { "" },
            if thin == 0 {
                "a block"
            } else if dim == 3 && thin == 2 {
                "a line"
            } else {
                "a single node"
            }
        ));
    }
    Ok(())
}

/// How many of the grid's lines across direction `d` (its node positions along `d`) lie in the box
/// `region` (with `slack` [m] beyond its tolerance in x and y; along z the region's `z` range, all
/// of it without one).
fn grid_lines_in(c: &Case, region: &crate::case::Region, d: usize, slack: f64) -> usize {
    let (origin, h, cells) = (c.origin_in::<3>(), c.cell_size_in::<3>(), c.cells_in::<3>());
    (0..=cells[d])
        .filter(|&i| {
            let x = origin[d] + i as f64 * h[d];
            if d == 2 {
                region.spans_z(x)
            } else {
                region.spans(d, x, slack)
            }
        })
        .count()
}

fn axisymmetry(c: &Case, tol: f64) -> R {
    if c.analysis.geometry != crate::case::Geometry::Axisymmetric {
        return Ok(());
    }
    if c.origin()[0] < -tol {
        return Err(format!(
            "key `grid.origin`: an axisymmetric analysis has x ≡ r ≥ 0, so the grid must start at x ≥ 0 (got {})",
            c.origin()[0]
        ));
    }
    if let Some(b) = c.boundaries.iter().find(|b| b.name == crate::model::AXIS) {
        return Err(format!(
            "key `boundaries`: the name `{}` is taken by the axis of an axisymmetric analysis (u_r = 0 at r = 0,              added by the program); rename the boundary",
            b.name
        ));
    }
    match &c.verification {
        None
        | Some(Verification::Terzaghi { .. })
        | Some(Verification::ElasticColumn { .. })
        | Some(Verification::HollowCylinder { .. }) => Ok(()),
        Some(v) => Err(format!(
            "key `verification`: the `{}` reference is a plane-strain solution and cannot check an axisymmetric              analysis (the one-dimensional columns `terzaghi` and `elastic_column` and the `hollow_cylinder` can)",
            v.kind()
        )),
    }
}

pub fn validate(c: &Case) -> R {
    let two_phase = c.analysis.formulation == Formulation::TwoPhase;
    positive("analysis.g", c.analysis.g)?;
    if c.analysis.kinematics == KinematicsKind::LinearIncrements {
        if two_phase {
            return Err("key `analysis.kinematics`: `linear_increments` is for a one_phase analysis (the two-phase \
                        pressure and flow terms are written on the configuration at the step's end)"
                .into());
        }
        if let Some(s) =
            c.stages.iter().find(|s| matches!(s.analysis, AnalysisType::Dynamic | AnalysisType::DynamicExplicit))
        {
            return Err(format!(
                "key `analysis.kinematics`: `linear_increments` steps are static (stage `{}` is dynamic)",
                s.name
            ));
        }
    }

    if let Some(alpha) = c.stabilisation.pressure_projection {
        magnitude(
            "stabilisation.pressure_projection",
            alpha,
            MAX_PROJECTION,
            "times 1/G",
            "beyond it the penalty swamps the coupling it stabilises",
        )?;
    }
    if c.stabilisation.pressure_update == PressureUpdate::ProjectedTotal {
        if !two_phase {
            return Err("key `stabilisation.pressure_update`: `projected_total` needs a two-phase case".into());
        }
        if c.stabilisation.patch_recovery == Some(true) {
            return Err(
                "keys `stabilisation.pressure_update = \"projected_total\"` and `stabilisation.patch_recovery = \
                        true` exclude each other: choose one way to update the particles' pressure"
                    .into(),
            );
        }
    }

    if c.stabilisation.mapped_stiffness == MappedStiffnessUse::Diagnostics
        && c.stabilisation.stiffness == crate::case::Stiffness::Particle
    {
        return Err("key `stabilisation.mapped_stiffness`: `diagnostics` computes K_mag with a mapped \
                    `stabilisation.stiffness`, and the case has `particle`"
            .into());
    }
    if c.stabilisation.stiffness == crate::case::Stiffness::DoubleMappingGimp
        && c.analysis.shape_functions == crate::case::ShapeFunctions::Linear
    {
        return Err(
            "key `stabilisation.stiffness`: `double_mapping_gimp` maps with the points' GIMP domains and needs \
                    `analysis.shape_functions = \"gimp\"` or `\"ugimp\"` (a linear basis's stencil does not reach \
                    every cell a domain overlaps)"
                .into(),
        );
    }
    if matches!(c.analysis.shape_functions, ShapeFunctions::Bspline2 | ShapeFunctions::Bspline3) {
        bspline_options(c)?;
    }
    finite_strain_materials(c)?;
    if c.stabilisation.fbar {
        // The implicit stages whose unknowns have no F̄ form (`Layout::with_fbar`: u–p–U).
        if let Some(s) = c.stages.iter().find(|s| {
            s.analysis != AnalysisType::DynamicExplicit
                && crate::analysis::StageAnalysis::of(c, s).layout.jbar.is_none()
        }) {
            return Err(format!(
                "key `stabilisation.fbar`: stage `{}` solves u–p–U, and the F̄ projection is built for the u and \
                 u–p systems of implicit stages and for one-phase explicit stages (one more nodal unknown would \
                 exceed the five a node carries); run it as quasi_static or static, or without F̄",
                s.name
            ));
        }
        if c.analysis.kinematics == KinematicsKind::LinearIncrements {
            return Err("key `stabilisation.fbar`: F̄ scales the finite-strain increment, and \
                        `analysis.kinematics = \"linear_increments\"` has none; use B̄ for small strains"
                .into());
        }
        if c.stabilisation.stiffness != Stiffness::Particle
            || c.stabilisation.stress_recovery == crate::case::StressRecovery::Cmpm
        {
            return Err("key `stabilisation.fbar`: F̄ is built with the particle-integrated tangent and the \
                        basis's own strain; [001]'s stiffness options and CMPM recovery are for cases without it"
                .into());
        }
        if c.stabilisation.bbar {
            return Err("keys `stabilisation.fbar` and `stabilisation.bbar` exclude each other: both replace the \
                        volumetric deformation"
                .into());
        }
        if c.analysis.geometry == Geometry::Axisymmetric {
            return Err("key `stabilisation.fbar`: plane strain only for now (axial symmetry scales three axes)".into());
        }
    }
    if c.stabilisation.stress_recovery == crate::case::StressRecovery::Cmpm {
        if two_phase {
            return Err("key `stabilisation.stress_recovery`: `cmpm` is for one_phase analyses ([001] is one-phase; \
                        in the coupled systems the continuity equation's divergence would no longer be the \
                        transpose of the pressure's force)"
                .into());
        }
        if c.stabilisation.bbar {
            return Err(
                "keys `stabilisation.stress_recovery = \"cmpm\"` and `stabilisation.bbar = true` exclude each \
                        other: the CMPM patch recovers the whole strain, B̄ would replace its volumetric part"
                    .into(),
            );
        }
    }
    if c.stabilisation.internal_force == InternalForce::Mapped {
        if !matches!(
            c.stabilisation.stiffness,
            Stiffness::GaussMapping | Stiffness::DoubleMapping | Stiffness::DoubleMappingGimp
        ) {
            return Err(format!(
                "key `stabilisation.internal_force`: `mapped` maps the points' stresses with the weights of a                  mapped stiffness, and `stabilisation.stiffness` is `{}`; choose `gauss_mapping`,                  `double_mapping` or `double_mapping_gimp`",
                c.stabilisation.stiffness.name()
            ));
        }
        if two_phase {
            return Err("key `stabilisation.internal_force`: `mapped` is for one_phase analyses ([001] is \
                        one-phase; the pore pressure's forces and the continuity equation keep the basis)"
                .into());
        }
    } else if c.stabilisation.stress_recovery == StressRecovery::Mapped {
        return Err("key `stabilisation.stress_recovery`: `mapped` recovers the strain with the double-mapped \
                    force operators; set `stabilisation.internal_force = \"mapped\"` too"
            .into());
    }

    // Grid.
    let dim = c.grid.size.len();
    if dim != 2 && dim != 3 {
        return Err(format!(
            "key `grid.size`: two entries (a plane or axisymmetric case) or three (a three-dimensional one), got {dim}"
        ));
    }
    for (key, n) in [("origin", c.grid.origin.len()), ("cells", c.grid.cells.len())] {
        if n != dim && !(key == "origin" && n == 0) {
            return Err(format!("key `grid.{key}`: {dim} entries, as `grid.size` has, got {n}"));
        }
    }
    finite2("grid.origin", c.origin())?;
    for d in 0..dim {
        positive(&format!("grid.size[{d}]"), c.grid.size[d])?;
        if c.grid.cells[d] == 0 || c.grid.cells[d] > 100_000 {
            return Err(format!("key `grid.cells[{d}]`: must be between 1 and 100000, got {}", c.grid.cells[d]));
        }
    }
    if dim == 3 {
        three_dimensional(c)?;
    }
    // The grid's bounds (beyond the case's dimension unused), and whether a point with a
    // coordinate per direction (a plane section's two, or a case's D) lies within them.
    let lo = c.origin_in::<3>();
    let h = c.cell_size_in::<3>();
    let hi: [f64; 3] = std::array::from_fn(|d| lo[d] + c.grid.size.get(d).copied().unwrap_or(1.0));
    let tol = h.map(|h| 1e-9 * h);
    let inside_grid = |p: &[f64]| p.iter().enumerate().all(|(d, &x)| x >= lo[d] - tol[d] && x <= hi[d] + tol[d]);
    axisymmetry(c, tol[0])?;

    // Materials.
    if c.materials.is_empty() {
        return Err("at least one [[materials]] table is needed".into());
    }
    unique("materials", c.materials.iter().map(|m| m.name.as_str()))?;
    for (i, m) in c.materials.iter().enumerate() {
        let k = |f: &str| format!("materials[{i}].{f}");
        // A one-phase material may have no pores (a fluid, a solid): its density is the mixture's.
        if two_phase {
            in_open(&k("porosity"), m.porosity, 0.0, 1.0)?;
        } else {
            in_closed_open(&k("porosity"), m.porosity, 0.0, 1.0)?;
        }
        for (f, v) in [("solid_density", m.solid_density), ("water_density", m.water_density)] {
            magnitude(&k(f), v, MAX_DENSITY, "kg/m³", "denser than any material")?;
        }
        soil_model(&k("model"), &m.model)?;
        if two_phase {
            for (f, v) in
                [("water_bulk_modulus", m.water_bulk_modulus), ("hydraulic_conductivity", m.hydraulic_conductivity)]
            {
                match v {
                    Some(v) if f == "water_bulk_modulus" => modulus(&k(f), v)?,
                    Some(v) => magnitude(&k(f), v, MAX_CONDUCTIVITY, "m/s", "more permeable than open gravel")?,
                    None => return Err(format!("key `{}`: required in a two_phase analysis", k(f))),
                }
            }
            match m.solid_bulk_modulus {
                Some(v) if v.is_infinite() => positive_or_inf(&k("solid_bulk_modulus"), v)?,
                Some(v) => modulus(&k("solid_bulk_modulus"), v)?,
                None => {
                    return Err(format!(
                        "key `{}`: required in a two_phase analysis (inf for incompressible grains)",
                        k("solid_bulk_modulus")
                    ))
                }
            }
        }
    }

    // Bodies.
    if c.bodies.is_empty() {
        return Err("at least one [[bodies]] table is needed".into());
    }
    unique("bodies", c.bodies.iter().map(|b| b.name.as_str()))?;
    for (i, b) in c.bodies.iter().enumerate() {
        if c.material(&b.material).is_none() {
            return Err(format!("key `bodies[{i}].material`: no material named `{}`", b.material));
        }
        if b.particles_per_cell == 0 || b.particles_per_cell > 8 {
            return Err(format!(
                "key `bodies[{i}].particles_per_cell`: must be between 1 and 8, got {}",
                b.particles_per_cell
            ));
        }
        match &b.shape {
            Shape::Rectangle { min, max } => {
                finite2(&format!("bodies[{i}].shape.rectangle.min"), *min)?;
                finite2(&format!("bodies[{i}].shape.rectangle.max"), *max)?;
                if !(max[0] > min[0] && max[1] > min[1]) {
                    return Err(format!(
                        "key `bodies[{i}].shape.rectangle`: max must exceed min in x and y, got {min:?} .. {max:?}"
                    ));
                }
            }
            Shape::Polygon { vertices } => {
                if vertices.len() < 3 {
                    return Err(format!(
                        "key `bodies[{i}].shape.polygon.vertices`: a polygon needs at least 3 vertices"
                    ));
                }
                for (j, v) in vertices.iter().enumerate() {
                    finite2(&format!("bodies[{i}].shape.polygon.vertices[{j}]"), *v)?;
                }
            }
        }
        if !(0.0..0.5).contains(&b.perturbation) {
            return Err(format!("key `bodies[{i}].perturbation`: must be in [0, 0.5), got {}", b.perturbation));
        }
        if let Some(s) = &b.uniform_stress {
            if b.initial_stress.is_some() {
                return Err(format!("key `bodies[{i}]`: give `initial_stress` or `uniform_stress`, not both"));
            }
            if !(s.len() == 4 || (dim == 3 && s.len() == 6)) {
                return Err(format!(
                    "key `bodies[{i}].uniform_stress`: four entries [xx, yy, xy, zz]{}, got {}",
                    if dim == 3 { " or six [xx, yy, xy, zz, yz, zx]" } else { " in a plane case" },
                    s.len()
                ));
            }
            if s.iter().any(|v| !v.is_finite()) {
                return Err(format!("key `bodies[{i}].uniform_stress`: must be finite"));
            }
        }
        if let Some(init) = &b.initial_stress {
            positive(&format!("bodies[{i}].initial_stress.k0"), init.k0)?;
            if let crate::case::WaterTable::Level(y) = init.water_table {
                if !y.is_finite() {
                    return Err(format!("key `bodies[{i}].initial_stress.water_table`: must be finite"));
                }
            }
        }
        match (dim, b.z) {
            (2, Some(_)) => {
                return Err(format!(
                    "key `bodies[{i}].z`: only a three-dimensional case (three entries in `grid.size`) takes a \
                     body's extent along z"
                ))
            }
            (3, Some([z0, z1])) => {
                let (g0, g1) = (c.grid.origin.get(2).copied().unwrap_or(0.0), c.grid.size[2]);
                let tol = 1e-9 * g1 / c.grid.cells[2] as f64;
                if !(z0.is_finite() && z1.is_finite() && z0 < z1 && z0 >= g0 - tol && z1 <= g0 + g1 + tol) {
                    return Err(format!(
                        "key `bodies[{i}].z`: body `{}` needs z_min < z_max inside the grid's [{g0}, {}], got \
                         [{z0}, {z1}]",
                        b.name,
                        g0 + g1
                    ));
                }
            }
            _ => {}
        }
        let (bmin, bmax) = b.shape.bounds();
        if !inside_grid(&bmin) || !inside_grid(&bmax) {
            return Err(format!(
                "key `bodies[{i}].shape`: body `{}` ({bmin:?} .. {bmax:?}) reaches outside the grid ({:?} .. {:?}); particles outside the grid are not allowed",
                b.name,
                &lo[..2],
                &hi[..2]
            ));
        }
    }

    // Time functions.
    unique("time_functions", c.time_functions.iter().map(|f| f.name()))?;
    for (i, f) in c.time_functions.iter().enumerate() {
        let k = |x: &str| format!("time_functions[{i}].{x}");
        match f {
            TimeFunction::Constant { value, .. } => {
                if !value.is_finite() {
                    return Err(format!("key `{}`: must be finite", k("value")));
                }
            }
            TimeFunction::Ramp { start, duration, .. } | TimeFunction::SmoothRamp { start, duration, .. } => {
                positive(&k("duration"), *duration)?;
                if !start.is_finite() || *start < 0.0 {
                    return Err(format!("key `{}`: must be ≥ 0, got {start}", k("start")));
                }
            }
            TimeFunction::Harmonic { angular_frequency, phase, ramp_duration, .. } => {
                positive(&k("angular_frequency"), *angular_frequency)?;
                if !phase.is_finite() {
                    return Err(format!("key `{}`: must be finite", k("phase")));
                }
                if !ramp_duration.is_finite() || *ramp_duration < 0.0 {
                    return Err(format!("key `{}`: must be ≥ 0, got {ramp_duration}", k("ramp_duration")));
                }
            }
            TimeFunction::Table { times, values, .. } => {
                if times.is_empty() || times.len() != values.len() {
                    return Err(format!(
                        "key `{}`: times and values must be non-empty and of equal length",
                        k("times")
                    ));
                }
                if times.windows(2).any(|w| w[1] <= w[0]) || times.iter().chain(values).any(|v| !v.is_finite()) {
                    return Err(format!("key `{}`: times must be finite and strictly increasing", k("times")));
                }
            }
        }
    }

    // Boundaries.
    unique("boundaries", c.boundaries.iter().map(|b| b.name.as_str()))?;
    for (i, b) in c.boundaries.iter().enumerate() {
        if [b.side.is_some(), b.region.is_some(), b.surface.is_some()].iter().filter(|&&x| x).count() != 1 {
            return Err(format!("key `boundaries[{i}]`: give exactly one of `side`, `region` and `surface`"));
        }
        if let Some(sf) = &b.surface {
            if c.body(&sf.body).is_none() {
                return Err(format!("key `boundaries[{i}].surface.body`: no body named `{}`", sf.body));
            }
            if sf.faces.is_empty() {
                return Err(format!("key `boundaries[{i}].surface.faces`: list at least one face"));
            }
        }
        if b.fix.is_empty() {
            return Err(format!("key `boundaries[{i}].fix`: list at least one component"));
        }
        dimension_of_boundary(c, i, dim)?;
        if let Some(r) = &b.region {
            // A region between grid lines fixes nothing: the body it was meant to hold would move
            // freely (a clamp at x = 0 on a grid whose lines miss x = 0). A box holds a node if
            // some grid line of each direction crosses it (`Region::holds_node`, one axis at a time).
            let crossed = |d: usize| grid_lines_in(c, r, d, 1e-9 * h[d]) > 0;
            if !(crossed(0) && crossed(1)) {
                return Err(format!(
                    "key `boundaries[{i}].region`: holds no grid node (the grid lines lie at x = {} + i·{}, \
                     y = {} + j·{} m); move the region onto them or change the grid",
                    lo[0], h[0], lo[1], h[1]
                ));
            }
        }
        if b.displacement.is_some() && b.velocity.is_some() {
            return Err(format!("key `boundaries[{i}]`: give `displacement` or `velocity`, not both"));
        }
        if let Some(l) = &b.velocity_gradient {
            if b.displacement.is_some() {
                return Err(format!(
                    "key `boundaries[{i}].velocity_gradient`: goes with `velocity`, not `displacement`"
                ));
            }
            if l.len() != dim || l.iter().any(|row| row.len() != dim) {
                return Err(format!(
                    "key `boundaries[{i}].velocity_gradient`: {dim} rows of {dim} entries (∂v_i/∂x_j) in a case of \
                     {dim} dimensions, got {:?}",
                    l.iter().map(Vec::len).collect::<Vec<_>>()
                ));
            }
            if l.iter().flatten().any(|v| !v.is_finite()) {
                return Err(format!("key `boundaries[{i}].velocity_gradient`: must be finite"));
            }
            let moved = [Dof::Ux, Dof::Uy, Dof::Uz];
            if !moved[..dim].iter().all(|d| b.fix.contains(d)) {
                return Err(format!(
                    "key `boundaries[{i}].velocity_gradient`: moves every displacement component, so `fix` must \
                     list {}",
                    moved[..dim].iter().map(|d| format!("`{d}`")).collect::<Vec<_>>().join(", ")
                ));
            }
        }
        if let Some(cn) = &b.center {
            if b.velocity_gradient.is_none() {
                return Err(format!("key `boundaries[{i}].center`: is the centre of a `velocity_gradient`, not given"));
            }
            if cn.len() != dim || cn.iter().any(|v| !v.is_finite()) {
                return Err(format!(
                    "key `boundaries[{i}].center`: {dim} finite coordinates in a case of {dim} dimensions, got {cn:?}"
                ));
            }
        }
        let motion =
            b.displacement.clone().or(b.velocity.clone()).or(b.velocity_gradient.as_ref().map(|_| vec![0.0; dim]));
        if let Some(m) = &motion {
            let key = if b.displacement.is_some() { "displacement" } else { "velocity" };
            if m.len() != dim {
                return Err(format!(
                    "key `boundaries[{i}].{key}`: {dim} components in a case of {dim} dimensions, got {}",
                    m.len()
                ));
            }
            if m.iter().any(|v| !v.is_finite()) {
                return Err(format!("key `boundaries[{i}].{key}`: must be finite"));
            }
            for (c, dof) in [(0, Dof::Ux), (1, Dof::Uy), (2, Dof::Uz)].into_iter().take(dim) {
                if m[c] != 0.0 && !b.fix.contains(&dof) {
                    return Err(format!(
                        "key `boundaries[{i}].{key}`: component {c} moves `{dof}`, which `fix` does not list"
                    ));
                }
            }
        }
        if let Some(tf) = &b.time_function {
            if motion.is_none() {
                return Err(format!(
                    "key `boundaries[{i}].time_function`: only a `displacement` or `velocity` has a time function"
                ));
            }
            if c.time_function(tf).is_none() {
                return Err(format!("key `boundaries[{i}].time_function`: no time function named `{tf}`"));
            }
        }
        // In a one_phase analysis the water-phase components (p, Ux, Uy) have no dofs and are
        // ignored, so that one case file can switch formulation with `--set analysis.formulation`.
    }

    // Loads.
    unique("loads", c.loads.iter().map(|l| l.name()))?;
    for (i, l) in c.loads.iter().enumerate() {
        if let Some(tf) = l.time_function() {
            if c.time_function(tf).is_none() {
                return Err(format!("key `loads[{i}].time_function`: no time function named `{tf}`"));
            }
        }
        match l {
            Load::ParticleTraction { region, traction, .. } | Load::NodalTraction { region, traction, .. } => {
                components(&format!("loads[{i}].traction"), traction, c.dimension())?;
                finite2(&format!("loads[{i}].region.min"), region.min)?;
                finite2(&format!("loads[{i}].region.max"), region.max)?;
                if region.max[0] < region.min[0] || region.max[1] < region.min[1] {
                    return Err(format!("key `loads[{i}].region`: max must not be below min"));
                }
                if matches!(l, Load::NodalTraction { .. }) {
                    nodal_layer(c, region).map_err(|m| format!("key `loads[{i}].region`: {m}"))?;
                }
                if let Some(e) = l.increment_factor() {
                    // Tried where the loaded faces start: the region's centre (its z range's, or
                    // the grid's, in three dimensions).
                    let mut centre = vec![0.5 * (region.min[0] + region.max[0]), 0.5 * (region.min[1] + region.max[1])];
                    if c.dimension() == 3 {
                        let z0 = c.origin_in::<3>()[2];
                        let [lo, hi] = region.z.unwrap_or([z0, z0 + c.grid.size[2]]);
                        centre.push(0.5 * (lo + hi));
                    }
                    crate::model::loads::increment_factor(e, &c.parameters, &centre)
                        .map_err(|m| format!("key `loads[{i}].increment_factor`: `{e}` at {centre:?}: {m}"))?;
                }
            }
            Load::BodyForce { acceleration, .. } => {
                components(&format!("loads[{i}].acceleration"), acceleration, c.dimension())?
            }
            Load::LinePressure { points, pressure, .. } => {
                if points.len() < 2 {
                    return Err(format!("key `loads[{i}].points`: a line needs at least two points"));
                }
                for (j, p) in points.iter().enumerate() {
                    finite2(&format!("loads[{i}].points[{j}]"), *p)?;
                    if !inside_grid(p) {
                        return Err(format!("key `loads[{i}].points[{j}]`: {p:?} is outside the grid"));
                    }
                }
                if !pressure.is_finite() {
                    return Err(format!("key `loads[{i}].pressure`: must be finite"));
                }
            }
        }
        let bodies: Vec<&String> = match l {
            Load::ParticleTraction { body: Some(b), .. } => vec![b],
            Load::BodyForce { bodies: Some(bs), .. } => bs.iter().collect(),
            _ => Vec::new(),
        };
        for b in bodies {
            if c.body(b).is_none() {
                return Err(format!("key `loads[{i}]`: no body named `{b}`"));
            }
        }
    }

    // Stages.
    if c.stages.is_empty() {
        return Err("at least one [[stages]] table is needed".into());
    }
    for (i, s) in c.stages.iter().enumerate() {
        let k = |x: &str| format!("stages[{i}].{x}");
        positive(&k("duration"), s.duration)?;
        positive(&k("dt"), s.dt())?;
        if s.dt() > s.duration * (1.0 + 1e-12) {
            return Err(format!("key `{}`: Δt = {} exceeds the stage duration {}", k("dt"), s.dt(), s.duration));
        }
        if s.duration / s.dt() > 1e8 {
            return Err(format!("key `{}`: more than 1e8 steps in the stage", k("dt")));
        }
        in_open(&k("cut_factor"), s.cut_factor, 0.0, 1.0)?;
        if s.max_step_cuts > 30 {
            return Err(format!("key `{}`: at most 30, got {}", k("max_step_cuts"), s.max_step_cuts));
        }
        for n in s.boundaries.iter().flatten() {
            if !c.boundaries.iter().any(|b| &b.name == n) {
                return Err(format!("key `{}`: no boundary named `{n}`", k("boundaries")));
            }
        }
        for n in s.loads.iter().flatten() {
            if c.load(n).is_none() {
                return Err(format!("key `{}`: no load named `{n}`", k("loads")));
            }
        }
    }

    // Newmark: unconditional stability of the average-acceleration family needs 2β ≥ γ ≥ 1/2.
    let newmarks = std::iter::once(("time_integration".to_string(), &c.time_integration)).chain(
        c.stages
            .iter()
            .filter_map(|s| s.time_integration.as_ref().map(|t| (format!("stages.{}.time_integration", s.name), t))),
    );
    for (key, ti) in newmarks {
        let (beta, gamma) = ti.newmark();
        if let Some(r) = ti.rho_inf {
            if !(0.0..=1.0).contains(&r) {
                return Err(format!("key `{key}.rho_inf`: ρ∞ = {r} must lie in [0, 1]"));
            }
            if ti.is_newmark() {
                return Err(format!(
                    "key `{key}`: give either `rho_inf` (generalized-α, which sets β and γ) or `beta`/`gamma` (Newmark), not both"
                ));
            }
        }
        if ti.scheme == Some(super::TimeScheme::GeneralizedAlpha) && (ti.beta.is_some() || ti.gamma.is_some()) {
            return Err(format!("key `{key}`: the generalized-α method takes `rho_inf`, not `beta`/`gamma`"));
        }
        if !ti.is_newmark() {
            continue;
        }
        if !(gamma >= 0.5 && 2.0 * beta >= gamma && beta <= 1.0) {
            return Err(format!(
                "key `{key}`: β = {beta}, γ = {gamma} is not unconditionally stable; use 2β ≥ γ ≥ 1/2 (default β = 1/4, γ = 1/2)"
            ));
        }
    }
    // Analysis types.
    for s in &c.stages {
        let key = |k: &str| format!("stages.{}.{k}", s.name);
        let two_phase = c.analysis.formulation == super::Formulation::TwoPhase;
        match s.analysis {
            super::AnalysisType::QuasiStatic if !two_phase => {
                return Err(format!(
                    "key `{}`: a quasi_static stage solves the water's flow and needs `analysis.formulation = \"two_phase\"`; use `static` for a one-phase case",
                    key("analysis")
                ))
            }
            super::AnalysisType::Static if two_phase && s.drainage.is_none() => {
                return Err(format!(
                    "key `{}`: a static stage of a two-phase case needs `drainage = \"drained\"` (the pore pressure is held) or `\"undrained\"` (no flow)",
                    key("drainage")
                ))
            }
            _ => {}
        }
        if s.drainage.is_some() && !(s.analysis == super::AnalysisType::Static && two_phase) {
            return Err(format!("key `{}`: only a static stage of a two-phase case takes `drainage`", key("drainage")));
        }
        if let Some(th) = s.theta {
            if s.analysis != super::AnalysisType::QuasiStatic {
                return Err(format!("key `{}`: only a quasi_static stage takes `theta`", key("theta")));
            }
            if !(0.5..=1.0).contains(&th) {
                return Err(format!("key `{}`: θ = {th} must lie in [1/2, 1] (1: backward Euler)", key("theta")));
            }
        }
        if s.analysis == super::AnalysisType::DynamicExplicit {
            let e = s.explicit.unwrap_or_default();
            if two_phase {
                explicit_two_phase(c, s, &e)?;
            } else if e.pore_pressure.is_some() {
                return Err(format!(
                    "key `{}`: a one-phase stage has no pore pressure; leave `pore_pressure` out",
                    key("explicit.pore_pressure")
                ));
            }
            if !(e.cfl > 0.0 && e.cfl <= 1.0) {
                return Err(format!(
                    "key `{}`: C = {} must lie in (0, 1] (the explicit step's stability limit is C = 1)",
                    key("explicit.cfl"),
                    e.cfl
                ));
            }
            if !(0.0..=1.0).contains(&e.flip_blend) {
                return Err(format!("key `{}`: η = {} must lie in [0, 1]", key("explicit.flip_blend"), e.flip_blend));
            }
            if let Some(m) = e.xpic_order {
                if !(1..=8).contains(&m) {
                    return Err(format!("key `{}`: m = {m} must lie in [1, 8]", key("explicit.xpic_order")));
                }
                if e.flip_blend != 1.0 {
                    return Err(format!(
                        "key `{}`: XPIC (`xpic_order`) replaces the FLIP/PIC blend; leave flip_blend out",
                        key("explicit.flip_blend")
                    ));
                }
            }
            if !(0.0..1.0).contains(&e.local_damping) {
                return Err(format!(
                    "key `{}`: α = {} must lie in [0, 1)",
                    key("explicit.local_damping"),
                    e.local_damping
                ));
            }
        } else if s.explicit.is_some() {
            return Err(format!("key `{}`: only a dynamic_explicit stage takes `explicit`", key("explicit")));
        }
        if let Some(f) = s.strength_reduction {
            if !(f > 0.0 && f <= 100.0) {
                return Err(format!(
                    "key `{}`: the strength reduction factor F = {f} must lie in (0, 100] (the strengths are \
                     divided by F)",
                    key("strength_reduction")
                ));
            }
        }
        if s.time_integration.is_some() && s.analysis != super::AnalysisType::Dynamic {
            return Err(format!("key `{}`: only a dynamic stage takes `time_integration`", key("time_integration")));
        }
        if let Some(m) = s.dt_max {
            if !(m.is_finite() && m >= s.dt()) {
                return Err(format!(
                    "key `{}`: {m} s must be finite and at least the stage's Δt = {} s",
                    key("dt_max"),
                    s.dt()
                ));
            }
        }
    }
    if c.output.history_every == 0 {
        return Err("key `output.history_every`: must be at least 1".into());
    }

    // Probes.
    unique("probes", c.probes.iter().map(|p| p.name.as_str()))?;
    for (i, p) in c.probes.iter().enumerate() {
        components(&format!("probes[{i}].point"), &p.point, dim)?;
        if !inside_grid(&p.point) {
            return Err(format!("key `probes[{i}].point`: {:?} is outside the grid", p.point));
        }
    }

    // Verification references.
    if let Some(v) = &c.verification {
        let (body, load) = match v {
            Verification::Lame {
                body,
                load,
                center,
                inner_radius,
                outer_radius,
                displacement_tolerance,
                stress_tolerance,
            } => {
                finite2("verification.center", *center)?;
                positive("verification.inner_radius", *inner_radius)?;
                positive("verification.outer_radius", *outer_radius)?;
                if outer_radius <= inner_radius {
                    return Err("key `verification.outer_radius`: must exceed `inner_radius`".into());
                }
                positive("verification.displacement_tolerance", *displacement_tolerance)?;
                positive("verification.stress_tolerance", *stress_tolerance)?;
                if !matches!(c.load(load), Some(Load::LinePressure { .. })) {
                    return Err(format!("key `verification.load`: `{load}` must be a line_pressure load"));
                }
                if let Some(b) = c.body(body) {
                    let mat = &c.materials[c.material_index(&b.material).expect("validated")];
                    if !matches!(mat.model, SoilModel::LinearElastic { .. }) {
                        return Err(format!("key `verification.body`: the Lamé reference needs a linear elastic body, and `{body}` is not"));
                    }
                }
                if two_phase {
                    return Err("key `verification`: the Lamé reference is for a one_phase analysis".into());
                }
                (body, load)
            }
            Verification::HollowCylinder {
                body,
                load,
                inner_radius,
                outer_radius,
                displacement_tolerance,
                stress_tolerance,
                increments,
            } => {
                positive("verification.inner_radius", *inner_radius)?;
                if outer_radius <= inner_radius {
                    return Err("key `verification.outer_radius`: must exceed `inner_radius`".into());
                }
                positive("verification.displacement_tolerance", *displacement_tolerance)?;
                positive("verification.stress_tolerance", *stress_tolerance)?;
                if let Some(t) = increments {
                    positive("verification.increments.q", t.q)?;
                    positive("verification.increments.mean_stress", t.mean_stress)?;
                    positive("verification.increments.radius", t.radius)?;
                }
                if !matches!(c.load(load), Some(Load::NodalTraction { .. } | Load::ParticleTraction { .. })) {
                    return Err(format!(
                        "key `verification.load`: `{load}` must be a nodal_traction or particle_traction load"
                    ));
                }
                if let Some(b) = c.body(body) {
                    let mat = &c.materials[c.material_index(&b.material).expect("validated")];
                    if !matches!(mat.model, SoilModel::LinearElastic { .. }) {
                        return Err(format!("key `verification.body`: the hollow cylinder's reference needs a linear elastic body, and `{body}` is not"));
                    }
                }
                if two_phase {
                    return Err(
                        "key `verification`: the hollow cylinder's reference is for a one_phase analysis".into()
                    );
                }
                if c.analysis.geometry != crate::case::Geometry::Axisymmetric {
                    return Err("key `verification`: the hollow cylinder's reference needs `analysis.geometry = \"axisymmetric\"`".into());
                }
                (body, load)
            }
            Verification::VerticalCut { body, toe, b, c: cpoint, stop_displacement, snapshots } => {
                for (k, v) in [("toe", toe), ("b", b), ("c", cpoint)] {
                    finite2(&format!("verification.{k}"), *v)?;
                }
                positive("verification.stop_displacement", *stop_displacement)?;
                for (j, s) in snapshots.iter().enumerate() {
                    positive(&format!("verification.snapshots[{j}]"), *s)?;
                }
                let Some(bd) = c.body(body) else {
                    return Err(format!("key `verification.body`: no body named `{body}`"));
                };
                let mat = &c.materials[c.material_index(&bd.material).expect("validated")];
                if !matches!(mat.model, SoilModel::VonMises { .. }) {
                    return Err(format!(
                        "key `verification.body`: the vertical cut's checks need a von_mises body, and `{body}` is not"
                    ));
                }
                return Ok(());
            }
            Verification::CookMembrane { body, tip, reference, tolerance, fit_radius } => {
                finite2("verification.tip", *tip)?;
                positive("verification.reference", *reference)?;
                if !(*tolerance > 0.0 && *tolerance < 1.0) {
                    return Err(format!("key `verification.tolerance`: must be in (0, 1), got {tolerance}"));
                }
                if !(1.0..=10.0).contains(fit_radius) {
                    return Err(format!("key `verification.fit_radius`: must be in [1, 10] cells, got {fit_radius}"));
                }
                if c.body(body).is_none() {
                    return Err(format!("key `verification.body`: no body named `{body}`"));
                }
                if two_phase {
                    return Err("key `verification`: Cook's membrane is for a one_phase analysis".into());
                }
                return Ok(());
            }
            Verification::Runout {
                body,
                trigger_stage,
                standing_advance,
                standing_speed,
                snapshot_times,
                failed_strain,
                spray_fraction,
            } => {
                positive("verification.standing_advance", *standing_advance)?;
                positive("verification.standing_speed", *standing_speed)?;
                positive("verification.failed_strain", *failed_strain)?;
                if !(0.0..=0.05).contains(spray_fraction) {
                    return Err(format!(
                        "key `verification.spray_fraction`: must be in [0, 0.05], got {spray_fraction}"
                    ));
                }
                if c.body(body).is_none() {
                    return Err(format!("key `verification.body`: no body named `{body}`"));
                }
                let Some(s) = c.stages.iter().position(|s| &s.name == trigger_stage) else {
                    return Err(format!("key `verification.trigger_stage`: no stage named `{trigger_stage}`"));
                };
                let after: f64 = c.stages[s..].iter().map(|s| s.duration).sum();
                if let Some(t) = snapshot_times.iter().find(|&&t| !(t > 0.0 && t <= after * (1.0 + 1e-12))) {
                    return Err(format!(
                        "key `verification.snapshot_times`: {t} s is not within the {after} s after the trigger"
                    ));
                }
                if two_phase {
                    return Err("key `verification`: the run-out check is for a one_phase analysis".into());
                }
                return Ok(());
            }
            Verification::DamBreak {
                body,
                gravity,
                settle_stage,
                hydrostatic_tolerance,
                far_wall,
                experiment,
                front_tolerance,
                spray_fraction,
            } => {
                positive("verification.hydrostatic_tolerance", *hydrostatic_tolerance)?;
                if !(0.0..=0.05).contains(spray_fraction) {
                    return Err(format!(
                        "key `verification.spray_fraction`: must be in [0, 0.05], got {spray_fraction}"
                    ));
                }
                positive("verification.front_tolerance", *front_tolerance)?;
                if let Some(x) = far_wall {
                    finite2("verification.far_wall", [*x, 0.0])?;
                }
                let Some(bd) = c.body(body) else {
                    return Err(format!("key `verification.body`: no body named `{body}`"));
                };
                if !matches!(bd.shape, crate::case::Shape::Rectangle { .. }) {
                    return Err(format!(
                        "key `verification.body`: the dam break's column `{body}` must be a rectangle"
                    ));
                }
                if !matches!(c.load(gravity), Some(Load::BodyForce { .. })) {
                    return Err(format!("key `verification.gravity`: `{gravity}` must be a body_force load"));
                }
                let Some(s) = c.stages.iter().position(|s| &s.name == settle_stage) else {
                    return Err(format!("key `verification.settle_stage`: no stage named `{settle_stage}`"));
                };
                if s + 1 == c.stages.len() {
                    return Err(format!(
                        "key `verification.settle_stage`: `{settle_stage}` is the last stage, so the water never flows"
                    ));
                }
                if let Some(e) = experiment {
                    if e != "martin_moyce_1952" {
                        return Err(format!(
                            "key `verification.experiment`: unknown experiment `{e}` (known: martin_moyce_1952)"
                        ));
                    }
                }
                if two_phase {
                    return Err("key `verification`: the dam break is for a one_phase analysis".into());
                }
                return Ok(());
            }
            Verification::StiffnessMap { body, center, radius, tolerance } => {
                finite2("verification.center", *center)?;
                positive("verification.radius", *radius)?;
                positive("verification.tolerance", *tolerance)?;
                if let Some(b) = c.body(body) {
                    let mat = &c.materials[c.material_index(&b.material).expect("validated")];
                    if !matches!(mat.model, SoilModel::LinearElastic { .. }) {
                        return Err(format!("key `verification.body`: the stiffness map's reference needs a linear elastic body, and `{body}` is not"));
                    }
                }
                let h = c.cell_size();
                if (h[0] - h[1]).abs() > 1e-9 * h[0] {
                    return Err(format!(
                        "key `grid`: the stiffness map's reference is for square cells, got {} × {} m",
                        h[0], h[1]
                    ));
                }
                if c.body(body).is_none() {
                    return Err(format!("key `verification.body`: no body named `{body}`"));
                }
                if c.analysis.geometry != crate::case::Geometry::PlaneStrain {
                    return Err("key `verification`: the stiffness map's reference is for plane strain".into());
                }
                return Ok(());
            }
            Verification::Patch { body, boundary, spread_tolerance, tolerance } => {
                positive("verification.spread_tolerance", *spread_tolerance)?;
                positive("verification.tolerance", *tolerance)?;
                let Some(b) = c.body(body) else {
                    return Err(format!("key `verification.body`: no body named `{body}`"));
                };
                let mat = &c.materials[c.material_index(&b.material).expect("validated")];
                if !matches!(mat.model, SoilModel::LinearElastic { .. } | SoilModel::NeoHookean { .. }) {
                    return Err(format!(
                        "key `verification.body`: the patch reference needs a linear elastic or neo-Hookean body, and \
                         `{body}` is neither"
                    ));
                }
                match c.boundaries.iter().find(|x| &x.name == boundary) {
                    Some(x) if x.velocity_gradient.is_some() => {}
                    Some(_) => {
                        return Err(format!("key `verification.boundary`: `{boundary}` has no `velocity_gradient`"))
                    }
                    None => return Err(format!("key `verification.boundary`: no boundary named `{boundary}`")),
                }
                if two_phase {
                    return Err("key `verification`: the patch reference is for a one_phase analysis".into());
                }
                return Ok(());
            }
            Verification::Terzaghi {
                body,
                load,
                time_factors,
                e_p_tolerance,
                p_rms_tolerance,
                settlement_tolerance,
            } => {
                if time_factors.is_empty() || time_factors.iter().any(|t| !(*t > 0.0 && t.is_finite())) {
                    return Err("key `verification.time_factors`: give positive time factors".into());
                }
                for (k, t) in [
                    ("e_p_tolerance", e_p_tolerance),
                    ("p_rms_tolerance", p_rms_tolerance),
                    ("settlement_tolerance", settlement_tolerance),
                ] {
                    positive(&format!("verification.{k}"), *t)?;
                }
                (body, load)
            }
            Verification::HarmonicColumn { body, load, measure_periods, tolerance } => {
                positive("verification.tolerance", *tolerance)?;
                if *measure_periods == 0 {
                    return Err("key `verification.measure_periods`: must be at least 1".into());
                }
                (body, load)
            }
            Verification::ElasticColumn { body, gravity, stress_tolerance, settlement_tolerance, .. } => {
                positive("verification.stress_tolerance", *stress_tolerance)?;
                positive("verification.settlement_tolerance", *settlement_tolerance)?;
                (body, gravity)
            }
            Verification::LargeStrainConsolidation {
                body,
                load,
                degrees,
                e_p_tolerance,
                p_rms_tolerance,
                settlement_tolerance,
            } => {
                if degrees.is_empty() || degrees.iter().any(|u| !(*u > 0.0 && *u < 1.0)) {
                    return Err("key `verification.degrees`: give degrees of consolidation in (0, 1)".into());
                }
                positive("verification.e_p_tolerance", *e_p_tolerance)?;
                positive("verification.p_rms_tolerance", *p_rms_tolerance)?;
                positive("verification.settlement_tolerance", *settlement_tolerance)?;
                (body, load)
            }
            Verification::ShockWave { body, load, probe_depth, fast_tolerance, slow_tolerance } => {
                positive("verification.probe_depth", *probe_depth)?;
                positive("verification.fast_tolerance", *fast_tolerance)?;
                positive("verification.slow_tolerance", *slow_tolerance)?;
                (body, load)
            }
            Verification::BearingCapacity {
                soil,
                load,
                loaded_width,
                loaded_depth,
                breadth,
                settlement_point,
                failure_settlement,
                plateau,
                reference,
                tolerance,
                report_settlements,
                report_loads,
                stop_settlement,
                footing,
            } => {
                positive("verification.loaded_width", *loaded_width)?;
                match (loaded_depth, c.dimension()) {
                    (Some(d), 3) => positive("verification.loaded_depth", *d)?,
                    (None, 3) => {
                        return Err("key `verification.loaded_depth`: a three-dimensional footing needs the loaded \
                                    area's extent along z"
                            .into())
                    }
                    (Some(_), _) => {
                        return Err("key `verification.loaded_depth`: only a three-dimensional case takes it \
                                    (a plane footing's pressure is its force per unit length over `loaded_width`)"
                            .into())
                    }
                    (None, _) => {}
                }
                if let Some([from, to]) = plateau {
                    if !(*from >= 0.0 && to > from && to.is_finite()) {
                        return Err(format!(
                            "key `verification.plateau`: give 0 ≤ d/B_from < d/B_to, got [{from}, {to}]"
                        ));
                    }
                    if failure_settlement.is_some() {
                        return Err(
                            "key `verification.plateau`: give `plateau` or `failure_settlement`, not both".into()
                        );
                    }
                }
                if let Some(s) = stop_settlement {
                    positive("verification.stop_settlement", *s)?;
                }
                positive("verification.breadth", *breadth)?;
                components("verification.settlement_point", settlement_point, c.dimension())?;
                if let Some(f) = failure_settlement {
                    positive("verification.failure_settlement", *f)?;
                }
                positive("verification.reference", *reference)?;
                positive("verification.tolerance", *tolerance)?;
                for (j, r) in report_settlements.iter().enumerate() {
                    positive(&format!("verification.report_settlements[{j}]"), *r)?;
                }
                for (j, r) in report_loads.iter().enumerate() {
                    positive(&format!("verification.report_loads[{j}]"), *r)?;
                }
                let load = match (load, footing) {
                    (Some(load), None) => load,
                    (None, Some(f)) => {
                        let Some(b) = c.boundaries.iter().find(|b| &b.name == f) else {
                            return Err(format!("key `verification.footing`: no boundary named `{f}`"));
                        };
                        let vertical =
                            |v: &Option<Vec<f64>>| v.as_ref().is_some_and(|v| v.get(1).is_some_and(|&y| y != 0.0));
                        if !b.fix.contains(&Dof::Uy) || !(vertical(&b.velocity) || vertical(&b.displacement)) {
                            return Err(format!(
                                "key `verification.footing`: the boundary `{f}` must fix `uy` and move it vertically \
                                 (`velocity` or `displacement`): its reaction is the footing's load"
                            ));
                        }
                        if c.body(soil).is_none() {
                            return Err(format!("key `verification.soil`: no body named `{soil}`"));
                        }
                        return Ok(());
                    }
                    _ => {
                        return Err(
                            "key `verification`: a bearing_capacity check takes either `load` (load control) or \
                             `footing` (a moving boundary)"
                                .into(),
                        )
                    }
                };
                if matches!(c.load(load), Some(Load::BodyForce { bodies: None, .. })) {
                    return Err(format!(
                        "key `verification.load`: the body force `{load}` must name the footing body in `bodies`"
                    ));
                }
                (soil, load)
            }
        };
        if c.body(body).is_none() {
            let key = if matches!(v, Verification::BearingCapacity { .. }) { "soil" } else { "body" };
            return Err(format!("key `verification.{key}`: no body named `{body}`"));
        }
        if c.load(load).is_none() {
            return Err(format!(
                "key `verification.{}`: no load named `{load}`",
                if matches!(v, Verification::ElasticColumn { .. }) { "gravity" } else { "load" }
            ));
        }
        if c.load(load).and_then(|l| l.increment_factor()).is_some()
            && !matches!(v, Verification::HollowCylinder { .. })
        {
            return Err(format!(
                "key `verification.load`: the check's reference follows the load's time function, and `{load}` has an \
                 `increment_factor` (only the hollow_cylinder check follows one)"
            ));
        }
        match v {
            Verification::ElasticColumn { surcharge, .. } => {
                if !matches!(c.load(load), Some(Load::BodyForce { .. })) {
                    return Err(format!("key `verification.gravity`: `{load}` must be a body_force load"));
                }
                if let Some(sname) = surcharge {
                    if !matches!(c.load(sname), Some(Load::ParticleTraction { .. } | Load::NodalTraction { .. })) {
                        return Err(format!("key `verification.surcharge`: no traction load named `{sname}`"));
                    }
                }
                if two_phase {
                    return Err("key `verification`: the elastic column reference is for a one_phase analysis".into());
                }
            }
            Verification::BearingCapacity { .. }
            | Verification::Lame { .. }
            | Verification::HollowCylinder { .. }
            | Verification::StiffnessMap { .. }
            | Verification::VerticalCut { .. } => {}
            _ => {
                if !two_phase {
                    return Err(
                        "key `verification`: the consolidation and wave references need a two_phase analysis".into()
                    );
                }
            }
        }
    }
    Ok(())
}

/// Checks a soil model's parameters; `prefix` is the key of its table (e.g. `materials[0].model`).
pub(crate) fn soil_model(prefix: &str, model: &SoilModel) -> R {
    let k = |f: &str| format!("{prefix}.{f}");
    match model {
        SoilModel::LinearElastic { young_modulus, poisson_ratio }
        | SoilModel::NeoHookean { young_modulus, poisson_ratio } => {
            modulus(&k("young_modulus"), *young_modulus)?;
            in_open(&k("poisson_ratio"), *poisson_ratio, -1.0, 0.5)?;
        }
        SoilModel::MohrCoulomb {
            young_modulus,
            poisson_ratio,
            friction_angle,
            cohesion,
            residual_cohesion,
            softening_strain,
            dilation_angle,
            critical_dilation_angle,
            dilation_decay,
            tension_cutoff,
        } => {
            modulus(&k("young_modulus"), *young_modulus)?;
            in_open(&k("poisson_ratio"), *poisson_ratio, -1.0, 0.5)?;
            in_closed_open(&k("friction_angle"), *friction_angle, 0.0, 90.0)?;
            non_negative(&k("cohesion"), *cohesion)?;
            for (f, v) in
                [("dilation_angle", Some(*dilation_angle)), ("critical_dilation_angle", *critical_dilation_angle)]
            {
                if let Some(v) = v {
                    if !(v > -90.0 && v <= *friction_angle) {
                        return Err(format!(
                            "key `{}`: must be in (-90, friction_angle = {friction_angle}], got {v}",
                            k(f)
                        ));
                    }
                }
            }
            non_negative(&k("dilation_decay"), *dilation_decay)?;
            if let Some(r) = residual_cohesion {
                non_negative(&k("residual_cohesion"), *r)?;
                if *r != *cohesion && softening_strain.is_none() {
                    return Err(format!(
                        "key `{}`: required when residual_cohesion differs from cohesion",
                        k("softening_strain")
                    ));
                }
            }
            if let Some(e) = softening_strain {
                positive(&k("softening_strain"), *e)?;
            }
            if let Some(t) = tension_cutoff {
                non_negative(&k("tension_cutoff"), *t)?;
            }
            if *friction_angle == 0.0 && *cohesion == 0.0 {
                return Err(format!(
                    "key `{}`: a Tresca material (friction_angle = 0) needs a positive cohesion",
                    k("cohesion")
                ));
            }
        }
        SoilModel::VonMises { young_modulus, poisson_ratio, cohesion, residual_cohesion, softening_modulus } => {
            modulus(&k("young_modulus"), *young_modulus)?;
            in_open(&k("poisson_ratio"), *poisson_ratio, -1.0, 0.5)?;
            positive(&k("cohesion"), *cohesion)?;
            if let Some(r) = residual_cohesion {
                non_negative(&k("residual_cohesion"), *r)?;
            }
            // Softening steeper than the elastic shear stiffness has no unique return.
            let g = young_modulus / (2.0 * (1.0 + poisson_ratio));
            if !(*softening_modulus <= 0.0 && *softening_modulus > -3f64.sqrt() * g) {
                return Err(format!(
                    "key `{}`: must be in (-√3 G, 0] = ({:.4e}, 0], got {softening_modulus}",
                    k("softening_modulus"),
                    -3f64.sqrt() * g
                ));
            }
        }
        SoilModel::NewtonianFluid { bulk_modulus, viscosity, bulk_viscosity } => {
            modulus(&k("bulk_modulus"), *bulk_modulus)?;
            non_negative(&k("viscosity"), *viscosity)?;
            non_negative(&k("bulk_viscosity"), *bulk_viscosity)?;
        }
        SoilModel::HenckyJ2 { young_modulus, poisson_ratio, cohesion, residual_cohesion, softening_rate } => {
            modulus(&k("young_modulus"), *young_modulus)?;
            in_open(&k("poisson_ratio"), *poisson_ratio, -1.0, 0.5)?;
            positive(&k("cohesion"), *cohesion)?;
            let residual = residual_cohesion.unwrap_or(*cohesion);
            if !(0.0..=*cohesion).contains(&residual) {
                return Err(format!(
                    "key `{}`: must be in [0, cohesion = {cohesion}], got {residual}",
                    k("residual_cohesion")
                ));
            }
            non_negative(&k("softening_rate"), *softening_rate)?;
            let m = crate::model::finite_strain::HenckyJ2::new(
                *young_modulus,
                *poisson_ratio,
                *cohesion,
                residual,
                *softening_rate,
            );
            if !m.well_posed() {
                return Err(format!(
                    "key `{}`: the softening outpaces the elastic unloading (3μ ≤ √3 η (c_p − c_r)), so the return \
                     is not unique; it must be below {:.4e}",
                    k("softening_rate"),
                    3.0 * m.shear / (3f64.sqrt() * (cohesion - residual))
                ));
            }
        }
    }
    Ok(())
}

/// The limits of a two-phase `dynamic_explicit` stage (the u–U system, `Layout::UW`): its pore
/// pressure lives at the points, so no boundary can fix it (a surface where the water may leave is
/// drained by itself, one where its normal motion is fixed is impermeable), and the transfers and
/// projections built for the one-phase system (XPIC, F̄) are not built for the water.
fn explicit_two_phase(c: &Case, s: &super::Stage, e: &super::Explicit) -> Result<(), String> {
    let key = |k: &str| format!("stages.{}.{k}", s.name);
    let pointwise = e.pore_pressure != Some(super::ExplicitPressure::Nodal);
    if e.xpic_order.is_some() {
        return Err(format!(
            "key `{}`: XPIC is built for one-phase explicit stages only (the water's velocities would need their \
             own passes); use `flip_blend`",
            key("explicit.xpic_order")
        ));
    }
    if c.stabilisation.fbar {
        return Err(
            "key `stabilisation.fbar`: the F̄ projection is built for one-phase explicit stages only (the pore \
             pressure of a two-phase explicit stage follows the points' own volume changes); use \
             `stabilisation.bbar` for the volumetric smoothing"
                .into(),
        );
    }
    let active = |name: &str| s.boundaries.as_ref().is_none_or(|list| list.iter().any(|n| n == name));
    let fixes_p = c.boundaries.iter().find(|b| active(&b.name) && b.fix.contains(&super::Dof::P));
    if let (true, Some(b)) = (pointwise, fixes_p) {
        return Err(format!(
            "key `boundaries` (`{}`): stage `{}` is explicit two-phase and holds its pore pressure point by point \
             (`explicit.pore_pressure = \"pointwise\"`, the default), so `p` cannot be fixed; a surface where the \
             water's motion is free is drained (p = 0) by itself, one that fixes the water's normal motion \
             (`Ux`/`Uy`) is impermeable. Take `p` out of `fix`, leave the boundary out of the stage's `boundaries`, \
             or set `explicit.pore_pressure = \"nodal\"` (the pressure at the nodes, which drained nodes fix)",
            b.name, s.name
        ));
    }
    Ok(())
}
