use whet_testkit::shared_fixture;

/// (fixture, Draco bytes at q = 11, q = 14; level 10), from ../shared/anchors/draco.md.
const DRACO: &[(&str, usize, usize)] = &[
    ("armadillo", 73863, 123101),
    ("block", 9672, 13488),
    ("bunny", 9814, 14045),
    ("cad_box_hole", 21970, 34594),
    ("cad_bracket", 17186, 26769),
    ("cad_cyl_fillet", 25596, 40539),
    ("fandisk", 8537, 14313),
    ("fertility", 11155, 16683),
    ("joint", 28545, 39134),
    ("partLp", 7699, 12705),
    ("rocker_arm", 22883, 34941),
    ("screwdriver", 8201, 12425),
    ("sharp_sphere", 23252, 35608),
    ("spot", 6139, 9519),
];

#[test]
fn payload_sizes_against_draco() {
    for &(name, d11, d14) in DRACO {
        let mesh = whet_io::read_path(&shared_fixture(&format!("{name}.off")), None).unwrap();
        for (bits, draco) in [(11, d11), (14, d14)] {
            let p = whet_codec::encode_exact_payloads(&mesh, bits).unwrap();
            let dec = whet_codec::decode_exact_payloads(&p).unwrap();
            assert_eq!(dec.triangles.len(), mesh.triangles.len());
            let half = p.quantizer.step * 0.5 * (1.0 + 1e-9);
            for (i, &src) in p.vertex_order.iter().enumerate() {
                let d = (dec.positions[i] - mesh.positions[src as usize])
                    .abs()
                    .max_element();
                assert!(d <= half, "{name} q{bits}: vertex {i} off by {d}");
            }
            let ours = p.connectivity.len() + p.geometry.len();
            eprintln!(
                "{name} q{bits}: conn {} geom {} total {} vs draco {} ({:.3})",
                p.connectivity.len(),
                p.geometry.len(),
                ours,
                draco,
                ours as f64 / draco as f64
            );
        }
    }
}
