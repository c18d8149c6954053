//! The variational fit of seed 004 (section 4): control points `p` and edge sharpness `h` of
//! a semi-sharp Loop surface minimising `||L p||_{2,1} + lambda ||v - M(h) p||_{2,1}` over the
//! vertices `v` of the input, where `L` is the uniform Laplacian of the control mesh and
//! `M(h) p` are the closest points of the data on the `levels`-times subdivided surface
//! pushed to its limit (sharpening-extras B.5-B.6).
//!
//! Solver: seed 004's augmented Lagrangian (Algorithm 1) with `q = L p`, `z = v - M p`:
//!
//! ```text
//! for each outer iteration:
//!     foot points of the data on the current surface -> M (rows of barycentric
//!         combinations of the composed subdivision-and-limit matrix C(h))
//!     K times:
//!         p-step  (aq L^T L + az M^T M) p = aq L^T (q + lq/aq) + az M^T (v - z - lz/az)   [CG]
//!         h-step  min_h |M(h) p - (v - z - lz/az)|^2          [coordinate descent or PSO]
//!         q-step  q = shrink(L p - lq/aq, 1/aq)
//!         z-step  z = shrink(v - M p - lz/az, lambda/az)
//!     lq += aq (q - L p);  lz += az (z - (v - M p))
//! ```
//!
//! with `shrink(w, t) = max(0, 1 - t/|w|) w` per row, the paper's parameters
//! `lambda = alpha m lc / (n ld)`, `alpha = 100`, `aq = 1`, `az = 25` (`lc`, `ld` the mean edge
//! lengths of control and input, `m`, `n` their vertex counts). The shrinkage thresholds
//! carry units of length, so the fit works in coordinates scaled to a unit bounding-box
//! diagonal (the paper does not say which scale its parameters assume).
//!
//! The sharpness subproblem uses [`SharpnessSolver::CoordinateDescent`] by default (see
//! `sharpness_fit.rs` and the measurements in `docs/results.md`); the paper's particle swarm
//! is [`SharpnessSolver::ParticleSwarm`]. [`SharpnessMode`] selects the three surfaces of the
//! paper's Table 1: smooth Loop (`h = 0`), Hoppe's detected creases (`h` in {0, 1} from the
//! dihedral angles of the control mesh, fixed) and continuous sharpness.
//!
//! Not handled: changing the control connectivity during the fit (the paper's own stated
//! limitation), more semi-sharp levels than fitting levels.

use crate::denoise::bilateral_denoise;
use crate::loop_subdivision::Hierarchy;
use crate::qem::{simplify, SimplifyOptions};
use crate::sharpness::EdgeSharpness;
use crate::sharpness_fit::{pso, LocalEval};
use crate::sparse::{conjugate_gradient, Csr, Row};
use crate::topology::Topology;
use crate::Error;
use glam::DVec3;
use rayon::prelude::*;
use std::time::Instant;
use whet_mesh::{CornerTable, Mesh};
use whet_metro::Bvh;

/// Which sharpness the fit uses (the three columns of seed 004's Table 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum SharpnessMode {
    /// Every edge smooth: classical Loop subdivision.
    Smooth,
    /// Hoppe et al.: `h = 1` on control edges whose dihedral angle exceeds the crease angle,
    /// 0 elsewhere, kept fixed.
    Crease,
    /// Seed 004: `h` optimised with the control points, starting from the crease detection.
    Continuous,
}

/// Solver of the sharpness subproblem.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum SharpnessSolver {
    /// Exact coordinate descent over the quantized sharpness values (whet's default).
    CoordinateDescent,
    /// The paper's particle swarm optimisation.
    ParticleSwarm,
}

