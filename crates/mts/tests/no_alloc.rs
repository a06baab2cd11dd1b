//! `Extractor::set_lod` and the baselines' `LodSource::set_lod` allocate
//! nothing after construction: counted with a global allocator wrapper (this
//! test binary only; one test, so no other thread allocates meanwhile).

use mts::mesh::generate::Generated;
use mts::model::BuildOptions;
use mts::simplify::SimplifyOptions;
use mts::{stripify, Extractor, Mesh, StripifyOptions};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn set_lod_allocates_nothing() {
    let mesh: Mesh = "torus:20k".parse::<Generated>().unwrap().build();
    let strips = stripify(&mesh, &StripifyOptions::default());
    let collapses = mts::simplify(&mesh, &SimplifyOptions::default()).collapses;
    let model = mts::model::build(&mesh, &strips, &collapses, &BuildOptions::default());
    let mut ex = Extractor::new(&model);
    ex.set_lod(0);
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let max = model.max_lod();
    for lod in (0..=max).step_by(7).chain((0..=max).rev().step_by(13)) {
        ex.set_lod(lod);
    }
    for lod in [max, 0, max / 2, max / 3] {
        ex.set_lod_from_scratch(lod);
        ex.set_triangles(1000);
        ex.set_ratio(0.5);
    }
    assert_eq!(ALLOCATIONS.load(Ordering::Relaxed) - before, 0);

    // The baselines, over the same sequence.
    use mts::methods::Method;
    let mut sources: Vec<_> = Method::ALL
        .iter()
        .filter(|&&m| m != Method::Mts)
        .map(|m| m.source(&model, &mesh).unwrap())
        .collect();
    for source in &mut sources {
        source.set_lod(0);
        let max = source.max_lod();
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        for lod in (0..=max)
            .step_by(7)
            .chain((0..=max).rev().step_by(13))
            .chain([max, 0, max / 2, max / 3])
        {
            source.set_lod(lod);
        }
        assert_eq!(
            ALLOCATIONS.load(Ordering::Relaxed) - before,
            0,
            "{}",
            source.name()
        );
    }
}
