//! Spirale Reversi (Isenburg & Snoeyink 2000) in the corner-table form Draco decodes with:
//! the CLERS string is read from its last symbol to its first, rebuilding the mesh backwards,
//! which lets the decoder know, before each symbol, how many triangles each vertex still
//! gains — the valence context that makes the labels cheap (Szymczak 2002; Draco's valence
//! coding). `../shared/docs/algorithms.md` 2.7b restates the rules.
//!
//! The encoder runs this very decoder over its own labels to learn the context of every
//! symbol, so the two sides cannot disagree about contexts.
//!
//! Every step checks what it reads (stack depth, free corners, bounded vertex merges), so a
//! corrupted label string gives an error, never a panic or an endless loop.

use crate::traversal::{Clers, SplitEvent};
use crate::Error;
use whet_mesh::is_multiple_of_three;

pub(crate) const NONE: u32 = u32::MAX;

/// Number of valence contexts (remaining valence clamped to 2..=7).
pub const VALENCE_CONTEXTS: usize = 6;

#[inline]
fn next(c: u32) -> u32 {
    // c % 3 == 2 exactly when c + 1 is a multiple of 3.
    if is_multiple_of_three(c.wrapping_add(1)) {
        c.wrapping_sub(2)
    } else {
        c.wrapping_add(1)
    }
}

#[inline]
fn prev(c: u32) -> u32 {
    if is_multiple_of_three(c) {
        c.wrapping_add(2)
    } else {
        c.wrapping_sub(1)
    }
}

/// The open edge a symbol is applied at: the corner on top of the active stack, the vertex
/// after it and that vertex's valence context.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Gate {
    corner: u32,
    vertex: u32,
    /// Remaining valence context, in `0..VALENCE_CONTEXTS`.
    pub context: usize,
}

#[inline]
fn checked_vertex(x: u32) -> Result<u32, Error> {
    if x == NONE {
        Err(Error::Corrupt("a corner has no vertex"))
    } else {
        Ok(x)
    }
}

/// The state of a reverse decode.
/// The large arrays of a [`ReverseDecoder`], kept between decodes.
#[derive(Debug, Default)]
pub(crate) struct ReverseBuffers {
    pub v: Vec<[u32; 3]>,
    pub o: Vec<u32>,
    pub leftmost: Vec<u32>,
    pub valence: Vec<u32>,
}

pub(crate) struct ReverseDecoder {
    /// Vertices of each triangle's corners (corner `3 t + j` is `v[t][j]`): the decoded
    /// mesh's triangle list, handed on without a copy.
    pub v: Vec<[u32; 3]>,
    /// Opposite of each corner.
    pub o: Vec<u32>,
    pub leftmost: Vec<u32>,
    pub valence: Vec<u32>,
    active: Vec<u32>,
    /// Per entry of `active`, the decoder step of the E that opened it (kept when an S
    /// puts a split corner in the place of the entry it pops): the entries left at the end
    /// are the components' bottoms, opened by each component's first decoded symbol.
    origin: Vec<u32>,
    /// (decoder step of the S, saved corner), in insertion order; looked up linearly from
    /// the back because a pending split is consumed soon after it appears.
    split_active: Vec<(u32, u32)>,
    /// Split events sorted by source, descending (the order the decoder meets them).
    splits: Vec<SplitEvent>,
    next_split: usize,
    /// Total number of symbols (N).
    symbols: u32,
    /// Decoder steps done.
    step: u32,
}

impl ReverseDecoder {
    /// A decoder for `symbols` labels with the given handle contacts, filling the arrays of
    /// `buffers` (their contents ignored: a decoder that kept them from an earlier stream
    /// does not fault their memory in again). `capacity_faces` is the number of faces to
    /// reserve (symbols plus components), already checked by the caller against its limits.
    pub fn with_buffers(
        symbols: u32,
        splits: &[SplitEvent],
        capacity_faces: usize,
        buffers: ReverseBuffers,
    ) -> Self {
        let mut splits = splits.to_vec();
        splits.sort_unstable_by(|a, b| b.source.cmp(&a.source).then(a.right.cmp(&b.right)));
        let ReverseBuffers {
            mut v,
            mut o,
            mut leftmost,
            mut valence,
        } = buffers;
        v.clear();
        v.reserve(capacity_faces);
        o.clear();
        o.reserve(3 * capacity_faces);
        // Vertices are made before merges identify them (one per R or L, three per E): on a
        // mesh of C and R symbols a little over half a vertex per triangle, more than the
        // mesh's own count, so room for one per triangle (reserved, not touched) saves the
        // grown copy a one-shot decode otherwise ends with.
        leftmost.clear();
        leftmost.reserve(capacity_faces + 3);
        valence.clear();
        valence.reserve(capacity_faces + 3);
        ReverseDecoder {
            v,
            o,
            leftmost,
            valence,
            active: Vec::new(),
            origin: Vec::new(),
            split_active: Vec::new(),
            splits,
            next_split: 0,
            symbols,
            step: 0,
        }
    }

