//! Material points in struct-of-arrays storage, and their generation from the case geometry.
//!
//! One set of points carries both phases ([003] §3, single-layer MPM): it moves with the solid;
//! the water is described by its velocity, acceleration and mass n ρ_w V on the same points.

use super::grid::Grid;
use crate::case::{Case, Formulation};

/// All material points held by this rank.
#[derive(Debug, Clone, Default)]
pub struct Particles {
    /// Global identifier (stable over the run, unique across ranks).
    pub id: Vec<u64>,
    /// Index of the body it was generated in.
    pub body: Vec<u16>,
    /// Index of its material.
    pub material: Vec<u16>,
    /// Position [m].
    pub x: Vec<[f64; 2]>,
    /// Position at t = 0 [m].
    pub x0: Vec<[f64; 2]>,
    /// Total solid displacement [m].
    pub disp: Vec<[f64; 2]>,
    /// Half-widths of the GIMP domain l_p [m] (see `ShapeFunctions::Gimp` for how they follow the
    /// deformation).
    pub lp: Vec<[f64; 2]>,
    /// Half-widths of the GIMP domain at t = 0 [m].
    pub lp0: Vec<[f64; 2]>,
    /// In-plane deformation gradient F = ∂x/∂X of the solid, rows [[F_xx, F_xy], [F_yx, F_yy]] [-].
    pub def_grad: Vec<[[f64; 2]; 2]>,
    /// Volume per metre of thickness [m²·1 m].
    pub volume: Vec<f64>,
    /// Porosity [-].
    pub porosity: Vec<f64>,
    /// Mass carried by the solid-displacement equation [kg]: the grains' (1 − n)ρ_s V in two-phase
    /// analyses (constant: solid mass is conserved), the mixture's ρV in one-phase analyses.
    pub mass: Vec<f64>,
    /// Solid velocity [m/s].
    pub vel: Vec<[f64; 2]>,
    /// Solid acceleration [m/s²].
    pub acc: Vec<[f64; 2]>,
    /// Water velocity [m/s] (two-phase).
    pub vel_w: Vec<[f64; 2]>,
    /// Water acceleration [m/s²] (two-phase).
    pub acc_w: Vec<[f64; 2]>,
    /// Effective stress [xx, yy, xy, zz, yz, zx] (total stress in one-phase analyses; yz = zx = 0 in
    /// plane strain and axial symmetry) [Pa].
    pub stress: Vec<crate::model::soil::Stress>,
    /// Pore pressure (compression positive) [Pa].
    pub p: Vec<f64>,
    /// Pore pressure at t = 0 [Pa] (the excess pore pressure is p − p₀).
    pub p0: Vec<f64>,
    /// Deviatoric plastic strain ε_p^d = sqrt(2/3 e_p : e_p) [-].
    pub eps_pd: Vec<f64>,
    /// Pore-pressure gradient [Pa/m] (two-phase), carried like p: it drives the Darcy flux of the
    /// u–p system from the start of a step.
    pub grad_p: Vec<[f64; 2]>,
    /// [002]'s projected volume ratio J̄ = det F̄ (`stabilisation.fbar`, §3 Algorithm 1): the
    /// stress sees F̄ = (J̄/J)^{1/2} F, while the volume and F follow the point's own motion; 1 at
    /// t = 0 and without F̄ [-].
    pub jbar: Vec<f64>,
}

