//! What a sharpening run did: the counts of `whet sharpen --json`.

use std::fmt::Write as _;
use std::time::Duration;

use crate::options::Method;

/// Why a new vertex stayed at the midpoint of its chamfer edge or the centroid of its corner
/// triangle instead of moving onto the extrapolated planes (docs/sharpen.md, "Degenerate
/// cases").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum UnmovedReason {
    /// The two planes of a chamfer edge are parallel (closer than the smooth threshold).
    Parallel,
    /// The three planes of a corner triangle have coplanar normals.
    Dependent,
    /// The strip is convex at one end of the edge and concave at the other.
    MixedConvexity,
    /// The snapped position would make an edge longer than the longest input edge.
    TooLong,
    /// The snapped position would reverse a triangle against the input triangle it replaces.
    Flipped,
    /// Unsnapped by the sliver pass, which could remove a small angle no other way.
    Sliver,
    /// Extended method: the planes of the neighbouring vertices of the same surfaces disagree
    /// with the snapped point (the surface is curved at the scale of the sampling).
    Curved,
    /// A [`crate::SnapJudge`] vetoed the snap: a swing stream's encoder measured it farther
    /// from the original than the rest position (docs/sharpen.md, "Snap vetoes").
    Vetoed,
}

impl UnmovedReason {
    /// Every reason, in declaration order.
    pub const ALL: [UnmovedReason; 8] = [
        UnmovedReason::Parallel,
        UnmovedReason::Dependent,
        UnmovedReason::MixedConvexity,
        UnmovedReason::TooLong,
        UnmovedReason::Flipped,
        UnmovedReason::Sliver,
        UnmovedReason::Curved,
        UnmovedReason::Vetoed,
    ];

    /// The snake_case name used in JSON.
    pub const fn name(self) -> &'static str {
        match self {
            UnmovedReason::Parallel => "parallel",
            UnmovedReason::Dependent => "dependent",
            UnmovedReason::MixedConvexity => "mixed_convexity",
            UnmovedReason::TooLong => "too_long",
            UnmovedReason::Flipped => "flipped",
            UnmovedReason::Sliver => "sliver",
            UnmovedReason::Curved => "curved",
            UnmovedReason::Vetoed => "vetoed",
        }
    }

    pub(crate) const fn index(self) -> usize {
        self as usize
    }
}

