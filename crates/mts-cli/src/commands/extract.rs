//! `mts extract`: one LoD of a model, by MTS or a baseline.

use crate::args::*;
use crate::stdout::outln;
use anyhow::{bail, Context, Result};
use clap::Args;
use mts::mesh::Mesh;
use mts::methods::Method;
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
pub struct ExtractArgs {
    #[command(flatten)]
    pub source: MeshSource,
    #[command(flatten)]
    pub level: LevelArgs,
    /// Write the extracted triangles (.obj, .ply, .glb or .gltf, by extension).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub gltf: GltfOut,
    /// Timed extractions from scratch (1 to 10,000); the median is reported.
    #[arg(long, default_value_t = 11, value_parser = count_in::<1, MAX_REPEAT>, allow_negative_numbers = true)]
    pub repeat: usize,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// The method extracting the LoD: mts (strips) or a baseline. The
    /// cluster tree has its own clustering, so its LoD k differs; use
    /// --triangles or --ratio to compare methods.
    #[arg(long, value_parser = method_parser(), default_value = "mts")]
    pub method: Method,
    /// Read only the first N bytes of the .mts file, as a reader would
    /// while it arrives: a version-6 file (what `mts build` writes) opens
    /// from its first coarse chunk, as the model of the LoDs it holds
    /// (`lods_available`); a LoD finer than those draws the finest held.
    #[arg(long, conflicts_with = "method")]
    pub bytes: Option<u64>,
}

pub fn run(args: &ExtractArgs) -> Result<()> {
    use mts::Extractor;
    if let Some(out) = &args.output {
        args.source.check_output(out)?;
        args.gltf.check(out)?;
    }
    if args.method != Method::Mts {
        return extract_baseline(args);
    }
    if let Some(n) = args.bytes {
        return extract_prefix(args, n);
    }
    let started = Instant::now();
    let (name, model) = args.source.model()?;
    // Opening, validating (and, today, rebuilding the graphs from the
    // file's recipe), until an extractor is ready.
    let ready = Extractor::new(&model);
    let load_ms = started.elapsed().as_secs_f64() * 1e3;
    drop(ready);
    let lod = args
        .level
        .resolve_model(&model)?
        .context("give --lod, --triangles or --ratio")?;
    let Extracted {
        ex,
        us,
        runs,
        vertices_written,
    } = extract_timed(&model, lod, args)?;
    let triangles = model.triangle_count(lod);
    if args.json {
        let mut v = json!({
            "input": name,
            "lod": lod,
            "max_lod": model.max_lod(),
            "triangles": triangles,
            "strips": runs,
            "indices": ex.indices_sent(),
            "indices_per_triangle": ex.indices_sent() as f64 / triangles.max(1) as f64,
            "us": us,
            "load_ms": load_ms,
            "lods_available": [0, model.max_lod()],
        });
        if let Some(n) = vertices_written {
            v["vertices_written"] = json!(n);
        }
        outln!("{v}")?;
    } else {
        outln!(
            "{name}: LoD {lod} of {}: {triangles} triangles in {runs} strips, {} indices sent ({:.3} per triangle), extracted in {us:.1} us (median of {} from scratch)",
            model.max_lod(),
            ex.indices_sent(),
            ex.indices_sent() as f64 / triangles.max(1) as f64,
            args.repeat.max(1)
        )?;
    }
    Ok(())
}

/// One LoD extracted: the extractor, the median microseconds, the strips
/// (runs) it sends, the vertices `-o` wrote.
struct Extracted<'m> {
    ex: mts::Extractor<'m>,
    us: f64,
    runs: usize,
    vertices_written: Option<usize>,
}

/// Extracts `lod` of `model` `--repeat` times, each from an empty
/// extractor (no coherence), and writes it to `-o` when given.
fn extract_timed<'m>(
    model: &'m mts::MtsModel,
    lod: usize,
    args: &ExtractArgs,
) -> Result<Extracted<'m>> {
    use mts::Extractor;
    let mut times = Vec::with_capacity(args.repeat.max(1));
    let mut ex = Extractor::new(model);
    for _ in 0..args.repeat.max(1) {
        ex = Extractor::new(model);
        let t = Instant::now();
        ex.set_lod(lod);
        times.push(t.elapsed().as_secs_f64() * 1e6);
    }
    times.sort_by(f64::total_cmp);
    let us = times[times.len() / 2];
    let mut compact = Vec::new();
    ex.write_compact(&mut compact);
    let runs = compact
        .split(|&i| i == mts::strip::encode::RESTART_U32)
        .filter(|r| !r.is_empty())
        .count();
    let mut vertices_written = None;
    if let Some(out) = &args.output {
        // The level's own vertices only, renumbered; their properties are
        // the input vertices' (a model with properties has no created
        // vertices: endpoint placement).
        let mesh = Mesh::level(model.positions(), &ex.triangles(), model.properties());
        super::save_mesh_as(&mesh, out, args.gltf)?;
        vertices_written = Some(mesh.vertex_count());
    }
    Ok(Extracted {
        ex,
        us,
        runs,
        vertices_written,
    })
}

