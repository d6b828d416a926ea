//! The ranges a value of a case file may take, each a function whose message names the key
//! (`key `materials[0].porosity`: must be in (0, 1), got 1.2`). The tables of the schema check
//! their own values with them, next to their definitions; validation checks what several tables
//! say together with the same functions.

use std::collections::HashSet;

/// The outcome of a check: `Err` holds the whole message, starting with the key it names.
pub type Checked = Result<(), String>;

/// Largest modulus accepted [Pa]: ten times diamond's Young's modulus. Beyond it a soil tangent
/// holds no digits of the load (E = 1e308 overflowed to NaN before the run failed).
pub const MAX_MODULUS: f64 = 1e13;
/// Largest hydraulic conductivity accepted [m/s] (open gravel is about 1e-1).
pub const MAX_CONDUCTIVITY: f64 = 1.0;
/// Largest pressure-projection factor α accepted (τ = α/G; the values that work are of order 1).
pub const MAX_PROJECTION: f64 = 1e3;
/// Largest density accepted [kg/m³] (osmium is 22 590).
pub const MAX_DENSITY: f64 = 1e5;

/// The key of `field` in the table at `key`: `at("materials[0]", "porosity")` is
/// `materials[0].porosity`.
pub fn at(key: &str, field: &str) -> String {
    format!("{key}.{field}")
}

/// A finite number above zero.
pub fn positive(key: &str, v: f64) -> Checked {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be a positive number, got {v}"))
    }
}

/// A positive physical magnitude of at most `hi` (in `unit`), with the reason for the bound.
pub fn magnitude(key: &str, v: f64, hi: f64, unit: &str, why: &str) -> Checked {
    positive(key, v)?;
    at_most(key, v, hi, unit, why)
}

/// At most `hi` (in `unit`, empty for a pure number), with the reason for the bound.
pub fn at_most(key: &str, v: f64, hi: f64, unit: &str, why: &str) -> Checked {
    if v > hi {
        let bound = if unit.is_empty() { format!("{hi:e}") } else { format!("{hi:e} {unit}") };
        return Err(format!("key `{key}`: must be at most {bound} ({why}), got {v:e}"));
    }
    Ok(())
}

/// A modulus in (0, [`MAX_MODULUS`]] Pa.
pub fn modulus(key: &str, v: f64) -> Checked {
    magnitude(key, v, MAX_MODULUS, "Pa", "stiffer than any geomaterial: the tangent would hold no digits of the load")
}

/// A strength in [0, [`MAX_MODULUS`]] Pa (above zero unless `zero` allows it): a strength above the
/// stiffest modulus a case may give is never reached.
pub fn strength(key: &str, v: f64, zero: bool) -> Checked {
    if zero {
        non_negative(key, v)?;
    } else {
        positive(key, v)?;
    }
    at_most(
        key,
        v,
        MAX_MODULUS,
        "Pa",
        "a strength above the stiffest modulus a case may give: the material would never yield",
    )
}

/// The largest dynamic viscosity a case may give [Pa s]: about glacier ice's.
pub const MAX_VISCOSITY: f64 = 1e13;

/// A dynamic viscosity in [0, [`MAX_VISCOSITY`]] Pa s.
pub fn viscosity(key: &str, v: f64) -> Checked {
    non_negative(key, v)?;
    let why = "about glacier ice's: a fluid more viscous is a solid over any duration a run resolves";
    at_most(key, v, MAX_VISCOSITY, "Pa s", why)
}

/// A number above zero, or `inf`.
pub fn positive_or_inf(key: &str, v: f64) -> Checked {
    if v > 0.0 && !v.is_nan() {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be positive (or inf), got {v}"))
    }
}

/// A number in the open interval (lo, hi).
pub fn in_open(key: &str, v: f64, lo: f64, hi: f64) -> Checked {
    if v > lo && v < hi {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be in ({lo}, {hi}), got {v}"))
    }
}

/// A number in [lo, hi).
pub fn in_closed_open(key: &str, v: f64, lo: f64, hi: f64) -> Checked {
    if v >= lo && v < hi {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be in [{lo}, {hi}), got {v}"))
    }
}

/// A finite number of at least zero.
pub fn non_negative(key: &str, v: f64) -> Checked {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be a non-negative number, got {v}"))
    }
}

/// A finite number.
pub fn finite(key: &str, v: f64) -> Checked {
    if v.is_finite() {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be finite"))
    }
}

/// A point of the plane with finite coordinates.
pub fn finite2(key: &str, v: [f64; 2]) -> Checked {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be finite, got {v:?}"))
    }
}

/// At least `min` finite points in the plane under `key`.`field` (`what` names the figure they
/// make in the message: "a polygon needs at least 3 vertices").
pub fn finite_points(key: &str, field: &str, points: &[[f64; 2]], min: usize, what: &str) -> Checked {
    if points.len() < min {
        return Err(format!("key `{}`: {what} needs at least {min} {field}", at(key, field)));
    }
    points.iter().enumerate().try_for_each(|(j, p)| finite2(&format!("{key}.{field}[{j}]"), *p))
}

/// A vector of `dim` finite components (one per direction of the grid).
pub fn components(key: &str, v: &[f64], dim: usize) -> Checked {
    if v.len() != dim {
        return Err(format!("key `{key}`: {dim} components in a case of {dim} dimensions, got {}", v.len()));
    }
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be finite, got {v:?}"))
    }
}

/// Names of the tables of an array (`what`: `materials`, `bodies`, ...), each given and used once.
pub fn unique<'a>(what: &str, names: impl Iterator<Item = &'a str>) -> Checked {
    let mut seen = HashSet::new();
    for n in names {
        if n.is_empty() {
            return Err(format!("{what}: names must not be empty"));
        }
        if !seen.insert(n) {
            return Err(format!("{what}: the name `{n}` is used twice"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::finite_points;

    #[test]
    fn too_few_or_non_finite_points_are_refused_with_the_key_named() {
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]];
        assert!(finite_points("bodies[0].polygon", "vertices", &square, 3, "a polygon").is_ok());
        let short = finite_points("bodies[0].polygon", "vertices", &square[..2], 3, "a polygon").unwrap_err();
        assert_eq!(short, "key `bodies[0].polygon.vertices`: a polygon needs at least 3 vertices");
        let nan = [[0.0, 0.0], [f64::NAN, 1.0]];
        let bad = finite_points("loads[1]", "points", &nan, 2, "a line").unwrap_err();
        assert!(bad.starts_with("key `loads[1].points[1]`: must be finite"), "{bad}");
    }
}
