//! Local quadric projection: after sharpening a swing-decoded CAD mesh, the vertices on its
//! curved faces (cylinders, fillets, gently bent faces) still carry the swing angles'
//! quantization noise, which neither EdgeSharpener (chamfer vertices only) nor the
//! planar-region projection (flat faces only) removes. Each vertex whose rings of
//! neighbours all face nearly its own way moves, along its normal, onto the least-squares
//! quadratic height field of those rings: a quadric follows a curved face's bend, so only
//! the noise is taken out, and a vertex near a crease (whose rings turn) stays.
//! docs/sharpen.md, "Local quadric projection".

use glam::DVec3;
use whet_mesh::{CornerTable, Mesh, VertexId};

use crate::planar::{
    apply_moves, clamped_step, run_vertex_blocks, solve6, table_for, vertex_normals, HeightSamples,
};
use crate::Error;

/// Most points a fit gathers, per square of its ring count: 144 for three rings, about four
/// times what a regular mesh's three rings hold (37). A vertex whose rings hold more stays.
const MAX_POINTS_PER_SQUARED_RING: usize = 16;

/// Options of [`project_onto_local_quadrics`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct QuadricOptions {
    /// How many rings of neighbours each fit takes (the vertex's own position included):
    /// 1 to 4. A fit needs 12 points, so one ring fits only around vertices of valence 11
    /// or more: on regular meshes it moves nothing.
    pub rings: usize,
    /// Largest angle, in degrees, between a vertex's normal and that of any vertex of its
    /// rings: past it the rings cross a crease or a bend too tight for a quadric, and the
    /// vertex stays.
    pub max_normal_angle_degrees: f64,
    /// Largest move, in mean edge lengths of the mesh: the noise to take out is that
    /// small, and a larger move would be the fit cutting through a feature.
    pub max_move: f64,
}

impl QuadricOptions {
    /// Three rings, 30 degrees, moves of at most 0.05 mean edge lengths (the swing
    /// decoder's limit is [`Self::for_swing`]'s).
    pub const DEFAULT: QuadricOptions = QuadricOptions {
        rings: 3,
        max_normal_angle_degrees: 30.0,
        max_move: 0.05,
    };

    /// The options with moves of at most `max_move` mean edge lengths.
    pub const fn with_max_move(self, max_move: f64) -> QuadricOptions {
        QuadricOptions { max_move, ..self }
    }

    /// The options with `rings` rings of neighbours per fit.
    pub const fn with_rings(self, rings: usize) -> QuadricOptions {
        QuadricOptions { rings, ..self }
    }

    /// The options with the normal-angle limit `degrees`.
    pub const fn with_max_normal_angle_degrees(self, degrees: f64) -> QuadricOptions {
        QuadricOptions {
            max_normal_angle_degrees: degrees,
            ..self
        }
    }

    /// The options for a swing stream of `angle_bits` angle bits whose header states the
    /// move limit `factor` in angle steps (`whet_codec::SharpenHint::quadric_of`): a swing
    /// tip is off the surface by at most half a step `2 pi / 2^bits` times the edge length.
    pub fn for_swing(angle_bits: u32, factor: f64) -> QuadricOptions {
        Self::DEFAULT.with_max_move(crate::PlanarOptions::swing_tolerance(angle_bits, factor))
    }

    fn validate(&self) -> Result<(), Error> {
        let ok = (1..=4).contains(&self.rings)
            && self.max_normal_angle_degrees > 0.0
            && self.max_normal_angle_degrees < 90.0
            && self.max_move >= 0.0
            && self.max_move.is_finite();
        if ok {
            Ok(())
        } else {
            Err(Error::Parameter(format!(
                "quadric projection: rings {} (1..=4), angle {} (0..90) and max move {} \
                 (finite, >= 0)",
                self.rings, self.max_normal_angle_degrees, self.max_move
            )))
        }
    }
}

