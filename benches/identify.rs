//! Timing of mode identification (issue 20): `identify` on the test set's raw sweep recordings
//! and `identify_spectrum` on its resonances files (criterion), default options. Compare two
//! commits side by side with criterion's baselines: `cargo bench --bench identify --
//! --save-baseline before` on one, `cargo bench --bench identify -- --baseline before` on the
//! other (docs/measured-data.md, *Speed of identification*, has the figures).

// criterion is a native-only dev-dependency: on wasm32 this bench compiles to an empty program.
#[cfg(not(target_arch = "wasm32"))]
mod native {
    use criterion::Criterion;
    use input_shaping::measure::identify::{identify, identify_spectrum, IdentifyOptions};
    use input_shaping::measure::recording::{parse_file, Parsed};
    use input_shaping::measure::RecordingOptions;
    use std::hint::black_box;

    fn read(name: &str) -> Parsed {
        let path = format!("{}/tests/data/klipper/{name}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(path).expect("test-set file");
        let options = RecordingOptions {
            file_name: Some(name.into()),
            ..RecordingOptions::default()
        };
        parse_file(&text, &options).expect("a Klipper file")
    }

    pub fn main() {
        let mut c = Criterion::default().configure_from_args();
        let mut g = c.benchmark_group("identify");
        g.sample_size(10);
        for name in [
            "raw_data_x_single47z08.csv",
            "raw_data_y_two38x14.csv",
            "raw_data_x_z018f61.csv",
            "resonances_y_three.csv",
            "resonances_y_two38x14.csv",
            "resonances_x_cliff133.csv",
        ] {
            match read(name) {
                Parsed::Recording(r) => {
                    let channel = if name.contains("_y_") {
                        "accel_y"
                    } else {
                        "accel_x"
                    };
                    let x = r
                        .channel(channel)
                        .expect("the axis's channel")
                        .values
                        .clone();
                    let options = IdentifyOptions::new(r.sample_rate_hz);
                    g.bench_function(name, |b| {
                        b.iter(|| identify(black_box(&x), &options).expect("identified"))
                    });
                }
                Parsed::Spectrum(s) => {
                    let options = IdentifyOptions::default();
                    g.bench_function(name, |b| {
                        b.iter(|| identify_spectrum(black_box(&s), &options))
                    });
                }
            }
        }
        g.finish();
        c.final_summary();
    }
}

fn main() {
    #[cfg(not(target_arch = "wasm32"))]
    native::main();
}
