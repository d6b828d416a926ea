//! The residual and Jacobian callbacks of a step's Newton solve: the particle side's sums
//! ([`Points`]) at PETSc's iterate, added into a ghosted vector (summed over ranks by PETSc) and
//! into the matrix's blocks in place, in PETSc's scaling of the pressure unknowns.

use super::pattern::Pattern;
use super::points::{run_bands, run_parts, Points};
use super::step::{Band, Step};
use super::ties;
use crate::model::Model;
use crate::parallel::Collective;
use petsc::snes::NonlinearProblem;
use petsc::{BlockFill, BlockOps, BlockPlaces, CallbackError, DmDa, LogStage, MatRef, VecOps, VecRef, Vector};
use std::time::Instant;

fn fatal(e: petsc::Error) -> CallbackError {
    CallbackError::Fatal(e.to_string())
}

/// The wall time of a solve's residual and Jacobian callbacks [s], and of its Jacobians alone with
/// their number (the cost of one tangent assembly is `jacobian_seconds / jacobians`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AssemblyTime {
    /// Residuals and Jacobians [s].
    pub seconds: f64,
    /// The Jacobians [s].
    pub jacobian_seconds: f64,
    /// The Jacobians evaluated.
    pub jacobians: usize,
}

impl AssemblyTime {
    /// Adds another solve's times.
    pub fn add(&mut self, other: AssemblyTime) {
        self.seconds += other.seconds;
        self.jacobian_seconds += other.jacobian_seconds;
        self.jacobians += other.jacobians;
    }
}

/// Where the blocks of each of `bands` begin in `pattern`'s list, and where the last ends.
fn band_cuts<const D: usize>(bands: &[Band], pattern: &Pattern<D>) -> Vec<usize> {
    bands.iter().map(|b| pattern.row_start(b.lo)).chain([pattern.len()]).collect()
}

/// Fixed dofs: a unit diagonal at each (block, component) of `diagonals` (every other entry of
/// their rows and columns stays zero).
fn unit_diagonals(values: &mut BlockFill<'_>, diagonals: &[(u32, usize)]) {
    for &(blk, c) in diagonals {
        values.row_mut(blk as usize, c)[c] = 1.0;
    }
}

/// The callbacks of one step's Newton solve (points of dimension D with at most M nodes of at
/// most N dofs).
pub(super) struct Callbacks<'a, const D: usize, const M: usize, const N: usize> {
    points: Points<'a, D, M, N>,
    step: &'a Step<D, M>,
    dm: &'a DmDa<D>,
    x_local: &'a mut Vector,
    f_local: &'a mut Vector,
    /// Wall time spent in the callbacks, and in the Jacobians alone with their number.
    pub(super) time: AssemblyTime,
    stage: &'a LogStage,
    /// The fixed-stress Schur preconditioner, refilled after every Jacobian.
    schur: Option<&'a mut petsc::SchurUser>,
    /// Where the pattern's blocks sit in the matrix.
    places: &'a BlockPlaces,
    /// Where the multilinear pattern's blocks sit in the preconditioning matrix, if it is not the
    /// Jacobian ([`super::lowered`]).
    lowered_places: Option<&'a BlockPlaces>,
    /// The first material point whose residual block was not finite in this solve (on this
    /// rank), with the quantity that was not.
    pub(super) nonfinite: Option<String>,
    /// The run's ranks (a rigid body's balance sums over them).
    coll: &'a Collective,
}

/// What the callbacks borrow from the solver: the node space's DMDA, the local work vectors, the
/// assembly's log stage, the user-built Schur preconditioner, if any, and the places of the
/// patterns' blocks in the matrices.
pub(super) struct Workspace<'a, const D: usize> {
    pub dm: &'a DmDa<D>,
    pub x_local: &'a mut Vector,
    pub f_local: &'a mut Vector,
    pub stage: &'a LogStage,
    pub schur: Option<&'a mut petsc::SchurUser>,
    /// Where the pattern's blocks sit in the Jacobian and, if the preconditioner has a matrix of
    /// its own, in that one.
    pub places: (&'a BlockPlaces, Option<&'a BlockPlaces>),
    pub coll: &'a Collective,
}

