//! The run-out of a failing slope ([002] §4.4, the landslide), in any dimension. The case has
//! stages in which the slope stands (e.g. a settling stage at peak strength) and, from the
//! `trigger_stage` on, stages in which it fails (e.g. with the peak strength divided by a strength
//! reduction factor). What the run says about itself:
//!
//! * before the trigger, the slope stands: the front's advance since t = 0 and, at the trigger,
//!   the largest speed of the body's points (metrics `standing_advance` and `standing_speed`);
//! * the body's mass against its initial value (metric `mass_change`: a point lost or counted
//!   twice by a migration shows here);
//! * after every step, history columns: the run-out R (the front's advance beyond its position at
//!   the trigger), the foremost point's leading edge, the centre of mass along x, the largest
//!   speed of a point, the largest accumulated plastic strain ε̄ and the rearmost x of the failed points (ε̄ ≥ `failed_strain`:
//!   how far back the failure has retrogressed);
//! * results: R at the end and at each of the `snapshot_times` after the trigger, the advance of
//!   the centre of mass, the foremost point's advance.
//!
//! The front is the leading edge along +x of the body with at most `spray_fraction` of its mass
//! ahead of it (the points' leading edges x_p + l_p binned at h/20, as the dam break's front,
//! [`Front::of`]): a few points shed ahead of the mass do not carry it. There is no reference
//! solution; `make study-landslide` compares the run-outs of the bases and of F̄ against standard
//! MPM (assertions on their ratios, which do not depend on the slope's geometry).

use super::{all_positive, spray, BuiltCheck, Check, CheckParameters, Findings, FormulationNeed, Metric};
use crate::case::{BodyId, Case, Formulation, StageId};
use crate::check::Checked;
use crate::model::Model;
use crate::parallel::Collective;
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "runout"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Runout {
    /// The name of the sliding body (its material moves along +x).
    pub body: String,
    /// The name of the stage whose start triggers the failure (e.g. by its
    /// `strength_reduction`); the run-out counts from the front's position then.
    pub trigger_stage: String,
    /// Largest accepted advance of the front before the trigger (the slope stands) [m], > 0
    /// (default 0.05).
    #[serde(default = "default_standing_advance")]
    pub standing_advance: f64,
    /// Largest accepted speed of any point of the body at the trigger [m/s], > 0 (default 0.01).
    #[serde(default = "default_standing_speed")]
    pub standing_speed: f64,
    /// Times after the trigger at which the run-out is reported as a result (`runout_t<τ>`,
    /// the stepping lands on them) [s], each in (0, the time from the trigger to the end].
    #[serde(default)]
    pub snapshot_times: Vec<f64>,
    /// Accumulated plastic strain ε̄ beyond which a point counts as failed (the rearmost
    /// failed point marks the retrogression of the failure) [-], > 0 (default 0.5).
    #[serde(default = "default_failed_strain")]
    pub failed_strain: f64,
    /// The share of the body's mass that may lie ahead of the front [-], in [0, 0.05] (default
    /// 1e-3).
    #[serde(default = "default_runout_spray")]
    pub spray_fraction: f64,
}

serde_defaults! {
    default_standing_advance: f64 = 0.05,
    default_standing_speed: f64 = 0.01,
    default_failed_strain: f64 = 0.5,
    default_runout_spray: f64 = 1.0e-3,
}

/// What a run-out check names.
#[derive(Debug, Clone, Copy)]
pub struct RunoutIds {
    /// `body`.
    pub body: BodyId,
    /// `trigger_stage`.
    pub trigger_stage: StageId,
}

impl CheckParameters for Runout {
    type Ids = RunoutIds;
    const FORMULATION: FormulationNeed = Some((Formulation::OnePhase, "the run-out check is for a one_phase analysis"));
    const SOLID: bool = true;

    /// Checks the standing limits, the failed strain and the spray.
    fn check(&self, key: &str) -> Checked {
        let (a, s, f) = (self.standing_advance, self.standing_speed, self.failed_strain);
        all_positive(key, &[("standing_advance", a), ("standing_speed", s), ("failed_strain", f)])?;
        spray(key, self.spray_fraction)
    }

