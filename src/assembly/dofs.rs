//! Which dofs of a step are unknowns, which are fixed and to what (step 3 of a step).
//!
//! Every ghosted dof is either free or fixed. A dof is fixed when an active boundary fixes it (its
//! prescribed increment is then `value`, and its reaction is booked to that boundary), or when its
//! node is not well filled (see [`super::stencils`]): such a node's motion is extended from its
//! neighbours in every particle that reaches it, so its own motion dofs carry nothing, and its pore
//! pressure is the drained value zero (its projected volume ratio in an implicit F̄ step stays
//! free wherever a point reaches the node, `kernels::fbar`). Fixed dofs keep their rows in the global vector (residual
//! x − value, unit diagonal, no column entries), so the layout never changes.
//!
//! A dof of a rigid body's node (a boundary under a `force`) is *tied*: it stays an unknown, and
//! [`super::ties`] makes it the weighted sum of the body's master dofs that its motion gives and
//! moves its equation, weighted, into the masters', the body's balance.

use super::ties::rigid::{Param, Selection, MAX_PARAMS};
use crate::algebra::pad3;
use crate::layout::Layout;
use crate::model::{Active, Model};
use petsc::GhostedRange;

/// No boundary fixes the dof.
pub const NO_BOUNDARY: u16 = u16::MAX;

/// One master of a rigid body: a tied solid dof whose value, with the body's other masters',
/// fixes the body's motion ([`super::ties`]), the same on every rank.
#[derive(Debug, Clone, PartialEq)]
pub struct Tie {
    /// The body (index into `DofMap::bodies`).
    pub body: usize,
    /// The master's component (its direction: 0: x, 1: y, 2: z).
    pub dir: usize,
    /// The master's global node number.
    pub master_node: i64,
    /// The master's ghosted dof on this rank, if this rank ghosts its node.
    pub master_local: Option<usize>,
    /// The master's offset in the owned part of global vectors, if this rank owns it.
    pub master_owned: Option<usize>,
    /// The body's load carried at this master (its generalized force) at t_{n+1} and at t_n [N/m, N].
    pub force: [f64; 2],
}

/// A rigid body of a step: a boundary under a force whose tied dofs move together, in translation
/// along the directions it ties and, where its force has a point of application, in rotation about
/// that point ([`super::ties::rigid`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// The boundary (index into `Model::boundaries`).
    pub boundary: usize,
    /// The parameters of its motion: the translations along the directions it ties, then the
    /// rotations if it rotates.
    pub params: Vec<Param>,
    /// Where its force acts, the centre of its rotations [m] (zero if it does not rotate).
    pub point: [f64; 3],
    /// Its force at t_{n+1} and at t_n [N/m, N].
    pub force: [[f64; 3]; 2],
    /// Its masters (a range of `DofMap::ties`, filled by [`super::ties::resolve`]).
    pub masters: std::ops::Range<usize>,
    /// How its motion follows from its masters'.
    pub selection: Selection,
}

/// A tied dof: one of a rigid body's, moving as the weighted sum of the body's masters.
#[derive(Debug, Clone, PartialEq)]
pub struct Tied {
    /// The ghosted dof.
    pub q: u32,
    /// The body (index into `DofMap::bodies`).
    pub body: u32,
    /// Its direction.
    pub dir: u8,
    /// Whether it is the solid's (a candidate master) rather than the water's.
    pub solid: bool,
    /// Its weights on the body's masters, u_q = Σ_k w_k u_{m_k} (filled by [`super::ties::resolve`]).
    pub w: [f64; MAX_PARAMS],
}

/// The dof map of a step.
#[derive(Debug, Clone, Default)]
pub struct DofMap {
    /// Dofs per node.
    pub nd: usize,
    /// Whether each ghosted node is well filled.
    pub well: Vec<bool>,
    /// Whether each ghosted dof is fixed.
    pub fixed: Vec<bool>,
    /// The prescribed increment of each fixed dof over the step (0 for a homogeneous condition).
    pub value: Vec<f64>,
    /// The boundary (index into `Model::boundaries`) fixing each ghosted dof, or [`NO_BOUNDARY`].
    pub boundary: Vec<u16>,
    /// Offsets of the fixed dofs in the owned part of global vectors, with their ghosted index.
    pub owned_fixed: Vec<(usize, usize)>,
    /// Unknowns (free dofs) over all ranks.
    pub free_dofs: usize,
    /// The step's rigid bodies, in the order of the active boundaries.
    pub bodies: Vec<Body>,
    /// The rigid bodies' masters, body by body.
    pub ties: Vec<Tie>,
    /// The tied ghosted dofs, in increasing order.
    pub tied: Vec<Tied>,
    /// Offsets of the owned tied dofs in the owned part of global vectors, with their index in
    /// `tied` (the masters left out once resolved).
    pub owned_tied: Vec<(usize, usize)>,
    /// The ghosted water dofs of an impermeable surface, each with the solid dof of its node and
    /// direction that it follows (U_d = u_d), in increasing order.
    pub follows: Vec<(u32, u32)>,
    /// Offsets of the owned following dofs in the owned part of global vectors, with the offset
    /// of the solid dof each follows and its ghosted index.
    pub owned_follows: Vec<(usize, usize, usize)>,
}

