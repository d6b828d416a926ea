//! `porompm check`: what a case will build, computed without PETSc (one process).

use crate::assembly::{dofs, WELL_FILLED_FRACTION};
use crate::case::{Case, Load};
use crate::model::{shape, Model};
use std::fmt::Write;

/// A plain-text description of the discrete problem a case defines.
pub fn describe(case: &Case, label: &str) -> String {
    if case.dimension() == 3 {
        return describe_solid(case, label);
    }
    let model = Model::build(case, |_, _| true);
    // The first stage's own unknowns per node (its analysis type's layout).
    let layout = crate::analysis::StageAnalysis::of(case, &case.stages[0]).layout;
    let mut s = String::new();
    let _ = writeln!(s, "case: {label}");
    let _ = writeln!(
        s,
        "formulation: {} (the first stage: {} dofs per node: {})",
        if model.pore_water { "two_phase" } else { "one_phase" },
        layout.nd,
        layout.field_names().join(", ")
    );
    let _ = writeln!(s, "basis: {:?}", case.analysis.shape_functions);
    let _ = writeln!(s, "geometry: {}", geometry_line(&model));
    let g = &model.grid;
    let _ = writeln!(
        s,
        "grid: {} × {} cells of {:.4} × {:.4} m from ({}, {}); {} nodes, {} grid dofs",
        g.cells[0],
        g.cells[1],
        g.h[0],
        g.h[1],
        g.origin[0],
        g.origin[1],
        g.node_count(),
        g.node_count() * model.ndof()
    );
    for m in &case.materials {
        let _ = writeln!(
            s,
            "material `{}`: {}, n = {}, ρ_s = {} kg/m³",
            m.name,
            m.model.describe(),
            m.porosity,
            m.solid_density
        );
    }
    for (b, body) in case.bodies.iter().enumerate() {
        let (count, volume) = body_points(&model.particles, b);
        let _ = writeln!(
            s,
            "body `{}`: {count} material points ({}), volume {volume:.6e}, material `{}`{}",
            body.name,
            fill_text(body, 2),
            body.material,
            initial_text(body)
        );
    }
    let _ = writeln!(s, "material points: {}", model.particles.len());
    let _ = writeln!(s, "{}", unknowns_line(case, &model, layout));
    for (l, id) in model.loads.iter().zip(case.load_ids()) {
        let _ = writeln!(s, "load `{}`: {}", l.name, load_text(case.load(id), l.size()));
    }
    boundary_lines(&mut s, &model);
    for st in &case.stages {
        let _ = writeln!(s, "{}", stage_line(case, &model, st));
    }
    numerics_lines(&mut s, case, &model);
    for w in crate::diagnostics::physics::warnings(case, &model) {
        let _ = writeln!(s, "warning [{}]: {}", w.kind, w.message);
    }
    let _ = writeln!(s, "verification: {}", crate::verification::describe(case));
    s
}

/// The plane's geometry in words, with the axis of an axisymmetric model.
fn geometry_line(model: &Model) -> String {
    match model.geometry {
        shape::Geometry::PlaneStrain => "plane strain (volumes per metre of thickness)".to_string(),
        shape::Geometry::Solid => "three dimensions (volumes in m³)".to_string(),
        shape::Geometry::Axisymmetric(w) => format!(
            "axisymmetric about the y axis (x ≡ r; ring volumes 2πrA; hoop strain u_r/r; GIMP weights in r: {w:?}){}",
            if model.boundaries.iter().any(|b| b.is_axis()) { "; u_r = 0 on the axis (boundary `axis`)" } else { "" }
        ),
    }
}

/// The active nodes at t = 0 (filled fraction of their support, as in crate::assembly) and the
/// unknowns of the first step.
fn unknowns_line(case: &Case, model: &Model, layout: crate::layout::Layout) -> String {
    let g = &model.grid;
    let mut filled = vec![0.0; g.node_count()];
    for k in 0..model.particles.len() {
        let st = shape::stencil(model.basis, g, model.particles.x[k], model.particles.lp[k]);
        for ([i, j], w, _) in st.iter() {
            filled[j as usize * g.nodes()[0] + i as usize] += w * model.area(k) / (g.h[0] * g.h[1]);
        }
    }
    let active_nodes = filled.iter().filter(|&&f| f > WELL_FILLED_FRACTION).count();
    let first = model.active(&case.stages[0]);
    let mut unknowns = 0;
    for j in 0..g.nodes()[1] {
        for i in 0..g.nodes()[0] {
            let f = filled[j * g.nodes()[0] + i];
            let fixed = model.fixing_boundaries(&first, [i, j]);
            unknowns += (0..layout.nd)
                .filter(|&c| {
                    layout.canonical(c).is_none_or(|k| fixed[k].is_none())
                        && dofs::carries_unknown(layout, c, f, WELL_FILLED_FRACTION)
                })
                .count();
        }
    }
    format!("active nodes at t = 0: {active_nodes}; unknowns of the first step: {unknowns}")
}

