//! `mts info`: describe an `.mts` file (a model, or a hierarchy of
//! version 4).

use crate::stdout::outln;
use anyhow::{Context, Result};
use clap::Args;
use mts::{stripify, StripifyOptions};
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
pub struct InfoArgs {
    /// The .mts file.
    pub model: PathBuf,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &InfoArgs) -> Result<()> {
    use mts::model::format::{holds, Holds};
    use mts::{Extractor, MtsModel};
    let t0 = Instant::now();
    let bytes = mts::mesh::io::read_file(&args.model)?;
    if holds(&bytes) == Some(Holds::Hierarchy) {
        return hierarchy_info(args, &bytes, t0);
    }
    let model = MtsModel::from_bytes(&bytes, &args.model)?;
    let version = mts::model::format::file_version(&bytes).unwrap_or(0);
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let chunks = mts::model::chunk_index(&bytes, &args.model)?;
    drop(bytes);
    let file_bytes = std::fs::metadata(&args.model)
        .with_context(|| format!("cannot read {}", args.model.display()))?
        .len();
    let st = model.stats();
    let mesh = model.mesh();
    let mut ex = Extractor::new(&model);
    let mut levels = Vec::new();
    for ratio in [1.0, 0.5, 0.25, 0.1, 0.05, 0.01] {
        let lod = model.lod_for_ratio(ratio);
        ex.set_lod(lod);
        let triangles = model.triangle_count(lod);
        let fresh = stripify(
            &model.collapses().mesh_at(&mesh, lod),
            &StripifyOptions::default(),
        );
        let ours = ex.indices_sent() as f64 / triangles.max(1) as f64;
        let theirs = fresh.restart_index_count() as f64 / triangles.max(1) as f64;
        levels.push(json!({
            "ratio": ratio,
            "lod": lod,
            "triangles": triangles,
            "indices": ex.indices_sent(),
            "indices_per_triangle": ours,
            "restripified_indices_per_triangle": theirs,
            "quality_ratio": ours / theirs,
        }));
    }
    let props = model.properties();
    let (streams, points, texture) = describe(props, model.collapses().vertex_count());
    if args.json {
        let mut v = json!({
            "file": args.model.display().to_string(),
            "file_bytes": file_bytes,
            "file_version": version,
                "raw_bytes": model.raw_bytes(),
                "load_ms": load_ms,
                "vertices": model.positions().len(),
                "triangles": model.triangle_count(0),
                "max_lod": model.max_lod(),
                "bands": model.band_count(),
                "strips": st.strips,
                "nodes": st.nodes,
                "arcs": st.arcs,
            "memory_bytes": st.memory_bytes,
            "levels": levels,
        });
        if version == mts::model::STREAMED_VERSION {
            v["prefixes"] = super::build::chunk_json(&chunks, &model, usize::try_from(file_bytes)?);
        }
        // Only for a model with properties, so that the output of the
        // others stays as it was.
        if !props.is_empty() {
            v["properties"] = json!({
                "streams": streams,
                "points": points,
                "texture": texture,
            });
        }
        outln!("{}", serde_json::to_string_pretty(&v)?)?;
    } else {
        // Versions 1 and 2 hold the recipe only: loading builds the model.
        let how = if version < 3 {
            "loaded and built"
        } else {
            "loaded"
        };
        outln!(
            "{}: {} bytes ({:.2} x raw), version {version}, {how} in {load_ms:.1} ms",
            args.model.display(),
            file_bytes,
            file_bytes as f64 / model.raw_bytes() as f64
        )?;
        outln!("  {} vertices, {} triangles, {} LoDs, {} bands, {} strips, {} nodes, {} arcs, {:.1} MB in memory",
            model.positions().len(), model.triangle_count(0), model.max_lod() + 1, model.band_count(), st.strips, st.nodes, st.arcs, st.memory_bytes as f64 / 1e6)?;
        for c in &chunks {
            outln!(
                "  its first {} bytes ({:.1}%) open LoDs {}.. ({} triangles)",
                c.end,
                100.0 * c.end as f64 / file_bytes.max(1) as f64,
                c.first_lod,
                model.triangle_count(c.first_lod)
            )?;
        }
        if !props.is_empty() {
            outln!(
                "  properties: {} on {points} points; texture: {}",
                if streams.is_empty() {
                    "none".to_string()
                } else {
                    streams.join(", ")
                },
                texture.as_deref().unwrap_or("none")
            )?;
        }
        outln!(
            "  {:>6} {:>7} {:>9} {:>9} {:>11} {:>7}",
            "share",
            "LoD",
            "triangles",
            "idx/tri",
            "restripify",
            "ratio"
        )?;
        for l in &levels {
            outln!(
                "  {:>5.0}% {:>7} {:>9} {:>9.3} {:>11.3} {:>7.3}",
                l["ratio"].as_f64().unwrap_or(0.0) * 100.0,
                l["lod"].as_u64().unwrap_or(0),
                l["triangles"].as_u64().unwrap_or(0),
                l["indices_per_triangle"].as_f64().unwrap_or(0.0),
                l["restripified_indices_per_triangle"]
                    .as_f64()
                    .unwrap_or(0.0),
                l["quality_ratio"].as_f64().unwrap_or(0.0),
            )?;
        }
    }
    Ok(())
}

