//! The functions given by data that the graph reads ([`Node::Table`], [`Node::Grid`]):
//! their registries and their leaves, folded where the argument is constant or the order is
//! beyond what the data has.

use super::{Graph, Grid, Id, Node, Table};

impl Graph {
    /// Registers a tabulated function (once per name); returns its index for
    /// [`Graph::table`].
    pub fn add_table(&mut self, table: Table) -> u32 {
        if let Some(k) = self.tables.iter().position(|t| t.name == table.name) {
            return k as u32;
        }
        self.tables.push(table);
        (self.tables.len() - 1) as u32
    }

    /// The tabulated functions, by index.
    pub fn tables(&self) -> &[Table] {
        &self.tables
    }

    /// The derivative of order `order` of table `t` at a, with folding: a constant argument
    /// gives a constant, an order above 3 a constant too (zero for a spline, whose fourth
    /// derivative vanishes inside every segment; NaN for a law, which does not provide it).
    pub fn table(&mut self, t: u32, order: u8, a: Id) -> Id {
        let Some(table) = self.tables.get(t as usize).cloned() else {
            return self.constant(f64::NAN);
        };
        if order > 3 {
            return self.constant(table.derivative(order, 0.0));
        }
        match self.as_const(a) {
            Some(x) => self.constant(table.derivative(order, x)),
            None => self.intern(Node::Table(t, order, a)),
        }
    }

    /// Registers a surface given on a grid (once per name); returns its index for
    /// [`Graph::grid`].
    pub fn add_grid(&mut self, grid: Grid) -> u32 {
        if let Some(k) = self.grids.iter().position(|g| g.name == grid.name) {
            return k as u32;
        }
        self.grids.push(grid);
        (self.grids.len() - 1) as u32
    }

    /// The surfaces given on grids, by index.
    pub fn grids(&self) -> &[Grid] {
        &self.grids
    }

    /// ∂ᵖ_x ∂ᵠ_y (`order` = (p, q)) of surface `k` at (a, b), with folding: constant
    /// arguments give a constant, an order above 3 in either variable zero (the spline is
    /// cubic in each inside every cell).
    pub fn grid(&mut self, k: u32, order: (u8, u8), a: Id, b: Id) -> Id {
        let Some(grid) = self.grids.get(k as usize).cloned() else {
            return self.constant(f64::NAN);
        };
        if order.0 > 3 || order.1 > 3 {
            return self.zero();
        }
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => self.constant(grid.derivative(order, x, y)),
            _ => self.intern(Node::Grid(k, order, a, b)),
        }
    }
}
