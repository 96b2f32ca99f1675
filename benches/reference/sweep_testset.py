#!/usr/bin/env python3
"""Generator of the independent Klipper-format test set (tests/data/klipper/).

Simulates Klipper's resonance test on machines with known modes and writes the three file
kinds Klipper writes, plus a manifest with the true modes and the reference output of
klipper_reference.py for every file.  Deterministic (fixed seeds).  numpy + scipy.

Run:  python3 benches/reference/sweep_testset.py [--out tests/data/klipper] [--only NAME,...]

THE EXCITATION (klippy/extras/resonance_tester.py, Klipper3d/klipper commit 034cb673,
VibrationPulseTestGenerator.gen_test, SweepingVibrationsTestGenerator.gen_test,
ResonanceTestExecutor.run_test), re-implemented:
  * from freq_start, repeatedly: t_seg = 1 / (4 f); accelerate at +s * accel_per_hz * f for
    t_seg, then at -s * accel_per_hz * f for t_seg (the toolhead goes out and back to rest);
    f += 2 t_seg * hz_per_sec; s = -s; while f <= freq_end + 1e-6.  The commanded
    acceleration is piecewise constant.
  * the slow sweep (sweeping_period > 0): a square wave of +-sweeping_accel added to it, +1
    first, switching at P sqrt2/8, then P (sqrt2/8 + 1/4) later, then every P/2 (P =
    sweeping_period), so the toolhead drifts slowly back and forth over the test point.
  * at the end, if the toolhead still moves, a deceleration to rest at the printer's
    max_accel (5000 mm/s^2 here) in the direction of motion, as run_test does.
  * the accelerometer records from the first test move to the end of the last move.
  Defaults are Klipper's current ones: accel_per_hz 60, hz_per_sec 1, sweeping_accel 400,
  sweeping_period 1.2, min_freq 5, max_freq 200.  Cases may narrow the band, and the slow
  machine and one damped case go outside Klipper's limits (FREQ_START >= 1, HZ_PER_SEC <= 2):
  the manifest says so.

THE PLANT (a belt-driven toolhead, base-excited modes): the motors impose the commanded
position x_c(t) (x_c'' = a_cmd); each mode i is a relative coordinate e_i with
    e_i'' + 2 zeta_i w_i e_i' + w_i^2 e_i = -a_cmd(t),
and the accelerometer on the toolhead measures  y'' = a_cmd + sum_i g_i e_i''.
For one mode with g = 1 this is the base-excitation transmissibility
    Y''/A(s) = (2 zeta w s + w^2) / (s^2 + 2 zeta w s + w^2);
in general H(s) = 1 - sum_i g_i s^2 / (s^2 + 2 zeta_i w_i s + w_i^2).  The modal gain g_i is
a participation factor; the g_i sum to 1 (the absolute acceleration of a point of a
base-excited structure: sum_i Gamma_i phi_i = 1), so H(0) = 1 and H falls off above the
modes, H = sum_i g_i (2 zeta_i w_i s + w_i^2) / (s^2 + 2 zeta_i w_i s + w_i^2).  The peak of
mode i is about g_i / (2 zeta_i); cases give the modes' peaks relative to each other (e.g.
4 dB), the g_i follow.  The manifest gives each mode's f, zeta, g and
peak_db = 20 log10(g / (2 zeta)).
Integration is EXACT: a_cmd is constant between its switching times, so over every interval
between consecutive events (sample instants and switching times) each mode's state advances
by the closed-form solution of the damped oscillator under a constant input (the matrix
exponential of the 2x2 companion matrix, in complex modal form; checked against
scipy.linalg.expm in self_check()).  No time step error.

THE SENSOR (an ADXL345 at full resolution, klippy/extras/adxl345.py): the axis under test
reads y'', with the chip mounted 2 degrees off the axis (so the other horizontal axis reads
sin(2 deg) y''); z reads gravity (9806.65 mm/s^2) and a small share of y''.  Each channel gets
white noise (sigma given per case, mm/s^2), a slow drift (offset + linear + a slow sine),
then is quantised to the chip's LSB (SCALE_XY = 0.003774 g, SCALE_Z = 0.003906 g per LSB,
g = 9806.65 mm/s^2), clipped to the 13-bit range, rounded to 6 decimals.  Sample times are
print times starting at t0, at the nominal rate times (1 - 1.5e-4) (a crystal's error), '%.6f'.

THE FILES (klippy/extras/shaper_calibrate.py save_calibration_data, resonance_tester.py):
  raw_data_<axis>_<name>.csv          TEST_RESONANCES OUTPUT=raw_data
  resonances_<axis>_<name>.csv        TEST_RESONANCES: Welch PSD, NOT normalised, rows up to
                                      (excluding) 1.5 * freq_end
  calibration_data_<axis>_<name>.csv  SHAPER_CALIBRATE: normalised PSD, find_best_shaper with
                                      max_freq = 1.5 * freq_end and scv 5, shaper columns.
Long default tests (5 -> 200 Hz at 1 Hz/s: 195 s) are written only as the PSD files (a raw
file of them would be 30 MB); raw files are kept short to keep tests/data small.
"""
import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import klipper_reference as kr  # noqa: E402

