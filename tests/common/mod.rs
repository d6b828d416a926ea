//! What the integration tests share: running the real binary on a case into a fresh directory
//! and reading back what it wrote.
#![allow(dead_code)] // each test crate uses its own part

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The repository root (cases are named relative to it).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A finished `porompm run`: the process output, summary.json (`Null` if none was written) and
/// history.csv's header and rows (empty if none).
pub struct Run {
    pub output: Output,
    pub summary: Value,
    pub header: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Run {
    /// Whether the process succeeded and the summary says `completed`.
    pub fn completed(&self) -> bool {
        self.output.status.success() && self.summary["status"] == "completed"
    }

    /// The process's standard error.
    pub fn stderr(&self) -> String {
        String::from_utf8_lossy(&self.output.stderr).into_owned()
    }

    /// Column `name` of history.csv.
    pub fn column(&self, name: &str) -> Vec<f64> {
        column(&self.header, &self.rows, name)
    }
}

pub mod harness;

/// The machine's cores, shared by every test of every test binary (the runner may run tests of
/// several binaries at once, each in its own process): a one-rank run holds them shared (two may
/// run side by side, as two tests run at a time on two cores), a run on several ranks holds them
/// exclusively, alone. Two or three ranks beside another run oversubscribe the cores, and the
/// ranks, waiting on each other, slow down several times (cases/footing_ld.toml on three ranks:
/// 12 s alone, 49 s beside a one-rank run). The hold is an advisory lock on one file of the
/// target directory, released when the guard is dropped (or its process ends).
pub struct Cores(std::fs::File);

impl Cores {
    fn file() -> std::fs::File {
        let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cores.lock");
        std::fs::OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&path)
            .unwrap_or_else(|e| panic!("cannot open {}: {e}", path.display()))
    }

    /// Holds the cores beside at most one other one-rank run.
    pub fn shared() -> Cores {
        let f = Cores::file();
        f.lock_shared().expect("the cores' lock is taken");
        Cores(f)
    }

    /// Holds the cores alone.
    pub fn exclusive() -> Cores {
        let f = Cores::file();
        f.lock().expect("the cores' lock is taken");
        Cores(f)
    }
}

/// Runs `porompm run CASE --out DIR --quiet` with `args` after it (e.g. `--set` pairs, an options
/// file, PETSc options after `--`) into `dir`, emptied first, with a 900 s limit so that a hang
/// fails the test instead of holding the suite.
pub fn run_case(case: &str, dir: &Path, args: &[String]) -> Run {
    run_case_within(900, case, dir, args)
}

/// [`run_case`] with a limit of `seconds`: then the run is stopped (SIGTERM, which porompm honours
/// after a complete step, and SIGKILL 10 s later) and the test fails, naming the hang.
pub fn run_case_within(seconds: u32, case: &str, dir: &Path, args: &[String]) -> Run {
    let _cores = Cores::shared();
    let _ = std::fs::remove_dir_all(dir);
    let limit = seconds.to_string();
    let mut all =
        ["-k", "10", limit.as_str(), env!("CARGO_BIN_EXE_porompm"), "run", case, "--out"].map(String::from).to_vec();
    all.extend([dir.display().to_string(), "--quiet".into()]);
    all.extend(args.iter().cloned());
    let output = Command::new("timeout").args(&all).current_dir(root()).output().expect("porompm runs");
    assert!(!timed_out(&output), "{case}: no end within {seconds} s (a hang)");
    let summary = serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap_or_default())
        .unwrap_or(Value::Null);
    let (header, rows) = read_history(dir);
    Run { output, summary, header, rows }
}

/// Runs `case` with `sets` into `dir` and asserts that it is refused as bad input: exit code 2 and
/// `message` on standard error.
pub fn assert_refused(case: &str, dir: &Path, sets: &[&str], message: &str) {
    let r = run_case(case, dir, &set_args(sets));
    assert_eq!(r.output.status.code(), Some(2), "{case} {sets:?}: {}", r.stderr());
    assert!(r.stderr().contains(message), "{case} {sets:?}: `{message}` not in: {}", r.stderr());
}

/// `--set` arguments for each of `sets`.
pub fn set_args(sets: &[&str]) -> Vec<String> {
    sets.iter().flat_map(|s| ["--set".to_string(), s.to_string()]).collect()
}

