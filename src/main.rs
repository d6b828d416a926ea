//! The `porompm` command line. The only place that initialises MPI and PETSc.
//!
//! Exit codes: 0 success; 1 a run failed (e.g. a step did not converge); 2 bad input (case file,
//! override, options file, unused PETSc option). Every error is one line on standard error.

use clap::{Parser, Subcommand};
use mpi::raw::AsRaw;
use porompm::case::{self, Override};
use porompm::driver::{self, RunError, RunRequest};
use porompm::io::{self, RunOutput};
use porompm::parallel::Collective;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

#[derive(Parser)]
#[command(name = "porompm", version = porompm::VERSION_LONG, about = "Implicit u–p–U GIMP material point method for saturated soils, on PETSc")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a case: writes summary.json, history.csv and fields.h5/fields.xdmf into DIR.
    Run {
        /// The case file (TOML).
        case: PathBuf,
        /// Output directory (created if needed).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// PETSc options file(s), applied in order after the case's own and before the command line's.
        #[arg(long = "options-file", value_name = "FILE")]
        options_file: Vec<PathBuf>,
        /// Override a case value by its dotted path, e.g. `--set time.dt=5e-4`.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// No progress bar and no progress messages (the bar is shown only when standard error is
        /// a terminal).
        #[arg(long)]
        quiet: bool,
        /// Write the full state to DIR/checkpoint.h5 every N steps, N ≥ 1 (atomically; without
        /// it, no checkpoint).
        #[arg(long = "checkpoint-every", value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
        checkpoint_every: Option<u32>,
        /// Continue from a checkpoint.h5 written by a run of the same case.
        #[arg(long, value_name = "CHECKPOINT")]
        restart: Option<PathBuf>,
        /// Repartition the grid over the ranks when the busiest rank holds more than this many times
        /// the mean number of material points per rank (≥ 1; `inf`: never). Ignored on one rank.
        #[arg(long = "balance-threshold", value_name = "RATIO", default_value_t = porompm::distribution::DEFAULT_BALANCE_THRESHOLD, value_parser = parse_balance_threshold)]
        balance_threshold: f64,
        /// Threads per rank for the particle loops (default: this machine's cores divided by the
        /// ranks running on it). The results do not depend on it.
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=1024))]
        threads: Option<u16>,
        /// PETSc options, after `--` (they reach PETSc's options database unchanged).
        #[arg(last = true, value_name = "PETSC_OPTIONS")]
        petsc: Vec<String>,
    },
    /// Run a case once per solver strategy (options file) and combination of varied values, each
    /// as a child `porompm run` into DIR/run_<i>; write DIR/sweep.csv, DIR/sweep.md and
    /// DIR/work_precision.png. Exits with 2 on bad input, 1 if every run failed.
    Sweep {
        /// The case file (TOML).
        case: PathBuf,
        /// Output directory (created if needed).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// One solver strategy per PETSc options file (none: porompm's defaults).
        #[arg(long = "options-file", value_name = "FILE")]
        options_file: Vec<PathBuf>,
        /// Vary a case value: `KEY=V1,V2,...`; commas inside [] or {} or quotes do not separate
        /// values, and a list with a `;` is split at `;` only (e.g. `grid.cells=[1,20];[1,40]`).
        #[arg(long = "vary", value_name = "KEY=V1,V2,...")]
        vary: Vec<String>,
        /// A named version of the case, `NAME:KEY=VALUE;KEY=VALUE...` (e.g.
        /// `explicit:stages.consolidation.analysis=dynamic_explicit`): every strategy runs every
        /// variant, and the keys a variant sets are not varied for it.
        #[arg(long = "variant", value_name = "NAME:KEY=VALUE;...")]
        variant: Vec<String>,
        /// Override a case value in every run, e.g. `--set time.dt=5e-4`.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// The error metric of work_precision.png (default: the case's first verification metric).
        #[arg(long, value_name = "NAME")]
        metric: Option<String>,
        /// No progress lines.
        #[arg(long)]
        quiet: bool,
        /// PETSc options for every run, after `--`.
        #[arg(last = true, value_name = "PETSC_OPTIONS")]
        petsc: Vec<String>,
    },
    /// Parse and validate a case and print what it will build.
    Check {
        /// The case file (TOML).
        case: PathBuf,
        /// Override a case value by its dotted path.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Compare the assembled tangent with finite differences of the residual, block by block, after
    /// a few steps of a (small) case; exits with 1 if a block differs by more than the tolerance.
    TestJacobian {
        /// The case file (TOML).
        case: PathBuf,
        /// Steps to run before the check (so that particles carry stress, velocity, pressure).
        #[arg(long, default_value_t = 3)]
        steps: usize,
        /// Largest accepted relative difference per block.
        #[arg(long, default_value_t = 1e-6)]
        tolerance: f64,
        /// Negate one block of the assembled tangent before the comparison, given as ROW,COL fields
        /// (e.g. `p,p`): the check must then fail (to see that it sees that block).
        #[arg(long = "flip-block", value_name = "ROW,COL")]
        flip_block: Option<String>,
        /// Override a case value by its dotted path.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// PETSc options, after `--`.
        #[arg(last = true)]
        petsc: Vec<String>,
    },
    /// Drive one material point of a soil model along a load path (strain, stress or mixed control)
    /// and write element_test.csv into DIR: stress, strain, p, q, ε̄, the return's region and the
    /// Newton residuals of the stress control per increment.
    ElementTest {
        /// The soil model: a TOML file with a `[model]` table as in a case's `[materials.model]`.
        material: PathBuf,
        /// The load path (TOML): initial stress and segments; see element_tests/ for examples.
        #[arg(long, value_name = "PATH.toml")]
        path: PathBuf,
        /// Output directory (created if needed).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
    },
    /// Print a run's summary.json (finished, failed or still running) as a readable table.
    Report {
        /// The run's output directory.
        dir: PathBuf,
    },
    /// Print the MPI and PETSc environment and check a collective operation.
    Info {
        /// PETSc options, after `--`.
        #[arg(last = true)]
        petsc: Vec<String>,
    },
}

