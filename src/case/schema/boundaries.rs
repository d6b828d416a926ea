//! `[[boundaries]]`: Dirichlet conditions on grid nodes, the sides of the grid and the nodal
//! degrees of freedom they name.

use super::bodies::Region;
use super::from_files::MeshBoundary;
use crate::check::{at, Checked};
use serde::{Deserialize, Serialize};

/// Dirichlet conditions on the grid nodes of a side, of a box or of a body's moving surface: the
/// listed components are fixed, to zero (drained p = 0, a fixed or sliding wall), or moving with a
/// prescribed displacement or velocity (a loading platen, a displacement-driven rigid footing: all
/// its nodes move together, and the boundary's reaction is the force that drives it), or tied to
/// one unknown displacement per direction that a prescribed `force` drives (a rigid plate or
/// footing under a load; with `force_point`, also to its rotation about that point).
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Boundary {
    /// The name stages and the verification give to use it.
    pub name: String,
    /// A side of the grid (give exactly one of `side`, `region`, `surface` and `mesh`).
    pub side: Option<Side>,
    /// The nodes inside this box, at least one (give exactly one of `side`, `region`, `surface`
    /// and `mesh`).
    pub region: Option<Region>,
    /// The nodes on a physical group of a Gmsh mesh's boundary, at least one: `{ file, group }`
    /// (give exactly one of `side`, `region`, `surface` and `mesh`).
    pub mesh: Option<MeshBoundary>,
    /// The moving surface of a body: the nodes on or beyond the exposed faces of its boundary
    /// particles, found again every step (a drained free surface: `fix = ["p"]`; in the
    /// quasi-static u–p system p = 0 is imposed on the faces themselves, by Nitsche's method).
    pub surface: Option<Surface>,
    /// Components fixed: `ux`, `uy`, `uz`, `Ux`, `Uy`, `Uz` and `p` (drained), at least one unless
    /// `impermeable` lists some. In a one_phase analysis the water-phase components have no dofs
    /// and are ignored. Fixed to zero unless `displacement` or `velocity` moves them.
    #[serde(default)]
    pub fix: Vec<Dof>,
    /// Water components (`Ux`, `Uy`, `Uz`) that follow the solid's at the boundary's nodes, U_d =
    /// u_d, with the solid free: a surface that moves with the material and lets no water across
    /// it in those directions (U·n = u·n on a face normal to d). Used by the u–p–U system (a u–p
    /// system's surfaces are impermeable unless drained; a one_phase analysis has no water); not a
    /// component `fix` lists.
    #[serde(default)]
    pub impermeable: Vec<Dof>,
    /// Prescribed displacement [m] of the fixed displacement components: at time t the nodes have
    /// moved by `displacement` × f(t) (f the time function; constant 1 without one). Fixed water
    /// components move with the solid (the boundary is impermeable to flow across it).
    /// Two components in a plane case, three in a three-dimensional one.
    pub displacement: Option<Vec<f64>>,
    /// Prescribed velocity [m/s] of the fixed displacement components, scaled by the time function:
    /// the nodes move by ∫ `velocity` f(t) dt. One component per dimension; not with
    /// `displacement`.
    pub velocity: Option<Vec<f64>>,
    /// A velocity gradient L [1/s] of a homogeneous flow about `center`, scaled by the time
    /// function with `velocity` (its translation part, default zero): over a step the node at x moves
    /// by (exp(L s) − I)(x − c) + v s with s = ∫ f dt — exactly the step of a uniform deformation
    /// (e.g. a rigid rotation ω: L = [[0, −ω], [ω, 0]]). Rows L_ij = ∂v_i/∂x_j: two rows of two in a
    /// plane case, three rows of three in a three-dimensional one. `fix` must list every
    /// displacement component.
    pub velocity_gradient: Option<Vec<Vec<f64>>>,
    /// Centre c of the `velocity_gradient`'s flow [m] (default: the origin); one coordinate per
    /// dimension.
    pub center: Option<Vec<f64>>,
    /// A rigid body's load [N per metre of thickness in plane strain, N on the full ring in
    /// axial symmetry, N in three dimensions], scaled by the time function: the nodes' listed
    /// displacement components move together by one unknown per direction (a rigid plate or
    /// footing in translation; with `force_point` also in rotation; listed water components move
    /// with them, so the body is impermeable), and the boundary's reaction on the material is
    /// this force. One component per dimension;
    /// each non-zero one along a direction `fix` lists; not with `displacement`, `velocity` or
    /// `velocity_gradient`; implicit stages only.
    pub force: Option<Vec<f64>>,
    /// Where the `force` acts [m], one coordinate per dimension: given, the rigid body also
    /// rotates, by a small rotation about this point (about z in plane strain; about x, y and z in
    /// three dimensions, as far as the tied components see it: a plate tying only its normal
    /// component tilts but does not twist), so that an eccentric load tilts a footing;
    /// `<name>.rotation_*` and `<name>.reaction_moment_*` in history.csv. Not in axial symmetry.
    pub force_point: Option<Vec<f64>>,
    /// The name of the time function scaling `displacement`, `velocity`, `velocity_gradient` or
    /// `force` (default: a constant 1).
    pub time_function: Option<String>,
}

/// The faces of a body's surface.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Surface {
    /// The name of the body.
    pub body: String,
    /// Which faces, at least one: the particles whose face in one of these directions is exposed
    /// at t = 0.
    pub faces: Vec<Side>,
    /// Only the particles whose centres lie in this box at t = 0 (default: all of the body's), e.g.
    /// the part of the ground under a footing [m]. The box also bounds the nodes fixed along each
    /// face (x for a y face, y for an x face; the box stays where it is at t = 0), so that a
    /// footing's edge stays at the box's edge; put that edge on a grid line (a boundary fixes whole
    /// nodes).
    pub region: Option<Region>,
}

