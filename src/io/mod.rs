//! Files: reading case files, and writing a run's results (`summary.json`, `history.csv`, extra
//! CSV tables). The only application module that touches the file system. Under MPI only rank 0
//! writes; the other ranks hold a [`RunOutput`] that does nothing.
//!
//! A run first writes `summary.json` with `"status": "running"` and rewrites it at the end with
//! `"completed"` or `"failed"`; a run that dies in between never looks complete.
//! `history.csv` is flushed row by row, so it stays readable whatever happens.

pub mod checkpoint;
pub mod fields;
pub mod geometry;
pub mod plot;

use mpi::topology::SimpleCommunicator;
use serde::Serialize;
use std::fs::{self, File};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Reads a whole text file, with the path in the error message.
pub fn read_text(path: &Path) -> Result<String, String> {
    fs::read_to_string(path).map_err(|e| format!("cannot read {}: {e}", path.display()))
}

/// Writes a CSV file `name` with `header` and text `rows` into `dir` (created if needed),
/// atomically.
pub fn write_csv(dir: &Path, name: &str, header: &[&str], rows: &[Vec<String>]) -> Result<PathBuf, String> {
    fs::create_dir_all(dir).map_err(|e| format!("cannot create output directory {}: {e}", dir.display()))?;
    let mut text = header.join(",");
    text.push('\n');
    for r in rows {
        text.push_str(&r.join(","));
        text.push('\n');
    }
    let path = dir.join(name);
    write_atomic(&path, text.as_bytes())?;
    Ok(path)
}

/// Where a run's figures go, inside its output directory.
pub const PLOTS_DIR: &str = "plots";

/// The peak resident memory of this process so far [MiB] (`ru_maxrss` of getrusage(2), the
/// `VmHWM` of `/proc/self/status`), if the system reports it. One system call, cheap enough for
/// the driver to read it around every phase of every step.
pub fn peak_memory_mib() -> Option<f64> {
    use nix::sys::resource::{getrusage, UsageWho};
    let kib = getrusage(UsageWho::RUSAGE_SELF).ok()?.max_rss();
    (kib > 0).then(|| kib as f64 / 1024.0)
}

/// The memory this machine has available for a new run [B] (`MemAvailable` of `/proc/meminfo`),
/// if the system reports it.
pub fn available_memory() -> Option<f64> {
    let info = fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// A number naming this machine (a hash of its host name), to tell which ranks share it.
pub fn machine_id() -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    hostname().hash(&mut h);
    h.finish()
}

/// Creates a directory and its parents if needed.
pub fn create_dir(dir: &Path) -> Result<(), String> {
    fs::create_dir_all(dir).map_err(|e| format!("cannot create output directory {}: {e}", dir.display()))
}

/// Writes a text file `name` into `dir` (created if needed), atomically.
pub fn write_text(dir: &Path, name: &str, text: &str) -> Result<PathBuf, String> {
    create_dir(dir)?;
    let path = dir.join(name);
    write_atomic(&path, text.as_bytes())?;
    Ok(path)
}

/// The output directory of a run.
pub struct RunOutput {
    /// The directory, on the writing rank.
    dir: Option<PathBuf>,
    /// The directory, on every rank (the field files are written by all ranks); `None` when
    /// nothing is written ([`RunOutput::silent`]).
    shared: Option<PathBuf>,
    history: Option<BufWriter<File>>,
    fields: Option<fields::FieldFiles>,
    /// The writing rank's lock on the directory ([`LOCK_FILE`]), held while this output lives.
    _lock: Option<File>,
    /// Whether the run has begun writing ([`RunOutput::begin`]).
    begun: bool,
}

/// The file in an output directory that the run writing into it holds locked (`flock`, released
/// by the kernel when the process ends, however it ends); it holds the process id.
pub const LOCK_FILE: &str = ".porompm.lock";

/// Takes the lock on `dir` ([`LOCK_FILE`]), or says which process holds it.
fn lock(dir: &Path) -> Result<File, String> {
    let path = dir.join(LOCK_FILE);
    let mut f = fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .map_err(|e| format!("cannot open {}: {e}", path.display()))?;
    match f.try_lock() {
        Ok(()) => {}
        Err(fs::TryLockError::WouldBlock) => {
            let holder = fs::read_to_string(&path).unwrap_or_default();
            let holder = holder.trim();
            let holder = if holder.is_empty() { String::new() } else { format!(" ({holder})") };
            return Err(format!(
                "output directory {} is in use by another run{holder}: give this run another --out, or wait for that one to end",
                dir.display()
            ));
        }
        Err(fs::TryLockError::Error(e)) => return Err(format!("cannot lock {}: {e}", path.display())),
    }
    let stamp = format!("process {} on {}", std::process::id(), hostname());
    f.set_len(0)
        .and_then(|_| f.write_all(stamp.as_bytes()))
        .and_then(|_| f.flush())
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(f)
}