/// Counts and timing of one run. Vertex counts refer to the output mesh unless named
/// otherwise: `snapped_vertices` plus the sum of `unmoved` is `new_vertices`.
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct SharpenReport {
    /// The method that ran.
    pub method: Method,
    /// The smooth factor used.
    pub smooth_factor: f64,
    /// Mean angle between the normals of adjacent triangles over the interior edges, in
    /// degrees (the papers' epsilon).
    pub mean_angle_degrees: f64,
    /// `smooth_factor` times the mean: edges under it are smooth.
    pub smooth_threshold_degrees: f64,
    /// Vertices of the input.
    pub input_vertices: usize,
    /// Triangles of the input.
    pub input_triangles: usize,
    /// Vertices of the output.
    pub output_vertices: usize,
    /// Triangles of the output.
    pub output_triangles: usize,
    /// Smooth (brown) edges.
    pub smooth_edges: usize,
    /// Chamfer (blue) edges: each got a new vertex.
    pub chamfer_edges: usize,
    /// Corner (green) triangles: each got a new vertex (a pair of twins counts once).
    pub corner_triangles: usize,
    /// Pairs of twin corner triangles that share one centre (extended method;
    /// docs/sharpen.md, "What we extend", step 13); each pair's shared edge is not counted in
    /// `chamfer_edges`.
    pub twin_corners: usize,
    /// Input vertices classified as chamfer vertices by the extended detection (0 in papers
    /// mode).
    pub chamfer_vertices: usize,
    /// New vertices inserted before the sliver pass.
    pub inserted_vertices: usize,
    /// New vertices in the output (inserted minus those the sliver pass removed).
    pub new_vertices: usize,
    /// New vertices of the output that sit on their extrapolated planes.
    pub snapped_vertices: usize,
    /// New vertices of the output left at their midpoint or centroid, by reason (indexed like
    /// [`UnmovedReason::ALL`]; see [`SharpenReport::unmoved`]).
    pub unmoved_by_reason: [usize; 8],
    /// Extended method: chamfer edges found and then left unsplit because their new vertex
    /// could not move, by reason (indexed like [`UnmovedReason::ALL`]): no vertex was
    /// inserted for them, so they are in no count of `unmoved_by_reason`; the chamfer stays
    /// there.
    pub dropped_edges_by_reason: [usize; 8],
    /// Extended method: chamfer edges left unsplit because their new vertex would move by
    /// under a thousandth of the edge (an already sharp crease).
    pub idle_splits: usize,
    /// Extended method: corner triangles found and then left without a centre because it
    /// could not move, by reason (indexed like [`UnmovedReason::ALL`]).
    pub dropped_corners_by_reason: [usize; 8],
    /// Input vertices moved (extended mode only; always chamfer vertices).
    pub moved_input_vertices: usize,
    /// Triangles removed by the sliver pass's edge collapses.
    pub collapsed_triangles: usize,
    /// Extended method: input vertices welded into a near-coincident neighbour because their
    /// cluster's slivers kept a chamfer edge from splitting (docs/sharpen.md, "What we extend",
    /// step 10). They keep their index, used by no triangle.
    pub welded_vertices: usize,
    /// The options' curved-wall factor (0: off).
    pub curved_wall_factor: f64,
    /// Edges the curved walls made smooth (included in `smooth_edges`).
    pub curved_wall_edges: usize,
    /// Passes that ran (`SharpenOptions::passes`; fewer when one changed nothing, the mesh
    /// outgrew `pass_budget_triangles` or a later pass failed). The counts of events of the
    /// later passes (chamfer edges, new vertices, collapses, ...) are added to the first's;
    /// the smooth threshold, the mean angle, `smooth_edges` and `curved_wall_edges` are the
    /// first pass's.
    pub passes: usize,
    /// Subdivided triangles the sliver pass restored to their input triangles (docs/sharpen.md,
    /// "The sliver pass").
    pub restored_triangles: usize,
    /// Extended method: connected parts left alone because their creases are already sharp
    /// (most of their strong creases run along edges between smooth regions instead of
    /// bordering a chamfer; docs/sharpen.md, "What we extend", step 17).
    pub already_sharp_components: usize,
    /// Extended method, first pass: the fraction of the whole mesh's strong-crease length that
    /// runs along edges between smooth regions (`already_sharp_components`' measure; 0 without
    /// strong creases or in later passes).
    pub direct_crease_fraction: f64,
    /// Extended method, first pass on a surface sampling: connected parts left as they went
    /// in because most of the chamfer edges found there were refused as curved (a surface
    /// that bends everywhere; docs/sharpen.md, "What we extend", step 19).
    pub curved_parts: usize,
    /// Chamfer edges that would have been cut in those parts (left unsplit with them).
    pub curved_part_splits: usize,
    /// The options' `surface_gray_labels` (gray vertices of surface samplings labelled too;
    /// those labelled are in `chamfer_vertices`).
    pub surface_gray_labels: bool,
    /// Vertices tagged sharp (filter 3bis plus the new vertices).
    pub tagged_vertices: usize,
    /// Edges tagged sharp.
    pub sharp_edges: usize,
    /// Wall time of the run.
    pub time: Duration,
    /// Normal filter (zero for the other methods): the neighbourhood radius in mean edge
    /// lengths, and `eta`, `lambda`.
    pub rho: f64,
    /// Normal filter: the feature threshold.
    pub eta: f64,
    /// Normal filter: the flood stop.
    pub lambda: f64,
    /// Normal filter: feature faces found by detection (`FFt`).
    pub feature_faces: usize,
    /// Normal filter: vertices with a feature face around them (`VFt`).
    pub feature_vertices: usize,
    /// Normal filter: vertices with only feature faces around them (`FAFt`).
    pub absolute_feature_vertices: usize,
    /// Normal filter: bilaplacian pre-smoothing iterations (`ceil(4 / rho)`).
    pub presmooth_iterations: usize,
    /// Normal filter: feature faces that received a filtered normal.
    pub filtered_normals: usize,
    /// Normal filter: normals replaced by the rectifying pass.
    pub rectified_normals: usize,
    /// Normal filter: vertex-updating sweeps run.
    pub update_iterations: usize,
    /// Normal filter: vertex moves whose full step would have flipped or flattened a face, so
    /// the step was shortened or refused.
    pub flips_avoided: usize,
    /// Normal filter: cap faces removed by swapping their longest edge.
    pub swaps: usize,
    /// Normal filter: needle faces removed by collapsing their shortest edge (one vertex each).
    pub collapses: usize,
    /// Normal filter: time of feature detection.
    pub detection_time: Duration,
    /// Normal filter: time of pre-smoothing, normal filtering and rectifying.
    pub filtering_time: Duration,
    /// Normal filter: time of vertex updating with cap and needle removal.
    pub updating_time: Duration,
}

