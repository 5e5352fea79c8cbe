//! One phase of a run: free adaptive steps with dense output, outputs on the run's grid, and
//! the watched quantities checked inside every step, not only at its ends (docs/method.md
//! §12): the normal forces in contact, a flying follower's gap.
//!
//! A bilateral run is one phase; a one-sided run ([`crate::unilateral`]) alternates phases
//! in contact and in flight, which share the run's [`Grid`] of output times and its
//! [`Recorder`] (samples, events, work, the monitor and the stall watchdog).

use crate::control::{Monitor, Progress, Watchdog};
use crate::dynamics::{Dynamics, SimSettings};
use crate::error::SimError;
use crate::events::{
    ContactEvent, EVENT_TIME_TOLERANCE, EventKind, changes_sign, locate_root, locate_root_within,
};
use crate::integrators::stage_quadrature;
use crate::partition::Workspace;
use crate::sample::{Sample, SampleLevel, sample_in_place, sample_interpolated};
use crate::scan::{Closing, ForceStep, GapPoint, excursion_guess, find_excursion, first_closing};
use crate::stepping::{
    State, Stats, adaptive_step, finish_step, interpolate_last_step, load_state,
};

/// The output times of a run, t0 + k·dt_out and t_end, shared by its phases.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Grid {
    t0: f64,
    intervals: usize,
    /// Index of the next output to emit.
    pub(crate) next: usize,
}

impl Grid {
    /// The grid of `settings` from t0, nothing emitted yet.
    pub(crate) fn new(t0: f64, settings: &SimSettings) -> Self {
        Grid {
            t0,
            intervals: output_intervals(t0, settings),
            next: 0,
        }
    }

    fn time(&self, k: usize, settings: &SimSettings) -> f64 {
        output_time(self.t0, k, self.intervals, settings)
    }

    /// The next output time, if any is left.
    pub(crate) fn pending(&self, settings: &SimSettings) -> Option<f64> {
        (self.next <= self.intervals).then(|| self.time(self.next, settings))
    }
}

/// What a run keeps across its phases: the samples (each shown to the monitor as soon as it
/// is recorded; all of them, or only the last when the monitor keeps none), the events, the
/// work done, and the pace of its steps.
pub(crate) struct Recorder<'m> {
    /// Every sample in time order, or only the last one (see [`Monitor::keep_samples`]).
    pub(crate) samples: Vec<Sample>,
    /// Samples recorded, kept or not.
    pub(crate) count: usize,
    /// Whether every sample is kept.
    keep: bool,
    pub(crate) events: Vec<ContactEvent>,
    pub(crate) stats: Stats,
    monitor: &'m mut dyn Monitor,
    watchdog: Watchdog,
    steps: usize,
    /// The run's end time.
    end: f64,
}

impl<'m> Recorder<'m> {
    /// An empty record of a run from `t0` with `settings`, watched by `monitor`.
    pub(crate) fn new(monitor: &'m mut dyn Monitor, settings: &SimSettings, t0: f64) -> Self {
        Recorder {
            samples: Vec::new(),
            count: 0,
            keep: monitor.keep_samples(),
            events: Vec::new(),
            stats: Stats::default(),
            monitor,
            watchdog: Watchdog::new(t0, settings.rtol, settings.atol),
            steps: 0,
            end: settings.t_end,
        }
    }

    /// Records a sample at an output time.
    ///
    /// # Errors
    /// [`SimError::Interrupted`] when the monitor asks to stop.
    pub(crate) fn emit(&mut self, sample: Sample) -> Result<(), SimError> {
        let flow = self.monitor.sample(&sample);
        let t = sample.t;
        self.keep_sample(sample);
        self.watchdog.output_reached();
        if flow.is_break() {
            Err(SimError::Interrupted { t })
        } else {
            Ok(())
        }
    }

    /// Whether every sample is kept (the monitor's choice when the run started).
    pub(crate) fn keeps_samples(&self) -> bool {
        self.keep
    }

    /// Counts a sample and keeps it: after the others, or in place of the last one when the
    /// run keeps only that. Not shown to the monitor (the last accepted state after a
    /// failure goes through here alone).
    pub(crate) fn keep_sample(&mut self, sample: Sample) {
        self.count += 1;
        match self.samples.last_mut() {
            Some(last) if !self.keep => *last = sample,
            _ => self.samples.push(sample),
        }
    }

