//! `mts build`: build the MTS model (or, with `--hierarchy`, the
//! view-dependent hierarchy) and write it as an `.mts` file.

use crate::args::*;
use crate::stdout::{outln, warnln};
use anyhow::{bail, Result};
use clap::Args;
use mts::mesh::Mesh;
use mts::StripifyOptions;
use serde_json::json;
use std::path::PathBuf;

#[derive(Args)]
pub struct BuildArgs {
    #[command(flatten)]
    pub source: MeshSource,
    /// The .mts file to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Start a new band of strips when they send this much more indices per
    /// triangle than at the band's start (see BuildOptions::band_slack):
    /// 0.1 for a model, 0.5 for each group of a hierarchy
    /// (mts::hierarchy::BAND_SLACK).
    #[arg(allow_negative_numbers = true, long, value_parser = band_slack)]
    pub band_slack: Option<f64>,
    /// One band only: the paper's model, whose strips degrade as the mesh
    /// is simplified.
    #[arg(long, conflicts_with = "band_slack")]
    pub single_band: bool,
    /// Optimal placement in the contraction sequence (new vertices).
    #[arg(long)]
    pub optimal: bool,
    /// Cache-aware strips for LoD 0 and every band (see
    /// StripifyOptions::cache_aware).
    #[arg(long)]
    pub cache_aware: bool,
    /// Write the recipe only (strips, contraction sequence, options; the
    /// file format's version 1 or 2): about a seventh of the ready file,
    /// but loading builds the graphs again (hundreds of milliseconds
    /// instead of a few).
    #[arg(long)]
    pub recipe_only: bool,
    /// Write the ready arrays uncoded (version 3; a hierarchy's version
    /// 4): about three times the bytes of the default coded file (version
    /// 6; a hierarchy's 7), loaded a few milliseconds sooner.
    #[arg(long, conflicts_with = "recipe_only")]
    pub uncompressed: bool,
    /// The Zstandard level of the coded file (1 to 22): 17 by default
    /// (mts::model::compress::DEFAULT_LEVEL); 9 writes about ten times
    /// faster and a fifth larger, 19 about twice as slowly and a few
    /// percent smaller.
    #[arg(long, value_parser = clap::value_parser!(i32).range(1..=22),
          conflicts_with_all = ["recipe_only", "uncompressed"])]
    pub level: Option<i32>,
    /// Where the coded file's coarse chunks are, in percent of the
    /// triangles, comma-separated ("none" for no chunk): a prefix of the
    /// file that holds one opens as the model of the LoDs from there on
    /// (`mts extract --bytes N`). 1,10 by default (about 4% of the file);
    /// each chunk costs about half a raw mesh per share.
    #[arg(long, value_parser = prefix_shares,
          conflicts_with_all = ["recipe_only", "uncompressed", "hierarchy"])]
    pub prefixes: Option<Shares>,
    /// Build the view-dependent hierarchy instead (mts::hierarchy: a DAG
    /// of cluster groups, each a multiresolution strip model over its
    /// locked-border sequence) and write it as a version-4 .mts file, which
    /// `info` and `verify` read. The strip and band options apply to every
    /// group.
    #[arg(long, conflicts_with_all = ["optimal", "recipe_only"])]
    pub hierarchy: bool,
}

impl BuildArgs {
    fn pipeline_options(&self) -> mts::model::PipelineOptions {
        use mts::simplify::{Placement, SimplifyOptions};
        let bands = mts::model::BuildOptions::default().stripify;
        mts::model::PipelineOptions {
            stripify: StripifyOptions {
                cache_aware: self.cache_aware,
                ..StripifyOptions::default()
            },
            simplify: SimplifyOptions {
                placement: if self.optimal {
                    Placement::Optimal
                } else {
                    Placement::Endpoint
                },
                ..SimplifyOptions::default()
            },
            build: mts::model::BuildOptions {
                band_slack: if self.single_band {
                    f64::INFINITY
                } else if self.hierarchy {
                    self.band_slack.unwrap_or(mts::hierarchy::BAND_SLACK)
                } else {
                    self.band_slack.unwrap_or(mts::model::DEFAULT_BAND_SLACK)
                },
                stripify: StripifyOptions {
                    cache_aware: self.cache_aware,
                    ..bands
                },
            },
        }
    }
}

