//! The kernels' checks in three dimensions: every term against central differences, wrong signs
//! caught, a plane point as a three-dimensional one without z, and the forces of a homogeneous
//! state.

use super::*;

/// The three-dimensional samples of the tests below.
mod samples {
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
            pred: Motion {
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
            pred: Motion { a_u: v(p.pred.a_u), v_u: v(p.pred.v_u), a_w: v(p.pred.a_w), v_w: v(p.pred.v_w) },
            linear: p.linear,
            fbar: p.fbar,
            fbar_total: p.fbar_total,
            dt: p.dt,
            jbar: p.jbar,
            fbar_rows: p.fbar_rows,
            control: p.control,
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
    for (layout, sname, nm) in samples::layouts_and_schemes() {
        let names = layout.field_names();
        for (mname, model, stress) in samples::models() {
            // (Geometrically linear steps are one-phase and without F̄, as in the plane test.)
            let one_phase = layout.p.is_none() && layout.w.is_none() && layout.jbar.is_none();
            for term in terms_in::<3, { samples::M3 }>() {
                for (recovery, linear) in [(false, false), (true, false), (false, true)] {
                    if linear && !one_phase {
                        continue;
                    }
                    let blocks = samples::check(&term, (&model, stress), layout, &nm, recovery, linear);
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

/// The finite-strain solids' tangents in three dimensions against central differences, block by
/// block: neo-Hookean and Hencky–J2 (elastic and plastic, general stresses) in every layout and
/// scheme, with the basis's own strain operators and with recovered ones; and the plastic sample
/// flows.
#[test]
fn finite_strain_solids_match_central_differences_in_three_dimensions() {
    let hencky = Constitutive::HenckyJ2(soils::HenckyJ2Law::new(1e7, 0.3, 1.5e4, 0.75e4, 5.0));
    let models = [
        ("neo-Hookean", Constitutive::NeoHookean(soils::NeoHookeanLaw::new(1e7, 0.3)), [0.0; soils::NS]),
        ("Hencky-J2 elastic", hencky, [-1.0e3, -2.0e3, 150.0, -1.2e3, 80.0, -120.0]),
        ("Hencky-J2 plastic", hencky, [-1.0e4, -4.0e4, 9.0e3, -2.0e4, 3.0e3, -2.0e3]),
    ];
    for (layout, sname, nm) in samples::layouts_and_schemes().into_iter().filter(|(l, ..)| l.jbar.is_none()) {
        let names = layout.field_names();
        for (mname, model, stress) in models {
            for term in terms_in::<3, { samples::M3 }>() {
                for recovery in [false, true] {
                    for b in &samples::check(&term, (&model, stress), layout, &nm, recovery, false) {
                        assert_block(
                            b,
                            names,
                            &format!("{} ({mname}, {names:?}, {sname}, recovered {recovery})", term.0),
                        );
                    }
                }
            }
        }
    }
    let (basis, p) = (samples::basis(8), ParticleInput { stress: models[2].2, ..samples::part() });
    let d0 = increments(basis.len() * 3, Layout::U.in_dim(3));
    let st = states3(&d0, 3, &Scheme::of(&Integration::Static, 1e-3, false));
    let pt = Point::<3, { samples::M3 }>::with_recovery(&basis, &basis, &st, &p, &models[2].1, Layout::U.in_dim(3));
    assert_ne!(pt.upd.region, soils::Region::Elastic, "the plastic sample stays elastic");
}

/// The three-dimensional samples exercise what the plane ones cannot: the plastic sample returns,
/// the step rotates about a tilted axis and its strain has out-of-plane shears.
#[test]
fn the_three_dimensional_samples_return_rotate_and_shear_out_of_plane() {
    let (_, model, stress) = samples::models().remove(1);
    let basis = samples::basis(8);
    let nm = Scheme::newmark(0.25, 0.5, 1e-3);
    let p = ParticleInput { stress, ..samples::part() };
    let layout = Layout::UPU.in_dim(3);
    let d0 = increments(basis.len() * layout.nd, layout);
    let st = states3(&d0, layout.nd, &nm);
    let pt = Point::<3, { samples::M3 }>::with_recovery(&basis, &basis, &st, &p, &model, layout);
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
    let (_, model, stress) = samples::models().remove(0);
    let p = ParticleInput { stress, ..samples::part() };
    let cases = samples::layouts_and_schemes();
    let mut flipped_blocks = 0;
    for (layout, sname, nm) in [cases[1], cases[4]] {
        let basis = samples::basis(8);
        let faces = samples::faces(basis.len());
        let nd = layout.nd;
        let m = basis.len() * nd;
        let d0 = increments(m, layout);
        for term in terms_in::<3, { samples::M3 }>() {
            let res = |d: &[f64]| {
                let st = states3(d, nd, &nm);
                let pt = Point::<3, { samples::M3 }>::with_recovery(&basis, &basis, &st, &p, &model, layout)
                    .with_faces(&faces, &st);
                let mut r = vec![0.0; m];
                (term.1)(&pt, &nm, &mut r);
                r
            };
            let st = states3(&d0, nd, &nm);
            let pt = Point::<3, { samples::M3 }>::with_recovery(&basis, &basis, &st, &p, &model, layout)
                .with_faces(&faces, &st);
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
            let p3 = samples::lift(&p2);
            let (n2, n3) = (l2.nd, l3.nd);
            let d2 = increments(b2.len() * n2, l2);
            let mut d3 = vec![0.0; b2.len() * n3];
            for (i, x) in d2.iter().enumerate() {
                d3[(i / n2) * n3 + lift_dof(i % n2)] = *x;
            }
            let (s2, s3) = (states(&d2, n2, &nm), states3(&d3, n3, &nm));
            let pt2 = Point::<2>::with_recovery(&b2, &b2, &s2, &p2, &model, l2);
            let pt3 = Point::<3, { samples::M3 }>::with_recovery(&b3, &b3, &s3, &p3, &model, l3);
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
        let st: shape::Stencil<3, { samples::M3 }> = shape::stencil_in(basis_kind, &grid, x, lp);
        let mut basis = Vec::new();
        plain_basis(&st, &[0.0; samples::M3], &mut basis);
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
            let p = ParticleInput { stress: [-3.0e4, -1.0e4, 4.0e3, -2.0e4, -2.5e3, 1.5e3], ..samples::part() };
            let pt = Point::<3, { samples::M3 }>::with_recovery(&basis, &basis, &states, &p, &model, layout);
            let mut f = vec![0.0; d.len()];
            stress::residual(&pt, &nm, &mut f);
            stress::pore_pressure::residual(&pt, &nm, &mut f);
            let s = crate::soils::principal::tensor(&pt.upd.stress);
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