    fn describe(&self) -> String {
        format!(
            "run-out of a slope failing from stage `{}` on ([002] §4.4): the slope standing before it, the mass, \
             the front's advance (no reference solution)",
            self.trigger_stage
        )
    }

    /// The body and the trigger stage, with the snapshot times within the stages from it on.
    fn link(&self, c: &Case) -> Result<RunoutIds, String> {
        let ids = RunoutIds {
            body: c.body_named("verification.body", &self.body)?,
            trigger_stage: c.stage_named("verification.trigger_stage", &self.trigger_stage)?,
        };
        let after: f64 = c.stages[ids.trigger_stage.index()..].iter().map(|s| s.duration).sum();
        match self.snapshot_times.iter().find(|&&t| !(t > 0.0 && t <= after * (1.0 + 1e-12))) {
            Some(t) => {
                Err(format!("key `verification.snapshot_times`: {t} s is not within the {after} s after the trigger"))
            }
            None => Ok(ids),
        }
    }

    fn plane(&self, c: &Case, ids: &RunoutIds, model: &Model, coll: &Collective) -> BuiltCheck {
        Ok(Box::new(RunoutCheck::new(c, model, coll, self, ids)?))
    }

    fn solid(&self, c: &Case, ids: &RunoutIds, model: &Model<3>, coll: &Collective) -> BuiltCheck<3> {
        Ok(Box::new(RunoutCheck::new(c, model, coll, self, ids)?))
    }
}

/// Bins per cell of the leading edges' histogram.
pub(crate) const FRONT_BINS: usize = 20;

/// A body's extent along +x and its mass, summed over the ranks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Front {
    /// The upper edge of the bin in which the mass ahead first exceeds the spray [m].
    pub front: f64,
    /// The foremost point's leading edge x_p + l_p [m].
    pub tip: f64,
    /// The body's mass [kg].
    pub mass: f64,
    /// The x of its centre of mass [m].
    pub centre: f64,
}

impl Front {
    /// The front of the points of `body` with at most `spray` of the mass ahead of it; collective.
    /// The leading edges x_p + l_p (l_p the initial half size along x) are binned at h/20 over the
    /// grid; the front is the upper edge of the bin where the mass ahead first exceeds the spray
    /// (by more than round-off: points of equal mass can make the mass ahead equal the spray, and
    /// the sums over the ranks must not decide the bin).
    pub fn of<const D: usize>(model: &Model<D>, body: u16, spray: f64, coll: &Collective) -> Result<Front, String> {
        let ps = &model.particles;
        let (x0, width) = (model.grid.origin[0], model.grid.h[0] / FRONT_BINS as f64);
        let bins = model.grid.cells[0] * FRONT_BINS + 1;
        let mut hist = vec![0.0; bins + 2];
        let mut tip = f64::NEG_INFINITY;
        for k in (0..ps.len()).filter(|&k| ps.body[k] == body) {
            let edge = ps.x[k][0] + ps.lp0[k][0];
            hist[(((edge - x0) / width).floor().max(0.0) as usize).min(bins - 1)] += ps.mass[k];
            hist[bins] += ps.mass[k];
            hist[bins + 1] += ps.mass[k] * ps.x[k][0];
            tip = tip.max(edge);
        }
        let hist = coll.sum(&hist)?;
        let (mass, moment) = (hist[bins], hist[bins + 1]);
        let front = leading_edge(&hist[..bins], x0, width, spray * mass);
        Ok(Front { front, tip: coll.max(&[tip])?[0], mass, centre: moment / mass })
    }
}

/// The upper edge of the bin (of `width`, the first starting at `x0`) in which the mass ahead of
/// it, counted from the last bin of `hist` backwards, first exceeds `spray` by more than
/// round-off; `x0` without any mass.
fn leading_edge(hist: &[f64], x0: f64, width: f64, spray: f64) -> f64 {
    let mut ahead = 0.0;
    for b in (0..hist.len()).rev() {
        ahead += hist[b];
        if ahead > spray * (1.0 + 1e-9) {
            return x0 + (b + 1) as f64 * width;
        }
    }
    x0
}

