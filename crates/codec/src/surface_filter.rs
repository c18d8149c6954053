//! The swing decoder's surface filter: a post-pass over the decoded mesh that moves each
//! interior vertex along its normal to cancel the chord bias of uniform retiling.
//!
//! Every swing vertex lies on the original surface, so on a convex patch every flat
//! triangle between them lies inside it (and outside on a concave one): the error has a
//! mean, not only a spread. For a sphere of radius `R` sampled at edge length `L` the mean
//! depth of a triangle below the surface is about `L²/(8R)`, while the normal component of
//! a vertex's umbrella Laplacian is about `L²/(2R)`: moving the vertex out by a quarter of
//! that component cancels the bias. The encoder fits the factors by least squares against
//! the original (whet-swing) and writes them in the header; the decoder runs this very code
//! on its decoded mesh, so the output is still bit-exact between the two (docs/swing.md
//! section 2, "Surface filter").
//!
//! Two displacement fields are combined, both along the area-weighted vertex normal `n`:
//! `d(v) n`, where `d(v) = −n · (mean of the neighbours − v)` is the normal component of the
//! umbrella Laplacian (positive on convex parts), and `s(v) n`, where `s(v)` is the mean of
//! `d` over `v` and its neighbours. The first also carries the angle quantization's noise;
//! the smoothed one carries mostly the curvature, so their least-squares mix both restores
//! the bulge and damps the noise. Boundary vertices (open fans) and vertices without a
//! normal are not moved and contribute `d = 0`.
//!
//! The extended filter (format 1.4) adds three fields: `s2`, the one-ring mean of `s`;
//! `q = d |d| / L`; and `t`, the tangential part of the umbrella Laplacian, which slides
//! vertices along the surface towards an even spread (docs/swing.md section 2, "Extended
//! surface filter").

use whet_mesh::{DVec3, Mesh};

/// Units of a coded factor: the header stores `round(factor · SCALE)`.
pub const SCALE: f64 = 1024.0;

/// Largest coded factor magnitude (`±4.0`), checked by the decoder.
pub const MAX_CODED: i64 = 4 * 1024;

/// The coded factors of the filter, in units of `1 / SCALE`; all zero: no filter. The last
/// three make the extended filter (format 1.4, header fields 34, 36 and 38); with them zero
/// the filter is the two-field one of format 1.1, computed exactly as before.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SurfaceFilter {
    /// Factor of the vertex's own normal Laplacian `d(v)`.
    pub normal: i64,
    /// Factor of the one-ring mean `s(v)` of the normal Laplacian.
    pub smoothed: i64,
    /// Factor of `s2(v)`, the one-ring mean of `s` (extended filter).
    pub smoothed2: i64,
    /// Factor of `q(v) = d(v) |d(v)| / L` (extended filter).
    pub quadratic: i64,
    /// Factor of `t(v)`, the tangential part of the umbrella Laplacian, a vector (extended
    /// filter).
    pub tangential: i64,
}

impl SurfaceFilter {
    /// No filter.
    pub const NONE: SurfaceFilter = SurfaceFilter {
        normal: 0,
        smoothed: 0,
        smoothed2: 0,
        quadratic: 0,
        tangential: 0,
    };

    /// The coded form of real factors: rounded, and clamped to the range the decoder
    /// accepts (non-finite factors give no filter).
    pub fn from_factors(normal: f64, smoothed: f64) -> SurfaceFilter {
        SurfaceFilter::from_extended_factors([normal, smoothed, 0.0, 0.0, 0.0])
    }

    /// The coded form of the five real factors of the extended filter, in the order of
    /// [`Self::extended_factors`].
    pub fn from_extended_factors(f: [f64; 5]) -> SurfaceFilter {
        let [normal, smoothed, smoothed2, quadratic, tangential] = f.map(code_factor);
        SurfaceFilter {
            normal,
            smoothed,
            smoothed2,
            quadratic,
            tangential,
        }
    }

    /// True when the filter moves nothing.
    pub fn is_none(&self) -> bool {
        self.normal == 0 && self.smoothed == 0 && !self.is_extended()
    }

    /// True when a factor of the extended filter (format 1.4) is not zero.
    pub fn is_extended(&self) -> bool {
        self.smoothed2 != 0 || self.quadratic != 0 || self.tangential != 0
    }

    /// Every coded factor lies within `±MAX_CODED` (what a decoder accepts).
    pub fn in_range(&self) -> bool {
        self.coded()
            .iter()
            .all(|c| (-MAX_CODED..=MAX_CODED).contains(c))
    }

