//! Material points given one by one (a particle file's): their positions and measures, and the
//! region they fill, the union of their GIMP domains (cubes of their measure).

use super::buckets::Buckets;

/// A particle file's rows as read: positions [m], volumes [m³] and the initial fields the file
/// gives (each for every row, or none).
#[derive(Debug, Clone, Default)]
pub struct PointRows {
    /// Positions.
    pub x: Vec<[f64; 3]>,
    /// Volumes.
    pub volume: Vec<f64>,
    /// Initial fields.
    pub fields: PointFields,
}

/// The initial fields a particle file gives its points, each for every point or none.
#[derive(Debug, Clone, Default)]
pub struct PointFields {
    /// Velocity [m/s] (z zero in the plane).
    pub velocity: Option<Vec<[f64; 3]>>,
    /// Effective stress [xx, yy, xy, zz, yz, zx] [Pa] (tension positive).
    pub stress: Option<Vec<[f64; 6]>>,
    /// Pore pressure [Pa] (compression positive).
    pub pore_pressure: Option<Vec<f64>>,
}

/// Points of a plane (x, y) or three-dimensional region.
#[derive(Clone)]
pub struct PointCloud {
    dim: usize,
    x: Vec<[f64; 3]>,
    measure: Vec<f64>,
    /// The initial fields of its points.
    pub fields: PointFields,
    lo: [f64; 3],
    hi: [f64; 3],
    buckets: Buckets<3>,
}

impl std::fmt::Debug for PointCloud {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "PointCloud {{ dim: {}, points: {}, bounds: {:?} .. {:?} }}",
            self.dim,
            self.x.len(),
            self.lo,
            self.hi
        )
    }
}

impl PointCloud {
    /// The points at `x` (z ignored in the plane) with measures `measure` (areas in the plane,
    /// volumes in three dimensions) [m², m³]; an error names the first point without a finite
    /// position or a positive measure, counting from 0.
    pub fn new(dim: usize, mut x: Vec<[f64; 3]>, measure: Vec<f64>) -> Result<PointCloud, String> {
        if x.is_empty() {
            return Err("it holds no point".into());
        }
        if dim == 2 {
            x.iter_mut().for_each(|p| p[2] = 0.0);
        }
        if let Some(k) = (0..x.len()).find(|&k| x[k].iter().any(|v| !v.is_finite())) {
            return Err(format!("its point {k} is at {:?}", x[k]));
        }
        if let Some(k) = (0..x.len()).find(|&k| !(measure[k] > 0.0 && measure[k].is_finite())) {
            return Err(format!("its point {k} has the measure {}, which must be positive", measure[k]));
        }
        let mut cloud = PointCloud {
            dim,
            x,
            measure,
            fields: PointFields::default(),
            lo: [0.0; 3],
            hi: [0.0; 3],
            buckets: Buckets::new([0.0; 3], [0.0; 3], &[]),
        };
        let boxes: Vec<([f64; 3], [f64; 3])> = (0..cloud.x.len()).map(|k| cloud.domain(k)).collect();
        cloud.lo = std::array::from_fn(|d| boxes.iter().map(|b| b.0[d]).fold(f64::INFINITY, f64::min));
        cloud.hi = std::array::from_fn(|d| boxes.iter().map(|b| b.1[d]).fold(f64::NEG_INFINITY, f64::max));
        cloud.buckets = Buckets::new(cloud.lo, cloud.hi, &boxes);
        Ok(cloud)
    }

    /// The half-width of point `k`'s domain [m]: half the side of the square or cube of its
    /// measure.
    pub fn half_width(&self, k: usize) -> f64 {
        super::half_side(self.measure[k], self.dim)
    }

    /// Point `k`'s domain (its z extent zero in the plane).
    fn domain(&self, k: usize) -> ([f64; 3], [f64; 3]) {
        let a = self.half_width(k);
        let reach = |d: usize| if d < self.dim { a } else { 0.0 };
        (std::array::from_fn(|d| self.x[k][d] - reach(d)), std::array::from_fn(|d| self.x[k][d] + reach(d)))
    }

    /// Its dimension: 2 (x, y) or 3.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Its number of points.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether it has no point (never: [`PointCloud::new`] refuses none).
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// The bounding box of its points' domains [m].
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        (self.lo, self.hi)
    }

    /// Calls `f(k, x, measure)` for every point.
    pub fn for_each(&self, mut f: impl FnMut(usize, [f64; 3], f64)) {
        for k in 0..self.x.len() {
            f(k, self.x[k], self.measure[k]);
        }
    }

    /// Whether a point's domain holds `p` (its boundary included).
    pub fn holds(&self, p: [f64; 3]) -> bool {
        let p = if self.dim == 2 { [p[0], p[1], 0.0] } else { p };
        self.buckets.near(p).iter().any(|&k| {
            let (lo, hi) = self.domain(k as usize);
            (0..3).all(|d| p[d] >= lo[d] && p[d] <= hi[d])
        })
    }
}

#[cfg(test)]
mod tests {
    use super::PointCloud;

    /// Four points of 0.01 m² in the plane: their domains are 0.1 m squares; what lies between
    /// two of them is held, beyond them not; a point without a positive measure is named.
    #[test]
    fn a_cloud_holds_its_points_domains() {
        let x = vec![[0.05, 0.05, 9.0], [0.15, 0.05, 0.0], [0.05, 0.15, 0.0], [0.15, 0.15, 0.0]];
        let c = PointCloud::new(2, x.clone(), vec![0.01; 4]).unwrap();
        assert_eq!(c.bounds(), ([0.0, 0.0, 0.0], [0.2, 0.2, 0.0]));
        assert!(c.holds([0.1, 0.1, 3.0]) && c.holds([0.2, 0.0, 0.0]) && !c.holds([0.21, 0.1, 0.0]));
        let e = PointCloud::new(2, x, vec![0.01, 0.0, 0.01, 0.01]).unwrap_err();
        assert!(e.contains("its point 1 has the measure 0"), "{e}");
    }
}
