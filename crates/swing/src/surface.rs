//! The original surface `M` as the retiler queries it: per-triangle normals and components,
//! smooth vertex normals, a uniform grid over the triangles, the intersection of a swing
//! circle with the surface (`algorithms.md` 1.3: plane–triangle segments, then
//! segment–circle roots) and closest points within one component.
//!
//! Everything here is encoder-side: the angles it returns are measured with std `atan2`,
//! then quantized; only the quantized index reaches the bit-exact reconstruction.

use crate::grid::{Cells, StaticGrid};
use whet_codec::SwingFrame;
use whet_mesh::{DVec3, Mesh};
use whet_metro::closest_point_on_triangle;

/// One intersection of a swing circle with the surface.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Hit {
    /// Swing angle of the hit, in `(-π, π]`.
    pub theta: f64,
    /// The point on the surface.
    pub point: DVec3,
    /// The original triangle it lies on.
    pub triangle: u32,
}

/// The original mesh with the acceleration structures of one retiling.
pub(crate) struct Surface<'m> {
    pub mesh: &'m Mesh,
    /// Component of each triangle (components are numbered in order of their first triangle).
    pub component: Vec<u32>,
    /// Number of components.
    pub component_count: usize,
    /// Unit normal of each triangle (zero for degenerate ones).
    pub face_normal: Vec<DVec3>,
    /// Area-weighted unit vertex normals.
    pub vertex_normal: Vec<DVec3>,
    grid: StaticGrid,
    /// Scratch: the query stamp of each triangle (dedupes triangles seen in several cells).
    stamp: Vec<u32>,
    query: u32,
    /// Scratch of [`Self::nearest`]: the cells of a query, nearest first.
    cell_scratch: std::cell::RefCell<Vec<(f64, u64)>>,
}

impl<'m> Surface<'m> {
    /// Prepares `mesh` for queries at edge length about `cell` (the grid's cell size).
    pub fn new(mesh: &'m Mesh, cell: f64) -> Surface<'m> {
        let nt = mesh.triangles.len();
        let nv = mesh.positions.len();
        let face_normal: Vec<DVec3> = (0..nt).map(|t| mesh.face_normal(t)).collect();
        let mut vertex_normal = vec![DVec3::ZERO; nv];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let w = mesh.face_cross(t);
            for &v in tri {
                vertex_normal[v as usize] += w;
            }
        }
        for n in &mut vertex_normal {
            *n = n.normalize_or_zero();
        }
        // Components by union-find over the triangles' vertices.
        let mut parent: Vec<u32> = (0..nv as u32).collect();
        fn find(p: &mut [u32], mut x: u32) -> u32 {
            while p[x as usize] != x {
                let g = p[p[x as usize] as usize];
                p[x as usize] = g;
                x = g;
            }
            x
        }
        for tri in &mesh.triangles {
            let r0 = find(&mut parent, tri[0]);
            for &v in &tri[1..] {
                let r = find(&mut parent, v);
                if r != r0 {
                    parent[r as usize] = r0;
                }
            }
        }
        let mut label = vec![u32::MAX; nv];
        let mut component = Vec::with_capacity(nt);
        let mut count = 0u32;
        for tri in &mesh.triangles {
            let r = find(&mut parent, tri[0]) as usize;
            if label[r] == u32::MAX {
                label[r] = count;
                count += 1;
            }
            component.push(label[r]);
        }
        let bbox = mesh.bounding_box();
        let cells = Cells::new(bbox.min, cell.max(1e-300));
        let grid = StaticGrid::build(
            cells,
            mesh.triangles
                .iter()
                .map(|t| t.map(|v| mesh.positions[v as usize])),
        );
        Surface {
            mesh,
            component,
            component_count: count as usize,
            face_normal,
            vertex_normal,
            grid,
            stamp: vec![0; nt],
            query: 0,
            cell_scratch: Default::default(),
        }
    }

    fn next_query(&mut self) -> u32 {
        self.query = self.query.wrapping_add(1);
        if self.query == 0 {
            self.stamp.iter_mut().for_each(|s| *s = 0);
            self.query = 1;
        }
        self.query
    }

