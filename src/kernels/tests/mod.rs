//! Unit tests of the kernels: each term's tangent against central differences of its own residual,
//! block by block and each block against its own scale, so that a wrong sign in a block whose
//! entries are 10⁻¹⁵ of the largest entry of the tangent still fails; and the properties of the
//! whole point (rest, rigid rotation, Newmark).

use super::*;
use crate::layout::MAX_DOF_3D;
use crate::scheme::Integration;
use crate::soils::{LinearElastic, MohrCoulomb, SoilModel};

/// A non-associated Mohr–Coulomb soil with softening.
fn mohr_coulomb(cohesion: f64) -> Constitutive {
    SoilModel::MohrCoulomb(MohrCoulomb {
        young_modulus: 1e7,
        poisson_ratio: 0.3,
        friction_angle: 30.0,
        cohesion,
        residual_cohesion: Some(0.5 * cohesion),
        softening_strain: Some(0.05),
        dilation_angle: 5.0,
        critical_dilation_angle: Some(0.0),
        dilation_decay: 10.0,
        tension_cutoff: None,
    })
    .law()
}

/// The agreement of one (row field, column field) block of a tangent with finite differences.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BlockError {
    pub row: usize,
    pub col: usize,
    /// max |J − FD| over the block.
    pub err: f64,
    /// max |J| over the block.
    pub jmax: f64,
    /// max |FD| over the block.
    pub fdmax: f64,
    /// The finite-difference noise expected in the block.
    pub noise: f64,
}

impl BlockError {
    /// Whether the block agrees: within 1e-6 of its own scale, or within the noise for a block
    /// that is zero.
    pub fn pass(&self) -> bool {
        self.err <= 1e-6 * self.jmax.max(self.fdmax) + self.noise
    }
}

/// Compares `tangent` (row-major m × m) with central differences of `residual` at `d0`, with the
/// step `h[field]` for each field of a node of `nd` dofs.
pub(crate) fn fd_blocks(
    nd: usize,
    d0: &[f64],
    h: &[f64],
    residual: &dyn Fn(&[f64]) -> Vec<f64>,
    tangent: &[f64],
) -> Vec<BlockError> {
    let m = d0.len();
    let mut fd = vec![0.0; m * m];
    for c in 0..m {
        let hc = h[c % nd];
        let (mut dp, mut dm) = (d0.to_vec(), d0.to_vec());
        dp[c] += hc;
        dm[c] -= hc;
        let (rp, rm) = (residual(&dp), residual(&dm));
        for r in 0..m {
            fd[r * m + c] = (rp[r] - rm[r]) / (2.0 * hc);
        }
    }
    // Expected round-off of a difference quotient in row field a, column field b: the residual's
    // change over one step of each column field, times 1e-8, divided by h_b.
    let change = |a: usize| -> f64 {
        (0..m)
            .filter(|r| r % nd == a)
            .flat_map(|r| (0..m).map(move |c| (r, c)))
            .fold(0.0f64, |s, (r, c)| s.max(tangent[r * m + c].abs() * h[c % nd]))
    };
    // And the round-off of the residual itself: a few ulps of its largest entry in the row field,
    // divided by 2h_b.
    let r0 = residual(d0);
    let size = |a: usize| -> f64 { (0..m).filter(|r| r % nd == a).fold(0.0f64, |s, r| s.max(r0[r].abs())) };
    let mut out = Vec::new();
    for a in 0..nd {
        let ch = change(a);
        let ulps = 8.0 * f64::EPSILON * size(a);
        for (b, &hb) in h.iter().enumerate().take(nd) {
            let (mut err, mut jmax, mut fdmax) = (0.0f64, 0.0f64, 0.0f64);
            for r in (0..m).filter(|r| r % nd == a) {
                for c in (0..m).filter(|c| c % nd == b) {
                    err = err.max((tangent[r * m + c] - fd[r * m + c]).abs());
                    jmax = jmax.max(tangent[r * m + c].abs());
                    fdmax = fdmax.max(fd[r * m + c].abs());
                }
            }
            out.push(BlockError { row: a, col: b, err, jmax, fdmax, noise: 1e-8 * ch / hb + ulps / (2.0 * hb) });
        }
    }
    out
}

fn sample(nn: usize) -> Vec<NodeBasis> {
    sample_in(nn, false)
}

/// A sample basis; with `hoop` the hoop operators of a point at r ≈ 0.2 m of an axisymmetric
/// analysis (T ≈ S/r, and B̄'s T̄ different from it).
fn sample_in(nn: usize, hoop: bool) -> Vec<NodeBasis> {
    (0..nn)
        .map(|k| {
            let x = k as f64;
            let s = 0.05 + 0.1 * (x * 0.7).sin().abs();
            let (t, tv) = if hoop { (s / 0.2, 0.04 + 0.5 * (x * 0.3).cos().abs()) } else { (0.0, 0.0) };
            NodeBasis {
                s,
                g: [(x * 1.3).cos() * 3.0, (x * 0.9).sin() * 2.0],
                gv: [(x * 1.1).cos() * 2.5, (x * 0.4).sin() * 1.5],
                t,
                tv,
            }
        })
        .collect()
}