    /// After an accepted step that ended at `t` with size `h`, on the way to `next` (the next
    /// output time) and to the run's end.
    ///
    /// # Errors
    /// [`SimError::Stalled`] or [`SimError::TooManySteps`] from the watchdog,
    /// [`SimError::Interrupted`] when the monitor asks to stop.
    pub(crate) fn stepped(&mut self, t: f64, h: f64, next: f64) -> Result<(), SimError> {
        self.watchdog.step(t, h, (next, self.end))?;
        self.steps += 1;
        let progress = Progress {
            t,
            h,
            steps: self.steps,
        };
        if self.monitor.step(&progress).is_break() {
            Err(SimError::Interrupted { t })
        } else {
            Ok(())
        }
    }
}

/// A flying follower's gap as the scan needs it at one state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GapReading {
    /// The gap h (m, positive above the cam).
    pub(crate) g: f64,
    /// ḣ = J q̇ (m/s).
    pub(crate) rate: f64,
    /// How fast the cam turns relative to the follower point (rad/s): the point's speed in
    /// the cam frame over its distance from the frame's origin. Sets how finely a step is cut
    /// for the gap's scan.
    pub(crate) turn_rate: f64,
    /// A bound on |ḣ| (m/s): the speed, relative to the follower, of the cam's material at
    /// the contact point.
    pub(crate) speed: f64,
}

/// A flying follower's gap at (q, q̇).
pub(crate) type GapFn<'a> = &'a dyn Fn(&[f64], &[f64]) -> GapReading;

/// What a phase of a run watches for at every step (see [`crate::scan`]).
pub(crate) enum Watch<'a> {
    /// Nothing.
    Nothing,
    /// Sign changes of the normal forces, inside steps too, recorded as events; with
    /// `stop`, the first one to zero or below ends the phase (a one-sided follower lifts off).
    Forces {
        /// End the phase when a force reaches zero from above.
        stop: bool,
    },
    /// The gap h(q) of a flying follower, read by `gap` at (q, q̇): its reaching zero from
    /// above ends the phase (the follower lands). The flight starts on the cam.
    Gap {
        /// The gap at (q, q̇).
        gap: GapFn<'a>,
        /// The landing is located until |h| is below this (m); see [`landing_tolerance`].
        tolerance: f64,
    },
}

/// The gap a landing is located to: max(atol, 1e-12) m times the model's length scale (at
/// least 1). Time's own resolution can make the located gap larger at high approach speeds
/// late in a run: |ḣ| times a few units of the last place of t.
pub(crate) fn landing_tolerance(settings: &SimSettings, length_scale: f64) -> f64 {
    settings.atol.max(1e-12) * length_scale.max(1.0)
}

/// Where and why a phase ended before t_end.
#[derive(Debug, Clone)]
pub(crate) struct Stop {
    pub(crate) t: f64,
    pub(crate) contact: usize,
    pub(crate) q: Vec<f64>,
    pub(crate) qd: Vec<f64>,
    /// Dissipated energy and driven work at t.
    pub(crate) quadratures: (f64, f64),
}

/// One phase of a run: free adaptive steps with dense output, outputs on the shared grid,
/// events located inside the steps.
pub(crate) struct Phase<'p, 'w, 'm> {
    pub(crate) settings: &'p SimSettings,
    pub(crate) level: SampleLevel,
    pub(crate) watch: &'p Watch<'w>,
    pub(crate) grid: &'p mut Grid,
    pub(crate) record: &'p mut Recorder<'m>,
    /// Completes every sample before it is recorded (a flight's samples get the contact's
    /// view of the gap).
    pub(crate) complete: Option<&'p dyn Fn(&mut Sample)>,
}

/// A watched value at one time: −λ of a contact (the sign of its normal force), or a gap.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Reading {
    value: f64,
    rate: f64,
    turn_rate: f64,
    speed: f64,
}

impl Reading {
    fn of_force(p: f64) -> Self {
        Reading {
            value: p,
            rate: 0.0,
            turn_rate: 0.0,
            speed: 0.0,
        }
    }

