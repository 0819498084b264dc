//! The constants of Assumption 1 (method.md section 3) for one metric `P`, certified.
//!
//! * `c`: the smallest number with `A'P + PA <= 2cP` for every Jacobian `A = D_x f(x, u, t)`.
//! * `sigma`: `G(x, t)' P G(x, t) <= sigma^2 I`.
//! * `rho`: `|D_u f v|_P <= rho |v|_U` with `|v|_U = max_j |v_j| / h_j` (input box half-widths).
//!
//! Each matrix (`D_x f`, `G`, `D_u f`) is split into atoms, `M = M0 + sum_k a_k M_k`; every
//! quantity above is convex in `M`, so its maximum over the `2^K` vertices (atoms at the ends of
//! their interval ranges) bounds it over everything the model can produce. With more than
//! [`MAX_VERTEX_ATOMS`] atoms the whole matrix is taken as an interval matrix instead.
//!
//! Floats only propose: every returned number passed an interval-arithmetic test (see
//! [`super::psd`]) computed from the exact float data of the model and the metric.

use std::fmt;

use nalgebra::{DMatrix, SymmetricEigen};
use reachc_core::interval::Interval;
use reachc_core::model::{
    Bounds, Constants, ConstantsParts, InputGain, MatrixBound, MetricRegion, Provenance, Region,
};

use super::psd::{certify_min, is_psd, is_zero, sqrt_up, IMat, Pencil};
use super::{bound_matrix, eval_box, split_atoms, time_range, Derivatives};
use crate::ir::ExprId;
use crate::model::Model;

/// With more atoms than this, the `2^K` vertices are too many and the interval-matrix bound is
/// used instead.
pub const MAX_VERTEX_ATOMS: usize = 10;

/// With more inputs than this, `rho` is bounded column by column instead of over all `2^p` sign
/// vectors of the input box.
pub const MAX_SIGN_INPUTS: usize = 12;

/// Above this dimension float eigenvalues (`O(n^3)`) are not used to propose a constant; the
/// search starts from a Rayleigh-quotient lower bound and bisects with the certified test.
const EIGEN_MAX_DIM: usize = 200;

/// Why the constants could not be derived.
#[derive(Clone, Debug, PartialEq)]
pub enum ConstantsError {
    /// An entry of a matrix has an unbounded range over the domain (no `domain` box, or one too
    /// large): `matrix` is `"D_x f"`, `"G"` or `"D_u f"`, `row` the state, `column` the state,
    /// noise channel or input.
    Unbounded {
        /// Which matrix.
        matrix: &'static str,
        /// Its row (an equation / state index).
        row: usize,
        /// Its column.
        column: usize,
    },
    /// The metric is not an `n x n` symmetric positive definite matrix (or could not be
    /// certified as one).
    BadMetric {
        /// What is wrong with it.
        reason: String,
    },
    /// No bound could be certified for a constant (numerically hopeless data, e.g. entries
    /// near `f64::MAX`).
    NotCertified {
        /// `"c"`, `"sigma"` or `"rho"`.
        constant: &'static str,
    },
}

impl fmt::Display for ConstantsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ConstantsError::Unbounded {
                matrix,
                row,
                column,
            } => write!(
                f,
                "entry ({row}, {column}) of {matrix} is unbounded over the domain"
            ),
            ConstantsError::BadMetric { reason } => write!(f, "invalid metric: {reason}"),
            ConstantsError::NotCertified { constant } => {
                write!(f, "could not certify a bound for {constant}")
            }
        }
    }
}

impl std::error::Error for ConstantsError {}

/// The set of matrices a model's `D_x f`, `G` or `D_u f` ranges over.
#[derive(Clone, Debug)]
pub(crate) enum MatrixSet {
    /// The vertex matrices (each entry an interval enclosing the exact vertex entry).
    Vertices {
        /// One matrix per vertex.
        vertices: Vec<IMat>,
        /// Number of atoms with a non-degenerate range
        /// (`vertices.len() == 2^(atoms - fixed)`).
        atoms: usize,
        /// How many of them were fixed at one end of their range (see [`semidefinite_atoms`]).
        fixed: usize,
    },
    /// The interval matrix enclosing every entry (too many atoms for vertices).
    Hull {
        /// The enclosure.
        matrix: IMat,
        /// Number of atoms with a non-degenerate range.
        atoms: usize,
        /// How many of them were fixed at one end of their range.
        fixed: usize,
    },
}

impl MatrixSet {
    /// What the set is, for the constants' provenance.
    fn bound(&self) -> MatrixBound {
        match self {
            MatrixSet::Vertices {
                vertices,
                atoms,
                fixed,
            } => MatrixBound::Vertices {
                count: vertices.len(),
                atoms: *atoms,
                fixed: *fixed,
            },
            MatrixSet::Hull { atoms, fixed, .. } => MatrixBound::Hull {
                atoms: *atoms,
                fixed: *fixed,
                vertex_limit: MAX_VERTEX_ATOMS,
            },
        }
    }
}

/// An atom with a non-degenerate range: `a_k M_k` with `a_k` in `range`.
#[derive(Clone, Debug)]
pub(crate) struct VaryingAtom {
    /// `M_k` as sparse entries `(row, column, coefficient)` (exact floats).
    pub entries: Vec<(usize, usize, f64)>,
    /// An enclosure of the atom's range (its ends are exact floats).
    pub range: Interval,
}

