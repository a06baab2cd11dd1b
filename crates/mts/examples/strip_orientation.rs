//! Issue 34, item 1's "strips laid along the contraction sequence", its
//! cheapest form: the same LoD-0 strips, each run turned so that its end
//! that dies first (in the contraction sequence) is its last window. A
//! strip's dead windows at its end are trimmed for free, inside it they
//! stay as repeats; so a run whose first triangle dies before its last is
//! reversed (only runs of an even index count: reversing those keeps every
//! triangle's winding; an odd one would need an extra index). Prints the
//! single-band model's indices per triangle (what the strips send over the
//! triangles drawn) at each share, for the strips as stripified and as
//! turned, and how many runs were turned. Then step 0e: the stripifier
//! itself laying strips along the sequence (`stripify_along`: a
//! candidate's score gains the difference of its death LoD from the
//! current triangle's), as a tie-break and as a cost.
//!
//! `cargo run --release -p mts --example strip_orientation -- MESH [SHARE...]`
//! (shares in percent; default 100 75 50 25 10 5 1).

use mts::mesh::io::{load, LoadOptions};
use mts::model::{build, BuildOptions};
use mts::simplify::Collapses;
use mts::strip::Strips;
use mts::{stripify, Extractor, SimplifyOptions, StripifyOptions};
use std::path::Path;

/// The first LoD at which triangle `t` has two corners on one vertex.
fn death(collapses: &Collapses, t: [u32; 3]) -> usize {
    let dead = |lod: usize| {
        let [a, b, c] = t.map(|v| collapses.representative(v, lod));
        a == b || b == c || a == c
    };
    let (mut lo, mut hi) = (0, collapses.max_lod() + 1);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if dead(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo
}

/// Indices per triangle the single-band model of `strips` sends at `lod`.
fn sent_per_triangle(model: &mts::MtsModel, ex: &mut Extractor, lod: usize) -> f64 {
    ex.set_lod(lod);
    let mut compact = Vec::new();
    ex.write_compact(&mut compact);
    compact.len() as f64 / model.triangle_count(lod).max(1) as f64
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .ok_or("usage: strip_orientation MESH [SHARE...]")?;
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
    let mut runs: Vec<Vec<u32>> = Vec::new();
    let (mut turned, mut odd_kept) = (0usize, 0usize);
    for run in strips.runs() {
        let first = death(&collapses, [run[0], run[1], run[2]]);
        let n = run.len();
        let last = death(&collapses, [run[n - 3], run[n - 2], run[n - 1]]);
        if first < last && n % 2 == 0 {
            runs.push(run.iter().rev().copied().collect());
            turned += 1;
        } else {
            if first < last {
                odd_kept += 1;
            }
            runs.push(run.to_vec());
        }
    }
    let turned_strips = Strips::from_runs(runs.iter().map(Vec::as_slice), strips.vertex_count())?;
    assert_eq!(
        mts::strip::sorted_canonical(&turned_strips.triangles()),
        mts::strip::sorted_canonical(&strips.triangles()),
        "turning keeps every triangle and its winding"
    );
    println!(
        "{path}: {} runs, {turned} turned (their first triangle dies before their last), {odd_kept} \
         more would be but have an odd index count",
        strips.run_count()
    );
    // Step 0e: strips laid along the sequence by the stripifier itself
    // (`stripify_along`), the death term as a tie-break (0.49) and as a
    // real cost (2, 8).
    let deaths: Vec<u32> = mesh
        .triangles
        .iter()
        .map(|&t| death(&collapses, t) as u32)
        .collect();
    // The death term acts in the local pass; the global (patch) pass is
    // left out of these variants so that it reaches every triangle, and
    // the local pass alone is their baseline.
    let local = StripifyOptions {
        patches: false,
        ..StripifyOptions::default()
    };
    let mut variants = vec![
        ("as stripified", strips.clone()),
        ("turned", turned_strips),
        ("local pass only", stripify(&mesh, &local)),
    ];
    for weight in [0.49f32, 2.0, 8.0] {
        let along = mts::strip::stripify_along(&mesh, &local, &deaths, weight);
        assert_eq!(
            mts::strip::sorted_canonical(&along.triangles()),
            mts::strip::sorted_canonical(&strips.triangles())
        );
        variants.push((
            match weight {
                w if w < 1.0 => "along, tie-break",
                w if w < 4.0 => "along, weight 2",
                _ => "along, weight 8",
            },
            along,
        ));
    }
    let options = BuildOptions {
        band_slack: f64::INFINITY,
        ..BuildOptions::default()
    };
    let models: Vec<_> = variants
        .iter()
        .map(|(_, s)| build(&mesh, s, &collapses, &options))
        .collect();
    let mut extractors: Vec<_> = models.iter().map(Extractor::new).collect();
    println!(
        "share: indices per triangle, single band: {}",
        variants
            .iter()
            .map(|(n, _)| *n)
            .collect::<Vec<_>>()
            .join(" | ")
    );
    for share in shares {
        let lod = models[0].lod_for_ratio(share / 100.0);
        let row: Vec<String> = models
            .iter()
            .zip(&mut extractors)
            .map(|(m, ex)| format!("{:.3}", sent_per_triangle(m, ex, lod)))
            .collect();
        println!("  {share:>5}%: {}", row.join(" | "));
    }
    Ok(())
}
