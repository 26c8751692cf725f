//! `softarm animate`: run a simulation and show it. `animation.gif`, the
//! arm as a shaded tube from a chosen view with the time, the tip path and
//! the inputs as bars (plotters' GIF backend draws it), and `viewer.html`,
//! an interactive 3D view in one self-contained file (`viewer`).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Result, anyhow};
use clap::Args;
use plotters::prelude::*;

use super::commands::{self, SimulateArgs};
use crate::scene::{Look, Scene};

#[derive(Args, Clone)]
pub struct AnimateArgs {
    #[command(flatten)]
    pub simulate: SimulateArgs,
    /// The GIF's view: front (x right, up up: y for a planar model, z in
    /// 3D), side (looking along x), top (looking down), iso (turned and
    /// tilted), or auto (front if planar, else iso).
    #[arg(long, value_enum, default_value_t = View::Auto)]
    pub view: View,
    /// Frames per second of the GIF (the run's output rows come four
    /// times as often unless --output-dt is given).
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
    pub fps: f64,
    /// Playback speed: simulated seconds per second of GIF.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub speed: f64,
    /// GIF size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "480x480")]
    pub size: String,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum View {
    /// front for a planar model (its plane), iso for a 3D one.
    Auto,
    Iso,
    Front,
    Side,
    Top,
}

/// Most frames of an animation (100 s of GIF at 20 frames a second): a
/// longer run plays faster.
pub const MAX_FRAMES: usize = 2000;

pub fn animate(a: AnimateArgs) -> Result<ExitCode> {
    if !(a.fps > 0.0 && a.fps <= 100.0) {
        return Err(anyhow!(
            "--fps {}: must be in (0, 100] frames a second",
            a.fps
        ));
    }
    if !(a.speed > 0.0 && a.speed.is_finite()) {
        return Err(anyhow!(
            "--speed {}: must be a positive number (simulated seconds per second)",
            a.speed
        ));
    }
    let size = parse_size(&a.size)?;
    let mut sim = a.simulate.clone();
    let loaded = commands::load(&sim.model)?;
    let t_end = (sim.t_end)
        .or(loaded.model.simulate.t_end)
        .unwrap_or(runtime::DEFAULT_T_END);
    // The whole run in at most MAX_FRAMES frames: faster playback if need be.
    let mut speed = a.speed;
    if t_end / speed * a.fps >= MAX_FRAMES as f64 {
        speed = t_end * a.fps / (MAX_FRAMES - 1) as f64;
        eprintln!(
            "animation: {t_end} s at --speed {} and --fps {} would be {:.0} frames; played at --speed {speed:.4} to fit the whole run in {MAX_FRAMES}",
            a.speed,
            a.fps,
            (t_end / a.speed * a.fps).floor() + 1.0
        );
    }
    // Rows four times a frame: the tip path follows what frames skip.
    let spacing = speed / a.fps / 4.0;
    sim.output_dt = sim.output_dt.or(Some(spacing));
    sim.shape_points = sim.shape_points.max(1);
    let code = commands::simulate(sim.clone())?;
    let out = (sim.out.clone())
        .unwrap_or_else(|| PathBuf::from("out").join(model_stem(&sim.model.model)));
    // Read at that spacing whatever rows the run wrote: a bounded scene.
    let scene = Scene::read(&loaded, &out, spacing)?;
    // The animation joins the files of the run it shows.
    let mut dir = crate::output_dir::OutputDir::reopen(&out)?;
    let gif = dir.file("animation.gif")?;
    draw_gif(&scene, a.view, a.fps, speed, size, &gif)?;
    let html = dir.file("viewer.html")?;
    crate::viewer::write(&scene, &html)?;
    if !sim.quiet {
        eprintln!("animation: {} and {}", gif.display(), html.display());
    }
    Ok(code)
}

fn model_stem(model: &str) -> String {
    let p = std::path::Path::new(model);
    match p.extension() {
        Some(_) => p
            .file_stem()
            .map_or(model.into(), |s| s.to_string_lossy().into()),
        None => model.to_string(),
    }
}

fn parse_size(s: &str) -> Result<(u32, u32)> {
    let bad = || anyhow!("--size {s}: expected WIDTHxHEIGHT, e.g. 480x480 (64 to 2000 each)");
    let (w, h) = s.split_once('x').ok_or_else(bad)?;
    let (w, h): (u32, u32) = (w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?);
    if !(64..=2000).contains(&w) || !(64..=2000).contains(&h) {
        return Err(bad());
    }
    Ok((w, h))
}

/// An orthographic view: screen right, screen up and towards the viewer,
/// in the world.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    pub right: [f64; 3],
    pub up: [f64; 3],
    pub toward: [f64; 3],
}

