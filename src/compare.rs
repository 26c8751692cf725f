//! Simulation against measurement: a model's `[compare]` section maps a
//! recorded tip motion into the model frame; the tip error statistics go to
//! summary.json and a plot of simulated against measured tip x, y, z.

use std::path::Path;

use anyhow::{Context, Result, bail};
use eomgen::atomic_write::write_atomic;
use eomgen::model::Compare;
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use runtime::signal::moving_average;
use serde::Serialize;

use crate::data::{Csv, resolve};

/// The measured tip in the model frame.
pub struct Measured {
    pub t: Vec<f64>,
    pub tip: Vec<[f64; 3]>,
}

/// Read and transform the measured tip motion:
/// p = rotation (scale (position - reference) - R_c offset - (p_0 - offset)) + initial,
/// R_c the tip rotation relative to the first sample. `initial` defaults to
/// `initial_default` (the caller's simulated tip at the start).
pub fn measured(spec: &Compare, base: &Path, initial_default: [f64; 3]) -> Result<Measured> {
    let path = resolve(base, &spec.file);
    let csv = Csv::read(&path).context("compare.file")?;
    let t = csv.time_column(&spec.time).context("compare.time")?;
    let mut pos: Vec<Vec<f64>> = Vec::with_capacity(3);
    for (k, name) in spec.position.iter().enumerate() {
        let mut v = csv
            .column(name)
            .with_context(|| format!("compare.position[{k}]"))?;
        if let Some(r) = &spec.reference {
            let base = csv
                .column(&r[k])
                .with_context(|| format!("compare.reference[{k}]"))?;
            for (a, b) in v.iter_mut().zip(base) {
                *a -= b;
            }
        }
        pos.push(
            moving_average(&v, spec.smooth)
                .iter()
                .map(|x| spec.scale * x)
                .collect(),
        );
    }
    let n = t.len();
    let p = |i: usize| Vector3::new(pos[0][i], pos[1][i], pos[2][i]);
    // Tip rotation relative to the first sample.
    let relative: Vec<Matrix3<f64>> = match &spec.orientation {
        None => vec![Matrix3::identity(); n],
        Some(cols) => {
            let c = cols
                .iter()
                .enumerate()
                .map(|(k, name)| {
                    csv.column(name)
                        .with_context(|| format!("compare.orientation[{k}]"))
                })
                .collect::<Result<Vec<_>>>()?;
            let mut rot = Vec::with_capacity(n);
            for (i, ((w, x), (y, z))) in c[0]
                .iter()
                .zip(&c[1])
                .zip(c[2].iter().zip(&c[3]))
                .enumerate()
            {
                let q = nalgebra::Quaternion::new(*w, *x, *y, *z);
                if q.norm().is_nan() || q.norm() <= 1e-6 {
                    bail!(
                        "{}: row {}: the tip quaternion is zero",
                        path.display(),
                        i + 2
                    );
                }
                rot.push(
                    UnitQuaternion::from_quaternion(q)
                        .to_rotation_matrix()
                        .into_inner(),
                );
            }
            let r0t = rot[0].transpose();
            rot.iter().map(|r| r * r0t).collect()
        }
    };
    let offset = Vector3::from(spec.sensor_offset.unwrap_or([0.0; 3]));
    let frame = match spec.rotation {
        Some(r) => Matrix3::from_fn(|i, j| r[i][j]),
        None => Matrix3::identity(),
    };
    let initial = Vector3::from(spec.initial.unwrap_or(initial_default));
    let p0 = p(0);
    let tip = (0..n)
        .map(|i| {
            let v = frame * (p(i) - relative[i] * offset - (p0 - offset)) + initial;
            [v.x, v.y, v.z]
        })
        .collect();
    Ok(Measured { t, tip })
}

/// Tip error statistics over a window, as summary.json reports them.
#[derive(Clone, Debug, Serialize)]
pub struct TipError {
    pub window_s: [f64; 2],
    pub samples: usize,
    pub mean_m: f64,
    pub rms_m: f64,
    pub max_m: f64,
    pub mean_percent_length: f64,
}

/// Euclidean tip errors at the measured times inside `window` (and inside
/// the simulated span); `simulated(t)` gives the simulated tip.
pub fn tip_error(
    measured: &Measured,
    window: [f64; 2],
    length: f64,
    mut simulated: impl FnMut(f64) -> Option<[f64; 3]>,
) -> Result<TipError> {
    let mut errors = Vec::new();
    for (t, m) in measured.t.iter().zip(&measured.tip) {
        if *t < window[0] || *t > window[1] {
            continue;
        }
        let Some(s) = simulated(*t) else { continue };
        let e = ((s[0] - m[0]).powi(2) + (s[1] - m[1]).powi(2) + (s[2] - m[2]).powi(2)).sqrt();
        errors.push(e);
    }
    if errors.is_empty() {
        bail!(
            "compare.window: no measured sample between {} s and {} s within the simulated time",
            window[0],
            window[1]
        );
    }
    let n = errors.len() as f64;
    let mean = errors.iter().sum::<f64>() / n;
    Ok(TipError {
        window_s: window,
        samples: errors.len(),
        mean_m: mean,
        rms_m: (errors.iter().map(|e| e * e).sum::<f64>() / n).sqrt(),
        max_m: errors.iter().copied().fold(0.0, f64::max),
        mean_percent_length: 100.0 * mean / length,
    })
}

