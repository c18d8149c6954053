//! Extended method: welding marching cubes' clusters of near-coincident input vertices
//! (docs/sharpen.md, "What we extend", step 10).
//!
//! Where a grid value is near zero, marching cubes puts the vertices of every crossing grid
//! edge at that grid point: clusters of three or four input vertices within a few hundredths
//! of an edge, joined by zero-area triangles. A chamfer edge that is a long edge of such a
//! sliver cannot be split (the piece holding the sliver's short edge would be as thin), so the
//! crease keeps a gap there and the max error sits in it. Welding each cluster into one vertex
//! removes the slivers and lets the chamfer be cut.
//!
//! Every cluster is welded before the run ([`weld_clusters`]), so the engine runs once; the
//! run keeps the input's smooth threshold. Afterwards [`restore_untouched`] puts back, as
//! they were in the input, the clusters whose welded fans the run left exactly as they were,
//! so smooth regions and meshes without chamfers (already sharp ones) keep their triangles.
//! A cluster holds the vertices joined to a sliver's shortest edge by edges shorter than
//! [`CLUSTER_EDGE`] mean edge lengths. Its vertices merge into the one whose position turns
//! the remapped triangles least; the others stay at their indices with no triangle using them
//! (the output promise "input vertex `i` is output vertex `i`" holds), and the triangles that
//! had two of them disappear. A cluster is left alone when it touches the boundary, when the
//! merge would break the manifold around it, or when a changed triangle would be a sliver.

use glam::DVec3;
use whet_mesh::{CornerTable, FaceId, Mesh, VertexId};

/// Vertices closer than this many mean edge lengths form a cluster. Marching cubes' clusters
/// span up to a few hundredths of an edge (measured: welding within 0.01 changes nothing on
/// the cube at 64, within 0.05 it welds its clusters); real features of a sampled surface
/// are not this small.
pub(crate) const CLUSTER_EDGE: f64 = 0.05;

/// The welded input and how to map its triangles back.
pub(crate) struct Welded {
    /// Every input vertex at its input index; the merged ones are used by no triangle.
    pub mesh: Mesh,
    /// Input triangle of each welded triangle.
    pub input_triangle: Vec<u32>,
    /// Welded triangle of each input triangle (`u32::MAX` for the ones welding removed).
    pub welded_index: Vec<u32>,
    /// The vertex each input vertex was merged into (itself when not merged).
    pub rep: Vec<u32>,
    /// A bit per welded triangle: set on those welding changed (holding a vertex another
    /// was merged into).
    pub welded_changed: Vec<u64>,
    /// The normal angles (sum and count, as [`crate::edge_sharpener`]'s smooth pass adds
    /// them) of the input's interior edges beside a triangle welding changed or removed
    /// (one holding a merged vertex), each edge once. Every other input triangle is in the
    /// welded mesh with the same vertices and, across every edge between two such
    /// triangles, the same neighbour (the welded table pairs anew only across removed
    /// triangles, whose neighbours there hold a merged vertex). So the smooth pass's sum
    /// over the welded edges beside no changed triangle ([`Welded::welded_changed`]) plus
    /// this one is the input's, up to the order of the additions: the run's smooth
    /// threshold is the input's (see `Run::smooth_edges`).
    pub input_edges: (f64, usize),
    /// The merged clusters, for putting them back ([`restore_untouched`]).
    pub clusters: Clusters,
    /// A bit per input vertex: set on the clusters' kept vertices.
    pub root_bits: Vec<u64>,
    /// The welded table's triangles and opposites as the copy left them, with the corners
    /// still to pair across removed triangles, until [`welded_table`] takes them.
    pub table_parts: Option<TableParts>,
}

/// See [`Welded::table_parts`].
pub(crate) type TableParts = (Vec<[u32; 3]>, Vec<u32>, Vec<(u64, u32)>);

impl Welded {
    /// Whether `v` is the kept vertex of a cluster (false past the input's vertices).
    #[inline]
    pub fn is_root(&self, v: u32) -> bool {
        self.root_bits
            .get(v as usize / 64)
            .is_some_and(|w| w >> (v % 64) & 1 != 0)
    }
}

/// The clusters [`weld_clusters`] merged, in merge order, as flat lists.
#[derive(Clone, Debug, Default)]
pub(crate) struct Clusters {
    /// Each cluster's vertices, its kept vertex first; `member_ends` holds where each ends.
    pub members: Vec<u32>,
    pub member_ends: Vec<u32>,
    /// Each cluster's input triangles around its vertices (those welding removed included),
    /// ascending; `fan_ends` holds where each ends.
    pub fans: Vec<u32>,
    pub fan_ends: Vec<u32>,
}

impl Clusters {
    /// Number of clusters.
    pub fn len(&self) -> usize {
        self.member_ends.len()
    }

    /// The vertices of cluster `c`, its kept vertex first.
    pub fn members(&self, c: usize) -> &[u32] {
        let start = if c == 0 { 0 } else { self.member_ends[c - 1] };
        &self.members[start as usize..self.member_ends[c] as usize]
    }

    /// The input triangles around cluster `c`, ascending.
    pub fn fan(&self, c: usize) -> &[u32] {
        let start = if c == 0 { 0 } else { self.fan_ends[c - 1] };
        &self.fans[start as usize..self.fan_ends[c] as usize]
    }
}

