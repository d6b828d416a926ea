//! The case's verification check ([`crate::verification::Check`]): its history columns, the
//! metrics against the analytical reference in `summary.json`, its tables and figures, the event
//! times the stepping lands on and its reason to stop a run.

use super::{Converged, FromCheckpoint, Moment, Recorder, Restored, Sink};
use crate::case::Case;
use crate::layout::Dim;
use crate::model::Model;
use crate::parallel::Collective;
use crate::verification::{self, CaseChecks, Check};

/// The check the case asks for.
pub struct Verification<const D: usize> {
    check: Box<dyn Check<D>>,
}

impl<const D: usize> Verification<D> {
    /// The check of `case`, if it asks for one (collective): the registry types the case's
    /// `[verification]` and resolves its names again ([`verification::for_case_in`]).
    pub fn new(case: &Case, model: &Model<D>, coll: &Collective) -> Result<Option<Verification<D>>, String>
    where
        Dim<D>: CaseChecks<D>,
    {
        let check = verification::for_case_in(case, model, coll).map_err(|e| format!("verification: {e}"))?;
        Ok(check.map(|check| Verification { check }))
    }
}

impl<const D: usize> Recorder<D> for Verification<D> {
    fn name(&self) -> &'static str {
        "check"
    }

    fn columns(&self) -> Vec<String> {
        self.check.columns()
    }

    fn converged(&mut self, at: &Converged<D>) -> Result<(), String> {
        if let (Some(nodes), true) = (at.nodes, self.check.needs_nodes()) {
            self.check.observe_nodes(nodes, at.model, at.coll)?;
        }
        self.check.observe_reactions(&at.forces.reactions);
        Ok(())
    }

    fn record(&mut self, at: &Moment<D>, _row: bool, _sink: &mut Sink) -> Result<Vec<f64>, String> {
        self.check.observe(at.t, at.dt, at.model, at.coll)
    }

    fn finish(&mut self, at: &Moment<D>, sink: &mut Sink) -> Result<(), String> {
        // The results after `finish` (which may complete them), also when it fails.
        let finished = self.check.finish(at.model, at.coll);
        sink.summary.results.extend(self.check.results());
        let (metrics, tables) = finished?;
        sink.summary.verification_passed = Some(metrics.iter().all(|m| m.1.pass));
        for t in &tables {
            sink.out.write_table(&t.name, &t.header, &t.rows)?;
        }
        sink.summary.verification = metrics.into_iter().collect();
        sink.figures.extend(self.check.figures());
        Ok(())
    }

    fn state(&self, at: &Moment<D>) -> Result<Option<Vec<f64>>, String> {
        self.check.checkpoint_state(at.model, at.coll)
    }

    fn restore(&mut self, FromCheckpoint { state, at, .. }: FromCheckpoint<D>) -> Restored {
        match state {
            Some(s) => {
                self.check.restore_state(s, at.model).map_err(|e| format!("verification state: {e}"))?;
                Ok(None)
            }
            None => Ok(Some(format!(
                "the verification check keeps no checkpoint state: its metrics use the run from t = {:.6e} s only",
                at.t
            ))),
        }
    }

    fn event_times(&self) -> Vec<f64> {
        self.check.event_times()
    }

    fn stop(&self) -> Option<String> {
        self.check.stop()
    }

    fn needs_nodes(&self, _step: usize, _stage_end: bool) -> bool {
        self.check.needs_nodes()
    }
}
