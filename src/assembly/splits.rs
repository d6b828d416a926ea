//! The named field splits of the block preconditioners.
//!
//! When the PETSc options choose `-pc_type fieldsplit` and define no splits of their own
//! (`-pc_fieldsplit_<n>_fields`), porompm defines two, by index sets, whatever the system:
//!
//! * `u`: every displacement dof, the solid's (ux, uy) and, in the u–p–U system, the water's
//!   (Ux, Uy) — kept in one block because the drag couples them strongly; the index set carries
//!   the node's displacement components as its block size (4 or 2), so BoomerAMG treats the
//!   components of a node together, and the rigid-body modes of the grid (two translations and
//!   the rotation, solid and water moving together) as its near-null space, which GAMG uses for
//!   its aggregates and BoomerAMG with nodal coarsening;
//! * `p`: the pore pressures.
//!
//! One options file (`-fieldsplit_u_*`, `-fieldsplit_p_*`) thus serves the u–p and the u–p–U
//! systems alike. PETSc 3.18's own DM splits lose the block size (see docs/solvers.md).
//!
//! A Schur-complement split of the dynamic u–p–U system whose options ask for a user-built Schur
//! preconditioner gets porompm's free-surface approximation, Sp = A_pp − A_pu B⁻¹ A_up −
//! c s² Σ (1 − n)² N V / K_dr: selfp with the exact inverse of A_uu over the aggregates of the
//! free-surface strip ([`super::aggregates`]) in place of its diagonal there, plus a share c of the
//! solid's fixed-stress term that grows with the step's Courant number (see
//! `pressure::fixed_stress_diagonal`). `-porompm_schur_strip_depth` (live pressure layers, 3;
//! 0 leaves selfp's diagonal everywhere), `-porompm_schur_strip_width` (nodes along the surface, 2)
//! and `-porompm_schur_fixed_stress_share` (c, in place of the rule) tune it.
//!
//! A Schur-complement split of the u–p system whose options ask for a user-built Schur
//! preconditioner (`-pc_fieldsplit_schur_precondition user`) gets porompm's fixed-stress
//! approximation, Sp = A_pp − s² M_L / K_dr (see `pressure::fixed_stress_diagonal`): the
//! pressure block of the tangent plus the lumped pressure mass over the skeleton's drained bulk
//! modulus, the volume change a pressure increment causes when the mean total stress is held
//! fixed. PETSc's `selfp` (A_pp − A_pu diag(A_uu)⁻¹ A_up) approximates that volume change through
//! the diagonal of the stiffness, which shrinks as h² under refinement, and its spectrum spreads
//! with the grid; the fixed-stress one does not (docs/solvers.md).

use crate::layout::Layout;
use crate::parallel::Collective;
use petsc::ksp::KspOps;
use petsc::{Comm, IndexSet, Options, SchurUser, Snes, VecOps, Vector};

/// Defines the splits `u` and `p` when the preconditioner is a field split of a system with a
/// pressure and the options define no splits themselves; otherwise does nothing. Returns the
/// user-built Schur preconditioner when the options ask for one (the caller fills it after each
/// Jacobian); that needs porompm's splits and the u–p system, and asking for it otherwise is an
/// error naming the option.
pub(super) fn define<const D: usize>(
    snes: &mut Snes,
    comm: Comm,
    coll: &Collective,
    layout: Layout,
    first_dof: usize,
    positions: &[[f64; D]],
) -> Result<Option<SchurUser>, petsc::Error> {
    let mut ksp = snes.ksp()?;
    let mut pc = ksp.pc()?;
    let user_schur = SchurUser::requested(&pc)?;
    let Some(p) = layout.p else { return Ok(None) };
    let own_splits = !user_defines_splits()?;
    if user_schur && !own_splits {
        return Err(petsc::Error::new(format!(
            "-{SCHUR_USER_OPTION} user (porompm's own Schur preconditioner) needs porompm's splits `u` and `p`; \
             this run defines its own -pc_fieldsplit_<n>_fields: use selfp"
        )));
    }
    if pc.type_name()? != "fieldsplit" || !own_splits {
        return Ok(None);
    }
    let nd = layout.nd;
    let displacement: Vec<usize> = (0..nd).filter(|&c| c != p).collect();
    let index = |cs: &[usize]| -> Vec<petsc::Int> {
        (0..positions.len()).flat_map(|a| cs.iter().map(move |&c| (first_dof + a * nd + c) as petsc::Int)).collect()
    };
    let mut u = IndexSet::new_general(comm, &index(&displacement))?;
    u.set_block_size(displacement.len())?;
    let modes = rigid_body_modes(comm, coll, displacement.len(), positions)?;
    u.compose_near_null_space(comm, &modes)?;
    let pressure = IndexSet::new_general(comm, &index(&[p]))?;
    pc.field_split_set_is("u", &u)?;
    pc.field_split_set_is("p", &pressure)?;
    if !user_schur {
        return Ok(None);
    }
    Ok(Some(if layout.w.is_some() {
        SchurUser::with_blocks(&pc, u, pressure)?
    } else {
        SchurUser::new(&pc, pressure)?
    }))
}

