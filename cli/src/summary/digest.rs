//! What a run's summary and warnings need of its samples, taken in one sample at a time
//! (issue 25): the summary of a run of any length from memory that does not grow with it.
//!
//! [`Digest::add`] folds each sample into running extremes (in the order and with the
//! operations the summary's table always used, so the text is the same to the last digit
//! as that of the whole trajectory), counts, the first and the last times, the energy
//! balance against the first sample, and the few values of the previous sample that the
//! re-partitions and the lift-off between two samples need.

use super::{LISTED_EVENTS, LISTED_LOOPS, LiftOff, drive_unit, unit};
use camchain_runtime::{ModelInfo, Sample};
use std::sync::Arc;

/// The running summary of a run's samples.
#[derive(Debug, Clone)]
pub struct Digest {
    /// Samples taken in.
    count: usize,
    /// Time of the first and of the last sample (s).
    first_t: f64,
    last_t: f64,
    /// The table's rows, in order.
    rows: Vec<Row>,
    /// Per contact: the largest |pressure angle| in contact, where (the last such sample).
    steepest: Vec<Option<Steepest>>,
    /// Per contact: max |h| over the samples with a dependent coordinate (m).
    max_h: Vec<f64>,
    /// The loops' max |h|: one for all of them, or one per loop (see [`LISTED_LOOPS`]).
    loop_h: Vec<f64>,
    /// The cam coordinate of each contact, if its cam turns on one.
    cam_coordinates: Vec<Option<usize>>,
    /// Where each loop's rows start and how many there are.
    loop_rows: Vec<(usize, usize)>,
    /// Whether the loops are too many to list: their max |h| is pooled into one.
    pooled: bool,
    contacts: usize,
    energy: EnergyBalance,
    /// The first re-partitions between consecutive samples in contact, and how many in all.
    repartitions: Vec<Repartition>,
    repartition_count: usize,
    /// Per contact: where its normal force first turns negative.
    lift_offs: Vec<Option<LiftOff>>,
    /// The normal forces of the first sample (N).
    first_forces: Vec<f64>,
    /// Per contact: samples in contact, and of those, with a negative normal force.
    in_contact: Vec<usize>,
    negative: Vec<usize>,
    /// The previous sample's time, dependent set, contact state and normal forces.
    previous: Option<Previous>,
}

/// One row of the table: a quantity and its range.
#[derive(Debug, Clone)]
struct Row {
    name: String,
    reading: Reading,
    /// Taken only where contact k is closed (a flying follower has no pressure angle).
    only_in_contact: Option<usize>,
    /// Shown only when the cam of its contact moves (the pressure angle).
    needs_moving_cam: bool,
    /// (min, max), folded from (+∞, −∞) with `f64::min` and `f64::max`.
    range: (f64, f64),
    /// Samples taken in.
    taken: usize,
}

/// How a row reads its quantity from a sample.
#[derive(Debug, Clone, Copy)]
enum Reading {
    /// q[i].
    Coordinate(usize),
    /// Contact k's position, axis a.
    Position(usize, usize),
    /// Contact k's normal force.
    NormalForce(usize),
    /// Contact k's pressure angle.
    PressureAngle(usize),
    /// Contact k's sliding speed.
    SlidingSpeed(usize),
    /// The largest |λ| of the loops' rows (those after the contacts').
    LargestLoopReaction,
    /// −λ of constraint row r (NaN when absent).
    Reaction(usize),
    /// The drive load of coordinate i.
    Drive(usize),
}

impl Reading {
    fn of(self, s: &Sample, contacts: usize) -> f64 {
        match self {
            Reading::Coordinate(i) => s.q[i],
            Reading::Position(k, a) => s.contacts[k].position[a],
            Reading::NormalForce(k) => s.normal_force[k],
            Reading::PressureAngle(k) => s.contacts[k].pressure_angle(),
            Reading::SlidingSpeed(k) => s.contacts[k].sliding_speed,
            Reading::LargestLoopReaction => s
                .lambda
                .iter()
                .skip(contacts)
                .fold(0.0_f64, |m, l| m.max(l.abs())),
            Reading::Reaction(r) => -s.lambda.get(r).copied().unwrap_or(f64::NAN),
            Reading::Drive(i) => s.drive[i],
        }
    }
}

