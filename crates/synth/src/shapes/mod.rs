//! Shapes whose true surface is known exactly: a signed distance function (negative inside)
//! and a truth triangle mesh whose sharp edges and corners lie exactly on the true creases.
//!
//! All shapes are centred near the origin with bounding-box diagonals between 1.3 and 2.1, and
//! use y as "up" where it matters (cylinder and cone axes, the fandisk's profile). An optional
//! rotation turns the shape about the origin; the SDF, the truth mesh and the bounds all
//! describe the rotated shape.
//!
//! | shape | SDF |
//! |---|---|
//! | cube, box, sphere, cylinder, cone, blend (rounded box) | exact Euclidean distance everywhere |
//! | pyramid, octahedron, thin-face | exact everywhere (convex polyhedron: largest plane distance inside, nearest face polygon outside) |
//! | torus-box (box minus cylinder) | exact inside, a 1-Lipschitz lower bound outside (max of exact SDFs) |
//! | fandisk (extruded profile plus frustum) | exact outside, a 1-Lipschitz lower bound inside (min of exact SDFs) |
//!
//! Every SDF is 1-Lipschitz with the exact zero set, which is what the narrow-band marching
//! cubes relies on.

mod blend;
mod build;
mod fandisk;
mod polyhedra;
mod revolved;
mod sdf;
mod torus_box;

use std::fmt;
use std::str::FromStr;

use glam::{DQuat, DVec3};
use whet_mesh::{Aabb, Mesh};

use crate::Error;

/// Chordal error allowed in the truth meshes of curved shapes, as a fraction of the bounding
/// box diagonal (0.005 %). Tessellations are designed for 80 % of it.
pub const TESSELLATION_TOLERANCE: f64 = 5e-5;

/// Half-extents of the 1.0 x 0.7 x 0.5 box that `box`, `blend`, `thin-face` and `torus-box`
/// are made from.
const BOX_HALF: DVec3 = DVec3::new(0.5, 0.35, 0.25);
/// Default fillet radius of `blend`.
const DEFAULT_BLEND_RADIUS: f64 = 0.04;
/// Width of the thin-face chamfer: 2 % of the box's length, under three sampling steps at the
/// default resolution 64 (one step is 1/64 there).
const THIN_FACE_WIDTH: f64 = 0.02;
/// Radius of the torus-box hole.
const HOLE_RADIUS: f64 = 0.15;

/// The shapes. See [`ShapeKind::description`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ShapeKind {
    /// Unit cube.
    Cube,
    /// 1.0 x 0.7 x 0.5 box.
    Box,
    /// Square pyramid.
    Pyramid,
    /// Regular octahedron.
    Octahedron,
    /// Cylinder with flat caps.
    Cylinder,
    /// Cone.
    Cone,
    /// Fandisk-like CAD part.
    Fandisk,
    /// The box with rounded edges.
    Blend,
    /// The box with one edge cut by a narrow chamfer face.
    ThinFace,
    /// The box with a cylindrical through-hole (genus 1).
    TorusBox,
    /// Sphere.
    Sphere,
}

impl ShapeKind {
    /// Every shape, in declaration order.
    pub const ALL: [ShapeKind; 11] = [
        ShapeKind::Cube,
        ShapeKind::Box,
        ShapeKind::Pyramid,
        ShapeKind::Octahedron,
        ShapeKind::Cylinder,
        ShapeKind::Cone,
        ShapeKind::Fandisk,
        ShapeKind::Blend,
        ShapeKind::ThinFace,
        ShapeKind::TorusBox,
        ShapeKind::Sphere,
    ];

    /// The name used on the command line and by [`FromStr`].
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Cube => "cube",
            ShapeKind::Box => "box",
            ShapeKind::Pyramid => "pyramid",
            ShapeKind::Octahedron => "octahedron",
            ShapeKind::Cylinder => "cylinder",
            ShapeKind::Cone => "cone",
            ShapeKind::Fandisk => "fandisk",
            ShapeKind::Blend => "blend",
            ShapeKind::ThinFace => "thin-face",
            ShapeKind::TorusBox => "torus-box",
            ShapeKind::Sphere => "sphere",
        }
    }

    /// One line on what the shape is and what it tests.
    pub fn description(self) -> &'static str {
        match self {
            ShapeKind::Cube => "unit cube centred at the origin: three sharp edges at each corner",
            ShapeKind::Box => "1.0 x 0.7 x 0.5 box: unequal sides, three sharp edges per corner",
            ShapeKind::Pyramid => {
                "square pyramid (base 1 x 1, height 0.8): four edges meeting at the apex"
            }
            ShapeKind::Octahedron => "regular octahedron |x|+|y|+|z| <= 0.5: four edges per corner",
            ShapeKind::Cylinder => {
                "cylinder of radius 0.5 and height 1 with flat caps: circular sharp edges"
            }
            ShapeKind::Cone => {
                "cone of base radius 0.5 and height 1: a circular sharp edge and an apex"
            }
            ShapeKind::Fandisk => {
                "fandisk-like CAD part: planar, cylindrical and conical faces, convex and concave \
                 sharp edges, corners where three creases meet"
            }
            ShapeKind::Blend => {
                "the box with every edge rounded by a fillet (radius 0.04 by default): the smooth \
                 counterpart of box"
            }
            ShapeKind::ThinFace => {
                "the box with one edge cut by a 45-degree chamfer face 0.02 wide, narrower than \
                 three sampling steps at resolution 64"
            }
            ShapeKind::TorusBox => {
                "the box with a cylindrical through-hole of radius 0.15 (genus 1)"
            }
            ShapeKind::Sphere => "sphere of radius 0.5: smooth everywhere",
        }
    }

    /// Genus of the shape's surface.
    pub fn genus(self) -> u32 {
        match self {
            ShapeKind::TorusBox => 1,
            _ => 0,
        }
    }

    /// True when the surface has sharp edges (every shape but blend and sphere).
    pub fn has_sharp_edges(self) -> bool {
        !matches!(self, ShapeKind::Blend | ShapeKind::Sphere)
    }
}

