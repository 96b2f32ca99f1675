#!/usr/bin/env python3
"""Independent numpy re-implementation of Klipper's input-shaper calibration.

Written from a reading of Klipper's published algorithm (repository Klipper3d/klipper; it is
GPLv3, nothing here is copied from it):

  * klippy/extras/shaper_calibrate.py  (commit 034cb6734a9a2b0c56e3ccee6c33866526c8cbab):
    CalibrationData.add_data / normalize_to_frequencies, ShaperCalibrate._psd,
    calc_freq_response, _estimate_shaper, _estimate_remaining_vibrations,
    _get_shaper_smoothing, fit_shaper, _bisect, find_shaper_max_accel, find_best_shaper,
    save_calibration_data;
  * klippy/extras/shaper_defs.py  (commit 1819369886bac3e5210674c0e9b36ae60619ce82):
    the shaper table (zv, mzv, zvd, ei, 2hump_ei, 3hump_ei), DEFAULT_DAMPING_RATIO = 0.1,
    SHAPER_VIBRATION_REDUCTION = 20;
  * klippy/extras/resonance_tester.py (commit 034cb6734a9a2b0c56e3ccee6c33866526c8cbab):
    what TEST_RESONANCES and SHAPER_CALIBRATE write (max_freq = 1.5 * freq_end for both, the
    resonances file NOT normalised, the calibration file normalised and with shaper columns);
  * scripts/calibrate_shaper.py (the 2020-2025 version with --max_vibrs_pcnt and the API
    capture; the index did not name its commit): parse_log and calibrate_shaper.

What this file reproduces, and the quirks kept on purpose (each checked against the reading):

  * parse_log: a file whose first non-'#' line does not start with 'freq,' is a raw
    accelerometer CSV (#time,accel_x,accel_y,accel_z); its PSD is computed and normalised at
    once.  A file starting 'freq,psd_x,psd_y,psd_z,psd_xyz' is one data set; any other 'freq,'
    header is one data set per column up to a 'shapers:' column (psd_sum only).  Empty fields
    read as 0 (genfromtxt filling_values=0).  The PSD is normalised to frequencies unless the
    header contains ',shapers:' (a SHAPER_CALIBRATE file is already normalised).
  * Welch PSD: sampling frequency fs = N / (t_last - t_first) (N samples, not N-1 intervals);
    segment M = 1 << bit_length(int(fs * 0.5 - 1)); half overlap (M // 2); the number of
    segments (N - M//2) // (M - M//2); each segment's mean removed; a SYMMETRIC Kaiser window
    beta = 6 (numpy.kaiser; scipy.signal.welch would use the periodic one); density scaling
    1 / (fs * sum(w^2)); one-sided doubling of every bin except DC and the last (Nyquist);
    plain mean over segments.  No PSD if N <= M.
  * normalize_to_frequencies: psd /= f + 0.1; below 2 * MIN_FREQ = 10 Hz also
    psd *= exp(1 - (10 / (f + 0.1))**2).
  * Several files are NOT averaged: each stays a data set; fit_shaper takes, per test
    frequency, the largest remaining vibration over data sets and test damping ratios.
  * fit_shaper scans np.arange(min_freq_of_family, 200, 0.2) from the top down, uses the
    PSD bins with f <= max_freq (200 by default; SHAPER_CALIBRATE passes 1.5 * freq_end),
    and the shaper curve is reported on np.arange(min bin, max_freq, 0.2).
  * save_calibration_data (one data set) writes the freq column from the PSD bins but the
    shaper columns from row i of that 0.2 Hz curve: the shaper columns of a
    calibration_data_*.csv are NOT aligned with its freq column (row i holds V at
    f0 + 0.2 i).  Kept exactly.

Run:
    python3 klipper_reference.py FILE [FILE ...] [--json out.json] [--max_smoothing S]
        [--max_vibrs_pcnt P] [--scv V] [--shapers zv,mzv,...] [--max_freq F] [--damping_ratio Z]
Prints what calibrate_shaper.py prints and writes JSON (per shaper name, freq, vibrs,
smoothing, max_accel, score; the best).  numpy only.
"""
import argparse
import csv
import io
import json
import math
import sys

