//! Per-particle kernels: pure functions from one material point and the nodal values of its
//! stencil to a small dense residual block and tangent block. Nothing here knows about PETSc,
//! ranks or global numbering.
//!
//! # The discrete system ([003] Eqs. 10, 16, 22, 23; [000] Eqs. 6–10, Appendix A)
//!
//! Unknowns of a time step are the nodal increments Δd = (Δu, Δp, ΔU) (the grid is reset every step,
//! d_n = 0). Newmark ([003] Eqs. 20–21) gives the acceleration and velocity at t_{n+1} at a material
//! point as
//!   a = a₀ Σ S_i Δd_i + ã_n,  v = a₁ Σ S_i Δd_i + ṽ_n,   a₀ = 1/(βΔt²), a₁ = γ/(βΔt),
//! with predictors ã_n = −v_n/(βΔt) − (1/(2β) − 1) a_n and ṽ_n = −(γ/β − 1) v_n − (γ/(2β) − 1)Δt a_n
//! of the nodal v_n, a_n of [003] Eq. 19, interpolated to the point (the caller passes them as
//! [`Predictors`]: the predictors are linear in v_n and a_n, so interpolating nodal predictors and
//! forming predictors from interpolated values is the same).
//! The residual of a particle at its stencil node i is
//!   R_u,i = S_i [m_s a_u + c (v_u − v_U) − m_s b] + B̄_iᵀ (σ' − (1 − n) m p) V         ([003] 16a,c,d, 23a)
//!   R_U,i = S_i [m_w a_U + c (v_U − v_u) − m_w b] − ∇̄S_i n p V                         ([003] 16b,d,e, 23c)
//!   R_p,i = −S_i [(1 − n) Δε_v^u + n Δε_v^U + Δp/Q] V                                  ([003] 23b)
//! with c = n² γ_w V / k the drag coefficient (k the hydraulic conductivity), m_s = (1 − n)ρ_s V,
//! m_w = n ρ_w V, σ' the effective stress after the soil model's update with Δε = B̄ Δu, and
//! p = p_n + Σ S_j Δp_j. Eq. 23b is written for the step increments (the grid is reset every step, so
//! ε_v and p/Q there are the step's), which makes R_p zero at Δd = 0 and linear in Δd.
//!
//! [003] writes these equations for a uniform porosity. When the porosity varies (large strain,
//! several materials), the exact balances differ from them by three terms, which vanish for uniform
//! n: the water is pushed by −n∇p, not −∇(np), so it gets +p∇n and the skeleton its reaction −p∇n;
//! and the continuity equation ∇·u̇ + ∇·(n(U̇ − u̇)) + ṗ/Q = 0 has ∇n·(U̇ − u̇) besides the divergences:
//!   R_u,i += S_i p ∇n V,   R_U,i −= S_i p ∇n V,   R_p,i −= S_i ∇n·(ΔU − Δu) V,
//! with ∇n the porosity gradient at the particle at t_n (from a nodal projection of the particles'
//! porosities). Without them the settlement of a large-strain consolidation test is off by about
//! its strain (11 % at m_v q = 0.1).
//! The tangent is the exact derivative of this residual: the blocks M, C, K_u, G₁, G₂ of [003] Eq. 16
//! combined as K̄ = a₀M + a₁C + K ([003] Eq. 22), with −G₁, −G₂ off the diagonal and −P (not the +P
//! printed in [003] Eq. 10) in the p–p block. It is symmetric whenever the soil tangent is.
//!
//! # B̄
//! Each node carries the gradient ∇S_i used for the deviatoric part of B and a gradient ∇̄S_i for the
//! volumetric part ([000] Eqs. 12–16). Without B̄ the two are equal and B̄ reduces to B.

use crate::model::shape::Stencil;
use crate::model::soil::{Constitutive, Mat4, StressUpdate};

