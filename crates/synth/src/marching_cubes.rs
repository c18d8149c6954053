//! Marching cubes of a signed distance function: the feature-insensitive sampler.
//!
//! The grid covers the bounds padded by about 1.5 cells on every side; `resolution` N cells
//! of side `h = L / N` span the longest side `L` of the bounds (so that axis has N + 3 cells),
//! and the other axes use the same `h`. Output guarantees, for any function whose zero set
//! stays inside the bounds:
//!
//! - one vertex per crossed grid edge, shared by every cell around the edge (no duplicates,
//!   nothing welded by position), placed by linear interpolation of the two grid values;
//! - closed, manifold and consistently oriented (counter-clockwise seen from the positive
//!   side): ambiguous faces are resolved by a rule that depends only on the face's four signs
//!   (the inside corners are joined), so neighbouring cells agree (see `table`); inside grid
//!   points are thus connected through faces (18-connectivity), outside ones only through
//!   edges (6-connectivity);
//! - grid values with magnitude under `1e-7 h` are replaced by `+-1e-7 h` (exact zeros by
//!   `+1e-7 h`), so no vertex lands on a grid corner and no triangle collapses;
//! - deterministic: the same input gives the same mesh bit for bit, whatever the thread count.
//!
//! Speed: the function is evaluated only in a narrow band. The grid is cut into slabs of 8
//! cell layers processed in parallel; in each slab, blocks of 8^3 cells and then sub-blocks of
//! 2^3 cells are skipped when the function's magnitude at their centre exceeds their
//! half-diagonal: for a 1-Lipschitz function no surface passes through them. Per-slab results
//! are concatenated in slab order; the vertices of edges on the plane between two slabs belong
//! to the upper slab, and the lower slab's references to them are resolved at assembly. A
//! function that is not 1-Lipschitz can make a slab skip a block its neighbour finds crossed;
//! where that shows on the plane between two slabs the sampling fails with
//! [`Error::NotLipschitz`] rather than return a surface with a hole (elsewhere the narrow band
//! cannot see it: the contract is the caller's).

mod table;

use glam::DVec3;
use rayon::prelude::*;
use whet_mesh::{Aabb, Mesh};

use crate::shapes::Shape;
use crate::{Error, MAX_RESOLUTION};

/// Cells per block side (and slab thickness).
const BLOCK: usize = 8;
/// Cells per sub-block side.
const SUB: usize = 2;
/// Marks an edge id referring to a vertex owned by the next slab; the low bits are its key.
const FOREIGN: u32 = 1 << 31;
const NONE: u32 = u32::MAX;
/// Values below this many cell sizes in magnitude are pushed out to it.
const ZERO_GUARD: f64 = 1e-7;

/// The sampling grid: points `origin + h * (i, j, k)` for `0 <= i <= cells[0]` etc.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// The grid point `(0, 0, 0)`.
    pub origin: DVec3,
    /// Cell side `h`.
    pub cell: f64,
    /// Cells along x, y, z.
    pub cells: [usize; 3],
}

impl Grid {
    /// The grid marching cubes uses for `bounds` at `resolution`.
    pub fn new(bounds: &Aabb, resolution: usize) -> Result<Grid, Error> {
        if !(2..=MAX_RESOLUTION).contains(&resolution) {
            return Err(Error::BadResolution(resolution));
        }
        if bounds.is_empty() || !bounds.min.is_finite() || !bounds.max.is_finite() {
            return Err(Error::BadBounds);
        }
        let size = bounds.size();
        let longest = size.max_element();
        if longest <= 0.0 {
            return Err(Error::BadBounds);
        }
        let h = longest / resolution as f64;
        let mut cells = [0; 3];
        let mut origin = DVec3::ZERO;
        let center = bounds.center();
        for a in 0..3 {
            // At least 1.5 cells of padding each side; the longest axis gets exactly N + 3.
            let n = ((size[a] / h) - 1e-9).ceil().max(0.0) as usize + 3;
            cells[a] = n.min(resolution + 3);
            origin[a] = center[a] - 0.5 * h * cells[a] as f64;
        }
        Ok(Grid {
            origin,
            cell: h,
            cells,
        })
    }

    /// Position of grid point `(i, j, k)`.
    #[inline]
    pub fn point(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.origin + DVec3::new(i as f64, j as f64, k as f64) * self.cell
    }
}