/// Options of [`fit`] and [`fit_control`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct FitOptions {
    /// Control vertices [`fit`] simplifies the input to.
    pub control_vertices: usize,
    /// Subdivision levels of the fitted surface (all semi-sharp; then the limit masks).
    pub levels: u32,
    /// Which sharpness to use.
    pub mode: SharpnessMode,
    /// How to solve for it.
    pub solver: SharpnessSolver,
    /// Crease angle of the simplification and of the initial sharpness (seed 004's theta_0).
    pub crease_angle_degrees: f64,
    /// The sharpness takes values `k / (2^bits - 1)` (what the codec transmits), 1..=8.
    pub sharpness_bits: u32,
    /// Outer iterations of the augmented Lagrangian (seed 004's max-iterations).
    pub iterations: u32,
    /// Sweeps over (p, h, q, z) per outer iteration (seed 004's K).
    pub inner_iterations: u32,
    /// Fidelity scale alpha of `lambda = alpha m lc / (n ld)`.
    pub alpha: f64,
    /// Penalty of `q = L p`.
    pub aq: f64,
    /// Penalty of `z = v - M p`.
    pub az: f64,
    /// Iterations of bilateral denoising before the simplification (0: none).
    pub denoise_iterations: u32,
    /// Weight of the reverse fidelity term (0: the paper's one-sided model). The paper
    /// measures the distance from the data to the surface only, so parts of the surface that
    /// no data point projects onto (beside a wrongly detected corner, say) are free to wander;
    /// whet adds `w |C_j p - y_j|^2` over the limit vertices `j`, `y_j` their closest input
    /// point, with `w = two_sided az n / n_fine`, as a plain least-squares term.
    pub two_sided: f64,
    /// Seed of the particle swarm.
    pub seed: u64,
}

impl FitOptions {
    /// 275 control vertices, 3 levels, continuous sharpness by coordinate descent over 3-bit
    /// values, 12 outer iterations, the paper's alpha = 100, aq = 1, az = 25, reverse term
    /// weight 2.
    pub const DEFAULT: FitOptions = FitOptions {
        control_vertices: 275,
        levels: 3,
        mode: SharpnessMode::Continuous,
        solver: SharpnessSolver::CoordinateDescent,
        crease_angle_degrees: 35.0,
        sharpness_bits: 3,
        iterations: 12,
        inner_iterations: 1,
        alpha: 100.0,
        aq: 1.0,
        az: 25.0,
        denoise_iterations: 0,
        two_sided: 2.0,
        seed: 0,
    };

    /// Sets the control vertex count.
    pub const fn with_control_vertices(mut self, n: usize) -> Self {
        self.control_vertices = n;
        self
    }

    /// Sets the levels.
    pub const fn with_levels(mut self, levels: u32) -> Self {
        self.levels = levels;
        self
    }

    /// Sets the sharpness mode.
    pub const fn with_mode(mut self, mode: SharpnessMode) -> Self {
        self.mode = mode;
        self
    }

    /// Sets the sharpness solver.
    pub const fn with_solver(mut self, solver: SharpnessSolver) -> Self {
        self.solver = solver;
        self
    }

    /// Sets the crease angle.
    pub const fn with_crease_angle(mut self, degrees: f64) -> Self {
        self.crease_angle_degrees = degrees;
        self
    }

    /// Sets the sharpness bits.
    pub const fn with_sharpness_bits(mut self, bits: u32) -> Self {
        self.sharpness_bits = bits;
        self
    }

    /// Sets the outer iterations.
    pub const fn with_iterations(mut self, n: u32) -> Self {
        self.iterations = n;
        self
    }

    /// Sets the denoising iterations.
    pub const fn with_denoise_iterations(mut self, n: u32) -> Self {
        self.denoise_iterations = n;
        self
    }

    /// Sets the weight of the reverse fidelity term.
    pub const fn with_two_sided(mut self, w: f64) -> Self {
        self.two_sided = w;
        self
    }

    /// Sets the seed of the particle swarm.
    pub const fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    fn check(&self) -> Result<(), Error> {
        if !(1..=5).contains(&self.levels) {
            return Err(Error::Parameter(format!(
                "fitting levels must be 1..=5, got {}",
                self.levels
            )));
        }
        if !(1..=8).contains(&self.sharpness_bits) {
            return Err(Error::Parameter(format!(
                "sharpness bits must be 1..=8, got {}",
                self.sharpness_bits
            )));
        }
        if !(self.two_sided.is_finite() && self.two_sided >= 0.0) {
            return Err(Error::Parameter(format!(
                "the two-sided weight must be finite and non-negative, got {}",
                self.two_sided
            )));
        }
        for (name, v) in [("alpha", self.alpha), ("aq", self.aq), ("az", self.az)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::Parameter(format!(
                    "{name} must be finite and positive, got {v}"
                )));
            }
        }
        if !self.crease_angle_degrees.is_finite() {
            return Err(Error::Parameter("the crease angle must be finite".into()));
        }
        Ok(())
    }
}

