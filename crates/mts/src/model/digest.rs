//! What loading a ready `.mts` guarantees: its strips draw what its recipe
//! replays at three LoDs of every band (the first, the last and one drawn
//! at random), and its LoD → triangle table is the replay's at every LoD.
//!
//! A version-3 file carries the model twice: the recipe (the LoD-0 strips
//! and the contraction sequence, what the model is built from) and the
//! ready records that are walked. The checksum catches accidents, not a
//! file whose ready section was changed and resealed: structure checks
//! ([`MtsModel::validate`]) keep such a file memory-safe, but it could draw
//! other triangles than the recipe says (a record's vertex plus one).
//!
//! **Decision.** Loading compares the two at a sample of LoDs. Validation
//! walks every strip at its band's first LoD anyway (to check its slot
//! size); it also walks it at the band's last LoD and at one LoD of the
//! band drawn at random, and sums each band's triangles at each of these
//! into a multiset digest: the wrapping sum of a keyed 64-bit hash of each
//! oriented triangle (canonical rotation). The recipe is replayed once,
//! incrementally (per-vertex triangle lists; a contraction visits only the
//! triangles around the vertices it moves), its digest taken at the same
//! LoDs and its live triangles counted at every LoD. The key and the random
//! LoDs are drawn per process, so a file cannot be made to collide, nor
//! know which LoDs are looked at. Why these three: every node of a band's
//! strips is walked at its first LoD except those a contraction inside the
//! band brings in; most of those still stand at the band's last LoD (a band
//! ends when a tenth of its triangles are gone), and the random one reaches
//! the rest with the probability of its share of the band. Cost: the
//! replay is O(triangles + the triangles each contraction moves), beside
//! the strip checks on another thread; two more walks of every strip.
//!
//! What is left to trust: a resealed change whose effect lies only between
//! the sampled LoDs of its band (a label moved by one, a node brought in
//! and dropped again inside the band) is caught only when the random LoD
//! falls there; `mts verify --lods all` checks every LoD. Checking every
//! LoD at load time would cost what that verification costs (seconds on
//! large models); a user who trusts nothing loads the recipe-only file,
//! which builds the model from the recipe.

use super::MtsModel;
use crate::encoding::{is_degenerate, RESTART_U32};
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
            for (i, w) in run.windows(3).enumerate() {
                let t = if i % 2 == 0 {
                    [w[0], w[1], w[2]]
                } else {
                    [w[1], w[0], w[2]]
                };
                if !is_degenerate(t) {
                    d.sum = d.sum.wrapping_add(self.hash(t));
                    d.count += 1;
                }
            }
        }
        d
    }
}

impl TriangleKey {
    /// The LoDs of band `b` (LoDs `first..=last`) whose triangles loading
    /// compares: its first and last, and one between drawn with the key;
    /// ascending, without repeats.
    pub(crate) fn band_samples(&self, b: usize, first: u32, last: u32) -> Vec<u32> {
        let span = u64::from(last - first) + 1;
        let drawn =
            first + (mix(self.k1 ^ (b as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)) % span) as u32;
        let mut lods = vec![first, drawn, last];
        lods.sort_unstable();
        lods.dedup();
        lods
    }
}

/// No entry: the end of a vertex's triangle list.
const NONE: u32 = u32::MAX;

/// Replays `model`'s recipe: the digest of its triangles at each of
/// `samples` (ascending LoDs), after checking the LoD → triangle table
/// against the live triangles at every LoD.
///
/// # Errors
/// The first LoD whose table entry differs from the replay's count.
///
/// Cost: O(triangles + vertices + the triangles moved by all
/// contractions); three `u32` per triangle corner and one per vertex.
pub(crate) fn replay_digests(
    model: &MtsModel,
    key: &TriangleKey,
    samples: &[u32],
) -> Result<Vec<Digest>, String> {
    let collapses = model.collapses();
    let table = collapses.triangle_counts();
    let vertices = model.positions.len();
    let mut triangles = model.recipe.strips.triangles();
    // Per vertex, its triangles as a list through the corners: entry
    // 3t + c is corner c of triangle t, `next` links the corners of one
    // vertex, `head` starts each list.
    let mut head = vec![NONE; vertices];
    let mut next = vec![NONE; 3 * triangles.len()];
    let mut digest = Digest::default();
    for (t, tri) in triangles.iter().enumerate() {
        if tri.iter().any(|&v| v as usize >= vertices) {
            return Err(format!(
                "the recipe's triangle {t} names a vertex past {vertices}"
            ));
        }
        for (c, &v) in tri.iter().enumerate() {
            let e = 3 * t + c;
            next[e] = head[v as usize];
            head[v as usize] = e as u32;
        }
        digest.sum = digest.sum.wrapping_add(key.hash(*tri));
        digest.count += 1;
    }
    let mut digests = Vec::with_capacity(samples.len());
    let mut samples = samples.iter().peekable();
    for (lod, &expected) in table.iter().enumerate() {
        if lod > 0 {
            for (from, to) in collapses.moves(lod - 1) {
                if from == to || from as usize >= vertices || to as usize >= vertices {
                    continue;
                }
                let mut e = std::mem::replace(&mut head[from as usize], NONE);
                while e != NONE {
                    let following = next[e as usize];
                    let (t, c) = (e as usize / 3, e as usize % 3);
                    let tri = &mut triangles[t];
                    // A dead triangle keeps its entries until their vertex
                    // moves; its corners no longer name that vertex.
                    if tri[c] == from {
                        digest.sum = digest.sum.wrapping_sub(key.hash(*tri));
                        tri[c] = to;
                        if is_degenerate(*tri) {
                            *tri = [NONE; 3];
                            digest.count -= 1;
                        } else {
                            digest.sum = digest.sum.wrapping_add(key.hash(*tri));
                            next[e as usize] = head[to as usize];
                            head[to as usize] = e;
                        }
                    }
                    e = following;
                }
            }
        }
        if u64::from(expected) != digest.count {
            return Err(format!(
                "the LoD → triangle table says {expected} triangles at LoD {lod}, the recipe's \
                 replay has {}",
                digest.count
            ));
        }
        while samples.peek().is_some_and(|&&l| l as usize == lod) {
            samples.next();
            digests.push(digest);
        }
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