/// What a step's preparation computes for porompm's Schur preconditioner: its diagonal when there
/// is one, and the free-surface aggregates when it inverts blocks of A_uu (see
/// `assembly::pressure::fixed_stress_diagonal` and [`super::aggregates`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct SchurNeeds {
    /// The options ask for porompm's Schur preconditioner.
    pub schur: bool,
    /// It inverts A_uu's blocks over the free-surface aggregates (the u–p–U system's).
    pub blocks: bool,
    /// Its tuning.
    pub tuning: SchurTuning,
}

/// The tuning of porompm's Schur preconditioner of the u–p–U system (see the module documentation),
/// from the options database.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct SchurTuning {
    /// The free-surface aggregates' shape.
    pub strip: super::aggregates::StripShape,
    /// The share c of the solid's fixed-stress term, when the options set it (else the rule of
    /// `assembly::pressure::fixed_stress_share`).
    pub share: Option<f64>,
}

impl SchurTuning {
    /// Reads `-porompm_schur_strip_depth`, `-porompm_schur_strip_width` and
    /// `-porompm_schur_fixed_stress_share`; a value that does not parse, or a negative share, is
    /// an error naming the option.
    pub fn from_options() -> Result<SchurTuning, petsc::Error> {
        let options = Options::global();
        let read = |name: &str| -> Result<Option<f64>, petsc::Error> {
            match options.get_string(name)? {
                None => Ok(None),
                Some(v) => match v.trim().parse::<f64>() {
                    Ok(x) if x.is_finite() && x >= 0.0 => Ok(Some(x)),
                    _ => Err(petsc::Error::new(format!("{name} {v}: expected a number ≥ 0"))),
                },
            }
        };
        let mut t = SchurTuning::default();
        if let Some(d) = read("-porompm_schur_strip_depth")? {
            t.strip.depth = d as usize;
        }
        if let Some(w) = read("-porompm_schur_strip_width")? {
            t.strip.width = (w as usize).max(1);
        }
        t.share = read("-porompm_schur_fixed_stress_share")?;
        Ok(t)
    }
}

/// The rigid-body modes of the grid as the near-null space of a system whose unknowns are all
/// displacements (the one-phase solid, u; the two phases' motions, u–U), for the Jacobian itself
/// (`MatSetNearNullSpace`): GAMG then builds its aggregates from them whatever the options, as it
/// does for the `u` split of the coupled systems. Empty for a system with a pore pressure or a
/// projected volume ratio among its unknowns (their splits carry the modes, see [`define`]).
pub(super) fn displacement_near_null_space<const D: usize>(
    comm: Comm,
    coll: &Collective,
    layout: Layout,
    positions: &[[f64; D]],
) -> Result<Vec<Vector>, petsc::Error> {
    if layout.p.is_some() || layout.jbar.is_some() {
        return Ok(Vec::new());
    }
    rigid_body_modes(comm, coll, layout.nd, positions)
}

/// The PETSc option that chooses the Schur preconditioner (`user`: porompm's fixed-stress one).
const SCHUR_USER_OPTION: &str = "pc_fieldsplit_schur_precondition";

/// Whether the options database defines field splits by component lists.
fn user_defines_splits() -> Result<bool, petsc::Error> {
    Ok(Options::global().all()?.iter().any(|o| o.name.starts_with("pc_fieldsplit_") && o.name.ends_with("_fields")))
}

/// The orthonormal rigid-body modes of the grid for a block of `components` displacement dofs per
/// node (groups of D, solid then water) as PETSc vectors (collective; see [`rigid_body_mode_values`]).
fn rigid_body_modes<const D: usize>(
    comm: Comm,
    coll: &Collective,
    components: usize,
    positions: &[[f64; D]],
) -> Result<Vec<Vector>, petsc::Error> {
    let modes = rigid_body_mode_values(components, positions, |v| coll.sum(v)).map_err(petsc::Error::new)?;
    let n = positions.len() * components;
    modes
        .iter()
        .map(|m| {
            let mut v = Vector::new_mpi(comm, n as petsc::Int, petsc::DETERMINE)?;
            v.write()?.copy_from_slice(m);
            Ok(v)
        })
        .collect()
}

