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
    let moved = project(arm, 0.0, q, qd, 1e-12).map_err(|e| {
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
    })?;
    let dependent = dependent_rows(arm, 0.0, q);
    if let Some(rows) = dependent.first() {
        bail!(
            "{origin}: joints {} hold the same freedom twice at the start (rows {} are dependent): \
             redundant or conflicting joints, or a loop stretched straight; remove one of them, \
             make a weld a pin, or start the loop bent ([simulate] q0)",
            joints_of(rows).join(", "),
            rows.join(", ")
        );
    }
    Ok(moved)
}

/// A constraint row's output column: a joint's force on its second frame
/// (fx, fy, fz) and a weld's moment (m in the plane; mx, my, mz), world
/// frame. A free 3D body's unit-quaternion row is not a joint: none.
fn column(row: &str) -> Option<String> {
    let (joint, what) = row.rsplit_once('.')?;
    let what = match what {
        "x" => "fx",
        "y" => "fy",
        "z" => "fz",
        "angle" => "m",
        "rx" => "mx",
        "ry" => "my",
        "rz" => "mz",
        _ => return None,
    };
    Some(format!("joint_{joint}_{what}"))
}

/// The extra trajectory columns of a model with joints.
pub fn reaction_names(arm: &dyn Dynamics) -> Vec<String> {
    arm.info()
        .constraints
        .iter()
        .filter_map(|r| column(r))
        .collect()
}

/// The joint forces of a static solution by column name.
pub fn static_forces(
    arm: &dyn Dynamics,
    lambda: &[f64],
) -> std::collections::BTreeMap<String, f64> {
    arm.info()
        .constraints
        .iter()
        .zip(lambda)
        .filter_map(|(r, &l)| Some((column(r)?, l)))
        .collect()
}

/// The joint forces at a sample, as `reaction_names` (NaN where the solve
/// fails).
pub fn reactions(arm: &dyn Dynamics, t: f64, x: &[f64]) -> Vec<f64> {
    let n = arm.dof();
    let rows = &arm.info().constraints;
    let lambda =
        forces(arm, t, &x[..n], &x[n..2 * n]).unwrap_or_else(|_| vec![f64::NAN; rows.len()]);
    rows.iter()
        .zip(lambda)
        .filter(|(r, _)| column(r).is_some())
        .map(|(_, l)| l)
        .collect()
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

/// A body's path in the plane and its height against time,
/// `<stem>.png`; `path` is (t, x, y).
pub fn plot_path(stem: &Path, title: &str, path: &[(f64, f64, f64)]) -> Result<()> {
    use plotters::prelude::*;
    let finite: Vec<(f64, f64, f64)> = path
        .iter()
        .copied()
        .filter(|p| p.1.is_finite() && p.2.is_finite())
        .collect();
    let Some(&(_, fx, fy)) = finite.first() else {
        bail!("{}: no finite positions to plot", stem.display());
    };
    let range = |f: &dyn Fn(&(f64, f64, f64)) -> f64, start: f64| {
        finite
            .iter()
            .map(f)
            .fold((start, start), |(a, b), v| (a.min(v), b.max(v)))
    };
    let (x0, x1) = range(&|p| 1e3 * p.1, 1e3 * fx);
    let (y0, y1) = range(&|p| 1e3 * p.2, 1e3 * fy);
    let t1 = finite.last().map_or(1.0, |p| p.0).max(1e-9);
    let pad = 0.05 * (x1 - x0).max(y1 - y0).max(1.0);
    crate::compare::register_font();
    let size = (900u32, 900u32);
    let mut rgb = vec![255u8; 3 * (size.0 * size.1) as usize];
    {
        let e = |e: &dyn std::fmt::Display| anyhow::anyhow!("{}: {e}", stem.display());
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        root.fill(&WHITE).map_err(|x| e(&x))?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(|x| e(&x))?;
        let (top, bottom) = root.split_vertically(540);
        // The path with equal scales on both axes.
        let half = 0.5 * (x1 - x0).max(y1 - y0) + pad;
        let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
        let mut chart = ChartBuilder::on(&top)
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .build_cartesian_2d((cx - half)..(cx + half), (cy - half)..(cy + half))
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc("x (mm)")
            .y_desc("y (mm)")
            .draw()
            .map_err(|x| e(&x))?;
        chart
            .draw_series(LineSeries::new(
                finite.iter().map(|p| (1e3 * p.1, 1e3 * p.2)),
                BLUE.stroke_width(2),
            ))
            .map_err(|x| e(&x))?;
        chart
            .draw_series([Circle::new((1e3 * fx, 1e3 * fy), 5, BLACK.filled())])
            .map_err(|x| e(&x))?;
        // Each coordinate's displacement from the start against time, on
        // its own scale: a path that is a short line above still shows
        // how it moves.
        let (dx, dy) = (
            (x0 - 1e3 * fx, x1 - 1e3 * fx),
            (y0 - 1e3 * fy, y1 - 1e3 * fy),
        );
        let (lo, hi) = (dx.0.min(dy.0), dx.1.max(dy.1));
        let margin = 0.05 * (hi - lo).max(1e-6);
        let mut chart = ChartBuilder::on(&bottom)
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..t1, (lo - margin)..(hi + margin))
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc("t (s)")
            .y_desc("displacement from the start (mm)")
            .draw()
            .map_err(|x| e(&x))?;
        chart
            .draw_series(LineSeries::new(
                finite.iter().map(|p| (p.0, 1e3 * (p.1 - fx))),
                BLUE.stroke_width(2),
            ))
            .map_err(|x| e(&x))?
            .label("x")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLUE));
        chart
            .draw_series(LineSeries::new(
                finite.iter().map(|p| (p.0, 1e3 * (p.2 - fy))),
                RED.stroke_width(2),
            ))
            .map_err(|x| e(&x))?
            .label("y")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED));
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|x| e(&x))?;
        root.present().map_err(|x| e(&x))?;
    }
    crate::compare::write_png(&stem.with_extension("png"), size, &rgb)
}
