//! Case files: typed TOML with `deny_unknown_fields`, `--set` overrides, range checks.
//!
//! [`parse`] turns the text of a case file plus the command line's overrides into a validated
//! [`Case`]; every error names the file, the key and what is wrong, in one line.

pub mod element;
pub mod overrides;
pub mod parameters;
pub mod schema;
mod validate;

pub use overrides::Override;
pub use schema::*;

use std::fmt;

/// A problem with a case file or an override, as one line of text.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseError(String);

impl CaseError {
    /// An error with the given message.
    pub fn new(msg: impl Into<String>) -> Self {
        CaseError(msg.into())
    }
}

impl fmt::Display for CaseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for CaseError {}

/// Line (1-based) of a byte offset in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}

/// Parses and validates a case. `origin` names the file in messages.
pub fn parse(text: &str, origin: &str, overrides: &[Override]) -> Result<Case, CaseError> {
    let mut doc: toml::Value = toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| format!(" (line {})", line_of(text, s.start))).unwrap_or_default();
        CaseError::new(format!("{origin}{line}: {}", e.message().trim()))
    })?;
    let mut set_paths = Vec::new();
    for ov in overrides {
        let path = overrides::apply(&mut doc, ov).map_err(|e| CaseError::new(format!("{origin}: {e}")))?;
        set_paths.push((path, ov.key.clone()));
    }
    parameters::expand(&mut doc).map_err(|e| CaseError::new(format!("{origin}: {e}")))?;
    let case: Case = serde_path_to_error::deserialize(doc).map_err(|e| {
        let path = e.path().to_string();
        let msg = e.inner().message().trim().to_string();
        let from_set = set_paths
            .iter()
            .find(|(p, _)| path == *p || path.starts_with(&format!("{p}.")) || path.starts_with(&format!("{p}[")));
        match from_set {
            Some((_, key)) => CaseError::new(format!("{origin}: --set {key}: {msg}")),
            None if path == "." || path.is_empty() => CaseError::new(format!("{origin}: {msg}")),
            None => CaseError::new(format!("{origin}: key `{path}`: {msg}")),
        }
    })?;
    let mut case = case;
    for (i, st) in case.stages.iter_mut().enumerate() {
        if st.dt.is_none() {
            st.dt = case.time.dt;
        }
        if st.dt.is_none() {
            return Err(CaseError::new(format!(
                "{origin}: key `stages[{i}].dt`: give the stage a Δt, or a default in [time] dt"
            )));
        }
    }
    validate::validate(&case).map_err(|e| CaseError::new(format!("{origin}: {e}")))?;
    Ok(case)
}

impl Case {
    /// The material called `name`.
    pub fn material(&self, name: &str) -> Option<&Material> {
        self.materials.iter().find(|m| m.name == name)
    }

    /// Index of the material called `name`.
    pub fn material_index(&self, name: &str) -> Option<usize> {
        self.materials.iter().position(|m| m.name == name)
    }

    /// Index of the body called `name` (the particles' `body` id).
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// The body called `name`.
    pub fn body(&self, name: &str) -> Option<&Body> {
        self.bodies.iter().find(|b| b.name == name)
    }

    /// The load called `name`.
    pub fn load(&self, name: &str) -> Option<&Load> {
        self.loads.iter().find(|l| l.name() == name)
    }

    /// The time function called `name`.
    pub fn time_function(&self, name: &str) -> Option<&TimeFunction> {
        self.time_functions.iter().find(|f| f.name() == name)
    }

    /// Total analysis time [s].
    pub fn end_time(&self) -> f64 {
        self.stages.iter().map(|s| s.duration).sum()
    }

    /// Cell size in x and y [m].
    pub fn cell_size(&self) -> [f64; 2] {
        self.cell_size_in()
    }

    /// The dimension of the case: the number of entries of `grid.size` (2 or 3, validated).
    pub fn dimension(&self) -> usize {
        self.grid.size.len()
    }

    /// The grid's origin in the first `D` directions [m] (zero where the case gives none).
    pub fn origin_in<const D: usize>(&self) -> [f64; D] {
        std::array::from_fn(|d| self.grid.origin.get(d).copied().unwrap_or(0.0))
    }

    /// The grid's cells in the first `D` directions.
    pub fn cells_in<const D: usize>(&self) -> [usize; D] {
        std::array::from_fn(|d| self.grid.cells.get(d).copied().unwrap_or(1))
    }

