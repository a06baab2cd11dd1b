//! `mts bench summary`: the README's "Latest bench report" section, made
//! from a `results.json` so that every figure the README quotes is a row
//! of a report this command produced.
//!
//! The section sits between [`BEGIN`] and [`END`] in the README;
//! `--readme` rewrites it there, `--check` fails when it differs from what
//! the data gives (a test runs that on the committed report).

use super::charts::view_dependent_focus;
use super::report::{figure6_row, machine_words};
use crate::bench::results::{MethodRow, Model, Results, ScaleRow};
use std::fmt::Write as _;

/// First line of the generated section in the README.
pub const BEGIN: &str = "<!-- BEGIN mts bench summary: generated from the report's results.json by `mts bench summary`; edit the generator, not this block -->";
/// Last line of the generated section in the README.
pub const END: &str = "<!-- END mts bench summary -->";

/// The model the single-model tables describe: the bunny when measured,
/// otherwise the first one.
fn focus(models: &[Model]) -> Option<&Model> {
    models
        .iter()
        .find(|m| m.name == "bunny.ply")
        .or_else(|| models.first())
}

/// The scale row closest to `triangles`.
fn scale_row(results: &Results, triangles: f64) -> Option<&ScaleRow> {
    results.scale.as_ref()?.rows.iter().min_by(|a, b| {
        (a.triangles as f64 - triangles)
            .abs()
            .total_cmp(&(b.triangles as f64 - triangles).abs())
    })
}

/// One number of a scale row.
type Column = fn(&ScaleRow) -> f64;

/// The "met" cell: `None` when this machine cannot show the figure.
fn yes(met: Option<bool>) -> &'static str {
    match met {
        Some(true) => "yes",
        Some(false) => "**no**",
        None => "not measurable here",
    }
}

/// The measured methods of a model (skipped ones left out).
fn measured(m: &Model) -> impl Iterator<Item = &crate::bench::results::Method> {
    m.methods.iter().filter_map(|x| match x {
        MethodRow::Measured(x) => Some(x),
        MethodRow::Skipped { .. } => None,
    })
}

/// The Markdown section (between [`BEGIN`] and [`END`], both included)
/// for `results`; `report_dir` is where the report lies, relative to the
/// README (links and charts).
#[must_use]
pub fn summary(results: &Results, report_dir: &str) -> String {
    let mut s = String::new();
    let models = &results.models;
    let _ = writeln!(s, "{BEGIN}\n");
    let elapsed = format!(" in {:.0} s", results.elapsed_s);
    let (machine, adapter) = machine_words(results);
    let _ = writeln!(
        s,
        "Produced by `{}`{elapsed} on {machine}; graphics adapter: {adapter}. The whole report is [{report_dir}/report.md]({report_dir}/report.md), its data `{report_dir}/results.json` (schema `docs/bench-schema.md`). Every figure below is copied from that data by `mts bench summary {report_dir}/results.json --readme README.md`, and `crates/mts-cli/tests/readme.rs` fails when this section and the data disagree. Timings are medians of runs interleaved with the peer they are compared with; the machine is shared, so compare within a row.\n",
        results.command,
    );
    targets(&mut s, results, models);
    // The per-model tables (strips, simplification, its peers) and the
    // scale rows stay in the report: the README keeps the targets and the
    // focus model.
    let _ = writeln!(
        s,
        "Per model ({} in this run): strips, simplification against meshoptimizer (and fast-simplification where it ran) and the scale rows are tables of [the report]({report_dir}/report.md).\n",
        models.len()
    );
    if let Some(b) = focus(models) {
        levels(&mut s, b, models);
        methods(&mut s, b, models);
        render(&mut s, results, b);
    }
    view_dependent(&mut s, results, report_dir);
    // The charts `mts bench` draws from the same data.
    let mut charts = Vec::new();
    if let Some(b) = focus(models) {
        charts.push("indices");
        if b.figure6.is_some() {
            charts.extend(["figure6_immediate", "figure6_per_second"]);
        }
    }
    if results.scale.is_some() {
        charts.push("scale");
    }
    if view_dependent_focus(&results.view_dependent).is_some() {
        charts.push("view_dependent");
    }
    let images: Vec<String> = charts
        .iter()
        .map(|chart| format!("![{chart}]({report_dir}/{chart}.png)"))
        .collect();
    if !images.is_empty() {
        let _ = writeln!(s, "{}\n", images.join(" "));
    }
    let _ = writeln!(s, "{END}");
    s
}

