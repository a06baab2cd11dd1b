//! Medians of timed runs.

use std::time::Instant;

pub fn median_ms<T>(repeat: usize, mut f: impl FnMut() -> T) -> (T, f64) {
    let mut times = Vec::with_capacity(repeat.max(1));
    let mut out = None;
    for _ in 0..repeat.max(1) {
        let t = Instant::now();
        let r = f();
        times.push(t.elapsed().as_secs_f64() * 1e3);
        out = Some(r);
    }
    times.sort_by(f64::total_cmp);
    (out.expect("at least one run"), times[times.len() / 2])
}
