//! The outputs' layout and names (`output`).

use runtime_kernels::output::*;

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
