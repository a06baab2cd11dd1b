//! An image metric for levels of detail: how far a frame drawn at some LoD
//! is from the truth, in units of how far the full-detail frame is.
//!
//! The truth is the full-detail frame drawn at [`SUPERSAMPLING`] ×
//! [`SUPERSAMPLING`] samples per pixel (a regular grid: one frame
//! `SUPERSAMPLING` times wider and taller) and box-filtered in linear light
//! down to the frame's pixels ([`Reference`]). The figure
//! ([`ImageError::ratio`]) is
//!
//! ```text
//! RMSE(LoD frame at 1 sample per pixel, reference)
//! / RMSE(full-detail frame at 1 sample per pixel, reference)
//! ```
//!
//! 1.0: as close to the truth as drawing everything; below 1, closer (a
//! coarser surface can alias less); above 1, farther. Drawing everything
//! at one sample per pixel is not the truth either (its edges alias), and
//! that error is the unit: a LoD at 1.0 strays from the truth no more than
//! the frame it replaces.
//!
//! Why RMSE of sRGB-encoded values, and not SSIM or FLIP:
//! - the ratio compares two errors of the same kind on the same pixels, so
//!   what a perceptual metric adds (weighting by visibility) would largely
//!   cancel; what is left is the one property the ratio needs: squared
//!   errors add over pixels and over frames, so frames pool exactly (sums,
//!   then one square root) and pixels that are background in all three
//!   images add 0 to both sums — counting the background or not gives the
//!   same figure, so it is counted (no "is this the background" test to get
//!   wrong);
//! - it has no parameters (FLIP needs the viewing distance in pixels per
//!   degree; SSIM a window and two constants, which make a dark flat region
//!   such as this background score differently from a bright one);
//! - values are compared sRGB-encoded (closer to perceptually uniform than
//!   linear light, and the units of [`crate::headless::Difference::rms`]),
//!   while the filter averages linear light, which is what a pixel's area
//!   sums: an edge pixel half white, half black is 0.5 linear, 188 of 255,
//!   not 128.
//!
//! What it costs: RMSE does not weight by visibility, so a faint shading
//! change over a large area counts as much as a few strong edge errors of
//! the same sum of squares.
//!
//! When the full-detail frame equals the reference (no edges at all, or an
//! empty frame) the ratio would divide by zero. Both sums of squares carry
//! the variance of rounding to 8 bits, (1/255)² / 12 per channel value
//! (`ROUNDING_VARIANCE`): an error below what an 8-bit image can show is
//! not measured. Identical images give exactly 1.0, a LoD frame identical
//! to the full-detail one exactly 1.0, and a full-detail frame equal to the
//! reference gives the LoD frame's error in units of that rounding, finite.
//! On a real frame the allowance is small: 3.0 in squared units at
//! 1024 × 768, where the 1-spp full-detail frame of `mts render --generated
//! torus:20k --scene 1000` is 447 from its reference (lavapipe).
//!
//! Based on: P. Lindstrom and G. Turk, "Image-Driven Simplification", ACM
//! TOG 19(3), 2000 (the RMS difference of images over views as the measure
//! of a simplified mesh); the sRGB transfer function of IEC 61966-2-1. Not used, and why
//! above: Z. Wang et al., "Image Quality Assessment: From Error Visibility
//! to Structural Similarity", IEEE TIP 13(4), 2004; P. Andersson et al.,
//! "FLIP: A Difference Evaluator for Alternating Images", HPG 2020.

use crate::headless::{HeadlessTarget, Image};
use crate::Camera;
use glam::{Mat4, Vec3};
use mts::{Error, Result};

/// Samples per pixel side of a [`Reference`] (4: 16 samples per pixel).
/// An axis-aligned edge through a pixel is then placed to within 1/8 of
/// the pixel (one sample per pixel: 1/2), a slanted one closer: the
/// reference's own error is at most a quarter of the error it measures at
/// an edge.
pub const SUPERSAMPLING: u32 = 4;

/// The variance of rounding a value in 0..=1 to 8 bits, (1/255)² / 12:
/// what [`ImageError::ratio`] adds per channel value to both sums.
const ROUNDING_VARIANCE: f64 = 1.0 / (12.0 * 255.0 * 255.0);