impl Default for FitOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Most triangles of the fitted level (control triangles x 4^levels) a fit takes on. The fit
/// holds about 1.1 KB per fitted triangle (the composed subdivision-and-limit map, its
/// normal equations, the correspondences: 450 MB for 3200 control vertices at 3 levels,
/// measured on fandisk), so this bounds it near 2.3 GB; a mesh that needs more control
/// vertices than this is better coded by the swing or exact mode.
pub const MAX_FITTED_TRIANGLES: u64 = 1 << 21;

/// Refuses a fit whose fitted level would have more than [`MAX_FITTED_TRIANGLES`]
/// triangles, before anything of that size is allocated.
fn check_fitted_size(control_triangles: u64, levels: u32) -> Result<(), Error> {
    let fitted = control_triangles.saturating_mul(1u64 << (2 * levels.min(31)));
    if fitted > MAX_FITTED_TRIANGLES {
        return Err(Error::LimitExceeded {
            what: "fitted triangles (control triangles x 4^levels)",
            limit: MAX_FITTED_TRIANGLES,
            value: fitted,
        });
    }
    Ok(())
}

/// What a fit did and how well it fits.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct FitReport {
    /// Vertices of the control mesh.
    pub control_vertices: usize,
    /// Edges of the control mesh.
    pub control_edges: usize,
    /// Edges with `h > 0` at the end.
    pub sharp_edges: usize,
    /// Outer iterations run.
    pub iterations: u32,
    /// Root mean square distance from the input vertices to the fitted surface (at the
    /// fitting level, limit positions), in input units.
    pub rms_distance: f64,
    /// Largest such distance.
    pub max_distance: f64,
    /// Root mean square distance from the limit vertices of the fitted surface to the input
    /// (the other direction; it catches surface parts no input vertex is near).
    pub reverse_rms_distance: f64,
    /// Largest such distance.
    pub reverse_max_distance: f64,
    /// Whether the returned surface is not the last iterate (see [`FitFallback`]).
    pub fallback: FitFallback,
    /// `sum |M p - t|^2` of the sharpness subproblem before and after each h-step (unit
    /// diagonal), for the solver comparison.
    pub h_objective: Vec<(f64, f64)>,
    /// Milliseconds: denoising and simplification.
    pub simplify_ms: f64,
    /// Milliseconds: the whole variational fit.
    pub fit_ms: f64,
    /// Milliseconds of the fit spent in the sharpness subproblem.
    pub sharpness_ms: f64,
}

/// What [`fit_control`] returned when the last iterate of the augmented Lagrangian was not
/// the best surface it measured. Every candidate is scored by its symmetric RMS distance to
/// the input (input vertices to the limit surface, limit vertices to the input).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum FitFallback {
    /// The last iterate was the best.
    None,
    /// An earlier iterate was better (0: the control mesh's points with the initial
    /// sharpness); the fit drifted after it.
    Iteration(u32),
    /// Continuous mode only: the control mesh itself, every edge fully sharp (the
    /// subdivision then reproduces the piecewise-linear control mesh), was better than any
    /// smooth or semi-sharp iterate (polyhedral inputs).
    Polyhedral,
}

/// One candidate result of the fit and its error against the input (unit-diagonal units).
struct Snapshot {
    p: Vec<DVec3>,
    h: Vec<f64>,
    error: SurfaceError,
    iteration: u32,
}

impl Snapshot {
    fn evaluate(
        hier: &Hierarchy,
        p: &[DVec3],
        h: &[f64],
        depth: usize,
        data: &[DVec3],
        input_bvh: &Bvh,
        iteration: u32,
    ) -> Snapshot {
        let c = compose(hier, h, depth);
        let x = c.apply(p);
        let fine = Mesh::new(x.clone(), hier.finest().triangles.clone());
        let bvh = Bvh::new(&fine);
        let feet: Vec<DVec3> = data
            .par_iter()
            .map(|&v| bvh.closest_point(v).point)
            .collect();
        let rev: Vec<DVec3> = x
            .par_iter()
            .map(|&xj| input_bvh.closest_point(xj).point)
            .collect();
        Snapshot {
            p: p.to_vec(),
            h: h.to_vec(),
            error: SurfaceError::measure(data, &feet, &x, &rev),
            iteration,
        }
    }
}

/// Distances between the input and a surface, both ways.
#[derive(Clone, Copy, Debug)]
struct SurfaceError {
    rms_forward: f64,
    max_forward: f64,
    rms_reverse: f64,
    max_reverse: f64,
}

