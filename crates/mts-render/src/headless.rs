//! Headless rendering: a colour and depth texture to draw into, a readback
//! through a staging buffer (rows padded to wgpu's 256-byte copy
//! alignment), and the RGBA8 image written as PNG.

use mts::{Error, Result};
use std::path::Path;

/// Colour format of [`HeadlessTarget`] (8-bit sRGB, what a PNG holds).
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// Depth format of [`HeadlessTarget`].
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Clear colour of [`HeadlessTarget::render`] (a dark blue-grey; the
/// background pixels of the PNG are `BACKGROUND_RGBA`).
pub const BACKGROUND: wgpu::Color = wgpu::Color {
    r: 0.02,
    g: 0.025,
    b: 0.035,
    a: 1.0,
};

/// An RGBA8 image read back from the GPU, rows top to bottom, no padding.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `4 * width * height` bytes, sRGB-encoded RGBA.
    pub rgba: Vec<u8>,
}

impl Image {
    /// Pixels whose RGBA differs from the top-left pixel (the background
    /// wherever the model does not reach the corner). Cost: O(pixels).
    #[must_use]
    pub fn foreground_pixels(&self) -> usize {
        let Some(corner) = self.rgba.get(..4) else {
            return 0;
        };
        self.rgba.chunks_exact(4).filter(|p| *p != corner).count()
    }

    /// Pixels that differ between `self` and `other` (every pixel when the
    /// sizes differ). Cost: O(pixels).
    #[must_use]
    pub fn differing_pixels(&self, other: &Image) -> usize {
        if (self.width, self.height) != (other.width, other.height) {
            return (self.width * self.height).max(other.width * other.height) as usize;
        }
        self.rgba
            .chunks_exact(4)
            .zip(other.rgba.chunks_exact(4))
            .filter(|(a, b)| a != b)
            .count()
    }

    /// How `other` differs from `self` (the reference) over the pixels
    /// where either shows the model (differs from its own top-left pixel,
    /// as [`Image::foreground_pixels`]): the share of them whose red, green
    /// or blue byte differs by more than `tolerance`, and the RMS of the
    /// RGB difference in 0..=1 sRGB units; beside them the share that
    /// differs at all (`changed_share`). The tolerance keeps shading
    /// that moves by a step or two of rounding from counting as a changed
    /// pixel while a checker square that moved (about 160 steps apart)
    /// always does. Images of different sizes differ everywhere (share 1,
    /// RMS 1). Cost: O(pixels).
    #[must_use]
    pub fn difference(&self, other: &Image, tolerance: u8) -> Difference {
        if (self.width, self.height) != (other.width, other.height) {
            let pixels = (self.width * self.height).max(other.width * other.height) as usize;
            return Difference {
                pixels,
                share: 1.0,
                changed_share: 1.0,
                rms: 1.0,
                coverage_changed: pixels,
            };
        }
        let (Some(ca), Some(cb)) = (self.rgba.get(..4), other.rgba.get(..4)) else {
            return Difference::default();
        };
        let (mut pixels, mut differing, mut changed, mut sum, mut coverage) =
            (0usize, 0usize, 0usize, 0f64, 0usize);
        for (a, b) in self.rgba.chunks_exact(4).zip(other.rgba.chunks_exact(4)) {
            if a == ca && b == cb {
                continue;
            }
            pixels += 1;
            coverage += usize::from((a == ca) != (b == cb));
            let mut most = 0u8;
            for c in 0..3 {
                let d = a[c].abs_diff(b[c]);
                most = most.max(d);
                sum += (f64::from(d) / 255.0).powi(2);
            }
            differing += usize::from(most > tolerance);
            changed += usize::from(most > 0);
        }
        if pixels == 0 {
            return Difference::default();
        }
        Difference {
            pixels,
            share: differing as f64 / pixels as f64,
            changed_share: changed as f64 / pixels as f64,
            rms: (sum / (3 * pixels) as f64).sqrt(),
            coverage_changed: coverage,
        }
    }

