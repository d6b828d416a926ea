//! Benchmarks of the per-particle kernels and of one global assembly, in material points per
//! second (`cargo bench`; criterion's reports go to target/criterion/).
//!
//! * `shape/gimp_stencil`: GIMP weights and gradients of every particle of the slumping block
//!   (two particles per cell and direction, so 3 × 3-node stencils), with B̄'s volumetric gradients.
//! * `kernels/residual`, `kernels/tangent`: the u–p–U residual and tangent blocks of one particle
//!   (linear elastic soil) at a non-zero nodal increment.
//! * `soil/linear_elastic`, `soil/mohr_coulomb_plastic`: one stress update per particle; the
//!   Mohr–Coulomb increment is a shear that yields every particle (checked before timing).
//! * `patch/recover`: MLSA patch recovery of Δp at every particle.
//! * `kernels_3d/residual`, `kernels_3d/tangent`, `kernels_3d/gimp_stencil`: the same in three
//!   dimensions (a two-phase box of 8 × 8 × 8 cells, two particles per cell and direction, so
//!   3 × 3 × 3-node GIMP stencils with B̄; u–p–U with seven dofs per node), per particle as above,
//!   the cost per point the estimate of a large three-dimensional run starts from.
//! * `assembly/residual_and_jacobian`: the residual and Jacobian of one Newton iteration assembled into
//!   PETSc (`System::assemble_once`) on the slumping block at its first step.
//!
//! PETSc is initialised once for the whole run in `main`.

use criterion::{black_box, Criterion, Throughput};
use porompm::case::{self, Override};
use porompm::kernels::{self, Motion, NodeBasis, NodeState};
use porompm::model::patch::PatchField;
use porompm::model::shape::{self, Basis};
use porompm::model::Model;
use porompm::soils::Region;
use std::path::Path;
use std::time::Duration;

fn load(case_file: &str, sets: &[&str]) -> case::Case {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(case_file);
    let text = porompm::io::read_text(&path).expect("the case file is readable");
    let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).expect("valid override")).collect();
    porompm::validation::load(&text, case_file, &overrides).expect("the case parses")
}

/// A small deterministic pseudo-random sequence in [-1, 1].
fn noise(i: usize) -> f64 {
    let x = (i as f64 * 12.9898).sin() * 43758.5453;
    2.0 * (x - x.floor()) - 1.0
}

/// Particle `k`'s stencil and B̄'s volumetric gradients (every cell its own root, plane strain).
fn stencil_of(model: &Model, k: usize) -> (shape::Stencil, [[f64; 2]; shape::MAX_STENCIL]) {
    let ps = &model.particles;
    let mut st = shape::stencil(model.basis, &model.grid, ps.x[k], ps.lp[k]);
    let gv = shape::volumetric_operators(model.basis, &model.grid, ps.x[k], ps.lp[k], &mut st, &|i, j| (i, j), false).0;
    (st, gv)
}

/// The GIMP basis with B̄ of every particle.
fn bases(model: &Model) -> Vec<Vec<NodeBasis>> {
    (0..model.particles.len())
        .map(|k| {
            let (st, gv) = stencil_of(model, k);
            (0..st.len).map(|n| NodeBasis { s: st.w[n], g: st.dw[n], gv: gv[n], t: 0.0, tv: 0.0 }).collect()
        })
        .collect()
}

fn group<'a>(
    c: &'a mut Criterion,
    name: &str,
    n: usize,
) -> criterion::BenchmarkGroup<'a, criterion::measurement::WallTime> {
    let mut g = c.benchmark_group(name);
    g.throughput(Throughput::Elements(n as u64));
    g.warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(3)).sample_size(30);
    g
}