/// One row of the targets table.
fn row_if(s: &mut String, figure: &str, target: &str, measured: String, met: Option<bool>) {
    let _ = writeln!(s, "| {figure} | {target} | {measured} | {} |", yes(met));
}

fn row(s: &mut String, figure: &str, target: &str, measured: String, met: bool) {
    row_if(s, figure, target, measured, Some(met));
}

/// The issues' figures, measured value against target.
fn targets(s: &mut String, results: &Results, models: &[Model]) {
    let _ = writeln!(s, "### Targets\n");
    let _ = writeln!(s, "| figure | target | measured | met |");
    let _ = writeln!(s, "|---|---|---|---|");
    let files: Vec<&Model> = models
        .iter()
        .filter(|m| !m.name.starts_with("generated"))
        .collect();
    if !files.is_empty() {
        let worst = files
            .iter()
            .map(|m| {
                let x = &m.stripify;
                (
                    x.mts.indices_per_triangle / x.meshopt.indices_per_triangle,
                    m.name.as_str(),
                )
            })
            .max_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((ratio, worst)) = worst {
            row(
                s,
                "strips: indices per triangle against meshoptimizer's, every model",
                "lower on every model",
                format!("{} models, highest ratio {ratio:.3} ({worst})", files.len()),
                ratio < 1.0,
            );
        }
        let n = files.len();
        let verdicts: Vec<(bool, bool, bool)> = files
            .iter()
            .map(|m| super::report::cache_aware_verdict(m))
            .collect();
        let count = |f: fn(&(bool, bool, bool)) -> bool| verdicts.iter().filter(|v| f(v)).count();
        let (i, f, b) = (count(|v| v.0), count(|v| v.1), count(|v| v.2));
        let largest =
            |g: fn(&Model) -> f64| files.iter().map(|m| g(m)).fold(f64::NEG_INFINITY, f64::max);
        row(
            s,
            "cache-aware strips (`--cache-aware`): indices per triangle below meshoptimizer's strips, and FIFO 16 and batch 96 within +0.05 of the meshoptimizer-ordered list, every model",
            "all three on every model",
            format!(
                "indices below on {i} of {n} (highest ratio {:.3}); FIFO 16 within on {f} (largest gap {:+.3}); batch 96 within on {b} (largest gap {:+.3})",
                largest(|m| m.stripify.cache_aware.indices_per_triangle
                    / m.stripify.meshopt.indices_per_triangle),
                largest(|m| m.stripify.cache_aware.acmr - m.stripify.list_acmr),
                largest(|m| m.stripify.cache_aware.acmr_batch96 - m.stripify.list_acmr_batch96),
            ),
            i == n && f == n && b == n,
        );
        let mut above = Vec::new();
        let mut rows = 0;
        for m in &files {
            for q in &m.quality {
                rows += 1;
                let r = q.mts.hausdorff / q.meshopt.hausdorff;
                // Both exact (0 / 0) counts as equal.
                if r > 1.15 {
                    above.push(format!("{} {:.0}% {r:.2}", m.name, q.share * 100.0));
                }
            }
        }
        row(
            s,
            "simplify: Hausdorff at 10% and 1% against meshoptimizer's, every model",
            "≤ 1.15 ×",
            if above.is_empty() {
                format!("{rows} rows, none above")
            } else {
                format!("{} of {rows} rows above: {}", above.len(), above.join(", "))
            },
            above.is_empty(),
        );
    }
    if let Some(b) = models.iter().find(|m| m.name == "bunny.ply") {
        let x = &b.stripify;
        row(
            s,
            "bunny: indices per triangle (restart)",
            "≤ 1.20",
            format!("{:.4}", x.mts.indices_per_triangle),
            x.mts.indices_per_triangle <= 1.20,
        );
        row(
            s,
            "bunny: stripify",
            "< 30 ms",
            format!("{:.1} ms (meshoptimizer {:.1} ms)", x.mts.ms, x.meshopt.ms),
            x.mts.ms < 30.0,
        );
        let y = &b.simplify;
        row(
            s,
            "bunny: whole contraction sequence",
            "< 150 ms",
            format!(
                "{:.0} ms (meshoptimizer to 10%: {:.0} ms)",
                y.ms, y.meshopt_ms_to_10
            ),
            y.ms < 150.0,
        );
        let ratio = b.bytes.mts_file as f64 / b.bytes.raw as f64;
        row(
            s,
            "bunny: .mts file (ready to walk, coded) against the raw mesh (12 + 12 bytes)",
            "≤ 1.5 ×",
            format!(
                "{ratio:.2} × (uncoded: {:.2} ×; recipe only, which loads by building: {:.2} ×)",
                b.bytes.mts_file_uncompressed as f64 / b.bytes.raw as f64,
                b.bytes.mts_recipe_file as f64 / b.bytes.raw as f64
            ),
            ratio <= 1.5,
        );
        let prefix = b.bytes.prefix_bytes_10 as f64 / b.bytes.mts_file.max(1) as f64;
        row(
            s,
            "bunny: share of the .mts file that opens and draws 10% of the triangles",
            "≤ 15%",
            format!(
                "{:.1}% ({} bytes; 50%: {:.0}%)",
                100.0 * prefix,
                b.bytes.prefix_bytes_10,
                100.0 * b.bytes.prefix_bytes_50 as f64 / b.bytes.mts_file.max(1) as f64
            ),
            prefix <= 0.15,
        );
        let memory = b.bytes.mts_memory as f64 / b.bytes.raw as f64;
        row(
            s,
            "bunny: MTS model in memory against the raw mesh",
            "≤ 3 ×",
            format!("{memory:.2} × ({} bytes)", b.bytes.mts_memory),
            memory <= 3.0,
        );
        let load = b.methods.iter().find_map(|m| match m {
            MethodRow::Measured(m) if m.method == "mts" => m.load_ms,
            _ => None,
        });
        if let Some(load) = load {
            row(
                s,
                "bunny: load of the coded file (decoded, parsed, validated, extractor ready)",
                "< 10 ms",
                format!("{load:.1} ms"),
                load < 10.0,
            );
        }
        let gain = |seq: &str| {
            b.extraction
                .get(seq)
                .map_or(f64::NAN, |e| e.mts_scratch_us / e.mts_coherent_us)
        };
        let (lin, exp, rnd) = (gain("linear"), gain("exponential"), gain("random"));
        row(
            s,
            "bunny: coherent extraction against from scratch, linear / exponential / random",
            "≥ 20 × / ≥ 10 × / ≥ 1 ×",
            format!("{lin:.1} × / {exp:.1} × / {rnd:.2} ×"),
            lin >= 20.0 && exp >= 10.0 && rnd >= 1.0,
        );
        row(
            s,
            "bunny: build (strips, sequence, model)",
            "< 500 ms",
            format!("{:.0} ms", b.build_ms.total),
            b.build_ms.total < 500.0,
        );
        if let Some(l0) = b.levels.first() {
            row(
                s,
                "bunny: LoD 0 extracted from scratch",
                "< 0.5 ms",
                format!("{:.0} µs", l0.extract_us),
                l0.extract_us < 500.0,
            );
        }
        let changes: Vec<f64> = b
            .figure6
            .iter()
            .flat_map(|f| &f.rows)
            .filter_map(|x| x.change_us)
            .collect();
        if let Some(max) = changes.iter().copied().reduce(f64::max) {
            row(
                s,
                "bunny: one LoD change (extraction and upload), every share",
                "< 1 ms",
                format!("at most {max:.0} µs"),
                max < 1000.0,
            );
        }
    }
    if let Some(b) = focus(models) {
        let share = b
            .levels
            .iter()
            .map(|l| l.mts_indices as f64 / l.list_indices as f64)
            .reduce(f64::max);
        if let Some(share) = share {
            row(
                s,
                &format!(
                    "{}: indices sent by strips against the triangle list, every level",
                    b.name
                ),
                "≤ 50%",
                format!("at most {:.1}%", 100.0 * share),
                share <= 0.5,
            );
        }
    }
    if let Some(r) = scale_row(results, 1e6) {
        let t = r.triangles as f64;
        row(
            s,
            &format!("{t:.0}-triangle icosphere: stripify"),
            "< 1 s",
            format!(
                "{:.0} ms (meshoptimizer {:.0} ms)",
                r.stripify_ms, r.meshopt_stripify_ms
            ),
            r.stripify_ms < 1000.0,
        );
        row(
            s,
            &format!("{t:.0}-triangle icosphere: whole contraction sequence"),
            "< 3 s",
            format!(
                "{:.0} ms (meshoptimizer to 10%: {:.0} ms)",
                r.simplify_ms, r.meshopt_simplify_to_10_ms
            ),
            r.simplify_ms < 3000.0,
        );
        row(
            s,
            &format!("{t:.0}-triangle icosphere: build"),
            "< 10 s",
            format!("{:.1} s", r.build_ms / 1e3),
            r.build_ms < 10_000.0,
        );
        // A closed genus-0 mesh has triangles / 2 + 2 vertices.
        let raw = 12.0 * (t / 2.0 + 2.0) + 12.0 * t;
        let memory = r.model_bytes as f64 / raw;
        row(
            s,
            &format!("{t:.0}-triangle icosphere: MTS model in memory against the raw mesh"),
            "≤ 3 ×",
            format!(
                "{memory:.2} × ({:.1} bytes per triangle)",
                r.model_bytes as f64 / t
            ),
            memory <= 3.0,
        );
        row(
            s,
            &format!(
                "{t:.0}-triangle icosphere: load of the coded file (decode, parse, validate, \
                 extractor ready)"
            ),
            "< 150 ms",
            format!(
                "{:.0} ms (uncoded file: {:.0} ms)",
                r.coded_load_ms, r.load_ms
            ),
            r.coded_load_ms < 150.0,
        );
    }
    if let Some(scale) = &results.scale {
        let e = &scale.exponent;
        let (ours, theirs) = (e.stripify_ms, e.meshopt_stripify_ms);
        let per = |r: Option<&ScaleRow>, value: Column| {
            r.map_or(f64::NAN, |r| value(r) * 1e6 / r.triangles as f64)
        };
        let (first, last) = (scale.rows.first(), scale.rows.last());
        let ours_ms: Column = |r| r.stripify_ms;
        let theirs_ms: Column = |r| r.meshopt_stripify_ms;
        row(
            s,
            "stripify time against triangles (fitted exponent k of t ~ n^k over the scale rows)",
            "linear: k within 0.1 of meshoptimizer's, a linear-time stripifier on the same machine",
            format!(
                "k = {ours:.2} (meshoptimizer {theirs:.2}); {:.0} → {:.0} ns per triangle (meshoptimizer {:.0} → {:.0})",
                per(first, ours_ms),
                per(last, ours_ms),
                per(first, theirs_ms),
                per(last, theirs_ms),
            ),
            ours <= theirs + 0.1,
        );
    }
    if let Some(scene) = results
        .scenes
        .iter()
        .filter(|r| r.pixel_threshold == 1.0)
        .max_by_key(|r| r.instances)
    {
        row_if(
            s,
            &format!(
                "scene of {} instances of {} models on this adapter",
                scene.instances, scene.models
            ),
            "> 60 fps on a GPU; frame time on lavapipe",
            format!(
                "{:.1} ms = {:.0} fps ({:.0} visible)",
                scene.frame_ms_median,
                1e3 / scene.frame_ms_median,
                scene.visible
            ),
            // A CPU rasteriser (lavapipe) gives the frame time only.
            results
                .machine
                .adapter
                .as_deref()
                .filter(|a| !a.contains("Cpu") && !a.contains("llvmpipe"))
                .map(|_| scene.frame_ms_median < 1e3 / 60.0),
        );
    }
    if !results.quick {
        let e = results.elapsed_s;
        row(
            s,
            "the whole report over every model",
            "< 30 min",
            format!("{:.1} min", e / 60.0),
            e < 1800.0,
        );
    }
    let _ = writeln!(s);
}

