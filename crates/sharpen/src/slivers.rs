//! The output triangle list and the sliver pass (seed 001 section 3.3: "a triangle having at
//! least one angle smaller than 1 degree ... we simply collapse the edge which is opposite to
//! such an acute corner and update the connectivity graph consistently").
//!
//! The output keeps the input's triangle order: each input triangle becomes one *slot* or, if
//! it was subdivided, the contiguous slots of its pieces. Pieces are *new* triangles, and so is
//! any triangle an operation below changes. The pass fixes, smallest angle first, every new
//! triangle with an angle under the threshold or whose normal points against the area it
//! replaces (`Run::reference_normal`), choosing among these operations:
//!
//! - the papers' one: collapse the edge opposite the smallest angle, removing its new end
//!   (input vertices are never removed); taken whenever it is valid and leaves no thin
//!   triangle;
//! - if it is not valid, merging a new vertex into a neighbour at the same point (of the
//!   triangle's vertices or of theirs), which changes no geometry: a cluster of three
//!   coincident corner vertices has no valid collapse inside one of its triangles;
//! - otherwise the best valid one (largest smallest angle among the triangles it makes) of:
//!   collapsing any edge of the triangle with a new end, collapsing a new vertex back into an
//!   end of the edge it split (undoing the split), and flipping an edge of the triangle. Flips
//!   remove the thin triangles no collapse can: needles on the near-zero-length edges that
//!   marching cubes makes between two input vertices, and caps.
//!
//! An operation is valid when it keeps the mesh an oriented manifold (collapse: the link
//! condition and no duplicate triangle; flip: the new edge does not exist yet), reverses no
//! triangle against the area it replaces, and does not make a thin triangle that only a change
//! of input vertices could fix. When no operation is valid the triangle's snapped (or moved)
//! vertices go back to their rest positions, and when it has none its input triangle is
//! *restored*: put back as it was in the input, with its split edges unsplit. A neighbour across
//! such an edge that no operation has changed yet (*pristine*) is simply re-cut with one split
//! fewer (the pieces are a function of which edges are split); a changed one is restored too,
//! together with every triangle the same operations changed (an operation's triangles share
//! vertices and edges that only exist together). The restored region's border edges are then
//! input edges on both sides, so the mesh stays a manifold with the input's boundary.
//!
//! Each step removes a vertex, replaces a thin triangle by better ones, unsnaps a vertex for
//! good or restores input triangles for good; flips are bounded by a budget proportional to the
//! number of new triangles, after which only the other steps run. So the pass ends, and at its
//! end no new triangle is thin or reversed.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use glam::DVec3;
use whet_mesh::{FaceId, Mesh, VertexId};

use crate::edge_sharpener::{min_angle, Run, NONE, SNAPPED, T_TOUCHED, V_MOVED};
use crate::report::UnmovedReason;

/// The output under construction.
pub(crate) struct Output {
    tris: Vec<[u32; 3]>,
    alive: Vec<bool>,
    /// Input triangle of each slot.
    parent: Vec<u32>,
    is_new: Vec<bool>,
    /// Slot of each input triangle (its first piece when subdivided).
    slot_of_input: Vec<u32>,
    /// Per touched input triangle (in `Scratch::touched` order): first slot and count.
    ranges: Vec<(u32, u8)>,
    /// The sliver threshold, radians.
    min_angle_rad: f64,
}

/// The memory of an [`Output`]'s slots and of its slot lists' per-vertex arrays, kept in
/// the run's scratch between runs.
#[derive(Clone, Debug, Default)]
pub(crate) struct SlotArrays {
    tris: Vec<[u32; 3]>,
    alive: Vec<bool>,
    parent: Vec<u32>,
    is_new: Vec<bool>,
    slot_of_input: Vec<u32>,
    head: Vec<u32>,
    tail: Vec<u32>,
    len: Vec<u32>,
}

/// Union-find with path halving that also lists each set's members: a linked list per set
/// that starts at its root, the smaller list appended to the larger (so a member moves
/// O(log n) times), in flat arrays rather than one vector per set.
struct Groups {
    parent: Vec<u32>,
    /// Next member in its set's list, `NONE` at the end.
    next: Vec<u32>,
    /// At a root: the last member of its list, and the set's size.
    tail: Vec<u32>,
    size: Vec<u32>,
}

impl Groups {
    fn new(n: usize) -> Groups {
        Groups {
            parent: (0..n as u32).collect(),
            next: vec![NONE; n],
            tail: (0..n as u32).collect(),
            size: vec![1; n],
        }
    }
    fn push(&mut self) -> u32 {
        let i = self.parent.len() as u32;
        self.parent.push(i);
        self.next.push(NONE);
        self.tail.push(i);
        self.size.push(1);
        i
    }
    fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let g = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = g;
            x = g;
        }
        x
    }
    fn union(&mut self, a: u32, b: u32) {
        let (a, b) = (self.find(a), self.find(b));
        if a == b {
            return;
        }
        let (big, small) = if self.size[a as usize] >= self.size[b as usize] {
            (a, b)
        } else {
            (b, a)
        };
        self.parent[small as usize] = big;
        let end = self.tail[big as usize];
        self.next[end as usize] = small;
        self.tail[big as usize] = self.tail[small as usize];
        self.size[big as usize] += self.size[small as usize];
    }
    /// Appends the members of `x`'s set to `out`, in the order the unions listed them.
    fn members_of(&mut self, x: u32, out: &mut Vec<u32>) {
        let mut m = self.find(x);
        while m != NONE {
            out.push(m);
            m = self.next[m as usize];
        }
    }
}

