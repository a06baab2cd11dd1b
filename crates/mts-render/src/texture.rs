//! Base-colour textures of [`crate::StripRenderer::with_properties`]: the
//! asset's image decoded (PNG or JPEG, through the `image` crate) or a
//! procedural checker, a mip chain built on the CPU, and the upload as
//! RGBA8 sRGB sampled trilinearly with repeat addressing.
//!
//! Mip levels are a box filter in linear light: each texel of a level
//! averages the texels of the level above that its footprint touches (2 × 2
//! for even sizes, 2 or 3 per axis for odd ones, so no texel is dropped),
//! after decoding sRGB, so that a fine pattern fades to its mean brightness
//! rather than darker, as averaging the sRGB bytes would.
//!
//! A texture that cannot be drawn (missing file, corrupt or unsupported
//! image, a side above the device's `max_texture_dimension_2d`, no UVs to
//! sample it with) is not an error: the renderer draws untextured and keeps
//! a warning that names the image ([`crate::StripRenderer::warnings`]).

use crate::headless::Image;
use mts::mesh::{Properties, Texture};
use std::io::Cursor;

/// How [`crate::StripRenderer::with_properties`] colours a surface beyond
/// what the mesh's properties say.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Appearance {
    /// Draw a procedural checker ([`CHECKER_SQUARES`] squares per unit of
    /// `u` and of `v`, [`CHECKER_LIGHT`] and [`CHECKER_DARK`], mipmapped)
    /// instead of the asset's texture: stretched or sheared squares show
    /// the UV distortion of any mesh with UVs, textured or not.
    pub checker: bool,
}

/// Squares of the checker along each of `u` and `v` over 0..1 (it repeats
/// beyond).
pub const CHECKER_SQUARES: u32 = 8;

/// Side of the checker image in texels: 32 texels per square keep the
/// squares' edges sharp (bilinear blur of one texel) until a square covers
/// about 32 pixels, and cost 256 KiB plus mips.
pub const CHECKER_SIZE: u32 = 256;

/// The square of the checker at the UV origin (`u`, `v` in 0..1/8), and
/// every other one: sRGB RGBA8.
pub const CHECKER_LIGHT: [u8; 4] = [224, 224, 224, 255];

/// The other squares of the checker: sRGB RGBA8.
pub const CHECKER_DARK: [u8; 4] = [64, 64, 64, 255];

/// The base-colour image that `properties` and `appearance` ask for: the
/// checker, the asset's decoded texture, or `None` (untextured) when
/// neither is asked for or it cannot be drawn, with the reason pushed onto
/// `warnings`. A mesh without UVs draws no texture (every fragment would
/// sample one texel).
///
/// Cost: as [`decode`], or the checker's.
pub(crate) fn base_colour(
    properties: &Properties,
    appearance: &Appearance,
    max_dimension: u32,
    warnings: &mut Vec<String>,
) -> Option<Image> {
    let no_uvs = properties.uvs.is_none();
    if appearance.checker {
        if no_uvs {
            warnings.push("checker: the mesh has no texture coordinates; drawn untextured".into());
            return None;
        }
        return Some(checker());
    }
    let texture = properties.texture.as_ref()?;
    if no_uvs {
        warnings.push(format!(
            "texture {}: the mesh has no texture coordinates; drawn untextured",
            describe(texture)
        ));
        return None;
    }
    decode(texture, max_dimension)
        .map_err(|why| warnings.push(why))
        .ok()
}

/// The 1 × 1 white texture an untextured renderer binds (the shader
/// leaves it out of the colour).
pub(crate) fn white() -> Image {
    Image {
        width: 1,
        height: 1,
        rgba: vec![255; 4],
    }
}

/// Decodes `texture` into RGBA8 (sRGB assumed, rows top to bottom), or
/// says why it cannot be drawn, naming the image. The format is read from
/// the bytes (PNG or JPEG; a MIME type is not trusted). A side above
/// `max_dimension` is refused from the header, before the pixels are
/// decoded; the `image` crate's default allocation limit (512 MiB) holds.
///
/// Cost: one read of the file (at most `mts::mesh::io::MAX_FILE_BYTES`),
/// O(pixels) decode.
pub(crate) fn decode(texture: &Texture, max_dimension: u32) -> Result<Image, String> {
    let name = describe(texture);
    let result = match texture {
        // The core's reader: capped in size, and refuses what is not a
        // regular file (an MTL may name /dev/zero).
        Texture::File(path) => mts::mesh::io::read_file(path)
            .map_err(|e| match e {
                // The warning names the file already.
                mts::Error::Io { source, .. } => format!("cannot read it ({source})"),
                e => format!("cannot read it ({e})"),
            })
            .and_then(|bytes| decode_from(&bytes, max_dimension)),
        Texture::Embedded { bytes, .. } => decode_from(bytes, max_dimension),
    };
    result.map_err(|why| format!("texture {name}: {why}; drawn untextured"))
}

