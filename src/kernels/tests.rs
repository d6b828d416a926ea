//! Unit tests of the kernels: each term's tangent against central differences of its own residual,
//! block by block and each block against its own scale, so that a wrong sign in a block whose
//! entries are 10⁻¹⁵ of the largest entry of the tangent still fails; and the properties of the
//! whole point (rest, rigid rotation, Newmark).

use super::*;
use crate::case::{self, SoilModel};
use crate::model::material::soil_model;
use crate::model::soil::LinearElastic;

/// A non-associated Mohr–Coulomb soil with softening.
fn mohr_coulomb(cohesion: f64) -> Constitutive {
    soil_model(&SoilModel::MohrCoulomb(case::MohrCoulomb {
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
    }))
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
        stress: soil::plane([-1.0e3, -2.0e3, 150.0, -1.2e3]),
        def_grad: [[1.02, 0.01], [-0.03, 0.97]],
        eps_pd: 0.0,
        p: 500.0,
        body_acc: [0.0, -9.81],
        grad_n: [0.7, -1.3],
        pred: Predictors { a_u: [0.3, -0.2], v_u: [0.01, 0.02], a_w: [-0.1, 0.4], v_w: [0.03, -0.01] },
        linear: false,
        fbar: 1.0,
        fbar_total: 1.0,
        dt: 0.0,
        jbar: 1.0,
        fbar_rows: 0.0,
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
        ("elastic", Constitutive::LinearElastic(el), soil::plane([-1.0e3, -2.0e3, 150.0, -1.2e3])),
        ("mohr-coulomb", mohr_coulomb(1.0e3), soil::plane([-1.0e4, -4.0e4, 9.0e3, -2.0e4])),
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
        let pt = Point::<2>::new(&basis, &st, &p, &model, Layout::U);
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
    let pt = Point::<2>::new(&basis, &st, &p, &model, Layout::UPU);
    assert!(pt.upd.eps_pd > 0.0, "{:?}", pt.upd.region);
    assert!(pt.kin.theta.abs() > 1e-4, "the sample must rotate: θ = {}", pt.kin.theta);
}

/// A recovered strain is the stress's only ([001] read as `../shared/seeds-001-002.md` Part A8):
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
        let own = Point::<2>::new(&basis, &st, &p, &model, Layout::U);
        let of_strain = Point::<2>::new(&strain, &st, &p, &model, Layout::U);
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
            let pt = Point::<2>::new(&basis, &st, &p, &model, layout).with_faces(&faces, &st);
            let mut r = vec![0.0; m];
            (term.1)(&pt, &nm, &mut r);
            r
        };
        let st = states(&d0, nd, &nm);
        let pt = Point::<2>::new(&basis, &st, &p, &model, layout).with_faces(&faces, &st);
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
        let pred = Predictors::new(&nm, v, a, v, a);
        let d = [v[0] * dt + 0.5 * a[0] * dt * dt, v[1] * dt + 0.5 * a[1] * dt * dt];
        let basis = [NodeBasis { s: 1.0, ..NodeBasis::default() }];
        let st = states(&[d[0], d[1], 0.0, d[0], d[1]], 5, &nm);
        let k = interpolate(&basis, &st, &pred, Layout::UPU);
        for c in 0..2 {
            assert!((k.a_u[c] - a[c]).abs() < 1e-9 && (k.a_w[c] - a[c]).abs() < 1e-9, "{k:?}");
            assert!((k.v_u[c] - (v[c] + a[c] * dt)).abs() < 1e-12, "{k:?}");
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
    p.stress = [0.0; soil::NS];
    p.p = 0.0;
    p.grad_n = [0.0; 2];
    p.pred = Predictors::default();
    let st = vec![NodeState::<MAX_DOF>::default(); 4];
    let model = Constitutive::LinearElastic(LinearElastic::new(1e7, 0.3));
    let pt = Point::<2>::new(&basis, &st, &p, &model, Layout::UPU);
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
    let p = ParticleInput { stress: [0.0; soil::NS], ..part() };
    let pt = Point::<2>::new(&basis, &st, &p, &model, Layout::U);
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
            let s0 = soil::plane([-3.0e4, -1.0e4, 4.0e3, -2.0e4]);
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
                s = Point::<2>::new(&basis, &st, &p, &model, Layout::U).upd.stress;
            }
            // A quarter turn: σ_xx ↔ σ_yy, σ_xy → −σ_xy.
            let expected = soil::plane([s0[1], s0[0], -s0[2], s0[3]]);
            let worst = (0..soil::NS).map(|i| (s[i] - expected[i]).abs()).fold(0.0, f64::max);
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

