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
    /// compressed-row storage ([`OFF`] set for the off-diagonal part).
    at: Vec<u32>,
    /// The first entry of every local row in the diagonal part, then in the off-diagonal part.
    diag_rows: Vec<Int>,
    off_rows: Vec<Int>,
    /// Blocks of rows other ranks own: (block, global block row, global block column).
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

/// The compressed rows (row starts, columns) of a sequential AIJ matrix, copied.
fn rows_of(m: sys::Mat) -> Result<(Vec<Int>, Vec<Int>)> {
    let (mut n, mut ia, mut ja) = (0 as Int, std::ptr::null(), std::ptr::null());
    let mut done = sys::PetscBool::PETSC_FALSE;
    let f = sys::PetscBool::PETSC_FALSE;
    call!(MatGetRowIJ(m, 0, f, f, &mut n, &mut ia, &mut ja, &mut done))?;
    if !crate::from_bool(done) {
        return Err(Error::new("MatGetRowIJ gave no compressed rows"));
    }
    // SAFETY: MatGetRowIJ returned n + 1 row starts and ia[n] column indices, valid until
    // MatRestoreRowIJ; they are copied before it.
    let (starts, cols) = unsafe {
        let starts = std::slice::from_raw_parts(ia, n as usize + 1).to_vec();
        let cols = std::slice::from_raw_parts(ja, starts[n as usize] as usize).to_vec();
        (starts, cols)
    };
    call!(MatRestoreRowIJ(m, 0, f, f, &mut n, &mut ia, &mut ja, &mut done))?;
    Ok((starts, cols))
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
        let (lo, hi) = self.ownership_range()?;
        let (lo, hi) = (lo as Int, hi as Int);
        let b = bs as Int;
        let parts = parts(self.raw())?;
        let (diag_rows, diag_cols) = rows_of(parts.diag)?;
        let (off_rows, off_cols) = match parts.off {
            Some((ao, garray)) => {
                let (rows, local) = rows_of(ao)?;
                let n = local.iter().map(|&c| c + 1).max().unwrap_or(0) as usize;
                // SAFETY: garray holds the global column of each of the off-diagonal part's
                // columns, at least as many as its largest local column index + 1.
                let global = unsafe { std::slice::from_raw_parts(garray, n) };
                (rows, local.iter().map(|&c| global[c as usize]).collect())
            }
            None => (vec![0; diag_rows.len()], Vec::new()),
        };
        let mut places = BlockPlaces { bs, diag_rows, off_rows, ..BlockPlaces::default() };
        places.row.reserve_exact(blocks.len());
        places.at.reserve_exact(blocks.len());
        for (k, &(r, c)) in blocks.iter().enumerate() {
            if r * b < lo || r * b >= hi {
                places.row.push(REMOTE);
                places.at.push(0);
                places.remote.push((k as u32, r, c));
                continue;
            }
            let local = (r * b - lo) as usize;
            let (rows, cols, shift, flag) = if c * b >= lo && c * b < hi {
                (&places.diag_rows, &diag_cols, lo, 0)
            } else {
                (&places.off_rows, &off_cols, 0, OFF)
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
    }

    /// Sets the matrix to the sum of `values` (block after block in the order of `places`, each
    /// row-major) over all ranks, and assembles it: owned rows are written in place, other ranks'
    /// rows sent to their owners. Collective.
    fn set_blocks(&mut self, places: &BlockPlaces, values: &[Real]) -> Result<()> {
        let bs = places.bs;
        if values.len() != places.len() * bs * bs {
            return Err(Error::new("block values do not match their places"));
        }
        self.zero_entries()?;
        let parts = parts(self.raw())?;
        let add = |arr: &mut [Real], starts: &[Int], off: u32| {
            for (k, (&row, &at)) in places.row.iter().zip(&places.at).enumerate() {
                if row == REMOTE || at & OFF != off {
                    continue;
                }
                let (row, at) = (row as usize * bs, (at & !OFF) as usize);
                for i in 0..bs {
                    let s = starts[row + i] as usize + at;
                    let v = &values[(k * bs + i) * bs..(k * bs + i + 1) * bs];
                    arr[s..s + bs].iter_mut().zip(v).for_each(|(a, v)| *a += v);
                }
            }
        };
        let nnz = |starts: &[Int]| starts.last().map_or(0, |&n| n as usize);
        with_values(parts.diag, nnz(&places.diag_rows), |arr| add(arr, &places.diag_rows, 0))?;
        if let Some((ao, _)) = parts.off {
            with_values(ao, nnz(&places.off_rows), |arr| add(arr, &places.off_rows, OFF))?;
        }
        let mut rows = vec![0 as Int; bs];
        let mut cols = vec![0 as Int; bs];
        for &(k, r, c) in &places.remote {
            for i in 0..bs {
                rows[i] = r * bs as Int + i as Int;
                cols[i] = c * bs as Int + i as Int;
            }
            let k = k as usize;
            self.set_values(&rows, &cols, &values[k * bs * bs..(k + 1) * bs * bs], true)?;
        }
        self.assemble()
    }
}

impl<T: MatOps + ?Sized> BlockOps for T {}
