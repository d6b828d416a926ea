//! The external forces of a step on the nodes ([`external_forces`]) and the check that the grid
//! carries all of them ([`check_loads`]).

use super::dofs::DofMap;
use super::space::NodeSpace;
use super::stencils;
use super::step::Step;
use crate::model::loads::{face_point, LoadTarget};
use crate::model::{shape, Active, Model};
use crate::parallel::Collective;

/// The tractions of a step as the case applies them (before they are shared out to nodes), on
/// this rank, for [`check_loads`].
#[derive(Debug, Clone)]
pub(super) struct AppliedLoads<const D: usize> {
    /// Total force [N/m in two dimensions, N in three].
    total: [f64; D],
    /// The traction loads that are active.
    names: Vec<String>,
}

impl<const D: usize> AppliedLoads<D> {
    fn add(&mut self, force: [f64; D]) {
        for (t, f) in self.total.iter_mut().zip(force) {
            *t += f;
        }
    }
}

/// The external forces at `t_new` per ghosted dof. A traction's share at a node whose motion is
/// extended goes to the node's masters (extended towards the loaded particle); a share that no
/// node can carry stays where it is, and [`check_loads`] reports it. Returns the nodal forces and,
/// for that check, the total force the loads apply on this rank (before it is shared out to
/// nodes).
pub(super) fn external_forces<const D: usize, const M: usize>(
    space: &NodeSpace<D>,
    model: &Model<D>,
    active: &Active,
    t_new: f64,
    dofs: &DofMap,
) -> Result<(Vec<f64>, AppliedLoads<D>), String> {
    let nd = space.layout.nd;
    let ghost = &space.ghost;
    let g = &model.grid;
    let mut fext = vec![0.0; ghost.len() * nd];
    let mut applied = AppliedLoads { total: [0.0; D], names: Vec::new() };
    let tiny = 1e-9 * g.h.iter().copied().fold(f64::INFINITY, f64::min);
    let is_well = |n: [i64; D]| -> bool {
        n.iter().all(|&v| v >= 0) && ghost.local(n.map(|v| v as usize)).is_some_and(|l| dofs.well[l])
    };
    let mut add = |l: usize, force: [f64; D], toward: [f64; D]| {
        for c in 0..D {
            if dofs.well[l] || dofs.boundary_fixed(l, c) {
                fext[l * nd + c] += force[c];
                continue;
            }
            let n = ghost.indices(l);
            match stencils::extension_in(n, g.position(n), toward, &is_well, tiny, model.basis.is_bspline()) {
                Some((masters, coefs, count)) => {
                    for m in 0..count {
                        // The masters are well filled, hence ghosted.
                        if let Some(ml) = ghost.local(masters[m].map(|v| v as usize)) {
                            fext[ml * nd + c] += coefs[m] * force[c];
                        }
                    }
                }
                None => fext[l * nd + c] += force[c],
            }
        }
    };
    for &li in &active.loads {
        let load = &model.loads[li];
        let f = load.factor(t_new);
        if !matches!(load.target, LoadTarget::BodyForce { .. }) {
            applied.names.push(load.name.clone());
        }
        for (l, force, toward) in load_shares::<D, M>(space, model, li, f)? {
            if let Some(l) = l {
                add(l, force, toward);
            } else {
                applied.add(force);
            }
        }
    }
    Ok((fext, applied))
}

