//! Stanford PLY reader (`ascii`, `binary_little_endian`,
//! `binary_big_endian`) and writer (binary little endian).
//!
//! Hand-written rather than built on `ply-rs-bw` so that every error names
//! the file, line or byte offset, element and index, and so that no
//! allocation is ever sized by a header count: capacities are capped by what
//! the remaining bytes can hold, and lists are read item by item.
//!
//! Read: `vertex` (`x`, `y`, `z` of any numeric type), `face` (list
//! `vertex_indices` or `vertex_index`, any polygon size, triangulated by
//! [`super::triangulate_polygon`]), `tristrips` (list `vertex_indices`,
//! `-1` restarts, odd triangles flipped). Vertex property streams, each
//! component of any scalar type:
//!
//! - normals `nx ny nz`;
//! - texture coordinates `texture_u texture_v`, `u v`, `s t` or
//!   `texture_s texture_t` (the first of these pairs declared whole), `v`
//!   up as in OBJ;
//! - colours `red green blue [alpha]`, `r g b [a]` or `diffuse_red
//!   diffuse_green diffuse_blue [diffuse_alpha]`: integer types divided by
//!   their largest value (`uchar` by 255, `ushort` by 65535), floats taken
//!   as they are; no alpha is 1.
//!
//! A stream is read only when every component it needs is declared: a lone
//! `nx`, or `u` without `v`, is skipped like any unknown property. A
//! component declared as a list is an error. The first header line
//! `comment TextureFile name.png` (MeshLab writes it) names the texture the
//! coordinates sample, resolved against the PLY file's folder; it is kept
//! only with texture coordinates. Per-face properties (colours, normals,
//! MeshLab's per-corner `texcoord` lists) are ignored. Every other element
//! and property is skipped according to its declared type, list properties
//! included.

use crate::error::{Error, Place, Result};
use crate::mesh::{Mesh, RawMesh, Texture};
use glam::{Vec2, Vec3, Vec4};
use std::path::Path;

/// Longest header accepted, in bytes; real headers are a few hundred.
const MAX_HEADER_BYTES: usize = 64 * 1024;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    BinaryLittle,
    BinaryBig,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
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
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
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

    /// What a colour channel of this type is multiplied by to bring it to
    /// 0..=1: the reciprocal of the type's largest value, 1 for floats.
    fn color_scale(self) -> f64 {
        1.0 / match self {
            Scalar::I8 => f64::from(i8::MAX),
            Scalar::U8 => f64::from(u8::MAX),
            Scalar::I16 => f64::from(i16::MAX),
            Scalar::U16 => f64::from(u16::MAX),
            Scalar::I32 => f64::from(i32::MAX),
            Scalar::U32 => f64::from(u32::MAX),
            Scalar::F32 | Scalar::F64 => 1.0,
        }
    }
}

#[derive(Debug, Clone)]
enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug, Clone)]
struct Property {
    name: String,
    kind: Kind,
    /// Its header line.
    line: u64,
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
    line: u64,
}

impl Element {
    /// Fewest bytes one instance can take in a binary file.
    fn min_binary_size(&self) -> usize {
        self.properties
            .iter()
            .map(|p| match p.kind {
                Kind::Scalar(s) => s.size(),
                Kind::List { count, .. } => count.size(),
            })
            .sum()
    }
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Offset of the first data byte.
    data_start: usize,
    /// Line number of the first data line (ascii).
    data_line: u64,
    /// The first `comment TextureFile` name, as written.
    texture: Option<String>,
}

