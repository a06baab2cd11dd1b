//! The renderer draws vertex properties: texels at known pixels, vertex
//! colours, input normals, the checker, and a texture that cannot be drawn
//! falls back to untextured with a warning. Every check runs on Vulkan
//! (lavapipe) and on GL (llvmpipe), each skipped with a message when its
//! adapter is missing (a failure when `MTS_REQUIRE` names gpu).
//!
//! The scene: one quad filling the clip square, seen head-on through an
//! identity view-projection, lit along its normal (+z), so a fragment's
//! colour is its surface colour with shade exactly 1.
//!
//! ```text
//!  3 (0,1) ---- 2 (1,1)     positions (±1, ±1, 0.5), UVs in brackets;
//!  |          / |           CCW seen from +z: triangles 012 and 023
//!  |       /    |
//!  |    /       |           66 × 66 pixels: pixel x samples
//!  0 (0,0) ---- 1 (1,0)     u = (x + 0.5) / 66, so x = 16 is u = 1/4
//! ```

#[path = "../../mts/tests/common/mod.rs"]
mod common;
// Each test binary uses some of the shared helpers.
#[allow(dead_code)]
mod support;

use glam::{Mat4, Vec2, Vec3, Vec4};
use mts::mesh::io::{load, LoadOptions};
use mts::mesh::{Properties, Texture};
use mts::Error;
use mts_render::headless::HeadlessTarget;
use mts_render::strip_renderer::DEFAULT_COLOUR;
use mts_render::texture::{CHECKER_DARK, CHECKER_LIGHT};
use mts_render::{Appearance, Camera, Gpu, Image, RendererConfig, Shading, StripRenderer};
use support::gpu_on;

/// Side of the target: 4k + 2 pixels put the centres of a 2 × 2 texture's
/// texels (u, v = 1/4, 3/4) on pixel centres (16 and 49), where bilinear
/// filtering returns the texel alone.
const SIDE: u32 = 66;

const QUAD_POSITIONS: [Vec3; 4] = [
    Vec3::new(-1.0, -1.0, 0.5),
    Vec3::new(1.0, -1.0, 0.5),
    Vec3::new(1.0, 1.0, 0.5),
    Vec3::new(-1.0, 1.0, 0.5),
];
const QUAD_TRIANGLES: [[u32; 3]; 2] = [[0, 1, 2], [0, 2, 3]];

/// Runs `check` on every backend that has an adapter, with its name.
fn on_each_backend(check: impl Fn(&Gpu, &str)) {
    for (backends, what) in [
        (wgpu::Backends::VULKAN, "Vulkan"),
        (wgpu::Backends::GL, "GL"),
    ] {
        if let Some(gpu) = gpu_on(backends, what) {
            eprintln!("{what}: {}", gpu.report());
            check(&gpu, what);
        }
    }
}

