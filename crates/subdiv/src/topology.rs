//! The connectivity one subdivision level works on: canonical edges (sorted `[low, high]`
//! pairs, the order of `Mesh::undirected_edges`), the two vertices opposite each edge, the edge
//! opposite each corner, and each vertex's neighbours in counter-clockwise order.
//!
//! ```text
//!              c                 edge (a, b) with a < b; c and d are the vertices
//!             / \                opposite it in its two triangles (d = NONE on a
//!            /   \               boundary). The ring of a vertex lists its neighbours
//!           a-----b              counter-clockwise with the edge to each; at a boundary
//!            \   /               vertex it runs from one boundary edge to the other, so it
//!             \ /                has one more neighbour than triangles.
//!              d
//! ```
//!
//! It is built once per level from the triangles (through whet-mesh's `CornerTable`, which
//! refuses non-manifold or inconsistently oriented input) and never changes afterwards: the
//! sharpness only changes the weights of [`crate::loop_subdivision`], not the connectivity.

use whet_mesh::{edge_key, CornerId, CornerTable, MeshError, VertexId};

/// Marker of a missing vertex or edge.
pub(crate) const NONE: u32 = u32::MAX;

/// Connectivity of one level.
#[derive(Clone, Debug)]
pub(crate) struct Topology {
    pub triangles: Vec<[u32; 3]>,
    pub vertex_count: usize,
    /// Canonical edges `[low, high]`, sorted.
    pub edges: Vec<[u32; 2]>,
    /// The two vertices opposite each edge; the second is `NONE` on a boundary edge.
    pub edge_opposite: Vec<[u32; 2]>,
    /// The edge opposite each corner (corner `3 t + k` sits at `triangles[t][k]`).
    pub corner_edge: Vec<u32>,
    /// CSR offsets of the rings.
    ring_offsets: Vec<u32>,
    /// Ring entries: (neighbour, edge to it), counter-clockwise.
    ring: Vec<(u32, u32)>,
    /// Whether each vertex lies on a boundary.
    pub boundary: Vec<bool>,
}

impl Topology {
    /// Builds the connectivity of an oriented manifold triangle set.
    pub fn new(triangles: Vec<[u32; 3]>, vertex_count: usize) -> Result<Topology, MeshError> {
        let table = CornerTable::from_triangles(&triangles, vertex_count)?;
        let nc = table.corner_count();
        // Edges in first-corner order, then renumbered canonically.
        let mut corner_edge = vec![NONE; nc];
        let mut raw: Vec<([u32; 2], [u32; 2])> = Vec::with_capacity(nc / 2 + 1);
        for c in 0..nc {
            let cid = CornerId(c as u32);
            if let Some(o) = table.opposite(cid) {
                if (o.index()) < c {
                    corner_edge[c] = corner_edge[o.index()];
                    continue;
                }
            }
            let a = table.vertex(table.next(cid)).0;
            let b = table.vertex(table.prev(cid)).0;
            let d = table.opposite(cid).map_or(NONE, |o| table.vertex(o).0);
            corner_edge[c] = raw.len() as u32;
            raw.push(([a.min(b), a.max(b)], [table.vertex(cid).0, d]));
        }
        let mut order: Vec<u32> = (0..raw.len() as u32).collect();
        order.sort_unstable_by_key(|&e| {
            let [a, b] = raw[e as usize].0;
            edge_key(a, b)
        });
        let mut rank = vec![0u32; raw.len()];
        for (new, &old) in order.iter().enumerate() {
            rank[old as usize] = new as u32;
        }
        for ce in &mut corner_edge {
            *ce = rank[*ce as usize];
        }
        let edges: Vec<[u32; 2]> = order.iter().map(|&e| raw[e as usize].0).collect();
        let edge_opposite: Vec<[u32; 2]> = order.iter().map(|&e| raw[e as usize].1).collect();

        let mut ring_offsets = Vec::with_capacity(vertex_count + 1);
        let mut ring = Vec::with_capacity(nc + vertex_count / 8);
        let mut boundary = vec![false; vertex_count];
        ring_offsets.push(0u32);
        for v in 0..vertex_count {
            let vid = VertexId(v as u32);
            let mut last = None;
            for c in table.vertex_corners(vid) {
                ring.push((
                    table.vertex(table.next(c)).0,
                    corner_edge[table.prev(c).index()],
                ));
                last = Some(c);
            }
            if let Some(c) = last {
                if table.is_boundary_vertex(vid) {
                    boundary[v] = true;
                    ring.push((
                        table.vertex(table.prev(c)).0,
                        corner_edge[table.next(c).index()],
                    ));
                }
            }
            ring_offsets.push(ring.len() as u32);
        }
        Ok(Topology {
            triangles,
            vertex_count,
            edges,
            edge_opposite,
            corner_edge,
            ring_offsets,
            ring,
            boundary,
        })
    }