impl fmt::Display for ShapeKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ShapeKind {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self, Error> {
        ShapeKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| Error::UnknownShape {
                name: s.to_string(),
                known: ShapeKind::ALL.map(ShapeKind::name).join(", "),
            })
    }
}

/// Parameters of a shape. Build with [`ShapeParams::default`] and the `with_` methods (the
/// struct may grow).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct ShapeParams {
    /// Fillet radius of `blend` (default 0.04; must be > 0 and < 0.25, half the box's smallest
    /// side). Other shapes ignore it.
    pub radius: Option<f64>,
    /// Rotation applied to the shape about the origin before anything else, so that creases
    /// are not aligned with a sampling grid. Normalised by [`Shape::new`].
    pub rotation: DQuat,
}

impl Default for ShapeParams {
    fn default() -> Self {
        ShapeParams {
            radius: None,
            rotation: DQuat::IDENTITY,
        }
    }
}

impl ShapeParams {
    /// Sets the blend fillet radius.
    pub fn with_radius(mut self, radius: f64) -> Self {
        self.radius = Some(radius);
        self
    }

    /// Sets the rotation.
    pub fn with_rotation(mut self, rotation: DQuat) -> Self {
        self.rotation = rotation;
        self
    }
}

/// The exact description each SDF is evaluated from.
#[derive(Clone, Debug)]
enum Geometry {
    Box(DVec3),
    Convex(sdf::ConvexSdf),
    Cylinder { r: f64, hh: f64 },
    Revolved(sdf::Revolved),
    Sphere(f64),
    RoundBox { half: DVec3, r: f64 },
    TorusBox { half: DVec3, r: f64 },
    Fandisk(Box<fandisk::Fandisk>),
}

impl Geometry {
    #[inline]
    fn sdf(&self, p: DVec3) -> f64 {
        match self {
            Geometry::Box(h) => sdf::sd_box(p, *h),
            Geometry::Convex(c) => c.sdf(p),
            Geometry::Cylinder { r, hh } => {
                let rho = glam::DVec2::new(p.x, p.z).length();
                sdf::sd_extrude(rho - r, p.y, *hh)
            }
            Geometry::Revolved(rev) => rev.sdf(glam::DVec2::new(p.x, p.z).length(), p.y),
            Geometry::Sphere(r) => p.length() - r,
            Geometry::RoundBox { half, r } => sdf::sd_round_box(p, *half, *r),
            Geometry::TorusBox { half, r } => {
                sdf::sd_box(p, *half).max(r - glam::DVec2::new(p.x, p.y).length())
            }
            Geometry::Fandisk(f) => f.sdf(p),
        }
    }
}

/// What each family's builder returns (in the shape's own frame).
struct Built {
    geometry: Geometry,
    mesh: Mesh,
    tessellation_error: f64,
    volume: f64,
}

/// A shape: its exact SDF and its truth mesh, in the (possibly rotated) world frame.
#[derive(Clone, Debug)]
pub struct Shape {
    kind: ShapeKind,
    params: ShapeParams,
    geometry: Geometry,
    /// World -> shape frame; `None` for the identity (keeps unrotated evaluation bit-exact).
    inverse: Option<DQuat>,
    truth: Mesh,
    tessellation_error: f64,
    volume: f64,
    bounds: Aabb,
}

