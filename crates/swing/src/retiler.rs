//! The SwingWrapper retiler (Attene, Falcidieno, Spagnuolo, Rossignac 2003;
//! `../shared/docs/algorithms.md` 1.4-1.7): grows the retiled mesh `M'` over the original `M`
//! one triangle at a time, in exactly the order in which `whet_edgebreaker::traverse` will
//! later visit `M'`, so that the Edgebreaker encoder reproduces the retiler's labels and
//! vertex order and every new vertex can be sent as one swing index.
//!
//! State (what the Edgebreaker compressor would hold while traversing the final `M'`): the
//! built triangles; the **loops** bounding the built region, as doubly linked lists of loop
//! nodes (one vertex may have several nodes), oriented so the unbuilt region lies to the
//! left of each directed loop edge; the current gate `A -> A.next`; a stack of deferred gates.
//!
//! ```text
//!            a⁻ ----- a ===gate==> b ----- b⁺        new triangle (tip, a, b), CCW
//!                      \         /                   right edge b -> tip, left edge tip -> a
//!             unbuilt   \  tip  /   (left of the loop)
//!
//!   C  tip new, between a and b          next gate tip -> b      (go right)
//!   R  tip = b⁺, node b closes           next gate a -> b⁺       (go left)
//!   L  tip = a⁻, node a closes           next gate a⁻ -> b       (go right)
//!   E  loop of 3 closes                  pop a deferred gate
//!   S  tip = another loop node w         push a -> w, go on with w -> b (a split, or a
//!                                        merge of two loops when w is on another one)
//! ```
//!
//! Labels are computed with the traversal's own rule on this state (tip new; right
//! neighbour built = directed edge `tip -> b` built; left = `a -> tip` built), and popped
//! gates whose edge is already used are skipped, exactly as the traversal skips visited
//! triangles. Each component starts with its seed `[x0, x1, x2]` (quantized positions) and
//! the traversal's first gate `x0 -> x2`.
//!
//! Decision rules at a gate (tunable, [`RetileTuning`]): close a small wedge with R/L/E;
//! else swing (smallest `|θ|` hit of the circle with `M`, quantized); snap the tip to a live
//! loop vertex within `snap · L`; else C; fallbacks close with the best valid loop vertex.
//! Validity keeps `M'` an oriented manifold: combinatorial rules (no repeated directed edge,
//! no new edge duplicating an existing one) and geometric ones (the new triangle must fit
//! in the open wedge of each of its three vertices, fold less than `max_fold` against its
//! built neighbours, face outwards; a tip must not land on the built part: the cheap
//! triangloid coverage test of `algorithms.md` 1.5).
//!
//! Originals with boundaries are retiled with their holes capped (`holes.rs`); the retiled
//! triangles over the caps are flagged for deletion at the end ([`RetiledMesh::deleted`]).
//!
//! Not handled: retiling features narrower than about `L` faithfully (thin parts are
//! wrapped as well as the rules allow, never by more than a bounded number of triangles);
//! sharp edges are chamfered by design (EdgeSharpener restores them after decoding).

use crate::grid::{Cells, FastMap, PointGrid};
use crate::surface::{Hit, Surface};
use crate::Error;
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};
use whet_codec::{RetiledMesh, SurfaceFilter, SwingFrame, SwingParams, VertexSource};
use whet_edgebreaker::Clers;
use whet_mesh::DVec3;

/// Tunable constants of the retiler (`algorithms.md` 1.4; defaults as prototyped there,
/// adjusted on the fixtures).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct RetileTuning {
    /// Close a wedge (R, L, E) whose open angle is below this (radians).
    pub close_angle: f64,
    /// Snap a swing tip to a live loop vertex closer than this fraction of `L`.
    pub snap: f64,
    /// Largest admissible `|θ|` of a swing hit (radians).
    pub theta_max: f64,
    /// Slack of the wedge-containment tests (radians; vertex normals are estimates).
    pub wedge_slack: f64,
    /// Largest fold between a new triangle and a built neighbour (radians between their
    /// normals).
    pub max_fold: f64,
    /// A hit within this fraction of `L` of a built triangle's plane, over the triangle,
    /// counts as covered.
    pub cover_thickness: f64,
    /// A tip closer than this fraction of `L` to a closed (interior) retiled vertex is
    /// refused.
    pub interior_clearance: f64,
    /// Work bound: at most this many times the expected triangle count per component.
    pub budget_factor: f64,
    /// Longest new edge (fraction of `L`) the regular rules may create: a gate of `2L`
    /// or more has no swing circle.
    pub max_edge: f64,
    /// Where the swing circle misses the surface (a hole smaller than `L`), a point of it
    /// within this fraction of `L` of the surface is still a regular new vertex.
    pub bridge: f64,
    /// A triangle joining existing front vertices (R, L, E, S) whose centroid or new edge
    /// midpoints lie farther than this fraction of `L` from the original spans a gap or
    /// cuts a thin part off: the regular rules do not take it (the fallback may, at a cost).
    pub off_surface: f64,
    /// The closing angle of a wedge (rule 2) grows by this (radians) when closing makes
    /// its vertex's valence 6 or more, and shrinks by it when the valence would stay
    /// under 6.
    pub valence_bias: f64,
    /// Largest retiling attempted: an edge length at which the original's area would need
    /// more triangles than this (`2.4 A / L²`) is refused before any work, so an absurdly
    /// short `L` gets an error instead of exhausting memory (the retiler needs about
    /// 450 bytes per retiled triangle).
    pub max_triangles: usize,
}

impl RetileTuning {
    /// The defaults.
    pub const DEFAULT: RetileTuning = RetileTuning {
        close_angle: 80.0 * PI / 180.0,
        snap: 0.55,
        theta_max: 170.0 * PI / 180.0,
        wedge_slack: 12.0 * PI / 180.0,
        max_fold: 170.0 * PI / 180.0,
        cover_thickness: 0.3,
        interior_clearance: 0.45,
        budget_factor: 2.5,
        max_edge: 1.7,
        bridge: 0.35,
        off_surface: 0.35,
        valence_bias: 45.0 * PI / 180.0,
        max_triangles: 1 << 24,
    };
}

impl RetileTuning {
    /// Sets the wedge-closing angle (radians).
    pub const fn with_close_angle(mut self, angle: f64) -> Self {
        self.close_angle = angle;
        self
    }

    /// Sets the off-surface limit of closing triangles (fraction of `L`; 1 or more turns the
    /// test off).
    pub const fn with_off_surface(mut self, off: f64) -> Self {
        self.off_surface = off;
        self
    }

    /// Sets the valence bias of the closing angle (radians).
    pub const fn with_valence_bias(mut self, bias: f64) -> Self {
        self.valence_bias = bias;
        self
    }

    /// Sets the largest retiling attempted (triangles expected from the area).
    pub const fn with_max_triangles(mut self, triangles: usize) -> Self {
        self.max_triangles = triangles;
        self
    }

    /// Sets the snapping distance (fraction of `L`).
    pub const fn with_snap(mut self, snap: f64) -> Self {
        self.snap = snap;
        self
    }
}

