//! Timing of the analysis functions (criterion). Run with `npm run bench` (benches/run.sh),
//! which also runs the numpy baseline (benches/map_numpy.py) and prints the comparison.
//!
//! Besides timing, this writes `target/bench/map.json`: the shaper, the map's options and the
//! map itself, so the numpy script can check that it computes the same numbers (to 1e-9).

// criterion is a native-only dev-dependency: on wasm32 (`cargo clippy --target wasm32-unknown-unknown
// --all-targets`) this bench compiles to an empty program.
#[cfg(not(target_arch = "wasm32"))]
mod native {
    use criterion::Criterion;
    use input_shaping::design::zero_vibration::zvd;
    use input_shaping::design::{design_for, ShaperSpec};
    use input_shaping::vibration::{
        damping_sensitivity, insensitivities, insensitivity, insensitivity_full_scan, sensitivity,
        sensitivity_map, vibration_rad, DampingSensitivityOptions, SensitivityMapOptions,
        SensitivityOptions,
    };
    use input_shaping::{Mode, Shaper};
    use std::hint::black_box;

    /// A 9-impulse shaper: ZVD for 1 Hz, ζ = 0.05 convolved with ZVD for 2.7 Hz, ζ = 0.02.
    fn nine_impulses() -> Shaper {
        let a = zvd(&Mode::new(1.0, 0.05).expect("valid mode")).expect("ZVD designs");
        let b = zvd(&Mode::new(2.7, 0.02).expect("valid mode")).expect("ZVD designs");
        a.convolve(&b).expect("9 impulses")
    }

    /// The benchmarked map: 400 frequencies (0 … 5 Hz) × 200 damping ratios (0 … 0.3).
    const MAP: SensitivityMapOptions = SensitivityMapOptions {
        from_hz: 0.0,
        to_hz: 5.0,
        frequency_points: 400,
        damping_from: 0.0,
        damping_to: 0.3,
        damping_points: 200,
    };

    /// The same map point by point through `vibration_rad` (what the fast path replaces).
    fn map_direct(shaper: &Shaper, o: &SensitivityMapOptions) -> Vec<f64> {
        let step_f = (o.to_hz - o.from_hz) / (o.frequency_points - 1) as f64;
        let step_z = (o.damping_to - o.damping_from) / (o.damping_points - 1) as f64;
        let mut out = Vec::with_capacity(o.frequency_points * o.damping_points);
        for k in 0..o.damping_points {
            let zeta = o.damping_from + step_z * k as f64;
            for j in 0..o.frequency_points {
                let f = o.from_hz + step_f * j as f64;
                out.push(vibration_rad(
                    shaper.impulses(),
                    2.0 * std::f64::consts::PI * f,
                    zeta,
                ));
            }
        }
        out
    }

    /// The benchmarked sensitivity curve: 1000 frequencies (0 … 5 Hz) at ζ = 0.05.
    const CURVE: SensitivityOptions = SensitivityOptions {
        from_hz: 0.0,
        to_hz: 5.0,
        points: 1000,
        damping: 0.05,
    };

    fn write_reference(shaper: &Shaper) {
        let map = sensitivity_map(shaper, &MAP).expect("the benchmark map is valid");
        let curve = sensitivity(shaper, &CURVE).expect("the benchmark curve is valid");
        let json = serde_json::json!({
            "shaper": shaper.to_data(),
            "options": MAP,
            "map": map,
            "curveOptions": CURVE,
            "curve": curve,
        });
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench");
        let written = std::fs::create_dir_all(&dir)
            .and_then(|_| std::fs::write(dir.join("map.json"), json.to_string()));
        if let Err(e) = written {
            eprintln!("could not write {}: {e}", dir.join("map.json").display());
        }
    }

    fn bench(c: &mut Criterion) {
        let shaper = nine_impulses();
        assert_eq!(shaper.len(), 9);
        write_reference(&shaper);

        c.bench_function("sensitivity_map 400x200, 9 impulses", |b| {
            b.iter(|| sensitivity_map(black_box(&shaper), black_box(&MAP)))
        });
        c.bench_function("map point by point 400x200, 9 impulses", |b| {
            b.iter(|| map_direct(black_box(&shaper), black_box(&MAP)))
        });
        c.bench_function("sensitivity 1000 points, 9 impulses", |b| {
            b.iter(|| sensitivity(black_box(&shaper), black_box(&CURVE)))
        });
        let damping = DampingSensitivityOptions {
            frequency_hz: 1.0,
            from_damping: 0.0,
            to_damping: 0.3,
            points: 1000,
        };
        c.bench_function("damping_sensitivity 1000 points, 9 impulses", |b| {
            b.iter(|| damping_sensitivity(black_box(&shaper), black_box(&damping)))
        });
        insensitivity_six_modes(c);
    }

    /// I(Vtol 5 %) at issue 24's six modes (1.2 … 34 Hz, ζ 0.02) of the page's four convolved
    /// shapers: the full scan each mode (the path before the decay bound), the bounded scan each
    /// mode, and the six bands scanned jointly (what the page calls).
    fn insensitivity_six_modes(c: &mut Criterion) {
        let modes: Vec<Mode> = [1.2, 3.4, 7.9, 13.0, 21.0, 34.0]
            .iter()
            .map(|&f| Mode::new(f, 0.02).expect("valid mode"))
            .collect();
        let specs = [
            ("ZV", ShaperSpec::Zv),
            ("ZVD", ShaperSpec::Zvd),
            ("ZVDD", ShaperSpec::Zvdd),
            ("ZV-D3", ShaperSpec::Zvdn { derivatives: 3 }),
        ];
        for (name, spec) in specs {
            let shaper = design_for(&spec, &modes).expect("six-mode design");
            c.bench_function(&format!("I(Vtol) six modes {name}, full scan"), |b| {
                b.iter(|| {
                    modes
                        .iter()
                        .map(|m| insensitivity_full_scan(black_box(&shaper), m, 0.05))
                        .collect::<Vec<_>>()
                })
            });
            c.bench_function(&format!("I(Vtol) six modes {name}, bounded"), |b| {
                b.iter(|| {
                    modes
                        .iter()
                        .map(|m| insensitivity(black_box(&shaper), m, 0.05))
                        .collect::<Vec<_>>()
                })
            });
            c.bench_function(&format!("I(Vtol) six modes {name}, joint"), |b| {
                b.iter(|| insensitivities(black_box(&shaper), &modes, 0.05))
            });
        }
    }

    /// The criterion group, configured for a shared machine (1 s warm-up, 3 s measurement).
    pub fn benches() {
        let mut criterion = Criterion::default()
            .warm_up_time(std::time::Duration::from_secs(1))
            .measurement_time(std::time::Duration::from_secs(3))
            .configure_from_args();
        bench(&mut criterion);
        criterion.final_summary();
    }
}

#[cfg(not(target_arch = "wasm32"))]
fn main() {
    native::benches();
}

#[cfg(target_arch = "wasm32")]
fn main() {}
