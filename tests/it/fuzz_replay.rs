//! Replays every fuzz regression (fuzz/corpus/<target>/regressions) and the seed corpora on
//! stable, so crashers found once stay fixed.

use std::path::PathBuf;

fn files(target: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let base = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/corpus")
        .join(target);
    for dir in [base.join("regressions"), base.clone()] {
        if let Ok(rd) = std::fs::read_dir(&dir) {
            for e in rd.flatten() {
                let p = e.path();
                if p.is_file() {
                    out.push(p);
                }
            }
        }
    }
    out.sort();
    out
}

#[test]
fn decode_regressions_and_seeds() {
    let f = files("decode");
    assert!(!f.is_empty(), "fuzz/corpus/decode has the seed streams");
    for p in f {
        whet_swing::fuzz_decode_sharpen(&std::fs::read(&p).unwrap());
    }
}

/// The readers on their seeds: every format, and OFF and OBJ in small blocks against the
/// default ones (`whet_io::fuzz`). fuzz/corpus/read_mesh/regressions/crash-48c73030…: an OBJ
/// line too long inside a statement continued on a second line too long was refused at the
/// second line's number with the default blocks (found by the target's first run, fixed by
/// looking for the first line too long after the last statement end).
#[test]
fn read_mesh_regressions_and_seeds() {
    let f = files("read_mesh");
    assert!(!f.is_empty(), "fuzz/corpus/read_mesh has the seed files");
    for p in f {
        let data = std::fs::read(&p).unwrap();
        // Other cuts the target draws from the last bytes (block sizes, long-line limits),
        // not only the file's own.
        for (a, b) in (0..16u8).flat_map(|a| (0..16u8).map(move |b| (a, b))) {
            let mut varied = data.clone();
            varied.extend_from_slice(&[a, b]);
            whet_io::fuzz::read_every_way(&varied);
        }
        whet_io::fuzz::read_every_way(&data);
    }
}

/// fuzz/corpus/exact_payloads/regressions/crash-39d2b6a2…: the seed-triangle midpoint
/// overflowed i32 on garbage residuals (found by cargo fuzz, fixed by i64 arithmetic and
/// an early stop on off-grid coordinates).
#[test]
fn exact_payload_regressions_and_seeds() {
    let f = files("exact_payloads");
    assert!(!f.is_empty());
    for p in f {
        whet_codec::fuzz_exact_payloads(&std::fs::read(&p).unwrap());
    }
}

/// Swing streams of built meshes (closed, filtered; open, with deletion flags; unfiltered)
/// as `swing_payloads` inputs: the seeds of that target's corpus (with the two-field
/// surface filter, the one that target's input holds).
fn swing_seed_streams() -> Vec<(String, Vec<u8>)> {
    use whet_swing::{encode, Rate, SwingOptions};
    use whet_testkit::meshes::{icosphere, punch, torus};
    let at = |f: f64| {
        SwingOptions::DEFAULT
            .with_rate(Rate::EdgeLength(f))
            .with_extended_filter(false)
    };
    let cases = [
        ("icosphere_filtered", icosphere(3), at(0.08)),
        (
            "icosphere_plain",
            icosphere(3),
            at(0.1).with_surface_filter(false),
        ),
        ("torus", torus(24, 12), at(0.06)),
        ("punched", punch(&icosphere(4), |t| t % 97 < 6), at(0.05)),
    ];
    cases
        .into_iter()
        .map(|(name, mesh, opts)| (name.to_string(), encode(&mesh, &opts).unwrap().bytes))
        .collect()
}

/// The seed conversion keeps the stream: the fuzz harness decodes a seed to exactly what
/// `decode` makes of its stream. `WHET_WRITE_FUZZ_SEEDS=1` (re)writes the seed files.
#[test]
fn swing_payload_seeds_decode_like_their_streams() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/swing_payloads");
    for (name, stream) in swing_seed_streams() {
        let seed = whet_codec::swing_payload_seed(&stream).unwrap();
        let direct = whet_codec::decode(&stream, &whet_codec::DecodeOptions::DEFAULT).unwrap();
        let via_seed = whet_codec::fuzz_swing_payloads(&seed).unwrap();
        assert_eq!(via_seed, direct, "{name}");
        if std::env::var_os("WHET_WRITE_FUZZ_SEEDS").is_some() {
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(dir.join(format!("seed-{name}")), &seed).unwrap();
        }
    }
}