/// The three-dimensional samples of the tests below.
mod three {
    use super::*;

    /// Scratch of the largest three-dimensional stencil.
    pub(super) const M3: usize = MAX_NODES_3D;

    /// A sample basis of `nn` nodes in three dimensions, with B̄ gradients different from its own.
    pub(super) fn basis(nn: usize) -> Vec<NodeBasis<3>> {
        (0..nn)
            .map(|k| {
                let x = k as f64;
                NodeBasis {
                    s: 0.05 + 0.1 * (x * 0.7).sin().abs(),
                    g: [(x * 1.3).cos() * 3.0, (x * 0.9).sin() * 2.0, (x * 0.6 + 0.4).cos() * 2.5],
                    gv: [(x * 1.1).cos() * 2.5, (x * 0.4).sin() * 1.5, (x * 0.8 + 0.2).sin() * 2.0],
                    t: 0.0,
                    tv: 0.0,
                }
            })
            .collect()
    }

    /// Strain operators that differ from [`basis`] (standing for recovered strains).
    pub(super) fn strain(nn: usize) -> Vec<NodeBasis<3>> {
        (0..nn)
            .map(|k| {
                let x = k as f64 + 0.5;
                let g = [(x * 0.8).sin() * 2.5, (x * 1.6).cos() * 1.8, (x * 0.5).cos() * 2.2];
                NodeBasis { s: 0.0, g, gv: g, t: 0.0, tv: 0.0 }
            })
            .collect()
    }

    /// A sample particle: two-phase quantities set, a general stress (every shear non-zero), a
    /// deformation gradient with every entry non-zero.
    pub(super) fn part() -> ParticleInput<3> {
        ParticleInput {
            grad_p: [300.0, -400.0, -9.0e3],
            stress: [-1.0e3, -2.0e3, 150.0, -1.2e3, 80.0, -120.0],
            def_grad: [[1.02, 0.01, -0.02], [-0.03, 0.97, 0.015], [0.01, -0.02, 1.01]],
            body_acc: [0.0, 0.0, -9.81],
            grad_n: [0.7, -1.3, 0.4],
            pred: Predictors {
                a_u: [0.3, -0.2, 0.1],
                v_u: [0.01, 0.02, -0.015],
                a_w: [-0.1, 0.4, 0.2],
                v_w: [0.03, -0.01, 0.02],
            },
            ..lift(&super::part())
        }
    }

    /// A plane particle as a three-dimensional one: its in-plane vectors with z = 0 and F_zz = 1.
    pub(super) fn lift(p: &ParticleInput) -> ParticleInput<3> {
        let v = |a: [f64; 2]| [a[0], a[1], 0.0];
        let f = p.def_grad;
        ParticleInput {
            volume: p.volume,
            porosity: p.porosity,
            mass: p.mass,
            water_mass: p.water_mass,
            drag: p.drag,
            inv_q: p.inv_q,
            mobility: p.mobility,
            water_density: p.water_density,
            grad_p: v(p.grad_p),
            stress: p.stress,
            def_grad: [[f[0][0], f[0][1], 0.0], [f[1][0], f[1][1], 0.0], [0.0, 0.0, 1.0]],
            eps_pd: p.eps_pd,
            p: p.p,
            body_acc: v(p.body_acc),
            grad_n: v(p.grad_n),
            pred: Predictors { a_u: v(p.pred.a_u), v_u: v(p.pred.v_u), a_w: v(p.pred.a_w), v_w: v(p.pred.v_w) },
            linear: p.linear,
            fbar: p.fbar,
            fbar_total: p.fbar_total,
            dt: p.dt,
            jbar: p.jbar,
            fbar_rows: p.fbar_rows,
        }
    }

