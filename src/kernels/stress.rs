//! The divergence of the effective stress on the current configuration ([003] Eq. 23a, [000]
//! Eq. 16 on x_{n+1}) and the pore pressure's forces on both phases ([`pore_pressure`]).
//!
//! Residual in the u rows: f_i = B̄'_iᵀ σ'_{n+1} V_{n+1} = V_{n+1} (dev σ' ∇'S_i + σ'_m ∇̄'S_i) (in
//! the plane; σ'_m the mean stress including σ'_zz), with ∇' and ∇̄' the gradients on x_{n+1} and
//! σ'_{n+1} the soil model's update from the rotated stress (see [`super::kinematics`]).
//!
//! Its derivative with respect to Δu_l (component d) has three parts:
//! * material: V_{n+1} B̄'_iᵀ A_l with A_l = ∂σ'/∂Δu_l = T (∂(Rσ_nRᵀ)/∂θ) ∂θ/∂Δu_l + D_alg ∂Δε/∂Δu_l
//!   (T = ∂σ'/∂σ_trial of the return, D_alg = T D);
//! * volume: f_i,c (∇̄'S_l)_d, from ∂J_v/∂Δu_l,d = J_v (∇̄'S_l)_d;
//! * geometric: from ∂∇'S_i/∂Δu_l,d = −∇'S_l (∇'S_i)_d (and the same for ∇̄'):
//!   −V_{n+1} [(dev σ' ∇'S_l)_c (∇'S_i)_d + σ'_m (∇̄'S_l)_c (∇̄'S_i)_d].
//!
//! Every derivative with respect to Δu_l goes through node l's strain operators
//! ([`super::Point::strain`], `strain_spatial`, `strain_hoop`): the basis itself, or [001]'s CMPM
//! patch functions, which recover the strain while the forces keep the basis.
//!
//! Axial symmetry adds the hoop stress to the radial force, f_i,r += V_{n+1}(dev σ'_θθ T'_i +
//! σ'_m T̄'_i) (B̄'ᵀσ' with the hoop row of [`super::bbar`]), ∂J_v/∂Δu_l,r gains J_v T̄'_l, and
//! ∂T'_i/∂Δu_l,r = −T'_i T'_l (T' = T/F_θθ) gives the geometric part
//! −V_{n+1} (dev σ'_θθ T'_i T'_l + σ'_m T̄'_i T̄'_l) in the r–r entry.

use super::{bbar, kinematics, Point, Scheme};
use crate::model::soil::Stress;

/// In-plane deviatoric stress and the mean stress of a plane state [xx, yy, xy, zz, 0, 0].
fn split(s: &Stress) -> ([[f64; 2]; 2], f64) {
    let pm = (s[0] + s[1] + s[3]) / 3.0;
    ([[s[0] - pm, s[2]], [s[2], s[1] - pm]], pm)
}

/// The force of stress `s` on a node with gradients (g, gv) on x_{n+1}, per unit volume.
#[inline]
fn traction(dev: &[[f64; 2]; 2], pm: f64, g: [f64; 2], gv: [f64; 2]) -> [f64; 2] {
    [dev[0][0] * g[0] + dev[0][1] * g[1] + pm * gv[0], dev[1][0] * g[0] + dev[1][1] * g[1] + pm * gv[1]]
}

/// The radial force of the hoop stress on a node with hoop operators (T', T̄') on x_{n+1}, per
/// unit volume: dev σ_θθ T' + σ_m T̄' (zero in plane strain).
#[inline]
fn hoop_force(s: &Stress, pm: f64, hoop: (f64, f64)) -> f64 {
    (s[3] - pm) * hoop.0 + pm * hoop.1
}

/// Adds the effective-stress residual in the u rows (weight w_f = 1 − α_f).
pub fn residual(pt: &Point, nm: &Scheme, out: &mut [f64]) {
    let nd = pt.layout.nd;
    let v = pt.volume_new() * nm.w_force;
    let (dev, pm) = split(&pt.upd.stress);
    for k in 0..pt.basis.len() {
        let (g, gv) = pt.spatial[k];
        let t = traction(&dev, pm, g, gv);
        out[k * nd] += (t[0] + hoop_force(&pt.upd.stress, pm, pt.hoop[k])) * v;
        out[k * nd + 1] += t[1] * v;
    }
}

