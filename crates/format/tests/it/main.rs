//! Integration tests of whet-format: one binary, one module per concern.

mod common;
mod corruption;
mod fuzz;
mod roundtrip;
mod streaming;
mod versions;