impl Camera {
    /// `view` of a scene whose up is y (planar) or z (3D).
    pub fn new(view: View, dimensions: u8) -> Self {
        let (x, up, depth) = match dimensions {
            2 => ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
            _ => ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]),
        };
        let neg = |v: [f64; 3]| v.map(|c| -c);
        let view = match (view, dimensions) {
            (View::Auto, 2) => View::Front,
            (View::Auto, _) => View::Iso,
            (v, _) => v,
        };
        match view {
            View::Front => Self {
                right: x,
                up,
                toward: depth,
            },
            View::Side => Self {
                right: neg(depth),
                up,
                toward: x,
            },
            View::Top => Self {
                right: x,
                up: neg(depth),
                toward: up,
            },
            // (Auto is resolved above.)
            View::Iso | View::Auto => {
                // Turned 35 degrees about up, tilted 25 degrees down.
                let (a, e) = (35f64.to_radians(), 25f64.to_radians());
                let mix = |u: [f64; 3], v: [f64; 3], cu: f64, cv: f64| {
                    [0, 1, 2].map(|i| cu * u[i] + cv * v[i])
                };
                let right = mix(x, depth, a.cos(), -a.sin());
                let flat = mix(depth, x, a.cos(), a.sin());
                Self {
                    right,
                    up: mix(up, flat, e.cos(), -e.sin()),
                    toward: mix(flat, up, e.cos(), e.sin()),
                }
            }
        }
    }

    /// (screen x, screen y, depth toward the viewer).
    pub fn project(&self, p: [f64; 3]) -> [f64; 3] {
        let d = |v: [f64; 3]| v[0] * p[0] + v[1] * p[1] + v[2] * p[2];
        [d(self.right), d(self.up), d(self.toward)]
    }
}

/// Rotate v by the unit quaternion q (w, x, y, z).
pub fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let [w, x, y, z] = q;
    let u = [x, y, z];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let t = cross(u, v).map(|c| 2.0 * c);
    let ut = cross(u, t);
    [0, 1, 2].map(|i| v[i] + w * t[i] + ut[i])
}

/// A capsule to draw: its two ends on screen (x, y, depth toward the
/// viewer), radius (m) and colour; a sphere has both ends at its centre.
struct Piece {
    a: [f64; 3],
    b: [f64; 3],
    r: f64,
    rgb: (u8, u8, u8),
}

/// The pieces of every part at frame k, back to front: a tube a capsule
/// per pair of neighbouring rows, a body or obstacle by its shape (a box
/// as its bounding sphere); planes are drawn apart.
fn pieces(scene: &Scene, cam: &Camera, k: usize) -> Vec<Piece> {
    let mut out = Vec::new();
    for part in &scene.parts {
        let rows = &part.frames[k];
        let at = |r: &[f64; 7]| cam.project([r[0], r[1], r[2]]);
        let r0 = &rows[0];
        match &part.look {
            Look::Tube { radius } => {
                for (i, w) in rows.windows(2).enumerate() {
                    out.push(Piece {
                        a: at(&w[0]),
                        b: at(&w[1]),
                        r: radius[i + 1],
                        rgb: (70, 130, 210),
                    });
                }
            }
            Look::Sphere { radius } => out.push(Piece {
                a: at(r0),
                b: at(r0),
                r: *radius,
                rgb: (220, 150, 50),
            }),
            Look::Cylinder {
                radius,
                half_length,
            } => {
                let axis = rotate([r0[3], r0[4], r0[5], r0[6]], [1.0, 0.0, 0.0]);
                let end =
                    |s: f64| cam.project([0, 1, 2].map(|c| r0[c] + s * half_length * axis[c]));
                out.push(Piece {
                    a: end(-1.0),
                    b: end(1.0),
                    r: *radius,
                    rgb: (160, 160, 160),
                });
            }
            Look::Box { half } => out.push(Piece {
                a: at(r0),
                b: at(r0),
                r: half.iter().map(|h| h * h).sum::<f64>().sqrt(),
                rgb: (160, 160, 160),
            }),
            Look::Plane => {}
        }
    }
    out.sort_by(|p, q| (p.a[2] + p.b[2]).total_cmp(&(q.a[2] + q.b[2])));
    out
}

