//! A Schur-complement field split whose Schur preconditioner the application builds
//! (`-pc_fieldsplit_schur_precondition user`), in one of two forms:
//!
//! * **diagonal**: the sub-matrix of the operator on the Schur split's rows and columns plus a
//!   diagonal the application supplies, Sp = A₁₁ + diag(d) ([`SchurUser::update`]);
//! * **block inverse**: Sp = A₁₁ − A₁₀ B⁻¹ A₀₁ + diag(d), where B⁻¹ approximates A₀₀⁻¹ by the
//!   exact inverse of A₀₀ over groups of the first split's rows the application chooses and by
//!   diag(A₀₀)⁻¹ elsewhere ([`SchurUser::update_with_blocks`]). Without groups this is PETSc's
//!   `selfp` plus the diagonal.
//!
//! PETSc's own choices (`a11`, `selfp`, `full`) are formed from the operator alone; a
//! preconditioner that needs physics the operator does not show (the fixed-stress mass of a
//! poroelastic system, the soft free-surface strip of a dynamic one) is built here. Sp is refilled
//! after every Jacobian; the field split hands it to the Schur split's preconditioner at its next
//! set-up, which is rebuilt because the matrix changed.

use crate::mat::MatOps;
use crate::vector::VecOps;
use crate::{Comm, Error, IndexSet, Int, Mat, PcRef, Real, Result, Vector};
use petsc_sys as sys;

/// Replaces a dense row-major `n × n` block by its inverse, or says why it cannot.
pub type BlockInverter<'a> = dyn FnMut(&mut [Real], usize) -> std::result::Result<(), String> + 'a;

/// The Schur preconditioning matrix of one field split, kept between Jacobians.
pub struct SchurUser {
    /// The field split (a reference of our own, released on drop).
    pc: sys::PC,
    /// The rows (and columns) of the Schur split.
    rows: IndexSet,
    /// The rows of the first split, for the block-inverse form.
    first: Option<IndexSet>,
    /// The diagonal form's Sp, once built from the current operator's pattern, with the vector
    /// holding the diagonal added to it (laid out like Sp's rows).
    built: Option<(Mat, Vector)>,
    /// The block-inverse form's sub-matrices A₁₀, A₀₁ and A₁₁, extracted with the current
    /// operator's pattern.
    coupling: Option<[Mat; 3]>,
    /// The block-inverse form's Sp (a new matrix after every update).
    product: Option<Mat>,
}

impl Drop for SchurUser {
    fn drop(&mut self) {
        // SAFETY: releases the reference taken in `SchurUser::new`.
        unsafe { sys::PCDestroy(&mut self.pc) };
    }
}

impl SchurUser {
    /// Whether `pc` is a Schur-complement field split whose options ask for a user-built Schur
    /// preconditioner (`-pc_fieldsplit_type schur -pc_fieldsplit_schur_precondition user`).
    pub fn requested(pc: &PcRef) -> Result<bool> {
        if pc.type_name()? != "fieldsplit" {
            return Ok(false);
        }
        let mut kind = sys::PCCompositeType(0);
        call!(PCFieldSplitGetType(pc.raw, &mut kind))?;
        if kind != sys::PCCompositeType::PC_COMPOSITE_SCHUR {
            return Ok(false);
        }
        let mut pre = sys::PCFieldSplitSchurPreType(0);
        let mut user: sys::Mat = std::ptr::null_mut();
        call!(PCFieldSplitGetSchurPre(pc.raw, &mut pre, &mut user))?;
        Ok(pre == sys::PCFieldSplitSchurPreType::PC_FIELDSPLIT_SCHUR_PRE_USER)
    }

    /// The user-built Schur preconditioner of the field split `pc` in the diagonal form, whose
    /// Schur split (its second) has the rows `rows`. Nothing is built before the first
    /// [`SchurUser::update`].
    pub fn new(pc: &PcRef, rows: IndexSet) -> Result<SchurUser> {
        call!(PetscObjectReference(pc.raw as sys::PetscObject))?;
        Ok(SchurUser { pc: pc.raw, rows, first: None, built: None, coupling: None, product: None })
    }

    /// The user-built Schur preconditioner of the field split `pc` in the block-inverse form: its
    /// first split has the rows `first`, its Schur split the rows `rows`. Nothing is built before
    /// the first [`SchurUser::update_with_blocks`].
    pub fn with_blocks(pc: &PcRef, first: IndexSet, rows: IndexSet) -> Result<SchurUser> {
        let mut s = SchurUser::new(pc, rows)?;
        s.first = Some(first);
        Ok(s)
    }