/// Two drained faces of a sample particle (a corner: top and right), with bilinear-like values
/// and gradients that differ from the particle's basis.
fn sample_faces(nn: usize) -> Vec<DrainedFace> {
    [([0.0, 0.02], [0.1, 0.995]), ([0.03, 0.0], [0.98, -0.2])]
        .iter()
        .map(|&(offset, n)| {
            let len = f64::hypot(n[0], n[1]);
            let mut basis = [(0.0, [0.0; 2]); crate::kernels::MAX_NODES];
            for (k, b) in basis.iter_mut().take(nn).enumerate() {
                let x = k as f64 + offset[1] * 10.0;
                *b = (0.1 + 0.08 * (x * 0.9).cos().abs(), [(x * 0.8).sin() * 4.0, (x * 1.7).cos() * 3.0]);
            }
            DrainedFace { offset, normal: [n[0] / len, n[1] / len], area: 0.05, penalty: 20.0, basis }
        })
        .collect()
}

/// A sample particle (two-phase quantities set, stressed, J ≠ 1).
pub(super) fn part() -> ParticleInput {
    ParticleInput {
        volume: 2.5e-3,
        porosity: 0.35,
        mass: 4.3,
        water_mass: 0.9,
        drag: 7.0e3,
        inv_q: 3.0e-9,
        mobility: 2.0e-7,
        water_density: 1000.0,
        grad_p: [300.0, -9.0e3],
        stress: soils::plane([-1.0e3, -2.0e3, 150.0, -1.2e3]),
        def_grad: [[1.02, 0.01], [-0.03, 0.97]],
        eps_pd: 0.0,
        p: 500.0,
        body_acc: [0.0, -9.81],
        grad_n: [0.7, -1.3],
        pred: Motion { a_u: [0.3, -0.2], v_u: [0.01, 0.02], a_w: [-0.1, 0.4], v_w: [0.03, -0.01] },
        ..ParticleInput::at_rest()
    }
}

fn states(d: &[f64], nd: usize, nm: &Scheme) -> Vec<NodeState> {
    states_of(d, nd, nm)
}

/// The nodal states of the increments `d` (nodes of `nd` dofs) in states of `N` dofs.
fn states_of<const N: usize>(d: &[f64], nd: usize, nm: &Scheme) -> Vec<NodeState<N>> {
    d.chunks(nd).map(|c| NodeState::new(c, nm)).collect()
}

/// [`states`] in three dimensions.
fn states3(d: &[f64], nd: usize, nm: &Scheme) -> Vec<NodeState<MAX_DOF_3D>> {
    states_of(d, nd, nm)
}

/// Increments of typical size: displacements of 1e-3 m (strains of a few 1e-3, rotations), 500 Pa.
fn increments(m: usize, layout: Layout) -> Vec<f64> {
    (0..m)
        .map(|i| {
            let s = ((i as f64) * 0.37 + 0.1).sin();
            if Some(i % layout.nd) == layout.p {
                500.0 * s
            } else {
                1e-3 * s
            }
        })
        .collect()
}

fn steps(layout: Layout) -> Vec<f64> {
    (0..layout.nd)
        .map(|c| {
            if Some(c) == layout.p {
                1e-3
            } else if Some(c) == layout.jbar {
                1e-6
            } else {
                1e-9
            }
        })
        .collect()
}