fn particle_kernels(c: &mut Criterion) {
    let case = load("cases/slumping_block.toml", &[]);
    let model = Model::build(&case, |_, _| true);
    let ps = &model.particles;
    let n = ps.len();
    assert_eq!(model.basis, Basis::Gimp);

    let mut g = group(c, "shape", n);
    g.bench_function("gimp_stencil", |b| {
        b.iter(|| {
            let mut sum = 0.0;
            for k in 0..n {
                let (st, gv) = stencil_of(&model, k);
                sum += st.w[0] + gv[0][0];
            }
            black_box(sum)
        })
    });
    g.finish();

    let basis = bases(&model);
    let nm = porompm::scheme::Scheme::of(&model.integration, 1e-3, false);
    let states: Vec<Vec<NodeState>> = basis
        .iter()
        .enumerate()
        .map(|(k, b)| {
            (0..b.len())
                .map(|m| {
                    let mut s = NodeState::default();
                    for c in 0..5 {
                        let d = 1e-6 * noise(97 * k + 5 * m + c) * if c == 2 { 1e6 } else { 1.0 };
                        s.d[c] = d;
                        s.a[c] = nm.a0 * d;
                        s.v[c] = nm.a1 * d;
                    }
                    s
                })
                .collect()
        })
        .collect();
    let body_acc = vec![[0.0, -9.81]; model.n_bodies];
    let inputs: Vec<kernels::ParticleInput> = (0..n)
        .map(|k| {
            let mut input = kernels::ParticleInput::of(&model, k, &body_acc);
            input.pred = Motion::predicted(&nm, [0.0; 2], [0.0; 2], [0.0; 2], [0.0; 2]);
            input
        })
        .collect();
    let soil = &model.materials[ps.material[0] as usize].model;
    // The point of particle `k` at its nodal states, as the residual and tangent benchmarks evaluate it.
    let point = |k: usize| {
        let layout = porompm::layout::Layout::UPU;
        kernels::Point::<2>::with_recovery(&basis[k], &basis[k], &states[k], &inputs[k], soil, layout)
    };
    let mut g = group(c, "kernels", n);
    g.bench_function("residual", |b| {
        let mut buf = [0.0; kernels::MAX_LOCAL];
        b.iter(|| {
            let mut sum = 0.0;
            for (k, own) in basis.iter().enumerate() {
                let m = own.len() * 5;
                let pt = point(k);
                kernels::residual(&pt, &nm, &mut buf[..m]);
                sum += buf[0];
            }
            black_box(sum)
        })
    });
    g.bench_function("tangent", |b| {
        let mut block = vec![0.0; kernels::MAX_LOCAL * kernels::MAX_LOCAL];
        b.iter(|| {
            let mut sum = 0.0;
            for (k, own) in basis.iter().enumerate() {
                let m = own.len() * 5;
                let pt = point(k);
                kernels::tangent(&pt, &nm, &mut block[..m * m]);
                sum += block[0];
            }
            black_box(sum)
        })
    });
    g.finish();

    // Stress updates: the slumping block's elastic soil, and a Mohr–Coulomb soil (φ = 30°) sheared
    // into yield.
    let deps: Vec<[f64; 6]> =
        (0..n).map(|k| [1e-5 * noise(k), -1e-5 * noise(k + 1), 1e-5 * noise(k + 2), 0.0, 0.0, 0.0]).collect();
    let mut g = group(c, "soil", n);
    g.bench_function("linear_elastic", |b| {
        b.iter(|| {
            let mut sum = 0.0;
            for (stress, d) in ps.stress.iter().zip(&deps) {
                sum += soil.update(stress, 0.0, d).stress[0];
            }
            black_box(sum)
        })
    });
    let footing = load("cases/footing_sd.toml", &["materials.clay.model.friction_angle=30"]);
    let mc = footing.materials[0].model.law();
    let stress0 = [-2e3, -2e3, 0.0, -2e3, 0.0, 0.0];
    // Isochoric (the soil is nearly incompressible, ν = 0.49): ε_xx = −ε_yy.
    let shear: Vec<[f64; 6]> = (0..n)
        .map(|k| {
            let a = 1e-2 * (1.0 + 0.1 * noise(k));
            [a, -a, 2e-3 * noise(k + 7), 0.0, 0.0, 0.0]
        })
        .collect();
    for d in &shear {
        let u = mc.update(&stress0, 0.0, d);
        assert!(!matches!(u.region, Region::Elastic), "the benchmark step must yield: {mc:?} {d:?} {u:?}");
    }
    g.bench_function("mohr_coulomb_plastic", |b| {
        b.iter(|| {
            let mut sum = 0.0;
            for d in &shear {
                sum += mc.update(&stress0, 0.0, d).stress[0];
            }
            black_box(sum)
        })
    });
    // The same steps with out-of-plane shears as well (a three-dimensional point: the principal
    // frame by Jacobi rotations instead of the plane's closed form).
    let shear3: Vec<[f64; 6]> = shear
        .iter()
        .enumerate()
        .map(|(k, d)| [d[0], d[1], d[2], 0.0, 3e-3 * noise(k + 3), -2e-3 * noise(k + 5)])
        .collect();
    g.bench_function("mohr_coulomb_plastic_3d", |b| {
        b.iter(|| {
            let mut sum = 0.0;
            for d in &shear3 {
                sum += mc.update(&stress0, 0.0, d).stress[0];
            }
            black_box(sum)
        })
    });
    g.finish();

    let nodes = model.grid.nodes();
    let dp: Vec<f64> = (0..model.grid.node_count()).map(noise).collect();
    let active = vec![true; dp.len()];
    let field = PatchField { grid: &model.grid, start: [0, 0], count: nodes, dp: &dp, active: &active };
    let mut g = group(c, "patch", n);
    g.bench_function("recover", |b| {
        b.iter(|| {
            let mut sum = 0.0;
            for k in 0..n {
                sum += field.recover(ps.x[k]).unwrap_or(0.0);
            }
            black_box(sum)
        })
    });
    g.finish();
}

