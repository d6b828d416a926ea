//! `checkpoint.h5`: reading and writing a [`Checkpoint`] (see [`crate::state`] for what it holds).
//!
//! Layout: root attributes `format` ("porompm-checkpoint"), `version`, `case_fingerprint`, `time`
//! [s], `step`, `stage`, `dt` [s], `successes`, then
//! `checksum` and, written last, `complete` = 1; datasets `counters` (step cuts, Newton and Krylov
//! iterations, matrix-structure reuses, line-search retries), `load_totals`, the group `recorders`
//! with one dataset per recorder's state (named as the recorder), and one dataset per
//! particle array under `/particles` (n × components, SI units, sorted by id; the points' dimension
//! is the number of components of `x`, 2 or 3, and sets every vector's and F's, `state::particle_fields`).
//!
//! All ranks write and read the file together (HDF5's MPI-I/O driver): each writes the slab of the
//! id-sorted particle records it holds and reads back an equal share of the rows; no rank holds the
//! records of all. The particles' checksum is a sum over the records of a hash of each record's
//! position and values ([`Checkpoint::records_hash`]), added over the ranks, so it is the same for
//! any number of ranks.
//!
//! Atomicity: the file is written as `<name>.tmp`, closed, synced to disk, and renamed over the
//! old checkpoint by the writing rank (then the directory is synced). A run killed while writing leaves the previous
//! checkpoint in place and at most a stray `.tmp`. On reading, a file without `complete`, of
//! another format version, or whose content does not match its checksum is refused.

use crate::state::{particle_fields, record_len, Checkpoint};
use hdf5_metno as h5;
use hdf5_metno::types::VarLenUnicode;
use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::{AsRaw, Communicator, CommunicatorCollectives};
use std::fs;
use std::path::Path;

const FORMAT: &str = "porompm-checkpoint";

fn attr_f64(loc: &h5::Location, name: &str, v: f64) -> h5::Result<()> {
    loc.new_attr::<f64>().create(name)?.write_scalar(&v)
}

fn attr_u64(loc: &h5::Location, name: &str, v: u64) -> h5::Result<()> {
    loc.new_attr::<u64>().create(name)?.write_scalar(&v)
}

fn dataset_f64(g: &h5::Group, name: &str, shape: &[usize], data: &[f64]) -> h5::Result<()> {
    g.new_dataset::<f64>().shape(shape.to_vec()).create(name)?.write_raw(data)
}

/// The same outcome on every rank of `comm` ([`super::agree`]).
fn agree<T>(comm: &SimpleCommunicator, local: Result<T, String>) -> Result<T, String> {
    super::agree(comm, local, "another rank could not read or write the checkpoint")
}

/// The size of `cp`'s file [B], about: its numbers and the metadata of its datasets.
fn size_of(cp: &Checkpoint) -> u64 {
    let numbers = cp.total as usize * record_len(cp.dim)
        + cp.recorders.iter().map(|(_, s)| s.len()).sum::<usize>()
        + cp.counters.len()
        + cp.load_totals.len();
    8 * numbers as u64 + 16 * 1024
}

/// The particles' checksum share of every rank, added (wrapping).
fn hash_over_ranks(comm: &SimpleCommunicator, mine: u64) -> u64 {
    let mut sum = 0u64;
    comm.all_reduce_into(&mine, &mut sum, SystemOperation::sum());
    sum
}

fn open_mpio(path: &Path, comm: &SimpleCommunicator, create: bool) -> h5::Result<h5::File> {
    let raw = comm.as_raw();
    let mut b = h5::File::with_options();
    b.with_fapl(|p| p.mpio(raw, None));
    if create {
        b.create(path)
    } else {
        b.open(path)
    }
}

