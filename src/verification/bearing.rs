//! Bearing capacity of a strip footing (or, in three dimensions, a rectangular one): the
//! load–settlement curve of a run and the ultimate pressure read from it ([000] §4.1, §4.3).
//!
//! Every step the check records the footing pressure q and the settlement d:
//! * q is the applied pressure: |traction_y| f(t) for a traction load, or, for a body force acting on
//!   a footing body ([000] §4.1.2: a footing of increasing unit weight), the weight of that body's
//!   material points over the loaded width, Σ m_p |b_y| f(t) / w (the contact force at rest), or,
//!   for a rigid footing pushed in under displacement control (a boundary moving its nodes,
//!   [002] §4.2) or driven by a force (a boundary under a `force`, its nodes tied), the boundary's
//!   downward reaction on the soil over the loaded width, −R_y / w (over the loaded area w ×
//!   `loaded_depth` in three dimensions);
//! * d is the downward displacement of the material point nearest to `settlement_point` at t = 0,
//!   counted from the last observation before the load starts (q = 0), so that a gravity stage
//!   before the loading does not count as settlement.
//!
//! The curve goes to `load_settlement.csv` and history.csv (q, q/c, d/B). With `failure_settlement`,
//! q_ult is the pressure at which d/B first reaches it (interpolated between steps); with `plateau`
//! = [a, b] (displacement control, where q levels off at the limit load), q_ult is the mean of q
//! over the steps with d/B in [a, b] (an explicit run's reaction oscillates about it). The metric
//! `bearing_capacity_ratio` = (q_ult/c)/reference, with reference 2 + π for Prandtl's undrained
//! strip footing; c is the soil's cohesion (its peak strength). `results` gets q/c at each of `report_settlements`
//! (interpolated), the settlement d [m] at each q/c of `report_loads` and the largest q/c reached. With `stop_settlement` the run ends (completed) once
//! d/B reaches it: a load-controlled footing beyond its limit load would otherwise run away.

use super::undrained::{self, UndrainedPressure};
use super::{
    all_positive, each_positive, load_name, plain_load, BuiltCheck, Check, CheckParameters, Findings, Metric, Table,
};
use crate::case::{BodyId, BoundaryId, Case, Dof, Formulation, Geometry, Load, LoadId};
use crate::check::{at, components, positive, Checked};
use crate::model::loads::TimeFn;
use crate::model::Model;
use crate::parallel::Collective;
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "bearing_capacity"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BearingCapacity {
    /// The name of the soil body (its cohesion normalises the pressure).
    pub soil: String,
    /// The name of the load: a traction (its pressure), or a body force on the footing body (its
    /// weight over `loaded_width`; the body force must name its bodies). Give `load` or `footing`.
    pub load: Option<String>,
    /// The name of a rigid footing: a boundary that fixes `uy` and pushes it into the soil under
    /// displacement control (a vertical `velocity` or `displacement`, [002] §4.2) or drives it by a
    /// vertical `force`; the pressure is its vertical reaction on the soil over `loaded_width`.
    /// Give `load` or `footing`.
    pub footing: Option<String>,
    /// Width carrying the load in the model [m], > 0 (the half-width in a half model).
    pub loaded_width: f64,
    /// In three dimensions, the loaded area's extent along z in the model [m], > 0 (the
    /// half-length of a footing in a quarter model): the pressure is the force over
    /// `loaded_width` × `loaded_depth`. Required in three dimensions; two-dimensional cases do not
    /// take it.
    pub loaded_depth: Option<f64>,
    /// Footing breadth B [m], > 0 (normalises the settlement).
    pub breadth: f64,
    /// The settlement is the downward displacement of the material point nearest to this point
    /// at t = 0 [m] (one coordinate per dimension).
    pub settlement_point: Vec<f64>,
    /// d/B [-], > 0, at which q_ult is read for the metric `bearing_capacity_ratio` (a
    /// load-controlled footing; give this or `plateau`, or neither for no metric).
    pub failure_settlement: Option<f64>,
    /// The range [d/B_from, d/B_to] [-], 0 ≤ d/B_from < d/B_to, over which the mean of q is q_ult
    /// for the metric `bearing_capacity_ratio` (a displacement-controlled footing, whose load
    /// levels off at the limit load).
    pub plateau: Option<[f64; 2]>,
    /// Reference q_ult/c [-], > 0 (default 2 + π, Prandtl).
    #[serde(default = "default_prandtl")]
    pub reference: f64,
    /// Largest accepted |(q_ult/c)/reference − 1| [-], in (0, 1] (default 0.03).
    #[serde(default = "default_bearing_tol")]
    pub tolerance: f64,
    /// d/B values [-], each > 0, at which q/c is reported in summary.json `results`.
    #[serde(default)]
    pub report_settlements: Vec<f64>,
    /// q/c values [-], each > 0, at which the settlement of the point d [m] is reported in
    /// summary.json `results` as `settlement_at_qc<value>`.
    #[serde(default)]
    pub report_loads: Vec<f64>,
    /// d/B [-], > 0, at which the run ends, completed (a load-controlled footing beyond its limit
    /// load runs away; default: run to the end).
    pub stop_settlement: Option<f64>,
    /// The excess pore pressure under a rigid strip footing (`footing`) on undrained two-phase
    /// soil at an early load level against the elastic undrained closed form (the metric
    /// `excess_pressure_rms_rel_error`; plane strain).
    pub undrained_pressure: Option<UndrainedPressure>,
}