    /// The five coded factors: `d`, `s`, `s2`, `q`, `t`.
    pub fn coded(&self) -> [i64; 5] {
        [
            self.normal,
            self.smoothed,
            self.smoothed2,
            self.quadratic,
            self.tangential,
        ]
    }

    /// The five factors as reals, in the order `d`, `s`, `s2`, `q`, `t`.
    pub fn extended_factors(&self) -> [f64; 5] {
        self.coded().map(|c| c as f64 / SCALE)
    }

    /// The factors as reals.
    pub fn factors(&self) -> (f64, f64) {
        (self.normal as f64 / SCALE, self.smoothed as f64 / SCALE)
    }

    /// Moves the vertices of `mesh`, a swing stream's decoded mesh at edge length
    /// `edge_length`, by the filter (nothing when it is [`Self::NONE`]).
    pub fn apply(&self, mesh: &mut Mesh, edge_length: f64) {
        if self.is_none() {
            return;
        }
        let normals = unit_normals(&mesh.positions, &mesh.triangles);
        self.apply_with_normals(mesh, normals, Given::default(), edge_length);
    }

    /// [`Self::apply`] on a closed mesh (every fan closed) whose per-vertex sums the walk
    /// that rebuilt it gathered as it added the triangles (`sums`; the walk keeps the cross
    /// products for its prediction). The walk sums the same products in the same triangle
    /// order, but its arithmetic is its own code: encoder and decoder pick the same entry
    /// point by rule (docs/swing.md section 2), so the two never need to agree to the bit.
    /// The triangle counts and next-corner sums, when given, are the very sums this filter
    /// makes (integer counts; vector adds in triangle order), so they change no bit.
    pub(crate) fn apply_closed(&self, mesh: &mut Mesh, sums: WalkSums, edge_length: f64) {
        if self.is_none() {
            return;
        }
        let WalkSums {
            fan: mut fan_sums,
            triangles_at,
            next_corners,
        } = sums;
        fan_sums.resize(mesh.positions.len(), DVec3::ZERO);
        for n in &mut fan_sums {
            let len = n.length();
            *n = if len.is_normal() {
                *n / len
            } else {
                DVec3::ZERO
            };
        }
        self.apply_with_normals(
            mesh,
            fan_sums,
            Given {
                triangles_at,
                next_corners,
            },
            edge_length,
        );
    }

    fn apply_with_normals(
        &self,
        mesh: &mut Mesh,
        normals: Vec<DVec3>,
        given: Given,
        edge_length: f64,
    ) {
        if !self.is_extended() {
            // The two-field filter of format 1.1, to the bit as it always was.
            let (a, b) = self.factors();
            let x = fields(&mesh.positions, &mesh.triangles, &normals, false, given);
            let (d, s) = (x.d, x.s);
            for (((p, n), d), s) in mesh.positions.iter_mut().zip(&normals).zip(&d).zip(&s) {
                // Finite in, finite out: sums of huge coordinates may overflow, and such a
                // vertex then stays where it is (on both sides alike).
                let moved = *p + (a * d + b * s) * *n;
                if moved.is_finite() {
                    *p = moved;
                }
            }
            return;
        }
        self.apply_extended(mesh, &normals, given, edge_length);
    }

    /// The extended filter's move (docs/format.md, tags 34 to 38): per vertex with a nonzero
    /// normal, `p ← (p + along · n) + f · t` with `along = ((a d + b s) + c s2) + e q`, kept
    /// only when all three coordinates are finite.
    fn apply_extended(&self, mesh: &mut Mesh, normals: &[DVec3], given: Given, edge_length: f64) {
        let [a, b, c, e, f] = self.extended_factors();
        let x = fields(&mesh.positions, &mesh.triangles, normals, true, given);
        // `s2` is divided here, vertex by vertex, as `one_ring_mean` would (one pass less).
        let s2_sums = one_ring_sums(&mesh.triangles, &x.s, &x.k);
        for (v, p) in mesh.positions.iter_mut().enumerate().take(s2_sums.len()) {
            let n = normals[v];
            if n == DVec3::ZERO {
                // Boundary vertices and vanishing normals stay put, as in the two-field
                // filter.
                continue;
            }
            let d = x.d[v];
            let s2 = ring_mean(s2_sums[v], x.k[v]);
            let along = a * d + b * x.s[v] + c * s2 + e * quadratic_field(d, edge_length);
            let t = tangential_field(x.next_sum[v], x.k[v], *p, n, d);
            let moved = (*p + along * n) + f * t;
            if moved.is_finite() {
                *p = moved;
            }
        }
    }
}