    /// Three drained faces of a sample particle (a corner: top, right and front), with values and
    /// gradients that differ from the particle's basis.
    pub(super) fn faces(nn: usize) -> Vec<DrainedFace<3, M3>> {
        [
            ([0.0, 0.0, 0.02], [0.1, -0.05, 0.99]),
            ([0.03, 0.0, 0.0], [0.98, -0.2, 0.1]),
            ([0.0, 0.025, 0.0], [0.0, 1.0, 0.0]),
        ]
        .iter()
        .map(|&(offset, n): &([f64; 3], [f64; 3])| {
            let len: f64 = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            let mut basis = [(0.0, [0.0; 3]); M3];
            for (k, b) in basis.iter_mut().take(nn).enumerate() {
                let x = k as f64 + offset[2] * 10.0 + offset[1] * 20.0;
                *b = (
                    0.1 + 0.08 * (x * 0.9).cos().abs(),
                    [(x * 0.8).sin() * 4.0, (x * 1.7).cos() * 3.0, (x * 0.3).sin() * 2.0],
                );
            }
            DrainedFace { offset, normal: n.map(|c| c / len), area: 0.05, penalty: 20.0, basis }
        })
        .collect()
    }

    /// The elastic and the plastic Mohr–Coulomb sample with general three-dimensional stresses.
    pub(super) fn models() -> Vec<(&'static str, Constitutive, Stress)> {
        let el = LinearElastic::new(1e7, 0.3);
        vec![
            ("elastic", Constitutive::LinearElastic(el), [-1.0e3, -2.0e3, 150.0, -1.2e3, 80.0, -120.0]),
            ("mohr-coulomb", mohr_coulomb(1.0e3), [-1.0e4, -4.0e4, 9.0e3, -2.0e4, 3.0e3, -2.0e3]),
        ]
    }

    /// The layouts and schemes of the plane tests in three dimensions, with the F̄ layouts.
    pub(super) fn layouts_and_schemes() -> Vec<(Layout, &'static str, Scheme)> {
        let dt = 1e-3;
        let mut out: Vec<_> = super::layouts_and_schemes().into_iter().map(|(l, n, s)| (l.in_dim(3), n, s)).collect();
        out.push((Layout::U_FBAR.in_dim(3), "static F̄", Scheme::of(&Integration::Static, dt, false)));
        out.push((
            Layout::UP_FBAR.in_dim(3),
            "quasi-static F̄",
            Scheme::of(&Integration::QuasiStatic { theta: 0.7 }, dt, true),
        ));
        out
    }

    /// The finite-difference check of one term in three dimensions.
    pub(super) fn check(
        term: &Term<3, M3>,
        (model, stress): (&Constitutive, Stress),
        layout: Layout,
        nm: &Scheme,
        recovery: bool,
        linear: bool,
    ) -> Vec<BlockError> {
        let mut basis = basis(8);
        let mut p = ParticleInput { stress, linear, ..part() };
        if layout.jbar.is_some() {
            basis.iter_mut().for_each(|b| b.gv = b.g);
            p.jbar = 1.03;
            p.fbar_rows = 2.0e8;
        }
        let recovered = if recovery { strain(8) } else { Vec::new() };
        let ops = super::Operators { basis: &basis, strain: if recovery { &recovered } else { &basis }, forces: &[] };
        check_term_in::<3, M3, MAX_DOF_3D>(term, model, layout, nm, ops, &p, &faces(basis.len()))
    }
}