impl Particles {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Appends a point with the given id, body and material and every other array zero (to be
    /// filled by the caller).
    pub fn push_blank(&mut self, id: u64, body: u16, material: u16) {
        self.id.push(id);
        self.body.push(body);
        self.material.push(material);
        self.x.push([0.0; 2]);
        self.x0.push([0.0; 2]);
        self.disp.push([0.0; 2]);
        self.lp.push([0.0; 2]);
        self.lp0.push([0.0; 2]);
        self.def_grad.push([[0.0; 2]; 2]);
        self.volume.push(0.0);
        self.porosity.push(0.0);
        self.mass.push(0.0);
        self.vel.push([0.0; 2]);
        self.acc.push([0.0; 2]);
        self.vel_w.push([0.0; 2]);
        self.acc_w.push([0.0; 2]);
        self.stress.push([0.0; crate::model::soil::NS]);
        self.p.push(0.0);
        self.p0.push(0.0);
        self.eps_pd.push(0.0);
        self.grad_p.push([0.0; 2]);
        self.jbar.push(1.0);
    }

    /// Fills the bodies of the case with `n × n` points per cell, keeping those whose cell
    /// satisfies `owned(cell_i, cell_j)` (the cells of this rank). Points are placed at the centres
    /// of the n × n sub-cells; a point belongs to the first body that contains it.
    pub fn generate(case: &Case, grid: &Grid, owned: impl Fn(usize, usize) -> bool) -> Particles {
        let mut ps = Particles::default();
        let two_phase = case.analysis.formulation == Formulation::TwoPhase;
        for (b, body) in case.bodies.iter().enumerate() {
            let mat_index = case.material_index(&body.material).expect("validated");
            let mat = &case.materials[mat_index];
            let n = body.particles_per_cell;
            let (lo, hi) = body.shape.bounds();
            let c0 = grid.cell_of(lo).unwrap_or((0, 0));
            let c1 = grid.cell_of(hi).unwrap_or((grid.cells[0] - 1, grid.cells[1] - 1));
            let lp = [grid.h[0] / (2.0 * n as f64), grid.h[1] / (2.0 * n as f64)];
            let area = grid.h[0] * grid.h[1] / (n * n) as f64;
            let geometry = super::geometry_of(case);
            for cj in c0.1..=c1.1 {
                for ci in c0.0..=c1.0 {
                    for sj in 0..n {
                        for si in 0..n {
                            // Global id from the body and the sub-cell position: unique and independent
                            // of how cells are distributed over ranks.
                            let gi = (ci * n + si) as u64;
                            let gj = (cj * n + sj) as u64;
                            let id = ((b as u64) << 48) | (gj * (grid.cells[0] * 8) as u64 + gi);
                            let shake = [jitter(id, 0), jitter(id, 1)].map(|r| body.perturbation * (2.0 * r - 1.0));
                            let x = [
                                grid.origin[0] + (ci as f64 + (si as f64 + 0.5 + shake[0]) / n as f64) * grid.h[0],
                                grid.origin[1] + (cj as f64 + (sj as f64 + 0.5 + shake[1]) / n as f64) * grid.h[1],
                            ];
                            let earlier = case.bodies[..b].iter().any(|o| o.shape.contains(x));
                            if !body.shape.contains(x) || earlier || !owned(ci, cj) {
                                continue;
                            }
                            // The ring's volume 2πr A in axial symmetry.
                            let vol = area * geometry.measure(x[0]);
                            let mass = if two_phase {
                                (1.0 - mat.porosity) * mat.solid_density * vol
                            } else {
                                ((1.0 - mat.porosity) * mat.solid_density + mat.porosity * mat.water_density) * vol
                            };
                            ps.id.push(id);
                            ps.body.push(b as u16);
                            ps.material.push(mat_index as u16);
                            ps.x.push(x);
                            ps.x0.push(x);
                            ps.disp.push([0.0; 2]);
                            ps.lp.push(lp);
                            ps.lp0.push(lp);
                            ps.def_grad.push([[1.0, 0.0], [0.0, 1.0]]);
                            ps.volume.push(vol);
                            ps.porosity.push(mat.porosity);
                            ps.mass.push(mass);
                            ps.vel.push([0.0; 2]);
                            ps.acc.push([0.0; 2]);
                            ps.vel_w.push([0.0; 2]);
                            ps.acc_w.push([0.0; 2]);
                            let (stress, p, grad_p) = match (&body.initial_stress, &body.uniform_stress) {
                                (Some(init), _) => geostatic(case, grid, init, x, two_phase),
                                (None, Some(s)) => (*s, 0.0, [0.0; 2]),
                                (None, None) => ([0.0; 4], 0.0, [0.0; 2]),
                            };
                            ps.grad_p.push(grad_p);
                            ps.stress.push(crate::model::soil::plane(stress));
                            ps.p.push(p);
                            ps.p0.push(p);
                            ps.eps_pd.push(0.0);
                            ps.jbar.push(1.0);
                        }
                    }
                }
            }
        }
        ps
    }
}

/// A pseudo-random number in [0, 1) from a point's id and a stream (SplitMix64): the same point
/// gets the same number on any rank.
fn jitter(id: u64, stream: u64) -> f64 {
    let mut z = id.wrapping_mul(2).wrapping_add(stream).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// The geostatic effective stress, pore pressure and pore-pressure gradient at `x` (see
/// [`crate::case::InitialStress`]).
fn geostatic(
    case: &Case,
    grid: &Grid,
    init: &crate::case::InitialStress,
    x: [f64; 2],
    two_phase: bool,
) -> ([f64; 4], f64, [f64; 2]) {
    let g = case.analysis.g;
    let (surface, mass) = case.column_above(x, grid.h[1] / 50.0);
    let sigma_v = -g * mass;
    let (p, grad_p) = if two_phase {
        let rho_w = case
            .body_at(x)
            .map_or(1000.0, |b| case.materials[case.material_index(&b.material).expect("validated")].water_density);
        let level = match init.water_table {
            crate::case::WaterTable::Surface => surface,
            crate::case::WaterTable::Level(y) => y,
        };
        let below = level > x[1];
        (rho_w * g * (level - x[1]).max(0.0), [0.0, if below { -rho_w * g } else { 0.0 }])
    } else {
        (0.0, [0.0; 2])
    };
    let sv = sigma_v + p;
    ([init.k0 * sv, sv, 0.0, init.k0 * sv], p, grad_p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case;

    #[test]
    fn a_column_is_filled_with_two_by_two_points_per_cell_of_the_right_volume() {
        let c = case::parse(crate::case::tests_support::MINIMAL, "t", &[]).unwrap();
        let g = Grid::new([0.0, 0.0], c.cell_size(), c.grid.cells);
        let ps = Particles::generate(&c, &g, |_, _| true);
        assert_eq!(ps.len(), 40);
        let v: f64 = ps.volume.iter().sum();
        assert!((v - 0.1).abs() < 1e-12);
        assert!((ps.lp[0][0] - 0.025).abs() < 1e-15);
        let mut ids = ps.id.clone();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), 40, "ids are unique");
        // Only the cells a rank owns.
        let half = Particles::generate(&c, &g, |_, j| j < 5);
        assert_eq!(half.len(), 20);
        assert!(half.x.iter().all(|x| x[1] < 0.5));
    }

    #[test]
    fn polygons_and_several_bodies_are_filled_without_overlap() {
        let text = crate::case::tests_support::MINIMAL
            .replace("size = [0.1, 1.0]\n        cells = [1, 10]", "size = [1.0, 1.0]\n        cells = [10, 10]")
            .replace(
                "shape = { rectangle = { min = [0.0, 0.0], max = [0.1, 1.0] } }",
                "shape = { polygon = { vertices = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]] } }\n        [[bodies]]\n        name = \"block\"\n        material = \"soil\"\n        particles_per_cell = 1\n        shape = { rectangle = { min = [0.0, 0.0], max = [1.0, 1.0] } }",
            );
        let c = case::parse(&text, "t", &[]).unwrap();
        let g = Grid::new([0.0, 0.0], c.cell_size(), c.grid.cells);
        let ps = Particles::generate(&c, &g, |_, _| true);
        let tri: f64 = (0..ps.len()).filter(|&k| ps.body[k] == 0).map(|k| ps.volume[k]).sum();
        // The 2×2 points of the triangle cover half the square up to the staircase along the hypotenuse.
        assert!((tri - 0.5).abs() < 0.05, "triangle area {tri}");
        // The block takes only the points the triangle left (one per cell, where the cell centre is
        // not in the triangle): the 45 cells above the diagonal, and those whose centre lies on it
        // if the even-odd rule leaves them out of the triangle.
        let block: Vec<usize> = (0..ps.len()).filter(|&k| ps.body[k] == 1).collect();
        assert!((45..=55).contains(&block.len()), "{} block points", block.len());
        assert!(block.iter().all(|&k| !c.bodies[0].shape.contains(ps.x[k])));
        assert!((0..ps.len()).filter(|&k| ps.body[k] == 0).all(|k| c.bodies[0].shape.contains(ps.x[k])));
        let mut ids = ps.id.clone();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), ps.len());
    }
}