/// A term's residual or tangent at a point of dimension `D` with scratch for `M` nodes.
type TermFn<const D: usize, const M: usize> = fn(&Point<D, M>, &Scheme, &mut [f64]);
/// A term: its name, residual and tangent.
type Term<const D: usize = 2, const M: usize = MAX_NODES> = (&'static str, TermFn<D, M>, TermFn<D, M>);

/// Every term with its residual and tangent.
fn terms() -> Vec<Term> {
    terms_in::<2, MAX_NODES>()
}

/// Every term with its residual and tangent, in `D` dimensions.
fn terms_in<const D: usize, const M: usize>() -> Vec<Term<D, M>> {
    vec![
        ("inertia", inertia::residual::<D, M>, inertia::tangent::<D, M>),
        ("drag", inertia::drag::residual::<D, M>, inertia::drag::tangent::<D, M>),
        ("effective stress", stress::residual::<D, M>, stress::tangent::<D, M>),
        ("filtered-mode control", control::residual::<D, M>, control::tangent::<D, M>),
        ("pore pressure", stress::pore_pressure::residual::<D, M>, stress::pore_pressure::tangent::<D, M>),
        ("porosity gradient", flow::porosity_gradient::residual::<D, M>, flow::porosity_gradient::tangent::<D, M>),
        ("continuity", flow::continuity::residual::<D, M>, flow::continuity::tangent::<D, M>),
        ("darcy", flow::darcy::residual::<D, M>, flow::darcy::tangent::<D, M>),
        ("drained face", flow::drained_face::residual::<D, M>, flow::drained_face::tangent::<D, M>),
        ("F̄ projection", fbar::residual::<D, M>, fbar::tangent::<D, M>),
        ("all", residual::<D, M>, tangent::<D, M>),
    ]
}

/// The layouts with the time schemes each is used with: u–p–U and u under Newmark and
/// generalized-α, u–p quasi-static with Darcy's law (θ = 0.7) and static undrained, u static.
fn layouts_and_schemes() -> Vec<(Layout, &'static str, Scheme)> {
    let dt = 1e-3;
    vec![
        (Layout::UPU, "Newmark", Scheme::newmark(0.25, 0.5, dt)),
        (Layout::UPU, "generalized-α", Scheme::of(&Integration::generalized_alpha(0.6), dt, false)),
        (Layout::U, "Newmark", Scheme::newmark(0.25, 0.5, dt)),
        (Layout::U, "static", Scheme::of(&Integration::Static, dt, false)),
        (Layout::UP, "quasi-static", Scheme::of(&Integration::QuasiStatic { theta: 0.7 }, dt, true)),
        (Layout::UP, "static undrained", Scheme::of(&Integration::Static, dt, true)),
    ]
}

fn models() -> Vec<(&'static str, Constitutive, Stress)> {
    let el = LinearElastic::new(1e7, 0.3);
    // A Mohr–Coulomb point close to its yield surface, so the step returns plastically.
    vec![
        ("elastic", Constitutive::LinearElastic(el), soils::plane([-1.0e3, -2.0e3, 150.0, -1.2e3])),
        ("mohr-coulomb", mohr_coulomb(1.0e3), soils::plane([-1.0e4, -4.0e4, 9.0e3, -2.0e4])),
    ]
}

/// Strain operators that differ from [`sample_in`]'s basis (standing for [001]'s CMPM patch
/// functions, see [`Point::with_recovery`]), with hoop operators if `hoop`.
fn sample_strain(nn: usize, hoop: bool) -> Vec<NodeBasis> {
    (0..nn)
        .map(|k| {
            let x = k as f64 + 0.5;
            let g = [(x * 0.8).sin() * 2.5, (x * 1.6).cos() * 1.8];
            let t = if hoop { 0.3 + 0.2 * (x * 0.5).sin() } else { 0.0 };
            NodeBasis { s: 0.0, g, gv: g, t, tv: t }
        })
        .collect()
}

/// Force operators that differ from [`sample_in`]'s basis and from [`sample_strain`] (standing
/// for [001]'s double-mapped internal force, see [`Point::with_forces`]), with a volumetric part
/// of their own and, if `hoop`, hoop operators.
fn sample_forces(nn: usize, hoop: bool) -> Vec<NodeBasis> {
    (0..nn)
        .map(|k| {
            let x = k as f64 + 0.25;
            let g = [(x * 1.7).sin() * 2.2, (x * 0.6).cos() * 2.9];
            let gv = [(x * 0.5).cos() * 1.9, (x * 1.2).sin() * 2.4];
            let (t, tv) = if hoop { (0.4 + 0.3 * (x * 0.9).cos(), 0.2 + 0.1 * x.sin()) } else { (0.0, 0.0) };
            NodeBasis { s: 0.0, g, gv, t, tv }
        })
        .collect()
}

/// The operators of a point for [`check_term`]: axisymmetric (`.0`), its strain recovered by
/// other operators than the basis (`.1`), its forces integrated by others again (`.2`).
type Mode = (bool, bool, bool);

/// The modes [`check_term`] runs through: each switch alone, none, and all together.
const MODES: [Mode; 6] = [
    (false, false, false),
    (true, false, false),
    (false, true, false),
    (true, true, false),
    (false, false, true),
    (true, true, true),
];

/// Runs the finite-difference check of one term (with the hoop operators of an axisymmetric
/// point, the strain recovered by other operators than the basis and the forces integrated by
/// others again, as `mode` says); returns the blocks.
fn check_term(
    term: &Term,
    model: &Constitutive,
    stress: Stress,
    layout: Layout,
    nm: &Scheme,
    (hoop, recovery, forces): Mode,
    linear: bool,
) -> Vec<BlockError> {
    let mut basis = sample_in(6, hoop);
    let mut p = part();
    if layout.jbar.is_some() {
        // F̄ replaces B̄: the basis's volumetric gradients are its own; the point carries a J̄ of
        // its own and the projection rows their scale.
        basis.iter_mut().for_each(|b| b.gv = b.g);
        p.jbar = 1.03;
        p.fbar_rows = 2.0e8;
    }
    let recovered = if recovery { sample_strain(6, hoop) } else { Vec::new() };
    // The control acts where the strain is recovered (it is nothing otherwise).
    p.control = 0.4;
    p.stress = stress;
    p.linear = linear;
    let forces = if forces { sample_forces(6, hoop) } else { Vec::new() };
    // Without recovery the strain operators are the basis itself (the same slice, as the
    // assembly passes it: the point then keeps one set of operators on x_{n+1}).
    let ops = Operators { basis: &basis, strain: if recovery { &recovered } else { &basis }, forces: &forces };
    check_term_in::<2, MAX_NODES, MAX_DOF>(term, model, layout, nm, ops, &p, &sample_faces(basis.len()))
}

/// A point's basis, strain operators and force operators (empty: the basis's) for
/// [`check_term_in`].
#[derive(Clone, Copy)]
struct Operators<'a, const D: usize> {
    basis: &'a [NodeBasis<D>],
    strain: &'a [NodeBasis<D>],
    forces: &'a [NodeBasis<D>],
}

