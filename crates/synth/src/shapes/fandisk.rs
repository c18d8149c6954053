//! The fandisk-like CAD part: a 2-D profile of line segments and circular arcs extruded along
//! z, with a truncated cone standing on one of its planar faces.
//!
//! Profile (counter-clockwise in the xy plane, y up), extruded over `|z| <= 0.35`:
//!
//! ```text
//!   I____H                    ____
//!   |    |                   /    \     frustum standing on the plateau
//!   |    G__F      E________/______\________D
//!   |         \____/                          \   convex arc C -> D
//!   |         groove                           C
//!   |                                          |
//!   A__________________________________________B
//! ```
//!
//! A = (-0.8, -0.3), B = (0.8, -0.3), C = (0.8, 0), D = (0.58.., 0.2), E = (-0.15, 0.2),
//! F = (-0.45, 0.2), G = (-0.55, 0.2), H = (-0.55, 0.4), I = (-0.8, 0.4). The convex arc
//! (radius 0.68) leaves the wall at 35 degrees and meets the plateau at 30 degrees; the groove
//! (radius 0.18, 0.08 deep) meets the plateau at 56 degrees on both rims; the frustum has
//! radii 0.18 and 0.09 and height 0.15.
//!
//! Faces: planar (caps, walls, plateau, cone top), cylindrical (a convex one from the arc, a
//! concave one from the groove), conical (the frustum on the plateau). Creases: convex profile
//! corners (B, C, D, E, F, H, I, A), the concave step corner G, a concave circle where the cone
//! meets the plateau and a convex circle at its top; the cap corners are where three creases
//! meet. The SDF is the minimum of the exact extrusion SDF and the exact frustum SDF (the
//! frustum reaches a little below the plateau so the union has no internal zero set): exact
//! outside, a 1-Lipschitz bound inside.

use std::f64::consts::{PI, TAU};

use glam::{DVec2, DVec3};

use super::build::{chords_for, circle, sagitta, signed_area2, Builder};
use super::sdf::{dist_segment2, inside_polygon2, sd_extrude, Arc2, Revolved};
use super::{Built, Geometry};

const HZ: f64 = 0.35;
const PLATEAU_Y: f64 = 0.2;
const ARC1_START: f64 = 35.0; // degrees: crease with the right wall
const ARC1_END: f64 = 60.0; // degrees: 30-degree crease with the plateau
const GROOVE_RADIUS: f64 = 0.18;
const CONE_BASE_RADIUS: f64 = 0.18;
const CONE_TOP_RADIUS: f64 = 0.09;
const CONE_HEIGHT: f64 = 0.15;
/// How far the frustum reaches below the plateau, inside the body.
const CONE_FOOT: f64 = 0.03;

/// The fandisk's exact data, shared by its SDF and its truth mesh.
#[derive(Clone, Debug)]
pub(crate) struct Fandisk {
    /// A, B, C, D, E, F, G, H, I: the profile with arcs replaced by chords.
    chord_poly: Vec<DVec2>,
    /// The straight profile edges.
    lines: Vec<(DVec2, DVec2)>,
    /// Convex arc C -> D (counter-clockwise about its centre).
    convex: Arc2,
    /// The groove, stored counter-clockwise from F to E (the profile runs it clockwise).
    groove: Arc2,
    /// Centre of the cone's base circle on the plateau.
    cone_base: DVec3,
    /// The frustum in its meridian plane `(rho, y - cone_base.y)`.
    cone: Revolved,
}

impl Fandisk {
    pub(crate) fn new() -> Self {
        let (t0, t1) = (ARC1_START.to_radians(), ARC1_END.to_radians());
        let r1 = PLATEAU_Y / (t1.sin() - t0.sin());
        let c = DVec2::new(0.8, 0.0);
        let o1 = c - DVec2::new(t0.cos(), t0.sin()) * r1;
        let d = DVec2::new(o1.x + r1 * t1.cos(), PLATEAU_Y);
        let e = DVec2::new(-0.15, PLATEAU_Y);
        let f = DVec2::new(-0.45, PLATEAU_Y);
        let half_chord = 0.5 * (e.x - f.x);
        let o2 = DVec2::new(
            0.5 * (e.x + f.x),
            PLATEAU_Y + (GROOVE_RADIUS * GROOVE_RADIUS - half_chord * half_chord).sqrt(),
        );
        let a = DVec2::new(-0.8, -0.3);
        let b = DVec2::new(0.8, -0.3);
        let g = DVec2::new(-0.55, PLATEAU_Y);
        let h = DVec2::new(-0.55, 0.4);
        let i = DVec2::new(-0.8, 0.4);
        let chord_poly = vec![a, b, c, d, e, f, g, h, i];
        let lines = vec![(a, b), (b, c), (d, e), (f, g), (g, h), (h, i), (i, a)];
        let cone_base = DVec3::new(0.5 * (d.x + e.x), PLATEAU_Y, 0.0);
        let foot_r =
            CONE_BASE_RADIUS + (CONE_BASE_RADIUS - CONE_TOP_RADIUS) * CONE_FOOT / CONE_HEIGHT;
        let cone = Revolved::new(vec![
            DVec2::new(0.0, -CONE_FOOT),
            DVec2::new(foot_r, -CONE_FOOT),
            DVec2::new(CONE_TOP_RADIUS, CONE_HEIGHT),
            DVec2::new(0.0, CONE_HEIGHT),
        ]);
        Fandisk {
            chord_poly,
            lines,
            convex: Arc2 {
                center: o1,
                radius: r1,
                start: c,
                end: d,
            },
            groove: Arc2 {
                center: o2,
                radius: GROOVE_RADIUS,
                start: f,
                end: e,
            },
            cone_base,
            cone,
        }
    }