/// Where a contact's pressure angle is largest.
#[derive(Debug, Clone, Copy)]
pub(super) struct Steepest {
    /// |pressure angle| (rad).
    pub(super) angle: f64,
    /// Time (s).
    pub(super) t: f64,
    /// The cam's angle then (rad), if the cam turns on a coordinate.
    pub(super) cam_angle: Option<f64>,
}

/// E + dissipated − driven work against its first value, and the energy scale.
#[derive(Debug, Clone, Copy)]
struct EnergyBalance {
    first: Option<f64>,
    drift: f64,
    kinetic: f64,
    potential: (f64, f64),
}

/// A change of the dependent set between two consecutive samples in contact.
#[derive(Debug, Clone)]
pub struct Repartition {
    /// The two samples' times (s).
    pub between: (f64, f64),
    /// The dependent sets before and after.
    pub from: Arc<[usize]>,
    pub to: Arc<[usize]>,
}

#[derive(Debug, Clone)]
struct Previous {
    t: f64,
    dependent: Arc<[usize]>,
    closed: bool,
    forces: Vec<f64>,
}

/// Contact k is closed in the sample (always in a bilateral run; not while a one-sided
/// follower flies).
pub(super) fn touching(sample: &Sample, k: usize) -> bool {
    sample.in_contact.get(k).copied().unwrap_or(true)
}

/// The normal force of contact k, 0 where the sample has none.
fn force(sample: &Sample, k: usize) -> f64 {
    sample.normal_force.get(k).copied().unwrap_or(0.0)
}

impl Digest {
    /// An empty digest of a run of the model `info` describes.
    pub fn new(info: &ModelInfo) -> Self {
        let contacts = info.n_contacts();
        let pooled = info.loops.len() > LISTED_LOOPS;
        let loop_rows: Vec<(usize, usize)> = info
            .loop_rows()
            .map(|(first, l)| (first, l.equations.len()))
            .collect();
        Digest {
            count: 0,
            first_t: f64::NAN,
            last_t: f64::NAN,
            rows: rows(info),
            steepest: vec![None; contacts],
            max_h: vec![0.0; contacts],
            loop_h: vec![0.0; if pooled { 1 } else { loop_rows.len() }],
            cam_coordinates: info.contacts.iter().map(|c| c.cam_coordinate).collect(),
            loop_rows,
            pooled,
            contacts,
            energy: EnergyBalance {
                first: None,
                drift: 0.0,
                kinetic: 0.0,
                potential: (f64::INFINITY, f64::NEG_INFINITY),
            },
            repartitions: Vec::new(),
            repartition_count: 0,
            lift_offs: vec![None; contacts],
            first_forces: Vec::new(),
            in_contact: vec![0; contacts],
            negative: vec![0; contacts],
            previous: None,
        }
    }

    /// Takes in the next sample (in time order).
    pub fn add(&mut self, s: &Sample) {
        if self.count == 0 {
            self.first_t = s.t;
            self.first_forces.clone_from(&s.normal_force);
        }
        self.count += 1;
        self.last_t = s.t;
        let contacts = self.contacts;
        for row in &mut self.rows {
            if row.only_in_contact.is_some_and(|k| !touching(s, k)) {
                continue;
            }
            let v = row.reading.of(s, contacts);
            row.range = (row.range.0.min(v), row.range.1.max(v));
            row.taken += 1;
        }
        for k in 0..contacts {
            if touching(s, k) {
                let angle = s.contacts[k].pressure_angle().abs();
                // The last of equal maxima, as `Iterator::max_by` picks.
                let steeper = self.steepest[k].is_none_or(|best| !best.angle.gt(&angle));
                if angle.is_finite() && steeper {
                    self.steepest[k] = Some(Steepest {
                        angle,
                        t: s.t,
                        cam_angle: self.cam_coordinates[k].map(|i| s.q[i]),
                    });
                }
                self.in_contact[k] += 1;
                self.negative[k] += usize::from(s.normal_force[k] < 0.0);
            }
            if !s.dependent.is_empty() {
                self.max_h[k] = f64::max(self.max_h[k], s.h[k].abs());
            }
        }
        self.add_loop_residuals(s);
        self.add_energy(s);
        self.add_crossings(s);
    }