impl Default for RetileTuning {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What the retiler did, beyond the mesh.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct RetileStats {
    /// Components retiled normally.
    pub components: usize,
    /// Components smaller than about `L`, coded as a flat two-triangle pillow.
    pub tiny_components: usize,
    /// Small components (at most a tenth of the area) the front could not cover, coded as
    /// pillows instead.
    pub degraded_components: usize,
    /// Gates where the smallest-angle swing hit fell on the built part.
    pub covered_hits: usize,
    /// Gates closed by the fallback rule (no swing possible or valid).
    pub fallbacks: usize,
    /// Fallbacks whose move clearly violates the geometric checks (cost above 2).
    pub forced: usize,
    /// Triangles deleted after retiling because they cover a hole of the original.
    pub deleted_triangles: usize,
    /// New vertices placed off the surface, where the swing circle passed through a hole
    /// or crack of the original smaller than `L` (the hole is covered over).
    pub bridged: usize,
}

/// The result of [`retile`].
#[derive(Clone, Debug)]
pub struct Retiled {
    /// The retiled mesh, ready for `whet_codec::encode_retiled`.
    pub mesh: RetiledMesh,
    /// What happened.
    pub stats: RetileStats,
    /// Per vertex of the original: whether it belongs to a component coded as a pillow
    /// (tiny, or a small one the front could not cover), which the retiling leaves out by
    /// design (the encoder's coverage check skips these vertices).
    pub pillowed_vertices: Vec<bool>,
    /// The surface filter fitted to the original ([`SurfaceFilter::NONE`] unless asked for).
    pub filter: SurfaceFilter,
    /// The extended surface filter fitted on the same samples, with the ratio of its fitted
    /// RMS to that of [`Self::filter`] (`None` unless asked for, or when degenerate): the
    /// encoder writes it when the gain is worth its header bytes.
    pub extended_filter: Option<(SurfaceFilter, f64)>,
    /// The filters for after EdgeSharpener (`SurfaceFilter::apply_after_sharpening`), one
    /// per sharpening asked for, each fitted on the retiling sharpened that way, as `whet
    /// decode --sharpen` does ([`SurfaceFilter::NONE`] unless asked for; empty when none
    /// was asked for).
    pub sharpened_filters: Vec<SurfaceFilter>,
}

const NONE: u32 = u32::MAX;

/// Most triangles one retiled vertex may get (a regular one has 6; the wedge measure walks
/// at most 64): beyond, the front is spinning around the vertex, wrapping the same spot
/// again and again, and the retiler gives up at once (the encoder retries at another `L`)
/// instead of running on to the triangle budget, which took minutes on the armadillo at
/// one length (5 angle bits, L = 0.9606 % of the diagonal).
const MAX_VALENCE: u32 = 40;

#[derive(Clone, Copy, Debug)]
struct Node {
    v: u32,
    prev: u32,
    next: u32,
    /// Next node of the same vertex (a per-vertex list).
    same: u32,
    alive: bool,
}

/// A swing tip the regular rules refused, kept for the fallback with a penalty for why.
struct Spare {
    pos: DVec3,
    normal: DVec3,
    q: i32,
    penalty: f64,
}

enum Tip {
    New { pos: DVec3, normal: DVec3, q: i32 },
    Existing(u32),
}

#[inline]
fn ekey(a: u32, b: u32) -> u64 {
    ((a as u64) << 32) | b as u64
}

/// Counter-clockwise angle about `n` from `d1` to `d2` after projecting both on the plane
/// normal to `n`, in `[0, 2π)`.
#[inline]
fn ccw(n: DVec3, d1: DVec3, d2: DVec3) -> f64 {
    let p1 = d1 - n * d1.dot(n);
    let p2 = d2 - n * d2.dot(n);
    let a = n.dot(p1.cross(p2)).atan2(p1.dot(p2));
    if a < 0.0 {
        a + TAU
    } else {
        a
    }
}

/// Debugging output (`--features trace`): the environment variable `name`, read only when
/// the feature is on, so that release builds carry no tracing at all. `WHET_SWING_TRACE`
/// prints every refused swing and fallback, `WHET_SWING_DUMP=path` writes the partial mesh
/// when the retiler gets stuck, `WHET_SWING_DUMP_AT=n` writes it to `/tmp/dump_at.off` when
/// it has `n` triangles.
#[inline]
fn trace_var(name: &str) -> Option<std::ffi::OsString> {
    if cfg!(feature = "trace") {
        std::env::var_os(name)
    } else {
        None
    }
}

/// The angle between two vectors (0 for a zero vector).
#[inline]
fn angle3(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

struct Retiler<'s, 'm> {
    surf: &'s mut Surface<'m>,
    /// The triangles of each component in increasing order: component `c` holds
    /// `comp_tris[comp_start[c]..comp_start[c + 1]]` (one counting sort, so a component's
    /// seed and pillow read its own triangles instead of scanning the whole mesh, which was
    /// quadratic in the component count: a soup of 300k triangles did not finish).
    comp_start: Vec<u32>,
    comp_tris: Vec<u32>,
    /// Per original triangle (after capping): part of a hole's cap. Seeds avoid caps.
    filler: &'s [bool],
    params: &'s SwingParams,
    tune: RetileTuning,
    l: f64,
    pos: Vec<DVec3>,
    nrm: Vec<DVec3>,
    /// Triangles incident to each vertex so far.
    valence: Vec<u32>,
    /// Set when a vertex exceeds [`MAX_VALENCE`]: the front is spinning around it.
    runaway: bool,
    src: Vec<VertexSource>,
    tris: Vec<[u32; 3]>,
    tri_normal: Vec<DVec3>,
    labels: Vec<Clers>,
    /// Incident triangles per vertex: head corner, then `corner_next`.
    vcorner: Vec<u32>,
    corner_next: Vec<u32>,
    /// Loop nodes per vertex (head of the `same` list) and how many are alive.
    vnode: Vec<u32>,
    vlive: Vec<u32>,
    /// Component of the original each retiled vertex was made for: the front of one
    /// component never snaps to, or is blocked by, another's vertices.
    vcomp: Vec<u32>,
    nodes: Vec<Node>,
    edges: FastMap<u64, u32>,
    vgrid: PointGrid,
    stack: Vec<(u32, u32, u32)>,
    hits: Vec<Hit>,
    tri_stamp: Vec<u32>,
    query: u32,
    comp: u32,
    stats: RetileStats,
}

/// The error for an edge length `l` at which a surface of area `area` needs more than
/// `max` retiled triangles by the area law.
pub(crate) fn too_many_triangles(l: f64, diagonal: f64, area: f64, max: usize) -> Error {
    let expected = 2.4 * area / (l * l);
    Error::Parameter(format!(
        "an edge length of {:.3e} of the bounding-box diagonal ({l:.3e}) would retile this \
         mesh (area {area:.3e}) into about {expected:.3e} triangles, more than the limit of \
         {max} (--max-retiled-triangles): choose a longer edge length or a lower rate",
        l / diagonal
    ))
}

/// Seeds a component may grow from before its retiling counts as stuck (docs/swing.md,
/// "Bounded work").
const SEED_ATTEMPTS: usize = 3;

/// Least distance, in `L`, between the seeds of two attempts on one component.
const SEED_SPREAD: f64 = 4.0;

/// Retiles `mesh` with the edge length and grids of `params` (see the module docs).
pub fn retile(
    mesh: &whet_mesh::Mesh,
    params: &SwingParams,
    tune: &RetileTuning,
) -> Result<Retiled, Error> {
    retile_fitted(mesh, params, tune, FilterFits::None, &[])
}

/// Which surface filters [`retile_fitted`] fits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum FilterFits {
    /// None.
    None,
    /// The two-field filter (and those for after sharpening).
    Basic,
    /// Also the extended one, on the same samples.
    Extended,
}

/// [`retile`], and with `fits` also the surface filter fitted to `mesh`
/// ([`crate::fit_surface_filter`], on the retiler's own grid of the original; with
/// [`FilterFits::Extended`] the extended one too, [`crate::fit_filters`]) and one for after
/// sharpening per entry of `sharpen` (one retiling serves every sharpening the encoder's
/// choice measures).
pub(crate) fn retile_fitted(
    mesh: &whet_mesh::Mesh,
    params: &SwingParams,
    tune: &RetileTuning,
    fits: FilterFits,
    sharpen: &[whet_sharpen::SharpenOptions],
) -> Result<Retiled, Error> {
    let l = params.edge_length;
    // Expected triangles: 2.4 · area / L² (algorithms.md 1.9). Checked first: the grid of
    // the original and the retiling both grow with it.
    // The grid's cells are indexed by 21 bits per axis around the box's corner: a length
    // under 2^-19 of the diagonal (far finer than any useful one; only a mesh of almost no
    // area gets past the size limit below with it) would leave its range.
    let diagonal = mesh.bounding_box().diagonal();
    if l.is_nan() || diagonal.is_nan() || l < diagonal / (1u64 << 19) as f64 {
        return Err(Error::Parameter(format!(
            "an edge length of {:.3e} of the bounding-box diagonal ({l:e}) is under 2^-19 \
             of it: finer than the retiler's grid indexes; choose a longer edge length or a \
             lower rate",
            l / diagonal
        )));
    }
    // Originals with boundaries: retile the surface with its holes capped, then delete the
    // retiled triangles over the caps (holes.rs).
    let capped = crate::holes::cap_holes(mesh, l);
    let (mesh, filler) = match &capped {
        Some((m, f)) => (m, Some(f.as_slice())),
        None => (mesh, None),
    };
    // The caps count: they are retiled too.
    let mesh_area = mesh.area();
    let expected = 2.4 * mesh_area / (l * l);
    if expected.is_nan() || expected > tune.max_triangles as f64 {
        return Err(too_many_triangles(
            l,
            diagonal,
            mesh_area,
            tune.max_triangles,
        ));
    }
    let mut surf = Surface::new(mesh, l);
    let bbox = mesh.bounding_box();
    let (comp_start, comp_tris) = component_triangles(&surf.component, surf.component_count);
    let mut r = Retiler {
        comp_start,
        comp_tris,
        params,
        tune: *tune,
        l,
        pos: Vec::new(),
        nrm: Vec::new(),
        valence: Vec::new(),
        runaway: false,
        src: Vec::new(),
        tris: Vec::new(),
        tri_normal: Vec::new(),
        labels: Vec::new(),
        vcorner: Vec::new(),
        corner_next: Vec::new(),
        vnode: Vec::new(),
        vlive: Vec::new(),
        vcomp: Vec::new(),
        nodes: Vec::new(),
        edges: FastMap::default(),
        vgrid: PointGrid::new(Cells::new(bbox.min, l)),
        stack: Vec::new(),
        hits: Vec::new(),
        tri_stamp: Vec::new(),
        query: 0,
        comp: 0,
        stats: RetileStats::default(),
        surf: &mut surf,
        filler: filler.unwrap_or(&[]),
    };
    let comps = r.surf.component_count;
    // Per component: its first triangle, area and box.
    let mut first = vec![u32::MAX; comps];
    let mut area = vec![0.0f64; comps];
    let mut boxes = vec![whet_mesh::Aabb::EMPTY; comps];
    for (t, &c) in r.surf.component.iter().enumerate() {
        let c = c as usize;
        if first[c] == u32::MAX {
            first[c] = t as u32;
        }
        area[c] += mesh.face_area(t);
        for p in mesh.triangle_positions(t) {
            boxes[c].include(p);
        }
    }
    let total_area: f64 = area.iter().sum();
    let mut pillowed = vec![false; comps];
    for c in 0..comps {
        r.comp = c as u32;
        let tiny = boxes[c].diagonal() < 1.5 * l || area[c] < 0.75 * l * l;
        if tiny {
            r.pillow(first[c])?;
            r.stats.tiny_components += 1;
            pillowed[c] = true;
            continue;
        }
        // Expected triangles: 2.4 · area / L² (algorithms.md 1.9).
        let budget = (tune.budget_factor * 2.4 * area[c] / (l * l)) as usize + 200;
        let mark = r.mark();
        // A front that stalls depends on where it started: before giving up on the
        // component, grow it again from the next seeds (in the seed's own order).
        // Only a success replaces the first attempt's Stuck: any other error of a later
        // attempt leaves the component to the fallbacks below, as the first one's would.
        let mut result = r.component(first[c], budget, 0);
        for attempt in 1..SEED_ATTEMPTS {
            if !matches!(result, Err(Error::Stuck(_))) {
                break;
            }
            r.rollback(&mark);
            if r.component(first[c], budget, attempt).is_ok() {
                result = Ok(());
            }
        }
        match result {
            Ok(()) => r.stats.components += 1,
            // A small component the front cannot cover (a strip narrower than L, a
            // splinter): a pillow loses it gracefully; a large one is an error (the encoder
            // retries at another L).
            Err(Error::Stuck(_)) if area[c] <= 0.1 * total_area => {
                r.rollback(&mark);
                r.pillow(first[c])?;
                r.stats.degraded_components += 1;
                pillowed[c] = true;
            }
            Err(e) => return Err(e),
        }
    }
    let deleted = match filler {
        Some(f) => r.over_filler(f),
        None => Vec::new(),
    };
    r.stats.deleted_triangles = deleted.iter().filter(|&&d| d).count();
    let (filter, extended_filter, sharpened_filters) = if fits != FilterFits::None {
        // The decoder's output: the kept triangles (unused vertices do not matter to the
        // filter). Closest points on the original only, not on the filler over its holes.
        let kept = whet_mesh::Mesh::new(
            r.pos.clone(),
            r.tris
                .iter()
                .enumerate()
                .filter(|(t, _)| !deleted.get(*t).copied().unwrap_or(false))
                .map(|(_, t)| *t)
                .collect(),
        );
        let filler = filler.unwrap_or(&[]);
        let surf = &*r.surf;
        let closest =
            |p| surf.closest_point(p, 2.0 * l, |t| !filler.get(t).copied().unwrap_or(false));
        // One set of fields serves every fit (fit_surface_filter computes the same), and
        // one set of samples both decoded filters.
        let (filter, extended, fields) = if fits == FilterFits::Extended {
            let (fields, extra) = whet_codec::FilterFields::extended(&kept, l);
            let fit = crate::fit_filters(&kept, &fields, &extra, closest);
            (fit.basic, fit.extended, fields)
        } else {
            let fields = whet_codec::FilterFields::new(&kept);
            let basic = crate::fit_displacements(&kept, &fields.normal, &fields.smoothed, closest);
            (basic, None, fields)
        };
        // Candidates that sharpen to the same mesh (the papers' method with curved walls
        // that turn no edge smooth, a second pass that changes nothing) share one fit.
        // (Keyed by a hash, not by the meshes: 25 candidates' meshes need not stay in memory.)
        // The sharpenings run side by side, as many at a time as there are threads (that
        // many meshes in memory at once); the fits, which query the original's grid, after
        // them in candidate order.
        let mut fitted: Vec<(Option<u64>, SurfaceFilter)> = Vec::new();
        let mut after = Vec::with_capacity(sharpen.len());
        for group in sharpen.chunks(rayon::current_num_threads().max(1)) {
            let sharps: Vec<Option<whet_mesh::Mesh>> = group
                .par_iter()
                .map(|o| whet_sharpen::sharpen(&kept, o).ok().map(|s| s.mesh))
                .collect();
            for sharp in sharps {
                let key = sharp.as_ref().map(crate::encoder::mesh_key);
                if let Some((_, f)) = fitted.iter().find(|(k, _)| *k == key) {
                    after.push(*f);
                    continue;
                }
                let f = match &sharp {
                    Some(s) => fit_after_sharpening(&kept, &fields, s, closest),
                    None => SurfaceFilter::NONE,
                };
                fitted.push((key, f));
                after.push(f);
            }
        }
        (filter, extended, after)
    } else {
        (
            SurfaceFilter::NONE,
            None,
            vec![SurfaceFilter::NONE; sharpen.len()],
        )
    };
    // Vertices of pillowed components (the original's vertices come first in a capped mesh,
    // and its triangles first too).
    let mut pillowed_vertices = vec![false; mesh.positions.len()];
    if pillowed.iter().any(|&p| p) {
        for (t, &c) in r.surf.component.iter().enumerate() {
            if pillowed.get(c as usize).copied().unwrap_or(false) {
                for &v in &mesh.triangles[t] {
                    if let Some(x) = pillowed_vertices.get_mut(v as usize) {
                        *x = true;
                    }
                }
            }
        }
    }
    Ok(Retiled {
        mesh: RetiledMesh {
            positions: r.pos,
            triangles: r.tris,
            sources: r.src,
            labels: r.labels,
            components: comps,
            deleted,
        },
        stats: r.stats,
        pillowed_vertices,
        filter,
        extended_filter,
        sharpened_filters,
    })
}

/// The factors of the filter for after sharpening: `sharp`, `kept` (the unfiltered decoded
/// mesh) sharpened (with whet-sharpen's defaults, or a stream's choice), the filter's fields
/// of `kept` on the vertices the sharpener left alone, fitted to the original (docs/swing.md
/// section 2). On a smooth part the sharpener changes little and the fit finds the decoded
/// filter again; on a CAD part it fits the flat faces between the restored creases. (No
/// filter when the sharpener refuses the mesh: the caller's.)
fn fit_after_sharpening(
    kept: &whet_mesh::Mesh,
    fields: &whet_codec::FilterFields,
    sharp: &whet_mesh::Mesh,
    closest: impl FnMut(DVec3) -> Option<DVec3>,
) -> SurfaceFilter {
    let moved = fields.after_sharpening(kept, sharp);
    crate::fit_displacements(sharp, &moved.normal, &moved.smoothed, closest)
}

impl Retiler<'_, '_> {
    // --- Holes of the original -----------------------------------------------------------

