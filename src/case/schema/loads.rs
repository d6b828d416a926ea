//! `[[loads]]` and `[[time_functions]]`: tractions, pressures and body forces, and the functions of
//! time that scale them.

use super::bodies::Region;
use super::boundaries::Side;
use crate::check::{at, finite, finite_points, positive, Checked};
use serde::{Deserialize, Serialize};

/// A load, scaled in time by a named time function (default: constant 1), chosen by its `kind`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Load {
    /// A traction [Pa] on one face of the particle domains whose centres lie in `region` at t = 0
    /// and whose face is on the surface of the material (the point just beyond it is outside every
    /// body), applied at the face centre (force = traction × the face's length per metre of
    /// thickness in two dimensions, × its area in three).
    ParticleTraction(ParticleTraction),
    /// A traction [Pa] on the line (plane) or surface (three dimensions) of grid nodes inside
    /// `region`, each node taking its tributary length of the line or the product of its tributary
    /// lengths along the surface. The load stays on that grid line: when the loaded surface moves
    /// off it by δ, the stress of the particles in the cell below is too large by about h/(h − δ)
    /// (the force passes through a partly filled cell). Use a `particle_traction`, which follows the
    /// surface, when the surface moves by more than a small fraction of a cell.
    NodalTraction(NodalTraction),
    /// A pressure [Pa] on a polyline fixed in space (e.g. the inside of a cylinder; plane and
    /// axisymmetric cases only), pushing the material that lies on the left of the direction of
    /// travel along `points`: the force per metre is p n with n the unit normal to the left. It is
    /// integrated along each segment with two Gauss points and distributed with the bilinear hat
    /// functions of the cell holding each point (nodes the material does not fill pass their share
    /// to filled ones). Fixed in space: for small deformations.
    LinePressure(LinePressure),
    /// A pressure [Pa] on a surface fixed in space (three-dimensional cases only): a Gmsh mesh's
    /// physical surface or an STL file's triangles (e.g. the inside of a cavity, a loaded slab),
    /// pushing the material on the side of the surface it fills: the force on each Gauss point (of
    /// order 2) of its cells is p times its share of the area along the normal into the material,
    /// which must lie on one side only, within a quarter cell. Distributed as a `line_pressure`'s;
    /// fixed in space: for small deformations.
    SurfacePressure(SurfacePressure),
    /// A body acceleration [m/s²] on every particle (gravity: [0, -9.81], or [0, -9.81, 0] in three
    /// dimensions), acting on both phases.
    BodyForce(BodyForce),
}

/// The parameters of `kind = "particle_traction"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ParticleTraction {
    /// The name stages and the verification give to use it.
    pub name: String,
    /// The particles carrying it: those whose centres lie inside at t = 0.
    pub region: Region,
    /// The name of the only body whose particles carry it (default: any).
    pub body: Option<String>,
    /// Which face of each particle domain carries it.
    pub face: Side,
    /// Traction vector [Pa]: two components in a plane case, three in a three-dimensional one.
    pub traction: Vec<f64>,
    /// The name of the time function scaling it (default: a constant 1).
    pub time_function: Option<String>,
    /// An expression in `x` and `y` [m] (and `z` in a three-dimensional case, and the case's
    /// parameters) that scales each step's increment of the load by where the loaded faces are
    /// at the start of the step: over the step from t_n to t_{n+1} the traction grows by
    /// `traction` × (f(t_{n+1}) − f(t_n)) × g(x̄_n, ȳ_n[, z̄_n]), with (x̄_n, ȳ_n[, z̄_n]) the
    /// area-weighted mean centre of the loaded faces at t_n.
    /// The total is the sum of the increments, each applied where the surface was (e.g.
    /// [001]'s internal pressure re-evaluated at the current inner radius,
    /// `"A / x^2 + 2 * C"`). Written without the leading `=` (it is evaluated during the run,
    /// not when the case is read). Without it the traction is `traction` × f(t).
    pub increment_factor: Option<String>,
}

/// The parameters of `kind = "nodal_traction"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NodalTraction {
    /// The name stages and the verification give to use it.
    pub name: String,
    /// The nodes carrying it: a row or column of nodes in the plane, a layer of nodes in three
    /// dimensions (one node thick in one direction).
    pub region: Region,
    /// Traction vector [Pa]: two components in a plane case, three in a three-dimensional one.
    pub traction: Vec<f64>,
    /// The name of the time function scaling it (default: a constant 1).
    pub time_function: Option<String>,
}

