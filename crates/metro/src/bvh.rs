//! A bounding volume hierarchy over the triangles of a mesh, for exact closest-point queries.
//!
//! **Build** (linear BVH, a spatial-median split hierarchy): each triangle's box centre gets
//! a 63-bit Morton code on a cube over all centres; the triangles are radix-sorted by code
//! (stable, so ties keep mesh order), and the tree is emitted top-down by splitting each
//! range where its highest differing code bit flips — a geometric midpoint split — down to
//! leaves of at most four triangles, with subtrees built in parallel by rayon. This is a few
//! linear passes instead of the log-depth partitioning of a SAH builder, and for
//! closest-point queries on surfaces (where the answer is local) it loses nothing measurable.
//!
//! **Layout**: the tree is flattened depth-first into 64-byte inner nodes, each holding the
//! conservative `f32` boxes of both children (rounded outwards, so pruning never drops a
//! triangle) and two child references; a leaf reference carries its triangle range and a
//! mask of degenerate triangles. The triangle corners are copied into one contiguous `f64`
//! array in leaf order (72 bytes each), and two small arrays map each node to its parent and
//! each triangle to its leaf's node, so a search can also run bottom-up. Memory is linear:
//! about 120 bytes per triangle.
//!
//! **Queries** walk the tree with an explicit stack, nearest child first, pruning every box
//! no closer than the best triangle so far. [`CoherentQuery`] starts from the leaf of the
//! previous answer instead: it tests that leaf, then climbs to the root testing the sibling
//! subtree at each ancestor (descending nearest-first where it is close enough). For a
//! stream of nearby points — the samples of one face, the probes along a mesh's edges — the
//! answer is found in the first few nodes, and the climb is one box test per level.

use std::cmp::Ordering;

use glam::DVec3;
use rayon::prelude::*;
use whet_mesh::{morton_spread, Aabb, Mesh};

use crate::triangle_distance::{
    closest_point_on_proper_triangle, closest_point_on_triangle, is_degenerate,
};
use crate::Error;

/// The closest point of a surface to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestPoint {
    /// Euclidean distance from the query point to `point`.
    pub distance: f64,
    /// The closest point on the surface.
    pub point: DVec3,
    /// Index (into the mesh's `triangles`) of the triangle `point` lies on.
    pub triangle: u32,
}

/// Build-time node, depth-first: conservative `f32` box, and either a leaf (`count > 0`
/// triangles starting at `index` in the packed array) or an inner node (`count == 0`, left
/// child at the next index, right child at `index`).
#[derive(Clone, Copy, Debug)]
struct BuildNode {
    min: [f32; 3],
    max: [f32; 3],
    index: u32,
    count: u32,
}

/// A flattened inner node: the conservative `f32` boxes of both children, stored per axis
/// (`lo[axis][child]`), and a reference to each child. One 64-byte cache line answers "how
/// far are my two children", which is all a traversal step needs.
///
/// A child reference is `(index, meta)`: `meta == 0` means an inner node at `index`;
/// otherwise the child is a leaf of `meta & 0xFFFF` packed triangles starting at `index`,
/// and bit `16 + k` of `meta` flags the leaf's `k`-th triangle as (numerically) degenerate.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node {
    lo: [[f32; 2]; 3],
    hi: [[f32; 2]; 3],
    index: [u32; 2],
    meta: [u32; 2],
}

const _: () = assert!(std::mem::size_of::<Node>() == 64);
const _: () = assert!(MAX_LEAF <= 16);

impl Node {
    /// Squared distances from `p` to the two child boxes.
    #[inline(always)]
    fn child_distances(&self, p: DVec3) -> (f64, f64) {
        (self.child_distance(p, 0), self.child_distance(p, 1))
    }

    /// Squared distance from `p` to the box of child `k`.
    #[inline(always)]
    fn child_distance(&self, p: DVec3, k: usize) -> f64 {
        let mut s = 0.0;
        for (a, pa) in [p.x, p.y, p.z].into_iter().enumerate() {
            let below = self.lo[a][k] as f64 - pa;
            let above = pa - self.hi[a][k] as f64;
            let e = if below > above { below } else { above };
            if e > 0.0 {
                s += e * e;
            }
        }
        s
    }
}

/// Squared distance from `p` to an `f32` box.
#[inline(always)]
fn box_distance_squared(min: &[f32; 3], max: &[f32; 3], p: DVec3) -> f64 {
    let mut s = 0.0;
    for (a, pa) in [p.x, p.y, p.z].into_iter().enumerate() {
        let e = (min[a] as f64 - pa).max(pa - max[a] as f64).max(0.0);
        s += e * e;
    }
    s
}

