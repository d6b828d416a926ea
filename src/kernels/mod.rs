//! Per-particle kernels: pure functions from one material point and the nodal values of its
//! stencil to a small dense residual block and tangent block. Nothing here knows about PETSc,
//! ranks, global numbering or constraints.
//!
//! # The discrete system ([003] Eqs. 10, 16, 22, 23; [000] Eqs. 6–10, Appendix A)
//!
//! Unknowns of a time step are the nodal increments Δd = (Δu, Δp, ΔU) (the grid is reset every step,
//! d_n = 0). Newmark ([003] Eqs. 20–21) gives the acceleration and velocity at t_{n+1} at a material
//! point as
//!   a = a₀ Σ S_i Δd_i + ã_n,  v = a₁ Σ S_i Δd_i + ṽ_n,   a₀ = 1/(βΔt²), a₁ = γ/(βΔt),
//! with predictors ã_n = −v_n/(βΔt) − (1/(2β) − 1) a_n and ṽ_n = −(γ/β − 1) v_n − (γ/(2β) − 1)Δt a_n
//! of the nodal v_n, a_n of [003] Eq. 19, interpolated to the point (the caller passes them as
//! a [`Motion`], [`Motion::predicted`]).
//!
//! The residual of a particle is a sum of terms, each in its own module with its exact tangent and
//! its own finite-difference test:
//!
//! | term | rows | residual at stencil node i |
//! |---|---|---|
//! | [`inertia`] | u, U | S_i m_s (a_u − b), S_i m_w (a_U − b) ([003] 16a, b) |
//! | [`inertia::drag`] | u, U | ±S_i c (v_u − v_U), c = n²γ_w V/k ([003] 16c–e) |
//! | [`stress`] | u | B̄'_iᵀ σ'_{n+1} V_{n+1} ([003] 23a on x_{n+1}) |
//! | [`stress::pore_pressure`] | u, U | −(1 − n) p ∇̄'S_i V_{n+1}, −n p ∇̄'S_i V_{n+1} ([003] 23a, c) |
//! | [`flow::porosity_gradient`] | u, U, p | ±S_i p ∇n V, −S_i ∇n·(ΔU − Δu) V |
//! | [`flow::continuity`] | p | −S_i [(1 − n) ∇̄·Δu + n ∇̄·ΔU + Δp/Q] V ([003] 23b) |
//! | [`flow::darcy`] | p | −Δt V (k/γ_w) ∇S_i·(∇p_θ − ρ_w b) (u–p with flow) |
//! | [`flow::drained_face`] | p | Nitsche's terms of p = 0 on the particle's drained faces (u–p with flow) |
//! | [`fbar`] | Jbar | κ S_i V_n (ϑ_i − (J_n ΔJ − 1)), [002]'s projection of J (implicit F̄ steps) |
//!
//! with m_s = (1 − n)ρ_s V (the mixture's mass in one-phase runs), m_w = nρ_w V, p = p_n + Σ S_j Δp_j,
//! σ' the effective stress after the soil model's objective update (see [`kinematics`]) and ∇̄'
//! the B̄ gradients on the current configuration. Eq. 23b is written for the step's increments (the
//! grid is reset every step), which makes the continuity rows zero at Δd = 0 and linear in Δd.
//!
//! [003] writes these equations for a uniform porosity. When the porosity varies (large strain,
//! several materials), the exact balances differ from them by three terms, which vanish for uniform
//! n: the water is pushed by −n∇p, not −∇(np), so it gets +p∇n and the skeleton its reaction −p∇n;
//! and the continuity equation ∇·u̇ + ∇·(n(U̇ − u̇)) + ṗ/Q = 0 has ∇n·(U̇ − u̇) besides the divergences
//! ([`flow::porosity_gradient`]). Without them a large-strain column settles by about its strain too
//! much (11 % at m_v q = 0.1).
//!
//! The tangent is the exact derivative of the residual: with small strains and without rotation it
//! is K̄ = a₀M + a₁C + K of [003] Eq. 22 with −G₁, −G₂ off the diagonal and −P (not the +P printed in
//! [003] Eq. 10) in the p–p block; the current configuration and the objective update add the
//! geometric and rotational terms of [`stress`]. It is not symmetric in general.
//!
//! # B̄
//! Each node carries the gradient ∇S_i used for the deviatoric part of B and a gradient ∇̄S_i for the
//! volumetric part ([000] Eqs. 12–16). Without B̄ the two are equal and B̄ reduces to B. With an
//! implicit F̄ instead, the stress's volumetric strain comes from the projected J̄ at the nodes
//! ([`fbar`], [`kinematics::Kinematics::with_projected_volume`]).

pub mod cell;
pub mod control;
pub mod fbar;
pub mod flow;
pub mod inertia;
pub mod input;
pub mod kinematics;
pub mod lowered;
pub mod stress;

use crate::layout::{Layout, MAX_DOF, MAX_DOF_3D};
use crate::model::shape::Stencil;
use crate::scheme::Scheme;
use crate::soils::finite_strain;
use crate::soils::{self, Constitutive, Stress, StressUpdate};
pub use input::ParticleInput;
pub use kinematics::Kinematics;