G = 9806.65
# sensor drift (mm/s^2, s): offset, slope per second, a slow sine; per channel k = 0, 1, 2 the
# offset is scaled by (1 - k/2), the slope by (1 + k), the sine's phase shifted by k rad
DRIFT = {"offset": 60.0, "slope": 3.0, "sine": 25.0, "period": 40.0}
SCALE_XY = 0.003774 * G
SCALE_Z = 0.003906 * G
MOUNT_DEG = 2.0


# ---------------------------------------------------------------------------------------------
# Excitation
# ---------------------------------------------------------------------------------------------

def pulse_sequence(freq_start, freq_end, accel_per_hz, hz_per_sec):
    """Breakpoints (t_end, accel, freq) of the back-and-forth test: accel holds up to t_end."""
    out = []
    f, s, t = freq_start, 1.0, 0.0
    while f <= freq_end + 1e-6:
        half = 0.25 / f
        a = accel_per_hz * f
        t += half
        out.append((t, s * a, f))
        t += half
        out.append((t, -s * a, f))
        f += 2.0 * half * hz_per_sec
        s = -s
    return out


def add_slow_sweep(seq, sweeping_accel, period):
    """Superpose the +-sweeping_accel square wave (switch times as in the module docstring)."""
    if not period:
        return list(seq)
    switches = []
    first = period * math.sqrt(2.0) / 8.0
    t_end = seq[-1][0]
    t = first
    step = period * (math.sqrt(2.0) / 8.0 + 0.25)
    while t < t_end:
        switches.append(t)
        t += step
        step = period * 0.5
    out = []
    last = 0.0
    k = 0
    sign = 1.0
    for t_end_seg, a, f in seq:
        while k < len(switches) and switches[k] <= t_end_seg:
            if switches[k] > last:
                out.append((switches[k], a + sweeping_accel * sign, f))
                last = switches[k]
            sign = -sign
            k += 1
        out.append((t_end_seg, a + sweeping_accel * sign, f))
        last = t_end_seg
    return out


def finish_to_rest(seq, max_accel=5000.0):
    """Append the final deceleration if the toolhead still moves."""
    v, last = 0.0, 0.0
    for t, a, _ in seq:
        v += a * (t - last)
        last = t
    if abs(v) > 1e-9:
        seq = list(seq) + [(last + abs(v) / max_accel, -math.copysign(max_accel, v), seq[-1][2])]
    return seq


def excitation(freq_start, freq_end, accel_per_hz=60.0, hz_per_sec=1.0, sweeping_accel=400.0,
               sweeping_period=1.2):
    seq = pulse_sequence(freq_start, freq_end, accel_per_hz, hz_per_sec)
    seq = add_slow_sweep(seq, sweeping_accel, sweeping_period)
    seq = finish_to_rest(seq)
    times = np.array([s[0] for s in seq])
    accels = np.array([s[1] for s in seq])
    return times, accels


def a_cmd_at(times, accels, t):
    """The commanded acceleration at instants t (value on the interval (t_{k-1}, t_k])."""
    idx = np.searchsorted(times, t, side="left")
    idx = np.minimum(idx, len(accels) - 1)
    return np.where(t > times[-1], 0.0, accels[idx])


# ---------------------------------------------------------------------------------------------
# Exact integration of a base-excited mode under piecewise-constant input
# ---------------------------------------------------------------------------------------------

