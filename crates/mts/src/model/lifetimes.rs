//! Strips with their own lifetimes (issue 34, item 1), measured before the
//! model, the extractor and the file hold them: the contraction sequence
//! replayed by one builder that renews strips as they decay, counting what
//! such a model would store and send.
//!
//! Three renewals go through the same replay:
//! - **single band** ([`Renewal::Bands`] with an infinite slack): the
//!   paper's model, no strip ever renewed;
//! - **bands** ([`Renewal::Bands`]): today's model. Every strip is retired
//!   and the mesh stripified afresh where the band rule of
//!   [`super::build`] fires (and at every construction segment's start),
//!   so its counts equal the built model's: records, and indices at every
//!   LoD (the tests check both);
//! - **strips** ([`Renewal::Strips`]): per-strip lifetimes. After each
//!   contraction, a strip it changed is *ripe* when it has lost at least
//!   [`super::MIN_BAND_DROP`] of its triangles since its birth and sends
//!   more than `1 + slack` times the indices per triangle it sent then (the
//!   band rule applied to one strip), and at least [`MIN_EXCESS`] indices
//!   more. A ripe strip is retired with its *neighbourhood* and their
//!   triangles stripified afresh; the new strips are born at that LoD.
//!
//! **Decision: the renewal unit is a neighbourhood, not the strip.** A
//! strip's live windows are a ribbon folded by its contractions:
//! stripifying the ribbon alone only removes its repeats, while strips laid
//! afresh over a patch turn across the old strips' seams. The neighbourhood
//! is the ripe strip, then breadth first the alive strips sharing a vertex
//! with it that have decayed at least half the slack, and any others while
//! the unit holds fewer than `min_triangles`; it stops growing at
//! `max_triangles`.
//!
//! What a per-strip model stores (the layout of
//! `docs/experiments/strip-lifetimes.md`, section 2): one record per arc
//! (or per node without arcs), the vertex and label narrow where they fit
//! (labels relative to the strip's birth), a code byte; per strip its
//! first record, its first beginning, its slot size, birth and death; per
//! beginning a node and a label. [`RenewalMeasure::memory_bytes`] counts
//! that for every renewal alike, so the three are compared on one layout.

use super::build::{effective_options, BuildOptions, Builder, Context, MIN_BAND_DROP};
use crate::mesh::Mesh;
use crate::simplify::Collapses;
use crate::strip::{stripify, Strips};

/// Fewest indices above its birth ratio a strip must send to be ripe: a
/// renewal costs a restart and a slot, so a short strip one index over is
/// left alone.
pub const MIN_EXCESS: f64 = 4.0;

/// How strips are renewed as the LoD coarsens.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Renewal {
    /// Every strip at once, where the band rule fires (today's model; an
    /// infinite slack is the paper's single band).
    Bands,
    /// A ripe strip and its neighbourhood (module documentation).
    Strips {
        /// The unit grows through any neighbour below this many triangles.
        min_triangles: u32,
        /// ... and stops growing at this many.
        max_triangles: u32,
    },
}

/// What one replay counted.
#[derive(Debug, Clone, PartialEq)]
pub struct RenewalMeasure {
    /// Strips ever born (LoD 0's included).
    pub strips: usize,
    /// Renewal events (a band start, or one neighbourhood renewed).
    pub renewals: usize,
    /// Triangles stripified by renewals (LoD 0's strips not counted), and
    /// the indices their strips sent at birth (emitted positions and run
    /// breaks, no separators): how well renewals strip.
    pub renewed_triangles: usize,
    pub renewed_indices: usize,
    /// Records the model would store (one per arc, one per node without
    /// arcs).
    pub records: usize,
    /// Strip beginnings (each strip's list; no padding outside its life).
    pub begins: usize,
    /// The largest label relative to its strip's birth.
    pub label_span: u32,
    /// The model's bytes in the per-strip layout (module documentation):
    /// records, per-strip and per-beginning tables, positions; the vertex
    /// properties are not counted.
    pub memory_bytes: usize,
    /// Indices the drawn strips send (compact, restart-separated) at each
    /// LoD asked for, and the triangles drawn there.
    pub indices: Vec<usize>,
    pub triangles: Vec<usize>,
}

