//! PNG charts of `mts bench`'s results (plotters, bitmap backend, DejaVu
//! Sans embedded so no system font is needed).

use crate::bench::results::{
    Figure6Row, Level, Model, Results, ScaleRow, ViewDependentRun, VIEW_DEPENDENT_METHODS,
};
use anyhow::{anyhow, Result};
use plotters::prelude::*;
use std::path::{Path, PathBuf};

const SIZE: (u32, u32) = (900, 560);
const FONT: &str = "sans-serif";

fn register_font() {
    // Registering twice replaces the same font: harmless.
    let _ = plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
}

fn err<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow!("chart: {e:?}")
}

/// Writes every chart the results allow into `dir`; returns their paths.
pub fn write_all(dir: &Path, results: &Results) -> Result<Vec<PathBuf>> {
    register_font();
    let mut written = Vec::new();
    let models = &results.models;
    // The bunny when measured, otherwise the first model.
    if let Some(m) = models
        .iter()
        .find(|m| m.name == "bunny.ply")
        .or_else(|| models.first())
    {
        let path = dir.join("indices.png");
        mts::output::write_through(&path, |p| indices_chart(p, m))?;
        written.push(path);
        if let Some(figure6) = &m.figure6 {
            for mode in ["immediate", "per_second"] {
                let path = dir.join(format!("figure6_{mode}.png"));
                mts::output::write_through(&path, |p| {
                    figure6_chart(p, &m.name, &figure6.rows, mode)
                })?;
                written.push(path);
            }
        }
    }
    if let Some(scale) = &results.scale {
        let path = dir.join("scale.png");
        mts::output::write_through(&path, |p| scale_chart(p, &scale.rows))?;
        written.push(path);
    }
    if let Some(run) = view_dependent_focus(&results.view_dependent) {
        let path = dir.join("view_dependent.png");
        mts::output::write_through(&path, |p| view_dependent_chart(p, run))?;
        written.push(path);
    }
    Ok(written)
}

/// The view-dependent run the chart shows: the largest terrain (flown
/// over), otherwise the largest input.
pub fn view_dependent_focus(runs: &[ViewDependentRun]) -> Option<&ViewDependentRun> {
    runs.iter()
        .filter(|r| r.flight == "over")
        .max_by_key(|r| r.triangles_full_detail)
        .or_else(|| runs.iter().max_by_key(|r| r.triangles_full_detail))
}

