//! The extended chamfer detection of [`Method::Extended`](crate::Method::Extended)
//! (docs/sharpen.md, "What we extend", has the reasons and the measurements).
//!
//! The papers split an edge only when both of its ends lie on the border of a smooth (red)
//! region. On marching-cubes and other irregular samplings many chamfer triangles have a
//! vertex that lies in no red triangle at all (a *gray* vertex, too close to the crease for any
//! of its triangles to be smooth), so they are never split and the chamfer survives, with the
//! largest errors at corners. We extend the detection with *labels*, one per smooth surface:
//!
//! 1. regions: the connected components of filter 3's flood (labelled in `filters`); thin
//!    corridors whose vertices lie on their neighbours' planes are demoted (`demote_corridors`);
//! 2. label planes: one per region around each region-border vertex (`border_planes`);
//! 3. each gray vertex takes the label plane of a neighbour that it lies on (`gray_vertices`);
//! 4. vertices on two surfaces get both labels; gray ones move onto their crease
//!    (`crease_vertices`, `snap_chamfer_vertices`); the nearest gray vertex of a corner point
//!    moves onto it (`corner_vertices`);
//! 5. chamfer edges join vertices that share no surface (`is_chamfer_edge`), corner triangles
//!    are those whose vertices span three surfaces (`is_corner_triangle`; by Sperner's lemma
//!    every corner of three labelled faces has one), and new vertices snap onto the planes of
//!    the best pair or triple when the point is consistent with the neighbours' planes and
//!    supported by the input surface (`edge_snap`, `corner_snap`).
//!
//! Red vertices never move; gray ones only within their chamfer.

use glam::DVec3;
use whet_mesh::{CornerId, VertexId};

use crate::edge_sharpener::{
    next, Planes, Run, C_BROWN, C_RED, NONE, T_RED, T_TOUCHED, V_CHAMFER, V_CORE, V_MOVED, V_RED,
    V_USED,
};
use crate::report::UnmovedReason;
use crate::snap::{self, Plane};

/// A gray vertex joins a neighbouring plane when it lies within this fraction of its mean
/// edge length from it. Measured on marching cubes of cube, pyramid and fandisk at 64 and 128:
/// 85-90 % of gray vertices lie within 0.25 edge lengths of the nearest neighbouring plane, the
/// rest are vertices the interpolation put inside the chamfer. Tuned on the synth table
/// (docs/results.md): 0.5 gains a little RMS at 64-128 but mislabels vertices of fandisk at 32
/// (one case then gets worse), 0.3 loses RMS everywhere. Widened by the wedge's acute reach
/// (2026-12-03, [`gray_vertices`]). Re-swept then, flat: 0.5 and 0.6 gain on seven and ten
/// rows of the marching-cubes table (all but two of them pyramid rows) and lose on none, but
/// make the rotated synth `blend` (fillets 2.6 cells wide at 64) 12-18 % worse in RMS; the
/// flat value stays and only acute cuts get more (docs/results.md, "Gray vertices in acute
/// cuts").
pub(crate) const GRAY_TOLERANCE: f64 = 0.4;

/// Labelling passes over the gray vertices (each reaches one ring further into a chamfer).
/// One: measured on the stand-in retilings (docs/results.md), a second and third pass reach
/// into blends a few samples wide (cad_cyl_fillet's fillet, cad_box_hole's hole), whose two
/// sides then meet and get sharpened into a crease, making those cases worse; on the synth
/// samplings they gain nothing.
pub(crate) const GRAY_PASSES: usize = 1;

/// A labelled gray (chamfer) vertex also takes a neighbour's non-parallel label plane when it
/// lies within this fraction of its mean edge length from it: it is next to the crease, and
/// moves onto it ([`snap_chamfer_vertices`]); if it cannot move it keeps one label. Swept on
/// the marching-cubes table (docs/results.md, "Crease tolerance"; the 30 rows of cube,
/// pyramid and fandisk at 32-128): from 0.3, 0.35 raises the RMS gain of 25 rows (up to 19 %,
/// 5.7 % geometric mean) and moves the max by at most 3.2 %; 0.4 gains 9.5 % but lets two
/// fandisk rows lose up to 43 % of their max gain (labels that place a corner vertex on three
/// planes meeting off the part), 0.5 more so. On surface samplings no gray vertex is labelled
/// (step 8) unless `SharpenOptions::surface_gray_labels` asks for it (step 20), so it applies
/// there only then.
pub(crate) const CREASE_TOLERANCE: f64 = 0.35;

/// The same for a red vertex, which never moves: only one practically on the crease takes a
/// second label. Without it, an error of the crease estimate larger than the vertex's distance
/// to the crease would fold the small piece it anchors.
pub(crate) const RED_CREASE_TOLERANCE: f64 = 0.05;

/// One region's plane at a vertex.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LabelPlane {
    pub label: u32,
    pub plane: Plane,
}

/// Labels regions and border vertices, then classifies the gray vertices.
pub(crate) fn classify(run: &mut Run) {
    run.grid_edges = None;
    run.surface_samples = is_surface_sampling(run.mesh, !run.later_pass, &mut run.grid_edges);
    // Regions with a deep vertex (marching cubes only: the corridors and `tube_creases`).
    let mut thick: Vec<bool> = Vec::new();
    if !run.surface_samples {
        // Deep vertices depend on filter 1's core flags alone, which demotion leaves as they
        // are: one pass serves both demotions (and the regions keep their labels).
        let (deep, of) = deep_vertices(run);
        thick = thick_regions(run, &deep, &of);
        demote_corridors(run, &thick);
        demote_strip_arms(run, &deep);
    }
    // The red set is final from here on.
    run.list_gray_triangles();
    let sharp_parts = if run.input_may_be_sharp {
        let (fraction, parts) = already_sharp_parts(run);
        run.report.direct_crease_fraction = fraction;
        parts
    } else {
        None
    };
    border_planes(run);
    if let Some((sharp, parts)) = &sharp_parts {
        // No label plane in an already sharp part: no chamfer edge, no corner triangle, no
        // gray vertex labelled or moved there (every later step starts from the planes).
        run.report.already_sharp_components = sharp.iter().filter(|&&x| x).count();
        for (tri, &part) in run.mesh.triangles.iter().zip(parts) {
            if sharp[part as usize] {
                for &v in tri {
                    run.s.lp_start[v as usize] = NONE;
                    run.s.lp_len[v as usize] = 0;
                }
            }
        }
    }
    // Both kinds of input measure their regions' typical turns: surface samplings for
    // `distinct_crease`, marching cubes for `flat_sided_crease`.
    region_turns(run, !run.surface_samples);
    // Surface samplings label theirs only when the options say so (step 20).
    if !run.surface_samples || run.opts.surface_gray_labels {
        gray_vertices(run);
    }
    crease_vertices(run);
    run.s.blend_creases.clear();
    if !run.surface_samples {
        blend_creases(run, &thick);
    }
    snap_chamfer_vertices(run);
}

/// A chamfer-edge end lies *off* its own plane when it is more than this fraction of the
/// edge's length under it (inside) or over it (outside; see [`blend_creases`]; convex fillet
/// arcs put their gray vertices 0.1-0.3 edges under the planes they are labelled with,
/// concave ones over them, cut creases theirs on them).
pub(crate) const BLEND_DEPTH: f64 = 0.05;

/// A crease is a rounded blend when more than this fraction of its chamfer edges have both
/// ends off their own planes on one side (after [`BLEND_PRIOR_EDGES`]; see
/// [`blend_creases`]).
/// Swept with `sharpen_diag` on 31 cases of ten synth shapes (2026-12-03; docs/results.md,
/// "Rounded blends"): 0.4 leaves the blend at 64 cells r0 1.4x worse in RMS than its input
/// (0.3 and 0.2 restore it); 0.3 still sharpens the blend at 48 cells r0 (RMS 0.083 % against
/// 0.051 % at 0.2); 0.15 changes no sharp case either, 0.1 moves the octahedron's corners
/// (32 cells r1 max 0.82 % -> 0.96 %). 0.2 keeps a step from both; 0.15-0.4 change no row of
/// the marching-cubes table or the noise table.
pub(crate) const BLEND_FRACTION: f64 = 0.2;

/// The fraction of a crease is taken as if it also had this many edges at the fraction of the
/// whole mesh's chamfer edges: a crease of one to four edges says little on its own (at a cut corner the
/// vertices lie inside all planes, so the single edges between the faces that meet at the
/// grid-aligned pyramid's apex have both ends inside), while on a mesh whose creases are
/// mostly blends its short creases are too (the corners where three fillets meet).
pub(crate) const BLEND_PRIOR_EDGES: f64 = 4.0;

/// Marching cubes: finds the creases (pairs of labels) that are rounded blends rather than
/// cut sharp edges, into `run.s.blend_creases`. [`consistent`] refuses every point computed
/// from the planes of such a pair, and [`snap_chamfer_vertices`] does not move a vertex onto
/// them, so their edges are not split and no corner vertex moves onto them.
///
/// Where the grid cut a sharp crease, the chamfer it left runs from one face plane to the
/// other: at least one end of nearly every chamfer edge lies on its own plane (a red vertex,
/// or a gray one the grid put on the face). Across a blend a few cells wide (a fillet) the
/// gray vertices lie on the arc, inside both face planes, and the edges between them join
/// two such vertices. The planes' line lies 0.41 radii above the arc at a right angle, about
/// as far as a cut crease lies from its chamfer at these resolutions, so the support test
/// cannot tell the two apart. Measured per label pair with `sharpen_diag` (2026-12-03): the
/// fraction of chamfer edges with both ends inside their own planes is 0.48-0.72 on 11 of the
/// 16 creases of the synth blend (radius 0.04) at 64 cells r0 (0.38 over the mesh), and at
/// most 0.07 on every crease of five edges or more of cube, pyramid, fandisk and cylinder at
/// 32-128 cells (generic rotations, grid-aligned and slightly turned). A fillet under about
/// 1.5 cells in radius looks like a cut crease (blend at 32 cells: 0-0.26) and is sharpened.
///
/// A concave blend (a fillet in a valley, or a concave face curved at the sampling's scale
/// that the grid split into two smooth regions) is the mirror image: its arc lies outside
/// both planes, whose line lies under it, and a snap there digs into the part (near-axis
/// fandisk at 33 cells: a row of snaps 0.5 edges under a concave face, max 1.128 -> 1.481 %).
/// An edge whose ends both lie more than [`BLEND_DEPTH`] outside their own planes counts as
/// one whose ends both lie inside; a cut concave crease, like a convex one, has an end of
/// nearly every chamfer edge on its plane.
///
/// The creases between the facets of a thin tube ([`tube_creases`]) are listed too: their
/// planes are no more trusted than a blend's. `thick` tells the regions with a deep vertex.
#[inline(never)] // one call per run; kept out of line so profiles show it
fn blend_creases(run: &mut Run, thick: &[bool]) {
    // (smaller label, larger label, edge has both ends off their planes on one side)
    let mut counts: Vec<(u32, u32, bool)> = Vec::new();
    for (c, _) in run.non_red_edges() {
        let (a, b) = (run.cv(next(c)), run.cv(crate::edge_sharpener::prev(c)));
        if !is_chamfer_edge(run, a, b) {
            continue;
        }
        let (pa, pb) = (run.positions[a as usize], run.positions[b as usize]);
        let depth = BLEND_DEPTH * pa.distance(pb);
        let height = |p: DVec3, lp: &LabelPlane| (p - lp.plane.point).dot(lp.plane.normal);
        for x in planes_of(run, a) {
            for y in planes_of(run, b) {
                let key = (x.label.min(y.label), x.label.max(y.label));
                let (ha, hb) = (height(pa, x), height(pb, y));
                let off = (ha < -depth && hb < -depth) || (ha > depth && hb > depth);
                counts.push((key.0, key.1, off));
            }
        }
    }
    // The whole mesh's fraction, over the chamfer edges.
    let total_inside = counts.iter().filter(|e| e.2).count();
    let global = total_inside as f64 / counts.len().max(1) as f64;
    // Vertices on two surfaces (step 4's crease vertices) count as edges with an end on its
    // plane: the crease passes through the input there, as it does all along a sharp edge the
    // grid cut, and seldom across a blend. Where most of a crease's vertices move onto it,
    // few chamfer edges remain to count (the stand-in of cad_box_hole at 1x: a crease of two
    // such edges, both ends inside, was refused without them and RMS went 0.0108 -> 0.0149 %).
    for v in 0..run.mesh.positions.len() as u32 {
        let planes = planes_of(run, v);
        for (i, x) in planes.iter().enumerate() {
            for y in &planes[i + 1..] {
                if !same_surface(run, x, y) {
                    counts.push((x.label.min(y.label), x.label.max(y.label), false));
                }
            }
        }
    }
    counts.sort_unstable();
    let creases: Vec<(u32, u32)> = counts
        .chunk_by(|p, q| (p.0, p.1) == (q.0, q.1))
        .map(|g| (g[0].0, g[0].1))
        .collect();
    let tubes = tube_creases(&creases, |r| {
        !thick.get(r as usize).copied().unwrap_or(false)
    });
    for group in counts.chunk_by(|p, q| (p.0, p.1) == (q.0, q.1)) {
        let inside = group.iter().filter(|e| e.2).count();
        let (n, k) = (group.len() as f64, BLEND_PRIOR_EDGES);
        let pair = (group[0].0, group[0].1);
        if inside as f64 + k * global > BLEND_FRACTION * (n + k)
            || tubes.binary_search(&pair).is_ok()
        {
            run.s.blend_creases.push(pair);
        }
    }
}

/// A closed band of at least this many thin regions, each meeting exactly two others of the
/// band at a crease, is the wall of a tube ([`tube_creases`]). Measured (2026-12-05, ninth
/// session; docs/results.md, "Tubes of thin facets"): the torus-box's hole turned near a grid
/// axis forms bands of 8 facets at 25 cells; the synth fandisk's thin regions meet in groups
/// of 2-7 with more creases than a band has (one closed band of 3 at 48 cells, generic
/// rotation, a corner where three narrow faces meet, which the rule must leave alone: at 3
/// the table's fandisk 48 r1 lost RMS gain, 3.05x -> 2.89x). 5 changes no row of the
/// marching-cubes table.
pub(crate) const TUBE_FACETS: usize = 5;

/// Marching cubes: the creases between the facets of a *thin tube*, out of the sorted label
/// pairs `creases` (smaller label first), where `thin(label)` tells a region without a deep
/// vertex (a corridor the corridor test kept, as a real narrow face). A hole's wall or a
/// boss a few cells across, turned near a grid axis, comes out of marching cubes as flat
/// grid-aligned strips, each its own thin region, each meeting the two next to it at a
/// crease: the planes of two neighbours meet outside the round wall (by `r (1 / cos(t/2) -
/// 1)` for strips turned by `t`: 16 % of the radius for the torus-box's 8 strips at 25
/// cells), and every strip is flat, so the consistency test sees nothing curved. Such a
/// closed band of at least [`TUBE_FACETS`] thin regions, each with exactly two creases to
/// others of the band, is taken for a tube and its creases are not sharpened (the creases
/// between a strip and a thick face, a hole's rim, still are). Sorted.
fn tube_creases(creases: &[(u32, u32)], thin: impl Fn(u32) -> bool) -> Vec<(u32, u32)> {
    let pairs: Vec<(u32, u32)> = creases
        .iter()
        .copied()
        .filter(|&(a, b)| thin(a) && thin(b))
        .collect();
    if pairs.len() < TUBE_FACETS {
        return Vec::new();
    }
    let mut labels: Vec<u32> = pairs.iter().flat_map(|&(a, b)| [a, b]).collect();
    labels.sort_unstable();
    labels.dedup();
    let index = |x: u32| labels.partition_point(|&l| l < x);
    // Components through thin-thin creases (union-find), with their sizes and whether every
    // member has exactly two creases: a connected component of such members is one closed
    // band.
    let n = labels.len();
    let mut root: Vec<usize> = (0..n).collect();
    fn find(root: &mut [usize], mut x: usize) -> usize {
        while root[x] != x {
            root[x] = root[root[x]];
            x = root[x];
        }
        x
    }
    let mut degree = vec![0usize; n];
    for &(a, b) in &pairs {
        let (i, j) = (index(a), index(b));
        degree[i] += 1;
        degree[j] += 1;
        let (ri, rj) = (find(&mut root, i), find(&mut root, j));
        if ri != rj {
            root[ri.max(rj)] = ri.min(rj);
        }
    }
    let (mut size, mut band) = (vec![0usize; n], vec![true; n]);
    for i in 0..n {
        let r = find(&mut root, i);
        size[r] += 1;
        band[r] &= degree[i] == 2;
    }
    pairs
        .into_iter()
        .filter(|&(a, _)| {
            let r = find(&mut root, index(a));
            band[r] && size[r] >= TUBE_FACETS
        })
        .collect()
}

