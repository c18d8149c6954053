//! Debugging aid: renders the original mesh (grey) and a retiled mesh (wireframe, newest
//! triangles red) around a point, as a PNG.
//!
//! ```text
//! cargo run --release -p whet-swing --example swing_render -- original.off retiled.off \
//!     out.png cx cy cz dx dy dz size [highlight_last_n]
//! ```
#![allow(clippy::unwrap_used)] // a debugging tool

use whet_mesh::{DVec3, Mesh};

const W: usize = 900;

struct Img {
    rgb: Vec<[u8; 3]>,
    depth: Vec<f64>,
}

fn crc32(data: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in data {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                (c >> 1) ^ 0xEDB8_8320
            } else {
                c >> 1
            };
        }
    }
    !c
}

fn png(img: &Img, path: &str) {
    let mut raw = Vec::new();
    for y in 0..W {
        raw.push(0u8);
        for x in 0..W {
            raw.extend_from_slice(&img.rgb[y * W + x]);
        }
    }
    // zlib, stored blocks
    let mut z = vec![0x78, 0x01];
    for (i, chunk) in raw.chunks(65535).enumerate() {
        let last = (i + 1) * 65535 >= raw.len();
        z.push(last as u8);
        let n = chunk.len() as u16;
        z.extend_from_slice(&n.to_le_bytes());
        z.extend_from_slice(&(!n).to_le_bytes());
        z.extend_from_slice(chunk);
    }
    let (mut a, mut b) = (1u32, 0u32);
    for &x in &raw {
        a = (a + x as u32) % 65521;
        b = (b + a) % 65521;
    }
    z.extend_from_slice(&((b << 16) | a).to_be_bytes());
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut chunk = |tag: &[u8], data: &[u8]| {
        out.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let mut td = tag.to_vec();
        td.extend_from_slice(data);
        out.extend_from_slice(&td);
        out.extend_from_slice(&crc32(&td).to_be_bytes());
    };
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&(W as u32).to_be_bytes());
    ihdr.extend_from_slice(&(W as u32).to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    chunk(b"IHDR", &ihdr);
    chunk(b"IDAT", &z);
    chunk(b"IEND", &[]);
    std::fs::write(path, out).unwrap();
}

struct Cam {
    c: DVec3,
    right: DVec3,
    up: DVec3,
    fwd: DVec3,
    scale: f64,
}

impl Cam {
    fn project(&self, p: DVec3) -> (f64, f64, f64) {
        let d = p - self.c;
        (
            (d.dot(self.right) * self.scale + 0.5) * W as f64,
            (0.5 - d.dot(self.up) * self.scale) * W as f64,
            d.dot(self.fwd),
        )
    }
}

fn tri(img: &mut Img, cam: &Cam, p: [DVec3; 3], color: [u8; 3], bias: f64) {
    let q = p.map(|x| cam.project(x));
    let minx = q.iter().map(|v| v.0).fold(f64::MAX, f64::min).max(0.0) as usize;
    let maxx = (q
        .iter()
        .map(|v| v.0)
        .fold(f64::MIN, f64::max)
        .min(W as f64 - 1.0)) as isize;
    let miny = q.iter().map(|v| v.1).fold(f64::MAX, f64::min).max(0.0) as usize;
    let maxy = (q
        .iter()
        .map(|v| v.1)
        .fold(f64::MIN, f64::max)
        .min(W as f64 - 1.0)) as isize;
    let area = (q[1].0 - q[0].0) * (q[2].1 - q[0].1) - (q[2].0 - q[0].0) * (q[1].1 - q[0].1);
    if area.abs() < 1e-12 || maxx < 0 || maxy < 0 {
        return;
    }
    for y in miny..=maxy as usize {
        for x in minx..=maxx as usize {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            let w0 = ((q[1].0 - px) * (q[2].1 - py) - (q[2].0 - px) * (q[1].1 - py)) / area;
            let w1 = ((q[2].0 - px) * (q[0].1 - py) - (q[0].0 - px) * (q[2].1 - py)) / area;
            let w2 = 1.0 - w0 - w1;
            if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                continue;
            }
            let z = w0 * q[0].2 + w1 * q[1].2 + w2 * q[2].2 - bias;
            let i = y * W + x;
            if z < img.depth[i] {
                img.depth[i] = z;
                img.rgb[i] = color;
            }
        }
    }
}