/// The finite-difference check of one term at the point of operators `ops`, particle `p` and
/// drained `faces`, in any dimension; returns the blocks.
fn check_term_in<const D: usize, const M: usize, const N: usize>(
    term: &Term<D, M>,
    model: &Constitutive,
    layout: Layout,
    nm: &Scheme,
    ops: Operators<D>,
    p: &ParticleInput<D>,
    faces: &[DrainedFace<D, M>],
) -> Vec<BlockError> {
    let Operators { basis, strain, forces } = ops;
    let nd = layout.nd;
    let m = basis.len() * nd;
    let nm = *nm;
    let d0 = increments(m, layout);
    let point = |st: &[NodeState<N>]| -> Vec<f64> {
        let pt =
            Point::<D, M>::with_recovery(basis, strain, st, p, model, layout).with_forces(forces).with_faces(faces, st);
        let mut r = vec![0.0; m];
        (term.1)(&pt, &nm, &mut r);
        r
    };
    let res = |d: &[f64]| point(&states_of::<N>(d, nd, &nm));
    let st = states_of::<N>(&d0, nd, &nm);
    let pt =
        Point::<D, M>::with_recovery(basis, strain, &st, p, model, layout).with_forces(forces).with_faces(faces, &st);
    let mut t = vec![0.0; m * m];
    (term.2)(&pt, &nm, &mut t);
    fd_blocks(nd, &d0, &steps(layout), &res, &t)
}

/// Asserts that block `b` agrees with central differences, naming it by `names` and `what`.
fn assert_block(b: &BlockError, names: &[&str], what: &str) {
    assert!(
        b.pass(),
        "{what}: block {}–{} differs by {:e} (|J| ≤ {:e}, |FD| ≤ {:e}, noise {:e})",
        names[b.row],
        names[b.col],
        b.err,
        b.jmax,
        b.fdmax,
        b.noise
    );
}

#[test]
fn every_term_matches_central_differences_block_by_block() {
    let names = ["ux", "uy", "p", "Ux", "Uy"];
    for (layout, sname, nm) in layouts_and_schemes() {
        for (mname, model, stress) in models() {
            for (term, mode) in terms().into_iter().flat_map(|t| MODES.map(|m| (t, m))) {
                for b in check_term(&term, &model, stress, layout, &nm, mode, false) {
                    let what = format!(
                        "{} ({mname}, nd = {}, {sname}, (axisymmetric, recovered strain, mapped forces) {mode:?})",
                        term.0, layout.nd
                    );
                    assert_block(&b, &names, &what);
                }
            }
        }
    }
}

/// Implicit F̄ steps (`kernels::fbar`, plane strain, the basis's own strain operators): every
/// term's tangent, the projection rows' and the ϑ columns of the forces among them, matches
/// central differences, for the u and u–p layouts with their schemes, elastic and plastic.
#[test]
fn fbar_terms_match_central_differences_block_by_block() {
    let dt = 1e-3;
    let cases = [
        (Layout::U_FBAR, "static", Scheme::of(&Integration::Static, dt, false)),
        (Layout::U_FBAR, "Newmark", Scheme::newmark(0.25, 0.5, dt)),
        (Layout::UP_FBAR, "quasi-static", Scheme::of(&Integration::QuasiStatic { theta: 0.7 }, dt, true)),
        (Layout::UP_FBAR, "static undrained", Scheme::of(&Integration::Static, dt, true)),
    ];
    let terms = terms();
    for (layout, sname, nm) in cases {
        let names = layout.field_names();
        for (mname, model, stress) in models() {
            for term in &terms {
                let blocks = check_term(term, &model, stress, layout, &nm, (false, false, false), false);
                for b in &blocks {
                    assert_block(b, names, &format!("{} ({mname}, {sname})", term.0));
                }
                if term.0 == "all" {
                    // The check sees the coupling: the forces' ϑ columns and the rows' u columns.
                    let j = layout.jbar.unwrap();
                    let at =
                        |r: usize, c: usize| blocks.iter().find(|b| b.row == r && b.col == c).map_or(0.0, |b| b.jmax);
                    assert!(at(0, j) > 0.0 && at(j, 0) > 0.0 && at(j, j) > 0.0, "{sname} {mname}: F̄ couplings missing");
                }
            }
        }
    }
}

