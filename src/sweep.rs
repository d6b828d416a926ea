//! `porompm sweep`: the Cartesian product of solver strategies and varied case values, each run as
//! a child process `porompm run`, collected into `sweep.csv`, `sweep.md` and `work_precision.png`.
//!
//! * A strategy is one PETSc options file (`--options-file`, in the order given); without any, the
//!   single strategy `default` (porompm's built-in solver settings). The case's own options file
//!   applies to every run as in `porompm run`.
//! * `--vary KEY=V1,V2,...` varies one `--set` key over a list. Commas inside brackets, braces or
//!   quotes do not separate values (`grid.cells=[1,20],[1,40]` is two values); a list holding a
//!   semicolon is split at semicolons only (`grid.cells=[1,20];[1,40]`).
//! * `--variant NAME:KEY=VALUE;KEY=VALUE...` names a set of `--set`s (e.g. an analysis type and
//!   its settings), so that differently run versions of one problem sit side by side: every
//!   strategy runs every variant (none given: the case as it is). A key the variant sets is not
//!   varied for it (`--vary time.dt=...` with `--variant explicit:time.dt=1` runs the explicit
//!   variant once per other value); its table cell shows the variant's value.
//! * Run i (numbered from 0, strategies outermost, then the variants, then the `--vary` keys in
//!   order with the last one varying fastest) writes into `DIR/run_<i>`. A run that fails (a step that does not
//!   converge, an invalid varied value, a crash) cannot stop the sweep: it becomes a row with its
//!   status and the reason (the run's one-line error), and the sweep goes on. Each run's standard
//!   error is kept as `DIR/run_<i>/stderr.txt`.
//! * Exit status: 2 for bad input of the sweep itself (malformed `--vary`, a case that does not
//!   parse with the fixed `--set`s, a missing options file, a `--metric` no run reports), 1 if every
//!   run failed, else 0 (some failed rows are a result, not an error of the sweep).
//!
//! The work–precision figure plots the error (the `--metric`, else the first verification metric
//! of the first completed run in summary.json's alphabetical order) against the run's wall time,
//! log–log, one series per strategy and variant, each point labelled with its varied values. The
//! table gives each run's mean step (simulated time over steps), so that the steps of two
//! variants can be compared at equal error.

use crate::io;
use crate::plot::{Axis, Figure, Series, Style};
use serde_json::Value;
use std::path::PathBuf;
use std::process::Command;
use std::time::Instant;

/// One `--vary` option: a case key and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct Vary {
    /// The dotted key, as for `--set`.
    pub key: String,
    /// The values, as text (each becomes `--set KEY=VALUE`).
    pub values: Vec<String>,
}

impl Vary {
    /// Parses `KEY=V1,V2,...` (see the module documentation for commas inside values).
    pub fn parse(text: &str) -> Result<Vary, String> {
        let (key, list) =
            text.split_once('=').ok_or(format!("--vary `{text}`: expected KEY=V1,V2,... (e.g. time.dt=1e-3,5e-4)"))?;
        let key = key.trim();
        if key.is_empty() {
            return Err(format!("--vary `{text}`: the key is empty"));
        }
        let values = split_values(list)?;
        if values.iter().any(|v| v.is_empty()) {
            return Err(format!("--vary `{text}`: an empty value in the list"));
        }
        Ok(Vary { key: key.to_string(), values })
    }
}

/// Splits a value list at semicolons if it has any, else at commas outside brackets, braces and
/// quotes.
fn split_values(list: &str) -> Result<Vec<String>, String> {
    if list.contains(';') {
        return Ok(list.split(';').map(|v| v.trim().to_string()).collect());
    }
    let mut values = Vec::new();
    let (mut depth, mut quote, mut current) = (0i32, None::<char>, String::new());
    for ch in list.chars() {
        match (quote, ch) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), _) => {}
            (None, '"' | '\'') => quote = Some(ch),
            (None, '[' | '{') => depth += 1,
            (None, ']' | '}') => depth -= 1,
            (None, ',') if depth == 0 => {
                values.push(current.trim().to_string());
                current.clear();
                continue;
            }
            _ => {}
        }
        if depth < 0 {
            return Err(format!("--vary list `{list}`: a closing bracket without an opening one"));
        }
        current.push(ch);
    }
    if depth != 0 || quote.is_some() {
        return Err(format!("--vary list `{list}`: unbalanced brackets or quotes"));
    }
    values.push(current.trim().to_string());
    Ok(values)
}

