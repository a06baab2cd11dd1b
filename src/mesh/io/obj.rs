//! Wavefront OBJ through `tobj`: polygons fan-triangulated, all objects and
//! groups merged, materials ignored (a missing `.mtl` is fine).
//!
//! `tobj` reports errors without a position, so when it fails (or when a
//! coordinate is not finite, which it accepts) this module scans the text
//! once more to find the offending line. That scan runs only on the error
//! path.

use crate::error::{Error, Place, Result};
use crate::mesh::RawMesh;
use glam::Vec3;
use std::path::Path;

/// Parses OBJ text into a raw mesh (geometry only).
///
/// # Errors
/// [`Error::Parse`] naming the line for malformed statements, out-of-range
/// face indices and non-finite coordinates.
///
/// Cost: O(file size).
pub fn parse_obj(bytes: &[u8], path: &Path) -> Result<RawMesh> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = bytes;
    let loaded = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    });
    let models = match loaded {
        Ok((models, _materials_ignored)) => models,
        Err(e) => {
            let (place, what) = locate_error(bytes, e);
            return Err(Error::Parse {
                file: path.to_owned(),
                place,
                message: what,
            });
        }
    };

    let mut raw = RawMesh::default();
    for model in &models {
        let m = &model.mesh;
        let base = raw.positions.len() as u64;
        if base + (m.positions.len() / 3) as u64 > u64::from(u32::MAX) {
            return Err(Error::InvalidMesh {
                source_name: path.display().to_string(),
                message: "more than 2^32 - 1 vertices".into(),
            });
        }
        raw.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        raw.triangles.extend(
            m.indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]].map(|i| i + base as u32)),
        );
    }
    if raw.positions.iter().any(|p| !p.is_finite()) {
        let place = find_line(bytes, |words| {
            words.first() == Some(&"v")
                && words[1..]
                    .iter()
                    .take(3)
                    .any(|w| w.parse::<f32>().is_ok_and(|x| !x.is_finite()))
        });
        return Err(Error::Parse {
            file: path.to_owned(),
            place,
            message: "vertex coordinate is NaN or infinite".into(),
        });
    }
    Ok(raw)
}

/// Finds the first line whose whitespace-separated words satisfy `bad`.
fn find_line(bytes: &[u8], mut bad: impl FnMut(&[&str]) -> bool) -> Place {
    let text = String::from_utf8_lossy(bytes);
    let mut words = Vec::new();
    for (i, line) in text.lines().enumerate() {
        words.clear();
        words.extend(line.split_whitespace());
        if !words.is_empty() && bad(&words) {
            let mut place = Place::line(i as u64 + 1);
            place.element = Some(format!("`{}` statement", words[0]));
            return place;
        }
    }
    Place::default()
}

/// Maps a `tobj` error to the line that caused it and a message.
fn locate_error(bytes: &[u8], e: tobj::LoadError) -> (Place, String) {
    use tobj::LoadError as E;
    let what = e.to_string();
    let place = match e {
        E::PositionParseError => find_line(bytes, |w| w[0] == "v" && !floats_ok(&w[1..], 3)),
        E::NormalParseError => find_line(bytes, |w| w[0] == "vn" && !floats_ok(&w[1..], 3)),
        E::TexcoordParseError => find_line(bytes, |w| w[0] == "vt" && !floats_ok(&w[1..], 1)),
        E::FaceVertexOutOfBounds | E::FaceParseError | E::InvalidPolygon => {
            let mut v_count: i64 = 0;
            find_line(bytes, |w| {
                if w[0] == "v" {
                    v_count += 1;
                    return false;
                }
                w[0] == "f" && !face_ok(&w[1..], v_count)
            })
        }
        _ => Place::default(),
    };
    (place, what)
}

fn floats_ok(words: &[&str], min: usize) -> bool {
    words.len() >= min && words.iter().take(3).all(|w| w.parse::<f32>().is_ok())
}

/// A face statement is well formed when it has at least three corners and
/// every position index is 1..=count (or a valid negative relative index).
fn face_ok(corners: &[&str], vertices_so_far: i64) -> bool {
    corners.len() >= 3
        && corners.iter().all(|c| {
            c.split('/')
                .next()
                .and_then(|s| s.parse::<i64>().ok())
                .is_some_and(|i| {
                    (i > 0 && i <= vertices_so_far) || (i < 0 && -i <= vertices_so_far)
                })
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<RawMesh> {
        parse_obj(text.as_bytes(), Path::new("t.obj"))
    }

    #[test]
    fn quad_is_fan_triangulated_and_objects_merged() {
        let raw = parse(
            "mtllib missing.mtl\no a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl x\nf 1 2 3 4\n\
             o b\nv 0 0 1\nv 1 0 1\nv 1 1 1\nf 5 6 7\n",
        )
        .unwrap();
        assert_eq!(raw.positions.len(), 7);
        assert_eq!(raw.triangles, vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]]);
    }

    #[test]
    fn out_of_range_index_names_its_line() {
        let err = parse("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 2 9\n").unwrap_err();
        let s = err.to_string();
        assert!(s.contains("t.obj") && s.contains("line 5"), "{s}");
    }

    #[test]
    fn nan_coordinate_names_its_line() {
        let err = parse("v 0 0 0\nv nan 0 0\nv 1 1 0\nf 1 2 3\n").unwrap_err();
        let s = err.to_string();
        assert!(s.contains("line 2") && s.contains("NaN"), "{s}");
    }

    #[test]
    fn malformed_position_names_its_line() {
        let err = parse("v 0 0 0\nv 1 0 0\nv 1 x 0\nf 1 2 3\n").unwrap_err();
        assert!(err.to_string().contains("line 3"), "{err}");
    }
}