impl<'a, const D: usize, const M: usize, const N: usize> Callbacks<'a, D, M, N> {
    /// The callbacks of `step` of `model` on the solver's `work`.
    pub(super) fn new(model: &'a Model<D>, step: &'a Step<D, M>, work: Workspace<'a, D>) -> Callbacks<'a, D, M, N> {
        let Workspace { dm, x_local, f_local, stage, schur, places: (places, lowered_places), coll } = work;
        Callbacks {
            points: Points::new(model, step),
            step,
            dm,
            x_local,
            f_local,
            time: AssemblyTime::default(),
            stage,
            schur,
            places,
            lowered_places,
            nonfinite: None,
            coll,
        }
    }

    /// The physical increments of the ghosted dofs at PETSc's `x` (pressures times the step's
    /// scale, see [`super::pressure::scale`]).
    fn gather(&mut self, x: &VecRef) -> Result<Vec<f64>, CallbackError> {
        self.dm.global_to_local(x, self.x_local).map_err(fatal)?;
        let mut xl = self.x_local.read().map_err(fatal)?.to_vec();
        self.for_pressures(&mut xl, |v, s| *v *= s);
        Ok(xl)
    }

    /// Applies `f(value, s)` to the pressure component of every ghosted node of `v`.
    fn for_pressures(&self, v: &mut [f64], f: impl Fn(&mut f64, f64)) {
        if let Some(p) = self.step.layout.p {
            let (nd, s) = (self.step.dofs.nd, self.step.p_scale);
            v.iter_mut().skip(p).step_by(nd).for_each(|x| f(x, s));
        }
    }
}

impl<const D: usize, const M: usize, const N: usize> NonlinearProblem for Callbacks<'_, D, M, N> {
    fn residual(&mut self, x: &VecRef, f: &mut VecRef) -> Result<(), CallbackError> {
        let _stage = self.stage.push().map_err(fatal)?;
        let t0 = Instant::now();
        let xl = self.gather(x)?;
        let mut fl = vec![0.0; xl.len()];
        let wf = self.step.scheme.w_force;
        for (v, e) in fl.iter_mut().zip(&self.step.fext) {
            *v = -wf * e;
        }
        for (v, h) in fl.iter_mut().zip(&self.step.history) {
            *v += h;
        }
        let ps = self.points;
        let nd = self.step.dofs.nd;
        let block = |k: usize, buf: &mut [f64], scratch: &mut _| ps.residual_of(k, &xl, buf, scratch);
        let bad =
            run_bands(&self.step.bands, &mut fl, |a| a as usize * nd, |band, f| ps.residual_band(band, f, &block));
        if let Some(k) = bad.into_iter().flatten().min() {
            if self.nonfinite.is_none() {
                self.nonfinite = Some(self.points.describe_nonfinite(k, &xl));
            }
        }
        self.points.add_projection(&xl, &mut fl);
        // The continuity rows in PETSc's scaling (see [`super::pressure::scale`]).
        self.for_pressures(&mut fl, |v, s| *v *= s);
        let tied = ties::gather_residual(&self.step.dofs, &mut fl);
        self.f_local.write().map_err(fatal)?.copy_from_slice(&fl);
        f.set_all(0.0).map_err(fatal)?;
        self.dm.local_to_global_add(self.f_local, f).map_err(fatal)?;
        {
            // Fixed dofs: residual x − prescribed increment.
            let xo = x.read().map_err(fatal)?;
            let mut fo = f.write().map_err(fatal)?;
            for &(o, q) in &self.step.dofs.owned_fixed {
                fo[o] = xo[o] - self.step.dofs.value[q] / self.step.unit(q);
            }
            // Rigid bodies: their balance at the masters, x_s − x_m at the other tied dofs.
            ties::finish_residual(&self.step.dofs, tied, &xo, &mut fo, self.coll).map_err(CallbackError::Fatal)?;
        }
        self.time.seconds += t0.elapsed().as_secs_f64();
        Ok(())
    }

