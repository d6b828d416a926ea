//! The equilibrium identity of every converged step and the boundaries' reactions
//! (`equilibrium_error`, `<boundary>.reaction_*` and, for a boundary with prescribed motion or a
//! rigid body under a force, `<boundary>.displacement_*` in `history.csv`, and for a rigid body
//! that rotates `<boundary>.rotation_*` and `<boundary>.reaction_moment_*`; the worst error in
//! `summary.json`). A rigid body's displacement (of its force's point) and rotation are the sums
//! of its steps' motions, kept in checkpoints.
//!
//! The identity: the volume integral of the total Cauchy stress over the updated material points,
//! ∫σ dV = Σ_p (σ' − p m) V_p, against the first moment of the external forces, the reactions and
//! the inertia forces about the same point, Σ_i x_i ⊗ (F_ext + R − F_inertia)_i on the nodes at
//! t_{n+1} ([`StepForces`]). The relative error is taken in the Frobenius norm against the largest
//! of the moments. In axial symmetry the moments are taken about the axis (r = 0) and the hoop
//! stress takes part: Σ r_i f_r,i = ∫(σ_rr + σ_θθ) dV and Σ (y_i − y_o) f_r,i = ∫(σ_ry + (y − y_o)
//! σ_θθ / r) dV (virtual displacements r e_r and (y − y_o) e_r), exact for the planar weights
//! without B̄ and up to the discretisation of the hoop operator otherwise. An explicit step's
//! forces are those of its start (`StepForces::at_start`): ∫σ dV is then taken over the points
//! before their update, and the identity holds at t_n on x_n with the lumped inertia of the nodal
//! update.

use super::{Converged, FromCheckpoint, Moment, Recorder, Restored, Sink};
use crate::assembly::StepForces;
use crate::model::Model;

const AXES: [&str; 3] = ["x", "y", "z"];

/// The identity and the reactions of the last converged step.
pub struct Equilibrium<const D: usize> {
    names: Vec<String>,
    moving: Vec<String>,
    /// The rigid bodies that rotate, with the axes they turn about.
    rotating: Vec<(String, std::ops::Range<usize>)>,
    /// The last converged step's forces, and ∫σ dV of its points before their update (an explicit
    /// step's).
    last: Option<(StepForces<D>, Option<Vec<f64>>)>,
    /// The last accepted step's error and reactions.
    error: f64,
    reactions: Vec<[f64; D]>,
    /// The moments of the last accepted step's reactions about the origin.
    moments: Vec<[f64; 3]>,
    /// Each rigid body's displacement [m] and rotation [rad] so far (per boundary; zero for the
    /// others), in the slots of [`StepForces::rigid_motion`].
    rigid: Vec<[f64; 6]>,
}

impl<const D: usize> Equilibrium<D> {
    /// The identity of `model`'s runs, with a reaction per boundary.
    pub fn new(model: &Model<D>) -> Equilibrium<D> {
        Equilibrium {
            names: model.boundaries.iter().map(|b| b.name.clone()).collect(),
            moving: model
                .boundaries
                .iter()
                .filter(|b| b.motion.is_some() || b.force.is_some())
                .map(|b| b.name.clone())
                .collect(),
            rotating: model
                .boundaries
                .iter()
                .filter_map(|b| Some((b.name.clone(), b.force.as_ref()?.rotation_axes())))
                .filter(|(_, axes)| !axes.is_empty())
                .collect(),
            last: None,
            error: 0.0,
            reactions: vec![[0.0; D]; model.boundaries.len()],
            moments: vec![[0.0; 3]; model.boundaries.len()],
            rigid: vec![[0.0; 6]; model.boundaries.len()],
        }
    }
}

/// This rank's share of ∫σ dV (total stress, current configuration; in axial symmetry with the
/// hoop stress's share about `origin`), the left side of the identity, row by row (D × D
/// entries).
fn stress_integral<const D: usize>(model: &Model<D>, origin: &[f64; D]) -> Vec<f64> {
    let ps = &model.particles;
    let axisymmetric = model.geometry.axisymmetric();
    let mut local = vec![0.0; D * D];
    for k in 0..ps.len() {
        let s = ps.stress[k];
        let p = if model.pore_water { ps.p[k] } else { 0.0 };
        let v = ps.volume[k];
        // The stress tensor [xx, xy, xz; yx, yy, yz; zx, zy, zz] from [xx, yy, xy, zz, yz, zx].
        let t = [[s[0] - p, s[2], s[5]], [s[2], s[1] - p, s[4]], [s[5], s[4], s[3] - p]];
        for a in 0..D {
            for b in 0..D {
                local[a * D + b] += t[a][b] * v;
            }
        }
        if axisymmetric {
            local[0] += (s[3] - p) * v;
            local[2] += (ps.x[k][1] - origin[1]) * (s[3] - p) * v / ps.x[k][0];
        }
    }
    local
}

