//! Criterion benchmark of SI design: the Peláez & Singhose 2002 example (0.5 Hz, ζ = 0.002,
//! Vtol = 5 %, I = 0.7), sampled at six frequencies (the problem benches/si_slsqp.py solves
//! with scipy's SLSQP from random starts) and over the whole band.
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

#[cfg(not(target_arch = "wasm32"))]
criterion_group!(benches, bench);
#[cfg(not(target_arch = "wasm32"))]
criterion_main!(benches);

/// Criterion is a native-only dev-dependency: on wasm32 this bench is empty.
#[cfg(target_arch = "wasm32")]
fn main() {
    let _ = design(&request(true));
}