/// Parses PLY bytes into a raw mesh, with the vertex property streams the
/// header declares (see the module docs); `path` names the file in errors
/// and is the folder a `TextureFile` is resolved against.
///
/// # Errors
/// [`Error::UnknownFormat`] without the `ply` magic or with an unknown
/// `format`; [`Error::Parse`] with line (ascii and header) or byte offset
/// (binary), element and index for a malformed header (a property stream
/// component or an index declared with the wrong kind of type: the
/// property's line), truncated data, non-numeric tokens, NaN or infinite
/// coordinates, normals, texture coordinates or colours (the line or byte
/// of the value), indices out of range, and header counts larger than the
/// data.
///
/// Cost: O(file size); memory O(vertices + triangles) actually present.
pub fn parse_ply(bytes: &[u8], path: &Path) -> Result<RawMesh> {
    let header = parse_header(bytes, path)?;
    let mut reader = match header.encoding {
        Encoding::Ascii => Reader::Ascii(AsciiReader {
            bytes,
            pos: header.data_start,
            line: header.data_line,
        }),
        Encoding::BinaryLittle | Encoding::BinaryBig => Reader::Binary(BinaryReader {
            bytes,
            pos: header.data_start,
            big_endian: header.encoding == Encoding::BinaryBig,
        }),
    };
    let file = path.to_owned();
    let vertex_count = header
        .elements
        .iter()
        .find(|e| e.name == "vertex")
        .map(|e| e.count)
        .ok_or_else(|| Error::Parse {
            file: file.to_owned(),
            place: Place::line(1),
            message: "no `vertex` element in the header".into(),
        })?;
    let mut raw = RawMesh::default();
    for element in &header.elements {
        read_element(&mut reader, element, vertex_count, &mut raw, &file)?;
    }
    if let (Some(name), Some(_)) = (&header.texture, &raw.properties.uvs) {
        let folder = path.parent().unwrap_or(Path::new(""));
        raw.properties.texture = Some(Texture::File(folder.join(name)));
    }
    // What follows the last element is not part of the mesh: a wrong count
    // in the header, or two files run together. Whitespace ends ASCII data.
    let trailing = |at: usize, line: Option<u64>| Error::Parse {
        file: file.clone(),
        place: Place {
            line,
            ..Place::default()
        }
        .at_byte(at as u64),
        message: format!(
            "{} bytes after the data of the header's elements (do the header's counts match \
             the data?)",
            bytes.len() - at
        ),
    };
    match &reader {
        Reader::Ascii(r) => {
            let rest = &bytes[r.pos.min(bytes.len())..];
            if let Some(k) = rest.iter().position(|b| !b.is_ascii_whitespace()) {
                let line = r.line + rest[..k].iter().filter(|&&b| b == b'\n').count() as u64;
                return Err(trailing(r.pos + k, Some(line)));
            }
        }
        Reader::Binary(r) => {
            if r.pos < bytes.len() {
                return Err(trailing(r.pos, None));
            }
        }
    }
    // No triangle of three distinct vertices: no mesh, said where the data
    // starts (clean would say it of the whole file).
    if raw.triangles.iter().all(|&t| crate::mesh::is_degenerate(t)) {
        let place = match header.encoding {
            Encoding::Ascii => Place::line(header.data_line),
            _ => Place::default(),
        }
        .at_byte(header.data_start as u64);
        return Err(Error::Parse {
            file,
            place,
            message: format!(
                "the data from here holds no face of three distinct vertices ({} faces or \
                 strip triangles, {} dropped as degenerate)",
                raw.triangles.len(),
                raw.degenerate_in_source
            ),
        });
    }
    Ok(raw)
}