/// Samples `shape` by marching cubes at `resolution` cells along the longest side of its
/// bounds. See the module documentation for the guarantees.
pub fn marching_cubes(shape: &Shape, resolution: usize) -> Result<Mesh, Error> {
    marching_cubes_fn(|p| shape.sdf(p), &shape.bounds(), resolution)
}

/// Marching cubes of any function over `bounds` (which must contain its zero set) at
/// `resolution` cells along the longest side. `f` must be 1-Lipschitz (a signed distance or a
/// lower bound of one; divide an L-Lipschitz function by L): the narrow band relies on it.
/// Negative is inside; triangles are counter-clockwise seen from the positive side.
pub fn marching_cubes_fn<F>(f: F, bounds: &Aabb, resolution: usize) -> Result<Mesh, Error>
where
    F: Fn(DVec3) -> f64 + Sync,
{
    let grid = Grid::new(bounds, resolution)?;
    let table = table::table();
    let [nx, ny, nz] = grid.cells;
    let slabs = nz.div_ceil(BLOCK);
    let ctx = Ctx {
        f: &f,
        grid,
        table,
        guard: ZERO_GUARD * grid.cell,
    };
    let outs: Vec<SlabOut> = (0..slabs)
        .into_par_iter()
        .map_init(
            || Scratch::new(nx, ny),
            |scratch, s| {
                let z0 = s * BLOCK;
                let z1 = (z0 + BLOCK).min(nz);
                ctx.slab(scratch, z0, z1, s + 1 < slabs)
            },
        )
        .collect::<Result<_, _>>()?;
    assemble(outs, &grid)
}

struct SlabOut {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    /// (key, local id) of the vertices on the slab's bottom plane, sorted by key.
    bottom: Vec<(u32, u32)>,
}

fn assemble(outs: Vec<SlabOut>, grid: &Grid) -> Result<Mesh, Error> {
    let mut offsets = Vec::with_capacity(outs.len() + 1);
    let mut total: u64 = 0;
    for o in &outs {
        offsets.push(total);
        total += o.positions.len() as u64;
    }
    if total > u64::from(u32::MAX - 1) {
        return Err(Error::TooLarge(total));
    }
    let mut triangles = Vec::with_capacity(outs.iter().map(|o| o.triangles.len()).sum());
    for (s, o) in outs.iter().enumerate() {
        let own = offsets[s] as u32;
        for t in &o.triangles {
            let mut g = [0u32; 3];
            for (slot, &id) in g.iter_mut().zip(t) {
                *slot = if id & FOREIGN == 0 {
                    own + id
                } else {
                    let key = id & !FOREIGN;
                    let next = outs
                        .get(s + 1)
                        .ok_or(Error::Internal("foreign vertex in the last slab"))?;
                    // The slab above found no crossing on this edge of their shared
                    // plane: its narrow band skipped the block holding it, which a
                    // 1-Lipschitz function cannot make it do (the edge lies in both slabs'
                    // blocks, and a zero on it bounds the value at either centre).
                    let i = next
                        .bottom
                        .binary_search_by_key(&key, |&(k, _)| k)
                        .map_err(|_| {
                            let p = (key / 2) as usize;
                            let nx1 = grid.cells[0] + 1;
                            Error::NotLipschitz {
                                at: grid.point(p % nx1, p / nx1, (s + 1) * BLOCK),
                            }
                        })?;
                    offsets[s + 1] as u32 + next.bottom[i].1
                };
            }
            triangles.push(g);
        }
    }
    let mut positions = Vec::with_capacity(total as usize);
    for o in outs {
        positions.extend(o.positions);
    }
    Ok(Mesh::new(positions, triangles))
}

/// Per-thread buffers for two point planes and the edges between them. Entries are reset
/// through the `touched` lists, so the buffers are clean between slabs.
struct Scratch {
    /// Values on the lower (0) and upper (1) plane; NaN = not evaluated.
    val: [Vec<f64>; 2],
    val_touched: [Vec<u32>; 2],
    /// Vertex ids of x- and y-edges on the lower and upper plane.
    xe: [Vec<u32>; 2],
    ye: [Vec<u32>; 2],
    e_touched: [Vec<u32>; 2],
    /// Vertex ids of z-edges between the planes.
    ze: Vec<u32>,
    z_touched: Vec<u32>,
    /// Active sub-blocks of the slab.
    active: Vec<bool>,
}