/// history.csv of a run directory: header and rows (empty if there is none).
pub fn read_history(dir: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(dir.join("history.csv")).unwrap_or_default();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap_or("").split(',').map(String::from).collect();
    let rows = lines.map(|l| l.split(',').map(|v| v.parse().unwrap_or(f64::NAN)).collect()).collect();
    (header, rows)
}

/// Column `name` of a history.
pub fn column(header: &[String], rows: &[Vec<f64>], name: &str) -> Vec<f64> {
    let i = header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name} in {header:?}"));
    rows.iter().map(|r| r[i]).collect()
}

/// Whether a run's summary lists a warning of `kind`.
pub fn has_warning(s: &Value, kind: &str) -> bool {
    s["warnings"].as_array().is_some_and(|w| w.iter().any(|w| w["kind"] == kind))
}

/// The value of verification metric `name` (NaN if the summary has none).
pub fn metric(s: &Value, name: &str) -> f64 {
    s["verification"][name]["value"].as_f64().unwrap_or(f64::NAN)
}

/// The environment of an `mpirun` on this machine: as root, and on the shared-memory transports
/// without probing the network ones (UCX).
pub fn mpi_env(cmd: &mut Command) -> &mut Command {
    cmd.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_pml", "ob1")
        .env("OMPI_MCA_osc", "^ucx")
}

/// Whether `timeout` ended the command: exit code 124 after SIGTERM, or killed by the SIGKILL that
/// follows (`timeout` then ends itself by the same signal).
fn timed_out(output: &Output) -> bool {
    use std::os::unix::process::ExitStatusExt;
    matches!(output.status.code(), Some(124) | Some(137)) || output.status.signal() == Some(9)
}

/// Runs `porompm run CASE --out DIR --quiet ARGS` on `ranks` MPI ranks (through `mpirun`, alone on
/// the [`Cores`]; one rank runs as [`run_case`] does), with a 600 s limit (then SIGTERM, and
/// SIGKILL 30 s later) so that a hang fails the test instead of holding it.
pub fn run_case_on(ranks: usize, case: &str, dir: &Path, args: &[String]) -> Run {
    if ranks == 1 {
        return run_case(case, dir, args);
    }
    let _cores = Cores::exclusive();
    let _ = std::fs::remove_dir_all(dir);
    let np = ranks.to_string();
    let mut all: Vec<String> =
        ["-k", "30", "600", "mpirun", "--oversubscribe", "-n", np.as_str(), env!("CARGO_BIN_EXE_porompm")]
            .map(String::from)
            .to_vec();
    all.extend(["run".to_string(), case.to_string(), "--out".into(), dir.display().to_string(), "--quiet".into()]);
    all.extend(args.iter().cloned());
    let output = mpi_env(&mut Command::new("timeout")).args(&all).current_dir(root()).output().expect("mpirun runs");
    assert!(!timed_out(&output), "{case} on {ranks} ranks: no end within 600 s (a hang)");
    let summary = serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap_or_default())
        .unwrap_or(Value::Null);
    let (header, rows) = read_history(dir);
    Run { output, summary, header, rows }
}

