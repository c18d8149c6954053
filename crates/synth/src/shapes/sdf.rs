//! Signed distance primitives (negative inside). Each says whether it is exact.
//!
//! Two facts the shapes rely on: the minimum of exact SDFs (a union) is exact *outside* the
//! union and a 1-Lipschitz lower bound of the distance inside; the maximum (an intersection) is
//! exact *inside* and a 1-Lipschitz lower bound outside. Both have the exact zero set.

use glam::{DVec2, DVec3};

/// Exact SDF of the axis-aligned box `|p_i| <= half_i`.
#[inline]
pub(crate) fn sd_box(p: DVec3, half: DVec3) -> f64 {
    let q = p.abs() - half;
    q.max(DVec3::ZERO).length() + q.max_element().min(0.0)
}

/// Exact SDF of the box `|p_i| <= half_i` with all edges and corners rounded by radius `r`
/// (the Minkowski sum of the box shrunk by `r` and a ball of radius `r`).
#[inline]
pub(crate) fn sd_round_box(p: DVec3, half: DVec3, r: f64) -> f64 {
    sd_box(p, half - DVec3::splat(r)) - r
}

/// Exact SDF of the extrusion `|z| <= hz` of a 2-D region whose exact SDF at `(x, y)` is `d2`.
#[inline]
pub(crate) fn sd_extrude(d2: f64, z: f64, hz: f64) -> f64 {
    let w = DVec2::new(d2, z.abs() - hz);
    w.max_element().min(0.0) + w.max(DVec2::ZERO).length()
}

/// Distance from `p` to the segment `ab` in 2-D.
#[inline]
pub(crate) fn dist_segment2(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).length()
}

