//! The particle side of a step: every point's kernels at given nodal increments, mapped through
//! its extensions (see [`super::stencils`]) onto the nodes that carry unknowns, summed per ghosted
//! dof or into the rows of the matrix, by bands of node layers on threads. Pure Rust: the SNES
//! callbacks ([`super::callbacks`]) and the step's preparation, balance and explicit update call it.

use super::stencils::Stencils;
use super::step::{Band, Lowered, Solution, Step};
use crate::kernels::{self, NodeState, StepResult};
use crate::model::Model;
use crate::scheme::Scheme;
use petsc::BlockBand;
use std::marker::PhantomData;

/// Largest number of effective nodes of a particle beyond its raw stencil of at most M nodes (the
/// masters of extended nodes outside it).
const EXTRA_MASTERS: usize = 8;

/// The kernel input of particle `k` for the prepared step. Without water dofs the u rows carry
/// the mixture's mass (the water moves with the solid).
pub(super) fn particle_input<const D: usize, const M: usize>(
    model: &Model<D>,
    step: &Step<D, M>,
    k: usize,
) -> kernels::ParticleInput<D> {
    let mut input = kernels::ParticleInput::of(model, k, &step.body_acc);
    if let Some(g) = step.grad_n.get(k) {
        input.grad_n = *g;
    }
    if step.layout.w.is_none() {
        input.mass += input.water_mass;
    }
    let nm = &step.scheme;
    let s = &step.smooth[k];
    input.pred = kernels::Motion::predicted(nm, s[0], s[1], s[2], s[3]);
    input.dt = nm.dt();
    if step.layout.jbar.is_some() {
        // An implicit F̄ step's projection rows weigh as much as the forces (`kernels::fbar`).
        input.fbar_rows = step.p_scale;
    }
    input
}

/// The nodal states (of at most N dofs) of particle `k`'s raw stencil (at most M nodes) from the
/// ghosted increments `xl`, with the motion of extended nodes taken from their masters.
#[inline]
pub(super) fn node_states<const D: usize, const M: usize, const N: usize>(
    step: &Step<D, M>,
    k: usize,
    xl: &[f64],
) -> [NodeState<N>; M] {
    let mut out = [NodeState::default(); M];
    node_states_into(step, k, xl, &mut out);
    out
}

/// [`node_states`] written into the first entries of `out` (as many as the stencil's nodes; the
/// others are left as they are), for a loop over points that keeps one array: zeroing and
/// returning an array of the bound M for every point (125 nodes of seven dofs in three
/// dimensions, 21 kB) costs more than a three-dimensional point's stencil of 8 to 27 nodes.
#[inline]
pub(super) fn node_states_into<const D: usize, const M: usize, const N: usize>(
    step: &Step<D, M>,
    k: usize,
    xl: &[f64],
    out: &mut [NodeState<N>],
) {
    let nm = step.scheme;
    let nd = step.dofs.nd;
    let (nodes, _) = step.stencils.get(k);
    let eff = step.stencils.effective(k);
    for (s, &node) in out.iter_mut().zip(nodes) {
        let b = node as usize * nd;
        *s = NodeState::new(&xl[b..b + nd], &nm);
    }
    for e in step.stencils.extensions(k) {
        for c in (0..nd).filter(|&c| e.mask & (1 << c) != 0) {
            out[e.slot as usize].set(c, e.of_masters(eff, |n| xl[n * nd + c]), &nm);
        }
    }
}

/// The solid displacement increments (the first D dofs) of particle `k`'s raw stencil from the
/// ghosted increments `xl`, extended nodes taken from their masters: [`node_states`]' `d` of
/// the solid, without the rest of a node's state (what the kinematics of the point need).
#[inline]
pub(super) fn node_displacements<const D: usize, const M: usize>(
    step: &Step<D, M>,
    k: usize,
    xl: &[f64],
) -> [[f64; D]; M] {
    node_vectors(step, k, xl, 0)
}

/// The D components from `first` of each node's dofs (a vector field: the solid's from 0, the
/// water's from the layout's `w`) of particle `k`'s raw stencil from the ghosted nodal field `xl`,
/// extended nodes taken from their masters.
#[inline]
fn node_vectors<const D: usize, const M: usize>(
    step: &Step<D, M>,
    k: usize,
    xl: &[f64],
    first: usize,
) -> [[f64; D]; M] {
    let nd = step.dofs.nd;
    let (nodes, _) = step.stencils.get(k);
    let eff = step.stencils.effective(k);
    let mut out = [[0.0; D]; M];
    for (s, &node) in out.iter_mut().zip(nodes) {
        let b = node as usize * nd + first;
        s.copy_from_slice(&xl[b..b + D]);
    }
    for e in step.stencils.extensions(k) {
        for c in (0..D).filter(|&c| e.mask & (1 << (first + c)) != 0) {
            out[e.slot as usize][c] = e.of_masters(eff, |n| xl[n * nd + first + c]);
        }
    }
    out
}

/// For every raw local dof of particle `k`, where it goes among the effective dofs: one (dof, 1)
/// pair, or the masters of an extended component. Returns the number of effective dofs.
fn transform<const D: usize, const M: usize>(step: &Step<D, M>, k: usize, out: &mut Vec<Vec<(usize, f64)>>) -> usize {
    let nd = step.dofs.nd;
    let (nodes, _) = step.stencils.get(k);
    out.clear();
    out.extend((0..nodes.len() * nd).map(|a| vec![(a, 1.0)]));
    for e in step.stencils.extensions(k) {
        for c in (0..nd).filter(|&c| e.mask & (1 << c) != 0) {
            out[e.slot as usize * nd + c] =
                (0..e.n as usize).map(|m| (e.masters[m].0 as usize * nd + c, e.masters[m].1)).collect();
        }
    }
    step.stencils.effective(k).len() * nd
}

