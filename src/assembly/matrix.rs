//! The Jacobian matrix of a pattern: PETSc AIJ storage preallocated exactly from the node-pair
//! blocks of every rank's pattern, and the place of each of this rank's blocks in it, so that a
//! Jacobian writes its blocks in place ([`petsc::BlockOps::fill_blocks`]) with no coordinate maps
//! beside the matrix (docs/solvers.md, "Assembly").
//!
//! A rank's pattern lists the blocks its points reach, including rows of ghost nodes that another
//! rank owns; those pairs are sent to the owner once per pattern, so that every owned block row
//! lists every block any rank adds to it.

use super::pattern::Pattern;
use super::space::NodeSpace;
use crate::parallel::Collective;
use petsc::{BlockOps, BlockPlaces, Int, Mat};
use std::sync::Arc;

/// The Jacobian matrix, the pattern it was made for and the place of each of the pattern's blocks.
pub(super) struct Matrix<const D: usize> {
    pub mat: Mat,
    pub pattern: Arc<Pattern<D>>,
    pub places: BlockPlaces,
}

impl<const D: usize> Matrix<D> {
    /// The matrix of `pattern` on `space`. Collective.
    pub fn of(pattern: &Arc<Pattern<D>>, space: &NodeSpace<D>, coll: &Collective) -> Result<Matrix<D>, String> {
        let nd = space.layout.nd;
        // A rigid body's master that this rank does not ghost has a virtual index past the ghosted
        // nodes (`super::ties`).
        let ghosted = space.ghost.len();
        let node = |a: u32| match (a as usize).checked_sub(ghosted) {
            None => (space.l2g[a as usize * nd] / nd as i32) as Int,
            Some(k) => pattern.ties.extra[k] as Int,
        };
        let owned = space.owned_nodes.len();
        let counts = coll.gather(&[owned as f64])?;
        let mut starts = vec![0 as Int; counts.len() + 1];
        for (r, &c) in counts.iter().enumerate() {
            starts[r + 1] = starts[r] + c as Int;
        }
        let first = starts[coll.rank()];
        let owner = |n: Int| starts.partition_point(|&s| s <= n) - 1;
        let blocks: Vec<(Int, Int)> = pattern.pairs.iter().map(|&(a, b)| (node(a), node(b))).collect();
        let mut outgoing = vec![Vec::new(); coll.size()];
        let mut rows: Vec<(Int, Int)> = Vec::with_capacity(blocks.len());
        for &(r, c) in &blocks {
            let o = owner(r);
            if o == coll.rank() {
                rows.push((r - first, c));
            } else {
                outgoing[o].extend([r as f64, c as f64]);
            }
        }
        let received = coll.exchange(&outgoing);
        rows.extend(received.chunks_exact(2).map(|p| (p[0] as Int - first, p[1] as Int)));
        rows.sort_unstable();
        rows.dedup();
        let mut row_starts = vec![0 as Int; owned + 1];
        for &(r, _) in &rows {
            row_starts[r as usize + 1] += 1;
        }
        for r in 0..owned {
            row_starts[r + 1] += row_starts[r];
        }
        let cols: Vec<Int> = rows.into_iter().map(|(_, c)| c).collect();
        let made = space.dm.create_matrix_blocks(&row_starts, &cols);
        drop(cols);
        let mat = coll.agree(made.map_err(|e| e.to_string()))?;
        let places = coll.agree(mat.block_places(nd, &blocks).map_err(|e| e.to_string()))?;
        Ok(Matrix { mat, pattern: pattern.clone(), places })
    }
}
