//! A model's contacts as the runtime sees them: the sampled points with
//! their tube radii (in the generator's order: each arm's elements,
//! `points_per_element` each, then the bodies' centres), the obstacles
//! with their laws and motions, and the pairs (docs/design.md section 8).

use std::path::Path;

use anyhow::{Result, bail};
use eomgen::model::Model;
use eomgen::model::assembly::BodyShape;
use eomgen::model::contact::{ContactLaw, ContactModel, ObstacleDecl};
use runtime::contact::{ContactPoint, ContactSet, Damping, Law, Normal, Obstacle};

/// Default regularisation speed of friction (m/s).
pub const SLIP_VELOCITY: f64 = 1e-3;
/// Default Hertz exponent (a sphere on a flat).
pub const HERTZ_EXPONENT: f64 = 1.5;

/// The contact set of `model`, or `None` without contact; `points` is the
/// kernel's count, which the sampling here must match.
pub fn contact_set(model: &Model, base: &Path, points: usize) -> Result<Option<ContactSet>> {
    if !model.has_contact() {
        return Ok(None);
    }
    let per = model.contact_points();
    let mut sampled = Vec::new();
    for (arm, (_, am)) in model.arm_models().iter().enumerate() {
        let mut element = 0;
        for s in &am.segments {
            // A rom segment's elements are its quadrature slices; an
            // element's points are evenly spaced along it, the last at its
            // end, each as thick as the section there.
            let n = s.slices();
            for e in 0..n {
                for j in 0..per {
                    let at = (e as f64 + (j + 1) as f64 / per as f64) / n as f64;
                    sampled.push(ContactPoint {
                        radius: match &s.section {
                            Some(sec) => sec.bounding_radius(),
                            None => s.outer_radius.as_ref().map_or(0.0, |r| r.at(at)),
                        },
                        element: Some((arm, element)),
                    });
                }
                element += 1;
            }
        }
    }
    for b in &model.bodies {
        sampled.push(ContactPoint {
            radius: body_radius(b),
            element: None,
        });
    }
    if sampled.len() != points {
        bail!(
            "the model samples {} contact points but its kernels have {points}: regenerate (cargo build)",
            sampled.len()
        );
    }
    let decl = model.contact.clone().unwrap_or_default();
    let defaults = decl.law();
    let obstacles = model
        .obstacles
        .iter()
        .map(|o| obstacle(model, o, &defaults, base))
        .collect::<Result<Vec<_>>>()?;
    let default_law = law(&defaults);
    let self_law = decl.self_contact.then_some(default_law);
    let bodies = (!model.bodies.is_empty()).then(|| {
        (
            default_law,
            model.bodies.iter().map(|b| b.name.clone()).collect(),
        )
    });
    Ok(Some(ContactSet::new(sampled, obstacles, self_law, bodies)))
}

/// A body touches as the sphere around its centre: exact for a sphere,
/// the bounding sphere of a cylinder or a box.
fn body_radius(b: &eomgen::model::assembly::BodyDecl) -> f64 {
    match b.shape {
        BodyShape::Sphere => b.radius.unwrap_or(0.0),
        BodyShape::Cylinder => {
            let (r, l) = (b.radius.unwrap_or(0.0), b.length.unwrap_or(0.0));
            (r * r + l * l / 4.0).sqrt()
        }
        BodyShape::Box => {
            let s = b.size.unwrap_or([0.0; 3]);
            0.5 * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt()
        }
    }
}

/// The runtime law of a model law (validated: complete and in range).
pub fn law(l: &ContactLaw) -> Law {
    let k = l.stiffness.unwrap_or(0.0);
    let n = l.exponent.unwrap_or(HERTZ_EXPONENT);
    let normal = match l.model.unwrap_or(ContactModel::HuntCrossley) {
        ContactModel::SpringDashpot => Normal::SpringDashpot {
            k,
            c: l.damping.unwrap_or(0.0),
        },
        ContactModel::Hertz => Normal::Hertz { k, n },
        ContactModel::HuntCrossley => Normal::HuntCrossley {
            k,
            n,
            damping: match (l.damping, l.restitution) {
                (Some(b), _) => Damping::Given(b),
                (None, Some(e)) => match runtime::contact::restitution_damping(e) {
                    Some(a) => Damping::Restitution { e, a },
                    None => Damping::Given(0.0),
                },
                (None, None) => Damping::Given(0.0),
            },
        },
        ContactModel::Impulse => Normal::Impulse {
            e: l.restitution.unwrap_or(0.0),
        },
    };
    Law {
        normal,
        friction: l.friction.unwrap_or(0.0),
        slip: l.slip_velocity.unwrap_or(SLIP_VELOCITY),
    }
}