/// How a warning names `texture`: the file's path, or the embedded image's
/// type and size.
pub(crate) fn describe(texture: &Texture) -> String {
    match texture {
        Texture::File(path) => path.display().to_string(),
        Texture::Embedded { mime, bytes } => {
            let mime = if mime.is_empty() { "image" } else { mime };
            format!("embedded {mime} ({} bytes)", bytes.len())
        }
    }
}

fn decode_from(bytes: &[u8], max_dimension: u32) -> Result<Image, String> {
    // The dimension query consumes its reader: one reader for the header,
    // another for the pixels.
    let reader = || {
        image::ImageReader::new(Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| format!("cannot read it ({e})"))
    };
    match reader()?.format() {
        Some(image::ImageFormat::Png | image::ImageFormat::Jpeg) => {}
        Some(other) => return Err(format!("{other:?} images are not supported (PNG, JPEG)")),
        None => return Err("not a PNG or JPEG image".into()),
    }
    let (width, height) = reader()?
        .into_dimensions()
        .map_err(|e| format!("corrupt image header ({e})"))?;
    if width == 0 || height == 0 || width > max_dimension || height > max_dimension {
        return Err(format!(
            "{width}x{height} texels, outside the device's 1..={max_dimension} per side"
        ));
    }
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(max_dimension);
    limits.max_image_height = Some(max_dimension);
    let mut pixels = reader()?;
    pixels.limits(limits);
    let rgba = pixels
        .decode()
        .map_err(|e| format!("corrupt image ({e})"))?
        .into_rgba8();
    Ok(Image {
        width: rgba.width(),
        height: rgba.height(),
        rgba: rgba.into_raw(),
    })
}

/// The checker of [`Appearance::checker`]: [`CHECKER_SIZE`]² texels,
/// [`CHECKER_SQUARES`]² squares, [`CHECKER_LIGHT`] at the UV origin (the
/// image's bottom-left square). Cost: 256 KiB, O(texels).
pub(crate) fn checker() -> Image {
    let side = CHECKER_SIZE / CHECKER_SQUARES;
    let mut rgba = Vec::with_capacity((4 * CHECKER_SIZE * CHECKER_SIZE) as usize);
    for y in 0..CHECKER_SIZE {
        // Rows run top to bottom and v up, so count squares from the bottom.
        let row = (CHECKER_SIZE - 1 - y) / side;
        for x in 0..CHECKER_SIZE {
            let light = (x / side + row) % 2 == 0;
            rgba.extend_from_slice(if light { &CHECKER_LIGHT } else { &CHECKER_DARK });
        }
    }
    Image {
        width: CHECKER_SIZE,
        height: CHECKER_SIZE,
        rgba,
    }
}

/// The full mip chain of `base`: `base` itself, then each level half the
/// one above (rounded down, at least 1) down to 1 × 1, box-filtered in
/// linear light (see the module docs); alpha is averaged as is.
///
/// Precondition: `base` is at least 1 × 1 with `4 * width * height` bytes.
/// Cost: about 4/3 of `base` in memory; O(texels) time, three `powf` per
/// texel below level 0.
pub(crate) fn mip_chain(base: Image) -> Vec<Image> {
    debug_assert_eq!(
        base.rgba.len(),
        4 * base.width as usize * base.height as usize,
        "mip_chain: {}x{} image of {} bytes",
        base.width,
        base.height,
        base.rgba.len()
    );
    let to_linear: Vec<f32> = (0..=255u8)
        .map(|b| srgb_to_linear(f32::from(b) / 255.0))
        .collect();
    let mut levels = vec![base];
    while let Some(last) = levels.last() {
        if last.width <= 1 && last.height <= 1 {
            break;
        }
        let next = downsample(last, &to_linear);
        levels.push(next);
    }
    levels
}

