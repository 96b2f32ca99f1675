//! The forks checked against upstream (issue 21 item 4). Every read of a JS value in this
//! crate's tests is made three times:
//!
//! - *upstream*: `serde_path_to_error::deserialize` over `serde_wasm_bindgen::Deserializer`
//!   0.6.5, the pair [`super`] folds into one type, with serde's own (buffered) parser for the
//!   internally tagged specs and flattened structs;
//! - *buffered*: the fork's reader ([`super::deserialize`]) with serde's same buffered parser
//!   (`crate::tagged::BUFFERED`);
//! - *fork*: the fork's reader with `crate::tagged`'s tag-first reading, as shipped.
//!
//! upstream against buffered checks the reader fork (crate/js/jsde.rs); buffered against fork
//! checks the tagged-enum fork (crate/tagged.rs). Each pair must give the same value (`Debug`),
//! or the same error path and message, except where a fork differs on purpose: those
//! differences are exactly the rules of [`judge_reader`] and [`judge_tagged`] (each [`Rule`]
//! says what and why, and docs/page-performance.md, *The forks, re-measured*, lists them). Any
//! other difference fails the test, and each rule must have been needed at least once (a rule
//! that never fires is no longer true of the fork: remove it). The corpus: the family table's
//! specs, commands, profiles, plants, simulation and spectrum specs, every export's valid
//! arguments (`tests/boundary/fuzz.mjs`' table), the boundary fuzz's hostile values in every
//! argument and planted at every key, and the libFuzzer seed corpus `fuzz/corpus/spec`.

use serde::de::DeserializeOwned;
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::fmt::Debug;
use std::rc::Rc;
use std::sync::atomic::Ordering;
use wasm_bindgen::prelude::*;

/// What one reader made of a value.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Outcome {
    /// The value read, as `Debug` prints it.
    Value(String),
    /// The error: the path as serde_path_to_error prints it, and the message.
    Failed { path: String, message: String },
    /// A JS exception went through the reader (upstream calls some JS functions without
    /// catching their exceptions).
    Threw(String),
}

