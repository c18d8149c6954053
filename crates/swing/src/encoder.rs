//! The swing encoder: input preparation, retiling at one edge length, the stream, and the
//! rate control that searches the edge length `L` for a size or an error target
//! (`algorithms.md` 1.9: the size goes as `L^-2`, so a secant on `log L` converges in a few
//! steps; the error goes roughly as `L^2`).

use crate::retiler::{retile_fitted, FilterFits, RetileStats, RetileTuning};
use crate::stated::StatedProjection;
use crate::Error;
use rayon::prelude::*;
use whet_codec::{
    encode_retiled, prepare_mesh, EncodeReport, SharpenHint, SnapVetoes, SurfaceFilter,
    SwingEncoded, SwingGeometry, SwingParams, SwingStreamInfo, Version,
};
use whet_mesh::Mesh;
use whet_metro::{metro, MetroOptions};

/// How the encoder chooses the edge length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rate {
    /// `L` as a fraction of the original's bounding-box diagonal.
    EdgeLength(f64),
    /// Bits per vertex of the ORIGINAL mesh (the papers' unit); `L` is searched.
    BitsPerVertex(f64),
    /// Whole-stream size in bytes; `L` is searched.
    TargetBytes(usize),
    /// Largest symmetric RMS error, in percent of the original's diagonal, measured with
    /// whet-metro; the cheapest stream found that meets it.
    MaxError(f64),
}

/// Which output of the decoder an error measurement of the encoder refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ErrorOf {
    /// The decoded (retiled) mesh itself.
    #[default]
    Decoded,
    /// The decoded mesh after EdgeSharpener with whet-sharpen's defaults (`whet decode
    /// --sharpen`): the output that matters for CAD parts.
    Sharpened,
}

/// One angle quantization tried by the automatic choice ([`SwingOptions::auto_angle_bits`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AngleTrial {
    /// Angle bits.
    pub angle_bits: u32,
    /// Edge length fraction the rate search settled on.
    pub edge_length_fraction: f64,
    /// Stream size.
    pub bytes: usize,
    /// Measured RMS error (of [`SwingOptions::error_of`]), % of the diagonal; `None` when
    /// this quantization reached no stream (an error target it cannot meet).
    pub rms_pct: Option<f64>,
    /// The max error measured with it (`None` when only the RMS was measured: an error
    /// target's search, or no stream).
    pub max_pct: Option<f64>,
    /// For the sharpened output: the `(rms, max)` its stream ends with once its sharpening
    /// and projections are chosen, for the quantization written and for a finalist
    /// (`SwingEncoder::encode`); `None` for the others.
    pub sharpened: Option<(f64, f64)>,
}

/// One sharpening measured by the encoder's choice ([`SwingOutput::sharpen_trials`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SharpenTrial {
    /// The method (or none).
    pub hint: SharpenHint,
    /// EdgeSharpener's smooth factor (irrelevant for [`SharpenHint::Unsharpened`]).
    pub smooth_factor: f64,
    /// EdgeSharpener's curved-wall factor (`SharpenOptions::curved_walls`; 0: off).
    pub curved_walls: f64,
    /// EdgeSharpener passes (`SharpenOptions::passes`; irrelevant for
    /// [`SharpenHint::Unsharpened`]).
    pub passes: u32,
    /// EdgeSharpener's gray-vertex labels on surface samplings
    /// (`SharpenOptions::surface_gray_labels`, header field 41): tried on the extended
    /// method's best after the grid's refinement only.
    pub gray_labels: bool,
    /// Measured symmetric RMS error of `whet decode --sharpen`'s output, % of the diagonal.
    pub rms_pct: f64,
    /// Its measured symmetric max error, % of the diagonal: a sharpening whose max is over
    /// that of the mesh it sharpens (the decoded mesh without its surface filter) is not
    /// chosen.
    pub max_pct: f64,
    /// With the planar-region projection after sharpening (optional header field 25, at
    /// [`PLANAR_FACTOR`]): tried on the best sharpening only.
    pub planar: bool,
    /// With the local quadric projection after that (optional header field 31, at
    /// [`QUADRIC_FACTOR`]): tried on the best sharpening, with the planar projection when
    /// that was kept.
    pub quadric: bool,
    /// With the one-sided quadric projection of the vertices beside creases after those
    /// (optional header field 37, at [`BESIDE_FACTOR`]): tried with the projections kept
    /// before it.
    pub beside: bool,
    /// With the crease projection after those (optional header field 35, at
    /// [`CREASE_MOVE`]): tried with the projections kept before it.
    pub crease: bool,
    /// With the apex restoration after those (optional header field 39, at [`APEX_MOVE`]):
    /// tried last, with the projections kept before it.
    pub apex: bool,
    /// With the stream's surface filter for after sharpening (header fields 17 and 19)
    /// applied: true but for the chosen sharpening tried without it (a stream whose filter
    /// the encoder fitted to zero counts as with it).
    pub sharpened_filter: bool,
    /// Measured on a runner-up's path: the best sharpening of another method (or of the
    /// extended method with gray labels, [`Self::gray_labels`]), which the encoder also
    /// takes through the vetoes, the projections and the filter's removal, and which is
    /// chosen when it ends better than the path standing by the margin (docs/swing.md
    /// section 2, "The runner-up"). False on the grid, its refinement and the best's path.
    pub runner_up: bool,
}

impl SharpenTrial {
    /// What the encoder's choice minimises: the RMS error times the max error to the power
    /// [`MAX_ERROR_WEIGHT`] (docs/swing.md section 2, "The max error counts too").
    pub fn score(&self) -> f64 {
        self.rms_pct * self.max_pct.max(0.0).powf(MAX_ERROR_WEIGHT)
    }
}

/// Weight of the max error in the choice of sharpening: the encoder minimises
/// `rms * max^MAX_ERROR_WEIGHT`, so a 1 % lower RMS is worth a 4 % higher max. By RMS alone,
/// a candidate 1.3 % lower in RMS and 59 % higher in max won (joint at 3.3 bpv, 6 bits:
/// max 0.26 % -> 0.42 %); a quarter makes a max 34 % lower worth an RMS 10 % higher, and
/// keeps RMS the main figure.
pub const MAX_ERROR_WEIGHT: f64 = 0.25;

/// The automatic angle bits (sharpened output): a quantization whose score with
/// EdgeSharpener's default comes within this factor of the best one's is a *finalist*, whose
/// sharpening is chosen too (`SwingEncoder::encode`). The scores move by a few % from one
/// edge length to the next (the walk's own noise allowance is 3 %), and the default's figures
/// are only a proxy of the chosen sharpening's.
const FINALIST_WINDOW: f64 = 1.05;

/// What a later sharpening candidate or refinement must beat the score before it by: more
/// than the sampling noise of a measurement (about 0.3 % at 300 000 samples).
const SHARPEN_MARGIN: f64 = 0.995;

/// The planar-region projection's tolerance, in angle steps, that the encoder tries after
/// the best sharpening (`whet_sharpen::PlanarOptions::for_swing`; docs/swing.md section 2):
/// 2: of 0.6, 1, 1.5, 2 and 3 on the 48 swing rows of the sharpening figures (`planar_sweep`
/// in whet-sharpen), 2 and 3 gained the most, and below 1 the 6-bit rows gained less
/// (docs/results.md).
pub const PLANAR_FACTOR: f64 = 2.0;

/// The local quadric projection's move limit, in angle steps, that the encoder tries after
/// the best sharpening and the planar projection (`whet_sharpen::QuadricOptions::for_swing`;
/// docs/swing.md section 2): a quarter step, about the RMS of the angle quantization's
/// offset of a swing tip (a uniform error over one step has an RMS of 0.29 steps), so that
/// a fit never moves a vertex much farther than its noise. Of 0.125, 0.25, 0.35, 0.5, 1 and
/// 2 steps on the 42 sharpened swing rows of the sharpening figures (`quadric_sweep` in
/// whet-sharpen), 0.25 gained the most where it was kept (docs/results.md, "Local quadric
/// projection").
pub const QUADRIC_FACTOR: f64 = 0.25;

/// The one-sided quadric projection's move limit, in angle steps, that the encoder tries
/// after the local quadric projection (`whet_sharpen::BesideOptions::for_swing`;
/// docs/swing.md section 2): a quarter step, as the local quadric projection's. Of 0.1,
/// 0.15, 0.25, 0.35, 0.5 and 1 steps on the 42 sharpened swing rows of the sharpening
/// figures (`beside_sweep` in whet-sharpen), 0.25 gained the most (docs/results.md,
/// "One-sided quadric projection").
pub const BESIDE_FACTOR: f64 = 0.25;

/// The crease projection's move limit, in mean edge lengths, that the encoder tries after
/// the other projections (`whet_sharpen::CreaseOptions`; docs/swing.md section 2): the
/// crease vertices' errors come from the sharpener's plane intersections as much as from
/// the angle quantization, so the limit is not in angle steps. Of 0.1, 0.25, 0.35, 0.5,
/// 0.75 and 1 on the 42 sharpened swing rows of the sharpening figures (`crease_sweep` in
/// whet-sharpen), 0.5 gained the most and raised no row's max (docs/results.md, "Crease
/// projection").
pub const CREASE_MOVE: f64 = 0.5;

/// The apex restoration's move limit, in mean edge lengths, that the encoder tries after
/// every other projection (`whet_sharpen::ApexOptions`; docs/swing.md section 2): a uniform
/// retiling cuts a cone's tip or a corner by under an edge (0.6-1.1 edges on the synth
/// cone's swing streams), so 1.5 takes every cut and refuses fits gone far.
pub const APEX_MOVE: f64 = 1.5;

/// Options of [`SwingEncoder`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SwingOptions {
    /// The rate.
    pub rate: Rate,
    /// Swing angle bits.
    pub angle_bits: u32,
    /// Bits per coordinate of the seeds (and of explicit geometry).
    pub quant_bits: u32,
    /// Relative tolerance of the size searches (the issue asks for 5 %).
    pub tolerance: f64,
    /// Most retilings a search may run.
    pub max_iterations: u32,
    /// Face samples per direction of the Metro measurements of [`Rate::MaxError`].
    pub metro_samples: usize,
    /// Cut non-manifold input instead of refusing it.
    pub repair: bool,
    /// Container version to write.
    pub version: Version,
    /// Retiler constants.
    pub tuning: RetileTuning,
    /// Choose the angle bits too: with a size target, the quantization in
    /// [`SwingOptions::AUTO_ANGLE_BITS`] whose stream measures the lowest error; with an
    /// error target, the one with the smallest stream meeting it. Each candidate costs one
    /// rate search and one Metro measurement. Not available with a fixed edge length.
    pub auto_angle_bits: bool,
    /// What the error measurements (error targets, automatic angle bits) refer to.
    pub error_of: ErrorOf,
    /// Fit the decoder's surface filter to the original and write it into the stream
    /// (`whet_codec::surface_filter`; docs/swing.md section 2). Off, the stream carries no
    /// filter. Sharpening decodes without it either way, so [`ErrorOf::Sharpened`]
    /// measures the sharpened unfiltered mesh.
    pub surface_filter: bool,
    /// Let the surface filter be the extended one (five fields, format 1.4; docs/swing.md
    /// section 2, "Extended surface filter") where its fitted gain beats its header bytes.
    /// Off, streams keep the two-field filter: readable by whet before format 1.4, and
    /// about 5 % faster to decode.
    pub extended_filter: bool,
}

impl SwingOptions {
    /// Default angle bits (chosen by measurement on the fixtures: docs/results.md).
    pub const DEFAULT_ANGLE_BITS: u32 = 6;

    /// Range of the automatic angle-bit choice, which climbs from
    /// [`Self::DEFAULT_ANGLE_BITS`] while the measured error keeps falling (docs/results.md,
    /// "Angle bits": smooth meshes stay at 5-6, flat CAD parts climb to 9-12).
    pub const AUTO_ANGLE_BITS: std::ops::RangeInclusive<u32> = 4..=12;

    /// `L` = 1 % of the diagonal, default angle bits, 20-bit seeds, 5 % tolerance.
    pub const DEFAULT: SwingOptions = SwingOptions {
        rate: Rate::EdgeLength(0.01),
        angle_bits: Self::DEFAULT_ANGLE_BITS,
        quant_bits: 20,
        tolerance: 0.05,
        max_iterations: 12,
        metro_samples: 300_000,
        repair: true,
        version: Version::CURRENT,
        tuning: RetileTuning::DEFAULT,
        auto_angle_bits: false,
        error_of: ErrorOf::Decoded,
        surface_filter: true,
        extended_filter: true,
    };

    /// Sets the rate.
    pub const fn with_rate(mut self, rate: Rate) -> Self {
        self.rate = rate;
        self
    }