/// `M = M0 + sum_k a_k M_k` over the domain: the constant part (with point-range atoms folded
/// in), the varying atoms and the direct interval enclosure of every entry.
#[derive(Clone, Debug)]
pub(crate) struct Decomposition {
    /// `M0` (intervals: point-range atoms times coefficients are rounded).
    pub base: IMat,
    /// The atoms with a non-degenerate range.
    pub atoms: Vec<VaryingAtom>,
    /// Entry-wise interval bounds of the matrix over the domain.
    pub bounds: IMat,
}

/// Adds `value * M_k` to `m` in interval arithmetic.
fn add_atom(m: &mut IMat, atom: &VaryingAtom, value: Interval) {
    for &(i, j, c) in &atom.entries {
        *m.at_mut(i, j) += Interval::point(c) * value;
    }
}

/// The atom split of `matrix` over the domain, input box and `time`.
///
/// Errors name the first unbounded entry in row-major order.
pub(crate) fn decompose(
    model: &Model,
    matrix: &[Vec<ExprId>],
    name: &'static str,
    time: Interval,
) -> Result<Decomposition, ConstantsError> {
    let rows = matrix.len();
    let cols = matrix.first().map_or(0, Vec::len);
    let bounds = bound_matrix(model, matrix, time);
    for (row, r) in bounds.iter().enumerate() {
        for (column, b) in r.iter().enumerate() {
            if !b.is_bounded() {
                return Err(ConstantsError::Unbounded {
                    matrix: name,
                    row,
                    column,
                });
            }
        }
    }
    let split = split_atoms(&model.pool, matrix);
    let exprs: Vec<ExprId> = split.atoms.iter().map(|a| a.expr).collect();
    let ranges = eval_box(model, &exprs, time);
    // An atom can be unbounded while its entries are not only through cancellations interval
    // evaluation does not see; report its first entry all the same.
    for (atom, range) in split.atoms.iter().zip(&ranges) {
        if !range.is_bounded() {
            let &(row, column, _) = atom.entries.iter().min_by_key(|e| (e.0, e.1)).unwrap();
            return Err(ConstantsError::Unbounded {
                matrix: name,
                row,
                column,
            });
        }
    }
    let mut base = IMat::zeros(rows, cols);
    for (i, row) in split.constant.iter().enumerate() {
        for (j, &v) in row.iter().enumerate() {
            *base.at_mut(i, j) = Interval::point(v);
        }
    }
    // Atoms with a point range are constants over the domain: fold them into `M0`.
    let mut atoms = Vec::new();
    for (atom, &range) in split.atoms.iter().zip(&ranges) {
        let atom = VaryingAtom {
            entries: atom.entries.clone(),
            range,
        };
        if range.lo() == range.hi() {
            add_atom(&mut base, &atom, range);
        } else {
            atoms.push(atom);
        }
    }
    let mut hull = IMat::zeros(rows, cols);
    for (i, r) in bounds.iter().enumerate() {
        for (j, &b) in r.iter().enumerate() {
            *hull.at_mut(i, j) = b;
        }
    }
    Ok(Decomposition {
        base,
        atoms,
        bounds: hull,
    })
}

impl Decomposition {
    /// The vertex set (or interval hull) with atom `k` fixed at the upper end of its range if
    /// `fix[k] == Some(true)`, at the lower end if `Some(false)`, and free if `None`.
    ///
    /// Without fixed atoms the hull is the direct entry-wise enclosure; with fixed atoms it is
    /// `M0 + sum_fixed end_k M_k + sum_free range_k M_k` (in interval arithmetic).
    pub(crate) fn set(&self, fix: &[Option<bool>]) -> MatrixSet {
        assert_eq!(fix.len(), self.atoms.len());
        let atoms = self.atoms.len();
        let mut base = self.base.clone();
        let mut free = Vec::new();
        for (atom, f) in self.atoms.iter().zip(fix) {
            match f {
                Some(hi) => {
                    let end = if *hi {
                        atom.range.hi()
                    } else {
                        atom.range.lo()
                    };
                    add_atom(&mut base, atom, Interval::point(end));
                }
                None => free.push(atom),
            }
        }
        let fixed = atoms - free.len();
        if free.len() > MAX_VERTEX_ATOMS {
            let matrix = if fixed == 0 {
                self.bounds.clone()
            } else {
                for atom in &free {
                    add_atom(&mut base, atom, atom.range);
                }
                base
            };
            return MatrixSet::Hull {
                matrix,
                atoms,
                fixed,
            };
        }
        let mut vertices = Vec::with_capacity(1 << free.len());
        for bits in 0..1usize << free.len() {
            let mut v = base.clone();
            for (k, atom) in free.iter().enumerate() {
                // The atom's ends are exact floats; the products with the coefficients are not,
                // so the vertex entries are computed (and kept) as intervals.
                let end = if bits >> k & 1 == 0 {
                    atom.range.lo()
                } else {
                    atom.range.hi()
                };
                add_atom(&mut v, atom, Interval::point(end));
            }
            vertices.push(v);
        }
        MatrixSet::Vertices {
            vertices,
            atoms,
            fixed,
        }
    }

    /// The set with every atom free.
    pub(crate) fn all_free(&self) -> MatrixSet {
        self.set(&vec![None; self.atoms.len()])
    }
}

