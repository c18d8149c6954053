//! The Metro measure: one-sided and symmetric max / mean / RMS surface distances.
//!
//! For one direction the sampled mesh `A` is probed at every referenced vertex, along every
//! edge and at `n` area-uniform face points ([`crate::sampling`]); each probe's distance to
//! the target surface comes from the target's [`Bvh`]. The maximum is taken over all probes,
//! so creases and corners always count; mean and RMS are plain averages over the face samples
//! only, which makes them area-weighted averages (vertex and edge probes would bias them
//! toward finely tessellated regions). Sample queries run on rayon in fixed-size chunks whose
//! partial results are combined in chunk order, so every figure is bit-for-bit the same for
//! any number of threads.

use rayon::prelude::*;
use whet_mesh::Mesh;

use crate::bvh::Bvh;
use crate::sampling::{
    derive_seed, face_sample_offsets, uniform_in_triangle, unique_edges, vertex_triangles,
    EdgePlan, SplitMix64, EDGE_CHUNK, FACE_CHUNK, NONE, VERTEX_CHUNK,
};
use crate::Error;

/// Most face samples per direction [`metro`] and [`one_sided`] take: about a billion, some
/// minutes per direction on one core. Memory does not grow with the samples (they are
/// streamed), but time does, and a count past this is a typo rather than a measurement.
pub const MAX_FACE_SAMPLES: usize = 1 << 30;

/// Options of [`metro`].
#[non_exhaustive]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MetroOptions {
    /// Face samples per direction; `None` picks [`MetroOptions::default_samples`]:
    /// `max(10 × the larger face count, 1 000 000)`.
    pub samples: Option<usize>,
    /// Seed of the sample layout; equal seeds give identical reports.
    pub seed: u64,
}

impl MetroOptions {
    /// Default rule for the samples and seed 0.
    pub const DEFAULT: MetroOptions = MetroOptions {
        samples: None,
        seed: 0,
    };

    /// Sets the number of face samples per direction.
    pub fn with_samples(mut self, samples: usize) -> Self {
        self.samples = Some(samples);
        self
    }

    /// Sets the seed.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// The default number of face samples per direction for a pair of meshes: at least ten
    /// per face of the larger mesh and at least one million, at most [`MAX_FACE_SAMPLES`].
    pub fn default_samples(reference: &Mesh, test: &Mesh) -> usize {
        reference
            .triangles
            .len()
            .max(test.triangles.len())
            .saturating_mul(10)
            .clamp(1_000_000, MAX_FACE_SAMPLES)
    }

    /// The number of face samples per direction these options give for a pair of meshes.
    pub fn face_samples(&self, reference: &Mesh, test: &Mesh) -> usize {
        self.samples
            .unwrap_or_else(|| Self::default_samples(reference, test))
    }
}

impl Default for MetroOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Maximum, mean and RMS distance, absolute and in percent of the reference diagonal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Figures {
    /// Largest distance over all probes (vertices, edges, faces).
    pub max: f64,
    /// Mean distance over the area-uniform face samples.
    pub mean: f64,
    /// Root mean square distance over the area-uniform face samples.
    pub rms: f64,
    /// `max` in percent of the reference bounding-box diagonal.
    pub max_pct: f64,
    /// `mean` in percent of the reference bounding-box diagonal.
    pub mean_pct: f64,
    /// `rms` in percent of the reference bounding-box diagonal.
    pub rms_pct: f64,
}

impl Figures {
    /// Figures from absolute values and the diagonal they are relative to (`diagonal > 0`).
    pub fn new(max: f64, mean: f64, rms: f64, diagonal: f64) -> Figures {
        let pct = 100.0 / diagonal;
        Figures {
            max,
            mean,
            rms,
            max_pct: max * pct,
            mean_pct: mean * pct,
            rms_pct: rms * pct,
        }
    }

    /// The larger of `self` and `other`, figure by figure (the symmetric figures).
    pub fn larger(&self, other: &Figures) -> Figures {
        Figures {
            max: self.max.max(other.max),
            mean: self.mean.max(other.mean),
            rms: self.rms.max(other.rms),
            max_pct: self.max_pct.max(other.max_pct),
            mean_pct: self.mean_pct.max(other.mean_pct),
            rms_pct: self.rms_pct.max(other.rms_pct),
        }
    }
}

