"""Reference values for tests/measure.rs (`welch_matches_scipy`): scipy.signal.welch on a
deterministic signal, printed as Rust arrays. Run: python3 benches/reference/welch_reference.py"""
import numpy as np
from scipy.signal import welch

n = np.arange(1000)
# The same formula as `reference_signal` in tests/measure.rs.
x = (np.sin(2 * np.pi * 0.1 * n) + 0.5 * np.cos(2 * np.pi * 0.237 * n + 0.3)
     + 0.01 * n + 0.2 * ((n * 7919) % 13) / 13.0)
fs = 100.0
cases = {
    "hann_128_64_constant": dict(window="hann", nperseg=128, noverlap=64, detrend="constant"),
    "hamming_200_50_linear": dict(window="hamming", nperseg=200, noverlap=50, detrend="linear"),
    "kaiser6_sym_256_128_constant": dict(window=np.kaiser(256, 6.0), nperseg=256, noverlap=128,
                                         detrend="constant"),
    "boxcar_100_0_none_spectrum": dict(window="boxcar", nperseg=100, noverlap=0, detrend=False,
                                       scaling="spectrum"),
}
bins = [0, 1, 5, 10, 13, 24, 30, 50]
for name, kw in cases.items():
    f, p = welch(x, fs=fs, **kw)
    idx = [b for b in bins if b < len(p)]
    print(f"// {name}: len {len(p)}")
    print(f"const {name.upper()}: &[(usize, f64)] = &[" +
          ", ".join(f"({b}, {float(p[b])!r})" for b in idx) + "];")
