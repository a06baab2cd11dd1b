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

/// `f` on every item, on up to all cores when there are at least `min`
/// items (else on the caller alone: a thread costs tens of microseconds),
/// items handed out `grain` at a time from a shared queue. A worker's
/// panic is resumed on the caller.
pub(crate) fn for_each_mut<T: Send>(
    items: &mut [T],
    min: usize,
    grain: usize,
    f: impl Fn(&mut T) + Sync,
) {
    let threads = std::thread::available_parallelism()
        .map_or(1, std::num::NonZeroUsize::get)
        .min(items.len().div_ceil(grain.max(1)));
    if threads < 2 || items.len() < min {
        items.iter_mut().for_each(f);
        return;
    }
    let queue = std::sync::Mutex::new(items.chunks_mut(grain.max(1)));
    // A poisoned lock means another worker panicked: stop, and let the
    // join below resume that panic.
    let work = || {
        while let Some(chunk) = queue.lock().ok().and_then(|mut q| q.next()) {
            chunk.iter_mut().for_each(&f);
        }
    };
    std::thread::scope(|scope| {
        let workers: Vec<_> = (1..threads).map(|_| scope.spawn(work)).collect();
        work();
        for w in workers {
            w.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
        }
    });
}

#[cfg(test)]
mod tests {
    #[test]
    fn for_each_mut_visits_every_item_once_above_and_below_the_minimum() {
        for (n, min) in [(1000, 10), (1000, 2000), (3, 1), (0, 0)] {
            let mut items: Vec<usize> = (0..n).collect();
            super::for_each_mut(&mut items, min, 7, |x| *x = *x * 3 + 1);
            assert_eq!(items, (0..n).map(|i| i * 3 + 1).collect::<Vec<_>>());
        }
    }

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