/// Whether labels `a` and `b` meet in a rounded blend ([`blend_creases`]).
#[inline]
fn is_blend(run: &Run, a: u32, b: u32) -> bool {
    !run.s.blend_creases.is_empty()
        && run
            .s
            .blend_creases
            .binary_search(&(a.min(b), a.max(b)))
            .is_ok()
}

/// An input is a *surface sampling* when fewer than this fraction of its triangles have an
/// angle under [`THIN_ANGLE_DEGREES`] (see [`is_surface_sampling`]). Measured: swing-decoded
/// fixtures 0-0.1 % (6 and automatic angle bits, 0.4x-3.3x the vertex count), marching cubes
/// of the synth shapes 14-27 %, the marching-cubes stand-ins of the fixtures 14-16 %.
pub(crate) const SURFACE_SAMPLING_THIN_FRACTION: f64 = 0.02;

/// See [`SURFACE_SAMPLING_THIN_FRACTION`].
pub(crate) const THIN_ANGLE_DEGREES: f64 = 20.0;

/// Inputs whose vertices are not on the edges of an axis-aligned grid ([`on_grid_edges`])
/// are surface samplings up to this fraction of thin triangles (instead of
/// [`SURFACE_SAMPLING_THIN_FRACTION`]). The organic originals have 3.6-7.4 % of their triangles
/// thin (spot 3.6, bunny 5.9, rocker_arm 5.6, screwdriver 7.1, fertility 7.4) and no grid:
/// taken for marching cubes, their thin parts gave strips that the gray-vertex labelling
/// moved onto plane intersections (spot: 38 new vertices, a horn tip moved 1.05 % of the
/// diagonal; rocker_arm 5, 0.26 %). Marching cubes has 14-27 % (generic rotations; noise
/// along the normals, which takes its vertices off the grid, keeps them), and 2-8 % only
/// near axis-aligned rotations, where its vertices are on the grid. 10 %: the middle of the
/// gap on a log scale.
pub(crate) const GRIDLESS_THIN_FRACTION: f64 = 0.10;

/// [`on_grid_edges`] holds when at least this fraction of the sampled triangle edges have
/// ends that agree, to the bit, in exactly one coordinate. Marching cubes puts each vertex on
/// a grid edge and two of the three edges of each of its triangles in a cell face, so their
/// ends share that face's coordinate: 0.667 on every synth sampling measured (cube, pyramid
/// and fandisk at 32 and 64 cells turned generically, fandisk at 48 turned near an axis, 6.4 %
/// thin); the organic originals
/// 0-0.04, the CAD originals up to 0.30 (cad_cyl_fillet), exact-mode decodings (every
/// coordinate on the quantization lattice) 0.02-0.46 (rocker_arm at 8 bits the highest).
pub(crate) const GRID_EDGE_FRACTION: f64 = 0.55;

/// Triangles [`on_grid_edges`] looks at (spread over the triangle order).
const GRID_SAMPLE: usize = 4096;

/// Whether `mesh` looks like a regular retiling (SwingWrapper, isotropic remeshers) or an
/// original surface rather than an interpolating grid sampler (marching cubes): almost no
/// thin triangle, or, with `grid_test` and vertices that are not on the edges of an
/// axis-aligned grid ([`on_grid_edges`]), few ([`GRIDLESS_THIN_FRACTION`]). Later passes
/// (`SharpenOptions::passes`) go by the thin triangles alone: their input is the sharpener's
/// own output, whose split pieces make 2-10 % of a swing-decoded mesh's triangles thin, and
/// the marching-cubes path's labelling of the vertices left in the chamfers finished the
/// sharpened swing fandisk at 1x better (docs/results.md, "Samplings off a grid": with the
/// grid test there too its `decode --sharpen` RMS gain fell from 4.90x to 4.36x). A retiler
/// puts every vertex on the surface and makes near-equilateral triangles, so a vertex with no
/// smooth triangle around it lies on a blend rather than inside a chamfer, every vertex of a
/// chamfer strip lies on one of the two faces, and the planes of a curved face are those of
/// its own samples. Marching cubes puts vertices inside the chamfers it cuts (interpolation
/// along grid edges) and makes slivers wherever a cell is cut near a crease.
///
/// On a surface sampling the extended method (docs/sharpen.md, "Surface samplings") skips the
/// demotion of corridors (on the swing-decoded fixtures it changed nothing but joint, which it
/// made worse: RMS 0.0090 -> 0.0098 % at 4.5 bpv) and the labelling of gray vertices (on swing-decoded rocker_arm it reached into blends and made
/// them worse; on the swing-decoded CAD parts it gained nothing) and the consistency test (it
/// refused good snaps on every swing-decoded CAD part), counts the planes of one region that
/// turn by more than twice the smooth threshold as two surfaces, and refuses snaps across a
/// strip that holds a vertex on neither plane ([`STRIP_TOLERANCE`]). Everything else, and
/// marching-cubes input, is unchanged.
#[inline(never)] // one call per run; kept out of line so profiles show it
///
/// `grid` keeps the answer of [`on_grid_edges`] when the test looks at it (or gives it, when
/// known), so that a later step of the run does not sample the mesh again.
pub(crate) fn is_surface_sampling(
    mesh: &whet_mesh::Mesh,
    grid_test: bool,
    grid: &mut Option<bool>,
) -> bool {
    let nt = mesh.triangles.len();
    if nt == 0 {
        return false;
    }
    // One pass without trigonometry (the smallest angle is opposite the shortest edge; it is
    // under the limit when its cosine is above the limit's), stopping as soon as the count
    // decides: marching cubes on its grid is decided within its first tenth.
    let cos2 = THIN_ANGLE_DEGREES.to_radians().cos().powi(2);
    let allowed = (SURFACE_SAMPLING_THIN_FRACTION * nt as f64).ceil() as usize;
    let allowed_off_grid = (GRIDLESS_THIN_FRACTION * nt as f64).ceil() as usize;
    // Whether the vertices are on grid edges, looked at once the thin count reaches `allowed`.
    let mut thin = 0usize;
    for t in 0..nt {
        let p = mesh.triangle_positions(t);
        let (k, l) = crate::edge_sharpener::smallest_angle_corner(&p);
        let (a, b) = (l[(k + 2) % 3], l[(k + 1) % 3]);
        let d = (p[(k + 1) % 3] - p[k]).dot(p[(k + 2) % 3] - p[k]);
        // Degenerate triangles (a zero side: a * b == 0) count as thin.
        if a * b == 0.0 || (d > 0.0 && d * d > cos2 * a * b) {
            thin += 1;
            if thin >= allowed
                && (!grid_test
                    || *grid.get_or_insert_with(|| on_grid_edges(mesh))
                    || thin >= allowed_off_grid)
            {
                return false;
            }
        }
    }
    true
}

/// Whether the vertices of `mesh` lie on the edges of an axis-aligned grid, as marching cubes
/// puts them: at least [`GRID_EDGE_FRACTION`] of the edges of up to [`GRID_SAMPLE`] triangles
/// (spread over the triangle order) have ends that agree exactly in one coordinate and differ
/// in the other two. A mesh moved by a translation or a scale keeps the agreements (equal
/// coordinates map to equal ones); a rotation or noise loses them, and such an input is then
/// told apart by its thin triangles alone ([`GRIDLESS_THIN_FRACTION`]).
pub(crate) fn on_grid_edges(mesh: &whet_mesh::Mesh) -> bool {
    let nt = mesh.triangles.len();
    let step = nt.div_ceil(GRID_SAMPLE).max(1);
    let (mut edges, mut one) = (0usize, 0usize);
    for t in (0..nt).step_by(step) {
        let p = mesh.triangle_positions(t);
        for j in 0..3 {
            let (a, b) = (p[j], p[(j + 1) % 3]);
            let same = usize::from(a.x == b.x) + usize::from(a.y == b.y) + usize::from(a.z == b.z);
            one += usize::from(same == 1);
            edges += 1;
        }
    }
    edges > 0 && one as f64 >= GRID_EDGE_FRACTION * edges as f64
}

/// A chamfer vertex moves onto its crease or corner only when that is within this fraction of
/// its mean edge length (it lies within [`CREASE_TOLERANCE`] of its second plane, so farther
/// targets mean inconsistent planes). Measured with the tolerance at 0.35 (docs/results.md,
/// "Crease tolerance"): 0.6 moves two rows of the marching-cubes table, both for the worse
/// (fandisk 96 r0 max 2.08x -> 1.96x and RMS 4.84x -> 4.70x, fandisk 128 r0 RMS 5.65x ->
/// 5.62x); 0.75 the same fandisk 96 r0 loss against fandisk 128 r1 RMS 6.34x -> 6.41x.
pub(crate) const MOVE_LIMIT: f64 = 0.5;

/// Moves each labelled gray (chamfer) vertex that lies on two or more surfaces onto their
/// intersection: the point of the crease line nearest to it, or the (least-squares) corner
/// point. Only gray vertices move, never the vertices of smooth (red) triangles.
#[inline(never)] // one call per run; kept out of line so profiles show it
fn snap_chamfer_vertices(run: &mut Run) {
    let nv = run.mesh.positions.len();
    let mut moves: Vec<(u32, DVec3)> = Vec::new();
    let mut stay: Vec<u32> = Vec::new();
    let mut kept: Vec<LabelPlane> = Vec::new();
    let mut surfaces: Vec<Plane> = Vec::new();
    for v in 0..nv as u32 {
        if run.s.vflags[v as usize] & V_CHAMFER == 0 {
            continue;
        }
        if run.s.lp_len[v as usize] > 1 {
            // Assume it stays; a kept move below takes it off the list.
            stay.push(v);
        }
        kept.clear();
        for lp in planes_of(run, v) {
            if kept.iter().all(|k| !same_surface(run, k, lp)) {
                kept.push(*lp);
            }
        }
        let blend = kept.iter().enumerate().any(|(i, x)| {
            kept[i + 1..]
                .iter()
                .any(|y| is_blend(run, x.label, y.label))
        });
        if blend {
            continue;
        }
        if !run.surface_samples && !flat_sided_crease(run, &kept) {
            continue;
        }
        surfaces.clear();
        surfaces.extend(kept.iter().map(|k| k.plane));
        if surfaces.len() < 2 || !well_separated(run, &surfaces) {
            continue;
        }
        let p = run.mesh.positions[v as usize];
        let target = if surfaces.len() == 2 {
            snap::line_point(&surfaces[0], &surfaces[1], p)
        } else {
            snap::planes_point(&surfaces, p)
        };
        let Some(target) = target else { continue };
        let mut len = 0.0;
        let mut k = 0usize;
        for c in run.table.vertex_corners(VertexId(v)) {
            len += (run.mesh.positions[run.cv(next(c.index())) as usize] - p).length();
            k += 1;
        }
        // The vertex lies within `CREASE_TOLERANCE * reach` of its planes (see
        // `crease_vertices`), and the crease of a wedge of interior angle `a` is `1 / sin(a / 2)`
        // (`sqrt 2` times `reach`) farther than the planes from a point inside it: the limit
        // grows with the square of the reach.
        let reach = acute_reach(run, &surfaces.iter().collect::<Vec<_>>());
        if k == 0 || target.distance(p) > MOVE_LIMIT * reach * reach * len / k as f64 {
            continue;
        }
        moves.push((v, target));
    }
    // Each move with the neighbours at rest (nothing has moved yet: `run.positions` are the
    // input's): the fan must stay unfolded and free of thin triangles.
    let mut keep: Vec<bool> = moves
        .iter()
        .map(|&(v, target)| fan_stays_unfolded(run, v, target))
        .collect();
    if keep.iter().any(|&k| !k) {
        second_chance(run, &moves, &mut keep);
    }
    // A chamfer vertex that cannot reach its crease is on one surface only.
    for v in stay {
        // `moves` is in vertex order.
        let kept_move = moves
            .binary_search_by_key(&v, |m| m.0)
            .is_ok_and(|i| keep[i]);
        if !kept_move {
            run.s.lp_len[v as usize] = 1;
        }
    }
    for (&(v, target), &k) in moves.iter().zip(&keep) {
        if !k {
            continue;
        }
        run.positions[v as usize] = target;
        run.s.vflags[v as usize] |= V_MOVED;
        for c in run.table.vertex_corners(VertexId(v)) {
            run.s.tflags[c.index() / 3] |= T_TOUCHED;
        }
    }
}

/// The moves of [`snap_chamfer_vertices`] refused with their neighbours at rest, tried again
/// with every other candidate move in place (`run.positions` is left as it was). A chamfer
/// triangle whose vertices all move, onto the crease and a face, turns by up to the chamfer's
/// angle, against its input normal though not folded: such a triangle is judged by the label
/// plane it now lies on best, as [`Run::is_reversed`] judges pieces, and must face the way
/// that plane does. Moves whose fan still folds or thins give up one by one (in vertex order)
/// until every kept move's fan is sound with all kept moves in place. Synth pyramid at 128 r1:
/// a vertex inside a 58-degree cut, whose neighbour moved onto the crease too, left a gap of
/// 2.4 edges in the crease (docs/results.md, "A vertex inside an acute cut").
fn second_chance(run: &mut Run, moves: &[(u32, DVec3)], keep: &mut [bool]) {
    let thin = run.opts.min_angle_degrees.to_radians();
    for &(v, target) in moves {
        run.positions[v as usize] = target;
    }
    let lies_right = |run: &Run, t: usize| {
        let tri = run.mesh.triangles[t];
        let q = tri.map(|x| run.positions[x as usize]);
        if crate::edge_sharpener::min_angle(&q) < thin {
            return false;
        }
        let area = (q[1] - q[0]).cross(q[2] - q[0]);
        if area.dot(run.mesh.face_cross(t)) > 0.0 {
            return true;
        }
        let longest2 = (0..3)
            .map(|k| q[k].distance_squared(q[(k + 1) % 3]))
            .fold(0.0f64, f64::max);
        let mut best = (f64::INFINITY, DVec3::ZERO);
        for &x in &tri {
            for lp in planes_of(run, x) {
                let d = q
                    .iter()
                    .map(|y| (*y - lp.plane.point).dot(lp.plane.normal).abs())
                    .fold(0.0f64, f64::max);
                if d < best.0 {
                    best = (d, lp.plane.normal);
                }
            }
        }
        // On the plane as `Run::is_reversed`'s fold test counts it (a fifth of the longest
        // side), and facing its way.
        best.0 * best.0 <= 0.04 * longest2 && area.dot(best.1) > 0.0
    };
    let mut retry: Vec<usize> = (0..moves.len()).filter(|&i| !keep[i]).collect();
    loop {
        let before = retry.len();
        retry.retain(|&i| {
            let v = moves[i].0;
            let sound = run
                .table
                .vertex_corners(VertexId(v))
                .all(|c| lies_right(run, c.index() / 3));
            if !sound {
                run.positions[v as usize] = run.mesh.positions[v as usize];
            }
            sound
        });
        if retry.len() == before {
            break;
        }
    }
    for &i in &retry {
        keep[i] = true;
    }
    for &(v, _) in moves {
        run.positions[v as usize] = run.mesh.positions[v as usize];
    }
}

/// A corridor region is a chamfer when at most this fraction of its vertices is off the
/// neighbours' planes. Measured on marching cubes of cube and fandisk at 32-64 with two
/// rotations: chamfer strips that passed the smooth test have 3-10 % of their vertices off
/// (interpolation puts a few samples inside a chamfer), fandisk's real narrow bands 75-85 %.
pub(crate) const CORRIDOR_OFF_FRACTION: f64 = 0.25;

/// A vertex of a corridor region is *on a neighbour* when it lies within this fraction of its
/// mean edge length from a neighbouring region's plane (see [`demote_corridors`]).
pub(crate) const CORRIDOR_ON_PLANE: f64 = 0.1;