import numpy as np

MIN_FREQ = 5.0
MAX_FREQ = 200.0
WINDOW_T_SEC = 0.5
MAX_SHAPER_FREQ = 200.0
TEST_DAMPING_RATIOS = (0.075, 0.1, 0.15)
AUTOTUNE_SHAPERS = ("zv", "mzv", "ei", "2hump_ei", "3hump_ei")
SHAPER_VIBRATION_REDUCTION = 20.0
DEFAULT_DAMPING_RATIO = 0.1
DEFAULT_SCV = 5.0
TARGET_SMOOTHING = 0.12


# ---------------------------------------------------------------------------------------------
# Shaper table (shaper_defs.py).  Each returns (amplitudes, times); amplitudes are not
# necessarily normalised (the EI-hump polynomial fits are not), users divide by the sum.
# ---------------------------------------------------------------------------------------------

def _damped(f, zeta):
    """sqrt(1 - zeta^2) and the damped period 1 / (f sqrt(1 - zeta^2))."""
    root = math.sqrt(1.0 - zeta * zeta)
    return root, 1.0 / (f * root)


def shaper_zv(f, zeta):
    root, td = _damped(f, zeta)
    k = math.exp(-zeta * math.pi / root)
    return [1.0, k], [0.0, 0.5 * td]


def shaper_zvd(f, zeta):
    root, td = _damped(f, zeta)
    k = math.exp(-zeta * math.pi / root)
    return [1.0, 2.0 * k, k * k], [0.0, 0.5 * td, td]


def shaper_mzv(f, zeta):
    # Klipper's MZV: three impulses at 0, 3/8 and 3/4 of the damped period, undamped weights
    # (1 - 1/sqrt2, sqrt2 - 1, 1 - 1/sqrt2) (zeros of the undamped response at f and 5/3 f),
    # each then multiplied by k^i with k = exp(-0.75 zeta pi / sqrt(1 - zeta^2)).  The newer
    # shaper_defs.py builds the same weights from a pseudo-inverse (get_mzv_coeffs(3, 0.75));
    # mzv_weights_by_solve() below re-derives them that way as a check.
    root, td = _damped(f, zeta)
    k = math.exp(-0.75 * zeta * math.pi / root)
    a1 = 1.0 - 1.0 / math.sqrt(2.0)
    return [a1, (math.sqrt(2.0) - 1.0) * k, a1 * k * k], [0.0, 0.375 * td, 0.75 * td]


def mzv_weights_by_solve(n=3, t=0.75):
    """Weights with sum 1 and undamped zeros at 1 + i / tau (i < n-1), least squares."""
    tau = t * (n - 2.0) / (n - 2.0 * t - 1.0)
    times = np.arange(n) * t / (n - 1.0)
    rows, rhs = [np.ones(n)], [1.0]
    for i in range(n - 1):
        w = 2.0 * math.pi * (1.0 + i / tau) * times
        rows += [np.cos(w), np.sin(w)]
        rhs += [0.0, 0.0]
    return np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)[0]


def shaper_ei(f, zeta, v_tol=1.0 / SHAPER_VIBRATION_REDUCTION):
    # Extra-insensitive shaper, Klipper's polynomial fit in (v_tol, zeta).
    root, td = _damped(f, zeta)
    z, v = zeta, v_tol
    a1 = (0.24968 + 0.24961 * v) + ((0.80008 + 1.23328 * v) + (0.49599 + 3.17316 * v) * z) * z
    a3 = (0.25149 + 0.21474 * v) + ((-0.83249 + 1.41498 * v) + (0.85181 - 4.90094 * v) * z) * z
    a2 = 1.0 - a1 - a3
    t2 = 0.4999 + (((0.46159 + 8.57843 * v) * v)
                   + (((4.26169 - 108.644 * v) * v)
                      + ((1.75601 + 336.989 * v) * v) * z) * z) * z
    return [a1, a2, a3], [0.0, t2 * td, td]