def mode_response(f, zeta, seg_end, seg_acc, sample_t):
    """e'' of  e'' + 2 zeta w e' + w^2 e = -a(t)  at the sample instants (state 0 at t = 0),
    a piecewise constant (seg_acc[k] on (seg_end[k-1], seg_end[k]], 0 after the last).
    Complex modal form: z = e' - lam2 e obeys z' = lam1 z - a (lam1,2 the poles), so over an
    interval of length h with constant a:  z <- exp(lam1 h) z + (exp(lam1 h) - 1) / lam1 * (-a),
    exact.  For real e (conjugate poles) e = Im(z) / Im(lam1 - lam2) ... recovered below."""
    w = 2.0 * math.pi * f
    lam = complex(-zeta * w, w * math.sqrt(1.0 - zeta * zeta))
    lamc = lam.conjugate()
    # State x = (e, v).  Modal coordinates: q1 = v - lamc e  (q1' = lam q1 - a),
    # and q2 = conj(q1).  e = (q1 - q2) / (lam - lamc) = Im(q1) / Im(lam).
    events = np.union1d(seg_end[seg_end < sample_t[-1]], sample_t)
    acc = a_cmd_at(seg_end, seg_acc, events)  # input on the interval ending at each event
    # h for each event interval
    h = np.diff(np.concatenate([[0.0], events]))
    ex = np.exp(lam * h)
    gain = (ex - 1.0) / lam
    q = 0.0 + 0.0j
    qs = np.empty(events.shape[0], dtype=complex)
    # The recurrence (varying h) is a scalar loop; ~1e6 steps run in a few seconds.
    for i in range(events.shape[0]):
        q = ex[i] * q - gain[i] * acc[i]
        qs[i] = q
    pick = np.searchsorted(events, sample_t)
    q = qs[pick]
    e = q.imag / lam.imag
    v = (q + lamc * e).real
    a_now = a_cmd_at(seg_end, seg_acc, sample_t)  # e'' from the ODE, input just before t
    # the ODE gives e'' = -a - 2 zeta w v - w^2 e; with a piecewise constant the sample
    # instant may sit on a switch: the value of the interval ending there is used.
    return -a_now - 2.0 * zeta * w * v - w * w * e


def self_check():
    """The closed-form step of mode_response against scipy.linalg.expm of the companion
    matrix augmented with the constant input."""
    from scipy.linalg import expm
    f, zeta, a = 37.0, 0.05, 1234.0
    w = 2 * math.pi * f
    h = 0.00731
    m = np.array([[0, 1, 0], [-w * w, -2 * zeta * w, -1], [0, 0, 0]], float)
    x1 = expm(m * h) @ np.array([0.0, 0.0, a])
    seg_end = np.array([1.0])
    seg_acc = np.array([a])
    ts = np.array([h])
    e2 = mode_response(f, zeta, seg_end, seg_acc, ts)[0]
    e2_ref = -a - 2 * zeta * w * x1[1] - w * w * x1[0]
    assert abs(e2 - e2_ref) < 1e-9 * max(1.0, abs(e2_ref)), (e2, e2_ref)


# ---------------------------------------------------------------------------------------------
# Sensor and files
# ---------------------------------------------------------------------------------------------

def record(case):
    """Simulate one recording: returns rows (t, ax, ay, az) as Klipper would store them."""
    ex = case["excitation"]
    seg_end, seg_acc = excitation(ex["freq_start"], ex["freq_end"], ex["accel_per_hz"],
                                  ex["hz_per_sec"], ex["sweeping_accel"], ex["sweeping_period"])
    rate = case["rate"] * (1.0 - 1.5e-4)
    n = int(seg_end[-1] * rate) + 1
    t = np.arange(n) / rate
    t[0] = 1e-12  # the first sample is taken just after the first move starts
    y = a_cmd_at(seg_end, seg_acc, t).copy()
    for m in case["modes"]:
        y += m["gain"] * mode_response(m["f"], m["zeta"], seg_end, seg_acc, t)
    rng = np.random.default_rng(case["seed"])
    sig = case["noise"]
    span = t[-1]
    drift = case.get("drift", DRIFT)

    def drift_of(k):
        return (drift["offset"] * (1 - 0.5 * k) + drift["slope"] * t * (1 + k)
                + drift["sine"] * np.sin(2 * math.pi * t / drift["period"] + k))

    c, s = math.cos(math.radians(MOUNT_DEG)), math.sin(math.radians(MOUNT_DEG))
    along = c * y + drift_of(0) + rng.normal(0.0, sig, n)
    across = s * y + drift_of(1) + rng.normal(0.0, sig, n)
    vert = G + 0.01 * y + drift_of(2) + rng.normal(0.0, sig * 1.4, n)

    def quant(v, scale):
        raw = np.clip(np.round(v / scale), -4096, 4095)
        clipped = int(np.sum(np.abs(raw) >= 4095))
        return np.round(raw * scale, 6), clipped

    ax_, ay_ = (along, across) if case["axis"] == "x" else (across, along)
    qx, cx = quant(ax_, SCALE_XY)
    qy, cy = quant(ay_, SCALE_XY)
    qz, cz = quant(vert, SCALE_Z)
    t_print = np.round(case.get("t0", 1000.0) + t, 6)
    case["_clipped"] = cx + cy + cz
    case["_duration"] = float(span)
    case["_samples"] = int(n)
    return np.column_stack([t_print, qx, qy, qz])


