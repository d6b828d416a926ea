use super::*;
use principal::Principal;

const KPA: f64 = 1e3;

fn mc(phi_deg: f64, c: f64, psi_deg: f64, tension: Option<f64>) -> Constitutive {
    Constitutive::MohrCoulomb(MohrCoulombLaw {
        elastic: LinearElastic::new(10e3 * KPA, 0.3),
        phi: phi_deg.to_radians(),
        cohesion: c,
        residual_cohesion: c,
        softening_strain: f64::INFINITY,
        psi_ini: psi_deg.to_radians(),
        psi_crit: psi_deg.to_radians(),
        eta: 0.0,
        tension,
    })
}

fn softening_mc() -> Constitutive {
    Constitutive::MohrCoulomb(MohrCoulombLaw {
        elastic: LinearElastic::new(10e3 * KPA, 0.3),
        phi: 25f64.to_radians(),
        cohesion: 20.0 * KPA,
        residual_cohesion: 5.0 * KPA,
        softening_strain: 0.05,
        psi_ini: (-5f64).to_radians(),
        psi_crit: 0.0,
        eta: 25.0,
        tension: Some(2.0 * KPA),
    })
}

fn vm(c: f64, c_r: f64, h: f64) -> Constitutive {
    Constitutive::VonMises(VonMisesLaw {
        elastic: LinearElastic::new(1e3 * KPA, 0.35),
        cohesion: c,
        residual_cohesion: c_r,
        softening_modulus: h,
    })
}

/// The plane stress [xx, yy, xy, zz, 0, 0] with principal values `l` (l[2] out of plane) rotated by
/// `theta` about z.
fn stress_with(l: [f64; 3], theta: f64) -> Stress {
    Principal::in_plane(l, theta).compose(&l)
}

/// A general rotation (its axis in no coordinate plane).
fn tilt() -> [[f64; 3]; 3] {
    let n = 14f64.sqrt();
    principal::rotation([1.0 / n, -2.0 / n, 3.0 / n], 0.83)
}

/// The stress with principal values `l` along the columns of `r` (every shear non-zero).
fn stress_in(l: [f64; 3], r: &[[f64; 3]; 3]) -> Stress {
    principal::rotate(r, &[l[0], l[1], 0.0, l[2], 0.0, 0.0])
}

/// A start state and strain increment whose elastic trial is `trial` (with out-of-plane strains
/// when `out_of_plane`).
fn start_for_3d(model: &Constitutive, trial: Stress, out_of_plane: bool) -> (Stress, Stress) {
    let g = if out_of_plane { 1.0 } else { 0.0 };
    let deps = [1.3e-4, -2.1e-4, 0.7e-4, 0.0, 0.4e-4 * g, -0.9e-4 * g];
    let el = model.elastic();
    let de = el.trial(&[0.0; NS], &deps);
    (std::array::from_fn(|c| trial[c] - de[c]), deps)
}

/// A start state and in-plane strain increment whose elastic trial is `trial`.
fn start_for(model: &Constitutive, trial: Stress) -> (Stress, Stress) {
    start_for_3d(model, trial, false)
}

/// Largest |analytic − central difference| of the tangent, relative to the elastic modulus (all
/// six components: the out-of-plane ones take a plane state out of its plane).
fn tangent_error(model: &Constitutive, s0: &Stress, eps: f64, deps: &Stress) -> f64 {
    let u = model.update(s0, eps, deps);
    let scale = model.elastic().d[0][0];
    let mut worst: f64 = 0.0;
    for c in 0..NS {
        let h = 1e-9;
        let (mut dp, mut dm) = (*deps, *deps);
        dp[c] += h;
        dm[c] -= h;
        let (up, um) = (model.update(s0, eps, &dp), model.update(s0, eps, &dm));
        for r in 0..NS {
            let fd = (up.stress[r] - um.stress[r]) / (2.0 * h);
            worst = worst.max((fd - u.tangent[r][c]).abs() / scale);
        }
    }
    worst
}

