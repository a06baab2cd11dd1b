//! A chain of levels of detail in one glTF file, laid out the way engines
//! load one: the `MSFT_lod` extension (Microsoft, glTF 2.0 vendor
//! extension) on the node of the finest level, naming the nodes of the
//! coarser levels in order, with `extras.MSFT_screencoverage` hints for
//! when to switch, derived from the errors the simplifier recorded.
//!
//! Each level is an indexed triangle list (glTF has no primitive restart,
//! so strips would cost a degenerate pair per join) in vertex-cache order
//! ([`crate::strip::cache_order`]) with only the vertices it uses,
//! renumbered in order of first use, so that vertex fetch walks the buffer
//! forwards. Levels share one material and one image.
//!
//! **Screen coverage.** A level's error `e` ([`ChainLevel::error`]) is
//! relative to the bounding-box diagonal `d` of the mesh the levels were
//! made from, as [`crate::simplify::Collapses::error`] is. Coverage `c` is
//! the fraction of the screen height that the model's bounding sphere
//! (diameter `d`) covers, the measure Unity's LOD groups and Unreal's
//! screen size use. On a screen `H` pixels high the level's error then
//! spans `e · c · H` pixels, and the level may be drawn while that is at
//! most the threshold `τ`: while `c ≤ τ / (e · H)`. This is the rule of
//! [`crate::lod_for_screen_error`] with `c · H / d` pixels per unit. The
//! extension's value `k` is the coverage below which level `k + 1` is
//! drawn instead of level `k` (its example: level 0 from 1.0 down to the
//! first value, level 1 down to the second, nothing below the last), so
//! ([`screen_coverages`]):
//!
//! ```text
//! s[k]     = min(1, τ / (e[k+1] · H))   for k < n - 1   (1 when e[k+1] = 0)
//! s[n - 1] = 0                                           (never culled)
//! ```
//!
//! Not increasing, since errors do not decrease along the chain. The hint
//! holds for the stated `τ` and `H` ([`Coverage`]; 1 pixel at 1080 by
//! default); an engine with another screen scales it by `1080 / H'`.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::simplify::Collapses;
#[cfg(feature = "gltf")]
use serde_json::{json, Value};
#[cfg(feature = "gltf")]
use std::path::Path;

/// One level of a chain: its mesh and its geometric error.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainLevel {
    /// The level as a standalone mesh (every vertex used, as
    /// [`Mesh::validate`] requires; [`Collapses::mesh_at`] and
    /// [`Mesh::level`] make one).
    pub mesh: Mesh,
    /// Error relative to the bounding-box diagonal of the mesh the chain
    /// was made from (0 for that mesh itself): [`Collapses::error`] at the
    /// level's LoD.
    pub error: f32,
}

/// The screen on which the coverage hints hold: a level is drawn while its
/// error spans at most `pixel_threshold` pixels on a screen
/// `screen_height` pixels high (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coverage {
    /// Largest error a drawn level may show, in pixels (default 1).
    pub pixel_threshold: f32,
    /// Height of the reference screen in pixels (default 1080).
    pub screen_height: f32,
}

impl Default for Coverage {
    fn default() -> Self {
        Coverage {
            pixel_threshold: 1.0,
            screen_height: 1080.0,
        }
    }
}

/// The `MSFT_screencoverage` values for a chain whose levels have the
/// relative `errors` (finest first): one per level, value `k` the fraction
/// of the screen height below which level `k + 1` replaces level `k`, the
/// last 0 (see the module docs for the formula). Values lie in `0..=1` and
/// do not increase when `errors` do not decrease.
///
/// Cost: O(levels).
#[must_use]
pub fn screen_coverages(errors: &[f32], coverage: &Coverage) -> Vec<f32> {
    let budget = f64::from(coverage.pixel_threshold) / f64::from(coverage.screen_height);
    (0..errors.len())
        .map(|k| match errors.get(k + 1) {
            None => 0.0,
            Some(&e) if e <= 0.0 => 1.0,
            Some(&e) => (budget / f64::from(e)).min(1.0) as f32,
        })
        .collect()
}

