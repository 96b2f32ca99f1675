"""Reference numbers for tests/sampled.rs (Kamel, Lange & Hirzinger), computed independently of
the Rust code: the cost matrices by brute-force trapezoid quadrature of the error signal (no
closed form), the optimum by eq. 25 with explicit inverses, the bounded optimum by scipy's SLSQP.

Run: python3 benches/reference/kamel_sampled.py   (numpy, scipy)
"""
import numpy as np
from scipy.optimize import minimize

w0, D, K, T, n, m, qw = 30.0, 0.02, 8e-4, 0.012, 36, 17, 0.1
sig, wd = w0 * D, w0 * np.sqrt(1 - D * D)
t = np.arange(n) * T


def g(x):
    return np.where(x > 0, K * w0 / np.sqrt(1 - D * D) * np.exp(-sig * x) * np.sin(wd * x), 0.0)


def gd(x):
    return np.where(x >= 0, K * w0 / np.sqrt(1 - D * D) * np.exp(-sig * x)
                    * (wd * np.cos(wd * x) - sig * np.sin(wd * x)), 0.0)


def constraints(m, delay=True):
    e = np.exp(sig * t)
    rows = [e * np.cos(wd * t), e * np.sin(wd * t), np.ones(n),
            t * e * np.cos(wd * t), t * e * np.sin(wd * t)]
    b = [0, 0, 1, 0, 0]
    if delay:
        rows.append(t)
        b.append(m * T - 2 * D / w0)
    return np.array(rows), np.array(b, float)


N = 400000
tt = np.linspace(0, (n - 1) * T, N + 1)
B = np.array([(tt >= i * T).astype(float) + gd(tt - i * T) for i in range(n)])
wts = np.full(N + 1, (n - 1) * T / N)
wts[0] /= 2
wts[-1] /= 2
Psi = (B * wts) @ B.T


def theta(m):
    return (B * wts) @ (tt >= m * T).astype(float)


def cost(A, m, Q):
    return A @ (Psi + Q) @ A - 2 * A @ theta(m) + (n - m - 1) * T


def eq25(m, Q):
    C, b = constraints(m)
    Pt = Psi + Q
    P = np.linalg.inv(Pt + Pt.T)
    th = theta(m)
    return P @ (2 * th - C.T @ np.linalg.solve(C @ P @ C.T, 2 * C @ P @ th - b))


Q = qw * np.eye(n)
for mm in (17, 0):
    C, b = constraints(mm)
    A = eq25(mm, Q)
    Amn = np.linalg.pinv(C) @ b
    print(f"m={mm}: J_opt={cost(A, mm, Q):.6f} J_minnorm={cost(Amn, mm, Q):.6f} "
          f"reduction={1 - cost(A, mm, Q) / cost(Amn, mm, Q):.4f} "
          f"int_e2_opt={cost(A, mm, 0 * Q):.6f} int_e2_minnorm={cost(Amn, mm, 0 * Q):.6f}")

# Bounded: 0 <= A_i <= 0.1, |A_i - A_{i-1}| <= 0.02, m = 17.
C, b = constraints(17)
cons = [{"type": "eq", "fun": lambda A: C @ A - b, "jac": lambda A: C},
        {"type": "ineq", "fun": lambda A: 0.02 - np.diff(A)},
        {"type": "ineq", "fun": lambda A: 0.02 + np.diff(A)}]
res = minimize(lambda A: cost(A, 17, Q), np.full(n, 1 / n),
               jac=lambda A: 2 * (Psi + Q) @ A - 2 * theta(17),
               bounds=[(0, 0.1)] * n, constraints=cons, method="SLSQP",
               options={"ftol": 1e-14, "maxiter": 1000})
print(f"bounded m=17: J={res.fun:.6f} success={res.success} max A={res.x.max():.4f} "
      f"min A={res.x.min():.2e} first={res.x[:3]}")