impl Welded {
    /// Gives the arrays back to `pool`.
    pub fn recycle(self, pool: &mut whet_mesh::Scratch) {
        pool.give(self.mesh.positions);
        pool.give(self.mesh.triangles);
        pool.give(self.input_triangle);
        pool.give(self.welded_index);
        pool.give(self.rep);
        pool.give(self.welded_changed);
        pool.give(self.root_bits);
        if let Some((triangles, opposite, _)) = self.table_parts {
            pool.give(triangles);
            pool.give(opposite);
        }
    }
}

/// Working memory of [`weld_clusters`], kept between runs by the engine: a million-triangle
/// input needs about 6 MB of it, which fresh each run cost page faults, and the merge
/// checks of every cluster (thousands a run) ran on vectors allocated per cluster.
#[derive(Clone, Debug, Default)]
pub(crate) struct WeldScratch {
    shortest: Vec<f32>,
    alive: Vec<bool>,
    in_cluster: Vec<bool>,
    cluster: Vec<u32>,
    /// Refused clusters, one after another; `refused_ends` holds where each ends.
    refused: Vec<u32>,
    refused_ends: Vec<u32>,
    merge: MergeScratch,
}

/// [`merge_cluster`]'s vectors.
#[derive(Clone, Debug, Default)]
struct MergeScratch {
    around: Vec<u32>,
    before: Vec<(DVec3, f64)>,
    edges: Vec<(u32, u32)>,
    faces: Vec<[u32; 3]>,
    fan: Vec<(u32, u32)>,
}

