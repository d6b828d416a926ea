//! The divergence of the effective stress on the current configuration ([003] Eq. 23a, [000]
//! Eq. 16 on x_{n+1}) and the pore pressure's forces on both phases ([`pore_pressure`]).
//!
//! Residual in the u rows: f_i = B̄'_iᵀ σ'_{n+1} V_{n+1} = V_{n+1} (dev σ' ∇'S_i + σ'_m ∇̄'S_i) (in
//! the plane its in-plane part; σ'_m the mean stress including σ'_zz), with ∇' and ∇̄' the
//! gradients on x_{n+1} and σ'_{n+1} the soil model's update from the rotated stress (see
//! [`super::kinematics`]). The same code serves two and three dimensions (`D`): a plane point
//! takes the first four stress components and the 4 × 4 block of the tangents
//! ([`super::strain_rows`]).
//!
//! Its derivative with respect to Δu_l (component d) has three parts:
//! * material: V_{n+1} B̄'_iᵀ A_l with A_l = ∂σ'/∂Δu_l = T ∂(Rσ_nRᵀ)/∂Δu_l + D_alg ∂Δε/∂Δu_l
//!   (T = ∂σ'/∂σ_trial of the return, D_alg = T D; in two dimensions ∂(Rσ_nRᵀ)/∂Δu_l is
//!   ∂(Rσ_nRᵀ)/∂θ ∂θ/∂Δu_l, in three [`super::kinematics::Kinematics::rotated_derivative`]);
//! * volume: f_i,c (∇̄'S_l)_d, from ∂J_v/∂Δu_l,d = J_v (∇̄'S_l)_d;
//! * geometric: from ∂∇'S_i/∂Δu_l,d = −∇'S_l (∇'S_i)_d (and the same for ∇̄'):
//!   −V_{n+1} [(dev σ' ∇'S_l)_c (∇'S_i)_d + σ'_m (∇̄'S_l)_c (∇̄'S_i)_d].
//!
//! A finite-strain solid (neo-Hookean, Hencky–J2) has no strain increment or rotation: its
//! A_l = ∂σ'/∂ΔF̄ : ∂ΔF̄/∂Δu_l ([`FiniteChain`], the law's [`crate::soils::SoilLaw::finite_tangent`]).
//!
//! The material part's derivatives with respect to Δu_l go through node l's strain operators
//! ([`super::Point::strain`] with [`super::Point::strain_kin`]): the basis itself, or [001]'s CMPM
//! patch functions, which recover the strain the stress sees; the volume and geometric parts go
//! through the basis ([`super::Point::motion_operators`]), which moves the point and its volume.
//!
//! Axial symmetry adds the hoop stress to the radial force, f_i,r += V_{n+1}(dev σ'_θθ T'_i +
//! σ'_m T̄'_i) (B̄'ᵀσ' with the hoop row of [`super::bbar`]), ∂J_v/∂Δu_l,r gains J_v T̄'_l, and
//! ∂T'_i/∂Δu_l,r = −T'_i T'_l (T' = T/F_θθ) gives the geometric part
//! −V_{n+1} (dev σ'_θθ T'_i T'_l + σ'_m T̄'_i T̄'_l) in the r–r entry.

use super::{bbar, kinematics, strain_rows, Point, Scheme};
use crate::algebra::Mat;
use crate::soils::{principal, Stress, NS};

/// The deviatoric stress (its in-plane part in two dimensions) and the mean stress (σ_zz
/// included) of `s`.
fn split<const D: usize>(s: &Stress) -> (Mat<D>, f64) {
    let pm = (s[0] + s[1] + s[3]) / 3.0;
    let t = principal::tensor(s);
    (std::array::from_fn(|i| std::array::from_fn(|j| if i == j { t[i][j] - pm } else { t[i][j] })), pm)
}

