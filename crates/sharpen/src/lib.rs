//! whet-sharpen owns EdgeSharpener (Attene et al., SGP 2003 and ACM TOG 2005): it finds the
//! chamfers that feature-insensitive sampling (marching cubes, scanners, the SwingWrapper
//! retiler) cuts through sharp edges and corners, subdivides them, and snaps the new vertices
//! onto the intersections of planes extending the smooth surfaces around them, then tags the
//! sharp edges for Bender. [`sharpen`] takes an oriented manifold [`Mesh`] and returns the
//! sharpened mesh, the [`SharpTags`] and a [`SharpenReport`]; input vertices keep their indices
//! and, outside the chamfers, their exact coordinates. [`Method::Papers`] is the papers'
//! algorithm alone, [`Method::Extended`] (the default) adds whet's extended chamfer detection.
//! [`Method::NormalFilter`] is the normal-filtering sharpener of seed 002 (fillets, chamfers
//! with samples, noisy creases; [`sharpen_region`] limits it to a [`VertexSelection`]).
//! [`flatten_planar_regions`] moves the vertices inside a decoded mesh's flat faces onto
//! their fitted planes (the swing decoder's quantization noise, which sharpening leaves);
//! [`project_onto_local_quadrics`] does the same for curved faces, vertex by vertex,
//! [`project_beside_creases_onto_local_quadrics`] for the face vertices beside a crease
//! (from their own side only), and [`project_creases_onto_local_quadrics`] moves the vertices on crease lines onto the
//! intersection of the quadrics fitted to their two sides; [`restore_apexes`] moves the
//! vertex nearest a cut cone tip or corner onto the point where the tangent planes around
//! it meet.
//! See `docs/sharpen.md` for the rules and the degenerate cases.
//!
//! ```
//! use whet_sharpen::{sharpen, SharpenOptions};
//! use whet_synth::{marching_cubes, Shape, ShapeKind, ShapeParams};
//!
//! // A marching-cubes cube has chamfered edges and corners.
//! let cube = Shape::new(ShapeKind::Cube, &ShapeParams::default()).unwrap();
//! let chamfered = marching_cubes(&cube, 16).unwrap();
//! let out = sharpen(&chamfered, &SharpenOptions::DEFAULT).unwrap();
//! assert!(out.report.chamfer_edges > 0 && out.report.new_vertices > 0);
//! // Input vertices come first, at their input indices.
//! assert_eq!(out.mesh.positions.len(), chamfered.positions.len() + out.report.new_vertices);
//! let report = out.mesh.topology_report();
//! assert!(report.manifold && report.oriented && report.boundary_edges == 0);
//! assert!(out.report.to_json().contains("\"chamfer_edges\":"));
//! ```
#![forbid(unsafe_code)]

/// The `*_with_table` entry point of a projection after sharpening: its body `$inner` on
/// a corner table the caller built once for several projections in a row.
macro_rules! with_table_entry_point {
    ($name:ident, $with_table:ident, $inner:ident, $opts:ty, $report:ty) => {
        #[doc = concat!(
            "[`", stringify!($name), "`] on `table`, the corner table of `mesh`'s triangles, ",
            "built once for several projections in a row (they move vertices, never triangles; ",
            "the coordinates are checked again). A table of other triangles is not used: one is ",
            "built, as without it."
        )]
        pub fn $with_table(
            mesh: &mut Mesh,
            opts: &$opts,
            table: &CornerTable,
        ) -> Result<$report, Error> {
            $inner(mesh, opts, Some(table))
        }
    };
}

mod apex;
mod beside;
mod crease;
mod edge_sharpener;
mod extended;
mod fuzz;
mod judge;
mod normal_filter;
mod options;
mod planar;
mod quadric;
mod report;
mod slivers;
mod snap;
mod tags;
mod weld;

pub use apex::{restore_apexes, restore_apexes_with_table, ApexOptions, ApexReport};
pub use beside::{
    project_beside_creases_onto_local_quadrics,
    project_beside_creases_onto_local_quadrics_with_table, BesideOptions, BesideReport,
};
pub use crease::{
    project_creases_onto_local_quadrics, project_creases_onto_local_quadrics_with_table,
    CreaseOptions, CreaseReport,
};
pub use edge_sharpener::EdgeSharpener;

/// What sharpening holds at its peak per input triangle, with the input mesh and the
/// output's writer, rounded up from measurements (`whet sharpen`, 2026-12-02: 171 bytes per
/// triangle on a 1.05M-triangle swing-decoded sphere, 179 on a 627k-triangle marching-cubes
/// fandisk, 8 % of whose triangles are chamfered): what a caller holds a run against a
/// memory budget with (`whet decode --sharpen --max-memory`).
pub const PEAK_BYTES_PER_TRIANGLE: u64 = 200;