def write_files(case, outdir):
    rows = record(case)
    axis, name = case["axis"], case["name"]
    written = {}
    fmax = 1.5 * case["excitation"]["freq_end"]
    if "raw" in case["outputs"]:
        path = os.path.join(outdir, "raw_data_%s_%s.csv" % (axis, name))
        kr.write_raw_csv(path, rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3])
        written["raw"] = os.path.basename(path)
        # Klipper reads the written numbers back: compute the PSD from the file's values.
        rows = np.loadtxt(path, comments="#", delimiter=",")
    ds = kr.psd_of_raw("resonances_%s_%s" % (axis, name), rows)
    if "resonances" in case["outputs"]:
        path = os.path.join(outdir, "resonances_%s_%s.csv" % (axis, name))
        kr.write_calibration_csv(path, [ds], None, max_freq=fmax)
        written["resonances"] = os.path.basename(path)
    if "calibration_data" in case["outputs"]:
        ds2 = kr.psd_of_raw("calibration_%s_%s" % (axis, name), rows)
        ds2.normalize()
        best, picks, _ = kr.best_shaper([ds2], scv=5.0, max_freq=fmax)
        path = os.path.join(outdir, "calibration_data_%s_%s.csv" % (axis, name))
        kr.write_calibration_csv(path, [ds2], picks, max_freq=fmax)
        written["calibration_data"] = os.path.basename(path)
        written["shaper_calibrate"] = {"best": best.summary(),
                                       "shapers": [p.summary() for p in picks],
                                       "max_freq": fmax, "scv": 5.0}
    written["welch"] = {"fs_klipper": float(ds.fs), "nperseg": int(ds.nperseg),
                        "segments": int(ds.nseg), "bin_hz": float(ds.fs / ds.nperseg)}
    return written


# ---------------------------------------------------------------------------------------------
# Cases
# ---------------------------------------------------------------------------------------------

def mode(f, zeta, rel_db=0.0):
    """A mode by frequency, damping and its peak relative to the case's other modes (dB);
    the gains are set by normalize_gains."""
    return {"f": f, "zeta": zeta, "rel_db": rel_db}


def normalize_gains(modes):
    """Participation factors g_i summing to 1 (so H(0) = 1 and H -> 0 above the modes, as for
    the absolute acceleration of a point of a base-excited structure: sum_i Gamma_i phi_i = 1),
    in the ratios that make the peaks g_i / (2 zeta_i) differ by the rel_db given."""
    w = [2.0 * m["zeta"] * 10 ** (m["rel_db"] / 20.0) for m in modes]
    for m, wi in zip(modes, w):
        m["gain"] = wi / sum(w)
        m["peak_db"] = 20 * math.log10(m["gain"] / (2 * m["zeta"]))
        del m["rel_db"]
    return modes


def exc(fs, fe, aph=60.0, hps=1.0, sacc=400.0, sper=1.2):
    return {"freq_start": fs, "freq_end": fe, "accel_per_hz": aph, "hz_per_sec": hps,
            "sweeping_accel": sacc, "sweeping_period": sper}


FULL = exc(5.0, 200.0)  # Klipper's default test: 195 s


