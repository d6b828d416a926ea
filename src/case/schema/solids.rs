//! The three-dimensional shapes a body may fill instead of a planar section extruded along z: an
//! axis-aligned box, a ball and a circular cylinder along a grid axis. A point on the surface
//! counts as inside, as on a rectangle's edge.

use crate::check::{at, positive, Checked};
use serde::{Deserialize, Serialize};

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Cuboid {
    /// The corner of the smallest x, y and z [m].
    pub min: [f64; 3],
    /// The opposite corner [m], beyond `min` in every direction.
    pub max: [f64; 3],
}

/// A ball.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Sphere {
    /// Its centre [m].
    pub center: [f64; 3],
    /// Its radius [m], > 0.
    pub radius: f64,
}

/// A circular cylinder whose axis is parallel to a grid axis.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Cylinder {
    /// The centre of its axis, halfway between its end faces [m].
    pub center: [f64; 3],
    /// The direction of its axis: `"x"`, `"y"` or `"z"`.
    pub axis: Direction,
    /// Its radius [m], > 0.
    pub radius: f64,
    /// Its length along the axis [m], > 0.
    pub length: f64,
}

/// A grid axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// x.
    X,
    /// y.
    Y,
    /// z.
    Z,
}

/// A shape of three dimensions.
pub trait Solid {
    /// Checks its values; `key` is its table (`bodies[0].shape.sphere`).
    fn check(&self, key: &str) -> Checked;
    /// Its bounding box (min, max) [m].
    fn bounds3(&self) -> ([f64; 3], [f64; 3]);
    /// Whether it holds the point `p` [m].
    fn holds(&self, p: [f64; 3]) -> bool;
}

/// Each of `v` finite, named `key`.
fn finite3(key: &str, v: [f64; 3]) -> Checked {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(format!("key `{key}`: must be finite, got {v:?}"))
    }
}

impl Solid for Cuboid {
    fn check(&self, key: &str) -> Checked {
        finite3(&at(key, "min"), self.min)?;
        finite3(&at(key, "max"), self.max)?;
        if (0..3).any(|d| self.max[d] <= self.min[d]) {
            return Err(format!(
                "key `{key}`: max must exceed min in x, y and z, got {:?} .. {:?}",
                self.min, self.max
            ));
        }
        Ok(())
    }
    fn bounds3(&self) -> ([f64; 3], [f64; 3]) {
        (self.min, self.max)
    }
    fn holds(&self, p: [f64; 3]) -> bool {
        (0..3).all(|d| p[d] >= self.min[d] && p[d] <= self.max[d])
    }
}

impl Solid for Sphere {
    fn check(&self, key: &str) -> Checked {
        finite3(&at(key, "center"), self.center)?;
        positive(&at(key, "radius"), self.radius)
    }
    fn bounds3(&self) -> ([f64; 3], [f64; 3]) {
        (self.center.map(|c| c - self.radius), self.center.map(|c| c + self.radius))
    }
    fn holds(&self, p: [f64; 3]) -> bool {
        (0..3).map(|d| (p[d] - self.center[d]).powi(2)).sum::<f64>() <= self.radius * self.radius
    }
}

impl Cylinder {
    /// The index of its axis.
    fn along(&self) -> usize {
        match self.axis {
            Direction::X => 0,
            Direction::Y => 1,
            Direction::Z => 2,
        }
    }
}

impl Solid for Cylinder {
    fn check(&self, key: &str) -> Checked {
        finite3(&at(key, "center"), self.center)?;
        positive(&at(key, "radius"), self.radius)?;
        positive(&at(key, "length"), self.length)
    }
    fn bounds3(&self) -> ([f64; 3], [f64; 3]) {
        let a = self.along();
        let half = |d: usize| if d == a { 0.5 * self.length } else { self.radius };
        (std::array::from_fn(|d| self.center[d] - half(d)), std::array::from_fn(|d| self.center[d] + half(d)))
    }
    fn holds(&self, p: [f64; 3]) -> bool {
        let a = self.along();
        let r2: f64 = (0..3).filter(|&d| d != a).map(|d| (p[d] - self.center[d]).powi(2)).sum();
        r2 <= self.radius * self.radius && (p[a] - self.center[a]).abs() <= 0.5 * self.length
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_solid_holds_its_points_and_bounds_them() {
        let ball = Sphere { center: [1.0, 2.0, 3.0], radius: 0.5 };
        assert!(ball.holds([1.0, 2.5, 3.0]) && !ball.holds([1.4, 2.4, 3.0]));
        assert_eq!(ball.bounds3(), ([0.5, 1.5, 2.5], [1.5, 2.5, 3.5]));
        let pipe = Cylinder { center: [0.0, 0.0, 0.0], axis: Direction::Y, radius: 1.0, length: 4.0 };
        assert!(pipe.holds([0.6, 1.9, -0.7]) && !pipe.holds([0.8, 0.0, 0.7]) && !pipe.holds([0.0, 2.1, 0.0]));
        assert_eq!(pipe.bounds3(), ([-1.0, -2.0, -1.0], [1.0, 2.0, 1.0]));
        let block = Cuboid { min: [0.0; 3], max: [1.0, 2.0, 3.0] };
        assert!(block.holds([1.0, 2.0, 3.0]) && !block.holds([0.5, 0.5, 3.1]));
        assert!(block.check("b").is_ok());
        let flat = Cuboid { min: [0.0; 3], max: [1.0, 2.0, 0.0] };
        assert!(flat.check("b").unwrap_err().contains("max must exceed min"));
        assert!(Sphere { radius: 0.0, ..ball }.check("s").unwrap_err().contains("radius"));
    }
}
