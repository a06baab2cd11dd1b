//! Where a decayed strip's extra indices come from, on the paper's
//! single-band model (its LoD-0 strips walked to every share): issue 34's
//! measurement before "strips laid along the contraction sequence"
//! (`docs/experiments/strip-lifetimes.md`, §7.4).
//!
//! A strip of `t` live triangles in `r` runs sends at least `t + 2r`
//! indices plus `r - 1` restarts; what it sends above that is dead
//! windows kept inside runs (a repeat that keeps the parity, or a filler
//! cheaper than a break). So per share this prints indices per triangle
//! split into: 1 (the triangles), the runs' two leading indices, the
//! restarts, and the dead windows inside runs — the part a strip that
//! drops a pair of indices per contraction would remove, where the runs
//! and restarts are not.
//!
//! Then, for the banded model, how concentrated the decay is at each
//! band's last LoD: each strip's excess (its indices now less what its
//! ratio at the band's first LoD would send for its triangles now), and
//! the share of the band's excess that its most-decayed strips hold,
//! against their share of the band's indices at birth (what renewing only
//! them would write again).
//!
//! Then, for the banded model, how concentrated the decay is at each
//! band's last LoD: each strip's excess (its indices now less what its
//! ratio at the band's first LoD would send for its triangles now), and
//! the share of all bands' excess that the most-decayed strips hold,
//! against their share of the indices at birth (what renewing only them
//! would write again).
//!
//! `cargo run --release -p mts --example decay_split -- MESH [SHARE...]`
//! (shares in percent; default 100 75 50 25 10 5 1).

use mts::encoding::is_degenerate;
use mts::mesh::io::{load, LoadOptions};
use mts::model::{build, BuildOptions};
use mts::strip::encode::RESTART_U32;
use mts::{stripify, Extractor, SimplifyOptions, StripifyOptions};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).ok_or("usage: decay_split MESH [SHARE...]")?;
    let mut shares: Vec<f64> = args[2..]
        .iter()
        .map(|s| s.parse::<f64>())
        .collect::<Result<_, _>>()?;
    if shares.is_empty() {
        shares = vec![100.0, 75.0, 50.0, 25.0, 10.0, 5.0, 1.0];
    }
    let (mesh, _) = load(Path::new(path), LoadOptions::default())?;
    let strips = stripify(&mesh, &StripifyOptions::default());
    let collapses = mts::simplify(&mesh, &SimplifyOptions::default()).collapses;
    for (name, slack) in [("single band", f64::INFINITY), ("bands 0.1", 0.1)] {
        let options = BuildOptions {
            band_slack: slack,
            ..BuildOptions::default()
        };
        let model = build(&mesh, &strips, &collapses, &options);
        let mut ex = Extractor::new(&model);
        println!(
            "{path}, {name} ({} bands): indices per triangle = 1 + leading + restarts + dead windows",
            model.band_count()
        );
        for &share in &shares {
            let lod = model.lod_for_ratio(share / 100.0);
            ex.set_lod(lod);
            let (mut live, mut dead, mut runs, mut sent) = (0usize, 0usize, 0usize, 0usize);
            let band = model.band_strips(model.band_of(lod));
            for s in band {
                let strip = ex.strip(s);
                for run in strip.split(|&v| v == RESTART_U32).filter(|r| !r.is_empty()) {
                    runs += 1;
                    sent += run.len();
                    for w in run.windows(3) {
                        if is_degenerate([w[0], w[1], w[2]]) {
                            dead += 1;
                        } else {
                            live += 1;
                        }
                    }
                }
            }
            let restarts = runs.saturating_sub(1);
            let t = live.max(1) as f64;
            println!(
                "  {share:>5}%: {live:>7} triangles, {:.3} indices each = 1 + {:.3} leading + {:.3} restarts + {:.3} dead windows ({} runs, {} dead)",
                (sent + restarts) as f64 / t,
                (sent - live - dead) as f64 / t,
                restarts as f64 / t,
                dead as f64 / t,
                runs,
                dead
            );
            assert_eq!(
                live,
                model.triangle_count(lod),
                "live windows are the LoD's triangles"
            );
        }
        if model.band_count() > 1 {
            concentration(&model, &mut ex);
        }
    }
    Ok(())
}

/// Indices a strip sends (its runs and the restarts between them) and its
/// live triangles.
fn sent_and_live(strip: &[u32]) -> (usize, usize) {
    let (mut sent, mut live, mut runs) = (0usize, 0usize, 0usize);
    for run in strip.split(|&v| v == RESTART_U32).filter(|r| !r.is_empty()) {
        runs += 1;
        sent += run.len();
        live += run
            .windows(3)
            .filter(|w| !is_degenerate([w[0], w[1], w[2]]))
            .count();
    }
    (sent + runs.saturating_sub(1), live)
}

/// See the module documentation; summed over the bands.
fn concentration(model: &mts::MtsModel, ex: &mut Extractor<'_>) {
    // Over every band but the last: (excess, indices at birth) per strip.
    let mut all: Vec<(f64, usize)> = Vec::new();
    for b in 0..model.band_count() - 1 {
        let (first, last) = (model.band_first_lod(b), model.band_first_lod(b + 1) - 1);
        ex.set_lod_from_scratch(first);
        let birth: Vec<(usize, usize)> = model
            .band_strips(b)
            .map(|s| sent_and_live(ex.strip(s)))
            .collect();
        ex.set_lod_from_scratch(last);
        for (s, &(born_sent, born_live)) in model.band_strips(b).zip(&birth) {
            let (sent, live) = sent_and_live(ex.strip(s));
            let expected = if born_live == 0 {
                0.0
            } else {
                born_sent as f64 * live as f64 / born_live as f64
            };
            all.push(((sent as f64 - expected).max(0.0), born_sent));
        }
    }
    let total_excess: f64 = all.iter().map(|a| a.0).sum();
    let total_born: usize = all.iter().map(|a| a.1).sum();
    // Most decayed first, by excess per index at birth.
    all.sort_by(|a, b| {
        let ka = a.0 / a.1.max(1) as f64;
        let kb = b.0 / b.1.max(1) as f64;
        kb.total_cmp(&ka)
    });
    println!(
        "  at each band's last LoD, over {} bands and {} strips: excess {:.0} indices over {} indices at birth",
        model.band_count() - 1,
        all.len(),
        total_excess,
        total_born
    );
    for share in [0.05, 0.1, 0.25, 0.5] {
        let (mut excess, mut born) = (0.0, 0usize);
        for a in &all {
            if born as f64 >= share * total_born as f64 {
                break;
            }
            excess += a.0;
            born += a.1;
        }
        println!(
            "  the most decayed strips holding {:>3.0}% of the indices at birth hold {:>5.1}% of the excess",
            100.0 * share,
            100.0 * excess / total_excess.max(1.0)
        );
    }
}