/// Adds the u–u tangent of the effective-stress term (material, volume and geometric parts).
pub fn tangent(pt: &Point, nm: &Scheme, out: &mut [f64]) {
    tangent_with(pt, nm, out, 1.0);
}

/// [`tangent`] with the material part V B̄'ᵀ D_alg ∂Δε/∂Δu scaled by `material`: 1 is the exact
/// tangent; [001]'s modified weights W* scale it by omp/cmp, and its mapped stiffnesses replace
/// it (0) by their cell kernels ([`super::cell`]). The rotation of the objective update and the
/// volume and geometric parts are kept.
pub fn tangent_with(pt: &Point, nm: &Scheme, out: &mut [f64], material: f64) {
    let (nd, m) = (pt.layout.nd, pt.size());
    let v = pt.volume_new() * nm.w_force;
    let s = &pt.upd.stress;
    let (dev, pm) = split(s);
    let (t_mat, d_alg) = (&pt.upd.trial_tangent, &pt.upd.tangent);
    // ∂σ'/∂θ through the return: T · d(Rσ_nRᵀ)/dθ.
    let drot = kinematics::rotate_derivative(&pt.rotated);
    let t_drot: [f64; 4] = std::array::from_fn(|r| (0..4).map(|q| t_mat[r][q] * drot[q]).sum());
    // A_l = ∂σ'/∂Δu_l (4 × 2) for every node.
    let mut a = [[[0.0; 2]; 4]; super::MAX_NODES];
    for (l, bl) in pt.strain.iter().enumerate().take(pt.basis.len()) {
        let de = pt.kin.deps_derivative(bl);
        let dt = pt.kin.theta_derivative(bl);
        for r in 0..4 {
            for d in 0..2 {
                a[l][r][d] = t_drot[r] * dt[d] + material * (0..4).map(|q| d_alg[r][q] * de[q][d]).sum::<f64>();
            }
        }
    }
    let dev_tt = s[3] - pm;
    // A geometrically linear step has forces on x_n with V_n: no volume or geometric part.
    let linear = pt.kin.linear;
    for k in 0..pt.basis.len() {
        let (gk, gvk) = pt.spatial[k];
        let hk = pt.hoop[k];
        let bk = bbar(gk, gvk, hk);
        let mut tk = traction(&dev, pm, gk, gvk);
        tk[0] += hoop_force(s, pm, hk);
        for l in 0..pt.basis.len() {
            // Derivatives with respect to Δu_l go through the strain operators of node l.
            let (gl, gvl) = pt.strain_spatial[l];
            let hl = pt.strain_hoop[l];
            let dev_gl = [dev[0][0] * gl[0] + dev[0][1] * gl[1], dev[1][0] * gl[0] + dev[1][1] * gl[1]];
            // ∂J_v/∂Δu_l / J_v: the in-plane divergence and, radially, the hoop term.
            let djv = [gvl[0] + hl.1, gvl[1]];
            for c in 0..2 {
                for d in 0..2 {
                    let material: f64 = (0..4).map(|r| bk[r][c] * a[l][r][d]).sum();
                    let volume = tk[c] * djv[d];
                    let mut geometric = -dev_gl[c] * gk[d] - pm * gvl[c] * gvk[d];
                    if c == 0 && d == 0 {
                        geometric -= dev_tt * hk.0 * hl.0 + pm * hk.1 * hl.1;
                    }
                    out[(k * nd + c) * m + l * nd + d] +=
                        v * if linear { material } else { material + volume + geometric };
                }
            }
        }
    }
    // An implicit F̄ step ([`super::fbar`]): the stress sees r = (1 + Σ_i S_ip ϑ_i)/J̄_p^n, so
    // ∂f_k/∂ϑ_i = V_{n+1} B̄'_kᵀ D_alg ∂Δε/∂r S_ip/J̄_p^n (the material part, scaled likewise).
    if let Some(j) = pt.layout.jbar {
        let de = pt.kin.deps_volume_derivative();
        let dsig: [f64; 4] = std::array::from_fn(|r| (0..4).map(|q| d_alg[r][q] * de[q]).sum::<f64>());
        let vj = v * material / pt.part.jbar;
        for k in 0..pt.basis.len() {
            let (gk, gvk) = pt.spatial[k];
            let bk = bbar(gk, gvk, pt.hoop[k]);
            let force: [f64; 2] = std::array::from_fn(|c| vj * (0..4).map(|r| bk[r][c] * dsig[r]).sum::<f64>());
            for (c, f) in force.into_iter().enumerate() {
                let row = (k * nd + c) * m;
                for (i, b) in pt.basis.iter().enumerate() {
                    out[row + i * nd + j] += f * b.s;
                }
            }
        }
    }
}

