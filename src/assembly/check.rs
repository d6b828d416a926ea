//! The finite-difference check of the assembled tangent (`porompm test-jacobian`).
//!
//! The tangent J and the central differences of the assembled residual are both scaled
//! symmetrically by the tangent's diagonal, J̃ = D^{-1/2} J D^{-1/2} with D = |diag J| (the largest
//! entry of a row where its diagonal is zero), so that every field-pair block is seen in the units
//! of its own fields: the p–p block of a u–p–U tangent, whose entries are 10⁻¹⁸ of the u–u ones,
//! has unit diagonal there. A block is then judged by max |J̃ − J̃_fd| against its own largest
//! scaled entry, or against [`WEAK_BLOCK`] for a block weaker than that (in scaled units the
//! central differences' round-off is about 1e-10, which would swamp a block of 1e-5 judged by its
//! own scale; a wrong sign in it is still an error of 2e-5/1e-3).

/// Scaled size below which a block's error is measured against this floor instead of its own scale.
pub const WEAK_BLOCK: f64 = 1e-3;

use super::step::Step;
use super::System;
use crate::model::Model;
use crate::parallel::Collective;
use petsc::mat::MatOps;
use petsc::snes::NonlinearProblem;
use petsc::VecOps;

/// Agreement of one field-pair block of the assembled tangent with finite differences.
#[derive(Debug, Clone, serde::Serialize)]
pub struct BlockCheck {
    /// Row field (`ux`, `uy`, [`uz`,] `p`, `Ux`, `Uy`[, `Uz`], `Jbar`: `Layout::field_names`).
    pub row: &'static str,
    /// Column field.
    pub col: &'static str,
    /// max |J̃ − J̃_fd| over the block (diagonally scaled).
    pub max_abs_error: f64,
    /// max |J̃| over the block (diagonally scaled).
    pub max_abs_entry: f64,
    /// max |J̃ − J̃_fd| / max(max |J̃|, max |J̃_fd|, [`WEAK_BLOCK`]) over the block.
    pub relative_error: f64,
}

