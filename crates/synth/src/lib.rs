//! whet-synth owns whet's ground truth: shapes whose true surface is known exactly (each with
//! a signed distance function, negative inside, and a truth triangle mesh whose sharp edges and
//! corners lie exactly on the true creases), the feature-insensitive sampler that aliases them
//! the way scanners, iso-surface extraction and remeshing compressors do ([`marching_cubes`]:
//! a closed, manifold, outward-oriented mesh whose vertices lie on grid edges, so sharp edges
//! come out chamfered), and the normal-direction noise of the Edge-Sharpener experiments
//! ([`add_noise`]). Later stages (sharpening, subdivision, the error measure) are tested against
//! these: the truth mesh is the reference, the sampling the input. The crate depends only on
//! `whet-mesh`.
//!
//! ```
//! use whet_synth::{marching_cubes, Shape, ShapeKind, ShapeParams};
//!
//! let cube = Shape::new(ShapeKind::Cube, &ShapeParams::default()).unwrap();
//! assert!(cube.sdf(glam::DVec3::ZERO) < 0.0); // negative inside
//! let sampled = marching_cubes(&cube, 16).unwrap();
//! let report = sampled.topology_report();
//! assert!(report.manifold && report.oriented && report.problems.is_empty());
//! assert_eq!((report.boundary_loops, report.genus), (0, Some(0)));
//! ```
#![forbid(unsafe_code)]

mod marching_cubes;
mod noise;
mod refine;
mod shapes;

pub use marching_cubes::{marching_cubes, marching_cubes_fn, Grid};
pub use noise::{add_noise, SplitMix64};
pub use refine::{jitter_within_surface, midpoint_subdivide};
pub use shapes::{Shape, ShapeKind, ShapeParams, TESSELLATION_TOLERANCE};

/// Largest accepted marching-cubes resolution (cells along the longest axis).
pub const MAX_RESOLUTION: usize = 2048;

/// Everything that can go wrong building a shape or sampling it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A shape name that [`ShapeKind::from_str`](std::str::FromStr) does not know.
    #[error("unknown shape {name:?} (known: {known})")]
    UnknownShape {
        /// The name given.
        name: String,
        /// The known names, comma separated.
        known: String,
    },
    /// A marching-cubes resolution outside `2..=MAX_RESOLUTION`.
    #[error("resolution {0} is out of range: it must be between 2 and {MAX_RESOLUTION} cells")]
    BadResolution(usize),
    /// A fillet radius that is not positive, not finite, or too large for the box.
    #[error("fillet radius {radius} is out of range: it must be > 0 and < {max}")]
    BadRadius {
        /// The radius given.
        radius: f64,
        /// The exclusive upper limit (half the box's smallest side).
        max: f64,
    },
    /// A rotation quaternion that is zero or not finite.
    #[error("rotation {0:?} is not a finite non-zero quaternion")]
    BadRotation(glam::DQuat),
    /// Sampling bounds that are empty, not finite, or of zero size.
    #[error("sampling bounds are empty, not finite or of zero size")]
    BadBounds,
    /// The sampled function returned NaN or an infinity.
    #[error("the sampled function returned the non-finite value {value} at {at}")]
    NonFiniteValue {
        /// Where.
        at: glam::DVec3,
        /// What it returned.
        value: f64,
    },
    /// The output would need more vertices than 32-bit indices address.
    #[error("the sampling is too large: more than {0} vertices")]
    TooLarge(u64),
    /// The sampled function broke the 1-Lipschitz contract of
    /// [`marching_cubes_fn`]: the surface crosses a grid edge at `at`
    /// inside a block whose value said it could not, so part of the surface would be missing.
    #[error(
        "the sampled function is not 1-Lipschitz near {at}: the surface crosses a grid edge \
         there that the function's values ruled out (divide an L-Lipschitz function by L)"
    )]
    NotLipschitz {
        /// A grid point of the edge the surface crosses.
        at: glam::DVec3,
    },
    /// A broken internal invariant (a bug): reported instead of panicking.
    #[error("internal error in whet-synth: {0}")]
    Internal(&'static str),
}