    fn of_gap(gap: GapReading) -> Self {
        Reading {
            value: gap.g,
            rate: gap.rate,
            turn_rate: gap.turn_rate,
            speed: gap.speed,
        }
    }
}

/// A piece of a flight's step turns the cam by at most this much relative to the follower
/// point (rad): a cam's profile is smooth over a quarter radian, so the cubic Hermite check
/// of each piece sees every lobe (docs/method.md §14).
const PIECE_TURN: f64 = 0.25;

/// Most pieces a flight's step is cut into.
const MAX_PIECES: usize = 4096;

impl Phase<'_, '_, '_> {
    /// Integrates until the grid is done or the watch stops the phase.
    pub(crate) fn run(
        &mut self,
        model: &dyn Dynamics,
        state: &mut State,
    ) -> Result<Option<Stop>, SimError> {
        if state.modified_since_last_step() {
            state.load_integrated_state();
        }
        if self.grid.next == 0 {
            let sample = sample_in_place(model, state, self.level)?;
            self.emit(sample)?;
            self.grid.next = 1;
        }
        let contacts = match self.watch {
            Watch::Forces { .. } => model.info().n_contacts(),
            _ => 0,
        };
        state.engine.stages.watch(contacts);
        let outcome = self.steps(model, state);
        state.engine.stages.watch(0);
        outcome
    }

    fn steps(&mut self, model: &dyn Dynamics, state: &mut State) -> Result<Option<Stop>, SimError> {
        let settings = self.settings;
        let mut sample_ws = state.engine.ws.clone();
        let mut y_out = state.engine.y.clone();
        let y_start = state.engine.y.clone();
        let t_start = state.t;
        let mut start = self.readings(model, state, &mut sample_ws, t_start, &y_start)?;
        if let Some(stop) = self.stop_at_start(state, &start) {
            return Ok(Some(stop));
        }
        let mut take_off = matches!(self.watch, Watch::Gap { .. });
        while self.grid.pending(settings).is_some() {
            let t_old = state.t;
            let t_new = adaptive_step(model, state, settings.t_end, settings)?;
            sample_ws
                .v_anchor
                .copy_from_slice(&state.engine.ws.v_anchor);
            // The step's end, where its last right-hand side left the workspace.
            let end = self.readings_at_end(model, state);
            let stop = self.scan_step(
                model,
                state,
                &mut sample_ws,
                (t_old, &start),
                (t_new, &end),
                take_off,
            )?;
            take_off = false;
            let limit = stop.as_ref().map_or(t_new, |s| s.t);
            while let Some(t_out) = self.grid.pending(settings) {
                let inside = t_out < limit || (stop.is_some() && t_out <= limit);
                if !inside {
                    break;
                }
                interpolate_last_step(model, state, settings, t_out, &mut y_out)?;
                let sample =
                    sample_interpolated(model, state, &mut sample_ws, t_out, &y_out, self.level)?;
                self.emit(sample)?;
                self.grid.next += 1;
            }
            if stop.is_some() {
                return Ok(stop);
            }
            if finish_step(model, state, t_new)? {
                self.record.stats.repartitions += 1;
            }
            if self
                .grid
                .pending(settings)
                .is_some_and(|t_out| t_out <= t_new)
            {
                let sample = sample_in_place(model, state, self.level)?;
                self.emit(sample)?;
                self.grid.next += 1;
            }
            let next = self.grid.pending(settings).unwrap_or(settings.t_end);
            self.record.stepped(t_new, t_new - t_old, next)?;
            start = end;
        }
        Ok(None)
    }

    /// Records a sample, completed first where the phase says so.
    fn emit(&mut self, mut sample: Sample) -> Result<(), SimError> {
        if let Some(complete) = self.complete {
            complete(&mut sample);
        }
        self.record.emit(sample)
    }

    /// The watched quantities at (t, y) of the current step's partition.
    fn readings(
        &mut self,
        model: &dyn Dynamics,
        state: &State,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
    ) -> Result<Vec<Reading>, SimError> {
        if matches!(self.watch, Watch::Nothing) {
            return Ok(Vec::new());
        }
        let partition = &state.partition;
        load_state(model, partition, ws, t, y)?;
        match self.watch {
            Watch::Nothing => Ok(Vec::new()),
            Watch::Forces { .. } => {
                ws.solve_accelerations(model, partition, t)?;
                ws.solve_multipliers(partition, t)?;
                Ok((0..model.info().n_contacts())
                    .map(|k| Reading::of_force(-ws.contact_lambda(k)))
                    .collect())
            }
            Watch::Gap { gap, .. } => Ok(vec![Reading::of_gap(gap(ws.q(), ws.qd()))]),
        }
    }

    /// The watched quantities at the end of the step just accepted, from what its last
    /// right-hand side left: the logged multipliers, or the flight's state.
    fn readings_at_end(&self, model: &dyn Dynamics, state: &State) -> Vec<Reading> {
        match self.watch {
            Watch::Nothing => Vec::new(),
            Watch::Forces { .. } => {
                let n = model.info().n_contacts();
                state
                    .engine
                    .stages
                    .last(1)
                    .next()
                    .map(|(_, p)| p.iter().map(|&p| Reading::of_force(p)).collect())
                    .unwrap_or_else(|| vec![Reading::of_force(f64::NAN); n])
            }
            Watch::Gap { gap, .. } => {
                let ws = &state.engine.ws;
                vec![Reading::of_gap(gap(ws.q(), ws.qd()))]
            }
        }
    }

    /// A phase that must stop at once: a one-sided contact starting with a pulling force.
    fn stop_at_start(&self, state: &State, watched: &[Reading]) -> Option<Stop> {
        let Watch::Forces { stop: true } = self.watch else {
            return None;
        };
        watched
            .iter()
            .position(|r| r.value <= 0.0)
            .map(|contact| Stop {
                t: state.t,
                contact,
                q: state.q.clone(),
                qd: state.qd.clone(),
                quadratures: (state.dissipated, state.driven_work),
            })
    }

    /// The events inside the step (t0, t1]: sign changes between its ends and excursions
    /// across zero within it, located on the dense output; records them and returns the
    /// first one that stops the phase (with q, q̇ there).
    fn scan_step(
        &mut self,
        model: &dyn Dynamics,
        state: &mut State,
        ws: &mut Workspace,
        (t0, before): (f64, &[Reading]),
        (t1, after): (f64, &[Reading]),
        take_off: bool,
    ) -> Result<Option<Stop>, SimError> {
        let watch = self.watch;
        let found = match watch {
            Watch::Nothing => Vec::new(),
            Watch::Forces { stop } => {
                self.force_events(model, state, ws, (t0, before), (t1, after), *stop)?
            }
            Watch::Gap { gap, tolerance } => {
                let (start, end) = (before[0], after[0]);
                self.landing(
                    model,
                    state,
                    ws,
                    (t0, start),
                    (t1, end),
                    (*gap, *tolerance),
                    take_off,
                )?
                .into_iter()
                .map(|t| (t, 0, Crossing::Lands))
                .collect()
            }
        };
        self.record_events(model, state, ws, found)
    }

    /// The crossings of every contact's −λ in the step: between its ends, and inside it where
    /// the stages predict one (the exact value then searched on the dense output).
    fn force_events(
        &mut self,
        model: &dyn Dynamics,
        state: &mut State,
        ws: &mut Workspace,
        (t0, before): (f64, &[Reading]),
        (t1, after): (f64, &[Reading]),
        stop: bool,
    ) -> Result<Vec<(f64, usize, Crossing)>, SimError> {
        let settings = self.settings;
        let (evaluations, quadrature) = stage_quadrature(settings.integrator);
        let mut found = Vec::new();
        let mut stages: Vec<(f64, f64)> = Vec::with_capacity(evaluations);
        for k in 0..before.len() {
            let (p0, p1) = (before[k].value, after[k].value);
            let crossing = |from: f64| {
                if from > 0.0 {
                    if stop {
                        Crossing::LiftsOff
                    } else {
                        Crossing::BecomesNegative
                    }
                } else {
                    Crossing::BecomesPositive
                }
            };
            // The step's own stages: their values and the quadrature of −λ over the step.
            stages.clear();
            let mut mean = quadrature[0] * p0;
            for ((t, values), b) in state.engine.stages.last(evaluations).zip(&quadrature[1..]) {
                mean += b * values[k];
                if t < t1 {
                    stages.push((t, values[k]));
                }
            }
            let logged = state.engine.stages.len() >= evaluations;
            let mut y = vec![0.0; state.engine.y.len()];
            let mut used = 0;
            let mut p = |t: f64| -> Result<f64, SimError> {
                used += 1;
                interpolate_last_step(model, state, settings, t, &mut y)?;
                load_state(model, &state.partition, ws, t, &y)?;
                ws.solve_accelerations(model, &state.partition, t)?;
                ws.solve_multipliers(&state.partition, t)?;
                Ok(-ws.contact_lambda(k))
            };
            if changes_sign(p0, p1) {
                let t = locate_root(&mut p, (t0, p0), (t1, p1), EVENT_TIME_TOLERANCE)?;
                found.push((t, k, crossing(p0)));
            } else if p0 != 0.0 {
                let step = ForceStep {
                    start: (t0, p0),
                    end: (t1, p1),
                    mean: if logged { mean } else { f64::NAN },
                    stages: &stages,
                };
                if let Some(guess) = excursion_guess(&step) {
                    if let Some(excursion) = find_excursion(&mut p, (t0, p0), (t1, p1), guess)? {
                        let (a, b) = excursion.leaves;
                        let t = locate_root(&mut p, a, b, EVENT_TIME_TOLERANCE)?;
                        found.push((t, k, crossing(p0)));
                        if let Some((a, b)) = excursion.returns {
                            let t = locate_root(&mut p, a, b, EVENT_TIME_TOLERANCE)?;
                            found.push((t, k, crossing(-p0)));
                        }
                    }
                }
            }
            self.record.stats.event_evaluations += used;
        }
        Ok(found)
    }

    /// Where a flight's gap first closes in the step, if it does: the step cut into pieces
    /// of at most [`PIECE_TURN`] of the cam's turn relative to the follower, each checked
    /// (see [`first_closing`]), the closing located to `tolerance`.
    #[allow(clippy::too_many_arguments)]
    fn landing(
        &mut self,
        model: &dyn Dynamics,
        state: &mut State,
        ws: &mut Workspace,
        (t0, start): (f64, Reading),
        (t1, end): (f64, Reading),
        (gap, tolerance): (GapFn, f64),
        take_off: bool,
    ) -> Result<Option<f64>, SimError> {
        let settings = self.settings;
        let turn = (t1 - t0) * start.turn_rate.max(end.turn_rate);
        let pieces = if turn.is_finite() {
            ((turn / PIECE_TURN).ceil() as usize).clamp(1, MAX_PIECES)
        } else {
            MAX_PIECES
        };
        let mut y = vec![0.0; state.engine.y.len()];
        let mut used = 0;
        let mut at = |t: f64| -> Result<GapPoint, SimError> {
            used += 1;
            interpolate_last_step(model, state, settings, t, &mut y)?;
            load_state(model, &state.partition, ws, t, &y)?;
            let reading = gap(ws.q(), ws.qd());
            Ok(GapPoint {
                t,
                g: reading.g,
                rate: reading.rate,
                speed: reading.speed,
            })
        };
        let point = |t: f64, r: Reading| GapPoint {
            t,
            g: r.value,
            rate: r.rate,
            speed: r.speed,
        };
        let (a, b) = (point(t0, start), point(t1, end));
        let closing = first_closing(&mut at, a, b, (pieces, tolerance), take_off)?;
        let landing = match closing {
            Closing::Clear => None,
            // A hop within the landing tolerance: the follower never really left the cam; it
            // lands where it took off.
            Closing::NeverOpened => Some(t0),
            // Already within the tolerance where the gap was last seen open.
            Closing::Bracket(open, _) if open.g <= 0.0 => Some(open.t),
            Closing::Bracket(open, closed) => {
                let mut g = |t: f64| at(t).map(|p| p.g);
                Some(locate_root_within(
                    &mut g,
                    (open.t, open.g),
                    (closed.t, closed.g),
                    EVENT_TIME_TOLERANCE,
                    tolerance,
                )?)
            }
        };
        self.record.stats.gap_evaluations += used;
        Ok(landing)
    }

    /// Records the located crossings in time order up to the first that stops the phase,
    /// which is returned with q, q̇ and the quadratures there (its driver records it).
    fn record_events(
        &mut self,
        model: &dyn Dynamics,
        state: &mut State,
        ws: &mut Workspace,
        mut found: Vec<(f64, usize, Crossing)>,
    ) -> Result<Option<Stop>, SimError> {
        found.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (t, k, crossing) in found {
            let mut y = vec![0.0; state.engine.y.len()];
            interpolate_last_step(model, state, self.settings, t, &mut y)?;
            load_state(model, &state.partition, ws, t, &y)?;
            let (q, qd) = (ws.q().to_vec(), ws.qd().to_vec());
            let kind = match crossing {
                Crossing::LiftsOff | Crossing::Lands => {
                    let nu = state.partition.independent().len();
                    return Ok(Some(Stop {
                        t,
                        contact: k,
                        q,
                        qd,
                        quadratures: (y[2 * nu], y[2 * nu + 1]),
                    }));
                }
                Crossing::BecomesNegative => EventKind::ForceBecameNegative,
                Crossing::BecomesPositive => EventKind::ForceBecamePositive,
            };
            self.record.events.push(ContactEvent {
                t,
                contact: k,
                kind,
                q,
                qd,
                flank: None,
            });
        }
        Ok(None)
    }
}

