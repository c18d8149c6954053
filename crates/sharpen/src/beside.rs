//! One-sided quadric projection: the vertices of a face near a crease. The local quadric
//! projection leaves a vertex where it is when its rings cross a crease (their normals turn),
//! and the crease projection moves only the vertices on crease lines, so on a
//! swing-decoded CAD part the face vertices within a few edges of a crease keep the swing
//! angles' quantization noise (on fandisk at about half the original vertex count and 6
//! angle bits, a third of the output's vertices). Here such a vertex gathers its own side
//! only: the triangles reached from its fan without crossing a crease, within a few mean
//! edges; the quadratic height field of their vertices off every crease is fitted, and the
//! vertex moves along its normal onto it. docs/sharpen.md, "One-sided quadric projection".

use glam::DVec3;
use whet_mesh::{CornerTable, Mesh, VertexId};

use crate::crease::{crease_edges, NearPoints, SideReach};
use crate::planar::{
    apply_moves, clamped_step, run_vertex_blocks, solve6, table_for, vertex_normals, HeightSamples,
};
use crate::Error;

/// Most triangles a gathering takes, per square of its reach in mean edges (as the crease
/// projection's): past it the vertex stays.
const MAX_TRIANGLES_PER_SQUARED_RING: usize = 16;

/// Options of [`project_beside_creases_onto_local_quadrics`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct BesideOptions {
    /// The reach of a gathering, in mean edge lengths (a triangle is taken when its centroid
    /// is within it): 1 to 4.
    pub rings: usize,
    /// An edge whose two triangles' normals differ by more than this (degrees) is a crease.
    pub crease_angle_degrees: f64,
    /// Largest angle, in degrees, between the vertex's normal and that of a fitted point:
    /// past it the side bends too tightly for a quadric and the vertex stays.
    pub max_normal_angle_degrees: f64,
    /// Largest move, in mean edge lengths of the mesh.
    pub max_move: f64,
}

impl BesideOptions {
    /// A reach of three mean edges, creases at 30 degrees, points within 30 degrees, moves
    /// of at most 0.05 mean edge lengths (the swing decoder's limit is
    /// [`Self::for_swing`]'s).
    pub const DEFAULT: BesideOptions = BesideOptions {
        rings: 3,
        crease_angle_degrees: 30.0,
        max_normal_angle_degrees: 30.0,
        max_move: 0.05,
    };

    /// The options with moves of at most `max_move` mean edge lengths.
    pub const fn with_max_move(self, max_move: f64) -> BesideOptions {
        BesideOptions { max_move, ..self }
    }

    /// The options with a reach of `rings` mean edge lengths.
    pub const fn with_rings(self, rings: usize) -> BesideOptions {
        BesideOptions { rings, ..self }
    }

    /// The options with creases at `degrees`.
    pub const fn with_crease_angle_degrees(self, degrees: f64) -> BesideOptions {
        BesideOptions {
            crease_angle_degrees: degrees,
            ..self
        }
    }

    /// The options with the normal-angle limit of fitted points `degrees`.
    pub const fn with_max_normal_angle_degrees(self, degrees: f64) -> BesideOptions {
        BesideOptions {
            max_normal_angle_degrees: degrees,
            ..self
        }
    }

    /// The options for a swing stream of `angle_bits` angle bits whose header states the
    /// move limit `factor` in angle steps, as the local quadric projection's
    /// ([`crate::QuadricOptions::for_swing`]).
    pub fn for_swing(angle_bits: u32, factor: f64) -> BesideOptions {
        Self::DEFAULT.with_max_move(crate::PlanarOptions::swing_tolerance(angle_bits, factor))
    }

    fn validate(&self) -> Result<(), Error> {
        let ok = (1..=4).contains(&self.rings)
            && self.crease_angle_degrees > 0.0
            && self.crease_angle_degrees < 90.0
            && self.max_normal_angle_degrees > 0.0
            && self.max_normal_angle_degrees < 90.0
            && self.max_move >= 0.0
            && self.max_move.is_finite();
        if ok {
            Ok(())
        } else {
            Err(Error::Parameter(format!(
                "one-sided quadric projection: rings {} (1..=4), crease angle {} (0..90), \
                 normal angle {} (0..90) and max move {} (finite, >= 0)",
                self.rings, self.crease_angle_degrees, self.max_normal_angle_degrees, self.max_move
            )))
        }
    }
}

