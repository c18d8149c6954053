//! The corner table (Rossignac's representation used by Edgebreaker): one entry per corner
//! holding its vertex and its opposite corner.
//!
//! ```text
//!            v(prev c)
//!              /\
//!             /  \          corner c sits at v(c) in triangle c / 3;
//!            /    \         next(c), prev(c) are the other corners of that triangle
//!           /  t   \        counter-clockwise; opposite(c) is the corner across the
//!          /        \       edge v(next c) - v(prev c) in the neighbouring triangle.
//!    v(c) ------------ v(next c)
//!          \        /
//!           \  t'  /
//!            \    /
//!             \/
//!          v(opposite c)
//! ```
//!
//! Invariants: every edge has at most two triangles, traversed in opposite directions; every
//! vertex has a single fan (a disk or, at a boundary, a half-disk). `new` refuses anything
//! else with the [`MeshError`] naming the first offender; cut such input with
//! [`Mesh::make_manifold`] first. Boundary corners (whose opposite edge is a boundary edge)
//! have no opposite. Building is linear in the number of corners for bounded valence (each
//! vertex's outgoing edges are sorted once, O(k log k) for valence k).

use crate::ids::{CornerId, VertexId};
use crate::mesh::Mesh;
use crate::scratch::Scratch;
use crate::topology::MeshError;

const NONE: u32 = u32::MAX;

/// Corner table of an oriented manifold triangle mesh.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CornerTable {
    /// The vertices of each triangle's corners: corner `3 t + j` is `triangles[t][j]`. Kept
    /// as triangles so that a decoder can hand the array on as its mesh's triangles without
    /// a copy ([`CornerTable::into_triangles`]); read flat, per corner, through
    /// [`CornerTable::corner_vertices`].
    triangles: Vec<[u32; 3]>,
    /// Opposite of each corner, `NONE` at a boundary.
    opposite: Vec<u32>,
    /// For each vertex a corner at it from which [`CornerTable::swing`] visits the whole fan
    /// (at a boundary vertex, the clockwise-most corner); `NONE` for an unused vertex.
    vertex_corner: Vec<u32>,
}

impl CornerTable {
    /// Builds the table of `mesh`, checking indices, edge- and vertex-manifoldness and
    /// orientation on the way.
    pub fn new(mesh: &Mesh) -> Result<CornerTable, MeshError> {
        CornerTable::from_triangles(&mesh.triangles, mesh.positions.len())
    }

    /// Builds the table from triangles alone (positions are not needed).
    pub fn from_triangles(
        triangles: &[[u32; 3]],
        vertex_count: usize,
    ) -> Result<CornerTable, MeshError> {
        CornerTable::build(triangles, vertex_count, true, &mut Scratch::new())
    }

    /// [`CornerTable::from_triangles`] in the memory of `scratch` (its working arrays taken
    /// from it and given back, the table's own taken from it): the same table, or the same
    /// error. [`CornerTable::recycle`] gives the table's arrays back.
    pub fn from_triangles_in(
        triangles: &[[u32; 3]],
        vertex_count: usize,
        scratch: &mut Scratch,
    ) -> Result<CornerTable, MeshError> {
        CornerTable::build(triangles, vertex_count, true, scratch)
    }

    /// [`CornerTable::from_triangles`] without the walk around closed fans: it checks
    /// indices, edges, orientation and that no vertex starts two open fans, but a vertex
    /// whose corners form several closed fans (two closed surfaces pinched at it) is not
    /// refused, so the table may break the single-fan invariant until
    /// [`CornerTable::check_fans`] passes. The walk is the costliest part of building on
    /// a mesh in random memory order; a caller that relabels the table in a cache-friendly
    /// order first can check there.
    pub fn from_triangles_deferring_fans(
        triangles: &[[u32; 3]],
        vertex_count: usize,
    ) -> Result<CornerTable, MeshError> {
        CornerTable::build(triangles, vertex_count, false, &mut Scratch::new())
    }

    /// [`CornerTable::from_triangles_deferring_fans`] in the memory of `scratch` (its
    /// working arrays taken from it and given back, the table's own taken from it): the
    /// same table. [`CornerTable::recycle`] gives the table's arrays back.
    pub fn from_triangles_deferring_fans_in(
        triangles: &[[u32; 3]],
        vertex_count: usize,
        scratch: &mut Scratch,
    ) -> Result<CornerTable, MeshError> {
        CornerTable::build(triangles, vertex_count, false, scratch)
    }

    /// Gives the table's arrays to `scratch` for a later build.
    pub fn recycle(self, scratch: &mut Scratch) {
        scratch.give(self.triangles);
        scratch.give(self.opposite);
        scratch.give(self.vertex_corner);
    }

    /// Checks that every used vertex has a single fan (the check
    /// [`CornerTable::from_triangles`] makes; tables built otherwise may need it).
    pub fn check_fans(&self) -> Result<(), MeshError> {
        if self.fans_cover_all_corners() {
            return Ok(());
        }
        // Something is wrong: find and name the vertex.
        let (valence, open_fans) = self.fan_counts();
        for v in 0..self.vertex_corner.len() {
            self.check_fan(v, &valence, &open_fans)?;
        }
        Ok(())
    }

    fn build(
        triangles: &[[u32; 3]],
        vertex_count: usize,
        walk_fans: bool,
        scratch: &mut Scratch,
    ) -> Result<CornerTable, MeshError> {
        let down = if vertex_count <= DOWN as usize {
            DOWN
        } else {
            0
        };
        CornerTable::build_with(triangles, vertex_count, walk_fans, down, scratch)
    }

    /// [`CornerTable::build`] with the bucket entries' direction bit `down` (0: none, every
    /// bucket sorted; the tests take that path on small meshes too).
    fn build_with(
        triangles: &[[u32; 3]],
        vertex_count: usize,
        walk_fans: bool,
        down: u32,
        scratch: &mut Scratch,
    ) -> Result<CornerTable, MeshError> {
        let nt = triangles.len();
        if nt > (u32::MAX as usize - 3) / 3 {
            return Err(MeshError::TooLarge {
                what: "triangle count",
                count: nt,
            });
        }
        check_vertex_count(vertex_count)?;
        let nc = 3 * nt;
        let mut triangles_out: Vec<[u32; 3]> = scratch.take_empty(nt);
        // One pass over the triangles checks them, counts each vertex's corners and the edges
        // bucketed at it (by lower vertex, see below), and notes each vertex's first corner
        // (its fan's start unless it is on a boundary).
        let edges = |tri: &[u32]| [(tri[1], tri[2]), (tri[2], tri[0]), (tri[0], tri[1])];
        let mut offsets = scratch.take_filled(vertex_count + 1, 0u32);
        let mut valence = scratch.take_filled(vertex_count, 0u32);
        let mut vertex_corner = scratch.take_filled(vertex_count, NONE);
        {
            // Slices of the lengths the index check below bounds (so that the compiler drops
            // the per-access bounds checks).
            let offsets = &mut offsets[..vertex_count + 1];
            let valence = &mut valence[..vertex_count];
            let vertex_corner = &mut vertex_corner[..vertex_count];
            for (t, tri) in triangles.iter().enumerate() {
                for &v in tri {
                    if v as usize >= vertex_count {
                        return Err(MeshError::IndexOutOfRange {
                            triangle: t as u32,
                            index: v,
                            vertex_count: vertex_count as u32,
                        });
                    }
                }
                if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                    let vertex = if tri[0] == tri[1] || tri[0] == tri[2] {
                        tri[0]
                    } else {
                        tri[1]
                    };
                    return Err(MeshError::RepeatedVertex {
                        triangle: t as u32,
                        vertex,
                    });
                }
                triangles_out.push(*tri);
                for (j, &v) in tri.iter().enumerate() {
                    valence[v as usize] += 1;
                    let slot = &mut vertex_corner[v as usize];
                    if *slot == NONE {
                        *slot = (3 * t + j) as u32;
                    }
                }
                for (a, b) in edges(tri) {
                    offsets[a.min(b) as usize + 1] += 1;
                }
            }
        }