impl SurfaceError {
    /// `data[i]` against its foot `feet[i]` on the surface, limit vertex `x[j]` against its
    /// closest input point `rev[j]`.
    fn measure(data: &[DVec3], feet: &[DVec3], x: &[DVec3], rev: &[DVec3]) -> SurfaceError {
        let stats = |a: &[DVec3], b: &[DVec3]| {
            let (sum, max) = a
                .iter()
                .zip(b)
                .map(|(p, q)| (*p - *q).length())
                .fold((0.0, 0.0f64), |(s, m), d| (s + d * d, m.max(d)));
            ((sum / a.len().max(1) as f64).sqrt(), max)
        };
        let (rms_forward, max_forward) = stats(data, feet);
        let (rms_reverse, max_reverse) = stats(x, rev);
        SurfaceError {
            rms_forward,
            max_forward,
            rms_reverse,
            max_reverse,
        }
    }

    /// Symmetric RMS distance; NaN (a broken iterate) scores worst.
    fn score(&self) -> f64 {
        let s = (0.5 * (self.rms_forward.powi(2) + self.rms_reverse.powi(2))).sqrt();
        if s.is_nan() {
            f64::INFINITY
        } else {
            s
        }
    }
}

/// A fitted surface: control mesh, sharpness, and the report.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct Fitted {
    /// The control mesh (input units).
    pub control: Mesh,
    /// Sharpness of its edges.
    pub sharpness: EdgeSharpness,
    /// What happened.
    pub report: FitReport,
}

/// The whole pipeline of seed 004: optional bilateral denoising, feature-preserving
/// simplification to `opts.control_vertices` vertices, then [`fit_control`] against the
/// (noisy) input.
pub fn fit(input: &Mesh, opts: &FitOptions) -> Result<Fitted, Error> {
    opts.check()?;
    check_input(input)?;
    // A closed control mesh has about twice as many triangles as vertices; a target above
    // the input's vertex count keeps the input's own triangles.
    let control_triangles = if opts.control_vertices >= input.positions.len() {
        input.triangles.len() as u64
    } else {
        2 * opts.control_vertices as u64
    };
    check_fitted_size(control_triangles, opts.levels)?;
    let start = Instant::now();
    let denoised;
    let source = if opts.denoise_iterations > 0 {
        denoised = bilateral_denoise(input, opts.denoise_iterations)?;
        &denoised
    } else {
        input
    };
    let simplified = simplify(
        source,
        &SimplifyOptions::DEFAULT
            .with_target_vertices(opts.control_vertices)
            .with_crease_angle(opts.crease_angle_degrees),
    )?;
    let initial = initial_sharpness(&simplified.mesh, opts);
    let simplify_ms = start.elapsed().as_secs_f64() * 1e3;
    let mut fitted = fit_control(input, &simplified.mesh, &initial, opts)?;
    fitted.report.simplify_ms = simplify_ms;
    Ok(fitted)
}

/// The initial sharpness of `opts.mode` on `control`.
pub fn initial_sharpness(control: &Mesh, opts: &FitOptions) -> EdgeSharpness {
    match opts.mode {
        SharpnessMode::Smooth => EdgeSharpness::zeros(control),
        SharpnessMode::Crease | SharpnessMode::Continuous => {
            EdgeSharpness::from_dihedral_angle(control, opts.crease_angle_degrees)
        }
    }
}

fn check_input(input: &Mesh) -> Result<(), Error> {
    if input.triangles.is_empty() {
        return Err(Error::InvalidInput(whet_mesh::MeshError::Empty));
    }
    if let Some(v) = input.positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::InvalidInput(
            whet_mesh::MeshError::NonFiniteCoordinate { vertex: v as u32 },
        ));
    }
    CornerTable::new(input).map_err(Error::InvalidInput)?;
    if !(input.diagonal() > 0.0 && input.diagonal().is_finite()) {
        return Err(Error::Parameter(
            "the input has a zero or non-finite bounding-box diagonal".into(),
        ));
    }
    Ok(())
}

