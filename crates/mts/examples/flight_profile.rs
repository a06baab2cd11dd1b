//! Times [`mts::hierarchy::ViewDependent::update`] along the flight of
//! `mts bench view-dependent` over a hierarchy file (low over a terrain,
//! corner to corner; around anything else; 40° vertical field of view),
//! with no frustum, for profiling.
//!
//! `cargo run --release -p mts --example flight_profile -- H.mts [FRAMES] [PX] [HEIGHT] [PASSES]`
//! (passes fly there and back, for a profiler's sake).

use glam::Vec3;
use mts::hierarchy::{Hierarchy, View, ViewDependent};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: flight_profile H.mts [FRAMES] [PX] [HEIGHT] [PASSES]";
    let path = std::path::Path::new(args.get(1).ok_or(usage)?);
    let frames: usize = args.get(2).map_or(Ok(120), |s| s.parse())?;
    let px: f32 = args.get(3).map_or(Ok(1.0), |s| s.parse())?;
    let height: f32 = args.get(4).map_or(Ok(360.0), |s| s.parse())?;
    let passes: usize = args.get(5).map_or(Ok(1), |s| s.parse())?;
    let h = Hierarchy::load(path)?;
    let (lo, hi) = bounds(h.positions());
    let projection = mts::Projection::Perspective {
        fov_y: 40f32.to_radians(),
        viewport_height: height,
    };
    let mut vd = ViewDependent::new(&h);
    let mut times = Vec::with_capacity(frames);
    let (mut walked, mut written) = (0, 0);
    let mut sum = [0usize; 7];
    for f in 0..frames * passes {
        let (pass, f) = (f / frames, f % frames);
        let f = if pass % 2 == 0 { f } else { frames - 1 - f };
        let t = f as f32 / (frames - 1).max(1) as f32;
        let view = View {
            projection,
            eye: eye_at(lo, hi, t),
            pixel_threshold: px,
            frustum: None,
        };
        let t0 = std::time::Instant::now();
        let u = vd.update(&view);
        times.push(t0.elapsed().as_secs_f64() * 1e3);
        walked += u.strips_walked;
        written += u.indices_written;
        for (a, b) in sum.iter_mut().zip([
            u.groups_drawn,
            u.clusters_drawn,
            u.groups_entered,
            u.groups_left,
            u.groups_changed,
            u.clusters_entered,
            u.clusters_left,
        ]) {
            *a += b;
        }
    }
    let n = times.len();
    println!(
        "a frame on average: {} groups and {} clusters drawn; groups {} entered, {} left, {} changed; clusters {} entered, {} left",
        sum[0] / n, sum[1] / n, sum[2] / n, sum[3] / n, sum[4] / n, sum[5] / n, sum[6] / n
    );
    let first = times[0];
    let mut rest = times[1..].to_vec();
    rest.sort_by(f64::total_cmp);
    println!(
        "first {first:.1} ms; then median {:.2} ms, p99 {:.2} ms over {} frames; \
         {} triangles, {:.2} indices a triangle, arena {} indices; \
         {walked} strips walked, {written} indices written",
        rest[rest.len() / 2],
        rest[(rest.len() * 99 / 100).min(rest.len() - 1)],
        rest.len(),
        vd.triangle_count(),
        vd.indices_sent() as f64 / vd.triangle_count().max(1) as f64,
        vd.buffer().len(),
    );
    Ok(())
}

fn bounds(p: &[Vec3]) -> (Vec3, Vec3) {
    p.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &v| {
        (lo.min(v), hi.max(v))
    })
}

/// The eye of the bench's flight at `t` in 0..=1: low over a terrain (a
/// box flat along `y`), else circling the box while closing in.
fn eye_at(lo: Vec3, hi: Vec3, t: f32) -> Vec3 {
    let extent = hi - lo;
    let largest = extent.max_element();
    if extent.y >= 0.25 * largest {
        let radius = 0.5 * extent.length();
        let angle = t * 3.0 * std::f32::consts::PI;
        let distance = radius * (2.2 - 1.4 * t);
        return 0.5 * (lo + hi)
            + Vec3::new(
                distance * angle.cos(),
                0.2 * radius * (2.0 * angle).sin(),
                distance * angle.sin(),
            );
    }
    let from = Vec3::new(lo.x + 0.05 * extent.x, 0.0, lo.z + 0.05 * extent.z);
    let to = Vec3::new(hi.x - 0.05 * extent.x, 0.0, hi.z - 0.25 * extent.z);
    let ground = from.lerp(to, t);
    Vec3::new(ground.x, hi.y + 0.06 * largest, ground.z)
}
