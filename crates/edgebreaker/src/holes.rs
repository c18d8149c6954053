//! Closing holes with dummy vertices (`../shared/docs/algorithms.md` 2.5, method A, as in the
//! Georgia Tech Edgebreaker code): every boundary loop gets one new vertex and a fan of
//! triangles to its edges, so the traversal only ever sees closed surfaces. The dummy
//! vertices' positions in the traversal order are transmitted (a few bits per hole) and the
//! decoder deletes them with their fans.
//!
//! Requires a vertex-manifold mesh (two holes touching at a vertex would make the loop walk
//! ambiguous); `Mesh::make_manifold` guarantees it.

use whet_mesh::{CornerId, CornerTable, MeshError};

/// Adds one dummy vertex per boundary loop of `table` (built from `triangles`) and returns the
/// closed triangle list and the number of dummy vertices (numbered from `vertex_count` on).
pub fn close_holes(
    triangles: &[[u32; 3]],
    table: &CornerTable,
    vertex_count: usize,
) -> Result<(Vec<[u32; 3]>, usize), MeshError> {
    // Boundary half-edge x -> y faces boundary corner c: x = v(next c), y = v(prev c).
    let mut out_edge = vec![u32::MAX; vertex_count];
    let mut any = false;
    for c in table.corners() {
        if table.is_boundary_corner(c) {
            any = true;
            let x = table.vertex(table.next(c));
            out_edge[x.index()] = c.0;
        }
    }
    if !any {
        return Ok((triangles.to_vec(), 0));
    }
    let mut closed = triangles.to_vec();
    let mut done = vec![false; table.corner_count()];
    let mut dummies = 0usize;
    for c in table.corners() {
        if !table.is_boundary_corner(c) || done[c.index()] {
            continue;
        }
        let d = (vertex_count + dummies) as u32;
        dummies += 1;
        let mut e = c;
        loop {
            done[e.index()] = true;
            let x = table.vertex(table.next(e)).0;
            let y = table.vertex(table.prev(e)).0;
            closed.push([d, y, x]);
            let following = out_edge[y as usize];
            if following == u32::MAX {
                // Cannot happen in a vertex-manifold mesh: every boundary vertex starts one
                // boundary edge.
                return Err(MeshError::NonManifoldVertex { vertex: y, fans: 2 });
            }
            e = CornerId(following);
            if done[e.index()] {
                break;
            }
        }
    }
    Ok((closed, dummies))
}