/// `n` bands of whole layers of a ghosted grid of `counts` nodes per direction (layers along the
/// last direction: rows in two dimensions), cut where about equal numbers of the particles' first
/// layers lie below (fewer bands if there are few layers).
pub(super) fn bands<const D: usize>(st: &Stencils<D>, counts: [usize; D], n: usize) -> Vec<Band> {
    // Nodes per layer and layers.
    let (nx, ny) = (counts[..D - 1].iter().product::<usize>(), counts[D - 1]);
    let total = (nx * ny) as u32;
    let n = n.min(ny / 4).max(1);
    if n == 1 || st.is_empty() {
        return vec![Band { lo: 0, hi: total }];
    }
    let mut per_row = vec![0usize; ny + 1];
    for k in 0..st.len() {
        let first = st.effective(k).iter().min().copied().unwrap_or(0) as usize / nx;
        per_row[first] += 1;
    }
    let mut out = Vec::with_capacity(n);
    let (mut lo, mut seen, mut row) = (0u32, 0usize, 0usize);
    for b in 1..n {
        let goal = st.len() * b / n;
        while row < ny && seen + per_row[row] <= goal {
            seen += per_row[row];
            row += 1;
        }
        let hi = ((row * nx) as u32).max(lo);
        out.push(Band { lo, hi });
        lo = hi;
    }
    out.push(Band { lo, hi: total });
    out.retain(|b| b.hi > b.lo);
    out
}

/// Runs `work` on every band on its own thread (the first on this one), each with its part of
/// `data`: entries `start(band.lo)..start(band.hi)` (the bands cover `data` in order).
pub(super) fn run_bands<R: Send>(
    bands: &[Band],
    data: &mut [f64],
    start: impl Fn(u32) -> usize,
    work: impl Fn(Band, &mut [f64]) -> R + Sync,
) -> Vec<R> {
    let mut parts = Vec::with_capacity(bands.len());
    let (mut rest, mut at) = (data, 0);
    for b in bands {
        let end = start(b.hi);
        let (head, tail) = rest.split_at_mut(end - at);
        parts.push((*b, head));
        rest = tail;
        at = end;
    }
    run_parts(parts, work)
}

/// Runs `work` on every band and its part on its own thread (the first on this one).
pub(super) fn run_parts<P: Send, R: Send>(mut parts: Vec<(Band, P)>, work: impl Fn(Band, P) -> R + Sync) -> Vec<R> {
    if parts.len() == 1 {
        let (b, d) = parts.pop().expect("one band");
        return vec![work(b, d)];
    }
    let work = &work;
    std::thread::scope(|scope| {
        let mut it = parts.into_iter();
        let (b0, d0) = it.next().expect("a first band");
        let handles: Vec<_> = it.map(|(b, d)| scope.spawn(move || work(b, d))).collect();
        let mut out = vec![work(b0, d0)];
        out.extend(handles.into_iter().map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p))));
        out
    })
}

/// Grows `v` with zeros to at least `n` values.
fn at_least(v: &mut Vec<f64>, n: usize) {
    if v.len() < n {
        v.resize(n, 0.0);
    }
}

/// What a loop over points keeps from one point to the next: the nodal states (at least as many
/// as a stencil's nodes, [`node_states_into`]) and the point's per-node arrays.
pub(super) struct PointScratch<const D: usize, const N: usize> {
    states: Vec<NodeState<N>>,
    buffers: kernels::PointBuffers<D>,
}

impl<const D: usize, const N: usize> PointScratch<D, N> {
    /// Empty scratch (the states grow to the first stencil's length).
    pub(super) fn new() -> PointScratch<D, N> {
        PointScratch { states: Vec::new(), buffers: kernels::PointBuffers::default() }
    }
}

/// The scratch of [`Points::add_tangent`]: the map of raw to effective dofs, the effective
/// block, the effective nodes' grid indices and places in the pattern's table, the pattern
/// blocks of one block row.
struct Scratch<const D: usize> {
    transform: Vec<Vec<(usize, f64)>>,
    block: Vec<f64>,
    indices: Vec<[i64; D]>,
    codes: Vec<usize>,
    blocks: Vec<usize>,
}

/// The particle side of the callbacks: the model and the prepared step (shared by the threads);
/// points of dimension D with at most M nodes of at most N dofs.
pub(super) struct Points<'a, const D: usize, const M: usize, const N: usize> {
    model: &'a Model<D>,
    step: &'a Step<D, M>,
    dofs: PhantomData<[(); N]>,
}

impl<const D: usize, const M: usize, const N: usize> Clone for Points<'_, D, M, N> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<const D: usize, const M: usize, const N: usize> Copy for Points<'_, D, M, N> {}