    /// For each retiled triangle, whether it lies over the filler that capped a hole of the
    /// original (its centroid's closest original triangle is filler); then, so that the
    /// kept part stays vertex-manifold, at every vertex whose kept triangles form several
    /// fans only the largest fan is kept.
    fn over_filler(&mut self, filler: &[bool]) -> Vec<bool> {
        let l = self.l;
        // Over filler: at least three of the triangle's corners and centroid project onto
        // filler (a triangle straddling the border stays: better a flap than a notch).
        let mut deleted: Vec<bool> = (0..self.tris.len())
            .map(|t| {
                let [a, b, c] = self.tris[t].map(|v| self.pos[v as usize]);
                let comp = self.vcomp[self.tris[t][0] as usize];
                let on_filler = [a, b, c, (a + b + c) / 3.0]
                    .iter()
                    .filter(
                        |&&p| match self.surf.closest_in_component(p, comp, 2.0 * l) {
                            Some((_, o)) => filler.get(o as usize).copied().unwrap_or(false),
                            None => false,
                        },
                    )
                    .count();
                on_filler >= 3
            })
            .collect();
        if !deleted.iter().any(|&d| d) {
            return deleted;
        }
        // A connected original keeps a connected retiling: of the kept pieces of each
        // retiled component only the largest stays (small islands of kept triangles out on
        // a cap would only add error).
        let kept = self.pieces(&deleted, false);
        let mut largest: std::collections::HashMap<u32, usize> = Default::default();
        for (id, p) in kept.iter().enumerate() {
            let comp = self.vcomp[self.tris[p[0] as usize][0] as usize];
            let e = largest.entry(comp).or_insert(id);
            if p.len() > kept[*e].len() {
                *e = id;
            }
        }
        for (id, p) in kept.iter().enumerate() {
            let comp = self.vcomp[self.tris[p[0] as usize][0] as usize];
            if largest.get(&comp) != Some(&id) {
                for &t in p {
                    deleted[t as usize] = true;
                }
            }
        }
        for _round in 0..4 {
            // Pinholes: a connected piece of at most three deleted triangles is a notch of
            // the border approximation, not a hole of the original: keep it.
            let mut undeleted = false;
            for p in self.pieces(&deleted, true) {
                if p.len() <= 3 {
                    for t in p {
                        deleted[t as usize] = false;
                    }
                    undeleted = true;
                }
            }
            if !self.fix_fans(&mut deleted) && !undeleted {
                break;
            }
        }
        deleted
    }

    /// At every vertex whose kept triangles form several fans, deletes all but the largest
    /// fan (so the kept part stays vertex-manifold). Returns whether anything changed.
    fn fix_fans(&self, deleted: &mut [bool]) -> bool {
        let mut any = false;
        for _pass in 0..4 {
            let mut changed = false;
            for v in 0..self.pos.len() as u32 {
                let fan = self.fan(v);
                if fan.is_empty() {
                    continue;
                }
                // Runs of kept triangles around v (cyclic).
                let n = fan.len();
                let Some(start) = (0..n).find(|&i| deleted[fan[i] as usize]) else {
                    continue; // all kept
                };
                let mut runs: Vec<Vec<u32>> = Vec::new();
                let mut cur: Vec<u32> = Vec::new();
                for k in 1..=n {
                    let t = fan[(start + k) % n];
                    if deleted[t as usize] {
                        if !cur.is_empty() {
                            runs.push(std::mem::take(&mut cur));
                        }
                    } else {
                        cur.push(t);
                    }
                }
                if !cur.is_empty() {
                    runs.push(cur);
                }
                if runs.len() > 1 {
                    let keep = runs
                        .iter()
                        .enumerate()
                        .max_by_key(|(i, r)| (r.len(), usize::MAX - i))
                        .map_or(0, |(i, _)| i);
                    for (i, r) in runs.iter().enumerate() {
                        if i != keep {
                            for &t in r {
                                deleted[t as usize] = true;
                            }
                        }
                    }
                    changed = true;
                }
            }
            any |= changed;
            if !changed {
                break;
            }
        }
        any
    }

    /// The connected pieces (across edges) of the triangles whose flag equals `which`.
    fn pieces(&self, flags: &[bool], which: bool) -> Vec<Vec<u32>> {
        let nt = self.tris.len();
        let mut seen = vec![false; nt];
        let mut out = Vec::new();
        for t0 in 0..nt {
            if flags[t0] != which || seen[t0] {
                continue;
            }
            seen[t0] = true;
            let mut piece = Vec::new();
            let mut stack = vec![t0 as u32];
            while let Some(t) = stack.pop() {
                piece.push(t);
                let tri = self.tris[t as usize];
                for k in 0..3 {
                    let (x, y) = (tri[k], tri[(k + 1) % 3]);
                    if let Some(&n) = self.edges.get(&ekey(y, x)) {
                        let n = n as usize;
                        if flags[n] == which && !seen[n] {
                            seen[n] = true;
                            stack.push(n as u32);
                        }
                    }
                }
            }
            out.push(piece);
        }
        out
    }