/// `mesh` with its triangles in vertex-cache order
/// ([`crate::strip::cache_order::reorder_for_vertex_cache`]) and its
/// vertices renumbered in order of first use ([`Mesh::level`]; unused ones
/// dropped): the same surface, as an engine draws a triangle list best.
///
/// Cost: O(triangles × cache size × valence).
#[must_use]
pub fn order_for_cache(mesh: &Mesh) -> Mesh {
    let ordered =
        crate::strip::cache_order::reorder_for_vertex_cache(&mesh.triangles, mesh.vertex_count());
    Mesh::level(&mesh.positions, &ordered, &mesh.properties)
}

/// The levels of `collapses` (computed from `mesh`) at `lods`, finest
/// first: each [`Collapses::mesh_at`] (with the mesh's properties) and
/// its [`Collapses::error`]. A caller with ratios maps them with
/// [`Collapses::lod_for_ratio`] and drops repeats first.
///
/// # Errors
/// [`Error::InvalidArgument`] when `lods` is empty, not strictly
/// increasing, or names a LoD past [`Collapses::max_lod`].
///
/// # Panics
/// If `mesh` is not the mesh `collapses` was computed from.
///
/// Cost: O(levels × (vertices + triangles)).
pub fn chain_from_collapses(
    mesh: &Mesh,
    collapses: &Collapses,
    lods: &[usize],
) -> Result<Vec<ChainLevel>> {
    if lods.is_empty() {
        return Err(Error::InvalidArgument(
            "a LoD chain needs at least one level".into(),
        ));
    }
    if let Some(w) = lods.windows(2).find(|w| w[0] >= w[1]) {
        return Err(Error::InvalidArgument(format!(
            "the LoDs of a chain go from fine to coarse without repeats; {} comes before {}",
            w[0], w[1]
        )));
    }
    let max = collapses.max_lod();
    if let Some(lod) = lods.iter().find(|&&l| l > max) {
        return Err(Error::InvalidArgument(format!(
            "LoD {lod} is past the coarsest, {max}"
        )));
    }
    Ok(lods
        .iter()
        .map(|&lod| ChainLevel {
            mesh: collapses.mesh_at(mesh, lod),
            error: collapses.error(lod),
        })
        .collect())
}