/// The truth a frame is measured against: the full-detail frame
/// supersampled and box-filtered, as unrounded sRGB-encoded values.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `3 * width * height` sRGB-encoded RGB values in 0..=1, rows top to
    /// bottom, not rounded to 8 bits.
    pub rgb: Vec<f32>,
}

impl Reference {
    /// The reference of an image drawn `factor` times wider and taller than
    /// the frame: each `factor` × `factor` block's RGB decoded from sRGB,
    /// averaged (a box filter) and encoded again. Alpha is ignored.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when `factor` is 0 or does not divide the
    /// image's width and height.
    ///
    /// Cost: O(pixels of `image`); one allocation of the result.
    pub fn from_supersampled(image: &Image, factor: u32) -> Result<Reference> {
        if factor == 0 || image.width % factor != 0 || image.height % factor != 0 {
            return Err(Error::InvalidArgument(format!(
                "a {}x{} image is not {factor} times a whole frame per side",
                image.width, image.height
            )));
        }
        let (width, height) = (image.width / factor, image.height / factor);
        let mut linear = vec![0f32; 3 * width as usize * height as usize];
        add_linear(&mut linear, (width, height), image, factor, (0, 0));
        Ok(Reference::from_linear_sums(
            width,
            height,
            linear,
            factor * factor,
        ))
    }

    /// Sums of `samples` linear values per channel, averaged and encoded.
    fn from_linear_sums(width: u32, height: u32, mut rgb: Vec<f32>, samples: u32) -> Reference {
        let scale = 1.0 / samples as f32;
        for v in &mut rgb {
            *v = encode_srgb(*v * scale);
        }
        Reference { width, height, rgb }
    }

    /// The sum over pixels and RGB channels of the squared difference
    /// between `image` (bytes / 255) and the reference, sRGB-encoded.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when the sizes differ.
    ///
    /// Cost: O(pixels), allocation-free.
    pub fn squared_error(&self, image: &Image) -> Result<f64> {
        if (image.width, image.height) != (self.width, self.height) {
            return Err(Error::InvalidArgument(format!(
                "a {}x{} image against a {}x{} reference",
                image.width, image.height, self.width, self.height
            )));
        }
        let mut sum = 0f64;
        for (pixel, truth) in image.rgba.chunks_exact(4).zip(self.rgb.chunks_exact(3)) {
            for c in 0..3 {
                sum += (f64::from(pixel[c]) / 255.0 - f64::from(truth[c])).powi(2);
            }
        }
        Ok(sum)
    }
}

/// A frame `SUPERSAMPLING` times wider and taller than `width` × `height`,
/// drawn in tiles as the device's texture and buffer limits allow, and
/// filtered into a [`Reference`].
pub struct ReferenceTarget {
    /// Where each tile is drawn: `SUPERSAMPLING` × the tile's pixels.
    tile: HeadlessTarget,
    /// The frame's size in pixels.
    width: u32,
    height: u32,
    /// Frame pixels per tile side (the last tile of a row or column may
    /// reach past the frame; what lies past it is dropped).
    tile_width: u32,
    tile_height: u32,
}

impl ReferenceTarget {
    /// A target for the references of `width` × `height` frames, in as few
    /// tiles as the device holds: 1, then 2 × 2, 4 × 4… tiles.
    ///
    /// # Errors
    /// As [`HeadlessTarget::new`] when even one-pixel tiles do not fit, and
    /// for a zero size.
    ///
    /// Cost: one texture pair and readback buffer of at most
    /// `SUPERSAMPLING²` × the frame's pixels.
    pub fn new(device: &wgpu::Device, width: u32, height: u32) -> Result<ReferenceTarget> {
        let mut tiles = 1;
        loop {
            match ReferenceTarget::tiled(device, width, height, tiles) {
                Ok(target) => return Ok(target),
                Err(e) if tiles >= width.max(height) => return Err(e),
                Err(_) => tiles = tiles.saturating_mul(2),
            }
        }
    }

