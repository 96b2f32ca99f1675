//! `family: "custom"`: a user's impulses, validated through Shaper::new.

use input_shaping::{design, DesignRequest};
use wasm_bindgen_test::wasm_bindgen_test;

fn request(json: &str) -> DesignRequest {
    serde_json::from_str(json).unwrap()
}

/// Unsorted impulses are sorted, shifted to t = 0, merged; `normalize` makes Σ A = 1.
#[wasm_bindgen_test(unsupported = test)]
fn custom_is_validated_and_optionally_normalised() {
    let r = request(
        r#"{"family":"custom","modes":[{"frequencyHz":1}],
            "impulses":[{"time":1.5,"amplitude":1},{"time":0.5,"amplitude":2},
                        {"time":1.5,"amplitude":1}]}"#,
    );
    let s = design(&r).unwrap();
    let got: Vec<(f64, f64)> = s.impulses().iter().map(|i| (i.time, i.amplitude)).collect();
    assert_eq!(got, vec![(0.0, 2.0), (1.0, 2.0)]);
    let r = request(
        r#"{"family":"custom","modes":[{"frequencyHz":1}],"normalize":true,
            "impulses":[{"time":0,"amplitude":1},{"time":0.5,"amplitude":3}]}"#,
    );
    let s = design(&r).unwrap();
    let got: Vec<f64> = s.impulses().iter().map(|i| i.amplitude).collect();
    assert_eq!(got, vec![0.25, 0.75]);
}

/// Errors name the offending impulse or field.
#[wasm_bindgen_test(unsupported = test)]
fn custom_errors_name_the_field() {
    for (impulses, extra, field) in [
        (r#"[]"#, "", "impulses"),
        (r#"[{"time":-1,"amplitude":1}]"#, "", "impulses[0].time"),
        (
            r#"[{"time":0,"amplitude":1},{"time":1,"amplitude":-1}]"#,
            r#","normalize":true"#,
            "impulses",
        ),
    ] {
        let json = format!(
            r#"{{"family":"custom","modes":[{{"frequencyHz":1}}],"impulses":{impulses}{extra}}}"#
        );
        let err = design(&request(&json)).unwrap_err();
        assert_eq!(err.field(), Some(field), "{json}: {err}");
    }
}

/// Every family added here parses from JSON with its documented parameters, has a row in
/// FAMILIES, and that row lists exactly the parameters the JSON used.
#[wasm_bindgen_test(unsupported = test)]
fn new_families_have_rows_and_parameters() {
    let specs = [
        r#"{"family":"ei","vtol":0.05}"#,
        r#"{"family":"ei2","vtol":0.05}"#,
        r#"{"family":"ei3","vtol":0.05}"#,
        r#"{"family":"eihump","humps":4,"vtol":0.05}"#,
        r#"{"family":"mzv"}"#,
        r#"{"family":"umzv"}"#,
        r#"{"family":"umzvd"}"#,
        r#"{"family":"umei","vtol":0.05}"#,
        r#"{"family":"bangbang","distance":1,"maxAcceleration":2}"#,
        r#"{"family":"onoff","distance":1,"maxAcceleration":2,"coastTime":0.5}"#,
        r#"{"family":"custom","impulses":[],"normalize":false}"#,
    ];
    for json in specs {
        let spec: input_shaping::ShaperSpec = serde_json::from_str(json).unwrap();
        let row = spec
            .info()
            .unwrap_or_else(|| panic!("no FAMILIES row for {json}"));
        assert_eq!(row.name, spec.name());
        let value: serde_json::Value = serde_json::from_str(json).unwrap();
        let mut keys: Vec<&str> = value
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .filter(|k| *k != "family")
            .collect();
        keys.sort_unstable();
        let mut params = row.parameters.to_vec();
        params.sort_unstable();
        assert_eq!(keys, params, "{json}");
    }
}
