//! The preamble (magic, version) and the header: mode, counts, declared stream length and
//! typed fields (docs/format.md §1, §3), plus [`peek_header`].

use std::fmt;

use byteorder::{ByteOrder, LittleEndian};

use crate::error::{Error, FormatError};
use crate::limits::Limits;
use crate::varint::{self, write_varint, VarintError};

/// The first four bytes of every stream.
pub const MAGIC: [u8; 4] = *b"WHET";

/// Longest header body the format allows (docs/format.md §1); bulk data belongs in sections.
pub const MAX_HEADER_LEN: u64 = 65_535;

/// Bytes before `header_len`: magic, major, minor.
pub(crate) const PREAMBLE_LEN: usize = 6;

/// Largest field tag: `tag << 2` must fit the 64-bit key.
pub(crate) const MAX_FIELD_TAG: u64 = u64::MAX >> 2;

/// A format version, `major.minor` (docs/format.md §6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Version {
    /// Incompatible changes; readers refuse majors they do not know.
    pub major: u8,
    /// Compatible additions; readers accept every minor of their major.
    pub minor: u8,
}

impl Version {
    /// The version this crate writes by default and the major it reads: 1.0.
    pub const CURRENT: Version = Version { major: 1, minor: 0 };

    /// `major.minor`.
    pub const fn new(major: u8, minor: u8) -> Self {
        Version { major, minor }
    }

    /// True when this crate reads streams of this version (same major as
    /// [`Version::CURRENT`]).
    pub const fn is_readable(self) -> bool {
        self.major == Version::CURRENT.major
    }

    fn check(self) -> Result<(), Error> {
        if self.is_readable() {
            Ok(())
        } else {
            Err(Error::Unsupported {
                major: self.major,
                minor: self.minor,
            })
        }
    }
}

impl Default for Version {
    fn default() -> Self {
        Version::CURRENT
    }
}

impl fmt::Display for Version {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}", self.major, self.minor)
    }
}

/// The codec mode that produced the stream; decides which fields and sections it carries.
///
/// Deliberately exhaustive: a new mode should fail to compile wherever modes are matched.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Mode {
    /// Edgebreaker connectivity plus quantized positions.
    Exact = 0,
    /// SwingWrapper-retiled mesh with swing angles.
    Swing = 1,
    /// Subdivision-based coding (reserved for whet-subdiv).
    Subdiv = 2,
}

impl Mode {
    /// Every mode, in code order.
    pub const ALL: [Mode; 3] = [Mode::Exact, Mode::Swing, Mode::Subdiv];

    /// The value stored in the header.
    pub const fn code(self) -> u64 {
        self as u64
    }

    /// The mode stored as `code`, if this crate knows it.
    pub const fn from_code(code: u64) -> Option<Mode> {
        match code {
            0 => Some(Mode::Exact),
            1 => Some(Mode::Swing),
            2 => Some(Mode::Subdiv),
            _ => None,
        }
    }

    /// Lower-case name as in docs/format.md: `exact`, `swing`, `subdiv`.
    pub const fn name(self) -> &'static str {
        match self {
            Mode::Exact => "exact",
            Mode::Swing => "swing",
            Mode::Subdiv => "subdiv",
        }
    }
}

impl TryFrom<u64> for Mode {
    type Error = Error;

    fn try_from(code: u64) -> Result<Self, Error> {
        Mode::from_code(code).ok_or(Error::Format(FormatError::UnknownMode(code)))
    }
}

impl fmt::Display for Mode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Header field tags of format 1.0 (docs/format.md §3). Odd tags are optional.
pub mod tag {
    use super::ValueType;

