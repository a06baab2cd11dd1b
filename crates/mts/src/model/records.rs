//! The compact form of the per-strip graphs: one *record* per arc.
//!
//! The paper's `ColumnNode { v_index, neighbours }` with its `RowNode {
//! col_index, res }` list becomes a run of consecutive records, one per
//! arc, the first carrying the node's vertex. A record holds three things,
//! each in its own array:
//! - the node's **vertex** (`u16` when the model has at most 65,536
//!   vertices, else `u32`; 0 on the node's later records);
//! - the arc's **label** `res`, *relative to the first LoD of the strip's
//!   band* (`u16` when every band's labels fit, else `u32`);
//! - a **code** byte: the arc's target as a forward distance in records
//!   (bits 0–5: 0 is the strip's end, the paper's −3; 1 to 62 the target
//!   node's first record that many records on; [`FAR`] the target is in the
//!   model's `far` table), [`BREAK`] (end the run before the target, the
//!   paper's −2/−1), and [`MORE`] (the next record is another arc of this
//!   node). A node without arcs is one record with code [`NO_ARC`].
//!
//! A node is named by its first record, so arc targets and beginnings are
//! record indices and no per-node offset array is needed.
//!
//! **Decision: relative labels and distances, narrow where they fit.** On
//! the bunny's model (87 bands, 1.0 M nodes, 1.09 M arcs) 92% of the nodes
//! have one arc, 90% of the arcs go to the next node, no arc jumps more than
//! 16 records and no label is more than 3,504 LoDs past its band's first;
//! the 1M icosphere's largest jump is 30 records. Five bytes per arc
//! replace the wide form's 16.7 bytes per node (vertex, arc offset, target
//! and label as `u32`) and the walk reads the same number of arrays, in
//! order. A jump of 63 records or more (never seen in the shared models)
//! goes through the `far` table, found by binary search, so no input can
//! break the encoding. Sizes per step: `docs/experiments/compact-model.md`.

/// Code bits 0–5: the forward distance in records to the target.
pub(crate) const DISTANCE: u8 = 0x3f;
/// Distance value meaning "the target is in the `far` table".
pub(crate) const FAR: u8 = 0x3f;
/// Code bit: end the current run before the target (a restart).
pub(crate) const BREAK: u8 = 0x40;
/// Code bit: the next record is another arc of the same node.
pub(crate) const MORE: u8 = 0x80;
/// The code of a node without arcs (a break to the strip's end, which no
/// arc can be).
pub(crate) const NO_ARC: u8 = BREAK;

/// An array of small unsigned integers stored as `u16` when every value
/// fits, else as `u32`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Narrow {
    U16(Vec<u16>),
    U32(Vec<u32>),
}

impl Narrow {
    /// `values` in the narrowest of the two widths that holds them all.
    pub(crate) fn new(values: Vec<u32>) -> Narrow {
        if values.iter().all(|&v| v <= u32::from(u16::MAX)) {
            Narrow::U16(values.iter().map(|&v| v as u16).collect())
        } else {
            Narrow::U32(values)
        }
    }

    pub(crate) fn len(&self) -> usize {
        match self {
            Narrow::U16(v) => v.len(),
            Narrow::U32(v) => v.len(),
        }
    }

    #[cfg(test)]
    pub(crate) fn get(&self, i: usize) -> u32 {
        match self {
            Narrow::U16(v) => u32::from(v[i]),
            Narrow::U32(v) => v[i],
        }
    }

    /// Bytes per value (2 or 4).
    pub(crate) fn width(&self) -> usize {
        match self {
            Narrow::U16(_) => 2,
            Narrow::U32(_) => 4,
        }
    }

    pub(crate) fn bytes(&self) -> usize {
        self.width() * self.len()
    }

    /// Sets value `i` (tests corrupt models with it); a value too wide for
    /// `u16` storage is truncated.
    #[cfg(test)]
    pub(crate) fn set(&mut self, i: usize, value: u32) {
        match self {
            Narrow::U16(v) => v[i] = value as u16,
            Narrow::U32(v) => v[i] = value,
        }
    }
}

/// Evaluates `$body` with `$v` and `$l` bound to the vertex and label
/// arrays of a model at their stored widths, so that the code it calls is
/// monomorphised per width pair (the walks and the validation).
macro_rules! with_widths {
    ($vertex:expr, $label:expr, |$v:ident, $l:ident| $body:expr) => {
        match ($vertex, $label) {
            (Narrow::U16($v), Narrow::U16($l)) => $body,
            (Narrow::U16($v), Narrow::U32($l)) => $body,
            (Narrow::U32($v), Narrow::U16($l)) => $body,
            (Narrow::U32($v), Narrow::U32($l)) => $body,
        }
    };
}
pub(crate) use with_widths;

