//! `results.json` as one typed structure (`docs/bench-schema.md`): what
//! `mts bench` writes, and what `mts bench summary`, the charts,
//! `mts bench check` and the README test read. A missing, renamed or extra
//! key, or a `null` where a number belongs (a NaN the writer produced), is
//! a load error naming the key and its place — never a NaN in a table.

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Version of `results.json`'s layout (`docs/bench-schema.md`).
pub const SCHEMA_VERSION: u32 = 11;

/// Steps (of 255) an RGB byte may move before an image comparison
/// (Figure 6's, the scene's, the properties') counts the pixel as changed.
pub const IMAGE_TOLERANCE: u8 = 8;

/// The whole file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Results {
    pub schema: u32,
    pub command: String,
    pub elapsed_s: f64,
    pub quick: bool,
    pub machine: Machine,
    pub models: Vec<Model>,
    /// `null` with `--quick`.
    pub scale: Option<Scale>,
    /// `null` with `--quick`; rows, or why they are missing.
    pub fast_simplification: Option<FastSimplificationRun>,
    /// `null` without an adapter.
    pub scenes: Vec<Scene>,
    /// Measured vertex work of one model (the bunny when measured) on
    /// machine.adapter; null without one.
    pub vertex_work: Option<VertexWork>,
    /// Vertex properties against meshoptimizer's `simplifyWithAttributes`:
    /// one row per model with properties and share.
    pub properties: Vec<PropertyRow>,
    /// `mts bench view-dependent` per input: the strip hierarchy, the
    /// cluster LoD, the cluster tree and per-object MTS along one flight.
    pub view_dependent: Vec<ViewDependentRun>,
}

/// One input flown over or around (`mts bench view-dependent`, whose
/// `--json` prints this): every method at every pixel threshold.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViewDependentRun {
    pub input: String,
    pub triangles_full_detail: u64,
    pub vertices: u64,
    /// 12 bytes a vertex and a triangle (32-bit indices).
    pub raw_bytes: u64,
    /// `over` (a terrain, corner to corner) or `around` (circled, closing in).
    pub flight: String,
    pub frames: u64,
    pub width: u32,
    pub height: u32,
    /// The adapter the images came from; `None` without images.
    pub adapter: Option<String>,
    /// Per threshold, the methods in the order of [`VIEW_DEPENDENT_METHODS`].
    pub methods: Vec<ViewDependentRow>,
}

/// The methods of a [`ViewDependentRun`], in their order per threshold.
pub const VIEW_DEPENDENT_METHODS: [&str; 4] =
    ["mts_hierarchy", "clusterlod", "cluster_tree", "mts"];

/// One method at one pixel threshold along the flight.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViewDependentRow {
    pub method: String,
    pub pixel_threshold: f64,
    pub triangles_drawn_median: f64,
    pub triangles_drawn_max: u64,
    pub triangles_full_detail: u64,
    /// Hierarchy only: the median of what frustum culling keeps.
    pub triangles_visible_median: Option<f64>,
    /// Indices sent over triangles drawn: the median frame's.
    pub indices_per_triangle: f64,
    /// The worst frame's.
    pub indices_per_triangle_max: f64,
    pub update_ms_median: f64,
    pub update_ms_p99: f64,
    /// Crack edges summed over every frame.
    pub cracks: u64,
    pub popping_px_max: f64,
    pub popping_px_median: f64,
    pub triangles_changed_median: f64,
    /// What the method holds in memory to select and extract.
    pub memory_bytes: u64,
    pub raw_bytes: u64,
    /// Vertices plus the largest index buffer of the flight, as uploaded
    /// (4-byte indices).
    pub gpu_bytes: u64,
    pub build_ms: f64,
    /// `null` without images.
    pub image_error_ratio: Option<f64>,
}

/// One model with properties at one share: ours and meshoptimizer's
/// `simplifyWithAttributes` at the same triangle count.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PropertyRow {
    pub model: String,
    pub share: f64,
    pub mts: PropertySide,
    pub meshopt: PropertySide,
}

