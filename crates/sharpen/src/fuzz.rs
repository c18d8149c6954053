//! The entry point of the `sharpen` cargo-fuzz target (`fuzz/`), shared with the stable
//! replay test of its corpus, so a crasher the fuzzer finds is re-checked by `cargo test`.
//!
//! `whet decode --sharpen` runs the sharpener and the projections on whatever mesh a stream
//! decodes to, and `whet sharpen` on any file: tiny, folded, coplanar, with coincident
//! vertices and zero-area triangles. The marching-cubes property test covers noisy samplings
//! of solids; this target covers arbitrary small topology on a coarse grid, where exact
//! coincidences and exact coplanarity are common.

use crate::{
    flatten_planar_regions, project_beside_creases_onto_local_quadrics,
    project_creases_onto_local_quadrics, project_onto_local_quadrics, restore_apexes, sharpen,
    ApexOptions, BesideOptions, CreaseOptions, Error, Method, PlanarOptions, QuadricOptions,
    SharpenOptions,
};
use whet_mesh::{CornerTable, DVec3, Mesh, MeshError, VertexId};

/// Most vertices an input can have (small meshes keep each run short).
const MAX_VERTICES: usize = 48;
/// Most triangles an input can have.
const MAX_TRIANGLES: usize = 160;
/// The smooth factors bits 5-7 of the first byte pick (0: the default).
const SMOOTH_FACTORS: [f64; 8] = [2.0, 0.5, 1.0, 1.5, 2.5, 3.0, 3.5, 4.0];

/// The mesh and options an input describes, or `None` when it is too short.
///
/// Byte 0 picks the options (bits 0-1 the method: extended, papers, normal filter, and
/// extended with the gray labels of surface samplings (`surface_gray_labels`); bit 2
/// turns the welding off; bit 3 a second pass; bit 4 the curved walls; bits 5-7 the smooth
/// factor: 2 by default, else 0.5 to 4). Byte 1 the angle bits (3 to 14) and byte 2 the
/// move factor of the two projections after sharpening (0.01 to 10 angle steps), as a
/// swing stream states them. Byte 3 the vertex count (4 to 48), then three bytes per vertex
/// (a grid of sixteenths: coincidences and coplanarity are common), then three bytes per
/// triangle (vertex indices modulo the count).
pub fn fuzz_input(data: &[u8]) -> Option<(Mesh, SharpenOptions, PlanarOptions, QuadricOptions)> {
    let (&flags, rest) = data.split_first()?;
    let (&bits, rest) = rest.split_first()?;
    let (&factor, rest) = rest.split_first()?;
    let (&count, rest) = rest.split_first()?;
    let n = 4 + count as usize % (MAX_VERTICES - 3);
    if rest.len() < 3 * n {
        return None;
    }
    let (coords, tris) = rest.split_at(3 * n);
    let positions: Vec<DVec3> = coords
        .chunks_exact(3)
        .map(|c| DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) / 16.0)
        .collect();
    let triangles: Vec<[u32; 3]> = tris
        .chunks_exact(3)
        .take(MAX_TRIANGLES)
        .map(|t| [t[0], t[1], t[2]].map(|i| (i as usize % n) as u32))
        .collect();
    let method = match flags & 3 {
        0 | 3 => Method::Extended,
        1 => Method::Papers,
        _ => Method::NormalFilter,
    };
    let mut opts = SharpenOptions::DEFAULT
        .with_method(method)
        .with_smooth_factor(SMOOTH_FACTORS[usize::from(flags >> 5)])
        .with_weld_clusters(flags & 4 == 0)
        .with_passes(1 + u32::from(flags & 8 != 0))
        .with_surface_gray_labels(flags & 3 == 3);
    if flags & 16 != 0 {
        opts = opts.with_curved_wall_factor(crate::DEFAULT_CURVED_WALL_FACTOR);
    }
    let angle_bits = 3 + u32::from(bits) % 12;
    // The range a stream's header allows: 0.01 to 10 angle steps.
    let move_factor = f64::from(1 + u32::from(factor) * 999 / 255) / 100.0;
    Some((
        Mesh::new(positions, triangles),
        opts,
        PlanarOptions::for_swing(angle_bits, move_factor),
        QuadricOptions::for_swing(angle_bits, move_factor),
    ))
}

