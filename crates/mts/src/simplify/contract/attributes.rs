//! Appearance in the cost: attribute quadrics (Hoppe, "New quadric metric
//! for simplifying meshes with appearance attributes", 1999) per vertex of
//! a mesh with properties, so that a contraction that distorts texture
//! coordinates, normals or colours costs what it distorts.
//!
//! Each triangle defines, per property channel `s` (u, v, nx, ny, nz, r,
//! g, b, a), the linear function `s(p) = g·p + d` that interpolates its
//! corners' values over its plane. A vertex accumulates, over the input
//! triangles it is a corner of (weighted by `sqrt(area)`, as the face
//! planes are), `Σ w (g·p + d - s)²` as a quadric in `(p, s)`. Moving
//! vertex `wa` onto `wb` costs the mean of that sum at `wb`'s position and
//! values: the squared difference between the properties `wa`'s old
//! triangles showed there and what `wb` carries. Quadrics add when
//! vertices merge, like the face quadrics.
//!
//! **Scale**: channel values are multiplied by [`AttributeWeights`] times
//! the bounding-box diagonal, so an attribute error of `1 / weight` counts
//! as much as a geometric error of one diagonal; the cost stays a squared
//! length and adds to the geometric one. The recorded error (the LoD's
//! geometric error) leaves it out.

use super::*;
use crate::mesh::Properties;
use crate::simplify::AttributeWeights;

/// Vertices of a point that [`Attributes::cost`] looks at, on each
/// side (real meshes have at most a handful per point).
const MOST_VERTICES: usize = 16;

/// Channels at most: 2 texture coordinates, 3 normal, 4 colour.
const MAX_CHANNELS: usize = 9;

/// A property stream a channel reads a component of.
#[derive(Debug, Clone, Copy)]
enum Stream {
    Uv,
    Normal,
    Color,
}

/// The channels of `p` with a positive weight: `(stream, component,
/// scale)`, texture coordinates first, then normals, then colours.
fn layout(p: &Properties, weights: AttributeWeights, diagonal: f64) -> Vec<(Stream, usize, f64)> {
    let mut out = Vec::new();
    for (present, w, stream, n) in [
        (p.uvs.is_some(), weights.uv, Stream::Uv, 2),
        (p.normals.is_some(), weights.normal, Stream::Normal, 3),
        (p.colors.is_some(), weights.color, Stream::Color, 4),
    ] {
        if present && w > 0.0 {
            let scale = f64::from(w) * diagonal;
            out.extend((0..n).map(|c| (stream, c, scale)));
        }
    }
    out
}

/// The scaled value of `channel` at vertex `v` of `p`.
fn value(p: &Properties, v: usize, (stream, c, scale): (Stream, usize, f64)) -> f64 {
    let x = match stream {
        Stream::Uv => p.uvs.as_ref().map(|s| s[v].to_array()[c]),
        Stream::Normal => p.normals.as_ref().map(|s| s[v].to_array()[c]),
        Stream::Color => p.colors.as_ref().map(|s| s[v].to_array()[c]),
    };
    scale * f64::from(x.expect("the layout names present streams"))
}

/// One channel's quadric: `Σ w (g·p + d - s)²` expanded.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Channel {
    /// `Σ w g gᵀ` (upper triangle: xx, xy, xz, yy, yz, zz).
    gg: [f64; 6],
    /// `Σ w g d`.
    gd: DVec3,
    /// `Σ w d²`.
    dd: f64,
    /// `Σ w g`.
    g: DVec3,
    /// `Σ w d`.
    d: f64,
}

impl Channel {
    fn add_plane(&mut self, g: DVec3, d: f64, w: f64) {
        let gg = [
            g.x * g.x,
            g.x * g.y,
            g.x * g.z,
            g.y * g.y,
            g.y * g.z,
            g.z * g.z,
        ];
        for (a, b) in self.gg.iter_mut().zip(gg) {
            *a += w * b;
        }
        self.gd += w * d * g;
        self.dd += w * d * d;
        self.g += w * g;
        self.d += w * d;
    }

