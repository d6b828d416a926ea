//! Materials: the porosity and the water's keys as the formulation needs them, each model's own
//! ranges, whether a softening model has a unique return, and where the finite-strain models may
//! be used.

use crate::case::{AnalysisType, Case, Formulation, Geometry, Material};
use crate::check::{at, in_closed_open, in_open, magnitude, modulus, positive_or_inf, Checked, MAX_CONDUCTIVITY};

/// Every material, then where its model may be used.
pub(super) fn check(c: &Case) -> Checked {
    let pore_water = c.analysis.formulation == Formulation::TwoPhase;
    for (i, m) in c.materials.iter().enumerate() {
        material(&format!("materials[{i}]"), m, pore_water)?;
    }
    finite_strain_materials(c)
}

/// One material: its porosity's range (a one-phase material may have no pores: a fluid, a solid;
/// its density is the mixture's), its own values and model, and the two-phase keys.
fn material(key: &str, m: &Material, pore_water: bool) -> Checked {
    let k = |f: &str| at(key, f);
    if pore_water {
        in_open(&k("porosity"), m.porosity, 0.0, 1.0)?;
    } else {
        in_closed_open(&k("porosity"), m.porosity, 0.0, 1.0)?;
    }
    m.check(key)?;
    if !pore_water {
        return Ok(());
    }
    let required = |f: &str, v: Option<f64>, hint: &str| {
        v.ok_or_else(|| format!("key `{}`: required with `formulation = \"two_phase\"`{hint}", k(f)))
    };
    modulus(&k("water_bulk_modulus"), required("water_bulk_modulus", m.water_bulk_modulus, "")?)?;
    let why = "more permeable than open gravel";
    let conductivity = required("hydraulic_conductivity", m.hydraulic_conductivity, "")?;
    magnitude(&k("hydraulic_conductivity"), conductivity, MAX_CONDUCTIVITY, "m/s", why)?;
    match required("solid_bulk_modulus", m.solid_bulk_modulus, " (inf for incompressible grains)")? {
        ks if ks.is_infinite() => positive_or_inf(&k("solid_bulk_modulus"), ks),
        ks => modulus(&k("solid_bulk_modulus"), ks),
    }
}

/// Where a finite-strain material (`neo_hookean`, `hencky_j2`, `newtonian_fluid`) may be used: in
/// explicit stages only (the implicit stages need its consistent tangent, not built), in plane
/// strain (its kinematics have F_zz = 1), and, for the hyperelastic neo-Hookean and the fluid,
/// without an initial stress (their stress is a function of the deformation and rate alone; a
/// Hencky–J2 point's initial stress is its initial elastic strain).
fn finite_strain_materials(c: &Case) -> Checked {
    for (i, m) in c.materials.iter().enumerate().filter(|(_, m)| m.model.is_finite_strain()) {
        let name = m.model.kind();
        if let Some(s) = c.stages.iter().find(|s| s.analysis != AnalysisType::DynamicExplicit) {
            return Err(format!(
                "key `materials[{i}].model`: `{name}` runs in dynamic_explicit stages only (its consistent \
                 tangent for the implicit stages is not built), and stage `{}` is not one",
                s.name
            ));
        }
        if c.analysis.geometry == Geometry::Axisymmetric {
            return Err(format!(
                "key `materials[{i}].model`: `{name}` is written for plane strain (F_zz = 1) and the analysis is \
                 axisymmetric"
            ));
        }
        let Some(function_of) = m.model.stress_function_of() else {
            continue;
        };
        let stressed = c.body_ids().find(|&b| {
            let body = c.body(b);
            c.material_id_of(b).index() == i
                && (body.initial_stress.is_some()
                    || body.uniform_stress.is_some()
                    || body.initial.as_ref().is_some_and(|i| i.stress.is_some()))
        });
        if let Some(b) = stressed {
            return Err(format!(
                "key `bodies.{}`: a {name} body takes no initial stress (its stress is a function of \
                 {function_of}; reach a stressed state with a settling stage)",
                c.body(b).name
            ));
        }
    }
    Ok(())
}