/// Demotes *chamfer corridors*: smooth regions too thin to have a vertex whose whole two-ring
/// lies in them (the papers' "thin corridors of smoothly connected triangles, which although
/// smooth, may correspond to the actual chamfers", seed 001 section 3.1) and almost all of
/// whose vertices lie on the planes of neighbouring regions. Their triangles stop being red, so their
/// vertices are classified like any chamfer vertex. This reaches what the papers' core test
/// (filter 1) misses on coarse samplings.
#[inline(never)] // one call per run; kept out of line so profiles show it
fn demote_corridors(run: &mut Run, thick: &[bool]) {
    let nv = run.mesh.positions.len();
    let nt = run.mesh.triangles.len();
    let nregions = thick.len();
    if thick.iter().all(|&t| t) {
        return;
    }
    // A thin region is a chamfer when every one of its vertices lies on a neighbouring
    // region's plane: marching cubes, scanners and retilers put their samples on the true
    // surface, so a chamfer strip has no vertex of its own, while a real narrow face has (its
    // core vertex at least is on none of its neighbours).
    let mut off = vec![0usize; nregions];
    let mut count = vec![0usize; nregions];
    let mut seen = vec![false; nv];
    for t in 0..nt {
        let r = run.s.region[t];
        if r == NONE || thick[r as usize] {
            continue;
        }
        for &v in &run.mesh.triangles[t] {
            if seen[v as usize] {
                continue;
            }
            seen[v as usize] = true;
            count[r as usize] += 1;
            if neighbour_plane_distance(run, v, r) > CORRIDOR_ON_PLANE {
                off[r as usize] += 1;
            }
        }
    }
    let mut demoted: Vec<bool> = (0..nregions)
        .map(|r| (off[r] as f64) <= CORRIDOR_OFF_FRACTION * count[r] as f64)
        .collect();
    let mut any = false;
    for r in 0..nregions {
        if thick[r] {
            demoted[r] = false;
        }
        any |= demoted[r];
    }
    if !any {
        return;
    }
    let gone: Vec<usize> = (0..nt)
        .filter(|&t| {
            let r = run.s.region[t];
            r != NONE && demoted[r as usize]
        })
        .collect();
    demote(run, &gone);
}

/// One past the highest region label in use (0 without red triangles): the length of the
/// per-region arrays.
fn region_count(run: &Run) -> usize {
    let labels = run.s.region.iter().filter(|&&r| r != NONE);
    labels.max().map_or(0, |&m| m as usize + 1)
}

/// Per region label (up to the highest one in use), whether it has a deep vertex (see
/// [`deep_vertices`]): the thin ones are the corridors' candidates.
fn thick_regions(run: &Run, deep: &[bool], of: &[u32]) -> Vec<bool> {
    let nregions = region_count(run);
    let mut thick = vec![false; nregions];
    for (&d, &r) in deep.iter().zip(of) {
        if d && r != NONE {
            thick[r as usize] = true;
        }
    }
    thick
}

/// The *deep* vertices, each a core vertex (filter 1: all its edges smooth, so its whole fan
/// lies in one region) whose neighbours are all core too, and the region of each (`NONE` for
/// the others). One pass over the corners.
fn deep_vertices(run: &Run) -> (Vec<bool>, Vec<u32>) {
    let flags = &run.s.vflags[..];
    let mut deep: Vec<bool> = flags.iter().map(|&f| f & V_CORE != 0).collect();
    let mut of: Vec<u32> = vec![NONE; flags.len()];
    for (tri, &region) in run.mesh.triangles.iter().zip(&run.s.region) {
        let [a, b, c] = tri.map(|v| v as usize);
        let core = [a, b, c].map(|v| flags[v] & V_CORE != 0);
        // Each vertex and the one after it: a core vertex next to a non-core one is not deep.
        for (v, next_core) in [(a, core[1]), (b, core[2]), (c, core[0])] {
            if deep[v] {
                of[v] = region;
                deep[v] = next_core;
            }
        }
    }
    (deep, of)
}

/// An inner edge of a region (both triangles in it) that turns by more than this many smooth
/// thresholds is a crease the region reaches around: see [`demote_strip_arms`]. Measured on
/// the synth table (docs/results.md, "Strip arms"): 4 found only fandisk 64 r1's and the
/// pyramid's arms; 3 also part of fandisk 48 r1's, whose rest turns from its face by 25
/// degrees, 2.5 thresholds (on 2026-12-03, before the rule that exactly one side be thin, 2.5
/// demoted a narrow corner region of the pyramid at 48 r1). Swept again on 2026-12-05
/// ("Strip arms, a lower turn"): 2.4 leaves fandisk 48 r1 at 2.95x RMS; 2.2 to 1.8 take it
/// over 3x and lower the RMS of 8 to 12 other rows, no max gain falling under 2x; 1.6
/// demotes real faces (pyramid 96 r0 max 3.36x -> 1.87x, fandisk 64 r1 2.13x -> 1.87x). 2 is
/// the middle of the range that works.
pub(crate) const STRONG_INNER_TURN: f64 = 2.0;

/// How many triangles [`demote_strip_arms`] grows from one side of a strong inner edge,
/// through smooth edges of the region, looking for a deep vertex.
pub(crate) const ARM_PROBE: usize = 8;

/// An arm's triangles lie within this many rings of a strong inner edge (see
/// [`demote_strip_arms`]): without the bound, fandisk 48 r1's arm grew along a face's border
/// into 329 triangles far from its crease; 2 and 4 rings gave the same rows at 2x and 3x, 4
/// a little more RMS.
pub(crate) const ARM_RINGS: usize = 4;

/// Demotes *strip arms*: the chamfer strip of a crease that fades out (synth fandisk) is smooth
/// and joined, through smooth edges around the crease's end, to one of its two faces, so it is
/// one thick region with that face and never a corridor; its edges with that face are inner
/// edges of the region that turn by the chamfer's angle, its vertices share the region with
/// the face's, and no chamfer edge is found along the whole crease. From each side of such a
/// strong inner edge ([`STRONG_INNER_TURN`]) the region is grown through smooth edges for
/// [`ARM_PROBE`] triangles: the face side soon reaches a deep vertex, the strip side (a band a
/// few triangles wide, every vertex next to a crease) does not. The strip side is then grown
/// through smooth edges over the region's triangles that hold no deep vertex and touch a
/// strong inner edge or the region's border, and taken out of the region like a corridor.
#[inline(never)] // one call per run; kept out of line so profiles show it
fn demote_strip_arms(run: &mut Run, deep: &[bool]) {
    let nt = run.mesh.triangles.len();
    let nv = run.mesh.positions.len();
    let threshold = (STRONG_INNER_TURN * run.smooth_threshold) as f32;
    let opposite = run.table.opposites();
    let mut strong: Vec<(usize, usize)> = Vec::new();
    // A strong turn is a rough edge (`Run::smooth_edges` lists their lower corners, which
    // hold the angles): the threshold is at least the smooth one.
    for &c in &run.s.rough {
        let c = c as usize;
        let o = opposite[c] as usize;
        let r = run.s.region[c / 3];
        if r != NONE && run.s.region[o / 3] == r && run.s.angles[c].max(run.s.angles[o]) > threshold
        {
            strong.push((c, o));
        }
    }
    if strong.is_empty() {
        return;
    }
    // Vertices of a strong inner edge, or on the border of their region (a triangle around
    // them in another region, or in none): the vertices an arm's triangles touch.
    let mut edge_vertex = vec![false; nv];
    // Vertices within ARM_RINGS rings of a strong inner edge: an arm is a band along its
    // crease, and growing along a face's border elsewhere is a leak.
    let mut near = vec![false; nv];
    let mut ring: Vec<u32> = Vec::new();
    for &(c, _) in &strong {
        for v in [run.cv(next(c)), run.cv(crate::edge_sharpener::prev(c))] {
            edge_vertex[v as usize] = true;
            if !near[v as usize] {
                near[v as usize] = true;
                ring.push(v);
            }
        }
    }
    let mut near_list = ring.clone();
    for _ in 0..ARM_RINGS {
        let mut next_ring = Vec::new();
        for &v in &ring {
            for vc in run.table.vertex_corners(VertexId(v)) {
                let w = run.cv(next(vc.index()));
                if !near[w as usize] {
                    near[w as usize] = true;
                    next_ring.push(w);
                }
            }
        }
        near_list.extend_from_slice(&next_ring);
        ring = next_ring;
    }
    // The region borders, where arms need them only (`arm_like` asks about near vertices):
    // a vertex is on one when an interior edge at it joins triangles of two regions (or a
    // region and none). Both edges at the vertex in each triangle of its fan are opposite
    // the triangle's other two corners.
    for &v in &near_list {
        if edge_vertex[v as usize] {
            continue;
        }
        edge_vertex[v as usize] = run.table.vertex_corners(VertexId(v)).any(|vc| {
            let c = vc.index();
            let r = run.s.region[c / 3];
            [next(c), crate::edge_sharpener::prev(c)]
                .into_iter()
                .any(|k| {
                    let o = opposite[k];
                    o != NONE && run.s.region[o as usize / 3] != r
                })
        });
    }
    let tri = |t: usize| run.mesh.triangles[t];
    let has_deep = |t: usize| tri(t).iter().any(|&v| deep[v as usize]);
    let arm_like = |t: usize| {
        !has_deep(t)
            && tri(t).iter().all(|&v| near[v as usize])
            && tri(t).iter().any(|&v| edge_vertex[v as usize])
    };
    // Growth through smooth edges inside one region, breadth first; `stamp` marks the
    // triangles one growth has reached (a new number per growth, no clearing).
    let mut stamp: Vec<u32> = vec![0; nt];
    let mut generation = 0u32;
    let mut reached: Vec<usize> = Vec::new();
    let mut grow =
        |t0: usize, cap: usize, admit: &dyn Fn(usize) -> bool, reached: &mut Vec<usize>| {
            generation += 1;
            let r = run.s.region[t0];
            reached.clear();
            reached.push(t0);
            stamp[t0] = generation;
            let mut i = 0;
            while i < reached.len() && reached.len() < cap {
                let t = reached[i];
                i += 1;
                for c in 3 * t..3 * t + 3 {
                    let o = opposite[c];
                    if o == NONE || run.s.cflags[c] & crate::edge_sharpener::C_BROWN == 0 {
                        continue;
                    }
                    let u = o as usize / 3;
                    if run.s.region[u] == r && stamp[u] != generation && admit(u) {
                        stamp[u] = generation;
                        reached.push(u);
                    }
                }
            }
        };
    let mut in_arm = vec![false; nt];
    let mut gone: Vec<usize> = Vec::new();
    for &(c, o) in &strong {
        // Which sides look like a strip: no deep vertex within the probe. Exactly one must
        // (near a corner or an apex both faces are narrow, and neither is known to be the
        // strip).
        let mut thin = [false; 2];
        for (k, t) in [c / 3, o / 3].into_iter().enumerate() {
            if !has_deep(t) {
                grow(t, ARM_PROBE, &|_| true, &mut reached);
                thin[k] = !reached.iter().any(|&u| has_deep(u));
            }
        }
        let t = if thin[0] { c / 3 } else { o / 3 };
        if thin[0] == thin[1] || in_arm[t] {
            continue;
        }
        grow(t, usize::MAX, &|u| !in_arm[u] && arm_like(u), &mut reached);
        for &u in &reached {
            in_arm[u] = true;
        }
        gone.extend_from_slice(&reached);
    }
    demote(run, &gone);
}

/// Takes the triangles `gone` out of their regions (no longer red), and runs filter 4 again
/// for the red triangles that remain, only where it can change: the edges and vertices of the
/// demoted triangles (a corner is red when a triangle on either side of its edge is, a vertex
/// when a triangle around it is). The same flags as running it over the whole mesh (test
/// builds check), for a few hundred triangles instead of all.
fn demote(run: &mut Run, gone: &[usize]) {
    for &t in gone {
        run.s.region[t] = NONE;
        run.s.tflags[t] &= !T_RED;
    }
    let red = |run: &Run, t: usize| run.s.tflags[t] & T_RED != 0;
    for &t in gone {
        for c in 3 * t..3 * t + 3 {
            let o = run.table.opposite(CornerId(c as u32));
            let edge_red = o.is_some_and(|o| red(run, o.index() / 3));
            set_flag(&mut run.s.cflags[c], C_RED, edge_red);
            if let Some(o) = o {
                set_flag(&mut run.s.cflags[o.index()], C_RED, edge_red);
            }
            let v = run.cv(c);
            let vertex_red = run
                .table
                .vertex_corners(VertexId(v))
                .any(|vc| red(run, vc.index() / 3));
            set_flag(&mut run.s.vflags[v as usize], V_RED, vertex_red);
        }
    }
    #[cfg(debug_assertions)]
    {
        let nt = run.mesh.triangles.len();
        let mut vflags: Vec<u8> = run.s.vflags.iter().map(|f| f & !V_RED).collect();
        let mut cflags: Vec<u8> = run.s.cflags.iter().map(|f| f & !C_RED).collect();
        for t in (0..nt).filter(|&t| red(run, t)) {
            for c in 3 * t..3 * t + 3 {
                cflags[c] |= C_RED;
                if let Some(o) = run.table.opposite(CornerId(c as u32)) {
                    cflags[o.index()] |= C_RED;
                }
                vflags[run.cv(c) as usize] |= V_RED;
            }
        }
        debug_assert!(vflags == run.s.vflags && cflags == run.s.cflags);
    }
}

/// Sets or clears `bit` in `flags`.
#[inline]
fn set_flag(flags: &mut u8, bit: u8, on: bool) {
    if on {
        *flags |= bit;
    } else {
        *flags &= !bit;
    }
}

/// Most corners of a neighbour's fan that [`neighbour_plane_distance`] reads: far above the
/// valences of the samplings sharpened (retilings, marching cubes: under 20).
const NEIGHBOUR_FAN_CORNERS: usize = 64;

/// Distance of vertex `v` from the nearest plane of a red triangle of another region than `r`
/// around it or around a neighbour, in units of its mean edge length.
fn neighbour_plane_distance(run: &Run, v: u32, r: u32) -> f64 {
    let p = run.mesh.positions[v as usize];
    let mut len = 0.0;
    let mut k = 0usize;
    let mut best = f64::INFINITY;
    let mut nearest_in_fan = |x: u32, most: usize| {
        for cc in run.table.vertex_corners(VertexId(x)).take(most) {
            let t = cc.index() / 3;
            let rt = run.s.region[t];
            if rt == NONE || rt == r {
                continue;
            }
            let n = run.s.normals[t];
            let q = run.mesh.positions[run.mesh.triangles[t][0] as usize];
            best = best.min((p - q).dot(n).abs());
        }
    };
    // The vertex's own fan once, then each neighbour's (a minimum: the order is free), the
    // first `NEIGHBOUR_FAN_CORNERS` corners of it: walking a neighbour of high valence whole
    // from each of its neighbours was quadratic in its valence.
    nearest_in_fan(v, usize::MAX);
    for c in run.table.vertex_corners(VertexId(v)) {
        let u = run.cv(next(c.index()));
        len += (run.mesh.positions[u as usize] - p).length();
        k += 1;
        nearest_in_fan(u, NEIGHBOUR_FAN_CORNERS);
    }
    best / (len / k.max(1) as f64)
}