/// Writes `cp` (this rank's slab of the particles) to `path` atomically, on all ranks of `comm`
/// together; `writer` is the rank that renames the finished file (see the module documentation).
pub fn write(path: &Path, cp: &Checkpoint, comm: &SimpleCommunicator, writer: bool) -> Result<(), String> {
    let tmp = path.with_extension("h5.tmp");
    let fail = |e: h5::Error| format!("cannot write checkpoint {}: {e}", tmp.display());
    let removed = match writer && tmp.exists() {
        true => fs::remove_file(&tmp).map_err(|e| format!("cannot remove {}: {e}", tmp.display())),
        false => Ok(()),
    };
    agree(comm, removed)?;
    // A full disk is refused before HDF5 starts: a write that fails inside its collective calls
    // can leave the ranks in different ones and the file open at exit.
    let room = if writer { super::check_room(&tmp, size_of(cp)) } else { Ok(()) };
    agree(comm, room.map_err(|e| format!("cannot write a checkpoint, the last one is kept: {e}")))?;
    let hash = hash_over_ranks(comm, cp.records_hash());
    let written = (|| -> h5::Result<()> {
        let f = open_mpio(&tmp, comm, true)?;
        let format: VarLenUnicode = FORMAT.parse().expect("ASCII");
        f.new_attr::<VarLenUnicode>().create("format").and_then(|a| a.write_scalar(&format))?;
        let loc: &h5::Location = &f;
        attr_u64(loc, "version", crate::state::FORMAT_VERSION)?;
        attr_u64(loc, "case_fingerprint", cp.case_fingerprint)?;
        attr_f64(loc, "time", cp.time)?;
        attr_u64(loc, "step", cp.step)?;
        attr_u64(loc, "stage", cp.stage)?;
        attr_f64(loc, "dt", cp.dt)?;
        attr_u64(loc, "successes", cp.successes)?;
        f.new_dataset::<u64>()
            .shape(cp.counters.len())
            .create("counters")
            .and_then(|d| d.write_raw(&cp.counters[..]))?;
        dataset_f64(&f, "load_totals", &[cp.load_totals.len()], &cp.load_totals)?;
        {
            let g = f.create_group("recorders")?;
            for (name, state) in &cp.recorders {
                dataset_f64(&g, name, &[state.len()], state)?;
            }
        }
        {
            let g = f.create_group("particles")?;
            let (n, rows, first) = (cp.total as usize, cp.records().len(), cp.first as usize);
            let mut offset = 0;
            for (name, comps) in particle_fields(cp.dim) {
                let ds = g.new_dataset::<f64>().shape([n, comps]).create(name)?;
                if rows > 0 {
                    let data: Vec<f64> = cp.records().flat_map(|r| r[offset..offset + comps].to_vec()).collect();
                    super::fields::write_block(&ds, &data, &[first], &[rows, comps])?;
                }
                offset += comps;
            }
        }
        attr_u64(loc, "checksum", cp.checksum(hash))?;
        attr_u64(loc, "complete", 1)?;
        f.flush()?;
        f.close()
    })();
    if let Err(e) = agree(comm, written.map_err(fail)) {
        // The partial file is removed to give its room back to the summary.
        if writer {
            let _ = fs::remove_file(&tmp);
        }
        return Err(e);
    }
    let renamed = if writer {
        let sync = |p: &Path| fs::File::open(p).and_then(|f| f.sync_all());
        sync(&tmp)
            .map_err(|e| format!("cannot sync {}: {e}", tmp.display()))
            .and_then(|_| {
                fs::rename(&tmp, path)
                    .map_err(|e| format!("cannot rename {} to {}: {e}", tmp.display(), path.display()))
            })
            .and_then(|_| match path.parent().filter(|d| !d.as_os_str().is_empty()) {
                Some(dir) => sync(dir).map_err(|e| format!("cannot sync {}: {e}", dir.display())),
                None => Ok(()),
            })
    } else {
        Ok(())
    };
    agree(comm, renamed)
}

/// Reads and verifies a checkpoint (format, version, completeness, checksum), on all ranks of
/// `comm` together: each rank gets an equal share of the id-sorted particle records (rows
/// [r n/P, (r + 1) n/P) of n on P ranks). Every rank returns the same outcome.
pub fn read(path: &Path, comm: &SimpleCommunicator) -> Result<Checkpoint, String> {
    let read = read_share(path, comm);
    let hash = hash_over_ranks(comm, read.as_ref().map_or(0, |(cp, _)| cp.records_hash()));
    let cp = agree(comm, read)?;
    let (cp, stored) = cp;
    if stored != cp.checksum(hash) {
        return Err(format!("checkpoint {} is corrupt: its content does not match its checksum", path.display()));
    }
    Ok(cp)
}