pub fn run(args: &BuildArgs) -> Result<()> {
    args.source.check_output(&args.output)?;
    let started = std::time::Instant::now();
    let (name, mesh, _) = args.source.load()?;
    let load = started.elapsed();
    note_gltf_parts(&args.source)?;
    let options = args.pipeline_options();
    if args.hierarchy {
        return run_hierarchy(args, &name, &mesh, options, load);
    }
    if args.optimal && !mesh.properties.is_empty() {
        bail!(
            "{name}: the MTS model cannot hold the vertices optimal placement creates with \
             properties; drop --optimal, or add --positions-only (`mts simplify --optimal` \
             writes such levels with their properties)"
        );
    }
    let (model, _, t) = build_with_bar(&mesh, &options)?;
    let recipe = model.to_recipe_bytes();
    let coding = std::time::Instant::now();
    let bytes = if args.recipe_only {
        recipe.clone()
    } else if args.uncompressed {
        model.to_bytes()
    } else {
        let shares = args
            .prefixes
            .as_ref()
            .map_or(mts::model::DEFAULT_PREFIX_SHARES.to_vec(), |s| s.0.clone());
        let level = args.level.unwrap_or(mts::model::compress::DEFAULT_LEVEL);
        model.to_streamed_bytes(level, &shares)
    };
    let coding = coding.elapsed();
    mts::output::write_file(&args.output, &bytes)?;
    let version = mts::model::format::file_version(&bytes).unwrap_or(0);
    let chunks = mts::model::chunk_index(&bytes, &args.output)?;
    let st = model.stats();
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    if args.json {
        outln!(
            "{}",
            json!({
                "input": name,
                "vertices": mesh.vertex_count(),
                "triangles": mesh.triangle_count(),
                "max_lod": model.max_lod(),
                "strips": st.strips,
                "bytes": bytes.len(),
                "file_version": version,
                "prefixes": chunk_json(&chunks, &model, bytes.len()),
                "ms_write": ms(coding),
                "recipe_bytes": recipe.len(),
                "raw_bytes": model.raw_bytes(),
                "bands": model.band_count(),
                "nodes": st.nodes,
                "arcs": st.arcs,
                "memory_bytes": st.memory_bytes,
                "ms_load": ms(load),
                "ms_stripify": ms(t.stripify),
                "ms_simplify": ms(t.simplify),
                "ms_model": ms(t.model),
                "ms": ms(t.total),
            })
        )?;
    } else {
        outln!(
            "{name}: {} triangles, {} vertices, {} LoDs",
            mesh.triangle_count(),
            mesh.vertex_count(),
            model.max_lod() + 1
        )?;
        outln!(
            "  time      load {:.1} ms; stripify {:.1} ms beside simplify {:.1} ms, model {:.1} ms, total {:.1} ms",
            ms(load),
            ms(t.stripify),
            ms(t.simplify),
            ms(t.model),
            ms(t.total)
        )?;
        outln!(
            "  model     {} bands, {} strips, {} nodes, {} arcs, {:.1} MB in memory",
            model.band_count(),
            st.strips,
            st.nodes,
            st.arcs,
            st.memory_bytes as f64 / 1e6
        )?;
        outln!(
            "  file      {} bytes = {:.2} x raw ({} bytes: 12 per vertex and its properties, 12 per triangle), version {version}, coded in {:.0} ms -> {}",
            bytes.len(),
            bytes.len() as f64 / model.raw_bytes() as f64,
            model.raw_bytes(),
            ms(coding),
            args.output.display()
        )?;
        for c in &chunks {
            outln!(
                "            its first {} bytes ({:.1}%) open LoDs {}.. ({} triangles, {:.1}%)",
                c.end,
                100.0 * c.end as f64 / bytes.len() as f64,
                c.first_lod,
                model.triangle_count(c.first_lod),
                100.0 * model.triangle_count(c.first_lod) as f64 / mesh.triangle_count() as f64
            )?;
        }
        if !args.recipe_only {
            outln!(
                "            of which the recipe {} bytes = {:.2} x raw (what --recipe-only writes)",
                recipe.len(),
                recipe.len() as f64 / model.raw_bytes() as f64
            )?;
        }
    }
    Ok(())
}

