//! The points over the ranks: after every accepted step each point moves to the rank owning the
//! cell that holds its centre ([`crate::distribution::migrate`]), and when the busiest rank holds
//! more than `--balance-threshold` times the mean the grid is repartitioned
//! ([`crate::distribution::balanced`]).

use super::{failed, Dimension, RunError, Simulation};
use crate::distribution::{self, BALANCE_GAIN};
use crate::layout::Dim;
use std::time::Instant;

/// The load balance of a run.
pub(super) struct Balance {
    /// `--balance-threshold`.
    threshold: f64,
    /// The imbalance after the last attempt to repartition (a new attempt waits until the
    /// imbalance has grown by [`BALANCE_GAIN`]).
    last: Option<f64>,
}

impl Balance {
    /// Repartitions past `threshold` (infinite: never).
    pub fn new(threshold: f64) -> Balance {
        Balance { threshold, last: None }
    }
}

impl<const D: usize, const M: usize, const N: usize> Simulation<'_, D, M, N>
where
    Dim<D>: Dimension<D>,
{
    /// Moves the material points whose centre left this rank's cells to their new owner;
    /// counted in summary.json.
    pub(super) fn migrate_particles(&mut self) -> Result<(), RunError> {
        if self.coll.size() == 1 {
            return Ok(());
        }
        let t0 = Instant::now();
        let sent = distribution::migrate(&mut self.model, self.case, self.system.space().owners(), self.coll);
        let summary = &mut *self.journal.summary;
        summary.migrated_particles += self.coll.sum_count(sent as u64) as usize;
        summary.timings.particle_update_s += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// Repartitions the grid over the ranks when the load imbalance passes the threshold and a
    /// better distribution exists: a new global system on the new distribution, the last step's
    /// nodal values carried over to it (for the fields), and the points moved to their new
    /// owners. Counted in summary.json.
    pub(super) fn balance_load(&mut self) -> Result<(), RunError> {
        let Balance { threshold, last } = self.balance;
        if self.coll.size() == 1 || !threshold.is_finite() {
            return Ok(());
        }
        let now = distribution::imbalance_of(self.model.particles.len(), self.coll).map_err(failed)?;
        if now <= threshold || last.is_some_and(|l| now < l * BALANCE_GAIN) {
            return Ok(());
        }
        let t0 = Instant::now();
        let grid = &self.model.grid;
        let mut hist = vec![0.0; grid.cells.iter().product()];
        for x in &self.model.particles.x {
            // The cell that decides the point's owner (`Owners::rank_of`), x fastest.
            hist[grid.cell_number(grid.nearest(*x))] += 1.0;
        }
        let hist = self.coll.sum(&hist).map_err(failed)?;
        let proposal = distribution::balanced(&hist, grid.cells, self.coll.size(), crate::assembly::STENCIL_WIDTH);
        let Some((owners, predicted)) = proposal.filter(|(_, p)| *p * BALANCE_GAIN <= now) else {
            self.balance.last = Some(now);
            return Ok(());
        };
        // The last step's nodal values, for the field output on the new distribution.
        let carried = self.system.space().global_values(&self.nodes, self.coll).map_err(failed)?;
        // The last step's reactions, by node: the next step's work takes their mean with its own.
        let reactions = self.system.space().global_dofs(&self.last_reactions, self.coll).map_err(failed)?;
        let had_reactions = !self.last_reactions.is_empty();
        self.replace_system(self.system.layout(), &owners)?;
        self.nodes = self.system.space().block_of(&carried);
        if had_reactions {
            self.last_reactions = self.system.space().owned_dofs_of(&reactions);
        }
        self.journal.summary.timings.particle_update_s += t0.elapsed().as_secs_f64();
        self.migrate_particles()?;
        self.journal.summary.repartitions += 1;
        self.balance.last = Some(predicted);
        self.journal.progress(&format!(
            "  t = {:.6e} s: load imbalance {now:.2} > {threshold}: grid repartitioned, imbalance now {predicted:.2}",
            self.t
        ));
        Ok(())
    }
}
