//! Planar shapes: cube, box, pyramid, octahedron and the thin-face box. Their truth meshes are
//! exact (every face triangulated as a fan of its convex polygon, tessellation error 0).

use glam::DVec3;
use whet_mesh::Mesh;

use super::build::Builder;
use super::sdf::ConvexSdf;

/// A convex polyhedron given by vertices and faces (vertex indices in cyclic order, either
/// direction): the truth mesh and the exact SDF data come from the same numbers.
pub(crate) struct Polyhedron {
    pub vertices: Vec<DVec3>,
    pub faces: Vec<Vec<usize>>,
}

impl Polyhedron {
    fn centroid(&self) -> DVec3 {
        self.vertices.iter().copied().sum::<DVec3>() / self.vertices.len() as f64
    }

    /// Outward unit normal of face `f` (Newell's method, turned away from the centroid).
    fn normal(&self, f: usize) -> DVec3 {
        let face = &self.faces[f];
        let mut n = DVec3::ZERO;
        for i in 0..face.len() {
            let a = self.vertices[face[i]];
            let b = self.vertices[face[(i + 1) % face.len()]];
            n += a.cross(b);
        }
        let n = n.normalize();
        let c = face.iter().map(|&i| self.vertices[i]).sum::<DVec3>() / face.len() as f64;
        if n.dot(c - self.centroid()) < 0.0 {
            -n
        } else {
            n
        }
    }

    pub(crate) fn mesh(&self) -> Mesh {
        let mut b = Builder::new();
        let ids = b.vertices(self.vertices.iter().copied());
        for f in 0..self.faces.len() {
            let ring: Vec<u32> = self.faces[f].iter().map(|&i| ids[i]).collect();
            b.convex_polygon(&ring, self.normal(f));
        }
        b.finish()
    }

    pub(crate) fn sdf(&self) -> ConvexSdf {
        let mut planes = Vec::new();
        let mut face_triangles = Vec::new();
        for (f, face) in self.faces.iter().enumerate() {
            let n = self.normal(f);
            // Offset from the face's mean vertex, so every vertex is within rounding of it.
            let c = face.iter().map(|&i| self.vertices[i]).sum::<DVec3>() / face.len() as f64;
            planes.push((n, n.dot(c)));
            let v = |k: usize| self.vertices[face[k]];
            face_triangles.push(
                (1..face.len() - 1)
                    .map(|k| [v(0), v(k), v(k + 1)])
                    .collect(),
            );
        }
        ConvexSdf {
            planes,
            face_triangles,
        }
    }
}

/// The box `|x| <= h.x, |y| <= h.y, |z| <= h.z` (vertex `i` has coordinate signs from its bits).
pub(crate) fn cuboid(h: DVec3) -> Polyhedron {
    let vertices = (0..8)
        .map(|i| {
            let s = |bit: usize| if i >> bit & 1 == 1 { 1.0 } else { -1.0 };
            DVec3::new(s(0) * h.x, s(1) * h.y, s(2) * h.z)
        })
        .collect();
    let faces = vec![
        vec![0, 2, 6, 4], // -x
        vec![1, 3, 7, 5], // +x
        vec![0, 1, 5, 4], // -y
        vec![2, 3, 7, 6], // +y
        vec![0, 1, 3, 2], // -z
        vec![4, 5, 7, 6], // +z
    ];
    Polyhedron { vertices, faces }
}

/// Square base `|x|, |z| <= half` at `y = -height / 2`, apex at `(0, height / 2, 0)`.
pub(crate) fn pyramid(half: f64, height: f64) -> Polyhedron {
    let y0 = -0.5 * height;
    let vertices = vec![
        DVec3::new(-half, y0, -half),
        DVec3::new(half, y0, -half),
        DVec3::new(half, y0, half),
        DVec3::new(-half, y0, half),
        DVec3::new(0.0, 0.5 * height, 0.0),
    ];
    let faces = vec![
        vec![0, 1, 2, 3],
        vec![0, 1, 4],
        vec![1, 2, 4],
        vec![2, 3, 4],
        vec![3, 0, 4],
    ];
    Polyhedron { vertices, faces }
}

/// `|x| + |y| + |z| <= s`.
pub(crate) fn octahedron(s: f64) -> Polyhedron {
    let vertices = vec![
        DVec3::new(s, 0.0, 0.0),
        DVec3::new(-s, 0.0, 0.0),
        DVec3::new(0.0, s, 0.0),
        DVec3::new(0.0, -s, 0.0),
        DVec3::new(0.0, 0.0, s),
        DVec3::new(0.0, 0.0, -s),
    ];
    let mut faces = Vec::new();
    for x in [0, 1] {
        for y in [2, 3] {
            for z in [4, 5] {
                faces.push(vec![x, y, z]);
            }
        }
    }
    Polyhedron { vertices, faces }
}

/// The box `h` with its edge at `y = +h.y, z = +h.z` (parallel to x) cut by a 45-degree
/// chamfer face of width `width`.
pub(crate) fn chamfered_box(h: DVec3, width: f64) -> Polyhedron {
    let c = width / std::f64::consts::SQRT_2;
    let mut vertices = Vec::new();
    for sx in [-1.0, 1.0] {
        let x = sx * h.x;
        vertices.extend([
            DVec3::new(x, -h.y, -h.z),
            DVec3::new(x, h.y, -h.z),
            DVec3::new(x, h.y, h.z - c),
            DVec3::new(x, h.y - c, h.z),
            DVec3::new(x, -h.y, h.z),
        ]);
    }
    // Vertex k on the -x side is k, on the +x side k + 5.
    let faces = vec![
        vec![0, 1, 2, 3, 4],
        vec![5, 6, 7, 8, 9],
        vec![0, 5, 9, 4], // -y
        vec![0, 5, 6, 1], // -z
        vec![1, 6, 7, 2], // +y
        vec![2, 7, 8, 3], // chamfer
        vec![3, 8, 9, 4], // +z
    ];
    Polyhedron { vertices, faces }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polytope_sdf_is_exact_outside_and_inside() {
        let cube = cuboid(DVec3::splat(0.5)).sdf();
        let p = DVec3::new(1.5, 1.5, 0.0);
        assert!((cube.sdf(p) - 2f64.sqrt()).abs() < 1e-15);
        assert!((cube.sdf(DVec3::new(0.2, 0.0, 0.0)) + 0.3).abs() < 1e-15);
        let oct = octahedron(0.5).sdf();
        assert!((oct.sdf(DVec3::new(2.0, 0.0, 0.0)) - 1.5).abs() < 1e-15);
        assert!((oct.sdf(DVec3::ZERO) + 0.5 / 3f64.sqrt()).abs() < 1e-15);
    }
}