/// Per-vertex lists of slots, each in the order its slots were added, as linked lists in one
/// arena (a sharpening makes thousands of short lists; one vector each cost more in the
/// allocator than the sliver pass itself).
struct SlotLists {
    /// Per vertex: first and last node, `NONE` when empty.
    head: Vec<u32>,
    tail: Vec<u32>,
    /// Per vertex: nodes in its list.
    len: Vec<u32>,
    /// Per node: its slot and the next node.
    slot: Vec<u32>,
    next: Vec<u32>,
    /// `(vertex, slot)` keys of the lists longer than [`Self::SCAN`]: their membership test
    /// is a lookup, not a walk (a vertex of high valence gathers as many slots as it has
    /// triangles, and walking its list at each push was quadratic in its valence).
    long: std::collections::HashSet<u64>,
}

impl SlotLists {
    /// Longest list whose membership test walks it.
    const SCAN: u32 = 32;

    /// Empty lists for `vertex_count` vertices, in the memory of `arrays` (given back by
    /// [`SlotLists::recycle`]).
    fn new(vertex_count: usize, arrays: &mut SlotArrays) -> SlotLists {
        let take = |v: &mut Vec<u32>, x: u32| {
            let mut v = std::mem::take(v);
            v.clear();
            v.resize(vertex_count, x);
            v
        };
        SlotLists {
            head: take(&mut arrays.head, NONE),
            tail: take(&mut arrays.tail, NONE),
            len: take(&mut arrays.len, 0),
            slot: Vec::new(),
            next: Vec::new(),
            long: Default::default(),
        }
    }

    fn recycle(self, arrays: &mut SlotArrays) {
        arrays.head = self.head;
        arrays.tail = self.tail;
        arrays.len = self.len;
    }
    fn key(v: u32, s: u32) -> u64 {
        (u64::from(v) << 32) | u64::from(s)
    }
    /// Lists slot `s` at `v`, once: a slot can come back to a vertex (a re-cut triangle, a
    /// flip, a collapse into a vertex the slot held before), and a slot listed twice would be
    /// seen twice by a collapse, which kills a triangle holding both of its ends: the second
    /// visit found the first one's result and opened a hole.
    fn push(&mut self, v: u32, s: u32) {
        let len = self.len[v as usize];
        if len < Self::SCAN {
            if self.iter(v).any(|x| x == s) {
                return;
            }
        } else {
            if len == Self::SCAN {
                // The list becomes long: its keys move into the set.
                let keys: Vec<u64> = self.iter(v).map(|x| Self::key(v, x)).collect();
                self.long.extend(keys);
            }
            if !self.long.insert(Self::key(v, s)) {
                return;
            }
        }
        self.len[v as usize] = len + 1;
        let node = self.slot.len() as u32;
        self.slot.push(s);
        self.next.push(NONE);
        let v = v as usize;
        match self.tail[v] {
            NONE => self.head[v] = node,
            t => self.next[t as usize] = node,
        }
        self.tail[v] = node;
    }
    fn clear(&mut self, v: u32) {
        if self.len[v as usize] > Self::SCAN {
            let keys: Vec<u64> = self.iter(v).map(|x| Self::key(v, x)).collect();
            for k in keys {
                self.long.remove(&k);
            }
        }
        self.head[v as usize] = NONE;
        self.tail[v as usize] = NONE;
        self.len[v as usize] = 0;
    }
    fn iter(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        let mut node = self.head[v as usize];
        std::iter::from_fn(move || {
            (node != NONE).then(|| {
                let s = self.slot[node as usize];
                node = self.next[node as usize];
                s
            })
        })
    }
}

/// Local topology of the new triangles, built only when a bad one exists.
struct Local {
    /// New slots around each vertex that has one (filter: dead, restored, or no longer
    /// holding the vertex).
    slots: SlotLists,
    /// Touched triangles changed together by operations (restored together).
    groups: Groups,
    /// Per touched index: no operation changed its pieces yet.
    pristine: Vec<bool>,
    /// Flips left.
    flip_budget: usize,
}

/// An operation of the pass.
#[derive(Clone, Copy, Debug)]
enum Op {
    /// Remove new vertex `u`, merging it into `w`.
    Collapse { u: u32, w: u32 },
    /// Flip the edge of slot `s` opposite its corner `k`; `s2` is the slot across.
    Flip { s: u32, k: u8, s2: u32 },
}

/// Two vertices closer than this fraction of a triangle's longest edge are one point to the
/// sliver pass's coincident merge (vertices moved onto one corner point differ by rounding).
const COINCIDENT: f64 = 1e-6;

/// Triangle equality up to rotation (same orientation).
#[inline]
fn same_triangle(a: [u32; 3], b: [u32; 3]) -> bool {
    a == b || a == [b[1], b[2], b[0]] || a == [b[2], b[0], b[1]]
}

