//! Measurement behind swing geometry kinds 7 and 8: what the CLERS labels of a retiling
//! cost when a forward decoder codes them with the geometry it has already rebuilt as
//! context (open wedges at the gate ends, their valences so far, the predicted tip's
//! distance to the front neighbours, whether the front is a loop of three), under count
//! estimates and under the stream's fixed-rate bit models, against the bytes of the
//! reverse-order Edgebreaker coder (kinds 0 to 6).
//!
//! ```text
//! cargo run --release -p whet-swing --example swing_labelctx -- L/diag mesh.off...
//! ```
#![allow(clippy::unwrap_used)] // a measurement tool
use std::collections::HashMap;
use whet_codec::SwingParams;
use whet_edgebreaker::{traverse, Clers, Step};
use whet_mesh::{CornerId, CornerTable, DVec3};
use whet_swing::{retile, RetileTuning};

/// Adaptive count-based code length of 5-symbol labels per context (KT-like estimator).
#[derive(Default)]
struct Adaptive {
    counts: HashMap<u64, [f64; 5]>,
    bits: f64,
}
impl Adaptive {
    fn code(&mut self, ctx: u64, s: usize) {
        let c = self.counts.entry(ctx).or_insert([0.4; 5]);
        let tot: f64 = c.iter().sum();
        self.bits -= (c[s] / tot).log2();
        c[s] += 1.0;
    }
}

fn angle(p: DVec3, q: DVec3, r: DVec3) -> f64 {
    let (u, v) = (q - p, r - p);
    u.angle_between(v)
}