/// A solver strategy: its name and options file (none for porompm's defaults).
/// One `--variant`: a name and the `--set`s that make it.
#[derive(Debug, Clone, PartialEq)]
pub struct Variant {
    /// The series' name.
    pub name: String,
    /// (key, value) pairs, each a `--set KEY=VALUE`.
    pub sets: Vec<(String, String)>,
}

impl Variant {
    /// Parses `NAME:KEY=VALUE;KEY=VALUE...` (no settings after the colon: the case as it is).
    pub fn parse(text: &str) -> Result<Variant, String> {
        let (name, list) = text
            .split_once(':')
            .ok_or(format!("--variant `{text}`: expected NAME:KEY=VALUE;KEY=VALUE... (e.g. explicit:time.dt=1)"))?;
        let name = name.trim();
        if name.is_empty() {
            return Err(format!("--variant `{text}`: the name is empty"));
        }
        let mut sets = Vec::new();
        for item in list.split(';').map(str::trim).filter(|s| !s.is_empty()) {
            let (k, v) = item
                .split_once('=')
                .filter(|(k, v)| !k.trim().is_empty() && !v.trim().is_empty())
                .ok_or(format!("--variant `{text}`: `{item}` is not KEY=VALUE"))?;
            if sets.iter().any(|(key, _): &(String, String)| key == k.trim()) {
                return Err(format!("--variant `{text}`: `{}` is set twice", k.trim()));
            }
            sets.push((k.trim().to_string(), v.trim().to_string()));
        }
        Ok(Variant { name: name.to_string(), sets })
    }