/// Largest number of stencil nodes of a particle in two dimensions (see
/// [`crate::model::shape::MAX_STENCIL`]): the size of a plane point's per-node scratch.
pub const MAX_NODES: usize = crate::model::shape::MAX_STENCIL;
/// Largest number of stencil nodes of a particle in three dimensions (see
/// [`crate::model::shape::MAX_STENCIL_3D`]).
pub const MAX_NODES_3D: usize = crate::model::shape::MAX_STENCIL_3D;
/// Largest local block dimension of a plane point.
pub const MAX_LOCAL: usize = MAX_NODES * MAX_DOF;

/// The number of strain (and stress) components a point of dimension `D` uses: the first four of
/// [`soils::Stress`] in two dimensions (plane strain or axial symmetry, the fourth the
/// out-of-plane or hoop component), all six in three.
#[inline]
pub const fn strain_rows<const D: usize>() -> usize {
    if D == 2 {
        soils::NS_PLANE
    } else {
        soils::NS
    }
}

/// Basis values of one stencil node for one particle (two-dimensional unless `D` says otherwise).
#[derive(Debug, Clone, Copy)]
pub struct NodeBasis<const D: usize = 2> {
    /// S_i.
    pub s: f64,
    /// ∇S_i (deviatoric part of B̄), on x_n.
    pub g: [f64; D],
    /// ∇̄S_i (volumetric part of B̄; equals `g` without B̄), on x_n.
    pub gv: [f64; D],
    /// The hoop operator T_i of an axisymmetric analysis (ε_θθ = Σ T_i u_r,i; S_i/r_p for the
    /// planar weights), on x_n; zero in plane strain.
    pub t: f64,
    /// The hoop operator of B̄'s volumetric part (equals `t` without B̄).
    pub tv: f64,
}

impl<const D: usize> Default for NodeBasis<D> {
    fn default() -> Self {
        NodeBasis { s: 0.0, g: [0.0; D], gv: [0.0; D], t: 0.0, tv: 0.0 }
    }
}

impl<const D: usize> NodeBasis<D> {
    /// Whether every operator is zero: a stencil node that the particle's domain only touches.
    #[inline]
    pub fn is_zero(&self) -> bool {
        self.s == 0.0 && self.t == 0.0 && self.tv == 0.0 && self.g.iter().chain(&self.gv).all(|&v| v == 0.0)
    }

    /// Adds `factor` times every operator of `other` (value, gradients, hoop operators).
    pub fn add_scaled(&mut self, other: &NodeBasis<D>, factor: f64) {
        self.s += factor * other.s;
        self.t += factor * other.t;
        self.tv += factor * other.tv;
        for d in 0..D {
            self.g[d] += factor * other.g[d];
            self.gv[d] += factor * other.gv[d];
        }
    }
}

/// The basis of a whole stencil without B̄, with the hoop operators `hoop` (zero in plane
/// strain), appended to `out`.
pub fn plain_basis<const D: usize, const M: usize>(st: &Stencil<D, M>, hoop: &[f64], out: &mut Vec<NodeBasis<D>>) {
    out.extend((0..st.len).map(|k| NodeBasis { s: st.w[k], g: st.dw[k], gv: st.dw[k], t: hoop[k], tv: hoop[k] }));
}

/// Nodal values seen by a particle: the increment Δd and its parts a₀Δd, a₁Δd of the acceleration
/// and velocity at t_{n+1} (the particle adds its predictors).
///
/// `N` is the number of dofs it holds, at least the layout's: [`MAX_DOF`] in two dimensions,
/// [`MAX_DOF_3D`] in three (a plane point's states are copied per point, so they are not sized
/// for the largest three-dimensional layout).
#[derive(Debug, Clone, Copy)]
pub struct NodeState<const N: usize = MAX_DOF> {
    /// Δd in the node's layout.
    pub d: [f64; N],
    /// a₀ Δd.
    pub a: [f64; N],
    /// a₁ Δd.
    pub v: [f64; N],
}

/// The nodal states of a step's start (Δd = 0) for the largest stencil of any dimension, shared
/// so that an explicit step's points do not build a zero array each ([`Point::at_start`]).
static AT_REST: [NodeState<MAX_DOF_3D>; MAX_NODES_3D] =
    [NodeState { d: [0.0; MAX_DOF_3D], a: [0.0; MAX_DOF_3D], v: [0.0; MAX_DOF_3D] }; MAX_NODES_3D];

impl<const N: usize> Default for NodeState<N> {
    fn default() -> Self {
        NodeState { d: [0.0; N], a: [0.0; N], v: [0.0; N] }
    }
}

impl<const N: usize> NodeState<N> {
    /// The state of a node with increments `d` under the time scheme `nm`.
    pub fn new(d: &[f64], nm: &Scheme) -> NodeState<N> {
        let mut s = NodeState::default();
        for (c, &x) in d.iter().enumerate() {
            s.set(c, x, nm);
        }
        s
    }

    /// Sets component `c` to the increment `x` under the time scheme `nm` (with its a₀x and a₁x).
    #[inline]
    pub fn set(&mut self, c: usize, x: f64, nm: &Scheme) {
        (self.d[c], self.a[c], self.v[c]) = (x, nm.a0 * x, nm.a1 * x);
    }
}

