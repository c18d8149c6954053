//! Feature-preserving simplification by quadric error metrics (Garland & Heckbert 1997), the
//! third step of seed 004's pipeline: it turns the dense input into the initial control mesh.
//!
//! Each vertex carries the sum of the area-weighted plane quadrics of its triangles. Edges
//! whose dihedral angle exceeds [`SimplifyOptions::crease_angle_degrees`], and boundary
//! edges, add Garland's constraint quadrics: for each triangle at the edge, the plane through
//! the edge perpendicular to the triangle, weighted by `crease_weight` times the squared edge
//! length. A vertex on one crease can then slide along it but not off it, and a vertex where
//! creases meet stays put, so the control mesh keeps edges on the creases, where seed 004's
//! sharpness can act (its own limitation: "the approach may not work well for cases where
//! none of the edges of the initial control mesh are aligned with the creases").
//!
//! Edges collapse cheapest first (lazy-deletion heap) to the point minimising the summed
//! quadric (falling back to the best of the endpoints and the midpoint when the 3 x 3 system
//! is singular). A collapse is refused when it breaks the link condition (it would change
//! the topology), joins two boundary vertices through the interior, leaves a vertex with
//! fewer than three neighbours, turns a triangle by more than about 72 degrees or makes it a
//! needle (quality below 0.02, or below the worst triangle already around the edge: inputs
//! meshed in long strips, such as midpoint subdivisions of CAD facets, are full of needles,
//! and an absolute threshold stalled them far above the target with a folded control mesh).
//! Refused collapses are retried when the heap runs dry above the target. So the output is an oriented manifold of the input's genus whenever the input is
//! one. Not handled: non-manifold input (refused), attribute seams, volume preservation.

use crate::sharpness::dihedral_angles;
use crate::Error;
use glam::{DMat3, DVec3};
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use whet_mesh::{CornerTable, Mesh};

/// Options of [`simplify`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SimplifyOptions {
    /// Stop when this many vertices remain (at least 4).
    pub target_vertices: usize,
    /// Edges whose triangles' normals differ by more than this are creases.
    pub crease_angle_degrees: f64,
    /// Weight of the crease constraint quadrics relative to the plane quadrics.
    pub crease_weight: f64,
}

impl SimplifyOptions {
    /// 275 vertices (seed 004's rocker arm), creases above 35 degrees, weight 100.
    pub const DEFAULT: SimplifyOptions = SimplifyOptions {
        target_vertices: 275,
        crease_angle_degrees: 35.0,
        crease_weight: 100.0,
    };

    /// Sets the target vertex count.
    pub const fn with_target_vertices(mut self, n: usize) -> Self {
        self.target_vertices = n;
        self
    }

    /// Sets the crease angle.
    pub const fn with_crease_angle(mut self, degrees: f64) -> Self {
        self.crease_angle_degrees = degrees;
        self
    }

    /// Sets the crease weight (0 gives plain QEM).
    pub const fn with_crease_weight(mut self, w: f64) -> Self {
        self.crease_weight = w;
        self
    }
}

impl Default for SimplifyOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The result of [`simplify`].
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct Simplified {
    /// The simplified mesh (compact: every vertex used).
    pub mesh: Mesh,
    /// Edges of the input counted as creases.
    pub crease_edges: usize,
    /// Collapses refused by the safety checks.
    pub refused: usize,
    /// Largest quadric error of an accepted collapse.
    pub max_error: f64,
}

/// A symmetric 4 x 4 quadric: `[a2, ab, ac, ad, b2, bc, bd, c2, cd, d2]`.
#[derive(Clone, Copy, Debug, Default)]
struct Quadric([f64; 10]);

impl Quadric {
    fn plane(n: DVec3, d: f64, w: f64) -> Quadric {
        let (a, b, c) = (n.x, n.y, n.z);
        Quadric([
            w * a * a,
            w * a * b,
            w * a * c,
            w * a * d,
            w * b * b,
            w * b * c,
            w * b * d,
            w * c * c,
            w * c * d,
            w * d * d,
        ])
    }

