//! PLY (Stanford Polygon File Format) 1.0 in all three encodings.
//!
//! Reads: `format ascii`, `binary_little_endian` and `binary_big_endian` (version 1.x); header
//! `comment` and `obj_info` lines; a `vertex` element whose `x`, `y`, `z` properties may sit in
//! any position and have any scalar type (`char uchar short ushort int uint float double` and
//! the `int8 ... float64` aliases), with every other property, scalar or list, skipped; an
//! optional `face` element with a `vertex_indices` (or `vertex_index`) list of any integer count
//! and index types, other face properties skipped, polygons fan-triangulated; any other element
//! (edges, materials...) skipped, before or after the vertices and faces. Ascii data is read as
//! a stream of whitespace-separated tokens, so an element need not sit on one line. Data after
//! the last element is ignored. Binary vertices whose properties are all scalars, with `x y z`
//! of one type, are decoded by a loop specialised for that type and byte order.
//!
//! Does not read: files without a vertex element, list-valued or missing coordinates, float
//! face indices, triangle strips (`tristrips`), and a face element without an index list (all
//! [`Error::Unsupported`]). Vertex normals, colours and other attributes are skipped.
//!
//! The read report ([`crate::ReadReport`]) lists what the header declares besides `x y z` and
//! the face index list, in header order, each with the element count from the header: on the
//! vertex and face elements, normals (`nx ny nz`: "vertex normals", "face normals"), colours
//! (`red green blue alpha`, also `diffuse_*`: "vertex colours", "face colours") and texture
//! coordinates (`u v`, `s t`, `texture_u`...: "texture coordinates"; a face `texcoord` list:
//! "per-corner texture coordinates"), one entry per kind, and every other property by name
//! ("vertex property `confidence`", "face property `flags`"); every other element with at
//! least one property by name ("element `edge`"). Elements with no entries or no properties
//! hold nothing and are not listed.
//!
//! Writes `double x y z` (exact round trip), optionally `double quality` and `uchar red green
//! blue`, and faces as `list uchar uint vertex_indices`, in any of the three encodings.

use std::io::{BufRead, Read, Write};

use whet_mesh::{DVec3, Mesh};

use crate::binary::{ended, BinReader, Decode};
use crate::text::{
    parse_f64, parse_i64, show, tokens, write_f64, write_face_line, LineReader, TokenReader,
    MAX_LINE,
};
use crate::{capacity, check_index, finite_point, Error, Fan, PlyEncoding, ReadReport, Skipped};

/// Longest header the reader accepts, in bytes.
const MAX_HEADER: usize = 1 << 20;
/// Longest header line the reader accepts, in bytes.
const MAX_HEADER_LINE: usize = 1 << 16;
/// Binary index lists up to this many bytes are fetched as one slice; longer ones item by item.
const MAX_LIST_BYTES: u64 = 4096;

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn from_name(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    /// The canonical PLY name of the type.
    fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }

    /// The value at the start of `b` (at least `size()` bytes).
    #[inline]
    fn f64_from(self, b: &[u8], big_endian: bool) -> f64 {
        match self {
            Scalar::I8 => i8::f64_from(b, big_endian),
            Scalar::U8 => u8::f64_from(b, big_endian),
            Scalar::I16 => i16::f64_from(b, big_endian),
            Scalar::U16 => u16::f64_from(b, big_endian),
            Scalar::I32 => i32::f64_from(b, big_endian),
            Scalar::U32 => u32::f64_from(b, big_endian),
            Scalar::F32 => f32::f64_from(b, big_endian),
            Scalar::F64 => f64::f64_from(b, big_endian),
        }
    }

    /// An integer value at the start of `b` (exact for every integer type).
    #[inline]
    fn i64_from(self, b: &[u8], big_endian: bool) -> i64 {
        self.f64_from(b, big_endian) as i64
    }
}

/// A property of an element.
#[derive(Clone, Debug)]
enum Property {
    Scalar {
        ty: Scalar,
        name: String,
    },
    List {
        count: Scalar,
        item: Scalar,
        name: String,
    },
}

impl Property {
    fn name(&self) -> &str {
        match self {
            Property::Scalar { name, .. } | Property::List { name, .. } => name,
        }
    }
}

/// An element declared in the header.
#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Ascii,
    Binary { big_endian: bool },
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
}

/// Where the mesh lives among the elements.
struct Plan {
    /// Index of the vertex element.
    vertex: usize,
    /// Index, within the vertex element, of the `x`, `y` and `z` properties.
    xyz: [usize; 3],
    /// Index of the face element and of its index list property.
    face: Option<(usize, usize)>,
    /// Declared number of vertices.
    vertex_count: usize,
}

/// Reads a PLY file and reports what it skipped.
pub(crate) fn read<R: BufRead>(reader: R) -> Result<(Mesh, ReadReport), Error> {
    let mut lines = LineReader::with_max_len(reader, MAX_HEADER_LINE);
    let header = read_header(&mut lines)?;
    let plan = plan(&header)?;
    let mesh = match header.encoding {
        Encoding::Ascii => {
            lines.set_max_len(MAX_LINE);
            read_ascii(&mut TokenReader::new(lines), &header, &plan)
        }
        Encoding::Binary { big_endian } => {
            let mut bin = BinReader::new(lines.into_inner());
            read_binary(&mut bin, &header, &plan, big_endian)
        }
    }?;
    Ok((mesh, report(&header, &plan)))
}

/// A kind of attribute PLY files name by convention.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Normals,
    Colours,
    TextureCoordinates,
}

