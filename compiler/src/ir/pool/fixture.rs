//! The fixture the pool's unit tests share: a pool with the states `x`, `y`, `z`.

use super::Pool;
use crate::ir::{ExprId, Names, Var};

pub(super) struct Fx {
    pub(super) pool: Pool,
    pub(super) x: ExprId,
    pub(super) y: ExprId,
    pub(super) z: ExprId,
    pub(super) names: Vec<String>,
}

pub(super) fn fx() -> Fx {
    let mut pool = Pool::new();
    let x = pool.var(Var::State(0));
    let y = pool.var(Var::State(1));
    let z = pool.var(Var::State(2));
    Fx {
        pool,
        x,
        y,
        z,
        names: vec!["x".into(), "y".into(), "z".into()],
    }
}

impl Fx {
    pub(super) fn show(&self, e: ExprId) -> String {
        let names = Names {
            states: &self.names,
            inputs: &[],
            noises: &[],
            tables: &[],
        };
        self.pool.to_sde(e, &names)
    }
    pub(super) fn c(&mut self, v: f64) -> ExprId {
        self.pool.num(v)
    }
}
