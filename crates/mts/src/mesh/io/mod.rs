//! Reading meshes from files: OBJ and PLY, each with its own reader, and
//! glTF 2.0 (`.gltf`, `.glb`; reader and writer) behind the feature `gltf`.
//!
//! Every loader returns a [`RawMesh`] whose positions are finite and whose
//! indices are in range, or an error naming the file and the place; [`load`]
//! then cleans it (see [`crate::mesh::clean`]).
//!
//! Writing: [`save_mesh`] by extension ([`save_obj`] with a `.mtl` for
//! the texture, [`save_ply`] binary, `save_gltf` with the feature), every
//! property the format can hold ([`dropped_by`] names the rest); a chain
//! of levels in one glTF file for engines (`save_lod_chain`: MSFT_lod,
//! levels of [`ChainLevel`] in vertex-cache order).

#[cfg(feature = "gltf")]
mod gltf;
#[cfg(feature = "gltf")]
mod gltf_compress;
#[cfg(feature = "gltf")]
mod gltf_meshopt;
#[cfg(feature = "gltf")]
mod gltf_write;
mod lod_chain;
mod obj;
mod ply;

#[cfg(feature = "gltf")]
pub use gltf::{gltf_part_count, parse_gltf, parse_gltf_parts, parse_gltf_with, GltfPart};
#[cfg(feature = "gltf")]
pub use gltf_compress::Grid;
#[cfg(feature = "gltf")]
pub use gltf_write::{save_gltf, save_gltf_as, Encoding};
#[cfg(feature = "gltf")]
pub use lod_chain::save_lod_chain;
pub use lod_chain::{
    chain_from_collapses, order_for_cache, screen_coverages, ChainLevel, Coverage,
};
pub use obj::{parse_obj, parse_obj_with, save_obj};
pub use ply::parse_ply;
pub use ply::save_ply;

use super::{clean, CleanOptions, CleanReport, Mesh, RawMesh, Texture};
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
    /// glTF 2.0, JSON (`.gltf`) or binary (`.glb`).
    #[cfg(feature = "gltf")]
    Gltf,
}

impl Format {
    /// Picks the format from the file extension, then from the content
    /// (`ply` magic line; with the feature `gltf`, the GLB magic `glTF`;
    /// `v `/`f `/`o `/`#` lines for OBJ).
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
            #[cfg(feature = "gltf")]
            Some("gltf" | "glb") => return Ok(Format::Gltf),
            _ => {}
        }
        if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n") {
            return Ok(Format::Ply);
        }
        #[cfg(feature = "gltf")]
        if bytes.starts_with(b"glTF") {
            return Ok(Format::Gltf);
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
            message: if cfg!(feature = "gltf") {
                "expected a .obj, .ply, .gltf or .glb file (no extension matched, and from byte 0 \
                 the content starts with neither a `ply` line, the GLB magic `glTF`, nor OBJ \
                 statements)"
            } else {
                "expected a .obj or .ply file (no extension matched, and from byte 0 the content \
                 starts with neither a `ply` line nor OBJ statements)"
            }
            .into(),
        })
    }
}

/// The most triangles [`LoadOptions::default`] lets a file ask for:
/// 2^24 = 16,777,216. Building the model of that many takes about 10 GB
/// (650 bytes a triangle at the peak, measured on the 1M icosphere), which
/// is what a workstation has; a larger scan loads with a larger limit.
pub const DEFAULT_MAX_TRIANGLES: u64 = 1 << 24;

/// How a limit error tells the user what to do.
pub(crate) const RAISE_LIMIT: &str =
    " this load allows (LoadOptions::max_triangles; `mts --max-triangles N` raises it)";

