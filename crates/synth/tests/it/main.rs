//! Integration tests of whet-synth: truth meshes, marching cubes, accuracy, creases, noise.

// Helpers outside #[test] functions unwrap too: a panic there is a test failure.
#![allow(clippy::unwrap_used)]

mod accuracy;
mod common;
mod creases;
mod marching;
mod noise;
mod shapes;
