//! Matrices of node-pair blocks with an exact pattern: created from a block compressed-row list
//! ([`crate::DmDa::create_matrix_blocks`]) and filled by writing each block straight into the
//! AIJ value arrays at a place found once per pattern ([`BlockPlaces`]), without the coordinate
//! maps that `MatSetPreallocationCOO` keeps (two 8-byte integers per nonzero) and without a
//! search per entry. Blocks of rows another rank owns go to their owner through PETSc's stash.

use crate::mat::MatOps;
use crate::{Error, Int, Real, Result};
use petsc_sys as sys;

/// Marks a place in the off-diagonal (other ranks' columns) part of a distributed AIJ matrix.
const OFF: u32 = 1 << 31;
/// A block of a row this rank does not own.
const REMOTE: u32 = u32::MAX;

/// Where each block of a list of node-pair blocks sits in a matrix's value arrays.
#[derive(Debug, Clone, Default)]
pub struct BlockPlaces {
    /// Rows and columns per block.
    bs: usize,
    /// The block's local block row, or [`REMOTE`].
    row: Vec<u32>,
    /// The offset of the block's first column in each of its rows, within the row's part of the
    /// compressed-row storage ([`OFF`] set for the off-diagonal part); for a block of a row
    /// another rank owns, its index in `remote`.
    at: Vec<u32>,
    /// The first entry of every local row in the diagonal part, then in the off-diagonal part.
    diag_rows: Vec<Int>,
    off_rows: Vec<Int>,
    /// Blocks of rows other ranks own, in the order of the list: (block, global block row,
    /// global block column).
    remote: Vec<(u32, Int, Int)>,
}

impl BlockPlaces {
    /// The bytes held on the heap.
    pub fn heap_bytes(&self) -> usize {
        self.row.capacity() * 4
            + self.at.capacity() * 4
            + (self.diag_rows.capacity() + self.off_rows.capacity()) * std::mem::size_of::<Int>()
            + self.remote.capacity() * std::mem::size_of::<(u32, Int, Int)>()
    }

    /// Number of blocks.
    pub fn len(&self) -> usize {
        self.row.len()
    }

    /// Whether there are no blocks.
    pub fn is_empty(&self) -> bool {
        self.row.is_empty()
    }
}

/// The diagonal and off-diagonal sequential parts of an AIJ matrix (the matrix itself and none
/// on one rank) with the global column of every off-diagonal column.
struct Parts {
    diag: sys::Mat,
    off: Option<(sys::Mat, *const Int)>,
}

fn parts(m: sys::Mat) -> Result<Parts> {
    let mut mpi = sys::PetscBool::PETSC_FALSE;
    call!(PetscObjectTypeCompare(m as sys::PetscObject, sys::MATMPIAIJ.as_ptr() as *const _, &mut mpi))?;
    if !crate::from_bool(mpi) {
        let mut seq = sys::PetscBool::PETSC_FALSE;
        call!(PetscObjectTypeCompare(m as sys::PetscObject, sys::MATSEQAIJ.as_ptr() as *const _, &mut seq))?;
        if !crate::from_bool(seq) {
            return Err(Error::new("block places need an AIJ matrix (mpiaij or seqaij)"));
        }
        return Ok(Parts { diag: m, off: None });
    }
    let (mut ad, mut ao, mut garray) = (std::ptr::null_mut(), std::ptr::null_mut(), std::ptr::null());
    call!(MatMPIAIJGetSeqAIJ(m, &mut ad, &mut ao, &mut garray))?;
    Ok(Parts { diag: ad, off: Some((ao, garray)) })
}