        // Pair the edges facing the corners. The edge facing c runs v(next c) -> v(prev c);
        // bucket it by its lower vertex with (higher vertex, corner), sort each small bucket
        // by the higher vertex, and pair the runs: two entries of opposite directions are
        // twins, one is a boundary edge, anything else is refused. Two sequential passes with
        // one scatter in between: linear for bounded valence.
        // Triangle by triangle: corner 3t + j faces the edge from vertex j + 1 to j + 2
        // (mod 3) of triangle t, read without a modulo per corner.
        for v in 0..vertex_count {
            offsets[v + 1] += offsets[v];
        }
        let mut fill: Vec<u32> = scratch.take_empty(vertex_count + 1);
        fill.extend_from_slice(&offsets);
        // Entries are (higher vertex, corner) in two u32 arrays of the corner count: the
        // size and type of arrays later stages take from the scratch again (one packed u64
        // array would be memory nothing reuses; corners alone, reading the higher vertex
        // back from the triangle, cost the pairing a random access per entry). Every entry
        // is written before it is read. The higher vertex carries the half-edge's direction
        // in its top bit (`down`: it runs from the higher vertex down), which vertex
        // numbers below 2^31 leave free; twins must differ in it. (A bit array per corner
        // cost the build a tenth of its instructions in shifts and masks.) With more vertices
        // no bit is free: every bucket then takes the sorting path, which reads directions
        // from the triangles.
        let mut bucket_higher = scratch.take_overwritten(nc, 0u32);
        let mut bucket = scratch.take_overwritten(nc, 0u32);
        let corner_vertex = triangles_out.as_flattened();
        for (t, tri) in triangles_out.iter().enumerate() {
            for (j, (a, b)) in edges(tri).into_iter().enumerate() {
                let c = 3 * t + j;
                let lo = a.min(b) as usize;
                let at = fill[lo] as usize;
                bucket_higher[at] = a.max(b) | if a > b { down } else { 0 };
                bucket[at] = c as u32;
                fill[lo] += 1;
            }
        }
        // The sorting path's direction test, from the triangles.
        let is_upward = |c: usize| corner_vertex[next_raw(c)] < corner_vertex[prev_raw(c)];
        let mut opposite = scratch.take_filled(nc, NONE);
        // Corners that start an open fan, per vertex: the corner after each boundary corner
        // (the edge behind it is the boundary). The fan walk then starts there.
        let mut open_fans = scratch.take_filled(vertex_count, 0u8);
        // A closed bucket's twins are paired in one pass over it, without branches on the
        // data (sorting each small bucket mispredicted most of its compares: a third of the
        // build on the bench mesh): `mate[w]` holds the entry (its index in the bucket
        // arrays) of the first half-edge to w seen in this bucket, NONE before, PAIRED after
        // the second; cleared after each bucket. A bucket with a third half-edge on one edge,
        // twins of one direction, or a half-edge without twin (a boundary) is sorted and
        // paired again below, which names the error or starts the open fans.
        const PAIRED: u32 = NONE - 1;
        let mut mate = fill;
        mate.fill(NONE);
        let mut sorted: Vec<u64> = Vec::new();
        let higher = !down;
        for v in 0..vertex_count {
            let range = offsets[v] as usize..offsets[v + 1] as usize;
            let first = range.start;
            let (s, hs) = (&bucket[range.clone()], &bucket_higher[range]);
            let (mut pairs, mut irregular) = (0usize, false);
            for (i, (&c, &h)) in s.iter().zip(hs).enumerate() {
                let w = (h & higher) as usize;
                let m = mate[w];
                let open = m < PAIRED;
                // The twin's entry, or this one's when there is no twin yet.
                let e = if open { m as usize } else { first + i };
                let (twin, twin_h) = (bucket[e], bucket_higher[e]);
                irregular |= (m == PAIRED) | (open & ((h ^ twin_h) & down == 0));
                opposite[twin as usize] = c;
                opposite[c as usize] = if open { twin } else { NONE };
                mate[w] = if open { PAIRED } else { (first + i) as u32 };
                pairs += open as usize;
            }
            for &h in hs {
                mate[(h & higher) as usize] = NONE;
            }
            if !irregular && 2 * pairs == s.len() {
                continue;
            }
            // (higher vertex, corner) packed, so that a sort groups each edge's half-edges.
            sorted.clear();
            sorted.extend(
                s.iter()
                    .zip(hs)
                    .map(|(&c, &h)| ((h & higher) as u64) << 32 | c as u64),
            );
            sorted.sort_unstable();
            let s = &sorted;
            let mut i = 0;
            while i < s.len() {
                let mut j = i + 1;
                while j < s.len() && s[j] >> 32 == s[i] >> 32 {
                    j += 1;
                }
                match j - i {
                    1 => {
                        let start = next_raw(s[i] as u32 as usize);
                        let w = corner_vertex[start] as usize;
                        open_fans[w] = open_fans[w].saturating_add(1);
                        // The fan starts there. Of several starts (refused below) keep the
                        // highest corner, as `from_parts`'s scan in corner order does.
                        if open_fans[w] == 1 || start as u32 > vertex_corner[w] {
                            vertex_corner[w] = start as u32;
                        }
                    }
                    2 => {
                        let (c1, c2) = (s[i] as u32 as usize, s[i + 1] as u32 as usize);
                        // Twins run in opposite directions: c1's edge starts where c2's ends.
                        if is_upward(c1) == is_upward(c2) {
                            return Err(MeshError::InconsistentOrientation {
                                a: corner_vertex[next_raw(c1)],
                                b: corner_vertex[prev_raw(c1)],
                                t0: (c1 / 3) as u32,
                                t1: (c2 / 3) as u32,
                            });
                        }
                        opposite[c1] = c2 as u32;
                        opposite[c2] = c1 as u32;
                    }
                    n => {
                        return Err(MeshError::NonManifoldEdge {
                            a: v as u32,
                            b: (s[i] >> 32) as u32,
                            count: n as u32,
                        })
                    }
                }
                i = j;
            }
        }
        scratch.give(mate);
        scratch.give(bucket);
        scratch.give(bucket_higher);
        scratch.give(offsets);
        let table = CornerTable {
            triangles: triangles_out,
            opposite,
            vertex_corner,
        };
        let checked = table.check_vertex_fans(&valence, &open_fans, walk_fans);
        scratch.give(valence);
        scratch.give(open_fans);
        checked?;
        Ok(table)
    }

    /// Builds the table from the arrays of a checked table whose corners and vertices were
    /// renumbered (each triangle keeping its corners' rotation), as the Edgebreaker encoder
    /// relabels its input in traversal order. Such arrays are consistent by construction, so
    /// only what keeps every access in bounds is checked (array lengths, vertex indices,
    /// opposite indices): a sequential pass instead of [`CornerTable::from_raw`]'s random
    /// reads of each opposite's triangle. Start corners are picked by `from_raw`'s rule, so
    /// for consistent arrays the two give the same table. Inconsistent arrays give a table
    /// whose walks are wrong but bounded, never an out-of-bounds access.
    pub fn from_relabelled(
        triangles: Vec<[u32; 3]>,
        opposite: Vec<u32>,
        vertex_count: usize,
    ) -> Result<CornerTable, MeshError> {
        Self::from_relabelled_in(triangles, opposite, vertex_count, &mut Scratch::new())
    }

    /// [`CornerTable::from_relabelled`] with its per-vertex array taken from `scratch`.
    pub fn from_relabelled_in(
        triangles: Vec<[u32; 3]>,
        opposite: Vec<u32>,
        vertex_count: usize,
        scratch: &mut Scratch,
    ) -> Result<CornerTable, MeshError> {
        let nc = check_corner_arrays(&triangles, &opposite, vertex_count)?;
        let mut vertex_corner = scratch.take_filled(vertex_count, NONE);
        for (t, (tv, to)) in triangles.iter().zip(opposite.chunks_exact(3)).enumerate() {
            for j in 0..3 {
                let v = tv[j];
                let Some(slot) = vertex_corner.get_mut(v as usize) else {
                    return Err(MeshError::IndexOutOfRange {
                        triangle: t as u32,
                        index: v,
                        vertex_count: vertex_count as u32,
                    });
                };
                if to[j] != NONE && to[j] as usize >= nc {
                    return Err(MeshError::TooLarge {
                        what: "opposite corner index",
                        count: to[j] as usize,
                    });
                }
                // from_raw's rule: the first corner, or one whose edge behind is open.
                if *slot == NONE || to[(j + 2) % 3] == NONE {
                    *slot = (3 * t + j) as u32;
                }
            }
        }
        Ok(CornerTable {
            triangles,
            opposite,
            vertex_corner,
        })
    }

    /// Builds the table from corner vertices and opposites that are already paired (a
    /// decoder that rebuilt them itself), checking that they are consistent: indices in
    /// range, no repeated vertex in a triangle, opposites mutual and facing the same edge
    /// reversed. With `check_fans` it also checks that every vertex has a single fan (a walk
    /// around every vertex: the costliest check, which a decoder whose construction cannot
    /// split fans may skip; every table walk stays bounded either way).
    pub fn from_raw(
        triangles: Vec<[u32; 3]>,
        opposite: Vec<u32>,
        vertex_count: usize,
        check_fans: bool,
    ) -> Result<CornerTable, MeshError> {
        Self::from_raw_checked::<false>(
            triangles,
            opposite,
            vertex_count,
            check_fans,
            Vec::new(),
            None,
        )
    }

    /// [`CornerTable::from_raw`] for a table that must be closed: an opposite left at the
    /// boundary marker is [`MeshError::OpenEdge`]. Found in the pass that checks the pairs,
    /// so a decoder need not scan its arrays for the marker first.
    pub fn from_raw_closed(
        triangles: Vec<[u32; 3]>,
        opposite: Vec<u32>,
        vertex_count: usize,
        check_fans: bool,
    ) -> Result<CornerTable, MeshError> {
        Self::from_raw_checked::<true>(
            triangles,
            opposite,
            vertex_count,
            check_fans,
            Vec::new(),
            None,
        )
    }

    /// [`CornerTable::from_raw_closed`] that builds its per-vertex array in `buffer` (its
    /// contents ignored: memory a decoder kept from its last table is not faulted in again)
    /// and renumbers the vertices: vertex `v` of `triangles` becomes `renumber[v]`, in the
    /// pass that checks the table (a decoder that numbers its vertices in another order saves
    /// a pass over its triangles). The map
    /// must be injective on the vertices used; a vertex without a number (`u32::MAX`, or
    /// past the map) is [`MeshError::IndexOutOfRange`] against the map's length, and the new
    /// numbers must lie below `vertex_count`.
    pub fn from_raw_closed_renumbering(
        triangles: Vec<[u32; 3]>,
        opposite: Vec<u32>,
        renumber: &[u32],
        vertex_count: usize,
        buffer: Vec<u32>,
    ) -> Result<CornerTable, MeshError> {
        Self::from_raw_checked::<true>(
            triangles,
            opposite,
            vertex_count,
            false,
            buffer,
            Some(renumber),
        )
    }

    /// The table's arrays: its triangles, the opposite of each corner, and each vertex's
    /// start corner (for reuse by a decoder; see [`CornerTable::from_raw_closed_renumbering`]).
    pub fn into_parts(self) -> (Vec<[u32; 3]>, Vec<u32>, Vec<u32>) {
        (self.triangles, self.opposite, self.vertex_corner)
    }

    fn from_raw_checked<const CLOSED: bool>(
        mut triangles: Vec<[u32; 3]>,
        opposite: Vec<u32>,
        vertex_count: usize,
        check_fans: bool,
        mut buffer: Vec<u32>,
        renumber: Option<&[u32]>,
    ) -> Result<CornerTable, MeshError> {
        let nc = check_corner_arrays(&triangles, &opposite, vertex_count)?;
        // One pass over the triangles: vertex indices, repeated vertices, and each corner's
        // opposite (mutual, facing the same edge reversed); without the fan check the start
        // corners are picked on the way. When renumbering, the checks compare the old
        // numbers (a triangle is renumbered after its checks, and its later neighbours are
        // still in the old ones; the map is injective, so the comparisons agree).
        buffer.clear();
        let mut vertex_corner = buffer;
        if !check_fans {
            vertex_corner.resize(vertex_count, NONE);
        }
        let old_count = renumber.map_or(vertex_count, |m| m.len());
        for (t, to) in opposite.chunks_exact(3).enumerate() {
            let tv = triangles[t];
            if let Some(&v) = tv.iter().find(|&&v| v as usize >= old_count) {
                return Err(MeshError::IndexOutOfRange {
                    triangle: t as u32,
                    index: v,
                    vertex_count: old_count as u32,
                });
            }
            let [a, b, c] = tv;
            if a == b || b == c || a == c {
                return Err(MeshError::RepeatedVertex {
                    triangle: t as u32,
                    vertex: if a == b || a == c { a } else { b },
                });
            }
            for j in 0..3 {
                let o = to[j];
                if o == NONE {
                    if CLOSED {
                        let (x, y) = (tv[(j + 1) % 3], tv[(j + 2) % 3]);
                        return Err(MeshError::OpenEdge {
                            a: x.min(y),
                            b: x.max(y),
                        });
                    }
                    continue;
                }
                let oi = o as usize;
                let c = 3 * t + j;
                let (x, y) = (tv[(j + 1) % 3], tv[(j + 2) % 3]);
                // The vertices before and after oi in its triangle from one 32-bit division
                // and two table offsets (three 64-bit modulos were most of this loop).
                const BEFORE: [usize; 3] = [2, 0, 1];
                const AFTER: [usize; 3] = [1, 2, 0];
                let (ot, k) = ((o / 3) as usize, (o % 3) as usize);
                // A pair is checked in full from its first corner; from the second, that
                // it is mutual is enough (the first then checked this very pair).
                let consistent = oi < nc
                    && opposite[oi] == c as u32
                    && (oi < c || {
                        let to = triangles[ot];
                        to[BEFORE[k]] == x && to[AFTER[k]] == y
                    });
                if !consistent {
                    return Err(MeshError::NonManifoldEdge {
                        a: x.min(y),
                        b: x.max(y),
                        count: 3,
                    });
                }
            }
            let tv = match renumber {
                None => tv,
                Some(map) => {
                    let new = tv.map(|v| map[v as usize]);
                    if let Some(j) = new.iter().position(|&v| v as usize >= vertex_count) {
                        return Err(MeshError::IndexOutOfRange {
                            triangle: t as u32,
                            index: tv[j],
                            vertex_count: old_count as u32,
                        });
                    }
                    triangles[t] = new;
                    new
                }
            };
            if !check_fans {
                for j in 0..3 {
                    let slot = &mut vertex_corner[tv[j] as usize];
                    // A closed table has no open edge behind any corner (an open one was
                    // refused above): the first corner is the start.
                    if *slot == NONE || (!CLOSED && to[(j + 2) % 3] == NONE) {
                        *slot = (3 * t + j) as u32;
                    }
                }
            }
        }
        if !check_fans {
            return Ok(CornerTable {
                triangles,
                opposite,
                vertex_corner,
            });
        }
        CornerTable::from_parts(triangles, opposite, vertex_count, true)
    }

    /// Finishes a table whose opposites are paired: picks each vertex's start corner (the
    /// clockwise-most at a boundary) and checks that swinging from it visits all the
    /// vertex's corners.
    fn from_parts(
        triangles: Vec<[u32; 3]>,
        opposite: Vec<u32>,
        vertex_count: usize,
        walk_fans: bool,
    ) -> Result<CornerTable, MeshError> {
        let nc = 3 * triangles.len();
        let mut table = CornerTable {
            triangles,
            opposite,
            vertex_corner: vec![NONE; vertex_count],
        };
        let mut valence = vec![0u32; vertex_count];
        let mut open_fans = vec![0u8; vertex_count];
        for c in 0..nc {
            let v = table.corner_vertices()[c] as usize;
            valence[v] += 1;
            // c starts an open fan when the edge behind it, (v(prev c), v(c)), is a boundary.
            if table.opposite[prev_raw(c)] == NONE {
                open_fans[v] = open_fans[v].saturating_add(1);
                table.vertex_corner[v] = c as u32;
            } else if table.vertex_corner[v] == NONE {
                table.vertex_corner[v] = c as u32;
            }
        }
        table.check_vertex_fans(&valence, &open_fans, walk_fans)?;
        Ok(table)
    }

    /// Refuses a vertex with two open fans and, with `walk_fans`, one whose fan from its
    /// start corner misses some of its corners; vertices in order, so the error names the
    /// lowest offender.
    fn check_vertex_fans(
        &self,
        valence: &[u32],
        open_fans: &[u8],
        walk_fans: bool,
    ) -> Result<(), MeshError> {
        if walk_fans {
            return self.walk_vertex_fans(valence, open_fans);
        }
        for v in 0..self.vertex_corner.len() {
            if open_fans[v] > 1 {
                return Err(MeshError::NonManifoldVertex {
                    vertex: v as u32,
                    fans: self.count_fans(VertexId(v as u32)),
                });
            }
        }
        Ok(())
    }

    /// [`Self::check_fan`] for every vertex, the same first error, the walks of
    /// [`FAN_LANES`] consecutive vertices at a time advancing together ([`Self::fan_walks`]).
    fn walk_vertex_fans(&self, valence: &[u32], open_fans: &[u8]) -> Result<(), MeshError> {
        let nv = self.vertex_corner.len();
        for first in (0..nv).step_by(FAN_LANES) {
            let lanes = FAN_LANES.min(nv - first);
            let mut starts = [NONE; FAN_LANES];
            let mut caps = [0u64; FAN_LANES];
            starts[..lanes].copy_from_slice(&self.vertex_corner[first..first + lanes]);
            for (cap, &k) in caps.iter_mut().zip(&valence[first..first + lanes]) {
                *cap = u64::from(k);
            }
            let seen = self.fan_walks(&starts, &caps);
            for i in 0..lanes {
                let v = first + i;
                if starts[i] != NONE && (open_fans[v] > 1 || seen[i] != caps[i]) {
                    // The error as the single walk names it.
                    return self.check_fan(v, valence, open_fans);
                }
            }
        }
        Ok(())
    }

    /// [`Self::fan_walk`] from each of `starts` (`NONE`: no walk, 0 met) with its cap, the
    /// walks advancing a step each in turn: their reads of the opposites (scattered over the
    /// table on an input in file order) overlap instead of each waiting for the one before.
    /// A finished walk keeps its state (selects, not branches: which walk ends when is
    /// data).
    fn fan_walks(&self, starts: &[u32; FAN_LANES], caps: &[u64; FAN_LANES]) -> [u64; FAN_LANES] {
        let opposite = self.opposite.as_slice();
        let mut after = [0u32; FAN_LANES];
        let mut seen = [0u64; FAN_LANES];
        let mut live = [false; FAN_LANES];
        for i in 0..FAN_LANES {
            let s = starts[i];
            if s != NONE {
                let j = s % 3;
                after[i] = s - j + NEXT_IN_TRIANGLE[j as usize];
                seen[i] = 1;
                live[i] = true;
            }
        }
        loop {
            let mut any = false;
            for i in 0..FAN_LANES {
                let o = opposite.get(after[i] as usize).copied().unwrap_or(NONE);
                let jo = o % 3;
                let base = o.wrapping_sub(jo);
                let jn = NEXT_IN_TRIANGLE[jo as usize];
                let stop = o == NONE || base.wrapping_add(jn) == starts[i] || seen[i] > caps[i];
                let go = live[i] & !stop;
                seen[i] += u64::from(go);
                after[i] = if go {
                    base + NEXT_IN_TRIANGLE[jn as usize]
                } else {
                    after[i]
                };
                live[i] = go;
                any |= go;
            }
            if !any {
                return seen;
            }
        }
    }

    /// Per vertex: corners, and corners that start an open fan.
    /// True when swinging from every vertex's start corner meets every corner of the table:
    /// exactly when [`Self::check_fans`] passes, without its per-vertex counts. A walk meets
    /// distinct corners of its own vertex only (the swing is injective and keeps the vertex
    /// in a paired table), so it meets at most the vertex's valence, and the sum over the
    /// vertices is the corner count only when each walk meets all its vertex's corners: a
    /// second fan, open or closed, or a start corner that is not an open fan's clockwise
    /// end leaves corners unmet.
    fn fans_cover_all_corners(&self) -> bool {
        let nc = self.corner_count() as u64;
        let mut met = 0u64;
        for chunk in self.vertex_corner.chunks(FAN_LANES) {
            let mut starts = [NONE; FAN_LANES];
            starts[..chunk.len()].copy_from_slice(chunk);
            // Each walk capped by what is left: the work stays linear on any table.
            let seen = self.fan_walks(&starts, &[nc - met; FAN_LANES]);
            met += seen.iter().sum::<u64>();
            if met > nc {
                // Only an inconsistent table walks past its corner count.
                return false;
            }
        }
        met == nc
    }

    /// The corners met swinging from `start` (itself included) until the walk returns to
    /// it or reaches a boundary, stopping once more than `cap` are met. Open fans start at
    /// their clockwise end; a closed fan anywhere. Over the raw arrays with one 32-bit
    /// modulo per step: the corner's own position in its triangle is known from the step
    /// before (the walk runs once per vertex of every input, so its instructions count).
    fn fan_walk(&self, start: u32, cap: u64) -> u64 {
        let opposite = self.opposite.as_slice();
        let mut seen = 1u64;
        // The corner after c in its triangle.
        let mut after = {
            let j = start % 3;
            start - j + NEXT_IN_TRIANGLE[j as usize]
        };
        while let Some(&o) = opposite.get(after as usize) {
            if o == NONE {
                break;
            }
            // The swung corner n = next(o), and the corner after it.
            let jo = o % 3;
            let base = o - jo;
            let jn = NEXT_IN_TRIANGLE[jo as usize];
            if base + jn == start || seen > cap {
                break;
            }
            seen += 1;
            after = base + NEXT_IN_TRIANGLE[jn as usize];
        }
        seen
    }

    fn fan_counts(&self) -> (Vec<u32>, Vec<u8>) {
        let mut valence = vec![0u32; self.vertex_corner.len()];
        let mut open_fans = vec![0u8; self.vertex_corner.len()];
        for (c, &v) in self.corner_vertices().iter().enumerate() {
            let v = v as usize;
            valence[v] += 1;
            if self.opposite[prev_raw(c)] == NONE {
                open_fans[v] = open_fans[v].saturating_add(1);
            }
        }
        (valence, open_fans)
    }

    /// Checks that `v` (if used) has at most one open fan and that swinging from its start
    /// corner meets all its corners.
    fn check_fan(&self, v: usize, valence: &[u32], open_fans: &[u8]) -> Result<(), MeshError> {
        let start = self.vertex_corner[v];
        if start == NONE {
            return Ok(());
        }
        let fail = || MeshError::NonManifoldVertex {
            vertex: v as u32,
            fans: self.count_fans(VertexId(v as u32)),
        };
        if open_fans[v] > 1 {
            return Err(fail());
        }
        let seen = self.fan_walk(start, valence[v] as u64);
        if seen != valence[v] as u64 {
            return Err(fail());
        }
        Ok(())
    }

    // Error path only: the number of separate fans around `v` (a linear scan).
    fn count_fans(&self, v: VertexId) -> u32 {
        let corners: Vec<u32> = (0..self.corner_count() as u32)
            .filter(|&c| self.corner_vertices()[c as usize] == v.0)
            .collect();
        let mut seen = vec![false; corners.len()];
        let mut fans = 0;
        for i in 0..corners.len() {
            if seen[i] {
                continue;
            }
            fans += 1;
            // Mark the whole fan through i, in both directions.
            for dir in [true, false] {
                let mut c = CornerId(corners[i]);
                loop {
                    if let Ok(k) = corners.binary_search(&c.0) {
                        if seen[k] && c.0 != corners[i] {
                            break;
                        }
                        seen[k] = true;
                    }
                    let n = if dir {
                        self.swing(c)
                    } else {
                        self.swing_back(c)
                    };
                    match n {
                        Some(n) if n.0 != corners[i] => c = n,
                        _ => break,
                    }
                }
            }
        }
        fans
    }

    /// Number of corners (three per triangle).
    #[inline]
    pub fn corner_count(&self) -> usize {
        3 * self.triangles.len()
    }

    /// Number of triangles.
    #[inline]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Number of vertices (including unused ones).
    #[inline]
    pub fn vertex_count(&self) -> usize {
        self.vertex_corner.len()
    }

    /// The vertex of every corner, indexed by corner (for hot loops that walk fans).
    #[inline]
    pub fn corner_vertices(&self) -> &[u32] {
        self.triangles.as_flattened()
    }

    /// The vertices of each triangle, indexed by triangle.
    #[inline]
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The table's triangles, as a mesh's triangle list, without copying them (a decoder's
    /// output).
    pub fn into_triangles(self) -> Vec<[u32; 3]> {
        self.triangles
    }

    /// The opposite of every corner, indexed by corner; `u32::MAX` at a boundary.
    #[inline]
    pub fn opposites(&self) -> &[u32] {
        &self.opposite
    }
    /// The connected component of each triangle (through the table's interior edges), named
    /// by its lowest triangle: triangles `a` and `b` are joined exactly when
    /// `components[a] == components[b]`, and `components[t] <= t`.
    pub fn triangle_components(&self) -> Vec<u32> {
        let nt = self.triangles.len();
        let mut uf = crate::topology::UnionFind::new(nt);
        for (c, &o) in self.opposite.iter().enumerate() {
            if o != NONE && o as usize > c {
                uf.union((c / 3) as u32, o / 3);
            }
        }
        (0..nt as u32).map(|t| uf.find(t)).collect()
    }

    /// Mean length of the mesh's edges, each counted once (the table pairs them), for the
    /// `positions` of its vertices; 0 without triangles. The same figure as
    /// [`Mesh::mean_edge_length`] without collecting and sorting the edges (on a 100k-triangle
    /// mesh 6 M instructions instead of 63 M).
    pub fn mean_edge_length(&self, positions: &[glam::DVec3]) -> f64 {
        let (mut sum, mut count) = (0.0, 0usize);
        // Triangle by triangle, in corner order (the same sum): corner j of a triangle faces
        // the edge from vertex j + 1 to j + 2, read without a modulo per corner.
        for (t, (tri, o3)) in self
            .triangles
            .iter()
            .zip(self.opposite.chunks_exact(3))
            .enumerate()
        {
            for (j, (a, b)) in [(tri[1], tri[2]), (tri[2], tri[0]), (tri[0], tri[1])]
                .into_iter()
                .enumerate()
            {
                // Each interior edge from its lower corner, each boundary edge once.
                let o = o3[j];
                if o != NONE && (o as usize) < 3 * t + j {
                    continue;
                }
                sum += positions[a as usize].distance(positions[b as usize]);
                count += 1;
            }
        }
        if count == 0 {
            0.0
        } else {
            sum / count as f64
        }
    }

    /// All corners in order.
    pub fn corners(&self) -> impl Iterator<Item = CornerId> + '_ {
        (0..self.corner_count() as u32).map(CornerId)
    }

    /// Vertex at corner `c`.
    #[inline]
    pub fn vertex(&self, c: CornerId) -> VertexId {
        VertexId(self.corner_vertices()[c.index()])
    }

    /// Next corner of the same triangle (counter-clockwise).
    #[inline]
    pub fn next(&self, c: CornerId) -> CornerId {
        // c % 3 == 2 exactly when c + 1 is a multiple of 3 (corners stay below u32::MAX - 3).
        CornerId(if is_multiple_of_three(c.0 + 1) {
            c.0 - 2
        } else {
            c.0 + 1
        })
    }

    /// Previous corner of the same triangle.
    #[inline]
    pub fn prev(&self, c: CornerId) -> CornerId {
        CornerId(if is_multiple_of_three(c.0) {
            c.0 + 2
        } else {
            c.0 - 1
        })
    }

    /// Corner across the edge opposite `c`; `None` when that edge is a boundary edge.
    #[inline]
    pub fn opposite(&self, c: CornerId) -> Option<CornerId> {
        let o = self.opposite[c.index()];
        (o != NONE).then_some(CornerId(o))
    }

    /// The corner of the same vertex in the next triangle counter-clockwise around it
    /// (`next(opposite(next(c)))`); `None` at a boundary.
    #[inline]
    pub fn swing(&self, c: CornerId) -> Option<CornerId> {
        self.opposite(self.next(c)).map(|o| self.next(o))
    }

    /// The corner of the same vertex in the next triangle clockwise around it
    /// (`prev(opposite(prev(c)))`); `None` at a boundary.
    #[inline]
    pub fn swing_back(&self, c: CornerId) -> Option<CornerId> {
        self.opposite(self.prev(c)).map(|o| self.prev(o))
    }

    /// A corner at `v` from which [`CornerTable::swing`] visits its whole fan (the
    /// clockwise-most one at a boundary); `None` for a vertex no triangle uses.
    #[inline]
    pub fn vertex_corner(&self, v: VertexId) -> Option<CornerId> {
        let c = self.vertex_corner[v.index()];
        (c != NONE).then_some(CornerId(c))
    }

    /// True when the edge opposite `c` is a boundary edge.
    #[inline]
    pub fn is_boundary_corner(&self, c: CornerId) -> bool {
        self.opposite[c.index()] == NONE
    }

    /// The first corner without an opposite (its edge is on a boundary), `None` for a
    /// closed table. Scans the opposites in blocks the compiler vectorizes: a corner by
    /// corner search with its early exit ran a few cycles per corner (about 1 % of an exact
    /// encode, which asks twice).
    pub fn first_boundary_corner(&self) -> Option<CornerId> {
        const BLOCK: usize = 256;
        let block = self
            .opposite
            .chunks(BLOCK)
            .position(|b| b.iter().fold(false, |open, &o| open | (o == NONE)))?;
        let at = self.opposite[block * BLOCK..]
            .iter()
            .position(|&o| o == NONE)?;
        Some(CornerId((block * BLOCK + at) as u32))
    }

    /// True when `v` lies on a boundary (its fan is open).
    pub fn is_boundary_vertex(&self, v: VertexId) -> bool {
        match self.vertex_corner(v) {
            Some(c) => self.swing_back(c).is_none(),
            None => false,
        }
    }

    /// The corners around `v`, counter-clockwise, starting at [`CornerTable::vertex_corner`].
    pub fn vertex_corners(&self, v: VertexId) -> VertexCorners<'_> {
        let start = self.vertex_corner(v);
        VertexCorners {
            table: self,
            start,
            current: start,
        }
    }

    /// Number of triangles around `v`.
    pub fn valence(&self, v: VertexId) -> usize {
        self.vertex_corners(v).count()
    }
}

