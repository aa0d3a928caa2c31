//! A model's right-hand side for several runs at once, lane by lane: what
//! the ensemble integrator (`integrate::ensemble`) asks of a model that can
//! evaluate [`LANES`] states in one call.

use crate::lanes::{Lanes, LANES};
use crate::model::{Modes, System};

/// A right-hand side evaluated for [`LANES`] runs at once, lane-wise, for
/// `integrate::ensemble::simulate_ensemble_lanes`: the stage combinations already run across
/// lanes; with this the slopes do too, and no lane's state is copied out of
/// (or its slope into) the lane-wise arrays.
///
/// The contract is [`System::field`]'s, lane by lane and bit for bit: each
/// lane's slope must come from the same IEEE operations in the same order as
/// `field` on that lane's model, state and time (lane-wise products, sums
/// and quotients of [`Lanes`] are the scalar ones). A call may leave lanes
/// out (e.g. a mode it does not cover): those lanes are then evaluated by
/// [`System::field`].
pub trait LaneField<const N: usize>: System<N> + Sized {
    /// What the lane-wise field needs of the lanes' models, gathered once
    /// per change of the lanes' jobs (not on every call).
    type Pack;
    /// What the lane-wise field needs of the lanes' modes, made once per
    /// attempt (the modes hold over a step's stages).
    type Masks;
    /// The pack of the lanes' models (`None`: an empty lane); `None` if these
    /// models cannot be evaluated lane-wise (every call then falls back to
    /// [`System::field`]).
    fn pack(models: [Option<&Self>; LANES]) -> Option<Self::Pack>;
    /// The masks of the lanes' `modes` (`None`: an idle lane), and the
    /// lanes that [`field_masked`](Self::field_masked) computes with them;
    /// the others are left to [`System::field`].
    fn masks(modes: &[Option<Modes>; LANES]) -> (Self::Masks, [bool; LANES]);
    /// `dz = f(t, z)` lane by lane, each lane in the modes of `masks`. The
    /// `dz` of lanes it does not compute may hold anything.
    fn field_masked(
        pack: &Self::Pack,
        masks: &Self::Masks,
        t: Lanes,
        z: &[Lanes; N],
        dz: &mut [Lanes; N],
    );
    /// `dz = f(t, z)` lane by lane, each lane in its own `modes`
    /// (`None`: an idle lane, whose `dz` is not used). Returns the lanes it
    /// computed; the others' `dz` may hold anything (they are computed
    /// again by [`System::field`]).
    fn field_lanes(
        pack: &Self::Pack,
        t: Lanes,
        modes: &[Option<Modes>; LANES],
        z: &[Lanes; N],
        dz: &mut [Lanes; N],
    ) -> [bool; LANES] {
        let (masks, done) = Self::masks(modes);
        if done.contains(&true) {
            Self::field_masked(pack, &masks, t, z, dz);
        }
        done
    }
}
