//! The Edgebreaker traversal (Rossignac 1999; the corner-table form of Rossignac, Safonova,
//! Szymczak 2001): the one order in which whet visits triangles and creates vertices.
//!
//! The encoder labels triangles with it, and every geometry coder (the exact mode's
//! parallelogram predictor, the swing decoder) walks the decoded corner table with the very
//! same function, so encoder and decoder meet every vertex in the same order with the same
//! already-known neighbours.
//!
//! ```text
//!             tip c                     r(c) = O[n(c)]  right neighbour
//!              /\                       l(c) = O[p(c)]  left neighbour
//!     l(c)    /  \    r(c)
//!            /    \                     C  tip not yet visited      -> go right
//!     p(c)  /______\  n(c)              L  left visited, right not  -> go right
//!            gate (entered here)        R  right visited, left not  -> go left
//!                                       E  both visited             -> pop a branch
//!                                       S  neither                  -> right now, left later
//! ```
//!
//! Order per component: the start triangle (corners `s`, `n(s)`, `p(s)`, its three vertices
//! created in that order), then the traversal enters through the edge opposite `n(s)` (Draco's
//! convention), right branches before left ones (an explicit stack, no recursion). A tip is
//! created by its C triangle. When a right branch runs around a handle and touches the left
//! edge of the S triangle that spawned it, the contact is a [`SplitEvent`] (Lopes et al. 2002;
//! Draco's topology split) — two per handle.
//!
//! The traversal needs a closed manifold (every corner has an opposite): close holes first
//! (see [`crate::close_holes`]). Corner tables with boundaries are refused.

use whet_mesh::{CornerId, CornerTable, Scratch, VertexId};

/// The five Edgebreaker labels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum Clers {
    /// The tip is a new vertex.
    C = 0,
    /// Tip visited, left neighbour visited, right not.
    L = 1,
    /// Tip visited, both neighbours visited: the end of a branch.
    E = 2,
    /// Tip visited, right neighbour visited, left not.
    R = 3,
    /// Tip visited, neither neighbour visited: the region splits.
    S = 4,
}

impl Clers {
    /// All labels in code order.
    pub const ALL: [Clers; 5] = [Clers::C, Clers::L, Clers::E, Clers::R, Clers::S];

    /// The label with code `i` (0..5).
    pub fn from_index(i: usize) -> Option<Clers> {
        Clers::ALL.get(i).copied()
    }

    /// The label's letter.
    pub fn letter(self) -> char {
        match self {
            Clers::C => 'C',
            Clers::L => 'L',
            Clers::E => 'E',
            Clers::R => 'R',
            Clers::S => 'S',
        }
    }
}

/// A handle contact: the triangle of symbol `source` touches, across its right or left edge,
/// the left edge of the S triangle of symbol `split` (`split < source`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct SplitEvent {
    /// Symbol index (encoding order) of the touching R, L or E triangle.
    pub source: u32,
    /// Symbol index of the S triangle touched.
    pub split: u32,
    /// True when the contact is across the source triangle's right edge (`r(c)`), false for
    /// its left edge.
    pub right: bool,
}

/// One step of the traversal, handed to the visitor in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// A component starts with triangle `s / 3`; its vertices `v(s)`, `v(n s)`, `v(p s)` are
    /// created in that order.
    Start {
        /// The start corner.
        corner: CornerId,
    },
    /// A triangle entered through the edge opposite `tip`. For [`Clers::C`] the vertex at
    /// `tip` is created now; its gate vertices `v(n tip)`, `v(p tip)` and the vertex across
    /// the gate `v(opposite tip)` are already known.
    Triangle {
        /// The corner facing the gate.
        tip: CornerId,
        /// Its label.
        label: Clers,
        /// Index of this symbol in encoding order.
        symbol: u32,
    },
}

/// What a traversal produced besides the visits.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct TraversalSummary {
    /// The labels in encoding order.
    pub labels: Vec<Clers>,
    /// Handle contacts, in order of their `source`.
    pub splits: Vec<SplitEvent>,
    /// The start corner of each component, in order.
    pub starts: Vec<CornerId>,
    /// The vertices in creation order (each used vertex exactly once).
    pub vertex_order: Vec<VertexId>,
}

/// Why a traversal could not run.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum TraversalError {
    /// The mesh has a boundary edge (close holes first).
    #[error("corner {0} has no opposite: the mesh must be closed before the traversal")]
    Boundary(u32),
    /// A given start corner does not exist or starts an already visited triangle.
    #[error("start corner {0} is out of range or in an already visited component")]
    BadStart(u32),
    /// The given start corners do not cover every triangle.
    #[error("{0} triangles are not reachable from the given start corners")]
    Unreached(usize),
}

/// Bit `i` of a bit array.
#[inline(always)]
fn bit(bits: &[u64], i: usize) -> bool {
    bits[i / 64] >> (i % 64) & 1 != 0
}

#[inline(always)]
fn set_bit(bits: &mut [u64], i: usize) {
    bits[i / 64] |= 1 << (i % 64);
}

/// Runs the traversal over every triangle of `table`, calling `visit` for each step.
///
/// With `starts` `None` each component starts at its lowest-numbered triangle, corner
/// `3 t`; otherwise the given corners are used in order (as the decoder does with the start
/// corners it rebuilt) and must cover every component.
pub fn traverse(
    table: &CornerTable,
    starts: Option<&[CornerId]>,
    visit: impl FnMut(Step),
) -> Result<TraversalSummary, TraversalError> {
    traverse_in(table, starts, visit, &mut Scratch::new())
}

