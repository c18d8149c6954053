//! The decoder's side of what a swing stream states about its sharpening (docs/swing.md
//! section 2): the method, smooth factor, curved walls and passes its encoder measured best
//! (`SharpenHint`), the snaps it vetoed (field 33), its filter for after sharpening, and the
//! projections after that (fields 25, 31, 37, 35 and 39, in that order). `whet decode --sharpen`, `whet rd` and the
//! sharpening figures all read a header through [`StatedSharpening`], and the encoder
//! measures its projections through [`StatedProjection`], so what the encoder measured is
//! what every decoder writes.

use whet_codec::{SharpenHint, SnapVetoes, SurfaceFilter};
use whet_mesh::Mesh;
use whet_sharpen::{EdgeSharpener, Method, SharpenOptions, Sharpened, VetoReplay};

/// One of the projections a swing stream may state after sharpening, in the order they run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StatedProjection {
    /// Field 25: planar regions onto their planes (`whet_sharpen::flatten_planar_regions`),
    /// the tolerance `factor` angle steps of a stream of `angle_bits`.
    Planar { factor: f64, angle_bits: u32 },
    /// Field 31: curved parts onto local quadrics (`whet_sharpen::project_onto_local_quadrics`),
    /// moves of at most `factor` angle steps.
    Quadric { factor: f64, angle_bits: u32 },
    /// Field 37: the vertices beside creases onto their own side's local quadric
    /// (`whet_sharpen::project_beside_creases_onto_local_quadrics`), moves of at most
    /// `factor` angle steps; runs before the crease projection.
    Beside { factor: f64, angle_bits: u32 },
    /// Field 35: crease vertices onto their sides' intersection
    /// (`whet_sharpen::project_creases_onto_local_quadrics`), moves of at most `max_move`
    /// mean edge lengths.
    Crease { max_move: f64 },
    /// Field 39: the vertex nearest each cut apex or corner onto the point where the
    /// tangent planes around it meet (`whet_sharpen::restore_apexes`), moves of at most
    /// `max_move` mean edge lengths; runs last.
    Apex { max_move: f64 },
}

impl StatedProjection {
    /// The projections `header` states, in the order they run (none for a stream that is
    /// not a swing stream).
    pub fn all_of(header: &whet_format::Header) -> Vec<StatedProjection> {
        let mut projections = Vec::new();
        if let Some((factor, angle_bits)) = SharpenHint::planar_of(header) {
            projections.push(StatedProjection::Planar { factor, angle_bits });
        }
        if let Some((factor, angle_bits)) = SharpenHint::quadric_of(header) {
            projections.push(StatedProjection::Quadric { factor, angle_bits });
        }
        if let Some((factor, angle_bits)) = SharpenHint::beside_of(header) {
            projections.push(StatedProjection::Beside { factor, angle_bits });
        }
        if let Some(max_move) = SharpenHint::crease_of(header) {
            projections.push(StatedProjection::Crease { max_move });
        }
        if let Some(max_move) = SharpenHint::apex_of(header) {
            projections.push(StatedProjection::Apex { max_move });
        }
        projections
    }

