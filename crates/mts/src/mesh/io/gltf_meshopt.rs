//! Buffer views compressed with `EXT_meshopt_compression` or its
//! successor `KHR_meshopt_compression` (what gltfpack `-c`/`-cc` writes):
//! the extension objects read from the document and checked, and each
//! view decoded through meshoptimizer's decoders (the `meshopt` crate,
//! which the specification names as the reference decoder).
//!
//! The rules checked are the extension's ("JSON schema updates"): the
//! parent view's `byteLength` is `byteStride × count`, and equals its own
//! `byteStride` where it has one; `ATTRIBUTES` with a stride divisible by 4
//! and at most 256; `TRIANGLES` with a count divisible by 3; `TRIANGLES`
//! and `INDICES` with a stride of 2 or 4 and no filter; `OCTAHEDRAL` and
//! `COLOR` (the `KHR_` extension's) with a stride of 4 or 8, `QUATERNION`
//! of 8, `EXPONENTIAL` divisible by 4. The C decoders assert these, so
//! they are checked before any call.
//!
//! **No allocation sized by an untrusted count.** A stream cannot expand
//! without bound: in version 0 of the attribute codec each byte of 16
//! elements costs at least 2 header bits (64 × at best, before the tail);
//! version 1 (the `KHR_` extension's) spends at least 2 control bits per
//! byte channel of a block of up to 256 elements (1024 ×); the index
//! codecs spend at least a byte per triangle or per index (12 ×). So a
//! view whose decoded length is more than twice that ([`max_expansion`])
//! times its compressed bytes is refused before anything is allocated, as
//! is one of more elements than the caller's vertex limit (three times its
//! triangle limit); the compressed bytes lie in a buffer that was read, so
//! the output is bounded by the input.
//!
//! A stream the decoder rejects is named by its view, its buffer and its
//! first byte (the file offset for a `.glb`'s BIN chunk); meshoptimizer's
//! decoders report why (an unknown header or version, data that ends
//! early or is malformed, bytes left over), not where inside the stream.

use serde_json::Value;

/// The extension names read, the ratified `KHR_` one first: a view that
/// has both is decoded from the `KHR_` object.
pub(super) const EXTENSIONS: [&str; 2] = ["KHR_meshopt_compression", "EXT_meshopt_compression"];

/// The most bytes a compressed stream may decode to per compressed byte:
/// twice the best case of its codec (see the module docs), by the version
/// in an attribute stream's header byte.
pub(super) fn max_expansion(mode: Mode, header: u8) -> u64 {
    match (mode, header & 0x0f) {
        (Mode::Attributes, 0) => 128,
        (Mode::Attributes, _) => 2048,
        _ => 128,
    }
}

/// The bitstream a view is coded in (the extension's `mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Mode {
    Attributes,
    Triangles,
    Indices,
}

/// The filter applied after an attribute stream is decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Filter {
    None,
    Octahedral,
    Quaternion,
    Exponential,
    Color,
}

/// One compressed view's extension object, checked.
#[derive(Clone, Debug)]
pub(super) struct Compressed {
    /// Which extension the object came from (for messages).
    pub extension: &'static str,
    /// The buffer holding the compressed bytes, and their range in it.
    pub buffer: usize,
    pub offset: u64,
    pub length: u64,
    pub stride: usize,
    pub count: u64,
    pub mode: Mode,
    pub filter: Filter,
}

impl Compressed {
    /// The decoded length: `stride × count` (checked to fit at parse).
    pub fn decoded_len(&self) -> u64 {
        self.stride as u64 * self.count
    }
}

/// The compressed views of a document (its `bufferViews`, as JSON), one
/// entry per view; `None` for a view without either extension.
///
/// # Errors
/// The index of the view at fault and what is wrong with its extension
/// object.
pub(super) fn compressed_views(
    document: &Value,
) -> std::result::Result<Vec<Option<Compressed>>, (usize, String)> {
    let Some(views) = document.get("bufferViews").and_then(Value::as_array) else {
        return Ok(Vec::new());
    };
    views
        .iter()
        .enumerate()
        .map(|(v, view)| compressed_view(view).map_err(|m| (v, m)))
        .collect()
}

