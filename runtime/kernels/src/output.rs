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
