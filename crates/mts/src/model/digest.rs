//! What loading a ready `.mts` guarantees: its strips draw what its recipe
//! replays at LoD 0 and at one LoD drawn at random per load, with the
//! triangle counts its LoD table gives there.
//!
//! A version-3 file carries the model twice: the recipe (the LoD-0 strips
//! and the contraction sequence, what the model is built from) and the
//! ready records that are walked. The checksum catches accidents, not a
//! file whose ready section was changed and resealed: structure checks
//! ([`MtsModel::validate`]) keep such a file memory-safe, but it could draw
//! other triangles than the recipe says (a record's vertex plus one).
//!
//! **Decision: a sample, drawn per load.** Loading compares, at LoD 0 and
//! at one LoD drawn at random, the multiset of triangles the strips draw
//! with the recipe's replay there: each side is summed into a digest, the wrapping sum of a
//! keyed 64-bit hash of each oriented triangle (canonical rotation), with
//! its count, which must also be the LoD table's. The key and the LoDs are
//! drawn per process, so a file can neither be made to collide nor know
//! where it is looked at. The walks reuse validation's (every strip is
//! walked at its band's first LoD to check its slot), plus one walk of the
//! drawn LoD's band; the replay maps the recipe's triangles through their
//! representatives there (climbs of the contraction forest with path
//! compression) on a second thread.
//!
//! **Why not more.** Each sampled LoD costs a pass over its triangles on
//! each side. Measured on the bunny, in the same run as the loader without
//! the check (about 10 ms on this 2-core machine that day): LoD 0 and one
//! drawn LoD add 2–3 ms; three LoDs of every band (replayed incrementally
//! with per-vertex triangle lists) made the load 2.2 × as long, every
//! band's first LoD by representatives 3 ×, and the LoD table checked at
//! every LoD (each triangle's death found by climbing the forest) 8 ms on
//! its own (`docs/experiments/ready-file-trust.md`). So a resealed change
//! whose effect lies elsewhere (a node of a later band, a label moved by
//! one, a table entry past LoD 0) can load: about one single-field change
//! in seven to the records of a small model is refused.
//! `mts verify --lods all` checks every LoD, and a user who trusts no
//! ready section loads the recipe-only file, which builds the model from
//! the recipe.

use super::MtsModel;
use crate::encoding::{is_degenerate, run_triangles, RESTART_U32};
use crate::strip::canonical_triangle;

/// A keyed hash of oriented triangles, and the multiset digest built on it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TriangleKey {
    k0: u64,
    k1: u64,
}

/// The digest of a multiset of triangles: the wrapping sum of their
/// hashes, and their count.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Digest {
    pub(crate) sum: u64,
    pub(crate) count: u64,
}

impl Digest {
    pub(crate) fn merge(&mut self, other: Digest) {
        self.sum = self.sum.wrapping_add(other.sum);
        self.count += other.count;
    }
}

/// The finaliser of MurmurHash3: a bijection of `u64` whose output bits
/// each depend on every input bit.
#[inline]
fn mix(mut x: u64) -> u64 {
    x ^= x >> 33;
    x = x.wrapping_mul(0xff51_afd7_ed55_8ccd);
    x ^= x >> 33;
    x = x.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    x ^ (x >> 33)
}

impl TriangleKey {
    /// A key drawn from the standard library's per-process random seed
    /// (the one `HashMap` uses), so no dependency is needed for it.
    pub(crate) fn random() -> TriangleKey {
        use std::hash::BuildHasher;
        let state = std::collections::hash_map::RandomState::new();
        TriangleKey {
            k0: state.hash_one(0x6d74_735f_6b30_u64),
            k1: state.hash_one(0x6d74_735f_6b31_u64),
        }
    }

    /// The hash of oriented triangle `t` (any rotation of it hashes the
    /// same; the other orientation does not): the folded 128-bit product
    /// of its first two vertices and its third, each mixed with the key
    /// (the "mum" step of wyhash), after the rotation that puts the
    /// smallest vertex first.
    #[inline]
    pub(crate) fn hash(&self, t: [u32; 3]) -> u64 {
        let [a, b, c] = canonical_triangle(t);
        let x = u128::from(self.k0 ^ (u64::from(a) | u64::from(b) << 32));
        let y = u128::from(self.k1 ^ u64::from(c));
        let p = x * y;
        (p >> 64) as u64 ^ p as u64
    }

    /// The digest of the triangles a strip buffer draws (runs joined by
    /// [`RESTART_U32`]; odd triangles of a run flipped, windows with a
    /// repeated vertex skipped, as [`crate::encoding::decode_run`]).
    /// Allocation-free.
    pub(crate) fn digest_of_runs(&self, buffer: &[u32]) -> Digest {
        let mut d = Digest::default();
        for run in buffer.split(|&i| i == RESTART_U32) {
            for t in run_triangles(run) {
                d.sum = d.sum.wrapping_add(self.hash(t));
                d.count += 1;
            }
        }
        d
    }