    /// Sets the angle bits.
    pub const fn with_angle_bits(mut self, bits: u32) -> Self {
        self.angle_bits = bits;
        self
    }

    /// Sets the seed quantization bits.
    pub const fn with_quant_bits(mut self, bits: u32) -> Self {
        self.quant_bits = bits;
        self
    }

    /// Sets the search tolerance.
    pub const fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }

    /// Sets the Metro samples of error searches.
    pub const fn with_metro_samples(mut self, samples: usize) -> Self {
        self.metro_samples = samples;
        self
    }

    /// Turns manifold repair on or off.
    pub const fn with_repair(mut self, repair: bool) -> Self {
        self.repair = repair;
        self
    }

    /// Turns the automatic angle-bit choice on or off.
    pub const fn with_auto_angle_bits(mut self, auto: bool) -> Self {
        self.auto_angle_bits = auto;
        self
    }

    /// Sets what error measurements refer to.
    pub const fn with_error_of(mut self, error_of: ErrorOf) -> Self {
        self.error_of = error_of;
        self
    }

    /// Turns the surface filter on or off.
    pub const fn with_surface_filter(mut self, on: bool) -> Self {
        self.surface_filter = on;
        self
    }

    /// Allows or forbids the extended surface filter ([`Self::extended_filter`]).
    pub const fn with_extended_filter(mut self, on: bool) -> Self {
        self.extended_filter = on;
        self
    }

    /// Sets the retiler constants.
    pub const fn with_tuning(mut self, tuning: RetileTuning) -> Self {
        self.tuning = tuning;
        self
    }
}

impl Default for SwingOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// One encoded stream and everything known about it.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct SwingOutput {
    /// The `.whet` bytes.
    pub bytes: Vec<u8>,
    /// Sizes and counts; `vertices` / `triangles` are the retiled mesh's.
    pub report: EncodeReport,
    /// The retiled mesh exactly as `whet_codec::decode(bytes)` returns it.
    pub retiled: Mesh,
    /// How the geometry was coded.
    pub geometry: SwingGeometry,
    /// The edge length used, absolute.
    pub edge_length: f64,
    /// The edge length as a fraction of the original's diagonal.
    pub edge_length_fraction: f64,
    /// Angle bits used.
    pub angle_bits: u32,
    /// Vertices of the original (after preparation).
    pub original_vertices: usize,
    /// Triangles of the original.
    pub original_triangles: usize,
    /// Retiler statistics.
    pub stats: RetileStats,
    /// Symmetric RMS error in % of the diagonal, when the encoder measured it.
    pub rms_pct: Option<f64>,
    /// The `(edge length fraction, bytes)` of every retiling the search ran.
    pub search: Vec<(f64, usize)>,
    /// The quantizations the automatic angle-bit choice tried (empty when off).
    pub angle_trials: Vec<AngleTrial>,
    /// The surface filter the stream carries ([`SurfaceFilter::NONE`]: none).
    pub surface_filter: SurfaceFilter,
    /// The surface filter for after EdgeSharpener carried in the stream (optional header
    /// fields 17 and 19; `SurfaceFilter::apply_after_sharpening`).
    pub sharpened_filter: SurfaceFilter,
    /// The sharpening the stream recommends to `whet decode --sharpen` (optional header
    /// field 21): chosen by measurement when [`SwingOptions::error_of`] is
    /// [`ErrorOf::Sharpened`], `None` otherwise.
    pub sharpen_hint: Option<SharpenHint>,
    /// The smooth factor that goes with [`Self::sharpen_hint`] (optional header field 23).
    pub sharpen_smooth_factor: Option<f64>,
    /// The curved-wall factor that goes with [`Self::sharpen_hint`] when on (optional header
    /// field 27; `None`: off).
    pub sharpen_curved_walls: Option<f64>,
    /// The EdgeSharpener passes that go with [`Self::sharpen_hint`] when more than one
    /// (optional header field 29).
    pub sharpen_passes: Option<u32>,
    /// The gray-vertex labels on surface samplings that go with [`Self::sharpen_hint`] when
    /// on (optional header field 41).
    pub sharpen_gray_labels: bool,
    /// The planar-region projection after sharpening the stream states (optional header
    /// field 25: its tolerance in angle steps), when the encoder measured it better.
    pub planar_factor: Option<f64>,
    /// The local quadric projection after those the stream states (optional header field
    /// 31: its move limit in angle steps), when the encoder measured it better.
    pub quadric_factor: Option<f64>,
    /// The one-sided quadric projection of the vertices beside creases after those the
    /// stream states (optional header field 37: its move limit in angle steps), when the
    /// encoder measured it better.
    pub beside_factor: Option<f64>,
    /// The crease projection after those the stream states (optional header field 35: its
    /// move limit in mean edge lengths), when the encoder measured it better.
    pub crease_factor: Option<f64>,
    /// The apex restoration after those the stream states (optional header field 39: its
    /// move limit in mean edge lengths), when the encoder measured it better.
    pub apex_factor: Option<f64>,
    /// The candidates of that choice with their measured symmetric RMS error (% of the
    /// diagonal; empty when no choice was made).
    pub sharpen_trials: Vec<SharpenTrial>,
    /// The symmetric max error (% of the diagonal) of the mesh those candidates sharpen (the
    /// decoded mesh without its surface filter): no sharpening whose max is over it is
    /// chosen. `None` when no choice was made.
    pub sharpen_input_max_pct: Option<f64>,
    /// The snaps of the stated sharpening (EdgeSharpener's default when the stream states
    /// none) that the encoder judged against the original, and which it vetoed: what header
    /// field 33 states when one or more was vetoed and the field was written (see
    /// `SwingEncoder::encode`; a size-searched stream leaves it out rather than miss its
    /// target, and a part where most snaps were vetoed states no sharpening instead; a
    /// stream for the sharpened output keeps them only where they buy more error than they
    /// cost bytes). `None` when no judgement was made or its vetoes were left out.
    pub snap_vetoes: Option<SnapVetoes>,
    /// How far the original's surface strays from the retiling, in units of `L`: the
    /// largest distance of a sample of the original's vertices, outside the components
    /// coded as pillows, to the retiled mesh (see `MAX_COVERAGE_GAP`); infinite when a
    /// distance could not be computed (counted as uncovered), 0 for an empty retiling.
    pub coverage_gap: f64,
}

impl SwingOutput {
    /// Whole-stream bits per original vertex.
    pub fn bits_per_original_vertex(&self) -> f64 {
        if self.original_vertices == 0 {
            0.0
        } else {
            self.bytes.len() as f64 * 8.0 / self.original_vertices as f64
        }
    }

    /// Fraction of retiled vertices with exactly six incident triangles.
    pub fn valence6_fraction(&self) -> f64 {
        valence6_fraction(&self.retiled)
    }
}

/// Fraction of the vertices of `mesh` with exactly six incident triangles.
pub fn valence6_fraction(mesh: &Mesh) -> f64 {
    let mut deg = vec![0u32; mesh.positions.len()];
    for t in &mesh.triangles {
        for &v in t {
            if let Some(d) = deg.get_mut(v as usize) {
                *d += 1;
            }
        }
    }
    if deg.is_empty() {
        return 0.0;
    }
    deg.iter().filter(|&&d| d == 6).count() as f64 / deg.len() as f64
}

/// The box of the seeds' quantization grid: the mesh's bounding box rounded outward to
/// binary32 coordinates, which the stream states in 24 bytes instead of 48 (docs/format.md,
/// tag 32); the mesh's own box when it is beyond the f32 range. The grid moves by about
/// 1e-7 of the box, far below its step.
fn seed_box(mesh: &Mesh) -> whet_mesh::Aabb {
    let b = mesh.bounding_box();
    match whet_format::box_f32_outward(b.min.to_array(), b.max.to_array()) {
        Some((min, max)) => whet_mesh::Aabb {
            min: whet_mesh::DVec3::from_array(min),
            max: whet_mesh::DVec3::from_array(max),
        },
        None => b,
    }
}

/// A retiler that got stuck on a surface that is not orientable (a Möbius strip, a Klein
/// bottle, or a part whose triangles face both ways across an edge) says so: the repair
/// oriented it by cutting it open, but the two sides of the cut still touch, and the retiler,
/// which follows the surface by its geometry, walks across the cut onto the side facing the
/// other way, where no swing closes. Other errors pass through unchanged.
fn explain_stuck(e: Error, mesh: &Mesh) -> Error {
    match e {
        Error::Stuck(why) => match orientation_seams(mesh) {
            0 => Error::Stuck(why),
            n => Error::InvalidInput(format!(
                "the surface is not orientable: orienting it cut {n} edge{} whose two sides \
                 still touch and face opposite ways, and the retiler cannot grow across such a \
                 seam ({why}); --mode exact codes it",
                if n == 1 { "" } else { "s" }
            )),
        },
        e => e,
    }
}

/// Boundary edges of `mesh` (an oriented manifold) that run the same way as another boundary
/// edge between the same two positions: the two sides of an edge that was cut to orient the
/// surface. A hole's boundary, or two surfaces that merely touch with their orientations
/// agreeing, run opposite ways and do not count.
fn orientation_seams(mesh: &Mesh) -> usize {
    use std::collections::{HashMap, HashSet};
    let key = |p: whet_mesh::DVec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let directed: HashSet<(u32, u32)> = mesh
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .collect();
    let mut by_position: HashMap<([u64; 3], [u64; 3]), usize> = HashMap::new();
    for &(u, v) in &directed {
        if !directed.contains(&(v, u)) {
            let ends = (
                key(mesh.positions[u as usize]),
                key(mesh.positions[v as usize]),
            );
            *by_position.entry(ends).or_default() += 1;
        }
    }
    by_position.values().filter(|&&n| n >= 2).count()
}

/// Encodes meshes in the swing mode with fixed options.
#[derive(Clone, Debug, Default)]
pub struct SwingEncoder {
    opts: SwingOptions,
}

struct Prepared {
    mesh: Mesh,
    /// The original's BVH for judging snaps (`crate::snap_judge`), built on first use.
    bvh: std::sync::OnceLock<whet_metro::Bvh>,
    repair: whet_mesh::ManifoldRepair,
    dropped: usize,
    diagonal: f64,
    area: f64,
}

impl SwingEncoder {
    /// An encoder with `opts`.
    pub fn new(opts: SwingOptions) -> Self {
        SwingEncoder { opts }
    }

    /// The options.
    pub fn options(&self) -> &SwingOptions {
        &self.opts
    }

    /// Encodes `mesh`.
    pub fn encode(&self, mesh: &Mesh) -> Result<SwingOutput, Error> {
        let o = &self.opts;
        if !(whet_codec::swing::MIN_ANGLE_BITS..=whet_codec::swing::MAX_ANGLE_BITS)
            .contains(&o.angle_bits)
        {
            return Err(Error::Parameter(format!(
                "angle bits must be {}..={}, got {}",
                whet_codec::swing::MIN_ANGLE_BITS,
                whet_codec::swing::MAX_ANGLE_BITS,
                o.angle_bits
            )));
        }
        let p = prepare_mesh(mesh, o.repair)?;
        if p.mesh.triangles.is_empty() {
            return Err(Error::InvalidInput(
                "the mesh has no triangles: there is no surface to retile".into(),
            ));
        }
        let diagonal = p.mesh.diagonal();
        if diagonal.is_nan() || diagonal <= 0.0 {
            return Err(Error::InvalidInput(
                "the mesh has no extent (all vertices coincide, or its size underflows)".into(),
            ));
        }
        // Lengths, areas and the seed grid are all measured against the diagonal.
        if diagonal.is_infinite() || !p.mesh.area().is_finite() {
            return Err(Error::InvalidInput(format!(
                "the mesh is too large to retile: its bounding-box diagonal or area overflows \
                 (diagonal {diagonal:e}); scale it down, or use --mode exact"
            )));
        }
        let prep = Prepared {
            bvh: std::sync::OnceLock::new(),
            area: p.mesh.area(),
            diagonal,
            repair: p.repair,
            dropped: p.dropped_unused_vertices,
            mesh: p.mesh,
        };
        let out = if o.auto_angle_bits {
            self.encode_auto_angle_bits(&prep)
        } else {
            self.encode_prepared(&prep).map(|out| (out, None))
        };
        let (out, finalist) = out.map_err(|e| explain_stuck(e, &prep.mesh))?;
        if o.error_of == ErrorOf::Sharpened {
            return self.choose_sharpening_of_finalists(&prep, out, finalist);
        }
        self.veto_default_sharpening(&prep, out)
    }

