//! Exact closest point on a triangle (Ericson, *Real-Time Collision Detection*, 5.1.5).
//!
//! The point `p` is classified into one of the seven Voronoi regions of the triangle (three
//! vertices, three edges, the face) with dot products only; the face case projects onto the
//! plane through barycentric coordinates. Every division is guarded, so zero-area triangles
//! (coincident or collinear corners) fall back to the closest point on their three edges, which
//! is exactly the closest point of the degenerate triangle, and the result is never NaN for
//! finite input.

use glam::DVec3;

/// Closest point to `p` on the segment `a`-`b` (on `a` when the segment has zero length).
#[inline]
pub fn closest_point_on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let ab = b - a;
    let len2 = ab.dot(ab);
    if len2 > 0.0 {
        let t = ((p - a).dot(ab) / len2).clamp(0.0, 1.0);
        a + ab * t
    } else {
        a
    }
}

/// Closest point to `p` on the triangle `a b c` (closed: boundary and interior).
///
/// Exact up to rounding for every position of `p` (all seven Voronoi regions) and robust for
/// degenerate triangles: a triangle whose corners coincide or are collinear is treated as the
/// union of its edges.
///
/// ```
/// use whet_metro::closest_point_on_triangle;
/// use glam::DVec3;
///
/// let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
/// // Above the face: the foot of the perpendicular.
/// let q = closest_point_on_triangle(DVec3::new(0.25, 0.25, 2.0), a, b, c);
/// assert!((q - DVec3::new(0.25, 0.25, 0.0)).length() < 1e-15);
/// // Beyond corner b: the corner itself.
/// assert_eq!(closest_point_on_triangle(DVec3::new(3.0, -1.0, 0.0), a, b, c), b);
/// ```
#[inline]
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    if is_degenerate(a, b, c) {
        return closest_on_edges(p, a, b, c);
    }
    closest_point_on_proper_triangle(p, a, b, c)
}

/// True when the triangle is (numerically) degenerate: a segment or a point, whose closest
/// points are those of its edges. The Voronoi tests of Ericson's method assume a proper
/// triangle (its vertex tests stay valid, but a zero-length edge or collinear corners can
/// fool the edge tests). The threshold only catches triangles narrower than about 1e-12 of
/// their edge lengths, for which the edges are the closest points up to that width.
#[inline]
pub(crate) fn is_degenerate(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let ab = b - a;
    let ac = c - a;
    let n2 = ab.cross(ac).length_squared();
    // (NaN compares as degenerate, which takes the careful path.)
    n2.partial_cmp(&(1e-24 * ab.length_squared() * ac.length_squared()))
        != Some(std::cmp::Ordering::Greater)
}

/// [`closest_point_on_triangle`] for a triangle known not to be degenerate
/// (`!is_degenerate(a, b, c)`); on a degenerate one the answer is a point of the triangle,
/// but not necessarily the closest.
#[inline]
pub(crate) fn closest_point_on_proper_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let ab = b - a;
    let ac = c - a;

    // Vertex region of a.
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }

    // Vertex region of b.
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }

    // Edge region of ab. Here d1 >= 0 >= d3, so d1 - d3 = |ab|^2 >= 0; it is zero only when
    // a == b, and then a is the answer.
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let den = d1 - d3;
        let v = if den > 0.0 { d1 / den } else { 0.0 };
        return a + ab * v;
    }

    // Vertex region of c.
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }

    // Edge region of ac (d2 - d6 = |ac|^2).
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let den = d2 - d6;
        let w = if den > 0.0 { d2 / den } else { 0.0 };
        return a + ac * w;
    }

    // Edge region of bc ((d4 - d3) + (d5 - d6) = |bc|^2).
    let va = d3 * d6 - d5 * d4;
    let e1 = d4 - d3;
    let e2 = d5 - d6;
    if va <= 0.0 && e1 >= 0.0 && e2 >= 0.0 {
        let den = e1 + e2;
        let w = if den > 0.0 { e1 / den } else { 0.0 };
        return b + (c - b) * w;
    }

    // Face region: va + vb + vc = |ab x ac|^2. For a proper triangle all three are positive
    // here; if rounding or a degenerate triangle says otherwise, the triangle is (numerically)
    // a segment and its edges hold the answer.
    let den = va + vb + vc;
    if va >= 0.0 && vb >= 0.0 && vc >= 0.0 && den > 0.0 {
        let v = vb / den;
        let w = vc / den;
        return a + ab * v + ac * w;
    }
    closest_on_edges(p, a, b, c)
}

/// Closest point on the boundary of the triangle: the best of its three edges.
#[cold]
fn closest_on_edges(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let mut best = closest_point_on_segment(p, a, b);
    let mut best_d2 = p.distance_squared(best);
    for q in [
        closest_point_on_segment(p, b, c),
        closest_point_on_segment(p, c, a),
    ] {
        let d2 = p.distance_squared(q);
        if d2 < best_d2 {
            best = q;
            best_d2 = d2;
        }
    }
    best
}

