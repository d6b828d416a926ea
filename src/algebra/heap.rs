//! Bytes a container holds on the heap (its capacity times its element's size), for the memory
//! breakdown of a run (`summary.json`'s `memory`).

/// The heap bytes of a vector's buffer at its capacity (not of what its elements own).
pub fn capacity<T>(v: &Vec<T>) -> usize {
    v.capacity() * std::mem::size_of::<T>()
}

/// The heap bytes of a vector of vectors: the outer buffer and every inner one.
pub fn nested<T>(v: &Vec<Vec<T>>) -> usize {
    capacity(v) + v.iter().map(capacity).sum::<usize>()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_vector_holds_its_capacity_of_elements() {
        let mut v: Vec<[f64; 3]> = Vec::with_capacity(10);
        v.push([0.0; 3]);
        assert_eq!(capacity(&v), 240);
        let n = vec![vec![1u32; 4], Vec::with_capacity(2)];
        assert_eq!(nested(&n), 2 * 24 + 16 + 8);
    }
}
