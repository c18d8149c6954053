//! Property tests: no input makes a reader panic, whatever the bytes.

use proptest::prelude::*;
use whet_io::{read, Format};
use whet_mesh::DVec3;

use crate::common::{bytes, encodings, grid};

/// Reads `data` in every format; the only requirement is not to panic.
fn read_all(data: &[u8]) {
    for format in Format::ALL {
        if let Ok(mesh) = read(data, format) {
            // Whatever is accepted is a consistent mesh.
            let n = mesh.positions.len();
            assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n));
            assert!(mesh.positions.iter().all(|p| p.is_finite()));
        }
    }
}

/// Valid files of a small mesh in every encoding.
fn samples() -> Vec<(Format, Vec<u8>)> {
    let mut mesh = grid(3, true, 9);
    // An unreferenced vertex, for variety (STL drops it).
    mesh.positions.push(DVec3::new(0.5, -0.25, 2.0));
    encodings()
        .into_iter()
        .map(|(_, format, opts)| (format, bytes(&mesh, format, &opts)))
        .collect()
}

/// Headers after which random bytes reach the body parsers.
const PREFIXES: [&[u8]; 8] = [
    b"OFF\n",
    b"OFF\n4 2 0\n",
    b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf ",
    b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n",
    b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty list uchar short n\n\
property double x\nproperty uchar y\nproperty int z\nelement face 2\nproperty uchar f\n\
property list int uint vertex_indices\nelement e 2\nproperty list uint float v\nend_header\n",
    b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n",
    b"solid x\nfacet normal 0 0 1\nouter loop\nvertex ",
    b"solid binary header\0\0\0",
];

/// Text made of the formats' own words, numbers and separators.
fn text_soup() -> impl Strategy<Value = String> {
    let word = prop_oneof![
        Just("v".to_owned()),
        Just("f".to_owned()),
        Just("vt".to_owned()),
        Just("OFF".to_owned()),
        Just("ply".to_owned()),
        Just("format ascii 1.0".to_owned()),
        Just("element vertex".to_owned()),
        Just("element face".to_owned()),
        Just("property float x".to_owned()),
        Just("property list uchar int vertex_indices".to_owned()),
        Just("end_header".to_owned()),
        Just("solid".to_owned()),
        Just("facet normal".to_owned()),
        Just("outer loop".to_owned()),
        Just("vertex".to_owned()),
        Just("endloop".to_owned()),
        Just("endfacet".to_owned()),
        Just("endsolid".to_owned()),
        Just("#".to_owned()),
        Just("\\".to_owned()),
        Just("\n".to_owned()),
        Just("/".to_owned()),
        "-?[0-9]{1,3}".prop_map(|s| s),
        "-?[0-9]{0,2}\\.[0-9]{0,3}(e-?[0-9]{1,3})?".prop_map(|s| s),
        Just("nan".to_owned()),
        Just("4294967295".to_owned()),
        Just("99999999999999999999".to_owned()),
    ];
    prop::collection::vec(word, 0..80).prop_map(|words| words.join(" "))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(data in prop::collection::vec(any::<u8>(), 0..2048)) {
        read_all(&data);
    }

    #[test]
    fn random_bodies_after_valid_headers_never_panic(
        prefix in 0..PREFIXES.len(),
        body in prop::collection::vec(any::<u8>(), 0..512),
    ) {
        let data = [PREFIXES[prefix], &body[..]].concat();
        read_all(&data);
    }

    #[test]
    fn token_soup_never_panics(text in text_soup()) {
        read_all(text.as_bytes());
    }

    #[test]
    fn truncated_and_corrupted_files_never_panic(
        which in 0..7usize,
        cut in any::<prop::sample::Index>(),
        flips in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..4),
    ) {
        let samples = samples();
        let (format, data) = &samples[which];
        let mut data = data[..cut.index(data.len() + 1)].to_vec();
        if !data.is_empty() {
            for (at, byte) in flips {
                let i = at.index(data.len());
                data[i] = byte;
            }
        }
        let _ = read(&data[..], *format);
        read_all(&data);
    }
}

#[test]
fn every_prefix_of_every_sample_is_handled() {
    for (format, data) in samples() {
        for cut in 0..=data.len() {
            let _ = read(&data[..cut], format);
        }
        // The whole file reads.
        assert!(read(&data[..], format).is_ok(), "{format}");
    }
}
