//! Under load (issue 31, item 10): several threads share one model, each
//! with its own [`Extractor`], and run a long random sequence of LoD
//! requests (linear steps, short and long jumps, band edges, budgets,
//! ratios, repeats, from-scratch walks, clones, fresh extractors). After
//! every request the buffer must equal a fresh extractor's from-scratch
//! walk at that LoD byte for byte, every index that changed must lie in a
//! reported dirty range, and every [`ORACLE_EVERY`] requests the triangles
//! must be the contraction sequence's (the oracle). Models are built and
//! dropped one after another; the live heap (a counting allocator, this
//! binary only, one test so no other test allocates meanwhile) must come
//! back exactly to its level before the extractors once they are dropped,
//! and to its level before the model once the model is dropped.
//!
//! Length: `MTS_SOAK_OPS` requests in all (default [`DEFAULT_OPS`], a few
//! seconds in release), seed `MTS_SOAK_SEED` (default 1). The long run of
//! issue 31:
//! `MTS_SOAK_OPS=1000000 cargo test --release -p mts --test soak -- --nocapture`.

use mts::mesh::generate::Generated;
use mts::model::{build_from_mesh, BuildOptions, PipelineOptions};
use mts::strip::sorted_canonical;
use mts::{Extractor, Mesh, MtsModel, StripifyOptions};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Requests in all when `MTS_SOAK_OPS` is unset: about 5 s in release on
/// two cores (measured: about 25 µs a request with its checks).
const DEFAULT_OPS: usize = 200_000;

/// Threads sharing each model.
const THREADS: usize = 4;

/// Requests between two checks against the oracle (a replay of the
/// contraction sequence over the whole mesh, O(triangles)).
const ORACLE_EVERY: usize = 256;

/// Requests kept to describe a mismatch (the run is deterministic in the
/// seed, so the message and the seed reproduce it).
const HISTORY: usize = 16;

/// Counts the live heap bytes of this binary, and their peak.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(bytes: usize) {
    let now = LIVE.fetch_add(bytes, Ordering::Relaxed) + bytes;
    PEAK.fetch_max(now, Ordering::Relaxed);
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
            grew(new_size);
        }
        p
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn live() -> usize {
    LIVE.load(Ordering::Relaxed)
}

/// Starts a new peak at the current level.
fn reset_peak() {
    PEAK.store(live(), Ordering::Relaxed);
}

/// SplitMix64 (Steele, Lea and Flood, 2014): small, fixed-seed, good
/// enough to pick requests.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`; the modulo bias is irrelevant here).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    /// Uniform in `0..1`.
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn env_usize(name: &str, default: usize) -> usize {
    match std::env::var(name) {
        Ok(v) => v
            .trim()
            .parse()
            .unwrap_or_else(|e| panic!("{name}={v:?} is not a count: {e}")),
        Err(_) => default,
    }
}

/// The models soaked: generated meshes with and without properties, banded
/// and single-band, bands stripified plainly and cache-aware.
fn cases() -> Vec<(&'static str, bool, BuildOptions)> {
    let banded = BuildOptions::default();
    let single = BuildOptions {
        band_slack: f64::INFINITY,
        ..BuildOptions::default()
    };
    let cache_aware = BuildOptions {
        stripify: StripifyOptions {
            cache_aware: true,
            ..banded.stripify
        },
        ..banded.clone()
    };
    vec![
        ("torus:3k", false, banded.clone()),
        ("icosphere:3k", true, banded.clone()),
        ("grid:2k", false, single.clone()),
        ("torus:3k", true, single),
        ("icosphere:4k", false, cache_aware),
        ("torus:12k", false, banded),
    ]
}

/// What one thread's requests found.
#[derive(Debug, Default)]
struct Tally {
    requests: usize,
    mismatches: usize,
    first: Option<String>,
    strips_walked: usize,
    dirty_indices: usize,
    oracle_checks: usize,
}

impl Tally {
    fn fail(&mut self, what: String) {
        self.mismatches += 1;
        if self.first.is_none() {
            self.first = Some(what);
        }
    }

    fn add(&mut self, other: Tally) {
        self.requests += other.requests;
        self.mismatches += other.mismatches;
        self.strips_walked += other.strips_walked;
        self.dirty_indices += other.dirty_indices;
        self.oracle_checks += other.oracle_checks;
        if self.first.is_none() {
            self.first = other.first;
        }
    }
}

/// A request and the LoD it must extract.
#[derive(Debug, Clone, Copy)]
enum Request {
    Lod(usize),
    Scratch(usize),
    Triangles(usize),
    Ratio(f64),
}