impl Kind {
    /// The kind of property `prop` of the vertex (`face` false) or face element.
    fn of(prop: &Property, face: bool) -> Option<Kind> {
        match (prop, face) {
            (Property::Scalar { name, .. }, _) => match name.as_str() {
                "nx" | "ny" | "nz" => Some(Kind::Normals),
                "red" | "green" | "blue" | "alpha" | "diffuse_red" | "diffuse_green"
                | "diffuse_blue" | "diffuse_alpha" => Some(Kind::Colours),
                "u" | "v" | "s" | "t" | "texture_u" | "texture_v" | "texture_s" | "texture_t"
                    if !face =>
                {
                    Some(Kind::TextureCoordinates)
                }
                _ => None,
            },
            (Property::List { name, .. }, true) if name == "texcoord" => {
                Some(Kind::TextureCoordinates)
            }
            (Property::List { .. }, _) => None,
        }
    }

    /// The report entry of `count` values of this kind on the vertex or face element.
    fn skipped(self, face: bool, count: u64) -> Skipped {
        match (self, face) {
            (Kind::Normals, false) => Skipped::items("vertex normals", "vertex normal", count),
            (Kind::Normals, true) => Skipped::items("face normals", "face normal", count),
            (Kind::Colours, false) => Skipped::items("vertex colours", "vertex colour", count),
            (Kind::Colours, true) => Skipped::items("face colours", "face colour", count),
            (Kind::TextureCoordinates, false) => {
                Skipped::items("texture coordinates", "texture coordinate", count)
            }
            (Kind::TextureCoordinates, true) => Skipped::of(
                "per-corner texture coordinates".to_owned(),
                count,
                "on ",
                "face",
                "faces",
            ),
        }
    }
}

/// What the header declares besides the coordinates and the face indices (see the module
/// documentation).
fn report(header: &Header, plan: &Plan) -> ReadReport {
    let mut r = ReadReport::default();
    for (i, element) in header.elements.iter().enumerate() {
        if element.count == 0 || element.props.is_empty() {
            continue;
        }
        let face_list = plan.face.filter(|&(f, _)| f == i).map(|(_, list)| list);
        if i != plan.vertex && face_list.is_none() {
            r.push(Skipped::of(
                format!("element `{}`", element.name),
                element.count,
                "",
                "entry",
                "entries",
            ));
            continue;
        }
        let face = i != plan.vertex;
        let used = |k: usize| {
            if face {
                face_list == Some(k)
            } else {
                plan.xyz.contains(&k)
            }
        };
        // The kinds already listed, indexed by `Kind as usize`.
        let mut listed = [false; 3];
        for (k, prop) in element.props.iter().enumerate() {
            if used(k) {
                continue;
            }
            match Kind::of(prop, face) {
                Some(kind) => {
                    if !listed[kind as usize] {
                        listed[kind as usize] = true;
                        r.push(kind.skipped(face, element.count));
                    }
                }
                None => r.push(Skipped::of(
                    format!("{} property `{}`", element.name, prop.name()),
                    element.count,
                    "",
                    "value",
                    "values",
                )),
            }
        }
    }
    r
}

fn read_header<R: BufRead>(lines: &mut LineReader<R>) -> Result<Header, Error> {
    if !lines.advance()? {
        return Err(Error::truncated("the file is empty: expected a PLY header"));
    }
    if lines.current().trim_ascii() != b"ply" {
        return Err(Error::parse(
            1,
            "not a PLY file: the first line must be 'ply'",
        ));
    }
    let mut total = 4;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        if !lines.advance()? {
            return Err(Error::truncated(
                "the PLY header ended without an end_header line",
            ));
        }
        let line_no = lines.line();
        let line = lines.current();
        total += line.len() + 1;
        if total > MAX_HEADER {
            return Err(Error::parse(
                line_no,
                format!("the PLY header is longer than {MAX_HEADER} bytes"),
            ));
        }
        let mut toks = tokens(line);
        let Some(keyword) = toks.next() else { continue };
        let bad = |what: &str| Error::parse(line_no, what.to_owned());
        match keyword {
            b"comment" | b"obj_info" => {}
            b"format" => {
                let (Some(name), Some(version)) = (toks.next(), toks.next()) else {
                    return Err(bad("the format line needs an encoding and a version"));
                };
                encoding = Some(match name {
                    b"ascii" => Encoding::Ascii,
                    b"binary_little_endian" => Encoding::Binary { big_endian: false },
                    b"binary_big_endian" => Encoding::Binary { big_endian: true },
                    _ => {
                        return Err(bad(&format!("unknown PLY encoding '{}'", show(name))));
                    }
                });
                if !version.starts_with(b"1") {
                    return Err(Error::unsupported(format!("PLY version {}", show(version))));
                }
            }
            b"element" => {
                let (Some(name), Some(count)) = (toks.next(), toks.next()) else {
                    return Err(bad("an element line needs a name and a count"));
                };
                let count = parse_i64(count)
                    .and_then(|c| u64::try_from(c).ok())
                    .ok_or_else(|| {
                        bad(&format!(
                            "invalid count '{}' of element '{}'",
                            show(count),
                            show(name)
                        ))
                    })?;
                elements.push(Element {
                    name: String::from_utf8_lossy(name).into_owned(),
                    count,
                    props: Vec::new(),
                });
            }
            b"property" => {
                let Some(element) = elements.last_mut() else {
                    return Err(bad("a property line before any element line"));
                };
                let property = parse_property(toks, line_no)?;
                element.props.push(property);
            }
            b"end_header" => break,
            _ => {
                return Err(bad(&format!(
                    "unknown PLY header line starting with '{}'",
                    show(keyword)
                )));
            }
        }
    }
    let encoding =
        encoding.ok_or_else(|| Error::parse(lines.line(), "the PLY header has no format line"))?;
    Ok(Header { encoding, elements })
}

