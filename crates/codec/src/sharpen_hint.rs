//! The sharpening a swing stream's encoder measured best for `whet decode --sharpen`
//! (optional header fields 21 and 23, docs/format.md section 3; docs/swing.md section 2,
//! "Which sharpening").
//!
//! whet-codec does not carry the sharpener: this is only the value the stream states, which
//! the caller maps onto whet-sharpen's methods.

/// What `whet decode --sharpen` should do with a swing stream, as its encoder measured it
/// against the original (`--optimize-for sharpened`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SharpenHint {
    /// EdgeSharpener's extended method (whet's default).
    Extended,
    /// The papers' method.
    Papers,
    /// No sharpening: no method and smooth factor the encoder tried beat the decoded mesh
    /// by its margin (a part without a real crease, like rocker_arm's blends).
    Unsharpened,
}

impl SharpenHint {
    /// Every hint, in code order.
    pub const ALL: [SharpenHint; 3] = [
        SharpenHint::Extended,
        SharpenHint::Papers,
        SharpenHint::Unsharpened,
    ];

    /// The value of header field 21.
    pub const fn code(self) -> u64 {
        match self {
            SharpenHint::Extended => 0,
            SharpenHint::Papers => 1,
            SharpenHint::Unsharpened => 2,
        }
    }

    /// The hint of a field value; `None` for a value this whet does not know (a newer
    /// encoder's: the decoder then sharpens with its default).
    pub const fn from_code(code: u64) -> Option<SharpenHint> {
        match code {
            0 => Some(SharpenHint::Extended),
            1 => Some(SharpenHint::Papers),
            2 => Some(SharpenHint::Unsharpened),
            _ => None,
        }
    }

