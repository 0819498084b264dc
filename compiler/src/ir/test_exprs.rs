//! Expressions the IR's unit tests share.

use super::{ExprId, Func1, Pool, Var};

/// Every one-argument function, [`Func1::DSinc`] (which only derivatives make) last.
pub(crate) const FUNC1: [Func1; 14] = [
    Func1::Sin,
    Func1::Cos,
    Func1::Tan,
    Func1::Exp,
    Func1::Log,
    Func1::Sqrt,
    Func1::Abs,
    Func1::Atan,
    Func1::Sinh,
    Func1::Cosh,
    Func1::Tanh,
    Func1::Sinc,
    Func1::Sign,
    Func1::DSinc,
];

/// A let-style chain of `levels` steps in the states `x` (0) and `y` (1), alternately `e <-
/// sin(e)` and `e <- e y + x` from `e = x`: a DAG as deep as it is long.
pub(crate) fn sin_chain(p: &mut Pool, levels: usize) -> ExprId {
    let x = p.var(Var::State(0));
    let y = p.var(Var::State(1));
    let mut e = x;
    for i in 0..levels {
        e = if i % 2 == 0 {
            p.call1(Func1::Sin, e)
        } else {
            let m = p.mul(e, y);
            p.add(m, x)
        };
    }
    e
}