/// The shares of load `li` at factor `f`: `(Some(ghosted node), force, the point an extension
/// reaches towards)` for each nodal share, in the order they are added, and `(None, total, _)`
/// for each force the load applies (what [`check_loads`] holds the grid to).
#[allow(clippy::type_complexity)]
fn load_shares<const D: usize, const M: usize>(
    space: &NodeSpace<D>,
    model: &Model<D>,
    li: usize,
    f: f64,
) -> Result<Vec<(Option<usize>, [f64; D], [f64; D])>, String> {
    let (ps, g, ghost) = (&model.particles, &model.grid, &space.ghost);
    let load = &model.loads[li];
    let mut out = Vec::new();
    match &load.target {
        LoadTarget::ParticleTraction { particles, face, traction } => {
            // The traction acts at the centre of the particle's loaded face (force = traction ×
            // current face measure) with the multilinear weights there (see shape::face_weights).
            for &k in particles {
                let (x, lp) = (ps.x[k], ps.lp[k]);
                let (point, length) = face_point(*face, x, lp);
                // The face's area: its length times the ring's 2πr in axial symmetry.
                let length = length * model.geometry.measure(point[0]);
                out.push((None, std::array::from_fn(|d| traction[d] * f * length), x));
                let w: shape::Stencil<D, M> = shape::face_weights_in(model.basis, g, point);
                for (node, s, _) in w.iter() {
                    let l = ghost.local(node.map(|v| v as usize)).ok_or_else(|| {
                        format!(
                            "the traction `{}` on material point {} acts outside this rank's ghost region",
                            load.name, ps.id[k]
                        )
                    })?;
                    out.push((Some(l), std::array::from_fn(|d| s * traction[d] * f * length), x));
                }
            }
        }
        LoadTarget::NodalTraction { nodes, traction } => {
            // Each node's share on the rank owning it (the cell it is the lower corner of).
            for &(n, measure) in nodes.iter().filter(|(n, _)| space.owns_cell_in(*n)) {
                let l = ghost.local(n).ok_or("an owned node is not ghosted")?;
                let x = g.position(n);
                let measure = measure * model.geometry.measure(x[0]);
                let force = std::array::from_fn(|d| traction[d] * f * measure);
                out.push((None, force, x));
                out.push((Some(l), force, x));
            }
        }
        LoadTarget::Pressure { points, pressure } => {
            // Each Gauss point on the rank owning the cell that holds it.
            for &(point, force) in points {
                if !g.cell_containing(point).is_some_and(|c| space.owns_cell_in(c)) {
                    continue;
                }
                let ring = model.geometry.measure(point[0]);
                let force: [f64; D] = std::array::from_fn(|d| force[d] * ring);
                out.push((None, std::array::from_fn(|d| force[d] * pressure * f), point));
                // Shares on unfilled nodes are extended from the material's side.
                let len = (1..D).fold(force[0], |h, d| h.hypot(force[d])).max(f64::MIN_POSITIVE);
                let inward = std::array::from_fn(|d| point[d] + force[d] / len * g.h[d]);
                let w: shape::Stencil<D, M> = shape::face_weights_in(model.basis, g, point);
                for (n, s, _) in w.iter() {
                    let l = ghost.local(n.map(|v| v as usize)).ok_or("an owned cell's nodes are not ghosted")?;
                    out.push((Some(l), std::array::from_fn(|d| s * force[d] * pressure * f), inward));
                }
            }
        }
        LoadTarget::BodyForce { .. } => {}
    }
    Ok(out)
}

/// The load accounting of a step: the tractions the case applies at t_{n+1} against the forces
/// assembled on nodes that carry them (free, or fixed by a boundary, whose reaction then takes
/// them). A difference beyond round-off means that part of a load would be lost: an error
/// naming the load.
pub(super) fn check_loads<const D: usize, const M: usize>(
    space: &mut NodeSpace<D>,
    step: &Step<D, M>,
    applied: &AppliedLoads<D>,
    t_new: f64,
    coll: &Collective,
) -> Result<(), String> {
    let nd = space.layout.nd;
    let (applied, names) = (applied.total, &applied.names);
    if names.is_empty() {
        return Ok(());
    }
    let mut summed = step.fext.clone();
    space.sum_over_ranks(&mut summed).map_err(|e| e.to_string())?;
    let mut carried = [0.0; D];
    let mut magnitude = 0.0f64;
    for &a in &space.owned_nodes {
        let l = a as usize;
        for (c, carried_c) in carried.iter_mut().enumerate() {
            let q = l * nd + c;
            magnitude = magnitude.max(summed[q].abs());
            if !step.dofs.fixed[q] || step.dofs.boundary_fixed(l, c) {
                *carried_c += summed[q];
            }
        }
    }
    let totals = coll.sum(&[&applied[..], &carried[..]].concat())?;
    let scale = totals[..D].iter().fold(coll.max(&[magnitude])?[0], |m, t| m.max(t.abs()));
    let lost = (0..D).fold(0.0f64, |m, d| m.hypot(totals[d] - totals[D + d]));
    if lost > 1e-9 * scale.max(f64::MIN_POSITIVE) {
        let vector = |v: &[f64]| format!("({})", v.iter().map(|x| format!("{x:.6e}")).collect::<Vec<_>>().join(", "));
        let unit = if D == 2 { "N/m" } else { "N" };
        return Err(format!(
            "at t = {t_new:.6e} s the load(s) {} apply {} {unit} but the grid carries {} {unit}: part of the load \
             acts on nodes the material does not fill",
            names.join(", "),
            vector(&totals[..D]),
            vector(&totals[D..])
        ));
    }
    Ok(())
}
