//! Large-strain one-dimensional consolidation of a homogeneous layer (Xie & Leo 2004, after Gibson's
//! finite-strain theory; the reference of [003] §4.2).
//!
//! A layer of initial height H₀, drained at the top and impermeable at the base, is loaded at t = 0 by
//! a constant surface pressure q. In the Lagrangian (initial) depth a and the volume ratio
//! λ = (1 + e)/(1 + e₀) = V/V₀, continuity of the pore water reads
//!   ∂λ/∂t = ∂/∂a [ (k/γ_w) (1/λ) ∂u/∂a ].
//! Xie & Leo assume incompressible constituents, a constant coefficient of volume compressibility
//! m_v = −(1/(1+e)) de/dσ', i.e. ln λ = −m_v σ' with σ' = q − u, and a conductivity k = k₀ λ². Then
//! λ ∂u/∂a = (1/m_v) ∂λ/∂a and the equation becomes linear in λ:
//!   ∂λ/∂t = c_v ∂²λ/∂a²,   c_v = k₀/(γ_w m_v),
//! with λ = 1 at t = 0 (undrained: u = q), λ = λ_∞ = e^{−m_v q} at the drained top and ∂λ/∂a = 0 at the
//! base. Hence, with P(a/H₀, T_v) the normalised Terzaghi series and U(T_v) its degree of consolidation,
//!   λ = λ_∞ + (1 − λ_∞) P,   u = (1/m_v) ln[1 + (e^{m_v q} − 1) P],   S = H₀ (1 − e^{−m_v q}) U.
//! For m_v q → 0 these reduce to Terzaghi's u = q P and S = m_v q H₀ U.
//!
//! An updated-Lagrangian elastic skeleton that adds E_c Δε with Δε the increment of strain on the
//! current configuration accumulates σ' = −E_c ln λ (compression positive): it is this law with
//! m_v = 1/E_c.

use super::terzaghi::Terzaghi;

/// Parameters of the large-strain consolidation problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct XieLeo {
    /// Surface load q [Pa] (compression positive), applied as a step at t = 0.
    pub load: f64,
    /// Initial height H₀ [m].
    pub height: f64,
    /// Coefficient of volume compressibility m_v [1/Pa].
    pub m_v: f64,
    /// Hydraulic conductivity at the initial void ratio k₀ [m/s].
    pub conductivity: f64,
    /// Unit weight of water γ_w [N/m³].
    pub water_unit_weight: f64,
}