/// The *typical turn* of each smooth region, the median normal angle of the edges inside it
/// (both triangles in the region), into `run.s.region_turn` (radians; 0 for a region without
/// inner edges). Linear: the angles are bucketed by region with prefix sums, and each bucket's
/// median is a selection, not a sort. The median, not the mean: a CAD region often joins flat
/// faces and the tangent blends between them, whose larger angles would pull a mean up; the
/// median is the turn of most of the region.
///
/// Surface samplings take every inner edge. Marching cubes (`sampled`) takes the inner edges
/// of about [`REGION_SAMPLE`] triangles, evenly spread over the triangle order (every one
/// under twice that): a face of a million-triangle sampling has hundreds of thousands, whose
/// bucketing and selection took 22 ms of a 320 ms run (every eighth triangle still 9.5 ms:
/// the passes read every cache line of the corner arrays), and a sample places its median as
/// well. A region the sample misses has typical turn 0, which refuses nothing.
#[inline(never)] // one call per run; kept out of line so profiles show it
pub(crate) fn region_turns(run: &mut Run, sampled: bool) {
    let nregions = region_count(run);
    let stride = if sampled {
        (run.mesh.triangles.len() / REGION_SAMPLE).max(1)
    } else {
        1
    };
    let s = &mut *run.s;
    s.region_turn.clear();
    s.region_turn.resize(nregions, 0.0);
    if nregions == 0 {
        return;
    }
    let opposite = run.table.opposites();
    // The inner edges of triangle `t` in region `r`: a corner holding an angle (the lower
    // corner of an interior edge) whose opposite triangle is in the same region.
    let inner = |t: usize, r: u32, s: &crate::edge_sharpener::Scratch| {
        let (mut corners, mut n) = ([0usize; 3], 0);
        for c in 3 * t..3 * t + 3 {
            let o = opposite[c];
            if s.angles[c] >= 0.0 && o != NONE && s.region[o as usize / 3] == r {
                corners[n] = c;
                n += 1;
            }
        }
        (corners, n)
    };
    s.region_start.clear();
    s.region_start.resize(nregions + 1, 0);
    for t in (0..s.region.len()).step_by(stride) {
        let r = s.region[t];
        if r != NONE {
            s.region_start[r as usize + 1] += inner(t, r, s).1 as u32;
        }
    }
    for r in 0..nregions {
        s.region_start[r + 1] += s.region_start[r];
    }
    s.region_angles.clear();
    s.region_angles
        .resize(s.region_start[nregions] as usize, 0.0);
    // Fill, advancing each region's start: afterwards region_start[r] is where r ends.
    for t in (0..s.region.len()).step_by(stride) {
        let r = s.region[t];
        if r == NONE {
            continue;
        }
        let (corners, n) = inner(t, r, s);
        for &c in &corners[..n] {
            let k = s.region_start[r as usize] as usize;
            s.region_angles[k] = s.angles[c];
            s.region_start[r as usize] += 1;
        }
    }
    for r in 0..nregions {
        let a = if r == 0 {
            0
        } else {
            s.region_start[r - 1] as usize
        };
        let b = s.region_start[r] as usize;
        s.region_turn[r] = if a == b {
            0.0
        } else {
            let bucket = &mut s.region_angles[a..b];
            let mid = bucket.len() / 2;
            *bucket.select_nth_unstable_by(mid, f32::total_cmp).1
        };
    }
}

/// Marching cubes: about how many triangles measure the regions' typical turns
/// ([`region_turns`]).
const REGION_SAMPLE: usize = 1 << 12;

/// Label planes of the red vertices that touch a non-red triangle or two regions.
#[inline(never)] // one call per run; kept out of line so profiles show it
fn border_planes(run: &mut Run) {
    let nv = run.mesh.positions.len();
    run.s.lp_start.clear();
    run.s.lp_start.resize(nv, NONE);
    run.s.lp_len.clear();
    run.s.lp_len.resize(nv, 0);
    run.s.lps.clear();
    // Border vertices: a red vertex with a non-red triangle or triangles of two regions.
    // Going around its fan, two regions meet across an edge at the vertex that is rough (a
    // brown edge joins its triangles into one region), unless a gray triangle lies between
    // them: so every border vertex is a vertex of a gray triangle or an end of a rough edge,
    // and only those are tested, in ascending order.
    // Each listed once (a vertex is in about six gray triangles), then sorted.
    let mut listed = vec![false; nv];
    let mut candidates: Vec<u32> = Vec::new();
    let mut list = |v: u32| {
        if !std::mem::replace(&mut listed[v as usize], true) {
            candidates.push(v);
        }
    };
    for &t in &run.s.gray {
        for v in run.mesh.triangles[t as usize] {
            list(v);
        }
    }
    for &c in &run.s.rough {
        let c = c as usize;
        list(run.cv(next(c)));
        list(run.cv(crate::edge_sharpener::prev(c)));
    }
    drop(listed);
    candidates.sort_unstable();
    // Per label around the vertex: the angle-weighted normal sum and the fan triangles.
    let mut acc: Vec<(u32, DVec3, u32)> = Vec::new();
    let mut ring: Vec<u32> = Vec::new();
    let mesh = run.mesh;
    let ring_planes =
        !run.surface_samples && *run.grid_edges.get_or_insert_with(|| on_grid_edges(mesh));
    for v in candidates {
        let v = v as usize;
        if run.s.vflags[v] & V_RED == 0 {
            continue;
        }
        let mut first = NONE;
        let border = run.table.vertex_corners(VertexId(v as u32)).any(|c| {
            let r = run.s.region[c.index() / 3];
            if first == NONE {
                first = r;
            }
            r == NONE || r != first
        });
        if !border {
            continue;
        }
        acc.clear();
        for c in run.table.vertex_corners(VertexId(v as u32)) {
            let t = c.index() / 3;
            let r = run.s.region[t];
            if r == NONE {
                continue;
            }
            let w = run.s.normals[t] * run.corner_angle(c.index());
            // At most 255 labels per vertex (`lp_len` is a byte): past them a new label is
            // dropped here rather than after summing, so the search stays bounded around a
            // vertex of high valence (the same labels and sums as dropping them after).
            let full = acc.len() >= u8::MAX as usize;
            match acc.iter_mut().find(|(l, _, _)| *l == r) {
                Some((_, n, k)) => {
                    *n += w;
                    *k += 1;
                }
                None if !full => acc.push((r, w, 1)),
                None => {}
            }
        }
        // Marching cubes on its grid: a label holding a single triangle of the fan takes its
        // plane from all of its triangles around the one-ring instead. That lone triangle is
        // the last before the crease, whose vertex marching cubes interpolates on a grid
        // edge that cuts the crease, so it is tilted, and its normal alone tilts the line or
        // point the vertex's chamfer is snapped onto. A surface sampling's vertices lie on
        // the surface, and so do those a pass snapped (a later pass over a sharpened
        // sampling goes down the marching-cubes path, but is off any grid): there the lone
        // triangle is as flat as its face and the ring's farther triangles only add
        // curvature (measured: the swing table's fandisk 1x stream, max 0.425 -> 0.594 %
        // after `decode --sharpen`, two passes, with the ring everywhere). The test is on
        // the mesh alone, so a later pass does what a run on the earlier output does.
        if ring_planes {
            for (label, n, in_fan) in &mut acc {
                if *in_fan == 1 {
                    *n = ring_label_normal(run, v as u32, *label, &mut ring);
                }
            }
        }
        run.s.lp_start[v] = run.s.lps.len() as u32;
        let point = run.mesh.positions[v];
        for &(label, n, _) in &acc {
            let normal = n.normalize_or_zero();
            if normal != DVec3::ZERO {
                run.s.lps.push(LabelPlane {
                    label,
                    plane: Plane { point, normal },
                });
                run.s.lp_len[v] += 1;
            }
        }
    }
}

/// The angle-weighted normal sum of the triangles of `label` that touch the one-ring of `v`
/// (each weighted by its angle at the ring vertex it is first met through, counted once;
/// `seen` is scratch).
fn ring_label_normal(run: &Run, v: u32, label: u32, seen: &mut Vec<u32>) -> DVec3 {
    seen.clear();
    let mut sum = DVec3::ZERO;
    for c in run.table.vertex_corners(VertexId(v)) {
        let u = run.cv(next(c.index()));
        for cu in run.table.vertex_corners(VertexId(u)) {
            let t = (cu.index() / 3) as u32;
            if run.s.region[t as usize] != label || seen.contains(&t) {
                continue;
            }
            seen.push(t);
            sum += run.s.normals[t as usize] * run.corner_angle(cu.index());
        }
    }
    sum
}

/// The label planes of vertex `v`.
#[inline]
pub(crate) fn planes_of<'a>(run: &'a Run, v: u32) -> &'a [LabelPlane] {
    let start = run.s.lp_start[v as usize];
    if start == NONE {
        return &[];
    }
    let len = run.s.lp_len[v as usize] as usize;
    &run.s.lps[start as usize..start as usize + len]
}

/// Gives each gray vertex the nearest label plane of a neighbour when it lies on it.
#[inline(never)] // one call per run; kept out of line so profiles show it
fn gray_vertices(run: &mut Run) {
    let nv = run.mesh.positions.len();
    let mut gray: Vec<u32> = (0..nv as u32)
        .filter(|&v| {
            let f = run.s.vflags[v as usize];
            f & V_USED != 0 && f & V_RED == 0 && !run.table.is_boundary_vertex(VertexId(v))
        })
        .collect();
    let mut found: Vec<(u32, LabelPlane)> = Vec::new();
    let mut around: Vec<LabelPlane> = Vec::new();
    for _ in 0..GRAY_PASSES {
        found.clear();
        for &g in &gray {
            let p = run.mesh.positions[g as usize];
            let mut len = 0.0;
            let mut k = 0usize;
            let mut best: Option<(f64, LabelPlane)> = None;
            around.clear();
            for c in run.table.vertex_corners(VertexId(g)) {
                let u = run.cv(next(c.index()));
                len += (run.mesh.positions[u as usize] - p).length();
                k += 1;
                for lp in planes_of(run, u) {
                    around.push(*lp);
                    let d = (p - lp.plane.point).dot(lp.plane.normal).abs();
                    let better = match &best {
                        None => true,
                        Some((bd, b)) => d < *bd || (d == *bd && lp.label < b.label),
                    };
                    if better {
                        best = Some((d, *lp));
                    }
                }
            }
            if let Some((d, lp)) = best {
                // Inside an acute cut the vertex lies deeper under the plane it belongs to
                // (marching cubes cuts a wedge of interior angle `a` `acute_reach` times deeper
                // than a right angle), so the tolerance widens with the sharpest wedge the
                // plane makes with another surface around the vertex, as step 4's does.
                let reach = around
                    .iter()
                    .filter(|o| !same_surface(run, o, &lp))
                    .map(|o| acute_reach(run, &[&lp.plane, &o.plane]))
                    .fold(1.0f64, f64::max);
                if k > 0 && d <= GRAY_TOLERANCE * reach * len / k as f64 {
                    found.push((g, lp));
                }
            }
        }
        if found.is_empty() {
            break;
        }
        // Apply after the pass, so the result does not depend on the vertex order.
        for &(g, lp) in &found {
            run.s.lp_start[g as usize] = run.s.lps.len() as u32;
            run.s.lp_len[g as usize] = 1;
            run.s.lps.push(lp);
            run.s.vflags[g as usize] |= V_CHAMFER;
        }
        gray.retain(|&g| run.s.vflags[g as usize] & V_CHAMFER == 0);
    }
    run.report.chamfer_vertices = run.s.vflags.iter().filter(|&&f| f & V_CHAMFER != 0).count();
}

/// Gives labelled vertices that lie on a neighbour's other, non-parallel plane that label too.
#[inline(never)] // one call per run; kept out of line so profiles show it
fn crease_vertices(run: &mut Run) {
    let nv = run.mesh.positions.len();
    // The mesh's mean edge (from the smooth-edge pass) serves chamfer (gray) vertices only,
    // which `gray_vertices` has just counted.
    let mesh_mean = if run.report.chamfer_vertices > 0 {
        run.mean_edge
    } else {
        0.0
    };
    let mut extra: Vec<(u32, LabelPlane)> = Vec::new();
    let mut found: Vec<LabelPlane> = Vec::new();
    for v in 0..nv as u32 {
        let own = planes_of(run, v);
        if own.is_empty() || run.table.is_boundary_vertex(VertexId(v)) {
            continue;
        }
        let p = run.mesh.positions[v as usize];
        let mut len = 0.0;
        let mut k = 0usize;
        found.clear();
        for c in run.table.vertex_corners(VertexId(v)) {
            let u = run.cv(next(c.index()));
            len += (run.mesh.positions[u as usize] - p).length();
            k += 1;
            for lp in planes_of(run, u) {
                let new_surface = own
                    .iter()
                    .chain(found.iter())
                    .all(|o| !same_surface(run, o, lp));
                if new_surface {
                    found.push(*lp);
                }
            }
        }
        if k == 0 {
            continue;
        }
        let chamfer = run.s.vflags[v as usize] & V_CHAMFER != 0;
        let factor = if chamfer {
            CREASE_TOLERANCE
        } else {
            RED_CREASE_TOLERANCE
        };
        let local = len / k as f64;
        let tol = factor * local;
        // Marching cubes cuts a chamfer as deep as its grid cell whatever the local
        // triangles, so a chamfer vertex among short edges is also measured against the
        // mesh's mean edge; a label admitted only that way must not complete a corner (a
        // triangle around the vertex reaching a third surface), whose point could lie off
        // the part.
        let wide = if chamfer {
            factor * local.max(mesh_mean)
        } else {
            tol
        };
        for &lp in &found {
            // A chamfer vertex inside an acute cut lies deeper under both planes (marching
            // cubes cuts a wedge `acute_reach` times deeper than a right angle): synth pyramid,
            // 58-degree edges, vertices 0.38 edges under both planes.
            let reach = if chamfer {
                own.iter()
                    .map(|o| acute_reach(run, &[&o.plane, &lp.plane]))
                    .fold(1.0f64, f64::max)
            } else {
                1.0
            };
            let d = (p - lp.plane.point).dot(lp.plane.normal).abs();
            if d <= tol * reach || (d <= wide * reach && !completes_corner(run, v, &lp)) {
                extra.push((v, lp));
            }
        }
    }
    // The additions, applied after the scan (order independent): each vertex that gains
    // labels gets its list again at the end, its own planes then the new ones by label (the
    // old entries stay, unreferenced, as `move_to_corner` leaves them).
    extra.sort_by_key(|(v, lp)| (*v, lp.label));
    for group in extra.chunk_by(|x, y| x.0 == y.0) {
        let v = group[0].0 as usize;
        let start = run.s.lps.len();
        let own = run.s.lp_start[v];
        if own != NONE {
            let own = own as usize;
            run.s
                .lps
                .extend_from_within(own..own + run.s.lp_len[v] as usize);
        }
        for &(_, lp) in group {
            if run.s.lps.len() - start < u8::MAX as usize {
                run.s.lps.push(lp);
            }
        }
        run.s.lp_start[v] = start as u32;
        run.s.lp_len[v] = (run.s.lps.len() - start) as u8;
    }
}

/// Whether giving `v` the label `lp` makes a triangle around it reach three surfaces that its
/// vertices' labels did not reach before.
fn completes_corner(run: &Run, v: u32, lp: &LabelPlane) -> bool {
    let mut seen: Vec<LabelPlane> = Vec::new();
    for c in run.table.vertex_corners(VertexId(v)) {
        seen.clear();
        let t = c.index() / 3;
        for &u in &run.mesh.triangles[t] {
            for q in planes_of(run, u) {
                if seen.iter().all(|o| !same_surface(run, o, q)) {
                    seen.push(*q);
                }
            }
        }
        if seen.len() == 2 && seen.iter().all(|o| !same_surface(run, o, lp)) {
            return true;
        }
    }
    false
}

/// Planes a vertex may be moved onto must meet at angles of at least twice the smooth
/// threshold (and, for three, with a triple product of at least [`MIN_CORNER_DET`]): the
/// intersection of nearly parallel planes moves by the planes' error divided by the sine of
/// their angle, and a moved input vertex, unlike a new one, changes triangles that would
/// otherwise be left alone.
fn well_separated(run: &Run, planes: &[Plane]) -> bool {
    let limit = (2.0 * run.limits.threshold).min(60f64.to_radians()).cos();
    for i in 0..planes.len() {
        for j in i + 1..planes.len() {
            if planes[i].normal.dot(planes[j].normal).abs() > limit {
                return false;
            }
        }
    }
    planes.len() != 3
        || planes[0]
            .normal
            .dot(planes[1].normal.cross(planes[2].normal))
            .abs()
            >= MIN_CORNER_DET
}

/// Smallest triple product of the unit normals of three planes whose point a vertex moves to
/// (0.1: the planes' error is amplified at most tenfold; a cube corner has 1, the synth
/// pyramid's base corners 0.7 and its apex triples 0.5).
pub(crate) const MIN_CORNER_DET: f64 = 0.1;

