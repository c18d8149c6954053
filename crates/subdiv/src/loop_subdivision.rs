//! Loop subdivision with Hoppe et al.'s piecewise-smooth rules and Wu, Zheng, Cai & Li's
//! continuous edge sharpness (seed 004 section 3; the rules are restated with their sources in
//! `../shared/docs/sharpening-extras.md` B.1-B.4 and `docs/subdiv.md`).
//!
//! Every control edge carries a sharpness `h` in [0, 1]; boundary edges count as `h = 1`.
//! A vertex is classified by its number `n_v` of incident edges with `h > 0`:
//!
//! ```text
//!   n_v = 0 smooth        n_v = 1 dart          n_v = 2 crease        n_v >= 3 corner
//!     \ | /                 \ | /                 \ | /                 \ | /
//!    --(v)--               ==(v)--               ==(v)==               ==(v)==
//!     / | \                 / | \                 / | \                 / # \
//!   smooth mask           smooth mask       (1-s) smooth + s crease   (1-s) avg + s v
//! ```
//!
//! (`==` and `#` are edges with `h > 0`.) A crease vertex is *regular* when it is interior
//! with six neighbours split 3 | 3 by its two sharp edges, or on a boundary with four
//! neighbours; otherwise it is *extraordinary*.
//!
//! * Edge point: `(1 - h) e_smooth + h e_crease`, with `e_smooth = 3/8 (a + b) + 1/8 (c + d)`
//!   and `e_crease` from Hoppe's table: the smooth mask when an endpoint is a dart,
//!   `3/8 special + 5/8 regular` between a corner or extraordinary crease vertex and a regular
//!   crease vertex, the midpoint otherwise.
//! * Vertex point: the smooth Loop mask `(1 - a(n)) v + a(n)/n sum` with
//!   `a(n) = (40 - (3 + 2 cos(2 pi / n))^2) / 64` for `n_v < 2`;
//!   `(1 - s) v_smooth + s (3/4 v + 1/8 x + 1/8 y)`, `s = (h_x + h_y) / 2`, at a crease;
//!   `(1 - s) v_bar + s v`, `s = sum h / n_v`, at a corner, where `v_bar` averages the crease
//!   points of every pair of sharp edges weighted by `h_j + h_k` (B.3, a reconstruction).
//! * Children of an edge inherit its `h`; edges inside a triangle get `h = 0`.
//! * The first `sharp_levels` levels use the continuous rules; later levels and the limit
//!   masks use Hoppe's binary rules with an edge sharp iff `h = 1` (B.3 [RECON]: DeRose's
//!   semi-sharp edges fall back to smooth rules once their sharpness is used up).
//! * Limit masks (B.4): smooth and dart `3/(3 + 8a)` centre; regular crease 1/6, 2/3, 1/6;
//!   extraordinary crease 1/5, 3/5, 1/5; corners stay.
//!
//! Boundary vertices have no smooth mask; where the blend asks for one they use the boundary
//! crease mask, so an open mesh subdivides like Hoppe's boundary curves. Not handled: Hoppe's
//! modified smooth-edge weights next to extraordinary crease vertices (we use 3/8, 1/8 as the
//! paper's Fig. 1 does), Biermann et al.'s rules. The scheme is discontinuous where `n_v`
//! changes (an `h` leaving 0): that is the paper's definition.
//!
//! All arithmetic is f64 with `libm::cos`, so every machine computes the same surface.

use crate::sparse::{Csr, Row};
use crate::topology::{Topology, NONE};
use whet_mesh::MeshError;

/// Which rules a level uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Rules {
    /// Seed 004's continuous sharpness.
    SemiSharp,
    /// Hoppe's binary rules: an edge is sharp iff `h = 1`.
    Binary,
}

/// An edge counts as fully sharp under the binary rules from this value on.
pub(crate) const SHARP_ONE: f64 = 1.0 - 1e-9;

/// Vertex type of Hoppe et al.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum VertexKind {
    Smooth,
    Dart,
    RegularCrease,
    ExtraordinaryCrease,
    Corner,
}

impl VertexKind {
    #[inline]
    fn special(self) -> bool {
        matches!(self, VertexKind::Corner | VertexKind::ExtraordinaryCrease)
    }
}

/// `a(n)` of seed 004 (= n beta of Loop).
#[inline]
pub(crate) fn loop_a(n: usize) -> f64 {
    let c = 3.0 + 2.0 * libm::cos(2.0 * core::f64::consts::PI / n as f64);
    (40.0 - c * c) / 64.0
}

