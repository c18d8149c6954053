//! Bender (Attene, Falcidieno, Spagnuolo, Rossignac, "Sharpen&Bend", ACM TOG 2005, section
//! 4.2), with the stencils of `../shared/docs/algorithms.md` section 4.
//!
//! One level splits every triangle 1-to-4; old vertices never move (the scheme interpolates)
//! and every edge gets one new point computed from the old mesh only:
//!
//! ```text
//!  sharp edge (V, W)            both V, W manifold sharp (2 sharp edges each): four-point
//!     u --- V ===p=== W --- x       p = 9/16 (V + W) - 1/16 (u + x)
//!                               both non-manifold (1 or 3+ sharp edges): midpoint
//!                               V non-manifold, W manifold: W's other sharp edge (W, X)
//!                                 mirrored across E's bisector gives V's: X', then four-point
//!
//!  smooth edge (a, b)                 neither end on >= 2 sharp edges:
//!        e_ac     c     e_bc            both valence 6: butterfly 1/2, 1/8, -1/16
//!            \   / \   /                otherwise Zorin's modified butterfly around each
//!             \ /   \ /                 extraordinary end (averaged when both are)
//!              a --p-- b              one end cut (>= 2 sharp edges, i.e. the topological
//!             / \   / \                 cut of S&B 4.2.2): Zorin's stencil centred at the
//!            /   \ /   \                other end (its ring never crosses a cut)
//!        e_ad     d     e_bd          both ends cut: the butterfly with every wing across a
//!                                       sharp edge replaced by its reflection x + y - z
//! ```
//!
//! Mesh boundaries are sharp edges (four-point, cut at their vertices), so meshes with both
//! boundaries and tags work. Tags propagate: a sharp edge's two halves are sharp, so levels
//! can be repeated. Invariants: weights always sum to one (affine invariance: planar regions
//! stay planar), and nothing reads across a cut except wings at a chain end (a vertex with one
//! sharp edge is smooth by the paper's rule). An end of valence over 64 takes the edge's
//! butterfly in place of its Zorin stencil: that stencil reads the whole ring, once per
//! edge, which is quadratic in the valence (a stream can decode to such a vertex).
//!
//! Not handled: non-manifold input (refused with the corner table's error); the exact
//! Zorin-2003 boundary-sector coefficients of S&B Figure 13 (lost; algorithms.md 4.4 gives the
//! rules used instead).

use crate::Error;
use whet_mesh::{edge_key, CornerId, CornerTable, DVec3, Mesh, VertexId};

const NONE: u32 = u32::MAX;

/// The result of [`bend`].
#[derive(Clone, Debug, PartialEq)]
pub struct Bent {
    /// The refined mesh: old vertices first (unchanged), then one new vertex per old edge.
    pub mesh: Mesh,
    /// The sharp edges of the refined mesh (`[a, b]`, `a < b`, sorted): the halves of every
    /// input sharp edge.
    pub sharp_edges: Vec<[u32; 2]>,
}

/// Largest valence whose vertices get Zorin's stencil; past it an edge takes the butterfly
/// (`Context::zorin_or_butterfly`).
const MAX_STENCIL_VALENCE: usize = 64;

/// Zorin's modified-butterfly weights `s_0..s_{k-1}` for an extraordinary vertex of valence `k`
/// (Zorin, Schröder, Sweldens 1996; the centre gets 3/4). `libm`'s cosine keeps the results
/// identical on every machine.
pub fn zorin_weights(k: usize) -> Vec<f64> {
    match k {
        0 => Vec::new(),
        1 => vec![0.25],
        2 => vec![0.25, 0.0],
        3 => vec![5.0 / 12.0, -1.0 / 12.0, -1.0 / 12.0],
        4 => vec![3.0 / 8.0, 0.0, -1.0 / 8.0, 0.0],
        _ => (0..k)
            .map(|j| {
                let t = 2.0 * std::f64::consts::PI * j as f64 / k as f64;
                (0.25 + libm::cos(t) + 0.5 * libm::cos(2.0 * t)) / k as f64
            })
            .collect(),
    }
}

struct Context<'a> {
    table: &'a CornerTable,
    pos: &'a [DVec3],
    /// Per corner: the edge facing it is sharp (tagged or a boundary).
    sharp_corner: Vec<bool>,
    /// Per vertex: its sharp neighbours (the other ends of its sharp edges).
    sharp_nbrs: Vec<Vec<u32>>,
    /// Zorin weights by valence, cached.
    weights: Vec<Vec<f64>>,
}

