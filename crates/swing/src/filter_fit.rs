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
//! lands on the sweep's optimum within its resolution (docs/results.md). The extended
//! filter's five factors are fitted the same way on the same samples ([`fit_filters`]).

use whet_codec::{FilterFields, SurfaceFilter};
use whet_mesh::{DVec3, Mesh};

/// Most surface samples of one fit: two (or five) unknowns need few, and the fit runs once
/// per retiling of a rate search.
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
    closest: impl FnMut(DVec3) -> Option<DVec3>,
) -> SurfaceFilter {
    let mut normal = TwoFieldEquations::default();
    sample_fields(mesh, [first, second], closest, |area, r, [x0, x1]| {
        normal.add(area, r, x0, x1);
    });
    normal.solve()
}

/// What [`fit_filters`] found on one set of samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterFit {
    /// The two-field filter, exactly as [`fit_displacements`] fits it.
    pub basic: SurfaceFilter,
    /// The extended filter (five fields, format 1.4) and the ratio of its fitted RMS to the
    /// basic filter's, both with their coded factors (under 1 when it fits better); `None`
    /// when its equations are degenerate.
    pub extended: Option<(SurfaceFilter, f64)>,
}

/// Fits the two-field filter and the extended one (docs/swing.md section 2, "Extended
/// surface filter") to the original on one set of samples: `fields` are the filter's fields
/// of `decoded` and `extra` the extended filter's three ([`FilterFields::extended`]).
pub fn fit_filters(
    decoded: &Mesh,
    fields: &FilterFields,
    extra: &[Vec<DVec3>; 3],
    closest: impl FnMut(DVec3) -> Option<DVec3>,
) -> FilterFit {
    let mut basic = TwoFieldEquations::default();
    let mut m = [[0.0f64; 5]; 5];
    let mut v = [0.0f64; 5];
    let mut rr = 0.0f64;
    let all: [&[DVec3]; 5] = [
        &fields.normal,
        &fields.smoothed,
        &extra[0],
        &extra[1],
        &extra[2],
    ];
    sample_fields(decoded, all, closest, |area, r, x| {
        // The two-field sums exactly as fit_displacements makes them (same samples, same
        // order), so the basic filter does not change with the extended fit beside it.
        basic.add(area, r, x[0], x[1]);
        if !(r.is_finite() && x.iter().all(|x| x.is_finite())) {
            return;
        }
        rr += area * r * r;
        for a in 0..5 {
            v[a] += area * r * x[a];
            for b in 0..5 {
                m[a][b] += area * x[a] * x[b];
            }
        }
    });
    let basic = basic.solve();
    let extended = solve_spd(m, v).and_then(|c| {
        let filter = SurfaceFilter::from_extended_factors(c);
        if !filter.is_extended() {
            return None;
        }
        // The fitted sums of squares of both coded filters: rr − 2 cᵀv + cᵀ M c.
        let sse = |c: [f64; 5]| {
            let mut e = rr;
            for a in 0..5 {
                e -= 2.0 * c[a] * v[a];
                for b in 0..5 {
                    e += c[a] * m[a][b] * c[b];
                }
            }
            e.max(0.0)
        };
        let (ext, two) = (
            sse(filter.extended_factors()),
            sse(basic.extended_factors()),
        );
        let ratio = (ext / two).sqrt();
        (ratio.is_finite()).then_some((filter, ratio))
    });
    FilterFit { basic, extended }
}

/// The normal equations of a two-field fit.
#[derive(Default)]
struct TwoFieldEquations {
    m00: f64,
    m01: f64,
    m11: f64,
    v0: f64,
    v1: f64,
}

impl TwoFieldEquations {
    fn add(&mut self, area: f64, r: f64, x0: f64, x1: f64) {
        if !(r.is_finite() && x0.is_finite() && x1.is_finite()) {
            return;
        }
        self.m00 += area * x0 * x0;
        self.m01 += area * x0 * x1;
        self.m11 += area * x1 * x1;
        self.v0 += area * r * x0;
        self.v1 += area * r * x1;
    }

