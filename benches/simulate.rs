//! Benchmarks (not tests): the streaming shaper's throughput and the exact simulation against
//! scipy.signal.lsim (run `python3 benches/lsim_scipy.py` side by side; see docs/benchmarks.md).
//!
//! `cargo bench --bench simulate`

// Native only: criterion is not a wasm dependency (`cargo clippy --target wasm32 --all-targets`
// still compiles this file, to an empty main).
#[cfg(not(target_arch = "wasm32"))]
mod native {
    use criterion::{criterion_group, Criterion, Throughput};
    use input_shaping::command::{Command, CommandSpec, Interpolation, Sampled, StreamingShaper};
    use input_shaping::design::design_for;
    use input_shaping::design::zero_vibration::zv_dn;
    use input_shaping::plant::{ModalPlant, Plant};
    use input_shaping::scenario::{run, SimulationSpec};
    use input_shaping::simulate::{simulate, simulate_shaped};
    use input_shaping::{Mode, ShaperSpec};
    use std::hint::black_box;

    fn streaming(c: &mut Criterion) {
        // A 5-impulse shaper (ZV-D³) at 10 kHz, delays deliberately fractional: 10 taps.
        let shaper = zv_dn(&Mode::new(13.7, 0.03).unwrap(), 3).unwrap();
        assert_eq!(shaper.len(), 5);
        let n = 1 << 20;
        let input: Vec<f64> = (0..n).map(|k| ((k % 1000) as f64).sqrt()).collect();
        let mut output = vec![0.0; n];
        let mut g = c.benchmark_group("streaming_shaper_5_impulses");
        g.throughput(Throughput::Elements(n as u64));
        g.bench_function("block", |b| {
            let mut f = StreamingShaper::new(&shaper, 1e-4).unwrap();
            b.iter(|| {
                f.process(black_box(&input), &mut output);
                black_box(output[n - 1])
            })
        });
        g.bench_function("push", |b| {
            let mut f = StreamingShaper::new(&shaper, 1e-4).unwrap();
            b.iter(|| {
                let mut acc = 0.0;
                for &x in black_box(&input) {
                    acc += f.push(x);
                }
                black_box(acc)
            })
        });
        g.finish();
    }

    /// The same system and input as benches/lsim_scipy.py: three modes (1.2 Hz ζ 0.012, 3.4 Hz
    /// ζ 0.013, 7 Hz ζ 0.02, participation ⅓ each), u = clip(t, 0, 1) sampled at 1 kHz for 10 s
    /// and read linearly between samples (lsim's first-order hold).
    fn modal_10s_1khz(c: &mut Criterion) {
        let plant = Plant::Modal(
            ModalPlant::new(
                vec![
                    Mode::new(1.2, 0.012).unwrap(),
                    Mode::new(3.4, 0.013).unwrap(),
                    Mode::new(7.0, 0.02).unwrap(),
                ],
                vec![1.0 / 3.0; 3],
            )
            .unwrap(),
        );
        let values: Vec<f64> = (0..10_000).map(|k| (k as f64 * 1e-3).min(1.0)).collect();
        let cmd = Command::Sampled(Sampled::new(1e-3, values, Interpolation::Linear).unwrap());
        let t = simulate(&plant, &cmd, 1e-3, 9.999).unwrap();
        println!(
            "endpoint at t = 1, 5, 9.999 s: {:.12} {:.12} {:.12} (compare with lsim_scipy.py)",
            t.endpoint[1000], t.endpoint[5000], t.endpoint[9999]
        );
        c.bench_function("simulate_3_modes_10s_at_1kHz", |b| {
            b.iter(|| black_box(simulate(&plant, black_box(&cmd), 1e-3, 9.999).unwrap()))
        });
    }

    /// What one page frame costs: a shaped and an unshaped S-curve on the Veciana test bed, 2000
    /// samples each, with metrics.
    fn page_frame(c: &mut Criterion) {
        let spec: SimulationSpec = serde_json::from_str(
            r#"{"plant":{"kind":"vecianaTestBed"},
                "command":{"kind":"sCurve","distance":1,"maxVelocity":1,"maxAcceleration":4,"maxJerk":40},
                "shaper":{"family":"zvd"}}"#,
        )
        .unwrap();
        c.bench_function("run_page_frame_2000_samples", |b| {
            b.iter(|| black_box(run(black_box(&spec)).unwrap()))
        });
    }

    /// Issue 24's six modes (1.2 … 34 Hz, ζ 0.02) on the page: the trapezoid shaped by ZV, ZVD,
    /// ZVDD and ZV-D³ over them (64 … 15 625 impulses) and simulated from the shapers' factors
    /// on the plant with every mode 1.1 times higher, 1000 samples over 6 s — the four shaped
    /// responses of a six-mode frame (`simulate_shaped`, `Lti::respond_shaped`; the figures of
    /// docs/page-performance.md, *2026-12-07, later*, were taken by a throwaway binary of the
    /// same case).
    fn six_mode_shaped_responses(c: &mut Criterion) {
        let freqs = [1.2, 3.4, 7.9, 13.0, 21.0, 34.0];
        let modes: Vec<Mode> = freqs.iter().map(|&f| Mode::new(f, 0.02).unwrap()).collect();
        let shapers: Vec<_> = [
            ShaperSpec::Zv,
            ShaperSpec::Zvd,
            ShaperSpec::Zvdd,
            ShaperSpec::Zvdn { derivatives: 3 },
        ]
        .iter()
        .map(|s| design_for(s, &modes).unwrap())
        .collect();
        let plant_modes = freqs
            .iter()
            .map(|&f| Mode::new(1.1 * f, 0.02).unwrap())
            .collect();
        let plant = Plant::Modal(ModalPlant::new(plant_modes, vec![1.0 / 6.0; 6]).unwrap());
        let cmd = Command::from_spec(&CommandSpec::Trapezoid {
            distance: 1.0,
            max_velocity: 0.75,
            max_acceleration: 8.0,
            start: 0.0,
        })
        .unwrap();
        c.bench_function("simulate_shaped_6_modes_4_shapers", |b| {
            b.iter(|| {
                for s in &shapers {
                    black_box(simulate_shaped(&plant, &cmd, s, 6.0 / 999.0, 6.0).unwrap());
                }
            })
        });
    }

    criterion_group!(
        benches,
        streaming,
        modal_10s_1khz,
        page_frame,
        six_mode_shaped_responses
    );
}

#[cfg(not(target_arch = "wasm32"))]
criterion::criterion_main!(native::benches);

#[cfg(target_arch = "wasm32")]
fn main() {}
