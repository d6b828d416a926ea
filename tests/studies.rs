//! Convergence studies (long; not part of the default suite). Run them with `make study`, which is
//! `cargo test --release --test studies -- --ignored --nocapture --test-threads=1`. Each prints a
//! Markdown table and writes it to `target/studies/`.

mod common;
use common::csv_fields;
use serde_json::Value;
use std::fmt::Write;
use std::path::PathBuf;
use std::process::Command;

fn run(label: &str, sets: &[String]) -> Value {
    run_case("terzaghi", label, sets)
}

fn run_case(case: &str, label: &str, sets: &[String]) -> Value {
    run_case_on(1, case, label, sets)
}

/// `run_case` on `ranks` MPI ranks (through `mpirun` when more than one).
fn run_case_on(ranks: usize, case: &str, label: &str, sets: &[String]) -> Value {
    let args: Vec<String> = sets.iter().flat_map(|s| ["--set".to_string(), s.clone()]).collect();
    run_file_on(ranks, &format!("cases/{case}.toml"), label, &args)
}

/// Runs the case file `path` (from the repository root) with `args` on `ranks` MPI ranks into the
/// study directory `label`, without a time limit; returns summary.json. Panics unless it exits 0.
fn run_file_on(ranks: usize, path: &str, label: &str, args: &[String]) -> Value {
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("studies").join(label);
    let _ = std::fs::remove_dir_all(&out);
    let mut all: Vec<String> =
        vec!["run".into(), path.to_string(), "--out".into(), out.display().to_string(), "--quiet".into()];
    all.extend(args.iter().cloned());
    let mut cmd = if ranks > 1 {
        let mut c = Command::new("mpirun");
        c.args(["--oversubscribe", "-n", &ranks.to_string(), env!("CARGO_BIN_EXE_porompm")]);
        common::mpi_env(&mut c);
        c
    } else {
        Command::new(env!("CARGO_BIN_EXE_porompm"))
    };
    let o = cmd.args(&all).current_dir(env!("CARGO_MANIFEST_DIR")).output().expect("porompm runs");
    assert!(o.status.success(), "{label}: {}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

fn value(s: &Value, metric: &str) -> f64 {
    s["verification"][metric]["value"].as_f64().unwrap()
}

fn save(name: &str, text: &str) {
    println!("{text}");
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target").join("studies");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(name), text).unwrap();
}

/// Grid refinement 10 → 20 → 40 → 80 cells at Δt = 1e-4 s, small enough that the time error of
/// the non-dissipative Newmark scheme does not mask the spatial error (at the paper's
/// Δt = 1e-3 s it does on the finer grids; the second table shows it). The RMS error must fall at
/// every refinement; the observed order is log2 of successive RMS ratios.
#[test]
#[ignore]
fn terzaghi_grid_refinement() {
    let mut text = String::from("## Terzaghi: grid refinement (column 0.1 × 1.0 m, 2×2 GIMP points per cell)\n\n");
    for (dt, must_decrease) in [("1e-4", true), ("1e-3", false)] {
        let _ = writeln!(text, "Δt = {dt} s\n\n| cells | h [m] | e_p(T_v=0.1) | e_p(T_v=0.5) | RMS(T_v=0.5) | order (RMS) | settlement error | wall [s] |");
        let _ = writeln!(text, "|---|---|---|---|---|---|---|---|");
        let mut previous: Option<f64> = None;
        let mut rms_all = Vec::new();
        for n in [10, 20, 40, 80] {
            let s = run(&format!("refine-{dt}-{n}"), &[format!("grid.cells=[1,{n}]"), format!("time.dt={dt}")]);
            let rms = value(&s, "p_rms_error_Tv0.5");
            let order = previous.map(|p| format!("{:.2}", (p / rms).log2())).unwrap_or_else(|| "–".into());
            let _ = writeln!(
                text,
                "| {n} | {:.4} | {:.3e} | {:.3e} | {rms:.3e} | {order} | {:.3e} | {:.2} |",
                1.0 / n as f64,
                value(&s, "e_p_Tv0.1"),
                value(&s, "e_p_Tv0.5"),
                value(&s, "settlement_rel_error_Tv0.5"),
                s["wall_time_s"].as_f64().unwrap()
            );
            previous = Some(rms);
            rms_all.push(rms);
        }
        text.push('\n');
        if must_decrease {
            assert!(
                rms_all.windows(2).all(|w| w[1] < w[0]),
                "the RMS error must fall under refinement at Δt = {dt}: {rms_all:?}"
            );
        }
    }
    save("terzaghi_refinement.md", &text);
}

/// Time-step dependence at 10 cells ([003] Fig. 4 studies e_p against Δt).
#[test]
#[ignore]
fn terzaghi_time_step() {
    let mut text = String::from("## Terzaghi: time step (10 cells)\n\n| Δt [s] | e_p(T_v=0.1) | e_p(T_v=0.5) | RMS(T_v=0.5) | steps | wall [s] |\n|---|---|---|---|---|---|\n");
    for dt in ["4e-3", "2e-3", "1e-3", "5e-4", "2.5e-4", "1e-4"] {
        let s = run(&format!("dt-{dt}"), &[format!("time.dt={dt}")]);
        let _ = writeln!(
            text,
            "| {dt} | {:.3e} | {:.3e} | {:.3e} | {} | {:.2} |",
            value(&s, "e_p_Tv0.1"),
            value(&s, "e_p_Tv0.5"),
            value(&s, "p_rms_error_Tv0.5"),
            s["steps"],
            s["wall_time_s"].as_f64().unwrap()
        );
        assert!(value(&s, "e_p_Tv0.5") <= 1e-2, "e_p target at Δt = {dt}");
    }
    save("terzaghi_time_step.md", &text);
}

/// Large-strain consolidation ([003] §4.2, Fig. 10): refinement 10 → 20 → 40 cells at the case's
/// Δt = 1e-4 s. The settlement error at U_s = 0.5 must fall at every refinement and stay within 3 %
/// at 10 cells.
#[test]
#[ignore]
fn large_strain_consolidation_grid_refinement() {
    let mut text = String::from(
        "## Large-strain consolidation: grid refinement (column 0.1 × 1.0 m, 200 kPa, Xie & Leo 2004)\n\n\
         | cells | h [m] | e_p(U_s=0.5) | RMS(U_s=0.5) | settlement error | order (settlement) | wall [s] |\n\
         |---|---|---|---|---|---|---|\n",
    );
    let mut errors = Vec::new();
    for n in [10, 20, 40] {
        let s = run_case("large_strain_consolidation", &format!("large-strain-{n}"), &[format!("grid.cells=[1,{n}]")]);
        let se = value(&s, "settlement_rel_error_Us0.5");
        let order = errors.last().map(|p: &f64| format!("{:.2}", (p / se).log2())).unwrap_or_else(|| "–".into());
        let _ = writeln!(
            text,
            "| {n} | {:.4} | {:.3e} | {:.3e} | {se:.3e} | {order} | {:.2} |",
            1.0 / n as f64,
            value(&s, "e_p_Us0.5"),
            value(&s, "p_rms_error_Us0.5"),
            s["wall_time_s"].as_f64().unwrap()
        );
        errors.push(se);
    }
    save("large_strain_refinement.md", &text);
    assert!(errors[0] <= 0.03, "settlement error at 10 cells: {}", errors[0]);
    assert!(errors.windows(2).all(|w| w[1] < w[0]), "the settlement error must fall: {errors:?}");
}

fn result(s: &Value, name: &str) -> f64 {
    s["results"][name].as_f64().unwrap_or(f64::NAN)
}

/// The undrained footing ([000] §4.1.1, Fig. 6) at h = 0.5, 0.25, 0.1 m, with and without B̄:
/// q/c at d/B = 0.01 (the case's q_ult). With B̄ it must fall towards 2 + π as h falls; without B̄
/// the footing locks (no failure up to q/c = 7, or a q_ult far above).
#[test]
#[ignore]
fn footing_sd_mesh_and_locking() {
    let mut text = String::from(
        "## Undrained strip footing (Tresca, E/c = 10⁴): q_ult/c at d/B = 0.01\n\n\
         | h [m] | B̄ | q_ult/c | ratio to 2 + π | q/c at d/B = 0.005 | wall [s] |\n|---|---|---|---|---|---|\n",
    );
    let mut with = Vec::new();
    for (h, n, point) in [(0.5, 10, "[0.125,4.875]"), (0.25, 20, "[0.0625,4.9375]"), (0.1, 50, "[0.025,4.975]")] {
        for bbar in [true, false] {
            let s = run_case(
                "footing_sd",
                &format!("footing-sd-{n}-{bbar}"),
                &[
                    format!("grid.cells=[{n},{n}]"),
                    format!("verification.settlement_point={point}"),
                    format!("stabilisation.bbar={bbar}"),
                ],
            );
            let q = result(&s, "q_over_c_at_dB0.01");
            let _ = writeln!(
                text,
                "| {h} | {} | {} | {} | {:.3} | {:.1} |",
                if bbar { "on" } else { "off" },
                if q.is_nan() { format!("> {:.2}", result(&s, "q_over_c_max")) } else { format!("{q:.3}") },
                if q.is_nan() { "–".into() } else { format!("{:.3}", q / (2.0 + std::f64::consts::PI)) },
                result(&s, "q_over_c_at_dB0.005"),
                s["wall_time_s"].as_f64().unwrap()
            );
            if bbar {
                with.push(q);
            }
        }
    }
    save("footing_sd_mesh.md", &text);
    assert!(with.windows(2).all(|w| w[1] < w[0]), "q_ult/c with B̄ must fall as h falls: {with:?}");
}

/// The rigid rough square footing on Tresca clay (`tests/cases/footing_square_3d.toml`, quarter
/// model, the footing the nodes x, z ≤ k h with h = B/(2k + 1)): N_c = q_ult/c from the bearing
/// check (mean over d/B in [0.003, 0.005]) and its peak, against 5.91 (Gourvenec et al. 2006;
/// Salgado et al. 2004's bounds 5.52–6.22), with the cost of each run: k = 2, 3, 4 with the direct
/// solver, k = 6 with GAMG (`petsc_options/gamg-solid.opts`). N_c must rise towards the reference as
/// h falls, and stay below the upper bound 6.22.
#[test]
#[ignore]
fn footing_square_3d_mesh() {
    let mut text = String::from(
        "## Rigid rough square footing on Tresca clay (3D, quarter model): N_c against the mesh\n\n\
         | k | h / B | ranks | solver | points | unknowns | N_c (plateau) | N_c peak | ratio to 5.91 | Newton | Krylov | wall [s] | peak memory per rank [MiB] |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut ncs = Vec::new();
    for (k, gamg) in [(2, false), (3, false), (4, false), (6, true)] {
        let (nc, _) = footing_square_3d_row(&mut text, k, 1, gamg);
        ncs.push(nc);
    }
    save("footing_square_3d_mesh.md", &text);
    assert!(ncs.windows(2).all(|w| w[1] > w[0]), "N_c must rise as h falls: {ncs:?}");
    assert!(ncs.iter().all(|&n| n < 6.22), "N_c above Salgado et al.'s upper bound: {ncs:?}");
}

/// The square footing at the finest mesh that runs here, k = 10 (h = B/21, 262 144 points,
/// ≈ 10⁵ unknowns), on two ranks with GAMG: the bearing check's `bearing_capacity_ratio` within the
/// issue's 5 % of 5.91 (the check's own pass), and the same run's k = 3 on one and two ranks alike.
#[test]
#[ignore]
fn footing_square_3d_finest() {
    let mut text = String::from(
        "## Rigid rough square footing on Tresca clay (3D): the finest mesh, and one against two ranks\n\n\
         | k | h / B | ranks | solver | points | unknowns | N_c (plateau) | N_c peak | ratio to 5.91 | Newton | Krylov | wall [s] | peak memory per rank [MiB] |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let (one, _) = footing_square_3d_row(&mut text, 3, 1, true);
    let (two, _) = footing_square_3d_row(&mut text, 3, 2, true);
    let (finest, pass) = footing_square_3d_row(&mut text, 10, 2, true);
    save("footing_square_3d_finest.md", &text);
    assert!((one - two).abs() < 1e-6 * one, "one rank {one}, two ranks {two}");
    assert!(pass, "N_c = {finest} at k = 10 is not within 5 % of 5.91");
}

/// Runs the square footing at k on `ranks` ranks (GAMG or the default direct solver) and appends
/// its row; returns the plateau's N_c and whether the bearing check passed.
fn footing_square_3d_row(text: &mut String, k: usize, ranks: usize, gamg: bool) -> (f64, bool) {
    let label = format!("footing-square-3d-k{k}-{ranks}");
    let mut args: Vec<String> = vec!["--set".into(), format!("parameters.k={k}")];
    if gamg {
        args.extend(["--options-file".into(), "petsc_options/gamg-solid.opts".into()]);
    }
    let s = &run_file_on(ranks, "tests/cases/footing_square_3d.toml", &label, &args);
    assert_eq!(s["status"], "completed", "{label}");
    let ratio = &s["verification"]["bearing_capacity_ratio"];
    let nc = ratio["value"].as_f64().unwrap() * 5.91;
    let peak = s["results"]["q_over_c_max"].as_f64().unwrap();
    let _ = writeln!(
        text,
        "| {k} | 1/{} | {ranks} | {} | {} | {} | {nc:.3} | {peak:.3} | {:.3} | {} | {} | {:.0} | {:.0} |",
        2 * k + 1,
        if gamg { "GMRES + GAMG" } else { "LU" },
        s["particles"],
        s["dofs"],
        nc / 5.91,
        s["snes_iterations"],
        s["ksp_iterations"],
        s["wall_time_s"].as_f64().unwrap(),
        s["peak_memory_mib"].as_f64().unwrap_or(f64::NAN)
    );
    (nc, ratio["pass"].as_bool().unwrap())
}

/// The footing near a slope ([000] §4.3, Fig. 18): q/c at d/B = 0.1 and 0.5 for λ = 0, 2, 6 and
/// level ground. [000] finds q increasing with λ (measured 2026-11-22 at d/B = 0.5: 4.80, 5.58,
/// 6.99, 9.34).
#[test]
#[ignore]
fn footing_near_slope_distance() {
    let mut text = String::from(
        "## Strip footing near a slope: q/c against the footing-to-crest distance λB\n\n\
         | λ | q/c at d/B = 0.1 | q/c at d/B = 0.5 | wall [s] |\n|---|---|---|---|\n",
    );
    let mut at05 = Vec::new();
    for (label, sets) in [
        ("0", vec!["parameters.lambda=0".to_string()]),
        ("2", vec!["parameters.lambda=2".to_string()]),
        ("6", vec!["parameters.lambda=6".to_string()]),
        ("∞ (level ground)", vec!["parameters.lambda=6".to_string(), "parameters.crest_x=26".to_string()]),
    ] {
        let s = run_case("footing_near_slope", &format!("fns-{}", at05.len()), &sets);
        let (a, b) = (result(&s, "q_over_c_at_dB0.1"), result(&s, "q_over_c_at_dB0.5"));
        let _ = writeln!(text, "| {label} | {a:.3} | {b:.3} | {:.1} |", s["wall_time_s"].as_f64().unwrap());
        at05.push(b);
    }
    save("footing_near_slope.md", &text);
    assert!(at05.windows(2).all(|w| w[0] < w[1]), "q/c at d/B = 0.5 must increase with λ: {at05:?}");
}

/// The sand slope ([000] §4.2.2, Fig. 16) at k = 1e-4 m/s: the signed peak of the excess pore
/// pressure at the toe probe A for ψ_ini = −5°, 0°, +5° over the first `duration` s of the failure.
#[test]
#[ignore]
fn slope_sand_dilatancy() {
    let mut text = String::from(
        "## Sand slope: excess pore pressure at the toe (probe A), k = 1e-4 m/s\n\n\
         | ψ_ini [°] | peak p_excess at A [kPa] | final [kPa] | toe displacement [m] | wall [s] |\n|---|---|---|---|---|\n",
    );
    let mut peaks = Vec::new();
    for psi in [-5, 0, 5] {
        let s = run_case(
            "slope_sand",
            &format!("slope-sand-{psi}"),
            &[format!("parameters.psi_ini={psi}"), "stages.failure.duration=3".into()],
        );
        let peak = result(&s, "A.excess_p_peak");
        let _ = writeln!(
            text,
            "| {psi} | {:.2} | {:.2} | {:.3} | {:.1} |",
            peak / 1e3,
            result(&s, "A.excess_p_final") / 1e3,
            result(&s, "A.displacement"),
            s["wall_time_s"].as_f64().unwrap()
        );
        peaks.push(peak);
    }
    save("slope_sand_dilatancy.md", &text);
    assert!(peaks[0] > 0.0 && peaks[2] < 0.0, "peak excess pore pressure at A for ψ = −5, 0, 5: {peaks:?}");
}

/// Cook's membrane of [002] §4.1 (`cases/cook_membrane.toml`; Part E item 13): the neo-Hookean
/// membrane at ν = 0.499 on 1 m and 0.5 m cells ([002]'s 5,776 and 23,072 points), uGIMP and
/// quadratic B-splines, with F̄ and without. Item 13's assertions: with F̄ on the fine grid the
/// tip within 3 % of 0.2765 m for both bases; closer on the fine grid than on the coarse one;
/// standard MPM below F̄ at each resolution; F̄'s chequerboard index of σ_m at most a third of
/// the standard one on the finest grid (printed for each; on 1 m cells the B-splines' is 0.34).
/// [001]'s vertical cut to 1.0 m of toe displacement (Part E items 10 and 11), Newton on the exact
/// tangent: regular MPM (the case as shipped); DM-G with the double-mapped internal force and its
/// transpose as the strain (`stabilisation.internal_force = "mapped"`, `stress_recovery =
/// "mapped"`, the mapped stiffness for the K_mag diagnostic); DM-GC (CMPM's strain for the stress,
/// `cases/vertical_cut_dmgc.toml`) without the control of its filtered modes, to 0.1 m (it fails at
/// 0.84 m, a point near the crest inverted by its basis's motion), and with it at the shipped α =
/// 0.04 and at α = 0.1. Every run but the uncontrolled DM-GC reaches 1.0 m; each smoothing variant's
/// K_mag roughness is at most a fifth of MPM's and its σ_m chequerboard index below MPM's at each
/// snapshot it reaches. F^int_mag's roughness and σ_m's total variation at B and C are reported,
/// not asserted: [001]'s ratios (≤ 1/3) are not reached by any variant (docs/stiffness.md). About
/// 4 minutes.
#[test]
#[ignore]
fn vertical_cut_items_10_and_11() {
    let mut text = String::from(
        "## The vertical cut to 1.0 m of toe displacement ([001] §7.2, Part E items 10–11)\n\n\
         | method | toe [m] | K_mag rough. 0.1 / 1.0 m | F^int_mag rough. 0.1 / 1.0 m | σ_m chequerboard 0.1 / 1.0 m | Σ|Δσ_m| B / C [kPa] | ε̄ max | equilibrium error | Newton its | wall [s] |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    let pair = [
        "stabilisation.stiffness=double_mapping_gimp",
        "stabilisation.internal_force=mapped",
        "stabilisation.stress_recovery=mapped",
        "stabilisation.mapped_stiffness=diagnostics",
    ];
    let uncontrolled =
        ["stabilisation.filtered_mode_control=0", "verification.stop_displacement=0.1", "verification.snapshots=[0.1]"];
    let runs: [(&str, &str, &[&str]); 5] = [
        ("regular MPM (GIMP)", "vertical_cut", &[]),
        ("DM-G, mapped force and strain", "vertical_cut", &pair),
        ("DM-GC without the control (to 0.1 m)", "vertical_cut_dmgc", &uncontrolled),
        ("DM-GC, control α = 0.04 (the case)", "vertical_cut_dmgc", &[]),
        ("DM-GC, control α = 0.1", "vertical_cut_dmgc", &["stabilisation.filtered_mode_control=0.1"]),
    ];
    let mut rows = Vec::new();
    for (label, case, sets) in runs {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let s = run_case(case, &format!("cut-{}", rows.len()), &sets);
        let r = |k: &str| result(&s, k);
        let _ = writeln!(
            text,
            "| {label} | {:.3} | {:.4} / {:.4} | {:.4} / {:.4} | {:.4} / {:.4} | {:.1} / {:.1} | {:.2} | {:.1e} | {} | {:.0} |",
            r("toe_displacement"),
            r("k_mag_roughness_at_0.1"),
            r("k_mag_roughness_at_1"),
            r("fint_mag_roughness_at_0.1"),
            r("fint_mag_roughness_at_1"),
            r("sigma_m_checkerboard_at_0.1"),
            r("sigma_m_checkerboard_at_1"),
            r("sigma_m_variation_B") / 1e3,
            r("sigma_m_variation_C") / 1e3,
            r("eps_pd_max"),
            s["equilibrium_error"].as_f64().unwrap_or(f64::NAN),
            s["snes_iterations"],
            s["wall_time_s"].as_f64().unwrap()
        );
        rows.push(s);
    }
    save("vertical_cut.md", &text);
    let mpm = &rows[0];
    for (i, s) in rows.iter().enumerate() {
        let reach = if i == 2 { 0.1 } else { 1.0 };
        assert!(result(s, "toe_displacement") >= reach, "{}: toe at {}", runs[i].0, result(s, "toe_displacement"));
        let snapshots: &[&str] = if i == 2 { &["0.1"] } else { &["0.1", "1"] };
        for at in snapshots.iter().filter(|_| i > 0) {
            let (k, c) = (format!("k_mag_roughness_at_{at}"), format!("sigma_m_checkerboard_at_{at}"));
            let what = runs[i].0;
            assert!(
                result(s, &k) <= 0.2 * result(mpm, &k),
                "{what}, {k}: {} against {}",
                result(s, &k),
                result(mpm, &k)
            );
            assert!(result(s, &c) < result(mpm, &c), "{what}, {c}: {} against {}", result(s, &c), result(mpm, &c));
        }
    }
}

/// Runs on two ranks. The 0.5 m runs last 400 s: at 200 s the membrane still swings about its
/// rest state by ±0.3 % with the 55 s period (less PIC dissipation on the finer cells), and the
/// check's at-rest metric fails (measured 1.09 %). Each 1 m run takes about 7 minutes, each 0.5 m
/// run about 95 (about 7 hours in all); `COOK_H=1` keeps the coarse grid only.
#[test]
#[ignore]
fn cook_membrane_item_13() {
    let reference = 0.2765;
    let mut text = String::from(
        "## Cook's membrane (neo-Hookean, ν = 0.499, 1 N): tip u_y at rest against 0.2765 m\n\n\
         | h [m] | points | basis | F̄ | tip u_y [m] | error | nearest point's u_y [m] | σ_m chequerboard | wall [s] |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    let sizes: Vec<f64> = match std::env::var("COOK_H").ok().as_deref() {
        Some("1") => vec![1.0],
        _ => vec![1.0, 0.5],
    };
    // (h, basis, F̄) → (tip, chequerboard)
    let mut got = std::collections::HashMap::new();
    for &h in &sizes {
        for basis in ["ugimp", "bspline2"] {
            for fbar in [true, false] {
                let s = run_case_on(
                    2,
                    "cook_membrane",
                    &format!("cook-{h}-{basis}-{fbar}"),
                    &[
                        format!("parameters.h={h}"),
                        format!("analysis.shape_functions={basis}"),
                        format!("stabilisation.fbar={fbar}"),
                        format!("stages.load.duration={}", if h < 1.0 { 400 } else { 200 }),
                    ],
                );
                assert!(
                    s["verification"]["tip_uy_change_last_tenth"]["pass"] == true,
                    "{h} {basis} {fbar}: not at rest"
                );
                let (tip, board) = (result(&s, "tip_uy"), result(&s, "mean_stress_checkerboard"));
                let _ = writeln!(
                    text,
                    "| {h} | {} | {basis} | {} | {tip:.4} | {:+.2} % | {:.4} | {board:.3} | {:.0} |",
                    result(&s, "points"),
                    if fbar { "on" } else { "off" },
                    100.0 * (tip / reference - 1.0),
                    result(&s, "tip_uy_nearest_point"),
                    s["wall_time_s"].as_f64().unwrap()
                );
                got.insert((h.to_string(), basis, fbar), (tip, board));
            }
        }
    }
    save("cook_membrane.md", &text);
    let fine = sizes.last().unwrap().to_string();
    for basis in ["ugimp", "bspline2"] {
        for h in &sizes {
            let (f, s) = (got[&(h.to_string(), basis, true)], got[&(h.to_string(), basis, false)]);
            assert!(s.0 < f.0, "{basis}, h = {h}: standard {} not below F̄ {}", s.0, f.0);
        }
        let (f, s) = (got[&(fine.clone(), basis, true)], got[&(fine.clone(), basis, false)]);
        assert!(f.1 <= s.1 / 3.0, "{basis}, h = {fine}: chequerboard {} against {}", f.1, s.1);
        let tip = got[&(fine.clone(), basis, true)].0;
        assert!((tip / reference - 1.0).abs() <= 0.03, "{basis}, h = {fine}: F̄ tip {tip}");
        if sizes.len() > 1 {
            let coarse = got[&("1".to_string(), basis, true)].0;
            assert!((tip - reference).abs() < (coarse - reference).abs(), "{basis}: fine {tip}, coarse {coarse}");
        }
    }
}

/// [002]'s strip footing (`cases/footing_fbar.toml`; Part E item 14): the rigid footing pushed
/// into Hencky–J2 clay (E/s_u = 10⁴, ν = 0.49) on B/10, B/20 and B/40 cells, F̄ with uGIMP and with
/// quadratic B-splines, and standard uGIMP; q_ult the mean of q over d/B in [0.01, 0.02]. Item 14's
/// assertions, each checked and all failures reported together at the end: F̄-uGIMP within 10 % of
/// 2 + π at B/20 and 6 % at B/40; the ratio of its errors between successive refinements within
/// 1.3–2.0 ([002]: rate ≈ 2/3); F̄-uGIMP's error below F̄-B-spline's at every h; standard MPM above
/// 1.10 × (2 + π) at every h. Runs on two ranks; about 80 minutes (the B/40 runs 20 each).
#[test]
#[ignore]
fn footing_fbar_item_14() {
    let mut text = String::from(
        "## Rigid strip footing on Hencky–J2 clay: q_ult/((2 + π) s_u), mean over d/B in [0.01, 0.02]\n\n\
         | h | points | basis | F̄ | ratio | error | largest deviation of q/s_u in the window | wall [s] |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    let sizes = [0.1, 0.05, 0.025];
    let runs = [("ugimp", true), ("bspline2", true), ("ugimp", false)];
    let mut got = std::collections::HashMap::new();
    for &h in &sizes {
        for (basis, fbar) in runs {
            let s = run_case_on(
                2,
                "footing_fbar",
                &format!("footing-{h}-{basis}-{fbar}"),
                &[
                    format!("parameters.h={h}"),
                    format!("analysis.shape_functions={basis}"),
                    format!("stabilisation.fbar={fbar}"),
                ],
            );
            let m = &s["verification"]["bearing_capacity_ratio"];
            let ratio = m["value"].as_f64().unwrap_or(f64::NAN);
            let detail = m["detail"].as_str().unwrap_or("");
            let deviation = detail.split("largest deviation ").nth(1).and_then(|t| t.split(')').next()).unwrap_or("");
            let _ = writeln!(
                text,
                "| B/{:.0} | {:.0} | {basis} | {} | {ratio:.4} | {:+.1} % | {deviation} | {:.0} |",
                1.0 / h,
                s["particles"].as_f64().unwrap_or(f64::NAN),
                if fbar { "on" } else { "off" },
                100.0 * (ratio - 1.0),
                s["wall_time_s"].as_f64().unwrap()
            );
            got.insert((h.to_string(), basis, fbar), ratio);
        }
    }
    save("footing_fbar.md", &text);
    let err = |h: f64, basis: &str, fbar: bool| (got[&(h.to_string(), basis, fbar)] - 1.0).abs();
    let mut unmet = Vec::new();
    for (h, tol) in [(0.05, 0.10), (0.025, 0.06)] {
        if !matches!(
            err(h, "ugimp", true).partial_cmp(&tol),
            Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
        ) {
            unmet.push(format!("F̄-uGIMP at h = {h}: error {:.4} > {tol}", err(h, "ugimp", true)));
        }
    }
    for w in sizes.windows(2) {
        let r = err(w[0], "ugimp", true) / err(w[1], "ugimp", true);
        if !(1.3..=2.0).contains(&r) {
            unmet.push(format!("F̄-uGIMP error ratio {} → {}: {r:.2} outside 1.3–2.0", w[0], w[1]));
        }
    }
    for &h in &sizes {
        if err(h, "ugimp", true).partial_cmp(&err(h, "bspline2", true)) != Some(std::cmp::Ordering::Less) {
            unmet.push(format!(
                "h = {h}: F̄-uGIMP error {:.4} not below F̄-B-spline's {:.4}",
                err(h, "ugimp", true),
                err(h, "bspline2", true)
            ));
        }
        let standard = got[&(h.to_string(), "ugimp", false)];
        if standard.partial_cmp(&1.10) != Some(std::cmp::Ordering::Greater) {
            unmet.push(format!("h = {h}: standard ratio {standard:.4} ≤ 1.10"));
        }
    }
    assert!(unmet.is_empty(), "item 14 not met:\n{}", unmet.join("\n"));
}

/// The history column `name` of a study run (`label`) as (time, value) pairs.
fn study_history(label: &str, name: &str) -> Vec<(f64, f64)> {
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("studies").join(label).join("history.csv");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let c = header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}"));
    lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap_or(f64::NAN)).collect();
            (v[0], v[c])
        })
        .collect()
}

/// [002]'s dam break (Part E item 15) at the water's stiffness (K = 2 GPa), with the XPIC(8)
/// transfer: Martin & Moyce's n² = 2 column (front within 10 % of the measurement on average), and
/// [002]'s reservoir with F̄-uGIMP, F̄-B-spline and standard uGIMP for 2 s of flow. Item 15's
/// assertions, each checked and all failures reported together at the end: hydrostatic within 2 %
/// of ρ g H after settling, the mass unchanged, the front behind Ritter's before the far wall,
/// x_c(t) of F̄-uGIMP and F̄-B-spline within 0.1 m of each other, and the pressure chequerboard of
/// F̄ at most a third of standard MPM's (settled and at the end). On two ranks; about 7 minutes.
/// Measured: unmet the B-spline run's hydrostatic error (11.6 %) and the x_c gap (0.146 m at the
/// end; under 0.1 m until 1.69 s of flow); the rest met.
#[test]
#[ignore]
fn dam_break_item_15() {
    let mut text = String::from(
        "## Dam break at K = 2 GPa, XPIC(8)\n\n\
         | case | basis | F̄ | hydrostatic | front vs experiment | Ritter ratio | x_c at the end [m] | p chequerboard settled / end | wall [s] |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    let mut unmet = Vec::new();
    let runs: [(&str, &str, &str, bool); 4] = [
        ("dam_break_martin_moyce", "column", "ugimp", true),
        ("dam_break", "reservoir-ugimp", "ugimp", true),
        ("dam_break", "reservoir-bspline", "bspline2", true),
        ("dam_break", "reservoir-standard", "ugimp", false),
    ];
    let mut summaries = std::collections::HashMap::new();
    for (case, label, basis, fbar) in runs {
        let mut sets = vec![format!("analysis.shape_functions={basis}"), format!("stabilisation.fbar={fbar}")];
        if basis == "bspline2" {
            // FLIP blows up in the B-splines' settling stage.
            sets.push("stages.settle.explicit.xpic_order=8".into());
        }
        let s = run_case_on(2, case, label, &sets);
        let v = |m: &str| s["verification"][m]["value"].as_f64().unwrap_or(f64::NAN);
        let r = |m: &str| s["results"][m].as_f64().unwrap_or(f64::NAN);
        let _ = writeln!(
            text,
            "| {case} | {basis} | {} | {:.4} | {:.4} | {:.3} | {:.4} | {:.2e} / {:.2e} | {:.0} |",
            if fbar { "on" } else { "off" },
            v("hydrostatic_pressure_error"),
            v("front_vs_experiment"),
            v("front_speed_ratio"),
            r("centre_x_end"),
            r("pressure_checkerboard_settled"),
            r("pressure_checkerboard_end"),
            s["wall_time_s"].as_f64().unwrap_or(f64::NAN)
        );
        // Item 15 asks its metrics of F̄; the standard run is there for the chequerboard.
        for m in ["hydrostatic_pressure_error", "mass_change", "front_speed_ratio", "front_vs_experiment"] {
            if fbar && s["verification"][m].is_object() && s["verification"][m]["pass"] != true {
                unmet.push(format!("{label}: {m} = {}", v(m)));
            }
        }
        summaries.insert(label, s);
    }
    // x_c(t) of the two bases, compared at the uGIMP run's history times.
    let (a, b) = (
        study_history("reservoir-ugimp", "dam_break.centre_x"),
        study_history("reservoir-bspline", "dam_break.centre_x"),
    );
    let at = |h: &[(f64, f64)], t: f64| {
        h.windows(2)
            .find(|w| w[0].0 <= t && t <= w[1].0)
            .map_or(f64::NAN, |w| w[0].1 + (t - w[0].0) / (w[1].0 - w[0].0).max(1e-300) * (w[1].1 - w[0].1))
    };
    let gap = a.iter().map(|&(t, x)| (at(&b, t) - x).abs()).fold(0.0f64, f64::max);
    let _ = writeln!(text, "\nLargest |x_c(uGIMP) − x_c(B-spline)| over the run: {gap:.4} m");
    if gap.is_nan() || gap > 0.1 {
        unmet.push(format!("x_c of F̄-uGIMP and F̄-B-spline differ by up to {gap:.4} m (> 0.1 m)"));
    }
    let r = |label: &str, m: &str| summaries[label]["results"][m].as_f64().unwrap_or(f64::NAN);
    for m in ["pressure_checkerboard_settled", "pressure_checkerboard_end"] {
        let (f, s) = (r("reservoir-ugimp", m), r("reservoir-standard", m));
        if f.is_nan() || f > s / 3.0 {
            unmet.push(format!("{m}: F̄ {f:.3e} is not at most a third of standard's {s:.3e}"));
        }
    }
    save("dam_break.md", &text);
    assert!(unmet.is_empty(), "Part E item 15, unmet:\n  {}", unmet.join("\n  "));
}

/// Runs `porompm sweep ARGS --out target/studies/NAME --quiet` (the case first in `args`) into a
/// fresh directory, asserts that it succeeded, and returns the directory.
fn study_sweep(name: &str, args: &[&str]) -> PathBuf {
    let out = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/studies").join(name);
    let _ = std::fs::remove_dir_all(&out);
    let o = Command::new(env!("CARGO_BIN_EXE_porompm"))
        .arg("sweep")
        .args(args)
        .args(["--out", &out.display().to_string(), "--quiet"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("porompm sweep runs");
    assert!(o.status.success(), "{name}: {}", String::from_utf8_lossy(&o.stderr));
    out
}

/// Implicit against explicit on Terzaghi's column (issue «Seed [002]» item 6; [003]'s claim that
/// the implicit step can be ~100× larger at equal accuracy): one `porompm sweep` of
/// cases/terzaghi.toml with three variants (the implicit dynamic u–p–U as shipped, the implicit
/// quasi-static u–p, and the explicit u–U with the nodal pore pressure at its wave step) on 10
/// and 20 cells, the implicit steps varied. For each grid, the implicit step at the explicit
/// run's error (the RMS pressure error at T_v = 0.5) is read off the implicit error–step curve,
/// log–log between the largest step that is at least as accurate and the next larger one; the
/// ratio of that step to the explicit one, and of the two runs' wall times, go into the table.
/// The assertion is the claim itself: at least 100× at both grids.
#[test]
#[ignore]
fn implicit_against_explicit_terzaghi() {
    let metric = "p_rms_error_Tv0.5";
    let out = study_sweep(
        "implicit_explicit_terzaghi",
        &[
            "cases/terzaghi.toml",
            "--variant",
            "implicit_dynamic:",
            "--variant",
            "quasi_static:stages.consolidation.analysis=quasi_static",
            "--variant",
            "explicit:stages.consolidation.analysis=dynamic_explicit;\
             stages.consolidation.explicit={cfl=0.5,pore_pressure=\"nodal\"};time.dt=1e-3",
            "--vary",
            "grid.cells=[1,10],[1,20]",
            "--vary",
            "time.dt=0.05,0.02,1e-2,7e-3,5e-3,3e-3,2e-3,1.5e-3,1e-3,5e-4",
            "--set",
            "output.fields_every=0",
            "--metric",
            metric,
        ],
    );
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let mut lines = csv.lines();
    let header = csv_fields(lines.next().unwrap());
    let col = |name: &str| header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"));
    // Fields with commas ("[1,10]") are quoted.
    let rows: Vec<Vec<String>> = lines.map(csv_fields).collect();
    let num = |r: &Vec<String>, c: &str| r[col(c)].parse::<f64>().unwrap_or(f64::NAN);
    let mut text = String::from(
        "## Implicit against explicit: Terzaghi's column (RMS pressure error at T_v = 0.5)\n\n\
         | cells | implicit | explicit step [s] | explicit error | explicit wall [s] | implicit step at that error [s] | step ratio | implicit wall there [s] | wall ratio |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    let mut unmet = Vec::new();
    for cells in ["[1,10]", "[1,20]"] {
        let of = |variant: &str| -> Vec<&Vec<String>> {
            rows.iter().filter(|r| r[col("variant")] == variant && r[col("grid.cells")] == cells).collect()
        };
        let explicit = of("explicit")[0];
        let (ex_err, ex_dt, ex_wall) =
            (num(explicit, metric), num(explicit, "mean_dt_s"), num(explicit, "wall_time_s"));
        for variant in ["implicit_dynamic", "quasi_static"] {
            let mut curve: Vec<(f64, f64, f64)> =
                of(variant).iter().map(|r| (num(r, "mean_dt_s"), num(r, metric), num(r, "wall_time_s"))).collect();
            curve.sort_by(|a, b| a.0.total_cmp(&b.0));
            // The largest step at least as accurate as the explicit run, and the next larger one.
            let pass = curve.iter().rposition(|c| c.1 <= ex_err);
            let (dt, wall) = match pass {
                Some(i) if i + 1 < curve.len() => {
                    let (a, b) = (curve[i], curve[i + 1]);
                    let s = (ex_err / a.1).ln() / (b.1 / a.1).ln();
                    (a.0 * (b.0 / a.0).powf(s), a.2 + s * (b.2 - a.2))
                }
                Some(i) => (curve[i].0, curve[i].2),
                None => (f64::NAN, f64::NAN),
            };
            let _ = writeln!(
                text,
                "| {cells} | {variant} | {ex_dt:.3e} | {ex_err:.3e} | {ex_wall:.2} | {dt:.3e} | {:.0} | {wall:.3} | {:.0} |",
                dt / ex_dt,
                ex_wall / wall
            );
            let ratio = dt / ex_dt;
            if variant == "implicit_dynamic" && (ratio.is_nan() || ratio < 100.0) {
                unmet.push(format!("{cells}: the implicit step at equal error is {:.0}× the explicit one", dt / ex_dt));
            }
        }
    }
    let _ = writeln!(text, "\nThe sweep's table and work_precision.png: {}", out.display());
    save("implicit_explicit_terzaghi.md", &text);
    assert!(unmet.is_empty(), "[003]'s ~100× claim, unmet:\n  {}", unmet.join("\n  "));
}

/// Implicit against explicit on [002]'s rigid strip footing (issue «Seed [002]» item 6): one
/// `porompm sweep` of cases/footing_fbar.toml, the explicit F̄-uGIMP run as shipped (Hencky–J2,
/// Δt = 0.4 h/c_p) against an implicit static stage of the same geometry and footing (von Mises
/// with q ≤ √3 s_u, the same plane-strain collapse load, with B̄, and with the implicit F̄ of
/// `kernels::fbar`; load steps of 0.01 s, d = 0.1 mm) at B/10 and B/20. q_ult/s_u is read over
/// item 14's window, d/B in [0.01, 0.02] (the implicit static footing reaches it at B/20 since a
/// failed step is retried with a line search, `assembly::LINE_SEARCH_RETRY`). The table gives each
/// run's error against 2 + π, step and wall time. The
/// assertions: the implicit B̄ run is at least as accurate as the explicit one on each grid, in
/// less wall time; the implicit F̄ run finds the explicit F̄ run's plateau within 1.5 %.
#[test]
#[ignore]
fn implicit_against_explicit_footing() {
    let out = study_sweep(
        "implicit_explicit_footing",
        &[
            "cases/footing_fbar.toml",
            "--metric",
            "bearing_capacity_ratio",
            "--variant",
            "explicit_fbar:",
            "--variant",
            "implicit_static:stages.penetration={name=\"penetration\",analysis=\"static\",duration=3.0,dt=0.01};\
             materials.clay.model={type=\"von_mises\",young_modulus=1e6,poisson_ratio=0.49,cohesion=100.0};\
             stabilisation={bbar=true}",
            "--variant",
            "implicit_static_fbar:stages.penetration={name=\"penetration\",analysis=\"static\",duration=3.0,dt=0.01};\
             materials.clay.model={type=\"von_mises\",young_modulus=1e6,poisson_ratio=0.49,cohesion=100.0};\
             stabilisation={fbar=true}",
            "--vary",
            "parameters.h=0.1,0.05",
            "--set",
            "verification.plateau=[0.01,0.02]",
            "--set",
            "verification.stop_settlement=0.021",
            "--set",
            "output.history_every=10",
        ],
    );
    let mut text = String::from(
        "## Implicit against explicit: [002]'s rigid strip footing (q_ult/s_u over d/B in [0.01, 0.02])\n\n\
         | h | run | q_ult/s_u | error vs 2 + π | steps | mean step [s] | wall [s] |\n|---|---|---|---|---|---|---|\n",
    );
    let mut unmet = Vec::new();
    for (i, h) in ["B/10", "B/20"].iter().enumerate() {
        // Runs: explicit h = 0.1, 0.05, then implicit B̄ h = 0.1, 0.05, then implicit F̄.
        let mut errors = Vec::new();
        for (run, label) in [
            (i, "explicit F̄-uGIMP, Hencky–J2"),
            (2 + i, "implicit static B̄-uGIMP, von Mises"),
            (4 + i, "implicit static F̄-uGIMP, von Mises"),
        ] {
            let s: Value =
                serde_json::from_str(&std::fs::read_to_string(out.join(format!("run_{run}/summary.json"))).unwrap())
                    .unwrap();
            let ratio = value(&s, "bearing_capacity_ratio");
            let (steps, time, wall) =
                (s["steps"].as_f64().unwrap(), s["time_s"].as_f64().unwrap(), s["wall_time_s"].as_f64().unwrap());
            let _ = writeln!(
                text,
                "| {h} | {label} | {:.4} | {:+.2} % | {steps} | {:.3e} | {wall:.1} |",
                ratio * (2.0 + std::f64::consts::PI),
                100.0 * (ratio - 1.0),
                time / steps
            );
            errors.push(((ratio - 1.0).abs(), wall));
        }
        let ((ex, ew), (im, iw), (imf, _)) = (errors[0], errors[1], errors[2]);
        if im.is_nan() || im > ex || iw >= ew {
            unmet.push(format!("{h}: implicit error {im:.4} in {iw:.1} s against explicit {ex:.4} in {ew:.1} s"));
        }
        // The implicit F̄ projects what the explicit one does: the same plateau within 1.5 %.
        if imf.is_nan() || (imf - ex).abs() > 0.015 {
            unmet.push(format!("{h}: implicit F̄ error {imf:.4} against explicit F̄ {ex:.4}"));
        }
    }
    save("implicit_explicit_footing.md", &text);
    assert!(unmet.is_empty(), "unmet:\n  {}", unmet.join("\n  "));
}

/// [002]'s landslide (§4.4, Part E item 16; `cases/landslide_3d.toml`, the reconstructed slope of
/// docs/cases_3d.md §1, on a prism one cell wide between its roller walls, W = h = 0.5 m: the
/// walls make it a plane-strain slice whatever its width) with F̄-uGIMP, F̄-B-spline and standard
/// uGIMP and B-splines, each
/// settled for 1 s at peak strength and run for 5.5 s after the peak strength is divided by 1.65
/// (the flow with XPIC(8), see the case).
/// Item 16's geometry-independent assertions, each checked and all failures reported together:
/// the F̄ run-outs within 5 % of each other, standard uGIMP's below 1 % of F̄'s, standard
/// B-splines' below 0.75 of each F̄ run-out; and the guards without which the ratios mean
/// nothing: every slope stood before the trigger (front advance and largest speed within the
/// check's tolerances), every body kept its mass, and both F̄ slopes failed (R ≥ H = 5 m: the mass
/// ran out farther than the slope is high; the plane section's F̄ run-outs are 9.0 and 8.7 m). The
/// paper's run-outs (29.96, 29.29, 0.0055 and 19.07 m) belong to its lost geometry and are
/// printed beside ours, not asserted. On two ranks; about an hour (F̄-uGIMP: 834 s).
#[test]
#[ignore]
fn landslide_item_16() {
    let mut text = String::from(
        "## [002]'s landslide, reconstructed (h = 0.5 m, W = 0.5 m): run-out R 5.5 s after the trigger\n\n\
         | basis | F̄ | R at 1.5 / 2.5 / 3.5 / 5.5 s [m] | foremost point [m] | centre of mass [m] | paper's R [m] | front before the trigger [m] | speed at the trigger [m/s] | points | wall [s] |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    let runs =
        [("ugimp", true, 29.96), ("bspline2", true, 29.29), ("ugimp", false, 0.0055), ("bspline2", false, 19.07)];
    let mut unmet = Vec::new();
    let mut got = std::collections::HashMap::new();
    for (basis, fbar, paper) in runs {
        let label = format!("landslide-{basis}-{fbar}");
        let s = run_case_on(
            2,
            "landslide_3d",
            &label,
            &[
                "parameters.W=0.5".to_string(),
                format!("analysis.shape_functions={basis}"),
                format!("stabilisation.fbar={fbar}"),
            ],
        );
        let r = |m: &str| s["results"][m].as_f64().unwrap_or(f64::NAN);
        for m in ["standing_advance", "standing_speed", "mass_change"] {
            if s["verification"][m]["pass"] != true {
                unmet.push(format!(
                    "{label}: {m} = {} ({})",
                    s["verification"][m]["value"], s["verification"][m]["detail"]
                ));
            }
        }
        let runout = r("runout");
        let _ = writeln!(
            text,
            "| {basis} | {} | {:.3} / {:.3} / {:.3} / {:.3} | {:.3} | {:.3} | {paper} | {:.2e} | {:.2e} | {:.0} | {:.0} |",
            if fbar { "on" } else { "off" },
            r("runout_t1.5"),
            r("runout_t2.5"),
            r("runout_t3.5"),
            r("runout_t5.5"),
            r("runout_tip"),
            r("mass_centre_advance"),
            s["verification"]["standing_advance"]["value"].as_f64().unwrap_or(f64::NAN),
            s["verification"]["standing_speed"]["value"].as_f64().unwrap_or(f64::NAN),
            s["particles"].as_f64().unwrap_or(f64::NAN),
            s["wall_time_s"].as_f64().unwrap_or(f64::NAN),
        );
        got.insert((basis, fbar), runout);
    }
    let (fg, fb, sg, sb) =
        (got[&("ugimp", true)], got[&("bspline2", true)], got[&("ugimp", false)], got[&("bspline2", false)]);
    let agree = (fg - fb).abs() / (0.5 * (fg + fb));
    let locks = sg / fg.min(fb);
    let _ = writeln!(
        text,
        "\n| assertion (item 16) | value | pass if | paper |\n|---|---|---|---|\n\
         | F̄ bases agree, |R_FG − R_FB| / mean | {agree:.4} | ≤ 0.05 | 0.023 |\n\
         | standard uGIMP locks, R_SG / min R_F | {locks:.2e} | < 0.01 | 1.8e-4 |\n\
         | standard B-splines too stiff, R_SB / R_FG | {:.3} | < 0.75 | 0.637 |\n\
         | standard B-splines too stiff, R_SB / R_FB | {:.3} | < 0.75 | 0.651 |",
        sb / fg,
        sb / fb
    );
    save("landslide.md", &text);
    for (name, r) in [("F̄-uGIMP", fg), ("F̄-B-spline", fb)] {
        if !matches!(r.partial_cmp(&5.0), Some(std::cmp::Ordering::Greater | std::cmp::Ordering::Equal)) {
            unmet.push(format!("{name}: R = {r:.3} m, the slope did not fail (R < H = 5 m)"));
        }
    }
    if !matches!(agree.partial_cmp(&0.05), Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)) {
        unmet.push(format!("F̄ run-outs {fg:.3} and {fb:.3} m differ by {:.1} % (> 5 %)", 100.0 * agree));
    }
    if locks.partial_cmp(&0.01) != Some(std::cmp::Ordering::Less) {
        unmet.push(format!("standard uGIMP's run-out {sg:.4} m is {:.2} % of F̄'s (≥ 1 %)", 100.0 * locks));
    }
    for (name, r) in [("F̄-uGIMP", fg), ("F̄-B-spline", fb)] {
        if (sb / r).partial_cmp(&0.75) != Some(std::cmp::Ordering::Less) {
            unmet.push(format!("standard B-splines' run-out {sb:.3} m is {:.3} of {name}'s (≥ 0.75)", sb / r));
        }
    }
    assert!(unmet.is_empty(), "item 16 not met:\n{}", unmet.join("\n"));
}