    /// The triangles around vertex `v` in cyclic order (the retiled mesh is closed).
    fn fan(&self, v: u32) -> Vec<u32> {
        let first = self.vcorner[v as usize];
        if first == NONE {
            return Vec::new();
        }
        let t0 = first / 3;
        let mut out = vec![t0];
        let mut t = t0;
        for _ in 0..256 {
            let tri = self.tris[t as usize];
            let k = tri.iter().position(|&x| x == v).unwrap_or(0);
            let p = tri[(k + 1) % 3];
            // The neighbour across edge (v, p) holds p -> v.
            match self.edges.get(&ekey(p, v)) {
                Some(&n) if n != t0 => {
                    out.push(n);
                    t = n;
                }
                _ => break,
            }
        }
        out
    }

    // --- Construction -------------------------------------------------------------------

    fn add_vertex(&mut self, p: DVec3, n: DVec3, s: VertexSource) -> u32 {
        let v = self.pos.len() as u32;
        self.pos.push(p);
        self.nrm.push(n);
        self.valence.push(0);
        self.src.push(s);
        self.vcorner.push(NONE);
        self.vnode.push(NONE);
        self.vlive.push(0);
        self.vcomp.push(self.comp);
        self.vgrid.insert(v, p);
        v
    }

    fn add_node(&mut self, v: u32) -> u32 {
        let id = self.nodes.len() as u32;
        self.nodes.push(Node {
            v,
            prev: NONE,
            next: NONE,
            same: self.vnode[v as usize],
            alive: true,
        });
        self.vnode[v as usize] = id;
        self.vlive[v as usize] += 1;
        id
    }

    fn kill_node(&mut self, n: u32) {
        let node = &mut self.nodes[n as usize];
        if node.alive {
            node.alive = false;
            self.vlive[node.v as usize] -= 1;
        }
    }

    fn add_triangle(&mut self, t: [u32; 3]) {
        let id = self.tris.len() as u32;
        let [w, a, b] = t;
        for (k, &v) in t.iter().enumerate() {
            let n = &mut self.valence[v as usize];
            *n += 1;
            self.runaway |= *n > MAX_VALENCE;
            let c = 3 * id + k as u32;
            self.corner_next.push(self.vcorner[v as usize]);
            self.vcorner[v as usize] = c;
        }
        self.edges.insert(ekey(w, a), id);
        self.edges.insert(ekey(a, b), id);
        self.edges.insert(ekey(b, w), id);
        let [pw, pa, pb] = t.map(|v| self.pos[v as usize]);
        self.tri_normal
            .push((pa - pw).cross(pb - pw).normalize_or_zero());
        self.tris.push(t);
    }

    #[inline]
    fn built(&self, a: u32, b: u32) -> bool {
        self.edges.contains_key(&ekey(a, b))
    }

    /// The third vertex of the built triangle holding directed edge `b -> a`.
    fn parent_vertex(&self, a: u32, b: u32) -> Option<u32> {
        let t = *self.edges.get(&ekey(b, a))?;
        self.tris[t as usize]
            .iter()
            .copied()
            .find(|&v| v != a && v != b)
    }

    // --- Components ---------------------------------------------------------------------

    /// The sizes to roll a failed component back to.
    fn mark(&self) -> (usize, usize, usize, usize, RetileStats) {
        (
            self.pos.len(),
            self.tris.len(),
            self.labels.len(),
            self.nodes.len(),
            self.stats.clone(),
        )
    }

    /// Forgets everything built since `mark` (one component: it created all its vertices,
    /// triangles and loop nodes after the mark and touched nothing older).
    fn rollback(&mut self, mark: &(usize, usize, usize, usize, RetileStats)) {
        let (nv, nt, nl, nn, stats) = mark;
        let (nv, nt, nl, nn) = (*nv, *nt, *nl, *nn);
        // The counters of the attempt undone go with it.
        self.stats = stats.clone();
        for t in nt..self.tris.len() {
            let [w, a, b] = self.tris[t];
            for (x, y) in [(w, a), (a, b), (b, w)] {
                self.edges.remove(&ekey(x, y));
            }
        }
        for v in nv..self.pos.len() {
            self.vgrid.remove(v as u32, self.pos[v]);
        }
        self.pos.truncate(nv);
        self.nrm.truncate(nv);
        self.valence.truncate(nv);
        self.runaway = false;
        self.src.truncate(nv);
        self.vcorner.truncate(nv);
        self.vnode.truncate(nv);
        self.vlive.truncate(nv);
        self.vcomp.truncate(nv);
        self.tris.truncate(nt);
        self.tri_normal.truncate(nt);
        self.corner_next.truncate(3 * nt);
        self.labels.truncate(nl);
        self.nodes.truncate(nn);
        self.stack.clear();
    }

    /// A component smaller than about `L`: its three most spread-out vertices as a seed and
    /// the seed's back face (label E), a flat closed pillow.
    /// The triangles of component `comp`, in increasing order.
    fn component_tris(&self, comp: u32) -> &[u32] {
        let c = comp as usize;
        &self.comp_tris[self.comp_start[c] as usize..self.comp_start[c + 1] as usize]
    }

    fn pillow(&mut self, first_tri: u32) -> Result<(), Error> {
        let mesh = self.surf.mesh;
        let comp = self.comp;
        let verts: Vec<u32> = {
            let mut vs: Vec<u32> = self
                .component_tris(comp)
                .iter()
                .flat_map(|&t| mesh.triangles[t as usize])
                .collect();
            vs.sort_unstable();
            vs.dedup();
            vs
        };
        let p = |v: u32| mesh.positions[v as usize];
        let v0 = mesh.triangles[first_tri as usize][0];
        let v1 = *verts
            .iter()
            .max_by(|&&x, &&y| {
                (p(x) - p(v0))
                    .length_squared()
                    .total_cmp(&(p(y) - p(v0)).length_squared())
            })
            .unwrap_or(&v0);
        let axis = p(v1) - p(v0);
        let v2 = *verts
            .iter()
            .max_by(|&&x, &&y| {
                axis.cross(p(x) - p(v0))
                    .length_squared()
                    .total_cmp(&axis.cross(p(y) - p(v0)).length_squared())
            })
            .unwrap_or(&v0);
        let ids: Vec<u32> = [v0, v1, v2]
            .iter()
            .map(|&v| {
                let (g, q) = self.params.snap_seed(p(v));
                let n = self.surf.vertex_normal[v as usize];
                self.add_vertex(q, n, VertexSource::Seed(g))
            })
            .collect();
        let (x0, x1, x2) = (ids[0], ids[1], ids[2]);
        self.add_triangle([x0, x1, x2]);
        self.add_triangle([x1, x0, x2]);
        self.labels.push(Clers::E);
        Ok(())
    }

    /// Seeds and retiles one component.
    fn component(&mut self, first_tri: u32, budget: usize, attempt: usize) -> Result<(), Error> {
        let start = self.tris.len();
        let forced_before = self.stats.forced;
        // A flag the previous component raised on its very last triangle is not this one's.
        self.runaway = false;
        let mut gate = self.seed(first_tri, attempt)?;
        loop {
            // Fail fast when the front degenerates (a cascade of fallbacks feeds itself):
            // the encoder retries at a slightly different L.
            let built = self.tris.len() - start;
            if self.stats.forced - forced_before > 30 + built / 50 {
                return Err(Error::Stuck(format!(
                    "component {} needed {} forced moves in {built} triangles at L = {}",
                    self.comp,
                    self.stats.forced - forced_before,
                    self.l
                )));
            }
            if self.tris.len() - start > budget {
                return Err(Error::Stuck(format!(
                    "component {} needed more than {budget} triangles (the retiler is \
                     wrapping the surface more than once)",
                    self.comp
                )));
            }
            if let Some(at) = trace_var("WHET_SWING_DUMP_AT") {
                if at.to_str().and_then(|x| x.parse::<usize>().ok()) == Some(self.tris.len()) {
                    self.dump(std::path::Path::new("/tmp/dump_at.off"), gate);
                }
            }
            if self.runaway {
                self.runaway = false;
                return Err(Error::Stuck(format!(
                    "component {} has a vertex with more than {MAX_VALENCE} triangles (the \
                     front is spinning around it)",
                    self.comp
                )));
            }
            let stepped = self.step(gate);
            if let (Err(_), Some(path)) = (&stepped, trace_var("WHET_SWING_DUMP")) {
                self.dump(std::path::Path::new(&path), gate);
            }
            match stepped? {
                Some(next) => gate = next,
                None => match self.pop() {
                    Some(g) => gate = g,
                    None => break,
                },
            }
        }
        Ok(())
    }

    /// Debugging aid: writes the partial retiled mesh as OFF and the stuck gate's vertices.
    fn dump(&self, path: &std::path::Path, gate: u32) {
        use std::fmt::Write as _;
        let mut s = format!("OFF\n{} {} 0\n", self.pos.len(), self.tris.len());
        for p in &self.pos {
            let _ = writeln!(s, "{} {} {}", p.x, p.y, p.z);
        }
        for t in &self.tris {
            let _ = writeln!(s, "3 {} {} {}", t[0], t[1], t[2]);
        }
        let _ = std::fs::write(path, s);
        let a = self.nodes[gate as usize].v;
        let b = self.nodes[self.nodes[gate as usize].next as usize].v;
        eprintln!(
            "stuck gate {a} -> {b}: {:?} -> {:?}, normal {:?}",
            self.pos[a as usize].to_array(),
            self.pos[b as usize].to_array(),
            self.nrm[a as usize].to_array()
        );
    }

    /// The deferred gate to continue with, skipping those whose edge was used meanwhile.
    fn pop(&mut self) -> Option<u32> {
        while let Some((n, a, w)) = self.stack.pop() {
            if self.built(a, w) {
                continue;
            }
            let node = self.nodes[n as usize];
            if node.alive && node.v == a && self.nodes[node.next as usize].v == w {
                return Some(n);
            }
            // Not reachable: an unused loop edge keeps its node. Search a's nodes anyway.
            let mut m = self.vnode[a as usize];
            while m != NONE {
                let nm = self.nodes[m as usize];
                if nm.alive && self.nodes[nm.next as usize].v == w {
                    return Some(m);
                }
                m = nm.same;
            }
        }
        None
    }

