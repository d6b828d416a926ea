//! The free-surface aggregates of the dynamic u–p–U system's Schur preconditioner.
//!
//! PETSc's `selfp` approximates the Schur complement S = A_pp − A_pu A_uu⁻¹ A_up with diag(A_uu)⁻¹
//! in place of A_uu⁻¹. Where the material ends at a drained free surface, the nodes of the last
//! few layers hold slivers of material: their motion is soft (stiffness over inertia up to 17× a
//! bulk node's) and the inverse of A_uu there is far from diagonal. The largest eigenvalues of
//! selfp⁻¹ S live on those layers and grow with M Δt²/h² (docs/solvers.md, "Why the iterations
//! grow"). [`surface_groups`] picks, along every free surface, small non-overlapping aggregates:
//! columns normal to the surface, `depth` live pressure layers deep plus the nodes beyond them
//! whose motion is free, `width` nodes wide along it, and one block at each corner where two
//! surfaces meet. The Schur preconditioner then inverts A_uu exactly on every aggregate (all
//! displacement dofs of its nodes, solid and water) and uses its diagonal elsewhere
//! (`petsc::SchurUser::update_with_blocks`). On the spectra of the slumping block's tangents the
//! aggregates 3 deep and 2 wide matched the exact inverse of the whole strip within 1–7 %; with
//! both blocks factorised they halve selfp's Krylov iterations on 64 × 48 cells, but not on finer
//! grids, whose spread lives in the bulk, and AMG V-cycles do not carry the gain (docs/solvers.md:
//! a study tool).
//!
//! An aggregate holds nodes of one rank only (the rank that owns them): a column that a rank
//! boundary cuts becomes two. A node sees the surface only within its rank's ghosted block.

use crate::assembly::dofs::DofMap;
use crate::model::grid::indices_of;
use petsc::GhostedRange;
use std::collections::BTreeMap;

/// The aggregates' shape: live pressure layers across the strip and nodes along it.
#[derive(Debug, Clone, Copy)]
pub struct StripShape {
    /// Live pressure layers counted from the surface (0: no aggregates).
    pub depth: usize,
    /// Nodes along the surface per aggregate.
    pub width: usize,
}

impl Default for StripShape {
    fn default() -> Self {
        StripShape { depth: 3, width: 2 }
    }
}

/// How far beyond the last live pressure layer a node with free motion is attached to the strip
/// (GIMP domains reach at most two nodes past the material's edge).
const BEYOND: usize = 2;