impl<const D: usize, const M: usize, const N: usize> Points<'_, D, M, N> {
    /// Calls `f` with the point of particle `k` at the ghosted increments `xl`.
    pub(super) fn with_point<R>(&self, k: usize, xl: &[f64], f: impl FnOnce(&kernels::Point<D, M>) -> R) -> R {
        let mut scratch = PointScratch::new();
        self.with_point_of(k, xl, particle_input(self.model, self.step, k), &mut scratch, f)
    }

    /// [`Self::with_point`] with the particle's kernel input given, and its nodal states and
    /// per-node arrays in `scratch`, which a loop over points keeps.
    fn with_point_of<R>(
        &self,
        k: usize,
        xl: &[f64],
        input: kernels::ParticleInput<D>,
        scratch: &mut PointScratch<D, N>,
        f: impl FnOnce(&kernels::Point<D, M>) -> R,
    ) -> R {
        let step = self.step;
        let (nodes, basis) = step.stencils.get(k);
        let PointScratch { states, buffers } = scratch;
        if states.len() < nodes.len() {
            states.resize(nodes.len(), NodeState::default());
        }
        node_states_into::<D, M, N>(step, k, xl, states);
        let mat = &self.model.materials[self.model.particles.material[k] as usize];
        let strain = step.stencils.strain_of(k);
        let layout = step.layout;
        let states = &states[..nodes.len()];
        let mut pt = kernels::Point::<D, M>::with_recovery_in(
            std::mem::take(buffers),
            basis,
            strain,
            states,
            &input,
            &mat.model,
            layout,
        );
        pt.set_forces(step.stencils.forces_of(k));
        pt.set_faces(step.faces_of(k), states);
        let r = f(&pt);
        *buffers = pt.into_buffers();
        r
    }

    /// Particle `k` at an explicit step's start with the stress it carries
    /// ([`kernels::Point::at_start`]), its per-node arrays in `buffers`.
    fn with_point_at_start<R>(
        &self,
        k: usize,
        buffers: &mut kernels::PointBuffers<D>,
        f: impl FnOnce(&kernels::Point<D, M>) -> R,
    ) -> R {
        let step = self.step;
        let (_, basis) = step.stencils.get(k);
        let input = particle_input(self.model, step, k);
        let strain = step.stencils.strain_of(k);
        let mut pt = kernels::Point::<D, M>::at_start_in(std::mem::take(buffers), basis, strain, &input, step.layout);
        pt.set_forces(step.stencils.forces_of(k));
        let r = f(&pt);
        *buffers = pt.into_buffers();
        r
    }

    /// Calls `f` with the point of particle `k` whose basis also holds its slots beyond the grid
    /// ([`super::stencils::WallSlot`], after the raw slots), at the ghosted increments `xl` or at an
    /// explicit step's start: the held slots move nothing (zero increments), so the point's state
    /// is the one of [`Self::with_point`] and the extra entries of its blocks are the wall's share.
    /// Without drained faces (they act on the pressure rows only).
    fn with_point_beyond<R>(
        &self,
        k: usize,
        xl: &[f64],
        at_start: bool,
        f: impl FnOnce(&kernels::Point<D, M>) -> R,
    ) -> R {
        let step = self.step;
        let (nodes, basis) = step.stencils.get(k);
        let beyond = step.stencils.beyond_of(k);
        let grown = |ops: &[kernels::NodeBasis<D>], held: bool| -> Vec<kernels::NodeBasis<D>> {
            let extra = beyond.iter().map(|w| if held { w.basis } else { kernels::NodeBasis::default() });
            ops.iter().copied().chain(extra).collect()
        };
        let all = grown(basis, true);
        // Recovered strain and double-mapped force operators have nothing beyond the grid: zero
        // operators there (the held slots' increments are zero anyway).
        let recovered = !std::ptr::eq(step.stencils.strain_of(k), basis);
        let strain_ops = recovered.then(|| grown(step.stencils.strain_of(k), false));
        let strain = strain_ops.as_deref().unwrap_or(&all);
        // An empty slice: the forces take the basis (`kernels::Point::with_forces`).
        let forces = step.stencils.forces_of(k);
        let forces = if forces.is_empty() { Vec::new() } else { grown(forces, false) };
        let input = particle_input(self.model, step, k);
        let layout = step.layout;
        if at_start {
            let mut pt = kernels::Point::<D, M>::at_start(&all, strain, &input, layout);
            pt.set_forces(&forces);
            return f(&pt);
        }
        let mut states = node_states::<D, M, N>(step, k, xl);
        for s in &mut states[nodes.len()..all.len()] {
            *s = NodeState::default();
        }
        let mat = &self.model.materials[self.model.particles.material[k] as usize];
        let mut pt =
            kernels::Point::<D, M>::with_recovery(&all, strain, &states[..all.len()], &input, &mat.model, layout);
        pt.set_forces(&forces);
        f(&pt)
    }

    /// Adds particle `k`'s residual at `xl` into `buf` and returns its length (`scratch`: see
    /// [`Self::with_point_of`]).
    pub(super) fn residual_of(&self, k: usize, xl: &[f64], buf: &mut [f64], scratch: &mut PointScratch<D, N>) -> usize {
        let nm = self.step.scheme;
        let input = particle_input(self.model, self.step, k);
        self.with_point_of(k, xl, input, scratch, |pt| {
            kernels::residual(pt, &nm, buf);
            pt.size()
        })
    }

    /// Whether particle `k` has an effective node in `band`.
    fn touches(&self, k: usize, band: Band) -> bool {
        self.step.stencils.effective(k).iter().any(|&a| band.holds(a))
    }

    /// Adds particle `k`'s raw residual block `r` (length m) through its extensions to the rows of
    /// `band`, whose part of a ghosted array is `f`.
    pub(super) fn scatter(&self, k: usize, r: &[f64], f: &mut [f64], band: Band) {
        let nd = self.step.dofs.nd;
        let first = band.lo as usize * nd;
        let (nodes, _) = self.step.stencils.get(k);
        let eff = self.step.stencils.effective(k);
        let extensions = self.step.stencils.extensions(k);
        for e in extensions {
            for c in (0..nd).filter(|&c| e.mask & (1 << c) != 0) {
                let a = e.slot as usize * nd + c;
                for m in 0..e.n as usize {
                    let node = eff[e.masters[m].0 as usize];
                    if band.holds(node) {
                        f[node as usize * nd + c - first] += e.masters[m].1 * r[a];
                    }
                }
            }
        }
        for (n, &node) in nodes.iter().enumerate() {
            if !band.holds(node) {
                continue;
            }
            // The components of this slot that an extension moved to its masters.
            let moved = extensions.iter().filter(|e| e.slot as usize == n).fold(0u8, |m, e| m | e.mask);
            for c in 0..nd {
                if moved & (1 << c) == 0 {
                    f[node as usize * nd + c - first] += r[n * nd + c];
                }
            }
        }
    }

    /// The residual rows of `band` (its part `f` of a ghosted array) from every particle that
    /// reaches it, each particle's block given by `block(k, buf, scratch) -> length` (`scratch`:
    /// see [`Self::with_point_of`]); returns the first particle whose block was not finite.
    pub(super) fn residual_band(
        &self,
        band: Band,
        f: &mut [f64],
        block: &(impl Fn(usize, &mut [f64], &mut PointScratch<D, N>) -> usize + Sync),
    ) -> Option<usize> {
        let mut buf = vec![0.0; M * N];
        let mut scratch = PointScratch::new();
        let mut nonfinite = None;
        for k in (0..self.step.stencils.len()).filter(|&k| self.touches(k, band)) {
            let m = block(k, &mut buf, &mut scratch);
            if nonfinite.is_none() && !buf[..m].iter().all(|r| r.is_finite()) {
                nonfinite = Some(k);
            }
            self.scatter(k, &buf[..m], f, band);
        }
        nonfinite
    }

    /// The tangent blocks of every particle that reaches `band`, added into the band's part
    /// `values` of the matrix.
    pub(super) fn tangent_band(
        &self,
        band: Band,
        values: &mut BlockBand<'_>,
        mut lowered: Option<(&mut BlockBand<'_>, &Lowered<D>)>,
        xl: &[f64],
    ) {
        let mut cell = Vec::new();
        let step = self.step;
        let nm = step.scheme;
        let layout = step.layout;
        // Sized by the largest block met, not by the bounds M and N: a three-dimensional
        // one-phase point's block is 192² values, the bounds' 875² (6 MB a thread).
        let mut block = Vec::new();
        let mut scratch = Scratch {
            transform: Vec::new(),
            block: Vec::new(),
            indices: Vec::with_capacity(M + EXTRA_MASTERS),
            codes: Vec::with_capacity(M + EXTRA_MASTERS),
            blocks: Vec::with_capacity(M + EXTRA_MASTERS),
        };
        let mut point = PointScratch::new();
        for k in (0..step.stencils.len()).filter(|&k| self.touches(k, band)) {
            let input = particle_input(self.model, step, k);
            let m = self.with_point_of(k, xl, input, &mut point, |pt| {
                let m = pt.size();
                at_least(&mut block, m * m);
                if self.model.stiffness_in_jacobian {
                    kernels::tangent_with(pt, &nm, &mut block[..m * m], step.stiffness.material(k));
                    step.stiffness.add(k, nm.w_force, &mut block[..m * m], m, layout.nd);
                } else {
                    // The mapped stiffness serves the diagnostics only: the exact tangent.
                    kernels::tangent_with(pt, &nm, &mut block[..m * m], 1.0);
                }
                if let Some((pv, low)) = lowered.as_mut() {
                    self.add_lowered(k, pt, band, pv, low, &mut cell);
                }
                m
            });
            self.add_tangent(k, &mut block[..m * m], m, &mut scratch, values, band);
        }
    }

    /// Adds point `k`'s multilinear preconditioning blocks ([`kernels::lowered`]) of point `pt`
    /// whose rows lie in `band` to the band's part `values` of the preconditioning matrix of
    /// `lowered`: the cell block over its corners and the diagonal block of each stencil node that
    /// is no point's corner, without the rows and columns of fixed dofs. `cell` is scratch.
    fn add_lowered(
        &self,
        k: usize,
        pt: &kernels::Point<D, M>,
        band: Band,
        values: &mut BlockBand<'_>,
        lowered: &Lowered<D>,
        cell: &mut Vec<f64>,
    ) {
        let step = self.step;
        let (nd, grid) = (step.dofs.nd, &self.model.grid);
        let fixed = &step.dofs.fixed;
        let free = |a: u32, i: usize| !fixed[a as usize * nd + i];
        let corners = lowered.corners_of(k);
        let (raw, _) = step.stencils.get(k);
        let v = pt.volume_new() * step.scheme.w_force;
        let d = &pt.upd.tangent;
        // The point on x_n and its cell's lowest corner (the cell `lowered` took the corners of).
        let x = self.model.particles.x[k];
        let lo = grid.position(grid.nearest(x));
        let n = corners.len() * D;
        at_least(cell, n * n);
        let grads = kernels::lowered::corner_gradients(lo, grid.h, x);
        kernels::lowered::cell_block(&grads[..corners.len()], d, v, &mut cell[..n * n]);
        for (p, &a) in corners.iter().enumerate().filter(|(_, &a)| band.holds(a)) {
            let first = lowered.pattern.block(a, a).expect("the pattern holds every pair of corners") as usize;
            let rows = values.row_places(first);
            for (q, &b) in corners.iter().enumerate() {
                let blk = lowered.pattern.block(a, b).expect("the pattern holds every pair of corners") as usize;
                values.with_rows_of_run(&rows, blk, 1, |i, out| {
                    if free(a, i) {
                        let row = &cell[(p * D + i) * n + q * D..][..D];
                        for (j, (o, x)) in out.iter_mut().zip(row).enumerate() {
                            if free(b, j) {
                                *o += x;
                            }
                        }
                    }
                });
            }
        }
        for (i, &a) in raw.iter().enumerate().filter(|(_, &a)| band.holds(a) && lowered.lone[a as usize]) {
            let b = kernels::lowered::strain_operator(pt.spatial[i].0);
            let k3 = kernels::lowered::pair_block(&b, &b, d, v);
            let blk = lowered.pattern.block(a, a).expect("the pattern holds every stencil node's diagonal") as usize;
            let rows = values.row_places(blk);
            values.with_rows_of_run(&rows, blk, 1, |i, out| {
                if free(a, i) {
                    for (j, o) in out.iter_mut().enumerate().take(D) {
                        if free(a, j) {
                            *o += k3[i][j];
                        }
                    }
                }
            });
        }
    }

    /// Adds the rows of `band` of particle `k`'s tangent block (overwritten: its rows and columns
    /// of fixed dofs are zeroed) to the band's part `values` of the matrix.
    fn add_tangent(
        &self,
        k: usize,
        block: &mut [f64],
        m: usize,
        scratch: &mut Scratch<D>,
        values: &mut BlockBand<'_>,
        band: Band,
    ) {
        let step = self.step;
        let nd = step.dofs.nd;
        let Scratch { transform: tr, block: eff_block, indices, codes, blocks } = scratch;
        let has_ext = !step.stencils.extensions(k).is_empty();
        let eff = step.stencils.effective(k);
        let (me, kb): (usize, &mut [f64]) = if has_ext {
            let me = transform(step, k, tr);
            at_least(eff_block, me * me);
            eff_block[..me * me].fill(0.0);
            for a in 0..m {
                for &(ea, wa) in &tr[a] {
                    for b in 0..m {
                        let v = block[a * m + b];
                        if v == 0.0 {
                            continue;
                        }
                        for &(eb, wb) in &tr[b] {
                            eff_block[ea * me + eb] += wa * wb * v;
                        }
                    }
                }
            }
            (me, &mut eff_block[..me * me])
        } else {
            (m, &mut block[..m * m])
        };
        let ne = me / nd;
        // A fixed dof keeps its row (x − prescribed, unit diagonal) and takes nothing from the
        // points: its row and column of the block are zeroed, and every value is then added as
        // it is (adding a zero leaves a value unchanged).
        let fixed = &step.dofs.fixed;
        for a in (0..me).filter(|&a| fixed[eff[a / nd] as usize * nd + a % nd]) {
            kb[a * me..(a + 1) * me].fill(0.0);
            for row in kb.chunks_exact_mut(me) {
                row[a] = 0.0;
            }
        }
        let pattern = &step.pattern;
        indices.clear();
        indices.extend(eff.iter().map(|&a| pattern.indices(a)));
        let compact = pattern.codes(indices, codes);
        for p in (0..ne).filter(|&p| band.holds(eff[p])) {
            pattern.row_blocks(eff, indices, compact.then_some(&codes[..]), p, blocks);
            let rows = values.row_places(blocks[0]);
            // Nodes whose blocks lie side by side in the matrix's rows (a stencil's nodes along x)
            // are added together: a row of the block is a few runs of values, not ne pieces.
            let mut q = 0;
            while q < ne {
                let n = 1 + (q + 1..ne).take_while(|&r| values.follows(blocks[r - 1], blocks[r])).count();
                values.with_rows_of_run(&rows, blocks[q], n, |c1, out| {
                    let first = (p * nd + c1) * me + q * nd;
                    for (o, x) in out.iter_mut().zip(&kb[first..first + n * nd]) {
                        *o += x;
                    }
                });
                q += n;
            }
        }
    }

    /// The band of every node.
    pub(super) fn whole(&self) -> Band {
        Band { lo: 0, hi: (self.step.dofs.fixed.len() / self.step.dofs.nd) as u32 }
    }
}

