//! The forks checked against upstream (issue 21 item 4): every read of a JS value in this
//! crate's tests is made twice, by the fork ([`super::deserialize`]: serde-wasm-bindgen 0.6.5's
//! deserializer with serde_path_to_error's path folded in, and `crate::tagged`'s tag-first
//! reading of internally tagged enums and flattened structs) and by upstream
//! (`serde_path_to_error::deserialize` over `serde_wasm_bindgen::Deserializer`, which reads
//! the tagged enums through serde's own buffered parser). The test below feeds a corpus through
//! every export and through the spec types directly — the family table's specs, commands,
//! profiles, plants, simulation and spectrum specs, every export's valid arguments
//! (`tests/boundary/fuzz.mjs`' table), the boundary fuzz's hostile values in every argument
//! and planted at every key, and the libFuzzer seed corpus `fuzz/corpus/spec` — and requires
//! the same value (`Debug`), or the same error path and message, except where the fork
//! differs on purpose. Those differences are exactly the rules of [`judge`]; any other
//! difference fails the test, and each rule must have been needed at least once (a rule that
//! never fires is a rule that is no longer true of the fork: remove it).

use serde::de::DeserializeOwned;
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::fmt::Debug;
use std::rc::Rc;
use wasm_bindgen::prelude::*;

/// What one reader made of a value.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Outcome {
    /// The value read, as `Debug` prints it.
    Value(String),
    /// The error: the path as serde_path_to_error prints it, and the message.
    Failed { path: String, message: String },
    /// A JS exception went through the reader (upstream does not catch a getter's throw).
    Threw(String),
}

/// Why the two readers' outcomes are accepted (see [`judge`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Rule {
    /// The same value, or the same path and message.
    Identical,
    /// A value upstream names by its `Debug` (`JsValue(Symbol(x))`, the whole of an array) is
    /// named by what it is (`a symbol`, `an array`, `binary data`, `an object`).
    DescribedNotPrinted,
    /// A string of more than 40 characters is quoted to its first 40 and `…`.
    LongStringCut,
    /// Inside a tagged spec upstream reads serde's buffer, which loses the path at the spec
    /// and names values as the buffer holds them; the fork names the field inside
    /// (`shapers[0].humps` for `shapers[0]`) and the value as JS has it: `map` is
    /// `an object`, `sequence` is `an array`, an integer `` integer `-1` `` is
    /// `` floating point `-1.0` `` (and its `invalid value` an `invalid type`), a BigInt's
    /// `` integer `N` `` is `a BigInt`.
    TaggedPathAndNames,
    /// A getter or a Proxy trap threw: the exception went through upstream; the fork returns
    /// an error.
    ThrowCaught,
    /// A typed array where an externally tagged enum goes: upstream counts its entries
    /// (`invalid length N, expected 1`, and `Object.entries` of 2^26 elements for a long
    /// signal); the fork says `invalid type: binary data`.
    TypedArrayNotEntries,
    /// A JS `Map` is not read as a tagged spec (upstream's buffer reads any iterable of
    /// pairs): the fork says the tag is missing.
    MapNotSpec,
}

#[derive(Default)]
struct State {
    /// Whether reads are compared (only while the test below runs).
    on: bool,
    /// The hostile value being fed (its label in fuzz.mjs), if any.
    hostile: Option<String>,
    /// Why upstream is not asked for this value (it would take minutes, gigabytes, or
    /// overflow the stack), if so.
    skip: bool,
    /// How many reads each rule accepted, per type.
    accepted: BTreeMap<Rule, usize>,
    types: BTreeMap<String, usize>,
    skipped: usize,
    /// The differences no rule accepts.
    failures: Vec<String>,
}

thread_local! {
    static STATE: RefCell<State> = RefCell::new(State::default());
}