/// The aggregates of this rank's owned nodes as positions in the rank's rows of the displacement
/// split (owned node `a` holds the positions `a (nd − 1) .. (a + 1)(nd − 1)`, every dof but the
/// pressure `p`), each sorted, in a deterministic order. `nodes` counts the grid's nodes per
/// direction; `owned` lists the owned nodes' ghosted numbers in the split's order.
pub fn surface_groups<const D: usize>(
    ghost: &GhostedRange<D>,
    nodes: [usize; D],
    owned: &[u32],
    dofs: &DofMap,
    p: usize,
    shape: StripShape,
) -> Vec<Vec<usize>> {
    if shape.depth == 0 || shape.width == 0 {
        return Vec::new();
    }
    let nd = dofs.nd;
    let live = |l: usize| !dofs.fixed[l * nd + p];
    let moving = |l: usize| (0..nd).any(|c| c != p && !dofs.fixed[l * nd + c]);
    // The neighbour `t` nodes from `n` along axis `a` in direction `up`, if the rank sees it.
    let neighbour = |n: [usize; D], a: usize, up: bool, t: usize| -> Option<usize> {
        let i = if up { n[a].checked_add(t).filter(|&i| i < nodes[a]) } else { n[a].checked_sub(t) }?;
        let mut m = n;
        m[a] = i;
        ghost.local(m)
    };
    // The key of a live node's aggregate: per axis, the surfaces within `depth` live layers
    // (direction and the position of the first node past the last live one) or, along the
    // surface, the node's index over `width`. None away from every surface.
    let key_of_live = |l: usize| -> Option<Vec<i64>> {
        let n = ghost.indices(l);
        let mut key = Vec::with_capacity(3 * D);
        let mut near = false;
        for a in 0..D {
            let mut stops = [None, None];
            for (s, up) in [false, true].into_iter().enumerate() {
                for t in 1..=shape.depth {
                    let Some(m) = neighbour(n, a, up, t) else { break };
                    if !live(m) {
                        // The material ends here when the node past the last live one moves
                        // freely or holds (next to) no material; a held wall is no surface.
                        if moving(m) || !dofs.well[m] {
                            stops[s] = Some(ghost.indices(m)[a] as i64);
                        }
                        break;
                    }
                }
            }
            match stops {
                [None, None] => key.extend([0, (n[a] / shape.width) as i64, 0]),
                [lo, hi] => {
                    near = true;
                    key.extend([1, lo.unwrap_or(-1), hi.unwrap_or(-1)]);
                }
            }
        }
        near.then_some(key)
    };
    // The offsets within `BEYOND` nodes, nearest first.
    let side = 2 * BEYOND + 1;
    let mut offsets: Vec<[i64; D]> = (0..side.pow(D as u32))
        .map(|k| indices_of([side; D], k).map(|i| i as i64 - BEYOND as i64))
        .filter(|o| o.iter().any(|&v| v != 0))
        .collect();
    offsets.sort_by_key(|o| (o.iter().map(|v| v * v).sum::<i64>(), *o));
    let key_of = |l: usize| -> Option<Vec<i64>> {
        if live(l) {
            return key_of_live(l);
        }
        if !moving(l) {
            return None;
        }
        // A node past the surface whose motion is free joins the aggregate of the nearest live
        // node within `BEYOND` nodes in every direction (the nearest first, then in a fixed order:
        // an axis neighbour before a diagonal one, so that a corner's outer node finds the corner).
        let n = ghost.indices(l);
        offsets.iter().find_map(|o| {
            let mut m = n;
            for d in 0..D {
                let i = n[d] as i64 + o[d];
                if i < 0 || i >= nodes[d] as i64 {
                    return None;
                }
                m[d] = i as usize;
            }
            let m = ghost.local(m)?;
            if live(m) {
                key_of_live(m)
            } else {
                None
            }
        })
    };
    let per_node = nd - 1;
    let mut groups: BTreeMap<Vec<i64>, Vec<usize>> = BTreeMap::new();
    for (a, &l) in owned.iter().enumerate() {
        if let Some(key) = key_of(l as usize) {
            groups.entry(key).or_default().extend(a * per_node..(a + 1) * per_node);
        }
    }
    groups.into_values().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 10 × 8-node grid on one rank with u–p–U's five dofs per node (p at 2): the material
    /// covers the nodes i ≤ 6, j ≤ 5, its pressure live for i ≤ 5, j ≤ 4 (the last layer drained,
    /// its motion free), the base j = 0 held in u (pressure live), the side i = 0 held in x.
    fn block() -> (GhostedRange<2>, DofMap, Vec<u32>) {
        let (nx, ny, nd) = (10, 8, 5);
        let ghost = GhostedRange { start: [0, 0], count: [nx, ny], dof: nd };
        let mut fixed = vec![true; nx * ny * nd];
        let mut well = vec![false; nx * ny];
        for j in 0..ny {
            for i in 0..nx {
                let l = ghost.local([i, j]).unwrap();
                if i <= 6 && j <= 5 {
                    well[l] = true;
                    for c in 0..nd {
                        let held = (j == 0 && c != 2) || (i == 0 && (c == 0 || c == 3));
                        let drained = c == 2 && (i == 6 || j == 5);
                        fixed[l * nd + c] = held || drained;
                    }
                }
            }
        }
        let n = nx * ny * nd;
        let dofs = DofMap {
            nd,
            well,
            fixed,
            value: vec![0.0; n],
            boundary: vec![crate::assembly::dofs::NO_BOUNDARY; n],
            owned_fixed: Vec::new(),
            free_dofs: 0,
            ..DofMap::default()
        };
        (ghost, dofs, (0..(nx * ny) as u32).collect())
    }

    /// The groups as sorted lists of (i, j) nodes.
    fn nodes_of(groups: &[Vec<usize>], ghost: &GhostedRange<2>) -> Vec<Vec<[usize; 2]>> {
        groups
            .iter()
            .map(|g| {
                assert_eq!(g.len() % 4, 0, "a group holds whole nodes: {g:?}");
                let mut ns: Vec<[usize; 2]> = g.chunks(4).map(|c| ghost.indices(c[0] / 4)).collect();
                ns.sort_by_key(|n| (n[1], n[0]));
                ns
            })
            .collect()
    }

    #[test]
    fn the_strip_is_cut_into_columns_two_wide_and_one_corner_block() {
        let (ghost, dofs, owned) = block();
        let groups = surface_groups(&ghost, [10, 8], &owned, &dofs, 2, StripShape::default());
        let got = nodes_of(&groups, &ghost);
        // The right side: live layers i = 3, 4, 5 and the drained layer i = 6, rows paired (j = 0
        // with 1) up to the corner's j = 2; the top: j = 2..=5, columns paired up to i = 2; the corner
        // block i = 3..=6 × j = 2..=5 (within three live layers of both surfaces).
        let column = |is: std::ops::RangeInclusive<usize>, js: std::ops::RangeInclusive<usize>| {
            let mut v: Vec<[usize; 2]> = js.flat_map(|j| is.clone().map(move |i| [i, j])).collect();
            v.sort_by_key(|n| (n[1], n[0]));
            v
        };
        // The base row j = 0 is held: its live nodes see a held wall to their right, no surface.
        let mut want = vec![column(3..=6, 1..=1), column(0..=1, 2..=5), column(2..=2, 2..=5), column(3..=6, 2..=5)];
        let mut got_sorted = got.clone();
        got_sorted.sort();
        want.sort();
        assert_eq!(got_sorted, want, "groups: {got:?}");
        // Every dof of a grouped node is in its group once.
        let mut all: Vec<usize> = groups.concat();
        let n = all.len();
        all.sort();
        all.dedup();
        assert_eq!(all.len(), n);
    }

    #[test]
    fn no_depth_no_groups_and_a_held_wall_is_no_surface() {
        let (ghost, mut dofs, owned) = block();
        assert!(surface_groups(&ghost, [10, 8], &owned, &dofs, 2, StripShape { depth: 0, width: 2 }).is_empty());
        // Hold the drained layer's motion too: the material now ends at a wall, no surface.
        for l in 0..ghost.len() {
            if dofs.well[l] && dofs.fixed[l * 5 + 2] {
                for c in [0, 1, 3, 4] {
                    dofs.fixed[l * 5 + c] = true;
                }
            }
        }
        let groups = surface_groups(&ghost, [10, 8], &owned, &dofs, 2, StripShape::default());
        assert!(groups.is_empty(), "{:?}", nodes_of(&groups, &ghost));
    }
}
