//! `report.md`: the bench's Markdown, made from the typed results alone.

//! `mts bench`: the MTS paper's tables measured on this machine, written as
//! `report.md` and `results.json` (schema in `docs/bench-schema.md`).
//!
//! Every figure of a row is measured in the same run as the figures it is
//! compared with. Timings are medians of a few repetitions; the machine
//! section names the CPU they come from.

use super::measure::{PROPERTY_MESH, SAMPLES};
use super::view_dependent::COMPARED_FRAMES;
use crate::bench::results::{
    FastSimplificationRun, Figure6Row, MethodRow, Model, PropertyRow, Results, Scale, Scene,
    ViewDependentRun,
};
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::Path;

/// The report's measured vertex work: the adapter's counts beside the
/// cache models' predictions for the buffers it drew.
fn vertex_table(s: &mut String, w: Option<&crate::bench::results::VertexWork>) {
    let Some(w) = w else {
        return;
    };
    let _ = writeln!(
        s,
        "\n### Vertex work measured by the adapter: {}\n",
        w.model
    );
    let _ = writeln!(s, "Pipeline-statistics queries on Figure 6's adapter (`mts bench render`): vertex-shader invocations per triangle drawn, beside the invocations the cache models predict for the same index buffer (FIFO of 16, batches of 96 and 384 indices, LRU of 32, and LRU of 32 emptied at every primitive restart; per triangle), clipper primitives against the triangles drawn (degenerate strip windows included where the clipper counts them) and the pass's GPU time (timestamps, median of 5). Methods: MTS strips as the backend draws them (`mts_strips`) and stitched into one run by degenerate triangles (`mts_stitched`), the same model built with cache-aware bands (`mts_cache_aware`), meshoptimizer's strips, the cache-aware stripifier on the level's triangles (`cache_aware_strips`, and its runs stitched into one by degenerate triangles: `cache_aware_stitched`), the meshoptimizer-ordered list, the list in the oracle's order, and the baselines' lists at their finest LoD within the same triangles.\n");
    if let Some(note) = &w.note {
        let _ = writeln!(s, "Not measured: {note}.\n");
    }
    let _ = writeln!(s, "| share | method | triangles | indices | measured / triangle | FIFO16 | batch96 | batch384 | LRU32 | LRU32 per run | clipper (assembled) | GPU ms |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    let opt =
        |x: Option<f64>, digits: usize| x.map_or("—".to_string(), |x| format!("{x:.digits$}"));
    for r in &w.rows {
        let per = |name: &str| {
            let m = r.modelled.get(name).copied().unwrap_or(0);
            format!("{:.3}", m as f64 / r.triangles.max(1) as f64)
        };
        let _ = writeln!(
            s,
            "| {:.0}% | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} ({}) | {} |",
            r.ratio * 100.0,
            r.method,
            r.triangles,
            r.indices_sent,
            opt(r.invocations_per_triangle, 3),
            per("fifo16"),
            per("batch96"),
            per("batch384"),
            per("lru32"),
            per("lru32_run"),
            r.clipper_invocations
                .map_or("—".to_string(), |c| c.to_string()),
            r.primitives_assembled,
            opt(r.gpu_ms, 2),
        );
    }
    let fits: Vec<String> = w
        .model_fit
        .iter()
        .filter_map(|(n, f)| {
            f.map(|f| {
                format!(
                    "{n} {:.3} (spread {:.3})",
                    f.ratio_geomean, f.mean_abs_log_ratio
                )
            })
        })
        .collect();
    if !fits.is_empty() {
        let _ = writeln!(
            s,
            "\nMeasured / modelled invocations, geometric mean over the rows (spread: mean |ln ratio|): {}; the best fit here: {}. Rows whose clipper count differs from the triangles drawn: {}.",
            fits.join(", "),
            w.best_model.as_deref().unwrap_or("—"),
            w.clipper_mismatches
        );
    }
}

/// The report's section on the scene.
fn scene_table(s: &mut String, rows: &[Scene]) {
    let Some(first) = rows.first() else {
        return;
    };
    let _ = writeln!(
        s,
        "\n## Scene: many instances of several models, LoD by screen-space error, shared buffers\n"
    );
    let _ = writeln!(s, "`mts bench render --scene`'s rows on Figure 6's adapter: instances of {} ({}) scaled to one radius on a ground plane, {}×{} pixels, a camera flying through the field ({} frames). Each visible instance gets the coarsest LoD whose recorded error projects within the threshold, and draws the shared buffer of its LoD bucket (10% fewer triangles a bucket), one instanced draw per (model, bucket). Update: cull, LoD choice, extractions, uploads; frame: update and draw. GPU: peak bucket buffers and transforms, against the sum of the models' full-detail strip buffers. Image: pixels covered by instances that differ at all from the same frame at full detail ({} frames of the path); image error: against that frame drawn 4 × 4 times denser and box-filtered (the truth), the RMSE of the LoD frame over the RMSE of the full-detail frame at one sample per pixel, sRGB values, pooled over the frames (1: as close to the truth as drawing everything).\n", first.models, first.model_names.join(", "), first.width, first.height, first.frames, first.compared_frames);
    let _ = writeln!(s, "{}", scene_table_head());
    for r in rows {
        let _ = writeln!(s, "{}", scene_table_row(r));
    }
}

/// The head of the scene table (the report's, and `mts bench render
/// --scene`'s text).
pub fn scene_table_head() -> String {
    format!("| instances | px | visible | triangles (share of full) | draws | extractions / frame | update ms median / p99 | frame ms | CPU B / instance | GPU MB (× full strips) | buffers | pixels differing (by > {}/255; in coverage) | image error (× full detail's) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|", super::results::IMAGE_TOLERANCE)
}

/// One scene row of [`scene_table_head`]'s table.
pub fn scene_table_row(r: &Scene) -> String {
    let share = |x: Option<f64>| x.map_or("—".into(), |x| format!("{:.3}%", 100.0 * x));
    format!(
        "| {} | {} | {:.0} | {:.0} ({:.2}%) | {:.1} | {:.2} | {:.2} / {:.2} | {:.1} | {} | {:.2} ({:.2}×) | {} | {} ({}; {}) | {} |",
        r.instances,
        r.pixel_threshold,
        r.visible,
        r.triangles_drawn,
        100.0 * r.triangles_drawn / r.triangles_full_detail.max(1.0),
        r.draws,
        r.extractions_per_frame,
        r.update_ms_median,
        r.update_ms_p99,
        r.frame_ms_median,
        r.cpu_bytes_per_instance,
        r.gpu_bytes as f64 / 1e6,
        r.gpu_bytes as f64 / r.full_detail_strip_bytes.max(1) as f64,
        r.buffers,
        share(r.differing_pixel_share),
        share(r.visibly_differing_pixel_share),
        share(r.coverage_differing_pixel_share),
        r.image_error_ratio.map_or("—".into(), |x| format!("{x:.3}")),
    )
}

/// The report's section on view-dependent detail: a table per input.
fn view_dependent_section(s: &mut String, results: &Results) {
    let runs = &results.view_dependent;
    if runs.is_empty() {
        return;
    }
    let _ = writeln!(s, "\n## View-dependent detail\n");
    let _ = writeln!(s, "`mts bench view-dependent` per input: every method that varies its resolution within one object — the strip hierarchy (`mts_hierarchy`), meshoptimizer's cluster LoD (`clusterlod`), the cluster tree's variable resolution (`cluster_tree`) — and the per-object MTS model (`mts`), with the same cameras and pixel threshold along a fixed flight: low over a terrain from one corner to the opposite one, looking ahead and down; around any other mesh once and a half, closing in from 2.2 to 0.8 bounding radii. Triangles: the median frame's cut, not culled, and over the cluster LoD's at the same threshold; update: the selection and extraction (medians and 99th percentiles of the frames); cracks: edges, taken by point, drawn a different number of times in each direction away from the input's boundary, summed over the frames; popping: the largest distance in pixels from a vertex drawn in one frame but not the next to the surface the next frame draws, both ways; memory and GPU bytes (vertices and the flight's largest index buffer) over the raw mesh (12 bytes a vertex and a triangle); image error: on {COMPARED_FRAMES} frames of the flight, the RMSE against the full-detail frame drawn 4 × 4 times denser and box-filtered, over the full-detail frame's at one sample per pixel, pooled (1: as close to the truth as drawing everything).\n");
    if runs.iter().all(|r| r.adapter.is_none()) {
        let _ = writeln!(
            s,
            "Image error not measured: {}.\n",
            results
                .machine
                .adapter_note
                .as_deref()
                .unwrap_or("no adapter")
        );
    }
    for (i, run) in runs.iter().enumerate() {
        if i > 0 {
            let _ = writeln!(s);
        }
        view_dependent_table(s, run);
    }
}

/// One input's table of [`view_dependent_section`].
fn view_dependent_table(s: &mut String, run: &ViewDependentRun) {
    let _ = writeln!(
        s,
        "### {}: {} triangles, {} frames {} it, {}×{} pixels{}\n",
        run.input,
        run.triangles_full_detail,
        run.frames,
        if run.flight == "over" {
            "flying over"
        } else {
            "circling"
        },
        run.width,
        run.height,
        run.adapter
            .as_ref()
            .map_or(String::new(), |a| format!(", images on {a}"))
    );
    let _ = writeln!(s, "| method | px | triangles drawn (× cluster LoD) | indices / triangle | update ms median / p99 | cracks | popping px max | memory / raw | GPU bytes / raw | build s | image error (× full detail's) |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|");
    for r in &run.methods {
        let clusterlod = run
            .methods
            .iter()
            .find(|c| c.method == "clusterlod" && c.pixel_threshold == r.pixel_threshold)
            .map_or(f64::NAN, |c| c.triangles_drawn_median);
        let raw = r.raw_bytes.max(1) as f64;
        let _ = writeln!(
            s,
            "| {} | {} | {:.0} ({:.2}×) | {:.3} | {:.3} / {:.3} | {} | {:.2} | {:.2} | {:.2} | {:.1} | {} |",
            r.method,
            r.pixel_threshold,
            r.triangles_drawn_median,
            r.triangles_drawn_median / clusterlod,
            r.indices_per_triangle,
            r.update_ms_median,
            r.update_ms_p99,
            r.cracks,
            r.popping_px_max,
            r.memory_bytes as f64 / raw,
            r.gpu_bytes as f64 / raw,
            r.build_ms / 1e3,
            r.image_error_ratio
                .map_or("—".into(), |x| format!("{x:.3}")),
        );
    }
}

/// The report's section on vertex properties.
fn property_table(s: &mut String, rows: &[PropertyRow]) {
    let _ = writeln!(
        s,
        "\n## Vertex properties against meshoptimizer's `simplifyWithAttributes`\n"
    );
    let _ = writeln!(s, "Models loaded with `--properties` (UV and normal seams kept) and the generated `{PROPERTY_MESH}` with UVs, normals and colours; meshoptimizer's `simplifyWithAttributes` (normals 1, UV 30, colours 1) at the same triangle count. Geometric error relative to the diagonal; property error sampled like it at corresponding points, both directions pooled: UV distance, normal angle in degrees, RGBA distance (RMS; `docs/experiments/properties.md`).\n");
    let _ = writeln!(s, "Image: the LoD drawn with the model's properties (the checker texture where it has UVs, `mts render --checker`) from the fixed camera that frames it, against the full model drawn alike: share of the model's pixels whose colour moved by more than {} of 255, and the RMS RGB difference.\n", super::results::IMAGE_TOLERANCE);
    let _ = writeln!(s, "| model | share | triangles (mts / meshopt) | Hausdorff mts / meshopt | RMS mts / meshopt | UV mts / meshopt | normal° mts / meshopt | colour mts / meshopt | image pixels changed mts / meshopt | image RMS mts / meshopt |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    let pair = |a: Option<f64>, b: Option<f64>, digits: usize| match (a, b) {
        (Some(a), Some(b)) => format!("{a:.digits$} / {b:.digits$}"),
        _ => "—".to_string(),
    };
    for r in rows {
        let (m, o) = (&r.mts, &r.meshopt);
        let _ = writeln!(
            s,
            "| {} | {:.0}% | {} / {} | {:.5} / {:.5} | {:.5} / {:.5} | {} | {} | {} | {} | {} |",
            r.model,
            r.share * 100.0,
            m.triangles,
            o.triangles,
            m.hausdorff,
            o.hausdorff,
            m.rms,
            o.rms,
            pair(m.uv_rms, o.uv_rms, 4),
            pair(m.normal_degrees_rms, o.normal_degrees_rms, 1),
            pair(m.color_rms, o.color_rms, 4),
            match (m.image_differing_share, o.image_differing_share) {
                (Some(a), Some(b)) => format!("{:.1}% / {:.1}%", 100.0 * a, 100.0 * b),
                _ => "—".to_string(),
            },
            pair(m.image_rms, o.image_rms, 4),
        );
    }
}

/// The Skip Strips and MTS figures the MTS paper prints for the bunny
/// (Tables 3 and 4, 550 MHz Pentium III): triangles, Skip Strips vertices,
/// MTS vertices. A printed reference, not a measurement.
const PAPER_TABLE_3: [(&str, &str, &str); 3] = [
    ("10.2K", "22K", "23K"),
    ("50.8K", "83K", "71K"),
    ("69.4K", "92K", "83K"),
];

/// The immediate-mode Figure 6 row of `method` at the share of `at`
/// (`None` when not measured).
pub fn figure6_row<'r>(
    rows: &'r [Figure6Row],
    at: &Figure6Row,
    method: &str,
) -> Option<&'r Figure6Row> {
    rows.iter()
        .find(|y| y.share == at.share && y.method == method && y.mode == "immediate")
}