/// The vertex set (or interval hull) of `matrix` over the domain, input box and `time`, with
/// every atom free.
///
/// Errors name the first unbounded entry in row-major order.
pub(crate) fn matrix_set(
    model: &Model,
    matrix: &[Vec<ExprId>],
    name: &'static str,
    time: Interval,
) -> Result<MatrixSet, ConstantsError> {
    Ok(decompose(model, matrix, name, time)?.all_free())
}

/// Above this total work (sum of the cubes of the tested blocks' sizes) the remaining atoms are
/// not tested for semidefiniteness (they stay free, which is sound).
const SEMIDEFINITE_WORK: usize = 200_000_000;

/// For each atom of a square matrix `A = M0 + sum_k a_k M_k` (the Jacobian): `Some(true)` if
/// `Q_k = (M_k'P + P M_k) / 2` is certified positive semidefinite, `Some(false)` if certified
/// negative semidefinite, `None` otherwise.
///
/// Why this is sound: `A'P + PA <= 2cP` is `S(a) = sum_k a_k Q_k + Q_0 <= cP`, and
/// `mu_P(A) = lambda_max(P^(-1/2) S(a) P^(-1/2))` is monotone in the PSD order. If `Q_k >= 0`
/// the maximum over `a_k` in `[lo, hi]` is at `a_k = hi` whatever the other atoms are (and at
/// `lo` if `Q_k <= 0`), so the maximum over the box is attained with every such atom fixed
/// there: fixing them loses nothing and halves the vertex count per atom. (`sym(R M R^-1)` for
/// `P = R'R` is congruent to `Q_k`, so this is the test of the task's `P`-transformed matrix.)
///
/// `Q_k` is computed in interval arithmetic from the exact coefficients and `P`, restricted to
/// the rows and columns where it can be non-zero, and tested with the interval LDL' of
/// [`is_psd`] (a zero pivot is accepted only with an exactly zero column).
pub(crate) fn semidefinite_atoms(dec: &Decomposition, p: &IMat) -> Vec<Option<bool>> {
    let n = p.rows;
    assert_eq!((dec.base.rows, dec.base.cols), (n, n));
    // Non-zero columns of every row of P.
    let p_rows: Vec<Vec<usize>> = (0..n)
        .map(|l| (0..n).filter(|&t| !is_zero(p.at(l, t))).collect())
        .collect();
    let mut work = 0usize;
    let mut position = vec![usize::MAX; n];
    dec.atoms
        .iter()
        .map(|atom| {
            // Support of `X = M_k' P` (rows: columns of M_k; columns: P-neighbours of M_k's
            // rows); `Q_k = (X + X') / 2` vanishes outside `support x support`.
            let mut support: Vec<usize> = Vec::new();
            let mut push = |i: usize, support: &mut Vec<usize>| {
                if position[i] == usize::MAX {
                    position[i] = support.len();
                    support.push(i);
                }
            };
            for &(l, j, _) in &atom.entries {
                push(j, &mut support);
                for &t in &p_rows[l] {
                    push(t, &mut support);
                }
            }
            let m = support.len();
            let result = (|| {
                work = work.saturating_add(m.saturating_pow(3));
                if work > SEMIDEFINITE_WORK {
                    return None;
                }
                let mut x = IMat::zeros(m, m);
                for &(l, j, c) in &atom.entries {
                    let c = Interval::point(c);
                    for &t in &p_rows[l] {
                        *x.at_mut(position[j], position[t]) += c * p.at(l, t);
                    }
                }
                let q = x.add(&x.transpose());
                let q = IMat {
                    data: q.data.iter().map(|&v| v * 0.5).collect(),
                    ..q
                };
                if is_psd(&q, false) {
                    return Some(true);
                }
                let neg = IMat {
                    data: q.data.iter().map(|&v| -v).collect(),
                    ..q
                };
                is_psd(&neg, false).then_some(false)
            })();
            for &i in &support {
                position[i] = usize::MAX;
            }
            result
        })
        .collect()
}

/// The Jacobian's set for the metric `P`: semidefinite atoms fixed (see
/// [`semidefinite_atoms`]), the others enumerated (or hulled when too many).
pub(crate) fn jacobian_set(dec: &Decomposition, p: &IMat) -> MatrixSet {
    dec.set(&semidefinite_atoms(dec, p))
}

/// Checks that `metric` is `n x n`, finite, exactly symmetric and (certifiably) positive definite.
pub(crate) fn check_metric(metric: &[f64], n: usize) -> Result<IMat, ConstantsError> {
    let bad = |reason: String| Err(ConstantsError::BadMetric { reason });
    if metric.len() != n * n {
        return bad(format!(
            "expected {n} x {n} = {} entries, found {}",
            n * n,
            metric.len()
        ));
    }
    if metric.iter().any(|v| !v.is_finite()) {
        return bad("an entry is not finite".into());
    }
    for i in 0..n {
        for j in 0..i {
            if metric[i * n + j] != metric[j * n + i] {
                return bad(format!(
                    "not symmetric: entries ({i}, {j}) and ({j}, {i}) differ"
                ));
            }
        }
    }
    let p = IMat::from_f64(n, n, metric);
    if !is_psd(&p, true) {
        return bad("not positive definite".into());
    }
    Ok(p)
}

/// Float square matrix from row-major data.
fn dmat(n: usize, data: &[f64]) -> DMatrix<f64> {
    DMatrix::from_row_slice(n, n, data)
}

