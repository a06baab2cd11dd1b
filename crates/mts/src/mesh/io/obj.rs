//! Wavefront OBJ reader and writer ([`save_obj`]). The reader: `v`, `f`,
//! and with properties `vt`, `vn` and the material's `map_Kd`; polygons
//! triangulated by
//! [`super::triangulate_polygon`] (quads as the fan `tobj` made), all
//! objects and groups merged, lines (`l`), points (`p`) and everything else
//! ignored.
//!
//! **Properties** ([`parse_obj_with`]): a vertex is a distinct
//! `(v, vt, vn)` triple of a face corner, so a position with several
//! texture coordinates or normals becomes several vertices with the
//! position id of its `v` (a seam); a corner without `vt` or `vn` gets
//! zero there when the file has them elsewhere. `vt u v [w]` keeps `u v`;
//! `vn` is normalised by [`crate::mesh::clean`]. The texture is the
//! `map_Kd` of the first material a face uses (`usemtl`), read from the
//! `mtllib` file beside the OBJ; a missing or unreadable `.mtl` or a
//! material without `map_Kd` leaves the mesh untextured with a warning on
//! stderr, not an error (the geometry is still good). Several materials
//! with different textures are merged into one mesh with the first
//! texture and a warning: one mesh has one texture here.
//!
//! An own reader rather than `tobj` (used until 2026-12): every error names
//! the line and byte where it is, text that is not UTF-8 (UTF-16, binary
//! data) is named as such, CR-only line endings work, and a face of any
//! size is read in time linear in its corners. For the files `tobj`
//! accepted it gives the same mesh, vertex for vertex: within each object
//! or group (a new `o`/`g` after faces starts one) vertices are numbered in
//! the order the faces first use them, and a vertex used by two objects is
//! listed once for each, as `tobj` does without `single_index`; `v x y z w`
//! divides by `w`. It is stricter where `tobj` accepted garbage: `l`
//! statements are lines, not triangles; `vt`/`vn` indices must be in range;
//! a face of one or two corners is counted in
//! [`RawMesh::degenerate_in_source`] instead of vanishing.

use crate::error::{Error, Place, Result};
use crate::mesh::{Mesh, RawMesh, Texture};
use glam::{Vec2, Vec3};
use std::collections::HashMap;
use std::path::Path;

/// No `vt` or `vn` at a corner.
const NONE: u64 = u64::MAX;

/// One face as read: the line it is on and its corners' position indices
/// (0-based, resolved, not yet checked against the position count).
struct Face {
    line: u64,
    byte: u64,
    corners: std::ops::Range<usize>,
}

/// A position, texture-coordinate or normal reference, resolved to 0-based,
/// with where it was first seen past the end of its list.
#[derive(Default)]
struct Highest {
    index: Option<(u64, u64, u64)>,
}

impl Highest {
    fn see(&mut self, index: u64, line: u64, byte: u64) {
        if self.index.is_none_or(|(i, _, _)| index > i) {
            self.index = Some((index, line, byte));
        }
    }
}

/// State of the reader between lines.
struct Reader<'p> {
    path: &'p Path,
    positions: Vec<Vec3>,
    texcoord_count: u64,
    normal_count: u64,
    /// Whether properties are read ([`parse_obj_with`]).
    properties: bool,
    texcoords: Vec<Vec2>,
    normals: Vec<Vec3>,
    /// Faces of the current object, not yet numbered.
    faces: Vec<Face>,
    corners: Vec<u64>,
    /// The `vt` and `vn` of each corner ([`NONE`] for none), with
    /// properties.
    corner_attributes: Vec<(u64, u64)>,
    /// With properties: the current object's vertices of corners that name
    /// a `vt` or `vn`, by `(v, vt, vn)`.
    triples: HashMap<(u64, u64, u64), u32>,
    /// With properties: the `(v, vt, vn)` of each output vertex.
    vertex_sources: Vec<(u64, u64, u64)>,
    /// `mtllib` files named, and the first material a face uses.
    material_libraries: Vec<String>,
    current_material: Option<String>,
    materials_used: Vec<String>,
    highest_texcoord: Highest,
    highest_normal: Highest,
    raw: RawMesh,
    /// Per input position: the object that last numbered it and the number
    /// it got there (object-local vertex numbering, as `tobj`).
    stamp: Vec<u32>,
    local: Vec<u32>,
    object: u32,
    /// Line and byte of the first face statement.
    first_face: Option<(u64, u64)>,
}

