//! The encoder's side of snap vetoes (optional header field 33; docs/sharpen.md, "Snap
//! vetoes"): it runs the sharpening its stream states on the mesh the decoder will sharpen
//! and vetoes the snaps that the original says are worse than no snap.
//!
//! A snap's costs are the sum of squared distances to the original, and the largest, at the
//! vertex and at a quarter, a half and three quarters of the way to it from each vertex it
//! was inserted between (the ends of its chamfer edge, the corners of its corner triangle):
//! the new edges it makes, not the vertex alone (which vetoed 2-3 times more snaps on the
//! CAD fixtures and raised cad_cyl_fillet's max). Snaps are judged by strip, with a bound
//! for new maxima (`rule`).

use std::collections::{HashMap, HashSet};
use std::sync::OnceLock;

use whet_codec::SnapVetoes;
use whet_mesh::{DVec3, Mesh};
use whet_metro::Bvh;
use whet_sharpen::{Snap, SnapJudge};

/// A strip is vetoed when either of its costs is over this many times that of its rest
/// positions: the costs are a ten-point proxy per snap, and a veto costs bits.
const VETO_MARGIN: f64 = 1.25;

/// Judges snaps against the original: the judge `whet encode` runs (public for the
/// measurement examples). The BVH is built when the first snap comes (a mesh without a
/// chamfer costs one sharpening run and nothing more).
pub struct OriginalJudge<'a> {
    original: &'a Mesh,
    bvh: &'a OnceLock<Bvh>,
    longest_edge: Option<f64>,
    passes: Vec<Vec<bool>>,
}

impl<'a> OriginalJudge<'a> {
    /// A judge against `original`, whose BVH `bvh` holds or will hold.
    pub fn new(original: &'a Mesh, bvh: &'a OnceLock<Bvh>) -> Self {
        OriginalJudge {
            original,
            bvh,
            longest_edge: None,
            passes: Vec::new(),
        }
    }

    /// The vetoes of the passes judged so far (a stream carries them only when one snap or
    /// more was vetoed).
    pub fn into_vetoes(self) -> SnapVetoes {
        SnapVetoes::new(self.passes)
    }
}

/// Distances to the original over the points of a vertex's new edges.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Cost {
    /// Sum of squares (what RMS sees).
    sum: f64,
    /// Largest (what the max sees).
    max: f64,
}

impl Cost {
    /// The cost over the new edges of a vertex at `p`, `distance` giving the distance to the
    /// original: the vertex, and a quarter, a half and three quarters of the way to it from
    /// each of `origins`.
    fn of(distance: &impl Fn(DVec3) -> f64, p: DVec3, origins: &[DVec3]) -> Cost {
        let mut c = Cost::default();
        let mut add = |q: DVec3| {
            let x = distance(q);
            c.sum += x * x;
            c.max = c.max.max(x);
        };
        add(p);
        for &o in origins {
            for t in [0.25, 0.5, 0.75] {
                add(o.lerp(p, t));
            }
        }
        c
    }

    /// Both added up (sums added, maxima taken).
    fn merge(self, o: Cost) -> Cost {
        Cost {
            sum: self.sum + o.sum,
            max: self.max.max(o.max),
        }
    }

    /// Worse than `rest` by [`VETO_MARGIN`] in either.
    fn worse_than(self, rest: Cost) -> bool {
        self.sum > VETO_MARGIN * rest.sum || self.max > VETO_MARGIN * rest.max
    }
}

/// A snap's costs snapped and at rest.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct SnapCost {
    snapped: Cost,
    rest: Cost,
}

/// The strip of each snap: edge snaps (two origins) that share an origin vertex are one
/// strip; every other snap is a strip of its own. Returns a representative per snap.
fn strips(snaps: &[Snap]) -> Vec<usize> {
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut parent: Vec<usize> = (0..snaps.len()).collect();
    // Origins are input vertices, whose positions the sharpener reads from one array: equal
    // bits are the same vertex (two distinct vertices at one point join two strips, which
    // only coarsens the decision).
    let mut owner: HashMap<[u64; 3], usize> = HashMap::new();
    for (i, s) in snaps.iter().enumerate() {
        if s.origins.len() != 2 {
            continue;
        }
        for o in &s.origins {
            let key = [o.x.to_bits(), o.y.to_bits(), o.z.to_bits()];
            match owner.get(&key) {
                Some(&j) => {
                    let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                    parent[a] = b;
                }
                None => {
                    owner.insert(key, i);
                }
            }
        }
    }
    (0..snaps.len()).map(|i| root(&mut parent, i)).collect()
}

/// Which of `snaps` to veto, from each one's costs snapped and at rest.
///
/// - A strip whose snaps together are worse than at rest, in the sum (RMS) or the largest
///   distance (max), by [`VETO_MARGIN`], is vetoed whole: a fillet about an edge wide
///   sharpened into a crease (fertility's rounded base). Judged snap by snap, the few
///   worse snaps of a CAD crease were vetoed and left notches in it (cad_bracket at 4 bpv:
///   max 0.259 % -> 0.270 %).
/// - A snap whose new edges reach farther from the original than any rest position of the
///   pass would set a new maximum, and is vetoed on its own: a rounded corner snapped to the
///   box's corner point (synth blend, radius 0.03, at L = 0.03: max 1.025 % -> 1.156 %).
fn rule(snaps: &[Snap], costs: &[SnapCost]) -> Vec<bool> {
    let strip = strips(snaps);
    let mut totals: HashMap<usize, SnapCost> = HashMap::new();
    for (&r, c) in strip.iter().zip(costs) {
        let t = totals.entry(r).or_default();
        t.snapped = t.snapped.merge(c.snapped);
        t.rest = t.rest.merge(c.rest);
    }
    let rest_max = costs.iter().map(|c| c.rest.max).fold(0.0, f64::max);
    strip
        .iter()
        .zip(costs)
        .map(|(r, c)| {
            let t = totals[r];
            t.snapped.worse_than(t.rest) || c.snapped.max > rest_max
        })
        .collect()
}

