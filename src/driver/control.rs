//! Time-step control within a stage ([`StepControl`]): the Δt of the next try, cuts after a
//! failed try, regrowth after successes, and landing exactly on event times (the times a
//! verification needs) and on the stage end.

use crate::case::Stage;

/// Accepted steps after which a cut Δt grows back by one factor.
const GROW_AFTER: usize = 3;
/// Newton iterations up to which a step counts as easy: after [`GROW_AFTER`] accepted steps, the
/// last of them easy, Δt may grow beyond the stage's `dt` up to its `dt_max`.
const EASY_NEWTON: usize = 3;

/// The step control of a stage.
#[derive(Debug, Clone)]
pub(super) struct StepControl {
    stage_dt: f64,
    /// The largest Δt after easy steps.
    dt_max: f64,
    /// The Δt of the next try [s].
    pub dt: f64,
    cuts: usize,
    /// Accepted steps since Δt last changed.
    pub successes: usize,
    max_cuts: usize,
    factor: f64,
    /// The stage's end [s].
    pub t_end: f64,
}

impl StepControl {
    /// The control of `stage` up to `t_end`, its steps at most `limit` (an explicit stage's
    /// stable step) as well as its `dt`.
    pub(super) fn new(stage: &Stage, t_end: f64, limit: Option<f64>) -> StepControl {
        let dt = limit.map_or(stage.dt(), |l| l.min(stage.dt()));
        StepControl {
            stage_dt: dt,
            dt_max: if limit.is_some() { dt } else { stage.dt_max.unwrap_or(dt) },
            dt,
            cuts: 0,
            successes: 0,
            max_cuts: stage.max_step_cuts,
            factor: stage.cut_factor,
            t_end,
        }
    }

    /// Round-off allowance on times.
    fn tiny(&self) -> f64 {
        1e-9 * self.stage_dt
    }

    /// Whether the stage is done at time `t`.
    pub(super) fn finished(&self, t: f64) -> bool {
        t >= self.t_end - self.tiny()
    }

    /// Δt of the next try from `t`: the current Δt, shortened to land on the first event time
    /// inside the step and on the stage end.
    pub(super) fn next(&self, t: f64, events: &[f64]) -> f64 {
        let mut next = t + self.dt;
        for &e in events {
            if e > t + self.tiny() && e < next {
                next = e;
            }
        }
        // Do not leave a sliver of less than a millionth of a step before the end.
        if next > self.t_end - 1e-6 * self.dt {
            next = self.t_end;
        }
        next - t
    }

    /// The time after an accepted step (exactly the stage end when it lands there).
    pub(super) fn advance(&self, t: f64, dt: f64) -> f64 {
        if (self.t_end - (t + dt)).abs() <= self.tiny() {
            self.t_end
        } else {
            t + dt
        }
    }

    /// Whether a step of `dt` from `t`, once accepted, ends the stage.
    pub(super) fn ends_stage(&self, t: f64, dt: f64) -> bool {
        self.finished(self.advance(t, dt))
    }

    /// After an accepted step that took `newton` iterations: reset the cut count, and after
    /// [`GROW_AFTER`] accepted steps at the same Δt let it grow back towards the stage's (growing
    /// after every step would retry the Δt that just failed at once, which costs a full failed
    /// Newton solve each time in a plastic run), and beyond it up to `dt_max` when the last step
    /// was easy.
    pub(super) fn accepted(&mut self, newton: usize) {
        self.cuts = 0;
        self.successes += 1;
        if self.successes >= GROW_AFTER {
            let cap = if newton <= EASY_NEWTON { self.dt_max } else { self.stage_dt };
            self.dt = self.dt.max((self.dt / self.factor).min(cap));
            self.successes = 0;
        }
    }

