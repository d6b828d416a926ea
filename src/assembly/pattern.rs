//! The matrix pattern of a step as a list of node-pair blocks, and where each particle adds its
//! tangent into it (step 5 of a step), in any dimension.
//!
//! The list holds each (node a, node b) block of dofs once: the pairs of every particle's effective
//! stencil and the diagonal block of every owned node (so that fixed dofs always find their unit
//! diagonal). A Jacobian adds every particle's dense block straight into the matrix's storage at
//! the place of each of its node-pair blocks ([`super::matrix`]), which is several times faster
//! than inserting the blocks one by one (docs/solvers.md). A particle finds the block of a pair
//! through a dense table indexed by the first node and the pair's offset on the grid (no
//! per-particle map: that map cost more memory than the particles themselves on the peer
//! footing). The table spans the offsets of the pairs within the raw stencils of 99 % of the
//! particles, at most ±3 nodes: it holds (2r + 1)^D entries per ghosted node for that offset r
//! (r = 2 for GIMP and quadratic B-splines, 125 entries, 500 bytes, in three dimensions; r = 3 for
//! cubic B-splines, 343), against the matrix's own 3 × 375 entries per node of a three-dimensional
//! solid (about 13 kB) or 7 × 875 of a u–p–U system (about 73 kB). The few pairs farther apart (the
//! rest of the particles, an extended node's masters, the nodes of a tied face) are kept in a map.
//!
//! The pattern is kept from step to step while every pair a particle needs is already in it (the
//! matrix then keeps its structure, and a direct solver its symbolic factorisation); otherwise a
//! new one is built. The decision involves a collective (the matrix is created on all ranks), so the
//! caller agrees on it across ranks.

use super::stencils::Stencils;
use std::collections::HashMap;

/// No block.
const NONE: u32 = u32::MAX;

/// Offsets (Δi, Δj, Δk) within ±`reach` ≤ REACH nodes are looked up in a dense table; farther
/// ones in a map.
const REACH: i64 = 3;

/// The rigid-body ties of a pattern on this rank ([`super::ties::pattern_ties`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PatternTies {
    /// (tied node, master node) for every ghosted node with a tied dof, sorted.
    pub pairs: Vec<(u32, u32)>,
    /// The global node numbers of the virtual masters, in order of their indices.
    pub extra: Vec<i32>,
    /// Each master's node (in the order of `DofMap::ties`): its ghosted index, or where this rank
    /// does not ghost it a virtual index past the ghosted nodes.
    pub masters: Vec<u32>,
}

/// The node-pair blocks of the matrix, on a ghosted grid of dimension `D`.
#[derive(Debug, Clone)]
pub struct Pattern<const D: usize = 2> {
    /// Ghosted-node pairs (a, b), one nd × nd block each, in list order.
    pub pairs: Vec<(u32, u32)>,
    /// Dense lookup: `near[a · (2 reach + 1)^D + offset(a, b)]` is the block of (a, b).
    near: Vec<u32>,
    /// The largest offset per direction the dense table spans (at most REACH).
    reach: i64,
    /// The table's width per direction, 2 reach + 1, and its entries per node, width^D.
    width: usize,
    stride: usize,
    /// Pairs whose nodes are farther apart than `reach`.
    far: HashMap<(u32, u32), u32>,
    /// Nodes of the ghosted grid per direction (to turn node numbers into indices).
    counts: [usize; D],
    /// The blocks of row node a are `row_start[a]..row_start[a + 1]` (the list is sorted by
    /// (a, b), so that the blocks of a range of row nodes are one range of the list).
    row_start: Vec<u32>,
    /// The rigid-body ties it was built for ([`Pattern::tie`]): the master nodes past the
    /// ghosted ones are virtual, named by their global numbers (`ties.extra`).
    pub ties: PatternTies,
}

impl<const D: usize> Default for Pattern<D> {
    fn default() -> Self {
        let mut p = Pattern {
            pairs: Vec::new(),
            near: Vec::new(),
            reach: 0,
            width: 0,
            stride: 0,
            far: HashMap::new(),
            counts: [0; D],
            row_start: Vec::new(),
            ties: Default::default(),
        };
        p.set_reach(REACH);
        p
    }
}