    /// [`ReferenceTarget::new`] drawn in `tiles` × `tiles` tiles of
    /// `⌈width / tiles⌉` × `⌈height / tiles⌉` frame pixels: for a device
    /// whose limits are known, and to check that tiling changes nothing.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a zero size or `tiles`; as
    /// [`HeadlessTarget::new`] when a tile does not fit the device.
    pub fn tiled(
        device: &wgpu::Device,
        width: u32,
        height: u32,
        tiles: u32,
    ) -> Result<ReferenceTarget> {
        if width == 0 || height == 0 || tiles == 0 {
            return Err(Error::InvalidArgument(format!(
                "a reference of {width}x{height} pixels in {tiles} tiles a side"
            )));
        }
        let (tile_width, tile_height) = (width.div_ceil(tiles), height.div_ceil(tiles));
        let tile = HeadlessTarget::new(
            device,
            tile_width.saturating_mul(SUPERSAMPLING),
            tile_height.saturating_mul(SUPERSAMPLING),
        )?;
        Ok(ReferenceTarget {
            tile,
            width,
            height,
            tile_width,
            tile_height,
        })
    }

    /// Tiles per side.
    #[must_use]
    pub fn tiles(&self) -> u32 {
        self.width
            .div_ceil(self.tile_width)
            .max(self.height.div_ceil(self.tile_height))
    }

    /// The reference of the frame `camera` sees: for each tile, `frame`
    /// draws the full-detail frame seen by the camera it is given (this
    /// camera with the tile's part of the view stretched over the whole
    /// clip space) into the target it is given and reads it back
    /// ([`HeadlessTarget::render_image`]). The tile camera's projection is
    /// not the frame's: `frame` must draw full detail, not choose LoDs by
    /// screen-space error through it.
    ///
    /// # Errors
    /// As `frame`; [`Error::InvalidArgument`] when it returns an image of
    /// another size than the target's.
    ///
    /// Cost: one `frame` call per tile; O(`SUPERSAMPLING²` × pixels) to
    /// filter; the result and one sum buffer of the frame's size.
    pub fn render(
        &self,
        camera: &Camera,
        mut frame: impl FnMut(&Camera, &HeadlessTarget) -> Result<Image>,
    ) -> Result<Reference> {
        let (width, height) = (self.width, self.height);
        let mut linear = vec![0f32; 3 * width as usize * height as usize];
        let ndc_x = |x: u32| -1.0 + 2.0 * f64::from(x) / f64::from(width);
        let ndc_y = |y: u32| 1.0 - 2.0 * f64::from(y) / f64::from(height);
        for y0 in (0..height).step_by(self.tile_height as usize) {
            for x0 in (0..width).step_by(self.tile_width as usize) {
                // The tile's rectangle in normalised device coordinates
                // (x right, y up; rows counted from the top), mapped onto
                // -1..1: in clip space, before the division by w.
                let (left, right) = (ndc_x(x0), ndc_x(x0 + self.tile_width));
                let (bottom, top) = (ndc_y(y0 + self.tile_height), ndc_y(y0));
                let to_tile = Mat4::from_scale(Vec3::new(
                    (2.0 / (right - left)) as f32,
                    (2.0 / (top - bottom)) as f32,
                    1.0,
                )) * Mat4::from_translation(Vec3::new(
                    (-0.5 * (left + right)) as f32,
                    (-0.5 * (bottom + top)) as f32,
                    0.0,
                ));
                let tile_camera = Camera {
                    view_proj: to_tile * camera.view_proj,
                    ..*camera
                };
                let image = frame(&tile_camera, &self.tile)?;
                if (image.width, image.height) != self.tile.size() {
                    return Err(Error::InvalidArgument(format!(
                        "a {}x{} tile drawn where the target is {:?}",
                        image.width,
                        image.height,
                        self.tile.size()
                    )));
                }
                add_linear(
                    &mut linear,
                    (width, height),
                    &image,
                    SUPERSAMPLING,
                    (x0, y0),
                );
            }
        }
        Ok(Reference::from_linear_sums(
            width,
            height,
            linear,
            SUPERSAMPLING * SUPERSAMPLING,
        ))
    }
}

/// Squared errors of LoD frames and of full-detail frames against their
/// references, summed over frames: [`ImageError::ratio`] is the figure.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ImageError {
    /// Σ of squared sRGB-encoded differences, LoD frames.
    pub lod_squared: f64,
    /// Σ of squared differences, full-detail frames at one sample a pixel.
    pub full_detail_squared: f64,
    /// Channel values summed over: 3 × pixels × frames.
    pub values: u64,
}