# Polynomial coefficients in zeta (constant term first) of each impulse's time (in units of
# 1/f, the UNDAMPED period) and amplitude, for the 2- and 3-hump EI shapers at 5 % tolerance.
_EI2_T = [[0.0, 0.0, 0.0, 0.0],
          [0.49890, 0.16270, -0.54262, 6.16180],
          [0.99748, 0.18382, -1.58270, 8.17120],
          [1.49920, -0.09297, -0.28338, 1.85710]]
_EI2_A = [[0.16054, 0.76699, 2.26560, -1.22750],
          [0.33911, 0.45081, -2.58080, 1.73650],
          [0.34089, -0.61533, -0.68765, 0.42261],
          [0.15997, -0.60246, 1.00280, -0.93145]]
_EI3_T = [[0.0, 0.0, 0.0, 0.0],
          [0.49974, 0.23834, 0.44559, 12.4720],
          [0.99849, 0.29808, -2.36460, 23.3990],
          [1.49870, 0.10306, -2.01390, 17.0320],
          [1.99960, -0.28231, 0.61536, 5.40450]]
_EI3_A = [[0.11275, 0.76632, 3.29160, -1.44380],
          [0.23698, 0.61164, -2.57850, 4.85220],
          [0.30008, -0.19062, -2.14560, 0.13744],
          [0.23775, -0.73297, 0.46885, -2.08650],
          [0.11244, -0.45439, 0.96382, -1.46000]]


def _poly(coeffs, z):
    acc = 0.0
    for c in reversed(coeffs):  # Horner
        acc = acc * z + c
    return acc


def _hump(t_tab, a_tab, f, zeta):
    return ([_poly(row, zeta) for row in a_tab], [_poly(row, zeta) / f for row in t_tab])


def shaper_2hump_ei(f, zeta):
    return _hump(_EI2_T, _EI2_A, f, zeta)


def shaper_3hump_ei(f, zeta):
    return _hump(_EI3_T, _EI3_A, f, zeta)


# name -> (constructor, lowest frequency scanned by default)
SHAPERS = {
    "zv": (shaper_zv, 21.0),
    "mzv": (shaper_mzv, 23.0),
    "zvd": (shaper_zvd, 29.0),
    "ei": (shaper_ei, 29.0),
    "2hump_ei": (shaper_2hump_ei, 39.0),
    "3hump_ei": (shaper_3hump_ei, 48.0),
}


# ---------------------------------------------------------------------------------------------
# Spectra
# ---------------------------------------------------------------------------------------------

class Dataset:
    """One spectrum: bins and the x, y, z and sum PSDs (x/y/z may be None)."""

    def __init__(self, name, freqs, psd_sum, psd_x=None, psd_y=None, psd_z=None):
        self.name = name
        self.freqs = np.asarray(freqs, dtype=float)
        self.psd_sum = np.array(psd_sum, dtype=float)
        self.psd_x = None if psd_x is None else np.array(psd_x, dtype=float)
        self.psd_y = None if psd_y is None else np.array(psd_y, dtype=float)
        self.psd_z = None if psd_z is None else np.array(psd_z, dtype=float)
        self.normalized = False

    def normalize(self):
        """Klipper's normalize_to_frequencies (idempotent, as there)."""
        if self.normalized:
            return
        f = self.freqs
        low = f < 2.0 * MIN_FREQ
        gain = np.ones_like(f)
        gain[low] = np.exp(1.0 - (2.0 * MIN_FREQ / (f[low] + 0.1)) ** 2)
        for attr in ("psd_sum", "psd_x", "psd_y", "psd_z"):
            p = getattr(self, attr)
            if p is not None:
                setattr(self, attr, p / (f + 0.1) * gain)
        self.normalized = True