/// Bounding volume hierarchy over the triangles of a [`Mesh`] answering exact closest-point
/// queries (see the module documentation for how it is built and laid out).
///
/// ```
/// use whet_metro::Bvh;
/// use whet_mesh::{DVec3, Mesh};
///
/// let mesh = Mesh::new(
///     vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
///     vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
/// );
/// let bvh = Bvh::new(&mesh);
/// let hit = bvh.closest_point(DVec3::new(0.2, 0.2, -1.0));
/// assert_eq!(hit.triangle, 0);
/// assert!((hit.distance - 1.0).abs() < 1e-15);
/// assert!(bvh.closest_point_within(DVec3::new(0.2, 0.2, -1.0), 0.5).is_none());
/// ```
#[derive(Clone, Debug)]
pub struct Bvh {
    /// Inner nodes, depth-first; `nodes[0]` is the root when `root_meta == 0`.
    nodes: Vec<Node>,
    /// The root reference (see [`Node`]) and box.
    root_index: u32,
    root_meta: u32,
    root_min: [f32; 3],
    root_max: [f32; 3],
    /// Parent of each inner node, with the child slot it occupies there in the top bit
    /// (`NONE` for the root).
    parents: Vec<u32>,
    /// Inner node holding the leaf of each packed triangle (`NONE` when the root is a leaf).
    tri_parent: Vec<u32>,
    /// Triangle corners in leaf order.
    tris: Vec<[DVec3; 3]>,
    /// Mesh triangle index of each packed triangle.
    ids: Vec<u32>,
    bounds: Aabb,
}

/// "No node".
const NONE: u32 = u32::MAX;

/// Build-time record of one triangle: conservative `f32` box (4 lanes so the box arithmetic
/// vectorises; lane 3 is 0) and mesh index. Its centroid is the box centre.
#[derive(Clone, Copy, Debug)]
struct Prim {
    min: [f32; 4],
    max: [f32; 4],
    id: u32,
}

impl Prim {
    #[inline(always)]
    fn centroid(&self) -> [f32; 4] {
        let mut c = [0.0; 4];
        for k in 0..4 {
            c[k] = (self.min[k] + self.max[k]) * 0.5;
        }
        c
    }
}

#[inline(always)]
fn min4(a: [f32; 4], b: &[f32; 4]) -> [f32; 4] {
    let mut r = a;
    for k in 0..4 {
        if b[k] < r[k] {
            r[k] = b[k];
        }
    }
    r
}

#[inline(always)]
fn max4(a: [f32; 4], b: &[f32; 4]) -> [f32; 4] {
    let mut r = a;
    for k in 0..4 {
        if b[k] > r[k] {
            r[k] = b[k];
        }
    }
    r
}

/// An `f32` box used while building (4 lanes, lane 3 unused).
#[derive(Clone, Copy, Debug)]
struct Box3 {
    min: [f32; 4],
    max: [f32; 4],
}

impl Box3 {
    const EMPTY: Box3 = Box3 {
        min: [f32::INFINITY; 4],
        max: [f32::NEG_INFINITY; 4],
    };

    #[inline(always)]
    fn grow_box(&mut self, min: &[f32; 4], max: &[f32; 4]) {
        self.min = min4(self.min, min);
        self.max = max4(self.max, max);
    }

    #[inline(always)]
    fn grow_point(&mut self, p: &[f32; 4]) {
        self.grow_box(p, p);
    }

    #[inline]
    fn union(mut self, o: &Box3) -> Box3 {
        self.grow_box(&o.min, &o.max);
        self
    }

    fn min3(&self) -> [f32; 3] {
        [self.min[0], self.min[1], self.min[2]]
    }

    fn max3(&self) -> [f32; 3] {
        [self.max[0], self.max[1], self.max[2]]
    }
}

/// Smallest `f32` strictly above `f` (identity for +inf and NaN).
fn next_up(f: f32) -> f32 {
    if f.is_nan() || f == f32::INFINITY {
        return f;
    }
    if f == 0.0 {
        return f32::from_bits(1);
    }
    let bits = f.to_bits();
    if f > 0.0 {
        f32::from_bits(bits + 1)
    } else {
        f32::from_bits(bits - 1)
    }
}

/// `x` rounded to an `f32` that is `<= x`.
fn f32_down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x {
        -next_up(-f)
    } else {
        f
    }
}

/// `x` rounded to an `f32` that is `>= x`.
fn f32_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x {
        next_up(f)
    } else {
        f
    }
}

/// Leaves never hold more triangles than this (unless all centroids coincide and the
/// median split is forced anyway, which still halves the count).
const MAX_LEAF: usize = 4;
/// Below this many triangles a subtree is built on the current thread.
const PAR_SUBTREE: usize = 16 * 1024;
fn bounds_of(prims: &[Prim]) -> (Box3, Box3) {
    let mut bounds = Box3::EMPTY;
    let mut centroids = Box3::EMPTY;
    for p in prims {
        bounds.grow_box(&p.min, &p.max);
        centroids.grow_point(&p.centroid());
    }
    (bounds, centroids)
}

