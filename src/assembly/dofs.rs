//! Which dofs of a step are unknowns, which are fixed and to what (step 3 of a step).
//!
//! Every ghosted dof is either free or fixed. A dof is fixed when an active boundary fixes it (its
//! prescribed increment is then `value`, and its reaction is booked to that boundary), or when its
//! node is not well filled (see [`super::stencils`]): such a node's motion is extended from its
//! neighbours in every particle that reaches it, so its own motion dofs carry nothing, and its pore
//! pressure is the drained value zero (its projected volume ratio in an implicit F̄ step stays
//! free wherever a point reaches the node, `kernels::fbar`). Fixed dofs keep their rows in the global vector (residual
//! x − value, unit diagonal, no column entries), so the layout never changes.

use crate::kernels::Layout;
use crate::model::{Active, Model};
use petsc::GhostedRange;

/// No boundary fixes the dof.
pub const NO_BOUNDARY: u16 = u16::MAX;

/// The dof map of a step.
#[derive(Debug, Clone, Default)]
pub struct DofMap {
    /// Dofs per node.
    pub nd: usize,
    /// Whether each ghosted node is well filled.
    pub well: Vec<bool>,
    /// Whether each ghosted dof is fixed.
    pub fixed: Vec<bool>,
    /// The prescribed increment of each fixed dof over the step (0 for a homogeneous condition).
    pub value: Vec<f64>,
    /// The boundary (index into `Model::boundaries`) fixing each ghosted dof, or [`NO_BOUNDARY`].
    pub boundary: Vec<u16>,
    /// Offsets of the fixed dofs in the owned part of global vectors, with their ghosted index.
    pub owned_fixed: Vec<(usize, usize)>,
    /// Unknowns (free dofs) over all ranks.
    pub free_dofs: usize,
}

impl DofMap {
    /// Whether a node's motion component `c` is fixed by a boundary (not merely by being barely
    /// filled).
    pub fn boundary_fixed(&self, node: usize, c: usize) -> bool {
        self.boundary[node * self.nd + c] != NO_BOUNDARY
    }
}

/// Whether component `c` of a node that the material fills to `fill` (a fraction of a cell) is an
/// unknown where no boundary fixes it: every component of a well-filled node (above
/// `well_fraction`); and the projected volume ratio of an implicit F̄ step wherever points reach
/// the node at all (above [`super::REACHED_FRACTION`]), since it is [002]'s average over the points
/// that reach it, however few (its row's diagonal is κ Σ_p S_ip V_p), unlike the motion, which is
/// extended, and the pressure, which is drained.
pub fn carries_unknown(layout: Layout, c: usize, fill: f64, well_fraction: f64) -> bool {
    if Some(c) == layout.jbar {
        fill > super::REACHED_FRACTION
    } else {
        fill > well_fraction
    }
}

/// Builds the dof map from the filled fractions `phi` (per ghosted node, summed over ranks) and the
/// moving-surface fixes `surface` (per ghosted dof, the boundary index + 1 or 0, maximum over ranks).
#[allow(clippy::too_many_arguments)]
pub fn build(
    model: &Model,
    active: &Active,
    (t0, t1): (f64, f64),
    ghost: &GhostedRange,
    owned_start: [usize; 2],
    owned_count: [usize; 2],
    nd: usize,
    phi: &[f64],
    surface: &[f64],
    well_fraction: f64,
    layout: Layout,
) -> DofMap {
    let n = ghost.len();
    let mut m = DofMap {
        nd,
        well: phi.iter().map(|&f| f > well_fraction).collect(),
        fixed: vec![false; n * nd],
        value: vec![0.0; n * nd],
        boundary: vec![NO_BOUNDARY; n * nd],
        owned_fixed: Vec::new(),
        free_dofs: 0,
    };
    for (l, reached) in phi.iter().enumerate() {
        let (i, j) = ghost.ij(l);
        let by = model.fixing_boundaries(active, [i, j]);
        for c in 0..nd {
            let (q, by_c) = (l * nd + c, layout.canonical(c).and_then(|k| by[k]));
            let b = by_c.or_else(|| (surface[q] > 0.5).then(|| surface[q].round() as usize - 1));
            if let Some(b) = b {
                m.boundary[q] = b as u16;
                // A moving boundary: its solid components and the water's move by its increment.
                if let Some(motion) = &model.boundaries[b].motion {
                    let dir = if c < 2 { Some(c) } else { layout.w.and_then(|w| (c >= w).then(|| c - w)) };
                    if let Some(d) = dir.filter(|&d| d < 2) {
                        m.value[q] = motion.increment_at(model.grid.node_position(i, j), t0, t1)[d];
                    }
                }
            }
            m.fixed[q] = b.is_some() || !carries_unknown(layout, c, *reached, well_fraction);
        }
    }
    for jj in 0..owned_count[1] {
        for ii in 0..owned_count[0] {
            let l = ghost.node(owned_start[0] + ii, owned_start[1] + jj).expect("owned nodes are ghosted");
            for c in 0..nd {
                let o = (jj * owned_count[0] + ii) * nd + c;
                if m.fixed[l * nd + c] {
                    m.owned_fixed.push((o, l * nd + c));
                } else {
                    m.free_dofs += 1;
                }
            }
        }
    }
    m
}