impl XieLeo {
    /// The normalised Terzaghi problem with the same c_v (unit load, incompressible constituents).
    fn linear(&self) -> Terzaghi {
        Terzaghi::new(1.0, self.height, 1.0 / self.m_v, 0.0, self.conductivity, self.water_unit_weight)
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.load.is_finite() && self.load > 0.0 && self.m_v.is_finite() && self.m_v > 0.0) {
            return Err(format!("load and m_v must be positive, got {} and {}", self.load, self.m_v));
        }
        self.linear().validate()
    }

    /// c_v = k₀/(γ_w m_v) [m²/s].
    pub fn cv(&self) -> f64 {
        self.linear().cv()
    }

    /// Final volume ratio λ_∞ = e^{−m_v q}.
    pub fn final_volume_ratio(&self) -> f64 {
        (-self.m_v * self.load).exp()
    }

    /// Volume ratio λ(a, t) at initial depth `depth` below the drained top.
    pub fn volume_ratio(&self, depth: f64, t: f64) -> f64 {
        let l = self.final_volume_ratio();
        l + (1.0 - l) * self.linear().pressure(depth, t)
    }

    /// Excess pore pressure u(a, t) [Pa] at initial depth `depth` [m] below the drained top.
    pub fn pressure(&self, depth: f64, t: f64) -> f64 {
        let p = self.linear().pressure(depth, t);
        (1.0 + (self.m_v * self.load).exp_m1() * p).ln() / self.m_v
    }

    /// Degree of consolidation U_s = S/S_∞ (Terzaghi's U(T_v)).
    pub fn degree_of_consolidation(&self, t: f64) -> f64 {
        self.linear().degree_of_consolidation(t)
    }

    /// Settlement S(t) = H₀ (1 − e^{−m_v q}) U(T_v) [m].
    pub fn settlement(&self, t: f64) -> f64 {
        self.height * (1.0 - self.final_volume_ratio()) * self.degree_of_consolidation(t)
    }

    /// The time [s] at which the degree of consolidation reaches `u` (0 < u < 1), by bisection.
    pub fn time_for_degree(&self, u: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, self.linear().time_for(1.0));
        while self.degree_of_consolidation(hi) < u {
            hi *= 2.0;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if self.degree_of_consolidation(mid) < u {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn column(q: f64) -> XieLeo {
        XieLeo { load: q, height: 1.0, m_v: 1e-6, conductivity: 1e-2, water_unit_weight: 9810.0 }
    }

    #[test]
    fn small_loads_give_terzaghi() {
        let x = column(1.0);
        let t = x.time_for_degree(0.5);
        let terz = Terzaghi::new(1.0, 1.0, 1e6, 0.0, 1e-2, 9810.0);
        for d in [0.1, 0.5, 0.9] {
            assert!((x.pressure(d, t) - terz.pressure(d, t)).abs() < 1e-6, "depth {d}");
        }
        assert!((x.settlement(t) - 1e-6 * 0.5).abs() < 1e-12);
    }

    #[test]
    fn boundary_initial_and_final_states() {
        let x = column(2e5);
        assert!(x.pressure(0.0, 0.3).abs() < 1e-9);
        // Shortly after loading (T_v = 1e-3) the pore water at mid-depth still carries the whole load.
        assert!((x.pressure(0.5, 1e-3 / x.cv()) - 2e5).abs() < 1e-6 * 2e5);
        // Degree 0.5 is reached when Terzaghi's T_v = 0.19671.
        let t = x.time_for_degree(0.5);
        assert!((x.degree_of_consolidation(t) - 0.5).abs() < 1e-10);
        assert!((x.cv() * t - 0.19671).abs() < 1e-4, "T_v = {}", x.cv() * t);
        // Final settlement H (1 − e^{−m_v q}) = 0.181 m: a large strain.
        assert!((x.settlement(1e6) - (1.0 - (-0.2f64).exp())).abs() < 1e-9);
    }

    #[test]
    fn settlement_is_the_integral_of_the_volume_change() {
        let x = column(2e5);
        let t = x.time_for_degree(0.3);
        let n = 4000;
        let integral: f64 = (0..n)
            .map(|i| {
                let a = (i as f64 + 0.5) / n as f64;
                (1.0 - x.volume_ratio(a, t)) / n as f64
            })
            .sum();
        assert!((integral - x.settlement(t)).abs() < 1e-6 * x.settlement(t), "{integral} vs {}", x.settlement(t));
    }

    /// The pressure satisfies Gibson's equation m_v λ ∂u/∂t = ∂/∂a [(k₀/γ_w) λ ∂u/∂a] (with k = k₀λ²
    /// and ∂λ/∂t = m_v λ ∂u/∂t), checked by central differences at interior points.
    #[test]
    fn the_pressure_satisfies_the_nonlinear_consolidation_equation() {
        let x = column(2e5);
        let t = x.time_for_degree(0.4);
        let (da, dt) = (1e-3, 1e-5 * t);
        let c = x.conductivity / x.water_unit_weight;
        for a in [0.2, 0.5, 0.8] {
            let lam = |a: f64| x.volume_ratio(a, t);
            let u = |a: f64, t: f64| x.pressure(a, t);
            let dudt = (u(a, t + dt) - u(a, t - dt)) / (2.0 * dt);
            let flux = |a: f64| c * lam(a) * (u(a + da / 2.0, t) - u(a - da / 2.0, t)) / da;
            let rhs = (flux(a + da / 2.0) - flux(a - da / 2.0)) / da;
            let lhs = x.m_v * lam(a) * dudt;
            assert!((lhs - rhs).abs() < 1e-4 * lhs.abs(), "a = {a}: {lhs} vs {rhs}");
        }
    }
}
