//! The memory a run of a case takes, estimated from the case alone before anything is allocated:
//! its material points, the grid's vectors, the matrix of an implicit stage and, for a direct
//! solver, the factors. A run refuses to start when the part it cannot do without (everything but
//! the factors) does not fit in the memory the machine has available; `porompm check` prints the
//! whole estimate.

use crate::case::{AnalysisType, Case, Formulation, ShapeFunctions};

/// What every rank takes before the case's own data: PETSc, MPI, HDF5 and the program (measured:
/// 50–60 MiB for the smallest cases on one rank) [B].
pub const BASE_BYTES: f64 = 60.0 * 1024.0 * 1024.0;

/// A material point's state, stencil and the step's per-point data in two dimensions, measured
/// (peak memory of the shipped plane cases against their points: 6–9 kB) [B].
pub const POINT_BYTES_2D: f64 = 6.0e3;

/// The same in three dimensions for a two-phase case, with the solver's copies and hierarchies of
/// the matrix that the estimate's entries leave out (measured: the consolidating layer of
/// `cases/consolidation_layer_3d.toml` at n = 29, 195 112 points under the fixed-stress field
/// split, peaks at 1.30 GiB, 5.5 kB per point besides the libraries, matrix entries and grid
/// vectors) [B].
pub const POINT_BYTES_3D: f64 = 6.0e3;

/// The same in three dimensions for a one-phase case (measured: the square footing of
/// `tests/cases/footing_square_3d.toml` at k = 10, 262 144 points, its whole run on one rank with
/// `petsc_options/gamg-solid-multilinear.opts`, peaks at 1.63 GiB, 3.1 kB per point besides the
/// libraries, the estimate's matrix entries and grid vectors; the first four steps with
/// `gamg-solid-inexact.opts` 1.30 GiB) [B].
pub const POINT_BYTES_3D_ONE_PHASE: f64 = 4.5e3;

/// Vectors of the grid's dofs a step keeps (solution, residual, local copies, predictors,
/// projections, forces and reactions), 8 B each.
const GRID_VECTORS: f64 = 30.0;

/// Bytes per matrix entry: its value and column index, and the COO arrays it is built from.
const MATRIX_ENTRY_BYTES: f64 = 20.0;

/// The memory of a run of a case, estimated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Material points (exact, or for a very large case the sub-cell count of the bodies' boxes).
    pub points: f64,
    /// Grid dofs of the largest layout the case's stages take.
    pub grid_dofs: f64,
    /// Entries of the matrix (zero when every stage is explicit).
    pub matrix_entries: f64,
    /// The points, grid vectors and matrix, with one rank's [`BASE_BYTES`] [B].
    pub needed: f64,
    /// A direct solver's factors on top of `needed` (fill measured on the shipped cases: about 10
    /// times the matrix in two dimensions, 50 in three) [B].
    pub factors: f64,
}

impl Estimate {
    /// The estimate of `case`.
    pub fn of(case: &Case) -> Estimate {
        let dim = case.dimension();
        let cells: Vec<f64> = (0..dim).map(|d| case.grid.cells[d] as f64).collect();
        let nodes: f64 = cells.iter().map(|c| c + 1.0).product();
        let pore_water = case.analysis.formulation == Formulation::TwoPhase;
        // Unknowns per node of each stage (`Stage::layout`); the explicit ones form no matrix.
        let fbar = case.stabilisation.fbar;
        let per_node = |s: &crate::case::Stage| s.layout(pore_water, fbar).in_dim(dim).nd;
        let nd = case.stages.iter().map(per_node).max().unwrap_or(dim) as f64;
        let nd_matrix = case.stages.iter().filter(|s| s.analysis != AnalysisType::DynamicExplicit).map(per_node).max();
        let grid_dofs = nodes * nd;
        // How far a node's matrix row reaches at the start, in nodes per direction: a GIMP point
        // reaches the nodes of its own cell (those its domain only touches are left out), B̄ one
        // cell further; a B-spline of degree p reaches p + 1 nodes per direction. Points that
        // cross grid lines widen it during the run.
        let reach = match case.analysis.shape_functions {
            ShapeFunctions::Linear => 1.0,
            ShapeFunctions::Bspline2 => 2.0,
            ShapeFunctions::Bspline3 => 3.0,
            _ if case.stabilisation.bbar => 2.0,
            _ => 1.0,
        };
        let matrix_entries = match nd_matrix {
            Some(n) => nodes * n as f64 * (2.0f64 * reach + 1.0).powi(dim as i32) * n as f64,
            None => 0.0,
        };
        let points = points_of(case);
        let point_bytes = match (dim, pore_water) {
            (3, true) => POINT_BYTES_3D,
            (3, false) => POINT_BYTES_3D_ONE_PHASE,
            _ => POINT_BYTES_2D,
        };
        let needed =
            BASE_BYTES + points * point_bytes + grid_dofs * GRID_VECTORS * 8.0 + matrix_entries * MATRIX_ENTRY_BYTES;
        let fill = if dim == 3 { 50.0 } else { 10.0 };
        Estimate { points, grid_dofs, matrix_entries, needed, factors: matrix_entries * 12.0 * fill }
    }
}