/// The accelerations and velocities of the solid and the water at a material point: its Newmark
/// predictors (those at t_{n+1} for a zero displacement increment, [`Motion::predicted`]), or its
/// motion at t_{n+1} ([`Interp::motion`]).
#[derive(Debug, Clone, Copy)]
pub struct Motion<const D: usize = 2> {
    /// Acceleration of the solid [m/s²].
    pub a_u: [f64; D],
    /// Velocity of the solid [m/s].
    pub v_u: [f64; D],
    /// Acceleration of the water [m/s²] (two-phase).
    pub a_w: [f64; D],
    /// Velocity of the water [m/s] (two-phase).
    pub v_w: [f64; D],
}

impl<const D: usize> Default for Motion<D> {
    fn default() -> Self {
        Motion { a_u: [0.0; D], v_u: [0.0; D], a_w: [0.0; D], v_w: [0.0; D] }
    }
}

impl<const D: usize> Motion<D> {
    /// The predictors ã_n, ṽ_n for solid (`v_u`, `a_u`) and water (`v_w`, `a_w`) velocities and
    /// accelerations at t_n (the nodal values interpolated to the point).
    pub fn predicted(nm: &Scheme, v_u: [f64; D], a_u: [f64; D], v_w: [f64; D], a_w: [f64; D]) -> Motion<D> {
        let (pa_u, pv_u) = nm.predict(v_u, a_u);
        let (pa_w, pv_w) = nm.predict(v_w, a_w);
        Motion { a_u: pa_u, v_u: pv_u, a_w: pa_w, v_w: pv_w }
    }
}

/// B̄ of one node from its deviatoric gradient `g` and volumetric gradient `gv` and, in axial
/// symmetry, its hoop operators `hoop` = (T, T̄) (zero in plane strain and in three dimensions):
/// the strain rows [xx, yy, γxy, zz, γyz, γzx] × D displacement components ([000] Eq. 16):
/// B̄ = B − ⅓ m mᵀB + ⅓ m mᵀB̄_v with m = [1, 1, 0, 1, 0, 0]. In two dimensions the rows are
/// [rr, yy, ry, θθ] (the last two zero), the hoop row of B being [T, 0]
/// (docs/axisymmetry.md); in three the zz row of B is [0, 0, ∂_z S] and the shear
/// rows [0, ∂_z S, ∂_y S] and [∂_z S, 0, ∂_x S].
#[inline]
pub fn bbar<const D: usize>(g: [f64; D], gv: [f64; D], hoop: (f64, f64)) -> [[f64; D]; soils::NS] {
    let mut out = [[0.0; D]; soils::NS];
    let (tt, tv) = hoop;
    let t = 1.0 / 3.0;
    // ⅓(mᵀB̄_v − mᵀB): the volumetric correction of every normal row (the hoop term radially).
    let corr: [f64; D] =
        std::array::from_fn(|d| if d == 0 { t * (gv[0] + tv - g[0] - tt) } else { t * (gv[d] - g[d]) });
    out[0] = corr;
    out[0][0] += g[0];
    out[1] = corr;
    out[1][1] += g[1];
    out[2][0] = g[1];
    out[2][1] = g[0];
    out[3] = corr;
    if D == 2 {
        out[3][0] += tt;
    } else {
        out[3][2] += g[2];
        out[4][1] = g[2];
        out[4][2] = g[1];
        out[5][0] = g[2];
        out[5][2] = g[0];
    }
    out
}

/// Values interpolated to a particle from the nodal increments, with its Newmark predictors.
#[derive(Debug, Clone, Copy)]
pub struct Interp<const D: usize = 2> {
    /// Solid displacement increment Σ S Δu.
    pub du: [f64; D],
    /// Water displacement increment Σ S ΔU.
    pub dw: [f64; D],
    /// Pressure increment Σ S Δp.
    pub dp: f64,
    /// Volumetric strain increment of the solid on x_n, ∇̄·Δu = Σ ∇̄S·Δu (+ Σ T̄ Δu_r in axial
    /// symmetry).
    pub dvol_u: f64,
    /// Volumetric strain increment of the water on x_n, ∇̄·ΔU.
    pub dvol_w: f64,
    /// Gradient of the pressure increment on x_n, Σ ∇S Δp.
    pub grad_dp: [f64; D],
    /// The projected volume ratio's excess at t_{n+1}, J̄_{n+1} − 1 = Σ S ϑ (implicit F̄ steps).
    pub jbar: f64,
    /// The accelerations and velocities at t_{n+1}.
    pub motion: Motion<D>,
}

impl<const D: usize> Default for Interp<D> {
    fn default() -> Self {
        let z = [0.0; D];
        Interp { du: z, dw: z, dp: 0.0, dvol_u: 0.0, dvol_w: 0.0, grad_dp: z, jbar: 0.0, motion: Motion::default() }
    }
}

/// Interpolates nodal values to the particle and adds its Newmark predictors.
pub fn interpolate<const D: usize, const N: usize>(
    basis: &[NodeBasis<D>],
    states: &[NodeState<N>],
    pred: &Motion<D>,
    layout: Layout,
) -> Interp<D> {
    let mut k = Interp::default();
    k.motion.a_u = pred.a_u;
    k.motion.v_u = pred.v_u;
    if layout.w.is_some() {
        k.motion.a_w = pred.a_w;
        k.motion.v_w = pred.v_w;
    }
    for (b, st) in basis.iter().zip(states) {
        k.dvol_u += b.tv * st.d[0];
        for c in 0..D {
            k.motion.a_u[c] += b.s * st.a[c];
            k.motion.v_u[c] += b.s * st.v[c];
            k.du[c] += b.s * st.d[c];
            k.dvol_u += b.gv[c] * st.d[c];
        }
        if let Some(p) = layout.p {
            k.dp += b.s * st.d[p];
            for c in 0..D {
                k.grad_dp[c] += b.g[c] * st.d[p];
            }
        }
        if let Some(j) = layout.jbar {
            k.jbar += b.s * st.d[j];
        }
        if let Some(w) = layout.w {
            k.dvol_w += b.tv * st.d[w];
            for c in 0..D {
                k.dvol_w += b.gv[c] * st.d[w + c];
                k.motion.a_w[c] += b.s * st.a[w + c];
                k.motion.v_w[c] += b.s * st.v[w + c];
                k.dw[c] += b.s * st.d[w + c];
            }
        }
    }
    k
}

