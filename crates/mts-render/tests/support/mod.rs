//! The GPU helpers shared by the renderer's integration tests: an adapter
//! on the backends asked for, or a skip with a message when there is none
//! (a failure when `MTS_REQUIRE` names `gpu`).

use mts::Error;
use mts_render::Gpu;

/// Whether `MTS_REQUIRE` (set by `.ci/run`) names `gpu`: a missing
/// adapter then fails instead of skipping.
pub fn required_gpu() -> bool {
    std::env::var("MTS_REQUIRE").is_ok_and(|v| v.split(',').any(|w| w.trim() == "gpu"))
}

/// The GPU on `backends`, or `None` with a message (a failure when
/// `MTS_REQUIRE` names gpu).
pub fn gpu_on(backends: wgpu::Backends, what: &str) -> Option<Gpu> {
    match Gpu::new_headless_on(backends) {
        Ok(gpu) => Some(gpu),
        Err(Error::NoAdapter(why)) => {
            assert!(
                !required_gpu(),
                "MTS_REQUIRE names gpu: no {what} adapter ({why})"
            );
            eprintln!("skipped: no {what} adapter ({why})");
            None
        }
        Err(e) => panic!("{what} setup failed: {e}"),
    }
}

/// The default headless GPU (any backend), or `None` with a message (a
/// failure when `MTS_REQUIRE` names gpu).
pub fn default_gpu() -> Option<Gpu> {
    match Gpu::new_headless() {
        Ok(gpu) => {
            eprintln!("adapter: {}", gpu.report());
            Some(gpu)
        }
        Err(Error::NoAdapter(why)) => {
            assert!(!required_gpu(), "MTS_REQUIRE names gpu: no adapter ({why})");
            eprintln!("skipped: no graphics adapter ({why}); install mesa-vulkan-drivers");
            None
        }
        Err(e) => panic!("GPU setup failed: {e}"),
    }
}

/// Pixels that differ, and the largest channel difference.
#[allow(dead_code)] // not every test file compares images
pub fn difference(a: &mts_render::headless::Image, b: &mts_render::headless::Image) -> (usize, u8) {
    let max = a
        .rgba
        .iter()
        .zip(&b.rgba)
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap_or(0);
    (a.differing_pixels(b), max)
}