/// Step 4 of the pipeline: fits the points and (per `opts.mode`) the sharpness of `control`,
/// keeping its connectivity, to the vertices of `input`.
pub fn fit_control(
    input: &Mesh,
    control: &Mesh,
    initial: &EdgeSharpness,
    opts: &FitOptions,
) -> Result<Fitted, Error> {
    opts.check()?;
    check_input(input)?;
    check_fitted_size(control.triangles.len() as u64, opts.levels)?;
    let (hier, _) = crate::surface::prepare(control, initial, opts.levels)?;
    let start = Instant::now();
    let bbox = input.bounding_box();
    let centre = bbox.center();
    let scale = 1.0 / input.diagonal();
    let to_unit = |p: DVec3| (p - centre) * scale;

    // Data: the used input vertices.
    let mut used = vec![false; input.positions.len()];
    for t in &input.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let data: Vec<DVec3> = input
        .positions
        .iter()
        .zip(&used)
        .filter(|(_, &u)| u)
        .map(|(&p, _)| to_unit(p))
        .collect();
    let n = data.len();
    let m = control.positions.len();
    let unit_input = Mesh::new(
        input.positions.iter().map(|&x| to_unit(x)).collect(),
        input.triangles.clone(),
    );
    let input_bvh = Bvh::new(&unit_input);
    let n_fine = hier.finest().vertex_count;
    let w_rev = opts.two_sided * opts.az * n as f64 / n_fine.max(1) as f64;
    let mut p: Vec<DVec3> = control.positions.iter().map(|&x| to_unit(x)).collect();
    let levels_values: Vec<f64> = {
        let k = (1u32 << opts.sharpness_bits) - 1;
        (0..=k).map(|i| i as f64 / k as f64).collect()
    };
    let mut h: Vec<f64> = initial.quantized(opts.sharpness_bits).values().to_vec();
    if opts.mode == SharpnessMode::Smooth {
        h.iter_mut().for_each(|x| *x = 0.0);
    }
    let control_topo = &hier.levels[0];
    let lap = laplacian(control_topo);
    let lc = control.mean_edge_length() * scale;
    let ld = input.mean_edge_length() * scale;
    let lambda = opts.alpha * m as f64 * lc / (n as f64 * ld).max(f64::MIN_POSITIVE);
    let (aq, az) = (opts.aq, opts.az);
    let mut q = vec![DVec3::ZERO; m];
    let mut lq = vec![DVec3::ZERO; m];
    let mut z = vec![DVec3::ZERO; n];
    let mut lz = vec![DVec3::ZERO; n];
    let candidates: Vec<u32> = (0..control_topo.edges.len() as u32)
        .filter(|&e| !control_topo.is_boundary_edge(e as usize))
        .collect();
    let depth = opts.levels as usize;
    let mut sharpness_ms = 0.0;
    let mut h_objective = Vec::new();
    let mut iterations = 0;
    let eps0 = 1e-12 * m as f64;
    let mut best: Option<Snapshot> = None;
    for outer in 0..opts.iterations {
        iterations = outer + 1;
        let p_old = p.clone();
        let mut c = compose(&hier, &h, depth);
        let (foot_t, bary) = feet(&hier, &c, &p, &data);
        let fine_tris = &hier.finest().triangles;
        let foot: Vec<[u32; 3]> = foot_t.iter().map(|&t| fine_tris[t as usize]).collect();
        let mut mm = feet_matrix(&c, &foot, &bary);
        // Reverse correspondences: each limit vertex and its closest input point.
        let x = c.apply(&p);
        let rev_target: Vec<DVec3> = x
            .par_iter()
            .map(|&xj| input_bvh.closest_point(xj).point)
            .collect();
        // The surface this iteration starts from (the control mesh's own surface first),
        // measured both ways; the fit returns the best one it saw.
        let error = SurfaceError::measure(&data, &mm.apply(&p), &x, &rev_target);
        if best
            .as_ref()
            .is_none_or(|b| error.score() < b.error.score())
        {
            best = Some(Snapshot {
                p: p.clone(),
                h: h.clone(),
                error,
                iteration: outer,
            });
        }
        let rev_target = if w_rev > 0.0 { rev_target } else { Vec::new() };
        for _ in 0..opts.inner_iterations.max(1) {
            // p-step.
            let rhs_l: Vec<DVec3> = (0..m).map(|i| q[i] + lq[i] / aq).collect();
            let rhs_m: Vec<DVec3> = (0..n).map(|i| data[i] - z[i] - lz[i] / az).collect();
            let a = lap.apply_transpose(&rhs_l);
            let b = mm.apply_transpose(&rhs_m);
            let mut rhs: Vec<DVec3> = (0..m).map(|i| a[i] * aq + b[i] * az).collect();
            let dl = lap.gram_diagonal();
            let dm = mm.gram_diagonal();
            let mut diag: Vec<f64> = (0..m).map(|i| aq * dl[i] + az * dm[i]).collect();
            if w_rev > 0.0 {
                let r = c.apply_transpose(&rev_target);
                let dc = c.gram_diagonal();
                for i in 0..m {
                    rhs[i] += r[i] * w_rev;
                    diag[i] += w_rev * dc[i];
                }
            }
            let apply = |x: &[DVec3]| -> Vec<DVec3> {
                let l1 = lap.apply_transpose(&lap.apply(x));
                let m1 = mm.apply_transpose(&mm.apply(x));
                let mut out: Vec<DVec3> = (0..x.len()).map(|i| l1[i] * aq + m1[i] * az).collect();
                if w_rev > 0.0 {
                    let c1 = c.apply_transpose(&c.apply(x));
                    for i in 0..out.len() {
                        out[i] += c1[i] * w_rev;
                    }
                }
                out
            };
            conjugate_gradient(apply, &diag, &rhs, &mut p, 1e-10, 500);

            // h-step.
            if opts.mode == SharpnessMode::Continuous {
                let t0 = Instant::now();
                let mut target: Vec<DVec3> = (0..n).map(|i| data[i] - z[i] - lz[i] / az).collect();
                let mut all_foot = foot.clone();
                let mut all_bary = bary.clone();
                let mut weight = vec![1.0; n];
                for (j, &y) in rev_target.iter().enumerate() {
                    all_foot.push([j as u32; 3]);
                    all_bary.push(DVec3::X);
                    target.push(y);
                    weight.push(w_rev / az);
                }
                let mut eval = LocalEval::new(&hier, &h, &p, all_foot, all_bary, target, weight);
                let before = eval.objective();
                match opts.solver {
                    SharpnessSolver::CoordinateDescent => {
                        // One sweep per h-step: a second one changed nothing measurable on the
                        // rocker arm (docs/results.md) and doubles the time.
                        eval.coordinate_descent(&candidates, &levels_values, 1);
                    }
                    SharpnessSolver::ParticleSwarm => {
                        // The swarm searches the edges the detection or earlier steps made
                        // sharp and their neighbours' edges; the full space is hopeless.
                        let cand = swarm_candidates(control_topo, &h, &candidates);
                        let best = pso(&mut eval, &cand, 24, 30, opts.seed ^ outer as u64);
                        // Quantize to the transmitted values, keeping the better of the two.
                        let _ = best;
                        for &e in &cand {
                            let v = eval.h[e as usize];
                            let qv = quantize(v, opts.sharpness_bits);
                            if qv != v {
                                eval.set(e as usize, qv);
                            }
                        }
                    }
                }
                let after = eval.objective();
                h_objective.push((before, after));
                if after < before {
                    h = eval.h.clone();
                    c = compose(&hier, &h, depth);
                    mm = feet_matrix(&c, &foot, &bary);
                }
                sharpness_ms += t0.elapsed().as_secs_f64() * 1e3;
            }

            // q- and z-steps.
            let lp = lap.apply(&p);
            for i in 0..m {
                q[i] = shrink(lp[i] - lq[i] / aq, 1.0 / aq);
            }
            let mp = mm.apply(&p);
            for i in 0..n {
                z[i] = shrink(data[i] - mp[i] - lz[i] / az, lambda / az);
            }
        }
        let lp = lap.apply(&p);
        let mp = mm.apply(&p);
        for i in 0..m {
            lq[i] += (q[i] - lp[i]) * aq;
        }
        for i in 0..n {
            lz[i] += (z[i] - (data[i] - mp[i])) * az;
        }
        let eps: f64 = p
            .iter()
            .zip(&p_old)
            .map(|(a, b)| (*a - *b).length_squared())
            .sum();
        if eps <= eps0 {
            break;
        }
    }
    // Safeguard: the final iterate against the best one seen (iteration 0 is the control
    // mesh's own surface), and in continuous mode against the control mesh itself (every edge
    // sharp reproduces it exactly). An augmented Lagrangian that drifts (ill-shaped control
    // triangles, surface parts no data point projects onto) can then never return a surface
    // worse than what it started from.
    let mut candidates_final = vec![Snapshot::evaluate(
        &hier, &p, &h, depth, &data, &input_bvh, iterations,
    )];
    if let Some(b) = best {
        candidates_final.push(b);
    }
    if opts.mode == SharpnessMode::Continuous {
        let p0: Vec<DVec3> = control.positions.iter().map(|&x| to_unit(x)).collect();
        let ones = vec![1.0; h.len()];
        candidates_final.push(Snapshot::evaluate(
            &hier, &p0, &ones, depth, &data, &input_bvh, 0,
        ));
    }
    // Ties go to the earliest candidate: the final iterate.
    let chosen = candidates_final
        .into_iter()
        .reduce(|a, b| {
            if b.error.score() < a.error.score() {
                b
            } else {
                a
            }
        })
        .expect("at least the final iterate");
    let fallback = if chosen.iteration == iterations {
        FitFallback::None
    } else if chosen.h.iter().all(|&x| x == 1.0)
        && opts.mode == SharpnessMode::Continuous
        && chosen.iteration == 0
        && chosen
            .p
            .iter()
            .zip(&control.positions)
            .all(|(a, b)| *a == to_unit(*b))
    {
        FitFallback::Polyhedral
    } else {
        FitFallback::Iteration(chosen.iteration)
    };
    let Snapshot { p, h, error, .. } = chosen;
    let rms = error.rms_forward / scale;
    let max = error.max_forward / scale;
    let positions: Vec<DVec3> = p.iter().map(|&x| x / scale + centre).collect();
    let control_mesh = Mesh::new(positions, control.triangles.clone());
    let sharpness = EdgeSharpness::from_parts(initial.edges().to_vec(), h);
    let report = FitReport {
        control_vertices: m,
        control_edges: sharpness.len(),
        sharp_edges: sharpness.sharp_count(),
        iterations,
        rms_distance: rms,
        max_distance: max,
        reverse_rms_distance: error.rms_reverse / scale,
        reverse_max_distance: error.max_reverse / scale,
        fallback,
        h_objective,
        simplify_ms: 0.0,
        fit_ms: start.elapsed().as_secs_f64() * 1e3,
        sharpness_ms,
    };
    Ok(Fitted {
        control: control_mesh,
        sharpness,
        report,
    })
}

