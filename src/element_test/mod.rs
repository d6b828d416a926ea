//! One material point driven along a load path (`porompm element-test`): the tool for calibrating
//! a soil model and checking it against closed forms.
//!
//! Each increment prescribes the strain of the strain-controlled components and the stress of the
//! stress-controlled ones; the unknown strain increments of the latter are found by Newton's method
//! with the model's consistent tangent (the stress-controlled rows of dσ/dΔε), so a plastic increment
//! converges quadratically, as the residual history of each row shows.

pub mod input;

use crate::soils::{Constitutive, Region, Stress, NS};
use input::{Control, LoadPath};

/// The state after one increment.
#[derive(Debug, Clone)]
pub struct Row {
    /// Increment number (1-based over the whole path).
    pub step: usize,
    /// Segment index.
    pub segment: usize,
    /// Total strain [xx, yy, γxy, zz, γyz, γzx].
    pub strain: Stress,
    /// Stress [xx, yy, xy, zz, yz, zx] [Pa].
    pub stress: Stress,
    /// Accumulated deviatoric plastic strain ε̄.
    pub eps_pd: f64,
    /// Region of the return.
    pub region: Region,
    /// Residual norms of the mixed-control Newton iterations (empty when fully strain-controlled).
    pub residuals: Vec<f64>,
}

impl Row {
    /// Mean stress p = (σ_xx + σ_yy + σ_zz)/3 (tension positive) [Pa].
    pub fn mean(&self) -> f64 {
        (self.stress[0] + self.stress[1] + self.stress[3]) / 3.0
    }

    /// Deviatoric stress q = sqrt(3/2 s:s) [Pa].
    pub fn q(&self) -> f64 {
        let p = self.mean();
        let s = &self.stress;
        let shear = s[2] * s[2] + s[4] * s[4] + s[5] * s[5];
        (1.5 * ((s[0] - p).powi(2) + (s[1] - p).powi(2) + (s[3] - p).powi(2) + 2.0 * shear)).sqrt()
    }
}

/// Drives `model` along `path`; fails if an increment's mixed control does not converge.
pub fn run(model: &Constitutive, path: &LoadPath) -> Result<Vec<Row>, String> {
    let mut stress = path.initial();
    let mut strain = [0.0; NS];
    let mut eps = path.initial_plastic_strain;
    let mut rows = Vec::new();
    let scale = model.elastic().d[0][0];
    for (si, seg) in path.segments.iter().enumerate() {
        let start = stress;
        let controls = seg.controls();
        let free: Vec<usize> = (0..NS).filter(|&c| matches!(controls[c], Control::Stress(_))).collect();
        for n in 1..=seg.steps {
            let frac = n as f64 / seg.steps as f64;
            let mut de = [0.0; NS];
            let mut target = [0.0; NS];
            for c in 0..NS {
                match controls[c] {
                    Control::Strain(total) => de[c] = total / seg.steps as f64,
                    Control::Stress(end) => target[c] = start[c] + (end - start[c]) * frac,
                }
            }
            // Newton on the stress-controlled components.
            let mut residuals = Vec::new();
            let mut upd = model.update(&stress, eps, &de);
            for _ in 0..50 {
                let r: Vec<f64> = free.iter().map(|&c| upd.stress[c] - target[c]).collect();
                let norm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
                if free.is_empty() {
                    break;
                }
                residuals.push(norm);
                if norm <= 1e-10 * (scale * 1e-6 + target.iter().fold(0.0f64, |a, v| a.max(v.abs()))) {
                    break;
                }
                // The stress-controlled block of the tangent; at a Mohr–Coulomb edge with both lateral
                // stresses controlled it is singular (the split of the lateral flow between them is
                // free) and the regularised solve picks the smallest correction.
                let m = free.len();
                let mut a = [[0.0; NS]; NS];
                let mut rhs = [0.0; NS];
                for (i, &ci) in free.iter().enumerate() {
                    rhs[i] = r[i];
                    for (j, &cj) in free.iter().enumerate() {
                        a[i][j] = upd.tangent[ci][cj];
                    }
                }
                let dx = crate::algebra::linalg::solve_regularised(a, rhs, m).ok_or_else(|| {
                    format!("segment {si}, increment {n}: the stress-controlled rows of the tangent are singular")
                })?;
                for (j, &cj) in free.iter().enumerate() {
                    de[cj] -= dx[j];
                }
                upd = model.update(&stress, eps, &de);
            }
            if let Some(&last) = residuals.last() {
                let first = residuals[0].max(f64::MIN_POSITIVE);
                if residuals.len() >= 50 && last > 1e-8 * first {
                    return Err(format!(
                        "segment {si}, increment {n}: the stress control did not converge (residual {last:.3e} Pa)"
                    ));
                }
            }
            for c in 0..NS {
                strain[c] += de[c];
            }
            stress = upd.stress;
            eps = upd.eps_pd;
            rows.push(Row {
                step: rows.len() + 1,
                segment: si,
                strain,
                stress,
                eps_pd: eps,
                region: upd.region,
                residuals,
            });
        }
    }
    Ok(rows)
}