fn parse_property<'a>(
    mut toks: impl Iterator<Item = &'a [u8]>,
    line_no: usize,
) -> Result<Property, Error> {
    let ty = |tok: Option<&[u8]>| -> Result<Scalar, Error> {
        let tok = tok.ok_or_else(|| Error::parse(line_no, "incomplete property line"))?;
        Scalar::from_name(tok)
            .ok_or_else(|| Error::parse(line_no, format!("unknown PLY type '{}'", show(tok))))
    };
    let first = toks.next();
    let property = if first == Some(b"list") {
        let count = ty(toks.next())?;
        let item = ty(toks.next())?;
        if !count.is_integer() {
            return Err(Error::parse(
                line_no,
                "the count type of a list property must be an integer type",
            ));
        }
        let name = toks
            .next()
            .ok_or_else(|| Error::parse(line_no, "a list property needs a name"))?;
        Property::List {
            count,
            item,
            name: String::from_utf8_lossy(name).into_owned(),
        }
    } else {
        let ty = ty(first)?;
        let name = toks
            .next()
            .ok_or_else(|| Error::parse(line_no, "a property needs a name"))?;
        Property::Scalar {
            ty,
            name: String::from_utf8_lossy(name).into_owned(),
        }
    };
    Ok(property)
}

/// Finds the vertex coordinates and the face indices among the declared elements.
fn plan(header: &Header) -> Result<Plan, Error> {
    let elements = &header.elements;
    let vertex = elements
        .iter()
        .position(|e| e.name == "vertex")
        .ok_or_else(|| Error::unsupported("PLY file has no vertex element"))?;
    let vertex_element = &elements[vertex];
    let vertex_count = checked_count(vertex_element.count, "PLY vertex")?;
    let mut xyz = [0; 3];
    for (slot, axis) in xyz.iter_mut().zip(["x", "y", "z"]) {
        *slot = match vertex_element.props.iter().position(|p| p.name() == axis) {
            Some(i) if matches!(vertex_element.props[i], Property::Scalar { .. }) => i,
            Some(_) => {
                return Err(Error::unsupported(format!(
                    "PLY vertex property '{axis}' is a list"
                )))
            }
            None => {
                let names: Vec<&str> = vertex_element.props.iter().map(Property::name).collect();
                return Err(Error::unsupported(format!(
                    "PLY vertex element has no '{axis}' property (it has: {})",
                    names.join(", ")
                )));
            }
        };
    }
    let face = match elements.iter().position(|e| e.name == "face") {
        None => {
            if elements
                .iter()
                .any(|e| e.name == "tristrips" && e.count > 0)
            {
                return Err(Error::unsupported(
                    "PLY triangle strips (element tristrips)",
                ));
            }
            None
        }
        Some(f) => {
            let face_element = &elements[f];
            checked_count(face_element.count, "PLY face")?;
            let list = face_element.props.iter().position(|p| match p {
                Property::List { name, .. } => name == "vertex_indices" || name == "vertex_index",
                Property::Scalar { .. } => false,
            });
            let Some(list) = list else {
                return Err(Error::unsupported(
                    "PLY face element has no vertex_indices list property",
                ));
            };
            if let Property::List { item, .. } = face_element.props[list] {
                if !item.is_integer() {
                    return Err(Error::unsupported(format!(
                        "PLY face indices of type {}",
                        item.name()
                    )));
                }
            }
            Some((f, list))
        }
    };
    Ok(Plan {
        vertex,
        xyz,
        face,
        vertex_count,
    })
}

fn checked_count(count: u64, what: &str) -> Result<usize, Error> {
    u32::try_from(count)
        .map(|c| c as usize)
        .map_err(|_| Error::TooLarge {
            what: what.to_owned(),
            count,
        })
}

/// How an element's instances are called in truncation messages.
fn plural(element: &Element) -> String {
    match element.name.as_str() {
        "vertex" => "vertices".to_owned(),
        "face" => "faces".to_owned(),
        name => format!("'{name}' elements"),
    }
}

// ---------------------------------------------------------------------------------------------
// Binary

fn read_binary<R: Read>(
    bin: &mut BinReader<R>,
    header: &Header,
    plan: &Plan,
    big: bool,
) -> Result<Mesh, Error> {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for (i, element) in header.elements.iter().enumerate() {
        if i == plan.vertex {
            positions = binary_vertices(bin, element, plan.xyz, big)?;
        } else if let Some((_, list)) = plan.face.filter(|&(f, _)| f == i) {
            triangles = binary_faces(bin, element, list, big, plan.vertex_count)?;
        } else {
            binary_skip(bin, element, big)?;
        }
    }
    Ok(Mesh::new(positions, triangles))
}

fn binary_vertices<R: Read>(
    bin: &mut BinReader<R>,
    element: &Element,
    xyz: [usize; 3],
    big: bool,
) -> Result<Vec<DVec3>, Error> {
    let n = element.count;
    let mut positions = Vec::with_capacity(capacity(n));
    let all_scalar = element
        .props
        .iter()
        .all(|p| matches!(p, Property::Scalar { .. }));
    if !all_scalar {
        // General layout: walk the properties of each vertex.
        for i in 0..n {
            let mut p = [0.0; 3];
            for (k, prop) in element.props.iter().enumerate() {
                let eof = |e| ended(e, n, "vertices", i);
                match *prop {
                    Property::Scalar { ty, .. } => {
                        let b = bin.get(ty.size()).map_err(eof)?;
                        if let Some(axis) = xyz.iter().position(|&a| a == k) {
                            p[axis] = ty.f64_from(b, big);
                        }
                    }
                    Property::List { count, item, .. } => {
                        let c = list_len(bin, count, big, eof)?;
                        bin.skip(c.saturating_mul(item.size() as u64))
                            .map_err(eof)?;
                    }
                }
            }
            let index = positions.len();
            positions.push(finite_point(p[0], p[1], p[2], index)?);
        }
        return Ok(positions);
    }

    // Fixed-size records: one slice per vertex, coordinates at fixed offsets.
    let mut offsets = Vec::with_capacity(element.props.len());
    let mut stride = 0;
    for prop in &element.props {
        offsets.push(stride);
        if let Property::Scalar { ty, .. } = prop {
            stride += ty.size();
        }
    }
    let ty = |k: usize| match element.props[k] {
        Property::Scalar { ty, .. } => ty,
        // `plan` only accepts scalar coordinates.
        Property::List { count, .. } => count,
    };
    let types = xyz.map(ty);
    let offs = xyz.map(|k| offsets[k]);
    let record = Record { n, stride, offs };
    macro_rules! fixed {
        ($t:ty) => {
            if big {
                record.read::<$t, true, R>(bin, &mut positions)
            } else {
                record.read::<$t, false, R>(bin, &mut positions)
            }
        };
    }
    if types[0] == types[1] && types[1] == types[2] {
        match types[0] {
            Scalar::I8 => fixed!(i8),
            Scalar::U8 => fixed!(u8),
            Scalar::I16 => fixed!(i16),
            Scalar::U16 => fixed!(u16),
            Scalar::I32 => fixed!(i32),
            Scalar::U32 => fixed!(u32),
            Scalar::F32 => fixed!(f32),
            Scalar::F64 => fixed!(f64),
        }?;
    } else {
        for i in 0..n {
            let rec = bin.get(stride).map_err(|e| ended(e, n, "vertices", i))?;
            let [x, y, z] = [0, 1, 2].map(|a| types[a].f64_from(&rec[offs[a]..], big));
            let index = positions.len();
            positions.push(finite_point(x, y, z, index)?);
        }
    }
    Ok(positions)
}

