#!/usr/bin/env python3
"""Exploration for issue 25: how low can Klipper's score go with a custom impulse sequence?

For fixed impulse times on a grid over [0, T] (the last one used, A_N >= 0.001) and a fixed
centroid c, Klipper's smoothing is the maximum of two linear functions of the amplitudes and
its remaining vibration R is a sum of hinges of |W A| (convex); |z| <= r is imposed on a
16-sided inner polygon (so the true |z| is at most r). Minimising the smoothing subject to
R <= rho is then a linear program (scipy's HiGHS). Sweeping T, c/T and rho and scoring every
solution by klipper_reference.py gives the global optimum on each grid, to compare with the
local Nelder-Mead of optimal_reference.py.

    python3 benches/reference/optimal_lp.py tests/data/klipper/resonances_y_m1.csv
"""
import math
import os
import sys

import numpy as np
from scipy.optimize import linprog

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import klipper_reference as kr  # noqa: E402
import optimal_reference as opt  # noqa: E402

DIRS = 16
LAST_MIN = float(os.environ.get("LAST_MIN", "0.001"))
ACCEL, SCV = 5000.0, kr.DEFAULT_SCV


def program(sets, T, c, rho, n=40, factors=(1.0,)):
    t = np.linspace(0.0, T, n + 1)
    nv = n + 1
    rows, rhs = [], []
    hinge_blocks = []
    for fb, psd in sets:
        thr = psd.max() / kr.SHAPER_VIBRATION_REDUCTION
        sel = psd > thr
        f_k, p_k = fb[sel], psd[sel]
        total = np.maximum(psd - thr, 0).sum()
        for z in kr.TEST_DAMPING_RATIOS:
            for s in factors:
                w = 2 * math.pi * f_k * s
                wd = w * math.sqrt(1 - z * z)
                W = np.exp(-z * np.outer(w, T - t)) * np.exp(1j * np.outer(wd, t))
                hinge_blocks.append((W, p_k, thr, total))
    nu = sum(b[0].shape[0] for b in hinge_blocks)
    # variables: A (nv), u (nu), s (1)
    nvar = nv + nu + 1
    cos_m = math.cos(math.pi / DIRS)
    off = nv
    A_ub, b_ub = [], []
    for W, p_k, thr, total in hinge_blocks:
        K = W.shape[0]
        for m in range(DIRS):
            th = 2 * math.pi * m / DIRS
            proj = (W * np.exp(-1j * th)).real  # K x nv
            blk = np.zeros((K, nvar))
            blk[:, :nv] = p_k[:, None] * proj / cos_m
            blk[np.arange(K), off + np.arange(K)] = -1.0
            A_ub.append(blk)
            b_ub.append(np.full(K, thr))
        row = np.zeros(nvar)
        row[off:off + K] = 1.0 / total
        A_ub.append(row[None, :])
        b_ub.append([rho])
        off += K
    # smoothing epigraphs
    half = 0.5 * ACCEL
    o180 = np.zeros(nvar)
    o180[:nv] = half * (t - c) ** 2
    o180[-1] = -1.0
    o90 = np.zeros(nvar)
    after = t >= c
    o90[:nv][after] = math.sqrt(2) * (SCV + half * (t[after] - c)) * (t[after] - c)
    o90[-1] = -1.0
    A_ub += [o180[None, :], o90[None, :]]
    b_ub += [[0.0], [0.0]]
    A_eq = np.zeros((2, nvar))
    A_eq[0, :nv] = 1.0
    A_eq[1, :nv] = t
    b_eq = [1.0, c]
    bounds = [(0, None)] * nv + [(0, None)] * nu + [(0, None)]
    bounds[nv - 1] = (LAST_MIN, None)
    cost = np.zeros(nvar)
    cost[-1] = 1.0
    r = linprog(cost, A_ub=np.vstack(A_ub), b_ub=np.concatenate(b_ub), A_eq=A_eq, b_eq=b_eq,
                bounds=bounds, method="highs")
    if r.status != 0:
        return None
    a = r.x[:nv]
    keep = a > 1e-6
    return list(a[keep] / a[keep].sum()), list(t[keep])


def explore(path):
    datasets = kr.parse_file(path)
    sets = opt.cut(datasets)
    pick, _, _ = kr.best_shaper(datasets)
    pick_sh = kr.SHAPERS[pick.name][0](pick.freq, kr.DEFAULT_DAMPING_RATIO)
    pf = opt.figures(pick_sh, sets)
    T0 = pick_sh[1][-1]
    best = None
    for T in T0 * np.linspace(0.6, 1.4, 9):
        for ratio in (0.42, 0.46, 0.5):
            for rho in (0.0, 0.003, 0.01):
                sh = program(sets, T, ratio * T, rho)
                if sh is None:
                    continue
                f = opt.figures(sh, sets)
                if f["vibrs"] <= max(pf["vibrs"], 0.05) and (best is None or f["score"] < best[0]["score"]):
                    best = (f, T, ratio, rho, len(sh[0]), sh)
    print("%-30s klipper %s %.1f s=%.5f sm=%.4f v=%.2f%% | LP s=%.5f (%+.1f%%) sm=%.4f v=%.2f%% "
          "T/T0=%.2f c/T=%.2f rho=%.3f n=%d"
          % (os.path.basename(path), pick.name, pick.freq, pf["score"], pf["smoothing"],
             100 * pf["vibrs"], best[0]["score"], 100 * (best[0]["score"] / pf["score"] - 1),
             best[0]["smoothing"], 100 * best[0]["vibrs"], best[1] / T0, best[2], best[3],
             best[4]), flush=True)
    return best


if __name__ == "__main__":
    for p in sys.argv[1:]:
        explore(p)