/// Largest number of stencil nodes of a particle (4 × 4, see [`crate::model::shape::MAX_STENCIL`]).
pub const MAX_NODES: usize = crate::model::shape::MAX_STENCIL;
/// Largest number of dofs per node (u–p–U).
pub const MAX_DOF: usize = 5;
/// Largest local block dimension.
pub const MAX_LOCAL: usize = MAX_NODES * MAX_DOF;

/// Component indices within a node of the two-phase layout.
pub mod dof {
    /// Solid displacement x.
    pub const UX: usize = 0;
    /// Solid displacement y.
    pub const UY: usize = 1;
    /// Pore pressure.
    pub const P: usize = 2;
    /// Water displacement x.
    pub const WX: usize = 3;
    /// Water displacement y.
    pub const WY: usize = 4;
}

/// Basis values of one stencil node for one particle.
#[derive(Debug, Clone, Copy, Default)]
pub struct NodeBasis {
    /// S_i.
    pub s: f64,
    /// ∇S_i (deviatoric part of B̄).
    pub g: [f64; 2],
    /// ∇̄S_i (volumetric part of B̄; equals `g` without B̄).
    pub gv: [f64; 2],
}

/// The basis of a whole stencil without B̄, appended to `out`.
pub fn plain_basis(st: &Stencil, out: &mut Vec<NodeBasis>) {
    out.extend((0..st.len).map(|k| NodeBasis { s: st.w[k], g: st.dw[k], gv: st.dw[k] }));
}

/// Nodal values seen by a particle: the increment Δd and its parts a₀Δd, a₁Δd of the acceleration
/// and velocity at t_{n+1} (the particle adds its predictors).
#[derive(Debug, Clone, Copy, Default)]
pub struct NodeState {
    /// Δd (two-phase: [Δux, Δuy, Δp, ΔUx, ΔUy]; one-phase: [Δux, Δuy, ...]).
    pub d: [f64; MAX_DOF],
    /// a₀ Δd.
    pub a: [f64; MAX_DOF],
    /// a₁ Δd.
    pub v: [f64; MAX_DOF],
}

/// The particle quantities the kernels need.
#[derive(Debug, Clone, Copy)]
pub struct ParticleInput {
    /// Volume V [m³ per m].
    pub volume: f64,
    /// Porosity n.
    pub porosity: f64,
    /// Mass of the u equation (grains, or mixture in one-phase) [kg].
    pub mass: f64,
    /// Water mass n ρ_w V [kg] (two-phase).
    pub water_mass: f64,
    /// Drag coefficient n² γ_w V / k [N s/m] (two-phase).
    pub drag: f64,
    /// 1/Q [1/Pa] (two-phase).
    pub inv_q: f64,
    /// Effective stress at t_n [Pa].
    pub stress: [f64; 4],
    /// Accumulated deviatoric plastic strain ε̄ at t_n (the soil model's internal variable).
    pub eps_pd: f64,
    /// Pore pressure at t_n [Pa].
    pub p: f64,
    /// Body acceleration at t_{n+1} [m/s²].
    pub body_acc: [f64; 2],
    /// Porosity gradient ∇n at t_n [1/m] (two-phase).
    pub grad_n: [f64; 2],
    /// Newmark predictors of the point.
    pub pred: Predictors,
}

/// Newmark factors a₀ = 1/(βΔt²), a₁ = γ/(βΔt) of a step of length Δt.
#[derive(Debug, Clone, Copy)]
pub struct Newmark {
    /// 1/(βΔt²).
    pub a0: f64,
    /// γ/(βΔt).
    pub a1: f64,
    beta: f64,
    gamma: f64,
    dt: f64,
}

impl Newmark {
    /// Factors for step `dt`.
    pub fn new(beta: f64, gamma: f64, dt: f64) -> Newmark {
        Newmark { a0: 1.0 / (beta * dt * dt), a1: gamma / (beta * dt), beta, gamma, dt }
    }

