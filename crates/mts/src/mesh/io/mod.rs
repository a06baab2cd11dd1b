//! Reading meshes from files: OBJ and PLY, each with its own reader.
//!
//! Every loader returns a [`RawMesh`] whose positions are finite and whose
//! indices are in range, or an error naming the file and the place; [`load`]
//! then cleans it (see [`crate::mesh::clean`]).
//!
//! Writing: [`save_obj`], and [`save_ply`] (binary, with the mesh's normals,
//! texture coordinates, colours and texture file name).

mod obj;
mod ply;

pub use obj::parse_obj;
pub use ply::parse_ply;
pub use ply::save_ply;

use super::{clean, CleanOptions, CleanReport, Mesh, RawMesh};
use crate::error::{Error, Result};
use std::path::Path;

/// Cuts a polygon (corner ids in order, at least 3) into triangles of the
/// same winding: a triangle and a quad as the fan `(a, b, c), (a, c, d)`
/// every tool uses; five or more corners as a zigzag, `(c0, c1, cn-1),
/// (c1, cn-2, cn-1), (c1, c2, cn-2), ...` — the triangles of one strip
/// across the polygon. A fan would give its first corner one triangle per
/// side: a 100,000-corner face made a vertex of valence 100,000, which
/// every per-vertex loop downstream (adjacency, the vertex-cache
/// optimiser, distance queries over sliver triangles) paid for squared;
/// the zigzag keeps every valence at most 3 and the triangles' boxes apart.
/// No shared model has a face of more than four corners, so no output
/// changed.
pub(crate) fn triangulate_polygon(ids: &[u32], out: &mut Vec<[u32; 3]>) {
    let n = ids.len();
    if n < 5 {
        for i in 1..n.saturating_sub(1) {
            out.push([ids[0], ids[i], ids[i + 1]]);
        }
        return;
    }
    let (mut lo, mut hi) = (0, n - 1);
    let mut advance_low = true;
    while hi - lo >= 2 {
        if advance_low {
            out.push([ids[lo], ids[lo + 1], ids[hi]]);
            lo += 1;
        } else {
            out.push([ids[lo], ids[hi - 1], ids[hi]]);
            hi -= 1;
        }
        advance_low = !advance_low;
    }
}

/// Largest input file read, in bytes (4 GiB). Larger files are refused
/// before anything is allocated.
pub const MAX_FILE_BYTES: u64 = 4 << 30;

/// A mesh format this crate reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ (geometry only; materials are ignored).
    Obj,
    /// Stanford PLY, ascii or binary, with vertex normals, texture
    /// coordinates and colours.
    Ply,
}

impl Format {
    /// Picks the format from the file extension, then from the content
    /// (`ply` magic line; `v `/`f `/`o `/`#` lines for OBJ).
    ///
    /// # Errors
    /// [`Error::UnknownFormat`] when neither tells.
    pub fn detect(path: &Path, bytes: &[u8]) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("obj") => return Ok(Format::Obj),
            Some("ply") => return Ok(Format::Ply),
            _ => {}
        }
        if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n") {
            return Ok(Format::Ply);
        }
        let head = &bytes[..bytes.len().min(4096)];
        if let Ok(text) = std::str::from_utf8(head) {
            let obj_like = text.lines().any(|l| {
                let l = l.trim_start();
                l.starts_with("v ") || l.starts_with("f ") || l.starts_with("o ")
            });
            if obj_like {
                return Ok(Format::Obj);
            }
        }
        Err(Error::UnknownFormat {
            file: path.to_owned(),
            message:
                "expected a .obj or .ply file (no extension matched, and from byte 0 the content \
                      starts with neither a `ply` line nor OBJ statements)"
                    .into(),
        })
    }
}

/// How [`load`] reads and cleans a file.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LoadOptions {
    /// Cleaning options (weld of identical positions).
    pub clean: CleanOptions,
}