    /// Places the seed triangle `[x0, x1, x2]` of the current component on the surface and
    /// returns the first gate `x0 -> x2`.
    fn seed(&mut self, first_tri: u32, attempt: usize) -> Result<u32, Error> {
        // Seed `attempt` is the first valid candidate at least SEED_SPREAD · L from the
        // seeds of the attempts before it (a neighbour of a seed that stalled grows the same
        // front).
        let mut earlier: Vec<DVec3> = Vec::new();
        let mesh = self.surf.mesh;
        let l = self.l;
        let comp = self.comp;
        // First pass strict (off the caps of holes, sides between 0.7 L and 1.4 L), then
        // anywhere with sides between 0.3 L and 1.8 L (a surface riddled with holes).
        for (avoid_caps, lo, hi) in [(true, 0.7, 1.4), (false, 0.3, 1.8)] {
            // Candidates spread over the component, flattest first: a seed on a crease or a
            // corner starts the spiral badly.
            // (`first_tri` is the component's first triangle: all of its triangles.)
            let tris: Vec<usize> = self
                .component_tris(comp)
                .iter()
                .map(|&t| t as usize)
                .filter(|&t| {
                    t >= first_tri as usize
                        && !(avoid_caps && self.filler.get(t).copied().unwrap_or(false))
                })
                .collect();
            let stride = (tris.len() / 96).max(1);
            // Candidate points are triangle centroids: on coarse CAD meshes the vertices all
            // sit on creases and corners.
            let mut candidates: Vec<(f64, usize, DVec3)> = Vec::new();
            for &t in tris.iter().step_by(stride) {
                let [p0, p1, p2] = mesh.triangle_positions(t);
                let (n, flat) = self
                    .surf
                    .normal_coherence((p0 + p1 + p2) / 3.0, 1.5 * l, comp);
                if n != DVec3::ZERO {
                    candidates.push((flat, t, n));
                }
            }
            candidates.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
            for &(_, t0, n0) in candidates.iter().take(32) {
                let [p0, p1, p2] = mesh.triangle_positions(t0);
                let x0 = (p0 + p1 + p2) / 3.0;
                let t = n0.any_orthonormal_vector();
                let s = n0.cross(t);
                let Some((x1, t1)) = self.surf.closest_in_component(x0 + t * l, comp, l) else {
                    continue;
                };
                let target2 = x0 + (t * 0.5 + s * (0.75f64).sqrt()) * l;
                let Some((x2, t2)) = self.surf.closest_in_component(target2, comp, l) else {
                    continue;
                };
                let (g0, q0) = self.params.snap_seed(x0);
                let (g1, q1) = self.params.snap_seed(x1);
                let (g2, q2) = self.params.snap_seed(x2);
                let nrm = (q1 - q0).cross(q2 - q0);
                let edges_ok = [(q0, q1), (q1, q2), (q2, q0)].iter().all(|(a, b)| {
                    let d = (*a - *b).length();
                    d > lo * l && d < hi * l
                });
                if nrm.dot(n0).is_nan() || nrm.dot(n0) <= 0.0 || !edges_ok {
                    continue;
                }
                if earlier.len() < attempt {
                    if earlier.iter().all(|e| e.distance(x0) >= SEED_SPREAD * l) {
                        earlier.push(x0);
                    }
                    continue;
                }
                if earlier.iter().any(|e| e.distance(x0) < SEED_SPREAD * l) {
                    continue;
                }
                let n1 = self.surf.normal_at(t1, x1);
                let n1 = self.surf.smooth_normal(x1, 0.5 * l, comp, n1);
                let n2 = self.surf.normal_at(t2, x2);
                let n2 = self.surf.smooth_normal(x2, 0.5 * l, comp, n2);
                let a = self.add_vertex(q0, n0, VertexSource::Seed(g0));
                let b = self.add_vertex(q1, n1, VertexSource::Seed(g1));
                let c = self.add_vertex(q2, n2, VertexSource::Seed(g2));
                self.add_triangle([a, b, c]);
                // Loop x0 -> x2 -> x1 -> x0 (the seed's edges reversed).
                let n_a = self.add_node(a);
                let n_c = self.add_node(c);
                let n_b = self.add_node(b);
                self.link(n_a, n_c);
                self.link(n_c, n_b);
                self.link(n_b, n_a);
                return Ok(n_a);
            }
        }
        Err(Error::Stuck(format!(
            "no seed triangle of edge length {l} fits on component {comp}"
        )))
    }

    #[inline]
    fn link(&mut self, a: u32, b: u32) {
        self.nodes[a as usize].next = b;
        self.nodes[b as usize].prev = a;
    }

    // --- Geometry of the front ----------------------------------------------------------

    /// The open angle of node `n`: `2π` minus the angles of the built triangles of its
    /// sector (walked around the vertex from the loop edge to its next node to the one from
    /// its previous node), projected on the plane normal to the sum of their normals and
    /// `extra` (the normal of a triangle about to be added). Unlike the angle between the two
    /// loop edges it does not wrap: a sector whose triangles overlap gives a negative open
    /// angle, a nearly closed one a small positive angle. Measuring in the plane of the
    /// retiled fan itself, not along the original's normal, keeps it meaningful at creases
    /// and thin edges where the original's normals point anywhere. Returns the open angle
    /// and the projection normal.
    fn wedge_in(&self, n: u32, extra: DVec3) -> (f64, DVec3) {
        let node = self.nodes[n as usize];
        let v = node.v;
        let p = self.pos[v as usize];
        let xv = self.nodes[node.next as usize].v;
        let pv = self.nodes[node.prev as usize].v;
        let mut fan = [0u32; 66];
        let mut len = 1;
        fan[0] = xv;
        let mut sum = extra;
        let mut from = xv;
        // At most the vertex's valence; a guard against a corrupt fan.
        while len < fan.len() {
            let Some(&t) = self.edges.get(&ekey(from, v)) else {
                break;
            };
            sum += self.tri_normal[t as usize];
            let y = self.tris[t as usize]
                .iter()
                .copied()
                .find(|&u| u != from && u != v)
                .unwrap_or(from);
            fan[len] = y;
            len += 1;
            if y == pv {
                break;
            }
            from = y;
        }
        let mut nn = sum.normalize_or_zero();
        if nn == DVec3::ZERO {
            nn = self.nrm[v as usize];
        }
        let mut used = 0.0;
        for k in 1..len {
            let mut ang = ccw(
                nn,
                self.pos[fan[k] as usize] - p,
                self.pos[fan[k - 1] as usize] - p,
            );
            if ang > PI {
                ang -= TAU;
            }
            used += ang;
        }
        (TAU - used, nn)
    }

    /// The open angle of node `n` (see [`Self::wedge_in`]).
    #[inline]
    fn wedge(&self, n: u32) -> f64 {
        self.wedge_in(n, DVec3::ZERO).0
    }

    /// Does the triangle corner at node `n`, spanning counter-clockwise from the ray towards
    /// `first` to the ray towards `second`, fit inside the node's open wedge?
    #[inline]
    fn fits_wedge(&self, n: u32, first: DVec3, second: DVec3) -> bool {
        self.wedge_violation(n, first, second) == 0.0
    }

    /// How far (radians beyond the slack) the corner at node `n` spanning from `first` to
    /// `second` leaves the node's open wedge; 0 when it fits.
    fn wedge_violation(&self, n: u32, first: DVec3, second: DVec3) -> f64 {
        let node = self.nodes[n as usize];
        let p = self.pos[node.v as usize];
        let tri_n = (first - p).cross(second - p).normalize_or_zero();
        let (open, nn) = self.wedge_in(n, tri_n);
        let r = self.pos[self.nodes[node.next as usize].v as usize] - p;
        let slack = self.tune.wedge_slack;
        // Directions in the built arc (open..2π) count as clockwise of the reference ray
        // when they are nearer to its start than to the open wedge's end.
        let split = open.max(0.0) + (TAU - open.max(0.0)) * 0.5;
        let norm = |a: f64| if a > split { a - TAU } else { a };
        let af = norm(ccw(nn, r, first - p));
        let as_ = norm(ccw(nn, r, second - p));
        let projected =
            (af - as_ - slack).max(0.0) + (as_ - open - slack).max(0.0) + (-af - slack).max(0.0);
        if projected == 0.0 {
            return 0.0;
        }
        // Intrinsically (3D corner angles, as if the fan were unfolded): exact across a
        // crease, where the projection distorts the steep side. Either view may accept.
        let corner = angle3(first - p, second - p);
        let intrinsic = (corner - self.intrinsic_open(n) - slack).max(0.0);
        projected.min(intrinsic)
    }

    /// `2π` minus the 3D corner angles of the sector of node `n`.
    fn intrinsic_open(&self, n: u32) -> f64 {
        let node = self.nodes[n as usize];
        let v = node.v;
        let p = self.pos[v as usize];
        let pv = self.nodes[node.prev as usize].v;
        let mut from = self.nodes[node.next as usize].v;
        let mut used = 0.0;
        for _ in 0..64 {
            let Some(&t) = self.edges.get(&ekey(from, v)) else {
                break;
            };
            let y = self.tris[t as usize]
                .iter()
                .copied()
                .find(|&u| u != from && u != v)
                .unwrap_or(from);
            used += angle3(self.pos[y as usize] - p, self.pos[from as usize] - p);
            if y == pv {
                break;
            }
            from = y;
        }
        TAU - used
    }

