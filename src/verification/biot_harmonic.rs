//! Steady-state harmonic response of a saturated soil column from the full u–w Biot equations (Zienkiewicz, Chang &
//! Bettess 1980, "Drained, undrained, consolidating and dynamic behaviour assumptions in soils", Géotechnique 30(4);
//! [003] §4.1.2).
//!
//! The column has height `H`; depth `z` runs downward from the loaded, drained surface (`z = 0`) to the fixed,
//! impermeable base (`z = H`). The unknowns are the complex amplitudes of the solid displacement `u(z)` (positive
//! downward) and of the relative Darcy displacement `w(z) = n (U − u)`, with the time factor `e^{iωt}`; a physical
//! quantity is the real part of `amplitude · e^{iωt}`. All quantities are in SI units, stresses are tension positive
//! and the pore pressure is positive in compression.
//!
//! The governing equations are
//!
//! * mixture momentum: `(E_c + Q) u'' + Q w'' + ω² (ρ u + ρ_w w) = 0`,
//! * fluid momentum with Darcy drag: `Q u'' + Q w'' + ω² ρ_w u + (ω² ρ_w / n − i ω γ_w / k) w = 0`,
//!
//! with the effective stress `σ' = E_c u'` and the pore pressure `p = −Q (u' + w')`. The boundary conditions are
//! `σ' − p = −q` and `p = 0` at `z = 0`, and `u = w = 0` at `z = H`.
//!
//! The solution is a sum of four exponential modes. To stay bounded when `|λ| H` is large, each root `λ_j` is used
//! through the basis functions `e^{−λ_j z}` and `e^{λ_j (z − H)}`, both of modulus at most one on `[0, H]`.

use num_complex::Complex64;

/// The parameters of the harmonically loaded saturated column.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BiotColumn {
    /// The column height `H` [m].
    pub height: f64,
    /// The constrained (oedometric) modulus of the skeleton `E_c` [Pa].
    pub constrained_modulus: f64,
    /// The Biot storage modulus `Q` [Pa], equal to `K_w / n` for incompressible grains.
    pub q_modulus: f64,
    /// The porosity `n` [-], uniform over the column.
    pub porosity: f64,
    /// The density of the solid grains `ρ_s` [kg/m³].
    pub solid_density: f64,
    /// The density of the pore water `ρ_w` [kg/m³].
    pub water_density: f64,
    /// The hydraulic conductivity `k` [m/s].
    pub conductivity: f64,
    /// The gravitational acceleration `g` [m/s²], used only in the unit weight `γ_w = ρ_w g`.
    pub gravity: f64,
    /// The angular frequency `ω` [rad/s].
    pub omega: f64,
    /// The amplitude `q` [Pa] of the compressive surface load; the total stress at the surface is `−q e^{iωt}`.
    pub load_amplitude: f64,
}

/// The solved column: the two characteristic roots, their mode shapes and the four mode amplitudes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BiotSolution {
    height: f64,
    constrained_modulus: f64,
    q_modulus: f64,
    /// The roots `λ_j = √s_j` with non-negative real part.
    lambda: [Complex64; 2],
    /// The mode shapes `(u, w)` of each root.
    shape: [[Complex64; 2]; 2],
    /// The amplitudes of the decaying basis functions `e^{−λ_j z}`.
    decaying: [Complex64; 2],
    /// The amplitudes of the basis functions `e^{λ_j (z − H)}`, which decay away from the base.
    growing: [Complex64; 2],
}

impl BiotColumn {
    /// Returns the mixture density `ρ = (1 − n) ρ_s + n ρ_w` [kg/m³].
    pub fn mixture_density(&self) -> f64 {
        (1.0 - self.porosity) * self.solid_density + self.porosity * self.water_density
    }

    /// Checks that all parameters are finite and physically admissible, and returns a description of the first
    /// violation otherwise.
    pub fn validate(&self) -> Result<(), String> {
        super::finite_parameter("load_amplitude", self.load_amplitude)?;
        super::positive_finite(&[
            ("height", self.height),
            ("constrained_modulus", self.constrained_modulus),
            ("q_modulus", self.q_modulus),
            ("solid_density", self.solid_density),
            ("water_density", self.water_density),
            ("conductivity", self.conductivity),
            ("gravity", self.gravity),
            ("omega", self.omega),
        ])?;
        if !(self.porosity > 0.0 && self.porosity < 1.0) {
            return Err(format!("porosity must lie strictly between 0 and 1, got {}", self.porosity));
        }
        Ok(())
    }

