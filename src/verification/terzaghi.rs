//! One-dimensional consolidation of a saturated layer with a compressible pore fluid ([003] §4.1.1, Eqs. 31–32).
//!
//! A layer of height `H` is drained at the top (pore pressure `p = 0` at depth `z = 0`) and impermeable and fixed at
//! the bottom (`z = H`). At `t = 0` a constant compressive surface load `q` is applied. The load is first carried
//! partly by the pore fluid (the undrained pressure `p0`) and partly by the skeleton, and the excess pore pressure then
//! dissipates through the drained top according to the classical Terzaghi series.
//!
//! All quantities are in SI units. Pore pressure is positive in compression; settlement is positive downward; depth
//! `z` is measured downward from the drained top surface.

use std::f64::consts::PI;

/// The default number of series terms used by [`Terzaghi::new`].
pub const DEFAULT_TERMS: usize = 200;

/// Parameters of the one-dimensional consolidation problem ([003] Eqs. 31–32).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Terzaghi {
    /// The compressive surface load `q` [Pa], applied as a step at `t = 0`.
    pub load: f64,
    /// The layer height `H` [m].
    pub height: f64,
    /// The constrained (oedometric) modulus of the skeleton `E_c` [Pa].
    pub constrained_modulus: f64,
    /// The storage compressibility `1/Q = n/K_w + (1 − n)/K_s` [1/Pa]; zero for incompressible constituents.
    pub inv_q: f64,
    /// The hydraulic conductivity `k` [m/s].
    pub conductivity: f64,
    /// The unit weight of water `γ_w = ρ_w g` [N/m³].
    pub water_unit_weight: f64,
    /// The number of series terms (at least one term is always used).
    pub terms: usize,
}

impl Terzaghi {
    /// Creates a problem description that uses [`DEFAULT_TERMS`] series terms.
    pub fn new(
        load: f64,
        height: f64,
        constrained_modulus: f64,
        inv_q: f64,
        conductivity: f64,
        water_unit_weight: f64,
    ) -> Self {
        Self { load, height, constrained_modulus, inv_q, conductivity, water_unit_weight, terms: DEFAULT_TERMS }
    }

    /// Checks that all parameters are finite and physically admissible, and returns a description of the first
    /// violation otherwise.
    pub fn validate(&self) -> Result<(), String> {
        super::finite_parameter("load", self.load)?;
        super::positive_finite(&[
            ("height", self.height),
            ("constrained_modulus", self.constrained_modulus),
            ("conductivity", self.conductivity),
            ("water_unit_weight", self.water_unit_weight),
        ])?;
        if !(self.inv_q.is_finite() && self.inv_q >= 0.0) {
            return Err(format!("inv_q must be non-negative and finite, got {}", self.inv_q));
        }
        Ok(())
    }

    /// Returns the coefficient of consolidation `c_v = k / (γ_w (1/E_c + 1/Q))` [m²/s].
    pub fn cv(&self) -> f64 {
        self.conductivity / (self.water_unit_weight * (1.0 / self.constrained_modulus + self.inv_q))
    }

    /// Returns the initial (undrained) pore pressure `p0 = q (1/E_c) / (1/E_c + 1/Q)` [Pa], which equals `q` for an
    /// incompressible fluid.
    pub fn initial_pressure(&self) -> f64 {
        let inv_ec = 1.0 / self.constrained_modulus;
        self.load * inv_ec / (inv_ec + self.inv_q)
    }

    /// Returns the dimensionless time factor `T_v = c_v t / H²` for the time `t` [s].
    pub fn time_factor(&self, t: f64) -> f64 {
        self.cv() * t / (self.height * self.height)
    }

    /// Returns the time `t = T_v H² / c_v` [s] at which the time factor equals `tv`.
    pub fn time_for(&self, tv: f64) -> f64 {
        tv * self.height * self.height / self.cv()
    }