/// One box-filtered level below `src`.
fn downsample(src: &Image, to_linear: &[f32]) -> Image {
    let (width, height) = ((src.width / 2).max(1), (src.height / 2).max(1));
    let (sw, sh) = (src.width as usize, src.height as usize);
    let mut rgba = Vec::with_capacity(4 * width as usize * height as usize);
    for y in 0..height as usize {
        let rows = footprint(y, height as usize, sh);
        for x in 0..width as usize {
            let columns = footprint(x, width as usize, sw);
            let mut sum = [0.0f32; 4];
            for sy in rows.clone() {
                for texel in src.rgba[4 * (sy * sw + columns.start)..4 * (sy * sw + columns.end)]
                    .chunks_exact(4)
                {
                    for c in 0..3 {
                        sum[c] += to_linear[usize::from(texel[c])];
                    }
                    sum[3] += f32::from(texel[3]) / 255.0;
                }
            }
            let n = (rows.len() * columns.len()) as f32;
            for (c, s) in sum.iter().enumerate() {
                let mean = s / n;
                let encoded = if c < 3 { linear_to_srgb(mean) } else { mean };
                rgba.push((encoded * 255.0).round().clamp(0.0, 255.0) as u8);
            }
        }
    }
    Image {
        width,
        height,
        rgba,
    }
}

/// The texels `i * src / dst .. ceil((i + 1) * src / dst)` of a side of
/// `src` texels that texel `i` of `dst` covers.
fn footprint(i: usize, dst: usize, src: usize) -> std::ops::Range<usize> {
    i * src / dst..((i + 1) * src).div_ceil(dst)
}

/// The sRGB transfer function's inverse (IEC 61966-2-1), 0..1 to 0..1.
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB transfer function (IEC 61966-2-1), 0..1 to 0..1.
fn linear_to_srgb(l: f32) -> f32 {
    if l <= 0.003_130_8 {
        l * 12.92
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    }
}

/// `levels` (a mip chain from [`mip_chain`]) as an RGBA8 sRGB texture with
/// one mip level each, and its view.
///
/// Precondition: level 0 fits the device's `max_texture_dimension_2d`.
/// Cost: one texture, a `write_texture` per level.
pub(crate) fn upload(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    levels: &[Image],
    label: &str,
) -> wgpu::TextureView {
    let (width, height) = levels.first().map_or((1, 1), |l| (l.width, l.height));
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: levels.len().max(1) as u32,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (mip_level, level) in levels.iter().enumerate() {
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: mip_level as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            &level.rgba,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * level.width),
                rows_per_image: Some(level.height),
            },
            wgpu::Extent3d {
                width: level.width,
                height: level.height,
                depth_or_array_layers: 1,
            },
        );
    }
    texture.create_view(&wgpu::TextureViewDescriptor::default())
}