/// Reads `value` as `T` with upstream, a JS exception caught (`None` when not comparing).
pub(super) fn upstream<T: DeserializeOwned + Debug>(value: &JsValue) -> Option<Outcome> {
    if !STATE.with(|s| {
        let s = s.borrow();
        s.on && !s.skip
    }) {
        return None;
    }
    let out: Rc<RefCell<Option<Outcome>>> = Rc::default();
    let into = out.clone();
    let value = value.clone();
    let read = Closure::once_into_js(move || {
        let de = serde_wasm_bindgen::Deserializer::from(value);
        let outcome = match serde_path_to_error::deserialize::<_, T>(de) {
            Ok(v) => Outcome::Value(format!("{v:?}")),
            Err(e) => Outcome::Failed {
                path: e.path().to_string(),
                message: e.inner().to_string(),
            },
        };
        *into.borrow_mut() = Some(outcome);
    });
    let guard = js_sys::Function::new_with_args(
        "f",
        "try { f(); return null; } catch (e) { try { return String(e); } catch { return 'an exception'; } }",
    );
    let thrown = guard.call1(&JsValue::NULL, &read).unwrap_or_else(|e| e);
    let outcome = out.borrow_mut().take();
    Some(outcome.unwrap_or_else(|| Outcome::Threw(thrown.as_string().unwrap_or_default())))
}

/// Compares the fork's read with upstream's (see the module docs).
pub(super) fn compare<T: Debug>(
    ty: &str,
    value: &JsValue,
    upstream: Option<Outcome>,
    read: &Result<T, (String, super::Error)>,
) {
    let fork = match read {
        Ok(v) => Outcome::Value(format!("{v:?}")),
        Err((path, e)) => Outcome::Failed {
            path: path.clone(),
            message: e.to_string(),
        },
    };
    STATE.with(|s| {
        let mut s = s.borrow_mut();
        if !s.on {
            return;
        }
        let Some(upstream) = upstream else {
            s.skipped += 1;
            return;
        };
        *s.types.entry(ty.to_string()).or_default() += 1;
        match judge(&upstream, &fork, s.hostile.as_deref()) {
            Some(rule) => *s.accepted.entry(rule).or_default() += 1,
            None => {
                if s.failures.len() < 40 {
                    let text = js_sys::JSON::stringify(value)
                        .ok()
                        .and_then(|t| t.as_string())
                        .unwrap_or_else(|| super::super::args::describe(value).into());
                    let text: String = text.chars().take(200).collect();
                    let hostile = s.hostile.clone();
                    s.failures.push(format!(
                        "{ty} of {text} (hostile {hostile:?}):\n  upstream {upstream:?}\n  fork     {fork:?}"
                    ));
                }
            }
        }
    });
}

/// `invalid type: U, expected E` / `invalid value: U, expected E` as `(kind, U, E)`.
fn split(message: &str) -> Option<(&str, &str, &str)> {
    let (kind, rest) = if let Some(r) = message.strip_prefix("invalid type: ") {
        ("type", r)
    } else {
        ("value", message.strip_prefix("invalid value: ")?)
    };
    let at = rest.rfind(", expected ")?;
    Some((kind, &rest[..at], &rest[at + ", expected ".len()..]))
}

/// What [`super::super::args::describe`] calls a value that is not null, a boolean, a number or
/// a string.
const DESCRIBED: [&str; 6] = [
    "a BigInt",
    "a symbol",
    "a function",
    "an array",
    "binary data",
    "an object",
];

/// Whether upstream's unexpected value `up` (of an `invalid <kind>` error) is the fork's `fork`
/// under a rule, and which; `buffered`: the error came out of upstream's tagged-spec buffer.
fn same_unexpected(
    (up_kind, up): (&str, &str),
    (fork_kind, fork): (&str, &str),
    buffered: bool,
) -> Option<Rule> {
    if up_kind == fork_kind && up == fork {
        return Some(Rule::Identical);
    }
    if up_kind == "type" && fork_kind == "type" {
        if up.starts_with("JsValue(") && DESCRIBED.contains(&fork) {
            return Some(Rule::DescribedNotPrinted);
        }
        if let (Some(u), Some(f)) = (up.strip_prefix("string "), fork.strip_prefix("string ")) {
            let u = u.strip_suffix('"')?;
            let f = f.strip_suffix("…\"")?;
            if u.starts_with(f) && u.chars().count() > f.chars().count() && f.chars().count() == 41
            {
                return Some(Rule::LongStringCut);
            }
        }
    }
    if buffered && fork_kind == "type" {
        let ok = match (up, fork) {
            ("map", "an object") | ("sequence", "an array") => up_kind == "type",
            _ => up
                .strip_prefix("integer `")
                .and_then(|n| n.strip_suffix('`'))
                .is_some_and(|n| fork == format!("floating point `{n}.0`") || fork == "a BigInt"),
        };
        if ok {
            return Some(Rule::TaggedPathAndNames);
        }
    }
    None
}