fn obstacle(
    model: &Model,
    o: &ObstacleDecl,
    defaults: &ContactLaw,
    base: &Path,
) -> Result<Obstacle> {
    let shape = o
        .geometry()
        .map_err(|e| anyhow::anyhow!("obstacle \"{}\": {}: {}", o.name, e.key, e.message))?;
    let motion = match &o.translation_inputs {
        None => None,
        Some(channels) => {
            let mut signals = Vec::new();
            for name in channels {
                let input = model.inputs.get(name).expect("validated channel");
                signals.push(crate::inputs::signal(name, input, base)?);
            }
            // A planar model moves its obstacles in x and y.
            signals.resize(3, runtime::Signal::Constant(0.0));
            let [x, y, z]: [runtime::Signal; 3] = signals.try_into().expect("three signals");
            Some(runtime::contact::Motion::new([x, y, z]))
        }
    };
    Ok(Obstacle {
        name: o.name.clone(),
        shape,
        law: law(&o.contact.over(defaults)),
        motion,
    })
}

/// The trajectory columns of the contact channels: per obstacle (and
/// `self`, and per body) the total normal and friction force.
pub fn column_names(arm: &dyn runtime::Dynamics) -> Vec<String> {
    arm.contact().map_or_else(Vec::new, |set| {
        set.channels
            .iter()
            .flat_map(|c| [format!("contact_{c}_fn"), format!("contact_{c}_ft")])
            .collect()
    })
}

/// The pairs' forces at a sample.
fn forces_at(
    arm: &dyn runtime::Dynamics,
    t: f64,
    x: &[f64],
) -> Option<Vec<runtime::contact::PairForce<f64>>> {
    let set = arm.contact()?;
    let n = arm.dof();
    Some(runtime::contact::pair_forces(
        arm,
        set,
        t,
        &x[..n],
        &x[n..2 * n],
        true,
    ))
}

/// The contact columns at sample i (`column_names`' order): as the run
/// recorded them (under the contact state of that moment), or for a
/// trajectory without them (a failed run's) from the state alone.
pub fn columns(arm: &dyn runtime::Dynamics, traj: &runtime::Trajectory, i: usize) -> Vec<f64> {
    let Some(set) = arm.contact() else {
        return Vec::new();
    };
    if let Some(c) = traj.contact.get(i) {
        return c.clone();
    }
    let n = arm.dof();
    let x = &traj.x[i];
    runtime::contact::channel_columns(arm, set, traj.t[i], &x[..n], &x[n..2 * n])
}

