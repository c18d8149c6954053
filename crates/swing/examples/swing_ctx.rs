//! Measurement: cost of the swing indices under several context schemes (bits per index),
//! among them order 0 (stream kinds 0 and 2) and the shipped fan-normal prediction (kinds 3
//! and 4), and that prediction's angle scaled by 1-2 (not shipped: docs/swing.md section 2).
//!
//! ```text
//! cargo run --release -p whet-swing --example swing_ctx -- x BITS L/diag mesh.off...
//! ```
#![allow(clippy::unwrap_used, clippy::type_complexity)] // a measurement tool
use whet_bits::{BitSink, BitTree, CostCounter};
use whet_codec::{SwingParams, VertexSource};
use whet_edgebreaker::{traverse, Clers, Step};
use whet_swing::{retile, RetileTuning};

fn zz(q: i32) -> u32 {
    ((q << 1) ^ (q >> 31)) as u32
}
fn bl(z: u32) -> usize {
    (32 - z.leading_zeros()) as usize
}

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let bits: u32 = a[1].parse().unwrap();
    let f: f64 = a[2].parse().unwrap();
    for name in a[3..].iter() {
        let mesh = whet_io::read_path(&whet_testkit::shared_fixture(name), None).unwrap();
        let params = SwingParams::new(f * mesh.diagonal(), bits, &mesh.bounding_box(), 20).unwrap();
        let r = retile(&mesh, &params, &RetileTuning::DEFAULT).unwrap();
        let enc = whet_edgebreaker::encode_connectivity(&r.mesh.triangles, r.mesh.positions.len())
            .unwrap();
        let conn = &enc.connectivity;
        let t = &conn.table;
        // Per traversal C: (q, parent q or None, prev label, prev q, grandparent q)
        let mut tri_q = vec![None; t.triangle_count()];
        let mut tri_parent = vec![usize::MAX; t.triangle_count()];
        let mut rows = Vec::new();
        let mut preds: Vec<i32> = Vec::new();
        // Unrounded angle of the fan-normal prediction (std atan2; a measurement only).
        let mut pred_theta: Vec<f64> = Vec::new();
        let mut acc = vec![whet_mesh::DVec3::ZERO; t.vertex_count()];
        let pos = &r.mesh.positions;
        let add_tri = |acc: &mut Vec<whet_mesh::DVec3>, c: whet_mesh::CornerId| {
            let vs = [t.vertex(c), t.vertex(t.next(c)), t.vertex(t.prev(c))];
            let [p0, p1, p2] = vs.map(|v| pos[v.index()]);
            let n = (p1 - p0).cross(p2 - p0);
            for v in vs {
                acc[v.index()] += n;
            }
        };
        let mut prev_label = Clers::C;
        let mut last_q = 0i32;
        traverse(t, Some(&conn.starts), |s| {
            if let Step::Start { corner } = s {
                add_tri(&mut acc, corner);
            }
            if let Step::Triangle { tip, label, .. } = s {
                let o = t.opposite(tip).unwrap();
                let pt = o.face().index();
                tri_parent[tip.face().index()] = pt;
                if label == Clers::C {
                    let v = t.vertex(tip);
                    let VertexSource::Swing(q) = r.mesh.sources[v.index()] else {
                        panic!()
                    };
                    let gp = tri_parent[pt];
                    let gq = if gp != usize::MAX { tri_q[gp] } else { None };
                    rows.push((q, tri_q[pt], prev_label, last_q, gq));
                    let (a, b, c) = (t.vertex(t.next(tip)), t.vertex(t.prev(tip)), t.vertex(o));
                    let fr = params
                        .frame(pos[a.index()], pos[b.index()], pos[c.index()])
                        .unwrap();
                    // The shipped prediction (kinds 3 and 4 of the stream).
                    let nn = acc[a.index()] + acc[b.index()];
                    preds.push(whet_codec::swing::predict_swing(&fr, nn, &params.angles));
                    let (mut x, mut y) = (fr.e2.dot(nn), -fr.e1.dot(nn));
                    if x < 0.0 {
                        x = -x;
                        y = -y;
                    }
                    pred_theta.push(y.atan2(x));
                    tri_q[tip.face().index()] = Some(q);
                    last_q = q;
                }
                prev_label = label;
                add_tri(&mut acc, tip);
            }
        })
        .unwrap();
        let n = rows.len() as f64;
        for (i, r) in rows.iter_mut().enumerate() {
            r.3 = preds[i];
        }
        let run = |ctx: &dyn Fn(&(i32, Option<i32>, Clers, i32, Option<i32>)) -> (usize, i32),
                   nctx: usize| {
            let mut trees: Vec<BitTree> = (0..nctx).map(|_| BitTree::new(bits)).collect();
            let mut c = CostCounter::new();
            let mask = (1u32 << bits) - 1;
            for row in &rows {
                let (k, pred) = ctx(row);
                let d = row.0 - pred;
                // wrap into range
                let half = 1i32 << (bits - 1);
                let d = ((d + half).rem_euclid(1 << bits)) - half;
                c.encode_tree(&mut trees[k], zz(d) & mask);
            }
            c.bits() / n
        };
        let o0 = run(&|_| (0, 0), 1);
        let pbucket = run(&|r| (r.1.map_or(0, |p| 1 + bl(zz(p)).min(7)), 0), 9);
        let pres = run(&|r| (r.1.map_or(0, |_| 1), r.1.unwrap_or(0)), 2);
        let pres_b = run(
            &|r| (r.1.map_or(0, |p| 1 + bl(zz(p)).min(7)), r.1.unwrap_or(0)),
            9,
        );
        let lastq = run(&|r| (1 + bl(zz(r.3)).min(7), 0), 9);
        let lastres = run(&|r| (0, r.3), 1);
        let normpred_b = run(&|r| (1 + bl(zz(r.3)).min(7), r.3), 9);
        // What the stream codes (kinds 3 and 4): the residual, one tree per bucket of the
        // prediction.
        let shipped = run(&|r| (bl(zz(r.3)).min(7), r.3), 8);
        // Count-based alternative: one 64-symbol frequency model per bucket, escape at 63.
        let inv = 1.0 / params.angles.step();
        let freq_models =
            |nctx: usize, ctxf: &dyn Fn(usize) -> usize, predf: &dyn Fn(usize) -> i32| {
                let mut ms: Vec<whet_bits::SymbolModel> =
                    (0..nctx).map(|_| whet_bits::SymbolModel::new(64)).collect();
                let mut esc = BitTree::new(bits);
                let mut c = CostCounter::new();
                let half = 1i32 << (bits - 1);
                for (i, row) in rows.iter().enumerate() {
                    let p = predf(i);
                    let d = ((row.0 - p + half).rem_euclid(1 << bits)) - half;
                    let z = zz(d) & ((1u32 << bits) - 1);
                    let m = &mut ms[ctxf(i)];
                    if z < 63 {
                        c.encode_symbol(m, z as usize);
                    } else {
                        c.encode_symbol(m, 63);
                        c.encode_tree(&mut esc, z);
                    }
                }
                c.bits() / n
            };
        let freq8 = freq_models(8, &|i| bl(zz(rows[i].3)).min(7), &|i| rows[i].3);
        let freq1 = freq_models(1, &|_| 0, &|i| rows[i].3);
        print!("{name}: bit trees {shipped:.3}  frequency models per bucket {freq8:.3}  one frequency model {freq1:.3}");
        let half = 1i32 << (bits - 1);
        for lam in [1.5, 1.75, 2.0] {
            let sp = |i: usize| ((lam * pred_theta[i] * inv).round() as i32).clamp(-half, half - 1);
            let f = freq_models(8, &|i| bl(zz(sp(i))).min(7), &sp);
            print!("  scaled x{lam} {f:.3}");
        }
        println!();
        let avg = run(
            &|r| {
                let p = match (r.1, r.4) {
                    (Some(a), Some(b)) => (a + b) / 2,
                    (Some(a), None) => a,
                    _ => r.3,
                };
                (r.1.map_or(0, |_| 1), p)
            },
            2,
        );
        let pb_label = run(
            &|r| {
                (
                    r.1.map_or(0, |p| 1 + bl(zz(p)).min(7)) * 5 + r.2 as usize,
                    0,
                )
            },
            45,
        );
        // Scaled predictions: the fan normal lags behind the tip (it averages the built
        // side), so the surface bends on by more than the angle it predicts.
        for lam in [1.0, 1.25, 1.5, 1.75, 2.0] {
            let mut trees: Vec<BitTree> = (0..8).map(|_| BitTree::new(bits)).collect();
            let mut c = CostCounter::new();
            let mask = (1u32 << bits) - 1;
            let half = 1i32 << (bits - 1);
            for (row, th) in rows.iter().zip(&pred_theta) {
                let p = ((lam * th * inv).round() as i32).clamp(-half, half - 1);
                let d = ((row.0 - p + half).rem_euclid(1 << bits)) - half;
                c.encode_tree(&mut trees[bl(zz(p)).min(7)], zz(d) & mask);
            }
            println!("{name}: scaled prediction x{lam}: {:.3} bits", c.bits() / n);
        }
        println!("{name} B={bits} f={f}: n={} order0 {o0:.3} parent-bucket {pbucket:.3} parent-resid {pres:.3} parent-resid+bucket {pres_b:.3} last-bucket {lastq:.3} NORMAL-PRED {lastres:.3} normpred+bucket {normpred_b:.3} SHIPPED {shipped:.3} ({:+.1} %) avg-pred {avg:.3} pbucket+label {pb_label:.3}", rows.len(), 100.0 * (shipped / o0 - 1.0));
    }
}
