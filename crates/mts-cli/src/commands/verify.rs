//! `mts verify`: check a model against the replay oracle; a hierarchy's
//! file (version 4): its structure, every group's model, and cuts from a
//! sweep of cameras without a crack.

use crate::args::*;
use crate::stdout::outln;
use anyhow::{bail, Result};
use clap::Args;
use serde_json::json;
use std::path::Path;
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
    if let Some(path) = &args.source.mesh {
        if peek_holds(path) == Some(mts::model::format::Holds::Hierarchy) {
            return verify_hierarchy(args, path);
        }
    }
    let (name, model) = args.source.model()?;
    let requested = requested_lods(&args.lods)?;
    let lods = spread(model.max_lod(), requested);
    let t = Instant::now();
    let report = mts::model::verify(&model, &model.mesh(), &lods);
    // A version-6 file's chunks, each against the whole model at the LoDs
    // it holds.
    let mut chunk_problem = None;
    let mut chunks_checked = 0;
    if let Some(path) = &args.source.mesh {
        let bytes = mts::mesh::io::read_file(path)?;
        for chunk in mts::MtsModel::prefixes_of(&bytes, path)? {
            chunks_checked += 1;
            if let Err(e) = chunk.check_against(&model, &lods) {
                chunk_problem.get_or_insert(e);
            }
        }
    }
    let secs = t.elapsed().as_secs_f64();
    if args.json {
        outln!(
            "{}",
            json!({
                "input": name,
                "lods_checked": report.lods_checked,
                "mismatches": report.mismatches,
                "first_mismatch": report.first_mismatch.as_ref().map(|(l, what)| json!({"lod": l, "what": what})),
                "prefixes_checked": chunks_checked,
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
    if chunks_checked > 0 && !args.json {
        outln!(
            "  {chunks_checked} coarse chunks checked against the model: {}",
            chunk_problem.as_deref().unwrap_or("the same triangles")
        )?;
    }
    if let Some(problem) = chunk_problem {
        bail!("{name}: a coarse chunk does not draw the model's triangles: {problem}");
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

/// `--lods`: `None` for `all`, else the number asked for (at least 1).
fn requested_lods(text: &str) -> Result<Option<u128>> {
    if text == "all" {
        return Ok(None);
    }
    let n: u128 = text.trim().parse().map_err(|_| {
        anyhow::anyhow!("--lods takes `all` or a whole number of at least 1, not `{text}`")
    })?;
    if n == 0 {
        bail!("--lods 0 checks nothing: give `all` or at least 1");
    }
    Ok(Some(n))
}

/// The LoDs of a model of `max_lod` to check: `requested` spread evenly,
/// all of them when it asks for as many or more.
fn spread(max_lod: usize, requested: Option<u128>) -> Vec<usize> {
    let all = max_lod as u128 + 1;
    let n = requested.and_then(|n| (n < all).then_some(n as usize));
    mts::model::spread_lods(max_lod, n)
}

/// What the header of the file at `path` says it holds; `None` for
/// anything but a regular file with an `.mts` header (those take the
/// model's path, which names what is wrong). Reads 12 bytes.
pub fn peek_holds(path: &Path) -> Option<mts::model::format::Holds> {
    use std::io::Read;
    // Checked before opening: opening a FIFO blocks until a writer comes.
    if !std::fs::metadata(path).ok()?.is_file() {
        return None;
    }
    let file = std::fs::File::open(path).ok()?;
    if !file.metadata().ok()?.is_file() {
        return None;
    }
    let mut head = Vec::with_capacity(12);
    file.take(12).read_to_end(&mut head).ok()?;
    mts::model::format::holds(&head)
}

/// The pixel thresholds of the camera sweep.
const THRESHOLDS: [f32; 3] = [0.5, 2.0, 8.0];

/// Six eyes around and above the bounds of `positions`: one off each face
/// of the box, tilted towards the next axis, at 1.3 times the bounding
/// sphere's radius from its centre (near enough that a cut mixes levels).
fn eyes(positions: &[glam::Vec3]) -> Vec<glam::Vec3> {
    use glam::Vec3;
    let (lo, hi) = mts::mesh::bounds_of(positions).unwrap_or_default();
    let centre = 0.5 * (lo + hi);
    let radius = (0.5 * lo.distance(hi)).max(1e-6);
    let axes = [Vec3::X, Vec3::Y, Vec3::Z];
    let mut out = Vec::new();
    for i in 0..3 {
        for sign in [1.0f32, -1.0] {
            let dir = sign * axes[i] + 0.35 * axes[(i + 1) % 3] + 0.2 * axes[(i + 2) % 3];
            out.push(centre + 1.3 * radius * dir.normalize());
        }
    }
    out
}

/// `verify` on a version-4 file: [`mts::hierarchy::Hierarchy::validate`],
/// every group's model against its replay at the LoDs `--lods` asks for,
/// and the cuts of a sweep of cameras ([`eyes`] × [`THRESHOLDS`]) checked
/// for cracks ([`mts::hierarchy::cracks`]) and against their triangle
/// counts.
fn verify_hierarchy(args: &VerifyArgs, path: &Path) -> Result<()> {
    use mts::hierarchy::{self, Hierarchy};
    let name = path.display().to_string();
    let h = Hierarchy::load(path)?;
    let requested = requested_lods(&args.lods)?;
    let t = Instant::now();
    if let Err(e) = h.validate() {
        bail!("{name}: {e}");
    }
    // Every group's model, on all cores.
    let reports: Vec<(usize, mts::model::VerifyReport)> = h
        .verify_groups(|max_lod| spread(max_lod, requested))
        .into_iter()
        .enumerate()
        .collect();
    let lods_checked: usize = reports.iter().map(|(_, r)| r.lods_checked).sum();
    let mismatches: usize = reports.iter().map(|(_, r)| r.mismatches).sum();
    let first_mismatch = reports.iter().find_map(|(g, r)| {
        r.first_mismatch
            .as_ref()
            .map(|(lod, what)| (*g, *lod, what.clone()))
    });
    // The camera sweep.
    let projection = mts::Projection::Perspective {
        fov_y: 60f32.to_radians(),
        viewport_height: 1080.0,
    };
    let (mut cuts, mut cracks, mut miscounted) = (0usize, 0usize, 0usize);
    let (mut fewest, mut most) = (usize::MAX, 0usize);
    let mut first_crack = None;
    for eye in eyes(h.positions()) {
        for px in THRESHOLDS {
            let cut = hierarchy::select(&h, &projection, eye, px);
            let drawn = cut.triangles(&h);
            miscounted += usize::from(drawn.len() != cut.triangle_count(&h));
            let found = hierarchy::cracks(&h, &drawn);
            if found > 0 && first_crack.is_none() {
                first_crack = Some((eye, px, found));
            }
            cracks += found;
            fewest = fewest.min(drawn.len());
            most = most.max(drawn.len());
            cuts += 1;
        }
    }
    let secs = t.elapsed().as_secs_f64();
    if args.json {
        outln!(
            "{}",
            json!({
                "input": name,
                "kind": "hierarchy",
                "groups_checked": reports.len(),
                "lods_checked": lods_checked,
                "mismatches": mismatches,
                "first_mismatch": first_mismatch.as_ref().map(|(g, l, what)| json!({"group": g, "lod": l, "what": what})),
                "cuts": cuts,
                "cut_triangles": [fewest.min(most), most],
                "cracks": cracks,
                "miscounted_cuts": miscounted,
                "seconds": secs,
            })
        )?;
    } else {
        outln!(
            "{name}: a hierarchy of {} groups: {lods_checked} LoDs checked against the replay oracle and from-scratch extraction, {mismatches} mismatches; {cuts} cuts ({} to {} triangles, {} cameras at {:?} px), {cracks} cracks; {secs:.2} s",
            reports.len(),
            fewest.min(most),
            most,
            cuts / THRESHOLDS.len(),
            THRESHOLDS
        )?;
        if let Some((g, lod, what)) = &first_mismatch {
            outln!("  first mismatch in group {g} at LoD {lod}: {what}")?;
        }
    }
    if let Some((g, lod, what)) = &first_mismatch {
        bail!(
            "{name}: group {g}'s model breaks the invariant: {mismatches} of {lods_checked} LoDs mismatch, the first at LoD {lod}: {what}"
        );
    }
    if let Some((eye, px, found)) = first_crack {
        bail!(
            "{name}: {cracks} cracks over {cuts} cuts, the first {found} seen from {eye} at {px} px"
        );
    }
    if miscounted > 0 {
        bail!("{name}: {miscounted} cuts draw other triangle counts than their groups' tables say");
    }
    Ok(())
}