impl DofMap {
    /// The bytes the map holds on the heap.
    pub fn heap_bytes(&self) -> usize {
        use crate::algebra::heap::capacity as c;
        c(&self.well)
            + c(&self.fixed)
            + c(&self.value)
            + c(&self.boundary)
            + c(&self.owned_fixed)
            + c(&self.bodies)
            + c(&self.ties)
            + c(&self.tied)
            + c(&self.owned_tied)
            + c(&self.follows)
            + c(&self.owned_follows)
    }

    /// Whether ghosted dof `q` is held by a boundary or barely filled (fixed), tied to a rigid
    /// body, or one of an impermeable surface's pairs (the water and the solid it follows): its
    /// residual entry is a reaction rather than an equation of its own (a pair's two sum to zero).
    pub fn held(&self, q: usize) -> bool {
        self.fixed[q] || self.boundary[q] != NO_BOUNDARY
    }

    /// Whether a node's motion component `c` is fixed by a boundary (not merely by being barely
    /// filled).
    pub fn boundary_fixed(&self, node: usize, c: usize) -> bool {
        self.boundary[node * self.nd + c] != NO_BOUNDARY
    }
}

/// Whether component `c` of a node that the material fills to `fill` (a fraction of a cell) is an
/// unknown where no boundary fixes it: every component of a well-filled node (above
/// `well_fraction`); and the projected volume ratio of an implicit F̄ step wherever points reach
/// the node at all (a fill above zero), since it is [002]'s average over the points that reach it,
/// however few (its row's diagonal is κ Σ_p S_ip V_p), unlike the motion, which is extended, and the
/// pressure, which is drained. No threshold above zero: a point's J̄ = 1 + Σ_i S_ip ϑ_i needs ϑ at
/// every node with S_ip ≠ 0, and a node whose share is dropped costs the patch test its exactness
/// (in three dimensions a corner node beyond a cube is reached by a sliver ∝ δ³, and a threshold of
/// 1e-12 of a cell let the spread of the F̄ patch grow to 4e-12).
pub fn carries_unknown(layout: Layout, c: usize, fill: f64, well_fraction: f64) -> bool {
    if Some(c) == layout.jbar {
        fill > 0.0
    } else {
        fill > well_fraction
    }
}

