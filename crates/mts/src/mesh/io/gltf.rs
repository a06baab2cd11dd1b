//! glTF 2.0 reader: `.gltf` (JSON, buffers as data URIs or files beside it)
//! and `.glb` (binary container), behind the feature `gltf`. The writer is
//! [`super::save_gltf`].
//!
//! Follows the glTF 2.0 specification (Khronos, version 2.0.1), its
//! sections on scenes and node transformations, binary data storage
//! (buffers, buffer views, accessors), meshes (primitive topology),
//! materials, and the GLB file format.
//!
//! What is read: every primitive of every mesh reached from the default
//! scene (else scene 0; without scenes, from every root node; without
//! nodes, every mesh untransformed), each under its node's world matrix
//! (positions by the matrix, normals by its inverse transpose then
//! normalised, winding flipped where the determinant is negative).
//! Attributes `POSITION`, `NORMAL`, `TEXCOORD_0` (`v` flipped to point up
//! the image: `v = 1 - v_gltf`), `COLOR_0` (vec3 or vec4, float or
//! normalised integers; vec3 gets alpha 1) and the indices (u8, u16, u32, or
//! none: vertices in order), from dense or sparse accessors (the base
//! values from the buffer view, or zeros without one, then the
//! substitutions: "Sparse Accessors"); an accessor with neither buffer view
//! nor `sparse` reads as zeros. Triangle strips and fans become triangles of
//! the same winding; points and lines are skipped with a note on stderr.
//! Not read: skins, morph targets, animations, cameras, texture sets other
//! than 0, tangents, textures other than the base colour.
//!
//! **Primitives with different materials become one mesh.** The pipeline
//! simplifies and stripifies one surface, and a [`RawMesh`] has no
//! per-triangle material: splitting by material would give several meshes
//! whose shared borders the simplifier could no longer keep closed, and a
//! per-material option would reach every stage for a case the models at
//! hand do not have. What is kept of the materials: the base-colour texture
//! of the first primitive (in scene order) whose material has one, with a
//! note when another primitive samples a different image; and each
//! material's base-colour factor, multiplied into the vertex colours when
//! some factor is not white, so parts told apart by a flat colour stay
//! apart. Cost: a model with several textures (an atlas per part) is drawn
//! with the first one only.
//!
//! **Or kept apart, as parts.** [`parse_gltf_parts`] reads the same scene
//! as one [`GltfPart`] per triangle primitive of each mesh reached: its
//! vertices untransformed, its own properties and base-colour texture,
//! and the world matrix of every node that holds the mesh (a mesh under
//! several nodes is read once, placed several times). It is what a scene
//! renderer instances, one model per part; the pipeline's one surface is
//! still [`parse_gltf`]'s. [`gltf_part_count`] counts the parts from the
//! JSON alone, for a command to tell which of the two it needs.
//!
//! **Attributes only some primitives have** are filled for the others with
//! a neutral value: normal zero (no normal, computed where drawn), texture
//! coordinate `(0, 0)`, colour white (times the material's factor). A
//! stream no primitive has stays absent.
//!
//! **Checks.** The JSON is first read as a `serde_json::Value` (a syntax
//! error names its line), where what the typed model (gltf-json) would
//! let through is refused: an `asset.version` whose major is not 2 and an
//! `asset.minVersion` above 2.0 (a loader must refuse a major version it
//! does not know), and an integer of 2^32 or more where the schema wants
//! an index or a code, outside `extras` and `extensions` (the model reads
//! those modulo 2^32: `"mesh": 4294967296` would be mesh 0). The model
//! takes only an object as `extras`, which the specification lets be any
//! JSON value: a document the model refuses is tried again with every
//! `extras` dropped (its error then has a line only where the first try
//! failed with the same message). Every index followed (scene, node, mesh,
//! accessor, buffer view, buffer, material, texture, image) is checked
//! before use, so the `gltf` crate's own `validate`, whose primitive hook
//! indexes the accessor list before the range is checked (a panic on a bad
//! `POSITION` index), is not called. Accessor ranges (`offset + stride *
//! (count - 1) + element`, sparse indices and values tightly packed) are
//! checked against their buffer view and views against their buffer before
//! anything is allocated; an accessor without buffer view, which no bytes
//! bound, may have at most three times the caller's triangle limit of
//! elements; sparse indices must strictly increase and stay below the
//! accessor's count; index values are checked against the primitive's
//! vertex count; floats for finiteness; GLB chunks against the file
//! length; data URIs for base64. Node hierarchies must be trees (a node
//! reached twice is an error, so cycles end), walked without recursion.
//! All instances together may hold at most the caller's triangle limit
//! ([`super::LoadOptions::max_triangles`]) and three times as many
//! vertices: a 250 KB file that places a 10,000-triangle mesh under 2,000
//! nodes asks for 20 M triangles, and is refused at the primitive that
//! passes the limit, before its copy is made. Errors are [`Error::Parse`]
//! naming the glTF file and the JSON object (`accessor 3`, `node 2`,
//! `mesh 0 primitive 1`, `asset`), the message the field where the place
//! alone does not (`sparse index 2 is 7, ...`); `byte` is an offset in
//! that file when the data lies in it (the BIN chunk of a `.glb`), and for
//! data in a `.bin` file or a data URI the message gives the buffer and
//! its offset. An external buffer that cannot be read is [`Error::Io`]
//! naming that file.
//!
//! Position ids are left empty: glTF has no notion of one point split at a
//! seam (vertices are split per primitive and per attribute value alike);
//! [`crate::mesh::CleanOptions::weld`] merges bit-identical positions.

use super::gltf_meshopt::{self, Compressed};
use super::read_file;
use crate::error::{Error, Place, Result};
use crate::mesh::{RawMesh, Texture};
use glam::{DMat3, DMat4, DQuat, DVec3, Vec2, Vec3, Vec4};
use gltf::json;
use gltf::json::accessor::{ComponentType, Type};
use gltf::json::mesh::{Mode, Semantic};
use gltf::json::validation::Checked;
use serde_json::Value;
use std::borrow::Cow;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// Extensions a file may require that this reader honours: quantized
/// attributes are read through the generic component decoding; unlit
/// materials change no geometry or texture; compressed buffer views are
/// decoded ([`gltf_meshopt`]); the base-colour texture's
/// `KHR_texture_transform` is applied to `TEXCOORD_0`; a
/// `KHR_texture_basisu` (KTX2) image, which nothing here decodes, leaves
/// the mesh untextured with a note, its geometry read.
const SUPPORTED_REQUIRED: &[&str] = &[
    "KHR_mesh_quantization",
    "KHR_materials_unlit",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
    "KHR_texture_transform",
    "KHR_texture_basisu",
];

/// Parses a `.gltf` or `.glb` file (told apart by the GLB magic `glTF`)
/// into one [`RawMesh`], as described in the module docs: every instance
/// of every triangle primitive, transformed into world space, in scene
/// order (depth first, children in order). External buffers are read with
/// [`read_file`] relative to `path`'s folder; an external base-colour image
/// is only named ([`Texture::File`]), not read.
///
/// **Several textures.** A [`RawMesh`] has one texture: the mesh keeps the
/// base-colour texture of the first primitive in scene order whose
/// material has one, and every primitive's texture coordinates sample it;
/// a primitive whose material samples another image is drawn with that
/// first image (a note on stderr names both). The base-colour factors are
/// kept as vertex colours. [`parse_gltf_parts`] keeps every primitive
/// apart with its own texture, and [`gltf_part_count`] tells, without
/// reading any buffer, whether a file has more than one.
///
/// # Errors
/// [`Error::Parse`] with the JSON object (and the byte, for GLB data) at
/// fault; [`Error::Io`] for an external buffer that cannot be read.
///
/// Cost: O(file size + output) time; the output and the external buffers
/// are held in memory, nothing is allocated beyond what the checked counts
/// and the buffers bound.
pub fn parse_gltf(bytes: &[u8], path: &Path) -> Result<RawMesh> {
    parse_gltf_with(bytes, path, super::DEFAULT_MAX_TRIANGLES)
}

/// [`parse_gltf`] with the most triangles all instances may add up to
/// (three times as many vertices); see
/// [`super::LoadOptions::max_triangles`].
///
/// # Errors
/// As [`parse_gltf`]; [`Error::Parse`] naming the primitive whose instance
/// passes the limit.
pub fn parse_gltf_with(bytes: &[u8], path: &Path, max_triangles: u64) -> Result<RawMesh> {
    let (root, bin, beside) = parse_container(bytes, path)?;
    let mut reader = Reader::new(&root, path, bin, beside, max_triangles, Target::Merged);
    reader.check_extensions()?;
    reader.read_scene()?;
    reader.finish()
}

/// One part of a glTF scene ([`parse_gltf_parts`]): a triangle primitive
/// of a mesh, in the mesh's own coordinates, with its own vertex
/// properties and base-colour texture, and every world matrix the scene
/// places the mesh at.
#[derive(Debug, Clone)]
pub struct GltfPart {
    /// The mesh's index in the file's `meshes`.
    pub mesh: usize,
    /// The primitive's index in the mesh's `primitives`.
    pub primitive: usize,
    /// The mesh's `name`, when it has one.
    pub name: Option<String>,
    /// The primitive's `material` index; `None` for the default material
    /// (white, untextured).
    pub material: Option<usize>,
    /// The material's base-colour factor, linear RGBA clamped to 0..=1
    /// (white without a material).
    pub base_color: Vec4,
    /// The primitive's vertices and triangles, untransformed, as
    /// [`parse_gltf`] reads them: `NORMAL`, `TEXCOORD_0` (`v` flipped) and
    /// `COLOR_0` where the primitive has them; the colours times
    /// [`GltfPart::base_color`], or that factor on every vertex where the
    /// primitive has no `COLOR_0` and the factor is not white; the
    /// material's base-colour texture (kept even without texture
    /// coordinates, which a renderer cannot sample it with). Every index is
    /// in range and every value finite; [`crate::mesh::clean`] makes a
    /// [`crate::Mesh`] of it.
    pub raw: RawMesh,
    /// Model-to-world matrices, one per node that holds the mesh, in scene
    /// order (depth first, children in order), composed in `f64` from the
    /// root; at least one. A matrix may mirror (negative determinant): a
    /// renderer that culls back faces draws such an instance with its
    /// triangles' winding reversed, as [`parse_gltf`] stores it.
    pub transforms: Vec<DMat4>,
}

/// Parses a `.gltf` or `.glb` file into its parts: one [`GltfPart`] per
/// triangle primitive of every mesh the scene reaches (the same meshes,
/// nodes and attributes as [`parse_gltf`], in the order of their first
/// instance, primitives in order), each with its own properties and
/// texture and the transforms of every node that holds its mesh. A mesh
/// held by several nodes is read once. Points and lines are skipped with a
/// note, as in [`parse_gltf`].
///
/// `max_triangles` bounds the instances as in [`parse_gltf_with`] (each
/// instance counted, three times as many vertices), so a file this
/// accepts merges within the same limit, and the file's counts are
/// checked before anything is allocated. Every material's base-colour
/// image is read (each once, shared between parts by clone).
///
/// # Errors
/// As [`parse_gltf_with`], and [`Error::Parse`] naming an image that is
/// not valid (a data URI that is not base64) of any part.
///
/// Cost: O(file size + parts' data); a mesh's data is read once however
/// many nodes hold it, each further instance costs one matrix.
pub fn parse_gltf_parts(bytes: &[u8], path: &Path, max_triangles: u64) -> Result<Vec<GltfPart>> {
    let (root, bin, beside) = parse_container(bytes, path)?;
    let target = Target::Parts {
        parts: Vec::new(),
        of_mesh: HashMap::new(),
        images: HashMap::new(),
    };
    let mut reader = Reader::new(&root, path, bin, beside, max_triangles, target);
    reader.check_extensions()?;
    reader.read_scene()?;
    match reader.target {
        Target::Parts { parts, .. } => Ok(parts),
        _ => unreachable!("the reader was made for parts"),
    }
}