/// A real factor in units of `1 / SCALE`, rounded and clamped to what a decoder accepts
/// (0 when not finite).
fn code_factor(x: f64) -> i64 {
    if x.is_finite() {
        ((x * SCALE).round() as i64).clamp(-MAX_CODED, MAX_CODED)
    } else {
        0
    }
}

/// Which vertices of `sharpened` (EdgeSharpener's output from `raw`) the filter may still
/// move after sharpening: those of `raw` that kept their position bit for bit and share
/// no triangle with a moved or new vertex. Around the sharpened features nothing moves, so
/// the planes the sharpener extrapolated stay put.
pub fn untouched_by_sharpening(raw: &Mesh, sharpened: &Mesh) -> Vec<bool> {
    let n0 = raw.positions.len();
    let n = sharpened.positions.len();
    let moved: Vec<bool> = (0..n)
        .map(|v| {
            v >= n0
                || raw.positions[v].to_array().map(f64::to_bits)
                    != sharpened.positions[v].to_array().map(f64::to_bits)
        })
        .collect();
    let mut free: Vec<bool> = moved.iter().map(|&m| !m).collect();
    for t in &sharpened.triangles {
        let Some(c) = corners(t, n) else {
            continue;
        };
        if c.iter().any(|&v| moved[v]) {
            for v in c {
                free[v] = false;
            }
        }
    }
    free
}

impl SurfaceFilter {
    /// Moves the vertices of `sharpened` (EdgeSharpener's output from the unfiltered decoded
    /// mesh `raw`) that the sharpener left alone ([`untouched_by_sharpening`]) by the
    /// filter's fields of `raw`: the surface filter of the smooth parts, with the factors
    /// the encoder fitted on its own sharpened output (header fields 17 and 19). Nothing
    /// moves when it is [`Self::NONE`].
    pub fn apply_after_sharpening(&self, raw: &Mesh, sharpened: &mut Mesh) {
        if self.is_none() {
            return;
        }
        let (a, b) = self.factors();
        let fields = FilterFields::new(raw).after_sharpening(raw, sharpened);
        for ((p, d), s) in sharpened
            .positions
            .iter_mut()
            .zip(&fields.normal)
            .zip(&fields.smoothed)
        {
            let moved = *p + a * *d + b * *s;
            if moved.is_finite() {
                *p = moved;
            }
        }
    }

    /// The filter a swing stream's header states (fields 14, 16, 34, 36 and 38; an absent
    /// field is 0), as coded: the caller checks [`Self::in_range`].
    pub fn of_header(header: &whet_format::Header) -> SurfaceFilter {
        let get = |t| header.get_i64(t).unwrap_or(0);
        SurfaceFilter {
            normal: get(whet_format::tag::FILTER_NORMAL),
            smoothed: get(whet_format::tag::FILTER_SMOOTHED),
            smoothed2: get(whet_format::tag::FILTER_SMOOTHED2),
            quadratic: get(whet_format::tag::FILTER_QUADRATIC),
            tangential: get(whet_format::tag::FILTER_TANGENTIAL),
        }
    }

    /// The filter a swing stream's header gives for after sharpening (fields 17 and 19);
    /// [`Self::NONE`] for other streams, without the fields, or with a factor out of
    /// range.
    pub fn after_sharpening_of(header: &whet_format::Header) -> SurfaceFilter {
        let get = |t| header.get_i64(t).unwrap_or(0);
        let f = SurfaceFilter {
            normal: get(whet_format::tag::SHARPENED_FILTER_NORMAL),
            smoothed: get(whet_format::tag::SHARPENED_FILTER_SMOOTHED),
            ..SurfaceFilter::NONE
        };
        let coded = -MAX_CODED..=MAX_CODED;
        if header.mode != whet_format::Mode::Swing
            || !coded.contains(&f.normal)
            || !coded.contains(&f.smoothed)
        {
            return SurfaceFilter::NONE;
        }
        f
    }
}

/// The two displacement fields of a mesh (per vertex, along its normal), before any factor:
/// what the encoder fits the factors on (computed as [`SurfaceFilter::apply`] does).
#[derive(Clone, Debug)]
pub struct FilterFields {
    /// `d(v) n(v)`.
    pub normal: Vec<DVec3>,
    /// `s(v) n(v)`.
    pub smoothed: Vec<DVec3>,
}

