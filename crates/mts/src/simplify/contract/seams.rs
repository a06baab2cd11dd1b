//! Seams: a mesh whose points are split into several vertices (UV seams,
//! hard edges, colour borders; [`crate::mesh::Properties::position_ids`])
//! is contracted point by point, and each point's vertices follow it.
//!
//! The contractor runs on the points (triangles read through the position
//! ids), so the surface is connected across seams and the guards see its
//! true topology; beside each triangle it keeps the vertex of each corner
//! ([`Contractor::corners`]). Contracting point `a` onto point `b` moves
//! every vertex of `a` that live triangles use onto a vertex of `b`: the
//! one the triangles on edge `ab` pair it with ([`Contractor::seam_map`]).
//! The contraction is refused, so the seam is neither torn nor smeared,
//! when
//! - a vertex of `a` is used by no triangle on edge `ab` (moving `a` across
//!   a seam instead of along it would leave that side's corners behind:
//!   a tear),
//! - one vertex of `a` is paired with two of `b` (the seam crosses `ab` at
//!   `b` only: which side is meant is ambiguous), or
//! - two vertices of `a` are paired with one of `b` (the two sides of the
//!   seam would share `b`'s properties: a smear).
//!
//! - the point pairs more than [`MOST_PAIRS`] vertices (a hostile split),
//!   or
//! - with optimal placement, which moves `b` too, a vertex of `b` that live
//!   triangles use is paired with no vertex of `a` (it would leave the seam
//!   where `b` was: a tear). The pairing is then one to one, and each pair
//!   becomes one created vertex (`created.rs`).
//!
//! So a seam is simplified along itself, as a border is, and its points
//! never multiply. Virtual pairs (no shared triangle) are refused on a
//! seamed mesh. With endpoint placement each vertex keeps its input
//! properties, so a LoD change rewrites indices only.

use super::*;

/// A point whose vertices on the edges it would contract along are more
/// than this stays where it is: real seams meet a handful of times at a
/// point, and the pairing is found by linear search, so a hostile file
/// splitting one point into thousands costs bounded time per check.
const MOST_PAIRS: usize = 64;

impl<P: Place> Contractor<P> {
    /// Pairs each vertex of `a` that live triangles use with the vertex of
    /// `b` it moves onto, into [`Contractor::seam_map`] (first the pair of
    /// the first triangle on edge `ab`); `false` when the contraction would
    /// tear or smear a seam (see the module docs).
    pub(super) fn seam_map(&mut self, a: u32, b: u32) -> bool {
        let mut map = std::mem::take(&mut self.seam_pairs);
        map.clear();
        let mut fine = true;
        for &t in self.fans.get(a) {
            let tri = self.tris[t as usize];
            if tri[0] == DEAD {
                continue;
            }
            let Some(sb) = tri.iter().position(|&w| w == b) else {
                continue;
            };
            let sa = tri.iter().position(|&w| w == a).expect("a's fan holds a");
            let corners = self.corners[t as usize];
            let (wa, wb) = (corners[sa], corners[sb]);
            match map.iter().find(|&&(x, _)| x == wa) {
                Some(&(_, y)) if y != wb => fine = false,
                Some(_) => {}
                None if map.iter().any(|&(_, y)| y == wb) => fine = false,
                None if map.len() == MOST_PAIRS => fine = false,
                None => map.push((wa, wb)),
            }
            if !fine {
                break;
            }
        }
        if fine && !map.is_empty() {
            for &t in self.fans.get(a) {
                let tri = self.tris[t as usize];
                if tri[0] == DEAD || tri.contains(&b) {
                    continue;
                }
                let sa = tri.iter().position(|&w| w == a).expect("a's fan holds a");
                let wa = self.corners[t as usize][sa];
                if !map.iter().any(|&(x, _)| x == wa) {
                    fine = false;
                    break;
                }
            }
        }
        if fine && P::MOVES_KEPT {
            // Optimal placement moves `b` too: each of its vertices in use
            // needs a partner of `a` to share the vertex created for them.
            for &t in self.fans.get(b) {
                let tri = self.tris[t as usize];
                if tri[0] == DEAD || tri.contains(&a) {
                    continue;
                }
                let sb = tri.iter().position(|&w| w == b).expect("b's fan holds b");
                let wb = self.corners[t as usize][sb];
                if !map.iter().any(|&(_, y)| y == wb) {
                    fine = false;
                    break;
                }
            }
        }
        let fine = fine && !map.is_empty();
        self.seam_pairs = map;
        fine
    }

    /// The vertex corner `wa` of a moved triangle takes (after
    /// [`Contractor::seam_map`] accepted the contraction).
    #[inline]
    pub(super) fn seam_target(pairs: &[(u32, u32)], wa: u32) -> u32 {
        pairs
            .iter()
            .find(|&&(x, _)| x == wa)
            .map_or(wa, |&(_, y)| y)
    }
}
