//! Rigid bodies under a force: the dofs of a body's nodes tied to a few master dofs.
//!
//! A boundary with a `force` ties the displacement components it lists (and the water's it lists,
//! which then move with the body: impermeable there) to the body's motion: a translation along
//! each listed direction and, where the force has a point of application, a small rotation about
//! that point ([`rigid`]). The motion's parameters are carried by masters, tied solid dofs chosen
//! the same on every rank (for a body in translation, the dof of each direction at the tied node
//! with the smallest global number), and each tied dof moves as a weighted sum of the masters,
//! x_s = Σ_k w_sk x_k (in translation its direction's master alone, with weight 1). The global
//! vector keeps its layout (one block of dofs per node): every tied dof stays an unknown, and the
//! equations are rewritten by rows, the master-slave elimination written without renumbering:
//! * master k's row is the body's balance for its parameter: the sum over all tied dofs, on every
//!   rank, of w_sk times their residual rows (internal, inertia and external forces), minus the
//!   body's load carried at k (which [`add_forces`] puts at the master as an external load, so
//!   that schemes with a history of t_n weigh it as every other load);
//! * each other tied dof's row is x_s − Σ_k w_sk x_k = 0.
//!
//! An impermeable moving surface (a boundary's `impermeable` water components) is the same
//! rewriting within one node: its water row moves into the solid's row of its direction and
//! becomes U_d − u_d = 0, so that no water crosses the surface while it moves with the material.
//!
//! At convergence every tied dof moves with the body, the nodes' residual entries are the forces
//! the body exerts on the material (its reactions, [`super::forces`]), they sum to its force, and
//! for a body that rotates their moment about the force's point is zero. A master may lie far
//! from a rank's points: the ranks that do not ghost it name it by a
//! *virtual* ghosted index past their ghosted nodes ([`super::pattern::Pattern::tie`]), whose rows
//! and columns the matrix places by the master's global node number; the residual gathers the
//! sums and the master's value over all ranks with one reduction per evaluation.

pub mod rigid;

use super::dofs::DofMap;
use super::pattern::{Pattern, PatternTies};
use crate::parallel::Collective;
use petsc::BlockFill;
use rigid::{Candidate, Param, MAX_PARAMS};

/// Chooses each rigid body's masters ([`rigid::select`] over the tied solid dofs of every rank,
/// gathered), where this rank ghosts and owns them, each tied dof's weights and each master's
/// share of the body's load, and leaves the masters out of the owned tied dofs. `l2g` is the
/// global index of every ghosted dof, `position` the coordinates of a ghosted node. An error names
/// a body that ties no node, or whose force turns it about an axis its tied components do not
/// resist. Collective.
pub(super) fn resolve(
    dofs: &mut DofMap,
    l2g: &[i32],
    position: impl Fn(usize) -> [f64; 3],
    boundary_name: impl Fn(usize) -> String,
    coll: &Collective,
) -> Result<(), String> {
    if dofs.bodies.is_empty() {
        return Ok(());
    }
    let nd = dofs.nd;
    let key = |q: usize| (l2g[q] as usize / nd * 8 + q % nd) as f64;
    // Every rank's tied solid dofs: (key, body, position), sorted by body and key, each once.
    let mut mine = Vec::new();
    for t in dofs.tied.iter().filter(|t| t.solid) {
        let (q, x) = (t.q as usize, position(t.q as usize / nd));
        mine.extend([t.body as f64, key(q), t.dir as f64, x[0], x[1], x[2]]);
    }
    let mut all: Vec<[f64; 6]> = coll.gather(&mine)?.chunks_exact(6).map(|c| std::array::from_fn(|k| c[k])).collect();
    all.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    all.dedup_by(|a, b| a[..2] == b[..2]);
    for (i, body) in dofs.bodies.iter_mut().enumerate() {
        let name = || boundary_name(body.boundary);
        let rel = |x: &[f64]| std::array::from_fn(|d| x[d] - body.point[d]);
        let candidates: Vec<Candidate> = all
            .iter()
            .filter(|c| c[0] == i as f64)
            .map(|c| Candidate { key: c[1], dir: c[2] as usize, r: rel(&c[3..]) })
            .collect();
        if candidates.is_empty() {
            return Err(format!(
                "boundary `{}` drives a rigid body under a force, but no grid node of it is tied (the boundary \
                 holds no node of this stage's grid)",
                name()
            ));
        }
        let length = body_length(&candidates);
        let sel = rigid::select(&body.params, &candidates, length);
        // The load on each parameter at t_{n+1} and t_n: the force on the translations, nothing on
        // the rotations about the force's point.
        let g: [Vec<f64>; 2] = [0, 1].map(|s| {
            body.params.iter().map(|p| if let Param::Translation(d) = *p { body.force[s][d] } else { 0.0 }).collect()
        });
        let loads = [&g[0], &g[1]].map(|g| sel.master_forces(g));
        for (g, f) in g.iter().zip(&loads) {
            unresisted(&body.params, &sel, &candidates, g, f, length)
                .map_err(|what| format!("boundary `{}`: its force {what}", name()))?;
        }
        let start = dofs.ties.len();
        for (k, &m) in sel.masters.iter().enumerate() {
            let c = &candidates[m];
            let q = dofs.tied.iter().find(|t| t.solid && key(t.q as usize) == c.key).map(|t| t.q as usize);
            let tie = super::dofs::Tie {
                body: i,
                dir: c.dir,
                master_node: (c.key as usize / 8) as i64,
                master_local: q,
                master_owned: q.and_then(|q| {
                    dofs.owned_tied.iter().find(|&&(_, t)| dofs.tied[t].q as usize == q).map(|&(o, _)| o)
                }),
                force: [loads[0][k], loads[1][k]],
            };
            dofs.ties.push(tie);
        }
        body.masters = start..dofs.ties.len();
        body.selection = sel;
    }
    for t in &mut dofs.tied {
        let body = &dofs.bodies[t.body as usize];
        // A master moves as itself, exactly (its row stays its own in the Jacobian).
        let own = body.masters.clone().find(|&k| dofs.ties[k].master_local == Some(t.q as usize));
        t.w = match own {
            Some(k) => std::array::from_fn(|i| (i == k - body.masters.start) as u8 as f64),
            None => {
                let x = position(t.q as usize / nd);
                body.selection.weights(&body.params, t.dir as usize, std::array::from_fn(|d| x[d] - body.point[d]))
            }
        };
    }
    let masters: Vec<usize> = dofs.ties.iter().filter_map(|t| t.master_local).collect();
    let tied = &dofs.tied;
    dofs.owned_tied.retain(|&(_, t)| !masters.contains(&(tied[t].q as usize)));
    Ok(())
}