/// The parameters of `kind = "line_pressure"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LinePressure {
    /// The name stages and the verification give to use it.
    pub name: String,
    /// The polyline's points [m], at least two, inside the grid.
    pub points: Vec<[f64; 2]>,
    /// The pressure p [Pa].
    pub pressure: f64,
    /// The name of the time function scaling it (default: a constant 1).
    pub time_function: Option<String>,
}

/// The parameters of `kind = "surface_pressure"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SurfacePressure {
    /// The name stages and the verification give to use it.
    pub name: String,
    /// The surface: `{ mesh = { file = "dam.msh", group = "upstream_face" } }` or
    /// `{ stl = { file = "slab.stl" } }`.
    pub surface: super::from_files::LoadSurface,
    /// The pressure p [Pa].
    pub pressure: f64,
    /// The name of the time function scaling it (default: a constant 1).
    pub time_function: Option<String>,
}

/// The parameters of `kind = "body_force"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BodyForce {
    /// The name stages and the verification give to use it.
    pub name: String,
    /// Acceleration vector [m/s²]: two components in a plane case, three in a three-dimensional
    /// one.
    pub acceleration: Vec<f64>,
    /// The names of the bodies it acts on (default: all), e.g. a footing whose unit weight is
    /// ramped up.
    pub bodies: Option<Vec<String>>,
    /// The name of the time function scaling it (default: a constant 1).
    pub time_function: Option<String>,
}

impl Load {
    /// The `kind` the case file names.
    pub fn kind(&self) -> &'static str {
        match self {
            Load::ParticleTraction(_) => "particle_traction",
            Load::NodalTraction(_) => "nodal_traction",
            Load::LinePressure(_) => "line_pressure",
            Load::SurfacePressure(_) => "surface_pressure",
            Load::BodyForce(_) => "body_force",
        }
    }

    /// The load's name and the name of its time function (the keys every kind has).
    fn common(&self) -> (&str, Option<&str>) {
        match self {
            Load::ParticleTraction(l) => (&l.name, l.time_function.as_deref()),
            Load::NodalTraction(l) => (&l.name, l.time_function.as_deref()),
            Load::LinePressure(l) => (&l.name, l.time_function.as_deref()),
            Load::SurfacePressure(l) => (&l.name, l.time_function.as_deref()),
            Load::BodyForce(l) => (&l.name, l.time_function.as_deref()),
        }
    }

    /// The load's name.
    pub fn name(&self) -> &str {
        self.common().0
    }

    /// The name of its time function, if any.
    pub fn time_function(&self) -> Option<&str> {
        self.common().1
    }

    /// The expression scaling its increments by the loaded faces' position, if any (see
    /// [`ParticleTraction::increment_factor`]).
    pub fn increment_factor(&self) -> Option<&str> {
        match self {
            Load::ParticleTraction(l) => l.increment_factor.as_deref(),
            _ => None,
        }
    }

    /// The traction vector of a particle or nodal traction [Pa].
    pub fn traction(&self) -> Option<&[f64]> {
        match self {
            Load::ParticleTraction(l) => Some(&l.traction),
            Load::NodalTraction(l) => Some(&l.traction),
            Load::LinePressure(_) | Load::SurfacePressure(_) | Load::BodyForce(_) => None,
        }
    }

    /// The names of the bodies a load is limited to, if it is (a particle traction's `body`, a
    /// body force's `bodies`).
    pub fn body_names(&self) -> Option<&[String]> {
        match self {
            Load::ParticleTraction(l) => l.body.as_ref().map(std::slice::from_ref),
            Load::BodyForce(l) => l.bodies.as_deref(),
            Load::NodalTraction(_) | Load::LinePressure(_) | Load::SurfacePressure(_) => None,
        }
    }

    /// Checks the load's own values; `key` is its table (`loads[0]`). The number of components,
    /// the grid it must lie in and its names depend on the rest of the case: validation checks them.
    pub fn check(&self, key: &str) -> Checked {
        match self {
            Load::ParticleTraction(l) => l.region.check(&at(key, "region")),
            Load::NodalTraction(l) => l.region.check(&at(key, "region")),
            Load::LinePressure(l) => l.check(key),
            Load::SurfacePressure(l) => {
                l.surface.check(&at(key, "surface"))?;
                finite(&at(key, "pressure"), l.pressure)
            }
            Load::BodyForce(_) => Ok(()),
        }
    }
}

impl LinePressure {
    /// Checks the points and the pressure; `key` is the load's table.
    pub fn check(&self, key: &str) -> Checked {
        finite_points(key, "points", &self.points, 2, "a line")?;
        finite(&at(key, "pressure"), self.pressure)
    }
}