/// The CSV header of [`table`].
pub const HEADER: [&str; 19] = [
    "step",
    "segment",
    "eps_xx",
    "eps_yy",
    "gamma_xy",
    "eps_zz",
    "gamma_yz",
    "gamma_zx",
    "sig_xx",
    "sig_yy",
    "sig_xy",
    "sig_zz",
    "sig_yz",
    "sig_zx",
    "p",
    "q",
    "eps_pd",
    "region",
    "newton_residuals",
];

/// The rows as CSV fields (stresses in Pa; residuals separated by `;`).
pub fn table(rows: &[Row]) -> Vec<Vec<String>> {
    rows.iter()
        .map(|r| {
            let mut v = vec![r.step.to_string(), r.segment.to_string()];
            v.extend(r.strain.iter().map(|x| format!("{x:.10e}")));
            v.extend(r.stress.iter().map(|x| format!("{x:.10e}")));
            v.push(format!("{:.10e}", r.mean()));
            v.push(format!("{:.10e}", r.q()));
            v.push(format!("{:.10e}", r.eps_pd));
            v.push(format!("{:?}", r.region).to_lowercase());
            v.push(r.residuals.iter().map(|x| format!("{x:.3e}")).collect::<Vec<_>>().join(";"));
            v
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::input::{parse_material, parse_path};
    use super::*;

    fn model(text: &str) -> Constitutive {
        parse_material(text, "m").unwrap().model.law()
    }

    const SAND: &str = r#"
        [model]
        type = "mohr_coulomb"
        young_modulus = 20e6
        poisson_ratio = 0.3
        friction_angle = 30.0
        cohesion = 5e3
        dilation_angle = 5.0
    "#;

    #[test]
    fn a_drained_plane_strain_compression_reaches_the_mohr_coulomb_strength_with_quadratic_newton() {
        // σ_xx held at −100 kPa, ε_zz = 0, ε_yy compressed: at failure
        // (σ₁ − σ₃) + (σ₁ + σ₃) sin φ = 2c cos φ with σ₁ = −100 kPa the largest principal stress.
        let path = parse_path(
            r#"
            initial_stress = [-100e3, -100e3, 0.0, -100e3]
            [[segments]]
            steps = 100
            xx = { stress = -100e3 }
            yy = { strain = -0.03 }
            xy = { strain = 0.0 }
            zz = { strain = 0.0 }
            "#,
            "p",
        )
        .unwrap();
        let rows = run(&model(SAND), &path).unwrap();
        let last = rows.last().unwrap();
        let (s1, s3) = (last.stress[0], last.stress[1]);
        let (sp, cp) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
        let f = (s1 - s3) + (s1 + s3) * sp - 2.0 * 5e3 * cp;
        assert!(f.abs() < 1e-3, "f = {f} at failure, stress {:?}", last.stress);
        assert!((s1 + 100e3).abs() < 1e-3, "σ_xx held: {s1}");
        // Plastic increments converge quadratically: each residual at most C × the previous squared.
        let plastic =
            rows.iter().find(|r| r.region != Region::Elastic && r.residuals.len() >= 3).expect("a plastic row");
        let r = &plastic.residuals;
        for w in r.windows(2).skip(1) {
            if w[1] > 1e-6 {
                assert!(w[1] <= 1e-3 * w[0], "not quadratic: {r:?}");
            }
        }
    }

    #[test]
    fn an_elastic_oedometer_follows_the_constrained_modulus() {
        let path = parse_path(
            r#"
            [[segments]]
            steps = 10
            xx = { strain = 0.0 }
            yy = { strain = -0.001 }
            xy = { strain = 0.0 }
            zz = { strain = 0.0 }
            "#,
            "p",
        )
        .unwrap();
        let m = model("[model]\ntype = \"linear_elastic\"\nyoung_modulus = 1e7\npoisson_ratio = 0.25\n");
        let rows = run(&m, &path).unwrap();
        let ec = 1e7 * 0.75 / (1.25 * 0.5);
        assert!((rows.last().unwrap().stress[1] + ec * 1e-3).abs() < 1e-6);
    }

    #[test]
    fn simple_shear_of_tresca_clay_plateaus_at_the_cohesion() {
        let path = parse_path(
            r#"
            initial_stress = [-50e3, -50e3, 0.0, -50e3]
            [[segments]]
            steps = 50
            xx = { strain = 0.0 }
            yy = { stress = -50e3 }
            xy = { strain = 0.1 }
            zz = { strain = 0.0 }
            "#,
            "p",
        )
        .unwrap();
        let m = model("[model]\ntype = \"mohr_coulomb\"\nyoung_modulus = 1e6\npoisson_ratio = 0.49\nfriction_angle = 0.0\ncohesion = 10e3\n");
        let rows = run(&m, &path).unwrap();
        let tau = rows.last().unwrap().stress[2];
        assert!((tau - 10e3).abs() < 1e-3, "τ = {tau}");
    }

    #[test]
    fn softening_von_mises_clay_falls_to_its_residual_strength() {
        let path = parse_path(
            r#"
            [[segments]]
            steps = 200
            xx = { strain = 0.0 }
            yy = { strain = 0.0 }
            xy = { strain = 0.8 }
            zz = { strain = 0.0 }
            "#,
            "p",
        )
        .unwrap();
        let m = model("[model]\ntype = \"von_mises\"\nyoung_modulus = 1e6\npoisson_ratio = 0.35\ncohesion = 12e3\nresidual_cohesion = 3e3\nsoftening_modulus = -30e3\n");
        let rows = run(&m, &path).unwrap();
        // Pure shear: q = √3 τ, so τ peaks at c_p and ends at c_r once ε̄ = γ_p/√3 passes
        // (c_r − c_p)/H_s = 0.3.
        for r in &rows {
            let c = (12e3 - 30e3 * r.eps_pd).max(3e3);
            if r.region == Region::Elastic {
                assert!(r.stress[2] <= c + 1e-6);
            } else {
                assert!((r.stress[2] - c).abs() < 1e-6, "τ = {} vs c(ε̄) = {c}", r.stress[2]);
            }
        }
        assert!((rows.last().unwrap().stress[2] - 3e3).abs() < 1e-6);
    }

    /// A strain path driven in a turned frame (every shear component non-zero) gives the stresses
    /// of the same path in the material's own frame, turned: the soil models see the full
    /// three-dimensional state, and an isotropic one does not care about the frame.
    #[test]
    fn a_path_in_a_turned_frame_gives_the_turned_stresses() {
        use crate::soils::principal;
        // Strain-controlled compression with a lateral stretch, in principal axes, from a
        // geostatic start: the loose sand softens, dilates and reaches its edge regions.
        let axes = [-0.02, 0.006, 0.003];
        let start = [-100e3, -60e3, -80e3];
        let tensor_path = |r: &[[f64; 3]; 3]| -> String {
            let e = principal::rotate(r, &[axes[0], axes[1], 0.0, axes[2], 0.0, 0.0]);
            let s = principal::rotate(r, &[start[0], start[1], 0.0, start[2], 0.0, 0.0]);
            // Engineering shears γ = 2ε for the strain controls.
            let c = |k: usize| e[k] * if matches!(k, 2 | 4 | 5) { 2.0 } else { 1.0 };
            format!(
                "initial_stress = [{}, {}, {}, {}, {}, {}]\n[[segments]]\nsteps = 40\nxx = {{ strain = {} }}\n\
                 yy = {{ strain = {} }}\nxy = {{ strain = {} }}\nzz = {{ strain = {} }}\nyz = {{ strain = {} }}\n\
                 zx = {{ strain = {} }}\n",
                s[0],
                s[1],
                s[2],
                s[3],
                s[4],
                s[5],
                c(0),
                c(1),
                c(2),
                c(3),
                c(4),
                c(5)
            )
        };
        let m = model(
            "[model]\ntype = \"mohr_coulomb\"\nyoung_modulus = 20e6\npoisson_ratio = 0.3\nfriction_angle = 30.0\n\
             cohesion = 5e3\ndilation_angle = 5.0\n",
        );
        let own = principal::rotation([0.0, 0.0, 1.0], 0.0);
        let n = 14f64.sqrt();
        let turn = principal::rotation([1.0 / n, -2.0 / n, 3.0 / n], 1.1);
        let a = run(&m, &parse_path(&tensor_path(&own), "own").unwrap()).unwrap();
        let b = run(&m, &parse_path(&tensor_path(&turn), "turned").unwrap()).unwrap();
        assert!(a.iter().any(|r| r.region != Region::Elastic), "the path must yield");
        for (ra, rb) in a.iter().zip(&b) {
            let expected = principal::rotate(&turn, &ra.stress);
            for (c, (got, want)) in rb.stress.iter().zip(&expected).enumerate() {
                assert!((got - want).abs() < 1e-6, "step {} component {c}: {got} vs {want}", ra.step);
            }
            assert_eq!(ra.region, rb.region);
            assert!((ra.q() - rb.q()).abs() < 1e-6 && (ra.mean() - rb.mean()).abs() < 1e-6);
        }
    }
}