/// A value read from a [`Narrow`] array inside the walk (monomorphised
/// per width, so the walk's loop has no width test).
pub(crate) trait Word: Copy {
    fn get(self) -> u32;
}

impl Word for u16 {
    #[inline(always)]
    fn get(self) -> u32 {
        u32::from(self)
    }
}

impl Word for u32 {
    #[inline(always)]
    fn get(self) -> u32 {
        self
    }
}

/// The arc a walk takes from the node whose first record is `r`, at LoD
/// `birth + rel` (Fig. 5 of the paper: the first arc whose label is at
/// least the LoD): skipped arcs raise `from` past their labels, the taken
/// one lowers `to` to its label. Returns its record and code, or `None`
/// when the node has no arc valid there (the strip ends). Shared by every
/// walk, monomorphised per label width.
#[inline(always)]
fn take_arc<L: Word>(
    code: &[u8],
    label: &[L],
    mut r: usize,
    rel: u32,
    birth: u32,
    interval: &mut (u32, u32),
) -> Option<(usize, u8)> {
    loop {
        let c = code[r];
        if c == NO_ARC {
            return None;
        }
        let l = label[r].get();
        if l >= rel {
            interval.1 = interval.1.min(birth + l);
            return Some((r, c));
        }
        interval.0 = interval.0.max(birth + l + 1);
        if c & MORE == 0 {
            return None;
        }
        r += 1;
    }
}

/// One step of a walk from the node whose first record is `r`: the arc
/// [`take_arc`] takes and where it leads, `Some((the next node's first
/// record, whether a run break comes before it))`, or `None` where the
/// strip ends. `far` is the model's table of far arcs.
#[inline(always)]
pub(crate) fn step<L: Word>(
    code: &[u8],
    label: &[L],
    far: &[(u32, u32)],
    r: usize,
    rel: u32,
    birth: u32,
    interval: &mut (u32, u32),
) -> Option<(usize, bool)> {
    let (arc, c) = take_arc(code, label, r, rel, birth, interval)?;
    let next = match c & DISTANCE {
        0 => return None,
        FAR => far_target(far, arc),
        d => arc + usize::from(d),
    };
    Some((next, c & BREAK != 0))
}

/// The target of far arc `r` (validation checks that the table holds every
/// far arc).
#[cold]
fn far_target(far: &[(u32, u32)], r: usize) -> usize {
    let i = far.partition_point(|&(at, _)| (at as usize) < r);
    far[i].1 as usize
}

/// The records of every strip, built from the wide graphs the
/// construction produces (node offsets, vertex per node, arcs with global
/// node targets and absolute labels).
pub(crate) struct Records {
    pub(crate) strip_records: Vec<u32>,
    pub(crate) begin_record: Vec<u32>,
    pub(crate) vertex: Narrow,
    pub(crate) label: Narrow,
    pub(crate) code: Vec<u8>,
    pub(crate) far: Vec<(u32, u32)>,
}

/// The wide graphs, as [`super::build`] produces them.
pub(crate) struct Wide<'a> {
    pub(crate) strip_nodes: &'a [u32],
    pub(crate) begin_node: &'a [u32],
    pub(crate) node_vertex: &'a [u32],
    pub(crate) node_arcs: &'a [u32],
    pub(crate) arc_target: &'a [u32],
    pub(crate) arc_res: &'a [u32],
    /// First LoD of each strip's band.
    pub(crate) strip_birth: &'a [u32],
}

