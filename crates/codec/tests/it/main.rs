//! Exact-mode round trips, sizes against Draco, corruption and streaming.
#![allow(clippy::unwrap_used)] // a panic is a test failure

mod corruption;
mod roundtrip;
mod sizes;