/// Every term's tangent in three dimensions against central differences, block by block: every
/// layout (u, u–p, u–p–U, F̄) under its schemes, elastic and plastic (a general stress with every
/// shear non-zero), with the basis's own strain operators and with recovered ones, finite strain
/// and (one-phase) geometrically linear.
#[test]
fn every_term_matches_central_differences_in_three_dimensions() {
    for (layout, sname, nm) in three::layouts_and_schemes() {
        let names = layout.field_names();
        for (mname, model, stress) in three::models() {
            // (Geometrically linear steps are one-phase and without F̄, as in the plane test.)
            let one_phase = layout.p.is_none() && layout.w.is_none() && layout.jbar.is_none();
            for term in terms_in::<3, { three::M3 }>() {
                for (recovery, linear) in [(false, false), (true, false), (false, true)] {
                    if linear && !one_phase {
                        continue;
                    }
                    let blocks = three::check(&term, (&model, stress), layout, &nm, recovery, linear);
                    for b in &blocks {
                        let what =
                            format!("{} ({mname}, {names:?}, {sname}, recovered {recovery}, linear {linear})", term.0);
                        assert_block(b, names, &what);
                    }
                    if term.0 == "all" {
                        // Every displacement component is coupled to every other.
                        let at = |r: usize, c: usize| {
                            blocks.iter().find(|b| b.row == r && b.col == c).map_or(0.0, |b| b.jmax)
                        };
                        assert!((0..3).all(|r| (0..3).all(|c| at(r, c) > 0.0)), "{sname} {mname}: u–u blocks missing");
                        if let Some(j) = layout.jbar {
                            assert!(
                                at(0, j) > 0.0 && at(j, 2) > 0.0 && at(j, j) > 0.0,
                                "{sname} {mname}: F̄ couplings missing"
                            );
                        }
                    }
                }
            }
        }
    }
}

/// The three-dimensional samples exercise what the plane ones cannot: the plastic sample returns,
/// the step rotates about a tilted axis and its strain has out-of-plane shears.
#[test]
fn the_three_dimensional_samples_return_rotate_and_shear_out_of_plane() {
    let (_, model, stress) = three::models().remove(1);
    let basis = three::basis(8);
    let nm = Scheme::newmark(0.25, 0.5, 1e-3);
    let p = ParticleInput { stress, ..three::part() };
    let layout = Layout::UPU.in_dim(3);
    let d0 = increments(basis.len() * layout.nd, layout);
    let st = states3(&d0, layout.nd, &nm);
    let pt = Point::<3, { three::M3 }>::new(&basis, &st, &p, &model, layout);
    assert!(pt.upd.eps_pd > 0.0, "{:?}", pt.upd.region);
    let spin = pt.kin.rotation;
    assert!(
        (0..3).all(|i| (0..3).any(|j| i != j && spin[i][j].abs() > 1e-4)),
        "the sample must turn about a tilted axis"
    );
    assert!(pt.kin.deps[4].abs() > 1e-4 && pt.kin.deps[5].abs() > 1e-4, "{:?}", pt.kin.deps);
}

/// A wrong sign in any non-zero block of any term in three dimensions fails the check.
#[test]
fn a_wrong_sign_in_any_block_is_caught_in_three_dimensions() {
    let (_, model, stress) = three::models().remove(0);
    let p = ParticleInput { stress, ..three::part() };
    let cases = three::layouts_and_schemes();
    let mut flipped_blocks = 0;
    for (layout, sname, nm) in [cases[1], cases[4]] {
        let basis = three::basis(8);
        let faces = three::faces(basis.len());
        let nd = layout.nd;
        let m = basis.len() * nd;
        let d0 = increments(m, layout);
        for term in terms_in::<3, { three::M3 }>() {
            let res = |d: &[f64]| {
                let st = states3(d, nd, &nm);
                let pt = Point::<3, { three::M3 }>::new(&basis, &st, &p, &model, layout).with_faces(&faces, &st);
                let mut r = vec![0.0; m];
                (term.1)(&pt, &nm, &mut r);
                r
            };
            let st = states3(&d0, nd, &nm);
            let pt = Point::<3, { three::M3 }>::new(&basis, &st, &p, &model, layout).with_faces(&faces, &st);
            let mut t = vec![0.0; m * m];
            (term.2)(&pt, &nm, &mut t);
            flipped_blocks += flip_every_block(nd, &d0, layout, &res, &t, &format!("{} ({sname})", term.0));
        }
    }
    assert!(flipped_blocks > 130, "only {flipped_blocks} blocks were flipped");
}