    /// Predictors (ã_n, ṽ_n) of a point with velocity `v` and acceleration `a` at t_n ([003] Eq. 21
    /// at Δd = 0).
    pub fn predict(&self, v: [f64; 2], a: [f64; 2]) -> ([f64; 2], [f64; 2]) {
        let (b, g, dt) = (self.beta, self.gamma, self.dt);
        let pa = |c: usize| -v[c] / (b * dt) - (0.5 / b - 1.0) * a[c];
        let pv = |c: usize| -(g / b - 1.0) * v[c] - (0.5 * g / b - 1.0) * dt * a[c];
        ([pa(0), pa(1)], [pv(0), pv(1)])
    }
}

/// Newmark predictors at a material point: the acceleration and velocity at t_{n+1} for a zero
/// displacement increment.
#[derive(Debug, Clone, Copy, Default)]
pub struct Predictors {
    /// ã_n of the solid [m/s²].
    pub a_u: [f64; 2],
    /// ṽ_n of the solid [m/s].
    pub v_u: [f64; 2],
    /// ã_n of the water [m/s²] (two-phase).
    pub a_w: [f64; 2],
    /// ṽ_n of the water [m/s] (two-phase).
    pub v_w: [f64; 2],
}

impl Predictors {
    /// The predictors for solid (`v_u`, `a_u`) and water (`v_w`, `a_w`) velocities and accelerations
    /// at t_n (the nodal values interpolated to the point).
    pub fn new(nm: &Newmark, v_u: [f64; 2], a_u: [f64; 2], v_w: [f64; 2], a_w: [f64; 2]) -> Predictors {
        let (pa_u, pv_u) = nm.predict(v_u, a_u);
        let (pa_w, pv_w) = nm.predict(v_w, a_w);
        Predictors { a_u: pa_u, v_u: pv_u, a_w: pa_w, v_w: pv_w }
    }
}

/// B̄ of one node: 4 strain rows × 2 displacement components ([000] Eq. 16).
#[inline]
pub fn bbar(n: &NodeBasis) -> [[f64; 2]; 4] {
    let (gx, gy, vx, vy) = (n.g[0], n.g[1], n.gv[0], n.gv[1]);
    let t = 1.0 / 3.0;
    [
        [2.0 * t * gx + t * vx, -t * gy + t * vy],
        [-t * gx + t * vx, 2.0 * t * gy + t * vy],
        [gy, gx],
        [-t * gx + t * vx, -t * gy + t * vy],
    ]
}

/// Interpolated kinematics of a particle.
#[derive(Debug, Clone, Copy, Default)]
pub struct Kinematics {
    /// Strain increment B̄ Δu [xx, yy, γxy, zz].
    pub deps: [f64; 4],
    /// Volumetric strain increment of the water ∇̄·ΔU.
    pub dvol_w: f64,
    /// Pressure increment Σ S Δp.
    pub dp: f64,
    /// Solid acceleration, water acceleration, solid velocity, water velocity at t_{n+1}.
    pub a_u: [f64; 2],
    /// Water acceleration.
    pub a_w: [f64; 2],
    /// Solid velocity.
    pub v_u: [f64; 2],
    /// Water velocity.
    pub v_w: [f64; 2],
    /// Solid displacement increment Σ S Δu.
    pub du: [f64; 2],
    /// Water displacement increment Σ S ΔU.
    pub dw: [f64; 2],
}

/// Interpolates nodal values to the particle and adds its Newmark predictors.
pub fn interpolate(basis: &[NodeBasis], states: &[NodeState], pred: &Predictors, two_phase: bool) -> Kinematics {
    let mut k = Kinematics { a_u: pred.a_u, v_u: pred.v_u, ..Kinematics::default() };
    if two_phase {
        k.a_w = pred.a_w;
        k.v_w = pred.v_w;
    }
    for (b, st) in basis.iter().zip(states) {
        for (d, row) in k.deps.iter_mut().zip(bbar(b)) {
            *d += row[0] * st.d[dof::UX] + row[1] * st.d[dof::UY];
        }
        for c in 0..2 {
            k.a_u[c] += b.s * st.a[c];
            k.v_u[c] += b.s * st.v[c];
            k.du[c] += b.s * st.d[c];
        }
        if two_phase {
            k.dp += b.s * st.d[dof::P];
            k.dvol_w += b.gv[0] * st.d[dof::WX] + b.gv[1] * st.d[dof::WY];
            for c in 0..2 {
                k.a_w[c] += b.s * st.a[dof::WX + c];
                k.v_w[c] += b.s * st.v[dof::WX + c];
                k.dw[c] += b.s * st.d[dof::WX + c];
            }
        }
    }
    k
}

