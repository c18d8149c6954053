//! Measurement support shared by the examples and the integration tests (tests include this
//! file with `#[path]`): the stand-in for SwingWrapper retiling, the Metro figures, and the
//! output checks of the issue (manifold, no new boundary, reversed and thin new triangles).
#![allow(dead_code)]

use std::collections::HashMap;

use glam::{DQuat, DVec3};
use whet_mesh::{angle_between, edge_key, Mesh};
use whet_metro::{metro, Bvh, MetroOptions};

/// Two generic rotations (no crease aligned with the grid) used by every table.
pub fn rotations() -> [DQuat; 2] {
    [
        DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.5),
        DQuat::from_axis_angle(DVec3::new(-2.0, 1.0, 0.5).normalize(), 1.1),
    ]
}

/// Signed distance to a closed, oriented triangle mesh: Euclidean distance from the BVH,
/// sign from the angle-weighted pseudo-normal of the closest feature (Bærentzen & Aanæs 2005):
/// the face normal inside a face, the sum of the two face normals on an edge, the
/// angle-weighted vertex normal at a vertex. Exact and 1-Lipschitz for a closed manifold.
pub struct SignedDistance<'a> {
    mesh: &'a Mesh,
    bvh: Bvh,
    face_normals: Vec<DVec3>,
    vertex_normals: Vec<DVec3>,
    edge_normals: HashMap<u64, DVec3>,
}

impl<'a> SignedDistance<'a> {
    pub fn new(mesh: &'a Mesh) -> Self {
        let face_normals = mesh.face_normals();
        let vertex_normals = mesh.vertex_normals();
        let mut edge_normals: HashMap<u64, DVec3> = HashMap::new();
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                *edge_normals
                    .entry(edge_key(tri[k], tri[(k + 1) % 3]))
                    .or_insert(DVec3::ZERO) += face_normals[t];
            }
        }
        SignedDistance {
            mesh,
            bvh: Bvh::new(mesh),
            face_normals,
            vertex_normals,
            edge_normals,
        }
    }

    pub fn eval(&self, p: DVec3) -> f64 {
        let cp = self.bvh.closest_point(p);
        let t = cp.triangle as usize;
        let tri = self.mesh.triangles[t];
        let [a, b, c] = self.mesh.triangle_positions(t);
        // Barycentric coordinates of the closest point.
        let (v0, v1, v2) = (b - a, c - a, cp.point - a);
        let (d00, d01, d11) = (v0.dot(v0), v0.dot(v1), v1.dot(v1));
        let (d20, d21) = (v2.dot(v0), v2.dot(v1));
        let den = d00 * d11 - d01 * d01;
        let (v, w) = if den > 0.0 {
            ((d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den)
        } else {
            (1.0 / 3.0, 1.0 / 3.0)
        };
        let bary = [1.0 - v - w, v, w];
        let eps = 1e-9;
        let zero: Vec<usize> = (0..3).filter(|&k| bary[k] <= eps).collect();
        let n = match zero.len() {
            0 => self.face_normals[t],
            1 => {
                let k = zero[0];
                self.edge_normals[&edge_key(tri[(k + 1) % 3], tri[(k + 2) % 3])]
            }
            _ => {
                let k = (0..3).find(|k| !zero.contains(k)).unwrap_or(0);
                self.vertex_normals[tri[k] as usize]
            }
        };
        let s = (p - cp.point).dot(n);
        if s < 0.0 {
            -cp.distance
        } else {
            cp.distance
        }
    }
}

/// The sweeps' first three arguments: `[seed] [cases] [papers|extended]` (extended when
/// absent), with the given defaults; the rest of the arguments follow.
pub fn sweep_args(seed: u64, cases: usize) -> (u64, usize, whet_sharpen::Method, Vec<String>) {
    let args: Vec<String> = std::env::args().collect();
    let seed = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(seed);
    let cases = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(cases);
    let method = match args.get(3).map(String::as_str) {
        Some("papers") => whet_sharpen::Method::Papers,
        None | Some("extended") => whet_sharpen::Method::Extended,
        Some(other) => panic!("method {other:?}: expected papers or extended"),
    };
    (seed, cases, method, args.into_iter().skip(4).collect())
}

/// A random rotation axis and angle (radians, under `pi * angle_scale`) drawn from `rng`, as
/// the sweeps draw them (each line of their output prints both).
pub fn random_turn(rng: &mut whet_testkit::Lcg, angle_scale: f64) -> (DVec3, f64) {
    let axis = DVec3::new(
        rng.unit() * 2.0 - 1.0,
        rng.unit() * 2.0 - 1.0,
        rng.unit() * 2.0 - 1.0 + 1e-3,
    )
    .normalize();
    (axis, rng.unit() * std::f64::consts::PI * angle_scale)
}