/// Geometric error (relative to the diagonal) and property error (UV
/// units, degrees, RGBA distance; `null` for a stream the model lacks).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PropertySide {
    pub triangles: u64,
    pub hausdorff: f64,
    pub rms: f64,
    pub uv_rms: Option<f64>,
    pub normal_degrees_rms: Option<f64>,
    pub color_rms: Option<f64>,
    /// Against the full model drawn alike (checker where there are UVs,
    /// fixed camera): share of the model's pixels that changed, and the
    /// RMS RGB difference; `null` without an adapter.
    pub image_differing_share: Option<f64>,
    pub image_rms: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Machine {
    pub cpu: String,
    pub cores: u32,
    pub os: String,
    pub adapter: Option<String>,
    pub adapter_note: Option<String>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Model {
    pub name: String,
    pub triangles: u64,
    pub vertices: u64,
    pub strips: u64,
    pub max_lod: u64,
    pub bands: u64,
    pub bytes: Bytes,
    pub build_ms: BuildMs,
    pub stripify: Stripify,
    pub simplify: Simplify,
    pub extraction: BTreeMap<String, Extraction>,
    pub levels: Vec<Level>,
    pub quality: Vec<Quality>,
    pub methods: Vec<MethodRow>,
    /// `null` without an adapter.
    pub figure6: Option<Figure6>,
    /// The model's renewals side by side: the single band, bands and
    /// per-strip lifetimes (`mts::model::lifetimes`).
    pub renewal: Vec<RenewalRow>,
}

/// One renewal of the strips as the LoD coarsens, replayed over the
/// model's sequence (`mts::model::lifetimes::measure_renewal`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenewalRow {
    /// "single band", "bands" or "strips".
    pub renewal: String,
    /// The slack (`null` for the single band).
    pub slack: Option<f64>,
    /// A strips row's neighbourhood: fewest and most triangles.
    pub unit_triangles: Option<[u64; 2]>,
    pub strips_born: u64,
    pub renewals: u64,
    pub records: u64,
    /// Bytes in the per-strip layout, every row alike.
    pub memory_bytes: u64,
    /// Indices sent per triangle at the report's shares
    /// (`mts::methods::SHARES`).
    pub indices_per_triangle: Vec<f64>,
    /// Over the 100 shares 100%..1%: the mean and worst ratio of the
    /// indices sent to the default bands', and the shares more than 2%
    /// above.
    pub mean_ratio: f64,
    pub worst_ratio: f64,
    pub shares_above: u64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bytes {
    pub raw: u64,
    pub raw_u16: u64,
    /// The ready `.mts` file `mts build` writes (version 6: coarse chunks
    /// at `mts::model::DEFAULT_PREFIX_SHARES`, then version 5's sections
    /// coded at `mts::model::compress::DEFAULT_LEVEL`).
    pub mts_file: u64,
    /// The first bytes of that file that open and draw 10% of the
    /// triangles (`mts::model::bytes_for_lod`).
    pub prefix_bytes_10: u64,
    /// ... and 50% (the whole file when no chunk holds that LoD).
    pub prefix_bytes_50: u64,
    /// The ready file uncoded (version 3, `mts build --uncompressed`).
    pub mts_file_uncompressed: u64,
    /// The recipe-only `.mts` (`mts build --recipe-only`).
    pub mts_recipe_file: u64,
    pub mts_memory: u64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BuildMs {
    pub stripify: f64,
    pub simplify: f64,
    pub model: f64,
    pub total: f64,
}

/// One stripifier's row (`mts strips`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StripRow {
    pub triangles: u64,
    pub strips: u64,
    pub swaps: u64,
    pub indices_restart: u64,
    pub indices_per_triangle: f64,
    pub acmr: f64,
    /// Modelled invocations per triangle of the restart buffer in batches
    /// of 96 indices.
    pub acmr_batch96: f64,
    pub ms: f64,
}

impl From<&mts::strip::stats::StripStats> for StripRow {
    fn from(s: &mts::strip::stats::StripStats) -> StripRow {
        StripRow {
            triangles: s.triangles as u64,
            strips: s.strips as u64,
            swaps: s.swaps as u64,
            indices_restart: s.indices_restart as u64,
            indices_per_triangle: s.indices_per_triangle,
            acmr: s.acmr,
            acmr_batch96: s.acmr_batch96,
            ms: s.ms,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stripify {
    #[serde(flatten)]
    pub mts: StripRow,
    pub meshopt: StripRow,
    /// The cache-aware option (`mts strips --cache-aware`).
    pub cache_aware: StripRow,
    /// FIFO-16 ACMR of the meshoptimizer-ordered triangle list.
    pub list_acmr: f64,
    /// Its invocations per triangle in batches of 96 indices.
    pub list_acmr_batch96: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Simplify {
    pub ms: f64,
    pub max_lod: u64,
    pub stop: String,
    pub meshopt_ms_to_10: f64,
    pub meshopt_ms_to_1: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Extraction {
    pub requests: u64,
    pub mts_coherent_us: f64,
    pub mts_scratch_us: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Level {
    pub share: f64,
    pub lod: u64,
    pub triangles: u64,
    pub mts_indices: u64,
    pub list_indices: u64,
    pub meshopt_strip_indices: u64,
    pub mts_acmr: f64,
    pub list_acmr: f64,
    pub meshopt_strip_acmr: f64,
    pub extract_us: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Quality {
    pub share: f64,
    pub mts: Distance,
    pub meshopt: PeerDistance,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Distance {
    pub triangles: u64,
    pub hausdorff: f64,
    pub rms: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeerDistance {
    pub triangles: u64,
    pub hausdorff: f64,
    pub rms: f64,
    pub ms: f64,
}

/// A method measured, or skipped with the reason (meshoptimizer's discrete
/// LoDs on a mesh where its time would be quadratic).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum MethodRow {
    Measured(Method),
    Skipped { method: String, skipped: String },
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Method {
    pub method: String,
    pub build_ms: f64,
    pub memory_bytes: u64,
    pub file_bytes: u64,
    pub file_ratio_to_raw_u16: f64,
    /// From the file's bytes in memory to a source ready for its first
    /// LoD (median ms); `null` for a method without a file reader.
    pub load_ms: Option<f64>,
    pub us_per_change: BTreeMap<String, f64>,
    /// MTS only: the same requests, each LoD extracted from scratch (every
    /// strip walked), against which `us_per_change` shows coherence.
    pub us_per_change_scratch: Option<BTreeMap<String, f64>>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Figure6 {
    pub width: u32,
    pub height: u32,
    pub frames: u64,
    pub rows: Vec<Figure6Row>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Figure6Row {
    pub method: String,
    pub mode: String,
    pub share: f64,
    pub lod: u64,
    pub triangles: u64,
    pub indices_sent: u64,
    pub draw_ms: f64,
    pub fps: f64,
    /// The LoD change's cost: `null` in the per-second mode.
    pub change_us: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scale {
    pub rows: Vec<ScaleRow>,
    pub exponent: ScaleExponent,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScaleRow {
    pub triangles: u64,
    pub stripify_ms: f64,
    pub meshopt_stripify_ms: f64,
    pub simplify_ms: f64,
    pub meshopt_simplify_to_10_ms: f64,
    pub build_ms: f64,
    pub model_bytes: u64,
    /// The ready `.mts` file uncoded (version 3), and loading it (parse,
    /// validate, extractor ready; median ms).
    pub file_bytes: u64,
    pub load_ms: f64,
    /// The coded file `mts build` writes (version 6) and loading it
    /// (decode too).
    pub coded_file_bytes: u64,
    pub coded_load_ms: f64,
    pub extract_lod0_us: f64,
    pub peak_rss_bytes: u64,
}

/// Fitted growth exponents of the scale rows (time or bytes ∝ n^e).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScaleExponent {
    pub stripify_ms: f64,
    pub meshopt_stripify_ms: f64,
    pub simplify_ms: f64,
    pub meshopt_simplify_to_10_ms: f64,
    pub build_ms: f64,
    pub model_bytes: f64,
    pub load_ms: f64,
    pub extract_lod0_us: f64,
}

/// The fast-simplification peer's rows, or why there are none.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum FastSimplificationRun {
    Rows(Vec<FastSimplification>),
    Skipped { skipped: String },
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FastSimplification {
    pub mesh: String,
    pub ratio: f64,
    pub input_triangles: u64,
    pub triangles: u64,
    pub ms: f64,
    pub hausdorff: f64,
    pub rms: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Models, and their names.
    pub models: u64,
    pub model_names: Vec<String>,
    pub instances: u64,
    pub width: u32,
    pub height: u32,
    pub pixel_threshold: f64,
    /// Frames along the camera path.
    pub frames: u64,
    /// Means per frame along the path.
    pub visible: f64,
    pub triangles_drawn: f64,
    pub triangles_full_detail: f64,
    pub indices_drawn: f64,
    pub draws: f64,
    pub extractions_per_frame: f64,
    pub extractions_max: u64,
    /// CPU bytes that grow with the instances, per instance; CPU bytes
    /// per model.
    pub cpu_bytes_per_instance: u64,
    pub cpu_shared_bytes: u64,
    /// Peak GPU bytes of the bucket buffers and transforms; the models'
    /// vertices; the sum of the models' full-detail strip buffers.
    pub gpu_bytes: u64,
    pub gpu_vertex_bytes: u64,
    pub full_detail_strip_bytes: u64,
    /// Peak live bucket buffers.
    pub buffers: u64,
    pub update_ms_median: f64,
    pub update_ms_p99: f64,
    pub frame_ms_median: f64,
    /// Frames drawn also at full detail, and the share of the covered
    /// pixels that differ (`null` when none were compared).
    pub compared_frames: u64,
    pub differing_pixel_share: Option<f64>,
    /// The same, counting only pixels whose colour moved by more than
    /// [`crate::bench::results::IMAGE_TOLERANCE`] of 255 in a channel.
    pub visibly_differing_pixel_share: Option<f64>,
    /// The same, counting only pixels covered by instances in one image
    /// and not the other (silhouettes that moved).
    pub coverage_differing_pixel_share: Option<f64>,
    /// Over the same frames against the full-detail frame supersampled
    /// 4 × 4 and box-filtered: the LoD frames' RMSE over the full-detail
    /// frames' at one sample per pixel (1: as close to the truth as
    /// drawing everything; [`mts_render::image_error`]); `null` when none
    /// were compared.
    pub image_error_ratio: Option<f64>,
}

/// The adapter's own vertex work per method and level, beside the cache
/// models' predictions for the buffer it drew (`mts bench render`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VertexWork {
    /// The model measured.
    pub model: String,
    /// Whether the adapter offers pipeline statistics; when not, every
    /// measured count is null.
    pub pipeline_statistics: bool,
    /// Whether it offers timestamps; when not, `gpu_ms` is null.
    pub timestamps: bool,
    /// Why measured fields are null, if they are.
    pub note: Option<String>,
    pub rows: Vec<VertexRow>,
    /// Per cache model (`fifo16`, `batch96`, `batch384`, `lru32`): the
    /// geometric mean over rows of measured/modelled invocations, and its
    /// spread (mean |ln ratio|); null without statistics.
    pub model_fit: BTreeMap<String, Option<ModelFit>>,
    /// The model with the smallest spread.
    pub best_model: Option<String>,
    /// Rows whose clipper count differs from the triangles drawn.
    pub clipper_mismatches: u64,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFit {
    pub ratio_geomean: f64,
    pub mean_abs_log_ratio: f64,
}

/// One method at one level: what it sent and what the adapter did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VertexRow {
    pub ratio: f64,
    pub lod: u64,
    /// Non-degenerate triangles drawn.
    pub triangles: u64,
    /// `mts_strips`, `mts_cache_aware`, `meshopt_strips`,
    /// `cache_aware_strips`, `meshopt_list`, `list`, or a baseline's list.
    pub method: String,
    /// Indices in the drawn buffer (restart values or stitching included).
    pub indices_sent: u64,
    pub vertex_invocations: Option<u64>,
    pub invocations_per_triangle: Option<f64>,
    pub clipper_invocations: Option<u64>,
    /// `clipper_invocations == triangles` (strips' degenerate windows may
    /// reach the clipper on some drivers: then false, and counted).
    pub clipper_matches_triangles: Option<bool>,
    /// Primitives the buffer assembles to, degenerate windows (swaps,
    /// stitching) included: what the clipper counts where it counts them.
    pub primitives_assembled: u64,
    pub fragment_invocations: Option<u64>,
    /// Median GPU milliseconds of the pass over 5 passes.
    pub gpu_ms: Option<f64>,
    /// Modelled invocations of the drawn buffer per cache model.
    pub modelled: BTreeMap<String, u64>,
    /// measured / modelled per cache model.
    pub measured_over_modelled: BTreeMap<String, Option<f64>>,
}

impl Results {
    /// The typed form of what the bench assembled, or an error naming the
    /// first key that is missing, extra or of the wrong type.
    ///
    /// # Errors
    /// When `value` is not this layout.
    pub fn from_value(value: serde_json::Value) -> Result<Results> {
        serde_path_to_error::deserialize(value)
            .map_err(|e| anyhow::anyhow!("results.json layout: at `{}`: {}", e.path(), e.inner()))
    }

    /// Reads and checks `path` (the layout and the schema version).
    ///
    /// # Errors
    /// When the file cannot be read, is not this layout (the error names the
    /// key) or has another schema version.
    pub fn load(path: &Path) -> Result<Results> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        let mut de = serde_json::Deserializer::from_str(&text);
        let results: Results = serde_path_to_error::deserialize(&mut de)
            .map_err(|e| anyhow::anyhow!("{}: at `{}`: {}", path.display(), e.path(), e.inner()))?;
        if results.schema != SCHEMA_VERSION {
            anyhow::bail!(
                "{}: schema {} where this build reads {} (run mts bench again)",
                path.display(),
                results.schema,
                SCHEMA_VERSION
            );
        }
        Ok(results)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn committed() -> serde_json::Value {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../docs/report/results.json"
        );
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
    }

    /// The committed report loads, and writing it back gives the same JSON.
    #[test]
    fn the_committed_report_round_trips() {
        let value = committed();
        let typed = Results::from_value(value.clone()).unwrap();
        assert_eq!(serde_json::to_value(&typed).unwrap(), value);
    }

    /// A renamed key and a NaN written as null are errors that name where.
    #[test]
    fn a_renamed_key_or_a_null_is_named() {
        let mut value = committed();
        let bytes = value["models"][0]["bytes"].as_object_mut().unwrap();
        let raw = bytes.remove("raw").unwrap();
        bytes.insert("raw_bytes".into(), raw);
        let e = Results::from_value(value).unwrap_err().to_string();
        assert!(
            e.contains("models[0].bytes") && e.contains("raw_bytes"),
            "{e}"
        );
        let mut value = committed();
        value["models"][0]["levels"][2]["mts_acmr"] = serde_json::Value::Null;
        let e = Results::from_value(value).unwrap_err().to_string();
        assert!(e.contains("models[0].levels[2].mts_acmr"), "{e}");
    }

    /// Every key of the layout is documented in `docs/bench-schema.md`.
    #[test]
    fn every_key_is_in_the_schema_doc() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/bench-schema.md");
        let doc = std::fs::read_to_string(path).unwrap();
        fn keys(v: &serde_json::Value, out: &mut std::collections::BTreeSet<String>) {
            match v {
                serde_json::Value::Object(m) => {
                    for (k, x) in m {
                        out.insert(k.clone());
                        keys(x, out);
                    }
                }
                serde_json::Value::Array(a) => a.iter().for_each(|x| keys(x, out)),
                _ => {}
            }
        }
        // The committed report's keys, and a quick run's (its view-dependent
        // run: the committed report may have none).
        let quick = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/bench_quick.json");
        let mut all = std::collections::BTreeSet::new();
        for value in [
            committed(),
            serde_json::to_value(Results::load(Path::new(quick)).unwrap()).unwrap(),
        ] {
            keys(
                &serde_json::to_value(Results::from_value(value).unwrap()).unwrap(),
                &mut all,
            );
        }
        let missing: Vec<_> = all
            .iter()
            .filter(|k| !doc.contains(&format!("\"{k}\"")) && !doc.contains(&format!("{k}:")))
            .collect();
        assert!(
            missing.is_empty(),
            "not in docs/bench-schema.md: {missing:?}"
        );
        assert!(all.len() > 80, "{} keys", all.len());
    }
}