/// 63-bit Morton codes of the prims' centroids, quantised on a cube over `centroids` (so a
/// code bit splits space at a geometric midpoint).
fn morton_codes(prims: &[Prim], centroids: &Box3) -> Vec<u64> {
    let ext = (0..3)
        .map(|k| centroids.max[k] - centroids.min[k])
        .fold(0.0f32, f32::max);
    let scale = if ext > 0.0 && ext.is_finite() {
        ((1u32 << 21) - 1) as f32 / ext
    } else {
        0.0
    };
    let origin = centroids.min;
    prims
        .par_iter()
        .map(|p| {
            let c = p.centroid();
            // The float-to-int cast saturates, so rounding overshoot stays in range.
            let q = |k: usize| (((c[k] - origin[k]) * scale) as u64).min((1 << 21) - 1);
            (morton_spread(q(0)) << 2) | (morton_spread(q(1)) << 1) | morton_spread(q(2))
        })
        .collect()
}

/// Sorts `prims` by Morton code (LSD radix sort, stable, so equal codes keep mesh order) and
/// returns the sorted codes.
fn sort_by_morton(prims: &mut Vec<Prim>, codes: Vec<u64>) -> Vec<u64> {
    let n = prims.len();
    let mut keys: Vec<(u64, u32)> = codes
        .into_iter()
        .enumerate()
        .map(|(i, c)| (c, i as u32))
        .collect();
    let mut tmp = vec![(0u64, 0u32); n];
    let mut shift = 0;
    while shift < 63 {
        let mut counts = [0usize; 2049];
        for &(c, _) in &keys {
            counts[((c >> shift) & 0x7FF) as usize + 1] += 1;
        }
        if counts.contains(&n) {
            shift += 11; // every key has the same digit: nothing to do
            continue;
        }
        for d in 1..2049 {
            counts[d] += counts[d - 1];
        }
        for &(c, i) in &keys {
            let d = ((c >> shift) & 0x7FF) as usize;
            tmp[counts[d]] = (c, i);
            counts[d] += 1;
        }
        std::mem::swap(&mut keys, &mut tmp);
        shift += 11;
    }
    drop(tmp);
    *prims = keys.iter().map(|&(_, i)| prims[i as usize]).collect();
    keys.into_iter().map(|(c, _)| c).collect()
}

/// Emits the subtree over `prims` (sorted by `codes`) depth-first into `out` and returns its
/// box: split where the highest differing code bit flips (a spatial median), or at the middle
/// when all codes are equal. `first` is the position of `prims[0]` in the packed order.
fn emit_node(prims: &[Prim], codes: &[u64], first: usize, out: &mut Vec<BuildNode>) -> Box3 {
    let me = out.len();
    let n = prims.len();
    out.push(BuildNode {
        min: [0.0; 3],
        max: [0.0; 3],
        index: first as u32,
        count: n as u32,
    });
    let bounds = if n <= MAX_LEAF {
        bounds_of(prims).0
    } else {
        let (lo, hi) = (codes[0], codes[n - 1]);
        let mid = if lo == hi {
            n / 2
        } else {
            let bit = 63 - (lo ^ hi).leading_zeros();
            // Codes are sorted, so those with `bit` set form a suffix.
            codes.partition_point(|&c| (c >> bit) & 1 == 0)
        };
        let (lp, rp) = prims.split_at(mid);
        let (lc, rc) = codes.split_at(mid);
        let (lb, rb, right_index) = if n > PAR_SUBTREE {
            let ((lv, lb), (rv, rb)) = rayon::join(
                || {
                    let mut v = Vec::with_capacity(lp.len() / 2);
                    let b = emit_node(lp, lc, first, &mut v);
                    (v, b)
                },
                || {
                    let mut v = Vec::with_capacity(rp.len() / 2);
                    let b = emit_node(rp, rc, first + mid, &mut v);
                    (v, b)
                },
            );
            append_shifted(out, &lv);
            let r = out.len();
            append_shifted(out, &rv);
            (lb, rb, r)
        } else {
            let lb = emit_node(lp, lc, first, out);
            let r = out.len();
            let rb = emit_node(rp, rc, first + mid, out);
            (lb, rb, r)
        };
        out[me].count = 0;
        out[me].index = right_index as u32;
        lb.union(&rb)
    };
    out[me].min = bounds.min3();
    out[me].max = bounds.max3();
    bounds
}

/// Appends a subtree built in its own vector, shifting its inner-node child links.
fn append_shifted(out: &mut Vec<BuildNode>, sub: &[BuildNode]) {
    let base = out.len() as u32;
    out.extend(sub.iter().map(|n| {
        let mut n = *n;
        if n.count == 0 {
            n.index += base;
        }
        n
    }));
}

impl Default for Bvh {
    /// The empty hierarchy (every query finds nothing).
    fn default() -> Self {
        Bvh {
            nodes: Vec::new(),
            root_index: 0,
            root_meta: 0,
            root_min: [f32::INFINITY; 3],
            root_max: [f32::NEG_INFINITY; 3],
            parents: Vec::new(),
            tri_parent: Vec::new(),
            tris: Vec::new(),
            ids: Vec::new(),
            bounds: Aabb::EMPTY,
        }
    }
}