/// The check of a `runout` verification.
pub struct RunoutCheck {
    /// The body's index.
    body: u16,
    /// The trigger time (the trigger stage's start) [s].
    trigger: f64,
    /// The front at t = 0.
    start: Front,
    /// The front at the trigger, once reached.
    at_trigger: Option<Front>,
    /// The largest speed of the body's points at the trigger [m/s].
    speed_at_trigger: f64,
    /// The largest front advance before the trigger [m].
    advance_before: f64,
    /// The largest |mass/initial mass − 1| seen.
    mass_change: f64,
    /// The last front seen (for the results).
    last: Front,
    /// (time after the trigger, R) at each snapshot time.
    snapshots: Vec<(f64, f64)>,
    /// The snapshot times after the trigger [s].
    snapshot_times: Vec<f64>,
    standing_advance: f64,
    standing_speed: f64,
    failed_strain: f64,
    spray: f64,
}

impl RunoutCheck {
    /// The check of the case's `runout` verification `spec`, whose names resolve to `ids`;
    /// collective.
    pub fn new<const D: usize>(
        c: &Case,
        model: &Model<D>,
        coll: &Collective,
        spec: &Runout,
        ids: &RunoutIds,
    ) -> Result<RunoutCheck, String> {
        let bi = ids.body.index() as u16;
        let trigger = c.stages[..ids.trigger_stage.index()].iter().map(|s| s.duration).sum();
        let start = Front::of(model, bi, spec.spray_fraction, coll)?;
        if start.mass.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Err(format!("verification: the body `{}` holds no material points", spec.body));
        }
        Ok(RunoutCheck {
            body: bi,
            trigger,
            start,
            at_trigger: None,
            speed_at_trigger: f64::NAN,
            advance_before: 0.0,
            mass_change: 0.0,
            last: start,
            snapshots: Vec::new(),
            snapshot_times: spec.snapshot_times.clone(),
            standing_advance: spec.standing_advance,
            standing_speed: spec.standing_speed,
            failed_strain: spec.failed_strain,
            spray: spec.spray_fraction,
        })
    }

    /// The run-out of `f`: its front's advance beyond the front at the trigger (before the
    /// trigger, beyond the front at t = 0).
    fn runout(&self, f: &Front) -> f64 {
        f.front - self.at_trigger.as_ref().unwrap_or(&self.start).front
    }

    /// Whether `t` is the time `target` (to the stepping's round-off).
    fn at(t: f64, target: f64) -> bool {
        (t - target).abs() <= 1e-9 * target.abs().max(1e-300)
    }
}

impl<const D: usize> Check<D> for RunoutCheck {
    fn columns(&self) -> Vec<String> {
        ["runout", "runout_tip", "mass_centre_x", "max_speed", "max_plastic_strain", "failed_rearmost_x"]
            .iter()
            .map(|s| s.to_string())
            .collect()
    }

    fn event_times(&self) -> Vec<f64> {
        let mut t = vec![self.trigger];
        t.extend(self.snapshot_times.iter().map(|s| self.trigger + s));
        t
    }

    fn observe(&mut self, t: f64, _dt: f64, model: &Model<D>, coll: &Collective) -> Result<Vec<f64>, String> {
        let f = Front::of(model, self.body, self.spray, coll)?;
        let ps = &model.particles;
        let mine = (0..ps.len()).filter(|&k| ps.body[k] == self.body);
        let (mut strain, mut rearmost, mut speed) = (0.0f64, f64::INFINITY, 0.0f64);
        for k in mine {
            strain = strain.max(ps.eps_pd[k]);
            if ps.eps_pd[k] >= self.failed_strain {
                rearmost = rearmost.min(ps.x[k][0]);
            }
            speed = speed.max(ps.vel[k].iter().map(|v| v * v).sum::<f64>().sqrt());
        }
        let most = coll.max(&[strain, -rearmost, speed])?;
        let (strain, rearmost, speed) = (most[0], -most[1], most[2]);
        self.mass_change = self.mass_change.max((f.mass / self.start.mass - 1.0).abs());
        if self.at_trigger.is_none() {
            self.advance_before = self.advance_before.max(self.runout(&f));
            if Self::at(t, self.trigger) || t > self.trigger {
                self.at_trigger = Some(f);
                self.speed_at_trigger = speed;
            }
        } else if let Some(&s) = self.snapshot_times.iter().find(|&&s| Self::at(t, self.trigger + s)) {
            let r = self.runout(&f);
            self.snapshots.push((s, r));
        }
        self.last = f;
        Ok(vec![self.runout(&f), f.tip - self.start.tip, f.centre, speed, strain, rearmost])
    }