/// A failure of the command, with its exit code.
struct Failure {
    code: u8,
    message: String,
    /// Whether rank 0 has printed the message already (before MPI was finalised).
    reported: bool,
}

fn failed(message: impl Into<String>) -> Failure {
    Failure { code: 1, message: message.into(), reported: false }
}

fn input(message: impl Into<String>) -> Failure {
    Failure { code: 2, message: message.into(), reported: false }
}

fn load_case(path: &Path, sets: &[String]) -> Result<case::Case, Failure> {
    let overrides: Vec<Override> =
        sets.iter().map(|s| Override::parse(s)).collect::<Result<_, _>>().map_err(|e| input(e.to_string()))?;
    let text = io::read_text(path).map_err(input)?;
    porompm::validation::load(&text, &path.display().to_string(), &overrides).map_err(|e| input(e.to_string()))
}

/// Checkpointing, restart and distribution settings of `porompm run`.
struct Continuation<'a> {
    checkpoint_every: usize,
    restart: Option<&'a Path>,
    /// `--threads`, if given.
    threads: Option<u16>,
    /// `--balance-threshold`.
    balance_threshold: f64,
}

/// `--balance-threshold`: a ratio of at least 1 (or `inf`).
fn parse_balance_threshold(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v >= 1.0 => Ok(v),
        _ => Err(format!("must be a number ≥ 1 (the busiest rank's points over the mean; `inf`: never), got `{text}`")),
    }
}

fn run(
    case_path: &Path,
    out: &Path,
    options_files: &[PathBuf],
    sets: &[String],
    quiet: bool,
    cont: Continuation,
    petsc_args: &[String],
) -> Result<(), Failure> {
    let c = load_case(case_path, sets)?;
    // Options files: the case's own (relative to the case file), then the command line's.
    let mut files: Vec<PathBuf> = Vec::new();
    if let Some(f) = &c.solver.options_file {
        let base = case_path.parent().unwrap_or(Path::new("."));
        files.push(base.join(f));
    }
    files.extend(options_files.iter().cloned());
    for f in &files {
        if !f.is_file() {
            return Err(input(format!("PETSc options file {} does not exist", f.display())));
        }
        io::check_petsc_options_file(f).map_err(input)?;
    }
    let mut args: Vec<String> = Vec::new();
    for f in &files {
        args.push("-options_file".into());
        args.push(f.display().to_string());
    }
    args.extend(petsc_args.iter().cloned());
    // SIGINT and SIGTERM: the first asks the run to stop after its current step (with fields and a
    // checkpoint); a second one exits at once (code 130).
    let interrupt = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register_conditional_shutdown(sig, 130, Arc::clone(&interrupt))
            .and_then(|_| signal_hook::flag::register(sig, Arc::clone(&interrupt)))
            .map_err(|e| input(format!("cannot install the signal handler: {e}")))?;
    }
    let (universe, mut coll, petsc) = start_mpi_and_petsc(&args)?;
    if let Some(n) = cont.threads {
        coll.set_threads(n as usize);
    }
    let result = run_started(&c, case_path, out, sets, quiet, cont, interrupt, &coll);
    finish(universe, coll, petsc, result)
}