impl Shape {
    /// Builds the shape (including its truth mesh, a few milliseconds at most).
    ///
    /// Fails on a zero or non-finite rotation and, for `blend`, on a fillet radius that is not
    /// in `(0, 0.25)`.
    pub fn new(kind: ShapeKind, params: &ShapeParams) -> Result<Shape, Error> {
        let q = params.rotation;
        if !q.is_finite() || q.length() < 1e-12 {
            return Err(Error::BadRotation(q));
        }
        let q = q.normalize();
        let mut params = params.clone();
        params.rotation = q;
        let rotated = q != DQuat::IDENTITY && q != -DQuat::IDENTITY;

        // Design tolerance from the unrotated bounding box diagonal.
        let tol_for = |half: DVec3| 0.8 * TESSELLATION_TOLERANCE * (half * 2.0).length();
        let built = match kind {
            ShapeKind::Cube => polyhedral(polyhedra::cuboid(DVec3::splat(0.5)), true, 1.0),
            ShapeKind::Box => {
                let size = BOX_HALF * 2.0;
                polyhedral(polyhedra::cuboid(BOX_HALF), true, size.x * size.y * size.z)
            }
            ShapeKind::Pyramid => polyhedral(polyhedra::pyramid(0.5, 0.8), false, 0.8 / 3.0),
            ShapeKind::Octahedron => {
                polyhedral(polyhedra::octahedron(0.5), false, 4.0 / 3.0 * 0.125)
            }
            ShapeKind::ThinFace => {
                let size = BOX_HALF * 2.0;
                // The chamfer removes a prism with a right isosceles triangle of legs c.
                let c = THIN_FACE_WIDTH / std::f64::consts::SQRT_2;
                polyhedral(
                    polyhedra::chamfered_box(BOX_HALF, THIN_FACE_WIDTH),
                    false,
                    size.x * size.y * size.z - size.x * c * c / 2.0,
                )
            }
            ShapeKind::Cylinder => revolved::cylinder(0.5, 0.5, tol_for(DVec3::splat(0.5))),
            ShapeKind::Cone => revolved::cone(0.5, 1.0, tol_for(DVec3::splat(0.5))),
            ShapeKind::Sphere => revolved::sphere(0.5, tol_for(DVec3::splat(0.5))),
            ShapeKind::TorusBox => torus_box::torus_box(BOX_HALF, HOLE_RADIUS, tol_for(BOX_HALF)),
            ShapeKind::Blend => {
                let r = params.radius.unwrap_or(DEFAULT_BLEND_RADIUS);
                let max = BOX_HALF.min_element();
                if !(r > 0.0 && r < max) {
                    return Err(Error::BadRadius { radius: r, max });
                }
                blend::rounded_box(BOX_HALF, r, tol_for(BOX_HALF))
            }
            ShapeKind::Fandisk => {
                fandisk::Fandisk::new().build(tol_for(DVec3::new(0.8, 0.35, 0.35)))
            }
        };
        let mut truth = built.mesh;
        if rotated {
            for p in &mut truth.positions {
                *p = q * *p;
            }
        }
        let mut bounds = truth.bounding_box();
        bounds.min -= DVec3::splat(built.tessellation_error);
        bounds.max += DVec3::splat(built.tessellation_error);
        Ok(Shape {
            kind,
            params,
            geometry: built.geometry,
            inverse: rotated.then(|| q.inverse()),
            truth,
            tessellation_error: built.tessellation_error,
            volume: built.volume,
            bounds,
        })
    }

    /// The shape's kind.
    pub fn kind(&self) -> ShapeKind {
        self.kind
    }

    /// The parameters it was built with (rotation normalised).
    pub fn params(&self) -> &ShapeParams {
        &self.params
    }

    /// Signed distance (negative inside) at `p`, in the rotated world frame. See the module
    /// documentation for which shapes are exact where; all are 1-Lipschitz.
    #[inline]
    pub fn sdf(&self, p: DVec3) -> f64 {
        match self.inverse {
            Some(inv) => self.geometry.sdf(inv * p),
            None => self.geometry.sdf(p),
        }
    }

    /// The truth mesh (closed, manifold, outward counter-clockwise), in the rotated frame.
    pub fn truth_mesh(&self) -> Mesh {
        self.truth.clone()
    }

    /// The truth mesh without copying it.
    pub fn truth_mesh_ref(&self) -> &Mesh {
        &self.truth
    }

    /// An axis-aligned box containing the true surface: the truth mesh's box grown by the
    /// tessellation error (exact for the polyhedra).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Diagonal of [`Shape::bounds`].
    pub fn diagonal(&self) -> f64 {
        self.bounds.diagonal()
    }

    /// Genus of the surface.
    pub fn genus(&self) -> u32 {
        self.kind.genus()
    }

    /// Upper bound of the distance between the truth mesh and the true surface, both ways
    /// (absolute; 0 for the polyhedra, under [`TESSELLATION_TOLERANCE`] times the diagonal for
    /// the others).
    pub fn tessellation_error(&self) -> f64 {
        self.tessellation_error
    }

    /// The exact volume enclosed by the true surface.
    pub fn volume(&self) -> f64 {
        self.volume
    }
}

fn polyhedral(p: polyhedra::Polyhedron, is_box: bool, volume: f64) -> Built {
    let mesh = p.mesh();
    let geometry = if is_box {
        let h = p.vertices.iter().fold(DVec3::ZERO, |m, v| m.max(v.abs()));
        Geometry::Box(h)
    } else {
        Geometry::Convex(p.sdf())
    };
    Built {
        geometry,
        mesh,
        tessellation_error: 0.0,
        volume,
    }
}