    /// Optional, bytes: UTF-8 name and version of the writer; informational.
    pub const ENCODER: u64 = 1;
    /// u64: connected components (exact, swing).
    pub const COMPONENT_COUNT: u64 = 2;
    /// u64: position quantization bits per coordinate (exact, swing).
    pub const QUANT_BITS: u64 = 4;
    /// bytes, exactly 48: f64 min x, y, z then max x, y, z (exact, swing); see
    /// [`Header::bbox`](crate::Header::bbox).
    pub const BBOX: u64 = 6;
    /// f64: SwingWrapper target edge length L (swing).
    pub const EDGE_LENGTH: u64 = 8;
    /// u64: bits of a quantized swing angle (swing).
    pub const ANGLE_BITS: u64 = 10;
    /// u64: subdivision levels the decoder applies to the control mesh (subdiv).
    pub const SUBDIV_LEVELS: u64 = 12;
    /// i64 (format 1.1): factor of the normal Laplacian in the swing decoder's surface
    /// filter, in units of 1/1024 (swing; absent: 0).
    pub const FILTER_NORMAL: u64 = 14;
    /// i64 (format 1.1): factor of the one-ring mean of the normal Laplacian in the swing
    /// decoder's surface filter, in units of 1/1024 (swing; absent: 0).
    pub const FILTER_SMOOTHED: u64 = 16;
    /// i64 (format 1.2, optional): factor of the normal Laplacian in the surface filter
    /// applied after EdgeSharpener to the vertices it left in place (swing; absent: 0).
    pub const SHARPENED_FILTER_NORMAL: u64 = 17;
    /// i64 (format 1.2, optional): factor of the one-ring mean in that filter (swing;
    /// absent: 0).
    pub const SHARPENED_FILTER_SMOOTHED: u64 = 19;
    /// u64 (format 1.2, optional): how the encoder measured `whet decode --sharpen` best
    /// served: 0 EdgeSharpener's extended method, 1 the papers' method, 2 no sharpening
    /// (swing; absent or another value: the decoder's default).
    pub const SHARPEN_METHOD: u64 = 21;
    /// u64 (format 1.2, optional): the EdgeSharpener smooth factor that goes with
    /// [`SHARPEN_METHOD`], in hundredths (swing; absent or outside 1..=1000: the decoder's
    /// default, 2).
    pub const SHARPEN_SMOOTH_FACTOR: u64 = 23;
    /// u64 (format 1.2, optional): the planar-region projection a decoder applies after
    /// sharpening (`whet decode --sharpen`), its tolerance in hundredths of the angle step
    /// (swing; absent, or outside 1..=1000: none).
    pub const PLANAR_TOLERANCE: u64 = 25;
    /// u64 (format 1.2, optional): the EdgeSharpener curved-wall factor that goes with
    /// [`SHARPEN_METHOD`], in hundredths, 0 for off (swing; absent, or another value: off).
    pub const SHARPEN_CURVED_WALLS: u64 = 27;
    /// u64 (format 1.2, optional): how many EdgeSharpener passes go with
    /// [`SHARPEN_METHOD`] (swing; absent, or outside 1..=4: one).
    pub const SHARPEN_PASSES: u64 = 29;
    /// u64 (format 1.2, optional): the local quadric projection a decoder applies after
    /// sharpening and the planar-region projection, its move limit in hundredths of the
    /// angle step (swing; absent, or outside 1..=1000: none).
    pub const QUADRIC_PROJECTION: u64 = 31;
    /// bytes, exactly 24 (format 1.3): the quantization box as f32 min x, y, z then max x,
    /// y, z, for a box whose coordinates are binary32 values (swing streams round their box
    /// outward to them); a header holds this field or [`BBOX`], not both. See
    /// [`Header::bbox`](crate::Header::bbox).
    pub const BBOX_F32: u64 = 32;
    /// bytes (format 1.3, optional): the snaps of `whet decode --sharpen` that the encoder
    /// measured farther from the original than their rest positions, and vetoed, for the
    /// sharpening the stream states (swing; absent: none). Layout in docs/format.md section 3.
    pub const SNAP_VETOES: u64 = 33;
    /// u64 (optional, added 2026-12-06): the crease projection a decoder applies after
    /// sharpening and the planar and quadric projections, its move limit in hundredths of the
    /// mean edge length (swing; absent, or outside 1..=1000: none).
    pub const CREASE_PROJECTION: u64 = 35;
    /// u64 (optional, added 2026-12-06, later session): the one-sided quadric projection of
    /// the vertices beside creases a decoder applies after the planar and quadric
    /// projections and before the crease projection, its move limit in hundredths of the
    /// angle step (swing; absent, or outside 1..=1000: none).
    pub const BESIDE_PROJECTION: u64 = 37;
    /// u64 (optional, added 2026-12-07): the apex restoration a decoder applies after
    /// sharpening and every other projection, its move limit in hundredths of the mean edge
    /// length (swing; absent, or outside 1..=1000: none).
    pub const APEX_PROJECTION: u64 = 39;
    /// i64 (format 1.4): factor of `s2`, the one-ring mean of the filter's smoothed field,
    /// in the swing decoder's extended surface filter, in units of 1/1024 (swing; absent:
    /// 0). Required: a stream with it decodes to another mesh.
    pub const FILTER_SMOOTHED2: u64 = 34;
    /// i64 (format 1.4): factor of `q = d |d| / L` in the extended surface filter, in units
    /// of 1/1024 (swing; absent: 0).
    pub const FILTER_QUADRATIC: u64 = 36;
    /// i64 (format 1.4): factor of the tangential part of the umbrella Laplacian (a vector
    /// in the tangent plane: it moves vertices along the surface) in the extended surface
    /// filter, in units of 1/1024 (swing; absent: 0).
    pub const FILTER_TANGENTIAL: u64 = 38;
    /// u64 (format 1.5): the order and predictor of an exact-mode stream's positions: 0
    /// the prediction-degree order with several parallelograms (absent: 0), 1 traversal
    /// order with one parallelogram per vertex (faster to decode, larger).
    /// Required: a reader that does not know it would misread the geometry.
    pub const EXACT_PREDICTION: u64 = 40;
    /// u64 (optional, added 2026-12-07, twenty-seventh session): 1 when the EdgeSharpener
    /// sharpening that goes with [`SHARPEN_METHOD`] labels the gray vertices of surface
    /// samplings too (`whet_sharpen::SharpenOptions::surface_gray_labels`; swing; absent, or
    /// another value: off).
    pub const SHARPEN_GRAY_LABELS: u64 = 41;