/// Crossing-number point-in-polygon test (even-odd), for a closed polygon.
pub(crate) fn inside_polygon2(p: DVec2, poly: &[DVec2]) -> bool {
    let mut inside = false;
    let n = poly.len();
    let mut j = n.wrapping_sub(1);
    for i in 0..n {
        let (a, b) = (poly[i], poly[j]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

/// A circular arc of less than half a turn, for distances.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Arc2 {
    pub center: DVec2,
    pub radius: f64,
    /// Endpoint with the arc running counter-clockwise from `start` to `end` about `center`.
    pub start: DVec2,
    pub end: DVec2,
}

impl Arc2 {
    /// Distance from `p` to the arc.
    #[inline]
    pub(crate) fn distance(&self, p: DVec2) -> f64 {
        let u = p - self.center;
        let e0 = self.start - self.center;
        let e1 = self.end - self.center;
        // Inside the (convex, less than a half turn) sector: the nearest point is radial.
        if e0.perp_dot(u) >= 0.0 && u.perp_dot(e1) >= 0.0 {
            (u.length() - self.radius).abs()
        } else {
            (p - self.start).length().min((p - self.end).length())
        }
    }

    /// True when `p` lies strictly in the circular segment between the arc and its chord.
    #[inline]
    pub(crate) fn in_segment(&self, p: DVec2) -> bool {
        let chord = self.end - self.start;
        // The arc runs counter-clockwise, so the segment lies to the right of start -> end.
        chord.perp_dot(p - self.start) < 0.0
            && (p - self.center).length_squared() < self.radius * self.radius
    }
}

/// Closest point to `p` on the triangle `abc` (Ericson, Real-Time Collision Detection 5.1.5).
pub(crate) fn closest_point_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return a + ab * v;
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return a + ac * w;
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return b + (c - b) * w;
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    a + ab * v + ac * w
}

/// A 2-D polygon in the meridian half-plane `(rho, y)`, `rho >= 0`, revolved about the y axis.
/// Edges lying on the axis are not part of the surface and are left out of the distance, which
/// makes the SDF exact: the nearest surface point of a solid of revolution lies in the point's
/// own meridian half-plane.
#[derive(Clone, Debug)]
pub(crate) struct Revolved {
    /// Polygon vertices `(rho, y)`, counter-clockwise.
    pub poly: Vec<DVec2>,
    /// Edges `i -> i+1` that are on the surface (not on the axis).
    pub surface_edge: Vec<bool>,
}

impl Revolved {
    pub(crate) fn new(poly: Vec<DVec2>) -> Self {
        let n = poly.len();
        let surface_edge = (0..n)
            .map(|i| !(poly[i].x == 0.0 && poly[(i + 1) % n].x == 0.0))
            .collect();
        Revolved { poly, surface_edge }
    }

    /// Exact SDF at the point with axis distance `rho` and height `y`.
    #[inline]
    pub(crate) fn sdf(&self, rho: f64, y: f64) -> f64 {
        let q = DVec2::new(rho, y);
        let n = self.poly.len();
        let mut d = f64::INFINITY;
        for i in 0..n {
            if self.surface_edge[i] {
                d = d.min(dist_segment2(q, self.poly[i], self.poly[(i + 1) % n]));
            }
        }
        if inside_polygon2(q, &self.poly) {
            -d
        } else {
            d
        }
    }
}

/// A convex polyhedron's exact SDF: inside, the largest signed plane distance; outside, the
/// distance to the nearest face polygon, where only faces the point is in front of can hold the
/// nearest point.
#[derive(Clone, Debug)]
pub(crate) struct ConvexSdf {
    /// Outward unit normal and offset of each face plane (`n . x = d` on the face).
    pub planes: Vec<(DVec3, f64)>,
    /// Each face as triangles (a fan of its convex polygon).
    pub face_triangles: Vec<Vec<[DVec3; 3]>>,
}

impl ConvexSdf {
    #[inline]
    pub(crate) fn sdf(&self, p: DVec3) -> f64 {
        let mut max_plane = f64::NEG_INFINITY;
        let mut outside = f64::INFINITY;
        for (f, &(n, d)) in self.planes.iter().enumerate() {
            let s = n.dot(p) - d;
            max_plane = max_plane.max(s);
            if s > 0.0 {
                for t in &self.face_triangles[f] {
                    let q = closest_point_triangle(p, t[0], t[1], t[2]);
                    outside = outside.min((p - q).length());
                }
            }
        }
        if max_plane > 0.0 {
            outside
        } else {
            max_plane
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_sdf_is_euclidean() {
        let h = DVec3::new(0.5, 0.35, 0.25);
        assert_eq!(sd_box(DVec3::ZERO, h), -0.25);
        assert!((sd_box(DVec3::new(1.5, 0.0, 0.0), h) - 1.0).abs() < 1e-15);
        // Beyond a corner: the distance to the corner.
        let p = DVec3::new(1.5, 1.35, 1.25);
        assert!((sd_box(p, h) - 3f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn triangle_closest_point_regions() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        assert_eq!(
            closest_point_triangle(DVec3::new(-1.0, -1.0, 0.0), a, b, c),
            a
        );
        assert_eq!(
            closest_point_triangle(DVec3::new(0.25, 0.25, 3.0), a, b, c),
            DVec3::new(0.25, 0.25, 0.0)
        );
        let q = closest_point_triangle(DVec3::new(1.0, 1.0, 0.0), a, b, c);
        assert!((q - DVec3::new(0.5, 0.5, 0.0)).length() < 1e-15);
        assert_eq!(
            closest_point_triangle(DVec3::new(0.5, -2.0, 1.0), a, b, c),
            DVec3::new(0.5, 0.0, 0.0)
        );
    }

    #[test]
    fn arc_distance_and_segment() {
        let arc = Arc2 {
            center: DVec2::ZERO,
            radius: 1.0,
            start: DVec2::X,
            end: DVec2::Y,
        };
        assert!((arc.distance(DVec2::new(2.0, 2.0)) - (8f64.sqrt() - 1.0)).abs() < 1e-15);
        assert!((arc.distance(DVec2::new(-1.0, 0.0)) - 2f64.sqrt()).abs() < 1e-15);
        assert_eq!(arc.distance(DVec2::ZERO), 1.0);
        assert!(arc.in_segment(DVec2::new(0.69, 0.69)));
        assert!(!arc.in_segment(DVec2::new(0.4, 0.4)));
        assert!(!arc.in_segment(DVec2::new(0.8, 0.8)));
    }

    #[test]
    fn revolved_cone_is_exact() {
        // Cone of base radius 1 at y = 0 and apex at y = 1.
        let cone = Revolved::new(vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 1.0),
        ]);
        assert_eq!(cone.surface_edge, vec![true, true, false]);
        // On the axis inside: nearest is the slanted side or the base.
        let d = cone.sdf(0.0, 0.25);
        assert!((d + 0.25).abs() < 1e-15, "{d}");
        let d = cone.sdf(0.0, 0.5);
        assert!((d + 0.5 / 2f64.sqrt()).abs() < 1e-15, "{d}");
        assert!((cone.sdf(0.0, 2.0) - 1.0).abs() < 1e-15);
    }
}