/// Welds the clusters of `mesh` (whose table is `table`), each seeded by a triangle whose
/// shortest edge is under [`CLUSTER_EDGE`] mean edges; `min_angle` (radians) is the sliver
/// threshold no changed triangle may fall under. `None` when no cluster could be welded.
/// The welded mesh's arrays are taken from `pool` ([`Welded::recycle`] gives them back).
pub(crate) fn weld_clusters(
    mesh: &Mesh,
    table: &CornerTable,
    min_angle: f64,
    scratch: &mut WeldScratch,
    pool: &mut whet_mesh::Scratch,
) -> Option<Welded> {
    let nv = mesh.positions.len();
    // One pass over the triangles for the mean edge length (each edge once, in the order
    // `CornerTable::mean_edge_length` adds them: the same value) and each triangle's shortest
    // side, so the scan for slivers below reads one array instead of the positions again.
    let opposite = table.opposites();
    let WeldScratch {
        shortest,
        alive,
        in_cluster,
        cluster,
        refused,
        refused_ends,
        merge,
    } = scratch;
    shortest.clear();
    let (mut sum, mut count) = (0.0f64, 0usize);
    for (t, (tri, o3)) in mesh
        .triangles
        .iter()
        .zip(opposite.chunks_exact(3))
        .enumerate()
    {
        let p = tri.map(|v| mesh.positions[v as usize]);
        let (k, lengths) = crate::edge_sharpener::smallest_angle_corner(&p);
        // Rounded to f32 (relative error 6e-8; the scan allows for it); an overflow stays
        // finite so the scan's margin cannot make it pass where the exact test would not.
        shortest.push((lengths[k] as f32).min(f32::MAX));
        for (j, &o) in o3.iter().enumerate() {
            // Each interior edge from its lower corner, each boundary edge once.
            if o == u32::MAX || o as usize > 3 * t + j {
                sum += lengths[j].sqrt();
                count += 1;
            }
        }
    }
    let mean = if count == 0 { 0.0 } else { sum / count as f64 };
    debug_assert_eq!(
        mean.to_bits(),
        table.mean_edge_length(&mesh.positions).to_bits()
    );
    let limit = CLUSTER_EDGE * mean;
    // Also refuses a NaN length (no finite mean edge).
    if limit.is_nan() || limit <= 0.0 {
        return None;
    }
    let limit2 = limit * limit;
    let close = |a: u32, b: u32| {
        mesh.positions[a as usize].distance_squared(mesh.positions[b as usize]) < limit2
    };
    // Representative of each vertex (itself unless merged).
    let mut rep: Vec<u32> = Vec::new();
    let mut merged = 0usize;
    let mut clusters = Clusters::default();
    refused.clear();
    refused_ends.clear();
    let mut merge_one =
        |cluster: &[u32], rep: &mut [u32], alive: &mut [bool], to: &mut Clusters| {
            merge_cluster(mesh, table, cluster, rep, alive, min_angle, merge, to)
        };
    // Above this, a triangle's rounded shortest side cannot hide an exact one under `limit2`.
    let candidate = limit2 * (1.0 + 1e-6);
    for (t, &tri) in mesh.triangles.iter().enumerate() {
        if f64::from(shortest[t]) >= candidate {
            continue;
        }
        let p = mesh.triangle_positions(t);
        // The sliver's shortest edge, opposite its smallest angle.
        let (k, lengths) = crate::edge_sharpener::smallest_angle_corner(&p);
        let (a, b, d) = (tri[(k + 1) % 3], tri[(k + 2) % 3], lengths[k]);
        if d >= limit2 {
            continue;
        }
        if rep.is_empty() {
            rep = pool.take_empty(nv);
            rep.extend(0..nv as u32);
            alive.clear();
            alive.resize(mesh.triangles.len(), true);
            in_cluster.clear();
            in_cluster.resize(nv, false);
        }
        if a == b || in_cluster[a as usize] || in_cluster[b as usize] {
            continue;
        }
        // Grow the cluster over short edges.
        cluster.clear();
        cluster.extend([a, b]);
        in_cluster[a as usize] = true;
        in_cluster[b as usize] = true;
        let mut i = 0;
        let mut open = false;
        while i < cluster.len() {
            let v = cluster[i];
            i += 1;
            open |= table.is_boundary_vertex(VertexId(v));
            for c in table.vertex_corners(VertexId(v)) {
                for w in [table.vertex(table.next(c)).0, table.vertex(table.prev(c)).0] {
                    if !in_cluster[w as usize] && close(v, w) {
                        in_cluster[w as usize] = true;
                        cluster.push(w);
                    }
                }
            }
        }
        if open || cluster.len() > 8 {
            // On the boundary (welding would change it), or not a marching-cubes cluster.
            continue;
        }
        if let Some(n) = merge_one(cluster, &mut rep, alive, &mut clusters) {
            merged += n;
        } else {
            refused.extend_from_slice(cluster);
            refused_ends.push(refused.len() as u32);
        }
    }
    // A cluster can be refused for a sliver that a cluster welded after it removes (two
    // clusters across one triangle, each a face of a crease: synth cube 32 r0, where the
    // refused one left a needle that blocked the move restoring the crease). One more try
    // each, in the same order, once the first round is done.
    let mut start = 0;
    for &end in refused_ends.iter() {
        let cluster = &refused[start..end as usize];
        start = end as usize;
        if let Some(n) = merge_one(cluster, &mut rep, alive, &mut clusters) {
            merged += n;
        }
    }
    if merged == 0 {
        pool.give(rep);
        return None;
    }
    let nt = mesh.triangles.len();
    // Each input triangle's welded index first, so that the copy below pairs the welded
    // table's corners as it goes.
    let mut welded_index: Vec<u32> = pool.take_empty(nt);
    let mut next = 0u32;
    welded_index.extend(alive.iter().map(|&a| {
        let k = if a { next } else { u32::MAX };
        next += u32::from(a);
        k
    }));
    let nw = next as usize;
    let mut triangles = pool.take_empty(nw);
    let mut input_triangle = pool.take_empty(nw);
    let mut welded_changed = pool.take_filled(nt.div_ceil(64), 0u64);
    // The welded table's arrays: a welded triangle's corners face the same triangles as in
    // the input, except across the edges of removed triangles, paired anew by their vertices
    // afterwards (`loose`, by edge from -> to). Every corner is written once below.
    let mut table_triangles = pool.take_empty(nw);
    let mut table_opposite = pool.take_overwritten(3 * nw, u32::MAX);
    let mut loose: Vec<(u64, u32)> = Vec::new();
    // Only merged vertices map elsewhere, and a removed triangle holds one.
    let is_changed = |t: usize| mesh.triangles[t].iter().any(|&v| rep[v as usize] != v);
    let (mut sum, mut count) = (0.0f64, 0usize);
    for (t, tri) in mesh.triangles.iter().enumerate() {
        // The welded triangle, and whether welding changed it (`is_changed`, without reading
        // the merges twice).
        let welded = tri.map(|v| rep[v as usize]);
        let changed = welded != *tri;
        if changed {
            // The input's edges here, while its neighbourhood is in cache (the patch is
            // spread over the whole mesh: summed in the run, its reads missed).
            let n1 = mesh.face_normal(t);
            for c in 3 * t..3 * t + 3 {
                let o = opposite[c];
                if n1 == DVec3::ZERO || o == u32::MAX {
                    continue;
                }
                // Each edge once: from its lower corner when both sides changed.
                let u = o as usize / 3;
                if (o as usize) < c && is_changed(u) {
                    continue;
                }
                // An unchanged neighbour's normal is its welded image's (same vertices).
                let n2 = mesh.face_normal(u);
                if n2 != DVec3::ZERO {
                    sum += crate::edge_sharpener::normal_angle(n1, n2);
                    count += 1;
                }
            }
        }
        if alive[t] {
            let k = triangles.len();
            if changed {
                welded_changed[k / 64] |= 1 << (k % 64);
            }
            for (j, &o) in opposite[3 * t..3 * t + 3].iter().enumerate() {
                let ot = welded_index
                    .get(o as usize / 3)
                    .copied()
                    .unwrap_or(u32::MAX);
                table_opposite[3 * k + j] = if o == u32::MAX {
                    u32::MAX
                } else if ot != u32::MAX {
                    3 * ot + o % 3
                } else {
                    let (a, b) = (welded[(j + 1) % 3], welded[(j + 2) % 3]);
                    loose.push((u64::from(a) << 32 | u64::from(b), (3 * k + j) as u32));
                    u32::MAX
                };
            }
            triangles.push(welded);
            table_triangles.push(welded);
            input_triangle.push(t as u32);
        }
    }
    welded_changed.truncate(triangles.len().div_ceil(64));
    let mut positions = pool.take_empty(nv);
    positions.extend_from_slice(&mesh.positions);
    Some(Welded {
        mesh: Mesh::new(positions, triangles),
        input_triangle,
        welded_index,
        rep,
        welded_changed,
        input_edges: (sum, count),
        table_parts: Some((table_triangles, table_opposite, loose)),
        root_bits: {
            let mut bits = pool.take_filled(nv.div_ceil(64), 0u64);
            for c in 0..clusters.len() {
                let r = clusters.members(c)[0];
                bits[r as usize / 64] |= 1 << (r % 64);
            }
            bits
        },
        clusters,
    })
}

