//! Bender: interpolation, affine invariance, sharp edges staying sharp and bending into
//! curves, boundaries, tag propagation, no flipped triangles on smooth meshes.
#![allow(clippy::unwrap_used)] // a panic is a test failure

use whet_bend::{bend, bend_levels, zorin_weights};
use whet_mesh::{DVec3, Mesh};
use whet_testkit::meshes::{grid, hub_disk, icosphere};

#[test]
fn zorin_weights_sum_to_a_quarter() {
    for k in 3..20 {
        let s: f64 = zorin_weights(k).iter().sum();
        assert!((s - 0.25).abs() < 1e-12, "k = {k}: {s}");
    }
    // algorithms.md 4.2: k = 6 gives 7/24, 1/12, -1/12, -1/24, -1/12, 1/12.
    let w = zorin_weights(6);
    let want = [
        7.0 / 24.0,
        1.0 / 12.0,
        -1.0 / 12.0,
        -1.0 / 24.0,
        -1.0 / 12.0,
        1.0 / 12.0,
    ];
    for (a, b) in w.iter().zip(want) {
        assert!((a - b).abs() < 1e-12);
    }
}

#[test]
fn old_vertices_stay_and_planes_stay_planar() {
    let g = grid(6, 5);
    let out = bend_levels(&g, &[], 2).unwrap();
    assert_eq!(&out.mesh.positions[..g.positions.len()], &g.positions[..]);
    assert!(
        out.mesh.positions.iter().all(|p| p.z == 0.0),
        "affine invariance"
    );
    let r = out.mesh.topology_report();
    assert!(r.manifold && r.oriented && r.problems.is_empty());
    assert_eq!(r.boundary_loops, 1);
}

/// A closed cube made of n x n quads per face.
fn cube_mesh(n: u32) -> (Mesh, Vec<[u32; 2]>) {
    let mut pos: Vec<DVec3> = Vec::new();
    let mut index = std::collections::HashMap::new();
    let mut id = |p: DVec3, pos: &mut Vec<DVec3>| -> u32 {
        let key = [p.x, p.y, p.z].map(|c| (c * 1e6).round() as i64);
        *index.entry(key).or_insert_with(|| {
            pos.push(p);
            (pos.len() - 1) as u32
        })
    };
    let mut tris = Vec::new();
    for axis in 0..3 {
        for side in [-1.0, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for i in 0..n {
                for j in 0..n {
                    let corner = |di: u32, dj: u32| {
                        let mut p = [0.0; 3];
                        p[axis] = side;
                        p[u] = -1.0 + 2.0 * (i + di) as f64 / n as f64;
                        p[v] = -1.0 + 2.0 * (j + dj) as f64 / n as f64;
                        DVec3::from_array(p)
                    };
                    let q = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)]
                        .map(|p| id(p, &mut pos));
                    if side > 0.0 {
                        tris.push([q[0], q[1], q[2]]);
                        tris.push([q[0], q[2], q[3]]);
                    } else {
                        tris.push([q[0], q[2], q[1]]);
                        tris.push([q[0], q[3], q[2]]);
                    }
                }
            }
        }
    }
    let mesh = Mesh::new(pos, tris);
    let mut sharp = Vec::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
            let on_edge = |p: DVec3| p.abs().to_array().iter().filter(|c| **c == 1.0).count() >= 2;
            if on_edge(pa)
                && on_edge(pb)
                && (pa - pb)
                    .abs()
                    .to_array()
                    .iter()
                    .filter(|c| **c > 0.0)
                    .count()
                    == 1
            {
                sharp.push([a.min(b), a.max(b)]);
            }
        }
    }
    sharp.sort_unstable();
    sharp.dedup();
    (mesh, sharp)
}

#[test]
fn tagged_cube_stays_a_cube() {
    let (cube, sharp) = cube_mesh(3);
    assert_eq!(sharp.len(), 12 * 3);
    let out = bend_levels(&cube, &sharp, 2).unwrap();
    // Every vertex stays on the cube's surface: faces are planar and edges straight.
    for p in &out.mesh.positions {
        let m = p.abs().max_element();
        assert!((m - 1.0).abs() < 1e-12, "{p}");
        assert!(p.abs().to_array().iter().all(|c| *c <= 1.0 + 1e-12), "{p}");
    }
    assert_eq!(out.sharp_edges.len(), 12 * 3 * 4);
    let r = out.mesh.topology_report();
    assert!(r.manifold && r.oriented && r.problems.is_empty() && r.genus == Some(0));
}