/// The screen box of the whole run (m), with a margin.
fn bounds(scene: &Scene, cam: &Camera) -> [f64; 4] {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for k in 0..scene.t.len() {
        for p in pieces(scene, cam, k) {
            for c in 0..2 {
                lo[c] = lo[c].min(p.a[c].min(p.b[c]) - p.r);
                hi[c] = hi[c].max(p.a[c].max(p.b[c]) + p.r);
            }
        }
    }
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-3);
    let mid = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    let half = 0.6 * span;
    [mid[0] - half, mid[1] - half, mid[0] + half, mid[1] + half]
}

fn draw_gif(
    scene: &Scene,
    view: View,
    fps: f64,
    speed: f64,
    size: (u32, u32),
    path: &std::path::Path,
) -> Result<()> {
    crate::compare::register_font();
    let cam = Camera::new(view, scene.dimensions);
    let b = bounds(scene, &cam);
    // GIF delays are in hundredths of a second.
    let delay = (((1000.0 / fps).round() as u32 + 5) / 10).min(u16::MAX as u32) as u16;
    let mut gif = gif_file(path, size)?;
    let mut rgb = vec![0u8; 3 * size.0 as usize * size.1 as usize];
    // The scene above, the input bars (if any) in a strip below it.
    let strip = BAR * scene.inputs.len().min(MAX_BARS) as f64;
    let (w, h) = (size.0 as f64, (size.1 as f64 - strip).max(32.0));
    let s = (w / (b[2] - b[0])).min(h / (b[3] - b[1]));
    let px = |p: [f64; 3]| -> (i32, i32) {
        let x = 0.5 * w + s * (p[0] - 0.5 * (b[0] + b[2]));
        let y = 0.5 * h - s * (p[1] - 0.5 * (b[1] + b[3]));
        (x.round() as i32, y.round() as i32)
    };
    let err = |e: DrawingAreaErrorKind<_>| anyhow!("{}: {e}", path.display());
    // One GIF frame per 1 / fps s of playback: the nearest output row.
    let t_end = scene.t.last().copied().unwrap_or(0.0);
    let frames = ((t_end / speed * fps + 1e-9).floor() as usize + 1).min(MAX_FRAMES);
    let mut k = 0;
    for f in 0..frames {
        let t = f as f64 * speed / fps;
        while k + 1 < scene.t.len() && (scene.t[k + 1] - t).abs() <= (scene.t[k] - t).abs() {
            k += 1;
        }
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        for part in scene.parts.iter().filter(|p| matches!(p.look, Look::Plane)) {
            let r = part.frames[k][0];
            let n = rotate([r[3], r[4], r[5], r[6]], [1.0, 0.0, 0.0]);
            let (ns, at) = (cam.project(n), cam.project([r[0], r[1], r[2]]));
            // Edge-on enough to show: a line across the view, solid below.
            if ns[0].hypot(ns[1]) > 0.3 {
                let along = [-ns[1], ns[0], 0.0];
                let far = 10.0 * (b[2] - b[0]);
                let end = |sg: f64| [0, 1, 2].map(|c| at[c] + sg * far * along[c]);
                let deep = |p: [f64; 3]| [0, 1, 2].map(|c| p[c] - far * ns[c]);
                let (e0, e1) = (end(-1.0), end(1.0));
                let poly = vec![px(e0), px(e1), px(deep(e1)), px(deep(e0))];
                root.draw(&Polygon::new(poly, RGBColor(225, 225, 215).filled()))
                    .map_err(err)?;
                root.draw(&PathElement::new(
                    vec![px(e0), px(e1)],
                    BLACK.stroke_width(2),
                ))
                .map_err(err)?;
            }
        }
        // Layer by layer over all pieces: each layer joins its neighbours'
        // smoothly (a tube crossing itself is drawn by its layers' order).
        let pieces = pieces(scene, &cam, k);
        for layer in LAYERS {
            for p in &pieces {
                draw_piece(&root, p, layer, s, &px).map_err(err)?;
            }
        }
        let path_px: Vec<(i32, i32)> = scene.tip[..=k]
            .iter()
            .map(|p| px(cam.project(*p)))
            .collect();
        root.draw(&PathElement::new(path_px, RED.stroke_width(2)))
            .map_err(err)?;
        let label = ("sans-serif", 16).into_font();
        root.draw(&Text::new(
            format!("{}  t = {:.2} s", scene.model, scene.t[k]),
            (8, 8),
            label.clone(),
        ))
        .map_err(err)?;
        clamps(&root, scene, &cam, s, &px).map_err(err)?;
        let screen = (size.0 as i32, h as i32);
        scale_and_gravity(&root, scene, &cam, s, screen).map_err(err)?;
        input_bars(&root, scene, k, size).map_err(err)?;
        root.present().map_err(err)?;
        drop(root);
        let mut frame = gif_frame(size.0 as u16, size.1 as u16, &rgb);
        frame.delay = delay;
        gif.write_frame(&frame)
            .map_err(|e| anyhow!("{}: {e}", path.display()))?;
    }
    Ok(())
}