/// dev σ v (dev σ is symmetric: its transpose's product).
#[inline]
fn dev_times<const D: usize>(dev: &Mat<D>, v: [f64; D]) -> [f64; D] {
    crate::algebra::mul_t(dev, v)
}

/// The force of stress `s` on a node with gradients (g, gv) on x_{n+1}, per unit volume.
#[inline]
fn traction<const D: usize>(dev: &Mat<D>, pm: f64, g: [f64; D], gv: [f64; D]) -> [f64; D] {
    let t = dev_times(dev, g);
    std::array::from_fn(|c| t[c] + pm * gv[c])
}

/// The radial force of the hoop stress on a node with hoop operators (T', T̄') on x_{n+1}, per
/// unit volume: dev σ_θθ T' + σ_m T̄' (zero in plane strain).
#[inline]
fn hoop_force(s: &Stress, pm: f64, hoop: (f64, f64)) -> f64 {
    (s[3] - pm) * hoop.0 + pm * hoop.1
}

/// Adds the effective-stress residual in the u rows (weight w_f = 1 − α_f).
pub fn residual<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
    let nd = pt.layout.nd;
    let v = pt.volume_new() * nm.w_force;
    let (dev, pm) = split::<D>(&pt.upd.stress);
    for k in 0..pt.basis.len() {
        let (g, gv) = pt.spatial[k];
        let mut t = traction(&dev, pm, g, gv);
        t[0] += hoop_force(&pt.upd.stress, pm, pt.hoop[k]);
        for (c, tc) in t.into_iter().enumerate() {
            out[k * nd + c] += tc * v;
        }
    }
}

/// Adds the u–u tangent of the effective-stress term (material, volume and geometric parts).
pub fn tangent<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
    tangent_with(pt, nm, out, 1.0);
}

/// [`tangent`] with the material part V B̄'ᵀ D_alg ∂Δε/∂Δu scaled by `material`: 1 is the exact
/// tangent; [001]'s modified weights W* scale it by omp/cmp, and its mapped stiffnesses replace
/// it (0) by their cell kernels ([`super::cell`]). The rotation of the objective update and the
/// volume and geometric parts are kept.
pub fn tangent_with<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64], material: f64) {
    // The per-node scratch holds the point's strain rows only (four in two dimensions).
    if strain_rows::<D>() == 4 {
        tangent_in::<D, M, 4>(pt, nm, out, material)
    } else {
        tangent_in::<D, M, NS>(pt, nm, out, material)
    }
}

/// [`tangent_with`] of a point with `R` strain rows ([`strain_rows`]).
fn tangent_in<const D: usize, const M: usize, const R: usize>(
    pt: &Point<D, M>,
    nm: &Scheme,
    out: &mut [f64],
    material: f64,
) {
    let (nd, m) = (pt.layout.nd, pt.size());
    let nr = R;
    let v = pt.volume_new() * nm.w_force;
    let d_alg = &pt.upd.tangent;
    // A plane point's block is small (up to 25 nodes of two dofs): it is formed pair of nodes by
    // pair. A three-dimensional point's is formed row by row over the nodes its operators reach
    // ([`rows_of_nodes`]), which vectorises and leaves out the nodes its domain only touches.
    let sk = pt.strain_kin();
    let block = Block { pt, v, material, nd, m };
    if D == 2 {
        pairs_of_nodes::<D, M, R>(&block, out);
    } else {
        rows_of_nodes::<D, M, R>(&block, out);
    }
    // An implicit F̄ step ([`super::fbar`]): the stress sees r = (1 + Σ_i S_ip ϑ_i)/J̄_p^n, so
    // ∂f_k/∂ϑ_i = V_{n+1} B̄'_kᵀ D_alg ∂Δε/∂r S_ip/J̄_p^n (the material part, scaled likewise).
    if let Some(j) = pt.layout.jbar {
        let de = sk.deps_volume_derivative();
        let dsig: [f64; NS] = std::array::from_fn(|r| (0..nr).map(|q| d_alg[r][q] * de[q]).sum::<f64>());
        let vj = v * material / pt.part.jbar;
        for k in 0..pt.basis.len() {
            let (gk, gvk) = pt.spatial[k];
            let bk = bbar(gk, gvk, pt.hoop[k]);
            let force: [f64; D] = std::array::from_fn(|c| vj * (0..nr).map(|r| bk[r][c] * dsig[r]).sum::<f64>());
            for (c, f) in force.into_iter().enumerate() {
                let row = (k * nd + c) * m;
                for (i, b) in pt.basis.iter().enumerate() {
                    out[row + i * nd + j] += f * b.s;
                }
            }
        }
    }
}