/// How many parts [`parse_gltf_parts`] would return for the file: the
/// distinct (mesh, triangle primitive) pairs the scene reaches. Only the
/// JSON is read (and a `.glb`'s chunks checked): no buffer, accessor or
/// image, so a file whose data is broken may count and still fail to
/// parse.
///
/// # Errors
/// [`Error::Parse`] for what the walk over the scene checks: the JSON, the
/// asset's version, required extensions, scene, node and mesh indices, the
/// node trees, node transforms and primitive modes.
///
/// Cost: O(JSON size + nodes); nothing is allocated per vertex.
pub fn gltf_part_count(bytes: &[u8], path: &Path) -> Result<usize> {
    let (root, bin, beside) = parse_container(bytes, path)?;
    let target = Target::Count {
        meshes: HashSet::new(),
        parts: 0,
    };
    let mut reader = Reader::new(&root, path, bin, beside, u64::MAX, target);
    reader.check_extensions()?;
    reader.read_scene()?;
    match reader.target {
        Target::Count { parts, .. } => Ok(parts),
        _ => unreachable!("the reader was made to count"),
    }
}

/// The typed document of a `.gltf` or `.glb` file, its BIN chunk, and
/// what the reader takes from the JSON beside the typed model.
fn parse_container<'a>(bytes: &'a [u8], path: &Path) -> Result<(json::Root, Bin<'a>, Beside)> {
    let is_glb = bytes.starts_with(b"glTF");
    let (text, bin) = if is_glb {
        split_glb(bytes, path)?
    } else {
        (bytes, None)
    };
    let (root, beside) = parse_document(text, path, is_glb)?;
    Ok((root, bin, beside))
}

/// What the reader takes from the document's JSON that the typed model
/// (gltf-json without its `extensions` feature) does not hold: the
/// compressed buffer views ([`gltf_meshopt`]) and each material's
/// base-colour `KHR_texture_transform`.
#[derive(Default)]
struct Beside {
    /// One entry per buffer view; `None` for a plain view.
    compressed: Vec<Option<Compressed>>,
    /// The transform of the base-colour texture's coordinates, by
    /// material: `(u, v) -> (a u + b v + c, d u + e v + f)` as
    /// `[a, b, c, d, e, f]`.
    uv_transforms: HashMap<usize, [f32; 6]>,
}

impl Beside {
    /// Reads them from the document `value`.
    ///
    /// # Errors
    /// The place (a buffer view or a material) and what is wrong there.
    fn of(value: &Value) -> std::result::Result<Beside, (Place, String)> {
        let compressed = gltf_meshopt::compressed_views(value)
            .map_err(|(v, m)| (Place::element("bufferView", v as u64), m))?;
        let mut uv_transforms = HashMap::new();
        let materials = value.get("materials").and_then(Value::as_array);
        for (i, material) in materials.into_iter().flatten().enumerate() {
            let Some(t) = material
                .pointer("/pbrMetallicRoughness/baseColorTexture/extensions/KHR_texture_transform")
            else {
                continue;
            };
            let m = uv_transform(t).map_err(|m| (Place::element("material", i as u64), m))?;
            uv_transforms.insert(i, m);
        }
        Ok(Beside {
            compressed,
            uv_transforms,
        })
    }
}

/// The affine map of a `KHR_texture_transform` object: `offset`,
/// `rotation` (radians) and `scale`, applied as translation × rotation ×
/// scale: `u' = cos·sx·u + sin·sy·v + ox`, `v' = −sin·sx·u + cos·sy·v +
/// oy`. **Decision:** the extension's GLSL writes the rotation matrix's
/// columns in an order that reads the other way round in some copies; its
/// own worked example (offset `[0, 1]`, rotation π/2, scale `[0.5, 0.5]`
/// samples the lower-left quadrant, inside `[0, 1]`) holds only for the
/// signs used here, so the example decides (tested).
fn uv_transform(t: &Value) -> std::result::Result<[f32; 6], String> {
    let numbers = |key: &str, default: &[f64]| -> std::result::Result<Vec<f64>, String> {
        match t.get(key) {
            None => Ok(default.to_vec()),
            Some(Value::Number(n)) if default.len() == 1 => Ok(vec![n.as_f64().unwrap_or(0.0)]),
            Some(Value::Array(a)) if a.len() == default.len() && a.iter().all(Value::is_number) => {
                Ok(a.iter().map(|x| x.as_f64().unwrap_or(0.0)).collect())
            }
            Some(other) => Err(format!(
                "KHR_texture_transform: `{key}` is {other}, not {} number{}",
                default.len(),
                if default.len() == 1 { "" } else { "s" }
            )),
        }
    };
    let offset = numbers("offset", &[0.0, 0.0])?;
    let rotation = numbers("rotation", &[0.0])?[0];
    let scale = numbers("scale", &[1.0, 1.0])?;
    let (sin, cos) = rotation.sin_cos();
    let m = [
        cos * scale[0],
        sin * scale[1],
        offset[0],
        -sin * scale[0],
        cos * scale[1],
        offset[1],
    ];
    if m.iter().any(|x| !x.is_finite()) {
        return Err("KHR_texture_transform: a value is not finite".into());
    }
    Ok(m.map(|x| x as f32))
}

/// The typed document of the JSON `text`, after the checks the typed model
/// does not make: `asset`'s versions ([`check_asset`]), and integers of
/// 2^32 and more where the schema wants an index or a code
/// ([`check_integers`]), which the model would read modulo 2^32. An
/// `extras` member may hold any JSON value, but the model only takes an
/// object: when the text does not deserialize, it is tried again without
/// any `extras` ([`drop_extras`]).
///
/// # Errors
/// [`Error::Parse`]: not JSON, or not a glTF document, with the line where
/// serde_json gives one (the JSON chunk's line for a `.glb`); the object
/// and field at fault for the checks.
///
/// Cost: O(text) time: the text is parsed twice (as a `serde_json::Value`,
/// then typed), three times when the typed parse fails; one of these
/// copies is held at a time.
fn parse_document(text: &[u8], path: &Path, is_glb: bool) -> Result<(json::Root, Beside)> {
    let fail = |place: Place, message: String| Error::Parse {
        file: path.to_owned(),
        place,
        message,
    };
    let not_gltf = |e: &serde_json::Error| {
        fail(
            match e.line() {
                0 => Place::default(),
                line => Place::line(line as u64),
            },
            format!(
                "{}not a glTF document: {e}",
                if is_glb { "JSON chunk: " } else { "" }
            ),
        )
    };
    let value: Value = serde_json::from_slice(text).map_err(|e| not_gltf(&e))?;
    check_asset(&value).map_err(|m| fail(place_of(&[Step::Key("asset")]), m))?;
    let mut steps = Vec::new();
    check_integers(&value, None, &mut steps).map_err(|m| fail(place_of(&steps), m))?;
    let beside = Beside::of(&value).map_err(|(place, m)| fail(place, m))?;
    // Not held while the typed model is: a document is read twice, but
    // held once at a time.
    drop(value);
    let typed = match json::deserialize::from_slice(text) {
        Ok(root) => return Ok((root, beside)),
        Err(typed) => typed,
    };
    let mut value: Value = serde_json::from_slice(text).map_err(|e| not_gltf(&e))?;
    if !lenient(&mut value) {
        return Err(not_gltf(&typed));
    }
    let root = json::deserialize::from_value(value).map_err(|e| {
        // The same complaint as the text's: the text's line is its place.
        let bare = e.to_string();
        let located = typed.to_string();
        if located.strip_suffix(&format!(
            " at line {} column {}",
            typed.line(),
            typed.column()
        )) == Some(bare.as_str())
        {
            not_gltf(&typed)
        } else {
            fail(
                Place::default(),
                format!(
                    "{}not a glTF document (read leniently): {bare}",
                    if is_glb { "JSON chunk: " } else { "" }
                ),
            )
        }
    })?;
    Ok((root, beside))
}

/// Makes of a document the typed model refused one it may take, where
/// the specification allows what the model does not; returns whether
/// anything changed. What the model is stricter about than glTF 2.0:
///
/// - `extras` may be any JSON value; the model takes only an object. Every
///   `extras` is dropped (the reader uses none).
/// - An integer may be written with a zero fraction (`1.0`): JSON has one
///   number type, and the validator reads `1.0` as the integer 1. Every
///   number with no fraction becomes an integer (a float field still
///   reads it as a float).
/// - `animations`, `skins` and `cameras` are not read, and the model
///   requires fields the specification leaves optional there (an
///   animation channel's `target.node`, absent when `KHR_animation_pointer`
///   names the target): they are dropped whole.
/// - A scene's `nodes` is optional (a scene may be empty); the model
///   requires it: an empty list is written in.
fn lenient(value: &mut Value) -> bool {
    let mut changed = drop_extras(value);
    changed |= integral_numbers(value);
    if let Value::Object(top) = value {
        for unread in ["animations", "skins", "cameras"] {
            changed |= top.remove(unread).is_some();
        }
        if let Some(Value::Array(scenes)) = top.get_mut("scenes") {
            for scene in scenes.iter_mut().filter_map(Value::as_object_mut) {
                if !scene.contains_key("nodes") {
                    scene.insert("nodes".into(), Value::Array(Vec::new()));
                    changed = true;
                }
            }
        }
    }
    changed
}

/// Rewrites every finite number with no fraction, within ±2^53, written as
/// a float (`4.0`) as an integer; returns whether any was. Walks without
/// recursion (a document may nest deeply).
fn integral_numbers(value: &mut Value) -> bool {
    let mut changed = false;
    let mut stack = vec![value];
    while let Some(v) = stack.pop() {
        match v {
            Value::Number(n) if n.is_f64() => {
                let f = n.as_f64().unwrap_or(f64::NAN);
                if f.fract() == 0.0 && f.abs() < (1u64 << 53) as f64 {
                    *v = if f < 0.0 {
                        Value::from(f as i64)
                    } else {
                        Value::from(f as u64)
                    };
                    changed = true;
                }
            }
            Value::Array(a) => stack.extend(a.iter_mut()),
            Value::Object(o) => stack.extend(o.values_mut()),
            _ => {}
        }
    }
    changed
}

/// Refuses an `asset.version` whose major version is not 2, and an
/// `asset.minVersion` above 2.0 (glTF 2.0, "Asset": a loader must refuse a
/// major version it does not know, and a minimum version it does not
/// support). A missing or mistyped field is left to the typed model.
fn check_asset(document: &Value) -> std::result::Result<(), String> {
    let Some(asset) = document.get("asset") else {
        return Ok(());
    };
    if let Some(Value::String(version)) = asset.get("version") {
        match major_minor(version) {
            Some((2, _)) => {}
            Some((major, _)) => {
                return Err(format!(
                    "version \"{version}\": glTF {major}.x is not read, only 2.x"
                ))
            }
            None => return Err(format!("version \"{version}\" is not MAJOR.MINOR")),
        }
    }
    if let Some(Value::String(version)) = asset.get("minVersion") {
        match major_minor(version) {
            Some(v) if v <= (2, 0) => {}
            Some(_) => {
                return Err(format!(
                    "minVersion \"{version}\": the asset needs a reader of glTF {version}, this \
                     one reads 2.0"
                ))
            }
            None => return Err(format!("minVersion \"{version}\" is not MAJOR.MINOR")),
        }
    }
    Ok(())
}

/// `"2.1"` as `(2, 1)`: the specification's pattern `[0-9]+\.[0-9]+`.
fn major_minor(version: &str) -> Option<(u64, u64)> {
    let (major, minor) = version.split_once('.')?;
    let number = |s: &str| {
        if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        s.parse().ok()
    };
    Some((number(major)?, number(minor)?))
}

/// A step of a JSON path: an object member or an array item.
#[derive(Clone, Copy)]
enum Step<'a> {
    Key(&'a str),
    Item(usize),
}

