//! Options of the sharpener.

/// Which chamfer detection to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
#[non_exhaustive]
pub enum Method {
    /// The papers' EdgeSharpener exactly (seed 000 section 3, seed 001 sections 3 and 4.1):
    /// smooth edges, the six filters, chamfer edges and corner triangles, plane snapping and its
    /// degenerate cases, the final sliver collapse. `whet sharpen --method papers`.
    Papers,
    /// The papers' algorithm plus whet's extended chamfer detection (`docs/sharpen.md`, "What
    /// we extend"): chamfer vertices outside every smooth region are classified onto the planes
    /// of the regions around them, so the chamfer triangles they touch are found too. The
    /// default.
    #[default]
    Extended,
    /// Seed 002's normal-filtering sharpener (`docs/sharpen.md`, "The normal-filtering
    /// sharpener"): feature faces by bounded normal variation, greedy normal filtering from
    /// the outside of each feature inwards, least-squares vertex updating with flip avoidance
    /// and cap/needle removal. Handles fillets, chamfers with samples, and noisy creases.
    /// `whet sharpen --method normal-filter`.
    NormalFilter,
}

impl Method {
    /// Every method, in declaration order.
    pub const ALL: [Method; 3] = [Method::Papers, Method::Extended, Method::NormalFilter];

    /// The name used on the command line and in reports (`papers`, `extended`).
    pub const fn name(self) -> &'static str {
        match self {
            Method::Papers => "papers",
            Method::Extended => "extended",
            Method::NormalFilter => "normal-filter",
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Method {
    type Err = crate::Error;

    fn from_str(s: &str) -> Result<Method, crate::Error> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                crate::Error::Parameter(format!(
                    "unknown method {s:?} (known: papers, extended, normal-filter)"
                ))
            })
    }
}

/// The curved-wall factor to use when they are on ([`SharpenOptions::curved_wall_factor`],
/// `whet sharpen --curved-walls`, the swing encoder's candidates): 2. On the 48
/// swing-decoded CAD rows of the sharpening figures (docs/results.md, "Curved walls") it
/// gained more than 1.5 (partLp 1x at 6 bits, papers at factor 1.5: 2.49x against 2.62x at
/// 2; cad_box_hole and cad_bracket with automatic angle bits), and with the extended method
/// it lost nowhere against no walls. Off by default all the same: on the original spot
/// mesh the extended method with walls at 2 sharpens organic bends (RMS against the mesh
/// itself 0.0152 % -> 0.0451 %).
pub const DEFAULT_CURVED_WALL_FACTOR: f64 = 2.0;

/// The most passes [`SharpenOptions::passes`] allows: a third pass gains about 1 % where a
/// second gains 5-40 % (docs/results.md, "Passes").
pub const MAX_PASSES: u32 = 4;