    /// The cell size in the first `D` directions [m].
    pub fn cell_size_in<const D: usize>(&self) -> [f64; D] {
        let cells = self.cells_in::<D>();
        std::array::from_fn(|d| self.grid.size.get(d).copied().unwrap_or(1.0) / cells[d] as f64)
    }

    /// The grid's origin in x and y [m].
    pub fn origin(&self) -> [f64; 2] {
        self.origin_in()
    }

    /// The grid's cells in x and y.
    pub fn cells(&self) -> [usize; 2] {
        self.cells_in()
    }

    /// The extent [z_min, z_max] of `body` along z in a three-dimensional case [m]: its own, or
    /// the grid's.
    pub fn body_depth(&self, body: &Body) -> [f64; 2] {
        body.z.unwrap_or_else(|| {
            let z0 = self.grid.origin.get(2).copied().unwrap_or(0.0);
            [z0, z0 + self.grid.size.get(2).copied().unwrap_or(0.0)]
        })
    }

    /// Whether `body` holds the point `p` of a case of dimension `D`: its section holds (x, y) and,
    /// in three dimensions, its extent along z holds z (bounds included, as the section's).
    pub fn body_holds<const D: usize>(&self, body: &Body, p: [f64; D]) -> bool {
        if !body.shape.contains([p[0], p[1]]) {
            return false;
        }
        D == 2 || {
            let [lo, hi] = self.body_depth(body);
            p[2] >= lo && p[2] <= hi
        }
    }
}

impl Case {
    /// The material stiffness of Newton's matrix: `stabilisation.stiffness`, or the exact tangent
    /// (`particle`) when the mapped stiffness serves the diagnostics only.
    pub fn jacobian_stiffness(&self) -> Stiffness {
        match self.stabilisation.mapped_stiffness {
            MappedStiffnessUse::Jacobian => self.stabilisation.stiffness,
            MappedStiffnessUse::Diagnostics => Stiffness::Particle,
        }
    }

    /// The first body containing `p` (bodies earlier in the file take precedence), if any, in a case
    /// of dimension `D`.
    pub fn body_at<const D: usize>(&self, p: [f64; D]) -> Option<&Body> {
        self.bodies.iter().find(|b| self.body_holds(b, p))
    }

    /// Mass density of the material at `p` [kg/m³]: the saturated mixture (1 − n)ρ_s + nρ_w, or 0
    /// outside every body.
    pub fn density_at<const D: usize>(&self, p: [f64; D]) -> f64 {
        self.body_at(p).map_or(0.0, |b| {
            let m = &self.materials[self.material_index(&b.material).expect("validated")];
            (1.0 - m.porosity) * m.solid_density + m.porosity * m.water_density
        })
    }

    /// The top of the material above `p` (the highest point of the bodies on the vertical line
    /// through p, sampled at `dy`), and ∫_y^{top} ρ dy along it [kg/m²].
    pub fn column_above<const D: usize>(&self, p: [f64; D], dy: f64) -> (f64, f64) {
        let top = self.bodies.iter().map(|b| b.shape.bounds().1[1]).fold(p[1], f64::max);
        let n = ((top - p[1]) / dy).ceil().max(1.0) as usize;
        let h = (top - p[1]) / n as f64;
        let (mut mass, mut surface) = (0.0, p[1]);
        for i in 0..n {
            let mut q = p;
            q[1] = p[1] + (i as f64 + 0.5) * h;
            let rho = self.density_at(q);
            mass += rho * h;
            if rho > 0.0 {
                surface = p[1] + (i + 1) as f64 * h;
            }
        }
        (surface, mass)
    }
}

impl SoilModel {
    /// The model with its peak strength divided by the strength reduction factor `f` (a stage's
    /// `strength_reduction`): c_p/f, φ' = atan(tan φ/f) with the dilation angles at most φ', the
    /// residual strength at most the reduced peak; the stiffness unchanged. Models without a
    /// strength (elastic, neo-Hookean, fluid) are returned as they are.
    pub fn with_strength_reduced(&self, f: f64) -> SoilModel {
        let mut m = self.clone();
        match &mut m {
            SoilModel::MohrCoulomb {
                friction_angle,
                cohesion,
                residual_cohesion,
                dilation_angle,
                critical_dilation_angle,
                ..
            } => {
                *cohesion /= f;
                *friction_angle = (friction_angle.to_radians().tan() / f).atan().to_degrees();
                *dilation_angle = dilation_angle.min(*friction_angle);
                *critical_dilation_angle = critical_dilation_angle.map(|psi| psi.min(*friction_angle));
                *residual_cohesion = residual_cohesion.map(|cr| cr.min(*cohesion));
            }
            SoilModel::VonMises { cohesion, residual_cohesion, .. }
            | SoilModel::HenckyJ2 { cohesion, residual_cohesion, .. } => {
                *cohesion /= f;
                *residual_cohesion = residual_cohesion.map(|cr| cr.min(*cohesion));
            }
            SoilModel::LinearElastic { .. } | SoilModel::NeoHookean { .. } | SoilModel::NewtonianFluid { .. } => {}
        }
        m
    }
}

