//! Validation and the topology report: what is wrong with a mesh, named element by element,
//! and its global invariants (components, boundary loops, Euler characteristic, genus).
//!
//! Everything here is O(n log n) in the number of triangles (one sort of the half-edges) and
//! never panics, whatever the indices say: out-of-range and repeated indices are reported and
//! the offending triangles left out of the rest of the analysis.

use crate::mesh::{edge_key, Mesh};

/// A named problem of a mesh, pointing at the first element that shows it.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum MeshError {
    /// The mesh has no triangles.
    #[error("the mesh has no triangles")]
    Empty,
    /// A coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFiniteCoordinate {
        /// Offending vertex.
        vertex: u32,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "triangle {triangle} refers to vertex {index}, but the mesh has {vertex_count} vertices"
    )]
    IndexOutOfRange {
        /// Offending triangle.
        triangle: u32,
        /// The bad index.
        index: u32,
        /// Number of vertices of the mesh.
        vertex_count: u32,
    },
    /// A triangle uses one vertex twice (it has no area and no orientation).
    #[error("triangle {triangle} uses vertex {vertex} twice")]
    RepeatedVertex {
        /// Offending triangle.
        triangle: u32,
        /// The repeated vertex.
        vertex: u32,
    },
    /// A triangle with three distinct vertices but exactly zero area (collinear corners).
    #[error("triangle {triangle} has zero area")]
    ZeroAreaTriangle {
        /// Offending triangle.
        triangle: u32,
    },
    /// Two triangles on the same three vertices.
    #[error("triangle {triangle} duplicates triangle {first}")]
    DuplicateTriangle {
        /// The later copy.
        triangle: u32,
        /// The first triangle on the same vertices.
        first: u32,
    },
    /// An edge with more than two incident triangles.
    #[error("edge ({a}, {b}) has {count} incident triangles")]
    NonManifoldEdge {
        /// Lower vertex index.
        a: u32,
        /// Higher vertex index.
        b: u32,
        /// Number of incident triangles.
        count: u32,
    },
    /// An edge with one incident triangle where the table must be closed (a decoder's
    /// rebuilt mesh, before its holes are opened).
    #[error("edge ({a}, {b}) has one incident triangle in a mesh that must be closed")]
    OpenEdge {
        /// Lower vertex index.
        a: u32,
        /// Higher vertex index.
        b: u32,
    },
    /// Two triangles traverse their shared edge in the same direction.
    #[error("edge ({a}, {b}) is traversed in the same direction by triangles {t0} and {t1} (inconsistent orientation)")]
    InconsistentOrientation {
        /// Start vertex of the shared directed edge.
        a: u32,
        /// End vertex of the shared directed edge.
        b: u32,
        /// First triangle.
        t0: u32,
        /// Second triangle.
        t1: u32,
    },
    /// The triangles around a vertex form several fans joined only at the vertex (a bow tie).
    #[error(
        "vertex {vertex} is non-manifold: its triangles form {fans} fans joined only at the vertex"
    )]
    NonManifoldVertex {
        /// Offending vertex.
        vertex: u32,
        /// Number of separate fans.
        fans: u32,
    },
    /// Vertices that no triangle uses.
    #[error("{count} vertices are used by no triangle (the first is vertex {first})")]
    UnreferencedVertices {
        /// How many.
        count: u32,
        /// The lowest such vertex.
        first: u32,
    },
    /// The mesh has more elements than 32-bit indices can address.
    #[error("the mesh is too large: {what} {count} exceeds the 32-bit index range")]
    TooLarge {
        /// Which count.
        what: &'static str,
        /// Its value.
        count: usize,
    },
    /// The coordinates are finite but span more than an f64 holds: the bounding box's
    /// extent overflows, and no grid or length relative to it can be formed.
    #[error(
        "the bounding box's extent overflows (coordinates span more than 1.8e308 on an \
         axis): scale the mesh down"
    )]
    ExtentOverflow,
}