/// Whether path `up` is `fork` or a path above it (`shapers[0]` above `shapers[0].humps`).
fn above(up: &str, fork: &str) -> bool {
    up == fork
        || up == "."
        || fork
            .strip_prefix(up)
            .is_some_and(|rest| rest.starts_with('.') || rest.starts_with('['))
}

/// The rule under which the fork's `fork` stands for upstream's `up` (`hostile`: the label of
/// the hostile value being fed), or `None`: a difference no rule allows.
fn judge(up: &Outcome, fork: &Outcome, hostile: Option<&str>) -> Option<Rule> {
    use Outcome::*;
    match (up, fork) {
        _ if up == fork => Some(Rule::Identical),
        (Threw(_), Failed { .. })
            if matches!(
                hostile,
                Some("throwing getters" | "Proxy with throwing traps")
            ) =>
        {
            Some(Rule::ThrowCaught)
        }
        (Value(_), Failed { message, .. })
            if hostile == Some("Map") && message.starts_with("missing field `") =>
        {
            Some(Rule::MapNotSpec)
        }
        (
            Failed {
                path: up_path,
                message: up_message,
            },
            Failed {
                path: fork_path,
                message: fork_message,
            },
        ) => {
            if !above(up_path, fork_path) {
                return None;
            }
            let buffered = up_path != fork_path;
            if up_message.starts_with("invalid length ")
                && up_message.ends_with(", expected 1")
                && fork_message.starts_with("invalid type: binary data, expected ")
                && !buffered
            {
                return Some(Rule::TypedArrayNotEntries);
            }
            if up_message == fork_message {
                return buffered.then_some(Rule::TaggedPathAndNames);
            }
            let (uk, uu, ue) = split(up_message)?;
            let (fk, fu, fe) = split(fork_message)?;
            if ue != fe {
                return None;
            }
            // Upstream's buffer may also say `map`, `sequence`, `integer` where the path is
            // the same (a bad value at the spec's own level).
            let rule = same_unexpected((uk, uu), (fk, fu), true)?;
            if buffered && rule != Rule::TaggedPathAndNames {
                // A deeper path with a message a plain rule explains: both rules at once.
                return Some(Rule::TaggedPathAndNames);
            }
            Some(rule)
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::js as wasm;
    use js_sys::{Array, Function, Object, Reflect, JSON};
    use wasm_bindgen::JsCast;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn js(text: &str) -> JsValue {
        JSON::parse(text).unwrap_or_else(|_| panic!("test JSON parses: {text}"))
    }

    /// The hostile values that upstream is not asked about: it would print the whole value in
    /// its message (a sparse array of 2^32 - 1: minutes), count a typed array's 2^26 entries
    /// (gigabytes), or recurse once per level into serde's buffer (the stack). The fork reads
    /// them in the boundary fuzz (tests/boundary/).
    const NOT_UPSTREAM: [&str; 5] = [
        "sparse Array(2^32-1)",
        "sparse Array(2^27)",
        "huge Float32Array (2^26+1)",
        "deep array (10⁴)",
        "deep array (10⁵)",
    ];

    /// The hostile values fed only in place of a whole argument, not planted at every path
    /// (each is 10⁵ elements or 10⁶ characters, read twice per read).
    const HEAVY: [&str; 3] = ["10⁶-char string", "Array(1e5) of 0", "{impulses: huge}"];

    /// The boundary fuzz's hostile values and its table of exports with their valid arguments
    /// (tests/boundary/fuzz.mjs, read as a script).
    fn fuzz_corpus() -> (Vec<(String, Function)>, Array) {
        let source = include_str!("../../../tests/boundary/fuzz.mjs")
            .replace("\nexport const ", "\nconst ")
            .replace("\nexport function ", "\nfunction ");
        let load = Function::new_no_args(&format!(
            "{source}\nreturn [HOSTILE, exportsTable({{ canvas: () => null }})];"
        ));
        let both: Array = load.call0(&JsValue::NULL).unwrap().dyn_into().unwrap();
        let hostile = Array::from(&both.get(0))
            .iter()
            .map(|pair| {
                let pair = Array::from(&pair);
                (
                    pair.get(0).as_string().unwrap(),
                    pair.get(1).dyn_into().unwrap(),
                )
            })
            .collect();
        (hostile, both.get(1).dyn_into().unwrap())
    }

    fn with_state<R>(f: impl FnOnce(&mut State) -> R) -> R {
        STATE.with(|s| f(&mut s.borrow_mut()))
    }

    /// Feeds `make()`'s value with `label` as the hostile value being fed.
    fn feeding<R>(label: Option<&str>, f: impl FnOnce() -> R) -> R {
        with_state(|s| {
            s.hostile = label.map(str::to_string);
            s.skip = label.is_some_and(|l| NOT_UPSTREAM.contains(&l));
        });
        let r = f();
        with_state(|s| {
            s.hostile = None;
            s.skip = false;
        });
        r
    }

    type Call = fn(&[JsValue]) -> Result<JsValue, JsValue>;

    /// Every export the fuzz table names, by its JS name (the drawing exports are left out:
    /// without a canvas, in Node, they stop at the canvas before reading anything).
    fn export(name: &str) -> Option<Call> {
        fn arg(args: &[JsValue], i: usize) -> JsValue {
            args.get(i).cloned().unwrap_or(JsValue::UNDEFINED)
        }
        Some(match name {
            "design" => |a| wasm::design(arg(a, 0)),
            "residualVibration" => {
                |a| wasm::residual_vibration(arg(a, 0), arg(a, 1)).map(JsValue::from)
            }
            "sensitivity" => |a| wasm::sensitivity(arg(a, 0), arg(a, 1)),
            "insensitivity" => |a| wasm::insensitivity(arg(a, 0), arg(a, 1), arg(a, 2)),
            "sensitivityMap" => |a| wasm::sensitivity_map(arg(a, 0), arg(a, 1)),
            "dampingSensitivity" => |a| wasm::damping_sensitivity(arg(a, 0), arg(a, 1)),
            "dampingInsensitivity" => {
                |a| wasm::damping_insensitivity(arg(a, 0), arg(a, 1), arg(a, 2))
            }
            "robustnessTable" => |a| wasm::robustness_table(arg(a, 0), arg(a, 1), arg(a, 2)),
            "exportShaper" => |a| wasm::export_shaper(arg(a, 0), arg(a, 1)).map(JsValue::from),
            "klipperFigures" => |a| wasm::klipper_figures(arg(a, 0), arg(a, 1)),
            "rampDelay" => |a| wasm::ramp_delay(arg(a, 0), arg(a, 1)).map(JsValue::from),
            "sampledReport" => |a| wasm::sampled_report(arg(a, 0)),
            "quantize" => |a| wasm::quantize(arg(a, 0), arg(a, 1), arg(a, 2)),
            "simulate" => |a| wasm::simulate(arg(a, 0)),
            "spectrum" => |a| wasm::spectrum(arg(a, 0)),
            "renderPlayground" => |a| wasm::render_playground(arg(a, 0), arg(a, 1)),
            "parseRecording" => |a| wasm::parse_recording(arg(a, 0), arg(a, 1)),
            "welch" => |a| wasm::welch_js(arg(a, 0), arg(a, 1)),
            "fftSpectrum" => |a| wasm::fft_spectrum_js(arg(a, 0), arg(a, 1)),
            "identifyModes" => |a| wasm::identify_modes(arg(a, 0), arg(a, 1)),
            "recommendShaper" => |a| wasm::recommend_shaper(arg(a, 0), arg(a, 1), arg(a, 2)),
            "firmwareConfig" => |a| wasm::firmware_config_js(arg(a, 0)),
            "new RecordingParser" => {
                |a| wasm::measure::JsRecordingParser::new(arg(a, 0)).map(|_| JsValue::NULL)
            }
            _ => return None,
        })
    }

    /// Every path to a value inside `value` (keys of objects, indices of arrays), to depth 3.
    fn paths(
        value: &JsValue,
        depth: usize,
        prefix: &mut Vec<JsValue>,
        out: &mut Vec<Vec<JsValue>>,
    ) {
        if depth == 0 || !value.is_object() || js_sys::ArrayBuffer::is_view(value) {
            return;
        }
        for key in Object::keys(value.unchecked_ref::<Object>()).iter().take(6) {
            let key = if Array::is_array(value) {
                JsValue::from(key.as_string().unwrap().parse::<f64>().unwrap())
            } else {
                key
            };
            prefix.push(key.clone());
            out.push(prefix.clone());
            paths(&Reflect::get(value, &key).unwrap(), depth - 1, prefix, out);
            prefix.pop();
        }
    }

    /// `make()` with `hostile` set at `path`.
    fn planted(make: &dyn Fn() -> JsValue, path: &[JsValue], hostile: &JsValue) -> JsValue {
        let root = make();
        let mut at = root.clone();
        for key in &path[..path.len() - 1] {
            at = Reflect::get(&at, key).unwrap();
        }
        Reflect::set(&at, &path[path.len() - 1], hostile).unwrap();
        root
    }

    /// Feeds `make()`, then each hostile value in its place and at each of its inner paths,
    /// to `read`.
    fn feed_all(
        hostile: &[(String, Function)],
        make: &dyn Fn() -> JsValue,
        read: &mut dyn FnMut(JsValue),
    ) {
        feeding(None, || read(make()));
        let mut inner = Vec::new();
        paths(&make(), 3, &mut Vec::new(), &mut inner);
        for (label, value) in hostile {
            let fresh = || value.call0(&JsValue::NULL).unwrap();
            feeding(Some(label), || read(fresh()));
            if HEAVY.contains(&label.as_str()) {
                continue;
            }
            for path in &inner {
                let v = planted(make, path, &fresh());
                feeding(Some(label), || read(v));
            }
        }
    }

    /// The family table's specs at their defaults (counts as integers), each with a mode.
    fn family_specs() -> Vec<String> {
        use crate::design::{ParamKind, FAMILIES};
        FAMILIES
            .iter()
            .map(|row| {
                let mut spec = serde_json::Map::new();
                spec.insert("family".into(), row.name.into());
                for p in row.params {
                    if let Some(d) = p.default {
                        let mut v = serde_json::to_value(d).unwrap();
                        if p.kind == ParamKind::Integer {
                            v = (v.as_f64().unwrap() as i64).into();
                        }
                        spec.insert(p.name.into(), v);
                    }
                }
                spec.insert(
                    "modes".into(),
                    serde_json::json!([{ "frequencyHz": 40, "damping": 0.05 }]),
                );
                serde_json::Value::Object(spec).to_string()
            })
            .collect()
    }

    const COMMANDS: [&str; 11] = [
        r#"{"kind":"step"}"#,
        r#"{"kind":"step","distance":2,"start":0.1}"#,
        r#"{"kind":"ramp","slope":3}"#,
        r#"{"kind":"trapezoid","distance":1,"maxVelocity":1,"maxAcceleration":4}"#,
        r#"{"kind":"sCurve","distance":1,"maxVelocity":1,"maxAcceleration":4,"maxJerk":100}"#,
        r#"{"kind":"sampled","samplePeriod":0.01,"values":[0,0.5,1],"interpolation":"hold"}"#,
        r#"{"kind":"profile","shape":"pulse","frequencyHz":2,"distance":1,"duration":1}"#,
        r#"{"kind":"profile","shape":"triangle","frequencyHz":2,"distance":1,"duration":1}"#,
        r#"{"kind":"profile","shape":"robustTrapezium","frequencyHz":2,"deltaHz":0.4,"distance":1,"duration":1.5}"#,
        r#"{"kind":"profile","shape":"multiMode","modesHz":[2,5],"distance":1,"duration":1.5}"#,
        r#"{"kind":"profile","shape":"multiMode","modesHz":[2,5],"commonHz":1,"distance":1,"duration":1.5}"#,
    ];

    const PLANTS: [&str; 5] = [
        r#"{"kind":"modal","modes":[{"frequencyHz":4,"damping":0.05},{"frequencyHz":9}]}"#,
        r#"{"kind":"twoMass","baseMass":1,"tipMass":1,"stiffness":10}"#,
        r#"{"kind":"pendulum","length":0.5}"#,
        r#"{"kind":"pendulum","length":0.5,"gravity":9.7,"damping":0.01}"#,
        r#"{"kind":"vecianaTestBed"}"#,
    ];

    /// Every read in the corpus agrees with upstream, or differs only as a rule of [`judge`]
    /// says; every rule is needed; every spec and options type is read.
    #[wasm_bindgen_test]
    #[ignore = "unfinished (issue 21 item 4): upstream's read of a hostile value (a Set or Map whose entries are not pairs) throws through wasm-bindgen's debug import wrapper and the Node run exits; the rules are not yet checked against a full run"]
    fn the_forks_read_the_corpus_as_upstream_does() {
        use crate::command::CommandSpec;
        use crate::design::DesignRequest;
        use crate::plant::PlantSpec;
        use crate::profile::ProfileSpec;
        use crate::scenario::{SimulationSpec, SpectrumSpec};
        with_state(|s| {
            *s = State {
                on: true,
                ..State::default()
            }
        });
        let (hostile, table) = fuzz_corpus();
        let direct = |text: String| move || js(&text);
        // The spec types, read directly (no design, no simulation: the corpus is large).
        let read = |v: JsValue| {
            let _ = super::super::deserialize::<DesignRequest>(v);
        };
        for spec in family_specs() {
            feed_all(&hostile, &direct(spec), &mut |v| read(v));
        }
        for command in COMMANDS {
            let spec = format!(
                r#"{{"command":{command},"shaper":{{"family":"zvd","modes":[{{"frequencyHz":2}}]}},"toHz":5,"points":16}}"#
            );
            feed_all(&hostile, &direct(command.into()), &mut |v| {
                let _ = super::super::deserialize::<CommandSpec>(v);
            });
            feed_all(&hostile, &direct(spec), &mut |v| {
                let _ = super::super::deserialize::<SpectrumSpec>(v);
            });
            if let Some(profile) = command.strip_prefix(r#"{"kind":"profile","#) {
                feed_all(&hostile, &direct(format!("{{{profile}")), &mut |v| {
                    let _ = super::super::deserialize::<ProfileSpec>(v);
                });
            }
        }
        for plant in PLANTS {
            let spec = format!(
                r#"{{"plant":{plant},"command":{{"kind":"step"}},"shaper":{{"family":"ei","vtol":0.05}},"sampleRateHz":100}}"#
            );
            feed_all(&hostile, &direct(plant.into()), &mut |v| {
                let _ = super::super::deserialize::<PlantSpec>(v);
            });
            feed_all(&hostile, &direct(spec), &mut |v| {
                let _ = super::super::deserialize::<SimulationSpec>(v);
            });
        }
        // The libFuzzer seeds (design, simulation or spectrum specs, as the target reads them).
        for (name, text) in SEEDS {
            let Ok(v) = JSON::parse(text) else { continue };
            let _ = name;
            feeding(None, || {
                let _ = super::super::deserialize::<DesignRequest>(v.clone());
                let _ = super::super::deserialize::<SimulationSpec>(v.clone());
                let _ = super::super::deserialize::<SpectrumSpec>(v);
            });
        }
        // Every export, with the fuzz table's valid arguments, hostile values in each argument
        // and planted inside each.
        let mut exported = 0;
        for e in table.iter() {
            let name = Reflect::get(&e, &"name".into())
                .unwrap()
                .as_string()
                .unwrap();
            let Some(call) = export(&name) else { continue };
            exported += 1;
            let args: Function = Reflect::get(&e, &"args".into())
                .unwrap()
                .dyn_into()
                .unwrap();
            let valid = || Array::from(&args.call0(&JsValue::NULL).unwrap());
            let n = valid().length();
            for i in 0..n {
                let make = || valid().get(i);
                feed_all(&hostile, &make, &mut |v| {
                    let mut a: Vec<JsValue> = valid().iter().collect();
                    a[i as usize] = v;
                    let _ = call(&a);
                });
            }
        }
        let state = with_state(std::mem::take);
        assert!(
            state.failures.is_empty(),
            "{} reads differ from upstream beyond the rules:\n{}",
            state.failures.len(),
            state.failures.join("\n")
        );
        assert!(exported >= 23, "only {exported} exports fed");
        for rule in [
            Rule::Identical,
            Rule::DescribedNotPrinted,
            Rule::LongStringCut,
            Rule::TaggedPathAndNames,
            Rule::ThrowCaught,
            Rule::TypedArrayNotEntries,
            Rule::MapNotSpec,
        ] {
            assert!(
                state.accepted.get(&rule).copied().unwrap_or(0) > 0,
                "rule {rule:?} was never needed: {:?}",
                state.accepted
            );
        }
        // Every type a JS argument is read into (module paths shortened), compared at least
        // 50 times.
        let read: BTreeMap<String, usize> = state
            .types
            .iter()
            .map(|(t, n)| (t.rsplit("::").next().unwrap_or(t).to_string(), *n))
            .collect();
        for ty in [
            "DesignRequest",
            "ShaperData",
            "ModeSpec",
            "SensitivityOptions",
            "SensitivityMapOptions",
            "DampingSensitivityOptions",
            "ExportOptions",
            "Options",
            "QuantizeOptions",
            "SimulationSpec",
            "SpectrumSpec",
            "CommandSpec",
            "PlantSpec",
            "ProfileSpec",
            "PlaygroundState",
            "RecordingOptions",
            "WelchOptions",
            "FftOptions",
            "IdentifyOptions",
            "ChannelChoice",
            "RecommendOptions",
            "Request",
        ] {
            assert!(
                read.get(ty).copied().unwrap_or(0) >= 50,
                "{ty} compared {:?} times: {read:?}",
                read.get(ty)
            );
        }
        web_sys::console::log_1(
            &format!(
                "differential: {:?}; not asked of upstream: {}; per type: {read:?}",
                state.accepted, state.skipped
            )
            .into(),
        );
    }

    /// The libFuzzer target's seed corpus (fuzz/corpus/spec).
    const SEEDS: [(&str, &str); 30] = [
        (
            "seed-01.json",
            include_str!("../../../fuzz/corpus/spec/seed-01.json"),
        ),
        (
            "seed-02.json",
            include_str!("../../../fuzz/corpus/spec/seed-02.json"),
        ),
        (
            "seed-03.json",
            include_str!("../../../fuzz/corpus/spec/seed-03.json"),
        ),
        (
            "seed-04.json",
            include_str!("../../../fuzz/corpus/spec/seed-04.json"),
        ),
        (
            "seed-05.json",
            include_str!("../../../fuzz/corpus/spec/seed-05.json"),
        ),
        (
            "seed-06.json",
            include_str!("../../../fuzz/corpus/spec/seed-06.json"),
        ),
        (
            "seed-07.json",
            include_str!("../../../fuzz/corpus/spec/seed-07.json"),
        ),
        (
            "seed-08.json",
            include_str!("../../../fuzz/corpus/spec/seed-08.json"),
        ),
        (
            "seed-09.json",
            include_str!("../../../fuzz/corpus/spec/seed-09.json"),
        ),
        (
            "seed-10.json",
            include_str!("../../../fuzz/corpus/spec/seed-10.json"),
        ),
        (
            "seed-11.json",
            include_str!("../../../fuzz/corpus/spec/seed-11.json"),
        ),
        (
            "seed-12.json",
            include_str!("../../../fuzz/corpus/spec/seed-12.json"),
        ),
        (
            "seed-13.json",
            include_str!("../../../fuzz/corpus/spec/seed-13.json"),
        ),
        (
            "seed-14.json",
            include_str!("../../../fuzz/corpus/spec/seed-14.json"),
        ),
        (
            "seed-15.json",
            include_str!("../../../fuzz/corpus/spec/seed-15.json"),
        ),
        (
            "seed-16.json",
            include_str!("../../../fuzz/corpus/spec/seed-16.json"),
        ),
        (
            "seed-17.json",
            include_str!("../../../fuzz/corpus/spec/seed-17.json"),
        ),
        (
            "seed-18.json",
            include_str!("../../../fuzz/corpus/spec/seed-18.json"),
        ),
        (
            "seed-19.json",
            include_str!("../../../fuzz/corpus/spec/seed-19.json"),
        ),
        (
            "seed-20.json",
            include_str!("../../../fuzz/corpus/spec/seed-20.json"),
        ),
        (
            "seed-21.json",
            include_str!("../../../fuzz/corpus/spec/seed-21.json"),
        ),
        (
            "seed-22.json",
            include_str!("../../../fuzz/corpus/spec/seed-22.json"),
        ),
        (
            "seed-23.json",
            include_str!("../../../fuzz/corpus/spec/seed-23.json"),
        ),
        (
            "seed-24.json",
            include_str!("../../../fuzz/corpus/spec/seed-24.json"),
        ),
        (
            "seed-25.json",
            include_str!("../../../fuzz/corpus/spec/seed-25.json"),
        ),
        (
            "seed-26.json",
            include_str!("../../../fuzz/corpus/spec/seed-26.json"),
        ),
        (
            "seed-27.json",
            include_str!("../../../fuzz/corpus/spec/seed-27.json"),
        ),
        (
            "seed-28.json",
            include_str!("../../../fuzz/corpus/spec/seed-28.json"),
        ),
        (
            "seed-29.json",
            include_str!("../../../fuzz/corpus/spec/seed-29.json"),
        ),
        (
            "seed-30.json",
            include_str!("../../../fuzz/corpus/spec/seed-30.json"),
        ),
    ];
}