    fn solve(&self) -> SurfaceFilter {
        let TwoFieldEquations {
            m00,
            m01,
            m11,
            v0,
            v1,
        } = *self;
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
}

/// Solves `m c = v` for a symmetric positive semi-definite `m` (normal equations) by a
/// Cholesky factorisation, on the equations scaled to a unit diagonal (the fields differ in
/// size: `q` is about `L / R` times `d`) and with a small ridge (a millionth), so that nearly
/// collinear fields (on a sphere `s` and `s2` are nearly `d`) get bounded factors instead of
/// a blow-up; `None` when a field is empty everywhere or a value is not finite.
fn solve_spd(m: [[f64; 5]; 5], v: [f64; 5]) -> Option<[f64; 5]> {
    let scale: [f64; 5] = std::array::from_fn(|i| m[i][i].sqrt());
    if scale.iter().any(|x| !(x.is_finite() && *x > 0.0)) || v.iter().any(|x| !x.is_finite()) {
        return None;
    }
    // m' = D⁻¹ m D⁻¹ (unit diagonal), v' = D⁻¹ v, c = D⁻¹ c'.
    let mut m: [[f64; 5]; 5] =
        std::array::from_fn(|i| std::array::from_fn(|j| m[i][j] / (scale[i] * scale[j])));
    let v: [f64; 5] = std::array::from_fn(|i| v[i] / scale[i]);
    for (i, row) in m.iter_mut().enumerate() {
        row[i] += 1e-6;
    }
    // m = l lᵀ.
    let mut l = [[0.0f64; 5]; 5];
    for i in 0..5 {
        for j in 0..=i {
            let mut sum = m[i][j];
            for k in 0..j {
                sum -= l[i][k] * l[j][k];
            }
            if i == j {
                if sum.is_nan() || sum <= 0.0 {
                    return None;
                }
                l[i][i] = sum.sqrt();
            } else {
                l[i][j] = sum / l[j][j];
            }
        }
    }
    let mut y = [0.0f64; 5];
    for i in 0..5 {
        let mut sum = v[i];
        for k in 0..i {
            sum -= l[i][k] * y[k];
        }
        y[i] = sum / l[i][i];
    }
    let mut c = [0.0f64; 5];
    for i in (0..5).rev() {
        let mut sum = y[i];
        for k in i + 1..5 {
            sum -= l[k][i] * c[k];
        }
        c[i] = sum / l[i][i];
    }
    let c: [f64; 5] = std::array::from_fn(|i| c[i] / scale[i]);
    c.iter().all(|x| x.is_finite()).then_some(c)
}

/// Calls `f(area, r, x)` for the filter fit's samples of `mesh` (see the module docs): at
/// most [`MAX_SAMPLES`] fixed barycentric points, each with its triangle's area, its signed
/// distance `r` to the original along the triangle's normal and the mixes `x` of the
/// `fields` there along that normal. Samples without a closest point, or on a triangle
/// without a normal, are left out; `f` checks the rest for finiteness.
fn sample_fields<const N: usize>(
    decoded: &Mesh,
    fields: [&[DVec3]; N],
    mut closest: impl FnMut(DVec3) -> Option<DVec3>,
    mut f: impl FnMut(f64, f64, [f64; N]),
) {
    let pos = &decoded.positions;
    if fields.iter().any(|x| x.len() < pos.len()) {
        return;
    }
    let total = decoded.triangles.len() * PATTERN.len();
    // An odd stride cycles through the four pattern points (an even one would keep to one
    // or two of them).
    let stride = match total.div_ceil(MAX_SAMPLES) {
        0 | 1 => 1,
        s => s | 1,
    };
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
        let p = w[0] * pos[i] + w[1] * pos[j] + w[2] * pos[k];
        let Some(c) = closest(p) else {
            continue;
        };
        let r = (c - p).dot(nf);
        let x = fields.map(|f| (w[0] * f[i] + w[1] * f[j] + w[2] * f[k]).dot(nf));
        f(area, r, x);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit icosphere with its vertices pushed off the sphere by a ripple, so the fit has
    /// a bias and noise to remove; the original is the unit sphere.
    fn rippled_sphere() -> Mesh {
        let mut m = whet_testkit::meshes::icosphere(3);
        for (i, p) in m.positions.iter_mut().enumerate() {
            *p *= 1.0 + 0.004 * ((i * 7919 % 13) as f64 / 13.0 - 0.5);
        }
        m
    }

    #[test]
    fn the_basic_filter_of_fit_filters_is_fit_displacements_to_the_bit() {
        let m = rippled_sphere();
        let closest = |p: DVec3| Some(p.normalize());
        let (fields, extra) = FilterFields::extended(&m, 0.1);
        let fit = fit_filters(&m, &fields, &extra, closest);
        assert_eq!(
            fit.basic,
            fit_displacements(&m, &fields.normal, &fields.smoothed, closest)
        );
        assert!(!fit.basic.is_none());
        let (_, ratio) = fit.extended.expect("a fit of five fields");
        // Five fields fit the samples at least as well as two of them, up to the factors'
        // rounding to 1/1024.
        assert!(ratio <= 1.0 + 1e-3, "{ratio}");
    }

    #[test]
    fn collinear_or_empty_equations_do_not_blow_up() {
        // Identical rows: the ridge keeps the factors bounded.
        let row = [1.0, 1.0, 1.0, 1.0, 1.0];
        let c = solve_spd([row; 5], [2.0; 5]).unwrap();
        assert!(c.iter().all(|x| x.is_finite() && x.abs() < 10.0), "{c:?}");
        assert!((c.iter().sum::<f64>() - 2.0).abs() < 1e-3, "{c:?}");
        // Fields of different sizes (as q is about L / R times d) are solved as well as
        // equal ones (the ridge acts on the scaled equations).
        let s = [1.0, 0.05, 20.0, 1.0, 0.1];
        let m: [[f64; 5]; 5] = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                if i == j {
                    s[i] * s[i]
                } else {
                    0.1 * s[i] * s[j]
                }
            })
        });
        let want = [0.5, -2.0, 0.25, 1.0, 3.0];
        let v: [f64; 5] = std::array::from_fn(|i| (0..5).map(|j| m[i][j] * want[j]).sum());
        let c = solve_spd(m, v).unwrap();
        for (c, w) in c.iter().zip(want) {
            assert!((c - w).abs() < 1e-3 * w.abs().max(1.0), "{c} against {w}");
        }
        assert_eq!(solve_spd([[0.0; 5]; 5], [0.0; 5]), None);
        assert_eq!(solve_spd([[f64::NAN; 5]; 5], [1.0; 5]), None);
    }
}
