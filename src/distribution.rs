//! Which rank holds which material point, and the migration of points to their owner after each
//! particle update.
//!
//! A material point belongs to the rank that owns the cell holding its centre, and a rank owns
//! cell (i, j) when it owns node (i, j) of the DMDA (the cell's lower-left node). The DMDA
//! distributes the nodes in a tensor grid of subdomains: `m` slabs along x and `n` along y, rank
//! r = a + b m holding slab a along x and slab b along y (PETSc's ordering). A point's stencil
//! (GIMP: the nodes within h + l_p of its centre; with B̄ the nodes of a neighbouring root cell) then
//! lies in its rank's ghost region of width three.
//!
//! After every accepted step the points whose centre left this rank's cells are packed into
//! records ([`crate::state::write_record`]: every per-point array, so stress, internal variables, F,
//! volumes, pressures and velocities move with them) and sent directly to their new owner in one
//! personalised all-to-all exchange, however far they moved. A rank's points are kept sorted by
//! id, so the order (and with it every sum over a rank's points) does not depend on how the
//! points arrived. The loads and moving surfaces that act on particular points are resolved again
//! from the case on the new set ([`crate::model::Model::resolve_targets`]): they depend only on
//! quantities that travel with the point (its body, its position and domain at t = 0).

use crate::case::Case;
use crate::model::grid::Grid;
use crate::model::Model;
use crate::parallel::Collective;
use crate::state::{particles_from_flat, record_len, write_record};

/// The load imbalance (the busiest rank's points over the mean) beyond which a run repartitions
/// the grid (`porompm run --balance-threshold`).
pub const DEFAULT_BALANCE_THRESHOLD: f64 = 1.2;

/// A repartition is made only if it lowers the imbalance by at least this factor; after one that
/// could not, the next attempt waits until the imbalance has grown by this factor.
pub const BALANCE_GAIN: f64 = 1.1;

/// The distribution of the grid's cells over ranks (two-dimensional unless `D` says otherwise).
#[derive(Debug, Clone, PartialEq)]
pub struct Owners<const D: usize = 2> {
    /// Along each direction, the first node layer of each slab and one past the last (length
    /// slabs + 1).
    starts: [Vec<usize>; D],
}

impl<const D: usize> Owners<D> {
    /// From the number of node layers each slab owns along each direction
    /// (`DMDAGetOwnershipRanges`).
    pub fn from_counts(counts: [&[usize]; D]) -> Owners<D> {
        let starts = counts.map(|c| {
            let mut v = vec![0];
            for &n in c {
                v.push(v.last().copied().unwrap_or(0) + n);
            }
            v
        });
        Owners { starts }
    }

    /// The number of node layers of each slab along each direction (the inverse of
    /// [`Owners::from_counts`]).
    pub fn counts_in(&self) -> [Vec<usize>; D] {
        std::array::from_fn(|d| self.starts[d].windows(2).map(|w| w[1] - w[0]).collect())
    }

    /// One rank owning everything.
    pub fn single(nodes: [usize; D]) -> Owners<D> {
        let counts = nodes.map(|n| vec![n]);
        Owners::from_counts(std::array::from_fn(|d| &counts[d][..]))
    }

    /// Number of ranks.
    pub fn ranks(&self) -> usize {
        self.starts.iter().map(|s| s.len() - 1).product()
    }

    /// The rank owning the cell with indices `c` (PETSc's ordering: x fastest, then y, then z).
    pub fn rank_of_cell_in(&self, c: [usize; D]) -> usize {
        let slab = |s: &[usize], k: usize| s[1..].partition_point(|&end| end <= k).min(s.len() - 2);
        (0..D).rev().fold(0, |acc, d| acc * (self.starts[d].len() - 1) + slab(&self.starts[d], c[d]))
    }

    /// The rank owning the cell that holds `x` (a centre outside the grid counts with the nearest
    /// cell: the grid-edge check stops such a run before it is mapped).
    pub fn rank_of(&self, grid: &Grid<D>, x: [f64; D]) -> usize {
        self.rank_of_cell_in(grid.nearest(x))
    }
}