/// A two-phase elastic box of 8 × 8 × 8 cells (2 × 2 × 2 points per cell) in three dimensions.
const BOX_3D: &str = r#"
    [analysis]
    formulation = "two_phase"
    [grid]
    size = [1.0, 1.0, 1.0]
    cells = [8, 8, 8]
    [[materials]]
    name = "soil"
    porosity = 0.3
    solid_density = 2650.0
    water_bulk_modulus = 2.2e9
    solid_bulk_modulus = inf
    hydraulic_conductivity = 1e-3
    [materials.model]
    type = "linear_elastic"
    young_modulus = 1e7
    poisson_ratio = 0.3
    [[bodies]]
    name = "box"
    material = "soil"
    shape = { rectangle = { min = [0.0, 0.0], max = [1.0, 1.0] } }
    initial_stress = { k0 = 0.5 }
    [[stages]]
    name = "load"
    duration = 0.1
    dt = 1e-3
"#;

fn particle_kernels_3d(c: &mut Criterion) {
    const M: usize = kernels::MAX_NODES_3D;
    let case = porompm::validation::load(BOX_3D, "box_3d", &[]).expect("the 3D box parses");
    let model = porompm::model::Model::build_solid(&case, |_| true);
    let ps = &model.particles;
    let n = ps.len();
    let stencil = |k: usize| -> Vec<NodeBasis<3>> {
        let mut st: shape::Stencil<3, M> = shape::stencil_in(model.basis, &model.grid, ps.x[k], ps.lp[k]);
        let (gv, _) =
            shape::volumetric_operators_in(model.basis, &model.grid, ps.x[k], ps.lp[k], &mut st, &|c| c, false);
        (0..st.len).map(|m| NodeBasis { s: st.w[m], g: st.dw[m], gv: gv[m], t: 0.0, tv: 0.0 }).collect()
    };
    let mut g = group(c, "kernels_3d", n);
    g.bench_function("gimp_stencil", |b| {
        b.iter(|| {
            let mut sum = 0.0;
            for k in 0..n {
                sum += stencil(k)[0].s;
            }
            black_box(sum)
        })
    });
    let basis: Vec<Vec<NodeBasis<3>>> = (0..n).map(stencil).collect();
    let layout = porompm::layout::Layout::UPU.in_dim(3);
    let nm = porompm::scheme::Scheme::of(&model.integration, 1e-3, false);
    let states: Vec<Vec<NodeState<{ porompm::layout::MAX_DOF_3D }>>> = basis
        .iter()
        .enumerate()
        .map(|(k, b)| {
            (0..b.len())
                .map(|m| {
                    let d: Vec<f64> = (0..layout.nd)
                        .map(|c| 1e-6 * noise(97 * k + 7 * m + c) * if Some(c) == layout.p { 1e6 } else { 1.0 })
                        .collect();
                    NodeState::new(&d, &nm)
                })
                .collect()
        })
        .collect();
    let body_acc = vec![[0.0, -9.81, 0.0]; model.n_bodies];
    let inputs: Vec<kernels::ParticleInput<3>> =
        (0..n).map(|k| kernels::ParticleInput::of(&model, k, &body_acc)).collect();
    let soil = &model.materials[0].model;
    let largest = basis.iter().map(|b| b.len() * layout.nd).max().unwrap_or(0);
    let point =
        |k: usize| kernels::Point::<3, M>::with_recovery(&basis[k], &basis[k], &states[k], &inputs[k], soil, layout);
    g.bench_function("residual", |b| {
        let mut buf = vec![0.0; largest];
        b.iter(|| {
            let mut sum = 0.0;
            for (k, own) in basis.iter().enumerate() {
                let m = own.len() * layout.nd;
                let pt = point(k);
                kernels::residual(&pt, &nm, &mut buf[..m]);
                sum += buf[0];
            }
            black_box(sum)
        })
    });
    g.bench_function("tangent", |b| {
        let mut block = vec![0.0; largest * largest];
        b.iter(|| {
            let mut sum = 0.0;
            for (k, own) in basis.iter().enumerate() {
                let m = own.len() * layout.nd;
                let pt = point(k);
                kernels::tangent(&pt, &nm, &mut block[..m * m]);
                sum += block[0];
            }
            black_box(sum)
        })
    });
    g.finish();
    eprintln!(
        "kernels_3d: {n} material points, {} to {} stencil nodes",
        basis.iter().map(|b| b.len()).min().unwrap_or(0),
        basis.iter().map(|b| b.len()).max().unwrap_or(0)
    );
}