/// The sampler every texture is drawn with: trilinear, repeating.
pub(crate) fn sampler(device: &wgpu::Device) -> wgpu::Sampler {
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("mts base colour"),
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: wgpu::AddressMode::Repeat,
        address_mode_w: wgpu::AddressMode::Repeat,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..wgpu::SamplerDescriptor::default()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(width: u32, height: u32, texels: &[[u8; 4]]) -> Image {
        Image {
            width,
            height,
            rgba: texels.concat(),
        }
    }

    fn png(img: &Image) -> Vec<u8> {
        let buffer = image::RgbaImage::from_raw(img.width, img.height, img.rgba.clone()).unwrap();
        let mut bytes = Vec::new();
        buffer
            .write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
            .unwrap();
        bytes
    }

    #[test]
    fn chain_halves_down_to_one_texel() {
        let sizes: Vec<(u32, u32)> = mip_chain(image(5, 3, &[[0; 4]; 15]))
            .iter()
            .map(|l| (l.width, l.height))
            .collect();
        assert_eq!(sizes, [(5, 3), (2, 1), (1, 1)]);
        assert_eq!(mip_chain(image(1, 1, &[[7; 4]])).len(), 1);
        assert_eq!(
            mip_chain(Image {
                width: 256,
                height: 64,
                rgba: vec![0; 4 * 256 * 64]
            })
            .len(),
            9
        );
    }

    #[test]
    fn box_filter_averages_in_linear_light() {
        // Black and white average to linear 0.5, sRGB 188 (not 128); alpha
        // averages as is.
        let black = [0, 0, 0, 255];
        let white = [255, 255, 255, 0];
        let chain = mip_chain(image(2, 2, &[black, white, white, black]));
        assert_eq!(chain[1].rgba, [188, 188, 188, 128]);
        // A constant image stays constant at every level.
        let flat = mip_chain(image(6, 5, &[[10, 100, 200, 255]; 30]));
        assert!(flat
            .iter()
            .all(|l| l.rgba.chunks_exact(4).all(|t| t == [10, 100, 200, 255])));
    }

    #[test]
    fn odd_sides_drop_no_texel() {
        // 3 x 1 -> 1 x 1 averages all three texels: (0 + 0 + 1) / 3 linear.
        let chain = mip_chain(image(
            3,
            1,
            &[[0, 0, 0, 0], [0, 0, 0, 0], [255, 255, 255, 255]],
        ));
        let third = (linear_to_srgb(1.0 / 3.0) * 255.0).round() as u8;
        assert_eq!(chain[1].rgba, [third, third, third, 85]);
        assert_eq!(footprint(0, 2, 5), 0..3);
        assert_eq!(footprint(1, 2, 5), 2..5);
        assert_eq!(footprint(1, 2, 4), 2..4);
    }

    #[test]
    fn jpeg_decodes_whatever_the_mime_says() {
        // A flat 16 x 8 JPEG (quality 90) comes back flat within a step or
        // two of rounding; the format is read from the bytes.
        let flat = image::RgbImage::from_pixel(16, 8, image::Rgb([200, 100, 50]));
        let mut bytes = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, 90)
            .encode_image(&flat)
            .unwrap();
        let texture = Texture::Embedded {
            mime: "image/png".into(),
            bytes,
        };
        let decoded = decode(&texture, 16).unwrap();
        assert_eq!((decoded.width, decoded.height), (16, 8));
        for texel in decoded.rgba.chunks_exact(4) {
            let close = texel
                .iter()
                .zip([200u8, 100, 50, 255])
                .all(|(a, b)| a.abs_diff(b) <= 2);
            assert!(close, "{texel:?}");
        }
    }

    #[test]
    fn checker_is_light_at_the_uv_origin() {
        let c = checker();
        let texel = |x: u32, y: u32| &c.rgba[(4 * (y * c.width + x)) as usize..][..4];
        let side = CHECKER_SIZE / CHECKER_SQUARES;
        // The bottom-left texel is the UV origin.
        assert_eq!(texel(0, CHECKER_SIZE - 1), CHECKER_LIGHT);
        assert_eq!(texel(side, CHECKER_SIZE - 1), CHECKER_DARK);
        assert_eq!(texel(side, CHECKER_SIZE - 1 - side), CHECKER_LIGHT);
        assert_eq!(texel(0, 0), CHECKER_DARK);
        let light = c
            .rgba
            .chunks_exact(4)
            .filter(|t| *t == CHECKER_LIGHT)
            .count();
        assert_eq!(light, (CHECKER_SIZE * CHECKER_SIZE / 2) as usize);
    }

    #[test]
    fn png_decodes_and_bad_images_say_why() {
        let img = image(2, 1, &[[255, 0, 0, 255], [0, 0, 255, 128]]);
        let bytes = png(&img);
        let embedded = |bytes: Vec<u8>| Texture::Embedded {
            mime: "image/png".into(),
            bytes,
        };
        assert_eq!(decode(&embedded(bytes.clone()), 16), Ok(img));
        let too_big = decode(&embedded(bytes.clone()), 1).unwrap_err();
        assert!(too_big.contains("2x1 texels"), "{too_big}");
        let corrupt = decode(&embedded(bytes[..bytes.len() / 2].to_vec()), 16).unwrap_err();
        assert!(
            corrupt.starts_with("texture embedded image/png"),
            "{corrupt}"
        );
        let garbage = decode(&embedded(b"not an image".to_vec()), 16).unwrap_err();
        assert!(garbage.contains("not a PNG or JPEG"), "{garbage}");
        let missing = Texture::File("/nonexistent/mts/albedo.png".into());
        let why = decode(&missing, 16).unwrap_err();
        assert!(
            why.starts_with("texture /nonexistent/mts/albedo.png: cannot read it (No such"),
            "{why}"
        );
        // Not a regular file: refused, not read forever.
        let device = decode(&Texture::File("/dev/zero".into()), 16).unwrap_err();
        assert!(device.contains("not a regular file"), "{device}");
    }
}
