//! Normal noise: deterministic, bounded, identity at zero.

use proptest::prelude::*;
use whet_synth::{add_noise, marching_cubes, ShapeKind};

use crate::common::shape;

fn sample() -> whet_mesh::Mesh {
    marching_cubes(&shape(ShapeKind::Fandisk), 24).unwrap()
}

#[test]
fn zero_amount_is_identity() {
    let m = sample();
    assert_eq!(add_noise(&m, 0.0, 1), m);
    assert_eq!(add_noise(&m, -0.0, 99), m);
    assert_eq!(add_noise(&m, f64::NAN, 5), m);
}

#[test]
fn deterministic_for_a_seed() {
    let m = sample();
    let a = add_noise(&m, 0.5, 42);
    assert_eq!(a, add_noise(&m, 0.5, 42));
    assert_ne!(a, add_noise(&m, 0.5, 43));
    assert_eq!(a.triangles, m.triangles);
    // The sign of the amount does not matter.
    assert_eq!(a, add_noise(&m, -0.5, 42));
}

#[test]
fn displacement_is_along_the_normal_and_bounded() {
    let m = sample();
    let normals = m.vertex_normals();
    let max_edge = m.max_edge_length();
    for amount in [0.1, 0.5, 1.0] {
        let noisy = add_noise(&m, amount, 7);
        let bound = amount * max_edge;
        let mut largest: f64 = 0.0;
        let mut mean = 0.0;
        for ((p, q), n) in m.positions.iter().zip(&noisy.positions).zip(&normals) {
            let d = *q - *p;
            assert!(
                d.length() <= bound * (1.0 + 1e-12),
                "{} > {bound}",
                d.length()
            );
            assert!(d.cross(*n).length() <= 1e-12, "not along the normal");
            largest = largest.max(d.length());
            mean += d.dot(*n);
        }
        // Uniform in [-F, F]: the extremes are reached and the mean is near zero.
        assert!(largest > 0.95 * bound);
        mean /= m.positions.len() as f64;
        assert!(mean.abs() < 0.05 * bound, "{mean}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn bounded_for_any_seed(seed in any::<u64>(), amount in 0.0f64..2.0) {
        let m = marching_cubes(&shape(ShapeKind::Cube), 8).unwrap();
        let noisy = add_noise(&m, amount, seed);
        let bound = amount * m.max_edge_length();
        for (p, q) in m.positions.iter().zip(&noisy.positions) {
            prop_assert!((*q - *p).length() <= bound * (1.0 + 1e-12));
        }
    }

    #[test]
    fn sdfs_are_one_lipschitz(
        a in prop::array::uniform3(-1.2f64..1.2),
        b in prop::array::uniform3(-1.2f64..1.2),
        k in 0usize..11,
    ) {
        let s = crate::common::rotated(ShapeKind::ALL[k], crate::common::generic_rotation());
        let (a, b) = (glam::DVec3::from_array(a), glam::DVec3::from_array(b));
        prop_assert!((s.sdf(a) - s.sdf(b)).abs() <= (a - b).length() * (1.0 + 1e-9) + 1e-12);
    }
}
