//! Originals with boundaries (`docs/swing.md`, "Boundaries"): SwingWrapper grows a closed
//! front, so each boundary loop of `M` is first capped ("filler": a dome over the loop's
//! centroid, or a flat fan for a hole less than about 2 L wide), the closed surface is retiled like any other, and the retiled
//! triangles lying over filler are then flagged for deletion. The stream carries the closed
//! retiled mesh (swing geometry, bit exact) and one flag per triangle; the decoder deletes the
//! flagged triangles. The hole of `M'` thus follows `M`'s border to within about `L`.
//!
//! Invariant: the capped mesh is closed when `M` is an oriented manifold whose boundary
//! vertices each start one boundary edge (what `Mesh::make_manifold` guarantees).

use whet_mesh::{DVec3, Mesh};

/// `mesh` with every boundary loop capped, and for each triangle of the result whether it
/// is filler. Returns `None` when `mesh` is closed.
pub(crate) fn cap_holes(mesh: &Mesh, edge_length: f64) -> Option<(Mesh, Vec<bool>)> {
    // Boundary edge x -> y: its reverse is absent. Chain by start vertex.
    let mut next: std::collections::HashMap<u32, Vec<u32>> = Default::default();
    for (x, y) in boundary_edges(mesh) {
        next.entry(x).or_default().push(y);
    }
    if next.is_empty() {
        return None;
    }
    let mut positions = mesh.positions.clone();
    let mut triangles = mesh.triangles.clone();
    let mut filler = vec![false; triangles.len()];
    let mut starts: Vec<u32> = next.keys().copied().collect();
    starts.sort_unstable();
    for s in starts {
        while let Some(first) = next.get_mut(&s).and_then(|v| v.pop()) {
            // One loop: s -> first -> ... -> s.
            let mut lp = vec![s];
            let mut at = first;
            let mut guard = 0usize;
            while at != s && guard <= mesh.positions.len() {
                lp.push(at);
                match next.get_mut(&at).and_then(|v| v.pop()) {
                    Some(n) => at = n,
                    None => break,
                }
                guard += 1;
            }
            let centroid = lp
                .iter()
                .map(|&v| mesh.positions[v as usize])
                .fold(DVec3::ZERO, |a, p| a + p)
                / lp.len() as f64;
            // The filler's outward side: the fan (c, y, x) over boundary edges x -> y.
            let mut area = DVec3::ZERO;
            for k in 0..lp.len() {
                let x = mesh.positions[lp[k] as usize];
                let y = mesh.positions[lp[(k + 1) % lp.len()] as usize];
                area += (y - centroid).cross(x - centroid);
            }
            // A dome over the loop: rings pulled towards the centroid along a quarter circle
            // (the dome leaves the border at a right angle, so the rim the front must wrap
            // is no sharper than 90 degrees, and it ends smoothly at its apex), its height the
            // loop's radius along the loop's vector area. A flat cap would lie on a flat sheet
            // itself; a single cone would give the front a sharp apex to wrap.
            // The radius of the disk of the hole's (projected) area: a long narrow slit
            // gets a low cap, not a tall fin. (`area` sums cross products: twice the area.)
            let radius = (area.length() / std::f64::consts::TAU).sqrt();
            let n = lp.len();
            if radius < 2.0 * edge_length {
                // A hole not much wider than L: a flat fan, which the retiling covers over.
                let apex = positions.len() as u32;
                positions.push(centroid);
                for k in 0..n {
                    triangles.push([apex, lp[(k + 1) % n], lp[k]]);
                    filler.push(true);
                }
                continue;
            }
            let up = area.normalize_or_zero() * radius;
            const RINGS: usize = 4;
            let mut outer: Vec<u32> = lp.clone();
            for ring in 1..=RINGS {
                let s = ring as f64 / (RINGS + 1) as f64 * std::f64::consts::FRAC_PI_2;
                // Encoder-side shape only (never in the stream): std trigonometry is fine.
                let (c, h) = (s.cos(), s.sin());
                let inner: Vec<u32> = lp
                    .iter()
                    .map(|&v| {
                        let d = mesh.positions[v as usize] - centroid;
                        positions.push(centroid + d * c + up * h);
                        (positions.len() - 1) as u32
                    })
                    .collect();
                for k in 0..n {
                    let k1 = (k + 1) % n;
                    triangles.push([outer[k1], outer[k], inner[k]]);
                    triangles.push([outer[k1], inner[k], inner[k1]]);
                    filler.push(true);
                    filler.push(true);
                }
                outer = inner;
            }
            let apex = positions.len() as u32;
            positions.push(centroid + up);
            for k in 0..n {
                triangles.push([apex, outer[(k + 1) % n], outer[k]]);
                filler.push(true);
            }
        }
    }
    Some((Mesh::new(positions, triangles), filler))
}