/// Geometrically linear steps (`analysis.kinematics = "linear_increments"`, one-phase): every
/// term's tangent matches central differences, the residual of an elastic point is affine in the
/// increments (f(d₀ + s δ) is linear in s), and its stress increment is D sym ∇Δu without rotation.
#[test]
fn linear_increments_have_an_affine_residual_and_a_matching_tangent() {
    let names = ["ux", "uy"];
    for (layout, sname, nm) in layouts_and_schemes().into_iter().filter(|l| l.0.nd == 2) {
        for (mname, model, stress) in models() {
            for mode in MODES {
                for term in terms() {
                    for b in check_term(&term, &model, stress, layout, &nm, mode, true) {
                        assert!(
                            b.pass(),
                            "{} ({mname}, {sname}, {mode:?}, linear): block {}–{} differs by {:e} (|J| ≤ {:e})",
                            term.0,
                            names[b.row],
                            names[b.col],
                            b.err,
                            b.jmax
                        );
                    }
                }
            }
        }
    }
    let (_, model, stress) = models()[0];
    let basis = sample_in(6, true);
    let nm = Scheme::of(&Integration::Static, 1.0, false);
    let m = basis.len() * 2;
    let d0 = increments(m, Layout::U);
    // The residual, stress and rotation for the increments s d₀, linear or finite strain.
    let force = |s: f64, linear: bool| {
        let p = ParticleInput { stress, linear, ..part() };
        let d: Vec<f64> = d0.iter().map(|x| 30.0 * s * x).collect();
        let st = states(&d, 2, &nm);
        let pt = Point::<2>::with_recovery(&basis, &basis, &st, &p, &model, Layout::U);
        let mut r = vec![0.0; m];
        stress::residual(&pt, &nm, &mut r);
        (r, pt.upd.stress, pt.kin.theta)
    };
    let (r0, s0, _) = force(0.0, true);
    let (r1, s1, theta) = force(1.0, true);
    let (r2, s2, _) = force(2.0, true);
    let scale = r1.iter().map(|x| x.abs()).fold(0.0, f64::max);
    for i in 0..m {
        assert!((r2[i] - 2.0 * r1[i] + r0[i]).abs() < 1e-10 * scale, "row {i}: {} {} {}", r0[i], r1[i], r2[i]);
    }
    assert_eq!(theta, 0.0);
    for c in 0..4 {
        assert!((s2[c] - 2.0 * s1[c] + s0[c]).abs() < 1e-9 * (s1[c] - s0[c]).abs().max(1.0), "component {c}");
    }
    // The same increments under finite strain are not affine (the test can tell the two apart).
    let (f0, f1, f2) = (force(0.0, false).0, force(1.0, false).0, force(2.0, false).0);
    let curvature = (0..m).map(|i| (f2[i] - 2.0 * f1[i] + f0[i]).abs()).fold(0.0, f64::max);
    assert!(curvature > 1e-4 * scale, "finite strain curvature {curvature:e} against {scale:e}");
}

#[test]
fn the_plastic_sample_really_returns() {
    let (_, model, stress) = models()[1];
    let basis = sample(6);
    let nm = Scheme::newmark(0.25, 0.5, 1e-3);
    let mut p = part();
    p.stress = stress;
    let d0 = increments(basis.len() * 5, Layout::UPU);
    let st = states(&d0, 5, &nm);
    let pt = Point::<2>::with_recovery(&basis, &basis, &st, &p, &model, Layout::UPU);
    assert!(pt.upd.eps_pd > 0.0, "{:?}", pt.upd.region);
    assert!(pt.kin.theta.abs() > 1e-4, "the sample must rotate: θ = {}", pt.kin.theta);
}

/// A recovered strain is the stress's only ([001] §5.5 as docs/stiffness.md reads it):
/// the soil model's increment, the rotated stress and the update are those of a point whose basis
/// were the strain operators, while the motion (F, the volume ratio, the gradients on x_{n+1}, what
/// the particle keeps) is the basis's, as without recovery; in axial symmetry and in plane strain.
#[test]
fn a_recovered_strain_moves_the_stress_and_leaves_the_motion_to_the_basis() {
    for hoop in [false, true] {
        let (_, model, stress) = models()[1];
        let (basis, strain) = (sample_in(6, hoop), sample_strain(6, hoop));
        let nm = Scheme::newmark(0.25, 0.5, 1e-3);
        let p = ParticleInput { stress, ..part() };
        let st = states(&increments(basis.len() * 2, Layout::U), 2, &nm);
        let recovered = Point::<2>::with_recovery(&basis, &strain, &st, &p, &model, Layout::U);
        let own = Point::<2>::with_recovery(&basis, &basis, &st, &p, &model, Layout::U);
        let of_strain = Point::<2>::with_recovery(&strain, &strain, &st, &p, &model, Layout::U);
        let (r, b, s) = (StepResult::of(&recovered), StepResult::of(&own), StepResult::of(&of_strain));
        // The sample's two sets of operators give different motions and strains.
        assert!((b.jacobian - s.jacobian).abs() > 1e-3 && (b.deps[0] - s.deps[0]).abs() > 1e-3, "{hoop}");
        assert_eq!((r.jacobian, r.f_inc), (b.jacobian, b.f_inc), "the motion is the basis's ({hoop})");
        assert_eq!(recovered.spatial, own.spatial, "the gradients on x_{{n+1}} are the basis's ({hoop})");
        assert_eq!(recovered.volume_new(), own.volume_new());
        assert_eq!((r.deps, r.stress, r.eps_pd), (s.deps, s.stress, s.eps_pd), "the stress is the strain's ({hoop})");
        assert_eq!(recovered.rotated, of_strain.rotated);
        assert!(r.eps_pd > 0.0, "the sample returns plastically ({hoop})");
    }
}