    /// Combinatorial (and, with `geometric`, geometric) validity of existing node `w_node`
    /// as the tip of gate `A -> B`.
    fn valid_existing(&self, an: u32, bn: u32, wn: u32, geometric: bool) -> bool {
        let a = self.nodes[an as usize].v;
        let b = self.nodes[bn as usize].v;
        let w = self.nodes[wn as usize].v;
        if !self.nodes[wn as usize].alive || w == a || w == b {
            return false;
        }
        let xn = self.nodes[bn as usize].next;
        let pn = self.nodes[an as usize].prev;
        if self.built(b, w) || self.built(w, a) {
            return false;
        }
        if wn != xn && self.built(w, b) {
            return false;
        }
        if wn != pn && self.built(a, w) {
            return false;
        }
        // Never glue a triangle onto the three edges of one and the same triangle: that
        // closes a two-triangle pillow (only tiny components are pillows, built elsewhere).
        if let (Some(r), Some(l), Some(p)) = (
            self.edges.get(&ekey(w, b)),
            self.edges.get(&ekey(a, w)),
            self.edges.get(&ekey(b, a)),
        ) {
            if r == l && l == p {
                return false;
            }
        }
        if !geometric {
            return true;
        }
        let (pa, pb, pw) = (
            self.pos[a as usize],
            self.pos[b as usize],
            self.pos[w as usize],
        );
        // Edges longer than about 2L would leave gates no swing can cross.
        let max_edge = self.tune.max_edge * self.l;
        if (pw - pa).length() > max_edge || (pw - pb).length() > max_edge {
            return false;
        }
        if !self.triangle_ok(a, b, pw, self.nrm[w as usize]) {
            return false;
        }
        // Folds against the neighbours it will be glued to.
        let nt = (pa - pw).cross(pb - pw).normalize_or_zero();
        let cos_fold = self.tune.max_fold.cos();
        for (x, y) in [(w, b), (a, w)] {
            if let Some(&t) = self.edges.get(&ekey(x, y)) {
                if nt.dot(self.tri_normal[t as usize]) < cos_fold {
                    return false;
                }
            }
        }
        self.existing_wedges(an, bn, wn) == 0.0
    }

    /// Wedge violations of the corners of triangle `(w, a, b)`. A corner that fills its
    /// node's whole wedge (b for R, a for L, both for E) closes that wedge whatever its
    /// size: it is exactly what an over-full wedge needs, so it is not measured.
    fn existing_wedges(&self, an: u32, bn: u32, wn: u32) -> f64 {
        let xn = self.nodes[bn as usize].next;
        let pn = self.nodes[an as usize].prev;
        let (pa, pb, pw) = (
            self.pos[self.nodes[an as usize].v as usize],
            self.pos[self.nodes[bn as usize].v as usize],
            self.pos[self.nodes[wn as usize].v as usize],
        );
        let mut v = self.wedge_violation(wn, pa, pb);
        if wn != xn {
            v += self.wedge_violation(bn, pw, pa);
        }
        if wn != pn {
            v += self.wedge_violation(an, pb, pw);
        }
        v
    }

    /// Shape checks shared by new and existing tips: non-degenerate, facing outwards, folding
    /// less than `max_fold` against the parent.
    fn triangle_ok(&self, a: u32, b: u32, pw: DVec3, nw: DVec3) -> bool {
        let (pa, pb) = (self.pos[a as usize], self.pos[b as usize]);
        let n = (pa - pw).cross(pb - pw);
        let len = n.length();
        if len.is_nan() || len <= 1e-9 * self.l * self.l {
            return false;
        }
        let nt = n / len;
        if !self.faces_out(
            nt,
            pa,
            pb,
            pw,
            self.nrm[a as usize] + self.nrm[b as usize] + nw,
        ) {
            return false;
        }
        match self.edges.get(&ekey(b, a)) {
            Some(&t) => nt.dot(self.tri_normal[t as usize]) >= self.tune.max_fold.cos(),
            None => true,
        }
    }

    /// How far (fraction of `L`, at most 1) triangle `(w, a, b)` strays from the original:
    /// the largest distance to `M` of its centroid and the midpoints of its new edges
    /// `w a`, `w b`. A closing triangle far off `M` bridges a gap or cuts off a part
    /// thinner than `L` (an ear, a finger) that the front should climb instead.
    fn off_surface(&mut self, pa: DVec3, pb: DVec3, pw: DVec3) -> f64 {
        let l = self.l;
        let mut worst: f64 = 0.0;
        for p in [(pa + pb + pw) / 3.0, (pa + pw) * 0.5, (pb + pw) * 0.5] {
            let d = match self.surf.closest_in_component(p, self.comp, l) {
                Some((x, _)) => (x - p).length() / l,
                None => 1.0,
            };
            worst = worst.max(d);
            if worst >= self.tune.off_surface {
                break;
            }
        }
        worst
    }

    /// Triangles incident to vertex `v` so far.
    fn triangle_count(&self, v: u32) -> u32 {
        self.valence[v as usize]
    }

    /// Adjustment of the closing angle of node `n`'s wedge by the valence its vertex would
    /// end with: `+valence_bias` when one more triangle makes it 6 or more (closing now
    /// is regular, or keeps an already high valence from growing), `-valence_bias` when it
    /// would stay under 6 (one more swing fills the wedge better). Only for a vertex with
    /// one live node (closing its wedge makes it interior).
    fn valence_bias(&self, n: u32) -> f64 {
        let v = self.nodes[n as usize].v;
        if self.vlive[v as usize] != 1 || self.tune.valence_bias == 0.0 {
            return 0.0;
        }
        if self.triangle_count(v) + 1 >= 6 {
            self.tune.valence_bias
        } else {
            -self.tune.valence_bias
        }
    }

    /// Is closing gate `an -> bn` with existing node `wn` a triangle on the surface?
    fn on_surface(&mut self, an: u32, bn: u32, wn: u32) -> bool {
        let [pa, pb, pw] = [an, bn, wn].map(|n| self.pos[self.nodes[n as usize].v as usize]);
        self.off_surface(pa, pb, pw) < self.tune.off_surface
    }

    /// Does a triangle with unit normal `nt` and corners `pa, pb, pw` face outwards? Judged
    /// against the original's face nearest to its centroid (smoothed vertex normals,
    /// `vertex_sum`, mislead across creases and thin edges; they are the fallback when no
    /// face is near).
    fn faces_out(&self, nt: DVec3, pa: DVec3, pb: DVec3, pw: DVec3, vertex_sum: DVec3) -> bool {
        // Clearly outwards by the vertex normals: no query needed.
        if nt.dot(vertex_sum) > 0.5 * vertex_sum.length() {
            return true;
        }
        let c = (pa + pb + pw) / 3.0;
        match self.surf.closest_face_normal(c, self.comp, 0.75 * self.l) {
            Some(n) => nt.dot(n) > -0.3,
            None => nt.dot(vertex_sum) > 0.0,
        }
    }

    /// Is `h` (surface normal `nh`) over a built triangle facing the same way (within
    /// `cover_thickness · L` of its plane)? A triangle facing away is the other side of a
    /// thin part, which the front may still have to wrap.
    fn covered(&mut self, h: DVec3, nh: DVec3) -> bool {
        let l = self.l;
        let thick = self.tune.cover_thickness * l;
        self.query = self.query.wrapping_add(1);
        if self.query == 0 {
            self.tri_stamp.iter_mut().for_each(|s| *s = 0);
            self.query = 1;
        }
        if self.tri_stamp.len() < self.tris.len() {
            self.tri_stamp.resize(self.tris.len() + 1024, 0);
        }
        let q = self.query;
        let mut hit = false;
        let mut near = Vec::new();
        let comp = self.comp;
        let vcomp = &self.vcomp;
        self.vgrid.near(h, 1.2 * l, |v| {
            if vcomp[v as usize] == comp {
                near.push(v)
            }
        });
        'outer: for v in near {
            let mut c = self.vcorner[v as usize];
            while c != NONE {
                let t = (c / 3) as usize;
                c = self.corner_next[c as usize];
                if self.tri_stamp[t] == q {
                    continue;
                }
                self.tri_stamp[t] = q;
                let n = self.tri_normal[t];
                if n.dot(nh) < 0.0 {
                    continue;
                }
                let [p0, p1, p2] = self.tris[t].map(|x| self.pos[x as usize]);
                let d = (h - p0).dot(n);
                if d.abs() > thick {
                    continue;
                }
                let x = h - n * d;
                // Inside, and at least `margin` from every edge: a hit on the border of the
                // built part is the front itself (rule 4's business), not a covered spot.
                let margin = 0.1 * l;
                let inside = [(p0, p1), (p1, p2), (p2, p0)].iter().all(|&(s, e)| {
                    let edge = e - s;
                    let len = edge.length();
                    len > 0.0 && edge.cross(x - s).dot(n) >= margin * len
                });
                if inside {
                    hit = true;
                    if trace_var("WHET_SWING_TRACE2").is_some() {
                        eprintln!(
                            "   covered by tri {t} {:?} d {:.3}L at h {:?} tri pts {:?}",
                            self.tris[t],
                            d / l,
                            h.to_array(),
                            [p0, p1, p2].map(|p| p.to_array())
                        );
                    }
                    break 'outer;
                }
            }
        }
        hit
    }

    /// The live loop vertex nearest to `p` (surface normal `np`) within `radius`, other
    /// than `a` and `b`; and whether a closed (interior) vertex lies within `clearance`.
    /// Vertices whose normal opposes `np` are on the other side of a thin part and ignored.
    fn nearest_live(
        &self,
        p: DVec3,
        np: DVec3,
        radius: f64,
        clearance: f64,
        a: u32,
        b: u32,
    ) -> (Option<u32>, bool) {
        let mut best: Option<(f64, u32)> = None;
        let mut blocked = false;
        let r2 = radius * radius;
        let c2 = clearance * clearance;
        self.vgrid.near(p, radius.max(clearance), |v| {
            if v == a || v == b || self.vcomp[v as usize] != self.comp {
                return;
            }
            if self.nrm[v as usize].dot(np) < -0.2 {
                return;
            }
            let d2 = (self.pos[v as usize] - p).length_squared();
            if self.vlive[v as usize] == 0 {
                if d2 < c2 {
                    blocked = true;
                }
                return;
            }
            if d2 <= r2 && best.is_none_or(|(bd, _)| d2 < bd) {
                best = Some((d2, v));
            }
        });
        (best.map(|(_, v)| v), blocked)
    }

    /// The live nodes of vertex `v`, preferring the gate's neighbours `x` and `p` nodes.
    fn nodes_of(&self, v: u32, xn: u32, pn: u32) -> Vec<u32> {
        if self.nodes[xn as usize].v == v {
            return vec![xn];
        }
        if self.nodes[pn as usize].v == v {
            return vec![pn];
        }
        let mut out = Vec::new();
        let mut m = self.vnode[v as usize];
        while m != NONE {
            if self.nodes[m as usize].alive {
                out.push(m);
            }
            m = self.nodes[m as usize].same;
        }
        out
    }