/// `requests` random requests on one extractor over `model` (whose input
/// is `mesh`), each checked; see the module docs.
fn soak_thread(model: &MtsModel, mesh: &Mesh, seed: u64, requests: usize) -> Tally {
    let mut rng = Rng(seed);
    let max = model.max_lod();
    let full = model.triangle_count(0);
    let mut ex = Extractor::new(model);
    let mut shadow = ex.buffer().to_vec();
    let (mut compact, mut want_compact) = (Vec::new(), Vec::new());
    let mut history: Vec<Request> = Vec::with_capacity(HISTORY);
    let mut tally = Tally::default();
    let mut direction: isize = 1;
    for op in 0..requests {
        let at = ex.lod();
        let current = at.unwrap_or(0);
        let roll = rng.below(100);
        // Extractor-level events first: they keep or drop its state.
        match roll {
            0..=1 => {
                ex = Extractor::new(model);
                shadow.copy_from_slice(ex.buffer());
                history.clear();
            }
            2..=4 => ex = ex.clone(),
            _ => {}
        }
        let at = if roll <= 1 { None } else { at };
        let request = match roll {
            5..=44 => {
                // A linear sweep: a few LoDs on, bouncing at the ends.
                let step = 1 + rng.below(3) as isize;
                let next = current as isize + direction * step;
                if next < 0 || next > max as isize {
                    direction = -direction;
                }
                Request::Lod(next.clamp(0, max as isize) as usize)
            }
            45..=59 => {
                // A jump within a quarter of the band (the segment path).
                let band = model.band_of(current);
                let first = model.band_first_lod(band);
                let last = if band + 1 < model.band_count() {
                    model.band_first_lod(band + 1) - 1
                } else {
                    max
                };
                let reach = ((last - first) / 4).max(1);
                let lo = current.saturating_sub(reach).max(first);
                let hi = (current + reach).min(last);
                Request::Lod(lo + rng.below(hi - lo + 1))
            }
            60..=74 => Request::Lod(rng.below(max + 6)),
            75..=79 => {
                // A band's first LoD or the one before it.
                let b = rng.below(model.band_count());
                let first = model.band_first_lod(b);
                Request::Lod(if rng.below(2) == 0 {
                    first
                } else {
                    first.saturating_sub(1)
                })
            }
            80..=84 => Request::Triangles(rng.below(full + 10)),
            85..=88 => Request::Ratio(rng.unit() * 1.2 - 0.1),
            89..=93 => Request::Lod(current),
            94..=96 => Request::Scratch(rng.below(max + 1)),
            _ => Request::Lod([0, max, usize::MAX][rng.below(3)]),
        };
        let want = match request {
            Request::Lod(l) | Request::Scratch(l) => l.min(max),
            Request::Triangles(b) => model.lod_for_triangles(b),
            Request::Ratio(r) => model.lod_for_ratio(r),
        };
        let update = match request {
            Request::Lod(l) => ex.set_lod(l),
            Request::Scratch(l) => ex.set_lod_from_scratch(l),
            Request::Triangles(b) => ex.set_triangles(b),
            Request::Ratio(r) => ex.set_ratio(r),
        };
        if history.len() == HISTORY {
            history.remove(0);
        }
        history.push(request);
        tally.requests += 1;
        tally.strips_walked += update.strips_walked;
        let place = || format!("seed {seed}, request {op}, LoD {want}; last requests {history:?}");

        let mut fresh = Extractor::new(model);
        fresh.set_lod_from_scratch(want);
        if ex.buffer() != fresh.buffer() {
            let i = (0..ex.buffer().len())
                .find(|&i| ex.buffer()[i] != fresh.buffer()[i])
                .unwrap_or(0);
            tally.fail(format!(
                "buffer differs from a fresh extraction from index {i}: {}",
                place()
            ));
        }
        if update.lod != want || ex.lod() != Some(want) {
            tally.fail(format!("reported LoD {:?}: {}", update.lod, place()));
        }
        if ex.active_range() != fresh.active_range()
            || ex.indices_sent() != fresh.indices_sent()
            || ex.overflows() != 0
        {
            tally.fail(format!("range, count or overflow differ: {}", place()));
        }
        ex.write_compact(&mut compact);
        fresh.write_compact(&mut want_compact);
        if compact != want_compact || compact.len() != ex.indices_sent() {
            tally.fail(format!("compact strips differ: {}", place()));
        }
        // Dirty ranges: ascending, disjoint, non-empty, inside the buffer,
        // as many as reported, and covering every index that changed.
        let dirty = ex.dirty_ranges();
        let well_formed = dirty.iter().all(|r| r.start < r.end)
            && dirty.windows(2).all(|w| w[0].end <= w[1].start)
            && dirty.last().is_none_or(|r| r.end <= shadow.len())
            && update.dirty_ranges == dirty.len();
        if !well_formed {
            tally.fail(format!("malformed dirty ranges {dirty:?}: {}", place()));
        }
        let mut next_range = 0;
        for (i, (a, b)) in shadow.iter().zip(ex.buffer()).enumerate() {
            while next_range < dirty.len() && dirty[next_range].end <= i {
                next_range += 1;
            }
            if a != b && !dirty.get(next_range).is_some_and(|r| r.contains(&i)) {
                tally.fail(format!(
                    "index {i} changed outside the dirty ranges {dirty:?}: {}",
                    place()
                ));
                break;
            }
        }
        tally.dirty_indices += dirty.iter().map(|r| r.len()).sum::<usize>();
        shadow.copy_from_slice(ex.buffer());
        // Asking again for the LoD it holds walks nothing.
        if at == Some(want)
            && matches!(request, Request::Lod(_))
            && (update.strips_walked != 0 || !dirty.is_empty())
        {
            tally.fail(format!("a repeated LoD walked or dirtied: {}", place()));
        }
        if op % ORACLE_EVERY == 0 {
            tally.oracle_checks += 1;
            let oracle = sorted_canonical(&model.collapses().triangles_at(mesh, want));
            if sorted_canonical(&ex.triangles()) != oracle {
                tally.fail(format!("triangles differ from the oracle: {}", place()));
            }
        }
    }
    tally
}

