//! Property tests: the model parser and the override parser never panic,
//! whatever they are given, and every rejection is located in the file.

use eomgen::load::parse_model;
use eomgen::model::Override;
use proptest::prelude::*;

const GOOD: &str = include_str!("../../../models/double_pendulum.toml");

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn arbitrary_text_never_panics(text in ".{0,400}") {
        let r = parse_model(&text, "fuzz.toml", false, &[]);
        if let Err(e) = r {
            prop_assert_eq!(e.file, "fuzz.toml");
        }
        let _ = parse_model(&text, "fuzz.json", true, &[]);
    }

    #[test]
    fn mutated_models_never_panic(pos in 0usize..GOOD.len(), len in 0usize..20, insert in "[-0-9a-z.=\\[\\],\" ]{0,12}") {
        let mut text = GOOD.to_string();
        let start = pos.min(text.len());
        let end = (start + len).min(text.len());
        if text.is_char_boundary(start) && text.is_char_boundary(end) {
            text.replace_range(start..end, &insert);
        }
        let _ = parse_model(&text, "m.toml", false, &[]);
    }

    #[test]
    fn arbitrary_overrides_never_panic(s in "[a-z0-9_.\\[\\]=,\" -]{0,40}") {
        if let Ok(o) = Override::parse(&s) {
            let _ = parse_model(GOOD, "m.toml", false, &[o]);
        }
    }
}

#[test]
fn overrides_reach_nested_values() {
    let o = Override::parse("tip.force=[0, -2, 0]").unwrap();
    let m = parse_model(GOOD, "m.toml", false, &[o]).unwrap();
    assert_eq!(m.tip.force, Some([0.0, -2.0, 0.0]));
    let o = Override::parse("segment.1.length=0.25").unwrap();
    let m = parse_model(GOOD, "m.toml", false, &[o]).unwrap();
    assert_eq!(m.segments[1].length, 0.25);
    let o = Override::parse("segment.0.method=rigid").unwrap();
    assert!(parse_model(GOOD, "m.toml", false, &[o]).is_ok());
}