/// Classifies `v` given the effective sharpness `hl` of the level's edges.
pub(crate) fn classify(topo: &Topology, hl: &[f64], v: usize) -> VertexKind {
    let ring = topo.ring(v);
    let mut count = 0;
    let mut first = usize::MAX;
    let mut second = usize::MAX;
    for (i, &(_, e)) in ring.iter().enumerate() {
        if hl[e as usize] > 0.0 {
            count += 1;
            if first == usize::MAX {
                first = i;
            } else if second == usize::MAX {
                second = i;
            }
        }
    }
    match count {
        0 => VertexKind::Smooth,
        1 => VertexKind::Dart,
        2 => {
            let n = ring.len();
            let regular = if topo.boundary[v] {
                n == 4
            } else {
                n == 6 && second - first == 3
            };
            if regular {
                VertexKind::RegularCrease
            } else {
                VertexKind::ExtraordinaryCrease
            }
        }
        _ => VertexKind::Corner,
    }
}

/// Adds `scale` times the smooth vertex mask of `v` (the boundary crease mask at a boundary).
fn add_smooth(topo: &Topology, v: usize, scale: f64, row: &mut Row) {
    if scale == 0.0 {
        return;
    }
    let ring = topo.ring(v);
    let n = ring.len();
    if topo.boundary[v] {
        row.add(v as u32, 0.75 * scale);
        row.add(ring[0].0, 0.125 * scale);
        row.add(ring[n - 1].0, 0.125 * scale);
        return;
    }
    let a = loop_a(n);
    row.add(v as u32, (1.0 - a) * scale);
    let w = a / n as f64 * scale;
    for &(u, _) in ring {
        row.add(u, w);
    }
}

/// The new position of old vertex `v` as weights over the level's vertices.
pub(crate) fn vertex_row(topo: &Topology, hl: &[f64], v: usize, row: &mut Row) {
    row.clear();
    let ring = topo.ring(v);
    if ring.is_empty() {
        row.add(v as u32, 1.0);
        return;
    }
    // Sharp incident edges: (neighbour, h). Valences are small; a fixed buffer would do, but
    // a corner may have any number of sharp edges.
    let mut sharp: smallvec_lite::Buf = smallvec_lite::Buf::new();
    for &(u, e) in ring {
        let h = hl[e as usize];
        if h > 0.0 {
            sharp.push((u, h));
        }
    }
    let vi = v as u32;
    match sharp.len() {
        0 | 1 => add_smooth(topo, v, 1.0, row),
        2 => {
            let (x, hx) = sharp.get(0);
            let (y, hy) = sharp.get(1);
            let s = 0.5 * (hx + hy);
            add_smooth(topo, v, 1.0 - s, row);
            row.add(vi, 0.75 * s);
            row.add(x, 0.125 * s);
            row.add(y, 0.125 * s);
        }
        k => {
            let sum: f64 = (0..k).map(|i| sharp.get(i).1).sum();
            let s_v = sum / k as f64;
            // Sum over pairs of (h_j + h_k) = (k - 1) * sum.
            let total = (k - 1) as f64 * sum;
            for j in 0..k {
                let (xj, hj) = sharp.get(j);
                for l in j + 1..k {
                    let (xl, hl_) = sharp.get(l);
                    let w = (1.0 - s_v) * (hj + hl_) / total;
                    let s = 0.5 * (hj + hl_);
                    add_smooth(topo, v, w * (1.0 - s), row);
                    row.add(vi, 0.75 * w * s);
                    row.add(xj, 0.125 * w * s);
                    row.add(xl, 0.125 * w * s);
                }
            }
            row.add(vi, s_v);
        }
    }
}

/// The new point on edge `e` as weights over the level's vertices.
pub(crate) fn edge_row(topo: &Topology, hl: &[f64], kinds: &[VertexKind], e: usize, row: &mut Row) {
    row.clear();
    let [a, b] = topo.edges[e];
    let [c, d] = topo.edge_opposite[e];
    let h = if d == NONE { 1.0 } else { hl[e] };
    let add_smooth_edge = |row: &mut Row, s: f64| {
        row.add(a, 0.375 * s);
        row.add(b, 0.375 * s);
        row.add(c, 0.125 * s);
        row.add(d, 0.125 * s);
    };
    if h < 1.0 {
        add_smooth_edge(row, 1.0 - h);
    }
    if h > 0.0 {
        let (ka, kb) = (kinds[a as usize], kinds[b as usize]);
        if (ka == VertexKind::Dart || kb == VertexKind::Dart) && d != NONE {
            add_smooth_edge(row, h);
        } else if ka.special() && kb == VertexKind::RegularCrease {
            row.add(a, 0.375 * h);
            row.add(b, 0.625 * h);
        } else if kb.special() && ka == VertexKind::RegularCrease {
            row.add(b, 0.375 * h);
            row.add(a, 0.625 * h);
        } else {
            row.add(a, 0.5 * h);
            row.add(b, 0.5 * h);
        }
    }
}

