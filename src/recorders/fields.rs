//! `fields.h5`/`fields.xdmf`: the points' and the nodes' fields every `output.fields_every` steps,
//! at the start, at each stage's end and when the run stops early or is interrupted (once per step
//! at most).

use super::{Moment, Recorder, Sink};

/// The field output of a run.
pub struct Fields {
    every: usize,
    /// Step of the last output.
    written: Option<usize>,
}

impl Fields {
    /// Fields every `every` steps (0: none).
    pub fn new(every: usize) -> Fields {
        Fields { every, written: None }
    }

    /// Whether step `step` is one of the every-`every` steps (never when fields are off).
    fn due(&self, step: usize) -> bool {
        self.every > 0 && step.is_multiple_of(self.every)
    }

    /// Writes the fields of `at`, unless they are off or written already.
    fn write<const D: usize>(&mut self, at: &Moment<D>, sink: &mut Sink) -> Result<(), String> {
        if self.every == 0 || self.written == Some(at.step) {
            return Ok(());
        }
        let t0 = std::time::Instant::now();
        let frame = crate::fields::frame(at.model, at.nodes, at.coll, at.t);
        sink.out.write_fields(&frame, at.coll.communicator())?;
        self.written = Some(at.step);
        sink.summary.timings.output_s += t0.elapsed().as_secs_f64();
        Ok(())
    }
}

impl<const D: usize> Recorder<D> for Fields {
    fn name(&self) -> &'static str {
        "fields"
    }

    fn record(&mut self, at: &Moment<D>, _row: bool, sink: &mut Sink) -> Result<Vec<f64>, String> {
        if at.step > 0 && self.due(at.step) {
            self.write(at, sink)?;
        }
        Ok(Vec::new())
    }

    fn needs_nodes(&self, step: usize, stage_end: bool) -> bool {
        self.due(step) || (self.every > 0 && stage_end)
    }

    fn milestone(&mut self, at: &Moment<D>, sink: &mut Sink) -> Result<(), String> {
        self.write(at, sink)
    }
}