    /// Every tag this crate knows, with its name and value type.
    pub const KNOWN: [(u64, &str, ValueType); 27] = [
        (ENCODER, "encoder", ValueType::Bytes),
        (COMPONENT_COUNT, "component_count", ValueType::U64),
        (QUANT_BITS, "quant_bits", ValueType::U64),
        (BBOX, "bbox", ValueType::Bytes),
        (EDGE_LENGTH, "edge_length", ValueType::F64),
        (ANGLE_BITS, "angle_bits", ValueType::U64),
        (SUBDIV_LEVELS, "subdiv_levels", ValueType::U64),
        (FILTER_NORMAL, "filter_normal", ValueType::I64),
        (FILTER_SMOOTHED, "filter_smoothed", ValueType::I64),
        (
            SHARPENED_FILTER_NORMAL,
            "sharpened_filter_normal",
            ValueType::I64,
        ),
        (
            SHARPENED_FILTER_SMOOTHED,
            "sharpened_filter_smoothed",
            ValueType::I64,
        ),
        (SHARPEN_METHOD, "sharpen_method", ValueType::U64),
        (
            SHARPEN_SMOOTH_FACTOR,
            "sharpen_smooth_factor",
            ValueType::U64,
        ),
        (PLANAR_TOLERANCE, "planar_tolerance", ValueType::U64),
        (SHARPEN_CURVED_WALLS, "sharpen_curved_walls", ValueType::U64),
        (SHARPEN_PASSES, "sharpen_passes", ValueType::U64),
        (QUADRIC_PROJECTION, "quadric_projection", ValueType::U64),
        (BBOX_F32, "bbox_f32", ValueType::Bytes),
        (SNAP_VETOES, "snap_vetoes", ValueType::Bytes),
        (CREASE_PROJECTION, "crease_projection", ValueType::U64),
        (FILTER_SMOOTHED2, "filter_smoothed2", ValueType::I64),
        (FILTER_QUADRATIC, "filter_quadratic", ValueType::I64),
        (BESIDE_PROJECTION, "beside_projection", ValueType::U64),
        (FILTER_TANGENTIAL, "filter_tangential", ValueType::I64),
        (APEX_PROJECTION, "apex_projection", ValueType::U64),
        (EXACT_PREDICTION, "exact_prediction", ValueType::U64),
        (SHARPEN_GRAY_LABELS, "sharpen_gray_labels", ValueType::U64),
    ];

    /// Name and type of a known tag.
    pub fn known(tag: u64) -> Option<(&'static str, ValueType)> {
        KNOWN
            .iter()
            .find(|(t, _, _)| *t == tag)
            .map(|&(_, name, ty)| (name, ty))
    }

    /// True for odd tags, which a reader that does not know them skips.
    pub const fn is_optional(tag: u64) -> bool {
        tag & 1 == 1
    }
}

/// Byte length of the [`tag::BBOX`] value.
pub const BBOX_LEN: usize = 48;
/// Byte length of the [`tag::BBOX_F32`] value.
pub const BBOX_F32_LEN: usize = 24;

/// Wire type of a header field value, the low two bits of its key.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ValueType {
    /// Varint.
    U64 = 0,
    /// Zigzag varint.
    I64 = 1,
    /// 8 bytes little-endian IEEE 754.
    F64 = 2,
    /// Varint length, then the bytes.
    Bytes = 3,
}

impl ValueType {
    /// `u64`, `i64`, `f64` or `bytes`.
    pub const fn name(self) -> &'static str {
        match self {
            ValueType::U64 => "u64",
            ValueType::I64 => "i64",
            ValueType::F64 => "f64",
            ValueType::Bytes => "bytes",
        }
    }

    /// The type in the low two bits of a field key.
    const fn from_bits(bits: u64) -> ValueType {
        match bits & 3 {
            0 => ValueType::U64,
            1 => ValueType::I64,
            2 => ValueType::F64,
            _ => ValueType::Bytes,
        }
    }
}

impl fmt::Display for ValueType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A typed header field value.
///
/// Equality is bitwise for `F64` (so NaN payloads and the sign of zero survive round trips and
/// compare equal only to themselves).
#[derive(Debug, Clone)]
pub enum HeaderValue {
    /// Unsigned integer.
    U64(u64),
    /// Signed integer.
    I64(i64),
    /// Float.
    F64(f64),
    /// Raw bytes.
    Bytes(Vec<u8>),
}

impl HeaderValue {
    /// The wire type.
    pub const fn value_type(&self) -> ValueType {
        match self {
            HeaderValue::U64(_) => ValueType::U64,
            HeaderValue::I64(_) => ValueType::I64,
            HeaderValue::F64(_) => ValueType::F64,
            HeaderValue::Bytes(_) => ValueType::Bytes,
        }
    }
}

