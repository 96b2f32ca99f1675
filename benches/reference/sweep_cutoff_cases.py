#!/usr/bin/env python3
"""Klipper resonances files swept to 133.33 Hz (Klipper 2021-2023's default band) with modes in
the band and past its end, simulated by sweep_testset.py's time-domain model (the resonance
test's excitation, exact integration, the sensor, scipy's Welch as Klipper computes it), so
independent of the identification code.  A check of issue 20's cut-off report, not part of
the test set: the files are written to a scratch directory and read by the crate with

    python3 benches/reference/sweep_cutoff_cases.py /tmp/cutoff
    REAL_KLIPPER_DIR=/tmp/cutoff cargo test --release --test identify_real -- --ignored --nocapture

(docs/measured-data.md, *On real recordings*, the cut-off report).  numpy + scipy.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sweep_testset as st  # noqa: E402

# name, [(f Hz, zeta, peak relative to the first mode, dB)]
CASES = [
    ("c1", [(48.0, 0.06, 0.0), (145.0, 0.05, 6.0)]),
    ("c2", [(62.0, 0.08, 0.0), (150.0, 0.04, 4.0)]),
    ("c3", [(140.0, 0.05, 0.0)]),
    ("c4", [(55.0, 0.05, 0.0), (118.0, 0.04, -2.0)]),
    ("c5", [(40.0, 0.07, 0.0), (95.0, 0.05, -3.0), (160.0, 0.06, 3.0)]),
    ("c6", [(72.0, 0.1, 0.0), (138.0, 0.03, 0.0)]),
]


def main(out):
    os.makedirs(out, exist_ok=True)
    for i, (name, modes) in enumerate(CASES):
        case = dict(name=name, axis="x", rate=3200.0, seed=900 + i, noise=150.0,
                    modes=[st.mode(f, z, db) for f, z, db in modes],
                    excitation=st.exc(5.0, 133.33), outputs=["resonances"],
                    note="sweep 5-133.33 Hz, modes in the band and past its end")
        st.normalize_gains(case["modes"])
        case.setdefault("drift", dict(st.DRIFT))
        files = st.write_files(case, out)
        print(name, files["resonances"],
              ", ".join("%.1f Hz zeta %.3f (%.1f dB)" % (m["f"], m["zeta"], m["peak_db"])
                        for m in case["modes"]))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "/tmp/cutoff")
