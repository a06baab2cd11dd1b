//! Per-vertex property values in the baselines' bit formats (the
//! progressive mesh file and the cluster-tree packet stream).
//!
//! A vertex's values follow its position: its normal (3 × f32), texture
//! coordinate (2 × f32) and colour (4 × f32), each when the format's flags
//! say the stream is present (bit 0 normals, 1 UVs, 2 colours). Position
//! ids are not carried: the baselines draw vertices, not points. Values are
//! checked as they are read, with [`Properties::validate`]'s rules, so a
//! prefix of a stream never holds a bad value.

use super::bits::{BitReader, BitWriter};
use crate::error::Result;
use crate::mesh::Properties;
use glam::{Vec2, Vec3, Vec4};

/// The flag bits the formats know.
pub(crate) const KNOWN_FLAGS: u64 = 0b111;

/// The stream flags of `p`.
pub(crate) fn flags(p: &Properties) -> u64 {
    u64::from(p.normals.is_some())
        | u64::from(p.uvs.is_some()) << 1
        | u64::from(p.colors.is_some()) << 2
}

/// Bits each vertex's values take under `flags`.
pub(crate) fn bits_per_vertex(flags: u64) -> u64 {
    32 * (3 * (flags & 1) + 2 * (flags >> 1 & 1) + 4 * (flags >> 2 & 1))
}

/// Empty streams for the flags set in `flags`.
pub(crate) fn empty(flags: u64) -> Properties {
    Properties {
        normals: (flags & 1 != 0).then(Vec::new),
        uvs: (flags & 2 != 0).then(Vec::new),
        colors: (flags & 4 != 0).then(Vec::new),
        ..Properties::default()
    }
}

/// Writes vertex `v`'s values of every stream `p` has.
pub(crate) fn write(w: &mut BitWriter, p: &Properties, v: usize) {
    let normals = p.normals.as_ref().map(|n| n[v].to_array().to_vec());
    let uvs = p.uvs.as_ref().map(|t| t[v].to_array().to_vec());
    let colors = p.colors.as_ref().map(|c| c[v].to_array().to_vec());
    for x in [normals, uvs, colors].into_iter().flatten().flatten() {
        w.f32(x);
    }
}

/// One vertex's values, read whole before they are applied.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Values {
    normal: Vec3,
    uv: Vec2,
    color: Vec4,
}

impl Values {
    /// Appends these values to the streams of `p` (those `flags` named).
    pub(crate) fn push(self, p: &mut Properties) {
        if let Some(n) = &mut p.normals {
            n.push(self.normal);
        }
        if let Some(t) = &mut p.uvs {
            t.push(self.uv);
        }
        if let Some(c) = &mut p.colors {
            c.push(self.color);
        }
    }
}

/// Reads one vertex's values under `flags`; `element` names the record in
/// errors.
///
/// # Errors
/// Truncation, a non-finite value, a normal neither unit nor zero, a colour
/// channel outside 0..=1.
pub(crate) fn read(r: &mut BitReader<'_>, flags: u64, element: &str) -> Result<Values> {
    let mut out = Values::default();
    if flags & 1 != 0 {
        let n = Vec3::new(
            r.finite_f32(element)?,
            r.finite_f32(element)?,
            r.finite_f32(element)?,
        );
        let len2 = n.length_squared();
        if len2 != 0.0 && (len2 - 1.0).abs() > 1e-3 {
            return Err(r.error(element, format!("normal {n} is not unit or zero")));
        }
        out.normal = n;
    }
    if flags & 2 != 0 {
        out.uv = Vec2::new(r.finite_f32(element)?, r.finite_f32(element)?);
    }
    if flags & 4 != 0 {
        let c = Vec4::new(
            r.finite_f32(element)?,
            r.finite_f32(element)?,
            r.finite_f32(element)?,
            r.finite_f32(element)?,
        );
        if c.min_element() < 0.0 || c.max_element() > 1.0 {
            return Err(r.error(element, format!("colour {c} is outside 0..=1")));
        }
        out.color = c;
    }
    Ok(out)
}