/// A plane case's load in words; `size` is the number of points, nodes or Gauss points it acts on.
fn load_text(load: &Load, size: usize) -> String {
    match load {
        Load::ParticleTraction(t) => {
            let follows = t.increment_factor.as_deref().map_or(String::new(), |e| {
                format!(", each increment scaled by `{e}` at the loaded faces' mean centre at the step's start")
            });
            format!("particle traction on {size} material points{follows}")
        }
        Load::NodalTraction(_) => format!("nodal traction on {size} nodes"),
        Load::LinePressure(p) => format!("pressure {} Pa on a line ({size} Gauss points)", p.pressure),
        Load::SurfacePressure(p) => {
            format!("pressure {} Pa on the surface of {} ({size} Gauss points)", p.pressure, p.surface.file())
        }
        Load::BodyForce(f) => format!("body force {:?} m/s²", f.acceleration),
    }
}

/// Each boundary of a plane model with the nodes it fixes.
fn boundary_lines(s: &mut String, model: &Model) {
    let g = &model.grid;
    for (bi, b) in model.boundaries.iter().enumerate() {
        let fix: Vec<String> = b.fix.iter().map(|d| d.to_string()).collect();
        if let Some(line) = surface_line(model, bi, &fix) {
            let _ = writeln!(s, "{line}");
            continue;
        }
        let count = (0..g.nodes()[1])
            .flat_map(|j| (0..g.nodes()[0]).map(move |i| (i, j)))
            .filter(|&(i, j)| b.contains(g, i, j))
            .count();
        let water_only = b.fix.iter().all(|d| !matches!(d, crate::case::Dof::Ux | crate::case::Dof::Uy));
        let ignored = if model.ndof() == 2 && water_only {
            " (water-phase components: ignored in a one_phase analysis)"
        } else {
            ""
        };
        let _ = writeln!(s, "boundary `{}`: {} fixed on {count} nodes{ignored}", b.name, fix.join(", "));
    }
}

/// The features, kinematics, stiffness and strain recovery, internal force and solver of a plane
/// model.
fn numerics_lines(s: &mut String, case: &Case, model: &Model) {
    let gravity = case.loads.iter().any(|l| matches!(l, Load::BodyForce(_)));
    let _ = writeln!(
        s,
        "features: gravity {}; return mapping {}; B-bar {}; F-bar {}; patch recovery {}; GIMP domains {}",
        if gravity { "on" } else { "off" },
        if model.materials.iter().all(|m| m.model.is_elastic()) { "never called (elastic)" } else { "on" },
        if model.bbar { "on" } else { "off" },
        if model.fbar { "on" } else { "off" },
        match (model.patch_recovery, model.pressure_update) {
            (_, crate::case::PressureUpdate::ProjectedTotal) => "off (pressure from the projected total field)",
            (true, _) => "on",
            (false, _) => "off",
        },
        match (model.basis, model.stretch_domains) {
            (crate::model::shape::Basis::Linear, _) => "none (linear basis)",
            (_, true) => "follow the stretch",
            (_, false) => "undeformed",
        }
    );
    let _ = writeln!(
        s,
        "kinematics: {}",
        if model.linear_increments {
            "geometrically linear steps on the configuration at each step's start ([001]: K Δu = ΔF, the residual \
             of the step's start taken off)"
        } else {
            "finite strain on the configuration at each step's end (objective update, exact tangent)"
        }
    );
    let _ = writeln!(
        s,
        "stiffness in the Newton matrix: {}; strain recovery: {}",
        stiffness_text(model),
        recovery_text(model)
    );
    if model.internal_force == crate::case::InternalForce::Mapped {
        let _ = writeln!(
            s,
            "internal force: double-mapped to the cells' Gauss points with the weights of {}",
            model.stiffness.name()
        );
    }
    let _ = writeln!(
        s,
        "solver: {}",
        case.solver.options_file.as_deref().map_or(
            "built-in default (Newton; sparse LU by UMFPACK on one rank up to 2 000 grid dofs, MUMPS beyond and on several)".to_string(),
            |f| format!("options file {f}")
        )
    );
}

