//! Small dense-matrix checks for user-given matrices (metrics, transforms).

/// Why a matrix was rejected.
#[derive(Debug, PartialEq)]
pub(super) enum MatrixError {
    NotSquare {
        rows: usize,
        bad_row: usize,
        len: usize,
    },
    WrongSize {
        expected: usize,
        got: usize,
    },
    NotSymmetric {
        i: usize,
        j: usize,
    },
    NotPositiveDefinite,
    Singular,
}

impl std::fmt::Display for MatrixError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MatrixError::NotSquare { rows, bad_row, len } => write!(
                f,
                "the matrix is not square: it has {rows} rows but row {} has {len} entries",
                bad_row + 1
            ),
            MatrixError::WrongSize { expected, got } => write!(
                f,
                "the matrix must be {expected} x {expected} (one row and column per state), not {got} x {got}"
            ),
            MatrixError::NotSymmetric { i, j } => write!(
                f,
                "the matrix is not symmetric: entries ({}, {}) and ({}, {}) differ",
                i + 1,
                j + 1,
                j + 1,
                i + 1
            ),
            MatrixError::NotPositiveDefinite => write!(f, "the matrix is not positive definite"),
            MatrixError::Singular => write!(f, "the matrix is singular (not invertible)"),
        }
    }
}

/// Checks that `m` is square with `n` rows.
pub(super) fn check_square(m: &[Vec<f64>], n: usize) -> Result<(), MatrixError> {
    if let Some((bad_row, row)) = m.iter().enumerate().find(|(_, r)| r.len() != m.len()) {
        return Err(MatrixError::NotSquare {
            rows: m.len(),
            bad_row,
            len: row.len(),
        });
    }
    if m.len() != n {
        return Err(MatrixError::WrongSize {
            expected: n,
            got: m.len(),
        });
    }
    Ok(())
}

fn max_abs(m: &[Vec<f64>]) -> f64 {
    m.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()))
}

/// Checks symmetry (to a relative 1e-12) and positive definiteness (a Cholesky factorisation
/// with pivots above a relative 1e-12, so nearly singular metrics are rejected too).
pub(super) fn check_spd(m: &[Vec<f64>]) -> Result<(), MatrixError> {
    let n = m.len();
    let scale = max_abs(m);
    for (i, row) in m.iter().enumerate() {
        for (j, v) in row.iter().enumerate().take(i) {
            if (v - m[j][i]).abs() > 1e-12 * scale {
                return Err(MatrixError::NotSymmetric { i, j });
            }
        }
    }
    let mut l = vec![vec![0.0; n]; n];
    for j in 0..n {
        let d = m[j][j] - (0..j).map(|k| l[j][k] * l[j][k]).sum::<f64>();
        if d.is_nan() || d <= 1e-12 * scale {
            return Err(MatrixError::NotPositiveDefinite);
        }
        l[j][j] = d.sqrt();
        for i in j + 1..n {
            let s = m[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            l[i][j] = s / l[j][j];
        }
    }
    Ok(())
}

/// Checks that a square matrix is invertible: Gaussian elimination with partial pivoting,
/// rejecting pivots below `n * 1e-12` relative to the largest entry.
pub(super) fn check_nonsingular(m: &[Vec<f64>]) -> Result<(), MatrixError> {
    let n = m.len();
    let scale = max_abs(m);
    let mut a = m.to_vec();
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))
            .unwrap_or(col);
        let p = a[pivot][col].abs();
        if p.is_nan() || p <= n as f64 * 1e-12 * scale {
            return Err(MatrixError::Singular);
        }
        a.swap(col, pivot);
        let (top, bottom) = a.split_at_mut(col + 1);
        let pivot_row = &top[col];
        for row in bottom {
            let factor = row[col] / pivot_row[col];
            for (x, p) in row[col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= factor * p;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spd() {
        assert_eq!(check_spd(&[vec![2.0, 1.0], vec![1.0, 2.0]]), Ok(()));
        assert_eq!(
            check_spd(&[vec![1.0, 2.0], vec![2.0, 1.0]]),
            Err(MatrixError::NotPositiveDefinite)
        );
        assert_eq!(
            check_spd(&[vec![1.0, 0.5], vec![0.0, 1.0]]),
            Err(MatrixError::NotSymmetric { i: 1, j: 0 })
        );
        // The paper's pendulum metric.
        assert_eq!(check_spd(&[vec![35.68, 2.21], vec![2.21, 1.27]]), Ok(()));
    }

    #[test]
    fn singular() {
        assert_eq!(check_nonsingular(&[vec![1.0, 0.2], vec![1.0, 0.0]]), Ok(()));
        assert_eq!(
            check_nonsingular(&[vec![1.0, 2.0], vec![2.0, 4.0]]),
            Err(MatrixError::Singular)
        );
        assert_eq!(
            check_square(&[vec![1.0, 2.0], vec![2.0]], 2),
            Err(MatrixError::NotSquare {
                rows: 2,
                bad_row: 1,
                len: 1
            })
        );
        assert_eq!(
            check_square(&[vec![1.0]], 2),
            Err(MatrixError::WrongSize {
                expected: 2,
                got: 1
            })
        );
    }
}