/// The two-dimensional forms.
impl Owners {
    /// From the number of node columns and rows each slab owns.
    pub fn new(counts_x: &[usize], counts_y: &[usize]) -> Owners {
        Owners::from_counts([counts_x, counts_y])
    }

    /// The number of node columns and rows of each slab (the inverse of [`Owners::new`]).
    pub fn counts(&self) -> (Vec<usize>, Vec<usize>) {
        let [x, y] = self.counts_in();
        (x, y)
    }

    /// The rank owning cell (i, j).
    pub fn rank_of_cell(&self, i: usize, j: usize) -> usize {
        self.rank_of_cell_in([i, j])
    }
}

/// The load imbalance of a distribution of points: the largest count of a rank over the mean
/// (1 when balanced; 1 when there are no points).
pub fn imbalance(counts: &[f64]) -> f64 {
    let total: f64 = counts.iter().sum();
    if total <= 0.0 || counts.is_empty() {
        return 1.0;
    }
    counts.iter().copied().fold(0.0, f64::max) / (total / counts.len() as f64)
}

/// The load imbalance of the run's ranks holding `local` points each (collective; 1 on one rank).
pub fn imbalance_of(local: usize, coll: &Collective) -> Result<f64, String> {
    if coll.size() == 1 {
        return Ok(1.0);
    }
    Ok(imbalance(&coll.gather(&[local as f64])?))
}

/// A distribution of the cells over `ranks` ranks that balances the points, in any dimension:
/// `hist` holds the number of points per cell (x fastest: i + j nx [+ k nx ny], summed over
/// ranks). Every tensor grid of slabs m × n [× l] = ranks is tried (m, then n, ascending), its cuts
/// along each direction balancing the points per cell layer across that direction, and the one
/// whose busiest rank holds the fewest points is returned with its imbalance (the first of equals).
/// Every slab keeps at least `min_width` node layers (the DMDA's stencil width).
pub fn balanced<const D: usize>(
    hist: &[f64],
    cells: [usize; D],
    ranks: usize,
    min_width: usize,
) -> Option<(Owners<D>, f64)> {
    // The cell of flat index `c` (x fastest, `Grid::cell_number`).
    let cell = |c: usize| crate::model::grid::indices_of(cells, c);
    let mut layers: [Vec<f64>; D] = std::array::from_fn(|d| vec![0.0; cells[d]]);
    for (c, &w) in hist.iter().enumerate() {
        let at = cell(c);
        for d in 0..D {
            layers[d][at[d]] += w;
        }
    }
    let mut best: Option<(Owners<D>, f64)> = None;
    for split in splits::<D>(ranks) {
        let Some(counts) = (0..D).map(|d| cuts(&layers[d], split[d], min_width)).collect::<Option<Vec<_>>>() else {
            continue;
        };
        let owners = Owners::from_counts(std::array::from_fn(|d| &counts[d][..]));
        let mut per_rank = vec![0.0; ranks];
        for (c, &w) in hist.iter().enumerate() {
            per_rank[owners.rank_of_cell_in(cell(c))] += w;
        }
        let im = imbalance(&per_rank);
        if best.as_ref().is_none_or(|b| im < b.1) {
            best = Some((owners, im));
        }
    }
    best
}

/// Every way of writing `ranks` as a product of D slab counts, the first count ascending, then the
/// second.
fn splits<const D: usize>(ranks: usize) -> Vec<[usize; D]> {
    let divisors = |n: usize| (1..=n).filter(move |m| n.is_multiple_of(*m));
    let mut out = Vec::new();
    for m in divisors(ranks) {
        if D == 2 {
            out.push(std::array::from_fn(|d| if d == 0 { m } else { ranks / m }));
            continue;
        }
        for n in divisors(ranks / m) {
            out.push(std::array::from_fn(|d| [m, n, ranks / (m * n)][d]));
        }
    }
    out
}

