//! The steady-state harmonic column (Zienkiewicz, Chang & Bettess 1980; [003] §4.1.2,
//! `kind = "harmonic_column"`): over the last `measure_periods` whole load periods each particle's
//! pressure is projected on cos ωt and sin ωt with a Hann window w(t) = sin²(π(t−t₀)/T_w),
//! A = 2 |∫ w p e^{-iωt} dt| / ∫ w dt. For a pure tone at ω over whole periods this is exact; free
//! vibrations at other frequencies ω' leak into it only like 1/((ω'−ω)T_w)³ (a rectangular window
//! leaks like 1/((ω'−ω)T_w)). `p_amplitude_max_rel_error` is max_z |A − A*| / max_z A* over the
//! depth profile (particles at the same depth averaged), A* from [`biot_harmonic`].

use super::consolidation::TWO_PHASE;
use super::{
    biot_harmonic, figures, tolerance, BodyAndLoad, BuiltCheck, Check, CheckParameters, Column, Findings,
    FormulationNeed, Metric, Table,
};
use crate::case::{Case, TimeFunction};
use crate::check::{at, Checked};
use crate::model::Model;
use crate::parallel::Collective;
use serde::{Deserialize, Serialize};

/// The parameters of `kind = "harmonic_column"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HarmonicColumn {
    /// The name of the column body.
    pub body: String,
    /// The name of the harmonic surface load, a particle or nodal traction with a `harmonic` time
    /// function.
    pub load: String,
    /// Number of final load periods over which the amplitude is measured [-], ≥ 1 (default 3).
    #[serde(default = "default_periods")]
    pub measure_periods: usize,
    /// Pass threshold for the maximum amplitude error relative to the peak amplitude [-], in (0, 1].
    pub tolerance: f64,
}

serde_defaults! { default_periods: usize = 3 }

impl CheckParameters for HarmonicColumn {
    type Ids = BodyAndLoad;
    const FORMULATION: FormulationNeed = TWO_PHASE;

    fn check(&self, key: &str) -> Checked {
        tolerance(&at(key, "tolerance"), self.tolerance)?;
        if self.measure_periods == 0 {
            return Err(format!("key `{}`: must be at least 1", at(key, "measure_periods")));
        }
        Ok(())
    }

    fn describe(&self) -> String {
        format!("harmonic column (Zienkiewicz et al. 1980), last {} periods", self.measure_periods)
    }

    fn link(&self, c: &Case) -> Result<BodyAndLoad, String> {
        BodyAndLoad::plain(c, &self.body, &self.load)
    }

    fn plane(&self, c: &Case, ids: &BodyAndLoad, model: &Model, _coll: &Collective) -> BuiltCheck {
        let col = Column::from_case(c, model, ids)?;
        let Some(TimeFunction::Harmonic(f)) = c.load_time_function(ids.load) else {
            let name = c.load(ids.load).name();
            return Err(format!("verification load `{name}` must have a harmonic time function"));
        };
        let (periods, tol) = (self.measure_periods, self.tolerance);
        Ok(Box::new(HarmonicCheck::new(col, f.angular_frequency, c.end_time(), periods, tol)?))
    }
}

/// Steady-state harmonic column check.
pub struct HarmonicCheck {
    col: Column,
    omega: f64,
    window: (f64, f64),
    tolerance: f64,
    theory: biot_harmonic::BiotSolution,
    /// Per local particle: (∫ w p cos ωt, ∫ w p sin ωt) over the window.
    sums: Vec<(f64, f64)>,
    /// ∫ w dt.
    weight: f64,
    /// (depth, computed |p|/q) after [`Check::finish`].
    profile: Vec<(f64, f64)>,
}

impl HarmonicCheck {
    fn new(col: Column, omega: f64, end: f64, periods: usize, tolerance: f64) -> Result<HarmonicCheck, String> {
        if col.inv_q <= 0.0 {
            return Err("the harmonic column needs a compressible pore fluid (finite water_bulk_modulus)".into());
        }
        let period = 2.0 * std::f64::consts::PI / omega;
        let start = end - periods as f64 * period;
        if start <= 0.0 {
            return Err(format!(
                "the run ({end} s) is shorter than the {periods} measured load periods ({period:.4e} s each)"
            ));
        }
        let theory = biot_harmonic::BiotColumn {
            height: col.height,
            constrained_modulus: col.constrained_modulus,
            q_modulus: 1.0 / col.inv_q,
            porosity: col.porosity,
            solid_density: col.solid_density,
            water_density: col.water_density,
            conductivity: col.conductivity,
            gravity: col.g,
            omega,
            load_amplitude: col.load,
        }
        .solve()?;
        Ok(HarmonicCheck {
            col,
            omega,
            window: (start, end),
            tolerance,
            theory,
            sums: Vec::new(),
            weight: 0.0,
            profile: Vec::new(),
        })
    }
}

impl Check for HarmonicCheck {
    fn columns(&self) -> Vec<String> {
        Vec::new()
    }

    fn event_times(&self) -> Vec<f64> {
        vec![self.window.0]
    }

