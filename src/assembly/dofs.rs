//! Which dofs of a step are unknowns, which are fixed and to what (step 3 of a step).
//!
//! Every ghosted dof is either free or fixed. A dof is fixed when an active boundary fixes it (its
//! prescribed increment is then `value`, and its reaction is booked to that boundary), or when its
//! node is not well filled (see [`super::stencils`]): such a node's motion is extended from its
//! neighbours in every particle that reaches it, so its own motion dofs carry nothing, and its pore
//! pressure is the drained value zero (its projected volume ratio in an implicit F̄ step stays
//! free wherever a point reaches the node, `kernels::fbar`). Fixed dofs keep their rows in the global vector (residual
//! x − value, unit diagonal, no column entries), so the layout never changes.

use crate::layout::Layout;
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
    /// The bytes the map holds on the heap.
    pub fn heap_bytes(&self) -> usize {
        use crate::algebra::heap::capacity as c;
        c(&self.well) + c(&self.fixed) + c(&self.value) + c(&self.boundary) + c(&self.owned_fixed)
    }

    /// Whether a node's motion component `c` is fixed by a boundary (not merely by being barely
    /// filled).
    pub fn boundary_fixed(&self, node: usize, c: usize) -> bool {
        self.boundary[node * self.nd + c] != NO_BOUNDARY
    }
}

/// Whether component `c` of a node that the material fills to `fill` (a fraction of a cell) is an
/// unknown where no boundary fixes it: every component of a well-filled node (above
/// `well_fraction`); and the projected volume ratio of an implicit F̄ step wherever points reach
/// the node at all (a fill above zero), since it is [002]'s average over the points that reach it,
/// however few (its row's diagonal is κ Σ_p S_ip V_p), unlike the motion, which is extended, and the
/// pressure, which is drained. No threshold above zero: a point's J̄ = 1 + Σ_i S_ip ϑ_i needs ϑ at
/// every node with S_ip ≠ 0, and a node whose share is dropped costs the patch test its exactness
/// (in three dimensions a corner node beyond a cube is reached by a sliver ∝ δ³, and a threshold of
/// 1e-12 of a cell let the spread of the F̄ patch grow to 4e-12).
pub fn carries_unknown(layout: Layout, c: usize, fill: f64, well_fraction: f64) -> bool {
    if Some(c) == layout.jbar {
        fill > 0.0
    } else {
        fill > well_fraction
    }
}

/// Builds the dof map from the filled fractions `phi` (per ghosted node, summed over ranks) and the
/// moving-surface fixes `surface` (per ghosted dof, the boundary index + 1 or 0, maximum over ranks),
/// in any dimension.
#[allow(clippy::too_many_arguments)]
pub fn build<const D: usize>(
    model: &Model<D>,
    active: &Active,
    (t0, t1): (f64, f64),
    ghost: &GhostedRange<D>,
    owned_start: [usize; D],
    owned_count: [usize; D],
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
        let node = ghost.indices(l);
        let by = model.fixing_boundaries(active, node);
        for c in 0..nd {
            let (q, by_c) = (l * nd + c, layout.canonical(c).and_then(|k| by[k]));
            let b = by_c.or_else(|| (surface[q] > 0.5).then(|| surface[q].round() as usize - 1));
            if let Some(b) = b {
                m.boundary[q] = b as u16;
                // A moving boundary: its solid components and the water's move by its increment.
                if let Some(motion) = &model.boundaries[b].motion {
                    let dir = if c < D { Some(c) } else { layout.w.and_then(|w| (c >= w).then(|| c - w)) };
                    if let Some(d) = dir.filter(|&d| d < D) {
                        m.value[q] = motion.increment_at(model.grid.position(node), t0, t1)[d];
                    }
                }
            }
            m.fixed[q] = b.is_some() || !carries_unknown(layout, c, *reached, well_fraction);
        }
    }
    // The owned nodes, x fastest, and their place in the owned part of global vectors.
    let owned: usize = owned_count.iter().product();
    let mut at = [0usize; D];
    for node in 0..owned {
        let l = ghost.local(std::array::from_fn(|d| owned_start[d] + at[d])).expect("owned nodes are ghosted");
        for c in 0..nd {
            let o = node * nd + c;
            if m.fixed[l * nd + c] {
                m.owned_fixed.push((o, l * nd + c));
            } else {
                m.free_dofs += 1;
            }
        }
        crate::model::shape::next_combination(&mut at, owned_count);
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dof map of a three-dimensional u–p step: the base fixes ux, uy, uz, the back wall uz, a
    /// moving region at the top ux, uy, uz and p with its step's increment; a barely filled node's
    /// dofs are fixed; the owned part lists every fixed dof and counts the rest.
    #[test]
    fn a_three_dimensional_dof_map_fixes_and_moves_its_boundaries() {
        let text = crate::case::tests_support::solid_with_boundaries(r#"["uz"]"#, "velocity = [0.0, -0.01, 0.002]");
        let c = crate::validation::load(&text, "t", &[]).unwrap();
        let m = Model::build_solid(&c, |_| true);
        let active = m.active(&c.stages[0]);
        let nodes = m.grid.nodes();
        let ghost = GhostedRange { start: [0; 3], count: nodes, dof: 4 };
        let layout = Layout::UP.in_dim(3);
        let nd = layout.nd;
        let n = ghost.len();
        // Every node well filled but one.
        let lonely = ghost.local([2, 5, 3]).unwrap();
        let phi: Vec<f64> = (0..n).map(|l| if l == lonely { 0.1 } else { 1.0 }).collect();
        let map = build(&m, &active, (0.0, 0.5), &ghost, [0; 3], nodes, nd, &phi, &vec![0.0; n * nd], 0.5, layout);
        let base = (nodes[0] * nodes[2]) * 3;
        let back = nodes[0] * nodes[1] - nodes[0];
        // The top region: x ∈ {0, 0.1}, z ∈ {0.1, 0.2} at y = 1: four nodes, four components each.
        let top = 4 * 4;
        let fixed = map.fixed.iter().filter(|&&f| f).count();
        assert_eq!(fixed, base + back + top + nd, "base {base}, back {back}, top {top}, the lonely node");
        let q = ghost.local([1, 10, 2]).unwrap() * nd;
        assert_eq!(&map.value[q..q + 4], &[0.0, -0.005, 0.001, 0.0]);
        assert_eq!(map.boundary[q + 3], 2);
        assert!(map.boundary_fixed(ghost.local([0, 0, 1]).unwrap(), 2));
        assert!(map.fixed[lonely * nd..lonely * nd + nd].iter().all(|&f| f));
        assert_eq!(map.owned_fixed.len(), fixed);
        assert_eq!(map.free_dofs, n * nd - fixed);
    }
}
