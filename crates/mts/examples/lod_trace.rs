//! Which contractions make the error jump: the Hausdorff distance to the
//! input of every LoD in a triangle range, with the step that made it.
//!
//! The quality table compares one LoD per share; when a row fails, this
//! finds the contraction responsible. Each line gives the LoD, its
//! triangle count, the recorded error (the sequence's running maximum),
//! the measured Hausdorff distance and its two sides (input to LoD,
//! LoD to input), and the step `removed -> kept`; `<<<` marks a LoD whose
//! Hausdorff distance is more than 15% above the previous line's. All
//! distances are relative to the input's bounding-box diagonal.
//!
//! Run with `cargo run --release -p mts --example lod_trace -- MESH FROM TO
//! [EVERY]`, e.g. `… -- ../shared/models/beetle.obj 900 200` (triangle
//! counts; every `EVERY`-th LoD, default 1).

use mts::distance::surface_distance;
use mts::mesh::io::{load, LoadOptions};
use mts::SimplifyOptions;
use std::path::Path;

/// Samples per side for each LoD.
const SAMPLES: usize = 20_000;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: lod_trace MESH FROM_TRIANGLES TO_TRIANGLES [EVERY]";
    let path = args.get(1).ok_or(usage)?;
    let from: usize = args.get(2).ok_or(usage)?.parse()?;
    let to: usize = args.get(3).ok_or(usage)?.parse()?;
    let every: usize = args.get(4).map_or(Ok(1), |s| s.parse())?;
    if from < to || every == 0 {
        return Err(usage.into());
    }
    let (mesh, _) = load(Path::new(path), LoadOptions::default())?;
    let simplification = mts::simplify(&mesh, &SimplifyOptions::default());
    let collapses = simplification.collapses;
    println!("stop: {}", simplification.stop);
    let mut previous = 0.0;
    let first = collapses.lod_for_triangles(from);
    let last = collapses.lod_for_triangles(to);
    for lod in (first..=last).step_by(every) {
        let ours = collapses.mesh_at(&mesh, lod);
        let d = surface_distance((&mesh).into(), (&ours).into(), SAMPLES);
        let step = match lod {
            0 => "input".to_string(),
            _ => {
                let s = collapses.steps()[lod - 1];
                format!("{} -> {}", s.removed, s.kept)
            }
        };
        let jump = if lod > first && d.hausdorff > 1.15 * previous {
            "  <<<"
        } else {
            ""
        };
        println!(
            "lod {lod} triangles {} recorded {:.4} hausdorff {:.4} (input to LoD {:.4}, LoD to input {:.4}) step {step}{jump}",
            ours.triangle_count(),
            collapses.error(lod),
            d.hausdorff,
            d.forward,
            d.backward,
        );
        previous = d.hausdorff;
    }
    Ok(())
}