/// Options of [`crate::sharpen`] and [`crate::EdgeSharpener`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SharpenOptions {
    /// Chamfer detection; default [`Method::Extended`].
    pub method: Method,
    /// An edge is smooth when the angle between its triangles' normals is under this factor
    /// times the mean of that angle over the mesh (seed 000 section 3: 2). Must be finite and
    /// positive.
    pub smooth_factor: f64,
    /// New triangles with an angle under this many degrees are removed by collapsing an edge
    /// (seed 001 section 3.3: 1 degree). Must be in `[0, 20]`; 0 turns the pass off except for
    /// reversed triangles.
    pub min_angle_degrees: f64,
    /// Normal filter: radius of the neighbourhood `NFII`, in mean edge lengths (seed 002's
    /// `rho/L`; a little more than the widest feature to sharpen). Finite, in `(0, 64]`.
    pub rho: f64,
    /// Normal filter: a face is a feature face when the smallest dot product of two normals in
    /// its neighbourhood is under `eta`. In `[-1, 1]`.
    pub eta: f64,
    /// Normal filter: the neighbourhood flood does not cross an edge whose normals' dot product
    /// is `lambda` or less (an edge that is already sharp). In `[-1, 1]`.
    pub lambda: f64,
    /// Extended method: weld marching cubes' clusters of near-coincident input vertices
    /// before the run (with the input's smooth threshold), so that their slivers do not keep
    /// chamfer edges from splitting, and put back the clusters the run left untouched
    /// (docs/sharpen.md, "What we extend", step 10); vertices that stay welded keep their
    /// indices, used by no triangle. Default on.
    pub weld_clusters: bool,
    /// Extended method: leave alone the connected parts whose creases are already sharp
    /// (most of their strong creases run along edges between smooth regions, where a
    /// sampling would have cut them into chamfers: a CAD original, or a mesh this sharpener
    /// already sharpened; docs/sharpen.md, "What we extend", step 17). Default on; off, every
    /// part is taken for a chamfered sampling, as before. Later passes never look (their
    /// input is the previous pass's output).
    pub keep_sharp_parts: bool,
    /// Extended method: leave alone the connected parts of a surface sampling where fewer
    /// than 40 % of the chamfer edges found can be cut, the rest refused as curved (a
    /// surface that bends everywhere, whose few snaps left are bumps: docs/sharpen.md, "What
    /// we extend", step 19). Default on; off, they are sharpened as before. Later passes
    /// never look.
    pub keep_curved_parts: bool,
    /// Extended method: label the gray vertices of surface samplings too (step 3 of
    /// docs/sharpen.md, "What we extend", which surface samplings skip by default: step 8).
    /// On a chamfer two triangles wide its middle vertex lies in no smooth triangle and keeps
    /// the chamfer whole unless it is labelled; on a blend a few samples wide the same label
    /// sharpens the blend (rocker_arm). No local test tells the two apart, so it is off by
    /// default and a swing stream states it where its encoder measured it better (header
    /// field 41; step 20). Marching cubes always label their gray vertices.
    pub surface_gray_labels: bool,
    /// Curved walls (docs/sharpen.md): where two rings of triangles lie outside every smooth
    /// region, an edge turning by under this factor times the smooth threshold counts as
    /// smooth too, so that a face curved at the sampling's scale (a hole's cylinder a few
    /// edges across) becomes a smooth region and its chamfer with a flat face is found. `None`
    /// (the default) and `Some(0.0)`: off, for both methods (on the original spot it sharpens
    /// organic bends: docs/results.md, "Curved walls"); otherwise finite, in `[1, 4]`
    /// ([`DEFAULT_CURVED_WALL_FACTOR`] is the measured choice). See [`Self::curved_walls`].
    pub curved_wall_factor: Option<f64>,
    /// How many times EdgeSharpener runs, each pass on the previous one's output (1 to 4;
    /// default 1, the papers' single pass). A pass's splits can leave chamfers the next one
    /// finds (docs/sharpen.md, "Passes"); passes stop early once one changes nothing.
    pub passes: u32,
    /// Passes after the first run only while the mesh has at most this many triangles (a
    /// memory budget: `whet decode --max-memory`); `None`: no limit.
    pub pass_budget_triangles: Option<u64>,
}

impl SharpenOptions {
    /// [`Method::Extended`], smooth factor 2, minimum angle 1 degree; for the normal filter
    /// `rho` 4, `eta` 0.1, `lambda` 0.
    pub const DEFAULT: SharpenOptions = SharpenOptions {
        method: Method::Extended,
        smooth_factor: 2.0,
        min_angle_degrees: 1.0,
        rho: 4.0,
        eta: 0.1,
        lambda: 0.0,
        weld_clusters: true,
        keep_sharp_parts: true,
        keep_curved_parts: true,
        surface_gray_labels: false,
        curved_wall_factor: None,
        passes: 1,
        pass_budget_triangles: None,
    };

    /// The papers' algorithm with their constants (`--method papers`).
    pub const PAPERS: SharpenOptions = SharpenOptions::DEFAULT.with_method(Method::Papers);

    /// Sets the method.
    pub const fn with_method(mut self, method: Method) -> Self {
        self.method = method;
        self
    }

    /// Sets the smooth factor.
    pub const fn with_smooth_factor(mut self, smooth_factor: f64) -> Self {
        self.smooth_factor = smooth_factor;
        self
    }

