//! Charts drawn on real canvases in headless Chromium (`wasm-pack test --headless --chrome`):
//! after `renderPlayground` the canvases hold the chart's pixels, and a bad input leaves them
//! as they were.
#![cfg(target_arch = "wasm32")]

use input_shaping::js as wasm;
use js_sys::{Reflect, JSON};
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_test::{wasm_bindgen_test, wasm_bindgen_test_configure};
use web_sys::{CanvasRenderingContext2d, HtmlCanvasElement};

wasm_bindgen_test_configure!(run_in_browser);

fn canvas(width: u32, height: u32) -> HtmlCanvasElement {
    let document = web_sys::window().unwrap().document().unwrap();
    let c: HtmlCanvasElement = document
        .create_element("canvas")
        .unwrap()
        .dyn_into()
        .unwrap();
    c.set_width(width);
    c.set_height(height);
    document.body().unwrap().append_child(&c).unwrap();
    c
}

fn pixels(c: &HtmlCanvasElement) -> Vec<u8> {
    let ctx: CanvasRenderingContext2d = c.get_context("2d").unwrap().unwrap().dyn_into().unwrap();
    ctx.get_image_data(0.0, 0.0, c.width() as f64, c.height() as f64)
        .unwrap()
        .data()
        .to_vec()
}

/// Counts pixels of roughly the first series colour (0, 114, 178).
fn series_pixels(data: &[u8]) -> usize {
    data.chunks(4)
        .filter(|p| {
            (p[0] as i32) < 60 && (p[1] as i32 - 114).abs() < 40 && (p[2] as i32 - 178).abs() < 40
        })
        .count()
}