/// The material stiffness of the Newton matrix in words.
fn stiffness_text(model: &Model) -> String {
    match (model.stiffness, model.stiffness_in_jacobian) {
        (crate::case::Stiffness::Particle, _) => "the exact tangent".to_string(),
        (other, false) => format!("the exact tangent ({} serves the K_mag diagnostic only)", other.name()),
        (other, true) => format!(
            "{} ([001]'s mapped stiffness: an approximate Jacobian, Newton converges linearly; up to {} iterations a \
             step)",
            other.name(),
            crate::assembly::newton_iterations(other)
        ),
    }
}

/// The strain recovery in words.
fn recovery_text(model: &Model) -> &'static str {
    match model.stress_recovery {
        crate::case::StressRecovery::Basis => "the basis functions' gradients",
        crate::case::StressRecovery::Cmpm => "CMPM patch functions ([001] Eqs. 22–23, corrected)",
        crate::case::StressRecovery::Mapped => "the double-mapped operators (the forces' transpose)",
    }
}

/// How a body of a case of dimension `dim` is filled: its points per cell, its mesh's cells and
/// quadrature, or its surface's triangles and the volume they enclose.
fn fill_text(body: &crate::case::Body, dim: usize) -> String {
    use crate::case::Shape;
    let n = body.particles_per_cell;
    match &body.shape {
        Shape::Mesh(m) => format!("the {} cells of {}, quadrature of order {}", m.mesh().cells(), m.file, m.order),
        Shape::Points(p) => format!("the {} rows of {}", p.cloud().len(), p.file),
        Shape::Surface(f) => format!(
            "{n}×{n}×{n} per cell inside the {} triangles of {}, which enclose {:.6e} m³",
            f.surface().triangles(),
            f.file,
            f.surface().volume()
        ),
        _ if dim == 3 => format!("{n}×{n}×{n} per cell"),
        _ => format!("{n}×{n} per cell"),
    }
}

/// The number of body `b`'s material points among `ps`, and the sum of their volumes.
fn body_points<const D: usize>(ps: &crate::model::particles::Particles<D>, b: usize) -> (usize, f64) {
    let mine = || (0..ps.len()).filter(|&k| ps.body[k] as usize == b);
    (mine().count(), mine().map(|k| ps.volume[k]).sum())
}

/// The description of a three-dimensional case: its grid, bodies and material points, loads,
/// boundaries (with the nodes each holds) and stages.
fn describe_solid(case: &Case, label: &str) -> String {
    let model = Model::build_solid(case, |_| true);
    let g = &model.grid;
    let ps = &model.particles;
    let mut s = String::new();
    let _ = writeln!(s, "case: {label}");
    let _ = writeln!(s, "dimension: 3 (y vertical; volumes in m³)");
    let _ = writeln!(s, "formulation: {}", if model.pore_water { "two_phase" } else { "one_phase" });
    let _ = writeln!(s, "basis: {:?}", case.analysis.shape_functions);
    let _ = writeln!(
        s,
        "grid: {} × {} × {} cells of {:.4} × {:.4} × {:.4} m from ({}, {}, {}), {} nodes",
        g.cells[0],
        g.cells[1],
        g.cells[2],
        g.h[0],
        g.h[1],
        g.h[2],
        g.origin[0],
        g.origin[1],
        g.origin[2],
        g.node_count()
    );
    for (b, body) in case.bodies.iter().enumerate() {
        let (count, volume) = body_points(ps, b);
        let [z0, z1] = case.body_depth(body);
        let _ = writeln!(
            s,
            "body `{}`: {count} material points ({}), volume {volume:.6e} m³, z ∈ [{z0}, {z1}] m, material `{}`{}",
            body.name,
            fill_text(body, 3),
            body.material,
            initial_text(body)
        );
    }
    let _ = writeln!(s, "material points: {}", ps.len());
    for (l, id) in model.loads.iter().zip(case.load_ids()) {
        let load = case.load(id);
        let kind = match load {
            Load::ParticleTraction(t) => {
                format!("particle traction {:?} Pa on {} material points", t.traction, l.size())
            }
            Load::NodalTraction(t) => format!("nodal traction {:?} Pa on {} nodes", t.traction, l.size()),
            Load::BodyForce(f) => format!("body force {:?} m/s²", f.acceleration),
            Load::LinePressure(_) => String::new(),
            Load::SurfacePressure(_) => load_text(load, l.size()),
        };
        let _ = writeln!(s, "load `{}`: {kind}", l.name);
    }
    for (bi, b) in model.boundaries.iter().enumerate() {
        let fix: Vec<String> = b.fix.iter().map(|d| d.to_string()).collect();
        if let Some(line) = surface_line(&model, bi, &fix) {
            let _ = writeln!(s, "{line}");
            continue;
        }
        let count = (0..g.node_count()).filter(|&n| b.holds_node(g, g.node_indices(n))).count();
        let _ = writeln!(s, "boundary `{}`: {} fixed on {count} nodes", b.name, fix.join(", "));
    }
    for st in &case.stages {
        let _ = writeln!(s, "{}", stage_line(case, &model, st));
    }
    s
}