fn global_assembly(c: &mut Criterion) {
    let case = load("cases/slumping_block.toml", &[]);
    let coll = porompm::parallel::Collective::world();
    let layout = porompm::layout::Layout::UPU;
    let system = porompm::assembly::System::<2>::new(
        &coll,
        &porompm::model::grid_of(&case),
        layout,
        None,
        case.stabilisation.stiffness,
    );
    let mut system = system.expect("the grid system is created");
    let model = Model::build(&case, |i, j| system.space().owns_cell_in([i, j]));
    let stage = &case.stages[0];
    let active = model.active(stage);
    let step =
        system.prepare(&model, &active, (stage.dt(), stage.dt()), false, &coll).expect("the first step is prepared");
    system.assemble_once(&step, &model, &coll).expect("the system assembles");
    let mut g = group(c, "assembly", model.particles.len());
    g.bench_function("residual_and_jacobian", |b| {
        b.iter(|| black_box(system.assemble_once(&step, &model, &coll).unwrap()))
    });
    g.finish();
    eprintln!(
        "assembly: {} material points, {} grid dofs ({} unknowns)",
        model.particles.len(),
        system.space().total_dofs(),
        step.free_dofs()
    );
}

fn main() {
    let petsc = petsc::Petsc::initialize(&[], None, "porompm-bench").expect("PETSc initialises");
    let mut c = Criterion::default().configure_from_args();
    particle_kernels(&mut c);
    particle_kernels_3d(&mut c);
    global_assembly(&mut c);
    c.final_summary();
    drop(petsc);
}