/// `f` of the compressed rows (row starts, columns) of a sequential AIJ matrix, borrowed from it.
fn with_rows_of<R>(m: sys::Mat, f: impl FnOnce(&[Int], &[Int]) -> R) -> Result<R> {
    let (mut n, mut ia, mut ja) = (0 as Int, std::ptr::null(), std::ptr::null());
    let mut done = sys::PetscBool::PETSC_FALSE;
    let no = sys::PetscBool::PETSC_FALSE;
    call!(MatGetRowIJ(m, 0, no, no, &mut n, &mut ia, &mut ja, &mut done))?;
    if !crate::from_bool(done) {
        return Err(Error::new("MatGetRowIJ gave no compressed rows"));
    }
    // SAFETY: MatGetRowIJ returned n + 1 row starts and ia[n] column indices, valid until
    // MatRestoreRowIJ, which follows; the slices do not outlive `f`.
    let out = unsafe {
        let starts = std::slice::from_raw_parts(ia, n as usize + 1);
        let cols = std::slice::from_raw_parts(ja, starts[n as usize] as usize);
        f(starts, cols)
    };
    call!(MatRestoreRowIJ(m, 0, no, no, &mut n, &mut ia, &mut ja, &mut done))?;
    Ok(out)
}

/// The value array of a sequential AIJ matrix of `nnz` stored entries for the time of `f`.
fn with_values<R>(m: sys::Mat, nnz: usize, f: impl FnOnce(&mut [Real]) -> R) -> Result<R> {
    let mut a: *mut Real = std::ptr::null_mut();
    call!(MatSeqAIJGetArray(m, &mut a))?;
    // SAFETY: the array holds the matrix's nnz values and stays valid until
    // MatSeqAIJRestoreArray, which follows; no other view of it exists meanwhile.
    let out = f(unsafe { std::slice::from_raw_parts_mut(a, nnz) });
    call!(MatSeqAIJRestoreArray(m, &mut a))?;
    Ok(out)
}

/// Operations of block-pattern matrices, for owned and borrowed handles.
pub trait BlockOps: MatOps {
    /// The places of `blocks` (global block row, global block column) of `bs` × `bs` entries
    /// each in this matrix, whose pattern must hold every entry of every block of an owned row
    /// with the same columns in the block's `bs` rows (as
    /// [`crate::DmDa::create_matrix_blocks`] makes it). Not collective.
    fn block_places(&self, bs: usize, blocks: &[(Int, Int)]) -> Result<BlockPlaces> {
        if bs == 0 || bs > MAX_BS {
            return Err(Error::new(format!("blocks of {bs} rows: 1 to {MAX_BS} are supported")));
        }
        let (lo, hi) = self.ownership_range()?;
        let (lo, hi) = (lo as Int, hi as Int);
        let b = bs as Int;
        let parts = parts(self.raw())?;
        let (off_rows, off_cols) = match parts.off {
            Some((ao, garray)) => with_rows_of(ao, |rows, local| {
                let n = local.iter().map(|&c| c + 1).max().unwrap_or(0) as usize;
                // SAFETY: garray holds the global column of each of the off-diagonal part's
                // columns, at least as many as its largest local column index + 1.
                let global = unsafe { std::slice::from_raw_parts(garray, n) };
                (rows.to_vec(), local.iter().map(|&c| global[c as usize]).collect::<Vec<Int>>())
            })?,
            None => (Vec::new(), Vec::new()),
        };
        with_rows_of(parts.diag, |diag_rows, diag_cols| {
            let off_rows = if parts.off.is_some() { off_rows } else { vec![0; diag_rows.len()] };
            let mut places = BlockPlaces { bs, diag_rows: diag_rows.to_vec(), off_rows, ..BlockPlaces::default() };
            places.row.reserve_exact(blocks.len());
            places.at.reserve_exact(blocks.len());
            for (k, &(r, c)) in blocks.iter().enumerate() {
                if r * b < lo || r * b >= hi {
                    places.row.push(REMOTE);
                    places.at.push(places.remote.len() as u32);
                    places.remote.push((k as u32, r, c));
                    continue;
                }
                let local = (r * b - lo) as usize;
                let (rows, cols, shift, flag) = if c * b >= lo && c * b < hi {
                    (diag_rows, diag_cols, lo, 0)
                } else {
                    (&places.off_rows[..], &off_cols[..], 0, OFF)
                };
                let row = |i: usize| &cols[rows[local + i] as usize..rows[local + i + 1] as usize];
                let at = row(0)
                    .binary_search(&(c * b - shift))
                    .map_err(|_| Error::new(format!("block ({r}, {c}) is not in the matrix's pattern")))?;
                // Every row of the block has the block's columns at the same offset.
                for i in 0..bs {
                    let cs = row(i);
                    if at + bs > cs.len() || (0..bs).any(|j| cs[at + j] != c * b - shift + j as Int) {
                        return Err(Error::new(format!("block ({r}, {c}) is not whole in row {i} of its block row")));
                    }
                }
                places.row.push((local / bs) as u32);
                places.at.push(at as u32 | flag);
            }
            Ok(places)
        })?
    }

