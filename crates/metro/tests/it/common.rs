//! Mesh generators shared by the integration tests.

use whet_mesh::{DVec3, Mesh};

/// A `n` x `n` grid of squares (two triangles each) over `[0, size]^2` at height
/// `height(x, y)`.
pub fn grid(n: usize, size: f64, height: impl Fn(f64, f64) -> f64) -> Mesh {
    let mut positions = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (size * i as f64 / n as f64, size * j as f64 / n as f64);
            positions.push(DVec3::new(x, y, height(x, y)));
        }
    }
    let mut triangles = Vec::with_capacity(2 * n * n);
    for j in 0..n {
        for i in 0..n {
            let v = (j * (n + 1) + i) as u32;
            let w = v + n as u32 + 1;
            triangles.push([v, v + 1, w + 1]);
            triangles.push([v, w + 1, w]);
        }
    }
    Mesh::new(positions, triangles)
}

/// The axis-aligned unit cube `[0, 1]^3`, 12 outward triangles.
pub fn cube() -> Mesh {
    let positions = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
        .collect();
    let triangles = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    Mesh::new(positions, triangles)
}

/// `mesh` with every vertex moved by `d`.
pub fn translated(mesh: &Mesh, d: DVec3) -> Mesh {
    Mesh::new(
        mesh.positions.iter().map(|&p| p + d).collect(),
        mesh.triangles.clone(),
    )
}

/// A UV sphere of radius `r` with `rings` x `segments` quads split into triangles.
pub fn sphere(rings: usize, segments: usize, r: impl Fn(DVec3) -> f64) -> Mesh {
    let mut positions = vec![DVec3::Z * r(DVec3::Z)];
    for i in 1..rings {
        let theta = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..segments {
            let phi = std::f64::consts::TAU * j as f64 / segments as f64;
            let d = DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            positions.push(d * r(d));
        }
    }
    positions.push(-DVec3::Z * r(-DVec3::Z));
    let south = (positions.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * segments + j % segments) as u32;
    let mut triangles = Vec::new();
    for j in 0..segments {
        triangles.push([0, ring(1, j), ring(1, j + 1)]);
        triangles.push([south, ring(rings - 1, j + 1), ring(rings - 1, j)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j),
                ring(i + 1, j + 1),
            );
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    Mesh::new(positions, triangles)
}