/// How [`load`] reads and cleans a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LoadOptions {
    /// Cleaning options (weld of identical positions).
    pub clean: CleanOptions,
    /// Read normals, texture coordinates, colours and the texture
    /// ([`crate::mesh::Properties`]); positions only otherwise (an OBJ's
    /// vertices are then not split at seams).
    pub properties: bool,
    /// The most triangles the file may ask for (polygons triangulated,
    /// strips decoded, glTF instances counted each time), and three times
    /// as many vertices; more is an [`Error::Parse`] saying so. It bounds
    /// the work and memory a small file can ask for: glTF instancing
    /// multiplies a mesh by its nodes, and a one-byte strip index is a
    /// triangle. Default [`DEFAULT_MAX_TRIANGLES`].
    pub max_triangles: u64,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            clean: CleanOptions::default(),
            properties: false,
            max_triangles: DEFAULT_MAX_TRIANGLES,
        }
    }
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
    let not_a_file = || {
        refuse(
            "not a regular file (a directory, device or pipe): inputs are read whole from files"
                .into(),
        )
    };
    // Checked before opening: opening a FIFO for reading blocks until a
    // writer comes, which may be never. Checked again on the open file, for
    // a path swapped in between.
    if !std::fs::metadata(path).map_err(io)?.is_file() {
        return Err(not_a_file());
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(not_a_file());
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

/// Parses mesh bytes in the given format; `path` names the input in errors
/// (and, for glTF, is the folder external buffers are read from).
///
/// # Errors
/// As [`parse_obj`], [`parse_ply`] and `parse_gltf`.
pub fn parse(bytes: &[u8], format: Format, path: &Path) -> Result<RawMesh> {
    match format {
        Format::Obj => parse_obj(bytes, path),
        Format::Ply => parse_ply(bytes, path),
        #[cfg(feature = "gltf")]
        Format::Gltf => parse_gltf(bytes, path),
    }
}

/// Loads and cleans a mesh file (OBJ, PLY or, with the feature `gltf`,
/// glTF; detected by [`Format::detect`]).
///
/// # Errors
/// [`Error::Io`], [`Error::UnknownFormat`], [`Error::Parse`] with the place
/// of the problem, or [`Error::InvalidMesh`] when no triangle is left.
///
/// Cost: O(file size) time, the file is held in memory while parsing.
pub fn load(path: &Path, options: LoadOptions) -> Result<(Mesh, CleanReport)> {
    load_bytes(&read_file(path)?, path, options)
}

/// [`load`] of a file already read: `path` names it in errors, tells its
/// format with the bytes and, for glTF and OBJ, is the folder external
/// buffers and textures are read from.
///
/// # Errors
/// As [`load`].
pub fn load_bytes(bytes: &[u8], path: &Path, options: LoadOptions) -> Result<(Mesh, CleanReport)> {
    let format = Format::detect(path, bytes)?;
    let mut raw = match format {
        Format::Obj => parse_obj_with(bytes, path, options.properties)?,
        #[cfg(feature = "gltf")]
        Format::Gltf => parse_gltf_with(bytes, path, options.max_triangles)?,
        Format::Ply => parse_ply(bytes, path)?,
    };
    // OBJ and PLY hold at most a triangle per byte or two of the file (a
    // strip or polygon of one-byte indices), so the file's size bounds
    // what was read; the limit bounds what the caller does next.
    let (triangles, vertices) = (raw.triangles.len() as u64, raw.positions.len() as u64);
    if triangles > options.max_triangles || vertices > options.max_triangles.saturating_mul(3) {
        return Err(Error::Parse {
            file: path.to_owned(),
            place: crate::Place::default(),
            message: format!(
                "{triangles} triangles over {vertices} vertices, more than the limit of {} \
                 triangles (and three times as many vertices){RAISE_LIMIT}",
                options.max_triangles
            ),
        });
    }
    if !options.properties {
        raw.properties = crate::mesh::Properties::default();
    }
    clean(raw, options.clean, &path.display().to_string())
}

/// Writes `mesh` in the format its extension names: `.obj`
/// ([`save_obj`]), `.ply` ([`save_ply`]), and with the `gltf` feature `.glb`
/// and `.gltf` (`save_gltf`). Each writes every vertex of `mesh` in its
/// order, with every property the format holds; [`dropped_by`] names what
/// it cannot hold. A level of a model is made compact first with
/// [`Mesh::level`] (only the vertices its triangles use).
///
/// # Errors
/// [`Error::Io`] naming the file; [`Error::UnknownFormat`] for another
/// extension; as the format's writer.
pub fn save_mesh(mesh: &Mesh, path: &Path) -> Result<()> {
    match extension(path).as_deref() {
        Some("obj") => save_obj(mesh, path),
        Some("ply") => save_ply(mesh, path),
        #[cfg(feature = "gltf")]
        Some("glb" | "gltf") => save_gltf(mesh, path),
        _ => Err(Error::UnknownFormat {
            file: path.to_owned(),
            message: if cfg!(feature = "gltf") {
                "writes .obj, .ply, .glb and .gltf (by extension)"
            } else {
                "writes .obj and .ply (by extension; .glb and .gltf with the feature `gltf`)"
            }
            .into(),
        }),
    }
}

/// What of `mesh` the format [`save_mesh`] picks for `path` cannot hold,
/// as names for one warning ("colour alpha", "colour seams"), in that
/// order; empty when everything is written, and for an extension
/// [`save_mesh`] refuses.
///
/// - OBJ holds normals, texture coordinates and the texture (a `.mtl`
///   beside it) but colours only as `v x y z r g b`, one per point: an
///   alpha other than 1 is "colour alpha", vertices of one point with
///   different colours are "colour seams" (the first vertex's is kept).
/// - PLY and glTF hold every property ([`save_ply`] quantises colours to
///   8 bits a channel, which is not counted as a loss).
///
/// Position ids (which split vertices are one point) are not listed: PLY
/// and glTF have no place for them, and loading welds bit-identical
/// positions back into one point.
///
/// Cost: O(vertices) for an OBJ with colours, O(1) otherwise.
#[must_use]
pub fn dropped_by(mesh: &Mesh, path: &Path) -> Vec<&'static str> {
    let mut dropped = Vec::new();
    if extension(path).as_deref() != Some("obj") {
        return dropped;
    }
    let Some(colors) = &mesh.properties.colors else {
        return dropped;
    };
    if colors.iter().any(|c| c.w != 1.0) {
        dropped.push("colour alpha");
    }
    let mut first: Vec<Option<[u32; 3]>> = Vec::new();
    let seams = colors.iter().enumerate().any(|(v, c)| {
        let id = mesh.properties.position_id(v as u32) as usize;
        if first.len() <= id {
            first.resize(id + 1, None);
        }
        let rgb = c.truncate().to_array().map(f32::to_bits);
        *first[id].get_or_insert(rgb) != rgb
    });
    if seams {
        dropped.push("colour seams");
    }
    dropped
}