/// `extract --bytes N`: the LoD from the first `n` bytes of an `.mts`
/// file.
fn extract_prefix(args: &ExtractArgs, n: u64) -> Result<()> {
    use mts::Extractor;
    let Some(path) = &args.source.mesh else {
        bail!("--bytes reads the first bytes of an .mts file: give one");
    };
    let mut bytes = mts::mesh::io::read_file(path)?;
    if !bytes.starts_with(mts::model::format::MAGIC) {
        bail!(
            "{}: --bytes reads the first bytes of an .mts file, not a mesh",
            path.display()
        );
    }
    let file_bytes = bytes.len();
    bytes.truncate(usize::try_from(n).unwrap_or(usize::MAX));
    let started = Instant::now();
    let prefix = mts::MtsModel::from_prefix(&bytes, path)?;
    let ready = Extractor::new(&prefix.model);
    let load_ms = started.elapsed().as_secs_f64() * 1e3;
    drop(ready);
    let available = prefix.lods_available();
    let asked = args
        .level
        .resolve_in(*available.end(), prefix.full_triangles, |t| {
            prefix.lod_for_triangles(t)
        })?
        .context("give --lod, --triangles or --ratio")?;
    let lod = asked.clamp(*available.start(), *available.end());
    // A budget the prefix's first LoD is under asks for a finer LoD than
    // it holds (unless it is the whole file).
    let budget = match (args.level.lod, args.level.triangles, args.level.ratio) {
        (Some(_), _, _) => None,
        (_, Some(n), _) => Some(n as f64),
        (_, _, r) => r.map(|r| r * prefix.full_triangles as f64),
    };
    let coarser = lod != asked || budget.is_some_and(|b| !prefix.holds_budget(b.round() as usize));
    if coarser {
        eprintln!(
            "note: the LoD asked for is not in the first {} bytes, which hold LoDs {}..={}: drawing LoD {lod}",
            bytes.len(),
            available.start(),
            available.end()
        );
    }
    let model = &prefix.model;
    let Extracted {
        ex,
        us,
        runs,
        vertices_written,
    } = extract_timed(model, prefix.model_lod(lod), args)?;
    let triangles = model.triangle_count(prefix.model_lod(lod));
    let name = path.display().to_string();
    if args.json {
        let mut v = json!({
                "input": name,
                "bytes": bytes.len(),
                "file_bytes": file_bytes,
                "bytes_used": prefix.bytes_used,
                "whole": prefix.is_whole(),
                "lods_available": [available.start(), available.end()],
                "lod": lod,
                "max_lod": available.end(),
                "triangles": triangles,
                "strips": runs,
                "full_triangles": prefix.full_triangles,
                "indices": ex.indices_sent(),
                "indices_per_triangle": ex.indices_sent() as f64 / triangles.max(1) as f64,
                "us": us,
                "load_ms": load_ms,
        });
        if let Some(n) = vertices_written {
            v["vertices_written"] = json!(n);
        }
        outln!("{v}")?;
    } else {
        outln!(
            "{name}: the first {} of {file_bytes} bytes ({:.1}%) open LoDs {}..={} ({}), opened in {load_ms:.1} ms; LoD {lod}: {triangles} triangles of {}, {} indices sent, extracted in {us:.1} us",
            bytes.len(),
            100.0 * bytes.len() as f64 / file_bytes.max(1) as f64,
            available.start(),
            available.end(),
            if prefix.is_whole() {
                "the whole model"
            } else {
                "a coarse chunk, built"
            },
            prefix.full_triangles,
            ex.indices_sent(),
        )?;
    }
    Ok(())
}

fn extract_baseline(args: &ExtractArgs) -> Result<()> {
    let (name, model) = args.source.model()?;
    let mesh = model.mesh();
    let mut source = args.method.source(&model, &mesh)?;
    let lod = args
        .level
        .resolve(source.as_ref())?
        .context("give --lod, --triangles or --ratio")?;
    // Each timed change starts from a fresh source (no coherence).
    let mut times = Vec::with_capacity(args.repeat.max(1));
    for _ in 0..args.repeat.max(1) {
        source = args.method.source(&model, &mesh)?;
        let t = Instant::now();
        source.set_lod(lod);
        times.push(t.elapsed().as_secs_f64() * 1e6);
    }
    times.sort_by(f64::total_cmp);
    let us = times[times.len() / 2];
    let triangles = source.triangles();
    if let Some(out) = &args.output {
        let m = Mesh::level(&mesh.positions, &triangles, &mesh.properties);
        super::save_mesh_as(&m, out, args.gltf)?;
    }
    let method = source.name();
    if args.json {
        outln!(
            "{}",
            json!({
                "input": name,
                "method": method,
                "lod": lod,
                "max_lod": source.max_lod(),
                "triangles": triangles.len(),
                "indices": source.indices().len(),
                "indices_per_triangle": source.indices().len() as f64 / triangles.len().max(1) as f64,
                "us": us,
            })
        )?;
    } else {
        outln!(
            "{name}: {method} LoD {lod} of {}: {} triangles, {} indices sent, set in {us:.1} us (median of {} from a fresh source)",
            source.max_lod(),
            triangles.len(),
            source.indices().len(),
            times.len()
        )?;
    }
    Ok(())
}
