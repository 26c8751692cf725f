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
            delay,
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
            let times = times.iter().map(|t| t + delay).collect();
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

/// Input channels a controller drives: every drive bound to one of them
/// (a chamber pair's pressure, a tip load's component), to be held at a
/// value (zero-order hold) in place of the channel's signal.
#[derive(Clone, Debug)]
pub struct Controls {
    pub names: Vec<String>,
    /// (drive, channel in `names`, derivative the drive takes of it).
    drives: Vec<(usize, usize, usize)>,
}

impl Controls {
    /// The channels `names` of a model (its data files relative to
    /// `base_dir`), or an error naming the one that drives nothing and the
    /// channels that exist.
    pub fn new(model: &Model, base_dir: &Path, names: &[String]) -> Result<Self> {
        let structure = eomgen::model::Structure::of(model);
        let layout = ParamLayout::of(&structure);
        let labels = labelled_drives(model, &layout, base_dir)?;
        let mut drives = Vec::new();
        for (i, name) in names.iter().enumerate() {
            let of: Vec<_> = (labels.iter().enumerate())
                .filter_map(|(k, (_, l))| match l {
                    Some((c, der)) if c == name => Some((k, i, *der)),
                    _ => None,
                })
                .collect();
            if of.is_empty() {
                let known: Vec<&String> = model.inputs.keys().collect();
                anyhow::bail!(
                    "inputs: no channel {name:?} drives this model; its channels are {known:?}"
                );
            }
            drives.extend(of);
        }
        Ok(Self {
            names: names.to_vec(),
            drives,
        })
    }

    /// Hold the channels at `u` (one value each; a drive of a channel's
    /// rate holds zero).
    pub fn hold(&self, arm: &mut dyn runtime::Dynamics, u: &[f64]) {
        for &(k, i, der) in &self.drives {
            let v = if der == 0 { u[i] } else { 0.0 };
            arm.set_drive_signal(k, Signal::Constant(v));
        }
    }

    /// Drive channel `i` by `signal` (its drives of the channel's rate by
    /// the signal's derivative).
    pub fn drive(&self, arm: &mut dyn runtime::Dynamics, i: usize, signal: &Signal) {
        for &(k, c, der) in &self.drives {
            if c == i {
                let mut s = signal.clone();
                for _ in 0..der {
                    s = s.derivative();
                }
                arm.set_drive_signal(k, s);
            }
        }
    }
}
