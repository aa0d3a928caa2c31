//! Ready-made [`Sink`]s: record everything, or only the events.

use crate::integrate::{Flow, Sink};
use crate::model::{EventKind, Mode, Modes};

/// One recorded event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EventRecord<const N: usize> {
    /// Time (s).
    pub t: f64,
    /// What happened.
    pub kind: EventKind,
    /// State at the event.
    pub z: [f64; N],
    /// Mode after the event (of the first contact).
    pub mode: Mode,
    /// The contact the event belongs to (0 for one-contact models).
    pub contact: usize,
    /// Modes of every contact after the event.
    pub modes: Modes,
}

/// Keeps every sample and event in memory.
#[derive(Debug, Clone, Default)]
pub struct Recorder<const N: usize> {
    /// Sample times.
    pub t: Vec<f64>,
    /// Sampled states.
    pub z: Vec<[f64; N]>,
    /// Mode at each sample.
    pub mode: Vec<Mode>,
    /// Events in order.
    pub events: Vec<EventRecord<N>>,
}

impl<const N: usize> Recorder<N> {
    /// An empty recorder.
    pub fn new() -> Self {
        Recorder {
            t: Vec::new(),
            z: Vec::new(),
            mode: Vec::new(),
            events: Vec::new(),
        }
    }
    /// The time series of state component `i`.
    pub fn component(&self, i: usize) -> Vec<f64> {
        self.z.iter().map(|z| z[i]).collect()
    }
    /// Events of one kind.
    pub fn events_of(&self, kind: EventKind) -> impl Iterator<Item = &EventRecord<N>> {
        self.events.iter().filter(move |e| e.kind == kind)
    }
}

impl<const N: usize> Sink<N> for Recorder<N> {
    fn sample(&mut self, t: f64, z: &[f64; N], mode: Mode) -> Flow {
        self.t.push(t);
        self.z.push(*z);
        self.mode.push(mode);
        Flow::Continue
    }
    fn event(&mut self, t: f64, kind: EventKind, z: &[f64; N], mode: Mode) {
        self.contact_event(t, kind, 0, z, &Modes::single(mode));
    }
    fn contact_event(
        &mut self,
        t: f64,
        kind: EventKind,
        contact: usize,
        z: &[f64; N],
        modes: &Modes,
    ) {
        self.events.push(EventRecord {
            t,
            kind,
            z: *z,
            mode: modes.first(),
            contact,
            modes: *modes,
        });
    }
}

/// Keeps only the events (sampling is ignored).
#[derive(Debug, Clone, Default)]
pub struct EventLog<const N: usize> {
    /// Events in order.
    pub events: Vec<EventRecord<N>>,
}

impl<const N: usize> Sink<N> for EventLog<N> {
    fn sample(&mut self, _t: f64, _z: &[f64; N], _mode: Mode) -> Flow {
        Flow::Continue
    }
    fn event(&mut self, t: f64, kind: EventKind, z: &[f64; N], mode: Mode) {
        self.contact_event(t, kind, 0, z, &Modes::single(mode));
    }
    fn contact_event(
        &mut self,
        t: f64,
        kind: EventKind,
        contact: usize,
        z: &[f64; N],
        modes: &Modes,
    ) {
        self.events.push(EventRecord {
            t,
            kind,
            z: *z,
            mode: modes.first(),
            contact,
            modes: *modes,
        });
    }
}

/// Discards everything (for benchmarks and statistics-only runs).
#[derive(Debug, Clone, Copy, Default)]
pub struct Discard;

impl<const N: usize> Sink<N> for Discard {
    fn sample(&mut self, _t: f64, _z: &[f64; N], _mode: Mode) -> Flow {
        Flow::Continue
    }
}