/// Whether `planes` hold three or more distinct surfaces (greedy, in order; see
/// [`same_surface`]).
fn at_least_three_surfaces(run: &Run, planes: &[LabelPlane]) -> bool {
    // Counting stops at three, so the kept planes fit on the stack (this runs for every
    // candidate corner triangle).
    let mut kept: [Option<&LabelPlane>; 2] = [None; 2];
    let mut n = 0;
    for lp in planes {
        if kept[..n]
            .iter()
            .flatten()
            .all(|k| !same_surface(run, k, lp))
        {
            if n == 2 {
                return true;
            }
            kept[n] = Some(lp);
            n += 1;
        }
    }
    false
}

/// Two label planes belong to the same surface when they come from the same smooth region
/// (whose planes turn along a curved surface: a cylinder's planes two edges apart may differ by
/// more than the smooth threshold) or are parallel (different regions of one plane).
///
/// On a surface sampling, two planes of one region that turn by more than twice the smooth
/// threshold are different surfaces: a region that wraps around the end of a crease holds
/// both of its sides, whose chamfer would otherwise never be split (swing-decoded fandisk,
/// docs/results.md). Marching cubes keeps the region rule (it costs the synth pyramid there).
#[inline]
fn same_surface(run: &Run, a: &LabelPlane, b: &LabelPlane) -> bool {
    (a.label == b.label
        && (!run.surface_samples
            || a.plane.normal.dot(b.plane.normal) >= run.limits.same_region_cos))
        || parallel(run, &a.plane, &b.plane)
}

#[inline]
fn parallel(run: &Run, a: &Plane, b: &Plane) -> bool {
    let c = a.normal.dot(b.normal);
    c >= run.limits.parallel_cos || c <= -run.limits.parallel_cos
}

/// Filter 6, extended: a triangle (not red) is a corner triangle when its three vertices have
/// label planes, no surface holds all three, and one plane per vertex can be chosen so that
/// the three are pairwise non-parallel: the corner where those surfaces meet is inside it,
/// whether or not its edges are chamfer edges (its vertices may lie on the creases around the
/// corner).
pub(crate) fn is_corner_triangle(run: &Run, tri: [u32; 3]) -> bool {
    let p = tri.map(|v| planes_of(run, v));
    if p.iter().any(|x| x.is_empty()) {
        return false;
    }
    // A vertex already on three surfaces is the corner (a corner vertex moved there).
    if p.iter().any(|x| at_least_three_surfaces(run, x)) {
        return false;
    }
    let mut common = false;
    let mut spread = false;
    for x in p[0] {
        for y in p[1] {
            for z in p[2] {
                let (xy, yz, zx) = (
                    same_surface(run, x, y),
                    same_surface(run, y, z),
                    same_surface(run, z, x),
                );
                common |= xy && yz && zx;
                spread |= !xy && !yz && !zx;
            }
        }
    }
    spread && !common
}

/// Filter 5, extended: the non-red edge `a`-`b` is a chamfer edge when both ends have label
/// planes and they share no surface: every pair of their planes is non-parallel.
pub(crate) fn is_chamfer_edge(run: &Run, a: u32, b: u32) -> bool {
    let (pa, pb) = (planes_of(run, a), planes_of(run, b));
    !pa.is_empty()
        && !pb.is_empty()
        && pa
            .iter()
            .all(|x| pb.iter().all(|y| !same_surface(run, x, y)))
}

/// Snaps the new vertex of chamfer edge `a`-`b`: the plane pair whose line point is closest
/// to the midpoint; on marching cubes, where a convex neighbouring face cuts an acute crease
/// off ([`convex_cut`]), the crease's end on that face (three planes).
pub(crate) fn edge_snap(
    run: &Run,
    a: u32,
    b: u32,
    anchor: DVec3,
) -> Result<(DVec3, Planes), UnmovedReason> {
    let mut best: Option<(f64, DVec3, Planes)> = None;
    let mut reason = UnmovedReason::Parallel;
    let scale = run.positions[a as usize].distance(run.positions[b as usize]);
    for x in planes_of(run, a) {
        for y in planes_of(run, b) {
            match snap::edge_point(&x.plane, &y.plane, anchor, &run.limits) {
                Ok(p) => {
                    // Cheap tests first (the result does not depend on the order).
                    if !consistent(run, p, &[(a, x.label), (b, y.label)], scale)
                        || (!run.surface_samples && !flat_sided_crease(run, &[*x, *y]))
                        || (run.surface_samples
                            && (p.distance(anchor) > SURFACE_DISPLACEMENT * scale
                                || !distinct_crease(run, &[(a, x), (b, y)])
                                || strip_offset(run, a, b, x, y) > STRIP_TOLERANCE * scale))
                        || !supported(run, p, &[a, b])
                    {
                        reason = UnmovedReason::Curved;
                        continue;
                    }
                    // A crease end lies farther from the anchor than the line's closest point
                    // `p`: when `p` cannot beat the best, neither can the end (skip the scan).
                    if !better(best.as_ref().map(|b| b.0), p.distance_squared(anchor)) {
                        continue;
                    }
                    let Some((p, planes)) =
                        uncut_crease_point(run, p, [(a, x), (b, y)], scale, &[a, b])
                    else {
                        reason = UnmovedReason::Curved;
                        continue;
                    };
                    let d = p.distance_squared(anchor);
                    if better(best.as_ref().map(|b| b.0), d) {
                        best = Some((d, p, planes));
                    }
                }
                Err(r) => {
                    if r != UnmovedReason::Parallel {
                        reason = r;
                    }
                }
            }
        }
    }
    best.map(|(_, p, planes)| (p, planes)).ok_or(reason)
}

/// A snapped or moved-to point must lie within this many mean edge lengths of the input
/// surface around it (see [`supported`]). Measured on the marching-cubes table (2026-12-03,
/// with the crease tolerance at 0.35): 1.25 costs pyramid 96 r0 3 % of its RMS gain (8.18x ->
/// 7.94x) and moves nothing else, 2.0 moves no row.
pub(crate) const SUPPORT: f64 = 1.5;

/// Whether point `p` lies within [`SUPPORT`] mean edge lengths of the input triangles around
/// the vertices `around`. The crease of a sampled sharp edge is within about a cell of the
/// chamfer that cut it (deeper only at acute creases and corners); the planes of the faces
/// around a blend meet far above the blend (0.4 times its radius for a right angle), so a
/// blend wider than a few samples, which the smooth test may still call a chamfer, is left
/// alone.
fn supported(run: &Run, p: DVec3, around: &[u32]) -> bool {
    supported_within(run, p, around, 1.0)
}

/// How many times deeper than a right-angled one a grid sampler cuts the corner where the
/// planes `planes` meet: 1 for right angles and flatter, `sin(45) / sin(a / 2)` for a wedge of
/// interior angle `a` between two of them (at most [`MAX_ACUTE_REACH`]). Marching cubes cuts
/// a tip where its cross-section first holds a grid point, and a wedge's cross-section narrows
/// with its angle: the synth pyramid's base corners (interior angles of 58 degrees) were cut
/// 1.6-1.8 mean edge lengths deep and their three-plane points refused by the support test
/// (docs/results.md). It widens the support test of corner points and the move limit of
/// [`unlabelled_corner_vertices`]. Marching-cubes input only: on surface samplings
/// every sample is on the surface (and acute wedges were left alone when this was measured,
/// before [`ACUTE_CONTRAST_FACTOR`]), and widening the edge snaps' support too changed no row
/// of the synth or stand-in tables.
fn acute_reach(run: &Run, planes: &[&Plane]) -> f64 {
    if run.surface_samples {
        return 1.0;
    }
    let mut narrowest = 1.0f64;
    for i in 0..planes.len() {
        for j in i + 1..planes.len() {
            let turn = planes[i]
                .normal
                .dot(planes[j].normal)
                .clamp(-1.0, 1.0)
                .acos();
            let interior = std::f64::consts::PI - turn;
            narrowest = narrowest.min((0.5 * interior).sin());
        }
    }
    (std::f64::consts::FRAC_1_SQRT_2 / narrowest).clamp(1.0, MAX_ACUTE_REACH)
}

/// Cap of [`acute_reach`]: a wedge of about 27 degrees; sharper tips are cut so deep that the
/// corner point is no longer tied to the chamfer around it.
pub(crate) const MAX_ACUTE_REACH: f64 = 3.0;

/// [`supported`] with the limit multiplied by `reach`.
fn supported_within(run: &Run, p: DVec3, around: &[u32], reach: f64) -> bool {
    let mut len = 0.0;
    let mut k = 0usize;
    for &v in around {
        let pv = run.mesh.positions[v as usize];
        for c in run.table.vertex_corners(VertexId(v)) {
            len += (run.mesh.positions[run.cv(next(c.index())) as usize] - pv).length();
            k += 1;
        }
    }
    if k == 0 {
        return false;
    }
    let limit = SUPPORT * reach * len / k as f64;
    around.iter().any(|&v| {
        run.table.vertex_corners(VertexId(v)).any(|c| {
            let [a, b, q] = run.mesh.triangle_positions(c.index() / 3);
            snap::point_triangle_distance(p, a, b, q) <= limit
        })
    })
}

/// Points farther than this fraction of the chamfer edge from a same-label plane of a
/// neighbour are not trusted (see [`consistent`]). Tuned on the synth table: 0.2 costs RMS on
/// the planar pyramid (region planes near a chamfer carry some noise), 0.4 lets coarse
/// fandisk samplings snap onto badly extrapolated cylinder planes.
pub(crate) const CURVED_TOLERANCE: f64 = 0.3;

/// How many of the neighbours' same-label planes [`consistent`] lets miss the point. A
/// curved surface turns every neighbour's plane away from the point, so one miss says little;
/// it is most often the plane a vertex deep inside an acute cut borrowed from a neighbour whose
/// red triangles include one leaning into the chamfer (synth pyramid 48 r1: a plane tilted 7.7
/// degrees refused the snap of a base-crease edge onto the true crease, by 0.0076 against a
/// tolerance of 0.0072, and the crease stayed cut at 0.95 % of the diagonal). Measured on the
/// marching-cubes table (docs/results.md, "One noisy plane"): with one miss allowed RMS is
/// better on 23 of 30 rows and about 1 % worse on two, max better on 3 (pyramid 48 r1 1.63x
/// -> 2.16x) and worse on none.
pub(crate) const CONSISTENCY_MISSES: usize = 1;

/// Whether point `p`, computed from the planes of `(vertex, label)` pairs, also lies within
/// [`CURVED_TOLERANCE`] times `scale` of the planes of the same labels at those vertices'
/// neighbours, all but [`CONSISTENCY_MISSES`] of them. Where the surfaces are flat at the
/// scale of the sampling every such plane holds the point; on a surface curved at that scale
/// (a coarse sampling of a cylinder or cone) the extrapolated point is off the surface by
/// about the disagreement.
///
/// Not applied to surface samplings ([`is_surface_sampling`]), whose curved faces are
/// sampled by their own vertices: on the swing-decoded CAD parts it refused snaps that the
/// papers' method makes with profit (docs/results.md).
fn consistent(run: &Run, p: DVec3, sources: &[(u32, u32)], scale: f64) -> bool {
    if run.surface_samples {
        return true;
    }
    for (i, &(_, x)) in sources.iter().enumerate() {
        if sources[i + 1..].iter().any(|&(_, y)| is_blend(run, x, y)) {
            return false;
        }
    }
    let tol = CURVED_TOLERANCE * scale;
    let mut misses = 0usize;
    for &(v, label) in sources {
        for c in run.table.vertex_corners(VertexId(v)) {
            let u = run.cv(next(c.index()));
            for lp in planes_of(run, u) {
                if lp.label == label && (p - lp.plane.point).dot(lp.plane.normal).abs() > tol {
                    misses += 1;
                    if misses > CONSISTENCY_MISSES {
                        return false;
                    }
                }
            }
        }
    }
    true
}

/// How far, in multiples of the snap's scale (the chamfer edge's length, or the corner
/// triangle's radius), a snapped point may stand outside the plane of a convex neighbouring
/// surface, and its vertices on the wrong side of one another's planes, before
/// [`convex_cut`] calls it cut off: the allowance a plane's own noise gets
/// ([`CURVED_TOLERANCE`]).
pub(crate) const CUT_OFF_TOLERANCE: f64 = CURVED_TOLERANCE;

/// [`convex_cut`] looks only at snaps with a pair of planes whose normals' cosine is under
/// this: turned by more than 120 degrees, a wedge under 60. Marching cubes cuts such a tip
/// deep and its snap reaches far (`acute_reach`); at right angles the snap stays within a
/// cell of the chamfer, and there the rule mostly cut good snaps near corners (with right
/// angles included, 18 of 198 fixture samplings worse and 4 better, docs/results.md
/// "Fixtures at any angle").
pub(crate) const ACUTE_PAIR_COS: f64 = -0.5;

/// A surface cuts a crease off only if it turns from each of the crease's planes by more
/// than 60 degrees (cosine under this): the facets of a coarsely sampled cylinder or sphere,
/// 15-20 degrees apart, are one curved surface, whose tangent planes every extrapolated point
/// stands above.
pub(crate) const CUTTING_TURN_COS: f64 = 0.5;

/// Marching cubes: the plane of a surface that cuts off the crease or corner at snapped point
/// `p`, the meet of the planes of `sources` (vertex and label plane pairs), if any. Around a
/// convex corner the part is the intersection of its faces' half-spaces, so the crease of two
/// of them ends where a third cuts it off, and past that plane the point is in the air. A
/// face narrower than the sampling hides from the chamfer's own vertices (their labels name
/// the two wedge faces only), but its plane is on a vertex of their two-ring: rotated
/// fandisk at 38 cells snapped a 29-degree fin 1.1 mean edges past the face truncating it
/// (max 1.236 -> 1.963 %). Only snaps with an acute pair ([`ACUTE_PAIR_COS`]). The cutting
/// plane belongs to another label, turns from each source plane by over 60 degrees
/// ([`CUTTING_TURN_COS`]) with a flat side ([`flat_sided_crease`]), meets each convexly (the
/// source vertices on or under it, its own vertex on or under each source plane, within
/// [`CUT_OFF_TOLERANCE`] scales) and has `p` above it by more than that; at a concave
/// meeting the crease may run on past the plane, and nothing is cut. "Above" assumes outward
/// normals (counter-clockwise seen from outside), as marching cubes writes them; with the
/// opposite winding convex meetings read as concave and nothing is cut.
fn convex_cut(run: &Run, p: DVec3, sources: &[(u32, &LabelPlane)], scale: f64) -> Option<Plane> {
    let acute = sources.iter().enumerate().any(|(i, &(_, x))| {
        sources[i + 1..]
            .iter()
            .any(|&(_, y)| x.plane.normal.dot(y.plane.normal) < ACUTE_PAIR_COS)
    });
    if run.surface_samples || !acute {
        return None;
    }
    let tol = CUT_OFF_TOLERANCE * scale;
    let above = |plane: &Plane, q: DVec3| (q - plane.point).dot(plane.normal);
    for &(v, _) in sources {
        for c0 in run.table.vertex_corners(VertexId(v)) {
            let u0 = run.cv(next(c0.index()));
            for c in run.table.vertex_corners(VertexId(u0)) {
                let u = run.cv(next(c.index()));
                let pu = run.positions[u as usize];
                for z in planes_of(run, u) {
                    if sources.iter().any(|&(_, x)| x.label == z.label) || above(&z.plane, p) <= tol
                    {
                        continue;
                    }
                    let convex = sources.iter().all(|&(w, x)| {
                        above(&z.plane, run.positions[w as usize]) <= tol
                            && above(&x.plane, pu) <= tol
                            && z.plane.normal.dot(x.plane.normal) < CUTTING_TURN_COS
                            && flat_sided_crease(run, &[*x, *z])
                    });
                    if convex {
                        return Some(z.plane);
                    }
                }
            }
        }
    }
    None
}

/// Marching cubes: crease point `p` of the planes of `pair` (vertex and label plane), or,
/// where a convex neighbouring face cuts the crease off ([`convex_cut`]), the crease's end on
/// that face (three planes); `None` when the end is unsupported by the input around `around`
/// or another plane still cuts it off. The end lies on the cutting plane, so that plane
/// cannot cut it again.
fn uncut_crease_point(
    run: &Run,
    p: DVec3,
    pair: [(u32, &LabelPlane); 2],
    scale: f64,
    around: &[u32],
) -> Option<(DVec3, Planes)> {
    let [(_, x), (_, y)] = pair;
    match convex_cut(run, p, &pair, scale) {
        None => Some((p, Planes::two(x.plane, y.plane))),
        Some(z) => crease_end(run, &x.plane, &y.plane, &z, p)
            .filter(|&q| supported(run, q, around) && convex_cut(run, q, &pair, scale).is_none())
            .map(|q| (q, Planes::three(x.plane, y.plane, z))),
    }
}

