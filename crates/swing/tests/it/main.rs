//! Integration tests of whet-swing: retiling, bit-exact round trips, rate control.
#![allow(clippy::unwrap_used)] // a panic is a test failure

mod round_trip;
