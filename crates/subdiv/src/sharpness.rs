//! [`EdgeSharpness`]: one sharpness `h` in [0, 1] per undirected edge of a control mesh, in the
//! canonical edge order of `Mesh::undirected_edges` (sorted `[low, high]` vertex pairs). The
//! codec stores it in that order, so a decoder that rebuilds the control mesh with the same
//! vertex numbering knows which value belongs to which edge without coding the edges.

use crate::Error;
use whet_mesh::{angle_between, edge_key, Mesh};

/// Sharpness of every edge of a control mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct EdgeSharpness {
    edges: Vec<[u32; 2]>,
    values: Vec<f64>,
}

impl EdgeSharpness {
    /// Every edge of `mesh` smooth (`h = 0`): plain Loop subdivision.
    pub fn zeros(mesh: &Mesh) -> EdgeSharpness {
        let edges = mesh.undirected_edges();
        let values = vec![0.0; edges.len()];
        EdgeSharpness { edges, values }
    }

    /// Values aligned with `mesh.undirected_edges()`. Fails unless there is exactly one value
    /// per edge and every value is in [0, 1].
    pub fn from_values(mesh: &Mesh, values: Vec<f64>) -> Result<EdgeSharpness, Error> {
        let edges = mesh.undirected_edges();
        if edges.len() != values.len() {
            return Err(Error::Parameter(format!(
                "{} sharpness values for a mesh with {} edges",
                values.len(),
                edges.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| !(0.0..=1.0).contains(v)) {
            return Err(Error::Parameter(format!(
                "sharpness of edge {i} is {}, outside [0, 1]",
                values[i]
            )));
        }
        Ok(EdgeSharpness { edges, values })
    }

    /// Hoppe et al.'s detection (and seed 004's initial `h`): 1 on every edge whose two
    /// triangles' normals differ by more than `degrees`, and on boundary edges; 0 elsewhere.
    pub fn from_dihedral_angle(mesh: &Mesh, degrees: f64) -> EdgeSharpness {
        let mut s = EdgeSharpness::zeros(mesh);
        let threshold = degrees.to_radians();
        for (e, angle) in dihedral_angles(mesh, &s.edges).into_iter().enumerate() {
            if angle > threshold {
                s.values[e] = 1.0;
            }
        }
        s
    }

    /// Edges, `[low, high]`, sorted.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// One value per edge, in the order of [`EdgeSharpness::edges`].
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Number of edges.
    pub fn len(&self) -> usize {
        self.edges.len()
    }

    /// True for a mesh without edges.
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// Index of edge `{a, b}`.
    pub fn index_of(&self, a: u32, b: u32) -> Option<usize> {
        self.edges.binary_search(&[a.min(b), a.max(b)]).ok()
    }

    /// Sharpness of edge `{a, b}`, if it is an edge.
    pub fn get(&self, a: u32, b: u32) -> Option<f64> {
        self.index_of(a, b).map(|i| self.values[i])
    }

    /// Sets the sharpness of edge `{a, b}` (clamped to [0, 1]; NaN counts as 0).
    pub fn set(&mut self, a: u32, b: u32, h: f64) -> Result<(), Error> {
        let i = self
            .index_of(a, b)
            .ok_or_else(|| Error::Parameter(format!("({a}, {b}) is not an edge")))?;
        self.values[i] = clamp01(h);
        Ok(())
    }

    /// Number of edges with `h > 0`.
    pub fn sharp_count(&self) -> usize {
        self.values.iter().filter(|&&v| v > 0.0).count()
    }

    /// Rounds every value to the nearest of `0, 1/(2^bits - 1), ..., 1` (`bits` in 1..=8).
    pub fn quantized(&self, bits: u32) -> EdgeSharpness {
        let levels = ((1u32 << bits.clamp(1, 8)) - 1) as f64;
        EdgeSharpness {
            edges: self.edges.clone(),
            values: self
                .values
                .iter()
                .map(|&v| (v * levels).round() / levels)
                .collect(),
        }
    }

    pub(crate) fn from_parts(edges: Vec<[u32; 2]>, values: Vec<f64>) -> EdgeSharpness {
        EdgeSharpness { edges, values }
    }
}

#[inline]
pub(crate) fn clamp01(h: f64) -> f64 {
    if h.is_nan() {
        0.0
    } else {
        h.clamp(0.0, 1.0)
    }
}

/// Angle between the normals of the two triangles of each edge (`edges` canonical and
/// sorted); `PI` for boundary and non-manifold edges.
pub(crate) fn dihedral_angles(mesh: &Mesh, edges: &[[u32; 2]]) -> Vec<f64> {
    let normals = mesh.face_normals();
    let mut faces: Vec<(u64, u32)> = Vec::with_capacity(mesh.triangles.len() * 3);
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            faces.push((edge_key(tri[k], tri[(k + 1) % 3]), t as u32));
        }
    }
    faces.sort_unstable();
    let mut out = vec![core::f64::consts::PI; edges.len()];
    let mut i = 0;
    while i < faces.len() {
        let mut j = i + 1;
        while j < faces.len() && faces[j].0 == faces[i].0 {
            j += 1;
        }
        if j - i == 2 {
            let key = faces[i].0;
            let pair = [(key >> 32) as u32, key as u32];
            if let Ok(e) = edges.binary_search(&pair) {
                let (n0, n1) = (
                    normals[faces[i].1 as usize],
                    normals[faces[i + 1].1 as usize],
                );
                out[e] = angle_between(n0, n1);
            }
        }
        i = j;
    }
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use whet_mesh::DVec3;

    #[test]
    fn cube_edges_are_detected_and_diagonals_are_not() {
        let cube = whet_testkit_free_cube();
        let s = EdgeSharpness::from_dihedral_angle(&cube, 40.0);
        assert_eq!(s.len(), 18);
        assert_eq!(s.sharp_count(), 12);
        let q = EdgeSharpness::from_values(&cube, vec![0.49; 18])
            .unwrap()
            .quantized(3);
        assert!(q.values().iter().all(|&v| (v - 3.0 / 7.0).abs() < 1e-12));
        assert!(EdgeSharpness::from_values(&cube, vec![1.5; 18]).is_err());
        assert!(EdgeSharpness::from_values(&cube, vec![0.0; 17]).is_err());
    }

    /// A unit cube, two triangles per face, outward.
    pub(crate) fn whet_testkit_free_cube() -> Mesh {
        let p: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2 & 1) as f64))
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let mut t = Vec::new();
        for q in quads {
            t.push([q[0], q[1], q[2]]);
            t.push([q[0], q[2], q[3]]);
        }
        Mesh::new(p, t)
    }
}
