//! glTF 2.0 writer (feature `gltf`): one mesh, one indexed triangle-list
//! primitive, as a `.glb` or as a `.gltf` with its buffer in a sibling
//! `.bin`; the pieces ([`Document`]) are shared with the LoD chain writer
//! ([`super::lod_chain`]). The reader is [`super::parse_gltf`].
//!
//! Layout (glTF 2.0, binary data storage and the GLB format): one buffer of tightly packed, 4-byte
//! aligned views in the order indices, `POSITION` (with the `min`/`max` the
//! specification requires), then `NORMAL`, `TEXCOORD_0` (`v` flipped back
//! to glTF's downward axis), `COLOR_0` (float vec4) when present, then the
//! base-colour image when it is embedded. Indices are u16 when every index
//! fits below 65535 (the value glTF reserves), else u32. The JSON is built
//! with `serde_json` rather than `gltf-json`'s structs: the document is
//! fixed and small, and the reader's tests parse every written file back
//! with the `gltf` crate's full validation.
//!
//! **Quantized and compressed** ([`Encoding`], [`save_gltf_as`]): the
//! streams of `gltf_compress` (`KHR_mesh_quantization`), the node placing
//! the position grid; compressed, every vertex and index view is coded in
//! buffer 0 and decodes into buffer 1, a fallback without data
//! (`EXT_meshopt_compression`, required). Those files pass the Khronos
//! validator (checked outside the tests: the `gltf` crate's validation
//! refuses any required extension it does not implement).
//!
//! **The texture.** A `.glb` is one self-contained file: a
//! [`Texture::File`] is read and its bytes embedded (a file that cannot be
//! read is an error naming it; loading already drops, with a warning,
//! textures that are missing). A `.gltf` refers to a texture file by a
//! relative URI rather than copying it (the image stays one file, and the
//! `.gltf` is meant to sit beside its assets); embedded bytes go into its
//! `.bin`. The material is unlit-looking PBR: base-colour texture,
//! metallic 0, roughness 1.
//!
//! What is lost: position ids (glTF has no seams; weld on load merges
//! bit-identical positions again). A zero normal (the mesh's "no normal")
//! is written as the area-weighted normal of the triangles around its
//! point, or `+z` where they have no area: glTF normals are unit length,
//! and validators refuse zero ones.
//!
//! The `v` flip `1 - v` is exact for `v` in `[0.5, 1]` and for every `v`
//! that is a multiple of 2^-24 in `[0, 1]` (any texel corner of an image
//! up to 2^24 texels wide); elsewhere `1 - (1 - v)` may differ from `v` by
//! up to 2^-25 (half an ulp of 1.0).

use super::gltf_compress::{self, Grid};
use crate::error::{Error, Result};
use crate::mesh::{Mesh, Texture};
use glam::Vec3;
use serde_json::{json, Value};
use std::path::Path;

/// glTF's `ARRAY_BUFFER` and `ELEMENT_ARRAY_BUFFER` targets, `FLOAT`,
/// `UNSIGNED_SHORT` and `UNSIGNED_INT` component types, `TRIANGLES` mode.
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const BYTE: u32 = 5120;
const SHORT: u32 = 5122;
const UNSIGNED_BYTE: u32 = 5121;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
const TRIANGLES: u32 = 4;

/// Writes `mesh` as glTF 2.0 to `path`: a single binary `.glb`, or a
/// `.gltf` JSON file with its buffer beside it as `<stem>.bin`, chosen by
/// the extension (see the module docs for the layout and the texture).
/// Every vertex of `mesh` is written in its order; the mesh is expected to
/// satisfy [`Mesh::validate`] (so it holds only the vertices its triangles
/// use).
///
/// # Errors
/// [`Error::InvalidArgument`] for another extension, a mesh without
/// triangles, a `.glb` over 4 GiB, an embedded image that is neither PNG
/// nor JPEG and names no MIME type, or a texture file with no relative path
/// from the `.gltf`'s folder; [`Error::Io`] naming the file that cannot be
/// written (or the texture file that cannot be read).
///
/// Cost: O(V + T); the buffer is built in memory (about 52 bytes per vertex
/// with every property, 12 per triangle) before it is written.
pub fn save_gltf(mesh: &Mesh, path: &Path) -> Result<()> {
    save_gltf_as(mesh, path, Encoding::Plain)
}