fn levels(s: &mut String, b: &Model, models: &[Model]) {
    let _ = writeln!(s, "### Indices sent per level ({})\n", b.name);
    let _ = writeln!(s, "MTS strips extracted at each level, the level's triangle list, and meshoptimizer's strips of the level's mesh stripified afresh:\n");
    let _ = writeln!(
        s,
        "| share | triangles | MTS | list | meshopt strips | MTS / meshopt | MTS / list |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    for l in &b.levels {
        let _ = writeln!(
            s,
            "| {:.0}% | {} | {} | {} | {} | {:.3} | {:.3} |",
            l.share * 100.0,
            l.triangles,
            l.mts_indices,
            l.list_indices,
            l.meshopt_strip_indices,
            l.mts_indices as f64 / l.meshopt_strip_indices as f64,
            l.mts_indices as f64 / l.list_indices as f64,
        );
    }
    let worst = models
        .iter()
        .flat_map(|m| {
            m.levels
                .iter()
                .map(move |l| (l.mts_indices as f64 / l.list_indices as f64, m, l))
        })
        .max_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((share, m, l)) = worst {
        let _ = writeln!(
            s,
            "\nOver every model and level of the report, strips send at most {:.1}% of the list's indices ({} at {:.0}%, {} triangles: small levels of open or many-component meshes, where runs are short).",
            100.0 * share,
            m.name,
            l.share * 100.0,
            l.triangles,
        );
    }
    let _ = writeln!(s);
}

