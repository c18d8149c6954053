//! whet-testkit owns the one way tests and benches find the public fixture meshes: the
//! `shared/` folder that sits beside the checkout (`../shared` from the workspace root, as on
//! developer machines and CI). Every lookup fails loudly, naming the path it tried, so a
//! missing folder is never mistaken for a passing test. Set `WHET_SHARED_DIR` to point
//! elsewhere. It also builds the small test meshes every crate's tests share ([`meshes`]). It is a
//! dev-dependency only.
//!
//! ```no_run
//! let fandisk = whet_testkit::shared_fixture("fandisk.off");
//! assert!(fandisk.ends_with("fixtures/fandisk.off"));
//! ```
#![forbid(unsafe_code)]

use std::path::{Path, PathBuf};

pub mod meshes;

/// A small deterministic generator for sweeps whose cases must not change between runs
/// (Knuth's MMIX linear congruential step; the top 53 bits as a float).
#[derive(Clone, Debug)]
pub struct Lcg(pub u64);

impl Lcg {
    /// The next number, uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The workspace root (the folder holding the root `Cargo.toml`).
pub fn workspace_root() -> PathBuf {
    // This crate lives at <root>/crates/testkit.
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap_or_else(|e| panic!("cannot resolve the workspace root: {e}"))
}

/// The shared folder (`WHET_SHARED_DIR`, else `<workspace root>/../shared`). Panics with the
/// path it tried when the folder is missing.
pub fn shared_dir() -> PathBuf {
    let dir = match std::env::var_os("WHET_SHARED_DIR") {
        Some(d) => PathBuf::from(d),
        None => workspace_root().join("../shared"),
    };
    if !dir.is_dir() {
        panic!(
            "shared folder not found at {} (the public fixtures live in ../shared beside the \
             checkout; set WHET_SHARED_DIR to override)",
            dir.display()
        );
    }
    dir
}

/// Path of a file in `shared/fixtures`; panics naming the path when it does not exist.
pub fn shared_fixture(name: &str) -> PathBuf {
    let p = shared_dir().join("fixtures").join(name);
    if !p.is_file() {
        panic!("shared fixture not found: {}", p.display());
    }
    p
}

/// Path of a file anywhere under `shared/` (e.g. `metro-reference.json`); panics when missing.
pub fn shared_file(relative: &str) -> PathBuf {
    let p = shared_dir().join(relative);
    if !p.exists() {
        panic!("shared file not found: {}", p.display());
    }
    p
}

/// The `.off` fixtures in `shared/fixtures`, sorted by name.
pub fn shared_off_fixtures() -> Vec<PathBuf> {
    let dir = shared_dir().join("fixtures");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "off"))
        .collect();
    v.sort();
    v
}

/// Resolves a path as written in shared JSON files ("../shared/fixtures/x.off", relative to
/// the checkout root) against the actual shared folder.
pub fn resolve_shared_reference(path: &str) -> PathBuf {
    match path.strip_prefix("../shared/") {
        Some(rest) => shared_file(rest),
        None => workspace_root().join(path),
    }
}

/// A scratch folder unique to one test (under the system's temporary folder, named after the
/// test and the process), emptied on creation and removed when the value is dropped — kept
/// when the test fails (the thread is panicking), or when `WHET_KEEP_SCRATCH` is set, so the
/// files can be looked at. Dereferences to its [`std::path::Path`].
pub fn scratch_dir(test_name: &str) -> ScratchDir {
    let dir = std::env::temp_dir().join(format!("whet-{}-{}", test_name, std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir)
        .unwrap_or_else(|e| panic!("cannot create {}: {e}", dir.display()));
    ScratchDir(dir)
}

/// See [`scratch_dir`].
#[derive(Debug)]
pub struct ScratchDir(PathBuf);

impl std::ops::Deref for ScratchDir {
    type Target = std::path::Path;
    fn deref(&self) -> &std::path::Path {
        &self.0
    }
}

impl AsRef<std::path::Path> for ScratchDir {
    fn as_ref(&self) -> &std::path::Path {
        &self.0
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        if !std::thread::panicking() && std::env::var_os("WHET_KEEP_SCRATCH").is_none() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}
