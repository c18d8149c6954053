//! The Bender half of the `sharpen` cargo-fuzz target (`fuzz/`): one level over whatever
//! the sharpener and the projections made of an arbitrary small mesh, as `whet decode
//! --sharpen --bend 1` runs it. Shared with the stable replay test of the target's corpus.

use crate::bend;
use whet_mesh::Mesh;

/// Bends `mesh` (a sharpened mesh: an oriented manifold with finite coordinates, possibly
/// with unused vertices) one level with its sharp edges `sharp_edges` and checks the
/// result: four triangles for each (pillows, two triangles back to back, pass through
/// whole), the old vertices unchanged and first, finite new vertices, an oriented manifold,
/// and sharp edges in range. Panics only on a bug, a refusal included.
pub fn fuzz_bend(mesh: &Mesh, sharp_edges: &[[u32; 2]]) {
    let bent = match bend(mesh, sharp_edges) {
        Ok(b) => b,
        Err(e) => panic!("bend refused a sharpened mesh: {e}"),
    };
    let out = &bent.mesh;
    let n = mesh.positions.len();
    // Four triangles for one, except pillows (two triangles back to back over the same
    // three vertices), which pass through whole.
    assert_eq!(
        out.triangles.len(),
        4 * mesh.triangles.len() - 3 * pillow_triangles(mesh),
        "four triangles for one"
    );
    assert_eq!(
        &out.positions[..n],
        &mesh.positions[..],
        "old vertices moved"
    );
    assert!(
        out.positions.iter().all(|p| p.is_finite()),
        "non-finite vertex"
    );
    let m = out.positions.len() as u32;
    assert!(
        out.triangles.iter().flatten().all(|&v| v < m),
        "index out of range"
    );
    assert!(
        bent.sharp_edges.iter().flatten().all(|&v| v < m),
        "sharp edge out of range"
    );
    let report = out.topology_report();
    assert!(
        report.manifold && report.oriented,
        "not an oriented manifold"
    );
}

/// Triangles that have a twin over the same three vertices (the halves of pillows).
fn pillow_triangles(mesh: &Mesh) -> usize {
    let keys = mesh.sorted_vertex_sets();
    (0..keys.len())
        .filter(|&i| (i > 0 && keys[i - 1] == keys[i]) || keys.get(i + 1) == Some(&keys[i]))
        .count()
}