/// The figures of one direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Directional {
    /// Distances from the sampled mesh to the target surface.
    pub figures: Figures,
    /// Points measured: referenced vertices + edge samples + face samples.
    pub samples: usize,
    /// Area-uniform face samples (the ones mean and RMS average over).
    pub face_samples: usize,
}

/// Result of [`metro`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetroReport {
    /// Larger of the two directions, figure by figure.
    pub symmetric: Figures,
    /// Bounding-box diagonal of the reference mesh (the unit of the `_pct` figures).
    pub diagonal: f64,
    /// Face samples per direction.
    pub samples: usize,
    /// The test mesh sampled against the reference surface.
    pub forward: Directional,
    /// The reference mesh sampled against the test surface.
    pub backward: Directional,
}

impl MetroReport {
    /// The report as one JSON object: the symmetric figures at the top level (`max`, `mean`,
    /// `rms`, `max_pct`, `mean_pct`, `rms_pct`), `diagonal`, `samples` (face samples per
    /// direction), and objects `forward` and `backward` with the same six figures plus
    /// `samples` (all points measured) and `face_samples`.
    pub fn to_json(&self) -> String {
        let mut s = String::with_capacity(640);
        s.push('{');
        push_figures(&mut s, &self.symmetric);
        s.push_str(&format!(
            ",\"diagonal\":{},\"samples\":{}",
            json_num(self.diagonal),
            self.samples
        ));
        for (name, d) in [("forward", &self.forward), ("backward", &self.backward)] {
            s.push_str(&format!(",\"{name}\":{{"));
            push_figures(&mut s, &d.figures);
            s.push_str(&format!(
                ",\"samples\":{},\"face_samples\":{}}}",
                d.samples, d.face_samples
            ));
        }
        s.push('}');
        s
    }
}

fn push_figures(s: &mut String, f: &Figures) {
    s.push_str(&format!(
        "\"max\":{},\"mean\":{},\"rms\":{},\"max_pct\":{},\"mean_pct\":{},\"rms_pct\":{}",
        json_num(f.max),
        json_num(f.mean),
        json_num(f.rms),
        json_num(f.max_pct),
        json_num(f.mean_pct),
        json_num(f.rms_pct)
    ));
}

/// An `f64` as a JSON number (`Display` never uses exponents, so it is valid JSON); `null`
/// for the non-finite values that validated input cannot produce.
fn json_num(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        "null".to_string()
    }
}

/// Checks that `mesh` can be sampled and measured: it has a triangle, every index is in range
/// and every position is finite.
pub(crate) fn validate(mesh: &Mesh, which: &'static str) -> Result<(), Error> {
    if mesh.triangles.is_empty() {
        return Err(Error::NoTriangles { which });
    }
    let nv = mesh.positions.len();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            if v as usize >= nv {
                return Err(Error::IndexOutOfRange {
                    which,
                    triangle: t,
                    index: v,
                    vertex_count: nv,
                });
            }
        }
    }
    if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::NonFinitePosition { which, vertex: v });
    }
    Ok(())
}

/// Partial sums of one chunk of face samples.
#[derive(Clone, Copy, Debug, Default)]
struct FaceAcc {
    max: f64,
    sum: f64,
    sum_sq: f64,
}

