//! Least-squares fit of the swing decoder's surface filter (`whet_codec::surface_filter`)
//! against the original surface.
//!
//! The decoder moves each vertex by `a · d(v) n + b · s(v) n` (two displacement fields of
//! the decoded mesh). A point `p = Σ wᵢ pᵢ` of a decoded triangle then moves by the same
//! barycentric mix of its corners' displacements; its error along the triangle's normal `n_f`
//! is `r − a x₀ − b x₁` with `r = (closest point of the original − p) · n_f` and `xₖ` the
//! fields' mixes along `n_f`. The encoder samples fixed barycentric points of every decoded
//! triangle (a strided subset on large meshes), finds their closest points on the original
//! (the retiler's grid, within 2 L), weights them by the triangle's area and
//! solves the 2 × 2 normal equations for `(a, b)`: the forward (decoded to original) RMS of
//! the filtered mesh, linearised. Measured against the Metro error of factor sweeps, the fit
//! lands on the sweep's optimum within its resolution (docs/results.md).

use whet_codec::{FilterFields, SurfaceFilter};
use whet_mesh::{DVec3, Mesh};

/// Most surface samples of one fit: two unknowns need few, and the fit runs once per
/// retiling of a rate search.
const MAX_SAMPLES: usize = 1 << 14;

/// Barycentric sample points of a triangle: the centroid and the centroids of the three
/// corner sub-triangles.
const PATTERN: [[f64; 3]; 4] = [
    [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
    [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
    [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
];

/// The filter factors that best fit `decoded` to the original surface, coded;
/// [`SurfaceFilter::NONE`] when the fit is degenerate (no samples, no displacement).
/// `closest` gives the closest point of the original to a point, or `None` when there is
/// none near enough to trust (such samples are left out: wraps and bridges far from the
/// surface are not what the filter can fix).
pub fn fit_surface_filter(
    decoded: &Mesh,
    closest: impl FnMut(DVec3) -> Option<DVec3>,
) -> SurfaceFilter {
    let fields = FilterFields::new(decoded);
    fit_displacements(decoded, &fields.normal, &fields.smoothed, closest)
}

/// The factors `(a, b)` that best fit `mesh`, its vertices moved by `a · first + b ·
/// second` (one displacement of each field per vertex), to the original surface: the fit
/// of [`fit_surface_filter`] for any two fields, e.g. the filter's fields of the unfiltered
/// mesh restricted to the vertices EdgeSharpener left in place.
pub fn fit_displacements(
    mesh: &Mesh,
    first: &[DVec3],
    second: &[DVec3],
    mut closest: impl FnMut(DVec3) -> Option<DVec3>,
) -> SurfaceFilter {
    let decoded = mesh;
    let pos = &decoded.positions;
    if first.len() < pos.len() || second.len() < pos.len() {
        return SurfaceFilter::NONE;
    }
    let total = decoded.triangles.len() * PATTERN.len();
    // An odd stride cycles through the four pattern points (an even one would keep to one
    // or two of them).
    let stride = match total.div_ceil(MAX_SAMPLES) {
        0 | 1 => 1,
        s => s | 1,
    };
    // Normal equations: m = Σ w x xᵀ, v = Σ w r x.
    let (mut m00, mut m01, mut m11, mut v0, mut v1) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut sample = 0usize;
    while sample < total {
        let t = sample / PATTERN.len();
        let w = PATTERN[sample % PATTERN.len()];
        sample += stride;
        let [i, j, k] = decoded.triangles[t].map(|v| v as usize);
        if i >= pos.len() || j >= pos.len() || k >= pos.len() {
            continue;
        }
        let cross = (pos[j] - pos[i]).cross(pos[k] - pos[i]);
        let len = cross.length();
        if !(len > 0.0 && len.is_finite()) {
            continue;
        }
        let nf = cross / len;
        let area = 0.5 * len;
        let mix = |f: &[DVec3]| (w[0] * f[i] + w[1] * f[j] + w[2] * f[k]).dot(nf);
        let p = w[0] * pos[i] + w[1] * pos[j] + w[2] * pos[k];
        let Some(c) = closest(p) else {
            continue;
        };
        let r = (c - p).dot(nf);
        let (x0, x1) = (mix(first), mix(second));
        if !(r.is_finite() && x0.is_finite() && x1.is_finite()) {
            continue;
        }
        m00 += area * x0 * x0;
        m01 += area * x0 * x1;
        m11 += area * x1 * x1;
        v0 += area * r * x0;
        v1 += area * r * x1;
    }
    let det = m00 * m11 - m01 * m01;
    // Nearly collinear fields (a uniform curvature): one factor carries the fit.
    if det > 1e-9 * m00 * m11 && det.is_finite() {
        let a = (v0 * m11 - v1 * m01) / det;
        let b = (m00 * v1 - m01 * v0) / det;
        SurfaceFilter::from_factors(a, b)
    } else if m00 > 0.0 {
        SurfaceFilter::from_factors(v0 / m00, 0.0)
    } else {
        SurfaceFilter::NONE
    }
}