    /// The variant's value of `key`, if it sets it.
    fn value(&self, key: &str) -> Option<&str> {
        self.sets.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Strategy {
    /// The options file's stem, or `default`.
    pub name: String,
    /// The options file.
    pub file: Option<PathBuf>,
}

impl Strategy {
    /// The strategies of the given options files (the default strategy if there are none).
    pub fn from_files(files: &[PathBuf]) -> Vec<Strategy> {
        if files.is_empty() {
            return vec![Strategy { name: "default".into(), file: None }];
        }
        files
            .iter()
            .map(|f| Strategy {
                name: f.file_stem().map_or_else(|| f.display().to_string(), |s| s.to_string_lossy().into_owned()),
                file: Some(f.clone()),
            })
            .collect()
    }
}

/// One run of the sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSpec {
    /// Its number (output directory `run_<index>`).
    pub index: usize,
    /// Index into the strategies.
    pub strategy: usize,
    /// Index into the variants (0 when there are none).
    pub variant: usize,
    /// One value per `--vary` key (the variant's own where it sets the key).
    pub values: Vec<String>,
}

/// The runs: strategies outermost, then the variants (one unnamed if `variants` is empty), then
/// the Cartesian product of the `--vary` values, the last key fastest; a key a variant sets is
/// held at its value.
pub fn plan(strategies: usize, variants: &[Variant], varies: &[Vary]) -> Vec<RunSpec> {
    let none = [Variant { name: String::new(), sets: Vec::new() }];
    let variants = if variants.is_empty() { &none[..] } else { variants };
    let mut runs = Vec::new();
    for s in 0..strategies {
        for (vi, variant) in variants.iter().enumerate() {
            let mut combos: Vec<Vec<String>> = vec![Vec::new()];
            for v in varies {
                let own = variant.value(&v.key).map(|x| vec![x.to_string()]);
                let values = own.as_ref().unwrap_or(&v.values);
                combos = combos
                    .into_iter()
                    .flat_map(|c| {
                        values.iter().map(move |x| {
                            let mut c = c.clone();
                            c.push(x.clone());
                            c
                        })
                    })
                    .collect();
            }
            for c in combos {
                runs.push(RunSpec { index: runs.len(), strategy: s, variant: vi, values: c });
            }
        }
    }
    runs
}

/// What the sweep is asked to do.
pub struct SweepRequest {
    /// The `porompm` executable that runs each combination.
    pub exe: PathBuf,
    /// The case file.
    pub case: PathBuf,
    /// The sweep's output directory.
    pub out: PathBuf,
    /// One strategy per options file.
    pub options_files: Vec<PathBuf>,
    /// The named variants (`--variant`).
    pub variants: Vec<Variant>,
    /// The varied keys.
    pub varies: Vec<Vary>,
    /// `--set` overrides applied to every run.
    pub sets: Vec<String>,
    /// The error metric of the work–precision figure.
    pub metric: Option<String>,
    /// PETSc options for every run.
    pub petsc: Vec<String>,
    /// No progress lines.
    pub quiet: bool,
}

/// The outcome of one run.
#[derive(Debug, Clone)]
pub struct RunRow {
    /// What was run.
    pub spec: RunSpec,
    /// `completed`, `failed` (the run stopped, exit 1), `input error` (exit 2) or `crashed`.
    pub status: String,
    /// The child's exit code (none if killed by a signal).
    pub exit_code: Option<i32>,
    /// Why it did not complete.
    pub failure: String,
    /// The child's wall time including start-up [s].
    pub process_time_s: f64,
    /// Its summary.json, if it wrote one.
    pub summary: Option<Value>,
}

/// Why the sweep ended with an error.
#[derive(Debug)]
pub enum SweepError {
    /// Bad input of the sweep.
    Input(String),
    /// Every run failed.
    AllFailed(String),
}

/// The sweep's result files and rows.
pub struct SweepOutcome {
    /// One per run.
    pub rows: Vec<RunRow>,
    /// Files written.
    pub files: Vec<PathBuf>,
}

/// Runs the sweep: validates the input, runs every combination, writes the tables and the figure.
pub fn run(req: &SweepRequest) -> Result<SweepOutcome, SweepError> {
    let input = SweepError::Input;
    // The case must parse with the fixed overrides; the varied values are checked by each run.
    let overrides: Vec<crate::case::Override> = req
        .sets
        .iter()
        .map(|s| crate::case::Override::parse(s))
        .collect::<Result<_, _>>()
        .map_err(|e| input(e.to_string()))?;
    let text = io::read_text(&req.case).map_err(input)?;
    crate::validation::load(&text, &req.case.display().to_string(), &overrides).map_err(|e| input(e.to_string()))?;
    for f in &req.options_files {
        if !f.is_file() {
            return Err(input(format!("PETSc options file {} does not exist", f.display())));
        }
    }
    let mut keys: Vec<&str> = req.varies.iter().map(|v| v.key.as_str()).collect();
    keys.sort();
    if let Some(w) = keys.windows(2).find(|w| w[0] == w[1]) {
        return Err(input(format!("--vary {} is given twice", w[0])));
    }
    let mut names: Vec<&str> = req.variants.iter().map(|v| v.name.as_str()).collect();
    names.sort();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        return Err(input(format!("--variant {} is given twice", w[0])));
    }
    for v in &req.variants {
        let mut sets = overrides.clone();
        for (k, x) in &v.sets {
            sets.push(
                crate::case::Override::parse(&format!("{k}={x}"))
                    .map_err(|e| input(format!("--variant {}: {e}", v.name)))?,
            );
        }
        crate::validation::load(&text, &req.case.display().to_string(), &sets)
            .map_err(|e| input(format!("--variant {}: {e}", v.name)))?;
    }
    let strategies = Strategy::from_files(&req.options_files);
    let specs = plan(strategies.len(), &req.variants, &req.varies);
    io::create_dir(&req.out).map_err(input)?;
    let mut rows = Vec::new();
    for spec in &specs {
        let row = run_one(req, &strategies, spec);
        if !req.quiet {
            eprintln!("[{}/{}] {}", spec.index + 1, specs.len(), describe_row(req, &strategies, &row));
        }
        rows.push(row);
    }
    let metrics = metric_names(&rows);
    let chosen = match &req.metric {
        Some(m) if !metrics.contains(m) && rows.iter().any(|r| r.summary.is_some()) => {
            return Err(input(format!(
                "--metric {m}: no run reports it (metrics: {})",
                if metrics.is_empty() { "none".to_string() } else { metrics.join(", ") }
            )))
        }
        Some(m) => Some(m.clone()),
        None => first_metric(&rows),
    };
    let (header, table) = table(req, &strategies, &rows, &metrics);
    let mut files = Vec::new();
    files.push(io::write_text(&req.out, "sweep.csv", &csv(&header, &table)).map_err(input)?);
    files.push(io::write_text(&req.out, "sweep.md", &markdown(req, &header, &table)).map_err(input)?);
    if let Some(m) = &chosen {
        let fig = work_precision(req, &strategies, &rows, m);
        let written = io::plot::write_figures(&req.out, &[fig]).map_err(input)?;
        if written.is_empty() && !req.quiet {
            eprintln!("no completed run reports a positive {m}: work_precision.png is not drawn");
        }
        files.extend(written);
    }
    if rows.iter().all(|r| r.status != "completed") {
        return Err(SweepError::AllFailed(format!(
            "every run of the sweep failed (see {})",
            req.out.join("sweep.md").display()
        )));
    }
    Ok(SweepOutcome { rows, files })
}

