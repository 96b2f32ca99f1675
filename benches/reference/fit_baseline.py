#!/usr/bin/env python3
"""Baseline mode identification on tests/data/klipper: a plain least-squares fit of the modal
spectrum to a Welch PSD.  The accuracy it reaches is the bar for the project's identification.

Run:  python3 benches/reference/fit_baseline.py [--data tests/data/klipper] [--json out.json]

Model (the generator's plant, see sweep_testset.py):
    P(f) = c * E(f) * |H(f)|^2 + n0,   H(s) = 1 - sum_i g_i s^2 / (s^2 + 2 zeta_i w_i s + w_i^2)
fitted on log P over the swept band [freq_start, freq_end] (from the manifest, as a user knows
the band of the test they ran), with scipy.optimize.least_squares; the number of modes is
taken from the manifest; starting points from the largest local maxima of P / E (no use of
the true values), several starting dampings, the lowest cost kept.

E(f), the excitation's PSD, two ways:
  known   the PSD of the commanded acceleration, computed with the same Welch from Klipper's
          sweep re-generated from the test parameters (sweep_testset.excitation);
  f2      E = f^2 (what Klipper's sweep gives: amplitude accel_per_hz * f, equal time per Hz).
Spectra:
  raw     scipy.signal.welch of the raw file's axis channel, Hann, segments of 2^k samples
          near a quarter of the record (at least 0.25 Hz resolution where the record allows),
          half overlap;
  klipper the resonances_*.csv file itself (Klipper's Welch, 1.56 Hz bins), psd of the axis.
"""
import argparse
import json
import math
import os
import sys

import numpy as np
from scipy import optimize, signal

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sweep_testset as st  # noqa: E402


def modal_h2(f, modes):
    s = 2j * math.pi * f
    h = np.ones_like(s)
    for fi, zi, gi in modes:
        w = 2 * math.pi * fi
        h = h - gi * s * s / (s * s + 2 * zi * w * s + w * w)
    return np.abs(h) ** 2


def unpack(p, n):
    modes = [(math.exp(p[3 * i]), math.exp(p[3 * i + 1]), math.exp(p[3 * i + 2]))
             for i in range(n)]
    return modes, math.exp(p[3 * n]), math.exp(p[3 * n + 1])


def kaiser_kernel(fs, m, sub=16, reach=6):
    """Offsets (Hz) and weights of Klipper's Welch window in frequency: the expected value of
    its PSD at f is sum_j K_j S(f + d_j) (K = |DTFT of the symmetric Kaiser(6)|^2 / (fs sum w^2)
    times the offset step; sums to ~1)."""
    w = np.kaiser(m, 6.0)
    binw = fs / m
    d = np.arange(-reach * sub, reach * sub + 1) * binw / sub
    ph = np.exp(-2j * math.pi * np.outer(d, np.arange(m)) / fs)
    k = np.abs(ph @ w) ** 2 / (fs * np.sum(w * w)) * (binw / sub)
    return d, k