/// Node counts of `k` slabs along one direction (cells `w.len()`, nodes one more) whose shares of
/// the weights `w` per cell are as equal as the cells allow, each at least `min_width` nodes; None
/// if the nodes are too few. One slab takes every node, however few (the DMDA asks for the
/// stencil width only of a direction it splits: a column one cell wide has two nodes across).
fn cuts(w: &[f64], k: usize, min_width: usize) -> Option<Vec<usize>> {
    let nodes = w.len() + 1;
    if k == 1 {
        return Some(vec![nodes]);
    }
    if k * min_width > nodes {
        return None;
    }
    let total: f64 = w.iter().sum();
    let mut cum = vec![0.0; w.len() + 1];
    for (i, x) in w.iter().enumerate() {
        cum[i + 1] = cum[i] + x;
    }
    let mut starts = vec![0usize];
    for a in 1..k {
        let target = total * a as f64 / k as f64;
        let lo = starts[a - 1] + min_width;
        let hi = nodes - (k - a) * min_width;
        // The cut (first node of slab a) whose cumulative weight is nearest the target.
        let c = (lo..=hi.min(w.len()))
            .min_by(|&p, &q| (cum[p] - target).abs().total_cmp(&(cum[q] - target).abs()).then(p.cmp(&q)))
            .unwrap_or(lo);
        starts.push(c);
    }
    starts.push(nodes);
    Some(starts.windows(2).map(|s| s[1] - s[0]).collect())
}