/// A shared fixture turned by `rotation` and sampled by marching cubes of its signed distance
/// at `resolution` cells: the turned fixture (the reference) and the sampling. Parts a user
/// sends come at any angle; the figure tables sample the fixtures only in their own,
/// mostly axis-aligned, orientation.
pub fn turned_sampling(
    original: &Mesh,
    rotation: DQuat,
    resolution: usize,
) -> Result<(Mesh, Mesh), whet_synth::Error> {
    let truth = Mesh::new(
        original.positions.iter().map(|&p| rotation * p).collect(),
        original.triangles.clone(),
    );
    let sd = SignedDistance::new(&truth);
    let input = whet_synth::marching_cubes_fn(|p| sd.eval(p), &truth.bounding_box(), resolution)?;
    Ok((truth, input))
}

/// The stand-in for a SwingWrapper-decoded mesh until the swing codec lands: marching cubes of
/// the signed distance to `original` at the resolution whose output has about `ratio` times
/// the original's vertex count. Like SwingWrapper it samples the surface uniformly without
/// looking at its creases, puts its vertices on (or within interpolation error of) the
/// surface, and so chamfers every sharp edge and corner. Unlike SwingWrapper its triangles are
/// not near-equilateral (marching cubes makes slivers), which makes the test harder, not
/// easier. Returns the mesh and the resolution used.
pub fn retile_stand_in(original: &Mesh, ratio: f64) -> (Mesh, usize) {
    let sd = SignedDistance::new(original);
    let bounds = original.bounding_box();
    let target = ratio * original.positions.len() as f64;
    let mc = |res: usize| {
        whet_synth::marching_cubes_fn(|p| sd.eval(p), &bounds, res)
            .unwrap_or_else(|e| panic!("marching cubes of the fixture failed: {e}"))
    };
    let mut res = 48usize;
    let mut mesh = mc(res);
    // The vertex count grows as res^2: two corrections land within a few percent.
    for _ in 0..2 {
        let scale = (target / mesh.positions.len() as f64).sqrt();
        let next = ((res as f64 * scale).round() as usize).clamp(8, 1024);
        if next == res {
            break;
        }
        res = next;
        mesh = mc(res);
    }
    (mesh, res)
}

/// [`retile_stand_in`] of a shared fixture, cached under `target/sharpen-stand-in/` (the
/// marching cubes of a mesh's signed distance takes seconds; the result is deterministic).
pub fn cached_stand_in(name: &str, ratio: f64) -> (Mesh, Mesh, usize) {
    let original = whet_io::read_path(&whet_testkit::shared_fixture(name), None)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let dir = whet_testkit::workspace_root().join("target/sharpen-stand-in");
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join(format!("v1-{name}-{ratio}.off"));
    if let Ok(mesh) = whet_io::read_path(&path, None) {
        let res = std::fs::read_to_string(path.with_extension("res"))
            .ok()
            .and_then(|s| s.trim().parse().ok())
            .unwrap_or(0);
        return (original, mesh, res);
    }
    let (mesh, res) = retile_stand_in(&original, ratio);
    let _ = whet_io::write_path(&path, &mesh, None, &whet_io::WriteOptions::DEFAULT);
    let _ = std::fs::write(path.with_extension("res"), res.to_string());
    (original, mesh, res)
}

/// Symmetric Metro figures of `test` against `reference`, in percent of the reference's
/// bounding-box diagonal.
#[derive(Clone, Copy, Debug)]
pub struct Error {
    pub rms_pct: f64,
    pub max_pct: f64,
}

pub fn error(reference: &Mesh, test: &Mesh, samples: Option<usize>) -> Error {
    let mut opts = MetroOptions::DEFAULT;
    if let Some(n) = samples {
        opts = opts.with_samples(n);
    }
    let r = metro(reference, test, &opts).unwrap_or_else(|e| panic!("metro failed: {e}"));
    Error {
        rms_pct: r.symmetric.rms_pct,
        max_pct: r.symmetric.max_pct,
    }
}

/// The sweeps' verdict on one case, as they print it.
pub struct SweepVerdict {
    /// Worse at the sweep's sampling and again at 1M samples.
    pub worse: bool,
    /// Worse at the sweep's sampling only.
    pub unconfirmed: bool,
    /// The line's suffix: the errors at 1M samples, when they were measured.
    pub suffix: String,
}

impl SweepVerdict {
    /// The line's prefix: `"WORSE "`, `"UNCONFIRMED "` or nothing.
    pub fn flag(&self) -> &'static str {
        match (self.worse, self.unconfirmed) {
            (true, _) => "WORSE ",
            (false, true) => "UNCONFIRMED ",
            (false, false) => "",
        }
    }
}

