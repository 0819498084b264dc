//! The set of matrices a model's `D_x f`, `G` or `D_u f` ranges over: the atom split
//! `M = M0 + sum_k a_k M_k` over the domain, its `2^K` vertices or interval hull, and the atoms
//! whose symmetric part is semidefinite in the metric fixed at an end.

use reachc_core::interval::Interval;
use reachc_core::model::MatrixBound;

use super::{ConstantsError, MAX_VERTEX_ATOMS};
use crate::analysis::psd::{is_psd, is_zero, IMat};
use crate::analysis::{bound_matrix, eval_box, split_atoms};
use crate::ir::ExprId;
use crate::model::Model;

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
    pub(super) fn bound(&self) -> MatrixBound {
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

#[cfg(test)]
mod tests {
    use super::super::fixtures::{identity, model_of, spec, PAPER_P};
    use super::super::{check_metric, constants, contraction_rate};
    use super::*;
    use crate::analysis::time_range;

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
}
