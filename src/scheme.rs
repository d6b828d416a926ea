//! How a stage treats time ([`Integration`]) and its form for one step of length Δt
//! ([`Scheme`]): the weights and Newmark factors with which the kernels' terms enter a step.

/// How a stage treats time ([`Scheme`] is its form for one step of length Δt).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Integration {
    /// Dynamics with the generalized-α method of Chung & Hulbert (1993): inertia at
    /// t_{n+1−α_m}, every other force of the momentum balances at t_{n+1−α_f}, with the Newmark
    /// updates of parameters β and γ. Newmark is α_m = α_f = 0.
    Dynamic {
        /// Newmark β.
        beta: f64,
        /// Newmark γ.
        gamma: f64,
        /// α_m.
        alpha_m: f64,
        /// α_f.
        alpha_f: f64,
    },
    /// No inertia; the water's mass balance with Darcy's law, its flux at t_{n+θ} (θ-method;
    /// θ = 1 is backward Euler).
    QuasiStatic {
        /// θ ∈ [1/2, 1].
        theta: f64,
    },
    /// No inertia, no flow (drained with the pore pressure held, total stress, or undrained).
    Static,
    /// Explicit dynamics, update-stress-last ([002] §2.2, Eqs. 7–17): the nodal velocities follow
    /// from the lumped mass and the forces of the step's start (`assembly::explicit`); the
    /// kernels see the step as a static one (no inertia terms: the step's out-of-balance force is
    /// the inertia).
    Explicit {
        /// FLIP share η of the particle velocity update ([002] Eq. 13).
        flip: f64,
        /// Local damping α (Al-Kafaji 2013).
        damping: f64,
        /// The order m of the XPIC transfer (Hammerquist & Nairn 2017) that replaces the FLIP/PIC
        /// blend; 0 for the blend.
        xpic: u8,
        /// A two-phase stage's pore pressure held point by point (the "v–w" form) rather than by
        /// the lumped nodal continuity equation (`assembly::explicit`).
        pointwise_pressure: bool,
    },
}

impl Integration {
    /// Whether a step starts from the last increment scaled to its Δt (a constant-rate predictor,
    /// as static and consolidation codes do) rather than from Δd = 0. Without inertia the path is
    /// smooth in the load, and the extrapolated increment leaves only the change of the rate to
    /// Newton: an elastic load step then converges in one iteration instead of two. The dynamic
    /// schemes start from Δd = 0, which is their own (Newmark) predictor of the motion.
    pub fn extrapolates(&self) -> bool {
        !matches!(self, Integration::Dynamic { .. } | Integration::Explicit { .. })
    }

    /// Whether the step is explicit (no equations are solved).
    pub fn is_explicit(&self) -> bool {
        matches!(self, Integration::Explicit { .. })
    }

    /// Newmark's method with β and γ.
    pub fn newmark(beta: f64, gamma: f64) -> Integration {
        Integration::Dynamic { beta, gamma, alpha_m: 0.0, alpha_f: 0.0 }
    }

    /// The generalized-α method with the spectral radius ρ∞ ∈ [0, 1] at infinite frequency
    /// (Chung & Hulbert 1993, Eqs. 25 and 17): α_m = (2ρ∞ − 1)/(ρ∞ + 1), α_f = ρ∞/(ρ∞ + 1),
    /// γ = 1/2 − α_m + α_f, β = (1 − α_m + α_f)²/4; second-order accurate, unconditionally stable,
    /// with the least low-frequency damping for the high-frequency damping ρ∞ asks for.
    pub fn generalized_alpha(rho_inf: f64) -> Integration {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 - alpha_m + alpha_f;
        Integration::Dynamic { beta: 0.25 * (1.0 - alpha_m + alpha_f).powi(2), gamma, alpha_m, alpha_f }
    }
}

/// One step of length Δt under an [`Integration`]: the factors a₀ = ∂a/∂Δd = 1/(βΔt²) and
/// a₁ = ∂v/∂Δd = γ/(βΔt) (zero without inertia), and the weights of the terms at t_{n+1}.
#[derive(Debug, Clone, Copy)]
pub struct Scheme {
    /// ∂a_{n+1}/∂Δd.
    pub a0: f64,
    /// ∂v_{n+1}/∂Δd.
    pub a1: f64,
    /// Weight of the inertia terms m a_{n+1}: 1 − α_m.
    pub w_inertia: f64,
    /// Weight of the other momentum terms at t_{n+1} (stress, pressure, drag, body force,
    /// external loads): 1 − α_f.
    pub w_force: f64,
    /// Weight of the mass balance of the water (continuity and Darcy flux): 1 (0 in the
    /// generalized-α history, which has none).
    pub w_mass: f64,
    /// Δt of the Darcy flux in the continuity rows (u–p), 0 where the water's motion is an unknown
    /// or there is no flow.
    pub flow_dt: f64,
    /// θ of the Darcy flux.
    pub theta: f64,
    beta: f64,
    gamma: f64,
    dt: f64,
    /// An explicit step: its "predictors" are the velocity and acceleration of the step's start
    /// interpolated from the nodes (what the FLIP update needs); no term of the residual uses them.
    explicit: bool,
}