/// A GIF frame of RGB pixels on a palette of its 256 most frequent
/// colours, each other colour (the anti-aliased fringes, a few hundred
/// pixels) drawn in its nearest: the same picture as the gif crate's
/// NeuQuant quantiser, which took two thirds of animate's time.
fn gif_frame(w: u16, h: u16, rgb: &[u8]) -> gif::Frame<'static> {
    // Colours as numbers, counted by sorting: no hashing per pixel.
    let colour = |p: &[u8]| u32::from_be_bytes([0, p[0], p[1], p[2]]);
    let mut sorted: Vec<u32> = rgb.chunks_exact(3).map(colour).collect();
    sorted.sort_unstable();
    let mut counted: Vec<(u32, u32)> = Vec::new();
    for c in sorted {
        match counted.last_mut() {
            Some((k, n)) if *k == c => *n += 1,
            _ => counted.push((c, 1)),
        }
    }
    // Most frequent first, ties by colour: the same frame, the same file.
    let mut frequent = counted.clone();
    frequent.sort_unstable_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let palette: Vec<[u8; 3]> = (frequent.iter().take(256))
        .map(|&(c, _)| {
            let [_, r, g, b] = c.to_be_bytes();
            [r, g, b]
        })
        .collect();
    let distance = |c: u32, p: [u8; 3]| -> i32 {
        let [_, r, g, b] = c.to_be_bytes();
        let d = |x: u8, y: u8| (i32::from(x) - i32::from(y)).pow(2);
        d(r, p[0]) + d(g, p[1]) + d(b, p[2])
    };
    // Each distinct colour's palette entry, in `counted`'s (sorted) order:
    // its own for the palette's colours, the nearest for the rest.
    let mut index = vec![0u8; counted.len()];
    for (rank, &(c, _)) in frequent.iter().enumerate() {
        let at = counted.partition_point(|&(k, _)| k < c);
        index[at] = match rank < palette.len() {
            true => rank as u8,
            false => (0..palette.len())
                .min_by_key(|&i| distance(c, palette[i]))
                .unwrap_or(0) as u8,
        };
    }
    let mut last: Option<(u32, u8)> = None;
    let pixels: Vec<u8> = (rgb.chunks_exact(3))
        .map(|p| {
            let c = colour(p);
            match last {
                Some((l, i)) if l == c => i,
                _ => {
                    let at = counted.partition_point(|&(k, _)| k < c);
                    let i = index[at];
                    last = Some((c, i));
                    i
                }
            }
        })
        .collect();
    gif::Frame::from_palette_pixels(w, h, &pixels, palette.as_flattened(), None)
}