    /// Sets the matrix to the sum over all ranks of what `fill` writes into its blocks
    /// ([`BlockFill`], starting from zeros), and assembles it: owned rows are written in place,
    /// other ranks' rows sent to their owners. Collective.
    fn fill_blocks<R>(&mut self, places: &BlockPlaces, fill: impl FnOnce(&mut BlockFill<'_>) -> R) -> Result<R> {
        let bs = places.bs;
        self.zero_entries()?;
        let parts = parts(self.raw())?;
        let mut remote = vec![0.0; places.remote.len() * bs * bs];
        let nnz = |starts: &[Int]| starts.last().map_or(0, |&n| n as usize);
        let out = with_values(parts.diag, nnz(&places.diag_rows), |diag| match parts.off {
            Some((ao, _)) => with_values(ao, nnz(&places.off_rows), |off| {
                fill(&mut BlockFill { places, diag, off, remote: &mut remote })
            }),
            None => Ok(fill(&mut BlockFill { places, diag, off: &mut [], remote: &mut remote })),
        })??;
        let mut rows = vec![0 as Int; bs];
        let mut cols = vec![0 as Int; bs];
        for (i, &(_, r, c)) in places.remote.iter().enumerate() {
            for j in 0..bs {
                rows[j] = r * bs as Int + j as Int;
                cols[j] = c * bs as Int + j as Int;
            }
            self.set_values(&rows, &cols, &remote[i * bs * bs..(i + 1) * bs * bs], true)?;
        }
        self.assemble()?;
        Ok(out)
    }

    /// Sets the matrix to the sum of `values` (block after block in the order of `places`, each
    /// row-major) over all ranks, and assembles it ([`BlockOps::fill_blocks`]). Collective.
    fn set_blocks(&mut self, places: &BlockPlaces, values: &[Real]) -> Result<()> {
        let bs = places.bs;
        if values.len() != places.len() * bs * bs {
            return Err(Error::new("block values do not match their places"));
        }
        self.fill_blocks(places, |fill| {
            for (k, block) in values.chunks_exact(bs * bs).enumerate() {
                for (i, row) in block.chunks_exact(bs).enumerate() {
                    fill.row_mut(k, i).iter_mut().zip(row).for_each(|(a, v)| *a += v);
                }
            }
        })
    }
}

/// Where row `i` of block `k` starts: in the diagonal part, the off-diagonal part or the buffer
/// of other ranks' rows, as an index into the whole array.
enum Slot {
    Diag(usize),
    Off(usize),
    Remote(usize),
}

fn slot(places: &BlockPlaces, k: usize, i: usize) -> Slot {
    let (row, at) = (places.row[k], places.at[k]);
    let bs = places.bs;
    if row == REMOTE {
        return Slot::Remote((at as usize * bs + i) * bs);
    }
    let r = row as usize * bs + i;
    if at & OFF == 0 {
        Slot::Diag(places.diag_rows[r] as usize + at as usize)
    } else {
        Slot::Off(places.off_rows[r] as usize + (at & !OFF) as usize)
    }
}

/// The values of a block matrix open for writing ([`BlockOps::fill_blocks`]): each block of the
/// places' list reached by its index, those of owned rows in the matrix's own arrays, those of
/// other ranks' rows in a buffer sent to their owners when the fill ends.
pub struct BlockFill<'a> {
    places: &'a BlockPlaces,
    diag: &'a mut [Real],
    off: &'a mut [Real],
    remote: &'a mut [Real],
}

