//! The snaps of `whet decode --sharpen` that a swing stream's encoder vetoed (optional header
//! field 33, docs/format.md section 3; docs/sharpen.md, "Snap vetoes").
//!
//! A decoder-side sharpener cannot tell a chamfer across a sharp crease from one across a
//! fillet about an edge wide: it snaps both, and the second ends farther from the original
//! than it was. The encoder holds the original, runs the sharpening the stream states on the
//! mesh the decoder will sharpen, and vetoes the snaps it measures worse. whet-codec does not
//! carry the sharpener: this is only the list, pass by pass, in the order the sharpener puts
//! its snaps to a judge (`whet_sharpen::SnapJudge`).

use whet_bits::{CountingBitModel, RangeDecoder, RangeEncoder};
use whet_format::{read_varint, write_varint};

use crate::Error;

/// The most judgements a stream can state: two per sharpening pass
/// (`whet_sharpen::MAX_PASSES` is 4), since a pass on a welded mesh whose splits all came
/// undone runs again unwelded and asks again.
pub const MAX_VETO_PASSES: usize = 8;

/// Per sharpening pass, whether each snap the sharpener put to its judge is vetoed.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SnapVetoes {
    passes: Vec<Vec<bool>>,
}

impl SnapVetoes {
    /// Vetoes of `passes` (at most [`MAX_VETO_PASSES`]; later ones are dropped).
    pub fn new(mut passes: Vec<Vec<bool>>) -> SnapVetoes {
        passes.truncate(MAX_VETO_PASSES);
        SnapVetoes { passes }
    }

    /// The flags, pass by pass.
    pub fn passes(&self) -> &[Vec<bool>] {
        &self.passes
    }

    /// The flags, pass by pass, taken out (for `whet_sharpen::VetoReplay::new`).
    pub fn into_passes(self) -> Vec<Vec<bool>> {
        self.passes
    }

    /// How many snaps were judged.
    pub fn judged(&self) -> usize {
        self.passes.iter().map(Vec::len).sum()
    }

    /// How many were vetoed.
    pub fn vetoed(&self) -> usize {
        self.passes.iter().flatten().filter(|&&v| v).count()
    }

    /// The value of field 33: the pass count, each pass's snap count (varints), then the
    /// flags through one adaptive binary model per previous flag of the same pass (vetoes
    /// come in runs along a fillet), range coded.
    pub fn to_field(&self) -> Vec<u8> {
        let mut out = Vec::new();
        write_varint(&mut out, self.passes.len() as u64);
        for p in &self.passes {
            write_varint(&mut out, p.len() as u64);
        }
        let mut enc = RangeEncoder::new();
        let mut models = [CountingBitModel::default(), CountingBitModel::default()];
        for p in &self.passes {
            let mut previous = false;
            for &veto in p {
                enc.encode_counting_bit(&mut models[previous as usize], veto);
                previous = veto;
            }
        }
        out.extend_from_slice(&enc.finish());
        out
    }

    /// Reads field 33's value. `max_snaps` bounds the flags it may hold (a hostile field
    /// cannot make the reader allocate more); more passes than [`MAX_VETO_PASSES`], more
    /// snaps than `max_snaps`, or a truncated value is an error naming the field.
    pub fn from_field(bytes: &[u8], max_snaps: u64) -> Result<SnapVetoes, Error> {
        let bad = |what: &str| Error::Corrupt(format!("header field 33 (snap_vetoes): {what}"));
        let mut pos = 0;
        let count = read_varint(bytes, &mut pos).map_err(|_| bad("truncated pass count"))?;
        if count == 0 || count > MAX_VETO_PASSES as u64 {
            return Err(bad(&format!(
                "{count} passes (1 to {MAX_VETO_PASSES} can be judged)"
            )));
        }
        let mut lens = Vec::with_capacity(count as usize);
        let mut total = 0u64;
        for _ in 0..count {
            let n = read_varint(bytes, &mut pos).map_err(|_| bad("truncated snap count"))?;
            total = total.saturating_add(n);
            if total > max_snaps {
                return Err(bad(&format!(
                    "more snaps ({total}) than a sharpening of this mesh can make \
                     ({max_snaps})"
                )));
            }
            lens.push(n as usize);
        }
        let mut dec = RangeDecoder::new(&bytes[pos..]).map_err(|_| bad("truncated flags"))?;
        let mut models = [CountingBitModel::default(), CountingBitModel::default()];
        let mut passes = Vec::with_capacity(lens.len());
        for n in lens {
            let mut flags = Vec::with_capacity(n);
            let mut previous = false;
            for _ in 0..n {
                let veto = dec.decode_counting_bit(&mut models[previous as usize]);
                flags.push(veto);
                previous = veto;
            }
            passes.push(flags);
        }
        if dec.overran() {
            return Err(bad("truncated flags"));
        }
        Ok(SnapVetoes { passes })
    }

