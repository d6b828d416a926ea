//! A Schur-complement field split whose Schur preconditioner the application builds: the
//! sub-matrix of the operator on the Schur split's rows and columns plus a diagonal the
//! application supplies (`-pc_fieldsplit_schur_precondition user`).
//!
//! PETSc's own choices (`a11`, `selfp`, `full`) are formed from the operator alone; a
//! preconditioner that needs physics the operator does not show (the fixed-stress mass of a
//! poroelastic system, for one) is built here: Sp = A₁₁ + diag(d). [`SchurUser::update`] refills
//! it after every Jacobian; the field split hands it to the Schur split's preconditioner at its
//! next set-up, which is rebuilt because the matrix changed.

use crate::mat::MatOps;
use crate::vector::VecOps;
use crate::{IndexSet, Mat, PcRef, Real, Result, Vector};
use petsc_sys as sys;

/// The Schur preconditioning matrix of one field split, kept between Jacobians.
pub struct SchurUser {
    /// The field split (a reference of our own, released on drop).
    pc: sys::PC,
    /// The rows (and columns) of the Schur split.
    rows: IndexSet,
    /// Sp, once built from the current operator's pattern, with the vector holding the diagonal
    /// added to it (laid out like Sp's rows).
    built: Option<(Mat, Vector)>,
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

    /// The user-built Schur preconditioner of the field split `pc`, whose Schur split (its second)
    /// has the rows `rows`. Nothing is built before the first [`SchurUser::update`].
    pub fn new(pc: &PcRef, rows: IndexSet) -> Result<SchurUser> {
        call!(PetscObjectReference(pc.raw as sys::PetscObject))?;
        Ok(SchurUser { pc: pc.raw, rows, built: None })
    }

    /// Forgets Sp: the operator's nonzero pattern changed, so the next update extracts a new one.
    pub fn forget(&mut self) {
        self.built = None;
    }

    /// Sets Sp = A[rows, rows] + diag(`add`) from the assembled operator `a` (`add`: this rank's
    /// rows, in the index set's order) and, when Sp is new, gives it to the field split.
    pub fn update(&mut self, a: &dyn MatOps, add: &[Real]) -> Result<()> {
        let old = self.built.take();
        let fresh = old.is_none();
        let reuse = if fresh { sys::MatReuse::MAT_INITIAL_MATRIX } else { sys::MatReuse::MAT_REUSE_MATRIX };
        let mut raw = old.as_ref().map_or(std::ptr::null_mut(), |(sp, _)| sp.raw);
        call!(MatCreateSubMatrix(a.raw(), self.rows.raw(), self.rows.raw(), reuse, &mut raw))?;
        let (sp, mut d) = match old {
            Some(kept) => kept,
            None => {
                let sp = Mat { raw };
                let d = sp.create_vecs()?.1;
                (sp, d)
            }
        };
        {
            let mut w = d.write()?;
            if w.len() != add.len() {
                return Err(crate::Error::new(format!(
                    "SchurUser::update: {} diagonal values for {} rows of the Schur split",
                    add.len(),
                    w.len()
                )));
            }
            w.copy_from_slice(add);
        }
        call!(MatDiagonalSet(sp.raw, d.raw, sys::InsertMode::ADD_VALUES))?;
        if fresh {
            call!(PCFieldSplitSetSchurPre(
                self.pc,
                sys::PCFieldSplitSchurPreType::PC_FIELDSPLIT_SCHUR_PRE_USER,
                sp.raw
            ))?;
        }
        self.built = Some((sp, d));
        Ok(())
    }
}