/// The seeds of `swing_payloads_extended`: the same streams with the extended surface
/// filter's three factors set in their headers (the small seed meshes do not fit one worth
/// its bytes), which the seed conversion keeps. `WHET_WRITE_FUZZ_SEEDS=1` (re)writes them.
#[test]
fn swing_payload_extended_seeds_decode_like_their_streams() {
    use whet_format::tag;
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/swing_payloads_extended");
    for (name, stream) in swing_seed_streams() {
        let mut c = whet_format::parse(&stream, &whet_format::Limits::DEFAULT).unwrap();
        if c.header.get_i64(tag::FILTER_NORMAL).is_none() {
            // The extended fields go with the two-field filter's.
            continue;
        }
        c.header = c
            .header
            .clone()
            .with_version(whet_codec::Version::new(1, 4))
            .with(tag::FILTER_SMOOTHED2, -300i64)
            .with(tag::FILTER_QUADRATIC, 200i64)
            .with(tag::FILTER_TANGENTIAL, 150i64);
        let stream = c.to_bytes().unwrap();
        let seed = whet_codec::swing_payload_seed_extended(&stream).unwrap();
        assert!(whet_codec::swing_payload_seed(&stream).is_none());
        let direct = whet_codec::decode(&stream, &whet_codec::DecodeOptions::DEFAULT).unwrap();
        let plain = whet_codec::fuzz_swing_payloads(
            &whet_codec::swing_payload_seed_extended(&stream).unwrap()[6..],
        )
        .unwrap();
        assert_ne!(plain, direct, "{name}: the extended fields move vertices");
        let via_seed = whet_codec::fuzz_swing_payloads_extended(&seed).unwrap();
        assert_eq!(via_seed, direct, "{name}");
        if std::env::var_os("WHET_WRITE_FUZZ_SEEDS").is_some() {
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(dir.join(format!("seed-{name}")), &seed).unwrap();
        }
    }
}

#[test]
fn swing_payload_extended_regressions_and_seeds() {
    let f = files("swing_payloads_extended");
    assert!(
        !f.is_empty(),
        "fuzz/corpus/swing_payloads_extended has the seed inputs"
    );
    for p in f {
        whet_codec::fuzz_swing_payloads_extended(&std::fs::read(&p).unwrap());
    }
}

#[test]
fn swing_payload_regressions_and_seeds() {
    let f = files("swing_payloads");
    assert!(
        !f.is_empty(),
        "fuzz/corpus/swing_payloads has the seed inputs"
    );
    for p in f {
        whet_codec::fuzz_swing_payloads(&std::fs::read(&p).unwrap());
    }
}

/// A cube of side 2 whose twelve edges are cut by chamfers `d` wide and whose eight corners
/// by corner triangles: what uniform retiling leaves of a box, the sharpener's own case (24
/// vertices, 44 triangles, outward).
fn chamfered_cube(d: f64) -> whet_mesh::Mesh {
    use whet_mesh::DVec3;
    let sign = |c: usize, k: usize| if c >> k & 1 == 1 { 1.0 } else { -1.0 };
    // Vertex 3c + k: corner c's vertex on the face across axis k.
    let positions: Vec<DVec3> = (0..24)
        .map(|i| {
            let (c, k) = (i / 3, i % 3);
            let v = |j: usize| sign(c, j) * if j == k { 1.0 } else { 1.0 - d };
            DVec3::new(v(0), v(1), v(2))
        })
        .collect();
    let corner = |signs: [bool; 3]| {
        signs
            .iter()
            .enumerate()
            .map(|(k, &s)| (s as usize) << k)
            .sum::<usize>()
    };
    let mut polygons: Vec<Vec<usize>> = Vec::new();
    let cyclic = [(false, false), (true, false), (true, true), (false, true)];
    for k in 0..3 {
        let (j, l) = ((k + 1) % 3, (k + 2) % 3);
        for s in [false, true] {
            // The face across axis k.
            polygons.push(
                cyclic
                    .iter()
                    .map(|&(a, b)| {
                        let mut signs = [false; 3];
                        (signs[k], signs[j], signs[l]) = (s, a, b);
                        3 * corner(signs) + k
                    })
                    .collect(),
            );
            // The chamfer between the faces across k and j, along axis l.
            for t in [false, true] {
                let at = |b: bool| {
                    let mut signs = [false; 3];
                    (signs[k], signs[j], signs[l]) = (s, t, b);
                    corner(signs)
                };
                polygons.push(vec![
                    3 * at(false) + k,
                    3 * at(true) + k,
                    3 * at(true) + j,
                    3 * at(false) + j,
                ]);
            }
        }
    }
    for c in 0..8 {
        polygons.push(vec![3 * c, 3 * c + 1, 3 * c + 2]);
    }
    // Fan each convex polygon and turn every triangle outward (the solid is convex about
    // the origin).
    let mut triangles = Vec::new();
    for poly in polygons {
        for w in 1..poly.len() - 1 {
            let mut tri = [poly[0], poly[w], poly[w + 1]].map(|v| v as u32);
            let p = tri.map(|v| positions[v as usize]);
            if (p[1] - p[0]).cross(p[2] - p[0]).dot(p[0] + p[1] + p[2]) < 0.0 {
                tri.swap(1, 2);
            }
            triangles.push(tri);
        }
    }
    whet_mesh::Mesh::new(positions, triangles)
}