/// An endlessly looping GIF at `path`, written frame by frame (our own
/// encoder rather than plotters' GIF backend, which brings the `image`
/// crate: ten seconds of every fresh build for one file format).
fn gif_file(path: &std::path::Path, size: (u32, u32)) -> Result<gif::Encoder<std::fs::File>> {
    let fail = |e: &dyn std::fmt::Display| anyhow!("{}: {e}", path.display());
    let (w, h) = (u16::try_from(size.0), u16::try_from(size.1));
    let (Ok(w), Ok(h)) = (w, h) else {
        return Err(anyhow!(
            "{}: a GIF is at most 65535 pixels a side",
            path.display()
        ));
    };
    let file = std::fs::File::create(path).map_err(|e| fail(&e))?;
    let mut gif = gif::Encoder::new(file, w, h, &[]).map_err(|e| fail(&e))?;
    gif.set_repeat(gif::Repeat::Infinite)
        .map_err(|e| fail(&e))?;
    Ok(gif)
}

/// The shading layers of a piece: (width, offset toward the light, both
/// in radii; brightness): a dark rim, the body, a highlight stripe.
const LAYERS: [(f64, f64, f64); 3] = [(1.0, 0.0, 0.45), (0.8, 0.1, 0.85), (0.3, 0.4, 1.25)];

/// One layer of a capsule shaded as a lit cylinder: a dark rim, the body, and a
/// highlight stripe on the side facing the upper left.
fn draw_piece<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    p: &Piece,
    (width, off, light): (f64, f64, f64),
    scale: f64,
    px: &dyn Fn([f64; 3]) -> (i32, i32),
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let r = scale * p.r;
    let (a, b) = (px(p.a), px(p.b));
    // The highlight's offset: across the piece, toward the upper left.
    let (dx, dy) = ((b.0 - a.0) as f64, (b.1 - a.1) as f64);
    let len = dx.hypot(dy);
    let (mut nx, mut ny) = if len > 0.5 {
        (-dy / len, dx / len)
    } else {
        (-0.7, -0.7)
    };
    if nx + ny > 0.0 {
        (nx, ny) = (-nx, -ny);
    }
    let (r0, g0, b0) = p.rgb;
    let shade = |f: f64| {
        let c = |v: u8| (v as f64 * f).clamp(0.0, 255.0) as u8;
        RGBColor(c(r0), c(g0), c(b0))
    };
    let colour = shade(light);
    let o = ((off * r * nx) as i32, (off * r * ny) as i32);
    let (a, b) = ((a.0 + o.0, a.1 + o.1), (b.0 + o.0, b.1 + o.1));
    let rad = (width * r).max(1.0) as i32;
    root.draw(&Circle::new(a, rad, colour.filled()))?;
    if a != b {
        root.draw(&Circle::new(b, rad, colour.filled()))?;
        root.draw(&PathElement::new(
            vec![a, b],
            colour.stroke_width(2 * rad as u32),
        ))?;
    }
    Ok(())
}

/// Input bars: at most this many, each this tall (px).
const MAX_BARS: usize = 4;
const BAR: f64 = 22.0;

/// Each arm's clamp: a dark block behind its base (the base frame's -x),
/// as wide as three tube radii either side.
fn clamps<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    scene: &Scene,
    cam: &Camera,
    scale: f64,
    px: &dyn Fn([f64; 3]) -> (i32, i32),
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    for part in &scene.parts {
        let (Look::Tube { radius }, Some(base)) = (&part.look, part.frames.first()) else {
            continue;
        };
        let (r, b) = (radius.first().copied().unwrap_or(0.0), base[0]);
        let q = [b[3], b[4], b[5], b[6]];
        let (along, across) = (rotate(q, [1.0, 0.0, 0.0]), rotate(q, [0.0, 1.0, 0.0]));
        // Across the arm on screen: its y axis, or z where y is edge-on.
        let across = match cam.project(across) {
            a if a[0].hypot(a[1]) > 0.3 => across,
            _ => rotate(q, [0.0, 0.0, 1.0]),
        };
        let (d, w) = ((4.0 * r).max(6.0 / scale), (3.0 * r).max(8.0 / scale));
        let at = |u: f64, v: f64| {
            let p = [0, 1, 2].map(|c| b[c] + u * along[c] + v * across[c]);
            px(cam.project(p))
        };
        let block = vec![at(0.0, -w), at(0.0, w), at(-d, w), at(-d, -w)];
        root.draw(&Polygon::new(block, RGBColor(90, 90, 90).filled()))?;
    }
    Ok(())
}