fn quantize(v: f64, bits: u32) -> f64 {
    let k = ((1u32 << bits) - 1) as f64;
    (v * k).round() / k
}

/// Edges the swarm searches: the sharp ones and every edge sharing a vertex with one.
fn swarm_candidates(topo: &Topology, h: &[f64], candidates: &[u32]) -> Vec<u32> {
    let mut near = vec![false; topo.vertex_count];
    for (e, &[a, b]) in topo.edges.iter().enumerate() {
        if h[e] > 0.0 && !topo.is_boundary_edge(e) {
            near[a as usize] = true;
            near[b as usize] = true;
        }
    }
    candidates
        .iter()
        .copied()
        .filter(|&e| {
            let [a, b] = topo.edges[e as usize];
            near[a as usize] || near[b as usize]
        })
        .collect()
}

#[inline]
fn shrink(w: DVec3, t: f64) -> DVec3 {
    let l = w.length();
    if l <= t || l == 0.0 {
        DVec3::ZERO
    } else {
        w * (1.0 - t / l)
    }
}

/// The uniform Laplacian `p_i - mean of the neighbours`.
fn laplacian(topo: &Topology) -> Csr {
    let mut l = Csr::new(topo.vertex_count);
    let mut row = Row::default();
    for v in 0..topo.vertex_count {
        row.clear();
        let ring = topo.ring(v);
        if !ring.is_empty() {
            row.add(v as u32, 1.0);
            let w = -1.0 / ring.len() as f64;
            for &(u, _) in ring {
                row.add(u, w);
            }
        }
        l.push_row(&row);
    }
    l
}