    fn add(&mut self, o: &Channel) {
        for (a, b) in self.gg.iter_mut().zip(o.gg) {
            *a += b;
        }
        self.gd += o.gd;
        self.dd += o.dd;
        self.g += o.g;
        self.d += o.d;
    }

    /// `Σ w (g·p + d - s)²` for total weight `w`.
    fn evaluate(&self, p: DVec3, s: f64, w: f64) -> f64 {
        let m = &self.gg;
        let pgp = m[0] * p.x * p.x
            + m[3] * p.y * p.y
            + m[5] * p.z * p.z
            + 2.0 * (m[1] * p.x * p.y + m[2] * p.x * p.z + m[4] * p.y * p.z);
        pgp + 2.0 * p.dot(self.gd) + self.dd - 2.0 * s * (self.g.dot(p) + self.d) + s * s * w
    }
}

/// The attribute quadrics of every vertex of a mesh with properties, the
/// scaled property values, and each point's vertices.
pub(super) struct Attributes {
    /// Channels per vertex.
    k: usize,
    /// What each channel reads, and its scale.
    layout: Vec<(Stream, usize, f64)>,
    /// `k` scaled values per vertex.
    values: Vec<f64>,
    /// Per vertex, the part of its channels' quadrics that does not depend
    /// on the target's values, summed over the channels (`gg`, `gd`, `dd`;
    /// its `g` and `d` unused).
    shared: Vec<Channel>,
    /// Per vertex and channel, `(Σ w g, Σ w d)`: the part that meets the
    /// target's value.
    linear: Vec<(DVec3, f64)>,
    /// Per vertex, the sum of its scaled values' squares.
    squares: Vec<f64>,
    /// Triangle weight per vertex.
    weight: Vec<f64>,
    /// Vertices of each point: `point_vertices[point_start[p]..point_start[p + 1]]`.
    point_start: Vec<u32>,
    point_vertices: Vec<u32>,
}

impl Attributes {
    /// The quadrics of `mesh`'s vertices (over its own triangles, which
    /// index vertices) with `ids` the point of each vertex; `None` when
    /// the mesh has no property stream or every weight is zero.
    pub(super) fn new(
        mesh: &Mesh,
        ids: &[u32],
        points: usize,
        weights: AttributeWeights,
        diagonal: f64,
    ) -> Option<Attributes> {
        let n = mesh.vertex_count();
        let layout = layout(&mesh.properties, weights, diagonal);
        let k = layout.len();
        if k == 0 {
            return None;
        }
        let mut values = vec![0.0; n * k];
        for v in 0..n {
            for (c, &channel) in layout.iter().enumerate() {
                values[v * k + c] = value(&mesh.properties, v, channel);
            }
        }
        let mut channels = vec![Channel::default(); n * k];
        let mut weight = vec![0.0; n];
        for t in &mesh.triangles {
            let [p0, p1, p2] = t.map(|v| mesh.positions[v as usize].as_dvec3());
            let (e1, e2) = (p1 - p0, p2 - p0);
            let area2 = e1.cross(e2).length();
            let (a, b, c) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
            let det = a * c - b * b;
            if area2 <= 0.0 || det <= 0.0 || !det.is_finite() {
                continue;
            }
            let w = (0.5 * area2).sqrt();
            for ch in 0..k {
                let s = t.map(|v| values[v as usize * k + ch]);
                let (r1, r2) = (s[1] - s[0], s[2] - s[0]);
                // g in the plane with g·e1 = r1 and g·e2 = r2.
                let alpha = (c * r1 - b * r2) / det;
                let beta = (a * r2 - b * r1) / det;
                let g = alpha * e1 + beta * e2;
                let d = s[0] - g.dot(p0);
                for &v in t {
                    channels[v as usize * k + ch].add_plane(g, d, w);
                }
            }
            for &v in t {
                weight[v as usize] += w;
            }
        }
        let mut point_start = vec![0u32; points + 1];
        for &id in ids {
            point_start[id as usize + 1] += 1;
        }
        for i in 0..points {
            point_start[i + 1] += point_start[i];
        }
        let mut fill = point_start.clone();
        let mut point_vertices = vec![0u32; n];
        for (v, &id) in ids.iter().enumerate() {
            point_vertices[fill[id as usize] as usize] = v as u32;
            fill[id as usize] += 1;
        }
        // Summed over the channels, `Σ_c Σ w (g_c·p + d_c - s_c)²` is one
        // quadric in `p` plus `-2 Σ_c s_c (G_c·p + D_c) + w Σ_c s_c²`: the
        // cost then needs one quadric and `k` dot products per vertex, and
        // `k` products per target (a third of the work of `k` quadrics).
        let mut shared = vec![Channel::default(); n];
        let mut linear = Vec::with_capacity(n * k);
        for v in 0..n {
            for c in &channels[v * k..(v + 1) * k] {
                shared[v].add(&Channel {
                    g: DVec3::ZERO,
                    d: 0.0,
                    ..*c
                });
                linear.push((c.g, c.d));
            }
        }
        let squares = (0..n)
            .map(|v| values[v * k..(v + 1) * k].iter().map(|x| x * x).sum())
            .collect();
        Some(Attributes {
            k,
            layout,
            values,
            shared,
            linear,
            squares,
            weight,
            point_start,
            point_vertices,
        })
    }

