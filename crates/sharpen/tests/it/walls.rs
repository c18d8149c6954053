//! Curved walls (`SharpenOptions::curved_wall_factor`, docs/sharpen.md): a flat plate meets a
//! cylinder a few samples in radius across a chamfer, the shape of a small hole's rim; and
//! passes (`SharpenOptions::passes`): the sharpener run again on its own output.

use whet_mesh::{DVec3, Mesh};
use whet_sharpen::{sharpen, Method, SharpenOptions};

/// Radius of the cylinder, in grid steps: it turns by about 16 degrees per step, over a
/// smooth threshold of twice the mean angle (9.4 degrees with the noise below, 0.05 steps;
/// at 0.06 the noise alone makes enough of its edges smooth to find the chamfer).
const RADIUS: f64 = 3.5;
/// Where the cylinder leaves the plate, and at what angle below it.
const TILT: f64 = std::f64::consts::FRAC_PI_4;

/// The true surface at `x` (the crease at `x = 0`): the plate `z = 0` for `x <= 0`, beyond
/// it the cylinder of axis `y` leaving the plate at 45 degrees and bending down, by arc
/// length.
fn surface(x: f64) -> (f64, f64) {
    if x <= 0.0 {
        (x, 0.0)
    } else {
        let a = TILT + x / RADIUS;
        (
            RADIUS * (a.sin() - TILT.sin()),
            RADIUS * (a.cos() - TILT.cos()),
        )
    }
}

