//! Timing of Klipper's recommendation (issue 20 item 7): a spectrum file of the test set to
//! Klipper's fit of its five autotuned families (criterion). The numpy side of the comparison is
//! benches/reference/klipper_reference.py on the same files (benches/klipper_bench.sh runs both;
//! docs/measured-data.md has the figures).

// criterion is a native-only dev-dependency: on wasm32 this bench compiles to an empty program.
#[cfg(not(target_arch = "wasm32"))]
mod native {
    use criterion::Criterion;
    use input_shaping::measure::klipper::{find_best_shaper, CalibrationData, Dataset, FitOptions};
    use std::hint::black_box;

    /// A `freq,psd_x,psd_y,psd_z,psd_xyz` file of the test set, as calibrate_shaper.py reads it.
    fn read(name: &str) -> CalibrationData {
        let path = format!("{}/tests/data/klipper/{name}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(path).expect("test-set file");
        let rows: Vec<Vec<f64>> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse().expect("number")).collect())
            .collect();
        let col = |i: usize| rows.iter().map(|r| r[i]).collect::<Vec<f64>>();
        let xyz = Some([col(1), col(2), col(3)]);
        let mut d = CalibrationData::new(
            Dataset::new(name, col(0), col(4), xyz, false).expect("valid spectrum"),
        );
        d.normalize_to_frequencies();
        d
    }

    pub fn main() {
        let mut c = Criterion::default().configure_from_args();
        let mut g = c.benchmark_group("klipper");
        for name in [
            "resonances_x_m1.csv",
            "resonances_x_z018f61.csv",
            "resonances_y_z020f61.csv",
        ] {
            let data = read(name);
            g.bench_function(format!("find_best_shaper {name}"), |b| {
                b.iter(|| find_best_shaper(black_box(&data), &FitOptions::default()))
            });
        }
        g.finish();
        c.final_summary();
    }
}

fn main() {
    #[cfg(not(target_arch = "wasm32"))]
    native::main();
}