/// Everything the terms need at one particle for the current iterate: the interpolated values, the
/// kinematics, the gradients on x_{n+1} and the soil model's update from the rotated stress.
///
/// `D` is the dimension (two: plane strain or axial symmetry; three) and `M` the number of nodes
/// its per-node scratch holds, at least the stencil's ([`MAX_NODES`] in two dimensions,
/// [`MAX_NODES_3D`] in three), so that a plane point does not carry the scratch of the largest
/// three-dimensional stencil.
#[derive(Debug, Clone)]
pub struct Point<'a, const D: usize = 2, const M: usize = MAX_NODES> {
    /// The soil model the stress was updated by (`None` at a step's start, [`Point::at_start`]).
    pub model: Option<Constitutive>,
    /// The stencil's basis on x_n.
    pub basis: &'a [NodeBasis<D>],
    /// The particle at t_n.
    pub part: &'a ParticleInput<D>,
    /// Which dofs the nodes carry.
    pub layout: Layout,
    /// Interpolated increments, velocities and accelerations.
    pub interp: Interp<D>,
    /// Finite-strain kinematics of the step's motion, from the basis: F, J, the volume ratio, the
    /// gradients on x_{n+1} and the deformation the particle keeps.
    pub kin: Kinematics<D>,
    /// The kinematics of the recovered strain (see [`Point::with_recovery`]) where the strain
    /// operators are not the basis (`None`: `kin`'s; [`Point::strain_kin`]).
    recovered_kin: Option<Kinematics<D>>,
    /// The effective stress at t_n rotated with the material (Hughes–Winget), by the strain's
    /// rotation.
    pub rotated: Stress,
    /// The soil model's update from `rotated` by the strain increment.
    pub upd: StressUpdate,
    /// Gradients ∇'S and ∇̄'S of each stencil node on x_{n+1}, the operators the forces are
    /// integrated with: the basis's own, or [001]'s double-mapped ones ([`Point::with_forces`]).
    pub spatial: Vec<Gradients<D>>,
    /// Hoop operators T' and T̄' of each stencil node on x_{n+1} (zero in plane strain and in three
    /// dimensions), the forces' like [`Point::spatial`].
    pub hoop: Vec<(f64, f64)>,
    /// The operators the strain is recovered with (see [`Point::with_recovery`]): the basis
    /// itself, or [001]'s CMPM patch functions; the strain increment, the rotation and the soil
    /// model's update use these (through [`Point::strain_kin`]), the motion and the forces the
    /// basis.
    pub strain: &'a [NodeBasis<D>],
    /// `spatial` and `hoop` of the basis where they are not the force operators (see
    /// [`Point::motion_operators`]; `None`: the same, not copied).
    motion: Option<Box<OnNew<D>>>,
    /// Pore pressure at t_{n+1}, p_n + Σ S Δp.
    pub p: f64,
    /// The particle's faces on a drained surface imposed weakly ([`flow::drained_face`]; most
    /// particles have none).
    pub faces: &'a [DrainedFace<D, M>],
    /// Σ N_j(x_f) Δp_j at each of `faces`.
    pub face_dp: [f64; MAX_FACES],
    /// The nodal ϑ_i = J̄_i − 1 of an implicit F̄ step, per stencil node (zero otherwise).
    pub jbar_nodes: Vec<f64>,
}

/// The per-node arrays of a point ([`Point::spatial`], [`Point::hoop`], [`Point::jbar_nodes`]), as
/// long as its stencil. A loop that forms many points hands them from one point to the next
/// ([`Point::with_recovery_in`], [`Point::into_buffers`]): neither allocated per point nor of the
/// bound M, whose zeroing and moving cost more than a stencil of 8 to 27 nodes.
#[derive(Debug, Clone, Default)]
pub struct PointBuffers<const D: usize> {
    spatial: Vec<Gradients<D>>,
    hoop: Vec<(f64, f64)>,
    jbar_nodes: Vec<f64>,
}

/// A node's gradients (∇'S, ∇̄'S) on x_{n+1}.
pub type Gradients<const D: usize> = ([f64; D], [f64; D]);

/// The per-node gradients and hoop operators of a point on x_{n+1} ([`Point::spatial`] and
/// [`Point::hoop`], or their strain operators').
type OnNew<const D: usize> = (Vec<Gradients<D>>, Vec<(f64, f64)>);