/// The two-dimensional forms with (i, j) indices.
impl Pattern {
    /// The grid coordinates (i, j) of ghosted node `a`.
    pub fn ij(&self, a: u32) -> (i64, i64) {
        let [i, j] = self.indices(a);
        (i, j)
    }

    /// The block of pair (a, b) with the nodes' grid coordinates given (see [`Pattern::ij`]);
    /// `u32::MAX` if the pattern lacks it.
    #[inline]
    pub fn block_at(&self, a: u32, ija: (i64, i64), b: u32, ijb: (i64, i64)) -> u32 {
        self.block_of(a, [ija.0, ija.1], b, [ijb.0, ijb.1])
    }

    /// The pattern of the particles' effective stencils, the `owned` nodes' diagonal blocks and the
    /// pairs of each of the node `groups` (tied faces, pressure-projection cells), on a ghosted grid
    /// of `nx × ny` nodes.
    pub fn build(st: &Stencils, owned: &[u32], groups: &[Vec<u32>], nx: usize, ny: usize) -> Pattern {
        Pattern::build_in(st, owned, groups, [nx, ny])
    }
}

impl<const D: usize> Pattern<D> {
    /// The bytes the pattern holds on the heap (the hash map's entries at its capacity, with one
    /// control byte each).
    pub fn heap_bytes(&self) -> usize {
        use crate::algebra::heap::capacity as c;
        let far = self.far.capacity() * (std::mem::size_of::<((u32, u32), u32)>() + 1);
        c(&self.pairs) + c(&self.near) + c(&self.row_start) + far
    }

    /// The place in the dense table of the pair of nodes a (indices `ia`) and b (indices `ib`),
    /// if their offset is within the table's reach in every direction.
    #[inline]
    fn near_index(&self, a: u32, ia: [i64; D], ib: [i64; D]) -> Option<usize> {
        let (reach, width) = (self.reach, self.width);
        let mut at = 0usize;
        for d in (0..D).rev() {
            let o = ib[d] - ia[d];
            if o.abs() > reach {
                return None;
            }
            at = at * width + (o + reach) as usize;
        }
        Some(a as usize * self.stride + at)
    }

    fn offset(&self, a: u32, b: u32) -> Option<usize> {
        // A virtual master node ([`Pattern::tie`]) has no place on the grid: its pairs are kept in
        // the map.
        let ghosted = self.ghosted();
        if a as usize >= ghosted || b as usize >= ghosted {
            return None;
        }
        self.near_index(a, self.indices(a), self.indices(b))
    }

    /// The ghosted nodes of the grid.
    fn ghosted(&self) -> usize {
        self.counts.iter().product()
    }

    /// Adds the rigid bodies' pairs ([`super::ties`]): for each (tied node s, master m) of `ties`,
    /// (s, m), then (m, b) for every block (s, b) of the row so completed (its own masters' columns
    /// included, (m, m) among them, and repeated while rows grow), so that a tied row can be moved
    /// into each of its masters' and hold its constraint.
    pub fn tie(&mut self, ties: PatternTies) {
        let nodes = self.ghosted() + ties.extra.len();
        for &(s, m) in &ties.pairs {
            self.insert(s, m);
        }
        self.sort(nodes);
        // Until no pair is new: a master's row grows by its slaves' blocks, and a master that is
        // itself tied in another direction moves that grown row on.
        loop {
            let before = self.pairs.len();
            let mut add = Vec::new();
            for &(s, m) in &ties.pairs {
                add.extend(self.pairs[self.row_start(s)..self.row_start(s + 1)].iter().map(|&(_, b)| (m, b)));
            }
            for (a, b) in add {
                self.insert(a, b);
            }
            self.sort(nodes);
            if self.pairs.len() == before {
                break;
            }
        }
        self.ties = ties;
    }

    /// The grid indices of ghosted node `a` (x fastest).
    pub fn indices(&self, a: u32) -> [i64; D] {
        let mut a = a as usize;
        std::array::from_fn(|d| {
            let i = a % self.counts[d];
            a /= self.counts[d];
            i as i64
        })
    }