/// Residual block of one particle (length `nn × ndof`, node-major) and the stress update it used.
pub fn residual(
    basis: &[NodeBasis],
    states: &[NodeState],
    part: &ParticleInput,
    model: &Constitutive,
    two_phase: bool,
    out: &mut [f64],
) -> StressUpdate {
    let nd = if two_phase { 5 } else { 2 };
    let kin = interpolate(basis, states, &part.pred, two_phase);
    let upd = model.update(&part.stress, part.eps_pd, &kin.deps);
    let v = part.volume;
    let n = part.porosity;
    let p_new = part.p + kin.dp;
    // Stress carried by the solid equation: σ' − (1 − n) m p (two-phase, [003] Eq. 23a) or σ.
    let mut s = upd.stress;
    if two_phase {
        for r in [0, 1, 3] {
            s[r] -= (1.0 - n) * p_new;
        }
    }
    let vol_u = kin.deps[0] + kin.deps[1] + kin.deps[3];
    for (k, b) in basis.iter().enumerate() {
        let bb = bbar(b);
        let o = k * nd;
        for c in 0..2 {
            let inertia = part.mass * (kin.a_u[c] - part.body_acc[c]);
            let drag = if two_phase { part.drag * (kin.v_u[c] - kin.v_w[c]) } else { 0.0 };
            let internal: f64 = (0..4).map(|r| bb[r][c] * s[r]).sum::<f64>() * v;
            out[o + c] = b.s * (inertia + drag) + internal;
        }
        if two_phase {
            // ∇n terms (see the module documentation).
            for c in 0..2 {
                out[o + c] += b.s * p_new * part.grad_n[c] * v;
            }
            let dn_rel: f64 = (0..2).map(|c| part.grad_n[c] * (kin.dw[c] - kin.du[c])).sum();
            out[o + dof::P] = -b.s * ((1.0 - n) * vol_u + n * kin.dvol_w + kin.dp * part.inv_q + dn_rel) * v;
            for c in 0..2 {
                let inertia = part.water_mass * (kin.a_w[c] - part.body_acc[c]);
                let drag = part.drag * (kin.v_w[c] - kin.v_u[c]);
                out[o + dof::WX + c] =
                    b.s * (inertia + drag) - b.gv[c] * n * p_new * v - b.s * p_new * part.grad_n[c] * v;
            }
        }
    }
    upd
}