/// Builds the dof map from the filled fractions `phi` (per ghosted node, summed over ranks) and the
/// moving-surface fixes `surface` (per ghosted dof, the boundary index + 1 or 0, maximum over ranks),
/// in any dimension; an error where a rigid body and another boundary hold the same component of
/// a node.
#[allow(clippy::too_many_arguments)]
pub fn build<const D: usize>(
    model: &Model<D>,
    active: &Active,
    (t0, t1): (f64, f64),
    ghost: &GhostedRange<D>,
    owned_start: [usize; D],
    owned_count: [usize; D],
    nd: usize,
    phi: &[f64],
    surface: &[f64],
    well_fraction: f64,
    layout: Layout,
) -> Result<DofMap, String> {
    let n = ghost.len();
    let bodies = bodies_of(model, active, (t0, t1));
    let mut m = DofMap {
        nd,
        well: phi.iter().map(|&f| f > well_fraction).collect(),
        fixed: vec![false; n * nd],
        value: vec![0.0; n * nd],
        boundary: vec![NO_BOUNDARY; n * nd],
        owned_fixed: Vec::new(),
        free_dofs: 0,
        bodies,
        ties: Vec::new(),
        tied: Vec::new(),
        owned_tied: Vec::new(),
        follows: Vec::new(),
        owned_follows: Vec::new(),
    };
    for (l, reached) in phi.iter().enumerate() {
        let node = ghost.indices(l);
        if let Some(both) = (!m.bodies.is_empty()).then(|| model.rigid_conflict(active, node)).flatten() {
            return Err(conflict(model, both, node));
        }
        let by = model.fixing_boundaries(active, node);
        for c in 0..nd {
            let (q, by_c) = (l * nd + c, layout.canonical(c).and_then(|k| by[k]));
            let b = by_c.or_else(|| (surface[q] > 0.5).then(|| surface[q].round() as usize - 1));
            let dir = if c < D { Some(c) } else { layout.w.and_then(|w| (c >= w).then(|| c - w)) };
            let dir = dir.filter(|&d| d < D);
            if let Some(b) = b {
                m.boundary[q] = b as u16;
                // A moving boundary: its solid components and the water's move by its increment.
                if let (Some(motion), Some(d)) = (&model.boundaries[b].motion, dir) {
                    m.value[q] = motion.increment_at(model.grid.position(node), t0, t1)[d];
                }
                // A rigid body: its components stay unknowns, tied to its masters.
                let body = |d: usize| m.bodies.iter().position(|t| t.boundary == b && t.ties(d));
                if let Some((d, g)) = dir.and_then(|d| Some((d, body(d)?))) {
                    let (body, dir, solid) = (g as u32, d as u8, c < D);
                    m.tied.push(Tied { q: q as u32, body, dir, solid, w: [0.0; MAX_PARAMS] });
                    continue;
                }
                // An impermeable surface: the water follows the solid where the solid is an
                // unknown, moves with it where a boundary holds it, and where the node is barely
                // filled (its solid extended) is treated as the solid is.
                if layout.canonical(c).is_some_and(|k| follows(model, b, k)) {
                    let solid = l * nd + dir.expect("a followed component is the water's");
                    if !m.fixed[solid] {
                        m.follows.push((q as u32, solid as u32));
                        // The pair's two entries are the surface's forces on each phase (their sum is
                        // zero): both booked to it.
                        if m.boundary[solid] == NO_BOUNDARY {
                            m.boundary[solid] = b as u16;
                        }
                    } else if m.boundary[solid] != NO_BOUNDARY {
                        (m.fixed[q], m.value[q]) = (true, m.value[solid]);
                    } else {
                        m.boundary[q] = NO_BOUNDARY;
                        m.fixed[q] = !carries_unknown(layout, c, *reached, well_fraction);
                    }
                    continue;
                }
            }
            m.fixed[q] = b.is_some() || !carries_unknown(layout, c, *reached, well_fraction);
        }
    }
    m.list_owned(ghost, owned_start, owned_count);
    Ok(m)
}

impl DofMap {
    /// Lists the owned nodes' fixed, tied and following dofs by their place in the owned part of
    /// global vectors (the owned nodes x fastest), and counts the free ones.
    fn list_owned<const D: usize>(
        &mut self,
        ghost: &GhostedRange<D>,
        owned_start: [usize; D],
        owned_count: [usize; D],
    ) {
        let nd = self.nd;
        let owned: usize = owned_count.iter().product();
        let mut at = [0usize; D];
        for node in 0..owned {
            let l = ghost.local(std::array::from_fn(|d| owned_start[d] + at[d])).expect("owned nodes are ghosted");
            for c in 0..nd {
                let (o, q) = (node * nd + c, l * nd + c);
                if self.fixed[q] {
                    self.owned_fixed.push((o, q));
                } else {
                    self.free_dofs += 1;
                }
                if let Ok(i) = self.tied.binary_search_by_key(&(q as u32), |t| t.q) {
                    self.owned_tied.push((o, i));
                }
                if let Ok(f) = self.follows.binary_search_by_key(&(q as u32), |f| f.0) {
                    let solid = self.follows[f].1 as usize % nd;
                    self.owned_follows.push((o, o - c + solid, q));
                }
            }
            crate::model::shape::next_combination(&mut at, owned_count);
        }
    }
}

/// The message of a node that rigid body `rigid` and boundary `other` both hold in the component of
/// canonical index `k`.
fn conflict<const D: usize>(model: &Model<D>, (rigid, other, k): (usize, usize, usize), node: [usize; D]) -> String {
    use crate::case::Dof;
    let all = [Dof::Ux, Dof::Uy, Dof::Uz, Dof::P, Dof::WUx, Dof::WUy, Dof::WUz];
    let name =
        all.into_iter().find(|&d| crate::model::dof_index_in::<D>(d) == Some(k)).map_or("?".into(), |d| d.to_string());
    format!(
        "boundary `{}` (a rigid body under a force) and boundary `{}` both hold `{name}` at the grid node at {} m: a \
         rigid body's nodes are held by it alone in its components (for a rough footing in a half model, fix `ux` \
         on the footing's nodes in a boundary of its own and let the force tie `uy` alone)",
        model.boundaries[rigid].name,
        model.boundaries[other].name,
        crate::model::position_text(&model.grid.position(node))
    )
}