/// This machine's name, for the lock's holder (empty if unknown).
fn hostname() -> String {
    fs::read_to_string("/proc/sys/kernel/hostname").map(|h| h.trim().to_string()).unwrap_or_default()
}

/// Writes `content` to `path` atomically (write a temporary file, then rename). A failed write
/// leaves `path` as it was and removes its temporary file.
pub(crate) fn write_atomic(path: &Path, content: &[u8]) -> Result<(), String> {
    let tmp = path.with_extension("tmp");
    let written = File::create(&tmp)
        .map_err(|e| format!("cannot create {}: {e}", tmp.display()))
        .and_then(|mut f| {
            f.write_all(content).and_then(|_| f.sync_all()).map_err(|e| format!("cannot write {}: {e}", tmp.display()))
        })
        .and_then(|_| {
            fs::rename(&tmp, path).map_err(|e| format!("cannot rename {} to {}: {e}", tmp.display(), path.display()))
        });
    if written.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    written
}

/// Room a file about to be written must leave free on its disk: the summary, the history rows
/// and the event lines that follow it must still fit, also when the run then ends.
pub const SPARE_BYTES: u64 = 64 * 1024;

/// Whether the disk of `file`'s directory has room for it, about `bytes` long, and
/// [`SPARE_BYTES`] more (one eighth of `bytes` added for the file's metadata); the error names the
/// file, what it needs and what is free. A disk whose free space cannot be read passes.
pub fn check_room(file: &Path, bytes: u64) -> Result<(), String> {
    let dir = file.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let Some(free) = free_space(dir) else { return Ok(()) };
    let need = bytes + bytes / 8 + SPARE_BYTES;
    if free >= need {
        return Ok(());
    }
    let kib = |b: u64| match b < 1 << 20 {
        true => format!("{} KiB", b.div_ceil(1024)),
        false => format!("{:.1} MiB", b as f64 / (1024.0 * 1024.0)),
    };
    Err(format!(
        "the disk is full: {} needs about {} and the disk of {} has {} free",
        file.display(),
        kib(need),
        dir.display(),
        kib(free)
    ))
}

/// The free space of the disk of `dir` [B]: the file system's or, for the tests of a full disk
/// (fault injection), that of a disk of `PORO_FAULT_DISK_BYTES` bytes holding `dir` alone.
fn free_space(dir: &Path) -> Option<u64> {
    match std::env::var("PORO_FAULT_DISK_BYTES").ok().and_then(|v| v.parse::<u64>().ok()) {
        Some(disk) => Some(disk.saturating_sub(bytes_under(dir))),
        None => fs4::available_space(dir).ok(),
    }
}

/// The bytes of the files under `dir`.
fn bytes_under(dir: &Path) -> u64 {
    let Ok(entries) = fs::read_dir(dir) else { return 0 };
    entries
        .flatten()
        .map(|e| match e.file_type() {
            Ok(t) if t.is_dir() => bytes_under(&e.path()),
            _ => e.metadata().map_or(0, |m| m.len()),
        })
        .sum()
}

/// The same outcome on every rank of `comm`: `Ok` if every rank's is, else this rank's error or,
/// on the ranks that succeeded, the note `other` that another failed.
pub(crate) fn agree<T>(comm: &SimpleCommunicator, local: Result<T, String>, other: &str) -> Result<T, String> {
    use mpi::collective::SystemOperation;
    use mpi::traits::CommunicatorCollectives;
    let mine = local.is_err() as i32;
    let mut any = 0i32;
    comm.all_reduce_into(&mine, &mut any, SystemOperation::max());
    match local {
        Ok(_) if any > 0 => Err(other.into()),
        other => other,
    }
}

impl RunOutput {
    /// Prepares `dir` (created if needed) on the writing rank and locks it for this run (a second
    /// run into it is refused while this one lives); the others only keep its name, for the field
    /// files all ranks write. Nothing in it changes until [`RunOutput::begin`].
    pub fn create(dir: &Path, writer: bool) -> Result<RunOutput, String> {
        let mut out = RunOutput {
            dir: None,
            shared: Some(dir.to_path_buf()),
            history: None,
            fields: None,
            _lock: None,
            begun: false,
        };
        if writer {
            fs::create_dir_all(dir).map_err(|e| format!("cannot create output directory {}: {e}", dir.display()))?;
            out._lock = Some(lock(dir)?);
            out.dir = Some(dir.to_path_buf());
        }
        Ok(out)
    }

