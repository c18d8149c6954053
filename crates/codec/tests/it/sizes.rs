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

/// Issue target: the whole exact-mode stream at Q = 11 and 14 is no larger than Draco's at
/// the same quantization and compression level 10, on every fixture with Draco figures.
#[test]
fn whole_stream_no_larger_than_draco() {
    let mut report = String::new();
    let mut worst: f64 = 0.0;
    for &(name, d11, d14) in DRACO {
        let mesh = whet_io::read_path(&shared_fixture(&format!("{name}.off")), None).unwrap();
        for (bits, draco) in [(11, d11), (14, d14)] {
            let enc = whet_codec::encode(
                &mesh,
                &whet_codec::EncodeOptions::DEFAULT.with_quant_bits(bits),
            )
            .unwrap();
            let ours = enc.bytes.len();
            let ratio = ours as f64 / draco as f64;
            worst = worst.max(ratio);
            report.push_str(&format!(
                "{name} q{bits}: {ours} B (conn {} + geom {} bits) vs Draco {draco} B: {ratio:.3}\n",
                enc.report.connectivity_bits, enc.report.geometry_bits
            ));
        }
    }
    eprintln!("{report}");
    assert!(worst <= 1.0, "larger than Draco somewhere:\n{report}");
}
