//! The subdiv payloads: round trip, levels override, damage.

use whet_codec::DecodeOptions;
use whet_subdiv::{
    decode_control, decode_subdiv, encode_subdiv, subdivide, Error, FitOptions,
    SubdivEncodeOptions, SubdivOptions,
};
use whet_synth::{Shape, ShapeKind, ShapeParams};

fn small_payloads() -> (whet_mesh::Mesh, whet_subdiv::SubdivPayloads) {
    let shape = Shape::new(ShapeKind::Fandisk, &ShapeParams::default()).unwrap();
    let input = whet_synth::marching_cubes(&shape, 24).unwrap();
    let opts = SubdivEncodeOptions::DEFAULT.with_fit(
        FitOptions::DEFAULT
            .with_control_vertices(80)
            .with_levels(2)
            .with_iterations(4),
    );
    let p = encode_subdiv(&input, &opts).unwrap();
    (input, p)
}

#[test]
fn payloads_round_trip_at_every_level() {
    let (input, p) = small_payloads();
    assert_eq!(p.levels, 2);
    let r = &p.report;
    assert_eq!(r.control_vertices, 80);
    assert_eq!(
        (r.control_bytes, r.sharpness_bytes),
        (p.control.len(), p.sharpness.len())
    );
    let opts = DecodeOptions::DEFAULT;
    let c = decode_control(&p.control, &p.sharpness, &opts).unwrap();
    assert_eq!(c.sharp_levels, 2);
    assert_eq!(c.sharpness.sharp_count(), r.sharp_edges);
    // --levels 0: the control mesh itself.
    let zero = decode_subdiv(&p.control, &p.sharpness, 0, &opts).unwrap();
    assert_eq!(zero, c.mesh);
    let two = decode_subdiv(&p.control, &p.sharpness, 2, &opts).unwrap();
    assert_eq!(two.positions.len() as u64, r.decoded_vertices);
    assert_eq!(two.triangles.len() as u64, r.decoded_triangles);
    let again = subdivide(
        &c.mesh,
        &c.sharpness,
        &SubdivOptions::DEFAULT.with_levels(2).with_sharp_levels(2),
    )
    .unwrap();
    assert_eq!(two, again);
    // Near the input: within 2% of the diagonal everywhere, 0.5% RMS (measured 0.9% and
    // 0.2% when written; generous because the input is a coarse marching-cubes sampling).
    let m = whet_metro::metro(
        &input,
        &two,
        &whet_metro::MetroOptions::DEFAULT.with_samples(50_000),
    )
    .unwrap();
    assert!(
        m.symmetric.max_pct < 2.0 && m.symmetric.rms_pct < 0.5,
        "{:?}",
        m.symmetric
    );
    // A finer decode of the same surface.
    let three = decode_subdiv(&p.control, &p.sharpness, 3, &opts).unwrap();
    assert_eq!(three.triangles.len(), two.triangles.len() * 4);
}

#[test]
fn damaged_payloads_fail_cleanly() {
    let (_, p) = small_payloads();
    let opts = DecodeOptions::DEFAULT;
    for len in 0..p.sharpness.len() {
        assert!(decode_subdiv(&p.control, &p.sharpness[..len], 1, &opts).is_err());
    }
    for len in (0..p.control.len()).step_by(7) {
        assert!(decode_subdiv(&p.control[..len], &p.sharpness, 1, &opts).is_err());
    }
    for i in 0..p.sharpness.len() {
        let mut bad = p.sharpness.clone();
        bad[i] ^= 0x5a;
        // Either an error or some valid surface: never a panic.
        let _ = decode_subdiv(&p.control, &bad, 1, &opts);
    }
    assert!(matches!(
        decode_subdiv(&p.control, &p.sharpness, 11, &opts),
        Err(Error::LimitExceeded { .. })
    ));
    // The bytes subdividing would allocate count too: within the face limit, over the
    // allocation limit.
    let mut limits = whet_codec::Limits::DEFAULT;
    limits.max_alloc_bytes = 1 << 20;
    let small_alloc = DecodeOptions::DEFAULT.with_limits(limits);
    match decode_subdiv(&p.control, &p.sharpness, 4, &small_alloc) {
        Err(Error::LimitExceeded { what, .. }) => assert!(what.contains("bytes"), "{what}"),
        other => panic!("{other:?}"),
    }
    decode_subdiv(&p.control, &p.sharpness, 1, &small_alloc).unwrap();
    let mut limits = whet_codec::Limits::DEFAULT;
    limits.max_faces = 1000;
    let tight = DecodeOptions::DEFAULT.with_limits(limits);
    assert!(matches!(
        decode_subdiv(&p.control, &p.sharpness, 4, &tight),
        Err(Error::LimitExceeded { .. })
    ));
}

mod prop {
    use super::*;
    use proptest::prelude::*;
    use whet_subdiv::{encode_control, EdgeSharpness};

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// Any sharpness survives coding up to its quantization, on the decoder's numbering.
        #[test]
        fn sharpness_round_trips(seed in any::<u64>(), bits in 1u32..=8, sparse in any::<bool>()) {
            let mesh = Shape::new(ShapeKind::Fandisk, &ShapeParams::default())
                .unwrap()
                .truth_mesh();
            let mut rng = whet_metro::sampling::SplitMix64::new(seed);
            let values: Vec<f64> = mesh
                .undirected_edges()
                .iter()
                .map(|_| {
                    let x = rng.next_f64();
                    if sparse && x < 0.8 { 0.0 } else { rng.next_f64() }
                })
                .collect();
            let s = EdgeSharpness::from_values(&mesh, values).unwrap();
            let p = encode_control(&mesh, &s, 2, 2, 14, bits).unwrap();
            let back = decode_control(&p.control, &p.sharpness, &DecodeOptions::DEFAULT).unwrap();
            let q = s.quantized(bits);
            let mut matched = 0;
            for (e, &[a, b]) in back.sharpness.edges().iter().enumerate() {
                let h = back.sharpness.values()[e];
                prop_assert!((0.0..=1.0).contains(&h));
                // Map decoded vertices back to the input's by position (14-bit grid).
                let near = |x: u32| {
                    let p = back.mesh.positions[x as usize];
                    (0..mesh.positions.len())
                        .min_by(|&i, &j| {
                            (mesh.positions[i] - p).length().total_cmp(&(mesh.positions[j] - p).length())
                        })
                        .unwrap() as u32
                };
                if let Some(hq) = q.get(near(a), near(b)) {
                    prop_assert!((hq - h).abs() < 1e-12);
                    matched += 1;
                }
            }
            prop_assert_eq!(matched, back.sharpness.len());
        }
    }
}