impl Scratch {
    fn new(nx: usize, ny: usize) -> Self {
        let n = (nx + 1) * (ny + 1);
        Scratch {
            val: [vec![f64::NAN; n], vec![f64::NAN; n]],
            val_touched: [Vec::new(), Vec::new()],
            xe: [vec![NONE; n], vec![NONE; n]],
            ye: [vec![NONE; n], vec![NONE; n]],
            e_touched: [Vec::new(), Vec::new()],
            ze: vec![NONE; n],
            z_touched: Vec::new(),
            active: Vec::new(),
        }
    }

    /// Clears plane buffer `p`.
    fn clear_plane(&mut self, p: usize) {
        for &i in &self.val_touched[p] {
            self.val[p][i as usize] = f64::NAN;
        }
        self.val_touched[p].clear();
        for &i in &self.e_touched[p] {
            self.xe[p][i as usize] = NONE;
            self.ye[p][i as usize] = NONE;
        }
        self.e_touched[p].clear();
    }

    fn clear_z(&mut self) {
        for &i in &self.z_touched {
            self.ze[i as usize] = NONE;
        }
        self.z_touched.clear();
    }

    /// The upper plane becomes the lower one; the new upper plane is empty.
    fn advance(&mut self) {
        self.clear_plane(0);
        self.val.swap(0, 1);
        self.val_touched.swap(0, 1);
        self.xe.swap(0, 1);
        self.ye.swap(0, 1);
        self.e_touched.swap(0, 1);
        self.clear_z();
    }
}

struct Ctx<'a, F> {
    f: &'a F,
    grid: Grid,
    table: &'static table::CaseTable,
    guard: f64,
}

struct SlabState {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
}