    /// The block of pair (a, b) with the nodes' grid indices given (see [`Pattern::indices`]);
    /// `u32::MAX` if the pattern lacks it.
    #[inline]
    pub fn block_of(&self, a: u32, ia: [i64; D], b: u32, ib: [i64; D]) -> u32 {
        match self.near_index(a, ia, ib) {
            Some(o) => self.near[o],
            None => *self.far.get(&(a, b)).unwrap_or(&NONE),
        }
    }

    /// The blocks of the pairs (nodes[p], nodes[q]) for every node q of one stencil, whose grid
    /// indices are `indices` ([`Pattern::indices`]), into `out` (`u32::MAX` where the pattern
    /// lacks a pair). `codes` are [`Pattern::codes`] of the stencil: where it spans no more than
    /// the dense table's reach, every block is one load of the table.
    pub fn row_blocks(
        &self,
        nodes: &[u32],
        indices: &[[i64; D]],
        codes: Option<&[usize]>,
        p: usize,
        out: &mut Vec<usize>,
    ) {
        out.clear();
        match codes {
            Some(codes) => {
                let base = nodes[p] as usize * self.stride + self.centre() - codes[p];
                out.extend(codes.iter().map(|&c| self.near[base + c] as usize));
            }
            None => {
                out.extend((0..nodes.len()).map(|q| self.block_of(nodes[p], indices[p], nodes[q], indices[q]) as usize))
            }
        }
    }

    /// The places in the dense table of a stencil's nodes with grid indices `indices` relative to
    /// its first corner, Σ_d i_d width^d, if the stencil spans no more than the table's reach in
    /// every direction (so that the place of a pair is the difference of theirs plus the centre's).
    pub fn codes(&self, indices: &[[i64; D]], out: &mut Vec<usize>) -> bool {
        out.clear();
        let Some(first) = indices.first() else { return true };
        let (mut lo, mut hi) = (*first, *first);
        for ix in indices {
            for d in 0..D {
                lo[d] = lo[d].min(ix[d]);
                hi[d] = hi[d].max(ix[d]);
            }
        }
        if (0..D).any(|d| hi[d] - lo[d] > self.reach) {
            return false;
        }
        out.extend(indices.iter().map(|ix| (0..D).rev().fold(0, |at, d| at * self.width + (ix[d] - lo[d]) as usize)));
        true
    }

    /// The place in the dense table of a node's pair with itself (every offset zero).
    fn centre(&self) -> usize {
        (0..D).fold(0, |at, _| at * self.width + self.reach as usize)
    }

    /// The block of pair (a, b), if the pattern has it.
    pub fn block(&self, a: u32, b: u32) -> Option<u32> {
        let v = match self.offset(a, b) {
            Some(o) => self.near[o],
            None => *self.far.get(&(a, b)).unwrap_or(&NONE),
        };
        (v != NONE).then_some(v)
    }

    fn insert(&mut self, a: u32, b: u32) -> u32 {
        if let Some(v) = self.block(a, b) {
            return v;
        }
        let v = self.pairs.len() as u32;
        self.pairs.push((a, b));
        match self.offset(a, b) {
            Some(o) => self.near[o] = v,
            None => {
                self.far.insert((a, b), v);
            }
        }
        v
    }

    /// Inserts every pair of the `nodes` (a block of the matrix each).
    fn insert_group(&mut self, nodes: &[u32]) {
        for &a in nodes {
            for &b in nodes {
                self.insert(a, b);
            }
        }
    }

    /// The pattern of the particles' effective stencils, the `owned` nodes' diagonal blocks and the
    /// pairs of each of the node `groups` (tied faces, pressure-projection cells), on a ghosted grid
    /// of `counts` nodes per direction.
    pub fn build_in(st: &Stencils<D>, owned: &[u32], groups: &[Vec<u32>], counts: [usize; D]) -> Pattern<D> {
        let nodes: usize = counts.iter().product();
        let mut p = Pattern { counts, ..Pattern::default() };
        // The table spans the raw stencils of all but at most one in a hundred particles (the
        // basis's support; B̄'s cells that take a neighbour's volumetric strain reach one node
        // farther); the pairs beyond it, of those particles, of an extension's masters or of a
        // group, go to the map.
        let mut count = [0usize; REACH as usize + 1];
        for k in 0..st.len() {
            count[p.extent(&st.nodes[st.offsets[k]..st.offsets[k + 1]]).min(REACH) as usize] += 1;
        }
        let (mut covered, mut r) = (0, 0);
        while r < REACH as usize && (covered + count[r]) * 100 < st.len() * 99 {
            covered += count[r];
            r += 1;
        }
        p.set_reach((r as i64).max(1));
        p.near = vec![NONE; nodes * p.stride];
        for &a in owned {
            p.insert(a, a);
        }
        for k in 0..st.len() {
            p.insert_group(st.effective(k));
        }
        for g in groups {
            p.insert_group(g);
        }
        p.sort(nodes);
        p
    }

