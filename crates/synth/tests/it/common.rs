//! Shared helpers: shape construction, rotations, geometric measures.

use glam::{DQuat, DVec3};
use whet_mesh::Mesh;
use whet_synth::{Shape, ShapeKind, ShapeParams, SplitMix64};

pub fn shape(kind: ShapeKind) -> Shape {
    Shape::new(kind, &ShapeParams::default()).unwrap()
}

/// A generic rotation: no crease stays aligned with the grid.
pub fn generic_rotation() -> DQuat {
    DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7)
}

pub fn rotated(kind: ShapeKind, q: DQuat) -> Shape {
    Shape::new(kind, &ShapeParams::default().with_rotation(q)).unwrap()
}

/// Signed volume enclosed by a closed mesh (divergence theorem).
pub fn volume(m: &Mesh) -> f64 {
    (0..m.triangles.len())
        .map(|t| {
            let [a, b, c] = m.triangle_positions(t);
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

/// Central-difference gradient.
pub fn gradient(shape: &Shape, p: DVec3, h: f64) -> DVec3 {
    let d = |e: DVec3| (shape.sdf(p + e * h) - shape.sdf(p - e * h)) / (2.0 * h);
    DVec3::new(d(DVec3::X), d(DVec3::Y), d(DVec3::Z))
}

/// Uniform random points on the mesh surface (area-weighted), reproducible from `seed`.
pub fn surface_samples(m: &Mesh, n: usize, seed: u64) -> Vec<DVec3> {
    let areas = m.face_areas();
    let mut cdf = Vec::with_capacity(areas.len());
    let mut acc = 0.0;
    for a in &areas {
        acc += a;
        cdf.push(acc);
    }
    let mut rng = SplitMix64::new(seed);
    (0..n)
        .map(|_| {
            let x = rng.next_f64() * acc;
            let t = cdf.partition_point(|&c| c < x).min(areas.len() - 1);
            let [a, b, c] = m.triangle_positions(t);
            let (mut u, mut v) = (rng.next_f64(), rng.next_f64());
            if u + v > 1.0 {
                u = 1.0 - u;
                v = 1.0 - v;
            }
            a + (b - a) * u + (c - a) * v
        })
        .collect()
}

/// Closest point on triangle `abc` to `p`.
pub fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
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
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Distance from `p` to the mesh surface, by brute force.
pub fn distance_to_mesh(m: &Mesh, p: DVec3) -> f64 {
    (0..m.triangles.len())
        .map(|t| {
            let [a, b, c] = m.triangle_positions(t);
            (closest_on_triangle(p, a, b, c) - p).length()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Newton steps along the numerical gradient onto the zero set.
pub fn project_to_surface(shape: &Shape, mut p: DVec3) -> Option<DVec3> {
    for _ in 0..50 {
        let d = shape.sdf(p);
        if d.abs() < 1e-13 {
            return Some(p);
        }
        let g = gradient(shape, p, 1e-7);
        let g2 = g.length_squared();
        if g2 < 1e-6 {
            return None;
        }
        p -= g * (d / g2);
    }
    None
}

/// Angle between the normals of the two triangles on each interior edge: (vertex a, vertex
/// b, triangle 0, triangle 1).
pub fn edge_pairs(m: &Mesh) -> Vec<(u32, u32, usize, usize)> {
    let mut half: Vec<(u64, u32, u32, usize)> = Vec::new();
    for (t, tri) in m.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            half.push((whet_mesh::edge_key(a, b), a, b, t));
        }
    }
    half.sort_unstable();
    half.windows(2)
        .filter(|w| w[0].0 == w[1].0)
        .map(|w| (w[0].1, w[0].2, w[0].3, w[1].3))
        .collect()
}