/// Sends every point of this rank whose centre lies in another rank's cells to that rank and takes
/// in the points sent here; collective (every rank calls it after the same step). The points stay
/// sorted by id and the case's point-wise loads and surfaces are resolved again on the new set.
/// Returns the number of points that left this rank.
pub fn migrate<const D: usize>(model: &mut Model<D>, case: &Case, owners: &Owners<D>, coll: &Collective) -> usize {
    let me = coll.rank();
    let size = coll.size();
    if size == 1 {
        return 0;
    }
    let ps = &model.particles;
    let len = record_len(D);
    let dest: Vec<usize> = (0..ps.len()).map(|k| owners.rank_of(&model.grid, ps.x[k])).collect();
    let mut outgoing = vec![Vec::new(); size];
    let mut sent = 0;
    let mut record = vec![0.0; len];
    for (k, &r) in dest.iter().enumerate() {
        if r != me {
            write_record(ps, k, &mut record);
            outgoing[r].extend_from_slice(&record);
            sent += 1;
        }
    }
    let arrived = coll.exchange(&outgoing);
    if sent == 0 && arrived.is_empty() {
        return 0;
    }
    let mut records: Vec<Vec<f64>> = (0..ps.len())
        .filter(|&k| dest[k] == me)
        .map(|k| {
            let mut r = vec![0.0; len];
            write_record(ps, k, &mut r);
            r
        })
        .collect();
    records.extend(arrived.chunks_exact(len).map(|c| c.to_vec()));
    records.sort_by(|a, b| a[0].total_cmp(&b[0]));
    model.particles = particles_from_flat(&records.concat());
    model.resolve_targets(case);
    sent
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_belong_to_the_slab_of_their_lower_left_node() {
        // 3 × 2 ranks over 10 × 7 nodes (9 × 6 cells).
        let o = Owners::new(&[4, 3, 3], &[4, 3]);
        assert_eq!(o.ranks(), 6);
        assert_eq!(o.rank_of_cell(0, 0), 0);
        assert_eq!(o.rank_of_cell(3, 3), 0);
        assert_eq!(o.rank_of_cell(4, 3), 1);
        assert_eq!(o.rank_of_cell(7, 0), 2);
        assert_eq!(o.rank_of_cell(8, 5), 5);
        assert_eq!(o.rank_of_cell(3, 4), 3);
        let g = Grid::new([0.0, 0.0], [1.0, 1.0], [9, 6]);
        assert_eq!(o.rank_of(&g, [4.5, 0.5]), 1);
        assert_eq!(o.rank_of(&g, [8.99, 6.0]), 5, "the top edge counts with the last cell");
        assert_eq!(o.rank_of(&g, [-0.5, -3.0]), 0, "outside: the nearest cell");
        assert_eq!(Owners::single([10, 7]).rank_of(&g, [8.5, 5.5]), 0);
        assert_eq!(o.counts(), (vec![4, 3, 3], vec![4, 3]));
    }

    #[test]
    fn a_crowded_corner_is_shared_out() {
        // 12 × 12 cells, every point in the 4 × 4 cells of the lower-left corner, 4 ranks.
        let cells = [12, 12];
        let mut hist = vec![0.0; 144];
        for j in 0..4 {
            for i in 0..4 {
                hist[i + 12 * j] = 4.0;
            }
        }
        let (o, im) = balanced(&hist, cells, 4, 2).unwrap();
        // PETSc's even split (7, 6 nodes each way) would put all 64 points on rank 0: imbalance 4.
        assert_eq!(imbalance(&[64.0, 0.0, 0.0, 0.0]), 4.0);
        assert!(im <= 1.0 + 1e-12, "imbalance {im} with {:?}", o.counts());
        let mut per = [0.0; 4];
        for j in 0..12 {
            for i in 0..12 {
                per[o.rank_of_cell(i, j)] += hist[i + 12 * j];
            }
        }
        assert_eq!(per, [16.0; 4]);
        let (cx, cy) = o.counts();
        assert_eq!(cx.iter().sum::<usize>(), 13);
        assert_eq!(cy.iter().sum::<usize>(), 13);
        assert!(cx.iter().chain(&cy).all(|&c| c >= 2));
    }

    /// In three dimensions: 8 × 8 × 8 cells with every point in the 4 × 4 × 2 cells of a corner and
    /// 4 ranks: PETSc's even split would give them all to one rank; the balanced split shares them
    /// out evenly (2 × 2 × 1 slabs), trying every m × n × l = 4.
    #[test]
    fn a_crowded_corner_is_shared_out_in_three_dimensions() {
        assert_eq!(splits::<3>(4), vec![[1, 1, 4], [1, 2, 2], [1, 4, 1], [2, 1, 2], [2, 2, 1], [4, 1, 1]]);
        assert_eq!(splits::<2>(6), vec![[1, 6], [2, 3], [3, 2], [6, 1]]);
        let cells = [8, 8, 8];
        let flat = |i: usize, j: usize, k: usize| i + 8 * (j + 8 * k);
        let mut hist = vec![0.0; 512];
        for k in 0..2 {
            for j in 0..4 {
                for i in 0..4 {
                    hist[flat(i, j, k)] = 3.0;
                }
            }
        }
        let (o, im) = balanced(&hist, cells, 4, 2).unwrap();
        assert!(im <= 1.0 + 1e-12, "imbalance {im} with {:?}", o.counts_in());
        let mut per = [0.0; 4];
        for (c, &w) in hist.iter().enumerate() {
            per[o.rank_of_cell_in([c % 8, (c / 8) % 8, c / 64])] += w;
        }
        assert_eq!(per, [24.0; 4]);
        assert!(o.counts_in().iter().all(|c| c.iter().sum::<usize>() == 9 && c.iter().all(|&n| n >= 2)));
    }

    #[test]
    fn slabs_keep_the_stencil_width_and_too_few_nodes_give_none() {
        // All the weight in one cell: the cuts cannot split it, every slab keeps two nodes.
        let w = [0.0, 0.0, 9.0, 0.0, 0.0, 0.0];
        let c = cuts(&w, 3, 2).unwrap();
        assert_eq!(c.iter().sum::<usize>(), 7);
        assert!(c.iter().all(|&n| n >= 2), "{c:?}");
        assert!(cuts(&w, 4, 2).is_none(), "4 slabs of 2 nodes need 8 nodes");
        assert_eq!(cuts(&[1.0], 1, 3), Some(vec![2]), "one slab of a column one cell wide");
        // Uniform weights over 9 cells: 4 and 5 cells (the last slab also holds the last node).
        let even = cuts(&[1.0; 9], 2, 2).unwrap();
        assert!(even == vec![4, 6] || even == vec![5, 5], "{even:?}");
        assert_eq!(imbalance(&[]), 1.0);
    }
}
