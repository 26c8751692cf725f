//! What the CLI does for a model with joints: the initial state put onto
//! them (and said how far it moved), dependent joints named, the joint
//! forces and free bodies as trajectory columns, each free body's path as
//! a plot.

use std::path::Path;

use anyhow::{Result, bail};
use runtime::Dynamics;
use runtime::constraints::{dependent_rows, forces, joints_of, project};

/// Put (q, qd) on the joints by the least change of the coordinates; the
/// distance moved. Dependent joints and an assembly that cannot close are
/// errors naming the joints.
pub fn assemble(arm: &dyn Dynamics, origin: &str, q: &mut [f64], qd: &mut [f64]) -> Result<f64> {
    if arm.info().constraints.is_empty() {
        return Ok(0.0);
    }
    let dependent = dependent_rows(arm, 0.0, q);
    if let Some(rows) = dependent.first() {
        bail!(
            "{origin}: joints {} hold the same freedom twice (redundant or conflicting constraints: \
             rows {} are dependent at the start); remove one of them or make it a pin",
            joints_of(rows).join(", "),
            rows.join(", ")
        );
    }
    project(arm, 0.0, q, qd, 1e-12).map_err(|e| {
        anyhow::anyhow!(
            "{origin}: the initial state cannot be assembled onto the joints: joint {} is still \
             {:.3e} {} apart after {} Newton iterations; start the arms and bodies closer to \
             where the joints hold them ([simulate] q0, body positions)",
            joints_of(std::slice::from_ref(&e.row))[0],
            e.residual,
            if e.row.ends_with(".angle") {
                "rad"
            } else {
                "m"
            },
            e.iterations
        )
    })
}

/// The extra trajectory columns of a model with joints: every joint's
/// force on its second frame (fx, fy) and a weld's moment (m), world frame.
pub fn reaction_names(arm: &dyn Dynamics) -> Vec<String> {
    arm.info()
        .constraints
        .iter()
        .map(|row| {
            let (joint, what) = row.rsplit_once('.').unwrap_or((row, ""));
            let what = match what {
                "x" => "fx",
                "y" => "fy",
                _ => "m",
            };
            format!("joint_{joint}_{what}")
        })
        .collect()
}

/// The joint forces at a sample (NaN where the solve fails).
pub fn reactions(arm: &dyn Dynamics, t: f64, x: &[f64]) -> Vec<f64> {
    let n = arm.dof();
    forces(arm, t, &x[..n], &x[n..])
        .unwrap_or_else(|_| vec![f64::NAN; arm.info().constraints.len()])
}

/// Free bodies: (name, index of its x coordinate), from the coordinate
/// names `BODY.x`, `BODY.y`, `BODY.angle`.
pub fn free_bodies(arm: &dyn Dynamics, bodies: &[String]) -> Vec<(String, usize)> {
    let coords = &arm.info().coordinates;
    bodies
        .iter()
        .filter_map(|b| {
            let i = coords.iter().position(|c| *c == format!("{b}.x"))?;
            Some((b.clone(), i))
        })
        .collect()
}

/// A body's path in the plane, `<stem>.png`.
pub fn plot_path(stem: &Path, title: &str, path: &[(f64, f64)]) -> Result<()> {
    use plotters::prelude::*;
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in path.iter().filter(|p| p.0.is_finite() && p.1.is_finite()) {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if !x0.is_finite() {
        bail!("{}: no finite positions to plot", stem.display());
    }
    let pad = 0.05 * (x1 - x0).max(y1 - y0).max(1e-3);
    crate::compare::register_font();
    let size = (800u32, 600u32);
    let mut rgb = vec![255u8; 3 * (size.0 * size.1) as usize];
    {
        let e = |e: &dyn std::fmt::Display| anyhow::anyhow!("{}: {e}", stem.display());
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        root.fill(&WHITE).map_err(|x| e(&x))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .build_cartesian_2d(
                (1e3 * (x0 - pad))..(1e3 * (x1 + pad)),
                (1e3 * (y0 - pad))..(1e3 * (y1 + pad)),
            )
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc("x (mm)")
            .y_desc("y (mm)")
            .draw()
            .map_err(|x| e(&x))?;
        chart
            .draw_series(LineSeries::new(
                path.iter().map(|&(x, y)| (1e3 * x, 1e3 * y)),
                BLUE.stroke_width(1),
            ))
            .map_err(|x| e(&x))?;
        if let Some(&(x, y)) = path.first() {
            chart
                .draw_series([Circle::new((1e3 * x, 1e3 * y), 4, BLACK.filled())])
                .map_err(|x| e(&x))?;
        }
        root.present().map_err(|x| e(&x))?;
    }
    crate::compare::write_png(&stem.with_extension("png"), size, &rgb)
}