/// The part of `run` that needs MPI and PETSc: everything after they start.
#[allow(clippy::too_many_arguments)]
fn run_started(
    c: &case::Case,
    case_path: &Path,
    out: &Path,
    sets: &[String],
    quiet: bool,
    cont: Continuation,
    interrupt: Arc<AtomicBool>,
    coll: &Collective,
) -> Result<(), Failure> {
    // Every rank reads its share of the checkpoint (MPI-I/O); all get the same outcome.
    let restart = match cont.restart {
        Some(p) => {
            let cp = io::checkpoint::read(p, coll.communicator()).map_err(input)?;
            porompm::state::check_case(&cp, c).map_err(|e| input(format!("checkpoint {}: {e}", p.display())))?;
            Some((p.display().to_string(), cp))
        }
        None => None,
    };
    // Rank 0 alone creates the output directory; every rank learns whether it could.
    let mut output = coll.agree(RunOutput::create(out, coll.rank() == 0)).map_err(input)?;
    let req = RunRequest {
        case: c,
        case_label: case_path.display().to_string(),
        overrides: sets.to_vec(),
        out_dir: out.to_path_buf(),
        quiet,
        coll,
        checkpoint_every: cont.checkpoint_every,
        balance_threshold: cont.balance_threshold,
        restart,
        interrupt: Some(interrupt),
    };
    let (summary, err) = driver::run(&req, &mut output);
    // A run refused before it began has only its error to say.
    let begun = output.has_begun();
    drop(output);
    if coll.rank() == 0 && !quiet && begun {
        for (name, m) in &summary.verification {
            eprintln!(
                "{name} = {:.4e} (tolerance {:.1e}) {}  [{}]",
                m.value,
                m.tolerance,
                if m.pass { "pass" } else { "FAIL" },
                m.detail
            );
        }
        eprintln!(
            "{}: {} steps, {} Newton and {} Krylov iterations, {} unknowns, {} material points, {:.2} s wall time",
            summary.status,
            summary.steps,
            summary.snes_iterations,
            summary.ksp_iterations,
            summary.dofs,
            summary.particles,
            summary.wall_time_s
        );
    }
    match err {
        None => Ok(()),
        Some(RunError::Input(m)) => Err(input(m)),
        Some(RunError::Failed(m)) => Err(failed(m)),
        Some(RunError::Interrupted(m)) => Err(Failure { code: 130, message: m, reported: false }),
    }
}

fn test_jacobian(
    case_path: &Path,
    steps: usize,
    tolerance: f64,
    flip: Option<&str>,
    sets: &[String],
    petsc_args: &[String],
) -> Result<(), Failure> {
    let c = load_case(case_path, sets)?;
    // The fields of the first stage, whose tangent is checked, in the case's dimension.
    let names = porompm::analysis::StageAnalysis::of(&c, &c.stages[0]).layout.in_dim(c.dimension()).field_names();
    let flip = match flip {
        None => None,
        Some(f) => {
            let parts: Vec<&str> = f.split(',').collect();
            let find = |n: &str| names.iter().position(|x| *x == n.trim());
            match parts.as_slice() {
                [r, c] => match (find(r), find(c)) {
                    (Some(r), Some(c)) => Some((r, c)),
                    _ => return Err(input(format!("--flip-block {f}: the fields are {}", names.join(", ")))),
                },
                _ => return Err(input(format!("--flip-block {f}: expected ROW,COL, e.g. p,p"))),
            }
        }
    };
    let (universe, coll, petsc) = start_mpi_and_petsc(petsc_args)?;
    let req = RunRequest {
        case: &c,
        case_label: case_path.display().to_string(),
        overrides: sets.to_vec(),
        out_dir: PathBuf::from("."),
        quiet: true,
        coll: &coll,
        checkpoint_every: 0,
        balance_threshold: f64::INFINITY,
        restart: None,
        interrupt: None,
    };
    let result = driver::test_jacobian(&req, steps, flip)
        .map_err(|e| Failure {
            code: if matches!(e, driver::RunError::Input(_)) { 2 } else { 1 },
            message: e.message().to_string(),
            reported: false,
        })
        .and_then(|(blocks, yielded)| jacobian_table(&blocks, yielded, steps, tolerance, coll.rank() == 0));
    finish(universe, coll, petsc, result)
}

