//! The layout of the `Outputs` kernel by name: the one place every writer
//! (the TMT sums, the link recursion, the parts) and reader of the outputs
//! finds where each sits.

use std::ops::Range;

/// The tip's position (x, y, z; m).
pub const TIP: Range<usize> = 0..3;
/// The kinetic energy (J).
pub const KINETIC: usize = 3;
/// The potential energy (J): gravity's, the springs', a constant tip
/// force's.
pub const POTENTIAL: usize = 4;
/// The tip frame's orientation as a unit quaternion (w, x, y, z; x
/// along the arm).
pub const ORIENTATION: Range<usize> = 5..9;
/// How many.
pub const COUNT: usize = 9;

/// The names of the outputs, in their layout (the constants above).
pub const OUTPUT_NAMES: [&str; N_OUTPUTS] = [
    "tip_x",
    "tip_y",
    "tip_z",
    "kinetic",
    "potential",
    "tip_qw",
    "tip_qx",
    "tip_qy",
    "tip_qz",
];

/// Number of outputs.
pub const N_OUTPUTS: usize = COUNT;

#[cfg(test)]
mod tests {
    use super::*;

    /// The names follow the layout: every slot named once, in order.
    #[test]
    fn the_names_follow_the_layout() {
        let mut slots: Vec<usize> = TIP.chain([KINETIC, POTENTIAL]).chain(ORIENTATION).collect();
        assert_eq!(slots.len(), COUNT);
        slots.sort();
        assert_eq!(slots, (0..COUNT).collect::<Vec<_>>());
        assert_eq!(OUTPUT_NAMES[TIP], ["tip_x", "tip_y", "tip_z"]);
        assert_eq!(OUTPUT_NAMES[KINETIC], "kinetic");
        assert_eq!(OUTPUT_NAMES[POTENTIAL], "potential");
        assert_eq!(
            OUTPUT_NAMES[ORIENTATION],
            ["tip_qw", "tip_qx", "tip_qy", "tip_qz"]
        );
    }
}