impl Context<'_> {
    #[inline]
    fn p(&self, v: VertexId) -> DVec3 {
        self.pos[v.index()]
    }

    #[inline]
    fn sharp_degree(&self, v: u32) -> usize {
        self.sharp_nbrs[v as usize].len()
    }

    /// Four-point (or its degenerate forms) on the sharp edge `(v, w)`.
    fn sharp_point(&self, v: u32, w: u32) -> DVec3 {
        let (pv, pw) = (self.pos[v as usize], self.pos[w as usize]);
        let other = |x: u32, not: u32| -> Option<u32> {
            let n = &self.sharp_nbrs[x as usize];
            if n.len() == 2 {
                n.iter().copied().find(|&y| y != not)
            } else {
                None
            }
        };
        match (other(v, w), other(w, v)) {
            (Some(u), Some(x)) => {
                (pv + pw) * (9.0 / 16.0) - (self.pos[u as usize] + self.pos[x as usize]) / 16.0
            }
            (None, None) => (pv + pw) * 0.5,
            (None, Some(x)) => self.reflected(pv, pw, self.pos[x as usize]),
            (Some(u), None) => self.reflected(pw, pv, self.pos[u as usize]),
        }
    }

    /// S&B Figure 13-R6: `v` non-manifold, `w` manifold with other sharp neighbour `x`.
    fn reflected(&self, pv: DVec3, pw: DVec3, px: DVec3) -> DVec3 {
        let e = pw - pv;
        let len = e.length();
        if len == 0.0 || !len.is_finite() {
            return (pv + pw) * 0.5;
        }
        let e = e / len;
        let m = (pv + pw) * 0.5;
        let x_mirror = px - e * (2.0 * (px - m).dot(e));
        (pv + pw) * (9.0 / 16.0) - (x_mirror + px) / 16.0
    }

    /// Zorin's stencil centred at the vertex of corner `c` for the edge towards `v(next c)`.
    fn zorin_at(&self, c: CornerId) -> DVec3 {
        let t = self.table;
        let centre = self.p(t.vertex(c));
        // Neighbours counter-clockwise from v(next c): each swing's next vertex is the
        // previous corner's prev vertex.
        let mut ring: [DVec3; 16] = [DVec3::ZERO; 16];
        let mut spill: Vec<DVec3> = Vec::new();
        let mut k = 0usize;
        let mut cur = c;
        loop {
            let n = self.p(t.vertex(t.next(cur)));
            if k < 16 {
                ring[k] = n;
            } else {
                if k == 16 {
                    spill.extend_from_slice(&ring);
                }
                spill.push(n);
            }
            k += 1;
            match t.swing(cur) {
                Some(s) if s != c && k <= t.corner_count() => cur = s,
                _ => break,
            }
        }
        let w = &self.weights[k.min(self.weights.len() - 1)];
        let ring: &[DVec3] = if k <= 16 { &ring[..k] } else { &spill };
        let mut p = centre * 0.75;
        for (j, q) in ring.iter().enumerate() {
            p += *q * w.get(j).copied().unwrap_or(0.0);
        }
        p
    }

    /// Valence (triangles around the vertex) from one of its corners, counted up to
    /// `MAX_STENCIL_VALENCE + 1` (any valence past the stencils' reads as that).
    fn valence(&self, c: CornerId) -> usize {
        let t = self.table;
        let mut k = 1usize;
        let mut cur = c;
        while let Some(s) = t.swing(cur) {
            if s == c || k > MAX_STENCIL_VALENCE {
                break;
            }
            k += 1;
            cur = s;
        }
        k
    }

    /// Zorin's stencil at the vertex of corner `c` (valence `k`) for the edge facing `e`
    /// (opposite `o`); past `MAX_STENCIL_VALENCE` the butterfly of the edge instead (with
    /// ghost wings across sharp edges when `ghosts`): the stencil of such a vertex reads its
    /// whole ring, once for each of its edges, quadratic in its valence, and such a vertex
    /// is no surface sample a smooth limit is expected from.
    fn zorin_or_butterfly(
        &self,
        c: CornerId,
        k: usize,
        e: CornerId,
        o: CornerId,
        ghosts: bool,
    ) -> DVec3 {
        if k > MAX_STENCIL_VALENCE {
            self.butterfly(e, o, ghosts)
        } else {
            self.zorin_at(c)
        }
    }

    /// New point of the smooth interior edge facing corner `c` (it has an opposite).
    fn smooth_point(&self, c: CornerId, o: CornerId) -> DVec3 {
        let t = self.table;
        // Triangle (c, a, b) and (o, b, a): edge a - b.
        let ca = t.next(c);
        let cb = t.prev(c);
        let a = t.vertex(ca).0;
        let b = t.vertex(cb).0;
        let a_cut = self.sharp_degree(a) >= 2;
        let b_cut = self.sharp_degree(b) >= 2;
        match (a_cut, b_cut) {
            (false, false) => {
                // Corners at a and b whose next vertex is the other end: at a, the corner n(c)
                // of triangle (c, a, b); at b, the corner n(o) of triangle (o, b, a).
                let at_a = ca;
                let at_b = t.next(o);
                let (ka, kb) = (self.valence(at_a), self.valence(at_b));
                match (ka == 6, kb == 6) {
                    (true, true) => self.butterfly(c, o, false),
                    (false, true) => self.zorin_or_butterfly(at_a, ka, c, o, false),
                    (true, false) => self.zorin_or_butterfly(at_b, kb, c, o, false),
                    (false, false) => {
                        (self.zorin_or_butterfly(at_a, ka, c, o, false)
                            + self.zorin_or_butterfly(at_b, kb, c, o, false))
                            * 0.5
                    }
                }
            }
            (true, false) => {
                let at_b = t.next(o);
                self.zorin_or_butterfly(at_b, self.valence(at_b), c, o, true)
            }
            (false, true) => self.zorin_or_butterfly(ca, self.valence(ca), c, o, true),
            (true, true) => self.butterfly(c, o, true),
        }
    }

    /// The 8-point butterfly on the edge facing `c`; with `ghosts`, a wing across a sharp
    /// edge is replaced by the reflection `x + y - z` of the triangle's far vertex.
    fn butterfly(&self, c: CornerId, o: CornerId, ghosts: bool) -> DVec3 {
        let t = self.table;
        let (ca, cb) = (t.next(c), t.prev(c));
        let (pa, pb) = (self.p(t.vertex(ca)), self.p(t.vertex(cb)));
        let pc = self.p(t.vertex(c));
        let pd = self.p(t.vertex(o));
        // Wing across the edge facing corner `corner` of a triangle whose third vertex (the
        // one not on that edge, seen from the far side) is `z`.
        let wing = |corner: CornerId, x: DVec3, y: DVec3, z: DVec3| -> DVec3 {
            match t.opposite(corner) {
                Some(op) if !(ghosts && self.sharp_corner[corner.index()]) => self.p(t.vertex(op)),
                _ => x + y - z,
            }
        };
        // In triangle (c, a, b): edge (c, a) faces cb, edge (b, c) faces ca.
        let e_ac = wing(cb, pa, pc, pb);
        let e_bc = wing(ca, pb, pc, pa);
        // In triangle (o, b, a): edge (a, d) faces n(o) (the b corner), edge (d, b) faces p(o).
        let e_ad = wing(t.next(o), pa, pd, pb);
        let e_bd = wing(t.prev(o), pb, pd, pa);
        (pa + pb) * 0.5 + (pc + pd) * 0.125 - (e_ac + e_bc + e_ad + e_bd) * 0.0625
    }
}