/// The simulated tip x, y, z over time, one panel each, against the
/// measured one when there is a record, as `<stem>.png` and `<stem>.svg`.
pub fn plot(
    stem: &Path,
    title: &str,
    simulated: &[(f64, [f64; 3])],
    measured: Option<&Measured>,
) -> Result<()> {
    let curve = Curve {
        label: "simulated",
        color: plotters::style::RED,
        points: simulated,
    };
    plot_curves(stem, title, &[curve], measured, None)
}

/// A simulated tip path on a plot against the record.
pub struct Curve<'a> {
    pub label: &'a str,
    pub color: plotters::style::RGBColor,
    pub points: &'a [(f64, [f64; 3])],
}

/// Simulated tips (`curves`) against the measured one (if any), x, y and
/// z over time, one panel each, with the time span `shaded` (a validation
/// window) shaded; as `<stem>.png` and `<stem>.svg`. Nothing is drawn for
/// a run that never left t = 0: it has no time axis.
pub fn plot_curves(
    stem: &Path,
    title: &str,
    curves: &[Curve],
    measured: Option<&Measured>,
    shaded: Option<[f64; 2]>,
) -> Result<()> {
    let none = Measured {
        t: Vec::new(),
        tip: Vec::new(),
    };
    let record = measured.unwrap_or(&none);
    let t_max = (curves.iter().flat_map(|c| c.points.iter().map(|p| p.0)))
        .chain(record.t.iter().copied())
        .filter(|t| t.is_finite())
        .fold(0.0, f64::max);
    if t_max <= 0.0 {
        return Ok(());
    }
    use plotters::prelude::*;
    register_font();
    fn e(e: impl std::fmt::Display) -> anyhow::Error {
        anyhow::anyhow!("{e}")
    }
    fn draw<DB: DrawingBackend>(
        root: DrawingArea<DB, plotters::coord::Shift>,
        title: &str,
        curves: &[Curve],
        measured: Option<&Measured>,
        t_max: f64,
        shaded: Option<[f64; 2]>,
    ) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(e)?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(e)?;
        let panels = root.split_evenly((3, 1));
        let points = || curves.iter().flat_map(|c| c.points.iter());
        let measured_tips = || measured.iter().flat_map(|m| m.tip.iter());
        for (k, panel) in panels.iter().enumerate() {
            let values = points()
                .map(|s| s.1[k])
                .chain(measured_tips().map(|m| m[k]))
                .map(|v| 1e3 * v)
                .filter(|v| v.is_finite());
            let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
            let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 0.0) };
            let pad = 0.05 * (hi - lo).max(1.0);
            let (y0, y1) = (lo - pad, hi + pad);
            let mut chart = ChartBuilder::on(panel)
                .margin(8)
                .x_label_area_size(30)
                .y_label_area_size(60)
                .build_cartesian_2d(0.0..t_max, y0..y1)
                .map_err(e)?;
            chart
                .configure_mesh()
                .x_desc("t (s)")
                .y_desc(format!("tip {} (mm)", ["x", "y", "z"][k]))
                .light_line_style(WHITE)
                .draw()
                .map_err(e)?;
            if let Some([a, b]) = shaded {
                let fill = RGBColor(220, 230, 245).filled();
                chart
                    .draw_series([Rectangle::new([(a, y0), (b.min(t_max), y1)], fill)])
                    .map_err(e)?
                    .label("validation window")
                    .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 20, y + 5)], fill));
            }
            if let Some(m) = measured {
                chart
                    .draw_series(LineSeries::new(
                        (m.t.iter().zip(&m.tip)).map(|(t, m)| (*t, 1e3 * m[k])),
                        BLACK.stroke_width(1),
                    ))
                    .map_err(e)?
                    .label("measured")
                    .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK));
            }
            for c in curves {
                let color = c.color;
                chart
                    .draw_series(LineSeries::new(
                        c.points.iter().map(|(t, s)| (*t, 1e3 * s[k])),
                        color.stroke_width(2),
                    ))
                    .map_err(e)?
                    .label(c.label)
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], color));
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()
                .map_err(e)?;
        }
        root.present().map_err(e)?;
        Ok(())
    }
    let size = (1000u32, 900u32);
    // Drawn into a buffer and encoded by the `png` crate: plotters' own
    // encoder would pull in the whole `image` crate.
    let mut rgb = vec![255u8; 3 * (size.0 * size.1) as usize];
    let area = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
    draw(area, title, curves, measured, t_max, shaded)?;
    write_png(&stem.with_extension("png"), size, &rgb)?;
    let mut text = String::new();
    let area = SVGBackend::with_string(&mut text, size).into_drawing_area();
    draw(area, title, curves, measured, t_max, shaded)?;
    Ok(write_atomic(&stem.with_extension("svg"), text.as_bytes())?)
}

/// Encode 8-bit RGB pixels as a PNG file.
pub fn write_png(path: &Path, size: (u32, u32), rgb: &[u8]) -> Result<()> {
    let mut bytes = Vec::new();
    let mut enc = png::Encoder::new(&mut bytes, size.0, size.1);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut w = enc.write_header()?;
    w.write_image_data(rgb)?;
    w.finish()?;
    Ok(write_atomic(path, &bytes)?)
}

/// The bundled font (DejaVu Sans Mono, assets/fonts): plots need no system
/// fonts.
pub fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let font: &'static [u8] = include_bytes!("../assets/fonts/DejaVuSansMono.ttf");
        let _ =
            plotters::style::register_font("sans-serif", plotters::style::FontStyle::Normal, font);
    });
}
