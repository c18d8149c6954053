//! whet is a mesh codec that gets far more shape per bit than vertex-quantizing codecs: it
//! re-tiles a dense triangle mesh into a nearly regular one whose vertices each cost a few
//! bits (SwingWrapper), codes the connectivity with Edgebreaker, and after decoding restores
//! the sharp edges and corners that uniform re-tiling chamfers away (EdgeSharpener, then the
//! Bender subdivision).
//!
//! This crate is the facade that applications depend on: it re-exports the public API of the
//! internal crates (which may change freely) under stable paths. The `whet` binary is the
//! command-line front end.
//!
//! ```
//! use whet::{io, Mesh};
//! let text = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";
//! let mesh: Mesh = io::read(text.as_bytes(), io::Format::Off)?;
//! let report = mesh.topology_report();
//! assert_eq!((report.vertices, report.triangles, report.genus), (4, 4, Some(0)));
//! # Ok::<(), whet::io::Error>(())
//! ```
#![forbid(unsafe_code)]

pub use whet_mesh::{
    angle_between, edge_key, Aabb, CornerId, CornerTable, DVec3, EdgeLengthStats, FaceId,
    ManifoldRepair, Mesh, MeshError, TopologyReport, VertexId,
};

/// Mesh files: OFF, OBJ, PLY and STL readers and writers.
pub mod io {
    pub use whet_io::*;
}

/// The codec: encoders, decoders, options and reports.
pub mod codec {
    pub use whet_codec::*;
}

/// EdgeSharpener: options, reports, sharp-edge tags and the projections after it.
pub mod sharpen {
    pub use whet_sharpen::*;
}

/// What a swing stream states about sharpening its decoded mesh ([`decode_sharpened`]).
pub use whet_swing::{StatedOutput, StatedProjection, StatedSharpening};

pub use whet_codec::{
    encode, DecodeBuffers, DecodeOptions, Decoder, EncodeBuffers, EncodeOptions, Encoder,
    StreamingDecoder,
};

