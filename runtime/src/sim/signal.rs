//! Input signals: functions of time that drive runtime parameters (chamber
//! pressures, tendon tensions, tip loads) during a run.
//!
//! Recorded data is interpolated linearly between samples, never held: a
//! sample-and-hold lags the record by half a sample on average, which shows
//! as a phase error against the measured motion.

use std::cell::Cell;

/// A signal of time.
#[derive(Clone, Debug)]
pub enum Signal {
    Constant(f64),
    /// `before` until `time`, then `after`.
    Step {
        before: f64,
        after: f64,
        time: f64,
    },
    /// `from` until `start`, linear to `to` at `end`, then `to`.
    Ramp {
        from: f64,
        to: f64,
        start: f64,
        end: f64,
    },
    /// bias + amplitude sin(2 pi frequency (t - start) + phase) from `start`,
    /// bias before (phase in radians).
    Sine {
        amplitude: f64,
        frequency: f64,
        phase: f64,
        bias: f64,
        start: f64,
    },
    /// Samples, linearly interpolated; the end values held outside.
    Table(Table),
    /// `inner` from `start` to `end` (both included), 0 outside: the rate
    /// of a ramp, or of a table (whose held end values do not move).
    Gate {
        inner: Box<Signal>,
        start: f64,
        end: f64,
    },
    /// A weighted sum of signals: a parameter several channels drive (a
    /// tip wrench read in a sensor's frame is a fixed linear map of its six
    /// channels).
    Sum(Vec<(f64, Signal)>),
}

impl Signal {
    pub fn at(&self, t: f64) -> f64 {
        match self {
            Signal::Constant(v) => *v,
            Signal::Step {
                before,
                after,
                time,
            } => {
                if t < *time {
                    *before
                } else {
                    *after
                }
            }
            Signal::Ramp {
                from,
                to,
                start,
                end,
            } => {
                let s = ((t - start) / (end - start)).clamp(0.0, 1.0);
                from + s * (to - from)
            }
            Signal::Sine {
                amplitude,
                frequency,
                phase,
                bias,
                start,
            } => {
                if t < *start {
                    *bias
                } else {
                    let arg = 2.0 * std::f64::consts::PI * frequency * (t - start) + phase;
                    bias + amplitude * arg.sin()
                }
            }
            Signal::Table(tab) => tab.at(t),
            Signal::Gate { inner, start, end } => {
                if (*start..=*end).contains(&t) {
                    inner.at(t)
                } else {
                    0.0
                }
            }
            Signal::Sum(terms) => terms.iter().map(|(w, s)| w * s.at(t)).sum(),
        }
    }

    /// The signal's time derivative (what a moving base's velocity and
    /// acceleration follow): exact for the analytic signals (the jumps of a
    /// step or at a gate's edges are left out), and for a table the
    /// differences of its samples (central, one-sided at the ends),
    /// interpolated linearly in turn, zero outside the record.
    pub fn derivative(&self) -> Signal {
        match self {
            Signal::Constant(_) | Signal::Step { .. } => Signal::Constant(0.0),
            Signal::Ramp {
                from,
                to,
                start,
                end,
            } => Signal::Gate {
                inner: Box::new(Signal::Constant((to - from) / (end - start))),
                start: *start,
                end: *end,
            },
            Signal::Gate { inner, start, end } => Signal::Gate {
                inner: Box::new(inner.derivative()),
                start: *start,
                end: *end,
            },
            Signal::Sine {
                amplitude,
                frequency,
                phase,
                start,
                ..
            } => Signal::Sine {
                amplitude: amplitude * 2.0 * std::f64::consts::PI * frequency,
                frequency: *frequency,
                phase: phase + std::f64::consts::FRAC_PI_2,
                bias: 0.0,
                start: *start,
            },
            Signal::Sum(terms) => {
                Signal::Sum(terms.iter().map(|(w, s)| (*w, s.derivative())).collect())
            }
            Signal::Table(tab) => {
                let (t0, t1) = (tab.times[0], tab.times[tab.times.len() - 1]);
                Signal::Gate {
                    inner: Box::new(Signal::Table(tab.derivative())),
                    start: t0,
                    end: t1,
                }
            }
        }
    }
}