/// `n` fixed-size vertex records of `stride` bytes with x, y, z at `offs`.
struct Record {
    n: u64,
    stride: usize,
    offs: [usize; 3],
}

impl Record {
    /// Reads the records whose coordinates are all of type `T` in byte order `BIG`.
    fn read<T: Decode, const BIG: bool, R: Read>(
        &self,
        bin: &mut BinReader<R>,
        positions: &mut Vec<DVec3>,
    ) -> Result<(), Error> {
        let [ox, oy, oz] = self.offs;
        for i in 0..self.n {
            let rec = bin
                .get(self.stride)
                .map_err(|e| ended(e, self.n, "vertices", i))?;
            let p = DVec3::new(
                T::f64_from(&rec[ox..], BIG),
                T::f64_from(&rec[oy..], BIG),
                T::f64_from(&rec[oz..], BIG),
            );
            if !p.is_finite() {
                return Err(Error::NonFinite {
                    vertex: positions.len(),
                });
            }
            positions.push(p);
        }
        Ok(())
    }
}

/// Reads a list length of type `count`, refusing negative ones.
fn list_len<R: Read>(
    bin: &mut BinReader<R>,
    count: Scalar,
    big: bool,
    eof: impl FnOnce(std::io::Error) -> Error,
) -> Result<u64, Error> {
    let c = count.i64_from(bin.get(count.size()).map_err(eof)?, big);
    u64::try_from(c).map_err(|_| Error::parse(0, format!("negative list length {c}")))
}

fn binary_faces<R: Read>(
    bin: &mut BinReader<R>,
    element: &Element,
    list: usize,
    big: bool,
    vertex_count: usize,
) -> Result<Vec<[u32; 3]>, Error> {
    let n = element.count;
    let mut triangles = Vec::with_capacity(capacity(n));
    for face in 0..n {
        // face < n <= u32::MAX (checked by `plan`).
        let face_index = face as usize;
        for (k, prop) in element.props.iter().enumerate() {
            let eof = |e| ended(e, n, "faces", face);
            match *prop {
                Property::Scalar { ty, .. } => {
                    bin.get(ty.size()).map_err(eof)?;
                }
                Property::List { count, item, .. } => {
                    let c = list_len(bin, count, big, eof)?;
                    let size = item.size();
                    if k != list {
                        bin.skip(c.saturating_mul(size as u64)).map_err(eof)?;
                        continue;
                    }
                    if c < 3 {
                        return Err(Error::parse(
                            0,
                            format!("face {face} has {c} vertices; at least 3 are needed"),
                        ));
                    }
                    let mut fan = Fan::new();
                    if c * (size as u64) <= MAX_LIST_BYTES {
                        // c <= MAX_LIST_BYTES, so it fits usize.
                        let bytes = bin.get(c as usize * size).map_err(eof)?;
                        for chunk in bytes.chunks_exact(size) {
                            let index = item.i64_from(chunk, big);
                            fan.push(
                                check_index(index, face_index, vertex_count)?,
                                &mut triangles,
                            );
                        }
                    } else {
                        for _ in 0..c {
                            let index = item.i64_from(bin.get(size).map_err(eof)?, big);
                            fan.push(
                                check_index(index, face_index, vertex_count)?,
                                &mut triangles,
                            );
                        }
                    }
                }
            }
        }
    }
    Ok(triangles)
}

