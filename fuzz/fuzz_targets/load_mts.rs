//! The `.mts` loader on arbitrary bytes: an error or a model whose
//! invariants hold and whose extraction stays in range, never a panic.
//! Each input is tried whole and as a prefix, as is and with its header's length and checksum
//! rewritten, so that mutations reach the section parsers.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mts::model::format::seal;
use mts::{Extractor, MtsModel};

fn try_load(bytes: &[u8]) {
    if let Ok(model) = MtsModel::from_bytes(bytes, std::path::Path::new("fuzz.mts")) {
        assert_eq!(model.validate(), Ok(()));
        let mut ex = Extractor::new(&model);
        for lod in [0, model.max_lod() / 2, model.max_lod()] {
            ex.set_lod(lod);
        }
        assert_eq!(ex.overflows(), 0);
    }
    // As a prefix of a file (a version-6 file opens from its chunks).
    if let Ok(p) = MtsModel::from_prefix(bytes, std::path::Path::new("fuzz.mts")) {
        assert_eq!(p.model.validate(), Ok(()));
        let mut ex = Extractor::new(&p.model);
        ex.set_lod(p.model_lod(*p.lods_available().end()));
        assert_eq!(ex.overflows(), 0);
    }
}

fuzz_target!(|data: &[u8]| {
    try_load(data);
    let mut sealed = data.to_vec();
    seal(&mut sealed);
    try_load(&sealed);
});