#[wasm_bindgen_test]
fn render_playground_draws_both_charts_and_keeps_them_on_error() {
    let (imp, sens) = (canvas(640, 360), canvas(640, 360));
    let canvases = js_sys::Object::new();
    Reflect::set(&canvases, &"impulses".into(), &imp).unwrap();
    Reflect::set(&canvases, &"sensitivity".into(), &sens).unwrap();
    let state = JSON::parse(r#"{"modes":[{"frequencyHz":2,"damping":0.05}],"shaper":{"family":"zvd"},"view":{"vtol":0.05}}"#).unwrap();
    let result = wasm::render_playground(state, canvases.clone().into()).unwrap();
    let before_imp = pixels(&imp);
    let before_sens = pixels(&sens);
    // White background, stems and curve in the series colour.
    assert!(
        series_pixels(&before_imp) > 200,
        "impulse stems drawn: {}",
        series_pixels(&before_imp)
    );
    assert!(
        series_pixels(&before_sens) > 300,
        "sensitivity curve drawn: {}",
        series_pixels(&before_sens)
    );
    let white = before_imp
        .chunks(4)
        .filter(|p| p[0] > 250 && p[1] > 250 && p[2] > 250)
        .count();
    assert!(white > 640 * 360 / 2, "mostly white background");
    let ins: js_sys::Array = Reflect::get(&result, &"insensitivity".into())
        .unwrap()
        .dyn_into()
        .unwrap();
    let width = Reflect::get(&ins.get(0), &"width".into())
        .unwrap()
        .as_f64()
        .unwrap();
    assert!(
        width > 0.2 && width < 0.4,
        "ZVD I(5 %) near 0.29 at ζ = 0.05: {width}"
    );

    let bad =
        JSON::parse(r#"{"modes":[{"frequencyHz":2,"damping":1.2}],"shaper":{"family":"zvd"}}"#)
            .unwrap();
    let err: js_sys::Error = wasm::render_playground(bad, canvases.into())
        .unwrap_err()
        .dyn_into()
        .unwrap();
    assert_eq!(
        Reflect::get(&err, &"field".into())
            .unwrap()
            .as_string()
            .as_deref(),
        Some("modes[0].damping")
    );
    assert_eq!(pixels(&imp), before_imp, "impulse chart kept");
    assert_eq!(pixels(&sens), before_sens, "sensitivity chart kept");
}

/// Counts pixels within 30 of `rgb` in every channel.
fn pixels_of(data: &[u8], rgb: (i32, i32, i32)) -> usize {
    data.chunks(4)
        .filter(|p| {
            (p[0] as i32 - rgb.0).abs() < 30
                && (p[1] as i32 - rgb.1).abs() < 30
                && (p[2] as i32 - rgb.2).abs() < 30
        })
        .count()
}

/// `view.seriesColors` gives each compared shaper its palette colour: the page leaves a shaper
/// it cannot design out and the others keep theirs (web/main.js). Two shapers drawn in the
/// palette's third and fourth colours (green, pink) have no pixel of the first two; a wrong
/// list is an error at the field and draws nothing.
#[wasm_bindgen_test]
fn series_colors_pick_the_palette_positions() {
    let blue = (0, 114, 178);
    let vermillion = (213, 94, 0);
    let green = (0, 158, 115);
    let pink = (204, 121, 167);
    let state = |colors: &str| {
        JSON::parse(&format!(
            r#"{{"modes":[{{"frequencyHz":2,"damping":0.05}}],"shapers":[{{"family":"zv"}},{{"family":"zvd"}}],"view":{{"seriesColors":{colors}}}}}"#
        ))
        .unwrap()
    };
    let draw = |colors: &str| {
        let imp = canvas(640, 360);
        let canvases = js_sys::Object::new();
        Reflect::set(&canvases, &"impulses".into(), &imp).unwrap();
        let r = wasm::render_playground(state(colors), canvases.into());
        (r, pixels(&imp))
    };
    let (r, default) = draw("null");
    r.unwrap();
    assert!(pixels_of(&default, blue) > 100 && pixels_of(&default, vermillion) > 100);
    assert_eq!(pixels_of(&default, green) + pixels_of(&default, pink), 0);

    let (r, picked) = draw("[2, 3]");
    r.unwrap();
    assert!(pixels_of(&picked, green) > 100, "ZV in green");
    assert!(pixels_of(&picked, pink) > 100, "ZVD in pink");
    assert_eq!(pixels_of(&picked, blue) + pixels_of(&picked, vermillion), 0);

    for (colors, field) in [
        ("[2]", "view.seriesColors"),
        ("[0, 4]", "view.seriesColors[1]"),
        ("[1, 1]", "view.seriesColors[1]"),
    ] {
        let (r, untouched) = draw(colors);
        let err: js_sys::Error = r.unwrap_err().dyn_into().unwrap();
        assert_eq!(
            Reflect::get(&err, &"field".into())
                .unwrap()
                .as_string()
                .as_deref(),
            Some(field),
            "{colors}"
        );
        assert!(
            untouched.chunks(4).all(|p| p[3] == 0),
            "{colors}: nothing drawn"
        );
    }
}

#[wasm_bindgen_test]
fn missing_canvases_are_skipped() {
    let state = JSON::parse(r#"{"modes":[{"frequencyHz":5}],"shaper":{"family":"zv"}}"#).unwrap();
    let result = wasm::render_playground(state, JsValue::from(js_sys::Object::new())).unwrap();
    assert!(Reflect::get(&result, &"shaper".into()).unwrap().is_object());
}

/// Bang-bang and on/off amplitudes sum to zero: Klipper's smoothing (which divides by that
/// sum) is `null` for them, and the frame is still drawn — it used to fail the whole frame.
#[wasm_bindgen_test]
fn zero_sum_shapers_render_with_null_klipper_figures() {
    let (imp, sens) = (canvas(640, 360), canvas(640, 360));
    let canvases = js_sys::Object::new();
    Reflect::set(&canvases, &"impulses".into(), &imp).unwrap();
    Reflect::set(&canvases, &"sensitivity".into(), &sens).unwrap();
    let state = JSON::parse(
        r#"{"modes":[{"frequencyHz":2,"damping":0.05}],
            "shapers":[{"family":"bangbang","distance":1,"maxAcceleration":10},
                       {"family":"onoff","distance":1,"maxAcceleration":10,"coastTime":0.5},
                       {"family":"zv"}]}"#,
    )
    .unwrap();
    let result = wasm::render_playground(state, canvases.into()).unwrap();
    let results: js_sys::Array = Reflect::get(&result, &"results".into())
        .unwrap()
        .dyn_into()
        .unwrap();
    let klipper = |k: u32| Reflect::get(&results.get(k), &"klipper".into()).unwrap();
    assert!(klipper(0).is_null(), "bang-bang: no Klipper figures");
    assert!(klipper(1).is_null(), "on/off: no Klipper figures");
    assert!(klipper(2).is_object(), "ZV has them");
    assert!(series_pixels(&pixels(&imp)) > 50, "impulses drawn");
}

/// Every playground canvas gets ink in one call; the mismatch redraws the response but not the
/// impulses; bang-bang's own move ends at rest at its distance (its simulated residual ≈ 0), and
/// a bad mismatch leaves every canvas as it was.
#[wasm_bindgen_test]
fn render_playground_draws_every_chart_and_the_mismatch_moves_the_response() {
    let keys = [
        "impulses",
        "sensitivity",
        "damping",
        "map",
        "response",
        "command",
        "spectrum",
        "robustness",
    ];
    let canvases = js_sys::Object::new();
    let all: Vec<HtmlCanvasElement> = keys
        .iter()
        .map(|k| {
            let c = canvas(560, 340);
            Reflect::set(&canvases, &(*k).into(), &c).unwrap();
            c
        })
        .collect();
    let state = |r: &str| {
        JSON::parse(&format!(
            r#"{{"modes":[{{"frequencyHz":2,"damping":0.05}}],
                "shapers":[{{"family":"zvd"}},{{"family":"bangbang","distance":1,"maxAcceleration":10}}],
                "view":{{"mismatch":{r},"command":{{"kind":"trapezoid","distance":1,"maxVelocity":0.8,"maxAcceleration":8}}}}}}"#
        ))
        .unwrap()
    };
    let result = wasm::render_playground(state("1"), canvases.clone().into()).unwrap();
    let first: Vec<Vec<u8>> = all.iter().map(pixels).collect();
    for (k, p) in keys.iter().zip(&first) {
        let ink = p
            .chunks(4)
            .filter(|q| q[0] < 230 || q[1] < 230 || q[2] < 230)
            .count();
        assert!(ink > 2000, "{k}: {ink} px of ink");
    }
    let results: js_sys::Array = Reflect::get(&result, &"results".into())
        .unwrap()
        .dyn_into()
        .unwrap();
    let residual = |k: u32| {
        let sim = Reflect::get(&results.get(k), &"simulation".into()).unwrap();
        Reflect::get(&sim, &"residualVibrationPercent".into())
            .unwrap()
            .as_f64()
            .unwrap()
    };
    assert!(residual(0) < 1e-9, "ZVD at the exact mode: {}", residual(0));
    assert!(residual(1) < 1e-9, "bang-bang's own move: {}", residual(1));

    wasm::render_playground(state("1.2"), canvases.clone().into()).unwrap();
    assert_eq!(
        pixels(&all[0]),
        first[0],
        "impulses unchanged by the mismatch"
    );
    assert_ne!(pixels(&all[4]), first[4], "response redrawn for r = 1.2");
    let second: Vec<Vec<u8>> = all.iter().map(pixels).collect();

    let err: js_sys::Error = wasm::render_playground(state("-1"), canvases.into())
        .unwrap_err()
        .dyn_into()
        .unwrap();
    assert_eq!(
        Reflect::get(&err, &"field".into())
            .unwrap()
            .as_string()
            .as_deref(),
        Some("view.mismatch")
    );
    for ((k, c), before) in keys.iter().zip(&all).zip(&second) {
        assert_eq!(&pixels(c), before, "{k} kept after the error");
    }
}

