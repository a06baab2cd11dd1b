//! `mts bench summary`: the README's "Latest bench report" section, made
//! from a `results.json` so that every figure the README quotes is a row
//! of a report this command produced.
//!
//! The section sits between [`BEGIN`] and [`END`] in the README;
//! `--readme` rewrites it there, `--check` fails when it differs from what
//! the data gives (a test runs that on the committed report).

use super::bench::{f, figure6_row, machine_words, scale_table, strips_table};
use serde_json::Value;
use std::fmt::Write as _;

/// First line of the generated section in the README.
pub const BEGIN: &str = "<!-- BEGIN mts bench summary: generated from the report's results.json by `mts bench summary`; edit the generator, not this block -->";
/// Last line of the generated section in the README.
pub const END: &str = "<!-- END mts bench summary -->";

fn name(v: &Value) -> &str {
    v["name"].as_str().unwrap_or("?")
}

/// The model the single-model tables describe: the bunny when measured,
/// otherwise the first one.
fn focus(models: &[Value]) -> Option<&Value> {
    models
        .iter()
        .find(|m| name(m) == "bunny.ply")
        .or_else(|| models.first())
}

/// The scale row closest to `triangles`.
fn scale_row(results: &Value, triangles: f64) -> Option<&Value> {
    results["scale"]["rows"].as_array()?.iter().min_by(|a, b| {
        (f(&a["triangles"]) - triangles)
            .abs()
            .total_cmp(&(f(&b["triangles"]) - triangles).abs())
    })
}

/// The "met" cell: `None` when this machine cannot show the figure.
fn yes(met: Option<bool>) -> &'static str {
    match met {
        Some(true) => "yes",
        Some(false) => "**no**",
        None => "not measurable here",
    }
}