/// Sharpens the mesh `data` describes ([`fuzz_input`]) as `whet sharpen` does (cut to a
/// manifold first when it is not one), then runs the three projections after sharpening; the
/// EdgeSharpener methods run once more with a pseudo-random half of their snaps vetoed, as
/// a stream's field 33 may ask.
/// Panics only on a bug: a panic inside, an internal error, or an output that breaks the
/// guarantees (indices in range, finite positions, an oriented manifold with the input's
/// boundary, one parent per triangle, the input's vertices first). Returns the projected
/// mesh and its sharp-edge tags (for Bender, as `whet decode --sharpen --bend` runs it), or
/// `None` when the input is refused.
pub fn fuzz_sharpen(data: &[u8]) -> Option<(Mesh, Vec<[u32; 2]>)> {
    let (mut mesh, opts, planar, quadric) = fuzz_input(data)?;
    let report = mesh.topology_report();
    if !(report.manifold && report.oriented && report.problems.is_empty()) {
        mesh.make_manifold();
    }
    let out = match sharpen(&mesh, &opts) {
        Ok(out) => out,
        // The normal filter alone refuses triangles of zero area (make_manifold keeps them)
        // and non-uniform samplings; the EdgeSharpener methods take any make_manifold output.
        Err(Error::InvalidInput(MeshError::ZeroAreaTriangle { .. }) | Error::Parameter(_))
            if opts.method == Method::NormalFilter =>
        {
            return None
        }
        Err(e) => panic!("{:?} refused a make_manifold output: {e}", opts.method),
    };
    if opts.method != Method::NormalFilter {
        // A stream's snap vetoes (header field 33) may veto any subset of the snaps: a
        // hostile one chooses. Vetoing a pseudo-random half (seeded by the input) must keep
        // every guarantee.
        let mut judge = ArbitraryVetoes(
            data.iter()
                .fold(data.len() as u64, |h, &b| h.rotate_left(5) ^ u64::from(b)),
        );
        match crate::sharpen_judged(&mesh, &opts, &mut judge) {
            Ok(judged) => {
                check_output(&mesh, &judged.mesh, true);
                assert_eq!(judged.parents.len(), judged.mesh.triangles.len());
            }
            Err(e) => panic!("{:?} with vetoes refused what it took: {e}", opts.method),
        }
    }
    let mut sharp = out.mesh;
    check_output(&mesh, &sharp, opts.method != Method::NormalFilter);
    assert_eq!(
        out.parents.len(),
        sharp.triangles.len(),
        "one parent per triangle"
    );
    assert!(
        out.parents.iter().all(|f| f.index() < mesh.triangles.len()),
        "parent out of range"
    );
    if opts.method == Method::Papers {
        assert_eq!(
            &sharp.positions[..mesh.positions.len()],
            &mesh.positions[..],
            "the papers' method moved an input vertex"
        );
    }
    // The projections take every sharpened mesh (an oriented manifold, finite), move only
    // interior vertices and by at most their limits in mean edge lengths: the planar
    // projection half an edge, the quadric one its option.
    let before = sharp.clone();
    if let Err(e) = flatten_planar_regions(&mut sharp, &planar) {
        panic!("planar projection refused a sharpened mesh: {e}");
    }
    check_moves(&before, &sharp, 0.5, "planar projection");
    let before = sharp.clone();
    if let Err(e) = project_onto_local_quadrics(&mut sharp, &quadric) {
        panic!("quadric projection refused a sharpened mesh: {e}");
    }
    check_moves(&before, &sharp, quadric.max_move, "quadric projection");
    // The one-sided projection beside creases, at the quadric one's limit: the same
    // promises.
    let beside = BesideOptions::DEFAULT.with_max_move(quadric.max_move);
    let before = sharp.clone();
    if let Err(e) = project_beside_creases_onto_local_quadrics(&mut sharp, &beside) {
        panic!("one-sided projection refused a sharpened mesh: {e}");
    }
    check_moves(&before, &sharp, beside.max_move, "one-sided projection");
    // The crease projection, at the quadric one's limit (a stream states its own in mean
    // edge lengths, 0.01 to 10): the same promises.
    let crease = CreaseOptions::DEFAULT.with_max_move(quadric.max_move);
    let before = sharp.clone();
    if let Err(e) = project_creases_onto_local_quadrics(&mut sharp, &crease) {
        panic!("crease projection refused a sharpened mesh: {e}");
    }
    check_moves(&before, &sharp, crease.max_move, "crease projection");
    // The apex restoration, at four times that limit (a stream states 1.5 edges): the same
    // promises, and no triangle of a moved vertex's fan turned over.
    let apex = ApexOptions::DEFAULT.with_max_move(4.0 * quadric.max_move);
    let before = sharp.clone();
    if let Err(e) = restore_apexes(&mut sharp, &apex) {
        panic!("apex restoration refused a sharpened mesh: {e}");
    }
    check_moves(&before, &sharp, apex.max_move, "apex restoration");
    for (t, tri) in sharp.triangles.iter().enumerate() {
        if tri
            .iter()
            .any(|&v| before.positions[v as usize] != sharp.positions[v as usize])
        {
            assert!(
                sharp.face_cross(t).dot(before.face_cross(t)) > 0.0,
                "apex restoration turned triangle {t} over"
            );
        }
    }
    let edges = out.tags.edges.iter().map(|e| [e[0].0, e[1].0]).collect();
    Some((sharp, edges))
}

/// Vetoes each snap by one bit of a SplitMix64 sequence seeded by the input.
struct ArbitraryVetoes(u64);

impl crate::SnapJudge for ArbitraryVetoes {
    fn vetoes(&mut self, snaps: &[crate::Snap]) -> Vec<bool> {
        snaps
            .iter()
            .map(|_| {
                self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
                let mut z = self.0;
                z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
                z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
                (z ^ (z >> 31)) & 1 == 1
            })
            .collect()
    }
}