/// Whether boundary `b` makes the water component of canonical index `k` follow the solid's.
fn follows<const D: usize>(model: &Model<D>, b: usize, k: usize) -> bool {
    model.boundaries[b].impermeable.iter().any(|&d| crate::model::dof_index_in::<D>(d) == Some(k))
}

/// The rigid bodies of the active boundaries under a force over `(t0, t1)`, in the order of the
/// active boundaries: translations along the directions whose solid component the boundary fixes,
/// and rotations where its force has a point of application (about z in the plane; about x, y
/// and z in three dimensions).
fn bodies_of<const D: usize>(model: &Model<D>, active: &Active, (t0, t1): (f64, f64)) -> Vec<Body> {
    use crate::case::Dof;
    let solid = [Dof::Ux, Dof::Uy, Dof::Uz];
    let mut bodies = Vec::new();
    for &b in &active.boundaries {
        let def = &model.boundaries[b];
        let Some(force) = &def.force else { continue };
        let translations = (0..D).filter(|&d| def.fix.contains(&solid[d])).map(Param::Translation);
        bodies.push(Body {
            boundary: b,
            params: translations.chain(force.rotation_axes().map(Param::Rotation)).collect(),
            point: pad3(force.point.unwrap_or([0.0; D])),
            force: [pad3(force.at(t1)), pad3(force.at(t0))],
            masters: 0..0,
            selection: Selection::default(),
        });
    }
    bodies
}

impl Body {
    /// Whether it ties the components of direction `d`.
    pub fn ties(&self, d: usize) -> bool {
        self.params.contains(&Param::Translation(d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dof map of a three-dimensional u–p step: the base fixes ux, uy, uz, the back wall uz, a
    /// moving region at the top ux, uy, uz and p with its step's increment; a barely filled node's
    /// dofs are fixed; the owned part lists every fixed dof and counts the rest.
    #[test]
    fn a_three_dimensional_dof_map_fixes_and_moves_its_boundaries() {
        let text = crate::case::tests_support::solid_with_boundaries(r#"["uz"]"#, "velocity = [0.0, -0.01, 0.002]");
        let c = crate::validation::load(&text, "t", &[]).unwrap();
        let m = Model::build_solid(&c, |_| true);
        let active = m.active(&c.stages[0]);
        let nodes = m.grid.nodes();
        let ghost = GhostedRange { start: [0; 3], count: nodes, dof: 4 };
        let layout = Layout::UP.in_dim(3);
        let nd = layout.nd;
        let n = ghost.len();
        // Every node well filled but one.
        let lonely = ghost.local([2, 5, 3]).unwrap();
        let phi: Vec<f64> = (0..n).map(|l| if l == lonely { 0.1 } else { 1.0 }).collect();
        let map =
            build(&m, &active, (0.0, 0.5), &ghost, [0; 3], nodes, nd, &phi, &vec![0.0; n * nd], 0.5, layout).unwrap();
        let base = (nodes[0] * nodes[2]) * 3;
        let back = nodes[0] * nodes[1] - nodes[0];
        // The top region: x ∈ {0, 0.1}, z ∈ {0.1, 0.2} at y = 1: four nodes, four components each.
        let top = 4 * 4;
        let fixed = map.fixed.iter().filter(|&&f| f).count();
        assert_eq!(fixed, base + back + top + nd, "base {base}, back {back}, top {top}, the lonely node");
        let q = ghost.local([1, 10, 2]).unwrap() * nd;
        assert_eq!(&map.value[q..q + 4], &[0.0, -0.005, 0.001, 0.0]);
        assert_eq!(map.boundary[q + 3], 2);
        assert!(map.boundary_fixed(ghost.local([0, 0, 1]).unwrap(), 2));
        assert!(map.fixed[lonely * nd..lonely * nd + nd].iter().all(|&f| f));
        assert_eq!(map.owned_fixed.len(), fixed);
        assert_eq!(map.free_dofs, n * nd - fixed);
    }
}
