//! What records a run: each [`Recorder`] is called by the driver at fixed points — after a step
//! converged (before its particle update), after every accepted step (and once at the start), at
//! the end — and may add columns to `history.csv`, keep a state in checkpoints, add to
//! `summary.json` and draw figures. The run's recorders are [`registered`] in one list, whose
//! order is the order of the history's columns.
//!
//! A new recorder is one file in this folder implementing [`Recorder`] and one line in
//! [`registered`].

mod check;
mod diagnostics;
mod dissipation;
mod equilibrium;
mod fields;
mod imbalance;
mod probes;
mod steps;

use crate::assembly::{NodeBlock, StepForces};
use crate::case::Case;
use crate::diagnostics::Warning;
use crate::distribution::Owners;
use crate::io::RunOutput;
use crate::kernels::StepResult;
use crate::layout::Dim;
use crate::model::Model;
use crate::parallel::Collective;
use crate::plot::Figure;
use crate::summary::Summary;
use crate::verification::CaseChecks;

/// A step that converged, before its particle update: what a recorder may look at then.
pub struct Converged<'a, const D: usize> {
    /// The model before the update (the points still at t_n).
    pub model: &'a Model<D>,
    /// The step's forces and reactions.
    pub forces: &'a StepForces<D>,
    /// What the step does to each of this rank's points (in the model's order).
    pub results: &'a [StepResult<D>],
    /// This rank's nodal values of the step, when a recorder [`Recorder::needs_nodes`] them.
    pub nodes: Option<&'a NodeBlock>,
    pub coll: &'a Collective,
}

/// The run after an accepted step (or at its start, step 0), as the recorders see it.
pub struct Moment<'a, const D: usize> {
    pub model: &'a Model<D>,
    pub coll: &'a Collective,
    /// Which rank owns which cells.
    pub owners: &'a Owners<D>,
    /// The time reached [s].
    pub t: f64,
    /// The step's Δt [s] (0 at the start).
    pub dt: f64,
    /// Accepted steps so far.
    pub step: usize,
    /// Newton and Krylov iterations of the step.
    pub iterations: (usize, usize),
    /// The energy of a dynamic step: the work of the external forces and the reactions, and the
    /// points' terms (body-force work, internal work, change of kinetic energy, Darcy
    /// dissipation, kinetic energy after the step; see [`crate::diagnostics::energy`]).
    pub energy: Option<(f64, [f64; 5])>,
    /// The last step's nodal values on this rank (for the fields).
    pub nodes: &'a NodeBlock,
}

impl<'a, const D: usize> Moment<'a, D> {
    /// The run between steps (no step just taken): at its start, a milestone, its end.
    pub fn between(
        model: &'a Model<D>,
        coll: &'a Collective,
        owners: &'a Owners<D>,
        (t, step): (f64, usize),
        nodes: &'a NodeBlock,
    ) -> Moment<'a, D> {
        Moment { model, coll, owners, t, dt: 0.0, step, iterations: (0, 0), energy: None, nodes }
    }
}

/// Where recorders put what they give the run besides their history columns.
pub struct Sink<'a> {
    pub summary: &'a mut Summary,
    /// Warnings raised for the first time (the driver shows and keeps them).
    pub warnings: Vec<Warning>,
    /// The run's output directory.
    pub out: &'a mut RunOutput,
    /// Figures to draw at the end.
    pub figures: Vec<Figure>,
}

/// What a recorder continues from at a restart.
pub struct FromCheckpoint<'a, 'b, const D: usize> {
    /// Its state in the checkpoint (`None`: the checkpoint holds none for it).
    pub state: Option<&'b [f64]>,
    /// The run as restored: its points, time and step.
    pub at: &'b Moment<'a, D>,
    /// The summary, which a recorder may fill again from its state.
    pub summary: &'b mut Summary,
}

/// What a recorder could not restore, if anything.
pub type Restored = Result<Option<String>, String>;

/// One thing that records a run (see the module documentation). Every method but
/// [`Recorder::record`] has a default that does nothing.
pub trait Recorder<const D: usize> {
    /// Its name: the key of its state in checkpoints.
    fn name(&self) -> &'static str;

    /// Its `history.csv` columns, in order.
    fn columns(&self) -> Vec<String> {
        Vec::new()
    }

    /// After a step converged, before its particle update (collective where it reduces).
    fn converged(&mut self, _at: &Converged<D>) -> Result<(), String> {
        Ok(())
    }

    /// After every accepted step and once at the start (collective where it reduces); `row`
    /// says whether a history row is written, for which it returns its columns' values.
    fn record(&mut self, at: &Moment<D>, row: bool, sink: &mut Sink) -> Result<Vec<f64>, String>;

    /// At the run's start, at the end of each stage, and when the run stops early or is
    /// interrupted, after that step's [`Recorder::record`].
    fn milestone(&mut self, _at: &Moment<D>, _sink: &mut Sink) -> Result<(), String> {
        Ok(())
    }

    /// At the end of the run (also of a failed one): what it adds to the summary.
    fn finish(&mut self, _at: &Moment<D>, _sink: &mut Sink) -> Result<(), String> {
        Ok(())
    }

    /// What it has gathered, for a checkpoint (the same on every rank; collective); `None` if it
    /// keeps nothing.
    fn state(&self, _at: &Moment<D>) -> Result<Option<Vec<f64>>, String> {
        Ok(None)
    }

    /// Continues from its checkpoint state, the points already restored; returns what it could
    /// not restore, if anything.
    fn restore(&mut self, _from: FromCheckpoint<D>) -> Restored {
        Ok(None)
    }

    /// Times the stepping must land on exactly.
    fn event_times(&self) -> Vec<f64> {
        Vec::new()
    }

    /// Some(reason) once the run has shown what it needs and should end (completed).
    fn stop(&self) -> Option<String> {
        None
    }

    /// Whether it reads the nodal values ([`Converged::nodes`], [`Moment::nodes`]) of the step
    /// that becomes accepted step number `step`, the last of its stage when `stage_end`. The nodal
    /// diagnostics, a second pass over the points, are computed only for such steps.
    fn needs_nodes(&self, _step: usize, _stage_end: bool) -> bool {
        false
    }
}

/// The recorders of a run, in the order of their history columns.
pub fn registered<const D: usize>(
    case: &Case,
    model: &Model<D>,
    coll: &Collective,
) -> Result<Vec<Box<dyn Recorder<D>>>, String>
where
    Dim<D>: CaseChecks<D>,
{
    let mut all: Vec<Box<dyn Recorder<D>>> = vec![
        Box::new(steps::Steps),
        Box::new(probes::Probes::new(case, model, coll)?),
        Box::new(diagnostics::Diagnostics::new(case, model)),
        Box::new(imbalance::Imbalance),
        Box::new(equilibrium::Equilibrium::new(model)),
    ];
    if let Some(check) = check::Verification::new(case, model, coll)? {
        all.push(Box::new(check));
    }
    if dissipation::applies(model) {
        all.push(Box::new(dissipation::Dissipation::default()));
    }
    all.push(Box::new(fields::Fields::new(case.output.fields_every)));
    Ok(all)
}