impl FilterFields {
    /// The fields of `mesh`.
    pub fn new(mesh: &Mesh) -> FilterFields {
        let normals = unit_normals(&mesh.positions, &mesh.triangles);
        let x = fields(
            &mesh.positions,
            &mesh.triangles,
            &normals,
            false,
            Given::default(),
        );
        let (d, s) = (x.d, x.s);
        FilterFields {
            normal: normals.iter().zip(&d).map(|(n, d)| *d * *n).collect(),
            smoothed: normals.iter().zip(&s).map(|(n, s)| *s * *n).collect(),
        }
    }

    /// These fields (of the unfiltered mesh `raw`) as the filter for after sharpening moves
    /// the vertices of `sharpened`, EdgeSharpener's output from `raw`: unchanged on the
    /// vertices [`untouched_by_sharpening`] finds, zero on the others and on new ones. The
    /// decoder applies them, the encoder fits its factors on them.
    pub fn after_sharpening(&self, raw: &Mesh, sharpened: &Mesh) -> FilterFields {
        let free = untouched_by_sharpening(raw, sharpened);
        let keep = |f: &[DVec3]| -> Vec<DVec3> {
            free.iter()
                .enumerate()
                .map(|(v, &free)| match f.get(v) {
                    Some(&x) if free => x,
                    _ => DVec3::ZERO,
                })
                .collect()
        };
        FilterFields {
            normal: keep(&self.normal),
            smoothed: keep(&self.smoothed),
        }
    }

    /// The fields of `mesh` (as [`Self::new`] computes them) and the extended filter's
    /// three, for a swing stream at edge length `edge_length`: `s2 n`, `q n` and `u` per
    /// vertex; the encoder fits the five factors on them.
    pub fn extended(mesh: &Mesh, edge_length: f64) -> (FilterFields, [Vec<DVec3>; 3]) {
        let normals = unit_normals(&mesh.positions, &mesh.triangles);
        let x = fields(
            &mesh.positions,
            &mesh.triangles,
            &normals,
            true,
            Given::default(),
        );
        let s2 = one_ring_mean(&mesh.triangles, &x.s, &x.k);
        let along =
            |f: &[f64]| -> Vec<DVec3> { normals.iter().zip(f).map(|(n, x)| *x * *n).collect() };
        let q: Vec<f64> =
            x.d.iter()
                .map(|&d| quadratic_field(d, edge_length))
                .collect();
        let u: Vec<DVec3> = (0..s2.len())
            .map(|v| tangential_field(x.next_sum[v], x.k[v], mesh.positions[v], normals[v], x.d[v]))
            .collect();
        (
            FilterFields {
                normal: along(&x.d),
                smoothed: along(&x.s),
            },
            [along(&s2), along(&q), u],
        )
    }

    /// `(d n, s n)` per vertex.
    pub fn displacements(&self) -> impl Iterator<Item = (DVec3, DVec3)> + '_ {
        self.normal
            .iter()
            .copied()
            .zip(self.smoothed.iter().copied())
    }
}

/// The triangle's corners as indices, when all are in range.
#[inline]
fn corners(t: &[u32; 3], n: usize) -> Option<[usize; 3]> {
    let c = t.map(|v| v as usize);
    (c[0] < n && c[1] < n && c[2] < n).then_some(c)
}

/// Unit area-weighted normal of every vertex with a closed fan; zero (the vertex does not
/// move) on open fans and where the normal vanishes. In a closed fan the next corners and
/// the previous corners are the same set of vertices, so the wrapping sum of `next − prev`
/// vanishes; in one open fan it is `last − first ≠ 0`.
fn unit_normals(pos: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let n = pos.len();
    let mut normals = vec![DVec3::ZERO; n];
    let mut open = vec![0u32; n];
    for t in triangles {
        let Some([i, j, k]) = corners(t, n) else {
            continue;
        };
        let c = (pos[j] - pos[i]).cross(pos[k] - pos[i]);
        for (v, next, prev) in [(i, t[1], t[2]), (j, t[2], t[0]), (k, t[0], t[1])] {
            normals[v] += c;
            open[v] = open[v].wrapping_add(next.wrapping_sub(prev));
        }
    }
    for (nv, open) in normals.iter_mut().zip(open) {
        let len = nv.length();
        *nv = if open == 0 && len.is_normal() {
            *nv / len
        } else {
            DVec3::ZERO
        };
    }
    normals
}

