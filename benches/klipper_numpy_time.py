"""Times benches/reference/klipper_reference.py's fit (numpy, calibrate_shaper.py's algorithm)
on the files benches/klipper.rs and benches/klipper_wasm.mjs time: the numpy side of the
comparison in docs/measured-data.md. Median and minimum of 5 runs (RUNS=n: n) after 1 warm-up,
the file read and normalised once outside the timing (as in the Rust and wasm figures).

    [RUNS=n] python3 benches/klipper_numpy_time.py [files…]
"""
import os
import sys
import time

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "reference"))
import klipper_reference as ref  # noqa: E402

files = sys.argv[1:] or ["resonances_x_m1.csv", "resonances_x_z018f61.csv",
                         "resonances_y_z020f61.csv", "calibration_data_x_m1.csv"]
for name in files:
    datasets = ref.parse_file(os.path.join(here, "..", "tests", "data", "klipper", name))
    times = []
    for i in range(1 + int(os.environ.get("RUNS", "5"))):
        t0 = time.perf_counter()
        out = ref.best_shaper(datasets)
        if i:
            times.append(time.perf_counter() - t0)
    times.sort()
    print(f"{name}: median {times[len(times) // 2] * 1e3:.0f} ms, min {times[0] * 1e3:.0f} ms")
