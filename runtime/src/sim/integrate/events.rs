//! Event location: the times at which a function of the state crosses zero.
//!
//! After every accepted step the event functions are evaluated at its end;
//! a sign change (in the direction asked for) is located on the method's
//! own dense output by the Illinois variant of regula falsi, so an event is
//! found to round-off in time, not to the step size. A terminal event ends
//! the run at the event, with the state there as the last sample: the hook
//! that contact and impact models build on.

use std::sync::Arc;

use differential_equations::interpolate::Interpolation;
use serde::Serialize;

use super::state::StateVec;

/// Which sign changes count.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Crossing {
    /// From negative to positive.
    Rising,
    /// From positive to negative.
    Falling,
    Either,
}

/// The event function g(t, x), x = [q, qd].
pub type EventFn = dyn Fn(f64, &[f64]) -> f64 + Send + Sync;

/// A g(t, x) that borrows (the contact switch reads the arm).
pub type SwitchFn<'a> = dyn Fn(f64, &[f64]) -> f64 + 'a;

/// A zero crossing to watch for.
#[derive(Clone)]
pub struct Event {
    pub name: String,
    pub crossing: Crossing,
    /// Stop the integration at the first such crossing.
    pub terminal: bool,
    pub g: Arc<EventFn>,
}

impl Event {
    pub fn new(
        name: impl Into<String>,
        crossing: Crossing,
        terminal: bool,
        g: impl Fn(f64, &[f64]) -> f64 + Send + Sync + 'static,
    ) -> Self {
        Self {
            name: name.into(),
            crossing,
            terminal,
            g: Arc::new(g),
        }
    }
}

impl std::fmt::Debug for Event {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Event")
            .field("name", &self.name)
            .field("crossing", &self.crossing)
            .field("terminal", &self.terminal)
            .finish_non_exhaustive()
    }
}

/// A located crossing.
#[derive(Clone, Debug, Serialize)]
pub struct EventHit {
    pub name: String,
    pub t: f64,
    /// The state [q, qd] at t.
    pub x: Vec<f64>,
}

/// The name of the event that ends a leg when a contact begins or ends
/// (`integrate::touch`).
pub const CONTACT_EVENT: &str = "contact";

/// The events of one run and what they have seen.
pub(crate) struct EventWatch {
    events: Vec<Event>,
    /// g at the start of the current step, per event, then the contact
    /// switch's.
    last: Vec<Option<f64>>,
    /// The length of the unpadded state.
    m: usize,
    pub hits: Vec<EventHit>,
}

impl EventWatch {
    pub fn new(events: &[Event], m: usize) -> Self {
        Self {
            events: events.to_vec(),
            last: vec![None; events.len() + 1],
            m,
            hits: Vec::new(),
        }
    }

    /// Check the step [t_prev, t_curr]: record its crossings in time order
    /// and return the first terminal one's time and state, if any.
    /// `switch` is the contact switch (a terminal falling crossing, named
    /// [`CONTACT_EVENT`]), which reads the arm and so is no `Event`.
    pub fn check<Y: StateVec, I: Interpolation<f64, Y> + ?Sized>(
        &mut self,
        t_prev: f64,
        t_curr: f64,
        y_prev: &Y,
        y_curr: &Y,
        interpolator: &mut I,
        switch: Option<&SwitchFn>,
    ) -> Option<(f64, Y)> {
        let m = self.m;
        let mut found: Vec<(f64, usize, Y)> = Vec::new();
        let count = self.events.len();
        for k in 0..=count {
            let (g, crossing): (&SwitchFn, Crossing) = match (k < count, switch) {
                (true, _) => (&*self.events[k].g, self.events[k].crossing),
                (false, Some(s)) => (s, Crossing::Falling),
                (false, None) => break,
            };
            let g0 = match self.last[k] {
                Some(g) => g,
                None => g(t_prev, &y_prev.as_ref()[..m]),
            };
            let g1 = g(t_curr, &y_curr.as_ref()[..m]);
            self.last[k] = Some(g1);
            let crossed = match crossing {
                Crossing::Rising => g0 < 0.0 && g1 >= 0.0,
                Crossing::Falling => g0 > 0.0 && g1 <= 0.0,
                Crossing::Either => (g0 < 0.0 && g1 >= 0.0) || (g0 > 0.0 && g1 <= 0.0),
            };
            if !crossed {
                continue;
            }
            let mut state_at = |t: f64| -> Y {
                if t == t_curr {
                    y_curr.clone()
                } else {
                    interpolator
                        .interpolate(t)
                        .unwrap_or_else(|_| y_curr.clone())
                }
            };
            let t = illinois(t_prev, t_curr, g0, g1, |t| g(t, &state_at(t).as_ref()[..m]));
            found.push((t, k, state_at(t)));
        }
        found.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut terminal = None;
        for (t, k, y) in found {
            let (name, stops) = match self.events.get(k) {
                Some(e) => (e.name.clone(), e.terminal),
                None => (CONTACT_EVENT.to_string(), true),
            };
            self.hits.push(EventHit {
                name,
                t,
                x: y.as_ref()[..m].to_vec(),
            });
            if stops {
                terminal = Some((t, y));
                break;
            }
        }
        terminal
    }
}

/// A root of g in [a, b], where g(a) = ga and g(b) = gb differ in sign:
/// regula falsi with the Illinois halving of a stagnant end's value.
fn illinois(
    mut a: f64,
    mut b: f64,
    mut ga: f64,
    mut gb: f64,
    mut g: impl FnMut(f64) -> f64,
) -> f64 {
    if gb == 0.0 {
        return b;
    }
    let mut side = 0i8;
    for _ in 0..100 {
        let tol = 4.0 * f64::EPSILON * a.abs().max(b.abs()).max(1e-300);
        if (b - a).abs() <= tol {
            break;
        }
        let c = (a * gb - b * ga) / (gb - ga);
        let c = if c > a.min(b) && c < a.max(b) {
            c
        } else {
            0.5 * (a + b)
        };
        let gc = g(c);
        if gc == 0.0 {
            return c;
        }
        if (gc > 0.0) == (gb > 0.0) {
            b = c;
            gb = gc;
            if side == -1 {
                ga *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            ga = gc;
            if side == 1 {
                gb *= 0.5;
            }
            side = 1;
        }
    }
    // The end on the far side of the crossing, so the event has happened.
    b
}

#[cfg(test)]
mod tests {
    use super::illinois;

    #[test]
    fn illinois_finds_roots_to_round_off() {
        let r = illinois(0.0, 2.0, -2.0, 2.0, |x| x * x - 2.0);
        assert!((r - 2f64.sqrt()).abs() < 1e-14, "{r}");
        // A flat, one-sided function where plain regula falsi stagnates.
        let f = |x: f64| x.powi(9) - 1e-9;
        let r = illinois(0.0, 1.0, f(0.0), f(1.0), f);
        assert!((r - 0.1).abs() < 1e-12, "{r}");
        let r = illinois(1.0, 4.0, 1f64.sin(), 4f64.sin(), f64::sin);
        assert!((r - std::f64::consts::PI).abs() < 1e-14, "{r}");
    }
}