    fn jacobian(&mut self, x: &VecRef, j: &mut MatRef, p: Option<&mut MatRef>) -> Result<(), CallbackError> {
        let _stage = self.stage.push().map_err(fatal)?;
        let t0 = Instant::now();
        let xl = self.gather(x)?;
        let step = self.step;
        let nd = step.dofs.nd;
        let layout = step.layout;
        let ps = self.points;
        let cuts = band_cuts(&step.bands, &step.pattern);
        // With a preconditioning matrix of its own ([`super::lowered`]), each point's blocks of
        // both matrices in one pass over the points.
        let lowered = match (p, step.lowered.as_ref(), self.lowered_places) {
            (Some(p), Some(low), Some(places)) => Some((p, low, places)),
            (None, _, _) => None,
            _ => return Err(CallbackError::Fatal("the step has no preconditioning matrix of its own".into())),
        };
        let filled = j.fill_blocks(self.places, |values| -> Result<(), petsc::Error> {
            let parts: Vec<_> = step.bands.iter().copied().zip(values.bands(&cuts)?).collect();
            match lowered {
                None => {
                    run_parts(parts, |band, mut v| ps.tangent_band(band, &mut v, None, &xl));
                }
                Some((p, low, places)) => {
                    let lcuts = band_cuts(&step.bands, &low.pattern);
                    p.fill_blocks(places, |lvalues| -> Result<(), petsc::Error> {
                        let both =
                            parts.into_iter().zip(lvalues.bands(&lcuts)?).map(|((b, v), l)| (b, (v, l))).collect();
                        run_parts(both, |band, (mut v, mut l)| ps.tangent_band(band, &mut v, Some((&mut l, low)), &xl));
                        unit_diagonals(lvalues, &low.fixed_diagonals);
                        Ok(())
                    })??;
                }
            }
            // Rigid bodies: tied rows moved into their masters', before the pressures' scaling.
            step.tied_rows.apply(values, nd);
            if let Some(p) = layout.p {
                for (cell, blocks) in step.projection.iter().zip(&step.projection_blocks) {
                    let c = cell.nodes.len();
                    for (a, &na) in cell.nodes.iter().enumerate() {
                        for (b, &nb) in cell.nodes.iter().enumerate() {
                            let (ra, cb) = (na as usize * nd + p, nb as usize * nd + p);
                            if !step.dofs.fixed[ra] && !step.dofs.fixed[cb] {
                                values.row_mut(blocks[a * c + b] as usize, p)[p] -= cell.s[a * c + b];
                            }
                        }
                    }
                }
                // PETSc's scaling: the continuity rows and the pressure columns times s.
                values.scale_row_and_column(p, step.p_scale);
            }
            unit_diagonals(values, &step.fixed_diagonals);
            Ok(())
        });
        filled.and_then(|r| r).map_err(fatal)?;
        if let Some(schur) = self.schur.as_deref_mut() {
            if schur.has_blocks() {
                let mut invert = |block: &mut [f64], n: usize| crate::algebra::dense::invert_in_place(block, n);
                schur.update_with_blocks(j, &step.schur_groups, &mut invert, &step.fixed_stress).map_err(fatal)?;
            } else {
                schur.update(j, &step.fixed_stress).map_err(fatal)?;
            }
        }
        let seconds = t0.elapsed().as_secs_f64();
        self.time.seconds += seconds;
        self.time.jacobian_seconds += seconds;
        self.time.jacobians += 1;
        Ok(())
    }
}