    /// Reads a PNG (any colour type and depth: palettes, grey and 16-bit
    /// samples are expanded or stripped to 8-bit RGBA, opaque where it has
    /// no alpha), as [`Image::save_png`] writes one: for hosts and tests
    /// that check what a command drew.
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be read, [`Error::Parse`] naming
    /// it when it is not a PNG the decoder reads.
    ///
    /// Cost: O(file + pixels); holds the file and the image.
    pub fn read_png(path: &Path) -> Result<Image> {
        let bytes = mts::mesh::io::read_file(path)?;
        let not_png = |e: png::DecodingError| Error::Parse {
            file: path.to_owned(),
            place: mts::Place::default(),
            message: format!("not a PNG this reader decodes: {e}"),
        };
        let mut decoder = png::Decoder::new(std::io::Cursor::new(&bytes[..]));
        decoder.set_transformations(png::Transformations::normalize_to_color8());
        let mut reader = decoder.read_info().map_err(not_png)?;
        let size = reader.output_buffer_size().ok_or_else(|| Error::Parse {
            file: path.to_owned(),
            place: mts::Place::default(),
            message: "the image is too large for memory".into(),
        })?;
        let mut buffer = vec![0; size];
        let info = reader.next_frame(&mut buffer).map_err(not_png)?;
        buffer.truncate(info.buffer_size());
        let rgba = match info.color_type {
            png::ColorType::Rgba => buffer,
            png::ColorType::Rgb => buffer
                .chunks_exact(3)
                .flat_map(|p| [p[0], p[1], p[2], 255])
                .collect(),
            png::ColorType::GrayscaleAlpha => buffer
                .chunks_exact(2)
                .flat_map(|p| [p[0], p[0], p[0], p[1]])
                .collect(),
            // Grey: palettes were expanded to RGB(A).
            _ => buffer.iter().flat_map(|&g| [g, g, g, 255]).collect(),
        };
        Ok(Image {
            width: info.width,
            height: info.height,
            rgba,
        })
    }

    /// Writes the image as an 8-bit RGBA PNG.
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be created or written.
    pub fn save_png(&self, path: &Path) -> Result<()> {
        mts::output::write_with(path, |file| {
            let mut encoder = png::Encoder::new(file, self.width, self.height);
            encoder.set_color(png::ColorType::Rgba);
            encoder.set_depth(png::BitDepth::Eight);
            encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
            let png_error = std::io::Error::other;
            let mut writer = encoder.write_header().map_err(png_error)?;
            writer.write_image_data(&self.rgba).map_err(png_error)?;
            writer.finish().map_err(png_error)
        })
    }
}

/// [`Image::difference`]: how one image differs from a reference.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Difference {
    /// Pixels where either image shows the model.
    pub pixels: usize,
    /// Share of those whose colour moved beyond the tolerance.
    pub share: f64,
    /// Share of those whose colour moved at all.
    pub changed_share: f64,
    /// RMS of the RGB difference over those pixels, in 0..=1.
    pub rms: f64,
    /// Of those, the pixels that show the model in one image only (the
    /// silhouettes moved).
    pub coverage_changed: usize,
}

/// A colour texture ([`COLOR_FORMAT`]) and depth texture ([`DEPTH_FORMAT`])
/// of one size, and the staging buffer to read the colour back.
#[derive(Debug)]
pub struct HeadlessTarget {
    width: u32,
    height: u32,
    color: wgpu::Texture,
    color_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    staging: wgpu::Buffer,
    /// `4 * width` rounded up to `COPY_BYTES_PER_ROW_ALIGNMENT` (256).
    padded_row: u32,
}

