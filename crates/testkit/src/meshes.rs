//! Test meshes built in code: an octahedron, subdivided icosahedra, torus grids, open grids,
//! unions, punched holes and deterministic relabelings.

use whet_mesh::{DVec3, Mesh};

/// The regular octahedron with vertices at ±x, ±y, ±z (outward orientation): six valence-4
/// vertices whose neighbours average to the origin.
pub fn octahedron() -> Mesh {
    Mesh::new(
        vec![
            DVec3::X,
            DVec3::Y,
            -DVec3::X,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ],
        vec![
            [0, 1, 4],
            [1, 2, 4],
            [2, 3, 4],
            [3, 0, 4],
            [1, 0, 5],
            [2, 1, 5],
            [3, 2, 5],
            [0, 3, 5],
        ],
    )
}

/// Icosahedron subdivided `levels` times (1-to-4), projected on the unit sphere.
pub fn icosphere(levels: u32) -> Mesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut p: Vec<DVec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut nf = Vec::with_capacity(f.len() * 4);
        let mut midpoint = |a: u32, b: u32, p: &mut Vec<DVec3>| -> u32 {
            let key = (a.min(b), a.max(b));
            *mid.entry(key).or_insert_with(|| {
                p.push(((p[a as usize] + p[b as usize]) * 0.5).normalize());
                (p.len() - 1) as u32
            })
        };
        for &[a, b, c] in &f {
            let ab = midpoint(a, b, &mut p);
            let bc = midpoint(b, c, &mut p);
            let ca = midpoint(c, a, &mut p);
            nf.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = nf;
    }
    Mesh::new(p, f)
}

/// Closed torus grid of `n x m` quads (all vertices valence 6).
pub fn torus(n: u32, m: u32) -> Mesh {
    let mut p = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let u = i as f64 / n as f64 * std::f64::consts::TAU;
            let v = j as f64 / m as f64 * std::f64::consts::TAU;
            let r = 2.0 + v.cos();
            p.push(DVec3::new(r * u.cos(), r * u.sin(), v.sin()));
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + (j % m);
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..m {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh::new(p, t)
}

/// A shallow cone of `spokes` spokes and `rings` rings of `spokes` vertices around one
/// centre of valence `spokes` (one boundary loop): the heights of ring `j` are `0.1 j`,
/// jittered by 1-2 % from spoke to spoke so that the fan's triangles are not all coplanar.
/// With thousands of spokes, it is the vertex of very high valence that tests of bounded
/// work need.
pub fn hub_disk(spokes: u32, rings: u32) -> Mesh {
    let mut p = vec![DVec3::ZERO];
    for j in 1..=rings {
        for i in 0..spokes {
            let a = std::f64::consts::TAU * i as f64 / spokes as f64;
            let z = 0.1 * j as f64 * (1.0 + 0.01 * (i % 3) as f64);
            p.push(DVec3::new(j as f64 * a.cos(), j as f64 * a.sin(), z));
        }
    }
    let at = |j: u32, i: u32| 1 + (j - 1) * spokes + i % spokes;
    let mut t = Vec::new();
    for i in 0..spokes {
        t.push([0, at(1, i), at(1, i + 1)]);
        for j in 1..rings {
            t.push([at(j, i), at(j + 1, i), at(j + 1, i + 1)]);
            t.push([at(j, i), at(j + 1, i + 1), at(j, i + 1)]);
        }
    }
    Mesh::new(p, t)
}

/// Open `n x m` grid in the xy plane (one boundary loop).
pub fn grid(n: u32, m: u32) -> Mesh {
    let mut p = Vec::new();
    for i in 0..=n {
        for j in 0..=m {
            p.push(DVec3::new(i as f64, j as f64, 0.0));
        }
    }
    let id = |i: u32, j: u32| i * (m + 1) + j;
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..m {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh::new(p, t)
}

/// Appends `b` to `a` as another component, shifted along x.
pub fn union(mut a: Mesh, b: &Mesh, shift: f64) -> Mesh {
    let off = a.positions.len() as u32;
    a.positions
        .extend(b.positions.iter().map(|p| *p + DVec3::X * shift));
    a.triangles.extend(
        b.triangles
            .iter()
            .map(|t| [t[0] + off, t[1] + off, t[2] + off]),
    );
    a
}

/// Removes the triangles whose index satisfies `drop`, then cuts what became non-manifold
/// (holes touching at a vertex), so the result is a valid mesh with holes.
pub fn punch(mesh: &Mesh, drop: impl Fn(usize) -> bool) -> Mesh {
    let mut m = Mesh::new(
        mesh.positions.clone(),
        mesh.triangles
            .iter()
            .enumerate()
            .filter(|(i, _)| !drop(*i))
            .map(|(_, t)| *t)
            .collect(),
    );
    m.make_manifold();
    m
}

/// Relabels vertices and triangles with a deterministic pseudo-random permutation and
/// rotates each triangle's corners.
pub fn shuffle(mesh: &Mesh, seed: u64) -> Mesh {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut rnd = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let nv = mesh.positions.len();
    let mut perm: Vec<u32> = (0..nv as u32).collect();
    for i in (1..nv).rev() {
        perm.swap(i, (rnd() % (i as u64 + 1)) as usize);
    }
    let mut positions = vec![DVec3::ZERO; nv];
    for (old, &new) in perm.iter().enumerate() {
        positions[new as usize] = mesh.positions[old];
    }
    let mut tris: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .map(|t| {
            let r = (rnd() % 3) as usize;
            let t = [t[r], t[(r + 1) % 3], t[(r + 2) % 3]];
            t.map(|v| perm[v as usize])
        })
        .collect();
    for i in (1..tris.len()).rev() {
        tris.swap(i, (rnd() % (i as u64 + 1)) as usize);
    }
    Mesh::new(positions, tris)
}