    fn add_loop_residuals(&mut self, s: &Sample) {
        if self.pooled {
            if let Some(pooled) = self.loop_h.first_mut() {
                *pooled =
                    s.h.iter()
                        .skip(self.contacts)
                        .fold(*pooled, |m, h| m.max(h.abs()));
            }
            return;
        }
        for (max, &(first, len)) in self.loop_h.iter_mut().zip(&self.loop_rows) {
            *max =
                s.h.iter()
                    .skip(first)
                    .take(len)
                    .fold(*max, |m, h| m.max(h.abs()));
        }
    }

    fn add_energy(&mut self, s: &Sample) {
        let e = &mut self.energy;
        let balance = s.energy.total() + s.dissipated - s.driven_work;
        let first = *e.first.get_or_insert(balance);
        e.drift = f64::max(e.drift, (balance - first).abs());
        e.kinetic = f64::max(e.kinetic, s.energy.kinetic);
        let potential = s.energy.gravity + s.energy.spring;
        e.potential = (e.potential.0.min(potential), e.potential.1.max(potential));
    }

    /// What happens between the previous sample and this one: a re-partition, a normal
    /// force turning negative.
    fn add_crossings(&mut self, s: &Sample) {
        let closed = s.in_contact.iter().all(|&c| c);
        let previous = self.previous.take();
        if let Some(p) = &previous
            && p.closed
            && closed
            && p.dependent != s.dependent
        {
            self.repartition_count += 1;
            if self.repartitions.len() < LISTED_EVENTS {
                self.repartitions.push(Repartition {
                    between: (p.t, s.t),
                    from: p.dependent.clone(),
                    to: s.dependent.clone(),
                });
            }
        }
        for k in 0..self.contacts {
            let now = force(s, k);
            if self.lift_offs[k].is_some() || now >= 0.0 || now.is_nan() {
                continue;
            }
            self.lift_offs[k] = Some(match &previous {
                None => LiftOff {
                    t: s.t,
                    from_start: true,
                },
                Some(p) => {
                    let before = p.forces.get(k).copied().unwrap_or(0.0);
                    LiftOff {
                        t: p.t + (s.t - p.t) * before / (before - now),
                        from_start: false,
                    }
                }
            });
        }
        let mut next = previous.unwrap_or_else(|| Previous {
            t: s.t,
            dependent: s.dependent.clone(),
            closed,
            forces: Vec::new(),
        });
        next.t = s.t;
        next.closed = closed;
        if next.dependent != s.dependent {
            next.dependent = s.dependent.clone();
        }
        next.forces.clear();
        next.forces.extend((0..self.contacts).map(|k| force(s, k)));
        self.previous = Some(next);
    }

    /// Samples taken in.
    pub fn count(&self) -> usize {
        self.count
    }

    /// Time of the first and the last sample (s), if there was one.
    pub fn span(&self) -> Option<(f64, f64)> {
        (self.count > 0).then_some((self.first_t, self.last_t))
    }

    /// The table's rows: (name with unit, min, max).
    pub fn rows(&self) -> Vec<(String, f64, f64)> {
        self.rows
            .iter()
            .filter(|r| r.taken > 0 || r.only_in_contact.is_none())
            .filter(|r| !r.needs_moving_cam)
            .map(|r| (r.name.clone(), r.range.0, r.range.1))
            .collect()
    }

    /// Where contact k's pressure angle is largest, over its samples in contact.
    pub(super) fn steepest(&self, k: usize) -> Option<Steepest> {
        self.steepest.get(k).copied().flatten()
    }

    /// Max |h| of contact k over the samples with a dependent coordinate (m).
    pub fn max_h(&self, k: usize) -> f64 {
        self.max_h.get(k).copied().unwrap_or(0.0)
    }

    /// Max |h| of every loop (one value when they are too many to list, see
    /// [`LISTED_LOOPS`]).
    pub fn loop_h(&self) -> &[f64] {
        &self.loop_h
    }