serde_defaults! { default_prandtl: f64 = 2.0 + std::f64::consts::PI, default_bearing_tol: f64 = 0.03 }

/// What a bearing-capacity check names.
#[derive(Debug, Clone, Copy)]
pub struct FootingIds {
    /// `soil`.
    pub soil: BodyId,
    /// What loads the footing.
    pub loading: Loading,
}

/// What loads a footing.
#[derive(Debug, Clone, Copy)]
pub enum Loading {
    /// `load`: a traction, or a body force on the footing body.
    Load(LoadId),
    /// `footing`: a boundary that moves the nodes under the footing (displacement control).
    Footing(BoundaryId),
}

impl CheckParameters for BearingCapacity {
    type Ids = FootingIds;
    const SOLID: bool = true;

    /// Checks the geometry, the settlements and loads to report, and that the footing is loaded
    /// one way.
    fn check(&self, key: &str) -> Checked {
        positive(&at(key, "loaded_width"), self.loaded_width)?;
        if let Some(d) = self.loaded_depth {
            positive(&at(key, "loaded_depth"), d)?;
        }
        if let Some([from, to]) = self.plateau {
            if !(from >= 0.0 && to > from && to.is_finite()) {
                return Err(format!("key `{}`: give 0 ≤ d/B_from < d/B_to, got [{from}, {to}]", at(key, "plateau")));
            }
            if self.failure_settlement.is_some() {
                return Err(format!("key `{}`: give `plateau` or `failure_settlement`, not both", at(key, "plateau")));
            }
        }
        for (f, v) in [("stop_settlement", self.stop_settlement), ("failure_settlement", self.failure_settlement)] {
            if let Some(v) = v {
                positive(&at(key, f), v)?;
            }
        }
        all_positive(key, &[("breadth", self.breadth), ("reference", self.reference), ("tolerance", self.tolerance)])?;
        each_positive(&at(key, "report_settlements"), &self.report_settlements)?;
        each_positive(&at(key, "report_loads"), &self.report_loads)?;
        if self.load.is_some() == self.footing.is_some() {
            return Err(loading_refused(key));
        }
        match &self.undrained_pressure {
            Some(u) => u.check(&at(key, "undrained_pressure")),
            None => Ok(()),
        }
    }

    fn describe(&self) -> String {
        match (self.failure_settlement, self.plateau) {
            (Some(f), _) => format!("bearing capacity: q_ult/c at d/B = {f} against {:.4}", self.reference),
            (None, Some([a, b])) => {
                format!("bearing capacity: q_ult/c, the mean q/c over d/B in [{a}, {b}], against {:.4}", self.reference)
            }
            (None, None) => "load–settlement curve of a footing".into(),
        }
    }