    /// The sharpening chosen for `out`, and for the automatic angle bits' `finalist` when
    /// there is one (the quantization whose measure came within [`FINALIST_WINDOW`] of
    /// `out`'s): whichever of the two ends better by the margin is written. The automatic
    /// choice measures each quantization with EdgeSharpener's default, while the stream
    /// states the sharpening and projections measured best for it; near a tie the default's
    /// figures do not say which quantization ends better (partLp at 5.2 bpv: 6 and 7 bits
    /// within 3 % with the default, 20 % apart in RMS at the end).
    fn choose_sharpening_of_finalists(
        &self,
        prep: &Prepared,
        out: SwingOutput,
        finalist: Option<SwingOutput>,
    ) -> Result<SwingOutput, Error> {
        // The two choices are independent: run side by side, so that each one's serial
        // work (sharpening, projections) overlaps the other's (Metro runs on every core
        // either way). The same result, and the same first error, as one after the other.
        let (chosen, other) = match finalist {
            Some(f) => {
                let (a, b) = rayon::join(
                    || self.choose_sharpening(prep, out),
                    || self.choose_sharpening(prep, f),
                );
                (a?, Some(b?))
            }
            None => (self.choose_sharpening(prep, out)?, None),
        };
        let (mut chosen, trial) = chosen;
        let ended = |trials: &mut Vec<AngleTrial>, bits: u32, t: &SharpenTrial| {
            if let Some(a) = trials.iter_mut().find(|a| a.angle_bits == bits) {
                a.sharpened = Some((t.rms_pct, t.max_pct));
            }
        };
        let mut trials = std::mem::take(&mut chosen.angle_trials);
        ended(&mut trials, chosen.angle_bits, &trial);
        if let Some((other, other_trial)) = other {
            ended(&mut trials, other.angle_bits, &other_trial);
            if other_trial.score() < SHARPEN_MARGIN * trial.score() {
                let search = std::mem::take(&mut chosen.search);
                chosen = other;
                chosen.search = search;
            }
        }
        chosen.angle_trials = trials;
        Ok(chosen)
    }

    /// A stream encoded for the decoded output states no sharpening, so `whet decode
    /// --sharpen` runs EdgeSharpener's default on it: the snaps of that run that the
    /// original says are worse than no snap (a fillet about an edge wide sharpened into a
    /// corner) are vetoed in field 33 (docs/sharpen.md, "Snap vetoes"). The field is left
    /// out when nothing is vetoed, and when its bytes would take a size-searched stream past
    /// the search's tolerance.
    fn veto_default_sharpening(
        &self,
        prep: &Prepared,
        out: SwingOutput,
    ) -> Result<SwingOutput, Error> {
        let input = unfiltered(&out)?;
        let (_, v) = crate::snap_judge::sharpen_judged(
            &prep.mesh,
            &prep.bvh,
            &input,
            &whet_sharpen::SharpenOptions::DEFAULT,
        );
        drop(input);
        let mut out = out;
        out.snap_vetoes = Some(v.clone());
        if v.vetoed() == 0 {
            return Ok(out);
        }
        if !vetoes_fit(&out, &v) {
            // More snaps than a reader accepts (not seen on any mesh): no field.
            out.snap_vetoes = None;
            return Ok(out);
        }
        let target = match self.opts.rate {
            Rate::BitsPerVertex(r) => Some(r * prep.mesh.positions.len() as f64 / 8.0),
            Rate::TargetBytes(n) => Some(n as f64),
            Rate::EdgeLength(_) | Rate::MaxError(_) => None,
        };
        // Where most snaps are worse than none, the part has no crease the sharpener finds
        // right (fertility's rounded base at L = 0.96 %: 123 of 155 vetoed): the stream
        // states no sharpening (two bytes), as a stream encoded for the sharpened output
        // would after measuring; the plain decoded mesh keeps its surface filter.
        let vetoed = if 2 * v.vetoed() > v.judged() {
            restate_hint(out.clone(), SharpenHint::Unsharpened)?
        } else {
            restate_vetoes(out.clone(), &v)?
        };
        match target {
            Some(t) if vetoed.bytes.len() as f64 > t * (1.0 + self.opts.tolerance) => {
                out.snap_vetoes = None;
                Ok(out)
            }
            _ => Ok(vetoed),
        }
    }

    /// Which sharpening `whet decode --sharpen` should run on `out`'s stream, measured
    /// against the original (docs/swing.md section 2, "Which sharpening"): EdgeSharpener's
    /// extended or papers' method at smooth factors 2, 1.5 and 1, or none. The classes a
    /// decoder-side rule must tell apart overlap (the extended method's rules for surface
    /// samplings keep organic parts from getting worse and refuse some CAD snaps the papers'
    /// method makes; rocker_arm's blends get worse under the papers' method; a lower smooth
    /// factor finds more chamfers on coarse CAD retilings, whose curved faces raise the mean
    /// normal angle), while the encoder holds the original and can simply measure. The
    /// candidates after the first cost one more retiling at the same length (with a filter
    /// for after sharpening fitted on each candidate's output) and one Metro measurement
    /// each.
    fn choose_sharpening(
        &self,
        prep: &Prepared,
        out: SwingOutput,
    ) -> Result<(SwingOutput, SharpenTrial), Error> {
        // A candidate's score must beat the ones before it (the default first, no
        // sharpening last) by SHARPEN_MARGIN.
        // (method, smooth factor, curved-wall factor; `None`: off). The sharpenings with
        // curved walls come after the others, and every sharpening in two passes after all of
        // them in one, so that each extension is chosen only where it beats what comes before
        // it by the margin.
        const W: Option<f64> = Some(CURVED_WALL_FACTOR);
        const SHARPENINGS: [(SharpenHint, f64, Option<f64>); 12] = [
            (SharpenHint::Extended, DEFAULT_SMOOTH_FACTOR, None),
            (SharpenHint::Papers, DEFAULT_SMOOTH_FACTOR, None),
            (SharpenHint::Extended, 1.5, None),
            (SharpenHint::Papers, 1.5, None),
            (SharpenHint::Extended, 1.0, None),
            (SharpenHint::Papers, 1.0, None),
            (SharpenHint::Extended, DEFAULT_SMOOTH_FACTOR, W),
            (SharpenHint::Papers, DEFAULT_SMOOTH_FACTOR, W),
            (SharpenHint::Extended, 1.5, W),
            (SharpenHint::Papers, 1.5, W),
            (SharpenHint::Extended, 1.0, W),
            (SharpenHint::Papers, 1.0, W),
        ];
        let candidates: Vec<Candidate> = [1, TWO_PASSES]
            .into_iter()
            .flat_map(|passes| {
                SHARPENINGS.map(|(hint, smooth_factor, curved_walls)| Candidate {
                    hint: Some(hint),
                    smooth_factor,
                    curved_walls,
                    passes,
                    gray_labels: false,
                })
            })
            .collect();
        let fraction = out.edge_length_fraction;
        // The candidates are retiled at `out`'s angle bits (the automatic choice's, when on).
        let at_bits = SwingEncoder::new(
            self.opts
                .with_angle_bits(out.angle_bits)
                .with_auto_angle_bits(false),
        );
        let streams = match at_bits.encode_at_for(prep, fraction, &candidates[1..]) {
            // The same retiling (the retiler is deterministic); only the hint and the filter
            // for after sharpening differ.
            Ok(s) if s.first().is_some_and(|p| p.retiled == out.retiled) => s,
            // Should the retiling differ after all, or the retiler get stuck where it did
            // not before, only the default is measured against no sharpening.
            Ok(_) | Err(Error::Stuck(_)) => Vec::new(),
            Err(e) => return Err(e),
        }
        .into_iter();
        let mut trials = Vec::new();
        let mut best: Option<(SharpenTrial, Option<SwingOutput>)> = None;
        // And the best of each method (extended, papers, extended with gray labels) by the
        // same rule: the runners-up's.
        let mut best_of: [Option<(SharpenTrial, Option<SwingOutput>)>; 3] = [None, None, None];
        // Sharpening must not make a case worse (the issue's "no case gets worse", RMS or
        // max): the score (RMS weighted by the max, `MAX_ERROR_WEIGHT`) decides among the
        // candidates whose max stays within that of the mesh they sharpen and whose RMS stays
        // within that of the plain decoded mesh (no sharpening). Without the second bound the
        // score took a 19 % lower max for a 7 % higher RMS on screwdriver at 12 bpv (docs/rd).
        // Every candidate's stream decodes, without its surface filter, to this same mesh
        // (they differ in header fields only): decoded once for all of them.
        let input = unfiltered(&out)?.into_owned();
        let input_max = self.measure_mesh(prep, &input, &mut Vec::new())?.1;
        let opts = whet_sharpen::SharpenOptions::DEFAULT;
        let (decoded, decoded_max) =
            self.measure_figures(prep, &out, ErrorOf::Decoded, &opts, &mut Vec::new())?;
        let none = SharpenTrial {
            hint: SharpenHint::Unsharpened,
            smooth_factor: DEFAULT_SMOOTH_FACTOR,
            curved_walls: 0.0,
            passes: 1,
            gray_labels: false,
            rms_pct: decoded,
            max_pct: decoded_max,
            planar: false,
            quadric: false,
            beside: false,
            crease: false,
            apex: false,
            sharpened_filter: true,
            runner_up: false,
        };
        // Candidates whose output is the same mesh (curved walls that turn no edge smooth, a
        // second pass that changes nothing) are measured once.
        let mut measured = Vec::new();
        // A candidate takes the place of the best so far when it keeps the max within the
        // input's and the RMS within no sharpening's, and beats it by the margin.
        let improves = |t: &SharpenTrial, best: &Option<(SharpenTrial, Option<SwingOutput>)>| {
            t.max_pct <= input_max
                && t.rms_pct <= none.rms_pct
                && best
                    .as_ref()
                    .is_none_or(|(b, _)| t.score() < SHARPEN_MARGIN * b.score())
        };
        // `out` was encoded for the first candidate; the others have their streams (as far as
        // they go).
        let streams: Vec<SwingOutput> = streams.collect();
        let jobs: Vec<(&SwingOutput, whet_sharpen::SharpenOptions)> = std::iter::once(&out)
            .chain(&streams)
            .zip(candidates.iter().map(Candidate::sharpen_options))
            .collect();
        let figures = self.measure_sharpened_each(prep, &jobs, &input, &mut measured)?;
        drop(jobs);
        let streams = std::iter::once(None).chain(streams.into_iter().map(Some));
        for ((c, figures), stream) in candidates.iter().zip(figures).zip(streams) {
            let trial = c.trial(figures);
            trials.push(trial);
            let slot = &mut best_of[method_slot(&trial)];
            if improves(&trial, slot) {
                *slot = Some((trial, stream.clone()));
            }
            if improves(&trial, &best) {
                best = Some((trial, stream));
            }
        }
        // Then the grid refined around its best: the smooth factor a quarter up and down,
        // and with curved walls the wall factor one up and one down (docs/swing.md section
        // 2, "Which sharpening": the best of the grid is often between its points, and the
        // two factors interact). Each must beat the best so far by the margin, as above.
        if let Some(centre) = best.as_ref().map(|(b, _)| *b) {
            let refined = refinements(&centre);
            let streams = match at_bits.encode_at_for(prep, fraction, &refined) {
                Ok(s) if s.first().is_some_and(|p| p.retiled == out.retiled) => s,
                Ok(_) | Err(Error::Stuck(_)) => Vec::new(),
                Err(e) => return Err(e),
            };
            let jobs: Vec<(&SwingOutput, whet_sharpen::SharpenOptions)> = streams
                .iter()
                .zip(refined.iter().map(Candidate::sharpen_options))
                .collect();
            let figures = self.measure_sharpened_each(prep, &jobs, &input, &mut measured)?;
            drop(jobs);
            for ((c, p), figures) in refined.iter().zip(streams).zip(figures) {
                let trial = c.trial(figures);
                trials.push(trial);
                let slot = &mut best_of[method_slot(&trial)];
                if improves(&trial, slot) {
                    *slot = Some((trial, Some(p.clone())));
                }
                if improves(&trial, &best) {
                    best = Some((trial, Some(p)));
                }
            }
        }
        // Then the extended method's best with the gray vertices of surface samplings
        // labelled too (docs/swing.md section 2, "Gray labels"): a chamfer two triangles
        // wide is cut only so, a blend a few samples wide is sharpened so, and only the
        // original tells which the stream holds. It has a slot of its own only when it beats
        // the extended best by the margin (else it would hide the extended best from the
        // runners-up). After the refinement, which it would otherwise draw away from the
        // sharpenings it refines (a smooth factor a quarter above the grid's, missed so,
        // cost the swing-decoded synth torus-box a max 2.7 times higher). Its field's three
        // bytes must leave room for the projections' under a size target, as the vetoes'
        // must.
        if let Some((ext, _)) = best_of[EXTENDED_SLOT].as_ref() {
            let gray = Candidate {
                hint: Some(SharpenHint::Extended),
                smooth_factor: ext.smooth_factor,
                curved_walls: (ext.curved_walls > 0.0).then_some(ext.curved_walls),
                passes: ext.passes,
                gray_labels: true,
            };
            let stream = match at_bits.encode_at_for(prep, fraction, &[gray]) {
                Ok(s) => s.into_iter().next().filter(|p| {
                    p.retiled == out.retiled
                        && self.below_size_ceiling(prep, p.bytes.len() + PROJECTION_FIELD_BYTES)
                }),
                Err(Error::Stuck(_)) => None,
                Err(e) => return Err(e),
            };
            if let Some(p) = stream {
                let opts = gray.sharpen_options();
                let (figures, _) =
                    self.measure_sharpened(prep, &p, &input, &opts, &mut measured, false)?;
                let trial = gray.trial(figures);
                trials.push(trial);
                if improves(&trial, &best_of[EXTENDED_SLOT]) {
                    best_of[method_slot(&trial)] = Some((trial, Some(p.clone())));
                }
                if improves(&trial, &best) {
                    best = Some((trial, Some(p)));
                }
            }
        }
        trials.push(none);
        let decision = match best {
            Some((b, s)) if none.score() >= SHARPEN_MARGIN * b.score() => (b, s),
            _ => (none, None),
        };
        // The runners-up: the best sharpening of each other slot (method, and gray labels
        // for the extended one). The grid measures each sharpening before the vetoes and
        // the projections, which then change the methods' outputs differently (on the
        // swing-decoded cad_bracket at 3.5 bpv the extended method with the papers' factors
        // and the projections ended 49 % lower in score than the papers' chosen path), so
        // each is taken through them too, in slot order, and chosen when it ends better
        // than the path standing by the margin.
        let runners_up: Vec<_> = match decision.0.hint {
            SharpenHint::Unsharpened => Vec::new(),
            _ => {
                let own = method_slot(&decision.0);
                (0..best_of.len())
                    .filter(|&k| k != own)
                    .filter_map(|k| best_of[k].take())
                    .collect()
            }
        };
        let spares: Vec<SwingOutput> = runners_up.iter().map(|_| out.clone()).collect();
        let (mut chosen, mut chosen_trial) = self.finish_sharpening(
            prep,
            out,
            decision,
            &input,
            (input_max, none),
            &mut trials,
            false,
        )?;
        for (candidate, out) in runners_up.into_iter().zip(spares) {
            let (other, other_trial) = self.finish_sharpening(
                prep,
                out,
                candidate,
                &input,
                (input_max, none),
                &mut trials,
                true,
            )?;
            if other_trial.score() < SHARPEN_MARGIN * chosen_trial.score() {
                chosen = other;
                chosen_trial = other_trial;
            }
        }
        chosen.sharpen_trials = trials;
        chosen.sharpen_input_max_pct = Some(input_max);
        Ok((chosen, chosen_trial))
    }