    /// Exact signed distance to the profile region in the xy plane.
    #[inline]
    fn profile_sdf(&self, q: DVec2) -> f64 {
        let mut d = self.convex.distance(q).min(self.groove.distance(q));
        for &(a, b) in &self.lines {
            d = d.min(dist_segment2(q, a, b));
        }
        let inside = inside_polygon2(q, &self.chord_poly)
            ^ self.convex.in_segment(q)
            ^ self.groove.in_segment(q);
        if inside {
            -d
        } else {
            d
        }
    }

    #[inline]
    pub(crate) fn sdf(&self, p: DVec3) -> f64 {
        let body = sd_extrude(self.profile_sdf(DVec2::new(p.x, p.y)), p.z, HZ);
        let l = p - self.cone_base;
        let cone = self.cone.sdf(DVec2::new(l.x, l.z).length(), l.y);
        body.min(cone)
    }

    /// The truth mesh, its chordal error and the exact volume, for chordal tolerance `tol`.
    pub(crate) fn build(self, tol: f64) -> Built {
        // The chord polygon is A..I as built in `new`.
        let (c, d, e, f) = (
            self.chord_poly[2],
            self.chord_poly[3],
            self.chord_poly[4],
            self.chord_poly[5],
        );
        let sweep = |from: DVec2, to: DVec2, arc: &Arc2| {
            let a0 = (from - arc.center).to_angle();
            let a1 = (to - arc.center).to_angle();
            let mut span = a1 - a0;
            if span > PI {
                span -= TAU;
            } else if span < -PI {
                span += TAU;
            }
            (a0, span)
        };
        // The profile polyline: arcs cut into chords.
        let (c0, cspan) = sweep(c, d, &self.convex);
        let n1 = chords_for(self.convex.radius, cspan.abs(), tol, 1);
        let (g0, gspan) = sweep(e, f, &self.groove);
        let n2 = chords_for(self.groove.radius, gspan.abs(), tol, 1);
        let mut pts: Vec<DVec2> = Vec::new();
        let mut plateau_start = 0;
        for (k, &v) in self.chord_poly.iter().enumerate() {
            pts.push(v);
            if k == 2 {
                for j in 1..n1 {
                    let t = c0 + cspan * j as f64 / n1 as f64;
                    pts.push(self.convex.center + DVec2::from_angle(t) * self.convex.radius);
                }
            }
            if k == 3 {
                plateau_start = pts.len() - 1;
            }
            if k == 4 {
                for j in 1..n2 {
                    let t = g0 + gspan * j as f64 / n2 as f64;
                    pts.push(self.groove.center + DVec2::from_angle(t) * self.groove.radius);
                }
            }
        }
        let np = pts.len();
        let mut b = Builder::new();
        let front = b.vertices(pts.iter().map(|p| p.extend(HZ)));
        let back = b.vertices(pts.iter().map(|p| p.extend(-HZ)));
        b.simple_polygon(&front, &pts, DVec3::Z);
        b.simple_polygon(&back, &pts, -DVec3::Z);

        // The cone: base ring on the plateau, top ring, top disk.
        let n3 = chords_for(CONE_BASE_RADIUS, TAU, tol, 8);
        let top_c = self.cone_base + DVec3::Y * CONE_HEIGHT;
        let base = b.vertices(circle(
            self.cone_base,
            DVec3::X,
            DVec3::Z,
            CONE_BASE_RADIUS,
            n3,
        ));
        let top = b.vertices(circle(top_c, DVec3::X, DVec3::Z, CONE_TOP_RADIUS, n3));
        let tc = b.vertex(top_c);
        let axis = self.cone_base;
        b.strip(&base, &top, true, |p| {
            DVec3::new(p.x - axis.x, 0.0, p.z - axis.z)
        });
        b.disk(tc, &top, DVec3::Y);

        // Side walls; the plateau D -> E carries the cone's hole.
        for k in 0..np {
            let k1 = (k + 1) % np;
            let dir = pts[k1] - pts[k];
            let outward = DVec3::new(dir.y, -dir.x, 0.0);
            if k == plateau_start {
                let ring = [back[k], back[k1], front[k1], front[k]];
                b.annulus(&ring, &base, self.cone_base, DVec3::Y);
            } else {
                b.quad_facing(back[k], back[k1], front[k1], front[k], outward);
            }
        }

        let segment = |r: f64, angle: f64| 0.5 * r * r * (angle - angle.sin());
        let area = 0.5 * signed_area2(&self.chord_poly) + segment(self.convex.radius, cspan.abs())
            - segment(self.groove.radius, gspan.abs());
        let frustum = PI * CONE_HEIGHT / 3.0
            * (CONE_BASE_RADIUS * CONE_BASE_RADIUS
                + CONE_BASE_RADIUS * CONE_TOP_RADIUS
                + CONE_TOP_RADIUS * CONE_TOP_RADIUS);
        let tessellation_error = sagitta(self.convex.radius, cspan.abs() / n1 as f64)
            .max(sagitta(self.groove.radius, gspan.abs() / n2 as f64))
            .max(sagitta(CONE_BASE_RADIUS, TAU / n3 as f64));
        Built {
            geometry: Geometry::Fandisk(Box::new(self)),
            mesh: b.finish(),
            tessellation_error,
            volume: area * 2.0 * HZ + frustum,
        }
    }
}