/// Mismatch per mode and in damping (issue 23 item 2): the simulated plant's mode i is the
/// model's × `mismatch` × `modeMismatch[i]` with `actualDamping[i]` (the model's when missing or
/// null). Checked against the products written out, against the exact shaper's promise (a
/// per-mode ratio that undoes the common one leaves ZVD's V = 0 at the exact modes, which
/// another damping breaks), and every bad entry named by its index.
#[wasm_bindgen_test]
fn render_playground_takes_a_mismatch_per_mode_and_in_damping() {
    let run = |view: &str| {
        let state = JSON::parse(&format!(
            r#"{{"modes":[{{"frequencyHz":2,"damping":0.05}},{{"frequencyHz":5,"damping":0.02}}],
                "shapers":[{{"family":"zvd"}}],
                "view":{{"command":{{"kind":"trapezoid","distance":1,"maxVelocity":0.8,"maxAcceleration":8}},{view}}}}}"#
        ))
        .unwrap();
        wasm::render_playground(state, JsValue::NULL)
    };
    let numbers = |v: JsValue| -> Vec<f64> {
        js_sys::Array::from(&v)
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let sim = |r: &JsValue, key: &str| {
        Reflect::get(&Reflect::get(r, &"simulation".into()).unwrap(), &key.into()).unwrap()
    };
    let residual = |r: &JsValue| {
        let first = js_sys::Array::from(&Reflect::get(r, &"results".into()).unwrap()).get(0);
        sim(&first, "residualVibrationPercent").as_f64().unwrap()
    };
    let r = run(r#""mismatch":1.1,"modeMismatch":[1,0.9],"actualDamping":[null,0.1]"#).unwrap();
    let hz = numbers(sim(&r, "plantModesHz"));
    assert!(
        (hz[0] - 2.2).abs() < 1e-12 && (hz[1] - 4.95).abs() < 1e-12,
        "{hz:?}"
    );
    assert_eq!(numbers(sim(&r, "plantDamping")), vec![0.05, 0.1]);
    assert!(residual(&r) > 1e-3, "mismatched: {}", residual(&r));
    // Per-mode ratios undoing the common one: the model's modes, ZVD's exact cancellation.
    let undone = format!(r#""mismatch":1.1,"modeMismatch":[{0},{0}]"#, 1.0 / 1.1);
    let exact = run(&undone).unwrap();
    assert!(residual(&exact) < 1e-6, "{}", residual(&exact));
    // The same with mode 2's damping changed: vibration left.
    let damped = run(&format!(r#"{},"actualDamping":[null,0.2]"#, undone)).unwrap();
    assert!(residual(&damped) > 1e-3, "{}", residual(&damped));
    for (view, field) in [
        (r#""modeMismatch":[1,-1]"#, "view.modeMismatch[1]"),
        (r#""modeMismatch":[1,1,1]"#, "view.modeMismatch"),
        (r#""actualDamping":[null,1.5]"#, "view.actualDamping[1]"),
        (r#""actualDamping":[0.1,0.1,0.1]"#, "view.actualDamping"),
        (r#""modeMismatch":["1"]"#, "view.modeMismatch[0]"),
    ] {
        let err: js_sys::Error = run(view).unwrap_err().dyn_into().unwrap();
        let got = Reflect::get(&err, &"field".into()).unwrap().as_string();
        assert_eq!(got.as_deref(), Some(field), "{view}: {:?}", err.message());
    }
}

/// `renderPlayground` keeps the last frame's designs and analyses and reuses them while only
/// the simulation's inputs change. Through a sequence of edits — mismatch, Vtol, square corner
/// velocity, a mode's frequency, the family, the mismatch again, the command's acceleration —
/// every frame's shaper, I(Vtol) and Klipper smoothing equal what `design`, `insensitivity` and
/// `klipperFigures` compute for that frame's state from scratch, and the shaped move's own
/// figures (its end, peak acceleration and jerk, acceleration peak-valley count, kept between
/// frames too) what `simulate` gives for the shaped command formed from scratch (so a stale
/// analysis or stale figures would fail here); the mismatch edits change the simulated
/// residual but not the analysis, the command edit the figures but not the analysis.
#[wasm_bindgen_test]
fn analyses_kept_between_frames_follow_every_input_they_depend_on() {
    let canvases = js_sys::Object::new();
    for key in ["damping", "map", "spectrum"] {
        Reflect::set(&canvases, &key.into(), &canvas(320, 200)).unwrap();
    }
    let get = |v: &JsValue, path: &[&str]| {
        path.iter()
            .fold(v.clone(), |v, k| Reflect::get(&v, &(*k).into()).unwrap())
    };
    let edits: [(f64, f64, f64, &str, f64, f64); 8] = [
        (2.0, 0.05, 5.0, "zvd", 1.0, 8.0),
        (2.0, 0.05, 5.0, "zvd", 1.2, 8.0),
        (2.0, 0.10, 5.0, "zvd", 1.2, 8.0),
        (2.0, 0.10, 400.0, "zvd", 1.2, 8.0),
        (2.5, 0.10, 400.0, "zvd", 1.2, 8.0),
        (2.5, 0.10, 400.0, "ei", 1.2, 8.0),
        (2.5, 0.10, 400.0, "ei", 0.9, 8.0),
        (2.5, 0.10, 400.0, "ei", 0.9, 3.0),
    ];
    let mut last_residual = f64::NAN;
    let mut last_analysis = String::new();
    let mut last_figures = String::new();
    for (i, &(f, vtol, scv, family, mismatch, acc)) in edits.iter().enumerate() {
        let command = format!(
            r#"{{"kind":"trapezoid","distance":1,"maxVelocity":0.8,"maxAcceleration":{acc}}}"#
        );
        let state = JSON::parse(&format!(
            r#"{{"modes":[{{"frequencyHz":{f},"damping":0.03}}],"shapers":[{{"family":"{family}"}}],
                "view":{{"vtol":{vtol},"scv":{scv},"mismatch":{mismatch},"command":{command}}}}}"#
        ))
        .unwrap();
        let out = wasm::render_playground(state, canvases.clone().into()).unwrap();
        let result = js_sys::Array::from(&get(&out, &["results"])).get(0);
        let mode = JSON::parse(&format!(r#"{{"frequencyHz":{f},"damping":0.03}}"#)).unwrap();
        let spec = JSON::parse(&format!(
            r#"{{"family":"{family}","modes":[{{"frequencyHz":{f},"damping":0.03}}]}}"#
        ))
        .unwrap();
        let fresh = wasm::design(spec).unwrap();
        assert_eq!(
            JSON::stringify(&get(&result, &["shaper"])).unwrap(),
            JSON::stringify(&fresh).unwrap(),
            "edit {i}: shaper"
        );
        let width = get(&result, &["insensitivity"]);
        let width = get(&js_sys::Array::from(&width).get(0), &["width"])
            .as_f64()
            .unwrap();
        let expect = get(
            &wasm::insensitivity(fresh.clone(), mode, vtol.into()).unwrap(),
            &["width"],
        );
        assert_eq!(width, expect.as_f64().unwrap(), "edit {i}: I(Vtol)");
        let options = JSON::parse(&format!(r#"{{"scv":{scv}}}"#)).unwrap();
        let klipper = wasm::klipper_figures(fresh, options).unwrap();
        assert_eq!(
            get(&result, &["klipper", "smoothing"]).as_f64(),
            get(&klipper, &["smoothing"]).as_f64(),
            "edit {i}: Klipper smoothing"
        );
        let residual = get(&result, &["simulation", "residualVibrationPercent"])
            .as_f64()
            .unwrap();
        let analysis = format!(
            "{} {width} {:?}",
            JSON::stringify(&get(&result, &["shaper"])).unwrap(),
            get(&result, &["klipper", "smoothing"]).as_f64()
        );
        // The shaped command's own figures, against `simulate` of the formed command (any
        // plant: they are the command's).
        let keys = [
            "moveEnd",
            "peakAcceleration",
            "peakJerk",
            "accelerationPeakValleyCount",
        ];
        let figures_of = |metrics: &JsValue| {
            keys.map(|k| {
                JSON::stringify(&get(metrics, &[k]))
                    .unwrap()
                    .as_string()
                    .unwrap()
            })
            .join(" ")
        };
        let figures = figures_of(&get(&result, &["simulation"]));
        let simulated = wasm::simulate(
            JSON::parse(&format!(
                r#"{{"plant":{{"kind":"modal","modes":[{{"frequencyHz":{f},"damping":0.03}}]}},
                    "command":{command},
                    "shaper":{{"family":"{family}","modes":[{{"frequencyHz":{f},"damping":0.03}}]}}}}"#
            ))
            .unwrap(),
        )
        .unwrap();
        assert_eq!(
            figures,
            figures_of(&get(&simulated, &["shaped", "metrics"])),
            "edit {i}: the shaped move's own figures"
        );
        let (mismatch_edit, command_edit) = match i {
            0 => (false, false),
            _ => (mismatch != edits[i - 1].4, acc != edits[i - 1].5),
        };
        if mismatch_edit || command_edit {
            assert_eq!(
                analysis, last_analysis,
                "edit {i}: a mismatch or command edit keeps the analysis"
            );
        } else if i > 0 {
            assert_ne!(
                analysis, last_analysis,
                "edit {i}: the analysis follows the edit"
            );
        }
        if mismatch_edit {
            assert_ne!(
                residual, last_residual,
                "edit {i}: the simulation follows r"
            );
        }
        if command_edit {
            assert_ne!(
                figures, last_figures,
                "edit {i}: the figures follow the command"
            );
        }
        last_residual = residual;
        last_analysis = analysis;
        last_figures = figures;
    }
}

/// The compared shapers' labels (legends, table headers) name the count of the families titled
/// by one: ZV-D³ and ZV-D¹² are told apart; identical labels are still numbered by position.
#[wasm_bindgen_test]
fn labels_write_in_the_derivative_and_hump_counts() {
    let state = JSON::parse(
        r#"{"modes":[{"frequencyHz":2,"damping":0.05}],
            "shapers":[{"family":"zvdn","derivatives":3},{"family":"zvdn","derivatives":12},
                       {"family":"eihump","humps":4},{"family":"eihump","humps":4}]}"#,
    )
    .unwrap();
    let result = wasm::render_playground(state, JsValue::from(js_sys::Object::new())).unwrap();
    let results: js_sys::Array = Reflect::get(&result, &"results".into())
        .unwrap()
        .dyn_into()
        .unwrap();
    let labels: Vec<String> = results
        .iter()
        .map(|r| {
            Reflect::get(&r, &"label".into())
                .unwrap()
                .as_string()
                .unwrap()
        })
        .collect();
    assert_eq!(labels, ["ZV-D³", "ZV-D¹²", "4-hump EI #3", "4-hump EI #4"]);
}

/// `state.designed`: a shaper designed elsewhere (the page's design worker) and handed back
/// with the state draws exactly what designing it here draws, is used as given (its label and
/// family still come from the spec), is part of what the kept analysis depends on, and a bad
/// one is refused at its field.
#[wasm_bindgen_test]
fn shapers_designed_elsewhere_are_used_as_given() {
    let canvases = js_sys::Object::new();
    for key in ["impulses", "sensitivity", "damping", "map", "spectrum"] {
        Reflect::set(&canvases, &key.into(), &canvas(320, 200)).unwrap();
    }
    let modes = r#"[{"frequencyHz":2,"damping":0.05},{"frequencyHz":5.5,"damping":0.02}]"#;
    let si = r#"{"family":"si","vtol":0.05,"insensitivity":0.3}"#;
    let state = |designed: &str| {
        JSON::parse(&format!(
            r#"{{"modes":{modes},"shapers":[{si},{{"family":"zvd"}}],"designed":{designed},
                "view":{{"command":{{"kind":"trapezoid","distance":1,"maxVelocity":0.8,"maxAcceleration":8}}}}}}"#
        ))
        .unwrap()
    };
    let json = |v: &JsValue| String::from(JSON::stringify(v).unwrap());
    let here = json(&wasm::render_playground(state("[]"), canvases.clone().into()).unwrap());
    let spec = JSON::parse(&format!(
        r#"{{"family":"si","vtol":0.05,"insensitivity":0.3,"modes":{modes}}}"#
    ))
    .unwrap();
    let designed = json(&wasm::design(spec).unwrap());
    // Handed back: the same frame, number for number (`designed` is part of the kept
    // analysis's key, so this frame is computed from the handed shaper).
    let zv_modes = JSON::parse(&format!(r#"{{"family":"zv","modes":{modes}}}"#)).unwrap();
    let zv = json(&wasm::design(zv_modes).unwrap());
    let other = wasm::render_playground(
        state(&format!("[{zv}]")),
        JsValue::from(js_sys::Object::new()),
    )
    .unwrap();
    let handed = json(
        &wasm::render_playground(state(&format!("[{designed}, null]")), canvases.into()).unwrap(),
    );
    assert_eq!(
        handed, here,
        "a handed-back design draws what designing it here draws"
    );
    // Used as given: a ZV handed for the SI spec is what the frame shows, under the SI's label.
    let first = js_sys::Array::from(&Reflect::get(&other, &"results".into()).unwrap()).get(0);
    let get = |k: &str| Reflect::get(&first, &k.into()).unwrap();
    assert_eq!(json(&get("shaper")), zv);
    assert_eq!(get("family").as_string().unwrap(), "si");
    assert!(
        get("label").as_string().unwrap().starts_with("SI"),
        "{:?}",
        get("label")
    );
    // Refused at the field.
    let field = |designed: &str| {
        let err: js_sys::Error = wasm::render_playground(state(designed), JsValue::NULL)
            .unwrap_err()
            .dyn_into()
            .unwrap();
        let field = Reflect::get(&err, &"field".into()).unwrap().as_string();
        (field.unwrap_or_default(), String::from(err.message()))
    };
    let (f, m) = field(&format!("[null, null, {zv}]"));
    assert_eq!(f, "designed", "{m}");
    let (f, m) = field(r#"[null, {"impulses":[]}]"#);
    assert!(f.starts_with("designed[1]"), "{f}: {m}");
    let (f, m) = field(r#"[{"impulses":[{"time":0,"amplitude":"one"}]}]"#);
    assert!(f.starts_with("designed[0]"), "{f}: {m}");
}

/// The shapers a frame hands out (`results[k].shaper` and the first one's `shaper`) have their
/// impulse objects built in bulk by a small JS function (crate/js/bulk.rs) rather than by
/// serde-wasm-bindgen: they must be what `design` (serde's path) gives for the same spec, to
/// every number and key, for a short shaper, 4096 impulses and a factored convolution (ZV-D³
/// over six modes: 15 625 impulses with its six `factors`).
#[wasm_bindgen_test]
fn render_playground_hands_out_the_shapers_design_gives() {
    let modes = r#"[{"frequencyHz":1.2,"damping":0.02},{"frequencyHz":3.4,"damping":0.02},
        {"frequencyHz":7.9,"damping":0.02},{"frequencyHz":13,"damping":0.02},
        {"frequencyHz":21,"damping":0.02},{"frequencyHz":34,"damping":0.02}]"#;
    let shapers = [
        r#"{"family":"zv"}"#,
        r#"{"family":"zvdd"}"#,
        r#"{"family":"zvdn","derivatives":3}"#,
    ];
    let state = JSON::parse(&format!(
        r#"{{"modes":{modes},"shapers":[{}],"view":{{"vtol":0.05}}}}"#,
        shapers.join(",")
    ))
    .unwrap();
    let out = wasm::render_playground(state, JsValue::NULL).unwrap();
    let results = js_sys::Array::from(&Reflect::get(&out, &"results".into()).unwrap());
    let text = |v: &JsValue| String::from(JSON::stringify(v).unwrap());
    for (k, spec) in shapers.iter().enumerate() {
        let spec = JSON::parse(&format!(r#"{{"modes":{modes},{}"#, &spec[1..])).unwrap();
        let fresh = wasm::design(spec).unwrap();
        let given = Reflect::get(&results.get(k as u32), &"shaper".into()).unwrap();
        assert_eq!(text(&given), text(&fresh), "shaper {k}");
        let factors = Reflect::get(&given, &"factors".into()).unwrap();
        let count = js_sys::Array::from(&Reflect::get(&given, &"impulses".into()).unwrap());
        match k {
            2 => {
                assert_eq!(count.length(), 15_625);
                assert_eq!(js_sys::Array::from(&factors).length(), 6);
            }
            _ => assert!(factors.is_undefined(), "shaper {k}: no factors"),
        }
    }
    let first = Reflect::get(&out, &"shaper".into()).unwrap();
    let first_result = Reflect::get(&results.get(0), &"shaper".into()).unwrap();
    assert_eq!(
        text(&first),
        text(&first_result),
        "the first shaper's fields"
    );
}