/// Why a stream could not be decoded (or a subdiv stream encoded).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The container, or an exact or swing stream, is bad.
    #[error(transparent)]
    Codec(#[from] whet_codec::Error),
    /// A subdiv stream is bad.
    #[error(transparent)]
    Subdiv(#[from] whet_subdiv::Error),
    /// The decoded mesh could not be sharpened ([`decode_sharpened`]).
    #[error(transparent)]
    Sharpen(#[from] whet_sharpen::Error),
}

impl Error {
    /// True when the fault is in the bytes handed to a decoder.
    pub fn is_input_error(&self) -> bool {
        match self {
            Error::Codec(e) => e.is_input_error(),
            Error::Subdiv(e) => !matches!(e, whet_subdiv::Error::Parameter(_)),
            Error::Sharpen(e) => !matches!(e, whet_sharpen::Error::Parameter(_)),
        }
    }
}

/// Decodes a `.whet` stream of any mode: exact and swing through whet-codec, subdiv through
/// whet-subdiv (its control mesh is subdivided `subdiv_levels` times, or `levels` when given;
/// `Some(0)` returns the control mesh).
pub fn decode_with_levels(
    bytes: &[u8],
    opts: &DecodeOptions,
    levels: Option<u32>,
) -> Result<Mesh, Error> {
    let container = whet_format::parse(bytes, &opts.limits).map_err(whet_codec::Error::from)?;
    let h = &container.header;
    if h.mode != whet_format::Mode::Subdiv {
        return Ok(whet_codec::decode_container(&container, opts)?);
    }
    let missing =
        |what: &str| whet_subdiv::Error::Corrupt(format!("subdiv stream without its {what}"));
    let stated = h
        .get_u64(whet_format::tag::SUBDIV_LEVELS)
        .ok_or_else(|| missing("subdiv_levels field"))?;
    let control = container
        .section(whet_format::SectionKind::CONTROL)
        .ok_or_else(|| missing("control section"))?;
    let sharpness = container
        .section(whet_format::SectionKind::SHARPNESS)
        .ok_or_else(|| missing("sharpness section"))?;
    let levels = match levels {
        Some(l) => l,
        None => u32::try_from(stated).map_err(|_| missing("valid subdiv_levels"))?,
    };
    let mesh = whet_subdiv::decode_subdiv(control, sharpness, levels, opts)?;
    if levels as u64 == stated
        && (mesh.positions.len() as u64 != h.vertex_count
            || mesh.triangles.len() as u64 != h.triangle_count)
    {
        return Err(
            whet_subdiv::Error::Corrupt("decoded counts differ from the header's".into()).into(),
        );
    }
    Ok(mesh)
}

/// Decodes a `.whet` stream of any mode (see [`decode_with_levels`]).
pub fn decode(bytes: &[u8], opts: &DecodeOptions) -> Result<Mesh, Error> {
    decode_with_levels(bytes, opts, None)
}

/// A stream decoded and sharpened as it states ([`decode_sharpened`]).
#[derive(Debug)]
pub enum DecodedSharpened {
    /// The sharpening run: the output mesh with its sharp-edge tags (for Bender), its
    /// report, and the projections skipped.
    Sharpened(Box<StatedOutput>),
    /// The stream's encoder measured no sharpening best: the plain decoded mesh, its surface
    /// filter included.
    Unsharpened(Mesh),
}

impl DecodedSharpened {
    /// The output: what `whet decode --sharpen` writes.
    pub fn mesh(&self) -> &Mesh {
        match self {
            DecodedSharpened::Sharpened(s) => &s.sharpened.mesh,
            DecodedSharpened::Unsharpened(m) => m,
        }
    }

    /// [`Self::mesh`], taken.
    pub fn into_mesh(self) -> Mesh {
        match self {
            DecodedSharpened::Sharpened(s) => s.sharpened.mesh,
            DecodedSharpened::Unsharpened(m) => m,
        }
    }
}

/// Decodes a stream and sharpens it as its header states, exactly as `whet decode --sharpen`
/// with no option changed (docs/swing.md section 2): the sharpening its encoder measured
/// best with its snap vetoes replayed, the filter for after sharpening, then the planar,
/// quadric and crease projections it states (a projection the mesh does not admit is
/// skipped and listed in [`StatedOutput::skipped`]). A stream without sharpening fields (an
/// exact or subdiv stream, an older swing stream) gets the extended method at smooth
/// factor 2. `opts`'s surface filter applies only to a stream that states no sharpening.
///
/// ```
/// let mesh = whet::io::read_path(&whet_testkit::shared_fixture("fandisk.off"), None)?;
/// let opts = whet_swing::SwingOptions::DEFAULT.with_rate(whet_swing::Rate::BitsPerVertex(2.0));
/// let stream = whet_swing::encode(&mesh, &opts)?.bytes;
/// let out = whet::decode_sharpened(&stream, &whet::DecodeOptions::DEFAULT)?;
/// assert!(out.mesh().triangles.len() > 1000);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn decode_sharpened(bytes: &[u8], opts: &DecodeOptions) -> Result<DecodedSharpened, Error> {
    decode_sharpened_with(
        bytes,
        opts,
        &mut whet_sharpen::EdgeSharpener::new(whet_sharpen::SharpenOptions::DEFAULT),
    )
}

/// [`decode_sharpened`] with `sharpener`, an engine kept from stream to stream by a server
/// that decodes many: its working memory (the tables, the run's arrays) serves every call,
/// and an output given back to it (`sharpener.recycle(out.sharpened)` once done with a
/// [`DecodedSharpened::Sharpened`]) holds the next one. Each stream's own sharpening
/// options are set on it. The output is [`decode_sharpened`]'s.
///
/// ```
/// let mesh = whet::io::read_path(&whet_testkit::shared_fixture("fandisk.off"), None)?;
/// let opts = whet_swing::SwingOptions::DEFAULT.with_rate(whet_swing::Rate::BitsPerVertex(2.0));
/// let stream = whet_swing::encode(&mesh, &opts)?.bytes;
/// let mut sharpener = whet::sharpen::EdgeSharpener::new(whet::sharpen::SharpenOptions::DEFAULT);
/// for _ in 0..2 {
///     match whet::decode_sharpened_with(&stream, &whet::DecodeOptions::DEFAULT, &mut sharpener)? {
///         whet::DecodedSharpened::Sharpened(out) => {
///             assert!(out.sharpened.mesh.triangles.len() > 1000);
///             sharpener.recycle(out.sharpened);
///         }
///         whet::DecodedSharpened::Unsharpened(mesh) => assert!(mesh.triangles.len() > 1000),
///     }
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn decode_sharpened_with(
    bytes: &[u8],
    opts: &DecodeOptions,
    sharpener: &mut whet_sharpen::EdgeSharpener,
) -> Result<DecodedSharpened, Error> {
    let container = whet_format::parse(bytes, &opts.limits).map_err(whet_codec::Error::from)?;
    let stated = StatedSharpening::of(&container.header)?;
    // The container parsed above, decoded without parsing (and checking) it again; a subdiv
    // stream goes through `decode`, which also subdivides.
    let decode_parsed = |o: &DecodeOptions| -> Result<Mesh, Error> {
        if container.header.mode == whet_format::Mode::Subdiv {
            decode(bytes, o)
        } else {
            Ok(whet_codec::decode_container(&container, o)?)
        }
    };
    if stated.is_unsharpened() {
        return Ok(DecodedSharpened::Unsharpened(decode_parsed(opts)?));
    }
    let raw = decode_parsed(&opts.with_surface_filter(false))?;
    Ok(match stated.apply_with(&raw, sharpener)? {
        Some(out) => DecodedSharpened::Sharpened(Box::new(out)),
        // `apply` sharpens every stream that does not state "none" (handled above).
        None => DecodedSharpened::Unsharpened(raw),
    })
}

/// [`decode`] in the memory of `buffers`, for a caller that decodes stream after stream
/// (see [`DecodeBuffers`]: the exact mode then allocates nothing once the buffers are large
/// enough, and a mesh given back with [`DecodeBuffers::recycle`] receives the next one).
pub fn decode_reusing(
    bytes: &[u8],
    opts: &DecodeOptions,
    buffers: &mut DecodeBuffers,
) -> Result<Mesh, Error> {
    let container = whet_format::parse(bytes, &opts.limits).map_err(whet_codec::Error::from)?;
    if container.header.mode == whet_format::Mode::Subdiv {
        return decode(bytes, opts);
    }
    Ok(whet_codec::decode_container_reusing(
        &container, opts, buffers,
    )?)
}

/// Encodes `mesh` in the subdiv mode: fits a control mesh with continuous edge sharpness and
/// writes the container (header field `subdiv_levels`, sections `control` and `sharpness`).
pub fn encode_subdiv(
    mesh: &Mesh,
    opts: &whet_subdiv::SubdivEncodeOptions,
) -> Result<(Vec<u8>, whet_subdiv::SubdivReport), Error> {
    let p = whet_subdiv::encode_subdiv(mesh, opts)?;
    let header = whet_format::Header::new(
        whet_format::Mode::Subdiv,
        p.report.decoded_vertices,
        p.report.decoded_triangles,
    )
    .with(whet_format::tag::SUBDIV_LEVELS, p.levels as u64);
    let bytes = whet_format::Container::new(header)
        .with_section(whet_format::SectionKind::CONTROL, p.control)
        .with_section(whet_format::SectionKind::SHARPNESS, p.sharpness)
        .to_bytes()
        .map_err(whet_codec::Error::from)?;
    Ok((bytes, p.report))
}

#[cfg(test)]
mod thread_safety {
    /// Servers decode on worker threads and share options and meshes between them: the
    /// facade's types must stay `Send + Sync` (a compile-time check: a type that stops being
    /// thread-safe fails the build of the tests).
    #[test]
    fn the_facade_types_are_send_and_sync() {
        fn both<T: Send + Sync>() {}
        both::<crate::Mesh>();
        both::<crate::CornerTable>();
        both::<crate::Encoder>();
        both::<crate::Decoder<std::fs::File>>();
        both::<crate::StreamingDecoder>();
        both::<crate::EncodeOptions>();
        both::<crate::DecodeOptions>();
        both::<crate::Error>();
        both::<crate::io::Error>();
        both::<crate::codec::Error>();
        both::<crate::codec::EncodeReport>();
        // Buffers belong to one worker at a time: they move between threads.
        fn send<T: Send>() {}
        send::<crate::DecodeBuffers>();
        send::<crate::EncodeBuffers>();
    }

    /// The facade's reusing decoder gives `decode`'s mesh, stream after stream, with the
    /// meshes given back.
    #[test]
    fn decode_reusing_decodes_what_decode_decodes() {
        let mut buffers = crate::DecodeBuffers::new();
        for n in [3, 2, 4] {
            let mesh = whet_testkit::meshes::icosphere(n);
            let bytes = crate::encode(&mesh, &crate::EncodeOptions::DEFAULT)
                .unwrap()
                .bytes;
            let opts = crate::DecodeOptions::DEFAULT;
            let got = crate::decode_reusing(&bytes, &opts, &mut buffers).unwrap();
            assert_eq!(got, crate::decode(&bytes, &opts).unwrap());
            buffers.recycle(got);
        }
    }
}
