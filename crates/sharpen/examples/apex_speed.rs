//! Times `whet_sharpen::restore_apexes` on a mesh file (best of seven runs, each on a fresh
//! copy) and prints its report: `cargo run --release -p whet-sharpen --example apex_speed --
//! <mesh>` (docs/results.md, "Apex restoration"). The mesh is typically a `whet decode
//! --sharpen` output, where the restoration runs.

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: apex_speed <mesh>");
        std::process::exit(2);
    };
    let mesh = match whet_io::read_path(std::path::Path::new(&path), None) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("{path}: {e}");
            std::process::exit(1);
        }
    };
    let mut best = f64::INFINITY;
    let mut report = whet_sharpen::ApexReport::default();
    for _ in 0..7 {
        let mut m = mesh.clone();
        let t = std::time::Instant::now();
        match whet_sharpen::restore_apexes(&mut m, &whet_sharpen::ApexOptions::DEFAULT) {
            Ok(r) => report = r,
            Err(e) => {
                eprintln!("{path}: {e}");
                std::process::exit(1);
            }
        }
        best = best.min(t.elapsed().as_secs_f64());
    }
    let n = mesh.triangles.len();
    println!(
        "{n} triangles: best {:.2} ms ({:.1} M triangles/s); {report:?}",
        best * 1e3,
        n as f64 / best / 1e6
    );
}
