//! The verification: the names it gives resolved ([`link`]), and what its reference needs of the
//! bodies, loads, boundaries and stages it names and of the analysis ([`check`]).

use crate::case::{
    BearingCapacity, BodyAndLoad, BodyId, Case, CaseFile, DamBreakIds, ElasticColumnIds, FootingIds, Formulation,
    Geometry, LinkedVerification, Load, LoadId, Loading, PatchIds, RunoutIds, Shape, SoilModel, Verification,
};
use crate::check::{components, Checked};

/// The verification with the ids of what it names, after its own ranges.
pub(super) fn link(v: &Verification, file: &CaseFile) -> Result<LinkedVerification, String> {
    v.check("verification")?;
    let body = |name: &str| file.body_named("verification.body", name);
    let load = |name: &str| file.load_named("verification.load", name);
    let column = |b: &str, l: &str| Ok::<_, String>(BodyAndLoad { body: body(b)?, load: load(l)? });
    Ok(match v {
        Verification::Terzaghi(t) => LinkedVerification::Terzaghi(t.clone(), column(&t.body, &t.load)?),
        Verification::HarmonicColumn(h) => LinkedVerification::HarmonicColumn(h.clone(), column(&h.body, &h.load)?),
        Verification::LargeStrainConsolidation(x) => {
            LinkedVerification::LargeStrainConsolidation(x.clone(), column(&x.body, &x.load)?)
        }
        Verification::ShockWave(s) => LinkedVerification::ShockWave(s.clone(), column(&s.body, &s.load)?),
        Verification::Lame(l) => LinkedVerification::Lame(l.clone(), column(&l.body, &l.load)?),
        Verification::HollowCylinder(h) => LinkedVerification::HollowCylinder(h.clone(), column(&h.body, &h.load)?),
        Verification::ElasticColumn(e) => {
            let ids = ElasticColumnIds {
                body: body(&e.body)?,
                gravity: file.load_named("verification.gravity", &e.gravity)?,
                surcharge: e.surcharge.as_ref().map(|s| file.load_named("verification.surcharge", s)).transpose()?,
            };
            LinkedVerification::ElasticColumn(e.clone(), ids)
        }
        Verification::BearingCapacity(b) => {
            let soil = file.body_named("verification.soil", &b.soil)?;
            let loading = match (&b.load, &b.footing) {
                (None, Some(f)) => Loading::Footing(file.boundary_named("verification.footing", f)?),
                (Some(l), None) => Loading::Load(load(l)?),
                _ => return Err(BearingCapacity::loading_refused("verification")),
            };
            LinkedVerification::BearingCapacity(b.clone(), FootingIds { soil, loading })
        }
        Verification::Patch(p) => {
            let ids =
                PatchIds { body: body(&p.body)?, boundary: file.boundary_named("verification.boundary", &p.boundary)? };
            LinkedVerification::Patch(p.clone(), ids)
        }
        Verification::StiffnessMap(s) => LinkedVerification::StiffnessMap(s.clone(), body(&s.body)?),
        Verification::VerticalCut(v) => LinkedVerification::VerticalCut(v.clone(), body(&v.body)?),
        Verification::CookMembrane(m) => LinkedVerification::CookMembrane(m.clone(), body(&m.body)?),
        Verification::DamBreak(d) => {
            let ids = DamBreakIds {
                body: body(&d.body)?,
                gravity: file.load_named("verification.gravity", &d.gravity)?,
                settle_stage: file.stage_named("verification.settle_stage", &d.settle_stage)?,
            };
            LinkedVerification::DamBreak(d.clone(), ids)
        }
        Verification::Runout(r) => {
            let ids = RunoutIds {
                body: body(&r.body)?,
                trigger_stage: file.stage_named("verification.trigger_stage", &r.trigger_stage)?,
            };
            LinkedVerification::Runout(r.clone(), ids)
        }
    })
}

/// What the reference needs of the analysis and of what it names.
pub(super) fn check(c: &Case) -> Checked {
    let Some(v) = c.linked_verification() else {
        return Ok(());
    };
    if let Some((pore_water, message)) = formulation_needed(v) {
        if pore_water != (c.analysis.formulation == Formulation::TwoPhase) {
            return Err(format!("key `verification`: {message}"));
        }
    }
    references(c, v)
}