/// A scalar function of the analysis time t [s] multiplying a load or a boundary's motion, chosen
/// by its `type`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum TimeFunction {
    /// f = value.
    Constant(Constant),
    /// f rises linearly from 0 at `start` to 1 at `start + duration` [s], then stays 1.
    Ramp(Ramp),
    /// As `ramp` but with the C² smoothstep 6s⁵ − 15s⁴ + 10s³ (no jump in rate or acceleration).
    SmoothRamp(Ramp),
    /// f = cos(ω t + φ), multiplied by a smooth ramp over `ramp_duration` [s] if it is positive.
    Harmonic(Harmonic),
    /// Piecewise linear through (times[i], values[i]); constant outside.
    Table(Table),
}

/// The parameters of `type = "constant"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Constant {
    /// The name loads and boundaries give to use it.
    pub name: String,
    /// The value [-], finite.
    pub value: f64,
}

/// The parameters of `type = "ramp"` and `type = "smooth_ramp"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Ramp {
    /// The name loads and boundaries give to use it.
    pub name: String,
    /// When the rise starts [s], ≥ 0 (default 0).
    #[serde(default)]
    pub start: f64,
    /// How long the rise takes [s], > 0.
    pub duration: f64,
}

/// The parameters of `type = "harmonic"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Harmonic {
    /// The name loads and boundaries give to use it.
    pub name: String,
    /// The angular frequency ω [rad/s], > 0.
    pub angular_frequency: f64,
    /// The phase φ [rad], finite (default 0).
    #[serde(default)]
    pub phase: f64,
    /// The duration of the smooth start [s], ≥ 0 (default 0: none).
    #[serde(default)]
    pub ramp_duration: f64,
}

/// The parameters of `type = "table"`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Table {
    /// The name loads and boundaries give to use it.
    pub name: String,
    /// Times [s], finite and strictly increasing, at least one.
    pub times: Vec<f64>,
    /// The values at those times [-], finite, as many as `times`.
    pub values: Vec<f64>,
}

impl TimeFunction {
    /// The `type` the case file names.
    pub fn kind(&self) -> &'static str {
        match self {
            TimeFunction::Constant(_) => "constant",
            TimeFunction::Ramp(_) => "ramp",
            TimeFunction::SmoothRamp(_) => "smooth_ramp",
            TimeFunction::Harmonic(_) => "harmonic",
            TimeFunction::Table(_) => "table",
        }
    }

    /// The function's name.
    pub fn name(&self) -> &str {
        match self {
            TimeFunction::Constant(f) => &f.name,
            TimeFunction::Ramp(f) | TimeFunction::SmoothRamp(f) => &f.name,
            TimeFunction::Harmonic(f) => &f.name,
            TimeFunction::Table(f) => &f.name,
        }
    }

    /// Checks the function's parameters; `key` is its table (`time_functions[0]`).
    pub fn check(&self, key: &str) -> Checked {
        match self {
            TimeFunction::Constant(f) => finite(&at(key, "value"), f.value),
            TimeFunction::Ramp(f) | TimeFunction::SmoothRamp(f) => f.check(key),
            TimeFunction::Harmonic(f) => f.check(key),
            TimeFunction::Table(f) => f.check(key),
        }
    }
}

/// A finite number of at least zero, with the message of a start or a duration.
fn at_least_zero(key: &str, v: f64) -> Checked {
    if !v.is_finite() || v < 0.0 {
        return Err(format!("key `{key}`: must be ≥ 0, got {v}"));
    }
    Ok(())
}

impl Ramp {
    /// Checks the start and the duration; `key` is the function's table.
    pub fn check(&self, key: &str) -> Checked {
        positive(&at(key, "duration"), self.duration)?;
        at_least_zero(&at(key, "start"), self.start)
    }
}

impl Harmonic {
    /// Checks ω, φ and the ramp; `key` is the function's table.
    pub fn check(&self, key: &str) -> Checked {
        positive(&at(key, "angular_frequency"), self.angular_frequency)?;
        finite(&at(key, "phase"), self.phase)?;
        at_least_zero(&at(key, "ramp_duration"), self.ramp_duration)
    }
}

impl Table {
    /// Checks that the times increase and the values are as many; `key` is the function's table.
    pub fn check(&self, key: &str) -> Checked {
        let (times, values) = (&self.times, &self.values);
        if times.is_empty() || times.len() != values.len() {
            return Err(format!("key `{}`: times and values must be non-empty and of equal length", at(key, "times")));
        }
        if times.windows(2).any(|w| w[1] <= w[0]) || times.iter().chain(values).any(|v| !v.is_finite()) {
            return Err(format!("key `{}`: times must be finite and strictly increasing", at(key, "times")));
        }
        Ok(())
    }
}