/// Whether a later collapse surely can fix the thin triangle `q` (positions `p`): it is a
/// needle (its shortest edge under half the next one) whose short edge has a new end. An
/// operation may leave such a triangle behind (clusters of coincident new vertices collapse
/// one by one), but never any other thin triangle.
fn fixable(q: &[u32; 3], p: &[DVec3; 3], nv: u32) -> bool {
    let l = [0, 1, 2].map(|k| p[k].distance_squared(p[(k + 1) % 3]));
    let k = (0..3).min_by(|&i, &j| l[i].total_cmp(&l[j])).unwrap_or(0);
    let second = l[(k + 1) % 3].min(l[(k + 2) % 3]);
    // A needle (one edge much shorter than the others) with a new end on that edge: a
    // collapse of it fixes the triangle. Caps and needles on input edges are refused.
    l[k] < 0.25 * second && (q[k] >= nv || q[(k + 1) % 3] >= nv)
}

impl Output {
    /// Lays out the output triangles from the run's subdivision.
    pub(crate) fn assemble(run: &mut Run) -> Output {
        let nt = run.mesh.triangles.len();
        let extra = run.s.touched.len() * 3;
        // The slot arrays of the last run, emptied.
        fn empty<T>(v: &mut Vec<T>, n: usize) -> Vec<T> {
            let mut v = std::mem::take(v);
            v.clear();
            v.reserve(n);
            v
        }
        let a = &mut run.s.slots;
        let mut o = Output {
            tris: empty(&mut a.tris, nt + extra),
            alive: empty(&mut a.alive, nt + extra),
            parent: empty(&mut a.parent, nt + extra),
            is_new: empty(&mut a.is_new, nt + extra),
            slot_of_input: empty(&mut a.slot_of_input, nt),
            ranges: Vec::with_capacity(run.s.touched.len()),
            min_angle_rad: run.opts.min_angle_degrees.to_radians(),
        };
        for (t, tri) in run.mesh.triangles.iter().enumerate() {
            o.slot_of_input.push(o.tris.len() as u32);
            if run.s.tflags[t] & T_TOUCHED != 0 {
                let (pieces, n) = run.pieces(t);
                o.ranges.push((o.tris.len() as u32, n as u8));
                for p in &pieces[..n] {
                    o.tris.push(*p);
                    o.parent.push(t as u32);
                    o.is_new.push(true);
                }
            } else {
                o.tris.push(*tri);
                o.parent.push(t as u32);
                o.is_new.push(false);
            }
        }
        o.alive.resize(o.tris.len(), true);
        o
    }

    fn points(&self, run: &Run, s: usize) -> [DVec3; 3] {
        self.tris[s].map(|v| run.positions[v as usize])
    }

    /// `Some(smallest angle)` when new slot `s` needs fixing. A slot that is its input
    /// triangle again (its vertices unmoved) never does: input slivers are not ours to fix.
    fn badness(&self, run: &Run, s: usize) -> Option<f64> {
        if same_triangle(self.tris[s], run.mesh.triangles[self.parent[s] as usize])
            && self.tris[s].iter().all(|&v| !run.is_snapped(v))
        {
            return None;
        }
        let p = self.points(run, s);
        let a = min_angle(&p);
        (a < self.min_angle_rad || run.is_reversed(&self.tris[s], self.parent[s] as usize, &p))
            .then_some(a)
    }

    /// [`Output::badness`] before any operation, using what settling found: a piece it last
    /// saw neither thin nor reversed needs only the thin test (same answer, since nothing
    /// moved since).
    fn initial_badness(&self, run: &Run, s: usize) -> Option<f64> {
        let i = run.s.touched_index[self.parent[s] as usize];
        let known_ok = i != NONE && {
            let (start, n) = self.ranges[i as usize];
            let k = s.wrapping_sub(start as usize);
            k < n as usize
                && run
                    .s
                    .settled_ok
                    .get(i as usize)
                    .is_some_and(|m| m >> k & 1 == 1)
        };
        if !known_ok {
            return self.badness(run, s);
        }
        if same_triangle(self.tris[s], run.mesh.triangles[self.parent[s] as usize])
            && self.tris[s].iter().all(|&v| !run.is_snapped(v))
        {
            return None;
        }
        let a = min_angle(&self.points(run, s));
        (a < self.min_angle_rad).then_some(a)
    }

    fn push_bad(&self, run: &Run, heap: &mut BinaryHeap<Reverse<(u64, u32)>>, s: usize) {
        if self.alive[s] && self.is_new[s] {
            if let Some(a) = self.badness(run, s) {
                heap.push(Reverse((a.to_bits(), s as u32)));
            }
        }
    }

