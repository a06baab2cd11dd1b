//! Vertex work on the adapter: pipeline-statistics queries of each
//! method's index buffer beside the cache models' predictions (`mts bench
//! render`, the report's vertex-work table).

//! `mts bench render`: frames and triangles per second of the MTS strips
//! against meshoptimizer-ordered triangle lists, headless, on the adapter
//! at hand; and the cost of one LoD change (extraction plus upload).

use crate::bench::results::{ModelFit, VertexRow, VertexWork};
use anyhow::Result;
use mts::{peers, Extractor, StripifyOptions};
use mts_render::headless::HeadlessTarget;
use mts_render::{Camera, Gpu, RendererConfig, StripRenderer};
use std::collections::BTreeMap;

/// Shares of the vertex-work rows (the 100/50/10/1%).
const VERTEX_SHARES: [f64; 4] = [1.0, 0.5, 0.1, 0.01];

/// Measures [`VertexWork`] of `model` on `gpu`: MTS strips (restart or
/// stitched, as the backend draws; and stitched: `mts_stitched`), the MTS strips of the same model built
/// with cache-aware bands (`mts_cache_aware`), meshoptimizer's strips, the
/// cache-aware stripifier on the level's triangles (`cache_aware_strips`,
/// and stitched into one run: `cache_aware_stitched`),
/// the meshoptimizer-ordered list and the unordered list (the oracle's
/// order) at each of [`VERTEX_SHARES`], and the baselines' lists (`pm_list`,
/// `multilevel_list`, `cluster_list`, `discrete_list`; discrete where
/// meshoptimizer takes the mesh) at their finest LoD within the same
/// triangles.
pub fn measure_vertex_work(
    gpu: &Gpu,
    target: &HeadlessTarget,
    config: &RendererConfig,
    model_name: &str,
    model: &mts::MtsModel,
    camera: &Camera,
) -> Result<VertexWork> {
    use mts::lod::Topology;
    use mts::strip::encode::stitch_restart_buffer;
    use mts::strip::vertex_work::REPORTED_MODELS;
    use mts_render::{DrawQueries, StripMode};
    let (d, q) = (&gpu.device, &gpu.queue);
    let queries = DrawQueries::new(d, q);
    let mesh = model.mesh();
    let mut renderer = StripRenderer::for_model(d, q, config, model)?;
    renderer.set_camera(q, camera);
    let mut ex = Extractor::new(model);
    // The same sequence and band slack, every band stripified cache-aware.
    let aware = StripifyOptions {
        cache_aware: true,
        ..StripifyOptions::default()
    };
    let aware_model = mts::model::build(
        &mesh,
        &mts::stripify(&mesh, &aware),
        model.collapses(),
        &mts::model::BuildOptions {
            band_slack: model.build_options().band_slack,
            stripify: aware,
        },
    );
    let mut aware_ex = Extractor::new(&aware_model);
    let mut rows = Vec::new();
    for ratio in VERTEX_SHARES {
        let lod = model.lod_for_ratio(ratio);
        ex.set_lod(lod);
        let oracle = model.collapses().triangles_at(&mesh, lod);
        let n = model.positions().len();
        let ordered = peers::meshopt::optimize_vertex_cache(&oracle, n);
        let level = mts::Mesh {
            positions: model.positions().to_vec(),
            triangles: oracle.clone(),
            properties: Default::default(),
        };
        let theirs = peers::meshopt::stripify(&level).to_restart_u32();
        let aware_strips = mts::stripify(&level, &aware).to_restart_u32();
        // The same runs joined by degenerate triangles instead of restart
        // values: a driver that empties its vertex cache at each restart
        // keeps it across the joins.
        let mut aware_stitched = Vec::new();
        stitch_restart_buffer(&aware_strips, &mut aware_stitched);
        let ours = ex.buffer()[ex.active_range()].to_vec();
        let mut ours_stitched = Vec::new();
        stitch_restart_buffer(&ours, &mut ours_stitched);
        aware_ex.set_lod(lod);
        let ours_aware = aware_ex.buffer()[aware_ex.active_range()].to_vec();
        let flat = |t: &[[u32; 3]]| t.iter().flatten().copied().collect::<Vec<u32>>();
        for (method, buffer, topology) in [
            ("mts_strips", ours, Topology::StripRestart),
            ("mts_stitched", ours_stitched, Topology::StripRestart),
            ("mts_cache_aware", ours_aware, Topology::StripRestart),
            ("meshopt_strips", theirs, Topology::StripRestart),
            ("cache_aware_strips", aware_strips, Topology::StripRestart),
            (
                "cache_aware_stitched",
                aware_stitched,
                Topology::StripRestart,
            ),
            ("meshopt_list", flat(&ordered), Topology::TriangleList),
            ("list", flat(&oracle), Topology::TriangleList),
        ] {
            // What the GPU reads: the restart buffer, or its stitching.
            let drawn = if topology == Topology::TriangleList {
                renderer.upload_list(d, q, bytemuck_triangles(&buffer))?;
                buffer
            } else {
                renderer.upload_strip_indices(d, q, &buffer)?;
                match config.strip_mode {
                    StripMode::Restart => buffer,
                    StripMode::Stitched => {
                        let mut out = Vec::new();
                        stitch_restart_buffer(&buffer, &mut out);
                        out
                    }
                }
            };
            let triangles = model.triangle_count(lod);
            rows.push(vertex_row(
                &queries, d, q, target, &renderer, method, ratio, lod, triangles, &drawn, topology,
            )?);
        }
    }
    // The baselines' lists (their own vertex numbering), each at its
    // finest LoD within the MTS level's triangles.
    for method in [
        mts::methods::Method::Pm,
        mts::methods::Method::Multilevel,
        mts::methods::Method::Cluster,
        mts::methods::Method::Discrete,
    ] {
        if method == mts::methods::Method::Discrete && peers::meshopt::refusal(&mesh).is_some() {
            continue;
        }
        let mut source = method.source(model, &mesh)?;
        let mut renderer = StripRenderer::for_source(d, q, config, source.as_mut())?;
        renderer.set_camera(q, camera);
        for ratio in VERTEX_SHARES {
            let budget = model.triangle_count(model.lod_for_ratio(ratio));
            let lod = source.set_lod(mts::lod::lod_for_triangles(&*source, budget));
            renderer.upload_source(d, q, &*source)?;
            let topology = match source.topology() {
                mts::Topology::TriangleList => Topology::TriangleList,
                mts::Topology::StripRestart => Topology::StripRestart,
            };
            let name = format!("{}_list", source.name());
            let triangles = source.triangle_count(lod);
            let drawn = source.indices().to_vec();
            rows.push(vertex_row(
                &queries, d, q, target, &renderer, &name, ratio, lod, triangles, &drawn, topology,
            )?);
        }
    }
    // Share by share, finest first; methods in the order measured.
    rows.sort_by(|a, b| b.ratio.total_cmp(&a.ratio));
    let mut model_fit = BTreeMap::new();
    for (name, _) in REPORTED_MODELS {
        let logs: Option<Vec<f64>> = rows
            .iter()
            .map(|r| r.measured_over_modelled[name].map(f64::ln))
            .collect();
        let fit = logs.filter(|l| !l.is_empty()).map(|l| ModelFit {
            ratio_geomean: (l.iter().sum::<f64>() / l.len() as f64).exp(),
            mean_abs_log_ratio: l.iter().map(|x| x.abs()).sum::<f64>() / l.len() as f64,
        });
        model_fit.insert(name.to_string(), fit);
    }
    let best_model = model_fit
        .iter()
        .filter_map(|(n, f)| f.map(|f| (n.clone(), f.mean_abs_log_ratio)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(n, _)| n);
    let mut missing = Vec::new();
    if !queries.has_statistics() {
        missing.push("pipeline statistics");
    }
    if !queries.has_timestamps() {
        missing.push("timestamps");
    }
    Ok(VertexWork {
        model: model_name.to_string(),
        pipeline_statistics: queries.has_statistics(),
        timestamps: queries.has_timestamps(),
        note: (!missing.is_empty())
            .then(|| format!("the adapter does not offer {}", missing.join(" or "))),
        clipper_mismatches: rows
            .iter()
            .filter(|r| r.clipper_matches_triangles == Some(false))
            .count() as u64,
        rows,
        model_fit,
        best_model,
    })
}

/// One vertex-work row: `renderer` drawn five times under the queries
/// (it holds `drawn`, `triangles` triangles of `method` at `lod`), beside
/// each cache model's invocations for `drawn`.
#[allow(clippy::too_many_arguments)]
fn vertex_row(
    queries: &mts_render::DrawQueries,
    d: &wgpu::Device,
    q: &wgpu::Queue,
    target: &HeadlessTarget,
    renderer: &StripRenderer,
    method: &str,
    ratio: f64,
    lod: usize,
    triangles: usize,
    drawn: &[u32],
    topology: mts::lod::Topology,
) -> Result<VertexRow> {
    use mts::strip::vertex_work::{vertex_work, REPORTED_MODELS};
    let mut times = Vec::new();
    let mut counts = None;
    for _ in 0..5 {
        let m = queries.measure(d, q, target, |pass| renderer.draw(pass))?;
        counts = m.counts;
        times.extend(m.gpu_ms);
    }
    times.sort_by(f64::total_cmp);
    let mut modelled = BTreeMap::new();
    let mut ratios = BTreeMap::new();
    for (name, cache) in REPORTED_MODELS {
        let w = vertex_work(drawn, topology, cache);
        modelled.insert(name.to_string(), w.invocations);
        ratios.insert(
            name.to_string(),
            counts.map(|c| c.vertex_invocations as f64 / w.invocations.max(1) as f64),
        );
    }
    Ok(VertexRow {
        ratio,
        lod: lod as u64,
        triangles: triangles as u64,
        method: method.to_string(),
        indices_sent: drawn.len() as u64,
        vertex_invocations: counts.map(|c| c.vertex_invocations),
        invocations_per_triangle: counts
            .map(|c| c.vertex_invocations as f64 / triangles.max(1) as f64),
        clipper_invocations: counts.map(|c| c.clipper_invocations),
        primitives_assembled: assembled(drawn, topology) as u64,
        clipper_matches_triangles: counts.map(|c| c.clipper_invocations == triangles as u64),
        fragment_invocations: counts.map(|c| c.fragment_invocations),
        gpu_ms: times.get(times.len() / 2).copied(),
        modelled,
        measured_over_modelled: ratios,
    })
}

/// Windows of three indices `buffer` assembles to (no restart inside).
fn assembled(buffer: &[u32], topology: mts::lod::Topology) -> usize {
    use mts::strip::encode::RESTART_U32;
    if topology == mts::lod::Topology::TriangleList {
        return buffer.len() / 3;
    }
    buffer
        .windows(3)
        .filter(|w| !w.contains(&RESTART_U32))
        .count()
}

/// A flat list as triangles (its length is a multiple of 3).
fn bytemuck_triangles(flat: &[u32]) -> &[[u32; 3]] {
    bytemuck::cast_slice(flat)
}