    /// The soil and what loads the footing: a load (a traction, or a body force naming the footing
    /// body) or a boundary that moves it down; the loaded depth as the case's dimension asks, a
    /// settlement point of as many coordinates.
    fn link(&self, c: &Case) -> Result<FootingIds, String> {
        let soil = c.body_named("verification.soil", &self.soil)?;
        let loading = match (&self.load, &self.footing) {
            (None, Some(f)) => Loading::Footing(c.boundary_named("verification.footing", f)?),
            (Some(l), None) => Loading::Load(c.load_named("verification.load", l)?),
            _ => return Err(loading_refused("verification")),
        };
        self.dimensions(c)?;
        if self.undrained_pressure.is_some() {
            let plane = c.dimension() == 2 && c.analysis.geometry != Geometry::Axisymmetric;
            if !(plane && c.analysis.formulation == Formulation::TwoPhase && matches!(loading, Loading::Footing(_))) {
                return Err("key `verification.undrained_pressure`: its closed form is a rigid strip footing's \
                            (`footing`) on two-phase soil in plane strain"
                    .into());
            }
        }
        match loading {
            Loading::Footing(f) => footing_boundary(c, f)?,
            Loading::Load(l) => {
                plain_load(c, l)?;
                if matches!(c.load(l), Load::BodyForce(f) if f.bodies.is_none()) {
                    return Err(format!(
                        "key `verification.load`: the body force `{}` must name the footing body in `bodies`",
                        load_name(c, l)
                    ));
                }
            }
        }
        Ok(FootingIds { soil, loading })
    }

    fn plane(&self, c: &Case, ids: &FootingIds, model: &Model, coll: &Collective) -> BuiltCheck {
        Ok(Box::new(BearingCheck::new(c, model, coll, self, ids)?))
    }

    fn solid(&self, c: &Case, ids: &FootingIds, model: &Model<3>, coll: &Collective) -> BuiltCheck<3> {
        Ok(Box::new(BearingCheck::new(c, model, coll, self, ids)?))
    }
}

impl BearingCapacity {
    /// The loaded depth as the case's dimension asks, and a settlement point of as many
    /// coordinates.
    fn dimensions(&self, c: &Case) -> Checked {
        match (self.loaded_depth, c.dimension()) {
            (None, 3) => {
                return Err("key `verification.loaded_depth`: a three-dimensional footing needs the loaded area's \
                            extent along z"
                    .into())
            }
            (Some(_), 2) => {
                return Err("key `verification.loaded_depth`: only a three-dimensional case takes it (a plane \
                            footing's pressure is its force per unit length over `loaded_width`)"
                    .into())
            }
            _ => {}
        }
        components("verification.settlement_point", &self.settlement_point, c.dimension())
    }
}

/// The message of a footing given both or neither of `load` and `footing`; `key` is the table.
fn loading_refused(key: &str) -> String {
    format!("key `{key}`: a bearing_capacity check takes either `load` (load control) or `footing` (a moving boundary)")
}

/// A footing's boundary: it fixes `uy` and moves it vertically or drives it by a vertical force, so
/// that its reaction is the load.
fn footing_boundary(c: &Case, f: BoundaryId) -> Checked {
    let b = c.boundary(f);
    let vertical = |v: &Option<Vec<f64>>| v.as_ref().is_some_and(|v| v.get(1).is_some_and(|&y| y != 0.0));
    if !b.fix.contains(&Dof::Uy) || !(vertical(&b.velocity) || vertical(&b.displacement) || vertical(&b.force)) {
        return Err(format!(
            "key `verification.footing`: the boundary `{}` must fix `uy` and move it vertically (`velocity` or \
             `displacement`) or drive it by a vertical `force` (a rigid footing): its reaction is the footing's load",
            b.name
        ));
    }
    Ok(())
}

/// The load–settlement check, of a footing in D dimensions.
pub struct BearingCheck<const D: usize = 2> {
    load: LoadKind,
    time_fn: TimeFn,
    cohesion: f64,
    breadth: f64,
    point_id: u64,
    failure: Option<f64>,
    plateau: Option<[f64; 2]>,
    reference: f64,
    tolerance: f64,
    report: Vec<f64>,
    report_loads: Vec<f64>,
    stop_at: Option<f64>,
    /// Downward displacement of the point while q = 0 [m].
    baseline: f64,
    /// The footing boundary's last reaction [N per m; N in 3D] (a displacement-controlled footing).
    reaction: [f64; D],
    /// (t, d/B, q/c) per step.
    curve: Vec<[f64; 3]>,
    /// The undrained pore pressure's comparison, and its last result at an early load level:
    /// [RMS relative error, q/c, points compared].
    undrained: Option<(UndrainedPressure, Option<[f64; 3]>)>,
}