/// Merges `cluster` into the member whose position turns the triangles around it least, if
/// they stay an oriented manifold with no new sliver ([`merge_keeps_manifold`]): updates
/// `rep` and `alive`, appends the cluster to `merged` and returns the number of vertices
/// merged away; `None`, with `rep` as it was, when refused.
#[allow(clippy::too_many_arguments)] // the welding's state, passed down to each cluster
fn merge_cluster(
    mesh: &Mesh,
    table: &CornerTable,
    cluster: &[u32],
    rep: &mut [u32],
    alive: &mut [bool],
    min_angle: f64,
    scratch: &mut MergeScratch,
    merged: &mut Clusters,
) -> Option<usize> {
    let MergeScratch {
        around,
        before,
        edges,
        faces,
        fan,
    } = scratch;
    around.clear();
    for &v in cluster {
        around.extend(table.vertex_corners(VertexId(v)).map(|c| c.0 / 3));
    }
    around.sort_unstable();
    around.dedup();
    // Every triangle around the cluster, kept for putting it back.
    let fan_start = merged.fans.len();
    merged.fans.extend_from_slice(around);
    around.retain(|&t| alive[t as usize]);
    // The member whose position turns the remapped triangles least: the largest cosine of
    // the worst turn (no arc cosine per candidate and triangle).
    before.clear();
    before.extend(around.iter().map(|&t| {
        let n = mesh.face_cross(t as usize);
        (n, n.length_squared())
    }));
    let mut best = (f64::NEG_INFINITY, cluster[0]);
    for &r in cluster {
        for &v in cluster {
            rep[v as usize] = r;
        }
        let cos = smallest_turn_cosine(mesh, rep, around, before);
        if cos > best.0 || (cos == best.0 && r < best.1) {
            best = (cos, r);
        }
    }
    let root = best.1;
    for &v in cluster {
        rep[v as usize] = root;
    }
    if merge_keeps_manifold(mesh, rep, around, root, min_angle, (edges, faces, fan)) {
        for &t in around.iter() {
            let [x, y, z] = mesh.triangles[t as usize].map(|v| rep[v as usize]);
            if x == y || y == z || z == x {
                alive[t as usize] = false;
            }
        }
        merged.fan_ends.push(merged.fans.len() as u32);
        merged.members.push(root);
        merged
            .members
            .extend(cluster.iter().copied().filter(|&v| v != root));
        merged.member_ends.push(merged.members.len() as u32);
        Some(cluster.len() - 1)
    } else {
        merged.fans.truncate(fan_start);
        for &v in cluster {
            rep[v as usize] = v;
        }
        None
    }
}

/// The corner table of `welded` (the welding of the input whose table gave its corners'
/// opposites): a welded triangle's corners face the same triangles as in the input, except
/// across the edges of removed triangles, which pair up anew by their vertices. (The merge
/// checks keep every fan one cycle, so this pairing is the whole table.) `None` when an edge
/// does not pair with exactly one reversed twin, the arrays are out of range, or the arrays
/// were taken already: then the caller builds the table from scratch, which says why. Takes
/// [`Welded::table_parts`]; the table's per-vertex array comes from `pool`.
pub(crate) fn welded_table(
    welded: &mut Welded,
    pool: &mut whet_mesh::Scratch,
) -> Option<CornerTable> {
    let (triangles, mut opposite, mut loose) = welded.table_parts.take()?;
    loose.sort_unstable();
    if loose.windows(2).any(|w| w[0].0 == w[1].0) {
        return None;
    }
    for &(key, c) in &loose {
        let twin = key.rotate_left(32);
        let i = loose.binary_search_by_key(&twin, |e| e.0).ok()?;
        *opposite.get_mut(c as usize)? = loose[i].1;
    }
    CornerTable::from_relabelled_in(triangles, opposite, welded.mesh.positions.len(), pool).ok()
}

/// An input and its welding, for a run on the welded mesh: its smooth threshold is the
/// input's ([`Welded::input_edges`]), its output has room for the triangles putting the
/// clusters back returns.
#[derive(Clone, Copy)]
pub(crate) struct WeldPatch<'a> {
    pub input: &'a Mesh,
    pub welded: &'a Welded,
}

/// What [`restore_untouched`] put back.
pub(crate) struct Restored {
    /// Clusters restored.
    pub clusters: usize,
    /// Input vertices still merged into another.
    pub still_welded: usize,
    /// Each restored vertex with the vertex it had been merged into.
    pub members: Vec<(u32, u32)>,
}

impl Restored {
    /// Tags every restored vertex as the vertex it had been merged into was, in the tagged
    /// vertex flags of the output.
    pub fn retag(&self, tagged: &mut [bool]) {
        let before = tagged.to_vec();
        for &(v, root) in &self.members {
            let root_tagged = before.get(root as usize).copied().unwrap_or(false);
            if let Some(f) = tagged.get_mut(v as usize) {
                *f = root_tagged;
            }
        }
    }
}