impl ImageError {
    /// Adds one frame: its reference, the full-detail frame and the LoD
    /// frame drawn at one sample per pixel with the same camera.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when a size differs from the
    /// reference's; nothing is added then.
    ///
    /// Cost: O(pixels), allocation-free.
    pub fn add(&mut self, reference: &Reference, full_detail: &Image, lod: &Image) -> Result<()> {
        let full = reference.squared_error(full_detail)?;
        let lod = reference.squared_error(lod)?;
        self.full_detail_squared += full;
        self.lod_squared += lod;
        self.values += 3 * u64::from(reference.width) * u64::from(reference.height);
        Ok(())
    }

    /// RMSE of the LoD frames over RMSE of the full-detail frames, both
    /// against the references and pooled over the frames added, each sum
    /// of squares with the 8-bit rounding allowance (the module's doc):
    /// `√((lod + a) / (full + a))`, `a = values · (1/255)² / 12`. Finite
    /// and positive; `None` before any frame was added.
    #[must_use]
    pub fn ratio(&self) -> Option<f64> {
        (self.values > 0).then(|| {
            let allowance = self.values as f64 * ROUNDING_VARIANCE;
            ((self.lod_squared + allowance) / (self.full_detail_squared + allowance)).sqrt()
        })
    }
}

/// Adds the linear RGB of `image`, drawn `factor` times denser than the
/// frame, into `linear` (the frame's `3 × width × height` sums) with the
/// image's top-left at frame pixel `at`; samples past the frame are
/// dropped. Cost: O(pixels of `image`).
fn add_linear(
    linear: &mut [f32],
    (width, height): (u32, u32),
    image: &Image,
    factor: u32,
    at: (u32, u32),
) {
    let decode = srgb_to_linear_table();
    for (row, line) in image
        .rgba
        .chunks_exact(4 * image.width as usize)
        .enumerate()
    {
        let y = at.1 as usize + row / factor as usize;
        if y >= height as usize {
            break;
        }
        for (column, pixel) in line.chunks_exact(4).enumerate() {
            let x = at.0 as usize + column / factor as usize;
            if x >= width as usize {
                break;
            }
            let sum = &mut linear[3 * (y * width as usize + x)..][..3];
            for c in 0..3 {
                sum[c] += decode[usize::from(pixel[c])];
            }
        }
    }
}

/// Linear light of each 8-bit sRGB value (IEC 61966-2-1).
fn srgb_to_linear_table() -> [f32; 256] {
    std::array::from_fn(|i| {
        let v = i as f64 / 255.0;
        let linear = if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        };
        linear as f32
    })
}