impl Records {
    /// Packs `wide` (valid, as the construction makes it) into records.
    pub(crate) fn pack(wide: &Wide<'_>) -> Records {
        use super::{END, NODE_MASK, RESTART};
        let nodes = wide.node_vertex.len();
        // A node's first record: one per arc, one for a node without arcs.
        let mut first = Vec::with_capacity(nodes + 1);
        let mut r = 0u32;
        for n in 0..nodes {
            first.push(r);
            r += (wide.node_arcs[n + 1] - wide.node_arcs[n]).max(1);
        }
        first.push(r);
        let records = r as usize;
        let mut vertex = vec![0u32; records];
        let mut label = vec![0u32; records];
        let mut code = vec![NO_ARC; records];
        let mut far = Vec::new();
        let strips = wide.strip_nodes.len() - 1;
        for s in 0..strips {
            let birth = wide.strip_birth[s];
            for n in wide.strip_nodes[s] as usize..wide.strip_nodes[s + 1] as usize {
                let r0 = first[n] as usize;
                vertex[r0] = wide.node_vertex[n];
                let arcs = wide.node_arcs[n] as usize..wide.node_arcs[n + 1] as usize;
                for (i, a) in arcs.clone().enumerate() {
                    let r = r0 + i;
                    debug_assert!(wide.arc_res[a] >= birth, "a label before its band");
                    label[r] = wide.arc_res[a].saturating_sub(birth);
                    let t = wide.arc_target[a];
                    let mut c = if t == END {
                        0
                    } else {
                        let target = first[(t & NODE_MASK) as usize];
                        let distance = target - r as u32;
                        if distance >= u32::from(FAR) {
                            far.push((r as u32, target));
                            FAR
                        } else {
                            distance as u8
                        }
                    };
                    if t != END && t & RESTART != 0 {
                        c |= BREAK;
                    }
                    if a + 1 < arcs.end {
                        c |= MORE;
                    }
                    code[r] = c;
                }
            }
        }
        Records {
            strip_records: wide
                .strip_nodes
                .iter()
                .map(|&n| first[n as usize])
                .collect(),
            begin_record: wide
                .begin_node
                .iter()
                .map(|&n| if n == END { END } else { first[n as usize] })
                .collect(),
            vertex: Narrow::new(vertex),
            label: Narrow::new(label),
            code,
            far,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn narrow_picks_the_smallest_width() {
        let n = Narrow::new(vec![0, 65_535]);
        assert_eq!(n.width(), 2);
        assert_eq!((n.get(0), n.get(1)), (0, 65_535));
        let w = Narrow::new(vec![65_536, 1]);
        assert_eq!(w.width(), 4);
        assert_eq!(w.get(0), 65_536);
        assert_eq!(w.bytes(), 8);
    }

    /// One strip of three nodes: node 0 with two arcs (to node 1 until LoD
    /// 4, then a break to node 2), node 1 to the end, node 2 without arcs;
    /// a band born at LoD 2, and node 2 placed 70 records on through
    /// padding nodes so the far table is used.
    #[test]
    fn packing_keeps_targets_labels_and_breaks() {
        use crate::model::{END, RESTART};
        let mut node_vertex = vec![7, 8, 9];
        let mut node_arcs = vec![0, 2, 3, 3];
        let mut arc_target = vec![1, 2 | RESTART, END];
        let mut arc_res = vec![4, 9, 9];
        // Padding nodes 3.. between node 1 and node 2 in record order are
        // simpler to add after: move node 2 to the end.
        let padding = 70;
        node_vertex.truncate(2);
        node_arcs.truncate(3);
        for i in 0..padding {
            node_vertex.push(100 + i);
            arc_target.push(END);
            arc_res.push(9);
            node_arcs.push(arc_target.len() as u32);
        }
        node_vertex.push(9);
        node_arcs.push(arc_target.len() as u32);
        let last = node_vertex.len() as u32 - 1;
        arc_target[1] = last | RESTART;
        let wide = Wide {
            strip_nodes: &[0, node_vertex.len() as u32],
            begin_node: &[0],
            node_vertex: &node_vertex,
            node_arcs: &node_arcs,
            arc_target: &arc_target,
            arc_res: &arc_res,
            strip_birth: &[2],
        };
        let r = Records::pack(&wide);
        // Records: node 0 (2), node 1 (1), padding (70), node 2 (1).
        assert_eq!(r.code.len(), 74);
        assert_eq!(r.vertex.get(0), 7);
        assert_eq!(r.vertex.get(2), 8);
        assert_eq!(r.vertex.get(73), 9);
        assert_eq!(r.code[0], 2 | MORE, "node 0's first arc: 2 records on");
        assert_eq!(r.code[1], FAR | BREAK);
        assert_eq!(r.far, vec![(1, 73)]);
        assert_eq!(r.code[2], 0, "node 1 ends the strip");
        assert_eq!(r.code[73], NO_ARC);
        assert_eq!(
            (r.label.get(0), r.label.get(1)),
            (2, 7),
            "labels relative to LoD 2"
        );
        assert_eq!(r.strip_records, vec![0, 74]);
        assert_eq!(r.begin_record, vec![0]);
    }
}