/// This rank's share of the checkpoint and the stored checksum.
fn read_share(path: &Path, comm: &SimpleCommunicator) -> Result<(Checkpoint, u64), String> {
    let name = path.display();
    if !path.is_file() {
        return Err(format!("checkpoint {name} does not exist"));
    }
    // Not an HDF5 file: every rank sees it the same way before the collective open.
    let mut signature = [0u8; 8];
    let read = fs::File::open(path).and_then(|mut f| std::io::Read::read_exact(&mut f, &mut signature));
    if read.is_err() || &signature != b"\x89HDF\r\n\x1a\n" {
        return Err(format!("checkpoint {name} cannot be opened (not an HDF5 file, or truncated)"));
    }
    let f = open_mpio(path, comm, false)
        .map_err(|_| format!("checkpoint {name} cannot be opened (not an HDF5 file, or truncated)"))?;
    let bad = |what: &str| format!("checkpoint {name} is not a porompm checkpoint ({what})");
    let format = f.attr("format").and_then(|a| a.read_scalar::<VarLenUnicode>()).map_err(|_| bad("no `format`"))?;
    if format.as_str() != FORMAT {
        return Err(bad(&format!("format `{}`", format.as_str())));
    }
    let u = |n: &str| f.attr(n).and_then(|a| a.read_scalar::<u64>());
    let x = |n: &str| f.attr(n).and_then(|a| a.read_scalar::<f64>());
    let version = u("version").map_err(|_| bad("no `version`"))?;
    if version != crate::state::FORMAT_VERSION {
        return Err(format!(
            "checkpoint {name} has format version {version}; this porompm reads version {}",
            crate::state::FORMAT_VERSION
        ));
    }
    if u("complete").ok() != Some(1) {
        return Err(format!("checkpoint {name} is incomplete (its writing was interrupted)"));
    }
    let corrupt = |e: h5::Error| format!("checkpoint {name} cannot be read: {e}");
    let counters: Vec<u64> = f.dataset("counters").and_then(|d| d.read_raw()).map_err(corrupt)?;
    let vec_f64 = |n: &str| f.dataset(n).and_then(|d| d.read_raw::<f64>());
    let recorders = {
        let g = f.group("recorders").map_err(corrupt)?;
        let mut names = g.member_names().map_err(corrupt)?;
        names.sort();
        let mut states = Vec::with_capacity(names.len());
        for n in names {
            states.push((n.clone(), g.dataset(&n).and_then(|d| d.read_raw::<f64>()).map_err(corrupt)?));
        }
        states
    };
    let g = f.group("particles").map_err(corrupt)?;
    // The points' dimension: the components of their positions.
    let dim = g.dataset("x").map_err(corrupt)?.shape().get(1).copied().unwrap_or(0);
    if !(2..=3).contains(&dim) {
        return Err(format!("checkpoint {name}: particle array `x` has {dim} components (2 or 3 expected)"));
    }
    let mut datasets = Vec::new();
    let mut n = None;
    for (field, comps) in particle_fields(dim) {
        let d = g.dataset(field).map_err(corrupt)?;
        let shape = d.shape();
        if shape.len() != 2 || shape[1] != comps || n.is_some_and(|n| n != shape[0]) {
            return Err(format!("checkpoint {name}: particle array `{field}` has shape {shape:?}"));
        }
        n = Some(shape[0]);
        datasets.push(d);
    }
    let n = n.unwrap_or(0);
    let (rank, size) = (comm.rank() as usize, comm.size() as usize);
    let (a, b) = (rank * n / size, (rank + 1) * n / size);
    let mut columns = Vec::new();
    for d in &datasets {
        let column = match b > a {
            true => d.read_slice_2d::<f64, _>((a..b, ..)).map_err(corrupt)?.iter().copied().collect(),
            false => Vec::new(),
        };
        columns.push(column);
    }
    let len = record_len(dim);
    let mut particles = vec![0.0; (b - a) * len];
    for (k, r) in particles.chunks_exact_mut(len).enumerate() {
        let mut o = 0;
        for (c, (_, comps)) in columns.iter().zip(particle_fields(dim)) {
            r[o..o + comps].copy_from_slice(&c[k * comps..(k + 1) * comps]);
            o += comps;
        }
    }
    let cp = Checkpoint {
        case_fingerprint: u("case_fingerprint").map_err(corrupt)?,
        time: x("time").map_err(corrupt)?,
        step: u("step").map_err(corrupt)?,
        stage: u("stage").map_err(corrupt)?,
        dt: x("dt").map_err(corrupt)?,
        successes: u("successes").map_err(corrupt)?,
        counters: counters.try_into().map_err(|_| format!("checkpoint {name}: `counters` must hold 5 values"))?,
        recorders,
        load_totals: vec_f64("load_totals").map_err(corrupt)?,
        dim,
        particles,
        first: a as u64,
        total: n as u64,
    };
    let stored = u("checksum").map_err(corrupt)?;
    Ok((cp, stored))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A checkpoint of two points of dimension `dim`.
    fn sample(dim: usize) -> Checkpoint {
        let len = record_len(dim);
        let mut particles: Vec<f64> = (0..2 * len).map(|i| (i % len) as f64 * 0.5 + 1.0 / 3.0).collect();
        particles[len] = 99.0;
        Checkpoint {
            case_fingerprint: 0xdead_beef_0123,
            time: 0.3 + 1e-17,
            step: 300,
            stage: 1,
            dt: 1e-3 / 3.0,
            successes: 2,
            counters: [1, 301, 302, 7, 2],
            recorders: vec![("check".into(), vec![1.0, 2.0]), ("diagnostics".into(), vec![f64::NAN, 0.5])],
            load_totals: vec![0.25, 1.0 / 3.0],
            dim,
            particles,
            first: 0,
            total: 2,
        }
    }

    #[test]
    fn a_checkpoint_round_trips_exactly_and_a_tampered_or_partial_one_is_refused() {
        let (_lock, world) = crate::io::test_world();
        let dir = std::env::temp_dir().join(format!("porompm-cp-test-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let path = dir.join("checkpoint.h5");
        // Three-dimensional points: 55 values each, the vectors with three components.
        let cp = sample(3);
        write(&path, &cp, &world, true).unwrap();
        let back = read(&path, &world).unwrap();
        assert_eq!((back.dim, &back.particles), (3, &cp.particles));
        let x = h5::File::open(&path).unwrap().dataset("particles/x").unwrap().shape();
        assert_eq!(x, [2, 3]);
        let cp = sample(2);
        write(&path, &cp, &world, true).unwrap();
        assert!(!dir.join("checkpoint.h5.tmp").exists());
        let back = read(&path, &world).unwrap();
        assert_eq!(back.checksum(back.records_hash()), cp.checksum(cp.records_hash()));
        assert_eq!((back.first, back.total, back.dim), (0, 2, 2));
        assert_eq!(back.particles, cp.particles);
        assert_eq!(back.time.to_bits(), cp.time.to_bits());
        assert_eq!(back.recorders.len(), 2);
        assert!(
            back.recorders[1].1[0].is_nan() && back.recorders[1].1[1] == 0.5 && back.recorders[0] == cp.recorders[0]
        );

        // Change one particle value behind the checksum's back.
        {
            let f = h5::File::open_rw(&path).unwrap();
            let d = f.dataset("particles/p").unwrap();
            d.write_raw(&[1.0, 2.0][..]).unwrap();
        }
        assert!(read(&path, &world).unwrap_err().contains("does not match its checksum"));

        // A file whose writing stopped before `complete`.
        write(&path, &cp, &world, true).unwrap();
        {
            let f = h5::File::open_rw(&path).unwrap();
            f.delete_attr("complete").unwrap();
        }
        assert!(read(&path, &world).unwrap_err().contains("incomplete"));

        fs::write(&path, "not hdf5").unwrap();
        assert!(read(&path, &world).unwrap_err().contains("not an HDF5 file, or truncated"));
        assert!(read(&dir.join("none.h5"), &world).unwrap_err().contains("does not exist"));
        fs::remove_dir_all(&dir).unwrap();
    }
}
