//! A uniform grid of buckets over a bounding box, each listing the items (cells, triangles) whose
//! own boxes meet it: a point's candidates are its bucket's list.

/// Items of `D`-dimensional boxes sorted into buckets (a compressed list per bucket).
#[derive(Debug, Clone)]
pub(super) struct Buckets<const D: usize> {
    lo: [f64; D],
    hi: [f64; D],
    width: [f64; D],
    n: [usize; D],
    start: Vec<u32>,
    items: Vec<u32>,
}

impl<const D: usize> Buckets<D> {
    /// Buckets over (`lo`, `hi`) for the items whose boxes are `boxes`, about one item per bucket.
    pub fn new(lo: [f64; D], hi: [f64; D], boxes: &[([f64; D], [f64; D])]) -> Buckets<D> {
        let per_side = ((boxes.len().max(1) as f64).powf(1.0 / D as f64).ceil() as usize).clamp(1, 256);
        let n = std::array::from_fn(|d| if hi[d] > lo[d] { per_side } else { 1 });
        let width = std::array::from_fn(|d| if hi[d] > lo[d] { (hi[d] - lo[d]) / n[d] as f64 } else { 1.0 });
        let mut b = Buckets { lo, hi, width, n, start: Vec::new(), items: Vec::new() };
        let total: usize = n.iter().product();
        let mut count = vec![0u32; total + 1];
        b.each_bucket_of(boxes, |k, _| count[k + 1] += 1);
        for k in 0..total {
            count[k + 1] += count[k];
        }
        let mut fill = count.clone();
        b.items = vec![0; count[total] as usize];
        let mut items = std::mem::take(&mut b.items);
        b.each_bucket_of(boxes, |k, i| {
            items[fill[k] as usize] = i as u32;
            fill[k] += 1;
        });
        b.items = items;
        b.start = count;
        b
    }

    /// Calls `f(bucket, item)` for every bucket each item's box meets.
    fn each_bucket_of(&self, boxes: &[([f64; D], [f64; D])], mut f: impl FnMut(usize, usize)) {
        for (i, (lo, hi)) in boxes.iter().enumerate() {
            let a: [usize; D] = std::array::from_fn(|d| self.coord(d, lo[d]));
            let z: [usize; D] = std::array::from_fn(|d| self.coord(d, hi[d]));
            let mut k = a;
            loop {
                f(self.linear(k), i);
                let mut d = 0;
                while d < D {
                    if k[d] < z[d] {
                        k[d] += 1;
                        break;
                    }
                    k[d] = a[d];
                    d += 1;
                }
                if d == D {
                    break;
                }
            }
        }
    }

    /// The bucket coordinate of `v` in direction `d`, clamped to the grid: monotone in `v`, so a
    /// point inside an item's box lands in one of the buckets the box was listed in.
    fn coord(&self, d: usize, v: f64) -> usize {
        let c = ((v - self.lo[d]) / self.width[d]).floor();
        if c > 0.0 {
            (c as usize).min(self.n[d] - 1)
        } else {
            0
        }
    }

    fn linear(&self, k: [usize; D]) -> usize {
        (0..D).rev().fold(0, |acc, d| acc * self.n[d] + k[d])
    }

    /// The items listed in the bucket of `x` (none outside the bounding box).
    pub fn near(&self, x: [f64; D]) -> &[u32] {
        if (0..D).any(|d| !(x[d] >= self.lo[d] && x[d] <= self.hi[d])) {
            return &[];
        }
        let k = self.linear(std::array::from_fn(|d| self.coord(d, x[d])));
        &self.items[self.start[k] as usize..self.start[k + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::Buckets;

    /// Every point inside an item's box finds the item among its bucket's.
    #[test]
    fn a_point_in_a_box_finds_the_box() {
        let boxes: Vec<([f64; 2], [f64; 2])> = (0..50)
            .map(|i| {
                let x = (i as f64 * 0.37) % 1.0;
                let y = (i as f64 * 0.61) % 1.0;
                ([x, y], [x + 0.1, y + 0.05])
            })
            .collect();
        let b = Buckets::new([0.0, 0.0], [1.1, 1.05], &boxes);
        for (i, (lo, hi)) in boxes.iter().enumerate() {
            for t in [0.0, 0.3, 1.0] {
                let p = [lo[0] + t * (hi[0] - lo[0]), lo[1] + t * (hi[1] - lo[1])];
                assert!(b.near(p).contains(&(i as u32)), "{i} at {p:?}");
            }
        }
        assert!(b.near([1.2, 0.5]).is_empty());
    }
}