    /// The sliver pass (module docs).
    pub(crate) fn remove_slivers(&mut self, run: &mut Run) {
        let mut heap: BinaryHeap<Reverse<(u64, u32)>> = BinaryHeap::new();
        for s in 0..self.tris.len() {
            if self.alive[s] && self.is_new[s] {
                let bad = self.initial_badness(run, s);
                // Test builds check the shortcut against the full test on every sharpening.
                debug_assert_eq!(
                    bad.map(f64::to_bits),
                    self.badness(run, s).map(f64::to_bits),
                    "slot {s}"
                );
                if let Some(a) = bad {
                    heap.push(Reverse((a.to_bits(), s as u32)));
                }
            }
        }
        if heap.is_empty() {
            return;
        }
        let mut arrays = std::mem::take(&mut run.s.slots);
        let mut local = self.build_local(run, &mut arrays);
        let mut retreats: Vec<u8> = Vec::new();
        while let Some(Reverse((_, s))) = heap.pop() {
            let s = s as usize;
            if !self.alive[s] || !self.is_new[s] || self.badness(run, s).is_none() {
                continue;
            }
            if let Some(op) = self.best_op(run, &local, s) {
                let changed = self.apply(run, &mut local, op);
                for x in changed {
                    self.push_bad(run, &mut heap, x as usize);
                }
                continue;
            }
            let snapped: Vec<u32> = self.tris[s]
                .iter()
                .copied()
                .filter(|&v| run.is_snapped(v))
                .collect();
            if !snapped.is_empty() {
                for &v in &snapped {
                    if !run.retreat(v, UnmovedReason::Sliver, &mut retreats) {
                        run.unsnap(v, UnmovedReason::Sliver);
                    }
                }
                for v in snapped {
                    let around: Vec<usize> = self.slots_at(&local, v).collect();
                    for x in around {
                        self.push_bad(run, &mut heap, x);
                    }
                }
                continue;
            }
            let changed = self.restore(run, &mut local, s);
            for x in changed {
                self.push_bad(run, &mut heap, x as usize);
            }
        }
        local.slots.recycle(&mut arrays);
        run.s.slots = arrays;
    }

    fn build_local(&self, run: &Run, arrays: &mut SlotArrays) -> Local {
        let mut slots = SlotLists::new(run.positions.len(), arrays);
        for s in 0..self.tris.len() {
            if self.is_new[s] {
                for &v in &self.tris[s] {
                    slots.push(v, s as u32);
                }
            }
        }
        let touched_index = &run.s.touched_index;
        let n = run.s.touched.len();
        let mut groups = Groups::new(n);
        let mut pristine = vec![true; n];
        // A moved input vertex's triangles move together.
        let nv = run.mesh.positions.len();
        for v in 0..nv as u32 {
            if run.s.vflags[v as usize] & V_MOVED == 0 {
                continue;
            }
            let mut first = None;
            // Every new slot's parent is touched (pieces, or triangles around a moved vertex).
            for s in slots.iter(v) {
                let i = touched_index[self.parent[s as usize] as usize];
                if i == NONE {
                    continue;
                }
                pristine[i as usize] = false;
                match first {
                    None => first = Some(i),
                    Some(f) => groups.union(f, i),
                }
            }
        }
        // Twin corner triangles share their centre's fan: one goes back only with the other.
        for &(t, u) in &run.twins {
            let (i, j) = (touched_index[t as usize], touched_index[u as usize]);
            if t < u && i != NONE && j != NONE {
                groups.union(i, j);
                pristine[i as usize] = false;
                pristine[j as usize] = false;
            }
        }
        let new_count = self.is_new.iter().filter(|&&x| x).count();
        Local {
            slots,
            groups,
            pristine,
            flip_budget: 4 * new_count + 16,
        }
    }

    /// Alive new slots holding `v`.
    fn slots_at<'a>(&'a self, local: &'a Local, v: u32) -> impl Iterator<Item = usize> + 'a {
        local
            .slots
            .iter(v)
            .map(|s| s as usize)
            .filter(move |&s| self.alive[s] && self.is_new[s] && self.tris[s].contains(&v))
    }

    /// Every triangle of the current output at vertex `v` as (slot, vertices): its alive new
    /// slots, and for an input vertex the input triangles around it that are in the output as
    /// themselves.
    fn triangles_at(&self, run: &Run, local: &Local, v: u32, out: &mut Vec<(u32, [u32; 3])>) {
        out.clear();
        out.extend(self.slots_at(local, v).map(|s| (s as u32, self.tris[s])));
        if (v as usize) < run.mesh.positions.len() {
            for c in run.table.vertex_corners(VertexId(v)) {
                let t = c.index() / 3;
                if run.s.tflags[t] & T_TOUCHED == 0 {
                    out.push((self.slot_of_input[t], run.mesh.triangles[t]));
                }
            }
        }
    }