/// The directed edges `x -> y` of `mesh`'s triangles whose reverse `y -> x` no triangle has
/// (the boundary edges), in triangle order. The out-edges of every vertex are gathered in
/// one array (a counting sort by start vertex), so each reverse is looked up among a few
/// entries: on a closed original of a million triangles this is a fraction of the time a
/// hash set of its edges took. Triangles with a vertex out of range are left out.
fn boundary_edges(mesh: &Mesh) -> Vec<(u32, u32)> {
    let nv = mesh.positions.len();
    let valid = |t: &&[u32; 3]| t.iter().all(|&v| (v as usize) < nv);
    let mut start = vec![0u32; nv + 1];
    for t in mesh.triangles.iter().filter(valid) {
        for &v in t {
            start[v as usize + 1] += 1;
        }
    }
    for v in 0..nv {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut out = vec![0u32; start[nv] as usize];
    for t in mesh.triangles.iter().filter(valid) {
        for i in 0..3 {
            let slot = &mut fill[t[i] as usize];
            out[*slot as usize] = t[(i + 1) % 3];
            *slot += 1;
        }
    }
    let out_of = |v: u32| &out[start[v as usize] as usize..start[v as usize + 1] as usize];
    let mut boundary = Vec::new();
    for t in mesh.triangles.iter().filter(valid) {
        for i in 0..3 {
            let (x, y) = (t[i], t[(i + 1) % 3]);
            if !out_of(y).contains(&x) {
                boundary.push((x, y));
            }
        }
    }
    boundary
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_capped_grid_is_closed_and_its_filler_is_marked() {
        let g = whet_testkit_grid();
        let (closed, filler) = cap_holes(&g, 0.1).unwrap();
        let r = closed.topology_report();
        assert_eq!(r.boundary_edges, 0, "{r:?}");
        assert_eq!(r.genus, Some(0));
        // 4 rings of 2 triangles per boundary edge, then the apex fan.
        assert_eq!(filler.iter().filter(|&&f| f).count(), 16 * 9);
        assert!(!filler[..g.triangles.len()].iter().any(|&f| f));
        assert!(cap_holes(&closed, 0.1).is_none());
    }

    #[test]
    fn boundary_edges_are_the_directed_edges_without_a_reverse() {
        // The grid, a torus grid with a hole cut out, and an icosphere (closed); checked
        // against a set of all directed edges.
        let mut holed = whet_testkit::meshes::torus(12, 8);
        holed.triangles.retain(|t| t.iter().all(|&v| v % 7 != 3));
        for mesh in [
            whet_testkit_grid(),
            holed,
            whet_testkit::meshes::icosphere(2),
        ] {
            let all: std::collections::HashSet<(u32, u32)> = mesh
                .triangles
                .iter()
                .flat_map(|t| (0..3).map(move |i| (t[i], t[(i + 1) % 3])))
                .collect();
            let expected: Vec<(u32, u32)> = mesh
                .triangles
                .iter()
                .flat_map(|t| (0..3).map(move |i| (t[i], t[(i + 1) % 3])))
                .filter(|&(x, y)| !all.contains(&(y, x)))
                .collect();
            assert_eq!(boundary_edges(&mesh), expected);
        }
        assert_eq!(boundary_edges(&whet_testkit_grid()).len(), 16);
    }

    /// A 4 x 4 grid in the xy plane (16 boundary edges).
    fn whet_testkit_grid() -> Mesh {
        let n = 4u32;
        let mut p = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                p.push(DVec3::new(i as f64, j as f64, 0.0));
            }
        }
        let id = |i: u32, j: u32| i * (n + 1) + j;
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        Mesh::new(p, t)
    }
}