impl Default for QuadricOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What [`project_onto_local_quadrics`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct QuadricReport {
    /// Vertices whose rings passed the normal test and whose fit was determined.
    pub fitted_vertices: usize,
    /// Vertices moved (fitted and off their quadric by a nonzero amount).
    pub moved_vertices: usize,
    /// Moves cut to the move limit.
    pub clamped_moves: usize,
}

/// Moves every interior vertex whose rings pass the normal test onto its rings'
/// least-squares quadratic height field, along its area-weighted normal and by at most
/// `max_move` mean edge lengths (module docs). Every fit reads the input positions, so the
/// result does not depend on the vertex order. Fails with [`Error::InvalidInput`] when
/// `mesh` is not an oriented manifold with finite coordinates, [`Error::Parameter`] for
/// options out of range.
pub fn project_onto_local_quadrics(
    mesh: &mut Mesh,
    opts: &QuadricOptions,
) -> Result<QuadricReport, Error> {
    project_onto_local_quadrics_in(mesh, opts, None)
}

with_table_entry_point!(
    project_onto_local_quadrics,
    project_onto_local_quadrics_with_table,
    project_onto_local_quadrics_in,
    QuadricOptions,
    QuadricReport
);

fn project_onto_local_quadrics_in(
    mesh: &mut Mesh,
    opts: &QuadricOptions,
    given: Option<&CornerTable>,
) -> Result<QuadricReport, Error> {
    opts.validate()?;
    let table = table_for(mesh, given)?;
    let p = &mesh.positions;
    let nv = p.len();
    let normals = vertex_normals(mesh);
    let edge = table.mean_edge_length(p);
    let max_move = opts.max_move * edge;
    let cos_max = opts.max_normal_angle_degrees.to_radians().cos();
    // Coordinates scaled by the rings' reach keep the normal equations well conditioned.
    let scale = edge * opts.rings as f64;
    if !(scale > 0.0 && scale.is_finite()) {
        return Ok(QuadricReport::default());
    }
    const NONE: u32 = u32::MAX;
    // Rings that hold more points than this have a vertex of high valence: such a vertex is
    // no regular surface sample, and without the cap each of its neighbours would walk
    // its whole fan, quadratic in its valence (a hostile stream can decode to one).
    let max_points = MAX_POINTS_PER_SQUARED_RING * opts.rings * opts.rings;
    // Vertex by vertex in blocks side by side, each with its own scratch; the moves after.
    let block = |range: std::ops::Range<usize>| {
        // The vertex whose rings last gathered each vertex.
        let mut stamp = vec![NONE; nv];
        let mut ring: Vec<u32> = Vec::new();
        let mut report = QuadricReport::default();
        let mut moves: Vec<(usize, DVec3)> = Vec::new();
        'vertices: for v in range {
            let n = normals[v];
            let vid = VertexId(v as u32);
            if n == DVec3::ZERO
                || table.vertex_corner(vid).is_none()
                || table.is_boundary_vertex(vid)
            {
                continue;
            }
            // Breadth first, ring by ring; `ring[start..]` is the last ring gathered.
            ring.clear();
            ring.push(v as u32);
            stamp[v] = v as u32;
            let mut start = 0;
            for _ in 0..opts.rings {
                let end = ring.len();
                for i in start..end {
                    for c in table.vertex_corners(VertexId(ring[i])) {
                        let w = table.vertex(table.next(c)).0;
                        if stamp[w as usize] != v as u32 {
                            stamp[w as usize] = v as u32;
                            if normals[w as usize].dot(n) < cos_max || ring.len() >= max_points {
                                continue 'vertices;
                            }
                            ring.push(w);
                        }
                    }
                }
                start = end;
            }
            // Six unknowns: at least twice as many points (an interior vertex's two rings hold
            // about 19).
            if ring.len() < 12 {
                continue;
            }
            let (eu, ev) = n.any_orthonormal_pair();
            let mut samples = HeightSamples::default();
            for &w in &ring {
                let d = (p[w as usize] - p[v]) / scale;
                let (u, s, h) = (d.dot(eu), d.dot(ev), d.dot(n));
                samples.add([u * u, u * s, s * s, u, s, 1.0], h);
            }
            let Some(coef) = solve6(samples.system()) else {
                continue;
            };
            report.fitted_vertices += 1;
            // The fitted height at the vertex itself (u = s = 0).
            let (step, clamped) = clamped_step(coef[5] * scale, max_move);
            report.clamped_moves += usize::from(clamped);
            if step != 0.0 {
                moves.push((v, p[v] + n * step));
            }
        }
        (report, moves)
    };
    let mut report = QuadricReport::default();
    for (part, moves) in run_vertex_blocks(nv, 4 * nv, block) {
        report.fitted_vertices += part.fitted_vertices;
        report.clamped_moves += part.clamped_moves;
        report.moved_vertices += apply_moves(&mut mesh.positions, moves);
    }
    Ok(report)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A closed cylinder of radius `r` and height `h` wrapped by `around` x `up` quads
    /// (capped by fans), its side vertices pushed along their radius by a deterministic
    /// pseudo-random `noise` (absolute).
    pub(crate) fn cylinder(r: f64, h: f64, around: usize, up: usize, noise: f64) -> Mesh {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut rand = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut positions = Vec::new();
        for j in 0..=up {
            for i in 0..around {
                let a = std::f64::consts::TAU * i as f64 / around as f64;
                let rr = r + noise * rand();
                positions.push(DVec3::new(
                    rr * a.cos(),
                    rr * a.sin(),
                    h * j as f64 / up as f64,
                ));
            }
        }
        let bottom = positions.len() as u32;
        positions.push(DVec3::new(0.0, 0.0, 0.0));
        let top = bottom + 1;
        positions.push(DVec3::new(0.0, 0.0, h));
        let id = |i: usize, j: usize| (j * around + i % around) as u32;
        let mut triangles = Vec::new();
        for j in 0..up {
            for i in 0..around {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        for i in 0..around {
            triangles.push([bottom, id(i + 1, 0), id(i, 0)]);
            triangles.push([top, id(i, up), id(i + 1, up)]);
        }
        Mesh::new(positions, triangles)
    }

    /// RMS distance of the side vertices (not the rims) to the exact cylinder.
    fn side_rms(m: &Mesh, r: f64, h: f64) -> f64 {
        let side: Vec<f64> = m
            .positions
            .iter()
            .filter(|q| q.z > 0.2 * h && q.z < 0.8 * h)
            .map(|q| q.truncate().length() - r)
            .collect();
        (side.iter().map(|d| d * d).sum::<f64>() / side.len() as f64).sqrt()
    }

    #[test]
    fn a_noisy_cylinder_comes_closer_to_the_exact_one() {
        // Edge about 0.1 around a radius of 2: the bend per edge is 3 degrees, the noise
        // 0.005 (5 % of an edge, a 6-bit swing stream's scale).
        let (r, h) = (2.0, 3.0);
        let mut m = cylinder(r, h, 126, 30, 0.01);
        let before = side_rms(&m, r, h);
        let rep = project_onto_local_quadrics(&mut m, &QuadricOptions::DEFAULT.with_max_move(0.2))
            .expect("a manifold");
        let after = side_rms(&m, r, h);
        assert!(rep.moved_vertices > 126 * 20, "{rep:?}");
        // A three-ring quadric averages 37 points with six unknowns; measured 0.00290 ->
        // 0.00100 (2.9x), bound at 2.2x.
        assert!(after < before / 2.2, "{before} -> {after}");
    }

    #[test]
    fn a_noiseless_cylinder_stays_on_itself() {
        // The quadric follows the bend: no shrinking towards the axis (what Laplacian
        // smoothing would do).
        let (r, h) = (2.0, 3.0);
        let mut m = cylinder(r, h, 126, 30, 0.0);
        project_onto_local_quadrics(&mut m, &QuadricOptions::DEFAULT).expect("a manifold");
        // Measured 1.6e-5 (the fit of a polygon's vertices by a quadric; the chords sag by
        // r (1 - cos(pi / 126)) = 6e-4), bound at 5e-5: under a tenth of the noise above.
        assert!(side_rms(&m, r, h) < 5e-5, "{}", side_rms(&m, r, h));
    }

    #[test]
    fn the_rims_and_the_caps_do_not_move() {
        // The rims' rings turn by 90 degrees; the caps' fans are flat and exact.
        let (r, h) = (2.0, 3.0);
        let before = cylinder(r, h, 126, 30, 0.01);
        let mut m = before.clone();
        project_onto_local_quadrics(&mut m, &QuadricOptions::DEFAULT.with_max_move(0.2))
            .expect("a manifold");
        for (v, (a, b)) in before.positions.iter().zip(&m.positions).enumerate() {
            if a.z == 0.0 || a.z == h {
                assert!(
                    a.distance(*b) < 1e-12,
                    "vertex {v} moved by {}",
                    a.distance(*b)
                );
            }
        }
    }

    #[test]
    fn moves_are_clamped_to_the_limit() {
        let (r, h) = (2.0, 3.0);
        let before = cylinder(r, h, 126, 30, 0.02);
        let mut m = before.clone();
        let rep = project_onto_local_quadrics(&mut m, &QuadricOptions::DEFAULT.with_max_move(0.01))
            .expect("a manifold");
        let edge = before.mean_edge_length();
        assert!(rep.clamped_moves > 0, "{rep:?}");
        for (a, b) in before.positions.iter().zip(&m.positions) {
            assert!(a.distance(*b) <= 0.01 * edge * (1.0 + 1e-9));
        }
    }

    #[test]
    fn a_vertex_of_high_valence_keeps_its_neighbourhood_in_place() {
        // Every interior vertex has the centre (valence 3000) within three rings: gathering
        // it would take 3000 steps per neighbour; past 144 points the vertex stays.
        let before = whet_testkit::meshes::hub_disk(3000, 3);
        let mut m = before.clone();
        let rep = project_onto_local_quadrics(&mut m, &QuadricOptions::DEFAULT.with_max_move(1.0))
            .expect("a manifold");
        assert_eq!(rep.fitted_vertices, 0, "{rep:?}");
        assert_eq!(m.positions, before.positions);
        // The same disk with a centre of valence 12: its rings stay small, and fits happen.
        let mut small = whet_testkit::meshes::hub_disk(12, 5);
        let rep =
            project_onto_local_quadrics(&mut small, &QuadricOptions::DEFAULT.with_max_move(1.0))
                .expect("a manifold");
        assert!(rep.fitted_vertices > 0, "{rep:?}");
    }

    #[test]
    fn bad_input_and_options_are_refused() {
        let mut m = cylinder(2.0, 3.0, 40, 10, 0.0);
        for bad in [
            QuadricOptions::DEFAULT.with_rings(0),
            QuadricOptions::DEFAULT.with_rings(5),
            QuadricOptions::DEFAULT.with_max_move(f64::NAN),
            QuadricOptions::DEFAULT.with_max_move(-1.0),
            QuadricOptions::DEFAULT.with_max_normal_angle_degrees(90.0),
        ] {
            assert!(matches!(
                project_onto_local_quadrics(&mut m, &bad),
                Err(Error::Parameter(_))
            ));
        }
        m.positions[3].x = f64::NAN;
        assert!(matches!(
            project_onto_local_quadrics(&mut m, &QuadricOptions::DEFAULT),
            Err(Error::InvalidInput(_))
        ));
    }
}
