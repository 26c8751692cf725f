//! What an animation shows, read from a run's outputs: the parts of
//! `shape.csv` over time (arms as tubes of their segments' radii, bodies by
//! their shapes, obstacles), the tip path of `trajectory.csv`, the input
//! channels' values, and the measured tip of `[compare]`.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result, bail};
use eomgen::model::assembly::BodyShape;
use runtime::contact;
use serde::Serialize;

use crate::backend::Loaded;

/// A part of the scene and how it is drawn.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Look {
    /// A tube; the radius of each row (its segment's outer radius).
    Tube {
        radius: Vec<f64>,
    },
    Sphere {
        radius: f64,
    },
    /// A cylinder along the row's x axis, or a box of half sizes.
    Cylinder {
        radius: f64,
        half_length: f64,
    },
    Box {
        half: [f64; 3],
    },
    /// A plane through the row's point, normal along its x axis.
    Plane,
}

/// One part: its name, look and pose rows (x, y, z, qw, qx, qy, qz) at
/// every frame.
#[derive(Clone, Debug, Serialize)]
pub struct Part {
    pub name: String,
    pub look: Look,
    pub frames: Vec<Vec<[f64; 7]>>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Scene {
    pub model: String,
    /// 2 or 3; planar arms move in the x-y plane (y up), 3D ones have z up.
    pub dimensions: u8,
    pub t: Vec<f64>,
    pub parts: Vec<Part>,
    /// The tip at each frame (`trajectory.csv`'s tip_x, tip_y, tip_z).
    pub tip: Vec<[f64; 3]>,
    /// Input channels' values at each frame, by name.
    pub inputs: BTreeMap<String, Vec<f64>>,
    /// The measured tip (t, x, y, z), if the model has `[compare]`.
    pub measured: Vec<[f64; 4]>,
    /// Gravity (m/s^2), drawn as an arrow.
    pub gravity: [f64; 3],
}

impl Scene {
    /// The scene of the run in `dir` of the model `loaded`, its rows at
    /// least `spacing` s apart (and the last): read as a stream, so a run
    /// of any length gives a scene of its length over `spacing`.
    pub fn read(loaded: &Loaded, dir: &Path, spacing: f64) -> Result<Self> {
        let (t, tip) = read_tips(&dir.join("trajectory.csv"), spacing)?;
        let [x, y, z] = tip.first().copied().unwrap_or_default();
        let parts = read_shape(&dir.join("shape.csv"), &t)?
            .into_iter()
            .map(|(name, s, frames)| {
                let look = look_of(loaded, &name, &s);
                Part { name, look, frames }
            })
            .collect();
        let mut inputs = BTreeMap::new();
        for (name, input) in &loaded.model.inputs {
            let signal = crate::inputs::signal(name, input, &loaded.base_dir)?;
            inputs.insert(name.clone(), t.iter().map(|&t| signal.at(t)).collect());
        }
        let measured = match &loaded.model.compare {
            Some(spec) => {
                let m = crate::compare::measured(spec, &loaded.base_dir, [x, y, z])?;
                let end = t.last().copied().unwrap_or(0.0);
                (m.t.iter().zip(&m.tip))
                    .filter(|(t, _)| **t <= end)
                    .map(|(t, p)| [*t, p[0], p[1], p[2]])
                    .collect()
            }
            None => Vec::new(),
        };
        Ok(Self {
            model: loaded.model.name.clone(),
            dimensions: loaded.model.dimensions,
            t,
            parts,
            tip,
            inputs,
            measured,
            gravity: loaded.model.gravity,
        })
    }
}

/// trajectory.csv's times and tips, the rows at least `spacing` apart
/// from the first, and the last.
type Tips = (Vec<f64>, Vec<[f64; 3]>);

fn read_tips(path: &Path, spacing: f64) -> Result<Tips> {
    let mut reader = csv::Reader::from_path(path)
        .with_context(|| format!("{}: cannot read the CSV file", path.display()))?;
    let header = reader.headers()?.clone();
    let column = |name: &str| {
        (header.iter().position(|h| h == name))
            .with_context(|| format!("{}: no column {name}", path.display()))
    };
    let cols = [
        column("t")?,
        column("tip_x")?,
        column("tip_y")?,
        column("tip_z")?,
    ];
    let (mut t, mut tip) = (Vec::new(), Vec::new());
    let mut last = None;
    for (i, record) in reader.records().enumerate() {
        let r =
            record.with_context(|| format!("{}: row {}: not valid CSV", path.display(), i + 2))?;
        let v = cols.map(|c| r.get(c).and_then(|s| s.parse::<f64>().ok()));
        let [Some(time), Some(x), Some(y), Some(z)] = v else {
            bail!("{}: row {}: not numbers", path.display(), i + 2);
        };
        // (Times are written to 9 decimals: equal spacings read within 1e-9.)
        let due = t.last().is_none_or(|&l: &f64| time >= l + spacing - 1e-8);
        if due {
            t.push(time);
            tip.push([x, y, z]);
            last = None;
        } else {
            last = Some((time, [x, y, z]));
        }
    }
    if let Some((time, p)) = last {
        t.push(time);
        tip.push(p);
    }
    Ok((t, tip))
}

/// `shape.csv`'s rows grouped by part, in order of first appearance: the
/// material coordinate of each row, and the rows at each time of `t`.
type Tracks = Vec<(String, Vec<f64>, Vec<Vec<[f64; 7]>>)>;

/// The rows of `shape.csv` at the times `t` (trajectory.csv's, which print
/// the same digits); the rows between them are skipped as they are read.
fn read_shape(path: &Path, t: &[f64]) -> Result<Tracks> {
    let mut reader = csv::Reader::from_path(path).with_context(|| {
        format!(
            "{}: cannot read (run with --shape-points > 0)",
            path.display()
        )
    })?;
    let mut tracks: Tracks = Vec::new();
    let mut frame = 0usize;
    for record in reader.records() {
        let r = record.with_context(|| format!("{}: a bad row", path.display()))?;
        let num = |i: usize| -> Result<f64> {
            r.get(i)
                .and_then(|s| s.parse().ok())
                .with_context(|| format!("{}: column {i} is not a number", path.display()))
        };
        let time = num(0)?;
        while frame < t.len() && t[frame] < time {
            frame += 1;
        }
        if t.get(frame) != Some(&time) {
            continue;
        }
        let part = r.get(1).unwrap_or_default();
        let pose: [f64; 7] = [
            num(4)?,
            num(5)?,
            num(6)?,
            num(7)?,
            num(8)?,
            num(9)?,
            num(10)?,
        ];
        let k = match tracks.iter().position(|(n, ..)| n == part) {
            Some(k) => k,
            None => {
                tracks.push((part.to_string(), Vec::new(), Vec::new()));
                tracks.len() - 1
            }
        };
        let (_, s, frames) = &mut tracks[k];
        if frame == 0 {
            s.push(num(3)?);
        }
        frames.resize(frame + 1, Vec::new());
        frames[frame].push(pose);
    }
    let frames = tracks.iter().map(|(_, _, f)| f.len()).min().unwrap_or(0);
    if frames != t.len() {
        bail!(
            "{}: {frames} of trajectory.csv's {} times: not the same run",
            path.display(),
            t.len()
        );
    }
    Ok(tracks)
}

/// How a part of `shape.csv` is drawn: an arm by its segments' radii, a
/// body or an obstacle by its shape.
fn look_of(loaded: &Loaded, name: &str, s: &[f64]) -> Look {
    let m = &loaded.model;
    let radius_of = |segments: &[eomgen::model::Segment]| -> Look {
        // Each row's segment, by its material coordinate.
        let radius = s
            .iter()
            .map(|&s| {
                let mut start = 0.0;
                for g in segments {
                    if s <= (start + g.length) * (1.0 + 1e-9) {
                        let at = (s - start) / g.length;
                        if let Some(sec) = &g.section {
                            return sec.bounding_radius();
                        }
                        return g.outer_radius.as_ref().map_or(0.01, |r| r.at(at));
                    }
                    start += g.length;
                }
                (segments.last())
                    .and_then(|g| g.outer_radius.as_ref())
                    .map_or(0.01, |r| r.at(1.0))
            })
            .collect();
        Look::Tube { radius }
    };
    if name == "arm" {
        return radius_of(&m.segments);
    }
    if let Some(a) = m.arms.iter().find(|a| a.name == name) {
        return radius_of(&a.segments);
    }
    if let Some(b) = m.bodies.iter().find(|b| b.name == name) {
        let r = b.radius.unwrap_or(0.02);
        return match b.shape {
            BodyShape::Sphere => Look::Sphere { radius: r },
            BodyShape::Cylinder => Look::Cylinder {
                radius: r,
                half_length: 0.5 * b.length.unwrap_or(2.0 * r),
            },
            _ => Look::Box {
                half: b.size.map_or([r; 3], |s| s.map(|x| 0.5 * x)),
            },
        };
    }
    let obstacle = loaded
        .arm
        .contact()
        .and_then(|c| c.obstacles.iter().find(|o| o.name == name));
    match obstacle.map(|o| &o.shape) {
        Some(contact::Shape::Sphere { radius, .. }) => Look::Sphere { radius: *radius },
        Some(contact::Shape::Cylinder {
            radius,
            half_length,
            ..
        }) => Look::Cylinder {
            radius: *radius,
            half_length: *half_length,
        },
        Some(contact::Shape::Box { half, .. }) => Look::Box { half: *half },
        // Exhaustive on purpose: a new shape is drawn here, or not at all.
        Some(contact::Shape::Plane { .. }) | None => Look::Plane,
    }
}
