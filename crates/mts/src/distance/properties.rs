//! Property error: how far a simplified surface's texture coordinates,
//! normals and colours are from the reference's at corresponding points,
//! the attribute counterpart of [`super::surface_distance`].
//!
//! Correspondence by closest point, as Cignoni, Montani, Rocchini and
//! Scopigno transfer attributes onto a simplified mesh ("A general method
//! for preserving attribute values on simplified meshes", IEEE
//! Visualization 1998) and as Roy, Foufou and Truchetet measure attribute
//! deviation ("Mesh comparison using attribute deviation metric", IJIG
//! 4(1), 2004): each surface is sampled the way
//! [`super::sample`] does, every sample is projected onto the other surface
//! through a [`TriangleBvh`], and the property interpolated
//! (barycentrically) at the sample is compared with the one interpolated
//! at its projection. Both directions are pooled as for the Hausdorff
//! distance: the maximum over both, the RMS over all samples.
//!
//! Where the projection lands on an edge or corner at which the other
//! surface has several vertices (split vertices at a UV seam or hard edge,
//! or parts that touch), the property there has one value per side; the
//! sample is compared with the nearest of them, since every side is that
//! point of the surface.
//!
//! What it measures is appearance error at corresponding surface points,
//! not in the image. Known weaknesses: across a thin part (an ear, a fin)
//! the closest point may lie on the wrong side, whose normal is opposite
//! and whose UVs belong to another chart; where simplification moved a seam
//! a little, samples in the moved strip project into the neighbouring chart
//! and count a UV distance that a texture continuous across the seam would
//! not show. Both inflate the maximum far more than the RMS.

use super::{sample_each, Surface, TriangleBvh};
use crate::mesh::{Mesh, Properties};
use glam::{DVec3, Vec2, Vec3, Vec4};

/// Error of one property stream over the samples of both directions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stat {
    /// Root mean square over every sample that had the property on both
    /// sides.
    pub rms: f64,
    /// Largest error of a sample.
    pub max: f64,
}

/// Error of each property stream of one surface against another, in the
/// stream's own units (not relative to the diagonal); `None` for a stream
/// that one of the meshes lacks, or that no sample had on both sides.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PropertyError {
    /// Distance between texture coordinates, in UV units (1 = the texture's
    /// width).
    pub uv: Option<Stat>,
    /// Angle between the normalised interpolated normals, in degrees; a
    /// sample whose interpolated normal is zero on either side is skipped.
    pub normal_degrees: Option<Stat>,
    /// Euclidean distance between RGBA colours (channels in 0..=1, so at
    /// most 2).
    pub color: Option<Stat>,
}

/// Measures the properties of `other` against `reference` with `samples`
/// area-spread points on each surface plus their vertices, from the seeds
/// [`super::surface_distance`] uses (so the samples are its samples).
///
/// A stream counts only when both meshes carry it. The surfaces are the
/// triangles: unreferenced vertices are ignored, so `other` may be a
/// peer's triangles over all of `reference`'s vertices. An empty `other`
/// against a non-empty `reference` gives infinite errors.
///
/// Cost: O((T + samples) log T) on each side, the queries on all cores.
///
/// # Panics
/// If a stream has fewer entries than its mesh has vertices (an invalid
/// [`Mesh`]).
#[must_use]
pub fn property_error(reference: &Mesh, other: &Mesh, samples: usize) -> PropertyError {
    let (a, b) = (&reference.properties, &other.properties);
    let streams = Streams {
        uv: a.uvs.is_some() && b.uvs.is_some(),
        normal: a.normals.is_some() && b.normals.is_some(),
        color: a.colors.is_some() && b.colors.is_some(),
    };
    if !(streams.uv || streams.normal || streams.color) {
        return PropertyError::default();
    }
    let forward = one_side(reference, &Target::new(other), samples, 1, streams);
    let backward = one_side(other, &Target::new(reference), samples, 2, streams);
    let stat = |k: usize| forward[k].merge(backward[k]).stat();
    PropertyError {
        uv: stat(UV),
        normal_degrees: stat(NORMAL),
        color: stat(COLOR),
    }
}