/// After a run on `welded` (the welding of `input`): puts back the clusters the run left
/// untouched, as they were in the input.
/// A cluster is untouched when its kept vertex did not move and every output triangle around
/// it is a welded triangle as it was, of unmoved input vertices, all of them there. Clusters
/// sharing an input triangle are put back together or not at all, so every fan put back is
/// the input's. `out` and `parents` (input triangle indices) are rewritten in place; the
/// triangles put back keep their place in parent order (an output without any change
/// elsewhere is the input again). `around_roots` lists, ascending, the output triangles
/// holding a kept vertex (the run's output pass collects them).
pub(crate) fn restore_untouched(
    input: &Mesh,
    welded: &Welded,
    out: &mut Mesh,
    parents: &mut Vec<FaceId>,
    around_roots: &[u32],
) -> Restored {
    let nv = input.positions.len();
    let rep = &welded.rep;
    let merged = &welded.clusters;
    // Cluster index of every vertex of a cluster (its kept vertex included).
    let mut cluster = vec![NO_CLUSTER; nv];
    let mut roots: Vec<u32> = Vec::with_capacity(merged.len());
    for c in 0..merged.len() {
        let members = merged.members(c);
        roots.push(members[0]);
        for &v in members {
            cluster[v as usize] = c as u32;
        }
    }
    let clustered = &merged.members;
    let n = roots.len();
    // The welding's bit per kept vertex, widened to every output vertex (new ones clear), so
    // the tests below read three per triangle without a range check or a branch each.
    let no = out.positions.len().max(nv);
    let mut root_bits = welded.root_bits.clone();
    root_bits.resize(no.div_ceil(64), 0);
    let is_root = |bits: &[u64], v: u32| bits[v as usize / 64] >> (v % 64) & 1 != 0;
    let touches = |bits: &[u64], t: &[u32; 3]| {
        (bits[t[0] as usize / 64] >> (t[0] % 64)
            | bits[t[1] as usize / 64] >> (t[1] % 64)
            | bits[t[2] as usize / 64] >> (t[2] % 64))
            & 1
            != 0
    };
    let mut touched: Vec<bool> = roots
        .iter()
        .map(|&r| out.positions.get(r as usize) != Some(&input.positions[r as usize]))
        .collect();
    // Output triangles around each kept vertex: as many as welded ones (the triangles around
    // its cluster that welding kept), each as it was.
    let welded_index = &welded.welded_index;
    let mut missing: Vec<i64> = (0..merged.len())
        .map(|c| {
            let fan = merged.fan(c).iter();
            fan.filter(|&&t| welded_index[t as usize] != u32::MAX)
                .count() as i64
        })
        .collect();
    let unmoved =
        |v: u32| (v as usize) < nv && out.positions[v as usize] == input.positions[v as usize];
    // Output triangles around the kept vertices (only they can change below).
    for &i in around_roots {
        let (tri, p) = (&out.triangles[i as usize], parents[i as usize]);
        debug_assert!(touches(&root_bits, tri));
        let same = *tri == input.triangles[p.index()].map(|x| rep[x as usize])
            && tri.iter().all(|&x| unmoved(x));
        for &v in tri {
            if is_root(&root_bits, v) {
                let c = cluster[v as usize] as usize;
                missing[c] -= 1;
                touched[c] |= !same;
            }
        }
    }
    for (t, m) in touched.iter_mut().zip(&missing) {
        *t |= *m != 0;
    }
    // Clusters sharing an input triangle share one fate.
    fn find(group: &mut [u32], mut x: u32) -> u32 {
        while group[x as usize] != x {
            let g = group[group[x as usize] as usize];
            group[x as usize] = g;
            x = g;
        }
        x
    }
    let mut group: Vec<u32> = (0..n as u32).collect();
    // Input triangles around the clustered vertices, ascending (a bit each, then read in
    // order: the clusters' fans overlap and come in merge order).
    let mut fan_bits = vec![0u64; input.triangles.len().div_ceil(64)];
    for &t in &merged.fans {
        fan_bits[t as usize / 64] |= 1 << (t % 64);
    }
    let mut fan: Vec<u32> = Vec::with_capacity(merged.fans.len());
    for (i, &word) in fan_bits.iter().enumerate() {
        let mut w = word;
        while w != 0 {
            fan.push((64 * i) as u32 + w.trailing_zeros());
            w &= w - 1;
        }
    }
    for &t in &fan {
        let cs = input.triangles[t as usize].map(|v| cluster[v as usize]);
        for k in 0..3 {
            let (a, b) = (cs[k], cs[(k + 1) % 3]);
            if a != NO_CLUSTER && b != NO_CLUSTER && a != b {
                let (ga, gb) = (find(&mut group, a), find(&mut group, b));
                if ga != gb {
                    group[ga.max(gb) as usize] = ga.min(gb);
                }
            }
        }
    }
    let mut group_touched = vec![false; n];
    for i in 0..n {
        if touched[i] {
            let g = find(&mut group, i as u32);
            group_touched[g as usize] = true;
        }
    }
    let restore: Vec<bool> = (0..n)
        .map(|i| !group_touched[find(&mut group, i as u32) as usize])
        .collect();
    let clusters = restore.iter().filter(|&&r| r).count();
    let mut members = Vec::new();
    let mut still_welded = 0;
    for &v in clustered {
        let r = rep[v as usize];
        if r != v {
            if restore[cluster[v as usize] as usize] {
                members.push((v, r));
            } else {
                still_welded += 1;
            }
        }
    }
    if clusters == 0 {
        return Restored {
            clusters,
            still_welded,
            members,
        };
    }
    let mut restored_bits = vec![0u64; no.div_ceil(64)];
    for (i, &r) in roots.iter().enumerate() {
        if restore[i] {
            restored_bits[r as usize / 64] |= 1 << (r % 64);
        }
    }
    // The map after the restoration: restored vertices are themselves again.
    let map = |v: u32| {
        let c = cluster[v as usize];
        if c != NO_CLUSTER && restore[c as usize] {
            v
        } else {
            rep[v as usize]
        }
    };
    let degenerate = |t: [u32; 3]| t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
    // Input triangles the welding removed that come back, in input order (all of them touch
    // a clustered vertex).
    let back: Vec<u32> = fan
        .iter()
        .copied()
        .filter(|&t| {
            let tri = input.triangles[t as usize];
            degenerate(tri.map(|x| rep[x as usize])) && !degenerate(tri.map(map))
        })
        .collect();
    // The triangles around restored kept vertices become the input's again...
    for &i in around_roots {
        let i = i as usize;
        if touches(&restored_bits, &out.triangles[i]) {
            out.triangles[i] = input.triangles[parents[i].index()].map(map);
        }
    }
    // ...and each triangle coming back goes before the first output triangle (after the
    // one before it) of a later parent, so an output without any other change is the input
    // in its order. Where each goes, by one read of the parents; then the output moves up
    // segment by segment from the end, in place (a fresh copy of a million-triangle output
    // cost more in page faults than the moves).
    let n = out.triangles.len();
    let mut at = Vec::with_capacity(back.len());
    let mut i = 0;
    for &t in &back {
        while i < n && parents[i].index() <= t as usize {
            i += 1;
        }
        at.push(i);
    }
    out.triangles.resize(n + back.len(), [0; 3]);
    parents.resize(n + back.len(), FaceId(0));
    let mut end = n;
    for (j, (&t, &pos)) in back.iter().zip(&at).enumerate().rev() {
        out.triangles.copy_within(pos..end, pos + j + 1);
        parents.copy_within(pos..end, pos + j + 1);
        out.triangles[pos + j] = input.triangles[t as usize].map(map);
        parents[pos + j] = FaceId(t);
        end = pos;
    }
    Restored {
        clusters,
        still_welded,
        members,
    }
}