    /// Whether this is the block-inverse form.
    pub fn has_blocks(&self) -> bool {
        self.first.is_some()
    }

    /// Forgets the extracted sub-matrices: the operator's nonzero pattern changed, so the next
    /// update extracts new ones.
    pub fn forget(&mut self) {
        self.built = None;
        self.coupling = None;
    }

    /// Sets Sp = A[rows, rows] + diag(`add`) from the assembled operator `a` (`add`: this rank's
    /// rows, in the index set's order) and, when Sp is new, gives it to the field split.
    pub fn update(&mut self, a: &dyn MatOps, add: &[Real]) -> Result<()> {
        let old = self.built.take();
        let fresh = old.is_none();
        let (sp, mut d) = match old {
            Some((sp, d)) => (sub_matrix(a, &self.rows, &self.rows, Some(sp))?, d),
            None => {
                let sp = sub_matrix(a, &self.rows, &self.rows, None)?;
                let d = sp.create_vecs()?.1;
                (sp, d)
            }
        };
        add_diagonal(&sp, &mut d, add)?;
        if fresh {
            self.hand_over(&sp)?;
        }
        self.built = Some((sp, d));
        Ok(())
    }

    /// Sets Sp = A₁₁ − A₁₀ B⁻¹ A₀₁ + diag(`add`) from the assembled operator `a` and gives it to
    /// the field split. `groups` lists, per group, positions in this rank's rows of the first split
    /// (its index set's local order; every group on one rank, no position in two groups);
    /// `invert` replaces a group's dense block of A₀₀ (row-major, `n × n`) by its inverse, or
    /// fails. Collective.
    pub fn update_with_blocks(
        &mut self,
        a: &dyn MatOps,
        groups: &[Vec<usize>],
        invert: &mut BlockInverter<'_>,
        add: &[Real],
    ) -> Result<()> {
        let first = self.first.as_ref().ok_or_else(|| Error::new("SchurUser: no first split for a block inverse"))?;
        let binv = block_inverse(a, first, groups, invert)?;
        let [k10, k01, k11] = self.coupling.take().map_or([None, None, None], |k| k.map(Some));
        let (rows, first) = (&self.rows, first);
        let coupling =
            [sub_matrix(a, rows, first, k10)?, sub_matrix(a, first, rows, k01)?, sub_matrix(a, rows, rows, k11)?];
        let [a10, a01, a11] = self.coupling.insert(coupling);
        let mut raw = std::ptr::null_mut();
        call!(MatMatMatMult(
            a10.raw,
            binv.raw,
            a01.raw,
            sys::MatReuse::MAT_INITIAL_MATRIX,
            sys::PETSC_DEFAULT as Real,
            &mut raw
        ))?;
        let sp = Mat { raw };
        call!(MatScale(sp.raw, -1.0))?;
        call!(MatAXPY(sp.raw, 1.0, a11.raw, sys::MatStructure::DIFFERENT_NONZERO_PATTERN))?;
        let mut d = sp.create_vecs()?.1;
        add_diagonal(&sp, &mut d, add)?;
        self.hand_over(&sp)?;
        self.product = Some(sp);
        Ok(())
    }

    /// Gives `sp` to the field split as its Schur preconditioning matrix (the split keeps a
    /// reference of its own).
    fn hand_over(&self, sp: &Mat) -> Result<()> {
        call!(PCFieldSplitSetSchurPre(self.pc, sys::PCFieldSplitSchurPreType::PC_FIELDSPLIT_SCHUR_PRE_USER, sp.raw))
    }
}

/// The sub-matrix `a[rows, cols]`, refilled in `kept` (extracted before from an operator of the
/// same pattern) or extracted anew.
fn sub_matrix(a: &dyn MatOps, rows: &IndexSet, cols: &IndexSet, kept: Option<Mat>) -> Result<Mat> {
    let reuse = if kept.is_some() { sys::MatReuse::MAT_REUSE_MATRIX } else { sys::MatReuse::MAT_INITIAL_MATRIX };
    let mut m = kept.unwrap_or(Mat { raw: std::ptr::null_mut() });
    call!(MatCreateSubMatrix(a.raw(), rows.raw(), cols.raw(), reuse, &mut m.raw))?;
    Ok(m)
}