impl SharpenReport {
    /// New vertices of the output left unmoved for `reason`.
    pub fn unmoved(&self, reason: UnmovedReason) -> usize {
        self.unmoved_by_reason[reason.index()]
    }

    /// All unmoved new vertices of the output.
    pub fn unmoved_total(&self) -> usize {
        self.unmoved_by_reason.iter().sum()
    }

    /// Extended method: chamfer edges left unsplit because their new vertex could not move
    /// for `reason` (no vertex inserted, so not in [`SharpenReport::unmoved`]).
    pub fn dropped_edges(&self, reason: UnmovedReason) -> usize {
        self.dropped_edges_by_reason[reason.index()]
    }

    /// Extended method: corner triangles left without a centre because it could not move
    /// for `reason`.
    pub fn dropped_corners(&self, reason: UnmovedReason) -> usize {
        self.dropped_corners_by_reason[reason.index()]
    }

    /// The report as one JSON object (no whitespace), for `whet sharpen --json`: `method`,
    /// `smooth_factor`, `mean_angle_degrees`, `smooth_threshold_degrees`, the input and output
    /// counts, `smooth_edges`, `chamfer_edges`, `corner_triangles`, `chamfer_vertices`,
    /// `inserted_vertices`, `new_vertices`, `snapped_vertices`, `unmoved` (an object with one
    /// count per [`UnmovedReason`] name), `moved_input_vertices`, `collapsed_triangles`,
    /// `restored_triangles`, `tagged_vertices`, `sharp_edges`, `time_ms`, then the normal
    /// filter's `rho`, `eta`, `lambda`, `feature_faces`, `feature_vertices`,
    /// `absolute_feature_vertices`, `presmooth_iterations`, `filtered_normals`,
    /// `rectified_normals`, `update_iterations`, `flips_avoided`, `swaps`, `collapses`,
    /// `detection_ms`, `filtering_ms` and `updating_ms` (zeros for the other methods), then
    /// `curved_wall_factor`, `curved_wall_edges`, `passes`, `twin_corners`,
    /// `already_sharp_components`, `direct_crease_fraction`, and the extended method's
    /// `dropped_chamfer_edges` (an object like `unmoved`, plus `idle`) and
    /// `dropped_corner_triangles` (like `unmoved`), `curved_parts`, `curved_part_splits` and
    /// `surface_gray_labels`.
    pub fn to_json(&self) -> String {
        let mut s = String::with_capacity(768);
        // Writing to a String cannot fail.
        let _ = write!(
            s,
            "{{\"method\":\"{}\",\"smooth_factor\":{},\"mean_angle_degrees\":{},\
             \"smooth_threshold_degrees\":{},\"input_vertices\":{},\"input_triangles\":{},\
             \"output_vertices\":{},\"output_triangles\":{},\"smooth_edges\":{},\
             \"chamfer_edges\":{},\"corner_triangles\":{},\"chamfer_vertices\":{},\
             \"inserted_vertices\":{},\"new_vertices\":{},\"snapped_vertices\":{},\"unmoved\":{{",
            self.method.name(),
            json_num(self.smooth_factor),
            json_num(self.mean_angle_degrees),
            json_num(self.smooth_threshold_degrees),
            self.input_vertices,
            self.input_triangles,
            self.output_vertices,
            self.output_triangles,
            self.smooth_edges,
            self.chamfer_edges,
            self.corner_triangles,
            self.chamfer_vertices,
            self.inserted_vertices,
            self.new_vertices,
            self.snapped_vertices,
        );
        write_reasons(&mut s, &self.unmoved_by_reason);
        let _ = write!(
            s,
            "}},\"moved_input_vertices\":{},\"collapsed_triangles\":{},\"restored_triangles\":{},\
             \"tagged_vertices\":{},\"sharp_edges\":{},\"time_ms\":{},\"welded_vertices\":{},",
            self.moved_input_vertices,
            self.collapsed_triangles,
            self.restored_triangles,
            self.tagged_vertices,
            self.sharp_edges,
            json_num(self.time.as_secs_f64() * 1e3),
            self.welded_vertices,
        );
        let _ = write!(
            s,
            "\"rho\":{},\"eta\":{},\"lambda\":{},\"feature_faces\":{},\"feature_vertices\":{},\
             \"absolute_feature_vertices\":{},\"presmooth_iterations\":{},\"filtered_normals\":{},\
             \"rectified_normals\":{},\"update_iterations\":{},\"flips_avoided\":{},\"swaps\":{},\
             \"collapses\":{},\"detection_ms\":{},\"filtering_ms\":{},\"updating_ms\":{},\
             \"curved_wall_factor\":{},\"curved_wall_edges\":{},\"passes\":{},\
             \"twin_corners\":{},\"already_sharp_components\":{},\"direct_crease_fraction\":{},",
            json_num(self.rho),
            json_num(self.eta),
            json_num(self.lambda),
            self.feature_faces,
            self.feature_vertices,
            self.absolute_feature_vertices,
            self.presmooth_iterations,
            self.filtered_normals,
            self.rectified_normals,
            self.update_iterations,
            self.flips_avoided,
            self.swaps,
            self.collapses,
            json_num(self.detection_time.as_secs_f64() * 1e3),
            json_num(self.filtering_time.as_secs_f64() * 1e3),
            json_num(self.updating_time.as_secs_f64() * 1e3),
            json_num(self.curved_wall_factor),
            self.curved_wall_edges,
            self.passes,
            self.twin_corners,
            self.already_sharp_components,
            json_num(self.direct_crease_fraction),
        );
        s.push_str("\"dropped_chamfer_edges\":{");
        write_reasons(&mut s, &self.dropped_edges_by_reason);
        let _ = write!(
            s,
            ",\"idle\":{}}},\"dropped_corner_triangles\":{{",
            self.idle_splits
        );
        write_reasons(&mut s, &self.dropped_corners_by_reason);
        let _ = write!(
            s,
            "}},\"curved_parts\":{},\"curved_part_splits\":{},\"surface_gray_labels\":{}}}",
            self.curved_parts, self.curved_part_splits, self.surface_gray_labels
        );
        s
    }
}

