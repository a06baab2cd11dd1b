//! Discrete levels of detail, what users do today: meshoptimizer's
//! `simplify` (Garland-Heckbert quadrics with its own topology rules) at
//! fixed shares of the triangles, each level reordered by
//! `optimize_vertex_cache` (Forsyth-style) and stored as its own index
//! buffer over the full vertex buffer.
//!
//! A LoD `k` of the shared numbering is answered by the coarsest level
//! that still has at least the triangle count of LoD `k` (so the image is
//! never coarser than asked for).
//!
//! The levels index the input's vertex buffer, so the property streams are
//! the input's, stored once (meshoptimizer finds seams by equal positions
//! and simplifies along them).

use crate::lod::{LodSource, Topology};
use crate::mesh::{Mesh, Properties};
use glam::Vec3;
use std::ops::Range;

/// Shares of the input's triangles kept by the levels, finest first.
pub const RATIOS: [f64; 6] = crate::methods::SHARES;

/// Discrete LoDs: one index buffer per level, concatenated.
///
/// Invariants: `level_start` has one more entry than there are levels and
/// triangle counts do not increase from one level to the next.
#[derive(Debug, Clone)]
pub struct DiscreteLods {
    positions: Vec<Vec3>,
    /// The input's normals, UVs and colours (no position ids).
    properties: Properties,
    /// All levels' triangle lists, finest first.
    buffer: Vec<u32>,
    /// Level `l` is `buffer[level_start[l]..level_start[l + 1]]`.
    level_start: Vec<usize>,
    /// The shared LoD -> triangle count table (of the contraction sequence).
    counts: Vec<u32>,
    level: Option<usize>,
    lod: Option<usize>,
    dirty: Vec<Range<usize>>,
}

impl DiscreteLods {
    /// Simplifies `mesh` with meshoptimizer to each of [`RATIOS`] and
    /// optimizes each level for the vertex cache. `counts` is the LoD →
    /// triangle count table the LoDs are read through (the contraction
    /// sequence's, so that LoD `k` means the same budget for every method).
    /// Cost: six meshoptimizer runs (about O(T log T) each).
    #[must_use]
    pub fn new(mesh: &Mesh, counts: &[u32]) -> DiscreteLods {
        let n = mesh.vertex_count();
        let full = mesh.triangle_count();
        let mut buffer = Vec::new();
        let mut level_start = vec![0];
        let mut last = usize::MAX;
        for ratio in RATIOS {
            let target = (ratio * full as f64).round() as usize;
            let triangles = if ratio >= 1.0 {
                mesh.triangles.clone()
            } else {
                crate::peers::meshopt::simplify(mesh, target)
            };
            // meshoptimizer may stop above the target; a level that is not
            // coarser than the previous one adds nothing.
            if triangles.is_empty() || triangles.len() >= last {
                continue;
            }
            last = triangles.len();
            let list: Vec<u32> = triangles.iter().flatten().copied().collect();
            buffer.extend(meshopt::optimize_vertex_cache(&list, n));
            level_start.push(buffer.len());
        }
        DiscreteLods {
            positions: mesh.positions.clone(),
            properties: Properties {
                position_ids: Vec::new(),
                ..mesh.properties.clone()
            },
            buffer,
            level_start,
            counts: counts.to_vec(),
            level: None,
            lod: None,
            dirty: Vec::with_capacity(1),
        }
    }

    /// Number of levels kept.
    #[must_use]
    pub fn level_count(&self) -> usize {
        self.level_start.len() - 1
    }

    /// Triangles of level `l`.
    #[must_use]
    pub fn level_triangles(&self, l: usize) -> usize {
        (self.level_start[l + 1] - self.level_start[l]) / 3
    }

    /// The level that answers LoD `lod`: the coarsest with at least its
    /// triangle count (level 0 if none is coarse enough). O(levels).
    #[must_use]
    pub fn level_for(&self, lod: usize) -> usize {
        let want = self.counts[lod.min(self.counts.len() - 1)] as usize;
        (0..self.level_count())
            .rev()
            .find(|&l| self.level_triangles(l) >= want)
            .unwrap_or(0)
    }
}

impl LodSource for DiscreteLods {
    fn name(&self) -> &'static str {
        "discrete"
    }

    fn max_lod(&self) -> usize {
        self.counts.len() - 1
    }

    fn triangle_count(&self, lod: usize) -> usize {
        self.level_triangles(self.level_for(lod))
    }

    fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    fn properties(&self) -> &Properties {
        &self.properties
    }

    fn topology(&self) -> Topology {
        Topology::TriangleList
    }

    /// Picks the level (O(levels)); the buffer holds every level already,
    /// so nothing is rewritten: the dirty ranges are empty after the first
    /// call, which reports the whole buffer.
    fn set_lod(&mut self, lod: usize) -> usize {
        let lod = lod.min(self.max_lod());
        self.dirty.clear();
        if self.level.is_none() && !self.buffer.is_empty() {
            self.dirty.push(0..self.buffer.len());
        }
        self.level = Some(self.level_for(lod));
        self.lod = Some(lod);
        lod
    }

    fn lod(&self) -> Option<usize> {
        self.lod
    }

    /// The current level's slice of the concatenated buffer (dirty ranges
    /// refer to the whole buffer).
    fn indices(&self) -> &[u32] {
        match self.level {
            Some(l) => &self.buffer[self.level_start[l]..self.level_start[l + 1]],
            None => &[],
        }
    }

    fn dirty_ranges(&self) -> &[Range<usize>] {
        &self.dirty
    }

    fn memory_bytes(&self) -> usize {
        (12 + self.properties.bytes_per_vertex()) * self.positions.len()
            + 4 * self.buffer.len()
            + 8 * self.level_start.len()
    }

    /// Positions, their property values and every level with 32-bit
    /// indices (as stored).
    fn file_bytes(&self) -> usize {
        (12 + self.properties.bytes_per_vertex()) * self.positions.len() + 4 * self.buffer.len()
    }

    fn triangles(&self) -> Vec<[u32; 3]> {
        self.indices()
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect()
    }
}