    /// Returns the excess pore pressure `p(z, t)` [Pa] at `depth` `z` [m] below the drained top and time `t` [s].
    ///
    /// This evaluates the series `p = p0 Σ (2/M) sin(M z/H) exp(−M² T_v)` with `M = (m − 1/2)π`, `m = 1..terms`
    /// ([003] Eqs. 31–32). The depth is clamped to `[0, H]`. Times `t ≤ 0` return the undrained state just after
    /// loading, that is `p0` everywhere except at the drained surface, where the pressure is zero.
    pub fn pressure(&self, depth: f64, t: f64) -> f64 {
        let z = depth.clamp(0.0, self.height);
        let tv = self.time_factor(t);
        if tv <= 0.0 {
            return if z > 0.0 { self.initial_pressure() } else { 0.0 };
        }
        let zeta = z / self.height;
        let mut sum = 0.0;
        for m in 1..=self.terms.max(1) {
            let big_m = (m as f64 - 0.5) * PI;
            let decay = big_m * big_m * tv;
            if decay > 745.0 {
                break;
            }
            sum += 2.0 / big_m * (big_m * zeta).sin() * (-decay).exp();
        }
        self.initial_pressure() * sum
    }

    /// Returns the average degree of consolidation `U(t) = 1 − Σ (2/M²) exp(−M² T_v)` ([003] Eqs. 31–32).
    ///
    /// The sum over `m = 1..terms` is complemented by an integral estimate of the truncated tail
    /// `Σ_{m > terms} (2/M²) exp(−M² T_v)`, so that `U(0) = 0` holds to about `1/(6π² terms³)` instead of the plain
    /// truncation error `2/(π² terms)`. For `T_v ≳ 10/terms²` the correction is zero to machine precision. Times
    /// `t ≤ 0` return zero.
    pub fn degree_of_consolidation(&self, t: f64) -> f64 {
        let tv = self.time_factor(t);
        if tv <= 0.0 {
            return 0.0;
        }
        let terms = self.terms.max(1);
        let mut sum = 0.0;
        for m in 1..=terms {
            let big_m = (m as f64 - 0.5) * PI;
            let decay = big_m * big_m * tv;
            if decay > 745.0 {
                break;
            }
            sum += 2.0 / (big_m * big_m) * (-decay).exp();
        }
        1.0 - sum - series_tail(terms, tv)
    }

    /// Returns the surface settlement `s(t) = s_u + (s_∞ − s_u) U(t)` [m], positive downward, with the final
    /// settlement `s_∞ = q H / E_c` and the undrained settlement `s_u = (q − p0) H / E_c` ([003] Eqs. 31–32).
    pub fn settlement(&self, t: f64) -> f64 {
        let s_final = self.load * self.height / self.constrained_modulus;
        let s_undrained = (self.load - self.initial_pressure()) * self.height / self.constrained_modulus;
        s_undrained + (s_final - s_undrained) * self.degree_of_consolidation(t)
    }
}

/// Returns an estimate of `Σ_{m > n} (2/M²) exp(−M² T_v)` with `M = (m − 1/2)π`.
///
/// Each summand is replaced by its integral over the cell `M ∈ [(m − 1)π, mπ]` (the midpoint rule read backwards),
/// which gives `(2/π) ∫_{nπ}^∞ exp(−M² T_v)/M² dM = (2/(π a)) e^{−x²} (1 − √π x erfcx(x))` with `a = nπ` and
/// `x = a √T_v`.
fn series_tail(n: usize, tv: f64) -> f64 {
    let a = n as f64 * PI;
    let x = a * tv.max(0.0).sqrt();
    if x > 27.0 {
        return 0.0;
    }
    2.0 / (PI * a) * (-x * x).exp() * (1.0 - PI.sqrt() * x * erfcx(x))
}

