//! Apex restoration: a uniform retiling cuts the tip off a cone (or a corner the sharpener
//! left cut) and puts no vertex where the surfaces meet, so the tip is off by up to an edge
//! whatever the swing angles' precision. The tangent planes of a cone all pass through its
//! apex, and those of the faces at a corner through the corner, while a sphere's or a
//! paraboloid's do not meet in one point. So around each vertex where the normals turn, the
//! tangent planes of the vertices in a band of a few edges (the cut itself left out) are
//! intersected in the least-squares sense; where their normals span all three directions,
//! the point lies on every plane within a small residual, and the band's nearer and farther
//! halves find the same point, the vertex nearest that point moves onto it.
//! docs/sharpen.md, "Apex restoration".

use glam::{DMat3, DVec3};
use whet_mesh::{CornerTable, Mesh, VertexId};

use crate::planar::{table_for, vertex_normals};
use crate::Error;

/// A vertex whose one-ring neighbours' normals all lie within this many degrees of its own
/// is no tip (a flat or gently bent place) and is not fitted: the pre-test that keeps the
/// fits to the few vertices where the surface turns.
const TURN_DEGREES: f64 = 15.0;

/// Least smallest eigenvalue of the band's mean normal tensor `sum(n n^T) / k`: under it the
/// normals lie near a plane of directions (a crease's two faces, a cylinder's ring) and the
/// point is ill determined along the remaining direction. A cone of half-angle 27 degrees
/// gives 0.20, a cube corner 0.33, a crease 0.
const MIN_SPREAD: f64 = 0.05;

/// Least smallest eigenvalue of the same tensor over the candidate's two rings (itself
/// included), the pre-test before the band is gathered: a crease vertex's rings see two
/// faces (0 up to noise). Every fitted vertex of the 48 swing-decoded fixture streams and the
/// synth shapes' at 6 bits measured 0.036 or more (most over 0.1); 0.02 lets 2-15 % of the
/// turning vertices through to the band.
const MIN_RING_SPREAD: f64 = 0.02;

/// Largest RMS distance, in mean edge lengths, of the fitted point from the band's tangent
/// planes: a cone's or a corner's planes meet in one point up to the decoder's noise
/// (0.06-0.20 edges on swing-decoded cones, 0.002-0.05 at corners); a sphere's spread.
const MAX_RESIDUAL: f64 = 0.25;

/// Largest distance, in mean edge lengths, between the points the band's nearer and farther
/// halves find: a cone's and a corner's agree, a dome's nearer planes meet closer to it than
/// its farther ones.
const MAX_HALVES_APART: f64 = 0.35;

/// Moves shorter than this, in mean edge lengths, are not made: the vertex is at its tip
/// already (a corner the sharpener restored).
const MIN_MOVE: f64 = 0.05;

/// Fewest band vertices per half of a fit (three unknowns each).
const MIN_HALF_POINTS: usize = 4;

/// Most vertices one gathering takes per squared mean edge of its reach (about five times
/// what a regular mesh holds): a vertex whose neighbourhood holds more (a hostile stream's
/// high valence) is not fitted, so each gathering's cost stays bounded.
const MAX_POINTS_PER_SQUARED_EDGE: f64 = 16.0;

/// Least angle, in degrees, of a triangle of the moved vertex's fan: a move that makes a
/// sliver is not made (the sharpener's own rule).
const MIN_ANGLE_DEGREES: f64 = 1.0;

/// Options of [`restore_apexes`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct ApexOptions {
    /// Inner radius of the band, in mean edge lengths: the vertices nearer the tip sit on
    /// the cut and their normals are the cut's, not the surface's.
    pub inner: f64,
    /// Outer radius of the band, in mean edge lengths (reached across edges).
    pub outer: f64,
    /// Largest move, in mean edge lengths: a farther point is a fit gone wrong.
    pub max_move: f64,
}

impl ApexOptions {
    /// A band from 1.5 to 5 mean edges, moves of at most 1.5 edges (the cut of a cone by a
    /// uniform retiling is under one edge deep: 0.6-1.1 on the swing-decoded synth cone).
    pub const DEFAULT: ApexOptions = ApexOptions {
        inner: 1.5,
        outer: 5.0,
        max_move: 1.5,
    };