/// Fields whose integers are indices of glTF objects (glTF 2.0 JSON
/// schema): those of every core object, found by their names. `attributes`
/// and `targets` hold maps of indices by semantic.
const INDEX_FIELDS: &[&str] = &[
    "attributes",
    "buffer",
    "bufferView",
    "camera",
    "children",
    "index",
    "indices",
    "input",
    "inverseBindMatrices",
    "joints",
    "material",
    "mesh",
    "node",
    "nodes",
    "output",
    "sampler",
    "scene",
    "skeleton",
    "skin",
    "source",
    "targets",
];

/// Fields whose integers are codes or small numbers the typed model holds
/// in 32 bits (component types, modes, targets, filters, wrapping modes,
/// texture coordinate sets). The other integer fields, `byteOffset`,
/// `byteLength`, `byteStride` and `count`, are read in 64 bits and checked
/// against the data.
const CODE_FIELDS: &[&str] = &[
    "componentType",
    "magFilter",
    "minFilter",
    "mode",
    "target",
    "texCoord",
    "wrapS",
    "wrapT",
];

/// Refuses an integer of 2^32 or more in an index or code field (named
/// `field`, the member that holds it, or the map of semantics it is in),
/// outside `extras` and `extensions`; `steps` is `value`'s path, and on
/// error the path of the integer.
///
/// Cost: O(value) time; recursion as deep as the JSON's nesting, which
/// serde_json bounds (128).
fn check_integers<'v>(
    value: &'v Value,
    field: Option<&'v str>,
    steps: &mut Vec<Step<'v>>,
) -> std::result::Result<(), String> {
    match value {
        Value::Number(n) => {
            let (Some(field), Some(x)) = (field, n.as_u64()) else {
                return Ok(());
            };
            if x <= u64::from(u32::MAX) {
                return Ok(());
            }
            let what = if INDEX_FIELDS.contains(&field) {
                "an index"
            } else if CODE_FIELDS.contains(&field) {
                "a valid value (at most 2^32 - 1)"
            } else {
                return Ok(());
            };
            let inner = steps.iter().skip(usize::from(is_top_object(steps)) * 2);
            let mut name = String::new();
            for step in inner {
                match step {
                    Step::Key(k) if name.is_empty() => name.push_str(k),
                    Step::Key(k) => {
                        name.push('.');
                        name.push_str(k);
                    }
                    Step::Item(i) => name.push_str(&format!("[{i}]")),
                }
            }
            if name.is_empty() {
                name.push_str("value");
            }
            Err(format!("{name} {x} is not {what}"))
        }
        Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                steps.push(Step::Item(i));
                check_integers(item, field, steps)?;
                steps.pop();
            }
            Ok(())
        }
        Value::Object(members) => {
            let semantics = matches!(field, Some("attributes" | "targets"));
            for (key, member) in members {
                if key == "extras" || key == "extensions" {
                    continue;
                }
                steps.push(Step::Key(key));
                check_integers(member, if semantics { field } else { Some(key) }, steps)?;
                steps.pop();
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

/// Whether `steps` starts at an object of one of the root's arrays
/// (`nodes[3]`).
fn is_top_object(steps: &[Step]) -> bool {
    matches!(steps, [Step::Key(_), Step::Item(_), ..])
}

/// The place of the JSON path `steps`: the object of a root array it lies
/// in (`node 3`, from `nodes[3]`), else the root member (`asset`).
fn place_of(steps: &[Step]) -> Place {
    match steps {
        [Step::Key(array), Step::Item(i), ..] => {
            let element = match *array {
                "accessors" => "accessor",
                "animations" => "animation",
                "buffers" => "buffer",
                "bufferViews" => "bufferView",
                "cameras" => "camera",
                "images" => "image",
                "materials" => "material",
                "meshes" => "mesh",
                "nodes" => "node",
                "samplers" => "sampler",
                "scenes" => "scene",
                "skins" => "skin",
                "textures" => "texture",
                other => other,
            };
            Place::element(element, *i as u64)
        }
        [Step::Key("asset"), ..] => Place {
            element: Some("asset".into()),
            ..Place::default()
        },
        _ => Place {
            element: Some("root".into()),
            ..Place::default()
        },
    }
}

/// Removes every `extras` member; whether there was one.
///
/// Cost: O(value) time; recursion bounded as in [`check_integers`].
fn drop_extras(value: &mut Value) -> bool {
    match value {
        Value::Array(items) => items.iter_mut().fold(false, |d, v| drop_extras(v) | d),
        Value::Object(members) => {
            let dropped = members.remove("extras").is_some();
            members
                .values_mut()
                .fold(dropped, |d, v| drop_extras(v) | d)
        }
        _ => false,
    }
}

/// The GLB BIN chunk: its bytes and their offset in the file.
type Bin<'a> = Option<(&'a [u8], u64)>;

/// Splits a GLB file into its JSON chunk and optional BIN chunk, checking
/// the header and every chunk against the file's length.
fn split_glb<'a>(bytes: &'a [u8], path: &Path) -> Result<(&'a [u8], Bin<'a>)> {
    use std::io::Write as _;
    let fail = |byte: usize, element: &str, index: Option<u64>, message: String| Error::Parse {
        file: path.to_owned(),
        place: Place {
            byte: Some(byte as u64),
            element: Some(element.to_owned()),
            index,
            ..Place::default()
        },
        message,
    };
    let word = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
    };
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(fail(
            0,
            "GLB header",
            None,
            format!(
                "{} bytes, a GLB header has 12: the file is truncated",
                bytes.len()
            ),
        ));
    };
    if version != 2 {
        return Err(fail(
            4,
            "GLB header",
            None,
            format!("GLB version {version}; only version 2 is read"),
        ));
    }
    let end = (length as usize).min(bytes.len());
    let (mut at, mut chunk) = (12usize, 0u64);
    let (mut json, mut bin) = (None, None);
    while at < end {
        let (Some(len), Some(kind)) = (word(at), word(at + 4)) else {
            return Err(fail(
                at,
                "GLB chunk",
                Some(chunk),
                format!(
                    "the chunk header runs past the end of the file at byte {}: the file is truncated",
                    bytes.len()
                ),
            ));
        };
        let data = at + 8;
        let Some(data_end) = data.checked_add(len as usize).filter(|&e| e <= bytes.len()) else {
            return Err(fail(
                at,
                "GLB chunk",
                Some(chunk),
                format!(
                    "a chunk of {len} bytes from byte {data} runs past the end of the file at byte {}: the file is truncated",
                    bytes.len()
                ),
            ));
        };
        match (&kind.to_le_bytes(), chunk) {
            (b"JSON", 0) => json = Some(&bytes[data..data_end]),
            (b"BIN\0", 1) => bin = Some((&bytes[data..data_end], data as u64)),
            (_, 0) => {
                return Err(fail(
                    at,
                    "GLB chunk",
                    Some(0),
                    "the first chunk is not JSON".into(),
                ))
            }
            _ => {} // Chunks of unknown type are skipped (GLB file format: chunks).
        }
        at = data_end.next_multiple_of(4);
        chunk += 1;
    }
    if (length as usize) < bytes.len() && length >= 12 {
        // Bytes after the declared length: the validator's GLB_EXTRA_DATA
        // is a warning, and the chunks within the length are whole (each
        // was checked to end inside it or before the file's end).
        let _ = writeln!(
            std::io::stderr(),
            "note: {}: {} bytes after the GLB's declared length of {length}: ignored",
            path.display(),
            bytes.len() - length as usize
        );
    } else if length as usize != bytes.len() {
        return Err(fail(
            8,
            "GLB header",
            None,
            format!(
                "the header says the file has {length} bytes, it has {}{}",
                bytes.len(),
                if (length as usize) > bytes.len() {
                    ": the file is truncated"
                } else {
                    ""
                }
            ),
        ));
    }
    let Some(json) = json else {
        return Err(fail(12, "GLB chunk", Some(0), "no JSON chunk".into()));
    };
    Ok((json, bin))
}

/// A buffer's bytes and where they came from.
struct Buffer<'a> {
    bytes: Cow<'a, [u8]>,
    /// The file offset of byte 0 when the bytes lie in the parsed file
    /// (GLB BIN chunk); `None` for a `.bin` file or a data URI.
    base: Option<u64>,
    /// Where the bytes came from, for messages.
    origin: String,
}

/// Where elements lie in a buffer: element `k` at byte
/// `start + k * stride` of buffer `buffer` (read), all checked to lie
/// inside their buffer view.
#[derive(Clone, Copy)]
struct Run {
    buffer: usize,
    start: usize,
    stride: usize,
}

/// An accessor's elements, checked against their buffers: base values,
/// then a sparse accessor's substitutions.
struct Elements {
    ty: ComponentType,
    normalized: bool,
    dims: usize,
    count: usize,
    /// The base values; `None` for an accessor without bufferView, whose
    /// base values are zeros (its count checked against the caller's
    /// limit, as no bytes bound it).
    dense: Option<Run>,
    sparse: Option<Sparse>,
}

/// A sparse accessor's substitutions (glTF 2.0, "Sparse Accessors"):
/// `count` element indices of type `index_ty`, which must strictly
/// increase and stay below the accessor's count, and as many elements of
/// the accessor's type at `values`; both tightly packed.
struct Sparse {
    count: usize,
    index_ty: ComponentType,
    indices: Run,
    values: Run,
}

/// The base-colour texture chosen, and the image it came from.
struct BaseColor {
    image: usize,
    texture: Texture,
}

/// A primitive's data before it is placed ([`Reader::geometry`]).
struct Geometry {
    /// The `POSITION` accessor and its checked layout (read last).
    pa: usize,
    positions: Elements,
    /// `NORMAL`, `TEXCOORD_0` and `COLOR_0` as floats, with their
    /// components per element, where the primitive has them.
    streams: [Option<(Vec<f32>, usize)>; 3],
    triangles: Vec<[u32; 3]>,
    /// Degenerate strip or fan triangles dropped.
    degenerate: usize,
}

/// A primitive's material, checked ([`Reader::material`]).
struct Material {
    index: Option<usize>,
    factor: Vec4,
    /// The base-colour image, and the texture that names it.
    image: Option<(usize, usize)>,
}

/// State of one parse.
struct Reader<'a> {
    root: &'a json::Root,
    path: &'a Path,
    folder: PathBuf,
    bin: Bin<'a>,
    /// Buffers read so far (an unused buffer is never read).
    buffers: Vec<Option<Buffer<'a>>>,
    raw: RawMesh,
    base_color: Option<BaseColor>,
    /// Whether some material's base-colour factor is not white.
    factors_used: bool,
    instanced_triangles: u64,
    /// Vertices of every instance so far (the merged mesh's vertex count).
    instanced_vertices: u64,
    /// The caller's limit on `instanced_triangles` (and on three times as
    /// many vertices).
    max_triangles: u64,
    /// Notes printed so far (each once, though a mesh is instanced often).
    notes: HashSet<String>,
    /// What the walk over the scene makes.
    target: Target,
    /// The extension objects read beside the typed model.
    beside: Beside,
    /// Compressed buffer views decoded so far: the view's index, and the
    /// slot of `buffers` (past the file's buffers) holding its bytes.
    decoded: HashMap<usize, usize>,
}

/// What a [`Reader`] makes of the meshes the scene reaches.
enum Target {
    /// One mesh of every instance, transformed ([`parse_gltf`]).
    Merged,
    /// A part per triangle primitive of every mesh reached, untransformed,
    /// with its instances' transforms ([`parse_gltf_parts`]).
    Parts {
        parts: Vec<GltfPart>,
        /// The parts of each mesh read so far, by mesh index.
        of_mesh: HashMap<usize, Vec<usize>>,
        /// Base-colour images read so far, by image index.
        images: HashMap<usize, Option<Texture>>,
    },
    /// Only the parts counted, no data read ([`gltf_part_count`]).
    Count {
        meshes: HashSet<usize>,
        parts: usize,
    },
}

