//! Criterion benchmarks of `design` for every family (issue: "criterion benches for each
//! family"), each on a representative spec: one lightly damped mode unless the family is about
//! several. `cargo bench --bench design` (native only).
//!
//! The solved families (`si`, `direct`) are also compared with scipy's SLSQP in benches/si.rs +
//! benches/si_slsqp.py; this file gives every family's cost side by side in one run.

#![cfg_attr(target_arch = "wasm32", allow(unused))]

#[cfg(not(target_arch = "wasm32"))]
use criterion::{criterion_group, criterion_main, Criterion};
use input_shaping::{design, DesignRequest};
#[cfg(not(target_arch = "wasm32"))]
use std::hint::black_box;

/// (benchmark name, spec as the JS API takes it).
const SPECS: &[(&str, &str)] = &[
    (
        "zv",
        r#"{"family":"zv","modes":[{"frequencyHz":2,"damping":0.05}]}"#,
    ),
    (
        "zvd",
        r#"{"family":"zvd","modes":[{"frequencyHz":2,"damping":0.05}]}"#,
    ),
    (
        "zvdd",
        r#"{"family":"zvdd","modes":[{"frequencyHz":2,"damping":0.05}]}"#,
    ),
    (
        "zvdn_5",
        r#"{"family":"zvdn","derivatives":5,"modes":[{"frequencyHz":2,"damping":0.05}]}"#,
    ),
    (
        "mzv",
        r#"{"family":"mzv","modes":[{"frequencyHz":45,"damping":0.1}]}"#,
    ),
    (
        "ei",
        r#"{"family":"ei","vtol":0.05,"modes":[{"frequencyHz":2,"damping":0.05}]}"#,
    ),
    (
        "ei2",
        r#"{"family":"ei2","vtol":0.05,"modes":[{"frequencyHz":2,"damping":0.05}]}"#,
    ),
    (
        "ei3",
        r#"{"family":"ei3","vtol":0.05,"modes":[{"frequencyHz":2,"damping":0.05}]}"#,
    ),
    (
        "eihump_5",
        r#"{"family":"eihump","humps":5,"vtol":0.05,"modes":[{"frequencyHz":2,"damping":0.05}]}"#,
    ),
    (
        "umzv",
        r#"{"family":"umzv","modes":[{"frequencyHz":2,"damping":0.05}]}"#,
    ),
    (
        "umzvd",
        r#"{"family":"umzvd","modes":[{"frequencyHz":2,"damping":0.05}]}"#,
    ),
    (
        "umei",
        r#"{"family":"umei","vtol":0.05,"modes":[{"frequencyHz":2,"damping":0.05}]}"#,
    ),
    (
        "bangbang",
        r#"{"family":"bangbang","distance":1,"maxAcceleration":20,"modes":[{"frequencyHz":2,"damping":0.05}]}"#,
    ),
    (
        "onoff",
        r#"{"family":"onoff","distance":1,"maxAcceleration":20,"coastTime":0.5,"modes":[{"frequencyHz":2,"damping":0.05}]}"#,
    ),
    (
        "si_i07",
        r#"{"family":"si","vtol":0.05,"insensitivity":0.7,"modes":[{"frequencyHz":0.5,"damping":0.002}]}"#,
    ),
    (
        "si_damping_range",
        r#"{"family":"si","bandHz":[0.7,1.3],"dampingRange":[0,0.2],"modes":[{"frequencyHz":1,"damping":0.1}]}"#,
    ),
    (
        "direct_zvd_2_modes",
        r#"{"family":"direct","derivatives":1,"modes":[{"frequencyHz":1,"damping":0.02},{"frequencyHz":2.7,"damping":0.03}]}"#,
    ),
    (
        "sampled_kamel",
        r#"{"family":"sampled","periodS":0.012,"impulses":36,"delaySamples":17,"weight":0.1,"plantGain":0.0008,"modes":[{"frequencyHz":4.7746482927568605,"damping":0.02}]}"#,
    ),
    (
        "custom",
        r#"{"family":"custom","impulses":[{"time":0,"amplitude":0.5},{"time":0.25,"amplitude":0.5}],"modes":[{"frequencyHz":2,"damping":0}]}"#,
    ),
    (
        "zvd_convolved_3_modes",
        r#"{"family":"zvd","modes":[{"frequencyHz":1.2,"damping":0.012},{"frequencyHz":3.4,"damping":0.013},{"frequencyHz":7,"damping":0.02}]}"#,
    ),
];

fn request(json: &str) -> DesignRequest {
    serde_json::from_str(json).expect("bench spec parses")
}

#[cfg(not(target_arch = "wasm32"))]
fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("design");
    for (name, json) in SPECS {
        let req = request(json);
        let s = design(&req).unwrap_or_else(|e| panic!("{name}: {e}"));
        eprintln!(
            "{name}: {} impulses, duration {:.6} s",
            s.len(),
            s.duration()
        );
        g.bench_function(*name, |b| {
            b.iter(|| design(black_box(&req)).expect("design"))
        });
    }
    g.finish();
}

#[cfg(not(target_arch = "wasm32"))]
criterion_group!(benches, bench);
#[cfg(not(target_arch = "wasm32"))]
criterion_main!(benches);

/// Criterion is a native-only dev-dependency: on wasm32 this bench is empty.
#[cfg(target_arch = "wasm32")]
fn main() {
    for (_, json) in SPECS {
        let _ = design(&request(json));
    }
}