    /// The open edge the next symbol is applied at (`None` when nothing is open and the
    /// next symbol is a forced E), looked up once for both the symbol's context and
    /// [`ReverseDecoder::apply`].
    #[inline(always)]
    pub fn gate(&self) -> Option<Gate> {
        let &a = self.active.last()?;
        let x = self
            .v
            .as_flattened()
            .get(next(a) as usize)
            .copied()
            .unwrap_or(NONE);
        let val = self
            .valence
            .get(x as usize)
            .copied()
            .unwrap_or(0)
            .clamp(2, 7);
        Some(Gate {
            corner: a,
            vertex: x,
            context: (val - 2) as usize,
        })
    }

    #[inline(always)]
    fn new_vertex(&mut self, corner: u32) -> u32 {
        let id = self.leftmost.len() as u32;
        self.leftmost.push(corner);
        self.valence.push(0);
        id
    }

    #[inline]
    fn glue(&mut self, a: u32, b: u32) -> Result<(), Error> {
        let (ai, bi) = (a as usize, b as usize);
        match (self.o.get(ai), self.o.get(bi)) {
            (Some(&NONE), Some(&NONE)) if a != b => {
                self.o[ai] = b;
                self.o[bi] = a;
                Ok(())
            }
            _ => Err(Error::Corrupt("an edge is glued twice")),
        }
    }

    #[inline]
    fn vertex_of(&self, c: u32) -> Result<u32, Error> {
        match self.v.as_flattened().get(c as usize) {
            Some(&x) if x != NONE => Ok(x),
            _ => Err(Error::Corrupt("a corner has no vertex")),
        }
    }

    #[inline]
    fn leftmost_of(&self, x: u32) -> Result<u32, Error> {
        match self.leftmost.get(x as usize) {
            Some(&c) if c != NONE => Ok(c),
            _ => Err(Error::Corrupt("a vertex has no corner")),
        }
    }

    /// Applies one symbol (the next one in decoding order) at `gate`, which must be what
    /// [`ReverseDecoder::gate`] returned just before.
    #[inline(always)]
    pub fn apply(&mut self, sym: Clers, gate: Option<Gate>) -> Result<(), Error> {
        if self.step >= self.symbols {
            return Err(Error::Corrupt("more symbols than announced"));
        }
        let k = (3 * self.v.len()) as u32;
        if k > u32::MAX - 8 {
            return Err(Error::Corrupt("too many faces"));
        }
        match sym {
            Clers::C => self.apply_c(k, gate)?,
            Clers::R | Clers::L => self.apply_rl(k, gate, sym == Clers::R)?,
            Clers::E => self.apply_e(k)?,
            Clers::S => self.apply_s(k)?,
        }
        self.step += 1;
        Ok(())
    }

    /// Adds `n` triangle-edge gains to vertex `x`'s valence counter (Draco's table).
    #[inline(always)]
    fn gain(&mut self, x: u32, n: u32) {
        if let Some(val) = self.valence.get_mut(x as usize) {
            *val += n;
        }
    }

    /// Pairs an existing corner `a` (below the new triangle) with the new triangle's
    /// corner `new`: `a` must still be unpaired.
    #[inline(always)]
    fn glue_new(&mut self, a: u32, new: u32) -> Result<(), Error> {
        match self.o.get_mut(a as usize) {
            Some(slot) if *slot == NONE => {
                *slot = new;
                Ok(())
            }
            _ => Err(Error::Corrupt("an edge is glued twice")),
        }
    }

