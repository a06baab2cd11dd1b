//! `mts bench render --scene N --json` reports the scene's image-error
//! ratio (issue 33, item 6) beside the differing-pixel share: exactly 1 at
//! 0 pixels (every instance at full detail draws the full-detail frame),
//! finite and positive at 1. Where there is no adapter the command says
//! so: skipped, unless `MTS_REQUIRE` names gpu (as in CI).

mod common;

use common::{json, mts};

/// The scene object of `mts bench render --generated torus:5k --scene 50
/// --json` at `px` pixels, small and short; `None` when skipped.
fn scene_at(px: &str) -> Option<serde_json::Value> {
    let (ok, out, err) = mts(&[
        "bench",
        "render",
        "--generated",
        "torus:5k",
        "--scene",
        "50",
        "--pixel-error",
        px,
        "--frames",
        "2",
        "--size",
        "160x120",
        "--json",
    ]);
    if common::skipped_without_adapter(ok, &err) {
        return None;
    }
    assert!(ok, "{err}");
    Some(json(&out)["scene"].clone())
}

#[test]
fn bench_render_scene_reports_the_image_error_ratio() {
    let Some(full) = scene_at("0") else { return };
    assert_eq!(full["compared_frames"], 3, "{full}");
    assert_eq!(full["image_error_ratio"].as_f64(), Some(1.0), "{full}");
    assert_eq!(full["differing_pixel_share"].as_f64(), Some(0.0), "{full}");
    let Some(lod) = scene_at("1") else { return };
    let ratio = lod["image_error_ratio"].as_f64();
    assert!(ratio.is_some_and(|r| r.is_finite() && r > 0.0), "{lod}");
    assert!(lod["differing_pixel_share"].as_f64().is_some(), "{lod}");
}
