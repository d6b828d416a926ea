//! The load balance of the ranks (`load_imbalance` in `history.csv`, its largest in
//! `summary.json`): the busiest rank's material points over the mean.

use super::{Moment, Recorder, Sink};

/// The load imbalance at each history row (1 on one rank).
pub struct Imbalance;

impl<const D: usize> Recorder<D> for Imbalance {
    fn name(&self) -> &'static str {
        "load_imbalance"
    }

    fn columns(&self) -> Vec<String> {
        vec!["load_imbalance".into()]
    }

    fn record(&mut self, at: &Moment<D>, row: bool, sink: &mut Sink) -> Result<Vec<f64>, String> {
        if !row {
            return Ok(Vec::new());
        }
        let imbalance = crate::distribution::imbalance_of(at.model.particles.len(), at.coll)?;
        sink.summary.load_imbalance_max = sink.summary.load_imbalance_max.max(imbalance);
        Ok(vec![imbalance])
    }
}