/// Whether the reference needs a two-phase analysis (`true`) or a one-phase one, and the message
/// when the case has the other; `None` where either will do.
fn formulation_needed(v: &LinkedVerification) -> Option<(bool, &'static str)> {
    use LinkedVerification as V;
    let one_phase = |what| Some((false, what));
    match v {
        V::Terzaghi(..) | V::HarmonicColumn(..) | V::LargeStrainConsolidation(..) | V::ShockWave(..) => {
            Some((true, "the consolidation and wave references need a two_phase analysis"))
        }
        V::ElasticColumn(..) => one_phase("the elastic column reference is for a one_phase analysis"),
        V::Lame(..) => one_phase("the Lamé reference is for a one_phase analysis"),
        V::HollowCylinder(..) => one_phase("the hollow cylinder's reference is for a one_phase analysis"),
        V::Patch(..) => one_phase("the patch reference is for a one_phase analysis"),
        V::CookMembrane(..) => one_phase("Cook's membrane is for a one_phase analysis"),
        V::DamBreak(..) => one_phase("the dam break is for a one_phase analysis"),
        V::Runout(..) => one_phase("the run-out check is for a one_phase analysis"),
        V::BearingCapacity(..) | V::StiffnessMap(..) | V::VerticalCut(..) => None,
    }
}

/// What each reference needs of the bodies, loads, boundaries and stages it names.
fn references(c: &Case, v: &LinkedVerification) -> Checked {
    use LinkedVerification as V;
    match v {
        V::Terzaghi(_, ids)
        | V::HarmonicColumn(_, ids)
        | V::LargeStrainConsolidation(_, ids)
        | V::ShockWave(_, ids) => plain_load(c, ids.load),
        V::Lame(_, ids) => {
            if !matches!(c.load(ids.load), Load::LinePressure(_)) {
                return Err(format!("key `verification.load`: `{}` must be a line_pressure load", name(c, ids.load)));
            }
            linear_elastic(c, ids.body, "the Lamé reference")
        }
        V::HollowCylinder(_, ids) => {
            if c.load(ids.load).traction().is_none() {
                return Err(format!(
                    "key `verification.load`: `{}` must be a nodal_traction or particle_traction load",
                    name(c, ids.load)
                ));
            }
            linear_elastic(c, ids.body, "the hollow cylinder's reference")?;
            if c.analysis.geometry != Geometry::Axisymmetric {
                return Err("key `verification`: the hollow cylinder's reference needs `analysis.geometry = \
                            \"axisymmetric\"`"
                    .into());
            }
            Ok(())
        }
        V::ElasticColumn(_, ids) => elastic_column(c, ids),
        V::BearingCapacity(b, ids) => bearing_capacity(c, &b.settlement_point, b.loaded_depth, ids),
        V::Patch(_, ids) => {
            if !matches!(c.material_of(ids.body).model, SoilModel::LinearElastic(_) | SoilModel::NeoHookean(_)) {
                return Err(format!(
                    "key `verification.body`: the patch reference needs a linear elastic or neo-Hookean body, and \
                     `{}` is neither",
                    c.body(ids.body).name
                ));
            }
            let b = c.boundary(ids.boundary);
            if b.velocity_gradient.is_none() {
                return Err(format!("key `verification.boundary`: `{}` has no `velocity_gradient`", b.name));
            }
            Ok(())
        }
        V::StiffnessMap(_, body) => stiffness_map(c, *body),
        V::VerticalCut(_, body) => {
            if !matches!(c.material_of(*body).model, SoilModel::VonMises(_)) {
                return Err(format!(
                    "key `verification.body`: the vertical cut's checks need a von_mises body, and `{}` is not",
                    c.body(*body).name
                ));
            }
            Ok(())
        }
        V::CookMembrane(..) => Ok(()),
        V::DamBreak(_, ids) => dam_break(c, ids),
        V::Runout(r, ids) => {
            let after: f64 = c.stages[ids.trigger_stage.index()..].iter().map(|s| s.duration).sum();
            match r.snapshot_times.iter().find(|&&t| !(t > 0.0 && t <= after * (1.0 + 1e-12))) {
                Some(t) => Err(format!(
                    "key `verification.snapshot_times`: {t} s is not within the {after} s after the trigger"
                )),
                None => Ok(()),
            }
        }
    }
}

/// The name of a load.
fn name(c: &Case, load: LoadId) -> &str {
    c.load(load).name()
}

