//! Reading meshes from files: OBJ and PLY, each with its own reader, and
//! glTF 2.0 (`.gltf`, `.glb`; reader and writer) behind the feature `gltf`.
//!
//! Every loader returns a [`RawMesh`] whose positions are finite and whose
//! indices are in range, or an error naming the file and the place; [`load`]
//! then cleans it (see [`crate::mesh::clean`]).
//!
//! Writing: [`save_obj`], and [`save_ply`] (binary, with the mesh's normals,
//! texture coordinates, colours and texture file name).

#[cfg(feature = "gltf")]
mod gltf;
#[cfg(feature = "gltf")]
mod gltf_write;
mod obj;
mod ply;

#[cfg(feature = "gltf")]
pub use gltf::{parse_gltf, parse_gltf_with};
#[cfg(feature = "gltf")]
pub use gltf_write::save_gltf;
pub use obj::{parse_obj, parse_obj_with};
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
/// ([`save_obj`]), `.ply` ([`save_ply`]), and with the `gltf` feature `.glb` and `.gltf`
/// (`save_gltf`).
///
/// # Errors
/// [`Error::Io`] naming the file; [`Error::UnknownFormat`] for another
/// extension.
pub fn save_mesh(mesh: &Mesh, path: &Path) -> Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("obj") => save_obj(mesh, path),
        Some("ply") => save_ply(mesh, path),
        #[cfg(feature = "gltf")]
        Some("glb" | "gltf") => save_gltf(mesh, path),
        _ => Err(Error::UnknownFormat {
            file: path.to_owned(),
            message: "writes .obj, .ply, .glb and .gltf (by extension)".into(),
        }),
    }
}

/// Writes `mesh` as OBJ text to `path`: one `v` line per point (vertices
/// split at a seam share it, so the seam reads back as one), `vt` and `vn`
/// lines when the mesh has texture coordinates or normals (one per
/// vertex), and `f` lines with 1-based indices; floats in the shortest
/// form that reads back to the same bits. Colours are written as
/// `v x y z r g b`, per point (OBJ has no alpha and no colour seam: the
/// first vertex of a point gives it). A texture is referenced through a `.mtl` file written beside the
/// OBJ (`map_Kd`): a file texture by its path, an embedded one written as
/// an image file beside the OBJ.
///
/// # Errors
/// [`Error::Io`] naming the file.
pub fn save_obj(mesh: &Mesh, path: &Path) -> Result<()> {
    use std::fmt::Write as _;
    use std::io::Write;
    let props = &mesh.properties;
    let mut head = String::new();
    if let Some(texture) = &props.texture {
        let stem = path
            .file_stem()
            .map_or("mesh".into(), |s| s.to_string_lossy());
        let folder = path.parent().unwrap_or(Path::new(""));
        let image = match texture {
            crate::mesh::Texture::File(file) => file.display().to_string(),
            crate::mesh::Texture::Embedded { mime, bytes } => {
                let ext = if mime.contains("jpeg") { "jpg" } else { "png" };
                let name = format!("{stem}.{ext}");
                crate::output::write_file(&folder.join(&name), bytes)?;
                name
            }
        };
        let mtl = format!("{stem}.mtl");
        crate::output::write_file(
            &folder.join(&mtl),
            format!("newmtl textured\nKd 1 1 1\nmap_Kd {image}\n").as_bytes(),
        )?;
        let _ = write!(head, "mtllib {mtl}\nusemtl textured\n");
    }
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