    /// Solves the boundary value problem and returns the modal solution.
    ///
    /// The characteristic equation `det(s A + ω² B) = 0` with `s = λ²`, `A = [[E_c + Q, Q], [Q, Q]]` and
    /// `B = [[ρ, ρ_w], [ρ_w, ρ_w/n − i γ_w/(ω k)]]` is a quadratic in `s`. Each root gives two modes,
    /// `e^{−λ z}` and `e^{λ (z − H)}`, sharing a mode shape from the null space of `s A + ω² B`. The four mode
    /// amplitudes follow from the boundary conditions `E_c u'(0) = −q`, `u'(0) + w'(0) = 0`, `u(H) = 0` and
    /// `w(H) = 0`, solved by Gaussian elimination with partial pivoting.
    ///
    /// An error is returned for inadmissible parameters or if the characteristic roots or the boundary system are
    /// degenerate.
    pub fn solve(&self) -> Result<BiotSolution, String> {
        self.validate()?;
        let ec = self.constrained_modulus;
        let q = self.q_modulus;
        let n = self.porosity;
        let rho = self.mixture_density();
        let rho_w = self.water_density;
        let omega = self.omega;
        let gamma_w = rho_w * self.gravity;
        let h = self.height;

        // ω² B, with the Darcy drag in the fluid-fluid entry.
        let w2 = omega * omega;
        let c11 = Complex64::new(w2 * rho, 0.0);
        let c12 = Complex64::new(w2 * rho_w, 0.0);
        let c22 = Complex64::new(w2 * rho_w / n, -omega * gamma_w / self.conductivity);
        let (a11, a12, a22) = (ec + q, q, q);

        // det(s A + C) = s² det A + s (a11 c22 + a22 c11 − 2 a12 c12) + det C, divided by det A = E_c Q.
        let det_a = ec * q;
        let b = (c22 * a11 + c11 * a22 - c12 * (2.0 * a12)) / det_a;
        let c = (c11 * c22 - c12 * c12) / det_a;
        let roots = quadratic_roots(b, c)?;

        let mut lambda = [Complex64::new(0.0, 0.0); 2];
        let mut shape = [[Complex64::new(0.0, 0.0); 2]; 2];
        for j in 0..2 {
            let s = roots[j];
            let l = s.sqrt();
            lambda[j] = if l.re < 0.0 { -l } else { l };
            let m11 = c11 + s * a11;
            let m12 = c12 + s * a12;
            let m21 = m12;
            let m22 = c22 + s * a22;
            let first = [-m12, m11];
            let second = [m22, -m21];
            let norm = |v: &[Complex64; 2]| v[0].norm().max(v[1].norm());
            let v = if norm(&first) >= norm(&second) { first } else { second };
            let scale = norm(&v);
            if !(scale.is_finite() && scale > 0.0) {
                return Err("degenerate mode shape in the characteristic problem".to_string());
            }
            shape[j] = [v[0] / scale, v[1] / scale];
        }

        // Unknowns: [a_1, a_2, b_1, b_2] for a_j e^{−λ_j z} + b_j e^{λ_j (z − H)}.
        let zero = Complex64::new(0.0, 0.0);
        let mut matrix = [[zero; 4]; 4];
        let mut rhs = [zero; 4];
        for j in 0..2 {
            let l = lambda[j];
            let far = (-l * h).exp();
            let [su, sw] = shape[j];
            let sum = su + sw;
            // u'(0) = −q / E_c.
            matrix[0][j] = -su * l;
            matrix[0][j + 2] = su * l * far;
            // u'(0) + w'(0) = 0.
            matrix[1][j] = -sum * l;
            matrix[1][j + 2] = sum * l * far;
            // u(H) = 0.
            matrix[2][j] = su * far;
            matrix[2][j + 2] = su;
            // w(H) = 0.
            matrix[3][j] = sw * far;
            matrix[3][j + 2] = sw;
        }
        rhs[0] = Complex64::new(-self.load_amplitude / ec, 0.0);
        let x = solve_complex(matrix, rhs)?;

        Ok(BiotSolution {
            height: h,
            constrained_modulus: ec,
            q_modulus: q,
            lambda,
            shape,
            decaying: [x[0], x[1]],
            growing: [x[2], x[3]],
        })
    }
}

