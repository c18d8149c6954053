//! Integration tests of whet-subdiv: subdivision on the synth shapes and fixtures, the fit,
//! and the stream payloads.
#![allow(clippy::unwrap_used)] // a panic is a test failure

mod fit;
mod stream;
mod subdivision;