enum LoadKind {
    /// |traction_y| [Pa].
    Traction(f64),
    /// |b_y| [m/s²], bodies, loaded width [m] (area [m²] in 3D).
    Weight(f64, Vec<u16>, f64),
    /// The index of the footing's boundary in `Model::boundaries`, loaded width [m] (area [m²] in 3D).
    Reaction(usize, f64),
}

impl<const D: usize> BearingCheck<D> {
    /// Builds the check of the case's `bearing_capacity` verification `spec`, whose names resolve
    /// to `ids`. The pressure is the force over the loaded width (per unit length in the plane) or
    /// over the loaded width × depth (three dimensions).
    pub fn new(
        c: &Case,
        model: &Model<D>,
        coll: &Collective,
        spec: &BearingCapacity,
        ids: &FootingIds,
    ) -> Result<BearingCheck<D>, String> {
        let Some(cohesion) = c.material_of(ids.soil).model.cohesion() else {
            return Err(format!("the soil `{}` has no cohesion: give it a plastic model", spec.soil));
        };
        if cohesion <= 0.0 {
            return Err("the bearing capacity check normalises by the cohesion, which must be positive".into());
        }
        let loaded = spec.loaded_width * spec.loaded_depth.unwrap_or(1.0);
        let (load, time_fn) = match ids.loading {
            Loading::Footing(b) => (LoadKind::Reaction(b.index(), loaded), TimeFn::Constant(1.0)),
            Loading::Load(l) => (load_of(c, l, loaded)?, super::load_time_fn(c, l)),
        };
        if spec.settlement_point.len() != D {
            return Err(format!("the settlement point needs {D} coordinates, got {}", spec.settlement_point.len()));
        }
        Ok(BearingCheck {
            load,
            time_fn,
            cohesion,
            breadth: spec.breadth,
            point_id: model.nearest_point(coll, &spec.settlement_point)?.ok_or("there are no material points")?,
            failure: spec.failure_settlement,
            plateau: spec.plateau,
            reference: spec.reference,
            tolerance: spec.tolerance,
            report: spec.report_settlements.clone(),
            report_loads: spec.report_loads.clone(),
            stop_at: spec.stop_settlement,
            baseline: 0.0,
            reaction: [0.0; D],
            curve: Vec::new(),
            undrained: spec.undrained_pressure.clone().map(|u| (u, None)),
        })
    }

    fn pressure(&self, t: f64, model: &Model<D>, coll: &Collective) -> Result<f64, String> {
        let f = self.time_fn.eval(t);
        Ok(match &self.load {
            LoadKind::Traction(q) => q * f,
            LoadKind::Weight(b, bodies, width) => {
                let ps = &model.particles;
                let local: f64 = (0..ps.len())
                    .filter(|&k| bodies.contains(&ps.body[k]))
                    .map(|k| ps.mass[k] + model.water_mass(k))
                    .sum();
                coll.sum(&[local])?[0] * b * f / width
            }
            LoadKind::Reaction(_, width) => -self.reaction[1] / width,
        })
    }

    /// While the load is early (q/c at most the undrained comparison's fraction of the reference),
    /// compares the excess pore pressure with the closed form under the load q (collective).
    fn compare_pressure(&mut self, q: f64, model: &Model<D>, coll: &Collective) -> Result<(), String> {
        let (limit, breadth) = (self.reference * self.cohesion, self.breadth);
        let Some((spec, last)) = &mut self.undrained else {
            return Ok(());
        };
        if q > 0.0 && q <= spec.load_fraction * limit {
            let (error, n) = undrained::compare(spec, model, coll, q * breadth, breadth / 2.0)?;
            *last = Some([error, q / self.cohesion, n as f64]);
        }
        Ok(())
    }