fn compressed_view(view: &Value) -> std::result::Result<Option<Compressed>, String> {
    let Some(extensions) = view.get("extensions") else {
        return Ok(None);
    };
    let Some((extension, object)) = EXTENSIONS
        .iter()
        .find_map(|name| extensions.get(*name).map(|o| (*name, o)))
    else {
        return Ok(None);
    };
    let fail = |m: String| format!("{extension}: {m}");
    let integer = |key: &str, default: Option<u64>| match object.get(key) {
        None => default.ok_or_else(|| fail(format!("`{key}` is missing"))),
        Some(x) => as_integer(x).ok_or_else(|| {
            fail(format!(
                "`{key}` is {x}, not a non-negative integer below 2^53"
            ))
        }),
    };
    let buffer = integer("buffer", None)?;
    let offset = integer("byteOffset", Some(0))?;
    let length = integer("byteLength", None)?;
    let stride = integer("byteStride", None)?;
    let count = integer("count", None)?;
    let mode = match object.get("mode").map(|m| (m, m.as_str())) {
        Some((_, Some("ATTRIBUTES"))) => Mode::Attributes,
        Some((_, Some("TRIANGLES"))) => Mode::Triangles,
        Some((_, Some("INDICES"))) => Mode::Indices,
        None => return Err(fail("`mode` is missing".into())),
        Some((m, _)) => {
            return Err(fail(format!(
                "`mode` is {m}, not ATTRIBUTES, TRIANGLES or INDICES"
            )))
        }
    };
    let is_khr = extension == EXTENSIONS[0];
    let filter = match object.get("filter").map(|f| f.as_str()) {
        None | Some(Some("NONE")) => Filter::None,
        Some(Some("OCTAHEDRAL")) => Filter::Octahedral,
        Some(Some("QUATERNION")) => Filter::Quaternion,
        Some(Some("EXPONENTIAL")) => Filter::Exponential,
        Some(Some("COLOR")) if is_khr => Filter::Color,
        Some(_) => {
            return Err(fail(format!(
                "`filter` is {}, not NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL{}",
                object["filter"],
                if is_khr { " or COLOR" } else { "" }
            )))
        }
    };
    let stride_ok = match mode {
        Mode::Attributes => stride > 0 && stride % 4 == 0 && stride <= 256,
        Mode::Triangles | Mode::Indices => stride == 2 || stride == 4,
    };
    if !stride_ok {
        return Err(fail(format!(
            "byteStride {stride} for {mode:?}: {}",
            match mode {
                Mode::Attributes => "it must be a multiple of 4 from 4 to 256",
                _ => "it must be 2 or 4",
            }
        )));
    }
    if mode == Mode::Triangles && count % 3 != 0 {
        return Err(fail(format!(
            "count {count} for TRIANGLES is not a multiple of 3"
        )));
    }
    let filter_ok = match filter {
        Filter::None => true,
        _ if mode != Mode::Attributes => false,
        Filter::Octahedral | Filter::Color => stride == 4 || stride == 8,
        Filter::Quaternion => stride == 8,
        Filter::Exponential => true,
    };
    if !filter_ok {
        return Err(fail(format!(
            "filter {filter:?} with mode {mode:?} and byteStride {stride}"
        )));
    }
    let decoded = stride.checked_mul(count);
    let parent_length = view.get("byteLength").and_then(as_integer);
    if decoded.is_none() || parent_length != decoded {
        return Err(fail(format!(
            "byteStride {stride} × count {count} is not the view's byteLength {}",
            parent_length.map_or_else(|| "(none)".to_owned(), |l| l.to_string())
        )));
    }
    if let Some(parent) = view.get("byteStride").and_then(as_integer) {
        if parent != stride {
            return Err(fail(format!(
                "byteStride {stride}, the view's own byteStride {parent}"
            )));
        }
    }
    Ok(Some(Compressed {
        extension,
        buffer: buffer as usize,
        offset,
        length,
        stride: stride as usize,
        count,
        mode,
        filter,
    }))
}

/// A JSON number that is a non-negative integer below 2^53, written as an
/// integer or as a float with no fraction (`4.0`), as glTF allows.
pub(super) fn as_integer(x: &Value) -> Option<u64> {
    if let Some(n) = x.as_u64() {
        return (n < 1 << 53).then_some(n);
    }
    let f = x.as_f64()?;
    (f >= 0.0 && f < (1u64 << 53) as f64 && f.fract() == 0.0).then_some(f as u64)
}