/// A plane-strain point is a three-dimensional point whose basis and motion do not depend on z:
/// with a basis whose z gradients are zero, increments with Δu_z = ΔU_z = 0 and a plane stress,
/// the three-dimensional residual and tangent equal the plane ones in every in-plane entry (to
/// round-off: the rotation is formed in another way) and the z rows of the residual vanish, for
/// every layout, elastic and plastic. (Not with F̄: a plane point projects its in-plane
/// deformation, ΔF̄ = (r/J)^{1/2} ΔF with F̄_zz = 1, a three-dimensional one all of it.)
#[test]
fn a_plane_point_is_a_three_dimensional_point_without_z() {
    for (l2, sname, nm) in layouts_and_schemes() {
        let l3 = l2.in_dim(3);
        // The three-dimensional component of each plane one.
        let lift_dof = |c: usize| -> usize {
            match (l2.p, l2.w, l2.jbar) {
                (Some(p), ..) if c == p => l3.p.unwrap(),
                (_, Some(w), _) if c >= w && c < w + 2 => l3.w.unwrap() + c - w,
                (.., Some(j)) if c == j => l3.jbar.unwrap(),
                _ => c,
            }
        };
        for (mname, model, stress) in models() {
            let b2 = sample(6);
            let b3: Vec<NodeBasis<3>> = b2
                .iter()
                .map(|b| NodeBasis { s: b.s, g: [b.g[0], b.g[1], 0.0], gv: [b.gv[0], b.gv[1], 0.0], t: 0.0, tv: 0.0 })
                .collect();
            let p2 = ParticleInput { stress, ..part() };
            let p3 = three::lift(&p2);
            let (n2, n3) = (l2.nd, l3.nd);
            let d2 = increments(b2.len() * n2, l2);
            let mut d3 = vec![0.0; b2.len() * n3];
            for (i, x) in d2.iter().enumerate() {
                d3[(i / n2) * n3 + lift_dof(i % n2)] = *x;
            }
            let (s2, s3) = (states(&d2, n2, &nm), states3(&d3, n3, &nm));
            let pt2 = Point::<2>::new(&b2, &s2, &p2, &model, l2);
            let pt3 = Point::<3, { three::M3 }>::new(&b3, &s3, &p3, &model, l3);
            let (m2, m3) = (d2.len(), d3.len());
            let (mut r2, mut r3, mut t2, mut t3) =
                (vec![0.0; m2], vec![0.0; m3], vec![0.0; m2 * m2], vec![0.0; m3 * m3]);
            residual(&pt2, &nm, &mut r2);
            residual(&pt3, &nm, &mut r3);
            tangent(&pt2, &nm, &mut t2);
            tangent(&pt3, &nm, &mut t3);
            let what = format!("{mname}, {:?}, {sname}", l2.field_names());
            let lift = |i: usize| (i / n2) * n3 + lift_dof(i % n2);
            // Each field against its own scale.
            let scale = |r: &[f64], nd: usize, c: usize| {
                (0..r.len()).filter(|i| i % nd == c).fold(0.0f64, |s, i| s.max(r[i].abs()))
            };
            for i in 0..m2 {
                let tol = 1e-10 * scale(&r2, n2, i % n2);
                assert!(
                    (r2[i] - r3[lift(i)]).abs() <= tol,
                    "{what}: residual row {i}: {} against {}",
                    r2[i],
                    r3[lift(i)]
                );
                let row_scale = (0..m2).fold(0.0f64, |s, j| s.max(t2[i * m2 + j].abs()));
                for j in 0..m2 {
                    let (a, b) = (t2[i * m2 + j], t3[lift(i) * m3 + lift(j)]);
                    assert!((a - b).abs() <= 1e-10 * row_scale, "{what}: tangent ({i}, {j}): {a} against {b}");
                }
            }
            for k in 0..b2.len() {
                assert!(r3[k * n3 + 2].abs() <= 1e-10 * scale(&r3, n3, 0), "{what}: a z force {}", r3[k * n3 + 2]);
            }
        }
    }
}