    /// The operation that fixes slot `s` best, if any is valid.
    fn best_op(&self, run: &Run, local: &Local, s: usize) -> Option<Op> {
        let tri = self.tris[s];
        let p = self.points(run, s);
        let nv = run.mesh.positions.len() as u32;
        // Corners by their angle, smallest first: by the length of the opposite side, which
        // orders them exactly (the larger side faces the larger angle) and, unlike an angle,
        // stays defined where two vertices coincide (a zero-length side faces the zero angle;
        // both angles at its ends are undefined).
        let mut order: [(f64, usize); 3] =
            [0, 1, 2].map(|k| (p[(k + 1) % 3].distance_squared(p[(k + 2) % 3]), k));
        order.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut best: Option<(f64, Op)> = None;
        let consider = |q: Option<f64>, op: Op, best: &mut Option<(f64, Op)>| {
            if let Some(q) = q {
                let wins = match best {
                    None => true,
                    Some((bq, _)) => q > *bq,
                };
                if wins {
                    *best = Some((q, op));
                }
            }
        };
        // The papers' collapse: the edge opposite the smallest angle.
        let k0 = order[0].1;
        let (a, b) = (tri[(k0 + 1) % 3], tri[(k0 + 2) % 3]);
        for (u, w) in [(a, b), (b, a)] {
            if u >= nv {
                consider(
                    self.collapse_quality(run, local, u, w),
                    Op::Collapse { u, w },
                    &mut best,
                );
            }
        }
        if let Some((q, op)) = best {
            if q >= self.min_angle_rad {
                return Some(op);
            }
        }
        // A new vertex coinciding with a neighbour merges into it first, whether or not that
        // neighbour is in this triangle: it changes no geometry. Where three vertices of a
        // corner coincide (a moved corner vertex, a split joined to the corner and a centre)
        // no pair of them in one triangle may collapse first (a third common neighbour), and
        // the best of the rest moved the split onto an end of its edge, cutting the corner
        // again (synth fandisk 64 r0).
        if best.is_none() {
            if let Some(op) = self.coincident_merge(run, local, &tri, &p) {
                return Some(op);
            }
        }
        // Everything else.
        for &(_, k) in &order[1..] {
            let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            for (u, w) in [(a, b), (b, a)] {
                if u >= nv {
                    consider(
                        self.collapse_quality(run, local, u, w),
                        Op::Collapse { u, w },
                        &mut best,
                    );
                }
            }
        }
        for &u in &tri {
            if u >= nv {
                for w in run.origin_vertices(u) {
                    if !tri.contains(&w) {
                        consider(
                            self.collapse_quality(run, local, u, w),
                            Op::Collapse { u, w },
                            &mut best,
                        );
                    }
                }
            }
        }
        if local.flip_budget > 0 {
            for k in 0..3 {
                if let Some((q, s2)) = self.flip_quality(run, local, s, k) {
                    consider(
                        Some(q),
                        Op::Flip {
                            s: s as u32,
                            k: k as u8,
                            s2,
                        },
                        &mut best,
                    );
                }
            }
        }
        best.map(|(_, op)| op)
    }

    /// A valid collapse of a new vertex into a neighbour at the same position, for a vertex of
    /// `tri` (positions `p`) or a neighbour of one: the one whose triangles come out best.
    fn coincident_merge(
        &self,
        run: &Run,
        local: &Local,
        tri: &[u32; 3],
        p: &[DVec3; 3],
    ) -> Option<Op> {
        let nv = run.mesh.positions.len() as u32;
        let longest = (0..3)
            .map(|k| p[k].distance_squared(p[(k + 1) % 3]))
            .fold(0.0f64, f64::max);
        let tol2 = COINCIDENT * COINCIDENT * longest;
        let mut best: Option<(f64, Op)> = None;
        let mut around = Vec::new();
        for &x in tri {
            self.triangles_at(run, local, x, &mut around);
            let px = run.positions[x as usize];
            for y in Self::neighbours(&around, x) {
                if run.positions[y as usize].distance_squared(px) > tol2 {
                    continue;
                }
                for (u, w) in [(x, y), (y, x)] {
                    if u < nv {
                        continue;
                    }
                    if let Some(q) = self.collapse_quality(run, local, u, w) {
                        if best.as_ref().is_none_or(|(bq, _)| q > *bq) {
                            best = Some((q, Op::Collapse { u, w }));
                        }
                    }
                }
            }
        }
        best.map(|(_, op)| op)
    }

    /// Sorted, deduplicated neighbours of `v` from its triangles.
    fn neighbours(tris: &[(u32, [u32; 3])], v: u32) -> Vec<u32> {
        let mut n: Vec<u32> = tris
            .iter()
            .flat_map(|(_, t)| t.iter().copied())
            .filter(|&x| x != v)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    }

    /// If collapsing new vertex `u` into `w` is valid, the smallest angle of the triangles it
    /// changes (infinite when it changes none that matter).
    fn collapse_quality(&self, run: &Run, local: &Local, u: u32, w: u32) -> Option<f64> {
        let nv = run.mesh.positions.len() as u32;
        let mut around_u = Vec::new();
        self.triangles_at(run, local, u, &mut around_u);
        let across = around_u.iter().filter(|(_, t)| t.contains(&w)).count();
        if across != 2 {
            return None;
        }
        let mut around_w = Vec::new();
        self.triangles_at(run, local, w, &mut around_w);
        // Link condition: u and w share exactly the two vertices opposite their edge.
        let nu = Self::neighbours(&around_u, u);
        let nw = Self::neighbours(&around_w, w);
        if nu.iter().filter(|x| nw.binary_search(x).is_ok()).count() != 2 {
            return None;
        }
        let mut quality = f64::INFINITY;
        for &(s, t) in &around_u {
            if t.contains(&w) {
                continue;
            }
            let q = t.map(|x| if x == u { w } else { x });
            let mut key = q;
            key.sort_unstable();
            if around_w.iter().any(|(_, x)| {
                let mut k = *x;
                k.sort_unstable();
                k == key
            }) {
                return None;
            }
            let parent = self.parent[s as usize] as usize;
            if same_triangle(q, run.mesh.triangles[parent]) {
                // Back to the input triangle: always acceptable, and not ours to judge.
                continue;
            }
            let p = q.map(|x| run.positions[x as usize]);
            if run.is_reversed(&q, parent, &p) {
                return None;
            }
            let a = min_angle(&p);
            if a < self.min_angle_rad && !fixable(&q, &p, nv) {
                return None;
            }
            quality = quality.min(a);
        }
        Some(quality)
    }

