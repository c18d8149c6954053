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

/// Most cells a triangle is registered in by its bounding box alone (a 4 x 4 x 4 block):
/// more than any triangle of an original finer than the cells spans.
const BOX_CELLS: u64 = 64;

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

    /// Number of cells overlapping the box `[lo, hi]` (saturating).
    fn box_cells(&self, lo: DVec3, hi: DVec3) -> u64 {
        let (a, b) = (self.cell(lo), self.cell(hi));
        (0..3).fold(1u64, |n, i| {
            n.saturating_mul((b[i] - a[i] + 1).max(0) as u64)
        })
    }

    /// Calls `f` with the keys of cells that together cover triangle `t` (every cell the
    /// triangle meets, and a few more): the cells of its box when they are few, as for any
    /// triangle of an original finer than the cells. A larger one is covered piece by
    /// piece, so the cells follow the triangle instead of filling its box (a face spanning
    /// the mesh at a fine edge length would otherwise fill billions of cells):
    ///
    /// * a thin piece, whose height over its longest edge is at most half a cell, lies
    ///   within that height of the edge: the edge is walked in steps of half a cell and
    ///   each step registers the cells within the height and half a step of it;
    /// * a wider piece is cut into four similar halves at its edge midpoints.
    ///
    /// Work is in proportion to the area over the cell size squared, or for a thin
    /// triangle its length over the cell size. Keys come sorted, each once, for the large
    /// ones. Callers keep the triangle within the grid's unclamped range (the retiler
    /// refuses lengths under 2^-19 of the diagonal), where a walk has at most a few
    /// million steps.
    pub fn for_triangle(&self, t: [DVec3; 3], mut f: impl FnMut(u64)) {
        let bounds = |p: &[DVec3; 3]| (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        let (lo, hi) = bounds(&t);
        if self.box_cells(lo, hi) <= BOX_CELLS || !(lo.is_finite() && hi.is_finite()) {
            self.for_box(lo, hi, f);
            return;
        }
        let size = 1.0 / self.inv;
        let mut keys = Vec::new();
        let mut pieces = vec![t];
        while let Some(p) = pieces.pop() {
            let (lo, hi) = bounds(&p);
            if self.box_cells(lo, hi) <= BOX_CELLS {
                self.for_box(lo, hi, |k| keys.push(k));
                continue;
            }
            // The longest edge a -> b, the third vertex c.
            let len2 = |i: usize| (p[(i + 1) % 3] - p[i]).length_squared();
            let i = (0..3).fold(0, |b, i| if len2(i) > len2(b) { i } else { b });
            let (a, b, c) = (p[i], p[(i + 1) % 3], p[(i + 2) % 3]);
            let long = len2(i).sqrt();
            let height = (b - a).cross(c - a).length() / long;
            let m = [
                (p[0] + p[1]) * 0.5,
                (p[1] + p[2]) * 0.5,
                (p[2] + p[0]) * 0.5,
            ];
            // Midpoints that round onto a vertex (a cell under the coordinates' ulp) cannot
            // shrink the piece: its box is only a few ulps wide.
            let stuck = (0..3).any(|k| m[k] == p[k] || m[k] == p[(k + 1) % 3]);
            if height.is_nan() || height <= 0.5 * size || stuck {
                // Every point of the triangle is within `height` of the longest edge (the
                // foot of the height falls on it); each lies within `height + step / 2` of
                // some step point.
                let steps = (2.0 * long / size).ceil().clamp(1.0, 1e7) as usize;
                let reach = DVec3::splat(height + 0.5 * long / steps as f64);
                for k in 0..=steps {
                    let q = a + (b - a) * (k as f64 / steps as f64);
                    self.for_box(q - reach, q + reach, |key| keys.push(key));
                }
                continue;
            }
            pieces.extend([
                [p[0], m[0], m[2]],
                [m[0], p[1], m[1]],
                [m[2], m[1], p[2]],
                [m[0], m[1], m[2]],
            ]);
        }
        keys.sort_unstable();
        keys.dedup();
        for k in keys {
            f(k);
        }
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
    /// The keys of the cells at squared distance at most `r2` from `p` (leaving out cell
    /// `skip`), with that squared distance, nearest first (so a nearest-item search can stop
    /// as soon as the next cell lies farther than the best item found).
    pub fn by_squared_distance(
        &self,
        p: DVec3,
        r2: f64,
        skip: Option<u64>,
        out: &mut Vec<(f64, u64)>,
    ) {
        out.clear();
        let r2 = r2.max(0.0);
        // The cells of the ball's box, widened by a millionth of a cell: `cell`'s rounding
        // and the gap's may disagree by an ulp at a cell face (well under that margin
        // within the 2^20 cells the retiler keeps its original in), and the test below
        // (squared gaps, the measure a nearest search bounds by) decides.
        let d = DVec3::splat(r2.sqrt() + 1e-6 / self.inv);
        let (a, b) = (self.cell(p - d), self.cell(p + d));
        for i in a[0]..=b[0] {
            let gx = self.axis_gap(p.x, self.origin.x, i);
            for j in a[1]..=b[1] {
                let gy = self.axis_gap(p.y, self.origin.y, j);
                for k in a[2]..=b[2] {
                    let gz = self.axis_gap(p.z, self.origin.z, k);
                    let d2 = gx * gx + gy * gy + gz * gz;
                    let key = Self::key([i, j, k]);
                    if d2 <= r2 && Some(key) != skip {
                        out.push((d2, key));
                    }
                }
            }
        }
        out.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    }

    /// Squared distance from `p` to cell `c` (0 inside it).
    pub fn squared_gap(&self, p: DVec3, c: [i64; 3]) -> f64 {
        let g = [
            self.axis_gap(p.x, self.origin.x, c[0]),
            self.axis_gap(p.y, self.origin.y, c[1]),
            self.axis_gap(p.z, self.origin.z, c[2]),
        ];
        g[0] * g[0] + g[1] * g[1] + g[2] * g[2]
    }

    /// Distance along one axis from coordinate `x` to cell `c` of that axis (origin `o`).
    #[inline]
    fn axis_gap(&self, x: f64, o: f64, c: i64) -> f64 {
        let size = 1.0 / self.inv;
        let lo = o + c as f64 * size;
        let hi = lo + size;
        if x < lo {
            lo - x
        } else if x > hi {
            x - hi
        } else {
            0.0
        }
    }
}

/// A static grid: for each non-empty cell the items whose boxes overlap it.
pub(crate) struct StaticGrid {
    pub cells: Cells,
    ranges: FastMap<u64, (u32, u32)>,
    items: Vec<u32>,
}

impl StaticGrid {
    /// Builds the grid of triangles (items numbered in order), each in the cells
    /// [`Cells::for_triangle`] gives.
    pub fn build(cells: Cells, triangles: impl Iterator<Item = [DVec3; 3]>) -> StaticGrid {
        // (cell, item) in item order, each cell numbered at its first item; then a counting
        // sort by cell, which keeps every cell's items in increasing order (what queries
        // iterate, so the order of their results is fixed) without sorting the pairs.
        let mut number: FastMap<u64, u32> = FastMap::default();
        let mut keys: Vec<u64> = Vec::new();
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for (id, t) in triangles.enumerate() {
            cells.for_triangle(t, |k| {
                let next = keys.len() as u32;
                let cell = *number.entry(k).or_insert(next);
                if cell == next {
                    keys.push(k);
                }
                pairs.push((cell, id as u32));
            });
        }
        let mut start = vec![0u32; keys.len() + 1];
        for &(cell, _) in &pairs {
            start[cell as usize + 1] += 1;
        }
        for c in 0..keys.len() {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; pairs.len()];
        for &(cell, id) in &pairs {
            let slot = &mut fill[cell as usize];
            items[*slot as usize] = id;
            *slot += 1;
        }
        let mut ranges: FastMap<u64, (u32, u32)> = FastMap::default();
        ranges.reserve(keys.len());
        for (c, &k) in keys.iter().enumerate() {
            ranges.insert(k, (start[c], start[c + 1]));
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

    #[test]
    fn static_grid_lists_each_cells_items_in_increasing_order() {
        // Triangles of several sizes, some spanning many cells; against a brute force over
        // every item and the cells `for_triangle` gives it.
        let cells = Cells::new(DVec3::ZERO, 1.0);
        let triangles: Vec<[DVec3; 3]> = (0..200)
            .map(|i| {
                let f = i as f64;
                let a = DVec3::new((f * 0.37) % 5.0, (f * 0.61) % 4.0, (f * 0.83) % 3.0);
                let size = 0.2 + (f * 0.13) % 2.0 + if i % 50 == 7 { 9.0 } else { 0.0 };
                [a, a + DVec3::X * size, a + DVec3::new(0.3, 1.0, 0.7) * size]
            })
            .collect();
        let grid = StaticGrid::build(cells, triangles.iter().copied());
        let mut expected: std::collections::BTreeMap<u64, Vec<u32>> = Default::default();
        for (id, &t) in triangles.iter().enumerate() {
            cells.for_triangle(t, |k| expected.entry(k).or_default().push(id as u32));
        }
        for (k, items) in &expected {
            assert_eq!(grid.cell_items(*k), items.as_slice());
        }
        assert_eq!(
            grid.items.len(),
            expected.values().map(Vec::len).sum::<usize>()
        );
        assert!(grid.cell_items(Cells::key([40, 40, 40])).is_empty());
    }

    #[test]
    fn a_large_triangle_is_in_every_cell_it_crosses_and_few_others() {
        let cells = Cells::new(DVec3::ZERO, 1.0);
        for t in [
            // A face across a 100-cell box, a needle along its diagonal, a flat one.
            [
                DVec3::ZERO,
                DVec3::new(100.0, 0.0, 0.0),
                DVec3::new(0.0, 100.0, 100.0),
            ],
            [
                DVec3::ZERO,
                DVec3::splat(100.0),
                DVec3::splat(100.0) + DVec3::X * 1e-3,
            ],
            [
                DVec3::new(0.5, 0.5, 0.5),
                DVec3::new(60.5, 0.5, 0.5),
                DVec3::new(0.5, 60.5, 0.5),
            ],
            // Long and thin, off the axes: cells in proportion to its length.
            [
                DVec3::ZERO,
                DVec3::new(3000.0, 2000.0, 1000.0),
                DVec3::new(0.0, 0.7, 0.7),
            ],
        ] {
            let mut keys = std::collections::HashSet::new();
            cells.for_triangle(t, |k| assert!(keys.insert(k)));
            let n = 400;
            for i in 0..=n {
                for j in 0..=n - i {
                    let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                    let p = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v;
                    assert!(keys.contains(&Cells::key(cells.cell(p))), "{p:?}");
                }
            }
            // Area over cell size squared (or length over cell size), not the box's up to
            // 6 * 10^9 cells.
            assert!(keys.len() < 60_000, "{}", keys.len());
        }
    }

    #[test]
    fn cells_by_squared_distance_are_those_within_it_nearest_first() {
        let cells = Cells::new(DVec3::ZERO, 1.0);
        let p = DVec3::new(0.3, 0.9, 0.5);
        let mut out = Vec::new();
        cells.by_squared_distance(p, 0.2, None, &mut out);
        // The home cell, the +y neighbour (0.1 away), the -x one (0.3 away) and the cell
        // diagonal to both (squared 0.1); the z neighbours are 0.5 away.
        let keys: Vec<u64> = out.iter().map(|c| c.1).collect();
        assert_eq!(
            keys,
            vec![
                Cells::key([0, 0, 0]),
                Cells::key([0, 1, 0]),
                Cells::key([-1, 0, 0]),
                Cells::key([-1, 1, 0]),
            ]
        );
        assert!(out.windows(2).all(|w| w[0].0 <= w[1].0));
        cells.by_squared_distance(p, 0.2, Some(Cells::key([0, 0, 0])), &mut out);
        assert_eq!(out.len(), 3);
    }
}