/// A model's or hierarchy's properties for `info`: the streams present,
/// the points (`vertices` when no vertex is split) and the texture.
fn describe(
    props: &mts::mesh::Properties,
    vertices: usize,
) -> (Vec<&'static str>, usize, Option<String>) {
    let mut streams = Vec::new();
    for (present, name) in [
        (props.normals.is_some(), "normals"),
        (props.uvs.is_some(), "uvs"),
        (props.colors.is_some(), "colors"),
    ] {
        if present {
            streams.push(name);
        }
    }
    let points = props
        .position_ids
        .iter()
        .max()
        .map_or(vertices, |&m| m as usize + 1);
    let texture = props.texture.as_ref().map(|t| match t {
        mts::mesh::Texture::File(f) => f.display().to_string(),
        mts::mesh::Texture::Embedded { mime, bytes } => {
            format!("embedded {mime} ({} bytes)", bytes.len())
        }
    });
    (streams, points, texture)
}

/// `info` on a version-4 file: the hierarchy's sizes and, per level, its
/// groups and the triangles they take in and give out.
fn hierarchy_info(args: &InfoArgs, bytes: &[u8], t0: Instant) -> Result<()> {
    let h = mts::hierarchy::Hierarchy::from_bytes(bytes, &args.model)?;
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let file_bytes = bytes.len();
    let raw = h.raw_bytes();
    let mut levels = Vec::new();
    for level in 0..h.level_count() as u32 {
        let groups: Vec<_> = h.groups().iter().filter(|g| g.level == level).collect();
        let input: usize = groups.iter().map(|g| g.model.triangle_count(0)).sum();
        let output: usize = groups
            .iter()
            .map(|g| g.model.triangle_count(g.model.max_lod()))
            .sum();
        let error = groups.iter().map(|g| g.output_error()).fold(0f32, f32::max);
        levels.push(json!({
            "level": level,
            "groups": groups.len(),
            "triangles": input,
            "output_triangles": output,
            "max_output_error": error,
        }));
    }
    let props = h.properties();
    let (streams, points, texture) = describe(props, h.vertex_count());
    if args.json {
        let mut v = json!({
            "file": args.model.display().to_string(),
            "kind": "hierarchy",
            "file_bytes": file_bytes,
            "file_version": mts::model::format::file_version(bytes).unwrap_or(0),
            "bytes": file_bytes,
            "raw_bytes": raw,
            "load_ms": load_ms,
            "vertices": h.vertex_count(),
            "triangles": h.triangle_count(),
            "levels": h.level_count(),
            "groups": h.groups().len(),
            "clusters": h.clusters().len(),
            "memory_bytes": h.memory_bytes(),
            "per_level": levels,
        });
        if !props.is_empty() {
            v["properties"] = json!({
                "streams": streams,
                "points": points,
                "texture": texture,
            });
        }
        outln!("{}", serde_json::to_string_pretty(&v)?)?;
    } else {
        outln!(
            "{}: {file_bytes} bytes ({:.2} x raw), a view-dependent hierarchy, loaded and checked in {load_ms:.1} ms",
            args.model.display(),
            file_bytes as f64 / raw as f64
        )?;
        outln!(
            "  {} vertices, {} triangles, {} levels, {} groups, {} clusters, {:.1} MB in memory",
            h.vertex_count(),
            h.triangle_count(),
            h.level_count(),
            h.groups().len(),
            h.clusters().len(),
            h.memory_bytes() as f64 / 1e6
        )?;
        if !props.is_empty() {
            outln!(
                "  properties: {} on {points} points; texture: {}",
                if streams.is_empty() {
                    "none".to_string()
                } else {
                    streams.join(", ")
                },
                texture.as_deref().unwrap_or("none")
            )?;
        }
        outln!(
            "  {:>5} {:>6} {:>10} {:>10} {:>12}",
            "level",
            "groups",
            "triangles",
            "output",
            "max error"
        )?;
        for l in &levels {
            outln!(
                "  {:>5} {:>6} {:>10} {:>10} {:>12.3e}",
                l["level"].as_u64().unwrap_or(0),
                l["groups"].as_u64().unwrap_or(0),
                l["triangles"].as_u64().unwrap_or(0),
                l["output_triangles"].as_u64().unwrap_or(0),
                l["max_output_error"].as_f64().unwrap_or(0.0),
            )?;
        }
    }
    Ok(())
}
