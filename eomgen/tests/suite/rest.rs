//! A segment's rest curvature as a model file gives it.

use eomgen::model::*;

fn read(text: &str) -> Result<RestCurvature, toml::de::Error> {
    let t: toml::Table = toml::from_str(text).unwrap();
    t["v"].clone().try_into()
}

#[test]
fn a_pair_is_k_y_k_z_in_3d_and_a_taper_in_the_plane() {
    let pair = read("v = [1.0, 2.0]").unwrap();
    let ([y, z], given) = pair.axes(true);
    assert_eq!((y.at(0.5), z.at(0.5), given), (1.0, 2.0, true));
    let ([y, z], given) = pair.axes(false);
    assert_eq!(
        (y.at(0.5), z.at(0.0), z.at(1.0), given),
        (0.0, 1.0, 2.0, false)
    );
    let ([y, z], given) = read("v = 3.0").unwrap().axes(true);
    assert_eq!((y.at(0.5), z.at(0.5), given), (0.0, 3.0, false));
    let tapered_z = read("v = [0.0, [1.0, 3.0]]").unwrap();
    assert_eq!(tapered_z.axes(true).0[1].at(0.5), 2.0);
    assert!(tapered_z.planar_error().is_some());
    let table = read("v = { s = [0.0, 1.0], value = [1.0, 3.0] }").unwrap();
    assert_eq!(table.axes(false).0[1].at(0.5), 2.0);
    assert!(read("v = [1.0, 2.0, 3.0]").is_err());
    for text in ["v = 2.5", "v = [0.5, 1.5]", "v = [0.0, [1.0, 3.0]]"] {
        let back = toml::Value::try_from(read(text).unwrap()).unwrap();
        let t: toml::Table = toml::from_str(text).unwrap();
        assert_eq!(back, t["v"], "{text}");
    }
}
