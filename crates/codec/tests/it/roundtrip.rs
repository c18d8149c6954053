//! Round trips of the exact mode: same triangles up to the reported vertex permutation,
//! positions within half a quantization step.

use proptest::prelude::*;
use whet_codec::{
    decode, decode_reusing, encode, DecodeBuffers, DecodeOptions, Decoder, EncodeBuffers,
    EncodeOptions, Encoder, ExactPrediction, StreamingDecoder,
};
use whet_mesh::{DVec3, Mesh};
use whet_testkit::meshes::*;

fn canonical(t: [u32; 3]) -> [u32; 3] {
    let r = (0..3).min_by_key(|&i| t[i]).unwrap();
    [t[r], t[(r + 1) % 3], t[(r + 2) % 3]]
}

/// Checks a decoded mesh against its source through the report's vertex order, for every
/// exact-mode prediction; returns the default (degree order) stream.
pub fn check_round_trip(mesh: &Mesh, bits: u32) -> Vec<u8> {
    check_round_trip_with(mesh, bits, ExactPrediction::Traversal);
    check_round_trip_with(mesh, bits, ExactPrediction::TraversalStatic);
    check_round_trip_with(mesh, bits, ExactPrediction::Degree)
}

/// [`check_round_trip`] for one prediction.
pub fn check_round_trip_with(mesh: &Mesh, bits: u32, prediction: ExactPrediction) -> Vec<u8> {
    let opts = EncodeOptions::DEFAULT
        .with_quant_bits(bits)
        .with_prediction(prediction);
    let enc = encode(mesh, &opts).unwrap();
    let dec = decode(&enc.bytes, &DecodeOptions::DEFAULT).unwrap();
    let order = &enc.report.vertex_order;
    assert_eq!(dec.positions.len(), order.len());
    let ext = mesh.bounding_box().size().max_element();
    let half = if ext > 0.0 {
        ext / ((1u64 << bits) - 1) as f64 * 0.5 * (1.0 + 1e-9)
    } else {
        0.0
    };
    for (i, &src) in order.iter().enumerate() {
        let d = (dec.positions[i] - mesh.positions[src as usize])
            .abs()
            .max_element();
        assert!(
            d <= half + 1e-12,
            "vertex {i}: off by {d}, half step {half}"
        );
    }
    let mut want: Vec<[u32; 3]> = mesh.triangles.iter().map(|&t| canonical(t)).collect();
    let mut got: Vec<[u32; 3]> = dec
        .triangles
        .iter()
        .map(|t| canonical(t.map(|v| order[v as usize])))
        .collect();
    want.sort_unstable();
    got.sort_unstable();
    assert_eq!(got, want);
    enc.bytes
}

#[test]
fn fixtures_round_trip() {
    for path in whet_testkit::shared_off_fixtures() {
        let mesh = whet_io::read_path(&path, None).unwrap();
        for bits in [8, 14] {
            check_round_trip(&mesh, bits);
        }
    }
}

/// One set of buffers through streams of every size and kind, each mesh given back when
/// checked (larger and smaller than the last, with holes and without, both predictions, a
/// corrupt stream in between): every decode is `decode`'s.
#[test]
fn reused_buffers_decode_what_decode_decodes() {
    let holes = holes_handles_components_mesh();
    let meshes = [
        shuffle(&icosphere(4), 1),
        Mesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 2]]),
        shuffle(&holes, 2),
        Mesh::default(),
        shuffle(&icosphere(5), 3),
        torus(6, 5),
    ];
    let mut buffers = DecodeBuffers::new();
    for round in 0..2 {
        for (i, mesh) in meshes.iter().enumerate() {
            for prediction in [
                ExactPrediction::Traversal,
                ExactPrediction::TraversalStatic,
                ExactPrediction::Degree,
            ] {
                let opts = EncodeOptions::DEFAULT
                    .with_quant_bits(10 + i as u32)
                    .with_prediction(prediction);
                let bytes = encode(mesh, &opts).unwrap().bytes;
                let want = decode(&bytes, &DecodeOptions::DEFAULT).unwrap();
                let got = decode_reusing(&bytes, &DecodeOptions::DEFAULT, &mut buffers).unwrap();
                assert_eq!(got, want, "round {round}, mesh {i}, {prediction:?}");
                if round == 1 {
                    buffers.recycle(got);
                }
                // A stream cut short fails the same way and leaves the buffers usable.
                let cut = &bytes[..bytes.len() * 2 / 3];
                let e = decode_reusing(cut, &DecodeOptions::DEFAULT, &mut buffers).unwrap_err();
                assert_eq!(
                    e.to_string(),
                    decode(cut, &DecodeOptions::DEFAULT)
                        .unwrap_err()
                        .to_string()
                );
            }
        }
    }
}