fn run_one(req: &SweepRequest, strategies: &[Strategy], spec: &RunSpec) -> RunRow {
    let dir = req.out.join(format!("run_{}", spec.index));
    let mut cmd = Command::new(&req.exe);
    cmd.arg("run").arg(&req.case).arg("--out").arg(&dir).arg("--quiet");
    if let Some(f) = &strategies[spec.strategy].file {
        cmd.arg("--options-file").arg(f);
    }
    for s in &req.sets {
        cmd.arg("--set").arg(s);
    }
    let variant = req.variants.get(spec.variant);
    for (k, value) in variant.iter().flat_map(|v| &v.sets) {
        cmd.arg("--set").arg(format!("{k}={value}"));
    }
    for (v, value) in req.varies.iter().zip(&spec.values) {
        if variant.is_none_or(|x| x.value(&v.key).is_none()) {
            cmd.arg("--set").arg(format!("{}={value}", v.key));
        }
    }
    if !req.petsc.is_empty() {
        cmd.arg("--").args(&req.petsc);
    }
    let t0 = Instant::now();
    let output = cmd.output();
    let process_time_s = t0.elapsed().as_secs_f64();
    let summary = io::read_text(&dir.join("summary.json")).ok().and_then(|t| serde_json::from_str::<Value>(&t).ok());
    let (status, exit_code, failure) = match output {
        Err(e) => ("crashed".to_string(), None, format!("cannot start {}: {e}", req.exe.display())),
        Ok(o) => {
            let stderr = String::from_utf8_lossy(&o.stderr);
            // The run's own messages stay next to its results (best effort: the row says the rest).
            let _ = io::write_text(&dir, "stderr.txt", &stderr);
            let last = stderr
                .lines()
                .rev()
                .find(|l| l.starts_with("error: "))
                .or_else(|| stderr.lines().rev().find(|l| !l.trim().is_empty()))
                .map(|l| l.trim_start_matches("error: ").to_string());
            match o.status.code() {
                Some(0) => ("completed".to_string(), Some(0), String::new()),
                Some(1) => ("failed".to_string(), Some(1), last.unwrap_or_else(|| "exit status 1".into())),
                Some(2) => ("input error".to_string(), Some(2), last.unwrap_or_else(|| "exit status 2".into())),
                Some(c) => ("crashed".to_string(), Some(c), last.unwrap_or_else(|| format!("exit status {c}"))),
                None => ("crashed".to_string(), None, last.unwrap_or_else(|| "killed by a signal".into())),
            }
        }
    };
    RunRow { spec: spec.clone(), status, exit_code, failure, process_time_s, summary }
}

fn describe_row(req: &SweepRequest, strategies: &[Strategy], row: &RunRow) -> String {
    let values: Vec<String> = req.varies.iter().zip(&row.spec.values).map(|(v, x)| format!("{}={x}", v.key)).collect();
    let mut s = format!("{} {}: {}", series_name(req, strategies, &row.spec), values.join(" "), row.status);
    match row.status.as_str() {
        "completed" => s.push_str(&format!(" in {:.2} s", wall_time(row))),
        _ => s.push_str(&format!(" ({})", row.failure)),
    }
    s
}

