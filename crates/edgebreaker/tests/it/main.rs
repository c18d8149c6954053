//! Round trips, compression figures and corruption handling of the connectivity coder.
#![allow(clippy::unwrap_used)] // a panic is a test failure

mod fixtures;
mod roundtrip;

pub use whet_testkit::meshes::*;
