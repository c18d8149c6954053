//! Debugging aid: local thickness of a mesh at a point (ray casts along ± a direction).
#![allow(clippy::unwrap_used)]
use whet_mesh::DVec3;
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let mesh = whet_io::read_path(&whet_testkit::shared_fixture(&a[0]), None).unwrap();
    let v: Vec<f64> = a[1..7].iter().map(|x| x.parse().unwrap()).collect();
    let p = DVec3::new(v[0], v[1], v[2]);
    let n = DVec3::new(v[3], v[4], v[5]).normalize();
    let l = mesh.diagonal() * a.get(7).map_or(0.01, |x| x.parse().unwrap());
    // closest point
    let bvh = whet_metro::Bvh::new(&mesh);
    let c = bvh.closest_point(p);
    println!("closest dist {:.3}L", c.distance / l);
    let q = c.point;
    let fnorm = mesh.face_normal(c.triangle as usize);
    for dir in [fnorm, -fnorm, n, -n] {
        let mut hits = Vec::new();
        for t in 0..mesh.triangles.len() {
            let [p0, p1, p2] = mesh.triangle_positions(t);
            let e1 = p1 - p0;
            let e2 = p2 - p0;
            let h = dir.cross(e2);
            let det = e1.dot(h);
            if det.abs() < 1e-15 {
                continue;
            }
            let s = q - p0;
            let u = s.dot(h) / det;
            if !(0.0..=1.0).contains(&u) {
                continue;
            }
            let qq = s.cross(e1);
            let w = dir.dot(qq) / det;
            if w < 0.0 || u + w > 1.0 {
                continue;
            }
            let d = e2.dot(qq) / det;
            if d > 1e-9 {
                hits.push(d / l);
            }
        }
        hits.sort_by(|a, b| a.total_cmp(b));
        println!(
            "dir {:?}: hits at {:?} L",
            dir.to_array().map(|x| (x * 100.0).round() / 100.0),
            &hits[..hits.len().min(6)]
        );
    }
}
