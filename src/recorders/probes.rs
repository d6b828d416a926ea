//! The case's probes: each follows the material point nearest to its point at t = 0, and
//! `history.csv` carries its position, displacement, velocity, stresses, plastic strain and, in
//! two-phase runs, pore pressure and excess pore pressure; `summary.json` its final displacement and
//! the extremes of its excess pore pressure.

use super::{FromCheckpoint, Moment, Recorder, Restored, Sink};
use crate::case::Case;
use crate::model::Model;
use crate::parallel::Collective;

/// A probe: the particle it follows and what it has seen.
struct Probe {
    name: String,
    id: u64,
    /// Its values after the last step ([`fields`] order).
    last: Vec<f64>,
    /// The excess pore pressure of largest magnitude so far, with its sign.
    excess_extreme: f64,
}

/// The probes of a run.
pub struct Probes {
    probes: Vec<Probe>,
    pore_water: bool,
}

impl Probes {
    /// The probes of the case: each the point nearest its `point` at t = 0 (the lowest identifier
    /// among equally near ones), in any dimension (collective).
    pub fn new<const D: usize>(case: &Case, model: &Model<D>, coll: &Collective) -> Result<Probes, String> {
        let mut probes = Vec::new();
        for p in &case.probes {
            let id = model
                .nearest_point(coll, &p.point)?
                .ok_or(format!("probe `{}`: there are no material points", p.name))?;
            probes.push(Probe { name: p.name.clone(), id, last: Vec::new(), excess_extreme: 0.0 });
        }
        Ok(Probes { probes, pore_water: model.pore_water })
    }
}

/// The history columns of a probe in dimension `dim`: its position, displacement and velocity
/// (D components each), its stresses (the plane's xx, yy, xy; in three dimensions also zz, yz,
/// zx, in `Particles::stress` order), its plastic strain, and in two-phase runs its pore pressure
/// and excess pore pressure (last).
fn fields(pore_water: bool, dim: usize) -> Vec<&'static str> {
    let mut fields = if dim == 3 {
        vec!["x", "y", "z", "ux", "uy", "uz", "vx", "vy", "vz", "sxx", "syy", "sxy", "szz", "syz", "szx", "eps_pd"]
    } else {
        vec!["x", "y", "ux", "uy", "vx", "vy", "sxx", "syy", "sxy", "eps_pd"]
    };
    if pore_water {
        fields.extend(["p", "p_excess"]);
    }
    fields
}

impl<const D: usize> Recorder<D> for Probes {
    fn name(&self) -> &'static str {
        "probes"
    }

    fn columns(&self) -> Vec<String> {
        let fields = fields(self.pore_water, D);
        self.probes.iter().flat_map(|p| fields.iter().map(move |f| format!("{}.{f}", p.name))).collect()
    }

    fn record(&mut self, at: &Moment<D>, _row: bool, _sink: &mut Sink) -> Result<Vec<f64>, String> {
        let (model, ps) = (at.model, &at.model.particles);
        let nf = fields(self.pore_water, D).len();
        // The plane's xx, yy, xy; in three dimensions all six ([xx, yy, xy, zz, yz, zx]).
        let stresses = if D == 3 { 6 } else { 3 };
        let mut local = vec![0.0; self.probes.len() * nf];
        for (i, pr) in self.probes.iter().enumerate() {
            if let Some(k) = (0..ps.len()).find(|&k| ps.id[k] == pr.id) {
                let mut v = Vec::with_capacity(nf);
                v.extend(ps.x[k].iter().chain(&ps.disp[k]).chain(&ps.vel[k]).chain(&ps.stress[k][..stresses]));
                v.push(ps.eps_pd[k]);
                if model.pore_water {
                    v.extend([ps.p[k], ps.p[k] - ps.p0[k]]);
                }
                local[i * nf..(i + 1) * nf].copy_from_slice(&v);
            }
        }
        let all = at.coll.sum(&local)?;
        for (i, pr) in self.probes.iter_mut().enumerate() {
            pr.last = all[i * nf..(i + 1) * nf].to_vec();
            if self.pore_water {
                let e = pr.last[nf - 1];
                if e.abs() > pr.excess_extreme.abs() {
                    pr.excess_extreme = e;
                }
            }
        }
        Ok(all)
    }

    fn finish(&mut self, _at: &Moment<D>, sink: &mut Sink) -> Result<(), String> {
        let results = &mut sink.summary.results;
        for pr in &self.probes {
            if pr.last.len() >= 2 * D {
                // |u| from the displacement's D components (after the position's D).
                let u = pr.last[D..2 * D].iter().fold(0.0f64, |m, c| m.hypot(*c));
                results.insert(format!("{}.displacement", pr.name), u);
            }
            if self.pore_water {
                results.insert(format!("{}.excess_p_peak", pr.name), pr.excess_extreme);
                if let Some(&e) = pr.last.last() {
                    results.insert(format!("{}.excess_p_final", pr.name), e);
                }
            }
        }
        Ok(())
    }

    fn state(&self, _at: &Moment<D>) -> Result<Option<Vec<f64>>, String> {
        Ok(Some(self.probes.iter().map(|p| p.excess_extreme).collect()))
    }

    fn restore(&mut self, FromCheckpoint { state, .. }: FromCheckpoint<D>) -> Restored {
        let extremes = state.unwrap_or_default();
        if extremes.len() != self.probes.len() {
            return Err(format!(
                "it holds {} probes' extremes, this case has {} probes",
                extremes.len(),
                self.probes.len()
            ));
        }
        for (p, &e) in self.probes.iter_mut().zip(extremes) {
            p.excess_extreme = e;
        }
        Ok(None)
    }
}
