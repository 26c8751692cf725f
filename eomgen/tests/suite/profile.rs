//! A section property's profile along a segment (`eomgen::model::Profile`).

use eomgen::model::*;

#[test]
fn values_between_the_points_are_linear() {
    let lin = Profile::Linear([2.0, 1.0]);
    assert_eq!(lin.at(0.25), 1.75);
    let table = Profile::Table {
        s: vec![0.0, 0.5, 1.0],
        value: vec![1.0, 3.0, 2.0],
    };
    assert_eq!(table.at(0.0), 1.0);
    assert_eq!(table.at(0.25), 2.0);
    assert_eq!(table.at(0.5), 3.0);
    assert_eq!(table.at(0.75), 2.5);
    assert_eq!(table.at(1.0), 2.0);
    assert_eq!((table.min(), table.max()), (1.0, 3.0));
}

#[test]
fn it_reads_and_writes_all_three_forms() {
    for text in [
        "v = 0.5",
        "v = [0.5, 0.25]",
        "v = { s = [0.0, 0.5, 1.0], value = [1.0, 2.0, 3.0] }",
    ] {
        let t: toml::Table = toml::from_str(text).unwrap();
        let p: Profile = t["v"].clone().try_into().unwrap();
        let back = toml::Value::try_from(&p).unwrap();
        assert_eq!(back, t["v"], "{text}");
    }
    for (text, says) in [
        ("v = [1.0, 2.0, 3.0]", "two numbers"),
        (
            "v = { s = [0.0, 0.4], value = [1.0, 2.0] }",
            "rising from 0 to 1",
        ),
        (
            "v = { s = [0.0, 1.0], value = [1.0] }",
            "as many s as values",
        ),
        ("v = \"thick\"", "a linear taper"),
    ] {
        let t: toml::Table = toml::from_str(text).unwrap();
        let e = t["v"].clone().try_into::<Profile>().unwrap_err();
        assert!(e.to_string().contains(says), "{text}: {e}");
    }
}
