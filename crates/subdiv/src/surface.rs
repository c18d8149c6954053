//! The public subdivision entry point: [`subdivide`] a control mesh with its
//! [`EdgeSharpness`] `levels` times, optionally pushing the result to the limit surface.

use crate::loop_subdivision::Hierarchy;
use crate::sharpness::EdgeSharpness;
use crate::topology::Topology;
use crate::Error;
use glam::DVec3;
use whet_mesh::Mesh;

/// Most levels [`subdivide`] accepts (each multiplies the triangle count by 4).
pub const MAX_LEVELS: u32 = 10;

/// Most triangles [`subdivide`] produces (the codec's default triangle limit, 2^28).
pub const MAX_OUTPUT_TRIANGLES: u64 = 1 << 28;

/// Options of [`subdivide`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct SubdivOptions {
    /// Number of 1-to-4 splits; 0 returns the control mesh unchanged.
    pub levels: u32,
    /// How many of the first levels use the continuous (semi-sharp) rules before the switch
    /// to Hoppe's binary rules (seed 004's global `k`). Part of the surface's definition: the
    /// fit and the decoder must agree on it.
    pub sharp_levels: u32,
    /// Move the vertices of the last level to their limit positions (Hoppe's limit masks).
    pub limit: bool,
}

impl SubdivOptions {
    /// Three levels, three semi-sharp levels, limit positions.
    pub const DEFAULT: SubdivOptions = SubdivOptions {
        levels: 3,
        sharp_levels: 3,
        limit: true,
    };

    /// Sets the number of levels.
    pub const fn with_levels(mut self, levels: u32) -> Self {
        self.levels = levels;
        self
    }

    /// Sets the number of semi-sharp levels.
    pub const fn with_sharp_levels(mut self, sharp_levels: u32) -> Self {
        self.sharp_levels = sharp_levels;
        self
    }

    /// Turns the limit projection on or off.
    pub const fn with_limit(mut self, limit: bool) -> Self {
        self.limit = limit;
        self
    }
}

impl Default for SubdivOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Vertex and triangle counts after `levels` splits of a closed or open manifold mesh with
/// `v` vertices, `e` edges and `t` triangles (`V' = V + E`, `E' = 2E + 3T`, `T' = 4T`).
/// `None` when a count overflows `u64`.
pub fn subdivided_counts(v: u64, e: u64, t: u64, levels: u32) -> Option<(u64, u64)> {
    let (mut v, mut e, mut t) = (v, e, t);
    for _ in 0..levels {
        v = v.checked_add(e)?;
        e = e.checked_mul(2)?.checked_add(t.checked_mul(3)?)?;
        t = t.checked_mul(4)?;
    }
    Some((v, t))
}

/// Subdivides `control` (an oriented manifold triangle mesh, possibly with boundaries)
/// `opts.levels` times with the semi-sharp Loop rules of seed 004, `sharpness` giving `h`
/// per control edge.
///
/// Old vertices keep their indices at every level; the point on edge `e` (canonical order) of
/// a level follows them. Fails on non-manifold or non-finite input, on a `sharpness` made for
/// another mesh, and when the output would exceed [`MAX_LEVELS`] or
/// [`MAX_OUTPUT_TRIANGLES`].
pub fn subdivide(
    control: &Mesh,
    sharpness: &EdgeSharpness,
    opts: &SubdivOptions,
) -> Result<Mesh, Error> {
    if opts.levels == 0 {
        return Ok(control.clone());
    }
    let (hier, _) = prepare(control, sharpness, opts.levels)?;
    let positions = evaluate(&hier, sharpness.values(), &control.positions, opts);
    Ok(Mesh::new(positions, hier.finest().triangles.clone()))
}