/// The Markdown section (between [`BEGIN`] and [`END`], both included)
/// for `results`; `report_dir` is where the report lies, relative to the
/// README (links and charts).
#[must_use]
pub fn summary(results: &Value, report_dir: &str) -> String {
    let mut s = String::new();
    let models = results["models"].as_array().cloned().unwrap_or_default();
    let _ = writeln!(s, "{BEGIN}\n");
    let elapsed = results["elapsed_s"]
        .as_f64()
        .map_or_else(String::new, |e| format!(" in {e:.0} s"));
    let (machine, adapter) = machine_words(results);
    let _ = writeln!(
        s,
        "Produced by `{}`{elapsed} on {machine}; graphics adapter: {adapter}. The whole report is [{report_dir}/report.md]({report_dir}/report.md), its data `{report_dir}/results.json` (schema `docs/bench-schema.md`). Every figure below is copied from that data by `mts bench summary {report_dir}/results.json --readme README.md`, and `crates/mts-cli/tests/readme.rs` fails when this section and the data disagree. Timings are medians of runs interleaved with the peer they are compared with; the machine is shared, so compare within a row.\n",
        results["command"].as_str().unwrap_or("?"),
    );
    targets(&mut s, results, &models);
    strips(&mut s, &models);
    if let Some(b) = focus(&models) {
        levels(&mut s, b, &models);
    }
    quality(&mut s, results, &models);
    if let Some(b) = focus(&models) {
        methods(&mut s, b, &models);
        render(&mut s, results, b);
    }
    scale(&mut s, results);
    // The charts `mts bench` draws from the same data.
    let mut charts = Vec::new();
    if let Some(b) = focus(&models) {
        charts.push("indices");
        if b["figure6"]["rows"].is_array() {
            charts.extend(["figure6_immediate", "figure6_per_second"]);
        }
    }
    if results["scale"]["rows"].is_array() {
        charts.push("scale");
    }
    for chart in charts {
        let _ = writeln!(s, "![{chart}]({report_dir}/{chart}.png)\n");
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
fn targets(s: &mut String, results: &Value, models: &[Value]) {
    let _ = writeln!(s, "### Targets\n");
    let _ = writeln!(s, "| figure | target | measured | met |");
    let _ = writeln!(s, "|---|---|---|---|");
    let files: Vec<&Value> = models
        .iter()
        .filter(|m| !name(m).starts_with("generated"))
        .collect();
    if !files.is_empty() {
        let worst = files
            .iter()
            .map(|m| {
                let x = &m["stripify"];
                (
                    f(&x["indices_per_triangle"]) / f(&x["meshopt"]["indices_per_triangle"]),
                    name(m),
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
        let mut above = Vec::new();
        let mut rows = 0;
        for m in &files {
            for q in m["quality"].as_array().into_iter().flatten() {
                rows += 1;
                let r = f(&q["mts"]["hausdorff"]) / f(&q["meshopt"]["hausdorff"]);
                // Both exact (0 / 0) counts as equal.
                if r > 1.15 {
                    above.push(format!("{} {:.0}% {r:.2}", name(m), f(&q["share"]) * 100.0));
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
    if let Some(b) = models.iter().find(|m| name(m) == "bunny.ply") {
        let x = &b["stripify"];
        row(
            s,
            "bunny: indices per triangle (restart)",
            "≤ 1.20",
            format!("{:.4}", f(&x["indices_per_triangle"])),
            f(&x["indices_per_triangle"]) <= 1.20,
        );
        row(
            s,
            "bunny: stripify",
            "< 30 ms",
            format!(
                "{:.1} ms (meshoptimizer {:.1} ms)",
                f(&x["ms"]),
                f(&x["meshopt"]["ms"])
            ),
            f(&x["ms"]) < 30.0,
        );
        let y = &b["simplify"];
        row(
            s,
            "bunny: whole contraction sequence",
            "< 150 ms",
            format!(
                "{:.0} ms (meshoptimizer to 10%: {:.0} ms)",
                f(&y["ms"]),
                f(&y["meshopt_ms_to_10"])
            ),
            f(&y["ms"]) < 150.0,
        );
        let bytes = &b["bytes"];
        let ratio = f(&bytes["mts_file"]) / f(&bytes["raw"]);
        row(
            s,
            "bunny: .mts file against the raw mesh (12 + 12 bytes)",
            "≤ 1.5 ×",
            format!("{ratio:.2} ×"),
            ratio <= 1.5,
        );
        row(
            s,
            "bunny: build (strips, sequence, model)",
            "< 500 ms",
            format!("{:.0} ms", f(&b["build_ms"]["total"])),
            f(&b["build_ms"]["total"]) < 500.0,
        );
        if let Some(l0) = b["levels"].as_array().and_then(|l| l.first()) {
            row(
                s,
                "bunny: LoD 0 extracted from scratch",
                "< 0.5 ms",
                format!("{:.0} µs", f(&l0["extract_us"])),
                f(&l0["extract_us"]) < 500.0,
            );
        }
        let changes: Vec<f64> = b["figure6"]["rows"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|x| x["change_us"].as_f64())
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
        let share = b["levels"]
            .as_array()
            .into_iter()
            .flatten()
            .map(|l| f(&l["mts_indices"]) / f(&l["list_indices"]))
            .reduce(f64::max);
        if let Some(share) = share {
            row(
                s,
                &format!(
                    "{}: indices sent by strips against the triangle list, every level",
                    name(b)
                ),
                "≤ 50%",
                format!("at most {:.1}%", 100.0 * share),
                share <= 0.5,
            );
        }
    }
    if let Some(r) = scale_row(results, 1e6) {
        let t = f(&r["triangles"]);
        row(
            s,
            &format!("{t:.0}-triangle icosphere: stripify"),
            "< 1 s",
            format!(
                "{:.0} ms (meshoptimizer {:.0} ms)",
                f(&r["stripify_ms"]),
                f(&r["meshopt_stripify_ms"])
            ),
            f(&r["stripify_ms"]) < 1000.0,
        );
        row(
            s,
            &format!("{t:.0}-triangle icosphere: whole contraction sequence"),
            "< 3 s",
            format!(
                "{:.0} ms (meshoptimizer to 10%: {:.0} ms)",
                f(&r["simplify_ms"]),
                f(&r["meshopt_simplify_to_10_ms"])
            ),
            f(&r["simplify_ms"]) < 3000.0,
        );
        row(
            s,
            &format!("{t:.0}-triangle icosphere: build"),
            "< 10 s",
            format!("{:.1} s", f(&r["build_ms"]) / 1e3),
            f(&r["build_ms"]) < 10_000.0,
        );
    }
    let e = &results["scale"]["exponent"];
    if e["stripify_ms"].is_number() {
        let (ours, theirs) = (f(&e["stripify_ms"]), f(&e["meshopt_stripify_ms"]));
        let rows = results["scale"]["rows"]
            .as_array()
            .cloned()
            .unwrap_or_default();
        let per = |r: Option<&Value>, key: &str| {
            r.map_or(f64::NAN, |r| f(&r[key]) * 1e6 / f(&r["triangles"]))
        };
        let (first, last) = (rows.first(), rows.last());
        row(
            s,
            "stripify time against triangles (fitted exponent k of t ~ n^k over the scale rows)",
            "linear: k within 0.1 of meshoptimizer's, a linear-time stripifier on the same machine",
            format!(
                "k = {ours:.2} (meshoptimizer {theirs:.2}); {:.0} → {:.0} ns per triangle (meshoptimizer {:.0} → {:.0})",
                per(first, "stripify_ms"),
                per(last, "stripify_ms"),
                per(first, "meshopt_stripify_ms"),
                per(last, "meshopt_stripify_ms"),
            ),
            ours <= theirs + 0.1,
        );
    }
    let scene = &results["scene"];
    if scene.is_object() {
        row_if(
            s,
            &format!(
                "scene of {} × {} on this adapter",
                scene["instances"],
                scene["model"].as_str().unwrap_or("?")
            ),
            "> 60 fps on a GPU; frame time on lavapipe",
            format!(
                "{:.1} ms = {:.0} fps ({} visible)",
                f(&scene["ms_per_frame"]),
                f(&scene["fps"]),
                scene["visible"]
            ),
            // A CPU rasteriser (lavapipe) gives the frame time only.
            results["machine"]["adapter"]
                .as_str()
                .filter(|a| !a.contains("Cpu") && !a.contains("llvmpipe"))
                .map(|_| f(&scene["fps"]) > 60.0),
        );
    }
    if let Some(e) = results["elapsed_s"].as_f64() {
        if !results["quick"].as_bool().unwrap_or(true) {
            row(
                s,
                "the whole report over every model",
                "< 30 min",
                format!("{:.1} min", e / 60.0),
                e < 1800.0,
            );
        }
    }
    let _ = writeln!(s);
}

fn strips(s: &mut String, models: &[Value]) {
    let _ = writeln!(s, "### Strips against meshoptimizer\n");
    strips_table(s, models);
    let _ = writeln!(s);
}

fn levels(s: &mut String, b: &Value, models: &[Value]) {
    let _ = writeln!(s, "### Indices sent per level ({})\n", name(b));
    let _ = writeln!(s, "MTS strips extracted at each level, the level's triangle list, and meshoptimizer's strips of the level's mesh stripified afresh:\n");
    let _ = writeln!(
        s,
        "| share | triangles | MTS | list | meshopt strips | MTS / meshopt | MTS / list |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    for l in b["levels"].as_array().into_iter().flatten() {
        let _ = writeln!(
            s,
            "| {:.0}% | {} | {} | {} | {} | {:.3} | {:.3} |",
            f(&l["share"]) * 100.0,
            l["triangles"],
            l["mts_indices"],
            l["list_indices"],
            l["meshopt_strip_indices"],
            f(&l["mts_indices"]) / f(&l["meshopt_strip_indices"]),
            f(&l["mts_indices"]) / f(&l["list_indices"]),
        );
    }
    let worst = models
        .iter()
        .flat_map(|m| {
            m["levels"]
                .as_array()
                .into_iter()
                .flatten()
                .map(move |l| (f(&l["mts_indices"]) / f(&l["list_indices"]), m, l))
        })
        .max_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((share, m, l)) = worst {
        let _ = writeln!(
            s,
            "\nOver every model and level of the report, strips send at most {:.1}% of the list's indices ({} at {:.0}%, {} triangles: small levels of open or many-component meshes, where runs are short).",
            100.0 * share,
            name(m),
            f(&l["share"]) * 100.0,
            l["triangles"],
        );
    }
    let _ = writeln!(s);
}

fn quality(s: &mut String, results: &Value, models: &[Value]) {
    let _ = writeln!(s, "### Simplification against meshoptimizer\n");
    let _ = writeln!(s, "Hausdorff distance to the input (relative to the bounding-box diagonal) of the project's LoD and of meshoptimizer's `simplify` asked for the same triangle count (where it stops above it, the project's LoD is taken at its count), as mts / meshoptimizer (ratio); the milliseconds of the project's whole sequence (every LoD) against meshoptimizer's `simplify` to 10%.\n");
    let _ = writeln!(
        s,
        "| model | Hausdorff at 10% | Hausdorff at 1% | ms whole sequence / meshopt to 10% |"
    );
    let _ = writeln!(s, "|---|---|---|---|");
    for m in models {
        let mut row = format!("| {} |", name(m));
        for q in m["quality"].as_array().into_iter().flatten() {
            let (a, b) = (f(&q["mts"]["hausdorff"]), f(&q["meshopt"]["hausdorff"]));
            let ratio = if a == 0.0 && b == 0.0 { 1.0 } else { a / b };
            let bold = if ratio > 1.15 { "**" } else { "" };
            let _ = write!(row, " {a:.5} / {b:.5} ({bold}{ratio:.2}{bold}) |");
        }
        let _ = writeln!(
            s,
            "{row} {:.0} / {:.0} |",
            f(&m["simplify"]["ms"]),
            f(&m["simplify"]["meshopt_ms_to_10"])
        );
    }
    let _ = writeln!(s);
    if let Some(peer) = results["fast_simplification"].as_array() {
        let _ = writeln!(s, "fast-simplification (`crates/mts-cli/peers/fast_simplification.py`, error measured by `mts distance`), Hausdorff at 10% / 1% against the project's:");
        let _ = writeln!(s);
        let _ = writeln!(
            s,
            "| model | fast-simplification | mts | fast-simplification ms to 10% |"
        );
        let _ = writeln!(s, "|---|---|---|---|");
        for m in models {
            let find = |share: f64| {
                peer.iter().find(|p| {
                    p["mesh"].as_str() == Some(name(m)) && p["ratio"].as_f64() == Some(share)
                })
            };
            let ours = |share: f64| {
                m["quality"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .find(|q| q["share"].as_f64() == Some(share))
                    .map_or(f64::NAN, |q| f(&q["mts"]["hausdorff"]))
            };
            if let (Some(a), Some(b)) = (find(0.1), find(0.01)) {
                let _ = writeln!(
                    s,
                    "| {} | {:.5} / {:.5} | {:.5} / {:.5} | {:.0} |",
                    name(m),
                    f(&a["hausdorff"]),
                    f(&b["hausdorff"]),
                    ours(0.1),
                    ours(0.01),
                    f(&a["ms"]),
                );
            }
        }
        let _ = writeln!(s);
    }
}

fn methods(s: &mut String, b: &Value, models: &[Value]) {
    let _ = writeln!(s, "### Every method ({})\n", name(b));
    let _ = writeln!(s, "File bytes against the raw mesh with 16-bit indices (12 per vertex + 6 per triangle), memory, build time and microseconds per LoD change on the linear, exponential and random request sequences, through `LodSource`:\n");
    let _ = writeln!(s, "| method | file bytes | / raw 16-bit | memory bytes | build ms | µs per change linear / exponential / random |");
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    for x in b["methods"].as_array().into_iter().flatten() {
        let u = &x["us_per_change"];
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {} | {:.0} | {:.1} / {:.1} / {:.1} |",
            x["method"].as_str().unwrap_or("?"),
            x["file_bytes"],
            f(&x["file_ratio_to_raw_u16"]),
            x["memory_bytes"],
            f(&x["build_ms"]),
            f(&u["linear"]),
            f(&u["exponential"]),
            f(&u["random"]),
        );
    }
    let _ = writeln!(s);
    let range = |method: &str| {
        let v: Vec<f64> = models
            .iter()
            .flat_map(|m| m["methods"].as_array().into_iter().flatten())
            .filter(|x| x["method"] == method)
            .map(|x| f(&x["file_ratio_to_raw_u16"]))
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
    let e = &b["extraction"];
    let _ = write!(
        s,
        "Coherence cache ({}, microseconds per LoD change with / without):",
        name(b)
    );
    for seq in ["linear", "exponential", "random"] {
        let (c, w) = (f(&e[seq]["mts_coherent_us"]), f(&e[seq]["mts_scratch_us"]));
        let _ = write!(s, " {seq} {c:.1} / {w:.1} ({:.1} ×);", w / c);
    }
    let _ = writeln!(s, "\n");
}

fn render(s: &mut String, results: &Value, b: &Value) {
    let rows = b["figure6"]["rows"].as_array().cloned().unwrap_or_default();
    if rows.is_empty() {
        let _ = writeln!(
            s,
            "### Rendering\n\nNot measured: {}.\n",
            results["machine"]["adapter_note"]
                .as_str()
                .unwrap_or("no adapter")
        );
        return;
    }
    let _ = writeln!(s, "### Rendering ({}, Figure 6)\n", name(b));
    let _ = writeln!(s, "Frames per second with a LoD change before every frame (immediate) and with one extraction per second, per method; the draw alone (MTS strips against the meshoptimizer-ordered list) and one MTS LoD change (extraction and dirty-range upload). {} × {} pixels.\n", b["figure6"]["width"], b["figure6"]["height"]);
    let _ = writeln!(s, "| share | triangles | indices mts / list | draw ms mts / list | LoD change µs | fps immediate: mts / list / pm / multilevel / cluster / discrete |");
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    for x in rows
        .iter()
        .filter(|x| x["method"] == "mts" && x["mode"] == "immediate")
    {
        let list = figure6_row(&rows, x, "list");
        let fps: Vec<String> = ["mts", "list", "pm", "multilevel", "cluster", "discrete"]
            .iter()
            .map(|m| format!("{:.0}", f(&figure6_row(&rows, x, m)["fps"])))
            .collect();
        let _ = writeln!(
            s,
            "| {:.0}% | {} | {} / {} | {:.2} / {:.2} | {:.0} | {} |",
            f(&x["share"]) * 100.0,
            x["triangles"],
            x["indices_sent"],
            list["indices_sent"],
            f(&x["draw_ms"]),
            f(&list["draw_ms"]),
            f(&x["change_us"]),
            fps.join(" / "),
        );
    }
    let scene = &results["scene"];
    if scene.is_object() {
        let _ = writeln!(s, "\nScene: {} instances of {} on a ground plane, each with its own LoD and coherence cache, culled by the instance BVH: {} visible, {} triangles, {} indices sent, {:.2} ms per frame ({:.1} fps; {} bytes of coherence cache per instance).", scene["instances"], scene["model"].as_str().unwrap_or("?"), scene["visible"], scene["triangles"], scene["indices_sent"], f(&scene["ms_per_frame"]), f(&scene["fps"]), scene["cpu_bytes_per_instance"]);
    }
    let _ = writeln!(s);
}

fn scale(s: &mut String, results: &Value) {
    if results["scale"]["rows"].is_array() {
        let _ = writeln!(s, "### Scale (generated icospheres)\n");
        scale_table(s, results);
        let _ = writeln!(s);
    }
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
    use serde_json::json;

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
        let results = json!({
            "machine": {"cpu": "c", "cores": 2, "os": "o", "adapter": null},
            "models": [{
                "name": "bunny.ply",
                "stripify": {"indices_per_triangle": 1.25, "ms": 20.0,
                             "meshopt": {"indices_per_triangle": 1.3, "ms": 25.0}},
                "simplify": {"ms": 100.0, "meshopt_ms_to_10": 50.0},
                "bytes": {"mts_file": 10, "raw": 10},
                "build_ms": {"total": 400.0},
                "quality": [{"share": 0.1, "mts": {"hausdorff": 2.0}, "meshopt": {"hausdorff": 1.0}}],
            }],
        });
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
            s.contains("1 of 1 rows above: bunny.ply 10% 2.00 | **no** |"),
            "{s}"
        );
        assert!(s.starts_with(BEGIN) && s.trim_end().ends_with(END));
    }
}