    /// The rest of [`Self::choose_sharpening`] for one sharpening (`decision`: its measured
    /// trial and its candidate stream, `None` for `out`'s own): its vetoes, then the
    /// projections with and without the filter for after sharpening, within the bounds of
    /// the input's max and no sharpening's trial (`none`). Every trial goes to `trials` (flagged
    /// [`SharpenTrial::runner_up`] on a runner-up's path); returns the stream and the
    /// trial that stand.
    #[allow(clippy::too_many_arguments)]
    fn finish_sharpening(
        &self,
        prep: &Prepared,
        out: SwingOutput,
        decision: (SharpenTrial, Option<SwingOutput>),
        input: &Mesh,
        (input_max, none): (f64, SharpenTrial),
        trials: &mut Vec<SharpenTrial>,
        runner_up: bool,
    ) -> Result<(SwingOutput, SharpenTrial), Error> {
        let first = trials.len();
        let (mut chosen_trial, stream) = decision;
        let mut chosen = match stream {
            Some(mut p) => {
                // The searches' records stay those of the search that found the rate.
                p.search = out.search;
                p.angle_trials = out.angle_trials;
                p
            }
            None if chosen_trial.hint == SharpenHint::Unsharpened => {
                restate_hint(out, SharpenHint::Unsharpened)?
            }
            None => out,
        };
        let chosen_opts = Candidate {
            hint: Some(chosen_trial.hint),
            smooth_factor: chosen_trial.smooth_factor,
            curved_walls: Some(chosen_trial.curved_walls),
            passes: chosen_trial.passes,
            gray_labels: chosen_trial.gray_labels,
        }
        .sharpen_options();
        // Then the chosen sharpening judged against the original (docs/sharpen.md, "Snap
        // vetoes"): its vetoes go into the stream when they buy more than they cost, a
        // relative RMS gain over the relative growth of the stream (RMS falls about as
        // 1 / bytes along a swing curve), without raising the max or the RMS over their
        // bounds. The candidates are compared without vetoes: judging each and keeping the
        // winner's flags whatever they cost made docs/rd pay 1-4 % more bytes on partLp,
        // sharp_sphere and the smooth parts at high rates for the same error.
        let mut judged = false;
        let mut vetoes = None;
        if chosen_trial.hint != SharpenHint::Unsharpened {
            let ((rms, max), v) =
                self.measure_sharpened(prep, &chosen, input, &chosen_opts, &mut Vec::new(), true)?;
            if v.vetoed() > 0 && vetoes_fit(&chosen, &v) {
                let with = restate_vetoes(chosen.clone(), &v)?;
                let judged_trial = SharpenTrial {
                    rms_pct: rms,
                    max_pct: max,
                    ..chosen_trial
                };
                let gain = chosen_trial.rms_pct / rms - 1.0;
                let cost = with.bytes.len() as f64 / chosen.bytes.len() as f64 - 1.0;
                // The vetoes' bytes are not in the search's reserve (their count varies):
                // with the projections' fields still to come, they must fit under a size
                // target's upper bound.
                if gain > cost
                    && max <= input_max
                    && rms <= none.rms_pct
                    && judged_trial.score() < chosen_trial.score()
                    && self.below_size_ceiling(prep, with.bytes.len() + PROJECTION_FIELD_BYTES)
                {
                    // The record shows the chosen candidate as its stream is written (the
                    // runner-up's grid record stays, and its judged one is added).
                    if runner_up {
                        trials.push(judged_trial);
                    } else if let Some(t) = trials.iter_mut().find(|t| **t == chosen_trial) {
                        *t = judged_trial;
                    }
                    chosen = with;
                    chosen_trial = judged_trial;
                    judged = true;
                }
            }
            vetoes = Some(v);
        }
        chosen.rms_pct = Some(chosen_trial.rms_pct);
        chosen.snap_vetoes = vetoes.filter(|_| judged);
        let mut standing = chosen_trial;
        if chosen_trial.hint != SharpenHint::Unsharpened {
            let bounds = TrialBounds {
                max: input_max.max(chosen_trial.max_pct),
                rms: none.rms_pct,
            };
            let (mut with, mut with_trial) = self.project_after_sharpening(
                prep,
                (chosen.clone(), chosen_trial),
                input,
                &chosen_opts,
                judged,
                bounds,
                trials,
            )?;
            // The filter for after sharpening is fitted on the sharpened mesh alone, before
            // the projections, which then move many of the vertices it moved: on CAD parts
            // the projections did better without it (docs/results.md, "The filter for after
            // sharpening under the projections"). So the chosen sharpening is tried without
            // the filter too, then with the projections on that, and the better of the two
            // ends wins by the margin.
            let bare = if chosen.sharpened_filter.is_none() {
                None
            } else {
                // A size target's lower bound still holds without the fields' bytes (a
                // small stream can land near it), or the filter stays.
                Some(restate_without_sharpened_filter(chosen)?)
                    .filter(|b| self.above_size_floor(prep, b.bytes.len()))
            };
            if let Some(bare) = bare {
                let ((rms, max), _) = self.measure_sharpened(
                    prep,
                    &bare,
                    input,
                    &chosen_opts,
                    &mut Vec::new(),
                    judged,
                )?;
                let bare_trial = SharpenTrial {
                    rms_pct: rms,
                    max_pct: max,
                    sharpened_filter: false,
                    ..chosen_trial
                };
                trials.push(bare_trial);
                let (without, without_trial) = self.project_after_sharpening(
                    prep,
                    (bare, bare_trial),
                    input,
                    &chosen_opts,
                    judged,
                    bounds,
                    trials,
                )?;
                if without_trial.score() < SHARPEN_MARGIN * with_trial.score()
                    && bounds.admit(&without_trial)
                {
                    with = without;
                    with.rms_pct = Some(without_trial.rms_pct);
                    with_trial = without_trial;
                }
            }
            chosen = with;
            standing = with_trial;
        }
        for t in &mut trials[first..] {
            t.runner_up = runner_up;
        }
        Ok((chosen, standing))
    }

    /// Whether a stream of `bytes` is not under the lower bound of the options' size target
    /// (`--bpv`, `--target-bytes`: the target less the tolerance); true without one.
    fn above_size_floor(&self, prep: &Prepared, bytes: usize) -> bool {
        let target = match self.size_target(prep) {
            Some(t) => t,
            None => return true,
        };
        bytes as f64 >= (1.0 - self.opts.tolerance) * target.max(1.0)
    }

    /// Whether a stream of `bytes` stays within a size target's upper bound (always without
    /// a size target).
    fn below_size_ceiling(&self, prep: &Prepared, bytes: usize) -> bool {
        self.size_target(prep)
            .is_none_or(|t| bytes as f64 <= (1.0 + self.opts.tolerance) * t.max(1.0))
    }

    /// The stream size a size-targeted rate asks for, in bytes; `None` for other rates.
    fn size_target(&self, prep: &Prepared) -> Option<f64> {
        match self.opts.rate {
            Rate::BitsPerVertex(r) => Some((r * prep.mesh.positions.len() as f64 / 8.0).round()),
            Rate::TargetBytes(n) => Some(n as f64),
            Rate::EdgeLength(_) | Rate::MaxError(_) => None,
        }
    }

    /// The projections after sharpening tried on `start` (a stream stating a sharpening and
    /// its measured trial), each kept when it beats what it refines by the margin within
    /// `bounds`: first the planar one (the flat faces' quantization noise, which the
    /// sharpener leaves), then the local quadric one (that of the curved faces), the
    /// one-sided one (that of the faces beside creases), the crease one and the apex
    /// restoration (docs/swing.md section 2). Every trial goes to `trials`; returns the
    /// stream and trial that stand.
    #[allow(clippy::too_many_arguments)]
    fn project_after_sharpening(
        &self,
        prep: &Prepared,
        start: (SwingOutput, SharpenTrial),
        input: &Mesh,
        opts: &whet_sharpen::SharpenOptions,
        judged: bool,
        bounds: TrialBounds,
        trials: &mut Vec<SharpenTrial>,
    ) -> Result<(SwingOutput, SharpenTrial), Error> {
        let (mut chosen, mut current) = start;
        let restated: [fn(SwingOutput) -> Result<SwingOutput, Error>; 5] = [
            |o| restate_planar(o, PLANAR_FACTOR),
            |o| restate_quadric(o, QUADRIC_FACTOR),
            |o| restate_beside(o, BESIDE_FACTOR),
            |o| restate_crease(o, CREASE_MOVE),
            |o| restate_apex(o, APEX_MOVE),
        ];
        for (k, restate) in restated.iter().enumerate() {
            let projected = restate(chosen.clone())?;
            let ((rms, max), _) =
                self.measure_sharpened(prep, &projected, input, opts, &mut Vec::new(), judged)?;
            let trial = SharpenTrial {
                rms_pct: rms,
                max_pct: max,
                planar: current.planar || k == 0,
                quadric: current.quadric || k == 1,
                beside: current.beside || k == 2,
                crease: current.crease || k == 3,
                apex: k == 4,
                ..current
            };
            trials.push(trial);
            if trial.score() < SHARPEN_MARGIN * current.score() && bounds.admit(&trial) {
                chosen = projected;
                chosen.rms_pct = Some(rms);
                current = trial;
            }
        }
        Ok((chosen, current))
    }

    /// Encodes a prepared mesh at the options' angle bits.
    fn encode_prepared(&self, prep: &Prepared) -> Result<SwingOutput, Error> {
        let o = &self.opts;
        match o.rate {
            Rate::EdgeLength(f) => {
                if !(f > 0.0 && f.is_finite()) {
                    return Err(Error::Parameter(format!(
                        "the edge length must be a positive fraction of the diagonal, got {f}"
                    )));
                }
                let mut out = self.encode_near(prep, f)?;
                out.search = vec![(out.edge_length_fraction, out.bytes.len())];
                Ok(out)
            }
            Rate::BitsPerVertex(r) => {
                if !(r > 0.0 && r.is_finite()) {
                    return Err(Error::Parameter(format!(
                        "bits per vertex must be positive, got {r}"
                    )));
                }
                let target = (r * prep.mesh.positions.len() as f64 / 8.0).round() as usize;
                self.search_bytes(prep, target.max(1), None)
            }
            Rate::TargetBytes(n) => {
                if n == 0 {
                    return Err(Error::Parameter("the target size must be positive".into()));
                }
                self.search_bytes(prep, n, None)
            }
            Rate::MaxError(e) => {
                if !(e > 0.0 && e.is_finite()) {
                    return Err(Error::Parameter(format!(
                        "the error target must be a positive percentage, got {e}"
                    )));
                }
                self.search_error(prep, e)
            }
        }
    }

