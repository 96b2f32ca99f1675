//! A user's own impulse sequence, validated like any shaper.
//!
//! `{ family: "custom", impulses: [{ time, amplitude }], normalize }`: the impulses in any
//! order; impulses at the same time are merged and the sequence is shifted to start at t = 0
//! ([`Shaper::new`]). With `normalize: true` the amplitudes are divided by their sum so it is 1
//! (an error if they sum to 0). The modes of the request are validated but not used: a custom
//! shaper promises nothing beyond being a valid sequence — analyse it with the sensitivity
//! curve and V at the modes.

use crate::error::Result;
use crate::shaper::{Impulse, Shaper};

/// The shaper with these impulses, optionally normalised to Σ Aᵢ = 1.
///
/// ```
/// use input_shaping::{design::custom::custom, Impulse};
/// let impulses = [Impulse { time: 0.2, amplitude: 2.0 }, Impulse { time: 0.1, amplitude: 2.0 }];
/// let shaper = custom(&impulses, true)?; // sorted, shifted to start at 0, summing to 1
/// assert_eq!(shaper.impulses(), [Impulse { time: 0.0, amplitude: 0.5 }, Impulse { time: 0.1, amplitude: 0.5 }]);
/// # Ok::<(), input_shaping::Error>(())
/// ```
pub fn custom(impulses: &[Impulse], normalize: bool) -> Result<Shaper> {
    let shaper = Shaper::new(impulses.to_vec())?;
    if normalize {
        shaper.normalized()
    } else {
        Ok(shaper)
    }
}
