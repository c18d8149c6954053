//! Constructive truth-mesh building: vertices by id (shared pieces are joined by id, never by
//! position), planar faces triangulated exactly, curved faces as strips and patches, and the
//! chordal errors of those tessellations.

use glam::{DVec2, DVec3};
use whet_mesh::Mesh;

use super::sdf::closest_point_triangle;

/// Collects positions and triangles; triangles are oriented by an outward hint where the
/// caller cannot easily order them itself.
#[derive(Default)]
pub(crate) struct Builder {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl Builder {
    pub(crate) fn new() -> Self {
        Builder::default()
    }

    /// Adds a vertex and returns its id.
    pub(crate) fn vertex(&mut self, p: DVec3) -> u32 {
        self.positions.push(p);
        (self.positions.len() - 1) as u32
    }

    /// Adds vertices, returning their ids.
    pub(crate) fn vertices(&mut self, ps: impl IntoIterator<Item = DVec3>) -> Vec<u32> {
        ps.into_iter().map(|p| self.vertex(p)).collect()
    }

    pub(crate) fn pos(&self, v: u32) -> DVec3 {
        self.positions[v as usize]
    }

    /// Adds the triangle as given (counter-clockwise seen from outside).
    pub(crate) fn tri(&mut self, a: u32, b: u32, c: u32) {
        self.triangles.push([a, b, c]);
    }

    /// Adds triangle `abc` oriented so that its normal points along `outward`.
    pub(crate) fn tri_facing(&mut self, a: u32, b: u32, c: u32, outward: DVec3) {
        let n = (self.pos(b) - self.pos(a)).cross(self.pos(c) - self.pos(a));
        if n.dot(outward) >= 0.0 {
            self.tri(a, b, c);
        } else {
            self.tri(a, c, b);
        }
    }

    /// Adds the quad `abcd` (vertices in cyclic order) as two triangles facing `outward`.
    pub(crate) fn quad_facing(&mut self, a: u32, b: u32, c: u32, d: u32, outward: DVec3) {
        self.tri_facing(a, b, c, outward);
        self.tri_facing(a, c, d, outward);
    }

    /// Triangulates a convex planar polygon (vertices in cyclic order) as a fan.
    pub(crate) fn convex_polygon(&mut self, ring: &[u32], outward: DVec3) {
        for i in 1..ring.len().saturating_sub(1) {
            self.tri_facing(ring[0], ring[i], ring[i + 1], outward);
        }
    }

    /// A planar disk: a fan from `center` to the closed `ring`.
    pub(crate) fn disk(&mut self, center: u32, ring: &[u32], outward: DVec3) {
        let n = ring.len();
        for i in 0..n {
            self.tri_facing(center, ring[i], ring[(i + 1) % n], outward);
        }
    }

    /// A strip of quads between two matching polylines; `outward(centroid)` gives the side.
    pub(crate) fn strip(
        &mut self,
        a: &[u32],
        b: &[u32],
        closed: bool,
        outward: impl Fn(DVec3) -> DVec3,
    ) {
        let n = a.len().min(b.len());
        let count = if closed { n } else { n.saturating_sub(1) };
        for i in 0..count {
            let j = (i + 1) % n;
            let c = (self.pos(a[i]) + self.pos(a[j]) + self.pos(b[i]) + self.pos(b[j])) * 0.25;
            self.quad_facing(a[i], a[j], b[j], b[i], outward(c));
        }
    }