    fn finish(&mut self, _model: &Model<D>, _coll: &Collective) -> Result<Findings, String> {
        let mut metrics = vec![(
            "mass_change".to_string(),
            Metric::error(
                self.mass_change,
                1e-12,
                format!("largest |m/m₀ − 1| of the body over the run, m₀ = {:.6e} kg", self.start.mass),
            ),
        )];
        if self.at_trigger.is_some() {
            metrics.push((
                "standing_advance".into(),
                Metric::error(
                    self.advance_before,
                    self.standing_advance,
                    format!("largest advance of the front before the trigger at t = {} s [m]", self.trigger),
                ),
            ));
            metrics.push((
                "standing_speed".into(),
                Metric::error(
                    self.speed_at_trigger,
                    self.standing_speed,
                    format!("largest speed of the body's points at the trigger, t = {} s [m/s]", self.trigger),
                ),
            ));
        } else {
            metrics.push((
                "standing_advance".into(),
                Metric::error(f64::NAN, self.standing_advance, "the run ended before the trigger".into()),
            ));
        }
        Ok((metrics, Vec::new()))
    }

    fn results(&self) -> Vec<(String, f64)> {
        let mut r = vec![
            ("runout".to_string(), if self.at_trigger.is_some() { self.runout(&self.last) } else { f64::NAN }),
            ("runout_tip".to_string(), self.last.tip - self.at_trigger.unwrap_or(self.start).tip),
            ("mass_centre_advance".to_string(), self.last.centre - self.at_trigger.unwrap_or(self.start).centre),
        ];
        r.extend(self.snapshots.iter().map(|(s, v)| (format!("runout_t{s}"), *v)));
        r
    }

    fn checkpoint_state(&self, _model: &Model<D>, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        let f = |f: &Front| [f.front, f.tip, f.mass, f.centre];
        let mut v = vec![self.speed_at_trigger, self.advance_before, self.mass_change];
        v.extend(f(&self.start));
        v.extend(self.at_trigger.as_ref().map_or([f64::NAN; 4], f));
        v.extend(self.snapshots.iter().flat_map(|&(s, r)| [s, r]));
        Ok(Some(v))
    }

    fn restore_state(&mut self, state: &[f64], _model: &Model<D>) -> Result<(), String> {
        if state.len() < 11 || !(state.len() - 11).is_multiple_of(2) {
            return Err(format!("a run-out check's state has 11 + 2n values, the checkpoint has {}", state.len()));
        }
        let f = |v: &[f64]| Front { front: v[0], tip: v[1], mass: v[2], centre: v[3] };
        self.speed_at_trigger = state[0];
        self.advance_before = state[1];
        self.mass_change = state[2];
        self.start = f(&state[3..7]);
        self.at_trigger = if state[7].is_nan() { None } else { Some(f(&state[7..11])) };
        self.snapshots = state[11..].chunks_exact(2).map(|c| (c[0], c[1])).collect();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::leading_edge;

    /// The front is the upper edge of the foremost bin with mass when no spray is allowed; a spray
    /// of exactly the foremost bins' mass leaves them ahead of the front (round-off does not
    /// decide); an empty histogram gives its start.
    #[test]
    fn the_front_leaves_at_most_the_spray_ahead_of_it() {
        let hist = [0.0, 2.0, 1.0, 0.0, 1.0, 0.0];
        assert_eq!(leading_edge(&hist, -1.0, 0.5, 0.0), 1.5);
        assert_eq!(leading_edge(&hist, -1.0, 0.5, 1.0), 0.5);
        assert_eq!(leading_edge(&hist, -1.0, 0.5, 1.0 + 1e-12), 0.5);
        assert_eq!(leading_edge(&hist, -1.0, 0.5, 2.5), 0.0);
        assert_eq!(leading_edge(&[0.0; 4], -1.0, 0.5, 0.0), -1.0);
    }
}
