//! The cluster-tree stream decoders and the progressive mesh loader on
//! arbitrary bytes: an error or a valid mesh, never a panic. The prefix
//! decoder skips the checksum, so mutations reach the packet parser.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mts::baselines::cluster::stream;
use mts::baselines::ProgressiveMesh;
use mts::LodSource;

fuzz_target!(|data: &[u8]| {
    if let Ok(d) = stream::decode_prefix(data, "fuzz.stream") {
        assert!(d.mesh().validate().is_ok());
    }
    if let Ok(d) = stream::decode(data, "fuzz.stream") {
        assert!(d.is_complete() && d.mesh().validate().is_ok());
    }
    if let Ok(mut pm) = ProgressiveMesh::from_bytes(data, "fuzz.pm") {
        pm.validate().unwrap();
        for lod in [0, pm.max_lod() / 2, pm.max_lod()] {
            pm.set_lod(lod);
        }
    }
});