impl BiotSolution {
    /// Returns the two characteristic roots `λ_j` [1/m] (with non-negative real part) of the modes `e^{±λ_j z}`.
    pub fn characteristic_roots(&self) -> [Complex64; 2] {
        self.lambda
    }

    /// Returns `(u, w, u', w')` at the given depth, clamped to `[0, H]`.
    fn fields(&self, depth: f64) -> [Complex64; 4] {
        let z = depth.clamp(0.0, self.height);
        let mut out = [Complex64::new(0.0, 0.0); 4];
        for j in 0..2 {
            let l = self.lambda[j];
            let e_down = (-l * z).exp();
            let e_up = (l * (z - self.height)).exp();
            let value = self.decaying[j] * e_down + self.growing[j] * e_up;
            let slope = l * (self.growing[j] * e_up - self.decaying[j] * e_down);
            let [su, sw] = self.shape[j];
            out[0] += su * value;
            out[1] += sw * value;
            out[2] += su * slope;
            out[3] += sw * slope;
        }
        out
    }

    /// Returns the complex amplitude of the solid displacement `u` [m] (positive downward) at the given depth [m].
    pub fn solid_displacement(&self, depth: f64) -> Complex64 {
        self.fields(depth)[0]
    }

    /// Returns the complex amplitude of the relative Darcy displacement `w = n (U − u)` [m] at the given depth [m].
    pub fn relative_displacement(&self, depth: f64) -> Complex64 {
        self.fields(depth)[1]
    }

    /// Returns the complex amplitude of the pore pressure `p = −Q (u' + w')` [Pa] (compression positive) at the given
    /// depth [m].
    pub fn pressure(&self, depth: f64) -> Complex64 {
        let f = self.fields(depth);
        -(f[2] + f[3]) * self.q_modulus
    }

    /// Returns the pore-pressure amplitude `|p|` [Pa] at the given depth [m].
    pub fn pressure_amplitude(&self, depth: f64) -> f64 {
        self.pressure(depth).norm()
    }

    /// Returns the complex amplitude of the vertical effective stress `σ' = E_c u'` [Pa] (tension positive) at the
    /// given depth [m].
    pub fn effective_stress(&self, depth: f64) -> Complex64 {
        self.fields(depth)[2] * self.constrained_modulus
    }

    /// Returns the complex amplitude of the vertical total stress `σ = σ' − p` [Pa] (tension positive) at the given
    /// depth [m].
    pub fn total_stress(&self, depth: f64) -> Complex64 {
        self.effective_stress(depth) - self.pressure(depth)
    }
}

/// The saturated mixture of a column as the Zienkiewicz, Chang & Bettess (1980) numbers see it:
/// with `ρ = (1 − n) ρ_s + n ρ_w`, the compression speed `V_c² = (E_c + K_w/n)/ρ` and `β = ρ_w/ρ`,
/// `Π₁ = k V_c² / (g β ω H²)` and `Π₂ = ω² H² / V_c²`.
#[derive(Debug, Clone, Copy)]
pub struct Mixture {
    /// E_c [Pa].
    pub constrained_modulus: f64,
    /// K_w [Pa].
    pub water_bulk_modulus: f64,
    /// n [-].
    pub porosity: f64,
    /// ρ_s [kg/m³].
    pub solid_density: f64,
    /// ρ_w [kg/m³].
    pub water_density: f64,
}

impl Mixture {
    /// `(V_c², β)`.
    fn speed_squared_and_beta(&self) -> (f64, f64) {
        let n = self.porosity;
        let rho = (1.0 - n) * self.solid_density + n * self.water_density;
        ((self.constrained_modulus + self.water_bulk_modulus / n) / rho, self.water_density / rho)
    }

    /// The angular frequency `ω` [rad/s] and the hydraulic conductivity `k` [m/s] of the numbers
    /// `Π₁` and `Π₂` on a column of height `H` under gravity `g`: `ω = √Π₂ V_c / H` and
    /// `k = Π₁ g β ω H² / V_c²`.
    pub fn zienkiewicz_parameters(&self, gravity: f64, height: f64, pi1: f64, pi2: f64) -> (f64, f64) {
        let (vc2, beta) = self.speed_squared_and_beta();
        let omega = pi2.sqrt() * vc2.sqrt() / height;
        (omega, pi1 * gravity * beta * omega * height * height / vc2)
    }