fn principal_sorted(s: &Stress) -> [f64; 3] {
    let mut v = Principal::of(s).values;
    v.sort_by(|a, b| b.total_cmp(a));
    v
}

fn mc_f(m: &MohrCoulombLaw, s: &[f64; 3], eps: f64) -> f64 {
    let (c, _) = m.cohesion_at(eps);
    (s[0] - s[2]) + (s[0] + s[2]) * m.phi.sin() - 2.0 * c * m.phi.cos()
}

#[test]
fn plane_strain_elasticity_gives_the_constrained_modulus_in_an_oedometer() {
    let el = LinearElastic::new(1e7, 0.3);
    let m = Constitutive::LinearElastic(el);
    let u = m.update(&[0.0; NS], 0.0, &[0.0, -1e-3, 0.0, 0.0, 0.0, 0.0]);
    let ec = 1e7 * 0.7 / (1.3 * 0.4);
    assert!((u.stress[1] + ec * 1e-3).abs() < 1e-6 * ec);
    assert!((u.stress[0] / u.stress[1] - 0.3 / 0.7).abs() < 1e-12);
    assert!((u.stress[3] - u.stress[0]).abs() < 1e-9);
    assert!((el.shear_modulus() - 1e7 / 2.6).abs() < 1e-6);
}

#[test]
fn an_elastic_step_of_a_plastic_model_is_elastic() {
    let m = mc(30.0, 10.0 * KPA, 10.0, None);
    let s0 = [-50.0 * KPA, -60.0 * KPA, 2.0 * KPA, -55.0 * KPA, 0.0, 0.0];
    let de = [1e-6, -1e-6, 0.0, 0.0, 0.0, 0.0];
    let u = m.update(&s0, 0.0, &de);
    assert_eq!(u.region, Region::Elastic);
    assert_eq!(u.tangent, m.elastic().d);
    assert_eq!(u.eps_pd, 0.0);
}

#[test]
fn mohr_coulomb_returns_to_the_surface_in_every_region_with_the_exact_tangent() {
    // Trial principal stresses chosen in each region (kPa), with the out-of-plane one at each position.
    let cases: [(Constitutive, [f64; 3], Region); 7] = [
        (mc(30.0, 10.0 * KPA, 10.0, None), [-10.0, -50.0, -150.0], Region::Plane),
        (mc(30.0, 10.0 * KPA, 10.0, None), [-10.0, -140.0, -150.0], Region::EdgeLeft),
        (mc(30.0, 10.0 * KPA, 10.0, None), [-10.0, -15.0, -150.0], Region::EdgeRight),
        (mc(30.0, 10.0 * KPA, 10.0, None), [50.0, 40.0, 30.0], Region::Apex),
        (mc(30.0, 10.0 * KPA, 10.0, Some(5.0 * KPA)), [8.0, -5.0, -10.0], Region::Tension),
        (mc(30.0, 10.0 * KPA, 10.0, Some(5.0 * KPA)), [40.0, -5.0, -10.0], Region::TensionCorner),
        (mc(0.0, 10.0 * KPA, 0.0, None), [-10.0, -30.0, -60.0], Region::Plane),
    ];
    for (model, l, region) in cases {
        let Constitutive::MohrCoulomb(p) = model else { unreachable!() };
        for (perm, theta) in [([0, 1, 2], 0.3), ([2, 0, 1], -1.1), ([1, 2, 0], 2.0)] {
            let trial = stress_with([l[perm[0]] * KPA, l[perm[1]] * KPA, l[perm[2]] * KPA], theta);
            let (s0, de) = start_for(&model, trial);
            let u = model.update(&s0, 0.0, &de);
            assert_eq!(u.region, region, "{l:?} {perm:?}");
            let s = principal_sorted(&u.stress);
            let f = mc_f(&p, &s, u.eps_pd);
            assert!(f <= 1e-6 * KPA, "{region:?}: f = {f}");
            if !matches!(region, Region::Tension | Region::Apex) {
                assert!(f.abs() <= 1e-6 * KPA, "{region:?}: on the surface, f = {f}");
            }
            if let Some(t) = p.tension {
                assert!(s[0] <= t + 1e-6, "{region:?}: σ₁ = {} above the cut-off {t}", s[0]);
            }
            match region {
                Region::EdgeLeft => assert!((s[1] - s[2]).abs() < 1e-6 * KPA, "{s:?}"),
                Region::EdgeRight => assert!((s[0] - s[1]).abs() < 1e-6 * KPA, "{s:?}"),
                Region::Apex => {
                    let apex = p.cohesion / p.phi.tan();
                    assert!(s.iter().all(|v| (v - apex).abs() < 1e-6 * KPA), "{s:?} vs {apex}");
                }
                _ => {}
            }
            assert!(u.eps_pd > 0.0);
            let e = tangent_error(&model, &s0, 0.0, &de);
            assert!(e < 1e-6, "{region:?} {perm:?}: tangent error {e:e}");
        }
    }
}