/// Flips the sign of each non-zero (row field, column field) block of the tangent `t` (nodes of
/// `nd` dofs) in turn and asserts that the central differences of `res` at `d0` catch it, naming
/// the term by `what`; returns the number of blocks flipped.
fn flip_every_block(
    nd: usize,
    d0: &[f64],
    layout: Layout,
    res: &dyn Fn(&[f64]) -> Vec<f64>,
    t: &[f64],
    what: &str,
) -> usize {
    let m = d0.len();
    let mut flipped = 0;
    for a in 0..nd {
        for b in 0..nd {
            let mut wrong = t.to_vec();
            let mut any = false;
            for r in (0..m).filter(|r| r % nd == a) {
                for c in (0..m).filter(|c| c % nd == b) {
                    any |= wrong[r * m + c] != 0.0;
                    wrong[r * m + c] = -wrong[r * m + c];
                }
            }
            if !any {
                continue;
            }
            flipped += 1;
            let blocks = fd_blocks(nd, d0, &steps(layout), res, &wrong);
            let caught = blocks.iter().find(|e| e.row == a && e.col == b).is_some_and(|e| !e.pass());
            assert!(caught, "{what}: a flipped {a}–{b} block passed");
        }
    }
    flipped
}

/// The check is not blind: a wrong sign in any non-zero block of any term, however small its
/// entries against the rest of the tangent (p–p ≈ 1e-13, u–u ≈ 1e5 here), fails it.
#[test]
fn a_wrong_sign_in_any_block_of_any_term_is_caught() {
    let (_, model, stress) = models()[0];
    let p = ParticleInput { stress, ..part() };
    let mut flipped_blocks = 0;
    let cases = [layouts_and_schemes()[1], layouts_and_schemes()[4]];
    let all = terms().into_iter().flat_map(|t| cases.map(|c| (t, c))).flat_map(|(t, c)| [(t, c, false), (t, c, true)]);
    for (term, (layout, _, nm), hoop) in all {
        let basis = sample_in(6, hoop);
        let nd = layout.nd;
        let m = basis.len() * nd;
        let d0 = increments(m, layout);
        let faces = sample_faces(basis.len());
        let res = |d: &[f64]| {
            let st = states(d, nd, &nm);
            let pt = Point::<2>::with_recovery(&basis, &basis, &st, &p, &model, layout).with_faces(&faces, &st);
            let mut r = vec![0.0; m];
            (term.1)(&pt, &nm, &mut r);
            r
        };
        let st = states(&d0, nd, &nm);
        let pt = Point::<2>::with_recovery(&basis, &basis, &st, &p, &model, layout).with_faces(&faces, &st);
        let mut t = vec![0.0; m * m];
        (term.2)(&pt, &nm, &mut t);
        let what = format!("{} (nd = {nd}, axisymmetric {hoop})", term.0);
        flipped_blocks += flip_every_block(nd, &d0, layout, &res, &t, &what);
    }
    assert!(flipped_blocks > 120, "only {flipped_blocks} blocks were flipped");
}