    /// Its name in messages ("the {name} projection was skipped").
    pub fn name(&self) -> &'static str {
        match self {
            StatedProjection::Planar { .. } => "planar-region",
            StatedProjection::Quadric { .. } => "local quadric",
            StatedProjection::Beside { .. } => "beside-crease quadric",
            StatedProjection::Crease { .. } => "crease",
            StatedProjection::Apex { .. } => "apex",
        }
    }

    /// [`Self::apply`] on `table`, the corner table of `mesh`'s triangles (one table serves
    /// several projections in a row: they move vertices, never triangles). The same result.
    pub fn apply_on(
        &self,
        mesh: &mut Mesh,
        table: &whet_mesh::CornerTable,
    ) -> Result<(), whet_sharpen::Error> {
        match *self {
            StatedProjection::Planar { factor, angle_bits } => {
                let opts = whet_sharpen::PlanarOptions::for_swing(angle_bits, factor);
                whet_sharpen::flatten_planar_regions_with_table(mesh, &opts, table).map(|_| ())
            }
            StatedProjection::Quadric { factor, angle_bits } => {
                let opts = whet_sharpen::QuadricOptions::for_swing(angle_bits, factor);
                whet_sharpen::project_onto_local_quadrics_with_table(mesh, &opts, table).map(|_| ())
            }
            StatedProjection::Beside { factor, angle_bits } => {
                let opts = whet_sharpen::BesideOptions::for_swing(angle_bits, factor);
                whet_sharpen::project_beside_creases_onto_local_quadrics_with_table(
                    mesh, &opts, table,
                )
                .map(|_| ())
            }
            StatedProjection::Crease { max_move } => {
                let opts = whet_sharpen::CreaseOptions::DEFAULT.with_max_move(max_move);
                whet_sharpen::project_creases_onto_local_quadrics_with_table(mesh, &opts, table)
                    .map(|_| ())
            }
            StatedProjection::Apex { max_move } => {
                let opts = whet_sharpen::ApexOptions::DEFAULT.with_max_move(max_move);
                whet_sharpen::restore_apexes_with_table(mesh, &opts, table).map(|_| ())
            }
        }
    }

    /// Applies `projections` to `mesh` in order, as [`Self::apply`] one after the other
    /// does, but on one corner table built for them all: the projections that failed, with
    /// their errors (each failure leaves `mesh` as that projection found it).
    pub fn apply_all(
        projections: &[StatedProjection],
        mesh: &mut Mesh,
    ) -> Vec<(StatedProjection, whet_sharpen::Error)> {
        let table = if projections.is_empty() {
            None
        } else {
            // A mesh without a table (not a manifold) gets each projection's own refusal.
            whet_mesh::CornerTable::new(mesh).ok()
        };
        projections
            .iter()
            .filter_map(|p| {
                let done = match &table {
                    Some(t) => p.apply_on(mesh, t),
                    None => p.apply(mesh),
                };
                done.err().map(|e| (*p, e))
            })
            .collect()
    }

    /// Applies it to `mesh`; an error leaves `mesh` as it was (it needs an oriented manifold,
    /// which sharpening gives).
    pub fn apply(&self, mesh: &mut Mesh) -> Result<(), whet_sharpen::Error> {
        match *self {
            StatedProjection::Planar { factor, angle_bits } => {
                let opts = whet_sharpen::PlanarOptions::for_swing(angle_bits, factor);
                whet_sharpen::flatten_planar_regions(mesh, &opts).map(|_| ())
            }
            StatedProjection::Quadric { factor, angle_bits } => {
                let opts = whet_sharpen::QuadricOptions::for_swing(angle_bits, factor);
                whet_sharpen::project_onto_local_quadrics(mesh, &opts).map(|_| ())
            }
            StatedProjection::Beside { factor, angle_bits } => {
                let opts = whet_sharpen::BesideOptions::for_swing(angle_bits, factor);
                whet_sharpen::project_beside_creases_onto_local_quadrics(mesh, &opts).map(|_| ())
            }
            StatedProjection::Crease { max_move } => {
                let opts = whet_sharpen::CreaseOptions::DEFAULT.with_max_move(max_move);
                whet_sharpen::project_creases_onto_local_quadrics(mesh, &opts).map(|_| ())
            }
            StatedProjection::Apex { max_move } => {
                let opts = whet_sharpen::ApexOptions::DEFAULT.with_max_move(max_move);
                whet_sharpen::restore_apexes(mesh, &opts).map(|_| ())
            }
        }
    }
}

/// What a stream's header states about sharpening its decoded mesh. A header without a
/// sharpening hint (an exact stream, an older swing stream) states the defaults: the
/// extended method at smooth factor 2, one pass, nothing else.
#[derive(Clone, Debug)]
pub struct StatedSharpening {
    /// The stream's hint (`None` without one).
    pub hint: Option<SharpenHint>,
    /// Smooth factor (2 without a hint).
    pub smooth_factor: f64,
    /// Curved-wall factor, when stated.
    pub curved_walls: Option<f64>,
    /// Sharpening passes (1 unless stated).
    pub passes: u32,
    /// Gray-vertex labels on surface samplings (field 41; off unless stated).
    pub gray_labels: bool,
    /// The snaps the encoder vetoed (field 33), when stated.
    pub vetoes: Option<SnapVetoes>,
    /// The filter for after sharpening (none unless stated).
    pub after_filter: SurfaceFilter,
    /// The projections after that filter, in order.
    pub projections: Vec<StatedProjection>,
}

/// A [`StatedSharpening::apply`] result: the output and what did not go as stated.
#[derive(Debug)]
pub struct StatedOutput {
    /// The sharpened mesh after the stream's filter and projections, with its tags.
    pub sharpened: Sharpened,
    /// Sharpening passes whose snaps the stream's vetoes did not fit (they were not applied
    /// there); 0 when the run is the one the encoder judged.
    pub mismatched_veto_passes: usize,
    /// The projections refused (the mesh kept as it was), with why.
    pub skipped: Vec<(StatedProjection, whet_sharpen::Error)>,
}

