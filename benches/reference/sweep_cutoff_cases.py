#!/usr/bin/env python3
"""Klipper resonances files swept to 133.33 Hz (Klipper 2021-2023's default band) with modes in
the band and past its end, simulated by sweep_testset.py's time-domain model (the resonance
test's excitation, exact integration, the sensor, scipy's Welch as Klipper computes it), so
independent of the identification code.  A check of issue 20's cut-off report, not part of
the test set: the files are written to a scratch directory and read by the crate with

    python3 benches/reference/sweep_cutoff_cases.py /tmp/cutoff
    REAL_KLIPPER_DIR=/tmp/cutoff cargo test --release --test identify_real -- --ignored --nocapture

(docs/measured-data.md, *On real recordings*, the cut-off report).  With `--raw`, each file is
also written as Klipper's raw recording, and short raw sweeps ending at a mode are added
(RAW_CASES); `identify_real` reads the raw files too.  numpy + scipy.
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


# Raw recordings of short sweeps at 2 Hz/s ending at or just past a mode: name, sweep start and
# end Hz, modes as above.
RAW_CASES = [
    ("r1", 40.0, 60.0, [(59.75, 0.02, 0.0)]),
    ("r2", 45.0, 60.0, [(59.75, 0.02, 0.0)]),
    ("r3", 44.8, 62.0, [(59.75, 0.02, 0.0)]),
    ("r4", 30.0, 70.0, [(41.0, 0.05, 0.0), (72.0, 0.04, 0.0)]),
    ("r5", 30.0, 70.0, [(41.0, 0.05, 0.0), (68.0, 0.03, 0.0)]),
    ("r6", 30.0, 80.0, [(41.0, 0.05, 0.0), (66.0, 0.04, -3.0)]),
]


def main(out, raw):
    os.makedirs(out, exist_ok=True)
    todo = [(name, 5.0, 133.33, modes, 1.0) for name, modes in CASES]
    if raw:
        todo += [(name, a, b, modes, 2.0) for name, a, b, modes in RAW_CASES]
    for i, (name, start, end, modes, rate) in enumerate(todo):
        outputs = ["resonances", "raw"] if raw else ["resonances"]
        case = dict(name=name, axis="x", rate=3200.0, seed=900 + i, noise=150.0,
                    modes=[st.mode(f, z, db) for f, z, db in modes],
                    excitation=st.exc(start, end, hps=rate), outputs=outputs,
                    note="sweep %g-%g Hz, modes in the band and past its end" % (start, end))
        st.normalize_gains(case["modes"])
        case.setdefault("drift", dict(st.DRIFT))
        files = st.write_files(case, out)
        print(name, ", ".join(v for v in files.values() if isinstance(v, str)),
              ", ".join("%.1f Hz zeta %.3f (%.1f dB)" % (m["f"], m["zeta"], m["peak_db"])
                        for m in case["modes"]))


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--raw"]
    main(args[0] if args else "/tmp/cutoff", "--raw" in sys.argv[1:])