/// The values on this rank's `positions` of the orthonormal rigid-body modes of the grid for a
/// block of `components` displacement dofs per node (groups of D, solid then water): the
/// translations along each axis and the rotations about the nodes' centroid (about z in two
/// dimensions; about x, y and z in three), every group moving alike. `sum` adds values over the
/// ranks. The translations and rotations about the centroid are orthogonal; the three rotations of
/// a three-dimensional grid are orthonormalised among themselves (Gram–Schmidt, as PETSc's
/// `MatNullSpaceCreateRigidBody`).
fn rigid_body_mode_values<const D: usize>(
    components: usize,
    positions: &[[f64; D]],
    sum: impl Fn(&[f64]) -> Result<Vec<f64>, String>,
) -> Result<Vec<Vec<f64>>, String> {
    let mut local = vec![positions.len() as f64];
    local.extend((0..D).map(|d| positions.iter().map(|x| x[d]).sum::<f64>()));
    let sums = sum(&local)?;
    let centre: [f64; D] = std::array::from_fn(|d| sums[1 + d] / sums[0].max(1.0));
    let n = positions.len() * components;
    let groups = components / D;
    let values = |f: &dyn Fn([f64; D]) -> [f64; D]| -> Vec<f64> {
        let mut values = vec![0.0; n];
        for (a, x) in positions.iter().enumerate() {
            let d = f(std::array::from_fn(|c| x[c] - centre[c]));
            for k in 0..groups {
                values[a * components + D * k..a * components + D * (k + 1)].copy_from_slice(&d);
            }
        }
        values
    };
    let dot =
        |u: &[f64], v: &[f64]| -> Result<f64, String> { Ok(sum(&[u.iter().zip(v).map(|(a, b)| a * b).sum()])?[0]) };
    let mut modes: Vec<Vec<f64>> =
        (0..D).map(|t| values(&|_| std::array::from_fn(|c| if c == t { 1.0 } else { 0.0 }))).collect();
    // The rotation about axis a: ω × r with ω the unit vector of a (about z in the plane).
    let axes: &[usize] = if D == 2 { &[2] } else { &[0, 1, 2] };
    for &a in axes {
        let mut m = values(&|r| {
            let r3 = [r[0], r[1], if D == 3 { r[D - 1] } else { 0.0 }];
            let w = [f64::from(a == 0), f64::from(a == 1), f64::from(a == 2)];
            let c = [w[1] * r3[2] - w[2] * r3[1], w[2] * r3[0] - w[0] * r3[2], w[0] * r3[1] - w[1] * r3[0]];
            std::array::from_fn(|d| c[d])
        });
        for earlier in &modes[D..] {
            let along = dot(&m, earlier)?;
            for (x, e) in m.iter_mut().zip(earlier) {
                *x -= along * e;
            }
        }
        let norm = dot(&m, &m)?.sqrt();
        modes.push(m.iter().map(|x| x / norm).collect());
    }
    for m in modes.iter_mut().take(D) {
        let norm = dot(m, m)?.sqrt();
        m.iter_mut().for_each(|x| *x /= norm);
    }
    Ok(modes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The modes of a 3D grid block (solid and water groups) are orthonormal and rigid: each moves
    /// every pair of nodes without stretching the segment between them, (u_a − u_b)·(x_a − x_b) = 0
    /// (a rotation's sign or axis written wrongly stretches it), in each group alike.
    #[test]
    fn three_dimensional_rigid_body_modes_are_orthonormal_and_rigid() {
        let positions: Vec<[f64; 3]> = (0..27)
            .map(|i| [(i % 3) as f64 * 0.5 + 1.0, ((i / 3) % 3) as f64 * 0.25, (i / 9) as f64 * 0.4 - 2.0])
            .collect();
        let modes = rigid_body_mode_values(6, &positions, |v| Ok(v.to_vec())).unwrap();
        assert_eq!(modes.len(), 6);
        for (i, a) in modes.iter().enumerate() {
            for (j, b) in modes.iter().enumerate() {
                let d: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
                assert!((d - f64::from(i == j)).abs() < 1e-12, "modes {i}, {j}: {d}");
            }
            for g in [0, 3] {
                let u = |n: usize| [a[n * 6 + g], a[n * 6 + g + 1], a[n * 6 + g + 2]];
                for p in 0..positions.len() {
                    for q in 0..p {
                        let stretch: f64 =
                            (0..3).map(|c| (u(p)[c] - u(q)[c]) * (positions[p][c] - positions[q][c])).sum();
                        assert!(stretch.abs() < 1e-12, "mode {i} stretches ({p}, {q}) by {stretch}");
                    }
                }
            }
        }
        // The rotations are not the translations: each moves two nodes differently.
        assert!(modes[3..].iter().all(|m| (m[0] - m[6 * 26]).abs() + (m[1] - m[6 * 26 + 1]).abs() > 1e-3));
    }
}