/// Why two readers' outcomes are accepted (see [`judge_reader`], [`judge_tagged`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Rule {
    /// The same value, or the same path and message.
    Identical,
    /// Reader: a value upstream prints with `Debug` (`JsValue(Symbol(x))`, the whole of an
    /// array: seconds for a sparse `new Array(2 ** 27)`) is named by what it is (`a symbol`,
    /// `an array`, `binary data`, `an object`), so an error costs the same whatever was passed.
    DescribedNotPrinted,
    /// Reader: a string of more than 40 characters is quoted to its first 40 and `…` (upstream
    /// quotes all of it: a megabyte of message for a megabyte string).
    LongStringCut,
    /// Reader: upstream let a JS exception through the module, the fork returns an error. A
    /// getter or a Proxy trap threw inside `Object.entries`, or upstream took an entry of an
    /// iterable for a `[key, value]` pair and indexed `null` (`TypeError: Cannot read
    /// properties of null (reading '0')`, in serde-wasm-bindgen's `convert_pair`, reading
    /// `[null]` where a struct with a flattened part goes). An exception through wasm skips
    /// Rust's destructors: the boundary must never let one out (issue 21).
    UpstreamThrew,
    /// Reader: a number, a string or a boolean where a list or a map goes (or a struct with a
    /// flattened part, which serde reads as a map): upstream asks it for its `Symbol.iterator`
    /// with `Reflect.get`, which throws on a primitive, and reports that (`TypeError:
    /// Reflect.get called on non-object`); the fork says `invalid type`.
    PrimitiveNotIterated,
    /// Reader: a typed array where an externally tagged enum goes: upstream counts its entries
    /// (`invalid length N, expected 1`, `Object.entries` of 2^26 elements for a long signal:
    /// gigabytes); the fork says `invalid type: binary data` (`byte array` for bytes).
    TypedArrayNotEntries,
    /// Tagged: serde's buffer loses the path at the spec and names values as it holds them;
    /// the fork names the field inside (`shapers[0].humps` for `shapers[0]`) and the value as
    /// JS has it: `map` is `an object`, `sequence` is `an array`, `unit value` is `null`,
    /// `` integer `-1` `` is `` floating point `-1.0` `` (and its `invalid value` an
    /// `invalid type`), a BigInt's `` integer `N` `` is `a BigInt`.
    TaggedPathAndNames,
    /// Tagged: serde's buffer holds only what `deserialize_any` reads, and a typed array
    /// (other than bytes), a function, a symbol or a `Set` is not that (`invalid type: …,
    /// expected any value`); the fork reads the field as its type asks, as upstream does
    /// outside a tagged spec (a `Float64Array` of numbers is a list of numbers).
    BufferCannotHold,
    /// Tagged: from the buffer, `-0` is the integer `0` and a BigInt an integer, so `-0`
    /// arrives as `0` and a BigInt is accepted where a number goes; the fork reads the JS
    /// number as it is (`-0`) and a BigInt only where an integer type goes, as upstream does
    /// outside a tagged spec.
    BufferedNumbers,
    /// Tagged: from the buffer serde reads a struct from an array by position (`[4, 0.05]` as
    /// a mode, `invalid length 0, expected struct Impulse with 2 elements`), an internally
    /// tagged enum from an array with its tag first, and bytes (`Uint8Array`) as bytes, not a
    /// list; the fork reads a struct only from an object's fields and a list from any
    /// iterable, as upstream does outside a tagged spec.
    BufferedShapes,
    /// Tagged: an externally tagged enum inside a tagged spec (`objective`, `interpolation`):
    /// from the buffer serde wants `string or map` or a `map with a single key`; the fork says
    /// what upstream says outside a tagged spec (`invalid length N, expected 1`, the value's
    /// type, `unknown variant`).
    BufferedEnumNames,
    /// Tagged: a JS `Map` is not read as a tagged spec (serde's buffer reads any iterable of
    /// pairs): the fork says the tag is missing; inside a spec the buffer holds a `Map` as a
    /// map, the fork reads it as upstream does outside a spec (a list of `[key, value]` pairs
    /// where a list goes).
    MapNotSpec,
    /// Tagged: serde's derive reads a struct with a flattened part (`DesignRequest`,
    /// `ShaperRequest`, …) as a map of all its entries, so from the buffer an array is a map
    /// of its elements (`expected field identifier`, `expected a [key, value] pair`, at `?`)
    /// and a detached or proxied typed array's iterator throws; the fork reads the struct's
    /// fields from the object (`missing field`, `invalid type`), as for any other struct.
    FlattenedReadAsMap,
    /// Tagged: the buffer reads every property of an object (`Object.entries`), the fork only
    /// the fields it needs: a getter's or a Proxy trap's throw is reported by the buffer
    /// wherever it is, by the fork where it reads it (or never, when the value is of the wrong
    /// type before any property is read).
    BufferReadsEverything,
}

/// Every rule, each of which the corpus must need.
const RULES: [Rule; 14] = [
    Rule::Identical,
    Rule::DescribedNotPrinted,
    Rule::LongStringCut,
    Rule::UpstreamThrew,
    Rule::TypedArrayNotEntries,
    Rule::TaggedPathAndNames,
    Rule::BufferCannotHold,
    Rule::BufferedNumbers,
    Rule::BufferedShapes,
    Rule::BufferedEnumNames,
    Rule::MapNotSpec,
    Rule::PrimitiveNotIterated,
    Rule::FlattenedReadAsMap,
    Rule::BufferReadsEverything,
];

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
    /// The differences no rule accepts: the first example of each pair of messages, and how
    /// many reads gave that pair.
    failures: BTreeMap<String, (usize, String)>,
}