    fn vertices_of(&self, point: u32) -> &[u32] {
        let p = point as usize;
        &self.point_vertices[self.point_start[p] as usize..self.point_start[p + 1] as usize]
    }

    /// The appearance cost of moving point `a` onto point `b` at `p`: the
    /// mean, over the triangles of `a`'s vertices, of each vertex's error
    /// at the vertex of `b` it fits best (the seam guard later fixes the
    /// pairing; the best fit is its usual outcome and a cheap estimate).
    ///
    /// `a` and `b` are live points, whose vertices are all live: a vertex
    /// is only merged away with its point. Each side counts at most
    /// [`MOST_VERTICES`] vertices, so that a
    /// point split into thousands (a hostile file: every corner of one
    /// position with its own texture coordinate) costs a bounded time per
    /// evaluation instead of the square of its count.
    pub(super) fn cost(&self, a: u32, b: u32, p: DVec3) -> f64 {
        let (mut sum, mut weight) = (0.0, 0.0);
        let live = |point: u32| self.vertices_of(point).iter().copied().take(MOST_VERTICES);
        let k = self.k;
        let mut at = [0.0f64; MAX_CHANNELS];
        for wa in live(a) {
            let w = self.weight[wa as usize];
            if w == 0.0 {
                continue;
            }
            // `wa`'s own part at `p`, then each target's values against it.
            let own = self.shared[wa as usize].evaluate(p, 0.0, 0.0);
            for (t, &(g, d)) in at
                .iter_mut()
                .zip(&self.linear[wa as usize * k..(wa as usize + 1) * k])
            {
                *t = g.dot(p) + d;
            }
            let best = live(b)
                .map(|wb| {
                    let s = &self.values[wb as usize * k..(wb as usize + 1) * k];
                    let cross: f64 = s.iter().zip(&at).map(|(s, t)| s * t).sum();
                    (own - 2.0 * cross + w * self.squares[wb as usize]).max(0.0)
                })
                .fold(f64::INFINITY, f64::min);
            if best.is_finite() {
                sum += best;
                weight += self.weight[wa as usize];
            }
        }
        if weight > 0.0 {
            sum / weight
        } else {
            0.0
        }
    }