    /// Begins the run's output once it has been set up: the results of an earlier run in the
    /// directory are removed (so that they cannot be mistaken for this run's, and a run that
    /// fails to start leaves them as they were), then `summary` is written.
    pub fn begin<T: Serialize>(&mut self, summary: &T) -> Result<(), String> {
        if let Some(dir) = &self.dir {
            for old in ["summary.json", "history.csv", "amplitude_profile.csv", "fields.h5", "fields.xdmf"] {
                let p = dir.join(old);
                if p.exists() {
                    fs::remove_file(&p).map_err(|e| format!("cannot remove old {}: {e}", p.display()))?;
                }
            }
            let plots = dir.join(PLOTS_DIR);
            if plots.is_dir() {
                fs::remove_dir_all(&plots).map_err(|e| format!("cannot remove old {}: {e}", plots.display()))?;
            }
        }
        self.begun = true;
        self.write_summary(summary)
    }

    /// Whether [`RunOutput::begin`] has been called.
    pub fn has_begun(&self) -> bool {
        self.begun
    }

    /// An output that writes nothing on any rank (the tangent check).
    pub fn silent() -> RunOutput {
        RunOutput { dir: None, shared: None, history: None, fields: None, _lock: None, begun: false }
    }

    /// Draws the figures as PNG files into `plots/` (created if needed) and returns the paths.
    pub fn write_figures(&self, figures: &[crate::plot::Figure]) -> Result<Vec<PathBuf>, String> {
        let Some(dir) = &self.dir else { return Ok(Vec::new()) };
        plot::write_figures(&dir.join(PLOTS_DIR), figures)
    }

    /// Whether this rank writes.
    pub fn is_writer(&self) -> bool {
        self.dir.is_some()
    }

    /// The path of the output file `name` (as given on the command line; on a rank that writes
    /// nothing, `name` alone).
    pub fn path_of(&self, name: &str) -> String {
        self.dir.as_ref().map_or(name.to_string(), |d| d.join(name).display().to_string())
    }

    /// Writes (replaces) `summary.json`, atomically.
    pub fn write_summary<T: Serialize>(&self, summary: &T) -> Result<(), String> {
        let Some(dir) = &self.dir else { return Ok(()) };
        let text = serde_json::to_string_pretty(summary).map_err(|e| format!("cannot serialise the summary: {e}"))?;
        write_atomic(&dir.join("summary.json"), text.as_bytes())
    }

    /// Starts `history.csv` with the given column names.
    pub fn start_history(&mut self, columns: &[String]) -> Result<(), String> {
        let Some(dir) = &self.dir else { return Ok(()) };
        let path = dir.join("history.csv");
        let f = File::create(&path).map_err(|e| format!("cannot create {}: {e}", path.display()))?;
        let mut w = BufWriter::new(f);
        writeln!(w, "{}", columns.join(",")).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        w.flush().map_err(|e| e.to_string())?;
        self.history = Some(w);
        Ok(())
    }

    /// Appends one row to `history.csv` and flushes it.
    pub fn history_row(&mut self, values: &[f64]) -> Result<(), String> {
        let Some(w) = self.history.as_mut() else {
            return Ok(());
        };
        let line: Vec<String> = values.iter().map(|v| format!("{v:.10e}")).collect();
        writeln!(w, "{}", line.join(",")).and_then(|_| w.flush()).map_err(|e| format!("cannot write history.csv: {e}"))
    }

    /// Starts `fields.h5`/`fields.xdmf` for a grid, on all ranks of `comm` together.
    pub fn start_fields(&mut self, grid: fields::GridGeometry, comm: &SimpleCommunicator) -> Result<(), String> {
        if let Some(shared) = &self.shared {
            self.fields = Some(fields::FieldFiles::create(shared, grid, comm, self.dir.is_some())?);
        }
        Ok(())
    }

    /// Appends one output time to the field files (if started; collective over `comm`).
    pub fn write_fields(&mut self, frame: &fields::Frame, comm: &SimpleCommunicator) -> Result<(), String> {
        match self.fields.as_mut() {
            Some(f) => f.write(frame, comm),
            None => Ok(()),
        }
    }