    /// A planar face with one circular hole, triangulated by matching rings: `outer` is a
    /// convex polygon and `inner` a closed ring of points on the circle of centre `center`
    /// (both in cyclic order, either direction), all in the plane of normal `normal`.
    ///
    /// Each outer side is joined to the circle point nearest (in angle) to the foot of the
    /// perpendicular from the centre, and each outer corner fans over the circle points between
    /// its two sides' feet. Valid when every circle point a corner fans to is visible from the
    /// corner, which holds for the shapes here (the hole is well inside the face).
    pub(crate) fn annulus(&mut self, outer: &[u32], inner: &[u32], center: DVec3, normal: DVec3) {
        let (u, v) = plane_frame(normal);
        let angle = |p: DVec3| {
            let d = p - center;
            d.dot(v).atan2(d.dot(u))
        };
        let ccw = |ring: &[u32]| -> Vec<u32> {
            let pts: Vec<DVec2> = ring
                .iter()
                .map(|&i| {
                    let d = self.pos(i) - center;
                    DVec2::new(d.dot(u), d.dot(v))
                })
                .collect();
            if signed_area2(&pts) >= 0.0 {
                ring.to_vec()
            } else {
                ring.iter().rev().copied().collect()
            }
        };
        let outer = ccw(outer);
        let inner = ccw(inner);
        let (no, ni) = (outer.len(), inner.len());
        let inner_angles: Vec<f64> = inner.iter().map(|&i| angle(self.pos(i))).collect();
        // For each side k (outer[k] -> outer[k+1]) the circle point nearest the foot angle.
        let foot: Vec<usize> = (0..no)
            .map(|k| {
                let a = self.pos(outer[k]);
                let b = self.pos(outer[(k + 1) % no]);
                let ab = b - a;
                let t = ((center - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
                let phi = angle(a + ab * t);
                let mut best = 0;
                let mut best_d = f64::INFINITY;
                for (j, &aj) in inner_angles.iter().enumerate() {
                    let d = angle_diff(aj, phi).abs();
                    if d < best_d {
                        best_d = d;
                        best = j;
                    }
                }
                best
            })
            .collect();
        for k in 0..no {
            let next = (k + 1) % no;
            // Side triangle.
            self.tri_facing(outer[k], outer[next], inner[foot[k]], normal);
            // Corner `next` fans from foot[k] to foot[next].
            let mut j = foot[k];
            while j != foot[next] {
                let j1 = (j + 1) % ni;
                self.tri_facing(outer[next], inner[j], inner[j1], normal);
                j = j1;
            }
        }
    }

    /// Ear-clipping triangulation of a simple planar polygon given by vertex ids and its 2-D
    /// coordinates in the plane (counter-clockwise seen from `outward`).
    pub(crate) fn simple_polygon(&mut self, ids: &[u32], pts2: &[DVec2], outward: DVec3) {
        for [a, b, c] in ear_clip(pts2) {
            self.tri_facing(ids[a], ids[b], ids[c], outward);
        }
    }

    pub(crate) fn finish(self) -> Mesh {
        Mesh::new(self.positions, self.triangles)
    }
}

/// An orthonormal frame `(u, v)` of the plane with normal `n`, with `u x v = n`.
pub(crate) fn plane_frame(n: DVec3) -> (DVec3, DVec3) {
    let n = n.normalize();
    let u = n.any_orthonormal_vector();
    (u, n.cross(u))
}

fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    if d > std::f64::consts::PI {
        d - std::f64::consts::TAU
    } else {
        d
    }
}

/// Twice the signed area of a 2-D polygon (positive when counter-clockwise).
pub(crate) fn signed_area2(pts: &[DVec2]) -> f64 {
    let n = pts.len();
    (0..n).map(|i| pts[i].perp_dot(pts[(i + 1) % n])).sum()
}

/// Ear clipping of a simple counter-clockwise polygon, choosing at each step the ear with the
/// largest smallest angle. O(n^3), for the few dozen vertices of a profile.
pub(crate) fn ear_clip(pts: &[DVec2]) -> Vec<[usize; 3]> {
    let mut idx: Vec<usize> = (0..pts.len()).collect();
    let mut out = Vec::with_capacity(pts.len().saturating_sub(2));
    while idx.len() > 3 {
        let n = idx.len();
        let mut best: Option<(usize, f64)> = None;
        for k in 0..n {
            let (ia, ib, ic) = (idx[(k + n - 1) % n], idx[k], idx[(k + 1) % n]);
            let (a, b, c) = (pts[ia], pts[ib], pts[ic]);
            if (b - a).perp_dot(c - b) <= 0.0 {
                continue; // reflex or flat
            }
            let blocked = idx.iter().any(|&m| {
                m != ia && m != ib && m != ic && point_in_triangle_closed(pts[m], a, b, c)
            });
            if blocked {
                continue;
            }
            let q = min_angle(a, b, c);
            if best.is_none_or(|(_, bq)| q > bq) {
                best = Some((k, q));
            }
        }
        // A simple polygon always has an ear; if rounding hides every one, clip the first
        // convex-looking vertex rather than loop forever.
        let k = best.map_or(0, |(k, _)| k);
        out.push([idx[(k + n - 1) % n], idx[k], idx[(k + 1) % n]]);
        idx.remove(k);
    }
    if idx.len() == 3 {
        out.push([idx[0], idx[1], idx[2]]);
    }
    out
}

fn point_in_triangle_closed(p: DVec2, a: DVec2, b: DVec2, c: DVec2) -> bool {
    let d1 = (b - a).perp_dot(p - a);
    let d2 = (c - b).perp_dot(p - b);
    let d3 = (a - c).perp_dot(p - c);
    d1 >= 0.0 && d2 >= 0.0 && d3 >= 0.0
}

fn min_angle(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let ang = |p: DVec2, q: DVec2, r: DVec2| (q - p).angle_to(r - p).abs();
    ang(a, b, c).min(ang(b, c, a)).min(ang(c, a, b))
}

/// Chordal error (sagitta) of a circular arc of radius `r` cut into chords of angle `step`.
pub(crate) fn sagitta(r: f64, step: f64) -> f64 {
    r * (1.0 - (0.5 * step).cos())
}

/// Smallest number of chords, a multiple of `multiple`, cutting an arc of radius `r` and angle
/// `span` with sagitta at most `tol`.
pub(crate) fn chords_for(r: f64, span: f64, tol: f64, multiple: usize) -> usize {
    let max_step = 2.0 * (1.0 - (tol / r).min(1.0)).acos();
    let n = (span / max_step).ceil().max(1.0) as usize;
    n.div_ceil(multiple) * multiple
}

/// Points on a circle `center + r (cos t * u + sin t * v)` at `n` equal steps of a full turn.
pub(crate) fn circle(center: DVec3, u: DVec3, v: DVec3, r: f64, n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|k| {
            let t = std::f64::consts::TAU * k as f64 / n as f64;
            center + (u * t.cos() + v * t.sin()) * r
        })
        .collect()
}

/// Largest distance between the sphere `(center, r)` and the triangles `tris` of `mesh` whose
/// corners lie on it: `r` minus the distance from the centre to the nearest triangle point.
pub(crate) fn sphere_patch_error(mesh: &Builder, tris: &[[u32; 3]], center: DVec3, r: f64) -> f64 {
    tris.iter()
        .map(|&[a, b, c]| {
            let q = closest_point_triangle(center, mesh.pos(a), mesh.pos(b), mesh.pos(c));
            r - (q - center).length()
        })
        .fold(0.0, f64::max)
}

/// Unit direction of the octant grid point `(a, b, c)`, `a + b + c = m`, with signs `s`: the
/// map `(sin(a pi / 2m), sin(b pi / 2m), sin(c pi / 2m))` normalised, which spaces the points
/// on the octant's three boundary quarter-circles at equal angles `pi / 2m` and gives exact
/// axis directions at the three poles.
pub(crate) fn octant_dir(a: usize, b: usize, c: usize, m: usize, s: DVec3) -> DVec3 {
    let f = |k: usize| (k as f64 * std::f64::consts::FRAC_PI_2 / m as f64).sin();
    (DVec3::new(f(a), f(b), f(c)) * s).normalize()
}

/// The triangles of an octant grid of side `m`, as index triples into the row-major grid
/// enumerated by [`octant_grid_index`].
pub(crate) fn octant_triangles(m: usize) -> Vec<[usize; 3]> {
    let mut t = Vec::with_capacity(m * m);
    for a in 0..m {
        for b in 0..(m - a) {
            let i = |a: usize, b: usize| octant_grid_index(a, b, m);
            t.push([i(a, b), i(a + 1, b), i(a, b + 1)]);
            if a + b + 2 <= m {
                t.push([i(a + 1, b), i(a + 1, b + 1), i(a, b + 1)]);
            }
        }
    }
    t
}

/// Index of the octant grid point `(a, b, m - a - b)` in the row-major enumeration (rows of
/// constant `a`, each of `m - a + 1` points).
pub(crate) fn octant_grid_index(a: usize, b: usize, m: usize) -> usize {
    // Rows 0..a hold (m+1) + m + ... + (m-a+2) points.
    a * (m + 1) - a * a.saturating_sub(1) / 2 + b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octant_index_is_dense() {
        for m in 1..6 {
            let mut seen = vec![false; (m + 1) * (m + 2) / 2];
            for a in 0..=m {
                for b in 0..=(m - a) {
                    let i = octant_grid_index(a, b, m);
                    assert!(!seen[i]);
                    seen[i] = true;
                }
            }
            assert!(seen.iter().all(|&s| s));
            assert_eq!(octant_triangles(m).len(), m * m);
        }
    }

    #[test]
    fn chords_meet_the_tolerance() {
        let n = chords_for(0.5, std::f64::consts::TAU, 1e-4, 4);
        assert_eq!(n % 4, 0);
        assert!(sagitta(0.5, std::f64::consts::TAU / n as f64) <= 1e-4);
        assert!(sagitta(0.5, std::f64::consts::TAU / (n - 4) as f64) > 1e-4);
    }

    #[test]
    fn ear_clip_handles_a_reflex_polygon() {
        // An L shape.
        let pts = [
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(2.0, 1.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(1.0, 2.0),
            DVec2::new(0.0, 2.0),
        ];
        let tris = ear_clip(&pts);
        assert_eq!(tris.len(), 4);
        let area: f64 = tris
            .iter()
            .map(|t| (pts[t[1]] - pts[t[0]]).perp_dot(pts[t[2]] - pts[t[0]]) * 0.5)
            .sum();
        assert!((area - 3.0).abs() < 1e-12);
        assert!(tris
            .iter()
            .all(|t| (pts[t[1]] - pts[t[0]]).perp_dot(pts[t[2]] - pts[t[0]]) > 0.0));
    }
}