/// Reads a whole file into memory, refusing files over [`MAX_FILE_BYTES`]
/// and anything that is not a regular file (a device such as `/dev/zero`
/// or a pipe reports no size and may never end). Never reads past
/// [`MAX_FILE_BYTES`], whatever the file's size turns out to be.
///
/// # Errors
/// [`Error::Io`] when the file cannot be read, [`Error::Parse`] when it is
/// too large or not a regular file.
pub fn read_file(path: &Path) -> Result<Vec<u8>> {
    use std::io::Read;
    let io = |source| Error::Io {
        file: path.to_owned(),
        source,
    };
    let refuse = |message: String| Error::Parse {
        file: path.to_owned(),
        place: crate::Place::default(),
        message,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(refuse(
            "not a regular file (a directory, device or pipe): inputs are read whole from files"
                .into(),
        ));
    }
    let len = meta.len();
    if len > MAX_FILE_BYTES {
        return Err(refuse(format!(
            "file is {len} bytes, more than the {MAX_FILE_BYTES} this reader accepts"
        )));
    }
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(refuse(format!(
            "file grew past the {MAX_FILE_BYTES} bytes this reader accepts while it was read"
        )));
    }
    Ok(bytes)
}

/// Parses mesh bytes in the given format; `path` names the input in errors.
///
/// # Errors
/// As [`parse_obj`] and [`parse_ply`].
pub fn parse(bytes: &[u8], format: Format, path: &Path) -> Result<RawMesh> {
    match format {
        Format::Obj => parse_obj(bytes, path),
        Format::Ply => parse_ply(bytes, path),
    }
}

/// Loads and cleans a mesh file (OBJ or PLY, detected by [`Format::detect`]).
///
/// # Errors
/// [`Error::Io`], [`Error::UnknownFormat`], [`Error::Parse`] with the place
/// of the problem, or [`Error::InvalidMesh`] when no triangle is left.
///
/// Cost: O(file size) time, the file is held in memory while parsing.
pub fn load(path: &Path, options: LoadOptions) -> Result<(Mesh, CleanReport)> {
    let bytes = read_file(path)?;
    let format = Format::detect(path, &bytes)?;
    let raw = parse(&bytes, format, path)?;
    clean(raw, options.clean, &path.display().to_string())
}

/// Writes `mesh` as OBJ text (`v` and `f` lines, 1-based indices, shortest
/// round-tripping floats) to `path`.
///
/// # Errors
/// [`Error::Io`] naming the file.
pub fn save_obj(mesh: &Mesh, path: &Path) -> Result<()> {
    use std::io::Write;
    let io = |source| Error::Io {
        file: path.to_owned(),
        source,
    };
    let file = std::fs::File::create(path).map_err(io)?;
    let mut w = std::io::BufWriter::new(file);
    for p in &mesh.positions {
        writeln!(w, "v {} {} {}", p.x, p.y, p.z).map_err(io)?;
    }
    for t in &mesh.triangles {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).map_err(io)?;
    }
    w.flush().map_err(io)
}

#[cfg(test)]
mod tests {
    use super::triangulate_polygon;

    /// Every convex polygon from 3 to 40 corners: n - 2 triangles, all
    /// counter-clockwise like the polygon, covering its area exactly.
    #[test]
    fn polygons_keep_winding_and_area() {
        for n in 3..=40u32 {
            let corner = |i: u32| {
                let a = i as f64 / f64::from(n) * std::f64::consts::TAU;
                (a.cos(), a.sin())
            };
            let ids: Vec<u32> = (0..n).collect();
            let mut out = Vec::new();
            triangulate_polygon(&ids, &mut out);
            assert_eq!(out.len(), n as usize - 2, "{n} corners");
            let mut total = 0.0;
            for t in &out {
                let [(ax, ay), (bx, by), (cx, cy)] = t.map(corner);
                let area = 0.5 * ((bx - ax) * (cy - ay) - (cx - ax) * (by - ay));
                assert!(area > 0.0, "{n} corners: {t:?} is clockwise");
                total += area;
            }
            let polygon = 0.5 * f64::from(n) * (std::f64::consts::TAU / f64::from(n)).sin();
            assert!(
                (total - polygon).abs() < 1e-9,
                "{n} corners: {total} vs {polygon}"
            );
        }
    }
}