/// Writes the gradients and hoop operators on x_{n+1} under the step's kinematics `kin` of each
/// node of `nodes` into the first entries of `spatial` and `hoop` ([`Point::spatial`] and
/// [`Point::hoop`], or the strain operators'), in place.
fn on_new_configuration<const D: usize>(
    kin: &Kinematics<D>,
    nodes: &[NodeBasis<D>],
    spatial: &mut [Gradients<D>],
    hoop: &mut [(f64, f64)],
) {
    assert!(nodes.len() <= spatial.len(), "a stencil of {} nodes in a point of {}", nodes.len(), spatial.len());
    for ((s, t), b) in spatial.iter_mut().zip(hoop.iter_mut()).zip(nodes) {
        *s = kin.spatial(b);
        *t = kin.hoop(b);
    }
}

/// What a finite-strain model's stress sees of a step ([`soils::SoilLaw::finite`]), as 3 × 3
/// matrices (a plane point's with F_zz = 1): the step's ΔF̄ = c F̄ with F̄ the kinematics `sk`'s
/// (B̄'s volume-scaled [`Kinematics::f_bar`]) and c the explicit F̄ projection's scale of the step,
/// and the total F_{n+1} = s F̄ F_n with s that of the point's total deformation (c = s = 1
/// without F̄).
fn finite_gradients<const D: usize>(
    sk: &Kinematics<D>,
    part: &ParticleInput<D>,
) -> (finite_strain::M3, finite_strain::M3) {
    let f_bar = sk.f_bar();
    let df = f_bar.map(|r| r.map(|v| v * part.fbar));
    let f_new = crate::algebra::product(&f_bar, &part.def_grad).map(|r| r.map(|v| v * part.fbar_total));
    (finite_strain::embed(&df), finite_strain::embed(&f_new))
}

/// Largest number of drained faces of one particle (all sides of its domain: four in two
/// dimensions, six in three).
pub const MAX_FACES: usize = 6;

/// One exposed face of a particle on a drained surface imposed weakly (see
/// [`flow::drained_face`]), on x_n.
#[derive(Debug, Clone, Copy)]
pub struct DrainedFace<const D: usize = 2, const M: usize = MAX_NODES> {
    /// The face point minus the particle's centre, x_f − x_p [m].
    pub offset: [f64; D],
    /// The outward unit normal.
    pub normal: [f64; D],
    /// The face's area (its length, the area per unit thickness, in two dimensions) [m²].
    pub area: f64,
    /// Nitsche's penalty γ/h [1/m].
    pub penalty: f64,
    /// The grid's multilinear shape function N_i and its gradient at the face point, per stencil
    /// slot (in the order of the particle's basis).
    pub basis: [(f64, [f64; D]); M],
}

