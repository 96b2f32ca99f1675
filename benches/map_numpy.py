#!/usr/bin/env python3
"""The numpy baseline for benches/analysis.rs, and the comparison line `npm run bench` prints.

Reads what the Rust bench wrote (target/bench/map.json: the 9-impulse shaper, the options and
our values of the 400 x 200 frequency x damping map and of a 1000-point sensitivity curve),
recomputes both with vectorised numpy straight from Singhose 2009 eq. 11
    V = e^{-zeta w t_n} sqrt(C^2 + S^2),  C, S = sum A_i e^{zeta w t_i} (cos, sin)(w_d t_i),
checks that they agree with ours to 1e-9, times numpy, and reads criterion's timing of ours
(target/criterion/<benchmark>/new/estimates.json) to print how many times faster Rust is.

Usage: python3 benches/map_numpy.py   (after `cargo bench --bench analysis`)
"""
import json
import os
import statistics
import sys
import time

import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
TARGET = os.path.join(ROOT, "target")
REPEATS = 30
TOLERANCE = 1e-9


def map_real(t, a, f, z):
    """V on the grid (damping rows x frequency columns), real cos/sin form of eq. 11."""
    w = 2 * np.pi * f[None, :, None]
    zz = z[:, None, None]
    wd = w * np.sqrt(1 - zz * zz)
    e = a * np.exp(-zz * w * (t[-1] - t))  # e^{-zeta w (t_n - t_i)}: no overflow
    phase = wd * t
    return np.hypot((e * np.cos(phase)).sum(-1), (e * np.sin(phase)).sum(-1))


def map_complex(t, a, f, z):
    """The same with one complex exponential per term: A e^{w(-zeta(t_n - t_i) + i sqrt(1-zeta^2) t_i)}."""
    w = 2 * np.pi * f[None, :, None]
    zz = z[:, None, None]
    exponent = w * (-zz * (t[-1] - t) + 1j * np.sqrt(1 - zz * zz) * t)
    return np.abs((a * np.exp(exponent)).sum(-1))


def timed(fn, *args):
    """(result, median seconds, minimum seconds) over REPEATS runs."""
    result = fn(*args)
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        fn(*args)
        times.append(time.perf_counter() - start)
    return result, statistics.median(times), min(times)


def criterion_median_s(name):
    path = os.path.join(TARGET, "criterion", name, "new", "estimates.json")
    try:
        with open(path) as fh:
            return json.load(fh)["median"]["point_estimate"] * 1e-9
    except (OSError, KeyError, ValueError):
        return None


def check(name, ours, theirs):
    worst = float(np.max(np.abs(ours - theirs)))
    print(f"  {name}: max |numpy - rust| = {worst:.2e} (tolerance {TOLERANCE:g})")
    if not worst <= TOLERANCE:
        sys.exit(f"{name}: numpy and rust disagree by {worst:g}")


def main():
    path = os.path.join(TARGET, "bench", "map.json")
    try:
        with open(path) as fh:
            data = json.load(fh)
    except OSError:
        sys.exit(f"{path} is missing: run `cargo bench --bench analysis` first")
    impulses = data["shaper"]["impulses"]
    t = np.array([i["time"] for i in impulses])
    a = np.array([i["amplitude"] for i in impulses])
    o = data["options"]
    f = np.linspace(o["fromHz"], o["toHz"], o["frequencyPoints"])
    z = np.linspace(o["dampingFrom"], o["dampingTo"], o["dampingPoints"])
    ours = np.array(data["map"]["vibration"]).reshape(len(z), len(f))
    co = data["curveOptions"]
    cf = np.linspace(co["fromHz"], co["toHz"], co["points"])
    cz = np.array([co["damping"]])
    ours_curve = np.array(data["curve"]["vibration"])

    print(f"numpy {np.__version__}, {len(t)} impulses, map {len(f)} x {len(z)}, curve {len(cf)} points")
    real, real_med, real_min = timed(map_real, t, a, f, z)
    cplx, cplx_med, cplx_min = timed(map_complex, t, a, f, z)
    curve, curve_med, curve_min = timed(map_real, t, a, cf, cz)
    check("map, real form", ours, real)
    check("map, complex form", ours, cplx)
    check("curve", ours_curve, curve[0])
    numpy_map = min(real_med, cplx_med)
    print(f"  numpy map: real form median {real_med * 1e3:.2f} ms (min {real_min * 1e3:.2f}), "
          f"complex form median {cplx_med * 1e3:.2f} ms (min {cplx_min * 1e3:.2f})")
    print(f"  numpy curve: median {curve_med * 1e3:.3f} ms (min {curve_min * 1e3:.3f})")

    rust_map = criterion_median_s("sensitivity_map 400x200, 9 impulses")
    rust_direct = criterion_median_s("map point by point 400x200, 9 impulses")
    rust_curve = criterion_median_s("sensitivity 1000 points, 9 impulses")
    if rust_map is None or rust_curve is None:
        sys.exit("criterion estimates missing: run `cargo bench --bench analysis` first")
    extra = f"; rust point by point {rust_direct * 1e3:.2f} ms" if rust_direct else ""
    print(f"map 400x200, 9 impulses: rust {rust_map * 1e3:.3f} ms vs numpy {numpy_map * 1e3:.2f} ms "
          f"(medians, faster numpy form) -> rust {numpy_map / rust_map:.0f}x faster{extra}")
    print(f"curve 1000 points, 9 impulses: rust {rust_curve * 1e3:.3f} ms vs numpy {curve_med * 1e3:.3f} ms "
          f"(medians) -> rust {curve_med / rust_curve:.1f}x faster")


if __name__ == "__main__":
    main()