def cases():
    c = []
    # --- short raw recordings (Klipper's raw CSV), each also as resonances (+ calibration) ---
    c.append(dict(name="single47z08", axis="x", rate=3200.0, seed=101, noise=150.0,
                  modes=[mode(47.3, 0.08, 14.0)], excitation=exc(38.0, 56.0, hps=2.0),
                  outputs=["raw", "resonances", "calibration_data"],
                  note="one mode; band 38-56 Hz at Klipper's fastest 2 Hz/s"))
    c.append(dict(name="two38x14", axis="y", rate=3200.0, seed=102, noise=150.0,
                  modes=[mode(38.0, 0.04, 16.0), mode(53.2, 0.04, 12.0)],
                  excitation=exc(33.0, 58.0, hps=2.0),
                  outputs=["raw", "resonances", "calibration_data"],
                  note="two modes, ratio 1.4, the second's peak 4 dB below the first's"))
    c.append(dict(name="z018f61", axis="x", rate=3200.0, seed=104, noise=150.0,
                  modes=[mode(61.0, 0.18, 9.0)], excitation=exc(40.0, 90.0, hps=5.0),
                  outputs=["raw", "resonances"],
                  note="a heavily damped mode; 5 Hz/s (faster than Klipper's HZ_PER_SEC "
                       "maximum of 2) to keep the file small"))
    c.append(dict(name="slow3modes", axis="x", rate=1000.0, seed=103, noise=100.0,
                  modes=[mode(1.0, 0.05, 14.0), mode(3.4, 0.04, 12.0), mode(11.0, 0.03, 10.0)],
                  excitation=exc(0.5, 16.0, aph=300.0, hps=0.775, sacc=400.0, sper=0.0),
                  outputs=["raw", "resonances"],
                  note="slow machine: 20 s at 1 kHz; sweep 0.5-16 Hz (below Klipper's FREQ_START "
                       "minimum of 1 Hz), no slow sweep; Klipper's Welch bins are 1.95 Hz wide"))
    # --- Klipper's default test (5-200 Hz at 1 Hz/s, 195 s): PSD files only ---
    full = "Klipper's default test 5-200 Hz at 1 Hz/s with the slow sweep"
    for name, axis, seed, modes, outs, note in [
        ("z001f88", "x", 201, [mode(88.0, 0.01, 12.0)], ["resonances"], "single mode"),
        ("z003f23", "y", 202, [mode(23.0, 0.03, 14.0)], ["resonances"], "single mode"),
        ("z008f47", "x", 203, [mode(47.3, 0.08, 14.0)], ["resonances"], "single mode"),
        ("z020f61", "y", 204, [mode(61.0, 0.2, 8.0)], ["resonances"], "single mode"),
        ("z003f110", "x", 205, [mode(110.0, 0.03, 12.0)], ["resonances"], "single mode"),
        ("two45x14", "x", 206, [mode(45.0, 0.05, 14.0), mode(63.0, 0.05, 10.0)],
         ["resonances", "calibration_data"],
         "two modes, ratio 1.4, the second 4 dB weaker"),
        ("three", "y", 207, [mode(32.0, 0.06, 12.0), mode(51.0, 0.03, 14.0),
                             mode(87.0, 0.1, 10.0)],
         ["resonances", "calibration_data"], "three modes"),
        # close pairs of damped modes, their peaks in the file within 0.5 dB of each other with
        # a dip of 4-5 dB between them (as on several real printers' X axes): read as one
        # broad mode until the identification split such a mode on the humps under it
        ("pair56x76", "x", 210, [mode(56.0, 0.12, 12.0), mode(76.0, 0.10, 8.0)],
         ["resonances", "calibration_data"],
         "two modes, ratio 1.36, peaks 0.4 dB apart with a 4 dB dip between them"),
        ("pair43x53", "y", 211, [mode(43.0, 0.06, 12.0), mode(53.0, 0.08, 10.5)],
         ["resonances"], "two modes, ratio 1.23, the second 1.5 dB weaker"),
        # a broad mode with a sharp one about twice as high, the sharp one's peak 4 dB under
        # the broad one's: the joint fit's starts missed its least-squares minimum (62.4 / 0.19
        # read 64.9 / 0.23 and 117.4 / 0.027 read 116.1 / 0.034) until a start with the
        # base-excited structure's signs was added
        ("broad62sharp117", "y", 212, [mode(62.4, 0.19, 12.0), mode(117.4, 0.027, 8.0)],
         ["resonances"], "a broad mode and a sharp one 1.88 times higher, 4 dB weaker"),
        # a sharp mode under a broad one 1.58 times higher, and a weak third (a random
        # machine's, found 2026-12-06): the joint fit returned the two seeds' modes swapped,
        # and by seed index the broad peak's slot took the sharp mode's fit: 61.98 and 62.99 Hz
        # reported, 99.8 Hz lost
        ("swap63x100", "y", 5013, [mode(62.98, 0.0271, 0.0), mode(99.76, 0.1364, -0.566359),
                                   mode(139.01, 0.0187, -5.436367)],
         ["resonances"], "a sharp mode and a broad one 1.58 times higher, the fit's swap"),
        # one machine: its X and Y axes (SHAPER_CALIBRATE without AXIS writes both, NAME m1),
        # and a second run of X with other noise (and drift) for robustness tests
        ("m1", "x", 301, [mode(42.0, 0.06, 14.0), mode(71.0, 0.04, 9.0)],
         ["resonances", "calibration_data"], "machine m1, X axis"),
        ("m1", "y", 302, [mode(36.0, 0.07, 14.0), mode(63.0, 0.05, 10.0)],
         ["resonances", "calibration_data"], "machine m1, Y axis"),
        ("m1run2", "x", 303, [mode(42.0, 0.06, 14.0), mode(71.0, 0.04, 9.0)],
         ["resonances"], "machine m1, X axis, second run: other noise seed"),
    ]:
        c.append(dict(name=name, axis=axis, rate=3200.0, seed=seed, noise=150.0, modes=modes,
                      excitation=FULL, outputs=outs, note=note + "; " + full))
    c[-1]["drift"] = {"offset": -40.0, "slope": -2.0, "sine": 35.0, "period": 55.0}
    # Klipper's releases of 2021-2023 swept to 133.33 Hz (max_freq = 1.5 * 133.33 = 200 Hz of
    # rows): the PSD falls off a cliff at the sweep's end; a genuine mode 10 Hz under it
    c.append(dict(name="cliff133", axis="x", rate=3200.0, seed=209, noise=150.0,
                  modes=[mode(45.0, 0.05, 12.0), mode(123.0, 0.03, 14.0)],
                  excitation=exc(5.0, 133.33), outputs=["resonances", "calibration_data"],
                  note="sweep 5-133.33 Hz at 1 Hz/s (Klipper 2021-2023's default band), "
                       "a mode 10 Hz under its end; " + full.replace("5-200", "5-133.33")))
    # A short sweep's resonances file whose start falls between two bins (Klipper's psd_xyz
    # rises 12.0 then 4.0 dB there): found by benches/reference/sweep_random.py --hard (seed 7,
    # machine r22); the raw recording (43 s) is not kept
    c.append(dict(name="short36x123", axis="y", rate=3200.0, seed=5022, noise=396.9,
                  modes=[mode(47.78, 0.0155, 0.0), mode(94.44, 0.067, -4.73)],
                  excitation=exc(35.8, 122.8, hps=2.0), outputs=["resonances"],
                  note="a short sweep 35.8-122.8 Hz at 2 Hz/s, noise 397 mm/s^2; its start "
                       "a cliff split over two bins"))
    # A broad mode and two weaker sharp ones 1.8 and 2.8 times higher, on a sensor at 3022 Hz
    # (sweep_random.py seed 14 --hard --rates, machine r32): every start of the joint fit fell
    # into a minimum of 100 times the least sum (48.2, 85.4, 133.3 Hz) until the physical
    # start gave each mode its level under the excitation's slope
    c.append(dict(name="three47r3022", axis="x", rate=3022.0, seed=5032, noise=272.9,
                  modes=[mode(47.02, 0.1409, 0.0), mode(85.74, 0.0644, -9.603588),
                         mode(133.85, 0.0155, -9.379784)],
                  excitation=FULL, outputs=["resonances"],
                  note="a broad mode and two sharp ones up to 2.8 times higher, the sensor at "
                       "3022 Hz, noise 273 mm/s^2; " + full))
    # No mode in the band: a stiff machine swept 5-133.33 Hz, its PSD rising as f^2 into the
    # sweep's end (sweep_random.py seed 15 --hard, machine r16): the resonances file read
    # 130.45 Hz, zeta 0.00001 -- a line between the last two bins that no bin shows
    c.append(dict(name="rigid133", axis="y", rate=3200.0, seed=5016, noise=440.9, modes=[],
                  excitation=exc(5.0, 133.33), outputs=["resonances", "calibration_data"],
                  note="no mode under 133.33 Hz (a stiff machine), noise 441 mm/s^2; "
                       + full.replace("5-200", "5-133.33")))
    c.append(dict(name="noisy47", axis="y", rate=3200.0, seed=208, noise=400.0,
                  modes=[mode(47.3, 0.08, 14.0)], excitation=FULL, outputs=["resonances"],
                  note="single mode, noise 400 mm/s^2 (PSD floor ~100); " + full))
    for case in c:
        normalize_gains(case["modes"])
        case.setdefault("drift", dict(DRIFT))
        if case["name"] == "z001f88":
            # a peak of 1/(2 zeta) = 50 would clip the sensor at Klipper's default 60
            # mm/s^2/Hz: the test is run with ACCEL_PER_HZ=20
            case["excitation"] = exc(5.0, 200.0, aph=20.0)
            case["note"] += "; ACCEL_PER_HZ=20"
    return c


