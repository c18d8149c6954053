//! Exact-mode round trips and sizes.
#![allow(clippy::unwrap_used)] // a panic is a test failure

mod sizes;