    fn add(&mut self, o: &Quadric) {
        for i in 0..10 {
            self.0[i] += o.0[i];
        }
    }

    fn eval(&self, p: DVec3) -> f64 {
        let q = &self.0;
        let (x, y, z) = (p.x, p.y, p.z);
        q[0] * x * x
            + 2.0 * q[1] * x * y
            + 2.0 * q[2] * x * z
            + 2.0 * q[3] * x
            + q[4] * y * y
            + 2.0 * q[5] * y * z
            + 2.0 * q[6] * y
            + q[7] * z * z
            + 2.0 * q[8] * z
            + q[9]
    }

    /// The minimiser, if the 3 x 3 part is well conditioned.
    fn minimiser(&self) -> Option<DVec3> {
        let q = &self.0;
        let a = DMat3::from_cols(
            DVec3::new(q[0], q[1], q[2]),
            DVec3::new(q[1], q[4], q[5]),
            DVec3::new(q[2], q[5], q[7]),
        );
        let det = a.determinant();
        let scale = (q[0] + q[4] + q[7]).abs();
        if det.is_nan() || det.abs() <= 1e-12 * scale * scale * scale || scale == 0.0 {
            return None;
        }
        let p = a.inverse() * DVec3::new(-q[3], -q[6], -q[8]);
        p.is_finite().then_some(p)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Candidate {
    cost: f64,
    u: u32,
    v: u32,
    stamp_u: u32,
    stamp_v: u32,
    target: DVec3,
}

impl Eq for Candidate {}

impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        // Min-heap on cost, ties by vertex ids so the order is deterministic.
        other
            .cost
            .total_cmp(&self.cost)
            .then_with(|| other.u.cmp(&self.u))
            .then_with(|| other.v.cmp(&self.v))
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Smallest cosine between a triangle's normal before and after a collapse (about 72 deg).
const MIN_NORMAL_COS: f64 = 0.3;
/// Smallest accepted triangle quality `4 sqrt 3 area / sum of squared edges` (1 equilateral).
const MIN_QUALITY: f64 = 0.02;

/// Simplifies `mesh` (an oriented manifold) to `opts.target_vertices` vertices, keeping
/// creases. Stops early when no collapse passes the checks.
pub fn simplify(mesh: &Mesh, opts: &SimplifyOptions) -> Result<Simplified, Error> {
    if opts.target_vertices < 4 {
        return Err(Error::Parameter(format!(
            "target of {} vertices: at least 4 are needed",
            opts.target_vertices
        )));
    }
    if !(opts.crease_weight.is_finite()
        && opts.crease_weight >= 0.0
        && opts.crease_angle_degrees.is_finite())
    {
        return Err(Error::Parameter(
            "crease weight and angle must be finite, the weight non-negative".into(),
        ));
    }
    if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::InvalidInput(
            whet_mesh::MeshError::NonFiniteCoordinate { vertex: v as u32 },
        ));
    }
    if mesh.triangles.is_empty() {
        return Err(Error::InvalidInput(whet_mesh::MeshError::Empty));
    }
    CornerTable::new(mesh).map_err(Error::InvalidInput)?;

    let nv = mesh.positions.len();
    let mut pos = mesh.positions.clone();
    let mut faces = mesh.triangles.clone();
    let mut alive_face = vec![true; faces.len()];
    let mut vfaces: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for (t, f) in faces.iter().enumerate() {
        for &v in f {
            vfaces[v as usize].push(t as u32);
        }
    }
    // Each collapse at a vertex reads and requeues its whole neighbourhood, so a vertex of
    // valence k costs k^2 in time and heap entries: past MAX_VALENCE the mesh is refused
    // (a fan of that many triangles is no surface sample to simplify).
    if let Some(f) = vfaces.iter().find(|f| f.len() > MAX_VALENCE) {
        return Err(Error::LimitExceeded {
            what: "triangles around one vertex for the subdiv mode's simplification",
            limit: MAX_VALENCE as u64,
            value: f.len() as u64,
        });
    }
    let mut used = vec![false; nv];
    for f in &faces {
        for &v in f {
            used[v as usize] = true;
        }
    }
    let mut alive_vertices = used.iter().filter(|&&u| u).count();

