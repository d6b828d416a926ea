//! Distributed runs: material points migrate between ranks with their whole state, and a run's
//! results and files do not depend on the number of ranks (1, 2 and 3 here; the 2-core machine
//! oversubscribes beyond that), including a restart on another number of ranks than wrote the
//! checkpoint.

mod common;

use common::*;
use hdf5_metno as h5;
use std::path::{Path, PathBuf};

fn out_dir(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("distributed").join(name)
}

/// One output time of fields.h5 of the sliding block: its time and the particle fields this test
/// reads.
struct Frame {
    time: f64,
    id: Vec<f64>,
    mass: Vec<f64>,
    position: Vec<[f64; 2]>,
    velocity: Vec<[f64; 2]>,
    stress: Vec<f64>,
    /// The grid fields: the active flag and the last step's displacement increment of every node.
    active: Vec<i32>,
    du: Vec<f64>,
}

/// Every output time of a run's fields.h5, in time order.
fn frames(dir: &Path) -> Vec<Frame> {
    let f = h5::File::open(dir.join("fields.h5")).expect("fields.h5 opens");
    let mut names: Vec<usize> =
        f.group("particles").unwrap().member_names().unwrap().iter().map(|n| n.parse().unwrap()).collect();
    names.sort();
    let read = |n: usize, name: &str| -> Vec<f64> {
        f.dataset(&format!("particles/{n}/{name}")).unwrap().read_raw::<f64>().unwrap()
    };
    let pairs = |v: Vec<f64>| -> Vec<[f64; 2]> { v.chunks_exact(3).map(|c| [c[0], c[1]]).collect() };
    names
        .into_iter()
        .map(|n| {
            // Output every 20 steps of 0.01 s (the case's `fields_every`), from t = 0.
            let time = 0.2 * n as f64;
            let sxx = read(n, "stress_xx");
            let syy = read(n, "stress_yy");
            let sxy = read(n, "stress_xy");
            Frame {
                time,
                id: read(n, "particle_id"),
                mass: read(n, "mass"),
                position: pairs(read(n, "position")),
                velocity: pairs(read(n, "velocity")),
                stress: sxx.iter().zip(&syy).zip(&sxy).map(|((a, b), c)| a.abs().max(b.abs()).max(c.abs())).collect(),
                active: f.dataset(&format!("grid/{n}/active")).unwrap().read_raw::<i32>().unwrap(),
                du: f.dataset(&format!("grid/{n}/du")).unwrap().read_raw::<f64>().unwrap(),
            }
        })
        .collect()
}

fn total_mass(f: &Frame) -> f64 {
    f.mass.iter().sum()
}

fn momentum(f: &Frame) -> [f64; 2] {
    let mut p = [0.0; 2];
    for (m, v) in f.mass.iter().zip(&f.velocity) {
        p[0] += m * v[0];
        p[1] += m * v[1];
    }
    p
}

/// The largest difference of positions and velocities between two frames of the same points.
fn largest_difference(a: &Frame, b: &Frame) -> (f64, f64) {
    assert_eq!(a.id, b.id, "the same points, sorted by id");
    let d = |x: &[[f64; 2]], y: &[[f64; 2]]| {
        x.iter().zip(y).fold(0.0f64, |m, (p, q)| m.max((p[0] - q[0]).abs()).max((p[1] - q[1]).abs()))
    };
    (d(&a.position, &b.position), d(&a.velocity, &b.velocity))
}

const SLIDING: &str = "tests/cases/sliding_block.toml";

/// `--balance-threshold inf`: PETSc's even split for the whole run, so that the points cross fixed
/// subdomain boundaries (the load balance has its own test below).
fn fixed_partition() -> Vec<String> {
    vec!["--balance-threshold".to_string(), "inf".to_string()]
}