/// No cluster.
const NO_CLUSTER: u32 = u32::MAX;

/// The cosine of the largest angle by which merging (per `rep`) turns the normal of a
/// triangle of `around` that keeps three distinct vertices (1 when none turns); `before`
/// holds each one's unnormalised normal before the merge and its squared length.
fn smallest_turn_cosine(
    mesh: &Mesh,
    rep: &[u32],
    around: &[u32],
    before: &[(glam::DVec3, f64)],
) -> f64 {
    let mut worst: f64 = 1.0;
    for (&t, &(n0, l0)) in around.iter().zip(before) {
        let tri = mesh.triangles[t as usize];
        let after = tri.map(|v| rep[v as usize]);
        if after == tri || after[0] == after[1] || after[1] == after[2] || after[2] == after[0] {
            continue;
        }
        let [p0, p1, p2] = after.map(|v| mesh.positions[v as usize]);
        let n1 = (p1 - p0).cross(p2 - p0);
        let l1 = n1.length_squared();
        if l0 > 0.0 && l1 > 0.0 {
            worst = worst.min((n0.dot(n1) / (l0 * l1).sqrt()).clamp(-1.0, 1.0));
        }
    }
    worst
}

/// Whether merging (per `rep`) leaves the triangles `around` (every live triangle touching
/// the cluster now represented by `root`) an oriented manifold patch: no directed edge or
/// triangle twice, and the triangles around `root` one closed fan. Only these triangles
/// change, and only their edges with `root` are new, so this is the whole check. A changed
/// triangle is a new triangle of the output, so none may have an angle under `min_angle`
/// (radians), the sliver pass's rule. `edges`, `faces` and `fan` are scratch vectors.
#[allow(clippy::type_complexity)] // three scratch vectors, named where they are unpacked
fn merge_keeps_manifold(
    mesh: &Mesh,
    rep: &[u32],
    around: &[u32],
    root: u32,
    min_angle: f64,
    (edges, faces, fan): (
        &mut Vec<(u32, u32)>,
        &mut Vec<[u32; 3]>,
        &mut Vec<(u32, u32)>,
    ),
) -> bool {
    // A few dozen triangles: sorted vectors, no hashing.
    edges.clear();
    faces.clear();
    // Around `root`: the edge opposite it in each triangle, as `from -> to`.
    fan.clear();
    for &t in around {
        let tri = mesh.triangles[t as usize].map(|v| rep[v as usize]);
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] {
            continue;
        }
        if tri != mesh.triangles[t as usize]
            && crate::edge_sharpener::min_angle(&tri.map(|v| mesh.positions[v as usize]))
                < min_angle
        {
            return false;
        }
        edges.extend((0..3).map(|k| (tri[k], tri[(k + 1) % 3])));
        let mut key = tri;
        key.sort_unstable();
        faces.push(key);
        if let Some(k) = tri.iter().position(|&v| v == root) {
            fan.push((tri[(k + 1) % 3], tri[(k + 2) % 3]));
        }
    }
    edges.sort_unstable();
    faces.sort_unstable();
    if edges.windows(2).any(|w| w[0] == w[1]) || faces.windows(2).any(|w| w[0] == w[1]) {
        return false;
    }
    // One closed cycle: every `from` once, and following the links from any edge comes back
    // to it after visiting them all.
    if fan.len() < 3 {
        return false;
    }
    fan.sort_unstable();
    if fan.windows(2).any(|w| w[0].0 == w[1].0) {
        return false;
    }
    let start = fan[0].0;
    let mut v = start;
    for step in 0..fan.len() {
        match fan.binary_search_by_key(&v, |e| e.0) {
            Ok(i) => v = fan[i].1,
            Err(_) => return false,
        }
        if v == start {
            return step + 1 == fan.len();
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A bipyramid (apexes 0 and 1, equator 2..8) whose top apex is split into two
    /// vertices `0` and `8` a millionth of an edge apart, joined by two zero-area triangles:
    /// the shape of a marching-cubes cluster. Returns the mesh and the first sliver.
    fn split_bipyramid() -> (Mesh, u32) {
        let mut positions = vec![DVec3::Z, -DVec3::Z];
        for i in 0..6 {
            let a = i as f64 * std::f64::consts::TAU / 6.0;
            positions.push(DVec3::new(a.cos(), a.sin(), 0.0));
        }
        positions.push(DVec3::new(1e-6, 0.0, 1.0));
        let e = |i: u32| 2 + i % 6;
        let (t, t2) = (0u32, 8u32);
        let mut triangles = Vec::new();
        for i in 0..6 {
            triangles.push([1, e(i + 1), e(i)]);
        }
        for i in 0..3 {
            triangles.push([t, e(i), e(i + 1)]);
        }
        for i in 3..6 {
            triangles.push([t2, e(i), e(i + 1)]);
        }
        let sliver = triangles.len() as u32;
        triangles.push([t, e(3), t2]);
        triangles.push([t2, e(0), t]);
        (Mesh::new(positions, triangles), sliver)
    }

    /// [`weld_clusters`] with fresh scratch, the sliver threshold in degrees.
    fn weld(mesh: &Mesh, table: &CornerTable, min_angle_degrees: f64) -> Option<Welded> {
        let scratch = &mut WeldScratch::default();
        let radians = min_angle_degrees.to_radians();
        weld_clusters(
            mesh,
            table,
            radians,
            scratch,
            &mut whet_mesh::Scratch::new(),
        )
    }

    /// Vertices merged into another.
    fn merged(w: &Welded) -> usize {
        w.rep
            .iter()
            .enumerate()
            .filter(|&(v, &r)| r as usize != v)
            .count()
    }

    #[test]
    fn a_cluster_welds_into_one_of_its_vertices() {
        let (mesh, _) = split_bipyramid();
        let table = CornerTable::new(&mesh).unwrap();
        let w = weld(&mesh, &table, 1.0).unwrap();
        assert_eq!(merged(&w), 1);
        // The two slivers are gone; every other triangle is kept, with one apex for both.
        assert_eq!(w.mesh.triangles.len(), mesh.triangles.len() - 2);
        assert_eq!(w.input_triangle, (0..12).collect::<Vec<u32>>());
        let uses = |v: u32| w.mesh.triangles.iter().filter(|t| t.contains(&v)).count();
        let (kept, gone) = if uses(8) == 0 { (0, 8) } else { (8, 0) };
        assert_eq!((uses(kept), uses(gone)), (6, 0));
        assert_eq!(w.mesh.triangles[9], [kept, 5, 6]);
        // Positions untouched: the merged vertex keeps its index and place, used by no
        // triangle.
        assert_eq!(w.mesh.positions, mesh.positions);
        CornerTable::new(&w.mesh).unwrap();
    }

    /// A marching-cubes sampling of the synth cube turned off the grid axes (clusters on
    /// its faces and at its chamfers), its table and its welding.
    fn welded_cube() -> (Mesh, CornerTable, Welded) {
        use whet_synth::{marching_cubes, Shape, ShapeKind, ShapeParams};
        let rotation = glam::DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.5);
        let shape = Shape::new(
            ShapeKind::Cube,
            &ShapeParams::default().with_rotation(rotation),
        )
        .unwrap();
        let mesh = marching_cubes(&shape, 40).unwrap();
        let table = CornerTable::new(&mesh).unwrap();
        let w = weld(&mesh, &table, 1.0).unwrap();
        (mesh, table, w)
    }

    #[test]
    fn the_welded_table_from_the_input_table_is_the_table_built_afresh() {
        let (mesh, _) = split_bipyramid();
        let table = CornerTable::new(&mesh).unwrap();
        let mut w = weld(&mesh, &table, 1.0).unwrap();
        assert_eq!(
            welded_table(&mut w, &mut whet_mesh::Scratch::new()),
            Some(CornerTable::new(&w.mesh).unwrap())
        );
        // Its arrays are taken: a second call says so.
        assert_eq!(welded_table(&mut w, &mut whet_mesh::Scratch::new()), None);
        let (_, _, mut w) = welded_cube();
        assert!(merged(&w) > 10, "{}", merged(&w));
        assert_eq!(
            welded_table(&mut w, &mut whet_mesh::Scratch::new()),
            Some(CornerTable::new(&w.mesh).unwrap())
        );
    }

    #[test]
    fn the_patched_angle_sum_is_the_inputs() {
        // The sum and count of the normal angles of the interior edges, as the smooth pass
        // adds them, over a whole mesh.
        fn sums(mesh: &Mesh, table: &CornerTable) -> (f64, usize) {
            let normals = mesh.face_normals();
            let (mut sum, mut count) = (0.0, 0);
            for (c, &o) in table.opposites().iter().enumerate() {
                let (n1, n2) = (normals[c / 3], normals.get(o as usize / 3));
                if let Some(&n2) = n2 {
                    if (o as usize) > c && n1 != DVec3::ZERO && n2 != DVec3::ZERO {
                        sum += crate::edge_sharpener::normal_angle(n1, n2);
                        count += 1;
                    }
                }
            }
            (sum, count)
        }
        let (mesh, table, mut w) = welded_cube();
        let wt = welded_table(&mut w, &mut whet_mesh::Scratch::new()).unwrap();
        let (ws, wc) = sums(&w.mesh, &wt);
        // The welded edges beside no changed triangle, as the smooth pass adds them.
        let changed = |t: usize| w.welded_changed[t / 64] >> (t % 64) & 1 != 0;
        let normals = w.mesh.face_normals();
        let (mut kept, mut kc) = (0.0, 0);
        for (c, &o) in wt.opposites().iter().enumerate() {
            let (t, u) = (c / 3, o as usize / 3);
            if o != u32::MAX && (o as usize) > c && !changed(t) && !changed(u) {
                kept += crate::edge_sharpener::normal_angle(normals[t], normals[u]);
                kc += 1;
            }
        }
        assert!(kc < wc, "welding changed no triangle");
        let (added, ac) = w.input_edges;
        let (is, ic) = sums(&mesh, &table);
        assert_eq!(kc + ac, ic);
        // Welding changes the sum (else this test would show nothing)...
        assert!((ws - is).abs() > 1e-6, "{ws} {is}");
        // ...and the patch restores it up to the order of the additions.
        assert!((kept + added - is).abs() < 1e-9 * is, "{kept} {added} {is}");
    }

    /// The triangles of `out` holding a kept vertex, as the run's output pass lists them.
    fn around_roots(w: &Welded, out: &Mesh) -> Vec<u32> {
        let roots = out.triangles.iter().enumerate();
        let roots = roots.filter(|(_, t)| t.iter().any(|&v| w.is_root(v)));
        roots.map(|(i, _)| i as u32).collect()
    }

    #[test]
    fn untouched_clusters_come_back_as_they_were() {
        let (mesh, _, mut w) = welded_cube();
        let wt = welded_table(&mut w, &mut whet_mesh::Scratch::new()).unwrap();
        // The triangles welding kept around a cluster are its kept vertex's fan in the
        // welded table (the count the restoration expects around it).
        assert!(w.clusters.len() > 1);
        for c in 0..w.clusters.len() {
            let root = w.clusters.members(c)[0];
            let kept = w.clusters.fan(c).iter();
            let kept = kept.filter(|&&t| w.welded_index[t as usize] != u32::MAX);
            assert_eq!(kept.count(), wt.vertex_corners(VertexId(root)).count());
        }
        // A run that changed nothing: everything comes back, in the input's order.
        let mut out = w.mesh.clone();
        let mut parents: Vec<FaceId> = w.input_triangle.iter().map(|&t| FaceId(t)).collect();
        let roots = around_roots(&w, &out);
        let r = restore_untouched(&mesh, &w, &mut out, &mut parents, &roots);
        assert_eq!(r.still_welded, 0);
        assert_eq!(r.members.len(), merged(&w));
        assert_eq!(out.triangles, mesh.triangles);
        assert_eq!(
            parents,
            (0..mesh.triangles.len() as u32)
                .map(FaceId)
                .collect::<Vec<_>>()
        );
        // A kept vertex that moved keeps its cluster (and those sharing a triangle with it)
        // welded; the others come back, and the result is a valid manifold.
        let (root, _) = w
            .rep
            .iter()
            .enumerate()
            .find(|&(v, &r)| r as usize != v)
            .map(|(v, &r)| (r, v))
            .unwrap();
        let mut out = w.mesh.clone();
        out.positions[root as usize] += DVec3::splat(1e-3);
        let mut parents: Vec<FaceId> = w.input_triangle.iter().map(|&t| FaceId(t)).collect();
        let roots = around_roots(&w, &out);
        let r = restore_untouched(&mesh, &w, &mut out, &mut parents, &roots);
        assert!(
            r.still_welded >= 1 && r.still_welded < merged(&w),
            "{}",
            r.still_welded
        );
        assert_eq!(r.still_welded + r.members.len(), merged(&w));
        let mut used = vec![false; mesh.positions.len()];
        for &v in out.triangles.iter().flatten() {
            used[v as usize] = true;
        }
        // The moved vertex's cluster stays welded (its members unused); every member put back
        // is used again.
        assert!(
            (0..mesh.positions.len()).any(|v| w.rep[v] == root && v != root as usize && !used[v])
        );
        assert!(r
            .members
            .iter()
            .all(|&(m, k)| used[m as usize] && k != root));
        CornerTable::new(&out).unwrap();
        assert_eq!(out.triangles.len(), parents.len());
    }

    #[test]
    fn clusters_that_would_break_the_manifold_or_make_slivers_stay() {
        let (mesh, _) = split_bipyramid();
        let table = CornerTable::new(&mesh).unwrap();
        // Vertices far apart are no cluster.
        let mut far = mesh.clone();
        far.positions[8] = DVec3::new(0.2, 0.0, 1.0);
        let far_table = CornerTable::new(&far).unwrap();
        assert!(weld(&far, &far_table, 1.0).is_none());
        // A minimum angle no remapped triangle meets refuses the merge.
        assert!(weld(&mesh, &table, 50.0).is_none());
        // A tetrahedron with two coincident vertices: merging them leaves a two-triangle
        // pillow, which is refused.
        let tet = Mesh::new(
            vec![DVec3::ZERO, DVec3::new(1e-6, 0.0, 0.0), DVec3::Y, DVec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        );
        let tet_table = CornerTable::new(&tet).unwrap();
        assert!(weld(&tet, &tet_table, 1.0).is_none());
    }

    #[test]
    fn boundary_clusters_are_left_alone() {
        let (mut mesh, _) = split_bipyramid();
        // Open the bottom: the equator becomes a boundary, but the apex cluster is inside.
        mesh.triangles.drain(0..6);
        let table = CornerTable::new(&mesh).unwrap();
        let w = weld(&mesh, &table, 1.0).unwrap();
        assert_eq!(merged(&w), 1);
        // A cluster on the boundary: split an equator vertex instead.
        let (mut open, _) = split_bipyramid();
        open.triangles.drain(0..6);
        open.triangles.retain(|t| !t.contains(&2));
        let table = CornerTable::new(&open).unwrap();
        assert!(weld(&open, &table, 1.0).is_none());
    }
}
