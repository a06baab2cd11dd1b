//! `mts build --hierarchy`, and `info` and `verify` on the version-4 file
//! it writes: JSON keys with their values, a sound file verified (no
//! mismatch, no crack), a corrupt one refused with its name, and the
//! model's commands naming what the file holds.

mod common;

use common::{json, mts};

#[test]
fn build_info_verify_a_terrain_hierarchy() {
    let dir = std::env::temp_dir().join(format!("mts-hierarchy-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("terrain.mts");
    let file = file.to_str().unwrap();
    let (ok, out, err) = mts(&[
        "build",
        "--generated",
        "terrain:20k",
        "--hierarchy",
        "-o",
        file,
        "--json",
    ]);
    assert!(ok, "{err}");
    let b = json(&out);
    let triangles = b["triangles"].as_u64().unwrap();
    let vertices = b["vertices"].as_u64().unwrap();
    // terrain:20k is a 100 × 100 grid of quads.
    assert_eq!((triangles, vertices), (20_000, 10_201));
    assert_eq!(
        b["raw_bytes"].as_u64().unwrap(),
        12 * vertices + 12 * triangles
    );
    let bytes = b["bytes"].as_u64().unwrap();
    assert_eq!(bytes, std::fs::metadata(file).unwrap().len());
    let (groups, levels, clusters) = (
        b["groups"].as_u64().unwrap(),
        b["levels"].as_u64().unwrap(),
        b["clusters"].as_u64().unwrap(),
    );
    // About 128 triangles a cluster, 4 clusters a group, halved per level.
    assert!((3..=12).contains(&levels), "{levels} levels");
    assert!((40..=200).contains(&groups), "{groups} groups");
    assert!(
        clusters > triangles / 128 && clusters < 4 * triangles / 64,
        "{clusters}"
    );
    assert!(b["memory_bytes"].as_u64().unwrap() > bytes / 2);
    assert!(b["build_ms"].as_f64().unwrap() > 0.0);
    // Coded (version 7) by default; --uncompressed writes version 4, at
    // more than twice the bytes.
    assert_eq!(b["file_version"], 7);
    let plain = dir.join("plain.mts");
    let plain = plain.to_str().unwrap();
    let (ok, out, err) = mts(&[
        "build",
        "--generated",
        "terrain:20k",
        "--hierarchy",
        "--uncompressed",
        "-o",
        plain,
        "--json",
    ]);
    assert!(ok, "{err}");
    let p = json(&out);
    assert_eq!(p["file_version"], 4);
    assert!(
        p["bytes"].as_u64().unwrap() > 2 * bytes,
        "{p} against {bytes}"
    );
    let (ok, out, err) = mts(&["info", plain, "--json"]);
    assert!(ok, "{err}");
    assert_eq!(json(&out)["groups"], b["groups"]);

    let (ok, out, err) = mts(&["info", file, "--json"]);
    assert!(ok, "{err}");
    let i = json(&out);
    assert_eq!(i["kind"], "hierarchy");
    assert_eq!(i["file_version"], 7);
    for key in [
        "triangles",
        "vertices",
        "groups",
        "levels",
        "clusters",
        "bytes",
        "raw_bytes",
        "memory_bytes",
    ] {
        assert_eq!(i[key], b[key], "{key}");
    }
    let per_level = i["per_level"].as_array().unwrap();
    assert_eq!(per_level.len() as u64, levels);
    assert_eq!(per_level[0]["triangles"].as_u64(), Some(triangles));
    let in_levels: u64 = per_level
        .iter()
        .map(|l| l["groups"].as_u64().unwrap())
        .sum();
    assert_eq!(in_levels, groups);
    let (ok, out, err) = mts(&["info", file]);
    assert!(ok, "{err}");
    assert!(
        out.contains("hierarchy") && out.contains(&format!("{groups} groups")),
        "{out}"
    );

    let (ok, out, err) = mts(&["verify", file, "--json"]);
    assert!(ok, "{err}");
    let v = json(&out);
    assert_eq!(v["groups_checked"].as_u64(), Some(groups));
    assert_eq!(v["mismatches"].as_u64(), Some(0));
    assert_eq!(v["cracks"].as_u64(), Some(0));
    assert_eq!(v["cuts"].as_u64(), Some(18));
    // Every LoD of every group: more than one per group.
    assert!(v["lods_checked"].as_u64().unwrap() > 10 * groups);
    // The sweep draws coarser cuts than the input, and mixes them.
    let range = v["cut_triangles"].as_array().unwrap();
    let (fewest, most) = (range[0].as_u64().unwrap(), range[1].as_u64().unwrap());
    assert!(fewest < most && most <= triangles, "{fewest}..{most}");
    let (ok, out, err) = mts(&["verify", file, "--lods", "2", "--json"]);
    assert!(ok, "{err}");
    // Two LoDs a group, one where a group has no contraction.
    let two = json(&out)["lods_checked"].as_u64().unwrap();
    assert!(two > groups && two <= 2 * groups, "{two}");

    // The model's commands say what the file holds.
    let (ok, _, err) = mts(&["extract", file, "--lod", "0"]);
    assert!(!ok);
    assert!(
        err.contains("terrain.mts") && err.contains("hierarchy"),
        "{err}"
    );

    // A flipped byte (the checksum), and a resealed lie past it: refused,
    // the file named.
    let mut data = std::fs::read(file).unwrap();
    let mid = data.len() / 2;
    data[mid] ^= 0x40;
    let bad = dir.join("bad.mts");
    std::fs::write(&bad, &data).unwrap();
    for command in ["info", "verify"] {
        let (ok, _, err) = mts(&[command, bad.to_str().unwrap()]);
        assert!(!ok, "{command}");
        assert!(
            err.contains("bad.mts") && err.contains("checksum"),
            "{command}: {err}"
        );
    }
    let truncated = dir.join("short.mts");
    let mut short = std::fs::read(file).unwrap();
    short.truncate(short.len() / 3);
    mts::model::format::seal(&mut short);
    std::fs::write(&truncated, &short).unwrap();
    for command in ["info", "verify"] {
        let (ok, _, err) = mts(&[command, truncated.to_str().unwrap()]);
        assert!(!ok, "{command}");
        assert!(
            err.contains("short.mts") && err.contains("byte"),
            "{command}: {err}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_hierarchy_refuses_what_it_cannot_hold() {
    let dir = std::env::temp_dir().join(format!("mts-hierarchy-cli-r-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("x.mts");
    let out = out.to_str().unwrap();
    for extra in ["--optimal", "--recipe-only"] {
        let (ok, _, err) = mts(&[
            "build",
            "--generated",
            "torus:2k",
            "--hierarchy",
            extra,
            "-o",
            out,
        ]);
        assert!(!ok && err.contains("cannot be used with"), "{extra}: {err}");
    }
    assert!(!std::path::Path::new(out).exists());
    // With properties and seams: built, described and verified.
    let (ok, _, err) = mts(&[
        "build",
        "--generated",
        "torus:2k",
        "--properties",
        "--hierarchy",
        "-o",
        out,
    ]);
    assert!(ok, "{err}");
    let (ok, text, err) = mts(&["info", out, "--json"]);
    assert!(ok, "{err}");
    assert!(
        json(&text)["properties"]["streams"]
            .as_array()
            .unwrap()
            .len()
            == 3
    );
    let (ok, text, err) = mts(&["verify", out, "--json"]);
    assert!(ok, "{err}");
    assert_eq!(json(&text)["cracks"].as_u64(), Some(0));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `mts bench view-dependent --json`: one row per method with the keys
/// other tools read, the hierarchy without cracks, popping at most twice
/// the threshold and drawing less than full detail, lists at 3 indices a
/// triangle, and the image error against the supersampled reference (the
/// full-detail method's ratio is 1). Without an adapter the command says
/// so (an error unless `MTS_REQUIRE` names gpu, as in CI).
#[test]
fn bench_view_dependent_compares_the_four_methods() {
    let (ok, out, err) = mts(&[
        "bench",
        "view-dependent",
        "--generated",
        "terrain:20k",
        "--frames",
        "24",
        "--pixel-error",
        "1,4",
        "--size",
        "160x90",
        "--json",
    ]);
    if common::skipped_without_adapter(ok, &err) {
        return;
    }
    assert!(ok, "{err}");
    let r = json(&out);
    let rows = r["methods"].as_array().unwrap();
    assert_eq!(rows.len(), 8);
    let names: Vec<&str> = rows.iter().map(|m| m["method"].as_str().unwrap()).collect();
    assert_eq!(
        names[..4],
        ["mts_hierarchy", "clusterlod", "cluster_tree", "mts"]
    );
    for m in rows {
        let name = m["method"].as_str().unwrap();
        let px = m["pixel_threshold"].as_f64().unwrap();
        let full = m["triangles_full_detail"].as_f64().unwrap();
        assert_eq!(full, 20_000.0);
        let drawn = m["triangles_drawn_median"].as_f64().unwrap();
        assert!(drawn > 0.0 && drawn <= full, "{name}: {drawn}");
        let ipt = m["indices_per_triangle"].as_f64().unwrap();
        let update = (
            m["update_ms_median"].as_f64().unwrap(),
            m["update_ms_p99"].as_f64().unwrap(),
        );
        assert!(
            update.0 >= 0.0 && update.0 <= update.1,
            "{name}: {update:?}"
        );
        assert!(m["memory_bytes"].as_u64().unwrap() > 0);
        assert_eq!(m["raw_bytes"].as_u64().unwrap(), 12 * 10_201 + 12 * 20_000);
        let ratio = m["image_error_ratio"].as_f64().unwrap();
        assert!(ratio > 0.5 && ratio < 20.0, "{name}: {ratio}");
        let popping = m["popping_px_max"].as_f64().unwrap();
        match name {
            "mts_hierarchy" => {
                assert_eq!(m["cracks"].as_u64().unwrap(), 0);
                assert!(drawn < full, "{px} px: {drawn}");
                assert!(ipt > 1.0 && ipt < 2.0, "{ipt}");
                // Two LoDs each within the threshold of the input may lie
                // twice the threshold apart; this 24-frame flight is fast.
                assert!(popping <= 2.0 * px, "{px} px: popping {popping}");
                assert!(m["triangles_visible_median"].as_f64().unwrap() <= drawn);
            }
            "clusterlod" => {
                assert_eq!(m["cracks"].as_u64().unwrap(), 0);
                assert_eq!(ipt, 3.0);
            }
            "cluster_tree" => assert_eq!(ipt, 3.0),
            _ => assert!(ipt < 1.5, "{ipt}"),
        }
    }
    // Where the per-object model draws everything, its frame is the
    // full-detail frame.
    let mts_rows: Vec<_> = rows.iter().filter(|m| m["method"] == "mts").collect();
    for m in mts_rows {
        if m["triangles_drawn_max"].as_f64().unwrap() == 20_000.0
            && m["triangles_drawn_median"].as_f64().unwrap() == 20_000.0
        {
            assert!((m["image_error_ratio"].as_f64().unwrap() - 1.0).abs() < 0.05);
        }
    }
}

/// `mts bench render --hierarchy --json`: the hierarchy's strips and the
/// same cut as a list over the flight, the strips sending fewer indices
/// for the same triangles, the list 3 a triangle, a camera step timed for
/// the strips only. Without an adapter the command says so (an error
/// unless `MTS_REQUIRE` names gpu, as in CI).
#[test]
fn bench_render_draws_a_hierarchy_along_the_flight() {
    let (ok, out, err) = mts(&[
        "bench",
        "render",
        "--generated",
        "terrain:20k",
        "--hierarchy",
        "--frames",
        "5",
        "--size",
        "160x90",
        "--json",
    ]);
    if common::skipped_without_adapter(ok, &err) {
        return;
    }
    assert!(ok, "{err}");
    let r = json(&out);
    assert_eq!(r["hierarchy"], true);
    assert_eq!(r["cameras"], 5);
    assert_eq!(r["triangles_full_detail"], 20_000);
    let rows = r["rows"].as_array().unwrap();
    let methods: Vec<_> = rows.iter().map(|m| m["method"].as_str().unwrap()).collect();
    assert_eq!(methods, ["mts_hierarchy", "meshopt"]);
    let (strips, list) = (&rows[0], &rows[1]);
    let triangles = strips["triangles_median"].as_u64().unwrap();
    assert!(triangles > 0 && triangles < 20_000, "{r}");
    assert_eq!(list["triangles_median"], triangles);
    assert_eq!(list["indices_sent_median"].as_u64(), Some(3 * triangles));
    let sent = strips["indices_sent_median"].as_u64().unwrap();
    assert!(sent > triangles && sent < 3 * triangles, "{r}");
    assert!(strips["indices_drawn_median"].as_u64().unwrap() >= sent);
    assert!(strips["step_us_median"].as_f64().unwrap() > 0.0);
    assert!(list["step_us_median"].is_null());
    for m in rows {
        assert!(m["ms_per_frame"].as_f64().unwrap() > 0.0, "{m}");
        assert!(m["gpu_bytes"].as_u64().unwrap() > 0, "{m}");
    }
}