/// A side of the background grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// x = origin_x.
    XMin,
    /// x = origin_x + size_x.
    XMax,
    /// y = origin_y.
    YMin,
    /// y = origin_y + size_y.
    YMax,
    /// z = origin_z (three-dimensional cases).
    ZMin,
    /// z = origin_z + size_z (three-dimensional cases).
    ZMax,
}

impl Side {
    /// The direction the side is normal to (0: x, 1: y, 2: z).
    pub fn axis(&self) -> usize {
        match self {
            Side::XMin | Side::XMax => 0,
            Side::YMin | Side::YMax => 1,
            Side::ZMin | Side::ZMax => 2,
        }
    }

    /// The sign of its outward normal along [`Side::axis`].
    pub fn sign(&self) -> f64 {
        match self {
            Side::XMin | Side::YMin | Side::ZMin => -1.0,
            Side::XMax | Side::YMax | Side::ZMax => 1.0,
        }
    }
}

/// A nodal degree of freedom.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize, Serialize, schemars::JsonSchema)]
pub enum Dof {
    /// Solid displacement, x.
    #[serde(rename = "ux")]
    Ux,
    /// Solid displacement, y.
    #[serde(rename = "uy")]
    Uy,
    /// Pore pressure.
    #[serde(rename = "p")]
    P,
    /// Water displacement, x.
    #[serde(rename = "Ux")]
    WUx,
    /// Water displacement, y.
    #[serde(rename = "Uy")]
    WUy,
    /// Solid displacement, z (three-dimensional cases).
    #[serde(rename = "uz")]
    Uz,
    /// Water displacement, z (three-dimensional cases).
    #[serde(rename = "Uz")]
    WUz,
}

impl std::fmt::Display for Dof {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Dof::Ux => "ux",
            Dof::Uy => "uy",
            Dof::P => "p",
            Dof::WUx => "Ux",
            Dof::WUy => "Uy",
            Dof::Uz => "uz",
            Dof::WUz => "Uz",
        })
    }
}

impl Boundary {
    /// Whether the boundary moves its nodes (a `displacement`, a `velocity` or a
    /// `velocity_gradient`).
    pub fn moves(&self) -> bool {
        self.displacement.is_some() || self.velocity.is_some() || self.velocity_gradient.is_some()
    }

    /// Checks what the boundary's keys require of each other; `key` is its table
    /// (`boundaries[0]`). What depends on the case's dimension and grid, and its names, validation
    /// checks.
    pub fn check(&self, key: &str) -> Checked {
        let given = [self.side.is_some(), self.region.is_some(), self.surface.is_some(), self.mesh.is_some()];
        if given.iter().filter(|&&x| x).count() != 1 {
            return Err(format!("key `{key}`: give exactly one of `side`, `region`, `surface` and `mesh`"));
        }
        if self.surface.as_ref().is_some_and(|sf| sf.faces.is_empty()) {
            return Err(format!("key `{key}.surface.faces`: list at least one face"));
        }
        if self.fix.is_empty() && self.impermeable.is_empty() {
            return Err(format!("key `{}`: list at least one component (or an `impermeable` one)", at(key, "fix")));
        }
        if let Some(d) = self.impermeable.iter().find(|d| !matches!(d, Dof::WUx | Dof::WUy | Dof::WUz)) {
            return Err(format!(
                "key `{key}.impermeable`: lists water components (`Ux`, `Uy`, `Uz`), which follow the solid's; got `{d}`"
            ));
        }
        if let Some(d) = self.impermeable.iter().find(|d| self.fix.contains(d)) {
            return Err(format!(
                "key `{key}.impermeable`: `{d}` is also in `fix`; a fixed water component is held (or moves with a \
                 prescribed motion), an impermeable one follows the free solid"
            ));
        }
        if self.displacement.is_some() && self.velocity.is_some() {
            return Err(format!("key `{key}`: give `displacement` or `velocity`, not both"));
        }
        if let Some(l) = &self.velocity_gradient {
            if self.displacement.is_some() {
                return Err(format!("key `{key}.velocity_gradient`: goes with `velocity`, not `displacement`"));
            }
            if l.iter().flatten().any(|v| !v.is_finite()) {
                return Err(format!("key `{key}.velocity_gradient`: must be finite"));
            }
        }
        if self.center.is_some() && self.velocity_gradient.is_none() {
            return Err(format!("key `{key}.center`: is the centre of a `velocity_gradient`, not given"));
        }
        if self.force.is_some() && self.moves() {
            return Err(format!(
                "key `{key}.force`: drives a rigid body whose motion is unknown; not with a prescribed \
                 `displacement`, `velocity` or `velocity_gradient`"
            ));
        }
        if self.force_point.is_some() && self.force.is_none() {
            return Err(format!("key `{key}.force_point`: is where a `force` acts, and no `force` is given"));
        }
        if self.force_point.as_ref().is_some_and(|x| x.iter().any(|v| !v.is_finite())) {
            return Err(format!("key `{key}.force_point`: must be finite"));
        }
        if self.time_function.is_some() && !self.moves() && self.force.is_none() {
            return Err(format!(
                "key `{key}.time_function`: only a `displacement`, `velocity` or `force` has a time function"
            ));
        }
        Ok(())
    }
}