    // Quadrics.
    let mut quad = vec![Quadric::default(); nv];
    for f in &faces {
        let [a, b, c] = f.map(|i| pos[i as usize]);
        let cross = (b - a).cross(c - a);
        let area2 = cross.length();
        if area2 == 0.0 {
            continue;
        }
        let n = cross / area2;
        let q = Quadric::plane(n, -n.dot(a), 0.5 * area2);
        for &v in f {
            quad[v as usize].add(&q);
        }
    }
    let edges = mesh.undirected_edges();
    let angles = dihedral_angles(mesh, &edges);
    let threshold = opts.crease_angle_degrees.to_radians();
    let mut boundary = vec![false; nv];
    let mut crease_edges = 0;
    {
        // Triangles of each edge, to build the constraint planes.
        let mut edge_faces: Vec<(u64, u32)> = Vec::with_capacity(faces.len() * 3);
        for (t, f) in faces.iter().enumerate() {
            for k in 0..3 {
                edge_faces.push((whet_mesh::edge_key(f[k], f[(k + 1) % 3]), t as u32));
            }
        }
        edge_faces.sort_unstable();
        for (e, &[a, b]) in edges.iter().enumerate() {
            let is_boundary = angles[e] >= core::f64::consts::PI;
            if !(angles[e] > threshold || is_boundary) {
                continue;
            }
            crease_edges += 1;
            if is_boundary {
                boundary[a as usize] = true;
                boundary[b as usize] = true;
            }
            let key = whet_mesh::edge_key(a, b);
            let start = edge_faces.partition_point(|x| x.0 < key);
            let (pa, pb) = (pos[a as usize], pos[b as usize]);
            let dir = pb - pa;
            let len2 = dir.length_squared();
            for &(k, t) in &edge_faces[start..] {
                if k != key {
                    break;
                }
                let n = mesh.face_normal(t as usize);
                let c = dir.cross(n);
                let cl = c.length();
                if cl == 0.0 || !n.is_finite() {
                    continue;
                }
                let c = c / cl;
                let q = Quadric::plane(c, -c.dot(pa), opts.crease_weight * len2);
                quad[a as usize].add(&q);
                quad[b as usize].add(&q);
            }
        }
    }

    let mut stamp = vec![0u32; nv];
    let mut heap = BinaryHeap::new();
    let candidate = |u: u32, v: u32, quad: &[Quadric], pos: &[DVec3], stamp: &[u32]| {
        let (u, v) = (u.min(v), u.max(v));
        let mut q = quad[u as usize];
        q.add(&quad[v as usize]);
        let (pu, pv) = (pos[u as usize], pos[v as usize]);
        let mut best = (f64::INFINITY, pu);
        if let Some(p) = q.minimiser() {
            // Keep the optimum near the edge: far optima come from nearly flat quadrics.
            let len = (pv - pu).length();
            let mid = 0.5 * (pu + pv);
            if (p - mid).length() <= 2.0 * len {
                best = (q.eval(p), p);
            }
        }
        for p in [pu, pv, 0.5 * (pu + pv)] {
            let c = q.eval(p);
            if c < best.0 {
                best = (c, p);
            }
        }
        Candidate {
            cost: best.0.max(0.0),
            u,
            v,
            stamp_u: stamp[u as usize],
            stamp_v: stamp[v as usize],
            target: best.1,
        }
    };
    for &[a, b] in &edges {
        heap.push(candidate(a, b, &quad, &pos, &stamp));
    }