/// Where the crease line of planes `x` and `y`, through `p`, crosses plane `z`; `None` when the
/// line runs within the smooth threshold of parallel to `z`. No convexity rule, unlike
/// [`snap::corner_point`]: the crease is known convex with `z` ([`convex_cut`]).
fn crease_end(run: &Run, x: &Plane, y: &Plane, z: &Plane, p: DVec3) -> Option<DVec3> {
    let d = x.normal.cross(y.normal).normalize_or_zero();
    let along = z.normal.dot(d);
    if along.abs() <= run.limits.dependent_det.sqrt() {
        return None;
    }
    let q = p - d * ((p - z.point).dot(z.normal) / along);
    q.is_finite().then_some(q)
}

/// Surface samplings: an edge snap moves its vertex at most this fraction of the chamfer edge
/// from the edge's midpoint. Across a right-angled crease the crease line is half a chamfer
/// edge from a symmetric chamfer (less from a lopsided one); it is farther only across acute
/// wedges, which [`MAX_SURFACE_TURN`] leaves alone anyway. Measured on swing-decoded fixtures
/// (6 angle bits, docs/results.md): no snap on the CAD parts goes farther than 0.66; on the
/// smooth ones (bunny's ears, fertility, armadillo) snaps of 0.8-1.6 put the worst errors.
pub(crate) const SURFACE_DISPLACEMENT: f64 = 0.75;

/// Surface samplings: a snap needs planes that turn by at least this many times the mean of
/// the *typical turns* of the two smooth regions they come from ([`region_turns`]): the
/// *crease contrast*. A sharp crease between smooth faces turns abruptly, far more than the
/// faces do from one triangle to the next (flat CAD faces swing-decoded with 6 angle bits:
/// typical turns of 1.5-3 degrees, so a 90-degree crease has a contrast of 30-60; a face curved
/// at the sampling's scale, a hole's cylinder, raises one side only, hence the mean of the two
/// sides rather than the larger). On an organic surface the regions are curved at the
/// sampling's scale (typical turns of 4-6 degrees), and a thin part (an ear, a finger,
/// fertility's limbs) sampled a few triangles across shows "creases" of 45-110 degrees with a
/// contrast of 6-20. There the truth is a rounded rim, and the plane intersection overshoots it
/// (a tip between planes turned by `t` stands `r (1 / cos(t/2) - 1)` above a rim of radius
/// `r`). Measured on swing-decoded fixtures at 6 angle bits and 2-8 bits per vertex
/// (`examples/swing_sweep`, docs/results.md): at 18, spot, fertility, armadillo, bunny and
/// rocker_arm come out unchanged or better, and the CAD parts' RMS ratios move by under 4 %
/// (fandisk at 2.1 bpv 10 %, block and partLp 7-14 %). The two classes overlap around 17-20:
/// fandisk retiled at a quarter of its vertices (1 bpv; its curved faces turn by 5-6 degrees
/// per edge) has creases at 18.3-20, and fertility has pseudo-creases at 17.5-18.3; at 17
/// fertility's come back (max +6-28 % at 8 bpv), at 19-20 fandisk at 1 bpv keeps only 4 % of
/// RMS gain instead of 7-12 %. With the larger of the two typical turns instead of the mean,
/// 15-18 cost cad_box_hole and cad_bracket a third of their gain and still sharpened fertility.
pub(crate) const CREASE_CONTRAST: f64 = 18.0;

/// Surface samplings: sides that are smoothly connected near the chamfer need this many times
/// [`CREASE_CONTRAST`]: planes of the *same* smooth region (a region that wraps around the end
/// of a chamfer strip, see [`same_surface`]), or a side whose region holds, within the two-ring
/// of its end, a triangle facing more like the other side than like its own plane ([`wraps`]).
/// That the two sides join smoothly is itself evidence of a smooth turn. On fandisk such pairs
/// sit where a crease fades out, with contrasts of 30-45; on fertility, spot and armadillo they
/// are 90-110-degree bends of thin parts with contrasts of 20-26, and rocker_arm's at 2 bpv a
/// bend next to a blend (contrast 17-20): they were the largest errors left at 1.0 (fertility
/// at 8 bpv: max +14 %, rocker_arm at 2 bpv +4 %); 1.5 still sharpens fertility's at 105-110
/// degrees, 2.0 costs fandisk 10 % of its RMS gain.
pub(crate) const SAME_REGION_CONTRAST: f64 = 1.75;

/// Surface samplings: no snap between planes turned by more than this (degrees): an acute
/// wedge (interior angle under 80 degrees) sampled at the retiler's density is
/// indistinguishable from a thin part with a rounded rim (bunny's and armadillo's ears,
/// fertility's limbs: the largest errors the sharpener added, at turns of 95-150 degrees),
/// and the wedge's tip overshoots a rounded rim by a factor `1 / cos(t/2) - 1` that grows
/// without bound as the wedge closes (1.9x the rim radius at 130 degrees). The swing-decoded
/// CAD fixtures have almost no snap above 100 degrees (2 of 10,000; 100 instead of 110 changes
/// their RMS by under 0.3 %), while armadillo's ear rims at 8 bpv (auto angle bits) turn by
/// 100-110 degrees (max +12 % at 110). A wedge turning by more is still a crease when its
/// faces are flat enough ([`ACUTE_CONTRAST_FACTOR`]).
pub(crate) const MAX_SURFACE_TURN_DEGREES: f64 = 100.0;

/// Surface samplings: a wedge turning by more than [`MAX_SURFACE_TURN_DEGREES`] is a crease
/// when its turn is at least this many times [`CREASE_CONTRAST`] over the mean typical turn
/// of its two regions: the faces of an acute CAD wedge are flat (a retiled pyramid's, with 6
/// angle bits: contrasts of 80-220, 160-460 with its base on a coordinate plane), a thin
/// organic part bends everywhere (contrasts mostly under 45). Measured (docs/results.md,
/// "Acute wedges on surface samplings") on the swing-decoded organic fixtures and rocker_arm
/// at 1-16 bpv with 6, 8 and 10 angle bits: of 3,573 such checks, 18 reach 3x (54), on
/// screwdriver at 16 bpv (16; its output then improves, max 0.319 -> 0.262 % at 6 angle
/// bits), screwdriver at 6 bpv and bunny_dense at 3 bpv (one each, figures unchanged); the
/// synth pyramid retiled at 1.5 % of its diagonal went from 1.474 % to 0.419 % in max through
/// `whet decode --sharpen`. Before it, acute CAD wedges stayed chamfered on surface
/// samplings.
pub(crate) const ACUTE_CONTRAST_FACTOR: f64 = 3.0;

/// The typical turn ([`region_turns`]) of the region of `lp`, in radians.
fn typical_turn(run: &Run, lp: &LabelPlane) -> f64 {
    f64::from(
        run.s
            .region_turn
            .get(lp.label as usize)
            .copied()
            .unwrap_or(0.0),
    )
}

/// Marching cubes: whether planes `planes` (of a snap, or of a vertex's move onto a crease or
/// corner) meet at a crease of a part rather than a bend of a smooth one: every pair turns by
/// at least [`CREASE_CONTRAST`] times the *typical turn* ([`region_turns`]) of the flatter of
/// its two regions. A sampled CAD crease has a flat or gently curved face on at least one
/// side (the synth shapes' planes turn by about 0 inside their regions, fandisk's cone and
/// cylinder at 32 cells by a few degrees); an organic mesh bends everywhere, and its thin
/// parts (ears, limbs, rims) give strips turning by 30-60 degrees between regions that turn
/// by 3-6 degrees per edge, which the filters take for chamfers. The flatter side, not the
/// mean of the two that surface samplings use ([`distinct_crease`]): with the mean, a crease
/// between a flat face and fandisk's coarse cone failed (synth fandisk 48 r1 RMS 3.05x ->
/// 2.90x). Measured (docs/results.md, "Creases with a flat side"): the organic originals
/// fertility and screwdriver come out unchanged, rocker_arm's max 0.396 -> 0.259 %; on the
/// marching-cubes table nine fandisk rows gain up to 2.5 % in RMS and 32 r1 loses 2 %, every
/// max gain as it was.
fn flat_sided_crease(run: &Run, planes: &[LabelPlane]) -> bool {
    for (i, x) in planes.iter().enumerate() {
        for y in &planes[i + 1..] {
            let least = CREASE_CONTRAST * typical_turn(run, x).min(typical_turn(run, y));
            // A flat side passes at once (no trigonometry: the common case).
            if least == 0.0 {
                continue;
            }
            if least >= std::f64::consts::PI
                || x.plane.normal.dot(y.plane.normal).clamp(-1.0, 1.0).acos() < least
            {
                return false;
            }
        }
    }
    true
}

/// Whether the planes of a snap (`(vertex, label plane)` pairs) meet at a crease distinct
/// from the regions' own curvature: every pair turns by at least [`CREASE_CONTRAST`] times
/// the mean typical turn of its two regions ([`SAME_REGION_CONTRAST`] times more for sides
/// joined smoothly, [`ACUTE_CONTRAST_FACTOR`] times more past
/// [`MAX_SURFACE_TURN_DEGREES`]).
/// Surface samplings only (marching cubes has the consistency test and [`flat_sided_crease`]).
fn distinct_crease(run: &Run, planes: &[(u32, &LabelPlane)]) -> bool {
    let typical = |lp: &LabelPlane| typical_turn(run, lp);
    let max_cos = MAX_SURFACE_TURN_DEGREES.to_radians().cos();
    for (i, &(a, x)) in planes.iter().enumerate() {
        for &(b, y) in &planes[i + 1..] {
            let c = x.plane.normal.dot(y.plane.normal).clamp(-1.0, 1.0);
            // Two sides that are smoothly connected near the chamfer (one region, or a region
            // that turns towards the other side within the two-ring of its end) need the higher
            // contrast; the two-ring is looked at only when the contrast is in between.
            let needed = CREASE_CONTRAST * 0.5 * (typical(x) + typical(y));
            let turn = c.acos();
            if turn < needed || (c < max_cos && turn < ACUTE_CONTRAST_FACTOR * needed) {
                return false;
            }
            if turn < SAME_REGION_CONTRAST * needed
                && (x.label == y.label
                    || wraps(run, a, x, y.plane.normal)
                    || wraps(run, b, y, x.plane.normal))
            {
                return false;
            }
        }
    }
    true
}

/// Whether the region of label plane `lp` at vertex `v` wraps around towards the other side of
/// the crease: a triangle of that region in the two-ring of `v` faces more like `other` (the
/// other side's normal) than like `lp`'s plane.
fn wraps(run: &Run, v: u32, lp: &LabelPlane, other: DVec3) -> bool {
    run.table.vertex_corners(VertexId(v)).any(|c| {
        let u = run.cv(next(c.index()));
        run.table.vertex_corners(VertexId(u)).any(|cc| {
            let t = cc.index() / 3;
            run.s.region[t] == lp.label
                && run.s.normals[t].dot(other) > run.s.normals[t].dot(lp.plane.normal)
        })
    })
}

/// On a surface sampling ([`is_surface_sampling`]) every vertex of a chamfer strip across a
/// sharp crease lies on one of the two faces; across a blend a few samples wide the strip's
/// vertices lie on the blend, between the planes, which meet far above it. An edge snap is
/// refused (reason `curved`) when a vertex opposite the chamfer edge (with no label of a third
/// surface) lies farther than this fraction of the chamfer edge from both planes. Measured on
/// swing-decoded meshes (docs/results.md): 95 % of the snaps on fandisk and the CAD parts are
/// under 0.1 (6 angle bits: 0.09), those that made rocker_arm's blends worse 0.3-0.5; 0.25
/// leaves rocker_arm 2-5 % worse in RMS, 0.15 costs fandisk 2-4 % RMS. Not applied to
/// marching cubes, which interpolates vertices inside the chamfers (the synth pyramid loses a
/// fifth of its RMS gain).
pub(crate) const STRIP_TOLERANCE: f64 = 0.15;

/// Largest distance of the vertices opposite edge `a`-`b` from the nearer of planes `x`, `y`
/// (a vertex with a label plane of a third surface counts as on it).
fn strip_offset(run: &Run, a: u32, b: u32, x: &LabelPlane, y: &LabelPlane) -> f64 {
    let mut m = 0.0f64;
    for c in run.table.vertex_corners(VertexId(a)) {
        let i = c.index();
        let (u, w) = (run.cv(next(i)), run.cv(crate::edge_sharpener::prev(i)));
        let opp = if u == b {
            w
        } else if w == b {
            u
        } else {
            continue;
        };
        let third = planes_of(run, opp)
            .iter()
            .any(|lp| !same_surface(run, lp, x) && !same_surface(run, lp, y));
        if third {
            continue;
        }
        let q = run.positions[opp as usize];
        let d = ((q - x.plane.point).dot(x.plane.normal).abs())
            .min((q - y.plane.point).dot(y.plane.normal).abs());
        m = m.max(d);
    }
    m
}

/// Snaps the new vertex of a corner triangle: the three-plane point of the best combination of
/// its vertices' planes, else the best line point of two of them.
pub(crate) fn corner_snap(
    run: &Run,
    tri: [u32; 3],
    anchor: DVec3,
) -> Result<(DVec3, Planes), UnmovedReason> {
    let p = tri.map(|v| planes_of(run, v));
    let mut best: Option<(f64, DVec3, Planes)> = None;
    let mut reason = UnmovedReason::Dependent;
    for x in p[0] {
        for y in p[1] {
            for z in p[2] {
                match snap::corner_point(&x.plane, &y.plane, &z.plane, anchor, &run.limits) {
                    Ok(q) => {
                        let scale = tri
                            .iter()
                            .map(|&v| run.positions[v as usize].distance(anchor))
                            .fold(0.0f64, f64::max);
                        if off_shared_surface(run, &p, [x.label, y.label, z.label], q, scale)
                            || !consistent(
                                run,
                                q,
                                &[(tri[0], x.label), (tri[1], y.label), (tri[2], z.label)],
                                2.0 * scale,
                            )
                            || (!run.surface_samples && !flat_sided_crease(run, &[*x, *y, *z]))
                            || (run.surface_samples
                                && !distinct_crease(run, &[(tri[0], x), (tri[1], y), (tri[2], z)]))
                            || !supported_within(
                                run,
                                q,
                                &tri,
                                acute_reach(run, &[&x.plane, &y.plane, &z.plane]),
                            )
                            || convex_cut(run, q, &[(tri[0], x), (tri[1], y), (tri[2], z)], scale)
                                .is_some()
                        {
                            reason = UnmovedReason::Curved;
                            continue;
                        }
                        let d = q.distance_squared(anchor);
                        if better(best.as_ref().map(|b| b.0), d) {
                            best = Some((d, q, Planes::three(x.plane, y.plane, z.plane)));
                        }
                    }
                    Err(r) => {
                        if r == UnmovedReason::MixedConvexity && reason != UnmovedReason::Curved {
                            reason = r;
                        }
                    }
                }
            }
        }
    }
    if let Some((_, q, planes)) = best {
        return Ok((q, planes));
    }
    // No three independent planes (a corner triangle inside a straight chamfer): the crease
    // line of the best pair. Not on surface samplings: there a corner triangle whose planes do
    // not give a corner point lies where a chamfer strip ends or bends, and the line of two of
    // its planes left spot's and rocker_arm's worst errors (swing-decoded, docs/results.md);
    // the chamfer edges around it are split and snapped on their own.
    if run.surface_samples {
        return Err(reason);
    }
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        for x in p[i] {
            for y in p[j] {
                if let Ok(q) = snap::edge_point(&x.plane, &y.plane, anchor, &run.limits) {
                    let scale =
                        run.positions[tri[i] as usize].distance(run.positions[tri[j] as usize]);
                    if !consistent(run, q, &[(tri[i], x.label), (tri[j], y.label)], scale)
                        || !supported(run, q, &tri)
                    {
                        continue;
                    }
                    // An acute wedge ends at the face that cuts it off, here as in `edge_snap`.
                    let Some((q, planes)) =
                        uncut_crease_point(run, q, [(tri[i], x), (tri[j], y)], scale, &tri)
                    else {
                        continue;
                    };
                    let d = q.distance_squared(anchor);
                    if better(best.as_ref().map(|b| b.0), d) {
                        best = Some((d, q, planes));
                    }
                }
            }
        }
    }
    best.map(|(_, q, planes)| (q, planes)).ok_or(reason)
}

