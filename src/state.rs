//! Checkpoints: everything the next step of a run depends on, so that a run restarted from a
//! checkpoint ends with the same fields as the uninterrupted run (to round-off).
//!
//! The state is: every particle array (including the soil model's internal variables, which are
//! the stress and ε_p^d, and the Newmark velocities and accelerations of both phases), the time,
//! the step count, the index of the stage, the step control's Δt and its count of accepted steps
//! since Δt last changed, the run's counters, each load's sum of increments, and what each of the
//! run's recorders has gathered (the probes' excess-pressure extremes, the largest diagnostics so
//! far, the verification check's state if it can keep one; see
//! `crate::recorders::Recorder::state`). Everything else (grid, loads, boundaries, matrices) is
//! rebuilt from the case.
//!
//! A checkpoint names its case by a fingerprint of the validated case without its `[output]` table
//! (output intervals may differ between the runs), and carries a checksum of its content. Reading
//! and writing the file is [`crate::io::checkpoint`]'s job; this module is pure.

use crate::case::Case;
use crate::model::particles::Particles;

/// Version of the checkpoint layout; a file of another version is refused.
pub const FORMAT_VERSION: u64 = 10;

/// The particle arrays of a checkpoint of points in `dim` dimensions: (name, components), in the
/// order of [`write_record`]: `dim` components per vector, dim² for F (row by row), six stresses.
pub fn particle_fields(dim: usize) -> [(&'static str, usize); 22] {
    let (v, f) = (dim, dim * dim);
    [
        ("id", 1),
        ("body", 1),
        ("material", 1),
        ("x", v),
        ("x0", v),
        ("disp", v),
        ("lp", v),
        ("lp0", v),
        ("def_grad", f),
        ("volume", 1),
        ("porosity", 1),
        ("mass", 1),
        ("vel", v),
        ("acc", v),
        ("vel_w", v),
        ("acc_w", v),
        ("stress", 6),
        ("p", 1),
        ("p0", 1),
        ("eps_pd", 1),
        ("grad_p", v),
        ("jbar", 1),
    ]
}

/// Values per particle record in two dimensions (the sum of [`particle_fields`]`(2)`'s components).
pub const RECORD: usize = 40;

/// `summary.json`'s `restarted_from`: the checkpoint a run continued from.
#[derive(Debug, Clone, serde::Serialize)]
pub struct RestartInfo {
    /// The checkpoint file, as given.
    pub checkpoint: String,
    /// Its time [s].
    pub time_s: f64,
    /// Its step count.
    pub step: usize,
    /// What the restarted run could not restore, if anything.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// The state of a run after an accepted step.
#[derive(Debug, Clone, PartialEq)]
pub struct Checkpoint {
    /// [`case_fingerprint`] of the case that wrote it.
    pub case_fingerprint: u64,
    /// Simulated time [s].
    pub time: f64,
    /// Accepted steps so far.
    pub step: u64,
    /// Index of the stage the run was in.
    pub stage: u64,
    /// The step control's current Δt [s].
    pub dt: f64,
    /// Accepted steps since Δt last changed.
    pub successes: u64,
    /// Step cuts, Newton iterations, Krylov iterations and matrix-structure reuses so far.
    pub counters: [u64; 5],
    /// The recorders' states, each under its name (`crate::recorders::Recorder::state`; a
    /// recorder that keeps none is absent).
    pub recorders: Vec<(String, Vec<f64>)>,
    /// Each load's factor reached so far, in case order (what a load with an `increment_factor`
    /// has summed; see [`crate::model::loads::Increments`]).
    pub load_totals: Vec<f64>,
    /// The dimension of the run's points (2 or 3): a record holds [`record_len`]`(dim)` values.
    pub dim: usize,
    /// This rank's slab of the particle records ([`write_record`]) of all ranks sorted by id, laid
    /// end to end: records `first .. first + n` of `total` (every rank writes and reads its own
    /// slab; [`Checkpoint::records`]).
    pub particles: Vec<f64>,
    /// The position of this rank's first record in the id-sorted list.
    pub first: u64,
    /// The number of records of all ranks.
    pub total: u64,
}

/// FNV-1a, 64 bit.
struct Fnv(u64);

impl Fnv {
    fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 ^= x as u64;
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn u64(&mut self, v: u64) {
        self.bytes(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.u64(v.to_bits());
    }
}

/// A fingerprint of the case as validated (after `--set` overrides), without its `[output]` table.
pub fn case_fingerprint(case: &Case) -> u64 {
    let mut c = case.file().clone();
    c.output = Default::default();
    let text = serde_json::to_string(&c).unwrap_or_default();
    let mut h = Fnv::new();
    h.bytes(text.as_bytes());
    h.0
}

/// Refuses a checkpoint written by another case (or with other `--set` values).
pub fn check_case(cp: &Checkpoint, case: &Case) -> Result<(), String> {
    let fp = case_fingerprint(case);
    if cp.case_fingerprint != fp {
        return Err(format!(
            "it was written by a different case or other --set values (case fingerprint {:016x}, this run {fp:016x})",
            cp.case_fingerprint
        ));
    }
    if cp.stage as usize >= case.stages.len() || cp.load_totals.len() != case.loads.len() {
        return Err("its stage or loads do not match the case".into());
    }
    if cp.dim != case.dimension() {
        return Err(format!("its points are {}-dimensional, this case's {}-dimensional", cp.dim, case.dimension()));
    }
    Ok(())
}

/// Values per particle record in `d` dimensions: [`RECORD`] in two, and in three the third
/// component of every position, domain, velocity and pressure gradient and the 3 × 3 deformation
/// gradient (55).
pub const fn record_len(d: usize) -> usize {
    RECORD + (d - 2) * 15
}

/// The records of all points of `ps`, laid end to end in their order ([`record_len`]`(D)` values
/// each; [`particles_from_flat`]'s inverse).
pub fn records_of<const D: usize>(ps: &Particles<D>) -> Vec<f64> {
    let len = record_len(D);
    let mut flat = vec![0.0; ps.len() * len];
    for (k, r) in flat.chunks_exact_mut(len).enumerate() {
        write_record(ps, k, r);
    }
    flat
}

/// Writes the record of particle `k` of dimension D into `r` ([`record_len`] values, in the order
/// of [`particle_fields`]`(D)`: D components per vector and D² for F, row by row; ids are exact in
/// f64, they stay below 2⁵³).
pub fn write_record<const D: usize>(ps: &Particles<D>, k: usize, r: &mut [f64]) {
    let f = &ps.def_grad[k];
    let f_rows: Vec<f64> = f.iter().flatten().copied().collect();
    let parts: [&[f64]; 22] = [
        &[ps.id[k] as f64],
        &[ps.body[k] as f64],
        &[ps.material[k] as f64],
        &ps.x[k],
        &ps.x0[k],
        &ps.disp[k],
        &ps.lp[k],
        &ps.lp0[k],
        &f_rows,
        &[ps.volume[k]],
        &[ps.porosity[k]],
        &[ps.mass[k]],
        &ps.vel[k],
        &ps.acc[k],
        &ps.vel_w[k],
        &ps.acc_w[k],
        &ps.stress[k],
        &[ps.p[k]],
        &[ps.p0[k]],
        &[ps.eps_pd[k]],
        &ps.grad_p[k],
        &[ps.jbar[k]],
    ];
    let mut i = 0;
    for p in parts {
        r[i..i + p.len()].copy_from_slice(p);
        i += p.len();
    }
}

/// A particle field read from the values of a record, in order.
trait FromValues {
    fn take(rest: &mut impl Iterator<Item = f64>) -> Self;
}

impl FromValues for f64 {
    fn take(rest: &mut impl Iterator<Item = f64>) -> f64 {
        rest.next().expect("RECORD values")
    }
}

impl<T: FromValues, const N: usize> FromValues for [T; N] {
    fn take(rest: &mut impl Iterator<Item = f64>) -> [T; N] {
        std::array::from_fn(|_| T::take(rest))
    }
}

/// Overwrites particle `k` with record `r` (same id, body and material, checked by the caller).
fn unpack<const D: usize>(ps: &mut Particles<D>, k: usize, r: &[f64]) {
    let rest = &mut r[3..].iter().copied();
    // The fields after id, body and material, in the order of `particle_fields`.
    macro_rules! read {
        ($($field:ident),*) => { $(ps.$field[k] = FromValues::take(rest);)* };
    }
    read!(
        x, x0, disp, lp, lp0, def_grad, volume, porosity, mass, vel, acc, vel_w, acc_w, stress, p, p0, eps_pd, grad_p,
        jbar
    );
}

/// The points of dimension D of the records laid end to end in `flat` ([`record_len`] values
/// each), in their order.
pub fn particles_from_flat<const D: usize>(flat: &[f64]) -> Particles<D> {
    let mut ps = Particles::default();
    for r in flat.chunks_exact(record_len(D)) {
        ps.push_blank(r[0] as u64, r[1] as u16, r[2] as u16);
        let k = ps.len() - 1;
        unpack(&mut ps, k, r);
    }
    ps.shrink_to_fit();
    ps
}

/// Whether the records of a checkpoint (a slab of the id-sorted list, [`record_len`]`(dim)` values
/// each, laid end to end) are the case's points `generated` (`[id, body, material]`, the same slab
/// of the case's points as generated): the same ids, each of the same body and material.
pub fn check_points(records: &[f64], dim: usize, generated: &[[f64; 3]]) -> Result<(), String> {
    let records: Vec<&[f64]> = records.chunks_exact(record_len(dim)).collect();
    for (r, g) in records.iter().zip(generated) {
        if r[0] != g[0] {
            let id = r[0].min(g[0]) as u64;
            return Err(format!("material point {id} is in only one of the case and the checkpoint"));
        }
        if r[1] != g[1] || r[2] != g[2] {
            return Err(format!("material point {} belongs to another body or material in it", g[0] as u64));
        }
    }
    if records.len() != generated.len() {
        return Err("its material points are not those of this case".into());
    }
    Ok(())
}

impl Checkpoint {
    /// This rank's records, [`record_len`]`(dim)` values each.
    pub fn records(&self) -> std::slice::ChunksExact<'_, f64> {
        self.particles.chunks_exact(record_len(self.dim))
    }

    /// This rank's share of the particles' checksum: the wrapping sum over its records of a hash of
    /// each record's position in the id-sorted list and its values. The shares of all ranks add up
    /// (wrapping) to the same sum whatever the number of ranks; a swapped or changed record changes it.
    pub fn records_hash(&self) -> u64 {
        self.records().enumerate().fold(0u64, |sum, (k, r)| {
            let mut h = Fnv::new();
            h.u64(self.first + k as u64);
            for &v in r {
                h.f64(v);
            }
            sum.wrapping_add(h.0)
        })
    }

    /// The checksum of the content (stored with the file and verified on reading), given the
    /// [`Checkpoint::records_hash`] summed over all ranks.
    pub fn checksum(&self, records_hash: u64) -> u64 {
        let mut h = Fnv::new();
        h.u64(FORMAT_VERSION);
        h.u64(self.case_fingerprint);
        h.f64(self.time);
        h.u64(self.step);
        h.u64(self.stage);
        h.f64(self.dt);
        h.u64(self.successes);
        for c in self.counters {
            h.u64(c);
        }
        h.u64(self.recorders.len() as u64);
        for (name, state) in &self.recorders {
            h.bytes(name.as_bytes());
            h.u64(state.len() as u64);
            for &v in state {
                h.f64(v);
            }
        }
        h.u64(self.load_totals.len() as u64);
        for &v in &self.load_totals {
            h.f64(v);
        }
        h.u64(self.total);
        h.u64(records_hash);
        h.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn particles() -> (Case, Particles) {
        let c = crate::validation::load(crate::case::tests_support::MINIMAL, "t", &[]).unwrap();
        let g = crate::model::grid_of(&c);
        let ps = Particles::generate(&c, &g, |_| true);
        (c, ps)
    }

    #[test]
    fn records_round_trip_every_particle_array() {
        assert_eq!(particle_fields(2).iter().map(|f| f.1).sum::<usize>(), RECORD);
        assert_eq!(particle_fields(3).iter().map(|f| f.1).sum::<usize>(), record_len(3));
        let (_, mut ps) = particles();
        // Give every array a distinct value so that a swapped slot would show.
        let k = 3;
        let mut v = 0.5;
        let mut next = || {
            v += 1.25;
            v
        };
        ps.x[k] = [next(), next()];
        ps.x0[k] = [next(), next()];
        ps.disp[k] = [next(), next()];
        ps.lp[k] = [next(), next()];
        ps.lp0[k] = [next(), next()];
        ps.def_grad[k] = [[next(), next()], [next(), next()]];
        ps.volume[k] = next();
        ps.porosity[k] = next();
        ps.mass[k] = next();
        ps.vel[k] = [next(), next()];
        ps.acc[k] = [next(), next()];
        ps.vel_w[k] = [next(), next()];
        ps.acc_w[k] = [next(), next()];
        ps.stress[k] = std::array::from_fn(|_| next());
        ps.p[k] = next();
        ps.p0[k] = next();
        ps.eps_pd[k] = next();
        ps.grad_p[k] = [next(), next()];
        ps.jbar[k] = next();
        let flat = records_of(&ps);
        let back = particles_from_flat::<2>(&flat);
        assert_eq!(format!("{back:?}"), format!("{ps:?}"));
        // The case's points, as generated, against the checkpoint's.
        let (_, fresh) = particles();
        let generated: Vec<[f64; 3]> =
            (0..fresh.len()).map(|k| [fresh.id[k] as f64, fresh.body[k] as f64, fresh.material[k] as f64]).collect();
        check_points(&flat, 2, &generated).unwrap();
        assert!(check_points(&flat, 2, &generated[1..]).unwrap_err().contains("material point 0 is in only one"));
        assert!(check_points(&flat[..39 * RECORD], 2, &generated).unwrap_err().contains("not those of this case"));
        let mut other = generated.clone();
        other[3][1] = 1.0;
        assert!(check_points(&flat, 2, &other).unwrap_err().contains("another body"));
    }

    /// Three-dimensional records ([`record_len`]`(3)` = 55 values) hold every array with its z
    /// components and the 3 × 3 F.
    #[test]
    fn three_dimensional_records_round_trip_every_particle_array() {
        let c =
            crate::validation::load(&crate::case::tests_support::with_grid("[0.2, 1.0, 0.3]", "[2, 10, 3]"), "t", &[])
                .unwrap();
        let mut ps = Particles::<3>::generate(&c, &crate::model::grid_of(&c), |_| true);
        let mut v = 0.5;
        let mut next = || {
            v += 1.25;
            v
        };
        for k in [0, 7] {
            for a in [&mut ps.x, &mut ps.x0, &mut ps.disp, &mut ps.lp, &mut ps.lp0, &mut ps.vel, &mut ps.acc] {
                a[k] = std::array::from_fn(|_| next());
            }
            for a in [&mut ps.vel_w, &mut ps.acc_w, &mut ps.grad_p] {
                a[k] = std::array::from_fn(|_| next());
            }
            ps.def_grad[k] = std::array::from_fn(|_| std::array::from_fn(|_| next()));
            ps.stress[k] = std::array::from_fn(|_| next());
            for a in [&mut ps.volume, &mut ps.porosity, &mut ps.mass, &mut ps.p, &mut ps.p0, &mut ps.eps_pd] {
                a[k] = next();
            }
            ps.jbar[k] = next();
        }
        let len = record_len(3);
        let flat = records_of(&ps);
        assert_eq!(flat[len + 3..len + 6], ps.x[1]);
        let back = particles_from_flat::<3>(&flat);
        assert_eq!(format!("{back:?}"), format!("{ps:?}"));
        let generated: Vec<[f64; 3]> =
            (0..ps.len()).map(|k| [ps.id[k] as f64, ps.body[k] as f64, ps.material[k] as f64]).collect();
        check_points(&flat, 3, &generated).unwrap();
        assert!(check_points(&flat, 2, &generated).is_err(), "read as plane records");
    }

    #[test]
    fn the_checksum_and_the_fingerprint_see_every_change() {
        let (c, ps) = particles();
        let cp = Checkpoint {
            case_fingerprint: case_fingerprint(&c),
            time: 0.25,
            step: 7,
            stage: 0,
            dt: 1e-3,
            successes: 2,
            counters: [1, 2, 3, 4, 5],
            recorders: vec![("diagnostics".into(), vec![0.1]), ("check".into(), vec![2.0])],
            load_totals: vec![0.5],
            dim: 2,
            particles: records_of(&ps),
            first: 0,
            total: ps.len() as u64,
        };
        let sum = |c: &Checkpoint| c.checksum(c.records_hash());
        let mut other = cp.clone();
        other.particles[5 * RECORD + 32] += 1e-12;
        assert_ne!(sum(&cp), sum(&other));
        let mut other = cp.clone();
        let (third, fourth) = other.particles.split_at_mut(4 * RECORD);
        third[3 * RECORD..].swap_with_slice(&mut fourth[..RECORD]);
        assert_ne!(sum(&cp), sum(&other), "records in another order");
        let mut other = cp.clone();
        other.recorders.pop();
        assert_ne!(sum(&cp), sum(&other), "a recorder's state dropped");
        let mut other = cp.clone();
        other.recorders[1].0 = "checks".into();
        assert_ne!(sum(&cp), sum(&other), "a recorder's state under another name");
        // Split into two slabs (two ranks), the shares add up to the whole's.
        let (mut a, mut b) = (cp.clone(), cp.clone());
        a.particles.truncate(15 * RECORD);
        b.particles.drain(..15 * RECORD);
        b.first = 15;
        assert_eq!(a.records_hash().wrapping_add(b.records_hash()), cp.records_hash());
        // The output table does not change the fingerprint; the physics does.
        let set = |s: &str| {
            let sets = [crate::case::Override::parse(s).unwrap()];
            crate::validation::load(crate::case::tests_support::MINIMAL, "t", &sets).unwrap()
        };
        assert_eq!(case_fingerprint(&c), cp.case_fingerprint);
        assert_eq!(case_fingerprint(&set("output.history_every=5")), cp.case_fingerprint);
        assert_ne!(case_fingerprint(&set("time.dt=2e-3")), cp.case_fingerprint);
    }
}