impl Scheme {
    /// The step's Δt [s].
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Whether the step is explicit (its forces are those of its start).
    pub fn is_explicit(&self) -> bool {
        self.explicit
    }

    /// Newmark factors for step `dt`.
    pub fn newmark(beta: f64, gamma: f64, dt: f64) -> Scheme {
        Scheme::of(&Integration::newmark(beta, gamma), dt, false)
    }

    /// The scheme of `integration` for a step `dt`; `flow` says whether the layout carries Darcy's
    /// flux (u–p: a pressure and no water motion).
    pub fn of(integration: &Integration, dt: f64, flow: bool) -> Scheme {
        let mut s = Scheme {
            a0: 0.0,
            a1: 0.0,
            w_inertia: 0.0,
            w_force: 1.0,
            w_mass: 1.0,
            flow_dt: 0.0,
            theta: 1.0,
            beta: 0.25,
            gamma: 0.5,
            dt,
            explicit: integration.is_explicit(),
        };
        match *integration {
            Integration::Dynamic { beta, gamma, alpha_m, alpha_f } => {
                s.a0 = 1.0 / (beta * dt * dt);
                s.a1 = gamma / (beta * dt);
                s.w_inertia = 1.0 - alpha_m;
                s.w_force = 1.0 - alpha_f;
                (s.beta, s.gamma) = (beta, gamma);
                if flow {
                    s.flow_dt = dt;
                }
            }
            Integration::QuasiStatic { theta } => {
                s.theta = theta;
                if flow {
                    s.flow_dt = dt;
                }
            }
            Integration::Static | Integration::Explicit { .. } => {}
        }
        s
    }

    /// The weights of the generalized-α history: α_m on the inertia at t_n, α_f on the forces at
    /// t_n, nothing on the mass balance; `None` for a scheme without one (Newmark, static).
    pub fn history(&self) -> Option<Scheme> {
        let (am, af) = (1.0 - self.w_inertia, 1.0 - self.w_force);
        if self.a0 == 0.0 || (am == 0.0 && af == 0.0) {
            return None;
        }
        Some(Scheme { a0: 0.0, a1: 0.0, w_inertia: am, w_force: af, w_mass: 0.0, flow_dt: 0.0, ..*self })
    }

    /// The momentum balance of the step's start, unweighted (w_m = w_f = 1, no mass balance, no
    /// dependence on Δd): with the velocities and accelerations of t_n in place of the predictors,
    /// its residual M a_n + f_int,n − f_n is what the start is out of balance by.
    pub fn start_balance(&self) -> Scheme {
        Scheme { a0: 0.0, a1: 0.0, w_inertia: 1.0, w_force: 1.0, w_mass: 0.0, flow_dt: 0.0, ..*self }
    }

    /// The same scheme with the terms at t_{n+1} unweighted (w_m = w_f = 1): the balance at t_{n+1}
    /// for the equilibrium identity.
    pub fn unweighted(&self) -> Scheme {
        // An explicit step has no inertia terms (its inertia is the lumped nodal update's).
        Scheme { w_inertia: if self.explicit { 0.0 } else { 1.0 }, w_force: 1.0, ..*self }
    }

    /// Predictors (ã_n, ṽ_n) of a point with velocity `v` and acceleration `a` at t_n ([003] Eq. 21
    /// at Δd = 0); zero without inertia.
    pub fn predict<const D: usize>(&self, v: [f64; D], a: [f64; D]) -> ([f64; D], [f64; D]) {
        if self.explicit {
            return (a, v);
        }
        if self.a0 == 0.0 {
            return ([0.0; D], [0.0; D]);
        }
        let (b, g, dt) = (self.beta, self.gamma, self.dt);
        let pa = |c: usize| -v[c] / (b * dt) - (0.5 / b - 1.0) * a[c];
        let pv = |c: usize| -(g / b - 1.0) * v[c] - (0.5 * g / b - 1.0) * dt * a[c];
        let (mut oa, mut ov) = ([0.0; D], [0.0; D]);
        for c in 0..D {
            (oa[c], ov[c]) = (pa(c), pv(c));
        }
        (oa, ov)
    }
}
