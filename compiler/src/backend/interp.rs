//! The IR interpreter backend: implements the runtime's [`System`] by evaluating the model's
//! expressions directly, so `reachc run --backend interp` needs no cargo invocation. Results
//! agree with generated code (the same operations in the same order; both use the runtime's
//! special functions and table interpolation).

use reachc_runtime::{Interval, System};

use crate::analysis::Derivatives;
use crate::ir::{Arith, ExprId, VarValues};
use crate::model::Model;

/// The outputs of one `System` method and the nodes they need, in evaluation order (computed
/// once: the engines call each method at every step).
#[derive(Debug)]
struct Plan {
    roots: Vec<ExprId>,
    order: Vec<ExprId>,
}

impl Plan {
    fn new(model: &Model, roots: Vec<ExprId>) -> Plan {
        Plan {
            order: model.pool.reachable(&roots),
            roots,
        }
    }
}

/// A model evaluated by walking its IR.
#[derive(Debug)]
pub struct Interpreter {
    model: Model,
    drift: Plan,
    jac_x: Plan,
    jac_u: Plan,
    diffusion: Plan,
}

impl Interpreter {
    /// Wraps a model and its derivatives (from the same pool).
    pub fn new(model: Model, derivatives: &Derivatives) -> Self {
        Interpreter {
            drift: Plan::new(&model, model.drift.clone()),
            jac_x: Plan::new(
                &model,
                derivatives.jac_x.iter().flatten().copied().collect(),
            ),
            jac_u: Plan::new(
                &model,
                derivatives.jac_u.iter().flatten().copied().collect(),
            ),
            diffusion: Plan::new(&model, model.diffusion.iter().flatten().copied().collect()),
            model,
        }
    }

    /// The wrapped model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    fn eval_into<T: Arith>(&self, plan: &Plan, x: &[T], u: &[T], t: T, out: &mut [T]) {
        let vars = VarValues {
            states: x,
            inputs: u,
            // Drift and diffusion coefficients never mention noise channels (the checker
            // extracted them), so no values are needed.
            noises: &[],
            time: t,
        };
        let values =
            self.model
                .pool
                .eval_ordered(&plan.order, &plan.roots, &vars, &self.model.tables);
        out.copy_from_slice(&values);
    }
}

impl System for Interpreter {
    fn n(&self) -> usize {
        self.model.states.len()
    }

    fn p(&self) -> usize {
        self.model.inputs.len()
    }

    fn m(&self) -> usize {
        self.model.noises.len()
    }

    fn drift(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]) {
        self.eval_into(&self.drift, x, u, t, out);
    }

    fn drift_interval(&self, x: &[Interval], u: &[Interval], t: Interval, out: &mut [Interval]) {
        self.eval_into(&self.drift, x, u, t, out);
    }

    fn jac_x(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]) {
        self.eval_into(&self.jac_x, x, u, t, out);
    }

    fn jac_x_interval(&self, x: &[Interval], u: &[Interval], t: Interval, out: &mut [Interval]) {
        self.eval_into(&self.jac_x, x, u, t, out);
    }

    fn jac_u(&self, x: &[f64], u: &[f64], t: f64, out: &mut [f64]) {
        self.eval_into(&self.jac_u, x, u, t, out);
    }

    fn jac_u_interval(&self, x: &[Interval], u: &[Interval], t: Interval, out: &mut [Interval]) {
        self.eval_into(&self.jac_u, x, u, t, out);
    }

    fn diffusion(&self, x: &[f64], t: f64, out: &mut [f64]) {
        self.eval_into(&self.diffusion, x, &[], t, out);
    }

    fn diffusion_interval(&self, x: &[Interval], t: Interval, out: &mut [Interval]) {
        self.eval_into(&self.diffusion, x, &[], t, out);
    }
}