/// The block of `tests/cases/sliding_block.toml` is carried 9 m to the right and back across the
/// two and three subdomains of a 2- and 3-rank run: every point crosses every rank boundary twice.
/// At every output time the point count and the total mass are those of one rank exactly (the same
/// points with the same masses, summed in id order), the momentum is one rank's to round-off and
/// follows the applied impulse, and every point is where it is on one rank.
#[test]
fn a_block_carried_across_every_rank_boundary_and_back_keeps_its_points_mass_and_momentum() {
    let runs: Vec<(usize, Run, Vec<Frame>)> = [1, 2, 3]
        .into_iter()
        .map(|n| {
            let dir = out_dir(&format!("sliding-{n}"));
            let r = run_case_on(n, SLIDING, &dir, &fixed_partition());
            assert!(r.completed(), "{n} ranks: {}\n{}", r.summary, r.stderr());
            let f = frames(&dir);
            (n, r, f)
        })
        .collect();
    let one = &runs[0].2;
    assert_eq!(one.len(), 11, "output times 0, 0.2, …, 2 s");
    let n_points = one[0].id.len();
    let m0 = total_mass(&one[0]);
    // The swing: a_x = A cos(ω t), v_x = (A/ω) sin(ω t), x = x₀ + (A/ω²)(1 − cos ω t).
    let (a, w) = (4.5 * std::f64::consts::PI.powi(2), std::f64::consts::PI);
    let far = one.iter().map(|f| f.position.iter().map(|p| p[0]).fold(f64::MIN, f64::max)).fold(f64::MIN, f64::max);
    assert!(far > 12.0, "the block went out to x = {far} m (its right points start at 3.25 m)");
    for (n, run, fr) in &runs {
        assert_eq!(fr.len(), one.len(), "{n} ranks: output times");
        let migrated = run.summary["migrated_particles"].as_u64().unwrap();
        if *n > 1 {
            // Out and back through n − 1 boundaries: at least 2 (n − 1) moves per point.
            assert!(migrated >= (2 * (n - 1) * n_points) as u64, "{n} ranks: {migrated} moves of {n_points} points");
        }
        let mut worst = (0.0f64, 0.0f64, 0.0f64);
        for (f, g) in fr.iter().zip(one) {
            assert_eq!(f.id.len(), n_points, "{n} ranks at t = {}: point count", f.time);
            assert_eq!(total_mass(f), m0, "{n} ranks at t = {}: total mass", f.time);
            let (p, q) = (momentum(f), momentum(g));
            let exact = m0 * a / w * (w * f.time).sin();
            let dp = ((p[0] - q[0]).abs() + (p[1] - q[1]).abs()) / (m0 * a / w);
            let (dx, dv) = largest_difference(f, g);
            worst = (worst.0.max(dp), worst.1.max(dx), worst.2.max(dv / (a / w)));
            assert!(dp <= 1e-9, "{n} ranks at t = {}: momentum {p:?} against one rank's {q:?}", f.time);
            assert!(dx <= 1e-9 && dv <= 1e-9 * a / w, "{n} ranks at t = {}: positions {dx}, velocities {dv}", f.time);
            // Each rank writes the block of nodes it owns: the grid fields are one rank's.
            assert_eq!(f.active, g.active, "{n} ranks at t = {}: active nodes", f.time);
            let ddu = f.du.iter().zip(&g.du).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(f.active.contains(&1) || f.time == 0.0, "t = {}: no active node", f.time);
            assert!(ddu <= 1e-9, "{n} ranks at t = {}: nodal increments differ by {ddu} m", f.time);
            // Against the exact swing: the dynamic stage starts from a₀ = 0 under the load A, which
            // leaves the velocity behind by about A Δt/3 (0.15 m/s of 14 m/s) for the whole run.
            assert!((p[0] - exact).abs() <= 2e-2 * m0 * a / w, "t = {}: momentum {} against {exact}", f.time, p[0]);
            // A rigid translation: no strain, no stress (round-off of the 1e7 Pa modulus).
            assert!(f.stress.iter().all(|s| *s <= 1e-3), "{n} ranks at t = {}: stress in a rigid motion", f.time);
        }
        let last = fr.last().unwrap();
        let back = last.position.iter().zip(&one[0].position).fold(0.0f64, |m, (p, q)| m.max((p[0] - q[0]).abs()));
        println!(
            "{n} rank(s): {} points, {migrated} moves between ranks, mass {:.6e} kg at every output; against one rank: momentum {:.1e} (relative), positions {:.1e} m, velocities {:.1e} (relative); back home within {back:.2e} m; {:.2} s",
            n_points,
            total_mass(last),
            worst.0,
            worst.1,
            worst.2,
            run.summary["wall_time_s"].as_f64().unwrap_or(f64::NAN)
        );
        assert!(back <= 0.05 * 9.0, "{n} ranks: the block came back to within {back} m of its start");
    }
}