/// Float estimates of `lambda_max` of the pencil `(S, P)`, i.e. of `L^-1 S L^-T` with
/// `P = L L'`, for symmetric `S` (given as row-major float data).
///
/// Large problems get the Rayleigh lower bound `max_i S_ii / P_ii` instead (the certified search
/// bisects up from it). Returns the estimates and a magnitude for the search's step sizes.
pub(crate) fn pencil_lambda_max(s_list: &[Vec<f64>], metric: &[f64], n: usize) -> (Vec<f64>, f64) {
    let mut scale = 0.0f64;
    for s in s_list {
        for i in 0..n {
            scale = scale.max((s[i * n + i] / metric[i * n + i]).abs());
        }
    }
    let chol = (n <= EIGEN_MAX_DIM)
        .then(|| nalgebra::Cholesky::new(dmat(n, metric)))
        .flatten();
    let estimates = s_list
        .iter()
        .map(|s| match &chol {
            Some(chol) => {
                let l = chol.l();
                let s = dmat(n, s);
                let x = l.solve_lower_triangular(&s).unwrap_or(s);
                let m = l
                    .solve_lower_triangular(&x.transpose())
                    .unwrap_or(x)
                    .transpose();
                let m = (&m + m.transpose()) * 0.5;
                let e = SymmetricEigen::new(m).eigenvalues;
                e.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            }
            None => (0..n)
                .map(|i| s[i * n + i] / metric[i * n + i])
                .fold(f64::NEG_INFINITY, f64::max),
        })
        .collect::<Vec<_>>();
    for e in &estimates {
        scale = scale.max(e.abs());
    }
    (estimates, scale)
}

/// The smallest `x` (certified) with `x * X - S_v` PSD for every `S_v` in `s_list`, where
/// `X` is the metric (for `c`, with `S = (A'P + PA) / 2`) or the identity (for `sigma^2`).
fn certify_pencil(
    s_list: &[IMat],
    x_mat: &IMat,
    x_float: &[f64],
    constant: &'static str,
) -> Result<f64, ConstantsError> {
    let n = x_mat.rows;
    if n == 0 || s_list.is_empty() {
        return Ok(0.0);
    }
    let mids: Vec<Vec<f64>> = s_list.iter().map(IMat::mid).collect();
    let (estimates, scale) = pencil_lambda_max(&mids, x_float, n);
    // Test the vertices with the largest estimates first: a failing one usually fails there.
    let mut order: Vec<usize> = (0..s_list.len()).collect();
    order.sort_by(|&a, &b| estimates[b].total_cmp(&estimates[a]));
    let guess = estimates.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let pencils: Vec<Pencil> = order
        .iter()
        .map(|&v| Pencil::new(&s_list[v], x_mat))
        .collect();
    let pass = |x: f64| pencils.iter().all(|q| q.psd_at(x));
    certify_min(guess, scale, pass).ok_or(ConstantsError::NotCertified { constant })
}

/// `S = (A'P + PA) / 2` in intervals (halving is exact).
fn sym_product(a: &IMat, p: &IMat) -> IMat {
    let pa = p.mul(a);
    let s = pa.add(&pa.transpose());
    IMat {
        data: s.data.iter().map(|&x| x * 0.5).collect(),
        ..s
    }
}

/// The certified contraction rate `c` for the metric `P`.
pub(crate) fn contraction_rate(
    set: &MatrixSet,
    p: &IMat,
    metric: &[f64],
) -> Result<f64, ConstantsError> {
    let s_list: Vec<IMat> = match set {
        MatrixSet::Vertices { vertices, .. } => {
            vertices.iter().map(|a| sym_product(a, p)).collect()
        }
        MatrixSet::Hull { matrix, .. } => vec![hull_pencil_matrix(matrix, p, metric)],
    };
    // `Q = 2cP - (A'P + PA) = 2 (c P - S)`: the factor 2 does not change PSD-ness.
    certify_pencil(&s_list, p, metric, "c")
}

/// For `A` in the interval matrix `[Mc - D, Mc + D]`: a symmetric interval matrix `S` with
/// `(A'P + PA) / 2 <= S` for every such `A`, so `cP - S >= 0` certifies `c`.
///
/// With `E = A - Mc`, `|E'P + PE| <= Nb = D'|P| + |P|D` entrywise. For any positive vector `v`,
/// the symmetric non-negative `Nb` satisfies `Nb <= diag(w)`, `w_i = (Nb v)_i / v_i` (the
/// difference is diagonally dominant after scaling by `v`), and `x'(E'P + PE)x <= |x|'Nb|x|`.
/// Hence `(A'P + PA)/2 <= (Mc'P + P Mc)/2 + diag(w)/2`. With `v_i = P_ii^(-1/2)` and a diagonal
/// `P` this is exactly method.md's `lambda_max(sym(Mc)) + rho(sym(D))` after the P-transform
/// (row sums bound the spectral radius); for a dense `P` it is a sound, cruder variant that
/// needs no exact square root of `P`.
fn hull_pencil_matrix(matrix: &IMat, p: &IMat, metric: &[f64]) -> IMat {
    let n = p.rows;
    let mut mc = IMat::zeros(n, n);
    let mut d = IMat::zeros(n, n);
    for (k, x) in matrix.data.iter().enumerate() {
        // `[mid - rad, mid + rad]` (exact) contains the entry.
        mc.data[k] = Interval::point(x.mid());
        d.data[k] = Interval::point(x.rad());
    }
    let abs_p = IMat::from_f64(n, n, &metric.iter().map(|x| x.abs()).collect::<Vec<_>>());
    let x = d.transpose().mul(&abs_p);
    let nb = x.add(&x.transpose());
    let v: Vec<Interval> = (0..n)
        .map(|i| Interval::point(1.0 / metric[i * n + i].sqrt()))
        .collect();
    let mut s = sym_product(&mc, p);
    for i in 0..n {
        let mut acc = Interval::ZERO;
        for (j, &vj) in v.iter().enumerate() {
            let b = nb.at(i, j);
            if !is_zero(b) {
                acc += Interval::point(b.hi()) * vj;
            }
        }
        let w = (acc / v[i]).hi();
        *s.at_mut(i, i) += Interval::point(w) * 0.5;
    }
    s
}