    /// Smooth normal at point `p` of triangle `t` (barycentric blend of vertex normals,
    /// falling back to the face normal).
    pub fn normal_at(&self, t: u32, p: DVec3) -> DVec3 {
        let tri = self.mesh.triangles[t as usize];
        let [a, b, c] = tri.map(|v| self.mesh.positions[v as usize]);
        let n = (b - a).cross(c - a);
        let n2 = n.length_squared();
        let blended = if n2 > 0.0 {
            let wa = (b - p).cross(c - p).dot(n) / n2;
            let wb = (c - p).cross(a - p).dot(n) / n2;
            let wc = 1.0 - wa - wb;
            self.vertex_normal[tri[0] as usize] * wa.max(0.0)
                + self.vertex_normal[tri[1] as usize] * wb.max(0.0)
                + self.vertex_normal[tri[2] as usize] * wc.max(0.0)
        } else {
            DVec3::ZERO
        };
        let m = blended.normalize_or_zero();
        if m == DVec3::ZERO {
            self.face_normal[t as usize]
        } else {
            m
        }
    }

    /// The surface normal at `p` averaged over the triangles of component `comp` whose
    /// centroids lie within `radius` (area-weighted): a normal at the scale of the retiling,
    /// insensitive to scanning noise. Falls back to `fallback`.
    pub fn smooth_normal(&mut self, p: DVec3, radius: f64, comp: u32, fallback: DVec3) -> DVec3 {
        let (n, _) = self.normal_coherence(p, radius, comp);
        if n == DVec3::ZERO {
            fallback
        } else {
            n
        }
    }

    /// The smoothed normal at `p` (see [`Self::smooth_normal`]) and how flat the surface is
    /// there: `|Σ w n_t| / Σ w |n_t|`, 1 on a plane, small on a sharp corner.
    pub fn normal_coherence(&mut self, p: DVec3, radius: f64, comp: u32) -> (DVec3, f64) {
        let q = self.next_query();
        let d = DVec3::splat(radius);
        let r2 = radius * radius;
        let mesh = self.mesh;
        let grid = &self.grid;
        let stamp = &mut self.stamp;
        let component = &self.component;
        let mut sum = DVec3::ZERO;
        let mut total = 0.0;
        grid.cells.for_box(p - d, p + d, |key| {
            for &t in grid.cell_items(key) {
                let ti = t as usize;
                if stamp[ti] == q || component[ti] != comp {
                    continue;
                }
                stamp[ti] = q;
                let [a, b, c] = mesh.triangles[ti].map(|v| mesh.positions[v as usize]);
                let centroid = (a + b + c) / 3.0;
                let d2 = (centroid - p).length_squared();
                if d2 <= r2 {
                    // Weight by area and a smooth falloff.
                    let w = 1.0 - d2 / r2;
                    let x = (b - a).cross(c - a);
                    sum += x * w;
                    total += x.length() * w;
                }
            }
        });
        let coherence = if total > 0.0 {
            sum.length() / total
        } else {
            0.0
        };
        (sum.normalize_or_zero(), coherence)
    }

