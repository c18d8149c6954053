//! A ridge `z = -|x|` sampled on a grid whose columns straddle the crease (x = ±0.5, ±1.5,
//! ±2.5; y = 0..5): the strip between x = -0.5 and x = 0.5 is one row of chamfer triangles,
//! every vertex lies on the true surface, and the expected result is known exactly.

use whet_mesh::{DVec3, Mesh, VertexId};
use whet_sharpen::{sharpen, SharpenOptions};

const XS: [f64; 6] = [-2.5, -1.5, -0.5, 0.5, 1.5, 2.5];
const NY: u32 = 6;

fn ridge() -> Mesh {
    columns(&XS.map(|x| [x, -x.abs()]))
}

/// A strip of `NY` rows (y = 0, 1, ...) through the profile points `[x, z]`, one column of
/// vertices per point, each cell cut along the same diagonal.
fn columns(profile: &[[f64; 2]]) -> Mesh {
    let mut p = Vec::new();
    for &[x, z] in profile {
        for j in 0..NY {
            p.push(DVec3::new(x, j as f64, z));
        }
    }
    let id = |i: u32, j: u32| i * NY + j;
    let mut t = Vec::new();
    for i in 0..profile.len() as u32 - 1 {
        for j in 0..NY - 1 {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh::new(p, t)
}

#[test]
fn ridge_is_restored_exactly() {
    let input = ridge();
    for method in crate::EDGE_SHARPENER {
        let out = sharpen(&input, &SharpenOptions::DEFAULT.with_method(method)).unwrap();
        let r = &out.report;
        // The crossing edges of the strip: 4 interior edges along x (the two on y = 0 and y = 5
        // are boundary edges, never split) and 5 diagonals.
        assert_eq!(r.chamfer_edges, 9, "{method}: {}", r.to_json());
        assert_eq!(r.corner_triangles, 0, "{method}");
        assert_eq!((r.new_vertices, r.snapped_vertices), (9, 9), "{method}");
        assert_eq!(
            (r.collapsed_triangles, r.restored_triangles),
            (0, 0),
            "{method}"
        );
        // Input vertices first, bit-identical; 9 new vertices on the crease line x = z = 0, at
        // the closest points to the midpoints of their edges (y = 0.5, 1.0, ..., 4.5).
        assert_eq!(
            &out.mesh.positions[..input.positions.len()],
            &input.positions[..]
        );
        let mut ys: Vec<f64> = out.mesh.positions[input.positions.len()..]
            .iter()
            .map(|p| {
                assert!(p.x.abs() < 1e-12 && p.z.abs() < 1e-12, "{method}: {p}");
                p.y
            })
            .collect();
        ys.sort_by(f64::total_cmp);
        for (k, y) in ys.iter().enumerate() {
            assert!((y - 0.5 * (k + 1) as f64).abs() < 1e-12, "{method}: {ys:?}");
        }
        // Every triangle lies on the ridge except the two strip pieces that keep a boundary
        // edge across the crease (the papers never split a boundary edge).
        let off: Vec<usize> = (0..out.mesh.triangles.len())
            .filter(|&t| {
                let p = out.mesh.triangle_positions(t);
                let c = (p[0] + p[1] + p[2]) / 3.0;
                (c.z + c.x.abs()).abs() > 1e-9
            })
            .collect();
        assert_eq!(off.len(), 2, "{method}: {off:?}");
        let report = out.mesh.topology_report();
        assert!(report.manifold && report.oriented);
        assert_eq!(
            report.boundary_edges,
            input.topology_report().boundary_edges
        );
        // Tags: the 9 new vertices, and the 8 edges between consecutive ones along the ridge.
        assert_eq!(out.tags.vertices.len(), 9, "{method}");
        assert_eq!(out.tags.edges.len(), 8, "{method}");
        for [a, b] in &out.tags.edges {
            let (pa, pb) = (out.mesh.positions[a.index()], out.mesh.positions[b.index()]);
            assert!((pa.y - pb.y).abs() - 0.5 < 1e-12, "{a}-{b}");
        }
        assert!(out.tags.is_tagged(VertexId(input.positions.len() as u32)));
        // Parents: one per triangle, each an input triangle index.
        assert_eq!(out.parents.len(), out.mesh.triangles.len());
        assert!(out
            .parents
            .iter()
            .all(|f| f.index() < input.triangles.len()));
    }
}

#[test]
fn ridge_with_a_step_is_mixed_convexity() {
    // Lower the x > 0 face so that the strip joins two parallel planes at different heights:
    // convex seen from the top, concave seen from the bottom. The papers leave such a strip
    // alone (its planes are parallel, and the convexity test agrees).
    let mut m = ridge();
    for p in &mut m.positions {
        p.z = if p.x > 0.0 { -1.0 } else { 0.0 };
    }
    let out = sharpen(&m, &SharpenOptions::PAPERS).unwrap();
    // Parallel planes: every new vertex stays at its midpoint, so the geometry is unchanged.
    assert_eq!(out.report.snapped_vertices, 0, "{}", out.report.to_json());
    for t in 0..out.mesh.triangles.len() {
        let p = out.mesh.triangle_positions(t);
        for q in p {
            assert!(
                q.z == 0.0 || q.z == -1.0 || (q.x.abs() < 0.5 + 1e-12),
                "{q}"
            );
        }
    }
    let ext = sharpen(&m, &SharpenOptions::DEFAULT).unwrap();
    assert_eq!(
        ext.mesh, m,
        "the extended method drops splits that change nothing"
    );
}

/// The ridge `z = -|x|` sampled with a chamfer two triangles wide: columns on the left face
/// (x = -6..-1), one column `MIDDLE` off both faces, columns on the right face (x = 1..6).
/// The middle column's triangles all cross the crease, so its vertices lie in no smooth
/// triangle (gray), and no edge joins the two faces' borders: the papers' filters see no
/// chamfer edge.
const MIDDLE: [f64; 2] = [0.0, -0.3];

fn two_wide_ridge() -> Mesh {
    let profile: Vec<[f64; 2]> = (-6..=6)
        .map(|i| {
            let x = f64::from(i);
            if i == 0 {
                MIDDLE
            } else {
                [x, -x.abs()]
            }
        })
        .collect();
    columns(&profile)
}

#[test]
fn a_chamfer_two_triangles_wide_needs_gray_labels_on_surface_samplings() {
    // docs/sharpen.md, "What we extend", step 20. The middle column is 0.21 from both
    // faces' planes, within the gray tolerance (0.4 of its mean edge, about 1.2) and the
    // crease tolerance (0.35): labelled, it takes both faces and moves onto their crease.
    let input = two_wide_ridge();
    let middle = |i: usize| i / NY as usize == 6;
    let by_default = sharpen(&input, &SharpenOptions::DEFAULT).unwrap();
    assert_eq!(by_default.report.chamfer_vertices, 0);
    assert_eq!(by_default.mesh, input, "{}", by_default.report.to_json());
    let out = sharpen(
        &input,
        &SharpenOptions::DEFAULT.with_surface_gray_labels(true),
    )
    .unwrap();
    assert!(out.report.surface_gray_labels);
    // The middle column's interior vertices (the boundary ones are never labelled).
    assert_eq!(
        out.report.chamfer_vertices,
        NY as usize - 2,
        "{}",
        out.report.to_json()
    );
    assert_eq!(out.mesh.triangles, input.triangles);
    for (i, (p, q)) in out.mesh.positions.iter().zip(&input.positions).enumerate() {
        let boundary = i % NY as usize == 0 || i % NY as usize == NY as usize - 1;
        if middle(i) && !boundary {
            assert!(p.x.abs() < 1e-12 && p.z.abs() < 1e-12, "{i}: {p}");
            assert_eq!(p.y, q.y, "{i}");
        } else {
            assert_eq!(p, q, "{i}: only the middle column moves");
        }
    }
    // The papers' method has no labels: the option changes nothing there.
    let papers = SharpenOptions::PAPERS.with_surface_gray_labels(true);
    assert_eq!(sharpen(&input, &papers).unwrap().mesh, input);
}