    /// The automatic angle-bit choice: every candidate quantization runs the rate (or error)
    /// search, and the stream with the lowest measured error (for the sharpened output
    /// `rms · max^MAX_ERROR_WEIGHT`, with EdgeSharpener's default), or the smallest one
    /// meeting the error target, wins; for the sharpened output the runner-up within
    /// [`FINALIST_WINDOW`] comes back too, as the finalist whose sharpening is also chosen.
    /// Flat regions predict their swing angles almost exactly, so extra bits cost little
    /// there and pay off after sharpening; curved ones pay for every bit: which wins depends
    /// on the mesh and the rate, hence a measurement, not a rule.
    fn encode_auto_angle_bits(
        &self,
        prep: &Prepared,
    ) -> Result<(SwingOutput, Option<SwingOutput>), Error> {
        let o = self.opts;
        if let Rate::EdgeLength(_) = o.rate {
            return Err(Error::Parameter(
                "automatic angle bits need a size or error target (bits per vertex, bytes or \
                 an RMS error), not a fixed edge length"
                    .into(),
            ));
        }
        let by_error = matches!(o.rate, Rate::MaxError(_));
        let mut trials = Vec::new();
        let mut search = Vec::new();
        let mut hint: Option<f64> = None;
        let mut last_err = None;
        // One candidate: its stream and score (bytes for an error target, error otherwise).
        let mut run = |bits: u32| -> Result<Option<(f64, SwingOutput)>, Error> {
            let enc = SwingEncoder::new(o.with_angle_bits(bits).with_auto_angle_bits(false));
            let result = match o.rate {
                Rate::BitsPerVertex(r) if r > 0.0 && r.is_finite() => {
                    let target = (r * prep.mesh.positions.len() as f64 / 8.0).round() as usize;
                    enc.search_bytes(prep, target.max(1), hint)
                }
                Rate::TargetBytes(n) if n > 0 => enc.search_bytes(prep, n, hint),
                _ => enc.encode_prepared(prep),
            };
            let mut out = match result {
                Ok(out) => out,
                Err(e @ (Error::Unreachable(_) | Error::Stuck(_))) => {
                    trials.push(AngleTrial {
                        angle_bits: bits,
                        edge_length_fraction: f64::NAN,
                        bytes: 0,
                        rms_pct: None,
                        max_pct: None,
                        sharpened: None,
                    });
                    last_err = Some(e);
                    return Ok(None);
                }
                Err(e) => return Err(e),
            };
            hint = Some(out.edge_length_fraction);
            search.extend_from_slice(&out.search);
            let (rms, max) = match out.rms_pct {
                Some(r) => (r, None),
                None => {
                    let opts = whet_sharpen::SharpenOptions::DEFAULT;
                    let (r, m) =
                        enc.measure_figures(prep, &out, o.error_of, &opts, &mut Vec::new())?;
                    (r, Some(m))
                }
            };
            out.rms_pct = Some(rms);
            trials.push(AngleTrial {
                angle_bits: bits,
                edge_length_fraction: out.edge_length_fraction,
                bytes: out.bytes.len(),
                rms_pct: Some(rms),
                max_pct: max,
                sharpened: None,
            });
            // For the sharpened output the score its sharpening is chosen by (the max error
            // counts too: `MAX_ERROR_WEIGHT`), so that the bits and the sharpening weigh the
            // two errors alike; for the decoded one the RMS.
            let score = match max {
                _ if by_error => out.bytes.len() as f64,
                Some(m) if o.error_of == ErrorOf::Sharpened => {
                    rms * m.max(0.0).powf(MAX_ERROR_WEIGHT)
                }
                _ => rms,
            };
            Ok(Some((score, out)))
        };
        // Hill climb from the default: upwards while the score improves, then downwards
        // while it beats the best of both. Scores are noisy by a few % from one L to the
        // next, so one worse step ends a direction only when it is worse by more than
        // that. Both directions are walked: a noisy gain one bit up must not hide a real
        // one below (sharp_sphere at 0.5 bpv, sharpened, climbed to 7 bits on a 5 % step,
        // 0.71 %, while 4 bits measure 0.48 %).
        const NOISE: f64 = 1.03;
        let range = SwingOptions::AUTO_ANGLE_BITS;
        let start = SwingOptions::DEFAULT_ANGLE_BITS;
        let mut best: Option<(f64, SwingOutput)> = run(start)?;
        // The best of the others, the finalist's candidate.
        let mut second: Option<(f64, SwingOutput)> = None;
        let keep_second = |c: (f64, SwingOutput), second: &mut Option<(f64, SwingOutput)>| {
            if second.as_ref().is_none_or(|s| c.0 < s.0) {
                *second = Some(c);
            }
        };
        for dir in [1i32, -1] {
            let mut bits = start;
            let mut misses = 0;
            loop {
                let next = bits as i32 + dir;
                if next < *range.start() as i32 || next > *range.end() as i32 {
                    break;
                }
                bits = next as u32;
                let Some((score, out)) = run(bits)? else {
                    break;
                };
                let best_score = best.as_ref().map_or(f64::INFINITY, |b| b.0);
                if score < best_score {
                    if let Some(old) = best.replace((score, out)) {
                        keep_second(old, &mut second);
                    }
                    misses = 0;
                } else {
                    keep_second((score, out), &mut second);
                    misses += 1;
                    if score > best_score * NOISE || misses >= 2 {
                        break;
                    }
                }
            }
        }
        let Some((best_score, mut out)) = best else {
            return Err(
                last_err.unwrap_or_else(|| Error::Stuck("no angle quantization worked".into()))
            );
        };
        out.search = search;
        out.angle_trials = trials;
        let finalist = second
            .filter(|(score, _)| {
                o.error_of == ErrorOf::Sharpened
                    && !by_error
                    && *score <= FINALIST_WINDOW * best_score
            })
            .map(|(_, f)| f);
        Ok((out, finalist))
    }

    /// Retiles and encodes at edge length `fraction · diagonal`. Streams optimised for
    /// sharpening carry a sharpening hint (extended until [`Self::choose_sharpening`] has
    /// measured the others), so that the size searches count its four or five bytes.
    fn encode_at(&self, prep: &Prepared, fraction: f64) -> Result<SwingOutput, Error> {
        let hint = (self.opts.error_of == ErrorOf::Sharpened).then_some(SharpenHint::Extended);
        let only = Candidate {
            hint,
            smooth_factor: DEFAULT_SMOOTH_FACTOR,
            curved_walls: None,
            passes: 1,
            gray_labels: false,
        };
        let mut outs = self.encode_at_for(prep, fraction, &[only])?;
        outs.pop()
            .ok_or_else(|| Error::Internal("a retiling gave no stream".into()))
    }

    /// [`Self::encode_at`] once per candidate sharpening, from one retiling:
    /// each stream states its candidate and carries the filter for after sharpening fitted
    /// for that sharpening (extended at factor 2 without a hint).
    fn encode_at_for(
        &self,
        prep: &Prepared,
        fraction: f64,
        candidates: &[Candidate],
    ) -> Result<Vec<SwingOutput>, Error> {
        let o = &self.opts;
        let l = fraction * prep.diagonal;
        let params = SwingParams::new(l, o.angle_bits, &seed_box(&prep.mesh), o.quant_bits)?;
        let sharpen: Vec<_> = candidates.iter().map(Candidate::sharpen_options).collect();
        // The extended filter serves the decoded output: it goes into the streams whose
        // decoded mesh is what the encoder optimizes (all of them for the decoded output;
        // with --optimize-for sharpened, only those stating no sharpening, whose decoded
        // mesh is their sharpened one: the others sharpen the unfiltered vertices, and its
        // bytes would buy nothing there). Fitted only when some candidate can use it.
        let extended_for = |c: &Candidate| {
            o.error_of == ErrorOf::Decoded || c.hint == Some(SharpenHint::Unsharpened)
        };
        let fit = if !o.surface_filter {
            FilterFits::None
        } else if o.extended_filter && candidates.iter().any(extended_for) {
            FilterFits::Extended
        } else {
            FilterFits::Basic
        };
        let retiled = retile_fitted(&prep.mesh, &params, &o.tuning, fit, &sharpen)?;
        let mut outs = Vec::with_capacity(candidates.len());
        // The same decoded mesh for every candidate (they differ in header fields only).
        let mut coverage = None;
        // The decoded filter of those streams: the extended one where half its fitted gain
        // beats the bytes its three header fields add, decided on the first such stream
        // (the fields and their bytes are the same in every candidate's).
        let extended = retiled
            .extended_filter
            .filter(|&(_, ratio)| ratio < 1.0 && !retiled.filter.is_none());
        let mut use_extended: Option<bool> = None;
        for (c, &sharpened_filter) in candidates.iter().zip(&retiled.sharpened_filters) {
            // What the stream cannot state, a decoder would not reproduce.
            let walls_ok = c
                .curved_walls
                .is_none_or(|w| SharpenHint::curved_walls_code(w).is_some());
            if !walls_ok || !SharpenHint::PASSES.contains(&u64::from(c.passes)) {
                return Err(Error::Internal(format!(
                    "a sharpening candidate the stream cannot state: {c:?}"
                )));
            }
            let ext = extended.filter(|_| extended_for(c));
            let mut info = SwingStreamInfo {
                version: o.version,
                repair: &prep.repair,
                dropped_unused_vertices: prep.dropped,
                filter: match (ext, use_extended) {
                    (Some((f, _)), Some(true)) => f,
                    _ => retiled.filter,
                },
                sharpened_filter,
                sharpen_hint: c.hint,
                // Always written with a hint, so that the size searches count its bytes (the
                // default's 200 hundredths take two, as 150 does; 100 takes one).
                sharpen_smooth_factor: c.hint.map(|_| c.smooth_factor),
                sharpen_curved_walls: c.hint.and(c.curved_walls),
                sharpen_passes: c.hint.and((c.passes > 1).then_some(c.passes)),
                sharpen_gray_labels: c.hint.is_some() && c.gray_labels,
            };
            let mut enc: SwingEncoded = encode_retiled(&retiled.mesh, &params, &info)?;
            if let (Some((ext, ratio)), None) = (ext, use_extended) {
                let with_ext = SwingStreamInfo {
                    filter: ext,
                    ..info
                };
                // A try: if its stream fails, the two-field one stands.
                let mut better = false;
                if let Ok(enc_ext) = encode_retiled(&retiled.mesh, &params, &with_ext) {
                    let growth = enc_ext.bytes.len() as f64 / enc.bytes.len() as f64 - 1.0;
                    // Half the fitted gain against the growth (RMS falls about as fast as
                    // the bytes grow at these rates): the fit is forward and linearised,
                    // and measured with Metro it delivers its gain on smooth meshes but
                    // less on sharp ones (sharp_sphere at 1 bpv: fitted 1.6 %, measured
                    // −2.5 %; docs/results.md, "Extended surface filter").
                    if 1.0 - ratio > 2.0 * growth {
                        better = true;
                        info = with_ext;
                        enc = enc_ext;
                    }
                }
                use_extended = Some(better);
            }
            let coverage_gap = *coverage.get_or_insert_with(|| {
                coverage_gap(&prep.mesh, &retiled.pillowed_vertices, &enc.decoded, l)
            });
            outs.push(SwingOutput {
                coverage_gap,
                bytes: enc.bytes,
                report: enc.report,
                retiled: enc.decoded,
                geometry: enc.geometry,
                edge_length: l,
                edge_length_fraction: fraction,
                angle_bits: o.angle_bits,
                original_vertices: prep.mesh.positions.len(),
                original_triangles: prep.mesh.triangles.len(),
                stats: retiled.stats.clone(),
                rms_pct: None,
                search: Vec::new(),
                angle_trials: Vec::new(),
                surface_filter: info.filter,
                sharpened_filter: info.sharpened_filter,
                sharpen_hint: c.hint,
                sharpen_smooth_factor: info.sharpen_smooth_factor,
                sharpen_curved_walls: info.sharpen_curved_walls,
                sharpen_passes: info.sharpen_passes,
                sharpen_gray_labels: info.sharpen_gray_labels,
                planar_factor: None,
                quadric_factor: None,
                beside_factor: None,
                crease_factor: None,
                apex_factor: None,
                sharpen_trials: Vec::new(),
                sharpen_input_max_pct: None,
                snap_vetoes: None,
            });
        }
        Ok(outs)
    }