/// [`save_gltf`] with the vertex data stored as `encoding` says
/// ([`Encoding::Quantized`], [`Encoding::Compressed`]: positions on a
/// 14-bit grid placed by the node's transform, the other attributes as
/// `gltf_compress` lists; vertices stored alike merged). Quantized, the
/// triangles are written in `mesh`'s order (give a mesh in vertex-cache
/// order, [`super::order_for_cache`]); compressed, they are first put in
/// the strip-like cache order the index codec does best with. Vertices are
/// numbered in order of first use.
///
/// # Errors
/// As [`save_gltf`].
pub fn save_gltf_as(mesh: &Mesh, path: &Path, encoding: Encoding) -> Result<()> {
    let binary = is_binary(path)?;
    let mut out = Document::new(encoding, &mesh.positions);
    let mut primitive = out.primitive(mesh, path)?;
    let mut node = json!({ "mesh": 0 });
    out.place_node(&mut node);
    let mut root = json!({
        "asset": { "version": "2.0", "generator": "mts" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [node],
    });
    if let Some(texture) = &mesh.properties.texture {
        out.material(&mut root, texture, binary, path)?;
        primitive["material"] = json!(0);
    }
    root["meshes"] = json!([{ "primitives": [primitive] }]);
    out.write(root, binary, path)
}

/// Whether `path` names a `.glb` (binary) or a `.gltf`.
///
/// # Errors
/// [`Error::InvalidArgument`] for another extension.
pub(super) fn is_binary(path: &Path) -> Result<bool> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("glb") => Ok(true),
        Some("gltf") => Ok(false),
        _ => Err(Error::InvalidArgument(format!(
            "{}: a glTF file is named .glb or .gltf",
            path.display()
        ))),
    }
}

/// How a glTF file's vertex data are stored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Encoding {
    /// Floats and u16/u32 indices, exact (the default).
    #[default]
    Plain,
    /// Attributes quantized (`KHR_mesh_quantization`, the layout of
    /// `gltf_compress`), views uncompressed.
    Quantized,
    /// Quantized, then every vertex and index view coded with
    /// meshoptimizer's codecs (`EXT_meshopt_compression`): what gltfpack
    /// `-cc` writes, read by any loader with meshoptimizer's decoder.
    Compressed,
}

/// The buffer and the views and accessors into it, as they are built.
#[derive(Default)]
pub(super) struct Document {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    encoding: Encoding,
    /// The positions' grid, for [`Encoding::Quantized`] and
    /// [`Encoding::Compressed`].
    grid: Option<Grid>,
    /// The length of the fallback buffer (buffer 1, no data) that the
    /// compressed views decode into.
    fallback: usize,
}