/// `build --hierarchy`: the hierarchy of `mesh`, written as a version-7
/// file (coded; version 4 with `--uncompressed`), and its sizes.
fn run_hierarchy(
    args: &BuildArgs,
    name: &str,
    mesh: &Mesh,
    pipeline: mts::model::PipelineOptions,
    load: std::time::Duration,
) -> Result<()> {
    let options = mts::hierarchy::HierarchyOptions {
        pipeline,
        ..Default::default()
    };
    let started = std::time::Instant::now();
    let h = hierarchy_with_progress(mesh, &options)?;
    let build = started.elapsed();
    let bytes = if args.uncompressed {
        h.to_bytes()
    } else {
        h.to_compressed_bytes(args.level.unwrap_or(mts::model::compress::DEFAULT_LEVEL))
    };
    mts::output::write_file(&args.output, &bytes)?;
    let version = mts::model::format::file_version(&bytes).unwrap_or(0);
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    let raw = h.raw_bytes();
    if args.json {
        outln!(
            "{}",
            json!({
                "input": name,
                "vertices": h.vertex_count(),
                "triangles": h.triangle_count(),
                "levels": h.level_count(),
                "groups": h.groups().len(),
                "clusters": h.clusters().len(),
                "memory_bytes": h.memory_bytes(),
                "bytes": bytes.len(),
                "file_version": version,
                "raw_bytes": raw,
                "ms_load": ms(load),
                "build_ms": ms(build),
            })
        )?;
    } else {
        outln!(
            "{name}: {} triangles, {} vertices: a hierarchy of {} groups over {} levels, {} clusters",
            h.triangle_count(),
            h.vertex_count(),
            h.groups().len(),
            h.level_count(),
            h.clusters().len()
        )?;
        outln!(
            "  time      load {:.1} ms, build {:.1} ms",
            ms(load),
            ms(build)
        )?;
        outln!(
            "  memory    {:.1} MB = {:.2} x raw",
            h.memory_bytes() as f64 / 1e6,
            h.memory_bytes() as f64 / raw as f64
        )?;
        outln!(
            "  file      {} bytes = {:.2} x raw ({raw} bytes: 12 per vertex and its properties, 12 per triangle), version {version} -> {}",
            bytes.len(),
            bytes.len() as f64 / raw as f64,
            args.output.display()
        )?;
    }
    Ok(())
}

/// [`mts::hierarchy::build`] with a progress bar on large inputs: the
/// triangles of the groups built, every level counted, against about
/// twice the input's.
fn hierarchy_with_progress(
    mesh: &Mesh,
    options: &mts::hierarchy::HierarchyOptions,
) -> mts::Result<mts::hierarchy::Hierarchy> {
    use indicatif::{ProgressBar, ProgressStyle};
    let expected = 2 * mesh.triangle_count() as u64;
    let bar = if mesh.triangle_count() >= PROGRESS_MIN_TRIANGLES {
        ProgressBar::new(expected)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template(
            "hierarchy, groups on every core: {wide_bar} {percent}% {msg} {elapsed} (eta {eta})",
        )
        .expect("valid template"),
    );
    let out = mts::hierarchy::build_with_progress(mesh, options, &|p| {
        bar.set_position((p.triangles_done as u64).min(expected));
        bar.set_message(format!("level {}", p.level));
    });
    bar.finish_and_clear();
    out
}

