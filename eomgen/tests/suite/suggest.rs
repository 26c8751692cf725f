//! The nearest allowed name suggested for a misspelt key.

use eomgen::model::*;

#[test]
fn the_nearest_allowed_name_is_suggested() {
    let m = "unknown field `lenght`, expected one of `method`, `length`, `elements`";
    assert!(
        with_suggestion(m).ends_with("did you mean `length`?"),
        "{}",
        with_suggestion(m)
    );
    let far = "unknown field `colour`, expected one of `name`, `gravity`";
    assert_eq!(with_suggestion(far), far);
    let variant = "unknown variant `radua5`, expected one of `dopri5`, `radau5`";
    assert!(with_suggestion(variant).ends_with("did you mean `radau5`?"));
    assert_eq!(distance("kitten", "sitting"), 3);
}