impl<F> Ctx<'_, F>
where
    F: Fn(DVec3) -> f64 + Sync,
{
    /// True unless the function's value `v` at a box centre proves no surface crosses the box
    /// of half-diagonal `half_diag` (NaN is kept, to be reported).
    #[inline]
    fn may_cross(&self, v: f64, half_diag: f64) -> bool {
        v.is_nan() || v.abs() <= half_diag * (1.0 + 1e-9) + self.guard
    }

    /// Evaluates at a cell-range centre: (value, half-diagonal).
    fn probe(&self, lo: [usize; 3], hi: [usize; 3]) -> (f64, f64) {
        let h = self.grid.cell;
        let c = self.grid.origin
            + DVec3::new(
                (lo[0] + hi[0]) as f64,
                (lo[1] + hi[1]) as f64,
                (lo[2] + hi[2]) as f64,
            ) * (0.5 * h);
        let ext = DVec3::new(
            (hi[0] - lo[0]) as f64,
            (hi[1] - lo[1]) as f64,
            (hi[2] - lo[2]) as f64,
        ) * h;
        ((self.f)(c), 0.5 * ext.length())
    }

    fn slab(
        &self,
        sc: &mut Scratch,
        z0: usize,
        z1: usize,
        has_next: bool,
    ) -> Result<SlabOut, Error> {
        let [nx, ny, _] = self.grid.cells;
        // Narrow band: blocks, then sub-blocks.
        let (nsx, nsy, nsz) = (nx.div_ceil(SUB), ny.div_ceil(SUB), (z1 - z0).div_ceil(SUB));
        sc.active.clear();
        sc.active.resize(nsx * nsy * nsz, false);
        for by in 0..ny.div_ceil(BLOCK) {
            for bx in 0..nx.div_ceil(BLOCK) {
                let lo = [bx * BLOCK, by * BLOCK, z0];
                let hi = [(lo[0] + BLOCK).min(nx), (lo[1] + BLOCK).min(ny), z1];
                let (v, hd) = self.probe(lo, hi);
                if !self.may_cross(v, hd) {
                    continue;
                }
                for sz in 0..nsz {
                    for sy in lo[1] / SUB..hi[1].div_ceil(SUB) {
                        for sx in lo[0] / SUB..hi[0].div_ceil(SUB) {
                            let slo = [sx * SUB, sy * SUB, z0 + sz * SUB];
                            let shi = [
                                (slo[0] + SUB).min(nx),
                                (slo[1] + SUB).min(ny),
                                (slo[2] + SUB).min(z1),
                            ];
                            let (v, hd) = self.probe(slo, shi);
                            if self.may_cross(v, hd) {
                                sc.active[(sz * nsy + sy) * nsx + sx] = true;
                            }
                        }
                    }
                }
            }
        }

        let mut st = SlabState {
            positions: Vec::new(),
            triangles: Vec::new(),
        };
        let mut bottom = Vec::new();
        for k in z0..z1 {
            let sz = (k - z0) / SUB;
            let last_layer = k + 1 == z1;
            for sy in 0..nsy {
                for sx in 0..nsx {
                    if !sc.active[(sz * nsy + sy) * nsx + sx] {
                        continue;
                    }
                    for j in sy * SUB..((sy + 1) * SUB).min(ny) {
                        for i in sx * SUB..((sx + 1) * SUB).min(nx) {
                            self.cell(sc, &mut st, [i, j, k], has_next && last_layer)?;
                        }
                    }
                }
            }
            if k == z0 {
                // Vertices on the slab's bottom plane, for the slab below to refer to.
                for &p in &sc.e_touched[0] {
                    for (axis, ids) in [(0u32, &sc.xe[0]), (1u32, &sc.ye[0])] {
                        let id = ids[p as usize];
                        if id != NONE {
                            bottom.push((p * 2 + axis, id));
                        }
                    }
                }
                bottom.sort_unstable();
                bottom.dedup();
            }
            sc.advance();
        }
        sc.clear_plane(0);
        sc.clear_plane(1);
        sc.clear_z();
        if st.positions.len() >= FOREIGN as usize {
            return Err(Error::TooLarge(st.positions.len() as u64));
        }
        Ok(SlabOut {
            positions: st.positions,
            triangles: st.triangles,
            bottom,
        })
    }

    /// The value at grid point `(i, j)` of plane `p` (0 = layer `k`, 1 = layer `k + 1`).
    #[inline]
    fn value(
        &self,
        sc: &mut Scratch,
        i: usize,
        j: usize,
        k: usize,
        p: usize,
    ) -> Result<f64, Error> {
        let nx1 = self.grid.cells[0] + 1;
        let idx = j * nx1 + i;
        let v = sc.val[p][idx];
        if !v.is_nan() {
            return Ok(v);
        }
        let at = self.grid.point(i, j, k + p);
        let raw = (self.f)(at);
        if !raw.is_finite() {
            return Err(Error::NonFiniteValue { at, value: raw });
        }
        let v = if raw.abs() >= self.guard {
            raw
        } else if raw < 0.0 {
            -self.guard
        } else {
            self.guard
        };
        sc.val[p][idx] = v;
        sc.val_touched[p].push(idx as u32);
        Ok(v)
    }

    fn cell(
        &self,
        sc: &mut Scratch,
        st: &mut SlabState,
        [i, j, k]: [usize; 3],
        top_is_foreign: bool,
    ) -> Result<(), Error> {
        let mut v = [0.0; 8];
        let mut case = 0;
        for (c, slot) in v.iter_mut().enumerate() {
            let o = table::corner_offset(c);
            *slot = self.value(sc, i + o[0], j + o[1], k, o[2])?;
            if *slot < 0.0 {
                case |= 1 << c;
            }
        }
        if case == 0 || case == 255 {
            return Ok(());
        }
        for tri in self.table.case(case) {
            let mut ids = [0u32; 3];
            for (slot, &e) in ids.iter_mut().zip(tri) {
                *slot = self.edge_vertex(sc, st, e as usize, [i, j, k], &v, top_is_foreign);
            }
            st.triangles.push(ids);
        }
        Ok(())
    }

    /// The vertex id of cube edge `e` of cell `(i, j, k)`, created on first use.
    fn edge_vertex(
        &self,
        sc: &mut Scratch,
        st: &mut SlabState,
        e: usize,
        [i, j, k]: [usize; 3],
        v: &[f64; 8],
        top_is_foreign: bool,
    ) -> u32 {
        let (c0, c1) = table::edge_corners(e);
        let o = table::corner_offset(c0);
        let (pi, pj, plane) = (i + o[0], j + o[1], o[2]);
        let idx = pj * (self.grid.cells[0] + 1) + pi;
        let axis = e / 4;
        let existing = match axis {
            0 => sc.xe[plane][idx],
            1 => sc.ye[plane][idx],
            _ => sc.ze[idx],
        };
        if existing != NONE {
            return existing;
        }
        let id = if axis < 2 && plane == 1 && top_is_foreign {
            FOREIGN | (idx as u32 * 2 + axis as u32)
        } else {
            let p0 = self.grid.point(pi, pj, k + plane);
            let mut p1 = p0;
            p1[axis] += self.grid.cell;
            let (v0, v1) = (v[c0], v[c1]);
            let t = v0 / (v0 - v1);
            st.positions.push(p0 + (p1 - p0) * t);
            (st.positions.len() - 1) as u32
        };
        match axis {
            0 => sc.xe[plane][idx] = id,
            1 => sc.ye[plane][idx] = id,
            _ => sc.ze[idx] = id,
        }
        if axis == 2 {
            sc.z_touched.push(idx as u32);
        } else {
            sc.e_touched[plane].push(idx as u32);
        }
        id
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_pads_by_one_and_a_half_cells() {
        let b = Aabb {
            min: DVec3::new(-0.5, -0.35, -0.25),
            max: DVec3::new(0.5, 0.35, 0.25),
        };
        let g = Grid::new(&b, 64).unwrap();
        assert_eq!(g.cells[0], 67);
        assert_eq!(g.cell, 1.0 / 64.0);
        for a in 0..3 {
            let pad = b.min[a] - g.origin[a];
            assert!(
                pad >= 1.5 * g.cell - 1e-12 && pad < 2.0 * g.cell,
                "{a}: {pad}"
            );
        }
        assert_eq!(Grid::new(&b, 1), Err(Error::BadResolution(1)));
        assert_eq!(Grid::new(&b, 4096), Err(Error::BadResolution(4096)));
        assert_eq!(Grid::new(&Aabb::EMPTY, 16), Err(Error::BadBounds));
    }

    #[test]
    fn sphere_sampling_is_closed_and_deterministic() {
        let b = Aabb {
            min: DVec3::splat(-0.5),
            max: DVec3::splat(0.5),
        };
        let sdf = |p: DVec3| p.length() - 0.5;
        let m = marching_cubes_fn(sdf, &b, 20).unwrap();
        let r = m.topology_report();
        assert!(r.manifold && r.oriented && r.problems.is_empty(), "{r:?}");
        assert_eq!((r.genus, r.components, r.boundary_loops), (Some(0), 1, 0));
        assert_eq!(m, marching_cubes_fn(sdf, &b, 20).unwrap());
        for p in &m.positions {
            assert!((p.length() - 0.5).abs() < 0.01);
        }
    }

    #[test]
    fn a_function_that_is_not_1_lipschitz_is_an_error_naming_it() {
        // Below the plane between the first two slabs a cylinder crosses it; above, the
        // function jumps to 100, so the second slab's narrow band skips the blocks on the
        // plane while the first slab's cells find crossings on its edges.
        let b = Aabb {
            min: DVec3::splat(-1.0),
            max: DVec3::splat(1.0),
        };
        let res = 3 * BLOCK;
        let grid = Grid::new(&b, res).unwrap();
        let plane = grid.point(0, 0, BLOCK).z;
        let h = grid.cell;
        let f = move |p: DVec3| {
            if p.z < plane + 0.5 * h {
                p.x.hypot(p.y) - 0.5
            } else {
                100.0
            }
        };
        match marching_cubes_fn(f, &b, res) {
            Err(Error::NotLipschitz { at }) => {
                assert!((at.z - plane).abs() < 1e-9, "{at}");
                assert!((at.x.hypot(at.y) - 0.5).abs() < 2.0 * h, "{at}");
            }
            other => panic!("expected NotLipschitz, got {other:?}"),
        }
    }

    #[test]
    fn non_finite_values_are_errors() {
        let b = Aabb {
            min: DVec3::splat(-0.5),
            max: DVec3::splat(0.5),
        };
        let r = marching_cubes_fn(|_| f64::NAN, &b, 4);
        assert!(matches!(r, Err(Error::NonFiniteValue { .. })));
    }
}