/// Squared distance from `p` to the triangle `a b c`.
#[inline]
pub fn point_triangle_distance_squared(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    p.distance_squared(closest_point_on_triangle(p, a, b, c))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Brute force: the best of a dense barycentric lattice refined around its best point, and
    /// the exact edges (which cover every boundary region exactly).
    fn brute_force_distance(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
        let mut best = f64::INFINITY;
        for (s, t) in [(a, b), (b, c), (c, a)] {
            best = best.min(p.distance(closest_point_on_segment(p, s, t)));
        }
        // Interior: the plane foot when it lies inside (direct formula through solving the
        // 2x2 normal equations), otherwise only the boundary matters.
        let ab = b - a;
        let ac = c - a;
        let (g11, g12, g22) = (ab.dot(ab), ab.dot(ac), ac.dot(ac));
        let det = g11 * g22 - g12 * g12;
        if det > 1e-300 {
            let r = p - a;
            let (r1, r2) = (r.dot(ab), r.dot(ac));
            let v = (g22 * r1 - g12 * r2) / det;
            let w = (g11 * r2 - g12 * r1) / det;
            if v >= 0.0 && w >= 0.0 && v + w <= 1.0 {
                best = best.min(p.distance(a + ab * v + ac * w));
            }
        }
        best
    }

    /// Dense sampling of the triangle: an upper bound that converges to the distance.
    fn sampled_distance(p: DVec3, a: DVec3, b: DVec3, c: DVec3, n: usize) -> f64 {
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=(n - i) {
                let v = i as f64 / n as f64;
                let w = j as f64 / n as f64;
                let q = a + (b - a) * v + (c - a) * w;
                best = best.min(p.distance(q));
            }
        }
        best
    }

    fn region_of(q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> &'static str {
        let eps = 1e-12;
        let near = |x: DVec3, y: DVec3| x.distance(y) < eps;
        if near(q, a) {
            return "A";
        }
        if near(q, b) {
            return "B";
        }
        if near(q, c) {
            return "C";
        }
        let on = |s: DVec3, t: DVec3| q.distance(closest_point_on_segment(q, s, t)) < eps;
        if on(a, b) {
            return "AB";
        }
        if on(b, c) {
            return "BC";
        }
        if on(c, a) {
            return "CA";
        }
        "F"
    }

    #[test]
    fn all_seven_voronoi_regions() {
        let a = DVec3::new(0.0, 0.0, 0.0);
        let b = DVec3::new(2.0, 0.0, 0.0);
        let c = DVec3::new(0.5, 1.5, 0.0);
        let n = (b - a).cross(c - a).normalize();
        let centroid = (a + b + c) / 3.0;
        let cases = [
            (a + DVec3::new(-1.0, -1.0, 0.3), "A"),
            (b + DVec3::new(1.0, -0.5, -0.2), "B"),
            (c + DVec3::new(0.0, 1.0, 0.7), "C"),
            ((a + b) * 0.5 + DVec3::new(0.0, -1.0, 0.4), "AB"),
            ((b + c) * 0.5 + DVec3::new(1.0, 0.7, -0.4), "BC"),
            ((c + a) * 0.5 + DVec3::new(-1.0, 0.2, 0.1), "CA"),
            (centroid + n * 0.8, "F"),
        ];
        for (p, want) in cases {
            let q = closest_point_on_triangle(p, a, b, c);
            assert_eq!(region_of(q, a, b, c), want, "p = {p}, q = {q}");
            let d = p.distance(q);
            let exact = brute_force_distance(p, a, b, c);
            assert!((d - exact).abs() < 1e-12, "{want}: {d} vs {exact}");
            let sampled = sampled_distance(p, a, b, c, 400);
            assert!(d <= sampled + 1e-12, "{want}: {d} > sampled {sampled}");
            assert!(
                sampled - d < 1e-2,
                "{want}: sampled {sampled} far above {d}"
            );
        }
    }

    #[test]
    fn degenerate_triangles() {
        let a = DVec3::new(1.0, 2.0, 3.0);
        let p = DVec3::new(4.0, -1.0, 0.5);
        // All corners equal.
        assert_eq!(closest_point_on_triangle(p, a, a, a), a);
        // Two corners equal: a segment.
        let b = DVec3::new(3.0, 2.0, 3.0);
        for (x, y, z) in [(a, a, b), (a, b, a), (b, a, a), (a, b, b)] {
            let q = closest_point_on_triangle(p, x, y, z);
            let want = closest_point_on_segment(p, a, b);
            assert!(q.distance(want) < 1e-12, "{q} vs {want}");
        }
        // Collinear corners, middle one in any slot.
        let m = (a + b) * 0.5;
        for (x, y, z) in [(a, m, b), (m, a, b), (a, b, m)] {
            for p in [p, m + DVec3::Y, a - DVec3::X, b + DVec3::X] {
                let q = closest_point_on_triangle(p, x, y, z);
                let want = closest_point_on_segment(p, a, b);
                assert!(q.is_finite());
                assert!(
                    (p.distance(q) - p.distance(want)).abs() < 1e-12,
                    "{q} vs {want}"
                );
            }
        }
    }

    fn coord() -> impl Strategy<Value = f64> {
        -10.0f64..10.0
    }
    fn point() -> impl Strategy<Value = DVec3> {
        (coord(), coord(), coord()).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    proptest! {
        #[test]
        fn matches_brute_force(p in point(), a in point(), b in point(), c in point()) {
            let q = closest_point_on_triangle(p, a, b, c);
            let d = p.distance(q);
            let exact = brute_force_distance(p, a, b, c);
            let scale = 1.0 + p.length() + a.length() + b.length() + c.length();
            prop_assert!((d - exact).abs() <= 1e-9 * scale, "{} vs {}", d, exact);
            // The returned point lies on the triangle: nothing on it is closer to q than 0.
            prop_assert!(brute_force_distance(q, a, b, c) <= 1e-9 * scale);
        }

        #[test]
        fn never_nan_on_degenerate(p in point(), a in point(), b in point(), t in 0.0f64..1.0) {
            let c = a + (b - a) * t;
            let q = closest_point_on_triangle(p, a, b, c);
            prop_assert!(q.is_finite());
            let want = p.distance(closest_point_on_segment(p, a, b));
            prop_assert!((p.distance(q) - want).abs() <= 1e-9 * (1.0 + want));
        }
    }
}