#[test]
fn softening_and_dilatancy_evolve_and_the_tangent_stays_exact() {
    let model = softening_mc();
    let Constitutive::MohrCoulomb(p) = model else { unreachable!() };
    // Cohesion falls linearly to the residual value, ψ decays towards ψ_crit.
    assert_eq!(p.cohesion_at(0.0).0, 20.0 * KPA);
    assert!((p.cohesion_at(0.025).0 - 12.5 * KPA).abs() < 1e-9);
    assert_eq!(p.cohesion_at(0.1), (5.0 * KPA, 0.0));
    assert!((p.dilation_at(0.1) - (-5f64).to_radians() * (-2.5f64).exp()).abs() < 1e-12);
    for (l, eps0) in [([-10.0, -80.0, -300.0], 0.0), ([-10.0, -80.0, -300.0], 0.02), ([-5.0, -280.0, -300.0], 0.01)] {
        let trial = stress_with([l[0] * KPA, l[1] * KPA, l[2] * KPA], 0.4);
        let (s0, de) = start_for(&model, trial);
        let u = model.update(&s0, eps0, &de);
        assert_ne!(u.region, Region::Elastic);
        assert!(u.eps_pd > eps0);
        let f = mc_f(&p, &principal_sorted(&u.stress), u.eps_pd);
        assert!(f.abs() < 1e-6 * KPA, "f = {f} with the softened cohesion");
        let e = tangent_error(&model, &s0, eps0, &de);
        assert!(e < 1e-6, "tangent error {e:e} at ε̄ = {eps0}");
    }
    // Past ε_r the cohesion is the residual one.
    let trial = stress_with([-10.0 * KPA, -80.0 * KPA, -300.0 * KPA], 0.0);
    let (s0, de) = start_for(&model, trial);
    let u = model.update(&s0, 0.2, &de);
    assert!(mc_f(&p, &principal_sorted(&u.stress), u.eps_pd).abs() < 1e-6 * KPA);
}

#[test]
fn negative_dilation_contracts_and_positive_dilation_dilates() {
    // In a plastic step the plastic volume change has the sign of sin ψ (tension positive):
    // tr Δε_p = Δγ · 2 sin ψ on the main plane.
    for (psi, sign) in [(-5.0, -1.0), (5.0, 1.0)] {
        let model = mc(25.0, 3.0 * KPA, psi, None);
        let trial = stress_with([-10.0 * KPA, -40.0 * KPA, -120.0 * KPA], 0.2);
        let (s0, de) = start_for(&model, trial);
        let u = model.update(&s0, 0.0, &de);
        assert_eq!(u.region, Region::Plane);
        // Δσ_mean = K (Δε_v − Δε_v^p): the returned mean is above (below) the trial mean for
        // contraction (dilation) under compression positive... here tension positive.
        let el = model.elastic();
        let k = el.lame() + 2.0 * el.shear_modulus() / 3.0;
        let dmean = (u.stress[0] + u.stress[1] + u.stress[3] - trial[0] - trial[1] - trial[3]) / 3.0;
        let dev_p = -dmean / k;
        assert!(dev_p * sign > 0.0, "ψ = {psi}: plastic volume change {dev_p}");
    }
}