impl Default for StatedSharpening {
    /// What a stream without any sharpening field states (the defaults above).
    fn default() -> Self {
        StatedSharpening {
            hint: None,
            smooth_factor: 2.0,
            curved_walls: None,
            passes: 1,
            gray_labels: false,
            vetoes: None,
            after_filter: SurfaceFilter::NONE,
            projections: Vec::new(),
        }
    }
}

impl StatedSharpening {
    /// Reads `header`. Fails on a malformed snap-veto field (bad input).
    pub fn of(header: &whet_format::Header) -> Result<StatedSharpening, whet_codec::Error> {
        let stated = SharpenHint::stated(header);
        let vetoes = SnapVetoes::of(header).transpose()?;
        Ok(StatedSharpening {
            hint: stated.map(|(h, _)| h),
            smooth_factor: stated.map_or(2.0, |(_, f)| f),
            curved_walls: stated.and_then(|_| SharpenHint::curved_walls_of(header)),
            passes: stated
                .and_then(|_| SharpenHint::passes_of(header))
                .unwrap_or(1),
            gray_labels: SharpenHint::gray_labels_of(header),
            vetoes,
            after_filter: SurfaceFilter::after_sharpening_of(header),
            projections: StatedProjection::all_of(header),
        })
    }

    /// True when the encoder measured no sharpening best: the plain decoded mesh (its
    /// surface filter included) is the stream's output.
    pub fn is_unsharpened(&self) -> bool {
        self.hint == Some(SharpenHint::Unsharpened)
    }

    /// The sharpening method it states (extended without a hint).
    pub fn method(&self) -> Method {
        match self.hint {
            Some(SharpenHint::Papers) => Method::Papers,
            _ => Method::Extended,
        }
    }

    /// The sharpener's options it states.
    pub fn options(&self) -> SharpenOptions {
        let opts = SharpenOptions::DEFAULT
            .with_method(self.method())
            .with_smooth_factor(self.smooth_factor)
            .with_passes(self.passes)
            .with_surface_gray_labels(self.gray_labels);
        match self.curved_walls {
            Some(w) => opts.with_curved_wall_factor(w),
            None => opts,
        }
    }

    /// The vetoes ready to replay in a sharpening run (`whet_sharpen::sharpen_judged`).
    pub fn veto_replay(&self) -> Option<VetoReplay> {
        self.vetoes
            .clone()
            .map(|v| VetoReplay::new(v.into_passes()))
    }

    /// The stream's filter for after sharpening (on the vertices the sharpener left alone,
    /// back to `decoded`'s), then its projections, on `sharpened`; the refused projections
    /// with why.
    pub fn finish(
        &self,
        decoded: &Mesh,
        sharpened: &mut Mesh,
    ) -> Vec<(StatedProjection, whet_sharpen::Error)> {
        self.after_filter.apply_after_sharpening(decoded, sharpened);
        StatedProjection::apply_all(&self.projections, sharpened)
    }

    /// What `whet decode --sharpen` writes for the `decoded` mesh of this stream with no
    /// option changed: the stated sharpening with its vetoes replayed, then
    /// [`Self::finish`]; `None` when the stream states no sharpening. A mesh the sharpener
    /// refuses as structurally broken is sharpened after `Mesh::make_manifold` (a swing
    /// stream always decodes to a manifold).
    pub fn apply(&self, decoded: &Mesh) -> Result<Option<StatedOutput>, whet_sharpen::Error> {
        self.apply_with(decoded, &mut EdgeSharpener::new(self.options()))
    }