impl<const D: usize> Recorder<D> for Equilibrium<D> {
    fn name(&self) -> &'static str {
        "equilibrium"
    }

    fn columns(&self) -> Vec<String> {
        let mut c = vec!["equilibrium_error".to_string()];
        for b in &self.names {
            c.extend(AXES[..D].iter().map(|a| format!("{b}.reaction_{a}")));
        }
        for b in &self.moving {
            c.extend(AXES[..D].iter().map(|a| format!("{b}.displacement_{a}")));
        }
        for (b, axes) in &self.rotating {
            c.extend(AXES[axes.clone()].iter().map(|a| format!("{b}.rotation_{a}")));
            c.extend(AXES[axes.clone()].iter().map(|a| format!("{b}.reaction_moment_{a}")));
        }
        c
    }

    fn converged(&mut self, at: &Converged<D>) -> Result<(), String> {
        let before = at.forces.at_start.then(|| stress_integral(at.model, &at.forces.origin));
        self.last = Some((at.forces.clone(), before));
        Ok(())
    }

    fn record(&mut self, at: &Moment<D>, row: bool, sink: &mut Sink) -> Result<Vec<f64>, String> {
        if let Some((forces, before)) = self.last.take() {
            let lhs = before.unwrap_or_else(|| stress_integral(at.model, &forces.origin));
            let lhs = at.coll.sum(&lhs)?;
            let m = &forces.moment;
            let diff: Vec<f64> = (0..D * D).map(|e| lhs[e] - m[e / D][e % D]).collect();
            let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
            let scale = norm(&lhs).max(forces.scale);
            self.error = if scale > 0.0 { norm(&diff) / scale } else { 0.0 };
            self.reactions = forces.reactions;
            self.moments = forces.reaction_moments;
            for (total, step) in self.rigid.iter_mut().zip(&forces.rigid_motion) {
                total.iter_mut().zip(step).for_each(|(t, s)| *t += s);
            }
            let error = self.error;
            let worst =
                sink.summary.equilibrium_error.map_or(error, |w| if error.is_nan() { error } else { w.max(error) });
            sink.summary.equilibrium_error = Some(worst);
        }
        if !row {
            return Ok(Vec::new());
        }
        let mut values = vec![self.error];
        for r in &self.reactions {
            values.extend(r);
        }
        for (b, rigid) in at.model.boundaries.iter().zip(&self.rigid) {
            match (&b.motion, &b.force) {
                (Some(m), _) => values.extend(m.displacement_at(at.t)),
                (None, Some(_)) => values.extend(&rigid[..D]),
                (None, None) => {}
            }
        }
        for (i, b) in at.model.boundaries.iter().enumerate() {
            let axes = b.force.as_ref().map_or(0..0, |f| f.rotation_axes());
            values.extend(axes.clone().map(|a| self.rigid[i][3 + a]));
            values.extend(axes.map(|a| self.moments[i][a]));
        }
        Ok(values)
    }

    fn state(&self, at: &Moment<D>) -> Result<Option<Vec<f64>>, String> {
        let rigid = at.model.boundaries.iter().any(|b| b.force.is_some());
        Ok(rigid.then(|| self.rigid.iter().flatten().copied().collect()))
    }

    fn restore(&mut self, from: FromCheckpoint<D>) -> Restored {
        let Some(state) = from.state else {
            let rigid = from.at.model.boundaries.iter().any(|b| b.force.is_some());
            return Ok(rigid.then(|| {
                format!("the checkpoint holds no rigid-body displacements: they count from t = {:.6e} s", from.at.t)
            }));
        };
        if state.len() != self.rigid.len() * 6 {
            return Err(format!(
                "it holds {} rigid-body motion components, this case has {}",
                state.len(),
                self.rigid.len() * 6
            ));
        }
        for (r, s) in self.rigid.iter_mut().zip(state.chunks_exact(6)) {
            r.copy_from_slice(s);
        }
        Ok(None)
    }
}