/// Per-vertex sums of a closed mesh that the swing walk gathered while it added the
/// triangles, in triangle order (docs/swing.md section 2): what the surface filter would
/// otherwise sum in a pass of its own.
#[derive(Clone, Debug, Default)]
pub(crate) struct WalkSums {
    /// The sum of the triangles' cross products `(p1 − p0) × (p2 − p0)`.
    pub(crate) fan: Vec<DVec3>,
    /// The triangles at the vertex (empty: the filter counts them).
    pub(crate) triangles_at: Vec<u32>,
    /// The sum of the next corners of the vertex's triangles, as vectors in triangle order
    /// (empty: the filter sums them).
    pub(crate) next_corners: Vec<DVec3>,
}

impl WalkSums {
    /// Only the cross products (the filter counts and sums the rest).
    pub(crate) fn of_fan(fan: Vec<DVec3>) -> WalkSums {
        WalkSums {
            fan,
            ..WalkSums::default()
        }
    }
}

/// Sums [`fields`] takes as given instead of making them (each used only at the mesh's
/// vertex count; otherwise made).
#[derive(Default)]
struct Given {
    triangles_at: Vec<u32>,
    next_corners: Vec<DVec3>,
}

/// The per-vertex sums the filters read.
struct Fields {
    /// `d(v) = −n · (mean of the neighbours − v) = n · (3k v − Σ corner sums) / 2k`, where the
    /// corner sum of a triangle is `p0 + p1 + p2` and `k` the triangles at `v`: an interior
    /// vertex meets each neighbour twice (0 where the normal is zero or `d` not finite).
    d: Vec<f64>,
    /// `s(v)`, the mean of `d` over `v` and its neighbours (each once, as the next corner of
    /// a triangle).
    s: Vec<f64>,
    /// Triangles at each vertex.
    k: Vec<u32>,
    /// Per vertex, the sum of the next corners of its triangles (the extended filter's
    /// umbrella Laplacian; empty unless asked for).
    next_sum: Vec<DVec3>,
}

/// `d`, `s` and the triangle counts of every vertex given its unit normal, and with
/// `umbrella` the sums of next corners too; all summed in triangle order in f64, so the
/// encoder and the decoder compute the same bits. Counts and next-corner sums in `given`
/// (the walk's, [`WalkSums`]) are used as they are, which leaves every bit the same.
fn fields(
    pos: &[DVec3],
    triangles: &[[u32; 3]],
    normals: &[DVec3],
    umbrella: bool,
    given: Given,
) -> Fields {
    let n = pos.len().min(normals.len());
    let mut d = vec![0.0f64; n];
    let count = given.triangles_at.len() != n;
    let mut k = if count {
        vec![0u32; n]
    } else {
        given.triangles_at
    };
    let sum_next = umbrella && given.next_corners.len() != n;
    let mut next_sum = if sum_next {
        vec![DVec3::ZERO; n]
    } else if umbrella {
        given.next_corners
    } else {
        Vec::new()
    };
    match (count, sum_next) {
        (true, true) => {
            corner_sums::<true, true>(pos, triangles, normals, &mut d, &mut k, &mut next_sum)
        }
        (true, false) => {
            corner_sums::<true, false>(pos, triangles, normals, &mut d, &mut k, &mut next_sum)
        }
        (false, true) => {
            corner_sums::<false, true>(pos, triangles, normals, &mut d, &mut k, &mut next_sum)
        }
        (false, false) => {
            corner_sums::<false, false>(pos, triangles, normals, &mut d, &mut k, &mut next_sum)
        }
    }
    for v in 0..n {
        let kv = k[v] as f64;
        let dv = (3.0 * kv * normals[v].dot(pos[v]) - d[v]) / (2.0 * kv);
        d[v] = if dv.is_finite() && normals[v] != DVec3::ZERO {
            dv
        } else {
            0.0
        };
    }
    let s = one_ring_mean(triangles, &d, &k);
    Fields { d, s, k, next_sum }
}

/// The triangle pass of [`fields`]: per corner `n · (p0 + p1 + p2)` into `d`, and with
/// `COUNT` and `NEXT` the triangle counts and next-corner sums (`d`, `k` and `next_sum` hold
/// `n` vertices, `normals` at least as many).
#[inline(always)]
fn corner_sums<const COUNT: bool, const NEXT: bool>(
    pos: &[DVec3],
    triangles: &[[u32; 3]],
    normals: &[DVec3],
    d: &mut [f64],
    k: &mut [u32],
    next_sum: &mut [DVec3],
) {
    let n = d.len();
    for t in triangles {
        let Some([i, j, l]) = corners(t, n) else {
            continue;
        };
        let sum = pos[i] + pos[j] + pos[l];
        for v in [i, j, l] {
            d[v] += normals[v].dot(sum);
            if COUNT {
                k[v] += 1;
            }
        }
        if NEXT {
            next_sum[i] += pos[j];
            next_sum[j] += pos[l];
            next_sum[l] += pos[i];
        }
    }
}

