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
}

impl Method {
    /// Every method, in declaration order.
    pub const ALL: [Method; 2] = [Method::Papers, Method::Extended];

    /// The name used on the command line and in reports (`papers`, `extended`).
    pub const fn name(self) -> &'static str {
        match self {
            Method::Papers => "papers",
            Method::Extended => "extended",
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
                crate::Error::Parameter(format!("unknown method {s:?} (known: papers, extended)"))
            })
    }
}

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
}

impl SharpenOptions {
    /// [`Method::Extended`], smooth factor 2, minimum angle 1 degree.
    pub const DEFAULT: SharpenOptions = SharpenOptions {
        method: Method::Extended,
        smooth_factor: 2.0,
        min_angle_degrees: 1.0,
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
        Ok(())
    }
}

impl Default for SharpenOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}