/// Iterator over the corners of one vertex; see [`CornerTable::vertex_corners`].
pub struct VertexCorners<'a> {
    table: &'a CornerTable,
    start: Option<CornerId>,
    current: Option<CornerId>,
}

impl Iterator for VertexCorners<'_> {
    type Item = CornerId;
    // Inlined into the callers' fan loops (other crates included): as a call it was a tenth
    // of EdgeSharpener's instructions.
    #[inline]
    fn next(&mut self) -> Option<CornerId> {
        let c = self.current?;
        self.current = self.table.swing(c).filter(|&n| Some(n) != self.start);
        Some(c)
    }
}

/// Position in its triangle of the corner after the one at position `j`.
const NEXT_IN_TRIANGLE: [u32; 3] = [1, 2, 0];

/// The direction bit of the build's bucket entries (see `CornerTable::build`).
const DOWN: u32 = 1 << 31;

/// Whether `x` is a multiple of 3: `x` times the inverse of 3 modulo 2^32 is at most
/// `(2^32 - 1) / 3` exactly for the multiples. One multiply and a compare, where `x % 3 == k`
/// takes a wide multiply, a shift and a subtraction: corner arithmetic (the corner after or
/// before another in its triangle) runs in the inner loops of every table walk.
#[inline(always)]
pub const fn is_multiple_of_three(x: u32) -> bool {
    x.wrapping_mul(0xAAAA_AAAB) <= 0x5555_5555
}

