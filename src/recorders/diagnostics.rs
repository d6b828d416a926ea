//! The stability diagnostics of every run ([`crate::diagnostics::Monitor`]): in two-phase runs the
//! checkerboard and pressure oscillation indices and the pore-pressure range, in runs with dynamic
//! stages the energy balance; the warnings they raise and their worst values in `summary.json`.

use super::{FromCheckpoint, Moment, Recorder, Restored, Sink};
use crate::case::{AnalysisType, Case};
use crate::diagnostics::Monitor;
use crate::model::Model;

/// The run's diagnostics.
pub struct Diagnostics {
    monitor: Monitor,
}

impl Diagnostics {
    /// The diagnostics of `case`: the two-phase ones in a two-phase model, the energy balance when
    /// a stage is dynamic.
    pub fn new<const D: usize>(case: &Case, model: &Model<D>) -> Diagnostics {
        let dynamic = case.stages.iter().any(|s| s.analysis == AnalysisType::Dynamic);
        Diagnostics { monitor: Monitor::new(model.pore_water, dynamic) }
    }
}

impl<const D: usize> Recorder<D> for Diagnostics {
    fn name(&self) -> &'static str {
        "diagnostics"
    }

    fn columns(&self) -> Vec<String> {
        self.monitor.columns()
    }

    fn record(&mut self, at: &Moment<D>, row: bool, sink: &mut Sink) -> Result<Vec<f64>, String> {
        if let Some((work, terms)) = at.energy {
            let [body, internal, d_kinetic, dissipated, kinetic] = terms;
            self.monitor.ledger.add_particles(body, internal, d_kinetic, dissipated, kinetic);
            self.monitor.ledger.external += work;
        }
        if !row {
            return Ok(Vec::new());
        }
        let (values, warnings) = self.monitor.row(at.model, at.owners, at.coll, at.t)?;
        sink.summary.take_worst(&self.monitor.worst);
        sink.warnings.extend(warnings);
        Ok(values)
    }

    fn finish(&mut self, at: &Moment<D>, sink: &mut Sink) -> Result<(), String> {
        sink.warnings.extend(self.monitor.finish(at.t));
        Ok(())
    }

    fn state(&self, at: &Moment<D>) -> Result<Option<Vec<f64>>, String> {
        self.monitor.state(at.coll).map(Some)
    }

    fn restore(&mut self, FromCheckpoint { state, at, summary }: FromCheckpoint<D>) -> Restored {
        self.monitor
            .restore_state(state.unwrap_or_default(), at.coll.rank() == 0)
            .map_err(|e| format!("diagnostics: {e}"))?;
        summary.take_worst(&self.monitor.worst);
        Ok(None)
    }
}