impl Default for BesideOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What [`project_beside_creases_onto_local_quadrics`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct BesideReport {
    /// Interior vertices on no crease whose side reaches one.
    pub beside_vertices: usize,
    /// Of those, the ones whose fit was made and determined.
    pub fitted_vertices: usize,
    /// Vertices moved (fitted and off their quadric by a nonzero amount).
    pub moved_vertices: usize,
    /// Moves cut to the move limit.
    pub clamped_moves: usize,
}

/// Moves each interior vertex that is on no crease edge but whose side (the triangles
/// reached from its fan across edges that are no crease, centroids within `rings` mean
/// edges) touches a crease, along its area-weighted normal onto the least-squares quadratic
/// height field of that side's vertices off every crease, by at most `max_move` mean edge
/// lengths (module docs). Vertices whose side reaches no crease are the local quadric
/// projection's, and stay. Every fit reads the input positions. Fails with
/// [`Error::InvalidInput`] when `mesh` is not an oriented manifold with finite coordinates,
/// [`Error::Parameter`] for options out of range.
pub fn project_beside_creases_onto_local_quadrics(
    mesh: &mut Mesh,
    opts: &BesideOptions,
) -> Result<BesideReport, Error> {
    project_beside_creases_onto_local_quadrics_in(mesh, opts, None)
}

with_table_entry_point!(
    project_beside_creases_onto_local_quadrics,
    project_beside_creases_onto_local_quadrics_with_table,
    project_beside_creases_onto_local_quadrics_in,
    BesideOptions,
    BesideReport
);

fn project_beside_creases_onto_local_quadrics_in(
    mesh: &mut Mesh,
    opts: &BesideOptions,
    given: Option<&CornerTable>,
) -> Result<BesideReport, Error> {
    opts.validate()?;
    let table = table_for(mesh, given)?;
    let p = &mesh.positions;
    let (nv, nt) = (p.len(), mesh.triangles.len());
    let edge = table.mean_edge_length(p);
    let reach = edge * opts.rings as f64;
    let mut report = BesideReport::default();
    if !(reach > 0.0 && reach.is_finite()) {
        return Ok(report);
    }
    let (crease, on_crease) = crease_edges(mesh, &table, opts.crease_angle_degrees);
    let centroids = crate::crease::centroids(mesh);
    // The triangles touching a crease, and their centroids bucketed: a vertex whose fan
    // touches none and that has none of those centroids within the reach gathers none of
    // them, so its side would hold no crease vertex; it is skipped without the flood.
    let touches_crease: Vec<bool> = mesh
        .triangles
        .iter()
        .map(|t| t.iter().any(|&w| on_crease[w as usize]))
        .collect();
    let near_points = NearPoints::new(
        (0..nt)
            .filter(|&t| touches_crease[t])
            .map(|t| centroids[t])
            .collect(),
        reach,
    );
    let normals = vertex_normals(mesh);
    let cos_max = opts.max_normal_angle_degrees.to_radians().cos();
    let max_move = opts.max_move * edge;
    let max_triangles = MAX_TRIANGLES_PER_SQUARED_RING * opts.rings * opts.rings;
    const NONE: u32 = u32::MAX;
    // Vertex by vertex in blocks side by side, each with its own scratch; the moves after.
    let block = |range: std::ops::Range<usize>| {
        // The vertex whose gathering last took each triangle and each vertex.
        let mut tri_stamp = vec![NONE; nt];
        let mut vert_stamp = vec![NONE; nv];
        let (mut gathered, mut stack) = (Vec::new(), Vec::new());
        let mut report = BesideReport::default();
        let mut moves: Vec<(usize, DVec3)> = Vec::new();
        'vertices: for v in range {
            let vid = VertexId(v as u32);
            let n = normals[v];
            if on_crease[v]
                || n == DVec3::ZERO
                || table.vertex_corner(vid).is_none()
                || table.is_boundary_vertex(vid)
            {
                continue;
            }
            let stamp = v as u32;
            stack.clear();
            // The fan: its edges at v are no crease (v is on none).
            let mut fan_touches_crease = false;
            for c in table.vertex_corners(vid) {
                let t = c.index() / 3;
                fan_touches_crease |= touches_crease[t];
                if tri_stamp[t] != stamp {
                    tri_stamp[t] = stamp;
                    stack.push(t);
                }
            }
            if !fan_touches_crease && !near_points.any_within(p[v], reach) {
                continue;
            }
            let side = SideReach {
                centroids: &centroids,
                table: &table,
                crease: &crease,
                centre: p[v],
                reach,
                max_triangles,
            };
            if !side.gather(stamp, &mut tri_stamp, &mut stack, &mut gathered) {
                continue;
            }
            let near = gathered.iter().any(|&t| touches_crease[t]);
            if !near {
                continue;
            }
            report.beside_vertices += 1;
            // In the frame of v's normal, centred on v, scaled by the reach.
            let (eu, ev) = n.any_orthonormal_pair();
            let mut samples = HeightSamples::default();
            let mut points = 0usize;
            for &t in &gathered {
                for w in mesh.triangles[t] {
                    let w = w as usize;
                    if on_crease[w] || vert_stamp[w] == stamp {
                        continue;
                    }
                    vert_stamp[w] = stamp;
                    if normals[w].dot(n) < cos_max {
                        continue 'vertices;
                    }
                    points += 1;
                    let d = (p[w] - p[v]) / reach;
                    let (a, b, h) = (d.dot(eu), d.dot(ev), d.dot(n));
                    samples.add([a * a, a * b, b * b, a, b, 1.0], h);
                }
            }
            // Six unknowns: at least twice as many points.
            if points < 12 {
                continue;
            }
            let Some(coef) = solve6(samples.system()) else {
                continue;
            };
            report.fitted_vertices += 1;
            // The fitted height at the vertex itself.
            let (step, clamped) = clamped_step(coef[5] * reach, max_move);
            report.clamped_moves += usize::from(clamped);
            if step != 0.0 {
                moves.push((v, p[v] + n * step));
            }
        }
        (report, moves)
    };
    for (part, moves) in run_vertex_blocks(nv, 4 * (nt + nv), block) {
        report.beside_vertices += part.beside_vertices;
        report.fitted_vertices += part.fitted_vertices;
        report.clamped_moves += part.clamped_moves;
        report.moved_vertices += apply_moves(&mut mesh.positions, moves);
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadric::tests::cylinder;

    /// RMS distance to the exact cylinder of radius `r` of the side vertices whose height
    /// picks them.
    fn rms_where(m: &Mesh, r: f64, pick: impl Fn(f64) -> bool) -> f64 {
        let d: Vec<f64> = m
            .positions
            .iter()
            .filter(|q| pick(q.z))
            .map(|q| q.truncate().length() - r)
            .collect();
        assert!(!d.is_empty());
        (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt()
    }

    // The cylinder of the quadric projection's tests: radius 2, height 3, side edges of
    // about 0.1; its rims are creases (the caps turn by 90 degrees). With the caps' spokes
    // (length 2) the mean edge is about 0.15, so the reach of three is about 0.45: the
    // five rows above each rim reach a triangle on it, and the rows from 0.8 to 2.2 reach
    // none.
    const R: f64 = 2.0;
    const H: f64 = 3.0;

    fn beside_rims(z: f64) -> bool {
        (z > 0.05 && z < 0.35) || (z > H - 0.35 && z < H - 0.05)
    }

    #[test]
    fn vertices_beside_the_rims_of_a_noisy_cylinder_come_closer_to_it() {
        let mut m = cylinder(R, H, 126, 30, 0.01);
        let before = rms_where(&m, R, beside_rims);
        let rep = project_beside_creases_onto_local_quadrics(
            &mut m,
            &BesideOptions::DEFAULT.with_max_move(0.2),
        )
        .expect("a manifold");
        let after = rms_where(&m, R, beside_rims);
        // Measured: 1262 beside (ten rows and the caps' centres, whose sides hold too few
        // points to fit), 1260 moved.
        assert!(rep.moved_vertices >= 126 * 10, "{rep:?}");
        // Measured 0.00281 -> 0.00075 (3.8x) on the three rows nearest each rim; bound at
        // 2.5x.
        assert!(after < before / 2.5, "{before} -> {after}");
    }

    #[test]
    fn the_rims_the_caps_and_the_vertices_far_from_them_stay() {
        let before = cylinder(R, H, 126, 30, 0.01);
        let mut m = before.clone();
        project_beside_creases_onto_local_quadrics(
            &mut m,
            &BesideOptions::DEFAULT.with_max_move(0.2),
        )
        .expect("a manifold");
        for (v, (a, b)) in before.positions.iter().zip(&m.positions).enumerate() {
            // On a crease (a rim, a cap's centre and fan), or beyond the reach of every
            // crease: the local quadric projection's vertices, bit for bit.
            if a.z == 0.0 || a.z == H || (a.z > 0.75 && a.z < H - 0.75) {
                assert_eq!(a, b, "vertex {v} moved");
            }
        }
    }

    #[test]
    fn a_noiseless_cylinder_stays_on_itself() {
        let mut m = cylinder(R, H, 126, 30, 0.0);
        project_beside_creases_onto_local_quadrics(&mut m, &BesideOptions::DEFAULT)
            .expect("a manifold");
        // Measured 8.1e-5: a one-sided fit extrapolates to the vertex at its side's border
        // (a centred one measures 1.6e-5); the chords sag by 6e-4, the noise above is 2.8e-3.
        // Bound at 1.5e-4.
        let rms = rms_where(&m, R, beside_rims);
        assert!(rms < 1.5e-4, "{rms}");
    }

    #[test]
    fn moves_are_clamped_to_the_limit() {
        let before = cylinder(R, H, 126, 30, 0.02);
        let mut m = before.clone();
        let rep = project_beside_creases_onto_local_quadrics(
            &mut m,
            &BesideOptions::DEFAULT.with_max_move(0.01),
        )
        .expect("a manifold");
        let edge = before.mean_edge_length();
        assert!(rep.clamped_moves > 0, "{rep:?}");
        for (a, b) in before.positions.iter().zip(&m.positions) {
            assert!(a.distance(*b) <= 0.01 * edge * (1.0 + 1e-9));
        }
    }

    #[test]
    fn bad_options_and_input_are_refused() {
        let mut m = cylinder(R, H, 12, 3, 0.0);
        for opts in [
            BesideOptions::DEFAULT.with_rings(0),
            BesideOptions::DEFAULT.with_rings(5),
            BesideOptions::DEFAULT.with_max_move(f64::NAN),
            BesideOptions::DEFAULT.with_max_move(-1.0),
            BesideOptions {
                crease_angle_degrees: 90.0,
                ..BesideOptions::DEFAULT
            },
            BesideOptions {
                max_normal_angle_degrees: 0.0,
                ..BesideOptions::DEFAULT
            },
        ] {
            assert!(matches!(
                project_beside_creases_onto_local_quadrics(&mut m, &opts),
                Err(Error::Parameter(_))
            ));
        }
        let mut nan = m.clone();
        nan.positions[0].x = f64::NAN;
        assert!(matches!(
            project_beside_creases_onto_local_quadrics(&mut nan, &BesideOptions::DEFAULT),
            Err(Error::InvalidInput(_))
        ));
        // A mesh without triangles: nothing to do.
        let mut empty = Mesh::new(vec![DVec3::ZERO], Vec::new());
        assert_eq!(
            project_beside_creases_onto_local_quadrics(&mut empty, &BesideOptions::DEFAULT)
                .expect("valid"),
            BesideReport::default()
        );
    }
}