/// One count per [`UnmovedReason`], by its name, comma separated (an object's members).
fn write_reasons(s: &mut String, counts: &[usize; 8]) {
    for (i, r) in UnmovedReason::ALL.iter().enumerate() {
        if i > 0 {
            s.push(',');
        }
        let _ = write!(s, "\"{}\":{}", r.name(), counts[i]);
    }
}

/// A finite number in JSON (non-finite values, which the report never holds, become null).
fn json_num(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        "null".to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_has_every_field_once() {
        let mut r = SharpenReport {
            smooth_factor: 2.0,
            ..SharpenReport::default()
        };
        r.unmoved_by_reason[UnmovedReason::TooLong.index()] = 3;
        let j = r.to_json();
        for key in [
            "method",
            "smooth_factor",
            "chamfer_edges",
            "corner_triangles",
            "new_vertices",
            "unmoved",
            "collapsed_triangles",
            "time_ms",
            "feature_faces",
            "absolute_feature_vertices",
            "swaps",
            "collapses",
            "detection_ms",
            "updating_ms",
            "curved_wall_factor",
            "curved_wall_edges",
            "passes",
            "twin_corners",
            "already_sharp_components",
            "direct_crease_fraction",
            "dropped_chamfer_edges",
            "idle",
            "dropped_corner_triangles",
            "curved_parts",
            "curved_part_splits",
            "surface_gray_labels",
        ] {
            assert_eq!(j.matches(&format!("\"{key}\":")).count(), 1, "{key} in {j}");
        }
        // Each reason once in each of the three objects that count by reason.
        for r in UnmovedReason::ALL {
            assert_eq!(j.matches(&format!("\"{}\":", r.name())).count(), 3, "{j}");
        }
        assert!(j.contains(
            "\"unmoved\":{\"parallel\":0,\"dependent\":0,\"mixed_convexity\":0,\"too_long\":3"
        ));
        assert!(j.contains("\"idle\":0},\"dropped_corner_triangles\":{\"parallel\":0"));
        assert!(j.starts_with("{\"method\":\"extended\"") && j.ends_with('}'));
        assert_eq!(r.unmoved_total(), 3);
    }
}
