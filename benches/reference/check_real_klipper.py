#!/usr/bin/env python3
"""Check klipper_reference.py against a real Klipper calibration_data_*.csv.

A SHAPER_CALIBRATE file records, in its header, the frequency Klipper picked for every family
(`zv(61.6)`, ...) and, in its columns, each pick's vibration-reduction curve.  This script refits
the file's (already normalised) PSD with klipper_reference.py and compares both.

    python3 benches/reference/check_real_klipper.py FILE [--scv 5] [--max_freq F]
        [--defs classic|current] [--legacy | --no-legacy]

Files of Klipper's 2021-2023 releases have no `shapers:` column; their shaper columns are on the
PSD bins; they were fitted with the closed-form EI shapers and the older selection rule, over
bins up to 200 Hz: for them the defaults are --defs classic --legacy --max_freq 200.  Newer files
(`shapers:` column) default to --defs current, the current rule and max_freq 300 (1.5 x the
default FREQ_END); their shaper columns are on a 0.2 Hz grid and are not checked.

Result on two public files of 2023-11-28 (repository agravelot/voron2-config, commit
f2cff10d26758815462e7653aa368f56e2ceb53a, input_shaper_history/20231128_184928/
calibration_data_{x,y}_*.csv; not copied into this repository): 8 of 10 family frequencies
equal; ei on Y 44.0 vs 43.6 Hz and 2hump_ei on X 93.2 vs 93.4 Hz, both where the remaining
vibrations of neighbouring frequencies differ by 1e-5 or less (below the file's 4-digit
rounding of the PSD and 0.1 Hz rounding of the bins); all shaper columns within 0.003 of the
curves recomputed at the recorded frequencies (0.001 is the printed precision).
"""
import argparse
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import klipper_reference as kr  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("file")
    ap.add_argument("--scv", type=float, default=5.0)
    ap.add_argument("--max_freq", type=float)
    ap.add_argument("--defs", choices=sorted(kr.DEFS))
    ap.add_argument("--legacy", dest="legacy", action="store_true", default=None)
    ap.add_argument("--no-legacy", dest="legacy", action="store_false")
    a = ap.parse_args(argv)
    with open(a.file) as fh:
        header = next(line for line in fh if not line.startswith("#"))
    new = ",shapers:" in header
    labels = re.findall(r"([0-9a-z_]+)\(([0-9.]+)\)", header)
    defs = a.defs or ("current" if new else "classic")
    legacy = (not new) if a.legacy is None else a.legacy
    max_freq = a.max_freq or (300.0 if new else 200.0)
    d = np.genfromtxt(a.file, delimiter=",", skip_header=1, filling_values=0.0)
    ds = kr.Dataset(a.file, d[:, 0], d[:, 4], d[:, 1], d[:, 2], d[:, 3])
    ds.normalized = True
    names = [n for n, _ in labels]
    best, picks, _ = kr.best_shaper([ds], names, a.scv, max_freq=max_freq, defs=defs,
                                    legacy=legacy)
    print("%s: defs=%s legacy=%s max_freq=%g scv=%g" % (a.file, defs, legacy, max_freq, a.scv))
    first_shaper_col = 6 if new else 5
    same = 0
    for j, ((name, f_k), p) in enumerate(zip(labels, picks)):
        f_k = float(f_k)
        ok = abs(round(float(p.freq), 1) - f_k) < 0.05
        same += ok
        line = "  %-9s klipper %6.1f  reference %6.1f  %s" % (name, f_k, p.freq,
                                                             "same" if ok else "DIFFERENT")
        if not new:
            sh = kr.DEFS[defs][name][0](f_k, kr.DEFAULT_DAMPING_RATIO)
            v = np.max([kr.shaper_response(sh, z, d[:, 0]) for z in kr.TEST_DAMPING_RATIOS],
                       axis=0)
            line += "   max |V - column| %.3f" % np.max(np.abs(v - d[:, first_shaper_col + j]))
        print(line)
    print("  %d of %d family frequencies equal; reference best: %s @ %.1f Hz"
          % (same, len(labels), best.name, best.freq))


if __name__ == "__main__":
    main(sys.argv[1:])
