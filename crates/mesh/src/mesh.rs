//! The indexed triangle mesh and its geometric measures.
//!
//! Geometry is computed in f64 (`glam::DVec3`) throughout: the codec's closed-loop prediction
//! and the error measure both need more than f32's 24 bits of mantissa.

use glam::DVec3;

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest coordinate on each axis.
    pub min: DVec3,
    /// Largest coordinate on each axis.
    pub max: DVec3,
}

/// Spreads the low 21 bits of `v` to every third bit (bit `i` to bit `3 i`): one axis of a
/// 63-bit Morton code, as spatial sorts interleave three quantized coordinates.
#[inline]
pub fn morton_spread(v: u64) -> u64 {
    let mut x = v & 0x1F_FFFF;
    x = (x | (x << 32)) & 0x001F_0000_0000_FFFF;
    x = (x | (x << 16)) & 0x001F_0000_FF00_00FF;
    x = (x | (x << 8)) & 0x100F_00F0_0F00_F00F;
    x = (x | (x << 4)) & 0x10C3_0C30_C30C_30C3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

impl Aabb {
    /// The box of no points: `min` is +inf and `max` is -inf, so any point grows it.
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    /// Grows the box to contain `p`.
    pub fn include(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// Grows the box to contain `other`.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// True when no point was ever included.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }

    /// Length of the box diagonal (0 for an empty box).
    pub fn diagonal(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            (self.max - self.min).length()
        }
    }

    /// Extent on each axis (zero for an empty box).
    pub fn size(&self) -> DVec3 {
        if self.is_empty() {
            DVec3::ZERO
        } else {
            self.max - self.min
        }
    }

    /// Centre of the box.
    pub fn center(&self) -> DVec3 {
        (self.min + self.max) * 0.5
    }
}

/// An indexed triangle mesh: positions and counter-clockwise (outward) oriented triangles.
///
/// The struct makes no promise about validity: readers produce it from outside data and
/// [`Mesh::topology_report`](crate::TopologyReport) / [`Mesh::validate`] say what is wrong with
/// it. Every algorithm that needs more (manifoldness, orientation) checks it first.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Triangles as three vertex indices, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// Builds a mesh from its parts (no checks; see [`Mesh::validate`]).
    pub fn new(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Self {
        Mesh {
            positions,
            triangles,
        }
    }

    /// Number of vertices (including unreferenced ones).
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Bounding box of all vertex positions.
    pub fn bounding_box(&self) -> Aabb {
        // Four boxes over interleaved positions, joined at the end: one running box is a
        // chain of dependent min/max operations, four are independent (about 3x as fast on
        // a large mesh). The same box: min and max are associative (a NaN coordinate is
        // skipped either way; only the sign of a zero bound may come from another point).
        let mut lanes = [Aabb::EMPTY; 4];
        let mut chunks = self.positions.chunks_exact(4);
        for c in &mut chunks {
            for (b, &p) in lanes.iter_mut().zip(c) {
                b.include(p);
            }
        }
        for &p in chunks.remainder() {
            lanes[0].include(p);
        }
        let [a, b, c, d] = lanes;
        a.union(&b).union(&c.union(&d))
    }

    /// Length of the bounding-box diagonal: the unit the papers quote errors in.
    pub fn diagonal(&self) -> f64 {
        self.bounding_box().diagonal()
    }

    /// The three corner positions of triangle `t`.
    ///
    /// Panics if `t` or one of its indices is out of range; validated meshes never are.
    #[inline]
    pub fn triangle_positions(&self, t: usize) -> [DVec3; 3] {
        let [a, b, c] = self.triangles[t];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// Each triangle's vertex set (its indices in increasing order), the list sorted: what a
    /// binary search answers "is there a triangle on these three vertices" from, whatever
    /// its orientation or rotation.
    pub fn sorted_vertex_sets(&self) -> Vec<[u32; 3]> {
        let mut keys: Vec<[u32; 3]> = self
            .triangles
            .iter()
            .map(|t| {
                let mut k = *t;
                k.sort_unstable();
                k
            })
            .collect();
        keys.sort_unstable();
        keys
    }

    /// Twice-area vector (unnormalised normal) of triangle `t`.
    #[inline]
    pub fn face_cross(&self, t: usize) -> DVec3 {
        let [a, b, c] = self.triangle_positions(t);
        (b - a).cross(c - a)
    }

    /// Unit normal of triangle `t` (zero for a zero-area triangle).
    #[inline]
    pub fn face_normal(&self, t: usize) -> DVec3 {
        self.face_cross(t).normalize_or_zero()
    }

    /// Area of triangle `t`.
    #[inline]
    pub fn face_area(&self, t: usize) -> f64 {
        0.5 * self.face_cross(t).length()
    }

    /// Unit normals of all triangles.
    pub fn face_normals(&self) -> Vec<DVec3> {
        (0..self.triangles.len())
            .map(|t| self.face_normal(t))
            .collect()
    }

    /// Areas of all triangles.
    pub fn face_areas(&self) -> Vec<f64> {
        (0..self.triangles.len())
            .map(|t| self.face_area(t))
            .collect()
    }

    /// Total surface area.
    pub fn area(&self) -> f64 {
        (0..self.triangles.len()).map(|t| self.face_area(t)).sum()
    }

    /// Angle-weighted vertex normals (Thürmer & Wüthrich 1998): each incident face normal is
    /// weighted by the face's interior angle at the vertex, which makes the result independent
    /// of how the surrounding surface happens to be triangulated. Unreferenced vertices and
    /// vertices whose faces cancel get a zero normal.
    pub fn vertex_normals(&self) -> Vec<DVec3> {
        let mut n = vec![DVec3::ZERO; self.positions.len()];
        for (t, tri) in self.triangles.iter().enumerate() {
            let p = self.triangle_positions(t);
            let fnormal = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
            if fnormal == DVec3::ZERO {
                continue;
            }
            for k in 0..3 {
                let e1 = p[(k + 1) % 3] - p[k];
                let e2 = p[(k + 2) % 3] - p[k];
                let angle = angle_between(e1, e2);
                n[tri[k] as usize] += fnormal * angle;
            }
        }
        for v in &mut n {
            *v = v.normalize_or_zero();
        }
        n
    }

    /// Mean and maximum edge length, each undirected edge counted once (an edge shared by two
    /// triangles is not counted twice). Returns zeros for a mesh without triangles.
    pub fn edge_length_stats(&self) -> EdgeLengthStats {
        let edges = self.undirected_edges();
        let mut sum = 0.0;
        let mut max: f64 = 0.0;
        for &[a, b] in &edges {
            let l = (self.positions[a as usize] - self.positions[b as usize]).length();
            sum += l;
            max = max.max(l);
        }
        EdgeLengthStats {
            mean: if edges.is_empty() {
                0.0
            } else {
                sum / edges.len() as f64
            },
            max,
            count: edges.len(),
        }
    }

    /// Every undirected edge once, as `[low, high]` vertex pairs in increasing order.
    pub fn undirected_edges(&self) -> Vec<[u32; 2]> {
        let mut keys: Vec<u64> = Vec::with_capacity(self.triangles.len() * 3);
        for tri in &self.triangles {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if a != b {
                    keys.push(edge_key(a, b));
                }
            }
        }
        keys.sort_unstable();
        keys.dedup();
        keys.into_iter()
            .map(|k| [(k >> 32) as u32, k as u32])
            .collect()
    }

    /// Mean edge length (see [`Mesh::edge_length_stats`]).
    pub fn mean_edge_length(&self) -> f64 {
        self.edge_length_stats().mean
    }

    /// Maximum edge length.
    pub fn max_edge_length(&self) -> f64 {
        self.edge_length_stats().max
    }
}

/// Summary of edge lengths.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeLengthStats {
    /// Mean length.
    pub mean: f64,
    /// Largest length.
    pub max: f64,
    /// Number of edges measured.
    pub count: usize,
}

