//! Meshes, encodings and comparisons shared by the test modules.

use std::path::PathBuf;

use whet_io::{read, write, Format, PlyEncoding, StlEncoding, WriteOptions};
use whet_mesh::{DVec3, Mesh};

/// Every format and encoding the writers produce, with a name for messages.
pub fn encodings() -> Vec<(&'static str, Format, WriteOptions)> {
    let d = WriteOptions::DEFAULT;
    vec![
        ("off", Format::Off, d),
        ("obj", Format::Obj, d),
        ("ply ascii", Format::Ply, d.with_ply(PlyEncoding::Ascii)),
        (
            "ply le",
            Format::Ply,
            d.with_ply(PlyEncoding::BinaryLittleEndian),
        ),
        (
            "ply be",
            Format::Ply,
            d.with_ply(PlyEncoding::BinaryBigEndian),
        ),
        ("stl ascii", Format::Stl, d.with_stl(StlEncoding::Ascii)),
        ("stl binary", Format::Stl, d.with_stl(StlEncoding::Binary)),
    ]
}

/// True for the encodings that store f64 exactly.
pub fn exact(name: &str) -> bool {
    name != "stl binary"
}

/// True for the encodings that weld vertices (their order follows first appearance).
pub fn welds(format: Format) -> bool {
    format == Format::Stl
}

/// `mesh` written in memory.
pub fn bytes(mesh: &Mesh, format: Format, opts: &WriteOptions) -> Vec<u8> {
    let mut out = Vec::new();
    write(&mut out, mesh, format, opts).expect("write to memory");
    out
}

/// Writes then reads `mesh`.
pub fn round_trip(mesh: &Mesh, format: Format, opts: &WriteOptions) -> Mesh {
    let data = bytes(mesh, format, opts);
    read(&data[..], format).expect("read back what was written")
}

/// Coordinates as bit patterns, for exact comparisons (`-0.0` differs from `0.0`).
pub fn bits(mesh: &Mesh) -> Vec<[u64; 3]> {
    mesh.positions
        .iter()
        .map(|p| p.to_array().map(f64::to_bits))
        .collect()
}

/// Asserts the same triangles and bit-identical positions.
pub fn assert_identical(a: &Mesh, b: &Mesh, context: &str) {
    assert_eq!(
        a.positions.len(),
        b.positions.len(),
        "{context}: vertex count"
    );
    assert_eq!(a.triangles, b.triangles, "{context}: triangles");
    assert_eq!(bits(a), bits(b), "{context}: positions");
}

/// Asserts that `welded` (read back from STL) has the same counts as `original` and that each
/// triangle's corners sit at the original corners' coordinates, compared as f32 when `as_f32`.
pub fn assert_same_after_welding(original: &Mesh, welded: &Mesh, as_f32: bool, context: &str) {
    assert_eq!(
        welded.positions.len(),
        original.positions.len(),
        "{context}: vertex count"
    );
    assert_eq!(
        welded.triangles.len(),
        original.triangles.len(),
        "{context}: triangle count"
    );
    for (t, (a, b)) in original.triangles.iter().zip(&welded.triangles).enumerate() {
        for k in 0..3 {
            let p = original.positions[a[k] as usize];
            let q = welded.positions[b[k] as usize];
            if as_f32 {
                assert_eq!(
                    p.as_vec3(),
                    q.as_vec3(),
                    "{context}: triangle {t} corner {k}"
                );
            } else {
                assert_eq!(p, q, "{context}: triangle {t} corner {k}");
            }
        }
    }
}

/// A pseudo-random number generator (xorshift), so tests need no dependency for noise.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// A value in [-1, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// A height-field grid of `n` x `n` vertices with noisy f64 coordinates (`f32_exact` rounds
/// them to f32 values), whose vertices first appear in the triangles in index order.
pub fn grid(n: u32, f32_exact: bool, seed: u64) -> Mesh {
    let mut rng = Rng(seed | 1);
    let mut positions = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let mut p = DVec3::new(
                f64::from(i) + 0.3 * rng.unit(),
                f64::from(j) + 0.3 * rng.unit(),
                rng.unit() * 1e-3,
            );
            if f32_exact {
                p = p.as_vec3().as_dvec3();
            }
            positions.push(p);
        }
    }
    let mut triangles = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let v = j * n + i;
            triangles.push([v, v + 1, v + n + 1]);
            triangles.push([v, v + n + 1, v + n]);
        }
    }
    by_first_appearance(&Mesh::new(positions, triangles))
}

/// `mesh` with its vertices renumbered in order of first appearance in the triangles (the
/// order STL welding produces); unreferenced vertices follow in their old order.
pub fn by_first_appearance(mesh: &Mesh) -> Mesh {
    let mut new_index = vec![u32::MAX; mesh.positions.len()];
    let mut order = Vec::with_capacity(mesh.positions.len());
    for &v in mesh
        .triangles
        .iter()
        .flatten()
        .chain(&(0..mesh.positions.len() as u32).collect::<Vec<_>>())
    {
        if new_index[v as usize] == u32::MAX {
            new_index[v as usize] = order.len() as u32;
            order.push(v);
        }
    }
    Mesh::new(
        order.iter().map(|&v| mesh.positions[v as usize]).collect(),
        mesh.triangles
            .iter()
            .map(|t| t.map(|v| new_index[v as usize]))
            .collect(),
    )
}

/// A small mesh with awkward coordinates: signed zero, subnormal, huge, tiny, thirds.
pub fn awkward() -> Mesh {
    Mesh::new(
        vec![
            DVec3::new(0.0, -0.0, 5e-324),
            DVec3::new(1.0 / 3.0, -2.0 / 3.0, 1e-300),
            DVec3::new(1e300, -1e-7, 0.1),
            DVec3::new(123456789.98765432, f64::MIN_POSITIVE, -f64::MAX),
            DVec3::new(f64::MAX, 2.97683e-21, 1e16),
        ],
        vec![[0, 1, 2], [0, 2, 3], [3, 2, 1], [1, 4, 3], [4, 0, 2]],
    )
}

/// The shared fixtures folder (`shared/fixtures` beside the workspace).
pub fn fixtures_dir() -> PathBuf {
    whet_testkit::shared_dir().join("fixtures")
}

/// A path in the temporary folder unique to this process and `name`.
pub fn temp_path(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("whet-io-test-{}-{name}", std::process::id()))
}