    /// Name shown by the CLI (`extended`, `papers`, `none`).
    pub const fn name(self) -> &'static str {
        match self {
            SharpenHint::Extended => "extended",
            SharpenHint::Papers => "papers",
            SharpenHint::Unsharpened => "none",
        }
    }

    /// The smooth factor a swing stream's header states for its sharpening (field 23, in
    /// hundredths): `None` without the field, for other modes, or outside
    /// [`Self::SMOOTH_FACTOR_HUNDREDTHS`].
    pub fn smooth_factor_of(header: &whet_format::Header) -> Option<f64> {
        if header.mode != whet_format::Mode::Swing {
            return None;
        }
        header
            .get_u64(whet_format::tag::SHARPEN_SMOOTH_FACTOR)
            .filter(|h| Self::SMOOTH_FACTOR_HUNDREDTHS.contains(h))
            .map(|h| h as f64 / 100.0)
    }

    /// The smooth factors field 23 can state, in hundredths (0.01 to 10).
    pub const SMOOTH_FACTOR_HUNDREDTHS: std::ops::RangeInclusive<u64> = 1..=1000;

    /// Field 23's value for `factor` (rounded to hundredths), `None` outside the range.
    pub fn smooth_factor_code(factor: f64) -> Option<u64> {
        let h = (factor * 100.0).round();
        (1.0..=1000.0).contains(&h).then_some(h as u64)
    }

    /// What a stream's header states for `whet decode --sharpen`: its hint (field 21) and
    /// the smooth factor that goes with it (field 23; 2 when absent or out of range). `None`
    /// without a hint this whet knows, and then field 23 is not read either: a factor goes
    /// with its method only.
    pub fn stated(header: &whet_format::Header) -> Option<(SharpenHint, f64)> {
        let hint = Self::of(header)?;
        Some((hint, Self::smooth_factor_of(header).unwrap_or(2.0)))
    }

    /// The curved-wall factor a swing stream's header states for its sharpening (field 27, in
    /// hundredths; `whet_sharpen::SharpenOptions::curved_wall_factor`): `Some(0.0)` for off
    /// (value 0), the factor for a value in [`Self::CURVED_WALL_HUNDREDTHS`]; `None` (off, the
    /// sharpener's default) without the field, with another value, for other modes, or
    /// without a hint this whet knows (the factor goes with its method, as field 23 does).
    pub fn curved_walls_of(header: &whet_format::Header) -> Option<f64> {
        Self::of(header)?;
        header
            .get_u64(whet_format::tag::SHARPEN_CURVED_WALLS)
            .filter(|&h| h == 0 || Self::CURVED_WALL_HUNDREDTHS.contains(&h))
            .map(|h| h as f64 / 100.0)
    }

    /// The curved-wall factors field 27 can state, in hundredths (1 to 4, the range
    /// `SharpenOptions::validate` accepts besides 0).
    pub const CURVED_WALL_HUNDREDTHS: std::ops::RangeInclusive<u64> = 100..=400;

    /// Field 27's value for `factor` (0 for off; otherwise rounded to hundredths), `None`
    /// outside the range.
    pub fn curved_walls_code(factor: f64) -> Option<u64> {
        if factor == 0.0 {
            return Some(0);
        }
        let h = (factor * 100.0).round();
        (100.0..=400.0).contains(&h).then_some(h as u64)
    }

    /// The EdgeSharpener passes a swing stream's header states with its sharpening (field
    /// 29; `whet_sharpen::SharpenOptions::passes`): `None` (one) without the field, with a
    /// value outside [`Self::PASSES`], for other modes, or without a hint this whet knows.
    pub fn passes_of(header: &whet_format::Header) -> Option<u32> {
        Self::of(header)?;
        header
            .get_u64(whet_format::tag::SHARPEN_PASSES)
            .filter(|p| Self::PASSES.contains(p))
            .map(|p| p as u32)
    }

    /// The pass counts field 29 can state (`whet_sharpen::MAX_PASSES` is 4).
    pub const PASSES: std::ops::RangeInclusive<u64> = 1..=4;

    /// Whether a swing stream's header states gray-vertex labels on surface samplings with
    /// its sharpening (field 41 at 1; `whet_sharpen::SharpenOptions::surface_gray_labels`):
    /// false (the sharpener's default) without the field, with another value, for other
    /// modes, or without a hint this whet knows.
    pub fn gray_labels_of(header: &whet_format::Header) -> bool {
        Self::of(header).is_some()
            && header.get_u64(whet_format::tag::SHARPEN_GRAY_LABELS) == Some(1)
    }

    /// The planar-region projection a swing stream's header states for after sharpening
    /// (field 25): its tolerance factor (the field's hundredths over 100, in angle steps)
    /// and the stream's angle bits, for `whet_sharpen::PlanarOptions::for_swing`. `None`
    /// without the field, for other modes, or with a value outside
    /// [`Self::SMOOTH_FACTOR_HUNDREDTHS`] (the same 0.01 to 10 range).
    pub fn planar_of(header: &whet_format::Header) -> Option<(f64, u32)> {
        Self::angle_step_factor(header, whet_format::tag::PLANAR_TOLERANCE)
    }

    /// The local quadric projection a swing stream's header states for after sharpening
    /// and the planar-region projection (field 31): its move limit (the field's hundredths
    /// over 100, in angle steps) and the stream's angle bits, for
    /// `whet_sharpen::QuadricOptions::for_swing`; `None` as for [`Self::planar_of`].
    pub fn quadric_of(header: &whet_format::Header) -> Option<(f64, u32)> {
        Self::angle_step_factor(header, whet_format::tag::QUADRIC_PROJECTION)
    }

    /// The one-sided quadric projection of the vertices beside creases a swing stream's
    /// header states (field 37): its move limit (the field's hundredths over 100, in angle
    /// steps) and the stream's angle bits, for `whet_sharpen::BesideOptions::for_swing`;
    /// `None` as for [`Self::planar_of`].
    pub fn beside_of(header: &whet_format::Header) -> Option<(f64, u32)> {
        Self::angle_step_factor(header, whet_format::tag::BESIDE_PROJECTION)
    }

    /// The crease projection a swing stream's header states for after sharpening and the
    /// two other projections (field 35): its move limit in mean edge lengths (the field's
    /// hundredths over 100), for `whet_sharpen::CreaseOptions::with_max_move`. `None`
    /// without the field, for other modes, or with a value outside
    /// [`Self::SMOOTH_FACTOR_HUNDREDTHS`].
    pub fn crease_of(header: &whet_format::Header) -> Option<f64> {
        if header.mode != whet_format::Mode::Swing {
            return None;
        }
        header
            .get_u64(whet_format::tag::CREASE_PROJECTION)
            .filter(|h| Self::SMOOTH_FACTOR_HUNDREDTHS.contains(h))
            .map(|h| h as f64 / 100.0)
    }

    /// The apex restoration a swing stream's header states for after sharpening and every
    /// other projection (field 39): its move limit in mean edge lengths (the field's
    /// hundredths over 100), for `whet_sharpen::ApexOptions::with_max_move`. `None` as for
    /// [`Self::crease_of`].
    pub fn apex_of(header: &whet_format::Header) -> Option<f64> {
        if header.mode != whet_format::Mode::Swing {
            return None;
        }
        header
            .get_u64(whet_format::tag::APEX_PROJECTION)
            .filter(|h| Self::SMOOTH_FACTOR_HUNDREDTHS.contains(h))
            .map(|h| h as f64 / 100.0)
    }

    /// A swing header's field `tag` as a factor in hundredths of the angle step, with the
    /// stream's angle bits.
    fn angle_step_factor(header: &whet_format::Header, tag: u64) -> Option<(f64, u32)> {
        if header.mode != whet_format::Mode::Swing {
            return None;
        }
        let factor = header
            .get_u64(tag)
            .filter(|h| Self::SMOOTH_FACTOR_HUNDREDTHS.contains(h))?;
        let bits = header
            .get_u64(whet_format::tag::ANGLE_BITS)
            .and_then(|b| u32::try_from(b).ok())?;
        Some((factor as f64 / 100.0, bits))
    }

    /// The hint a stream's header states: swing streams only, `None` without the field or
    /// with an unknown value.
    pub fn of(header: &whet_format::Header) -> Option<SharpenHint> {
        if header.mode != whet_format::Mode::Swing {
            return None;
        }
        header
            .get_u64(whet_format::tag::SHARPEN_METHOD)
            .and_then(SharpenHint::from_code)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planar_tolerance_is_read_from_swing_headers_only_and_in_range() {
        let swing = whet_format::Header::new(whet_format::Mode::Swing, 3, 1)
            .with(whet_format::tag::ANGLE_BITS, 6u64);
        assert_eq!(SharpenHint::planar_of(&swing), None);
        let on = swing
            .clone()
            .with(whet_format::tag::PLANAR_TOLERANCE, 100u64);
        assert_eq!(SharpenHint::planar_of(&on), Some((1.0, 6)));
        for bad in [0u64, 1001] {
            let h = swing.clone().with(whet_format::tag::PLANAR_TOLERANCE, bad);
            assert_eq!(SharpenHint::planar_of(&h), None);
        }
        let exact = whet_format::Header::new(whet_format::Mode::Exact, 3, 1)
            .with(whet_format::tag::ANGLE_BITS, 6u64)
            .with(whet_format::tag::PLANAR_TOLERANCE, 100u64);
        assert_eq!(SharpenHint::planar_of(&exact), None);
    }

    #[test]
    fn crease_projection_is_read_from_swing_headers_only_and_in_range() {
        let swing = whet_format::Header::new(whet_format::Mode::Swing, 3, 1)
            .with(whet_format::tag::ANGLE_BITS, 6u64);
        assert_eq!(SharpenHint::crease_of(&swing), None);
        let on = swing
            .clone()
            .with(whet_format::tag::CREASE_PROJECTION, 25u64);
        assert_eq!(SharpenHint::crease_of(&on), Some(0.25));
        for bad in [0u64, 1001] {
            let h = swing.clone().with(whet_format::tag::CREASE_PROJECTION, bad);
            assert_eq!(SharpenHint::crease_of(&h), None);
        }
        let exact = whet_format::Header::new(whet_format::Mode::Exact, 3, 1)
            .with(whet_format::tag::CREASE_PROJECTION, 25u64);
        assert_eq!(SharpenHint::crease_of(&exact), None);
    }

    #[test]
    fn apex_projection_is_read_from_swing_headers_only_and_in_range() {
        let swing = whet_format::Header::new(whet_format::Mode::Swing, 3, 1);
        assert_eq!(SharpenHint::apex_of(&swing), None);
        let on = swing
            .clone()
            .with(whet_format::tag::APEX_PROJECTION, 150u64);
        assert_eq!(SharpenHint::apex_of(&on), Some(1.5));
        for bad in [0u64, 1001] {
            let h = swing.clone().with(whet_format::tag::APEX_PROJECTION, bad);
            assert_eq!(SharpenHint::apex_of(&h), None);
        }
        let exact = whet_format::Header::new(whet_format::Mode::Exact, 3, 1)
            .with(whet_format::tag::APEX_PROJECTION, 150u64);
        assert_eq!(SharpenHint::apex_of(&exact), None);
    }

    #[test]
    fn quadric_projection_is_read_from_swing_headers_only_and_in_range() {
        let swing = whet_format::Header::new(whet_format::Mode::Swing, 3, 1)
            .with(whet_format::tag::ANGLE_BITS, 7u64);
        assert_eq!(SharpenHint::quadric_of(&swing), None);
        let on = swing
            .clone()
            .with(whet_format::tag::QUADRIC_PROJECTION, 50u64);
        assert_eq!(SharpenHint::quadric_of(&on), Some((0.5, 7)));
        // Field 25 and field 31 are read apart.
        assert_eq!(SharpenHint::planar_of(&on), None);
        for bad in [0u64, 1001] {
            let h = swing
                .clone()
                .with(whet_format::tag::QUADRIC_PROJECTION, bad);
            assert_eq!(SharpenHint::quadric_of(&h), None);
        }
        let exact = whet_format::Header::new(whet_format::Mode::Exact, 3, 1)
            .with(whet_format::tag::ANGLE_BITS, 6u64)
            .with(whet_format::tag::QUADRIC_PROJECTION, 50u64);
        assert_eq!(SharpenHint::quadric_of(&exact), None);
    }

    #[test]
    fn beside_projection_is_read_from_swing_headers_only_and_in_range() {
        let swing = whet_format::Header::new(whet_format::Mode::Swing, 3, 1)
            .with(whet_format::tag::ANGLE_BITS, 6u64);
        assert_eq!(SharpenHint::beside_of(&swing), None);
        let on = swing
            .clone()
            .with(whet_format::tag::BESIDE_PROJECTION, 25u64);
        assert_eq!(SharpenHint::beside_of(&on), Some((0.25, 6)));
        // Field 37 is read apart from field 31.
        assert_eq!(SharpenHint::quadric_of(&on), None);
        for bad in [0u64, 1001] {
            let h = swing.clone().with(whet_format::tag::BESIDE_PROJECTION, bad);
            assert_eq!(SharpenHint::beside_of(&h), None);
        }
        let exact = whet_format::Header::new(whet_format::Mode::Exact, 3, 1)
            .with(whet_format::tag::ANGLE_BITS, 6u64)
            .with(whet_format::tag::BESIDE_PROJECTION, 25u64);
        assert_eq!(SharpenHint::beside_of(&exact), None);
    }

    #[test]
    fn curved_walls_go_with_a_known_method_and_stay_in_range() {
        let swing = whet_format::Header::new(whet_format::Mode::Swing, 3, 1);
        let walls = swing
            .clone()
            .with(whet_format::tag::SHARPEN_CURVED_WALLS, 150u64);
        // Without field 21 the factor has no method to go with.
        assert_eq!(SharpenHint::curved_walls_of(&walls), None);
        let papers = walls.with(whet_format::tag::SHARPEN_METHOD, 1u64);
        assert_eq!(SharpenHint::curved_walls_of(&papers), Some(1.5));
        let off = papers
            .clone()
            .with(whet_format::tag::SHARPEN_CURVED_WALLS, 0u64);
        assert_eq!(SharpenHint::curved_walls_of(&off), Some(0.0));
        for bad in [1u64, 99, 401, u64::MAX] {
            let h = swing
                .clone()
                .with(whet_format::tag::SHARPEN_METHOD, 0u64)
                .with(whet_format::tag::SHARPEN_CURVED_WALLS, bad);
            assert_eq!(SharpenHint::curved_walls_of(&h), None, "{bad}");
        }
        let exact = whet_format::Header::new(whet_format::Mode::Exact, 3, 1)
            .with(whet_format::tag::SHARPEN_METHOD, 1u64)
            .with(whet_format::tag::SHARPEN_CURVED_WALLS, 150u64);
        assert_eq!(SharpenHint::curved_walls_of(&exact), None);
        assert_eq!(SharpenHint::curved_walls_code(1.5), Some(150));
        assert_eq!(SharpenHint::curved_walls_code(0.0), Some(0));
        assert_eq!(SharpenHint::curved_walls_code(0.5), None);
        assert_eq!(SharpenHint::curved_walls_code(4.004), Some(400));
        assert_eq!(SharpenHint::curved_walls_code(4.2), None);
    }

    #[test]
    fn passes_go_with_a_known_method_and_stay_in_range() {
        let swing = whet_format::Header::new(whet_format::Mode::Swing, 3, 1);
        let two = swing.clone().with(whet_format::tag::SHARPEN_PASSES, 2u64);
        assert_eq!(SharpenHint::passes_of(&two), None);
        let papers = two.with(whet_format::tag::SHARPEN_METHOD, 1u64);
        assert_eq!(SharpenHint::passes_of(&papers), Some(2));
        for bad in [0u64, 5, u64::MAX] {
            let h = papers.clone().with(whet_format::tag::SHARPEN_PASSES, bad);
            assert_eq!(SharpenHint::passes_of(&h), None, "{bad}");
        }
        let exact = whet_format::Header::new(whet_format::Mode::Exact, 3, 1)
            .with(whet_format::tag::SHARPEN_METHOD, 1u64)
            .with(whet_format::tag::SHARPEN_PASSES, 2u64);
        assert_eq!(SharpenHint::passes_of(&exact), None);
    }

    #[test]
    fn gray_labels_go_with_a_known_method_and_only_at_one() {
        let swing = whet_format::Header::new(whet_format::Mode::Swing, 3, 1);
        let on = swing
            .clone()
            .with(whet_format::tag::SHARPEN_GRAY_LABELS, 1u64);
        assert!(!SharpenHint::gray_labels_of(&on));
        let extended = on.with(whet_format::tag::SHARPEN_METHOD, 0u64);
        assert!(SharpenHint::gray_labels_of(&extended));
        for other in [0u64, 2, u64::MAX] {
            let h = extended
                .clone()
                .with(whet_format::tag::SHARPEN_GRAY_LABELS, other);
            assert!(!SharpenHint::gray_labels_of(&h), "{other}");
        }
        let unknown_method = swing
            .with(whet_format::tag::SHARPEN_METHOD, 7u64)
            .with(whet_format::tag::SHARPEN_GRAY_LABELS, 1u64);
        assert!(!SharpenHint::gray_labels_of(&unknown_method));
        let exact = whet_format::Header::new(whet_format::Mode::Exact, 3, 1)
            .with(whet_format::tag::SHARPEN_METHOD, 0u64)
            .with(whet_format::tag::SHARPEN_GRAY_LABELS, 1u64);
        assert!(!SharpenHint::gray_labels_of(&exact));
    }

    #[test]
    fn codes_round_trip_and_unknown_codes_are_no_hint() {
        for h in SharpenHint::ALL {
            assert_eq!(SharpenHint::from_code(h.code()), Some(h));
        }
        assert_eq!(SharpenHint::from_code(3), None);
        assert_eq!(SharpenHint::from_code(u64::MAX), None);
    }

    #[test]
    fn only_swing_headers_carry_a_hint() {
        let swing = whet_format::Header::new(whet_format::Mode::Swing, 0, 0);
        assert_eq!(SharpenHint::of(&swing), None);
        let papers = swing.clone().with(whet_format::tag::SHARPEN_METHOD, 1u64);
        assert_eq!(SharpenHint::of(&papers), Some(SharpenHint::Papers));
        let unknown = swing.with(whet_format::tag::SHARPEN_METHOD, 9u64);
        assert_eq!(SharpenHint::of(&unknown), None);
        let exact = whet_format::Header::new(whet_format::Mode::Exact, 0, 0)
            .with(whet_format::tag::SHARPEN_METHOD, 2u64)
            .with(whet_format::tag::SHARPEN_SMOOTH_FACTOR, 150u64);
        assert_eq!(SharpenHint::of(&exact), None);
        assert_eq!(SharpenHint::smooth_factor_of(&exact), None);
    }

    #[test]
    fn smooth_factors_are_hundredths_within_range() {
        let swing = whet_format::Header::new(whet_format::Mode::Swing, 0, 0);
        assert_eq!(SharpenHint::smooth_factor_of(&swing), None);
        for (code, factor) in [(1u64, Some(0.01)), (150, Some(1.5)), (1000, Some(10.0))] {
            let h = swing
                .clone()
                .with(whet_format::tag::SHARPEN_SMOOTH_FACTOR, code);
            assert_eq!(SharpenHint::smooth_factor_of(&h), factor);
        }
        for code in [0u64, 1001, u64::MAX] {
            let h = swing
                .clone()
                .with(whet_format::tag::SHARPEN_SMOOTH_FACTOR, code);
            assert_eq!(SharpenHint::smooth_factor_of(&h), None, "{code}");
        }
        assert_eq!(SharpenHint::smooth_factor_code(1.5), Some(150));
        assert_eq!(SharpenHint::smooth_factor_code(2.0), Some(200));
        assert_eq!(SharpenHint::smooth_factor_code(0.0), None);
        assert_eq!(SharpenHint::smooth_factor_code(f64::NAN), None);
        assert_eq!(SharpenHint::smooth_factor_code(11.0), None);
    }

    #[test]
    fn a_factor_is_stated_only_with_a_known_method() {
        let factor = whet_format::Header::new(whet_format::Mode::Swing, 0, 0)
            .with(whet_format::tag::SHARPEN_SMOOTH_FACTOR, 150u64);
        assert_eq!(SharpenHint::stated(&factor), None);
        let unknown = factor.clone().with(whet_format::tag::SHARPEN_METHOD, 7u64);
        assert_eq!(SharpenHint::stated(&unknown), None);
        let papers = factor.clone().with(whet_format::tag::SHARPEN_METHOD, 1u64);
        assert_eq!(
            SharpenHint::stated(&papers),
            Some((SharpenHint::Papers, 1.5))
        );
        let default = whet_format::Header::new(whet_format::Mode::Swing, 0, 0)
            .with(whet_format::tag::SHARPEN_METHOD, 0u64);
        assert_eq!(
            SharpenHint::stated(&default),
            Some((SharpenHint::Extended, 2.0))
        );
    }
}
