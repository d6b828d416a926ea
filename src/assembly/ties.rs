//! Rigid bodies under a force: the dofs of a body's nodes tied to one master dof per direction.
//!
//! A boundary with a `force` ties the displacement components it lists (and the water's it lists,
//! which then move with the body: impermeable there) to one unknown per direction, the master: the
//! solid dof in that direction of the tied node with the smallest global number, the same on every
//! rank. The global vector keeps its layout (one block of dofs per node): every tied dof stays an
//! unknown, and the equations are rewritten by rows, the master-slave elimination written without
//! renumbering:
//! * the master's row is the body's balance: the sum over all tied dofs of the direction, on every
//!   rank, of their residual rows (internal, inertia and external forces), minus the body's force
//!   (which [`add_forces`] puts at the master as an external load, so that schemes with a history
//!   of t_n weigh it as every other load);
//! * each other tied dof's row is x_s − x_m = 0 (unit diagonal, −1 in the master's column).
//!
//! An impermeable moving surface (a boundary's `impermeable` water components) is the same
//! rewriting within one node: its water row moves into the solid's row of its direction and
//! becomes U_d − u_d = 0, so that no water crosses the surface while it moves with the material.
//!
//! At convergence every tied dof moves as the master, the nodes' residual entries are the forces
//! the body exerts on the material (its reactions, [`super::forces`]), and they sum to its force.
//! The master may lie far from a rank's points: the ranks that do not ghost it name it by a
//! *virtual* ghosted index past their ghosted nodes ([`super::pattern::Pattern::tie`]), whose rows
//! and columns the matrix places by the master's global node number; the residual gathers the
//! sums and the master's value over all ranks with one reduction per evaluation.

use super::dofs::{DofMap, NO_TIE};
use super::pattern::{Pattern, PatternTies};
use crate::parallel::Collective;
use petsc::BlockFill;

/// Finds each rigid-body direction's master (the tied solid dof of the smallest global node
/// number over all ranks; `l2g` is the global index of every ghosted dof), where this rank ghosts
/// and owns it, and leaves the masters out of the owned tied dofs. A direction of an active rigid
/// body that ties no node is an error naming it. Collective.
pub(super) fn resolve(
    dofs: &mut DofMap,
    l2g: &[i32],
    boundary_name: impl Fn(usize) -> String,
    coll: &Collective,
) -> Result<(), String> {
    if dofs.ties.is_empty() {
        return Ok(());
    }
    let nd = dofs.nd;
    // Per direction, this rank's lowest tied node and its ghosted solid dof.
    let mut lowest = vec![(f64::INFINITY, 0); dofs.ties.len()];
    for (q, &g) in dofs.tie.iter().enumerate() {
        if g != NO_TIE && q % nd == dofs.ties[g as usize].dir {
            let node = (l2g[q] as usize / nd) as f64;
            if node < lowest[g as usize].0 {
                lowest[g as usize] = (node, q);
            }
        }
    }
    let global = coll.min(&lowest.iter().map(|l| l.0).collect::<Vec<_>>())?;
    for ((tie, &node), &(mine, q)) in dofs.ties.iter_mut().zip(&global).zip(&lowest) {
        if !node.is_finite() {
            return Err(format!(
                "boundary `{}` drives a rigid body under a force, but no grid node of it is tied in direction {} \
                 (the boundary holds no node of this stage's grid)",
                boundary_name(tie.boundary),
                ["x", "y", "z"][tie.dir]
            ));
        }
        tie.master_node = Some(node as i64);
        tie.master_local = (mine == node).then_some(q);
        tie.master_owned = dofs.owned_tied.iter().find(|&&(_, q)| Some(q) == tie.master_local).map(|&(o, _)| o);
    }
    let masters: Vec<usize> = dofs.ties.iter().filter_map(|t| t.master_local).collect();
    dofs.owned_tied.retain(|(_, q)| !masters.contains(q));
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
                let node = t.master_node.expect("a resolved master") as i32;
                let k = extra.iter().position(|&e| e == node).unwrap_or_else(|| {
                    extra.push(node);
                    extra.len() - 1
                });
                (ghosted + k) as u32
            }
        })
        .collect();
    let mut pairs: Vec<(u32, u32)> = dofs
        .tie
        .iter()
        .enumerate()
        .filter(|&(_, &g)| g != NO_TIE)
        .map(|(q, &g)| ((q / nd) as u32, masters[g as usize]))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    PatternTies { pairs, extra, masters }
}

/// The rows of a Jacobian that a step's ties rewrite: each moved row's blocks with their targets,
/// and each owned tied dof's constraint entries.
#[derive(Debug, Clone, Default)]
pub(super) struct TiedRows {
    /// (block (s, b), target block, component, target component) of every block of every moved
    /// row, in order: an impermeable surface's water rows into their own node's solid rows
    /// (block (s, b) itself), then each non-master rigid-body dof's row into its master's
    /// (block (m, b)), so that a followed solid row carries its water's on to a master.
    pub moves: Vec<(u32, u32, u8, u8)>,
    /// (block (s, s), block (s, m), component, master component) of every owned tied dof that is
    /// not a master (m = s for an impermeable surface's water): its row is x_s − x_m.
    pub constraints: Vec<(u32, u32, u8, u8)>,
}

