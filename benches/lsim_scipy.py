"""Reference for benches/simulate.rs: scipy.signal.lsim on the same system and input.

Three modes y'' + 2ζω y' + ω² y = ω² u (1.2 Hz ζ 0.012, 3.4 Hz ζ 0.013, 7 Hz ζ 0.02), endpoint
the mean of the three, u = clip(t, 0, 1) sampled at 1 kHz for 10 s (lsim interpolates linearly,
as the Rust side reads the sampled command).

    pip install numpy scipy && python3 benches/lsim_scipy.py
"""
import time

import numpy as np
from scipy import signal

ws = 2 * np.pi * np.array([1.2, 3.4, 7.0])
zs = [0.012, 0.013, 0.02]
n = 2 * len(ws)
A = np.zeros((n, n))
B = np.zeros((n, 1))
C = np.zeros((1, n))
for i, (w, z) in enumerate(zip(ws, zs)):
    A[2 * i, 2 * i + 1] = 1
    A[2 * i + 1, 2 * i] = -w * w
    A[2 * i + 1, 2 * i + 1] = -2 * z * w
    B[2 * i + 1, 0] = w * w
    C[0, 2 * i] = 1 / 3
sys = signal.StateSpace(A, B, C, np.zeros((1, 1)))
t = np.arange(10_000) * 1e-3
u = np.clip(t, 0, 1)

_, y, _ = signal.lsim(sys, u, t)
print("endpoint at t = 1, 5, 9.999 s: %.12f %.12f %.12f" % (y[1000], y[5000], y[9999]))
runs = []
for _ in range(20):
    t0 = time.perf_counter()
    signal.lsim(sys, u, t)
    runs.append(time.perf_counter() - t0)
runs.sort()
print("scipy %s lsim, 3 modes, 10 s at 1 kHz: median %.2f ms (min %.2f ms) over %d runs"
      % (__import__("scipy").__version__, 1e3 * runs[len(runs) // 2], 1e3 * runs[0], len(runs)))