    /// The numbers `(Π₁, Π₂)` of the angular frequency `ω` [rad/s] and the hydraulic conductivity
    /// `k` [m/s]: the inverse of [`Mixture::zienkiewicz_parameters`].
    pub fn zienkiewicz_numbers(&self, gravity: f64, height: f64, omega: f64, conductivity: f64) -> (f64, f64) {
        let (vc2, beta) = self.speed_squared_and_beta();
        let pi1 = conductivity * vc2 / (gravity * beta * omega * height * height);
        (pi1, omega * omega * height * height / vc2)
    }
}

/// Returns the two roots of the monic quadratic `s² + b s + c = 0`, computed without cancellation.
fn quadratic_roots(b: Complex64, c: Complex64) -> Result<[Complex64; 2], String> {
    let root = (b * b - c * 4.0).sqrt();
    // Choose the sign that makes |b ± √disc| as large as possible.
    let sum = if (b.conj() * root).re >= 0.0 { b + root } else { b - root };
    let big = -sum * 0.5;
    if !(big.norm() > 0.0 && big.is_finite() && c.is_finite()) {
        return Err("degenerate characteristic equation".to_string());
    }
    let small = c / big;
    if small.norm().is_nan() || small.norm() <= 0.0 {
        return Err("zero characteristic root (static limit)".to_string());
    }
    Ok([big, small])
}