impl Shape {
    /// Bounding box (min, max) [m].
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        match self {
            Shape::Rectangle { min, max } => (*min, *max),
            Shape::Polygon { vertices } => {
                let mut lo = [f64::INFINITY; 2];
                let mut hi = [f64::NEG_INFINITY; 2];
                for v in vertices {
                    for d in 0..2 {
                        lo[d] = lo[d].min(v[d]);
                        hi[d] = hi[d].max(v[d]);
                    }
                }
                (lo, hi)
            }
        }
    }

    /// Whether point `p` lies inside (boundary points of a rectangle count as inside; polygons use
    /// the even–odd rule).
    pub fn contains(&self, p: [f64; 2]) -> bool {
        match self {
            Shape::Rectangle { min, max } => p[0] >= min[0] && p[0] <= max[0] && p[1] >= min[1] && p[1] <= max[1],
            Shape::Polygon { vertices } => {
                let mut inside = false;
                let n = vertices.len();
                let mut j = n - 1;
                for i in 0..n {
                    let (a, b) = (vertices[i], vertices[j]);
                    if (a[1] > p[1]) != (b[1] > p[1]) && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0] {
                        inside = !inside;
                    }
                    j = i;
                }
                inside
            }
        }
    }
}

impl Region {
    /// Whether point `p` lies in the box (boundary included, with a tolerance of 1e-9 of the box's
    /// size and coordinates, so that points on a grid line are not lost to round-off, also when the
    /// box is a line).
    pub fn contains(&self, p: [f64; 2]) -> bool {
        (0..2).all(|d| self.spans(d, p[d], 0.0))
    }

    /// Whether point `p` of a case of dimension `D` lies in the box: [`Region::contains`] in x and
    /// y and, in three dimensions, its `z` range (all of z without one) with the same tolerance.
    pub fn contains_in<const D: usize>(&self, p: [f64; D]) -> bool {
        if !self.contains([p[0], p[1]]) {
            return false;
        }
        D < 3 || self.spans_z(p[2])
    }

    /// Whether `z` lies in the box's `z` range (all of z without one), with the tolerance of
    /// [`Region::contains`].
    pub fn spans_z(&self, z: f64) -> bool {
        match self.z {
            Some([lo, hi]) => {
                let tol = 1e-9 * ((hi - lo).abs() + lo.abs() + hi.abs()) + 1e-15;
                z >= lo - tol && z <= hi + tol
            }
            None => true,
        }
    }

    /// Whether the grid node at `p` lies in the box: as [`Region::contains`], with a further
    /// 1e-9 of the cell size `h`, the round-off of origin + i h (a line at x = 0 holds the node
    /// computed at −2e-15).
    pub fn holds_node(&self, p: [f64; 2], h: [f64; 2]) -> bool {
        (0..2).all(|d| self.spans(d, p[d], 1e-9 * h[d]))
    }

    /// Whether the grid node at `p` of a case of dimension `D` lies in the box: [`Region::holds_node`]
    /// in x and y and, in three dimensions, its `z` range (all of z without one) with the same
    /// tolerance.
    pub fn holds_node_in<const D: usize>(&self, p: [f64; D], h: [f64; D]) -> bool {
        if !self.holds_node([p[0], p[1]], [h[0], h[1]]) {
            return false;
        }
        match (D, self.z) {
            (3, Some([lo, hi])) => {
                let tol = 1e-9 * ((hi - lo).abs() + lo.abs() + hi.abs()) + 1e-15 + 1e-9 * h[2];
                p[2] >= lo - tol && p[2] <= hi + tol
            }
            _ => true,
        }
    }

    /// Whether coordinate `x` of direction `d` lies in the box's range, with `slack` beyond the
    /// tolerance of [`Region::contains`].
    pub fn spans(&self, d: usize, x: f64, slack: f64) -> bool {
        let tol = 1e-9 * ((self.max[d] - self.min[d]).abs() + self.min[d].abs() + self.max[d].abs()) + 1e-15 + slack;
        x >= self.min[d] - tol && x <= self.max[d] + tol
    }
}