impl Document {
    /// A document whose data are stored as `encoding` says; a quantized one
    /// puts every position on the grid over `points` (all the levels'
    /// positions, so that levels share one grid and one node transform).
    pub(super) fn new<'a>(encoding: Encoding, points: impl IntoIterator<Item = &'a Vec3>) -> Self {
        Document {
            encoding,
            grid: (encoding != Encoding::Plain).then(|| Grid::covering(points)),
            ..Document::default()
        }
    }

    /// Gives `node` the translation and uniform scale that map the
    /// quantized positions back (nothing for plain data).
    pub(super) fn place_node(&self, node: &mut Value) {
        if let Some(grid) = &self.grid {
            node["translation"] = json!(grid.origin.to_array());
            node["scale"] = json!([grid.step, grid.step, grid.step]);
        }
    }

    /// The triangle-list primitive of `mesh` (indices and every attribute
    /// it has; no material), its data appended to the buffer. `path` names
    /// the output in errors.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a mesh without triangles.
    pub(super) fn primitive(&mut self, mesh: &Mesh, path: &Path) -> Result<Value> {
        if mesh.triangles.is_empty() {
            return Err(Error::InvalidArgument(format!(
                "{}: a mesh without triangles cannot be written as glTF (accessors hold at least one element)",
                path.display()
            )));
        }
        debug_assert!(
            mesh.validate().is_ok(),
            "glTF writer: {:?}",
            mesh.validate()
        );
        if let Some(grid) = self.grid {
            return Ok(self.quantized_primitive(mesh, &grid));
        }
        let properties = &mesh.properties;
        let corners = mesh.triangles.iter().flatten();
        let (bytes, component) = if mesh.positions.len() > 65535 {
            let bytes = corners.flat_map(|i| i.to_le_bytes()).collect();
            (bytes, UNSIGNED_INT)
        } else {
            let bytes = corners.flat_map(|&i| (i as u16).to_le_bytes()).collect();
            (bytes, UNSIGNED_SHORT)
        };
        let count = mesh.triangles.len() * 3;
        let indices = self.accessor(bytes, ELEMENT_ARRAY_BUFFER, component, "SCALAR", count);
        let floats = |values: &mut dyn Iterator<Item = f32>| -> Vec<u8> {
            values.flat_map(f32::to_le_bytes).collect()
        };
        let mut attributes = serde_json::Map::new();
        let n = mesh.positions.len();
        let position = self.accessor(
            floats(&mut mesh.positions.iter().flat_map(|p| p.to_array())),
            ARRAY_BUFFER,
            FLOAT,
            "VEC3",
            n,
        );
        let (lo, hi) = crate::mesh::bounds_of(&mesh.positions).unwrap_or_default();
        self.accessors[position]["min"] = json!(lo.to_array());
        self.accessors[position]["max"] = json!(hi.to_array());
        attributes.insert("POSITION".into(), json!(position));
        if let Some(normals) = &properties.normals {
            let filled;
            let normals = if normals.contains(&Vec3::ZERO) {
                filled = fill_zero_normals(mesh, normals);
                &filled
            } else {
                normals
            };
            let a = self.accessor(
                floats(&mut normals.iter().flat_map(|v| v.to_array())),
                ARRAY_BUFFER,
                FLOAT,
                "VEC3",
                n,
            );
            attributes.insert("NORMAL".into(), json!(a));
        }
        if let Some(uvs) = &properties.uvs {
            let a = self.accessor(
                floats(&mut uvs.iter().flat_map(|t| [t.x, 1.0 - t.y])),
                ARRAY_BUFFER,
                FLOAT,
                "VEC2",
                n,
            );
            attributes.insert("TEXCOORD_0".into(), json!(a));
        }
        if let Some(colors) = &properties.colors {
            let a = self.accessor(
                floats(&mut colors.iter().flat_map(|c| c.to_array())),
                ARRAY_BUFFER,
                FLOAT,
                "VEC4",
                n,
            );
            attributes.insert("COLOR_0".into(), json!(a));
        }
        Ok(json!({ "attributes": attributes, "indices": indices, "mode": TRIANGLES }))
    }

    /// [`Document::primitive`] quantized, and compressed when the encoding
    /// says so (the layout of [`super::gltf_compress`]).
    fn quantized_primitive(&mut self, mesh: &Mesh, grid: &Grid) -> Value {
        let compressed = self.encoding == Encoding::Compressed;
        let filled;
        let normals = match &mesh.properties.normals {
            Some(n) if n.contains(&Vec3::ZERO) => {
                filled = fill_zero_normals(mesh, n);
                Some(&filled[..])
            }
            other => other.as_deref(),
        };
        let q = gltf_compress::quantize(mesh, normals, grid, compressed);
        let n = q.vertex_count;
        let indices: Vec<u32> = q.triangles.iter().flatten().copied().collect();
        let (component, size) = if n > 65535 {
            (UNSIGNED_INT, 4)
        } else {
            (UNSIGNED_SHORT, 2)
        };
        let bytes: Vec<u8> = if size == 4 {
            indices.iter().flat_map(|i| i.to_le_bytes()).collect()
        } else {
            indices
                .iter()
                .flat_map(|&i| (i as u16).to_le_bytes())
                .collect()
        };
        let view = if compressed {
            let coded = gltf_compress::encode_triangles(&indices, n);
            self.compressed_view(
                &coded,
                &bytes,
                size,
                "TRIANGLES",
                None,
                ELEMENT_ARRAY_BUFFER,
            )
        } else {
            self.view(&bytes, Some(ELEMENT_ARRAY_BUFFER))
        };
        let indices = self.push_accessor(view, component, false, "SCALAR", indices.len());
        let mut attributes = serde_json::Map::new();
        let position = self.attribute(&q.positions, 8, None, UNSIGNED_SHORT, false, "VEC3", n);
        self.accessors[position]["min"] = json!(q.lo);
        self.accessors[position]["max"] = json!(q.hi);
        attributes.insert("POSITION".into(), json!(position));
        if let Some(bytes) = &q.normals {
            let filter = compressed.then_some("OCTAHEDRAL");
            let a = self.attribute(bytes, 4, filter, BYTE, true, "VEC3", n);
            attributes.insert("NORMAL".into(), json!(a));
        }
        if let Some((bytes, unit)) = &q.uvs {
            let a = if *unit {
                self.attribute(bytes, 4, None, SHORT, true, "VEC2", n)
            } else {
                self.attribute(bytes, 8, None, FLOAT, false, "VEC2", n)
            };
            attributes.insert("TEXCOORD_0".into(), json!(a));
        }
        if let Some(bytes) = &q.colors {
            let a = self.attribute(bytes, 4, None, UNSIGNED_BYTE, true, "VEC4", n);
            attributes.insert("COLOR_0".into(), json!(a));
        }
        json!({ "attributes": attributes, "indices": indices, "mode": TRIANGLES })
    }

    /// A vertex attribute of `count` elements every `stride` bytes in
    /// `bytes`, compressed (with `filter`) when the encoding says so; the
    /// accessor's index.
    #[allow(clippy::too_many_arguments)]
    fn attribute(
        &mut self,
        bytes: &[u8],
        stride: usize,
        filter: Option<&str>,
        component: u32,
        normalized: bool,
        ty: &str,
        count: usize,
    ) -> usize {
        let view = if self.encoding == Encoding::Compressed {
            let coded = gltf_compress::encode_attributes(bytes, stride);
            self.compressed_view(&coded, bytes, stride, "ATTRIBUTES", filter, ARRAY_BUFFER)
        } else {
            self.view(bytes, Some(ARRAY_BUFFER))
        };
        self.views[view]["byteStride"] = json!(stride);
        self.push_accessor(view, component, normalized, ty, count)
    }

    /// A view of `plain` (elements of `stride` bytes) whose data are
    /// `coded` in buffer 0, decoding into the fallback buffer 1; its index.
    fn compressed_view(
        &mut self,
        coded: &[u8],
        plain: &[u8],
        stride: usize,
        mode: &str,
        filter: Option<&str>,
        target: u32,
    ) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        self.fallback = self.fallback.next_multiple_of(4);
        let mut extension = json!({
            "buffer": 0,
            "byteOffset": self.bin.len(),
            "byteLength": coded.len(),
            "byteStride": stride,
            "mode": mode,
            "count": plain.len() / stride,
        });
        if let Some(filter) = filter {
            extension["filter"] = json!(filter);
        }
        self.bin.extend_from_slice(coded);
        self.views.push(json!({
            "buffer": 1,
            "byteOffset": self.fallback,
            "byteLength": plain.len(),
            "target": target,
            "extensions": { "EXT_meshopt_compression": extension },
        }));
        self.fallback += plain.len();
        self.views.len() - 1
    }

    /// An accessor over view `view`; its index.
    fn push_accessor(
        &mut self,
        view: usize,
        component: u32,
        normalized: bool,
        ty: &str,
        count: usize,
    ) -> usize {
        let mut accessor = json!({
            "bufferView": view,
            "componentType": component,
            "type": ty,
            "count": count,
        });
        if normalized {
            accessor["normalized"] = json!(true);
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Puts material 0 into `root`: base-colour texture 0 sampling image 0,
    /// `texture` (embedded in the buffer, or for a file beside a `.gltf` a
    /// relative URI; see the module docs).
    ///
    /// # Errors
    /// As [`save_gltf`] for the texture.
    pub(super) fn material(
        &mut self,
        root: &mut Value,
        texture: &Texture,
        binary: bool,
        path: &Path,
    ) -> Result<()> {
        let image = self.image(texture, binary, path)?;
        root["images"] = json!([image]);
        root["textures"] = json!([{ "source": 0 }]);
        root["materials"] = json!([{
            "pbrMetallicRoughness": {
                "baseColorTexture": { "index": 0 },
                "metallicFactor": 0.0,
                "roughnessFactor": 1.0,
            }
        }]);
        Ok(())
    }

    /// Completes `root` with the buffer, views and accessors and writes it
    /// to `path`: one `.glb`, or the `.gltf` and its `<stem>.bin` (each
    /// whole or not at all, [`crate::output`]).
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a `.glb` over 4 GiB or a `.gltf`
    /// whose name is not UTF-8; [`Error::Io`] naming the file that cannot
    /// be written.
    pub(super) fn write(self, mut root: Value, binary: bool, path: &Path) -> Result<()> {
        let mut buffer = json!({ "byteLength": self.bin.len() });
        let bin_path = path.with_extension("bin");
        if !binary {
            let name = bin_path
                .file_name()
                .and_then(|n| n.to_str())
                .ok_or_else(|| {
                    Error::InvalidArgument(format!("{}: not a UTF-8 file name", path.display()))
                })?;
            buffer["uri"] = json!(encode_uri_segment(name));
        }
        root["buffers"] = json!([buffer]);
        let mut extensions = Vec::new();
        if self.encoding != Encoding::Plain {
            extensions.push("KHR_mesh_quantization");
        }
        if self.encoding == Encoding::Compressed {
            extensions.push("EXT_meshopt_compression");
            root["buffers"]
                .as_array_mut()
                .expect("an array")
                .push(json!({
                    "byteLength": self.fallback,
                    "extensions": { "EXT_meshopt_compression": { "fallback": true } },
                }));
        }
        for list in ["extensionsUsed", "extensionsRequired"] {
            for name in &extensions {
                match root.get_mut(list).and_then(Value::as_array_mut) {
                    Some(names) => names.push(json!(name)),
                    None => root[list] = json!([name]),
                }
            }
        }
        root["bufferViews"] = Value::Array(self.views);
        root["accessors"] = Value::Array(self.accessors);

        if binary {
            let mut text = serde_json::to_vec(&root).expect("a JSON value serialises");
            text.resize(text.len().next_multiple_of(4), b' ');
            let mut bin = self.bin;
            bin.resize(bin.len().next_multiple_of(4), 0);
            let total = 12 + 8 + text.len() + 8 + bin.len();
            let total = u32::try_from(total).map_err(|_| {
                Error::InvalidArgument(format!(
                    "{}: {total} bytes, more than a .glb holds (4 GiB)",
                    path.display()
                ))
            })?;
            let mut file = Vec::with_capacity(total as usize);
            file.extend_from_slice(b"glTF");
            file.extend_from_slice(&2u32.to_le_bytes());
            file.extend_from_slice(&total.to_le_bytes());
            for (kind, data) in [(b"JSON", &text), (b"BIN\0", &bin)] {
                file.extend_from_slice(&(data.len() as u32).to_le_bytes());
                file.extend_from_slice(kind);
                file.extend_from_slice(data);
            }
            crate::output::write_file(path, &file)
        } else {
            let text = serde_json::to_vec_pretty(&root).expect("a JSON value serialises");
            crate::output::write_file(&bin_path, &self.bin)?;
            crate::output::write_file(path, &text)
        }
    }

    /// Appends `data` as a 4-byte aligned buffer view; returns its index.
    fn view(&mut self, data: &[u8], target: Option<u32>) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let mut view =
            json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": data.len() });
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        self.bin.extend_from_slice(data);
        self.views.push(view);
        self.views.len() - 1
    }

    /// Appends `data` as a view with one accessor over it; returns the
    /// accessor's index.
    fn accessor(
        &mut self,
        data: Vec<u8>,
        target: u32,
        component: u32,
        ty: &str,
        count: usize,
    ) -> usize {
        let view = self.view(&data, Some(target));
        self.push_accessor(view, component, false, ty, count)
    }

    /// The image object for `texture`: a buffer view of its bytes, or (for
    /// a file written beside a `.gltf`) a relative URI.
    fn image(&mut self, texture: &Texture, binary: bool, path: &Path) -> Result<Value> {
        let (mime, bytes) = match texture {
            Texture::File(file) if !binary => {
                let folder = path.parent().unwrap_or(Path::new(""));
                return Ok(json!({ "uri": relative_uri(file, folder)? }));
            }
            Texture::File(file) => {
                let bytes = super::read_file(file)?;
                let ext = file
                    .extension()
                    .and_then(|e| e.to_str())
                    .map(str::to_ascii_lowercase);
                let mime = match ext.as_deref() {
                    Some("png") => "image/png",
                    Some("jpg" | "jpeg") => "image/jpeg",
                    _ => "",
                };
                (mime.to_owned(), bytes)
            }
            Texture::Embedded { mime, bytes } => (mime.clone(), bytes.clone()),
        };
        let mime = if mime.is_empty() {
            sniff_mime(&bytes)
                .ok_or_else(|| {
                    Error::InvalidArgument(format!(
                        "{}: the base-colour image is neither PNG nor JPEG and names no MIME type",
                        path.display()
                    ))
                })?
                .to_owned()
        } else {
            mime
        };
        let view = self.view(&bytes, None);
        Ok(json!({ "bufferView": view, "mimeType": mime }))
    }
}