thread_local! {
    static STATE: RefCell<State> = RefCell::new(State::default());
}

fn comparing() -> bool {
    STATE.with(|s| {
        let s = s.borrow();
        s.on && !s.skip
    })
}

/// Reads `value` as `T` with upstream, a JS exception caught (`None` when not comparing).
pub(super) fn upstream<T: DeserializeOwned + Debug>(value: &JsValue) -> Option<Outcome> {
    if !comparing() {
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
                message: message(e.inner()),
            },
        };
        *into.borrow_mut() = Some(outcome);
    });
    // Upstream's uncaught exception unwinds through the wasm frames to this catch: their
    // destructors do not run (what upstream held leaks), and the shadow stack is reset by the
    // next function frame that returns (its epilogue restores the pointer it saved).
    let guard = js_sys::Function::new_with_args(
        "f",
        "try { f(); return null; } catch (e) { try { return String(e); } catch { return 'an exception'; } }",
    );
    let thrown = guard.call1(&JsValue::NULL, &read).unwrap_or_else(|e| e);
    let outcome = out.borrow_mut().take();
    Some(outcome.unwrap_or_else(|| Outcome::Threw(thrown.as_string().unwrap_or_default())))
}

/// `read()` with the tagged specs read through serde's buffered parser (`None` when not
/// comparing).
pub(super) fn buffered<T>(
    read: impl FnOnce() -> Result<T, (String, super::Error)>,
) -> Option<Result<T, (String, super::Error)>> {
    if !comparing() {
        return None;
    }
    crate::tagged::BUFFERED.store(true, Ordering::Relaxed);
    let r = read();
    crate::tagged::BUFFERED.store(false, Ordering::Relaxed);
    Some(r)
}

/// An error's message: both readers' errors wrap a JS `Error` and print as it does
/// (`Error: invalid type: …`); the prefix is left out.
fn message(error: &serde_wasm_bindgen::Error) -> String {
    let text = error.to_string();
    text.strip_prefix("Error: ")
        .map(str::to_string)
        .unwrap_or(text)
}

fn outcome<T: Debug>(read: &Result<T, (String, super::Error)>) -> Outcome {
    match read {
        Ok(v) => Outcome::Value(format!("{v:?}")),
        Err((path, e)) => Outcome::Failed {
            path: path.clone(),
            message: message(e),
        },
    }
}

/// Compares upstream's read with the buffered one, and that with the fork's (see the module
/// docs).
pub(super) fn compare<T: Debug>(
    ty: &str,
    value: &JsValue,
    upstream: Option<Outcome>,
    buffered: Option<Result<T, (String, super::Error)>>,
    read: &Result<T, (String, super::Error)>,
) {
    let (Some(upstream), Some(buffered)) = (upstream, buffered) else {
        STATE.with(|s| {
            let mut s = s.borrow_mut();
            if s.on {
                s.skipped += 1;
            }
        });
        return;
    };
    let buffered = outcome(&buffered);
    let fork = outcome(read);
    STATE.with(|s| {
        let mut s = s.borrow_mut();
        *s.types.entry(ty.to_string()).or_default() += 1;
        let hostile = s.hostile.clone();
        for (stage, a, b, rule) in [
            (
                "reader",
                &upstream,
                &buffered,
                judge_reader(&upstream, &buffered),
            ),
            (
                "tagged",
                &buffered,
                &fork,
                judge_tagged(&buffered, &fork, hostile.as_deref()),
            ),
        ] {
            match rule {
                Some(rule) => *s.accepted.entry(rule).or_default() += 1,
                None => {
                    let key = format!("{stage}: {} | {}", shape(a), shape(b));
                    let entry = s.failures.entry(key).or_insert_with(|| {
                        let text = js_sys::JSON::stringify(value)
                            .ok()
                            .and_then(|t| t.as_string())
                            .unwrap_or_else(|| super::super::args::describe(value).into());
                        let text: String = text.chars().take(200).collect();
                        (
                            0,
                            format!("{ty} of {text} (hostile {hostile:?}):\n    {a:?}\n    {b:?}"),
                        )
                    });
                    entry.0 += 1;
                }
            }
        }
    });
}