/// Returns the scaled complementary error function `erfcx(x) = exp(x²) erfc(x)` for `x ≥ 0`.
///
/// A Maclaurin series for `erf` is used below `x = 2.5` and the Laplace continued fraction above, giving an absolute
/// error below about `1e-11` on the whole range.
fn erfcx(x: f64) -> f64 {
    let x = x.max(0.0);
    if x < 2.5 {
        let x2 = x * x;
        let mut term = x;
        let mut sum = x;
        let mut n = 0.0;
        loop {
            n += 1.0;
            term *= -x2 / n;
            let contribution = term / (2.0 * n + 1.0);
            sum += contribution;
            if contribution.abs() <= 1e-17 * sum.abs() || n > 200.0 {
                break;
            }
        }
        let erf = 2.0 / PI.sqrt() * sum;
        x2.exp() * (1.0 - erf)
    } else {
        let mut f = x;
        for k in (1..=60).rev() {
            f = x + 0.5 * k as f64 / f;
        }
        1.0 / (PI.sqrt() * f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A soft clay layer with a compressible pore fluid (n = 0.3, K_w = 2.2 GPa, K_s = ∞).
    fn layer() -> Terzaghi {
        Terzaghi::new(1.0e4, 5.0, 1.0e7, 0.3 / 2.2e9, 1.0e-7, 9810.0)
    }

    fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, intervals: usize) -> f64 {
        let n = intervals + intervals % 2;
        let h = (b - a) / n as f64;
        let mut sum = f(a) + f(b);
        for i in 1..n {
            let weight = if i % 2 == 1 { 4.0 } else { 2.0 };
            sum += weight * f(a + i as f64 * h);
        }
        sum * h / 3.0
    }

    #[test]
    fn parameters_are_validated() {
        assert!(layer().validate().is_ok());
        let mut bad = layer();
        bad.conductivity = 0.0;
        assert!(bad.validate().is_err());
        let mut bad = layer();
        bad.inv_q = -1.0;
        assert!(bad.validate().is_err());
    }

    #[test]
    fn initial_pressure_and_time_factor() {
        let t = layer();
        let inv_ec = 1.0e-7;
        let inv_q = 0.3 / 2.2e9;
        assert!((t.initial_pressure() - 1.0e4 * inv_ec / (inv_ec + inv_q)).abs() < 1e-9);
        assert!(t.initial_pressure() < t.load);
        let mut incompressible = t;
        incompressible.inv_q = 0.0;
        assert_eq!(incompressible.initial_pressure(), incompressible.load);
        let cv = 1.0e-7 / (9810.0 * (inv_ec + inv_q));
        assert!((t.cv() - cv).abs() < 1e-12 * cv);
        assert!((t.time_factor(t.time_for(0.37)) - 0.37).abs() < 1e-14);
    }

    #[test]
    fn pressure_vanishes_at_drained_top() {
        let t = layer();
        for tv in [1e-4, 1e-2, 0.2, 1.0] {
            assert_eq!(t.pressure(0.0, t.time_for(tv)), 0.0);
        }
        // The bottom is not drained, so the pressure there is far from zero at early times.
        assert!(t.pressure(t.height, t.time_for(1e-2)) > 0.99 * t.initial_pressure());
    }

    #[test]
    fn pressure_is_undrained_at_early_time() {
        let t = layer();
        let p0 = t.initial_pressure();
        let p = t.pressure(0.5 * t.height, t.time_for(1e-3));
        assert!((p - p0).abs() < 1e-3 * p0, "p = {p}, p0 = {p0}");
    }

    #[test]
    fn degree_of_consolidation_limits() {
        let t = layer();
        assert_eq!(t.degree_of_consolidation(0.0), 0.0);
        for tv in [1e-14, 1e-12, 1e-10] {
            // U vanishes like 2√(T_v/π); a plainly truncated series would stay near 2/(π² terms) ≈ 1e-3 instead.
            let u = t.degree_of_consolidation(t.time_for(tv));
            assert!(u > 0.0 && u < 1.01 * 2.0 * (tv / PI).sqrt(), "U({tv}) = {u}");
        }
        let u3 = t.degree_of_consolidation(t.time_for(3.0));
        assert!((1.0 - u3).abs() < 1e-3, "U(3) = {u3}");
        // At T_v = 3 only the first term survives.
        let first_term = 8.0 / (PI * PI) * (-PI * PI / 4.0 * 3.0).exp();
        assert!((1.0 - u3 - first_term).abs() < 1e-12);
    }

    #[test]
    fn degree_of_consolidation_matches_short_time_formula() {
        let t = layer();
        let mut worst: f64 = 0.0;
        let mut worst_early: f64 = 0.0;
        for i in 0..=200 {
            // Logarithmically spaced from 1e-10 to 0.15.
            let tv = 1e-10 * (0.15f64 / 1e-10).powf(i as f64 / 200.0);
            let u = t.degree_of_consolidation(t.time_for(tv));
            let short = 2.0 * (tv / PI).sqrt();
            worst = worst.max((u - short).abs());
            if tv <= 0.05 {
                worst_early = worst_early.max((u - short).abs());
            }
        }
        println!("worst deviation from 2√(T_v/π) for T_v ≤ 0.15: {worst:e}");
        println!("worst deviation for T_v ≤ 0.05: {worst_early:e}");
        assert!(worst < 1e-4, "worst deviation {worst}");
        // Below T_v = 0.05 the short-time formula itself is exact to about 3e-11, so this bounds the series error.
        assert!(worst_early < 1e-8, "worst deviation for T_v <= 0.05: {worst_early}");
    }

    #[test]
    fn degree_of_consolidation_matches_pressure_integral() {
        let t = layer();
        let p0 = t.initial_pressure();
        for tv in [0.1, 0.5] {
            let time = t.time_for(tv);
            let integral = simpson(|z| t.pressure(z, time), 0.0, t.height, 2000);
            let u_quadrature = 1.0 - integral / (p0 * t.height);
            let u = t.degree_of_consolidation(time);
            assert!((u - u_quadrature).abs() < 1e-6, "T_v = {tv}: U = {u}, quadrature {u_quadrature}");
        }
    }

    #[test]
    fn settlement_matches_effective_stress_integral() {
        let t = layer();
        assert!((t.settlement(0.0) - (t.load - t.initial_pressure()) * t.height / t.constrained_modulus).abs() < 1e-15);
        let s_final = t.load * t.height / t.constrained_modulus;
        assert!((t.settlement(t.time_for(50.0)) - s_final).abs() < 1e-12 * s_final);
        for tv in [0.05, 0.3] {
            let time = t.time_for(tv);
            // The vertical effective stress is q − p, so the strain is (q − p)/E_c.
            let s = simpson(|z| (t.load - t.pressure(z, time)) / t.constrained_modulus, 0.0, t.height, 2000);
            assert!((t.settlement(time) - s).abs() < 1e-6 * s_final);
        }
    }

    #[test]
    fn series_satisfies_diffusion_equation() {
        let t = layer();
        let cv = t.cv();
        let time = t.time_for(0.2);
        let dt = t.time_for(1e-5);
        let dz = 1e-3 * t.height;
        for zeta in [0.1, 0.3, 0.5, 0.7, 0.9] {
            let z = zeta * t.height;
            let p_t = (t.pressure(z, time + dt) - t.pressure(z, time - dt)) / (2.0 * dt);
            let p_zz = (t.pressure(z + dz, time) - 2.0 * t.pressure(z, time) + t.pressure(z - dz, time)) / (dz * dz);
            let residual = (p_t - cv * p_zz).abs() / (p_t.abs() + (cv * p_zz).abs());
            assert!(residual < 1e-4, "z/H = {zeta}: residual {residual}");
        }
    }

    #[test]
    fn known_value_at_base() {
        // At T_v = 0.5 and z/H = 1 the series gives P = p/p0 = 0.37078 (not e^{-1} = 0.3679); the one-term
        // approximation (4/π) exp(−π² T_v/4) is accurate there because the second term is about 6e-6.
        let t = layer();
        let p = t.pressure(t.height, t.time_for(0.5)) / t.initial_pressure();
        let one_term = 4.0 / PI * (-PI * PI * 0.5 / 4.0).exp();
        assert!((p - one_term).abs() < 1e-3, "P = {p}, one-term {one_term}");
        assert!((p - 0.37078).abs() < 1e-5, "P = {p}");
    }

    #[test]
    fn scaled_complementary_error_function() {
        // Reference values of erfc: erfc(0.5), erfc(1), erfc(2), erfc(3) and erfc(5).
        let reference = [
            (0.5, 0.479_500_122_186_953_5),
            (1.0, 0.157_299_207_050_285_13),
            (2.0, 0.004_677_734_981_047_266),
            (3.0, 2.209_049_699_858_544e-5),
            (5.0, 1.537_459_794_428_034_8e-12),
        ];
        for (x, erfc) in reference {
            let value = erfcx(x) * (-x * x).exp();
            assert!((value - erfc).abs() < 1e-10 * erfc, "erfc({x}) = {value}, expected {erfc}");
        }
        // Continuity at the switch between the two evaluation methods.
        assert!((erfcx(2.5 - 1e-12) - erfcx(2.5)).abs() < 1e-10);
    }
}