fn methods(s: &mut String, b: &Model, models: &[Model]) {
    let _ = writeln!(s, "### Every method ({})\n", b.name);
    let _ = writeln!(s, "File bytes against the raw mesh with 16-bit indices (12 per vertex + 6 per triangle), memory, build time and microseconds per LoD change on the linear, exponential and random request sequences, through `LodSource`:\n");
    let _ = writeln!(s, "| method | file bytes | / raw 16-bit | memory bytes | build ms | µs per change linear / exponential / random |");
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    for x in measured(b) {
        let u = |seq: &str| x.us_per_change.get(seq).copied().unwrap_or(f64::NAN);
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {} | {:.0} | {:.1} / {:.1} / {:.1} |",
            x.method,
            x.file_bytes,
            x.file_ratio_to_raw_u16,
            x.memory_bytes,
            x.build_ms,
            u("linear"),
            u("exponential"),
            u("random"),
        );
    }
    let _ = writeln!(s);
    let range = |method: &str| {
        let v: Vec<f64> = models
            .iter()
            .flat_map(measured)
            .filter(|x| x.method == method)
            .map(|x| x.file_ratio_to_raw_u16)
            .collect();
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo, hi, v.len())
    };
    let (clo, chi, n) = range("cluster");
    let (mlo, mhi, _) = range("multilevel");
    let (tlo, thi, _) = range("mts");
    if n > 0 {
        let _ = writeln!(s, "Over the {n} models, file / raw 16-bit: cluster-tree stream {:.1}% to {:.1}% (the cluster-tree paper: 79 to 89%), multilevel structure {mlo:.3} to {mhi:.3} (the paper's bound: 1.1), MTS {tlo:.3} to {thi:.3}.\n", 100.0 * clo, 100.0 * chi);
    }
    let _ = write!(
        s,
        "Coherence cache ({}, microseconds per LoD change with / without):",
        b.name
    );
    for seq in ["linear", "exponential", "random"] {
        let (c, w) = b.extraction.get(seq).map_or((f64::NAN, f64::NAN), |e| {
            (e.mts_coherent_us, e.mts_scratch_us)
        });
        let _ = write!(s, " {seq} {c:.1} / {w:.1} ({:.1} ×);", w / c);
    }
    let _ = writeln!(s, "\n");
}

