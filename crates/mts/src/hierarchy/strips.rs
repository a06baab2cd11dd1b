//! The strips of every cluster, so that a cluster drawn as it is (an input
//! of an open group whose other inputs are refined, see `select.rs`) sends
//! strips like the groups drawn through their models, not a triangle list.
//!
//! Each cluster is stripified on its own (its triangles become a small
//! submesh; the stripifier is the pipeline's), and its runs are stored back
//! to back in input vertex numbers, separated by [`RESTART`] (`u32::MAX`): the same
//! marker as an [`crate::Extractor`]'s buffer, so a renderer handles both
//! alike.

use super::Hierarchy;
use crate::mesh::{renumber, Mesh};
use crate::strip::encode::RESTART_U32 as RESTART;
use crate::strip::{stripify, StripifyOptions};
use glam::Vec3;

/// Clusters stripified per task of the worker threads.
const CHUNK: usize = 64;

/// The runs of `triangles` (input vertex numbers), each followed by
/// [`RESTART`] but the last, appended to `out`. `remap` is all `u32::MAX`
/// on entry and on return.
fn strip_cluster(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    options: &StripifyOptions,
    remap: &mut [u32],
    out: &mut Vec<u32>,
) {
    let (vertices, local) = renumber(triangles, remap);
    let submesh = Mesh {
        positions: vertices.iter().map(|&v| positions[v as usize]).collect(),
        triangles: local,
        properties: crate::mesh::Properties::default(),
    };
    let strips = stripify(&submesh, options);
    for (i, run) in strips.runs().enumerate() {
        if i > 0 {
            out.push(RESTART);
        }
        out.extend(run.iter().map(|&v| vertices[v as usize]));
    }
}

/// Fills `h.cluster_strips` and every cluster's `strip` range from
/// `triangles` (every cluster's, by its `triangles` range), on all cores.
pub(super) fn strip_clusters(h: &mut Hierarchy, triangles: &[[u32; 3]], options: &StripifyOptions) {
    let n = h.clusters.len();
    let hr: &Hierarchy = h;
    let done: Vec<(Vec<u32>, Vec<u32>)> = crate::parallel::map_indexed(
        n.div_ceil(CHUNK),
        || vec![u32::MAX; hr.positions.len()],
        |remap, chunk| {
            let (mut indices, mut ends) = (Vec::new(), Vec::new());
            for c in chunk * CHUNK..((chunk + 1) * CHUNK).min(n) {
                let r = &hr.clusters[c].triangles;
                let tris = &triangles[r.start as usize..r.end as usize];
                strip_cluster(&hr.positions, tris, options, remap, &mut indices);
                ends.push(indices.len() as u32);
            }
            (indices, ends)
        },
    );
    let mut all = Vec::new();
    let mut c = 0;
    for (indices, ends) in done {
        let base = all.len() as u32;
        let mut start = base;
        for end in ends {
            h.clusters[c].strip = start..base + end;
            start = base + end;
            c += 1;
        }
        all.extend(indices);
    }
    h.cluster_strips = all;
}

/// The triangles that `strip` (runs separated by [`RESTART`]) draws.
pub(super) fn triangles_of(strip: &[u32]) -> Vec<[u32; 3]> {
    let mut out = Vec::new();
    for run in strip.split(|&v| v == RESTART) {
        crate::encoding::decode_run(run, &mut out);
    }
    out
}