def welch_klipper(x, fs, m):
    """Welch PSD as Klipper's _psd: symmetric Kaiser(6), M//2 overlap, mean removed per segment."""
    x = np.asarray(x, dtype=float)
    hop = m - m // 2
    count = (x.shape[0] - m // 2) // hop
    w = np.kaiser(m, 6.0)
    acc = np.zeros(m // 2 + 1)
    for k in range(count):
        seg = x[k * hop:k * hop + m]
        spec = np.fft.rfft((seg - seg.mean()) * w)
        acc += spec.real ** 2 + spec.imag ** 2
    psd = acc / count / (fs * np.sum(w * w))
    psd[1:-1] *= 2.0
    return np.arange(m // 2 + 1) * (fs / m), psd


def segment_length(fs):
    """Klipper's M: 1 << bit_length(int(fs * WINDOW_T_SEC - 1))."""
    return 1 << int(fs * WINDOW_T_SEC - 1).bit_length()


def psd_of_raw(name, data):
    """calc_freq_response: data rows are (time, ax, ay, az).  Returns a Dataset or None."""
    data = np.asarray(data, dtype=float)
    n = data.shape[0]
    fs = n / (data[-1, 0] - data[0, 0])
    m = segment_length(fs)
    if n <= m:
        return None
    f, px = welch_klipper(data[:, 1], fs, m)
    _, py = welch_klipper(data[:, 2], fs, m)
    _, pz = welch_klipper(data[:, 3], fs, m)
    ds = Dataset(name, f, px + py + pz, px, py, pz)
    ds.fs, ds.nperseg, ds.nseg = fs, m, (n - m // 2) // (m - m // 2)
    return ds


def parse_file(path):
    """calibrate_shaper.py parse_log: returns a list of Datasets (normalised as Klipper does)."""
    with open(path) as fh:
        text = fh.read()
    header = ""
    for line in text.splitlines(True):
        if not line.startswith("#"):
            header = line
            break
    if not header.startswith("freq,"):
        rows = np.loadtxt(io.StringIO(text), comments="#", delimiter=",", ndmin=2)
        ds = psd_of_raw(path, rows)
        if ds is None:
            raise ValueError("%s: too short for one Welch segment" % path)
        ds.kind = "raw"
        ds.raw_x, ds.raw_y, ds.raw_z, ds.raw_sum = ds.psd_x, ds.psd_y, ds.psd_z, ds.psd_sum
        ds.normalize()
        return [ds]
    data = np.genfromtxt(io.StringIO(text), dtype=np.float64, skip_header=1, comments="#",
                         delimiter=",", filling_values=0.0)
    data = np.atleast_2d(data)
    if header.startswith("freq,psd_x,psd_y,psd_z,psd_xyz"):
        ds = Dataset(path, data[:, 0], data[:, 4], data[:, 1], data[:, 2], data[:, 3])
        sets = [ds]
    else:
        names = next(csv.reader([header.rstrip("\r\n")], delimiter=","))[1:]
        sets = []
        for i, nm in enumerate(names):
            if nm == "shapers:":
                break
            sets.append(Dataset(nm, data[:, 0], data[:, i + 1]))
    pre = ",shapers:" in header
    for ds in sets:
        ds.kind = "calibration_data" if pre else "resonances"
        if not pre:
            ds.normalize()
        else:
            ds.normalized = True
    return sets


# ---------------------------------------------------------------------------------------------
# Shaper figures
# ---------------------------------------------------------------------------------------------

def shaper_response(shaper, zeta, freqs):
    """Residual-vibration ratio of a shaper on a mode (f, zeta), relative to an unshaped step:
    |sum_j A_j exp(-zeta w (T_n - T_j)) exp(i w_d T_j)| / sum A (Klipper's _estimate_shaper)."""
    a, t = np.asarray(shaper[0], float), np.asarray(shaper[1], float)
    w = 2.0 * math.pi * np.asarray(freqs, float)
    wd = w * math.sqrt(1.0 - zeta * zeta)
    decay = np.exp(-zeta * np.outer(w, t[-1] - t))
    phase = np.exp(1j * np.outer(wd, t))
    return np.abs((a * decay * phase).sum(axis=1)) / a.sum()


def remaining_vibrations(shaper, zeta, freqs, psd):
    vals = shaper_response(shaper, zeta, freqs)
    floor = psd.max() / SHAPER_VIBRATION_REDUCTION
    left = np.maximum(vals * psd - floor, 0.0).sum()
    total = np.maximum(psd - floor, 0.0).sum()
    return left / total, vals


def smoothing(shaper, accel=5000.0, scv=DEFAULT_SCV):
    """Klipper's smoothing estimate: toolhead offset on a 90-degree corner (only impulses at or
    after the shaper's centroid, times sqrt 2) and on a 180-degree turn; the larger."""
    a, t = list(shaper[0]), list(shaper[1])
    total = sum(a)
    centre = sum(ai * ti for ai, ti in zip(a, t)) / total
    o90 = sum(ai * (scv + 0.5 * accel * (ti - centre)) * (ti - centre)
              for ai, ti in zip(a, t) if ti >= centre)
    o180 = sum(ai * 0.5 * accel * (ti - centre) ** 2 for ai, ti in zip(a, t))
    return max(o90 * math.sqrt(2.0) / total, o180 / total)


def _bisect_true_max(pred):
    """Largest x with pred(x), pred monotone (true then false), as Klipper's _bisect: 0 when
    pred(1e-9) fails; halve / double from 1 to bracket; bisect to a width of 1e-8."""
    if not pred(1e-9):
        return 0.0
    lo = hi = 1.0
    while not pred(lo):
        hi = lo
        lo *= 0.5
    if hi == lo:
        while pred(hi):
            hi *= 2.0
    while hi - lo > 1e-8:
        mid = 0.5 * (lo + hi)
        if pred(mid):
            lo = mid
        else:
            hi = mid
    return lo


def max_accel(shaper, scv):
    return _bisect_true_max(lambda acc: smoothing(shaper, acc, scv) <= TARGET_SMOOTHING)


def max_accel_closed_form(shaper, scv):
    """Both offsets are affine in accel: solve each for TARGET_SMOOTHING, take the smaller."""
    a, t = list(shaper[0]), list(shaper[1])
    total = sum(a)
    c = sum(ai * ti for ai, ti in zip(a, t)) / total
    b90 = math.sqrt(2) / total * sum(ai * scv * (ti - c) for ai, ti in zip(a, t) if ti >= c)
    k90 = math.sqrt(2) / total * sum(ai * 0.5 * (ti - c) ** 2 for ai, ti in zip(a, t) if ti >= c)
    k180 = sum(ai * 0.5 * (ti - c) ** 2 for ai, ti in zip(a, t)) / total
    if b90 > TARGET_SMOOTHING:
        return 0.0
    return min((TARGET_SMOOTHING - b90) / k90, TARGET_SMOOTHING / k180)


class Result:
    __slots__ = ("name", "freq", "freq_bins", "vals", "vibrs", "smoothing", "score", "max_accel")

    def __init__(self, **kw):
        for k, v in kw.items():
            setattr(self, k, v)

    def summary(self, curve=False):
        out = {"name": self.name, "freq": float(self.freq), "vibrs": float(self.vibrs),
               "smoothing": float(self.smoothing), "max_accel": float(self.max_accel),
               "score": float(self.score)}
        if curve:
            # V(f) (max over test dampings and data sets) on f0 + 0.2 k, k < count
            out["curve"] = {"f0": float(self.freq_bins[0]), "step": 0.2,
                            "count": int(self.freq_bins.size),
                            "vals": [round(float(v), 6) for v in self.vals]}
        return out


def fit_family(name, datasets, scv=DEFAULT_SCV, max_smoothing=None, max_vibrations=None,
               damping_ratio=None, test_damping=None, max_freq=None):
    """fit_shaper: returns (selected, all results in scan order, top frequency first)."""
    make, fmin = SHAPERS[name]
    zeta = damping_ratio or DEFAULT_DAMPING_RATIO
    tests = test_damping or TEST_DAMPING_RATIOS
    test_freqs = np.arange(min(fmin, MAX_SHAPER_FREQ - 1e-7), MAX_SHAPER_FREQ, 0.2)
    top = max(max_freq or MAX_FREQ, test_freqs.max())
    lowest_bin = min([top] + [ds.freqs.min() for ds in datasets])
    curve_f = np.arange(lowest_bin, top, 0.2)
    cut = [(ds.freqs[ds.freqs <= top], ds.psd_sum[ds.freqs <= top]) for ds in datasets]

    best = None
    results = []
    for f in test_freqs[::-1]:
        sh = make(f, zeta)
        sm = smoothing(sh, scv=scv)
        if max_smoothing and sm > max_smoothing and best is not None:
            return best, results
        acc = max_accel(sh, scv)
        worst = 0.0
        curve = np.zeros(curve_f.shape)
        for fb, psd in cut:
            per_set = np.zeros(fb.shape)
            for dr in tests:
                v, vals = remaining_vibrations(sh, dr, fb, psd)
                per_set = np.maximum(per_set, vals)
                worst = max(worst, v)
            curve = np.maximum(curve, np.interp(curve_f, fb, per_set))
        score = sm * (worst ** 1.5 + 0.2 * worst + 0.01)
        res = Result(name=name, freq=f, freq_bins=curve_f, vals=curve, vibrs=worst,
                     smoothing=sm, score=score, max_accel=acc)
        results.append(res)
        if best is None or best.vibrs > res.vibrs:
            best = res
    # A cheaper (less smoothing) frequency whose vibrations are within 10 % + 0.05 % of the
    # lowest wins if its score is lower; scanned from the lowest frequency up.
    chosen = best
    for res in reversed(results):
        if res.vibrs < best.vibrs * 1.1 + 0.0005 and (
                res.score < chosen.score
                or (max_vibrations is not None and best.vibrs > max_vibrations)):
            chosen = res
    return chosen, results


def best_shaper(datasets, shapers=None, scv=DEFAULT_SCV, max_smoothing=None,
                max_vibrations=None, damping_ratio=None, test_damping=None, max_freq=None,
                log=None):
    """find_best_shaper: returns (best, per-family picks in order, per-family scans)."""
    best = None
    picks = []
    scans = {}
    for name in shapers or AUTOTUNE_SHAPERS:
        chosen, results = fit_family(name, datasets, scv, max_smoothing, max_vibrations,
                                     damping_ratio, test_damping, max_freq)
        scans[name] = results
        if (best is None or chosen.score * 1.2 < best.score
                or (chosen.score * 1.05 < best.score
                    and chosen.smoothing * 1.1 < best.smoothing)
                or (max_vibrations is not None and best.vibrs > max_vibrations
                    and chosen.vibrs < best.vibrs)):
            best = chosen
        # Any scanned frequency of this family (lowest first) with both fewer vibrations and
        # less smoothing than the current best replaces it, and becomes this family's pick.
        for res in reversed(results):
            if res.vibrs < best.vibrs and res.smoothing < best.smoothing:
                best = chosen = res
        if log:
            log("Fitted shaper '%s' frequency = %.1f Hz (vibrations = %.1f%%, smoothing ~= %.3f)"
                % (chosen.name, chosen.freq, chosen.vibrs * 100.0, chosen.smoothing))
            log("To avoid too much smoothing with '%s', suggested max_accel <= %.0f mm/sec^2"
                % (chosen.name, round(chosen.max_accel / 100.0) * 100.0))
        picks.append(chosen)
    if best is not None and best.name == "zv":
        for p in picks:
            if p.name != "zv" and p.vibrs * 1.1 < best.vibrs:
                best = p
                break
    return best, picks, scans


# ---------------------------------------------------------------------------------------------
# Writers: what Klipper's save_calibration_data writes
# ---------------------------------------------------------------------------------------------

def _csv_name(name):
    name = name.replace('"', '""')
    return '"' + name + '"' if "," in name else name


def write_calibration_csv(path, datasets, picks=None, max_freq=None):
    """save_calibration_data.  One data set: freq,psd_x,psd_y,psd_z,psd_xyz on the PSD bins;
    several: freq,<name>... with each psd_sum interpolated on the 0.2 Hz grid.  With picks:
    ',shapers:' and one 'name(freq)' column each, row i holding pick.vals[i] (see the module
    docstring: not aligned with the freq column for one data set).  Rows stop before
    max_freq (200 by default).  Formats: %.1f freq, %.3e PSD, %.3f shaper."""
    top = max_freq or MAX_FREQ
    if len(datasets) > 1:
        if picks:
            grid = picks[0].freq_bins
        else:
            grid = np.arange(min([top] + [d.freqs.min() for d in datasets]), top, 0.2)
        cols = [np.interp(grid, d.freqs, d.psd_sum) for d in datasets]
    else:
        d = datasets[0]
        grid = d.freqs
        cols = [d.psd_x, d.psd_y, d.psd_z, d.psd_sum]
    out = ["freq,"]
    if len(datasets) > 1:
        out.append(",".join(_csv_name(d.name) for d in datasets))
    else:
        out.append("psd_x,psd_y,psd_z,psd_xyz")
    if picks:
        out.append(",shapers:")
        for p in picks:
            out.append(",%s(%.1f)" % (p.name, p.freq))
    out.append("\n")
    for i in range(grid.shape[0]):
        if grid[i] >= top:
            break
        out.append("%.1f" % grid[i])
        for c in cols:
            out.append(",%.3e" % c[i])
        if picks:
            out.append(",")
            for p in picks:
                out.append(",%.3f" % p.vals[i])
        out.append("\n")
    with open(path, "w") as fh:
        fh.write("".join(out))


def write_raw_csv(path, t, ax, ay, az):
    """The accelerometer's write_to_file: '#time,accel_x,accel_y,accel_z', '%.6f' four times."""
    with open(path, "w") as fh:
        fh.write("#time,accel_x,accel_y,accel_z\n")
        fh.write("".join("%.6f,%.6f,%.6f,%.6f\n" % r for r in zip(t, ax, ay, az)))


# ---------------------------------------------------------------------------------------------
# CLI
# ---------------------------------------------------------------------------------------------

def run(paths, scv=DEFAULT_SCV, max_smoothing=None, max_vibrs_pcnt=None, shapers=None,
        max_freq=None, damping_ratio=None, test_damping=None, log=print, detail=False):
    datasets = []
    for p in paths:
        datasets.extend(parse_file(p))
    if log:
        log("Processing resonances from %s" % ",".join(d.name for d in datasets))
    max_vibrations = None if max_vibrs_pcnt is None else max_vibrs_pcnt * 0.01
    best, picks, _ = best_shaper(datasets, shapers, scv, max_smoothing, max_vibrations,
                                 damping_ratio, test_damping, max_freq, log)
    if log:
        log("Recommended shaper is %s @ %.1f Hz" % (best.name, best.freq))
    out = {
        "files": list(paths),
        "options": {"scv": scv, "max_smoothing": max_smoothing,
                    "max_vibrs_pcnt": max_vibrs_pcnt, "shapers": list(shapers or AUTOTUNE_SHAPERS),
                    "max_freq": max_freq, "damping_ratio": damping_ratio or DEFAULT_DAMPING_RATIO},
        "datasets": [{"name": d.name, "kind": getattr(d, "kind", "?"), "bins": int(d.freqs.size),
                      "normalized_on_read": getattr(d, "kind", "") != "calibration_data"}
                     for d in datasets],
        "shapers": [p.summary(detail) for p in picks],
        "best": best.summary(),
    }
    if detail:
        for d, out_d in zip(datasets, out["datasets"]):
            if getattr(d, "kind", "") == "raw":
                # Klipper's Welch PSD of the file (before normalisation), every bin
                out_d["welch"] = {
                    "fs": float(d.fs), "nperseg": int(d.nperseg), "segments": int(d.nseg),
                    "bin_hz": float(d.fs / d.nperseg),
                    "psd_x": [float("%.10e" % v) for v in d.raw_x],
                    "psd_y": [float("%.10e" % v) for v in d.raw_y],
                    "psd_z": [float("%.10e" % v) for v in d.raw_z],
                    "psd_xyz": [float("%.10e" % v) for v in d.raw_sum]}
    return out


def self_test():
    """Checks of this file against independent computations (run: --self-test)."""
    from scipy import signal
    # MZV weights: closed form == least-squares solve of the zero conditions
    assert np.allclose(mzv_weights_by_solve(), shaper_mzv(1.0, 0.0)[0], atol=1e-12)
    # max_accel: Klipper's bisection == the closed form of the two affine offsets
    for name, (make, fmin) in SHAPERS.items():
        for f in (fmin, 57.3, 131.0):
            sh = make(f, 0.1)
            a, b = max_accel(sh, 5.0), max_accel_closed_form(sh, 5.0)
            assert abs(a - b) < 1e-6 * b, (name, f, a, b)
    # every shaper has zero residual vibration at (or near) its design point, zeta = 0.1
    for name, (make, _) in SHAPERS.items():
        v = shaper_response(make(50.0, 0.1), 0.1, [50.0])[0]
        assert v < (0.051 if "ei" in name else 1e-9), (name, v)
    # Welch: == scipy.signal.welch with the SYMMETRIC Kaiser window, mean removed
    rng = np.random.default_rng(7)
    x = rng.standard_normal(20000)
    m = segment_length(3200.0)
    f1, p1 = welch_klipper(x, 3200.0, m)
    f2, p2 = signal.welch(x, 3200.0, window=signal.windows.kaiser(m, 6.0, sym=True),
                          nperseg=m, noverlap=m // 2, detrend="constant")
    assert np.allclose(f1, f2) and np.max(np.abs(p1 - p2) / p2) < 1e-12
    assert segment_length(3200.0) == 2048 and segment_length(1000.0) == 512
    assert segment_length(1600.0) == 1024 and segment_length(400.0) == 256
    print("klipper_reference self-test: ok")


def main(argv=None):
    if argv and argv[0] == "--self-test":
        return self_test()
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--json")
    ap.add_argument("--scv", type=float, default=DEFAULT_SCV)
    ap.add_argument("--max_smoothing", "-s", type=float)
    ap.add_argument("--max_vibrs_pcnt", "-v", type=float)
    ap.add_argument("--max_freq", "-f", type=float)
    ap.add_argument("--shapers")
    ap.add_argument("--damping_ratio", type=float)
    ap.add_argument("--test_damping_ratios")
    ap.add_argument("--csv", help="write a calibration_data CSV as calibrate_shaper.py -c does")
    a = ap.parse_args(argv)
    shapers = a.shapers.lower().split(",") if a.shapers else None
    tdr = [float(x) for x in a.test_damping_ratios.split(",")] if a.test_damping_ratios else None
    out = run(a.files, a.scv, a.max_smoothing, a.max_vibrs_pcnt, shapers, a.max_freq,
              a.damping_ratio, tdr)
    if a.csv:
        datasets = [d for p in a.files for d in parse_file(p)]
        mv = None if a.max_vibrs_pcnt is None else a.max_vibrs_pcnt * 0.01
        _, picks, _ = best_shaper(datasets, shapers, a.scv, a.max_smoothing, mv,
                                  a.damping_ratio, tdr, a.max_freq)
        write_calibration_csv(a.csv, datasets, picks)
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(out, fh, indent=1)
    return out


if __name__ == "__main__":
    main(sys.argv[1:])