fn parse_header(bytes: &[u8], path: &Path) -> Result<Header> {
    let unknown = |message: &str| Error::UnknownFormat {
        file: path.to_owned(),
        message: message.to_owned(),
    };
    let bad = |line: u64, message: String| Error::Parse {
        file: path.to_owned(),
        place: Place::line(line),
        message,
    };
    if !(bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n")) {
        return Err(unknown("not a PLY file: line 1 is not `ply`"));
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut texture = None;
    let mut pos = 0usize;
    let mut line_no = 0u64;
    loop {
        if pos >= bytes.len() || pos > MAX_HEADER_BYTES {
            return Err(bad(line_no + 1, "header has no `end_header` line".into()));
        }
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| pos + i);
        let line = String::from_utf8_lossy(&bytes[pos..end]);
        line_no += 1;
        pos = (end + 1).min(bytes.len());
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["ply"] if line_no == 1 => {}
            ["comment", tag, ..] if tag.eq_ignore_ascii_case("TextureFile") => {
                // The rest of the line, inner spaces kept.
                let name = line.trim_start()["comment".len()..].trim_start()[tag.len()..].trim();
                if texture.is_none() && !name.is_empty() {
                    texture = Some(name.to_owned());
                }
            }
            [] | ["comment", ..] | ["obj_info", ..] => {}
            ["format", f, _version] => {
                encoding = Some(match *f {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::BinaryLittle,
                    "binary_big_endian" => Encoding::BinaryBig,
                    other => {
                        return Err(unknown(&format!(
                            "unknown PLY format `{other}` (line {line_no})"
                        )))
                    }
                });
            }
            ["element", name, count] => {
                let count: u64 = count.parse().map_err(|_| {
                    bad(
                        line_no,
                        format!("element `{name}` has a bad count `{count}`"),
                    )
                })?;
                if *name == "vertex" && elements.iter().any(|e| e.name == "vertex") {
                    return Err(bad(line_no, "a second `vertex` element".into()));
                }
                elements.push(Element {
                    name: (*name).to_owned(),
                    count,
                    properties: Vec::new(),
                    line: line_no,
                });
            }
            ["property", "list", count, item, name] => {
                let (Some(count), Some(item)) = (Scalar::parse(count), Scalar::parse(item)) else {
                    return Err(bad(
                        line_no,
                        format!("unknown type in list property `{name}`"),
                    ));
                };
                if !count.is_integer() {
                    return Err(bad(
                        line_no,
                        format!("list `{name}` has a non-integer count type"),
                    ));
                }
                let element = elements
                    .last_mut()
                    .ok_or_else(|| bad(line_no, "property before any element".into()))?;
                element.properties.push(Property {
                    name: (*name).to_owned(),
                    kind: Kind::List { count, item },
                    line: line_no,
                });
            }
            ["property", ty, name] => {
                let ty = Scalar::parse(ty).ok_or_else(|| {
                    bad(line_no, format!("unknown type `{ty}` of property `{name}`"))
                })?;
                let element = elements
                    .last_mut()
                    .ok_or_else(|| bad(line_no, "property before any element".into()))?;
                element.properties.push(Property {
                    name: (*name).to_owned(),
                    kind: Kind::Scalar(ty),
                    line: line_no,
                });
            }
            ["end_header"] => break,
            _ => {
                return Err(bad(
                    line_no,
                    format!("unrecognised header line `{}`", line.trim()),
                ))
            }
        }
    }
    let encoding = encoding.ok_or_else(|| unknown("PLY header has no `format` line"))?;
    Ok(Header {
        encoding,
        elements,
        data_start: pos,
        data_line: line_no + 1,
        texture,
    })
}

/// What the reader was doing when a value could not be read.
enum ReadError {
    /// The data ended.
    Eof,
    /// A token is not a number of the declared type.
    Malformed(String),
}

#[derive(Clone)]
enum Reader<'a> {
    Ascii(AsciiReader<'a>),
    Binary(BinaryReader<'a>),
}

#[derive(Clone)]
struct AsciiReader<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: u64,
}

#[derive(Clone)]
struct BinaryReader<'a> {
    bytes: &'a [u8],
    pos: usize,
    big_endian: bool,
}

impl Reader<'_> {
    /// Reads one value of type `ty` as f64 (exact for every PLY integer type).
    /// Inlined with the binary read into the element loops: a call per
    /// value was 8% of the instructions of a binary parse (lucy.ply).
    #[inline(always)]
    fn read(&mut self, ty: Scalar) -> std::result::Result<f64, ReadError> {
        match self {
            Reader::Ascii(r) => r.read(ty),
            Reader::Binary(r) => r.read(ty),
        }
    }

    fn place(&self, element: &str, index: u64) -> Place {
        let p = Place::element(element, index);
        match self {
            Reader::Ascii(r) => p.at_line(r.line),
            Reader::Binary(r) => p.at_byte(r.pos as u64),
        }
    }

    fn remaining(&self) -> usize {
        match self {
            Reader::Ascii(r) => r.bytes.len() - r.pos,
            Reader::Binary(r) => r.bytes.len() - r.pos,
        }
    }

    /// Upper bound on how many instances of `element` the rest can hold.
    fn capacity_for(&self, element: &Element) -> usize {
        let per = match self {
            // At least one character and one separator per property.
            Reader::Ascii(_) => 2 * element.properties.len(),
            Reader::Binary(_) => element.min_binary_size(),
        }
        .max(1);
        let fit = self.remaining() / per;
        fit.min(usize::try_from(element.count).unwrap_or(usize::MAX))
    }
}

