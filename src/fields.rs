//! The fields written to `fields.h5`/`fields.xdmf` at an output time, each rank's share of them
//! (all ranks write the file together through [`crate::io::fields`]).
//!
//! Particle fields, sorted by particle id: the records are redistributed so that each rank holds
//! one slab of the sorted list ([`Collective::sorted_slab`]), which it writes at its place in the
//! file; the file does not depend on the number of ranks. The fields: `position` and `displacement` [m], `velocity` [m/s]
//! (3 components, z = 0), the effective stress components `stress_xx`, `stress_yy`, `stress_xy`,
//! `stress_zz` [Pa] (tension positive; total stress in one-phase runs), the mean effective stress
//! `mean_stress` = −(σ'_xx + σ'_yy + σ'_zz)/3 [Pa] (compression positive), the deviatoric stress
//! `q` = sqrt(3/2 s:s) [Pa], the deviatoric plastic strain `eps_pd` [-], the `mass` [kg] (per metre of thickness) and `volume`
//! [m²] each point carries, `material_id`, `body_id`,
//! `particle_id`, and in two-phase runs the pore pressure `p` and the excess pore pressure
//! `p_excess` = p − p₀ [Pa].
//!
//! Grid fields, each rank writing the block of nodes it owns: `active` (1 where the node took part
//! in the last step) and the nodal increments of the last step, `du` [m] (and in two-phase runs `dp`
//! [Pa] and `dU` [m]), and [001]'s nodal diagnostics `K_mag` = √(K_x² + K_y²) (Eq. 25, the diagonal
//! of the skeleton's stiffness at the node's x and y dofs [N/m per m]) and `Fint_mag` (Eq. 26 with its
//! squares, the skeleton's internal force [N/m per m]) from the particles that reach the node; all zero
//! before the first step (e.g. at t = 0 and at the restart time). Node coordinates are the grid's
//! geometry.

use crate::assembly::{NodeBlock, NODE_VALUES};
use crate::io::fields::{Field, Frame, GridGeometry, Values};
use crate::model::Model;
use crate::parallel::Collective;

/// Values per particle record in the redistribution.
const PREC: usize = 19;

/// The grid's geometry for the field files.
pub fn grid_geometry(model: &Model) -> GridGeometry {
    GridGeometry { origin: model.grid.origin, spacing: model.grid.h, nodes: model.grid.nodes() }
}

fn vec3(v: impl Iterator<Item = [f64; 2]>) -> Vec<f64> {
    v.flat_map(|a| [a[0], a[1], 0.0]).collect()
}

/// This rank's share of the fields at time `t` (collective). `nodes` is this rank's
/// [`crate::assembly::GridSystem::owned_node_block`].
pub fn frame(model: &Model, nodes: &NodeBlock, coll: &Collective, t: f64) -> Frame {
    let ps = &model.particles;
    let local: Vec<f64> = (0..ps.len())
        .flat_map(|k| {
            let s = ps.stress[k];
            [
                ps.id[k] as f64,
                ps.body[k] as f64,
                ps.material[k] as f64,
                ps.x[k][0],
                ps.x[k][1],
                ps.disp[k][0],
                ps.disp[k][1],
                ps.vel[k][0],
                ps.vel[k][1],
                s[0],
                s[1],
                s[2],
                s[3],
                ps.p[k],
                ps.p0[k],
                ps.eps_pd[k],
                ps.mass[k],
                ps.volume[k],
                ps.jbar[k],
            ]
        })
        .collect();
    let slab = coll.sorted_slab(&local, PREC);
    let all: Vec<[f64; PREC]> = slab.values.chunks_exact(PREC).map(|c| c.try_into().expect("PREC values")).collect();
    let real = |f: &dyn Fn(&[f64; PREC]) -> f64| Values::Real(all.iter().map(f).collect());
    let int = |i: usize| Values::Int(all.iter().map(|r| r[i] as i32).collect());
    let scalar = |name, values| Field { name, components: 1, values };
    let mean = |r: &[f64; PREC]| (r[9] + r[10] + r[12]) / 3.0;
    let mut pf = vec![
        Field { name: "position", components: 3, values: Values::Real(vec3(all.iter().map(|r| [r[3], r[4]]))) },
        Field { name: "displacement", components: 3, values: Values::Real(vec3(all.iter().map(|r| [r[5], r[6]]))) },
        Field { name: "velocity", components: 3, values: Values::Real(vec3(all.iter().map(|r| [r[7], r[8]]))) },
        scalar("stress_xx", real(&|r| r[9])),
        scalar("stress_yy", real(&|r| r[10])),
        scalar("stress_xy", real(&|r| r[11])),
        scalar("stress_zz", real(&|r| r[12])),
        scalar("mean_stress", real(&|r| -mean(r))),
        scalar(
            "q",
            real(&|r| {
                let m = mean(r);
                (1.5 * ((r[9] - m).powi(2) + (r[10] - m).powi(2) + (r[12] - m).powi(2) + 2.0 * r[11] * r[11])).sqrt()
            }),
        ),
        scalar("eps_pd", real(&|r| r[15])),
        scalar("mass", real(&|r| r[16])),
        scalar("volume", real(&|r| r[17])),
        scalar("material_id", int(2)),
        scalar("body_id", int(1)),
        scalar("particle_id", Values::Real(all.iter().map(|r| r[0]).collect())),
    ];
    if model.fbar {
        // [002]'s projected volume ratio J̄ the stress sees (its volume is det F V⁰).
        pf.push(scalar("jbar", real(&|r| r[18])));
    }
    if model.two_phase {
        pf.push(scalar("p", real(&|r| r[13])));
        pf.push(scalar("p_excess", real(&|r| r[13] - r[14])));
    }

    let d: Vec<&[f64]> = nodes.values.chunks_exact(NODE_VALUES).collect();
    let active = d.iter().map(|v| (v[0] > 0.5) as i32).collect();
    let mut gf = vec![
        Field { name: "active", components: 1, values: Values::Int(active) },
        Field { name: "du", components: 3, values: Values::Real(vec3(d.iter().map(|v| [v[1], v[2]]))) },
    ];
    if model.two_phase {
        gf.push(Field { name: "dp", components: 1, values: Values::Real(d.iter().map(|v| v[3]).collect()) });
        gf.push(Field { name: "dU", components: 3, values: Values::Real(vec3(d.iter().map(|v| [v[4], v[5]]))) });
    }
    gf.push(Field { name: "K_mag", components: 1, values: Values::Real(d.iter().map(|v| v[6]).collect()) });
    gf.push(Field { name: "Fint_mag", components: 1, values: Values::Real(d.iter().map(|v| v[7]).collect()) });
    Frame {
        time: t,
        particles: slab.total,
        first_particle: slab.offset,
        particle_fields: pf,
        node_block: (nodes.start, nodes.count),
        grid_fields: gf,
    }
}