/// The pore pressure's forces: −(1 − n) p ∇̄'S_i V_{n+1} on the solid and −n p ∇̄'S_i V_{n+1} on the
/// water ([003] Eqs. 23a, 23c on x_{n+1}); in a layout without water the solid carries p whole (the
/// momentum balance of the mixture). A layout without a pressure (a drained static stage of a
/// two-phase model) keeps the particle's p_n, so that the total stress stays σ' − p m.
pub mod pore_pressure {
    use super::super::{Point, Scheme};

    /// The fractions of p carried by the solid and the water equations.
    fn shares(pt: &Point) -> (f64, f64) {
        let n = pt.part.porosity;
        if pt.layout.w.is_some() {
            (1.0 - n, n)
        } else {
            (1.0, 0.0)
        }
    }

    /// Adds the pressure forces (weight w_f).
    pub fn residual(pt: &Point, nm: &Scheme, out: &mut [f64]) {
        if pt.layout.p.is_none() && pt.p == 0.0 {
            return;
        }
        let nd = pt.layout.nd;
        let (fs, fw) = shares(pt);
        let pv = pt.p * pt.volume_new() * nm.w_force;
        for k in 0..pt.basis.len() {
            let (g, tv) = (pt.spatial[k].1, pt.hoop[k].1);
            // The divergence operator on x_{n+1}: ∇̄'S and, radially, the hoop term T̄'.
            let gv = [g[0] + tv, g[1]];
            for c in 0..2 {
                out[k * nd + c] -= fs * pv * gv[c];
                if let Some(w) = pt.layout.w {
                    out[k * nd + w + c] -= fw * pv * gv[c];
                }
            }
        }
    }

    /// Adds the u–p and U–p couplings (−G₁, −G₂ on x_{n+1}) and their geometric u–u and U–u parts.
    pub fn tangent(pt: &Point, nm: &Scheme, out: &mut [f64]) {
        if pt.layout.p.is_none() && pt.p == 0.0 {
            return;
        }
        let (nd, m) = (pt.layout.nd, pt.size());
        let (fs, fw) = shares(pt);
        let v = pt.volume_new() * nm.w_force;
        for k in 0..pt.basis.len() {
            let (gvk, tk) = (pt.spatial[k].1, pt.hoop[k].1);
            let divk = [gvk[0] + tk, gvk[1]];
            for (l, bl) in pt.basis.iter().enumerate() {
                let (gvl, tl) = (pt.strain_spatial[l].1, pt.strain_hoop[l].1);
                for c in 0..2 {
                    let ru = (k * nd + c) * m;
                    if let Some(p) = pt.layout.p {
                        out[ru + l * nd + p] -= fs * v * divk[c] * bl.s;
                    }
                    for d in 0..2 {
                        // ∂(J_v ∇̄'S_k,c)/∂Δu_l,d = J_v (∇̄'S_l,d ∇̄'S_k,c − ∇̄'S_l,c ∇̄'S_k,d); in
                        // axial symmetry the divergence gains T̄' (radially) and J_v's derivative
                        // T̄'_l (radially), whose hoop–hoop parts cancel.
                        let mut geo = gvl[d] * gvk[c] - gvl[c] * gvk[d];
                        if d == 0 {
                            geo += tl * gvk[c];
                        }
                        if c == 0 {
                            geo += tk * gvl[d];
                        }
                        // (None in a geometrically linear step: forces on x_n with V_n.)
                        let geo = if pt.kin.linear { 0.0 } else { pt.p * v * geo };
                        out[ru + l * nd + d] -= fs * geo;
                        if let Some(w) = pt.layout.w {
                            out[(k * nd + w + c) * m + l * nd + d] -= fw * geo;
                        }
                    }
                    if let (Some(w), Some(p)) = (pt.layout.w, pt.layout.p) {
                        out[(k * nd + w + c) * m + l * nd + p] -= fw * v * divk[c] * bl.s;
                    }
                }
            }
        }
    }
}
