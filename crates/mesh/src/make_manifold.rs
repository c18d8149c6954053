//! Cutting non-manifold input into an oriented manifold, so that nothing downstream has to
//! refuse a mesh a user hands in.
//!
//! Steps, each reported in [`ManifoldRepair`]:
//! 1. drop triangles with out-of-range or repeated indices, and duplicates (same three
//!    vertices, whichever orientation; the first is kept);
//! 2. orient each component consistently by a breadth-first walk over edges with exactly two
//!    triangles, flipping the minority (a non-orientable strip keeps its conflicting edges);
//! 3. pair the triangles of each edge: one triangle traversing it forwards with one
//!    traversing it backwards; every other triangle of the edge is left unpaired there, so the
//!    edge is cut;
//! 4. split every vertex whose corners fall into several fans (joined through paired edges)
//!    into one vertex per fan, duplicating its position.
//!
//! When a cut edge's leftover triangle still touches both ends of the same fans (a fan that
//! closes onto itself through the cut), that triangle is detached at the edge and steps 3-4
//! repeat; the loop is bounded, and its last resort (detaching every offending triangle
//! entirely) always yields a manifold. Zero-area triangles with distinct corners are kept:
//! they are topologically sound, and dropping them would open holes.

use crate::mesh::Mesh;
use crate::topology::{for_each_edge_group, sorted_half_edges, UnionFind};
use std::collections::VecDeque;

/// What [`Mesh::make_manifold`] changed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ManifoldRepair {
    /// Triangles dropped for an out-of-range index.
    pub dropped_out_of_range: usize,
    /// Triangles dropped for using a vertex twice.
    pub dropped_degenerate: usize,
    /// Triangles dropped as duplicates of an earlier one.
    pub dropped_duplicates: usize,
    /// Triangles whose orientation was reversed.
    pub flipped_triangles: usize,
    /// Edges cut because more than two triangles, or two of one direction, met there.
    pub cut_edges: usize,
    /// Vertices added by splitting non-manifold vertices.
    pub added_vertices: usize,
}

impl ManifoldRepair {
    /// True when the mesh was left as it was.
    pub fn is_unchanged(&self) -> bool {
        *self == ManifoldRepair::default()
    }
}

impl std::fmt::Display for ManifoldRepair {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "dropped {} out-of-range, {} degenerate and {} duplicate triangles; flipped {}; cut {} edges; added {} vertices",
            self.dropped_out_of_range,
            self.dropped_degenerate,
            self.dropped_duplicates,
            self.flipped_triangles,
            self.cut_edges,
            self.added_vertices
        )
    }
}

const NONE: u32 = u32::MAX;

impl Mesh {
    /// Cuts non-manifold vertices and edges by duplicating vertices, orients components
    /// consistently and drops degenerate and duplicate triangles; see the module docs. The
    /// result passes [`crate::CornerTable::new`] unless a coordinate is non-finite (which
    /// this does not touch).
    pub fn make_manifold(&mut self) -> ManifoldRepair {
        let mut rep = ManifoldRepair::default();
        self.drop_bad_triangles(&mut rep);
        self.orient_components(&mut rep);
        let mut cut_counted = false;
        for round in 0..8 {
            let offenders = self.split_by_pairing(&mut rep, !cut_counted);
            cut_counted = true;
            if offenders.is_empty() {
                return rep;
            }
            // Detach the offending triangles at their bad edges (round < 7) or entirely.
            for (t, k) in offenders {
                let tri = self.triangles[t as usize];
                let ks: &[usize] = if round < 7 {
                    &[k, (k + 1) % 3]
                } else {
                    &[0, 1, 2]
                };
                for &kk in ks {
                    let p = self.positions[tri[kk] as usize];
                    self.positions.push(p);
                    self.triangles[t as usize][kk] = (self.positions.len() - 1) as u32;
                    rep.added_vertices += 1;
                }
            }
        }
        rep
    }