/// Triangles drawn (median frame) as a share of full detail: a group of
/// bars per pixel threshold, one bar per method, its count above it.
fn view_dependent_chart(path: &Path, run: &ViewDependentRun) -> Result<()> {
    let mut thresholds: Vec<f64> = Vec::new();
    for r in &run.methods {
        if !thresholds.contains(&r.pixel_threshold) {
            thresholds.push(r.pixel_threshold);
        }
    }
    let full = run.triangles_full_detail.max(1) as f64;
    let groups = thresholds.len() as f64;
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "Triangles drawn per frame (median), {}, {} frames {} it",
                run.input,
                run.frames,
                if run.flight == "over" {
                    "flying over"
                } else {
                    "circling"
                }
            ),
            (FONT, 20),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(-0.5f64..groups - 0.5, 0f64..150.0)
        .map_err(err)?;
    let label = |x: &f64| {
        let i = x.round();
        match thresholds.get(i as usize) {
            Some(px) if (x - i).abs() < 1e-6 && i >= 0.0 => format!("{px} px"),
            _ => String::new(),
        }
    };
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(thresholds.len() + 1)
        .x_label_formatter(&label)
        .y_label_formatter(&|y| format!("{y:.0}"))
        .x_desc("pixel threshold")
        .y_desc(format!(
            "share of the full detail's {} triangles (%)",
            run.triangles_full_detail
        ))
        .label_style((FONT, 14))
        .draw()
        .map_err(err)?;
    let methods = [
        ("strip hierarchy (mts_hierarchy)", BLUE),
        ("meshoptimizer cluster LoD", RED),
        ("cluster tree", RGBColor(0, 140, 0)),
        ("per-object MTS", RGBColor(150, 60, 170)),
    ];
    let width = 0.8 / methods.len() as f64;
    for (k, (method, (name, color))) in VIEW_DEPENDENT_METHODS.iter().zip(methods).enumerate() {
        let bars: Vec<(f64, f64, f64)> = thresholds
            .iter()
            .enumerate()
            .filter_map(|(i, px)| {
                let r = run
                    .methods
                    .iter()
                    .find(|r| r.method == *method && r.pixel_threshold == *px)?;
                let x = i as f64 - 0.4 + width * k as f64;
                Some((
                    x,
                    100.0 * r.triangles_drawn_median / full,
                    r.triangles_drawn_median,
                ))
            })
            .collect();
        chart
            .draw_series(bars.iter().map(|&(x, y, _)| {
                Rectangle::new([(x + 0.01, 0.0), (x + width - 0.01, y)], color.filled())
            }))
            .map_err(err)?
            .label(name)
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], color.filled()));
        chart
            .draw_series(bars.iter().map(|&(x, y, n)| {
                let text = if n >= 1e6 {
                    format!("{:.2}M", n / 1e6)
                } else {
                    format!("{:.1}k", n / 1e3)
                };
                Text::new(
                    text,
                    (x + 0.01, y + 2.0),
                    (FONT, 12).into_font().color(&BLACK).pos(
                        plotters::style::text_anchor::Pos::new(
                            plotters::style::text_anchor::HPos::Left,
                            plotters::style::text_anchor::VPos::Bottom,
                        ),
                    ),
                )
            }))
            .map_err(err)?;
    }
    chart
        .configure_series_labels()
        .label_font((FONT, 14))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

/// Indices per triangle against the share of triangles (log axis): MTS
/// strips, meshoptimizer's strips of each level, the triangle list.
fn indices_chart(path: &Path, model: &Model) -> Result<()> {
    let series = |indices: fn(&Level) -> u64| -> Vec<(f64, f64)> {
        model
            .levels
            .iter()
            .map(|l| {
                let t = l.triangles as f64;
                (l.share * 100.0, indices(l) as f64 / t.max(1.0))
            })
            .collect()
    };
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("Indices sent per triangle, {}", model.name),
            (FONT, 22),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d((0.8f64..120.0).log_scale(), 0.8f64..3.2)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("share of the full triangle count (%)")
        .y_desc("indices / triangle")
        .label_style((FONT, 14))
        .draw()
        .map_err(err)?;
    let lines = [
        (
            (|l: &Level| l.mts_indices) as fn(&Level) -> u64,
            "MTS strips (restart values included)",
            BLUE,
        ),
        (
            |l: &Level| l.meshopt_strip_indices,
            "meshoptimizer strips of each level",
            RED,
        ),
        (|l: &Level| l.list_indices, "triangle list", BLACK),
    ]
    .into_iter()
    .map(|(indices, label, color)| (label, color, series(indices)))
    .collect();
    draw_lines(&mut chart, lines, SeriesLabelPosition::MiddleRight)?;
    root.present().map_err(err)?;
    Ok(())
}

