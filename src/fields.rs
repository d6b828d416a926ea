//! The fields written to `fields.h5`/`fields.xdmf` at an output time, each rank's share of them
//! (all ranks write the file together through [`crate::io::fields`]).
//!
//! Particle fields, sorted by particle id: the records are redistributed so that each rank holds
//! one slab of the sorted list ([`Collective::sorted_slab`]), which it writes at its place in the
//! file; the file does not depend on the number of ranks. The fields: `position` and `displacement` [m], `velocity` [m/s]
//! (3 components, z = 0 in two dimensions), the effective stress components `stress_xx`, `stress_yy`, `stress_xy`,
//! `stress_zz` (and in three dimensions `stress_yz`, `stress_zx`) [Pa] (tension positive; total
//! stress in one-phase runs), the mean effective stress
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
//! before the first step (e.g. at t = 0 and at the restart time). The diagnostics are computed for
//! the frames written every `output.fields_every` steps and at each stage's end; a frame written
//! when a run stops early or is interrupted between those carries NaN for them. Node coordinates
//! are the grid's geometry.

use crate::assembly::{node_values, NodeBlock};
use crate::io::fields::{Field, Frame, GridGeometry, Values};
use crate::model::Model;
use crate::parallel::Collective;

/// The grid's geometry for the field files.
pub fn grid_geometry<const D: usize>(model: &Model<D>) -> GridGeometry {
    GridGeometry::of(model.grid.origin, model.grid.h, model.grid.nodes())
}

/// Values per particle record in the redistribution, in `D` dimensions: id, body, material,
/// position, displacement and velocity (D each), the six stress components, p, p₀, ε̄, mass,
/// volume and J̄.
const fn record_len<const D: usize>() -> usize {
    15 + 3 * D
}

/// A record's D-vector at `at` as three components (z = 0 in two dimensions): a particle record's
/// or a grid node's.
fn vec3<const D: usize>(r: &[f64], at: usize) -> [f64; 3] {
    std::array::from_fn(|c| if c < D { r[at + c] } else { 0.0 })
}

/// This rank's slab of the particle fields of `model` (collective; see the module documentation):
/// the fields, the number of particles of all ranks and the place of this rank's first row.
pub fn particle_fields<const D: usize>(model: &Model<D>, coll: &Collective) -> (Vec<Field>, usize, usize) {
    let ps = &model.particles;
    let prec = record_len::<D>();
    let mut local = Vec::with_capacity(ps.len() * prec);
    for k in 0..ps.len() {
        local.extend([ps.id[k] as f64, ps.body[k] as f64, ps.material[k] as f64]);
        local.extend(ps.x[k]);
        local.extend(ps.disp[k]);
        local.extend(ps.vel[k]);
        local.extend(ps.stress[k]);
        local.extend([ps.p[k], ps.p0[k], ps.eps_pd[k], ps.mass[k], ps.volume[k], ps.jbar[k]]);
    }
    let slab = coll.sorted_slab(&local, prec);
    let all: Vec<&[f64]> = slab.values.chunks_exact(prec).collect();
    // The offsets of the record's parts.
    let (x, disp, vel, s) = (3, 3 + D, 3 + 2 * D, 3 + 3 * D);
    let scalars = s + 6;
    let real = |f: &dyn Fn(&[f64]) -> f64| Values::Real(all.iter().map(|r| f(r)).collect());
    let int = |i: usize| Values::Int(all.iter().map(|r| r[i] as i32).collect());
    let vector = |at: usize| Values::Real(all.iter().flat_map(|r| vec3::<D>(r, at)).collect());
    let scalar = |name, values| Field { name, components: 1, values };
    let mean = |r: &[f64]| (r[s] + r[s + 1] + r[s + 3]) / 3.0;
    let mut pf = vec![
        Field { name: "position", components: 3, values: vector(x) },
        Field { name: "displacement", components: 3, values: vector(disp) },
        Field { name: "velocity", components: 3, values: vector(vel) },
        scalar("stress_xx", real(&|r| r[s])),
        scalar("stress_yy", real(&|r| r[s + 1])),
        scalar("stress_xy", real(&|r| r[s + 2])),
        scalar("stress_zz", real(&|r| r[s + 3])),
    ];
    if D == 3 {
        pf.push(scalar("stress_yz", real(&|r| r[s + 4])));
        pf.push(scalar("stress_zx", real(&|r| r[s + 5])));
    }
    pf.extend([
        scalar("mean_stress", real(&|r| -mean(r))),
        scalar(
            "q",
            real(&|r| {
                let m = mean(r);
                let shear = 2.0 * r[s + 2] * r[s + 2];
                let normal = (r[s] - m).powi(2) + (r[s + 1] - m).powi(2) + (r[s + 3] - m).powi(2);
                // (The out-of-plane shears are zero in two dimensions.)
                (1.5 * (normal + shear + 2.0 * (r[s + 4] * r[s + 4] + r[s + 5] * r[s + 5]))).sqrt()
            }),
        ),
        scalar("eps_pd", real(&|r| r[scalars + 2])),
        scalar("mass", real(&|r| r[scalars + 3])),
        scalar("volume", real(&|r| r[scalars + 4])),
        scalar("material_id", int(2)),
        scalar("body_id", int(1)),
        scalar("particle_id", Values::Real(all.iter().map(|r| r[0]).collect())),
    ]);
    if model.fbar {
        // [002]'s projected volume ratio J̄ the stress sees (its volume is det F V⁰).
        pf.push(scalar("jbar", real(&|r| r[scalars + 5])));
    }
    if model.pore_water {
        pf.push(scalar("p", real(&|r| r[scalars])));
        pf.push(scalar("p_excess", real(&|r| r[scalars] - r[scalars + 1])));
    }
    (pf, slab.total, slab.offset)
}