/// The scale section's table and fitted exponents (the report's and the
/// README's).
pub fn scale_table(s: &mut String, scale: &Scale) {
    let _ = writeln!(s, "Stripify and simplify (whole sequence) each timed alone, beside meshoptimizer's `stripify` and `simplify` to 10%; build is the whole pipeline (stripify beside simplify, then the model).\n");
    let _ = writeln!(s, "| triangles | stripify ms (mts / meshopt) | simplify ms (mts whole / meshopt to 10%) | build ms | model bytes (per triangle) | .mts bytes, coded / uncoded | load ms (decode, parse, validate, extractor ready), coded / uncoded | peak RSS bytes (process so far) | LoD 0 extraction µs |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
    for r in &scale.rows {
        let _ = writeln!(
            s,
            "| {} | {:.0} / {:.0} | {:.0} / {:.0} | {:.0} | {} ({:.1}) | {} / {} | {:.1} / {:.1} | {} | {:.0} |",
            r.triangles,
            r.stripify_ms,
            r.meshopt_stripify_ms,
            r.simplify_ms,
            r.meshopt_simplify_to_10_ms,
            r.build_ms,
            r.model_bytes,
            r.model_bytes as f64 / r.triangles.max(1) as f64,
            r.coded_file_bytes,
            r.file_bytes,
            r.coded_load_ms,
            r.load_ms,
            r.peak_rss_bytes,
            r.extract_lod0_us,
        );
    }
    let e = &scale.exponent;
    let _ = writeln!(
        s,
        "\nFitted growth exponents (y ~ triangles^k): stripify {:.2} (meshoptimizer {:.2}), simplify {:.2} (meshoptimizer to 10% {:.2}), build {:.2}, model bytes {:.2}, load {:.2}, LoD 0 extraction {:.2}.",
        e.stripify_ms,
        e.meshopt_stripify_ms,
        e.simplify_ms,
        e.meshopt_simplify_to_10_ms,
        e.build_ms,
        e.model_bytes,
        e.load_ms,
        e.extract_lod0_us,
    );
}

/// The per-model strips table (the report's and the README's): the
/// project's strips against meshoptimizer's on each input mesh.
pub fn strips_table(s: &mut String, models: &[Model]) {
    let _ = writeln!(
        s, "The project's stripifier (adjacency included) against meshoptimizer's `optimize_vertex_cache_strip` + `stripify` on the input mesh, restart encoding; medians of interleaved runs. Each cell: mts / meshopt.\n");
    let _ = writeln!(
        s, "| model | triangles | strips | swaps | indices (restart) | indices per triangle | ACMR | ms |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    for r in models {
        let (a, b) = (&r.stripify.mts, &r.stripify.meshopt);
        let _ = writeln!(
            s,
            "| {} | {} | {} / {} | {} / {} | {} / {} | {:.4} / {:.4} | {:.3} / {:.3} | {:.1} / {:.1} |",
            r.name,
            a.triangles,
            a.strips,
            b.strips,
            a.swaps,
            b.swaps,
            a.indices_restart,
            b.indices_restart,
            a.indices_per_triangle,
            b.indices_per_triangle,
            a.acmr,
            b.acmr,
            a.ms,
            b.ms,
        );
    }
}

/// Most a strip set's modelled vertex work may exceed the ordered list's
/// and still count as matching it (issue 24's figure).
pub const CACHE_AWARE_SLACK: f64 = 0.05;

/// Per model, issue 24's figure for the cache-aware strips: (indices below
/// meshoptimizer's strips, FIFO 16 within [`CACHE_AWARE_SLACK`] of the
/// ordered list, batch 96 within it).
pub fn cache_aware_verdict(r: &Model) -> (bool, bool, bool) {
    let st = &r.stripify;
    let c = &st.cache_aware;
    (
        c.indices_per_triangle < st.meshopt.indices_per_triangle,
        c.acmr <= st.list_acmr + CACHE_AWARE_SLACK,
        c.acmr_batch96 <= st.list_acmr_batch96 + CACHE_AWARE_SLACK,
    )
}

/// The report's table of the cache-aware strips against meshoptimizer's
/// strips and ordered list.
pub fn cache_aware_table(s: &mut String, models: &[Model]) {
    let _ = writeln!(s, "\n### Cache-aware strips (`mts strips --cache-aware`)\n");
    let _ = writeln!(s, "Rows laid around the last row's vertices (`strip/stripify/cache.rs`) against meshoptimizer's strips (indices) and meshoptimizer's cache-ordered triangle list (modelled vertex work: FIFO of 16 over the triangle order, batches of 96 indices over the buffer, restart values counted). The figure (issue 24): fewer indices per triangle than meshoptimizer's strips, and both models at most the list's + {CACHE_AWARE_SLACK}. Columns: cache-aware / meshoptimizer's strips / the default stripifier; cache-aware / ordered list / meshoptimizer's strips.\n");
    let _ = writeln!(s, "| model | indices per triangle | FIFO 16 | batch 96 | ms | indices below / FIFO 16 / batch 96 met |");
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    let yes = |b: bool| if b { "yes" } else { "**no**" };
    for r in models {
        let st = &r.stripify;
        let (c, m, d) = (&st.cache_aware, &st.meshopt, &st.mts);
        let (i, f, b) = cache_aware_verdict(r);
        let _ = writeln!(
            s,
            "| {} | {:.3} / {:.3} / {:.3} | {:.3} / {:.3} / {:.3} | {:.3} / {:.3} / {:.3} | {:.1} | {} / {} / {} |",
            r.name,
            c.indices_per_triangle,
            m.indices_per_triangle,
            d.indices_per_triangle,
            c.acmr,
            st.list_acmr,
            m.acmr,
            c.acmr_batch96,
            st.list_acmr_batch96,
            m.acmr_batch96,
            c.ms,
            yes(i),
            yes(f),
            yes(b),
        );
    }
}

/// "CPU (N cores), OS" and the graphics adapter (or why there is none),
/// for the report's and the README's first lines.
pub fn machine_words(results: &Results) -> (String, String) {
    let m = &results.machine;
    (
        format!("{} ({} cores), {}", m.cpu, m.cores, m.os),
        m.adapter
            .as_deref()
            .or(m.adapter_note.as_deref())
            .unwrap_or("none")
            .to_string(),
    )
}

/// `report.md` from the results.
pub fn report(results: &Results) -> String {
    let mut s = String::new();
    let (machine, adapter) = machine_words(results);
    let models = &results.models;
    let _ = writeln!(s, "# mts bench report\n");
    let _ = writeln!(
        s,
        "Command: `{}`, {:.0} s. Machine: {machine}. Graphics adapter (Figure 6): {adapter}.\n",
        results.command, results.elapsed_s,
    );
    let _ = writeln!(s, "## Table 1: models and sizes (bytes)\n");
    let _ = writeln!(s, "The `.mts` file holds coarse chunks at 1% and 10% of the triangles, then the model ready to walk, coded (version 6, what `mts build` writes; uncoded, version 3, beside it); prefix 10% / 50% is the share of that file a reader needs before it can draw 10% / 50% of the triangles (`mts extract --bytes N`); the recipe-only file (`mts build --recipe-only`) loads by building the graphs again. Memory is the model's arrays with its vertices and their properties.\n");
    let _ = writeln!(s, "| model | strips | triangles | vertices | LoDs | bands | raw (12/vertex + 12/triangle) | raw 16-bit (12 + 6) | .mts file | .mts / raw | prefix 10% / 50% | uncoded .mts / raw | recipe-only .mts / raw | MTS in memory | memory / raw | memory bytes / triangle | build ms (stripify ‖ simplify, model, total) |");
    let _ = writeln!(
        s,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for r in models {
        let (b, t) = (&r.bytes, &r.build_ms);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} | {:.1}% / {:.0}% | {:.2} | {:.2} | {} | {:.2} | {:.1} | {:.0} ‖ {:.0}, {:.0}, {:.0} |",
            r.name,
            r.strips,
            r.triangles,
            r.vertices,
            r.max_lod + 1,
            r.bands,
            b.raw,
            b.raw_u16,
            b.mts_file,
            b.mts_file as f64 / b.raw as f64,
            100.0 * b.prefix_bytes_10 as f64 / b.mts_file.max(1) as f64,
            100.0 * b.prefix_bytes_50 as f64 / b.mts_file.max(1) as f64,
            b.mts_file_uncompressed as f64 / b.raw as f64,
            b.mts_recipe_file as f64 / b.raw as f64,
            b.mts_memory,
            b.mts_memory as f64 / b.raw as f64,
            b.mts_memory as f64 / r.triangles.max(1) as f64,
            t.stripify,
            t.simplify,
            t.model,
            t.total,
        );
    }
    let _ = writeln!(
        s,
        "\n### Table 1, renewal: the single band, bands and strips with lifetimes\n"
    );
    super::renewal::table(&mut s, models);
    let _ = writeln!(s, "\n## Strips against meshoptimizer\n");
    strips_table(&mut s, models);
    cache_aware_table(&mut s, models);
    let _ = writeln!(s, "\n### Table 1, every method: bytes and build time\n");
    let _ = writeln!(s, "File bytes against the raw mesh with 16-bit indices (12 per vertex + 6 per triangle, the cluster-tree paper's reference). MTS builds the whole pipeline; the baselines start from the mesh and MTS's contraction sequence (the cluster tree makes its own clustering). Multilevel has no file format of its own: its figure is the in-memory structure. Load: median of 5, from the file's bytes in memory to a source ready for its first LoD (MTS: parse, validate, extractor; progressive mesh: parse; cluster tree: decode the whole packet stream, its receiver's work); multilevel and discrete LoDs have no file reader.\n");
    let _ = writeln!(
        s,
        "| model | method | file bytes | file / raw 16-bit | memory bytes | memory bytes / triangle | load ms | build ms |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    for r in models {
        for m in &r.methods {
            let _ = match m {
                MethodRow::Measured(m) => writeln!(
                    s,
                    "| {} | {} | {} | {:.3} | {} | {:.1} | {} | {:.0} |",
                    r.name,
                    m.method,
                    m.file_bytes,
                    m.file_ratio_to_raw_u16,
                    m.memory_bytes,
                    m.memory_bytes as f64 / r.triangles.max(1) as f64,
                    m.load_ms
                        .map_or("no reader".to_string(), |ms| format!("{ms:.2}")),
                    m.build_ms,
                ),
                MethodRow::Skipped { method, skipped } => {
                    writeln!(
                        s,
                        "| {} | {method} | skipped: {skipped} | | | | | |",
                        r.name
                    )
                }
            };
        }
    }
    let _ = writeln!(s, "\n## Table 2: microseconds per LoD change\n");
    let _ = writeln!(s, "Sequences of `mts::model::requests` (linear: coarsest to finest in equal steps; exponential: triangle counts in geometric steps; random: uniform, seed 1); medians of five passes each, with and without coherence interleaved, each from a fresh extractor (its construction not timed).\n");
    let _ = writeln!(s, "| model | linear coherent | linear without | × | exponential coherent | exponential without | × | random coherent | random without | × |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for r in models {
        let mut row = format!("| {} |", r.name);
        for seq in ["linear", "exponential", "random"] {
            let (c, w) = r.extraction.get(seq).map_or((f64::NAN, f64::NAN), |e| {
                (e.mts_coherent_us, e.mts_scratch_us)
            });
            let _ = write!(row, " {c:.1} | {w:.1} | {:.1} |", w / c);
        }
        let _ = writeln!(s, "{row}");
    }
    let _ = writeln!(
        s,
        "\n### Table 2, every method: microseconds per LoD change\n"
    );
    let _ = writeln!(s, "Each method through `LodSource::set_lod` (MTS: the coherent extractor; from scratch: every strip walked at each request, with the scratch/coherent ratio), the same sequences over its own LoD range, in one run. The cluster tree's LoDs are its own joins; discrete LoDs only switch buffers.\n");
    let _ = writeln!(s, "| model | method | linear | exponential | random |");
    let _ = writeln!(s, "|---|---|---|---|---|");
    for r in models {
        for m in &r.methods {
            if let MethodRow::Measured(m) = m {
                let u = |seq: &str| m.us_per_change.get(seq).copied().unwrap_or(f64::NAN);
                let _ = writeln!(
                    s,
                    "| {} | {} | {:.1} | {:.1} | {:.1} |",
                    r.name,
                    m.method,
                    u("linear"),
                    u("exponential"),
                    u("random"),
                );
                if let Some(scratch) = &m.us_per_change_scratch {
                    // The same requests from scratch, and what coherence
                    // saves (scratch / coherent).
                    let c = |seq: &str| {
                        let x = scratch.get(seq).copied().unwrap_or(f64::NAN);
                        format!("{x:.1} ({:.2}×)", x / u(seq))
                    };
                    let _ = writeln!(
                        s,
                        "| {} | mts from scratch | {} | {} | {} |",
                        r.name,
                        c("linear"),
                        c("exponential"),
                        c("random"),
                    );
                }
            }
        }
    }
    let _ = writeln!(
        s,
        "\n## Tables 3–4: indices sent per level (ACMR, 16-entry FIFO)\n"
    );
    let _ = writeln!(s, "MTS strips with restart values, the triangle list (`optimize_vertex_cache` order) and meshoptimizer's strips of that level's mesh (`optimize_vertex_cache_strip` + `stripify`), measured on the same LoD.\n");
    let _ = writeln!(s, "| model | share | triangles | MTS indices | list indices | meshopt strip indices | MTS / meshopt | ACMR MTS / list / meshopt strips | extract µs (from scratch) |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
    for r in models {
        for l in &r.levels {
            let _ = writeln!(
                s,
                "| {} | {:.0}% | {} | {} | {} | {} | {:.3} | {:.3} / {:.3} / {:.3} | {:.1} |",
                r.name,
                l.share * 100.0,
                l.triangles,
                l.mts_indices,
                l.list_indices,
                l.meshopt_strip_indices,
                l.mts_indices as f64 / l.meshopt_strip_indices as f64,
                l.mts_acmr,
                l.list_acmr,
                l.meshopt_strip_acmr,
                l.extract_us,
            );
        }
    }
    vertex_table(&mut s, results.vertex_work.as_ref());
    let _ = writeln!(s, "\nPrinted reference, not measured here: the MTS paper's Table 3 for the bunny (vertices sent): Skip Strips / MTS —");
    for (t, skip, ours) in PAPER_TABLE_3 {
        let _ = write!(s, " {t} triangles: {skip} / {ours};");
    }
    let _ = writeln!(
        s,
        "\n\n## Quality: simplification error against meshoptimizer\n"
    );
    let _ = writeln!(s, "Hausdorff and RMS distance to the input relative to its bounding-box diagonal ({SAMPLES} samples per side), meshoptimizer's `simplify` asked for the same triangle count (where it stops above it, the project's LoD is taken at its count).\n");
    let peer = match &results.fast_simplification {
        Some(FastSimplificationRun::Rows(rows)) => Some(rows),
        Some(FastSimplificationRun::Skipped { skipped }) => {
            let _ = writeln!(s, "fast-simplification not measured: {skipped}.\n");
            None
        }
        None => None,
    };
    let _ = writeln!(s, "Speed: the project's whole contraction sequence (every LoD, default options) against meshoptimizer's `simplify` to 10% and to 1%, medians of interleaved runs in milliseconds.\n");
    let _ = writeln!(s, "| model | triangles | contractions | mts whole sequence | meshopt to 10% | meshopt to 1% | stopped |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    for r in models {
        let x = &r.simplify;
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1} | {:.1} | {:.1} | {} |",
            r.name, r.triangles, x.max_lod, x.ms, x.meshopt_ms_to_10, x.meshopt_ms_to_1, x.stop,
        );
    }
    let _ = writeln!(s);
    let _ = writeln!(s, "| model | share | triangles (mts / meshopt) | Hausdorff mts | Hausdorff meshopt | ratio | RMS mts | RMS meshopt | fast-simplification triangles, Hausdorff, RMS |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
    for r in models {
        for q in &r.quality {
            let fast = peer
                .into_iter()
                .flatten()
                .find(|p| p.mesh == r.name && p.ratio == q.share)
                .map_or_else(
                    || "—".to_string(),
                    |p| format!("{}, {:.5}, {:.5}", p.triangles, p.hausdorff, p.rms),
                );
            let _ = writeln!(
                s,
                "| {} | {:.0}% | {} / {} | {:.5} | {:.5} | {:.2} | {:.5} | {:.5} | {fast} |",
                r.name,
                q.share * 100.0,
                q.mts.triangles,
                q.meshopt.triangles,
                q.mts.hausdorff,
                q.meshopt.hausdorff,
                q.mts.hausdorff / q.meshopt.hausdorff,
                q.mts.rms,
                q.meshopt.rms,
            );
        }
    }
    property_table(&mut s, &results.properties);
    if models.iter().any(|r| r.figure6.is_some()) {
        let _ = writeln!(
            s,
            "\n## Figure 6: frames per second against the share of triangles\n"
        );
        let _ = writeln!(s, "Immediate: a LoD change (extraction and upload) before every frame. Per second: one extraction (MTS from scratch; the list replayed and put in meshoptimizer's cache order) and upload per second, drawing in between. The list is meshoptimizer-ordered; MTS draws strips with primitive restart.\n");
        let _ = writeln!(s, "Each cell: immediate / one extraction per second. The baselines (through `LodSource`) upload their whole index buffer per change and are asked for their finest LoD within the MTS level's triangles.\n");
        let _ = writeln!(
            s,
            "| model | share | triangles | mts | list | pm | multilevel | cluster | discrete |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
        for r in models {
            let rows = r.figure6.as_ref().map_or(&[][..], |f| &f.rows[..]);
            let mut shares: Vec<f64> = Vec::new();
            for x in rows {
                if !shares.contains(&x.share) {
                    shares.push(x.share);
                }
            }
            for share in shares {
                let cell = |method: &str| {
                    let fps = |mode: &str| {
                        rows.iter()
                            .find(|x| x.share == share && x.method == method && x.mode == mode)
                            .map_or(f64::NAN, |x| x.fps)
                    };
                    format!("{:.1} / {:.1}", fps("immediate"), fps("per_second"))
                };
                let triangles = rows
                    .iter()
                    .find(|x| x.share == share && x.method == "mts")
                    .map_or_else(|| "null".to_string(), |x| x.triangles.to_string());
                let _ = writeln!(
                    s,
                    "| {} | {:.0}% | {} | {} | {} | {} | {} | {} | {} |",
                    r.name,
                    share * 100.0,
                    triangles,
                    cell("mts"),
                    cell("list"),
                    cell("pm"),
                    cell("multilevel"),
                    cell("cluster"),
                    cell("discrete"),
                );
            }
        }
    }
    if models.iter().any(|r| r.figure6.is_some()) {
        let _ = writeln!(s, "\n### Figure 6, draw time per frame\n");
        let _ = writeln!(s, "The same runs: the median time of one frame drawn without a LoD change (submit and wait), MTS strips against the meshoptimizer-ordered list, and the median time of one MTS LoD change (extraction and dirty-range upload, one LoD step back and forth).\n");
        let _ = writeln!(s, "| model | share | triangles | indices mts / list | draw ms mts / list | Mtri/s mts / list | MTS LoD change µs |");
        let _ = writeln!(s, "|---|---|---|---|---|---|---|");
        for r in models {
            let rows = r.figure6.as_ref().map_or(&[][..], |f| &f.rows[..]);
            for x in rows
                .iter()
                .filter(|x| x.method == "mts" && x.mode == "immediate")
            {
                let list = figure6_row(rows, x, "list");
                let list_ms = list.map_or(f64::NAN, |l| l.draw_ms);
                let tri = x.triangles as f64;
                let _ = writeln!(
                    s,
                    "| {} | {:.0}% | {} | {} / {} | {:.2} / {:.2} | {:.2} / {:.2} | {:.0} |",
                    r.name,
                    x.share * 100.0,
                    x.triangles,
                    x.indices_sent,
                    list.map_or_else(|| "null".to_string(), |l| l.indices_sent.to_string()),
                    x.draw_ms,
                    list_ms,
                    tri / x.draw_ms / 1e3,
                    tri / list_ms / 1e3,
                    x.change_us.unwrap_or(f64::NAN),
                );
            }
        }
    }
    scene_table(&mut s, &results.scenes);
    view_dependent_section(&mut s, results);
    if let Some(scale) = &results.scale {
        let _ = writeln!(s, "\n## Scale: generated icospheres\n");
        scale_table(&mut s, scale);
    }
    s
}

/// Writes `report.md` and `results.json` into `dir` (created if needed),
/// after checking that `results` reads back ([`Results::from_value`]): a
/// NaN the bench produced is written as `null`, which stops here with the
/// key named.
///
/// # Errors
/// When `results` holds a NaN, or a file cannot be written.
pub fn write(dir: &Path, results: &Results) -> Result<()> {
    Results::from_value(serde_json::to_value(results)?)?;
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let json_path = dir.join("results.json");
    mts::output::write_file(
        &json_path,
        serde_json::to_string_pretty(results)?.as_bytes(),
    )?;
    let charts = super::charts::write_all(dir, results)?;
    let mut text = report(results);
    if !charts.is_empty() {
        let _ = writeln!(text, "\n## Charts\n");
        for c in &charts {
            if let Some(name) = c.file_name() {
                let name = name.to_string_lossy();
                let _ = writeln!(text, "![{name}]({name})\n");
            }
        }
    }
    let md = dir.join("report.md");
    mts::output::write_file(&md, text.as_bytes())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The report written from the committed results.json is the committed
    /// report.md, byte for byte.
    #[test]
    fn the_committed_report_is_what_its_data_gives() {
        let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/report"));
        let results = crate::bench::results::Results::load(&dir.join("results.json")).unwrap();
        let mut text = report(&results);
        let _ = writeln!(text, "\n## Charts\n");
        let mut names = vec![
            "indices",
            "figure6_immediate",
            "figure6_per_second",
            "scale",
        ];
        if !results.view_dependent.is_empty() {
            names.push("view_dependent");
        }
        for name in names {
            let _ = writeln!(text, "![{name}.png]({name}.png)\n");
        }
        let committed = std::fs::read_to_string(dir.join("report.md")).unwrap();
        let first = text
            .lines()
            .zip(committed.lines())
            .position(|(a, b)| a != b);
        assert!(
            text == committed,
            "report.md differs from what results.json gives, first at line {:?}:\n{:?}\n{:?}",
            first.map(|i| i + 1),
            first.and_then(|i| text.lines().nth(i)),
            first.and_then(|i| committed.lines().nth(i)),
        );
    }

    /// A `mts bench --quick` run's results.json (`tests/data/bench_quick.json`;
    /// a schema change fails here until it is made again with `mts bench
    /// --quick --out DIR`): `bench check --quick` accepts it, and its report
    /// has the view-dependent section after the scene, a row per method, the
    /// chart, and the README summary's line.
    #[test]
    fn a_quick_run_has_its_view_dependent_section() {
        use crate::bench::results::VIEW_DEPENDENT_METHODS;
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/bench_quick.json");
        let results = Results::load(Path::new(path)).unwrap();
        assert_eq!(
            crate::bench::check::check(&results, true),
            Vec::<String>::new()
        );
        let dir = std::env::temp_dir().join(format!("mts-report-quick-{}", std::process::id()));
        write(&dir, &results).unwrap();
        let text = std::fs::read_to_string(dir.join("report.md")).unwrap();
        let chart = dir.join("view_dependent.png").is_file();
        std::fs::remove_dir_all(&dir).ok();
        assert!(chart, "no view_dependent.png");
        let (scene, at) = (
            text.find("\n## Scene:").expect("the scene section"),
            text.find("\n## View-dependent detail\n")
                .expect("the view-dependent section"),
        );
        assert!(scene < at);
        let section = &text[at..];
        let section = &section[..section[1..].find("\n## ").map_or(section.len(), |i| i + 1)];
        assert!(
            section.contains("### generated terrain:100000: 100352 triangles, 120 frames flying over it, 320×180 pixels"),
            "{section}"
        );
        for m in VIEW_DEPENDENT_METHODS {
            assert!(
                section.contains(&format!("\n| {m} | 1 | ")),
                "{m}: {section}"
            );
        }
        assert!(text.contains("![view_dependent.png](view_dependent.png)"));
        let summary = crate::bench::summary::summary(&results, "dir");
        assert!(
            summary.contains("View-dependent detail (generated terrain:100000, 1 px")
                && summary.contains("![view_dependent](dir/view_dependent.png)"),
            "{summary}"
        );
    }
}