/// A scale bar (a round length near a fifth of the view) at the bottom
/// right of the scene, and gravity's direction as an arrow at the top
/// right.
fn scale_and_gravity<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    scene: &Scene,
    cam: &Camera,
    scale: f64,
    (w, h): (i32, i32),
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let font = ("sans-serif", 14).into_font();
    let target = 0.2 * w as f64 / scale;
    let unit = 10f64.powf(target.log10().floor());
    let length = [5.0, 2.0, 1.0]
        .map(|m| m * unit)
        .into_iter()
        .find(|l| *l <= target)
        .unwrap_or(unit);
    let pixels = (length * scale).round() as i32;
    let (x1, y) = (w - 16, h - 16);
    let bar = vec![(x1 - pixels, y), (x1, y)];
    root.draw(&PathElement::new(bar, BLACK.stroke_width(3)))?;
    for x in [x1 - pixels, x1] {
        root.draw(&PathElement::new(
            vec![(x, y - 6), (x, y + 6)],
            BLACK.stroke_width(2),
        ))?;
    }
    let text = match length {
        l if l >= 1.0 => format!("{l} m"),
        l => format!("{} mm", (l * 1e3 * 1e6).round() / 1e6),
    };
    root.draw(&Text::new(text, (x1 - pixels, y - 22), font.clone()))?;
    let g = cam.project(scene.gravity);
    let norm = g[0].hypot(g[1]);
    if norm > 1e-9 {
        let (cx, cy, len) = (w - 40, 40, 24.0);
        let (dx, dy) = (len * g[0] / norm, -len * g[1] / norm);
        let tip = (cx + dx as i32, cy + dy as i32);
        let back = |turn: f64| {
            let (c, s) = (turn.cos(), turn.sin());
            let (bx, by) = (-(dx * c - dy * s) * 0.35, -(dx * s + dy * c) * 0.35);
            (tip.0 + bx as i32, tip.1 + by as i32)
        };
        let (from, to) = ((cx - dx as i32, cy - dy as i32), tip);
        root.draw(&PathElement::new(vec![from, to], BLACK.stroke_width(2)))?;
        root.draw(&Polygon::new(
            vec![tip, back(0.5), back(-0.5)],
            BLACK.filled(),
        ))?;
        root.draw(&Text::new("g", (cx + 10, cy - 30), font))?;
    }
    Ok(())
}

/// The inputs at frame k as bars along the bottom, each scaled by its
/// largest magnitude over the run.
fn input_bars<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    scene: &Scene,
    k: usize,
    size: (u32, u32),
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (w, h) = (size.0 as i32, size.1 as i32);
    for (i, (name, v)) in scene.inputs.iter().take(MAX_BARS).enumerate() {
        let max = v.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
        let y = h - BAR as i32 * (i as i32 + 1);
        let (x0, full) = (w / 3, w / 2);
        let len = (v[k] / max * full as f64 / 2.0) as i32;
        let mid = x0 + full / 2;
        root.draw(&Rectangle::new(
            [(x0, y), (x0 + full, y + 14)],
            RGBColor(220, 220, 220).filled(),
        ))?;
        root.draw(&Rectangle::new(
            [(mid.min(mid + len), y), (mid.max(mid + len), y + 14)],
            RGBColor(40, 160, 80).filled(),
        ))?;
        let label = format!("{name} {:.3e}", v[k]);
        root.draw(&Text::new(label, (8, y), ("sans-serif", 13).into_font()))?;
    }
    Ok(())
}