    /// d/B at the first crossing of q/c = `target` (interpolated), if reached.
    fn settlement_at(&self, target: f64) -> Option<f64> {
        self.curve.windows(2).find(|w| w[0][2] < target && w[1][2] >= target).map(|w| {
            let s = (target - w[0][2]) / (w[1][2] - w[0][2]);
            w[0][1] + s * (w[1][1] - w[0][1])
        })
    }

    /// q/c at the first crossing of d/B = `target` (interpolated), if reached.
    fn at(&self, target: f64) -> Option<f64> {
        self.curve.windows(2).find(|w| w[0][1] < target && w[1][1] >= target).map(|w| {
            let s = (target - w[0][1]) / (w[1][1] - w[0][1]);
            w[0][2] + s * (w[1][2] - w[0][2])
        })
    }
}

/// The pressure of the case's load `id` on the footing, over the loaded `width`.
fn load_of(c: &Case, id: LoadId, width: f64) -> Result<LoadKind, String> {
    if let Some(traction) = c.load(id).traction() {
        return Ok(LoadKind::Traction(traction[1].abs()));
    }
    match (c.load(id), c.load_bodies(id)) {
        (Load::BodyForce(f), Some(bodies)) if !bodies.is_empty() => {
            Ok(LoadKind::Weight(f.acceleration[1].abs(), bodies.iter().map(|b| b.index() as u16).collect(), width))
        }
        (Load::BodyForce(f), _) => Err(format!("the body force `{}` must name the footing body in `bodies`", f.name)),
        (l, _) => Err(format!("the load `{}` of a bearing check must be a traction or a weight", l.name())),
    }
}

impl<const D: usize> Check<D> for BearingCheck<D> {
    fn columns(&self) -> Vec<String> {
        ["bearing.q", "bearing.q_over_c", "bearing.d_over_B"].iter().map(|s| s.to_string()).collect()
    }

    fn observe_reactions(&mut self, reactions: &[[f64; D]]) {
        if let LoadKind::Reaction(b, _) = self.load {
            self.reaction = reactions[b];
        }
    }

    fn observe(&mut self, t: f64, _dt: f64, model: &Model<D>, coll: &Collective) -> Result<Vec<f64>, String> {
        let q = self.pressure(t, model, coll)?;
        let ps = &model.particles;
        let local: f64 = (0..ps.len()).find(|&k| ps.id[k] == self.point_id).map_or(0.0, |k| -ps.disp[k][1]);
        let mut d = coll.sum(&[local])?[0];
        // A new step (not the repeated observation of a restart) with no load yet sets the zero
        // of the settlement.
        let new_row = self.curve.last().is_none_or(|l| l[0] < t);
        if q == 0.0 && new_row {
            self.baseline = d;
        }
        d -= self.baseline;
        let row = [t, d / self.breadth, q / self.cohesion];
        if new_row {
            self.curve.push(row);
            self.compare_pressure(q, model, coll)?;
        }
        Ok(vec![q, row[2], row[1]])
    }