/// The material points of `case`: counted where the bodies' boxes hold at most 5e7 candidate
/// places, otherwise the count of those places (an upper bound; such a case is refused on its
/// grid alone).
fn points_of(case: &Case) -> f64 {
    let dim = case.dimension();
    let h = case.cell_size_in::<3>();
    let boxes: f64 = case
        .bodies
        .iter()
        .map(|b| {
            if let Some(m) = b.shape.mesh() {
                return (m.mesh().cells() * m.mesh().points_per_cell(m.order)) as f64;
            }
            if let Some(p) = b.shape.points() {
                return p.cloud().len() as f64;
            }
            let (lo, hi) = b.shape.bounds();
            let depth = case.body_depth(b);
            let extent = [hi[0] - lo[0], hi[1] - lo[1], depth[1] - depth[0]];
            (0..dim).map(|d| (extent[d] / h[d]).ceil().max(1.0) * b.particles_per_cell as f64).product::<f64>()
        })
        .sum();
    if boxes > 5.0e7 {
        return boxes;
    }
    match dim {
        3 => counted::<3>(case),
        _ => counted::<2>(case),
    }
}

/// The material points of `case`, counted as [`super::particles::Particles::generate`] places them.
fn counted<const D: usize>(case: &Case) -> f64 {
    let grid = super::grid_of::<D>(case);
    let mut n = 0usize;
    for b in 0..case.bodies.len() {
        super::particles::for_each_point(case, &grid, b, |_| n += 1);
    }
    n as f64
}

impl Estimate {
    /// The line `porompm check` prints.
    pub fn line(&self) -> String {
        format!(
            "memory: about {} on one rank ({:.3e} material points, {:.3e} grid dofs, {:.3e} matrix entries); a \
             direct solver's factors about {} more",
            human(self.needed),
            self.points,
            self.grid_dofs,
            self.matrix_entries,
            human(self.factors)
        )
    }

    /// The refusal of a run that needs `need` [B] on a machine with `free` [B] available.
    pub fn refusal(&self, need: f64, free: f64) -> String {
        format!(
            "the case needs about {} of memory on this machine ({:.3e} material points, {:.3e} grid dofs, {:.3e} \
             matrix entries; `porompm check` shows the estimate) and it has {} available: coarsen the grid or run \
             on more machines",
            human(need),
            self.points,
            self.grid_dofs,
            self.matrix_entries,
            human(free)
        )
    }
}

/// `bytes` for a person: KiB, MiB or GiB with three figures.
pub fn human(bytes: f64) -> String {
    let units = [("GiB", 1u64 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)];
    for (name, size) in units {
        if bytes >= size as f64 {
            return format!("{:.3} {name}", bytes / size as f64);
        }
    }
    format!("{bytes:.0} B")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_estimate_counts_points_and_grows_with_the_grid() {
        let c = crate::validation::load(crate::case::tests_support::MINIMAL, "t", &[]).unwrap();
        let e = Estimate::of(&c);
        assert_eq!(e.points, 40.0);
        // Two-phase u–p–U in the plane: 5 dofs on each of 2 × 11 nodes.
        assert_eq!(e.grid_dofs, 110.0);
        assert!(e.needed > BASE_BYTES + 40.0 * POINT_BYTES_2D && e.needed < 2.0 * BASE_BYTES, "{}", human(e.needed));
        let big = crate::validation::load(
            crate::case::tests_support::MINIMAL,
            "t",
            &[crate::case::Override::parse("grid.cells=[4000,4000]").unwrap()],
        )
        .unwrap();
        // Quasi-static u–p: 3 dofs per node, and a GIMP point's row reaches the 3 × 3 nodes
        // around its node (B̄ off).
        let up = crate::validation::load(
            crate::case::tests_support::MINIMAL,
            "t",
            &[crate::case::Override::parse("stages.0.analysis=quasi_static").unwrap()],
        )
        .unwrap();
        let e = Estimate::of(&up);
        assert_eq!((e.grid_dofs, e.matrix_entries), (66.0, 66.0 * 9.0 * 3.0));
        let b = Estimate::of(&big);
        assert!(b.needed > 1e11, "a 4000 × 4000 grid needs over 100 GB: {}", human(b.needed));
        assert_eq!(human(1536.0), "1.500 KiB");
    }
}