/// Angle between two vectors in radians, accurate also for nearly parallel vectors (atan2 of
/// the cross and dot products instead of acos of a rounded cosine).
#[inline]
pub fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// Order-independent key of the undirected edge `{a, b}`: low index in the high half.
#[inline]
pub fn edge_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    ((lo as u64) << 32) | hi as u64
}

#[cfg(test)]
mod tests {
    use super::morton_spread;

    /// The four-lane box is the one-point-at-a-time box, for every remainder of four and with
    /// NaN coordinates skipped.
    #[test]
    fn the_bounding_box_is_the_running_box() {
        use super::{Aabb, Mesh};
        use glam::DVec3;
        let mut x = 12345u64;
        let mut next = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64 * 20.0 - 10.0
        };
        for n in 0..40 {
            let mut positions: Vec<DVec3> =
                (0..n).map(|_| DVec3::new(next(), next(), next())).collect();
            if n % 7 == 3 {
                positions[1].y = f64::NAN;
            }
            let mut want = Aabb::EMPTY;
            for &p in &positions {
                want.include(p);
            }
            let got = Mesh::new(positions, Vec::new()).bounding_box();
            assert_eq!((got.min, got.max), (want.min, want.max), "{n} points");
        }
    }

    #[test]
    fn morton_spread_moves_bit_i_to_bit_3i() {
        assert_eq!(morton_spread(0b101), 1 | 1 << 6);
        assert_eq!(morton_spread(1 << 20), 1 << 60);
        // Bits above the 21st are dropped.
        assert_eq!(morton_spread(1 << 21), 0);
        let all = morton_spread(0x1F_FFFF);
        assert_eq!(all.count_ones(), 21);
        assert_eq!(all & (all << 1), 0);
    }
}