    /// Appends to `out` every intersection of the circle of `frame` with the triangles of
    /// component `comp`.
    pub fn circle_hits(&mut self, frame: &SwingFrame, comp: u32, out: &mut Vec<Hit>) {
        out.clear();
        let q = self.next_query();
        let u = frame.axis;
        let r = frame.radius;
        let ext = DVec3::new(
            r * (1.0 - u.x * u.x).max(0.0).sqrt(),
            r * (1.0 - u.y * u.y).max(0.0).sqrt(),
            r * (1.0 - u.z * u.z).max(0.0).sqrt(),
        ) + DVec3::splat(r * 1e-6);
        let m = frame.center;
        let (lo, hi) = (m - ext, m + ext);
        let mesh = self.mesh;
        let grid = &self.grid;
        let stamp = &mut self.stamp;
        let component = &self.component;
        grid.cells.for_box(lo, hi, |key| {
            for &t in grid.cell_items(key) {
                let ti = t as usize;
                if stamp[ti] == q || component[ti] != comp {
                    continue;
                }
                stamp[ti] = q;
                let tri = mesh.triangles[ti];
                let p = tri.map(|v| mesh.positions[v as usize]);
                let d = p.map(|x| (x - m).dot(u));
                if (d[0] > 0.0 && d[1] > 0.0 && d[2] > 0.0)
                    || (d[0] < 0.0 && d[1] < 0.0 && d[2] < 0.0)
                {
                    continue;
                }
                // The segment where the plane cuts the triangle.
                let mut seg = [DVec3::ZERO; 2];
                let mut n = 0;
                for i in 0..3 {
                    let j = (i + 1) % 3;
                    if d[i] == 0.0 {
                        if n < 2 {
                            seg[n] = p[i];
                        }
                        n += 1;
                    } else if (d[i] < 0.0) != (d[j] < 0.0) && d[j] != 0.0 {
                        let s = d[i] / (d[i] - d[j]);
                        if n < 2 {
                            seg[n] = p[i] + (p[j] - p[i]) * s;
                        }
                        n += 1;
                    }
                }
                if n != 2 {
                    continue; // a vertex touching the plane, or the triangle in the plane
                }
                // Segment-circle intersection in the plane's frame.
                let to2 = |x: DVec3| {
                    let w = x - m;
                    (w.dot(frame.e1), w.dot(frame.e2))
                };
                let (x0, y0) = to2(seg[0]);
                let (x1, y1) = to2(seg[1]);
                let (dx, dy) = (x1 - x0, y1 - y0);
                let aa = dx * dx + dy * dy;
                if aa.is_nan() || aa <= 0.0 {
                    continue;
                }
                let bb = x0 * dx + y0 * dy;
                let cc = x0 * x0 + y0 * y0 - r * r;
                let disc = bb * bb - aa * cc;
                if disc < 0.0 {
                    continue;
                }
                let sq = disc.sqrt();
                for lam in [(-bb - sq) / aa, (-bb + sq) / aa] {
                    if !(-1e-9..=1.0 + 1e-9).contains(&lam) {
                        continue;
                    }
                    let (x, y) = (x0 + lam * dx, y0 + lam * dy);
                    out.push(Hit {
                        theta: y.atan2(x),
                        point: seg[0] + (seg[1] - seg[0]) * lam.clamp(0.0, 1.0),
                        triangle: t,
                    });
                    if sq == 0.0 {
                        break;
                    }
                }
            }
        });
    }

    /// The triangle of component `comp` closest to `p` within `radius`: squared distance,
    /// closest point, triangle. Cells are visited nearest first and the search stops at the
    /// first cell farther than the best triangle so far; a triangle whose bounding box is
    /// farther is skipped without the exact test. Ties go to the lowest triangle index, so
    /// the answer does not depend on the visiting order.
    fn nearest(&self, p: DVec3, comp: u32, radius: f64) -> Option<(f64, DVec3, u32)> {
        self.nearest_where(p, radius, |t| self.component[t] == comp)
    }

    /// [`Self::nearest`] among the triangles `accept` takes.
    fn nearest_where(
        &self,
        p: DVec3,
        radius: f64,
        accept: impl Fn(usize) -> bool,
    ) -> Option<(f64, DVec3, u32)> {
        let mesh = self.mesh;
        let mut best: Option<(f64, DVec3, u32)> = None;
        let limit = radius * radius;
        let scan = |items: &[u32], best: &mut Option<(f64, DVec3, u32)>| {
            for &t in items {
                let ti = t as usize;
                if !accept(ti) {
                    continue;
                }
                let [a, b, c] = mesh.triangles[ti].map(|v| mesh.positions[v as usize]);
                let bound = best.map_or(limit, |b| b.0);
                let gap = (a.min(b).min(c) - p)
                    .max(p - a.max(b).max(c))
                    .max(DVec3::ZERO);
                if gap.length_squared() > bound {
                    continue;
                }
                let x = closest_point_on_triangle(p, a, b, c);
                let dist = (x - p).length_squared();
                let better = match *best {
                    None => dist <= limit,
                    Some((bd, _, bt)) => dist < bd || (dist == bd && t < bt),
                };
                if better {
                    *best = Some((dist, x, t));
                }
            }
        };
        // The cell holding `p` first: its best triangle usually bounds the search so tightly
        // that no other cell is listed. The answer (the least distance, then the least
        // triangle index, within `radius`) does not depend on the order cells are visited.
        // (Only when within `radius` by the cells' own measure: a point beyond the grid's
        // clamped range lies in no cell.)
        let home_cell = self.grid.cells.cell(p);
        let home = Cells::key(home_cell);
        let scanned = self.grid.cells.squared_gap(p, home_cell) <= limit;
        if scanned {
            scan(self.grid.cell_items(home), &mut best);
        }
        let mut cells = std::mem::take(&mut *self.cell_scratch.borrow_mut());
        let bound = best.map_or(limit, |b| b.0);
        self.grid
            .cells
            .by_squared_distance(p, bound, scanned.then_some(home), &mut cells);
        for &(cell_d2, key) in &cells {
            let bound = best.map_or(limit, |b| b.0);
            if cell_d2 > bound {
                break;
            }
            scan(self.grid.cell_items(key), &mut best);
        }
        *self.cell_scratch.borrow_mut() = cells;
        best
    }

