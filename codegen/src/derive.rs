//! The whole symbolic derivation of a model: kinematics, cam constraints, dynamics, energy
//! and prescribed motions, all in one expression graph.

use crate::constraint::{ContactTerms, contact_terms, value_and_derivatives};
use crate::dynamics::{DynamicsTerms, EnergyTerms, backward, energy};
use crate::expr::{Graph, Id};
use crate::kinematics::{Symbols, forward};
use crate::model::Model;

/// q(t), q̇(t), q̈(t) of a driven coordinate.
#[derive(Debug, Clone, Copy)]
pub struct DriveTerms {
    /// Index of the driven coordinate.
    pub coordinate: usize,
    /// q(t), q̇(t), q̈(t).
    pub motion: [Id; 3],
}

/// Every symbolic term of a model.
#[derive(Debug, Clone)]
pub struct Derivation {
    /// The expression graph holding all terms.
    pub graph: Graph,
    /// Symbols of q, q̇, t.
    pub symbols: Symbols,
    /// M, F, Q (13).
    pub dynamics: DynamicsTerms,
    /// One entry per contact (1)–(8).
    pub contacts: Vec<ContactTerms>,
    /// Energy expressions.
    pub energy: EnergyTerms,
    /// Prescribed motions of driven joints.
    pub drives: Vec<DriveTerms>,
}

impl Derivation {
    /// Derives every term of `model`.
    pub fn new(model: &Model) -> Self {
        let mut g = Graph::new();
        let symbols = Symbols::new(&mut g, model);
        let kin = forward(&mut g, model, &symbols);
        let contacts = contact_terms(&mut g, model, &kin, &symbols.qd);
        let dynamics = backward(&mut g, model, &symbols, &kin);
        let energy = energy(&mut g, model, &symbols, &kin);
        let drives = model
            .bodies
            .iter()
            .enumerate()
            .filter_map(|(i, b)| {
                let p = b.joint.prescribed.as_ref()?;
                g.set_section(format!("prescribed motion of {}", b.joint.coordinate));
                let motion = value_and_derivatives(&mut g, &p.expr, "__drive_t", symbols.t);
                Some(DriveTerms {
                    coordinate: i,
                    motion,
                })
            })
            .collect();
        Derivation {
            graph: g,
            symbols,
            dynamics,
            contacts,
            energy,
            drives,
        }
    }

    /// Values of the graph's variables for a state (q, q̇, t), for [`Graph::eval`].
    pub fn variables(&self, t: f64, q: &[f64], qd: &[f64]) -> Vec<f64> {
        let mut vars = vec![f64::NAN; self.graph.var_names().len()];
        let mut set = |id: Id, v: f64| {
            if let crate::expr::Node::Var(k) = self.graph.node(id) {
                vars[k as usize] = v;
            }
        };
        for (i, &id) in self.symbols.q.iter().enumerate() {
            set(id, q[i]);
        }
        for (i, &id) in self.symbols.qd.iter().enumerate() {
            set(id, qd[i]);
        }
        set(self.symbols.t, t);
        vars
    }

    /// Evaluates expressions at a state with the interpreter.
    pub fn eval(&self, roots: &[Id], t: f64, q: &[f64], qd: &[f64]) -> Vec<f64> {
        self.graph.eval(roots, &self.variables(t, q, qd))
    }
}
