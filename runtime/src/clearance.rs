//! Grooves with backlash: a roller (or a pin) in a barrel or face cam's groove wider than it.
//!
//! A closed groove holds the roller on its centre line: the contact's gap function is d(q), the
//! signed offset of the roller's centre from it (positive towards the flank a negative normal
//! force would press: a face cam's outer flank, a barrel's upper one), and the contact is
//! bilateral. For a face cam d is the distance from the centre line; for a barrel it is the
//! height above the pitch surface along the cam's axis, so a barrel's backlash is the roller's
//! axial play (the flanks are the pitch surface moved b/2 up and down the axis, then offset by
//! the roller's radius). With a backlash b > 0 the groove is b wider than the roller, so the
//! centre moves freely while |d| < b/2 and touches a flank at d = ±b/2: two one-sided
//! contacts, never both at once. [`Clearance`] presents them to the one-sided run
//! ([`crate::unilateral`]) as one contact whose gap is the distance to the nearer flank,
//!
//! ```text
//! g = b/2 − s d,   s = sign d (s = +1 at d = 0),
//! ∂g/∂q = −s J,   c_g = −s c,
//! ```
//!
//! smooth wherever the roller can touch (|d| = b/2 > 0; the kink at d = 0 lies in the middle
//! of the clearance, where no contact is active). The force a flank exerts pushes the roller
//! away from it, towards the centre line: the normal is −s n (n the closed groove's normal,
//! from the inner or lower flank towards the roller), and the contact point is the roller's
//! rim on that side, C − ρ (−s n) with C its centre and ρ its radius (the closed groove's
//! reported point is C − d u − ρ n, u = n for a face cam and the cam's axis for a barrel,
//! which gives ρ). A lift-off is the roller leaving a flank,
//! a landing an impact on one ([`Dynamics::groove_flank`] says which).
//!
//! The cam-frame coordinates of the contact point (`x`, `y`, `z` of [`ContactGeometry`], what
//! the drawings of the cam plot) stay those of the closed groove's reported point: the
//! centre line moved by ρ towards the inner or lower flank.

use crate::dynamics::{
    ContactGeometry, ContactKinematics, Dynamics, Flank, ModelInfo, VelocityTerms,
};
use crate::error::SimError;
use std::cell::RefCell;

/// A model whose grooves with backlash ([`crate::dynamics::ContactInfo::backlash`] > 0)
/// are seen as one-sided contacts on the nearer flank (see the module documentation). Its
/// other contacts and everything else are the inner model's.
pub struct Clearance<'a, D: ?Sized> {
    inner: &'a D,
    /// b/2 of each contact (0 for a contact without backlash, left as it is).
    half: Vec<f64>,
    /// The last q seen (by its bits), the inner model's h there and the signs s: a
    /// right-hand side asks for them at one q several times.
    last: RefCell<(Vec<u64>, Vec<f64>, Vec<f64>)>,
}

impl<'a, D: Dynamics + ?Sized> Clearance<'a, D> {
    /// `inner` with its grooves' backlash.
    pub fn new(inner: &'a D) -> Self {
        let info = inner.info();
        Clearance {
            inner,
            half: info.contacts.iter().map(|c| 0.5 * c.backlash).collect(),
            last: RefCell::new((Vec::new(), Vec::new(), Vec::new())),
        }
    }

    /// True when some contact of `model` has backlash.
    pub fn applies_to(model: &D) -> bool {
        model.info().contacts.iter().any(|c| c.backlash > 0.0)
    }

    /// The signs s of the contacts with backlash at q (1 for the others) and the inner
    /// model's h there.
    fn signs(&self, q: &[f64]) -> (Vec<f64>, Vec<f64>) {
        {
            let last = self.last.borrow();
            if last.0.len() == q.len() && last.0.iter().zip(q).all(|(a, b)| *a == b.to_bits()) {
                return (last.2.clone(), last.1.clone());
            }
        }
        let mut h = vec![0.0; self.inner.info().n_constraints()];
        self.inner.constraint(q, &mut h);
        self.remember(q, &h)
    }

