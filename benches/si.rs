//! Criterion benchmark of SI design: the Peláez & Singhose 2002 example (0.5 Hz, ζ = 0.002,
//! Vtol = 5 %, I = 0.7), sampled at six frequencies (the problem benches/si_slsqp.py solves
//! with scipy's SLSQP from random starts) and over the whole band.
//!
//! Also issue 24's three-mode case (1.2 / 3.4 / 7.9 Hz, ζ 0.02, I 0.3 and 0.7).
//!
//! `cargo bench --bench si` (native only). Compare with `python3 benches/si_slsqp.py`.

#![cfg_attr(target_arch = "wasm32", allow(unused))]

#[cfg(not(target_arch = "wasm32"))]
use criterion::{criterion_group, criterion_main, Criterion};
use input_shaping::design::specified::SiSpec;
use input_shaping::{design, DesignRequest, ModeSpec};
#[cfg(not(target_arch = "wasm32"))]
use std::hint::black_box;

fn request(sampled: bool) -> DesignRequest {
    SiSpec {
        insensitivity: Some(0.7),
        vtol: 0.05,
        sample_frequencies_hz: sampled.then(|| (0..6).map(|i| 0.325 + 0.07 * i as f64).collect()),
        ..Default::default()
    }
    .request(vec![ModeSpec {
        frequency_hz: 0.5,
        damping: 0.002,
    }])
}

/// Issue 24's multi-mode case: `si` over 1.2 / 3.4 / 7.9 Hz (ζ = 0.02 each, Vtol 5 %) at
/// insensitivity `i`.
fn three_modes(i: f64) -> DesignRequest {
    SiSpec {
        insensitivity: Some(i),
        vtol: 0.05,
        ..Default::default()
    }
    .request(
        [1.2, 3.4, 7.9]
            .map(|f| ModeSpec {
                frequency_hz: f,
                damping: 0.02,
            })
            .to_vec(),
    )
}

#[cfg(not(target_arch = "wasm32"))]
fn bench(c: &mut Criterion) {
    for (name, sampled) in [("si_sampled_six", true), ("si_whole_band", false)] {
        let req = request(sampled);
        let s = design(&req).expect("design");
        eprintln!(
            "{name}: duration {:.6} s, {} impulses: {:?}",
            s.duration(),
            s.len(),
            s.impulses()
                .iter()
                .map(|i| (i.time, i.amplitude))
                .collect::<Vec<_>>()
        );
        c.bench_function(name, |b| {
            b.iter(|| design(black_box(&req)).expect("design"))
        });
    }
}

/// The three-mode designs take 0.1–1 s each: ten samples. Each is timed twice in the same run:
/// with the current polish (`i0.3`) and with the polish before issue 24's speed work
/// (`i0.3_reference`: the four-point Hessian stencil, a fixed null-step cap, four chord
/// iterations per trial point, the first split start that converges), selected by
/// `input_shaping::solve::set_reference_polish`.
#[cfg(not(target_arch = "wasm32"))]
fn bench_three_modes(c: &mut Criterion) {
    let mut group = c.benchmark_group("si_three_modes");
    group.sample_size(10);
    for i in [0.3, 0.7] {
        let req = three_modes(i);
        for (suffix, reference) in [("_reference", true), ("", false)] {
            input_shaping::solve::set_reference_polish(reference);
            let s = design(&req).expect("design");
            eprintln!(
                "si three modes I {i}{suffix}: duration {:.6} s, {} impulses",
                s.duration(),
                s.len()
            );
            group.bench_function(format!("i{i}{suffix}"), |b| {
                b.iter(|| design(black_box(&req)).expect("design"))
            });
        }
        input_shaping::solve::set_reference_polish(false);
    }
    group.finish();
}

#[cfg(not(target_arch = "wasm32"))]
criterion_group!(benches, bench, bench_three_modes);
#[cfg(not(target_arch = "wasm32"))]
criterion_main!(benches);

/// Criterion is a native-only dev-dependency: on wasm32 this bench is empty.
#[cfg(target_arch = "wasm32")]
fn main() {
    let _ = design(&request(true));
    let _ = design(&three_modes(0.3));
}
