//! The h-subproblem of seed 004's solver: with the control points `p`, the foot triangles and
//! barycentric coordinates of the data points and the targets `t = v - z - lz/az` fixed,
//! find the control-edge sharpness minimising `sum_i |M(h)_i p - t_i|^2`.
//!
//! Two solvers:
//!
//! * [`LocalEval::coordinate_descent`] (whet's default): exact coordinate descent over the
//!   quantized values the codec transmits (`0, 1/(2^b - 1), ..., 1`). Changing one `h_e`
//!   changes only a few rings of the subdivided surface, so each trial recomputes just the
//!   rows that can depend on `h_e` at every level (precomputed per edge) and the residuals of
//!   the data points whose foot triangles use them. Every accepted move lowers the objective,
//!   so the solver is monotone and deterministic, and the discontinuity of the scheme where
//!   `h` leaves 0 (seed 004's `n_v` counts edges with `h > 0`) costs it nothing.
//! * [`pso`] (the paper's particle swarm, for comparison): the global vector of sharpness
//!   over the candidate edges, each particle scored by a full evaluation.
//!
//! Not handled: more semi-sharp levels than fitting levels (the fitter always uses
//! `sharp_levels = levels`).

use crate::loop_subdivision::{
    classify, edge_row, limit_row, vertex_row, Hierarchy, Rules, VertexKind, SHARP_ONE,
};
use crate::sparse::Row;
use crate::topology::{Topology, NONE};
use glam::DVec3;

/// Rows that can change when one control edge's sharpness changes.
#[derive(Clone, Debug, Default)]
struct Deps {
    /// Edges of each level `0..=depth` descending from the control edge.
    edges: Vec<Vec<u32>>,
    /// Their endpoints (vertices whose kind may change), per level.
    verts: Vec<Vec<u32>>,
    /// Rows of each level `1..=depth + 1` (the last: limit rows), stored at index `l - 1`.
    rows: Vec<Vec<u32>>,
    /// Data points whose foot triangle uses a changed limit vertex.
    points: Vec<u32>,
}

/// The evaluator of the h-subproblem. Levels `0..depth` are split with the semi-sharp rules,
/// the finest level is pushed to the limit with the binary ones.
pub(crate) struct LocalEval<'a> {
    hier: &'a Hierarchy,
    depth: usize,
    /// Control sharpness.
    pub h: Vec<f64>,
    /// Effective sharpness per level; index `depth` holds the binary values of the finest.
    hl: Vec<Vec<f64>>,
    kinds: Vec<Vec<VertexKind>>,
    /// Positions per level `0..=depth`, then the limit positions at `depth + 1`.
    pos: Vec<Vec<DVec3>>,
    scratch: Vec<Vec<DVec3>>,
    stamp: Vec<Vec<u32>>,
    generation: u32,
    foot: Vec<[u32; 3]>,
    bary: Vec<DVec3>,
    target: Vec<DVec3>,
    /// Weight of each data point.
    weight: Vec<f64>,
    /// Weighted squared residual of each data point.
    r2: Vec<f64>,
    deps: Vec<Deps>,
    row: Row,
    tmp: Row,
    /// Saved kinds for revert: (level, vertex, kind).
    saved: Vec<(u32, u32, VertexKind)>,
}