impl<'a, const D: usize, const M: usize, const N: usize> Points<'a, D, M, N> {
    /// The points of `model` in the prepared `step`.
    pub(super) fn new(model: &'a Model<D>, step: &'a Step<D, M>) -> Points<'a, D, M, N> {
        Points { model, step, dofs: PhantomData }
    }

    /// Names particle `k`, whose residual at `xl` is not finite, and the first of its quantities
    /// that is not.
    pub(super) fn describe_nonfinite(&self, k: usize, xl: &[f64]) -> String {
        match self.with_point(k, xl, |pt| crate::update::nonfinite(self.model, k, &kernels::StepResult::of(pt))) {
            Some(e) => e.0,
            None => {
                let ps = &self.model.particles;
                format!(
                    "material point {} at {} m: its residual (internal, inertia or flow terms) is not finite (NaN or Inf)",
                    ps.id[k],
                    crate::model::position_text(&ps.x[k])
                )
            }
        }
    }

    /// The kernel terms of the converged step summed per ghosted dof (this rank's particles), as
    /// a balance at t_{n+1}. `all` holds the residual without the external loads: at a fixed or
    /// tied dof the terms at t_{n+1} unweighted (so that `all − f_ext` is the reaction at t_{n+1}); at a
    /// free dof the scheme's weighted residual with its history divided by the weight 1 − α_f of
    /// the forces at t_{n+1} (equal to f_ext,n+1 at convergence). `inertia` holds `all` minus the
    /// internal forces at t_{n+1} (stress, pore pressure, porosity gradient, drag): the inertia
    /// and body forces, and under the generalized-α method at a free dof the rest of the
    /// weighted balance (its history of t_n). With these, Σ x ⊗ (f_ext + R − inertia) is exactly
    /// the first moment of the internal forces at t_{n+1}, whatever the scheme.
    ///
    /// `magnitude` receives Σ over particles of the absolute values of their weighted residual
    /// blocks, plus the absolute external loads: the scale of each dof's equation at the
    /// converged state (see `StepForces::field_scales`).
    pub(super) fn nodal_terms(&self, xl: &[f64], all: &mut [f64], inertia: &mut [f64], magnitude: &mut [f64]) {
        let step = self.step;
        let nm = step.scheme;
        let plain = nm.unweighted();
        // Without a history (Newmark, static, quasi-static) the weighted terms are the terms at
        // t_{n+1}: one pass serves both.
        let weighted = nm.history().is_some();
        let (mut buf, mut ubuf, mut fbuf) = (vec![0.0; M * N], vec![0.0; M * N], vec![0.0; M * N]);
        let mut forces = vec![0.0; all.len()];
        let mut unweighted = if weighted { vec![0.0; all.len()] } else { Vec::new() };
        let ps = self;
        let whole = ps.whole();
        // An explicit step's terms are those of its start, with the stress each point carries.
        let at_start = nm.is_explicit();
        let mut point = PointScratch::new();
        debug_assert!(!at_start || xl.iter().all(|&x| x == 0.0));
        for k in 0..step.stencils.len() {
            let terms = |pt: &kernels::Point<D, M>| {
                let m = pt.size();
                kernels::residual(pt, &nm, &mut buf[..m]);
                if weighted {
                    kernels::residual(pt, &plain, &mut ubuf[..m]);
                }
                kernels::residual_terms(pt, &plain, kernels::Terms::Forces, &mut fbuf[..m]);
                m
            };
            let m = if at_start {
                ps.with_point_at_start(k, &mut point.buffers, terms)
            } else {
                ps.with_point_of(k, xl, particle_input(ps.model, step, k), &mut point, terms)
            };
            ps.scatter(k, &buf[..m], all, whole);
            for v in &mut buf[..m] {
                *v = v.abs();
            }
            ps.scatter(k, &buf[..m], magnitude, whole);
            if weighted {
                ps.scatter(k, &ubuf[..m], &mut unweighted, whole);
            }
            ps.scatter(k, &fbuf[..m], &mut forces, whole);
        }
        self.add_projection(xl, all);
        for (m, e) in magnitude.iter_mut().zip(&step.fext) {
            *m += e.abs();
        }
        for (a, h) in all.iter_mut().zip(&step.history) {
            *a += h;
        }
        for (q, ((a, i), f)) in all.iter_mut().zip(inertia.iter_mut()).zip(&forces).enumerate() {
            if weighted {
                *a = if step.dofs.held(q) { unweighted[q] } else { *a / nm.w_force };
            }
            *i = *a - f;
        }
    }

    /// The shares of the held slots beyond the grid ([`Stencils::beyond`], in their order) at the
    /// increments `xl` (or an explicit step's start): per slot its unweighted residual (every term,
    /// as on a held node) and its internal forces ([`kernels::Terms::Forces`]), `nd` values each,
    /// flat.
    pub(super) fn wall_shares(&self, xl: &[f64], at_start: bool) -> Vec<f64> {
        let step = self.step;
        let nd = step.dofs.nd;
        let plain = step.scheme.unweighted();
        let beyond = &step.stencils.beyond;
        let mut out = Vec::with_capacity(2 * nd * beyond.len());
        let (mut buf, mut fbuf) = (vec![0.0; M * N], vec![0.0; M * N]);
        let ps = self;
        for slots in beyond.chunk_by(|a, b| a.k == b.k) {
            let k = slots[0].k as usize;
            let raw = step.stencils.get(k).0.len();
            ps.with_point_beyond(k, xl, at_start, |pt| {
                let m = pt.size();
                kernels::residual(pt, &plain, &mut buf[..m]);
                kernels::residual_terms(pt, &plain, kernels::Terms::Forces, &mut fbuf[..m]);
            });
            for slot in raw..raw + slots.len() {
                out.extend_from_slice(&buf[slot * nd..(slot + 1) * nd]);
                out.extend_from_slice(&fbuf[slot * nd..(slot + 1) * nd]);
            }
        }
        out
    }

    /// The nodal diagnostics of [001] Eqs. 25–26 per ghosted dof of the solid's motion: the diagonal
    /// of the skeleton's stiffness (`k`, the stress term's tangent) and its internal force (`f`, the
    /// effective-stress and pore-pressure terms, unweighted) at the increments `xl`, from every
    /// particle that reaches the node, not mapped through the extensions (what the node itself sees).
    pub(super) fn nodal_stiffness_and_force(&self, xl: &[f64], k: &mut [f64], f: &mut [f64]) {
        let step = self.step;
        let plain = step.scheme.unweighted();
        let nd = step.dofs.nd;
        let mut block = Vec::new();
        let mut buf = vec![0.0; M * N];
        let ps = self;
        for p in 0..step.stencils.len() {
            let (nodes, _) = step.stencils.get(p);
            ps.with_point(p, xl, |pt| {
                let m = pt.size();
                at_least(&mut block, m * m);
                block[..m * m].fill(0.0);
                buf[..m].fill(0.0);
                kernels::stress::tangent_with(pt, &plain, &mut block[..m * m], step.stiffness.material(p));
                step.stiffness.add(p, 1.0, &mut block[..m * m], m, nd);
                kernels::stress::residual(pt, &plain, &mut buf[..m]);
                kernels::stress::pore_pressure::residual(pt, &plain, &mut buf[..m]);
                for (n, &node) in nodes.iter().enumerate() {
                    for c in 0..D {
                        let a = n * nd + c;
                        k[node as usize * nd + c] += block[a * m + a];
                        f[node as usize * nd + c] += buf[a];
                    }
                }
            });
        }
    }

    /// The magnitude of the forces of the step per ghosted dof: Σ over particles of the absolute
    /// values of their residual at Δd = 0 (stress, pore pressure, body force, inertia
    /// predictors), plus the external loads at t_{n+1}. It scales the absolute tolerance of the
    /// Newton solve, so that a step that starts in equilibrium (a body at rest) converges at the
    /// round-off of its forces instead of chasing a relative decrease below it.
    pub(super) fn force_magnitudes(&self) -> Vec<f64> {
        let step = self.step;
        let nm = step.scheme;
        let xl = vec![0.0; step.fext.len()];
        let mut out: Vec<f64> = step.fext.iter().map(|f| f.abs()).collect();
        let ps = self;
        let weight = nm.w_force.max(nm.w_inertia);
        let block = |k: usize, buf: &mut [f64], scratch: &mut PointScratch<D, N>| {
            let m = ps.residual_of(k, &xl, buf, scratch);
            for v in &mut buf[..m] {
                *v = v.abs() * weight;
            }
            m
        };
        run_bands(&step.bands, &mut out, |a| a as usize * step.dofs.nd, |band, f| ps.residual_band(band, f, &block));
        out
    }

    /// Every particle's terms at the step's start per ghosted dof, weighted by `scheme`: Δd = 0,
    /// the body acceleration `body_acc_old` of t_n and, with `smooth`, the particle's velocity and
    /// acceleration at t_n in place of the predictors; minus w_f f_ext,n (`fext_old`).
    pub(super) fn terms_at_start(
        &self,
        scheme: &crate::scheme::Scheme,
        body_acc_old: &[[f64; D]],
        fext_old: &[f64],
        smooth: bool,
    ) -> Vec<f64> {
        let step = self.step;
        let xl = vec![0.0; fext_old.len()];
        let mut out: Vec<f64> = fext_old.iter().map(|f| -scheme.w_force * f).collect();
        let ps = self;
        let block = |k: usize, buf: &mut [f64], scratch: &mut PointScratch<D, N>| {
            let mut input = particle_input(ps.model, step, k);
            if smooth {
                let s = &step.smooth[k];
                input.pred = kernels::Motion { v_u: s[0], a_u: s[1], v_w: s[2], a_w: s[3] };
            }
            input.body_acc = body_acc_old[ps.model.particles.body[k] as usize];
            // With an implicit F̄ the point at Δd = 0, ϑ = 0 sees r = 1/J̄_n: J̄_n = 1 makes it the
            // point at rest, with the stress it carries.
            input.jbar = 1.0;
            ps.with_point_of(k, &xl, input, scratch, |pt| {
                kernels::residual(pt, scheme, &mut buf[..pt.size()]);
                pt.size()
            })
        };
        run_bands(&step.bands, &mut out, |a| a as usize * step.dofs.nd, |band, f| ps.residual_band(band, f, &block));
        out
    }

    /// The generalized-α history of the step per ghosted dof: every particle's terms at t_n
    /// (its velocity and acceleration at t_n in place of the predictors) weighted by α_m (inertia)
    /// and α_f (forces), minus α_f f_ext,n ([`Self::terms_at_start`] with the history scheme `hs`,
    /// [`Scheme::history`]). Constant over the step's Newton iterations.
    pub(super) fn history(&self, hs: &Scheme, body_acc_old: &[[f64; D]], fext_old: &[f64]) -> Vec<f64> {
        self.terms_at_start(hs, body_acc_old, fext_old, true)
    }

    /// What a geometrically linear step (`analysis.kinematics = "linear_increments"`) adds to its
    /// residual: minus the residual of the step's start on x_n ([`Self::terms_at_start`]: the
    /// stress σ_n, the body acceleration and the loads of t_n) at every free dof, zero at the
    /// fixed ones. The step then solves F_int(Δσ) = ΔF_ext (less the body force's increment), the
    /// increment of a stress-free body as [001]'s K Δu = ΔF: whatever the stress of earlier steps
    /// leaves out of balance on the moved configuration is not carried. At the fixed dofs the
    /// terms stay whole, so that the reactions are those of the total stress. Constant over the
    /// step's iterations.
    pub(super) fn start_out_of_balance(&self, body_acc_old: &[[f64; D]], fext_old: &[f64]) -> Vec<f64> {
        let nm = self.step.scheme;
        let mut out = self.terms_at_start(&nm, body_acc_old, fext_old, false);
        for (v, &fixed) in out.iter_mut().zip(&self.step.dofs.fixed) {
            *v = if fixed { 0.0 } else { -*v };
        }
        out
    }

    /// An explicit step's lumped masses and momenta per ghosted dof, this rank's points' shares
    /// S_ip m_p and S_ip m_p v_p ([002] Eqs. 7–8) with v_p the point's entry of `velocities` (its own
    /// velocity, or a field XPIC maps through the points), given through the extensions of barely
    /// filled nodes as the residual is. With `water` (the u–U system: the points' water
    /// velocities), the water's S_ip n ρ_w V_p and momenta at the water's dofs, and the lumped drag
    /// S_ip c_p at the solid's and the water's dofs alike.
    pub(super) fn lumped_mass_and_momentum(&self, velocities: &[[f64; D]], water: Option<&[[f64; D]]>) -> Lumped {
        let step = self.step;
        let nd = step.dofs.nd;
        let ng = step.dofs.fixed.len();
        let w = step.layout.w.filter(|_| water.is_some());
        let mut out = Lumped {
            mass: vec![0.0; ng],
            momentum: vec![0.0; ng],
            drag: if w.is_some() { vec![0.0; ng] } else { Vec::new() },
        };
        let (ps, points) = (self, &self.model.particles);
        let whole = ps.whole();
        let (mut m, mut p, mut c) = (vec![0.0; M * N], vec![0.0; M * N], vec![0.0; M * N]);
        debug_assert_eq!(velocities.len(), step.stencils.len());
        for (k, v) in velocities.iter().enumerate() {
            let (nodes, basis) = step.stencils.get(k);
            let len = nodes.len() * nd;
            m[..len].fill(0.0);
            p[..len].fill(0.0);
            let (mw, drag) = (self.model.water_mass(k), self.model.drag(k));
            for (n, b) in basis.iter().enumerate() {
                for c in 0..D {
                    m[n * nd + c] = b.s * points.mass[k];
                    p[n * nd + c] = m[n * nd + c] * v[c];
                }
                if let (Some(w), Some(vw)) = (w, water) {
                    for d in 0..D {
                        m[n * nd + w + d] = b.s * mw;
                        p[n * nd + w + d] = b.s * mw * vw[k][d];
                        c[n * nd + d] = b.s * drag;
                        c[n * nd + w + d] = b.s * drag;
                    }
                }
            }
            ps.scatter(k, &m[..len], &mut out.mass, whole);
            ps.scatter(k, &p[..len], &mut out.momentum, whole);
            if w.is_some() {
                ps.scatter(k, &c[..len], &mut out.drag, whole);
            }
        }
        out
    }

    /// −S Δp of the pressure projection in the continuity rows of `f`.
    pub(super) fn add_projection(&self, xl: &[f64], f: &mut [f64]) {
        let Some(p) = self.step.layout.p else { return };
        let nd = self.step.dofs.nd;
        for cell in &self.step.projection {
            let (nodes, s, c) = (&cell.nodes, &cell.s, cell.nodes.len());
            for (a, &na) in nodes.iter().enumerate() {
                let ra = na as usize * nd + p;
                if self.step.dofs.fixed[ra] {
                    continue;
                }
                let v: f64 = nodes
                    .iter()
                    .enumerate()
                    .map(|(b, &nb)| {
                        let q = nb as usize * nd + p;
                        if self.step.dofs.fixed[q] {
                            0.0
                        } else {
                            s[a * c + b] * xl[q]
                        }
                    })
                    .sum();
                f[ra] -= v;
            }
        }
    }
}