impl PartialEq for HeaderValue {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (HeaderValue::U64(a), HeaderValue::U64(b)) => a == b,
            (HeaderValue::I64(a), HeaderValue::I64(b)) => a == b,
            (HeaderValue::F64(a), HeaderValue::F64(b)) => a.to_bits() == b.to_bits(),
            (HeaderValue::Bytes(a), HeaderValue::Bytes(b)) => a == b,
            _ => false,
        }
    }
}

impl Eq for HeaderValue {}

impl From<u64> for HeaderValue {
    fn from(v: u64) -> Self {
        HeaderValue::U64(v)
    }
}

impl From<i64> for HeaderValue {
    fn from(v: i64) -> Self {
        HeaderValue::I64(v)
    }
}

impl From<f64> for HeaderValue {
    fn from(v: f64) -> Self {
        HeaderValue::F64(v)
    }
}

impl From<Vec<u8>> for HeaderValue {
    fn from(v: Vec<u8>) -> Self {
        HeaderValue::Bytes(v)
    }
}

impl From<&[u8]> for HeaderValue {
    fn from(v: &[u8]) -> Self {
        HeaderValue::Bytes(v.to_vec())
    }
}

/// One header field: a tag from [`tag`] (or a newer one) and its value.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HeaderField {
    /// Field tag; odd tags are optional.
    pub tag: u64,
    /// Typed value.
    pub value: HeaderValue,
}

/// The container header: version, codec mode, counts and typed fields.
///
/// Fields are kept sorted by tag with at most one value per tag, the order the format
/// requires, so every `Header` can be written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Header {
    /// Format version: the one read, or the one to write (default [`Version::CURRENT`]).
    pub version: Version,
    /// Codec mode.
    pub mode: Mode,
    /// Vertices of the decoded mesh.
    pub vertex_count: u64,
    /// Triangles of the decoded mesh.
    pub triangle_count: u64,
    fields: Vec<HeaderField>,
}

impl Header {
    /// A version-[`Version::CURRENT`] header without fields.
    pub fn new(mode: Mode, vertex_count: u64, triangle_count: u64) -> Self {
        Header {
            version: Version::CURRENT,
            mode,
            vertex_count,
            triangle_count,
            fields: Vec::new(),
        }
    }

    /// Sets the version to write.
    pub fn with_version(mut self, version: Version) -> Self {
        self.version = version;
        self
    }

    /// Sets a field (builder form of [`Header::set`]).
    pub fn with(mut self, tag: u64, value: impl Into<HeaderValue>) -> Self {
        self.set(tag, value);
        self
    }

    /// Sets field `tag`, replacing any previous value. Tags and types are checked when the
    /// header is written.
    pub fn set(&mut self, tag: u64, value: impl Into<HeaderValue>) {
        let value = value.into();
        match self.fields.binary_search_by_key(&tag, |f| f.tag) {
            Ok(i) => {
                if let Some(f) = self.fields.get_mut(i) {
                    f.value = value;
                }
            }
            Err(i) => self.fields.insert(i, HeaderField { tag, value }),
        }
    }

    /// Removes field `tag`, returning its value.
    pub fn remove(&mut self, tag: u64) -> Option<HeaderValue> {
        let i = self.fields.binary_search_by_key(&tag, |f| f.tag).ok()?;
        Some(self.fields.remove(i).value)
    }

    /// All fields, sorted by tag.
    pub fn fields(&self) -> &[HeaderField] {
        &self.fields
    }

    /// The value of field `tag`.
    pub fn get(&self, tag: u64) -> Option<&HeaderValue> {
        let i = self.fields.binary_search_by_key(&tag, |f| f.tag).ok()?;
        self.fields.get(i).map(|f| &f.value)
    }

    /// Field `tag` if it is a `u64`.
    pub fn get_u64(&self, tag: u64) -> Option<u64> {
        match self.get(tag)? {
            HeaderValue::U64(v) => Some(*v),
            _ => None,
        }
    }

    /// Field `tag` if it is an `i64`.
    pub fn get_i64(&self, tag: u64) -> Option<i64> {
        match self.get(tag)? {
            HeaderValue::I64(v) => Some(*v),
            _ => None,
        }
    }

    /// Field `tag` if it is an `f64`.
    pub fn get_f64(&self, tag: u64) -> Option<f64> {
        match self.get(tag)? {
            HeaderValue::F64(v) => Some(*v),
            _ => None,
        }
    }

    /// Field `tag` if it is `bytes`.
    pub fn get_bytes(&self, tag: u64) -> Option<&[u8]> {
        match self.get(tag)? {
            HeaderValue::Bytes(v) => Some(v),
            _ => None,
        }
    }

