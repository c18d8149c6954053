//! The forward swing walk of geometry kinds 7 to 10 (9 and 10 code the swing indices through
//! `swing_neighbours.rs`): the connectivity of the retiled mesh is coded inside the geometry
//! walk, label by label in creation order, so that every label is coded in the context of
//! the geometry already rebuilt around its gate.
//!
//! Both sides run [`front_walk`]: it keeps the retiler's own state (whet-swing `retiler.rs`:
//! the loops bounding the built region as linked lists of nodes, the current gate, a stack of
//! deferred gates) and applies each label the way the retiler applied its move. The
//! retiler's closing decisions depend on the open angles at the gate's ends, the valences
//! they would leave, and whether the swing tip falls near a front neighbour; a decoder has
//! all of these from the decoded positions, so the label's context is made of them:
//!
//! * per gate end (`b` with its front neighbour `b⁺`, `a` with `a⁻`): the open angle of the
//!   candidate closing triangle in 5 bins, the valence the end would close with in 3 bins,
//!   and the length of the edge the closing would add in 4 bins (the retiler snaps a swing
//!   tip that falls near the neighbour; the predicted tip's distance to it codes a little
//!   better but needs a frame at every gate, docs/swing.md);
//! * whether the front is a loop of three.
//!
//! 7200 contexts of adaptive 5-symbol frequency tables. An S label's tip is coded as the rank
//! of its node among the other nodes of the gate's loop ordered by distance to the gate's
//! midpoint (nearly always 0 or 1); a tip on another loop (a handle) escapes to its vertex
//! index.
//! docs/swing.md section 2 has the measurements; docs/format.md the normative layout.

use super::*;
use whet_bits::{SymbolTables, UnsignedIntModel};

const NONE: u32 = u32::MAX;

/// Most nodes of one vertex a search walks: the retiler gives a vertex at most 40
/// triangles, so at most 40 nodes; the cap keeps a hostile stream's searches short.
const MAX_NODES_PER_VERTEX: usize = 64;

/// Label contexts: per gate end 5 wedge bins × 3 valence bins × 4 snap bins, both ends, and
/// the loop-of-three flag.
const SIDE_CONTEXTS: usize = 5 * 3 * 4;
pub(super) const LABEL_CONTEXTS: usize = SIDE_CONTEXTS * SIDE_CONTEXTS * 2;

/// A node of a front loop: vertex `v` with its loop neighbours, the next node of the same
/// vertex, and the third vertex of the built triangle across its loop edge `v -> next`.
#[derive(Clone, Copy, Debug)]
struct Node {
    v: u32,
    prev: u32,
    next: u32,
    same: u32,
    opp: u32,
    alive: bool,
}

/// The loops of the built region and the deferred gates.
#[derive(Debug, Default)]
pub(super) struct Front {
    nodes: Vec<Node>,
    /// Per vertex: its most recent node (then `Node::same`).
    vnode: Vec<u32>,
    /// Deferred gates `(node, a, w)`: the left branch of an S.
    stack: Vec<(u32, u32, u32)>,
}

impl Front {
    fn add_vertex(&mut self) {
        self.vnode.push(NONE);
    }

    fn add_node(&mut self, v: u32, opp: u32) -> u32 {
        let id = self.nodes.len() as u32;
        self.nodes.push(Node {
            v,
            prev: NONE,
            next: NONE,
            same: self.vnode[v as usize],
            opp,
            alive: true,
        });
        self.vnode[v as usize] = id;
        id
    }

    #[inline]
    fn link(&mut self, a: u32, b: u32) {
        self.nodes[a as usize].next = b;
        self.nodes[b as usize].prev = a;
    }

    #[inline]
    fn node(&self, n: u32) -> Node {
        self.nodes[n as usize]
    }

    /// The live node of vertex `v` whose loop edge goes to vertex `x` (front edges are
    /// unique, so there is at most one).
    pub(super) fn node_towards(&self, v: u32, x: u32) -> Option<u32> {
        let mut m = *self.vnode.get(v as usize)?;
        let mut guard = MAX_NODES_PER_VERTEX;
        while m != NONE && guard > 0 {
            let node = self.nodes[m as usize];
            if node.alive && self.nodes[node.next as usize].v == x {
                return Some(m);
            }
            m = node.same;
            guard -= 1;
        }
        None
    }

