//! Time per axis of the optimised shapers of issue 25 (crate/measure/optimal.rs), natively
//! (criterion): Klipper's own fit (the crate's reproduction of `find_best_shaper`, the baseline
//! every optimisation starts with), the best mainline-Klipper shaper, the custom shaper by the
//! continuation (the page's), and by the convex grid program. Spectrum:
//! tests/data/klipper/resonances_y_m1.csv (one machine's Y axis, 0.5 s Welch segments, 194
//! bins to 300 Hz). `cargo bench --bench optimal`. The numpy side by side:
//! `python3 benches/reference/optimal_reference.py FILE` (prints its own seconds).

#[cfg(not(target_arch = "wasm32"))]
mod native {
    use criterion::Criterion;
    use input_shaping::measure::klipper::{find_best_shaper, CalibrationData, Dataset, FitOptions};
    use input_shaping::measure::optimal::{optimal, CustomMethod, Firmware, OptimalOptions};
    use std::hint::black_box;

    fn read(path: &str) -> CalibrationData {
        let text = std::fs::read_to_string(path).expect("test-set file");
        let mut lines = text.lines();
        lines.next();
        let rows: Vec<Vec<f64>> = lines
            .filter(|l| !l.trim().is_empty())
            .map(|l| l.split(',').map(|x| x.parse().expect("number")).collect())
            .collect();
        let col = |i: usize| rows.iter().map(|r| r[i]).collect::<Vec<f64>>();
        let mut d = CalibrationData::new(
            Dataset::new(path, col(0), col(4), None, false).expect("valid spectrum"),
        );
        d.normalize_to_frequencies();
        d
    }

    pub fn benches(c: &mut Criterion) {
        let data = read("tests/data/klipper/resonances_y_m1.csv");
        let mut g = c.benchmark_group("optimal");
        g.sample_size(10);
        g.bench_function("klipper_fit", |b| {
            b.iter(|| find_best_shaper(black_box(&data), &FitOptions::default()))
        });
        for (name, firmware, method) in [
            ("mainline", Firmware::Klipper, CustomMethod::Continuation),
            (
                "custom_continuation",
                Firmware::Reprapfirmware,
                CustomMethod::Continuation,
            ),
            ("custom_grid", Firmware::Reprapfirmware, CustomMethod::Grid),
        ] {
            let options = OptimalOptions {
                firmware,
                custom_method: method,
                ..OptimalOptions::default()
            };
            g.bench_function(name, |b| {
                b.iter(|| optimal(black_box(&data), &[], &options).expect("optimises"))
            });
        }
        g.finish();
    }
}

#[cfg(not(target_arch = "wasm32"))]
criterion::criterion_group!(benches, native::benches);
#[cfg(not(target_arch = "wasm32"))]
criterion::criterion_main!(benches);

#[cfg(target_arch = "wasm32")]
fn main() {}