def case_key(case):
    return "%s_%s" % (case["axis"], case["name"])


# expected.json keys for several files read together -> the cases whose resonances files
COMBINED = {"resonances_x_m1+resonances_x_m1run2": ["x_m1", "x_m1run2"]}


# expected.json keys "<file>|<option>=<value>": the reference output with calibrate_shaper.py's
# options (the same names as its command line)
VARIANTS = [
    ("resonances_y_z003f23.csv", {"max_smoothing": 0.2}),
    ("resonances_y_three.csv", {"max_vibrs_pcnt": 1.0}),
    ("resonances_x_m1.csv", {"scv": 10.0}),
    ("resonances_x_z008f47.csv", {"shapers": ["zvd", "mzv", "zv"]}),
    ("resonances_x_z001f88.csv", {"damping_ratio": 0.05, "test_damping_ratios": [0.01, 0.02]}),
] + [
    # the closed-form EI shapers of the releases before the polynomial fits (defs=classic),
    # and with them the 2021-2023 selection rule (legacy=True)
    (fn, {"defs": "classic"}) for fn in (
        "resonances_x_m1.csv", "resonances_y_m1.csv", "resonances_y_three.csv",
        "resonances_x_two45x14.csv", "resonances_y_z003f23.csv", "resonances_x_z001f88.csv",
        "resonances_y_z020f61.csv", "resonances_x_z008f47.csv")
] + [
    (fn, {"defs": "classic", "legacy": True}) for fn in (
        "resonances_x_m1.csv", "resonances_y_m1.csv", "resonances_y_three.csv")
]