    /// [`Self::apply`] with `engine` (its options set to the stream's), whose memory serves
    /// stream after stream: a server gives each output back to it
    /// (`EdgeSharpener::recycle`) once done. The output is [`Self::apply`]'s.
    pub fn apply_with(
        &self,
        decoded: &Mesh,
        engine: &mut EdgeSharpener,
    ) -> Result<Option<StatedOutput>, whet_sharpen::Error> {
        if self.is_unsharpened() {
            return Ok(None);
        }
        engine.set_options(self.options());
        let mut replay = self.veto_replay();
        let mut run = |m: &Mesh| match replay.as_mut() {
            Some(r) => engine.sharpen_judged(m, r),
            None => engine.sharpen(m),
        };
        let mut sharpened = match run(decoded) {
            Err(whet_sharpen::Error::InvalidInput(e)) if e.is_structural() => {
                let mut m = decoded.clone();
                m.make_manifold();
                run(&m)?
            }
            other => other?,
        };
        let mismatched_veto_passes = replay.map_or(0, |r| r.mismatched_passes());
        let skipped = self.finish(decoded, &mut sharpened.mesh);
        Ok(Some(StatedOutput {
            sharpened,
            mismatched_veto_passes,
            skipped,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use whet_format::{tag, Header, Mode};

    #[test]
    fn projections_run_planar_quadric_beside_crease_then_apex_whatever_the_field_order() {
        let h = Header::new(Mode::Swing, 3, 1)
            .with(tag::APEX_PROJECTION, 150u64)
            .with(tag::ANGLE_BITS, 7u64)
            .with(tag::BESIDE_PROJECTION, 25u64)
            .with(tag::CREASE_PROJECTION, 50u64)
            .with(tag::QUADRIC_PROJECTION, 25u64)
            .with(tag::PLANAR_TOLERANCE, 200u64);
        assert_eq!(
            StatedProjection::all_of(&h),
            [
                StatedProjection::Planar {
                    factor: 2.0,
                    angle_bits: 7
                },
                StatedProjection::Quadric {
                    factor: 0.25,
                    angle_bits: 7
                },
                StatedProjection::Beside {
                    factor: 0.25,
                    angle_bits: 7
                },
                StatedProjection::Crease { max_move: 0.5 },
                StatedProjection::Apex { max_move: 1.5 },
            ]
        );
        let names: Vec<_> = StatedProjection::all_of(&h)
            .iter()
            .map(|p| p.name())
            .collect();
        assert_eq!(
            names,
            [
                "planar-region",
                "local quadric",
                "beside-crease quadric",
                "crease",
                "apex"
            ]
        );
        // An exact stream states none, whatever its fields.
        let exact = Header::new(Mode::Exact, 3, 1).with(tag::CREASE_PROJECTION, 50u64);
        assert!(StatedProjection::all_of(&exact).is_empty());
    }

    #[test]
    fn a_header_without_sharpening_fields_states_the_defaults() {
        let exact = Header::new(Mode::Exact, 3, 1);
        let stated = StatedSharpening::of(&exact).unwrap();
        let default = StatedSharpening::default();
        assert_eq!(stated.options(), default.options());
        assert_eq!(
            stated.options(),
            SharpenOptions::DEFAULT
                .with_method(Method::Extended)
                .with_smooth_factor(2.0)
                .with_passes(1)
        );
        assert!(!stated.is_unsharpened());
        assert!(stated.vetoes.is_none() && stated.projections.is_empty());
        assert!(stated.veto_replay().is_none());
    }

    #[test]
    fn the_stated_method_factor_walls_and_passes_become_the_options() {
        let papers = SharpenHint::Papers.code();
        let h = Header::new(Mode::Swing, 3, 1)
            .with(tag::ANGLE_BITS, 6u64)
            .with(tag::SHARPEN_METHOD, papers)
            .with(tag::SHARPEN_SMOOTH_FACTOR, 150u64)
            .with(tag::SHARPEN_PASSES, 2u64);
        let stated = StatedSharpening::of(&h).unwrap();
        assert_eq!(stated.method(), Method::Papers);
        assert_eq!(
            stated.options(),
            SharpenOptions::DEFAULT
                .with_method(Method::Papers)
                .with_smooth_factor(1.5)
                .with_passes(2)
        );
        // Field 41 turns the gray-vertex labels of surface samplings on.
        let gray = h
            .with(tag::SHARPEN_METHOD, SharpenHint::Extended.code())
            .with(tag::SHARPEN_GRAY_LABELS, 1u64);
        assert_eq!(
            StatedSharpening::of(&gray).unwrap().options(),
            SharpenOptions::DEFAULT
                .with_smooth_factor(1.5)
                .with_passes(2)
                .with_surface_gray_labels(true)
        );
    }

    #[test]
    fn a_stream_stating_no_sharpening_applies_none() {
        let none = SharpenHint::Unsharpened.code();
        let h = Header::new(Mode::Swing, 3, 1).with(tag::SHARPEN_METHOD, none);
        let stated = StatedSharpening::of(&h).unwrap();
        assert!(stated.is_unsharpened());
        let tetra = Mesh::new(
            vec![
                whet_mesh::DVec3::ZERO,
                whet_mesh::DVec3::X,
                whet_mesh::DVec3::Y,
                whet_mesh::DVec3::Z,
            ],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
        );
        assert!(stated.apply(&tetra).unwrap().is_none());
    }
}