impl MeshError {
    /// A short snake_case name of the problem kind, stable for JSON output and scripts.
    pub fn kind(&self) -> &'static str {
        match self {
            MeshError::Empty => "empty",
            MeshError::NonFiniteCoordinate { .. } => "non_finite_coordinate",
            MeshError::IndexOutOfRange { .. } => "index_out_of_range",
            MeshError::RepeatedVertex { .. } => "repeated_vertex",
            MeshError::ZeroAreaTriangle { .. } => "zero_area_triangle",
            MeshError::DuplicateTriangle { .. } => "duplicate_triangle",
            MeshError::NonManifoldEdge { .. } => "non_manifold_edge",
            MeshError::OpenEdge { .. } => "open_edge",
            MeshError::InconsistentOrientation { .. } => "inconsistent_orientation",
            MeshError::NonManifoldVertex { .. } => "non_manifold_vertex",
            MeshError::UnreferencedVertices { .. } => "unreferenced_vertices",
            MeshError::TooLarge { .. } => "too_large",
            MeshError::ExtentOverflow => "extent_overflow",
        }
    }

    /// True for problems that stop a corner table (and so every codec stage) from being built;
    /// zero-area triangles, duplicates in opposite orientation and unused vertices are reported
    /// but do not block.
    pub fn is_structural(&self) -> bool {
        !matches!(
            self,
            MeshError::ZeroAreaTriangle { .. }
                | MeshError::UnreferencedVertices { .. }
                | MeshError::DuplicateTriangle { .. }
        )
    }
}

/// The topology report of `whet info`: counts, invariants and every problem found.
#[derive(Clone, Debug, PartialEq)]
pub struct TopologyReport {
    /// Number of vertices (including unused ones).
    pub vertices: usize,
    /// Number of triangles.
    pub triangles: usize,
    /// Number of distinct undirected edges.
    pub edges: usize,
    /// Number of edges with one incident triangle.
    pub boundary_edges: usize,
    /// Connected components (through shared vertices) of the used vertices.
    pub components: usize,
    /// Closed chains of boundary edges.
    pub boundary_loops: usize,
    /// V - E + F over used vertices and valid triangles.
    pub euler_characteristic: i64,
    /// Sum of the genera of the components; `None` unless the mesh is manifold and oriented.
    pub genus: Option<u32>,
    /// Every edge has one or two triangles, every vertex one fan, every index valid, no
    /// triangle repeats a vertex and coordinates are finite.
    pub manifold: bool,
    /// Every interior edge is traversed in opposite directions by its two triangles.
    pub oriented: bool,
    /// The problems found, at most [`TopologyReport::MAX_LISTED`] of them (in the order of the
    /// checks: coordinates, indices, duplicates, edges, vertices, unused vertices).
    pub problems: Vec<MeshError>,
    /// Total number of problems found, listed or not.
    pub problem_count: usize,
}

impl TopologyReport {
    /// How many problems the report lists at most; a broken million-triangle mesh would
    /// otherwise produce a report larger than the mesh.
    pub const MAX_LISTED: usize = 100;

    fn push(&mut self, e: MeshError) {
        self.problem_count += 1;
        if self.problems.len() < Self::MAX_LISTED {
            self.problems.push(e);
        }
    }
}

/// Union-find with path halving, on `u32` ids.
pub(crate) struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    pub(crate) fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let gp = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = gp;
            x = gp;
        }
        x
    }
    pub(crate) fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            // Smaller root id wins, so results do not depend on the order of unions.
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            self.parent[hi as usize] = lo;
        }
    }
}

/// One directed edge of a triangle, sortable by its undirected key.
#[derive(Clone, Copy)]
pub(crate) struct HalfEdge {
    pub key: u64,
    pub from: u32,
    pub to: u32,
    pub triangle: u32,
}

/// Half-edges of the triangles for which `usable[t]` holds, sorted by undirected key (ties by
/// triangle, so the order is deterministic).
pub(crate) fn sorted_half_edges(triangles: &[[u32; 3]], usable: &[bool]) -> Vec<HalfEdge> {
    let mut h = Vec::with_capacity(triangles.len() * 3);
    for (t, tri) in triangles.iter().enumerate() {
        if !usable[t] {
            continue;
        }
        for k in 0..3 {
            let (from, to) = (tri[k], tri[(k + 1) % 3]);
            h.push(HalfEdge {
                key: edge_key(from, to),
                from,
                to,
                triangle: t as u32,
            });
        }
    }
    h.sort_unstable_by_key(|e| (e.key, e.triangle, e.from));
    h
}

/// Calls `f` on each run of half-edges with the same undirected key.
pub(crate) fn for_each_edge_group(h: &[HalfEdge], mut f: impl FnMut(&[HalfEdge])) {
    let mut i = 0;
    while i < h.len() {
        let mut j = i + 1;
        while j < h.len() && h[j].key == h[i].key {
            j += 1;
        }
        f(&h[i..j]);
        i = j;
    }
}