#[test]
fn the_return_is_invariant_to_a_rotation_of_the_stress() {
    let model = softening_mc();
    let l = [-10.0 * KPA, -80.0 * KPA, -300.0 * KPA];
    let a = model.update(&start_for(&model, stress_with(l, 0.0)).0, 0.0, &start_for(&model, stress_with(l, 0.0)).1);
    for theta in [0.5, 1.3, -2.2] {
        let (s0, de) = start_for(&model, stress_with(l, theta));
        let b = model.update(&s0, 0.0, &de);
        let (pa, pb) = (principal_sorted(&a.stress), principal_sorted(&b.stress));
        for k in 0..3 {
            assert!((pa[k] - pb[k]).abs() < 1e-6, "θ = {theta}: {pa:?} vs {pb:?}");
        }
        assert!((a.eps_pd - b.eps_pd).abs() < 1e-12);
        // The returned stress is coaxial with the trial stress.
        assert!(commutator(&stress_with(l, theta), &b.stress) < 1e-9, "θ = {theta}");
    }
}

#[test]
fn tresca_limits_the_largest_shear_stress_to_the_cohesion() {
    let model = mc(0.0, 10.0 * KPA, 0.0, None);
    for l in [[0.0, -35.0, -80.0], [-20.0, -25.0, -90.0], [-5.0, -70.0, -72.0]] {
        let trial = stress_with([l[0] * KPA, l[1] * KPA, l[2] * KPA], 0.7);
        let (s0, de) = start_for(&model, trial);
        let u = model.update(&s0, 0.0, &de);
        let s = principal_sorted(&u.stress);
        assert!(((s[0] - s[2]) / 2.0 - 10.0 * KPA).abs() < 1e-6, "{s:?}");
        // Isochoric: the mean stress is the trial's.
        let mean = |v: &Stress| (v[0] + v[1] + v[3]) / 3.0;
        assert!((mean(&u.stress) - mean(&trial)).abs() < 1e-6);
        assert!(tangent_error(&model, &s0, 0.0, &de) < 1e-6);
    }
}

#[test]
fn von_mises_returns_radially_and_softens_to_the_residual_strength() {
    let model = vm(12.0 * KPA, 3.0 * KPA, -30.0 * KPA);
    let Constitutive::VonMises(p) = model else { unreachable!() };
    let q = |s: &Stress| crate::soils::invariants(s).1;
    for (eps0, l) in [
        (0.0, [0.0, -40.0, -10.0]),
        (0.1, [5.0, -60.0, -20.0]),
        (0.29, [0.0, -40.0, -10.0]),
        (0.5, [0.0, -40.0, -10.0]),
    ] {
        let trial = stress_with([l[0] * KPA, l[1] * KPA, l[2] * KPA], -0.6);
        let (s0, de) = start_for(&model, trial);
        let u = model.update(&s0, eps0, &de);
        assert_eq!(u.region, Region::Plane);
        let (c, _) = p.cohesion_at(u.eps_pd);
        assert!(
            (q(&u.stress) - 3f64.sqrt() * c).abs() < 1e-6,
            "ε̄ {eps0}: q = {} vs √3 c = {}",
            q(&u.stress),
            3f64.sqrt() * c
        );
        assert!(tangent_error(&model, &s0, eps0, &de) < 1e-6, "tangent at ε̄ = {eps0}");
    }
    assert_eq!(p.cohesion_at(1.0).0, 3.0 * KPA);
}

