//! Connectivity cost on the public fixtures against Draco's whole stream at 1-bit
//! quantization (an upper bound on Draco's connectivity bits).

use whet_edgebreaker::{decode_connectivity, encode_connectivity, ConnectivityLimits};
use whet_testkit::shared_fixture;

/// (fixture, Draco bytes at q=1, level 10) from ../shared/anchors/draco.md,
/// "Connectivity-cost proxy"; every fixture with over 1000 triangles.
const DRACO_Q1_BYTES: &[(&str, usize)] = &[
    ("armadillo", 14042),
    ("block", 1299),
    ("bunny", 1376),
    ("cad_box_hole", 2745),
    ("cad_bracket", 2246),
    ("cad_cyl_fillet", 3079),
    ("fandisk", 1485),
    ("fertility", 1554),
    ("joint", 4628),
    ("partLp", 975),
    ("rocker_arm", 3221),
    ("screwdriver", 1113),
    ("sharp_sphere", 2703),
    ("spot", 806),
];

#[test]
fn beats_draco_connectivity_proxy_on_every_fixture() {
    let mut ratio_sum = 0.0;
    let mut report = String::new();
    for &(name, draco) in DRACO_Q1_BYTES {
        let mesh = whet_io::read_path(&shared_fixture(&format!("{name}.off")), None).unwrap();
        let enc = encode_connectivity(&mesh.triangles, mesh.positions.len()).unwrap();
        let (dec, _) = decode_connectivity(&enc.bytes, &ConnectivityLimits::DEFAULT).unwrap();
        assert_eq!(dec.output_triangles().len(), mesh.triangles.len());
        let ours = enc.bytes.len();
        let ratio = ours as f64 / draco as f64;
        ratio_sum += ratio;
        report.push_str(&format!(
            "{name}: {ours} B ({:.3} bpt) vs Draco q1 {draco} B: {ratio:.3}\n",
            ours as f64 * 8.0 / mesh.triangles.len() as f64
        ));
        assert!(
            ours <= draco,
            "{name}: {ours} bytes > Draco's {draco}\n{report}"
        );
    }
    let mean = ratio_sum / DRACO_Q1_BYTES.len() as f64;
    eprintln!("{report}mean ratio {mean:.3}");
    // Issue target: at least 10% fewer bits on average.
    assert!(mean <= 0.90, "mean ratio {mean}\n{report}");
}