/// Marching cubes: whether corner point `q` of a triangle's triple of planes (`chosen` labels)
/// lies off a surface that two of the triangle's vertices both lie on (`planes`: each vertex's
/// label planes) and that the triple leaves out, by more than [`CURVED_TOLERANCE`] times the
/// larger of `scale` and the mean edge (the plane is vertex `i`'s of the pair that shares it). Two vertices on one surface put that surface between them, so a corner inside the
/// triangle lies on it: where four faces meet two by two (rotated cad_bracket at 41 cells:
/// one vertex on faces A and C, one on A and D, one on B), the point of B, C and D stood 1.85
/// units (0.8 mean edges) above A, and only the triples with A give the two real corners. At
/// an apex of four faces (the octahedron's) every triple meets on the fourth plane, and all
/// of them stay candidates.
fn off_shared_surface(
    run: &Run,
    planes: &[&[LabelPlane]; 3],
    chosen: [u32; 3],
    q: DVec3,
    scale: f64,
) -> bool {
    if run.surface_samples {
        return false;
    }
    let tol = CURVED_TOLERANCE * scale.max(run.mean_edge);
    (0..3).any(|i| {
        let j = (i + 1) % 3;
        planes[i].iter().any(|a| {
            !chosen.contains(&a.label)
                && planes[j].iter().any(|b| b.label == a.label)
                && (q - a.plane.point).dot(a.plane.normal).abs() > tol
        })
    })
}

/// A chamfer vertex moves onto a corner point only when it is within this fraction of its
/// mean edge length (marching cubes cuts a corner off by up to sqrt(3) cells). 1.75 since
/// settling's move of the vertex a snap folds over reaches as deep as the corner vertex
/// moved (`FOLD_MOVE_LIMIT`): at 1.5 the synth pyramid's apex at 64 r1 (1.6 mean edges
/// from its nearest chamfer vertex) stayed cut, and 1.7 without that reach folded the
/// vertex inside the cut and was undone (max 1.05 % -> 1.22 %).
pub(crate) const CORNER_MOVE_LIMIT: f64 = 1.75;

/// Corner vertices: for each corner triangle whose three planes meet in a point, the nearest
/// chamfer vertex (of the triangle or around it) moves onto that point and takes the three
/// planes as labels; then, on marching cubes, [`unlabelled_corner_vertices`]. Returns the
/// vertices that moved; the caller then recomputes the chamfer edges and corner triangles
/// around them.
#[inline(never)] // one call per run; kept out of line so profiles show it
pub(crate) fn corner_vertices(run: &mut Run) -> Vec<u32> {
    let nt = run.mesh.triangles.len();
    let mut placed: Vec<DVec3> = Vec::new();
    let mut moved = Vec::new();
    for t in 0..nt {
        if run.s.tflags[t] & crate::edge_sharpener::T_GREEN == 0 {
            continue;
        }
        let tri = run.mesh.triangles[t];
        let anchor = tri
            .iter()
            .map(|&v| run.positions[v as usize])
            .sum::<DVec3>()
            / 3.0;
        let Ok((w, planes)) = corner_snap(run, tri, anchor) else {
            continue;
        };
        let [Some(a), Some(b), Some(c)] = planes.p else {
            continue;
        };
        if !well_separated(run, &[a, b, c]) {
            continue;
        }
        // Candidates: chamfer vertices of the triangle and of its neighbours.
        let mut best: Option<(f64, u32)> = None;
        for &v0 in &tri {
            for cc in run.table.vertex_corners(VertexId(v0)) {
                for v in [v0, run.cv(next(cc.index()))] {
                    if run.s.vflags[v as usize] & V_CHAMFER == 0 {
                        continue;
                    }
                    let d = run.positions[v as usize].distance(w);
                    if better(best.map(|b| b.0), d)
                        || best.is_some_and(|(bd, bv)| d == bd && v < bv)
                    {
                        best = Some((d, v));
                    }
                }
            }
        }
        let Some((d, v)) = best else { continue };
        let mean = run.mean_input_edge(v).unwrap_or(0.0);
        if d > CORNER_MOVE_LIMIT * mean || placed.iter().any(|q| q.distance(w) < 0.5 * mean) {
            continue;
        }
        if !fan_stays_unfolded(run, v, w) {
            continue;
        }
        // The corner vertex lies on the three surfaces: it takes their label planes (found
        // again among the triangle's vertices by their normals).
        let labels = [a, b, c].map(|pl| {
            let label = tri
                .iter()
                .flat_map(|&x| planes_of(run, x))
                .find(|lp| lp.plane.normal == pl.normal)
                .map_or(NONE, |lp| lp.label);
            (label, pl.normal)
        });
        move_to_corner(run, v, w, labels);
        placed.push(w);
        moved.push(v);
    }
    if !run.surface_samples {
        unlabelled_corner_vertices(run, &mut placed, &mut moved);
    }
    moved
}

/// A vertex inside a cut corner lies within this fraction of its mean edge length of one of
/// the three planes at least: marching cubes places it by interpolating the distance along a
/// grid edge, and near a convex corner the distance is the largest of the three plane
/// distances, so the vertex is off the nearest plane by a fraction of a cell only. A vertex
/// far from all three (synth fandisk at 32: 0.8 of its edges from each) sits where the planes
/// extrapolated from coarsely sampled curved faces disagree, and moving it there made the
/// max 1.7x worse.
pub(crate) const CORNER_SURFACE_GAP: f64 = 0.5;

/// A vertex inside a cut corner within this fraction of its mean edge length of one of the
/// three planes lies on one of the corner's faces, as marching cubes puts it; one farther off
/// all three (up to [`CORNER_SURFACE_GAP`]) may lie on a face the three planes do not hold, a
/// narrow real face cutting the corner, and moves only when the three surfaces also meet
/// pairwise in creases around it ([`creases_meet`]). Measured on the vertices that test
/// refused on 990 generic and 120 near-axis samplings (`generic_sweep`, the near-axis test):
/// at box corners the nearest plane is 0.04-0.07 edges away (refusing those cost a near-axis
/// cube at 42 cells 0.705 -> 0.824 % in max), at the narrow face's end 0.44, on a near-axis
/// hole's rim, whose refusal helped, 0.31-0.47 (docs/results.md, "A narrow face's end is no
/// cut corner").
pub(crate) const CORNER_ON_FACE: f64 = 0.25;

/// Fewest triangles a smooth region needs for [`unlabelled_corner_vertices`] to extrapolate
/// its plane to a corner: the rule moves a vertex up to [`CORNER_MOVE_LIMIT`] edges on three
/// planes taken from neighbours, and the plane of a region about one fan across (a coarse
/// sampling's curved face cut into small regions) does not hold that far. Near-axis fandisk
/// at 24 cells (docs/results.md, "Near-axis samplings"): a crease vertex on the true surface
/// moved 1.07 edges onto the point of three regions of 8, 8 and 9 triangles, 4.09 % of the
/// diagonal from the surface (max 2.85 % before sharpening). From 12 to 24 it changes no row
/// of the synth or noise tables and only fandisk at 24, 38 (and 67 at 24) of the 120
/// near-axis cases, each for the better.
pub(crate) const MIN_CORNER_REGION: u32 = 16;

/// Triangles per smooth region label (`run.s.region`), indexed by label.
fn region_sizes(run: &Run) -> Vec<u32> {
    let mut size: Vec<u32> = Vec::new();
    for &r in &run.s.region {
        if r == NONE {
            continue;
        }
        if r as usize >= size.len() {
            size.resize(r as usize + 1, 0);
        }
        size[r as usize] += 1;
    }
    size
}

/// Corner vertices that no corner triangle finds (marching cubes): a gray vertex with no label
/// plane (it lies on none of its neighbours' planes: it is inside the cut-off corner) whose
/// neighbours carry three or more surfaces moves onto the three-plane point of the best
/// triple (of regions of at least [`MIN_CORNER_REGION`] triangles each) and takes their labels, under the rules of [`corner_vertices`] (the move limit
/// widened by [`acute_reach`] like the support test). The corner triangles of the papers need
/// a label at each of their vertices, so a corner whose cut left such a vertex in its middle
/// had none (synth fandisk at 96-128). A vertex with a corner triangle in its two-ring is left
/// to that triangle (its centre would snap to the same point). A vertex farther than
/// [`CORNER_ON_FACE`] from all three planes also needs the three surfaces to meet pairwise
/// around it ([`creases_meet`]). Candidates are found first and moved nearest first (ties by
/// index), so the result does not depend on the vertex order.
fn unlabelled_corner_vertices(run: &mut Run, placed: &mut Vec<DVec3>, moved: &mut Vec<u32>) {
    let nv = run.mesh.positions.len();
    let region_size = region_sizes(run);
    let mut kept: Vec<(u32, LabelPlane)> = Vec::new();
    // (distance, vertex, target, the three label planes, the vertex's mean edge)
    let mut candidates: Vec<(f64, u32, DVec3, [LabelPlane; 3], f64)> = Vec::new();
    for v in 0..nv as u32 {
        let f = run.s.vflags[v as usize];
        if f & V_USED == 0
            || f & (V_RED | V_MOVED) != 0
            || run.s.lp_len[v as usize] != 0
            || run.table.is_boundary_vertex(VertexId(v))
        {
            continue;
        }
        kept.clear();
        let p = run.mesh.positions[v as usize];
        let mut len = 0.0;
        let mut k = 0usize;
        for c in run.table.vertex_corners(VertexId(v)) {
            let u = run.cv(next(c.index()));
            len += (run.mesh.positions[u as usize] - p).length();
            k += 1;
            for lp in planes_of(run, u) {
                if kept.iter().all(|(_, o)| !same_surface(run, o, lp)) {
                    kept.push((u, *lp));
                }
            }
        }
        if kept.len() < 3 || k == 0 || near_corner_triangle(run, v) {
            continue;
        }
        let mean = len / k as f64;
        // The triple whose point is nearest.
        let mut best: Option<(f64, DVec3, [usize; 3])> = None;
        for i in 0..kept.len() {
            for j in i + 1..kept.len() {
                for l in j + 1..kept.len() {
                    let (x, y, z) = (&kept[i].1, &kept[j].1, &kept[l].1);
                    if !well_separated(run, &[x.plane, y.plane, z.plane]) {
                        continue;
                    }
                    let small = |lp: &LabelPlane| {
                        region_size.get(lp.label as usize).copied().unwrap_or(0) < MIN_CORNER_REGION
                    };
                    if small(x) || small(y) || small(z) || !flat_sided_crease(run, &[*x, *y, *z]) {
                        continue;
                    }
                    let Ok(q) = snap::corner_point(&x.plane, &y.plane, &z.plane, p, &run.limits)
                    else {
                        continue;
                    };
                    let gap = [x, y, z]
                        .iter()
                        .map(|pl| (p - pl.plane.point).dot(pl.plane.normal).abs())
                        .fold(f64::INFINITY, f64::min);
                    if gap > CORNER_SURFACE_GAP * mean {
                        continue;
                    }
                    let d = q.distance(p);
                    let reach = acute_reach(run, &[&x.plane, &y.plane, &z.plane]);
                    if d > CORNER_MOVE_LIMIT * reach * mean
                        || !consistent(
                            run,
                            q,
                            &[
                                (kept[i].0, x.label),
                                (kept[j].0, y.label),
                                (kept[l].0, z.label),
                            ],
                            2.0 * d.max(mean),
                        )
                        || !supported_within(run, q, &[v], reach)
                        || (gap > CORNER_ON_FACE * mean
                            && !creases_meet(run, v, q, [x, y, z], CURVED_TOLERANCE * mean))
                    {
                        continue;
                    }
                    if better(best.map(|b| b.0), d) {
                        best = Some((d, q, [i, j, l]));
                    }
                }
            }
        }
        if let Some((d, w, [i, j, l])) = best {
            candidates.push((d, v, w, [kept[i].1, kept[j].1, kept[l].1], mean));
        }
    }
    candidates.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    for (_, v, w, planes, mean) in candidates {
        if placed.iter().any(|q| q.distance(w) < 0.5 * mean) {
            continue;
        }
        if !fan_stays_unfolded(run, v, w) {
            continue;
        }
        run.s.vflags[v as usize] |= V_CHAMFER;
        run.report.chamfer_vertices += 1;
        move_to_corner(run, v, w, planes.map(|lp| (lp.label, lp.plane.normal)));
        placed.push(w);
        moved.push(v);
    }
}

/// Rings around an unlabelled corner vertex in which [`creases_meet`] looks for its corner's
/// creases.
pub(crate) const CORNER_CREASE_RINGS: usize = 3;

/// Most vertices [`creases_meet`] gathers; a crease it did not reach refuses the corner (the
/// move is the risk).
const CORNER_CREASE_VERTICES: usize = 128;

/// Most triangles around one vertex [`creases_meet`] walks: a vertex of higher valence (no
/// marching-cubes vertex has more than a dozen) refuses the corner, so the test stays bounded
/// on any input.
const CORNER_CREASE_VALENCE: usize = 32;

/// Whether every two of a corner's three planes meet near vertex `v` (within
/// [`CORNER_CREASE_RINGS`], a neighbour of the last ring counting) in a crease, or both meet a fourth surface there whose plane holds
/// the corner point `q` too (within `tol`: the apex of four or more faces, of which the
/// triple holds two that are not adjacent). Two surfaces meet in a crease where a vertex lies
/// on both, or lies on one with a neighbour on the other: the chamfer edges and vertices of a
/// crease that marching cubes cut. A narrow real face along one of the creases leaves that
/// pair apart (synth thin-face, a face 0.02 wide, about 1.8 edges at 99 cells: its vertices
/// lie too deep under both planes of the edge it cuts for a label, and that crease stays as
/// it is); the corner point of the three planes is then a corner the face cut off, and moving
/// the vertex at the face's end onto it put a spike 1.2 edges out, 0.68 % of the diagonal
/// off the part (docs/results.md, "A narrow face's end is no cut corner").
fn creases_meet(run: &Run, v: u32, q: DVec3, triple: [&LabelPlane; 3], tol: f64) -> bool {
    // The fan of `w`, or `None` past the valence cap.
    let fan = |w: u32| {
        let id = VertexId(w);
        let small = run
            .table
            .vertex_corners(id)
            .nth(CORNER_CREASE_VALENCE)
            .is_none();
        small.then(|| run.table.vertex_corners(id))
    };
    // The vertices within the rings, breadth first.
    let mut ring: Vec<u32> = vec![v];
    let mut start = 0;
    'rings: for _ in 0..CORNER_CREASE_RINGS {
        let end = ring.len();
        for i in start..end {
            let Some(corners) = fan(ring[i]) else {
                return false;
            };
            for c in corners {
                let w = run.cv(next(c.index()));
                if !ring.contains(&w) {
                    if ring.len() == CORNER_CREASE_VERTICES {
                        break 'rings;
                    }
                    ring.push(w);
                }
            }
        }
        start = end;
    }
    // The surfaces on them, the triple's first; at most 64, one bit each.
    let mut surfaces: Vec<LabelPlane> = triple.iter().map(|&lp| *lp).collect();
    for &w in &ring {
        for lp in planes_of(run, w) {
            if surfaces.len() < 64 && surfaces.iter().all(|o| !same_surface(run, o, lp)) {
                surfaces.push(*lp);
            }
        }
    }
    // Each label plane stands for the first surface it is the same as (`same_surface` is
    // not transitive: a plane of one surface's label, parallel to another, is not both).
    let on = |w: u32| {
        let mut bits = 0u64;
        for lp in planes_of(run, w) {
            if let Some(i) = surfaces.iter().position(|o| same_surface(run, o, lp)) {
                bits |= 1 << i;
            }
        }
        bits
    };
    // Bit j of `meets[i]`: surfaces i and j meet in a crease.
    let mut meets = vec![0u64; surfaces.len()];
    for &w in &ring {
        let own = on(w);
        if own == 0 {
            continue;
        }
        let Some(corners) = fan(w) else {
            return false;
        };
        let mut near = own;
        for c in corners {
            near |= on(run.cv(next(c.index())));
        }
        for (i, m) in meets.iter_mut().enumerate() {
            if own >> i & 1 != 0 {
                *m |= near & !(1 << i);
            }
        }
        // Symmetric: a neighbour's surface meets the vertex's own.
        for j in 0..surfaces.len() {
            if near >> j & 1 != 0 {
                meets[j] |= own & !(1 << j);
            }
        }
    }
    [(0, 1), (0, 2), (1, 2)].iter().all(|&(i, j)| {
        meets[i] >> j & 1 != 0
            || (3..surfaces.len()).any(|k| {
                meets[i] >> k & 1 != 0
                    && meets[j] >> k & 1 != 0
                    && (q - surfaces[k].plane.point)
                        .dot(surfaces[k].plane.normal)
                        .abs()
                        <= tol
            })
    })
}