/// A load whose reference follows its time function: without an `increment_factor` (only the
/// hollow cylinder's check follows one).
fn plain_load(c: &Case, load: LoadId) -> Checked {
    if c.load(load).increment_factor().is_some() {
        return Err(format!(
            "key `verification.load`: the check's reference follows the load's time function, and `{}` has an \
             `increment_factor` (only the hollow_cylinder check follows one)",
            name(c, load)
        ));
    }
    Ok(())
}

/// A linear elastic body, which `reference` needs.
fn linear_elastic(c: &Case, body: BodyId, reference: &str) -> Checked {
    if !matches!(c.material_of(body).model, SoilModel::LinearElastic(_)) {
        return Err(format!(
            "key `verification.body`: {reference} needs a linear elastic body, and `{}` is not",
            c.body(body).name
        ));
    }
    Ok(())
}

/// An elastic column: gravity a body force, a surcharge a traction.
fn elastic_column(c: &Case, ids: &ElasticColumnIds) -> Checked {
    plain_load(c, ids.gravity)?;
    if !matches!(c.load(ids.gravity), Load::BodyForce(_)) {
        return Err(format!("key `verification.gravity`: `{}` must be a body_force load", name(c, ids.gravity)));
    }
    match ids.surcharge {
        Some(s) if c.load(s).traction().is_none() => {
            Err(format!("key `verification.surcharge`: no traction load named `{}`", name(c, s)))
        }
        _ => Ok(()),
    }
}

/// A footing: its loaded depth as its dimension asks, a settlement point of as many coordinates,
/// and either a load (a body force naming the footing body) or a boundary that moves it down.
fn bearing_capacity(c: &Case, point: &[f64], loaded_depth: Option<f64>, ids: &FootingIds) -> Checked {
    match (loaded_depth, c.dimension()) {
        (None, 3) => {
            return Err("key `verification.loaded_depth`: a three-dimensional footing needs the loaded area's \
                        extent along z"
                .into())
        }
        (Some(_), 2) => {
            return Err("key `verification.loaded_depth`: only a three-dimensional case takes it (a plane \
                        footing's pressure is its force per unit length over `loaded_width`)"
                .into())
        }
        _ => {}
    }
    components("verification.settlement_point", point, c.dimension())?;
    match ids.loading {
        Loading::Footing(f) => {
            let b = c.boundary(f);
            let vertical = |v: &Option<Vec<f64>>| v.as_ref().is_some_and(|v| v.get(1).is_some_and(|&y| y != 0.0));
            if !b.fix.contains(&crate::case::Dof::Uy) || !(vertical(&b.velocity) || vertical(&b.displacement)) {
                return Err(format!(
                    "key `verification.footing`: the boundary `{}` must fix `uy` and move it vertically (`velocity` \
                     or `displacement`): its reaction is the footing's load",
                    b.name
                ));
            }
            Ok(())
        }
        Loading::Load(l) => {
            plain_load(c, l)?;
            if matches!(c.load(l), Load::BodyForce(f) if f.bodies.is_none()) {
                return Err(format!(
                    "key `verification.load`: the body force `{}` must name the footing body in `bodies`",
                    name(c, l)
                ));
            }
            Ok(())
        }
    }
}

/// The stiffness map: a linear elastic block on square cells in plane strain.
fn stiffness_map(c: &Case, body: BodyId) -> Checked {
    linear_elastic(c, body, "the stiffness map's reference")?;
    let h = c.cell_size();
    if (h[0] - h[1]).abs() > 1e-9 * h[0] {
        return Err(format!(
            "key `grid`: the stiffness map's reference is for square cells, got {} × {} m",
            h[0], h[1]
        ));
    }
    if c.analysis.geometry != Geometry::PlaneStrain {
        return Err("key `verification`: the stiffness map's reference is for plane strain".into());
    }
    Ok(())
}

/// The dam break: a rectangular column, gravity a body force, a settling stage that is not the
/// last.
fn dam_break(c: &Case, ids: &DamBreakIds) -> Checked {
    let body = c.body(ids.body);
    if !matches!(body.shape, Shape::Rectangle(_)) {
        return Err(format!("key `verification.body`: the dam break's column `{}` must be a rectangle", body.name));
    }
    if !matches!(c.load(ids.gravity), Load::BodyForce(_)) {
        return Err(format!("key `verification.gravity`: `{}` must be a body_force load", name(c, ids.gravity)));
    }
    if ids.settle_stage.index() + 1 == c.stages.len() {
        return Err(format!(
            "key `verification.settle_stage`: `{}` is the last stage, so the water never flows",
            c.stage(ids.settle_stage).name
        ));
    }
    Ok(())
}