/// Tangent block of one particle: d(residual)/d(Δd), row-major `(nn·ndof)²`, for the soil tangent
/// `dsig` (the `tangent` of the stress update at the current iterate). Every entry of `out` is
/// written (the zero couplings too), so the buffer may be reused from particle to particle.
pub fn tangent(basis: &[NodeBasis], part: &ParticleInput, dsig: &Mat4, nm: Newmark, two_phase: bool, out: &mut [f64]) {
    let nd = if two_phase { 5 } else { 2 };
    let m = basis.len() * nd;
    out[..m * m].fill(0.0);
    let v = part.volume;
    let n = part.porosity;
    // B̄ and D B̄ of every node, computed once.
    let mut bbs = [[[0.0; 2]; 4]; MAX_NODES];
    let mut dbs = [[[0.0; 2]; 4]; MAX_NODES];
    for (k, b) in basis.iter().enumerate() {
        bbs[k] = bbar(b);
        for r in 0..4 {
            for c in 0..2 {
                dbs[k][r][c] = (0..4).map(|q| dsig[r][q] * bbs[k][q][c]).sum();
            }
        }
    }
    for (k, bk) in basis.iter().enumerate() {
        for (l, bl) in basis.iter().enumerate() {
            let ss = bk.s * bl.s;
            let row = |c: usize| (k * nd + c) * m + l * nd;
            // u–u: S S (a₀ m_s + a₁ c) I + B̄_kᵀ D B̄_l V  ([003] 16a, 16c, 16f)
            let muu = ss * (nm.a0 * part.mass + if two_phase { nm.a1 * part.drag } else { 0.0 });
            for a in 0..2 {
                for b in 0..2 {
                    let kab: f64 = (0..4).map(|r| bbs[k][r][a] * dbs[l][r][b]).sum();
                    out[row(a) + b] = kab * v + if a == b { muu } else { 0.0 };
                }
            }
            if !two_phase {
                continue;
            }
            let cuw = -ss * nm.a1 * part.drag;
            let mww = ss * (nm.a0 * part.water_mass + nm.a1 * part.drag);
            for a in 0..2 {
                // u–U and U–u: −a₁ C₂  ([003] 16d)
                out[row(a) + dof::WX + a] = cuw;
                out[row(dof::WX + a) + a] = cuw;
                // U–U: a₀ M_U + a₁ C₃  ([003] 16b, 16e)
                out[row(dof::WX + a) + dof::WX + a] = mww;
                // u–p: −G₁ = −(1 − n) ∇̄S_k S_l V, U–p: −G₂ = −n ∇̄S_k S_l V  ([003] 16g, 16h)
                out[row(a) + dof::P] = -(1.0 - n) * bk.gv[a] * bl.s * v;
                out[row(dof::WX + a) + dof::P] = -n * bk.gv[a] * bl.s * v;
                // p–u: −G₁ᵀ, p–U: −G₂ᵀ
                out[row(dof::P) + a] = -(1.0 - n) * bk.s * bl.gv[a] * v;
                out[row(dof::P) + dof::WX + a] = -n * bk.s * bl.gv[a] * v;
                // ∇n terms: ±S_k S_l ∇n V in u–p, U–p and their transposes.
                let gn = ss * part.grad_n[a] * v;
                out[row(a) + dof::P] += gn;
                out[row(dof::WX + a) + dof::P] -= gn;
                out[row(dof::P) + a] += gn;
                out[row(dof::P) + dof::WX + a] -= gn;
            }
            // p–p: −P = −S_k S_l V / Q  ([003] 16i, with the sign of Eq. 23b)
            out[row(dof::P) + dof::P] = -ss * v * part.inv_q;
        }
    }
}

/// What the particle update of [003] Eq. 24 / [000] Eq. 11 needs from the converged step.
#[derive(Debug, Clone, Copy)]
pub struct StepResult {
    /// Interpolated kinematics at the converged increments.
    pub kin: Kinematics,
    /// Deformation gradient of the step, I + ∇Δu (rows).
    pub f_inc: [[f64; 2]; 2],
    /// det(I + ∇Δu): volume ratio of the step.
    pub jacobian: f64,
}