    /// The slot across the edge `a -> b` of slot `s` (the triangle holding `b -> a`).
    fn across(&self, run: &Run, local: &Local, s: usize, a: u32, b: u32) -> Option<usize> {
        let mut around = Vec::new();
        self.triangles_at(run, local, a, &mut around);
        around.into_iter().find_map(|(x, t)| {
            let x = x as usize;
            let has = (0..3).any(|k| t[k] == b && t[(k + 1) % 3] == a);
            (x != s && has).then_some(x)
        })
    }

    /// If flipping the edge of slot `s` opposite its corner `k` is valid, the smallest angle of
    /// the two triangles it makes, and the slot across.
    fn flip_quality(&self, run: &Run, local: &Local, s: usize, k: usize) -> Option<(f64, u32)> {
        let nv = run.mesh.positions.len() as u32;
        let t = self.tris[s];
        let (c, a, b) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        let s2 = self.across(run, local, s, a, b)?;
        let t2 = self.tris[s2];
        let d = t2.iter().copied().find(|&x| x != a && x != b)?;
        if d == c {
            return None;
        }
        let mut around_c = Vec::new();
        self.triangles_at(run, local, c, &mut around_c);
        if Self::neighbours(&around_c, c).binary_search(&d).is_ok() {
            return None; // the edge c-d exists already
        }
        let q1 = [c, a, d];
        let q2 = [c, d, b];
        let mut quality = f64::INFINITY;
        for (q, slot) in [(q1, s), (q2, s2)] {
            let p = q.map(|x| run.positions[x as usize]);
            let parent = self.parent[slot] as usize;
            if run.is_reversed(&q, parent, &p) {
                return None;
            }
            let a = min_angle(&p);
            if a < self.min_angle_rad && !fixable(&q, &p, nv) {
                return None;
            }
            quality = quality.min(a);
        }
        // A flip must improve on what it replaces, or two flips could undo each other.
        let before = min_angle(&self.points(run, s)).min(min_angle(&self.points(run, s2)));
        (quality > before).then_some((quality, s2 as u32))
    }

    /// Applies `op`; returns the slots it changed.
    fn apply(&mut self, run: &mut Run, local: &mut Local, op: Op) -> Vec<u32> {
        match op {
            Op::Collapse { u, w } => self.collapse(run, local, u, w),
            Op::Flip { s, k, s2 } => self.flip(run, local, s as usize, k as usize, s2 as usize),
        }
    }

    fn collapse(&mut self, run: &mut Run, local: &mut Local, u: u32, w: u32) -> Vec<u32> {
        let nv = run.mesh.positions.len() as u32;
        let us: Vec<usize> = self.slots_at(local, u).collect();
        // Every triangle the collapse changes (around u) and the ones holding w are restored
        // together, if ever.
        let mut changed_parents: Vec<u32> = us
            .iter()
            .map(|&s| run.s.touched_index[self.parent[s] as usize])
            .filter(|&i| i != NONE)
            .collect();
        if w >= nv {
            changed_parents.extend(
                self.slots_at(local, w)
                    .map(|s| run.s.touched_index[self.parent[s] as usize])
                    .filter(|&i| i != NONE),
            );
        }
        if let Some(&first) = changed_parents.first() {
            for &i in &changed_parents {
                local.pristine[i as usize] = false;
                local.groups.union(first, i);
            }
        }
        let mut moved = Vec::new();
        for s in us {
            if self.tris[s].contains(&w) {
                self.alive[s] = false;
                run.report.collapsed_triangles += 1;
                continue;
            }
            for x in self.tris[s].iter_mut() {
                if *x == u {
                    *x = w;
                }
            }
            if same_triangle(self.tris[s], run.mesh.triangles[self.parent[s] as usize])
                && self.tris[s]
                    .iter()
                    .all(|&v| run.s.vflags[v as usize] & V_MOVED == 0)
            {
                // The collapse undid the split on this side: the input triangle is back
                // (possibly an input sliver, which is not ours to fix).
                self.is_new[s] = false;
            } else {
                moved.push(s as u32);
            }
        }
        local.slots.clear(u);
        for &s in &moved {
            local.slots.push(w, s);
        }
        let mut changed: Vec<u32> = self.slots_at(local, w).map(|s| s as u32).collect();
        changed.sort_unstable();
        changed.dedup();
        changed
    }

    /// Makes input triangle slot `s` (an untouched one) part of the local structure.
    fn touch(&mut self, run: &mut Run, local: &mut Local, s: usize) {
        if self.is_new[s] {
            return;
        }
        let t = self.parent[s];
        run.s.tflags[t as usize] |= T_TOUCHED;
        let i = run.s.touched.len() as u32;
        run.s.touched.push(t);
        self.ranges.push((s as u32, 1));
        run.s.touched_index[t as usize] = i;
        local.groups.push();
        local.pristine.push(false);
        self.is_new[s] = true;
        for &v in &self.tris[s] {
            local.slots.push(v, s as u32);
        }
    }