/// Parses OBJ text into a raw mesh (geometry only: [`parse_obj_with`]
/// without properties).
///
/// # Errors
/// As [`parse_obj_with`].
pub fn parse_obj(bytes: &[u8], path: &Path) -> Result<RawMesh> {
    parse_obj_with(bytes, path, false)
}

/// Parses OBJ text into a raw mesh, with texture coordinates, normals and
/// the base-colour texture when `properties` is set (see the module docs).
///
/// # Errors
/// [`Error::Parse`] naming the line and byte for text that is not UTF-8,
/// malformed statements, out-of-range `v`, `vt` or `vn` indices in faces,
/// and non-finite coordinates.
///
/// Cost: O(file size) time; memory linear in the elements read.
pub fn parse_obj_with(bytes: &[u8], path: &Path, properties: bool) -> Result<RawMesh> {
    let err = |line: u64, byte: u64, message: String| Error::Parse {
        file: path.to_owned(),
        place: Place::line(line).at_byte(byte),
        message,
    };
    if bytes.starts_with(&[0xFF, 0xFE]) || bytes.starts_with(&[0xFE, 0xFF]) {
        return Err(err(
            1,
            0,
            "UTF-16 text (byte-order mark): OBJ is read as UTF-8 or ASCII; save the file as UTF-8"
                .into(),
        ));
    }
    let mut reader = Reader {
        path,
        positions: Vec::new(),
        texcoord_count: 0,
        normal_count: 0,
        properties,
        texcoords: Vec::new(),
        normals: Vec::new(),
        faces: Vec::new(),
        corners: Vec::new(),
        corner_attributes: Vec::new(),
        triples: HashMap::new(),
        vertex_sources: Vec::new(),
        material_libraries: Vec::new(),
        current_material: None,
        materials_used: Vec::new(),
        highest_texcoord: Highest::default(),
        highest_normal: Highest::default(),
        raw: RawMesh::default(),
        stamp: Vec::new(),
        local: Vec::new(),
        object: 0,
        first_face: None,
    };
    let start = if bytes.starts_with(&[0xEF, 0xBB, 0xBF]) {
        3
    } else {
        0
    };
    let mut end = (1u64, start as u64);
    for (number, offset, line) in lines(bytes, start) {
        end = (number, offset);
        if let Some(nul) = line.iter().position(|&b| b == 0) {
            return Err(err(
                number,
                offset + nul as u64,
                "a NUL byte: binary data, not OBJ text (UTF-16 without a byte-order mark \
                 also looks like this)"
                    .into(),
            ));
        }
        let text = std::str::from_utf8(line).map_err(|e| {
            err(
                number,
                offset + e.valid_up_to() as u64,
                "not UTF-8 text: OBJ is read as UTF-8 or ASCII".into(),
            )
        })?;
        let text = text.split_once('#').map_or(text, |(before, _)| before);
        reader.statement(text, number, offset)?;
    }
    reader.end_object()?;
    reader.check_attribute_ranges()?;
    // A file without one triangle of three distinct vertices is no mesh:
    // said here, where the place is known (the first face, or the end).
    if reader
        .raw
        .triangles
        .iter()
        .all(|&t| crate::mesh::is_degenerate(t))
    {
        let (line, byte, message) = match reader.first_face {
            Some((line, byte)) => (
                line,
                byte,
                format!(
                    "no face has three distinct vertices ({} triangles, all repeating a \
                     vertex; the first face is here)",
                    reader.raw.triangles.len()
                ),
            ),
            None => (
                end.0,
                end.1,
                "end of file and no face of three or more corners (`f` statements): no \
                 triangle to read"
                    .into(),
            ),
        };
        return Err(reader.error(line, byte, "f", message));
    }
    if properties {
        reader.attach_properties();
    }
    Ok(reader.raw)
}