    /// [`Attributes::cost`] for optimal placement, where `a` and `b` both
    /// move to `p` and each pair's created vertex takes the values `t` of
    /// the way from its `a` side to its `b` side (`created.rs`): the mean,
    /// over the triangles of both vertices of each pair, of their error
    /// there, each vertex of `a` paired with the vertex of `b` that costs
    /// least (the seam guard later fixes the pairing). Bounded as
    /// [`Attributes::cost`] is.
    pub(super) fn cost_between(&self, a: u32, b: u32, p: DVec3, t: f64) -> f64 {
        let (mut sum, mut weight) = (0.0, 0.0);
        let live = |point: u32| self.vertices_of(point).iter().copied().take(MOST_VERTICES);
        let k = self.k;
        let at = |v: u32, out: &mut [f64; MAX_CHANNELS]| {
            for (o, &(g, d)) in out
                .iter_mut()
                .zip(&self.linear[v as usize * k..(v as usize + 1) * k])
            {
                *o = g.dot(p) + d;
            }
            self.shared[v as usize].evaluate(p, 0.0, 0.0)
        };
        let (mut at_a, mut at_b) = ([0.0f64; MAX_CHANNELS], [0.0f64; MAX_CHANNELS]);
        for wa in live(a) {
            let own_a = at(wa, &mut at_a);
            let sa = &self.values[wa as usize * k..(wa as usize + 1) * k];
            let best = live(b)
                .map(|wb| {
                    let own_b = at(wb, &mut at_b);
                    let sb = &self.values[wb as usize * k..(wb as usize + 1) * k];
                    let (mut cross, mut squares) = (0.0, 0.0);
                    for c in 0..k {
                        let s = sa[c] + t * (sb[c] - sa[c]);
                        cross += s * (at_a[c] + at_b[c]);
                        squares += s * s;
                    }
                    let w = self.weight[wa as usize] + self.weight[wb as usize];
                    ((own_a + own_b - 2.0 * cross + w * squares).max(0.0), w)
                })
                .fold((f64::INFINITY, 0.0), |x, y| if y.0 < x.0 { y } else { x });
            if best.0.is_finite() {
                sum += best.0;
                weight += best.1;
            }
        }
        if weight > 0.0 {
            sum / weight
        } else {
            0.0
        }
    }

    /// A point created by optimal placement, after the last one, whose
    /// vertices are `vertices` (created by [`Attributes::create`]).
    pub(super) fn push_point(&mut self, vertices: impl IntoIterator<Item = u32>) {
        self.point_vertices.extend(vertices);
        self.point_start.push(self.point_vertices.len() as u32);
    }

    /// Vertex `c` (the next one) created for the pair `wa`, `wb`, with its
    /// values read from `properties`: both quadrics join in its own.
    pub(super) fn create(&mut self, c: u32, wa: u32, wb: u32, properties: &Properties) {
        let k = self.k;
        assert_eq!(self.values.len(), c as usize * k, "created out of order");
        for &channel in &self.layout {
            self.values.push(value(properties, c as usize, channel));
        }
        let values = &self.values[c as usize * k..];
        self.squares.push(values.iter().map(|x| x * x).sum());
        let mut shared = self.shared[wa as usize];
        shared.add(&self.shared[wb as usize]);
        self.shared.push(shared);
        for ch in 0..k {
            let (ga, da) = self.linear[wa as usize * k + ch];
            let (gb, db) = self.linear[wb as usize * k + ch];
            self.linear.push((ga + gb, da + db));
        }
        self.weight
            .push(self.weight[wa as usize] + self.weight[wb as usize]);
    }

    /// Vertex `wa` moved onto `wb`: its quadric joins `wb`'s.
    pub(super) fn merge(&mut self, wa: u32, wb: u32) {
        let k = self.k;
        let from = self.shared[wa as usize];
        self.shared[wb as usize].add(&from);
        for c in 0..k {
            let (g, d) = self.linear[wa as usize * k + c];
            let to = &mut self.linear[wb as usize * k + c];
            to.0 += g;
            to.1 += d;
        }
        self.weight[wb as usize] += self.weight[wa as usize];
    }
}