/// Small meshes as `sharpen` inputs: the seeds of that target's corpus.
fn sharpen_seed_inputs() -> Vec<(String, Vec<u8>)> {
    use whet_testkit::meshes::{grid, icosphere, octahedron, punch, torus};
    let cube = chamfered_cube(0.25);
    let open_cube = punch(&cube, |t| t % 11 == 3);
    let mut folded = grid(6, 4);
    for p in &mut folded.positions {
        // A floor for x <= 3 and a wall at x = 4, joined by a 45-degree chamfer strip.
        if p.x > 3.0 {
            (p.x, p.z) = (4.0, p.x - 3.0);
        }
    }
    let mut channel = grid(8, 3);
    for p in &mut channel.positions {
        // A U: walls at x = 2 and x = 6 joined to the floor by 45-degree chamfers.
        if p.x < 3.0 {
            (p.x, p.z) = (2.0, 3.0 - p.x);
        } else if p.x > 5.0 {
            (p.x, p.z) = (6.0, p.x - 5.0);
        }
    }
    let mut bent = grid(5, 5);
    for p in &mut bent.positions {
        // A shallow cylinder-like bend with a little deterministic noise: curved, no crease.
        p.z = 0.08 * (p.x - 2.5) * (p.x - 2.5) + 0.02 * ((p.x * 3.0 + p.y * 5.0) % 3.0 - 1.0);
    }
    let cases = [
        ("bent_grid", bent, 0b0000_0001),
        ("chamfered_cube_extended", cube.clone(), 0b0100_0000u8),
        ("chamfered_cube_papers", cube.clone(), 0b0010_0001),
        ("chamfered_cube_normal_filter", cube, 2),
        ("open_chamfered_cube", open_cube, 0b0001_1000),
        ("folded_grid", folded.clone(), 0),
        ("folded_grid_papers_two_passes", folded, 0b0000_1001),
        ("channel", channel, 0b0001_0000),
        ("octahedron", octahedron(), 0),
        ("icosphere", icosphere(1), 0b0100_0000),
        ("torus", torus(6, 4), 0),
    ];
    cases
        .into_iter()
        .map(|(name, mesh, flags)| {
            let seed = whet_sharpen::fuzz_seed(&mesh, flags, 6, 50)
                .unwrap_or_else(|| panic!("{name} fits the seed layout"));
            (name.to_string(), seed)
        })
        .collect()
}

/// The folded grid and the channel are sharpened (their chamfers found and cut) and the
/// bent grid gets quadric fits, so the corpus starts where the sharpener and the projection
/// do real work; the chamfered cube, its faces only two triangles each, has no smooth region
/// to start from at this size. The committed seed files are these inputs;
/// `WHET_WRITE_FUZZ_SEEDS=1` (re)writes them.
#[test]
fn sharpen_seeds_exercise_the_sharpener() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/sharpen");
    for (name, seed) in sharpen_seed_inputs() {
        let (mesh, opts, _, quadric) = whet_sharpen::fuzz_input(&seed).unwrap();
        let out = whet_sharpen::sharpen(&mesh, &opts).unwrap();
        if name.starts_with("folded") || name == "channel" {
            assert!(out.report.chamfer_edges > 0, "{name}: {:?}", out.report);
            assert!(out.mesh.positions.len() > mesh.positions.len(), "{name}");
        }
        if name == "bent_grid" {
            let mut m = out.mesh.clone();
            let rep = whet_sharpen::project_onto_local_quadrics(&mut m, &quadric).unwrap();
            assert!(rep.moved_vertices > 0, "{name}: {rep:?}");
        }
        let (sharp, edges) = whet_sharpen::fuzz_sharpen(&seed).unwrap();
        whet_bend::fuzz_bend(&sharp, &edges);
        let path = dir.join(format!("seed-{name}"));
        if std::env::var_os("WHET_WRITE_FUZZ_SEEDS").is_some() {
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(&path, &seed).unwrap();
        }
        assert_eq!(
            std::fs::read(&path).ok().as_ref(),
            Some(&seed),
            "{} is stale: WHET_WRITE_FUZZ_SEEDS=1 rewrites it",
            path.display()
        );
    }
}

/// fuzz/corpus/sharpen/regressions: two inputs on which the first runs of the target
/// (2026-12-04) stopped on the harness's own expectations, kept because they reach rare
/// paths: `harness-normal-filter-collapse-*` (the normal filter's needle collapses remove
/// vertices, so its output may have fewer than the input) and `harness-pillow-*` (Bender
/// passes a pillow through whole instead of making four triangles of each half).
#[test]
fn sharpen_regressions_and_seeds() {
    let f = files("sharpen");
    assert!(!f.is_empty(), "fuzz/corpus/sharpen has the seed inputs");
    for p in f {
        if let Some((mesh, edges)) = whet_sharpen::fuzz_sharpen(&std::fs::read(&p).unwrap()) {
            whet_bend::fuzz_bend(&mesh, &edges);
        }
    }
}

/// The swing encoder's target starts from the sharpen target's seeds (the same mesh layout;
/// bytes 1 and 2 pick the angle bits and the edge length).
#[test]
fn swing_encode_regressions_and_seeds() {
    let f = files("swing_encode");
    assert!(
        !f.is_empty(),
        "fuzz/corpus/swing_encode has the seed inputs"
    );
    for p in f {
        whet_swing::fuzz_encode(&std::fs::read(&p).unwrap());
    }
}