impl AsciiReader<'_> {
    /// Moves to the next token, counting lines.
    fn skip_whitespace(&mut self) {
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
            if self.bytes[self.pos] == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
    }

    fn read(&mut self, ty: Scalar) -> std::result::Result<f64, ReadError> {
        self.skip_whitespace();
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(ReadError::Eof);
        }
        let token = &self.bytes[start..self.pos];
        let malformed = |what: &str| {
            let token = String::from_utf8_lossy(token);
            ReadError::Malformed(format!("`{token}` is not {what}"))
        };
        if ty.is_integer() {
            parse_integer(token)
                .map(|v| v as f64)
                .ok_or_else(|| malformed("an integer"))
        } else {
            std::str::from_utf8(token)
                .ok()
                .and_then(|t| t.parse::<f64>().ok())
                .ok_or_else(|| malformed("a number"))
        }
    }
}

/// A decimal integer with an optional sign, read as `i64::from_str` reads
/// it but from bytes: most tokens of an ascii PLY are indices, and checking
/// each for UTF-8 first cost a fifth of the parse.
fn parse_integer(token: &[u8]) -> Option<i64> {
    let (negative, digits) = match token {
        [b'-', rest @ ..] => (true, rest),
        [b'+', rest @ ..] => (false, rest),
        _ => (false, token),
    };
    if digits.is_empty() {
        return None;
    }
    // Accumulated negative, so that i64::MIN fits.
    let mut v: i64 = 0;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        v = v.checked_mul(10)?.checked_sub(i64::from(d - b'0'))?;
    }
    if negative {
        Some(v)
    } else {
        v.checked_neg()
    }
}

impl BinaryReader<'_> {
    fn take<const N: usize>(&mut self) -> std::result::Result<[u8; N], ReadError> {
        let end = self.pos.checked_add(N).ok_or(ReadError::Eof)?;
        let bytes: [u8; N] = self
            .bytes
            .get(self.pos..end)
            .ok_or(ReadError::Eof)?
            .try_into()
            .map_err(|_| ReadError::Eof)?;
        self.pos = end;
        Ok(bytes)
    }

    #[inline(always)]
    fn read(&mut self, ty: Scalar) -> std::result::Result<f64, ReadError> {
        macro_rules! num {
            ($t:ty, $n:literal) => {{
                let b = self.take::<$n>()?;
                if self.big_endian {
                    <$t>::from_be_bytes(b) as f64
                } else {
                    <$t>::from_le_bytes(b) as f64
                }
            }};
        }
        Ok(match ty {
            Scalar::I8 => num!(i8, 1),
            Scalar::U8 => num!(u8, 1),
            Scalar::I16 => num!(i16, 2),
            Scalar::U16 => num!(u16, 2),
            Scalar::I32 => num!(i32, 4),
            Scalar::U32 => num!(u32, 4),
            Scalar::F32 => num!(f32, 4),
            Scalar::F64 => num!(f64, 8),
        })
    }
}

/// What each property of an element is used for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Role {
    Skip,
    /// A vertex value, stored in this slot of [`Slots`].
    Value(usize),
    Indices,
}

/// One vertex's values: position, normal, texture coordinate, colour.
type Slots = [f64; SLOT_COUNT];
const SLOT_COUNT: usize = 12;
const POSITION: usize = 0;
const NORMAL: usize = 3;
const UV: usize = 6;
const COLOR: usize = 8;

/// Component names of each vertex stream, families in the order tried.
const POSITION_NAMES: &[&[&str]] = &[&["x", "y", "z"]];
const NORMAL_NAMES: &[&[&str]] = &[&["nx", "ny", "nz"]];
const UV_NAMES: &[&[&str]] = &[
    &["texture_u", "texture_v"],
    &["u", "v"],
    &["s", "t"],
    &["texture_s", "texture_t"],
];
/// Alpha, the fourth, may be absent.
const COLOR_NAMES: &[&[&str]] = &[
    &["red", "green", "blue", "alpha"],
    &["r", "g", "b", "a"],
    &[
        "diffuse_red",
        "diffuse_green",
        "diffuse_blue",
        "diffuse_alpha",
    ],
];

/// Where each property of a `vertex` element goes and which streams it
/// fills.
struct VertexLayout {
    roles: Vec<Role>,
    normals: bool,
    uvs: bool,
    colors: bool,
    /// The property each slot is read from (for error places), or
    /// `usize::MAX`.
    source: [usize; SLOT_COUNT],
    /// Slot values before a vertex is read: 1 for alpha, which may be
    /// absent.
    initial: Slots,
    /// What each colour channel is multiplied by ([`Scalar::color_scale`]).
    color_scale: [f64; 4],
}