    fn flip(
        &mut self,
        run: &mut Run,
        local: &mut Local,
        s: usize,
        k: usize,
        s2: usize,
    ) -> Vec<u32> {
        local.flip_budget = local.flip_budget.saturating_sub(1);
        self.touch(run, local, s2);
        let t = self.tris[s];
        let (c, a, b) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
        let d = self.tris[s2]
            .iter()
            .copied()
            .find(|&x| x != a && x != b)
            .unwrap_or(c); // flip_quality found d: the slot across holds a third vertex
        self.tris[s] = [c, a, d];
        self.tris[s2] = [c, d, b];
        local.slots.push(d, s as u32);
        local.slots.push(c, s2 as u32);
        // Both parents are touched: s is new, s2 was touched above.
        let (i1, i2) = (
            run.s.touched_index[self.parent[s] as usize],
            run.s.touched_index[self.parent[s2] as usize],
        );
        if i1 != NONE && i2 != NONE {
            local.groups.union(i1, i2);
            local.pristine[i1 as usize] = false;
            local.pristine[i2 as usize] = false;
        }
        vec![s as u32, s2 as u32]
    }

    /// Restores the input triangle of slot `s` (module docs): unsplits its edges, re-cuts
    /// pristine neighbours, restores changed ones with their groups. Returns the slots that
    /// changed and may need checking.
    fn restore(&mut self, run: &mut Run, local: &mut Local, s: usize) -> Vec<u32> {
        let mut changed: Vec<u32> = Vec::new();
        let mut work: Vec<u32> = vec![self.parent[s]];
        let mut members: Vec<u32> = Vec::new();
        while let Some(t) = work.pop() {
            let t = t as usize;
            if run.s.tflags[t] & T_TOUCHED == 0 {
                continue; // restored already, or never touched
            }
            let i = run.s.touched_index[t];
            if i == NONE {
                continue;
            }
            // Its group goes back with it.
            members.clear();
            local.groups.members_of(i, &mut members);
            for &j in &members {
                let u = run.s.touched[j as usize];
                if u as usize != t && run.s.tflags[u as usize] & T_TOUCHED != 0 {
                    work.push(u);
                }
            }
            run.s.tflags[t] &= !T_TOUCHED;
            local.pristine[i as usize] = false;
            for k in 0..3 {
                let c = 3 * t + k;
                if run.s.edge_vertex[c] == NONE {
                    continue;
                }
                run.s.edge_vertex[c] = NONE;
                let Some(o) = run.table.opposite(whet_mesh::CornerId(c as u32)) else {
                    continue;
                };
                run.s.edge_vertex[o.index()] = NONE;
                let t2 = o.index() / 3;
                if run.s.tflags[t2] & T_TOUCHED == 0 {
                    continue;
                }
                let i2 = run.s.touched_index[t2];
                if i2 == NONE {
                    continue;
                }
                if local.pristine[i2 as usize] {
                    changed.extend(self.recut(run, local, t2, i2));
                } else {
                    work.push(t2 as u32);
                }
            }
            if let Some(c) = run.s.center.get_mut(t) {
                *c = NONE;
            }
            let (start, n) = self.ranges[i as usize];
            let start = start as usize;
            self.tris[start] = run.mesh.triangles[t];
            self.alive[start] = true;
            self.is_new[start] = false;
            for x in start + 1..start + n as usize {
                self.alive[x] = false;
                self.is_new[x] = false;
            }
            for v in run.mesh.triangles[t] {
                if run.s.vflags[v as usize] & V_MOVED != 0 {
                    // Back to its input position: its other triangles change shape.
                    run.unsnap(v, UnmovedReason::Sliver);
                    changed.extend(self.slots_at(local, v).map(|x| x as u32));
                }
            }
            run.report.restored_triangles += 1;
        }
        changed
    }

    /// Re-cuts pristine touched triangle `t` (touched index `i`) from its current split edges.
    fn recut(&mut self, run: &Run, local: &mut Local, t: usize, i: u32) -> Vec<u32> {
        let (pieces, n) = run.pieces(t);
        let (start, count) = self.ranges[i as usize];
        let start = start as usize;
        let mut changed = Vec::with_capacity(n);
        for k in 0..count as usize {
            let slot = start + k;
            if k < n {
                self.tris[slot] = pieces[k];
                self.alive[slot] = true;
                self.is_new[slot] = true;
                for &v in &pieces[k] {
                    local.slots.push(v, slot as u32);
                }
                changed.push(slot as u32);
            } else {
                self.alive[slot] = false;
                self.is_new[slot] = false;
            }
        }
        changed
    }