/// What both ways of forming [`tangent_in`]'s block take: the point, its volume weight
/// V_{n+1} w_f, the material part's scale, the dofs per node and the block's size.
#[derive(Clone, Copy)]
struct Block<'a, const D: usize, const M: usize> {
    pt: &'a Point<'a, D, M>,
    v: f64,
    material: f64,
    nd: usize,
    m: usize,
}

/// ∂σ'/∂Δu_l of a point through a node's strain operators ([`tangent_in`]'s material part): the
/// return's tangents and, in two dimensions, T · d(Rσ_nRᵀ)/dθ.
struct StressResponse<'p, const R: usize> {
    t_mat: &'p [[f64; NS]; NS],
    /// T = I (an elastic update): T · d(Rσ_nRᵀ) is d(Rσ_nRᵀ) itself, to the bit.
    t_identity: bool,
    d_alg: &'p [[f64; NS]; NS],
    t_drot: [f64; R],
    material: f64,
    /// A finite-strain model's ∂σ'/∂ΔF̄ ([`super::Point::finite_tangent`]) with what its chain
    /// rule takes; `None` for the incremental models.
    finite: Option<FiniteChain<R>>,
}

/// The chain rule of a finite-strain model's stress σ'(ΔF̄), ΔF̄ = c s F with F = I + Σ Δu_l ⊗ ∇S_l
/// (the strain operators on x_n), s = (J_v/J)^{1/D} B̄'s volume scale and c the explicit F̄ scale
/// (a constant, and 1 in every step that builds a tangent: explicit steps build none, and the
/// implicit F̄ is refused for these models):
/// ∂ΔF̄_ab/∂Δu_l,d = c (s δ_ad (∇S_l)_b + F_ab ∂s/∂Δu_l,d) with
/// ∂s/∂Δu_l,d = (s/D) ((F_v⁻ᵀ∇̄S_l)_d − (F⁻ᵀ∇S_l)_d), so
/// ∂σ'_r/∂Δu_l,d = c (s Σ_b T_r,db (∇S_l)_b + (T_r : F) ∂s/∂Δu_l,d) with T = ∂σ'/∂ΔF̄. Where J or
/// J_v is not positive, s is held at 1 ([`kinematics::Kinematics::volume_scale`]) and ∂s is zero.
struct FiniteChain<const R: usize> {
    /// T_r,ab = ∂σ'_r/∂ΔF̄_ab.
    t: crate::soils::finite_strain::FiniteTangent,
    /// T_r : F over the point's D × D block.
    t_f: [f64; R],
    /// B̄'s volume scale s.
    s: f64,
    /// Whether s follows the motion (J and J_v positive; otherwise it is held at 1).
    s_varies: bool,
    /// The explicit F̄ scale c of the step.
    c: f64,
}

