//! Which unknowns a grid node carries and where ([`Layout`]): the one fact about an analysis
//! type that the model, the kernels and the assembly all need.

/// Largest number of dofs per node in two dimensions (u–p–U: 2D + 1), the size of a plane
/// [`NodeState`].
pub const MAX_DOF: usize = 5;
/// Largest number of dofs per node in three dimensions (u–p–U: 2D + 1).
pub const MAX_DOF_3D: usize = 7;
/// Component indices within a node of the two-phase layout.
pub mod dof {
    /// Solid displacement x.
    pub const UX: usize = 0;
    /// Solid displacement y.
    pub const UY: usize = 1;
    /// Pore pressure.
    pub const P: usize = 2;
    /// Water displacement x.
    pub const WX: usize = 3;
    /// Water displacement y.
    pub const WY: usize = 4;
}

/// Which unknowns a node carries and where: the solid displacement always at 0 and 1, then the
/// pore pressure and the water displacement if the system has them, and last the projected volume
/// ratio of an implicit F̄ step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    /// The spatial dimension: the solid (and the water) displacement has this many components.
    pub dim: usize,
    /// Dofs per node.
    pub nd: usize,
    /// Offset of the pore pressure.
    pub p: Option<usize>,
    /// Offset of the water displacement's x component.
    pub w: Option<usize>,
    /// Offset of ϑ = J̄ − 1, the nodal value of [002]'s projected volume ratio in an implicit
    /// step with F̄ ([`fbar`]; `stabilisation.fbar`).
    pub jbar: Option<usize>,
}

impl Layout {
    /// u (one-phase: total stress or dry).
    pub const U: Layout = Layout { dim: 2, nd: 2, p: None, w: None, jbar: None };
    /// u–p (the quasi-static Biot system, or undrained static): solid displacement and pore
    /// pressure; the water follows the solid plus its Darcy flux.
    pub const UP: Layout = Layout { dim: 2, nd: 3, p: Some(dof::P), w: None, jbar: None };
    /// u–p–U.
    pub const UPU: Layout = Layout { dim: 2, nd: 5, p: Some(dof::P), w: Some(dof::WX), jbar: None };
    /// u–U (the explicit two-phase system, the "v–w form"): the motion of both phases at the
    /// nodes, the pore pressure at the points (its continuity equation held point by point,
    /// [`flow::continuity::pointwise_increment`]).
    pub const UW: Layout = Layout { dim: 2, nd: 4, p: None, w: Some(2), jbar: None };
    /// u with [002]'s F̄ in an implicit step: the solid displacement and the projected volume
    /// ratio ϑ = J̄ − 1 at the nodes ([`fbar`]).
    pub const U_FBAR: Layout = Layout { dim: 2, nd: 3, p: None, w: None, jbar: Some(2) };
    /// u–p with F̄ (the quasi-static Biot system or an undrained static stage).
    pub const UP_FBAR: Layout = Layout { dim: 2, nd: 4, p: Some(dof::P), w: None, jbar: Some(3) };

    /// The layout of the same fields in `dim` dimensions: the solid displacement's `dim`
    /// components first, then the pore pressure, the water displacement's `dim` components and
    /// the projected volume ratio, each where the layout has it (the two-dimensional constants
    /// are `Layout::U.in_dim(2)` and so on).
    pub const fn in_dim(&self, dim: usize) -> Layout {
        let mut nd = dim;
        let p = if self.p.is_some() {
            nd += 1;
            Some(nd - 1)
        } else {
            None
        };
        let w = if self.w.is_some() {
            nd += dim;
            Some(nd - dim)
        } else {
            None
        };
        let jbar = if self.jbar.is_some() {
            nd += 1;
            Some(nd - 1)
        } else {
            None
        };
        Layout { dim, nd, p, w, jbar }
    }

    /// The layout with the projected volume ratio of an implicit F̄ step added (u and u–p only:
    /// `None` for the others).
    pub fn with_fbar(&self) -> Option<Layout> {
        match *self {
            Layout::U => Some(Layout::U_FBAR),
            Layout::UP => Some(Layout::UP_FBAR),
            _ => None,
        }
    }

    /// The names of the layout's nodal fields, in dof order.
    pub fn field_names(&self) -> &'static [&'static str] {
        match (self.dim, self.p, self.w, self.jbar) {
            (2, None, Some(_), _) => &["ux", "uy", "Ux", "Uy"],
            (2, None, None, Some(_)) => &["ux", "uy", "Jbar"],
            (2, Some(_), None, Some(_)) => &["ux", "uy", "p", "Jbar"],
            (2, ..) => &["ux", "uy", "p", "Ux", "Uy"][..self.nd],
            (_, None, Some(_), _) => &["ux", "uy", "uz", "Ux", "Uy", "Uz"],
            (_, None, None, Some(_)) => &["ux", "uy", "uz", "Jbar"],
            (_, Some(_), None, Some(_)) => &["ux", "uy", "uz", "p", "Jbar"],
            _ => &["ux", "uy", "uz", "p", "Ux", "Uy", "Uz"][..self.nd],
        }
    }

    /// The position in the full two-phase order (ux, uy, p, Ux, Uy; [`dof`]) of this layout's
    /// dof component `c`, the order in which boundaries name what they fix; `None` for the
    /// projected volume ratio, which no boundary fixes.
    pub fn canonical(&self, c: usize) -> Option<usize> {
        // The full two-phase layout of the same dimension: ux, uy, [uz,] p, Ux, Uy[, Uz].
        let full = Layout::UPU.in_dim(self.dim);
        match (self.p, self.w, self.jbar) {
            (_, _, Some(j)) if c == j => None,
            (_, Some(w), _) if c >= w => full.w.map(|fw| fw + c - w),
            (Some(p), _, _) if c == p => full.p,
            _ => Some(c),
        }
    }

    /// The physical fields and their dof offsets: the solid displacement u, then the pore
    /// pressure p and the water displacement U where the system has them.
    pub fn fields(&self) -> Vec<(&'static str, Vec<usize>)> {
        let mut out = vec![("u", (0..self.dim).collect())];
        if let Some(p) = self.p {
            out.push(("p", vec![p]));
        }
        if let Some(w) = self.w {
            out.push(("U", (w..w + self.dim).collect()));
        }
        if let Some(j) = self.jbar {
            out.push(("Jbar", vec![j]));
        }
        out
    }
}

/// The spatial dimension as a type, `Dim<2>` or `Dim<3>`: what exists in one dimension only
/// (the plane's line pressures, [001]'s CMPM recovery and mapped stiffnesses, the plane
/// verification checks) is a trait implemented for both, so that dimension-generic code reaches it
/// through a `where Dim<D>: ...` bound instead of inspecting its types at run time.
#[derive(Debug, Clone, Copy, Default)]
pub struct Dim<const D: usize>;
