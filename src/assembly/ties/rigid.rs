//! The motion of a rigid body and the choice of its master dofs (pure functions).
//!
//! A rigid body's small motion is u(x) = t + ω × (x − x_F): a translation t of the point x_F where
//! its force acts and, for a body that rotates, a rotation ω about it (about z alone in the
//! plane). Its parameters p are the translations along the directions it ties and, if it
//! rotates, the rotations; a tied dof of component d at x moves as T_d(x) · p ([`motion_row`]).
//! The masters are tied solid dofs whose values fix every parameter that moves a tied dof:
//! Gaussian elimination over all the body's tied solid dofs, column by column (translations
//! first), takes as each column's pivot the dof with the largest remaining entry (ties: the lowest
//! key), and leaves out a column with none (a rotation its tied components do not see). With T_M
//! the masters' rows in the pivot columns J, p_J = T_M⁻¹ u_M, and a tied dof moves as
//! u_s = T_s,J T_M⁻¹ u_M: its weights ([`Selection::weights`]). By virtual work the masters carry
//! the generalized forces f_M = T_M⁻ᵀ g_J of the body's load g (its force on the translations,
//! nothing on the rotations about x_F).

/// One parameter of a rigid body's motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Param {
    /// The translation along a direction (0: x, 1: y, 2: z).
    Translation(usize),
    /// The rotation about an axis (0: x, 1: y, 2: z; in the plane z alone).
    Rotation(usize),
}

impl Param {
    /// Its slot in a body's motion record: translations at 0..3, rotations at 3..6.
    pub fn slot(&self) -> usize {
        match *self {
            Param::Translation(d) => d,
            Param::Rotation(a) => 3 + a,
        }
    }
}

/// The most parameters a body has (three translations and three rotations).
pub const MAX_PARAMS: usize = 6;

/// The entries of T_d(x) for `params`: how component `dir` of a point at `r` = x − x_F moves with
/// each parameter (u = t + ω × r).
pub fn motion_row(params: &[Param], dir: usize, r: [f64; 3]) -> [f64; MAX_PARAMS] {
    let mut row = [0.0; MAX_PARAMS];
    for (v, p) in row.iter_mut().zip(params) {
        *v = match *p {
            Param::Translation(d) => (d == dir) as u8 as f64,
            // (e_a × r)_dir: e_x × r = (0, −r_z, r_y), e_y × r = (r_z, 0, −r_x), e_z × r = (−r_y, r_x, 0).
            Param::Rotation(a) => {
                let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                if dir == b {
                    -r[c]
                } else if dir == c {
                    r[b]
                } else {
                    0.0
                }
            }
        };
    }
    row
}

/// A candidate master: a tied solid dof, named by its `key` (the same on every rank), with its
/// component and its position relative to the force's point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// A number that orders the dofs the same way on every rank (node × 8 + component).
    pub key: f64,
    /// Its component (direction).
    pub dir: usize,
    /// x − x_F [m].
    pub r: [f64; 3],
}

/// The masters of a rigid body and how its motion follows from them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Selection {
    /// The masters (indices into the candidates), one per pivot column.
    pub masters: Vec<usize>,
    /// The parameters the masters fix (indices into the body's parameters), in the masters'
    /// order.
    pub columns: Vec<usize>,
    /// T_M⁻¹, row j for column j: p_J = T_M⁻¹ u_M.
    pub inverse: Vec<[f64; MAX_PARAMS]>,
}

/// The relative size below which a column's remaining entries count as zero.
const PIVOT_TOLERANCE: f64 = 1e-9;

/// Chooses a body's masters among its `candidates` (sorted by key, each once) for `params`;
/// `length` scales the rotation columns (the body's size) so that the tolerance is relative.
pub fn select(params: &[Param], candidates: &[Candidate], length: f64) -> Selection {
    let n = params.len();
    let scale = |j: usize| if matches!(params[j], Param::Rotation(_)) { 1.0 / length } else { 1.0 };
    let mut rows: Vec<[f64; MAX_PARAMS]> = candidates
        .iter()
        .map(|c| {
            let mut row = motion_row(params, c.dir, c.r);
            (0..n).for_each(|j| row[j] *= scale(j));
            row
        })
        .collect();
    let mut used = vec![false; rows.len()];
    let mut sel = Selection::default();
    for j in 0..n {
        let mut pivot: Option<usize> = None;
        for i in (0..rows.len()).filter(|&i| !used[i]) {
            if pivot.is_none_or(|p| rows[i][j].abs() > rows[p][j].abs()) {
                pivot = Some(i);
            }
        }
        let Some(p) = pivot.filter(|&p| rows[p][j].abs() > PIVOT_TOLERANCE) else { continue };
        used[p] = true;
        let prow = rows[p];
        for row in rows.iter_mut().zip(&used).filter(|(_, &u)| !u).map(|(r, _)| r) {
            let f = row[j] / prow[j];
            row.iter_mut().zip(&prow).for_each(|(v, pv)| *v -= f * pv);
        }
        sel.masters.push(p);
        sel.columns.push(j);
    }
    let tm: Vec<[f64; MAX_PARAMS]> = sel
        .masters
        .iter()
        .map(|&m| {
            let row = motion_row(params, candidates[m].dir, candidates[m].r);
            std::array::from_fn(|k| sel.columns.get(k).map_or(0.0, |&j| row[j]))
        })
        .collect();
    sel.inverse = invert(&tm);
    sel
}