/// The mesh and model of a case of [`cases`], checked for what the case
/// is meant to hold (LoDs, one band or several).
fn build_case(name: &str, properties: bool, build: &BuildOptions) -> (Mesh, MtsModel) {
    let generated: Generated = name.parse().unwrap();
    let mesh = if properties {
        generated.build_with_properties()
    } else {
        generated.build()
    };
    let options = PipelineOptions {
        build: build.clone(),
        ..PipelineOptions::default()
    };
    let (model, _, _) = build_from_mesh(&mesh, &options, &mut |_, _| {});
    model.validate().unwrap();
    assert!(model.max_lod() > 100, "{name}: {} LoDs", model.max_lod());
    if build.band_slack.is_finite() {
        assert!(model.band_count() > 1, "{name}: one band");
    } else {
        assert_eq!(model.band_count(), 1, "{name}");
    }
    (mesh, model)
}

/// [`soak_thread`] on [`THREADS`] threads sharing `model`; seeds from
/// `seed` and the case `c`.
fn soak_model(model: &MtsModel, mesh: &Mesh, seed: u64, c: usize, requests: usize) -> Vec<Tally> {
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..THREADS)
            .map(|t| {
                let seed = seed
                    .wrapping_mul(1_000_003)
                    .wrapping_add((c * THREADS + t) as u64);
                scope.spawn(move || soak_thread(model, mesh, seed, requests))
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    })
}

#[test]
fn extractors_on_several_threads_stay_exact_under_load() {
    let ops = env_usize("MTS_SOAK_OPS", DEFAULT_OPS);
    let seed = env_usize("MTS_SOAK_SEED", 1) as u64;
    let cases = cases();
    let per_thread = ops.div_ceil(cases.len() * THREADS).max(1);
    let started = Instant::now();
    let mut total = Tally::default();
    // Per model: heap before the extractors, peak while they ran, after.
    let mut memory = Vec::with_capacity(cases.len());
    // A short run first: what the standard library and the pipeline keep
    // once set up (thread handles, the test harness's own bookkeeping,
    // which runs beside the test) is in the base, not in a model's count.
    {
        let (name, properties, build) = &cases[0];
        let (mesh, model) = build_case(name, *properties, build);
        soak_model(&model, &mesh, seed, 0, 16);
    }
    let base = live();
    for (c, (name, properties, build)) in cases.iter().enumerate() {
        let (mesh, model) = build_case(name, *properties, build);
        let before = live();
        reset_peak();
        let tallies = soak_model(&model, &mesh, seed, c, per_thread);
        let peak = PEAK.load(Ordering::Relaxed);
        for t in tallies {
            total.add(t);
        }
        // The tallies' messages are the only survivors (none without a
        // mismatch).
        assert!(
            total.mismatches == 0,
            "{name}: {} mismatches; first: {}",
            total.mismatches,
            total.first.as_deref().unwrap_or("")
        );
        let after = live();
        let bands = model.band_count();
        memory.push((*name, *properties, bands, before, peak, after));
        assert_eq!(after, before, "{name}: extractors' heap not returned");
        drop(model);
        drop(mesh);
        assert_eq!(live(), base, "{name}: the model's heap not returned");
    }
    assert_eq!(total.requests, per_thread * THREADS * cases.len());
    assert_eq!(total.mismatches, 0);
    assert_eq!(
        total.oracle_checks,
        per_thread.div_ceil(ORACLE_EVERY) * THREADS * cases.len()
    );
    assert!(
        total.dirty_indices > 0 && total.strips_walked > 0,
        "{total:?}"
    );
    eprintln!(
        "soak: {} requests ({THREADS} threads a model, {} models, seed {seed}), {} mismatches, \
         {} oracle checks, {} strips walked, {} dirty indices, {:.1} s",
        total.requests,
        cases.len(),
        total.mismatches,
        total.oracle_checks,
        total.strips_walked,
        total.dirty_indices,
        started.elapsed().as_secs_f64()
    );
    eprintln!("heap bytes: base {base}; per model: before extractors / peak / after");
    for (name, properties, bands, before, peak, after) in memory {
        let props = if properties { "properties" } else { "plain" };
        eprintln!("  {name:>12} {props:>10} {bands:>3} bands: {before} / {peak} / {after}");
    }
}