/// Prints (on rank 0) the blocks of a Jacobian test and fails if one differs by more than `tolerance`.
fn jacobian_table(
    blocks: &[porompm::assembly::BlockCheck],
    yielded: usize,
    steps: usize,
    tolerance: f64,
    print: bool,
) -> Result<(), Failure> {
    let mut table = format!("material points that have yielded: {yielded}\n");
    table += &format!(
        "{:>4} {:>4} {:>14} {:>14} {:>12}  (tangent vs central differences after {steps} steps, scaled by D^-1/2 · D^-1/2)\n",
        "row", "col", "max|J-Jfd|", "max|J|", "relative"
    );
    let mut worst: f64 = 0.0;
    for b in blocks {
        table += &format!(
            "{:>4} {:>4} {:>14.4e} {:>14.4e} {:>12.3e}\n",
            b.row, b.col, b.max_abs_error, b.max_abs_entry, b.relative_error
        );
        worst = worst.max(b.relative_error);
    }
    if worst <= tolerance {
        table += &format!("all blocks agree within {tolerance:.1e} (worst {worst:.3e})\n");
    }
    if print {
        print!("{table}");
    }
    if worst > tolerance {
        return Err(failed(format!("the tangent differs from finite differences by {worst:.3e} > {tolerance:.1e}")));
    }
    Ok(())
}

/// Ends a command that started MPI and PETSc. mpirun ends the whole job as soon as one rank exits
/// with a non-zero code, so an error is printed by rank 0 while MPI still runs, and every rank
/// waits at a barrier for that before any of them finalises and exits.
fn finish(
    universe: mpi::environment::Universe,
    coll: Collective,
    petsc: petsc::Petsc,
    result: Result<(), Failure>,
) -> Result<(), Failure> {
    use mpi::collective::CommunicatorCollectives;
    let result = result.map_err(|f| {
        if coll.rank() == 0 {
            eprintln!("error: {}", f.message);
        }
        Failure { reported: true, ..f }
    });
    coll.communicator().barrier();
    drop(petsc);
    drop(coll);
    drop(universe);
    result
}

/// PETSc's command line is `-name [value]` pairs: a word where a name belongs (a name without its
/// dash, or a second value) PETSc would ignore without a word; it is refused, named.
fn check_petsc_words(args: &[String]) -> Result<(), String> {
    let mut after_name = false;
    for a in args {
        let name = a.strip_prefix('-').is_some_and(|n| n.starts_with(|c: char| c.is_ascii_alphabetic()));
        if !name && !after_name {
            return Err(format!(
                "PETSc option `{a}` (after `--`): an option's name begins with `-` (`-{a}`?) and at most one value \
                 follows it"
            ));
        }
        after_name = name;
    }
    Ok(())
}

/// Initialises MPI (rsmpi) and then PETSc on its world communicator; the caller drops them in
/// reverse order.
fn start_mpi_and_petsc(args: &[String]) -> Result<(mpi::environment::Universe, Collective, petsc::Petsc), Failure> {
    check_petsc_words(args).map_err(input)?;
    quick_singleton_start();
    no_shared_file_pointers();
    let universe = mpi::initialize().ok_or_else(|| input("MPI could not be initialised (already initialised?)"))?;
    let coll = Collective::world();
    if coll.size() > 1 {
        abort_all_ranks_on_panic();
    }
    let comm = petsc::Comm::from_raw(coll.communicator().as_raw());
    let petsc = petsc::Petsc::initialize_on(comm, args, None, "porompm")
        .map_err(|e| input(format!("cannot initialise PETSc: {e}")))?;
    // Fault injection for the test of `abort_all_ranks_on_panic` (tests/distributed.rs): the rank
    // named by PORO_FAULT_PANIC_RANK panics here, with PETSc running and the others going on.
    if std::env::var("PORO_FAULT_PANIC_RANK").ok().and_then(|r| r.parse::<usize>().ok()) == Some(coll.rank()) {
        panic!("fault injected by PORO_FAULT_PANIC_RANK on rank {}", coll.rank());
    }
    Ok((universe, coll, petsc))
}