    /// Completes the field files' XDMF index (see [`fields::FieldFiles::finish`]).
    pub fn finish_fields(&mut self) -> Result<(), String> {
        match self.fields.as_mut() {
            Some(f) => f.finish(),
            None => Ok(()),
        }
    }

    /// Writes `checkpoint.h5` atomically, on all ranks of `comm` together (see [`checkpoint`]);
    /// nothing on a silent output.
    pub fn write_checkpoint(&self, cp: &crate::state::Checkpoint, comm: &SimpleCommunicator) -> Result<(), String> {
        let Some(dir) = &self.shared else { return Ok(()) };
        checkpoint::write(&dir.join("checkpoint.h5"), cp, comm, self.dir.is_some())
    }

    /// Writes a CSV table `name` (header, rows) atomically.
    pub fn write_table(&self, name: &str, header: &[&str], rows: &[Vec<f64>]) -> Result<(), String> {
        let Some(dir) = &self.dir else { return Ok(()) };
        let mut text = header.join(",");
        text.push('\n');
        for r in rows {
            text.push_str(&r.iter().map(|v| format!("{v:.10e}")).collect::<Vec<_>>().join(","));
            text.push('\n');
        }
        write_atomic(&dir.join(name), text.as_bytes())
    }
}

/// Checks a PETSc options file against the grammar PETSc reads it with
/// (`PetscOptionsInsertFilePetsc`), so that a bad file is one clear error rather than PETSc's
/// traceback: text after `#` is a comment; a non-empty line starts with an option name (`-...`,
/// its value the rest of the line) or is `alias -new -old`. Files named `*.yml`/`*.yaml` are
/// PETSc's YAML form and only checked to be text. An `-options_file F` line is followed (F relative
/// to the working directory, as PETSc reads it), up to 8 levels deep.
pub fn check_petsc_options_file(path: &Path) -> Result<(), String> {
    check_options_file_at(path, 0)
}

fn check_options_file_at(path: &Path, depth: usize) -> Result<(), String> {
    let name = path.display();
    if depth > 8 {
        return Err(format!("PETSc options file {name}: `-options_file` nested more than 8 levels deep"));
    }
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read the PETSc options file {name}: {e}"))?;
    let text = String::from_utf8(bytes)
        .ok()
        .filter(|t| !t.contains('\0'))
        .ok_or_else(|| format!("PETSc options file {name} is not a text file"))?;
    let yaml = matches!(path.extension().and_then(|e| e.to_str()), Some("yml" | "yaml"));
    if yaml {
        return Ok(());
    }
    for (i, line) in text.lines().enumerate() {
        let content = line.split('#').next().unwrap_or("");
        let tokens = option_tokens(content);
        let Some(&first) = tokens.first() else { continue };
        let alias = first.eq_ignore_ascii_case("alias");
        if alias {
            if tokens.len() < 3 {
                return Err(format!("PETSc options file {name} line {}: `alias` needs two option names", i + 1));
            }
            if let Some(extra) = tokens.get(3) {
                let extra = shown(extra);
                return Err(format!("PETSc options file {name} line {}: `{extra}` is left over after `alias`", i + 1));
            }
        } else if !first.starts_with('-') || first.len() < 2 {
            let first = shown(first);
            return Err(format!(
                "PETSc options file {name} line {}: `{first}` is not an option (an option name begins with `-`; \
                 comments begin with `#`)",
                i + 1
            ));
        } else if tokens.get(1).is_some_and(|v| is_option_name(v)) {
            return Err(format!(
                "PETSc options file {name} line {}: two options on one line (`{first}` and `{}`): one a line",
                i + 1,
                tokens[1]
            ));
        } else if let Some(extra) = tokens.get(2) {
            let extra = shown(extra);
            return Err(format!(
                "PETSc options file {name} line {}: `{extra}` is left over (a line holds one option and its value; \
                 comments begin with `#`)",
                i + 1
            ));
        } else if first == "-options_file" {
            let Some(&nested) = tokens.get(1) else {
                return Err(format!("PETSc options file {name} line {}: `-options_file` without a file", i + 1));
            };
            let nested = Path::new(nested);
            if !nested.is_file() {
                return Err(format!(
                    "PETSc options file {name} line {}: the options file {} does not exist",
                    i + 1,
                    nested.display()
                ));
            }
            check_options_file_at(nested, depth + 1)?;
        }
    }
    Ok(())
}

/// A token of an options file as an error message shows it: its first 40 characters.
fn shown(token: &str) -> String {
    token.chars().take(40).collect()
}