/// `(f(v) + Σ f(next corner)) / (1 + k)` per vertex, 0 where not finite: `s` of `d`, and
/// `s2` of `s`.
fn one_ring_mean(triangles: &[[u32; 3]], f: &[f64], k: &[u32]) -> Vec<f64> {
    let mut s = one_ring_sums(triangles, f, k);
    for (s, &k) in s.iter_mut().zip(k) {
        *s = ring_mean(*s, k);
    }
    s
}

/// `f(v) + Σ f(next corner)` per vertex, summed in triangle order (over the first
/// `min(f.len(), k.len())` vertices).
fn one_ring_sums(triangles: &[[u32; 3]], f: &[f64], k: &[u32]) -> Vec<f64> {
    let n = f.len().min(k.len());
    let mut s = f[..n].to_vec();
    for t in triangles {
        let Some([i, j, l]) = corners(t, n) else {
            continue;
        };
        s[i] += f[j];
        s[j] += f[l];
        s[l] += f[i];
    }
    s
}

/// A one-ring sum over `v` and the next corners of its `k` triangles divided by `1 + k`, 0
/// where not finite.
#[inline]
fn ring_mean(sum: f64, k: u32) -> f64 {
    let s = sum / (1 + k) as f64;
    if s.is_finite() {
        s
    } else {
        0.0
    }
}

/// `q(v) = d |d| / L`, 0 where not finite.
#[inline]
fn quadratic_field(d: f64, edge_length: f64) -> f64 {
    let q = d * d.abs() / edge_length;
    if q.is_finite() {
        q
    } else {
        0.0
    }
}