/// ‖T S − S T‖/(‖T‖‖S‖) of two stresses: zero when they are coaxial.
fn commutator(t: &Stress, s: &Stress) -> f64 {
    let (a, b) = (principal::tensor(t), principal::tensor(s));
    let mut worst: f64 = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            let c: f64 = (0..3).map(|k| a[i][k] * b[k][j] - b[i][k] * a[k][j]).sum();
            worst = worst.max(c.abs());
        }
    }
    let norm = |m: [[f64; 3]; 3]| m.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
    worst / (norm(a) * norm(b)).max(f64::MIN_POSITIVE)
}

/// A three-dimensional state (every shear non-zero) returns as its plane-strain twin does, turned
/// with it: the same principal stresses, ε̄ and region, R σ Rᵀ, and the tangent exact in all six
/// components, in every Mohr–Coulomb region, for von Mises and with softening; and a rotation of
/// the whole step (trial stress and strain increment) rotates the returned stress.
#[test]
fn a_general_three_dimensional_state_returns_as_its_rotated_plane_twin() {
    let r = tilt();
    let cases: Vec<(Constitutive, [f64; 3], f64)> = vec![
        (mc(30.0, 10.0 * KPA, 10.0, None), [-10.0, -50.0, -150.0], 0.0),
        (mc(30.0, 10.0 * KPA, 10.0, None), [-10.0, -140.0, -150.0], 0.0),
        (mc(30.0, 10.0 * KPA, 10.0, None), [-10.0, -15.0, -150.0], 0.0),
        (mc(30.0, 10.0 * KPA, 10.0, None), [50.0, 40.0, 30.0], 0.0),
        (mc(30.0, 10.0 * KPA, 10.0, Some(5.0 * KPA)), [8.0, -5.0, -10.0], 0.0),
        (mc(30.0, 10.0 * KPA, 10.0, Some(5.0 * KPA)), [40.0, -5.0, -10.0], 0.0),
        (mc(0.0, 10.0 * KPA, 0.0, None), [-10.0, -30.0, -60.0], 0.0),
        (softening_mc(), [-10.0, -80.0, -300.0], 0.02),
        (vm(12.0 * KPA, 3.0 * KPA, -30.0 * KPA), [5.0, -60.0, -20.0], 0.1),
    ];
    for (model, l, eps0) in cases {
        let l = l.map(|v| v * KPA);
        // The plane twin: principal values along x, y, z.
        let plane_trial = stress_in(l, &principal::rotation([0.0, 0.0, 1.0], 0.0));
        let (p0, pde) = start_for(&model, plane_trial);
        let flat = model.update(&p0, eps0, &pde);
        // The same trial turned by R, reached from a start with out-of-plane strains.
        let trial = stress_in(l, &r);
        assert!(trial[4].abs() > 1.0 && trial[5].abs() > 1.0, "{trial:?}");
        let (s0, de) = start_for_3d(&model, trial, true);
        let u = model.update(&s0, eps0, &de);
        assert_eq!(u.region, flat.region, "{l:?}");
        assert!((u.eps_pd - flat.eps_pd).abs() <= 1e-12 * flat.eps_pd.max(1e-12), "{l:?}");
        let turned = principal::rotate(&r, &flat.stress);
        for c in 0..NS {
            assert!((u.stress[c] - turned[c]).abs() < 1e-6, "{l:?} component {c}: {:?} vs {turned:?}", u.stress);
        }
        let e = tangent_error(&model, &s0, eps0, &de);
        assert!(e < 1e-6, "{:?} {l:?}: tangent error {e:e}", u.region);
    }
}

/// D^e's structured products (its [xx, yy, xy, zz] block and the two out-of-plane shears apart)
/// are the full 6 × 6 ones.
#[test]
fn the_structured_elastic_products_are_the_full_ones() {
    let el = LinearElastic::new(3.0e7, 0.35);
    let m: Mat6 = std::array::from_fn(|r| std::array::from_fn(|c| ((r * 7 + c * 3) as f64 * 0.37).sin()));
    let v: Stress = std::array::from_fn(|c| (c as f64 * 1.3).cos() * 1e-3);
    let full = |r: usize, c: usize| (0..NS).map(|k| m[r][k] * el.d[k][c]).sum::<f64>();
    let product = el.right_multiply(&m);
    let trial = el.trial(&[0.0; NS], &v);
    for r in 0..NS {
        for (c, p) in product[r].iter().enumerate() {
            assert!((p - full(r, c)).abs() <= 1e-15 * el.d[0][0], "m D [{r}][{c}]");
        }
        let dv: f64 = (0..NS).map(|c| el.d[r][c] * v[c]).sum();
        assert!((trial[r] - dv).abs() <= 1e-15 * el.d[0][0], "D v [{r}]");
    }
}