    // --- One step -----------------------------------------------------------------------

    /// Builds the triangle at gate node `an`; returns the next gate, or `None` after an E.
    fn step(&mut self, an: u32) -> Result<Option<u32>, Error> {
        let bn = self.nodes[an as usize].next;
        let xn = self.nodes[bn as usize].next;
        let pn = self.nodes[an as usize].prev;
        let a = self.nodes[an as usize].v;
        let b = self.nodes[bn as usize].v;
        let three = xn == pn;
        let open_b = self.wedge(bn);
        let open_a = self.wedge(an);
        let close = self.tune.close_angle;
        // Rule 2: a small loop of three closes.
        if three
            && (open_a < close || open_b < close)
            && self.valid_existing(an, bn, xn, true)
            && self.on_surface(an, bn, xn)
        {
            return self.apply(an, Tip::Existing(xn));
        }
        // Rule 3: close a small wedge.
        if !three {
            let mut cands = [(open_b, xn), (open_a, pn)];
            if open_a < open_b {
                cands.swap(0, 1);
            }
            for (angle, n) in cands {
                // The vertex whose wedge closes (b for R, a for L) becomes interior with
                // one more triangle: lean towards closing when that makes it regular.
                let closing = if n == xn { bn } else { an };
                if angle < close + self.valence_bias(closing)
                    && self.valid_existing(an, bn, n, true)
                    && self.on_surface(an, bn, n)
                {
                    return self.apply(an, Tip::Existing(n));
                }
            }
        }
        // Rules 4 and 5: swing.
        let (pa, pb) = (self.pos[a as usize], self.pos[b as usize]);
        let mut spare: Option<Spare> = None;
        if let Some(c) = self.parent_vertex(a, b) {
            if let Some(frame) = self.params.frame(pa, pb, self.pos[c as usize]) {
                let mut hits = std::mem::take(&mut self.hits);
                self.surf.circle_hits(&frame, self.comp, &mut hits);
                let tmax = self.tune.theta_max;
                let best = hits
                    .iter()
                    .filter(|h| h.theta.abs() <= tmax)
                    .min_by(|x, y| x.theta.abs().total_cmp(&y.theta.abs()))
                    .copied();
                self.hits = hits;
                if let Some(h) = best {
                    let q = self.params.angles.quantize(h.theta);
                    let v = frame.tip(&self.params.angles, q);
                    let rough = self.surf.normal_at(h.triangle, h.point);
                    let normal = self
                        .surf
                        .smooth_normal(h.point, 0.5 * self.l, self.comp, rough);
                    let (near, blocked) = self.nearest_live(
                        v,
                        normal,
                        self.tune.snap * self.l,
                        self.tune.interior_clearance * self.l,
                        a,
                        b,
                    );
                    let mut penalty = 0.0;
                    if let Some(w) = near {
                        // Rule 4: the tip falls on the front: connect to it.
                        for wn in self.nodes_of(w, xn, pn) {
                            if self.valid_existing(an, bn, wn, true) && self.on_surface(an, bn, wn)
                            {
                                return self.apply(an, Tip::Existing(wn));
                            }
                        }
                        penalty += 1.0;
                    }
                    if blocked || (near.is_none() && self.covered(h.point, normal)) {
                        self.stats.covered_hits += 1;
                        penalty += 2.0;
                    }
                    if penalty == 0.0
                        && self.triangle_ok(a, b, v, normal)
                        && self.fits_wedge(bn, v, pa)
                        && self.fits_wedge(an, pb, v)
                    {
                        // Rule 5: a new vertex.
                        return self.apply(an, Tip::New { pos: v, normal, q });
                    }
                    if trace_var("WHET_SWING_TRACE").is_some() {
                        eprintln!(
                            "C refused at tri {}: theta {:.0} penalty {penalty} tri_ok {} fits b {} ({:.0}) fits a {} ({:.0}), viol b {:.2} a {:.2}",
                            self.tris.len(),
                            h.theta.to_degrees(),
                            self.triangle_ok(a, b, v, normal),
                            self.fits_wedge(bn, v, pa),
                            open_b.to_degrees(),
                            self.fits_wedge(an, pb, v),
                            open_a.to_degrees(),
                            self.wedge_violation(bn, v, pa),
                            self.wedge_violation(an, pb, v),
                        );
                    }
                    spare = Some(Spare {
                        pos: v,
                        normal,
                        q,
                        penalty,
                    });
                }
                // No clean hit: the point of the circle nearest to the surface, off the
                // built part (the wrapper then bridges gaps narrower than L, as a shrink
                // wrap would).
                if spare.as_ref().is_none_or(|sp| sp.penalty > 0.0) {
                    if let Some(sp) = self.nearest_on_circle(&frame, a, b) {
                        // The circle passes through a hole smaller than L or a crack of
                        // M, and a point of it lies near the surface: a regular new
                        // vertex that covers the hole over.
                        if best.is_none()
                            && sp.penalty <= 0.5 + 2.0 * self.tune.bridge
                            && self.fits_wedge(bn, sp.pos, pa)
                            && self.fits_wedge(an, pb, sp.pos)
                        {
                            self.stats.bridged += 1;
                            return self.apply(
                                an,
                                Tip::New {
                                    pos: sp.pos,
                                    normal: sp.normal,
                                    q: sp.q,
                                },
                            );
                        }
                        if spare.as_ref().is_none_or(|s| sp.penalty < s.penalty) {
                            spare = Some(sp);
                        }
                    }
                }
            }
        }
        self.fallback(an, spare)
    }

    /// The admissible swing tip nearest to the surface among those not over the built
    /// part and not near a closed vertex; its penalty grows with its distance to `M`.
    fn nearest_on_circle(&mut self, frame: &SwingFrame, a: u32, b: u32) -> Option<Spare> {
        let l = self.l;
        let tmax = self.tune.theta_max;
        let angles = &self.params.angles;
        let qmax = angles.quantize(tmax).abs().min(angles.max_index());
        let stride = ((15.0f64.to_radians() / angles.step()).round() as i32).max(1);
        let mut best: Option<(f64, i32, DVec3, DVec3)> = None;
        let eval = |r: &mut Self, q: i32, best: &mut Option<(f64, i32, DVec3, DVec3)>| {
            let p = frame.tip(&r.params.angles, q);
            // Points farther than L/2 from the surface would cost more than any closure.
            let Some((x, t)) = r.surf.closest_in_component(p, r.comp, 0.5 * l) else {
                return;
            };
            let d = (x - p).length();
            if best.is_some_and(|(bd, ..)| d >= bd) {
                return;
            }
            let rough = r.surf.normal_at(t, x);
            let n = r.surf.smooth_normal(x, 0.5 * l, r.comp, rough);
            let (near, blocked) =
                r.nearest_live(p, n, r.tune.snap * l, r.tune.interior_clearance * l, a, b);
            if near.is_some() || blocked || r.covered(x, n) {
                return;
            }
            *best = Some((d, q, p, n));
        };
        let mut q = -qmax;
        while q <= qmax {
            eval(self, q, &mut best);
            q += stride;
        }
        let (_, q0, ..) = best?;
        for q in (q0 - stride + 1)..(q0 + stride) {
            if q != q0 && (-qmax..=qmax).contains(&q) {
                eval(self, q, &mut best);
            }
        }
        best.map(|(d, q, pos, normal)| Spare {
            pos,
            normal,
            q,
            penalty: 0.5 + 2.0 * d / l,
        })
    }

    /// Rule 6: no regular move fits. Every combinatorially valid move (the loop
    /// neighbours, any front vertex near the gate, the spare swing tip) gets a cost for how
    /// much it violates the geometric checks and how long its edges are, and the cheapest is
    /// taken: the mesh stays a valid manifold and degrades gracefully where the surface is
    /// hard (thin parts, sharp creases, pockets of the front).
    fn fallback(&mut self, an: u32, spare: Option<Spare>) -> Result<Option<u32>, Error> {
        self.stats.fallbacks += 1;
        let bn = self.nodes[an as usize].next;
        let xn = self.nodes[bn as usize].next;
        let pn = self.nodes[an as usize].prev;
        let a = self.nodes[an as usize].v;
        let b = self.nodes[bn as usize].v;
        let (pa, pb) = (self.pos[a as usize], self.pos[b as usize]);
        let mut nodes = vec![xn, pn];
        let mid = (pa + pb) * 0.5;
        let radius = 2.5 * self.l + (pa - pb).length();
        let mut near = Vec::new();
        self.vgrid.near(mid, radius, |v| {
            if v != a && v != b && self.vlive[v as usize] > 0 && self.vcomp[v as usize] == self.comp
            {
                near.push(v);
            }
        });
        for v in near {
            for wn in self.nodes_of(v, xn, pn) {
                if !nodes.contains(&wn) {
                    nodes.push(wn);
                }
            }
        }
        // (cost, cost without the off-surface term, choice): a move that only strays from
        // the surface is not "forced" (the count that makes the retiler give up).
        let mut best: Option<(f64, f64, Option<u32>)> = None;
        for wn in nodes {
            if self.valid_existing(an, bn, wn, false) {
                // The off-surface term only adds (it is at least 0), so a candidate whose
                // cost without it already reaches the best cannot win: its three surface
                // queries are skipped (half the run on small hostile meshes, where every
                // front node is near the gate), and so is the rest of its cost once a
                // partial sum reaches the best (infinity then). The same choice as
                // measuring every one.
                let base = self.existing_cost_below(an, bn, wn, best.map(|(bc, ..)| bc));
                if best.is_some_and(|(bc, ..)| base >= bc) {
                    continue;
                }
                let [pa, pb, pw] =
                    [an, bn, wn].map(|n| self.pos[self.nodes[n as usize].v as usize]);
                let off = (self.off_surface(pa, pb, pw) - self.tune.off_surface).max(0.0);
                let c = base + 2.0 * off;
                if best.is_none_or(|(bc, ..)| c < bc) {
                    best = Some((c, base, Some(wn)));
                }
            }
        }
        if let Some(sp) = &spare {
            let c = 0.5 + sp.penalty + self.new_cost(an, bn, sp.pos, sp.normal);
            if best.is_none_or(|(bc, ..)| c < bc) {
                best = Some((c, c, None));
            }
        }
        if trace_var("WHET_SWING_TRACE").is_some() {
            let x = self.nodes[xn as usize].v;
            let px = self.pos[x as usize];
            eprintln!(
                "   R parts: shape {:.2} viol b {:.2} a {:.2} x {:.2}",
                self.shape_cost(a, b, px, self.nrm[x as usize]),
                self.wedge_violation(bn, px, pa),
                self.wedge_violation(an, pb, px),
                self.wedge_violation(xn, pa, pb)
            );
            eprintln!(
                "fallback at tri {}: gate {a}->{b} len {:.3}L, spare {:?}, best {:?}; R: valid {} cost {:.2} len {:.2}L built(x,a) {} built(a,x) {}",
                self.tris.len(),
                (pa - pb).length() / self.l,
                spare.as_ref().map(|s| s.penalty),
                best,
                self.valid_existing(an, bn, xn, false),
                self.existing_cost(an, bn, xn),
                (self.pos[x as usize] - pa).length() / self.l,
                self.built(x, a),
                self.built(a, x),
            );
        }
        match best {
            Some((_, base, choice)) => {
                if base > 2.0 {
                    self.stats.forced += 1;
                }
                match (choice, spare) {
                    (Some(wn), _) => self.apply(an, Tip::Existing(wn)),
                    (None, Some(sp)) => self.apply(
                        an,
                        Tip::New {
                            pos: sp.pos,
                            normal: sp.normal,
                            q: sp.q,
                        },
                    ),
                    (None, None) => Err(Error::Internal("fallback chose nothing".into())),
                }
            }
            None => Err(Error::Stuck(format!(
                "no valid triangle closes the gate between retiled vertices {a} and {b}"
            ))),
        }
    }