    /// The live nodes of vertex `v`, most recent first.
    pub(super) fn live_nodes(&self, v: u32) -> Vec<u32> {
        let mut out = Vec::new();
        let mut m = self.vnode.get(v as usize).copied().unwrap_or(NONE);
        let mut guard = MAX_NODES_PER_VERTEX;
        while m != NONE && guard > 0 {
            guard -= 1;
            let node = self.nodes[m as usize];
            if node.alive {
                out.push(m);
            }
            m = node.same;
        }
        out
    }

    /// The deferred gate to continue with, skipping those whose edge was used meanwhile
    /// (the retiler's `pop`: an edge is unused exactly while a live node of `a` leads to `w`).
    fn pop(&mut self) -> Option<u32> {
        while let Some((n, a, w)) = self.stack.pop() {
            let node = self.nodes[n as usize];
            if node.alive && node.v == a && self.nodes[node.next as usize].v == w {
                return Some(n);
            }
            if let Some(m) = self.node_towards(a, w) {
                return Some(m);
            }
        }
        None
    }
}

/// What the walk asks of its reader or writer besides seeds and indices.
pub(super) trait FrontIo: SwingIo {
    /// The label of the next triangle, coded in context `ctx`.
    fn label(&mut self, tables: &mut SymbolTables, ctx: usize) -> Result<Clers, Error>;
    /// The tip node of an S: one of `candidates` (the nodes of the gate's loop, in loop
    /// order) by its rank in [`candidate_order`], or any live node by escape. `triangle` is
    /// the index the S triangle gets. The slice may be reordered.
    fn split_target(
        &mut self,
        front: &Front,
        models: &mut SplitModels,
        candidates: &mut [Candidate],
        triangle: usize,
        vertices: usize,
    ) -> Result<u32, Error>;
}

/// A node that an S could reach: its squared distance to the gate's midpoint, its place in
/// the loop, the node.
pub(super) type Candidate = (f64, u32, u32);

/// The order in which S tips are ranked: nearest to the gate's midpoint first, then in loop
/// order (a total order: the loop places differ).
#[inline]
pub(super) fn candidate_order(x: &Candidate, y: &Candidate) -> std::cmp::Ordering {
    x.0.total_cmp(&y.0).then(x.1.cmp(&y.1))
}

/// Models of the S tips.
pub(super) struct SplitModels {
    pub(super) rank: UnsignedIntModel,
    pub(super) which: UnsignedIntModel,
}

/// Bits of a raw vertex index among `n` vertices.
pub(super) fn vertex_bits(n: usize) -> u32 {
    (usize::BITS - n.saturating_sub(1).leading_zeros()).max(1)
}

/// The open-angle bin of the closing triangle `[w, a, b]` at gate end `at` (the corner
/// between the gate and the front edge to `w`), seen from the fan normal `f` of `at`:
/// under 45, 70, 90, 110 degrees, else (also folded or reflex) the last bin.
#[inline]
fn wedge_bin(at: DVec3, other: DVec3, w: DVec3, tri: DVec3, f: DVec3) -> usize {
    if dot(tri, f) <= 0.0 {
        return 4;
    }
    let (u, v) = (sub(other, at), sub(w, at));
    let uv = dot(u, v);
    let nn = dot(u, u) * dot(v, v);
    if nn.is_nan() || nn <= 0.0 {
        return 4;
    }
    // The cosine uv / sqrt(nn) against cos 45, 70, 90, 110 degrees, compared squared (no
    // root, no division on the decoder's path).
    let uv2 = uv * uv;
    if uv > 0.0 {
        if uv2 > 0.5 * nn {
            0
        } else if uv2 > COS70_SQUARED * nn {
            1
        } else {
            2
        }
    } else if uv2 < COS70_SQUARED * nn {
        3
    } else {
        4
    }
}

/// cos² 70° (= cos² 110°).
const COS70_SQUARED: f64 = 0.116_977_778_440_511_06;

/// The valence bin of a vertex with `k` built triangles, were it closed by one more.
#[inline]
fn valence_bin(k: u32) -> usize {
    // Closing would give k + 1 triangles: 0 under 5, 1 at 5, 2 above (without branches:
    // the bin is data, not control flow).
    (k >= 4) as usize + (k >= 5) as usize
}

