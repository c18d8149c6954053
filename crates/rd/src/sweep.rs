//! The sweep: every (mesh, codec, rate) point is encoded and decoded once, then each stage
//! runs on the decoded mesh, and each result is measured with Metro against the original.

use std::time::Instant;
use whet_mesh::Mesh;
use whet_metro::{metro, MetroOptions};

/// A codec under test: a name, and encode/decode at a rate parameter whose meaning is the
/// codec's (quantization bits for the exact mode, bits per original vertex for swing).
pub trait Codec: Sync {
    /// Name shown in tables and legends (e.g. `exact`, `swing`).
    fn name(&self) -> String;
    /// Encodes `mesh` at `rate`.
    fn encode(&self, mesh: &Mesh, rate: f64) -> Result<Vec<u8>, String>;
    /// Decodes a stream this codec wrote.
    fn decode(&self, bytes: &[u8]) -> Result<Mesh, String>;
    /// The decoded mesh the post-processing stages start from, when it is not
    /// [`Codec::decode`]'s (`None`, the default): the swing mode's stages sharpen the mesh
    /// decoded without its surface filter, as `whet decode --sharpen` does.
    fn decode_for_stages(&self, _bytes: &[u8]) -> Option<Result<Mesh, String>> {
        None
    }
}

/// A post-processing stage applied to the decoded mesh (`decoded` itself is the identity).
pub struct Stage {
    /// Name shown in tables and legends (`decoded`, `sharpened`, `bent`).
    pub name: String,
    /// The stage; it receives the decoded mesh ([`Codec::decode`]'s, or for a
    /// post-processing stage [`Codec::decode_for_stages`]' when the codec has one) and the
    /// stream it came from (a stage may read what the stream carries for it, e.g. a swing
    /// stream's filter for after sharpening).
    #[allow(clippy::type_complexity)]
    pub apply: Box<dyn Fn(&Mesh, &[u8]) -> Result<Mesh, String> + Sync + Send>,
    /// Whether the stage starts from [`Codec::decode_for_stages`] (post-processing) rather
    /// than from [`Codec::decode`] (the identity stage).
    pub post_processing: bool,
}

impl Stage {
    /// The identity stage `decoded`: what the codec's decoder outputs.
    pub fn decoded() -> Stage {
        Stage {
            name: "decoded".into(),
            apply: Box::new(|m, _| Ok(m.clone())),
            post_processing: false,
        }
    }

    /// A named post-processing stage.
    pub fn new(
        name: impl Into<String>,
        f: impl Fn(&Mesh) -> Result<Mesh, String> + Sync + Send + 'static,
    ) -> Stage {
        Stage {
            name: name.into(),
            apply: Box::new(move |m, _| f(m)),
            post_processing: true,
        }
    }

    /// A named post-processing stage that also reads the stream.
    pub fn with_stream(
        name: impl Into<String>,
        f: impl Fn(&Mesh, &[u8]) -> Result<Mesh, String> + Sync + Send + 'static,
    ) -> Stage {
        Stage {
            name: name.into(),
            apply: Box::new(f),
            post_processing: true,
        }
    }
}

/// One codec with the rates to sweep it at.
pub struct CodecSweep<'a> {
    /// The codec.
    pub codec: &'a dyn Codec,
    /// Rate parameters.
    pub rates: Vec<f64>,
    /// Names of the sweep's stages this codec's decoded meshes go through (`None`: all of
    /// them). A baseline curve often needs only `decoded`.
    pub stages: Option<Vec<String>>,
}

impl<'a> CodecSweep<'a> {
    /// `codec` at `rates`, through every stage of the sweep.
    pub fn new(codec: &'a dyn Codec, rates: Vec<f64>) -> Self {
        CodecSweep {
            codec,
            rates,
            stages: None,
        }
    }

    /// Limits the stages this codec goes through to the named ones.
    pub fn with_stages(mut self, stages: Vec<String>) -> Self {
        self.stages = Some(stages);
        self
    }
}

/// One measured point (or a failed one, with `error` set and figures NaN).
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// Mesh name.
    pub mesh: String,
    /// Codec name.
    pub mode: String,
    /// Rate parameter given to the codec.
    pub rate: f64,
    /// Stage name.
    pub stage: String,
    /// Stream size.
    pub bytes: usize,
    /// Vertices of the original.
    pub original_vertices: usize,
    /// Triangles of the original.
    pub original_triangles: usize,
    /// Vertices of the measured mesh.
    pub vertices: usize,
    /// Triangles of the measured mesh.
    pub triangles: usize,
    /// Symmetric Metro figures (absolute).
    pub max: f64,
    /// Mean.
    pub mean: f64,
    /// RMS.
    pub rms: f64,
    /// Bounding-box diagonal of the original.
    pub diagonal: f64,
    /// Encode time.
    pub encode_ms: f64,
    /// Decode time of [`Codec::decode`] (on every stage's row; a post-processing stage's
    /// own decode through [`Codec::decode_for_stages`] is not timed).
    pub decode_ms: f64,
    /// Stage time (0 for `decoded`).
    pub stage_ms: f64,
    /// Metro time.
    pub metro_ms: f64,
    /// Why the point failed, if it did.
    pub error: Option<String>,
}

impl Point {
    /// Bits per original vertex.
    pub fn bits_per_original_vertex(&self) -> f64 {
        self.bytes as f64 * 8.0 / self.original_vertices.max(1) as f64
    }
    /// Bits per original triangle.
    pub fn bits_per_original_triangle(&self) -> f64 {
        self.bytes as f64 * 8.0 / self.original_triangles.max(1) as f64
    }
    /// A figure in percent of the diagonal.
    pub fn pct(&self, x: f64) -> f64 {
        100.0 * x / self.diagonal
    }
    /// A figure in units of 1e-4 of the diagonal (the papers' plots).
    pub fn e4(&self, x: f64) -> f64 {
        1e4 * x / self.diagonal
    }
}

