//! Collective operations over the run's ranks, on rsmpi (MPI's lifetime belongs to `main`, which
//! initialises it before PETSc and finalises it after).
//!
//! Every decision that leads to a collective operation (a new matrix, a step cut, a stage end, an
//! output or checkpoint) must be the same on every rank, and an error raised on one rank between
//! two collectives must reach the others before they enter the next one, or the run hangs. The
//! pattern is: compute the local outcome, then [`Collective::agree`] on it: every rank returns the
//! same `Ok` or the same error (that of the lowest failing rank).

use mpi::collective::SystemOperation;
use mpi::datatype::{Partition, PartitionMut};
use mpi::topology::{Communicator, SimpleCommunicator};
use mpi::traits::*;

/// Points a thread must get for a thread of its own to pay when the threads are not set: starting
/// and joining a thread at each of a step's assemblies costs about what the kernels of a few
/// hundred points do, and a small problem run on threads spends its steps waiting for them
/// (Terzaghi's column of 40 points took three times longer on two threads than on one while the
/// machine's other core was busy).
pub const POINTS_PER_THREAD: usize = 2000;

/// The run's communicator (MPI_COMM_WORLD) and its reductions, and the threads each rank runs its
/// particle loops on.
pub struct Collective {
    world: SimpleCommunicator,
    threads: usize,
    /// Whether `--threads` set the threads (then every one is used, however few the points).
    threads_set: bool,
    /// The collective operations this rank took part in, and the bytes they brought it.
    traffic: std::cell::Cell<Traffic>,
}

/// Counts of porompm's own collective operations on one rank (PETSc's are in its `-log_view`).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Traffic {
    /// Collective calls (reductions, gathers, exchanges, agreements).
    pub calls: u64,
    /// Bytes they delivered to this rank.
    pub bytes: u64,
}

impl Default for Collective {
    fn default() -> Self {
        Collective::world()
    }
}

impl Collective {
    /// All ranks of the run. MPI must be initialised.
    /// All ranks of the run, each with its share of this machine's cores as threads: the cores
    /// divided by the ranks running on the same node (at least one).
    pub fn world() -> Collective {
        let world = SimpleCommunicator::world();
        let on_node = world.split_shared(world.rank()).size().max(1) as usize;
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        Collective { world, threads: (cores / on_node).max(1), threads_set: false, traffic: Default::default() }
    }

    /// Sets the threads of this rank's particle loops (`--threads`; at least one), used whatever
    /// the number of points.
    pub fn set_threads(&mut self, n: usize) {
        self.threads = n.max(1);
        self.threads_set = true;
    }

    /// This rank's collective traffic so far.
    pub fn traffic(&self) -> Traffic {
        self.traffic.get()
    }

    fn count(&self, bytes: usize) {
        let t = self.traffic.get();
        self.traffic.set(Traffic { calls: t.calls + 1, bytes: t.bytes + bytes as u64 });
    }

    /// The threads of this rank's particle loops over `points` points: those `--threads` set, or
    /// else this rank's share of the cores, as long as each thread gets at least
    /// [`POINTS_PER_THREAD`] points.
    pub fn threads_for(&self, points: usize) -> usize {
        if self.threads_set {
            self.threads
        } else {
            self.threads.min(points / POINTS_PER_THREAD).max(1)
        }
    }

    /// The communicator (for PETSc and for point-to-point exchanges).
    pub fn communicator(&self) -> &SimpleCommunicator {
        &self.world
    }

    /// This rank.
    pub fn rank(&self) -> usize {
        self.world.rank() as usize
    }

    /// Number of ranks.
    pub fn size(&self) -> usize {
        self.world.size() as usize
    }

    fn reduce(&self, v: &[f64], op: SystemOperation) -> Vec<f64> {
        let mut out = vec![0.0; v.len()];
        self.count(8 * v.len());
        if !v.is_empty() {
            self.world.all_reduce_into(v, &mut out[..], op);
        }
        out
    }

    /// Element-wise sum over ranks.
    pub fn sum(&self, v: &[f64]) -> Result<Vec<f64>, String> {
        Ok(self.reduce(v, SystemOperation::sum()))
    }

    /// Element-wise maximum over ranks.
    pub fn max(&self, v: &[f64]) -> Result<Vec<f64>, String> {
        Ok(self.reduce(v, SystemOperation::max()))
    }

    /// Element-wise minimum over ranks.
    pub fn min(&self, v: &[f64]) -> Result<Vec<f64>, String> {
        Ok(self.reduce(v, SystemOperation::min()))
    }

    /// Exact sum of counts over ranks.
    pub fn sum_count(&self, v: u64) -> u64 {
        let mut out = 0u64;
        self.count(8);
        self.world.all_reduce_into(&v, &mut out, SystemOperation::sum());
        out
    }

    /// Every rank's values concatenated in rank order, on every rank.
    pub fn gather(&self, v: &[f64]) -> Result<Vec<f64>, String> {
        Ok(self.gather_of(v))
    }