/// Symmetric Metro distance between `reference` and `test`.
///
/// Builds a [`Bvh`] over each mesh and runs [`one_sided`] both ways with the same number of
/// face samples ([`MetroOptions::face_samples`]); the symmetric figures are the larger of the
/// two directions, and all `_pct` figures are relative to the reference's bounding-box
/// diagonal.
///
/// Fails when a mesh has no triangle, an out-of-range index or a non-finite position, or when
/// the reference's bounding box has zero diagonal.
pub fn metro(reference: &Mesh, test: &Mesh, opts: &MetroOptions) -> Result<MetroReport, Error> {
    validate(reference, "reference")?;
    validate(test, "test")?;
    let diagonal = reference.diagonal();
    check_diagonal(diagonal)?;
    let n = check_samples(opts.face_samples(reference, test))?;
    let (ref_bvh, test_bvh) = rayon::join(|| Bvh::new(reference), || Bvh::new(test));
    let (forward, backward) = rayon::join(
        || one_sided(test, &ref_bvh, n, derive_seed(opts.seed, 1), diagonal),
        || one_sided(reference, &test_bvh, n, derive_seed(opts.seed, 2), diagonal),
    );
    let (forward, backward) = (forward?, backward?);
    Ok(MetroReport {
        symmetric: forward.figures.larger(&backward.figures),
        diagonal,
        samples: n,
        forward,
        backward,
    })
}

/// The face samples to draw for a request: at least one, at most [`MAX_FACE_SAMPLES`].
fn check_samples(requested: usize) -> Result<usize, Error> {
    if requested > MAX_FACE_SAMPLES {
        return Err(Error::TooManySamples {
            samples: requested,
            limit: MAX_FACE_SAMPLES,
        });
    }
    Ok(requested.max(1))
}

fn check_diagonal(diagonal: f64) -> Result<(), Error> {
    if diagonal > 0.0 && diagonal.is_finite() {
        Ok(())
    } else {
        Err(Error::DegenerateDiagonal { diagonal })
    }
}

/// One direction of the Metro measure: `sampled` is probed at its referenced vertices, along
/// its edges and at `n_face_samples` area-uniform face points (at least one), each measured
/// against the surface in `target`. `diagonal` is the length the `_pct` figures are relative
/// to (normally the reference mesh's bounding-box diagonal). The result depends only on the
/// inputs and `seed`, not on the number of threads.
///
/// Reusing one target [`Bvh`] across many sampled meshes saves rebuilding it.
pub fn one_sided(
    sampled: &Mesh,
    target: &Bvh,
    n_face_samples: usize,
    seed: u64,
    diagonal: f64,
) -> Result<Directional, Error> {
    validate(sampled, "sampled")?;
    if target.is_empty() {
        return Err(Error::EmptyTarget);
    }
    check_diagonal(diagonal)?;
    let n = check_samples(n_face_samples)?;

    // Face samples: systematic area-proportional counts, one random stream per chunk.
    let offsets = face_sample_offsets(sampled, n, seed);
    let t_count = sampled.triangles.len();
    // The target triangle nearest to the last sample of each sampled triangle: the seed for
    // the vertex and edge probes on that triangle's boundary.
    let mut hits = vec![NONE; t_count];
    let face_parts: Vec<FaceAcc> = hits
        .par_chunks_mut(FACE_CHUNK)
        .enumerate()
        .map(|(chunk, chunk_hits)| {
            let mut rng = SplitMix64::new(derive_seed(seed, 0x1_0000_0000 + chunk as u64));
            let mut query = target.coherent_query();
            let mut acc = FaceAcc::default();
            let first = chunk * FACE_CHUNK;
            for (k, hit) in chunk_hits.iter_mut().enumerate() {
                let t = first + k;
                let [a, b, c] = sampled.triangle_positions(t);
                for _ in offsets[t]..offsets[t + 1] {
                    let p = uniform_in_triangle(a, b, c, rng.next_f64(), rng.next_f64());
                    let d = query.distance(p);
                    acc.max = acc.max.max(d);
                    acc.sum += d;
                    acc.sum_sq += d * d;
                    *hit = query.last_packed();
                }
            }
            acc
        })
        .collect();
    let mut face = FaceAcc::default();
    for part in &face_parts {
        face.max = face.max.max(part.max);
        face.sum += part.sum;
        face.sum_sq += part.sum_sq;
    }

    // Vertex and edge probes only feed the maximum, so each one only needs to know whether
    // it beats the largest distance seen so far (the face maximum, then the chunk's own):
    // usually the triangle nearest to the previous probe already says it does not. Probes
    // skipped that way are no farther than the final maximum, so it is exact.
    let floor = face.max;

    // Edge samples: n spread along the edges by length, each chunk starting from the
    // remainder carried into it.
    let (edges, edge_tris) = unique_edges(sampled);
    let plan = EdgePlan::new(sampled, &edges, n);
    let (edge_max, edge_count) = edges
        .par_chunks(EDGE_CHUNK)
        .zip(edge_tris.par_chunks(EDGE_CHUNK))
        .enumerate()
        .map(|(chunk, (chunk_edges, chunk_tris))| {
            let mut query = target.coherent_query();
            let mut max = floor;
            let mut count = 0usize;
            let mut current = usize::MAX;
            plan.for_each_sample(sampled, chunk, chunk_edges, |e, p| {
                if e != current {
                    current = e;
                    query.reseed(hits[chunk_tris[e] as usize]);
                }
                if let Some(d) = query.distance_above(p, max) {
                    max = d;
                }
                count += 1;
            });
            (max, count)
        })
        .reduce(
            || (floor, 0),
            |x, y| (x.0.max(y.0), x.1.saturating_add(y.1)),
        );
    // Vertex samples: every vertex used by a triangle.
    let vertex_tris = vertex_triangles(sampled);
    let (vertex_max, vertex_count) = vertex_tris
        .par_chunks(VERTEX_CHUNK)
        .enumerate()
        .map(|(chunk, tris)| {
            let mut query = target.coherent_query();
            let mut max = floor;
            let mut count = 0usize;
            for (k, &t) in tris.iter().enumerate() {
                if t == NONE {
                    continue;
                }
                query.reseed(hits[t as usize]);
                let p = sampled.positions[chunk * VERTEX_CHUNK + k];
                if let Some(d) = query.distance_above(p, max) {
                    max = d;
                }
                count += 1;
            }
            (max, count)
        })
        .reduce(
            || (floor, 0),
            |x, y| (x.0.max(y.0), x.1.saturating_add(y.1)),
        );

    let nf = n as f64;
    let max = face.max.max(edge_max).max(vertex_max);
    let mean = face.sum / nf;
    let rms = (face.sum_sq / nf).sqrt();
    if !(max.is_finite() && mean.is_finite() && rms.is_finite()) {
        // Only coordinates near the f64 range can get here (squared distances overflow).
        return Err(Error::Overflow);
    }
    Ok(Directional {
        figures: Figures::new(max, mean, rms, diagonal),
        samples: n.saturating_add(edge_count).saturating_add(vertex_count),
        face_samples: n,
    })
}