    /// The quantization box as `(min, max)`: the [`tag::BBOX`] field (48 bytes) or the
    /// [`tag::BBOX_F32`] field (24 bytes, widened exactly to f64); `None` when neither is
    /// present and well formed, or when both are.
    pub fn bbox(&self) -> Option<([f64; 3], [f64; 3])> {
        let v: [f64; 6] = match (self.get_bytes(tag::BBOX), self.get_bytes(tag::BBOX_F32)) {
            (Some(b), None) if b.len() == BBOX_LEN => {
                let mut v = [0.0; 6];
                LittleEndian::read_f64_into(b, &mut v);
                v
            }
            (None, Some(b)) if b.len() == BBOX_F32_LEN => {
                let mut v = [0.0f32; 6];
                LittleEndian::read_f32_into(b, &mut v);
                v.map(f64::from)
            }
            _ => return None,
        };
        Some(([v[0], v[1], v[2]], [v[3], v[4], v[5]]))
    }

    /// Sets the [`tag::BBOX`] field (and removes a [`tag::BBOX_F32`] one).
    pub fn set_bbox(&mut self, min: [f64; 3], max: [f64; 3]) {
        let mut b = vec![0; BBOX_LEN];
        let v = [min[0], min[1], min[2], max[0], max[1], max[2]];
        LittleEndian::write_f64_into(&v, &mut b);
        self.remove(tag::BBOX_F32);
        self.set(tag::BBOX, b);
    }

    /// Sets the box as the 24-byte [`tag::BBOX_F32`] field when every coordinate is a
    /// binary32 value (exactly), else as [`tag::BBOX`]; returns true for the short form. The
    /// short form is format 1.3: the caller raises the version.
    pub fn set_bbox_compact(&mut self, min: [f64; 3], max: [f64; 3]) -> bool {
        let v = [min[0], min[1], min[2], max[0], max[1], max[2]];
        if !v.iter().all(|&x| f64::from(x as f32) == x) {
            self.set_bbox(min, max);
            return false;
        }
        let mut b = vec![0; BBOX_F32_LEN];
        LittleEndian::write_f32_into(&v.map(|x| x as f32), &mut b);
        self.remove(tag::BBOX);
        self.set(tag::BBOX_F32, b);
        true
    }
}

/// The smallest box of binary32 coordinates holding `(min, max)`: each coordinate rounded
/// outward to the nearest f32 (`None` when one is not finite or beyond the f32 range).
pub fn box_f32_outward(min: [f64; 3], max: [f64; 3]) -> Option<([f64; 3], [f64; 3])> {
    // The neighbouring binary32 value towards `towards` (`f32::next_up`/`next_down`, spelled
    // out for the workspace's minimum Rust version); `f` finite.
    let step = |f: f32, towards: f32| -> f32 {
        if f == 0.0 {
            f32::from_bits(1).copysign(towards)
        } else if (f < towards) == (f > 0.0) {
            f32::from_bits(f.to_bits() + 1)
        } else {
            f32::from_bits(f.to_bits() - 1)
        }
    };
    let down = |x: f64| {
        let f = x as f32;
        let f = if f.is_finite() && f64::from(f) > x {
            step(f, f32::NEG_INFINITY)
        } else {
            f
        };
        (f.is_finite() && x.is_finite()).then_some(f64::from(f))
    };
    let up = |x: f64| {
        let f = x as f32;
        let f = if f.is_finite() && f64::from(f) < x {
            step(f, f32::INFINITY)
        } else {
            f
        };
        (f.is_finite() && x.is_finite()).then_some(f64::from(f))
    };
    Some((
        [down(min[0])?, down(min[1])?, down(min[2])?],
        [up(max[0])?, up(max[1])?, up(max[2])?],
    ))
}

/// Checks a field against the known-tag table (docs/format.md §3). Unknown odd tags pass.
pub(crate) fn check_field(tag: u64, value: &HeaderValue) -> Result<(), FormatError> {
    let Some((_, expected)) = tag::known(tag) else {
        return if tag::is_optional(tag) {
            Ok(())
        } else {
            Err(FormatError::UnknownRequiredField { tag })
        };
    };
    let found = value.value_type();
    if found != expected {
        return Err(FormatError::FieldType {
            tag,
            expected,
            found,
        });
    }
    if let HeaderValue::Bytes(b) = value {
        if tag == tag::BBOX && b.len() != BBOX_LEN {
            return Err(FormatError::FieldValue {
                tag,
                reason: "bbox must be 48 bytes (6 f64)",
            });
        }
        if tag == tag::BBOX_F32 && b.len() != BBOX_F32_LEN {
            return Err(FormatError::FieldValue {
                tag,
                reason: "bbox_f32 must be 24 bytes (6 f32)",
            });
        }
    }
    Ok(())
}