impl<'a> LocalEval<'a> {
    /// Sets up the evaluator for control points `p`, sharpness `h`, and data points given by
    /// their finest-level foot triangle (`foot`, vertex indices), barycentric coordinates and
    /// targets.
    pub fn new(
        hier: &'a Hierarchy,
        h: &[f64],
        p: &[DVec3],
        foot: Vec<[u32; 3]>,
        bary: Vec<DVec3>,
        target: Vec<DVec3>,
        weight: Vec<f64>,
    ) -> LocalEval<'a> {
        let depth = hier.depth();
        let mut hl = Vec::with_capacity(depth + 1);
        let mut kinds = Vec::with_capacity(depth + 1);
        for l in 0..=depth {
            let rules = if l < depth {
                Rules::SemiSharp
            } else {
                Rules::Binary
            };
            let s = hier.level_sharpness(l, h, rules);
            let topo = &hier.levels[l];
            kinds.push(
                (0..topo.vertex_count)
                    .map(|v| classify(topo, &s, v))
                    .collect(),
            );
            hl.push(s);
        }
        let mut pos = vec![p.to_vec()];
        for (l, s) in hier.stencils(h, depth, true).iter().enumerate() {
            let next = s.apply(&pos[l]);
            pos.push(next);
        }
        let scratch: Vec<Vec<DVec3>> = pos.iter().map(|x| vec![DVec3::ZERO; x.len()]).collect();
        let stamp: Vec<Vec<u32>> = pos.iter().map(|x| vec![0; x.len()]).collect();
        let mut eval = LocalEval {
            hier,
            depth,
            h: h.to_vec(),
            hl,
            kinds,
            pos,
            scratch,
            stamp,
            generation: 0,
            foot,
            bary,
            target,
            weight,
            r2: Vec::new(),
            deps: Vec::new(),
            row: Row::default(),
            tmp: Row::default(),
            saved: Vec::new(),
        };
        eval.r2 = (0..eval.foot.len())
            .map(|i| eval.weight[i] * eval.residual(i, false).length_squared())
            .collect();
        eval.deps = eval.dependencies();
        eval
    }

    /// The objective `sum |M p - t|^2`.
    pub fn objective(&self) -> f64 {
        self.r2.iter().sum()
    }

    /// Limit positions of the finest level.
    #[cfg(test)]
    pub fn limit_positions(&self) -> &[DVec3] {
        &self.pos[self.depth + 1]
    }

    #[inline]
    fn read(&self, l: usize, i: usize) -> DVec3 {
        if self.stamp[l][i] == self.generation {
            self.scratch[l][i]
        } else {
            self.pos[l][i]
        }
    }

    fn residual(&self, i: usize, trial: bool) -> DVec3 {
        let l = self.depth + 1;
        let f = self.foot[i];
        let b = self.bary[i];
        let x = |k: usize| {
            if trial {
                self.read(l, f[k] as usize)
            } else {
                self.pos[l][f[k] as usize]
            }
        };
        x(0) * b.x + x(1) * b.y + x(2) * b.z - self.target[i]
    }

    fn dependencies(&self) -> Vec<Deps> {
        let hier = self.hier;
        let depth = self.depth;
        let ne = hier.levels[0].edges.len();
        // Inverse of the origin map per level.
        let mut by_origin: Vec<Vec<Vec<u32>>> = Vec::with_capacity(depth + 1);
        for l in 0..=depth {
            let mut lists = vec![Vec::new(); ne];
            for (x, &o) in hier.origin[l].iter().enumerate() {
                if o != NONE {
                    lists[o as usize].push(x as u32);
                }
            }
            by_origin.push(lists);
        }
        // Finest vertex -> data points.
        let nfine = hier.finest().vertex_count;
        let mut count = vec![0u32; nfine + 1];
        for f in &self.foot {
            for &v in f {
                count[v as usize + 1] += 1;
            }
        }
        for i in 0..nfine {
            count[i + 1] += count[i];
        }
        let mut fill = count.clone();
        let mut vpoints = vec![0u32; count[nfine] as usize];
        for (i, f) in self.foot.iter().enumerate() {
            for &v in f {
                vpoints[fill[v as usize] as usize] = i as u32;
                fill[v as usize] += 1;
            }
        }
        let mut marks: Vec<Vec<u32>> = (0..=depth + 1)
            .map(|l| vec![u32::MAX; self.pos[l].len()])
            .collect();
        let mut point_mark = vec![u32::MAX; self.foot.len()];
        let mut out = Vec::with_capacity(ne);
        for e in 0..ne {
            let tag = e as u32;
            let mut d = Deps::default();
            let mut changed: Vec<u32> = Vec::new();
            for l in 0..=depth {
                let topo = &hier.levels[l];
                let edges = by_origin[l][e].clone();
                let mut verts: Vec<u32> =
                    edges.iter().flat_map(|&x| topo.edges[x as usize]).collect();
                verts.sort_unstable();
                verts.dedup();
                let target = &mut marks[l + 1];
                let mut rows = Vec::new();
                let mut mark = |r: u32, rows: &mut Vec<u32>| {
                    if target[r as usize] != tag {
                        target[r as usize] = tag;
                        rows.push(r);
                    }
                };
                if l < depth {
                    let nv = topo.vertex_count as u32;
                    for &v in &verts {
                        mark(v, &mut rows);
                        for &(_, x) in topo.ring(v as usize) {
                            mark(nv + x, &mut rows);
                        }
                    }
                    for &x in &edges {
                        mark(nv + x, &mut rows);
                    }
                    for &v in &changed {
                        mark(v, &mut rows);
                        let ring = topo.ring(v as usize);
                        for &(u, x) in ring {
                            mark(u, &mut rows);
                            mark(nv + x, &mut rows);
                        }
                        for j in 0..ring.len() {
                            if topo.boundary[v as usize] && j + 1 == ring.len() {
                                break;
                            }
                            let (a, b) = (ring[j].0, ring[(j + 1) % ring.len()].0);
                            if let Some(x) = topo.find_edge(a, b) {
                                mark(nv + x as u32, &mut rows);
                            }
                        }
                    }
                } else {
                    for &v in verts.iter().chain(changed.iter()) {
                        mark(v, &mut rows);
                        for &(u, _) in topo.ring(v as usize) {
                            mark(u, &mut rows);
                        }
                    }
                }
                rows.sort_unstable();
                changed = rows.clone();
                d.edges.push(edges);
                d.verts.push(verts);
                d.rows.push(rows);
            }
            for &y in &changed {
                for &i in &vpoints[count[y as usize] as usize..count[y as usize + 1] as usize] {
                    if point_mark[i as usize] != tag {
                        point_mark[i as usize] = tag;
                        d.points.push(i);
                    }
                }
            }
            d.points.sort_unstable();
            out.push(d);
        }
        if std::env::var_os("WHET_SUBDIV_DEBUG").is_some() {
            let ne = out.len().max(1);
            for l in 0..=depth {
                let s: usize = out.iter().map(|d| d.rows[l].len()).sum();
                eprintln!("deps level {l}: {} rows/edge", s / ne);
            }
            let s: usize = out.iter().map(|d| d.points.len()).sum();
            eprintln!("deps points: {}/edge", s / ne);
        }
        out
    }

    /// Sets `h_e = value` in the level tables (kinds included), saving what it overwrites.
    fn patch(&mut self, e: usize, value: f64) {
        self.h[e] = value;
        let depth = self.depth;
        for l in 0..=depth {
            let topo: &Topology = &self.hier.levels[l];
            let v = if l < depth {
                value
            } else if value >= SHARP_ONE {
                1.0
            } else {
                0.0
            };
            for &x in &self.deps[e].edges[l] {
                if !topo.is_boundary_edge(x as usize) {
                    self.hl[l][x as usize] = v;
                }
            }
            for &w in &self.deps[e].verts[l] {
                let k = classify(topo, &self.hl[l], w as usize);
                self.saved.push((l as u32, w, self.kinds[l][w as usize]));
                self.kinds[l][w as usize] = k;
            }
        }
    }

    /// Recomputes the rows depending on `h_e` into the scratch arrays and returns the change
    /// of the objective.
    fn trial(&mut self, e: usize) -> f64 {
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            for s in &mut self.stamp {
                s.iter_mut().for_each(|x| *x = u32::MAX);
            }
            self.generation = 1;
        }
        let depth = self.depth;
        let mut row = std::mem::take(&mut self.row);
        let mut tmp = std::mem::take(&mut self.tmp);
        for l in 0..=depth {
            let topo = &self.hier.levels[l];
            let nv = topo.vertex_count;
            for k in 0..self.deps[e].rows[l].len() {
                let r = self.deps[e].rows[l][k] as usize;
                if l < depth {
                    if r < nv {
                        vertex_row(topo, &self.hl[l], r, &mut row);
                    } else {
                        edge_row(topo, &self.hl[l], &self.kinds[l], r - nv, &mut row);
                    }
                } else {
                    limit_row(topo, &self.hl[l], &self.kinds[l], r, &mut row, &mut tmp);
                }
                let mut s = DVec3::ZERO;
                for &(i, w) in &row.entries {
                    s += self.read(l, i as usize) * w;
                }
                self.scratch[l + 1][r] = s;
                self.stamp[l + 1][r] = self.generation;
            }
        }
        self.row = row;
        self.tmp = tmp;
        let mut delta = 0.0;
        for &i in &self.deps[e].points {
            let i = i as usize;
            delta += self.weight[i] * self.residual(i, true).length_squared() - self.r2[i];
        }
        delta
    }

    /// Undoes [`LocalEval::patch`].
    fn revert(&mut self, e: usize, old: f64) {
        self.h[e] = old;
        let depth = self.depth;
        for l in 0..=depth {
            let topo: &Topology = &self.hier.levels[l];
            let v = if l < depth {
                old
            } else if old >= SHARP_ONE {
                1.0
            } else {
                0.0
            };
            for &x in &self.deps[e].edges[l] {
                if !topo.is_boundary_edge(x as usize) {
                    self.hl[l][x as usize] = v;
                }
            }
        }
        while let Some((l, w, k)) = self.saved.pop() {
            self.kinds[l as usize][w as usize] = k;
        }
    }

    /// Makes the last trial the state.
    fn commit(&mut self, e: usize) {
        self.saved.clear();
        for l in 0..=self.depth {
            for k in 0..self.deps[e].rows[l].len() {
                let r = self.deps[e].rows[l][k] as usize;
                self.pos[l + 1][r] = self.scratch[l + 1][r];
            }
        }
        for k in 0..self.deps[e].points.len() {
            let i = self.deps[e].points[k] as usize;
            self.r2[i] = self.weight[i] * self.residual(i, false).length_squared();
        }
    }

    /// The change of the objective if `h_e` were `value` (the state is left unchanged).
    pub fn delta(&mut self, e: usize, value: f64) -> f64 {
        let old = self.h[e];
        self.patch(e, value);
        let d = self.trial(e);
        self.revert(e, old);
        d
    }

    /// Sets `h_e = value`, updating every level.
    pub fn set(&mut self, e: usize, value: f64) {
        self.patch(e, value);
        self.trial(e);
        self.commit(e);
    }

    /// Coordinate descent over `values` on the `candidates` edges, at most `sweeps` sweeps;
    /// returns the number of accepted moves.
    pub fn coordinate_descent(
        &mut self,
        candidates: &[u32],
        values: &[f64],
        sweeps: usize,
    ) -> usize {
        let mut moves = 0;
        for _ in 0..sweeps {
            let mut moved = 0;
            let scale = self.objective().max(f64::MIN_POSITIVE);
            for &e in candidates {
                let e = e as usize;
                let current = self.h[e];
                let mut best = (-1e-12 * scale, current);
                for &v in values {
                    if v == current {
                        continue;
                    }
                    let d = self.delta(e, v);
                    if d < best.0 {
                        best = (d, v);
                    }
                }
                if best.1 != current {
                    self.set(e, best.1);
                    moved += 1;
                }
            }
            moves += moved;
            if moved == 0 {
                break;
            }
        }
        moves
    }
}

