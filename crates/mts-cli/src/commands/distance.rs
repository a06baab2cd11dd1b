//! `mts distance`: Hausdorff and RMS distance of a mesh to a reference.

use crate::args::*;
use crate::stdout::outln;
use anyhow::{Context, Result};
use clap::Args;
use mts::mesh::io::{load, LoadOptions};
use serde_json::json;
use std::path::PathBuf;

#[derive(Args)]
pub struct DistanceArgs {
    /// The reference mesh (errors are relative to its bounding-box diagonal).
    pub reference: PathBuf,
    /// The mesh measured against it.
    pub other: PathBuf,
    /// Surface samples per side.
    #[arg(long, default_value_t = mts::distance::DEFAULT_SAMPLES, value_parser = count_in::<1, MAX_SAMPLES>, allow_negative_numbers = true)]
    pub samples: usize,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &DistanceArgs) -> Result<()> {
    let options = LoadOptions::default();
    let (a, _) = load(&args.reference, options).context("cannot load the reference")?;
    let (b, _) = load(&args.other, options).context("cannot load the measured mesh")?;
    let d = mts::distance::surface_distance((&a).into(), (&b).into(), args.samples);
    if args.json {
        let v = json!({
            "reference_triangles": a.triangle_count(),
            "triangles": b.triangle_count(),
            "hausdorff": d.hausdorff,
            "rms": d.rms,
            "forward": d.forward,
            "backward": d.backward,
        });
        outln!("{v}")?;
    } else {
        outln!(
            "Hausdorff {:.6}  RMS {:.6}  (relative to the reference's diagonal; \
             reference -> other {:.6}, other -> reference {:.6})",
            d.hausdorff,
            d.rms,
            d.forward,
            d.backward
        )?;
    }
    Ok(())
}
