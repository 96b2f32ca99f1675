#!/usr/bin/env python3
"""Reference for benches/si.rs: the same specified-insensitivity (SI) shaper designed the
classic way, with scipy.optimize's SLSQP from several random starts (best feasible result kept).

Problem (Pelaez & Singhose 2002 eq. 6-7; Singhose 2009 eq. 18): mode 0.5 Hz, zeta = 0.002,
Vtol = 5 %, insensitivity I = 0.7, i.e. V <= Vtol at six evenly spaced frequencies of the band
[0.325, 0.675] Hz; amplitudes >= 0 summing to 1; minimise the time of the last impulse.
The number of impulses must be fixed in advance (SLSQP optimises times and amplitudes of a
given count); it is run with 4 and 5 impulses.

Constraints and objective are vectorised with analytic Jacobians, so this is a fair, not a
strawman, baseline. Usage: python3 benches/si_slsqp.py [starts] [seed]
Prints, per impulse count: best duration, the shaper, and wall time for all starts.
"""
import sys
import time

import numpy as np
from scipy.optimize import minimize

F_HZ, ZETA, VTOL, INSENS = 0.5, 0.002, 0.05, 0.7
SAMPLES_HZ = np.linspace(F_HZ * (1 - INSENS / 2), F_HZ * (1 + INSENS / 2), 6)
W = 2 * np.pi * SAMPLES_HZ
WD = W * np.sqrt(1 - ZETA**2)


def unpack(x, n):
    t = np.concatenate([[0.0], x[: n - 1]])
    return t, x[n - 1 :]


def vib2(x, n):
    """V^2 at every sample (Singhose 2009 eq. 11) and its Jacobian w.r.t. x."""
    t, a = unpack(x, n)
    tn = t[-1]
    e = np.exp(-ZETA * np.outer(W, tn - t))  # (m, n)
    c = np.cos(np.outer(WD, t))
    s = np.sin(np.outer(WD, t))
    C = (a * e * c).sum(1)
    S = (a * e * s).sum(1)
    v2 = C * C + S * S
    # d/da_i
    dv_da = 2 * (C[:, None] * e * c + S[:, None] * e * s)
    # d/dt_i (i >= 1), including t_n's effect on every decay factor
    dC_dt = a * e * (ZETA * W[:, None] * c - WD[:, None] * s)
    dS_dt = a * e * (ZETA * W[:, None] * s + WD[:, None] * c)
    dv_dt = 2 * (C[:, None] * dC_dt + S[:, None] * dS_dt)
    dv_dt[:, -1] += -2 * ZETA * W * v2  # d/dt_n of e^{-zeta w t_n}^2
    return v2, np.hstack([dv_dt[:, 1:], dv_da])


def design(n, starts, rng):
    best = None
    cons = [
        {"type": "eq", "fun": lambda x: np.sum(x[n - 1 :]) - 1,
         "jac": lambda x: np.concatenate([np.zeros(n - 1), np.ones(n)])},
        {"type": "ineq", "fun": lambda x: VTOL**2 - vib2(x, n)[0],
         "jac": lambda x: -vib2(x, n)[1]},
        {"type": "ineq", "fun": lambda x: np.diff(unpack(x, n)[0]),
         "jac": lambda x: np.hstack([np.eye(n - 1) - np.eye(n - 1, k=-1), np.zeros((n - 1, n))])},
    ]
    grad = np.zeros(2 * n - 1)
    grad[n - 2] = 1.0
    for _ in range(starts):
        t_end = rng.uniform(0.5, 2.5) / F_HZ
        t0 = np.sort(rng.uniform(0, t_end, n - 1))
        t0[-1] = t_end
        a0 = rng.uniform(0.1, 1, n)
        a0 /= a0.sum()
        r = minimize(lambda x: x[n - 2], np.concatenate([t0, a0]), jac=lambda x: grad,
                     method="SLSQP", constraints=cons,
                     bounds=[(0, 10 / F_HZ)] * (n - 1) + [(0, 1)] * n,
                     options={"maxiter": 300, "ftol": 1e-12})
        feasible = r.success and np.all(vib2(r.x, n)[0] <= VTOL**2 * (1 + 1e-6))
        if feasible and (best is None or r.x[n - 2] < best[n - 2]):
            best = r.x
    return best


def main():
    starts = int(sys.argv[1]) if len(sys.argv) > 1 else 10
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 0
    print(f"SI by SLSQP: {F_HZ} Hz, zeta {ZETA}, Vtol {VTOL}, I {INSENS}, "
          f"samples {np.round(SAMPLES_HZ, 4).tolist()} Hz, {starts} random starts")
    for n in (4, 5):
        rng = np.random.default_rng(seed)
        t = time.perf_counter()
        x = design(n, starts, rng)
        dt = time.perf_counter() - t
        if x is None:
            print(f"{n} impulses: no feasible start ({dt * 1e3:.1f} ms)")
            continue
        ts, a = unpack(x, n)
        print(f"{n} impulses: duration {ts[-1]:.6f} s in {dt * 1e3:.1f} ms "
              f"({dt / starts * 1e3:.2f} ms per start)")
        print("   t =", np.round(ts, 5).tolist())
        print("   A =", np.round(a, 5).tolist())


if __name__ == "__main__":
    main()