/// A strength reduction factor F divides c_p and tan φ, keeps ψ ≤ φ' and c_r ≤ c_p/F, leaves
/// the stiffness and a residual below the reduced peak alone, and leaves models without a
/// strength unchanged.
#[test]
fn a_strength_reduction_divides_the_peak_strength() {
    let mc = MohrCoulomb {
        young_modulus: 1e7,
        poisson_ratio: 0.3,
        friction_angle: 30.0,
        cohesion: 10e3,
        residual_cohesion: Some(8e3),
        softening_strain: Some(0.1),
        dilation_angle: 25.0,
        critical_dilation_angle: Some(5.0),
        dilation_decay: 0.0,
        tension_cutoff: None,
    };
    let SoilModel::MohrCoulomb(r) = SoilModel::MohrCoulomb(mc).with_strength_reduced(2.0) else { unreachable!() };
    assert_eq!(r.young_modulus, 1e7);
    assert_eq!(r.cohesion, 5e3);
    let phi = (30f64.to_radians().tan() / 2.0).atan().to_degrees();
    assert!((r.friction_angle - phi).abs() < 1e-12 && (phi - 16.102).abs() < 1e-3, "{}", r.friction_angle);
    assert_eq!(r.dilation_angle, r.friction_angle);
    assert_eq!(r.critical_dilation_angle, Some(5.0));
    assert_eq!(r.residual_cohesion, Some(5e3));
    let hj = HenckyJ2 {
        young_modulus: 25e6,
        poisson_ratio: 0.499,
        cohesion: 28868.0,
        residual_cohesion: Some(1732.0),
        softening_rate: 5.0,
    };
    let SoilModel::HenckyJ2(r) = SoilModel::HenckyJ2(hj).with_strength_reduced(1.65) else { unreachable!() };
    assert!((r.cohesion - 28868.0 / 1.65).abs() < 1e-9);
    assert_eq!((r.residual_cohesion, r.softening_rate), (Some(1732.0), 5.0));
    let el = LinearElasticParameters(Elasticity { young_modulus: 1e6, poisson_ratio: 0.3 });
    assert!(matches!(SoilModel::LinearElastic(el).with_strength_reduced(3.0), SoilModel::LinearElastic(e) if e == el));
}

/// Each model's `type` in the registry ([`SoilModel::kind`]) is the tag serde reads and the JSON
/// schema (the case reference) shows, in the registry's order.
#[test]
fn every_kind_is_the_type_its_table_is_chosen_by() {
    let schema = serde_json::to_value(schemars::schema_for!(SoilModel)).unwrap();
    let tags: Vec<&str> = schema["oneOf"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["properties"]["type"]["const"].as_str().unwrap())
        .collect();
    assert_eq!(tags, SoilModel::KINDS);
}

