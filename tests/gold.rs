//! Gold values: every case in `cases/` has its key numbers stored in `cases/gold/<case>.json` — the
//! verification metrics and whether each meets its target (`pass.<metric>`, 1 or 0), the
//! `results`, the number of steps and of warnings, a dynamic run's energy imbalance, and the probe,
//! reaction and boundary values of `history.csv` at the middle and at the end of the run — and
//! the default test run compares a fresh run with them at a relative tolerance near a direct
//! solver's round-off (each file's `rtol`, measured between the default solver and
//! `direct-lu.opts`). This is the habit of PETSc's test output files and MOOSE's CSVDiff: a change
//! of any number shows up here, and a refresh shows up in the diff.
//!
//! Refresh (after a change that is meant to move the numbers; review the diff of `cases/gold/`):
//!
//! ```text
//! make gold        # PORO_GOLD_REFRESH=1 cargo test --release --test gold
//! ```
//!
//! A refresh keeps each file's `sets` (the overrides that shorten a long case), `rtol` and
//! `governing` (the parameters whose 1 % change must fail the comparison; checked by
//! `make study`), and rewrites its `values`.
//!
//! Comparison: |v − g| ≤ rtol·|g| + rtol·scale, where scale is the largest |g| of the same kind of
//! quantity in the same file (displacements, stresses and pressures, forces, …), so that a value
//! at round-off level next to large ones of its kind (a shear stress of 1e-12 Pa beside 1e3 Pa) is
//! not compared digit by digit. Verification metrics are dimensionless errors or ratios and are
//! compared with an absolute floor of 1e-10.

mod common;

use common::{gold_path, read_gold, root, Gold};
use serde_json::{json, Map, Value};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

fn write_gold(case: &str, gold: &Gold) {
    let values: Map<String, Value> =
        gold.values.iter().map(|(k, v)| (k.clone(), v.map(|x| json!(x)).unwrap_or(Value::Null))).collect();
    let v = json!({
        "case": format!("cases/{case}.toml"),
        "sets": gold.sets,
        "rtol": gold.rtol,
        "governing": gold.governing,
        "values": values,
    });
    std::fs::write(gold_path(case), serde_json::to_string_pretty(&v).unwrap() + "\n").expect("gold file written");
}

/// Runs a case with its gold overrides (and `extra` ones) into a fresh directory; returns the
/// directory and the run's summary.
fn run(case: &str, label: &str, sets: &[String], extra: &[String], options: &[&str]) -> (PathBuf, Value) {
    let _cores = common::Cores::shared();
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("gold").join(label);
    let _ = std::fs::remove_dir_all(&out);
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_porompm"));
    cmd.args(["run", &format!("cases/{case}.toml"), "--out", out.to_str().unwrap(), "--quiet"]);
    cmd.args(options);
    for s in sets.iter().chain(extra) {
        cmd.args(["--set", s]);
    }
    let o = cmd.current_dir(root()).output().expect("porompm runs");
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json");
    let s: Value = serde_json::from_str(&text).expect("JSON");
    assert!(o.status.success() && s["status"] == "completed", "{label}: {}", String::from_utf8_lossy(&o.stderr));
    (out, s)
}

/// The kind of a value, for the scale of its absolute floor.
fn kind(key: &str) -> &'static str {
    if key.starts_with("verification.") || key == "summary.energy_balance_error" {
        return "verification";
    }
    if key.starts_with("results.") || key.starts_with("pass.") || key == "steps" || key == "summary.warnings" {
        return "exact";
    }
    let last = key.rsplit('.').next().unwrap();
    match last {
        "ux" | "uy" | "uz" | "displacement_x" | "displacement_y" | "displacement_z" | "settlement" => "displacement",
        "sxx" | "syy" | "sxy" | "p" | "p_excess" | "q" => "stress",
        "reaction_x" | "reaction_y" | "reaction_z" => "force",
        _ => "other",
    }
}