fn line(img: &mut Img, cam: &Cam, a: DVec3, b: DVec3, color: [u8; 3], bias: f64) {
    let (x0, y0, z0) = cam.project(a);
    let (x1, y1, z1) = cam.project(b);
    let n = ((x1 - x0).abs().max((y1 - y0).abs()) as usize).clamp(1, 4000);
    for k in 0..=n {
        let t = k as f64 / n as f64;
        let (x, y, z) = (
            x0 + (x1 - x0) * t,
            y0 + (y1 - y0) * t,
            z0 + (z1 - z0) * t - bias,
        );
        if x < 0.0 || y < 0.0 || x >= W as f64 || y >= W as f64 {
            continue;
        }
        let i = y as usize * W + x as usize;
        if z < img.depth[i] + bias * 0.5 {
            img.rgb[i] = color;
        }
    }
}

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let path = |s: &str| {
        if s.contains('/') {
            std::path::PathBuf::from(s)
        } else {
            whet_testkit::shared_fixture(s)
        }
    };
    let m: Mesh = whet_io::read_path(&path(&a[0]), None).unwrap();
    let r: Mesh = whet_io::read_path(&path(&a[1]), None).unwrap();
    let v: Vec<f64> = a[3..10].iter().map(|x| x.parse().unwrap()).collect();
    let center = DVec3::new(v[0], v[1], v[2]);
    let fwd = -DVec3::new(v[3], v[4], v[5]).normalize();
    let size = v[6];
    let last: usize = a.get(10).map_or(0, |x| x.parse().unwrap());
    let right = fwd.any_orthonormal_vector();
    let up = right.cross(fwd);
    let cam = Cam {
        c: center,
        right,
        up,
        fwd,
        scale: 1.0 / size,
    };
    let mut img = Img {
        rgb: vec![[255, 255, 255]; W * W],
        depth: vec![f64::MAX; W * W],
    };
    let light = (-fwd + up * 0.5).normalize();
    for t in 0..m.triangles.len() {
        let n = m.face_normal(t);
        let s = (n.dot(light).abs() * 0.6 + 0.3).min(1.0);
        let g = (200.0 * s) as u8;
        tri(&mut img, &cam, m.triangle_positions(t), [g, g, g], 0.0);
    }
    let bias = size * 0.004;
    let nt = r.triangles.len();
    for t in 0..nt {
        let n = r.face_normal(t);
        let s = (n.dot(light).abs() * 0.5 + 0.4).min(1.0);
        let recent = last > 0 && t + last >= nt;
        let col = if recent {
            [(255.0 * s) as u8, (80.0 * s) as u8, (60.0 * s) as u8]
        } else {
            [(120.0 * s) as u8, (170.0 * s) as u8, (230.0 * s) as u8]
        };
        tri(&mut img, &cam, r.triangle_positions(t), col, bias);
    }
    for t in 0..nt {
        let p = r.triangle_positions(t);
        for i in 0..3 {
            line(
                &mut img,
                &cam,
                p[i],
                p[(i + 1) % 3],
                [20, 20, 20],
                bias * 1.5,
            );
        }
    }
    // Mark the centre.
    let (cx, cy, _) = cam.project(center);
    for d in -4i32..=4 {
        for (x, y) in [(cx as i32 + d, cy as i32), (cx as i32, cy as i32 + d)] {
            if x >= 0 && y >= 0 && (x as usize) < W && (y as usize) < W {
                img.rgb[y as usize * W + x as usize] = [0, 160, 0];
            }
        }
    }
    png(&img, &a[2]);
}