/// Which streams both meshes carry.
#[derive(Debug, Clone, Copy)]
struct Streams {
    uv: bool,
    normal: bool,
    color: bool,
}

const UV: usize = 0;
const NORMAL: usize = 1;
const COLOR: usize = 2;

/// Running maximum, sum of squares and count of one stream's errors.
#[derive(Debug, Clone, Copy, Default)]
struct Sum {
    max: f64,
    sum2: f64,
    count: usize,
}

impl Sum {
    fn add(&mut self, e: f64) {
        self.max = self.max.max(e);
        self.sum2 += e * e;
        self.count += 1;
    }

    fn merge(self, o: Sum) -> Sum {
        Sum {
            max: self.max.max(o.max),
            sum2: self.sum2 + o.sum2,
            count: self.count + o.count,
        }
    }

    fn stat(self) -> Option<Stat> {
        (self.count > 0).then(|| Stat {
            rms: (self.sum2 / self.count as f64).sqrt(),
            max: self.max,
        })
    }
}

/// The property values at one point: weighted corners interpolated, the
/// normal normalised (`None` where it is zero or the stream is not
/// compared).
#[derive(Debug, Clone, Copy)]
struct Values {
    uv: Option<Vec2>,
    normal: Option<Vec3>,
    color: Option<Vec4>,
}

impl Values {
    fn at(p: &Properties, streams: Streams, corners: &[(u32, f32)]) -> Values {
        fn mix<T: Copy + std::ops::Mul<f32, Output = T> + std::iter::Sum>(
            s: &[T],
            corners: &[(u32, f32)],
        ) -> T {
            corners.iter().map(|&(v, w)| s[v as usize] * w).sum()
        }
        Values {
            uv: p
                .uvs
                .as_deref()
                .filter(|_| streams.uv)
                .map(|s| mix(s, corners)),
            normal: p
                .normals
                .as_deref()
                .filter(|_| streams.normal)
                .and_then(|s| mix(s, corners).try_normalize()),
            color: p
                .colors
                .as_deref()
                .filter(|_| streams.color)
                .map(|s| mix(s, corners)),
        }
    }

    /// Each stream's error between `self` and `o`, `None` where either
    /// lacks the value.
    fn errors(&self, o: &Values) -> [Option<f64>; 3] {
        let uv = self
            .uv
            .zip(o.uv)
            .map(|(a, b)| (a.as_dvec2() - b.as_dvec2()).length());
        let normal = self.normal.zip(o.normal).map(|(a, b)| {
            // atan2 of sine and cosine: exact near 0°, where acos of a dot
            // product near 1 is off by 0.02°.
            let (a, b): (DVec3, DVec3) = (a.as_dvec3(), b.as_dvec3());
            a.cross(b).length().atan2(a.dot(b)).to_degrees()
        });
        let color = self
            .color
            .zip(o.color)
            .map(|(a, b)| (a.as_dvec4() - b.as_dvec4()).length());
        [uv, normal, color]
    }
}

/// A surface samples are projected onto, with what finds the property
/// values at a projection: the BVH, and the vertices at every position and
/// along every edge between two positions.
struct Target<'a> {
    mesh: &'a Mesh,
    bvh: TriangleBvh,
    /// The point (distinct position) of each vertex.
    point_of: Vec<u32>,
    /// Vertices at point `i`: `point_vertices[point_start[i]..point_start[i
    /// + 1]]`.
    point_start: Vec<u32>,
    point_vertices: Vec<u32>,
    /// `[lo, hi, u, w]` for each triangle edge between vertex `u` at point
    /// `lo` and vertex `w` at point `hi`, `lo < hi`; sorted, no repeats.
    edges: Vec<[u32; 4]>,
}