#[test]
fn newmark_reproduces_a_uniformly_accelerated_motion() {
    // A point with v_n, a_n moved by Δd = v_n Δt + a_n Δt²/2 keeps a_n and reaches v_n + a_n Δt
    // ([003] Eqs. 20–21) for any β, γ.
    for (beta, gamma) in [(0.25, 0.5), (0.3025, 0.6)] {
        let (dt, v, a) = (2e-3, [0.4, -1.1], [3.0, -9.81]);
        let nm = Scheme::newmark(beta, gamma, dt);
        let pred = Motion::predicted(&nm, v, a, v, a);
        let d = [v[0] * dt + 0.5 * a[0] * dt * dt, v[1] * dt + 0.5 * a[1] * dt * dt];
        let basis = [NodeBasis { s: 1.0, ..NodeBasis::default() }];
        let st = states(&[d[0], d[1], 0.0, d[0], d[1]], 5, &nm);
        let k = interpolate(&basis, &st, &pred, Layout::UPU);
        for c in 0..2 {
            assert!((k.motion.a_u[c] - a[c]).abs() < 1e-9 && (k.motion.a_w[c] - a[c]).abs() < 1e-9, "{k:?}");
            assert!((k.motion.v_u[c] - (v[c] + a[c] * dt)).abs() < 1e-12, "{k:?}");
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
    p.stress = [0.0; soils::NS];
    p.p = 0.0;
    p.grad_n = [0.0; 2];
    p.pred = Motion::default();
    let st = vec![NodeState::<MAX_DOF>::default(); 4];
    let model = Constitutive::LinearElastic(LinearElastic::new(1e7, 0.3));
    let pt = Point::<2>::with_recovery(&basis, &basis, &st, &p, &model, Layout::UPU);
    let mut r = vec![0.0; 20];
    residual(&pt, &Scheme::newmark(0.25, 0.5, 1e-3), &mut r);
    let fy: f64 = (0..4).map(|k| r[k * 5 + 1] + r[k * 5 + 4]).sum();
    assert!((fy - (p.mass + p.water_mass) * 9.81).abs() < 1e-12);
    assert!((0..4).all(|k| r[k * 5 + 2] == 0.0));
}

/// Bilinear functions of the unit square evaluated for a point at `x` (S, ∇S; B̄ gradients equal).
fn unit_square(x: [f64; 2]) -> Vec<NodeBasis> {
    [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
        .iter()
        .map(|&(nx, ny): &(f64, f64)| {
            let sx = if nx == 0.0 { 1.0 - x[0] } else { x[0] };
            let sy = if ny == 0.0 { 1.0 - x[1] } else { x[1] };
            let gx = if nx == 0.0 { -1.0 } else { 1.0 };
            let gy = if ny == 0.0 { -1.0 } else { 1.0 };
            NodeBasis { s: sx * sy, g: [gx * sy, sx * gy], gv: [gx * sy, sx * gy], t: 0.0, tv: 0.0 }
        })
        .collect()
}

#[test]
fn volume_ratio_and_strain_of_a_uniform_compression() {
    // Δu = (−0.01 x, −0.02 y): F = diag(0.99, 0.98); the mid-step strain is the exact
    // L = H (I + H/2)⁻¹, the volume ratio det F.
    let basis = unit_square([0.3, 0.6]);
    let nm = Scheme::newmark(0.25, 0.5, 1.0);
    let pts = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
    let st: Vec<NodeState> = pts.iter().map(|&(x, y)| NodeState::new(&[-0.01 * x, -0.02 * y], &nm)).collect();
    let model = Constitutive::LinearElastic(LinearElastic::new(1e7, 0.3));
    let p = ParticleInput { stress: [0.0; soils::NS], ..part() };
    let pt = Point::<2>::with_recovery(&basis, &basis, &st, &p, &model, Layout::U);
    let r = StepResult::of(&pt);
    assert!((r.jacobian - 0.99 * 0.98).abs() < 1e-14);
    assert!((r.f_inc[0][0] - 0.99).abs() < 1e-14 && (r.f_inc[1][1] - 0.98).abs() < 1e-14);
    assert!(r.f_inc[0][1].abs() < 1e-14 && r.f_inc[1][0].abs() < 1e-14);
    assert!((pt.kin.deps[0] + 0.01 / 0.995).abs() < 1e-14 && (pt.kin.deps[1] + 0.02 / 0.99).abs() < 1e-14);
    assert!((r.interp.du[0] + 0.003).abs() < 1e-14);
}

/// A stressed point turned rigidly by 90° in 10 and in 100 steps keeps its principal stresses to
/// round-off and ends with R σ Rᵀ (Hughes–Winget is exact for rigid rotations).
#[test]
fn a_rigid_rotation_turns_the_stress_with_the_material() {
    for model in [Constitutive::LinearElastic(LinearElastic::new(1e7, 0.3)), mohr_coulomb(1.0e5)] {
        for n in [10usize, 100] {
            let s0 = soils::plane([-3.0e4, -1.0e4, 4.0e3, -2.0e4]);
            let mut s = s0;
            let alpha = std::f64::consts::FRAC_PI_2 / n as f64;
            let (c, sn) = (alpha.cos(), alpha.sin());
            let basis = unit_square([0.5, 0.5]);
            let nm = Scheme::newmark(0.25, 0.5, 1.0);
            let pts = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
            let st: Vec<NodeState> = pts
                .iter()
                .map(|&(x, y)| {
                    NodeState::new(
                        &[c * (x - 0.5) - sn * (y - 0.5) - (x - 0.5), sn * (x - 0.5) + c * (y - 0.5) - (y - 0.5)],
                        &nm,
                    )
                })
                .collect();
            for _ in 0..n {
                let p = ParticleInput { stress: s, ..part() };
                s = Point::<2>::with_recovery(&basis, &basis, &st, &p, &model, Layout::U).upd.stress;
            }
            // A quarter turn: σ_xx ↔ σ_yy, σ_xy → −σ_xy.
            let expected = soils::plane([s0[1], s0[0], -s0[2], s0[3]]);
            let worst = (0..soils::NS).map(|i| (s[i] - expected[i]).abs()).fold(0.0, f64::max);
            assert!(worst < 1e-9 * 3.0e4, "{n} steps: {s:?} vs {expected:?}");
        }
    }
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

mod three;

/// The finite-strain solids in the implicit stages: neo-Hookean, and Hencky–J2 elastic and
/// plastic (a stress at its yield surface, so the step flows), whose stress follows the point's
/// total deformation gradient (F_n ≠ I, B̄'s volume scale, recovered strains, mapped forces).
fn finite_strain_models() -> Vec<(&'static str, Constitutive, Stress)> {
    let hencky = Constitutive::HenckyJ2(soils::HenckyJ2Law::new(1e7, 0.3, 1.5e4, 0.75e4, 5.0));
    vec![
        ("neo-Hookean", Constitutive::NeoHookean(soils::NeoHookeanLaw::new(1e7, 0.3)), [0.0; soils::NS]),
        ("Hencky-J2 elastic", hencky, soils::plane([-1.0e3, -2.0e3, 150.0, -1.2e3])),
        ("Hencky-J2 plastic", hencky, soils::plane([-1.0e4, -4.0e4, 9.0e3, -2.0e4])),
    ]
}

/// Every term's tangent with a finite-strain solid matches central differences block by block,
/// in every layout and scheme of the implicit stages (plane strain: the models refuse axial
/// symmetry), and the plastic sample really flows.
#[test]
fn finite_strain_solids_match_central_differences_block_by_block() {
    let names = ["ux", "uy", "p", "Ux", "Uy"];
    for (layout, sname, nm) in layouts_and_schemes() {
        for (mname, model, stress) in finite_strain_models() {
            for (term, mode) in terms().into_iter().flat_map(|t| MODES.map(|m| (t, m))).filter(|(_, m)| !m.0) {
                for b in check_term(&term, &model, stress, layout, &nm, mode, false) {
                    let what = format!("{} ({mname}, nd = {}, {sname}, {mode:?})", term.0, layout.nd);
                    assert_block(&b, &names, &what);
                }
            }
        }
    }
    let (basis, p) = (sample(6), ParticleInput { stress: finite_strain_models()[2].2, ..part() });
    let d0 = increments(basis.len() * 2, Layout::U);
    let st = states(&d0, 2, &Scheme::of(&Integration::Static, 1e-3, false));
    let pt = Point::<2>::with_recovery(&basis, &basis, &st, &p, &finite_strain_models()[2].1, Layout::U);
    assert_ne!(pt.upd.region, soils::Region::Elastic, "the plastic sample stays elastic");
}

/// The filtered-mode control's forces are the gradient of its energy ½ α V_n e : C : e, with e
/// formed here from the nodal increments directly (sym Σ_i Δu_i ⊗ (∇S_i − ∇P_i), the hoop part
/// from T_i − T^P_i), by central differences, in the plane and in axial symmetry; they vanish
/// with α = 0 and where the strain is the basis's own.
#[test]
fn the_filtered_mode_control_is_the_gradient_of_its_energy() {
    let el = LinearElastic::new(1e7, 0.3);
    let model = Constitutive::LinearElastic(el);
    let (g, lambda) = (el.shear_modulus(), el.bulk_modulus() - 2.0 * el.shear_modulus() / 3.0);
    let nm = Scheme::of(&Integration::Static, 1e-3, false);
    let layout = Layout::U;
    for hoop in [false, true] {
        let (basis, strain) = (sample_in(6, hoop), sample_strain(6, hoop));
        let mut p = part();
        p.control = 0.4;
        let energy = |d: &[f64]| -> f64 {
            let mut e = [[0.0; 2]; 2];
            let mut e_hoop = 0.0;
            for (i, (b, r)) in basis.iter().zip(&strain).enumerate() {
                let u = [d[2 * i], d[2 * i + 1]];
                for a in 0..2 {
                    for c in 0..2 {
                        let h = |k: usize| b.g[k] - r.g[k];
                        e[a][c] += 0.5 * (u[a] * h(c) + u[c] * h(a));
                    }
                }
                e_hoop += (b.t - r.t) * u[0];
            }
            let tr = e[0][0] + e[1][1] + e_hoop;
            let ee = e[0][0].powi(2) + e[1][1].powi(2) + 2.0 * e[0][1].powi(2) + e_hoop * e_hoop;
            0.5 * p.control * p.volume * (lambda * tr * tr + 2.0 * g * ee)
        };
        let d0 = increments(12, layout);
        let st = states(&d0, 2, &nm);
        let pt = Point::<2>::with_recovery(&basis, &strain, &st, &p, &model, layout);
        let mut r = vec![0.0; 12];
        control::residual(&pt, &nm, &mut r);
        let scale = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0);
        for k in 0..12 {
            let step = 1e-7;
            let (mut dp, mut dm) = (d0.clone(), d0.clone());
            dp[k] += step;
            dm[k] -= step;
            let fd = (energy(&dp) - energy(&dm)) / (2.0 * step);
            assert!((fd - r[k]).abs() < 1e-6 * scale, "hoop {hoop}, dof {k}: {} against {fd}", r[k]);
        }
        let mut none = vec![0.0; 12];
        let own = Point::<2>::with_recovery(&basis, &basis, &st, &p, &model, layout);
        control::residual(&own, &nm, &mut none);
        p.control = 0.0;
        control::residual(&Point::<2>::with_recovery(&basis, &strain, &st, &p, &model, layout), &nm, &mut none);
        assert!(none.iter().all(|&v| v == 0.0));
    }
}