impl Mesh {
    /// Checks everything and reports counts, invariants and problems. Never fails: a broken
    /// mesh is described, not refused.
    pub fn topology_report(&self) -> TopologyReport {
        let nv = self.positions.len();
        let nt = self.triangles.len();
        let mut r = TopologyReport {
            vertices: nv,
            triangles: nt,
            edges: 0,
            boundary_edges: 0,
            components: 0,
            boundary_loops: 0,
            euler_characteristic: 0,
            genus: None,
            manifold: true,
            oriented: true,
            problems: Vec::new(),
            problem_count: 0,
        };
        if nv > u32::MAX as usize - 1 || nt > (u32::MAX as usize) / 3 {
            r.manifold = false;
            r.push(MeshError::TooLarge {
                what: if nt > (u32::MAX as usize) / 3 {
                    "triangle count"
                } else {
                    "vertex count"
                },
                count: nt.max(nv),
            });
            return r;
        }
        if nt == 0 {
            r.push(MeshError::Empty);
        }
        for (v, p) in self.positions.iter().enumerate() {
            if !p.is_finite() {
                r.manifold = false;
                r.push(MeshError::NonFiniteCoordinate { vertex: v as u32 });
            }
        }

        // Triangles that can take part in the topology: valid, distinct indices.
        let mut usable = vec![true; nt];
        for (t, tri) in self.triangles.iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&i| i as usize >= nv) {
                usable[t] = false;
                r.manifold = false;
                r.push(MeshError::IndexOutOfRange {
                    triangle: t as u32,
                    index: bad,
                    vertex_count: nv as u32,
                });
            } else if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                usable[t] = false;
                r.manifold = false;
                let vertex = if tri[0] == tri[1] || tri[0] == tri[2] {
                    tri[0]
                } else {
                    tri[1]
                };
                r.push(MeshError::RepeatedVertex {
                    triangle: t as u32,
                    vertex,
                });
            } else if self.face_cross(t) == glam::DVec3::ZERO {
                r.push(MeshError::ZeroAreaTriangle { triangle: t as u32 });
            }
        }

        // Duplicates: the same vertex set. Same orientation also shows up as an inconsistent
        // edge below; the opposite orientation (a two-sided sliver) only here.
        {
            let mut sorted: Vec<([u32; 3], u32)> = self
                .triangles
                .iter()
                .enumerate()
                .filter(|(t, _)| usable[*t])
                .map(|(t, tri)| {
                    let mut s = *tri;
                    s.sort_unstable();
                    (s, t as u32)
                })
                .collect();
            sorted.sort_unstable();
            for w in sorted.windows(2) {
                if w[0].0 == w[1].0 {
                    r.push(MeshError::DuplicateTriangle {
                        triangle: w[1].1,
                        first: w[0].1,
                    });
                }
            }
        }

        // Edges.
        let half = sorted_half_edges(&self.triangles, &usable);
        let mut edges = 0usize;
        let mut boundary: Vec<[u32; 2]> = Vec::new();
        let mut manifold_edge_keys: Vec<u64> = Vec::new();
        for_each_edge_group(&half, |g| {
            edges += 1;
            match g.len() {
                1 => boundary.push([g[0].from, g[0].to]),
                2 => {
                    if g[0].from == g[1].from {
                        r.oriented = false;
                        r.push(MeshError::InconsistentOrientation {
                            a: g[0].from,
                            b: g[0].to,
                            t0: g[0].triangle,
                            t1: g[1].triangle,
                        });
                    }
                    manifold_edge_keys.push(g[0].key);
                }
                n => {
                    r.manifold = false;
                    r.push(MeshError::NonManifoldEdge {
                        a: (g[0].key >> 32) as u32,
                        b: g[0].key as u32,
                        count: n as u32,
                    });
                }
            }
        });
        r.edges = edges;
        r.boundary_edges = boundary.len();

        // Vertex fans: corners of a vertex are joined when their triangles share an edge at
        // the vertex that has exactly two triangles.
        let (offsets, corner_list) = vertex_corners(&self.triangles, &usable, nv);
        let mut referenced = 0usize;
        let mut first_unreferenced: Option<u32> = None;
        let mut unreferenced = 0u32;
        let mut local: Vec<(u32, u32)> = Vec::new(); // (other vertex, local corner index)
        for v in 0..nv {
            let corners = &corner_list[offsets[v] as usize..offsets[v + 1] as usize];
            if corners.is_empty() {
                unreferenced += 1;
                first_unreferenced.get_or_insert(v as u32);
                continue;
            }
            referenced += 1;
            local.clear();
            for (i, &c) in corners.iter().enumerate() {
                let tri = self.triangles[(c / 3) as usize];
                let k = (c % 3) as usize;
                local.push((tri[(k + 1) % 3], i as u32));
                local.push((tri[(k + 2) % 3], i as u32));
            }
            local.sort_unstable();
            let mut uf = UnionFind::new(corners.len());
            // A vertex on a non-manifold edge has split fans by construction; the edge is
            // already reported, so it is not reported again as a vertex.
            let mut on_bad_edge = false;
            let mut i = 0;
            while i < local.len() {
                let mut j = i + 1;
                while j < local.len() && local[j].0 == local[i].0 {
                    j += 1;
                }
                // Exactly two triangles on edge (v, other): they are neighbours in the fan.
                if j - i == 2
                    && manifold_edge_keys
                        .binary_search(&edge_key(v as u32, local[i].0))
                        .is_ok()
                {
                    uf.union(local[i].1, local[i + 1].1);
                }
                on_bad_edge |= j - i > 2;
                i = j;
            }
            let fans = (0..corners.len() as u32)
                .filter(|&i| uf.find(i) == i)
                .count();
            if fans > 1 {
                r.manifold = false;
            }
            if fans > 1 && !on_bad_edge {
                r.push(MeshError::NonManifoldVertex {
                    vertex: v as u32,
                    fans: fans as u32,
                });
            }
        }
        if unreferenced > 0 {
            r.push(MeshError::UnreferencedVertices {
                count: unreferenced,
                first: first_unreferenced.unwrap_or(0),
            });
        }

        // Components, boundary loops and the Euler characteristic per component.
        let mut uf = UnionFind::new(nv);
        for (t, tri) in self.triangles.iter().enumerate() {
            if usable[t] {
                uf.union(tri[0], tri[1]);
                uf.union(tri[1], tri[2]);
            }
        }
        let mut comp_of_root = vec![u32::MAX; nv];
        let mut ncomp = 0u32;
        for v in 0..nv {
            if offsets[v + 1] > offsets[v] {
                let root = uf.find(v as u32) as usize;
                if comp_of_root[root] == u32::MAX {
                    comp_of_root[root] = ncomp;
                    ncomp += 1;
                }
            }
        }
        let comp = |uf: &mut UnionFind, v: u32| comp_of_root[uf.find(v) as usize] as usize;
        let mut chi = vec![0i64; ncomp as usize];
        let mut loops = vec![0i64; ncomp as usize];
        for v in 0..nv {
            if offsets[v + 1] > offsets[v] {
                chi[comp(&mut uf, v as u32)] += 1;
            }
        }
        for_each_edge_group(&half, |g| chi[comp(&mut uf, g[0].from)] -= 1);
        for (t, tri) in self.triangles.iter().enumerate() {
            if usable[t] {
                chi[comp(&mut uf, tri[0])] += 1;
            }
        }
        // Boundary loops: components of the graph of boundary edges.
        {
            let mut buf = UnionFind::new(nv);
            let mut is_bv = vec![false; nv];
            for &[a, b] in &boundary {
                buf.union(a, b);
                is_bv[a as usize] = true;
                is_bv[b as usize] = true;
            }
            for v in 0..nv {
                if is_bv[v] && buf.find(v as u32) == v as u32 {
                    loops[comp(&mut uf, v as u32)] += 1;
                }
            }
        }
        r.components = ncomp as usize;
        r.boundary_loops = loops.iter().sum::<i64>() as usize;
        r.euler_characteristic =
            referenced as i64 - edges as i64 + usable.iter().filter(|&&u| u).count() as i64;
        if r.manifold && r.oriented && nt > 0 {
            let mut genus = 0i64;
            let mut ok = true;
            for (c, &x) in chi.iter().enumerate() {
                let twice = 2 - loops[c] - x;
                if twice < 0 || twice % 2 != 0 {
                    ok = false;
                }
                genus += twice / 2;
            }
            r.genus = if ok { u32::try_from(genus).ok() } else { None };
        }
        r
    }

    /// Ok when a corner table can be built and every coordinate is finite; otherwise the
    /// first structural problem (see [`MeshError::is_structural`]).
    pub fn validate(&self) -> Result<(), MeshError> {
        let r = self.topology_report();
        match r.problems.into_iter().find(|p| p.is_structural()) {
            Some(p) => Err(p),
            None => Ok(()),
        }
    }
}