/// One set of encoder buffers through meshes of every size and kind (a shuffled one large
/// enough to be renumbered spatially, holes, a mesh that takes the repairing path, the
/// empty mesh), both predictions, twice: every stream and report is `encode`'s.
#[test]
fn reused_encoder_buffers_encode_what_encode_encodes() {
    let holes = holes_handles_components_mesh();
    // Two tetrahedra sharing one vertex: the fast path refuses, the repairing one cuts.
    let pinched = Mesh::new(
        vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::new(0.0, 0.0, -1.0),
        ],
        vec![
            [0, 2, 1],
            [0, 1, 3],
            [1, 2, 3],
            [2, 0, 3],
            [0, 4, 5],
            [0, 6, 4],
            [4, 6, 5],
            [5, 6, 0],
        ],
    );
    let large = shuffle(&icosphere(7), 5);
    let meshes = [
        shuffle(&icosphere(4), 1),
        large,
        shuffle(&holes, 2),
        pinched,
        Mesh::default(),
        torus(6, 5),
    ];
    for prediction in [
        ExactPrediction::Traversal,
        ExactPrediction::TraversalStatic,
        ExactPrediction::Degree,
    ] {
        let mut buffers = EncodeBuffers::new();
        for round in 0..2 {
            for (i, mesh) in meshes.iter().enumerate() {
                if i == 1 && prediction == ExactPrediction::Degree {
                    continue; // the large mesh once per round is enough
                }
                let opts = EncodeOptions::DEFAULT
                    .with_quant_bits(9 + i as u32)
                    .with_prediction(prediction);
                let want = encode(mesh, &opts).unwrap();
                let got = Encoder::new(opts)
                    .encode_reusing(mesh, &mut buffers)
                    .unwrap();
                assert_eq!(
                    got.bytes, want.bytes,
                    "round {round}, mesh {i}, {prediction:?}"
                );
                assert_eq!(got.report, want.report, "round {round}, mesh {i}");
                if i == 3 {
                    assert_eq!(want.report.repair.added_vertices, 1, "the pinch is cut");
                }
            }
        }
    }
}

#[test]
fn one_triangle_and_empty() {
    let one = Mesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 2]]);
    check_round_trip(&one, 10);
    let empty = Mesh::default();
    for prediction in [
        ExactPrediction::Degree,
        ExactPrediction::Traversal,
        ExactPrediction::TraversalStatic,
    ] {
        let opts = EncodeOptions::DEFAULT.with_prediction(prediction);
        let enc = encode(&empty, &opts).unwrap();
        let dec = decode(&enc.bytes, &DecodeOptions::DEFAULT).unwrap();
        assert!(dec.positions.is_empty() && dec.triangles.is_empty());
    }
}

/// A torus (a handle), a punched sphere (holes) and a grid (a boundary), three components.
fn holes_handles_components_mesh() -> Mesh {
    union(
        union(torus(10, 7), &punch(&icosphere(3), |i| i % 41 == 5), 6.0),
        &grid(4, 3),
        12.0,
    )
}

#[test]
fn holes_handles_components() {
    let m = holes_handles_components_mesh();
    for seed in 0..3 {
        check_round_trip(&shuffle(&m, seed), 12);
    }
}