/// A body's size: the largest distance of its candidates from the first (1 m for a single node),
/// which scales its rotations.
fn body_length(candidates: &[Candidate]) -> f64 {
    let first = candidates[0].r;
    let far =
        candidates.iter().map(|c| (0..3).map(|d| (c.r[d] - first[d]).powi(2)).sum::<f64>().sqrt()).fold(0.0, f64::max);
    if far > 0.0 {
        far
    } else {
        1.0
    }
}

/// Whether the body's load `g` does work on a motion its masters do not carry: a parameter left
/// out of the selection (a rotation the tied components do not see) whose load differs from what
/// the masters' loads `f` do on it (the force's moment about the tied nodes when they cannot
/// turn). An error says which.
fn unresisted(
    params: &[Param],
    sel: &rigid::Selection,
    candidates: &[Candidate],
    g: &[f64],
    f: &[f64],
    length: f64,
) -> Result<(), String> {
    let scale = g.iter().map(|v| v.abs()).fold(0.0, f64::max) * length;
    for (j, p) in params.iter().enumerate().filter(|(j, _)| !sel.columns.contains(j)) {
        let done: f64 = sel
            .masters
            .iter()
            .zip(f)
            .map(|(&m, fk)| fk * rigid::motion_row(params, candidates[m].dir, candidates[m].r)[j])
            .sum();
        if (g[j] - done).abs() > 1e-9 * scale.max(f64::MIN_POSITIVE) {
            let axis = match p {
                Param::Rotation(a) => ["x", "y", "z"][*a],
                Param::Translation(d) => ["x", "y", "z"][*d],
            };
            return Err(format!(
                "turns the body about {axis} (a moment of {:.6e} N m, per metre in the plane, about its tied nodes), \
                 which its tied components do not resist: tie the components that do, or put `force_point` where \
                 the force's line of action meets the body",
                g[j] - done
            ));
        }
    }
    Ok(())
}

/// The [`PatternTies`] of `dofs` on a rank with `ghosted` ghosted nodes.
pub(super) fn pattern_ties(dofs: &DofMap, ghosted: usize) -> PatternTies {
    let nd = dofs.nd;
    let mut extra: Vec<i32> = Vec::new();
    let masters: Vec<u32> = dofs
        .ties
        .iter()
        .map(|t| match t.master_local {
            Some(q) => (q / nd) as u32,
            None => {
                let node = t.master_node as i32;
                let k = extra.iter().position(|&e| e == node).unwrap_or_else(|| {
                    extra.push(node);
                    extra.len() - 1
                });
                (ghosted + k) as u32
            }
        })
        .collect();
    let mut pairs: Vec<(u32, u32)> = dofs
        .tied
        .iter()
        .flat_map(|t| dofs.bodies[t.body as usize].masters.clone().map(move |k| (t.q / nd as u32, k)))
        .map(|(s, k)| (s, masters[k]))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    PatternTies { pairs, extra, masters }
}