impl VertexLayout {
    /// The layout of `element`, or the header error as (line, message).
    fn new(element: &Element) -> std::result::Result<VertexLayout, (u64, String)> {
        let known = [POSITION_NAMES, NORMAL_NAMES, UV_NAMES, COLOR_NAMES];
        if let Some(p) = element.properties.iter().find(|p| {
            matches!(p.kind, Kind::List { .. })
                && known
                    .iter()
                    .flat_map(|f| f.iter())
                    .any(|f| f.contains(&&*p.name))
        }) {
            return Err((
                p.line,
                format!(
                    "vertex property `{}` is a list; a position, normal, texture coordinate \
                     or colour component is one scalar",
                    p.name
                ),
            ));
        }
        // The last scalar of that name (a repeated name: the last value wins).
        let find = |name: &str| element.properties.iter().rposition(|p| p.name == name);
        let mut layout = VertexLayout {
            roles: vec![Role::Skip; element.properties.len()],
            normals: false,
            uvs: false,
            colors: false,
            source: [usize::MAX; SLOT_COUNT],
            initial: [0.0; SLOT_COUNT],
            color_scale: [1.0; 4],
        };
        layout.initial[COLOR + 3] = 1.0;
        let mut place = |families: &[&[&str]], required: usize, first_slot: usize| {
            let family = families
                .iter()
                .find(|f| f[..required].iter().all(|n| find(n).is_some()))?;
            for (k, name) in family.iter().enumerate() {
                if let Some(p) = find(name) {
                    layout.roles[p] = Role::Value(first_slot + k);
                    layout.source[first_slot + k] = p;
                }
            }
            Some(())
        };
        if place(POSITION_NAMES, 3, POSITION).is_none() {
            let missing = ["x", "y", "z"].into_iter().find(|n| find(n).is_none());
            return Err((
                element.line,
                format!(
                    "`vertex` element has no scalar `{}` property",
                    missing.unwrap_or("x")
                ),
            ));
        }
        layout.normals = place(NORMAL_NAMES, 3, NORMAL).is_some();
        layout.uvs = place(UV_NAMES, 2, UV).is_some();
        layout.colors = place(COLOR_NAMES, 3, COLOR).is_some();
        for c in 0..4 {
            if let Some(p) = element.properties.get(layout.source[COLOR + c]) {
                if let Kind::Scalar(ty) = p.kind {
                    layout.color_scale[c] = ty.color_scale();
                }
            }
        }
        Ok(layout)
    }
}

/// Reads every instance of `element` into `raw`: vertices with their
/// streams, faces and strips as triangles, anything else skipped.
fn read_element(
    reader: &mut Reader<'_>,
    element: &Element,
    vertex_count: u64,
    raw: &mut RawMesh,
    file: &Path,
) -> Result<()> {
    if element.properties.is_empty() {
        // Nothing to read, whatever the count says.
        return Ok(());
    }
    let header_err = |line: u64, message: String| Error::Parse {
        file: file.to_owned(),
        place: Place::line(line),
        message,
    };
    match element.name.as_str() {
        "vertex" => {
            let layout = VertexLayout::new(element).map_err(|(line, m)| header_err(line, m))?;
            read_vertices(reader, element, &layout, raw, file)
        }
        "face" | "tristrips" => {
            let is_index_list = |p: &Property| {
                matches!(p.kind, Kind::List { .. })
                    && (p.name == "vertex_indices" || p.name == "vertex_index")
            };
            let Some(which) = element.properties.iter().position(is_index_list) else {
                return Err(header_err(
                    element.line,
                    format!(
                        "`{}` element has no list property `vertex_indices`",
                        element.name
                    ),
                ));
            };
            let property = &element.properties[which];
            if let Kind::List { item, .. } = property.kind {
                if !item.is_integer() {
                    return Err(header_err(
                        property.line,
                        format!("`{}` indices have a non-integer type", element.name),
                    ));
                }
            }
            let mut roles = vec![Role::Skip; element.properties.len()];
            roles[which] = Role::Indices;
            read_faces(reader, element, &roles, vertex_count, raw, file)
        }
        _ => {
            let roles = vec![Role::Skip; element.properties.len()];
            let (mut values, mut list) = ([0.0; SLOT_COUNT], Vec::new());
            for index in 0..element.count {
                read_instance(reader, element, &roles, index, &mut values, &mut list, file)?;
            }
            Ok(())
        }
    }
}

