#!/usr/bin/env python3
"""Side-by-side reference for crate/measure/optimal.rs (issue 25): on each Klipper file,
Klipper's own pick (klipper_reference.best_shaper), the best mainline-Klipper shaper
(family x shaper_freq x damping_ratio, a dense grid) and the best custom shaper (scipy's
Nelder-Mead over all times and amplitudes from the best mainline shapers), all scored by
klipper_reference.py's re-implementation of Klipper's own scoring, under the constraints of
issue 25: own score <= Klipper pick's, own vibrations <= max(pick's, 5 %).

This is an independent computation (numpy/scipy, dense grids, another optimiser's code) of
what the Rust optimiser searches; the Rust results must be at least as good within the
Rust search's resolution.

    python3 benches/reference/optimal_reference.py tests/data/klipper/resonances_*.csv \
        [--json out.json] [--max-impulses 5]
"""
import argparse
import json
import math
import os
import sys
import time

import numpy as np
from scipy.optimize import minimize

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import klipper_reference as kr  # noqa: E402

FAMILY_MAX_DAMPING = {"zv": 0.99, "mzv": 0.99, "zvd": 0.99, "ei": 0.4, "2hump_ei": 0.3,
                      "3hump_ei": 0.2}
CUSTOM_BAND = 0.02


def cut(datasets):
    return [(ds.freqs[ds.freqs <= kr.MAX_FREQ], ds.psd_sum[ds.freqs <= kr.MAX_FREQ])
            for ds in datasets]


def vibrations(shaper, sets, cases):
    worst = 0.0
    for fb, psd in sets:
        for z, s in cases:
            v, _ = kr.remaining_vibrations(shaper, z, fb * s, psd)
            worst = max(worst, v)
    return worst


def score(sm, v):
    return sm * (v ** 1.5 + 0.2 * v + 0.01)


OWN = [(z, 1.0) for z in kr.TEST_DAMPING_RATIOS]


def figures(shaper, sets):
    v = vibrations(shaper, sets, OWN)
    sm = kr.smoothing(shaper)
    return {"vibrs": v, "smoothing": sm, "max_accel": kr.max_accel(shaper, kr.DEFAULT_SCV),
            "score": score(sm, v)}


def best_mainline(sets, bound_score, bound_vibrs, pick):
    """Dense grid: damping_ratio every 0.025 (to the family's maximum, at most 0.4), shaper_freq
    every 0.25 Hz from half to twice Klipper's pick frequency; Klipper's pick included."""
    best = pick
    for name, (make, _fmin) in kr.SHAPERS.items():
        for dr in np.arange(0.0, min(FAMILY_MAX_DAMPING[name], 0.4) + 1e-9, 0.025):
            for f in np.arange(0.5 * pick[2], min(2.0 * pick[2], 200.0), 0.25):
                try:
                    sh = make(f, dr)
                except Exception:
                    continue
                v = vibrations(sh, sets, OWN)
                sm = kr.smoothing(sh)
                sc = score(sm, v)
                if sc <= bound_score and v <= bound_vibrs and (best is None or sc < best[0]):
                    best = (sc, name, f, dr, sh)
    return best


def custom(sets, start, bound_score, bound_vibrs, max_n):
    a0, t0 = np.asarray(start[0], float), np.asarray(start[1], float)
    a0 = a0 / a0.sum()
    n = len(a0)
    if n > max_n:
        return None
    t_ref = t0[-1] / (n - 1)
    x0 = np.concatenate([np.log(np.diff(t0) / t_ref), np.log(a0)])
    cases = [(z, s) for z in kr.TEST_DAMPING_RATIOS for s in (1 - CUSTOM_BAND, 1, 1 + CUSTOM_BAND)]

    def build(x):
        g = np.exp(np.clip(x[:n - 1], -30, 30)) * t_ref
        w = np.exp(x[n - 1:] - x[n - 1:].max())
        return list(w / w.sum()), list(np.concatenate([[0.0], np.cumsum(g)]))

    def obj(x):
        sh = build(x)
        if sh[1][-1] > 0.2 or min(sh[0]) < 0.001:
            return math.inf
        v = vibrations(sh, sets, OWN)
        sm = kr.smoothing(sh)
        if score(sm, v) > bound_score or v > bound_vibrs:
            return math.inf
        return score(sm, vibrations(sh, sets, cases))

    r = minimize(obj, x0, method="Nelder-Mead",
                 options={"maxfev": 3000, "xatol": 1e-6, "fatol": 1e-12, "adaptive": True})
    if not math.isfinite(r.fun):
        return None
    return build(r.x)


def run(path, max_n):
    datasets = kr.parse_file(path)
    sets = cut(datasets)
    t0 = time.time()
    pick, _, _ = kr.best_shaper(datasets)
    t_klipper = time.time() - t0
    pick_sh = kr.SHAPERS[pick.name][0](pick.freq, kr.DEFAULT_DAMPING_RATIO)
    pf = figures(pick_sh, sets)
    bound_score, bound_vibrs = pf["score"], max(pf["vibrs"], 0.05)
    t0 = time.time()
    main = best_mainline(sets, bound_score, bound_vibrs,
                         (bound_score, pick.name, pick.freq, kr.DEFAULT_DAMPING_RATIO, pick_sh))
    mf = figures(main[4], sets)
    cust = custom(sets, main[4], mf["score"], bound_vibrs, max_n)
    cf = figures(cust, sets) if cust else mf
    t_ours = time.time() - t0
    return {
        "file": os.path.basename(path),
        "klipper": dict(pf, name=pick.name, freq=pick.freq),
        "mainline": dict(mf, name=main[1], freq=main[2], damping_ratio=main[3]),
        "custom": dict(cf, impulses=len(cust[0]) if cust else None),
        "seconds": {"klipper": t_klipper, "optimal": t_ours},
    }


def main():
    p = argparse.ArgumentParser()
    p.add_argument("files", nargs="+")
    p.add_argument("--json")
    p.add_argument("--max-impulses", type=int, default=5)
    a = p.parse_args()
    rows = []
    for path in a.files:
        r = run(path, a.max_impulses)
        rows.append(r)
        k, m, c = r["klipper"], r["mainline"], r["custom"]
        print("%-34s klipper %-8s %6.1f Hz s=%.5f v=%.2f%% sm=%.4f | mainline %-8s %6.2f Hz "
              "dr=%.2f s=%.5f (%+.1f%%) v=%.2f%% | custom s=%.5f (%+.1f%%) v=%.2f%% sm=%.4f"
              % (r["file"], k["name"], k["freq"], k["score"], 100 * k["vibrs"], k["smoothing"],
                 m["name"], m["freq"], m["damping_ratio"], m["score"],
                 100 * (m["score"] / k["score"] - 1), 100 * m["vibrs"], c["score"],
                 100 * (c["score"] / k["score"] - 1), 100 * c["vibrs"], c["smoothing"]),
              flush=True)
    imp_m = [1 - r["mainline"]["score"] / r["klipper"]["score"] for r in rows]
    imp_c = [1 - r["custom"]["score"] / r["klipper"]["score"] for r in rows]
    print("median improvement: mainline %.1f %%, custom %.1f %%"
          % (100 * np.median(imp_m), 100 * np.median(imp_c)))
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main()
