//! Non-negative least squares in normal-equation (Gram) form:
//! minimize `½ aᵀ A a − bᵀ a` subject to `a ≥ 0`, A symmetric positive semi-definite.
//!
//! Lawson & Hanson's active-set method (Solving Least Squares Problems, 1974, ch. 23) in the
//! Gram form of Bro & de Jong (1997). It is exact and finite; the sub-solves use nalgebra's
//! Cholesky with a tiny ridge, so two coincident lobes (a singular A) cannot break it.

use nalgebra::{DMatrix, DVector};

/// Returns the minimizer `a ≥ 0`. `a` has `b.len()` entries; A is `n × n` row-major.
pub fn solve(a_mat: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let n = b.len();
    let mut x = DVector::zeros(n);
    let mut passive = vec![false; n];
    let scale = b.amax().max(1e-300);
    let tol = 1e-12 * scale;
    let ridge = 1e-12
        * (0..n)
            .map(|i| a_mat[(i, i)])
            .fold(0.0, f64::max)
            .max(1e-300);
    let mut w = b - a_mat * &x;
    for _outer in 0..3 * n + 3 {
        // The most violated dual constraint among the active (zero) variables.
        let candidate = (0..n)
            .filter(|&j| !passive[j] && w[j] > tol)
            .max_by(|&i, &j| w[i].total_cmp(&w[j]));
        let Some(j) = candidate else { break };
        passive[j] = true;
        for _inner in 0..3 * n + 3 {
            let s = solve_passive(a_mat, b, &passive, ridge);
            if (0..n).all(|i| !passive[i] || s[i] > 0.0) {
                x = s;
                break;
            }
            // Step from x toward s until the first passive variable hits zero.
            let alpha = (0..n)
                .filter(|&i| passive[i] && s[i] <= 0.0)
                .map(|i| x[i] / (x[i] - s[i]))
                .fold(f64::INFINITY, f64::min);
            x += (s - &x) * alpha;
            for i in 0..n {
                if passive[i] && x[i] <= 1e-15 * scale {
                    passive[i] = false;
                    x[i] = 0.0;
                }
            }
        }
        w = b - a_mat * &x;
    }
    x.iter_mut().for_each(|v| *v = v.max(0.0));
    x
}

/// Solves `A_PP s_P = b_P` with zeros outside the passive set P.
fn solve_passive(
    a_mat: &DMatrix<f64>,
    b: &DVector<f64>,
    passive: &[bool],
    ridge: f64,
) -> DVector<f64> {
    let idx: Vec<usize> = (0..b.len()).filter(|&i| passive[i]).collect();
    let m = idx.len();
    let sub = DMatrix::from_fn(m, m, |r, c| {
        a_mat[(idx[r], idx[c])] + if r == c { ridge } else { 0.0 }
    });
    let rhs = DVector::from_fn(m, |r, _| b[idx[r]]);
    let sol = match sub.clone().cholesky() {
        Some(ch) => ch.solve(&rhs),
        // Not numerically positive definite: fall back to a pseudo-inverse solve.
        None => sub
            .svd(true, true)
            .solve(&rhs, 1e-14)
            .unwrap_or_else(|_| DVector::zeros(m)),
    };
    let mut s = DVector::zeros(b.len());
    for (r, &i) in idx.iter().enumerate() {
        s[i] = sol[r];
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: the best over all 2ⁿ supports of the unconstrained solve restricted to
    /// the support, keeping only feasible ones.
    fn brute_force(a: &DMatrix<f64>, b: &DVector<f64>) -> f64 {
        let n = b.len();
        let obj = |x: &DVector<f64>| 0.5 * x.dot(&(a * x)) - b.dot(x);
        let mut best = 0.0;
        for mask in 1u32..(1 << n) {
            let passive: Vec<bool> = (0..n).map(|i| mask & (1 << i) != 0).collect();
            let s = solve_passive(a, b, &passive, 0.0);
            if s.iter().all(|&v| v >= 0.0) {
                best = f64::min(best, obj(&s));
            }
        }
        best
    }

    #[test]
    fn matches_brute_force_on_small_problems() {
        // A Gram matrix of random-ish vectors, several right-hand sides of mixed sign.
        let g = DMatrix::from_fn(9, 5, |r, c| {
            (((r * 131 + c * 71 + 7) as f64).sin() * 1000.0).fract()
        });
        let a = g.transpose() * &g;
        for seed in 0..6 {
            let b = DVector::from_fn(5, |r, _| ((r + seed * 5) as f64 * 1.3).cos());
            let x = solve(&a, &b);
            let got = 0.5 * x.dot(&(&a * &x)) - b.dot(&x);
            let want = brute_force(&a, &b);
            eprintln!("nnls seed {seed}: {got:.12} vs brute force {want:.12}");
            assert!(x.iter().all(|&v| v >= 0.0));
            assert!(
                (got - want).abs() < 1e-9 * (1.0 + want.abs()),
                "{got} vs {want}"
            );
        }
    }
}