/// The sweeps' verdict on one case (`before`, `after`: the errors of the input and of the
/// output at the sweep's sampling): whether it got worse, in RMS or max. A max is the largest
/// of the samples' distances, so two samplings of 50k a direction can rank a case's input and
/// output apart by sampling alone (rotated sharp_sphere at 41 cells: max 3.082 -> 3.139 % at
/// 50k, 3.145 -> 3.127 % at 300k). A case worse at the sweep's sampling is measured again at
/// Metro's default (at least 1M samples a direction) and counts as worse only if it still is.
pub fn sweep_verdict(
    truth: &Mesh,
    input: &Mesh,
    output: &Mesh,
    before: &Error,
    after: &Error,
) -> SweepVerdict {
    let grew = |b: &Error, a: &Error| a.rms_pct > b.rms_pct || a.max_pct > b.max_pct;
    if !grew(before, after) {
        return SweepVerdict {
            worse: false,
            unconfirmed: false,
            suffix: String::new(),
        };
    }
    let (b, a) = (error(truth, input, None), error(truth, output, None));
    let worse = grew(&b, &a);
    SweepVerdict {
        worse,
        unconfirmed: !worse,
        suffix: format!(
            "; at 1M samples RMS {:.4} -> {:.4}, max {:.3} -> {:.3}",
            b.rms_pct, a.rms_pct, b.max_pct, a.max_pct
        ),
    }
}

/// What the issue requires of every output, measured from the outside.
#[derive(Clone, Debug, Default)]
pub struct Checks {
    /// Oriented manifold (the topology report).
    pub manifold: bool,
    /// Boundary edge count of the output minus the input's (must be 0).
    pub new_boundary_edges: i64,
    /// Triangles of the output that are not triangles of the input.
    pub new_triangles: usize,
    /// New triangles facing against the reference surface they lie on (see [`reversed`]).
    pub reversed: usize,
    /// Input triangles facing against the reference surface (the noise floor of `reversed`).
    pub input_reversed: usize,
    /// Smallest angle of a new triangle, degrees.
    pub min_new_angle: f64,
    /// Input vertices whose position changed.
    pub moved_input_vertices: usize,
}

/// Whether triangle `p` faces against the reference surface it lies on: among the reference
/// triangles closest to its corners and centroid, the one whose plane holds its three corners
/// best gives the orientation it must have, if the corners are within a fifth of the longest
/// edge from that plane. (The closest face at the centroid alone is ambiguous next to an acute
/// crease; a triangle lying on no reference plane is an error Metro measures, not a fold.)
pub fn reversed(reference: &Mesh, bvh: &Bvh, normals: &[DVec3], p: &[DVec3; 3]) -> bool {
    let g = (p[0] + p[1] + p[2]) / 3.0;
    let mut best = (f64::INFINITY, DVec3::ZERO);
    for q in [p[0], p[1], p[2], g] {
        let t = bvh.closest_point(q).triangle as usize;
        let n = normals[t];
        let a = reference.positions[reference.triangles[t][0] as usize];
        let d = p
            .iter()
            .map(|x| (*x - a).dot(n).abs())
            .fold(0.0f64, f64::max);
        if d < best.0 {
            best = (d, n);
        }
    }
    let longest = (0..3)
        .map(|k| p[k].distance(p[(k + 1) % 3]))
        .fold(0.0f64, f64::max);
    best.0 <= 0.2 * longest && (p[1] - p[0]).cross(p[2] - p[0]).dot(best.1) < 0.0
}

/// The checks of `out` (sharpened from `input`) against `reference` (truth or original).
pub fn check(reference: &Mesh, input: &Mesh, out: &whet_sharpen::Sharpened) -> Checks {
    let output = &out.mesh;
    let rin = input.topology_report();
    let rout = output.topology_report();
    let keys = input.sorted_vertex_sets();
    let bvh = Bvh::new(reference);
    let normals = reference.face_normals();
    let mut c = Checks {
        manifold: rout.manifold && rout.oriented,
        new_boundary_edges: rout.boundary_edges as i64 - rin.boundary_edges as i64,
        min_new_angle: 180.0,
        ..Checks::default()
    };
    assert_eq!(
        out.parents.len(),
        output.triangles.len(),
        "one parent per triangle"
    );
    for (t, tri) in output.triangles.iter().enumerate() {
        let mut k = *tri;
        k.sort_unstable();
        let same_positions = tri.iter().all(|&v| {
            (v as usize) < input.positions.len()
                && output.positions[v as usize] == input.positions[v as usize]
        });
        if same_positions && keys.binary_search(&k).is_ok() {
            continue;
        }
        c.new_triangles += 1;
        let p = output.triangle_positions(t);
        for i in 0..3 {
            let a = angle_between(p[(i + 1) % 3] - p[i], p[(i + 2) % 3] - p[i]).to_degrees();
            c.min_new_angle = c.min_new_angle.min(a);
        }
        if reversed(reference, &bvh, &normals, &p) {
            c.reversed += 1;
        }
    }
    c.input_reversed = (0..input.triangles.len())
        .filter(|&t| reversed(reference, &bvh, &normals, &input.triangle_positions(t)))
        .count();
    c.moved_input_vertices = input
        .positions
        .iter()
        .zip(&output.positions)
        .filter(|(a, b)| a != b)
        .count();
    c
}