    /// C: the new triangle (x, v(n b), w) closes the gate `a` against the edge `b` after
    /// the gate vertex `x`'s leftmost corner. Each new triangle is appended whole (one
    /// write per array), not first filled with placeholders.
    #[inline(always)]
    fn apply_c(&mut self, k: u32, gate: Option<Gate>) -> Result<(), Error> {
        let Gate {
            corner: a,
            vertex: x,
            ..
        } = gate.ok_or(Error::Corrupt("C with nothing open"))?;
        let x = checked_vertex(x)?;
        let b = next(self.leftmost_of(x)?);
        if a == b {
            return Err(Error::Corrupt("an edge is glued twice"));
        }
        self.glue_new(a, k + 1)?;
        self.glue_new(b, k + 2)?;
        let nb = self.vertex_of(next(b))?;
        let w = self.vertex_of(prev(a))?;
        self.v.push([x, nb, w]);
        self.o.extend_from_slice(&[NONE, a, b]);
        self.leftmost[w as usize] = k + 2;
        if let Some(top) = self.active.last_mut() {
            *top = k;
        }
        self.gain(nb, 1);
        self.gain(w, 1);
        Ok(())
    }

    /// R (`right`) or L: the new triangle on the gate `a` with a new vertex at the corner
    /// facing it (k + 2 for R, k + 1 for L).
    #[inline(always)]
    fn apply_rl(&mut self, k: u32, gate: Option<Gate>, right: bool) -> Result<(), Error> {
        let Gate {
            corner: a,
            vertex: x,
            ..
        } = gate.ok_or(Error::Corrupt("R or L with nothing open"))?;
        let x = checked_vertex(x)?;
        let facing = if right { k + 2 } else { k + 1 };
        self.glue_new(a, facing)?;
        let vr = self.vertex_of(prev(a))?;
        let w = self.new_vertex(facing);
        if right {
            self.v.push([vr, x, w]);
            self.o.extend_from_slice(&[NONE, NONE, a]);
            self.leftmost[vr as usize] = k;
            self.gain(vr, 1);
            self.gain(x, 1);
            self.gain(w, 2);
        } else {
            self.v.push([x, w, vr]);
            self.o.extend_from_slice(&[NONE, a, NONE]);
            self.leftmost[vr as usize] = k + 2;
            self.gain(x, 1);
            self.gain(w, 2);
            self.gain(vr, 1);
        }
        if let Some(top) = self.active.last_mut() {
            *top = k;
        }
        self.check_splits(self.step)
    }

    /// E: a new triangle of three new vertices opens a new part of the stack.
    #[inline(always)]
    fn apply_e(&mut self, k: u32) -> Result<(), Error> {
        let ids = [k, k + 1, k + 2].map(|c| self.new_vertex(c));
        self.v.push(ids);
        self.o.extend_from_slice(&[NONE; 3]);
        for id in ids {
            self.gain(id, 2);
        }
        self.active.push(k);
        self.origin.push(self.step);
        self.check_splits(self.step)
    }

    /// S: the new triangle joins the two top parts of the stack, merging the vertex after
    /// the lower one's edge into the upper one's when they differ.
    #[inline(never)]
    fn apply_s(&mut self, k: u32) -> Result<(), Error> {
        let i = self.step;
        self.v.push([NONE; 3]);
        self.o.extend_from_slice(&[NONE; 3]);
        let b = self
            .active
            .pop()
            .ok_or(Error::Corrupt("S with nothing open"))?;
        let b_origin = self.origin.pop().unwrap_or(0);
        if let Some(pos) = self.split_active.iter().rposition(|&(s, _)| s == i) {
            let (_, c) = self.split_active.swap_remove(pos);
            self.active.push(c);
            self.origin.push(b_origin);
        }
        let a = *self
            .active
            .last()
            .ok_or(Error::Corrupt("S with one edge open"))?;
        self.glue(a, k + 2)?;
        self.glue(b, k + 1)?;
        // a and b are corners of earlier triangles: reading them before filling triangle k
        // reads what the corner-by-corner fill read.
        let p = self.vertex_of(prev(a))?;
        let after_a = self.vertex_of(next(a))?;
        let w = self.vertex_of(prev(b))?;
        self.v[k as usize / 3] = [p, after_a, w];
        self.leftmost[w as usize] = k + 2;
        let n = self.vertex_of(next(b))?;
        if n != p {
            self.leftmost[p as usize] = self.leftmost_of(n)?;
            // Merge n into p around n's fan, clockwise from next(b).
            let mut x = next(b);
            let mut guard = 3 * self.v.len();
            loop {
                self.v.as_flattened_mut()[x as usize] = p;
                let on = self.o[next(x) as usize];
                if on == NONE {
                    break;
                }
                x = next(on);
                guard -= 1;
                if guard == 0 {
                    return Err(Error::Corrupt("vertex merge does not end"));
                }
            }
            let merged = self.valence[n as usize];
            self.valence[p as usize] += merged;
            self.leftmost[n as usize] = NONE;
        }
        if let Some(top) = self.active.last_mut() {
            *top = k;
        }
        // The vertices at k + 1 and k + 2 gained an edge each.
        let (v1, v2) = (self.v[k as usize / 3][1], self.v[k as usize / 3][2]);
        self.gain(v1, 1);
        self.gain(v2, 1);
        Ok(())
    }

