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
//! Only the clusters whose slivers keep a chamfer edge from splitting are welded (the
//! engine's first detection lists them), so smooth regions and meshes without chamfers
//! (already sharp ones) are never touched. A cluster holds the vertices joined to such a
//! sliver's shortest edge by edges shorter than [`CLUSTER_EDGE`] mean edge lengths. Its
//! vertices merge into the one whose position turns the remapped triangles least; the others
//! stay at their indices with no triangle using them (the output promise "input vertex `i` is
//! output vertex `i`" holds), and the triangles that had two of them disappear. A cluster is
//! left alone when it touches the boundary, when the merge would break the manifold around
//! it, or when a changed triangle would be a sliver.

use whet_mesh::{CornerTable, Mesh, VertexId};

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
    /// Vertices merged into another.
    pub merged: usize,
}

/// Welds the clusters of `mesh` (whose table is `table`) seeded by the input triangles
/// `slivers` (each one's shortest edge, if under [`CLUSTER_EDGE`] mean edges); `min_angle`
/// (radians) is the sliver threshold no changed triangle may fall under. `None` when no
/// cluster could be welded.
pub(crate) fn weld_clusters(
    mesh: &Mesh,
    table: &CornerTable,
    slivers: &[u32],
    min_angle: f64,
) -> Option<Welded> {
    let nv = mesh.positions.len();
    let limit = CLUSTER_EDGE * table.mean_edge_length(&mesh.positions);
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
    let mut alive: Vec<bool> = Vec::new();
    let mut in_cluster: Vec<bool> = Vec::new();
    let mut merged = 0usize;
    let mut cluster: Vec<u32> = Vec::new();
    let mut around: Vec<u32> = Vec::new();
    for &t in slivers {
        let tri = mesh.triangles[t as usize];
        let p = mesh.triangle_positions(t as usize);
        // The sliver's shortest edge, opposite its smallest angle.
        let (k, lengths) = crate::edge_sharpener::smallest_angle_corner(&p);
        let (a, b, d) = (tri[(k + 1) % 3], tri[(k + 2) % 3], lengths[k]);
        if d >= limit2 {
            continue;
        }
        if rep.is_empty() {
            rep = (0..nv as u32).collect();
            alive = vec![true; mesh.triangles.len()];
            in_cluster = vec![false; nv];
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
        around.clear();
        for &v in &cluster {
            around.extend(table.vertex_corners(VertexId(v)).map(|c| c.0 / 3));
        }
        around.sort_unstable();
        around.dedup();
        around.retain(|&t| alive[t as usize]);
        // The member whose position turns the remapped triangles least.
        let mut best = (f64::INFINITY, a);
        for &r in &cluster {
            for &v in &cluster {
                rep[v as usize] = r;
            }
            let turn = largest_turn(mesh, &rep, &around);
            if turn < best.0 || (turn == best.0 && r < best.1) {
                best = (turn, r);
            }
        }
        let root = best.1;
        for &v in &cluster {
            rep[v as usize] = root;
        }
        if merge_keeps_manifold(mesh, &rep, &around, root, min_angle) {
            for &t in &around {
                let [x, y, z] = mesh.triangles[t as usize].map(|v| rep[v as usize]);
                if x == y || y == z || z == x {
                    alive[t as usize] = false;
                }
            }
            merged += cluster.len() - 1;
        } else {
            for &v in &cluster {
                rep[v as usize] = v;
            }
        }
    }
    if merged == 0 {
        return None;
    }
    let mut triangles = Vec::with_capacity(mesh.triangles.len());
    let mut input_triangle = Vec::with_capacity(mesh.triangles.len());
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if alive[t] {
            triangles.push(tri.map(|v| rep[v as usize]));
            input_triangle.push(t as u32);
        }
    }
    Some(Welded {
        mesh: Mesh::new(mesh.positions.clone(), triangles),
        input_triangle,
        merged,
    })
}