/// A grid over the parameter `x` (20 steps on the plate, 8 on the cylinder, offset by half a
/// step so that one column of cells straddles the crease: the chamfer) and `y` (12 steps),
/// each cell cut by one diagonal. Every vertex is on the true surface but for a
/// deterministic offset along the surface normal of up to `noise` steps, as quantization
/// leaves on a decoded mesh: it sets the mean normal angle, hence the smooth threshold.
fn plate_and_cylinder(noise: f64) -> Mesh {
    let (nx, ny) = (29usize, 13usize);
    let mut positions = Vec::with_capacity(nx * ny);
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    for j in 0..ny {
        for i in 0..nx {
            let t = i as f64 - 20.5;
            let (x, z) = surface(t);
            // splitmix64, mapped to [-1, 1)
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut h = state;
            h = (h ^ (h >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            h = (h ^ (h >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            h ^= h >> 31;
            let u = (h >> 11) as f64 / (1u64 << 52) as f64 - 1.0;
            let normal = if t <= 0.0 {
                DVec3::Z
            } else {
                let a = TILT + t / RADIUS;
                DVec3::new(a.sin(), 0.0, a.cos())
            };
            positions.push(DVec3::new(x, j as f64, z) + noise * u * normal);
        }
    }
    let mut triangles = Vec::new();
    let at = |i: usize, j: usize| (j * nx + i) as u32;
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    Mesh::new(positions, triangles)
}

/// Distance of `p` to the crease line (`x = z = 0`).
fn off_crease(p: DVec3) -> f64 {
    (p.x * p.x + p.z * p.z).sqrt()
}

#[test]
fn a_tight_cylinder_beside_a_plate_gets_its_chamfer_split_with_curved_walls_only() {
    let mesh = plate_and_cylinder(0.05);
    for method in crate::EDGE_SHARPENER {
        let opts = SharpenOptions::DEFAULT.with_method(method);
        // Without curved walls the cylinder has no core vertex: no red region on its side,
        // so no chamfer edge across the crease.
        let plain = sharpen(&mesh, &opts.with_curved_wall_factor(0.0)).unwrap();
        assert_eq!(plain.report.curved_wall_edges, 0, "{method}");
        let crease_vertices = |m: &Mesh| {
            m.positions[mesh.positions.len()..]
                .iter()
                .filter(|p| off_crease(**p) < 0.25)
                .count()
        };
        assert_eq!(crease_vertices(&plain.mesh), 0, "{method}");
        let walls = sharpen(&mesh, &opts.with_curved_wall_factor(2.0)).unwrap();
        let r = &walls.report;
        assert!(r.curved_wall_edges > 0, "{method}: {r:?}");
        assert_eq!(r.curved_wall_factor, 2.0);
        // Off by default, for both methods.
        let default = sharpen(&mesh, &opts).unwrap();
        assert_eq!(default.mesh, plain.mesh, "{method}");
        // The interior rows of the chamfer (11 cells, one new vertex on each cell's
        // crossing edge) get vertices near the crease: between the plate and the
        // cylinder's tangent plane one step from it, within a quarter step.
        let near = crease_vertices(&walls.mesh);
        assert!(
            near >= 9,
            "{method}: {near} new vertices near the crease, {r:?}"
        );
        // Nothing moved on the cylinder far from the crease, nor on the plate.
        for (v, (a, b)) in mesh.positions.iter().zip(&walls.mesh.positions).enumerate() {
            assert_eq!(a, b, "{method}: input vertex {v} moved");
        }
        // The output is an oriented manifold with the input's boundary.
        let c = crate::support::check(&mesh, &mesh, &walls);
        assert!(c.manifold, "{method}: {c:?}");
        assert_eq!(c.new_boundary_edges, 0, "{method}: {c:?}");
    }
}

/// `SharpenOptions::passes`: a second pass runs on the first one's output, and the result
/// is that of sharpening twice, with parents traced back to the input and the tags of both.
#[test]
fn two_passes_are_the_sharpener_run_on_its_own_output() {
    use whet_synth::{marching_cubes, Shape, ShapeKind, ShapeParams};
    let rotation = glam::DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.44);
    let shape = Shape::new(
        ShapeKind::Fandisk,
        &ShapeParams::default().with_rotation(rotation),
    )
    .unwrap();
    let mesh = marching_cubes(&shape, 24).unwrap();
    for method in crate::EDGE_SHARPENER {
        let once_opts = SharpenOptions::DEFAULT.with_method(method);
        let once = sharpen(&mesh, &once_opts).unwrap();
        // The first pass's output has its creases on edges: a run of its own leaves it
        // alone as already sharp (extended), unless told to take it for a sampling, as a
        // later pass does.
        if method == Method::Extended {
            let kept = sharpen(&once.mesh, &once_opts).unwrap();
            assert_eq!(kept.report.already_sharp_components, 1);
            assert_eq!(kept.mesh, once.mesh);
        }
        let again = sharpen(&once.mesh, &once_opts.with_keep_sharp_parts(false)).unwrap();
        assert!(
            again.report.new_vertices > 0,
            "{method}: nothing for a second pass"
        );
        let twice = sharpen(&mesh, &once_opts.with_passes(2)).unwrap();
        let r = &twice.report;
        assert_eq!(r.passes, 2, "{method}");
        assert_eq!(twice.mesh, again.mesh, "{method}");
        assert_eq!(
            r.new_vertices,
            once.report.new_vertices + again.report.new_vertices
        );
        assert_eq!(r.input_vertices, mesh.positions.len());
        assert_eq!(
            r.smooth_threshold_degrees,
            once.report.smooth_threshold_degrees
        );
        // Parents: each output triangle's parent in the second pass, then in the first.
        assert_eq!(twice.parents.len(), twice.mesh.triangles.len());
        for (p2, p) in again.parents.iter().zip(&twice.parents) {
            assert_eq!(*p, once.parents[p2.index()], "{method}");
            assert!(p.index() < mesh.triangles.len());
        }
        // Tags: every vertex either pass tagged that the output still uses (the second
        // pass may weld one of the first pass's vertices away), and the edges between them.
        let mut used = vec![false; twice.mesh.positions.len()];
        for &v in twice.mesh.triangles.iter().flatten() {
            used[v as usize] = true;
        }
        let mut kept = 0;
        for v in once.tags.vertices.iter().chain(&again.tags.vertices) {
            if !used[v.index()] {
                continue;
            }
            kept += 1;
            assert!(
                twice.tags.vertices.binary_search(v).is_ok(),
                "{method}: {v:?}"
            );
        }
        assert!(kept > 0, "{method}: no tag kept");
        assert_eq!(r.tagged_vertices, twice.tags.vertices.len());
        // Input vertices other than chamfer vertices stay put through both passes.
        let moved = mesh
            .positions
            .iter()
            .zip(&twice.mesh.positions)
            .filter(|(a, b)| a != b)
            .count();
        assert!(
            moved <= r.moved_input_vertices + r.welded_vertices,
            "{method}"
        );
        // Four passes are the sharpener run on its own output until a run gives its input
        // back (or four ran); more are refused.
        let mut manual = vec![once.mesh.clone()];
        while manual.len() < 4 {
            let later = once_opts.with_keep_sharp_parts(false);
            let m = sharpen(manual.last().unwrap(), &later).unwrap().mesh;
            if m == *manual.last().unwrap() {
                break;
            }
            manual.push(m);
        }
        let four = sharpen(&mesh, &once_opts.with_passes(4)).unwrap();
        assert_eq!(four.report.passes, manual.len(), "{method}");
        assert_eq!(four.mesh, *manual.last().unwrap(), "{method}");
        for bad in [0, 5] {
            assert!(
                sharpen(&mesh, &once_opts.with_passes(bad)).is_err(),
                "{bad}"
            );
        }
        // A budget under the first output's size stops after the first pass.
        let budget = once_opts
            .with_passes(4)
            .with_pass_budget_triangles(mesh.triangles.len() as u64);
        let capped = sharpen(&mesh, &budget).unwrap();
        assert_eq!(
            (capped.report.passes, &capped.mesh),
            (1, &once.mesh),
            "{method}"
        );
    }
}

/// A mesh the sharpener gives back unchanged takes one pass, however many are asked for.
#[test]
fn passes_stop_where_a_pass_changes_nothing() {
    use whet_synth::{Shape, ShapeKind, ShapeParams};
    // The exact cube: its creases lie on vertices, nothing is chamfered.
    let cube = Shape::new(ShapeKind::Cube, &ShapeParams::default())
        .unwrap()
        .truth_mesh();
    for method in crate::EDGE_SHARPENER {
        let opts = SharpenOptions::DEFAULT.with_method(method).with_passes(4);
        let out = sharpen(&cube, &opts).unwrap();
        assert_eq!(out.report.passes, 1, "{method}");
        assert_eq!(out.mesh, cube, "{method}");
        assert_eq!(out.report.new_vertices, 0, "{method}");
    }
}