#[test]
fn untagged_cube_gets_rounded() {
    let (cube, _) = cube_mesh(3);
    let out = bend(&cube, &[]).unwrap();
    let off = out
        .mesh
        .positions
        .iter()
        .map(|p| (p.abs().max_element() - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(off > 1e-3, "butterfly bends unconstrained edges");
}

/// Coarse cylinder of radius 1 (n sides, flat caps fanned to a centre), rims tagged.
fn cylinder(n: u32) -> (Mesh, Vec<[u32; 2]>) {
    let mut pos = Vec::new();
    for z in [0.0, 1.0] {
        for i in 0..n {
            let a = i as f64 / n as f64 * std::f64::consts::TAU;
            pos.push(DVec3::new(a.cos(), a.sin(), z));
        }
    }
    pos.push(DVec3::new(0.0, 0.0, 0.0));
    pos.push(DVec3::new(0.0, 0.0, 1.0));
    let (bc, tc) = (2 * n, 2 * n + 1);
    let mut tris = Vec::new();
    let mut sharp = Vec::new();
    for i in 0..n {
        let j = (i + 1) % n;
        tris.push([i, j, n + j]);
        tris.push([i, n + j, n + i]);
        tris.push([bc, j, i]);
        tris.push([tc, n + i, n + j]);
        sharp.push([i.min(j), i.max(j)]);
        sharp.push([(n + i).min(n + j), (n + i).max(n + j)]);
    }
    (Mesh::new(pos, tris), sharp)
}

#[test]
fn sharp_rims_bend_into_circles_and_stay_sharp() {
    let (cyl, rims) = cylinder(12);
    let before = cyl.positions[..24]
        .iter()
        .chain(std::iter::once(
            &((cyl.positions[0] + cyl.positions[1]) * 0.5),
        ))
        .map(|p| (p.truncate().length() - 1.0).abs())
        .fold(0.0, f64::max);
    let out = bend_levels(&cyl, &rims, 3).unwrap();
    // Rim vertices: every vertex with z exactly 0 or 1 and radius > 0.5.
    let mut worst: f64 = 0.0;
    for p in &out.mesh.positions {
        let r = p.truncate().length();
        if (p.z == 0.0 || p.z == 1.0) && r > 0.9 {
            worst = worst.max((r - 1.0).abs());
        }
    }
    // A 12-gon's chord midpoint is 3.4% inside the circle; the four-point curve is within
    // 0.1% (measured 0.0007 here).
    assert!(before > 0.03, "{before}");
    assert!(worst < 0.002, "rim radius off by {worst}");
    // The caps stay planar (sharp rims cut the stencils).
    for p in &out.mesh.positions {
        if p.truncate().length() < 0.9 {
            assert!(
                p.z.abs().min((p.z - 1.0).abs()) < 1e-12,
                "cap point off its plane: {p}"
            );
        }
    }
    let r = out.mesh.topology_report();
    assert!(r.manifold && r.oriented && r.problems.is_empty());
}

#[test]
fn smooth_sphere_gets_closer_and_nothing_flips() {
    let m = icosphere(2);
    let out = bend(&m, &[]).unwrap();
    let dev = |mesh: &Mesh| -> f64 {
        // RMS radial deviation of triangle centroids (the facets' sag).
        let mut s = 0.0;
        for t in 0..mesh.triangles.len() {
            let [a, b, c] = mesh.triangle_positions(t);
            let r = ((a + b + c) / 3.0).length() - 1.0;
            s += r * r;
        }
        (s / mesh.triangles.len() as f64).sqrt()
    };
    assert!(
        dev(&out.mesh) < 0.5 * dev(&m),
        "{} vs {}",
        dev(&out.mesh),
        dev(&m)
    );
    // No triangle faces inwards.
    for t in 0..out.mesh.triangles.len() {
        let [a, b, c] = out.mesh.triangle_positions(t);
        assert!(
            (b - a).cross(c - a).dot(a + b + c) > 0.0,
            "triangle {t} flipped"
        );
    }
}

#[test]
fn tags_that_are_not_edges_are_ignored_and_bad_input_refused() {
    let m = icosphere(1);
    assert!(bend(&m, &[[0, 0], [1_000_000, 3]]).is_ok());
    let mut nm = m.clone();
    nm.triangles.push(nm.triangles[0]);
    assert!(bend(&nm, &[]).is_err());
    let mut nan = m.clone();
    nan.positions[0].x = f64::NAN;
    assert!(bend(&nan, &[]).is_err());
}

#[test]
fn a_pillow_component_passes_through_and_the_rest_bends_as_alone() {
    // whet-swing codes a component smaller than L as a pillow: two triangles over the same
    // three vertices. Splitting it gave each inner edge four triangles, and the next level
    // refused the mesh.
    let sphere = icosphere(1);
    let n = sphere.positions.len() as u32;
    let mut both = sphere.clone();
    both.positions.extend([
        DVec3::new(3.0, 0.0, 0.0),
        DVec3::new(4.0, 0.0, 0.0),
        DVec3::new(3.0, 1.0, 0.0),
    ]);
    both.triangles
        .extend([[n, n + 1, n + 2], [n + 1, n, n + 2]]);
    let tags = [[n, n + 1]];
    let alone = bend_levels(&sphere, &[], 3).unwrap();
    let out = bend_levels(&both, &tags, 3).unwrap();
    let r = out.mesh.topology_report();
    assert!(r.manifold && r.oriented, "{r:?}");
    // The sphere part: the same triangles and positions as bending it alone, the pillow
    // after it, unchanged, with its tag.
    let pillow_tris: Vec<[u32; 3]> = out
        .mesh
        .triangles
        .iter()
        .filter(|t| t.iter().all(|&v| (n..n + 3).contains(&v)))
        .copied()
        .collect();
    assert_eq!(pillow_tris, vec![[n, n + 1, n + 2], [n + 1, n, n + 2]]);
    assert_eq!(
        out.mesh.triangles.len(),
        alone.mesh.triangles.len() + 2,
        "only the pillow is left unsplit"
    );
    for p in &alone.mesh.positions {
        assert!(out.mesh.positions.contains(p), "{p:?}");
    }
    assert!(out.sharp_edges.contains(&[n, n + 1]));
}

#[test]
fn levels_past_the_output_limit_are_refused_before_any_work() {
    // 20 triangles times 4^12 is 335M, past 2^28: refused up front (running the first
    // levels would allocate gigabytes before the last one failed).
    let ico = icosphere(0);
    assert_eq!(ico.triangles.len(), 20);
    match bend_levels(&ico, &[], 12) {
        Err(whet_bend::Error::TooLarge { triangles }) => {
            assert!(
                triangles * 4 > whet_bend::MAX_OUTPUT_TRIANGLES,
                "{triangles}"
            );
        }
        other => panic!("{:?}", other.map(|b| b.mesh.triangles.len())),
    }
    assert_eq!(bend_levels(&ico, &[], 2).unwrap().mesh.triangles.len(), 320);
}

/// A vertex of valence 20 000 (a stream can decode to one): its edges take the butterfly
/// instead of Zorin's stencil, which would read the whole ring once per edge (4e8 reads);
/// the result is a valid refinement with the hub's edge points on the cone.
#[test]
fn a_vertex_of_very_high_valence_is_refined_with_local_stencils() {
    let m = hub_disk(20_000, 3);
    let bent = bend(&m, &[]).unwrap();
    assert_eq!(bent.mesh.triangles.len(), 4 * m.triangles.len());
    let report = bent.mesh.topology_report();
    assert!(report.manifold && report.oriented);
    assert!(bent.mesh.positions.iter().all(|p| p.is_finite()));
    // The spoke from the centre to ring 1 is straight and its butterfly wings lie on the
    // same cone, so its new point stays within a spoke's length of its midpoint.
    let spoke_mid = DVec3::new(0.5, 0.0, 0.05);
    assert!(
        bent.mesh.positions[m.positions.len()..]
            .iter()
            .any(|p| p.distance(spoke_mid) < 0.1),
        "no edge point near the first spoke's midpoint"
    );
}