/// The rows of a Jacobian that a step's ties rewrite: each moved row's blocks with their targets,
/// and each owned tied dof's constraint entries.
#[derive(Debug, Clone, Default)]
pub(super) struct TiedRows {
    /// Every block of every moved row with each of its targets, in order: an impermeable
    /// surface's water rows into their own node's solid rows (block (s, b) itself, weight 1), then
    /// each non-master rigid-body dof's row into each of its masters' (block (m, b), its weight),
    /// so that a followed solid row carries its water's on to its masters. A block's first target
    /// reads and zeroes it; the others add the copy.
    pub moves: Vec<Move>,
    /// (block (s, s), component) of every owned tied dof that is not a master and of every
    /// following water dof: its row's unit diagonal.
    pub diagonals: Vec<(u32, u8)>,
    /// (block (s, m), component, master component, weight) of the same rows: x_s − Σ w x_m (m = s
    /// for an impermeable surface's water, weight 1).
    pub constraints: Vec<(u32, u8, u8, f64)>,
}

/// One block of a moved row and where it goes ([`TiedRows::moves`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Move {
    /// The block of the row.
    pub from: u32,
    /// The target block.
    pub to: u32,
    /// The row's component and the target's.
    pub c: u8,
    /// The target row's component.
    pub cm: u8,
    /// The weight the row takes into the target.
    pub w: f64,
    /// Whether this is the row's first target (the row is read and zeroed there).
    pub first: bool,
}

impl TiedRows {
    /// The rows of `dofs`' ties in `pattern` (tied as [`pattern_ties`] says, its masters'
    /// indices); an error if the pattern lacks a block they need.
    pub fn of<const D: usize>(dofs: &DofMap, pattern: &Pattern<D>) -> Result<TiedRows, String> {
        let nd = dofs.nd;
        let masters = &pattern.ties.masters;
        let missing = || "a tied row's block is not in the matrix pattern".to_string();
        let mut rows = TiedRows::default();
        // Row q's blocks into each (master node, component, weight) of `targets`.
        let mut move_row = |q: usize, targets: &[(u32, usize, f64)]| -> Result<(), String> {
            let s = (q / nd) as u32;
            for k in pattern.row_start(s)..pattern.row_start(s + 1) {
                for (i, &(m, cm, w)) in targets.iter().enumerate() {
                    let to = pattern.block(m, pattern.pairs[k].1).ok_or_else(missing)?;
                    rows.moves.push(Move { from: k as u32, to, c: (q % nd) as u8, cm: cm as u8, w, first: i == 0 });
                }
            }
            Ok(())
        };
        for &(q, solid) in &dofs.follows {
            move_row(q as usize, &[(q / nd as u32, solid as usize % nd, 1.0)])?;
        }
        let is_master = |q: usize| dofs.ties.iter().any(|t| t.master_local == Some(q));
        for t in dofs.tied.iter().filter(|t| !is_master(t.q as usize)) {
            let targets = master_weights(dofs, t, masters);
            move_row(t.q as usize, &targets)?;
        }
        for &(_, solid, q) in &dofs.owned_follows {
            let s = (q / nd) as u32;
            let ss = pattern.block(s, s).ok_or_else(missing)?;
            rows.diagonals.push((ss, (q % nd) as u8));
            rows.constraints.push((ss, (q % nd) as u8, (solid % nd) as u8, 1.0));
        }
        for &(_, i) in &dofs.owned_tied {
            let t = &dofs.tied[i];
            let s = t.q / nd as u32;
            let c = (t.q as usize % nd) as u8;
            rows.diagonals.push((pattern.block(s, s).ok_or_else(missing)?, c));
            for (m, cm, w) in master_weights(dofs, t, masters) {
                rows.constraints.push((pattern.block(s, m).ok_or_else(missing)?, c, cm as u8, w));
            }
        }
        Ok(rows)
    }

    /// Rewrites the Jacobian's rows: moves each tied row into its targets' (weighted) and writes
    /// the constraints' entries (before PETSc's scaling of the pressure columns, which the moved
    /// rows then share with their targets).
    pub fn apply(&self, values: &mut BlockFill<'_>, nd: usize) {
        let mut row = [0.0; petsc::MAX_BS];
        for m in &self.moves {
            if m.first {
                let from = values.row_mut(m.from as usize, m.c as usize);
                row[..nd].copy_from_slice(from);
                from.fill(0.0);
            }
            let to = values.row_mut(m.to as usize, m.cm as usize);
            to.iter_mut().zip(&row[..nd]).for_each(|(v, r)| *v += m.w * r);
        }
        for &(ss, c) in &self.diagonals {
            values.row_mut(ss as usize, c as usize)[c as usize] = 1.0;
        }
        for &(sm, c, cm, w) in &self.constraints {
            values.row_mut(sm as usize, c as usize)[cm as usize] -= w;
        }
    }
}