/// Why a table cannot be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TableError {
    #[error("needs at least one sample")]
    Empty,
    #[error("times and values differ in length ({times} and {values})")]
    Length { times: usize, values: usize },
    #[error("sample {index} is not finite (t = {t}, value = {value})")]
    NotFinite { index: usize, t: f64, value: f64 },
    #[error("times must increase: sample {index} at {t} s follows {previous} s")]
    NotIncreasing { index: usize, t: f64, previous: f64 },
}

/// Sampled values with increasing times.
#[derive(Clone, Debug)]
pub struct Table {
    times: Vec<f64>,
    values: Vec<f64>,
    /// The interval of the last lookup: integrators ask for nearby times.
    last: Cell<usize>,
}

impl Table {
    pub fn new(times: Vec<f64>, values: Vec<f64>) -> Result<Self, TableError> {
        if times.len() != values.len() {
            return Err(TableError::Length {
                times: times.len(),
                values: values.len(),
            });
        }
        if times.is_empty() {
            return Err(TableError::Empty);
        }
        for (i, (&t, &v)) in times.iter().zip(&values).enumerate() {
            if !(t.is_finite() && v.is_finite()) {
                return Err(TableError::NotFinite {
                    index: i,
                    t,
                    value: v,
                });
            }
            if i > 0 && t <= times[i - 1] {
                return Err(TableError::NotIncreasing {
                    index: i,
                    t,
                    previous: times[i - 1],
                });
            }
        }
        Ok(Self {
            times,
            values,
            last: Cell::new(0),
        })
    }

    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// Central differences of the samples, one-sided at the ends (zero for
    /// a single sample).
    pub fn derivative(&self) -> Table {
        let (ts, vs) = (&self.times, &self.values);
        let n = ts.len();
        let slope = |a: usize, b: usize| (vs[b] - vs[a]) / (ts[b] - ts[a]);
        let values = (0..n)
            .map(|i| match n {
                1 => 0.0,
                _ => slope(i.saturating_sub(1), (i + 1).min(n - 1)),
            })
            .collect();
        Table {
            times: ts.clone(),
            values,
            last: Cell::new(0),
        }
    }

    pub fn values(&self) -> &[f64] {
        &self.values
    }

    pub fn at(&self, t: f64) -> f64 {
        let (ts, vs) = (&self.times, &self.values);
        let n = ts.len();
        if n == 1 || t <= ts[0] {
            return vs[0];
        }
        if t >= ts[n - 1] {
            return vs[n - 1];
        }
        // Interval i with ts[i] <= t < ts[i + 1]: the cached one or its
        // neighbour, else a binary search.
        let mut i = self.last.get().min(n - 2);
        if !(ts[i] <= t && t < ts[i + 1]) {
            i = if i + 2 < n && ts[i + 1] <= t && t < ts[i + 2] {
                i + 1
            } else {
                ts.partition_point(|&x| x <= t) - 1
            };
            self.last.set(i);
        }
        let s = (t - ts[i]) / (ts[i + 1] - ts[i]);
        vs[i] + s * (vs[i + 1] - vs[i])
    }
}

/// Centred moving average over `window` samples (an even window uses one
/// fewer, as MATLAB's `smooth` does), shrinking near the ends so that the
/// first and last samples are kept: no lag.
pub fn moving_average(values: &[f64], window: usize) -> Vec<f64> {
    let half = window.saturating_sub(1) / 2;
    let n = values.len();
    (0..n)
        .map(|i| {
            let h = half.min(i).min(n - 1 - i);
            let s: f64 = values[i - h..=i + h].iter().sum();
            s / (2 * h + 1) as f64
        })
        .collect()
}