/// The certified `sigma` (`G'PG <= sigma^2 I`) for the metric.
pub(crate) fn noise_level(set: &MatrixSet, p: &IMat) -> Result<f64, ConstantsError> {
    let gs: Vec<&IMat> = match set {
        MatrixSet::Vertices { vertices, .. } => vertices.iter().collect(),
        MatrixSet::Hull { matrix, .. } => vec![matrix],
    };
    let m = gs.first().map_or(0, |g| g.cols);
    if m == 0 {
        return Ok(0.0);
    }
    // `G'PG` in intervals: for the hull this encloses `G'PG` for every `G` in the box (the
    // interval products over-approximate, which only loosens the bound).
    let t_list: Vec<IMat> = gs.iter().map(|g| g.transpose().mul(&p.mul(g))).collect();
    let identity: Vec<f64> = (0..m * m)
        .map(|k| if k % (m + 1) == 0 { 1.0 } else { 0.0 })
        .collect();
    let id = IMat::from_f64(m, m, &identity);
    let s2 = certify_pencil(&t_list, &id, &identity, "sigma")?;
    Ok(sqrt_up(s2))
}

/// The certified `rho` for the metric and the input box half-widths `h` (intervals enclosing
/// the exact half-widths, so whichever rounding the runtime uses for `h` is covered).
///
/// `rho = max over B and sign vectors s of |B diag(h) s|_P` (the U-ball's vertices; the norm is
/// convex), evaluated directly in interval arithmetic; with more than [`MAX_SIGN_INPUTS`] inputs
/// the sound column bound `sum_j h_j max_B |B e_j|_P` is used.
pub(crate) fn input_gain(
    set: &MatrixSet,
    p: &IMat,
    h: &[Interval],
) -> Result<(f64, InputGain), ConstantsError> {
    let bs: Vec<&IMat> = match set {
        MatrixSet::Vertices { vertices, .. } => vertices.iter().collect(),
        MatrixSet::Hull { matrix, .. } => vec![matrix],
    };
    let n = p.rows;
    let np = h.len();
    if np == 0 || bs.is_empty() {
        return Ok((0.0, InputGain::NoInputs));
    }
    for b in &bs {
        for (j, hj) in h.iter().enumerate() {
            if !hj.is_bounded() {
                if let Some(row) = (0..n).find(|&i| !is_zero(b.at(i, j))) {
                    return Err(ConstantsError::Unbounded {
                        matrix: "D_u f",
                        row,
                        column: j,
                    });
                }
            }
        }
    }
    let quad = |v: &[Interval]| {
        let mut q = Interval::ZERO;
        for i in 0..n {
            if is_zero(v[i]) {
                continue;
            }
            for j in 0..n {
                let pij = p.at(i, j);
                if !is_zero(pij) && !is_zero(v[j]) {
                    q += v[i] * pij * v[j];
                }
            }
        }
        q.hi()
    };
    // Bounded columns times finite (or zero) half-widths: drop columns with `h_j` unbounded
    // (they are zero columns, checked above).
    let column = |b: &IMat, j: usize, sign: f64| -> Vec<Interval> {
        if !h[j].is_bounded() {
            return vec![Interval::ZERO; n];
        }
        (0..n).map(|i| b.at(i, j) * h[j] * sign).collect()
    };
    if np > MAX_SIGN_INPUTS {
        let mut total = Interval::ZERO;
        for j in 0..np {
            let worst = bs
                .iter()
                .map(|b| quad(&column(b, j, 1.0)))
                .fold(0.0, f64::max);
            total += Interval::point(sqrt_up(worst));
        }
        return Ok((total.hi(), InputGain::Columns(set.bound())));
    }
    let mut worst = 0.0f64;
    for b in &bs {
        let cols: Vec<Vec<Interval>> = (0..np).map(|j| column(b, j, 1.0)).collect();
        // `s` and `-s` give the same norm: fix the last sign.
        for bits in 0..1usize << (np - 1) {
            let mut v = vec![Interval::ZERO; n];
            for (j, col) in cols.iter().enumerate() {
                let negative = j + 1 < np && bits >> j & 1 == 1;
                for i in 0..n {
                    v[i] = if negative {
                        v[i] - col[i]
                    } else {
                        v[i] + col[i]
                    };
                }
            }
            worst = worst.max(quad(&v));
        }
    }
    Ok((sqrt_up(worst), InputGain::Corners(set.bound())))
}