/// Reads one instance of `element`, number `index`: scalars with a
/// [`Role::Value`] into their slot of `values`, the items of the
/// [`Role::Indices`] list into `list`, the rest skipped.
#[inline(always)]
fn read_instance(
    reader: &mut Reader<'_>,
    element: &Element,
    roles: &[Role],
    index: u64,
    values: &mut Slots,
    list: &mut Vec<i64>,
    file: &Path,
) -> Result<()> {
    for (property, &role) in element.properties.iter().zip(roles) {
        let fail = |reader: &Reader<'_>, e: ReadError| {
            let message = match e {
                ReadError::Eof => format!(
                    "data ends inside `{}` {index} of {} declared (property `{}`): file \
                     truncated or header count too large",
                    element.name, element.count, property.name
                ),
                ReadError::Malformed(m) => format!("property `{}`: {m}", property.name),
            };
            Error::Parse {
                file: file.to_owned(),
                place: reader.place(&element.name, index),
                message,
            }
        };
        match property.kind {
            Kind::Scalar(ty) => {
                let v = reader.read(ty).map_err(|e| fail(reader, e))?;
                if let Role::Value(slot) = role {
                    values[slot] = v;
                }
            }
            Kind::List { count, item } => {
                let n = reader.read(count).map_err(|e| fail(reader, e))?;
                if n < 0.0 {
                    return Err(fail(
                        reader,
                        ReadError::Malformed(format!("negative list length {n}")),
                    ));
                }
                if role == Role::Indices {
                    list.clear();
                }
                for _ in 0..n as u64 {
                    let v = reader.read(item).map_err(|e| fail(reader, e))?;
                    if role == Role::Indices {
                        list.push(v as i64);
                    }
                }
            }
        }
    }
    Ok(())
}

/// Reads the `vertex` element: positions and the streams of `layout`.
fn read_vertices(
    reader: &mut Reader<'_>,
    element: &Element,
    layout: &VertexLayout,
    raw: &mut RawMesh,
    file: &Path,
) -> Result<()> {
    let capacity = reader.capacity_for(element);
    raw.positions.reserve(capacity);
    let streams = &mut raw.properties;
    if layout.normals {
        streams.normals = Some(Vec::with_capacity(capacity));
    }
    if layout.uvs {
        streams.uvs = Some(Vec::with_capacity(capacity));
    }
    if layout.colors {
        streams.colors = Some(Vec::with_capacity(capacity));
    }
    let mut values = layout.initial;
    let mut list = Vec::new();
    for index in 0..element.count {
        let start = reader.clone();
        read_instance(
            reader,
            element,
            &layout.roles,
            index,
            &mut values,
            &mut list,
            file,
        )?;
        push_vertex(&values, layout, raw).map_err(|slot| {
            let property = layout.source[slot];
            Error::Parse {
                file: file.to_owned(),
                place: property_place(start, element, index, property),
                message: format!(
                    "`{}` is NaN or infinite (or beyond f32 range): {}",
                    element.properties[property].name, values[slot]
                ),
            }
        })?;
    }
    Ok(())
}

/// Reads a `face` or `tristrips` element (its index list at the
/// [`Role::Indices`] of `roles`) into triangles.
fn read_faces(
    reader: &mut Reader<'_>,
    element: &Element,
    roles: &[Role],
    vertex_count: u64,
    raw: &mut RawMesh,
    file: &Path,
) -> Result<()> {
    let is_strip = element.name == "tristrips";
    if !is_strip {
        raw.triangles.reserve(reader.capacity_for(element));
    }
    let mut values = [0.0; SLOT_COUNT];
    let mut list: Vec<i64> = Vec::new();
    let mut run: Vec<u32> = Vec::new();
    for index in 0..element.count {
        read_instance(reader, element, roles, index, &mut values, &mut list, file)?;
        let out_of_range = list
            .iter()
            .find(|&&i| !((0..vertex_count as i64).contains(&i) || (is_strip && i == -1)));
        if let Some(&i) = out_of_range {
            return Err(Error::Parse {
                file: file.to_owned(),
                place: reader.place(&element.name, index),
                message: format!(
                    "vertex index {i} out of range (the header declares {vertex_count} vertices)"
                ),
            });
        }
        if is_strip {
            push_strip(&list, &mut run, raw);
        } else {
            push_polygon(&list, &mut run, raw);
        }
    }
    Ok(())
}