impl BlockFill<'_> {
    /// Row `i` of block `k` (its `bs` values).
    pub fn row_mut(&mut self, k: usize, i: usize) -> &mut [Real] {
        let bs = self.places.bs;
        match slot(self.places, k, i) {
            Slot::Diag(s) => &mut self.diag[s..s + bs],
            Slot::Off(s) => &mut self.off[s..s + bs],
            Slot::Remote(s) => &mut self.remote[s..s + bs],
        }
    }

    /// Multiplies row `c` of every block by `s`, then column `c`.
    pub fn scale_row_and_column(&mut self, c: usize, s: Real) {
        for k in 0..self.places.len() {
            self.row_mut(k, c).iter_mut().for_each(|v| *v *= s);
            for i in 0..self.places.bs {
                self.row_mut(k, i)[c] *= s;
            }
        }
    }

    /// The fill cut into bands of consecutive blocks, band `b` holding the blocks from `cuts[b]`
    /// to `cuts[b + 1]` (`cuts` rising from 0 to the number of blocks), each to be written by its
    /// own thread: the blocks of a band must sit in block rows no other band's blocks sit in,
    /// those of the owned rows in a range of rows that rises from band to band (as bands of whole
    /// node rows of a DMDA's ghosted grid do).
    pub fn bands(&mut self, cuts: &[usize]) -> Result<Vec<BlockBand<'_>>> {
        let places = self.places;
        let bs = places.bs;
        if cuts.first() != Some(&0) || cuts.last() != Some(&places.len()) || cuts.windows(2).any(|w| w[0] > w[1]) {
            return Err(Error::new("block bands must rise from the first block to the last"));
        }
        let (mut diag, mut off, mut remote): (&mut [Real], &mut [Real], &mut [Real]) =
            (&mut *self.diag, &mut *self.off, &mut *self.remote);
        let (mut diag0, mut off0, mut remote0, mut row_end) = (0, 0, 0, 0usize);
        let mut out = Vec::with_capacity(cuts.len() - 1);
        for w in cuts.windows(2) {
            let (blocks, rows) = (w[0]..w[1], places.row[w[0]..w[1]].iter().filter(|&&r| r != REMOTE));
            let (lo, hi) = rows.fold((usize::MAX, 0), |(lo, hi), &r| (lo.min(r as usize), hi.max(r as usize + 1)));
            let (lo, hi) = if lo == usize::MAX { (row_end, row_end) } else { (lo, hi) };
            row_end = hi;
            let remotes = places.at[blocks.clone()]
                .iter()
                .zip(&places.row[blocks.clone()])
                .filter(|(_, &r)| r == REMOTE)
                .map(|(&a, _)| a as usize + 1)
                .max()
                .map_or(remote0, |end| end * bs * bs);
            let d = places.diag_rows[hi * bs] as usize;
            let o = places.off_rows[hi * bs] as usize;
            let d_first = places.diag_rows[lo * bs] as usize;
            let o_first = places.off_rows[lo * bs] as usize;
            take(&mut diag, diag0, d_first)?;
            take(&mut off, off0, o_first)?;
            out.push(BlockBand {
                places,
                blocks: w[0]..w[1],
                diag0: d_first,
                off0: o_first,
                remote0,
                diag: take(&mut diag, d_first, d)?,
                off: take(&mut off, o_first, o)?,
                remote: take(&mut remote, remote0, remotes)?,
            });
            (diag0, off0, remote0) = (d, o, remotes);
        }
        Ok(out)
    }
}

/// The next `to - from` values of `rest` (which starts at `from`), taken off it.
fn take<'s>(rest: &mut &'s mut [Real], from: usize, to: usize) -> Result<&'s mut [Real]> {
    let r = std::mem::take(rest);
    if to < from || to - from > r.len() {
        return Err(Error::new("block bands share block rows or do not follow them"));
    }
    let (head, tail) = r.split_at_mut(to - from);
    *rest = tail;
    Ok(head)
}