impl<'a, const D: usize, const M: usize> Point<'a, D, M> {
    /// Evaluates the point for the nodal `states` (same order as `basis`), with the strain
    /// recovered by the operators `strain` (one per node of `basis`, in its order; its `g`, `gv`,
    /// `t`, `tv` are used, its `s` is not): the stress sees
    /// the deformation gradient F̃ = I + Σ Δu_i ⊗ e_i, e_i = `strain[i].g`, so the strain
    /// increment the soil model takes and the rotation of the stress are the recovered ones; the
    /// motion keeps the basis: the step's F, its volume ratio, the gradients on x_{n+1}, the
    /// deformation and volume the particle keeps, and the forces f_i = B̄'_iᵀσ V. This is [001]'s
    /// reading (docs/stiffness.md: the strain is recovered for the stress only; positions, F and
    /// volume as without it). [001]'s CMPM recovery (`stabilisation.stress_recovery = "cmpm"`)
    /// passes its patch functions; `strain = basis` is the usual point.
    pub fn with_recovery<const N: usize>(
        basis: &'a [NodeBasis<D>],
        strain: &'a [NodeBasis<D>],
        states: &[NodeState<N>],
        part: &'a ParticleInput<D>,
        model: &Constitutive,
        layout: Layout,
    ) -> Point<'a, D, M> {
        Point::with_recovery_in(PointBuffers::default(), basis, strain, states, part, model, layout)
    }

    /// [`Point::with_recovery`] with its per-node arrays in `buffers` (their earlier contents are
    /// overwritten; [`Point::into_buffers`] hands them back).
    #[inline]
    pub fn with_recovery_in<const N: usize>(
        buffers: PointBuffers<D>,
        basis: &'a [NodeBasis<D>],
        strain: &'a [NodeBasis<D>],
        states: &[NodeState<N>],
        part: &'a ParticleInput<D>,
        model: &Constitutive,
        layout: Layout,
    ) -> Point<'a, D, M> {
        debug_assert_eq!(layout.dim, D, "a layout of {} dimensions at a point of {D}", layout.dim);
        let interp = interpolate(basis, states, &part.pred, layout);
        let kinematics_of = |ops: &[NodeBasis<D>]| {
            Kinematics::new(ops, states.iter().map(|s| std::array::from_fn(|c| s.d[c])), part.linear)
                .with_volume_scale(part.fbar)
        };
        let mut kin = kinematics_of(basis);
        // (Cases combine neither F̄ nor B̄ with a recovered strain, validation; its kinematics take
        // F̄'s scale and projection all the same, so that every term is defined for any operators.)
        let mut recovered_kin = (!std::ptr::eq(strain, basis)).then(|| kinematics_of(strain));
        // An implicit F̄ step: the stress sees the projected volume ratio J̄_{n+1}/J̄_n.
        if layout.jbar.is_some() {
            // r − 1 = (1 + Σ S ϑ − J̄_n)/J̄_n, without the cancellation of forming r first.
            let r_minus_one = (interp.jbar - (part.jbar - 1.0)) / part.jbar;
            kin = kin.with_projected_volume(r_minus_one);
            recovered_kin = recovered_kin.map(|k| k.with_projected_volume(r_minus_one));
        }
        let sk = recovered_kin.as_ref().unwrap_or(&kin);
        let rotated = sk.rotate(&part.stress);
        // A finite-strain model takes the step's ΔF̄ = c ΔF and the total deformation
        // F̄_{n+1} = s ΔF F_n (c and s the F̄ scales, 1 without); the others the objective increment.
        let (df, f_new) = finite_gradients(sk, part);
        let upd = model
            .finite(&df, &f_new, &part.stress, part.eps_pd, part.dt)
            .unwrap_or_else(|| model.update(&rotated, part.eps_pd, &sk.deps));
        let mut pt =
            Point::of_parts(buffers, basis, strain, part, layout, interp, (kin, recovered_kin), (rotated, upd));
        pt.model = Some(*model);
        if let Some(j) = layout.jbar {
            for (t, st) in pt.jbar_nodes.iter_mut().zip(states) {
                *t = st.d[j];
            }
        }
        pt
    }

    /// The point at its step's start (Δd = 0) with the stress it carries, σ_n on x_n, as an
    /// explicit step's forces take it (update-stress-last, [002] Algorithm 1): no soil-model call
    /// (the stored stress is the one the last step's update left, the viscous part of a fluid's
    /// included, which a model evaluated again at a zero increment would drop) and no tangent (an
    /// explicit step builds no matrix). The interpolated velocities and accelerations are the
    /// point's predictors, as at Δd = 0.
    pub fn at_start(
        basis: &'a [NodeBasis<D>],
        strain: &'a [NodeBasis<D>],
        part: &'a ParticleInput<D>,
        layout: Layout,
    ) -> Point<'a, D, M> {
        Point::at_start_in(PointBuffers::default(), basis, strain, part, layout)
    }

    /// [`Point::at_start`] with its per-node arrays in `buffers` (see [`Point::with_recovery_in`]).
    pub fn at_start_in(
        buffers: PointBuffers<D>,
        basis: &'a [NodeBasis<D>],
        strain: &'a [NodeBasis<D>],
        part: &'a ParticleInput<D>,
        layout: Layout,
    ) -> Point<'a, D, M> {
        let interp = interpolate(basis, &AT_REST[..basis.len()], &part.pred, layout);
        let zero = [[0.0; soils::NS]; soils::NS];
        let upd = StressUpdate {
            stress: part.stress,
            tangent: zero,
            trial_tangent: zero,
            eps_pd: part.eps_pd,
            region: crate::soils::Region::Elastic,
        };
        let kin = (Kinematics::rest(), None);
        Point::of_parts(buffers, basis, strain, part, layout, interp, kin, (part.stress, upd))
    }

    /// The point's per-node arrays, for the next point ([`Point::with_recovery_in`]).
    pub fn into_buffers(self) -> PointBuffers<D> {
        PointBuffers { spatial: self.spatial, hoop: self.hoop, jbar_nodes: self.jbar_nodes }
    }

    /// The point of its parts: the kinematics (and the recovered strain's, if any), the rotated
    /// stress σ_n and the soil model's update; the gradients on the new configuration follow
    /// from the kinematics (into `buffers`, whose ϑ_i are zeroed), and the pore pressure is p_n + Δp.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn of_parts(
        buffers: PointBuffers<D>,
        basis: &'a [NodeBasis<D>],
        strain: &'a [NodeBasis<D>],
        part: &'a ParticleInput<D>,
        layout: Layout,
        interp: Interp<D>,
        (kin, recovered_kin): (Kinematics<D>, Option<Kinematics<D>>),
        (rotated, upd): (Stress, StressUpdate),
    ) -> Point<'a, D, M> {
        let PointBuffers { mut spatial, mut hoop, mut jbar_nodes } = buffers;
        spatial.clear();
        spatial.resize(basis.len(), ([0.0; D], [0.0; D]));
        hoop.clear();
        hoop.resize(basis.len(), (0.0, 0.0));
        jbar_nodes.clear();
        jbar_nodes.resize(basis.len(), 0.0);
        let mut pt = Point {
            model: None,
            basis,
            part,
            layout,
            interp,
            kin,
            recovered_kin,
            rotated,
            upd,
            spatial,
            hoop,
            strain,
            motion: None,
            p: part.p + interp.dp,
            faces: &[],
            face_dp: [0.0; MAX_FACES],
            jbar_nodes,
        };
        on_new_configuration(&pt.kin, basis, &mut pt.spatial, &mut pt.hoop);
        pt
    }

    /// The point with its drained `faces` (at most [`MAX_FACES`]), their pressure increments
    /// interpolated from the same nodal `states`.
    #[inline]
    pub fn with_faces<const N: usize>(mut self, faces: &'a [DrainedFace<D, M>], states: &[NodeState<N>]) -> Self {
        self.set_faces(faces, states);
        self
    }

    /// [`Point::with_faces`] in place (a point is a few kilobytes: the assembly loops build it
    /// once and set what it needs, rather than move it through each builder call).
    #[inline]
    pub fn set_faces<const N: usize>(&mut self, faces: &'a [DrainedFace<D, M>], states: &[NodeState<N>]) {
        let Some(p) = self.layout.p else { return };
        let faces = &faces[..faces.len().min(MAX_FACES)];
        for (dp, face) in self.face_dp.iter_mut().zip(faces) {
            *dp = face.basis.iter().zip(states.iter().take(self.basis.len())).map(|((s, _), st)| s * st.d[p]).sum();
        }
        self.faces = faces;
    }

    /// The point with its forces integrated by the operators `forces` (one per node of its basis,
    /// in its order; their `g`, `gv`, `t`, `tv` per unit volume of the point on x_n; empty: the
    /// basis's own, unchanged): [001]'s double-mapped internal force
    /// (`stabilisation.internal_force = "mapped"`, [`super::cell::mapped_force_operators`]). They
    /// take the step's kinematics as the basis does (pushed forward by F⁻ᵀ, the volume by J), so the
    /// residual's terms and their tangent need no change; the strain and the motion keep their
    /// own operators. One-phase only (validation): every term that integrates with
    /// [`Point::spatial`] takes them.
    #[inline]
    pub fn with_forces(mut self, forces: &[NodeBasis<D>]) -> Self {
        self.set_forces(forces);
        self
    }

    /// [`Point::with_forces`] in place (see [`Point::set_faces`]).
    #[inline]
    pub fn set_forces(&mut self, forces: &[NodeBasis<D>]) {
        if forces.is_empty() {
            return;
        }
        debug_assert_eq!(forces.len(), self.basis.len(), "force operators for another stencil");
        if self.motion.is_none() {
            // The basis's operators on x_{n+1}, held in `spatial` and `hoop` until now.
            self.motion = Some(Box::new((self.spatial.clone(), self.hoop.clone())));
        }
        on_new_configuration(&self.kin, forces, &mut self.spatial, &mut self.hoop);
    }

    /// The gradients ∇'S, ∇̄'S and hoop operators T', T̄' on x_{n+1} of the basis, per node: the
    /// operators the step's F and volume ratio are built with, so every derivative of the motion
    /// (of J_v, of the gradients on x_{n+1}) with respect to Δu_l goes through node l's. They are
    /// [`Point::spatial`] and [`Point::hoop`] unless the forces take other operators
    /// ([`Point::with_forces`]).
    #[inline]
    pub fn motion_operators(&self) -> (&[Gradients<D>], &[(f64, f64)]) {
        match &self.motion {
            Some(m) => (&m.0, &m.1),
            None => (&self.spatial, &self.hoop),
        }
    }

    /// The consistent tangent ∂σ'/∂ΔF̄ of a finite-strain model's stress at this point
    /// ([`soils::SoilLaw::finite_tangent`]; `None` for the incremental models).
    pub fn finite_tangent(&self) -> Option<finite_strain::FiniteTangent> {
        let model = self.model.filter(Constitutive::is_finite_strain)?;
        let (df, f_new) = finite_gradients(self.strain_kin(), self.part);
        model.finite_tangent(&df, &f_new, &self.part.stress, self.part.eps_pd, self.part.dt)
    }

    /// The kinematics the stress sees: the recovered strain's ([`Point::with_recovery`]) or the
    /// motion's ([`Point::kin`]). Its strain increment, rotation and their derivatives (taken
    /// with the operators [`Point::strain`]) are the soil model's.
    #[inline]
    pub fn strain_kin(&self) -> &Kinematics<D> {
        self.recovered_kin.as_ref().unwrap_or(&self.kin)
    }

    /// Number of local dofs (stencil nodes × dofs per node).
    pub fn size(&self) -> usize {
        self.basis.len() * self.layout.nd
    }

    /// The volume the forces integrate over: V_{n+1} = J_v V_n, or V_n in a geometrically linear
    /// step (the particle still takes V_{n+1} when it is updated).
    pub fn volume_new(&self) -> f64 {
        if self.kin.linear {
            self.part.volume
        } else {
            self.part.volume * self.kin.jv
        }
    }
}