    /// The most snaps a stream of `vertices` and `triangles` may state vetoes for, over all
    /// its judgements: four times one snap per vertex, per edge and per triangle (a first
    /// pass snaps at most one of each; later passes and repeated judgements snap few). The
    /// encoder leaves the field out beyond it, so a reader can hold a hostile field to it
    /// (14 bytes of flags per triangle at most, against the sharpener's 200).
    pub fn max_snaps(vertices: u64, triangles: u64) -> u64 {
        vertices
            .saturating_add(triangles.saturating_mul(3))
            .saturating_mul(4)
            .saturating_add(64)
    }

    /// The vetoes a swing stream's header states: `None` without field 33 or for other
    /// modes; at most [`Self::max_snaps`] of the header's counts.
    pub fn of(header: &whet_format::Header) -> Option<Result<SnapVetoes, Error>> {
        if header.mode != whet_format::Mode::Swing {
            return None;
        }
        let bytes = header.get_bytes(whet_format::tag::SNAP_VETOES)?;
        let max = Self::max_snaps(header.vertex_count, header.triangle_count);
        Some(SnapVetoes::from_field(bytes, max))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn sparse_vetoes_cost_a_few_bytes() {
        let mut flags = vec![false; 1000];
        for i in [17, 400, 401, 402, 900] {
            flags[i] = true;
        }
        let v = SnapVetoes::new(vec![flags]);
        let field = v.to_field();
        // 3 bytes of counts, then 5 vetoes among 1000 flags: about 80 bits of flags.
        assert!(field.len() <= 20, "{} bytes", field.len());
        assert_eq!(SnapVetoes::from_field(&field, 1000).unwrap(), v);
        assert_eq!((v.judged(), v.vetoed()), (1000, 5));
    }

    #[test]
    fn hostile_fields_are_refused_by_name() {
        let v = SnapVetoes::new(vec![vec![true; 10], vec![false, true]]);
        let field = v.to_field();
        // More snaps than the mesh allows.
        let e = SnapVetoes::from_field(&field, 11).unwrap_err().to_string();
        assert!(e.contains("field 33") && e.contains("more snaps"), "{e}");
        // No pass, too many passes, an empty value, a value cut in its counts.
        for bad in [&[0u8][..], &[9, 1, 1, 1, 1, 1], &[], &[1, 0x80]] {
            let e = SnapVetoes::from_field(bad, 100).unwrap_err().to_string();
            assert!(e.contains("snap_vetoes"), "{e}");
        }
        // A count that needs far more flag bytes than follow.
        let e = SnapVetoes::from_field(&[1, 0xe8, 0x07, 0x12], 5000).unwrap_err();
        assert!(e.to_string().contains("truncated"), "{e}");
    }

    #[test]
    fn the_header_bounds_the_flags_and_other_modes_have_none() {
        let field = SnapVetoes::new(vec![vec![true; 50]]).to_field();
        let swing = whet_format::Header::new(whet_format::Mode::Swing, 3, 1)
            .with(whet_format::tag::SNAP_VETOES, field.clone());
        // 3 vertices and 1 triangle: at most 4 · 6 + 64 = 88 snaps.
        assert_eq!(SnapVetoes::max_snaps(3, 1), 88);
        assert!(SnapVetoes::of(&swing).unwrap().is_ok());
        let big = SnapVetoes::new(vec![vec![true; 89]]).to_field();
        let over = whet_format::Header::new(whet_format::Mode::Swing, 3, 1)
            .with(whet_format::tag::SNAP_VETOES, big);
        assert!(SnapVetoes::of(&over).unwrap().is_err());
        let exact = whet_format::Header::new(whet_format::Mode::Exact, 3, 1)
            .with(whet_format::tag::SNAP_VETOES, field);
        assert!(SnapVetoes::of(&exact).is_none());
    }

    proptest! {
        #[test]
        fn vetoes_round_trip(passes in proptest::collection::vec(
            proptest::collection::vec(any::<bool>(), 0..300), 1..=MAX_VETO_PASSES)) {
            let v = SnapVetoes::new(passes);
            let field = v.to_field();
            prop_assert_eq!(SnapVetoes::from_field(&field, v.judged() as u64).unwrap(), v);
        }

        #[test]
        fn garbage_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..64)) {
            let _ = SnapVetoes::from_field(&bytes, 10_000);
        }
    }
}
