//! Uniform spatial hashing for the retiler: a static grid over the original triangles and a
//! dynamic one over the retiled vertices, both with cells of about the edge length `L`, so
//! every query the retiler makes (the swing circle, the neighbourhood of a tip) touches a
//! bounded number of cells whatever the size of the mesh.
//!
//! Cells are keyed by their integer coordinates packed into a `u64` (21 bits per axis around
//! an origin, which covers 2^21 cells per axis: far more than any useful `L`), and looked up
//! through a multiplicative hash (`FastMap`).

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use whet_mesh::DVec3;

/// A multiplicative hasher for integer keys (the `FxHash` idea): keys here are already
/// well-mixed cell and edge codes, and SipHash would cost more than the lookups themselves.
#[derive(Default, Clone, Copy)]
pub(crate) struct FastHasher(u64);

impl Hasher for FastHasher {
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    #[inline]
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
        // Fold the high bits down: hashbrown takes its bucket index from the low bits.
        self.0 ^= self.0 >> 29;
    }
    #[inline]
    fn write_u32(&mut self, v: u32) {
        self.write_u64(v as u64)
    }
}

/// A `HashMap` with [`FastHasher`].
pub(crate) type FastMap<K, V> = HashMap<K, V, BuildHasherDefault<FastHasher>>;

const AXIS_BITS: u32 = 21;
const AXIS_HALF: i64 = 1 << (AXIS_BITS - 1);
const AXIS_MASK: u64 = (1 << AXIS_BITS) - 1;

/// The mapping from positions to cells.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cells {
    origin: DVec3,
    inv: f64,
}

impl Cells {
    /// Cells of size `size` around `origin`.
    pub fn new(origin: DVec3, size: f64) -> Cells {
        Cells {
            origin,
            inv: 1.0 / size,
        }
    }

    #[inline]
    fn coord(&self, x: f64, o: f64) -> i64 {
        let c = ((x - o) * self.inv).floor();
        // Clamp into the packable range (far-away points share the border cells, which
        // only costs time, never correctness).
        (c.clamp(-(AXIS_HALF as f64) + 1.0, AXIS_HALF as f64 - 2.0)) as i64
    }

    /// Integer cell coordinates of `p`.
    #[inline]
    pub fn cell(&self, p: DVec3) -> [i64; 3] {
        [
            self.coord(p.x, self.origin.x),
            self.coord(p.y, self.origin.y),
            self.coord(p.z, self.origin.z),
        ]
    }

    /// Packed key of cell `c`.
    #[inline]
    pub fn key(c: [i64; 3]) -> u64 {
        let f = |v: i64| ((v + AXIS_HALF) as u64) & AXIS_MASK;
        (f(c[0]) << (2 * AXIS_BITS)) | (f(c[1]) << AXIS_BITS) | f(c[2])
    }

    /// Calls `f` with the key of every cell overlapping the box `[lo, hi]`.
    #[inline]
    pub fn for_box(&self, lo: DVec3, hi: DVec3, mut f: impl FnMut(u64)) {
        let a = self.cell(lo);
        let b = self.cell(hi);
        for i in a[0]..=b[0] {
            for j in a[1]..=b[1] {
                for k in a[2]..=b[2] {
                    f(Self::key([i, j, k]));
                }
            }
        }
    }
}

impl Cells {
    /// The keys of the cells overlapping the ball of radius `r` around `p`, with the squared
    /// distance from `p` to each cell, nearest first (so a nearest-item search can stop as
    /// soon as the next cell lies farther than the best item found).
    pub fn by_distance(&self, p: DVec3, r: f64, out: &mut Vec<(f64, u64)>) {
        out.clear();
        let d = DVec3::splat(r);
        let a = self.cell(p - d);
        let b = self.cell(p + d);
        let size = 1.0 / self.inv;
        let gap = |x: f64, o: f64, c: i64| {
            let lo = o + c as f64 * size;
            let hi = lo + size;
            if x < lo {
                lo - x
            } else if x > hi {
                x - hi
            } else {
                0.0
            }
        };
        for i in a[0]..=b[0] {
            let gx = gap(p.x, self.origin.x, i);
            for j in a[1]..=b[1] {
                let gy = gap(p.y, self.origin.y, j);
                for k in a[2]..=b[2] {
                    let gz = gap(p.z, self.origin.z, k);
                    let d2 = gx * gx + gy * gy + gz * gz;
                    if d2 <= r * r {
                        out.push((d2, Self::key([i, j, k])));
                    }
                }
            }
        }
        out.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    }
}