    /// [`Self::encode_at`], retrying at slightly different lengths when the retiler gets
    /// stuck (a rare configuration at one `L` is usually absent at the next; shorter lengths
    /// resolve thin parts better, so the retries lean that way).
    fn encode_near(&self, prep: &Prepared, fraction: f64) -> Result<SwingOutput, Error> {
        const FACTORS: [f64; 8] = [1.0, 0.985, 1.015, 0.96, 0.93, 0.9, 0.85, 0.8];
        let floor = self.min_fraction(prep);
        let mut last = None;
        // The retiling with the smallest coverage gap among those over the bound.
        let mut gapped: Option<(f64, SwingOutput)> = None;
        for k in FACTORS {
            // A retry never goes under the retiling size limit (the first try reports it).
            if k != 1.0 && fraction * k < floor {
                continue;
            }
            match self.encode_at(prep, fraction * k) {
                Ok(out) => {
                    let gap = out.coverage_gap;
                    if gap <= MAX_COVERAGE_GAP {
                        return Ok(out);
                    }
                    if gapped.as_ref().is_none_or(|(g, _)| gap < *g) {
                        gapped = Some((gap, out));
                    }
                }
                Err(e @ (Error::Stuck(_) | Error::Internal(_))) => last = Some(e),
                // A retry that fails otherwise (a shorter retry past the size limit on a
                // mesh whose capped holes add area) keeps the gapped retiling found before.
                Err(e) => match gapped {
                    Some((_, out)) => return Ok(out),
                    None => return Err(e),
                },
            }
        }
        if let Some((_, out)) = gapped {
            return Ok(out);
        }
        Err(last.unwrap_or_else(|| Error::Stuck("no retiling succeeded".into())))
    }

    /// The shortest edge-length fraction the retiler accepts on `prep`
    /// ([`RetileTuning::max_triangles`] by the area law of the original, before any hole
    /// is capped), a hair above: the searches stay at
    /// or above it, so a target out of reach ends the search with the best stream found.
    fn min_fraction(&self, prep: &Prepared) -> f64 {
        let max = self.opts.tuning.max_triangles.max(1) as f64;
        // And 2^-19 of the diagonal, the finest length the retiler's grid indexes.
        let by_area = (2.4 * prep.area / max).sqrt() / prep.diagonal;
        by_area.max(1.0 / (1u64 << 19) as f64) * (1.0 + 1e-9)
    }

    /// First guess of the edge-length fraction for a stream of `bytes`: `T' ≈ 2.4 A / L²`
    /// retiled triangles at about 3.5 bits each.
    fn guess_fraction(prep: &Prepared, bytes: usize) -> f64 {
        let bits = (bytes as f64 * 8.0 - 400.0).max(64.0);
        let l = (2.4 * prep.area * 3.5 / bits).sqrt();
        (l / prep.diagonal).clamp(1e-4, 0.5)
    }

    /// Secant search on `log L` for a stream of `target` bytes (within the tolerance),
    /// starting from `start` (an edge length fraction) when given.
    fn search_bytes(
        &self,
        prep: &Prepared,
        target: usize,
        start: Option<f64>,
    ) -> Result<SwingOutput, Error> {
        let tol = self.opts.tolerance;
        let late = match self.opts.error_of {
            ErrorOf::Sharpened => LATE_FIELD_BYTES,
            ErrorOf::Decoded => 0,
        };
        let goal = (target as f64).ln();
        let mut search = Vec::new();
        let mut best: Option<SwingOutput> = None;
        let mut prev: Option<(f64, f64)> = None; // (ln L, ln bytes)
        let floor = self.min_fraction(prep);
        let start = start.filter(|f| f.is_finite() && *f > 0.0);
        let guess = start.unwrap_or_else(|| Self::guess_fraction(prep, target));
        // A size the area law puts well past the retiling limit: refused before any work.
        if start.is_none() && guess < 0.5 * floor {
            return Err(crate::retiler::too_many_triangles(
                guess * prep.diagonal,
                prep.diagonal,
                prep.area,
                self.opts.tuning.max_triangles,
            ));
        }
        let mut f = guess.max(floor);
        let mut stuck: Option<Error> = None;
        let mut stuck_at: Vec<f64> = Vec::new();
        for _ in 0..self.opts.max_iterations.max(1) {
            let out = match self.encode_near(prep, f) {
                Ok(out) => out,
                Err(e @ Error::Stuck(_)) => {
                    // No retiling near this length: the front stalls on features of about
                    // L's size, which shorter lengths resolve. Go on a step shorter.
                    stuck = Some(e);
                    stuck_at.push(f);
                    match shorter_after_stuck(f, floor) {
                        Some(next) => {
                            f = outside_stuck(next, &stuck_at, floor);
                            continue;
                        }
                        None => break,
                    }
                }
                Err(e) => return Err(e),
            };
            let size = out.bytes.len();
            search.push((out.edge_length_fraction, size));
            let x = out.edge_length_fraction.ln();
            let y = (size as f64).ln();
            let err = (size as f64 / target as f64 - 1.0).abs();
            let better = best
                .as_ref()
                .is_none_or(|b| err < (b.bytes.len() as f64 / target as f64 - 1.0).abs());
            if better {
                best = Some(out);
            }
            // Within the tolerance with room for the header fields the sharpening choice
            // adds after the search, so that the final stream is within it too.
            let low = (1.0 - tol) * target as f64;
            let high = (1.0 + tol) * target as f64;
            if size as f64 >= low && (size + late) as f64 <= high {
                break;
            }
            // Slope of ln(bytes) against ln(L): -2 in theory; measured once two points exist.
            let slope = match prev {
                Some((px, py)) if (x - px).abs() > 1e-9 => ((y - py) / (x - px)).clamp(-4.0, -0.5),
                _ => -2.0,
            };
            prev = Some((x, y));
            let nx = x + (goal - y) / slope;
            // Damp jumps: at most a factor 3 per step.
            let next = nx.clamp(x - 1.1, x + 1.1).exp().clamp(1e-5, 0.7);
            // Past the size limit: the target is out of reach, the best stream stands.
            if next < floor && f <= floor {
                break;
            }
            let next = outside_stuck(next.max(floor), &stuck_at, floor);
            // The same length again gives the same stream (the clamps above can pin it).
            // Once the retiler got stuck the sizes jump between nearby lengths, and the
            // skipped ranges can send the search back to where it was: a length within a
            // thousandth of one tried then ends it too.
            let revisits = !stuck_at.is_empty()
                && search
                    .iter()
                    .any(|&(tried, _)| (next / tried - 1.0).abs() < 1e-3);
            if next == f || revisits {
                break;
            }
            f = next;
        }
        let mut out = match best {
            Some(out) => out,
            None => {
                return Err(
                    stuck.unwrap_or_else(|| Error::Stuck("the size search ran no retiling".into()))
                )
            }
        };
        out.search = search;
        Ok(out)
    }

    /// Measures the symmetric RMS error of `out` (decoded, or sharpened: [`ErrorOf`])
    /// against the original, in % of its diagonal.
    fn measure(&self, prep: &Prepared, out: &SwingOutput) -> Result<f64, Error> {
        let opts = whet_sharpen::SharpenOptions::DEFAULT;
        self.measure_as(prep, out, self.opts.error_of, &opts)
    }

    /// [`Self::measure`] of `error_of`, sharpening with `sharpen`.
    fn measure_as(
        &self,
        prep: &Prepared,
        out: &SwingOutput,
        error_of: ErrorOf,
        sharpen: &whet_sharpen::SharpenOptions,
    ) -> Result<f64, Error> {
        Ok(self
            .measure_figures(prep, out, error_of, sharpen, &mut Vec::new())?
            .0)
    }

    /// [`Self::measure_as`] with the max error too: `(rms, max)` in % of the diagonal.
    /// `measured` holds the figures of meshes measured before, by [`mesh_key`]: a mesh found
    /// there is not measured again.
    fn measure_figures(
        &self,
        prep: &Prepared,
        out: &SwingOutput,
        error_of: ErrorOf,
        sharpen: &whet_sharpen::SharpenOptions,
        measured: &mut Vec<(u64, (f64, f64))>,
    ) -> Result<(f64, f64), Error> {
        match error_of {
            ErrorOf::Decoded => self.measure_mesh(prep, &out.retiled, measured),
            ErrorOf::Sharpened => Ok(self
                .measure_sharpened(prep, out, &*unfiltered(out)?, sharpen, measured, false)?
                .0),
        }
    }

    /// [`Self::measure_figures`] of `whet decode --sharpen`'s output: `input`, `out`'s decoded
    /// mesh without its surface filter, sharpened, then the stream's filter for after
    /// sharpening and its planar and quadric projections.
    fn measure_sharpened(
        &self,
        prep: &Prepared,
        out: &SwingOutput,
        input: &Mesh,
        sharpen: &whet_sharpen::SharpenOptions,
        measured: &mut Vec<(u64, (f64, f64))>,
        judged: bool,
    ) -> Result<((f64, f64), SnapVetoes), Error> {
        // Judged against the original: the snaps that make it worse are vetoed, and the
        // stream that carries this sharpening carries the vetoes (field 33). Unjudged: what
        // a stream without the field decodes to.
        let (sharpened, vetoes) = if judged {
            crate::snap_judge::sharpen_judged(&prep.mesh, &prep.bvh, input, sharpen)
        } else {
            (
                whet_sharpen::sharpen(input, sharpen).ok(),
                SnapVetoes::default(),
            )
        };
        // A retiled mesh is a valid manifold; should the sharpener refuse one anyway, `whet
        // decode --sharpen` would fail the same way, and the decoded mesh is what the user
        // keeps.
        let sharpened = sharpened.map(|s| stated_output(out, input, s.mesh));
        let figures = self.measure_mesh(prep, sharpened.as_ref().unwrap_or(input), measured)?;
        Ok((figures, vetoes))
    }

    /// [`Self::measure_sharpened`], unjudged, of each `(stream, sharpening)` of `jobs` in
    /// turn: the same figures, and the same first error, as measuring them one after the
    /// other. The sharpenings of as many jobs as there are threads run side by side (that
    /// many meshes in memory at once), then the Metro measures of those not in `measured`
    /// (each mesh once): the sharpener is single-threaded, and side by side the sharpenings
    /// overlap one another's Metro work.
    fn measure_sharpened_each(
        &self,
        prep: &Prepared,
        jobs: &[(&SwingOutput, whet_sharpen::SharpenOptions)],
        input: &Mesh,
        measured: &mut Vec<(u64, (f64, f64))>,
    ) -> Result<Vec<(f64, f64)>, Error> {
        let mut figures = Vec::with_capacity(jobs.len());
        for group in jobs.chunks(rayon::current_num_threads().max(1)) {
            let meshes: Vec<Option<Mesh>> = group
                .par_iter()
                .map(|(out, opts)| {
                    whet_sharpen::sharpen(input, opts)
                        .ok()
                        .map(|s| stated_output(out, input, s.mesh))
                })
                .collect();
            let meshes: Vec<&Mesh> = meshes.iter().map(|m| m.as_ref().unwrap_or(input)).collect();
            let keys: Vec<u64> = meshes.iter().map(|m| mesh_key(m)).collect();
            // The meshes to measure: each key once, the first of its jobs, in job order.
            let mut fresh: Vec<usize> = Vec::new();
            for (k, key) in keys.iter().enumerate() {
                let seen = measured.iter().any(|(x, _)| x == key)
                    || fresh.iter().any(|&j| keys[j] == *key);
                if !seen {
                    fresh.push(k);
                }
            }
            let opts = MetroOptions::DEFAULT.with_samples(self.opts.metro_samples);
            let results: Vec<Result<(f64, f64), Error>> = fresh
                .par_iter()
                .map(|&k| {
                    let r = metro(&prep.mesh, meshes[k], &opts)?;
                    Ok((r.symmetric.rms_pct, r.symmetric.max_pct))
                })
                .collect();
            for (&k, r) in fresh.iter().zip(results) {
                measured.push((keys[k], r?));
            }
            for key in &keys {
                let f = measured.iter().find(|(x, _)| x == key).map(|(_, f)| *f);
                figures.push(f.ok_or_else(|| Error::Internal("a mesh left unmeasured".into()))?);
            }
        }
        Ok(figures)
    }