    let mut refused = 0;
    let mut max_error: f64 = 0.0;
    let mut nbrs_u: Vec<u32> = Vec::new();
    let mut nbrs_v: Vec<u32> = Vec::new();
    let mut marks = Marks::new(nv);
    // A refused collapse leaves the heap; it comes back only when one of its endpoints
    // changes, although a collapse next to it can make it valid. So when the heap runs dry
    // above the target, every live edge is queued again, until a pass collapses nothing.
    let mut collapsed_this_pass = 0usize;
    while alive_vertices > opts.target_vertices {
        let Some(c) = heap.pop() else {
            if collapsed_this_pass == 0 {
                break;
            }
            collapsed_this_pass = 0;
            for (t, f) in faces.iter().enumerate() {
                if alive_face[t] {
                    for k in 0..3 {
                        let (a, b) = (f[k], f[(k + 1) % 3]);
                        if a < b || !faces_have_edge(&vfaces[b as usize], &faces, b, a) {
                            heap.push(candidate(a, b, &quad, &pos, &stamp));
                        }
                    }
                }
            }
            continue;
        };
        let (u, v) = (c.u as usize, c.v as usize);
        if stamp[u] != c.stamp_u || stamp[v] != c.stamp_v || !used[u] || !used[v] {
            continue;
        }
        // Neighbour sets.
        neighbours(u, &vfaces, &faces, &mut nbrs_u, &mut marks);
        if !nbrs_u.contains(&(v as u32)) {
            continue;
        }
        neighbours(v, &vfaces, &faces, &mut nbrs_v, &mut marks);
        // `nbrs_v` is the last set marked.
        let shared: Vec<u32> = nbrs_u
            .iter()
            .copied()
            .filter(|&x| marks.is_current(x))
            .collect();
        let edge_faces: Vec<u32> = vfaces[u]
            .iter()
            .copied()
            .filter(|&t| faces[t as usize].contains(&(v as u32)))
            .collect();
        let is_boundary_edge = edge_faces.len() == 1;
        let ok_link = shared.len() == edge_faces.len()
            && edge_faces.iter().all(|&t| {
                let f = faces[t as usize];
                f.iter()
                    .any(|&x| x as usize != u && x as usize != v && shared.contains(&x))
            });
        let ok_boundary = is_boundary_edge || !(boundary[u] && boundary[v]);
        let merged_valence = nbrs_u.len() + nbrs_v.len() - shared.len() - 2;
        let ok_valence = merged_valence >= 3
            && shared.iter().all(|&x| {
                // Each shared vertex loses one neighbour.
                let mut n = Vec::new();
                neighbours(x as usize, &vfaces, &faces, &mut n, &mut marks);
                n.len() > 3
            });
        if !(ok_link
            && ok_boundary
            && ok_valence
            && geometry_ok(u, v, c.target, &vfaces, &faces, &pos))
        {
            refused += 1;
            continue;
        }
        // Collapse v into u.
        max_error = max_error.max(c.cost);
        pos[u] = c.target;
        let q = quad[v];
        quad[u].add(&q);
        boundary[u] |= boundary[v];
        for &t in &edge_faces {
            alive_face[t as usize] = false;
            for &x in &faces[t as usize] {
                vfaces[x as usize].retain(|&y| y != t);
            }
        }
        let moved: Vec<u32> = std::mem::take(&mut vfaces[v]);
        for &t in &moved {
            for x in faces[t as usize].iter_mut() {
                if *x as usize == v {
                    *x = u as u32;
                }
            }
            vfaces[u].push(t);
        }
        used[v] = false;
        alive_vertices -= 1;
        collapsed_this_pass += 1;
        stamp[u] = stamp[u].wrapping_add(1);
        stamp[v] = stamp[v].wrapping_add(1);
        neighbours(u, &vfaces, &faces, &mut nbrs_u, &mut marks);
        for &x in &nbrs_u {
            heap.push(candidate(u as u32, x, &quad, &pos, &stamp));
        }
    }