/// One level of Bender on `mesh` with `sharp_edges` tagged (`[a, b]` in any order; edges not
/// in the mesh are ignored). Mesh boundaries count as sharp.
pub fn bend(mesh: &Mesh, sharp_edges: &[[u32; 2]]) -> Result<Bent, Error> {
    if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::NonFinite { vertex: v });
    }
    let table = CornerTable::new(mesh)?;
    let nv = mesh.positions.len();
    let nc = table.corner_count();
    let mut tagged: Vec<u64> = sharp_edges
        .iter()
        .filter(|e| e[0] != e[1])
        .map(|e| edge_key(e[0], e[1]))
        .collect();
    tagged.sort_unstable();
    tagged.dedup();
    let is_tagged = |a: u32, b: u32| tagged.binary_search(&edge_key(a, b)).is_ok();

    // A pillow: two triangles over the same three vertices, back to back (whet-swing codes a
    // component smaller than L that way). Split, they would give every inner edge four
    // triangles (both halves share the edge points), so they pass through unchanged.
    let pillow: Vec<bool> = (0..table.triangle_count())
        .map(|t| {
            let first = table
                .opposite(CornerId(3 * t as u32))
                .map(|o| o.index() / 3);
            first.is_some()
                && (1..3).all(|k| {
                    table
                        .opposite(CornerId((3 * t + k) as u32))
                        .map(|o| o.index() / 3)
                        == first
                })
        })
        .collect();

    // Edges: one id per undirected edge, assigned to both corners facing it.
    let mut edge_of_corner = vec![NONE; nc];
    let mut edge_corner: Vec<u32> = Vec::with_capacity(nc / 2 + 1);
    let mut sharp_corner = vec![false; nc];
    let mut sharp_nbrs: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for c in table.corners() {
        if edge_of_corner[c.index()] != NONE || pillow[c.index() / 3] {
            continue;
        }
        let id = edge_corner.len() as u32;
        edge_corner.push(c.0);
        edge_of_corner[c.index()] = id;
        let a = table.vertex(table.next(c)).0;
        let b = table.vertex(table.prev(c)).0;
        let opp = table.opposite(c);
        let sharp = opp.is_none() || is_tagged(a, b);
        sharp_corner[c.index()] = sharp;
        if let Some(o) = opp {
            edge_of_corner[o.index()] = id;
            sharp_corner[o.index()] = sharp;
        }
        if sharp {
            sharp_nbrs[a as usize].push(b);
            sharp_nbrs[b as usize].push(a);
        }
    }
    let ctx = Context {
        table: &table,
        pos: &mesh.positions,
        sharp_corner,
        sharp_nbrs,
        weights: (0..=MAX_STENCIL_VALENCE).map(zorin_weights).collect(),
    };

    let ne = edge_corner.len();
    let mut positions = Vec::with_capacity(nv + ne);
    positions.extend_from_slice(&mesh.positions);
    for &c in &edge_corner {
        let c = CornerId(c);
        let a = table.vertex(table.next(c)).0;
        let b = table.vertex(table.prev(c)).0;
        let p = if ctx.sharp_corner[c.index()] {
            ctx.sharp_point(a, b)
        } else {
            // Smooth edges are interior (boundary edges are sharp).
            match table.opposite(c) {
                Some(o) => ctx.smooth_point(c, o),
                None => ctx.sharp_point(a, b),
            }
        };
        positions.push(p);
    }

    let mut triangles = Vec::with_capacity(4 * mesh.triangles.len());
    for t in 0..table.triangle_count() {
        let c0 = CornerId((3 * t) as u32);
        let (c1, c2) = (table.next(c0), table.prev(c0));
        let [v0, v1, v2] = [c0, c1, c2].map(|c| table.vertex(c).0);
        if pillow[t] {
            triangles.push([v0, v1, v2]);
            continue;
        }
        // The edge point facing corner c lies between the other two vertices.
        let m = |c: CornerId| nv as u32 + edge_of_corner[c.index()];
        let (m12, m20, m01) = (m(c0), m(c1), m(c2));
        triangles.push([v0, m01, m20]);
        triangles.push([v1, m12, m01]);
        triangles.push([v2, m20, m12]);
        triangles.push([m01, m12, m20]);
    }

    let mut out_sharp: Vec<[u32; 2]> = Vec::new();
    for (id, &c) in edge_corner.iter().enumerate() {
        let c = CornerId(c);
        if ctx.sharp_corner[c.index()] && table.opposite(c).is_some() {
            let a = table.vertex(table.next(c)).0;
            let b = table.vertex(table.prev(c)).0;
            let m = (nv + id) as u32;
            out_sharp.push([a.min(m), a.max(m)]);
            out_sharp.push([b.min(m), b.max(m)]);
        }
    }
    // A pillow's tagged edges stay tagged (the pillow is unchanged).
    for c in table.corners() {
        if pillow[c.index() / 3] && table.opposite(c).is_some_and(|o| c.0 < o.0) {
            let a = table.vertex(table.next(c)).0;
            let b = table.vertex(table.prev(c)).0;
            if is_tagged(a, b) {
                out_sharp.push([a.min(b), a.max(b)]);
            }
        }
    }
    out_sharp.sort_unstable();
    Ok(Bent {
        mesh: Mesh::new(positions, triangles),
        sharp_edges: out_sharp,
    })
}

/// `levels` levels of [`bend`], propagating the tags.
pub fn bend_levels(mesh: &Mesh, sharp_edges: &[[u32; 2]], levels: u32) -> Result<Bent, Error> {
    // Each level makes four triangles of one (a pillow passes through, so this is an upper
    // bound): the last level's count is checked before the first level runs.
    let mut triangles = mesh.triangles.len();
    for _ in 0..levels {
        match triangles.checked_mul(4) {
            Some(n) if n <= crate::MAX_OUTPUT_TRIANGLES => triangles = n,
            _ => return Err(Error::TooLarge { triangles }),
        }
    }
    let mut cur = Bent {
        mesh: mesh.clone(),
        sharp_edges: sharp_edges.to_vec(),
    };
    for _ in 0..levels {
        cur = bend(&cur.mesh, &cur.sharp_edges)?;
    }
    Ok(cur)
}
