//! Unit tests of the normal filter's phases on small hand-built and synth meshes.

use glam::{DQuat, DVec3};
use whet_mesh::Mesh;
use whet_synth::{marching_cubes, Shape, ShapeKind, ShapeParams};

use super::*;
use crate::options::Method;

fn nf() -> SharpenOptions {
    SharpenOptions::DEFAULT.with_method(Method::NormalFilter)
}

/// A grid over the unit square, folded along x = 0.5 into a roof (`slope` rise per unit).
fn roof(n: usize, slope: f64) -> Mesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let x = i as f64 / n as f64;
            let y = j as f64 / n as f64;
            positions.push(DVec3::new(x, y, slope * (0.5 - (x - 0.5).abs())));
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh::new(positions, triangles)
}

fn geo_of<'a>(m: &'a Mesh, centroids: &'a [DVec3], nfi: &'a [[u32; 3]]) -> Geo<'a> {
    Geo {
        positions: &m.positions,
        tris: &m.triangles,
        centroids,
        nfi,
    }
}

fn nfi_of(m: &Mesh) -> Vec<[u32; 3]> {
    let table = CornerTable::new(m).unwrap();
    (0..m.triangles.len())
        .map(|t| {
            [0, 1, 2].map(|k| {
                table
                    .opposite(CornerId((3 * t + k) as u32))
                    .map_or(NONE, |o| o.0 / 3)
            })
        })
        .collect()
}

#[test]
fn lambda_stops_the_flood_at_a_sharp_edge() {
    // A 90-degree roof: with lambda = 0 a face next to the ridge sees only its own side, so
    // nothing is a feature (Fig. 1); with lambda = -1 the flood crosses and both sides meet.
    let m = roof(10, 2.0);
    let (normals, centroids) = normals_and_centroids(&m.positions, &m.triangles);
    let nfi = nfi_of(&m);
    let geo = geo_of(&m, &centroids, &nfi);
    let all = vec![true; m.triangles.len()];
    let rho2 = (0.35f64).powi(2);
    let stopped = detect::detect(&geo, &normals, &all, rho2, 0.1, 0.0);
    assert_eq!(stopped.iter().filter(|&&f| f).count(), 0);
    let crossed = detect::detect(&geo, &normals, &all, rho2, 0.1, -1.0);
    assert!(crossed.iter().filter(|&&f| f).count() > 20);
    // NFII holds the seed and stays within rho of its centroid.
    let mut flood = detect::Flood::new(m.triangles.len());
    flood.nfii(7, &geo, &normals, rho2, -1.0);
    assert_eq!(flood.faces[0], 7);
    assert!(flood
        .faces
        .iter()
        .all(|&k| geo.dist2(centroids[7], k) < rho2 || k == 7));
}

#[test]
fn a_chamfered_roof_is_sharpened_onto_its_planes() {
    // A roof whose ridge is cut by a flat strip one cell wide: the strip's faces are features,
    // take the normals of the two sides, and its vertices move onto the ridge line.
    let n = 12;
    let mut m = roof(n, 1.0);
    let h = 1.0 / n as f64;
    for p in &mut m.positions {
        p.z = p.z.min(0.5 - h * 0.5);
    }
    // Distance to the roof over the interior (boundary vertices never move).
    let truth = |p: DVec3| {
        if p.y > 1e-9 && p.y < 1.0 - 1e-9 {
            (p.z - (0.5 - (p.x - 0.5).abs())).abs()
        } else {
            0.0
        }
    };
    let err0: f64 = m.positions.iter().map(|&p| truth(p)).fold(0.0, f64::max);
    let out = sharpen(&m, &nf().with_rho(3.0)).unwrap();
    let r = &out.report;
    assert!(r.feature_faces > 0 && r.filtered_normals > 0, "{r:?}");
    let err1: f64 = out
        .mesh
        .positions
        .iter()
        .map(|&p| truth(p))
        .fold(0.0, f64::max);
    assert!(
        err1 < err0 / 3.0,
        "max distance to the roof {err0} -> {err1}"
    );
    let rep = out.mesh.topology_report();
    assert!(rep.manifold && rep.oriented);
    assert_eq!(rep.boundary_edges, m.topology_report().boundary_edges);
    assert!(!out.tags.edges.is_empty());
}

fn sharpen(m: &Mesh, o: &SharpenOptions) -> Result<Sharpened, Error> {
    crate::sharpen(m, o)
}

#[test]
fn filtering_runs_from_the_outside_inwards() {
    // On a marching-cubes box every filtered face ends with a normal close to one of the box's
    // six face normals, and far more faces are filtered than left unreached.
    let rot = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.5);
    let shape = Shape::new(ShapeKind::Box, &ShapeParams::default().with_rotation(rot)).unwrap();
    let mc = marching_cubes(&shape, 24).unwrap();
    let out = sharpen(&mc, &nf()).unwrap();
    let r = &out.report;
    assert!(r.feature_faces > 100, "{r:?}");
    assert!(r.filtered_normals * 10 >= r.feature_faces * 9, "{r:?}");
    assert_eq!(r.presmooth_iterations, 1);
    assert!(r.detection_time > std::time::Duration::ZERO);
    let axes: Vec<DVec3> = [DVec3::X, DVec3::Y, DVec3::Z]
        .iter()
        .flat_map(|&a| [rot * a, -(rot * a)])
        .collect();
    let near_axis = out
        .mesh
        .face_normals()
        .iter()
        .filter(|n| axes.iter().any(|a| a.dot(**n) > 0.98))
        .count();
    assert!(near_axis * 10 > out.mesh.triangles.len() * 9);
}