/// What a located crossing means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Crossing {
    /// A one-sided contact's force reaches zero from above: the phase ends.
    LiftsOff,
    /// A flying follower's gap closes: the phase ends.
    Lands,
    /// A bilateral contact's force becomes negative.
    BecomesNegative,
    /// A bilateral contact's force becomes positive again.
    BecomesPositive,
}

/// Number of output intervals: the last one may be shorter and ends at t_end. A remainder
/// below 1e-9·dt_out (or the quotient's round-off, on grids of more than a million
/// intervals) is not an interval.
pub(crate) fn output_intervals(t0: f64, settings: &SimSettings) -> usize {
    let span = settings.t_end - t0;
    if span <= 0.0 {
        return 0;
    }
    // A quotient within round-off (4 ulp, at least 1e-9) of a whole number is that number:
    // no extra interval of zero length at t_end.
    let ratio = span / settings.dt_out;
    (ratio - (4.0 * f64::EPSILON * ratio).max(1e-9))
        .ceil()
        .max(1.0) as usize
}

/// t0 + k·dt_out (computed by multiplication: no accumulated round-off), t_end for the last.
pub(crate) fn output_time(t0: f64, k: usize, intervals: usize, settings: &SimSettings) -> f64 {
    if k == intervals && k > 0 {
        settings.t_end
    } else {
        t0 + k as f64 * settings.dt_out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::IntegratorKind;

    fn grid(t_end: f64, dt_out: f64) -> SimSettings {
        SimSettings {
            t_end,
            dt_out,
            integrator: IntegratorKind::Dop853,
            dt: 1e-3,
            rtol: 1e-9,
            atol: 1e-12,
        }
    }

    #[test]
    fn long_grids_have_no_interval_of_round_off() {
        // 0.1 + 123 456 789 · 0.01 s: the quotient (t_end − t0)/dt_out comes out as
        // 123456789.00000001, a round-off of 1.5e-8 that the former absolute tolerance of
        // 1e-9 took for one more interval (two samples at t_end). Streamed runs may have
        // such grids.
        let t0 = 0.1;
        let settings = grid(t0 + 123_456_789.0 * 0.01, 0.01);
        assert_eq!(output_intervals(t0, &settings), 123_456_789);
        // A true remainder is still an interval, and short grids are counted as before.
        let settings = grid(t0 + 123_456_789.5 * 0.01, 0.01);
        assert_eq!(output_intervals(t0, &settings), 123_456_790);
        assert_eq!(output_intervals(0.0, &grid(10.0, 0.01)), 1000);
        assert_eq!(output_intervals(0.0, &grid(1.0 + 1e-7, 1e-3)), 1001);
        assert_eq!(output_intervals(0.0, &grid(0.0, 0.01)), 0);
    }
}