/// Case texts shared by unit tests.
#[cfg(test)]
pub(crate) mod tests_support {
    /// A small valid two-phase column.
    pub const MINIMAL: &str = r#"
        [analysis]
        formulation = "two_phase"
        [grid]
        size = [0.1, 1.0]
        cells = [1, 10]
        [[materials]]
        name = "soil"
        porosity = 0.3
        solid_density = 2650.0
        water_bulk_modulus = 2.2e9
        solid_bulk_modulus = inf
        hydraulic_conductivity = 1e-3
        [materials.model]
        type = "linear_elastic"
        young_modulus = 1e7
        poisson_ratio = 0.0
        [[bodies]]
        name = "column"
        material = "soil"
        shape = { rectangle = { min = [0.0, 0.0], max = [0.1, 1.0] } }
        [[stages]]
        name = "load"
        duration = 0.1
        dt = 1e-3
    "#;

    /// [`MINIMAL`] on a grid of `size` [m] and `cells` (TOML arrays: two entries, or three for a
    /// three-dimensional case).
    pub fn with_grid(size: &str, cells: &str) -> String {
        MINIMAL
            .replace("size = [0.1, 1.0]\n        cells = [1, 10]", &format!("size = {size}\n        cells = {cells}"))
    }

    /// [`MINIMAL`] in three dimensions (0.2 × 1.0 × 0.3 m, 2 × 10 × 3 cells) with a base on
    /// `y_min` fixing ux, uy and uz, a back wall on `z_min` fixing the components `back_fix`, and
    /// a region at the top (x ∈ [0, 0.1], z ∈ [0.1, 0.2]) fixing ux, uy, uz and p that moves as
    /// `motion` says (a `displacement` or `velocity` key).
    pub fn solid_with_boundaries(back_fix: &str, motion: &str) -> String {
        with_grid("[0.2, 1.0, 0.3]", "[2, 10, 3]")
            + &format!(
                r#"
            [[boundaries]]
            name = "base"
            side = "y_min"
            fix = ["ux", "uy", "uz"]
            [[boundaries]]
            name = "back"
            side = "z_min"
            fix = {back_fix}
            [[boundaries]]
            name = "top"
            region = {{ min = [0.0, 1.0], max = [0.1, 1.0], z = [0.1, 0.2] }}
            fix = ["ux", "uy", "uz", "p"]
            {motion}
        "#
            )
    }
}

#[cfg(test)]
mod tests {
    use super::tests_support::MINIMAL;
    use super::*;

    /// A line region holds the grid node round-off put a hair beside it (origin −8.4 m, 25 cells
    /// of 2.8 m: the node meant for x = 0 at −1.8e-15 m), and not the node a cell away.
    #[test]
    fn a_line_region_holds_the_node_on_its_line() {
        let clamp = Region { min: [0.0, -1.0], max: [0.0, 1.0], z: None };
        let (origin, h) = (-8.4f64, 2.8f64);
        let x = origin + 3.0 * h;
        assert!(x != 0.0 && x.abs() < 1e-14, "{x}");
        assert!(!clamp.contains([x, 0.0]));
        assert!(clamp.holds_node([x, 0.0], [h, h]));
        assert!(!clamp.holds_node([x + h, 0.0], [h, h]));
    }

    /// The names the messages use are the case file's.
    #[test]
    fn stiffness_names_are_the_case_file_s() {
        for s in [
            Stiffness::Particle,
            Stiffness::WStar,
            Stiffness::GaussMapping,
            Stiffness::DoubleMapping,
            Stiffness::DoubleMappingGimp,
        ] {
            assert_eq!(serde_json::to_value(s).unwrap(), s.name());
        }
    }

    #[test]
    fn a_minimal_case_parses_with_defaults() {
        let c = parse(MINIMAL, "t.toml", &[]).unwrap();
        assert_eq!(c.analysis.shape_functions, ShapeFunctions::Gimp);
        assert_eq!(c.time_integration.newmark().0, 0.25);
        assert_eq!(c.cell_size(), [0.1, 0.1]);
        assert!(c.materials[0].solid_bulk_modulus.unwrap().is_infinite());
    }

