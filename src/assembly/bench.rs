//! One assembly of the global system without a solve, for benchmarks (`benches/kernels.rs`).

use super::{Assembler, GridSystem};
use crate::kernels;
use crate::model::Model;
use petsc::snes::NonlinearProblem;
use petsc::{CallbackError, Error, VecOps};

fn error(e: CallbackError) -> Error {
    match e {
        CallbackError::Domain(m) | CallbackError::Fatal(m) => Error::new(m),
    }
}

impl GridSystem {
    /// Assembles the residual and the Jacobian of the prepared step once at Δd = 0: the assembly
    /// work of one Newton iteration (every particle's kernels, scattered into PETSc's vector and
    /// matrix) without the linear solve. Returns the 2-norm of the residual.
    pub fn assemble_once(&mut self, model: &Model) -> Result<f64, Error> {
        self.x.set_all(0.0)?;
        let mut seconds = 0.0;
        let GridSystem { dm, x, x_local, f_local, work_global, jac, step, stages, .. } = self;
        let jac = jac.as_mut().ok_or_else(|| Error::new("the step was not prepared"))?;
        let mut asm = Assembler::<2, { kernels::MAX_NODES }, { kernels::MAX_DOF }>::new(
            dm,
            model,
            step,
            x_local,
            f_local,
            &mut seconds,
            &stages.assembly,
        );
        asm.residual(&x.as_ref(), &mut work_global.as_ref()).map_err(error)?;
        asm.jacobian(&x.as_ref(), &mut jac.as_ref()).map_err(error)?;
        work_global.norm2()
    }
}