impl Bvh {
    /// Builds the hierarchy over the triangles of `mesh`.
    ///
    /// Triangles that cannot be measured — an index out of range or a non-finite corner — are
    /// left out rather than panicking; use [`Bvh::try_new`] to have them reported instead.
    /// Zero-area triangles are kept (their closest points are those of their edges).
    pub fn new(mesh: &Mesh) -> Bvh {
        let nv = mesh.positions.len();
        let prims: Vec<Prim> = mesh
            .triangles
            .par_iter()
            .enumerate()
            .filter_map(|(id, t)| {
                let usable = t
                    .iter()
                    .all(|&i| (i as usize) < nv && mesh.positions[i as usize].is_finite());
                usable.then(|| prim(mesh, t, id as u32))
            })
            .collect();
        Self::from_prims(mesh, prims)
    }

    /// Like [`Bvh::new`], but fails on a triangle with an out-of-range index or a non-finite
    /// corner, and on a mesh without triangles.
    pub fn try_new(mesh: &Mesh) -> Result<Bvh, Error> {
        crate::metro::validate(mesh, "target")?;
        Ok(Bvh::new(mesh))
    }

    fn from_prims(mesh: &Mesh, mut prims: Vec<Prim>) -> Bvh {
        // The mesh has fewer than 2^32 triangles when its indices are u32 ... but its
        // triangle *count* is not bounded by that; refuse to index past u32 (by leaving the
        // excess out) rather than wrap.
        prims.truncate(u32::MAX as usize);
        if prims.is_empty() {
            return Bvh::default();
        }
        let (_, centroids) = bounds_of(&prims);
        let codes = morton_codes(&prims, &centroids);
        let codes = sort_by_morton(&mut prims, codes);
        let mut build = Vec::with_capacity(prims.len() / 2 + 1);
        emit_node(&prims, &codes, 0, &mut build);
        drop(codes);
        let (tris, ids): (Vec<[DVec3; 3]>, Vec<u32>) = prims
            .par_iter()
            .map(|p| (mesh.triangle_positions(p.id as usize), p.id))
            .unzip();
        drop(prims);
        let mut aabb = Aabb::EMPTY;
        for t in &tris {
            for &v in t {
                aabb.include(v);
            }
        }

        // Flatten: one `Node` per inner build node, numbered depth-first; leaves become child
        // references carrying their triangle range and degenerate-triangle mask.
        let mut inner_rank = vec![u32::MAX; build.len()];
        let mut count = 0u32;
        for (i, n) in build.iter().enumerate() {
            if n.count == 0 {
                inner_rank[i] = count;
                count += 1;
            }
        }
        let reference = |i: usize| -> (u32, u32) {
            let n = &build[i];
            if n.count == 0 {
                (inner_rank[i], 0)
            } else {
                let mut meta = n.count;
                for k in 0..n.count {
                    let [a, b, c] = tris[(n.index + k) as usize];
                    if is_degenerate(a, b, c) {
                        meta |= 1 << (16 + k);
                    }
                }
                (n.index, meta)
            }
        };
        let nodes: Vec<Node> = build
            .iter()
            .enumerate()
            .filter(|(_, n)| n.count == 0)
            .map(|(i, n)| {
                let (l, r) = (i + 1, n.index as usize);
                let (bl, br) = (&build[l], &build[r]);
                let (li, lm) = reference(l);
                let (ri, rm) = reference(r);
                Node {
                    lo: [
                        [bl.min[0], br.min[0]],
                        [bl.min[1], br.min[1]],
                        [bl.min[2], br.min[2]],
                    ],
                    hi: [
                        [bl.max[0], br.max[0]],
                        [bl.max[1], br.max[1]],
                        [bl.max[2], br.max[2]],
                    ],
                    index: [li, ri],
                    meta: [lm, rm],
                }
            })
            .collect();
        let (root_index, root_meta) = reference(0);
        let mut parents = vec![NONE; nodes.len()];
        let mut tri_parent = vec![NONE; tris.len()];
        for (i, n) in nodes.iter().enumerate() {
            for k in 0..2 {
                if n.meta[k] == 0 {
                    parents[n.index[k] as usize] = i as u32 | (k as u32) << 31;
                } else {
                    let start = n.index[k] as usize;
                    let count = (n.meta[k] & 0xFFFF) as usize;
                    for t in &mut tri_parent[start..start + count] {
                        *t = i as u32;
                    }
                }
            }
        }
        Bvh {
            nodes,
            root_index,
            root_meta,
            root_min: build[0].min,
            root_max: build[0].max,
            parents,
            tri_parent,
            tris,
            ids,
            bounds: aabb,
        }
    }