    /// Keeps the inner model's h at q (as computed by the caller) and its signs.
    fn remember(&self, q: &[f64], h: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let s: Vec<f64> = self
            .half
            .iter()
            .zip(h)
            .map(|(&half, &d)| if half > 0.0 && d < 0.0 { -1.0 } else { 1.0 })
            .collect();
        *self.last.borrow_mut() = (
            q.iter().map(|x| x.to_bits()).collect(),
            h.to_vec(),
            s.clone(),
        );
        (s, h.to_vec())
    }

    /// h, J and c rows of the contacts with backlash turned into the nearer flank's gap.
    fn transform(
        &self,
        s: &[f64],
        h: Option<&mut [f64]>,
        j: Option<&mut [f64]>,
        c: Option<&mut [f64]>,
    ) {
        let n = self.inner.info().n();
        let mut h = h;
        let mut j = j;
        let mut c = c;
        for (k, (&half, &s)) in self.half.iter().zip(s).enumerate() {
            if half <= 0.0 {
                continue;
            }
            if let Some(h) = h.as_deref_mut() {
                h[k] = half - s * h[k];
            }
            if let Some(j) = j.as_deref_mut() {
                for v in &mut j[k * n..(k + 1) * n] {
                    *v *= -s;
                }
            }
            if let Some(c) = c.as_deref_mut() {
                c[k] *= -s;
            }
        }
    }

    /// The geometry of contact k at the flank of sign s, from the closed groove's `g` with
    /// gap function d: the centre C is the closed groove's point plus d u + ρ n, u the normal
    /// n itself for a face cam (d a distance) and the cam's axis for a barrel (`axial`: d a
    /// height), which gives ρ.
    fn flank_geometry(g: &mut ContactGeometry, d: f64, s: f64, axial: bool) {
        let dot = |a: &[f64; 3], b: &[f64; 3]| (0..3).map(|i| a[i] * b[i]).sum::<f64>();
        let offset: [f64; 3] = std::array::from_fn(|i| g.follower[i] - g.position[i]);
        let along_normal = if axial { dot(&g.axis, &g.normal) } else { 1.0 };
        let radius = dot(&offset, &g.normal) - d * along_normal;
        g.normal = g.normal.map(|x| -s * x);
        for i in 0..3 {
            g.position[i] = g.follower[i] - radius * g.normal[i];
        }
    }
}

impl<D: Dynamics + ?Sized> Clearance<'_, D> {
    /// Whether contact k's gap is a height along the cam's axis (a barrel's pitch surface)
    /// rather than a distance (a face cam's centre line).
    fn axial(&self, k: usize) -> bool {
        self.inner.info().contacts[k].profile == crate::dynamics::ProfileKind::Barrel
    }
}

