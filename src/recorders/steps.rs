//! The step columns of `history.csv`: time, step, Δt and the step's Newton and Krylov iterations.

use super::{Moment, Recorder, Sink};

/// The step columns (always the first of the history).
pub struct Steps;

impl<const D: usize> Recorder<D> for Steps {
    fn name(&self) -> &'static str {
        "steps"
    }

    fn columns(&self) -> Vec<String> {
        ["time", "step", "dt", "newton_iterations", "linear_iterations"].map(String::from).to_vec()
    }

    fn record(&mut self, at: &Moment<D>, _row: bool, _sink: &mut Sink) -> Result<Vec<f64>, String> {
        Ok(vec![at.t, at.step as f64, at.dt, at.iterations.0 as f64, at.iterations.1 as f64])
    }
}