    fn observe(&mut self, t: f64, dt: f64, model: &Model, _coll: &Collective) -> Result<Vec<f64>, String> {
        if self.sums.len() != model.particles.len() {
            self.sums = vec![(0.0, 0.0); model.particles.len()];
        }
        // Right-endpoint sums (the window vanishes at both ends, so this is the trapezoidal rule).
        if t > self.window.0 + 1e-9 * dt && t <= self.window.1 + 1e-9 * dt {
            let tw = self.window.1 - self.window.0;
            let w = (std::f64::consts::PI * (t - self.window.0) / tw).sin().powi(2);
            self.weight += w * dt;
            let (c, s) = ((self.omega * t).cos(), (self.omega * t).sin());
            for k in self.col.particles(model) {
                self.sums[k].0 += w * model.particles.p[k] * c * dt;
                self.sums[k].1 += w * model.particles.p[k] * s * dt;
            }
        }
        Ok(Vec::new())
    }

    /// ∫ w dt, then (particle id, ∫ w p cos ωt dt, ∫ w p sin ωt dt) of every particle of the column.
    fn checkpoint_state(&self, model: &Model, coll: &Collective) -> Result<Option<Vec<f64>>, String> {
        let local: Vec<f64> = self
            .col
            .particles(model)
            .flat_map(|k| {
                let (c, s) = self.sums.get(k).copied().unwrap_or((0.0, 0.0));
                [model.particles.id[k] as f64, c, s]
            })
            .collect();
        let mut state = vec![self.weight];
        state.extend(coll.gather(&local)?);
        Ok(Some(state))
    }

    fn restore_state(&mut self, state: &[f64], model: &Model) -> Result<(), String> {
        if state.is_empty() || !(state.len() - 1).is_multiple_of(3) {
            return Err(format!("{} values do not make the harmonic sums", state.len()));
        }
        self.weight = state[0];
        let sums: std::collections::HashMap<u64, (f64, f64)> =
            state[1..].chunks(3).map(|r| (r[0] as u64, (r[1], r[2]))).collect();
        self.sums = (0..model.particles.len())
            .map(|k| sums.get(&model.particles.id[k]).copied().unwrap_or((0.0, 0.0)))
            .collect();
        Ok(())
    }

    fn finish(&mut self, model: &Model, coll: &Collective) -> Result<Findings, String> {
        if self.weight <= 0.0 {
            return Err("the measurement window of the harmonic column was never reached".into());
        }
        let norm = 2.0 / self.weight;
        let local: Vec<f64> = self
            .col
            .particles(model)
            .flat_map(|k| {
                let (c, s) = self.sums.get(k).copied().unwrap_or((0.0, 0.0));
                [self.col.top - model.particles.x0[k][1], norm * (c * c + s * s).sqrt()]
            })
            .collect();
        let all = coll.gather(&local)?;
        // Average the particles at the same depth.
        let mut rows: Vec<(f64, f64, usize)> = Vec::new();
        for d in all.chunks(2) {
            match rows.iter_mut().find(|r| (r.0 - d[0]).abs() < 1e-9 * self.col.height) {
                Some(r) => {
                    r.1 += d[1];
                    r.2 += 1;
                }
                None => rows.push((d[0], d[1], 1)),
            }
        }
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        let q = self.col.load;
        let table: Vec<Vec<f64>> =
            rows.iter().map(|r| vec![r.0, r.1 / r.2 as f64 / q, self.theory.pressure_amplitude(r.0) / q]).collect();
        let peak = table.iter().map(|r| r[2]).fold(0.0, f64::max);
        let (worst, at) =
            table.iter().map(|r| ((r[1] - r[2]).abs(), r[0])).fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a });
        let err = worst / peak;
        self.profile = table.iter().map(|r| (r[0], r[1])).collect();
        let metric = Metric::error(
            err,
            self.tolerance,
            format!(
                "largest |A - A*| = {worst:.4e} q at depth {at:.3} m; peak A* = {peak:.4e} q; ω = {:.4e} rad/s",
                self.omega
            ),
        );
        Ok((
            vec![("p_amplitude_max_rel_error".into(), metric)],
            vec![Table {
                name: "amplitude_profile.csv".into(),
                header: vec!["depth_m", "computed_p_amplitude_over_q", "analytical_p_amplitude_over_q"],
                rows: table,
            }],
        ))
    }

    fn figures(&self) -> Vec<crate::plot::Figure> {
        let q = self.col.load;
        let h = self.col.height;
        let reference: Vec<(f64, f64)> = figures::sample(0.0, h, 400, |d| d)
            .into_iter()
            .map(|d| (d, self.theory.pressure_amplitude(d) / q))
            .collect();
        vec![figures::depth_profile(
            "harmonic_amplitude_profile.png",
            &format!("Harmonic column: pore pressure amplitude (ω = {:.4e} rad/s)", self.omega),
            "pore pressure amplitude |p|/q [-]",
            "depth below the loaded top [m]",
            "MPM (particles at one depth averaged)",
            &self.profile,
            "Biot, steady state",
            &reference,
        )]
    }
}