def readme_table(manifest_path):
    man = json.load(open(manifest_path))["cases"]
    rows = ["| case (axis_name) | files | rate, length | excitation | noise | "
            "true modes f / ζ / g / peak dB |", "| --- | --- | --- | --- | --- | --- |"]
    for k, v in sorted(man.items(), key=lambda kv: (kv[1]["excitation"]["freq_end"] != 200,
                                                     kv[0])):
        ex = v["excitation"]
        files = ", ".join(x for x in ("raw", "resonances", "calibration_data") if x in v["files"])
        exs = "%g–%g Hz, %g Hz/s, %g mm/s²/Hz%s" % (
            ex["freq_start"], ex["freq_end"], ex["hz_per_sec"], ex["accel_per_hz"],
            ", slow sweep" if ex["sweeping_period"] else ", no slow sweep")
        modes = "; ".join("%g / %g / %.3f / %.1f" % (m["f"], m["zeta"], m["gain"], m["peak_db"])
                          for m in v["modes"])
        rows.append("| %s | %s | %g Hz, %.1f s | %s | %g | %s |" % (
            k, files, v["rate"], v["duration_s"], exs, v["noise"], modes))
    print("\n".join(rows))


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "..", "..",
                                                  "tests", "data", "klipper"))
    ap.add_argument("--only")
    ap.add_argument("--readme-table", action="store_true",
                    help="print the README's table of cases from the manifest and stop")
    ap.add_argument("--expected-only", action="store_true",
                    help="recompute expected.json from the files in the manifest, simulate nothing")
    a = ap.parse_args(argv)
    if a.readme_table:
        return readme_table(os.path.join(a.out, "manifest.json"))
    self_check()
    os.makedirs(a.out, exist_ok=True)
    only = set(a.only.split(",")) if a.only else None
    manifest_path = os.path.join(a.out, "manifest.json")
    manifest = {}
    if (only or a.expected_only) and os.path.exists(manifest_path):
        manifest = json.load(open(manifest_path))["cases"]
    for case in cases():
        if a.expected_only or (only and case["name"] not in only
                                         and case_key(case) not in only):
            continue
        print("generating", case["name"], file=sys.stderr)
        files = write_files(case, a.out)
        entry = {k: v for k, v in case.items() if not k.startswith("_") and k != "outputs"}
        entry.update(duration_s=case["_duration"], samples=case["_samples"],
                     clipped_samples=case["_clipped"], files=files)
        manifest[case_key(case)] = entry
    doc = {
        "generator": "benches/reference/sweep_testset.py",
        "model": "base-excited modes: e_i'' + 2 zeta_i w_i e_i' + w_i^2 e_i = -a_cmd; "
                 "sensor y'' = a_cmd + sum g_i e_i'', sum g_i = 1, so Y''/A = "
                 "sum g_i (2 zeta_i w_i s + w_i^2) / (s^2 + 2 zeta_i w_i s + w_i^2); "
                 "peak_db = 20 log10(g / (2 zeta)); accelerations in mm/s^2, f in Hz",
        "cases": manifest,
    }
    with open(manifest_path, "w") as fh:
        json.dump(doc, fh, indent=1, sort_keys=True)
    # Golden output of the reference for every file, read back as calibrate_shaper.py would.
    expected = {}
    for name, entry in sorted(manifest.items()):
        for kind in ("raw", "resonances", "calibration_data"):
            fn = entry["files"].get(kind)
            if fn:
                out = kr.run([os.path.join(a.out, fn)], log=None, detail=True)
                out["files"] = [fn]
                out["datasets"][0]["name"] = fn
                expected[fn] = out
    for fn, opts in VARIANTS:
        if not os.path.exists(os.path.join(a.out, fn)):
            continue
        kw = dict(opts)
        if "test_damping_ratios" in kw:
            kw["test_damping"] = kw.pop("test_damping_ratios")
        out = kr.run([os.path.join(a.out, fn)], log=None, detail=False, **kw)
        out["files"] = [fn]
        out["datasets"][0]["name"] = fn
        key = fn + "|" + ",".join("%s=%s" % (k, v if not isinstance(v, list) else
                                             ":".join(str(x) for x in v))
                                  for k, v in sorted(opts.items()))
        expected[key] = out
    # Several files of one axis, combined as calibrate_shaper.py combines them (one data set
    # each, the worst remaining vibration over them), and the multi-data-set calibration file
    # that calibrate_shaper.py -c writes for them.
    for key, names in COMBINED.items():
        paths = []
        for nm in names:
            if nm not in manifest:
                break
            paths.append(manifest[nm]["files"]["resonances"])
        else:
            out = kr.run([os.path.join(a.out, p) for p in paths], log=None, detail=True)
            out["files"] = paths
            for d, p in zip(out["datasets"], paths):
                d["name"] = p
            expected[key] = out
            sets = []
            for p in paths:
                ds = kr.parse_file(os.path.join(a.out, p))[0]
                ds.name = p
                sets.append(ds)
            _, picks, _ = kr.best_shaper(sets)
            cal = "calibration_data_%s.csv" % key.replace("+", "_")
            kr.write_calibration_csv(os.path.join(a.out, cal), sets, picks)
            out = kr.run([os.path.join(a.out, cal)], log=None, detail=True)
            out["files"] = [cal]
            for d in out["datasets"]:
                d["name"] = d["name"].split("/")[-1]
            expected[cal] = out
    with open(os.path.join(a.out, "expected.json"), "w") as fh:
        # one file per line, compact inside, so diffs stay readable and the file small
        fh.write("{\n")
        keys = sorted(expected)
        for i, k in enumerate(keys):
            fh.write("%s: %s%s\n" % (json.dumps(k), json.dumps(expected[k], sort_keys=True,
                                                               separators=(",", ":")),
                                      "," if i + 1 < len(keys) else ""))
        fh.write("}\n")


if __name__ == "__main__":
    main(sys.argv[1:])