impl<const D: usize, const M: usize, const N: usize> System<D, M, N> {
    /// Compares the assembled tangent of the prepared `step` with central finite differences of
    /// the assembled residual, block by block over the free dofs, at the iterate `fraction` × (the
    /// converged increment of this step). `flip` negates one (row field, column field) block of
    /// the assembled tangent first, to show that the check sees it. One rank only (it builds the
    /// dense FD Jacobian: small cases only); any dimension.
    pub fn jacobian_check(
        &mut self,
        step: &Step<D, M>,
        model: &Model<D>,
        coll: &Collective,
        fraction: f64,
        flip: Option<(usize, usize)>,
    ) -> Result<Vec<BlockCheck>, super::Error> {
        if coll.size() != 1 {
            return Err(petsc::Error::new("the finite-difference Jacobian check runs on one rank"));
        }
        let nd = step.layout.nd;
        let p = step.layout.p;
        let h_cell = model.grid.h_min();
        let names = step.layout.field_names();
        // A realistic iterate: part of this step's converged increment.
        self.solve(step, model, coll)?;
        let (x_now, jac, mut asm) = self.parts(step, model, coll)?;
        let mut x = x_now.duplicate()?;
        x_now.copy_to(&mut x)?;
        x.scale(fraction)?;
        let n = x.local_size()?;
        let fixed: Vec<bool> = {
            let mut f = vec![false; n];
            for &(o, _) in &step.dofs.owned_fixed {
                f[o] = true;
            }
            f
        };
        let free: Vec<usize> = (0..n).filter(|&o| !fixed[o]).collect();
        asm.jacobian(&x.as_ref(), &mut jac.as_ref(), None).map_err(|e| petsc::Error::new(format!("{e:?}")))?;
        let (_, mut dense) = jac.local_rows_dense()?;
        if let Some((rf, cf)) = flip {
            for &r in free.iter().filter(|&&r| r % nd == rf) {
                for &c in free.iter().filter(|&&c| c % nd == cf) {
                    dense[r * n + c] = -dense[r * n + c];
                }
            }
        }
        let xv = x.read()?.to_vec();
        // The step of a dof is 1e-6 of the typical size of its kind of unknown, whose floors are
        // 1e-3 of a cell (m) and 1 Pa when a kind is at rest: a step of 1e-9 of a cell keeps the
        // residual's round-off (1e-16 of forces near 1e5 N) below 1e-7 of the scaled tangent. (A
        // floor of 1e-6 of a cell, a step of 1e-12 of it, left 7e-6 on an elastic block at rest.)
        let is_p = |o: usize| Some(o % nd) == p;
        let (mut typ_u, mut typ_p) = (0.0f64, 0.0f64);
        for &o in &free {
            if is_p(o) {
                typ_p = typ_p.max(xv[o].abs());
            } else {
                typ_u = typ_u.max(xv[o].abs());
            }
        }
        let typical: Vec<f64> =
            (0..nd).map(|c| if is_p(c) { typ_p.max(1.0) } else { typ_u.max(1e-3 * h_cell) }).collect();
        let mut fd = vec![0.0; n * n];
        let (mut xp, mut fp, mut fm) = (x.duplicate()?, x.duplicate()?, x.duplicate()?);
        for &c in &free {
            let h = 1e-6 * (xv[c].abs() + typical[c % nd]);
            for (sign, out) in [(1.0, &mut fp), (-1.0, &mut fm)] {
                {
                    let mut w = xp.write()?;
                    w.copy_from_slice(&xv);
                    w[c] += sign * h;
                }
                asm.residual(&xp.as_ref(), &mut out.as_ref()).map_err(|e| petsc::Error::new(format!("{e:?}")))?;
            }
            let (a, b) = (fp.read()?, fm.read()?);
            for &r in &free {
                fd[r * n + c] = (a[r] - b[r]) / (2.0 * h);
            }
        }
        Ok(compare_blocks(&dense, &fd, &free, nd, names))
    }
}

/// Compares the tangent `dense` with its finite differences `fd` (both n × n, row-major), both
/// scaled by D^{-1/2} on either side, over the `free` dofs, block by block for each (row field,
/// column field) pair of the `nd` fields named `names`.
fn compare_blocks(dense: &[f64], fd: &[f64], free: &[usize], nd: usize, names: &[&'static str]) -> Vec<BlockCheck> {
    let n = fd.len().isqrt();
    // D: |diagonal|, or the row's largest entry where the diagonal is zero.
    let d: Vec<f64> = (0..n)
        .map(|r| {
            let diag = dense[r * n + r].abs();
            if diag > 0.0 {
                diag
            } else {
                free.iter().fold(0.0f64, |m, &c| m.max(dense[r * n + c].abs())).max(f64::MIN_POSITIVE)
            }
        })
        .collect();
    let mut out = Vec::new();
    for rf in 0..nd {
        for cf in 0..nd {
            let (mut err, mut big, mut big_fd) = (0.0f64, 0.0f64, 0.0f64);
            for &r in free.iter().filter(|&&r| r % nd == rf) {
                for &c in free.iter().filter(|&&c| c % nd == cf) {
                    let s = 1.0 / (d[r] * d[c]).sqrt();
                    err = err.max((dense[r * n + c] - fd[r * n + c]).abs() * s);
                    big = big.max(dense[r * n + c].abs() * s);
                    big_fd = big_fd.max(fd[r * n + c].abs() * s);
                }
            }
            let scale = big.max(big_fd).max(WEAK_BLOCK);
            out.push(BlockCheck {
                row: names[rf],
                col: names[cf],
                max_abs_error: err,
                max_abs_entry: big,
                relative_error: err / scale,
            });
        }
    }
    out
}