/// The constants of Assumption 1 for a model and one metric `P` (`n x n` row-major, symmetric
/// positive definite), each certified with interval arithmetic (never below the exact value for
/// the model's float data).
///
/// Bounds hold over the model's domain, input box and `t` in `[0, longest horizon]`.
/// Errors: an unbounded entry of `D_x f`, `G` or `D_u f` (the first in that order, row-major),
/// or a metric that is not symmetric positive definite.
pub fn constants(
    model: &Model,
    d: &Derivatives,
    metric: &[f64],
) -> Result<Constants, ConstantsError> {
    let n = model.states.len();
    let p = check_metric(metric, n)?;
    let jac = decompose(model, &d.jac_x, "D_x f", time_range(model))?;
    let jac = jacobian_set(&jac, &p);
    let c = contraction_rate(&jac, &p, metric)?;
    let mut consts = noise_and_input(model, d, metric, &p)?.into_parts();
    consts.c = c;
    if let Provenance::Certified { c, .. } = &mut consts.provenance {
        *c = Some(jac.bound());
    }
    Ok(Constants::from_parts(consts))
}

/// The constants of Assumption 1 without the contraction rate, for analyses whose rate is
/// estimated at run time ([`Rate::Empirical`](reachc_core::model::Rate::Empirical)):
/// `sigma` and `rho` as in [`constants`], `c` infinite (not bounded here).
pub fn constants_without_rate(
    model: &Model,
    d: &Derivatives,
    metric: &[f64],
) -> Result<Constants, ConstantsError> {
    let p = check_metric(metric, model.states.len())?;
    noise_and_input(model, d, metric, &p)
}