fn render(s: &mut String, results: &Results, b: &Model) {
    let Some(figure6) = b.figure6.as_ref().filter(|f| !f.rows.is_empty()) else {
        let _ = writeln!(
            s,
            "### Rendering\n\nNot measured: {}.\n",
            results
                .machine
                .adapter_note
                .as_deref()
                .unwrap_or("no adapter")
        );
        return;
    };
    let rows = &figure6.rows;
    let _ = writeln!(s, "### Rendering ({}, Figure 6)\n", b.name);
    let _ = writeln!(s, "Frames per second with a LoD change before every frame (immediate) and with one extraction per second, per method; the draw alone (MTS strips against the meshoptimizer-ordered list) and one MTS LoD change (extraction and dirty-range upload). {} × {} pixels.\n", figure6.width, figure6.height);
    let _ = writeln!(s, "| share | triangles | indices mts / list | draw ms mts / list | LoD change µs | fps immediate: mts / list / pm / multilevel / cluster / discrete |");
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    for x in rows
        .iter()
        .filter(|x| x.method == "mts" && x.mode == "immediate")
    {
        let list = figure6_row(rows, x, "list");
        let fps: Vec<String> = ["mts", "list", "pm", "multilevel", "cluster", "discrete"]
            .iter()
            .map(|m| format!("{:.0}", figure6_row(rows, x, m).map_or(f64::NAN, |r| r.fps)))
            .collect();
        let _ = writeln!(
            s,
            "| {:.0}% | {} | {} / {} | {:.2} / {:.2} | {:.0} | {} |",
            x.share * 100.0,
            x.triangles,
            x.indices_sent,
            list.map_or_else(|| "null".to_string(), |l| l.indices_sent.to_string()),
            x.draw_ms,
            list.map_or(f64::NAN, |l| l.draw_ms),
            x.change_us.unwrap_or(f64::NAN),
            fps.join(" / "),
        );
    }
    for scene in results.scenes.iter().filter(|r| r.pixel_threshold == 1.0) {
        let _ = writeln!(s, "\nScene: {} instances of {} models, LoD by screen-space error (1 px) from buffers shared per LoD bucket, culled by the instance BVH, along a fly-through: {:.0} visible, {:.0} triangles ({:.1}% of full detail), update {:.2} ms median ({:.2} ms p99), frame {:.2} ms; {} CPU bytes per instance, GPU {:.2} × the full-detail strips; {} of the covered pixels differ from full detail.", scene.instances, scene.models, scene.visible, scene.triangles_drawn, 100.0 * scene.triangles_drawn / scene.triangles_full_detail.max(1.0), scene.update_ms_median, scene.update_ms_p99, scene.frame_ms_median, scene.cpu_bytes_per_instance, scene.gpu_bytes as f64 / scene.full_detail_strip_bytes.max(1) as f64, scene.differing_pixel_share.map_or("—".into(), |x| format!("{:.3}%", 100.0 * x)));
    }
    let _ = writeln!(s);
}