/// Splits a CSV line at commas outside double quotes.
pub fn csv_fields(line: &str) -> Vec<String> {
    let (mut fields, mut cur, mut quoted) = (Vec::new(), String::new(), false);
    for c in line.chars() {
        match c {
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    fields.push(cur);
    fields
}

/// The gold file of `case`, `cases/gold/<case>.json` (written and compared by `tests/gold.rs`).
pub fn gold_path(case: &str) -> PathBuf {
    root().join("cases/gold").join(format!("{case}.json"))
}

/// A gold file: how the case is run, its tolerance, its governing parameters and its values.
pub struct Gold {
    pub sets: Vec<String>,
    pub rtol: f64,
    pub governing: Vec<String>,
    pub values: std::collections::BTreeMap<String, Option<f64>>,
    /// An absolute floor under every comparison but the exact ones (0 for the gold test itself).
    pub floor: f64,
}

/// Reads the gold file of `case` (see [`Gold`]).
pub fn read_gold(case: &str) -> Gold {
    let path = gold_path(case);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (every case needs a gold file: `make gold` writes it)", path.display()));
    let v: Value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let strings = |k: &str| -> Vec<String> {
        v[k].as_array().map(|a| a.iter().map(|s| s.as_str().unwrap().to_string()).collect()).unwrap_or_default()
    };
    Gold {
        sets: strings("sets"),
        rtol: v["rtol"].as_f64().unwrap_or_else(|| panic!("{}: no rtol", path.display())),
        governing: strings("governing"),
        values: v["values"]
            .as_object()
            .map(|o| o.iter().map(|(k, x)| (k.clone(), x.as_f64())).collect())
            .unwrap_or_default(),
        floor: 0.0,
    }
}

/// A case's default run as its gold file pins it: each verification metric's value and pass flag,
/// and each `results` value. `tests/gold.rs` runs the case with exactly these overrides on one and
/// two ranks and fails if any of these numbers moves beyond round-off, so a test that needs the
/// default run of a case whose gold file has no overrides reads it here instead of running it again.
pub struct GoldRun {
    /// Verification metric → (value, whether it meets its target).
    pub metrics: std::collections::BTreeMap<String, (f64, bool)>,
    /// `results` entry → value (NaN where the run wrote none).
    pub results: std::collections::BTreeMap<String, f64>,
}

/// The gold default run of `case` (see [`GoldRun`]); panics unless its gold file runs the case as
/// shipped (no `sets`).
pub fn gold_run(case: &str) -> GoldRun {
    let gold = read_gold(case);
    assert!(gold.sets.is_empty(), "{case}: the gold run has overrides, so it is not the case's default run");
    let number = |k: &str| gold.values.get(k).copied().flatten().unwrap_or(f64::NAN);
    let mut metrics = std::collections::BTreeMap::new();
    let mut results = std::collections::BTreeMap::new();
    for k in gold.values.keys() {
        if let Some(name) = k.strip_prefix("verification.") {
            let pass = gold.values.get(&format!("pass.{name}")).copied().flatten();
            let pass = pass.unwrap_or_else(|| panic!("{case}: no pass.{name} in its gold file")) == 1.0;
            metrics.insert(name.to_string(), (number(k), pass));
        } else if let Some(name) = k.strip_prefix("results.") {
            results.insert(name.to_string(), number(k));
        }
    }
    GoldRun { metrics, results }
}

/// `porompm test-jacobian ARGS` (one rank): its exit code, standard output and standard error.
pub fn test_jacobian(args: &[&str]) -> (Option<i32>, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_porompm"))
        .arg("test-jacobian")
        .args(args)
        .current_dir(root())
        .output()
        .expect("porompm runs");
    (o.status.code(), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

/// Checks that `porompm test-jacobian ARGS` passes with `n_blocks` blocks within 1e-6 and fails
/// with the block `flip` (ROW,COL) negated; returns the passing run's output.
pub fn assert_tangent_checked(args: &[&str], n_blocks: usize, flip: &str) -> String {
    let text = assert_tangent_agrees(args, n_blocks);
    let (code, flipped, err) = test_jacobian(&[args, &["--flip-block", flip]].concat());
    assert_eq!(code, Some(1), "the flipped {flip} block: {flipped}\n{err}");
    text
}

/// The number of material points that have yielded, as `porompm test-jacobian` reports it.
pub fn yielded_points(text: &str) -> usize {
    text.lines()
        .find_map(|l| l.strip_prefix("material points that have yielded: "))
        .and_then(|n| n.trim().parse().ok())
        .expect("the count of yielded points")
}

/// Checks that `porompm test-jacobian ARGS` passes with a table of `n_blocks` field-pair blocks,
/// every one within 1e-6 of central differences; returns its standard output.
pub fn assert_tangent_agrees(args: &[&str], n_blocks: usize) -> String {
    let (code, text, err) = test_jacobian(args);
    assert_eq!(code, Some(0), "{args:?}: {text}\n{err}");
    let blocks = text.lines().filter(|l| l.split_whitespace().count() == 5 && !l.contains("row")).count();
    assert_eq!(blocks, n_blocks, "{args:?}: {text}");
    assert!(text.contains("all blocks agree within 1.0e-6"), "{args:?}: {text}");
    text
}