    // Compact.
    let mut remap = vec![u32::MAX; nv];
    let mut positions = Vec::with_capacity(alive_vertices);
    let mut triangles = Vec::new();
    for (t, f) in faces.iter().enumerate() {
        if !alive_face[t] {
            continue;
        }
        let mut out = [0u32; 3];
        for k in 0..3 {
            let x = f[k] as usize;
            if remap[x] == u32::MAX {
                remap[x] = positions.len() as u32;
                positions.push(pos[x]);
            }
            out[k] = remap[x];
        }
        triangles.push(out);
    }
    Ok(Simplified {
        mesh: Mesh::new(positions, triangles),
        crease_edges,
        refused,
        max_error,
    })
}

/// Whether moving `u` and `v` to `target` keeps every surviving triangle around them from
/// turning by more than about 72 degrees or becoming a needle.
fn geometry_ok(
    u: usize,
    v: usize,
    target: DVec3,
    vfaces: &[Vec<u32>],
    faces: &[[u32; 3]],
    pos: &[DVec3],
) -> bool {
    // Needles already there (inputs meshed in long strips have many) are no reason to refuse
    // a collapse, as long as it does not make the worst triangle around worse.
    let min_quality = [u, v]
        .iter()
        .flat_map(|&w| vfaces[w].iter())
        .map(|&t| quality(faces[t as usize].map(|i| pos[i as usize])))
        .fold(MIN_QUALITY, f64::min);
    [u, v].iter().all(|&w| {
        vfaces[w].iter().all(|&t| {
            let f = faces[t as usize];
            if f.contains(&(u as u32)) && f.contains(&(v as u32)) {
                return true;
            }
            let old = f.map(|i| pos[i as usize]);
            let new = f.map(|i| {
                if i as usize == u || i as usize == v {
                    target
                } else {
                    pos[i as usize]
                }
            });
            let n0 = (old[1] - old[0]).cross(old[2] - old[0]);
            let n1 = (new[1] - new[0]).cross(new[2] - new[0]);
            let l0 = n0.length();
            let l1 = n1.length();
            if l0 == 0.0 || l1 == 0.0 {
                return l1 > 0.0;
            }
            n0.dot(n1) >= MIN_NORMAL_COS * l0 * l1 && quality(new) >= min_quality
        })
    })
}

/// `4 sqrt 3 area / sum of squared edges`: 1 for an equilateral triangle, 0 for a degenerate.
fn quality(p: [DVec3; 3]) -> f64 {
    let sum2 = (p[1] - p[0]).length_squared()
        + (p[2] - p[1]).length_squared()
        + (p[0] - p[2]).length_squared();
    let q = 2.0 * 3f64.sqrt() * (p[1] - p[0]).cross(p[2] - p[0]).length() / sum2;
    if q.is_finite() {
        q
    } else {
        0.0
    }
}

/// Whether a live triangle of `b` (listed in `b_faces`) has the directed edge `b -> a`; an
/// undirected edge is queued once, from its lower id, unless it is a boundary edge seen only
/// in the other direction.
fn faces_have_edge(b_faces: &[u32], faces: &[[u32; 3]], b: u32, a: u32) -> bool {
    b_faces.iter().any(|&t| {
        let f = faces[t as usize];
        (0..3).any(|k| f[k] == b && f[(k + 1) % 3] == a)
    })
}

/// Most triangles around one vertex that [`simplify`] takes.
const MAX_VALENCE: usize = 1024;

/// Per-vertex marks of the last set gathered, cleared in O(1) by a new generation.
struct Marks {
    mark: Vec<u32>,
    generation: u32,
}