/// A checkpoint written on N ranks restarts on M: taken at step 110 of 200 (the block on its way
/// back, its points spread over every subdomain), continued on another number of ranks, the run
/// ends where the uninterrupted one-rank run ends.
#[test]
fn a_checkpoint_written_on_n_ranks_restarts_on_m() {
    let full = out_dir("restart-full-1");
    let r = run_case_on(1, SLIDING, &full, &[]);
    assert!(r.completed(), "{}", r.stderr());
    let reference = frames(&full);
    let reference = reference.last().unwrap();
    let mut every = fixed_partition();
    every.extend(["--checkpoint-every".to_string(), "110".to_string()]);
    // The particle arrays of a checkpoint, read whole.
    let arrays = |cp: &Path| -> Vec<Vec<f64>> {
        let f = h5::File::open(cp).expect("checkpoint.h5 opens");
        ["id", "x", "vel", "stress"]
            .iter()
            .map(|a| f.dataset(&format!("particles/{a}")).unwrap().read_raw().unwrap())
            .collect()
    };
    let mut one_rank: Option<Vec<Vec<f64>>> = None;
    for (n, m) in [(1, 3), (3, 2), (3, 1), (2, 3)] {
        let first = out_dir(&format!("restart-{n}-to-{m}-first"));
        let r = run_case_on(n, SLIDING, &first, &every);
        assert!(r.completed(), "{n} ranks: {}", r.stderr());
        let cp = first.join("checkpoint.h5");
        // All ranks write their slabs of the id-sorted records: the file is the one-rank file.
        let a = arrays(&cp);
        let base = one_rank.get_or_insert_with(|| a.clone());
        assert_eq!(a[0], base[0], "{n} ranks: the checkpoint's ids");
        // Positions [m], velocities [m/s] and stresses (round-off of the 1e7 Pa modulus) [Pa].
        for (k, tol) in [(1, 1e-9), (2, 1e-9), (3, 1e-6)] {
            let diff = a[k].iter().zip(&base[k]).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
            assert!(diff <= tol, "{n} ranks: checkpoint array {k} differs from one rank's by {diff}");
        }
        let again = out_dir(&format!("restart-{n}-to-{m}"));
        let args = ["--restart".to_string(), cp.display().to_string()];
        let args: Vec<String> = args.into_iter().chain(fixed_partition()).collect();
        let r = run_case_on(m, SLIDING, &again, &args);
        assert!(r.completed(), "{n} → {m} ranks: {}\n{}", r.summary, r.stderr());
        assert_eq!(r.summary["restarted_from"]["step"], 110);
        assert_eq!(r.summary["steps"], 200);
        let end = frames(&again);
        let (dx, dv) = largest_difference(end.last().unwrap(), reference);
        println!("checkpoint on {n} rank(s), restart on {m}: final positions {dx:.1e} m, velocities {dv:.1e} m/s from the uninterrupted one-rank run");
        assert!(dx <= 1e-9 && dv <= 1e-8, "{n} → {m}: positions {dx}, velocities {dv}");
    }
}

/// A block falling through a grid split across its height moves from the upper rank to the lower
/// one and stops the run at the grid's bottom edge, which no boundary closes: on two ranks the run
/// fails at the time and with the message of the one-rank run, raised on the lower rank (rank 0)
/// and reported once by every rank's agreement — no hang.
#[test]
fn a_falling_block_moves_down_the_ranks_and_stops_at_the_grid_edge_as_on_one_rank() {
    let one = run_case_on(1, "tests/cases/falling_block.toml", &out_dir("falling-1"), &[]);
    let two = run_case_on(2, "tests/cases/falling_block.toml", &out_dir("falling-2"), &[]);
    for r in [&one, &two] {
        assert_eq!(r.output.status.code(), Some(1), "{}", r.stderr());
        assert_eq!(r.summary["status"], "failed");
    }
    let (e1, e2) = (one.summary["error"].as_str().unwrap(), two.summary["error"].as_str().unwrap());
    assert!(e1.contains("grid") && e2.starts_with(e1) && e2.ends_with("(rank 0)"), "one rank: {e1}\ntwo ranks: {e2}");
    assert_eq!(one.summary["steps"], two.summary["steps"]);
    assert!(two.summary["migrated_particles"].as_u64().unwrap() > 0);
    let errors = two.stderr().lines().filter(|l| l.starts_with("error:")).count();
    assert_eq!(errors, 1, "{}", two.stderr());
}