impl<'p, const R: usize> StressResponse<'p, R> {
    /// The response of `pt` with the material part scaled by `material`.
    fn of<const D: usize, const M: usize>(pt: &'p Point<D, M>, material: f64) -> StressResponse<'p, R> {
        let (t_mat, d_alg) = (&pt.upd.trial_tangent, &pt.upd.tangent);
        let drot = kinematics::rotate_derivative(&pt.rotated);
        let t_drot = std::array::from_fn(|r| (0..R).map(|q| t_mat[r][q] * drot[q]).sum());
        let t_identity = *t_mat == crate::soils::IDENTITY6;
        let finite = pt.finite_tangent().map(|t| {
            let f = &pt.strain_kin().f;
            let t_f = std::array::from_fn(|r| {
                (0..D).flat_map(|a| (0..D).map(move |b| (a, b))).map(|(a, b)| t[r][a][b] * f[a][b]).sum()
            });
            let sk = pt.strain_kin();
            debug_assert_eq!(pt.part.fbar, 1.0, "a tangent of an explicit F̄ step");
            FiniteChain { t, t_f, s: sk.volume_scale(), s_varies: sk.j > 0.0 && sk.jv > 0.0, c: pt.part.fbar }
        });
        StressResponse { t_mat, t_identity, d_alg, t_drot, material, finite }
    }

    /// A_l = ∂σ'/∂Δu_l (strain rows × D) through the operators `bl` and the kinematics `sk`.
    #[inline]
    fn to<const D: usize, const M: usize>(
        &self,
        pt: &Point<D, M>,
        sk: &kinematics::Kinematics<D>,
        bl: &super::NodeBasis<D>,
    ) -> [[f64; D]; R] {
        if let Some(fc) = &self.finite {
            let (gs, gvs) = sk.spatial(bl);
            let scale = self.material * fc.c;
            return std::array::from_fn(|r| {
                std::array::from_fn(|d| {
                    let ds = if fc.s_varies { fc.s / D as f64 * (gvs[d] - gs[d]) } else { 0.0 };
                    let direct: f64 = (0..D).map(|b| fc.t[r][d][b] * bl.g[b]).sum();
                    scale * (fc.s * direct + fc.t_f[r] * ds)
                })
            });
        }
        let de = sk.deps_derivative(bl);
        let material_part =
            |r: usize, d: usize| self.material * (0..R).map(|q| self.d_alg[r][q] * de[q][d]).sum::<f64>();
        if D == 2 {
            let dt = sk.theta_derivative(bl);
            std::array::from_fn(|r| std::array::from_fn(|d| self.t_drot[r] * dt[d] + material_part(r, d)))
        } else {
            let dr = sk.rotated_derivative(bl, &pt.rotated);
            let rotation_part = |r: usize, d: usize| {
                if self.t_identity {
                    dr[r][d]
                } else {
                    (0..R).map(|q| self.t_mat[r][q] * dr[q][d]).sum()
                }
            };
            std::array::from_fn(|r| std::array::from_fn(|d| rotation_part(r, d) + material_part(r, d)))
        }
    }
}

/// The material, volume and geometric parts of [`tangent_in`]'s block, pair of nodes by pair.
#[inline(always)]
fn pairs_of_nodes<const D: usize, const M: usize, const R: usize>(block: &Block<'_, D, M>, out: &mut [f64]) {
    let Block { pt, v, material, nd, m } = *block;
    let s = &pt.upd.stress;
    let (dev, pm) = split::<D>(s);
    // A_l = ∂σ'/∂Δu_l (strain rows × D) for every node, through the strain's kinematics.
    let sk = pt.strain_kin();
    let response = StressResponse::<R>::of(pt, material);
    let mut a = [[[0.0; D]; R]; M];
    for (l, bl) in pt.strain.iter().enumerate().take(pt.basis.len()) {
        a[l] = response.to(pt, sk, bl);
    }
    let dev_tt = s[3] - pm;
    // A geometrically linear step has forces on x_n with V_n: no volume or geometric part.
    let linear = pt.kin.linear;
    let (motion_spatial, motion_hoop) = pt.motion_operators();
    for k in 0..pt.basis.len() {
        let (gk, gvk) = pt.spatial[k];
        let hk = pt.hoop[k];
        let bk = bbar(gk, gvk, hk);
        let mut tk = traction(&dev, pm, gk, gvk);
        tk[0] += hoop_force(s, pm, hk);
        for l in 0..pt.basis.len() {
            // The motion's derivatives with respect to Δu_l go through node l's basis.
            let (gl, gvl) = motion_spatial[l];
            let hl = motion_hoop[l];
            let dev_gl = dev_times(&dev, gl);
            // ∂J_v/∂Δu_l / J_v: the divergence and, radially, the hoop term.
            let mut djv = gvl;
            djv[0] += hl.1;
            for c in 0..D {
                for d in 0..D {
                    let material: f64 = (0..R).map(|r| bk[r][c] * a[l][r][d]).sum();
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
}

/// Column c of a three-dimensional node's B̄ ([`bbar`]) with gradients (g, gv): the volumetric
/// correction ⅓(gv_c − g_c), which every normal row (xx, yy, zz) holds, and the three other
/// entries as (strain row, value): g_c on c's own normal row and the gradients on the two shear
/// rows that hold c. The rest of the column is zero.
#[inline]
fn bbar_column<const D: usize>(g: [f64; D], gv: [f64; D], c: usize) -> (f64, [(usize, f64); 3]) {
    debug_assert_eq!(D, 3, "a three-dimensional node's B̄");
    // The normal row of each component, and each component's shear rows with the gradient
    // component they take (bbar's rows [xx, yy, γxy, zz, γyz, γzx]).
    const NORMAL: [usize; 3] = [0, 1, 3];
    const SHEAR: [[(usize, usize); 2]; 3] = [[(2, 1), (5, 2)], [(2, 0), (4, 2)], [(4, 1), (5, 0)]];
    let [(r1, d1), (r2, d2)] = SHEAR[c];
    ((gv[c] - g[c]) / 3.0, [(NORMAL[c], g[c]), (r1, g[d1]), (r2, g[d2])])
}

/// The material, volume and geometric parts of [`tangent_in`]'s block, row by row: each row of
/// the block is one pass over the columns of the nodes whose operators are not all zero. For
/// three-dimensional points, which have no hoop terms (the axisymmetric ones take
/// [`pairs_of_nodes`]). B̄'s structure ([`bbar_column`]) makes the material part of a row
/// corr_c Σ_normal A_r + three rows of A instead of six.
fn rows_of_nodes<const D: usize, const M: usize, const R: usize>(block: &Block<'_, D, M>, out: &mut [f64]) {
    let Block { pt, v, material, nd, m } = *block;
    let s = &pt.upd.stress;
    let (dev, pm) = split::<D>(s);
    let nb = pt.basis.len();
    let (motion_spatial, motion_hoop) = pt.motion_operators();
    // The nodes whose operators are not all zero: a node the particle's domain only touches has
    // zero rows and columns in this block, which are left out of it (they stay zero).
    let mut act = [0usize; M];
    let mut na = 0;
    for l in 0..nb {
        let (gl, gvl) = motion_spatial[l];
        let moves = gl.iter().chain(&gvl).any(|&v| v != 0.0) || motion_hoop[l] != (0.0, 0.0);
        if !pt.basis[l].is_zero() || !pt.strain[l].is_zero() || moves {
            act[na] = l;
            na += 1;
        }
    }
    let act = &act[..na];
    let n = na * D;
    // The scratch, as long as the columns of the nodes of `act` (not of the bound M: zeroing
    // arrays of 125 nodes cost more than a GIMP point's 8 to 27), flat over the block's columns
    // j = i D + d of the i-th node of `act`, so that a row of the block is one pass over j.
    let mut scratch = vec![0.0; (R + 2 * D + 5) * n];
    let (a, rest) = scratch.split_at_mut(R * n);
    let (a_normal, rest) = rest.split_at_mut(n);
    let (djv, rest) = rest.split_at_mut(n);
    let (dev_g, rest) = rest.split_at_mut(D * n);
    let (pm_gv, rest) = rest.split_at_mut(D * n);
    let (g_k, rest) = rest.split_at_mut(n);
    let (gv_k, row_values) = rest.split_at_mut(n);
    stress_columns::<D, M, R>(pt, material, act, a, a_normal);
    // A geometrically linear step has forces on x_n with V_n: no volume or geometric part.
    let linear = pt.kin.linear;
    // The motion's derivatives with respect to Δu_l go through node l's basis: ∂J_v/∂Δu_l / J_v,
    // and for each force component c the geometric part's V (dev σ' ∇'S_l)_c and
    // V σ'_m (∇̄'S_l)_c (from dev_g[c n] and pm_gv[c n]).
    if !linear {
        for (i, &l) in act.iter().enumerate() {
            let (gl, gvl) = motion_spatial[l];
            djv[i * D..i * D + D].copy_from_slice(&gvl);
            let dev_gl = dev_times(&dev, gl);
            for c in 0..D {
                dev_g[c * n + i * D..c * n + i * D + D].fill(v * dev_gl[c]);
                pm_gv[c * n + i * D..c * n + i * D + D].fill(v * pm * gvl[c]);
            }
        }
    }
    let a_rows: [&[f64]; R] = std::array::from_fn(|r| &a[r * n..(r + 1) * n]);
    let (a_normal, djv) = (&*a_normal, &*djv);
    // The columns of `act` are the block's own (in order, of D dofs each): a row is added to the
    // block as it is formed.
    let direct = na == nb && nd == D;
    for &k in act {
        let (gk, gvk) = pt.spatial[k];
        let tk = traction(&dev, pm, gk, gvk);
        // Node k's gradients repeated for every node of `act`.
        for i in 0..na {
            g_k[i * D..i * D + D].copy_from_slice(&gk);
            gv_k[i * D..i * D + D].copy_from_slice(&gvk);
        }
        let (g_k, gv_k) = (&*g_k, &*gv_k);
        for c in 0..D {
            let (corr, terms) = bbar_column(gk, gvk, c);
            let (cv, [(r0, c0), (r1, c1), (r2, c2)]) = (v * corr, terms.map(|(r, x)| (r, v * x)));
            let (a0, a1, a2) = (a_rows[r0], a_rows[r1], a_rows[r2]);
            let first = (k * nd + c) * m;
            let row = if direct { &mut out[first..first + n] } else { &mut row_values[..] };
            if !direct {
                row.fill(0.0);
            }
            if linear {
                for j in 0..n {
                    row[j] += cv * a_normal[j] + c0 * a0[j] + c1 * a1[j] + c2 * a2[j];
                }
            } else {
                let (dev_gc, pm_gvc) = (&dev_g[c * n..(c + 1) * n], &pm_gv[c * n..(c + 1) * n]);
                let vt = v * tk[c];
                for j in 0..n {
                    row[j] += cv * a_normal[j] + c0 * a0[j] + c1 * a1[j] + c2 * a2[j] + vt * djv[j]
                        - (dev_gc[j] * g_k[j] + pm_gvc[j] * gv_k[j]);
                }
            }
            if !direct {
                for (&l, values) in act.iter().zip(row_values.chunks_exact(D)) {
                    for (o, x) in out[first + l * nd..first + l * nd + D].iter_mut().zip(values) {
                        *o += x;
                    }
                }
            }
        }
    }
}

/// The stress response's columns of [`rows_of_nodes`]: A_l = ∂σ'/∂Δu_l (strain rows × D) of every
/// node l of `act`, through the strain's kinematics, stored by row (row r of every A_l side by
/// side from a[r n], n = D × the nodes of `act`), and the sum of its normal rows, which B̄'s
/// volumetric correction multiplies, into `a_normal`. A_l is linear in node l's strain operators
/// (∇S_l, ∇̄S_l; no hoop operators in three dimensions): the responses to unit gradients, formed
/// once for the point, combine into every node's.
fn stress_columns<const D: usize, const M: usize, const R: usize>(
    pt: &Point<D, M>,
    material: f64,
    act: &[usize],
    a: &mut [f64],
    a_normal: &mut [f64],
) {
    let (n, sk) = (act.len() * D, pt.strain_kin());
    let response = StressResponse::<R>::of(pt, material);
    let unit = |m: usize, volumetric: bool| {
        let mut b = super::NodeBasis::<D>::default();
        if volumetric {
            b.gv[m] = 1.0;
        } else {
            b.g[m] = 1.0;
        }
        response.to(pt, sk, &b)
    };
    let per_g: [[[f64; D]; R]; D] = std::array::from_fn(|m| unit(m, false));
    let per_gv: [[[f64; D]; R]; D] = std::array::from_fn(|m| unit(m, true));
    for (i, &l) in act.iter().enumerate() {
        let bl = &pt.strain[l];
        debug_assert!(bl.t == 0.0 && bl.tv == 0.0, "hoop operators at a three-dimensional point");
        let mut al = [[0.0; D]; R];
        for m in 0..D {
            let (g, gv) = (bl.g[m], bl.gv[m]);
            for r in 0..R {
                for d in 0..D {
                    al[r][d] += g * per_g[m][r][d] + gv * per_gv[m][r][d];
                }
            }
        }
        for (r, row) in al.iter().enumerate() {
            a[r * n + i * D..r * n + i * D + D].copy_from_slice(row);
        }
        for d in 0..D {
            a_normal[i * D + d] = al[0][d] + al[1][d] + al[3][d];
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
    fn shares<const D: usize, const M: usize>(pt: &Point<D, M>) -> (f64, f64) {
        let n = pt.part.porosity;
        if pt.layout.w.is_some() {
            (1.0 - n, n)
        } else {
            (1.0, 0.0)
        }
    }

    /// Adds the pressure forces (weight w_f).
    pub fn residual<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
        if pt.layout.p.is_none() && pt.p == 0.0 {
            return;
        }
        let nd = pt.layout.nd;
        let (fs, fw) = shares(pt);
        let pv = pt.p * pt.volume_new() * nm.w_force;
        for k in 0..pt.basis.len() {
            let (g, tv) = (pt.spatial[k].1, pt.hoop[k].1);
            // The divergence operator on x_{n+1}: ∇̄'S and, radially, the hoop term T̄'.
            let mut gv = g;
            gv[0] += tv;
            for c in 0..D {
                out[k * nd + c] -= fs * pv * gv[c];
                if let Some(w) = pt.layout.w {
                    out[k * nd + w + c] -= fw * pv * gv[c];
                }
            }
        }
    }

    /// Adds the u–p and U–p couplings (−G₁, −G₂ on x_{n+1}) and their geometric u–u and U–u parts.
    pub fn tangent<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
        if pt.layout.p.is_none() && pt.p == 0.0 {
            return;
        }
        let (nd, m) = (pt.layout.nd, pt.size());
        let (motion_spatial, motion_hoop) = pt.motion_operators();
        let (fs, fw) = shares(pt);
        let v = pt.volume_new() * nm.w_force;
        for k in 0..pt.basis.len() {
            let (gvk, tk) = (pt.spatial[k].1, pt.hoop[k].1);
            let mut divk = gvk;
            divk[0] += tk;
            for (l, bl) in pt.basis.iter().enumerate() {
                let (gvl, tl) = (motion_spatial[l].1, motion_hoop[l].1);
                for c in 0..D {
                    let ru = (k * nd + c) * m;
                    if let Some(p) = pt.layout.p {
                        out[ru + l * nd + p] -= fs * v * divk[c] * bl.s;
                    }
                    for d in 0..D {
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