/// Replays `collapses` over `strips` (the strips of `mesh`'s LoD 0) with
/// `renewal` and `options` (the slack and the stripifier of renewals, as
/// [`super::build`] takes them), counting the model and the indices sent
/// at each of `lods` (any order).
///
/// # Panics
/// As [`super::build`].
#[must_use]
pub fn measure_renewal(
    mesh: &Mesh,
    strips: &Strips,
    collapses: &Collapses,
    options: &BuildOptions,
    renewal: Renewal,
    lods: &[usize],
) -> RenewalMeasure {
    let counts = collapses.triangle_counts();
    let mut sample_at: Vec<(usize, usize)> = lods
        .iter()
        .enumerate()
        .map(|(i, &l)| (l.min(collapses.max_lod()), i))
        .collect();
    sample_at.sort_unstable();
    let mut indices = vec![0; lods.len()];
    let mut triangles = vec![0; lods.len()];
    let mut next_sample = 0;
    let mut sample = |lod: usize, builder: &Builder| {
        while next_sample < sample_at.len() && sample_at[next_sample].0 == lod {
            indices[sample_at[next_sample].1] = builder.indices();
            triangles[sample_at[next_sample].1] = counts[lod] as usize;
            next_sample += 1;
        }
    };
    let options = effective_options(options);
    let ctx = Context::new(mesh, strips, collapses, &options);
    let replay = run(&ctx, strips, renewal, &mut |lod, builder| {
        sample(lod as usize, builder)
    });
    let (records, label_span) = replay.builder.record_count(&replay.birth, ctx.max_lod);
    let strip_count = replay.builder.strip_count();
    let ctx = replay.ctx;
    let begins = replay.builder.begin_count();
    let narrow = |wide: bool| if wide { 4 } else { 2 };
    let memory_bytes = records
        * (narrow(ctx.positions.len() > 1 << 16) + narrow(label_span > u32::from(u16::MAX)) + 1)
        + 4 * (2 * (strip_count + 1) + 3 * strip_count + 2 * begins)
        + 12 * ctx.positions.len();
    RenewalMeasure {
        strips: strip_count,
        renewals: replay.renewals,
        renewed_triangles: replay.renewed_triangles,
        renewed_indices: replay.renewed_indices,
        records,
        begins,
        label_span,
        memory_bytes,
        indices,
        triangles,
    }
}

/// The replay of `ctx`'s sequence from `strips` with `renewal`, calling
/// `observe(lod, builder)` at every LoD once its renewals are done.
fn run<'a>(
    ctx: &'a Context<'a>,
    strips: &Strips,
    renewal: Renewal,
    observe: &mut dyn FnMut(u32, &Builder),
) -> Replay<'a> {
    assert_eq!(strips.vertex_count() as usize, ctx.base.vertex_count());
    assert_eq!(ctx.collapses.vertex_count(), ctx.base.vertex_count());
    let counts = ctx.collapses.triangle_counts();
    let mut replay = Replay {
        builder: Builder::new(strips, ctx.positions.len(), 0),
        ctx,
        birth: Vec::new(),
        birth_ratio: Vec::new(),
        birth_live: Vec::new(),
        alive: Vec::new(),
        renewals: 0,
        renewed_triangles: 0,
        renewed_indices: 0,
        remap: vec![u32::MAX; ctx.positions.len()],
        unit: Vec::new(),
        scratch: Vec::new(),
    };
    replay.born(0);
    observe(0, &replay.builder);
    // Bands: the band's rule, from its first LoD.
    let starts = ctx.segment_starts();
    // The indices per triangle a band may send, and the triangles it must
    // have lost, before it ends.
    let band = |builder: &Builder, first: u32| {
        let start = counts[first as usize];
        (
            (1.0 + ctx.slack) * builder.indices() as f64 / f64::from(start.max(1)),
            (f64::from(start) * (1.0 - MIN_BAND_DROP)) as u32,
        )
    };
    let (mut band_limit, mut band_min_drop) = band(&replay.builder, 0);
    let mut moved = Vec::with_capacity(2);
    let mut changed = Vec::new();
    for k in 1..=ctx.max_lod {
        // A construction segment's first LoD starts a band without
        // replaying its contraction on the band before (`build.rs`).
        let segment_starts = renewal == Renewal::Bands && starts.binary_search(&k).is_ok();
        if segment_starts {
            replay.retire_all(k);
        }
        moved.clear();
        moved.extend(ctx.collapses.moves(k as usize - 1));
        replay.builder.contract(k, &moved);
        match renewal {
            Renewal::Bands => {
                let now = counts[k as usize];
                let band_ends = now <= band_min_drop
                    && replay.builder.indices() as f64 > band_limit * f64::from(now);
                if band_ends || segment_starts {
                    replay.renew_all(k);
                    (band_limit, band_min_drop) = band(&replay.builder, k);
                }
            }
            Renewal::Strips {
                min_triangles,
                max_triangles,
            } => {
                changed.clear();
                replay.builder.touched_strips(&mut changed);
                changed.sort_unstable();
                changed.dedup();
                for &s in &changed {
                    let s = s as usize;
                    if replay.alive[s] && replay.ripe(s) {
                        replay.renew_around(s, k, min_triangles, max_triangles);
                    }
                }
            }
        }
        observe(k, &replay.builder);
    }
    replay
}