/// Solves the complex linear system `matrix · x = rhs` by Gaussian elimination with partial pivoting, after scaling
/// every row and column to unit maximum modulus.
fn solve_complex<const N: usize>(
    mut matrix: [[Complex64; N]; N],
    mut rhs: [Complex64; N],
) -> Result<[Complex64; N], String> {
    for (row, value) in matrix.iter_mut().zip(rhs.iter_mut()) {
        let scale = row.iter().fold(0.0f64, |m, a| m.max(a.norm()));
        if !(scale.is_finite() && scale > 0.0) {
            return Err("singular boundary system (zero or non-finite row)".to_string());
        }
        row.iter_mut().for_each(|a| *a /= scale);
        *value /= scale;
    }
    let mut column_scale = [1.0f64; N];
    for (col, cs) in column_scale.iter_mut().enumerate() {
        let scale = matrix.iter().fold(0.0f64, |m, row| m.max(row[col].norm()));
        if !(scale.is_finite() && scale > 0.0) {
            return Err("singular boundary system (zero column)".to_string());
        }
        matrix.iter_mut().for_each(|row| row[col] /= scale);
        *cs = scale;
    }
    for k in 0..N {
        let pivot_row = (k..N).max_by(|&i, &j| matrix[i][k].norm().total_cmp(&matrix[j][k].norm())).unwrap_or(k);
        let pivot = matrix[pivot_row][k];
        if !(pivot.norm() > 1e-300 && pivot.is_finite()) {
            return Err("singular boundary system".to_string());
        }
        matrix.swap(k, pivot_row);
        rhs.swap(k, pivot_row);
        let (upper, lower) = matrix.split_at_mut(k + 1);
        let pivot_values = &upper[k];
        for (offset, row) in lower.iter_mut().enumerate() {
            let factor = row[k] / pivot;
            for (target, source) in row.iter_mut().zip(pivot_values.iter()).skip(k) {
                *target -= factor * source;
            }
            let delta = factor * rhs[k];
            rhs[k + 1 + offset] -= delta;
        }
    }
    let mut x = [Complex64::new(0.0, 0.0); N];
    for k in (0..N).rev() {
        let mut value = rhs[k];
        for j in k + 1..N {
            value -= matrix[k][j] * x[j];
        }
        x[k] = value / matrix[k][k];
    }
    for (value, scale) in x.iter_mut().zip(column_scale) {
        *value /= scale;
    }
    if x.iter().all(|v| v.is_finite()) {
        Ok(x)
    } else {
        Err("non-finite solution of the boundary system".to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const EC: f64 = 1.0e8;
    const KW: f64 = 2.2e9;
    const N: f64 = 0.3;
    const RHO_S: f64 = 2650.0;
    const RHO_W: f64 = 1000.0;
    const SOIL: Mixture = Mixture {
        constrained_modulus: EC,
        water_bulk_modulus: KW,
        porosity: N,
        solid_density: RHO_S,
        water_density: RHO_W,
    };
    const G: f64 = 9.81;
    const H: f64 = 10.0;
    const LOAD: f64 = 1000.0;

    /// The reference soil of the brief with incompressible grains, Q = K_w / n, for given Π₁ and Π₂.
    fn column(pi1: f64, pi2: f64) -> BiotColumn {
        let (omega, conductivity) = SOIL.zienkiewicz_parameters(G, H, pi1, pi2);
        BiotColumn {
            height: H,
            constrained_modulus: EC,
            q_modulus: KW / N,
            porosity: N,
            solid_density: RHO_S,
            water_density: RHO_W,
            conductivity,
            gravity: G,
            omega,
            load_amplitude: LOAD,
        }
    }

    /// The undrained pore pressure p_u = q (1/E_c) / (1/E_c + 1/Q).
    fn undrained_pressure(c: &BiotColumn) -> f64 {
        let inv_ec = 1.0 / c.constrained_modulus;
        c.load_amplitude * inv_ec / (inv_ec + 1.0 / c.q_modulus)
    }

    /// All regimes exercised by the tests, as (Π₁, Π₂).
    const REGIMES: [(f64, f64); 6] = [(1.0, 1.0), (1.0, 1e-7), (1e-6, 1e-4), (10.0, 5.0), (1e-8, 1e-3), (100.0, 0.5)];

    fn check_boundary_conditions(pi1: f64, pi2: f64) {
        let c = column(pi1, pi2);
        let s = c.solve().unwrap_or_else(|e| panic!("Π₁ = {pi1}, Π₂ = {pi2}: {e}"));
        let q = c.load_amplitude;
        let total = s.total_stress(0.0);
        assert!((total + q).norm() < 1e-9 * q, "Π = ({pi1}, {pi2}): σ(0) = {total}");
        assert!(s.pressure(0.0).norm() < 1e-9 * q, "Π = ({pi1}, {pi2}): p(0) = {}", s.pressure(0.0));
        let scale = (0..=100)
            .map(|i| {
                let z = H * i as f64 / 100.0;
                s.solid_displacement(z).norm().max(s.relative_displacement(z).norm())
            })
            .fold(0.0f64, f64::max);
        assert!(scale > 0.0);
        assert!(
            s.solid_displacement(H).norm() < 1e-9 * scale,
            "Π = ({pi1}, {pi2}): u(H) = {}",
            s.solid_displacement(H)
        );
        assert!(
            s.relative_displacement(H).norm() < 1e-9 * scale,
            "Π = ({pi1}, {pi2}): w(H) = {}",
            s.relative_displacement(H)
        );
    }

    /// Returns the largest relative residual of both equations over interior points, from central differences of the
    /// computed displacements. The solution mixes modal lengths that may differ by many orders of magnitude, so at
    /// each point the step is taken from a geometric sequence (from `0.9` times the distance to the nearer end down to
    /// `1e-7` times that) as the one giving the
    /// smallest residual, which balances truncation against rounding error. A wrong solution fails for every step.
    fn ode_residual(pi1: f64, pi2: f64) -> f64 {
        let c = column(pi1, pi2);
        let s = c.solve().unwrap_or_else(|e| panic!("Π₁ = {pi1}, Π₂ = {pi2}: {e}"));
        let ec = c.constrained_modulus;
        let q = c.q_modulus;
        let n = c.porosity;
        let rho = c.mixture_density();
        let rho_w = c.water_density;
        let w2 = c.omega * c.omega;
        let drag = Complex64::new(w2 * rho_w / n, -c.omega * rho_w * c.gravity / c.conductivity);
        let mut worst: f64 = 0.0;
        for i in 1..20 {
            let z = H * i as f64 / 20.0;
            let u = s.solid_displacement(z);
            let w = s.relative_displacement(z);
            let mut best = f64::INFINITY;
            let max_step = 0.9 * z.min(H - z);
            for k in 0..=28 {
                let dz = max_step * 10f64.powf(-(k as f64) / 4.0);
                let second = |f: &dyn Fn(f64) -> Complex64| (f(z + dz) - f(z) * 2.0 + f(z - dz)) / (dz * dz);
                let upp = second(&|x| s.solid_displacement(x));
                let wpp = second(&|x| s.relative_displacement(x));
                let mixture = [upp * (ec + q), wpp * q, u * (w2 * rho), w * (w2 * rho_w)];
                let fluid = [upp * q, wpp * q, u * (w2 * rho_w), w * drag];
                let mut residual: f64 = 0.0;
                for terms in [mixture, fluid] {
                    let sum: Complex64 = terms.iter().sum();
                    let size: f64 = terms.iter().map(|t| t.norm()).sum();
                    residual = residual.max(sum.norm() / size);
                }
                best = best.min(residual);
            }
            worst = worst.max(best);
        }
        worst
    }

    #[test]
    fn zienkiewicz_numbers_round_trip() {
        let (omega, k) = SOIL.zienkiewicz_parameters(G, H, 0.7, 3.0);
        let (pi1, pi2) = SOIL.zienkiewicz_numbers(G, H, omega, k);
        assert!((pi1 - 0.7).abs() < 1e-12 && (pi2 - 3.0).abs() < 1e-12);
        // V_c² = (E_c + K_w/n)/ρ, so Π₂ = 1 means ω H = V_c.
        let rho = (1.0 - N) * RHO_S + N * RHO_W;
        let vc = ((EC + KW / N) / rho).sqrt();
        let (omega, _) = SOIL.zienkiewicz_parameters(G, H, 1.0, 1.0);
        assert!((omega * H - vc).abs() < 1e-9 * vc);
    }

    #[test]
    fn invalid_parameters_are_rejected() {
        let mut c = column(1.0, 1.0);
        c.porosity = 1.0;
        assert!(c.solve().is_err());
        let mut c = column(1.0, 1.0);
        c.omega = 0.0;
        assert!(c.solve().is_err());
        let mut c = column(1.0, 1.0);
        c.conductivity = f64::NAN;
        assert!(c.solve().is_err());
    }

    #[test]
    fn boundary_conditions_hold() {
        for (pi1, pi2) in REGIMES {
            check_boundary_conditions(pi1, pi2);
        }
    }

    #[test]
    fn differential_equations_hold() {
        for (pi1, pi2) in REGIMES.into_iter().chain([(1e-2, 0.1)]) {
            let residual = ode_residual(pi1, pi2);
            assert!(residual < 1e-5, "Π = ({pi1}, {pi2}): residual {residual}");
        }
    }

    #[test]
    fn pressure_matches_finite_difference_of_displacements() {
        for (pi1, pi2) in [(1.0, 1.0), (10.0, 5.0)] {
            let c = column(pi1, pi2);
            let s = c.solve().expect("solve");
            let dz = 1e-5 * H;
            for i in 1..10 {
                let z = H * i as f64 / 10.0;
                let strain = |f: &dyn Fn(f64) -> Complex64| (f(z + dz) - f(z - dz)) / (2.0 * dz);
                let du = strain(&|x| s.solid_displacement(x));
                let dw = strain(&|x| s.relative_displacement(x));
                let p = -(du + dw) * c.q_modulus;
                assert!((p - s.pressure(z)).norm() < 1e-6 * c.load_amplitude, "z = {z}");
                let sigma = du * c.constrained_modulus;
                assert!((sigma - s.effective_stress(z)).norm() < 1e-6 * c.load_amplitude, "z = {z}");
            }
        }
    }

    #[test]
    fn quasi_static_limit_is_harmonic_consolidation() {
        let c = column(1.0, 1e-7);
        let s = c.solve().expect("solve");
        let inv_ec = 1.0 / c.constrained_modulus;
        let inv_q = 1.0 / c.q_modulus;
        let gamma_w = c.water_density * c.gravity;
        let kappa = (Complex64::new(0.0, c.omega * (inv_ec + inv_q) * gamma_w / c.conductivity)).sqrt();
        let p_u = undrained_pressure(&c);
        // |κ| H ≈ 8.7 here, so the profile is far from both the drained and the undrained limit.
        assert!((kappa * H).norm() > 5.0 && (kappa * H).norm() < 15.0);
        let mut worst: f64 = 0.0;
        for i in 0..=50 {
            let z = H * i as f64 / 50.0;
            let reference = p_u * (1.0 - (kappa * (H - z)).cosh() / (kappa * H).cosh());
            worst = worst.max((s.pressure_amplitude(z) - reference.norm()).abs());
            // The phase agrees as well, not only the amplitude.
            assert!((s.pressure(z) - reference).norm() < 1e-3 * c.load_amplitude, "z = {z}");
        }
        assert!(worst < 1e-3 * c.load_amplitude, "worst amplitude error {worst}");
    }

    #[test]
    fn undrained_limit() {
        let c = column(1e-6, 1e-4);
        let s = c.solve().expect("solve");
        let p_u = undrained_pressure(&c);
        // The undrained wave number k_w = ω / V_u gives the dynamic factor cos(k_w (H − z)) / cos(k_w H), which
        // differs from one by at most 5e-5 here because k_w H = √Π₂ = 0.01.
        let kw = c.omega / ((c.constrained_modulus + c.q_modulus) / c.mixture_density()).sqrt();
        assert!((kw * H - 0.01).abs() < 1e-12);
        for i in 0..=40 {
            let z = 0.2 * H + 0.8 * H * i as f64 / 40.0;
            let p = s.pressure_amplitude(z);
            assert!((p - p_u).abs() < 1e-2 * c.load_amplitude, "z = {z}: |p| = {p}, p_u = {p_u}");
            let dynamic = p_u * (kw * (H - z)).cos() / (kw * H).cos();
            assert!((p - dynamic).abs() < 1e-6 * c.load_amplitude, "z = {z}: |p| = {p}, undrained wave {dynamic}");
        }
        // The drained surface keeps a thin boundary layer where the pressure drops to zero.
        assert!(s.pressure_amplitude(0.0) < 1e-9 * c.load_amplitude);
    }

    #[test]
    fn fast_regime() {
        check_boundary_conditions(10.0, 5.0);
        let residual = ode_residual(10.0, 5.0);
        assert!(residual < 1e-5, "residual {residual}");
        // Π₂ = 5 is above the first undrained resonance (√Π₂ = π/2), so the response is strongly dynamic.
        let c = column(10.0, 5.0);
        let s = c.solve().expect("solve");
        let peak = (0..=100).map(|i| s.pressure_amplitude(H * i as f64 / 100.0)).fold(0.0f64, f64::max);
        assert!(peak.is_finite() && peak > 1.5 * undrained_pressure(&c), "peak {peak}");
    }

    #[test]
    fn large_exponents_stay_finite() {
        let c = column(1e-8, 1e-3);
        let s = c.solve().expect("solve");
        let lmax = s.characteristic_roots().iter().fold(0.0f64, |m, l| m.max(l.re));
        assert!(lmax * H > 1e4, "λH = {}", lmax * H);
        let p_u = undrained_pressure(&c);
        let kw = c.omega / ((c.constrained_modulus + c.q_modulus) / c.mixture_density()).sqrt();
        for i in 0..=200 {
            let z = H * i as f64 / 200.0;
            let values = [s.solid_displacement(z), s.relative_displacement(z), s.pressure(z), s.effective_stress(z)];
            assert!(values.iter().all(|v| v.is_finite()), "z = {z}: {values:?}");
            if z > 0.2 * H {
                // Practically undrained: p = p_u cos(k_w (H − z)) / cos(k_w H) with k_w = ω / V_u.
                let reference = p_u * (kw * (H - z)).cos() / (kw * H).cos();
                assert!((s.pressure_amplitude(z) - reference).abs() < 1e-2 * c.load_amplitude, "z = {z}");
            }
        }
    }
}

#[cfg(test)]
mod zone_parameters_for_cases {
    /// Prints ω and k of the three zones for the soil of `cases/harmonic_column_zone*.toml`
    /// (n = 0.4, ρ_s = 2666.7, ρ_w = 1000 kg/m³, K_w = 2 GPa, E_c = K_w/n; H = 10 m; run with
    /// `--nocapture` when editing those files) and checks them against the values in the files.
    #[test]
    fn the_case_files_use_these_zone_parameters() {
        let zones = [
            (1.0, 1e-3, 7.071032, 6.936683e-4),
            (1e-2, 0.5, 158.113092, 1.551089e-4),
            (10.0, 5.0, 499.9975, 0.4904975),
        ];
        for (pi1, pi2, w_case, k_case) in zones {
            let soil = super::Mixture {
                constrained_modulus: 5e9,
                water_bulk_modulus: 2e9,
                porosity: 0.4,
                solid_density: 2666.7,
                water_density: 1000.0,
            };
            let (w, k) = soil.zienkiewicz_parameters(9.81, 10.0, pi1, pi2);
            println!(
                "Π1 = {pi1}, Π2 = {pi2}: ω = {w:.6} rad/s, k = {k:.6e} m/s, period {:.6} s",
                2.0 * std::f64::consts::PI / w
            );
            assert!((w - w_case).abs() < 1e-5 * w && (k - k_case).abs() < 1e-5 * k, "zone ({pi1}, {pi2})");
        }
    }
}