    /// Number of triangles in the hierarchy.
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// True when the hierarchy holds no triangle (every query then finds nothing).
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// Number of inner nodes (each holds the boxes of its two children).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Bounding box of the triangles in the hierarchy.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The closest point of the surface to `p`, exact (up to rounding).
    ///
    /// On an empty hierarchy the answer is `distance = f64::INFINITY`, `point = p` and
    /// `triangle = u32::MAX`; for a non-finite `p` it is `distance = f64::NAN`, `point = p`,
    /// `triangle = u32::MAX`.
    pub fn closest_point(&self, p: DVec3) -> ClosestPoint {
        if !p.is_finite() {
            return nan_answer(p);
        }
        let mut stack = Vec::new();
        let hit = self.search(p, (f64::INFINITY, NONE, p), -1.0, &mut stack);
        self.finish(p, hit)
    }

    /// The closest point of the surface to `p` if it is at most `max_dist` away.
    pub fn closest_point_within(&self, p: DVec3, max_dist: f64) -> Option<ClosestPoint> {
        if max_dist.is_nan() || max_dist < 0.0 || !p.is_finite() {
            return None;
        }
        // Start just above max_dist^2 so that a point at exactly max_dist is still found.
        // (Squaring can round below the d^2 whose root is max_dist, hence the extra margin;
        // the final comparison is made on the distance itself.)
        let bound = next_up_f64(max_dist * max_dist * (1.0 + 1e-12));
        let mut stack = Vec::new();
        let hit = self.search(p, (bound, u32::MAX, DVec3::ZERO), -1.0, &mut stack);
        if hit.1 == u32::MAX {
            return None;
        }
        let c = self.finish(p, hit);
        (c.distance <= max_dist).then_some(c)
    }

    /// A query state for a stream of spatially coherent points: it keeps its traversal stack
    /// and seeds each search with the triangle nearest to the previous point, so a run of
    /// nearby points costs little more than one triangle test each. Results are exactly
    /// those of [`Bvh::closest_point`].
    pub fn coherent_query(&self) -> CoherentQuery<'_> {
        CoherentQuery {
            bvh: self,
            stack: Vec::with_capacity(64),
            last: u32::MAX,
        }
    }

    fn finish(&self, p: DVec3, (d2, packed, point): (f64, u32, DVec3)) -> ClosestPoint {
        if packed == u32::MAX {
            return ClosestPoint {
                distance: f64::INFINITY,
                point: p,
                triangle: u32::MAX,
            };
        }
        ClosestPoint {
            distance: d2.sqrt(),
            point,
            triangle: self.ids[packed as usize],
        }
    }

    /// Tests the triangles of a leaf reference, updating the best so far.
    #[inline(always)]
    fn test_leaf(&self, p: DVec3, index: u32, meta: u32, best: &mut (f64, u32, DVec3)) {
        let start = index as usize;
        let count = (meta & 0xFFFF) as usize;
        for k in 0..count {
            let Some(t) = self.tris.get(start + k) else {
                break; // unreachable: leaves index inside `tris`
            };
            let q = if meta & (1 << (16 + k)) == 0 {
                closest_point_on_proper_triangle(p, t[0], t[1], t[2])
            } else {
                closest_point_on_triangle(p, t[0], t[1], t[2])
            };
            let d2 = p.distance_squared(q);
            if d2 < best.0 {
                *best = (d2, (start + k) as u32, q);
            }
        }
    }

    /// Top-down search from the root: the best (squared distance, packed index, point)
    /// strictly below the incoming bound `best.0`, or `best` itself if nothing beats it.
    /// Stops early, with an answer that is merely `<= stop_d2`, as soon as one is found (pass
    /// a negative `stop_d2` for the exact closest point).
    #[inline]
    fn search(
        &self,
        p: DVec3,
        mut best: (f64, u32, DVec3),
        stop_d2: f64,
        stack: &mut Vec<(f64, u32)>,
    ) -> (f64, u32, DVec3) {
        if self.tris.is_empty()
            || box_distance_squared(&self.root_min, &self.root_max, p).partial_cmp(&best.0)
                != Some(Ordering::Less)
        {
            return best;
        }
        if self.root_meta != 0 {
            self.test_leaf(p, self.root_index, self.root_meta, &mut best);
            return best;
        }
        self.descend(p, self.root_index, best, stop_d2, stack)
    }

    /// Nearest-first search of the subtree under inner node `start`.
    #[inline]
    fn descend(
        &self,
        p: DVec3,
        start: u32,
        mut best: (f64, u32, DVec3),
        stop_d2: f64,
        stack: &mut Vec<(f64, u32)>,
    ) -> (f64, u32, DVec3) {
        let nodes = &self.nodes[..];
        stack.clear();
        let mut current = start as usize;
        loop {
            let Some(node) = nodes.get(current) else {
                return best; // unreachable: child references are in range
            };
            let (d0, d1) = node.child_distances(p);
            let (near, dn, far, df) = if d0 <= d1 {
                (0, d0, 1, d1)
            } else {
                (1, d1, 0, d0)
            };
            let mut next = None;
            for (k, d) in [(near, dn), (far, df)] {
                if d < best.0 {
                    let (index, meta) = (node.index[k], node.meta[k]);
                    if meta != 0 {
                        self.test_leaf(p, index, meta, &mut best);
                        if best.0 <= stop_d2 {
                            return best;
                        }
                    } else if next.is_none() {
                        next = Some(index);
                    } else {
                        stack.push((d, index));
                    }
                }
            }
            if let Some(n) = next {
                current = n as usize;
                continue;
            }
            // Pop the next node still worth visiting.
            loop {
                match stack.pop() {
                    None => return best,
                    Some((d2, n)) => {
                        if d2 < best.0 {
                            current = n as usize;
                            break;
                        }
                    }
                }
            }
        }
    }

    /// Bottom-up search from packed triangle `seed` (which must be in range): the seed's leaf
    /// first, then, climbing to the root, the sibling subtree at each ancestor. Every
    /// triangle is in the seed's leaf or in exactly one of those siblings, so the result is
    /// the same as [`Bvh::search`]'s; but near the seed the answer is found within a few
    /// nodes, and the climb above it costs one box test per level (boxes already in the cache
    /// line just loaded, a branch that is almost never taken) instead of a chain of dependent
    /// descents from the root. Same early stop as [`Bvh::search`].
    #[inline]
    fn search_up(
        &self,
        p: DVec3,
        seed: u32,
        stop_d2: f64,
        stack: &mut Vec<(f64, u32)>,
    ) -> (f64, u32, DVec3) {
        let mut best = (f64::INFINITY, NONE, p);
        let Some(&leaf_parent) = self.tri_parent.get(seed as usize) else {
            return self.search(p, best, stop_d2, stack);
        };
        if leaf_parent == NONE {
            // The root is the only leaf.
            self.test_leaf(p, self.root_index, self.root_meta, &mut best);
            return best;
        }
        let mut cur = leaf_parent as usize;
        let Some(node) = self.nodes.get(cur) else {
            return best; // unreachable: tri_parent holds node indices
        };
        let in_first = node.meta[0] != 0
            && node.index[0] <= seed
            && seed < node.index[0] + (node.meta[0] & 0xFFFF);
        let mut from = if in_first { 0 } else { 1 };
        self.test_leaf(p, node.index[from], node.meta[from], &mut best);
        if best.0 <= stop_d2 {
            return best;
        }
        loop {
            let Some(node) = self.nodes.get(cur) else {
                return best; // unreachable
            };
            let sib = 1 - from;
            if node.child_distance(p, sib) < best.0 {
                let (index, meta) = (node.index[sib], node.meta[sib]);
                if meta != 0 {
                    self.test_leaf(p, index, meta, &mut best);
                } else {
                    best = self.descend(p, index, best, stop_d2, stack);
                }
                if best.0 <= stop_d2 {
                    return best;
                }
            }
            let up = self.parents.get(cur).copied().unwrap_or(NONE);
            if up == NONE {
                return best; // climbed past the root
            }
            from = (up >> 31) as usize;
            cur = (up & 0x7FFF_FFFF) as usize;
        }
    }
}