/// An explicit step's lumped nodal quantities per ghosted dof (this rank's shares; see
/// [`Points::lumped_mass_and_momentum`]).
#[derive(Debug, Clone, Default)]
pub(super) struct Lumped {
    /// Σ S_ip m_p at the solid's dofs and Σ S_ip n ρ_w V_p at the water's.
    pub mass: Vec<f64>,
    /// Σ S_ip m_p v_p, likewise.
    pub momentum: Vec<f64>,
    /// Σ S_ip c_p (the drag) at the solid's and the water's dofs; empty without water.
    pub drag: Vec<f64>,
}

/// The particle side of the converged step: each point's result for the particle update.
impl<const D: usize, const M: usize> Step<D, M> {
    /// Σ S_ip u_i at particle `k` of the D components from `first` of a nodal field `u` per
    /// ghosted dof (barely filled nodes extended from their masters): [`kernels::interpolate`]'s
    /// `du` (`first` = 0) or `dw` (the layout's `w`), without the rest of the nodes' states.
    pub(super) fn interpolated_vector(&self, k: usize, u: &[f64], first: usize) -> [f64; D] {
        let (nodes, basis) = self.stencils.get(k);
        let d = node_vectors(self, k, u, first);
        let mut du = [0.0; D];
        for (b, d) in basis.iter().zip(&d[..nodes.len()]) {
            for c in 0..D {
                du[c] += b.s * d[c];
            }
        }
        du
    }

