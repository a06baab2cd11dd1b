//! Walks over triangles ("paths") and their vertex runs.
//!
//! A path `t0, t1, …, tn` has consecutive triangles adjacent. Its run starts
//! with `t0` rotated so that the edge to `t1` comes last; then each `tk`
//! appends its apex `d`, preceded by a swap (a repeat of the older vertex `x`
//! of the entry edge `x y`) when the exit edge towards `tk+1` is `x d`
//! rather than `y d`. Whether the swap is needed depends only on the pivots
//! (the vertex two consecutive shared edges have in common): a swap is
//! needed where three consecutive shared edges turn around the same vertex,
//! and at `t1` when its pivot is the tail of `t0`'s exit edge. Reversing a
//! path changes only the latter, so [`encode`] tries both directions.
//!
//! Orientation needs no bookkeeping: a triangle entered across edge `x y`
//! (in run order) is drawn as the run position's parity dictates, which for
//! a consistently oriented neighbour is always its own winding, with or
//! without a swap before it.

use crate::mesh::{TriangleAdjacency, NO_NEIGHBOUR};

/// The vertex shared by edge slots `a` and `b` (distinct) of triangle `t`.
pub(super) fn pivot(t: &[u32; 3], a: usize, b: usize) -> u32 {
    debug_assert_ne!(a, b);
    if b == (a + 1) % 3 {
        t[b]
    } else {
        t[a]
    }
}

/// A slot of `t` whose neighbour is `u` (the first when they share more
/// than one edge: any shared edge gives a valid run).
pub(super) fn slot_to(adj: &TriangleAdjacency, t: u32, u: u32) -> usize {
    // Selects instead of a search loop: the slot is unpredictable, the
    // check below is not.
    let ns = &adj.neighbours[t as usize];
    let s = if ns[0] == u {
        0
    } else if ns[1] == u {
        1
    } else {
        2
    };
    assert_eq!(ns[s], u, "path triangles are not adjacent (internal error)");
    s
}

/// Whether starting the run at `path[0]` costs a swap at `path[1]`.
fn start_swap(path: &[u32], tris: &[[u32; 3]], adj: &TriangleAdjacency) -> bool {
    if path.len() < 3 {
        return false;
    }
    let t0 = &tris[path[0] as usize];
    let e0 = slot_to(adj, path[0], path[1]);
    let t1 = &tris[path[1] as usize];
    let in1 = slot_to(adj, path[1], path[0]);
    let out1 = slot_to(adj, path[1], path[2]);
    pivot(t1, in1, out1) == t0[e0]
}

/// Appends the run of `path` to `out`, starting from the front, or, if
/// `reverse_if_cheaper`, from whichever end costs fewer swaps (the front
/// on a tie).
///
/// Cost: O(path length).
pub(super) fn encode(
    path: &[u32],
    tris: &[[u32; 3]],
    adj: &TriangleAdjacency,
    reverse_if_cheaper: bool,
    out: &mut Vec<u32>,
) {
    let reversed: Vec<u32>;
    let path = if reverse_if_cheaper
        && start_swap(path, tris, adj)
        && !start_swap_reversed(path, tris, adj)
    {
        reversed = path.iter().rev().copied().collect();
        &reversed[..]
    } else {
        path
    };
    let t0 = &tris[path[0] as usize];
    if path.len() == 1 {
        out.extend_from_slice(t0);
        return;
    }
    let e0 = slot_to(adj, path[0], path[1]);
    out.extend_from_slice(&[t0[(e0 + 2) % 3], t0[e0], t0[(e0 + 1) % 3]]);
    // Written without data-dependent branches where it can be (a search
    // for the apex or a test of two edge ends mispredicts about once per
    // triangle): the apex is what XOR leaves of the triangle after its
    // entry edge, and `y` lies on the exit edge unless it is the vertex
    // opposite it.
    for k in 1..path.len() {
        let t = &tris[path[k] as usize];
        let (x, y) = (out[out.len() - 2], out[out.len() - 1]);
        debug_assert!(
            t.contains(&x) && t.contains(&y) && x != y,
            "triangle does not hold its entry edge (internal error)"
        );
        let d = t[0] ^ t[1] ^ t[2] ^ x ^ y;
        if k + 1 < path.len() {
            let s = slot_to(adj, path[k], path[k + 1]);
            if t[(s + 2) % 3] == y {
                out.push(x);
            }
        }
        out.push(d);
    }
}

fn start_swap_reversed(path: &[u32], tris: &[[u32; 3]], adj: &TriangleAdjacency) -> bool {
    let n = path.len();
    if n < 3 {
        return false;
    }
    let r = [path[n - 1], path[n - 2], path[n - 3]];
    start_swap(&r, tris, adj)
}

/// Concatenates paths whose end triangles are neighbours.
///
/// A path end is joined to the end of another path when the two end
/// triangles share an edge; the joined walk is valid because the triangles
/// are adjacent. Saves the two starting vertices and the restart of one
/// run for at most one swap. One pass over the path ends.
///
/// Cost: O(paths + T) time.
pub(super) fn join_ends(paths: &mut Vec<Vec<u32>>, adj: &TriangleAdjacency) {
    // For every triangle that ends a path: (path id, is_front).
    let mut end_of = std::collections::HashMap::with_capacity(2 * paths.len());
    for (i, p) in paths.iter().enumerate() {
        end_of.insert(p[0], (i, true));
        end_of.insert(*p.last().expect("paths are not empty"), (i, false));
    }
    let mut alive = vec![true; paths.len()];
    for i in 0..paths.len() {
        if !alive[i] {
            continue;
        }
        // Extend path i at its back as long as the back touches another path's end.
        loop {
            let back = *paths[i].last().expect("paths are not empty");
            let mut joined = false;
            for &n in &adj.neighbours[back as usize] {
                if n == NO_NEIGHBOUR {
                    continue;
                }
                let Some(&(j, front)) = end_of.get(&n) else {
                    continue;
                };
                if j == i || !alive[j] {
                    continue;
                }
                let mut other = std::mem::take(&mut paths[j]);
                if !front {
                    other.reverse();
                }
                alive[j] = false;
                end_of.remove(&other[0]);
                end_of.remove(&back);
                let new_back = *other.last().expect("paths are not empty");
                end_of.insert(new_back, (i, false));
                paths[i].extend_from_slice(&other);
                joined = true;
                break;
            }
            if !joined {
                break;
            }
        }
    }
    let mut k = 0;
    paths.retain(|_| {
        k += 1;
        alive[k - 1]
    });
}
