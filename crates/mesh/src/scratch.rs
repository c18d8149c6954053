//! [`Scratch`]: vectors kept between runs of a stage, so that a caller that encodes mesh
//! after mesh works in memory already mapped instead of having the kernel fault fresh pages
//! in at every run (on the virtual machines whet is measured on, about 1 µs per 4 KB page:
//! an exact encode of a 1.3M-triangle mesh touches some 180 MB, 14 % of its time).

use std::any::{Any, TypeId};

/// A pool of vectors of any element type. A stage takes the vectors it needs
/// ([`Scratch::take_empty`], [`Scratch::take_filled`], [`Scratch::take_overwritten`]) and
/// gives them back when done ([`Scratch::give`]); the next run takes the same memory. Holds
/// what it was given until dropped.
#[derive(Default)]
pub struct Scratch {
    /// Per element type, the vectors given back (each a boxed `Vec<T>`).
    pools: Vec<(TypeId, Vec<Box<dyn Any + Send>>)>,
}

impl std::fmt::Debug for Scratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let vectors: usize = self.pools.iter().map(|(_, p)| p.len()).sum();
        f.debug_struct("Scratch")
            .field("vectors", &vectors)
            .finish()
    }
}

impl Scratch {
    /// An empty pool.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty vector with room for `n` elements: of the vectors given back, the smallest
    /// that holds `n`, else the largest (grown), else a new one.
    pub fn take_empty<T: Send + 'static>(&mut self, n: usize) -> Vec<T> {
        let mut v = self.take_vec::<T>(n);
        v.clear();
        v.reserve(n);
        v
    }

    /// `n` copies of `x`, in memory given back earlier when there is some.
    pub fn take_filled<T: Clone + Send + 'static>(&mut self, n: usize, x: T) -> Vec<T> {
        let mut v = self.take_empty(n);
        v.resize(n, x);
        v
    }

    /// `n` elements whose values are unspecified (what a vector given back held within its
    /// length, or `x` past it): for an array the caller writes in full before reading it,
    /// without filling what it already holds first.
    pub fn take_overwritten<T: Clone + Send + 'static>(&mut self, n: usize, x: T) -> Vec<T> {
        let mut v = self.take_vec::<T>(n);
        v.truncate(n);
        v.resize(n, x);
        v
    }

    /// Gives a vector back for a later take (one without capacity is dropped).
    pub fn give<T: Send + 'static>(&mut self, v: Vec<T>) {
        if v.capacity() == 0 {
            return;
        }
        let id = TypeId::of::<Vec<T>>();
        let boxed: Box<dyn Any + Send> = Box::new(v);
        match self.pools.iter_mut().find(|(t, _)| *t == id) {
            Some((_, pool)) => pool.push(boxed),
            None => self.pools.push((id, vec![boxed])),
        }
    }

    /// Bytes of the vectors held.
    pub fn held_bytes(&self) -> usize {
        // Only the sizes of the types given back are known here, through each vector.
        self.pools
            .iter()
            .flat_map(|(_, p)| p.iter())
            .map(|b| held_bytes_of(b.as_ref()))
            .sum()
    }

    fn take_vec<T: Send + 'static>(&mut self, n: usize) -> Vec<T> {
        let id = TypeId::of::<Vec<T>>();
        let Some((_, pool)) = self.pools.iter_mut().find(|(t, _)| *t == id) else {
            return Vec::new();
        };
        let capacity =
            |b: &Box<dyn Any + Send>| b.downcast_ref::<Vec<T>>().map_or(0, Vec::capacity);
        // The smallest that holds n, else the largest.
        let best = pool
            .iter()
            .enumerate()
            .filter(|(_, b)| capacity(b) >= n)
            .min_by_key(|(_, b)| capacity(b))
            .or_else(|| pool.iter().enumerate().max_by_key(|(_, b)| capacity(b)))
            .map(|(i, _)| i);
        match best.map(|i| pool.swap_remove(i).downcast::<Vec<T>>()) {
            Some(Ok(v)) => *v,
            _ => Vec::new(),
        }
    }
}

/// Bytes held by a pooled vector of one of the element types whet's stages use (others
/// count as zero).
fn held_bytes_of(b: &(dyn Any + Send)) -> usize {
    macro_rules! sizes {
        ($($t:ty),*) => {
            $(if let Some(v) = b.downcast_ref::<Vec<$t>>() {
                return v.capacity() * std::mem::size_of::<$t>();
            })*
        };
    }
    sizes!(u8, bool, u32, u64, i32, [u32; 3], [i32; 3], glam::DVec3);
    0
}

#[cfg(test)]
mod tests {
    use super::Scratch;

    #[test]
    fn a_vector_given_back_is_taken_again_by_its_type() {
        let mut s = Scratch::new();
        let v: Vec<u32> = s.take_filled(1000, 7);
        assert_eq!(v, vec![7; 1000]);
        let at = v.as_ptr();
        s.give(v);
        assert_eq!(s.held_bytes(), 4000);
        // Another type does not get it.
        let w: Vec<u64> = s.take_filled(10, 1);
        assert_eq!(w, vec![1; 10]);
        // The same type does, filled anew, or left as it was when to be overwritten.
        let v: Vec<u32> = s.take_filled(500, 3);
        assert_eq!((v.as_ptr(), v.len()), (at, 500));
        assert!(v.iter().all(|&x| x == 3));
        s.give(v);
        let v: Vec<u32> = s.take_overwritten(800, 0);
        assert_eq!((v.as_ptr(), v.len()), (at, 800));
        assert!(v[..500].iter().all(|&x| x == 3) && v[500..].iter().all(|&x| x == 0));
        s.give(v);
        // The smallest that holds the request; a larger request grows the largest.
        s.give(Vec::<u32>::with_capacity(100));
        let small: Vec<u32> = s.take_empty(50);
        assert!(small.capacity() >= 50 && small.capacity() < 1000);
        let big: Vec<u32> = s.take_empty(5000);
        assert!(big.is_empty() && big.capacity() >= 5000);
        assert_eq!(s.held_bytes(), 0);
    }
}
