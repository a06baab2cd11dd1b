//! What the adapter itself counts for one draw: pipeline statistics
//! (vertex-shader invocations, clipper invocations, fragment-shader
//! invocations) and GPU time from timestamps, through wgpu's
//! `PIPELINE_STATISTICS_QUERY` and `TIMESTAMP_QUERY` features.
//!
//! Each is optional: [`crate::Gpu`] requests a feature only where the
//! adapter offers it, and a missing one reads as `None`, never as a number
//! (lavapipe offers both; wgpu's GL backend offers neither).

use crate::headless::HeadlessTarget;
use mts::{Error, Result};

/// The adapter's counts for one pass.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PipelineCounts {
    /// Vertex-shader invocations: what the post-transform cache let through.
    pub vertex_invocations: u64,
    /// Primitives entering the clipper: the triangles assembled (degenerate
    /// windows of strips may or may not count, by driver).
    pub clipper_invocations: u64,
    /// Fragment-shader invocations (2×2 quads included).
    pub fragment_invocations: u64,
}

/// What [`DrawQueries::measure`] read: each `None` where the device lacks
/// the feature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrawMeasurement {
    /// Pipeline statistics of the pass.
    pub counts: Option<PipelineCounts>,
    /// GPU milliseconds between the pass's start and end timestamps.
    pub gpu_ms: Option<f64>,
}

/// Query sets and buffers for measuring one pass at a time.
#[derive(Debug)]
pub struct DrawQueries {
    statistics: Option<wgpu::QuerySet>,
    timestamps: Option<wgpu::QuerySet>,
    /// Resolved results: 3 statistics then 2 timestamps, u64 each.
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// Nanoseconds per timestamp tick.
    period_ns: f64,
}

/// Bytes of the resolved queries: 3 statistics, then 2 timestamps at a
/// 256-byte offset (wgpu's `QUERY_RESOLVE_BUFFER_ALIGNMENT`).
const TIMESTAMP_OFFSET: u64 = 256;
const RESOLVE_BYTES: u64 = TIMESTAMP_OFFSET + 16;