/// Adds `add` (this rank's rows) to the diagonal of `sp`, through the vector `d` laid out like its
/// rows.
fn add_diagonal(sp: &Mat, d: &mut Vector, add: &[Real]) -> Result<()> {
    {
        let mut w = d.write()?;
        if w.len() != add.len() {
            return Err(Error::new(format!(
                "SchurUser: {} diagonal values for {} rows of the Schur split",
                add.len(),
                w.len()
            )));
        }
        w.copy_from_slice(add);
    }
    call!(MatDiagonalSet(sp.raw, d.raw, sys::InsertMode::ADD_VALUES))
}

/// B⁻¹ on the rows `first` of `a` (numbered like the sub-matrix `a[first, first]`): per group the
/// inverse of its dense block (extracted with `MatCreateSubMatrices`, inverted by `invert`),
/// 1/a_ii on every other row. Collective.
fn block_inverse(
    a: &dyn MatOps,
    first: &IndexSet,
    groups: &[Vec<usize>],
    invert: &mut BlockInverter<'_>,
) -> Result<Mat> {
    let rows = first.indices()?;
    let n = rows.len();
    let mut member = vec![usize::MAX; n];
    for (g, group) in groups.iter().enumerate() {
        for &i in group {
            if i >= n || member[i] != usize::MAX {
                return Err(Error::new(format!(
                    "SchurUser: position {i} of the first split ({n} rows here) is out of range or in two groups"
                )));
            }
            member[i] = g;
        }
    }
    // The groups' blocks, each on this rank alone.
    let sets: Vec<IndexSet> = groups
        .iter()
        .map(|g| IndexSet::new_general(Comm::self_(), &g.iter().map(|&i| rows[i]).collect::<Vec<Int>>()))
        .collect::<Result<_>>()?;
    let raw_sets: Vec<sys::IS> = sets.iter().map(|s| s.raw()).collect();
    let mut subs: *mut sys::Mat = std::ptr::null_mut();
    call!(MatCreateSubMatrices(
        a.raw(),
        raw_sets.len() as Int,
        raw_sets.as_ptr(),
        raw_sets.as_ptr(),
        sys::MatReuse::MAT_INITIAL_MATRIX,
        &mut subs
    ))?;
    let mut blocks = Vec::with_capacity(groups.len());
    let mut read = || -> Result<()> {
        for (g, group) in groups.iter().enumerate() {
            let m = group.len();
            let local: Vec<Int> = (0..m as Int).collect();
            let mut v = vec![0.0; m * m];
            // SAFETY: MatCreateSubMatrices returned `groups.len()` matrices.
            let sub = unsafe { *subs.add(g) };
            call!(MatGetValues(sub, m as Int, local.as_ptr(), m as Int, local.as_ptr(), v.as_mut_ptr()))?;
            invert(&mut v, m).map_err(|e| Error::new(format!("SchurUser: block {g} of {m} rows: {e}")))?;
            blocks.push(v);
        }
        Ok(())
    };
    let read_result = read();
    call!(MatDestroySubMatrices(raw_sets.len() as Int, &mut subs))?;
    read_result?;
    // The diagonal elsewhere.
    let mut diag = std::ptr::null_mut();
    call!(MatCreateVecs(a.raw(), std::ptr::null_mut(), &mut diag))?;
    let diag = Vector { raw: diag };
    call!(MatGetDiagonal(a.raw(), diag.raw))?;
    let (start, _) = a.ownership_range()?;
    let values = diag.read()?;
    let d_nnz: Vec<Int> =
        (0..n).map(|i| if member[i] == usize::MAX { 1 } else { groups[member[i]].len() as Int }).collect();
    let o_nnz = vec![0 as Int; n];
    let mut binv = Mat::new_aij(Comm::of(a.raw() as sys::PetscObject)?, n, first.global_len()?, &d_nnz, &o_nnz)?;
    let (first_row, _) = binv.ownership_range()?;
    for i in (0..n).filter(|&i| member[i] == usize::MAX) {
        let aii = values[rows[i] as usize - start];
        let r = [(first_row + i) as Int];
        binv.set_values(&r, &r, &[if aii != 0.0 { 1.0 / aii } else { 0.0 }], false)?;
    }
    for (group, block) in groups.iter().zip(&blocks) {
        let idx: Vec<Int> = group.iter().map(|&i| (first_row + i) as Int).collect();
        binv.set_values(&idx, &idx, block, false)?;
    }
    binv.assemble()?;
    Ok(binv)
}
