//! Stanford PLY reader: `ascii`, `binary_little_endian`, `binary_big_endian`.
//!
//! Hand-written rather than built on `ply-rs-bw` so that every error names
//! the file, line or byte offset, element and index, and so that no
//! allocation is ever sized by a header count: capacities are capped by what
//! the remaining bytes can hold, and lists are read item by item.
//!
//! Read: `vertex` (`x`, `y`, `z` of any numeric type), `face` (list
//! `vertex_indices` or `vertex_index`, any polygon size, fan-triangulated),
//! `tristrips` (list `vertex_indices`, `-1` restarts, odd triangles flipped).
//! Every other element and property is skipped according to its declared
//! type, list properties included.

use crate::error::{Error, Place, Result};
use crate::mesh::RawMesh;
use glam::Vec3;
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
}

/// Parses PLY bytes into a raw mesh.
///
/// # Errors
/// [`Error::UnknownFormat`] without the `ply` magic or with an unknown
/// `format`; [`Error::Parse`] with line (ascii and header) or byte offset
/// (binary), element and index for a malformed header, truncated data,
/// non-numeric tokens, NaN or infinite coordinates, indices out of range,
/// and header counts larger than the data.
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
    })
}

/// What the reader was doing when a value could not be read.
enum ReadError {
    /// The data ended.
    Eof,
    /// A token is not a number of the declared type.
    Malformed(String),
}

enum Reader<'a> {
    Ascii(AsciiReader<'a>),
    Binary(BinaryReader<'a>),
}

struct AsciiReader<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: u64,
}

struct BinaryReader<'a> {
    bytes: &'a [u8],
    pos: usize,
    big_endian: bool,
}

impl Reader<'_> {
    /// Reads one value of type `ty` as f64 (exact for every PLY integer type).
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
    fn read(&mut self, ty: Scalar) -> std::result::Result<f64, ReadError> {
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
            if self.bytes[self.pos] == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(ReadError::Eof);
        }
        let token = std::str::from_utf8(&self.bytes[start..self.pos]).unwrap_or("?");
        if ty.is_integer() {
            token
                .parse::<i64>()
                .map(|v| v as f64)
                .map_err(|_| ReadError::Malformed(format!("`{token}` is not an integer")))
        } else {
            token
                .parse::<f64>()
                .map_err(|_| ReadError::Malformed(format!("`{token}` is not a number")))
        }
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
    Coord(usize),
    Indices,
}

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
    let header_err = |message: String| Error::Parse {
        file: file.to_owned(),
        place: Place::line(element.line),
        message,
    };
    let roles: Vec<Role> = match element.name.as_str() {
        "vertex" => {
            let roles: Vec<Role> = element
                .properties
                .iter()
                .map(|p| match (p.name.as_str(), &p.kind) {
                    ("x", Kind::Scalar(_)) => Role::Coord(0),
                    ("y", Kind::Scalar(_)) => Role::Coord(1),
                    ("z", Kind::Scalar(_)) => Role::Coord(2),
                    _ => Role::Skip,
                })
                .collect();
            for axis in 0..3 {
                if !roles.contains(&Role::Coord(axis)) {
                    return Err(header_err(format!(
                        "`vertex` element has no scalar `{}` property",
                        ["x", "y", "z"][axis]
                    )));
                }
            }
            roles
        }
        "face" | "tristrips" => {
            let is_index_list = |p: &Property| {
                matches!(p.kind, Kind::List { .. })
                    && (p.name == "vertex_indices" || p.name == "vertex_index")
            };
            let Some(which) = element.properties.iter().position(is_index_list) else {
                return Err(header_err(format!(
                    "`{}` element has no list property `vertex_indices`",
                    element.name
                )));
            };
            if let Kind::List { item, .. } = element.properties[which].kind {
                if !item.is_integer() {
                    return Err(header_err(format!(
                        "`{}` indices have a non-integer type",
                        element.name
                    )));
                }
            }
            (0..element.properties.len())
                .map(|i| {
                    if i == which {
                        Role::Indices
                    } else {
                        Role::Skip
                    }
                })
                .collect()
        }
        _ => vec![Role::Skip; element.properties.len()],
    };
    let is_vertex = element.name == "vertex";
    let is_strip = element.name == "tristrips";
    if is_vertex {
        raw.positions.reserve(reader.capacity_for(element));
    } else if element.name == "face" {
        raw.triangles.reserve(reader.capacity_for(element));
    }

    let mut list: Vec<i64> = Vec::new();
    let mut run: Vec<u32> = Vec::new();
    for index in 0..element.count {
        let mut coords = [0.0f64; 3];
        for (property, &role) in element.properties.iter().zip(&roles) {
            let fail = |reader: &Reader<'_>, e: ReadError| {
                let message = match e {
                    ReadError::Eof => format!(
                        "data ends inside `{}` {index} of {} declared (property `{}`): file truncated or header count too large",
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
                    if let Role::Coord(axis) = role {
                        coords[axis] = v;
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
                    list.clear();
                    for _ in 0..n as u64 {
                        let v = reader.read(item).map_err(|e| fail(reader, e))?;
                        if role == Role::Indices {
                            list.push(v as i64);
                        }
                    }
                }
            }
        }
        if is_vertex {
            let p = Vec3::new(coords[0] as f32, coords[1] as f32, coords[2] as f32);
            if !p.is_finite() {
                return Err(Error::Parse {
                    file: file.to_owned(),
                    place: reader.place("vertex", index),
                    message: format!(
                        "coordinate is NaN or infinite (or beyond f32 range): {coords:?}"
                    ),
                });
            }
            raw.positions.push(p);
        } else if roles.contains(&Role::Indices) {
            let out_of_range = list
                .iter()
                .find(|&&i| !((0..vertex_count as i64).contains(&i) || (is_strip && i == -1)));
            if let Some(&i) = out_of_range {
                return Err(Error::Parse {
                    file: file.to_owned(),
                    place: reader.place(&element.name, index),
                    message: format!("vertex index {i} out of range (the header declares {vertex_count} vertices)"),
                });
            }
            if is_strip {
                push_strip(&list, &mut run, raw);
            } else {
                push_polygon(&list, &mut run, raw);
            }
        }
    }
    Ok(())
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