/// Open MPI settings for a process started without `mpirun` (a singleton: one rank, which talks to
/// no other process), unless the environment already sets them: the shared-memory and self
/// transports instead of probing the network ones (UCX's `pml` and `osc`), which takes the start
/// of every one-rank run from 0.55 s to 0.34 s (`porompm info`, Open MPI 4.1). The singleton's
/// supporting daemon stays: without it (`ess_singleton_isolated`) every isolated singleton shares
/// one session directory, and MPI-I/O's shared file pointers of two runs at once clash there.
/// Runs started by `mpirun` are left alone: there the launcher and the user choose the transports
/// of the machine. Called before MPI starts, while the process has one thread.
fn quick_singleton_start() {
    let launched = ["OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK"].iter().any(|v| std::env::var_os(v).is_some());
    if launched {
        return;
    }
    default_env("OMPI_MCA_pml", "ob1");
    default_env("OMPI_MCA_osc", "^ucx");
}

/// Sets the environment variable `key` to `value` unless the environment already sets it (the
/// user's choice wins). Called before MPI starts, while the process has one thread.
fn default_env(key: &str, value: &str) {
    if std::env::var_os(key).is_none() {
        std::env::set_var(key, value);
    }
}

/// Open MPI's MPI-I/O leaves out its `sm` shared-file-pointer component, unless the environment
/// chooses one (`OMPI_MCA_sharedfp`). HDF5's files never use shared file pointers, but `sm` sets
/// one up at every open, guarded by a POSIX semaphore named after the file's base name alone
/// (`/dev/shm/sem.OMPIO_checkpoint.h5.tmp`) and shared by every process on the machine: a run
/// killed while the file is open leaves it taken, and two runs opening files of the same name at
/// once can race for it (Open MPI report 11934); either way every later open of that name waits for
/// ever. The remaining components (`individual`, `lockedfile`) keep no state between processes.
/// Called before MPI starts, while the process has one thread, on every rank alike.
fn no_shared_file_pointers() {
    default_env("OMPI_MCA_sharedfp", "^sm");
}

/// A panic on one rank of a parallel run (a bug: every expected failure is an agreed error) would
/// leave the other ranks waiting in their next collective operation for ever, and unwinding it
/// would drop PETSc objects, whose destruction is collective too. So after the usual panic message
/// the whole run is ended with MPI_Abort (exit code 70). A panic inside a residual or Jacobian
/// callback is not a reason: the callback catches it and every rank agrees on the error.
fn abort_all_ranks_on_panic() {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        previous(info);
        if !petsc::callback::in_callback() {
            eprintln!("porompm: a rank panicked (a bug, please report it); ending every rank of the run");
            use mpi::traits::Communicator;
            mpi::topology::SimpleCommunicator::world().abort(70);
        }
    }));
}