    /// The face normal of the triangle of component `comp` closest to `p`, if one lies
    /// within `radius` (no scratch state: usable from shared references).
    pub fn closest_face_normal(&self, p: DVec3, comp: u32, radius: f64) -> Option<DVec3> {
        let (_, _, t) = self.nearest(p, comp, radius)?;
        let n = self.face_normal[t as usize];
        (n != DVec3::ZERO).then_some(n)
    }

    /// The closest point to `p` within distance `radius` on any triangle `accept` takes.
    pub fn closest_point(
        &self,
        p: DVec3,
        radius: f64,
        accept: impl Fn(usize) -> bool,
    ) -> Option<DVec3> {
        self.nearest_where(p, radius, accept).map(|(_, x, _)| x)
    }

    /// The closest point to `p` on component `comp` within distance `radius`, with its
    /// triangle.
    pub fn closest_in_component(
        &mut self,
        p: DVec3,
        comp: u32,
        radius: f64,
    ) -> Option<(DVec3, u32)> {
        self.nearest(p, comp, radius).map(|(_, x, t)| (x, t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nearest triangle by brute force: least squared distance within `radius`, ties to
    /// the least index.
    fn brute_nearest(mesh: &Mesh, p: DVec3, radius: f64) -> Option<(f64, u32)> {
        let mut best: Option<(f64, u32)> = None;
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|v| mesh.positions[v as usize]);
            let d = (closest_point_on_triangle(p, a, b, c) - p).length_squared();
            if d <= radius * radius && best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, t as u32));
            }
        }
        best
    }

    #[test]
    fn nearest_matches_a_brute_force_search() {
        // A sphere finer than the cells, points near it, inside it and far from it, radii
        // that reach several cells or none.
        let mesh = whet_testkit::meshes::icosphere(4);
        let surf = Surface::new(&mesh, 0.3);
        let mut checked = 0;
        for i in 0..400 {
            let f = i as f64;
            let dir = DVec3::new((f * 0.731).sin(), (f * 1.37).cos(), (f * 0.417).sin())
                .normalize_or_zero();
            let p = dir * (0.2 + (f * 0.0113) % 1.6);
            for radius in [0.05, 0.3, 1.0] {
                let got = surf.nearest_where(p, radius, |_| true);
                let want = brute_nearest(&mesh, p, radius);
                assert_eq!(got.map(|g| (g.0, g.2)), want, "p {p:?} radius {radius}");
                checked += want.is_some() as usize;
            }
        }
        assert!(checked > 400, "{checked}");
        // Beyond the grid's clamped range (2^20 cells of 0.3): nothing within the radius,
        // and the border cell the point is clamped into is no answer either. (Radii are at
        // most a few L: the search enumerates the cells of the radius's box.)
        for p in [DVec3::new(1e6, 0.0, 0.0), DVec3::new(0.0, -1e7, 3.0)] {
            assert_eq!(surf.nearest_where(p, 1.0, |_| true).map(|g| g.2), None);
        }
    }
}