/// The most rows and columns a block may have.
pub const MAX_BS: usize = 8;

/// Where the rows of one block row start in a band's arrays ([`BlockBand::row_places`]).
pub struct RowPlaces {
    remote: bool,
    diag: [usize; MAX_BS],
    off: [usize; MAX_BS],
}

/// One band of a [`BlockFill`]: the blocks of a range of the list, written by one thread.
pub struct BlockBand<'a> {
    places: &'a BlockPlaces,
    blocks: std::ops::Range<usize>,
    diag0: usize,
    off0: usize,
    remote0: usize,
    diag: &'a mut [Real],
    off: &'a mut [Real],
    remote: &'a mut [Real],
}

impl BlockBand<'_> {
    /// The places of the rows of block `k`'s block row, one of the band's, which every block of
    /// that row shares ([`BlockBand::with_rows_of_run`]).
    pub fn row_places(&self, k: usize) -> RowPlaces {
        let places = self.places;
        let (bs, r) = (places.bs, places.row[k]);
        let mut out = RowPlaces { remote: r == REMOTE, diag: [0; MAX_BS], off: [0; MAX_BS] };
        if !out.remote {
            for i in 0..bs {
                out.diag[i] = places.diag_rows[r as usize * bs + i] as usize - self.diag0;
                out.off[i] = places.off_rows[r as usize * bs + i] as usize - self.off0;
            }
        }
        out
    }

    /// Whether block `b` lies right after block `a` in every row of their block row (the next
    /// `bs` columns of the same part of the matrix; never for rows another rank owns), so that
    /// [`BlockBand::with_rows_of_run`] can take them together.
    #[inline]
    pub fn follows(&self, a: usize, b: usize) -> bool {
        let (row, at) = (&self.places.row, &self.places.at);
        row[a] == row[b] && row[a] != REMOTE && at[b] == at[a] + self.places.bs as u32
    }

    /// Calls `row(i, values)` with each row `i` of the `n` blocks from block `k` (their `n bs`
    /// values side by side), blocks of the band's block row whose places are `rows`, each after the
    /// one before it ([`BlockBand::follows`]; any single block is a run of one, and the only run in
    /// rows another rank owns).
    #[inline]
    pub fn with_rows_of_run(&mut self, rows: &RowPlaces, k: usize, n: usize, mut row: impl FnMut(usize, &mut [Real])) {
        debug_assert!(self.blocks.contains(&k), "block {k} is outside its band {:?}", self.blocks);
        let places = self.places;
        let (bs, at) = (places.bs, places.at[k]);
        if rows.remote {
            debug_assert!(n == 1, "a run of {n} blocks in rows another rank owns");
            let first = at as usize * bs * bs - self.remote0;
            for (i, v) in self.remote[first..first + bs * bs].chunks_exact_mut(bs).enumerate() {
                row(i, v);
            }
            return;
        }
        let (starts, values) = if at & OFF == 0 { (&rows.diag, &mut *self.diag) } else { (&rows.off, &mut *self.off) };
        let at = (at & !OFF) as usize;
        for (i, &start) in starts[..bs].iter().enumerate() {
            row(i, &mut values[start + at..start + at + n * bs]);
        }
    }

    /// Row `i` of block `k`, one of the band's blocks (its `bs` values).
    pub fn row_mut(&mut self, k: usize, i: usize) -> &mut [Real] {
        debug_assert!(self.blocks.contains(&k), "block {k} is outside its band {:?}", self.blocks);
        let bs = self.places.bs;
        match slot(self.places, k, i) {
            Slot::Diag(s) => &mut self.diag[s - self.diag0..s - self.diag0 + bs],
            Slot::Off(s) => &mut self.off[s - self.off0..s - self.off0 + bs],
            Slot::Remote(s) => &mut self.remote[s - self.remote0..s - self.remote0 + bs],
        }
    }
}

impl<T: MatOps + ?Sized> BlockOps for T {}