    fn drop_bad_triangles(&mut self, rep: &mut ManifoldRepair) {
        let nv = self.positions.len();
        let mut keep = vec![true; self.triangles.len()];
        for (t, tri) in self.triangles.iter().enumerate() {
            if tri.iter().any(|&i| i as usize >= nv) {
                keep[t] = false;
                rep.dropped_out_of_range += 1;
            } else if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                keep[t] = false;
                rep.dropped_degenerate += 1;
            }
        }
        let mut sorted: Vec<([u32; 3], u32)> = self
            .triangles
            .iter()
            .enumerate()
            .filter(|(t, _)| keep[*t])
            .map(|(t, tri)| {
                let mut s = *tri;
                s.sort_unstable();
                (s, t as u32)
            })
            .collect();
        sorted.sort_unstable();
        for w in sorted.windows(2) {
            if w[0].0 == w[1].0 {
                keep[w[1].1 as usize] = false;
                rep.dropped_duplicates += 1;
            }
        }
        let mut t = 0;
        self.triangles.retain(|_| {
            t += 1;
            keep[t - 1]
        });
    }

    fn orient_components(&mut self, rep: &mut ManifoldRepair) {
        let nt = self.triangles.len();
        let usable = vec![true; nt];
        let half = sorted_half_edges(&self.triangles, &usable);
        // Neighbours across edges with exactly two triangles: (other triangle, same_direction).
        let mut adj_off = vec![0u32; nt + 1];
        let mut pairs: Vec<(u32, u32, bool)> = Vec::new();
        for_each_edge_group(&half, |g| {
            if g.len() == 2 {
                pairs.push((g[0].triangle, g[1].triangle, g[0].from == g[1].from));
            }
        });
        for &(a, b, _) in &pairs {
            adj_off[a as usize + 1] += 1;
            adj_off[b as usize + 1] += 1;
        }
        for t in 0..nt {
            adj_off[t + 1] += adj_off[t];
        }
        let mut fill = adj_off.clone();
        let mut adj = vec![(0u32, false); adj_off[nt] as usize];
        for &(a, b, same) in &pairs {
            adj[fill[a as usize] as usize] = (b, same);
            fill[a as usize] += 1;
            adj[fill[b as usize] as usize] = (a, same);
            fill[b as usize] += 1;
        }
        // flip[t]: 0 = keep, 1 = flip, NONE = unvisited.
        let mut flip = vec![NONE; nt];
        let mut queue = VecDeque::new();
        let mut component: Vec<u32> = Vec::new();
        for seed in 0..nt {
            if flip[seed] != NONE {
                continue;
            }
            flip[seed] = 0;
            queue.push_back(seed as u32);
            component.clear();
            while let Some(t) = queue.pop_front() {
                component.push(t);
                for &(n, same) in
                    &adj[adj_off[t as usize] as usize..adj_off[t as usize + 1] as usize]
                {
                    // Same direction on the shared edge means the two disagree.
                    let want = flip[t as usize] ^ same as u32;
                    if flip[n as usize] == NONE {
                        flip[n as usize] = want;
                        queue.push_back(n);
                    }
                }
            }
            // Flip whichever side is the minority, so a mostly right component keeps its
            // orientation.
            let flipped = component.iter().filter(|&&t| flip[t as usize] == 1).count();
            if 2 * flipped > component.len() {
                for &t in &component {
                    flip[t as usize] ^= 1;
                }
            }
        }
        for (t, tri) in self.triangles.iter_mut().enumerate() {
            if flip[t] == 1 {
                tri.swap(1, 2);
                rep.flipped_triangles += 1;
            }
        }
    }

    /// Steps 3 and 4. Returns the (triangle, slot) of leftover half-edges whose edge still has
    /// more than two triangles or two of one direction after the split.
    fn split_by_pairing(
        &mut self,
        rep: &mut ManifoldRepair,
        count_cuts: bool,
    ) -> Vec<(u32, usize)> {
        let nt = self.triangles.len();
        let usable = vec![true; nt];
        let half = sorted_half_edges(&self.triangles, &usable);
        // mate[corner c] = corner whose outgoing half-edge is paired with c's outgoing
        // half-edge (c at `from`, next(c) at `to`).
        let mut mate = vec![NONE; 3 * nt];
        let slot = |tri: [u32; 3], from: u32| tri.iter().position(|&v| v == from).unwrap_or(0);
        for_each_edge_group(&half, |g| {
            let lo = (g[0].key >> 32) as u32;
            let fwd: Vec<u32> = g
                .iter()
                .filter(|h| h.from == lo)
                .map(|h| 3 * h.triangle + slot(self.triangles[h.triangle as usize], h.from) as u32)
                .collect();
            let bwd: Vec<u32> = g
                .iter()
                .filter(|h| h.from != lo)
                .map(|h| 3 * h.triangle + slot(self.triangles[h.triangle as usize], h.from) as u32)
                .collect();
            for (&a, &b) in fwd.iter().zip(bwd.iter()) {
                mate[a as usize] = b;
                mate[b as usize] = a;
            }
            if count_cuts && (g.len() > 2 || fwd.len() != bwd.len()) && g.len() > 1 {
                rep.cut_edges += 1;
            }
        });
        // Corners of one vertex are in one fan when joined through paired half-edges: corner
        // c (at v) pairs its outgoing half-edge with mate m, whose triangle's corner at v is
        // next(m).
        let mut uf = UnionFind::new(3 * nt);
        for c in 0..3 * nt {
            let m = mate[c];
            if m != NONE {
                let m = m as usize;
                let next_m = if m % 3 == 2 { m - 2 } else { m + 1 };
                uf.union(c as u32, next_m as u32);
            }
        }
        // First fan of each vertex keeps the vertex; later fans get copies.
        let nv = self.positions.len();
        let mut owner = vec![NONE; nv]; // root of the fan that owns the original vertex
        let mut copy_of_root: std::collections::HashMap<u32, u32> = Default::default();
        for c in 0..3 * nt {
            let (t, k) = (c / 3, c % 3);
            let v = self.triangles[t][k];
            let root = uf.find(c as u32);
            if owner[v as usize] == NONE {
                owner[v as usize] = root;
            } else if owner[v as usize] != root {
                let nv_now = self.positions.len() as u32;
                let new_v = *copy_of_root.entry(root).or_insert_with(|| {
                    rep.added_vertices += 1;
                    nv_now
                });
                if new_v == nv_now {
                    let p = self.positions[v as usize];
                    self.positions.push(p);
                }
                self.triangles[t][k] = new_v;
            }
        }
        // Check the edges again.
        let half = sorted_half_edges(&self.triangles, &usable);
        let mut offenders = Vec::new();
        for_each_edge_group(&half, |g| {
            let bad = g.len() > 2 || (g.len() == 2 && g[0].from == g[1].from);
            if bad {
                // Keep the first forward/backward pair, detach the rest.
                let mut have_fwd = false;
                let mut have_bwd = false;
                let lo = (g[0].key >> 32) as u32;
                for h in g {
                    let fwd = h.from == lo;
                    let taken = if fwd { &mut have_fwd } else { &mut have_bwd };
                    if *taken {
                        let tri = self.triangles[h.triangle as usize];
                        offenders.push((h.triangle, slot(tri, h.from)));
                    } else {
                        *taken = true;
                    }
                }
            }
        });
        offenders
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CornerTable;
    use glam::DVec3;

    fn check(mut m: Mesh) -> ManifoldRepair {
        let rep = m.make_manifold();
        let r = m.topology_report();
        assert!(r.manifold && r.oriented, "{:?}", r.problems);
        CornerTable::new(&m).expect("repaired mesh builds a corner table");
        rep
    }

    #[test]
    fn bow_tie_vertex_is_split() {
        let m = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y],
            vec![[0, 1, 2], [0, 3, 4]],
        );
        assert!(!m.topology_report().manifold);
        let rep = check(m);
        assert_eq!(rep.added_vertices, 1);
        assert_eq!(rep.cut_edges, 0);
    }

    #[test]
    fn three_triangle_edge_is_cut() {
        let m = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z],
            vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
        );
        assert!(!m.topology_report().manifold);
        let rep = check(m);
        assert_eq!(rep.cut_edges, 1);
        assert!(rep.added_vertices >= 2);
    }

    #[test]
    fn flipped_triangle_is_reoriented() {
        // A square of two triangles, the second one flipped.
        let m = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
            vec![[0, 1, 2], [0, 3, 2]],
        );
        let rep = check(m);
        assert_eq!(rep.flipped_triangles, 1);
        assert_eq!(rep.added_vertices, 0);
    }

    #[test]
    fn degenerate_and_duplicate_are_dropped() {
        let m = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            vec![[0, 1, 2], [0, 0, 1], [0, 1, 2], [2, 1, 0], [0, 1, 9]],
        );
        let mut mm = m.clone();
        let rep = mm.make_manifold();
        assert_eq!(rep.dropped_degenerate, 1);
        assert_eq!(rep.dropped_duplicates, 2);
        assert_eq!(rep.dropped_out_of_range, 1);
        assert_eq!(mm.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn clean_mesh_is_unchanged() {
        let mut m = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
        );
        let before = m.clone();
        assert!(m.make_manifold().is_unchanged());
        assert_eq!(m, before);
    }

    #[test]
    fn edge_shared_by_four_triangles_of_one_fan() {
        // Two tetrahedra glued along edge (0,1): four triangles on that edge.
        let p = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(0.5, 1.0, 0.0),
            DVec3::new(0.5, 0.3, 1.0),
            DVec3::new(0.5, -1.0, 0.0),
            DVec3::new(0.5, -0.3, -1.0),
        ];
        let t = vec![
            [0, 2, 1],
            [0, 1, 3],
            [1, 2, 3],
            [2, 0, 3],
            [0, 1, 4],
            [0, 5, 1],
            [1, 5, 4],
            [4, 5, 0],
        ];
        check(Mesh::new(p, t));
    }
}
