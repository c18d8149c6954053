//! whet-metro integration tests: agreement with MeshLab's Hausdorff filter on the reference
//! pairs, and the measure's properties (exactness on known offsets, determinism, thread
//! independence, error handling, JSON).

mod common;
mod properties;
mod reference;
