//! `viewer.html`: the scene in one self-contained page (plain WebGL, no
//! library, no network at view time): orbit and zoom, play and pause, a
//! time slider, playback speed, the tip path and the measured tip. The
//! page is `assets/viewer.html` with the scene's JSON in it.

use std::path::Path;

use anyhow::Result;

use crate::scene::Scene;

const PAGE: &str = include_str!("../assets/viewer.html");

/// The page of `scene`.
pub fn page(scene: &Scene) -> Result<String> {
    // Inside a <script> element "</" would end it.
    let json = serde_json::to_string(scene)?.replace("</", "<\\/");
    Ok(PAGE.replace("/*SCENE*/", &json))
}

/// Write the page to `path` (through a temporary file).
pub fn write(scene: &Scene, path: &Path) -> Result<()> {
    Ok(eomgen::atomic_write::write_atomic(
        path,
        page(scene)?.as_bytes(),
    )?)
}