    /// Compacts the output: drops dead slots and unreferenced new vertices, fills the report.
    pub(crate) fn finish(self, run: &mut Run) -> (Mesh, Vec<FaceId>) {
        let nv = run.mesh.positions.len();
        let total = run.positions.len();
        let mut remap: Vec<u32> = vec![NONE; total - nv];
        // Room for the triangles welding removed, which putting clusters back may return
        // (growing a million-triangle output afterwards would copy it).
        let spare = run.weld_patch.map_or(0, |p| {
            p.input
                .triangles
                .len()
                .saturating_sub(p.welded.mesh.triangles.len())
        });
        // In the memory of an output given back, if any (`EdgeSharpener::recycle`).
        let mut tris = crate::edge_sharpener::take_spare(&mut run.s.spare_triangles);
        tris.reserve(self.tris.len() + spare);
        let mut parents = crate::edge_sharpener::take_spare(&mut run.s.spare_parents);
        parents.reserve(self.tris.len() + spare);
        // The output triangles holding a new vertex (the pieces: a few percent), renumbered
        // below without a second pass over all of them.
        let mut pieces: Vec<u32> = Vec::new();
        // On a welded input: parents are named by their input triangle, and the triangles
        // holding a cluster's kept vertex are listed for putting the clusters back
        // (`crate::weld::restore_untouched`), in this pass rather than one more over the
        // output.
        let welded = run.weld_patch.map(|p| p.welded);
        let input_of: &[u32] = welded.map_or(&[], |w| &w.input_triangle);
        let mut around_roots = std::mem::take(&mut run.s.around_roots);
        around_roots.clear();
        for (s, t) in self.tris.iter().enumerate() {
            if self.alive[s] {
                let mut new = false;
                let mut root = false;
                for &v in t {
                    if v as usize >= nv {
                        remap[v as usize - nv] = 0;
                        new = true;
                    } else if welded.is_some_and(|w| w.is_root(v)) {
                        root = true;
                    }
                }
                if new {
                    pieces.push(tris.len() as u32);
                }
                if root {
                    around_roots.push(tris.len() as u32);
                }
                tris.push(*t);
                let p = self.parent[s];
                parents.push(FaceId(input_of.get(p as usize).copied().unwrap_or(p)));
            }
        }
        run.s.around_roots = around_roots;
        let mut positions = std::mem::take(&mut run.positions);
        let mut next = nv as u32;
        let mut snapped = 0;
        let mut unmoved = [0usize; UnmovedReason::ALL.len()];
        for k in 0..remap.len() {
            if remap[k] == NONE {
                continue;
            }
            remap[k] = next;
            positions[next as usize] = positions[nv + k];
            next += 1;
            match run.s.new_vertices[k].status {
                SNAPPED => snapped += 1,
                r => unmoved[(r - 1) as usize] += 1,
            }
        }
        positions.truncate(next as usize);
        for &i in &pieces {
            for v in tris[i as usize].iter_mut() {
                if *v as usize >= nv {
                    *v = remap[*v as usize - nv];
                }
            }
        }
        let moved = (0..nv)
            .filter(|&v| run.s.vflags[v] & V_MOVED != 0 && positions[v] != run.mesh.positions[v])
            .count();
        let r = &mut run.report;
        r.new_vertices = next as usize - nv;
        r.snapped_vertices = snapped;
        r.unmoved_by_reason = unmoved;
        r.moved_input_vertices = moved;
        r.output_vertices = positions.len();
        r.output_triangles = tris.len();
        let a = &mut run.s.slots;
        a.tris = self.tris;
        a.alive = self.alive;
        a.parent = self.parent;
        a.is_new = self.is_new;
        a.slot_of_input = self.slot_of_input;
        (Mesh::new(positions, tris), parents)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_list_members_in_union_order() {
        let mut g = Groups::new(5);
        g.union(0, 1); // {0, 1}
        g.union(3, 4); // {3, 4}
        g.union(2, 0); // the smaller {2} joins {0, 1}
        let pushed = g.push();
        assert_eq!(pushed, 5);
        g.union(4, 1); // equal sizes would keep the first; {3, 4} is smaller here
        let mut m = Vec::new();
        g.members_of(3, &mut m);
        assert_eq!(m, vec![0, 1, 2, 3, 4]);
        m.clear();
        g.members_of(5, &mut m);
        assert_eq!(m, vec![5]);
        // Path halving leaves the sets as they were.
        for x in 0..5 {
            assert_eq!(g.find(x), g.find(0));
        }
    }

    #[test]
    fn slot_lists_keep_insertion_order_and_clear_per_vertex() {
        let mut l = SlotLists::new(4, &mut SlotArrays::default());
        for (v, s) in [(1, 10), (2, 20), (1, 11), (3, 30), (1, 12), (2, 21)] {
            l.push(v, s);
        }
        assert_eq!(l.iter(1).collect::<Vec<_>>(), vec![10, 11, 12]);
        assert_eq!(l.iter(2).collect::<Vec<_>>(), vec![20, 21]);
        assert_eq!(l.iter(0).count(), 0);
        l.clear(1);
        assert_eq!(l.iter(1).count(), 0);
        l.push(1, 13);
        assert_eq!(l.iter(1).collect::<Vec<_>>(), vec![13]);
        assert_eq!(l.iter(3).collect::<Vec<_>>(), vec![30]);
    }

    #[test]
    fn slot_lists_hold_a_slot_once_per_vertex() {
        // A re-cut or flipped slot is pushed again at vertices that list it already.
        let mut l = SlotLists::new(3, &mut SlotArrays::default());
        for (v, s) in [(1, 10), (1, 11), (1, 10), (2, 10), (1, 11), (2, 10)] {
            l.push(v, s);
        }
        assert_eq!(l.iter(1).collect::<Vec<_>>(), vec![10, 11]);
        assert_eq!(l.iter(2).collect::<Vec<_>>(), vec![10]);
        l.clear(1);
        l.push(1, 10);
        assert_eq!(l.iter(1).collect::<Vec<_>>(), vec![10]);
    }
}