/// Whether a history column is a probe, reaction or boundary-motion value worth keeping (one of
/// the kinds above), or a footing's load (`bearing.q…`) or a Lamé check column.
fn kept_column(name: &str) -> bool {
    kind(name) != "other" || name.starts_with("bearing.q") || name.starts_with("lame.")
}

/// The values of a run: metrics and their pass flags, results, steps and the kept history columns at the row nearest
/// half the run's time and at the last row.
fn values_of(out: &Path, s: &Value) -> BTreeMap<String, Option<f64>> {
    let mut v = BTreeMap::new();
    v.insert("steps".to_string(), s["steps"].as_f64());
    v.insert("summary.warnings".to_string(), s["warnings"].as_array().map(|w| w.len() as f64));
    if let Some(e) = s["energy_balance_error"].as_f64() {
        v.insert("summary.energy_balance_error".to_string(), Some(e));
    }
    for (k, m) in s["verification"].as_object().into_iter().flatten() {
        v.insert(format!("verification.{k}"), m["value"].as_f64());
        v.insert(format!("pass.{k}"), m["pass"].as_bool().map(|p| if p { 1.0 } else { 0.0 }));
    }
    for (k, x) in s["results"].as_object().into_iter().flatten() {
        v.insert(format!("results.{k}"), x.as_f64());
    }
    let text = std::fs::read_to_string(out.join("history.csv")).expect("history.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|x| x.parse().unwrap_or(f64::NAN)).collect()).collect();
    let end = rows.last().expect("history rows");
    let t_mid = 0.5 * end[0];
    let mid = rows.iter().min_by(|a, b| (a[0] - t_mid).abs().total_cmp(&(b[0] - t_mid).abs())).unwrap();
    for (c, name) in header.iter().enumerate() {
        if kept_column(name) {
            v.insert(format!("history.mid.{name}"), Some(mid[c]).filter(|x| x.is_finite()));
            v.insert(format!("history.end.{name}"), Some(end[c]).filter(|x| x.is_finite()));
        }
    }
    v
}

/// The largest magnitude of the gold values of each kind: the scale a value's difference is
/// measured against besides its own magnitude.
fn kind_scales(gold: &Gold) -> BTreeMap<&'static str, f64> {
    let mut scale: BTreeMap<&str, f64> = BTreeMap::new();
    for (k, g) in &gold.values {
        let s = scale.entry(kind(k)).or_insert(0.0);
        *s = s.max(g.unwrap_or(0.0).abs());
    }
    scale
}

/// The differences of `got` from `gold` beyond the tolerance, one line each.
fn differences(gold: &Gold, got: &BTreeMap<String, Option<f64>>) -> Vec<String> {
    let scale = kind_scales(gold);
    let mut out = Vec::new();
    for (k, g) in &gold.values {
        let floor = match kind(k) {
            "verification" => 1e-10_f64.max(gold.floor),
            "exact" => f64::MIN_POSITIVE,
            other => (gold.rtol * scale[other]).max(gold.floor),
        };
        match (g, got.get(k)) {
            (_, None) => out.push(format!("{k}: missing from the run")),
            (None, Some(None)) => {}
            (Some(g), Some(Some(v))) if (v - g).abs() <= gold.rtol * g.abs() + floor => {}
            (g, Some(v)) => out.push(format!(
                "{k}: {} (gold {}, relative difference {:.2e})",
                v.map_or("NaN".into(), |x| format!("{x:e}")),
                g.map_or("NaN".into(), |x| format!("{x:e}")),
                match (g, v) {
                    (Some(g), Some(v)) => (v - g).abs() / g.abs().max(f64::MIN_POSITIVE),
                    _ => f64::INFINITY,
                }
            )),
        }
    }
    for k in got.keys().filter(|k| !gold.values.contains_key(*k)) {
        out.push(format!("{k}: new in the run, not in the gold file"));
    }
    out
}

/// Runs `case` as its gold file says and compares (or, with PORO_GOLD_REFRESH=1, rewrites the
/// values).
fn check(case: &str) {
    let mut gold = read_gold(case);
    let (out, s) = run(case, case, &gold.sets, &[], &[]);
    let got = values_of(&out, &s);
    if std::env::var("PORO_GOLD_REFRESH").is_ok_and(|v| v == "1") {
        gold.values = got;
        write_gold(case, &gold);
        return;
    }
    let diff = differences(&gold, &got);
    assert!(diff.is_empty(), "{case} differs from cases/gold/{case}.json:\n  {}", diff.join("\n  "));
}

