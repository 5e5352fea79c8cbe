//! The split of the coordinates into driven, independent and dependent sets.

use crate::error::SimError;
use std::sync::Arc;

/// The split of the coordinates into driven, independent and dependent sets.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Partition {
    contacts: usize,
    driven: Vec<usize>,
    independent: Vec<usize>,
    /// Shared with every sample taken under this partition (a counter increment per
    /// sample instead of an allocation).
    dependent: Arc<[usize]>,
    eligible: Vec<bool>,
}

impl Partition {
    /// Partition with `driven_flags[i]` true for the driven coordinates and the given
    /// dependent ones; every other coordinate is independent (in increasing order, which is
    /// the order of u in the integrated state).
    pub fn new(driven_flags: &[bool], dependent: &[usize]) -> Result<Self, SimError> {
        let mut partition = Self {
            contacts: dependent.len(),
            driven: (0..driven_flags.len())
                .filter(|&i| driven_flags[i])
                .collect(),
            independent: Vec::with_capacity(driven_flags.len()),
            dependent: Arc::from(dependent),
            eligible: driven_flags.iter().map(|d| !d).collect(),
        };
        partition.set_dependent(dependent)?;
        Ok(partition)
    }

    /// Replaces the dependent set (same size: one per contact); the independent set follows.
    /// Fails when an index is out of range, repeated or driven.
    pub fn set_dependent(&mut self, dependent: &[usize]) -> Result<(), SimError> {
        self.validate_dependent(dependent)?;
        self.dependent = Arc::from(dependent);
        self.independent.clear();
        let n = self.eligible.len();
        let is_free = |i: &usize| self.eligible[*i] && !dependent.contains(i);
        self.independent.extend((0..n).filter(is_free));
        Ok(())
    }

    fn validate_dependent(&self, dependent: &[usize]) -> Result<(), SimError> {
        let n = self.eligible.len();
        let invalid = |message: String| Err(SimError::InvalidSettings { message });
        if dependent.len() != self.contacts {
            return invalid(format!(
                "{} dependent coordinates given, the model has {} contacts",
                dependent.len(),
                self.contacts
            ));
        }
        for (k, &i) in dependent.iter().enumerate() {
            if i >= n || !self.eligible[i] || dependent[..k].contains(&i) {
                return invalid(format!(
                    "dependent coordinate {i} is out of range, driven or repeated"
                ));
            }
        }
        Ok(())
    }

    /// Number of coordinates.
    pub fn n(&self) -> usize {
        self.eligible.len()
    }

    /// Driven coordinates d (increasing).
    pub fn driven(&self) -> &[usize] {
        &self.driven
    }

    /// Independent coordinates u (increasing): the integrated ones.
    pub fn independent(&self) -> &[usize] {
        &self.independent
    }

    /// Dependent coordinates v, one per contact: recovered by (15), (16).
    pub fn dependent(&self) -> &[usize] {
        &self.dependent
    }

    /// The dependent coordinates as a shared slice (what a [`crate::Sample`] records).
    pub fn dependent_shared(&self) -> Arc<[usize]> {
        Arc::clone(&self.dependent)
    }

    /// `eligible()[i]`: coordinate i may be dependent (it is not driven).
    pub fn eligible(&self) -> &[bool] {
        &self.eligible
    }
}