    #[test]
    fn unknown_keys_and_wrong_types_name_the_key() {
        let e = parse(&MINIMAL.replace("porosity = 0.3", "porosity = 0.3\nporosty = 1"), "t.toml", &[]).unwrap_err();
        assert!(e.to_string().contains("materials[0]") && e.to_string().contains("porosty"), "{e}");
        let e = parse(&MINIMAL.replace("cells = [1, 10]", "cells = [1, \"ten\"]"), "t.toml", &[]).unwrap_err();
        assert!(e.to_string().contains("grid.cells"), "{e}");
        let e = parse(MINIMAL, "t.toml", &[Override::parse("grid.cels=[2,20]").unwrap()]).unwrap_err();
        assert!(e.to_string().contains("--set grid.cels") && e.to_string().contains("unknown field"), "{e}");
    }

    #[test]
    fn overrides_change_values() {
        let c = parse(
            MINIMAL,
            "t.toml",
            &[Override::parse("grid.cells=[2,20]").unwrap(), Override::parse("stages[0].dt=5e-4").unwrap()],
        )
        .unwrap();
        assert_eq!(c.cells(), [2, 20]);
        assert_eq!(c.stages[0].dt(), 5e-4);
        // A stage without its own step takes time.dt.
        let no_dt =
            MINIMAL.replace("dt = 1e-3", "").replace("[[stages]]", "[time]\n        dt = 2e-3\n        [[stages]]");
        let c = parse(&no_dt, "t.toml", &[Override::parse("time.dt=4e-3").unwrap()]).unwrap();
        assert_eq!(c.stages[0].dt(), 4e-3);
        let e = parse(&MINIMAL.replace("dt = 1e-3", ""), "t.toml", &[]).unwrap_err();
        assert!(e.to_string().contains("stages[0].dt"), "{e}");
    }

    #[test]
    fn shapes_contain_points() {
        let poly = Shape::Polygon { vertices: vec![[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]] };
        assert!(poly.contains([0.5, 0.5]));
        assert!(!poly.contains([1.5, 1.5]));
        let r = Region { min: [0.0, 1.0], max: [1.0, 1.0], z: None };
        assert!(r.contains([0.5, 1.0 + 1e-12]));
        assert!(!r.contains([0.5, 1.01]));
    }

    /// A strength reduction factor F divides c_p and tan φ, keeps ψ ≤ φ' and c_r ≤ c_p/F, leaves
    /// the stiffness and a residual below the reduced peak alone, and leaves models without a
    /// strength unchanged.
    #[test]
    fn a_strength_reduction_divides_the_peak_strength() {
        let mc = SoilModel::MohrCoulomb {
            young_modulus: 1e7,
            poisson_ratio: 0.3,
            friction_angle: 30.0,
            cohesion: 10e3,
            residual_cohesion: Some(8e3),
            softening_strain: Some(0.1),
            dilation_angle: 25.0,
            critical_dilation_angle: Some(5.0),
            dilation_decay: 0.0,
            tension_cutoff: None,
        };
        let SoilModel::MohrCoulomb {
            young_modulus,
            friction_angle,
            cohesion,
            residual_cohesion,
            dilation_angle,
            critical_dilation_angle,
            ..
        } = mc.with_strength_reduced(2.0)
        else {
            unreachable!()
        };
        assert_eq!(young_modulus, 1e7);
        assert_eq!(cohesion, 5e3);
        let phi = (30f64.to_radians().tan() / 2.0).atan().to_degrees();
        assert!((friction_angle - phi).abs() < 1e-12 && (phi - 16.102).abs() < 1e-3, "{friction_angle}");
        assert_eq!(dilation_angle, friction_angle);
        assert_eq!(critical_dilation_angle, Some(5.0));
        assert_eq!(residual_cohesion, Some(5e3));
        let hj = SoilModel::HenckyJ2 {
            young_modulus: 25e6,
            poisson_ratio: 0.499,
            cohesion: 28868.0,
            residual_cohesion: Some(1732.0),
            softening_rate: 5.0,
        };
        let SoilModel::HenckyJ2 { cohesion, residual_cohesion, softening_rate, .. } = hj.with_strength_reduced(1.65)
        else {
            unreachable!()
        };
        assert!((cohesion - 28868.0 / 1.65).abs() < 1e-9);
        assert_eq!((residual_cohesion, softening_rate), (Some(1732.0), 5.0));
        let el = SoilModel::LinearElastic { young_modulus: 1e6, poisson_ratio: 0.3 };
        assert!(matches!(
            el.with_strength_reduced(3.0),
            SoilModel::LinearElastic { young_modulus, poisson_ratio } if young_modulus == 1e6 && poisson_ratio == 0.3
        ));
    }
}