/// A runtime parameter driven by a signal.
#[derive(Clone, Debug)]
pub struct Drive {
    /// Index in the parameter layout.
    pub param: usize,
    pub signal: Signal,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_are_exact_for_analytic_signals_and_second_order_for_tables() {
        let sine = Signal::Sine {
            amplitude: 0.3,
            frequency: 1.5,
            phase: 0.4,
            bias: 2.0,
            start: 0.1,
        };
        let ramp = Signal::Ramp {
            from: 1.0,
            to: 3.0,
            start: 0.5,
            end: 1.5,
        };
        // Central differences of the signal itself, away from kinks.
        let h = 1e-5;
        for s in [&sine, &ramp] {
            let (d, dd) = (s.derivative(), s.derivative().derivative());
            for t in [0.3, 0.7, 1.2, 2.0] {
                let fd = (s.at(t + h) - s.at(t - h)) / (2.0 * h);
                assert!(
                    (d.at(t) - fd).abs() < 1e-6,
                    "rate at {t}: {} vs {fd}",
                    d.at(t)
                );
                let fdd = (d.at(t + h) - d.at(t - h)) / (2.0 * h);
                assert!((dd.at(t) - fdd).abs() < 1e-5, "second at {t}");
            }
        }
        assert_eq!(sine.derivative().at(0.0), 0.0, "still before start");
        // A table of a parabola: central differences are exact for it.
        let times: Vec<f64> = (0..11).map(|i| 0.1 * f64::from(i)).collect();
        let values = times.iter().map(|t| 3.0 * t * t - t).collect();
        let d = Signal::Table(Table::new(times, values).unwrap()).derivative();
        for t in [0.1, 0.5, 0.9] {
            assert!(
                (d.at(t) - (6.0 * t - 1.0)).abs() < 1e-12,
                "table rate at {t}"
            );
        }
        // The table holds its end values: nothing moves outside the record.
        for t in [-0.5, 1.5] {
            assert_eq!(d.at(t), 0.0, "rate outside the record at {t}");
        }
    }

    #[test]
    fn table_interpolates_linearly_and_holds_the_ends() {
        let t = Table::new(vec![0.0, 1.0, 3.0], vec![2.0, 4.0, 0.0]).unwrap();
        // Exact for data on a line within each interval.
        for (x, want) in [
            (-1.0, 2.0),
            (0.0, 2.0),
            (0.25, 2.5),
            (1.0, 4.0),
            (2.0, 2.0),
            (2.9, 0.2),
            (3.0, 0.0),
            (9.0, 0.0),
            (0.5, 3.0), // backwards after a later lookup
        ] {
            assert!(
                (t.at(x) - want).abs() < 1e-14,
                "at {x}: {} vs {want}",
                t.at(x)
            );
        }
    }

    #[test]
    fn table_rejects_bad_samples() {
        assert_eq!(Table::new(vec![], vec![]).unwrap_err(), TableError::Empty);
        assert!(matches!(
            Table::new(vec![0.0, 0.0], vec![1.0, 2.0]),
            Err(TableError::NotIncreasing { index: 1, .. })
        ));
        assert!(matches!(
            Table::new(vec![0.0, f64::NAN], vec![1.0, 2.0]),
            Err(TableError::NotFinite { index: 1, .. })
        ));
    }

    #[test]
    fn moving_average_keeps_lines_and_removes_alternation() {
        // A centred average reproduces a straight line exactly (no lag)...
        let line: Vec<f64> = (0..20).map(|i| 0.5 * i as f64 + 1.0).collect();
        for (a, b) in moving_average(&line, 9).iter().zip(&line) {
            assert!((a - b).abs() < 1e-12);
        }
        // ... and averages an alternation of period 2 over an odd window
        // to +-1/window in the interior.
        let alt: Vec<f64> = (0..20)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let s = moving_average(&alt, 5);
        for v in &s[2..18] {
            assert!((v.abs() - 0.2).abs() < 1e-12, "{v}");
        }
        // An even window behaves as the odd one below it.
        assert_eq!(moving_average(&alt, 6), s);
    }

    #[test]
    fn analytic_signals_match_their_definitions() {
        let step = Signal::Step {
            before: 1.0,
            after: 3.0,
            time: 2.0,
        };
        assert_eq!((step.at(1.999), step.at(2.0)), (1.0, 3.0));
        let ramp = Signal::Ramp {
            from: 0.0,
            to: 10.0,
            start: 1.0,
            end: 3.0,
        };
        assert_eq!((ramp.at(0.0), ramp.at(2.0), ramp.at(5.0)), (0.0, 5.0, 10.0));
        let sine = Signal::Sine {
            amplitude: 2.0,
            frequency: 0.5,
            phase: 0.0,
            bias: 1.0,
            start: 1.0,
        };
        assert_eq!(sine.at(0.0), 1.0);
        assert!((sine.at(1.5) - (1.0 + 2.0 * (std::f64::consts::PI / 2.0).sin())).abs() < 1e-14);
    }
}