/// Build milliseconds, model megabytes and LoD-0 extraction microseconds
/// against triangles, log-log.
fn scale_chart(path: &Path, rows: &[ScaleRow]) -> Result<()> {
    let build = |r: &ScaleRow| r.build_ms;
    let bytes = |r: &ScaleRow| r.model_bytes as f64;
    let extract = |r: &ScaleRow| r.extract_lod0_us;
    let get = |value: fn(&ScaleRow) -> f64, scale: f64| -> Vec<(f64, f64)> {
        rows.iter()
            .map(|r| (r.triangles as f64, value(r) * scale))
            .collect()
    };
    let all: Vec<(f64, f64)> = [get(build, 1.0), get(bytes, 1e-6), get(extract, 1.0)].concat();
    let (x0, x1) = all
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (y0, y1) = all
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    if all.is_empty() {
        return Ok(());
    }
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let mut chart = ChartBuilder::on(&root)
        .caption("Scale: generated icospheres", (FONT, 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(
            (x0 * 0.8..x1 * 1.25).log_scale(),
            (y0.max(1e-3) * 0.5..y1 * 2.0).log_scale(),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("triangles")
        .label_style((FONT, 14))
        .draw()
        .map_err(err)?;
    let lines = [
        (build as fn(&ScaleRow) -> f64, 1.0, "build (ms)", BLUE),
        (bytes, 1e-6, "model in memory (MB)", RED),
        (extract, 1.0, "LoD 0 extraction (us)", GREEN),
    ]
    .into_iter()
    .map(|(value, scale, label, color)| (label, color, get(value, scale)))
    .collect();
    draw_lines(&mut chart, lines, SeriesLabelPosition::UpperLeft)?;
    root.present().map_err(err)?;
    Ok(())
}

/// Frames per second against the share of triangles (log axis), one line
/// per method, for one mode: the MTS paper's Figure 6 (up: `immediate`,
/// down: `per_second`).
fn figure6_chart(path: &Path, name: &str, rows: &[Figure6Row], mode: &str) -> Result<()> {
    let series = |method: &str| -> Vec<(f64, f64)> {
        rows.iter()
            .filter(|r| r.method == method && r.mode == mode)
            .map(|r| (r.share * 100.0, r.fps))
            .collect()
    };
    let top = rows
        .iter()
        .filter(|r| r.mode == mode)
        .map(|r| r.fps)
        .fold(1.0f64, f64::max);
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "Frames per second, {}, {}",
                name,
                if mode == "immediate" {
                    "extract + draw each frame"
                } else {
                    "one extraction per second"
                }
            ),
            (FONT, 22),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d((0.8f64..120.0).log_scale(), 0.0..top * 1.15)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("share of the full triangle count (%)")
        .y_desc("frames per second")
        .label_style((FONT, 14))
        .draw()
        .map_err(err)?;
    let lines = [
        ("mts", "MTS strips", BLUE),
        ("list", "list (replayed)", BLACK),
        ("pm", "progressive mesh", RED),
        ("multilevel", "multilevel", MAGENTA),
        ("cluster", "cluster tree", GREEN),
        ("discrete", "discrete", CYAN),
    ]
    .into_iter()
    .map(|(method, label, color)| (label, color, series(method)))
    .collect();
    draw_lines(&mut chart, lines, SeriesLabelPosition::UpperRight)?;
    root.present().map_err(err)?;
    Ok(())
}

/// One line of a chart: its legend label, colour and points.
type Line = (&'static str, RGBColor, Vec<(f64, f64)>);

/// Draws each `(label, colour, points)` as a line with dots, and the
/// legend at `position`.
fn draw_lines<'a, DB, X, Y>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    series: Vec<Line>,
    position: SeriesLabelPosition,
) -> Result<()>
where
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    for (label, color, points) in series {
        chart
            .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))
            .map_err(err)?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        chart
            .draw_series(points.iter().map(|&p| Circle::new(p, 4, color.filled())))
            .map_err(err)?;
    }
    chart
        .configure_series_labels()
        .label_font((FONT, 14))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .position(position)
        .draw()
        .map_err(err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The charts drawn from the committed report's data are the committed
    /// PNGs, byte for byte.
    #[test]
    fn charts_of_the_committed_report_are_its_pngs() {
        let report = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/report"));
        let results = Results::load(&report.join("results.json")).unwrap();
        let dir = std::env::temp_dir().join(format!("mts-charts-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let written = write_all(&dir, &results).unwrap();
        // Bunny's strips, Figure 6 twice, the scale, the flights.
        assert_eq!(
            written.len(),
            4 + usize::from(!results.view_dependent.is_empty())
        );
        assert!(!results.view_dependent.is_empty());
        for path in &written {
            let name = path.file_name().unwrap();
            let ours = std::fs::read(path).unwrap();
            let committed = std::fs::read(report.join(name)).unwrap();
            assert!(
                ours == committed,
                "{name:?} differs from the committed chart"
            );
        }
        std::fs::remove_dir_all(&dir).ok();
    }
}
