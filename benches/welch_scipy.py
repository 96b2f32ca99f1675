"""Baseline for benches/welch_page.mjs: scipy.signal.welch on the same 10^6 samples.
Run: python3 benches/welch_scipy.py   (pip install numpy scipy)"""
import time
import numpy as np
from scipy.signal import welch

RUNS = 20
n, fs = 1_000_000, 3200.0
i = np.arange(n)
x = (np.sin(2 * np.pi * 37.3 * i / fs) + 0.5 * np.sin(2 * np.pi * 91.7 * i / fs)
     + 0.3 * ((i * 7919) % 1009) / 1009)
cases = [
    ("hann, 4096-sample segments, half overlap", dict(window="hann", nperseg=4096, noverlap=2048)),
    ("Klipper's settings (Kaiser β = 6, 2048 samples, half overlap)",
     dict(window=np.kaiser(2048, 6.0), nperseg=2048, noverlap=1024)),
]
for name, kw in cases:
    f, p = welch(x, fs=fs, **kw)
    times = []
    for _ in range(RUNS):
        t0 = time.perf_counter()
        f, p = welch(x, fs=fs, **kw)
        times.append((time.perf_counter() - t0) * 1000)
    times.sort()
    print(f"scipy.signal.welch, 10^6 samples, {name}: median {times[len(times) // 2]:.1f} ms, "
          f"best {times[0]:.1f} ms ({RUNS} runs; {len(p)} bins, Σ psd {p.sum():.12g})")
