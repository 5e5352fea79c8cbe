//! The bounded copy of a run's samples that its figures are drawn from (issue 25).
//!
//! A figure of a million samples shows no more than one of twenty thousand, and keeping
//! them all would make a run's memory grow with its length. [`Decimated`] keeps every
//! `stride`-th sample; when [`KEPT`] are held it drops every other one and doubles the
//! stride (so the kept samples stay evenly spaced, between `KEPT / 2` and `KEPT` of them).
//! It keeps exactly, besides, the first and the last sample, and the samples the figures'
//! markers and the eye need: the two around the first sign change of each contact's normal
//! force (the lift-off the contact figure marks, interpolated between them) and the two
//! around every take-off and landing of a one-sided follower (the first [`PINNED`] such
//! changes), so that a short flight does not vanish between kept samples.
//!
//! The copies are thinned: they keep what the figures draw (t, q, q̇, q̈, the normal forces,
//! the contacts' residuals h, the contact geometry, the energies, the contact states), not
//! the multipliers, the drive loads or the loops' residuals.

use camchain_runtime::Sample;

/// Most samples kept at the regular stride.
pub const KEPT: usize = 20_000;

/// Most changes (a first lift-off, a take-off, a landing) whose two samples are kept
/// besides.
pub const PINNED: usize = 500;

/// A bounded, evenly decimated copy of a run's samples, with its markers' samples.
#[derive(Debug, Clone)]
pub struct Decimated {
    contacts: usize,
    /// Most samples at the regular stride.
    capacity: usize,
    /// Every `stride`-th sample (by index), with its index.
    regular: Vec<(usize, Sample)>,
    stride: usize,
    /// The samples around the markers, with their indices, in time order.
    pinned: Vec<(usize, Sample)>,
    /// Changes whose samples were pinned.
    changes: usize,
    /// Whether contact k's normal force has turned negative yet.
    turned: Vec<bool>,
    /// The last sample taken in (thinned), with its index.
    last: Option<(usize, Sample)>,
}

/// Contact k's normal force in the sample, 0 where it has none (as the summary reads it).
fn force(s: &Sample, k: usize) -> f64 {
    s.normal_force.get(k).copied().unwrap_or(0.0)
}

/// Copies into `to` what the figures draw of `from` (reusing `to`'s vectors).
fn thin_into(to: &mut Sample, from: &Sample, contacts: usize) {
    let Sample {
        t,
        q,
        qd,
        qdd,
        lambda: _,
        normal_force,
        h,
        contacts: geometry,
        drive: _,
        energy,
        dissipated,
        driven_work,
        dependent,
        in_contact,
    } = from;
    to.t = *t;
    to.q.clone_from(q);
    to.qd.clone_from(qd);
    to.qdd.clone_from(qdd);
    to.normal_force.clone_from(normal_force);
    to.h.clear();
    to.h.extend_from_slice(&h[..contacts.min(h.len())]);
    to.contacts.clone_from(geometry);
    to.energy = *energy;
    to.dissipated = *dissipated;
    to.driven_work = *driven_work;
    if to.dependent != *dependent {
        to.dependent = dependent.clone();
    }
    to.in_contact.clone_from(in_contact);
}

/// A thinned copy of `from`.
fn thinned(from: &Sample, contacts: usize) -> Sample {
    let mut to = Sample {
        t: 0.0,
        q: Vec::new(),
        qd: Vec::new(),
        qdd: Vec::new(),
        lambda: Vec::new(),
        normal_force: Vec::new(),
        h: Vec::new(),
        contacts: Vec::new(),
        drive: Vec::new(),
        energy: from.energy,
        dissipated: 0.0,
        driven_work: 0.0,
        dependent: from.dependent.clone(),
        in_contact: Vec::new(),
    };
    thin_into(&mut to, from, contacts);
    to
}

impl Decimated {
    /// An empty copy for a model with `contacts` contacts, at most [`KEPT`] samples at the
    /// regular stride.
    pub fn new(contacts: usize) -> Self {
        Self::with_capacity(contacts, KEPT)
    }

    /// An empty copy keeping at most `capacity` (at least 2) samples at the regular stride.
    pub fn with_capacity(contacts: usize, capacity: usize) -> Self {
        Decimated {
            contacts,
            capacity: capacity.max(2),
            regular: Vec::new(),
            stride: 1,
            pinned: Vec::new(),
            changes: 0,
            turned: vec![false; contacts],
            last: None,
        }
    }

    /// Takes in the next sample (in time order).
    pub fn add(&mut self, s: &Sample) {
        let index = self.last.as_ref().map_or(0, |(i, _)| i + 1);
        let mut marked = false;
        if let Some((_, previous)) = &self.last {
            marked |= previous.in_contact != s.in_contact;
        }
        for (k, turned) in self.turned.iter_mut().enumerate() {
            if !*turned && force(s, k) < 0.0 {
                *turned = true;
                marked = true;
            }
        }
        if marked && self.changes < PINNED {
            self.changes += 1;
            if let Some((i, previous)) = &self.last
                && self.pinned.last().is_none_or(|(j, _)| j != i)
            {
                self.pinned.push((*i, previous.clone()));
            }
            self.pinned.push((index, thinned(s, self.contacts)));
        }
        if index.is_multiple_of(self.stride) {
            self.regular.push((index, thinned(s, self.contacts)));
            if self.regular.len() > self.capacity {
                self.stride *= 2;
                let stride = self.stride;
                self.regular.retain(|(i, _)| i % stride == 0);
            }
        }
        match &mut self.last {
            Some((i, last)) => {
                *i = index;
                thin_into(last, s, self.contacts);
            }
            None => self.last = Some((index, thinned(s, self.contacts))),
        }
    }

