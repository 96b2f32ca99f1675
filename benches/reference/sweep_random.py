#!/usr/bin/env python3
"""Random machines through Klipper's resonance test: an independent check of the spectrum
identification beyond the fixed test set (issue 20), not part of `npm test`.

sweep_testset.py's time-domain model (the resonance test's excitation, exact integration, the
sensor, scipy's Welch as Klipper computes it) on N machines drawn at random from a seed: 1-3
modes (1: 40 %, 2: 40 %, 3: 20 %), the lowest at 25-90 Hz, each next one 1.3-2.0 times the
previous, damping ratios log-uniform in 0.015-0.15, peaks 0 to -6 dB under the first's; swept
5-200 Hz (Klipper's current default) or 5-133.33 Hz (its releases of 2021-2023), every mode's
half-power band under the end by 5 %.  Writes resonances and calibration_data files and a
manifest in the test set's format.  With --hard: modes 1.2-2.0 apart and down to -10 dB,
noise 150-600 mm/s^2, and a third of the machines recorded raw (and as resonances) on a
short sweep at 2 Hz/s from 0.75 times the lowest mode to 1.3 times the highest.  With
--rates: each sensor's sample rate drawn in 3000-3300 Hz (real ADXL345s run off their nominal
3200 Hz: a Voron's files show f_s = 3070 Hz, whose 1.4991 Hz bins Klipper writes 1.5 apart with
an occasional 1.4), from an RNG of its own, so the machines are those of the same seed without
it.  With --whole-raw (instead of --hard): each machine, hard or not at even odds, recorded raw
over Klipper's whole test from 5 Hz at 1, 2 or 4 Hz/s and written as a resonances file too
(draw_whole_raw):

    python3 benches/reference/sweep_random.py OUT [N] [SEED] [--hard] [--rates] [--whole-raw]
    SWEEP_RANDOM_DIR=OUT cargo test --release --test measure_testset -- --ignored random --nocapture

numpy + scipy.
"""
import json
import math
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sweep_testset as st  # noqa: E402


def draw(rng, i, hard=False):
    end = rng.choice([200.0, 133.33])
    n = rng.choices([1, 2, 3], weights=[4, 4, 2])[0]
    f = rng.uniform(25.0, 90.0)
    # hard: closer modes (1.2-2.0), weaker ones (to -10 dB), noise 150-600 mm/s^2, and a
    # third of the machines recorded raw on a short sweep at 2 Hz/s around their modes.
    ratio, weaker, noise = ((1.2, 2.0), -10.0, rng.uniform(150.0, 600.0)) if hard else \
        ((1.3, 2.0), -6.0, 150.0)
    raw = hard and rng.random() < 1 / 3
    modes = []
    for k in range(n):
        zeta = math.exp(rng.uniform(math.log(0.015), math.log(0.15)))
        if f * (1 + 3 * zeta) > 0.95 * end:
            break
        modes.append(st.mode(round(f, 2), round(zeta, 4),
                             0.0 if k == 0 else rng.uniform(weaker, 0)))
        f *= rng.uniform(*ratio)
    st.normalize_gains(modes)
    if raw:
        lo = max(5.0, min(m["f"] for m in modes) * 0.75)
        hi = max(m["f"] for m in modes) * 1.3
        excitation, outputs = st.exc(round(lo, 1), round(hi, 1), hps=2.0), ["raw", "resonances"]
    else:
        excitation, outputs = st.exc(5.0, end), ["resonances", "calibration_data"]
    return dict(name="r%02d" % i, axis=rng.choice("xy"), rate=3200.0, seed=5000 + i,
                noise=round(noise, 1), modes=modes, excitation=excitation, outputs=outputs,
                drift=dict(st.DRIFT), note="random machine %d, sweep %g-%g Hz" % (
                    i, excitation["freq_start"], excitation["freq_end"]))


def draw_whole_raw(rng, i):
    """--whole-raw: a machine of `draw` (hard or not, even odds), recorded raw over Klipper's
    whole test from 5 Hz (to the machine's own end, or 133.33 / 200 Hz for the short-sweep
    machines) at 1, 2 or 4 Hz/s (1 twice as often), and written as a resonances file too."""
    case = draw(rng, i, hard=rng.random() < 0.5)
    ex = case["excitation"]
    end = ex["freq_end"] if ex["freq_start"] == 5.0 else rng.choice([133.33, 200.0])
    hps = rng.choice([1.0, 1.0, 2.0, 4.0])
    case["excitation"] = st.exc(5.0, end, hps=hps)
    case["outputs"] = ["raw", "resonances"]
    case["name"] = "f%02d" % i
    case["note"] = "random machine %d, raw, sweep 5-%g Hz at %g Hz/s" % (i, end, hps)
    return case


def main(out, n=16, seed=1, hard=False, rates=False, whole_raw=False):
    os.makedirs(out, exist_ok=True)
    rng = random.Random(seed)
    rate_rng = random.Random(seed * 1000003 + 17)
    manifest = {}
    for i in range(n):
        case = draw_whole_raw(rng, i) if whole_raw else draw(rng, i, hard)
        if rates:
            case["rate"] = round(rate_rng.uniform(3000.0, 3300.0), 1)
        files = st.write_files(case, out)
        entry = {k: v for k, v in case.items() if not k.startswith("_") and k != "outputs"}
        entry["files"] = {k: v for k, v in files.items()
                          if k in ("raw", "resonances", "calibration_data")}
        manifest[case["axis"] + "_" + case["name"]] = entry
        print(case["name"], case["excitation"]["freq_start"], case["excitation"]["freq_end"],
              case["noise"],
              ", ".join("%.1f Hz zeta %.3f (%.1f dB)" % (m["f"], m["zeta"], m["peak_db"])
                        for m in case["modes"]), flush=True)
    with open(os.path.join(out, "manifest.json"), "w") as fh:
        json.dump({"generator": "benches/reference/sweep_random.py", "seed": seed, "hard": hard,
                   "rates": rates, "cases": manifest}, fh, indent=1, sort_keys=True)


if __name__ == "__main__":
    hard = "--hard" in sys.argv
    rates = "--rates" in sys.argv
    whole_raw = "--whole-raw" in sys.argv
    a = [x for x in sys.argv[1:] if x not in ("--hard", "--rates", "--whole-raw")]
    main(a[0] if a else "/tmp/sweep_random", int(a[1]) if len(a) > 1 else 16,
         int(a[2]) if len(a) > 2 else 1, hard, rates, whole_raw)