/// Meshes made mostly of boundary: 200 separate triangles (an unwelded STL's soup) and 150
/// separate quads. The connectivity codes one dummy triangle per boundary edge, four
/// times a soup's triangle count; the decoder once allowed only twice the header's count
/// plus 64, so every soup of over 32 triangles failed to decode.
#[test]
fn triangle_soups_and_separate_quads_round_trip() {
    let mut soup = Mesh::default();
    for i in 0..200u32 {
        let o = DVec3::new((i % 13) as f64, (i / 13) as f64, (i % 7) as f64 * 0.5);
        soup.positions
            .extend([o, o + DVec3::X * 0.4, o + DVec3::new(0.1, 0.4, 0.2)]);
        soup.triangles.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    check_round_trip(&soup, 12);
    let mut quads = Mesh::default();
    for i in 0..150u32 {
        let o = DVec3::new((i % 11) as f64, (i / 11) as f64, 0.0);
        quads.positions.extend([
            o,
            o + DVec3::X * 0.5,
            o + DVec3::new(0.5, 0.5, 0.1),
            o + DVec3::Y * 0.5,
        ]);
        quads.triangles.push([4 * i, 4 * i + 1, 4 * i + 2]);
        quads.triangles.push([4 * i, 4 * i + 2, 4 * i + 3]);
    }
    check_round_trip(&quads, 12);
}

/// Finite coordinates whose span overflows an f64 (-1e308 to 1e308): no grid over them
/// exists, so encoding is refused with a named error instead of writing a stream that
/// decodes every vertex to one corner (what it did before); a stream stating such a box is
/// corrupt.
#[test]
fn coordinates_whose_span_overflows_are_refused() {
    let m = Mesh::new(
        vec![
            DVec3::new(-1e308, 0.0, 0.0),
            DVec3::new(1e308, 0.0, 0.0),
            DVec3::new(0.0, 1e308, 0.0),
        ],
        vec![[0, 1, 2]],
    );
    let e = encode(&m, &EncodeOptions::DEFAULT).unwrap_err();
    assert!(e.to_string().contains("extent overflows"), "{e}");
    // The same triangle scaled into range encodes; its stream with the box widened past the
    // f64 range is refused by the decoder.
    let ok = Mesh::new(
        m.positions.iter().map(|p| *p * 1e-10).collect(),
        m.triangles.clone(),
    );
    let enc = encode(&ok, &EncodeOptions::DEFAULT).unwrap();
    let mut c = whet_format::parse(&enc.bytes, &whet_format::Limits::DEFAULT).unwrap();
    c.header.set_bbox([-1e308, 0.0, 0.0], [1e308, 1e308, 0.0]);
    let e = decode(&c.to_bytes().unwrap(), &DecodeOptions::DEFAULT).unwrap_err();
    assert!(e.to_string().contains("extent overflows"), "{e}");
}

#[test]
fn non_manifold_input_is_repaired_and_unused_vertices_dropped() {
    let mut m = icosphere(1);
    // A fin on an existing edge, a bow tie and an unused vertex.
    let [a, b, _] = m.triangles[0];
    m.positions.push(DVec3::new(3.0, 3.0, 3.0));
    let fin = (m.positions.len() - 1) as u32;
    m.triangles.push([a, b, fin]);
    m.positions.push(DVec3::new(9.0, 9.0, 9.0));
    let enc = encode(&m, &EncodeOptions::DEFAULT).unwrap();
    assert_eq!(enc.report.repair.cut_edges, 1);
    assert_eq!(enc.report.dropped_unused_vertices, 1);
    let dec = decode(&enc.bytes, &DecodeOptions::DEFAULT).unwrap();
    assert_eq!(dec.triangles.len(), m.triangles.len());
    let r = dec.topology_report();
    assert!(r.manifold && r.oriented);
    let refuse = encode(&m, &EncodeOptions::DEFAULT.with_repair(false));
    assert!(refuse.is_err());
}

#[test]
fn closed_surfaces_pinched_at_a_vertex_are_repaired_or_refused() {
    // Two icospheres sharing one vertex: two closed fans there, which the encoder's fast
    // path only detects on its relabelled table.
    let a = icosphere(2);
    let off = a.positions.len() as u32;
    let mut m = a.clone();
    m.positions
        .extend(a.positions[1..].iter().map(|p| *p + DVec3::X * 2.0));
    m.triangles.extend(
        a.triangles
            .iter()
            .map(|t| t.map(|v| if v == 0 { 0 } else { off + v - 1 })),
    );
    let m = shuffle(&m, 3);
    let enc = encode(&m, &EncodeOptions::DEFAULT).unwrap();
    assert!(
        enc.report.repair != Default::default(),
        "{:?}",
        enc.report.repair
    );
    assert_eq!(enc.report.dropped_unused_vertices, 0);
    let dec = decode(&enc.bytes, &DecodeOptions::DEFAULT).unwrap();
    assert_eq!(dec.triangles.len(), m.triangles.len());
    let refuse = encode(&m, &EncodeOptions::DEFAULT.with_repair(false)).unwrap_err();
    assert!(
        matches!(
            refuse,
            whet_codec::Error::InvalidInput(whet_mesh::MeshError::NonManifoldVertex { .. })
        ),
        "{refuse}"
    );
}

/// Two tetrahedra sharing one vertex, where the second component's first triangle holds it:
/// the traversal starts that component there and ranks the vertex a second time. The fast
/// path used to code only one copy's position (the other decoded at the grid's origin, a
/// third of the diagonal away) and report no repair; the vertex is now cut and reported,
/// and both copies decode where the input vertex is.
#[test]
fn a_vertex_shared_by_a_components_start_triangle_is_cut_and_reported() {
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let m = Mesh::new(
        vec![
            p(0.0, 0.0, 0.0),
            p(1.0, 0.0, 0.0),
            p(0.0, 1.0, 0.0),
            p(0.0, 0.0, 1.0),
            p(-1.0, 0.0, 0.0),
            p(0.0, -1.0, 0.0),
            p(0.0, 0.0, -1.0),
        ],
        vec![
            [0, 2, 1],
            [0, 1, 3],
            [0, 3, 2],
            [1, 2, 3],
            [0, 5, 4],
            [0, 4, 6],
            [0, 6, 5],
            [4, 5, 6],
        ],
    );
    let enc = encode(&m, &EncodeOptions::DEFAULT).unwrap();
    assert_eq!(
        enc.report.repair.added_vertices, 1,
        "{:?}",
        enc.report.repair
    );
    assert_eq!(enc.report.vertices, 8);
    let order = &enc.report.vertex_order;
    assert_eq!(order.iter().filter(|&&v| v == 0).count(), 2);
    let dec = decode(&enc.bytes, &DecodeOptions::DEFAULT).unwrap();
    // Every decoded vertex within half a step (14 bits over an extent of 2) of its source.
    let half = 2.0 / ((1u64 << 14) - 1) as f64 * 0.5 * (1.0 + 1e-9);
    for (i, &src) in order.iter().enumerate() {
        let d = (dec.positions[i] - m.positions[src as usize])
            .abs()
            .max_element();
        assert!(d <= half, "vertex {i} (input {src}) off by {d}");
    }
    let refuse = encode(&m, &EncodeOptions::DEFAULT.with_repair(false)).unwrap_err();
    assert!(
        matches!(
            refuse,
            whet_codec::Error::InvalidInput(whet_mesh::MeshError::NonManifoldVertex {
                vertex: 0,
                ..
            })
        ),
        "{refuse}"
    );
}

#[test]
fn nan_input_is_refused() {
    let mut m = icosphere(0);
    m.positions[3].y = f64::NAN;
    let e = encode(&m, &EncodeOptions::DEFAULT).unwrap_err();
    assert!(e.to_string().contains("non-finite"), "{e}");
}

#[test]
fn read_and_streaming_decoders_agree_for_any_chunking() {
    let m = shuffle(
        &union(torus(9, 5), &punch(&icosphere(2), |i| i % 13 == 0), 4.0),
        9,
    );
    for prediction in [
        ExactPrediction::Degree,
        ExactPrediction::Traversal,
        ExactPrediction::TraversalStatic,
    ] {
        let opts = EncodeOptions::DEFAULT.with_prediction(prediction);
        let enc = encode(&m, &opts).unwrap();
        let whole = decode(&enc.bytes, &DecodeOptions::DEFAULT).unwrap();
        let from_read = Decoder::new(&enc.bytes[..], DecodeOptions::DEFAULT)
            .decode()
            .unwrap();
        assert_eq!(from_read, whole);
        for chunk in [1usize, 2, 3, 7, 64, 1000] {
            let mut s = StreamingDecoder::new(DecodeOptions::DEFAULT);
            for piece in enc.bytes.chunks(chunk) {
                let mut rest = piece;
                while !rest.is_empty() {
                    let (used, _) = s.update(rest).unwrap();
                    rest = &rest[used..];
                }
            }
            assert!(s.is_done());
            assert_eq!(s.finish().unwrap(), whole, "{prediction:?} chunk {chunk}");
        }
    }
}

#[test]
fn encoding_is_deterministic() {
    let m = icosphere(3);
    let a = encode(&m, &EncodeOptions::DEFAULT).unwrap();
    let b = encode(&m, &EncodeOptions::DEFAULT).unwrap();
    assert_eq!(a.bytes, b.bytes);
}

fn random_mesh() -> impl Strategy<Value = Mesh> {
    (
        0u32..3,
        2u32..9,
        2u32..7,
        0u32..40,
        any::<u64>(),
        prop::bool::ANY,
    )
        .prop_map(|(levels, n, m, hole_every, seed, with_torus)| {
            let mut mesh = icosphere(levels);
            if with_torus {
                mesh = union(mesh, &torus(n.max(3), m.max(3)), 5.0);
            }
            if hole_every > 2 {
                mesh = punch(&mesh, |i| i as u32 % hole_every == 1);
            }
            shuffle(&mesh, seed)
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn random_meshes_round_trip(mesh in random_mesh(), bits in 4u32..20) {
        if !mesh.triangles.is_empty() {
            check_round_trip(&mesh, bits);
        }
    }
}

#[test]
fn a_large_mesh_in_random_order_round_trips_through_the_spatial_reorder() {
    // Icosphere level 7 (327,680 triangles) shuffled: over the encoder's size bound for
    // reordering, in random memory order, so the exact encoder works on a copy in spatial
    // order and reports the vertex order through it. Level 7 unshuffled is left in its order;
    // both must round-trip the same way.
    let ico = icosphere(7);
    let shuffled = shuffle(&ico, 3);
    check_round_trip(&shuffled, 12);
    check_round_trip(&ico, 12);
}