/// Distance from every vertex of `mesh` (referenced or not) to the surface in `target`, in
/// vertex order. A vertex with a non-finite position, or any vertex when `target` is empty,
/// gets `f64::INFINITY`.
pub fn vertex_distances(mesh: &Mesh, target: &Bvh) -> Vec<f64> {
    let mut out = vec![0.0; mesh.positions.len()];
    out.par_chunks_mut(VERTEX_CHUNK)
        .zip(mesh.positions.par_chunks(VERTEX_CHUNK))
        .for_each(|(dst, src)| {
            let mut query = target.coherent_query();
            for (d, p) in dst.iter_mut().zip(src) {
                *d = if p.is_finite() {
                    query.distance(*p)
                } else {
                    f64::INFINITY
                };
            }
        });
    out
}

/// Colour ramp for per-vertex errors: blue at 0, green at `max / 2`, red at `max` and above,
/// linear in between (sRGB bytes). A non-positive or non-finite `max` maps 0 (and NaN) to
/// blue and anything positive to red.
pub fn error_ramp(value: f64, max: f64) -> [u8; 3] {
    let t = if max > 0.0 && max.is_finite() {
        let t = value / max;
        if t.is_nan() {
            0.0
        } else {
            t.clamp(0.0, 1.0)
        }
    } else if value > 0.0 {
        1.0
    } else {
        0.0
    };
    let byte = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    if t <= 0.5 {
        let s = t * 2.0;
        [0, byte(s), byte(1.0 - s)]
    } else {
        let s = (t - 0.5) * 2.0;
        [byte(s), byte(1.0 - s), 0]
    }
}