/// `t(v) = u + d n`, the tangential part of the umbrella Laplacian `u` (the mean of the next
/// corners minus `v`; on a closed fan `n · u = −d`, so `t` keeps what `d n` does not say);
/// zero where the normal is zero, without triangles, or not finite.
#[inline]
fn tangential_field(next_sum: DVec3, k: u32, p: DVec3, normal: DVec3, d: f64) -> DVec3 {
    let t = (next_sum / k as f64 - p) + d * normal;
    if k > 0 && normal != DVec3::ZERO && t.is_finite() {
        t
    } else {
        DVec3::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An octahedron: every vertex convex, closed fans.
    fn octahedron() -> Mesh {
        whet_testkit::meshes::octahedron()
    }

    #[test]
    fn convex_vertices_move_outwards() {
        let mut m = octahedron();
        let before = m.positions.clone();
        SurfaceFilter::from_factors(0.25, 0.0).apply(&mut m, 1.0);
        for (p, q) in m.positions.iter().zip(&before) {
            // d = 1 at every vertex (the neighbours' mean is the origin): moved out by 1/4.
            assert!((p.length() - 1.25).abs() < 1e-12, "{p:?}");
            assert!((p.normalize() - *q).length() < 1e-12);
        }
    }

    #[test]
    fn after_sharpening_only_vertices_away_from_the_sharpened_part_move() {
        let raw = whet_testkit::meshes::icosphere(2);
        let n0 = raw.positions.len();
        // A stand-in for EdgeSharpener's output: vertex 0 moved, a new vertex on a new
        // triangle with vertices 5 and 6 (the sharpener appends what it adds).
        let mut sharp = raw.clone();
        sharp.positions[0] *= 1.01;
        sharp.positions.push(DVec3::new(0.0, 0.0, 2.0));
        sharp.triangles.push([5, 6, n0 as u32]);
        let free = untouched_by_sharpening(&raw, &sharp);
        assert!(!free[0] && !free[5] && !free[6] && !free[n0]);
        let ring_of_0: Vec<u32> = raw
            .triangles
            .iter()
            .filter(|t| t.contains(&0))
            .flatten()
            .copied()
            .collect();
        for v in 0..n0 {
            let expected = !(ring_of_0.contains(&(v as u32)) || v == 5 || v == 6);
            assert_eq!(free[v], expected, "vertex {v}");
        }
        let filter = SurfaceFilter::from_factors(0.25, 0.0);
        let mut out = sharp.clone();
        filter.apply_after_sharpening(&raw, &mut out);
        let mut expected = raw.clone();
        filter.apply(&mut expected, 1.0);
        for v in 0..out.positions.len() {
            if free[v] {
                // The fields are the unfiltered mesh's: exactly what the filter does there.
                assert!((out.positions[v] - expected.positions[v]).length() < 1e-12);
            } else {
                assert_eq!(out.positions[v], sharp.positions[v], "vertex {v}");
            }
        }
        // No filter, no move; an exact or unfiltered stream's header gives none.
        let mut same = sharp.clone();
        SurfaceFilter::NONE.apply_after_sharpening(&raw, &mut same);
        assert_eq!(same, sharp);
        let header = whet_format::Header::new(whet_format::Mode::Exact, 0, 0)
            .with(whet_format::tag::SHARPENED_FILTER_NORMAL, 100i64);
        assert!(SurfaceFilter::after_sharpening_of(&header).is_none());
        let header = whet_format::Header::new(whet_format::Mode::Swing, 0, 0)
            .with(whet_format::tag::SHARPENED_FILTER_NORMAL, MAX_CODED + 1);
        assert!(SurfaceFilter::after_sharpening_of(&header).is_none());
        let header = whet_format::Header::new(whet_format::Mode::Swing, 0, 0)
            .with(whet_format::tag::SHARPENED_FILTER_SMOOTHED, -7i64);
        assert_eq!(
            SurfaceFilter::after_sharpening_of(&header),
            SurfaceFilter {
                smoothed: -7,
                ..SurfaceFilter::NONE
            }
        );
    }

    #[test]
    fn smoothed_field_of_a_uniform_field_is_the_same() {
        let f = FilterFields::new(&octahedron());
        for (d, s) in f.displacements() {
            assert!((d - s).length() < 1e-12);
        }
    }

    #[test]
    fn boundary_vertices_stay_and_no_filter_moves_nothing() {
        // The octahedron without its last face: vertices 0, 3 and 5 are on the boundary.
        let mut m = octahedron();
        m.triangles.pop();
        let before = m.positions.clone();
        SurfaceFilter::NONE.apply(&mut m, 1.0);
        assert_eq!(m.positions, before);
        SurfaceFilter::from_factors(0.3, 0.2).apply(&mut m, 1.0);
        for v in [0usize, 3, 5] {
            assert_eq!(m.positions[v], before[v], "boundary vertex {v} moved");
        }
        assert_ne!(m.positions[4], before[4]);
    }

    #[test]
    fn huge_coordinates_never_give_non_finite_positions() {
        let mut m = octahedron();
        for p in &mut m.positions {
            *p *= 1e307;
        }
        SurfaceFilter::from_factors(4.0, 4.0).apply(&mut m, 1.0);
        assert!(m.positions.iter().all(|p| p.is_finite()));
    }

    #[test]
    fn coded_factors_are_rounded_and_clamped() {
        let f = SurfaceFilter::from_factors(0.2501, -100.0);
        assert_eq!(f.normal, 256);
        assert_eq!(f.smoothed, -MAX_CODED);
        assert_eq!(
            SurfaceFilter::from_factors(f64::NAN, 0.0),
            SurfaceFilter::NONE
        );
    }

    #[test]
    fn an_extended_filter_with_its_three_factors_zero_is_the_two_field_filter() {
        // A lopsided octahedron, so that no field vanishes by symmetry.
        let mut two = octahedron();
        two.positions[4] = DVec3::new(0.2, -0.1, 1.3);
        two.positions[1] = DVec3::new(0.1, 0.8, 0.05);
        let mut five = two.clone();
        let f = SurfaceFilter::from_factors(0.3, -0.2);
        assert!(!f.is_extended());
        f.apply(&mut two, 1.0);
        // The extended move with zero extended factors, run directly (the filter never
        // takes it: is_extended is false), lands on the same positions.
        let normals = unit_normals(&five.positions, &five.triangles);
        f.apply_extended(&mut five, &normals, Given::default(), 1.0);
        assert_eq!(two.positions, five.positions);
        assert_eq!(
            SurfaceFilter::from_extended_factors([0.3, -0.2, 0.0, 0.0, 0.0]),
            f
        );
    }

    #[test]
    fn a_walks_counts_and_next_corner_sums_change_no_bit() {
        // What the swing walk hands over (cross products, triangle counts, next-corner sums,
        // gathered in triangle order) against the filter counting and summing them itself.
        let mut m = octahedron();
        m.positions[4] = DVec3::new(0.2, -0.1, 1.3);
        m.positions[1] = DVec3::new(0.1, 0.8, 0.05);
        let n = m.positions.len();
        let mut sums = WalkSums {
            fan: vec![DVec3::ZERO; n],
            triangles_at: vec![0; n],
            next_corners: vec![DVec3::ZERO; n],
        };
        for t in &m.triangles {
            let [i, j, k] = t.map(|v| v as usize);
            let p = [m.positions[i], m.positions[j], m.positions[k]];
            let c = (p[1] - p[0]).cross(p[2] - p[0]);
            for (v, next) in [(i, p[1]), (j, p[2]), (k, p[0])] {
                sums.fan[v] += c;
                sums.triangles_at[v] += 1;
                sums.next_corners[v] += next;
            }
        }
        for f in [
            SurfaceFilter::from_factors(0.3, -0.2),
            SurfaceFilter::from_extended_factors([0.3, -0.2, 0.15, 0.4, -0.35]),
        ] {
            let (mut given, mut counted) = (m.clone(), m.clone());
            f.apply_closed(&mut given, sums.clone(), 1.0);
            f.apply_closed(&mut counted, WalkSums::of_fan(sums.fan.clone()), 1.0);
            let bits = |m: &Mesh| -> Vec<[u64; 3]> {
                m.positions
                    .iter()
                    .map(|p| p.to_array().map(f64::to_bits))
                    .collect()
            };
            assert_eq!(bits(&given), bits(&counted));
            assert_ne!(given.positions, m.positions, "the filter moved nothing");
        }
    }

    #[test]
    fn the_extended_fields_move_as_defined() {
        // The octahedron: every vertex has 4 triangles, d = 1 (the neighbours' mean is the
        // origin), s = s2 = 1, q = d |d| / L = 1 / L, and the umbrella Laplacian −v is all
        // normal: no tangential part.
        let m = octahedron();
        for (field, factor, along) in [(2usize, 0.25, 0.25), (3, 0.25, 0.25 / 2.0), (4, 0.25, 0.0)]
        {
            let mut f = [0.0; 5];
            f[field] = factor;
            let filter = SurfaceFilter::from_extended_factors(f);
            assert!(filter.is_extended());
            let mut moved = m.clone();
            filter.apply(&mut moved, 2.0);
            for (p, q) in moved.positions.iter().zip(&m.positions) {
                assert!(
                    (*p - (*q + along * *q)).length() < 1e-12,
                    "field {field}: {q:?} went to {p:?}"
                );
            }
        }
        // The encoder's fields are the ones applied.
        let (two, [s2, q, t]) = FilterFields::extended(&m, 2.0);
        let plain = FilterFields::new(&m);
        assert_eq!(two.normal, plain.normal);
        assert_eq!(two.smoothed, plain.smoothed);
        for (v, p) in m.positions.iter().enumerate() {
            assert!((s2[v] - *p).length() < 1e-12);
            assert!((q[v] - 0.5 * *p).length() < 1e-12);
            assert!(t[v].length() < 1e-12);
        }
        // The top vertex slid along the surface: its tangential field points back, in the
        // tangent plane.
        let mut slid = octahedron();
        slid.positions[4] = DVec3::new(0.3, 0.0, 1.0);
        let normals = unit_normals(&slid.positions, &slid.triangles);
        let (_, [_, _, t]) = FilterFields::extended(&slid, 2.0);
        assert!(t[4].x < -0.1, "{:?}", t[4]);
        assert!(t[4].dot(normals[4]).abs() < 1e-12, "{:?}", t[4]);
    }

    #[test]
    fn the_extended_filter_leaves_boundary_vertices_and_stays_finite() {
        let mut m = octahedron();
        m.triangles.pop();
        let before = m.positions.clone();
        SurfaceFilter::from_extended_factors([0.3, 0.2, -0.4, 0.5, 0.25]).apply(&mut m, 0.5);
        for v in [0usize, 3, 5] {
            assert_eq!(m.positions[v], before[v], "boundary vertex {v} moved");
        }
        assert_ne!(m.positions[4], before[4]);
        let mut huge = octahedron();
        for p in &mut huge.positions {
            *p *= 1e307;
        }
        SurfaceFilter::from_extended_factors([4.0; 5]).apply(&mut huge, 1e-300);
        assert!(huge.positions.iter().all(|p| p.is_finite()));
    }
}
