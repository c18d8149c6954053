//! whet-mesh owns the triangle mesh every other whet crate works on: the [`Mesh`] itself
//! (f64 positions, `u32` triangles) with its geometric measures, the typed indices
//! [`VertexId`] / [`CornerId`] / [`FaceId`], the [`CornerTable`] that the connectivity coder, the
//! retiler and the filters walk, the [`TopologyReport`] that names what is wrong with a mesh,
//! and [`Mesh::make_manifold`], which cuts non-manifold input into something they can use. It
//! depends on no other whet crate.
//!
//! ```
//! use whet_mesh::{CornerTable, Mesh};
//! use glam::DVec3;
//!
//! // A tetrahedron: closed, genus 0, every edge shared by two triangles.
//! let mesh = Mesh::new(
//!     vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
//!     vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
//! );
//! let report = mesh.topology_report();
//! assert!(report.manifold && report.problems.is_empty());
//! assert_eq!((report.edges, report.genus, report.boundary_loops), (6, Some(0), 0));
//! let table = CornerTable::new(&mesh).unwrap();
//! assert!(table.corners().all(|c| table.opposite(c).is_some()));
//! ```
#![forbid(unsafe_code)]

mod corner_table;
mod ids;
mod make_manifold;
mod mesh;
mod scratch;
mod topology;

pub use corner_table::{is_multiple_of_three, CornerTable, VertexCorners};
pub use ids::{CornerId, FaceId, VertexId};
pub use make_manifold::ManifoldRepair;
pub use mesh::{angle_between, edge_key, morton_spread, Aabb, EdgeLengthStats, Mesh};
pub use scratch::Scratch;
pub use topology::{MeshError, TopologyReport};

pub use glam::DVec3;