/// Appends one vertex's position and streams, or returns the slot of its
/// first value that is not a finite `f32`.
#[inline]
fn push_vertex(
    v: &Slots,
    layout: &VertexLayout,
    raw: &mut RawMesh,
) -> std::result::Result<(), usize> {
    let first_bad = |first: usize, count: usize| {
        (first..first + count)
            .find(|&s| !(v[s] as f32).is_finite())
            .unwrap_or(first)
    };
    let p = Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
    if !p.is_finite() {
        return Err(first_bad(POSITION, 3));
    }
    raw.positions.push(p);
    let streams = &mut raw.properties;
    if let (true, Some(normals)) = (layout.normals, &mut streams.normals) {
        let n = Vec3::new(v[NORMAL] as f32, v[NORMAL + 1] as f32, v[NORMAL + 2] as f32);
        if !n.is_finite() {
            return Err(first_bad(NORMAL, 3));
        }
        normals.push(n);
    }
    if let (true, Some(uvs)) = (layout.uvs, &mut streams.uvs) {
        let t = Vec2::new(v[UV] as f32, v[UV + 1] as f32);
        if !t.is_finite() {
            return Err(first_bad(UV, 2));
        }
        uvs.push(t);
    }
    if let (true, Some(colors)) = (layout.colors, &mut streams.colors) {
        // Scales are at most 1: a finite value stays finite.
        let s = layout.color_scale;
        let c = Vec4::new(
            (v[COLOR] * s[0]) as f32,
            (v[COLOR + 1] * s[1]) as f32,
            (v[COLOR + 2] * s[2]) as f32,
            (v[COLOR + 3] * s[3]) as f32,
        );
        if !c.is_finite() {
            return Err(first_bad(COLOR, 4));
        }
        colors.push(c);
    }
    Ok(())
}

/// The place of property `property` of `element` `index`, read again from
/// `start`, the reader where that instance begins (an error path: the
/// instance was read once already, so every value before it is there).
fn property_place(mut start: Reader<'_>, element: &Element, index: u64, property: usize) -> Place {
    for p in &element.properties[..property] {
        let _ = match p.kind {
            Kind::Scalar(ty) => start.read(ty).map(drop),
            Kind::List { count, item } => start.read(count).map(|n| {
                for _ in 0..n as u64 {
                    let _ = start.read(item);
                }
            }),
        };
    }
    if let Reader::Ascii(r) = &mut start {
        r.skip_whitespace();
    }
    start.place(&element.name, index)
}

/// Triangulates one polygon ([`super::triangulate_polygon`]); fewer than
/// three corners count as one dropped degenerate. `ids` is scratch.
fn push_polygon(corners: &[i64], ids: &mut Vec<u32>, raw: &mut RawMesh) {
    if corners.len() < 3 {
        raw.degenerate_in_source += 1;
        return;
    }
    ids.clear();
    ids.extend(corners.iter().map(|&c| c as u32));
    super::triangulate_polygon(ids, &mut raw.triangles);
}

/// Decodes one `tristrips` list: runs split at `-1`, each decoded by the
/// crate's one strip rule ([`crate::encoding::decode_run`]); windows with a
/// repeated index (the strip's swaps) are dropped and counted. Indices were
/// range-checked by the caller.
fn push_strip(list: &[i64], run: &mut Vec<u32>, raw: &mut RawMesh) {
    for part in list.split(|&i| i == -1) {
        run.clear();
        run.extend(part.iter().map(|&i| i as u32));
        let before = raw.triangles.len();
        crate::encoding::decode_run(run, &mut raw.triangles);
        let windows = run.len().saturating_sub(2);
        raw.degenerate_in_source += windows - (raw.triangles.len() - before);
    }
}