/// [`traverse`] with its arrays (the summary's included) taken from `scratch`; its own
/// marks are given back.
pub fn traverse_in(
    table: &CornerTable,
    starts: Option<&[CornerId]>,
    mut visit: impl FnMut(Step),
    scratch: &mut Scratch,
) -> Result<TraversalSummary, TraversalError> {
    let nt = table.triangle_count();
    if let Some(c) = table.first_boundary_corner() {
        return Err(TraversalError::Boundary(c.0));
    }
    // Marks in bit arrays (a bit per triangle, a tenth of a 4-byte mark's memory): the
    // traversal is one chain of dependent reads, each step waiting for its neighbours'
    // marks, and bits stay in a nearer cache. The symbol of an S triangle is kept apart,
    // read only when its bit says it is one.
    let mut visited: Vec<u64> = scratch.take_filled(nt.div_ceil(64), 0);
    let mut s_marked: Vec<u64> = scratch.take_filled(nt.div_ceil(64), 0);
    let mut split_symbol: Vec<u32> = scratch.take_filled(nt, 0);
    let mut vertex_seen: Vec<u64> = scratch.take_filled(table.vertex_count().div_ceil(64), 0);
    let mut summary = TraversalSummary {
        labels: scratch.take_empty(nt),
        vertex_order: scratch.take_empty(table.vertex_count()),
        ..Default::default()
    };
    let mut stack: Vec<CornerId> = Vec::new();
    let mut visited_count = 0usize;
    let mut next_auto = 0usize;
    let mut given = starts.map(|s| s.iter());
    let (corner_vertices, opposites) = (table.corner_vertices(), table.opposites());
    // Sum of values read only to bring the next triangle's lines into the cache early.
    let mut touched = 0u32;

    loop {
        let start = match given.as_mut() {
            Some(it) => match it.next() {
                Some(&c) => {
                    if c.index() >= table.corner_count() || bit(&visited, c.face().index()) {
                        return Err(TraversalError::BadStart(c.0));
                    }
                    c
                }
                None => break,
            },
            None => {
                // Whole words of visited triangles at a time.
                while next_auto < nt && bit(&visited, next_auto) {
                    if next_auto % 64 == 0 && visited[next_auto / 64] == u64::MAX {
                        next_auto += 64;
                    } else {
                        next_auto += 1;
                    }
                }
                next_auto = next_auto.min(nt);
                if next_auto == nt {
                    break;
                }
                CornerId((3 * next_auto) as u32)
            }
        };
        summary.starts.push(start);
        set_bit(&mut visited, start.face().index());
        visited_count += 1;
        for c in [start, table.next(start), table.prev(start)] {
            let v = table.vertex(c);
            set_bit(&mut vertex_seen, v.index());
            summary.vertex_order.push(v);
        }
        visit(Step::Start { corner: start });

        // Closed mesh: every opposite exists (checked above).
        let first = opposite(table, table.next(start));
        stack.push(first);
        while let Some(mut c) = stack.pop() {
            if bit(&visited, c.face().index()) {
                // The branch was swallowed by a handle.
                continue;
            }
            loop {
                let t = c.face().index();
                let symbol = summary.labels.len() as u32;
                set_bit(&mut visited, t);
                visited_count += 1;
                let v = table.vertex(c);
                let right = opposite(table, table.next(c));
                let left = opposite(table, table.prev(c));
                // The traversal goes on at `right` or `left`: start loading both triangles
                // now, while the marks that decide which are still on their way (on a
                // table in random memory order every step is a cache miss).
                touched = touched
                    .wrapping_add(corner_vertices[right.index()])
                    .wrapping_add(opposites[right.index()])
                    .wrapping_add(corner_vertices[left.index()])
                    .wrapping_add(opposites[left.index()]);
                let (rf, lf) = (right.face().index(), left.face().index());
                let right_visited = bit(&visited, rf);
                let left_visited = bit(&visited, lf);
                let label = if !bit(&vertex_seen, v.index()) {
                    set_bit(&mut vertex_seen, v.index());
                    summary.vertex_order.push(v);
                    Clers::C
                } else if right_visited {
                    if left_visited {
                        Clers::E
                    } else {
                        Clers::R
                    }
                } else if left_visited {
                    Clers::L
                } else {
                    Clers::S
                };
                if label != Clers::C && label != Clers::S {
                    if bit(&s_marked, rf) {
                        summary.splits.push(SplitEvent {
                            source: symbol,
                            split: split_symbol[rf],
                            right: true,
                        });
                    }
                    if bit(&s_marked, lf) {
                        summary.splits.push(SplitEvent {
                            source: symbol,
                            split: split_symbol[lf],
                            right: false,
                        });
                    }
                }
                summary.labels.push(label);
                visit(Step::Triangle {
                    tip: c,
                    label,
                    symbol,
                });
                match label {
                    Clers::C | Clers::L => c = right,
                    Clers::R => c = left,
                    Clers::S => {
                        set_bit(&mut s_marked, t);
                        split_symbol[t] = symbol;
                        stack.push(left);
                        c = right;
                    }
                    Clers::E => break,
                }
            }
        }
    }
    std::hint::black_box(touched);
    scratch.give(visited);
    scratch.give(s_marked);
    scratch.give(split_symbol);
    scratch.give(vertex_seen);
    if visited_count != nt {
        return Err(TraversalError::Unreached(nt - visited_count));
    }
    Ok(summary)
}

#[inline]
fn opposite(table: &CornerTable, c: CornerId) -> CornerId {
    // The caller checked that the table is closed.
    table.opposite(c).unwrap_or(c)
}