/// a · b.
#[inline]
pub(crate) fn dot<const D: usize>(a: [f64; D], b: [f64; D]) -> f64 {
    (1..D).fold(a[0] * b[0], |s, c| s + a[c] * b[c])
}

/// Which groups of terms a residual evaluation takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Terms {
    /// Every term of the layout.
    All,
    /// The internal forces of the momentum balances only: stress, pore pressure, porosity
    /// gradient and drag (no inertia or body force, no mass balance), for the equilibrium identity.
    Forces,
}

/// The residual block of one particle (length `nn × nd`, node-major): the sum of every term of the
/// layout (see the module documentation), each weighted as the time scheme `nm` says. `out` is
/// overwritten.
pub fn residual<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
    residual_terms(pt, nm, Terms::All, out);
}

/// The residual block of the chosen `terms` (see [`residual`]).
pub fn residual_terms<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, terms: Terms, out: &mut [f64]) {
    out[..pt.size()].fill(0.0);
    if terms == Terms::All {
        inertia::residual(pt, nm, out);
    }
    stress::residual(pt, nm, out);
    control::residual(pt, nm, out);
    stress::pore_pressure::residual(pt, nm, out);
    if pt.layout.w.is_some() {
        inertia::drag::residual(pt, nm, out);
        flow::porosity_gradient::residual(pt, nm, out);
    }
    if pt.layout.p.is_some() && terms == Terms::All {
        flow::continuity::residual(pt, nm, out);
        flow::darcy::residual(pt, nm, out);
        flow::drained_face::residual(pt, nm, out);
    }
    if pt.layout.jbar.is_some() && terms == Terms::All {
        fbar::residual(pt, nm, out);
    }
}