/// The slumping block fills two thirds of its grid's width: PETSc's even split of the nodes over
/// three ranks leaves the third rank without a point (imbalance 1.5). With the default threshold
/// (1.2) the run repartitions the grid after its first step, the imbalance stays within the
/// threshold, and the results are those of the run that never repartitions.
#[test]
fn the_grid_is_repartitioned_when_the_points_crowd_onto_some_ranks() {
    let short = set_args(&["stages.slump.duration=0.05"]);
    let fixed = {
        let mut a = short.clone();
        a.extend(["--balance-threshold".to_string(), "inf".to_string()]);
        run_case_on(3, "cases/slumping_block.toml", &out_dir("balance-never"), &a)
    };
    let balanced = run_case_on(3, "cases/slumping_block.toml", &out_dir("balance-default"), &short);
    for r in [&fixed, &balanced] {
        assert!(r.completed(), "{}\n{}", r.summary, r.stderr());
    }
    let never = fixed.column("load_imbalance");
    let after = balanced.column("load_imbalance");
    println!(
        "slumping block on 3 ranks: imbalance {:.3} without repartitioning; {} repartition(s), then {:.3} (largest after the first step {:.3})",
        never.last().unwrap(),
        balanced.summary["repartitions"],
        after.last().unwrap(),
        after[1..].iter().copied().fold(0.0, f64::max)
    );
    assert_eq!(fixed.summary["repartitions"], 0);
    assert!(never.iter().all(|&i| i >= 1.4), "PETSc's split leaves a rank idle: {never:?}");
    assert!(balanced.summary["repartitions"].as_u64().unwrap() >= 1);
    assert!(after[1..].iter().all(|&i| i <= 1.2), "after the first step: {after:?}");
    // The same answers: probe values at the end.
    for name in ["P1.p", "P2.p", "P3.p", "P2.ux", "P2.uy"] {
        let (a, b) = (*fixed.column(name).last().unwrap(), *balanced.column(name).last().unwrap());
        let scale = fixed.column(name).iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!((a - b).abs() <= 1e-6 * scale, "{name}: {a} without, {b} with repartitioning");
    }
}

/// A panic on one rank (a bug; injected here by PORO_FAULT_PANIC_RANK right after PETSc starts)
/// ends every rank of the run at once through MPI_Abort, with the panic's message, instead of
/// leaving the other ranks waiting in their next collective operation for ever.
#[test]
fn a_panic_on_one_rank_ends_every_rank() {
    let dir = out_dir("panic");
    let _ = std::fs::remove_dir_all(&dir);
    let started = std::time::Instant::now();
    let output = mpi_env(&mut std::process::Command::new("timeout"))
        .args(["120", "mpirun", "--oversubscribe", "-n", "2", env!("CARGO_BIN_EXE_porompm"), "run", SLIDING, "--out"])
        .arg(&dir)
        .arg("--quiet")
        .env("PORO_FAULT_PANIC_RANK", "1")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("mpirun runs");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_ne!(output.status.code(), Some(124), "the run hung after the panic:\n{stderr}");
    assert!(!output.status.success(), "a run with a panicking rank must fail");
    assert!(stderr.contains("fault injected by PORO_FAULT_PANIC_RANK on rank 1"), "{stderr}");
    assert!(stderr.contains("ending every rank of the run"), "{stderr}");
    println!("ended after {:.1} s with {:?}", started.elapsed().as_secs_f64(), output.status.code());
}

/// The energies of the 3D and the 2D patch tests are the same on 1, 2 and 3 ranks to 1e-10
/// relative, also on 2 ranks, where the grid is repartitioned after the first step (the last
/// step's reactions, which the next step's work averages with its own, are carried over to the
/// new distribution node by node).
#[test]
fn the_energies_are_the_same_on_one_two_and_three_ranks_with_repartitioning() {
    for case in ["patch_test_3d", "patch_test"] {
        let runs: Vec<Run> = (1..=3)
            .map(|n| {
                let r = run_case_on(n, &format!("cases/{case}.toml"), &out_dir(&format!("energies-{case}-{n}")), &[]);
                assert!(r.completed(), "{case} on {n} ranks: {}", r.stderr());
                r
            })
            .collect();
        assert_eq!(runs[1].summary["repartitions"], 1, "{case}: the two-rank run repartitions");
        // The matrix's storage summed over ranks is the one rank's, but for the ranks' row offsets.
        let matrix = |r: &Run| r.summary["memory"]["matrix_mib"].as_f64().unwrap();
        for (n, r) in runs.iter().enumerate().skip(1) {
            let (one, many) = (matrix(&runs[0]), matrix(r));
            assert!(
                one > 0.0 && (many / one - 1.0).abs() < 0.01,
                "{case}: matrix {many} MiB on {} ranks, {one} on one",
                n + 1
            );
        }
        for name in ["energy_external", "energy_internal", "energy_kinetic", "energy_balance_error"] {
            let one = runs[0].column(name);
            for (n, r) in runs.iter().enumerate().skip(1) {
                for (a, b) in one.iter().zip(r.column(name)) {
                    let scale = one.iter().fold(1e-30f64, |m, v| m.max(v.abs()));
                    assert!((a - b).abs() <= 1e-10 * scale, "{case}, {name} on {} ranks: {b} against {a}", n + 1);
                }
            }
        }
    }
}