/// CSR lists of the corners of each vertex (usable triangles only): `corners[offsets[v]..
/// offsets[v + 1]]` are the corners at vertex `v`, in increasing order.
pub(crate) fn vertex_corners(
    triangles: &[[u32; 3]],
    usable: &[bool],
    nv: usize,
) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; nv + 1];
    for (t, tri) in triangles.iter().enumerate() {
        if usable[t] {
            for &v in tri {
                offsets[v as usize + 1] += 1;
            }
        }
    }
    for v in 0..nv {
        offsets[v + 1] += offsets[v];
    }
    let mut fill = offsets.clone();
    let mut corners = vec![0u32; offsets[nv] as usize];
    for (t, tri) in triangles.iter().enumerate() {
        if usable[t] {
            for (k, &v) in tri.iter().enumerate() {
                corners[fill[v as usize] as usize] = (3 * t + k) as u32;
                fill[v as usize] += 1;
            }
        }
    }
    (offsets, corners)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A closed torus grid of n x m quads, two triangles each.
    pub(crate) fn torus(n: u32, m: u32) -> Mesh {
        let mut p = Vec::new();
        for i in 0..n {
            for j in 0..m {
                let (u, v) = (
                    i as f64 / n as f64 * std::f64::consts::TAU,
                    j as f64 / m as f64 * std::f64::consts::TAU,
                );
                let r = 2.0 + v.cos();
                p.push(DVec3::new(r * u.cos(), r * u.sin(), v.sin()));
            }
        }
        let id = |i: u32, j: u32| (i % n) * m + (j % m);
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..m {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        Mesh::new(p, t)
    }

    #[test]
    fn torus_has_genus_one() {
        let r = torus(8, 6).topology_report();
        assert!(r.manifold && r.oriented && r.problems.is_empty());
        assert_eq!(r.genus, Some(1));
        assert_eq!(r.euler_characteristic, 0);
        assert_eq!(r.edges, 8 * 6 * 3);
    }

    #[test]
    fn open_square_has_one_loop() {
        let m = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        let r = m.topology_report();
        assert_eq!(
            (r.boundary_loops, r.boundary_edges, r.genus),
            (1, 4, Some(0))
        );
        assert_eq!(r.components, 1);
    }

    #[test]
    fn two_components_and_an_unused_vertex() {
        let mut a = torus(4, 4);
        let b = torus(4, 4);
        let off = a.positions.len() as u32;
        a.positions
            .extend(b.positions.iter().map(|p| *p + DVec3::X * 10.0));
        a.triangles.extend(
            b.triangles
                .iter()
                .map(|t| [t[0] + off, t[1] + off, t[2] + off]),
        );
        a.positions.push(DVec3::ZERO);
        let r = a.topology_report();
        assert_eq!(r.components, 2);
        assert_eq!(r.genus, Some(2));
        assert!(r.manifold);
        assert_eq!(
            r.problems,
            vec![MeshError::UnreferencedVertices {
                count: 1,
                first: 32
            }]
        );
    }

    #[test]
    fn names_the_first_offender() {
        let m = Mesh::new(
            vec![
                DVec3::ZERO,
                DVec3::X,
                DVec3::Y,
                -DVec3::Y,
                DVec3::Z,
                DVec3::NAN,
            ],
            vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 2, 3], [0, 1, 7]],
        );
        let r = m.topology_report();
        assert!(!r.manifold);
        let text: Vec<String> = r.problems.iter().map(|p| p.to_string()).collect();
        assert_eq!(
            text,
            vec![
                "vertex 5 has a non-finite coordinate",
                "triangle 3 uses vertex 2 twice",
                "triangle 4 refers to vertex 7, but the mesh has 6 vertices",
                "edge (0, 1) has 3 incident triangles",
                "1 vertices are used by no triangle (the first is vertex 5)",
            ]
        );
        assert_eq!(
            m.validate(),
            Err(MeshError::NonFiniteCoordinate { vertex: 5 })
        );
    }

    #[test]
    fn zero_area_and_flipped_are_reported() {
        let m = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::X * 2.0, DVec3::Y],
            vec![[0, 1, 2], [0, 1, 3]],
        );
        let r = m.topology_report();
        assert_eq!(r.problems[0], MeshError::ZeroAreaTriangle { triangle: 0 });
        assert!(matches!(
            r.problems[1],
            MeshError::InconsistentOrientation { .. }
        ));
        assert!(r.manifold && !r.oriented && r.genus.is_none());
    }
}