/// The run's wall time: summary.json's, else the child process's.
/// The name of a run's series: its strategy, its variant, or both when the sweep has several
/// strategies and variants.
fn series_name(req: &SweepRequest, strategies: &[Strategy], spec: &RunSpec) -> String {
    let strategy = &strategies[spec.strategy].name;
    match req.variants.get(spec.variant) {
        None => strategy.clone(),
        Some(v) if strategies.len() == 1 => v.name.clone(),
        Some(v) => format!("{strategy}/{}", v.name),
    }
}

/// A run's mean step, its simulated time over its steps [s].
fn mean_step(row: &RunRow) -> Option<f64> {
    let s = row.summary.as_ref()?;
    let steps = s["steps"].as_f64().filter(|&n| n > 0.0)?;
    Some(s["time_s"].as_f64()? / steps)
}

fn wall_time(row: &RunRow) -> f64 {
    row.summary.as_ref().and_then(|s| s["wall_time_s"].as_f64()).unwrap_or(row.process_time_s)
}

/// Metric names over all runs, in order of first appearance.
fn metric_names(rows: &[RunRow]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for r in rows {
        if let Some(Value::Object(m)) = r.summary.as_ref().map(|s| &s["verification"]) {
            for k in m.keys() {
                if !names.contains(k) {
                    names.push(k.clone());
                }
            }
        }
    }
    names
}

fn first_metric(rows: &[RunRow]) -> Option<String> {
    rows.iter().filter(|r| r.status == "completed").find_map(|r| match &r.summary.as_ref()?["verification"] {
        Value::Object(m) => m.keys().next().cloned(),
        _ => None,
    })
}

fn metric_value(row: &RunRow, name: &str) -> Option<f64> {
    row.summary.as_ref()?["verification"][name]["value"].as_f64()
}

/// The phases of summary.json's `timings`, in order.
const PHASES: [&str; 6] = ["setup_s", "step_setup_s", "assembly_s", "linear_solve_s", "particle_update_s", "output_s"];

/// Counts and sizes copied from summary.json.
const COUNTS: [&str; 6] = ["steps", "step_cuts", "snes_iterations", "ksp_iterations", "dofs", "particles"];

fn table(
    req: &SweepRequest,
    strategies: &[Strategy],
    rows: &[RunRow],
    metrics: &[String],
) -> (Vec<String>, Vec<Vec<String>>) {
    let mut header: Vec<String> = vec!["run".into(), "strategy".into()];
    if !req.variants.is_empty() {
        header.push("variant".into());
    }
    header.extend(req.varies.iter().map(|v| v.key.clone()));
    header.extend(["status", "exit_code", "failure", "wall_time_s", "process_time_s"].map(String::from));
    header.extend(PHASES.iter().map(|p| format!("time_{p}")));
    header.extend(COUNTS.map(String::from));
    header.push("mean_dt_s".into());
    header.push("peak_memory_mib".into());
    header.extend(metrics.iter().cloned());
    let num = |v: Option<f64>, prec: usize| v.map_or(String::new(), |x| format!("{x:.prec$}"));
    let sci = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.4e}"));
    let body = rows
        .iter()
        .map(|r| {
            let s = r.summary.as_ref();
            let mut line = vec![r.spec.index.to_string(), strategies[r.spec.strategy].name.clone()];
            if let Some(v) = req.variants.get(r.spec.variant) {
                line.push(v.name.clone());
            }
            line.extend(r.spec.values.iter().cloned());
            line.push(r.status.clone());
            line.push(r.exit_code.map_or(String::new(), |c| c.to_string()));
            line.push(r.failure.clone());
            line.push(format!("{:.4}", wall_time(r)));
            line.push(format!("{:.4}", r.process_time_s));
            line.extend(PHASES.iter().map(|p| num(s.and_then(|s| s["timings"][p].as_f64()), 4)));
            line.extend(COUNTS.iter().map(|c| s.and_then(|s| s[c].as_u64()).map_or(String::new(), |v| v.to_string())));
            line.push(sci(mean_step(r)));
            line.push(num(s.and_then(|s| s["peak_memory_mib"].as_f64()), 1));
            line.extend(metrics.iter().map(|m| sci(metric_value(r, m))));
            line
        })
        .collect();
    (header, body)
}

