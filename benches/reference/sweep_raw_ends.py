#!/usr/bin/env python3
"""Raw sweep recordings that end anywhere around their machine's highest mode: an independent
check of issue 20's raw path at a sweep's end (a mode inside the band, at its end, or past
it), not part of `npm test`.

sweep_testset.py's time-domain model (Klipper's resonance-test drive with its slow square
wave, exact integration of base-excited modes, the sensor with drift and noise) on N machines
drawn at random from a seed: 1-2 modes, the first at 30-70 Hz, the second 1.4-1.9 times
higher, damping ratios log-uniform in 0.015-0.12, peaks 0 to -4 dB; swept at 2 Hz/s from 0.7
times the lowest mode to 0.9-1.25 times the highest; noise 150-400 mm/s^2.  Writes Klipper's
raw CSV (`raw_data_x_eNN.csv`) and `manifest.json` ({name, modes: [[f, zeta]], start, end}):

    python3 benches/reference/sweep_raw_ends.py OUT [N] [SEED]
    python3 benches/reference/sweep_raw_ends.py OUT --flat
    python3 benches/reference/sweep_raw_ends.py OUT --short [N] [SEED]
    SWEEP_RAW_ENDS_DIR=OUT cargo test --release --test identify_raw_sweep -- --ignored --nocapture

With --flat, four fixed recordings whose swept band holds no mode instead: a mode far past
the end (250 Hz swept 30-80 Hz, 300 Hz swept 20-120 Hz, 260 Hz swept 5-60 Hz) or far below
the start (8 Hz swept 30-80 Hz, where the response in the band is flat and only the
periodogram's wiggles stand out).

With --short, N short recordings instead (1.5-5 s: a fast sweep, as a shaker's chirp or a
quick test is): 1-3 modes, the first at 25-70 Hz, each next 1.4-1.9 times higher, damping
ratios log-uniform in 0.015-0.15, peaks 0 to -4 dB, swept from 0.7 times the lowest mode to
1.3 times the highest (every mode inside the band) at whatever rate fills the drawn duration.

numpy + scipy.
"""
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sweep_testset as st  # noqa: E402


def draw_modes(rng, kmax, f_lo, zeta_hi):
    """1 to kmax modes: the first at f_lo-70 Hz, each next 1.4-1.9 times higher, damping
    ratios log-uniform in 0.015-zeta_hi, peaks 0 to -4 dB: [(f, zeta, rel_db)]."""
    k = rng.integers(1, kmax + 1)
    f = [rng.uniform(f_lo, 70)]
    for _ in range(k - 1):
        f.append(f[-1] * rng.uniform(1.4, 1.9))
    return [(fi, float(np.exp(rng.uniform(np.log(0.015), np.log(zeta_hi)))),
             float(rng.uniform(-4, 0))) for fi in f]


def write_case(out, manifest, name, seed, noise, modes, start, end, hps):
    """One raw recording (sweep_testset.py's model) and its manifest entry."""
    case = dict(name=name, axis="x", rate=3200.0, seed=seed, noise=noise,
                modes=[st.mode(a, b, c) for a, b, c in modes],
                excitation=st.exc(start, end, hps=hps), outputs=["raw"], note="")
    st.normalize_gains(case["modes"])
    case.setdefault("drift", dict(st.DRIFT))
    st.write_files(case, out)
    manifest.append(dict(name=name, modes=[[m["f"], m["zeta"]] for m in case["modes"]],
                         start=start, end=end))
    return case


def write_manifest(out, manifest):
    with open(os.path.join(out, "manifest.json"), "w") as fh:
        json.dump(manifest, fh, indent=1)


def main(out, n, seed):
    os.makedirs(out, exist_ok=True)
    rng = np.random.default_rng(seed)
    manifest = []
    for i in range(n):
        modes = draw_modes(rng, 2, 30, 0.12)
        start = 0.7 * modes[0][0]
        end = modes[-1][0] * rng.uniform(0.9, 1.25)
        name = "e%02d" % i
        case = write_case(out, manifest, name, 5000 + i + 100 * seed,
                          float(rng.uniform(150, 400)), modes, start, end, 2.0)
        print(name, "%.1f-%.1f Hz" % (start, end),
              ", ".join("%.1f Hz zeta %.3f" % (m["f"], m["zeta"]) for m in case["modes"]))
    write_manifest(out, manifest)


FLAT = [([(250.0, 0.05, 0.0)], 30.0, 80.0), ([(300.0, 0.03, 0.0)], 20.0, 120.0),
        ([(8.0, 0.05, 0.0)], 30.0, 80.0), ([(260.0, 0.05, 0.0)], 5.0, 60.0)]


def flat(out):
    os.makedirs(out, exist_ok=True)
    manifest = []
    for i, (modes, start, end) in enumerate(FLAT):
        write_case(out, manifest, "e%02d" % i, 700 + i, 200.0, modes, start, end, 2.0)
    write_manifest(out, manifest)


def short(out, n, seed):
    os.makedirs(out, exist_ok=True)
    rng = np.random.default_rng(seed)
    manifest = []
    for i in range(n):
        modes = draw_modes(rng, 3, 25, 0.15)
        start, end = 0.7 * modes[0][0], 1.3 * modes[-1][0]
        duration = float(rng.uniform(1.5, 5.0))
        name = "s%02d" % i
        case = write_case(out, manifest, name, 9000 + i + 100 * seed,
                          float(rng.uniform(150, 400)), modes, start, end,
                          (end - start) / duration)
        print(name, "%.1f-%.1f Hz in %.1f s" % (start, end, duration),
              ", ".join("%.1f Hz zeta %.3f" % (m["f"], m["zeta"]) for m in case["modes"]))
    write_manifest(out, manifest)


if __name__ == "__main__":
    if "--short" in sys.argv[1:]:
        a = [x for x in sys.argv[1:] if x != "--short"]
        short(a[0] if a else "/tmp/raw_short", int(a[1]) if len(a) > 1 else 16,
              int(a[2]) if len(a) > 2 else 1)
        sys.exit(0)
    if "--flat" in sys.argv[1:]:
        flat(next((a for a in sys.argv[1:] if a != "--flat"), "/tmp/raw_flat"))
        sys.exit(0)
    args = sys.argv[1:]
    main(args[0] if args else "/tmp/raw_ends", int(args[1]) if len(args) > 1 else 20,
         int(args[2]) if len(args) > 2 else 3)