impl Selection {
    /// The weights of a tied dof of component `dir` at `r` = x − x_F: u_s = Σ_k w_k u_{M_k}.
    pub fn weights(&self, params: &[Param], dir: usize, r: [f64; 3]) -> [f64; MAX_PARAMS] {
        let row = motion_row(params, dir, r);
        let n = self.columns.len();
        std::array::from_fn(
            |k| if k < n { (0..n).map(|j| row[self.columns[j]] * self.inverse[j][k]).sum() } else { 0.0 },
        )
    }

    /// The generalized forces f_M = T_M⁻ᵀ g_J at the masters of a load `g` on the parameters.
    pub fn master_forces(&self, g: &[f64]) -> Vec<f64> {
        let n = self.columns.len();
        (0..n).map(|k| (0..n).map(|j| self.inverse[j][k] * g[self.columns[j]]).sum()).collect()
    }

    /// The parameters' increments (in the parameters' order, zero for those the masters do not
    /// fix) from the masters' increments `du`.
    pub fn motion(&self, params: &[Param], du: &[f64]) -> Vec<f64> {
        let mut p = vec![0.0; params.len()];
        for (j, &c) in self.columns.iter().enumerate() {
            p[c] = self.inverse[j].iter().zip(du).map(|(a, b)| a * b).sum();
        }
        p
    }
}