/// One paragraph on view-dependent detail: the strip hierarchy against
/// meshoptimizer's cluster LoD at 1 pixel on the chart's run.
fn view_dependent(s: &mut String, results: &Results, report_dir: &str) {
    let Some(run) = view_dependent_focus(&results.view_dependent) else {
        return;
    };
    let row = |method: &str| {
        run.methods
            .iter()
            .find(|r| r.method == method && r.pixel_threshold == 1.0)
    };
    let (Some(h), Some(c), Some(m)) = (row("mts_hierarchy"), row("clusterlod"), row("mts")) else {
        return;
    };
    let full = run.triangles_full_detail.max(1) as f64;
    let _ = writeln!(s, "View-dependent detail ({}, 1 px, {} frames {} it): the strip hierarchy draws {:.0} triangles a frame (median; {:.2}× meshoptimizer's cluster LoD, {:.1}% of full detail, where the per-object model draws {:.1}%) at {:.2} indices a triangle, updates in {:.2} ms median ({:.2} ms p99), with {} cracks and popping of at most {:.2} px; the cluster tree and the other inputs are in [the report]({report_dir}/report.md).\n",
        run.input,
        run.frames,
        if run.flight == "over" { "flying over" } else { "circling" },
        h.triangles_drawn_median,
        h.triangles_drawn_median / c.triangles_drawn_median,
        100.0 * h.triangles_drawn_median / full,
        100.0 * m.triangles_drawn_median / full,
        h.indices_per_triangle,
        h.update_ms_median,
        h.update_ms_p99,
        h.cracks,
        h.popping_px_max,
    );
}