/// A CSV field, quoted when it holds a comma, a quote or a line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn csv(header: &[String], rows: &[Vec<String>]) -> String {
    let mut text = String::new();
    for line in std::iter::once(header).chain(rows.iter().map(|r| r.as_slice())) {
        text.push_str(&line.iter().map(|f| csv_field(f)).collect::<Vec<_>>().join(","));
        text.push('\n');
    }
    text
}

fn markdown(req: &SweepRequest, header: &[String], rows: &[Vec<String>]) -> String {
    let cell = |s: &str| s.replace('|', "\\|").replace('\n', " ");
    let mut text = format!("# Sweep of `{}`\n\n", req.case.display());
    text.push_str(&format!(
        "{} runs; wall times in s, memory in MiB; the `time_*` columns are summary.json's `timings` per phase.\n\n",
        rows.len()
    ));
    text.push_str(&format!("| {} |\n", header.iter().map(|h| cell(h)).collect::<Vec<_>>().join(" | ")));
    text.push_str(&format!("|{}\n", "---|".repeat(header.len())));
    for r in rows {
        text.push_str(&format!("| {} |\n", r.iter().map(|f| cell(f)).collect::<Vec<_>>().join(" | ")));
    }
    text
}

fn work_precision(req: &SweepRequest, strategies: &[Strategy], rows: &[RunRow], metric: &str) -> Figure {
    let case = req.case.file_stem().map_or_else(|| req.case.display().to_string(), |s| s.to_string_lossy().into());
    let mut fig = Figure::new(
        "work_precision.png",
        format!("Work–precision: {case}"),
        Axis::log("wall time of the run [s]"),
        Axis::log(format!("error {metric} [-]")),
    );
    for (colour, (name, runs)) in line_groups(req, strategies, rows).into_iter().enumerate() {
        let mut pts: Vec<(f64, f64, String)> = runs
            .iter()
            .filter(|r| r.status == "completed")
            .filter_map(|r| {
                let label: Vec<String> =
                    req.varies.iter().zip(&r.spec.values).map(|(v, x)| format!("{}={x}", short_key(&v.key))).collect();
                metric_value(r, metric).map(|e| (wall_time(r), e, label.join(" ")))
            })
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let points = pts.iter().map(|p| (p.0, p.1)).collect();
        let mut line = Series::new(name, points, Style::LineMarkers, colour);
        line.point_labels = pts.into_iter().map(|p| p.2).collect();
        fig.series.push(line);
    }
    fig
}

/// The lines of the work–precision figure, in the plan's order: one per (strategy, variant); when
/// more than one `--vary` key takes several values within it, one per combination of those keys
/// but the last varying one (e.g. one line over Δt per grid), named by them, so that a line joins
/// runs that differ in one setting only.
fn line_groups<'a>(req: &SweepRequest, strategies: &[Strategy], rows: &'a [RunRow]) -> Vec<(String, Vec<&'a RunRow>)> {
    let mut series: Vec<(usize, usize)> = rows.iter().map(|r| (r.spec.strategy, r.spec.variant)).collect();
    series.dedup();
    let mut out = Vec::new();
    for (si, vi) in series {
        let runs: Vec<&RunRow> = rows.iter().filter(|r| (r.spec.strategy, r.spec.variant) == (si, vi)).collect();
        let name = series_name(req, strategies, &runs[0].spec);
        let varying: Vec<usize> = (0..req.varies.len())
            .filter(|&k| runs.iter().any(|r| r.spec.values[k] != runs[0].spec.values[k]))
            .collect();
        let Some((_, split)) = varying.split_last().filter(|(_, s)| !s.is_empty()) else {
            out.push((name, runs));
            continue;
        };
        let key = |r: &RunRow| split.iter().map(|&k| r.spec.values[k].clone()).collect::<Vec<_>>();
        let mut keys: Vec<Vec<String>> = runs.iter().map(|r| key(r)).collect();
        keys.dedup();
        for k in keys {
            let label: Vec<String> =
                split.iter().zip(&k).map(|(&i, x)| format!("{}={x}", short_key(&req.varies[i].key))).collect();
            let group = runs.iter().copied().filter(|r| key(r) == k).collect();
            out.push((format!("{name} ({})", label.join(" ")), group));
        }
    }
    out
}