/// The tokens of a line of a PETSc options file as PETSc reads them: separated by blanks, a token
/// in double quotes taken whole (blanks included).
fn option_tokens(line: &str) -> Vec<&str> {
    let mut tokens = Vec::new();
    let mut rest = line.trim_start();
    while !rest.is_empty() {
        let (token, after) = match rest.strip_prefix('"') {
            Some(quoted) => quoted.split_once('"').unwrap_or((quoted, "")),
            None => rest.split_once(char::is_whitespace).unwrap_or((rest, "")),
        };
        tokens.push(token);
        rest = after.trim_start();
    }
    tokens
}

/// Whether a token is an option's name rather than a value, as PETSc tells them apart
/// (`PetscOptionsValidKey`): one or two `-` followed by a letter, and not a number (`-inf`).
fn is_option_name(token: &str) -> bool {
    let Some(name) = token.strip_prefix('-') else { return false };
    let name = name.strip_prefix('-').unwrap_or(name);
    name.starts_with(|c: char| c.is_ascii_alphabetic()) && token.parse::<f64>().is_err()
}

/// MPI for the unit tests that write HDF5 files through MPI-I/O (a singleton run): initialised once
/// and never finalised (the test process ends without it), with a lock so that one test at a
/// time uses it.
#[cfg(test)]
pub(crate) fn test_world() -> (std::sync::MutexGuard<'static, ()>, SimpleCommunicator) {
    static INIT: std::sync::Once = std::sync::Once::new();
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    INIT.call_once(|| {
        let (universe, _) =
            mpi::initialize_with_threading(mpi::Threading::Multiple).expect("MPI initialises once per test process");
        std::mem::forget(universe);
    });
    let guard = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    (guard, SimpleCommunicator::world())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_options_line_splits_as_petsc_reads_it() {
        assert_eq!(option_tokens("  -ksp_rtol   1e-4 "), ["-ksp_rtol", "1e-4"]);
        assert_eq!(option_tokens("-snes_view_pre \"ascii:a b.txt\" x"), ["-snes_view_pre", "ascii:a b.txt", "x"]);
        assert!(option_tokens("   ").is_empty());
        for name in ["-ksp_type", "-pc_use_amat", "-x"] {
            assert!(is_option_name(name), "{name}");
        }
        for value in ["-1", "-2.5e-3", "-.5", "gmres", "1e-4", "-inf"] {
            assert!(!is_option_name(value), "{value}");
        }
    }

    #[test]
    fn outputs_are_written_and_old_results_removed() {
        let dir = std::env::temp_dir().join(format!("porompm-io-test-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        fs::write(dir.join("summary.json"), "{\"status\": \"completed\"}").unwrap();
        let mut out = RunOutput::create(&dir, true).unwrap();
        assert!(dir.join("summary.json").exists(), "nothing is removed before the run begins");
        let second = RunOutput::create(&dir, true).err().unwrap_or_default();
        assert!(second.contains("in use by another run (process "), "{second}");
        out.begin(&serde_json::json!({"status": "running"})).unwrap();
        assert!(
            fs::read_to_string(dir.join("summary.json")).unwrap().contains("running"),
            "a stale summary is replaced"
        );
        out.start_history(&["time".into(), "p".into()]).unwrap();
        out.history_row(&[0.5, 1.25]).unwrap();
        out.write_table("t.csv", &["a", "b"], &[vec![1.0, 2.0]]).unwrap();
        let h = fs::read_to_string(dir.join("history.csv")).unwrap();
        assert!(h.starts_with("time,p\n5.0000000000e-1,1.2500000000e0"));
        assert!(fs::read_to_string(dir.join("summary.json")).unwrap().contains("running"));
        assert!(fs::read_to_string(dir.join("t.csv")).unwrap().starts_with("a,b\n"));
        fs::create_dir_all(dir.join(PLOTS_DIR)).unwrap();
        fs::write(dir.join(PLOTS_DIR).join("old.png"), "stale").unwrap();
        drop(out);
        RunOutput::create(&dir, true).unwrap().begin(&serde_json::json!({})).unwrap();
        assert!(!dir.join(PLOTS_DIR).exists(), "stale plots must not survive");
        let peak = peak_memory_mib().unwrap();
        assert!(peak > 1.0 && peak < 1e6, "{peak} MiB");
        let silent = RunOutput::create(&dir.join("never"), false).unwrap();
        silent.write_summary(&serde_json::json!({})).unwrap();
        assert!(!dir.join("never").exists());
        fs::remove_dir_all(&dir).unwrap();
    }
}