/// The lines of `bytes` from `start` as (1-based number, byte offset,
/// content): a line ends at `\n`, `\r\n` or a lone `\r`.
fn lines(bytes: &[u8], start: usize) -> impl Iterator<Item = (u64, u64, &[u8])> {
    let mut at = start;
    let mut number = 0u64;
    std::iter::from_fn(move || {
        if at >= bytes.len() {
            return None;
        }
        let begin = at;
        let len = bytes[begin..]
            .iter()
            .position(|&b| b == b'\n' || b == b'\r')
            .unwrap_or(bytes.len() - begin);
        let end = begin + len;
        at = end;
        if at < bytes.len() {
            at += if bytes[at] == b'\r' && bytes.get(at + 1) == Some(&b'\n') {
                2
            } else {
                1
            };
        }
        number += 1;
        Some((number, begin as u64, &bytes[begin..end]))
    })
}

impl Reader<'_> {
    fn error(&self, line: u64, byte: u64, element: &str, message: String) -> Error {
        let mut place = Place::line(line).at_byte(byte);
        place.element = Some(format!("`{element}` statement"));
        Error::Parse {
            file: self.path.to_owned(),
            place,
            message,
        }
    }

    fn statement(&mut self, text: &str, line: u64, byte: u64) -> Result<()> {
        let mut words = text.split_whitespace();
        let Some(keyword) = words.next() else {
            return Ok(());
        };
        match keyword {
            "v" => self.vertex(words, line, byte),
            "vt" => {
                let (values, [u, v, ..]) = numbers(words)
                    .map_err(|w| self.error(line, byte, "vt", format!("`{w}` is not a number")))?;
                if !(1..=3).contains(&values) {
                    return Err(self.error(
                        line,
                        byte,
                        "vt",
                        format!("expected 1 to 3 texture coordinates, found {values}"),
                    ));
                }
                self.texcoord_count += 1;
                if self.properties {
                    // `vt u` alone has v = 0, as the format says.
                    let t = Vec2::new(u, v);
                    if !t.is_finite() {
                        return Err(self.error(line, byte, "vt", "NaN or infinite".into()));
                    }
                    self.texcoords.push(t);
                }
                Ok(())
            }
            "vn" => {
                let (values, [x, y, z, _]) = numbers(words)
                    .map_err(|w| self.error(line, byte, "vn", format!("`{w}` is not a number")))?;
                if values != 3 {
                    return Err(self.error(
                        line,
                        byte,
                        "vn",
                        format!("expected 3 normal coordinates, found {values}"),
                    ));
                }
                self.normal_count += 1;
                if self.properties {
                    let n = Vec3::new(x, y, z);
                    if !n.is_finite() {
                        return Err(self.error(line, byte, "vn", "NaN or infinite".into()));
                    }
                    self.normals.push(n);
                }
                Ok(())
            }
            "f" => self.face(words, line, byte),
            "o" | "g" => {
                if !self.faces.is_empty() {
                    self.end_object()?;
                }
                Ok(())
            }
            "mtllib" if self.properties => {
                // File names may hold spaces: the rest of the line.
                let name = text.trim_start()["mtllib".len()..].trim();
                if !name.is_empty() {
                    self.material_libraries.push(name.to_owned());
                }
                Ok(())
            }
            "usemtl" if self.properties => {
                let name = text.trim_start()["usemtl".len()..].trim().to_owned();
                self.current_material = Some(name);
                Ok(())
            }
            // Lines, points, free-form geometry, smoothing groups and
            // unknown statements carry no triangles.
            _ => Ok(()),
        }
    }

    /// `v x y z`, `v x y z w` (divided by w) or `v x y z r g b` (colour
    /// ignored).
    fn vertex<'a>(
        &mut self,
        mut words: impl Iterator<Item = &'a str>,
        line: u64,
        byte: u64,
    ) -> Result<()> {
        let mut xyz = [0f32; 3];
        for (k, c) in xyz.iter_mut().enumerate() {
            let Some(w) = words.next() else {
                return Err(self.error(
                    line,
                    byte,
                    "v",
                    format!("expected 3 coordinates x y z, found {k}"),
                ));
            };
            *c = w
                .parse()
                .map_err(|_| self.error(line, byte, "v", format!("`{w}` is not a number")))?;
        }
        let rest: Vec<&str> = words.take(4).collect();
        let mut p = Vec3::from(xyz);
        match rest.len() {
            0 => {}
            1 => {
                let w: f32 = rest[0].parse().map_err(|_| {
                    self.error(line, byte, "v", format!("`{}` is not a number", rest[0]))
                })?;
                if w == 0.0 {
                    return Err(self.error(line, byte, "v", "weight w is 0".into()));
                }
                p /= w;
            }
            3 => {
                if let Some(w) = rest.iter().find(|w| w.parse::<f32>().is_err()) {
                    return Err(self.error(line, byte, "v", format!("`{w}` is not a number")));
                }
            }
            n => {
                return Err(self.error(
                    line,
                    byte,
                    "v",
                    format!(
                        "expected x y z, then nothing, a weight w or a colour r g b; found {} \
                         values",
                        3 + n
                    ),
                ))
            }
        }
        if !p.is_finite() {
            return Err(self.error(
                line,
                byte,
                "v",
                "vertex coordinate is NaN or infinite".into(),
            ));
        }
        if self.positions.len() as u64 >= u64::from(u32::MAX) {
            return Err(self.error(line, byte, "v", "more than 2^32 - 1 vertices".into()));
        }
        self.positions.push(p);
        Ok(())
    }

    /// `f v v v ...` with corners `v`, `v/vt`, `v//vn` or `v/vt/vn`, indices
    /// from 1 or negative (relative to the elements read so far).
    fn face<'a>(
        &mut self,
        words: impl Iterator<Item = &'a str>,
        line: u64,
        byte: u64,
    ) -> Result<()> {
        self.first_face.get_or_insert((line, byte));
        if let Some(m) = &self.current_material {
            if !self.materials_used.contains(m) {
                self.materials_used.push(m.clone());
            }
        }
        let first = self.corners.len();
        for (k, corner) in words.enumerate() {
            let mut attributes = (NONE, NONE);
            let mut parts = corner.split('/');
            let counts = [
                self.positions.len() as u64,
                self.texcoord_count,
                self.normal_count,
            ];
            for (slot, count) in counts.into_iter().enumerate() {
                let Some(part) = parts.next() else { break };
                if part.is_empty() && slot > 0 {
                    continue;
                }
                let what = ["position", "texture coordinate", "normal"][slot];
                let index: i64 = part.parse().map_err(|_| {
                    self.error(
                        line,
                        byte,
                        "f",
                        format!(
                            "corner {} (`{corner}`): `{part}` is not a {what} index (expected \
                             v, v/vt, v//vn or v/vt/vn with integers)",
                            k + 1
                        ),
                    )
                })?;
                let resolved = match index {
                    i if i > 0 => Some(i as u64 - 1),
                    i if i < 0 => count.checked_sub(i.unsigned_abs()),
                    _ => None,
                };
                let Some(resolved) = resolved else {
                    return Err(self.error(
                        line,
                        byte,
                        "f",
                        format!(
                            "corner {}: {what} index {index} is out of range ({count} defined \
                             so far; indices start at 1, negative ones count back)",
                            k + 1
                        ),
                    ));
                };
                match slot {
                    0 => self.corners.push(resolved),
                    1 => {
                        self.highest_texcoord.see(resolved, line, byte);
                        attributes.0 = resolved;
                    }
                    _ => {
                        self.highest_normal.see(resolved, line, byte);
                        attributes.1 = resolved;
                    }
                }
            }
            if self.properties {
                self.corner_attributes.push(attributes);
            }
            if parts.next().is_some() {
                return Err(self.error(
                    line,
                    byte,
                    "f",
                    format!(
                        "corner {} (`{corner}`) has more than three parts v/vt/vn",
                        k + 1
                    ),
                ));
            }
        }
        if self.corners.len() - first < 3 {
            // A point or a line written as a face: no triangle, counted.
            self.corners.truncate(first);
            self.corner_attributes
                .truncate(first.min(self.corner_attributes.len()));
            self.raw.degenerate_in_source += 1;
            return Ok(());
        }
        self.faces.push(Face {
            line,
            byte,
            corners: first..self.corners.len(),
        });
        Ok(())
    }

    /// Numbers the current object's vertices in first-use order and
    /// triangulates its faces.
    fn end_object(&mut self) -> Result<()> {
        let count = self.positions.len() as u64;
        self.object += 1;
        if self.stamp.len() < self.positions.len() {
            self.stamp.resize(self.positions.len(), 0);
            self.local.resize(self.positions.len(), 0);
        }
        let base = self.raw.positions.len();
        let faces = std::mem::take(&mut self.faces);
        let mut ids = Vec::new();
        for face in &faces {
            ids.clear();
            for (k, c) in face.corners.clone().enumerate() {
                let v = self.corners[c];
                if v >= count {
                    return Err(self.error(
                        face.line,
                        face.byte,
                        "f",
                        format!(
                            "corner {}: position index {} is past the {count} vertices in the \
                             file",
                            k + 1,
                            v + 1
                        ),
                    ));
                }
                let attributes = self
                    .corner_attributes
                    .get(c)
                    .copied()
                    .unwrap_or((NONE, NONE));
                if attributes != (NONE, NONE) {
                    let key = (v, attributes.0, attributes.1);
                    let next = self.raw.positions.len() as u32;
                    let id = *self.triples.entry(key).or_insert(next);
                    if id == next {
                        if self.raw.positions.len() as u64 >= u64::from(u32::MAX) {
                            return Err(self.error(
                                face.line,
                                face.byte,
                                "f",
                                "more than 2^32 - 1 vertices".into(),
                            ));
                        }
                        self.raw.positions.push(self.positions[v as usize]);
                        self.vertex_sources.push(key);
                    }
                    ids.push(id);
                    continue;
                }
                let v = v as usize;
                if self.stamp[v] != self.object {
                    self.stamp[v] = self.object;
                    self.local[v] = (self.raw.positions.len() - base) as u32;
                    if self.raw.positions.len() as u64 >= u64::from(u32::MAX) {
                        return Err(self.error(
                            face.line,
                            face.byte,
                            "f",
                            "more than 2^32 - 1 vertices".into(),
                        ));
                    }
                    self.raw.positions.push(self.positions[v]);
                    if self.properties {
                        self.vertex_sources.push((v as u64, NONE, NONE));
                    }
                }
                ids.push(base as u32 + self.local[v]);
            }
            super::triangulate_polygon(&ids, &mut self.raw.triangles);
        }
        self.faces = faces;
        self.faces.clear();
        self.corners.clear();
        self.corner_attributes.clear();
        self.triples.clear();
        Ok(())
    }

    /// Gives the raw mesh its texture coordinates, normals, position ids
    /// and texture (after the ranges were checked against the whole file).
    fn attach_properties(&mut self) {
        let texture = self.texture();
        let sources = &self.vertex_sources;
        let props = &mut self.raw.properties;
        props.uvs = per_vertex(sources.iter().map(|s| s.1), &self.texcoords);
        props.normals = per_vertex(sources.iter().map(|s| s.2), &self.normals);
        if props.uvs.is_some() || props.normals.is_some() {
            props.position_ids = sources.iter().map(|s| s.0 as u32).collect();
        }
        props.texture = texture;
    }

    /// The `map_Kd` of the first material used, from the `mtllib` files
    /// beside the OBJ (warnings, never errors: see the module docs).
    fn texture(&self) -> Option<Texture> {
        let first = self.materials_used.first()?;
        let folder = self.path.parent().unwrap_or(Path::new(""));
        let warn = |what: String| {
            // A closed or full standard error is no reason to fail a load.
            {
                use std::io::Write as _;
                let _ = writeln!(
                    std::io::stderr(),
                    "{}: {what}; drawn untextured",
                    self.path.display()
                );
            }
        };
        let mut found: Vec<(String, Option<String>)> = Vec::new();
        let mut read = 0;
        for library in &self.material_libraries {
            let file = folder.join(library);
            match super::read_file(&file) {
                Ok(bytes) => {
                    found.extend(materials(&String::from_utf8_lossy(&bytes)));
                    read += 1;
                }
                Err(e) => warn(format!("material library: {e}")),
            }
        }
        let map_of = |name: &String| {
            found
                .iter()
                .find(|(m, _)| m == name)
                .and_then(|(_, map)| map.clone())
        };
        let Some(map) = map_of(first) else {
            if read > 0 {
                warn(format!("material `{first}` has no `map_Kd` texture"));
            }
            return None;
        };
        if self
            .materials_used
            .iter()
            .any(|m| map_of(m).is_some_and(|other| other != map))
        {
            warn(format!(
                "several materials with different textures; `{first}`'s ({map}) is used for all"
            ));
        }
        // A texture that cannot be read is a warning here, not an error
        // later in whatever uses it (a renderer, a .glb that embeds it).
        let file = folder.join(map);
        if !std::fs::metadata(&file).is_ok_and(|m| m.is_file()) {
            warn(format!("texture {}: not a readable file", file.display()));
            return None;
        }
        Some(Texture::File(file))
    }

    /// Texture-coordinate and normal indices against the counts in the
    /// whole file (a face may name ones defined after it, as `tobj` allowed).
    fn check_attribute_ranges(&self) -> Result<()> {
        for (highest, count, what) in [
            (
                &self.highest_texcoord,
                self.texcoord_count,
                "texture coordinate (`vt`)",
            ),
            (&self.highest_normal, self.normal_count, "normal (`vn`)"),
        ] {
            if let Some((index, line, byte)) = highest.index {
                if index >= count {
                    return Err(self.error(
                        line,
                        byte,
                        "f",
                        format!(
                            "{what} index {} is past the {count} defined in the file",
                            index + 1
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The values `indices` name, one per vertex (zero where a vertex names
/// none), or `None` when no vertex names one.
fn per_vertex<T: Copy + Default>(
    indices: impl Iterator<Item = u64> + Clone,
    values: &[T],
) -> Option<Vec<T>> {
    if indices.clone().all(|i| i == NONE) {
        return None;
    }
    Some(
        indices
            .map(|i| values.get(i as usize).copied().unwrap_or_default())
            .collect(),
    )
}

/// The materials of `.mtl` text with their `map_Kd` file, if any (its
/// last word: options such as `-s 1 1 1` come before the file name).
fn materials(text: &str) -> Vec<(String, Option<String>)> {
    let mut out: Vec<(String, Option<String>)> = Vec::new();
    for line in text.lines() {
        let line = line
            .split_once('#')
            .map_or(line, |(before, _)| before)
            .trim();
        if let Some(name) = line.strip_prefix("newmtl") {
            out.push((name.trim().to_owned(), None));
        } else if let Some(args) = line.strip_prefix("map_Kd") {
            if let (Some(last), Some(file)) = (out.last_mut(), args.split_whitespace().last()) {
                last.1 = Some(file.to_owned());
            }
        }
    }
    out
}

/// How many of `words` there are, or the first that is not a number.
/// How many of `words` there are and the first four of their values, or
/// the first that is not a number.
fn numbers<'a>(
    words: impl Iterator<Item = &'a str>,
) -> std::result::Result<(usize, [f32; 4]), &'a str> {
    let (mut n, mut values) = (0, [0.0; 4]);
    for w in words {
        let x = w.parse::<f32>().map_err(|_| w)?;
        if let Some(slot) = values.get_mut(n) {
            *slot = x;
        }
        n += 1;
    }
    Ok((n, values))
}

/// Writes `mesh` as OBJ text to `path`: one `v` line per point (vertices
/// split at a seam share it, so the seam reads back as one), `vt` and `vn`
/// lines when the mesh has texture coordinates or normals (one per
/// vertex), and `f` lines with 1-based indices (`f p/t/n`); floats in the
/// shortest form that reads back to the same bits. A mesh without
/// properties is `v` and `f` lines only, byte for byte what this writer
/// always wrote. Colours are written as `v x y z r g b`, per point: OBJ
/// has no alpha and no colour seam, the first vertex of a point gives it
/// ([`super::dropped_by`] names what is lost).
///
/// A texture is named by a `.mtl` written beside the OBJ as `<stem>.mtl`
/// (`mtllib`, `usemtl textured`, `map_Kd`): a [`Texture::File`] in the
/// OBJ's folder or below by its relative path (not copied), unless that
/// path holds white space (which `map_Kd` readers cut at); any other file,
/// and an embedded image, is copied beside the OBJ as `<stem>.png` (or its
/// own extension) and named so, so that the output folder holds everything
/// it refers to (a file that cannot be read is named where it is:
/// `texture_beside`). Every file is written whole or not at all
/// ([`crate::output`]), the image and `.mtl` before the OBJ.
///
/// # Errors
/// [`Error::Io`] naming the file that cannot be written (or the texture
/// file that cannot be read for a copy); [`Error::InvalidArgument`] for a
/// texture path that is not UTF-8.
///
/// Cost: O(V + T), one buffered write.
pub fn save_obj(mesh: &Mesh, path: &Path) -> Result<()> {
    use std::io::Write;
    let props = &mesh.properties;
    let head = match &props.texture {
        Some(texture) => write_material(texture, path)?,
        None => String::new(),
    };
    crate::output::write_with(path, |w| {
        w.write_all(head.as_bytes())?;
        let mut points_written = 0;
        for (i, p) in mesh.positions.iter().enumerate() {
            // Points are numbered in order of first use: a new one is next.
            if props.position_id(i as u32) != points_written {
                continue;
            }
            points_written += 1;
            match &props.colors {
                Some(c) => {
                    let c = c[i];
                    writeln!(w, "v {} {} {} {} {} {}", p.x, p.y, p.z, c.x, c.y, c.z)
                }
                None => writeln!(w, "v {} {} {}", p.x, p.y, p.z),
            }?;
        }
        for t in props.uvs.iter().flatten() {
            writeln!(w, "vt {} {}", t.x, t.y)?;
        }
        for n in props.normals.iter().flatten() {
            writeln!(w, "vn {} {} {}", n.x, n.y, n.z)?;
        }
        let corner = |v: u32| {
            let p = props.position_id(v) + 1;
            let v = v + 1;
            match (props.uvs.is_some(), props.normals.is_some()) {
                (false, false) => format!("{p}"),
                (true, false) => format!("{p}/{v}"),
                (false, true) => format!("{p}//{v}"),
                (true, true) => format!("{p}/{v}/{v}"),
            }
        };
        for t in &mesh.triangles {
            if props.is_empty() {
                writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)
            } else {
                writeln!(w, "f {} {} {}", corner(t[0]), corner(t[1]), corner(t[2]))
            }?;
        }
        Ok(())
    })
}

/// Writes `<stem>.mtl` (and, where [`save_obj`] says, the image) beside the
/// OBJ at `path`; returns the OBJ's `mtllib`/`usemtl` lines.
fn write_material(texture: &Texture, path: &Path) -> Result<String> {
    // `map_Kd` readers, this crate's included, take the last word.
    let image = super::texture_beside(texture, path, |name| !name.contains(char::is_whitespace))?;
    let stem = path
        .file_stem()
        .map_or("mesh".into(), |s| s.to_string_lossy());
    let mtl = format!("{stem}.mtl");
    let folder = path.parent().unwrap_or(Path::new(""));
    crate::output::write_file(
        &folder.join(&mtl),
        format!("newmtl textured\nKd 1 1 1\nmap_Kd {image}\n").as_bytes(),
    )?;
    Ok(format!("mtllib {mtl}\nusemtl textured\n"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<RawMesh> {
        parse_obj(text.as_bytes(), Path::new("t.obj"))
    }

    fn place(text: &[u8]) -> Place {
        match parse_obj(text, Path::new("t.obj")).unwrap_err() {
            Error::Parse { place, .. } => place,
            e => panic!("not a parse error: {e}"),
        }
    }

    #[test]
    fn quad_is_fan_triangulated_and_objects_merged() {
        let raw = parse(
            "mtllib missing.mtl\no a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl x\nf 1 2 3 4\n\
             o b\nv 0 0 1\nv 1 0 1\nv 1 1 1\nf 5 6 7\n",
        )
        .unwrap();
        assert_eq!(raw.positions.len(), 7);
        assert_eq!(raw.triangles, vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]]);
    }

    /// Vertices are numbered per object in first-use order, and one used by
    /// two objects is listed twice (what `tobj` gave, so outputs did not
    /// change with the reader).
    #[test]
    fn objects_number_vertices_in_first_use_order() {
        let raw =
            parse("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 9 9 9\ng a\nf 3 2 1\ng b\nf 1 3 4\n")
                .unwrap();
        let p = |x: f32, y: f32| Vec3::new(x, y, 0.0);
        assert_eq!(
            raw.positions,
            vec![
                p(1.0, 1.0),
                p(1.0, 0.0),
                p(0.0, 0.0),
                p(0.0, 0.0),
                p(1.0, 1.0),
                p(0.0, 1.0)
            ]
        );
        assert_eq!(raw.triangles, vec![[0, 1, 2], [3, 4, 5]]);
    }

    #[test]
    fn corners_with_attributes_relative_indices_and_weights() {
        let raw = parse(
            "v 0 0 0 2\nv 2 0 0\nv 0 2 0\nvt 0 0\nvt 1 0\nvn 0 0 1\n\
             f 1/1/1 2/2/1 3//1\nf -3/-2 -2/-1 -1/-1\n",
        )
        .unwrap();
        assert_eq!(raw.positions[0], Vec3::ZERO);
        assert_eq!(raw.triangles, vec![[0, 1, 2], [0, 1, 2]]);
    }

    #[test]
    fn lines_and_points_are_not_triangles() {
        let raw = parse("v 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2 3\np 1\nf 1 2 3\nf 1 2\n").unwrap();
        assert_eq!(raw.triangles, vec![[0, 1, 2]]);
        assert_eq!(
            raw.degenerate_in_source, 1,
            "the two-corner face is counted"
        );
    }

    #[test]
    fn out_of_range_index_names_its_line() {
        let err = parse("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 2 9\n").unwrap_err();
        let s = err.to_string();
        assert!(s.contains("t.obj") && s.contains("line 5"), "{s}");
        assert_eq!(place(b"v 0 0 0\nf 1 -2 1\n").line, Some(2));
        assert_eq!(place(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n").line, Some(4));
    }

    #[test]
    fn texture_and_normal_indices_are_checked() {
        let p = place(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 1/2 2/1 3/1\n");
        assert_eq!((p.line, p.byte), (Some(6), Some(45)));
        assert_eq!(
            place(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n").line,
            Some(4)
        );
    }

    #[test]
    fn nan_coordinate_names_its_line() {
        let err = parse("v 0 0 0\nv nan 0 0\nv 1 1 0\nf 1 2 3\n").unwrap_err();
        let s = err.to_string();
        assert!(s.contains("line 2") && s.contains("NaN"), "{s}");
        assert_eq!(place(b"v 1 1 1 0\n").line, Some(1));
    }

    #[test]
    fn malformed_statements_name_their_line() {
        assert_eq!(place(b"v 0 0 0\nv 1 0 0\nv 1 x 0\nf 1 2 3\n").line, Some(3));
        assert_eq!(place(b"v 0 0 0\nv 1 0\n").line, Some(2));
        assert_eq!(
            place(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/a 2 3\n").line,
            Some(4)
        );
        assert_eq!(
            place(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n").line,
            Some(4)
        );
        assert_eq!(place(b"vn 0 0\n").line, Some(1));
    }

    #[test]
    fn line_endings_and_encodings() {
        let cr = parse("v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r").unwrap();
        assert_eq!(cr.triangles.len(), 1);
        let crlf = parse("\u{feff}v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3 # comment\r\n").unwrap();
        assert_eq!(crlf.triangles.len(), 1);
        assert_eq!(
            place(b"v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 4\r\n").line,
            Some(4)
        );
        let utf16: Vec<u8> = [0xFF, 0xFE]
            .into_iter()
            .chain(b"v\x000\x00".iter().copied())
            .collect();
        let p = place(&utf16);
        assert_eq!((p.line, p.byte), (Some(1), Some(0)));
        let p = place(b"v 0 0 0\nv 1 \xC3\x28 0\n");
        assert_eq!((p.line, p.byte), (Some(2), Some(12)));
        let p = place(b"v 0 0 0\n\x00\x01\x02");
        assert_eq!((p.line, p.byte), (Some(2), Some(8)));
    }

    /// A 100,000-corner polygon is read in linear time and cut as a
    /// zigzag: no vertex in more than 3 triangles.
    #[test]
    fn huge_polygon_is_a_zigzag() {
        let n = 100_000;
        let mut text = String::new();
        for i in 0..n {
            let a = i as f32 / n as f32 * std::f32::consts::TAU;
            text.push_str(&format!("v {} {} 0\n", a.cos(), a.sin()));
        }
        text.push('f');
        for i in 1..=n {
            text.push_str(&format!(" {i}"));
        }
        let raw = parse(&text).unwrap();
        assert_eq!(raw.triangles.len(), n - 2);
        let top = n as u32 - 1;
        assert_eq!(
            raw.triangles[..3],
            [[0, 1, top], [1, top - 1, top], [1, 2, top - 1]]
        );
        let mut valence = vec![0; n];
        for t in &raw.triangles {
            for &v in t {
                valence[v as usize] += 1;
            }
        }
        assert_eq!(valence.iter().max(), Some(&3));
    }
}