/// The inverse of a small square matrix (Gauss–Jordan with partial pivoting; rows of
/// [`MAX_PARAMS`] entries, the first `a.len()` used). The matrix is non-singular by construction
/// (its rows are [`select`]'s pivots).
fn invert(a: &[[f64; MAX_PARAMS]]) -> Vec<[f64; MAX_PARAMS]> {
    let n = a.len();
    let mut m = a.to_vec();
    let mut inv: Vec<[f64; MAX_PARAMS]> = (0..n).map(|i| std::array::from_fn(|k| (i == k) as u8 as f64)).collect();
    for c in 0..n {
        let p = (c..n).max_by(|&i, &k| m[i][c].abs().total_cmp(&m[k][c].abs())).expect("a row");
        m.swap(c, p);
        inv.swap(c, p);
        let d = m[c][c];
        m[c].iter_mut().for_each(|v| *v /= d);
        inv[c].iter_mut().for_each(|v| *v /= d);
        for i in (0..n).filter(|&i| i != c) {
            let f = m[i][c];
            let (mc, ic) = (m[c], inv[c]);
            m[i].iter_mut().zip(&mc).for_each(|(v, x)| *v -= f * x);
            inv[i].iter_mut().zip(&ic).for_each(|(v, x)| *v -= f * x);
        }
    }
    inv
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Candidates of the components `dirs` at `points` relative to `point`, keyed in the order
    /// given.
    fn candidates(points: &[[f64; 3]], dirs: &[usize], point: [f64; 3]) -> Vec<Candidate> {
        let mut c = Vec::new();
        for (i, x) in points.iter().enumerate() {
            for &d in dirs {
                let r = std::array::from_fn(|k| x[k] - point[k]);
                c.push(Candidate { key: (i * 8 + d) as f64, dir: d, r });
            }
        }
        c
    }

    /// In translation the masters are each direction's lowest node, every dof's weight is 1 on
    /// its direction's master, and the load and the motion are the masters' own.
    #[test]
    fn a_body_in_translation_has_a_master_per_direction() {
        let params = [Param::Translation(0), Param::Translation(1)];
        let c = candidates(&[[0.0, 1.0, 0.0], [0.5, 1.0, 0.0], [1.0, 1.0, 0.0]], &[0, 1], [0.0; 3]);
        let sel = select(&params, &c, 1.0);
        assert_eq!(sel.masters, vec![0, 1]);
        assert_eq!(sel.columns, vec![0, 1]);
        assert_eq!(sel.weights(&params, 1, [0.7, 1.0, 0.0])[..2], [0.0, 1.0]);
        assert_eq!(sel.master_forces(&[3.0, -5.0]), vec![3.0, -5.0]);
        assert_eq!(sel.motion(&params, &[0.1, -0.2]), vec![0.1, -0.2]);
    }

    /// A smooth strip tying u_y that rotates about its force's point: its masters are the lowest
    /// node's u_y and the farthest node's; a dof's weights interpolate linearly between them; an
    /// eccentric force splits between them by the lever rule; a uniform settlement is no tilt.
    #[test]
    fn a_strip_that_tilts_interpolates_between_its_end_nodes() {
        let params = [Param::Translation(1), Param::Rotation(2)];
        let xs: Vec<[f64; 3]> = (0..5).map(|i| [i as f64, 2.0, 0.0]).collect();
        let point = [1.0, 2.0, 0.0];
        let c = candidates(&xs, &[1], point);
        let sel = select(&params, &c, 4.0);
        assert_eq!(sel.masters, vec![0, 4]);
        for x in [0.0, 1.5, 2.0, 4.0] {
            let w = sel.weights(&params, 1, [x - 1.0, 0.0, 0.0]);
            assert!((w[0] - (4.0 - x) / 4.0).abs() < 1e-15 && (w[1] - x / 4.0).abs() < 1e-15, "{x}: {w:?}");
        }
        let f = sel.master_forces(&[-10.0, 0.0]);
        assert!((f[0] + 7.5).abs() < 1e-14 && (f[1] + 2.5).abs() < 1e-14, "{f:?}");
        let p = sel.motion(&params, &[-1.0, -1.0]);
        assert!((p[0] + 1.0).abs() < 1e-15 && p[1].abs() < 1e-15, "{p:?}");
        let p = sel.motion(&params, &[0.0, 0.4]);
        assert!((p[1] - 0.1).abs() < 1e-15 && (p[0] - 0.1).abs() < 1e-15, "{p:?}");
    }

    /// A plate in three dimensions tying every component: six masters, and any small rigid motion
    /// of its masters is every dof's to round-off.
    #[test]
    fn a_plate_in_three_dimensions_carries_every_rigid_motion() {
        let params: Vec<Param> = (0..3).map(Param::Translation).chain((0..3).map(Param::Rotation)).collect();
        let xs: Vec<[f64; 3]> = (0..9).map(|i| [(i % 3) as f64 * 0.5, 1.0, (i / 3) as f64 * 0.5]).collect();
        let point = [0.4, 1.0, 0.7];
        let c = candidates(&xs, &[0, 1, 2], point);
        let sel = select(&params, &c, 1.4);
        assert_eq!(sel.columns, vec![0, 1, 2, 3, 4, 5]);
        let p = [0.01, -0.02, 0.03, 0.004, -0.005, 0.006];
        let u =
            |cand: &Candidate| motion_row(&params, cand.dir, cand.r).iter().zip(&p).map(|(a, b)| a * b).sum::<f64>();
        let um: Vec<f64> = sel.masters.iter().map(|&m| u(&c[m])).collect();
        for cand in &c {
            let w = sel.weights(&params, cand.dir, cand.r);
            let from: f64 = w.iter().zip(&um).map(|(a, b)| a * b).sum();
            assert!((from - u(cand)).abs() < 1e-15, "{cand:?}: {from} against {}", u(cand));
        }
        let back = sel.motion(&params, &um);
        assert!(back.iter().zip(&p).all(|(a, b)| (a - b).abs() < 1e-15), "{back:?}");
    }

    /// What the tied components do not see is left out: a plate tying only its normal component
    /// tilts about x and z but does not twist about its normal; a strip of nodes on one vertical
    /// line tying u_y does not turn.
    #[test]
    fn a_rotation_the_tied_components_do_not_see_is_left_out() {
        let params: Vec<Param> = [Param::Translation(1)].into_iter().chain((0..3).map(Param::Rotation)).collect();
        let xs: Vec<[f64; 3]> = (0..9).map(|i| [(i % 3) as f64, 0.0, (i / 3) as f64]).collect();
        let sel = select(&params, &candidates(&xs, &[1], [1.0, 0.0, 1.0]), 2.0);
        assert_eq!(sel.columns, vec![0, 1, 3]);
        let params = [Param::Translation(1), Param::Rotation(2)];
        let xs: Vec<[f64; 3]> = (0..4).map(|i| [2.0, i as f64, 0.0]).collect();
        let sel = select(&params, &candidates(&xs, &[1], [0.0; 3]), 3.0);
        assert_eq!((sel.masters, sel.columns), (vec![0], vec![0]));
    }
}