/// Writes `levels` (finest first) as one glTF 2.0 file, `.glb` or `.gltf`
/// by the extension (feature `gltf`): node `k` draws mesh `k`, level `k`
/// ([`order_for_cache`] of its mesh, one triangle-list primitive); node 0,
/// the only one in the scene (a viewer without the extension draws the
/// finest level), carries `MSFT_lod` with ids `1..n` and
/// `extras.MSFT_screencoverage` ([`screen_coverages`] for `coverage`);
/// `extensionsUsed` lists `MSFT_lod`, `extensionsRequired` does not. A
/// chain of one level is a plain glTF file without the extension. Levels
/// with a texture share material 0 and its image (embedded in a `.glb`;
/// see `save_gltf` for how a `.gltf` refers to it); compressed, the writer
/// then puts it in the codec's strip-like cache order (`save_gltf_as`).
/// `encoding` stores the
/// vertex data plain, quantized or compressed (`save_gltf_as`); quantized
/// levels share one position grid (over every level's positions) and so
/// one node transform.
///
/// # Errors
/// [`Error::InvalidArgument`] for no level, a level without triangles,
/// errors that are negative, not finite or decrease along the chain,
/// levels with different textures, a `coverage` whose values are not
/// positive and finite, and as `save_gltf`; [`Error::Io`] naming the file
/// that cannot be written.
///
/// Cost: the cache ordering of every level, then O(vertices + triangles)
/// of all levels; the file is built in memory.
#[cfg(feature = "gltf")]
pub fn save_lod_chain(
    levels: &[ChainLevel],
    coverage: &Coverage,
    path: &Path,
    encoding: super::Encoding,
) -> Result<()> {
    let binary = super::gltf_write::is_binary(path)?;
    let refuse = |message: String| Error::InvalidArgument(format!("{}: {message}", path.display()));
    let Some(first) = levels.first() else {
        return Err(refuse("a LoD chain needs at least one level".into()));
    };
    let sane = |x: f32| x.is_finite() && x > 0.0;
    if !sane(coverage.pixel_threshold) || !sane(coverage.screen_height) {
        return Err(refuse(format!(
            "screen coverage needs a positive pixel threshold and screen height, not {} and {}",
            coverage.pixel_threshold, coverage.screen_height
        )));
    }
    let mut last = 0.0f32;
    for (k, level) in levels.iter().enumerate() {
        if !level.error.is_finite() || level.error < last {
            return Err(refuse(format!(
                "level {k} has error {}: errors are finite, at least 0, and do not decrease \
                 from fine to coarse",
                level.error
            )));
        }
        last = level.error;
        if level.mesh.properties.texture.is_some()
            && first.mesh.properties.texture.is_some()
            && level.mesh.properties.texture != first.mesh.properties.texture
        {
            return Err(refuse(format!(
                "level {k} has another texture than level 0: the levels of a chain share one"
            )));
        }
    }
    let points = levels.iter().flat_map(|l| &l.mesh.positions);
    let mut out = super::gltf_write::Document::new(encoding, points);
    let mut root = json!({
        "asset": { "version": "2.0", "generator": "mts" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
    });
    let texture = levels
        .iter()
        .find_map(|level| level.mesh.properties.texture.as_ref());
    if let Some(texture) = texture {
        out.material(&mut root, texture, binary, path)?;
    }
    let mut meshes = Vec::with_capacity(levels.len());
    let mut nodes = Vec::with_capacity(levels.len());
    for (k, level) in levels.iter().enumerate() {
        // Compressed, the writer reorders for its codec, and does better
        // from the cache order than from the level's own (the bunny's file
        // 208,944 bytes against 210,088).
        let ordered = order_for_cache(&level.mesh);
        let mut primitive = out
            .primitive(&ordered, path)
            .map_err(|e| refuse(format!("level {k}: {e}")))?;
        if ordered.properties.texture.is_some() {
            primitive["material"] = json!(0);
        }
        meshes.push(json!({ "name": format!("LOD{k}"), "primitives": [primitive] }));
        let mut node = json!({ "name": format!("LOD{k}"), "mesh": k });
        out.place_node(&mut node);
        nodes.push(node);
    }
    if levels.len() > 1 {
        let errors: Vec<f32> = levels.iter().map(|l| l.error).collect();
        nodes[0]["extensions"] =
            json!({ "MSFT_lod": { "ids": (1..levels.len()).collect::<Vec<_>>() } });
        nodes[0]["extras"] = json!({ "MSFT_screencoverage": screen_coverages(&errors, coverage) });
        root["extensionsUsed"] = json!(["MSFT_lod"]);
    }
    root["meshes"] = Value::Array(meshes);
    root["nodes"] = Value::Array(nodes);
    out.write(root, binary, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coverage_follows_the_next_level_s_error() {
        let c = Coverage {
            pixel_threshold: 2.0,
            screen_height: 1024.0,
        };
        // τ / H = 1/512: an error of 1/256 is allowed up to half the
        // screen, 1/64 up to an eighth; a level without error replaces the
        // one before it at any size (1), the last is never culled (0).
        assert_eq!(
            screen_coverages(&[0.0, 0.0, 1.0 / 256.0, 1.0 / 64.0], &c),
            vec![1.0, 0.5, 0.125, 0.0]
        );
        assert_eq!(screen_coverages(&[0.0], &c), vec![0.0]);
        assert!(screen_coverages(&[], &c).is_empty());
        // Tiny errors clamp to the whole screen.
        assert_eq!(screen_coverages(&[0.0, 1e-9], &c), vec![1.0, 0.0]);
    }
}