impl<'a> Reader<'a> {
    fn new(
        root: &'a json::Root,
        path: &'a Path,
        bin: Bin<'a>,
        beside: Beside,
        max_triangles: u64,
        target: Target,
    ) -> Reader<'a> {
        Reader {
            root,
            path,
            folder: path.parent().map(Path::to_owned).unwrap_or_default(),
            bin,
            buffers: (0..root.buffers.len()).map(|_| None).collect(),
            raw: RawMesh::default(),
            base_color: None,
            factors_used: false,
            instanced_triangles: 0,
            instanced_vertices: 0,
            max_triangles,
            notes: HashSet::new(),
            target,
            beside,
            decoded: HashMap::new(),
        }
    }

    fn fail(&self, place: Place, message: String) -> Error {
        Error::Parse {
            file: self.path.to_owned(),
            place,
            message,
        }
    }

    fn note(&mut self, message: String) {
        if self.notes.insert(message.clone()) {
            // A closed or full standard error is no reason to fail a load.
            use std::io::Write as _;
            let _ = writeln!(
                std::io::stderr(),
                "note: {}: {message}",
                self.path.display()
            );
        }
    }

    fn check_extensions(&self) -> Result<()> {
        for (i, name) in self.root.extensions_required.iter().enumerate() {
            if !SUPPORTED_REQUIRED.contains(&name.as_str()) {
                return Err(self.fail(
                    Place::element("extensionsRequired", i as u64),
                    format!(
                        "the file requires the extension {name}, which this reader does not \
                         support (it supports {})",
                        SUPPORTED_REQUIRED.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Walks the scene's node trees depth first, children in order, and
    /// reads every mesh instance.
    fn read_scene(&mut self) -> Result<()> {
        let root = self.root;
        let node_count = root.nodes.len();
        let scene = match root.scene {
            Some(s) => Some((s.value(), Place::element("scene", s.value() as u64))),
            None if !root.scenes.is_empty() => Some((0, Place::element("scenes", 0))),
            None => None,
        };
        let roots: Vec<usize> = match scene {
            Some((s, place)) => {
                let Some(scene) = root.scenes.get(s) else {
                    return Err(self.fail(
                        place,
                        format!("no such scene ({} scenes)", root.scenes.len()),
                    ));
                };
                let mut roots = Vec::with_capacity(scene.nodes.len());
                for n in &scene.nodes {
                    if n.value() >= node_count {
                        return Err(self.fail(
                            Place::element("scene", s as u64),
                            format!("node {} does not exist ({node_count} nodes)", n.value()),
                        ));
                    }
                    roots.push(n.value());
                }
                roots
            }
            None if root.nodes.is_empty() => {
                for m in 0..root.meshes.len() {
                    self.read_mesh(m, DMat4::IDENTITY, Place::element("mesh", m as u64))?;
                }
                return Ok(());
            }
            None => {
                let mut child = vec![false; node_count];
                for (n, node) in root.nodes.iter().enumerate() {
                    for c in node.children.iter().flatten() {
                        self.check_child(c.value(), n)?;
                        child[c.value()] = true;
                    }
                }
                (0..node_count).filter(|&n| !child[n]).collect()
            }
        };
        let mut visited = vec![false; node_count];
        let mut stack: Vec<(usize, DMat4)> =
            roots.iter().rev().map(|&n| (n, DMat4::IDENTITY)).collect();
        while let Some((n, parent)) = stack.pop() {
            let place = Place::element("node", n as u64);
            if std::mem::replace(&mut visited[n], true) {
                return Err(self.fail(
                    place,
                    "the node is reached twice (glTF nodes form disjoint trees: a node has \
                     at most one parent and is in one scene root list once)"
                        .into(),
                ));
            }
            let node = &root.nodes[n];
            let world = parent * self.local_matrix(node, place.clone())?;
            if !world.is_finite() {
                return Err(self.fail(place, "the world transform is not finite".into()));
            }
            if let Some(m) = node.mesh {
                self.read_mesh(m.value(), world, place)?;
            }
            for c in node.children.iter().flatten().rev() {
                self.check_child(c.value(), n)?;
                stack.push((c.value(), world));
            }
        }
        Ok(())
    }

    /// An error naming `parent` when its child `child` does not exist.
    fn check_child(&self, child: usize, parent: usize) -> Result<()> {
        let count = self.root.nodes.len();
        if child < count {
            return Ok(());
        }
        Err(self.fail(
            Place::element("node", parent as u64),
            format!("child node {child} does not exist ({count} nodes)"),
        ))
    }

    /// The node's local matrix: `matrix`, or translation * rotation * scale.
    fn local_matrix(&self, node: &json::Node, place: Place) -> Result<DMat4> {
        if let Some(m) = node.matrix {
            return Ok(DMat4::from_cols_array(&m.map(f64::from)));
        }
        let t = node.translation.unwrap_or([0.0; 3]).map(f64::from);
        let s = node.scale.unwrap_or([1.0; 3]).map(f64::from);
        let q = node.rotation.unwrap_or_default().0.map(f64::from);
        let q = DQuat::from_array(q);
        let len = q.length();
        if !(len.is_finite() && len > 0.0) {
            return Err(self.fail(
                place,
                format!("rotation {q} is not a rotation (zero or not finite)"),
            ));
        }
        Ok(DMat4::from_scale_rotation_translation(
            DVec3::from_array(s),
            q / len,
            DVec3::from_array(t),
        ))
    }

    /// Reads every primitive of mesh `m` under `world` into the target;
    /// `place` is the node (or mesh) that asked for it.
    fn read_mesh(&mut self, m: usize, world: DMat4, place: Place) -> Result<()> {
        let root = self.root;
        let Some(mesh) = root.meshes.get(m) else {
            return Err(self.fail(
                place,
                format!("mesh {m} does not exist ({} meshes)", root.meshes.len()),
            ));
        };
        match &mut self.target {
            Target::Merged => {
                for (p, primitive) in mesh.primitives.iter().enumerate() {
                    self.read_primitive(m, p, primitive, world)?;
                }
            }
            Target::Parts { of_mesh, .. } => match of_mesh.get(&m) {
                Some(parts) => {
                    let parts = parts.clone();
                    self.instance_parts(&parts, world)?;
                }
                None => {
                    let mut parts = Vec::with_capacity(mesh.primitives.len());
                    for (p, primitive) in mesh.primitives.iter().enumerate() {
                        if let Some(part) = self.read_part(m, p, primitive, world)? {
                            parts.push(part);
                        }
                    }
                    if let Target::Parts { of_mesh, .. } = &mut self.target {
                        of_mesh.insert(m, parts);
                    }
                }
            },
            Target::Count { meshes, .. } => {
                if meshes.insert(m) {
                    for (p, primitive) in mesh.primitives.iter().enumerate() {
                        let place = Place::element(&format!("mesh {m} primitive"), p as u64);
                        let Checked::Valid(mode) = primitive.mode else {
                            return Err(self.fail(place, "unknown primitive mode".into()));
                        };
                        let drawn = is_triangles(mode) && self.undrawable(primitive).is_none();
                        if let Target::Count { parts, .. } = &mut self.target {
                            *parts += usize::from(drawn);
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// A primitive's attributes and triangles, read and checked, the
    /// instance counted against the limits; `None` (with a note) for points
    /// and lines. The positions are left unread: [`Reader::read_primitive`]
    /// reads the material first.
    fn geometry(
        &mut self,
        m: usize,
        p: usize,
        primitive: &json::mesh::Primitive,
        place: &Place,
    ) -> Result<Option<Geometry>> {
        let Checked::Valid(mode) = primitive.mode else {
            return Err(self.fail(place.clone(), "unknown primitive mode".into()));
        };
        if !is_triangles(mode) {
            let root = self.root;
            let name = root.meshes[m].name.as_deref().unwrap_or("");
            self.note(format!(
                "mesh {m} {name:?} primitive {p} draws {mode:?}, not triangles: skipped"
            ));
            return Ok(None);
        }
        let attribute = |semantic: Semantic| {
            primitive
                .attributes
                .get(&Checked::Valid(semantic))
                .map(|a| a.value())
        };
        if let Some(why) = self.undrawable(primitive) {
            self.note(format!("{place} {why}: skipped"));
            return Ok(None);
        }
        let Some(pa) = attribute(Semantic::Positions) else {
            unreachable!("undrawable() refuses a primitive without POSITION");
        };
        let positions = self.elements(pa, &[3], "POSITION", place)?;
        let count = positions.count;
        self.count_vertices(count, place)?;
        let mut streams = [None, None, None];
        for (slot, (semantic, dims, name)) in [
            (Semantic::Normals, &[3][..], "NORMAL"),
            (Semantic::TexCoords(0), &[2][..], "TEXCOORD_0"),
            (Semantic::Colors(0), &[3, 4][..], "COLOR_0"),
        ]
        .into_iter()
        .enumerate()
        {
            if let Some(a) = attribute(semantic) {
                let e = self.elements(a, dims, name, place)?;
                if e.count != count {
                    return Err(self.fail(
                        place.clone(),
                        format!(
                            "{name} (accessor {a}) has {} elements, POSITION (accessor {pa}) {count}",
                            e.count
                        ),
                    ));
                }
                streams[slot] = Some((self.floats(a, &e)?, e.dims));
            }
        }
        let transform = primitive
            .material
            .and_then(|m| self.beside.uv_transforms.get(&m.value()));
        if let (Some(m), Some((uvs, _))) = (transform, streams[1].as_mut()) {
            for uv in uvs.chunks_exact_mut(2) {
                let (u, v) = (uv[0], uv[1]);
                uv[0] = m[0] * u + m[1] * v + m[2];
                uv[1] = m[3] * u + m[4] * v + m[5];
            }
        }
        let indices = match primitive.indices {
            Some(a) => self.indices(a.value(), count, place)?,
            None => (0..count as u32).collect(),
        };
        let (triangles, degenerate) = self.triangles(mode, &indices, place)?;
        self.count_triangles(triangles.len(), place)?;
        Ok(Some(Geometry {
            pa,
            positions,
            streams,
            triangles,
            degenerate,
        }))
    }

    /// Counts `count` more instanced vertices, refused past three times
    /// the triangle limit.
    fn count_vertices(&mut self, count: usize, place: &Place) -> Result<()> {
        let max_vertices = self.max_triangles.saturating_mul(3);
        if self.instanced_vertices + count as u64 > max_vertices {
            return Err(self.fail(
                place.clone(),
                format!(
                    "the scene's instances ask for more than {max_vertices} vertices, three \
                     times the limit of {} triangles{}",
                    self.max_triangles,
                    super::RAISE_LIMIT
                ),
            ));
        }
        self.instanced_vertices += count as u64;
        Ok(())
    }

    /// Counts `count` more instanced triangles, refused past the limit.
    fn count_triangles(&mut self, count: usize, place: &Place) -> Result<()> {
        self.instanced_triangles += count as u64;
        if self.instanced_triangles > self.max_triangles {
            return Err(self.fail(
                place.clone(),
                format!(
                    "the scene's instances ask for more than {} triangles, the limit{}",
                    self.max_triangles,
                    super::RAISE_LIMIT
                ),
            ));
        }
        Ok(())
    }

    fn read_primitive(
        &mut self,
        m: usize,
        p: usize,
        primitive: &json::mesh::Primitive,
        world: DMat4,
    ) -> Result<()> {
        let place = Place::element(&format!("mesh {m} primitive"), p as u64);
        let before = self.raw.positions.len();
        let Some(geometry) = self.geometry(m, p, primitive, &place)? else {
            return Ok(());
        };
        let Geometry {
            pa,
            positions,
            streams,
            triangles,
            degenerate,
        } = geometry;
        let count = positions.count;
        self.raw.degenerate_in_source += degenerate;
        let factor = self.read_material(primitive, &place, streams[1].is_some())?;
        let positions = self.floats(pa, &positions)?;

        // Transform and append.
        let identity = world == DMat4::IDENTITY;
        let linear = DMat3::from_mat4(world);
        let (a, b, c) = (linear.x_axis, linear.y_axis, linear.z_axis);
        let det = linear.determinant();
        // The inverse transpose up to a positive factor: the cofactor
        // matrix times the determinant's sign (defined even when singular).
        let cofactor = DMat3::from_cols(b.cross(c), c.cross(a), a.cross(b)) * det.signum();
        for (v, p) in positions.chunks_exact(3).enumerate() {
            let p = Vec3::from_slice(p);
            let q = if identity {
                p
            } else {
                world.transform_point3(p.as_dvec3()).as_vec3()
            };
            if !q.is_finite() {
                return Err(self.fail(
                    place,
                    format!("vertex {v} is not finite once transformed ({p} to {q})"),
                ));
            }
            self.raw.positions.push(q);
        }
        let [normals, uvs, colors] = streams;
        let properties = &mut self.raw.properties;
        let normals = normals.map(|(n, _)| {
            n.chunks_exact(3)
                .map(|n| {
                    let n = Vec3::from_slice(n);
                    if identity {
                        n
                    } else {
                        (cofactor * n.as_dvec3()).normalize_or_zero().as_vec3()
                    }
                })
                .collect::<Vec<_>>()
        });
        extend(&mut properties.normals, before, count, normals, Vec3::ZERO);
        let uvs = uvs.map(|(t, _)| flip_uvs(&t));
        extend(&mut properties.uvs, before, count, uvs, Vec2::ZERO);
        let colors = match colors {
            Some((c, dims)) => Some(colors_times(&c, dims, factor)),
            None if self.factors_used => Some(vec![factor; count]),
            None => None,
        };
        extend(&mut properties.colors, before, count, colors, Vec4::ONE);
        let base = before as u32;
        let flip = det < 0.0;
        self.raw.triangles.extend(triangles.iter().map(|t| {
            let t = t.map(|v| v + base);
            if flip {
                [t[0], t[2], t[1]]
            } else {
                t
            }
        }));
        Ok(())
    }

    /// Reads primitive `p` of mesh `m` as a new part placed at `world`;
    /// returns its index in the parts, `None` for points and lines.
    fn read_part(
        &mut self,
        m: usize,
        p: usize,
        primitive: &json::mesh::Primitive,
        world: DMat4,
    ) -> Result<Option<usize>> {
        let place = Place::element(&format!("mesh {m} primitive"), p as u64);
        let Some(geometry) = self.geometry(m, p, primitive, &place)? else {
            return Ok(None);
        };
        let Geometry {
            pa,
            positions,
            streams,
            triangles,
            degenerate,
        } = geometry;
        let has_uvs = streams[1].is_some();
        let material = self.material(primitive, &place, has_uvs)?;
        let texture = match material.image {
            Some((image, texture)) => self.part_image(image, texture)?,
            None => None,
        };
        let factor = material.factor;
        let positions = self.floats(pa, &positions)?;
        let count = positions.len() / 3;
        let [normals, uvs, colors] = streams;
        let properties = crate::mesh::Properties {
            normals: normals.map(|(n, _)| n.chunks_exact(3).map(Vec3::from_slice).collect()),
            uvs: uvs.map(|(t, _)| flip_uvs(&t)),
            colors: match colors {
                Some((c, dims)) => Some(colors_times(&c, dims, factor)),
                None if factor != Vec4::ONE => Some(vec![factor; count]),
                None => None,
            },
            position_ids: Vec::new(),
            texture,
        };
        let raw = RawMesh {
            positions: positions.chunks_exact(3).map(Vec3::from_slice).collect(),
            triangles,
            degenerate_in_source: degenerate,
            properties,
        };
        let Target::Parts { parts, .. } = &mut self.target else {
            unreachable!("parts are read for the parts target");
        };
        parts.push(GltfPart {
            mesh: m,
            primitive: p,
            name: self.root.meshes[m].name.clone(),
            material: material.index,
            base_color: factor,
            raw,
            transforms: vec![world],
        });
        Ok(Some(parts.len() - 1))
    }

    /// One more instance, at `world`, of the mesh whose parts (read before)
    /// are `of_mesh`: counted against the limits as [`parse_gltf`] would
    /// count its copy.
    fn instance_parts(&mut self, of_mesh: &[usize], world: DMat4) -> Result<()> {
        for &i in of_mesh {
            let Target::Parts { parts, .. } = &self.target else {
                unreachable!("parts are instanced for the parts target");
            };
            let part = &parts[i];
            let place = Place::element(
                &format!("mesh {} primitive", part.mesh),
                part.primitive as u64,
            );
            let (vertices, triangles) = (part.raw.positions.len(), part.raw.triangles.len());
            self.count_vertices(vertices, &place)?;
            self.count_triangles(triangles, &place)?;
            if let Target::Parts { parts, .. } = &mut self.target {
                parts[i].transforms.push(world);
            }
        }
        Ok(())
    }

    /// The texture of image `i` for a part (read once, then cloned), from
    /// material texture `texture`.
    fn part_image(&mut self, i: usize, texture: usize) -> Result<Option<Texture>> {
        if let Target::Parts { images, .. } = &self.target {
            if let Some(read) = images.get(&i) {
                return Ok(read.clone());
            }
        }
        let read = self.image(i, Place::element("texture", texture as u64))?;
        if let Target::Parts { images, .. } = &mut self.target {
            images.insert(i, read.clone());
        }
        Ok(read)
    }

    /// The primitive's triangles from its index list, by mode (the
    /// specification's topology types): strip triangle `i` is
    /// `(i, i + 1 + i % 2, i + 2 - i % 2)`, fan triangle `i` is
    /// `(i + 1, i + 2, 0)`; and the degenerate strip and fan triangles (a
    /// strip's joins) dropped, for [`RawMesh::degenerate_in_source`].
    fn triangles(
        &mut self,
        mode: Mode,
        ix: &[u32],
        place: &Place,
    ) -> Result<(Vec<[u32; 3]>, usize)> {
        let n = ix.len();
        let mut out = Vec::with_capacity(if mode == Mode::Triangles {
            n / 3
        } else {
            n.saturating_sub(2)
        });
        let mut degenerate = 0;
        match mode {
            Mode::Triangles => {
                // A count that is not a multiple of 3 is the validator's
                // MESH_PRIMITIVE_INCOMPATIBLE_MODE, a warning: the whole
                // triangles are drawn, the rest left (as a GPU does).
                if n % 3 != 0 {
                    self.note(format!(
                        "{place}: {n} indices for a triangle list, not a multiple of 3: the \
                         last {} are not drawn",
                        n % 3
                    ));
                }
                out.extend(ix.chunks_exact(3).map(|t| [t[0], t[1], t[2]]));
            }
            Mode::TriangleStrip | Mode::TriangleFan => {
                for i in 0..n.saturating_sub(2) {
                    let t = if mode == Mode::TriangleFan {
                        [ix[i + 1], ix[i + 2], ix[0]]
                    } else {
                        [ix[i], ix[i + 1 + i % 2], ix[i + 2 - i % 2]]
                    };
                    if crate::mesh::is_degenerate(t) {
                        degenerate += 1;
                    } else {
                        out.push(t);
                    }
                }
            }
            _ => unreachable!("only triangle modes reach here"),
        }
        Ok((out, degenerate))
    }

    /// The primitive's material, checked: its index, base-colour factor
    /// (clamped to 0..=1) and base-colour image with the texture naming it;
    /// notes a texture set other than 0, and a texture without
    /// `TEXCOORD_0` (`has_uvs`).
    fn material(
        &mut self,
        primitive: &json::mesh::Primitive,
        place: &Place,
        has_uvs: bool,
    ) -> Result<Material> {
        let root = self.root;
        let Some(mi) = primitive.material.map(|m| m.value()) else {
            return Ok(Material {
                index: None,
                factor: Vec4::ONE,
                image: None,
            });
        };
        let Some(material) = root.materials.get(mi) else {
            return Err(self.fail(
                place.clone(),
                format!(
                    "material {mi} does not exist ({} materials)",
                    root.materials.len()
                ),
            ));
        };
        let pbr = &material.pbr_metallic_roughness;
        let factor = Vec4::from_array(pbr.base_color_factor.0);
        if !factor.is_finite() {
            return Err(self.fail(
                Place::element("material", mi as u64),
                "the base-colour factor is not finite".into(),
            ));
        }
        let factor = factor.clamp(Vec4::ZERO, Vec4::ONE);
        let Some(info) = &pbr.base_color_texture else {
            return Ok(Material {
                index: Some(mi),
                factor,
                image: None,
            });
        };
        let ti = info.index.value();
        let Some(texture) = root.textures.get(ti) else {
            return Err(self.fail(
                Place::element("material", mi as u64),
                format!(
                    "texture {ti} does not exist ({} textures)",
                    root.textures.len()
                ),
            ));
        };
        let image = texture.source.value();
        if image == u32::MAX as usize {
            // The model's value for an absent `source`: the image is only
            // in an extension (KHR_texture_basisu, EXT_texture_webp).
            self.note(format!(
                "texture {ti} has its image only in an extension (such as KHR_texture_basisu), \
                 which this reader does not decode: drawn untextured"
            ));
            return Ok(Material {
                index: Some(mi),
                factor,
                image: None,
            });
        }
        if info.tex_coord != 0 {
            self.note(format!(
                "material {mi}'s base-colour texture uses TEXCOORD_{}; only TEXCOORD_0 is read",
                info.tex_coord
            ));
        }
        if !has_uvs {
            self.note(format!(
                "{place} has a base-colour texture but no TEXCOORD_0: its texture coordinates \
                 are (0, 0)"
            ));
        }
        Ok(Material {
            index: Some(mi),
            factor,
            image: Some((image, ti)),
        })
    }

    /// The primitive material's base-colour factor, for the merged mesh;
    /// chooses the texture when none is chosen yet, notes one that differs.
    fn read_material(
        &mut self,
        primitive: &json::mesh::Primitive,
        place: &Place,
        has_uvs: bool,
    ) -> Result<Vec4> {
        let material = self.material(primitive, place, has_uvs)?;
        let factor = material.factor;
        if factor != Vec4::ONE && !self.factors_used {
            // Colours so far were white.
            self.factors_used = true;
            let n = self.raw.positions.len();
            self.raw
                .properties
                .colors
                .get_or_insert_with(|| vec![Vec4::ONE; n]);
        }
        let (Some((image, ti)), Some(mi)) = (material.image, material.index) else {
            return Ok(factor);
        };
        match &self.base_color {
            None => {
                if let Some(texture) = self.image(image, Place::element("texture", ti as u64))? {
                    self.base_color = Some(BaseColor { image, texture });
                }
            }
            Some(chosen) if chosen.image != image => {
                let first = chosen.image;
                self.note(format!(
                    "material {mi} samples image {image}, another primitive image {first}: \
                     the mesh keeps image {first} only"
                ));
            }
            Some(_) => {}
        }
        Ok(factor)
    }

    /// Image `i` as a texture: a file beside the asset, or embedded bytes;
    /// `None`, with a note, for a file that cannot be read (the mesh is
    /// drawn untextured, as an OBJ whose `map_Kd` is missing).
    fn image(&mut self, i: usize, place: Place) -> Result<Option<Texture>> {
        let root = self.root;
        let Some(image) = root.images.get(i) else {
            return Err(self.fail(
                place,
                format!("image {i} does not exist ({} images)", root.images.len()),
            ));
        };
        let place = Place::element("image", i as u64);
        let mime = image.mime_type.as_ref().map(|m| m.0.clone());
        let ktx2 = mime.as_deref() == Some("image/ktx2")
            || image
                .uri
                .as_deref()
                .is_some_and(|u| u.to_ascii_lowercase().ends_with(".ktx2"));
        if ktx2 {
            self.note(format!(
                "image {i} is KTX2 (KHR_texture_basisu), which this reader does not decode: \
                 drawn untextured"
            ));
            return Ok(None);
        }
        if let Some(view) = image.buffer_view {
            let (buffer, range) = self.view_range(view.value(), &place)?;
            let bytes = self.buffers[buffer]
                .as_ref()
                .map(|b| b.bytes[range].to_vec())
                .unwrap_or_default();
            return Ok(Some(Texture::Embedded {
                mime: mime.unwrap_or_default(),
                bytes,
            }));
        }
        let Some(uri) = &image.uri else {
            return Err(self.fail(place, "neither a uri nor a bufferView".into()));
        };
        match data_uri(uri).map_err(|m| self.fail(place.clone(), m))? {
            Some((data_mime, bytes)) => Ok(Some(Texture::Embedded {
                mime: mime.unwrap_or(data_mime),
                bytes,
            })),
            None => {
                let relative = decode_uri(uri).map_err(|m| self.fail(place, m))?;
                let file = self.folder.join(relative);
                if std::fs::metadata(&file).is_ok_and(|m| m.is_file()) {
                    Ok(Some(Texture::File(file)))
                } else {
                    self.note(format!(
                        "image {i} ({}) is not a readable file: drawn untextured",
                        file.display()
                    ));
                    Ok(None)
                }
            }
        }
    }

    /// Reads buffer `b` if not read yet.
    fn load_buffer(&mut self, b: usize, place: &Place) -> Result<()> {
        let root = self.root;
        let Some(buffer) = root.buffers.get(b) else {
            return Err(self.fail(
                place.clone(),
                format!("buffer {b} does not exist ({} buffers)", root.buffers.len()),
            ));
        };
        if self.buffers[b].is_some() {
            return Ok(());
        }
        let bplace = Place::element("buffer", b as u64);
        let loaded = match &buffer.uri {
            None => match self.bin {
                Some((bytes, base)) if b == 0 => Buffer {
                    bytes: Cow::Borrowed(bytes),
                    base: Some(base),
                    origin: "the BIN chunk".into(),
                },
                _ => {
                    return Err(self.fail(
                        bplace,
                        "no uri, and it is not buffer 0 of a .glb with a BIN chunk".into(),
                    ))
                }
            },
            Some(uri) => match data_uri(uri).map_err(|m| self.fail(bplace.clone(), m))? {
                Some((_, bytes)) => Buffer {
                    bytes: Cow::Owned(bytes),
                    base: None,
                    origin: "its data URI".into(),
                },
                None => {
                    let relative = decode_uri(uri).map_err(|m| self.fail(bplace.clone(), m))?;
                    let file = self.folder.join(relative);
                    Buffer {
                        bytes: Cow::Owned(read_file(&file)?),
                        base: None,
                        origin: file.display().to_string(),
                    }
                }
            },
        };
        let declared = buffer.byte_length.0;
        if (loaded.bytes.len() as u64) < declared {
            return Err(self.fail(
                bplace,
                format!(
                    "byteLength is {declared}, {} holds {} bytes",
                    loaded.origin,
                    loaded.bytes.len()
                ),
            ));
        }
        self.buffers[b] = Some(loaded);
        Ok(())
    }

    /// Buffer view `v`'s buffer (read) and byte range in it, checked
    /// against the buffer's declared length.
    fn view_range(&mut self, v: usize, place: &Place) -> Result<(usize, std::ops::Range<usize>)> {
        let root = self.root;
        let Some(view) = root.buffer_views.get(v) else {
            return Err(self.fail(
                place.clone(),
                format!(
                    "buffer view {v} does not exist ({} buffer views)",
                    root.buffer_views.len()
                ),
            ));
        };
        let vplace = Place::element("bufferView", v as u64);
        if let Some(c) = self.beside.compressed.get(v).cloned().flatten() {
            return self.decoded_view(v, &c);
        }
        let b = view.buffer.value();
        self.load_buffer(b, &vplace)?;
        let declared = root.buffers[b].byte_length.0;
        let offset = view.byte_offset.map_or(0, |o| o.0);
        let length = view.byte_length.0;
        match offset.checked_add(length) {
            Some(end) if end <= declared => Ok((b, offset as usize..end as usize)),
            _ => Err(self.fail(
                vplace,
                format!(
                    "bytes {offset}..{offset}+{length} lie beyond buffer {b} \
                     ({declared} bytes)"
                ),
            )),
        }
    }

    /// Why a triangle primitive is skipped rather than read, if it is: no
    /// `POSITION` (glTF 2.0, "Meshes": a client should then skip the
    /// primitive's rendering), or an accessor reading a buffer without data
    /// (a `.gltf` buffer without uri has no bytes anywhere: the validator
    /// lets it be, and there is nothing to draw). One rule for reading
    /// ([`Reader::geometry`]) and for counting parts.
    fn undrawable(&self, primitive: &json::mesh::Primitive) -> Option<String> {
        if !primitive
            .attributes
            .contains_key(&Checked::Valid(Semantic::Positions))
        {
            return Some("has no POSITION attribute".into());
        }
        let used = primitive
            .attributes
            .values()
            .map(|a| a.value())
            .chain(primitive.indices.map(|a| a.value()));
        let b = used.filter_map(|a| self.dataless_buffer(a)).next()?;
        Some(format!(
            "reads buffer {b}, which has no uri (and is not a .glb's BIN chunk), so no data"
        ))
    }

    /// The buffer without data (no uri, and not buffer 0 of a `.glb` with
    /// a BIN chunk) that accessor `a` reads, if any; out-of-range indices
    /// are left to the checks that report them.
    fn dataless_buffer(&self, a: usize) -> Option<usize> {
        let root = self.root;
        let accessor = root.accessors.get(a)?;
        let sparse = accessor.sparse.as_ref();
        let views = accessor
            .buffer_view
            .map(|v| v.value())
            .into_iter()
            .chain(sparse.map(|s| s.indices.buffer_view.value()))
            .chain(sparse.map(|s| s.values.buffer_view.value()));
        views
            .filter_map(|v| {
                let b = match self.beside.compressed.get(v) {
                    Some(Some(c)) => c.buffer,
                    _ => root.buffer_views.get(v)?.buffer.value(),
                };
                let dataless =
                    root.buffers.get(b)?.uri.is_none() && !(b == 0 && self.bin.is_some());
                dataless.then_some(b)
            })
            .next()
    }

    /// Compressed buffer view `v` ([`gltf_meshopt`]), decoded once into a
    /// slot of `buffers` past the file's own: that slot and the range of
    /// its bytes. The view's own `buffer` (a fallback, often without data)
    /// is not read.
    fn decoded_view(
        &mut self,
        v: usize,
        c: &Compressed,
    ) -> Result<(usize, std::ops::Range<usize>)> {
        let vplace = Place::element("bufferView", v as u64);
        let length = c.decoded_len() as usize;
        if let Some(&slot) = self.decoded.get(&v) {
            return Ok((slot, 0..length));
        }
        let b = c.buffer;
        self.load_buffer(b, &vplace)?;
        let declared = self.root.buffers[b].byte_length.0;
        let Some(end) = c.offset.checked_add(c.length).filter(|&e| e <= declared) else {
            return Err(self.fail(
                vplace,
                format!(
                    "{}: compressed bytes {}..{}+{} lie beyond buffer {b} ({declared} bytes)",
                    c.extension, c.offset, c.offset, c.length
                ),
            ));
        };
        let buffer = self.loaded(b);
        let bytes = &buffer.bytes[c.offset as usize..end as usize];
        let max_count = self.max_triangles.saturating_mul(3);
        let decoded = gltf_meshopt::decode(c, bytes, max_count).map_err(|m| {
            let place = Place {
                byte: buffer.base.map(|base| base.saturating_add(c.offset)),
                ..vplace.clone()
            };
            self.fail(
                place,
                format!(
                    "{}: the {} compressed bytes from byte {} of buffer {b} ({}): {m}",
                    c.extension, c.length, c.offset, buffer.origin
                ),
            )
        })?;
        self.buffers.push(Some(Buffer {
            bytes: Cow::Owned(decoded),
            base: None,
            origin: format!("buffer view {v} as decoded ({})", c.extension),
        }));
        let slot = self.buffers.len() - 1;
        self.decoded.insert(v, slot);
        Ok((slot, 0..length))
    }

    /// Accessor `a`'s layout, checked: a type of `dims` components; base
    /// values in a buffer view (every element inside it) or zeros, at most
    /// three times the caller's triangle limit; sparse indices and values
    /// inside their views.
    fn elements(
        &mut self,
        a: usize,
        dims: &[usize],
        what: &str,
        place: &Place,
    ) -> Result<Elements> {
        let root = self.root;
        let Some(accessor) = root.accessors.get(a) else {
            return Err(self.fail(
                place.clone(),
                format!(
                    "{what} accessor {a} does not exist ({} accessors)",
                    root.accessors.len()
                ),
            ));
        };
        let aplace = Place::element("accessor", a as u64);
        let (Checked::Valid(ty), Checked::Valid(shape)) = (accessor.component_type, accessor.type_)
        else {
            return Err(self.fail(aplace, "unknown componentType or type".into()));
        };
        let ty = ty.0;
        let n = match shape {
            Type::Scalar => 1,
            Type::Vec2 => 2,
            Type::Vec3 => 3,
            Type::Vec4 => 4,
            _ => 0,
        };
        if !dims.contains(&n) {
            let want: Vec<String> = dims
                .iter()
                .map(|d| {
                    if *d == 1 {
                        "SCALAR".into()
                    } else {
                        format!("VEC{d}")
                    }
                })
                .collect();
            return Err(self.fail(
                aplace,
                format!("type {shape:?} where {what} needs {}", want.join(" or ")),
            ));
        }
        let size = ty.size() * n;
        let count = accessor.count.0;
        let dense = match accessor.buffer_view {
            Some(v) => {
                let offset = accessor.byte_offset.map_or(0, |o| o.0);
                Some(self.run(a, "", v.value(), offset, count, size, true)?)
            }
            None => {
                let most = self.max_triangles.saturating_mul(3);
                if count > most || count.checked_mul(size as u64).is_none() {
                    return Err(self.fail(
                        aplace,
                        format!(
                            "no bufferView: {count} elements of zeros, more than the {most} \
                             vertices allowed by the limit of {} triangles{}",
                            self.max_triangles,
                            super::RAISE_LIMIT
                        ),
                    ));
                }
                None
            }
        };
        let sparse = match &accessor.sparse {
            None => None,
            Some(s) => {
                let k = s.count.0;
                if k > count {
                    return Err(self.fail(
                        aplace,
                        format!("sparse.count is {k}, more than the accessor's count {count}"),
                    ));
                }
                let Checked::Valid(index_ty) = s.indices.component_type else {
                    return Err(self.fail(
                        aplace,
                        "sparse.indices.componentType is not an unsigned byte, short or int".into(),
                    ));
                };
                let index_ty = index_ty.0;
                let (iv, vv) = (s.indices.buffer_view.value(), s.values.buffer_view.value());
                let indices = self.run(
                    a,
                    "sparse.indices: ",
                    iv,
                    s.indices.byte_offset.0,
                    k,
                    index_ty.size(),
                    false,
                )?;
                let values = self.run(
                    a,
                    "sparse.values: ",
                    vv,
                    s.values.byte_offset.0,
                    k,
                    size,
                    false,
                )?;
                Some(Sparse {
                    count: k as usize,
                    index_ty,
                    indices,
                    values,
                })
            }
        };
        Ok(Elements {
            ty,
            normalized: accessor.normalized,
            dims: n,
            count: count as usize,
            dense,
            sparse,
        })
    }

    /// `count` elements of `size` bytes from byte `offset` of buffer view
    /// `v`, for accessor `a` (`what` prefixes messages): every `size` bytes,
    /// or every byteStride of the view when `strided`; checked to end
    /// inside the view, the view inside its buffer, before any is read.
    #[allow(clippy::too_many_arguments)]
    fn run(
        &mut self,
        a: usize,
        what: &str,
        v: usize,
        offset: u64,
        count: u64,
        size: usize,
        strided: bool,
    ) -> Result<Run> {
        let aplace = Place::element("accessor", a as u64);
        let (buffer, range) = self.view_range(v, &aplace)?;
        let stride = match self.root.buffer_views[v].byte_stride {
            Some(s) if strided => s.0,
            _ => size,
        };
        if stride < size {
            return Err(self.fail(
                aplace,
                format!(
                    "{what}buffer view {v}'s byteStride {stride} is less than an element \
                     ({size} bytes)"
                ),
            ));
        }
        // The last element ends at offset + stride * (count - 1) + size.
        let end = match count {
            0 => Some(offset),
            _ => (count - 1)
                .checked_mul(stride as u64)
                .and_then(|x| x.checked_add(offset))
                .and_then(|x| x.checked_add(size as u64)),
        };
        let view_length = (range.end - range.start) as u64;
        let start = (range.start as u64).saturating_add(offset);
        match end {
            Some(end) if end <= view_length => Ok(Run {
                buffer,
                start: start as usize,
                stride,
            }),
            _ => {
                let origin = &self.loaded(buffer).origin;
                Err(self.fail(
                    self.byte_place(a, buffer, start),
                    format!(
                        "{what}{count} elements of {size} bytes every {stride} from byte {start} \
                         of buffer {buffer} ({origin}) run past the end of buffer view {v} \
                         ({view_length} bytes from byte {})",
                        range.start
                    ),
                ))
            }
        }
    }

    /// Buffer `b`, read.
    fn loaded(&self, b: usize) -> &Buffer<'a> {
        let Some(buffer) = self.buffers[b].as_ref() else {
            unreachable!("run() reads the buffer of every element it returns");
        };
        buffer
    }

    /// The place of byte `at` of buffer `b`, for accessor `a`.
    fn byte_place(&self, a: usize, b: usize, at: u64) -> Place {
        let base = self.buffers[b].as_ref().and_then(|b| b.base);
        Place {
            byte: base.map(|base| base.saturating_add(at)),
            ..Place::element("accessor", a as u64)
        }
    }

    /// The elements' components as `f32` (integers normalised when the
    /// accessor says so), `dims` per element, sparse substitutions made;
    /// all finite.
    fn floats(&self, a: usize, e: &Elements) -> Result<Vec<f32>> {
        let size = e.ty.size();
        // Component `j` at byte `at`, checked finite; `which` names it.
        let read = |run: &Run, buffer: &Buffer, at: usize, which: &dyn Fn() -> String| {
            let x = component(&buffer.bytes[at..], e.ty, e.normalized);
            if x.is_finite() {
                return Ok(x);
            }
            Err(self.fail(
                self.byte_place(a, run.buffer, at as u64),
                format!(
                    "{} is {x} (byte {at} of buffer {}, {})",
                    which(),
                    run.buffer,
                    buffer.origin
                ),
            ))
        };
        let mut out = match &e.dense {
            None => vec![0.0; e.count * e.dims],
            Some(run) => {
                let buffer = self.loaded(run.buffer);
                let mut out = Vec::with_capacity(e.count * e.dims);
                for k in 0..e.count {
                    let at = run.start + k * run.stride;
                    for j in 0..e.dims {
                        out.push(read(run, buffer, at + j * size, &|| {
                            format!("component {j} of element {k}")
                        })?);
                    }
                }
                out
            }
        };
        if let Some(s) = &e.sparse {
            let buffer = self.loaded(s.values.buffer);
            let mut previous = None;
            for k in 0..s.count {
                let i = self.sparse_index(a, e, s, k, &mut previous)?;
                let at = s.values.start + k * s.values.stride;
                for j in 0..e.dims {
                    out[i * e.dims + j] = read(&s.values, buffer, at + j * size, &|| {
                        format!("component {j} of sparse value {k} (element {i})")
                    })?;
                }
            }
        }
        Ok(out)
    }

    /// Sparse index `k` of accessor `a`: the element it replaces, checked
    /// to be below the accessor's count and above `previous`, the one
    /// before (then set to it).
    fn sparse_index(
        &self,
        a: usize,
        e: &Elements,
        s: &Sparse,
        k: usize,
        previous: &mut Option<usize>,
    ) -> Result<usize> {
        let buffer = self.loaded(s.indices.buffer);
        let at = s.indices.start + k * s.indices.stride;
        let i = unsigned(&buffer.bytes[at..], s.index_ty) as usize;
        let problem = match *previous {
            _ if i >= e.count => format!("the accessor has {} elements", e.count),
            Some(p) if i <= p => format!(
                "not above sparse index {} ({p}): sparse indices strictly increase",
                k - 1
            ),
            _ => {
                *previous = Some(i);
                return Ok(i);
            }
        };
        Err(self.fail(
            self.byte_place(a, s.indices.buffer, at as u64),
            format!(
                "sparse index {k} is {i}, {problem} (byte {at} of buffer {}, {})",
                s.indices.buffer, buffer.origin
            ),
        ))
    }

    /// Index accessor `a`'s values, sparse substitutions made, each below
    /// `vertex_count`.
    fn indices(&mut self, a: usize, vertex_count: usize, place: &Place) -> Result<Vec<u32>> {
        let e = self.elements(a, &[1], "indices", place)?;
        if !matches!(
            e.ty,
            ComponentType::U8 | ComponentType::U16 | ComponentType::U32
        ) {
            return Err(self.fail(
                Place::element("accessor", a as u64),
                format!(
                    "indices of component type {:?}; only unsigned bytes, shorts and ints are indices",
                    e.ty
                ),
            ));
        }
        // The index at byte `at` of `run`'s buffer, checked; `which` names it.
        let read = |run: &Run, buffer: &Buffer, at: usize, which: &dyn Fn() -> String| {
            let i = unsigned(&buffer.bytes[at..], e.ty);
            if (i as usize) < vertex_count {
                return Ok(i);
            }
            Err(self.fail(
                self.byte_place(a, run.buffer, at as u64),
                format!(
                    "{} is {i}, the primitive has {vertex_count} vertices (byte {at} of buffer \
                     {}, {})",
                    which(),
                    run.buffer,
                    buffer.origin
                ),
            ))
        };
        let mut out = match &e.dense {
            None if e.count > 0 && vertex_count == 0 => {
                return Err(self.fail(
                    Place::element("accessor", a as u64),
                    "no bufferView: the indices are 0, the primitive has no vertices".into(),
                ))
            }
            None => vec![0; e.count],
            Some(run) => {
                let buffer = self.loaded(run.buffer);
                let mut out = Vec::with_capacity(e.count);
                for k in 0..e.count {
                    let at = run.start + k * run.stride;
                    out.push(read(run, buffer, at, &|| format!("index {k}"))?);
                }
                out
            }
        };
        if let Some(s) = &e.sparse {
            let buffer = self.loaded(s.values.buffer);
            let mut previous = None;
            for k in 0..s.count {
                let i = self.sparse_index(a, &e, s, k, &mut previous)?;
                let at = s.values.start + k * s.values.stride;
                out[i] = read(&s.values, buffer, at, &|| {
                    format!("sparse value {k} (index {i})")
                })?;
            }
        }
        Ok(out)
    }

    fn finish(mut self) -> Result<RawMesh> {
        self.raw.properties.texture = self.base_color.map(|b| b.texture);
        Ok(self.raw)
    }
}

/// Whether primitives of `mode` are read (triangles, strips and fans).
fn is_triangles(mode: Mode) -> bool {
    matches!(
        mode,
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    )
}

/// glTF texture coordinates (`v` down the image) as the mesh's (`v` up).
fn flip_uvs(t: &[f32]) -> Vec<Vec2> {
    t.chunks_exact(2)
        .map(|t| Vec2::new(t[0], 1.0 - t[1]))
        .collect()
}

/// `COLOR_0` values of `dims` (3 or 4) components as RGBA (alpha 1 for
/// RGB), times the material's `factor`.
fn colors_times(c: &[f32], dims: usize, factor: Vec4) -> Vec<Vec4> {
    c.chunks_exact(dims)
        .map(|c| {
            let alpha = if dims == 4 { c[3] } else { 1.0 };
            Vec4::new(c[0], c[1], c[2], alpha) * factor
        })
        .collect()
}

/// Appends `count` values of a stream for vertices `before..`: `values`
/// when the primitive has them (the stream created with `neutral` for the
/// earlier vertices if it did not exist), else `neutral` when the stream
/// exists.
fn extend<T: Copy>(
    stream: &mut Option<Vec<T>>,
    before: usize,
    count: usize,
    values: Option<Vec<T>>,
    neutral: T,
) {
    match values {
        Some(values) => stream
            .get_or_insert_with(|| vec![neutral; before])
            .extend(values),
        None => {
            if let Some(s) = stream {
                s.resize(before + count, neutral);
            }
        }
    }
}

/// One component at the start of `bytes` (which holds at least its size),
/// as `f32`: normalised integers map to 0..=1 (unsigned) or -1..=1
/// (signed) as the specification's table of normalised integers says;
/// others convert.
fn component(bytes: &[u8], ty: ComponentType, normalized: bool) -> f32 {
    let b = |i: usize| bytes[i];
    match ty {
        ComponentType::F32 => f32::from_le_bytes([b(0), b(1), b(2), b(3)]),
        ComponentType::U8 if normalized => f32::from(b(0)) / 255.0,
        ComponentType::U8 => f32::from(b(0)),
        ComponentType::I8 if normalized => (f32::from(b(0) as i8) / 127.0).max(-1.0),
        ComponentType::I8 => f32::from(b(0) as i8),
        ComponentType::U16 => {
            let x = f32::from(u16::from_le_bytes([b(0), b(1)]));
            if normalized {
                x / 65535.0
            } else {
                x
            }
        }
        ComponentType::I16 => {
            let x = f32::from(i16::from_le_bytes([b(0), b(1)]));
            if normalized {
                (x / 32767.0).max(-1.0)
            } else {
                x
            }
        }
        ComponentType::U32 => u32::from_le_bytes([b(0), b(1), b(2), b(3)]) as f32,
    }
}

/// An unsigned integer component at the start of `bytes` (which holds at
/// least its size): `ty` is `U8`, `U16` or `U32`.
fn unsigned(bytes: &[u8], ty: ComponentType) -> u32 {
    match ty {
        ComponentType::U8 => u32::from(bytes[0]),
        ComponentType::U16 => u32::from(u16::from_le_bytes([bytes[0], bytes[1]])),
        _ => u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
    }
}

/// The MIME type and decoded bytes of a base64 `data:` URI; `None` when
/// `uri` is not a data URI.
///
/// # Errors
/// A message when it is a data URI but not base64, or not valid base64.
fn data_uri(uri: &str) -> std::result::Result<Option<(String, Vec<u8>)>, String> {
    let Some(rest) = uri.strip_prefix("data:") else {
        return Ok(None);
    };
    let Some((header, data)) = rest.split_once(',') else {
        return Err("data URI without a comma before its data".into());
    };
    let Some(mime) = header.strip_suffix(";base64") else {
        return Err(format!(
            "data URI \"data:{header},\" is not base64 (only base64 data URIs are read)"
        ));
    };
    let bytes = decode_base64(data).map_err(|m| format!("data URI: {m}"))?;
    Ok(Some((mime.to_owned(), bytes)))
}

/// Decodes standard base64 (padding optional).
///
/// # Errors
/// A message naming the character at fault, or a length no bytes fit.
fn decode_base64(text: &str) -> std::result::Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3 + 2);
    let (mut acc, mut bits) = (0u32, 0u32);
    let mut padding = 0;
    for (i, c) in text.char_indices() {
        let v = match c {
            'A'..='Z' => c as u32 - 'A' as u32,
            'a'..='z' => c as u32 - 'a' as u32 + 26,
            '0'..='9' => c as u32 - '0' as u32 + 52,
            '+' => 62,
            '/' => 63,
            '=' if padding < 2 && i > 0 => {
                padding += 1;
                continue;
            }
            _ => return Err(not_base64(i, c)),
        };
        if padding > 0 {
            return Err(not_base64(i, c));
        }
        acc = (acc << 6 | v) & 0xff_ffff;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
        }
    }
    if bits == 6 {
        return Err(format!(
            "{} characters of data: one is left over that encodes no whole byte",
            text.len() - padding
        ));
    }
    Ok(out)
}

fn not_base64(at: usize, c: char) -> String {
    format!(
        "character {at} of the data, {c:?}, is not base64 (A-Z a-z 0-9 + /, then at most two '=')"
    )
}

/// A relative URI reference as a path: `%XX` escapes decoded. Refuses
/// URIs with a scheme (`http:`, `file:`): only files beside the asset and
/// data URIs are read.
pub(super) fn decode_uri(uri: &str) -> std::result::Result<PathBuf, String> {
    if uri.is_empty() {
        return Err("an empty URI names no file".into());
    }
    if let Some((scheme, _)) = uri.split_once(':') {
        let is_scheme = scheme.len() > 1
            && scheme.starts_with(|c: char| c.is_ascii_alphabetic())
            && scheme
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c));
        if is_scheme {
            return Err(format!(
                "URI {uri:?} has the scheme {scheme:?}; only relative paths and data URIs are read"
            ));
        }
    }
    let raw = uri.as_bytes();
    let mut bytes = Vec::with_capacity(raw.len());
    let mut i = 0;
    while i < raw.len() {
        if raw[i] == b'%' {
            let hex = raw
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok());
            let Some(byte) = hex else {
                return Err(format!(
                    "URI {uri:?}: '%' at {i} is not followed by two hex digits"
                ));
            };
            bytes.push(byte);
            i += 3;
        } else {
            bytes.push(raw[i]);
            i += 1;
        }
    }
    String::from_utf8(bytes)
        .map(PathBuf::from)
        .map_err(|_| format!("URI {uri:?} decodes to bytes that are not UTF-8"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// Standard base64 with padding.
    fn base64(bytes: &[u8]) -> String {
        const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut out = String::new();
        for group in bytes.chunks(3) {
            let b = [
                group[0],
                *group.get(1).unwrap_or(&0),
                *group.get(2).unwrap_or(&0),
            ];
            let n = u32::from(b[0]) << 16 | u32::from(b[1]) << 8 | u32::from(b[2]);
            for k in 0..4 {
                if k <= group.len() {
                    out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
                } else {
                    out.push('=');
                }
            }
        }
        out
    }

    //  3 - 2
    //  | / |   a unit quad in z = 0, counter-clockwise seen from +z;
    //  0 - 1   texture coordinates (x, y) in glTF's (v down).
    //
    //  4        a triangle whose primitive draws points (skipped).
    //
    // Mesh 0: the quad with TEXCOORD_0 and material 0 (image 0); mesh 1:
    // the quad without, material 1 (a base-colour factor, no texture);
    // mesh 2: the quad with material 2 (image 1) and the point primitive.
    // Nodes: 0 (mesh 0, x + 3); 1 (no mesh, scale -1 in x, then z + 5)
    // with children 2 (mesh 1) and 3 (mesh 0, y + 2); 4 (mesh 2).
    fn scene_file() -> Vec<u8> {
        let floats: Vec<f32> = vec![
            0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0., // positions
            0., 0., 1., 0., 1., 1., 0., 1., // texture coordinates
        ];
        let mut bin: Vec<u8> = floats.iter().flat_map(|x| x.to_le_bytes()).collect();
        bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|x| x.to_le_bytes()));
        let body = json!({
            "asset": { "version": "2.0" },
            "buffers": [{
                "byteLength": bin.len(),
                "uri": format!("data:application/octet-stream;base64,{}", base64(&bin)),
            }],
            "bufferViews": [
                { "buffer": 0, "byteOffset": 0, "byteLength": 48 },
                { "buffer": 0, "byteOffset": 48, "byteLength": 32 },
                { "buffer": 0, "byteOffset": 80, "byteLength": 12 },
            ],
            "accessors": [
                { "bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 4 },
                { "bufferView": 1, "componentType": 5126, "type": "VEC2", "count": 4 },
                { "bufferView": 2, "componentType": 5123, "type": "SCALAR", "count": 6 },
            ],
            "images": [
                { "uri": format!("data:image/png;base64,{}", base64(b"first")) },
                { "uri": format!("data:image/png;base64,{}", base64(b"second")) },
            ],
            "textures": [{ "source": 0 }, { "source": 1 }],
            "materials": [
                { "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } },
                { "pbrMetallicRoughness": { "baseColorFactor": [0.5, 0.25, 1.0, 1.0] } },
                { "pbrMetallicRoughness": { "baseColorTexture": { "index": 1 } } },
            ],
            "meshes": [
                { "name": "a", "primitives": [
                    { "attributes": { "POSITION": 0, "TEXCOORD_0": 1 }, "indices": 2, "material": 0 },
                ] },
                { "primitives": [{ "attributes": { "POSITION": 0 }, "indices": 2, "material": 1 }] },
                { "primitives": [
                    { "attributes": { "POSITION": 0 }, "mode": 0 },
                    { "attributes": { "POSITION": 0, "TEXCOORD_0": 1 }, "indices": 2, "material": 2 },
                ] },
            ],
            "nodes": [
                { "mesh": 0, "translation": [3.0, 0.0, 0.0] },
                { "children": [2, 3], "translation": [0.0, 0.0, 5.0], "scale": [-1.0, 1.0, 1.0] },
                { "mesh": 1 },
                { "mesh": 0, "translation": [0.0, 2.0, 0.0] },
                { "mesh": 2 },
            ],
            "scenes": [{ "nodes": [0, 1, 4] }],
        });
        serde_json::to_vec(&body).unwrap()
    }

    /// Three parts in the order of their meshes' first instances, each
    /// untransformed with its own texture or factor; mesh 0 once with its
    /// two nodes' matrices; the merged mesh is the parts placed at their
    /// transforms, in scene order, mirrored copies' winding flipped.
    #[test]
    fn parts_keep_their_textures_and_list_their_instances() {
        let file = scene_file();
        let path = Path::new("scene.gltf");
        let parts = parse_gltf_parts(&file, path, 1000).unwrap();
        assert_eq!(gltf_part_count(&file, path).unwrap(), 3);
        let which: Vec<_> = parts.iter().map(|p| (p.mesh, p.primitive)).collect();
        assert_eq!(which, [(0, 0), (1, 0), (2, 1)]);
        let quad = [
            Vec3::ZERO,
            Vec3::new(1., 0., 0.),
            Vec3::new(1., 1., 0.),
            Vec3::new(0., 1., 0.),
        ];
        for part in &parts {
            assert_eq!(part.raw.positions, quad);
            assert_eq!(part.raw.triangles, [[0, 1, 2], [0, 2, 3]]);
            assert_eq!(part.raw.properties.normals, None);
        }
        let png = |b: &[u8]| {
            Some(Texture::Embedded {
                mime: "image/png".into(),
                bytes: b.to_vec(),
            })
        };
        let (a, b, c) = (&parts[0], &parts[1], &parts[2]);
        assert_eq!(a.name.as_deref(), Some("a"));
        assert_eq!(
            (a.material, b.material, c.material),
            (Some(0), Some(1), Some(2))
        );
        assert_eq!(a.raw.properties.texture, png(b"first"));
        assert_eq!(c.raw.properties.texture, png(b"second"));
        assert_eq!(b.raw.properties.texture, None);
        let uvs = [
            Vec2::new(0., 1.),
            Vec2::new(1., 1.),
            Vec2::new(1., 0.),
            Vec2::new(0., 0.),
        ];
        assert_eq!(a.raw.properties.uvs.as_deref(), Some(&uvs[..]));
        assert_eq!(b.raw.properties.uvs, None);
        // A factor that is not white colours every vertex of its part
        // only; white ones add no colours.
        let factor = Vec4::new(0.5, 0.25, 1.0, 1.0);
        assert_eq!(b.base_color, factor);
        assert_eq!(b.raw.properties.colors, Some(vec![factor; 4]));
        assert_eq!(
            (a.base_color, a.raw.properties.colors.as_ref()),
            (Vec4::ONE, None)
        );

        let mirror = DMat4::from_translation(DVec3::new(0., 0., 5.))
            * DMat4::from_scale(DVec3::new(-1., 1., 1.));
        let under = mirror * DMat4::from_translation(DVec3::new(0., 2., 0.));
        assert_eq!(
            a.transforms,
            [DMat4::from_translation(DVec3::new(3., 0., 0.)), under]
        );
        assert_eq!(b.transforms, [mirror]);
        assert_eq!(c.transforms, [DMat4::IDENTITY]);

        // The merged mesh: instances in scene order (node 0, 2, 3, 4).
        let merged = parse_gltf(&file, path).unwrap();
        let instances = [(a, 0), (b, 0), (a, 1), (c, 0)];
        assert_eq!(merged.positions.len(), 4 * instances.len());
        for (k, (part, t)) in instances.iter().enumerate() {
            let world = part.transforms[*t];
            let placed: Vec<Vec3> = part
                .raw
                .positions
                .iter()
                .map(|p| world.transform_point3(p.as_dvec3()).as_vec3())
                .collect();
            assert_eq!(
                merged.positions[4 * k..4 * k + 4],
                placed[..],
                "instance {k}"
            );
            let flip = world.determinant() < 0.0;
            for (i, t) in part.raw.triangles.iter().enumerate() {
                let t = t.map(|v| v + 4 * k as u32);
                let want = if flip { [t[0], t[2], t[1]] } else { t };
                assert_eq!(merged.triangles[2 * k + i], want, "instance {k}");
            }
        }
        // One texture kept: the first in scene order.
        assert_eq!(merged.properties.texture, png(b"first"));
    }

    /// The limit counts every instance, as the merged mesh's copies: 8
    /// triangles (mesh 0 twice, meshes 1 and 2) pass with 8 and not with 7,
    /// refused at the same primitive with the same message either way.
    #[test]
    fn parts_are_bounded_by_their_instances_as_the_merged_mesh() {
        let file = scene_file();
        let path = Path::new("scene.gltf");
        assert!(parse_gltf_parts(&file, path, 8).is_ok());
        let parts = parse_gltf_parts(&file, path, 7).unwrap_err().to_string();
        let merged = parse_gltf_with(&file, path, 7).unwrap_err().to_string();
        assert_eq!(parts, merged);
        assert!(parts.contains("mesh 2 primitive 1"), "{parts}");
        assert!(parts.contains("more than 7 triangles"), "{parts}");
        // With 5, at mesh 0's second instance (node 3), which reads no
        // data again but counts.
        let parts = parse_gltf_parts(&file, path, 5).unwrap_err().to_string();
        assert_eq!(
            parts,
            parse_gltf_with(&file, path, 5).unwrap_err().to_string()
        );
        assert!(parts.contains("mesh 0 primitive 0"), "{parts}");
    }

    /// The count reads no buffer: a file whose buffer is not there still
    /// counts its parts, and parsing it names the buffer.
    #[test]
    fn counting_parts_reads_only_the_json() {
        let mut value: serde_json::Value = serde_json::from_slice(&scene_file()).unwrap();
        value["buffers"][0]["uri"] = json!("missing.bin");
        let file = serde_json::to_vec(&value).unwrap();
        let path = Path::new("/nonexistent/scene.gltf");
        assert_eq!(gltf_part_count(&file, path).unwrap(), 3);
        let e = parse_gltf_parts(&file, path, 1000).unwrap_err();
        assert!(e.to_string().contains("missing.bin"), "{e}");
        // Structure is checked: a node out of range is an error.
        value["scenes"][0]["nodes"] = json!([0, 9]);
        let file = serde_json::to_vec(&value).unwrap();
        let e = gltf_part_count(&file, path).unwrap_err().to_string();
        assert!(e.contains("node 9 does not exist"), "{e}");
    }
}