/// The limit position of vertex `v` under the binary rules (`hl` binary, `kinds` from it).
///
/// Smooth and dart vertices use Loop's limit mask, corners stay. A crease vertex uses
/// Hoppe's crease limit mask (1/6, 2/3, 1/6 regular; 1/5, 3/5, 1/5 extraordinary) one level
/// later: `limit(v) = c v' + s (e_1 + e_2)`, with `v'` its next position and `e_i` the points
/// of its two sharp edges. That is Hoppe's mask whenever every edge rule around `v` is the
/// plain one, and it stays exact next to corners and extraordinary vertices, where the 3/5
/// edge rule makes the one-level mask wrong (a regular crease vertex beside a corner gets
/// 7/48, 33/48, 8/48): after one split the sharp neighbours of `v` are new, regular vertices.
pub(crate) fn limit_row(
    topo: &Topology,
    hl: &[f64],
    kinds: &[VertexKind],
    v: usize,
    row: &mut Row,
    tmp: &mut Row,
) {
    row.clear();
    let ring = topo.ring(v);
    let vi = v as u32;
    if ring.is_empty() {
        row.add(vi, 1.0);
        return;
    }
    let (centre, side) = match kinds[v] {
        VertexKind::Smooth | VertexKind::Dart => {
            let n = ring.len();
            let a = loop_a(n);
            let denom = 3.0 + 8.0 * a;
            row.add(vi, 3.0 / denom);
            let w = 8.0 * a / (n as f64 * denom);
            for &(u, _) in ring {
                row.add(u, w);
            }
            return;
        }
        VertexKind::Corner => {
            row.add(vi, 1.0);
            return;
        }
        VertexKind::RegularCrease => (2.0 / 3.0, 1.0 / 6.0),
        VertexKind::ExtraordinaryCrease => (0.6, 0.2),
    };
    vertex_row(topo, hl, v, tmp);
    for &(i, w) in &tmp.entries {
        row.add(i, centre * w);
    }
    for &(_, e) in ring {
        if hl[e as usize] > 0.0 {
            edge_row(topo, hl, kinds, e as usize, tmp);
            for &(i, w) in &tmp.entries {
                row.add(i, side * w);
            }
        }
    }
}

/// Tiny inline buffer for the sharp edges of one vertex (no allocation up to 8 entries).
mod smallvec_lite {
    pub(crate) struct Buf {
        inline: [(u32, f64); 8],
        len: usize,
        spill: Vec<(u32, f64)>,
    }
    impl Buf {
        pub fn new() -> Buf {
            Buf {
                inline: [(0, 0.0); 8],
                len: 0,
                spill: Vec::new(),
            }
        }
        pub fn push(&mut self, x: (u32, f64)) {
            if self.len < 8 {
                self.inline[self.len] = x;
            } else {
                self.spill.push(x);
            }
            self.len += 1;
        }
        pub fn len(&self) -> usize {
            self.len
        }
        pub fn get(&self, i: usize) -> (u32, f64) {
            if i < 8 {
                self.inline[i]
            } else {
                self.spill[i - 8]
            }
        }
    }
}

/// The connectivity of every level from the control mesh down, and for every edge of every
/// level the control edge it descends from (`NONE` for edges inside a control triangle).
#[derive(Clone, Debug)]
pub(crate) struct Hierarchy {
    pub levels: Vec<Topology>,
    pub origin: Vec<Vec<u32>>,
}

impl Hierarchy {
    /// Splits the control connectivity `depth` times.
    pub fn new(control: Topology, depth: usize) -> Result<Hierarchy, MeshError> {
        let origin0: Vec<u32> = (0..control.edges.len() as u32).collect();
        let mut levels = vec![control];
        let mut origin = vec![origin0];
        for _ in 0..depth {
            let (Some(prev), Some(prev_origin)) = (levels.last(), origin.last()) else {
                break;
            };
            let next = prev.split()?;
            let nv = prev.vertex_count as u32;
            let o: Vec<u32> = next
                .edges
                .iter()
                .map(|&[x, y]| {
                    if x < nv && y >= nv {
                        prev_origin[(y - nv) as usize]
                    } else {
                        NONE
                    }
                })
                .collect();
            levels.push(next);
            origin.push(o);
        }
        Ok(Hierarchy { levels, origin })
    }