    /// The symmetric `(rms, max)` errors of `mesh` against the original, % of the diagonal;
    /// `measured` holds the figures of meshes measured before, by [`mesh_key`].
    fn measure_mesh(
        &self,
        prep: &Prepared,
        mesh: &Mesh,
        measured: &mut Vec<(u64, (f64, f64))>,
    ) -> Result<(f64, f64), Error> {
        let key = mesh_key(mesh);
        if let Some((_, f)) = measured.iter().find(|(k, _)| *k == key) {
            return Ok(*f);
        }
        let r = metro(
            &prep.mesh,
            mesh,
            &MetroOptions::DEFAULT.with_samples(self.opts.metro_samples),
        )?;
        let f = (r.symmetric.rms_pct, r.symmetric.max_pct);
        measured.push((key, f));
        Ok(f)
    }

    /// The cheapest stream found whose RMS error is at most `target` % of the diagonal.
    fn search_error(&self, prep: &Prepared, target: f64) -> Result<SwingOutput, Error> {
        let mut search = Vec::new();
        let mut best_ok: Option<SwingOutput> = None;
        let mut best_any: Option<SwingOutput> = None;
        // RMS ≈ c L² for flattening-dominated error; start from 1 % of the diagonal.
        let floor = self.min_fraction(prep);
        let mut f = 0.01f64.max(floor);
        let mut limited = false;
        let mut lo_ok = 0.0f64; // largest fraction known to meet the target
        let mut hi_bad = f64::INFINITY; // smallest fraction known to miss it
        let mut stuck: Option<Error> = None;
        let mut stuck_at: Vec<f64> = Vec::new();
        for _ in 0..self.opts.max_iterations.max(1) {
            let mut out = match self.encode_near(prep, f) {
                Ok(out) => out,
                Err(e @ Error::Stuck(_)) => {
                    // As in the size search: a shorter length resolves what stalled the
                    // front, and costs more bytes, never more error.
                    stuck = Some(e);
                    stuck_at.push(f);
                    hi_bad = hi_bad.min(f);
                    match shorter_after_stuck(f, floor) {
                        Some(next) if next > lo_ok => {
                            f = outside_stuck(next, &stuck_at, floor);
                            continue;
                        }
                        _ => break,
                    }
                }
                Err(e) => return Err(e),
            };
            let rms = self.measure(prep, &out)?;
            out.rms_pct = Some(rms);
            let fr = out.edge_length_fraction;
            search.push((fr, out.bytes.len()));
            let ok = rms <= target;
            if ok {
                lo_ok = lo_ok.max(fr);
                let cheaper = best_ok
                    .as_ref()
                    .is_none_or(|b| out.bytes.len() < b.bytes.len());
                // Close enough to the target: nothing much cheaper remains.
                let done = rms >= target * (1.0 - self.opts.tolerance);
                if cheaper {
                    best_ok = Some(out);
                }
                if done {
                    break;
                }
            } else {
                hi_bad = hi_bad.min(fr);
                let closer = best_any
                    .as_ref()
                    .is_none_or(|b| b.rms_pct.unwrap_or(f64::MAX) > rms);
                if closer {
                    best_any = Some(out);
                }
            }
            // Next guess from the L² law, kept inside the bracket.
            let mut next = fr * (target / rms).sqrt() * 0.98;
            if next >= hi_bad {
                next = if lo_ok > 0.0 {
                    (lo_ok * hi_bad).sqrt()
                } else {
                    hi_bad * 0.7
                };
            }
            if next <= lo_ok {
                next = if hi_bad.is_finite() {
                    (lo_ok * hi_bad).sqrt()
                } else {
                    lo_ok * 1.4
                };
            }
            if hi_bad.is_finite() && lo_ok > 0.0 && hi_bad / lo_ok < 1.02 {
                break;
            }
            let next = next.clamp(1e-5, 0.7);
            // The longest length allowed met the target: nothing coarser (and cheaper) is
            // left to try. (Without this a loose target re-encoded and re-measured the
            // same length until the iterations ran out: 12 s for `--max-error 50`.)
            if ok && next <= fr {
                break;
            }
            // Past the size limit: the target is out of reach (the law puts it well past
            // the limit, or the shortest length allowed was tried).
            if next < 0.5 * floor || (next < floor && f <= floor) {
                limited = true;
                break;
            }
            // Lengths a stuck attempt's retries covered are skipped; when that leaves nothing
            // between the longest good length and the shortest bad one, the search is over.
            let next = outside_stuck(next.max(floor), &stuck_at, floor);
            if !stuck_at.is_empty() && lo_ok > 0.0 && next <= lo_ok {
                break;
            }
            f = next;
        }
        let mut out = match best_ok {
            Some(o) => o,
            None if best_any.is_none() && stuck.is_some() => {
                return Err(stuck.unwrap_or_else(|| Error::Stuck(String::new())));
            }
            None => {
                let limit = if limited {
                    format!(
                        "; shorter lengths would need more than the limit of {} retiled \
                         triangles",
                        self.opts.tuning.max_triangles
                    )
                } else {
                    String::new()
                };
                let limit = match &stuck {
                    Some(e) => format!("{limit}; at some shorter lengths {e}"),
                    None => limit,
                };
                return Err(Error::Unreachable(format!(
                    "no edge length reached an RMS error of {target} % of the diagonal \
                     (best: {:.4} %){limit}",
                    best_any.and_then(|o| o.rms_pct).unwrap_or(f64::NAN)
                )));
            }
        };
        out.search = search;
        Ok(out)
    }
}

/// Most original vertices [`coverage_gap`] measures (evenly strided over the vertex list).
const COVERAGE_SAMPLES: usize = 20_000;

/// A retiling whose coverage gap ([`SwingOutput::coverage_gap`]) is larger than this many `L`
/// is retried at the next length of the encoder's retries; when no retry does better (every
/// length gaps more, a later one fails, or the remaining lengths are out of range) the
/// smallest gap is kept. `whet encode` warns past it. A
/// retiling bridges features narrower than `L` (the armadillo's fingers: 1-1.8 L from the
/// original at the coarsest rates) but never leaves more of the surface uncovered; measured on
/// every fixture at 0.3-8 bpv, all under 2.5 L but screwdriver at 1 and 2 bpv, whose thin
/// shaft the front wrapped wrongly (7.3 and 4.7 L, RMS 4.5 and 0.9 % of the diagonal).
pub const MAX_COVERAGE_GAP: f64 = 3.0;

/// How far the original's surface strays from the retiling `out`, in units of its `L`: the
/// largest distance of a sample of the original's vertices to the retiled mesh. Cheap (a
/// bounding-volume tree of the retiling and at most [`COVERAGE_SAMPLES`] queries) next to the
/// retiling itself.
fn coverage_gap(original: &Mesh, pillowed: &[bool], retiled: &Mesh, l: f64) -> f64 {
    if retiled.triangles.is_empty() || l.is_nan() || l <= 0.0 {
        return 0.0;
    }
    let bvh = whet_metro::Bvh::new(retiled);
    let stride = original.positions.len().div_ceil(COVERAGE_SAMPLES).max(1);
    let gap = original
        .positions
        .iter()
        .enumerate()
        .step_by(stride)
        .filter(|&(v, _)| !pillowed.get(v).copied().unwrap_or(false))
        .map(|(_, &p)| {
            // A NaN distance (no finite triangle) counts as uncovered.
            let d = bvh.closest_point(p).distance;
            if d.is_nan() {
                f64::INFINITY
            } else {
                d
            }
        })
        .fold(0.0f64, f64::max);
    gap / l
}

/// The next length a rate search tries after the retiler got stuck at fraction `f` (with
/// its retries down to 0.8 f): the next shorter step below those retries, not under the
/// shortest allowed length `floor`; `None` once `f` is there.
fn shorter_after_stuck(f: f64, floor: f64) -> Option<f64> {
    (f > floor).then(|| (0.75 * f).max(floor))
}

/// `f`, or if [`SwingEncoder::encode_near`] already got stuck around it (the lengths its
/// retries cover, 0.8 to 1.015 times a stuck length), the next length below them.
fn outside_stuck(mut f: f64, stuck_at: &[f64], floor: f64) -> f64 {
    // Each move goes below one more stuck length: at most one pass per stuck length.
    for _ in 0..=stuck_at.len() {
        match stuck_at.iter().find(|&&s| f >= 0.79 * s && f <= 1.02 * s) {
            Some(&s) => f = (0.78 * s).max(floor),
            None => break,
        }
    }
    f
}

/// Encodes `mesh` with `opts` (see [`SwingEncoder`]).
pub fn encode(mesh: &Mesh, opts: &SwingOptions) -> Result<SwingOutput, Error> {
    SwingEncoder::new(*opts).encode(mesh)
}

/// EdgeSharpener's default smooth factor (seed 000 section 3), what a stream without field
/// 23 is sharpened with.
const DEFAULT_SMOOTH_FACTOR: f64 = 2.0;

/// The curved-wall factor of the candidates with curved walls (docs/swing.md section 2).
pub const CURVED_WALL_FACTOR: f64 = whet_sharpen::DEFAULT_CURVED_WALL_FACTOR;

/// A 64-bit hash of a mesh's positions (bit for bit) and triangles: equal meshes have equal
/// keys, and two different meshes one with probability about 2^-64.
pub(crate) fn mesh_key(mesh: &Mesh) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    mesh.positions.len().hash(&mut h);
    for p in &mesh.positions {
        p.to_array().map(f64::to_bits).hash(&mut h);
    }
    mesh.triangles.hash(&mut h);
    h.finish()
}

/// `out`'s decoded mesh without its surface filter (what `whet decode --sharpen` sharpens).
fn unfiltered(out: &SwingOutput) -> Result<std::borrow::Cow<'_, Mesh>, Error> {
    if out.surface_filter.is_none() {
        return Ok(std::borrow::Cow::Borrowed(&out.retiled));
    }
    // Its own stream: trusted, so without the hostile-input limits.
    let opts = whet_codec::DecodeOptions::DEFAULT
        .with_surface_filter(false)
        .with_limits(whet_codec::Limits::UNLIMITED);
    Ok(std::borrow::Cow::Owned(whet_codec::decode(
        &out.bytes, &opts,
    )?))
}

/// The EdgeSharpener passes of the candidates in more than one pass: a third pass gains
/// about 1 % where the second gains up to 40 % (docs/results.md, "Passes").
pub const TWO_PASSES: u32 = 2;

/// A sharpening the encoder can state: the hint (field 21; `None`: no hint, the stream of a
/// plain encode), smooth factor (23), curved-wall factor (27; `None`: off) and
/// passes (29).
#[derive(Clone, Copy, Debug)]
struct Candidate {
    hint: Option<SharpenHint>,
    smooth_factor: f64,
    curved_walls: Option<f64>,
    passes: u32,
    gray_labels: bool,
}

impl Candidate {
    /// The sharpener options it stands for (extended for "none" and no hint: its filter
    /// for after sharpening is never applied).
    fn sharpen_options(&self) -> whet_sharpen::SharpenOptions {
        let method = match self.hint {
            Some(SharpenHint::Papers) => whet_sharpen::Method::Papers,
            _ => whet_sharpen::Method::Extended,
        };
        let opts = whet_sharpen::SharpenOptions::DEFAULT
            .with_method(method)
            .with_smooth_factor(self.smooth_factor)
            .with_passes(self.passes)
            .with_surface_gray_labels(self.gray_labels);
        match self.curved_walls {
            Some(w) => opts.with_curved_wall_factor(w),
            None => opts,
        }
    }

    /// Its record, from its measured `(RMS, max)` (% of the diagonal): unprojected, with
    /// its filter for after sharpening.
    fn trial(&self, (rms_pct, max_pct): (f64, f64)) -> SharpenTrial {
        let opts = self.sharpen_options();
        SharpenTrial {
            hint: self.hint.unwrap_or(SharpenHint::Extended),
            smooth_factor: self.smooth_factor,
            curved_walls: opts.curved_walls(),
            passes: opts.passes,
            gray_labels: self.gray_labels,
            rms_pct,
            max_pct,
            planar: false,
            quadric: false,
            beside: false,
            crease: false,
            apex: false,
            sharpened_filter: true,
            runner_up: false,
        }
    }
}

/// Index of a trial's sharpening among the runners-up's candidates: [`EXTENDED_SLOT`] for
/// the extended method, 1 for the papers', 2 for the extended method with gray labels (a
/// trial of no sharpening is never in a slot).
fn method_slot(trial: &SharpenTrial) -> usize {
    match (trial.hint, trial.gray_labels) {
        (SharpenHint::Papers, _) => 1,
        (_, true) => 2,
        _ => EXTENDED_SLOT,
    }
}

/// [`method_slot`] of the extended method without gray labels.
const EXTENDED_SLOT: usize = 0;

/// Step of the refinement of the chosen smooth factor (`refinements`).
const SMOOTH_FACTOR_STEP: f64 = 0.25;

/// Step of the refinement of the chosen curved-wall factor (`refinements`); the factors stay
/// within what a stream can state (1 to 4).
const CURVED_WALL_STEP: f64 = 1.0;