/// Writes `mesh` as binary little-endian PLY to `path`: `x y z`, then the
/// streams the mesh has, `nx ny nz` and `texture_u texture_v` (the names
/// MeshLab writes and trimesh tries first) as `float`, `red green blue
/// alpha` as `uchar` (each channel times 255, rounded); faces as `property
/// list uchar uint vertex_indices`. The texture is named by a `comment
/// TextureFile` line (MeshLab's): a file in `path`'s folder or below by its
/// relative path; any other file, and an embedded image, copied beside the
/// PLY as `<stem>.png` (or the file's own extension) and named so (one
/// that cannot be read is named where it is). PLY has no place
/// for position ids: [`parse_ply`] reads the file back to the same mesh
/// with colours within 1/510, and split vertices come back as one point
/// when the reader welds ([`crate::mesh::CleanOptions`]).
///
/// # Errors
/// [`Error::Invalid`] when `mesh` breaks an invariant ([`Mesh::validate`]),
/// [`Error::InvalidArgument`] for a texture path that is not UTF-8 or
/// holds a line break, [`Error::Io`] naming the file (or the texture file
/// that cannot be read for its copy, or the copy).
///
/// Cost: O(V + T), one buffered write.
pub fn save_ply(mesh: &Mesh, path: &Path) -> Result<()> {
    use std::fmt::Write as _;
    use std::io::Write as _;
    fn put(record: &mut Vec<u8>, values: &[f32]) {
        for x in values {
            record.extend_from_slice(&x.to_le_bytes());
        }
    }
    mesh.validate()?;
    let streams = &mesh.properties;
    let mut header = String::from("ply\nformat binary_little_endian 1.0\ncomment written by mts\n");
    if let Some(texture) = &streams.texture {
        let _ = writeln!(
            header,
            "comment TextureFile {}",
            texture_name(texture, path)?
        );
    }
    let _ = write!(
        header,
        "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
        mesh.vertex_count()
    );
    if streams.normals.is_some() {
        header += "property float nx\nproperty float ny\nproperty float nz\n";
    }
    if streams.uvs.is_some() {
        header += "property float texture_u\nproperty float texture_v\n";
    }
    if streams.colors.is_some() {
        header +=
            "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
    }
    let _ = write!(
        header,
        "element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.triangle_count()
    );

    crate::output::write_with(path, |w| {
        w.write_all(header.as_bytes())?;
        let mut record: Vec<u8> = Vec::with_capacity(48);
        for (v, p) in mesh.positions.iter().enumerate() {
            record.clear();
            put(&mut record, &p.to_array());
            if let Some(normals) = &streams.normals {
                put(&mut record, &normals[v].to_array());
            }
            if let Some(uvs) = &streams.uvs {
                put(&mut record, &uvs[v].to_array());
            }
            if let Some(colors) = &streams.colors {
                let c = colors[v].to_array();
                record.extend(c.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8));
            }
            w.write_all(&record)?;
        }
        for t in &mesh.triangles {
            record.clear();
            record.push(3);
            for i in t {
                record.extend_from_slice(&i.to_le_bytes());
            }
            w.write_all(&record)?;
        }
        Ok(())
    })
}

/// How a `comment TextureFile` line names `texture` for a PLY at `ply`
/// ([`super::texture_beside`]: a file in its folder or below by its
/// relative path, any other texture copied beside it).
fn texture_name(texture: &Texture, ply: &Path) -> Result<String> {
    let one_line = |s: &str| !s.contains(['\n', '\r']) && !s.trim().is_empty();
    if let Texture::File(file) = texture {
        // Refused before anything is copied.
        if file.to_str().is_none_or(|s| s.contains(['\n', '\r'])) {
            return Err(Error::InvalidArgument(format!(
                "texture path {} cannot be written on a PLY header line (not UTF-8, or a line break)",
                file.display()
            )));
        }
    }
    let name = super::texture_beside(texture, ply, one_line)?;
    if one_line(&name) {
        Ok(name)
    } else {
        Err(Error::InvalidArgument(format!(
            "texture name {name:?} cannot be written on a PLY header line"
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::parse_integer;

    /// The same integers as `i64::from_str`, edges of the range included.
    #[test]
    fn integers_read_as_from_str_reads_them() {
        for token in [
            "",
            "+",
            "-",
            "0",
            "-0",
            "+12",
            "007",
            "-45",
            "1e3",
            "12a",
            " 1",
            "--1",
            "+-1",
            "9223372036854775807",
            "9223372036854775808",
            "-9223372036854775808",
            "-9223372036854775809",
            "99999999999999999999",
            "\u{663}",
        ] {
            assert_eq!(
                parse_integer(token.as_bytes()),
                token.parse::<i64>().ok(),
                "{token:?}"
            );
        }
    }
}
