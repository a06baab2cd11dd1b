//! Per-vertex properties (vertex attributes): normals, texture coordinates
//! and colours, and which vertices are one point of the surface.
//!
//! **Representation: split vertices with a position id.** Where one point
//! of the surface carries several property values (a UV seam, a hard edge,
//! a colour border) the mesh has one vertex per value, each with the same
//! position, and [`Properties::position_ids`] gives every vertex the id of
//! its point. Chosen over per-corner ("wedge") storage, where every corner
//! holds its own properties and triangles index positions only, because
//! what a GPU draws is one index per corner into one vertex buffer: split
//! vertices are that buffer, so strips, the extractor and every baseline
//! index it unchanged and a LoD change rewrites indices only (properties
//! are uploaded once). Chosen over the reverse (positions per corner,
//! properties per point) because seams are exactly where properties are
//! not per point. What split vertices cost is that the surface's
//! connectivity is no longer the index connectivity: the position ids give
//! it back to the stages that need it (simplification moves all vertices of
//! a point together; the stripifier may join across a seam only through a
//! swap or restart, since the indices differ).

use glam::{Vec2, Vec3, Vec4};
use std::path::PathBuf;

/// An image a material samples: a file, or bytes held in the asset.
#[derive(Debug, Clone, PartialEq)]
pub enum Texture {
    /// An image file (PNG, JPEG), resolved against the asset's folder.
    File(PathBuf),
    /// Image bytes embedded in the asset (glTF buffer views, data URIs),
    /// with their MIME type when the asset names one.
    Embedded {
        /// `image/png`, `image/jpeg`, or empty when unknown.
        mime: String,
        /// The encoded image.
        bytes: Vec<u8>,
    },
}

/// The optional property streams of a [`super::Mesh`], one value per
/// vertex each, and the position id of every vertex.
///
/// Invariants (checked by [`Properties::validate`] through
/// [`super::Mesh::validate`]): each present stream has one entry per vertex
/// and only finite values; normals are unit length or zero (zero: no
/// normal, computed where drawn); colours lie in 0..=1; `position_ids` is
/// empty (every vertex its own point) or has one id per vertex, ids
/// numbered from 0 in order of first use, and vertices with the same id have bit-identical positions.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Properties {
    /// Unit normals.
    pub normals: Option<Vec<Vec3>>,
    /// Texture coordinates (one set: glTF's `TEXCOORD_0`, OBJ's `vt`),
    /// `v` pointing up the image as in OBJ and OpenGL (glTF's is flipped on
    /// load and on write).
    pub uvs: Option<Vec<Vec2>>,
    /// Linear RGBA colours, each channel in 0..=1.
    pub colors: Option<Vec<Vec4>>,
    /// The point of the surface each vertex is; empty when no vertex is
    /// split (then vertex `v` is point `v`).
    pub position_ids: Vec<u32>,
    /// The base-colour texture the UVs sample, when the asset names one.
    pub texture: Option<Texture>,
}

impl Properties {
    /// Whether the mesh carries no property stream and no split vertex.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.normals.is_none()
            && self.uvs.is_none()
            && self.colors.is_none()
            && self.position_ids.is_empty()
    }

    /// The point of vertex `v`.
    #[inline]
    #[must_use]
    pub fn position_id(&self, v: u32) -> u32 {
        self.position_ids.get(v as usize).copied().unwrap_or(v)
    }

    /// Bytes of property data per vertex (4-byte floats: 12 a normal, 8 a
    /// UV, 16 a colour).
    #[must_use]
    pub fn bytes_per_vertex(&self) -> usize {
        12 * usize::from(self.normals.is_some())
            + 8 * usize::from(self.uvs.is_some())
            + 16 * usize::from(self.colors.is_some())
    }

    /// The properties of vertices `order` (new vertex `i` is old vertex
    /// `order[i]`), position ids renumbered densely in order of first use.
    ///
    /// # Panics
    /// If an entry of `order` is not a vertex of these properties.
    #[must_use]
    pub fn gather(&self, order: &[u32]) -> Properties {
        let position_ids = if self.position_ids.is_empty() {
            Vec::new()
        } else {
            let mut new_id = std::collections::HashMap::new();
            order
                .iter()
                .map(|&v| {
                    let next = new_id.len() as u32;
                    *new_id.entry(self.position_ids[v as usize]).or_insert(next)
                })
                .collect()
        };
        Properties {
            normals: pick(self.normals.as_deref(), order),
            uvs: pick(self.uvs.as_deref(), order),
            colors: pick(self.colors.as_deref(), order),
            position_ids,
            texture: self.texture.clone(),
        }
    }

    /// Checks that every stream, and the position ids when present, has
    /// one entry per vertex of `n`.
    ///
    /// # Errors
    /// The first stream of another length.
    pub fn check_counts(&self, n: usize) -> Result<(), String> {
        let count = |name: &str, len: Option<usize>| match len {
            Some(len) if len != n => Err(format!("{len} {name} for {n} vertices")),
            _ => Ok(()),
        };
        count("normals", self.normals.as_ref().map(Vec::len))?;
        count("texture coordinates", self.uvs.as_ref().map(Vec::len))?;
        count("colours", self.colors.as_ref().map(Vec::len))?;
        count(
            "position ids",
            (!self.position_ids.is_empty()).then_some(self.position_ids.len()),
        )
    }

    /// Checks the invariants listed on [`Properties`] for a mesh with
    /// `positions`.
    ///
    /// # Errors
    /// The first broken invariant.
    pub fn validate(&self, positions: &[Vec3]) -> Result<(), String> {
        let n = positions.len();
        self.check_counts(n)?;
        if let Some(normals) = &self.normals {
            for (v, n) in normals.iter().enumerate() {
                let len2 = n.length_squared();
                if !n.is_finite() || (len2 != 0.0 && (len2 - 1.0).abs() > 1e-3) {
                    return Err(format!("normal of vertex {v} is not unit or zero: {n}"));
                }
            }
        }
        if let Some(uvs) = &self.uvs {
            if let Some(v) = uvs.iter().position(|t| !t.is_finite()) {
                return Err(format!("texture coordinate of vertex {v} is not finite"));
            }
        }
        if let Some(colors) = &self.colors {
            let inside =
                |c: &Vec4| c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= 1.0;
            if let Some(v) = colors.iter().position(|c| !inside(c)) {
                return Err(format!("colour of vertex {v} is outside 0..=1"));
            }
        }
        if !self.position_ids.is_empty() {
            let mut first: Vec<u32> = Vec::new();
            for (v, &id) in self.position_ids.iter().enumerate() {
                let id = id as usize;
                if id > first.len() {
                    return Err(format!("position id {id} of vertex {v} skips an id"));
                }
                if id == first.len() {
                    first.push(v as u32);
                } else {
                    let w = first[id] as usize;
                    if positions[v].to_array().map(f32::to_bits)
                        != positions[w].to_array().map(f32::to_bits)
                    {
                        return Err(format!(
                            "vertices {w} and {v} share position id {id} but not their position"
                        ));
                    }
                }
            }
        }
        Ok(())
    }
}

/// `stream`'s values at `order`.
fn pick<T: Copy>(stream: Option<&[T]>, order: &[u32]) -> Option<Vec<T>> {
    stream.map(|s| order.iter().map(|&v| s[v as usize]).collect())
}