/// Kinematics of the converged step at a particle, with its deformation gradient F = I + ∇Δu and
/// volume ratio J = det F. With B̄ the volume follows the B̄ volumetric strain that the stress sees
/// (an F̄ update, as Coombs et al. 2018 do for the MPM): J̄ = J (1 + ∇̄·Δu)/(1 + ∇·Δu) and
/// F̄ = sqrt(J̄/J) F. Otherwise the points of a cell could trade volume among themselves at no
/// energy (B̄ only sees the cell's average) until one of them is crushed.
pub fn step_result(basis: &[NodeBasis], states: &[NodeState], pred: &Predictors, two_phase: bool) -> StepResult {
    let kin = interpolate(basis, states, pred, two_phase);
    let mut f = [[1.0, 0.0], [0.0, 1.0]];
    let (mut div, mut div_bar) = (0.0, 0.0);
    for (b, st) in basis.iter().zip(states) {
        for (a, fa) in f.iter_mut().enumerate() {
            for (fac, g) in fa.iter_mut().zip(b.g) {
                *fac += st.d[a] * g;
            }
        }
        div += b.g[0] * st.d[dof::UX] + b.g[1] * st.d[dof::UY];
        div_bar += b.gv[0] * st.d[dof::UX] + b.gv[1] * st.d[dof::UY];
    }
    let j = f[0][0] * f[1][1] - f[0][1] * f[1][0];
    if div_bar == div || 1.0 + div <= 0.0 || 1.0 + div_bar <= 0.0 {
        return StepResult { kin, f_inc: f, jacobian: j };
    }
    let j_bar = j * (1.0 + div_bar) / (1.0 + div);
    let scale = (j_bar / j).sqrt();
    let f_bar = [[f[0][0] * scale, f[0][1] * scale], [f[1][0] * scale, f[1][1] * scale]];
    StepResult { kin, f_inc: f_bar, jacobian: j_bar }
}