/// Inputs of this many triangles or more get a progress bar.
const PROGRESS_MIN_TRIANGLES: usize = 200_000;

/// The whole pipeline with a progress bar on large inputs.
pub fn build_with_bar(
    mesh: &Mesh,
    options: &mts::model::PipelineOptions,
) -> mts::Result<(
    mts::MtsModel,
    mts::simplify::Stop,
    mts::model::PipelineTimings,
)> {
    use indicatif::{ProgressBar, ProgressStyle};
    let bar = if mesh.triangle_count() >= PROGRESS_MIN_TRIANGLES {
        ProgressBar::new(1)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{spinner} {msg:16} [{bar:30}] {pos}/{len} {elapsed}")
            .expect("valid template"),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar.set_message("strips + QEM");
    let mut started = false;
    let out = mts::model::try_build_from_mesh(mesh, options, &mut |done, max_lod| {
        if !started {
            bar.set_message("graphs (LoDs)");
            bar.set_length(max_lod.max(1) as u64);
            started = true;
        }
        bar.set_position(done as u64);
    });
    bar.finish_and_clear();
    out
}

/// What `build` does with a glTF file of several parts (mesh primitives):
/// the `.mts` file holds one model, so they are merged, each placed by its
/// node, with one texture; said once, since `render` and `view` draw such
/// a file part by part.
fn note_gltf_parts(source: &MeshSource) -> Result<()> {
    let Some(path) = &source.mesh else {
        return Ok(());
    };
    let gltf = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"));
    if !gltf {
        return Ok(());
    }
    let bytes = mts::mesh::io::read_file(path)?;
    if mts::mesh::io::Format::detect(path, &bytes)? != mts::mesh::io::Format::Gltf {
        return Ok(());
    }
    let n = mts::mesh::io::gltf_part_count(&bytes, path)?;
    if n > 1 {
        warnln!(
            "note: {}: {n} parts (mesh primitives): `build` merges them, each placed by its node, into one model with one texture, the first part's; `mts render` and `mts view` draw every part with its own",
            path.display()
        );
    }
    Ok(())
}

/// Chunk shares in percent (`--prefixes`), as fractions.
#[derive(Clone, Debug)]
pub struct Shares(pub Vec<f64>);

fn prefix_shares(s: &str) -> std::result::Result<Shares, String> {
    if s == "none" {
        return Ok(Shares(Vec::new()));
    }
    let shares = s
        .split(',')
        .map(|p| match p.trim().parse::<f64>() {
            Ok(x) if x > 0.0 && x < 100.0 => Ok(x / 100.0),
            _ => Err(format!(
                "{p:?} is not a share in percent between 0 and 100 (exclusive)"
            )),
        })
        .collect::<std::result::Result<Vec<f64>, String>>()?;
    if shares.len() > mts::model::prefix::MAX_PREFIXES {
        return Err(format!(
            "{} chunks, at most {}",
            shares.len(),
            mts::model::prefix::MAX_PREFIXES
        ));
    }
    Ok(Shares(shares))
}

/// The chunks of a version-6 file as `build --json` and `info --json`
/// give them: each one's first LoD, its triangles, where it ends.
pub(crate) fn chunk_json(
    chunks: &[mts::model::Chunk],
    model: &mts::MtsModel,
    file_len: usize,
) -> serde_json::Value {
    chunks
        .iter()
        .map(|c| {
            json!({
                "first_lod": c.first_lod,
                "triangles": model.triangle_count(c.first_lod),
                "bytes": c.end,
                "share_of_file": c.end as f64 / file_len.max(1) as f64,
            })
        })
        .collect()
}