pub use fuzz::{fuzz_input, fuzz_seed, fuzz_sharpen};
pub use judge::{Snap, SnapJudge, VetoReplay};
pub use normal_filter::VertexSelection;
pub use options::{Method, SharpenOptions, DEFAULT_CURVED_WALL_FACTOR, MAX_PASSES};
pub use planar::{
    flatten_planar_regions, flatten_planar_regions_with_table, PlanarOptions, PlanarReport,
};
pub use quadric::{
    project_onto_local_quadrics, project_onto_local_quadrics_with_table, QuadricOptions,
    QuadricReport,
};
pub use report::{SharpenReport, UnmovedReason};
pub use tags::SharpTags;

use whet_mesh::{FaceId, Mesh, MeshError};

/// The result of [`sharpen`].
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct Sharpened {
    /// The sharpened mesh: the input vertices at their input indices (those the extended
    /// method welded into a near-coincident neighbour are used by no triangle), then the new
    /// vertices. The normal-filter method instead keeps the vertices its needle collapses
    /// leave, in input order, and adds none.
    pub mesh: Mesh,
    /// For each triangle of `mesh`, the input triangle it was cut from (or is): lets callers
    /// carry per-face attributes over, and is what the orientation guarantee refers to.
    pub parents: Vec<FaceId>,
    /// Sharp vertices and edges of `mesh`, for Bender (seed 001 section 4.1).
    pub tags: SharpTags,
    /// Counts and time of the run.
    pub report: SharpenReport,
}

/// Why sharpening or reading tags failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The mesh is not an oriented manifold with valid indices and finite coordinates. The
    /// error names the first offender; run `Mesh::make_manifold` first to accept any input.
    #[error("the mesh cannot be sharpened: {0}{hint}", hint = repair_hint(.0))]
    InvalidInput(MeshError),
    /// An option out of range (API misuse).
    #[error("bad sharpen option: {0}")]
    Parameter(String),
    /// Reading or writing a tag file failed.
    #[error("tag or selection file I/O: {0}")]
    Io(#[from] std::io::Error),
    /// A broken internal invariant (a bug), reported instead of returning a broken mesh.
    #[error("internal error in whet-sharpen: {0}")]
    Internal(String),
    /// A tag or selection file that does not follow the format or does not fit the mesh.
    #[error("tag or selection file line {line}: {message}")]
    Format {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
}

/// What a caller can do about an [`Error::InvalidInput`]: `make_manifold` repairs the
/// structure, not a zero-area triangle (which only the normal-filter method refuses).
fn repair_hint(e: &MeshError) -> &'static str {
    match e {
        MeshError::ZeroAreaTriangle { .. } => {
            " (the normal-filter method needs triangles of nonzero area; the extended and \
             papers methods take them)"
        }
        e if e.is_structural() => " (run make_manifold first)",
        _ => "",
    }
}

impl Error {
    pub(crate) fn format(line: usize, message: String) -> Error {
        Error::Format { line, message }
    }
}

/// Sharpens `mesh` with `options`: detects the chamfers, subdivides them, snaps the new
/// vertices onto the extrapolated planes and removes the slivers this leaves (see the crate
/// docs and `docs/sharpen.md`).
///
/// Fails with [`Error::InvalidInput`] when the mesh is not an oriented manifold (non-manifold
/// edges or vertices, inconsistent orientation, bad indices) or has a non-finite coordinate,
/// and with [`Error::Parameter`] for options out of range. Never panics.
pub fn sharpen(mesh: &Mesh, options: &SharpenOptions) -> Result<Sharpened, Error> {
    EdgeSharpener::new(*options).sharpen(mesh)
}

/// [`sharpen`] with every pass's snaps put to `judge` before the mesh is settled (see
/// [`SnapJudge`]; the normal-filter method snaps nothing and never asks).
pub fn sharpen_judged(
    mesh: &Mesh,
    options: &SharpenOptions,
    judge: &mut dyn SnapJudge,
) -> Result<Sharpened, Error> {
    EdgeSharpener::new(*options).sharpen_judged(mesh, judge)
}

/// The normal filter ([`Method::NormalFilter`], whatever `options.method` says) limited to
/// `region`: only faces whose three vertices are selected can be feature faces, and only
/// selected vertices move or are removed (docs/sharpen.md, "The normal-filtering sharpener").
pub fn sharpen_region(
    mesh: &Mesh,
    options: &SharpenOptions,
    region: &VertexSelection,
) -> Result<Sharpened, Error> {
    let options = options.with_method(Method::NormalFilter);
    normal_filter::run(mesh, &options, Some(region))
}