/// Writes preamble, `header_len`, header body and header CRC.
pub(crate) fn encode_header(header: &Header, body_len: u64) -> Result<Vec<u8>, Error> {
    if !header.version.is_readable() {
        return Err(Error::Parameter(format!(
            "cannot write format version {}: this whet writes {}.x",
            header.version,
            Version::CURRENT.major
        )));
    }
    let mut body = Vec::new();
    write_varint(&mut body, header.mode.code());
    write_varint(&mut body, header.vertex_count);
    write_varint(&mut body, header.triangle_count);
    write_varint(&mut body, body_len);
    for f in &header.fields {
        if f.tag > MAX_FIELD_TAG {
            return Err(Error::Parameter(format!(
                "header field tag {} is above the largest tag {MAX_FIELD_TAG}",
                f.tag
            )));
        }
        check_field(f.tag, &f.value)
            .map_err(|e| Error::Parameter(format!("cannot write header: {e}")))?;
        write_varint(&mut body, f.tag << 2 | f.value.value_type() as u64);
        match &f.value {
            HeaderValue::U64(v) => write_varint(&mut body, *v),
            HeaderValue::I64(v) => varint::write_varint_i64(&mut body, *v),
            HeaderValue::F64(v) => {
                let mut b = [0; 8];
                LittleEndian::write_f64(&mut b, *v);
                body.extend_from_slice(&b);
            }
            HeaderValue::Bytes(b) => {
                write_varint(&mut body, b.len() as u64);
                body.extend_from_slice(b);
            }
        }
    }
    let header_len = body.len() as u64;
    if header_len > MAX_HEADER_LEN {
        return Err(Error::Parameter(format!(
            "header body of {header_len} bytes exceeds the {MAX_HEADER_LEN} the format allows"
        )));
    }
    let mut out = Vec::with_capacity(PREAMBLE_LEN + 3 + body.len() + 4);
    out.extend_from_slice(&MAGIC);
    out.push(header.version.major);
    out.push(header.version.minor);
    write_varint(&mut out, header_len);
    out.extend_from_slice(&body);
    let mut crc = [0; 4];
    LittleEndian::write_u32(&mut crc, crc32fast::hash(&out));
    out.extend_from_slice(&crc);
    Ok(out)
}

/// Checks the first bytes of a stream as far as `prefix` goes: the magic byte by byte (so
/// garbage is refused as early as possible), the version once both of its bytes are in.
pub(crate) fn check_preamble(prefix: &[u8]) -> Result<(), Error> {
    let n = prefix.len().min(MAGIC.len());
    if prefix.get(..n) != MAGIC.get(..n) {
        return Err(Error::BadMagic {
            found: prefix.get(..n).unwrap_or_default().to_vec(),
        });
    }
    if let (Some(&major), Some(&minor)) = (prefix.get(4), prefix.get(5)) {
        Version::new(major, minor).check()?;
    }
    Ok(())
}

/// Maps a varint error inside the header body: the body is length-delimited, so running off
/// its end is a format error, not truncation.
fn in_header(e: VarintError) -> FormatError {
    match e {
        VarintError::Truncated => FormatError::HeaderOverrun,
        VarintError::Format(f) => f,
    }
}

/// The counts at the start of the header body.
struct Counts {
    mode: Mode,
    vertex_count: u64,
    triangle_count: u64,
    body_len: u64,
}

fn decode_counts(body: &[u8], pos: &mut usize) -> Result<Counts, VarintError> {
    let mode = varint::decode(body, pos)?;
    let vertex_count = varint::decode(body, pos)?;
    let triangle_count = varint::decode(body, pos)?;
    let body_len = varint::decode(body, pos)?;
    let mode = Mode::from_code(mode).ok_or(VarintError::Format(FormatError::UnknownMode(mode)))?;
    Ok(Counts {
        mode,
        vertex_count,
        triangle_count,
        body_len,
    })
}

/// Decodes a CRC-checked header body; returns the header and `body_len`.
pub(crate) fn decode_body(
    body: &[u8],
    version: Version,
    limits: &Limits,
) -> Result<(Header, u64), Error> {
    let mut pos = 0;
    let c = decode_counts(body, &mut pos).map_err(in_header)?;
    limits.check_counts(c.vertex_count, c.triangle_count)?;
    let mut header = Header {
        version,
        mode: c.mode,
        vertex_count: c.vertex_count,
        triangle_count: c.triangle_count,
        fields: Vec::new(),
    };
    let mut previous = None;
    while pos < body.len() {
        let key = varint::decode(body, &mut pos).map_err(in_header)?;
        let tag = key >> 2;
        if let Some(previous) = previous {
            if tag <= previous {
                return Err(FormatError::FieldOrder {
                    previous,
                    found: tag,
                }
                .into());
            }
        }
        previous = Some(tag);
        let value = decode_value(body, &mut pos, ValueType::from_bits(key))?;
        check_field(tag, &value)?;
        if tag == tag::BBOX_F32 && header.get(tag::BBOX).is_some() {
            return Err(FormatError::FieldValue {
                tag,
                reason: "the box is given twice (bbox and bbox_f32)",
            }
            .into());
        }
        if tag::known(tag).is_some() {
            // Fields arrive in increasing tag order, so pushing keeps `fields` sorted.
            header.fields.push(HeaderField { tag, value });
        }
    }
    Ok((header, c.body_len))
}

