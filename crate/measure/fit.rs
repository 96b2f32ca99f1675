//! Levenberg–Marquardt least squares with a forward-difference Jacobian: the small nonlinear
//! fits of mode identification (a few parameters, thousands of residuals).

use nalgebra::{DMatrix, DVector};

/// Outcome of a fit.
#[derive(Debug, Clone)]
pub(crate) struct FitResult {
    /// The parameters at the minimum.
    pub x: Vec<f64>,
    /// Sum of squared residuals there.
    pub rss: f64,
    /// Number of residuals.
    pub residuals: usize,
    /// (JᵀJ)⁻¹ at the minimum (None if singular): times rss/(m − p) it is the covariance.
    pub inverse_normal: Option<DMatrix<f64>>,
}

impl FitResult {
    /// Standard deviation of parameter `i` from s²(JᵀJ)⁻¹, s² = rss/(m − p).
    pub fn sigma(&self, i: usize) -> Option<f64> {
        let dof = self
            .residuals
            .checked_sub(self.x.len())
            .filter(|d| *d > 0)?;
        let s2 = self.rss / dof as f64;
        let c = self.inverse_normal.as_ref()?;
        let v = c[(i, i)] * s2;
        (v.is_finite() && v >= 0.0).then(|| v.sqrt())
    }
    /// Covariance of parameters `i`, `j`.
    pub fn covariance(&self, i: usize, j: usize) -> Option<f64> {
        let dof = self
            .residuals
            .checked_sub(self.x.len())
            .filter(|d| *d > 0)?;
        let c = self.inverse_normal.as_ref()?;
        let v = c[(i, j)] * self.rss / dof as f64;
        v.is_finite().then_some(v)
    }
}

/// Minimises Σ rᵢ(x)² from `x0`. `residuals(x, out)` fills `out` (always the same length) and
/// returns false where the model is undefined (the step is then rejected). `steps[i]` is the
/// finite-difference step of parameter i.
pub(crate) fn levenberg_marquardt<F>(
    mut residuals: F,
    x0: &[f64],
    steps: &[f64],
    max_iterations: usize,
) -> Option<FitResult>
where
    F: FnMut(&[f64], &mut Vec<f64>) -> bool,
{
    let p = x0.len();
    let mut x = x0.to_vec();
    let mut r = Vec::new();
    if !residuals(&x, &mut r) || r.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let m = r.len();
    if m < p {
        return None;
    }
    let mut rss: f64 = r.iter().map(|v| v * v).sum();
    let mut lambda = 1e-3;
    let mut jac = DMatrix::<f64>::zeros(m, p);
    let mut trial = Vec::with_capacity(m);
    let mut xt = x.clone();
    let jacobian = |x: &[f64], r: &[f64], jac: &mut DMatrix<f64>, f: &mut F, buf: &mut Vec<f64>| {
        let mut xs = x.to_vec();
        for i in 0..p {
            let h = steps[i];
            xs[i] = x[i] + h;
            let ok = f(&xs, buf);
            xs[i] = x[i];
            for k in 0..m {
                jac[(k, i)] = if ok { (buf[k] - r[k]) / h } else { 0.0 };
            }
        }
    };
    jacobian(&x, &r, &mut jac, &mut residuals, &mut trial);
    for _ in 0..max_iterations {
        let jt = jac.transpose();
        let a = &jt * &jac;
        let g = &jt * DVector::from_column_slice(&r);
        let mut improved = false;
        for _ in 0..12 {
            let mut damped = a.clone();
            for i in 0..p {
                damped[(i, i)] += lambda * a[(i, i)].max(1e-12);
            }
            let Some(chol) = damped.cholesky() else {
                lambda *= 10.0;
                continue;
            };
            let dx = chol.solve(&(-&g));
            for i in 0..p {
                xt[i] = x[i] + dx[i];
            }
            if residuals(&xt, &mut trial) && trial.iter().all(|v| v.is_finite()) {
                let rt: f64 = trial.iter().map(|v| v * v).sum();
                if rt < rss {
                    let gain = (rss - rt) / rss.max(1e-300);
                    x.copy_from_slice(&xt);
                    std::mem::swap(&mut r, &mut trial);
                    rss = rt;
                    lambda = (lambda * 0.3).max(1e-12);
                    improved = gain > 1e-10;
                    break;
                }
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
        jacobian(&x, &r, &mut jac, &mut residuals, &mut trial);
    }
    // A parameter the residuals do not depend on (a floor far below the data) would make JᵀJ
    // singular; a relative ridge of 10⁻¹² gives it a huge variance and leaves the others.
    let mut a = jac.transpose() * &jac;
    let top = (0..p).map(|i| a[(i, i)]).fold(0.0, f64::max);
    for i in 0..p {
        a[(i, i)] += 1e-12 * top.max(1e-300);
    }
    let inverse_normal = a.try_inverse();
    Some(FitResult {
        x,
        rss,
        residuals: m,
        inverse_normal,
    })
}