/// The length bin of the edge a closing triangle would add between the far gate end `o` and
/// the front neighbour `w`: squared length under 1.0, 1.44, 2.0 `L²`, else the last bin.
#[inline]
fn length_bin(o: DVec3, w: DVec3, inv_l2: f64) -> usize {
    let d = sub(o, w);
    let d2 = dot(d, d) * inv_l2;
    // Counted without branches (the bin is data for the label's coder; branching on it
    // mispredicts); NaN falls in the last bin, as a long edge.
    let d2 = if d2.is_nan() { f64::INFINITY } else { d2 };
    (d2 >= 1.0) as usize + (d2 >= 1.44) as usize + (d2 >= 2.0) as usize
}

/// The mesh a walk rebuilds, with the per-vertex sums its contexts and predictions read.
struct Rebuilt {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    /// Per vertex, the sum of its triangles' cross products.
    fan: Vec<DVec3>,
    /// Per vertex, its triangles (at most the triangle count, which the caller bounds far
    /// below `u32::MAX`).
    built: Vec<u32>,
    /// Per vertex, the sum of the next corners of its triangles, in triangle order: the
    /// surface filter's umbrella sums, gathered here where the walk holds the positions
    /// anyway (the walk waits on its chain of divisions and roots, so these adds cost it
    /// little, and the filter saves a gathering pass).
    next: Vec<DVec3>,
    /// Per vertex, the residual of its swing index in kinds 9 and 10 (0 for seeds and in
    /// kinds 7 and 8).
    residual: Vec<i32>,
}

impl Rebuilt {
    /// Room for about `triangles` triangles (a retiling has about half as many vertices).
    fn with_capacity(triangles: usize) -> Rebuilt {
        let vertices = triangles / 2 + 3;
        Rebuilt {
            positions: Vec::with_capacity(vertices),
            triangles: Vec::with_capacity(triangles),
            fan: Vec::with_capacity(vertices),
            built: Vec::with_capacity(vertices),
            next: Vec::with_capacity(vertices),
            residual: Vec::with_capacity(vertices),
        }
    }

    #[inline]
    fn add_vertex(&mut self, p: DVec3) {
        self.positions.push(p);
        self.fan.push(DVec3::ZERO);
        self.built.push(0);
        self.next.push(DVec3::ZERO);
        self.residual.push(0);
    }

    /// Adds triangle `t` of existing vertices; a triangle repeating a vertex (only a corrupt
    /// stream makes one: the retiler's front never meets itself that way) is an error.
    #[inline(always)]
    fn add_triangle(&mut self, t: [u32; 3]) -> Result<(), Error> {
        let [i, j, k] = t.map(|v| v as usize);
        if i == j || j == k || k == i {
            return Err(repeated_vertex());
        }
        let (p0, p1, p2) = (self.positions[i], self.positions[j], self.positions[k]);
        let n = cross(sub(p1, p0), sub(p2, p0));
        for v in [i, j, k] {
            self.fan[v] = add(self.fan[v], n);
            self.built[v] += 1;
        }
        self.next[i] = add(self.next[i], p1);
        self.next[j] = add(self.next[j], p2);
        self.next[k] = add(self.next[k], p0);
        self.triangles.push(t);
        Ok(())
    }
}

#[cold]
fn repeated_vertex() -> Error {
    Error::Corrupt("swing connectivity: a triangle repeats a vertex".into())
}

/// What [`front_walk`] rebuilt.
pub(super) struct FrontWalk {
    pub(super) positions: Vec<DVec3>,
    pub(super) triangles: Vec<[u32; 3]>,
    /// Per vertex, the sums the surface filter reads: its triangles' cross products (the
    /// normals), their count and their next corners, in triangle order.
    pub(super) sums: crate::surface_filter::WalkSums,
}