impl Marks {
    fn new(n: usize) -> Marks {
        Marks {
            mark: vec![0; n],
            generation: 0,
        }
    }
    /// Starts a new set.
    fn start(&mut self) {
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.mark.fill(0);
            self.generation = 1;
        }
    }
    /// Marks `x`; false when it was marked in this set already.
    fn insert(&mut self, x: u32) -> bool {
        let m = &mut self.mark[x as usize];
        let new = *m != self.generation;
        *m = self.generation;
        new
    }
    fn is_current(&self, x: u32) -> bool {
        self.mark[x as usize] == self.generation
    }
}

/// The distinct neighbours of `v` through its live triangles, in the order first met
/// (marked in `marks` as the current set: a membership test per neighbour, not a search).
fn neighbours(
    v: usize,
    vfaces: &[Vec<u32>],
    faces: &[[u32; 3]],
    out: &mut Vec<u32>,
    marks: &mut Marks,
) {
    out.clear();
    marks.start();
    for &t in &vfaces[v] {
        for &x in &faces[t as usize] {
            if x as usize != v && marks.insert(x) {
                out.push(x);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid_sphere(n: usize) -> Mesh {
        // A UV sphere: poles plus rings; closed, genus 0.
        let mut p = vec![DVec3::Z, -DVec3::Z];
        for i in 1..n {
            let th = core::f64::consts::PI * i as f64 / n as f64;
            for j in 0..2 * n {
                let ph = core::f64::consts::PI * j as f64 / n as f64;
                p.push(DVec3::new(
                    th.sin() * ph.cos(),
                    th.sin() * ph.sin(),
                    th.cos(),
                ));
            }
        }
        let m = 2 * n as u32;
        let ring = |i: u32, j: u32| 2 + (i - 1) * m + (j % m);
        let mut t = Vec::new();
        for j in 0..m {
            t.push([0, ring(1, j), ring(1, j + 1)]);
            t.push([1, ring(n as u32 - 1, j + 1), ring(n as u32 - 1, j)]);
        }
        for i in 1..n as u32 - 1 {
            for j in 0..m {
                t.push([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
                t.push([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
            }
        }
        Mesh::new(p, t)
    }

    #[test]
    fn sphere_simplifies_to_the_target_and_stays_a_closed_manifold() {
        let m = grid_sphere(16);
        let r = m.topology_report();
        assert!(r.manifold && r.oriented && r.genus == Some(0), "{r:?}");
        let s = simplify(&m, &SimplifyOptions::DEFAULT.with_target_vertices(40)).unwrap();
        assert_eq!(s.mesh.positions.len(), 40);
        let r = s.mesh.topology_report();
        assert!(r.manifold && r.oriented && r.boundary_edges == 0 && r.genus == Some(0));
        // Vertices stay near the sphere.
        for p in &s.mesh.positions {
            assert!((p.length() - 1.0).abs() < 0.1);
        }
    }

    #[test]
    fn refuses_bad_targets() {
        let m = grid_sphere(4);
        assert!(simplify(&m, &SimplifyOptions::DEFAULT.with_target_vertices(3)).is_err());
    }

    /// Collapses at a vertex of valence k read and requeue its k neighbours: 20 000 took
    /// minutes; past 1024 the mesh is refused with a named limit, at once.
    #[test]
    fn a_vertex_of_very_high_valence_is_refused() {
        let opts = SimplifyOptions::DEFAULT.with_target_vertices(40);
        match simplify(&whet_testkit::meshes::hub_disk(2000, 2), &opts) {
            Err(Error::LimitExceeded { limit, value, .. }) => {
                assert_eq!((limit, value), (1024, 2000));
            }
            other => panic!("{other:?}"),
        }
        let s = simplify(&whet_testkit::meshes::hub_disk(300, 2), &opts).unwrap();
        assert!(
            s.mesh.positions.len() <= 40 + 1,
            "{}",
            s.mesh.positions.len()
        );
    }
}