    /// The LoDs loading compares, per band of `bands` (each band's first
    /// LoD): LoD 0, and one drawn with the key from all of `1..=max_lod`
    /// (so a band is drawn in proportion to its LoDs).
    pub(crate) fn samples(&self, bands: &[u32], max_lod: u32) -> Vec<Vec<u32>> {
        let mut samples = vec![Vec::new(); bands.len()];
        if bands.is_empty() {
            return samples;
        }
        samples[0].push(bands[0]);
        if max_lod > 0 {
            let lod = 1 + (mix(self.k1 ^ 0x5a5a) % u64::from(max_lod)) as u32;
            let band = bands.partition_point(|&first| first <= lod).max(1) - 1;
            if samples[band].last() != Some(&lod) {
                samples[band].push(lod);
            }
        }
        samples
    }
}

/// The digest of the recipe's triangles at each of `samples` (ascending
/// LoDs), after checking that the LoD → triangle table gives their counts
/// there: the LoD-0 strips' triangles with their vertices replaced by their
/// representatives at the sample (climbs of the contraction forest with
/// path compression, valid because samples ascend), degenerate ones
/// dropped for good. Allocation: the LoD-0 triangles and a `u32` per
/// vertex.
///
/// # Errors
/// A recipe triangle past the vertices, or the first sample whose table
/// entry differs from the replay's count.
///
/// Cost: O(triangles alive at the sample) per sample, amortised climbs.
pub(crate) fn replay_digests(
    model: &MtsModel,
    key: &TriangleKey,
    samples: &[u32],
) -> Result<Vec<Digest>, String> {
    if samples.is_empty() {
        return Ok(Vec::new());
    }
    let collapses = model.collapses();
    let (parent, from) = (&collapses.parent, &collapses.parent_from_lod);
    let table = collapses.triangle_counts();
    let vertices = parent.len().min(from.len());
    let mut alive = model.recipe.strips.triangles();
    if let Some(t) = alive
        .iter()
        .position(|t| t.iter().any(|&v| v as usize >= vertices))
    {
        return Err(format!(
            "the recipe's triangle {t} names a vertex past {vertices}"
        ));
    }
    // `up[v]`: a vertex whose representative is `v`'s at every LoD from
    // the last sample on.
    let mut up: Vec<u32> = (0..vertices as u32).collect();
    let mut path = Vec::new();
    let mut digests = Vec::with_capacity(samples.len());
    for &lod in samples {
        // Jumps along `up` (set to a representative at this or an earlier
        // sample, which stays one later on), then climbs the forest; every
        // vertex passed then points at the end.
        let mut find = |v: u32| {
            let mut r = v;
            while path.len() <= vertices {
                let u = up[r as usize];
                if u != r {
                    path.push(r);
                    r = u;
                } else if from[r as usize] <= lod {
                    path.push(r);
                    r = parent[r as usize];
                } else {
                    break;
                }
            }
            for &p in &path {
                up[p as usize] = r;
            }
            path.clear();
            r
        };
        let mut d = Digest::default();
        // Degenerate triangles stay so: they are dropped for good.
        alive.retain_mut(|t| {
            if lod > 0 {
                *t = t.map(&mut find);
            }
            let keep = !is_degenerate(*t);
            if keep {
                d.sum = d.sum.wrapping_add(key.hash(*t));
                d.count += 1;
            }
            keep
        });
        let expected = table.get(lod as usize).copied().unwrap_or(0);
        if u64::from(expected) != d.count {
            return Err(format!(
                "the LoD → triangle table says {expected} triangles at LoD {lod}, the recipe's \
                 replay has {}",
                d.count
            ));
        }
        digests.push(d);
    }
    Ok(digests)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_digest_is_of_the_oriented_multiset() {
        let key = TriangleKey::random();
        // 0 1 2 3: triangles (0,1,2) and (2,1,3) flipped; a swap 2 3 2 adds
        // nothing.
        let a = key.digest_of_runs(&[0, 1, 2, 3, 2]);
        let b = key.digest_of_runs(&[1, 3, 2, RESTART_U32, 2, 0, 1]);
        assert_eq!(a, b, "same triangles, other runs and rotations");
        assert_eq!(a.count, 2);
        let flipped = key.digest_of_runs(&[0, 2, 1, 3]);
        assert_ne!(a.sum, flipped.sum, "the other winding");
        let plus_one = key.digest_of_runs(&[0, 1, 2, 4, 2]);
        assert_ne!(a.sum, plus_one.sum, "a vertex plus one");
    }

    #[test]
    fn keys_differ_between_draws() {
        let (a, b) = (TriangleKey::random(), TriangleKey::random());
        assert_ne!(a.hash([0, 1, 2]), b.hash([0, 1, 2]));
    }
}