/// `sigma` and `rho` (with `c` infinite) and how they were obtained.
fn noise_and_input(
    model: &Model,
    d: &Derivatives,
    metric: &[f64],
    p: &IMat,
) -> Result<Constants, ConstantsError> {
    let time = time_range(model);
    let diffusion = matrix_set(model, &model.diffusion, "G", time)?;
    let jac_u = matrix_set(model, &d.jac_u, "D_u f", time)?;
    let sigma = noise_level(&diffusion, p)?;
    let h: Vec<Interval> = model
        .input_box
        .iter()
        .map(|&b| match b {
            b if b.lo.is_finite() && b.hi.is_finite() => {
                (Interval::point(b.hi) - Interval::point(b.lo)) * 0.5
            }
            _ => Interval::ENTIRE,
        })
        .collect();
    let (rho, gain) = input_gain(&jac_u, p, &h)?;
    Ok(Constants::from_parts(ConstantsParts {
        metric: metric.to_vec(),
        // A caller that synthesised the metric says where.
        metric_region: MetricRegion::Given,
        c: f64::INFINITY,
        sigma,
        rho,
        provenance: Provenance::Certified {
            c: None,
            sigma: diffusion.bound(),
            rho: gain,
        },
        also: Vec::new(),
        alternatives: Vec::new(),
        region: Region {
            domain: model.domain.clone(),
            input_box: model.input_box.clone(),
            time: Bounds::new(time.lo(), time.hi()),
        },
    }))
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::analysis::time_range;
    use crate::driver::check_source;

    pub(crate) fn model_of(src: &str) -> (Model, Derivatives) {
        let (model, diags) = check_source(src, Path::new("."));
        let mut model = model.unwrap_or_else(|| panic!("spec does not check: {diags:?}"));
        let d = Derivatives::of(&mut model);
        (model, d)
    }

    fn spec(name: &str) -> String {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../specs")
            .join(name);
        std::fs::read_to_string(path).unwrap()
    }

    const PAPER_P: [f64; 4] = [35.68, 2.21, 2.21, 1.27];

    /// The pendulum's reference values (core/tests/data/README.md).
    fn pendulum_reference() -> serde_json::Value {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../core/tests/data/pendulum.json");
        let text = std::fs::read_to_string(&path).unwrap();
        serde_json::from_str(&text).unwrap()
    }

    #[test]
    fn pendulum_paper_metric() {
        let (model, d) = model_of(&spec("pendulum.sde"));
        let k = constants(&model, &d, &PAPER_P).unwrap();
        // Independent check (core/tests/data/pendulum.json): mu_P of the vertices -0.50747,
        // -1.31608; sigma = 0.1 sqrt(1.27) = 0.11269427...
        let reference = pendulum_reference();
        let checked = &reference["checked_independently"];
        let mu = checked["mu_P_of_vertices_with_paper_P"][0]
            .as_f64()
            .unwrap();
        // (The reference is for the decimal P, the model uses its nearest floats: 1e-14.)
        assert!(
            k.c() >= mu - 1e-14 && k.c() < mu + 1e-9,
            "c = {} vs {mu}",
            k.c()
        );
        let exact = checked["sigma_with_paper_P"].as_f64().unwrap();
        assert!(
            k.sigma() >= exact * (1.0 - 1e-14) && k.sigma() < exact * (1.0 + 1e-14),
            "{}",
            k.sigma()
        );
        assert_eq!(k.rho(), 0.0);
        assert!(
            k.provenance().to_string().contains("2 vertex matrices"),
            "{}",
            k.provenance()
        );
    }

    #[test]
    fn linear_is_exact() {
        let (model, d) = model_of(&spec("linear.sde"));
        let k = constants(&model, &d, &[1.0, 0.0, 0.0, 1.0]).unwrap();
        assert_eq!(k.c(), -0.4);
        let s = 2f64.sqrt();
        assert!(
            k.sigma() >= s && (k.sigma() - s) / s <= 1e-15,
            "{}",
            k.sigma()
        );
    }

    #[test]
    fn input_gain_identity() {
        let (model, d) = model_of(
            "model u1\nstate x in [0, 1]\ninput u in [-0.5, 0.5]\n\
             drift {\n x' = -x + 2 * u\n}\n",
        );
        let k = constants(&model, &d, &[1.0]).unwrap();
        assert_eq!(k.rho(), 1.0);
        assert_eq!(k.c(), -1.0);
        assert_eq!(k.sigma(), 0.0);
        // Two inputs: |B diag(h) s|_P over the corners, B = [[1, 1], [0, 3]], h = [1, 0.5].
        let (model, d) = model_of(
            "model u2\nstate x in [0, 1]\nstate y in [0, 1]\ninput u in [-1, 1]\n\
             input v in [0, 1]\ndrift {\n x' = -x + u + v\n y' = -y + 3 * v\n}\n",
        );
        let k = constants(&model, &d, &[1.0, 0.0, 0.0, 1.0]).unwrap();
        // Corners (1, 0.5) -> (1.5, 1.5), (1, -0.5) -> (0.5, -1.5): max norm sqrt(4.5).
        let exact = 4.5f64.sqrt();
        assert!(k.rho() >= exact && k.rho() < exact * (1.0 + 1e-15));
    }

    #[test]
    fn unbounded_names_entry() {
        let (model, d) = model_of("model cubic\nstate x in [0, 1]\ndrift {\n x' = -x^3\n}\n");
        assert_eq!(
            constants(&model, &d, &[1.0]),
            Err(ConstantsError::Unbounded {
                matrix: "D_x f",
                row: 0,
                column: 0
            })
        );
        let (model, d) = model_of(
            "model cubic\nstate x in [0, 1]\ndrift {\n x' = -x^3\n}\n\
             domain {\n x in [-2, 2]\n}\n",
        );
        let k = constants(&model, &d, &[1.0]).unwrap();
        assert_eq!(k.c(), 0.0);
    }

    #[test]
    fn bad_metric() {
        let (model, d) = model_of(&spec("linear.sde"));
        for m in [
            vec![1.0, 0.0, 0.0],
            vec![1.0, 0.5, 0.0, 1.0],
            vec![1.0, 2.0, 2.0, 1.0],
        ] {
            assert!(matches!(
                constants(&model, &d, &m),
                Err(ConstantsError::BadMetric { .. })
            ));
        }
    }

    fn identity(n: usize) -> Vec<f64> {
        let mut id = vec![0.0; n * n];
        for i in 0..n {
            id[i * n + i] = 1.0;
        }
        id
    }

    #[test]
    fn chain_fixes_semidefinite_atoms() {
        let (model, d) = model_of(&spec("chain10.sde"));
        let n = model.states.len();
        let k = constants(&model, &d, &identity(n)).unwrap();
        // Every coupling atom has a negative (or positive) semidefinite symmetric part: all 11
        // are fixed, one vertex remains, and the bound is the exact -a = -2 (the spec's comment;
        // the interval-matrix bound gave -1.017).
        assert!(
            k.provenance()
                .to_string()
                .contains("1 vertex matrix (11 atoms, 11 fixed"),
            "{}",
            k.provenance()
        );
        assert_eq!(k.c(), -2.0);
        let s = 0.05f64;
        assert!(k.sigma() >= s && k.sigma() < s * (1.0 + 1e-14));
        // Without the fixing, the same model falls back to the interval matrix.
        let dec = decompose(&model, &d.jac_x, "D_x f", time_range(&model)).unwrap();
        let set = dec.all_free();
        assert!(matches!(set, MatrixSet::Hull { atoms: 11, .. }));
        let id = identity(n);
        let hull = contraction_rate(&set, &check_metric(&id, n).unwrap(), &id).unwrap();
        eprintln!("chain10 without fixing: c = {hull}");
        assert!(hull > -1.1);
    }

    #[test]
    fn chain1000_is_exact_and_fast() {
        let (model, d) = model_of(&spec("chain1000.sde"));
        let n = model.states.len();
        let start = std::time::Instant::now();
        let k = constants(&model, &d, &identity(n)).unwrap();
        let elapsed = start.elapsed();
        eprintln!("chain1000: c = {}, {elapsed:?}, {}", k.c(), k.provenance());
        assert_eq!(k.c(), -2.0);
        assert!(
            k.provenance().to_string().contains("1 vertex matrix"),
            "{}",
            k.provenance()
        );
        assert!(elapsed.as_secs_f64() < 5.0, "{elapsed:?}");
        // The interval-matrix bound without the fixing, for comparison.
        let t0 = std::time::Instant::now();
        let dec = decompose(&model, &d.jac_x, "D_x f", time_range(&model)).unwrap();
        let t1 = t0.elapsed();
        let id = identity(n);
        let pi = check_metric(&id, n).unwrap();
        let t2 = t0.elapsed();
        let set = jacobian_set(&dec, &pi);
        let t3 = t0.elapsed();
        let _ = contraction_rate(&set, &pi, &id);
        let t4 = t0.elapsed();
        let hull = contraction_rate(&dec.all_free(), &pi, &id);
        let t5 = t0.elapsed();
        eprintln!("chain1000 without fixing: c = {hull:?}; decompose {t1:?} check {t2:?} fix {t3:?} rate {t4:?} hull {t5:?}");
    }

    #[test]
    fn indefinite_atom_stays_free() {
        // The pendulum's cos(theta) enters as [[0, 0], [10, 0]]: indefinite symmetric part.
        let (model, d) = model_of(&spec("pendulum.sde"));
        let dec = decompose(&model, &d.jac_x, "D_x f", time_range(&model)).unwrap();
        let p = IMat::from_f64(2, 2, &PAPER_P);
        assert_eq!(semidefinite_atoms(&dec, &p), vec![None]);
        assert_eq!(
            semidefinite_atoms(&dec, &IMat::from_f64(2, 2, &identity(2))),
            vec![None]
        );
    }

    #[test]
    fn semidefinite_in_metric() {
        // M_1 = [[0, 1], [-1, -1]]: sym(M_1) = diag(0, -1) <= 0 for P = I, but with
        // P = diag(1, 4), (M_1'P + P M_1) / 2 = [[0, -1.5], [-1.5, -4]] is indefinite.
        // M_2 = [[1, 0], [0, 0]] is PSD for every diagonal P.
        let dec = Decomposition {
            base: IMat::from_f64(2, 2, &[-1.0, 0.0, 0.0, -1.0]),
            atoms: vec![
                VaryingAtom {
                    entries: vec![(0, 1, 1.0), (1, 0, -1.0), (1, 1, -1.0)],
                    range: Interval::new(-1.0, 1.0),
                },
                VaryingAtom {
                    entries: vec![(0, 0, 1.0)],
                    range: Interval::new(0.0, 0.5),
                },
            ],
            bounds: IMat::zeros(2, 2),
        };
        let id = IMat::from_f64(2, 2, &identity(2));
        let p = IMat::from_f64(2, 2, &[1.0, 0.0, 0.0, 4.0]);
        assert_eq!(semidefinite_atoms(&dec, &id), vec![Some(false), Some(true)]);
        assert_eq!(semidefinite_atoms(&dec, &p), vec![None, Some(true)]);
        // Fixed at the ends: for P = I one vertex, [[-0.5, -1], [1, 0]] (sym: diag(-0.5, 0)).
        let set = jacobian_set(&dec, &id);
        let MatrixSet::Vertices { vertices, .. } = &set else {
            panic!("{set:?}")
        };
        assert_eq!(vertices.len(), 1);
        assert_eq!(vertices[0].mid(), vec![-0.5, -1.0, 1.0, 0.0]);
        assert_eq!(contraction_rate(&set, &id, &identity(2)).unwrap(), 0.0);
        assert!(matches!(
            jacobian_set(&dec, &p),
            MatrixSet::Vertices { ref vertices, fixed: 1, .. } if vertices.len() == 2
        ));
    }

    /// Float `max_v lambda_max(sym(R A_v R^-1))`, `P = R'R`, for the property test.
    fn float_mu(vertices: &[Vec<f64>], p: &[f64], n: usize) -> f64 {
        let l = nalgebra::Cholesky::new(dmat(n, p)).unwrap().l();
        let r = l.transpose();
        let r_inv = r.clone().try_inverse().unwrap();
        vertices
            .iter()
            .map(|a| {
                let t = &r * dmat(n, a) * &r_inv;
                let s = (&t + t.transpose()) * 0.5;
                SymmetricEigen::new(s).eigenvalues.max()
            })
            .fold(f64::NEG_INFINITY, f64::max)
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(200))]
        #[test]
        fn certified_c_is_tight_and_sound(
            n in 2usize..4,
            seeds in proptest::collection::vec(-3.0f64..3.0, 64),
            nv in 1usize..5,
        ) {
            // Vertices `-2 I + small random`, a random SPD metric `P = M M' + I / 2`.
            let mut it = seeds.iter().cycle().copied();
            let vertices: Vec<Vec<f64>> = (0..nv)
                .map(|_| (0..n * n).map(|k| {
                    let x = it.next().unwrap();
                    if k % (n + 1) == 0 { x - 4.0 } else { x }
                }).collect())
                .collect();
            let m: Vec<f64> = (0..n * n).map(|_| it.next().unwrap() / 2.0).collect();
            let mut p = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    let mut s = if i == j { 0.5 } else { 0.0 };
                    for k in 0..n {
                        s += m[i * n + k] * m[j * n + k];
                    }
                    p[i * n + j] = s;
                }
            }
            for i in 0..n {
                for j in 0..i {
                    p[i * n + j] = p[j * n + i];
                }
            }
            let set = MatrixSet::Vertices {
                vertices: vertices.iter().map(|v| IMat::from_f64(n, n, v)).collect(),
                atoms: 0,
                fixed: 0,
            };
            let pi = check_metric(&p, n).unwrap();
            let c = contraction_rate(&set, &pi, &p).unwrap();
            let truth = float_mu(&vertices, &p, n);
            let scale = truth.abs().max(1.0);
            // Never below the truth (up to the float reference's own error), at most 1e-9 above.
            proptest::prop_assert!(c >= truth - 1e-12 * scale, "c = {c}, truth = {truth}");
            proptest::prop_assert!(c <= truth + 1e-9 * scale, "c = {c}, truth = {truth}");
        }
    }
}