/// An outcome with its values left out (`invalid type: _, expected f64`), to group failures.
fn shape(outcome: &Outcome) -> String {
    match outcome {
        Outcome::Value(_) => "a value".into(),
        Outcome::Threw(t) => format!("threw {}", t.chars().take(60).collect::<String>()),
        Outcome::Failed { message, .. } => match split(message) {
            Some((kind, _, expected)) => format!("invalid {kind}: _, expected {expected}"),
            None => message.chars().take(80).collect(),
        },
    }
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

/// Whether path `up` is `fork` or a path above it (`shapers[0]` above `shapers[0].humps`).
fn above(up: &str, fork: &str) -> bool {
    up == fork
        || up == "."
        || fork
            .strip_prefix(up)
            .is_some_and(|rest| rest.starts_with('.') || rest.starts_with('['))
}

/// The rule under which the fork's reader (`fork`, tagged specs buffered) stands for
/// upstream's (`up`), or `None`: a difference no rule allows.
fn judge_reader(up: &Outcome, fork: &Outcome) -> Option<Rule> {
    use Outcome::*;
    match (up, fork) {
        _ if up == fork => Some(Rule::Identical),
        (Threw(_), Failed { .. }) => Some(Rule::UpstreamThrew),
        (
            Failed {
                path: up_path,
                message: up_message,
            },
            Failed {
                path: fork_path,
                message: fork_message,
            },
        ) if up_path == fork_path
            && up_message == "TypeError: Reflect.get called on non-object"
            && fork_message.starts_with("invalid type: ") =>
        {
            Some(Rule::PrimitiveNotIterated)
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
        ) if up_path == fork_path => {
            if up_message.starts_with("invalid length ")
                && up_message.ends_with(", expected 1")
                && (fork_message.starts_with("invalid type: binary data, expected ")
                    || fork_message.starts_with("invalid type: byte array, expected "))
            {
                return Some(Rule::TypedArrayNotEntries);
            }
            let (uk, uu, ue) = split(up_message)?;
            let (fk, fu, fe) = split(fork_message)?;
            if uk != fk || ue != fe {
                return None;
            }
            if uu.starts_with("JsValue(") && DESCRIBED.contains(&fu) {
                return Some(Rule::DescribedNotPrinted);
            }
            let u = uu.strip_prefix("string \"")?.strip_suffix('"')?;
            let f = fu.strip_prefix("string \"")?.strip_suffix("…\"")?;
            (u.starts_with(f) && f.chars().count() == 40).then_some(Rule::LongStringCut)
        }
        _ => None,
    }
}

/// Whether the buffer's unexpected value `buf` (of an `invalid <kind>` error) is the fork's
/// `fork` as JS has it (see [`Rule::TaggedPathAndNames`]).
fn same_value_named(buf: &str, fork: &str) -> bool {
    buf == fork
        || matches!(
            (buf, fork),
            ("map", "an object" | "binary data")
                | ("sequence", "an array")
                | ("unit value", "null")
        )
        || buf
            .strip_prefix("integer `")
            .and_then(|n| n.strip_suffix('`'))
            .is_some_and(|n| {
                fork == format!("floating point `{n}.0`")
                    || fork == "a BigInt"
                    || (n == "0" && fork == "floating point `-0.0`")
            })
}

/// The rule under which the tag-first fork's `fork` stands for the buffered read `buf`
/// (`hostile`: the label of the hostile value being fed), or `None`.
fn judge_tagged(buf: &Outcome, fork: &Outcome, hostile: Option<&str>) -> Option<Rule> {
    use Outcome::*;
    match (buf, fork) {
        _ if buf == fork => Some(Rule::Identical),
        (Value(b), Value(f)) => (*b == f.replace("-0.0", "0.0")).then_some(Rule::BufferedNumbers),
        (Value(_), Failed { message, .. }) => {
            if hostile == Some("Map") && message.starts_with("missing field `") {
                Some(Rule::MapNotSpec)
            } else if message.starts_with("invalid type: a BigInt, expected ") {
                Some(Rule::BufferedNumbers)
            } else if message.starts_with("missing field `") {
                // An array read as a struct by position (the hostile value is an array).
                is_array(hostile).then_some(Rule::BufferedShapes)
            } else {
                None
            }
        }
        (Failed { message, .. }, Value(_)) => message
            .starts_with("invalid type: byte array, expected ")
            .then_some(Rule::BufferedShapes)
            .or_else(|| {
                message
                    .ends_with(", expected any value")
                    .then_some(Rule::BufferCannotHold)
            }),
        (
            Failed {
                path: buf_path,
                message: buf_message,
            },
            Failed {
                path: fork_path,
                message: fork_message,
            },
        ) => judge_tagged_errors((buf_path, buf_message), (fork_path, fork_message), hostile),
        _ => None,
    }
}

/// Whether the hostile value being fed is an array.
fn is_array(hostile: Option<&str>) -> bool {
    hostile.is_some_and(|h| {
        h.starts_with('[') || h.starts_with("Array(") || h.contains("Proxy of an array")
    })
}

/// [`judge_tagged`] of two errors, `(path, message)` each.
fn judge_tagged_errors(
    (buf_path, buf_message): (&str, &str),
    (fork_path, fork_message): (&str, &str),
    hostile: Option<&str>,
) -> Option<Rule> {
    if let Some(rule) =
        buffer_read_otherwise((buf_path, buf_message), (fork_path, fork_message), hostile)
    {
        return Some(rule);
    }
    if !above(buf_path, fork_path) {
        return None;
    }
    if buf_message == fork_message {
        return Some(Rule::TaggedPathAndNames);
    }
    let buf_split = split(buf_message);
    if let Some((_, _, expected)) = buf_split {
        if expected == "any value" || expected.starts_with("internally tagged enum ") {
            return Some(Rule::BufferCannotHold);
        }
        if expected == "string or map" || expected == "map with a single key" {
            return Some(Rule::BufferedEnumNames);
        }
    }
    if buf_message.starts_with("invalid length ")
        && (buf_message.contains(", expected struct ")
            || buf_message.ends_with(" elements in sequence"))
    {
        return Some(Rule::BufferedShapes);
    }
    if buf_message.starts_with("invalid type: byte array, expected ")
        || (buf_message.starts_with("unknown variant `")
            && fork_message.starts_with("invalid type: byte array, expected "))
    {
        // Bytes from the buffer are bytes, a variant's name among them.
        return Some(Rule::BufferedShapes);
    }
    if buf_message.contains(", expected variant index ")
        && fork_message.starts_with("invalid type: a BigInt, expected ")
    {
        return Some(Rule::BufferedNumbers);
    }
    let (bk, bu, be) = buf_split?;
    let (fk, fu, fe) = split(fork_message)?;
    (be == fe && fk == "type" && (bk == "type" || bk == "value") && same_value_named(bu, fu))
        .then_some(Rule::TaggedPathAndNames)
}

/// The rules of [`judge_tagged_errors`] where the buffer read the value another way (as a map
/// of all its entries, every property, a `Map`, an array by position), the paths related
/// either way.
fn buffer_read_otherwise(
    (buf_path, buf_message): (&str, &str),
    (fork_path, fork_message): (&str, &str),
    hostile: Option<&str>,
) -> Option<Rule> {
    let buf_struct = buf_path
        .strip_suffix(".?")
        .or_else(|| {
            buf_path
                .strip_suffix('?')
                .map(|p| if p.is_empty() { "." } else { p })
        })
        .unwrap_or(buf_path);
    let throwing = matches!(
        hostile,
        Some("throwing getters" | "Proxy with throwing traps")
    );
    if (buf_message.starts_with("could not be read (") || throwing)
        && (above(buf_path, fork_path) || above(fork_path, buf_path))
    {
        return Some(Rule::BufferReadsEverything);
    }
    let fork_struct = fork_message.starts_with("missing field `")
        || (fork_message.starts_with("invalid type: ")
            && fork_message.contains(", expected struct "));
    if fork_struct
        && above(buf_struct, fork_path)
        && (buf_message == "TypeError: Reflect.get called on non-object"
            || buf_message.starts_with("TypeError: Cannot perform %TypedArray%")
            || buf_message == "TypeError: this is not a typed array."
            || buf_message.ends_with(", expected field identifier")
            || buf_message.ends_with(", expected a [key, value] pair"))
    {
        return Some(Rule::FlattenedReadAsMap);
    }
    if hostile == Some("Map") {
        return Some(Rule::MapNotSpec);
    }
    if is_array(hostile)
        && fork_message.starts_with("missing field `")
        && (above(buf_path, fork_path) || above(fork_path, buf_path))
    {
        // From the buffer an array is a struct by position, an internally tagged
        // enum's tag its first element.
        return Some(Rule::BufferedShapes);
    }
    None
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

    /// Of the hostile values planted inside a value, one in `STRIDE` is fed (the `i`-th
    /// hostile value at the `j`-th path when `(i + j) % STRIDE == 0`, so each value and each
    /// path is still fed); every hostile value is fed in place of the whole value.
    static STRIDE: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(1);

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
        let stride = STRIDE.load(Ordering::Relaxed);
        for (i, (label, value)) in hostile.iter().enumerate() {
            let fresh = || value.call0(&JsValue::NULL).unwrap();
            feeding(Some(label), || read(fresh()));
            if HEAVY.contains(&label.as_str()) {
                continue;
            }
            for (j, path) in inner.iter().enumerate() {
                if (i + j) % stride != 0 {
                    continue;
                }
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

    #[wasm_bindgen_test]
    #[ignore = "the whole corpus: ~4 min in Node (debug wasm); `cargo test --target wasm32-unknown-unknown --lib -- --include-ignored the_forks_read_the_whole_corpus`"]
    fn the_forks_read_the_whole_corpus_as_upstream_does() {
        STRIDE.store(1, Ordering::Relaxed);
        the_forks_read_the_corpus_as_upstream_does();
    }

    /// In `npm test`: every value of the corpus and every hostile value in place of each, and
    /// one in four of the hostile values planted inside them.
    #[wasm_bindgen_test]
    fn the_forks_read_a_quarter_of_the_corpus_as_upstream_does() {
        STRIDE.store(4, Ordering::Relaxed);
        the_forks_read_the_corpus_as_upstream_does();
    }

    /// Every read in the corpus agrees with upstream, or differs only as a rule of
    /// [`judge_reader`] / [`judge_tagged`] says; every rule is needed; every spec and options
    /// type is read.
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
        check(with_state(std::mem::take), exported);
    }

    /// What the test asserts of a run: no difference beyond the rules, every rule needed,
    /// every export fed and every type a JS argument is read into compared.
    fn check(state: State, exported: usize) {
        assert!(
            state.failures.is_empty(),
            "{} kinds of reads differ from upstream beyond the rules:\n{}",
            state.failures.len(),
            state
                .failures
                .iter()
                .map(|(key, (n, example))| format!("{n} × {key}\n  e.g. {example}"))
                .collect::<Vec<_>>()
                .join("\n")
        );
        assert!(exported >= 23, "only {exported} exports fed");
        for rule in RULES {
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