/// `normals` with each zero one replaced by the area-weighted normal of
/// the triangles around its point (all vertices of a point get the same),
/// or `+z` where those have no area. O(V + T).
fn fill_zero_normals(mesh: &Mesh, normals: &[Vec3]) -> Vec<Vec3> {
    let p = &mesh.properties;
    let points = (0..mesh.positions.len() as u32)
        .map(|v| p.position_id(v) as usize + 1)
        .max()
        .unwrap_or(0);
    let mut sum = vec![Vec3::ZERO; points];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
        // Twice the area times the unit normal: area weighting for free.
        let n = (b - a).cross(c - a);
        for &v in t {
            sum[p.position_id(v) as usize] += n;
        }
    }
    normals
        .iter()
        .enumerate()
        .map(|(v, &n)| {
            if n != Vec3::ZERO {
                return n;
            }
            sum[p.position_id(v as u32) as usize]
                .try_normalize()
                .unwrap_or(Vec3::Z)
        })
        .collect()
}

/// `image/png` or `image/jpeg` from the image's signature.
fn sniff_mime(bytes: &[u8]) -> Option<&'static str> {
    if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        Some("image/png")
    } else if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
        Some("image/jpeg")
    } else {
        None
    }
}

/// The URI of `file` relative to `folder` ([`super::relative_segments`]),
/// each segment percent-encoded.
fn relative_uri(file: &Path, folder: &Path) -> Result<String> {
    let Some(segments) = super::relative_segments(file, folder)? else {
        return Err(Error::InvalidArgument(format!(
            "texture {} has no relative path from {}",
            file.display(),
            folder.display()
        )));
    };
    let encoded: Vec<String> = segments.iter().map(|s| encode_uri_segment(s)).collect();
    Ok(encoded.join("/"))
}

/// Percent-encodes everything but RFC 3986's unreserved characters.
fn encode_uri_segment(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for b in s.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uri_segments_round_trip_through_the_reader() {
        let name = "a b%c+ü.png";
        let uri = encode_uri_segment(name);
        assert_eq!(uri, "a%20b%25c%2B%C3%BC.png");
        assert_eq!(
            super::super::gltf::decode_uri(&uri).unwrap(),
            Path::new(name)
        );
    }

    #[test]
    fn relative_uris_climb_out_of_the_folder() {
        let uri = relative_uri(Path::new("/a/b/tex/t.png"), Path::new("/a/b/out")).unwrap();
        assert_eq!(uri, "../tex/t.png");
        let uri = relative_uri(Path::new("/a/b/t.png"), Path::new("/a/b")).unwrap();
        assert_eq!(uri, "t.png");
    }
}