fn decode_value(body: &[u8], pos: &mut usize, ty: ValueType) -> Result<HeaderValue, FormatError> {
    Ok(match ty {
        ValueType::U64 => HeaderValue::U64(varint::decode(body, pos).map_err(in_header)?),
        ValueType::I64 => HeaderValue::I64(varint::zigzag_decode(
            varint::decode(body, pos).map_err(in_header)?,
        )),
        ValueType::F64 => {
            let end = pos.checked_add(8).ok_or(FormatError::HeaderOverrun)?;
            let b = body.get(*pos..end).ok_or(FormatError::HeaderOverrun)?;
            *pos = end;
            HeaderValue::F64(LittleEndian::read_f64(b))
        }
        ValueType::Bytes => {
            let len = varint::decode(body, pos).map_err(in_header)?;
            // Bounded by the header body, never by the declared length alone.
            let end = usize::try_from(len)
                .ok()
                .and_then(|len| pos.checked_add(len))
                .ok_or(FormatError::HeaderOverrun)?;
            let b = body.get(*pos..end).ok_or(FormatError::HeaderOverrun)?;
            *pos = end;
            HeaderValue::Bytes(b.to_vec())
        }
    })
}

/// What [`peek_header`] reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct HeaderInfo {
    /// Format version of the stream.
    pub version: Version,
    /// Codec mode.
    pub mode: Mode,
    /// Declared vertex count.
    pub vertex_count: u64,
    /// Declared triangle count.
    pub triangle_count: u64,
    /// Bytes from the magic through the header CRC: the offset of the first section.
    pub header_end: u64,
    /// Declared length of the whole stream, through the end marker.
    pub total_len: u64,
}