/// A static grid: for each non-empty cell the items whose boxes overlap it.
pub(crate) struct StaticGrid {
    pub cells: Cells,
    ranges: FastMap<u64, (u32, u32)>,
    items: Vec<u32>,
}

impl StaticGrid {
    /// Builds the grid from each item's box.
    pub fn build(cells: Cells, boxes: impl Iterator<Item = (DVec3, DVec3)>) -> StaticGrid {
        let mut pairs: Vec<(u64, u32)> = Vec::new();
        for (id, (lo, hi)) in boxes.enumerate() {
            cells.for_box(lo, hi, |k| pairs.push((k, id as u32)));
        }
        pairs.sort_unstable();
        let mut ranges: FastMap<u64, (u32, u32)> = FastMap::default();
        ranges.reserve(pairs.len() / 4 + 1);
        let mut items = Vec::with_capacity(pairs.len());
        let mut i = 0;
        while i < pairs.len() {
            let k = pairs[i].0;
            let start = items.len() as u32;
            while i < pairs.len() && pairs[i].0 == k {
                items.push(pairs[i].1);
                i += 1;
            }
            ranges.insert(k, (start, items.len() as u32));
        }
        StaticGrid {
            cells,
            ranges,
            items,
        }
    }

    /// The items of cell `key`.
    #[inline]
    pub fn cell_items(&self, key: u64) -> &[u32] {
        match self.ranges.get(&key) {
            Some(&(a, b)) => &self.items[a as usize..b as usize],
            None => &[],
        }
    }
}

/// A dynamic grid of points (the retiled vertices).
pub(crate) struct PointGrid {
    pub cells: Cells,
    map: FastMap<u64, Vec<u32>>,
}

impl PointGrid {
    pub fn new(cells: Cells) -> PointGrid {
        PointGrid {
            cells,
            map: FastMap::default(),
        }
    }

    /// Adds point `id` at `p`.
    pub fn insert(&mut self, id: u32, p: DVec3) {
        let k = Cells::key(self.cells.cell(p));
        self.map.entry(k).or_default().push(id);
    }

    /// Removes point `id`, inserted at `p`.
    pub fn remove(&mut self, id: u32, p: DVec3) {
        let k = Cells::key(self.cells.cell(p));
        if let Some(v) = self.map.get_mut(&k) {
            v.retain(|&x| x != id);
        }
    }

    /// Calls `f` with every point id in the cells overlapping the ball of radius `r`
    /// around `p` (a superset of the points within `r`).
    #[inline]
    pub fn near(&self, p: DVec3, r: f64, mut f: impl FnMut(u32)) {
        let d = DVec3::splat(r);
        self.cells.for_box(p - d, p + d, |k| {
            if let Some(v) = self.map.get(&k) {
                for &id in v {
                    f(id);
                }
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_distinct_for_neighbouring_cells() {
        let mut seen = std::collections::HashSet::new();
        for i in -3..3 {
            for j in -3..3 {
                for k in -3..3 {
                    assert!(seen.insert(Cells::key([i, j, k])));
                }
            }
        }
    }

    #[test]
    fn point_grid_finds_points_within_radius() {
        let mut g = PointGrid::new(Cells::new(DVec3::ZERO, 1.0));
        let pts = [
            DVec3::new(0.1, 0.1, 0.1),
            DVec3::new(2.5, 0.0, 0.0),
            DVec3::new(-0.9, 0.2, 0.0),
        ];
        for (i, &p) in pts.iter().enumerate() {
            g.insert(i as u32, p);
        }
        let mut found = Vec::new();
        g.near(DVec3::ZERO, 1.0, |id| found.push(id));
        found.sort();
        assert_eq!(found, vec![0, 2]);
    }
}