/// The [`fuzz_sharpen`] input describing `mesh` (scaled into the byte grid) with option
/// bytes `flags`, `bits` and `factor`; `None` when the mesh has under 4 or over 48 vertices
/// or over 160 triangles. Builds the seeds of the target's corpus.
pub fn fuzz_seed(mesh: &Mesh, flags: u8, bits: u8, factor: u8) -> Option<Vec<u8>> {
    let n = mesh.positions.len();
    if !(4..=MAX_VERTICES).contains(&n) || mesh.triangles.len() > MAX_TRIANGLES {
        return None;
    }
    let bbox = mesh.bounding_box();
    let extent = (bbox.max - bbox.min).max_element();
    let scale = if extent > 0.0 { 255.0 / extent } else { 0.0 };
    let mut out = vec![flags, bits, factor, (n - 4) as u8];
    for p in &mesh.positions {
        let g = ((*p - bbox.min) * scale).round();
        out.extend([g.x, g.y, g.z].map(|c| c.clamp(0.0, 255.0) as u8));
    }
    for t in &mesh.triangles {
        out.extend(t.map(|v| v as u8));
    }
    Some(out)
}

/// `output` is a valid sharpening of `input`: indices in range, finite positions, an
/// oriented manifold with the same boundary edge count and, when `keeps_vertices` (the
/// EdgeSharpener methods; the normal filter's needle collapses remove vertices), at least
/// the input's vertices.
fn check_output(input: &Mesh, output: &Mesh, keeps_vertices: bool) {
    let stage = "sharpen";
    let n = output.positions.len();
    assert!(
        !keeps_vertices || n >= input.positions.len(),
        "{stage}: vertices lost"
    );
    assert!(
        output.triangles.iter().flatten().all(|&v| (v as usize) < n),
        "{stage}: index out of range"
    );
    assert!(
        output.positions.iter().all(|p| p.is_finite()),
        "{stage}: non-finite position"
    );
    let (a, b) = (input.topology_report(), output.topology_report());
    assert!(
        b.manifold && b.oriented,
        "{stage}: output not an oriented manifold"
    );
    assert_eq!(
        a.boundary_edges, b.boundary_edges,
        "{stage}: boundary changed"
    );
}

/// A projection moved vertices only, to finite places: interior vertices, each by at most
/// `limit` mean edge lengths of `before`.
fn check_moves(before: &Mesh, after: &Mesh, limit: f64, stage: &str) {
    assert_eq!(
        before.triangles, after.triangles,
        "{stage}: triangles changed"
    );
    assert_eq!(
        before.positions.len(),
        after.positions.len(),
        "{stage}: vertex count changed"
    );
    assert!(
        after.positions.iter().all(|p| p.is_finite()),
        "{stage}: non-finite position"
    );
    let table = CornerTable::new(before).expect("checked before");
    let bound = limit * table.mean_edge_length(&before.positions) * (1.0 + 1e-9);
    for (v, (a, b)) in before.positions.iter().zip(&after.positions).enumerate() {
        if a == b {
            continue;
        }
        let vid = VertexId(v as u32);
        assert!(
            table.vertex_corner(vid).is_some() && !table.is_boundary_vertex(vid),
            "{stage}: unused or boundary vertex {v} moved"
        );
        assert!(
            a.distance(*b) <= bound,
            "{stage}: vertex {v} moved {} past {bound}",
            a.distance(*b)
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed tetrahedron (4 vertices, 4 triangles) with option byte `flags`, 3 angle bits
    /// and a move factor of about 2 steps.
    fn tetrahedron(flags: u8) -> Vec<u8> {
        let mut d = vec![flags, 3, 50, 0];
        d.extend_from_slice(&[0, 0, 0, 32, 0, 0, 0, 32, 0, 0, 0, 32]);
        d.extend_from_slice(&[0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]);
        d
    }

    #[test]
    fn input_layout_is_as_documented() {
        let (mesh, opts, _, _) = fuzz_input(&tetrahedron(0b0011_1101)).unwrap();
        assert_eq!(mesh.positions.len(), 4);
        assert_eq!(mesh.positions[1], DVec3::new(2.0, 0.0, 0.0));
        assert_eq!(
            mesh.triangles,
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
        );
        assert_eq!(opts.method, Method::Papers);
        assert!(!opts.weld_clusters);
        assert_eq!(opts.passes, 2);
        assert_eq!(opts.smooth_factor, 0.5);
        assert!(opts.curved_wall_factor.is_some());
        assert!(!opts.surface_gray_labels);
        let (_, gray, _, _) = fuzz_input(&tetrahedron(3)).unwrap();
        assert_eq!(gray.method, Method::Extended);
        assert!(gray.surface_gray_labels);
        assert!(
            fuzz_input(&tetrahedron(0)[..15]).is_none(),
            "too short for 4 vertices"
        );
    }

    #[test]
    fn every_method_keeps_a_tetrahedron_valid() {
        for flags in 0..=255u8 {
            fuzz_sharpen(&tetrahedron(flags));
        }
    }
}