/// Checks the input and builds the connectivity of every level.
pub(crate) fn prepare(
    control: &Mesh,
    sharpness: &EdgeSharpness,
    levels: u32,
) -> Result<(Hierarchy, usize), Error> {
    if levels > MAX_LEVELS {
        return Err(Error::LimitExceeded {
            what: "subdivision levels",
            limit: MAX_LEVELS as u64,
            value: levels as u64,
        });
    }
    let t = control.triangles.len() as u64;
    let out_t = t.saturating_mul(1u64 << (2 * levels));
    if out_t > MAX_OUTPUT_TRIANGLES {
        return Err(Error::LimitExceeded {
            what: "subdivided triangles",
            limit: MAX_OUTPUT_TRIANGLES,
            value: out_t,
        });
    }
    if let Some(v) = control.positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::InvalidInput(
            whet_mesh::MeshError::NonFiniteCoordinate { vertex: v as u32 },
        ));
    }
    let topo = Topology::new(control.triangles.clone(), control.positions.len())
        .map_err(Error::InvalidInput)?;
    if topo.edges.as_slice() != sharpness.edges() {
        return Err(Error::Parameter(format!(
            "the sharpness was made for another mesh ({} edges given, the control mesh has {})",
            sharpness.len(),
            topo.edges.len()
        )));
    }
    let ne = topo.edges.len();
    let hier = Hierarchy::new(topo, levels as usize).map_err(Error::InvalidInput)?;
    Ok((hier, ne))
}

/// Positions of the finest level of `hier` for control positions `p`.
pub(crate) fn evaluate(
    hier: &Hierarchy,
    h: &[f64],
    p: &[DVec3],
    opts: &SubdivOptions,
) -> Vec<DVec3> {
    let mut x = p.to_vec();
    for s in hier.stencils(h, opts.sharp_levels as usize, opts.limit) {
        x = s.apply(&x);
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sharpness::tests::whet_testkit_free_cube;

    #[test]
    fn counts_follow_euler() {
        // Level 1: 26 vertices, 72 edges, 48 triangles; level 2: 26 + 72 vertices.
        assert_eq!(subdivided_counts(8, 18, 12, 2), Some((98, 192)));
        assert_eq!(subdivided_counts(u64::MAX, 1, 1, 1), None);
    }

    #[test]
    fn fully_sharp_cube_keeps_its_corners_and_flat_faces() {
        let cube = whet_testkit_free_cube();
        let mut s = EdgeSharpness::zeros(&cube);
        // The 12 cube edges sharp, the 6 face diagonals smooth.
        let sharp = EdgeSharpness::from_dihedral_angle(&cube, 40.0);
        for (i, &[a, b]) in sharp.edges().iter().enumerate() {
            s.set(a, b, sharp.values()[i]).unwrap();
        }
        let out = subdivide(&cube, &s, &SubdivOptions::DEFAULT).unwrap();
        // Corners stay exactly.
        for v in 0..8 {
            assert!((out.positions[v] - cube.positions[v]).length() < 1e-12);
        }
        // Points on cube edges stay on the edges (crease rules are curve rules); face points
        // stay inside the cube.
        for p in &out.positions {
            assert!(p.min_element() > -1e-12 && p.max_element() < 1.0 + 1e-12);
        }
        let r = out.topology_report();
        assert!(r.manifold && r.oriented && r.boundary_edges == 0);
        assert_eq!(r.triangles, 12 * 64);
    }

    #[test]
    fn smooth_cube_shrinks_and_levels_zero_is_identity() {
        let cube = whet_testkit_free_cube();
        let s = EdgeSharpness::zeros(&cube);
        let same = subdivide(&cube, &s, &SubdivOptions::DEFAULT.with_levels(0)).unwrap();
        assert_eq!(same, cube);
        let out = subdivide(&cube, &s, &SubdivOptions::DEFAULT).unwrap();
        for p in &out.positions {
            assert!(p.min_element() > 0.0 && p.max_element() < 1.0);
        }
    }

    #[test]
    fn refuses_mismatched_sharpness_and_huge_levels() {
        let cube = whet_testkit_free_cube();
        let other = Mesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 2]]);
        let s = EdgeSharpness::zeros(&other);
        assert!(matches!(
            subdivide(&cube, &s, &SubdivOptions::DEFAULT),
            Err(Error::Parameter(_))
        ));
        let s = EdgeSharpness::zeros(&cube);
        assert!(matches!(
            subdivide(&cube, &s, &SubdivOptions::DEFAULT.with_levels(11)),
            Err(Error::LimitExceeded { .. })
        ));
    }
}