/// The extension of `path`, lower case.
fn extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}

/// How a mesh file at `path` (OBJ's `.mtl`, PLY's `TextureFile`) names
/// `texture`, relative to `path`'s folder: a file in that folder or below
/// by its relative path (`/` between segments), when `fits` accepts it; any
/// other file, and embedded bytes, copied beside `path` as `<stem>.<ext>`
/// (white space in the stem made `_`; the file's own extension, else
/// `png` or `jpg` by MIME type or signature) and named so. The output's
/// folder then holds everything it refers to: it can be moved whole, and
/// readers that refuse paths climbing out of it (trimesh) find the image.
/// A file that cannot be read (loading already warns about missing
/// textures and drops them) is named where it is, relative (`..`) or
/// absolute, when `fits` accepts that. Written whole or not at all
/// ([`crate::output`]).
///
/// # Errors
/// [`Error::Io`] naming the texture file that cannot be read (and cannot
/// be named) or the copy that cannot be written;
/// [`Error::InvalidArgument`] for a texture path that is not UTF-8.
pub(crate) fn texture_beside(
    texture: &Texture,
    path: &Path,
    fits: impl Fn(&str) -> bool,
) -> Result<String> {
    let folder = path.parent().unwrap_or(Path::new(""));
    let (ext, bytes) = match texture {
        Texture::File(file) => {
            let relative = relative_segments(file, folder)?;
            let inside = relative
                .as_ref()
                .filter(|s| s.first().is_some_and(|first| first != ".."))
                .map(|s| s.join("/"))
                .filter(|name| fits(name));
            if let Some(name) = inside {
                return Ok(name);
            }
            let bytes = match read_file(file) {
                Ok(bytes) => bytes,
                Err(e) => {
                    // Nothing to copy: named where it is, as the input did.
                    let name = match relative {
                        Some(s) => s.join("/"),
                        None => std::path::absolute(file)
                            .unwrap_or_else(|_| file.to_owned())
                            .display()
                            .to_string(),
                    };
                    return if fits(&name) { Ok(name) } else { Err(e) };
                }
            };
            let ext = file
                .extension()
                .and_then(|e| e.to_str())
                .filter(|e| !e.is_empty() && !e.contains(char::is_whitespace))
                .map_or_else(
                    || image_extension("", &bytes).to_owned(),
                    str::to_ascii_lowercase,
                );
            (ext, std::borrow::Cow::Owned(bytes))
        }
        Texture::Embedded { mime, bytes } => (
            image_extension(mime, bytes).to_owned(),
            std::borrow::Cow::Borrowed(bytes.as_slice()),
        ),
    };
    let stem: String = path
        .file_stem()
        .map_or("mesh".into(), |s| s.to_string_lossy())
        .chars()
        .map(|c| if c.is_whitespace() { '_' } else { c })
        .collect();
    let name = format!("{stem}.{ext}");
    crate::output::write_file(&folder.join(&name), &bytes)?;
    Ok(name)
}