/// The replay's state beside the builder's.
struct Replay<'a> {
    builder: Builder,
    ctx: &'a Context<'a>,
    /// Per strip: its birth LoD, indices per triangle then, triangles
    /// then, and whether it is alive.
    birth: Vec<u32>,
    birth_ratio: Vec<f64>,
    birth_live: Vec<u32>,
    alive: Vec<bool>,
    renewals: usize,
    renewed_triangles: usize,
    renewed_indices: usize,
    /// Scratch: vertex → local index (`u32::MAX` between uses), the unit's
    /// strips, strips met at a vertex.
    remap: Vec<u32>,
    unit: Vec<u32>,
    scratch: Vec<u32>,
}

impl Replay<'_> {
    /// Records the strips the builder holds beyond those known, born at
    /// `lod`.
    fn born(&mut self, lod: u32) {
        for s in self.birth.len()..self.builder.strip_count() {
            let (indices, live) = self.builder.strip_state(s);
            if lod > 0 {
                self.renewed_indices += indices as usize;
            }
            self.birth.push(lod);
            self.birth_ratio
                .push(f64::from(indices) / f64::from(live.max(1)));
            self.birth_live.push(live);
            self.alive.push(self.builder.strip_drawn(s));
        }
    }

    /// How far strip `s` sends above its birth ratio: `(excess indices,
    /// excess / indices at the birth ratio)`.
    fn excess(&self, s: usize) -> (f64, f64) {
        let (indices, live) = self.builder.strip_state(s);
        let fresh = self.birth_ratio[s] * f64::from(live);
        let excess = f64::from(indices) - fresh;
        (excess, excess / fresh.max(1.0))
    }

    fn ripe(&mut self, s: usize) -> bool {
        let (_, live) = self.builder.strip_state(s);
        if live == 0 {
            return true;
        }
        let (excess, ratio) = self.excess(s);
        f64::from(live) <= f64::from(self.birth_live[s]) * (1.0 - MIN_BAND_DROP)
            && ratio > self.ctx.slack
            && excess >= MIN_EXCESS
    }

    /// Every alive strip retired at `lod`.
    fn retire_all(&mut self, lod: u32) {
        for s in 0..self.alive.len() {
            if self.alive[s] {
                self.builder.retire(s, lod);
                self.alive[s] = false;
            }
        }
    }

    /// Every alive strip retired at `lod` and the mesh of `lod` stripified
    /// afresh (a band's start).
    fn renew_all(&mut self, lod: u32) {
        self.retire_all(lod);
        let mesh = Mesh {
            positions: self.ctx.positions.clone(),
            triangles: self
                .ctx
                .collapses
                .triangles_at(&self.ctx.base, lod as usize),
            properties: Default::default(),
        };
        self.renewed_triangles += mesh.triangles.len();
        let strips = stripify(&mesh, &self.ctx.options.stripify);
        for run in strips.runs() {
            self.builder.push_strip(run, lod);
        }
        self.renewals += 1;
        self.born(lod);
    }

    /// Ripe strip `s` and its neighbourhood retired at `lod`, their
    /// triangles stripified afresh.
    fn renew_around(&mut self, s: usize, lod: u32, min_triangles: u32, max_triangles: u32) {
        let (_, live) = self.builder.strip_state(s);
        if live == 0 {
            self.builder.retire(s, lod);
            self.alive[s] = false;
            return;
        }
        self.unit.clear();
        self.unit.push(s as u32);
        self.alive[s] = false;
        let mut held = live;
        let mut triangles = Vec::new();
        let mut i = 0;
        while i < self.unit.len() && held < max_triangles {
            let t = self.unit[i] as usize;
            let from = triangles.len();
            self.builder.strip_triangles(t, &mut triangles);
            for triangle in &triangles[from..] {
                for &v in triangle {
                    self.scratch.clear();
                    self.builder.strips_at_vertex(v, &mut self.scratch);
                    for k in 0..self.scratch.len() {
                        let n = self.scratch[k] as usize;
                        if !self.alive[n] || held >= max_triangles {
                            continue;
                        }
                        let decayed = self.excess(n).1 >= self.ctx.slack / 2.0;
                        if decayed || held < min_triangles {
                            self.alive[n] = false;
                            held += self.builder.strip_state(n).1;
                            self.unit.push(n as u32);
                        }
                    }
                }
            }
            i += 1;
        }
        // The strips added but not yet read.
        for &t in &self.unit[i..] {
            self.builder.strip_triangles(t as usize, &mut triangles);
        }
        for &t in &self.unit {
            self.builder.retire(t as usize, lod);
        }
        self.renewed_triangles += triangles.len();
        let (vertices, local) = crate::mesh::renumber(&triangles, &mut self.remap);
        let mesh = Mesh {
            positions: vertices
                .iter()
                .map(|&v| self.ctx.positions[v as usize])
                .collect(),
            triangles: local,
            properties: Default::default(),
        };
        let strips = stripify(&mesh, &self.ctx.options.stripify);
        let mut run_global = Vec::new();
        for run in strips.runs() {
            run_global.clear();
            run_global.extend(run.iter().map(|&v| vertices[v as usize]));
            self.builder.push_strip(&run_global, lod);
        }
        self.renewals += 1;
        self.born(lod);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::Generated;
    use crate::model::{build, Extractor};
    use crate::strip::{sorted_canonical, StripifyOptions};
    use crate::{simplify, SimplifyOptions};

    fn inputs(name: &str) -> (Mesh, Strips, Collapses) {
        let mesh = name.parse::<Generated>().unwrap().build();
        let strips = stripify(&mesh, &StripifyOptions::default());
        let collapses = simplify(&mesh, &SimplifyOptions::default()).collapses;
        (mesh, strips, collapses)
    }

    /// One builder retiring every strip where a band ends holds what the
    /// built model holds: the same records, and the same indices at every
    /// LoD (so `retire` and `push_strip` keep the builder's counts).
    #[test]
    fn bands_replayed_by_one_builder_count_what_the_built_model_holds() {
        for (name, slack) in [
            ("torus:3k", 0.1),
            ("icosphere:2k", 0.05),
            ("grid:2k", f64::INFINITY),
        ] {
            let (mesh, strips, collapses) = inputs(name);
            let options = BuildOptions {
                band_slack: slack,
                ..BuildOptions::default()
            };
            let lods: Vec<usize> = (0..=collapses.max_lod()).rev().collect();
            let m = measure_renewal(&mesh, &strips, &collapses, &options, Renewal::Bands, &lods);
            let model = build(&mesh, &strips, &collapses, &options);
            assert_eq!(m.records, model.stats().records, "{name}");
            assert_eq!(m.strips, model.strip_count(), "{name}");
            assert_eq!(m.renewals + 1, model.band_count(), "{name}");
            let mut ex = Extractor::new(&model);
            for (&lod, (&sent, &triangles)) in lods.iter().zip(m.indices.iter().zip(&m.triangles)) {
                ex.set_lod(lod);
                assert_eq!(
                    (sent, triangles),
                    (ex.indices_sent(), model.triangle_count(lod)),
                    "{name} LoD {lod}"
                );
            }
        }
    }

    /// Strips renewed in neighbourhoods draw exactly each LoD's triangles,
    /// and the builder's running counts equal a recount, at every LoD.
    #[test]
    fn strips_renewed_in_neighbourhoods_draw_every_lods_triangles() {
        for (name, unit) in [("torus:3k", (0, 64)), ("icosphere:2k", (32, 256))] {
            let (mesh, strips, collapses) = inputs(name);
            let options = effective_options(&BuildOptions {
                band_slack: 0.05,
                ..BuildOptions::default()
            });
            let ctx = Context::new(&mesh, &strips, &collapses, &options);
            let renewal = Renewal::Strips {
                min_triangles: unit.0,
                max_triangles: unit.1,
            };
            let mut checked = 0;
            let replay = run(&ctx, &strips, renewal, &mut |lod, builder| {
                let mut drawn = Vec::new();
                for s in 0..builder.strip_count() {
                    builder.strip_triangles(s, &mut drawn);
                }
                assert_eq!(
                    sorted_canonical(&drawn),
                    sorted_canonical(&collapses.triangles_at(&mesh, lod as usize)),
                    "{name} LoD {lod}"
                );
                let (total, per_strip) = builder.recount();
                assert_eq!(total, builder.indices(), "{name} LoD {lod}");
                for (s, &c) in per_strip.iter().enumerate() {
                    assert_eq!(c, builder.strip_state(s).0, "{name} LoD {lod} strip {s}");
                }
                checked += 1;
            });
            assert_eq!(checked, collapses.max_lod() + 1);
            assert!(
                replay.renewals > 20 && replay.birth.iter().any(|&b| b > 0),
                "{name}: {} renewals",
                replay.renewals
            );
        }
    }
}
