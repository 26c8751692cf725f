//! `softarm animate`: the GIF has a frame per 1/fps s of playback at the
//! requested size in the drawing's own colours, and the viewer page carries the run: its tip path is
//! trajectory.csv's tip and its arm rows are shape.csv's. (The page itself
//! is checked in a real browser by scripts/check_viewer.py, which CI runs.)

use crate::common::*;
use softarm::data::Csv;
use std::collections::HashSet;

fn frames(path: &std::path::Path) -> (usize, (u16, u16)) {
    let (n, size, _) = decode(path);
    (n, size)
}

/// The frame count, the size and the last frame's colours.
fn decode(path: &std::path::Path) -> (usize, (u16, u16), HashSet<[u8; 3]>) {
    let file = std::fs::File::open(path).expect("animation.gif exists");
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut d = options.read_info(file).expect("a GIF");
    let size = (d.width(), d.height());
    let mut n = 0;
    let mut colours = HashSet::new();
    while let Some(frame) = d.read_next_frame().expect("frames decode") {
        n += 1;
        colours = frame
            .buffer
            .chunks_exact(4)
            .map(|p| [p[0], p[1], p[2]])
            .collect();
    }
    (n, size, colours)
}

#[test]
fn the_gif_has_a_frame_per_step_of_playback_and_the_page_the_runs_tip() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = softarm(
        &[
            "animate",
            "soft_finger",
            "--t-end",
            "1",
            "--fps",
            "10",
            "--speed",
            "0.5",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let run = out.join("soft_finger");
    // 1 s at half speed: 2 s of GIF at 10 frames a second, both ends.
    let (n, size, colours) = decode(&run.join("animation.gif"));
    assert_eq!((n, size), (21, (480, 480)));
    // The drawing's flat colours arrive exactly through the frame's
    // palette: the white ground, the tip path's pure red, the clamp's grey
    // and the black of the scale bar and the gravity arrow.
    for c in [[255, 255, 255], [255, 0, 0], [90, 90, 90], [0, 0, 0]] {
        assert!(colours.contains(&c), "{c:?} is not in the last frame");
    }
    let page = std::fs::read_to_string(run.join("viewer.html")).unwrap();
    let start = page.find(r#"type="application/json">"#).unwrap() + 24;
    let end = start + page[start..].find("</script>").unwrap();
    let scene: serde_json::Value = serde_json::from_str(&page[start..end]).unwrap();
    assert_eq!(scene["gravity"], serde_json::json!([0.0, -9.81, 0.0]));
    let traj = Csv::read(&run.join("trajectory.csv")).unwrap();
    let t = traj.column("t").unwrap();
    let tip_x = traj.column("tip_x").unwrap();
    let tip_y = traj.column("tip_y").unwrap();
    // Rows four times a GIF step: every 0.0125 s of simulated time.
    assert_eq!(t.len(), 81);
    for (i, p) in scene["tip"].as_array().unwrap().iter().enumerate() {
        // The tip path is trajectory.csv's, carried into the page intact
        // (a check of the page's data, not of the kinematics) ...
        assert_eq!(p[0].as_f64().unwrap(), tip_x[i]);
        assert_eq!(p[1].as_f64().unwrap(), tip_y[i]);
        // ... and the arm drawn at that frame, from shape.csv's own tape,
        // ends where the Outputs kernel put the tip (shape.csv's 9 digits):
        // the independent check.
        let rows = scene["parts"][0]["frames"][i].as_array().unwrap();
        let last = rows.last().unwrap();
        assert_close(last[0].as_f64().unwrap(), tip_x[i], 1e-8, 1e-9, "end x");
        assert_close(last[1].as_f64().unwrap(), tip_y[i], 1e-8, 1e-9, "end y");
    }
    assert_eq!(scene["parts"][0]["look"]["kind"], "tube");
}

#[test]
fn bad_animation_options_are_named() {
    let dir = tempfile::tempdir().unwrap();
    for (args, says) in [
        (
            vec!["--size", "12by4"],
            "--size 12by4: expected WIDTHxHEIGHT",
        ),
        (vec!["--fps", "0"], "--fps 0: must be in (0, 100]"),
        (
            vec!["--speed", "-1"],
            "--speed -1: must be a positive number",
        ),
    ] {
        let mut all = vec!["animate", "soft_finger", "--t-end", "0.1"];
        all.extend(args);
        let o = softarm(&all, dir.path());
        assert!(!o.status.success());
        assert!(stderr(&o).contains(says), "{}", stderr(&o));
    }
}

/// A run longer than an animation holds plays faster: 400 s at 10 frames
/// a second would be 4001 frames; the GIF has the most an animation
/// holds, the last at the run's end, and the page's scene is read from
/// trajectory.csv at four rows a frame however finely the run wrote it.
#[test]
fn a_long_run_plays_faster_in_a_bounded_animation() {
    let dir = tempfile::tempdir().unwrap();
    let o = softarm(
        &[
            "animate",
            "chain",
            "--t-end",
            "400",
            "--fps",
            "10",
            "--size",
            "64x64",
            "--output-dt",
            "0.01",
            "--shape-points",
            "1",
            "--out",
            "o",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("would be 4001 frames"),
        "{}",
        stderr(&o)
    );
    let run = dir.path().join("o");
    let max = 2000;
    assert_eq!(frames(&run.join("animation.gif")).0, max);
    let written = Csv::read(&run.join("trajectory.csv")).unwrap();
    assert_eq!(written.column("t").unwrap().len(), 40_001);
    let page = std::fs::read_to_string(run.join("viewer.html")).unwrap();
    let start = page.find(r#"type="application/json">"#).unwrap() + 24;
    let end = start + page[start..].find("</script>").unwrap();
    let scene: serde_json::Value = serde_json::from_str(&page[start..end]).unwrap();
    let t: Vec<f64> = (scene["t"].as_array().unwrap().iter())
        .map(|v| v.as_f64().unwrap())
        .collect();
    // A row every quarter frame of the faster playback, to the run's end.
    let spacing = 400.0 / (max - 1) as f64 / 4.0;
    assert!(t.len() <= 4 * max + 1, "{} rows", t.len());
    assert!(t.windows(2).all(|w| w[1] - w[0] >= 0.5 * spacing - 1e-9));
    assert_eq!(*t.last().unwrap(), 400.0);
    let frames_of_arm = scene["parts"][0]["frames"].as_array().unwrap().len();
    assert_eq!(frames_of_arm, t.len());
}