/// The largest angle by which merging (per `rep`) turns the normal of a triangle of `around`
/// that keeps three distinct vertices.
fn largest_turn(mesh: &Mesh, rep: &[u32], around: &[u32]) -> f64 {
    let mut worst: f64 = 0.0;
    for &t in around {
        let before = mesh.triangles[t as usize];
        let after = before.map(|v| rep[v as usize]);
        if after == before || after[0] == after[1] || after[1] == after[2] || after[2] == after[0] {
            continue;
        }
        let normal = |tri: [u32; 3]| {
            let [p0, p1, p2] = tri.map(|v| mesh.positions[v as usize]);
            (p1 - p0).cross(p2 - p0)
        };
        let (n0, n1) = (normal(before), normal(after));
        if n0.length_squared() > 0.0 && n1.length_squared() > 0.0 {
            worst = worst.max(n0.angle_between(n1));
        }
    }
    worst
}

/// Whether merging (per `rep`) leaves the triangles `around` (every live triangle touching
/// the cluster now represented by `root`) an oriented manifold patch: no directed edge or
/// triangle twice, and the triangles around `root` one closed fan. Only these triangles
/// change, and only their edges with `root` are new, so this is the whole check. A changed
/// triangle is a new triangle of the output, so none may have an angle under `min_angle`
/// (radians), the sliver pass's rule.
fn merge_keeps_manifold(
    mesh: &Mesh,
    rep: &[u32],
    around: &[u32],
    root: u32,
    min_angle: f64,
) -> bool {
    // A few dozen triangles: sorted vectors, no hashing.
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(3 * around.len());
    let mut faces: Vec<[u32; 3]> = Vec::with_capacity(around.len());
    // Around `root`: the edge opposite it in each triangle, as `from -> to`.
    let mut fan: Vec<(u32, u32)> = Vec::new();
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

    /// Every triangle as a seed (the engine passes only the slivers that block a chamfer).
    fn all(mesh: &Mesh) -> Vec<u32> {
        (0..mesh.triangles.len() as u32).collect()
    }

    #[test]
    fn a_cluster_welds_into_one_of_its_vertices() {
        let (mesh, _) = split_bipyramid();
        let table = CornerTable::new(&mesh).unwrap();
        let w = weld_clusters(&mesh, &table, &all(&mesh), 1f64.to_radians()).unwrap();
        assert_eq!(w.merged, 1);
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

    #[test]
    fn clusters_that_would_break_the_manifold_or_make_slivers_stay() {
        let (mesh, _) = split_bipyramid();
        let table = CornerTable::new(&mesh).unwrap();
        // Vertices far apart are no cluster.
        let mut far = mesh.clone();
        far.positions[8] = DVec3::new(0.2, 0.0, 1.0);
        let far_table = CornerTable::new(&far).unwrap();
        assert!(weld_clusters(&far, &far_table, &all(&far), 1f64.to_radians()).is_none());
        // A minimum angle no remapped triangle meets refuses the merge.
        assert!(weld_clusters(&mesh, &table, &all(&mesh), 50f64.to_radians()).is_none());
        // A tetrahedron with two coincident vertices: merging them leaves a two-triangle
        // pillow, which is refused.
        let tet = Mesh::new(
            vec![DVec3::ZERO, DVec3::new(1e-6, 0.0, 0.0), DVec3::Y, DVec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        );
        let tet_table = CornerTable::new(&tet).unwrap();
        assert!(weld_clusters(&tet, &tet_table, &all(&tet), 1f64.to_radians()).is_none());
    }

    #[test]
    fn boundary_clusters_are_left_alone() {
        let (mut mesh, _) = split_bipyramid();
        // Open the bottom: the equator becomes a boundary, but the apex cluster is inside.
        mesh.triangles.drain(0..6);
        let table = CornerTable::new(&mesh).unwrap();
        let w = weld_clusters(&mesh, &table, &all(&mesh), 1f64.to_radians()).unwrap();
        assert_eq!(w.merged, 1);
        // A cluster on the boundary: split an equator vertex instead.
        let (mut open, _) = split_bipyramid();
        open.triangles.drain(0..6);
        open.triangles.retain(|t| !t.contains(&2));
        let table = CornerTable::new(&open).unwrap();
        assert!(weld_clusters(&open, &table, &all(&open), 1f64.to_radians()).is_none());
    }
}