/// Sweep settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct SweepOptions {
    /// Metro face samples per direction.
    pub metro_samples: usize,
    /// Metro seed.
    pub seed: u64,
}

impl SweepOptions {
    /// 300,000 samples per direction (RMS to about 1 %), seed 0.
    pub const DEFAULT: SweepOptions = SweepOptions {
        metro_samples: 300_000,
        seed: 0,
    };
    /// Sets the Metro samples.
    pub const fn with_metro_samples(mut self, n: usize) -> Self {
        self.metro_samples = n;
        self
    }
    /// Sets the seed.
    pub const fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }
}

impl Default for SweepOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Runs one (mesh, codec, rate) job: encode, decode, every stage, Metro for each. A failure
/// anywhere yields failed points for the stages not reached, never a panic of the sweep.
pub fn run_point(
    name: &str,
    original: &Mesh,
    codec: &dyn Codec,
    rate: f64,
    stages: &[&Stage],
    opts: &SweepOptions,
) -> Vec<Point> {
    let diagonal = original.diagonal();
    let base = Point {
        mesh: name.to_string(),
        mode: codec.name(),
        rate,
        stage: String::new(),
        bytes: 0,
        original_vertices: original.positions.len(),
        original_triangles: original.triangles.len(),
        vertices: 0,
        triangles: 0,
        max: f64::NAN,
        mean: f64::NAN,
        rms: f64::NAN,
        diagonal,
        encode_ms: 0.0,
        decode_ms: 0.0,
        stage_ms: 0.0,
        metro_ms: 0.0,
        error: None,
    };
    let fail_all = |mut p: Point, msg: String| -> Vec<Point> {
        p.error = Some(msg);
        stages
            .iter()
            .map(|s| Point {
                stage: s.name.clone(),
                ..p.clone()
            })
            .collect()
    };
    let t = Instant::now();
    let bytes = match codec.encode(original, rate) {
        Ok(b) => b,
        Err(e) => return fail_all(base, format!("encode: {e}")),
    };
    let mut base = Point {
        bytes: bytes.len(),
        encode_ms: ms(t),
        ..base
    };
    let t = Instant::now();
    let decoded = match codec.decode(&bytes) {
        Ok(m) => m,
        Err(e) => return fail_all(base, format!("decode: {e}")),
    };
    base.decode_ms = ms(t);
    // The post-processing stages' input, decoded once if the codec has its own and a stage
    // needs it (not timed: the decode column is the decoder's output).
    let for_stages = if stages.iter().any(|s| s.post_processing) {
        codec.decode_for_stages(&bytes)
    } else {
        None
    };
    let metro_opts = MetroOptions::DEFAULT
        .with_samples(opts.metro_samples)
        .with_seed(opts.seed);
    stages
        .iter()
        .map(|stage| {
            let mut p = Point {
                stage: stage.name.clone(),
                ..base.clone()
            };
            let input = match (&for_stages, stage.post_processing) {
                (Some(Ok(m)), true) => m,
                (Some(Err(e)), true) => {
                    p.error = Some(format!("decode: {e}"));
                    return p;
                }
                _ => &decoded,
            };
            let t = Instant::now();
            let mesh = match (stage.apply)(input, &bytes) {
                Ok(m) => m,
                Err(e) => {
                    p.error = Some(format!("{}: {e}", stage.name));
                    return p;
                }
            };
            p.stage_ms = ms(t);
            p.vertices = mesh.positions.len();
            p.triangles = mesh.triangles.len();
            let t = Instant::now();
            match metro(original, &mesh, &metro_opts) {
                Ok(r) => {
                    p.max = r.symmetric.max;
                    p.mean = r.symmetric.mean;
                    p.rms = r.symmetric.rms;
                }
                Err(e) => p.error = Some(format!("metro: {e}")),
            }
            p.metro_ms = ms(t);
            p
        })
        .collect()
}

/// Runs the whole sweep, jobs in parallel (rayon), results in a deterministic order (mesh,
/// codec, rate, stage as given). `progress` is called once per finished job.
pub fn sweep(
    meshes: &[(String, Mesh)],
    codecs: &[CodecSweep<'_>],
    stages: &[Stage],
    opts: &SweepOptions,
    progress: &(dyn Fn() + Sync),
) -> Vec<Point> {
    use rayon::prelude::*;
    let mut jobs: Vec<(usize, usize, f64)> = Vec::new();
    for m in 0..meshes.len() {
        for (c, cs) in codecs.iter().enumerate() {
            for &r in &cs.rates {
                jobs.push((m, c, r));
            }
        }
    }
    // Each codec's own stage list, in the sweep's order.
    let codec_stages: Vec<Vec<&Stage>> = codecs
        .iter()
        .map(|cs| {
            stages
                .iter()
                .filter(|s| {
                    cs.stages
                        .as_ref()
                        .is_none_or(|names| names.contains(&s.name))
                })
                .collect()
        })
        .collect();
    let results: Vec<Vec<Point>> = jobs
        .par_iter()
        .map(|&(m, c, r)| {
            let (name, mesh) = &meshes[m];
            let pts = run_point(name, mesh, codecs[c].codec, r, &codec_stages[c], opts);
            progress();
            pts
        })
        .collect();
    results.into_iter().flatten().collect()
}

/// Number of jobs a sweep will run (for a progress bar).
pub fn job_count(meshes: usize, codecs: &[CodecSweep<'_>]) -> usize {
    meshes * codecs.iter().map(|c| c.rates.len()).sum::<usize>()
}