    /// max over the samples of |(E + D − W)(t) − (E + D − W)(t0)| (J).
    pub fn energy_drift(&self) -> f64 {
        self.energy.drift
    }

    /// The scale the energy drift is measured against: the largest kinetic energy plus the
    /// range of the potential energy over the run (the energy that moves around; the total
    /// itself has an arbitrary zero) (J).
    pub fn energy_scale(&self) -> f64 {
        let (lo, hi) = self.energy.potential;
        self.energy.kinetic + (hi - lo).max(0.0)
    }

    /// The first re-partitions between consecutive samples in contact, and how many there
    /// were in all.
    pub fn repartitions(&self) -> (&[Repartition], usize) {
        (&self.repartitions, self.repartition_count)
    }

    /// Where each contact's normal force first turns negative (interpolated linearly
    /// between the two samples around the sign change), per contact.
    pub fn lift_offs(&self) -> &[Option<LiftOff>] {
        &self.lift_offs
    }

    /// Whether contact k's normal force is negative at the first sample.
    pub(super) fn negative_at_start(&self, k: usize) -> bool {
        self.first_forces.get(k).is_some_and(|f| *f < 0.0)
    }

    /// Contact k's samples in contact, and of those, with a negative normal force.
    pub(super) fn negative_share(&self, k: usize) -> (usize, usize) {
        (
            self.negative.get(k).copied().unwrap_or(0),
            self.in_contact.get(k).copied().unwrap_or(0),
        )
    }
}

/// A row of `reading` taken over every sample.
fn row(name: String, reading: Reading) -> Row {
    Row {
        name,
        reading,
        only_in_contact: None,
        needs_moving_cam: false,
        range: (f64::INFINITY, f64::NEG_INFINITY),
        taken: 0,
    }
}

/// The rows of the table for the model, in the order they are printed.
fn rows(info: &ModelInfo) -> Vec<Row> {
    let mut rows = Vec::new();
    for (i, c) in info.coordinates.iter().enumerate() {
        rows.push(row(
            format!("{} [{}]", c.name, unit(c.kind)),
            Reading::Coordinate(i),
        ));
    }
    let axes: &[&str] = if info.spatial {
        &["x", "y", "z"]
    } else {
        &["x", "y"]
    };
    for (k, contact) in info.contacts.iter().enumerate() {
        let name = &contact.name;
        for (a, axis) in axes.iter().enumerate() {
            rows.push(row(format!("{name}_{axis} [m]"), Reading::Position(k, a)));
        }
        rows.push(row(
            format!("{name}_normal_force [N]"),
            Reading::NormalForce(k),
        ));
        // In contact only: a flying follower has no pressure angle or sliding speed, and a
        // fixed cam drives nothing (no pressure angle either).
        rows.push(Row {
            only_in_contact: Some(k),
            needs_moving_cam: !contact.cam_moves,
            ..row(
                format!("{name}_pressure_angle [rad]"),
                Reading::PressureAngle(k),
            )
        });
        rows.push(Row {
            only_in_contact: Some(k),
            ..row(
                format!("{name}_sliding_speed [m/s]"),
                Reading::SlidingSpeed(k),
            )
        });
    }
    // Each loop's reactions, unless there are too many loops to list (an N-four-bar): then
    // the largest reaction over all of them.
    if info.loops.len() > LISTED_LOOPS {
        rows.push(row(
            format!("largest loop reaction, {} loops [N]", info.loops.len()),
            Reading::LargestLoopReaction,
        ));
    } else {
        for (first, l) in info.loop_rows() {
            for (e, equation) in l.equations.iter().enumerate() {
                let unit = if equation.starts_with("turn") || equation.starts_with("tilt") {
                    "N m"
                } else {
                    "N"
                };
                rows.push(row(
                    format!("{}_{equation}_reaction [{unit}]", l.name),
                    Reading::Reaction(first + e),
                ));
            }
        }
    }
    for (i, c) in info.coordinates.iter().enumerate() {
        if c.driven {
            rows.push(row(
                format!("{}_drive [{}]", c.name, drive_unit(c.kind)),
                Reading::Drive(i),
            ));
        }
    }
    rows
}
