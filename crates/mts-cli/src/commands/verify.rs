//! `mts verify`: check a model against the replay oracle.

use crate::args::*;
use crate::stdout::outln;
use anyhow::{bail, Result};
use clap::Args;
use serde_json::json;
use std::time::Instant;

#[derive(Args)]
pub struct VerifyArgs {
    #[command(flatten)]
    pub source: MeshSource,
    /// `all`, or a number of LoDs (at least 1) spread evenly from 0 to the
    /// last; a number above the model's LoD count checks them all.
    #[arg(long, default_value = "all", allow_negative_numbers = true)]
    pub lods: String,
    /// Print JSON instead of a sentence.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &VerifyArgs) -> Result<()> {
    let (name, model) = args.source.model()?;
    let n = match args.lods.as_str() {
        "all" => None,
        text => {
            let n: u128 = text.trim().parse().map_err(|_| {
                anyhow::anyhow!("--lods takes `all` or a whole number of at least 1, not `{text}`")
            })?;
            if n == 0 {
                bail!("--lods 0 checks nothing: give `all` or at least 1");
            }
            // More than the model has is all of them.
            let all = model.max_lod() as u128 + 1;
            (n < all).then_some(n as usize)
        }
    };
    let lods = mts::model::spread_lods(model.max_lod(), n);
    let t = Instant::now();
    let report = mts::model::verify(&model, &model.mesh(), &lods);
    let secs = t.elapsed().as_secs_f64();
    if args.json {
        outln!(
            "{}",
            json!({
                "input": name,
                "lods_checked": report.lods_checked,
                "mismatches": report.mismatches,
                "first_mismatch": report.first_mismatch.as_ref().map(|(l, what)| json!({"lod": l, "what": what})),
                "seconds": secs,
            })
        )?;
    } else {
        outln!(
            "{name}: {} LoDs checked against the replay oracle and from-scratch extraction in {secs:.2} s, {} mismatches",
            report.lods_checked, report.mismatches
        )?;
        if let Some((lod, what)) = &report.first_mismatch {
            outln!("  first at LoD {lod}: {what}")?;
        }
    }
    if let Some((lod, what)) = &report.first_mismatch {
        bail!(
            "{name}: the model breaks the invariant: {} of {} LoDs mismatch, the first at LoD {lod}: {what}",
            report.mismatches,
            report.lods_checked
        );
    }
    Ok(())
}