impl DrawQueries {
    /// Query sets for the features `device` has (see
    /// [`DrawQueries::has_statistics`], [`DrawQueries::has_timestamps`]).
    /// Cost: two small buffers, at most two query sets.
    #[must_use]
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> DrawQueries {
        let features = device.features();
        let statistics = features
            .contains(wgpu::Features::PIPELINE_STATISTICS_QUERY)
            .then(|| {
                device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("mts pipeline statistics"),
                    ty: wgpu::QueryType::PipelineStatistics(
                        wgpu::PipelineStatisticsTypes::VERTEX_SHADER_INVOCATIONS
                            | wgpu::PipelineStatisticsTypes::CLIPPER_INVOCATIONS
                            | wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS,
                    ),
                    count: 1,
                })
            });
        let timestamps = features.contains(wgpu::Features::TIMESTAMP_QUERY).then(|| {
            device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("mts pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            })
        });
        let buffer = |usage, label| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: RESOLVE_BYTES,
                usage,
                mapped_at_creation: false,
            })
        };
        DrawQueries {
            statistics,
            timestamps,
            resolve: buffer(
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                "mts query resolve",
            ),
            readback: buffer(
                wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                "mts query readback",
            ),
            period_ns: f64::from(queue.get_timestamp_period()),
        }
    }

    /// Whether pipeline statistics are read.
    #[must_use]
    pub fn has_statistics(&self) -> bool {
        self.statistics.is_some()
    }

    /// Whether GPU time is read.
    #[must_use]
    pub fn has_timestamps(&self) -> bool {
        self.timestamps.is_some()
    }

    /// Draws `draw` in one cleared pass into `target` inside the queries,
    /// waits, and reads the counts back.
    ///
    /// # Errors
    /// [`Error::Gpu`] when waiting or mapping fails.
    ///
    /// Cost: one submission, one wait, 272 bytes read back.
    pub fn measure(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        target: &HeadlessTarget,
        draw: impl FnOnce(&mut wgpu::RenderPass<'_>),
    ) -> Result<DrawMeasurement> {
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("mts measured frame"),
        });
        let writes = self
            .timestamps
            .as_ref()
            .map(|set| wgpu::RenderPassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(0),
                end_of_pass_write_index: Some(1),
            });
        target.encode_timed_pass(&mut encoder, writes, |pass| {
            if let Some(set) = &self.statistics {
                pass.begin_pipeline_statistics_query(set, 0);
            }
            draw(pass);
            if self.statistics.is_some() {
                pass.end_pipeline_statistics_query();
            }
        });
        if let Some(set) = &self.statistics {
            encoder.resolve_query_set(set, 0..1, &self.resolve, 0);
        }
        if let Some(set) = &self.timestamps {
            encoder.resolve_query_set(set, 0..2, &self.resolve, TIMESTAMP_OFFSET);
        }
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, RESOLVE_BYTES);
        queue.submit([encoder.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        self.readback
            .slice(..)
            .map_async(wgpu::MapMode::Read, move |r| {
                // The receiver outlives the poll below.
                let _ = tx.send(r);
            });
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| Error::Gpu(format!("waiting for the queries: {e}")))?;
        rx.recv()
            .map_err(|e| Error::Gpu(format!("query readback callback lost: {e}")))?
            .map_err(|e| Error::Gpu(format!("mapping the query readback: {e}")))?;
        let words: Vec<u64> = {
            let view = self
                .readback
                .slice(..)
                .get_mapped_range()
                .map_err(|e| Error::Gpu(format!("reading the query readback: {e}")))?;
            view.chunks_exact(8)
                .map(|c| u64::from_le_bytes(c.try_into().expect("8-byte chunk")))
                .collect()
        };
        self.readback.unmap();
        let t = (TIMESTAMP_OFFSET / 8) as usize;
        Ok(DrawMeasurement {
            // wgpu resolves the statistics in the order of their bits.
            counts: self.statistics.as_ref().map(|_| PipelineCounts {
                vertex_invocations: words[0],
                clipper_invocations: words[1],
                fragment_invocations: words[2],
            }),
            gpu_ms: self
                .timestamps
                .as_ref()
                .map(|_| words[t + 1].saturating_sub(words[t]) as f64 * self.period_ns / 1e6),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Camera, Gpu, RendererConfig, StripRenderer};
    use glam::Vec3;

    /// A grid of `n × n` quads in the xy plane, two triangles each.
    fn grid(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let positions = (0..=n)
            .flat_map(|y| (0..=n).map(move |x| Vec3::new(x as f32, y as f32, 0.0)))
            .collect();
        let mut triangles = Vec::new();
        for y in 0..n {
            for x in 0..n {
                let v = y * (n + 1) + x;
                triangles.push([v, v + 1, v + n + 2]);
                triangles.push([v, v + n + 2, v + n + 1]);
            }
        }
        (positions, triangles)
    }

    #[test]
    fn lavapipe_counts_a_list_s_triangles_and_shades_between_distinct_and_indices() {
        let Ok(gpu) = Gpu::new_headless() else {
            eprintln!("no adapter: skipped");
            return;
        };
        let (d, q) = (&gpu.device, &gpu.queue);
        let queries = DrawQueries::new(d, q);
        if !queries.has_statistics() {
            eprintln!("{}: no pipeline statistics: skipped", gpu.report());
            return;
        }
        let (positions, triangles) = grid(20);
        let target = HeadlessTarget::new(d, 256, 256).unwrap();
        let config = RendererConfig::headless(gpu.report().strip_mode);
        let mut renderer = StripRenderer::new(d, q, &config, &positions, &triangles).unwrap();
        renderer.set_camera(q, &Camera::framing_points(&positions, target.aspect()));
        renderer.upload_list(d, q, &triangles).unwrap();
        let m = queries
            .measure(d, q, &target, |pass| renderer.draw(pass))
            .unwrap();
        let c = m.counts.unwrap();
        assert_eq!(c.clipper_invocations, 800);
        assert!(
            (441..=2400).contains(&c.vertex_invocations),
            "{} invocations",
            c.vertex_invocations
        );
        assert!(c.fragment_invocations > 0);
        assert_eq!(m.gpu_ms.is_some(), queries.has_timestamps());
    }
}
