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
    SWEEP_RAW_ENDS_DIR=OUT cargo test --release --test identify_raw_sweep -- --ignored --nocapture

numpy + scipy.
"""
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sweep_testset as st  # noqa: E402


def main(out, n, seed):
    os.makedirs(out, exist_ok=True)
    rng = np.random.default_rng(seed)
    manifest = []
    for i in range(n):
        k = rng.integers(1, 3)
        f = [rng.uniform(30, 70)]
        for _ in range(k - 1):
            f.append(f[-1] * rng.uniform(1.4, 1.9))
        modes = [(fi, float(np.exp(rng.uniform(np.log(0.015), np.log(0.12)))),
                  float(rng.uniform(-4, 0))) for fi in f]
        start = 0.7 * f[0]
        end = f[-1] * rng.uniform(0.9, 1.25)
        name = "e%02d" % i
        case = dict(name=name, axis="x", rate=3200.0, seed=5000 + i + 100 * seed,
                    noise=float(rng.uniform(150, 400)),
                    modes=[st.mode(a, b, c) for a, b, c in modes],
                    excitation=st.exc(start, end, hps=2.0), outputs=["raw"], note="")
        st.normalize_gains(case["modes"])
        case.setdefault("drift", dict(st.DRIFT))
        st.write_files(case, out)
        manifest.append(dict(name=name, modes=[[m["f"], m["zeta"]] for m in case["modes"]],
                             start=start, end=end))
        print(name, "%.1f-%.1f Hz" % (start, end),
              ", ".join("%.1f Hz zeta %.3f" % (m["f"], m["zeta"]) for m in case["modes"]))
    with open(os.path.join(out, "manifest.json"), "w") as fh:
        json.dump(manifest, fh, indent=1)


if __name__ == "__main__":
    args = sys.argv[1:]
    main(args[0] if args else "/tmp/raw_ends", int(args[1]) if len(args) > 1 else 20,
         int(args[2]) if len(args) > 2 else 3)