impl HeadlessTarget {
    /// Textures and staging buffer for `width × height` pixels.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a zero size or one above the device's
    /// `max_texture_dimension_2d`.
    pub fn new(device: &wgpu::Device, width: u32, height: u32) -> Result<HeadlessTarget> {
        let max = device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(Error::InvalidArgument(format!(
                "image size {width}x{height} outside 1..={max} per side"
            )));
        }
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = |format, usage, label| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let color = texture(
            COLOR_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            "mts colour",
        );
        let depth = texture(
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
            "mts depth",
        );
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let padded_row = (4 * width).div_ceil(align) * align;
        let readback = u64::from(padded_row) * u64::from(height);
        let max_buffer = device.limits().max_buffer_size;
        if readback > max_buffer {
            return Err(Error::InvalidArgument(format!(
                "image size {width}x{height} needs a {readback}-byte readback buffer, above the \
                 device's max_buffer_size {max_buffer}"
            )));
        }
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("mts readback"),
            size: readback,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        Ok(HeadlessTarget {
            width,
            height,
            color_view: color.create_view(&wgpu::TextureViewDescriptor::default()),
            depth_view: depth.create_view(&wgpu::TextureViewDescriptor::default()),
            color,
            staging,
            padded_row,
        })
    }

    /// Width and height in pixels.
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Width / height, for [`crate::Camera::framing`].
    #[must_use]
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// Clears to [`BACKGROUND`] (depth 1), lets `draw` record into the pass,
    /// submits, and waits for the GPU. Cost: one submission and a wait.
    ///
    /// # Errors
    /// [`Error::Gpu`] when waiting for the device fails.
    pub fn render(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        draw: impl FnOnce(&mut wgpu::RenderPass<'_>),
    ) -> Result<()> {
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("mts headless frame"),
        });
        self.encode_pass(&mut encoder, draw);
        queue.submit([encoder.finish()]);
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| Error::Gpu(format!("waiting for the frame: {e}")))?;
        Ok(())
    }

    /// [`HeadlessTarget::render`], then copies the colour texture to the
    /// staging buffer and reads it back without the row padding.
    ///
    /// # Errors
    /// [`Error::Gpu`] when waiting or mapping fails.
    ///
    /// Cost: one submission, a copy of `padded_row × height` bytes, a wait.
    pub fn render_image(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        draw: impl FnOnce(&mut wgpu::RenderPass<'_>),
    ) -> Result<Image> {
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("mts headless frame"),
        });
        self.encode_pass(&mut encoder, draw);
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &self.color,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &self.staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row),
                    rows_per_image: Some(self.height),
                },
            },
            wgpu::Extent3d {
                width: self.width,
                height: self.height,
                depth_or_array_layers: 1,
            },
        );
        queue.submit([encoder.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        self.staging
            .slice(..)
            .map_async(wgpu::MapMode::Read, move |r| {
                // The receiver outlives the poll below; a send error cannot
                // happen and would only mean nobody is waiting.
                let _ = tx.send(r);
            });
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| Error::Gpu(format!("waiting for the readback: {e}")))?;
        rx.recv()
            .map_err(|e| Error::Gpu(format!("readback callback lost: {e}")))?
            .map_err(|e| Error::Gpu(format!("mapping the readback buffer: {e}")))?;
        let row = 4 * self.width as usize;
        let mut rgba = Vec::with_capacity(row * self.height as usize);
        {
            let view = self
                .staging
                .slice(..)
                .get_mapped_range()
                .map_err(|e| Error::Gpu(format!("reading the readback buffer: {e}")))?;
            for line in view.chunks_exact(self.padded_row as usize) {
                rgba.extend_from_slice(&line[..row]);
            }
        }
        self.staging.unmap();
        Ok(Image {
            width: self.width,
            height: self.height,
            rgba,
        })
    }

    /// Records the cleared pass and `draw` into `encoder`.
    fn encode_pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        draw: impl FnOnce(&mut wgpu::RenderPass<'_>),
    ) {
        self.encode_timed_pass(encoder, None, draw);
    }

    /// Encodes the cleared pass with `timestamps` written at its start and
    /// end (for [`crate::stats`]).
    pub(crate) fn encode_timed_pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
        draw: impl FnOnce(&mut wgpu::RenderPass<'_>),
    ) {
        let mut pass = begin_pass(
            encoder,
            "mts headless pass",
            &self.color_view,
            &self.depth_view,
            timestamps,
        );
        draw(&mut pass);
    }
}

