//! A model's input channels as runtime signals, bound to the parameters
//! they drive.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result};
use eomgen::model::sensor::{Source, wrench_sources};
use eomgen::model::{Input, Model, Offset, Param, ParamLayout};
use runtime::signal::{Drive, Signal, Table, moving_average};

use crate::data::{Csv, resolve};

/// The signal of one channel; CSV paths are relative to `base`.
pub fn signal(name: &str, input: &Input, base: &Path) -> Result<Signal> {
    Ok(match input {
        Input::Constant { value } => Signal::Constant(*value),
        Input::Step {
            before,
            after,
            time,
        } => Signal::Step {
            before: *before,
            after: *after,
            time: *time,
        },
        Input::Ramp {
            from,
            to,
            start,
            end,
        } => Signal::Ramp {
            from: *from,
            to: *to,
            start: *start,
            end: *end,
        },
        Input::Sine {
            amplitude,
            frequency,
            phase,
            bias,
            start,
        } => Signal::Sine {
            amplitude: *amplitude,
            frequency: *frequency,
            phase: phase.to_radians(),
            bias: *bias,
            start: *start,
        },
        Input::Csv {
            file,
            column,
            time,
            scale,
            offset,
            smooth,
        } => {
            let path = resolve(base, file);
            let csv = Csv::read(&path).with_context(|| format!("inputs.{name}.file"))?;
            let times = csv
                .time_column(time)
                .with_context(|| format!("inputs.{name}.time"))?;
            let raw = csv
                .column(column)
                .with_context(|| format!("inputs.{name}.column"))?;
            let shift = match offset {
                None => 0.0,
                Some(Offset::Value(v)) => *v,
                Some(Offset::Named(_)) => raw[0], // "first", validated
            };
            let values: Vec<f64> = raw.iter().map(|v| scale * (v - shift)).collect();
            let values = moving_average(&values, *smooth);
            Signal::Table(
                Table::new(times, values)
                    .with_context(|| format!("inputs.{name}: {}", path.display()))?,
            )
        }
    })
}

/// The drives of a model whose parameter layout is `layout`.
pub fn model_drives(model: &Model, layout: &ParamLayout, base: &Path) -> Result<Vec<Drive>> {
    Ok(labelled_drives(model, layout, base)?
        .into_iter()
        .map(|(d, _)| d)
        .collect())
}

/// A drive bound to one channel: the channel's name and which derivative
/// of it the parameter takes (0: the value; a moving base's velocity 1).
pub type DriveLabel = (String, usize);

/// `model_drives`, each with its channel where it reads one alone (a
/// sensor frame's weighted sum of channels has none): what a controller
/// replaces to hold a channel at its value over a step.
pub fn labelled_drives(
    model: &Model,
    layout: &ParamLayout,
    base: &Path,
) -> Result<Vec<(Drive, Option<DriveLabel>)>> {
    let mut signals: BTreeMap<&str, Signal> = BTreeMap::new();
    let mut out = Vec::new();
    for d in layout.driven() {
        // A tip wrench read in a sensor frame: a weighted sum of sources.
        let row = match d.param {
            Param::TipForce(c) => Some(c.index()),
            Param::TipMoment(c) => Some(3 + c.index()),
            _ => None,
        };
        if let Some(sources) = row.and_then(|r| wrench_sources(model, r)) {
            let mut terms = Vec::new();
            for (w, source) in sources {
                let s = match source {
                    Source::Constant(v) => Signal::Constant(v),
                    Source::Channel(name) => {
                        let (key, input) = model.inputs.get_key_value(name).expect("validated");
                        if !signals.contains_key(name) {
                            signals.insert(key, signal(name, input, base)?);
                        }
                        signals[name].clone()
                    }
                };
                terms.push((w, s));
            }
            let mut signal = Signal::Sum(terms);
            for _ in 0..d.derivative {
                signal = signal.derivative();
            }
            out.push((
                Drive {
                    param: layout.index(d.param),
                    signal,
                },
                None,
            ));
            continue;
        }
        let name = layout
            .channel(model, d.param)
            .with_context(|| format!("{}: no input channel (generator bug)", d.param.name()))?;
        let name = name.as_str();
        let (key, input) = model.inputs.get_key_value(name).expect("validated");
        if !signals.contains_key(name) {
            signals.insert(key, signal(name, input, base)?);
        }
        let mut signal = signals[name].clone();
        for _ in 0..d.derivative {
            signal = signal.derivative();
        }
        out.push((
            Drive {
                param: layout.index(d.param),
                signal,
            },
            Some((name.to_string(), d.derivative as usize)),
        ));
    }
    Ok(out)
}
