//! The excess pore pressure under a rigid strip footing on undrained soil at an early load level
//! (the `undrained_pressure` table of `kind = "bearing_capacity"`).
//!
//! A rigid strip of breadth B = 2b pressed into an elastic half-space with the force P per unit
//! length presses on it with p(s) = P/(π √(b² − s²)) (Sadowsky's contact pressure; e.g. Johnson,
//! Contact Mechanics, 1985, §2.8). Summing Flamant's line loads, the in-plane stresses under it add
//! up to σ_xx + σ_yy = (2P/π) Im[1/√(w² − b²)] at w = x + i z (x from the centre line, z the depth;
//! the root's branch ~w far away), which does not depend on Poisson's ratio. Undrained, with
//! incompressible water and grains, the soil keeps its volume, ν = ½, σ_zz is the in-plane mean and
//! the mean effective stress does not change, so the water carries the whole mean stress:
//! Δp* = −(σ_xx + σ_yy)/2 = −(P/π) Im[1/√(w² − b²)] (compression positive; P/(π √(b² + z²)) on the
//! centre line). The check compares the points' Δp = p − p₀ with Δp* over the points of a region
//! under the footing, `rms_rel_error` = √(Σ V (Δp − Δp*)²) / √(Σ V Δp*²), at the last step whose
//! footing pressure is at most `load_fraction` of the limit pressure (the early, nearly elastic
//! response, before the plastic zones grown from the footing's edges reach the region). The
//! half-space's closed form is the reference: a model of finite extent lies above it by a few per
//! cent (docs/verification.md).

use crate::check::{at, positive, Checked};
use crate::model::Model;
use crate::parallel::Collective;
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// The parameters of the early undrained pore pressure under a rigid strip footing.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct UndrainedPressure {
    /// The footing's centre line x [m] (the symmetry plane of a half model).
    pub axis: f64,
    /// The soil's surface y [m] at t = 0.
    pub surface: f64,
    /// The compared points: those whose initial depth below `surface` lies in this range [m],
    /// 0 ≤ from < to.
    pub depths: [f64; 2],
    /// ... and whose initial distance from `axis` is at most this [m], > 0.
    pub half_width: f64,
    /// The early load level: the last step whose q/c is at most this fraction of the reference
    /// q_ult/c [-], in (0, 1] (default 0.2).
    #[serde(default = "default_fraction")]
    pub load_fraction: f64,
    /// Pass threshold for `rms_rel_error` [-], in (0, 1] (default 0.05).
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
}

serde_defaults! { default_fraction: f64 = 0.2, default_tolerance: f64 = 0.05 }

impl UndrainedPressure {
    /// Checks the ranges; `key` is the table (`verification.undrained_pressure`).
    pub fn check(&self, key: &str) -> Checked {
        let [from, to] = self.depths;
        if !(from >= 0.0 && to > from && to.is_finite()) {
            return Err(format!("key `{}`: give 0 ≤ from < to, got [{from}, {to}]", at(key, "depths")));
        }
        positive(&at(key, "half_width"), self.half_width)?;
        super::tolerance(&at(key, "load_fraction"), self.load_fraction)?;
        super::tolerance(&at(key, "tolerance"), self.tolerance)?;
        if !(self.axis.is_finite() && self.surface.is_finite()) {
            return Err(format!("key `{key}`: `axis` and `surface` must be finite"));
        }
        Ok(())
    }
}

/// Δp* at (x, z) under a rigid strip of half-breadth `b` pressed with `force` per unit length.
pub fn excess_pressure(force: f64, b: f64, x: f64, z: f64) -> f64 {
    let w = Complex64::new(x, z);
    let root = (w - b).sqrt() * (w + b).sqrt();
    -force / std::f64::consts::PI * (1.0 / root).im
}

/// The comparison at one step: the RMS relative error and the number of points compared.
pub fn compare<const D: usize>(
    spec: &UndrainedPressure,
    model: &Model<D>,
    coll: &Collective,
    force: f64,
    b: f64,
) -> Result<(f64, u64), String> {
    let ps = &model.particles;
    let [from, to] = spec.depths;
    let (mut diff, mut norm, mut n) = (0.0, 0.0, 0u64);
    for k in 0..ps.len() {
        let (x, z) = ((ps.x0[k][0] - spec.axis).abs(), spec.surface - ps.x0[k][1]);
        if x <= spec.half_width && z >= from && z <= to {
            let exact = excess_pressure(force, b, x, z);
            diff += ps.volume[k] * (ps.p[k] - ps.p0[k] - exact).powi(2);
            norm += ps.volume[k] * exact * exact;
            n += 1;
        }
    }
    let s = coll.sum(&[diff, norm])?;
    Ok(((s[0] / s[1]).sqrt(), coll.sum_count(n)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form against a direct sum of the contact pressure's Flamant line loads.
    #[test]
    fn the_excess_pressure_is_the_sum_of_the_contact_pressures_line_loads() {
        let (force, b) = (3.0e4, 0.5);
        for (x, z) in [(0.0, 0.5), (0.2, 0.3), (0.45, 1.0), (0.8, 0.2), (0.0, 2.0)] {
            // s = b sin θ takes the contact pressure's root singularities out: p ds = P/π dθ.
            let n = 20_000;
            let sum: f64 = (0..n)
                .map(|i| {
                    let theta = -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * (i as f64 + 0.5) / n as f64;
                    let s = b * theta.sin();
                    // Flamant: σ_xx + σ_yy = −(2 F/π) z/r² for a line load F at the surface.
                    let trace = -2.0 / std::f64::consts::PI * z / ((x - s).powi(2) + z * z);
                    trace * force / std::f64::consts::PI * std::f64::consts::PI / n as f64
                })
                .sum();
            let exact = excess_pressure(force, b, x, z);
            assert!((exact + sum / 2.0).abs() < 1e-6 * exact.abs(), "({x}, {z}): {exact} against {}", -sum / 2.0);
        }
        // On the centre line P/(π √(b² + z²)).
        let z: f64 = 0.7;
        let centre = force / (std::f64::consts::PI * (b * b + z * z).sqrt());
        assert!((excess_pressure(force, b, 0.0, z) - centre).abs() < 1e-12 * centre);
    }
}
