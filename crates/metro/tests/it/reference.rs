//! Agreement with MeshLab's Hausdorff filter (vcglib) on the pairs of
//! `shared/metro-reference.json`: max within 1 % and mean / RMS within 3 % (relative), both
//! directions and symmetric, at one million face samples per direction.

use std::path::Path;

use serde_json::Value;
use whet_metro::{metro, Figures, MetroOptions};

const REFERENCE_JSON: &str = "shared/metro-reference.json";

fn load_json() -> Value {
    let path = whet_testkit::shared_file("metro-reference.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!("cannot read the MeshLab reference figures at {REFERENCE_JSON}: {e} (the shared/ directory must sit beside the checkout)")
    });
    serde_json::from_str(&text)
        .unwrap_or_else(|e| panic!("{REFERENCE_JSON} is not valid JSON: {e}"))
}

/// Reads a fixture with whet-io (MeshLab's `NCOFF` files included).
fn read_mesh(path: &Path) -> Result<whet_mesh::Mesh, String> {
    whet_io::read_path(path, None).map_err(|e| e.to_string())
}

fn num(v: &Value, key: &str, ctx: &str) -> f64 {
    v.get(key)
        .and_then(Value::as_f64)
        .unwrap_or_else(|| panic!("{ctx}: missing number {key:?} in {REFERENCE_JSON}"))
}

/// Extra seeds run for a pair whose max disagrees at the first seed (see
/// [`max_within_seed_spread`]).
const SPREAD_SEEDS: u64 = 8;

struct Check {
    failures: Vec<String>,
    rows: Vec<String>,
    notes: Vec<String>,
}

impl Check {
    /// Compares one side; returns whether its max was outside the 1 % tolerance (mean and
    /// RMS failures are recorded directly).
    fn compare(&mut self, pair: &str, side: &str, ours: &Figures, theirs: &Value) -> bool {
        let ctx = format!("{pair}/{side}");
        let mut row = format!("{pair:<22} {side:<9}");
        let mut max_off = false;
        for (key, got, tol) in [
            ("max_pct", ours.max_pct, 0.01),
            ("mean_pct", ours.mean_pct, 0.03),
            ("rms_pct", ours.rms_pct, 0.03),
        ] {
            let want = num(theirs, key, &ctx);
            let rel = (got - want) / want;
            row.push_str(&format!(" {got:>11.6} {want:>11.6} {:>+7.2}%", rel * 100.0));
            if rel.is_nan() || rel.abs() > tol {
                if key == "max_pct" {
                    max_off = true;
                } else {
                    self.failures.push(format!(
                        "{ctx} {key}: ours {got} vs MeshLab {want} ({:+.2} %, allowed {} %)",
                        rel * 100.0,
                        tol * 100.0
                    ));
                }
            }
        }
        self.rows.push(row);
        max_off
    }
}

/// The max is the one figure that is a random variable on both sides: where it is reached in
/// the interior of a face (the distance function there often has a cone-shaped peak), it
/// depends on how close the nearest face sample happens to fall, and MeshLab's value comes
/// from one draw of its Monte Carlo face samples. (Where the max is reached at a vertex or
/// along an edge, our vcglib-style vertex and edge probes reproduce MeshLab's figure to
/// about six digits.) So when our max misses MeshLab's by more than 1 % at the first seed,
/// we ask the question that can be answered: is MeshLab's value within 1 % of the range our
/// max takes over a few more seeds? If it is not, our sampling misses something MeshLab
/// finds (or invents something it does not), and the test fails.
fn max_within_seed_spread(
    reference: &whet_mesh::Mesh,
    test: &whet_mesh::Mesh,
    first: &whet_metro::MetroReport,
    side: &str,
    want: f64,
) -> Result<String, String> {
    let pick = |r: &whet_metro::MetroReport| match side {
        "forward" => r.forward.figures.max_pct,
        "backward" => r.backward.figures.max_pct,
        _ => r.symmetric.max_pct,
    };
    let mut values = vec![pick(first)];
    for seed in 1..=SPREAD_SEEDS {
        let opts = MetroOptions::DEFAULT
            .with_samples(1_000_000)
            .with_seed(seed);
        let r = metro(reference, test, &opts).map_err(|e| e.to_string())?;
        values.push(pick(&r));
    }
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(0.0, f64::max);
    let text = format!(
        "max_pct over seeds 0..={SPREAD_SEEDS} spans [{lo:.6}, {hi:.6}]; MeshLab {want:.6}"
    );
    if lo * 0.99 <= want && want <= hi * 1.01 {
        Ok(text)
    } else {
        Err(text)
    }
}

#[test]
fn matches_meshlab_on_reference_pairs() {
    let json = load_json();
    let pairs = json["pairs"]
        .as_array()
        .unwrap_or_else(|| panic!("{REFERENCE_JSON} has no \"pairs\" array"));
    assert!(!pairs.is_empty(), "{REFERENCE_JSON} lists no pairs");
    let mut check = Check {
        failures: Vec::new(),
        rows: Vec::new(),
        notes: Vec::new(),
    };
    let opts = MetroOptions::DEFAULT.with_samples(1_000_000);
    for pair in pairs {
        let name = pair["name"].as_str().unwrap_or("?");
        let load = |key: &str| {
            let rel = pair[key]
                .as_str()
                .unwrap_or_else(|| panic!("{name}: no {key:?} path in {REFERENCE_JSON}"));
            let path = whet_testkit::resolve_shared_reference(rel);
            read_mesh(&path).unwrap_or_else(|e| {
                panic!("{name}: cannot read {key} mesh {}: {e}", path.display())
            })
        };
        let (reference, test) = (load("reference"), load("test"));
        let report =
            metro(&reference, &test, &opts).unwrap_or_else(|e| panic!("{name}: metro failed: {e}"));
        assert_eq!(report.samples, 1_000_000);
        for (side, ours, theirs) in [
            ("symmetric", &report.symmetric, pair),
            ("forward", &report.forward.figures, &pair["forward"]),
            ("backward", &report.backward.figures, &pair["backward"]),
        ] {
            if check.compare(name, side, ours, theirs) {
                let want = num(theirs, "max_pct", name);
                match max_within_seed_spread(&reference, &test, &report, side, want) {
                    Ok(text) => check.notes.push(format!(
                        "{name}/{side}: max off by more than 1 % at seed 0, but {text}"
                    )),
                    Err(text) => check.failures.push(format!(
                        "{name}/{side} max_pct: ours {} vs MeshLab {want}, and {text}",
                        ours.max_pct
                    )),
                }
            }
        }
    }
    println!(
        "{:<22} {:<9} {:>11} {:>11} {:>8} {:>11} {:>11} {:>8} {:>11} {:>11} {:>8}",
        "pair",
        "side",
        "max%",
        "meshlab",
        "diff",
        "mean%",
        "meshlab",
        "diff",
        "rms%",
        "meshlab",
        "diff"
    );
    for row in &check.rows {
        println!("{row}");
    }
    for note in &check.notes {
        println!("note: {note}");
    }
    assert!(
        check.failures.is_empty(),
        "disagreement with MeshLab:\n{}",
        check.failures.join("\n")
    );
}