/// The (master node in the pattern, master component, weight) of each of a tied dof's masters
/// with a non-zero weight.
fn master_weights(dofs: &DofMap, t: &super::dofs::Tied, masters: &[u32]) -> Vec<(u32, usize, f64)> {
    let body = &dofs.bodies[t.body as usize];
    body.masters.clone().zip(&t.w).filter(|(_, &w)| w != 0.0).map(|(k, &w)| (masters[k], dofs.ties[k].dir, w)).collect()
}

/// Adds `sign` times each rigid body's load at its masters, on the rank that owns them, to `fext`
/// (t_{n+1}) and `fext_old` (t_n), per ghosted dof: with +1 an external load that the body's
/// balance (the masters' rows) carries; with −1 it is taken out again, since what acts on the
/// material there is the body's reaction.
pub(super) fn add_forces(dofs: &DofMap, sign: f64, fext: &mut [f64], fext_old: &mut [f64]) {
    for tie in dofs.ties.iter().filter(|t| t.master_owned.is_some()) {
        let q = tie.master_local.expect("an owned master is ghosted");
        fext[q] += sign * tie.force[0];
        fext_old[q] += sign * tie.force[1];
    }
}

/// Rewrites a residual for the ties: moves an impermeable surface's water entries into their
/// node's solid ones, then takes every tied ghosted dof's entry of this rank's shares `fl` (before
/// they are summed over ranks), weighted, into its masters' sums and zeroes it; after the sum over
/// ranks ([`finish_residual`]) a master's entry is the body's balance for its parameter.
pub(super) fn gather_residual(dofs: &DofMap, fl: &mut [f64]) -> Vec<f64> {
    // An impermeable surface's water entries into their node's solid ones (which a rigid body may
    // then gather on).
    for &(q, solid) in &dofs.follows {
        fl[solid as usize] += fl[q as usize];
        fl[q as usize] = 0.0;
    }
    if dofs.bodies.is_empty() {
        return Vec::new();
    }
    let mut sums = vec![0.0; 2 * dofs.ties.len()];
    for t in &dofs.tied {
        let v = std::mem::take(&mut fl[t.q as usize]);
        let masters = dofs.bodies[t.body as usize].masters.clone();
        sums[masters.clone()].iter_mut().zip(&t.w).for_each(|(s, w)| *s += w * v);
    }
    sums
}

/// Completes the residual `fo` (owned entries, summed over ranks) at the iterate `xo` from the
/// masters' `sums` of [`gather_residual`]: an impermeable surface's water entry is U_d − u_d, a
/// master's entry its sum over all ranks, each other tied dof's x_s − Σ_k w_sk x_k. Collective
/// where rigid bodies are.
pub(super) fn finish_residual(
    dofs: &DofMap,
    mut sums: Vec<f64>,
    xo: &[f64],
    fo: &mut [f64],
    coll: &Collective,
) -> Result<(), String> {
    for &(o, solid, _) in &dofs.owned_follows {
        fo[o] = xo[o] - xo[solid];
    }
    if dofs.bodies.is_empty() {
        return Ok(());
    }
    let n = dofs.ties.len();
    for (g, tie) in dofs.ties.iter().enumerate() {
        if let Some(o) = tie.master_owned {
            sums[n + g] = xo[o];
        }
    }
    let sums = coll.sum(&sums)?;
    for (g, tie) in dofs.ties.iter().enumerate() {
        if let Some(o) = tie.master_owned {
            fo[o] = sums[g];
        }
    }
    for &(o, i) in &dofs.owned_tied {
        let t = &dofs.tied[i];
        let masters = dofs.bodies[t.body as usize].masters.clone();
        fo[o] = xo[o] - sums[n + masters.start..n + masters.end].iter().zip(&t.w).map(|(x, w)| w * x).sum::<f64>();
    }
    Ok(())
}

/// Each rigid body's motion over a step from its masters' increments `du` (per ghosted dof; this
/// rank's owned masters only, to be summed over ranks): per body the six slots of
/// [`Param::slot`] (translations of the force's point, then rotations).
pub(super) fn motions(dofs: &DofMap, du: &[f64]) -> Vec<(usize, [f64; MAX_PARAMS])> {
    dofs.bodies
        .iter()
        .map(|body| {
            let owned: Vec<f64> = body
                .masters
                .clone()
                .map(|k| dofs.ties[k].master_owned.map_or(0.0, |_| du[dofs.ties[k].master_local.expect("ghosted")]))
                .collect();
            let p = body.selection.motion(&body.params, &owned);
            let mut slots = [0.0; MAX_PARAMS];
            body.params.iter().zip(&p).for_each(|(param, v)| slots[param.slot()] = *v);
            (body.boundary, slots)
        })
        .collect()
}