/// A BVH of the original's triangles near a judgement's snaps: building one over a 1.4M
/// triangle original took 0.2 s of a 2 s encode, for snaps that cover a few percent of it.
/// A distance it finds within `trust` is exact (every triangle within `trust` of a query
/// point is in it, below); a larger one is asked of the whole original's BVH, built then.
struct NearSnaps {
    bvh: Bvh,
    trust: f64,
}

impl NearSnaps {
    /// The original's triangles whose centroid lies within one cell of a cell holding a
    /// snap's rest position, the cells `2 trust` plus the original's longest edge wide,
    /// `trust` being the farthest a snapped position or an origin lies from its rest one.
    /// `None` when that is most of the original (the whole BVH serves then) or nothing.
    fn new(original: &Mesh, longest_edge: f64, snaps: &[Snap]) -> Option<NearSnaps> {
        let trust = snaps
            .iter()
            .flat_map(|s| {
                std::iter::once(s.snapped)
                    .chain(s.origins.iter().copied())
                    .map(|p| p.distance(s.rest))
            })
            .fold(0.0, f64::max);
        // Every query point is within `trust` of its snap's rest position (on a segment
        // from an origin to the snapped or the rest position): a triangle within `trust` of
        // one has its centroid within `2 trust + longest_edge` of that rest position.
        let size = 2.0 * trust + longest_edge;
        if !(size > 0.0 && size.is_finite()) {
            return None;
        }
        let cells = crate::grid::Cells::new(DVec3::ZERO, size);
        let mut near: HashSet<u64> = HashSet::new();
        for s in snaps {
            {
                let c = cells.cell(s.rest);
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            near.insert(crate::grid::Cells::key([c[0] + dx, c[1] + dy, c[2] + dz]));
                        }
                    }
                }
            }
        }
        let mut index = vec![u32::MAX; original.positions.len()];
        let mut local = Mesh::default();
        for tri in &original.triangles {
            let [a, b, c] = tri.map(|v| original.positions[v as usize]);
            if !near.contains(&crate::grid::Cells::key(cells.cell((a + b + c) / 3.0))) {
                continue;
            }
            local.triangles.push(tri.map(|v| {
                if index[v as usize] == u32::MAX {
                    index[v as usize] = local.positions.len() as u32;
                    local.positions.push(original.positions[v as usize]);
                }
                index[v as usize]
            }));
        }
        let n = local.triangles.len();
        (n > 0 && 2 * n < original.triangles.len()).then(|| NearSnaps {
            bvh: Bvh::new(&local),
            trust,
        })
    }
}

impl SnapJudge for OriginalJudge<'_> {
    fn vetoes(&mut self, snaps: &[Snap]) -> Vec<bool> {
        let original = self.original;
        let longest = *self
            .longest_edge
            .get_or_insert_with(|| longest_edge(original));
        let near = NearSnaps::new(original, longest, snaps);
        let full = self.bvh;
        let distance = |q: DVec3| {
            if let Some(n) = &near {
                // Points off the original's surface by more than the chamfers' scale ask the
                // whole original.
                let d = n.bvh.closest_point(q).distance;
                if d <= n.trust {
                    return d;
                }
            }
            full.get_or_init(|| Bvh::new(original))
                .closest_point(q)
                .distance
        };
        let costs: Vec<_> = snaps
            .iter()
            .map(|s| SnapCost {
                snapped: Cost::of(&distance, s.snapped, &s.origins),
                rest: Cost::of(&distance, s.rest, &s.origins),
            })
            .collect();
        let flags = rule(snaps, &costs);
        self.passes.push(flags.clone());
        flags
    }
}

/// The longest edge of `mesh` (0 without triangles).
fn longest_edge(mesh: &Mesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            a.distance_squared(b)
                .max(b.distance_squared(c))
                .max(c.distance_squared(a))
        })
        .fold(0.0, f64::max)
        .sqrt()
}

/// Sharpens `input` (a swing stream's decoded mesh without its surface filter) with `opts`,
/// judged against `original` as `whet encode` judges it: the output (`None` when the
/// sharpener refuses the mesh, as `whet decode --sharpen` would) and the vetoes.
pub fn sharpen_judged(
    original: &Mesh,
    bvh: &OnceLock<Bvh>,
    input: &Mesh,
    opts: &whet_sharpen::SharpenOptions,
) -> (Option<whet_sharpen::Sharpened>, SnapVetoes) {
    let mut judge = OriginalJudge::new(original, bvh);
    match whet_sharpen::sharpen_judged(input, opts, &mut judge) {
        Ok(s) => (Some(s), judge.into_vetoes()),
        Err(_) => (None, SnapVetoes::default()),
    }
}
