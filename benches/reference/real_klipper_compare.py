#!/usr/bin/env python3
"""Compare the crate's reproduction of Klipper's pick with klipper_reference.py on real files.

    node benches/real_klipper.mjs --json ours.json DIR
    python3 benches/reference/real_klipper_compare.py ours.json DIR

For every file of DIR in ours.json, runs klipper_reference.py on it (as `calibrate_shaper.py
FILE` would: current definitions and selection, max_freq 200, SCV 5) and prints the recommended
shaper of both and the largest differences over the families (frequency, vibrations,
smoothing, relative score).
"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import klipper_reference as kr  # noqa: E402


def main(ours_path, directory):
    ours = json.load(open(ours_path))
    same = 0
    rows = [r for r in ours if "klipperPick" in r]
    for r in rows:
        path = os.path.join(directory, r["file"])
        datasets = kr.parse_file(path)
        best, picks, _ = kr.best_shaper(datasets, kr.AUTOTUNE_SHAPERS, 5.0)
        k = r["klipperPick"]
        ok = k["name"] == best.name and abs(k["freq"] - best.freq) < 1e-6
        same += ok
        d_f = d_v = d_s = d_score = 0.0
        for mine, ref in zip(k["families"], picks):
            d_f = max(d_f, abs(mine["freq"] - ref.freq))
            d_v = max(d_v, abs(mine["vibr"] - ref.vibrs))
            d_s = max(d_s, abs(mine["smoothing"] - ref.smoothing))
            d_score = max(d_score, abs(mine["score"] / ref.score - 1))
        print("%-52s ours %-8s %6.1f  reference %-8s %6.1f  %s  max |df| %.1e |dv| %.1e "
              "|ds| %.1e score rel %.1e" % (r["file"], k["name"], k["freq"], best.name,
                                            best.freq, "same" if ok else "DIFFERENT",
                                            d_f, d_v, d_s, d_score))
    print("%d of %d recommended shapers equal (family and frequency)" % (same, len(rows)))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