impl TiedRows {
    /// The rows of `dofs`' ties in `pattern` (tied as [`pattern_ties`] says, its masters'
    /// indices); an error if the pattern lacks a block they need.
    pub fn of<const D: usize>(dofs: &DofMap, pattern: &Pattern<D>) -> Result<TiedRows, String> {
        let nd = dofs.nd;
        let masters = &pattern.ties.masters;
        let missing = || "a tied row's block is not in the matrix pattern".to_string();
        let mut rows = TiedRows::default();
        let mut move_row = |q: usize, m: u32, cm: usize| -> Result<(), String> {
            let s = (q / nd) as u32;
            for k in pattern.row_start(s)..pattern.row_start(s + 1) {
                let target = pattern.block(m, pattern.pairs[k].1).ok_or_else(missing)?;
                rows.moves.push((k as u32, target, (q % nd) as u8, cm as u8));
            }
            Ok(())
        };
        for &(q, solid) in &dofs.follows {
            move_row(q as usize, q / nd as u32, solid as usize % nd)?;
        }
        for (q, &g) in dofs.tie.iter().enumerate() {
            let tie = &dofs.ties.get(g as usize);
            let Some(tie) = tie.filter(|t| Some(q) != t.master_local) else { continue };
            move_row(q, masters[g as usize], tie.dir)?;
        }
        for &(_, solid, q) in &dofs.owned_follows {
            let s = (q / nd) as u32;
            let ss = pattern.block(s, s).ok_or_else(missing)?;
            rows.constraints.push((ss, ss, (q % nd) as u8, (solid % nd) as u8));
        }
        for &(_, q) in &dofs.owned_tied {
            let (s, g) = ((q / nd) as u32, dofs.tie[q] as usize);
            let (m, tie) = (masters[g], &dofs.ties[g]);
            let (ss, sm) = (pattern.block(s, s).ok_or_else(missing)?, pattern.block(s, m).ok_or_else(missing)?);
            rows.constraints.push((ss, sm, (q % nd) as u8, tie.dir as u8));
        }
        Ok(rows)
    }

    /// Rewrites the Jacobian's rows: moves each tied row into its target's and writes the
    /// constraints' entries (before PETSc's scaling of the pressure columns, which the moved rows
    /// then share with their targets).
    pub fn apply(&self, values: &mut BlockFill<'_>, nd: usize) {
        let mut row = [0.0; petsc::MAX_BS];
        for &(k, target, c, cm) in &self.moves {
            let from = values.row_mut(k as usize, c as usize);
            row[..nd].copy_from_slice(from);
            from.fill(0.0);
            values.row_mut(target as usize, cm as usize).iter_mut().zip(&row[..nd]).for_each(|(v, r)| *v += r);
        }
        for &(ss, sm, c, cm) in &self.constraints {
            values.row_mut(ss as usize, c as usize)[c as usize] = 1.0;
            values.row_mut(sm as usize, c as usize)[cm as usize] -= 1.0;
        }
    }
}

/// Adds `sign` times each rigid body's force at its master, on the rank that owns it, to `fext`
/// (t_{n+1}) and `fext_old` (t_n), per ghosted dof: with +1 an external load that the body's
/// balance (the master's row) carries; with −1 it is taken out again, since what acts on the
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
/// they are summed over ranks) into its direction's sum and zeroes it; after the sum over ranks
/// ([`finish_residual`]) the master's entry is the body's balance.
pub(super) fn gather_residual(dofs: &DofMap, fl: &mut [f64]) -> Vec<f64> {
    // An impermeable surface's water entries into their node's solid ones (which a rigid body may
    // then gather on).
    for &(q, solid) in &dofs.follows {
        fl[solid as usize] += fl[q as usize];
        fl[q as usize] = 0.0;
    }
    if dofs.ties.is_empty() {
        return Vec::new();
    }
    let mut sums = vec![0.0; 2 * dofs.ties.len()];
    for (v, &g) in fl.iter_mut().zip(&dofs.tie) {
        if g != NO_TIE {
            sums[g as usize] += *v;
            *v = 0.0;
        }
    }
    sums
}

/// Completes the residual `fo` (owned entries, summed over ranks) at the iterate `xo` from the
/// directions' `sums` of [`gather_residual`]: an impermeable surface's water entry is U_d − u_d,
/// the master's entry its direction's sum over all ranks, each other tied dof's x_s − x_m.
/// Collective where rigid bodies are.
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
    if dofs.ties.is_empty() {
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
    for &(o, q) in &dofs.owned_tied {
        fo[o] = xo[o] - sums[n + dofs.tie[q] as usize];
    }
    Ok(())
}