    /// Activates the split events whose source is decoder step `i`.
    #[inline(always)]
    fn check_splits(&mut self, i: u32) -> Result<(), Error> {
        // Most steps have none: the next event's source is further on.
        match self.splits.get(self.next_split) {
            Some(ev) if ev.source >= self.symbols - 1 - i => self.check_splits_at(i),
            _ => Ok(()),
        }
    }

    #[inline(never)]
    fn check_splits_at(&mut self, i: u32) -> Result<(), Error> {
        let source = self.symbols - 1 - i;
        while let Some(ev) = self.splits.get(self.next_split) {
            if ev.source != source {
                if ev.source > source {
                    return Err(Error::Corrupt("split events out of order"));
                }
                break;
            }
            let top = *self
                .active
                .last()
                .ok_or(Error::Corrupt("split with nothing open"))?;
            let corner = if ev.right { next(top) } else { prev(top) };
            if ev.split >= self.symbols {
                return Err(Error::Corrupt("split event names a missing symbol"));
            }
            self.split_active
                .push((self.symbols - 1 - ev.split, corner));
            self.next_split += 1;
        }
        Ok(())
    }

    /// Closes each component with its start face and returns the start corners in encoding
    /// order of the components. Fails unless exactly `components` stay open; that every
    /// corner is glued and has a vertex is left to the table built from the arrays
    /// (`CornerTable::from_raw_closed`). [`ReverseDecoder::component_steps`] then tells which decoder steps made each
    /// component.
    pub fn finish(&mut self, components: usize) -> Result<Vec<u32>, Error> {
        if self.step != self.symbols {
            return Err(Error::Corrupt("fewer symbols than announced"));
        }
        if self.active.len() != components {
            return Err(Error::Corrupt("component count does not match the labels"));
        }
        if self.next_split != self.splits.len() || !self.split_active.is_empty() {
            return Err(Error::Corrupt("unused split events"));
        }
        let mut starts = Vec::with_capacity(components);
        let active = std::mem::take(&mut self.active);
        for &a in active.iter().rev() {
            let k = (3 * self.v.len()) as u32;
            self.v.push([NONE; 3]);
            self.o.extend_from_slice(&[NONE; 3]);
            let n = self.vertex_of(next(a))?;
            let b = next(self.leftmost_of(n)?);
            let x = self.vertex_of(next(b))?;
            let c = next(self.leftmost_of(x)?);
            let p = self.vertex_of(next(c))?;
            self.glue(k, a)?;
            self.glue(k + 1, b)?;
            self.glue(k + 2, c)?;
            self.v[k as usize / 3] = [x, p, n];
            // Corner k faces the first symbol's triangle: it is n(s) of the encoder's start
            // corner s, so s itself is k + 2.
            starts.push(k + 2);
        }
        // Corners left unglued or without a vertex are the table's to find: its build
        // checks every corner anyway (`CornerTable::from_raw_closed`), and a scan here read
        // both arrays once more (2-3 % of an exact decode).
        Ok(starts)
    }

    /// After [`ReverseDecoder::finish`]: per component in encoding order, the range of
    /// decoder steps that made it (the decoder meets the components last first, each
    /// opened by an E that stays at the bottom of its part of the stack).
    pub fn component_steps(&self) -> Result<Vec<std::ops::Range<u32>>, Error> {
        let o = &self.origin;
        if o.first().is_some_and(|&x| x != 0) || o.windows(2).any(|w| w[0] >= w[1]) {
            return Err(Error::Corrupt("components do not follow each other"));
        }
        let mut ranges: Vec<std::ops::Range<u32>> = (0..o.len())
            .map(|m| o[m]..o.get(m + 1).copied().unwrap_or(self.symbols))
            .collect();
        ranges.reverse();
        Ok(ranges)
    }

    /// Number of vertex ids handed out (merged ids stay unused).
    pub fn vertex_ids(&self) -> usize {
        self.leftmost.len()
    }
}