fn element_test(material: &Path, path: &Path, out: &Path) -> Result<(), Failure> {
    let mtext = io::read_text(material).map_err(input)?;
    let m = porompm::element_test::input::parse_material(&mtext, &material.display().to_string())
        .map_err(|e| input(e.to_string()))?;
    let ptext = io::read_text(path).map_err(input)?;
    let p = porompm::element_test::input::parse_path(&ptext, &path.display().to_string())
        .map_err(|e| input(e.to_string()))?;
    let model = m.model.law();
    let rows = porompm::element_test::run(&model, &p).map_err(failed)?;
    let file =
        io::write_csv(out, "element_test.csv", &porompm::element_test::HEADER, &porompm::element_test::table(&rows))
            .map_err(input)?;
    if let Some(last) = rows.last() {
        let peak_q = rows.iter().map(|r| r.q()).fold(0.0, f64::max);
        println!(
            "{} increments; final stress [xx, yy, xy, zz, yz, zx] = [{:.4e}, {:.4e}, {:.4e}, {:.4e}, {:.4e}, {:.4e}] Pa, p = {:.4e} Pa, q = {:.4e} Pa (peak {:.4e}), ε̄ = {:.4e}",
            rows.len(),
            last.stress[0],
            last.stress[1],
            last.stress[2],
            last.stress[3],
            last.stress[4],
            last.stress[5],
            last.mean(),
            last.q(),
            peak_q,
            last.eps_pd
        );
    }
    println!("wrote {}", file.display());
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn sweep(
    case: &Path,
    out: &Path,
    options_files: &[PathBuf],
    vary: &[String],
    variant: &[String],
    sets: &[String],
    metric: &Option<String>,
    quiet: bool,
    petsc: &[String],
) -> Result<(), Failure> {
    use porompm::sweep::{self, SweepError};
    let varies = vary.iter().map(|v| sweep::Vary::parse(v)).collect::<Result<Vec<_>, _>>().map_err(input)?;
    let variants = variant.iter().map(|v| sweep::Variant::parse(v)).collect::<Result<Vec<_>, _>>().map_err(input)?;
    let exe = std::env::current_exe().map_err(|e| input(format!("cannot find the porompm executable: {e}")))?;
    let req = sweep::SweepRequest {
        exe,
        case: case.to_path_buf(),
        out: out.to_path_buf(),
        options_files: options_files.to_vec(),
        variants,
        varies,
        sets: sets.to_vec(),
        metric: metric.clone(),
        petsc: petsc.to_vec(),
        quiet,
    };
    match sweep::run(&req) {
        Ok(o) => {
            let failed = o.rows.iter().filter(|r| r.status != "completed").count();
            eprintln!(
                "{} runs, {failed} not completed; wrote {}",
                o.rows.len(),
                o.files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(", ")
            );
            Ok(())
        }
        Err(SweepError::Input(m)) => Err(input(m)),
        Err(SweepError::AllFailed(m)) => Err(failed(m)),
    }
}

fn info(petsc_args: &[String]) -> Result<(), Failure> {
    let (universe, coll, petsc) = start_mpi_and_petsc(petsc_args)?;
    let total = coll.sum(&[1.0]).map_err(failed)?[0];
    let ranks = coll.gather(&[coll.rank() as f64]).map_err(failed)?;
    if coll.rank() == 0 {
        let b = petsc::PetscBuild::get();
        println!("porompm {}", porompm::VERSION);
        println!("PETSc {} with {}", b.version, b.packages.join(", "));
        println!("ranks: {}", coll.size());
        println!("collective sum over ranks: {total} (ranks reporting: {ranks:?})");
    }
    let result = if total as usize != ranks.len() {
        Err(failed("the collective sum does not match the number of ranks"))
    } else {
        Ok(())
    };
    finish(universe, coll, petsc, result)
}

fn main() -> ExitCode {
    use clap::error::ErrorKind;
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e)
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) =>
        {
            e.exit()
        }
        // A bad command line is one error line, as any other bad input.
        Err(e) => {
            let text = e.render().to_string();
            eprintln!("{} (see --help)", text.lines().next().unwrap_or("error: bad command line"));
            return ExitCode::from(2);
        }
    };
    let result = match &cli.command {
        Command::Run {
            case,
            out,
            options_file,
            set,
            quiet,
            checkpoint_every,
            restart,
            threads,
            balance_threshold,
            petsc,
        } => {
            let cont = Continuation {
                checkpoint_every: checkpoint_every.map_or(0, |n| n as usize),
                restart: restart.as_deref(),
                threads: *threads,
                balance_threshold: *balance_threshold,
            };
            run(case, out, options_file, set, *quiet, cont, petsc)
        }
        Command::Sweep { case, out, options_file, vary, variant, set, metric, quiet, petsc } => {
            sweep(case, out, options_file, vary, variant, set, metric, *quiet, petsc)
        }
        Command::Report { dir } => porompm::report::report(dir).map(|t| print!("{t}")).map_err(input),
        Command::Check { case, set } => load_case(case, set).and_then(|c| {
            // The estimate first: a case too large for this machine is not built to be described.
            let e = porompm::model::memory::Estimate::of(&c);
            match io::available_memory() {
                Some(free) if e.needed > free => Err(input(e.refusal(e.needed, free))),
                _ => {
                    print!("{}", porompm::describe::describe(&c, &case.display().to_string()));
                    println!("{}", e.line());
                    Ok(())
                }
            }
        }),
        Command::TestJacobian { case, steps, tolerance, flip_block, set, petsc } => {
            test_jacobian(case, *steps, *tolerance, flip_block.as_deref(), set, petsc)
        }
        Command::ElementTest { material, path, out } => element_test(material, path, out),
        Command::Info { petsc } => info(petsc),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            // Under mpirun every rank ends with the same, agreed error: rank 0 prints it (`finish`
            // has, for a command that ran MPI).
            let rank = ["OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"]
                .iter()
                .find_map(|v| std::env::var(v).ok())
                .and_then(|r| r.parse::<usize>().ok())
                .unwrap_or(0);
            if rank == 0 && !f.reported {
                eprintln!("error: {}", f.message);
            }
            ExitCode::from(f.code)
        }
    }
}