/// Smallest `f64` strictly above `x` (identity for +inf and NaN).
fn next_up_f64(x: f64) -> f64 {
    if x.is_nan() || x == f64::INFINITY {
        return x;
    }
    if x == 0.0 {
        return f64::from_bits(1);
    }
    let bits = x.to_bits();
    if x > 0.0 {
        f64::from_bits(bits + 1)
    } else {
        f64::from_bits(bits - 1)
    }
}

/// The answer for a non-finite query point.
fn nan_answer(p: DVec3) -> ClosestPoint {
    ClosestPoint {
        distance: f64::NAN,
        point: p,
        triangle: NONE,
    }
}

fn prim(mesh: &Mesh, t: &[u32; 3], id: u32) -> Prim {
    let a = mesh.positions[t[0] as usize];
    let b = mesh.positions[t[1] as usize];
    let c = mesh.positions[t[2] as usize];
    let lo = a.min(b).min(c);
    let hi = a.max(b).max(c);
    Prim {
        min: [f32_down(lo.x), f32_down(lo.y), f32_down(lo.z), 0.0],
        max: [f32_up(hi.x), f32_up(hi.y), f32_up(hi.z), 0.0],
        id,
    }
}

/// Reusable closest-point query state; see [`Bvh::coherent_query`].
#[derive(Debug)]
pub struct CoherentQuery<'a> {
    bvh: &'a Bvh,
    stack: Vec<(f64, u32)>,
    /// Packed index of the previous answer (`u32::MAX`: none yet).
    last: u32,
}