/// The paper's particle swarm over the sharpness of `candidates` (Kennedy & Eberhart with
/// Clerc's constriction: inertia 0.7298, c1 = c2 = 1.49618; sharpening-extras B.6 [RECON]),
/// one particle seeded with the current `h`; each particle is scored by a full evaluation.
/// Returns the best `h` found (never worse than the start).
pub(crate) fn pso(
    eval: &mut LocalEval<'_>,
    candidates: &[u32],
    particles: usize,
    iterations: usize,
    seed: u64,
) -> Vec<f64> {
    let dim = candidates.len();
    let start = eval.h.clone();
    if dim == 0 || particles == 0 {
        return start;
    }
    let mut rng = whet_metro::sampling::SplitMix64::new(seed);
    let score = |eval: &mut LocalEval<'_>, x: &[f64]| -> f64 {
        // Full evaluation: set every candidate (the local machinery keeps it exact).
        for (k, &e) in candidates.iter().enumerate() {
            if eval.h[e as usize] != x[k] {
                eval.set(e as usize, x[k]);
            }
        }
        eval.objective()
    };
    let mut xs: Vec<Vec<f64>> = Vec::with_capacity(particles);
    let mut vs: Vec<Vec<f64>> = Vec::with_capacity(particles);
    for p in 0..particles {
        let x: Vec<f64> = if p == 0 {
            candidates.iter().map(|&e| start[e as usize]).collect()
        } else {
            (0..dim).map(|_| rng.next_f64()).collect()
        };
        xs.push(x);
        vs.push((0..dim).map(|_| 0.2 * (rng.next_f64() - 0.5)).collect());
    }
    let mut pbest = xs.clone();
    let mut pscore: Vec<f64> = Vec::with_capacity(particles);
    for x in &xs {
        let s = score(eval, x);
        pscore.push(s);
    }
    let mut g = 0;
    for p in 1..particles {
        if pscore[p] < pscore[g] {
            g = p;
        }
    }
    let mut gbest = pbest[g].clone();
    let mut gscore = pscore[g];
    let (w, c1, c2) = (0.7298, 1.49618, 1.49618);
    for _ in 0..iterations {
        for p in 0..particles {
            for k in 0..dim {
                let (r1, r2) = (rng.next_f64(), rng.next_f64());
                let v = w * vs[p][k]
                    + c1 * r1 * (pbest[p][k] - xs[p][k])
                    + c2 * r2 * (gbest[k] - xs[p][k]);
                vs[p][k] = v.clamp(-0.5, 0.5);
                xs[p][k] = (xs[p][k] + vs[p][k]).clamp(0.0, 1.0);
            }
            let s = score(eval, &xs[p]);
            if s < pscore[p] {
                pscore[p] = s;
                pbest[p] = xs[p].clone();
                if s < gscore {
                    gscore = s;
                    gbest = xs[p].clone();
                }
            }
        }
    }
    score(eval, &gbest);
    eval.h.clone()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::Topology;

    fn octahedron() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let m = whet_testkit::meshes::octahedron();
        (m.positions, m.triangles)
    }

    /// Local updates give exactly the positions a full re-subdivision gives.
    #[test]
    fn local_updates_match_full_evaluation() {
        let (p, t) = octahedron();
        let hier = Hierarchy::new(Topology::new(t, 6).unwrap(), 2).unwrap();
        let ne = hier.levels[0].edges.len();
        let h0 = vec![0.0; ne];
        let nf = hier.finest().triangles.len();
        // One data point per fine triangle, at its centroid pushed outwards.
        let fine = crate::surface::evaluate(
            &hier,
            &h0,
            &p,
            &crate::SubdivOptions::DEFAULT
                .with_levels(2)
                .with_sharp_levels(2),
        );
        let foot: Vec<[u32; 3]> = hier.finest().triangles.clone();
        let bary = vec![DVec3::splat(1.0 / 3.0); nf];
        let target: Vec<DVec3> = foot
            .iter()
            .map(|f| (fine[f[0] as usize] + fine[f[1] as usize] + fine[f[2] as usize]) * 0.4)
            .collect();
        let weight = vec![1.0; nf];
        let mut eval = LocalEval::new(&hier, &h0, &p, foot, bary, target, weight);
        let sequence = [(0, 1.0), (3, 0.5), (7, 1.0), (0, 0.25), (11, 1.0), (3, 0.0)];
        let mut h = h0.clone();
        for (e, v) in sequence {
            let predicted = eval.delta(e, v);
            let before = eval.objective();
            eval.set(e, v);
            h[e] = v;
            assert!((eval.objective() - before - predicted).abs() < 1e-12);
            let full = crate::surface::evaluate(
                &hier,
                &h,
                &p,
                &crate::SubdivOptions::DEFAULT
                    .with_levels(2)
                    .with_sharp_levels(2),
            );
            for (a, b) in full.iter().zip(eval.limit_positions()) {
                assert!((*a - *b).length() < 1e-12, "after h[{e}] = {v}");
            }
        }
    }
}