/// The run's contacts for summary.json: the energy they dissipated, the
/// normal impulse their forces transmitted and the deepest penetration
/// (metered on every step, `SimStats::contact`), and the contact switches
/// (where a pair with restitution records began or ended to touch): time,
/// point, obstacle, speed, and the impulse: at a touch, an impulse law's
/// jump; at a release, what the contact forces transmitted since that
/// pair's touch.
pub fn summary(
    arm: &dyn runtime::Dynamics,
    traj: &runtime::Trajectory,
    meter: Option<runtime::ContactMeter>,
) -> serde_json::Value {
    let Some(set) = arm.contact() else {
        return serde_json::Value::Null;
    };
    let record_at = |t: f64| {
        traj.switches
            .iter()
            .find(|r| (r.t - t).abs() <= 1e-12 * t.abs().max(1.0))
    };
    // The metered impulse at each pair's last touch.
    let mut touched_at: std::collections::HashMap<usize, f64> = Default::default();
    let switches: Vec<serde_json::Value> = traj
        .events
        .iter()
        .filter(|e| e.name == runtime::CONTACT_EVENT)
        .map(|e| {
            let forces = forces_at(arm, e.t, &e.x).unwrap_or_default();
            // The pair at its surface is the one that switched.
            let at = forces
                .iter()
                .enumerate()
                .filter(|(i, _)| set.keeps_record(*i))
                .min_by(|a, b| a.1.gap.abs().total_cmp(&b.1.gap.abs()));
            let Some((i, f)) = at else {
                return serde_json::json!({ "t": e.t });
            };
            let touch = f.approach > 0.0;
            let record = record_at(e.t);
            let metered = record.map(|r| r.metered_impulse_ns);
            let impulse = if touch {
                if let Some(m) = metered {
                    touched_at.insert(i, m);
                }
                record.and_then(|r| r.jumps.iter().find(|j| j.0 == i).map(|j| j.1))
            } else {
                metered
                    .zip(touched_at.remove(&i))
                    .map(|(now, then)| now - then)
            };
            serde_json::json!({
                "t": e.t,
                "point": set.pairs[i].point,
                "with": set.channels[set.pairs[i].channel],
                "kind": if touch { "touch" } else { "release" },
                "normal_speed": f.approach,
                "impulse_ns": impulse,
            })
        })
        .collect();
    let meter = meter.unwrap_or_default();
    serde_json::json!({
        "max_penetration_m": meter.max_penetration_m,
        "dissipated_j": meter.dissipated_j,
        "normal_impulse_ns": meter.normal_impulse_ns,
        "switches": switches,
    })
}

/// `<stem>.png`: each channel's normal force against time (`forces`: per
/// sample, t and the channel columns as `columns` gives them).
pub fn plot_forces(
    stem: &Path,
    title: &str,
    channels: &[String],
    forces: &[(f64, Vec<f64>)],
) -> Result<()> {
    use plotters::prelude::*;
    let t1 = forces.last().map_or(1.0, |f| f.0).max(1e-9);
    let top = forces
        .iter()
        .flat_map(|(_, v)| v.iter().step_by(2).copied())
        .filter(|v| v.is_finite())
        .fold(1e-6, f64::max);
    crate::compare::register_font();
    let size = (900u32, 500u32);
    let mut rgb = vec![255u8; 3 * (size.0 * size.1) as usize];
    {
        let e = |e: &dyn std::fmt::Display| anyhow::anyhow!("{}: {e}", stem.display());
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        root.fill(&WHITE).map_err(|x| e(&x))?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(|x| e(&x))?;
        let mut chart = ChartBuilder::on(&root)
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..t1, 0.0..1.05 * top)
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc("t (s)")
            .y_desc("normal force (N)")
            .draw()
            .map_err(|x| e(&x))?;
        for (k, name) in channels.iter().enumerate() {
            let color = Palette99::pick(k).to_rgba();
            chart
                .draw_series(LineSeries::new(
                    forces.iter().map(|(t, v)| (*t, v[2 * k])),
                    color.stroke_width(2),
                ))
                .map_err(|x| e(&x))?
                .label(name.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        }
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

/// A start with a point's centreline inside an obstacle (deeper than its
/// tube) is an error naming the obstacle, the point and the depth: the
/// penalty laws would throw it out violently, and an impulse contact
/// cannot begin there.
pub fn check_start(arm: &dyn runtime::Dynamics, origin: &str, q: &[f64]) -> Result<()> {
    let Some(set) = arm.contact() else {
        return Ok(());
    };
    let n = arm.dof();
    let mut x = q.to_vec();
    x.extend(vec![0.0; n]);
    let Some(forces) = forces_at(arm, 0.0, &x) else {
        return Ok(());
    };
    for (pair, f) in set.pairs.iter().zip(&forces) {
        let radius = set.points[pair.point].radius;
        let depth = -f.gap;
        if depth > radius.max(1e-9) && matches!(pair.other, runtime::contact::Against::Obstacle(_))
        {
            let at = match set.points[pair.point].element {
                Some((arm_k, e)) => format!("point {} (arm {arm_k}, element {e})", pair.point),
                None => format!("point {} (a body's centre)", pair.point),
            };
            bail!(
                "{origin}: the start is inside obstacle \"{}\": {at} is {:.3} mm deep (its tube radius is {:.3} mm); move the obstacle or start elsewhere (--q0, [simulate] q0)",
                set.channels[pair.channel],
                1e3 * depth,
                1e3 * radius
            );
        }
    }
    Ok(())
}