/// This rank's share of the fields at time `t` (collective). `nodes` is this rank's
/// [`crate::assembly::System::node_block`].
pub fn frame<const D: usize>(model: &Model<D>, nodes: &NodeBlock, coll: &Collective, t: f64) -> Frame {
    let (pf, particles, first_particle) = particle_fields(model, coll);
    let d: Vec<&[f64]> = nodes.values.chunks_exact(node_values(D)).collect();
    let active = d.iter().map(|v| (v[0] > 0.5) as i32).collect();
    // The node's values: flag, u (D), p, U (D), K_mag, F^int_mag.
    let (p, w, k) = (1 + D, 2 + D, 2 + 2 * D);
    let mut gf = vec![
        Field { name: "active", components: 1, values: Values::Int(active) },
        Field { name: "du", components: 3, values: Values::Real(d.iter().flat_map(|v| vec3::<D>(v, 1)).collect()) },
    ];
    if model.pore_water {
        gf.push(Field { name: "dp", components: 1, values: Values::Real(d.iter().map(|v| v[p]).collect()) });
        gf.push(Field {
            name: "dU",
            components: 3,
            values: Values::Real(d.iter().flat_map(|v| vec3::<D>(v, w)).collect()),
        });
    }
    gf.push(Field { name: "K_mag", components: 1, values: Values::Real(d.iter().map(|v| v[k]).collect()) });
    gf.push(Field { name: "Fint_mag", components: 1, values: Values::Real(d.iter().map(|v| v[k + 1]).collect()) });
    Frame {
        time: t,
        particles,
        first_particle,
        particle_fields: pf,
        node_block: (nodes.start, nodes.count),
        grid_fields: gf,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The particle fields of a three-dimensional model: positions with their z, the out-of-plane
    /// shears, q = sqrt(3/2 s:s) with all six components, sorted by id on one rank.
    #[test]
    fn a_three_dimensional_model_writes_its_third_components() {
        let (_lock, _world) = crate::io::test_world();
        let text = crate::case::tests_support::with_grid("[0.1, 1.0, 0.2]", "[1, 10, 2]");
        let c = crate::validation::load(&text, "t", &[]).unwrap();
        let mut m = Model::build_solid(&c, |_| true);
        let s = [-1.0e3, -2.0e3, 150.0, -1.2e3, 80.0, -120.0];
        m.particles.stress.iter_mut().for_each(|x| *x = s);
        let (fields, total, first) = particle_fields(&m, &Collective::world());
        assert_eq!((total, first), (m.particles.len(), 0));
        let get = |name: &str| fields.iter().find(|f| f.name == name).map(|f| f.values.clone());
        let Some(Values::Real(pos)) = get("position") else { panic!("no position") };
        let mut order: Vec<usize> = (0..m.particles.len()).collect();
        order.sort_by_key(|&k| m.particles.id[k]);
        for (row, &k) in order.iter().enumerate() {
            assert_eq!(&pos[3 * row..3 * row + 3], &m.particles.x[k][..]);
        }
        assert!(pos.chunks(3).any(|p| p[2] > 0.1), "points behind z = 0.1");
        let Some(Values::Real(yz)) = get("stress_yz") else { panic!("no stress_yz") };
        assert!(yz.iter().all(|&v| v == 80.0));
        let Some(Values::Real(q)) = get("q") else { panic!("no q") };
        let mean = (s[0] + s[1] + s[3]) / 3.0;
        let ss = (s[0] - mean).powi(2)
            + (s[1] - mean).powi(2)
            + (s[3] - mean).powi(2)
            + 2.0 * (s[2] * s[2] + s[4] * s[4] + s[5] * s[5]);
        assert!((q[0] - (1.5 * ss).sqrt()).abs() < 1e-9, "{} against {}", q[0], (1.5 * ss).sqrt());
    }
}