    /// The pattern of the pairs within each of `groups` and the diagonal blocks of the
    /// `diagonals` and of the `owned` nodes, on a ghosted grid of `counts` nodes per direction; the
    /// dense table spans neighbouring nodes (the preconditioning matrix of [`super::lowered`],
    /// whose groups are cells' corners).
    pub fn of_groups<'g>(
        groups: impl Iterator<Item = &'g [u32]>,
        diagonals: impl Iterator<Item = u32>,
        owned: &[u32],
        counts: [usize; D],
    ) -> Pattern<D> {
        let nodes: usize = counts.iter().product();
        let mut p = Pattern { counts, ..Pattern::default() };
        p.set_reach(1);
        p.near = vec![NONE; nodes * p.stride];
        for a in owned.iter().copied().chain(diagonals) {
            p.insert(a, a);
        }
        for g in groups {
            p.insert_group(g);
        }
        p.sort(nodes);
        p
    }

    /// (diagonal block, component) of each of the owned fixed dofs `owned_fixed` ((owned index,
    /// ghosted dof) pairs, [`super::dofs::DofMap::owned_fixed`]) of `nd` dofs per node.
    pub fn fixed_diagonals(&self, owned_fixed: &[(usize, usize)], nd: usize) -> Result<Vec<(u32, usize)>, String> {
        owned_fixed
            .iter()
            .map(|&(_, q)| {
                let node = (q / nd) as u32;
                self.block(node, node)
                    .map(|b| (b, q % nd))
                    .ok_or_else(|| "an owned diagonal block is not listed".into())
            })
            .collect()
    }

    /// Sets the dense table's reach and the width and stride derived from it (kept so that a
    /// lookup does not form them).
    fn set_reach(&mut self, reach: i64) {
        self.reach = reach;
        self.width = 2 * reach as usize + 1;
        self.stride = self.width.pow(D as u32);
    }

    /// The largest offset in any direction between two of the ghosted `nodes`.
    fn extent(&self, nodes: &[u32]) -> i64 {
        if nodes.is_empty() {
            return 0;
        }
        let (mut lo, mut hi) = ([i64::MAX; D], [i64::MIN; D]);
        for &a in nodes {
            let i = self.indices(a);
            for d in 0..D {
                lo[d] = lo[d].min(i[d]);
                hi[d] = hi[d].max(i[d]);
            }
        }
        (0..D).map(|d| hi[d] - lo[d]).max().unwrap_or(0)
    }

    /// Sorts the list by (a, b) and renumbers the blocks accordingly.
    fn sort(&mut self, nodes: usize) {
        self.pairs.sort_unstable();
        self.far.clear();
        for (v, &(a, b)) in self.pairs.iter().enumerate() {
            match self.offset(a, b) {
                Some(o) => self.near[o] = v as u32,
                None => {
                    self.far.insert((a, b), v as u32);
                }
            }
        }
        self.row_start = vec![0; nodes + 1];
        for &(a, _) in &self.pairs {
            self.row_start[a as usize + 1] += 1;
        }
        for a in 0..nodes {
            self.row_start[a + 1] += self.row_start[a];
        }
    }

    /// The first block of row node `a` (`a` may be one past the last node).
    pub fn row_start(&self, a: u32) -> usize {
        self.row_start[a as usize] as usize
    }

    /// Whether the pattern holds every pair of every particle's effective nodes, and was tied as
    /// `ties` says.
    pub fn covers(&self, st: &Stencils<D>, ties: &PatternTies) -> bool {
        self.ties == *ties
            && (0..st.len()).all(|k| {
                let eff = st.effective(k);
                eff.iter().all(|&a| eff.iter().all(|&b| self.block(a, b).is_some()))
            })
    }

    /// Number of blocks.
    pub fn len(&self) -> usize {
        self.pairs.len()
    }

    /// Whether the pattern is empty.
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }

    /// The COO lists (global row and column of every entry, block by block, row-major in a block)
    /// for `nd` dofs per node, with `l2g` the global index of every ghosted dof.
    pub fn coo(&self, nd: usize, l2g: &[i32]) -> (Vec<i32>, Vec<i32>) {
        let n = self.pairs.len() * nd * nd;
        let (mut rows, mut cols) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for &(a, b) in &self.pairs {
            for c1 in 0..nd {
                for c2 in 0..nd {
                    rows.push(l2g[a as usize * nd + c1]);
                    cols.push(l2g[b as usize * nd + c2]);
                }
            }
        }
        (rows, cols)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stencils(lists: &[&[u32]]) -> Stencils {
        let mut st = Stencils::default();
        st.offsets.push(0);
        st.eff_offsets.push(0);
        for l in lists {
            st.nodes.extend_from_slice(l);
            st.eff_nodes.extend_from_slice(l);
            st.offsets.push(st.nodes.len());
            st.eff_offsets.push(st.eff_nodes.len());
        }
        st
    }

    /// Ties to a master this rank ghosts (node 12) and to a virtual one (index 100, past the 10 × 10
    /// ghosted nodes): every block (s, b) of a tied row finds (m, b), and (s, m) and (m, m) exist;
    /// the virtual row's blocks are the last rows of the list.
    #[test]
    fn a_tied_row_finds_its_blocks_in_the_master_row() {
        let st = stencils(&[&[11, 12, 21, 22], &[12, 13, 22, 23], &[55, 56, 65, 66]]);
        let mut p = Pattern::build(&st, &[11, 55], &[], 10, 10);
        let ties = super::PatternTies {
            pairs: vec![(13, 12), (23, 12), (56, 100), (66, 100)],
            extra: vec![4711],
            masters: vec![12, 100],
        };
        p.tie(ties.clone());
        for &(s, m) in &ties.pairs {
            let row: Vec<u32> = p.pairs[p.row_start(s)..p.row_start(s + 1)].iter().map(|&(_, b)| b).collect();
            assert!(row.contains(&m), "({s}, {m})");
            for b in row {
                assert!(p.block(m, b).is_some(), "({m}, {b}) for the tied row {s}");
            }
        }
        assert!(p.pairs.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(p.row_start(101), p.len());
        assert_eq!(p.row_start(100), p.len() - (p.row_start(101) - p.row_start(100)));
        assert!(p.covers(&st, &ties) && !p.covers(&st, &Default::default()));
    }

    #[test]
    fn pairs_are_listed_once_and_every_particle_finds_its_blocks() {
        // A 10 × 10 ghosted grid; two particles sharing nodes, one reaching 5 columns (a far pair).
        let st = stencils(&[&[11, 12, 21, 22], &[12, 13, 22, 23], &[30, 35]]);
        let p = Pattern::build(&st, &[11], &[], 10, 10);
        // 16 + 16 − 4 shared + 4 for the far particle; (11, 11) is already a particle pair.
        assert_eq!(p.len(), 16 + 16 - 4 + 4);
        assert!(p.covers(&st, &Default::default()));
        // Sorted by (a, b), with the rows' ranges.
        assert!(p.pairs.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(p.row_start(12) - p.row_start(11), 4);
        assert_eq!(p.pairs[p.row_start(30)], (30, 30));
        assert_eq!(p.row_start(100), p.len());
        assert_eq!(p.pairs[p.block(12, 13).unwrap() as usize], (12, 13));
        assert_eq!(p.block_at(12, p.ij(12), 13, p.ij(13)), p.block(12, 13).unwrap());
        assert_eq!(p.pairs[p.block(30, 35).unwrap() as usize], (30, 35));
        assert_eq!(p.block_at(30, p.ij(30), 35, p.ij(35)), p.block(30, 35).unwrap());
        assert_eq!(p.block_at(30, p.ij(30), 36, p.ij(36)), NONE);
        // A particle needing a pair the pattern lacks.
        let other = stencils(&[&[11, 44]]);
        assert!(!p.covers(&other, &Default::default()));
        let (rows, cols) = p.coo(2, &(0..200).collect::<Vec<i32>>());
        assert_eq!(rows.len(), p.len() * 4);
        assert_eq!((rows[1], cols[1]), (22, 23));
    }

    /// In three dimensions: every pair of 27-node stencils (and a far pair) listed once, found by
    /// its indices and by its nodes, in row order.
    #[test]
    fn a_three_dimensional_pattern_lists_and_finds_every_pair() {
        let counts = [6usize, 5, 7];
        let node = |i: usize, j: usize, k: usize| (i + counts[0] * (j + counts[1] * k)) as u32;
        let cube = |c: [usize; 3]| -> Vec<u32> {
            let mut v = Vec::new();
            for k in 0..3 {
                for j in 0..3 {
                    for i in 0..3 {
                        v.push(node(c[0] + i, c[1] + j, c[2] + k));
                    }
                }
            }
            v
        };
        let (a, b) = (cube([0, 0, 0]), cube([1, 1, 2]));
        let far = vec![node(0, 0, 0), node(5, 4, 6)];
        let mut st = Stencils::<3>::default();
        st.offsets.push(0);
        st.eff_offsets.push(0);
        for l in [&a, &b, &far] {
            st.nodes.extend_from_slice(l);
            st.eff_nodes.extend_from_slice(l);
            st.offsets.push(st.nodes.len());
            st.eff_offsets.push(st.eff_nodes.len());
        }
        let p = Pattern::build_in(&st, &[node(5, 0, 0)], &[], counts);
        // The overlap of the two cubes: i, j ∈ {1, 2}, k = 2: 4 nodes, 16 pairs.
        assert_eq!(p.len(), 27 * 27 + 27 * 27 - 16 + 3 + 1);
        assert!(p.covers(&st, &Default::default()));
        assert!(p.pairs.windows(2).all(|w| w[0] < w[1]));
        for &(x, y) in &p.pairs {
            let v = p.block(x, y).unwrap();
            assert_eq!(p.pairs[v as usize], (x, y));
            assert_eq!(p.block_of(x, p.indices(x), y, p.indices(y)), v);
        }
        assert_eq!(p.indices(node(4, 3, 5)), [4, 3, 5]);
        assert_eq!(p.block(node(0, 0, 0), node(4, 0, 0)), None);
        assert_eq!(p.row_start(node(5, 4, 6) + 1), p.len());
        // The far pair (6 nodes apart) needs the widest table, ±3 nodes, and the map.
        assert_eq!((p.reach, p.near.len(), p.far.len()), (3, 210 * 343, 2));
        // The two 27-node stencils alone span ±2 nodes: a table of 125 entries per node, every
        // pair found in it.
        let two = Stencils::<3> {
            offsets: vec![0, 27, 54],
            nodes: [&a[..], &b[..]].concat(),
            eff_offsets: vec![0, 0, 0],
            ..Default::default()
        };
        let q = Pattern::build_in(&two, &[], &[], counts);
        assert_eq!((q.reach, q.near.len(), q.far.len(), q.len()), (2, 210 * 125, 0, 27 * 27 * 2 - 16));
        assert!(q.covers(&two, &Default::default()));
        assert!(q.pairs.iter().all(|&(x, y)| q.pairs[q.block(x, y).unwrap() as usize] == (x, y)));
        assert!(!q.covers(&st, &Default::default()));
        // A master beyond the raw stencil (three nodes from its first): the table keeps its raw
        // reach, the master's pairs three apart are in the map and found.
        let extended = Stencils::<3> {
            offsets: vec![0, 27],
            nodes: a.clone(),
            eff_offsets: vec![0, 28],
            eff_nodes: [&a[..], &[node(3, 0, 0)]].concat(),
            ..Default::default()
        };
        let e = Pattern::build_in(&extended, &[], &[], counts);
        assert_eq!((e.reach, e.len()), (2, 28 * 28));
        assert_eq!(e.far.len(), 2 * 9);
        assert!(e.covers(&extended, &Default::default()));
        assert_eq!(e.pairs[e.block(node(0, 1, 2), node(3, 0, 0)).unwrap() as usize], (node(0, 1, 2), node(3, 0, 0)));
    }
}