    /// The options with moves of at most `max_move` mean edge lengths.
    pub const fn with_max_move(self, max_move: f64) -> ApexOptions {
        ApexOptions { max_move, ..self }
    }

    /// The options with the band from `inner` to `outer` mean edge lengths.
    pub const fn with_band(self, inner: f64, outer: f64) -> ApexOptions {
        ApexOptions {
            inner,
            outer,
            ..self
        }
    }

    fn validate(&self) -> Result<(), Error> {
        let ok = self.inner >= 0.0
            && self.outer > self.inner
            && self.outer <= 8.0
            && self.max_move >= 0.0
            && self.max_move.is_finite();
        if ok {
            Ok(())
        } else {
            Err(Error::Parameter(format!(
                "apex restoration: band {} to {} (0 <= inner < outer <= 8) and max move {} \
                 (finite, >= 0)",
                self.inner, self.outer, self.max_move
            )))
        }
    }
}

impl Default for ApexOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What [`restore_apexes`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct ApexReport {
    /// Interior vertices whose one ring turns past the pre-test.
    pub candidates: usize,
    /// Of those, the ones whose two rings' normals spread over three directions (the band
    /// gathered and fitted).
    pub spread: usize,
    /// Of those, the ones whose band's tangent planes meet in one point (spread, residual
    /// and halves' tests passed) nearer to them than to any other vertex gathered.
    pub fitted: usize,
    /// Vertices moved onto their point.
    pub moved_vertices: usize,
    /// Fitted vertices that stayed: the point farther than the move limit, a neighbour
    /// moved already, or the move would turn or flatten a triangle of its fan.
    pub refused_moves: usize,
}

/// A least-squares point of tangent planes: the normal equations `sum(n n^T) x = sum(n (n.p))`
/// over the planes added, kept relative to an origin so the sums stay well conditioned.
#[derive(Clone, Copy)]
struct PlanePoint {
    origin: DVec3,
    m: DMat3,
    b: DVec3,
    /// `sum((n.p)^2)`, for the residual.
    c: f64,
    count: usize,
}

impl PlanePoint {
    fn new(origin: DVec3) -> PlanePoint {
        PlanePoint {
            origin,
            m: DMat3::ZERO,
            b: DVec3::ZERO,
            c: 0.0,
            count: 0,
        }
    }

    /// Adds the plane through `p` with unit normal `n`.
    fn add(&mut self, p: DVec3, n: DVec3) {
        let d = n.dot(p - self.origin);
        self.m += outer(n);
        self.b += n * d;
        self.c += d * d;
        self.count += 1;
    }

    /// The point and its RMS distance from the planes, when the normals' mean tensor has
    /// its smallest eigenvalue at least `MIN_SPREAD`.
    fn solve(&self) -> Option<(DVec3, f64)> {
        if self.count < MIN_HALF_POINTS {
            return None;
        }
        let k = self.count as f64;
        if smallest_eigenvalue(self.m * (1.0 / k)) < MIN_SPREAD {
            return None;
        }
        let x = self.m.inverse() * self.b;
        if !x.is_finite() {
            return None;
        }
        // sum((n.x - d)^2) = x^T M x - 2 b.x + c.
        let sq = (x.dot(self.m * x) - 2.0 * self.b.dot(x) + self.c).max(0.0);
        Some((self.origin + x, (sq / k).sqrt()))
    }
}

/// `n n^T`.
fn outer(n: DVec3) -> DMat3 {
    DMat3::from_cols(n * n.x, n * n.y, n * n.z)
}

/// Gathers into `out`, breadth first from `v` and up to `rings` rings, the vertices that
/// `admit` takes, reached across edges through taken vertices (`v` first, always taken);
/// `stamp` marks the vertices seen, with `v`'s index. False, with `out` cut short, when a
/// vertex past `max_points` would be taken.
fn gather(
    table: &CornerTable,
    v: usize,
    stamp: &mut [u32],
    out: &mut Vec<u32>,
    rings: usize,
    max_points: usize,
    mut admit: impl FnMut(usize) -> bool,
) -> bool {
    out.clear();
    out.push(v as u32);
    stamp[v] = v as u32;
    let mut start = 0;
    for _ in 0..rings {
        let end = out.len();
        if start == end {
            break;
        }
        for i in start..end {
            for c in table.vertex_corners(VertexId(out[i])) {
                let w = table.vertex(table.next(c)).index();
                if stamp[w] != v as u32 && admit(w) {
                    stamp[w] = v as u32;
                    if out.len() >= max_points {
                        return false;
                    }
                    out.push(w as u32);
                }
            }
        }
        start = end;
    }
    true
}

/// The smallest eigenvalue of a symmetric 3x3 matrix (the trigonometric solution of its
/// characteristic cubic).
fn smallest_eigenvalue(a: DMat3) -> f64 {
    let (a00, a11, a22) = (a.x_axis.x, a.y_axis.y, a.z_axis.z);
    let (a01, a02, a12) = (a.y_axis.x, a.z_axis.x, a.z_axis.y);
    let p1 = a01 * a01 + a02 * a02 + a12 * a12;
    let q = (a00 + a11 + a22) / 3.0;
    if p1 <= f64::EPSILON * q.abs().max(f64::MIN_POSITIVE) {
        return a00.min(a11).min(a22);
    }
    let p2 = (a00 - q).powi(2) + (a11 - q).powi(2) + (a22 - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    let bm = (a - DMat3::from_diagonal(DVec3::splat(q))) * (1.0 / p);
    let r = (bm.determinant() / 2.0).clamp(-1.0, 1.0);
    let phi = r.acos() / 3.0;
    // The three eigenvalues are q + 2p cos(phi + 2k pi / 3); k = 1 gives the smallest.
    q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos()
}

/// Moves the vertex nearest each apex (or corner) that a cut left off the surface onto the
/// point where the tangent planes of the vertices around it meet (module docs). Every fit
/// reads the input positions; the moves are then made fittest first (smallest residual),
/// each only when no neighbour of its vertex moved before it and no triangle of its fan
/// turns over or gets an angle under one degree, so the result does not depend on the
/// vertex order. Fails with [`Error::InvalidInput`] when `mesh` is not an oriented manifold
/// with finite coordinates, [`Error::Parameter`] for options out of range.
pub fn restore_apexes(mesh: &mut Mesh, opts: &ApexOptions) -> Result<ApexReport, Error> {
    restore_apexes_in(mesh, opts, None)
}

with_table_entry_point!(
    restore_apexes,
    restore_apexes_with_table,
    restore_apexes_in,
    ApexOptions,
    ApexReport
);

fn restore_apexes_in(
    mesh: &mut Mesh,
    opts: &ApexOptions,
    given: Option<&CornerTable>,
) -> Result<ApexReport, Error> {
    opts.validate()?;
    let table = table_for(mesh, given)?;
    let nv = mesh.positions.len();
    let normals = vertex_normals(mesh);
    let edge = table.mean_edge_length(&mesh.positions);
    let mut report = ApexReport::default();
    if !(edge > 0.0 && edge.is_finite()) {
        return Ok(report);
    }
    let p = &mesh.positions;
    let (inner, outer_squared) = (opts.inner * edge, (opts.outer * edge).powi(2));
    let max_points = (MAX_POINTS_PER_SQUARED_EDGE * opts.outer * opts.outer).ceil() as usize;
    let cos_turn = TURN_DEGREES.to_radians().cos();
    const NONE: u32 = u32::MAX;
    let (mut stamp, mut ring_stamp) = (vec![NONE; nv], vec![NONE; nv]);
    let mut ring: Vec<u32> = Vec::new();
    let mut gathered: Vec<u32> = Vec::new();
    // (distance, vertex) of the band, and a copy the median is selected in.
    let mut band: Vec<(f64, u32)> = Vec::new();
    let mut median = band.clone();
    // (residual, vertex, point) of each fitted vertex.
    let mut fits: Vec<(f64, u32, DVec3)> = Vec::new();
    for v in 0..nv {
        let n = normals[v];
        let vid = VertexId(v as u32);
        if n == DVec3::ZERO || table.vertex_corner(vid).is_none() || table.is_boundary_vertex(vid) {
            continue;
        }
        let turns = table.vertex_corners(vid).any(|c| {
            let w = table.vertex(table.next(c)).index();
            normals[w].dot(n) < cos_turn
        });
        if !turns {
            continue;
        }
        report.candidates += 1;
        // The two rings' normals must already spread over three directions: the tip of a
        // cut lies within an edge of the faces it joins, while the crease vertices that pass
        // the turn (most candidates) see two faces only. Cheaper than the band's gathering.
        gather(&table, v, &mut ring_stamp, &mut ring, 2, usize::MAX, |_| {
            true
        });
        let tensor = ring
            .iter()
            .fold(DMat3::ZERO, |t, &w| t + outer(normals[w as usize]));
        if smallest_eigenvalue(tensor * (1.0 / ring.len() as f64)) < MIN_RING_SPREAD {
            continue;
        }
        report.spread += 1;
        // Every vertex within the outer radius reached across edges from v through vertices
        // within it.
        let within = |w: usize| p[w].distance_squared(p[v]) <= outer_squared;
        if !gather(
            &table,
            v,
            &mut stamp,
            &mut gathered,
            usize::MAX,
            max_points,
            within,
        ) {
            continue;
        }
        // The band's point first: on most candidates (crease vertices, whose normals span
        // two directions) it is all there is to compute.
        band.clear();
        let mut all = PlanePoint::new(p[v]);
        for &w in &gathered {
            let (q, m) = (p[w as usize], normals[w as usize]);
            let d = q.distance(p[v]);
            if d >= inner && m != DVec3::ZERO {
                band.push((d, w));
                all.add(q, m);
            }
        }
        if band.len() < 2 * MIN_HALF_POINTS {
            continue;
        }
        let Some((x, residual)) = all.solve() else {
            continue;
        };
        if residual > MAX_RESIDUAL * edge {
            continue;
        }
        // The nearer half: below the median by distance (ties by index, so the split does
        // not depend on the gathering's order); each half summed in gathering order.
        let by_distance = |a: &(f64, u32), b: &(f64, u32)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
        median.clear();
        median.extend_from_slice(&band);
        let half = band.len() / 2;
        let pivot = *median.select_nth_unstable_by(half, by_distance).1;
        let (mut near, mut far) = (PlanePoint::new(p[v]), PlanePoint::new(p[v]));
        for b in &band {
            let (q, m) = (p[b.1 as usize], normals[b.1 as usize]);
            if by_distance(b, &pivot).is_lt() {
                near.add(q, m);
            } else {
                far.add(q, m);
            }
        }
        let (Some((x_near, _)), Some((x_far, _))) = (near.solve(), far.solve()) else {
            continue;
        };
        if x_near.distance(x_far) > MAX_HALVES_APART * edge {
            continue;
        }
        // Only the vertex nearest the point moves: the tip of the cut.
        let dv = x.distance_squared(p[v]);
        if gathered
            .iter()
            .any(|&w| w as usize != v && x.distance_squared(p[w as usize]) < dv)
        {
            continue;
        }
        report.fitted += 1;
        let moved = dv.sqrt();
        if moved < MIN_MOVE * edge {
            continue;
        }
        if moved > opts.max_move * edge {
            report.refused_moves += 1;
            continue;
        }
        fits.push((residual, v as u32, x));
    }
    fits.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut moved = vec![false; nv];
    let min_sin = MIN_ANGLE_DEGREES.to_radians().sin();
    for (_, v, x) in fits {
        let vid = VertexId(v);
        let neighbour_moved = table
            .vertex_corners(vid)
            .any(|c| moved[table.vertex(table.next(c)).index()]);
        let keeps_fan = table.vertex_corners(vid).all(|c| {
            let (a, b) = (
                mesh.positions[table.vertex(table.next(c)).index()],
                mesh.positions[table.vertex(table.prev(c)).index()],
            );
            let before = (a - mesh.positions[v as usize]).cross(b - mesh.positions[v as usize]);
            let after = (a - x).cross(b - x);
            after.dot(before) > 0.0 && angles_at_least(x, a, b, min_sin)
        });
        if neighbour_moved || !keeps_fan {
            report.refused_moves += 1;
            continue;
        }
        mesh.positions[v as usize] = x;
        moved[v as usize] = true;
        report.moved_vertices += 1;
    }
    Ok(report)
}

/// Whether each angle of the triangle `a b c` has a sine of at least `min_sin` (the
/// triangle's doubled area over the product of the two sides at the corner).
fn angles_at_least(a: DVec3, b: DVec3, c: DVec3, min_sin: f64) -> bool {
    let twice_area = (b - a).cross(c - a).length();
    let (ab, bc, ca) = (a.distance(b), b.distance(c), c.distance(a));
    [ab * ca, ab * bc, bc * ca]
        .iter()
        .all(|&sides| twice_area >= min_sin * sides && sides > 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planar::checked_table;

    /// A closed cone of half-angle `atan(radius / height)` with its apex at `(0, 0, height)`:
    /// `around` vertices on each of `rings` rings evenly spaced from the apex to the base
    /// rim, a fan to a centre vertex under the base, and the apex vertex (index 0) moved
    /// `cut` down the axis, as a retiling that cuts the tip leaves it. `noise` (absolute)
    /// pushes the ring vertices along their radius, deterministically. With four around it
    /// is a square pyramid.
    fn cut_cone(
        around: usize,
        rings: usize,
        height: f64,
        radius: f64,
        cut: f64,
        noise: f64,
    ) -> Mesh {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut rand = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut positions = vec![DVec3::new(0.0, 0.0, height - cut)];
        for j in 1..=rings {
            let t = j as f64 / rings as f64;
            for i in 0..around {
                // Each ring turned half a step from the one before, except on a pyramid
                // (four around), whose rings line up so its faces stay planar.
                let twist = if around > 4 { 0.5 * j as f64 } else { 0.0 };
                let a = std::f64::consts::TAU * (i as f64 + twist) / around as f64;
                let r = radius * t + noise * rand();
                positions.push(DVec3::new(r * a.cos(), r * a.sin(), height * (1.0 - t)));
            }
        }
        let base = positions.len() as u32;
        positions.push(DVec3::ZERO);
        let id = |j: usize, i: usize| (1 + (j - 1) * around + i % around) as u32;
        let mut triangles = Vec::new();
        for i in 0..around {
            triangles.push([0, id(1, i), id(1, i + 1)]);
            triangles.push([base, id(rings, i + 1), id(rings, i)]);
        }
        for j in 1..rings {
            for i in 0..around {
                triangles.push([id(j, i), id(j + 1, i), id(j + 1, i + 1)]);
                triangles.push([id(j, i), id(j + 1, i + 1), id(j, i + 1)]);
            }
        }
        Mesh::new(positions, triangles)
    }

    /// A UV sphere of radius `r` (`around` x `up` quads, fans at the poles).
    fn uv_sphere(r: f64, around: usize, up: usize) -> Mesh {
        let mut positions = vec![DVec3::new(0.0, 0.0, r)];
        for j in 1..up {
            let polar = std::f64::consts::PI * j as f64 / up as f64;
            for i in 0..around {
                let a = std::f64::consts::TAU * i as f64 / around as f64;
                positions.push(
                    r * DVec3::new(polar.sin() * a.cos(), polar.sin() * a.sin(), polar.cos()),
                );
            }
        }
        let south = positions.len() as u32;
        positions.push(DVec3::new(0.0, 0.0, -r));
        let id = |j: usize, i: usize| (1 + (j - 1) * around + i % around) as u32;
        let mut triangles = Vec::new();
        for i in 0..around {
            triangles.push([0, id(1, i), id(1, i + 1)]);
            triangles.push([south, id(up - 1, i + 1), id(up - 1, i)]);
        }
        for j in 1..up - 1 {
            for i in 0..around {
                triangles.push([id(j, i), id(j + 1, i), id(j + 1, i + 1)]);
                triangles.push([id(j, i), id(j + 1, i + 1), id(j, i + 1)]);
            }
        }
        Mesh::new(positions, triangles)
    }

    fn mean_edge(mesh: &Mesh) -> f64 {
        checked_table(mesh)
            .map(|t| t.mean_edge_length(&mesh.positions))
            .unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn a_cut_cone_gets_its_apex_back_and_nothing_else_moves() {
        let input = cut_cone(16, 8, 2.0, 1.0, 0.18, 0.0);
        assert!(input.topology_report().manifold);
        let edge = mean_edge(&input);
        let apex = DVec3::new(0.0, 0.0, 2.0);
        let before = input.positions[0].distance(apex);
        assert!(
            before > 0.4 * edge,
            "the cut is {} edges deep",
            before / edge
        );
        let mut out = input.clone();
        let report = restore_apexes(&mut out, &ApexOptions::DEFAULT).unwrap();
        assert_eq!(report.moved_vertices, 1, "{report:?}");
        let after = out.positions[0].distance(apex);
        assert!(after < 0.02 * edge, "{} edges off the apex", after / edge);
        for (v, (a, b)) in input
            .positions
            .iter()
            .zip(&out.positions)
            .enumerate()
            .skip(1)
        {
            assert_eq!(
                a.to_array().map(f64::to_bits),
                b.to_array().map(f64::to_bits),
                "vertex {v}"
            );
        }
        let topo = out.topology_report();
        assert!(topo.manifold && topo.oriented && topo.boundary_edges == 0);
    }

    #[test]
    fn a_noisy_cut_cone_gets_its_apex_back() {
        // Noise of 3-6 % of the ring spacing (a 6-bit swing stream's scale).
        for (around, noise) in [(16, 0.008), (12, 0.016)] {
            let input = cut_cone(around, 8, 2.0, 1.0, 0.18, noise);
            let edge = mean_edge(&input);
            let apex = DVec3::new(0.0, 0.0, 2.0);
            let mut out = input.clone();
            let report = restore_apexes(&mut out, &ApexOptions::DEFAULT).unwrap();
            let (before, after) = (
                input.positions[0].distance(apex),
                out.positions[0].distance(apex),
            );
            assert_eq!(report.moved_vertices, 1, "{around} around: {report:?}");
            assert!(
                after < 0.25 * before,
                "{around} around: {} -> {} edges off the apex",
                before / edge,
                after / edge
            );
        }
    }

    #[test]
    fn a_cut_conical_pit_gets_its_apex_back() {
        // The cut cone turned inside out (a countersink's or a drill point's hole): the
        // tangent planes meet at the apex all the same.
        let mut input = cut_cone(16, 8, 2.0, 1.0, 0.18, 0.0);
        for t in &mut input.triangles {
            t.swap(1, 2);
        }
        let edge = mean_edge(&input);
        let apex = DVec3::new(0.0, 0.0, 2.0);
        let mut out = input.clone();
        let report = restore_apexes(&mut out, &ApexOptions::DEFAULT).unwrap();
        assert_eq!(report.moved_vertices, 1, "{report:?}");
        let after = out.positions[0].distance(apex);
        assert!(after < 0.02 * edge, "{} edges off the apex", after / edge);
    }

    #[test]
    fn a_corner_pushed_in_goes_back_and_sharp_corners_stay() {
        use whet_synth::{midpoint_subdivide, Shape, ShapeKind, ShapeParams};
        // The pyramid's apex joins four faces, the cube's corners three.
        for kind in [ShapeKind::Pyramid, ShapeKind::Cube] {
            let shape = Shape::new(kind, &ShapeParams::default()).unwrap();
            let sharp = midpoint_subdivide(shape.truth_mesh_ref(), 3);
            let edge = mean_edge(&sharp);
            // Already sharp: no move.
            let mut out = sharp.clone();
            let report = restore_apexes(&mut out, &ApexOptions::DEFAULT).unwrap();
            assert_eq!(report.moved_vertices, 0, "{kind:?} {report:?}");
            assert_eq!(out.positions, sharp.positions);
            // The highest vertex (the apex, a cube corner) pushed 0.6 edges towards the
            // centroid, as a cut leaves it.
            let tip = (0..sharp.positions.len())
                .max_by(|&a, &b| {
                    let (pa, pb) = (sharp.positions[a], sharp.positions[b]);
                    (pa.y, pa.x + pa.z)
                        .partial_cmp(&(pb.y, pb.x + pb.z))
                        .unwrap()
                })
                .unwrap();
            let corner = sharp.positions[tip];
            let mut cut = sharp.clone();
            cut.positions[tip] -= corner.normalize() * 0.6 * edge;
            let report = restore_apexes(&mut cut, &ApexOptions::DEFAULT).unwrap();
            assert_eq!(report.moved_vertices, 1, "{kind:?} {report:?}");
            let off = cut.positions[tip].distance(corner) / edge;
            assert!(off < 0.01, "{kind:?}: {off} edges off the corner");
        }
    }

    #[test]
    fn domes_cylinders_and_limits_move_nothing() {
        // A coarse sphere (about 0.4 radius per edge): its poles turn, but their tangent
        // planes meet in no point.
        for mesh in [uv_sphere(1.0, 16, 8), uv_sphere(1.0, 10, 6)] {
            let mut out = mesh.clone();
            let report = restore_apexes(&mut out, &ApexOptions::DEFAULT).unwrap();
            assert!(report.candidates > 0, "{report:?}");
            assert_eq!(report.moved_vertices, 0, "{report:?}");
            assert_eq!(out.positions, mesh.positions);
        }
        // A closed cylinder: its rims are creases (normals in a plane of directions plus the
        // caps'), no point.
        let cylinder = crate::quadric::tests::cylinder(1.0, 3.0, 24, 12, 0.0);
        let mut out = cylinder.clone();
        let report = restore_apexes(&mut out, &ApexOptions::DEFAULT).unwrap();
        assert_eq!(report.moved_vertices, 0, "{report:?}");
        // The cut cone with a move limit under its cut's depth stays.
        let input = cut_cone(16, 8, 2.0, 1.0, 0.18, 0.0);
        let mut out = input.clone();
        let report = restore_apexes(&mut out, &ApexOptions::DEFAULT.with_max_move(0.3)).unwrap();
        assert_eq!(
            (report.moved_vertices, report.refused_moves),
            (0, 1),
            "{report:?}"
        );
        assert_eq!(out.positions, input.positions);
    }

    #[test]
    fn bad_options_and_bad_meshes_are_refused() {
        let mut cone = cut_cone(8, 6, 2.0, 1.0, 0.1, 0.0);
        for bad in [
            ApexOptions::DEFAULT.with_band(2.0, 1.0),
            ApexOptions::DEFAULT.with_band(-1.0, 3.0),
            ApexOptions::DEFAULT.with_band(1.0, 9.0),
            ApexOptions::DEFAULT.with_max_move(f64::NAN),
        ] {
            assert!(matches!(
                restore_apexes(&mut cone, &bad),
                Err(Error::Parameter(_))
            ));
        }
        let mut nan = cone.clone();
        nan.positions[3].x = f64::NAN;
        assert!(matches!(
            restore_apexes(&mut nan, &ApexOptions::DEFAULT),
            Err(Error::InvalidInput(_))
        ));
        // Three triangles on one edge.
        let mut fin = cone.clone();
        let [a, b, _] = fin.triangles[0];
        fin.positions.push(DVec3::new(5.0, 5.0, 5.0));
        fin.triangles.push([a, b, fin.positions.len() as u32 - 1]);
        assert!(matches!(
            restore_apexes(&mut fin, &ApexOptions::DEFAULT),
            Err(Error::InvalidInput(_))
        ));
        // No triangles: nothing to do.
        let mut empty = Mesh::new(vec![DVec3::ONE], Vec::new());
        assert_eq!(
            restore_apexes(&mut empty, &ApexOptions::DEFAULT).unwrap(),
            ApexReport::default()
        );
    }

    #[test]
    fn the_smallest_eigenvalue_is_that_of_known_matrices() {
        let d = DMat3::from_diagonal(DVec3::new(3.0, 1.0, 2.0));
        assert!((smallest_eigenvalue(d) - 1.0).abs() < 1e-12);
        // [[2, 1, 0], [1, 2, 0], [0, 0, 5]]: eigenvalues 1, 3, 5.
        let m = DMat3::from_cols(
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(0.0, 0.0, 5.0),
        );
        assert!((smallest_eigenvalue(m) - 1.0).abs() < 1e-12);
        // A rank-2 tensor of unit normals (a crease): 0.
        let (a, b) = (DVec3::X, DVec3::new(0.6, 0.8, 0.0));
        let t = DMat3::from_cols(a * a.x, a * a.y, a * a.z)
            + DMat3::from_cols(b * b.x, b * b.y, b * b.z);
        assert!(smallest_eigenvalue(t).abs() < 1e-12);
    }
}