    /// Cost of closing gate `an -> bn` with existing node `wn` (0 when every check passes).
    fn existing_cost(&self, an: u32, bn: u32, wn: u32) -> f64 {
        self.existing_cost_below(an, bn, wn, None)
    }

    /// [`Self::existing_cost`], or infinity as soon as a partial sum reaches `bound`: every
    /// term is at least 0 and a sum of such terms never decreases, so the cost would reach
    /// it too. The surface query of the facing test and the wedge checks are then skipped
    /// (the fallback measures every front node near its gate). Without a bound, the cost.
    fn existing_cost_below(&self, an: u32, bn: u32, wn: u32, bound: Option<f64>) -> f64 {
        let a = self.nodes[an as usize].v;
        let b = self.nodes[bn as usize].v;
        let w = self.nodes[wn as usize].v;
        let (pa, pb, pw) = (
            self.pos[a as usize],
            self.pos[b as usize],
            self.pos[w as usize],
        );
        let reached = |c: f64| bound.is_some_and(|bound| c >= bound);
        let mut c = self.shape_cost_below(a, b, pw, self.nrm[w as usize], bound);
        let nt = (pa - pw).cross(pb - pw).normalize_or_zero();
        for (x, y) in [(w, b), (a, w)] {
            if let Some(&t) = self.edges.get(&ekey(x, y)) {
                let fold = nt.dot(self.tri_normal[t as usize]).clamp(-1.0, 1.0).acos();
                c += 2.0 * (fold - self.tune.max_fold).max(0.0);
            }
        }
        if reached(c) {
            return f64::INFINITY;
        }
        c + 2.0 * self.existing_wedges(an, bn, wn)
    }

    /// Cost of a new tip at `pv` for gate `an -> bn`.
    fn new_cost(&self, an: u32, bn: u32, pv: DVec3, nv: DVec3) -> f64 {
        let a = self.nodes[an as usize].v;
        let b = self.nodes[bn as usize].v;
        let (pa, pb) = (self.pos[a as usize], self.pos[b as usize]);
        self.shape_cost(a, b, pv, nv)
            + 2.0 * (self.wedge_violation(bn, pv, pa) + self.wedge_violation(an, pb, pv))
    }

    /// Penalties of triangle `(w, a, b)`: long edges, degeneracy, facing inwards, folding
    /// against the parent.
    fn shape_cost(&self, a: u32, b: u32, pw: DVec3, nw: DVec3) -> f64 {
        self.shape_cost_below(a, b, pw, nw, None)
    }

    /// [`Self::shape_cost`], or infinity when its edge-length term alone reaches `bound`
    /// (the other terms only add; see [`Self::existing_cost_below`]).
    fn shape_cost_below(&self, a: u32, b: u32, pw: DVec3, nw: DVec3, bound: Option<f64>) -> f64 {
        let (pa, pb) = (self.pos[a as usize], self.pos[b as usize]);
        let l = self.l;
        let longest = (pw - pa).length().max((pw - pb).length()) / l;
        // Edges of 2L or more leave gates without a swing circle: the front can then only
        // zip itself shut with ever longer edges. Avoid them at almost any price.
        let mut c = 3.0 * (longest - 1.2).max(0.0) + 20.0 * (longest - 1.9).max(0.0);
        if bound.is_some_and(|bound| c >= bound) {
            return f64::INFINITY;
        }
        let n = (pa - pw).cross(pb - pw);
        let len = n.length();
        if len.is_nan() || len <= 1e-9 * l * l {
            return c + 10.0;
        }
        let nt = n / len;
        if !self.faces_out(
            nt,
            pa,
            pb,
            pw,
            self.nrm[a as usize] + self.nrm[b as usize] + nw,
        ) {
            c += 3.0;
        }
        if let Some(&t) = self.edges.get(&ekey(b, a)) {
            let fold = nt.dot(self.tri_normal[t as usize]).clamp(-1.0, 1.0).acos();
            c += 2.0 * (fold - self.tune.max_fold).max(0.0);
        }
        c
    }

    /// Adds the triangle of gate `an` with `tip`, updates the loops and returns the next gate.
    fn apply(&mut self, an: u32, tip: Tip) -> Result<Option<u32>, Error> {
        let bn = self.nodes[an as usize].next;
        let xn = self.nodes[bn as usize].next;
        let pn = self.nodes[an as usize].prev;
        let a = self.nodes[an as usize].v;
        let b = self.nodes[bn as usize].v;
        match tip {
            Tip::New { pos, normal, q } => {
                let v = self.add_vertex(pos, normal, VertexSource::Swing(q));
                self.add_triangle([v, a, b]);
                self.labels.push(Clers::C);
                let vn = self.add_node(v);
                self.link(an, vn);
                self.link(vn, bn);
                Ok(Some(vn))
            }
            Tip::Existing(wn) => {
                let w = self.nodes[wn as usize].v;
                // The traversal's rule: right neighbour built <=> w -> b built, left <=> a -> w.
                let right = self.built(w, b);
                let left = self.built(a, w);
                self.add_triangle([w, a, b]);
                let label = match (right, left) {
                    (true, true) => Clers::E,
                    (true, false) => Clers::R,
                    (false, true) => Clers::L,
                    (false, false) => Clers::S,
                };
                self.labels.push(label);
                if trace_var("WHET_SWING_TRACE").is_some() {
                    let (pa, pb, pw) = (
                        self.pos[a as usize],
                        self.pos[b as usize],
                        self.pos[w as usize],
                    );
                    let m = (pw - pa).length().max((pw - pb).length()) / self.l;
                    if m > 1.6 {
                        eprintln!(
                            "long edge {m:.2}L by {} at tri {} (gate {:.2}L)",
                            label.letter(),
                            self.tris.len(),
                            (pa - pb).length() / self.l
                        );
                    }
                }
                let consistent = match label {
                    Clers::E => wn == xn && wn == pn,
                    Clers::R => wn == xn,
                    Clers::L => wn == pn,
                    _ => wn != xn && wn != pn,
                };
                if !consistent {
                    return Err(Error::Internal(format!(
                        "label {} does not match the loop at gate {a} -> {b}",
                        label.letter()
                    )));
                }
                match label {
                    Clers::R => {
                        self.kill_node(bn);
                        self.link(an, xn);
                        Ok(Some(an))
                    }
                    Clers::L => {
                        self.kill_node(an);
                        self.link(pn, bn);
                        Ok(Some(pn))
                    }
                    Clers::E => {
                        self.kill_node(an);
                        self.kill_node(bn);
                        self.kill_node(xn);
                        Ok(None)
                    }
                    _ => {
                        // S: W keeps its predecessor and gets successor b; a new node W2
                        // for w gets W's old successor and predecessor a.
                        let wnext = self.nodes[wn as usize].next;
                        let w2 = self.add_node(w);
                        self.link(an, w2);
                        self.link(w2, wnext);
                        self.link(wn, bn);
                        self.stack.push((an, a, w));
                        Ok(Some(wn))
                    }
                }
            }
        }
    }
}

/// The triangles of each component, by a counting sort of `component` (`count` components):
/// offsets (`count + 1`) and the triangles, increasing within each component.
fn component_triangles(component: &[u32], count: usize) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; count + 1];
    for &c in component {
        start[c as usize + 1] += 1;
    }
    for c in 0..count {
        start[c + 1] += start[c];
    }
    let mut next = start.clone();
    let mut tris = vec![0u32; component.len()];
    for (t, &c) in component.iter().enumerate() {
        tris[next[c as usize] as usize] = t as u32;
        next[c as usize] += 1;
    }
    (start, tris)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runaway_cap_stays_within_the_wedge_walk() {
        // wedge_in walks a fan of at most 66 vertices: the cap must stop the front before
        // any fan outgrows it, and leave room far above regular valences.
        const { assert!(MAX_VALENCE < 64 && MAX_VALENCE >= 24) };
    }

    #[test]
    fn ccw_measures_counter_clockwise() {
        let n = DVec3::Z;
        assert!((ccw(n, DVec3::X, DVec3::Y) - PI / 2.0).abs() < 1e-12);
        assert!((ccw(n, DVec3::Y, DVec3::X) - 1.5 * PI).abs() < 1e-12);
        assert!((ccw(n, DVec3::X, -DVec3::X) - PI).abs() < 1e-12);
    }
}
