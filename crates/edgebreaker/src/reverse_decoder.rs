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

pub(crate) const NONE: u32 = u32::MAX;

/// Number of valence contexts (remaining valence clamped to 2..=7).
pub const VALENCE_CONTEXTS: usize = 6;

#[inline]
fn next(c: u32) -> u32 {
    if c % 3 == 2 {
        c - 2
    } else {
        c + 1
    }
}

#[inline]
fn prev(c: u32) -> u32 {
    if c % 3 == 0 {
        c + 2
    } else {
        c - 1
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
pub(crate) struct ReverseDecoder {
    /// Vertex of each corner.
    pub v: Vec<u32>,
    /// Opposite of each corner.
    pub o: Vec<u32>,
    leftmost: Vec<u32>,
    valence: Vec<u32>,
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
    /// A decoder for `symbols` labels with the given handle contacts. `capacity_faces` is
    /// the number of faces to reserve (symbols plus components), already checked by the
    /// caller against its limits.
    pub fn new(symbols: u32, splits: &[SplitEvent], capacity_faces: usize) -> Self {
        let mut splits = splits.to_vec();
        splits.sort_unstable_by(|a, b| b.source.cmp(&a.source).then(a.right.cmp(&b.right)));
        ReverseDecoder {
            v: Vec::with_capacity(3 * capacity_faces),
            o: Vec::with_capacity(3 * capacity_faces),
            leftmost: Vec::with_capacity(capacity_faces / 2 + 3),
            valence: Vec::with_capacity(capacity_faces / 2 + 3),
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
    #[inline]
    pub fn gate(&self) -> Option<Gate> {
        let &a = self.active.last()?;
        let x = self.v.get(next(a) as usize).copied().unwrap_or(NONE);
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
        match self.v.get(c as usize) {
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
    #[inline]
    pub fn apply(&mut self, sym: Clers, gate: Option<Gate>) -> Result<(), Error> {
        if self.step >= self.symbols {
            return Err(Error::Corrupt("more symbols than announced"));
        }
        let k = self.v.len() as u32;
        if k > u32::MAX - 8 {
            return Err(Error::Corrupt("too many faces"));
        }
        self.v.extend_from_slice(&[NONE; 3]);
        self.o.extend_from_slice(&[NONE; 3]);
        let i = self.step;
        match sym {
            Clers::E => {
                for j in 0..3 {
                    let w = self.new_vertex(k + j);
                    self.v[(k + j) as usize] = w;
                }
                self.active.push(k);
                self.origin.push(i);
                self.check_splits(i)?;
            }
            Clers::R | Clers::L => {
                let Gate {
                    corner: a,
                    vertex: x,
                    ..
                } = gate.ok_or(Error::Corrupt("R or L with nothing open"))?;
                let (o, cl, cr) = if sym == Clers::R {
                    (k + 2, k + 1, k)
                } else {
                    (k + 1, k, k + 2)
                };
                self.glue(o, a)?;
                let w = self.new_vertex(o);
                self.v[o as usize] = w;
                let vr = self.vertex_of(prev(a))?;
                self.v[cr as usize] = vr;
                self.leftmost[vr as usize] = cr;
                self.v[cl as usize] = checked_vertex(x)?;
                if let Some(top) = self.active.last_mut() {
                    *top = k;
                }
                self.check_splits(i)?;
            }
            Clers::C => {
                let Gate {
                    corner: a,
                    vertex: x,
                    ..
                } = gate.ok_or(Error::Corrupt("C with nothing open"))?;
                let x = checked_vertex(x)?;
                let b = next(self.leftmost_of(x)?);
                self.glue(a, k + 1)?;
                self.glue(b, k + 2)?;
                self.v[k as usize] = x;
                self.v[(k + 1) as usize] = self.vertex_of(next(b))?;
                let w = self.vertex_of(prev(a))?;
                self.v[(k + 2) as usize] = w;
                self.leftmost[w as usize] = k + 2;
                if let Some(top) = self.active.last_mut() {
                    *top = k;
                }
            }
            Clers::S => {
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
                let p = self.vertex_of(prev(a))?;
                self.v[k as usize] = p;
                self.v[(k + 1) as usize] = self.vertex_of(next(a))?;
                let w = self.vertex_of(prev(b))?;
                self.v[(k + 2) as usize] = w;
                self.leftmost[w as usize] = k + 2;
                let n = self.vertex_of(next(b))?;
                if n != p {
                    self.leftmost[p as usize] = self.leftmost_of(n)?;
                    // Merge n into p around n's fan, clockwise from next(b).
                    let mut x = next(b);
                    let mut guard = self.v.len();
                    loop {
                        self.v[x as usize] = p;
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
            }
        }
        // Valence counters (Draco's table): how many times each vertex of the new face
        // gained a triangle edge, by corner (k, k+1, k+2).
        let add: [u32; 3] = match sym {
            Clers::C | Clers::S => [0, 1, 1],
            Clers::R => [1, 1, 2],
            Clers::L => [1, 2, 1],
            Clers::E => [2, 2, 2],
        };
        for j in 0..3 {
            let x = self.v[(k + j) as usize] as usize;
            if let Some(val) = self.valence.get_mut(x) {
                *val += add[j as usize];
            }
        }
        self.step += 1;
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
    /// order of the components. Fails unless exactly `components` stay open and every corner
    /// is glued. [`ReverseDecoder::component_steps`] then tells which decoder steps made each
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
            let k = self.v.len() as u32;
            self.v.extend_from_slice(&[NONE; 3]);
            self.o.extend_from_slice(&[NONE; 3]);
            let n = self.vertex_of(next(a))?;
            let b = next(self.leftmost_of(n)?);
            let x = self.vertex_of(next(b))?;
            let c = next(self.leftmost_of(x)?);
            let p = self.vertex_of(next(c))?;
            self.glue(k, a)?;
            self.glue(k + 1, b)?;
            self.glue(k + 2, c)?;
            self.v[k as usize] = x;
            self.v[(k + 1) as usize] = p;
            self.v[(k + 2) as usize] = n;
            // Corner k faces the first symbol's triangle: it is n(s) of the encoder's start
            // corner s, so s itself is k + 2.
            starts.push(k + 2);
        }
        if self.o.contains(&NONE) || self.v.contains(&NONE) {
            return Err(Error::Corrupt("the decoded mesh is not closed"));
        }
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