    /// After a failed try of length `dt_tried`: cut, or `Err` if the cuts are exhausted.
    pub(super) fn rejected(&mut self, dt_tried: f64) -> Result<(), ()> {
        self.cuts += 1;
        if self.cuts > self.max_cuts {
            return Err(());
        }
        self.dt = dt_tried * self.factor;
        self.successes = 0;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stage(dt: f64, cuts: usize) -> Stage {
        Stage {
            name: "s".into(),
            duration: 1.0,
            dt: Some(dt),
            boundaries: None,
            loads: None,
            max_step_cuts: cuts,
            cut_factor: 0.5,
            time_integration: None,
            analysis: Default::default(),
            theta: None,
            drainage: None,
            dt_max: None,
            explicit: None,
            strength_reduction: None,
        }
    }

    #[test]
    fn an_explicit_stage_keeps_its_stable_step() {
        // The limit caps the stage's Δt, and easy steps do not grow past it.
        let mut st = stage(0.3, 2);
        st.dt_max = Some(1.0);
        let mut c = StepControl::new(&st, 10.0, Some(0.01));
        assert_eq!(c.next(0.0, &[]), 0.01);
        for _ in 0..20 {
            c.accepted(0);
        }
        assert_eq!(c.next(0.0, &[]), 0.01);
        // A stage Δt below the limit is kept.
        assert_eq!(StepControl::new(&stage(0.003, 2), 1.0, Some(0.01)).next(0.0, &[]), 0.003);
    }

    #[test]
    fn steps_land_on_events_and_on_the_stage_end() {
        let c = StepControl::new(&stage(0.3, 2), 1.0, None);
        assert_eq!(c.next(0.0, &[]), 0.3);
        assert!((c.next(0.0, &[0.1, 0.5]) - 0.1).abs() < 1e-15);
        // An event at the current time is not a target.
        assert!((c.next(0.1, &[0.1]) - 0.3).abs() < 1e-15);
        // The last step is shortened to end exactly at the stage end.
        assert!((c.next(0.9, &[]) - 0.1).abs() < 1e-15);
        assert_eq!(c.advance(0.9, 0.1), 1.0);
        assert!(c.finished(1.0 - 1e-12) && !c.finished(0.99));
    }

    #[test]
    fn failed_steps_are_cut_then_grow_back_and_the_cuts_are_limited() {
        let mut c = StepControl::new(&stage(0.2, 2), 1.0, None);
        assert!(c.rejected(0.2).is_ok());
        assert!((c.next(0.0, &[]) - 0.1).abs() < 1e-15);
        assert!(c.rejected(0.1).is_ok());
        assert!((c.next(0.0, &[]) - 0.05).abs() < 1e-15);
        // A third failure in a row exceeds max_step_cuts = 2.
        assert!(c.clone().rejected(0.05).is_err());
        // Success resets the count; every GROW_AFTER successes double Δt back, never above the
        // stage's.
        c.accepted(1);
        assert!((c.dt - 0.05).abs() < 1e-15 && c.cuts == 0);
        for _ in 1..GROW_AFTER {
            c.accepted(1);
        }
        assert!((c.dt - 0.1).abs() < 1e-15);
        for _ in 0..3 * GROW_AFTER {
            c.accepted(1);
        }
        assert_eq!(c.dt, 0.2);
    }

    #[test]
    fn easy_steps_grow_up_to_dt_max_and_hard_ones_do_not() {
        let mut st = stage(0.1, 2);
        st.dt_max = Some(0.4);
        let mut c = StepControl::new(&st, 10.0, None);
        for _ in 0..GROW_AFTER {
            c.accepted(EASY_NEWTON + 1);
        }
        assert_eq!(c.dt, 0.1, "a hard step does not grow beyond the stage's dt");
        for _ in 0..GROW_AFTER {
            c.accepted(EASY_NEWTON);
        }
        assert!((c.dt - 0.2).abs() < 1e-15);
        for _ in 0..4 * GROW_AFTER {
            c.accepted(1);
        }
        assert!((c.dt - 0.4).abs() < 1e-15, "capped at dt_max");
        // A hard step at a grown Δt keeps it (it converged); a failure cuts it.
        for _ in 0..GROW_AFTER {
            c.accepted(10);
        }
        assert!((c.dt - 0.4).abs() < 1e-15);
    }
}