/// Pressure-projection stabilisation of one cell (Bochev & Dohrmann 2006; Dohrmann & Bochev 2004,
/// for equal-order pressures): S_kl = Σ_p w_p (N_k(x_p) − N̄_k)(N_l(x_p) − N̄_l) over the material
/// points p of the cell, with N the cell's four bilinear functions at the points, w_p = τ_p V_p and
/// N̄ the w-weighted cell averages. Δpᵀ S Δp penalises the part of the pressure increment that is
/// not constant in the cell, which the volumetric coupling of equal-order (and B̄) interpolation
/// cannot see; it vanishes for a cell-wise constant field. The caller subtracts S Δp from the
/// continuity rows (the sign of −P).
pub fn pressure_projection(n: &[[f64; 4]], w: &[f64]) -> [[f64; 4]; 4] {
    let total: f64 = w.iter().sum();
    let mut out = [[0.0; 4]; 4];
    if total <= 0.0 {
        return out;
    }
    let mut mean = [0.0; 4];
    for (np, wp) in n.iter().zip(w) {
        for k in 0..4 {
            mean[k] += wp * np[k] / total;
        }
    }
    for (np, wp) in n.iter().zip(w) {
        for k in 0..4 {
            for l in 0..4 {
                out[k][l] += wp * (np[k] - mean[k]) * (np[l] - mean[l]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::soil::LinearElastic;

    fn sample(nn: usize) -> Vec<NodeBasis> {
        (0..nn)
            .map(|k| {
                let x = k as f64;
                NodeBasis {
                    s: 0.05 + 0.1 * (x * 0.7).sin().abs(),
                    g: [(x * 1.3).cos() * 3.0, (x * 0.9).sin() * 2.0],
                    gv: [(x * 1.1).cos() * 2.5, (x * 0.4).sin() * 1.5],
                }
            })
            .collect()
    }

    fn part() -> ParticleInput {
        ParticleInput {
            volume: 2.5e-3,
            porosity: 0.35,
            mass: 4.3,
            water_mass: 0.9,
            drag: 7.0e3,
            inv_q: 3.0e-9,
            stress: [-1.0e3, -2.0e3, 150.0, -1.2e3],
            eps_pd: 0.0,
            p: 500.0,
            body_acc: [0.0, -9.81],
            grad_n: [0.7, -1.3],
            pred: Predictors { a_u: [0.3, -0.2], v_u: [0.01, 0.02], a_w: [-0.1, 0.4], v_w: [0.03, -0.01] },
        }
    }

    /// Nodal states from increments, as the assembly builds them.
    fn states(d: &[f64], nd: usize, nm: Newmark) -> Vec<NodeState> {
        (0..d.len() / nd)
            .map(|k| {
                let mut s = NodeState::default();
                for c in 0..nd {
                    s.d[c] = d[k * nd + c];
                    s.a[c] = nm.a0 * d[k * nd + c];
                    s.v[c] = nm.a1 * d[k * nd + c];
                }
                s
            })
            .collect()
    }

    #[test]
    fn newmark_reproduces_a_uniformly_accelerated_motion() {
        // A point with v_n, a_n moved by Δd = v_n Δt + a_n Δt²/2 keeps a_n and reaches v_n + a_n Δt
        // ([003] Eqs. 20–21) for any β, γ.
        for (beta, gamma) in [(0.25, 0.5), (0.3025, 0.6)] {
            let (dt, v, a) = (2e-3, [0.4, -1.1], [3.0, -9.81]);
            let nm = Newmark::new(beta, gamma, dt);
            let pred = Predictors::new(&nm, v, a, v, a);
            let d = [v[0] * dt + 0.5 * a[0] * dt * dt, v[1] * dt + 0.5 * a[1] * dt * dt];
            let basis = [NodeBasis { s: 1.0, g: [0.0; 2], gv: [0.0; 2] }];
            let st = states(&[d[0], d[1], 0.0, d[0], d[1]], 5, nm);
            let k = interpolate(&basis, &st, &pred, true);
            for c in 0..2 {
                assert!((k.a_u[c] - a[c]).abs() < 1e-9 && (k.a_w[c] - a[c]).abs() < 1e-9, "{k:?}");
                assert!((k.v_u[c] - (v[c] + a[c] * dt)).abs() < 1e-12, "{k:?}");
            }
        }
    }

    /// The tangent is the derivative of the residual, block by block (u–u, u–p, u–U, p–*, U–*).
    #[test]
    fn tangent_matches_central_finite_differences_of_the_residual() {
        for two_phase in [true, false] {
            let nd = if two_phase { 5 } else { 2 };
            let basis = sample(6);
            let m = basis.len() * nd;
            let nm = Newmark::new(0.25, 0.5, 1e-3);
            let model = Constitutive::LinearElastic(LinearElastic::new(1e7, 0.3));
            let d0: Vec<f64> = (0..m).map(|i| 1e-5 * ((i as f64) * 0.37).sin()).collect();
            let p = part();
            let mut r0 = vec![0.0; m];
            let upd = residual(&basis, &states(&d0, nd, nm), &p, &model, two_phase, &mut r0);
            // A dirty buffer: the kernel must write every entry (the assembly reuses its buffer).
            let mut t = vec![f64::NAN; m * m];
            tangent(&basis, &p, &upd.tangent, nm, two_phase, &mut t);
            let names = ["ux", "uy", "p", "Ux", "Uy"];
            let mut worst: std::collections::BTreeMap<(usize, usize), f64> = Default::default();
            let scale = t.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            for c in 0..m {
                let h = 1e-7 * (1.0 + d0[c].abs());
                let (mut dp, mut dm) = (d0.clone(), d0.clone());
                dp[c] += h;
                dm[c] -= h;
                let (mut rp, mut rm) = (vec![0.0; m], vec![0.0; m]);
                residual(&basis, &states(&dp, nd, nm), &p, &model, two_phase, &mut rp);
                residual(&basis, &states(&dm, nd, nm), &p, &model, two_phase, &mut rm);
                for r in 0..m {
                    let fd = (rp[r] - rm[r]) / (2.0 * h);
                    let e = worst.entry((r % nd, c % nd)).or_insert(0.0);
                    *e = e.max((fd - t[r * m + c]).abs());
                }
            }
            for ((a, b), e) in worst {
                assert!(
                    e <= 1e-6 * scale,
                    "two_phase={two_phase}: block {}-{} differs by {e:e} (scale {scale:e})",
                    names[a],
                    names[b]
                );
            }
            // Symmetric for a symmetric soil tangent.
            for r in 0..m {
                for c in 0..m {
                    assert!((t[r * m + c] - t[c * m + r]).abs() <= 1e-12 * scale, "asymmetric at ({r},{c})");
                }
            }
        }
    }

    #[test]
    fn residual_vanishes_at_rest_in_equilibrium_and_balances_gravity() {
        // A particle at rest with zero stress under gravity: the u-rows carry −S m_s b, the U-rows −S m_w b,
        // the p-rows are zero; the sum over nodes of the vertical u+U forces is −(m_s + m_w) g when Σ S = 1.
        let mut basis = sample(4);
        let total: f64 = basis.iter().map(|b| b.s).sum();
        for b in basis.iter_mut() {
            b.s /= total;
        }
        let mut p = part();
        p.stress = [0.0; 4];
        p.p = 0.0;
        p.grad_n = [0.0; 2];
        p.pred = Predictors::default();
        let st = vec![NodeState::default(); 4];
        let mut r = vec![0.0; 20];
        residual(&basis, &st, &p, &Constitutive::LinearElastic(LinearElastic::new(1e7, 0.3)), true, &mut r);
        let fy: f64 = (0..4).map(|k| r[k * 5 + 1] + r[k * 5 + 4]).sum();
        assert!((fy - (p.mass + p.water_mass) * 9.81).abs() < 1e-12);
        assert!((0..4).all(|k| r[k * 5 + 2] == 0.0));
    }

    #[test]
    fn the_pressure_projection_ignores_constants_and_penalises_the_rest() {
        // Four points of a unit cell at the quarter points.
        let pts = [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)];
        let n: Vec<[f64; 4]> =
            pts.iter().map(|&(x, y)| [(1.0 - x) * (1.0 - y), x * (1.0 - y), (1.0 - x) * y, x * y]).collect();
        let s = pressure_projection(&n, &[0.25; 4]);
        let apply = |p: [f64; 4]| -> f64 { (0..4).map(|k| (0..4).map(|l| p[k] * s[k][l] * p[l]).sum::<f64>()).sum() };
        assert!(apply([1.0; 4]).abs() < 1e-15, "a constant is not penalised");
        // The checkerboard (+ − − +) and a linear field are.
        assert!(apply([1.0, -1.0, -1.0, 1.0]) > 1e-3);
        assert!(apply([0.0, 1.0, 0.0, 1.0]) > 1e-3);
        for (k, row) in s.iter().enumerate() {
            for (l, v) in row.iter().enumerate() {
                assert!((v - s[l][k]).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn volume_ratio_of_a_uniform_compression() {
        // Linear field Δu = (−0.01 x, −0.02 y) reproduced by nodal values at unit-square corners.
        let pts = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
        let (px, py) = (0.3, 0.6);
        let basis: Vec<NodeBasis> = pts
            .iter()
            .map(|&(x, y): &(f64, f64)| {
                let sx = if x == 0.0 { 1.0 - px } else { px };
                let sy = if y == 0.0 { 1.0 - py } else { py };
                let gx = if x == 0.0 { -1.0 } else { 1.0 };
                let gy = if y == 0.0 { -1.0 } else { 1.0 };
                NodeBasis { s: sx * sy, g: [gx * sy, sx * gy], gv: [gx * sy, sx * gy] }
            })
            .collect();
        let st: Vec<NodeState> = pts
            .iter()
            .map(|&(x, y)| {
                let mut s = NodeState::default();
                s.d[0] = -0.01 * x;
                s.d[1] = -0.02 * y;
                s
            })
            .collect();
        let r = step_result(&basis, &st, &Predictors::default(), false);
        assert!((r.jacobian - 0.99 * 0.98).abs() < 1e-14);
        assert!((r.f_inc[0][0] - 0.99).abs() < 1e-14 && (r.f_inc[1][1] - 0.98).abs() < 1e-14);
        assert!(r.f_inc[0][1].abs() < 1e-14 && r.f_inc[1][0].abs() < 1e-14);
        assert!((r.kin.deps[0] + 0.01).abs() < 1e-14 && (r.kin.deps[1] + 0.02).abs() < 1e-14);
        assert!((r.kin.du[0] + 0.003).abs() < 1e-14);
    }
}