/// The tangent block d(residual)/d(Δd) of one particle, row-major `(nn·nd)²`. Every entry of
/// `out` is written (the zero couplings too), so the buffer may be reused from particle to particle.
pub fn tangent<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64]) {
    tangent_with(pt, nm, out, 1.0);
}

/// [`tangent`] with the skeleton's material stiffness scaled by `material` (see
/// [`stress::tangent_with`]).
pub fn tangent_with<const D: usize, const M: usize>(pt: &Point<D, M>, nm: &Scheme, out: &mut [f64], material: f64) {
    let m = pt.size();
    out[..m * m].fill(0.0);
    inertia::tangent(pt, nm, out);
    stress::tangent_with(pt, nm, out, material);
    control::tangent(pt, nm, out);
    stress::pore_pressure::tangent(pt, nm, out);
    if pt.layout.w.is_some() {
        inertia::drag::tangent(pt, nm, out);
        flow::porosity_gradient::tangent(pt, nm, out);
    }
    if pt.layout.p.is_some() {
        flow::continuity::tangent(pt, nm, out);
        flow::darcy::tangent(pt, nm, out);
        flow::drained_face::tangent(pt, nm, out);
    }
    if pt.layout.jbar.is_some() {
        fbar::tangent(pt, nm, out);
    }
}

/// What the particle update of [003] Eq. 24 / [000] Eq. 11 takes from a converged step: exactly the
/// state the converged residual used, so that the stress stored at the particle and the stress in
/// the residual cannot part ways.
#[derive(Debug, Clone, Copy)]
pub struct StepResult<const D: usize = 2> {
    /// Interpolated increments, velocities and accelerations.
    pub interp: Interp<D>,
    /// The effective stress at t_{n+1} from the soil model [Pa] (its tangents are not kept: a
    /// step's results are held for every particle at once).
    pub stress: Stress,
    /// The accumulated deviatoric plastic strain ε̄ at t_{n+1} [-].
    pub eps_pd: f64,
    /// Incremental deformation gradient the particle keeps, F̄ = (J_v/J)^{1/D} F.
    pub f_inc: [[f64; D]; D],
    /// Volume ratio of the step, J_v.
    pub jacobian: f64,
    /// The objective strain increment Δε [xx, yy, γxy, zz, γyz, γzx] the stress update used (zero
    /// for a rigid rotation).
    pub deps: Stress,
    /// The porosity gradient ∇n at t_n the step used (two-phase u–p–U; zero otherwise).
    pub grad_n: [f64; D],
    /// [002]'s projected J̄ at t_{n+1} (`stabilisation.fbar`; `None`: the point keeps its J̄).
    pub jbar: Option<f64>,
    /// The point's velocity after an explicit step whose transfer sets it (XPIC,
    /// `assembly::explicit`); `None`: the stage's own update (FLIP/PIC blend, Newmark, …).
    pub velocity: Option<[f64; D]>,
}

impl<const D: usize> StepResult<D> {
    /// The result of the converged point.
    pub fn of<const M: usize>(pt: &Point<D, M>) -> StepResult<D> {
        StepResult {
            interp: pt.interp,
            stress: pt.upd.stress,
            eps_pd: pt.upd.eps_pd,
            f_inc: pt.kin.f_bar(),
            jacobian: pt.kin.jv,
            deps: pt.strain_kin().deps,
            grad_n: pt.part.grad_n,
            jbar: pt.layout.jbar.map(|_| 1.0 + pt.interp.jbar),
            velocity: None,
        }
    }
}

/// Pressure-projection stabilisation of one cell (Bochev & Dohrmann 2006; Dohrmann & Bochev 2004,
/// for equal-order pressures): S_kl = Σ_p w_p (N_k(x_p) − N̄_k)(N_l(x_p) − N̄_l) over the material
/// points p of the cell, with N the cell's C multilinear functions at the points (four bilinear
/// ones in the plane, eight trilinear ones in three dimensions), w_p = τ_p V_p and N̄ the
/// w-weighted cell averages. Δpᵀ S Δp penalises the part of the pressure increment that is not
/// constant in the cell, which the volumetric coupling of equal-order (and B̄) interpolation
/// cannot see; it vanishes for a cell-wise constant field. The caller subtracts S Δp from the
/// continuity rows (the sign of −P).
pub fn pressure_projection<const C: usize>(n: &[[f64; C]], w: &[f64]) -> [[f64; C]; C] {
    let total: f64 = w.iter().sum();
    let mut out = [[0.0; C]; C];
    if total <= 0.0 {
        return out;
    }
    let mut mean = [0.0; C];
    for (np, wp) in n.iter().zip(w) {
        for k in 0..C {
            mean[k] += wp * np[k] / total;
        }
    }
    for (np, wp) in n.iter().zip(w) {
        for k in 0..C {
            for l in 0..C {
                out[k][l] += wp * (np[k] - mean[k]) * (np[l] - mean[l]);
            }
        }
    }
    out
}

#[cfg(test)]
pub(crate) mod tests;