macro_rules! gold_tests {
    ($($name:ident),* $(,)?) => {
        $(#[test] fn $name() { check(stringify!($name)); })*
        const CASES: &[&str] = &[$(stringify!($name)),*];
    };
}

gold_tests!(
    consolidation_layer,
    consolidation_layer_3d,
    cook_membrane,
    dam_break,
    dam_break_martin_moyce,
    elastic_column,
    embankment_3d,
    footing_fbar,
    footing_ld,
    footing_near_slope,
    footing_peer,
    footing_peer_3d,
    footing_rigid,
    footing_sd,
    footing_stl_3d,
    footing_undrained,
    harmonic_column_zone1,
    harmonic_column_zone2,
    harmonic_column_zone3,
    hollow_cylinder,
    hollow_cylinder_increments,
    lame_cylinder,
    landslide_3d,
    large_strain_consolidation,
    patch_test,
    patch_test_3d,
    rigid_rotation,
    rotated_stiffness,
    shock_wave,
    slope_clay,
    slope_sand,
    slumping_block,
    terzaghi,
    terzaghi_3d,
    terzaghi_explicit,
    vertical_cut,
    vertical_cut_dmgc,
    vibrating_bar,
);

#[test]
fn every_case_has_a_gold_test_and_file() {
    let mut shipped: Vec<String> = std::fs::read_dir(root().join("cases"))
        .unwrap()
        .filter_map(|e| {
            let p = e.unwrap().path();
            (p.extension()? == "toml").then(|| p.file_stem().unwrap().to_string_lossy().into_owned())
        })
        .collect();
    shipped.sort();
    let mut listed: Vec<String> = CASES.iter().map(|c| c.to_string()).collect();
    listed.sort();
    assert_eq!(shipped, listed, "cases/ and the gold tests list different cases");
    for c in CASES {
        let g = read_gold(c);
        assert!(!g.values.is_empty() && !g.governing.is_empty(), "{c}: gold file without values or governing");
        assert!(g.rtol > 0.0 && g.rtol <= 1e-5, "{c}: rtol {} is not near round-off", g.rtol);
    }
}

/// The value at a dotted path of a case file (arrays of tables indexed by `name`).
fn case_value(case: &str, path: &str) -> toml::Value {
    let text = std::fs::read_to_string(root().join(format!("cases/{case}.toml"))).unwrap();
    let mut cur: toml::Value = toml::from_str(&text).unwrap();
    for seg in path.split('.') {
        cur = match cur {
            toml::Value::Table(mut t) => t.remove(seg).unwrap_or_else(|| panic!("{case}: no `{path}`")),
            toml::Value::Array(a) => a
                .into_iter()
                .find(|e| e.get("name").and_then(|n| n.as_str()) == Some(seg))
                .unwrap_or_else(|| panic!("{case}: no element `{seg}` in `{path}`")),
            _ => panic!("{case}: `{path}` is not a table"),
        };
    }
    cur
}

/// `path=value×factor` for a number or a (nested) array of numbers.
fn scaled(case: &str, path: &str, factor: f64) -> String {
    fn fmt(v: &toml::Value, factor: f64, what: &str) -> String {
        match v {
            toml::Value::Array(a) => {
                format!("[{}]", a.iter().map(|x| fmt(x, factor, what)).collect::<Vec<_>>().join(","))
            }
            v => {
                let x = v.as_float().or(v.as_integer().map(|i| i as f64));
                format!("{:e}", x.unwrap_or_else(|| panic!("`{what}` is not a number")) * factor)
            }
        }
    }
    format!("{path}={}", fmt(&case_value(case, path), factor, &format!("{case}: {path}")))
}

/// Whether a 1 % change of `param` makes `case` differ from its gold values.
fn one_percent_fails(case: &str, param: &str) -> Vec<String> {
    let gold = read_gold(case);
    let label = format!("{case}-{}", param.replace('.', "_"));
    assert!(!gold.values.is_empty(), "{case}: no gold values");
    let (out, s) = run(case, &label, &gold.sets, &[scaled(case, param, 1.01)], &[]);
    differences(&gold, &values_of(&out, &s)).into_iter().filter(|d| !d.ends_with("not in the gold file")).collect()
}

#[test]
fn terzaghi_with_one_percent_more_conductivity_differs_from_its_gold_values() {
    let diff = one_percent_fails("terzaghi", "materials.soil.hydraulic_conductivity");
    assert!(diff.len() > 5, "a 1 % larger k changed only: {diff:?}");
}

#[test]
fn the_comparison_ignores_nothing_beyond_its_tolerance() {
    // A value moved by 10 rtol is reported; by 0.1 rtol it is not; a missing value and a NaN are.
    let gold = Gold {
        sets: vec![],
        rtol: 1e-8,
        governing: vec![],
        values: [("history.end.a.uy", Some(2.0)), ("history.end.b.uy", Some(1e-3)), ("results.x", Some(5.0))]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect(),
        floor: 0.0,
    };
    let with = |k: &str, v: Option<f64>| {
        let mut g = gold.values.clone();
        g.insert(k.to_string(), v);
        g
    };
    assert!(differences(&gold, &gold.values).is_empty());
    assert!(differences(&gold, &with("results.x", Some(5.0 * (1.0 + 1e-9)))).is_empty());
    assert_eq!(differences(&gold, &with("results.x", Some(5.0 * (1.0 + 1e-7)))).len(), 1);
    assert_eq!(differences(&gold, &with("history.end.b.uy", Some(1e-3 + 1e-7))).len(), 1);
    assert_eq!(differences(&gold, &with("results.x", None)).len(), 1);
    let mut missing = gold.values.clone();
    missing.remove("results.x");
    assert_eq!(differences(&gold, &missing).len(), 1);
}

/// `make study`: a 1 % change of each governing parameter of every case (its stiffness,
/// permeability, strength or load) fails the comparison with its gold values.
#[test]
#[ignore]
fn one_percent_change_of_any_governing_parameter_fails_every_case() {
    let mut silent = Vec::new();
    for case in CASES {
        for param in read_gold(case).governing {
            let diff = one_percent_fails(case, &param);
            eprintln!("{case}: {param} × 1.01 → {} values differ", diff.len());
            if diff.is_empty() {
                silent.push(format!("{case}: {param}"));
            }
        }
    }
    assert!(silent.is_empty(), "a 1 % change went unnoticed: {silent:?}");
}

/// `make study`: the gold tolerance of each case covers the difference between the default solver
/// and a direct LU factorisation (prints the largest relative difference per case).
#[test]
#[ignore]
fn gold_values_hold_with_a_direct_solver() {
    let mut failed = Vec::new();
    for case in CASES {
        let gold = read_gold(case);
        let (out, s) =
            run(case, &format!("{case}-lu"), &gold.sets, &[], &["--options-file", "petsc_options/direct-lu.opts"]);
        let diff = differences(&gold, &values_of(&out, &s));
        eprintln!("{case}: {} values beyond rtol {:e} with direct LU", diff.len(), gold.rtol);
        if !diff.is_empty() {
            failed.push(format!("{case}: {}", diff.join("; ")));
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

/// Relative tolerance of a case's values on several ranks against its gold values (one rank): the
/// sums over particles and nodes run in another order and the default factorisation is MUMPS
/// instead of UMFPACK, so values agree to the Newton tolerance (1e-6 of the residual), not to
/// round-off.
const RANKS_RTOL: f64 = 1e-5;

/// Absolute floor [SI units] of the comparison on several ranks: values that are round-off on
/// one rank (the reactions of a rigid rotation or of a patch test, 1e-11 N) are round-off of
/// another size on several.
const RANKS_FLOOR: f64 = 1e-9;

/// The cases the default suite runs on three ranks rather than two: those whose three-rank run takes a few
/// seconds (the plane and 3D patch tests, rotations and cylinders, Terzaghi's column in the plane
/// and in 3D, the static elastic column, the peer footings in the plane and in 3D) and the explicit F̄ footing (7 s; the
/// explicit path with points crossing rank boundaries). Every other case's three-rank run took 7 to
/// 60 s, 650 s together, where three processes share the two cores of the CI machine: the default
/// suite runs those on two ranks, `make study` on three as well, and these on two
/// ([`every_case_gives_its_gold_values_on_the_other_rank_count`]).
const THREE_RANKS_BY_DEFAULT: &[&str] = &[
    "elastic_column",
    "footing_fbar",
    "footing_peer",
    "footing_peer_3d",
    "hollow_cylinder",
    "hollow_cylinder_increments",
    "lame_cylinder",
    "patch_test",
    "patch_test_3d",
    "rigid_rotation",
    "rotated_stiffness",
    "terzaghi",
    "terzaghi_3d",
];

/// Runs `runs` (case, ranks), each shortened as its gold file says, and compares each with its gold
/// values (those of one rank): completed with the same step count, every metric, result and kept
/// history value within [`RANKS_RTOL`] (or the gold file's own tolerance if larger). Never a hang:
/// each run has 600 s. Writes the table of the largest relative differences to
/// `target/distributed/{table}` and fails with every difference found.
fn gold_values_on_ranks(runs: &[(&str, usize)], table_name: &str) {
    let mut failed = Vec::new();
    let mut table = vec![
        "| case | ranks | status | steps | largest relative difference | value | migrated points | run time (s) |"
            .to_string(),
        "|---|---|---|---|---|---|---|---|".to_string(),
    ];
    let _cores = common::Cores::exclusive();
    for &(case, ranks) in runs {
        let gold = read_gold(case);
        let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("ranks").join(format!("{case}-{ranks}"));
        let _ = std::fs::remove_dir_all(&out);
        let np = ranks.to_string();
        let mut cmd = Command::new("timeout");
        cmd.args(["600", "mpirun", "--oversubscribe", "-n", &np, env!("CARGO_BIN_EXE_porompm"), "run"]);
        cmd.args([&format!("cases/{case}.toml"), "--out", out.to_str().unwrap(), "--quiet"]);
        for s in &gold.sets {
            cmd.args(["--set", s]);
        }
        let o = common::mpi_env(&mut cmd).current_dir(root()).output().expect("mpirun runs");
        assert_ne!(o.status.code(), Some(124), "{case}: no end within 600 s on {ranks} ranks (a hang)");
        let s: Value = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap_or_default())
            .unwrap_or_else(|_| panic!("{case}: no summary.json on {ranks} ranks"));
        if s["status"] != "completed" || !o.status.success() {
            failed.push(format!("{case} on {ranks} ranks: {} {}", s["status"], s["error"]));
            continue;
        }
        let got = values_of(&out, &s);
        let loose = Gold { rtol: gold.rtol.max(RANKS_RTOL), floor: RANKS_FLOOR, ..read_gold(case) };
        let diff = differences(&loose, &got);
        let (worst, which) = largest_relative_difference(&gold, &got);
        table.push(format!(
            "| {case} | {ranks} | {} | {} | {worst:.1e} | {which} | {} | {:.1} |",
            s["status"].as_str().unwrap_or("?"),
            s["steps"],
            s["migrated_particles"],
            s["wall_time_s"].as_f64().unwrap_or(f64::NAN)
        ));
        if !diff.is_empty() {
            failed.push(format!("{case} on {ranks} ranks:\n  {}", diff.join("\n  ")));
        }
    }
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/distributed");
    std::fs::create_dir_all(&dir).expect("target/distributed");
    std::fs::write(dir.join(table_name), table.join("\n") + "\n").expect("the table");
    eprintln!("{}", table.join("\n"));
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// Every case gives its gold values on several ranks: the [`THREE_RANKS_BY_DEFAULT`] on three,
/// every other case on two ([`gold_values_on_ranks`]; table `target/distributed/ranks.md`).
#[test]
fn every_case_gives_its_gold_values_on_two_ranks_or_on_three() {
    assert!(THREE_RANKS_BY_DEFAULT.iter().all(|c| CASES.contains(c)), "{THREE_RANKS_BY_DEFAULT:?} are cases");
    let runs: Vec<(&str, usize)> =
        CASES.iter().map(|&case| (case, if THREE_RANKS_BY_DEFAULT.contains(&case) { 3 } else { 2 })).collect();
    gold_values_on_ranks(&runs, "ranks.md");
}

/// The rank counts the default suite leaves out (`make study`; table
/// `target/distributed/ranks_study.md`): every case but the [`THREE_RANKS_BY_DEFAULT`] on three
/// ranks, and those on two.
#[test]
#[ignore = "the other rank counts (make study)"]
fn every_case_gives_its_gold_values_on_the_other_rank_count() {
    let runs: Vec<(&str, usize)> =
        CASES.iter().map(|&case| (case, if THREE_RANKS_BY_DEFAULT.contains(&case) { 2 } else { 3 })).collect();
    gold_values_on_ranks(&runs, "ranks_study.md");
}

/// Every case on one rank against its gold values: per case the number of values compared and the
/// largest difference relative to the value plus the scale of its kind (as [`differences`] measures,
/// with no floor), written to `target/gold/table.md`. This is the before/after table of a change
/// that must not change the answers (a refactor): the gold files hold the answers before it.
/// `make gold-table`.
#[test]
#[ignore = "writes the table of every case against its gold values (make gold-table)"]
fn every_case_against_its_gold_values_table() {
    let mut table = vec![
        "| case | values compared | largest relative difference | value | run time (s) |".to_string(),
        "|---|---|---|---|---|".to_string(),
    ];
    let mut failed = Vec::new();
    for case in CASES {
        let gold = read_gold(case);
        let (out, s) = run(case, case, &gold.sets, &[], &[]);
        let got = values_of(&out, &s);
        let scale = kind_scales(&gold);
        let (mut worst, mut which, mut compared) = (0.0f64, String::from("-"), 0);
        for (k, g) in &gold.values {
            if let (Some(g), Some(Some(v))) = (g, got.get(k)) {
                compared += 1;
                let d = (v - g).abs() / (g.abs() + scale[kind(k)]).max(f64::MIN_POSITIVE);
                if d > worst {
                    (worst, which) = (d, k.clone());
                }
            }
        }
        table.push(format!(
            "| {case} | {compared} | {worst:.1e} | {which} | {:.1} |",
            s["wall_time_s"].as_f64().unwrap_or(f64::NAN)
        ));
        let diff = differences(&gold, &got);
        if !diff.is_empty() {
            failed.push(format!("{case}:\n  {}", diff.join("\n  ")));
        }
    }
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/gold");
    std::fs::create_dir_all(&dir).expect("target/gold");
    std::fs::write(dir.join("table.md"), table.join("\n") + "\n").expect("table.md");
    eprintln!("{}", table.join("\n"));
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// The smallest relative tolerance under which a run's values would match the gold values (as
/// [`differences`] compares them: against |g| plus the scale of their kind), and the value that
/// needs it.
fn largest_relative_difference(gold: &Gold, got: &BTreeMap<String, Option<f64>>) -> (f64, String) {
    let scale = kind_scales(gold);
    let mut worst = (0.0, String::from("-"));
    for (k, g) in &gold.values {
        if let (Some(g), Some(Some(v))) = (g, got.get(k)) {
            let d = match kind(k) {
                "verification" => ((v - g).abs() - 1e-9).max(0.0) / g.abs().max(f64::MIN_POSITIVE),
                "exact" => (v - g).abs() / g.abs().max(f64::MIN_POSITIVE),
                other => ((v - g).abs() - RANKS_FLOOR).max(0.0) / (g.abs() + scale[other]).max(f64::MIN_POSITIVE),
            };
            if d > worst.0 {
                worst = (d, k.clone());
            }
        }
    }
    worst
}