/// `readme` with its generated section replaced by `section`; `None`
/// when the README has no [`BEGIN`] … [`END`] block.
#[must_use]
pub fn splice(readme: &str, section: &str) -> Option<String> {
    let start = readme.find(BEGIN)?;
    let end = readme[start..].find(END)? + start + END.len();
    let end = if readme[end..].starts_with('\n') {
        end + 1
    } else {
        end
    };
    Some(format!("{}{section}{}", &readme[..start], &readme[end..]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splice_replaces_only_the_block() {
        let readme = format!("intro\n{BEGIN}\nold\n{END}\noutro\n");
        let new = format!("{BEGIN}\nnew\n{END}\n");
        assert_eq!(
            splice(&readme, &new).unwrap(),
            format!("intro\n{BEGIN}\nnew\n{END}\noutro\n")
        );
        assert_eq!(splice("no block here", &new), None);
    }

    #[test]
    fn targets_report_misses_in_bold() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../docs/report/results.json"
        );
        let mut results = Results::load(std::path::Path::new(path)).unwrap();
        let bunny = results
            .models
            .iter_mut()
            .find(|m| m.name == "bunny.ply")
            .unwrap();
        bunny.stripify.mts.indices_per_triangle = 1.25;
        bunny.stripify.mts.ms = 20.0;
        bunny.stripify.meshopt.ms = 25.0;
        bunny.quality[0].mts.hausdorff = 2.0;
        bunny.quality[0].meshopt.hausdorff = 1.0;
        let s = summary(&results, "r");
        assert!(
            s.contains("| bunny: indices per triangle (restart) | ≤ 1.20 | 1.2500 | **no** |"),
            "{s}"
        );
        assert!(
            s.contains("| bunny: stripify | < 30 ms | 20.0 ms (meshoptimizer 25.0 ms) | yes |"),
            "{s}"
        );
        assert!(
            s.contains("1 of 40 rows above: bunny.ply 10% 2.00 | **no** |"),
            "{s}"
        );
        assert!(s.starts_with(BEGIN) && s.trim_end().ends_with(END));
    }
}
