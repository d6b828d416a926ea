//! The files of `porompm element-test`: a soil model and a load path for one material point.
//!
//! MATERIAL.toml holds the `model` table exactly as a case's `[materials.model]` (and an optional
//! `name`). PATH.toml holds the initial state and segments; in each segment every stress-vector
//! component (xx, yy, xy, zz and the out-of-plane shears yz, zx; tension positive) is either
//! strain-controlled, `{ strain = Δε }` (the change over the segment, engineering shears γ for
//! xy, yz, zx), or stress-controlled, `{ stress = σ }` (the value reached at the end of the
//! segment, approached linearly from the value at its start). yz and zx default to
//! `{ strain = 0.0 }`, which with `zz = { strain = 0.0 }` is plane strain. Examples live in
//! `element_tests/`.

use crate::case::{CaseError, SoilModel};
use crate::soils::{Stress, NS};
use serde::{Deserialize, Serialize};

/// MATERIAL.toml.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialFile {
    /// A label for the output.
    #[serde(default)]
    pub name: Option<String>,
    /// The soil model (as `[materials.model]` in a case).
    pub model: SoilModel,
}

/// How one stress component is driven in a segment.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Control {
    /// Change of the strain component over the segment [-] (engineering γ for xy).
    Strain(f64),
    /// Stress component at the end of the segment [Pa].
    Stress(f64),
}

/// One segment of a load path.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Segment {
    /// Label in the output.
    #[serde(default)]
    pub name: Option<String>,
    /// Number of equal increments.
    pub steps: usize,
    /// σ_xx / ε_xx.
    pub xx: Control,
    /// σ_yy / ε_yy.
    pub yy: Control,
    /// σ_xy / γ_xy.
    pub xy: Control,
    /// σ_zz / ε_zz (ε_zz = 0 is plane strain).
    pub zz: Control,
    /// σ_yz / γ_yz (default: no strain).
    #[serde(default = "no_strain")]
    pub yz: Control,
    /// σ_zx / γ_zx (default: no strain).
    #[serde(default = "no_strain")]
    pub zx: Control,
}

fn no_strain() -> Control {
    Control::Strain(0.0)
}

/// PATH.toml.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LoadPath {
    /// Stress at the start [xx, yy, xy, zz] or [xx, yy, xy, zz, yz, zx] [Pa] (default zero).
    #[serde(default)]
    pub initial_stress: Vec<f64>,
    /// Accumulated deviatoric plastic strain at the start [-].
    #[serde(default)]
    pub initial_plastic_strain: f64,
    /// The segments, in order.
    pub segments: Vec<Segment>,
}

impl Segment {
    /// The controls in component order.
    pub fn controls(&self) -> [Control; NS] {
        [self.xx, self.yy, self.xy, self.zz, self.yz, self.zx]
    }
}

/// The names of the components, in order.
pub const COMPONENTS: [&str; NS] = ["xx", "yy", "xy", "zz", "yz", "zx"];

impl LoadPath {
    /// The stress at the start (zero when not given; yz = zx = 0 when four components are given).
    pub fn initial(&self) -> Stress {
        let mut s = [0.0; NS];
        s[..self.initial_stress.len()].copy_from_slice(&self.initial_stress);
        s
    }
}

fn parse_toml<T: serde::de::DeserializeOwned>(text: &str, origin: &str) -> Result<T, CaseError> {
    let doc: toml::Value =
        toml::from_str(text).map_err(|e| CaseError::new(format!("{origin}: {}", e.message().trim())))?;
    serde_path_to_error::deserialize(doc).map_err(|e| {
        let path = e.path().to_string();
        let msg = e.inner().message().trim().to_string();
        if path == "." || path.is_empty() {
            CaseError::new(format!("{origin}: {msg}"))
        } else {
            CaseError::new(format!("{origin}: key `{path}`: {msg}"))
        }
    })
}

/// Parses and validates MATERIAL.toml.
pub fn parse_material(text: &str, origin: &str) -> Result<MaterialFile, CaseError> {
    let m: MaterialFile = parse_toml(text, origin)?;
    m.model.check("model").map_err(|e| CaseError::new(format!("{origin}: {e}")))?;
    if m.model.is_finite_strain() {
        return Err(CaseError::new(format!(
            "{origin}: key `model.type`: the element test drives incremental models along strain increments; \
             the finite-strain models (`neo_hookean`, `hencky_j2`, `newtonian_fluid`) follow the deformation gradient and are not \
             supported"
        )));
    }
    Ok(m)
}

/// Parses and validates PATH.toml.
pub fn parse_path(text: &str, origin: &str) -> Result<LoadPath, CaseError> {
    let p: LoadPath = parse_toml(text, origin)?;
    let err = |m: String| CaseError::new(format!("{origin}: {m}"));
    if p.segments.is_empty() {
        return Err(err("at least one [[segments]] table is needed".into()));
    }
    if !matches!(p.initial_stress.len(), 0 | 4 | NS) {
        return Err(err(format!(
            "key `initial_stress`: give 4 components [xx, yy, xy, zz] or 6 [xx, yy, xy, zz, yz, zx], not {}",
            p.initial_stress.len()
        )));
    }
    if p.initial_stress.iter().any(|v| !v.is_finite()) {
        return Err(err("key `initial_stress`: must be finite".into()));
    }
    if !(p.initial_plastic_strain.is_finite() && p.initial_plastic_strain >= 0.0) {
        return Err(err("key `initial_plastic_strain`: must be a non-negative number".into()));
    }
    for (i, s) in p.segments.iter().enumerate() {
        if s.steps == 0 {
            return Err(err(format!("key `segments[{i}].steps`: must be at least 1")));
        }
        for (name, c) in COMPONENTS.iter().zip(s.controls()) {
            let v = match c {
                Control::Strain(v) | Control::Stress(v) => v,
            };
            if !v.is_finite() {
                return Err(err(format!("key `segments[{i}].{name}`: must be finite")));
            }
        }
    }
    Ok(p)
}