    /// Every rank's records (any MPI-equivalent type) concatenated in rank order, on every rank.
    pub fn gather_of<T: Equivalence + Default + Clone>(&self, v: &[T]) -> Vec<T> {
        let size = self.size();
        let n = v.len() as i32;
        let mut counts = vec![0i32; size];
        self.world.all_gather_into(&n, &mut counts[..]);
        let displs = displacements(&counts);
        let total: i32 = counts.iter().sum();
        self.count(4 * size + total as usize * std::mem::size_of::<T>());
        let mut out = vec![T::default(); total as usize];
        {
            let mut part = PartitionMut::new(&mut out[..], counts, displs);
            self.world.all_gather_varcount_into(v, &mut part);
        }
        out
    }

    /// A personalised all-to-all exchange: `outgoing[r]` goes to rank r (the entry for this rank is
    /// sent to itself); returns what every rank sent here, concatenated in rank order. Counts are
    /// exchanged first, so any rank may send to any other in one exchange (a particle that moved
    /// several subdomains in one step reaches its owner at once).
    pub fn exchange(&self, outgoing: &[Vec<f64>]) -> Vec<f64> {
        let size = self.size();
        assert_eq!(outgoing.len(), size, "one buffer per rank");
        let send_counts: Vec<i32> = outgoing.iter().map(|v| v.len() as i32).collect();
        let mut recv_counts = vec![0i32; size];
        self.world.all_to_all_into(&send_counts[..], &mut recv_counts[..]);
        let send: Vec<f64> = outgoing.concat();
        let send_displs = displacements(&send_counts);
        let recv_displs = displacements(&recv_counts);
        let mut recv = vec![0.0; recv_counts.iter().sum::<i32>() as usize];
        self.count(4 * size + 8 * recv.len());
        {
            let part = Partition::new(&send[..], &send_counts[..], &send_displs[..]);
            let mut into = PartitionMut::new(&mut recv[..], &recv_counts[..], &recv_displs[..]);
            self.world.all_to_all_varcount_into(&part, &mut into);
        }
        recv
    }

    /// Records of `stride` values whose first value is a unique non-negative integer key (a
    /// particle id), redistributed so that rank r holds the r-th slab of the list of all ranks'
    /// records sorted by key: keys in [r K/P, (r + 1) K/P) with K one more than the largest key, so
    /// every rank receives a share of about n/P records and no rank the whole list. Returns this
    /// rank's slab (sorted), its first position in the global list, and the number of records of
    /// all ranks. Collective; the global list does not depend on the number of ranks.
    pub fn sorted_slab(&self, records: &[f64], stride: usize) -> Slab {
        let size = self.size();
        let largest = records.chunks_exact(stride).map(|r| r[0]).fold(-1.0f64, f64::max);
        let keys = self.reduce(&[largest + 1.0], SystemOperation::max())[0].max(1.0);
        let mut outgoing = vec![Vec::new(); size];
        for r in records.chunks_exact(stride) {
            let to = ((r[0] / keys * size as f64) as usize).min(size - 1);
            outgoing[to].extend_from_slice(r);
        }
        let received = self.exchange(&outgoing);
        let mut rows: Vec<&[f64]> = received.chunks_exact(stride).collect();
        rows.sort_by(|a, b| a[0].total_cmp(&b[0]));
        let values: Vec<f64> = rows.concat();
        let n = (values.len() / stride) as u64;
        let mut counts = vec![0u64; size];
        self.count(8 * size);
        self.world.all_gather_into(&n, &mut counts[..]);
        let offset = counts[..self.rank()].iter().sum::<u64>() as usize;
        Slab { values, offset, total: counts.iter().sum::<u64>() as usize }
    }

    /// Whether any rank reports `flag`.
    pub fn any(&self, flag: bool) -> Result<bool, String> {
        let mine = flag as i32;
        let mut out = 0i32;
        self.count(4);
        self.world.all_reduce_into(&mine, &mut out, SystemOperation::max());
        Ok(out > 0)
    }

    /// Agreement on a local outcome: `Ok` on every rank if every rank is `Ok`; otherwise every rank
    /// returns the error of the lowest failing rank (prefixed with that rank on several ranks).
    pub fn agree<T>(&self, local: Result<T, String>) -> Result<T, String> {
        let mine = if local.is_err() { self.rank() as i32 } else { i32::MAX };
        let mut first = i32::MAX;
        self.count(4);
        self.world.all_reduce_into(&mine, &mut first, SystemOperation::min());
        if first == i32::MAX {
            return local;
        }
        let root = self.world.process_at_rank(first);
        let text = match (&local, self.rank() as i32 == first) {
            (Err(m), true) => m.clone(),
            _ => String::new(),
        };
        let mut len = text.len() as u64;
        root.broadcast_into(&mut len);
        let mut bytes = text.into_bytes();
        bytes.resize(len as usize, 0);
        root.broadcast_into(&mut bytes[..]);
        let msg = String::from_utf8_lossy(&bytes).into_owned();
        Err(if self.size() > 1 { format!("{msg} (rank {first})") } else { msg })
    }
}

/// One rank's part of a list distributed over the ranks ([`Collective::sorted_slab`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Slab {
    /// This rank's records, laid end to end.
    pub values: Vec<f64>,
    /// The position of its first record in the whole list.
    pub offset: usize,
    /// The number of records of all ranks.
    pub total: usize,
}

/// The offset of each part in a buffer of parts of `counts` values laid end to end.
fn displacements(counts: &[i32]) -> Vec<i32> {
    counts
        .iter()
        .scan(0i32, |acc, &n| {
            let d = *acc;
            *acc += n;
            Some(d)
        })
        .collect()
}
