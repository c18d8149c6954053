//! The projections a stream states, run one after the other on one corner table
//! (`StatedProjection::apply_all`, what `whet decode --sharpen` and the encoder's
//! measurements run): the same vertices, bit for bit, as each projection building its own.

use whet_codec::{decode, DecodeOptions};
use whet_mesh::CornerTable;
use whet_sharpen::SharpenOptions;
use whet_swing::{encode, Rate, StatedProjection, SwingOptions};
use whet_synth::{Shape, ShapeKind, ShapeParams};

use crate::bits;

#[test]
fn projections_on_one_table_move_the_vertices_as_each_on_its_own() {
    // A swing decoding of a part with creases, flat and curved faces, sharpened: its
    // quantization noise is what the projections move.
    let original = Shape::new(ShapeKind::Fandisk, &ShapeParams::default())
        .unwrap()
        .truth_mesh();
    let out = encode(
        &original,
        &SwingOptions::DEFAULT
            .with_rate(Rate::EdgeLength(0.02))
            .with_angle_bits(6),
    )
    .unwrap();
    let decoded = decode(
        &out.bytes,
        &DecodeOptions::DEFAULT.with_surface_filter(false),
    )
    .unwrap();
    let sharpened = whet_sharpen::sharpen(&decoded, &SharpenOptions::DEFAULT)
        .unwrap()
        .mesh;
    let all = [
        StatedProjection::Planar {
            factor: 2.0,
            angle_bits: 6,
        },
        StatedProjection::Quadric {
            factor: 0.25,
            angle_bits: 6,
        },
        StatedProjection::Beside {
            factor: 0.25,
            angle_bits: 6,
        },
        StatedProjection::Crease { max_move: 0.5 },
        StatedProjection::Apex { max_move: 1.5 },
    ];
    let mut one_by_one = sharpened.clone();
    for p in &all {
        p.apply(&mut one_by_one).unwrap();
    }
    assert_ne!(bits(&one_by_one), bits(&sharpened), "nothing moved");
    let mut shared = sharpened.clone();
    assert!(StatedProjection::apply_all(&all, &mut shared).is_empty());
    assert_eq!(bits(&shared), bits(&one_by_one));
    assert_eq!(shared.triangles, one_by_one.triangles);
    // A table of other triangles (the decoded mesh's, before the sharpener cut it) is not
    // used: each projection builds its own, as without one.
    let other = CornerTable::new(&decoded).unwrap();
    let mut given_other = sharpened.clone();
    for p in &all {
        p.apply_on(&mut given_other, &other).unwrap();
    }
    assert_eq!(bits(&given_other), bits(&one_by_one));
}