    /// The kept samples in time order: every `stride`-th, those of the markers, and the
    /// last.
    pub fn finish(self) -> Vec<Sample> {
        let mut kept = self.regular;
        kept.extend(self.pinned);
        kept.extend(self.last);
        kept.sort_by_key(|(i, _)| *i);
        kept.dedup_by_key(|(i, _)| *i);
        kept.into_iter().map(|(_, s)| s).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use camchain_runtime::{ContactGeometry, Energy};

    /// Sample `i` of a run with one contact: force `force`, in contact or flying.
    fn sample(i: usize, force: f64, flying: bool) -> Sample {
        Sample {
            t: i as f64 * 1e-3,
            q: vec![i as f64, 1.0],
            qd: vec![0.5; 2],
            qdd: vec![0.25; 2],
            lambda: vec![-force, 2.0, 3.0],
            normal_force: vec![force],
            h: vec![1e-12, 5.0, 6.0],
            // A contact parameter (NaN by default) that compares equal to itself.
            contacts: vec![ContactGeometry {
                parameter: 0.5,
                ..ContactGeometry::default()
            }],
            drive: vec![7.0; 2],
            energy: Energy::default(),
            dissipated: 0.0,
            driven_work: 0.0,
            dependent: if flying { vec![] } else { vec![1] }.into(),
            in_contact: vec![!flying],
        }
    }

    fn index(s: &Sample) -> usize {
        s.q[0] as usize
    }

    #[test]
    fn a_short_run_is_kept_whole_and_thinned() {
        let mut copy = Decimated::with_capacity(1, 100);
        let samples: Vec<Sample> = (0..100).map(|i| sample(i, 1.0, false)).collect();
        for s in &samples {
            copy.add(s);
        }
        assert_eq!(copy.stride, 1);
        let kept = copy.finish();
        assert_eq!(kept.len(), 100);
        for (k, s) in kept.iter().zip(&samples) {
            assert_eq!((k.t, &k.q, &k.qd, &k.qdd), (s.t, &s.q, &s.qd, &s.qdd));
            assert_eq!(
                (&k.normal_force, &k.contacts),
                (&s.normal_force, &s.contacts)
            );
            assert_eq!((&k.dependent, &k.in_contact), (&s.dependent, &s.in_contact));
            // The contact's residual only; no multipliers or drive loads.
            assert_eq!(k.h, [1e-12]);
            assert!(k.lambda.is_empty() && k.drive.is_empty());
        }
    }

    #[test]
    fn a_long_run_is_decimated_evenly_and_bounded() {
        // 1 000 003 samples into at most 1000 at the stride: the stride doubles (1024 after
        // ten halvings, as 1 000 003 / 1000 ≈ 1000 → the next power of two), the first and
        // the last are kept, the others evenly spaced.
        let mut copy = Decimated::with_capacity(1, 1000);
        let count = 1_000_003;
        let mut largest = 0;
        for i in 0..count {
            copy.add(&sample(i, 1.0, false));
            largest = largest.max(copy.regular.len());
        }
        assert!(largest <= 1000, "{largest}");
        assert_eq!(copy.stride, 1024);
        let kept = copy.finish();
        let indices: Vec<usize> = kept.iter().map(index).collect();
        assert_eq!(indices.first(), Some(&0));
        assert_eq!(indices.last(), Some(&(count - 1)));
        let regular = &indices[..indices.len() - 1];
        assert!(regular.iter().enumerate().all(|(j, &i)| i == j * 1024));
        assert_eq!(regular.len(), (count - 1) / 1024 + 1);
    }

    #[test]
    fn the_markers_samples_are_kept_exactly() {
        // A long run at a stride that keeps none of them: the force turns negative between
        // samples 50 000 and 50 001 (the lift-off the contact figure marks, interpolated
        // between exactly those two), the follower flies from 70 001 to 70 003 and from
        // 80 001 to 80 001 (a one-sample flight).
        let flying = |i: usize| (70_001..=70_003).contains(&i) || i == 80_001;
        let force = |i: usize| if i > 50_000 && i < 60_000 { -1.0 } else { 1.0 };
        let mut copy = Decimated::with_capacity(1, 64);
        for i in 0..100_001 {
            copy.add(&sample(i, force(i), flying(i)));
        }
        assert!(copy.stride >= 2048);
        let kept: Vec<usize> = copy.finish().iter().map(index).collect();
        for marker in [
            50_000, 50_001, 70_000, 70_001, 70_003, 70_004, 80_000, 80_001, 80_002,
        ] {
            assert!(kept.contains(&marker), "{marker} missing from {kept:?}");
        }
        // The second sign change (back to positive at 60 000) is no marker.
        assert!(!kept.contains(&59_999) && !kept.contains(&60_000));
        assert!(
            kept.windows(2).all(|w| w[0] < w[1]),
            "in time order, once each"
        );
    }

    #[test]
    fn the_markers_are_bounded_too() {
        // A follower that takes off and lands at every sample: only the first PINNED
        // changes are kept besides the stride.
        let mut copy = Decimated::with_capacity(1, 100);
        let count = 20 * PINNED;
        for i in 0..count {
            copy.add(&sample(i, 1.0, i % 2 == 1));
        }
        let kept = copy.finish();
        assert!(kept.len() <= 100 + 2 * PINNED + 1, "{}", kept.len());
        assert_eq!(kept.last().map(index), Some(count - 1));
    }
}