impl CoherentQuery<'_> {
    /// The packed index of the triangle that answered the last query (`u32::MAX`: none
    /// yet). Only meaningful to [`CoherentQuery::reseed`] on a query over the same hierarchy.
    #[inline]
    pub(crate) fn last_packed(&self) -> u32 {
        self.last
    }

    /// Makes packed triangle `packed` (from [`CoherentQuery::last_packed`]) the seed of the
    /// next query; `u32::MAX` keeps the current seed.
    #[inline]
    pub(crate) fn reseed(&mut self, packed: u32) {
        if (packed as usize) < self.bvh.tris.len() {
            self.last = packed;
        }
    }

    /// The search, seeded with the previous answer when there is one.
    #[inline]
    fn run(&mut self, p: DVec3, stop_d2: f64) -> (f64, u32, DVec3) {
        let hit = if (self.last as usize) < self.bvh.tris.len() {
            self.bvh.search_up(p, self.last, stop_d2, &mut self.stack)
        } else {
            self.bvh
                .search(p, (f64::INFINITY, NONE, p), stop_d2, &mut self.stack)
        };
        if hit.1 != NONE {
            self.last = hit.1;
        }
        hit
    }

    /// The closest point of the surface to `p` (same contract as [`Bvh::closest_point`]).
    #[inline]
    pub fn closest_point(&mut self, p: DVec3) -> ClosestPoint {
        if !p.is_finite() {
            return nan_answer(p);
        }
        let hit = self.run(p, -1.0);
        self.bvh.finish(p, hit)
    }

    /// Distance from `p` to the surface (`f64::INFINITY` for an empty hierarchy, NaN for a
    /// non-finite `p`).
    #[inline]
    pub fn distance(&mut self, p: DVec3) -> f64 {
        if !p.is_finite() {
            return f64::NAN;
        }
        let (d2, packed, _) = self.run(p, -1.0);
        if packed == NONE {
            f64::INFINITY
        } else {
            d2.sqrt()
        }
    }

    /// The distance from `p` to the surface if it exceeds `threshold`, `None` if it does not.
    ///
    /// This is what a running maximum needs, and it is much cheaper than
    /// [`CoherentQuery::distance`] when the answer is `None`: the search stops at the first
    /// triangle within `threshold`, usually in the leaf of the previous answer.
    #[inline]
    pub fn distance_above(&mut self, p: DVec3, threshold: f64) -> Option<f64> {
        if !p.is_finite() {
            return None;
        }
        let stop_d2 = threshold * threshold;
        let hit = self.run(p, stop_d2);
        // sqrt(fl(t * t)) == t for binary floating point, so d2 <= t * t implies d <= t.
        if hit.1 == NONE || hit.0 <= stop_d2 {
            return None;
        }
        let d = self.bvh.finish(p, hit).distance;
        (d > threshold).then_some(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn brute(mesh: &Mesh, p: DVec3) -> f64 {
        (0..mesh.triangles.len())
            .map(|t| {
                let [a, b, c] = mesh.triangle_positions(t);
                p.distance(closest_point_on_triangle(p, a, b, c))
            })
            .fold(f64::INFINITY, f64::min)
    }

    fn check_tree(bvh: &Bvh) {
        // Every triangle sits in exactly one leaf and inside every box on its path; the
        // degenerate flags are right.
        let mut seen = vec![0u32; bvh.tris.len()];
        let mut stack = vec![(bvh.root_index, bvh.root_meta, bvh.root_min, bvh.root_max, 0)];
        let mut max_depth = 0;
        let mut inner = 0;
        while let Some((index, meta, min, max, depth)) = stack.pop() {
            max_depth = max_depth.max(depth);
            if meta != 0 {
                let count = meta & 0xFFFF;
                assert!(count as usize <= MAX_LEAF);
                for k in 0..count {
                    let t = bvh.tris[(index + k) as usize];
                    seen[(index + k) as usize] += 1;
                    assert_eq!(meta & (1 << (16 + k)) != 0, is_degenerate(t[0], t[1], t[2]));
                    for v in t {
                        for a in 0..3 {
                            assert!(min[a] as f64 <= v[a] && v[a] <= max[a] as f64);
                        }
                    }
                }
            } else {
                inner += 1;
                let n = bvh.nodes[index as usize];
                for c in 0..2 {
                    let cmin = [n.lo[0][c], n.lo[1][c], n.lo[2][c]];
                    let cmax = [n.hi[0][c], n.hi[1][c], n.hi[2][c]];
                    for a in 0..3 {
                        assert!(min[a] <= cmin[a] && cmax[a] <= max[a]);
                    }
                    stack.push((n.index[c], n.meta[c], cmin, cmax, depth + 1));
                }
            }
        }
        assert!(seen.iter().all(|&s| s == 1));
        assert_eq!(inner, bvh.nodes.len());
        assert!(max_depth < 128);
    }

    fn random_mesh(seed: u64, n_tris: usize, n_verts: usize) -> Mesh {
        let mut rng = crate::sampling::SplitMix64::new(seed);
        let positions: Vec<DVec3> = (0..n_verts)
            .map(|_| DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * 4.0 - 2.0)
            .collect();
        let triangles = (0..n_tris)
            .map(|_| {
                [
                    (rng.next_u64() % n_verts as u64) as u32,
                    (rng.next_u64() % n_verts as u64) as u32,
                    (rng.next_u64() % n_verts as u64) as u32,
                ]
            })
            .collect();
        Mesh::new(positions, triangles)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        #[test]
        fn closest_point_matches_brute_force(
            seed in any::<u64>(),
            n_tris in 1usize..300,
            n_verts in 3usize..200,
            queries in prop::collection::vec((-3.0f64..3.0, -3.0f64..3.0, -3.0f64..3.0), 1..40),
        ) {
            let mesh = random_mesh(seed, n_tris, n_verts);
            let bvh = Bvh::new(&mesh);
            check_tree(&bvh);
            let mut coherent = bvh.coherent_query();
            for (x, y, z) in queries {
                let p = DVec3::new(x, y, z);
                let want = brute(&mesh, p);
                let got = bvh.closest_point(p);
                prop_assert_eq!(got.distance, want);
                // The reported point is on the reported triangle and at that distance.
                let [a, b, c] = mesh.triangle_positions(got.triangle as usize);
                let q = closest_point_on_triangle(p, a, b, c);
                prop_assert!((q - got.point).length() <= 1e-12);
                prop_assert_eq!(coherent.closest_point(p).distance, want);
                let within = bvh.closest_point_within(p, want);
                prop_assert_eq!(within.map(|c| c.distance), Some(want));
                if want > 0.0 {
                    prop_assert!(bvh.closest_point_within(p, want * 0.999).is_none());
                }
            }
        }
    }

    #[test]
    fn grid_with_coherent_stream() {
        // A 60x60 grid on a bumpy height field, queried along a dense line.
        let n = 60;
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                positions.push(DVec3::new(x, y, 0.1 * (7.0 * x).sin() * (5.0 * y).cos()));
            }
        }
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let v = (j * (n + 1) + i) as u32;
                let w = v + n as u32 + 1;
                triangles.push([v, v + 1, w + 1]);
                triangles.push([v, w + 1, w]);
            }
        }
        let mesh = Mesh::new(positions, triangles);
        let bvh = Bvh::new(&mesh);
        check_tree(&bvh);
        let mut q = bvh.coherent_query();
        for k in 0..2000 {
            let t = k as f64 / 2000.0;
            let p = DVec3::new(t, 0.5 + 0.4 * (9.0 * t).sin(), 0.05 * (13.0 * t).cos());
            assert_eq!(q.closest_point(p).distance, brute(&mesh, p));
        }
    }

    #[test]
    fn empty_and_invalid() {
        let empty = Bvh::new(&Mesh::default());
        assert!(empty.is_empty());
        let c = empty.closest_point(DVec3::ONE);
        assert_eq!(
            (c.distance, c.triangle, c.point),
            (f64::INFINITY, u32::MAX, DVec3::ONE)
        );
        assert!(empty.closest_point_within(DVec3::ONE, 1e9).is_none());

        // Out-of-range and non-finite triangles are skipped, the rest is kept.
        let mesh = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::splat(f64::NAN)],
            vec![[0, 1, 2], [0, 1, 7], [0, 1, 3]],
        );
        let bvh = Bvh::new(&mesh);
        assert_eq!(bvh.triangle_count(), 1);
        assert_eq!(bvh.closest_point(DVec3::Z).triangle, 0);
        assert!(Bvh::try_new(&mesh).is_err());

        // All triangles degenerate and at one point.
        let mesh = Mesh::new(vec![DVec3::ONE], vec![[0, 0, 0]; 10]);
        let bvh = Bvh::new(&mesh);
        check_tree(&bvh);
        assert_eq!(bvh.closest_point(DVec3::ZERO).distance, 3f64.sqrt());
        // A NaN query does not panic and finds nothing.
        let c = bvh.closest_point(DVec3::NAN);
        assert!(c.distance.is_nan() && c.triangle == u32::MAX);
        let mut q = bvh.coherent_query();
        assert_eq!(q.closest_point(DVec3::ZERO).triangle, 0);
        assert!(q.closest_point(DVec3::NAN).distance.is_nan());
        assert_eq!(q.distance_above(DVec3::NAN, 0.0), None);
    }

    #[test]
    fn many_coincident_centroids_stay_shallow() {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for i in 0..5000u32 {
            let s = 1.0 + i as f64;
            positions.extend([DVec3::new(-s, 0.0, 0.0), DVec3::new(s, 0.0, 0.0), DVec3::Z]);
            triangles.push([3 * i, 3 * i + 1, 3 * i + 2]);
        }
        let mesh = Mesh::new(positions, triangles);
        let bvh = Bvh::new(&mesh);
        check_tree(&bvh);
        let p = DVec3::new(0.3, 2.0, 0.1);
        assert_eq!(bvh.closest_point(p).distance, brute(&mesh, p));
    }

    #[test]
    fn conservative_rounding() {
        for x in [0.1, -0.1, 1e-50, -1e-50, 1e40, -1e40, 3.0, 0.0, 16777217.0] {
            assert!((f32_down(x) as f64) <= x, "{x}");
            assert!((f32_up(x) as f64) >= x, "{x}");
        }
    }
}