/// `jpg` for a JPEG (by MIME type, else by signature), else `png`.
fn image_extension(mime: &str, bytes: &[u8]) -> &'static str {
    let jpeg = mime.contains("jpeg") || (mime.is_empty() && bytes.starts_with(&[0xff, 0xd8, 0xff]));
    if jpeg {
        "jpg"
    } else {
        "png"
    }
}

/// The path of `file` relative to `folder` as segments (`..` to climb),
/// both made absolute against the working directory (no symbolic link is
/// resolved); `None` when they share no root (another drive).
///
/// # Errors
/// [`Error::Io`] when the working directory cannot be read,
/// [`Error::InvalidArgument`] when a segment is not UTF-8.
pub(crate) fn relative_segments(file: &Path, folder: &Path) -> Result<Option<Vec<String>>> {
    use std::path::Component;
    let absolute = |p: &Path| {
        std::path::absolute(if p.as_os_str().is_empty() {
            Path::new(".")
        } else {
            p
        })
        .map_err(|source| Error::Io {
            file: p.to_owned(),
            source,
        })
    };
    fn normal(p: &Path) -> Vec<Component<'_>> {
        p.components()
            .filter(|c| !matches!(c, Component::CurDir))
            .collect()
    }
    let (file_abs, folder_abs) = (absolute(file)?, absolute(folder)?);
    let (f, d) = (normal(&file_abs), normal(&folder_abs));
    let common = f.iter().zip(&d).take_while(|(a, b)| a == b).count();
    if common == 0 {
        return Ok(None);
    }
    let mut segments: Vec<String> = vec!["..".into(); d.len() - common];
    for c in &f[common..] {
        let Some(s) = c.as_os_str().to_str() else {
            return Err(Error::InvalidArgument(format!(
                "texture {}: not a UTF-8 path",
                file.display()
            )));
        };
        segments.push(s.to_owned());
    }
    Ok(Some(segments))
}