/// Trial stresses about the yield surface: mean stress p, a deviatoric direction u (|u| = 1,
/// rotated by [`tilt`]) and a norm R about the R* at which `yield_norm(p, u)` puts the surface:
/// R = R*(1 + δ) with δ from 1e-12 to 1 on both sides, or (`inside`) R from 0 to 0.6 R*.
fn trials_about_the_surface(c: f64, inside: bool, yield_norm: impl Fn(f64, [f64; 3]) -> f64) -> Vec<Stress> {
    let mut seed = 12345u64;
    let mut next = move || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut out = Vec::new();
    for i in 0..4000 {
        let p = c * (2.0 - 60.0 * next());
        let lode = std::f64::consts::PI * next();
        // A deviatoric unit vector of Lode angle `lode` (components summing to zero).
        let u = [0.0, 2.0, 4.0].map(|k: f64| (2.0f64 / 3.0).sqrt() * (lode - k * std::f64::consts::PI / 3.0).cos());
        let delta = (if i % 2 == 0 { 1.0 } else { -1.0 }) * 10f64.powf(-12.0 * next());
        let r = yield_norm(p, u) * if inside { 0.6 * next() } else { 1.0 + delta };
        if r > 0.0 {
            out.push(stress_in([p + r * u[0], p + r * u[1], p + r * u[2]], &tilt()));
        }
    }
    out
}

#[test]
fn the_invariant_pre_check_never_calls_a_plastic_trial_elastic() {
    let c = 10.0 * KPA;
    let models = [mc(30.0, c, 10.0, None), mc(0.0, c, 0.0, None), mc(30.0, c, 10.0, Some(0.2 * c)), softening_mc()];
    for model in models {
        let Constitutive::MohrCoulomb(law) = model else { unreachable!() };
        let eps = if law.softening_strain.is_finite() { 0.02 } else { 0.0 };
        let (c_n, _) = law.cohesion_at(eps);
        let (sp, cp) = law.phi.sin_cos();
        // f of σ_i = p + R u_i (u sorted) is linear in R: zero at R*.
        let yield_norm = |p: f64, mut u: [f64; 3]| {
            u.sort_by(|a, b| b.total_cmp(a));
            (2.0 * c_n * cp - 2.0 * sp * p) / ((u[0] - u[2]) + sp * (u[0] + u[2]))
        };
        for inside in [false, true] {
            let (mut sure, mut elastic) = (0, 0);
            for t in &trials_about_the_surface(c, inside, yield_norm) {
                let plastic = law.return_sorted(&principal_sorted(t), eps).region != Region::Elastic;
                let pre = law.surely_elastic(t, eps);
                assert!(!(pre && plastic), "{law:?}: the trial {t:?} is plastic, the pre-check calls it elastic");
                sure += pre as usize;
                elastic += !plastic as usize;
            }
            // Well inside the surface, it spares (nearly) every elastic trial the decomposition.
            assert!(!inside || 10 * sure >= 9 * elastic, "{law:?}: {sure} of {elastic} elastic trials caught");
        }
    }
    // Tresca in pure shear (s_2 = 0), where the bound √2 R is tight: just inside and just outside.
    let Constitutive::MohrCoulomb(tresca) = mc(0.0, c, 0.0, None) else { unreachable!() };
    for (x, inside) in [(1.0 - 1e-8, true), (1.0 + 1e-9, false)] {
        let t = stress_in([-5.0 * c + x * c, -5.0 * c, -5.0 * c - x * c], &tilt());
        assert_eq!(tresca.surely_elastic(&t, 0.0), inside);
        assert_eq!(tresca.return_sorted(&principal_sorted(&t), 0.0).region == Region::Elastic, inside);
    }
    let Constitutive::VonMises(law) = vm(c, 0.5 * c, -1e5) else { unreachable!() };
    for eps in [0.0, 0.01] {
        let (c_n, _) = law.cohesion_at(eps);
        // The pre-check is exact for von Mises: it misses only trials within its margin.
        let (mut sure, mut elastic) = (0, 0);
        for t in &trials_about_the_surface(c, false, |_, _| 2f64.sqrt() * c_n) {
            let plastic = law.return_principal(&principal_sorted(t), eps).region != Region::Elastic;
            let pre = law.surely_elastic(t, eps);
            assert!(!(pre && plastic), "von Mises: the trial {t:?} is plastic, the pre-check calls it elastic");
            sure += pre as usize;
            elastic += !plastic as usize;
        }
        assert!(100 * sure >= 95 * elastic, "von Mises: {sure} of {elastic} elastic trials caught");
    }
}