    fn finish(&mut self, _model: &Model<D>, _coll: &Collective) -> Result<Findings, String> {
        // q_ult/c and how it was read (NaN when the curve never got there), by the settlement at
        // failure or by the plateau's mean.
        let read = match (self.failure, self.plateau) {
            (Some(fs), _) => Some(match self.at(fs) {
                Some(qc) => {
                    (qc, format!("q_ult/c = {qc:.4} at d/B = {fs} vs {:.4}; (q_ult/c)/reference", self.reference))
                }
                None => (f64::NAN, format!("the settlement never reached d/B = {fs}")),
            }),
            (None, Some([from, to])) => {
                let q: Vec<f64> = self.curve.iter().filter(|r| r[1] >= from && r[1] <= to).map(|r| r[2]).collect();
                let reached = self.curve.last().is_some_and(|r| r[1] >= to);
                Some(if q.is_empty() || !reached {
                    (f64::NAN, format!("the settlement never reached d/B = {to}"))
                } else {
                    let qc = q.iter().sum::<f64>() / q.len() as f64;
                    let spread = q.iter().fold(0.0f64, |m, v| m.max((v - qc).abs()));
                    let detail = format!(
                        "q_ult/c = {qc:.4} (mean of {} steps with d/B in [{from}, {to}], largest deviation {spread:.3}) vs \
                         {:.4}; (q_ult/c)/reference",
                        q.len(),
                        self.reference
                    );
                    (qc, detail)
                })
            }
            (None, None) => None,
        };
        let mut metrics: Vec<(String, Metric)> = read
            .map(|(qc, detail)| {
                let ratio = qc / self.reference;
                let metric = Metric {
                    value: ratio,
                    reference: 1.0,
                    tolerance: self.tolerance,
                    pass: (ratio - 1.0).abs() <= self.tolerance,
                    detail,
                };
                ("bearing_capacity_ratio".to_string(), metric)
            })
            .into_iter()
            .collect();
        if let Some((spec, last)) = &self.undrained {
            let metric = match last {
                Some([e, qc, n]) => Metric::error(
                    *e,
                    spec.tolerance,
                    format!(
                        "the excess pore pressure of {n} points at q/c = {qc:.4} against the rigid strip's undrained \
                         elastic closed form, RMS of the difference over RMS of the closed form"
                    ),
                ),
                None => Metric::error(
                    f64::INFINITY,
                    spec.tolerance,
                    format!("no step had q/c in (0, {:.4}]", spec.load_fraction * self.reference),
                ),
            };
            metrics.push(("excess_pressure_rms_rel_error".into(), metric));
        }
        let table = Table {
            name: "load_settlement.csv".into(),
            header: vec!["time", "d_over_B", "q_over_c"],
            rows: self.curve.iter().map(|r| r.to_vec()).collect(),
        };
        Ok((metrics, vec![table]))
    }

    fn figures(&self) -> Vec<crate::plot::Figure> {
        vec![super::figures::load_settlement(&self.curve, self.reference)]
    }

    fn checkpoint_state(&self, _model: &Model<D>, _coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        // [baseline, reaction (D), with the undrained comparison its last result [error, q/c, n]
        // (NaN for none), rows…]: the reaction of the last step is the footing's load when the run
        // restarts.
        let undrained = self.undrained.as_ref().map(|(_, last)| last.unwrap_or([f64::NAN; 3]));
        Ok(Some(
            std::iter::once(self.baseline)
                .chain(self.reaction.iter().copied())
                .chain(undrained.into_iter().flatten())
                .chain(self.curve.iter().flatten().copied())
                .collect(),
        ))
    }

    fn restore_state(&mut self, state: &[f64], _model: &Model<D>) -> Result<(), String> {
        let extra = if self.undrained.is_some() { 3 } else { 0 };
        if state.len() < 1 + D + extra {
            return Err("a load-settlement state without its baseline and reaction".into());
        }
        let (baseline, reaction, rows) = (state[0], &state[1..1 + D], &state[1 + D + extra..]);
        if let Some((_, last)) = &mut self.undrained {
            let r = &state[1 + D..1 + D + 3];
            *last = (!r[0].is_nan()).then(|| [r[0], r[1], r[2]]);
        }
        if !rows.len().is_multiple_of(3) {
            return Err(format!("{} values do not make rows of a load-settlement curve", rows.len()));
        }
        (self.baseline, self.reaction) = (baseline, std::array::from_fn(|c| reaction[c]));
        self.curve = rows.chunks(3).map(|r| [r[0], r[1], r[2]]).collect();
        Ok(())
    }

    fn stop(&self) -> Option<String> {
        let (stop, last) = (self.stop_at?, self.curve.last()?);
        (last[1] >= stop).then(|| format!("the footing settlement reached d/B = {:.4} ≥ {stop}", last[1]))
    }

    fn results(&self) -> Vec<(String, f64)> {
        let mut out: Vec<(String, f64)> =
            self.report.iter().filter_map(|&s| self.at(s).map(|qc| (format!("q_over_c_at_dB{s}"), qc))).collect();
        for &q in &self.report_loads {
            if let Some(d) = self.settlement_at(q) {
                out.push((format!("settlement_at_qc{q}"), d * self.breadth));
            }
        }
        out.push(("q_over_c_max".into(), self.curve.iter().map(|r| r[2]).fold(f64::NEG_INFINITY, f64::max)));
        out.push(("d_over_B_final".into(), self.curve.last().map_or(0.0, |r| r[1])));
        out
    }
}