/// The sRGB encoding of linear light `v` in 0..=1, not rounded.
fn encode_srgb(v: f32) -> f32 {
    let v = f64::from(v.clamp(0.0, 1.0));
    let encoded = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    encoded as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An image of `width` × `height` pixels of one grey level `g` each,
    /// given row by row.
    fn grey(width: u32, height: u32, g: &[u8]) -> Image {
        assert_eq!(g.len(), (width * height) as usize);
        Image {
            width,
            height,
            rgba: g.iter().flat_map(|&g| [g, g, g, 255]).collect(),
        }
    }

    /// A 2 × 1 frame supersampled 4 × 4: pixel 0 half white (left two
    /// columns of its block), half black; pixel 1 white.
    ///
    /// ```text
    ///   WWbb WWWW
    ///   WWbb WWWW
    ///   WWbb WWWW
    ///   WWbb WWWW
    /// ```
    fn half_covered() -> Image {
        let row = [255, 255, 0, 0, 255, 255, 255, 255];
        grey(8, 4, &row.repeat(4))
    }

    /// The box filter averages linear light: half white is 0.5 linear,
    /// encoded 0.7354 (188 of 255), not 0.5.
    #[test]
    fn the_reference_averages_linear_light() {
        let r = Reference::from_supersampled(&half_covered(), 4).unwrap();
        assert_eq!((r.width, r.height), (2, 1));
        let half = 1.055 * 0.5f64.powf(1.0 / 2.4) - 0.055;
        for c in 0..3 {
            assert!((f64::from(r.rgb[c]) - half).abs() < 1e-6, "{:?}", r.rgb);
            assert_eq!(r.rgb[3 + c], 1.0);
        }
        assert!((half - 0.735_356_6).abs() < 1e-6);
        let e = Reference::from_supersampled(&half_covered(), 3).unwrap_err();
        assert!(e.to_string().contains("not 3 times"), "{e}");
    }

    /// Identical frames: 1.0 exactly (the allowance over itself, where a
    /// bare ratio would be 0/0). A LoD frame equal to the full-detail one:
    /// 1.0 exactly. A worse one (the half-covered pixel black where the
    /// full-detail frame drew it white): the ratio of the two errors, up
    /// to the allowance.
    #[test]
    fn the_ratio_is_one_for_full_detail_and_above_for_worse() {
        let flat = grey(2, 1, &[255, 255]);
        let same = Reference::from_supersampled(&grey(8, 4, &[255; 32]), 4).unwrap();
        let mut e = ImageError::default();
        e.add(&same, &flat, &flat).unwrap();
        assert_eq!(e.lod_squared, 0.0);
        assert_eq!(e.full_detail_squared, 0.0);
        assert_eq!(e.values, 6);
        assert_eq!(e.ratio(), Some(1.0));
        // The full frame equals the reference, the LoD frame does not:
        // finite, in units of the rounding allowance.
        let mut e = ImageError::default();
        e.add(&same, &flat, &grey(2, 1, &[0, 255])).unwrap();
        let expected = ((3.0 + 6.0 * ROUNDING_VARIANCE) / (6.0 * ROUNDING_VARIANCE)).sqrt();
        assert!((e.ratio().unwrap() - expected).abs() < 1e-9, "{e:?}");
        assert!(e.ratio().unwrap() > 600.0);

        let reference = Reference::from_supersampled(&half_covered(), 4).unwrap();
        let full = grey(2, 1, &[255, 255]);
        let mut e = ImageError::default();
        e.add(&reference, &full, &full).unwrap();
        assert_eq!(e.ratio(), Some(1.0));
        assert!(e.full_detail_squared > 0.0);

        let lod = grey(2, 1, &[0, 255]);
        let mut e = ImageError::default();
        e.add(&reference, &full, &lod).unwrap();
        let half = f64::from(reference.rgb[0]);
        assert!((e.full_detail_squared - 3.0 * (1.0 - half).powi(2)).abs() < 1e-9);
        assert!((e.lod_squared - 3.0 * half.powi(2)).abs() < 1e-9);
        let a = 6.0 * ROUNDING_VARIANCE;
        let expected = ((3.0 * half.powi(2) + a) / (3.0 * (1.0 - half).powi(2) + a)).sqrt();
        assert!((e.ratio().unwrap() - expected).abs() < 1e-9, "{e:?}");
        assert!((expected - 2.778).abs() < 1e-3, "{expected}");
        // Pooled over frames: sums, then one square root.
        e.add(&reference, &full, &full).unwrap();
        let pooled = ((3.0 * half.powi(2) + 3.0 * (1.0 - half).powi(2) + 2.0 * a)
            / (6.0 * (1.0 - half).powi(2) + 2.0 * a))
            .sqrt();
        assert!((e.ratio().unwrap() - pooled).abs() < 1e-9, "{e:?}");
    }

    /// Background that is background in all three images adds nothing: the
    /// ratio over a frame with more of it is the same but for the
    /// allowance, which grows with the frame.
    #[test]
    fn background_pixels_add_nothing_but_the_allowance() {
        let mut wide = half_covered();
        // Four more black pixels to the right, in all three images.
        let mut rgba = Vec::new();
        for line in wide.rgba.chunks_exact(32) {
            rgba.extend_from_slice(line);
            rgba.extend_from_slice(&[0, 0, 0, 255].repeat(16));
        }
        wide = Image {
            width: 24,
            height: 4,
            rgba,
        };
        let reference = Reference::from_supersampled(&wide, 4).unwrap();
        let (full, lod) = (
            grey(6, 1, &[255, 255, 0, 0, 0, 0]),
            grey(6, 1, &[0, 255, 0, 0, 0, 0]),
        );
        let mut e = ImageError::default();
        e.add(&reference, &full, &lod).unwrap();
        let half = f64::from(reference.rgb[0]);
        assert!((e.lod_squared - 3.0 * half.powi(2)).abs() < 1e-9);
        assert!((e.full_detail_squared - 3.0 * (1.0 - half).powi(2)).abs() < 1e-9);
        assert_eq!(e.values, 18);
        assert_eq!(
            reference
                .squared_error(&grey(2, 1, &[0, 0]))
                .unwrap_err()
                .to_string(),
            "invalid argument: a 2x1 image against a 6x1 reference"
        );
        assert_eq!(ImageError::default().ratio(), None);
    }
}