/// The line of boundary `bi` if it is a moving surface (resolved per step; at t = 0 from the
/// particles' faces), with its fixed components `fix`.
fn surface_line<const D: usize>(model: &Model<D>, bi: usize, fix: &[String]) -> Option<String> {
    let b = &model.boundaries[bi];
    let list = b.surface.as_ref()?;
    let only = crate::model::Active { loads: Vec::new(), boundaries: vec![bi] };
    let mut nodes: Vec<[u32; D]> = model.surface_fixes(&only, false).into_iter().map(|(n, _, _)| n).collect();
    nodes.sort_unstable();
    nodes.dedup();
    let weak = if b.fix.contains(&crate::case::Dof::P) {
        "; in quasi-static stages p = 0 on the faces themselves (Nitsche), not at the nodes"
    } else {
        ""
    };
    Some(format!(
        "boundary `{}`: {} fixed on a moving surface of {} particle faces ({} nodes at t = 0{weak})",
        b.name,
        fix.join(", "),
        list.len(),
        nodes.len()
    ))
}

/// The line of a stage: its analysis, duration and step (an explicit stage's stable step where
/// that is the smaller), its strength reduction, its active loads and boundaries.
fn stage_line<const D: usize>(case: &Case, model: &Model<D>, st: &crate::case::Stage) -> String {
    let a = model.active(st);
    let loads: Vec<&str> = a.loads.iter().map(|&i| model.loads[i].name.as_str()).collect();
    let boundaries: Vec<&str> = a.boundaries.iter().map(|&i| model.boundaries[i].name.as_str()).collect();
    let analysis = crate::analysis::StageAnalysis::of(case, st);
    let dt = analysis.dt_limit.map_or(st.dt(), |l| l.min(st.dt()));
    let reduction = st.strength_reduction.map_or(String::new(), |f| format!("; peak strengths divided by {f}"));
    format!(
        "stage `{}` ({}): {} s in steps of {:.4e} s ({} steps){reduction}; loads [{}]; boundaries [{}]",
        st.name,
        analysis.describe(),
        st.duration,
        dt,
        (st.duration / dt).ceil() as usize,
        loads.join(", "),
        boundaries.join(", "),
    )
}

/// A body's initial fields as the case gives them (`; initial velocity (0, v0 * y) m/s`), or
/// nothing.
fn initial_text(body: &crate::case::Body) -> String {
    let Some(init) = &body.initial else {
        return String::new();
    };
    let text = |f: &crate::case::Field| match f {
        crate::case::Field::Value(v) => format!("{v}"),
        crate::case::Field::Expression(e) => e.clone(),
    };
    let list = |fs: &[crate::case::Field]| fs.iter().map(text).collect::<Vec<_>>().join(", ");
    let mut parts = Vec::new();
    if let Some(v) = &init.velocity {
        parts.push(format!("velocity ({}) m/s", list(v)));
    }
    if let Some(v) = &init.stress {
        parts.push(format!("effective stress ({}) Pa", list(v)));
    }
    if let Some(p) = &init.pore_pressure {
        parts.push(format!("pore pressure {} Pa", text(p)));
    }
    format!("; initial {}", parts.join(", "))
}

#[cfg(test)]
mod tests {
    /// `porompm check` of a three-dimensional case: its dimension, grid, bodies with their points
    /// and volumes, its stage.
    #[test]
    fn a_three_dimensional_case_is_described() {
        let text = crate::case::tests_support::with_grid("[0.1, 1.0, 0.2]", "[1, 10, 2]");
        let c = crate::validation::load(&text, "t", &[]).unwrap();
        let d = super::describe(&c, "column_3d.toml");
        for want in [
            "dimension: 3",
            "grid: 1 × 10 × 2 cells",
            "body `column`: 160 material points (2×2×2 per cell), volume 2.000000e-2 m³",
            "material points: 160",
            "stage `load` (dynamic u–p–U",
        ] {
            assert!(d.contains(want), "{d}\n  does not say: {want}");
        }
    }
}