impl<'a> Target<'a> {
    /// Cost: O(T log T + V), hashing each position once.
    fn new(mesh: &'a Mesh) -> Target<'a> {
        let bvh = TriangleBvh::new(
            mesh.triangles
                .iter()
                .map(|t| t.map(|v| mesh.positions[v as usize]))
                .collect(),
        );
        // Points by position, not by position id: an OBJ may repeat a `v`
        // where parts touch (pirate.obj has 217 such points), and the
        // surface there is one point all the same.
        let mut id = std::collections::HashMap::new();
        let point_of: Vec<u32> = mesh
            .positions
            .iter()
            .map(|p| {
                // + 0.0 makes -0.0 and 0.0 one key.
                let key = (*p + Vec3::ZERO).to_array().map(f32::to_bits);
                let next = id.len() as u32;
                *id.entry(key).or_insert(next)
            })
            .collect();
        // Only vertices of the surface: a peer's output keeps every input
        // vertex, and one whose triangles are gone is no reading.
        let mut used = vec![false; mesh.vertex_count()];
        for &v in mesh.triangles.iter().flatten() {
            used[v as usize] = true;
        }
        let points = id.len();
        let mut point_start = vec![0u32; points + 1];
        for (v, &i) in point_of.iter().enumerate() {
            point_start[i as usize + 1] += u32::from(used[v]);
        }
        for i in 0..points {
            point_start[i + 1] += point_start[i];
        }
        let mut next = point_start.clone();
        let mut point_vertices = vec![0u32; point_start[points] as usize];
        for (v, &i) in point_of.iter().enumerate().filter(|&(v, _)| used[v]) {
            point_vertices[next[i as usize] as usize] = v as u32;
            next[i as usize] += 1;
        }
        let mut edges = Vec::with_capacity(3 * mesh.triangle_count());
        for t in &mesh.triangles {
            for k in 0..3 {
                let (u, w) = (t[k], t[(k + 1) % 3]);
                let (pu, pw) = (point_of[u as usize], point_of[w as usize]);
                edges.push(if pu < pw {
                    [pu, pw, u, w]
                } else {
                    [pw, pu, w, u]
                });
            }
        }
        edges.sort_unstable();
        edges.dedup();
        Target {
            mesh,
            bvh,
            point_of,
            point_start,
            point_vertices,
            edges,
        }
    }

    /// Calls `f` with each set of weighted vertices that gives the property
    /// at barycentric `weights` of `triangle`: inside it, its own corners;
    /// on an edge or corner, the vertices of every triangle side there.
    fn readings(&self, triangle: u32, weights: [f64; 3], mut f: impl FnMut(&[(u32, f32)])) {
        let t = self.mesh.triangles[triangle as usize];
        let point = |k: usize| self.point_of[t[k] as usize];
        let mut on = [0usize; 3];
        let mut count = 0;
        for k in (0..3).filter(|&k| weights[k] != 0.0) {
            on[count] = k;
            count += 1;
        }
        match on[..count] {
            [k] => {
                let i = point(k) as usize;
                let range = self.point_start[i] as usize..self.point_start[i + 1] as usize;
                for &v in &self.point_vertices[range] {
                    f(&[(v, 1.0)]);
                }
            }
            [j, k] if point(j) != point(k) => {
                let (mut pj, mut pk) = (point(j), point(k));
                let (mut wj, mut wk) = (weights[j] as f32, weights[k] as f32);
                if pj > pk {
                    (pj, pk, wj, wk) = (pk, pj, wk, wj);
                }
                let first = self.edges.partition_point(|e| (e[0], e[1]) < (pj, pk));
                for e in self.edges[first..]
                    .iter()
                    .take_while(|e| (e[0], e[1]) == (pj, pk))
                {
                    f(&[(e[2], wj), (e[3], wk)]);
                }
            }
            _ => f(&[
                (t[0], weights[0] as f32),
                (t[1], weights[1] as f32),
                (t[2], weights[2] as f32),
            ]),
        }
    }

    /// Each stream's error of a sample with `values` at `p` against this
    /// surface: the smallest over the readings at its closest point.
    fn errors(&self, p: Vec3, values: &Values, streams: Streams) -> [Option<f64>; 3] {
        let Some((triangle, _, _)) = self.bvh.closest_triangle(p) else {
            let inf = |on: bool| on.then_some(f64::INFINITY);
            return [
                inf(values.uv.is_some()),
                inf(values.normal.is_some()),
                inf(values.color.is_some()),
            ];
        };
        let [a, b, c] = self.mesh.triangles[triangle as usize]
            .map(|v| self.mesh.positions[v as usize].as_dvec3());
        let (_, weights) = super::bvh::closest_on_triangle_weights_f64(p.as_dvec3(), a, b, c);
        let mut best = [None::<f64>; 3];
        self.readings(triangle, weights, |corners| {
            let there = Values::at(&self.mesh.properties, streams, corners);
            for (b, e) in best.iter_mut().zip(values.errors(&there)) {
                if let Some(e) = e {
                    *b = Some(b.map_or(e, |b| b.min(e)));
                }
            }
        });
        best
    }
}

/// The summed errors of samples of `from` against `to`.
fn one_side(from: &Mesh, to: &Target<'_>, samples: usize, seed: u64, streams: Streams) -> [Sum; 3] {
    let mut points = Vec::with_capacity(samples + from.vertex_count());
    sample_each(Surface::from(from), samples, seed, |p, t, w| {
        points.push((p, t, w));
    });
    let threads = std::thread::available_parallelism().map_or(1, usize::from);
    let chunk = points.len().div_ceil(threads).max(1);
    let parts: Vec<[Sum; 3]> = std::thread::scope(|scope| {
        let handles: Vec<_> = points
            .chunks(chunk)
            .map(|part| {
                scope.spawn(move || {
                    let mut sums = [Sum::default(); 3];
                    for &(p, t, w) in part {
                        let tri = from.triangles[t as usize];
                        let corners = [(tri[0], w[0]), (tri[1], w[1]), (tri[2], w[2])];
                        let values = Values::at(&from.properties, streams, &corners);
                        for (s, e) in sums.iter_mut().zip(to.errors(p, &values, streams)) {
                            if let Some(e) = e {
                                s.add(e);
                            }
                        }
                    }
                    sums
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("property error worker panicked"))
            .collect()
    });
    parts.iter().fold([Sum::default(); 3], |acc, p| {
        [acc[0].merge(p[0]), acc[1].merge(p[1]), acc[2].merge(p[2])]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two unit squares side by side in z = 0, facing +z, with a UV seam
    /// down the middle: points P1 and P4 are vertices 1 and 4 on the left
    /// (u = 0.4) and 6 and 7 on the right (u = 0.6).
    ///
    /// ```text
    ///   P3 ------ P4 ------ P5        v3 ---- v4 | v7 ---- v5
    ///   |      /  |      /  |          |    /   |  |    /   |
    ///   |    /    |    /    |          |  /     |  |  /     |
    ///   P0 ------ P1 ------ P2        v0 ---- v1 | v6 ---- v2
    /// ```
    fn seam_strip() -> Mesh {
        let p = |x: f32, y: f32| Vec3::new(x, y, 0.0);
        Mesh {
            positions: vec![
                p(0.0, 0.0),
                p(1.0, 0.0),
                p(2.0, 0.0),
                p(0.0, 1.0),
                p(1.0, 1.0),
                p(2.0, 1.0),
                p(1.0, 0.0),
                p(1.0, 1.0),
            ],
            triangles: vec![[0, 1, 4], [0, 4, 3], [6, 2, 5], [6, 5, 7]],
            properties: Properties {
                normals: Some(vec![Vec3::Z; 8]),
                uvs: Some(vec![
                    Vec2::new(0.0, 0.0),
                    Vec2::new(0.4, 0.0),
                    Vec2::new(1.0, 0.0),
                    Vec2::new(0.0, 1.0),
                    Vec2::new(0.4, 1.0),
                    Vec2::new(1.0, 1.0),
                    Vec2::new(0.6, 0.0),
                    Vec2::new(0.6, 1.0),
                ]),
                colors: Some(vec![Vec4::new(0.5, 0.5, 0.5, 1.0); 8]),
                position_ids: vec![0, 1, 2, 3, 4, 5, 1, 4],
                texture: None,
            },
        }
    }

    fn close(s: Option<Stat>, want: f64, tolerance: f64) {
        let s = s.expect("stream measured");
        assert!(
            (s.rms - want).abs() <= tolerance && (s.max - want).abs() <= tolerance,
            "{s:?}, want {want}"
        );
    }

    #[test]
    fn identical_meshes_measure_zero_across_a_seam() {
        let m = seam_strip();
        m.validate().unwrap();
        let e = property_error(&m, &m.clone(), 5000);
        close(e.uv, 0.0, 1e-6);
        close(e.normal_degrees, 0.0, 0.0);
        close(e.color, 0.0, 1e-6);
    }

    #[test]
    fn a_seam_edge_reads_both_sides() {
        let m = seam_strip();
        let target = Target::new(&m);
        let mut seen = Vec::new();
        // Triangle [0, 1, 4] at the middle of its edge v1-v4 (the seam).
        target.readings(0, [0.0, 0.25, 0.75], |c| seen.push(c.to_vec()));
        assert_eq!(
            seen,
            vec![vec![(1, 0.25), (4, 0.75)], vec![(6, 0.25), (7, 0.75)]]
        );
        seen.clear();
        // At the corner P4: both of its vertices.
        target.readings(1, [0.0, 1.0, 0.0], |c| seen.push(c.to_vec()));
        assert_eq!(seen, vec![vec![(4, 1.0)], vec![(7, 1.0)]]);
        seen.clear();
        // Inside: the triangle's own corners only.
        target.readings(2, [0.5, 0.25, 0.25], |c| seen.push(c.to_vec()));
        assert_eq!(seen, vec![vec![(6, 0.5), (2, 0.25), (5, 0.25)]]);
        // With the left square gone, its vertices at P1 and P4 are no
        // readings there.
        let right = Mesh {
            triangles: m.triangles[2..].to_vec(),
            ..m.clone()
        };
        let target = Target::new(&right);
        seen.clear();
        target.readings(0, [1.0, 0.0, 0.0], |c| seen.push(c.to_vec()));
        assert_eq!(seen, vec![vec![(6, 1.0)]]);
    }

    #[test]
    fn shifted_properties_measure_the_shift() {
        let m = seam_strip();
        let mut o = m.clone();
        let p = &mut o.properties;
        for uv in p.uvs.as_mut().unwrap() {
            *uv += Vec2::new(0.1, 0.0);
        }
        // Tilted 30° about x.
        let tilt = 30f32.to_radians();
        p.normals = Some(vec![Vec3::new(0.0, -tilt.sin(), tilt.cos()); 8]);
        for c in p.colors.as_mut().unwrap() {
            *c += Vec4::new(0.3, 0.0, -0.4, 0.0);
        }
        let e = property_error(&m, &o, 5000);
        close(e.uv, 0.1, 1e-6);
        close(e.normal_degrees, 30.0, 1e-4);
        close(e.color, 0.5, 1e-6);
    }

    #[test]
    fn a_stream_counts_only_when_both_have_it() {
        let m = seam_strip();
        let mut o = m.clone();
        o.properties.normals = None;
        let e = property_error(&m, &o, 100);
        assert!(e.normal_degrees.is_none());
        close(e.uv, 0.0, 1e-6);
        // Zero normals are no normals: nothing to compare.
        let mut z = m.clone();
        z.properties.normals = Some(vec![Vec3::ZERO; 8]);
        assert!(property_error(&m, &z, 100).normal_degrees.is_none());
        let bare = Mesh {
            properties: Properties::default(),
            ..m.clone()
        };
        assert_eq!(property_error(&m, &bare, 100), PropertyError::default());
    }

    #[test]
    fn an_empty_surface_is_infinitely_wrong() {
        let m = seam_strip();
        let empty = Mesh {
            triangles: Vec::new(),
            ..m.clone()
        };
        let e = property_error(&m, &empty, 100);
        assert_eq!(e.uv.map(|s| s.max), Some(f64::INFINITY));
        assert_eq!(e.normal_degrees.map(|s| s.rms), Some(f64::INFINITY));
    }
}