fn binary_skip<R: Read>(bin: &mut BinReader<R>, element: &Element, big: bool) -> Result<(), Error> {
    if element.props.is_empty() {
        return Ok(());
    }
    let n = element.count;
    let what = plural(element);
    for i in 0..n {
        for prop in &element.props {
            let eof = |e| ended(e, n, &what, i);
            match *prop {
                Property::Scalar { ty, .. } => {
                    bin.get(ty.size()).map_err(eof)?;
                }
                Property::List { count, item, .. } => {
                    let c = list_len(bin, count, big, eof)?;
                    bin.skip(c.saturating_mul(item.size() as u64))
                        .map_err(eof)?;
                }
            }
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Ascii

fn read_ascii<R: BufRead>(
    toks: &mut TokenReader<R>,
    header: &Header,
    plan: &Plan,
) -> Result<Mesh, Error> {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for (i, element) in header.elements.iter().enumerate() {
        if i == plan.vertex {
            positions = ascii_vertices(toks, element, plan.xyz)?;
        } else if let Some((_, list)) = plan.face.filter(|&(f, _)| f == i) {
            triangles = ascii_faces(toks, element, list, plan.vertex_count)?;
        } else {
            ascii_skip(toks, element)?;
        }
    }
    Ok(Mesh::new(positions, triangles))
}

/// The next token, or [`Error::Truncated`] naming the element being read.
fn need<'a, R: BufRead>(
    toks: &'a mut TokenReader<R>,
    expected: u64,
    what: &str,
    got: u64,
) -> Result<&'a [u8], Error> {
    toks.next_token()?.ok_or_else(|| {
        Error::truncated(format!(
            "expected {expected} {what}, file ended after {got}"
        ))
    })
}

/// Reads a list length token.
fn ascii_list_len<R: BufRead>(
    toks: &mut TokenReader<R>,
    expected: u64,
    what: &str,
    got: u64,
) -> Result<u64, Error> {
    let tok = need(toks, expected, what, got)?;
    match parse_i64(tok).and_then(|c| u64::try_from(c).ok()) {
        Some(c) => Ok(c),
        None => {
            let shown = show(tok);
            Err(Error::parse(
                toks.line(),
                format!("invalid list length '{shown}'"),
            ))
        }
    }
}

fn ascii_vertices<R: BufRead>(
    toks: &mut TokenReader<R>,
    element: &Element,
    xyz: [usize; 3],
) -> Result<Vec<DVec3>, Error> {
    let n = element.count;
    let mut positions = Vec::with_capacity(capacity(n));
    let axis_of: Vec<Option<usize>> = (0..element.props.len())
        .map(|k| xyz.iter().position(|&a| a == k))
        .collect();
    for i in 0..n {
        let mut p = [0.0; 3];
        for (prop, axis) in element.props.iter().zip(&axis_of) {
            match prop {
                Property::Scalar { name, .. } => {
                    let tok = need(toks, n, "vertices", i)?;
                    if let Some(axis) = *axis {
                        match parse_f64(tok) {
                            Some(v) => p[axis] = v,
                            None => {
                                let shown = show(tok);
                                return Err(Error::parse(
                                    toks.line(),
                                    format!(
                                        "invalid value '{shown}' for property {name} of vertex {i}"
                                    ),
                                ));
                            }
                        }
                    }
                }
                Property::List { .. } => {
                    let c = ascii_list_len(toks, n, "vertices", i)?;
                    for _ in 0..c {
                        need(toks, n, "vertices", i)?;
                    }
                }
            }
        }
        let index = positions.len();
        positions.push(finite_point(p[0], p[1], p[2], index)?);
    }
    Ok(positions)
}

fn ascii_faces<R: BufRead>(
    toks: &mut TokenReader<R>,
    element: &Element,
    list: usize,
    vertex_count: usize,
) -> Result<Vec<[u32; 3]>, Error> {
    let n = element.count;
    let mut triangles = Vec::with_capacity(capacity(n));
    for face in 0..n {
        // face < n <= u32::MAX (checked by `plan`).
        let face_index = face as usize;
        for (k, prop) in element.props.iter().enumerate() {
            match prop {
                Property::Scalar { .. } => {
                    need(toks, n, "faces", face)?;
                }
                Property::List { .. } => {
                    let c = ascii_list_len(toks, n, "faces", face)?;
                    if k != list {
                        for _ in 0..c {
                            need(toks, n, "faces", face)?;
                        }
                        continue;
                    }
                    if c < 3 {
                        return Err(Error::parse(
                            toks.line(),
                            format!("face {face} has {c} vertices; at least 3 are needed"),
                        ));
                    }
                    let mut fan = Fan::new();
                    for _ in 0..c {
                        let tok = need(toks, n, "faces", face)?;
                        let Some(index) = parse_i64(tok) else {
                            let shown = show(tok);
                            return Err(Error::parse(
                                toks.line(),
                                format!("invalid vertex index '{shown}' in face {face}"),
                            ));
                        };
                        fan.push(
                            check_index(index, face_index, vertex_count)?,
                            &mut triangles,
                        );
                    }
                }
            }
        }
    }
    Ok(triangles)
}

fn ascii_skip<R: BufRead>(toks: &mut TokenReader<R>, element: &Element) -> Result<(), Error> {
    if element.props.is_empty() {
        return Ok(());
    }
    let n = element.count;
    let what = plural(element);
    for i in 0..n {
        for prop in &element.props {
            match prop {
                Property::Scalar { .. } => {
                    need(toks, n, &what, i)?;
                }
                Property::List { .. } => {
                    let c = ascii_list_len(toks, n, &what, i)?;
                    for _ in 0..c {
                        need(toks, n, &what, i)?;
                    }
                }
            }
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Writer

/// Writes `mesh` as PLY; `quality` and `colors` are empty or hold one entry per vertex
/// (checked by the caller).
pub(crate) fn write<W: Write>(
    w: &mut W,
    mesh: &Mesh,
    quality: &[f64],
    colors: &[[u8; 3]],
    encoding: PlyEncoding,
) -> std::io::Result<()> {
    let format = match encoding {
        PlyEncoding::Ascii => "ascii",
        PlyEncoding::BinaryLittleEndian => "binary_little_endian",
        PlyEncoding::BinaryBigEndian => "binary_big_endian",
    };
    writeln!(w, "ply\nformat {format} 1.0\ncomment written by whet")?;
    writeln!(w, "element vertex {}", mesh.positions.len())?;
    writeln!(w, "property double x\nproperty double y\nproperty double z")?;
    if !quality.is_empty() {
        writeln!(w, "property double quality")?;
    }
    if !colors.is_empty() {
        writeln!(
            w,
            "property uchar red\nproperty uchar green\nproperty uchar blue"
        )?;
    }
    writeln!(w, "element face {}", mesh.triangles.len())?;
    writeln!(w, "property list uchar uint vertex_indices\nend_header")?;

    match encoding {
        PlyEncoding::Ascii => {
            for (i, p) in mesh.positions.iter().enumerate() {
                write_f64(w, p.x)?;
                w.write_all(b" ")?;
                write_f64(w, p.y)?;
                w.write_all(b" ")?;
                write_f64(w, p.z)?;
                if let Some(&q) = quality.get(i) {
                    w.write_all(b" ")?;
                    write_f64(w, q)?;
                }
                if let Some([r, g, b]) = colors.get(i) {
                    write!(w, " {r} {g} {b}")?;
                }
                w.write_all(b"\n")?;
            }
            for t in &mesh.triangles {
                write_face_line(w, b"3", t.map(u64::from))?;
            }
        }
        PlyEncoding::BinaryLittleEndian | PlyEncoding::BinaryBigEndian => {
            let big = encoding == PlyEncoding::BinaryBigEndian;
            let f = |x: f64| {
                if big {
                    x.to_be_bytes()
                } else {
                    x.to_le_bytes()
                }
            };
            let u = |x: u32| {
                if big {
                    x.to_be_bytes()
                } else {
                    x.to_le_bytes()
                }
            };
            let mut rec = Vec::with_capacity(35);
            for (i, p) in mesh.positions.iter().enumerate() {
                rec.clear();
                rec.extend_from_slice(&f(p.x));
                rec.extend_from_slice(&f(p.y));
                rec.extend_from_slice(&f(p.z));
                if let Some(&q) = quality.get(i) {
                    rec.extend_from_slice(&f(q));
                }
                if let Some(rgb) = colors.get(i) {
                    rec.extend_from_slice(rgb);
                }
                w.write_all(&rec)?;
            }
            let mut rec = [0u8; 13];
            rec[0] = 3;
            for t in &mesh.triangles {
                for (k, &v) in t.iter().enumerate() {
                    rec[1 + 4 * k..5 + 4 * k].copy_from_slice(&u(v));
                }
                w.write_all(&rec)?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read<R: BufRead>(reader: R) -> Result<Mesh, Error> {
        super::read(reader).map(|(mesh, _)| mesh)
    }

    fn tetra() -> Mesh {
        Mesh::new(
            vec![
                DVec3::new(0.1, -0.0, 1e-300),
                DVec3::new(1.0 / 3.0, 2e20, -7.25),
                DVec3::new(1.0, 2.0, 3.0),
                DVec3::new(-5.0, 0.5, f64::MIN_POSITIVE),
            ],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
        )
    }

    fn bits(m: &Mesh) -> Vec<[u64; 3]> {
        m.positions
            .iter()
            .map(|p| p.to_array().map(f64::to_bits))
            .collect()
    }

    #[test]
    fn round_trip_every_encoding() {
        let m = tetra();
        for enc in [
            PlyEncoding::Ascii,
            PlyEncoding::BinaryLittleEndian,
            PlyEncoding::BinaryBigEndian,
        ] {
            let mut out = Vec::new();
            write(&mut out, &m, &[], &[], enc).unwrap();
            let back = read(&out[..]).unwrap();
            assert_eq!(bits(&back), bits(&m), "{enc:?}");
            assert_eq!(back.triangles, m.triangles, "{enc:?}");
        }
    }

    #[test]
    fn quality_and_colours_are_skipped_on_read() {
        let m = tetra();
        for enc in [PlyEncoding::Ascii, PlyEncoding::BinaryBigEndian] {
            let mut out = Vec::new();
            let q = [0.5, f64::NAN, 2.0, 3.0];
            let c = [[255, 0, 0], [0, 255, 0], [0, 0, 255], [1, 2, 3]];
            write(&mut out, &m, &q, &c, enc).unwrap();
            let text = String::from_utf8_lossy(&out);
            assert!(text.contains("property double quality\nproperty uchar red\n"));
            let back = read(&out[..]).unwrap();
            assert_eq!(bits(&back), bits(&m));
            assert_eq!(back.triangles, m.triangles);
        }
    }

    #[test]
    fn report_lists_normals_colours_properties_and_elements() {
        let header = "comment normals, colours, a confidence, face colours and flags, edges\n\
            element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
            property float nx\nproperty float ny\nproperty float nz\n\
            property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n\
            property float confidence\n\
            element face 2\nproperty list uchar int vertex_indices\n\
            property uchar red\nproperty uchar green\nproperty uchar blue\nproperty int flags\n\
            element edge 1\nproperty int vertex1\nproperty int vertex2\n\
            element material 0\nproperty uchar ambient_red\nelement empty 5\n";
        let ascii_file = format!(
            "ply\nformat ascii 1.0\n{header}end_header\n\
             0 0 0 0 0 1 255 0 0 255 0.5\n1 0 0 0 0 1 0 255 0 255 0.25\n\
             0 1 0 0 0 1 0 0 255 255 1\n\
             3 0 1 2 9 9 9 7\n3 0 2 1 8 8 8 6\n0 1\n"
        );
        let binary = binary_file(true, header, |out, big| {
            for (x, y) in [(0.0f32, 0.0f32), (1.0, 0.0), (0.0, 1.0)] {
                for c in [x, y, 0.0, 0.0, 0.0, 1.0] {
                    put(out, c.to_le_bytes(), big);
                }
                out.extend_from_slice(&[1, 2, 3, 255]);
                put(out, 0.5f32.to_le_bytes(), big);
            }
            for tri in [[0i32, 1, 2], [0, 2, 1]] {
                out.push(3);
                for i in tri {
                    put(out, i.to_le_bytes(), big);
                }
                out.extend_from_slice(&[9, 9, 9]);
                put(out, 7i32.to_le_bytes(), big);
            }
            put(out, 0i32.to_le_bytes(), big);
            put(out, 1i32.to_le_bytes(), big);
        });
        for file in [ascii_file.into_bytes(), binary] {
            let (mesh, report) = super::read(&file[..]).unwrap();
            assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 1]]);
            assert_eq!(
                report.pairs(),
                vec![
                    ("vertex normals", 3),
                    ("vertex colours", 3),
                    ("vertex property `confidence`", 3),
                    ("face colours", 2),
                    ("face property `flags`", 2),
                    ("element `edge`", 1),
                ]
            );
            assert_eq!(
                report.to_string(),
                "3 vertex normals, 3 vertex colours, vertex property `confidence` (3 values), \
                 2 face colours, face property `flags` (2 values) and element `edge` (1 entry)"
            );
        }
    }

    #[test]
    fn report_of_texture_coordinates_and_of_a_plain_file() {
        let file = ascii(&[
            "element vertex 3",
            XYZ,
            "property float s",
            "property float t",
            "element face 1",
            "property list uchar int vertex_indices",
            "property list uchar float texcoord",
            "end_header",
            "0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 1",
            "3 0 1 2 6 0 0 1 0 0 1",
        ]);
        let (_, report) = super::read(&file[..]).unwrap();
        assert_eq!(
            report.pairs(),
            vec![
                ("texture coordinates", 3),
                ("per-corner texture coordinates", 1)
            ]
        );
        assert_eq!(
            report.to_string(),
            "3 texture coordinates and per-corner texture coordinates (on 1 face)"
        );
        let mut out = Vec::new();
        write(
            &mut out,
            &tetra(),
            &[],
            &[],
            PlyEncoding::BinaryLittleEndian,
        )
        .unwrap();
        assert!(super::read(&out[..]).unwrap().1.is_empty());
    }

    #[test]
    fn odd_layout_ascii() {
        let text = "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nobj_info x\r\n\
            element material 1\r\nproperty uchar r\r\nproperty list uchar float weights\r\n\
            element vertex 4\r\nproperty float z\r\nproperty list uint8 int32 tags\r\n\
            property uchar red\r\nproperty double x\r\nproperty short y\r\n\
            element face 2\r\nproperty uchar flags\r\nproperty list uchar int vertex_index\r\n\
            property float area\r\n\
            element edge 1\r\nproperty int vertex1\r\nproperty int vertex2\r\nend_header\r\n\
            7 2 0.5 0.25\r\n\
            1 2 7 8 200 0 0\r\n\
            2 0 9 1.5 1\r\n3 1 2 3 0 1\r\n\
            4 0 5 0 1\r\n\
            0 3 0 1 2 0.5\r\n1 4 0 1 2 3 1e-3\r\n\
            0 1\r\n";
        let m = read(text.as_bytes()).unwrap();
        assert_eq!(
            m.positions,
            vec![
                DVec3::new(0.0, 0.0, 1.0),
                DVec3::new(1.5, 1.0, 2.0),
                DVec3::new(0.0, 1.0, 3.0),
                DVec3::new(0.0, 1.0, 4.0),
            ]
        );
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 1, 2], [0, 2, 3]]);
    }

    fn binary_file(big: bool, header: &str, body: impl FnOnce(&mut Vec<u8>, bool)) -> Vec<u8> {
        let enc = if big {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let mut out = format!("ply\nformat {enc} 1.0\n{header}end_header\n").into_bytes();
        body(&mut out, big);
        out
    }

    fn put<const N: usize>(out: &mut Vec<u8>, le: [u8; N], big: bool) {
        let mut b = le;
        if big {
            b.reverse();
        }
        out.extend_from_slice(&b);
    }

    #[test]
    fn odd_layout_binary() {
        let header = "element edge 2\nproperty int a\nproperty list uchar ushort ids\n\
            element vertex 3\nproperty uchar red\nproperty float z\nproperty list ushort double n\n\
            property int x\nproperty int16 y\n\
            element face 1\nproperty list uint32 uint16 vertex_indices\nproperty double quality\n";
        for big in [false, true] {
            let file = binary_file(big, header, |out, big| {
                for e in 0..2u16 {
                    put(out, 5i32.to_le_bytes(), big);
                    out.push(2);
                    put(out, e.to_le_bytes(), big);
                    put(out, 9u16.to_le_bytes(), big);
                }
                for v in 0..3i32 {
                    out.push(255);
                    put(out, (v as f32 * 0.5).to_le_bytes(), big);
                    put(out, 1u16.to_le_bytes(), big);
                    put(out, 7.0f64.to_le_bytes(), big);
                    put(out, (-v).to_le_bytes(), big);
                    put(out, (v as i16 * 100).to_le_bytes(), big);
                }
                put(out, 4u32.to_le_bytes(), big);
                for i in [2u16, 1, 0, 1] {
                    put(out, i.to_le_bytes(), big);
                }
                put(out, 1.0f64.to_le_bytes(), big);
            });
            let m = read(&file[..]).unwrap();
            assert_eq!(
                m.positions,
                vec![
                    DVec3::new(0.0, 0.0, 0.0),
                    DVec3::new(-1.0, 100.0, 0.5),
                    DVec3::new(-2.0, 200.0, 1.0),
                ],
                "big {big}"
            );
            assert_eq!(m.triangles, vec![[2, 1, 0], [2, 0, 1]]);
        }
    }

    #[test]
    fn fixed_layouts_of_every_type() {
        for ty in [
            "char", "uchar", "short", "ushort", "int", "uint", "float", "double",
        ] {
            for big in [false, true] {
                let header = format!(
                    "element vertex 2\nproperty {ty} x\nproperty {ty} y\nproperty {ty} z\n\
                     element face 0\nproperty list uchar int vertex_indices\n"
                );
                let file = binary_file(big, &header, |out, big| {
                    let size = Scalar::from_name(ty.as_bytes()).unwrap().size();
                    for v in [1u8, 2, 3, 4, 5, 6] {
                        let mut le = vec![0u8; size];
                        match ty {
                            "float" => le.copy_from_slice(&f32::from(v).to_le_bytes()),
                            "double" => le.copy_from_slice(&f64::from(v).to_le_bytes()),
                            _ => le[0] = v,
                        }
                        if big {
                            le.reverse();
                        }
                        out.extend_from_slice(&le);
                    }
                });
                let m = read(&file[..]).unwrap();
                assert_eq!(
                    m.positions,
                    vec![DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, 5.0, 6.0)],
                    "{ty} big {big}"
                );
            }
        }
    }

    /// An ascii PLY file made of `lines`, after the `ply` and `format` lines.
    fn ascii(lines: &[&str]) -> Vec<u8> {
        format!("ply\nformat ascii 1.0\n{}\n", lines.join("\n")).into_bytes()
    }

    const XYZ: &str = "property float x\nproperty float y\nproperty float z";

    #[test]
    fn header_errors() {
        let e = read(&b"plx\n"[..]).unwrap_err();
        assert!(matches!(e, Error::Parse { line: 1, .. }), "{e}");
        let e = read(&ascii(&["element vertex 1", "property foo x", "end_header"])[..]);
        assert!(matches!(e, Err(Error::Parse { line: 4, .. })), "{e:?}");
        let file = ascii(&[
            "element face 0",
            "property list uchar int vertex_indices",
            "end_header",
        ]);
        let e = read(&file[..]).unwrap_err();
        assert!(matches!(e, Error::Unsupported { .. }), "{e}");
        let file = ascii(&[
            "element vertex 0",
            "property float x",
            "property float y",
            "end_header",
        ]);
        let e = read(&file[..]).unwrap_err();
        assert!(
            matches!(&e, Error::Unsupported { what } if what.contains("'z'")),
            "{e}"
        );
        let e = read(&b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\n"[..]);
        assert!(matches!(e, Err(Error::Truncated { .. })), "{e:?}");
        let e = read(&b"ply\nelement vertex 0\nend_header\n"[..]).unwrap_err();
        assert!(matches!(e, Error::Parse { .. }), "{e}");
        let file = ascii(&[
            "element vertex 4000000000",
            XYZ,
            "end_header",
            "0 0 0 1 1 1",
        ]);
        let e = read(&file[..]).unwrap_err();
        assert!(matches!(e, Error::Truncated { .. }), "{e}");
        let file = ascii(&["element vertex 5000000000", XYZ, "end_header"]);
        let e = read(&file[..]).unwrap_err();
        assert!(
            matches!(
                e,
                Error::TooLarge {
                    count: 5_000_000_000,
                    ..
                }
            ),
            "{e}"
        );
    }

    #[test]
    fn body_errors() {
        let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
                    property float y\nproperty float z\nelement face 1\n\
                    property list uchar int vertex_indices\nend_header\n";
        let ok = format!("{head}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
        assert_eq!(read(ok.as_bytes()).unwrap().triangles, vec![[0, 1, 2]]);
        let e = read(format!("{head}0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n").as_bytes()).unwrap_err();
        assert!(
            matches!(
                e,
                Error::IndexOutOfRange {
                    face: 0,
                    index: 3,
                    vertex_count: 3
                }
            ),
            "{e}"
        );
        let e = read(format!("{head}0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n").as_bytes()).unwrap_err();
        assert!(matches!(e, Error::IndexOutOfRange { index: -1, .. }), "{e}");
        let e = read(format!("{head}0 0 0\n1 0 0\n0 1 0\n2 0 1\n").as_bytes()).unwrap_err();
        assert!(matches!(e, Error::Parse { line: 13, .. }), "{e}");
        let e = read(format!("{head}0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n").as_bytes()).unwrap_err();
        assert!(matches!(e, Error::NonFinite { vertex: 1 }), "{e}");
        let e = read(format!("{head}0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n").as_bytes()).unwrap_err();
        assert!(matches!(e, Error::Parse { line: 11, .. }), "{e}");
        let e = read(format!("{head}0 0 0\n1 0 0\n").as_bytes()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "file is truncated: expected 3 vertices, file ended after 2"
        );
    }

    #[test]
    fn absurd_binary_counts() {
        let header =
            "element vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\n";
        let file = binary_file(false, header, |out, _| out.extend_from_slice(&[0; 10]));
        let e = read(&file[..]).unwrap_err();
        assert!(
            matches!(&e, Error::Truncated { what } if what.contains("4000000000 vertices")),
            "{e}"
        );
        let header = "element vertex 0\nproperty float x\nproperty float y\nproperty float z\n\
                      element face 1\nproperty list uint int vertex_indices\n";
        let file = binary_file(false, header, |out, _| {
            out.extend_from_slice(&u32::MAX.to_le_bytes());
            out.extend_from_slice(&[0; 10]);
        });
        let e = read(&file[..]).unwrap_err();
        assert!(
            matches!(e, Error::Truncated { .. } | Error::IndexOutOfRange { .. }),
            "{e}"
        );
        let header = "element vertex 0\nproperty float x\nproperty float y\nproperty float z\n\
                      element junk 9223372036854775807\nelement face 0\n\
                      property list uchar int vertex_indices\n";
        let file = binary_file(false, header, |_, _| {});
        assert_eq!(read(&file[..]).unwrap(), Mesh::default());
    }

    #[test]
    fn binary_face_errors() {
        let header = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                      element face 1\nproperty list char int vertex_indices\n";
        let body = |count: i8, last: i32| {
            binary_file(true, header, move |out, big| {
                for _ in 0..9 {
                    put(out, 0.5f32.to_le_bytes(), big);
                }
                out.push(count as u8);
                for i in [0, 1, last] {
                    put(out, i.to_le_bytes(), big);
                }
            })
        };
        assert_eq!(read(&body(3, 2)[..]).unwrap().triangles, vec![[0, 1, 2]]);
        let e = read(&body(3, 7)[..]).unwrap_err();
        assert!(matches!(e, Error::IndexOutOfRange { index: 7, .. }), "{e}");
        let e = read(&body(2, 2)[..]).unwrap_err();
        assert!(matches!(e, Error::Parse { line: 0, .. }), "{e}");
        let e = read(&body(-1, 2)[..]).unwrap_err();
        assert!(matches!(e, Error::Parse { line: 0, .. }), "{e}");
        let e = read(&body(4, 2)[..]).unwrap_err();
        assert!(matches!(e, Error::Truncated { .. }), "{e}");
    }
}