/// The composed map from control points to the limit points of the finest level.
fn compose(hier: &Hierarchy, h: &[f64], depth: usize) -> Csr {
    let stencils = hier.stencils(h, depth, true);
    let mut c = Csr::identity(hier.levels[0].vertex_count);
    for s in &stencils {
        c = s.compose(&c);
    }
    c
}

/// Closest point of every data point on the surface `C p`: the fine triangle and the
/// barycentric coordinates.
fn feet(hier: &Hierarchy, c: &Csr, p: &[DVec3], data: &[DVec3]) -> (Vec<u32>, Vec<DVec3>) {
    let x = c.apply(p);
    let fine = Mesh::new(x, hier.finest().triangles.clone());
    let bvh = Bvh::new(&fine);
    data.par_chunks(256)
        .flat_map_iter(|chunk| {
            let mut query = bvh.coherent_query();
            let fine = &fine;
            chunk.iter().map(move |&v| {
                let cp = query.closest_point(v);
                let t = cp.triangle as usize;
                if t >= fine.triangles.len() {
                    return (0u32, DVec3::new(1.0, 0.0, 0.0));
                }
                let [a, b, c] = fine.triangle_positions(t);
                (t as u32, barycentric(cp.point, a, b, c))
            })
        })
        .unzip()
}