/// The front neighbour of `x` on the far side of its built fan, starting from the built
/// triangle of corner `cx` (at `x`) entered through the edge `x - from`.
fn front_neighbour(t: &CornerTable, built: &[bool], mut cx: CornerId, mut from: u32) -> u32 {
    for _ in 0..64 {
        let (n, p) = (t.next(cx), t.prev(cx));
        let (vn, vp) = (t.vertex(n).0, t.vertex(p).0);
        // Cross the edge x - other, where other is not `from`; the corner facing it is the
        // one at `from`.
        let (other, facing) = if vn == from { (vp, n) } else { (vn, p) };
        let o = t.opposite(facing).unwrap();
        let tri = o.face().index();
        if !built[tri] {
            return other;
        }
        // The corner of that triangle at x.
        let x = t.vertex(cx);
        let mut c = o;
        for _ in 0..3 {
            if t.vertex(c) == x {
                break;
            }
            c = t.next(c);
        }
        cx = c;
        from = other;
    }
    u32::MAX
}

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let f: f64 = a[0].parse().unwrap();
    for name in a[1..].iter() {
        let mesh = whet_io::read_path(&whet_testkit::shared_fixture(name), None).unwrap();
        let params = SwingParams::new(f * mesh.diagonal(), 6, &mesh.bounding_box(), 20).unwrap();
        let r = retile(&mesh, &params, &RetileTuning::DEFAULT).unwrap();
        let enc = whet_edgebreaker::encode_connectivity(&r.mesh.triangles, r.mesh.positions.len())
            .unwrap();
        let conn = &enc.connectivity;
        let t = &conn.table;
        let pos = &r.mesh.positions;
        let nv = t.vertex_count();
        let mut built = vec![false; t.triangle_count()];
        let mut sum = vec![0.0f64; nv];
        let mut k = vec![0u32; nv];
        let mut acc = vec![DVec3::ZERO; nv];
        let add = |c: CornerId,
                   built: &mut Vec<bool>,
                   sum: &mut Vec<f64>,
                   k: &mut Vec<u32>,
                   acc: &mut Vec<DVec3>| {
            built[c.face().index()] = true;
            let vs = [c, t.next(c), t.prev(c)].map(|c| t.vertex(c).index());
            let n = (pos[vs[1]] - pos[vs[0]]).cross(pos[vs[2]] - pos[vs[0]]);
            for v in vs {
                acc[v] += n;
            }
            for i in 0..3 {
                let (p, q, s) = (pos[vs[i]], pos[vs[(i + 1) % 3]], pos[vs[(i + 2) % 3]]);
                sum[vs[i]] += angle(p, q, s);
                k[vs[i]] += 1;
            }
        };
        let mut schemes: Vec<(&str, Adaptive)> = [
            "order0",
            "prev",
            "loop3",
            "wedges",
            "wedges+val",
            "snap",
            "full+prev",
            "w5v3s4",
            "w8v4s3",
            "w5v3s4p",
        ]
        .into_iter()
        .map(|n| (n, Adaptive::default()))
        .collect();
        let mut prev = 0usize;
        // The binary decomposition with the stream's own adaptive bit models.
        let mut cc = whet_bits::CostCounter::new();
        let mut m_close = vec![whet_bits::BitModel::new(); 7200];
        let mut m_e = [whet_bits::BitModel::new(); 2];
        let mut m_s = [whet_bits::BitModel::new(); 16];
        let mut m_rl = vec![whet_bits::BitModel::new(); 400];
        use whet_bits::BitSink;
        let mut hist = [0usize; 5];
        traverse(t, Some(&conn.starts), |s| match s {
            Step::Start { corner } => add(corner, &mut built, &mut sum, &mut k, &mut acc),
            Step::Triangle { tip, label, .. } => {
                let o = t.opposite(tip).unwrap();
                let (x, y) = (t.vertex(t.next(tip)).0, t.vertex(t.prev(tip)).0);
                // Corners of the parent at x and y.
                let mut cx = o;
                while t.vertex(cx).0 != x {
                    cx = t.next(cx);
                }
                let mut cy = o;
                while t.vertex(cy).0 != y {
                    cy = t.next(cy);
                }
                let xn = front_neighbour(t, &built, cx, y);
                let yn = front_neighbour(t, &built, cy, x);
                let loop3 = xn == yn;
                let bin = |v: usize| {
                    let open = std::f64::consts::TAU - sum[v];
                    let deg = open.to_degrees();
                    // Bins around the retiler's closing thresholds (35, 80, 125 degrees).
                    [30.0, 45.0, 70.0, 90.0, 110.0, 130.0, 160.0]
                        .iter()
                        .filter(|&&b| deg > b)
                        .count() as u64
                };
                let val = |v: usize| (k[v] + 1).clamp(4, 7) as u64 - 4;
                let (bx, by) = (bin(x as usize), bin(y as usize));
                let (vx, vy) = (val(x as usize), val(y as usize));
                let c = t.vertex(o).index();
                let fr = params.frame(pos[x as usize], pos[y as usize], pos[c]);
                let snap = |w: u32| -> u64 {
                    let Some(fr) = fr else { return 5 };
                    let q = whet_codec::swing::predict_swing(
                        &fr,
                        acc[x as usize] + acc[y as usize],
                        &params.angles,
                    );
                    let tp = fr.tip(&params.angles, q);
                    let d = tp.distance(pos[w as usize]) / params.edge_length;
                    [0.3, 0.5, 0.7, 0.9, 1.2].iter().filter(|&&b| d > b).count() as u64
                };
                let (sx, sy) = (snap(xn), snap(yn));
                let l = label as usize;
                let b5 = |b: u64| [0, 0, 1, 2, 3, 4, 4, 4][b as usize];
                let s4 = |s: u64| s.min(3);
                let v3 = |v: u64| v.min(2);
                let side = |b: u64, v: u64, s: u64| (b5(b) * 3 + v3(v)) * 4 + s4(s);
                let sides = side(bx, vx, sx) * 60 + side(by, vy, sy);
                let side8 = |b: u64, v: u64, s: u64| (b * 4 + v) * 3 + s.min(2);
                let sides8 = side8(bx, vx, sx) * 96 + side8(by, vy, sy);
                hist[l] += 1;
                let ctxs = [
                    0,
                    prev as u64,
                    loop3 as u64,
                    (bx * 8 + by) * 2 + loop3 as u64,
                    ((bx * 8 + by) * 2 + loop3 as u64) * 16 + vx * 4 + vy,
                    (sx * 6 + sy) * 2 + loop3 as u64,
                    (((bx * 8 + by) * 2 + loop3 as u64) * 16 + vx * 4 + vy) * 5 + prev as u64,
                    sides * 2 + loop3 as u64,
                    sides8 * 2 + loop3 as u64,
                    (sides * 2 + loop3 as u64) * 5 + prev as u64,
                ];
                {
                    let closing = label != Clers::C;
                    cc.encode_bit(&mut m_close[(sides * 2 + loop3 as u64) as usize], closing);
                    if closing {
                        let is_s = label == Clers::S;
                        if loop3 {
                            cc.encode_bit(&mut m_e[0], is_s);
                        } else {
                            cc.encode_bit(&mut m_s[(s4(sx) * 4 + s4(sy)) as usize], is_s);
                            if !is_s {
                                let ctx = (b5(bx) * 4 + s4(sx)) * 20 + b5(by) * 4 + s4(sy);
                                cc.encode_bit(&mut m_rl[ctx as usize], label == Clers::R);
                            }
                        }
                    }
                }
                for (i, (_, m)) in schemes.iter_mut().enumerate() {
                    m.code(ctxs[i], l);
                }
                prev = l;
                add(tip, &mut built, &mut sum, &mut k, &mut acc);
            }
        })
        .unwrap();
        let tris = t.triangle_count() as f64;
        print!(
            "{name} L={f}: T'={} CLERS {:?} shipped {:.3} bpt |",
            t.triangle_count(),
            hist,
            enc.bytes.len() as f64 * 8.0 / tris
        );
        for (n, m) in &schemes {
            print!(" {n} {:.3}", m.bits / tris);
        }
        println!(" binary {:.3}", cc.bits() / tris);
        let _ = Clers::C;
    }
}