/// Whether moving input vertex `v` to `w` keeps its fan unfolded (every triangle facing as
/// in the input) and free of triangles thinner than the sliver threshold.
fn fan_stays_unfolded(run: &Run, v: u32, w: DVec3) -> bool {
    let thin = run.opts.min_angle_degrees.to_radians();
    run.table.vertex_corners(VertexId(v)).all(|cc| {
        let u = cc.index() / 3;
        let q = run.mesh.triangles[u].map(|x| if x == v { w } else { run.positions[x as usize] });
        let area = (q[1] - q[0]).cross(q[2] - q[0]);
        area.dot(run.mesh.face_cross(u)) > 0.0 && crate::edge_sharpener::min_angle(&q) >= thin
    })
}

/// Moves input vertex `v` onto corner point `w`, touches its triangles and gives it the three
/// label planes `(label, normal)` through `w`.
fn move_to_corner(run: &mut Run, v: u32, w: DVec3, labels: [(u32, DVec3); 3]) {
    run.positions[v as usize] = w;
    run.s.vflags[v as usize] |= V_MOVED;
    for cc in run.table.vertex_corners(VertexId(v)) {
        run.s.tflags[cc.index() / 3] |= T_TOUCHED;
    }
    run.s.lp_start[v as usize] = run.s.lps.len() as u32;
    run.s.lp_len[v as usize] = 3;
    for (label, normal) in labels {
        run.s.lps.push(LabelPlane {
            label,
            plane: Plane { point: w, normal },
        });
    }
}

/// Whether a corner triangle (green) lies in the two-ring of `v`.
fn near_corner_triangle(run: &Run, v: u32) -> bool {
    let green = |t: usize| run.s.tflags[t] & crate::edge_sharpener::T_GREEN != 0;
    run.table.vertex_corners(VertexId(v)).any(|c| {
        green(c.index() / 3)
            || run
                .table
                .vertex_corners(VertexId(run.cv(next(c.index()))))
                .any(|cc| green(cc.index() / 3))
    })
}

/// True when distance `d` beats the best so far (none yet counts as beaten).
#[inline]
fn better(best: Option<f64>, d: f64) -> bool {
    match best {
        None => true,
        Some(b) => d < b,
    }
}

/// Strong creases: rough interior edges turning by at least the smooth threshold and at least
/// this many degrees (see [`already_sharp_parts`]).
pub(crate) const STRONG_CREASE_DEGREES: f64 = 20.0;

/// A part (connected component) is already sharp when at least this fraction of the length
/// of its strong creases runs along *direct* edges, between red triangles of two smooth
/// regions. Measured (2026-12-06, the whole mesh as one part: `whet sharpen <in> -o out.off
/// --json`, key `direct_crease_fraction`): the CAD originals fandisk, partLp, joint, block,
/// cad_bracket, cad_box_hole, cad_cyl_fillet and sharp_sphere 0.68-1.0; the 48 swing-decoded
/// fixture meshes of `sharpen_figures -- swing` 0.00-0.09; marching cubes of cube, pyramid,
/// fandisk, cylinder and blend at 32-128 cells (generic, grid-aligned and near-axis
/// rotations) 0.00-0.12, of nine synth shapes at 20-28 cells at most 0.14, at 12-16 cells up
/// to 0.28 (creases barely resolved: the margin is thin there, and a part taken for sharp is
/// only left unchanged); the organic fixtures and rocker_arm 0.00-0.03.
pub(crate) const ALREADY_SHARP_FRACTION: f64 = 0.3;

/// The whole mesh's fraction under which no part is looked at on its own (a mesh of
/// chamfered parts never pays for the parts' labelling; a part that is already sharp on its
/// own raises the whole mesh's fraction by its share of the strong creases).
const PART_SCAN_FRACTION: f64 = 0.1;

/// Fewer strong creases than this in a part say nothing either way: the part is sharpened.
pub(crate) const MIN_STRONG_CREASES: usize = 8;

/// The whole mesh's fraction of strong-crease length on direct edges (0 without strong
/// creases), and the parts of the mesh whose creases are already sharp
/// ([`ALREADY_SHARP_FRACTION`]): per part, whether it is, and the part of each triangle;
/// `None` when none is (or the whole mesh's fraction is under [`PART_SCAN_FRACTION`]).
///
/// The papers' filters assume every crease was cut by the sampling, and a chamfer, locally,
/// looks like a narrow real face (a 45-degree chamfer one triangle wide, a facet of a coarsely
/// tessellated cylinder): on a CAD original the extended method snapped those and moved its
/// max error from 0.01 to 0.12-0.48 % of the diagonal (fandisk, partLp, joint). What tells
/// the two inputs apart is how the *other* creases look: a sampling cuts nearly every crease
/// into a chamfer, so its strong creases border a gray triangle; a CAD tessellation has its
/// creases on its edges, between the faces' own triangles.
#[allow(clippy::type_complexity)] // (fraction, (sharp per part, part per triangle))
fn already_sharp_parts(run: &Run) -> (f64, Option<(Vec<bool>, Vec<u32>)>) {
    let min_turn = run.smooth_threshold.max(STRONG_CREASE_DEGREES.to_radians());
    let opposite = run.table.opposites();
    let s = &run.s;
    // Each strong crease: its lower corner, its length and whether it is direct.
    let strong = s.rough.iter().filter_map(|&c| {
        let c = c as usize;
        if s.cflags[c] & C_BROWN != 0 || f64::from(s.angles[c]) < min_turn {
            return None;
        }
        let (t, u) = (c / 3, opposite[c] as usize / 3);
        let len = run.mesh.positions[run.cv(next(c)) as usize]
            .distance(run.mesh.positions[run.cv(crate::edge_sharpener::prev(c)) as usize]);
        let direct =
            s.tflags[t] & T_RED != 0 && s.tflags[u] & T_RED != 0 && s.region[t] != s.region[u];
        Some((c, len, direct))
    });
    let (mut direct, mut all) = (0.0f64, 0.0f64);
    for (_, len, d) in strong.clone() {
        all += len;
        if d {
            direct += len;
        }
    }
    if all == 0.0 {
        return (0.0, None);
    }
    let fraction = direct / all;
    if fraction < PART_SCAN_FRACTION {
        return (fraction, None);
    }
    let part = run.table.triangle_components();
    let nt = part.len();
    let mut length = vec![(0.0f64, 0.0f64, 0usize); nt];
    for (c, len, d) in strong {
        let x = &mut length[part[c / 3] as usize];
        x.1 += len;
        x.2 += 1;
        if d {
            x.0 += len;
        }
    }
    let sharp: Vec<bool> = length
        .iter()
        .map(|&(d, a, n)| n >= MIN_STRONG_CREASES && d >= ALREADY_SHARP_FRACTION * a)
        .collect();
    (fraction, sharp.contains(&true).then_some((sharp, part)))
}

/// A part of a surface sampling whose found chamfer edges are cut at under this fraction of
/// those cut or refused as curved bends everywhere: it is left as it went in
/// ([`leave_curved_parts`]). Measured (`whet sharpen --json`, cut / (cut + curved)): the 42
/// swing-decoded CAD streams of `sharpen_figures -- swing` at least 0.70 at the default
/// smooth factor (counting every refusal, not only `curved`), and the three sampled at
/// factors 1 and 1.25 (the encoder's lowest candidates) at least 0.67 (cad_cyl_fillet);
/// rocker_arm's six swing-decoded rows 0.04-0.20 (0.56-0.60 at factor 1), spot's exact
/// decodings at 8 and 10 bits 0.04 and 0.006, rocker_arm's at 12 bits 0.002.
pub(crate) const MIN_CUT_FRACTION: f64 = 0.4;

/// Fewer chamfer edges found (cut or refused as curved) than this in a part say nothing
/// either way: the part is sharpened.
pub(crate) const MIN_JUDGED_EDGES: usize = 8;

/// Drops every split of the parts whose chamfer edges `found` (lower corner, cut or refused
/// as curved) are mostly refused ([`MIN_CUT_FRACTION`]), and puts back any of their vertices
/// a corner move took: returns the number of splits dropped (chamfer edges that were to be
/// cut).
///
/// A chamfered crease is cut along its length: on a swing-decoded CAD part nearly all the
/// chamfer edges found snap, and the few refused sit where a crease meets a curved face. A
/// surface that bends everywhere (an organic model, a part of blends) gives the filters many
/// strips whose planes the consistency and curvature tests refuse; the one or two that pass
/// are bumps of the surface, not creases, and cutting them only adds error: spot's exact
/// decoding at 10 bits had one chamfer edge cut out of 179 found, and its max error went
/// from 0.048 to 0.367 % of the diagonal. Parts are looked at one by one only when the whole
/// mesh is under the fraction (a chamfered mesh pays for no labelling of its parts).
pub(crate) fn leave_curved_parts(run: &mut Run, found: &[(u32, bool)]) -> usize {
    let judged = |cut: usize, all: usize| {
        all >= MIN_JUDGED_EDGES && (cut as f64) < MIN_CUT_FRACTION * all as f64
    };
    let cut = found.iter().filter(|e| e.1).count();
    if !judged(cut, found.len()) {
        return 0;
    }
    // Per part (named by one of its triangles): edges cut, edges found.
    let part = run.table.triangle_components();
    let mut counts: std::collections::HashMap<u32, (usize, usize)> =
        std::collections::HashMap::new();
    for &(c, is_cut) in found {
        let e = counts.entry(part[c as usize / 3]).or_default();
        e.0 += usize::from(is_cut);
        e.1 += 1;
    }
    let curved = |t: usize| counts.get(&part[t]).is_some_and(|&(c, a)| judged(c, a));
    let mut dropped = 0;
    for &(c, is_cut) in found {
        let c = c as usize;
        if !is_cut || !curved(c / 3) {
            continue;
        }
        let o = run.table.opposites()[c] as usize;
        run.s.cflags[c] &= !crate::edge_sharpener::C_BLUE;
        run.s.cflags[o] &= !crate::edge_sharpener::C_BLUE;
        dropped += 1;
    }
    run.snap_cache.retain(|&(c, _)| !curved(c as usize / 3));
    for t in 0..run.mesh.triangles.len() {
        if !curved(t) {
            continue;
        }
        run.s.tflags[t] &= !(crate::edge_sharpener::T_GREEN | T_TOUCHED);
        for v in run.mesh.triangles[t] {
            run.positions[v as usize] = run.mesh.positions[v as usize];
            run.s.vflags[v as usize] &= !V_MOVED;
        }
    }
    run.report.curved_parts += counts.values().filter(|&&(c, a)| judged(c, a)).count();
    run.report.curved_part_splits += dropped;
    dropped
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;
    use whet_synth::{marching_cubes, Shape, ShapeKind, ShapeParams};

    /// Marching cubes of the synth fandisk turned generically (the grid stays on the axes).
    fn sampled_fandisk(cells: usize) -> whet_mesh::Mesh {
        let turn = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.5);
        let shape = Shape::new(
            ShapeKind::Fandisk,
            &ShapeParams::default().with_rotation(turn),
        )
        .unwrap();
        marching_cubes(&shape, cells).unwrap()
    }

    #[test]
    fn marching_cubes_vertices_are_on_grid_edges_until_the_mesh_is_turned() {
        let mc = sampled_fandisk(40);
        assert!(on_grid_edges(&mc));
        // The test keeps the grid answer it looked at for later steps of the run.
        let mut grid = None;
        assert!(!is_surface_sampling(&mc, true, &mut grid));
        assert_eq!(grid, Some(true));
        // Moved and scaled: equal coordinates stay equal.
        let mut moved = mc.clone();
        for p in &mut moved.positions {
            *p = *p * 3.5 + DVec3::new(0.25, -7.0, 1e3);
        }
        assert!(on_grid_edges(&moved));
        // Turned: no coordinate is shared any more, but its slivers (14-27 % thin) still
        // make it a grid sampler's.
        let turn = DQuat::from_axis_angle(DVec3::new(-2.0, 1.0, 0.5).normalize(), 0.7);
        let mut turned = mc.clone();
        for p in &mut turned.positions {
            *p = turn * *p;
        }
        assert!(!on_grid_edges(&turned));
        let mut grid = None;
        assert!(!is_surface_sampling(&turned, true, &mut grid));
        assert_eq!(grid, Some(false));
    }

    #[test]
    fn organic_originals_with_a_few_thin_triangles_are_surface_samplings() {
        // spot: 3.6 % of its triangles under 20 degrees, no vertex on a grid edge (with the
        // thin fraction alone it was taken for marching cubes: a horn tip moved 1.05 % of
        // the diagonal).
        let spot = whet_io::read_path(&whet_testkit::shared_fixture("spot.off"), None).unwrap();
        assert!(!on_grid_edges(&spot));
        assert!(is_surface_sampling(&spot, true, &mut None));
        // A later pass goes by the thin triangles alone, and never looks at the grid.
        let mut grid = None;
        assert!(!is_surface_sampling(&spot, false, &mut grid));
        assert_eq!(grid, None);
        // The same triangles with every coordinate on a lattice (as an exact-mode decoding's,
        // about 10 bits here): neighbours share a coordinate now and then, on any axis, but
        // not one in two of three edges as on a grid.
        let mut snapped = spot.clone();
        for p in &mut snapped.positions {
            *p = (*p * 1024.0).round() / 1024.0;
        }
        assert!(!on_grid_edges(&snapped));
    }

    /// The creases of a closed band of `n` labels from `first` on.
    fn band(first: u32, n: u32) -> Vec<(u32, u32)> {
        (0..n)
            .map(|i| {
                let (a, b) = (first + i, first + (i + 1) % n);
                (a.min(b), a.max(b))
            })
            .collect()
    }

    fn sorted(mut v: Vec<(u32, u32)>) -> Vec<(u32, u32)> {
        v.sort_unstable();
        v.dedup();
        v
    }

    #[test]
    fn a_closed_band_of_thin_regions_is_a_tube() {
        let all_thin = |_: u32| true;
        // Eight facets around a hole: every crease between them.
        let ring = sorted(band(10, 8));
        assert_eq!(tube_creases(&ring, all_thin), ring);
        // With a thick face along the band (the hole's rim): only the band's creases.
        let mut with_rim = ring.clone();
        with_rim.extend((10..18).map(|l| (0, l)));
        let with_rim = sorted(with_rim);
        assert_eq!(tube_creases(&with_rim, |l| l != 0), ring);
        // Too few facets: a corner where narrow faces meet, left alone.
        let small = sorted(band(10, TUBE_FACETS as u32 - 1));
        assert!(tube_creases(&small, all_thin).is_empty());
    }

    #[test]
    fn open_chains_and_dense_groups_are_not_tubes() {
        // An open chain (a curved face's strips between two real creases).
        let mut chain = band(10, 8);
        chain.retain(|&(a, b)| (a, b) != (10, 17));
        assert!(tube_creases(&sorted(chain), |_| true).is_empty());
        // A band with a chord: a member with three creases.
        let mut chord = band(10, 8);
        chord.push((10, 14));
        assert!(tube_creases(&sorted(chord), |_| true).is_empty());
        // A band one of whose members is thick.
        assert!(tube_creases(&sorted(band(10, 8)), |l| l != 13).is_empty());
        // Two bands: both are tubes.
        let two = sorted([band(10, 6), band(30, 5)].concat());
        assert_eq!(tube_creases(&two, |_| true), two);
    }
}