/// Reads version, mode, counts and declared size from the start of a stream.
///
/// Needs only the preamble and the first four varints of the header body (a few dozen bytes
/// at most); it checks neither CRCs nor [`Limits`] and reads nothing after the header, so a
/// server can decide what to do with a stream before receiving it. Errors: [`Error::BadMagic`],
/// [`Error::Unsupported`], [`Error::Truncated`] when `data` ends first, [`Error::Format`].
pub fn peek_header(data: &[u8]) -> Result<HeaderInfo, Error> {
    check_preamble(data.get(..PREAMBLE_LEN).unwrap_or(data))?;
    let truncated = |what: &str| Error::Truncated {
        offset: data.len() as u64,
        what: what.to_string(),
    };
    let (&major, &minor) = data
        .get(4)
        .zip(data.get(5))
        .ok_or_else(|| truncated("inside the magic and version"))?;
    let mut pos = PREAMBLE_LEN;
    let header_len = varint::decode(data, &mut pos).map_err(|e| match e {
        VarintError::Truncated => truncated("inside the header length"),
        VarintError::Format(f) => f.into(),
    })?;
    if header_len > MAX_HEADER_LEN {
        return Err(FormatError::HeaderTooLong(header_len).into());
    }
    // The check above bounds header_len by 65 535, so these sums cannot overflow.
    let body_start = pos;
    let body_end = body_start + header_len as usize;
    let body = data
        .get(body_start..body_end.min(data.len()))
        .unwrap_or_default();
    let mut at = 0;
    let c = decode_counts(body, &mut at).map_err(|e| match e {
        VarintError::Truncated if body_end > data.len() => truncated("inside the header"),
        e => in_header(e).into(),
    })?;
    let header_total = (body_end + 4) as u64;
    Ok(HeaderInfo {
        version: Version::new(major, minor),
        mode: c.mode,
        vertex_count: c.vertex_count,
        triangle_count: c.triangle_count,
        header_end: header_total,
        total_len: header_total
            .checked_add(c.body_len)
            .ok_or(FormatError::LengthOverflow)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_stay_sorted_and_unique() {
        let mut h = Header::new(Mode::Swing, 10, 16)
            .with(tag::ANGLE_BITS, 9u64)
            .with(tag::COMPONENT_COUNT, 1u64)
            .with(tag::EDGE_LENGTH, 0.25);
        h.set(tag::COMPONENT_COUNT, 2u64);
        let tags: Vec<u64> = h.fields().iter().map(|f| f.tag).collect();
        assert_eq!(tags, [2, 8, 10]);
        assert_eq!(h.get_u64(tag::COMPONENT_COUNT), Some(2));
        assert_eq!(h.get_f64(tag::EDGE_LENGTH), Some(0.25));
        assert_eq!(h.get_f64(tag::ANGLE_BITS), None, "wrong type");
        assert_eq!(h.remove(tag::ANGLE_BITS), Some(HeaderValue::U64(9)));
        assert_eq!(h.get(tag::ANGLE_BITS), None);
    }

    #[test]
    fn the_compact_box_round_trips_and_is_refused_twice() {
        let mut h = Header::new(Mode::Swing, 1, 1);
        // Not binary32 values: the long form.
        assert!(!h.set_bbox_compact([0.1, 0.0, 0.0], [1.0, 1.0, 1.0]));
        assert_eq!(h.get_bytes(tag::BBOX).map(<[u8]>::len), Some(48));
        // Rounded outward, they are: the short form, read back exactly.
        let (min, max) = box_f32_outward([0.1, -1e-9, 3.0], [1.0, 2.5e-7, 1e30]).unwrap();
        assert!(min[0] <= 0.1 && min[1] <= -1e-9 && max[1] >= 2.5e-7 && max[2] >= 1e30);
        assert!(min[0] > 0.1 - 1e-8 && max[2] < 1e30 * (1.0 + 1e-7));
        assert!(h.set_bbox_compact(min, max));
        assert_eq!(h.get(tag::BBOX), None);
        assert_eq!(h.get_bytes(tag::BBOX_F32).map(<[u8]>::len), Some(24));
        assert_eq!(h.bbox(), Some((min, max)));
        // Around zero and on negative values the rounding goes outward too.
        for x in [0.0, -0.0, 1e-50, -1e-50, -0.1, -3.0e38, 0.3] {
            let (lo, hi) = box_f32_outward([x; 3], [x; 3]).unwrap();
            assert!(lo[0] <= x && x <= hi[0], "{x}: {lo:?} {hi:?}");
            assert_eq!(f64::from(lo[0] as f32), lo[0]);
            assert_eq!(f64::from(hi[0] as f32), hi[0]);
            assert!(hi[0] - lo[0] <= x.abs() * 2.4e-7 + 3e-45, "{x}");
        }
        // Beyond the f32 range, or not finite: no short form.
        assert_eq!(box_f32_outward([0.0; 3], [1e39, 1.0, 1.0]), None);
        assert_eq!(box_f32_outward([f64::NAN, 0.0, 0.0], [1.0; 3]), None);
        // A header with both forms is refused when read, naming the problem.
        let mut both = Header::new(Mode::Swing, 1, 1);
        both.set_bbox([0.0; 3], [1.0; 3]);
        both.set(tag::BBOX_F32, vec![0u8; 24]);
        let bytes = crate::Container::new(both).to_bytes().unwrap();
        let err = crate::parse(&bytes, &crate::Limits::DEFAULT).unwrap_err();
        assert!(err.to_string().contains("twice"), "{err}");
        assert_eq!(
            check_field(tag::BBOX_F32, &vec![0u8; 23].into()).map_err(|e| e.to_string()),
            Err(FormatError::FieldValue {
                tag: tag::BBOX_F32,
                reason: "bbox_f32 must be 24 bytes (6 f32)"
            }
            .to_string())
        );
    }

    #[test]
    fn bbox_round_trip() {
        let mut h = Header::new(Mode::Exact, 0, 0);
        assert_eq!(h.bbox(), None);
        h.set_bbox([-1.0, 0.5, -0.0], [2.0, 3.0, 1e300]);
        assert_eq!(h.bbox(), Some(([-1.0, 0.5, -0.0], [2.0, 3.0, 1e300])));
        assert_eq!(h.get_bytes(tag::BBOX).map(<[u8]>::len), Some(48));
    }

    #[test]
    fn field_checks() {
        assert_eq!(check_field(tag::QUANT_BITS, &12u64.into()), Ok(()));
        assert_eq!(
            check_field(99, &HeaderValue::I64(-3)),
            Ok(()),
            "unknown optional"
        );
        assert_eq!(
            check_field(98, &1u64.into()),
            Err(FormatError::UnknownRequiredField { tag: 98 })
        );
        assert_eq!(
            check_field(tag::EDGE_LENGTH, &1u64.into()),
            Err(FormatError::FieldType {
                tag: 8,
                expected: ValueType::F64,
                found: ValueType::U64
            })
        );
        assert!(matches!(
            check_field(tag::BBOX, &vec![0u8; 47].into()),
            Err(FormatError::FieldValue { tag: 6, .. })
        ));
    }

    #[test]
    fn mode_codes() {
        for m in Mode::ALL {
            assert_eq!(Mode::try_from(m.code()).unwrap(), m);
        }
        let err = Mode::try_from(3).unwrap_err();
        assert!(matches!(err, Error::Format(FormatError::UnknownMode(3))));
        assert!(err.to_string().contains("codec mode 3"), "{err}");
    }

    #[test]
    fn unsupported_messages() {
        let newer = Error::Unsupported { major: 3, minor: 0 };
        assert_eq!(
            newer.to_string(),
            "stream format version 3.0 is newer than this whet (reads 1.x); upgrade whet"
        );
        let older = Error::Unsupported { major: 0, minor: 9 };
        assert!(older.to_string().contains("0.9 is older"), "{older}");
    }

    #[test]
    fn peek_matches_encoding() {
        let h = Header::new(Mode::Exact, 300, 600).with(tag::ENCODER, &b"whet"[..]);
        let bytes = encode_header(&h, 77).unwrap();
        let info = peek_header(&bytes).unwrap();
        assert_eq!(info.header_end, bytes.len() as u64);
        assert_eq!(info.total_len, bytes.len() as u64 + 77);
        assert_eq!((info.vertex_count, info.triangle_count), (300, 600));
    }
}
