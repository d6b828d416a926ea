//! One assembly of the global system without a solve, for benchmarks (`benches/kernels.rs`).

use super::step::Step;
use super::System;
use crate::model::Model;
use crate::parallel::Collective;
use petsc::snes::NonlinearProblem;
use petsc::{CallbackError, Error, VecOps};

fn error(e: CallbackError) -> Error {
    match e {
        CallbackError::Domain(m) | CallbackError::Fatal(m) => Error::new(m),
    }
}

impl<const D: usize, const M: usize, const N: usize> System<D, M, N> {
    /// Assembles the residual and the Jacobian of the prepared `step` once at Δd = 0: the assembly
    /// work of one Newton iteration (every particle's kernels, scattered into PETSc's vector and
    /// matrix) without the linear solve. Returns the 2-norm of the residual.
    pub fn assemble_once(&mut self, step: &Step<D, M>, model: &Model<D>, coll: &Collective) -> Result<f64, Error> {
        let (x, jac, mut callbacks) = self.parts(step, model, coll)?;
        x.set_all(0.0)?;
        let mut f = x.duplicate()?;
        callbacks.residual(&x.as_ref(), &mut f.as_ref()).map_err(error)?;
        callbacks.jacobian(&x.as_ref(), &mut jac.as_ref(), None).map_err(error)?;
        f.norm2()
    }
}