#[test]
fn refuses_bad_input_without_panicking() {
    let nan = Mesh::new(
        vec![DVec3::ZERO, DVec3::X, DVec3::new(f64::NAN, 0.0, 0.0)],
        vec![[0, 1, 2]],
    );
    assert!(matches!(
        sharpen(&nan, &nf()),
        Err(Error::InvalidInput(MeshError::NonFiniteCoordinate {
            vertex: 2
        }))
    ));
    let flat = Mesh::new(
        vec![DVec3::ZERO, DVec3::X, DVec3::X * 2.0, DVec3::Y],
        vec![[0, 1, 3], [1, 2, 3], [0, 2, 1]],
    );
    assert!(sharpen(&flat, &nf()).is_err());
    let fin = Mesh::new(
        vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z, -DVec3::Z],
        vec![[0, 1, 2], [0, 1, 3], [0, 1, 4]],
    );
    assert!(matches!(
        sharpen(&fin, &nf()),
        Err(Error::InvalidInput(MeshError::NonManifoldEdge { .. }))
    ));
    for bad in [
        nf().with_rho(0.0),
        nf().with_rho(f64::NAN),
        nf().with_eta(2.0),
        nf().with_lambda(-1.5),
    ] {
        assert!(matches!(
            sharpen(&roof(3, 1.0), &bad),
            Err(Error::Parameter(_))
        ));
    }
    let empty = Mesh::new(vec![DVec3::ZERO], vec![]);
    assert_eq!(sharpen(&empty, &nf()).unwrap().mesh, empty);
}

#[test]
fn an_empty_selection_changes_nothing() {
    let m = roof(8, 1.0);
    let out = crate::sharpen_region(&m, &nf(), &VertexSelection::default()).unwrap();
    assert_eq!(out.mesh, m);
    assert_eq!(out.report.feature_faces, 0);
}

#[test]
fn presmoothing_flattens_a_spike() {
    let mut m = roof(6, 0.0);
    let c = 3 * 7 + 3;
    m.positions[c].z = 0.2;
    let rings = filter::Rings::new(&m.triangles, m.positions.len());
    assert_eq!(rings.of(c).len(), 6);
    let mut movable = vec![false; m.positions.len()];
    movable[c] = true;
    let mut p = m.positions.clone();
    assert_eq!(
        filter::presmooth(
            &mut p,
            &m.triangles,
            &rings,
            &movable,
            2,
            1e-20,
            &m.face_normals()
        ),
        1
    );
    assert!(p[c].z.abs() < 0.05, "{}", p[c].z);
}

#[test]
fn a_noisy_roof_is_denoised_and_its_crease_kept() {
    // The roof (crease at x = 0.5, sides at +-45 degrees) with noise along z on the interior
    // vertices: more than half of the faces are noisy, so the denoising pass runs; the sides
    // come out flatter (distance to the true roof) and the boundary stays put.
    let clean = roof(16, 1.0);
    let mut rng = whet_synth::SplitMix64::new(3);
    let mut noisy = clean.clone();
    for (v, p) in noisy.positions.iter_mut().enumerate() {
        let (i, j) = (v % 17, v / 17);
        if i > 0 && i < 16 && j > 0 && j < 16 {
            p.z += 0.02 * rng.next_signed();
        }
    }
    let dist = |m: &Mesh| -> f64 {
        m.positions
            .iter()
            .map(|p| (p.z - 0.5 + (p.x - 0.5).abs()).abs() / 2f64.sqrt())
            .sum::<f64>()
            / m.positions.len() as f64
    };
    let table = CornerTable::new(&noisy).unwrap();
    let nfi: Vec<[u32; 3]> = (0..noisy.triangles.len())
        .map(|t| {
            [0, 1, 2].map(|k| {
                table
                    .opposite(CornerId((3 * t + k) as u32))
                    .map_or(NONE, |o| o.0 / 3)
            })
        })
        .collect();
    let (normals, _) = normals_and_centroids(&noisy.positions, &noisy.triangles);
    assert!(denoise::noisy_share(&normals, &nfi) > denoise::NOISY_SHARE);
    let (clean_normals, _) = normals_and_centroids(&clean.positions, &clean.triangles);
    assert_eq!(denoise::noisy_share(&clean_normals, &nfi), 0.0);
    let out = sharpen(&noisy, &nf()).unwrap();
    assert!(
        dist(&out.mesh) < dist(&noisy) / 2.0,
        "{} -> {}",
        dist(&noisy),
        dist(&out.mesh)
    );
    for (v, p) in noisy.positions.iter().enumerate() {
        let (i, j) = (v % 17, v / 17);
        if i == 0 || i == 16 || j == 0 || j == 16 {
            assert_eq!(out.mesh.positions[v], *p);
        }
    }
}

#[test]
fn uniform_samplings_have_no_coarse_faces() {
    let m = roof(8, 1.0);
    assert_eq!(
        denoise::coarse_share(&m.positions, &m.triangles, m.mean_edge_length()),
        0.0
    );
    // One large triangle fan around many tiny ones: the large faces cover most of the area.
    let mut positions = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(10.0, 0.0, 0.0),
        DVec3::new(0.0, 10.0, 0.0),
    ];
    let mut triangles = vec![[0, 1, 2]];
    for k in 0..200u32 {
        let o = DVec3::new(20.0 + 0.01 * k as f64, 0.0, 0.0);
        positions.extend([o, o + DVec3::X * 0.01, o + DVec3::Y * 0.01]);
        triangles.push([3 + 3 * k, 4 + 3 * k, 5 + 3 * k]);
    }
    let m = Mesh::new(positions, triangles);
    assert!(denoise::coarse_share(&m.positions, &m.triangles, m.mean_edge_length()) > 0.99);
}