    /// The converged step at particle `k` for the particle update: exactly the point the converged
    /// residual evaluated.
    pub fn result<const N: usize>(&self, model: &Model<D>, solution: &Solution, k: usize) -> StepResult<D> {
        let (nodes, basis) = self.stencils.get(k);
        let states = node_states::<D, M, N>(self, k, &solution.increments);
        let mut input = particle_input(model, self, k);
        // The F̄ projection's scale of an explicit step (only the particle update sees it: the
        // step's forces are those of its start).
        let fbar = solution.fbar_scale.get(k).copied();
        if let Some([c, s, _]) = fbar {
            input.fbar = c;
            input.fbar_total = s;
        }
        let mat = &model.materials[model.particles.material[k] as usize];
        let strain = self.stencils.strain_of(k);
        let mut pt =
            kernels::Point::with_recovery(basis, strain, &states[..nodes.len()], &input, &mat.model, self.layout);
        pt.set_forces(self.stencils.forces_of(k));
        pt.set_faces(self.faces_of(k), &states[..nodes.len()]);
        let mut result = StepResult::of(&pt);
        if let Some(f) = fbar {
            result.jbar = Some(f[2]);
        }
        if self.layout.w.is_some() && self.layout.p.is_none() {
            // The u–U system: the nodal pressure's increment, or the point's own.
            result.interp.dp = match solution.pressure_increment.get(k) {
                Some(&dp) => dp,
                None => kernels::flow::continuity::pointwise_increment(&pt.interp, pt.part),
            };
        }
        if !solution.start_velocity.is_empty() {
            // An explicit step's FLIP increment Σ S (v_i^{n+1} − v_i^n) takes the v_i^n of its
            // own grid update (the predictors' nodal velocities are those of the raw projection,
            // without the barely filled nodes' shares moved to their masters).
            result.interp.motion.v_u = self.interpolated_vector(k, &solution.start_velocity, 0);
            result.interp.motion.v_w = match self.layout.w {
                Some(w) => self.interpolated_vector(k, &solution.start_velocity, w),
                None => [0.0; D],
            };
        }
        if !solution.xpic_correction.is_empty() {
            // XPIC: v_p = S v^{n+1} + S (w − v^n), S v^{n+1} = Δu_p/Δt.
            let c = self.interpolated_vector(k, &solution.xpic_correction, 0);
            let dt = self.dt;
            result.velocity = Some(std::array::from_fn(|d| result.interp.du[d] / dt + c[d]));
        }
        result
    }
}