    /// Neighbours of `v` with the edge to each, counter-clockwise.
    #[inline]
    pub fn ring(&self, v: usize) -> &[(u32, u32)] {
        &self.ring[self.ring_offsets[v] as usize..self.ring_offsets[v + 1] as usize]
    }

    /// True for an edge with one triangle.
    #[inline]
    pub fn is_boundary_edge(&self, e: usize) -> bool {
        self.edge_opposite[e][1] == NONE
    }

    /// Index of the canonical edge `{a, b}`, if it exists.
    pub fn find_edge(&self, a: u32, b: u32) -> Option<usize> {
        let key = [a.min(b), a.max(b)];
        self.edges.binary_search(&key).ok()
    }

    /// The connectivity after one 1-to-4 split: old vertices keep their indices, the point on
    /// edge `e` gets `vertex_count + e`. Triangle `t` becomes `4 t .. 4 t + 4` (three corner
    /// triangles in the order of its corners, then the middle one), so every fine triangle
    /// knows its control triangle by integer division.
    pub fn split(&self) -> Result<Topology, MeshError> {
        let nv = self.vertex_count as u64;
        let total = nv + self.edges.len() as u64;
        if total > u32::MAX as u64 - 1 || self.triangles.len() as u64 * 4 > u32::MAX as u64 / 3 {
            return Err(MeshError::TooLarge {
                what: "subdivided mesh",
                count: total as usize,
            });
        }
        let mut tris = Vec::with_capacity(self.triangles.len() * 4);
        for (t, tri) in self.triangles.iter().enumerate() {
            // m[k] is the point on the edge opposite corner k.
            let m = [0, 1, 2].map(|k| nv as u32 + self.corner_edge[3 * t + k]);
            let [a, b, c] = *tri;
            tris.push([a, m[2], m[1]]);
            tris.push([b, m[0], m[2]]);
            tris.push([c, m[1], m[0]]);
            tris.push([m[0], m[1], m[2]]);
        }
        Topology::new(tris, total as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra() -> Vec<[u32; 3]> {
        vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]
    }

    #[test]
    fn tetrahedron_rings_and_edges() {
        let t = Topology::new(tetra(), 4).unwrap();
        assert_eq!(
            t.edges,
            vec![[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]]
        );
        for v in 0..4 {
            assert_eq!(t.ring(v).len(), 3);
            assert!(!t.boundary[v]);
            for &(n, e) in t.ring(v) {
                let [a, b] = t.edges[e as usize];
                assert!((a == v as u32 && b == n) || (b == v as u32 && a == n));
            }
        }
        // Edge (0, 1) lies in triangles [0,2,1] and [0,1,3]: opposite vertices 2 and 3.
        let mut opp = t.edge_opposite[0];
        opp.sort_unstable();
        assert_eq!(opp, [2, 3]);
    }

    #[test]
    fn split_counts_and_boundary_ring() {
        // One triangle: a boundary everywhere.
        let t = Topology::new(vec![[0, 1, 2]], 3).unwrap();
        assert!(t.boundary.iter().all(|&b| b));
        assert_eq!(t.ring(0).len(), 2);
        let s = t.split().unwrap();
        assert_eq!(
            (s.vertex_count, s.triangles.len(), s.edges.len()),
            (6, 4, 9)
        );
        let s2 = Topology::new(tetra(), 4).unwrap().split().unwrap();
        // V' = V + E, E' = 2E + 3T, T' = 4T.
        assert_eq!(
            (s2.vertex_count, s2.edges.len(), s2.triangles.len()),
            (10, 24, 16)
        );
        assert!(s2.boundary.iter().all(|&b| !b));
    }

    #[test]
    fn refuses_non_manifold() {
        let tris = vec![[0, 1, 2], [0, 1, 3], [0, 1, 4]];
        assert!(Topology::new(tris, 5).is_err());
    }
}
