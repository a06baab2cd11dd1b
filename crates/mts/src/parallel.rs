//! One work queue on all cores: items taken by index from a shared
//! counter (so uneven items balance), each worker with its own scratch
//! state, the results returned in item order.

use std::sync::atomic::{AtomicUsize, Ordering};

/// `f(&mut scratch, i)` for every `i` in `0..n`, on up to all cores, each
/// worker's scratch made by `scratch()`; the results in order of `i`. A
/// worker's panic is resumed on the caller.
pub(crate) fn map_indexed<S, T: Send>(
    n: usize,
    scratch: impl Fn() -> S + Sync,
    f: impl Fn(&mut S, usize) -> T + Sync,
) -> Vec<T> {
    let threads = std::thread::available_parallelism()
        .map_or(1, std::num::NonZeroUsize::get)
        .min(n)
        .max(1);
    let next = AtomicUsize::new(0);
    let mut done: Vec<(usize, T)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut state = scratch();
                    let mut out = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        if i >= n {
                            break;
                        }
                        out.push((i, f(&mut state, i)));
                    }
                    out
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    done.sort_unstable_by_key(|(i, _)| *i);
    done.into_iter().map(|(_, t)| t).collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn results_come_in_item_order_with_per_worker_scratch() {
        let out = super::map_indexed(1000, Vec::new, |seen: &mut Vec<usize>, i| {
            seen.push(i);
            i * i
        });
        assert_eq!(out, (0..1000).map(|i| i * i).collect::<Vec<_>>());
        assert!(super::map_indexed(0, || (), |(), i| i).is_empty());
    }
}
