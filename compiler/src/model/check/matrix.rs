//! Small dense-matrix checks for user-given matrices (metrics, transforms).

/// Why a matrix was rejected.
#[derive(Debug, PartialEq)]
pub(crate) enum MatrixError {
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

/// `m` scaled by a power of two (so exactly, short of subnormal entries) to a largest entry in
/// `[1, 2)` in absolute value. An analysis metric's rates and sets do not change when it is
/// scaled, but its factorisations overflow near 1e300 (and underflow near 1e-300): both the
/// compiler and the run factorise the metric the checker returns, so this is the one place.
pub(crate) fn normalised(mut m: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
    let max = max_abs(&m);
    if !(max.is_finite() && max > 0.0) {
        return m; // rejected by the checks that follow
    }
    let k = max.log2().floor() as i32;
    // Two factors, each a normal float, as 2^-k alone overflows for subnormal maxima.
    let (a, b) = (2f64.powi(-(k / 2)), 2f64.powi(-(k - k / 2)));
    for v in m.iter_mut().flatten() {
        *v = *v * a * b;
    }
    m
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

/// The inverse of a square matrix by Gauss-Jordan elimination with partial pivoting, rejecting
/// pivots below `n * 1e-12` relative to the largest entry (so nearly singular matrices too).
pub(crate) fn inverse(m: &[Vec<f64>]) -> Result<Vec<Vec<f64>>, MatrixError> {
    let n = m.len();
    let scale = max_abs(m);
    // [A | I] reduced to [I | A^-1].
    let mut a: Vec<Vec<f64>> = m
        .iter()
        .enumerate()
        .map(|(i, row)| {
            let mut r = row.clone();
            r.extend((0..n).map(|j| if i == j { 1.0 } else { 0.0 }));
            r
        })
        .collect();
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))
            .unwrap_or(col);
        let p = a[pivot][col].abs();
        if p.is_nan() || p <= n as f64 * 1e-12 * scale {
            return Err(MatrixError::Singular);
        }
        a.swap(col, pivot);
        let d = a[col][col];
        for v in &mut a[col] {
            *v /= d;
        }
        let pivot_row = a[col].clone();
        for (r, row) in a.iter_mut().enumerate() {
            if r != col && row[col] != 0.0 {
                let factor = row[col];
                for (x, p) in row.iter_mut().zip(&pivot_row) {
                    *x -= factor * p;
                }
            }
        }
    }
    let inv: Vec<Vec<f64>> = a.into_iter().map(|row| row[n..].to_vec()).collect();
    // Far inside the floating-point range, so the exact inverse (which the pivot bound keeps
    // within a small relative distance of this one) is finite too (analysis/transform.rs).
    if inv.iter().flatten().any(|v| v.is_nan() || v.abs() > 1e300) {
        return Err(MatrixError::Singular);
    }
    Ok(inv)
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
        // The paper's pendulum transform: T^-1 = [[0, 1], [5, -5]].
        let inv = inverse(&[vec![1.0, 0.2], vec![1.0, 0.0]]).unwrap();
        let expected = [[0.0, 1.0], [5.0, -5.0]];
        for (row, want) in inv.iter().zip(expected) {
            for (v, w) in row.iter().zip(want) {
                assert!((v - w).abs() <= 1e-14, "{inv:?}");
            }
        }
        // Row swaps (a zero first pivot) and a 3 x 3 case: A A^-1 = I.
        let a = vec![
            vec![0.0, 2.0, 1.0],
            vec![1.0, 1.0, 0.0],
            vec![3.0, 0.0, 4.0],
        ];
        let b = inverse(&a).unwrap();
        for (i, row) in a.iter().enumerate() {
            for j in 0..3 {
                let v: f64 = row.iter().zip(&b).map(|(x, b_row)| x * b_row[j]).sum();
                assert!((v - f64::from(u8::from(i == j))).abs() <= 1e-14);
            }
        }
        assert_eq!(
            inverse(&[vec![1.0, 2.0], vec![2.0, 4.0]]),
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