    /// Number of splits.
    pub fn depth(&self) -> usize {
        self.levels.len() - 1
    }

    /// The finest connectivity.
    pub fn finest(&self) -> &Topology {
        // `new` always pushes the control level.
        &self.levels[self.levels.len() - 1]
    }

    /// Effective sharpness of the edges of level `l` under `rules`, given the control
    /// sharpness `h`; boundary edges are 1.
    pub fn level_sharpness(&self, l: usize, h: &[f64], rules: Rules) -> Vec<f64> {
        let topo = &self.levels[l];
        self.origin[l]
            .iter()
            .enumerate()
            .map(|(e, &o)| {
                if topo.is_boundary_edge(e) {
                    1.0
                } else if o == NONE {
                    0.0
                } else {
                    let v = h.get(o as usize).copied().unwrap_or(0.0);
                    match rules {
                        Rules::SemiSharp => v,
                        Rules::Binary => {
                            if v >= SHARP_ONE {
                                1.0
                            } else {
                                0.0
                            }
                        }
                    }
                }
            })
            .collect()
    }

    /// Rules of the split from level `l` to `l + 1`.
    pub fn rules(l: usize, sharp_levels: usize) -> Rules {
        if l < sharp_levels {
            Rules::SemiSharp
        } else {
            Rules::Binary
        }
    }

    /// The matrices of every split (`levels[l + 1] = S[l] levels[l]`) and, when `limit`, the
    /// limit masks of the finest level as a last matrix.
    pub fn stencils(&self, h: &[f64], sharp_levels: usize, limit: bool) -> Vec<Csr> {
        let mut out = Vec::with_capacity(self.depth() + 1);
        let mut row = Row::default();
        for l in 0..self.depth() {
            let topo = &self.levels[l];
            let hl = self.level_sharpness(l, h, Self::rules(l, sharp_levels));
            let kinds: Vec<VertexKind> = (0..topo.vertex_count)
                .map(|v| classify(topo, &hl, v))
                .collect();
            let mut s = Csr::new(topo.vertex_count);
            for v in 0..topo.vertex_count {
                vertex_row(topo, &hl, v, &mut row);
                s.push_row(&row);
            }
            for e in 0..topo.edges.len() {
                edge_row(topo, &hl, &kinds, e, &mut row);
                s.push_row(&row);
            }
            out.push(s);
        }
        if limit {
            let l = self.depth();
            out.push(self.limit_stencil(l, h));
        }
        out
    }

    /// The limit masks of level `l` (binary rules).
    pub fn limit_stencil(&self, l: usize, h: &[f64]) -> Csr {
        let topo = &self.levels[l];
        let hl = self.level_sharpness(l, h, Rules::Binary);
        let kinds: Vec<VertexKind> = (0..topo.vertex_count)
            .map(|v| classify(topo, &hl, v))
            .collect();
        let (mut row, mut tmp) = (Row::default(), Row::default());
        let mut s = Csr::new(topo.vertex_count);
        for v in 0..topo.vertex_count {
            limit_row(topo, &hl, &kinds, v, &mut row, &mut tmp);
            s.push_row(&row);
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn loop_weights_match_the_table() {
        // sharpening-extras B.1: centre weights 1 - a(n).
        let expect = [
            (3, 0.4375),
            (4, 0.515625),
            (5, 0.579534),
            (6, 0.625),
            (7, 0.656826),
        ];
        for (n, c) in expect {
            assert!((1.0 - loop_a(n) - c).abs() < 5e-7, "n = {n}");
        }
    }

    fn octahedron() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let m = whet_testkit::meshes::octahedron();
        (m.positions, m.triangles)
    }

    #[test]
    fn rows_are_affine_for_every_sharpness() {
        let (_, t) = octahedron();
        let topo = Topology::new(t, 6).unwrap();
        let h = [0.0, 0.3, 1.0, 0.7, 0.0, 0.5, 1.0, 0.2, 0.0, 0.9, 1.0, 0.4];
        let hier = Hierarchy::new(topo, 2).unwrap();
        for s in hier.stencils(&h, 1, true) {
            for i in 0..s.rows() {
                let (_, w) = s.row(i);
                let sum: f64 = w.iter().sum();
                assert!((sum - 1.0).abs() < 1e-12, "row {i} sums to {sum}");
            }
        }
    }
}