    /// Sets the minimum angle of new triangles, in degrees.
    pub const fn with_min_angle_degrees(mut self, degrees: f64) -> Self {
        self.min_angle_degrees = degrees;
        self
    }

    /// Sets the normal filter's neighbourhood radius, in mean edge lengths.
    pub const fn with_rho(mut self, rho: f64) -> Self {
        self.rho = rho;
        self
    }

    /// Sets the normal filter's feature threshold.
    pub const fn with_eta(mut self, eta: f64) -> Self {
        self.eta = eta;
        self
    }

    /// Sets the normal filter's flood stop.
    pub const fn with_lambda(mut self, lambda: f64) -> Self {
        self.lambda = lambda;
        self
    }

    /// Sets whether the extended method welds the vertex clusters that block chamfers.
    pub const fn with_weld_clusters(mut self, weld: bool) -> Self {
        self.weld_clusters = weld;
        self
    }

    /// Sets whether the extended method leaves already sharp parts alone.
    pub const fn with_keep_sharp_parts(mut self, keep: bool) -> Self {
        self.keep_sharp_parts = keep;
        self
    }

    /// Sets whether the extended method leaves alone the parts whose chamfers are mostly
    /// refused as curved.
    pub const fn with_keep_curved_parts(mut self, keep: bool) -> Self {
        self.keep_curved_parts = keep;
        self
    }

    /// Sets whether the extended method labels the gray vertices of surface samplings too.
    pub const fn with_surface_gray_labels(mut self, on: bool) -> Self {
        self.surface_gray_labels = on;
        self
    }

    /// Sets the curved-wall factor (0: off).
    pub const fn with_curved_wall_factor(mut self, factor: f64) -> Self {
        self.curved_wall_factor = Some(factor);
        self
    }

    /// Sets the number of passes.
    pub const fn with_passes(mut self, passes: u32) -> Self {
        self.passes = passes;
        self
    }

    /// Sets the triangle budget of the passes after the first.
    pub const fn with_pass_budget_triangles(mut self, triangles: u64) -> Self {
        self.pass_budget_triangles = Some(triangles);
        self
    }

    /// The curved-wall factor a run uses: the one set, else 0 (off).
    pub fn curved_walls(&self) -> f64 {
        self.curved_wall_factor.unwrap_or(0.0)
    }

    /// Checks the values; [`crate::sharpen`] calls this first.
    pub fn validate(&self) -> Result<(), crate::Error> {
        if !(self.smooth_factor.is_finite() && self.smooth_factor > 0.0) {
            return Err(crate::Error::Parameter(format!(
                "smooth_factor must be finite and positive, got {}",
                self.smooth_factor
            )));
        }
        if !(0.0..=20.0).contains(&self.min_angle_degrees) {
            return Err(crate::Error::Parameter(format!(
                "min_angle_degrees must be between 0 and 20, got {}",
                self.min_angle_degrees
            )));
        }
        if !(self.rho.is_finite() && self.rho > 0.0 && self.rho <= 64.0) {
            return Err(crate::Error::Parameter(format!(
                "rho must be in (0, 64] mean edge lengths, got {}",
                self.rho
            )));
        }
        let w = self.curved_walls();
        if !(w == 0.0 || (1.0..=4.0).contains(&w)) {
            return Err(crate::Error::Parameter(format!(
                "curved_wall_factor must be 0 (off) or between 1 and 4, got {w}"
            )));
        }
        if !(1..=MAX_PASSES).contains(&self.passes) {
            return Err(crate::Error::Parameter(format!(
                "passes must be between 1 and {MAX_PASSES}, got {}",
                self.passes
            )));
        }
        for (name, x) in [("eta", self.eta), ("lambda", self.lambda)] {
            if !(-1.0..=1.0).contains(&x) {
                return Err(crate::Error::Parameter(format!(
                    "{name} must be between -1 and 1, got {x}"
                )));
            }
        }
        Ok(())
    }
}

impl Default for SharpenOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}