/// The equilibrium identity of the forces in three dimensions: for a GIMP and a cubic B-spline
/// stencil of a point in a three-dimensional grid and a homogeneous motion Δu_i = H x_i (every
/// entry of H non-zero, up to 20 %), the effective-stress and pore-pressure forces satisfy
/// Σ_i f_i = 0 and Σ_i f_i ⊗ x'_i = V_{n+1} (σ'_{n+1} − p I) on the moved nodes x'_i = x_i + Δu_i
/// (the basis reproduces linear fields), with σ'_{n+1} a general stress with every shear non-zero.
#[test]
fn the_forces_of_a_homogeneous_state_in_three_dimensions_are_its_stress() {
    use crate::model::grid::Grid;
    use crate::model::shape::{self, Basis};
    let grid: Grid<3> = Grid::new([0.0, -0.5, 1.0], [0.5, 0.25, 0.4], [6, 6, 6]);
    let model = Constitutive::LinearElastic(LinearElastic::new(1e7, 0.3));
    let nm = Scheme::of(&Integration::Static, 1.0, false);
    let layout = Layout::UP.in_dim(3);
    for basis_kind in [Basis::Gimp, Basis::BSpline3] {
        let (x, lp) = ([1.37, 0.21, 2.13], [0.125, 0.0625, 0.1]);
        let st: shape::Stencil<3, { three::M3 }> = shape::stencil_in(basis_kind, &grid, x, lp);
        let mut basis = Vec::new();
        plain_basis(&st, &[0.0; three::M3], &mut basis);
        let nodes: Vec<[f64; 3]> = st.iter().map(|(n, _, _)| grid.position(n.map(|i| i as usize))).collect();
        for scale in [1e-3, 0.2] {
            let h = [[0.3, -0.2, 0.5], [0.4, -0.6, 0.1], [-0.35, 0.25, 0.45]].map(|r| r.map(|v| v * scale));
            let du = |y: [f64; 3]| -> [f64; 3] { std::array::from_fn(|a| (0..3).map(|b| h[a][b] * y[b]).sum()) };
            let d: Vec<f64> = nodes
                .iter()
                .flat_map(|&y| {
                    let u = du(y);
                    [u[0], u[1], u[2], 0.0]
                })
                .collect();
            let states = states3(&d, layout.nd, &nm);
            let p = ParticleInput { stress: [-3.0e4, -1.0e4, 4.0e3, -2.0e4, -2.5e3, 1.5e3], ..three::part() };
            let pt = Point::<3, { three::M3 }>::new(&basis, &states, &p, &model, layout);
            let mut f = vec![0.0; d.len()];
            stress::residual(&pt, &nm, &mut f);
            stress::pore_pressure::residual(&pt, &nm, &mut f);
            let s = crate::model::soil::principal::tensor(&pt.upd.stress);
            let v = pt.volume_new();
            let mut moment = [[0.0; 3]; 3];
            for (k, y) in nodes.iter().enumerate() {
                let moved: [f64; 3] = std::array::from_fn(|b| y[b] + du(*y)[b]);
                for a in 0..3 {
                    for b in 0..3 {
                        moment[a][b] += f[k * layout.nd + a] * moved[b];
                    }
                }
            }
            for a in 0..3 {
                let sum: f64 = (0..nodes.len()).map(|k| f[k * layout.nd + a]).sum();
                assert!(sum.abs() < 1e-9 * 3.0e4 * v, "{basis_kind:?} {scale}: Σ f_{a} = {sum}");
                for b in 0..3 {
                    let want = v * (s[a][b] - if a == b { pt.p } else { 0.0 });
                    assert!(
                        (moment[a][b] - want).abs() < 1e-9 * 3.0e4 * v,
                        "{basis_kind:?} {scale}: (Σ f ⊗ x'){a}{b} = {} against V σ = {want}",
                        moment[a][b]
                    );
                }
            }
        }
    }
}
