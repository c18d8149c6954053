//! Snap vetoes: a caller that holds the original surface rules on each snap before the
//! sharpener settles the mesh (docs/sharpen.md, "Snap vetoes").
//!
//! Without the original, a chamfer across a sharp crease and one across a fillet about an
//! edge wide look alike: both strips turn as much, both sides are flat. Snapping the first
//! removes its error; snapping the second puts a corner `(√2 − 1) r` outside a fillet of
//! radius `r`, farther than the chamfer was. A swing encoder has the original, so it judges
//! every snap and states the vetoes in the stream; the decoder replays them through the same
//! hook, in the same order, on the same mesh.

use glam::DVec3;

/// One snap of a pass, as a [`SnapJudge`] sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct Snap {
    /// Where the vertex stays if the snap is vetoed: the midpoint of a chamfer edge, the
    /// centroid of a corner triangle, or a moved input vertex's input position.
    pub rest: DVec3,
    /// Where the snap puts it.
    pub snapped: DVec3,
    /// Where the vertices the new vertex was inserted between are (the ends of its chamfer
    /// edge, the corners of its corner triangle): the new edges run from them to it. Empty
    /// for a moved input vertex.
    pub origins: Vec<DVec3>,
}

/// Rules on the snaps of a sharpening pass ([`crate::EdgeSharpener::sharpen_judged`]).
///
/// Called once per pass that snapped anything, after the snaps and before the orientation
/// and sliver checks, with the pass's snaps in a fixed order: the moved input vertices by
/// increasing index, then the new vertices by increasing index. The same input and options
/// give the same calls, so an encoder's judge and a decoder's replay of its answers agree.
pub trait SnapJudge {
    /// Whether each of `snaps` is vetoed (`true`: the vertex goes back to its rest
    /// position). A shorter answer keeps the snaps it does not reach.
    fn vetoes(&mut self, snaps: &[Snap]) -> Vec<bool>;
}

/// Replays the vetoes a stream states (`whet_codec::SnapVetoes`), pass by pass. A pass that
/// puts a different number of snaps than the stream states for it (a stream made for
/// another sharpening, or by another version of the sharpener) keeps all its snaps and is
/// counted in [`VetoReplay::mismatched_passes`].
#[derive(Clone, Debug, Default)]
pub struct VetoReplay {
    passes: Vec<Vec<bool>>,
    next: usize,
    mismatched: usize,
    applied: usize,
}

impl VetoReplay {
    /// Replays `passes`, the flags of each pass in the order the sharpener asks.
    pub fn new(passes: Vec<Vec<bool>>) -> VetoReplay {
        VetoReplay {
            passes,
            ..VetoReplay::default()
        }
    }

    /// Passes whose snaps did not match the stated ones (their vetoes were not applied),
    /// plus stated passes the sharpener never asked about.
    pub fn mismatched_passes(&self) -> usize {
        self.mismatched + self.passes.len().saturating_sub(self.next)
    }

    /// Vetoes applied.
    pub fn applied(&self) -> usize {
        self.applied
    }
}

impl SnapJudge for VetoReplay {
    fn vetoes(&mut self, snaps: &[Snap]) -> Vec<bool> {
        let stated = self.passes.get(self.next);
        self.next += 1;
        match stated {
            Some(flags) if flags.len() == snaps.len() => {
                self.applied += flags.iter().filter(|&&v| v).count();
                flags.clone()
            }
            _ => {
                self.mismatched += 1;
                Vec::new()
            }
        }
    }
}