/// Fan walks [`CornerTable::walk_vertex_fans`] advances together.
const FAN_LANES: usize = 8;

#[inline]
fn next_raw(c: usize) -> usize {
    if c % 3 == 2 {
        c - 2
    } else {
        c + 1
    }
}

/// The sizes [`CornerTable::from_raw`] and [`CornerTable::from_relabelled`] accept: whole
/// triangles, one opposite per corner, corner and vertex indices below the `NONE` marker.
/// Returns the corner count.
fn check_corner_arrays(
    triangles: &[[u32; 3]],
    opposite: &[u32],
    vertex_count: usize,
) -> Result<usize, MeshError> {
    let nc = triangles.len().saturating_mul(3);
    if opposite.len() != nc || nc >= NONE as usize {
        return Err(MeshError::TooLarge {
            what: "corner arrays of unequal length",
            count: nc,
        });
    }
    check_vertex_count(vertex_count)?;
    Ok(nc)
}

/// Refuses a vertex count whose indices would reach the `NONE` marker.
fn check_vertex_count(vertex_count: usize) -> Result<(), MeshError> {
    if vertex_count >= NONE as usize {
        return Err(MeshError::TooLarge {
            what: "vertex count",
            count: vertex_count,
        });
    }
    Ok(())
}

#[inline]
fn prev_raw(c: usize) -> usize {
    if c % 3 == 0 {
        c + 2
    } else {
        c - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn triangle_components_name_each_part_by_its_lowest_triangle() {
        // Two tetrahedra, the second's triangles interleaved with the first's.
        let t = |o: u32| {
            [
                [o, o + 1, o + 2],
                [o, o + 3, o + 1],
                [o + 1, o + 3, o + 2],
                [o, o + 2, o + 3],
            ]
        };
        let (a, b) = (t(0), t(4));
        let triangles = vec![a[0], b[0], a[1], b[1], a[2], b[2], a[3], b[3]];
        let table = CornerTable::from_triangles(&triangles, 8).unwrap();
        assert_eq!(table.triangle_components(), vec![0, 1, 0, 1, 0, 1, 0, 1]);
        let empty = CornerTable::from_triangles(&[], 0).unwrap();
        assert!(empty.triangle_components().is_empty());
    }

    fn tetrahedron() -> Mesh {
        Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
        )
    }

    /// Two copies of [`tetrahedron`] sharing its vertices below `shared` (the second's
    /// others renumbered from `shared` on, past the first's), `vertices` in all.
    fn two_tetrahedra(shared: u32, vertices: usize) -> Mesh {
        let t = tetrahedron();
        let offset = vertices as u32 - 4;
        let mut triangles = t.triangles.clone();
        triangles.extend(
            t.triangles
                .iter()
                .map(|tri| tri.map(|v| if v < shared { v } else { v + offset })),
        );
        Mesh::new(vec![DVec3::ZERO; vertices], triangles)
    }

    #[test]
    fn a_closed_build_accepts_a_closed_table_and_names_an_unglued_corner() {
        let t = CornerTable::new(&tetrahedron()).unwrap();
        let (v, o) = (t.triangles().to_vec(), t.opposites().to_vec());
        assert_eq!(
            CornerTable::from_raw_closed(v.clone(), o.clone(), 4, false),
            CornerTable::from_raw(v.clone(), o.clone(), 4, false)
        );
        // Unglue one pair (the edge opposite corner 0 of triangle [0, 2, 1] is (1, 2)).
        let mut cut = o.clone();
        let twin = cut[0] as usize;
        cut[0] = NONE;
        cut[twin] = NONE;
        assert_eq!(
            CornerTable::from_raw_closed(v.clone(), cut.clone(), 4, false),
            Err(MeshError::OpenEdge { a: 1, b: 2 })
        );
        // The open build takes it as a boundary.
        assert!(CornerTable::from_raw(v.clone(), cut, 4, false).is_ok());
        // A corner without a vertex is out of range, as before (in the first triangle, whose
        // own check comes before any pair's).
        let mut lost = v;
        lost[0][1] = NONE;
        assert!(matches!(
            CornerTable::from_raw_closed(lost, o, 4, false),
            Err(MeshError::IndexOutOfRange { .. })
        ));
    }

    #[test]
    fn a_renumbering_build_is_the_build_of_the_renumbered_triangles() {
        let t = CornerTable::new(&tetrahedron()).unwrap();
        let (v, o) = (t.triangles().to_vec(), t.opposites().to_vec());
        let map = [2, 0, 3, 1];
        let renumbered: Vec<[u32; 3]> = v.iter().map(|t| t.map(|x| map[x as usize])).collect();
        let want = CornerTable::from_raw_closed(renumbered, o.clone(), 4, false).unwrap();
        let got =
            CornerTable::from_raw_closed_renumbering(v.clone(), o.clone(), &map, 4, vec![7; 9]);
        assert_eq!(got, Ok(want));
        // A vertex without a number, a map too short, a number past the count: refused.
        for (map, count) in [
            (vec![2, 0, u32::MAX, 1], 4),
            (vec![2, 0, 3], 4),
            (vec![2, 0, 3, 1], 3),
        ] {
            let r =
                CornerTable::from_raw_closed_renumbering(v.clone(), o.clone(), &map, count, vec![]);
            assert!(
                matches!(r, Err(MeshError::IndexOutOfRange { .. })),
                "{map:?}: {r:?}"
            );
        }
    }

    #[test]
    fn mean_edge_length_matches_the_mesh_s() {
        let mesh = Mesh::new(
            vec![
                DVec3::ZERO,
                DVec3::X,
                DVec3::Y,
                -DVec3::X,
                -DVec3::Y,
                DVec3::Z * 2.0,
            ],
            vec![
                [0, 1, 5],
                [0, 5, 2],
                [0, 2, 3],
                [0, 3, 4],
                [0, 4, 1],
                [1, 2, 5],
            ],
        );
        let table = CornerTable::new(&mesh).unwrap();
        let (a, b) = (
            table.mean_edge_length(&mesh.positions),
            mesh.mean_edge_length(),
        );
        assert!((a - b).abs() <= 1e-12 * b, "{a} {b}");
        let empty = Mesh::new(vec![DVec3::ZERO], Vec::new());
        assert_eq!(
            CornerTable::new(&empty)
                .unwrap()
                .mean_edge_length(&empty.positions),
            0.0
        );
    }

    #[test]
    fn tetrahedron_is_closed_and_consistent() {
        let m = tetrahedron();
        let t = CornerTable::new(&m).unwrap();
        assert_eq!(t.corner_count(), 12);
        for c in t.corners() {
            let o = t.opposite(c).expect("closed mesh");
            assert_eq!(t.opposite(o), Some(c));
            // The edge opposite c and the edge opposite o are the same edge, reversed.
            assert_eq!(t.vertex(t.next(c)), t.vertex(t.prev(o)));
            assert_eq!(t.vertex(t.prev(c)), t.vertex(t.next(o)));
            assert_eq!(t.vertex(t.swing(c).unwrap()), t.vertex(c));
            assert_eq!(t.swing_back(t.swing(c).unwrap()), Some(c));
        }
        for v in 0..4 {
            assert_eq!(t.valence(VertexId(v)), 3);
            assert!(!t.is_boundary_vertex(VertexId(v)));
        }
    }

    #[test]
    fn swing_is_counter_clockwise() {
        // A fan of four triangles around vertex 0 in the xy plane, seen from +z.
        let m = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y],
            vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]],
        );
        let t = CornerTable::new(&m).unwrap();
        let order: Vec<u32> = t
            .vertex_corners(VertexId(0))
            .map(|c| t.vertex(t.next(c)).0)
            .collect();
        // Counter-clockwise: the next vertex after the corner advances 1, 2, 3, 4 cyclically.
        let pos = order.iter().position(|&v| v == 1).unwrap();
        let rotated: Vec<u32> = (0..4).map(|i| order[(pos + i) % 4]).collect();
        assert_eq!(rotated, vec![1, 2, 3, 4]);
    }

    #[test]
    fn open_fan_starts_at_its_clockwise_end() {
        // Three triangles of a fan around vertex 0, open between 4 and 1.
        let m = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y],
            vec![[0, 2, 3], [0, 1, 2], [0, 3, 4]],
        );
        let t = CornerTable::new(&m).unwrap();
        assert!(t.is_boundary_vertex(VertexId(0)));
        let around: Vec<u32> = t
            .vertex_corners(VertexId(0))
            .map(|c| t.vertex(t.next(c)).0)
            .collect();
        assert_eq!(around, vec![1, 2, 3]);
        assert_eq!(t.valence(VertexId(0)), 3);
        let boundary = t.corners().filter(|&c| t.is_boundary_corner(c)).count();
        assert_eq!(boundary, 5, "three rim edges and two spokes are open");
    }

    #[test]
    fn refuses_non_manifold_edge() {
        let m = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z],
            vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
        );
        assert_eq!(
            CornerTable::new(&m),
            Err(MeshError::NonManifoldEdge {
                a: 0,
                b: 1,
                count: 3
            })
        );
    }

    #[test]
    fn the_first_boundary_corner_is_the_lowest_open_one() {
        let t = tetrahedron();
        assert_eq!(CornerTable::new(&t).unwrap().first_boundary_corner(), None);
        // A strip long enough to span blocks, open at its ends and sides.
        let n = 700u32;
        let positions = (0..2 * n).map(|i| DVec3::new(i as f64, 0.0, 0.0)).collect();
        let triangles = (0..n - 1)
            .flat_map(|i| {
                [
                    [2 * i, 2 * i + 2, 2 * i + 1],
                    [2 * i + 1, 2 * i + 2, 2 * i + 3],
                ]
            })
            .collect();
        let strip = CornerTable::new(&Mesh::new(positions, triangles)).unwrap();
        let want = strip.corners().find(|&c| strip.is_boundary_corner(c));
        assert!(want.is_some());
        assert_eq!(strip.first_boundary_corner(), want);
    }

    #[test]
    fn a_hub_vertex_with_a_long_bucket_is_paired() {
        // A bipyramid over a 20-gon: vertex 0's bucket holds 40 half-edges, a long run of
        // the one-pass pairing; the table must still be consistent.
        let n = 20u32;
        let mut triangles = Vec::new();
        for i in 0..n {
            let (a, b) = (2 + i, 2 + (i + 1) % n);
            triangles.push([0, a, b]);
            triangles.push([1, b, a]);
        }
        let positions = (0..n + 2).map(|i| DVec3::new(i as f64, 0.0, 0.0)).collect();
        let t = CornerTable::new(&Mesh::new(positions, triangles)).unwrap();
        assert_eq!(t.first_boundary_corner(), None);
        let raw = CornerTable::from_raw(
            t.triangles().to_vec(),
            t.opposites().to_vec(),
            t.vertex_count(),
            true,
        );
        assert_eq!(raw, Ok(t));
    }

    #[test]
    fn refuses_an_edge_of_four_triangles_in_two_consistent_pairs() {
        // Two tetrahedra glued along edge 0-1: every bucket pairs, but the bucket of vertex
        // 0 holds four half-edges to vertex 1 (the one-pass pairing must not pair them
        // two by two).
        let m = two_tetrahedra(2, 6);
        assert_eq!(
            CornerTable::new(&m),
            Err(MeshError::NonManifoldEdge {
                a: 0,
                b: 1,
                count: 4
            })
        );
    }

    #[test]
    fn the_buckets_direction_bit_changes_no_table_and_no_error() {
        // The fast pairing reads directions from the bucket entries; without the bit
        // (meshes of 2^31 vertices or more) every bucket is sorted and reads them from the
        // triangles. Both must give the same table or the same error.
        let mut flipped = tetrahedron();
        flipped.triangles[2].swap(0, 1);
        let mut hub = Vec::new();
        for i in 0..20u32 {
            let (a, b) = (2 + i, 2 + (i + 1) % 20);
            hub.push([0, a, b]);
            hub.push([1, b, a]);
        }
        let cases: Vec<(Vec<[u32; 3]>, usize)> = vec![
            (tetrahedron().triangles, 4),
            (flipped.triangles, 4),
            (two_tetrahedra(2, 6).triangles, 6),
            (two_tetrahedra(1, 7).triangles, 7),
            (vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]], 5),
            (vec![[0, 1, 2], [0, 3, 4]], 5),
            (vec![[0, 1, 2], [0, 1, 3]], 4),
            (vec![[0, 1, 2], [2, 1, 3]], 4),
            (hub, 22),
        ];
        for (tris, nv) in cases {
            for walk in [true, false] {
                let with_bit = CornerTable::build_with(&tris, nv, walk, DOWN, &mut Scratch::new());
                let sorted = CornerTable::build_with(&tris, nv, walk, 0, &mut Scratch::new());
                assert_eq!(with_bit, sorted, "{tris:?}");
            }
        }
    }

    #[test]
    fn refuses_a_flipped_triangle_of_a_closed_mesh() {
        // Every edge has two half-edges (no boundary): the one-pass pairing sees twins of
        // one direction.
        let mut m = tetrahedron();
        m.triangles[2].swap(0, 1);
        assert!(matches!(
            CornerTable::new(&m),
            Err(MeshError::InconsistentOrientation { .. })
        ));
        assert!(matches!(
            CornerTable::from_triangles_deferring_fans(&m.triangles, 4),
            Err(MeshError::InconsistentOrientation { .. })
        ));
    }

    #[test]
    fn deferred_fan_check_finds_pinched_closed_fans() {
        // Two tetrahedra sharing vertex 0: two closed fans around it.
        let m = two_tetrahedra(1, 7);
        let t = tetrahedron();
        assert!(matches!(
            CornerTable::new(&m),
            Err(MeshError::NonManifoldVertex { vertex: 0, .. })
        ));
        let table = CornerTable::from_triangles_deferring_fans(&m.triangles, 7).unwrap();
        assert!(matches!(
            table.check_fans(),
            Err(MeshError::NonManifoldVertex { vertex: 0, .. })
        ));
        let ok = CornerTable::from_triangles_deferring_fans(&t.triangles, 4).unwrap();
        assert_eq!(ok.check_fans(), Ok(()));
        assert_eq!(ok, CornerTable::new(&t).unwrap());
    }

    /// `count` tetrahedra, each sharing one vertex with the one before where `pinch` says
    /// so (a vertex with two closed fans), vertex labels spread by `stride` (or the next
    /// number coprime to the vertex count) so that the pinched vertices fall in various lanes and chunks of the
    /// fan walks.
    fn tetrahedron_chain(count: usize, pinch: &[bool], stride: usize) -> (Vec<[u32; 3]>, usize) {
        let t = tetrahedron();
        let mut triangles = Vec::new();
        let mut next = 0u32;
        let mut last = 0u32;
        for k in 0..count {
            let shared = k > 0 && pinch[k % pinch.len()];
            let ids: Vec<u32> = (0..4)
                .map(|j| {
                    if j == 0 && shared {
                        last
                    } else {
                        next += 1;
                        next - 1
                    }
                })
                .collect();
            last = ids[3];
            triangles.extend(t.triangles.iter().map(|tri| tri.map(|v| ids[v as usize])));
        }
        let nv = next as usize;
        let gcd = |mut a: usize, mut b: usize| {
            while b != 0 {
                (a, b) = (b, a % b);
            }
            a
        };
        let stride = (stride..).find(|&s| gcd(s, nv) == 1).unwrap_or(1);
        let label = |v: u32| ((v as usize * stride) % nv) as u32;
        (triangles.iter().map(|tri| tri.map(label)).collect(), nv)
    }

    #[test]
    fn multiples_of_three_by_the_inverse() {
        for x in (0..100_000u32).chain(u32::MAX - 100_000..=u32::MAX) {
            assert_eq!(is_multiple_of_three(x), x % 3 == 0, "{x}");
        }
    }

    #[test]
    fn walking_fans_together_finds_what_single_walks_find() {
        for (count, pinch, stride) in [
            (12, &[false][..], 5),
            (12, &[false, false, true][..], 5),
            (30, &[false, false, false, false, false, true][..], 7),
            (30, &[true, false][..], 11),
            (40, &[false; 9][..], 13),
            (
                40,
                &[false, false, false, false, false, false, false, false, true][..],
                3,
            ),
        ] {
            let (tris, nv) = tetrahedron_chain(count, pinch, stride);
            let deferred = CornerTable::from_triangles_deferring_fans(&tris, nv).unwrap();
            let (valence, open_fans) = deferred.fan_counts();
            // The reference: one walk per vertex, in vertex order.
            let single = (0..nv).try_for_each(|v| deferred.check_fan(v, &valence, &open_fans));
            assert_eq!(single.is_err(), pinch.contains(&true));
            assert_eq!(
                deferred.check_vertex_fans(&valence, &open_fans, true),
                single
            );
            assert_eq!(deferred.fans_cover_all_corners(), single.is_ok());
            assert_eq!(deferred.check_fans(), single);
            assert_eq!(CornerTable::from_triangles(&tris, nv).err(), single.err());
        }
    }

    #[test]
    fn refuses_bow_tie() {
        let m = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y],
            vec![[0, 1, 2], [0, 3, 4]],
        );
        assert!(matches!(
            CornerTable::new(&m),
            Err(MeshError::NonManifoldVertex { vertex: 0, .. })
        ));
    }

    #[test]
    fn refuses_flipped_neighbour() {
        let m = Mesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, -DVec3::Y],
            vec![[0, 1, 2], [0, 1, 3]],
        );
        assert!(matches!(
            CornerTable::new(&m),
            Err(MeshError::InconsistentOrientation { a: 1, b: 0, .. })
                | Err(MeshError::InconsistentOrientation { a: 0, b: 1, .. })
        ));
    }

    #[test]
    fn refuses_bad_indices() {
        let m = Mesh::new(vec![DVec3::ZERO, DVec3::X], vec![[0, 1, 2]]);
        assert!(matches!(
            CornerTable::new(&m),
            Err(MeshError::IndexOutOfRange { index: 2, .. })
        ));
        let m = Mesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 1]]);
        assert!(matches!(
            CornerTable::new(&m),
            Err(MeshError::RepeatedVertex { vertex: 1, .. })
        ));
    }

    /// Triangles of an n x n grid of quads, each split along a chosen diagonal, with the
    /// odd interior quads that `holes` picks left out, in the order given by `perm` (vertex indices relabelled
    /// by `relabel`).
    fn grid(
        n: u32,
        diagonals: &[bool],
        holes: &[bool],
        perm: &[usize],
        relabel: &[u32],
    ) -> Vec<[u32; 3]> {
        let mut tris = Vec::new();
        for y in 0..n {
            for x in 0..n {
                let q = (y * n + x) as usize;
                // Holes only at odd interior quads: never two touching, never at the rim, so
                // every vertex keeps a single fan.
                let interior = x % 2 == 1 && y % 2 == 1 && x + 1 < n && y + 1 < n;
                if interior && holes[q % holes.len()] {
                    continue;
                }
                let v = |dx: u32, dy: u32| relabel[((y + dy) * (n + 1) + x + dx) as usize];
                let (a, b, c, d) = (v(0, 0), v(1, 0), v(1, 1), v(0, 1));
                if diagonals[q % diagonals.len()] {
                    tris.push([a, b, c]);
                    tris.push([a, c, d]);
                } else {
                    tris.push([a, b, d]);
                    tris.push([b, c, d]);
                }
            }
        }
        perm.iter()
            .filter(|&&i| i < tris.len())
            .map(|&i| tris[i])
            .collect()
    }

    proptest::proptest! {
        /// The build's own fan bookkeeping (valences, open fans and start corners gathered
        /// while pairing) gives the table `from_raw`'s separate pass gives from the same
        /// opposites, and both refuse the same inputs.
        #[test]
        fn build_matches_the_separate_fan_pass(
            n in 1u32..8,
            diagonals in proptest::collection::vec(proptest::bool::ANY, 1..9),
            holes in proptest::collection::vec(proptest::bool::weighted(0.25), 1..11),
            seed in 0u64..u64::MAX,
        ) {
            let nv = ((n + 1) * (n + 1)) as usize;
            // A deterministic shuffle of triangles and vertex labels from the seed.
            let mut state = seed | 1;
            let mut rand = |m: usize| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state % m as u64) as usize
            };
            let mut perm: Vec<usize> = (0..2 * (n * n) as usize).collect();
            for i in (1..perm.len()).rev() {
                perm.swap(i, rand(i + 1));
            }
            let mut relabel: Vec<u32> = (0..nv as u32).collect();
            for i in (1..nv).rev() {
                relabel.swap(i, rand(i + 1));
            }
            let tris = grid(n, &diagonals, &holes, &perm, &relabel);
            let built = CornerTable::from_triangles(&tris, nv);
            proptest::prop_assert!(built.is_ok(), "{:?}", built);
            let Ok(t) = built else { unreachable!() };
            // Without the closed-fan walk the table is the same.
            let deferred = CornerTable::from_triangles_deferring_fans(&tris, nv);
            proptest::prop_assert_eq!(deferred.as_ref(), Ok(&t));
            // And without the buckets' direction bit (every bucket sorted).
            let sorted = CornerTable::build_with(&tris, nv, true, 0, &mut Scratch::new());
            proptest::prop_assert_eq!(sorted.as_ref(), Ok(&t));
            let raw = CornerTable::from_raw(
                t.triangles().to_vec(),
                t.opposites().to_vec(),
                nv,
                true,
            );
            proptest::prop_assert_eq!(raw, Ok(t.clone()));
            // A grid is open: the closed build names one of its boundary edges.
            let closed = CornerTable::from_raw_closed(
                t.triangles().to_vec(),
                t.opposites().to_vec(),
                nv,
                false,
            );
            let Err(MeshError::OpenEdge { a, b }) = closed else {
                return Err(proptest::test_runner::TestCaseError::fail(format!(
                    "an open grid built closed: {closed:?}"
                )));
            };
            let open = (0..t.corner_count()).any(|c| {
                let c = CornerId(c as u32);
                let (x, y) = (t.vertex(t.next(c)).0, t.vertex(t.prev(c)).0);
                t.opposite(c).is_none() && (x.min(y), x.max(y)) == (a, b)
            });
            proptest::prop_assert!(open, "({}, {}) is not a boundary edge", a, b);
            // Arrays of a checked table: the sequential constructor picks the same starts.
            let relabelled = CornerTable::from_relabelled(
                t.triangles().to_vec(),
                t.opposites().to_vec(),
                nv,
            );
            proptest::prop_assert_eq!(relabelled, Ok(t));
        }
    }

    proptest::proptest! {
        /// The one-sum fan test agrees with the per-vertex check on every table the deferred
        /// build accepts: grids with holes whose vertices are merged in pairs, which pinches
        /// fans (closed with closed, open with open, open with closed) wherever the merge
        /// keeps the edges manifold.
        #[test]
        fn the_fan_sum_is_the_per_vertex_check(
            n in 1u32..7,
            diagonals in proptest::collection::vec(proptest::bool::ANY, 1..9),
            holes in proptest::collection::vec(proptest::bool::weighted(0.3), 1..11),
            merges in proptest::collection::vec((0u32..64, 0u32..64), 0..4),
        ) {
            let nv = ((n + 1) * (n + 1)) as usize;
            let perm: Vec<usize> = (0..2 * (n * n) as usize).collect();
            let relabel: Vec<u32> = (0..nv as u32).collect();
            let mut tris = grid(n, &diagonals, &holes, &perm, &relabel);
            // A second copy of the grid, so merges can pinch two sheets at a vertex.
            let copy: Vec<[u32; 3]> = tris.iter().map(|t| t.map(|v| v + nv as u32)).collect();
            tris.extend(copy);
            let total = 2 * nv;
            let mut to = (0..total as u32).collect::<Vec<u32>>();
            for (a, b) in merges {
                let (a, b) = (a as usize % total, b as usize % total);
                to[b] = to[a];
            }
            let merged: Vec<[u32; 3]> = tris.iter().map(|t| t.map(|v| to[v as usize])).collect();
            if let Ok(t) = CornerTable::from_triangles_deferring_fans(&merged, total) {
                let detailed = {
                    let (valence, open_fans) = t.fan_counts();
                    (0..t.vertex_corner.len()).all(|v| t.check_fan(v, &valence, &open_fans).is_ok())
                };
                proptest::prop_assert_eq!(t.fans_cover_all_corners(), detailed);
                proptest::prop_assert_eq!(
                    t.check_fans().is_ok(),
                    CornerTable::from_triangles(&merged, total).is_ok()
                );
            }
        }
    }

    #[test]
    fn from_relabelled_refuses_what_would_index_out_of_bounds() {
        let t = CornerTable::from_triangles(&[[0, 1, 2], [0, 2, 3]], 4).unwrap();
        let (cv, opp) = (t.triangles().to_vec(), t.opposites().to_vec());
        assert!(CornerTable::from_relabelled(cv.clone(), opp.clone(), 3).is_err());
        let mut bad = opp.clone();
        bad[0] = 6;
        assert!(CornerTable::from_relabelled(cv.clone(), bad, 4).is_err());
        assert!(CornerTable::from_relabelled(cv[..1].to_vec(), opp[..5].to_vec(), 4).is_err());
        assert!(CornerTable::from_relabelled(cv, opp[..3].to_vec(), 4).is_err());
    }
}
