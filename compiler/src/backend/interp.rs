//! The IR interpreter backend: implements the runtime's [`System`] by evaluating the model's
//! expressions directly, so `reachc run --backend interp` needs no cargo invocation. Results
//! agree with generated code (the same operations in the same order; both use the runtime's
//! special functions and table interpolation).

use reachc_core::{Interval, ModelInfo, System};

use std::sync::Arc;

use super::Prepared;
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

/// A model evaluated by walking its IR, with the model data prepared from it: a
/// [`reachc_core::Model`] the engines run.
#[derive(Debug)]
pub struct Interpreter {
    model: Arc<Model>,
    /// The model data [`super::prepare`] derived (shared with the transformed systems, which
    /// are reached only as [`System::frame`]s).
    info: Arc<ModelInfo>,
    drift: Plan,
    jac_x: Plan,
    /// The entries of `jac_x` where the drift depends on the state, and where they are.
    jac_x_sparse: Plan,
    jac_x_pattern: Vec<(usize, usize)>,
    jac_u: Plan,
    diffusion: Plan,
    /// The numbers of the moving sets (method.md 8.15; empty in a transformed system).
    set_numbers: Plan,
    /// The transformed systems ([`System::frame`]), over the same model (and pool).
    frames: Vec<Interpreter>,
}

impl Interpreter {
    /// Wraps a model and what [`super::prepare`] derived from it (its pool holds the
    /// derivatives and the transformed systems).
    pub fn new(model: Model, prepared: &Prepared) -> Self {
        let model = Arc::new(model);
        let info = Arc::new(prepared.info.clone());
        let frames = prepared
            .frames
            .iter()
            .map(|f| {
                let (drift, diffusion) = (&f.drift, &f.diffusion);
                Interpreter::of(&model, &info, drift, diffusion, &f.derivatives, Vec::new())
            })
            .collect();
        let drift = model.drift.clone();
        let diffusion = model.diffusion.clone();
        let derivatives = &prepared.derivatives;
        let mut own = Interpreter::of(&model, &info, &drift, &diffusion, derivatives, frames);
        own.set_numbers = Plan::new(&model, model.set_numbers.clone());
        own
    }

    fn of(
        model: &Arc<Model>,
        info: &Arc<ModelInfo>,
        drift: &[ExprId],
        diffusion: &[Vec<ExprId>],
        derivatives: &Derivatives,
        frames: Vec<Interpreter>,
    ) -> Self {
        let flat = |m: &[Vec<ExprId>]| m.iter().flatten().copied().collect();
        let nonzeros = derivatives.jac_x_dependencies(&model.pool, drift);
        Interpreter {
            jac_x_sparse: Plan::new(model, nonzeros.iter().map(|&(_, _, e)| e).collect()),
            jac_x_pattern: nonzeros.iter().map(|&(i, j, _)| (i, j)).collect(),
            drift: Plan::new(model, drift.to_vec()),
            jac_x: Plan::new(model, flat(&derivatives.jac_x)),
            jac_u: Plan::new(model, flat(&derivatives.jac_u)),
            diffusion: Plan::new(model, flat(diffusion)),
            set_numbers: Plan::new(model, Vec::new()),
            model: Arc::clone(model),
            info: Arc::clone(info),
            frames,
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

impl reachc_core::Model for Interpreter {
    fn info(&self) -> &ModelInfo {
        &self.info
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

    fn jac_x_pattern(&self) -> Vec<(usize, usize)> {
        self.jac_x_pattern.clone()
    }

    fn jac_x_sparse_interval(
        &self,
        x: &[Interval],
        u: &[Interval],
        t: Interval,
        out: &mut [Interval],
    ) {
        self.eval_into(&self.jac_x_sparse, x, u, t, out);
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

    fn frame(&self, k: usize) -> Option<&dyn System> {
        self.frames.get(k).map(|f| f as &dyn System)
    }

    fn set_numbers(&self, t: Interval, out: &mut [Interval]) {
        if !self.set_numbers.roots.is_empty() {
            self.eval_into(&self.set_numbers, &[], &[], t, out);
        }
    }
}