/// Decodes the compressed `bytes` of view `c` into its `stride × count`
/// bytes, filter applied; `max_count` is the most elements allowed.
///
/// # Errors
/// Why the stream does not decode: more elements than `max_count`, an
/// expansion above [`max_expansion`] (both checked before anything is
/// allocated), or the decoder's reason.
///
/// Cost: O(decoded bytes), one allocation of that size.
pub(super) fn decode(
    c: &Compressed,
    bytes: &[u8],
    max_count: u64,
) -> std::result::Result<Vec<u8>, String> {
    let decoded = c.decoded_len();
    let most = max_expansion(c.mode, bytes.first().copied().unwrap_or(0));
    if decoded > most.saturating_mul(bytes.len() as u64) {
        return Err(format!(
            "{} bytes decoding to {decoded} ({} × {}): more than {most} × its bytes, which no \
             valid stream expands to",
            bytes.len(),
            c.count,
            c.stride
        ));
    }
    if c.count > max_count {
        return Err(format!(
            "{} elements, more than the {max_count} allowed by the limit on triangles (three \
             times as many vertices){}",
            c.count,
            super::RAISE_LIMIT
        ));
    }
    let count = c.count as usize;
    // Words, so that the filters (which read u16 and u32 lanes) see
    // aligned data; the bytes are copied out at the end.
    let mut words = vec![0u32; (decoded as usize).div_ceil(4)];
    let out = words.as_mut_ptr().cast::<std::ffi::c_void>();
    // SAFETY: `out` holds at least `count × stride` bytes, the length each
    // decoder writes; the arguments satisfy the decoders' asserts (stride
    // checked in `compressed_view`, count a multiple of 3 for triangles);
    // the decoders read `bytes` within its length and are documented safe
    // on untrusted input.
    let code = unsafe {
        match c.mode {
            Mode::Attributes => meshopt::ffi::meshopt_decodeVertexBuffer(
                out,
                count,
                c.stride,
                bytes.as_ptr(),
                bytes.len(),
            ),
            Mode::Triangles => meshopt::ffi::meshopt_decodeIndexBuffer(
                out,
                count,
                c.stride,
                bytes.as_ptr(),
                bytes.len(),
            ),
            Mode::Indices => meshopt::ffi::meshopt_decodeIndexSequence(
                out,
                count,
                c.stride,
                bytes.as_ptr(),
                bytes.len(),
            ),
        }
    };
    if code != 0 {
        let header = bytes
            .first()
            .map_or_else(|| "none".to_owned(), |h| format!("{h:#04x}"));
        return Err(match code {
            -1 => format!(
                "the {:?} stream's header byte ({header}) is not one of a version this \
                 decoder knows",
                c.mode
            ),
            -2 => format!(
                "the {:?} stream ends early or is malformed ({} bytes for {count} elements of \
                 {} bytes)",
                c.mode,
                bytes.len(),
                c.stride
            ),
            -3 => format!(
                "the {:?} stream has bytes left over after its {count} elements",
                c.mode
            ),
            other => format!("the {:?} stream does not decode (code {other})", c.mode),
        });
    }
    // SAFETY: as above, `out` holds `count × stride` bytes; each filter
    // reads and writes `count` elements of `stride` bytes, with the stride
    // it requires (checked in `compressed_view`).
    unsafe {
        match c.filter {
            Filter::None => {}
            Filter::Octahedral => meshopt::ffi::meshopt_decodeFilterOct(out, count, c.stride),
            Filter::Quaternion => meshopt::ffi::meshopt_decodeFilterQuat(out, count, c.stride),
            Filter::Exponential => meshopt::ffi::meshopt_decodeFilterExp(out, count, c.stride),
            Filter::Color => meshopt::ffi::meshopt_decodeFilterColor(out, count, c.stride),
        }
    }
    let mut bytes_out: Vec<u8> = bytemuck::cast_slice(&words).to_vec();
    bytes_out.truncate(decoded as usize);
    Ok(bytes_out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn view(ext: Value, length: u64) -> Value {
        json!({"buffer": 1, "byteLength": length,
               "extensions": {"EXT_meshopt_compression": ext}})
    }

    #[test]
    fn the_extension_rules_are_checked() {
        let ok = json!({"buffer": 0, "byteLength": 10, "byteStride": 8, "count": 4,
                        "mode": "ATTRIBUTES"});
        let c = compressed_view(&view(ok.clone(), 32)).unwrap().unwrap();
        assert_eq!((c.buffer, c.offset, c.stride, c.count), (0, 0, 8, 4));
        assert_eq!(c.filter, Filter::None);
        // The parent's length must be stride × count.
        let e = compressed_view(&view(ok, 36)).unwrap_err();
        assert!(e.contains("byteLength 36"), "{e}");
        let bad = [
            (
                json!({"buffer": 0, "byteLength": 1, "byteStride": 6, "count": 2,
                    "mode": "ATTRIBUTES"}),
                12,
                "multiple of 4",
            ),
            (
                json!({"buffer": 0, "byteLength": 1, "byteStride": 2, "count": 4,
                    "mode": "TRIANGLES"}),
                8,
                "multiple of 3",
            ),
            (
                json!({"buffer": 0, "byteLength": 1, "byteStride": 2, "count": 3,
                    "mode": "TRIANGLES", "filter": "OCTAHEDRAL"}),
                6,
                "filter Octahedral",
            ),
            (
                json!({"buffer": 0, "byteLength": 1, "byteStride": 4, "count": 3,
                    "mode": "ATTRIBUTES", "filter": "QUATERNION"}),
                12,
                "filter Quaternion",
            ),
            (
                json!({"buffer": 0, "byteLength": 1, "byteStride": 4, "count": 3,
                    "mode": "ATTRIBUTES", "filter": "COLOR"}),
                12,
                "`filter` is \"COLOR\"",
            ),
            (
                json!({"buffer": 0, "byteLength": 1, "byteStride": 4, "count": 3,
                    "mode": "LINES"}),
                12,
                "`mode` is \"LINES\"",
            ),
            (
                json!({"buffer": 0, "byteStride": 4, "count": 3,
                    "mode": "INDICES"}),
                12,
                "`byteLength` is missing",
            ),
            (
                json!({"buffer": -1, "byteLength": 1, "byteStride": 4, "count": 3,
                    "mode": "INDICES"}),
                12,
                "`buffer` is -1",
            ),
        ];
        for (ext, length, want) in bad {
            let e = compressed_view(&view(ext.clone(), length)).unwrap_err();
            assert!(e.contains(want), "{ext}: {e}");
        }
        // The KHR_ successor has COLOR, and wins over EXT_ in one view.
        let both = json!({"buffer": 1, "byteLength": 12, "extensions": {
            "EXT_meshopt_compression": {"buffer": 0, "byteLength": 1, "byteStride": 4,
                                        "count": 3, "mode": "ATTRIBUTES"},
            "KHR_meshopt_compression": {"buffer": 2, "byteLength": 1, "byteStride": 4,
                                        "count": 3, "mode": "ATTRIBUTES", "filter": "COLOR"}}});
        let c = compressed_view(&both).unwrap().unwrap();
        assert_eq!(
            (c.extension, c.buffer, c.filter),
            (EXTENSIONS[0], 2, Filter::Color)
        );
    }

    #[test]
    fn streams_decode_to_what_was_encoded() {
        let vertices: Vec<[u16; 4]> = (0..1000u16)
            .map(|i| [i, i.wrapping_mul(7), 3000 - i, 1])
            .collect();
        let coded = meshopt::encode_vertex_buffer(&vertices).unwrap();
        let c = Compressed {
            extension: EXTENSIONS[1],
            buffer: 0,
            offset: 0,
            length: coded.len() as u64,
            stride: 8,
            count: 1000,
            mode: Mode::Attributes,
            filter: Filter::None,
        };
        let out = decode(&c, &coded, 1000).unwrap();
        assert_eq!(out, bytemuck::cast_slice::<[u16; 4], u8>(&vertices));
        // More elements than the caller allows: refused before decoding.
        assert!(decode(&c, &coded, 999)
            .unwrap_err()
            .contains("1000 elements, more than"));
        let triangles: Vec<u32> = (0..300u32).map(|i| (i * 7) % 250).collect();
        let coded = meshopt::encode_index_buffer(&triangles, 250).unwrap();
        let c = Compressed {
            mode: Mode::Triangles,
            stride: 4,
            count: 300,
            length: coded.len() as u64,
            ..c
        };
        // The codec keeps each triangle and its winding, not the corner it
        // starts at.
        let out = decode(&c, &coded, 300).unwrap();
        let back: &[u32] = bytemuck::cast_slice(&out);
        let canonical = |t: &[u32]| {
            let k = (0..3).min_by_key(|&k| t[k]).unwrap();
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        };
        for (a, b) in back.chunks(3).zip(triangles.chunks(3)) {
            assert_eq!(canonical(a), canonical(b));
        }
        // Corrupt streams are refused, not read as garbage lengths.
        let mut broken = coded.clone();
        broken[0] = 0x00;
        assert!(decode(&c, &broken, 300)
            .unwrap_err()
            .contains("header byte (0x00)"));
        let half = &coded[..coded.len() / 2];
        assert!(decode(&c, half, 300).unwrap_err().contains("ends early"));
        // An expansion no stream reaches is refused before allocating.
        let huge = Compressed {
            count: 3 << 40,
            ..c
        };
        assert!(decode(&huge, &coded, u64::MAX)
            .unwrap_err()
            .contains("more than 128"));
    }

    #[test]
    fn all_zero_attributes_stay_within_the_expansion_bound() {
        // The codec's best case: zeros compress the most, in either
        // version of the attribute codec.
        for version in [0, 1] {
            for stride in [4usize, 8, 16, 64, 256] {
                let zeros = vec![0u8; stride * 100_000];
                let coded =
                    super::super::gltf_compress::encode_attributes_as(&zeros, stride, 3, version);
                let bound = max_expansion(Mode::Attributes, coded[0]);
                assert!(
                    (zeros.len() as u64) <= bound * coded.len() as u64 / 2,
                    "version {version}, stride {stride}: {} bytes from {}",
                    zeros.len(),
                    coded.len()
                );
            }
        }
    }
}
