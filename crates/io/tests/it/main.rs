//! Integration tests of whet-io: one binary, one module per concern.

mod common;
mod errors;
mod fixtures;
mod fuzz;
mod roundtrip;
mod samples;