/// The sharpenings around `centre`, the best of the candidates' grid: the same method and
/// passes, the smooth factor `SMOOTH_FACTOR_STEP` up and down, and with curved walls each of
/// those with the wall factor `CURVED_WALL_STEP` up and down too (8 around a sharpening with
/// curved walls, 2 around one without); then `centre` in one more pass (the grid's are 1
/// or 2, so always one more candidate).
fn refinements(centre: &SharpenTrial) -> Vec<Candidate> {
    let s = centre.smooth_factor;
    let smooth = [s - SMOOTH_FACTOR_STEP, s, s + SMOOTH_FACTOR_STEP];
    let walls: Vec<Option<f64>> = if centre.curved_walls > 0.0 {
        let w = centre.curved_walls;
        [w - CURVED_WALL_STEP, w, w + CURVED_WALL_STEP]
            .into_iter()
            .filter(|&w| SharpenHint::curved_walls_code(w).is_some_and(|h| h > 0))
            .map(Some)
            .collect()
    } else {
        vec![None]
    };
    let mut out = Vec::new();
    for &smooth_factor in &smooth {
        for &curved_walls in &walls {
            let same = smooth_factor == s && curved_walls.unwrap_or(0.0) == centre.curved_walls;
            let stated = SharpenHint::smooth_factor_code(smooth_factor).is_some();
            if !same && stated {
                out.push(Candidate {
                    hint: Some(centre.hint),
                    smooth_factor,
                    curved_walls,
                    passes: centre.passes,
                    gray_labels: centre.gray_labels,
                });
            }
        }
    }
    // And the centre itself in one more pass: the sharpener run again on its own output
    // finds the chamfers its splits left (docs/results.md, "One more pass").
    let more = centre.passes + 1;
    if SharpenHint::PASSES.contains(&u64::from(more)) {
        out.push(Candidate {
            hint: Some(centre.hint),
            smooth_factor: s,
            curved_walls: (centre.curved_walls > 0.0).then_some(centre.curved_walls),
            passes: more,
            gray_labels: centre.gray_labels,
        });
    }
    out
}

/// What `whet decode --sharpen` makes of `sharpened`, the sharpener's output on `input`
/// (`out`'s decoded mesh without its surface filter): the stream's filter for after
/// sharpening, then its projections in the decoder's order.
fn stated_output(out: &SwingOutput, input: &Mesh, sharpened: Mesh) -> Mesh {
    let mut m = sharpened;
    out.sharpened_filter.apply_after_sharpening(input, &mut m);
    // The projections as the decoder reads them from the header
    // (`StatedSharpening`), in its order.
    let projections = [
        out.planar_factor.map(|factor| StatedProjection::Planar {
            factor,
            angle_bits: out.angle_bits,
        }),
        out.quadric_factor.map(|factor| StatedProjection::Quadric {
            factor,
            angle_bits: out.angle_bits,
        }),
        out.beside_factor.map(|factor| StatedProjection::Beside {
            factor,
            angle_bits: out.angle_bits,
        }),
        out.crease_factor
            .map(|max_move| StatedProjection::Crease { max_move }),
        out.apex_factor
            .map(|max_move| StatedProjection::Apex { max_move }),
    ];
    let projections: Vec<StatedProjection> = projections.into_iter().flatten().collect();
    // The sharpened mesh is a manifold; were it refused, the decoder keeps it unprojected too
    // (with a warning).
    let _ = StatedProjection::apply_all(&projections, &mut m);
    m
}

/// Most bytes the sharpening choice (`--optimize-for sharpened`) adds to the size search's
/// stream in fields of a fixed size: header fields 21 (method, 2 bytes), 23, 25, 27, 31, 35
/// and 37 (3 each), 29 (2), and up to 2 more for the filter after sharpening refitted for
/// the chosen sharpening. The snap vetoes (field 33, of a varying size) are checked against
/// the size target when chosen instead.
const LATE_FIELD_BYTES: usize = 24;

/// Bytes of the projections' fields (25, 31, 35 and 37, three each), stated after the snap
/// vetoes are chosen.
const PROJECTION_FIELD_BYTES: usize = 12;

/// `out` with header field 25 stating the planar-region projection at `factor` angle steps
/// (rounded to the field's hundredths, which is what a decoder reads). The field's three
/// bytes come after the size search, in the room it leaves ([`LATE_FIELD_BYTES`]).
fn restate_planar(mut out: SwingOutput, factor: f64) -> Result<SwingOutput, Error> {
    let code = SharpenHint::smooth_factor_code(factor)
        .ok_or_else(|| Error::Internal(format!("planar factor {factor} out of range")))?;
    out.bytes = with_header_field(&out.bytes, whet_format::tag::PLANAR_TOLERANCE, code)?;
    out.report.bytes = out.bytes.len();
    out.planar_factor = Some(code as f64 / 100.0);
    Ok(out)
}

/// `out` with header field 31 stating the local quadric projection at a move limit of
/// `factor` angle steps (rounded to the field's hundredths). Like field 25, its bytes come
/// after the size search.
fn restate_quadric(mut out: SwingOutput, factor: f64) -> Result<SwingOutput, Error> {
    let code = SharpenHint::smooth_factor_code(factor)
        .ok_or_else(|| Error::Internal(format!("quadric factor {factor} out of range")))?;
    out.bytes = with_header_field(&out.bytes, whet_format::tag::QUADRIC_PROJECTION, code)?;
    out.report.bytes = out.bytes.len();
    out.quadric_factor = Some(code as f64 / 100.0);
    Ok(out)
}

/// `out` with header field 37 stating the one-sided quadric projection beside creases at a
/// move limit of `factor` angle steps (rounded to the field's hundredths). Like field 25,
/// its bytes come after the size search.
fn restate_beside(mut out: SwingOutput, factor: f64) -> Result<SwingOutput, Error> {
    let code = SharpenHint::smooth_factor_code(factor)
        .ok_or_else(|| Error::Internal(format!("beside factor {factor} out of range")))?;
    out.bytes = with_header_field(&out.bytes, whet_format::tag::BESIDE_PROJECTION, code)?;
    out.report.bytes = out.bytes.len();
    out.beside_factor = Some(code as f64 / 100.0);
    Ok(out)
}

/// `out` with header field 35 stating the crease projection at a move limit of `max_move`
/// mean edge lengths (rounded to the field's hundredths). Like field 25, its bytes come
/// after the size search.
fn restate_crease(mut out: SwingOutput, max_move: f64) -> Result<SwingOutput, Error> {
    let code = SharpenHint::smooth_factor_code(max_move)
        .ok_or_else(|| Error::Internal(format!("crease move {max_move} out of range")))?;
    out.bytes = with_header_field(&out.bytes, whet_format::tag::CREASE_PROJECTION, code)?;
    out.report.bytes = out.bytes.len();
    out.crease_factor = Some(code as f64 / 100.0);
    Ok(out)
}

/// `out` with header field 39 stating the apex restoration at a move limit of `max_move`
/// mean edge lengths (rounded to the field's hundredths). Like field 25, its bytes come
/// after the size search.
fn restate_apex(mut out: SwingOutput, max_move: f64) -> Result<SwingOutput, Error> {
    let code = SharpenHint::smooth_factor_code(max_move)
        .ok_or_else(|| Error::Internal(format!("apex move {max_move} out of range")))?;
    out.bytes = with_header_field(&out.bytes, whet_format::tag::APEX_PROJECTION, code)?;
    out.report.bytes = out.bytes.len();
    out.apex_factor = Some(code as f64 / 100.0);
    Ok(out)
}

/// `out` without header fields 17 and 19 (no surface filter for after sharpening); the
/// stream shrinks by their bytes.
fn restate_without_sharpened_filter(mut out: SwingOutput) -> Result<SwingOutput, Error> {
    out.bytes = with_header(&out.bytes, |mut h| {
        h.remove(whet_format::tag::SHARPENED_FILTER_NORMAL);
        h.remove(whet_format::tag::SHARPENED_FILTER_SMOOTHED);
        h
    })?;
    out.report.bytes = out.bytes.len();
    out.sharpened_filter = SurfaceFilter::NONE;
    Ok(out)
}

/// What a refinement of the chosen sharpening (a projection, the filter left out) must stay
/// within to be kept: the max of the mesh it sharpens or of the chosen sharpening, and the
/// RMS of no sharpening.
#[derive(Clone, Copy, Debug)]
struct TrialBounds {
    max: f64,
    rms: f64,
}

impl TrialBounds {
    fn admit(&self, t: &SharpenTrial) -> bool {
        t.max_pct <= self.max && t.rms_pct <= self.rms
    }
}

/// Whether `out`'s stream can state `vetoes` ([`SnapVetoes::max_snaps`] of its counts).
fn vetoes_fit(out: &SwingOutput, vetoes: &SnapVetoes) -> bool {
    vetoes.judged() as u64
        <= SnapVetoes::max_snaps(out.report.vertices as u64, out.report.triangles as u64)
}

/// `out` with header field 33 stating `vetoes` for the sharpening its stream states.
fn restate_vetoes(mut out: SwingOutput, vetoes: &SnapVetoes) -> Result<SwingOutput, Error> {
    out.bytes = with_header_field(&out.bytes, whet_format::tag::SNAP_VETOES, vetoes.to_field())?;
    out.report.bytes = out.bytes.len();
    out.snap_vetoes = Some(vetoes.clone());
    Ok(out)
}

/// `out` with its stream's sharpening hint changed to `hint` (the field's value is one byte
/// whatever the hint, so the size does not change).
fn restate_hint(mut out: SwingOutput, hint: SharpenHint) -> Result<SwingOutput, Error> {
    out.bytes = with_header_field(&out.bytes, whet_format::tag::SHARPEN_METHOD, hint.code())?;
    out.report.bytes = out.bytes.len();
    out.sharpen_hint = Some(hint);
    Ok(out)
}

/// The encoder's own stream `bytes` with header field `tag` set to `value` (the payload is
/// copied unchanged; the container's checksums are recomputed).
fn with_header_field(
    bytes: &[u8],
    tag: u64,
    value: impl Into<whet_format::HeaderValue>,
) -> Result<Vec<u8>, Error> {
    with_header(bytes, |h| h.with(tag, value))
}

/// The encoder's own stream `bytes` with its header changed by `edit` (the payload is
/// copied unchanged; the container's checksums are recomputed).
fn with_header(
    bytes: &[u8],
    edit: impl FnOnce(whet_format::Header) -> whet_format::Header,
) -> Result<Vec<u8>, Error> {
    let mut container = whet_format::parse(bytes, &whet_codec::Limits::UNLIMITED)
        .map_err(whet_codec::Error::from)?;
    container.header = edit(container.header.clone());
    Ok(container.to_bytes().map_err(whet_codec::Error::from)?)
}

#[cfg(test)]
mod stuck_search_tests {
    use super::{outside_stuck, shorter_after_stuck};

    fn near(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn after_a_stuck_length_the_search_goes_shorter_down_to_the_floor() {
        assert!(near(shorter_after_stuck(0.1, 0.01).unwrap(), 0.075));
        assert!(near(shorter_after_stuck(0.012, 0.01).unwrap(), 0.01));
        assert_eq!(shorter_after_stuck(0.01, 0.01), None);
    }

    #[test]
    fn lengths_the_retries_of_a_stuck_length_covered_are_skipped() {
        // 0.1 got stuck: its retries covered 0.08 to 0.1015.
        assert!(near(outside_stuck(0.09, &[0.1], 0.001), 0.078));
        assert!(near(outside_stuck(0.07, &[0.1], 0.001), 0.07));
        assert!(near(outside_stuck(0.11, &[0.1], 0.001), 0.11));
        // A move below one stuck length that lands in another's range moves on below it.
        assert!(near(outside_stuck(0.1, &[0.1, 0.08], 0.001), 0.78 * 0.08));
        // Never under the floor.
        assert!(near(outside_stuck(0.1, &[0.1], 0.09), 0.09));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use whet_testkit::meshes::{grid, union};

    #[test]
    fn only_the_cut_of_an_orientation_counts_as_a_seam() {
        // A border, and two grids touching along a border with agreeing orientations
        // (their border edges there run opposite ways): no seam.
        assert_eq!(orientation_seams(&grid(4, 3)), 0);
        assert_eq!(orientation_seams(&union(grid(4, 3), &grid(4, 3), 4.0)), 0);
        // The same two grids with the second one flipped: the shared border now runs the
        // same way on both sides, as the cut of a twist does (the 3 edges along x = 4).
        let mut flipped = grid(4, 3);
        for t in &mut flipped.triangles {
            t.swap(1, 2);
        }
        assert_eq!(orientation_seams(&union(grid(4, 3), &flipped, 4.0)), 3);
    }
}