fn quad_uvs() -> Vec<Vec2> {
    vec![
        Vec2::new(0.0, 0.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(0.0, 1.0),
    ]
}

/// The quad with `properties` drawn head-on, lit along +z.
fn quad_image(
    gpu: &Gpu,
    properties: &Properties,
    appearance: &Appearance,
) -> (StripRenderer, Image) {
    let (d, q) = (&gpu.device, &gpu.queue);
    let config = RendererConfig::headless(gpu.report().strip_mode);
    let mut renderer = StripRenderer::with_properties(
        d,
        q,
        &config,
        &QUAD_POSITIONS,
        &QUAD_TRIANGLES,
        properties,
        appearance,
    )
    .unwrap();
    let image = draw(gpu, &mut renderer);
    (renderer, image)
}

fn draw(gpu: &Gpu, renderer: &mut StripRenderer) -> Image {
    let (d, q) = (&gpu.device, &gpu.queue);
    renderer.upload_list(d, q, &QUAD_TRIANGLES).unwrap();
    let camera = Camera {
        view_proj: Mat4::IDENTITY,
        light_dir: Vec3::Z,
        shading: Shading::Lit,
    };
    renderer.set_camera(q, &camera);
    let target = HeadlessTarget::new(d, SIDE, SIDE).unwrap();
    target
        .render_image(d, q, |pass| renderer.draw(pass))
        .unwrap()
}

fn pixel(image: &Image, x: u32, y: u32) -> [u8; 4] {
    let at = 4 * (y * image.width + x) as usize;
    image.rgba[at..at + 4].try_into().unwrap()
}

/// Asserts that pixel (x, y) is `expected` within one step per channel
/// (sRGB decode and re-encode round on the way).
fn assert_pixel(image: &Image, x: u32, y: u32, expected: [u8; 4], what: &str) {
    let got = pixel(image, x, y);
    assert!(
        got.iter().zip(expected).all(|(g, e)| g.abs_diff(e) <= 1),
        "{what}: pixel ({x}, {y}) is {got:?}, expected {expected:?}"
    );
}

fn to_linear(c: u8) -> f32 {
    let c = f32::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn to_srgb(l: f32) -> u8 {
    let c = if l <= 0.003_130_8 {
        l * 12.92
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    (c * 255.0).round() as u8
}

/// Opaque sRGB bytes of a linear colour.
fn srgb(linear: Vec3) -> [u8; 4] {
    [to_srgb(linear.x), to_srgb(linear.y), to_srgb(linear.z), 255]
}

/// PNG bytes of a `width × height` RGBA8 image, rows top to bottom.
fn png(width: u32, height: u32, texels: &[[u8; 4]]) -> Vec<u8> {
    let image = image::RgbaImage::from_raw(width, height, texels.concat()).unwrap();
    let mut bytes = Vec::new();
    image
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .unwrap();
    bytes
}

fn embedded_png(bytes: Vec<u8>) -> Option<Texture> {
    Some(Texture::Embedded {
        mime: "image/png".into(),
        bytes,
    })
}

#[test]
fn a_2x2_texture_shows_its_texels_where_the_uvs_put_them() {
    // Top row red, green; bottom row blue, orange (image rows run down,
    // v up: the bottom row is v = 0..1/2).
    let texels = [
        [255, 0, 0, 255],
        [0, 255, 0, 255],
        [0, 0, 255, 255],
        [200, 150, 50, 255],
    ];
    let mut properties = Properties {
        uvs: Some(quad_uvs()),
        texture: embedded_png(png(2, 2, &texels)),
        ..Properties::default()
    };
    on_each_backend(|gpu, what| {
        let (renderer, image) = quad_image(gpu, &properties, &Appearance::default());
        assert_eq!(renderer.warnings(), &[] as &[String], "{what}");
        assert_eq!(renderer.texture_size(), Some((2, 2)), "{what}");
        // Pixel rows run down like the image's: texel (i, j) at pixel
        // (16 + 33 i, 16 + 33 j).
        for (i, texel) in texels.iter().enumerate() {
            let (x, y) = (16 + 33 * (i as u32 % 2), 16 + 33 * (i as u32 / 2));
            assert_pixel(&image, x, y, *texel, what);
        }
    });
    // Texture × vertex colour: a grey of linear 0.5 halves each texel's
    // linear value.
    properties.colors = Some(vec![Vec4::new(0.5, 0.5, 0.5, 1.0); 4]);
    on_each_backend(|gpu, what| {
        let (_, image) = quad_image(gpu, &properties, &Appearance::default());
        for (i, texel) in texels.iter().enumerate() {
            let (x, y) = (16 + 33 * (i as u32 % 2), 16 + 33 * (i as u32 / 2));
            let linear = Vec3::new(
                to_linear(texel[0]),
                to_linear(texel[1]),
                to_linear(texel[2]),
            );
            assert_pixel(&image, x, y, srgb(linear * 0.5), what);
        }
    });
}

#[test]
fn vertex_colours_show_interpolated_across_the_quad() {
    // Red on the left edge (vertices 0, 3), blue on the right (1, 2): the
    // colour at pixel x is red (1 - t) + blue t with t = (x + 0.5) / 66,
    // in linear light, on both triangles. No texture: surface colour white.
    let red = Vec4::new(1.0, 0.0, 0.0, 1.0);
    let blue = Vec4::new(0.0, 0.0, 1.0, 1.0);
    let properties = Properties {
        colors: Some(vec![red, blue, blue, red]),
        ..Properties::default()
    };
    on_each_backend(|gpu, what| {
        let (renderer, image) = quad_image(gpu, &properties, &Appearance::default());
        assert_eq!(renderer.warnings(), &[] as &[String], "{what}");
        assert_eq!(renderer.texture_size(), None, "{what}");
        for x in [0, 16, 33, 50, 65] {
            let t = (x as f32 + 0.5) / SIDE as f32;
            for y in [5, 33, 60] {
                assert_pixel(&image, x, y, srgb(Vec3::new(1.0 - t, 0.0, t)), what);
            }
        }
    });
}

#[test]
fn input_normals_replace_the_computed_ones() {
    // Computed normals face the light (+z): shade 1. Input normals tilted
    // to (0.6, 0, 0.8) get 0.18 + 0.82 × 0.8. A zero input normal means
    // "none": that vertex gets the computed one.
    let tilted = Vec3::new(0.6, 0.0, 0.8);
    let properties = Properties {
        normals: Some(vec![tilted; 4]),
        ..Properties::default()
    };
    let zero_is_none = Properties {
        normals: Some(vec![Vec3::ZERO; 4]),
        ..Properties::default()
    };
    on_each_backend(|gpu, what| {
        let config = RendererConfig::headless(gpu.report().strip_mode);
        let mut computed = StripRenderer::new(
            &gpu.device,
            &gpu.queue,
            &config,
            &QUAD_POSITIONS,
            &QUAD_TRIANGLES,
        )
        .unwrap();
        let computed = draw(gpu, &mut computed);
        let (_, given) = quad_image(gpu, &properties, &Appearance::default());
        let (_, zero) = quad_image(gpu, &zero_is_none, &Appearance::default());
        let shade = 0.18 + 0.82 * 0.8;
        for (x, y) in [(5, 5), (33, 33), (60, 20)] {
            assert_pixel(&computed, x, y, srgb(DEFAULT_COLOUR), what);
            assert_pixel(&given, x, y, srgb(DEFAULT_COLOUR * shade), what);
        }
        assert_eq!(zero, computed, "{what}: zero normals are computed ones");
        assert_eq!(given.differing_pixels(&computed), (SIDE * SIDE) as usize);
    });
}

#[test]
fn a_texture_that_cannot_be_drawn_is_a_warning_and_draws_untextured() {
    let valid = png(2, 2, &[[255, 0, 0, 255]; 4]);
    let untextured = |texture: Option<Texture>| Properties {
        uvs: Some(quad_uvs()),
        texture,
        ..Properties::default()
    };
    let corrupt = untextured(embedded_png(valid[..valid.len() / 2].to_vec()));
    let missing = untextured(Some(Texture::File("/nonexistent/mts/albedo.png".into())));
    let no_uvs = Properties {
        uvs: None,
        ..untextured(embedded_png(valid))
    };
    on_each_backend(|gpu, what| {
        let config = RendererConfig::headless(gpu.report().strip_mode);
        let (d, q) = (&gpu.device, &gpu.queue);
        let mut plain =
            StripRenderer::new(d, q, &config, &QUAD_POSITIONS, &QUAD_TRIANGLES).unwrap();
        let plain = draw(gpu, &mut plain);
        // One texel wider than the device takes: refused from the header.
        let side = d.limits().max_texture_dimension_2d + 1;
        let huge = untextured(embedded_png(png(
            side,
            1,
            &vec![[9, 9, 9, 255]; side as usize],
        )));
        for (properties, says) in [
            (&corrupt, "texture embedded image/png (".to_string()),
            (
                &missing,
                "texture /nonexistent/mts/albedo.png: cannot read it".to_string(),
            ),
            (&huge, format!("{side}x1 texels, outside the device's 1..=")),
            (&no_uvs, "the mesh has no texture coordinates".to_string()),
        ] {
            let (renderer, image) = quad_image(gpu, properties, &Appearance::default());
            let warnings = renderer.warnings();
            assert_eq!(warnings.len(), 1, "{what}: {warnings:?}");
            assert!(
                warnings[0].contains(&says) && warnings[0].ends_with("drawn untextured"),
                "{what}: {warnings:?} should say {says:?}"
            );
            assert_eq!(renderer.texture_size(), None, "{what}");
            assert_eq!(image, plain, "{what}: {says}");
        }
        // Properties that break their invariants are an error, not a
        // warning.
        let short = Properties {
            uvs: Some(vec![Vec2::ZERO; 3]),
            ..Properties::default()
        };
        let result = StripRenderer::with_properties(
            d,
            q,
            &config,
            &QUAD_POSITIONS,
            &QUAD_TRIANGLES,
            &short,
            &Appearance::default(),
        );
        match result {
            Err(Error::InvalidArgument(m)) => {
                assert!(m.contains("3 texture coordinates for 4 vertices"), "{m}")
            }
            other => panic!(
                "{what}: expected InvalidArgument, got {:?}",
                other.map(|_| ())
            ),
        }
    });
}

#[test]
fn the_checker_replaces_the_texture_and_shows_both_colours() {
    // 8 squares of 8.25 pixels per side; the square at the UV origin (the
    // bottom-left, v up) is light. The asset's texture is not drawn.
    let properties = Properties {
        uvs: Some(quad_uvs()),
        texture: embedded_png(png(1, 1, &[[255, 0, 0, 255]])),
        ..Properties::default()
    };
    let checker = Appearance { checker: true };
    on_each_backend(|gpu, what| {
        let (renderer, image) = quad_image(gpu, &properties, &checker);
        assert_eq!(renderer.warnings(), &[] as &[String], "{what}");
        assert_eq!(renderer.texture_size(), Some((256, 256)), "{what}");
        // Pixel (x, y) is square (floor(8 u), floor(8 v)) with
        // u = (x + 0.5) / 66, v = 1 - (y + 0.5) / 66.
        assert_pixel(&image, 4, 61, CHECKER_LIGHT, what);
        assert_pixel(&image, 12, 61, CHECKER_DARK, what);
        assert_pixel(&image, 12, 53, CHECKER_LIGHT, what);
        assert_pixel(&image, 4, 53, CHECKER_DARK, what);
        // Away from the edges (blurred by filtering), half of each.
        let count = |c: [u8; 4]| {
            image
                .rgba
                .chunks_exact(4)
                .filter(|p| p.iter().zip(c).all(|(a, b)| a.abs_diff(b) <= 1))
                .count()
        };
        let (light, dark) = (count(CHECKER_LIGHT), count(CHECKER_DARK));
        assert!(
            light > 1500 && dark > 1500 && light.abs_diff(dark) < 300,
            "{what}: {light} light and {dark} dark pixels of {}",
            SIDE * SIDE
        );
    });
}

#[test]
fn spot_with_the_checker_covers_what_it_covers_untextured() {
    // A real model with UVs: the checker changes colours, never coverage.
    let Some(dir) = common::models_dir() else {
        return;
    };
    let options = LoadOptions {
        properties: true,
        ..LoadOptions::default()
    };
    let (mesh, _) = load(&dir.join("spot.obj"), options).unwrap();
    assert!(mesh.properties.uvs.is_some(), "spot.obj has UVs");
    on_each_backend(|gpu, what| {
        let (d, q) = (&gpu.device, &gpu.queue);
        let config = RendererConfig::headless(gpu.report().strip_mode);
        let target = HeadlessTarget::new(d, 200, 150).unwrap();
        let mut camera = Camera::framing_points(&mesh.positions, target.aspect());
        let mut images = Vec::new();
        for checker in [false, true] {
            let mut renderer = StripRenderer::with_properties(
                d,
                q,
                &config,
                &mesh.positions,
                &mesh.triangles,
                &mesh.properties,
                &Appearance { checker },
            )
            .unwrap();
            assert_eq!(renderer.warnings(), &[] as &[String], "{what}");
            renderer.upload_list(d, q, &mesh.triangles).unwrap();
            renderer.set_colour(Vec3::ONE);
            for shading in [Shading::Unlit, Shading::Lit] {
                camera.shading = shading;
                renderer.set_camera(q, &camera);
                images.push(
                    target
                        .render_image(d, q, |pass| renderer.draw(pass))
                        .unwrap(),
                );
            }
        }
        let covered = images[0].foreground_pixels();
        assert!(covered > 3_000, "{what}: {covered}");
        assert_eq!(images[0], images[2], "{what}: unlit, same coverage");
        let changed = images[1].differing_pixels(&images[3]);
        assert!(
            changed * 2 > covered,
            "{what}: the checker changes {changed} of {covered} pixels"
        );
    });
}

/// The instanced scene draws the models' properties: with the checker,
/// instances of a torus with UVs change colour over most of the pixels
/// they cover, and cover exactly the same pixels, on every backend.
#[test]
fn instanced_scene_draws_the_checker() {
    use mts::mesh::generate::Generated;
    let mesh = "torus:2k"
        .parse::<Generated>()
        .unwrap()
        .build_with_properties();
    let (model, _, _) = mts::model::build_from_mesh(&mesh, &Default::default(), &mut |_, _| {});
    let size = mesh.diagonal();
    on_each_backend(|gpu, what| {
        let (d, q) = (&gpu.device, &gpu.queue);
        let config = RendererConfig::headless(gpu.report().strip_mode);
        let target = HeadlessTarget::new(d, 200, 150).unwrap();
        let mut images = Vec::new();
        for checker in [false, true] {
            let mut scene = mts_render::InstancedScene::new(&config);
            let id = scene
                .add_model_with(d, q, &model, &Appearance { checker })
                .unwrap();
            assert_eq!(scene.warnings(id), &[] as &[String], "{what}");
            for i in 0..4 {
                let at = Vec3::new((i % 2) as f32, 0.0, (i / 2) as f32) * size;
                scene.add_instance(id, Mat4::from_translation(at)).unwrap();
            }
            let camera = Camera::looking(
                Vec3::new(0.5, 1.2, 1.8) * size,
                Vec3::new(0.5, 0.0, 0.5) * size,
                target.aspect(),
                0.01 * size,
                100.0 * size,
            );
            let stats = scene.update(d, q, &camera, 150.0, 1.0).unwrap();
            assert_eq!(stats.visible, 4, "{what}");
            images.push(target.render_image(d, q, |pass| scene.draw(pass)).unwrap());
        }
        let covered = images[0].foreground_pixels();
        assert!(covered > 5_000, "{what}: {covered}");
        let d = images[0].difference(&images[1], 8);
        assert_eq!(d.coverage_changed, 0, "{what}: coverage");
        assert!(
            d.share > 0.5,
            "{what}: the checker changes {} of {covered} pixels",
            d.share
        );
    });
}