/// Barycentric coordinates of `p` (on or near triangle abc), clamped to the triangle.
fn barycentric(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (v0, v1, v2) = (b - a, c - a, p - a);
    let (d00, d01, d11) = (v0.dot(v0), v0.dot(v1), v1.dot(v1));
    let (d20, d21) = (v2.dot(v0), v2.dot(v1));
    let denom = d00 * d11 - d01 * d01;
    if denom.is_nan() || denom <= 0.0 {
        return DVec3::new(1.0, 0.0, 0.0);
    }
    let v = (d11 * d20 - d01 * d21) / denom;
    let w = (d00 * d21 - d01 * d20) / denom;
    let b = DVec3::new(1.0 - v - w, v, w).max(DVec3::ZERO);
    let s = b.x + b.y + b.z;
    if s > 0.0 && s.is_finite() {
        b / s
    } else {
        DVec3::new(1.0, 0.0, 0.0)
    }
}

/// `M`: row i is `sum_j bary_ij C[foot_ij]`.
fn feet_matrix(c: &Csr, foot: &[[u32; 3]], bary: &[DVec3]) -> Csr {
    let mut b = Csr::new(c.rows());
    let mut row = Row::default();
    for (f, w) in foot.iter().zip(bary) {
        row.clear();
        row.add(f[0], w.x);
        row.add(f[1], w.y);
        row.add(f[2], w.z);
        b.push_row(&row);
    }
    b.compose(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shrink_is_the_l2_proximal_map() {
        assert_eq!(shrink(DVec3::new(0.5, 0.0, 0.0), 1.0), DVec3::ZERO);
        let s = shrink(DVec3::new(3.0, 4.0, 0.0), 1.0);
        assert!((s - DVec3::new(2.4, 3.2, 0.0)).length() < 1e-12);
    }

    #[test]
    fn barycentric_round_trips() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let w = barycentric(DVec3::new(0.25, 0.5, 0.0), a, b, c);
        assert!((w - DVec3::new(0.25, 0.25, 0.5)).length() < 1e-12);
        // Degenerate triangle: no NaN.
        assert!(barycentric(DVec3::X, a, a, a).is_finite());
    }

    /// A control vertex target whose fitted level would pass the limit is refused before
    /// the simplification, by the limit's own error; one the input caps is measured by the
    /// input's triangles.
    #[test]
    fn an_oversized_fit_is_refused_up_front() {
        let mesh = whet_testkit::meshes::icosphere(2);
        let huge = FitOptions::DEFAULT.with_control_vertices(1 << 20);
        // The icosphere has 162 vertices: the target is capped by them, so it fits.
        assert!(check_fitted_size(mesh.triangles.len() as u64, huge.levels).is_ok());
        // 163 842 vertices, 327 680 triangles: a target under the vertex count is priced at
        // two triangles per vertex, one over it at the input's triangles.
        let big = whet_testkit::meshes::icosphere(7);
        let under = FitOptions::DEFAULT.with_control_vertices(100_000);
        for (opts, triangles) in [(under, 200_000), (huge, 327_680)] {
            match fit(&big, &opts) {
                Err(Error::LimitExceeded { what, limit, value }) => {
                    assert!(what.contains("fitted triangles"));
                    assert_eq!(limit, MAX_FITTED_TRIANGLES);
                    assert_eq!(value, triangles * 64);
                }
                other => panic!("expected the fitted-size limit, got {other:?}"),
            }
        }
        assert!(matches!(
            fit_control(
                &big,
                &big,
                &EdgeSharpness::zeros(&big),
                &FitOptions::DEFAULT
            ),
            Err(Error::LimitExceeded { .. })
        ));
    }
}