impl crate::RendererConfig {
    /// The configuration that draws into a [`HeadlessTarget`] (its colour
    /// and depth formats), sending strips by `strip_mode`.
    #[must_use]
    pub fn headless(strip_mode: crate::StripMode) -> crate::RendererConfig {
        crate::RendererConfig {
            color_format: COLOR_FORMAT,
            depth_format: Some(DEPTH_FORMAT),
            strip_mode,
        }
    }
}

/// Begins a pass that clears `color` to [`BACKGROUND`] and `depth` to 1
/// (depth is not kept after the pass): what every headless frame and every
/// viewer frame draws into.
pub fn begin_cleared_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    color: &wgpu::TextureView,
    depth: &wgpu::TextureView,
) -> wgpu::RenderPass<'e> {
    begin_pass(encoder, label, color, depth, None)
}

fn begin_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    color: &wgpu::TextureView,
    depth: &wgpu::TextureView,
    timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: color,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(BACKGROUND),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Discard,
            }),
            stencil_ops: None,
        }),
        timestamp_writes,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 × 1 image: background black in the corner, then `pixels`.
    fn image(pixels: [[u8; 3]; 3]) -> Image {
        let mut rgba = vec![0, 0, 0, 255];
        for p in pixels {
            rgba.extend_from_slice(&[p[0], p[1], p[2], 255]);
        }
        Image {
            width: 4,
            height: 1,
            rgba,
        }
    }

    #[test]
    fn difference_counts_model_pixels_beyond_the_tolerance() {
        let reference = image([[200, 200, 200], [64, 64, 64], [0, 0, 0]]);
        // One pixel moved by 2 steps (within 8), one by 160, one newly
        // covered; the corner is background in both.
        let other = image([[202, 200, 200], [224, 64, 64], [10, 10, 10]]);
        let d = reference.difference(&other, 8);
        assert_eq!(d.pixels, 3);
        assert_eq!(d.coverage_changed, 1);
        assert!((d.changed_share - 1.0).abs() < 1e-12, "{d:?}");
        assert!((d.share - 2.0 / 3.0).abs() < 1e-12, "{d:?}");
        let sum = (2f64 / 255.0).powi(2) + (160f64 / 255.0).powi(2) + 3.0 * (10f64 / 255.0).powi(2);
        assert!((d.rms - (sum / 9.0).sqrt()).abs() < 1e-12, "{d:?}");
        // Its own black pixel is background: two pixels show the model.
        assert_eq!(
            reference.difference(&reference, 0),
            Difference {
                pixels: 2,
                share: 0.0,
                changed_share: 0.0,
                rms: 0.0,
                coverage_changed: 0
            }
        );
        let other_size = Image {
            width: 2,
            height: 2,
            rgba: vec![0; 16],
        };
        assert_eq!(reference.difference(&other_size, 8).share, 1.0);
    }

    /// What `save_png` writes, `read_png` reads back byte for byte; a file
    /// that is not a PNG is a parse error naming it.
    #[test]
    fn png_round_trips() {
        let dir = std::env::temp_dir().join(format!("mts-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let original = image([[200, 10, 30], [64, 64, 64], [0, 255, 7]]);
        let path = dir.join("a.png");
        original.save_png(&path).unwrap();
        assert_eq!(Image::read_png(&path).unwrap(), original);
        let bad = dir.join("b.png");
        std::fs::write(&bad, b"not a png").unwrap();
        let e = Image::read_png(&bad).unwrap_err().to_string();
        assert!(e.contains("b.png") && e.contains("not a PNG"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