def fit(f, psd, exc, n, band, kernel=None):
    """Least squares of log(c E |H|^2 + n0) to log psd on the band.  With a kernel (offsets,
    weights), the model is smeared by the Welch window first and E(f) = f^2 is used."""
    sel = (f >= band[0]) & (f <= band[1]) & (psd > 0) & (exc > 0)
    f, psd, exc = f[sel], psd[sel], exc[sel]
    if kernel is not None:
        nu = f[:, None] + kernel[0][None, :]
        e_nu = np.where((nu >= band[0]) & (nu <= band[1]), nu * nu, 0.0)
    ratio = psd / exc
    # starting frequencies: the n most prominent peaks of the smoothed log ratio
    k = max(3, int(round(len(ratio) / 150)))
    sm = np.exp(np.convolve(np.log(ratio), np.ones(k) / k, mode="same"))
    idx, props = signal.find_peaks(np.log(sm), prominence=0.0)
    order = np.argsort(-props["prominences"])
    starts = [int(idx[i]) for i in order[:n]]
    while len(starts) < n:
        starts.append(int(np.argmax(sm)))
    base = np.median(ratio[:max(3, len(ratio) // 10)])
    best = None
    for z0 in (0.015, 0.05, 0.15):
        p0 = []
        for i in starts:
            g0 = 2 * z0 * math.sqrt(max(sm[i] / max(base, 1e-30), 1.0))
            p0 += [math.log(f[i]), math.log(z0), math.log(min(max(g0, 1e-3), 5.0))]
        p0 += [math.log(max(base, 1e-30)), math.log(max(np.min(psd), 1e-30))]

        def resid(p):
            modes, c, n0 = unpack(p, n)
            if kernel is None:
                model = c * exc * modal_h2(f, modes)
            else:
                model = c * ((e_nu * modal_h2(nu, modes)) @ kernel[1])
            return np.log(model + n0) - np.log(psd)

        try:
            r = optimize.least_squares(resid, np.array(p0), method="trf", x_scale="jac",
                                       max_nfev=4000)
        except Exception:
            continue
        if best is None or r.cost < best.cost:
            best = r
    modes, c, n0 = unpack(best.x, n)
    return sorted(modes), c, n0


def fit_frf(freqs, hmeas, weight, n, band, starts_f):
    """Complex least squares of c * H(f) to a measured FRF, residuals weighted by |A(f)|."""
    sel = (freqs >= band[0]) & (freqs <= band[1])
    f, h, w = freqs[sel], hmeas[sel], weight[sel] / weight[sel].max()
    best = None
    for z0 in (0.015, 0.05, 0.15):
        p0 = []
        for fi in starts_f:
            p0 += [math.log(fi), math.log(z0), math.log(0.3)]
        p0 += [0.0]

        def resid(p):
            modes = [(math.exp(p[3 * i]), math.exp(p[3 * i + 1]), math.exp(p[3 * i + 2]))
                     for i in range(n)]
            s = 2j * math.pi * f
            hm = np.ones_like(s)
            for fi, zi, gi in modes:
                om = 2 * math.pi * fi
                hm = hm - gi * s * s / (s * s + 2 * zi * om * s + om * om)
            r = (p[3 * n] + 1.0) * hm - h
            return np.concatenate([r.real * w, r.imag * w])

        try:
            r = optimize.least_squares(resid, np.array(p0), method="trf", x_scale="jac",
                                       max_nfev=4000)
        except Exception:
            continue
        if best is None or r.cost < best.cost:
            best = r
    return sorted((math.exp(best.x[3 * i]), math.exp(best.x[3 * i + 1]),
                   math.exp(best.x[3 * i + 2])) for i in range(n))


def frf_of_raw(entry, d, ax):
    """Y(f) / A(f) over the whole record (zero-padded 4x), A the commanded acceleration of
    Klipper's sweep re-generated from the test parameters at the file's sample times."""
    ex = entry["excitation"]
    seg_end, seg_acc = st.excitation(ex["freq_start"], ex["freq_end"], ex["accel_per_hz"],
                                     ex["hz_per_sec"], ex["sweeping_accel"],
                                     ex["sweeping_period"])
    t = d[:, 0] - d[0, 0]
    t[0] = 1e-12
    a = st.a_cmd_at(seg_end, seg_acc, t)
    y = signal.detrend(d[:, ax], type="linear")
    nfft = 1 << int(math.ceil(math.log2(4 * len(y))))
    fs = (len(y) - 1) / (d[-1, 0] - d[0, 0])
    A = np.fft.rfft(a, nfft)
    Y = np.fft.rfft(y, nfft)
    f = np.fft.rfftfreq(nfft, 1 / fs)
    return f, Y / np.where(A == 0, 1e-30, A), np.abs(A)


def exc_psd_known(entry, t0, t1, fs, nperseg, freqs):
    ex = entry["excitation"]
    seg_end, seg_acc = st.excitation(ex["freq_start"], ex["freq_end"], ex["accel_per_hz"],
                                     ex["hz_per_sec"], ex["sweeping_accel"],
                                     ex["sweeping_period"])
    n = int(seg_end[-1] * fs) + 1
    t = np.arange(n) / fs
    a = st.a_cmd_at(seg_end, seg_acc, t)
    fa, pa = signal.welch(a, fs, window="hann", nperseg=nperseg, noverlap=nperseg // 2)
    return np.interp(freqs, fa, pa)


def score(true_modes, got, bin_hz=0.0):
    rows = []
    for m in true_modes:
        # the fitted mode nearest in frequency
        g = min(got, key=lambda x: abs(x[0] - m["f"]))
        ef = (g[0] - m["f"]) / m["f"]
        ez = (g[1] - m["zeta"]) / m["zeta"]
        tol_f = max(0.01, 0.5 * bin_hz / m["f"])
        rows.append({"f": m["f"], "zeta": m["zeta"], "f_fit": g[0], "zeta_fit": g[1],
                     "f_err": ef, "zeta_err": ez,
                     "ok": bool(abs(ef) <= tol_f and abs(ez) <= 0.15)})
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", default=os.path.join(os.path.dirname(__file__), "..", "..",
                                                   "tests", "data", "klipper"))
    ap.add_argument("--json")
    a = ap.parse_args(argv)
    man = json.load(open(os.path.join(a.data, "manifest.json")))["cases"]
    out = []
    for key, e in sorted(man.items()):
        ax = 1 if e["axis"] == "x" else 2
        # the band swept; with the slow sweep on, below 15 Hz its +-400 mm/s^2 square wave
        # (and not the f^2 pulses) dominates the excitation, so the PSD fits start at 15 Hz
        ex = e["excitation"]
        band = (max(ex["freq_start"], 0.3), ex["freq_end"])
        if ex["sweeping_period"]:
            band = (max(band[0], 15.0), band[1])
        n = len(e["modes"])
        raw = e["files"].get("raw")
        if raw:
            d = np.loadtxt(os.path.join(a.data, raw), comments="#", delimiter=",")
            fs = (d.shape[0] - 1) / (d[-1, 0] - d[0, 0])
            span = d[-1, 0] - d[0, 0]
            # segments of a quarter of the record, or half of it if that is under 8 s
            nper = 1 << int(math.log2(max(span * fs / 4, 256)))
            if nper < 8 * fs:
                nper = 1 << int(math.log2(d.shape[0] / 2))
            f, p = signal.welch(d[:, ax], fs, window="hann", nperseg=nper, noverlap=nper // 2)
            # FRF fit, started from the Welch fit's frequencies
            exc = exc_psd_known(e, d[0, 0], d[-1, 0], fs, nper, f)
            got0, _, _ = fit(f, p, exc, n, band)
            ff, hh, ww = frf_of_raw(e, d, ax)
            got = fit_frf(ff, hh, ww, n, band, [g[0] for g in got0])
            out.append({"case": key, "spectrum": "raw", "excitation": "frf",
                        "bin_hz": ff[1], "modes": score(e["modes"], got)})
            for how in ("known", "f2"):
                exc = (exc_psd_known(e, d[0, 0], d[-1, 0], fs, nper, f) if how == "known"
                       else np.maximum(f, 1e-9) ** 2)
                got, _, _ = fit(f, p, exc, n, band)
                out.append({"case": key, "spectrum": "raw", "excitation": how,
                            "bin_hz": fs / nper, "modes": score(e["modes"], got)})
        res = e["files"].get("resonances")
        if res:
            d = np.loadtxt(os.path.join(a.data, res), skiprows=1, delimiter=",")
            f, p = d[:, 0], d[:, ax]
            bin_hz = f[2] - f[1]
            got, _, _ = fit(f, p, np.maximum(f, 1e-9) ** 2, n, band)
            out.append({"case": key, "spectrum": "klipper", "excitation": "f2",
                        "bin_hz": bin_hz, "modes": score(e["modes"], got, bin_hz)})
            # the same with the model smeared by Klipper's Kaiser window (parameters of the
            # Welch that wrote the file, from the manifest)
            wl = e["files"]["welch"]
            kern = kaiser_kernel(wl["fs_klipper"], wl["nperseg"])
            got, _, _ = fit(f, p, np.maximum(f, 1e-9) ** 2, n, band, kernel=kern)
            out.append({"case": key, "spectrum": "klipper", "excitation": "f2+window",
                        "bin_hz": bin_hz, "modes": score(e["modes"], got, bin_hz)})
    for r in out:
        for m in r["modes"]:
            print("%-16s %-7s %-5s f %7.2f -> %7.2f (%+6.2f%%)  zeta %.3f -> %.4f (%+6.1f%%) %s"
                  % (r["case"], r["spectrum"], r["excitation"], m["f"], m["f_fit"],
                     100 * m["f_err"], m["zeta"], m["zeta_fit"], 100 * m["zeta_err"],
                     "ok" if m["ok"] else "MISS"))
    print()
    print("summary (modes within 1 % (or half a bin) in f and 15 % in zeta):")
    groups = {}
    for r in out:
        k = (r["spectrum"], r["excitation"])
        if r["case"].endswith("slow3modes"):
            k = (k[0], k[1] + " (slow machine)")
        g = groups.setdefault(k, [0, 0, 0.0, 0.0])
        for m in r["modes"]:
            g[0] += m["ok"]
            g[1] += 1
            g[2] = max(g[2], abs(m["f_err"]))
            g[3] = max(g[3], abs(m["zeta_err"]))
    for k, g in groups.items():
        print("  %-8s %-27s %2d / %2d ok, worst |f err| %.2f %%, worst |zeta err| %.1f %%"
              % (k[0], k[1], g[0], g[1], 100 * g[2], 100 * g[3]))
    if a.json:
        json.dump(out, open(a.json, "w"), indent=1)


if __name__ == "__main__":
    main(sys.argv[1:])