/// Walks `components` components of `triangles` triangles in all, coding labels, S tips,
/// seeds and swing indices through `io`, and rebuilds the retiled mesh: positions in
/// creation order, triangles `[tip, a, b]` (seeds `[x0, x1, x2]`) in creation order, exactly
/// what the retiler built. The same code runs in the encoder and the decoder. `capacity`
/// caps what is reserved up front (a decoder passes what its bytes can plausibly hold, not
/// a count a hostile header could inflate).
pub(super) fn front_walk<I: FrontIo>(
    io: &mut I,
    params: &SwingParams,
    coding: ForwardCoding,
    components: usize,
    triangles: usize,
    capacity: usize,
) -> Result<FrontWalk, Error> {
    let corrupt = |what: &str| Error::Corrupt(format!("swing connectivity: {what}"));
    let bits = params.quantizer.bits;
    let angle_bits = params.angles.bits();
    let l = params.edge_length;
    let inv_l2 = 1.0 / (l * l);
    let mut models = SwingModels::new(angle_bits, IndexCoding::Scaled);
    let mut residual_models = neighbours::ResidualModels::new();
    let predictor = neighbours::Predictor::new(&params.angles);
    let mut labels = SymbolTables::new(LABEL_CONTEXTS, 5);
    let mut split = SplitModels {
        rank: UnsignedIntModel::below_2_31(),
        which: UnsignedIntModel::below_2_31(),
    };
    let mut front = Front::default();
    // A retiling has about half as many vertices as triangles.
    let reserve = triangles.min(capacity);
    let mut out = Rebuilt::with_capacity(reserve);
    let mut candidates: Vec<Candidate> = Vec::new();
    // Loop steps spent listing S candidates: bounded, so that a hostile stream cannot make
    // the walk quadratic.
    let mut split_work: usize = 0;
    let split_budget = triangles.saturating_mul(64).saturating_add(1 << 20);
    for _ in 0..components {
        if out.triangles.len() + 1 > triangles {
            return Err(corrupt("more triangles than announced"));
        }
        // The seed [x0, x1, x2]; the loop x0 -> x2 -> x1 -> x0, first gate x0 -> x2.
        let first = out.positions.len() as u32;
        for k in 0..3u32 {
            let mut g = [0i32; 3];
            io.seed(VertexId(first + k), bits, &mut g);
            out.add_vertex(params.quantizer.dequantize(g));
            front.add_vertex();
        }
        let (x0, x1, x2) = (first, first + 1, first + 2);
        out.add_triangle([x0, x1, x2])?;
        let n0 = front.add_node(x0, x1);
        let n2 = front.add_node(x2, x0);
        let n1 = front.add_node(x1, x2);
        front.link(n0, n2);
        front.link(n2, n1);
        front.link(n1, n0);
        let mut gate = n0;
        loop {
            if out.triangles.len() >= triangles {
                return Err(corrupt("more triangles than announced"));
            }
            let an = gate;
            let node_a = front.node(an);
            let bn = node_a.next;
            let node_b = front.node(bn);
            let xn = node_b.next;
            let pn = node_a.prev;
            let (a, b) = (node_a.v, node_b.v);
            let (x, p) = (front.node(xn).v, front.node(pn).v);
            let three = xn == pn;
            let (pa, pb) = (out.positions[a as usize], out.positions[b as usize]);
            let (px, pp) = (out.positions[x as usize], out.positions[p as usize]);
            // Gate end b closes with b⁺ (R), gate end a with a⁻ (L).
            let tri_r = cross(sub(pa, px), sub(pb, px));
            let tri_l = cross(sub(pa, pp), sub(pb, pp));
            let side_b = (wedge_bin(pb, pa, px, tri_r, out.fan[b as usize]) * 3
                + valence_bin(out.built[b as usize]))
                * 4
                + length_bin(pa, px, inv_l2);
            let side_a = (wedge_bin(pa, pb, pp, tri_l, out.fan[a as usize]) * 3
                + valence_bin(out.built[a as usize]))
                * 4
                + length_bin(pb, pp, inv_l2);
            let ctx = (side_a * SIDE_CONTEXTS + side_b) * 2 + three as usize;
            let label = io.label(&mut labels, ctx)?;
            let next = match label {
                Clers::C => {
                    let Some(frame) = params.frame(pa, pb, out.positions[node_a.opp as usize])
                    else {
                        return Err(corrupt("a C on a gate without a swing (2L or flat)"));
                    };
                    let normal = add(out.fan[a as usize], out.fan[b as usize]);
                    let v = out.positions.len() as u32;
                    let mut q = 0i32;
                    let residual = match coding {
                        ForwardCoding::Scaled => {
                            let pred = predict_swing_scaled(&frame, normal, &params.angles);
                            io.index(VertexId(v), models.model(pred), pred, angle_bits, &mut q)?;
                            0
                        }
                        ForwardCoding::Neighbours => {
                            let near = neighbours::Neighbourhood {
                                a: out.residual[a as usize],
                                b: out.residual[b as usize],
                                parent: out.residual[node_a.opp as usize],
                            };
                            let (pred, ctx) = predictor.predict(&frame, normal, px, near);
                            io.neighbour_index(
                                VertexId(v),
                                &mut residual_models,
                                &ctx,
                                pred,
                                angle_bits,
                                &mut q,
                            )?;
                            wrap_index(q - pred, angle_bits)
                        }
                    };
                    out.add_vertex(frame.tip(&params.angles, q));
                    out.residual[v as usize] = residual;
                    front.add_vertex();
                    out.add_triangle([v, a, b])?;
                    // Loop a -> v -> b: edge a -> v faces b, edge v -> b faces a.
                    front.nodes[an as usize].opp = b;
                    let vn = front.add_node(v, a);
                    front.link(an, vn);
                    front.link(vn, bn);
                    Some(vn)
                }
                Clers::R | Clers::L | Clers::E => {
                    if three != (label == Clers::E) {
                        return Err(corrupt(if three {
                            "an R or L on a loop of three"
                        } else {
                            "an E on a loop longer than three"
                        }));
                    }
                    if label == Clers::L {
                        out.add_triangle([p, a, b])?;
                        front.nodes[an as usize].alive = false;
                        front.nodes[pn as usize].opp = a;
                        front.link(pn, bn);
                        Some(pn)
                    } else {
                        out.add_triangle([x, a, b])?;
                        front.nodes[bn as usize].alive = false;
                        if label == Clers::R {
                            front.nodes[an as usize].opp = b;
                            front.link(an, xn);
                            Some(an)
                        } else {
                            front.nodes[an as usize].alive = false;
                            front.nodes[xn as usize].alive = false;
                            None
                        }
                    }
                }
                Clers::S => {
                    // The gate's loop from b⁺⁺ to a⁻⁻ (none on a loop of three: there the
                    // tip is on another loop, by escape).
                    candidates.clear();
                    let target = scale(add(pa, pb), 0.5);
                    let mut m = if three { pn } else { front.node(xn).next };
                    while m != pn {
                        split_work += 1;
                        if split_work > split_budget || m == an {
                            return Err(corrupt("a front loop does not close"));
                        }
                        let d = sub(out.positions[front.node(m).v as usize], target);
                        candidates.push((dot(d, d), candidates.len() as u32, m));
                        m = front.node(m).next;
                    }
                    let wn = io.split_target(
                        &front,
                        &mut split,
                        &mut candidates,
                        out.triangles.len(),
                        out.positions.len(),
                    )?;
                    let node_w = *front
                        .nodes
                        .get(wn as usize)
                        .ok_or_else(|| corrupt("an S tip node out of range"))?;
                    if !node_w.alive || [an, bn, xn, pn].contains(&wn) {
                        return Err(corrupt("an S tip that is not another front node"));
                    }
                    let w = node_w.v;
                    out.add_triangle([w, a, b])?;
                    // W keeps its predecessor and gets b; a new node for w gets W's old
                    // successor and predecessor a.
                    let wnext = node_w.next;
                    let w2 = front.add_node(w, node_w.opp);
                    front.nodes[an as usize].opp = b;
                    front.nodes[wn as usize].opp = a;
                    front.link(an, w2);
                    front.link(w2, wnext);
                    front.link(wn, bn);
                    front.stack.push((an, a, w));
                    Some(wn)
                }
            };
            match next {
                Some(g) => gate = g,
                None => match front.pop() {
                    Some(g) => gate = g,
                    None => break,
                },
            }
        }
    }
    if out.triangles.len() != triangles {
        return Err(corrupt("fewer triangles than announced"));
    }
    Ok(FrontWalk {
        positions: out.positions,
        triangles: out.triangles,
        sums: crate::surface_filter::WalkSums {
            fan: out.fan,
            triangles_at: out.built,
            next_corners: out.next,
        },
    })
}