impl<D: Dynamics + ?Sized> Dynamics for Clearance<'_, D> {
    fn info(&self) -> &ModelInfo {
        self.inner.info()
    }
    crate::dynamics::forward_free_motion!(inner);
    fn loop_points(&self, q: &[f64], out: &mut [[f64; 3]]) {
        self.inner.loop_points(q, out);
    }
    fn constraint(&self, q: &[f64], h: &mut [f64]) {
        self.inner.constraint(q, h);
        let (s, _) = self.remember(q, h);
        self.transform(&s, Some(h), None, None);
    }
    fn constraint_jacobian(&self, q: &[f64], j: &mut [f64]) {
        self.inner.constraint_jacobian(q, j);
        let (s, _) = self.signs(q);
        self.transform(&s, None, Some(j), None);
    }
    fn constraint_bias(&self, q: &[f64], qd: &[f64], c: &mut [f64]) {
        self.inner.constraint_bias(q, qd, c);
        let (s, _) = self.signs(q);
        self.transform(&s, None, None, Some(c));
    }
    fn constraint_terms(&self, q: &[f64], qd: &[f64], j: &mut [f64], c: &mut [f64]) {
        self.inner.constraint_terms(q, qd, j, c);
        let (s, _) = self.signs(q);
        self.transform(&s, None, Some(j), Some(c));
    }
    fn contact_geometry(&self, q: &[f64], qd: &[f64], out: &mut [ContactGeometry]) {
        self.inner.contact_geometry(q, qd, out);
        let (s, h) = self.signs(q);
        for (k, g) in out.iter_mut().enumerate() {
            if self.half.get(k).is_some_and(|&half| half > 0.0) {
                Self::flank_geometry(g, h[k], s[k], self.axial(k));
            }
        }
    }
    fn contact_kinematics_into(
        &self,
        q: &[f64],
        qd: &[f64],
        k: usize,
        out: &mut ContactKinematics,
    ) {
        self.inner.contact_kinematics_into(q, qd, k, out);
        if self.half.get(k).is_some_and(|&half| half > 0.0) {
            let (s, h) = self.signs(q);
            Self::flank_geometry(&mut out.geometry, h[k], s[k], self.axial(k));
        }
    }
    fn groove_flank(&self, q: &[f64], k: usize) -> Option<Flank> {
        if !self.half.get(k).is_some_and(|&half| half > 0.0) {
            return None;
        }
        let (s, _) = self.signs(q);
        Some(if s[k] < 0.0 {
            Flank::Inner
        } else {
            Flank::Outer
        })
    }
    fn position_terms(&self, q: &[f64], h: &mut [f64], j: &mut [f64], cache: &mut [f64]) {
        self.inner.position_terms(q, h, j, cache);
        let (s, _) = self.remember(q, h);
        self.transform(&s, Some(h), Some(j), None);
    }
    fn velocity_terms(&self, t: f64, q: &[f64], qd: &[f64], cache: &[f64], out: VelocityTerms) {
        let (s, _) = self.signs(q);
        let VelocityTerms {
            mass,
            inertial,
            applied,
            bias,
        } = out;
        self.inner.velocity_terms(
            t,
            q,
            qd,
            cache,
            VelocityTerms {
                mass,
                inertial,
                applied,
                bias: &mut *bias,
            },
        );
        self.transform(&s, None, None, Some(bias));
    }
}

/// A bilateral run holds every follower on its cam, which a groove with backlash cannot do:
/// its roller moves freely between the flanks ([`crate::clearance`]).
pub(crate) fn held_both_ways(model: &dyn Dynamics) -> Result<(), SimError> {
    match model.info().contacts.iter().find(|c| c.backlash > 0.0) {
        Some(c) => Err(SimError::InvalidSettings {
            message: format!(
                "the groove of {} has a backlash of {} m: its roller moves freely between the \
                 flanks and lands on one or the other, which only a one-sided run follows (give \
                 the flanks' coefficient of restitution: `restitution` in the model's \
                 `simulation`, or --restitution)",
                c.name, c.backlash
            ),
        }),
        None => Ok(()),
    }
}

/// A tapered roller's flanks push it outward (N tan γ, [`ContactGeometry::flank_force`]),
/// which the model leaves to the follower's guide: at the run's start no free coordinate may
/// move a tapered roller towards or away from the cam's axis, ∂r/∂q = (X J1 + Y J2)/r = 0
/// (to 1e-9 m per unit of the coordinate), or the push would do work the constraint misses.
pub(crate) fn tapered_rollers_hold_their_radius(
    model: &dyn Dynamics,
    q: &[f64],
    qd: &[f64],
) -> Result<(), SimError> {
    let info = model.info();
    for (k, contact) in info.contacts.iter().enumerate() {
        if contact.taper == 0.0 {
            continue;
        }
        let kinematics = model.contact_kinematics(q, qd, k);
        let r = kinematics.x.hypot(kinematics.y);
        let moving = info.coordinates.iter().enumerate().find_map(|(j, c)| {
            let rate = (kinematics.x * kinematics.j1[j] + kinematics.y * kinematics.j2[j]) / r;
            (!c.driven && rate.abs() > 1e-9).then_some((c.name.as_str(), rate))
        });
        if let Some((name, rate)) = moving {
            return Err(SimError::InvalidSettings {
                message: format!(
                    "the tapered roller of {} is pushed outward by its flanks (N tan γ), which \
                     its follower's guide must hold, but coordinate {name} moves it towards or \
                     away from the cam's axis (∂r/∂{name} = {rate:.6e} at the start): guide the \
                     follower so that the roller keeps its radius, or use a straight roller",
                    contact.name
                ),
            });
        }
    }
    Ok(())
}