/// The last part of a dotted key (`time.dt` → `dt`), for point labels.
fn short_key(key: &str) -> &str {
    key.rsplit('.').next().unwrap_or(key)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_split_at_commas_outside_brackets_or_at_semicolons() {
        let v = Vary::parse("time.dt=4e-3, 2e-3,1e-3").unwrap();
        assert_eq!(v.key, "time.dt");
        assert_eq!(v.values, vec!["4e-3", "2e-3", "1e-3"]);
        assert_eq!(Vary::parse("grid.cells=[1,20],[1,40]").unwrap().values, vec!["[1,20]", "[1,40]"]);
        assert_eq!(Vary::parse("grid.cells=[1,20];[1,40]").unwrap().values, vec!["[1,20]", "[1,40]"]);
        assert_eq!(Vary::parse("a.b=\"x,y\",z").unwrap().values, vec!["\"x,y\"", "z"]);
        assert!(Vary::parse("time.dt").is_err());
        assert!(Vary::parse("=1,2").is_err());
        assert!(Vary::parse("a=1,,2").is_err());
        assert!(Vary::parse("a=[1,2").is_err());
        assert!(Vary::parse("a=1],2").is_err());
    }

    #[test]
    fn the_plan_is_the_cartesian_product_with_the_last_key_fastest() {
        let v = [
            Vary { key: "a".into(), values: vec!["1".into(), "2".into()] },
            Vary { key: "b".into(), values: vec!["x".into(), "y".into(), "z".into()] },
        ];
        let p = plan(2, &[], &v);
        assert_eq!(p.len(), 12);
        assert_eq!(p[1].values, vec!["1", "y"]);
        assert_eq!(p[3].values, vec!["2", "x"]);
        assert_eq!((p[6].strategy, p[6].index), (1, 6));
        assert_eq!(plan(1, &[], &[]).len(), 1);
        // A variant holds the keys it sets: it does not multiply them.
        let variants = [Variant::parse("implicit:").unwrap(), Variant::parse("explicit:b=w; c=1").unwrap()];
        assert_eq!(variants[1].sets, vec![("b".to_string(), "w".to_string()), ("c".to_string(), "1".to_string())]);
        let p = plan(1, &variants, &v);
        assert_eq!(p.len(), 6 + 2);
        assert_eq!((p[6].variant, p[6].values.clone()), (1, vec!["1".to_string(), "w".to_string()]));
        assert_eq!((p[7].variant, p[7].values.clone()), (1, vec!["2".to_string(), "w".to_string()]));
        assert!(Variant::parse("no colon").is_err());
        assert!(Variant::parse(":a=1").is_err());
        assert!(Variant::parse("x:a").is_err());
        assert!(Variant::parse("x:a=1;a=2").is_err());
        // The figure's lines: per variant, and per value of every varying key but the last.
        let req = SweepRequest {
            exe: PathBuf::new(),
            case: PathBuf::from("c.toml"),
            out: PathBuf::new(),
            options_files: Vec::new(),
            variants: variants.to_vec(),
            varies: v.to_vec(),
            sets: Vec::new(),
            metric: None,
            petsc: Vec::new(),
            quiet: true,
        };
        let rows: Vec<RunRow> = p
            .iter()
            .map(|s| RunRow {
                spec: s.clone(),
                status: "completed".into(),
                exit_code: Some(0),
                failure: String::new(),
                process_time_s: 0.0,
                summary: None,
            })
            .collect();
        let groups = line_groups(&req, &Strategy::from_files(&[]), &rows);
        let names: Vec<(&str, usize)> = groups.iter().map(|(n, g)| (n.as_str(), g.len())).collect();
        assert_eq!(names, vec![("implicit (a=1)", 3), ("implicit (a=2)", 3), ("explicit", 2)]);
        let s = Strategy::from_files(&[PathBuf::from("petsc_options/direct-lu.opts")]);
        assert_eq!(s[0].name, "direct-lu");
        assert_eq!(Strategy::from_files(&[])[0].name, "default");
    }

    #[test]
    fn csv_fields_with_commas_are_quoted() {
        assert_eq!(csv_field("[1,20]"), "\"[1,20]\"");
        assert_eq!(csv_field("say \"hi\", then"), "\"say \"\"hi\"\", then\"");
        assert_eq!(csv_field("plain"), "plain");
        assert_eq!(short_key("time.dt"), "dt");
    }
}
