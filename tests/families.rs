//! The family table (`FAMILIES`, crate/design/family.rs) is the single source of a family's
//! name, parameters, limits, defaults and need of the solver. These tests tie it to what the
//! library does: every row parses to its spec variant and designs from its defaults, every limit
//! it states is the one the design enforces, its `solver` says which designs the solver makes,
//! and the family tables of docs/families.md and README.md are the ones generated from it
//! (`UPDATE_DOCS=1 cargo test --test families` rewrites them).

use input_shaping::design::{
    design_for, design_solved_for, FamilyInfo, ParamDefault, ParamInfo, ParamKind, Solver, FAMILIES,
};
use input_shaping::{Mode, ShaperSpec};
use serde_json::{json, Map, Value};
use wasm_bindgen_test::wasm_bindgen_test;

/// A row's parameters at their defaults (the optional ones without a default left out), as the
/// page's editor starts a spec.
fn defaults(row: &FamilyInfo) -> Map<String, Value> {
    let mut spec = Map::new();
    spec.insert("family".into(), json!(row.name));
    for p in row.params {
        if let Some(d) = p.default {
            spec.insert(p.name.into(), value(p, d));
        }
    }
    spec
}

/// A default as JSON (a whole number for an integer parameter: a spec's counts are integers).
fn value(p: &ParamInfo, d: ParamDefault) -> Value {
    match (p.kind, d) {
        (ParamKind::Integer, ParamDefault::Number(x)) => json!(x as u64),
        _ => serde_json::to_value(d).unwrap(),
    }
}

fn parse(spec: &Map<String, Value>) -> ShaperSpec {
    serde_json::from_value(Value::Object(spec.clone()))
        .unwrap_or_else(|e| panic!("{spec:?} does not parse: {e}"))
}

/// The page's default mode: 2 Hz, ζ = 0.05 (web/state.js).
fn mode() -> Vec<Mode> {
    vec![Mode::new(2.0, 0.05).unwrap()]
}

/// `parameters` lists the names of `params`, in order, and no row or parameter is repeated.
#[wasm_bindgen_test(unsupported = test)]
fn parameters_are_the_params_names() {
    let mut names: Vec<&str> = FAMILIES.iter().map(|f| f.name).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), FAMILIES.len(), "a family is listed twice");
    for row in FAMILIES {
        let from_params: Vec<&str> = row.params.iter().map(|p| p.name).collect();
        assert_eq!(row.parameters, from_params.as_slice(), "{}", row.name);
        let mut unique = from_params.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), from_params.len(), "{}", row.name);
        for p in row.params {
            assert_eq!(
                p.kind == ParamKind::Select,
                !p.options.is_empty(),
                "{}.{}: options belong to a select",
                row.name,
                p.name
            );
            if let (Some(min), Some(max)) = (p.min, p.max) {
                assert!(min < max, "{}.{}", row.name, p.name);
            }
            if let Some(ParamDefault::Number(d)) = p.default {
                assert!(
                    p.min.is_none_or(|m| d >= m) && p.max.is_none_or(|m| d <= m),
                    "{}.{}: default {d} outside its limits",
                    row.name,
                    p.name
                );
            }
            assert!(
                p.default.is_some() || p.optional || p.kind == ParamKind::Pairs,
                "{}.{}: a required parameter without a default",
                row.name,
                p.name
            );
        }
    }
}

/// Every row is a spec variant (its spec from the defaults parses, to the variant that names
/// this row), and every row designs from its defaults: the dispatch has an arm for each row.
/// Together with the exhaustive matches of `ShaperSpec::name` and the dispatch (every variant
/// has a name and a design), rows and designs are one to one.
#[wasm_bindgen_test(unsupported = test)]
fn every_row_parses_and_designs_from_its_defaults() {
    for row in FAMILIES {
        let spec = parse(&defaults(row));
        assert_eq!(spec.name(), row.name);
        assert_eq!(spec.info(), Some(row));
        let shaper = design_for(&spec, &mode())
            .unwrap_or_else(|e| panic!("{}: the defaults do not design: {e}", row.name));
        assert!(!shaper.impulses().is_empty());
    }
}

/// `solver` says which families `design_solved_for` (the design worker's entry, the solver's
/// families only) designs: `never` is refused at `family`; the others design there as through
/// `design_for`. (Without the solver, `always` and bounded `whenBounded` designs are
/// unavailable: tests/without_solver.rs.)
#[wasm_bindgen_test(unsupported = test)]
fn solver_column_matches_the_solved_dispatch() {
    for row in FAMILIES {
        let spec = parse(&defaults(row));
        let solved = design_solved_for(&spec, &mode());
        match row.solver {
            Solver::Never => {
                let e = solved.expect_err(row.name);
                assert_eq!(e.field(), Some("family"), "{}: {e}", row.name);
            }
            Solver::Always | Solver::WhenBounded => {
                assert_eq!(solved.unwrap(), design_for(&spec, &mode()).unwrap());
            }
        }
    }
}

/// A value just beyond a limit.
fn beyond(p: &ParamInfo, limit: f64, up: bool) -> f64 {
    let sign = if up { 1.0 } else { -1.0 };
    match p.kind {
        ParamKind::Integer => limit + sign,
        _ => limit + sign * 0.01 * limit.abs().max(1e-3),
    }
}

/// A row's defaults asking the least: every count at its minimum, the optional parameters out.
fn least(row: &FamilyInfo) -> Map<String, Value> {
    let mut spec = defaults(row);
    for p in row.params {
        if p.optional {
            spec.remove(p.name);
        } else if let (ParamKind::Integer, Some(min)) = (p.kind, p.min) {
            spec.insert(p.name.into(), json!(min as u64));
        }
    }
    spec
}

/// Every limit the table states is the design's: a value just beyond it is refused at that
/// parameter's field, and a required whole-number parameter designs at its limits: at its
/// maximum with the other defaults, at its minimum with the others asking the least of it
/// (every other count at its minimum, optional parameters left out). An undamped mode, so no
/// family ends early for its damping.
#[wasm_bindgen_test(unsupported = test)]
fn limits_are_the_designs_limits() {
    let modes = [Mode::new(2.0, 0.0).unwrap()];
    let mut checked = 0;
    for row in FAMILIES {
        for p in row.params {
            for (limit, up) in [(p.min, false), (p.max, true)] {
                let Some(limit) = limit else { continue };
                let value = beyond(p, limit, up);
                // A negative count does not parse: nothing to check below 0 for a count.
                if p.kind == ParamKind::Integer && value < 0.0 {
                    continue;
                }
                let mut spec = defaults(row);
                spec.insert(p.name.into(), json!(value));
                if p.kind == ParamKind::Integer {
                    spec.insert(p.name.into(), json!(value as u64));
                }
                let e = design_for(&parse(&spec), &modes).expect_err(&format!(
                    "{}.{} = {value} beyond its limit {limit} designs",
                    row.name, p.name
                ));
                assert_eq!(e.field(), Some(p.name), "{}.{}: {e}", row.name, p.name);
                if p.kind == ParamKind::Integer && !p.optional {
                    let mut spec = if up { defaults(row) } else { least(row) };
                    spec.insert(p.name.into(), json!(limit as u64));
                    design_for(&parse(&spec), &modes).unwrap_or_else(|e| {
                        panic!("{}.{} = {limit} (its limit) fails: {e}", row.name, p.name)
                    });
                }
                checked += 1;
            }
        }
    }
    assert!(checked >= 10, "only {checked} limits checked");
}

/// A number as the docs write it.
fn num(x: f64) -> String {
    format!("{x}")
}

/// One parameter as the docs' table describes it.
fn describe(p: &ParamInfo) -> String {
    let kind = match p.kind {
        ParamKind::Number => "number",
        ParamKind::Integer => "integer",
        ParamKind::Numbers => "list of numbers",
        ParamKind::Percent => "fraction",
        ParamKind::Select => "one of",
        ParamKind::Boolean => "true or false",
        ParamKind::Pairs => "impulses `[{ time, amplitude }]`",
        ParamKind::Points => "points `[[x, y], …]`",
    };
    let mut out = format!("`{}`: {kind}", p.name);
    if !p.options.is_empty() {
        let options: Vec<String> = p.options.iter().map(|o| format!("`\"{o}\"`")).collect();
        out += &format!(" {}", options.join(", "));
    }
    match (p.min, p.max) {
        (Some(a), Some(b)) => out += &format!(" {} … {}", num(a), num(b)),
        (None, Some(b)) => out += &format!(" ≤ {}", num(b)),
        (Some(a), None) => out += &format!(" ≥ {}", num(a)),
        (None, None) => {}
    }
    match p.default {
        Some(ParamDefault::Number(d)) => out += &format!(", default {}", num(d)),
        Some(ParamDefault::Text(t)) => out += &format!(", default `\"{t}\"`"),
        Some(ParamDefault::Flag(b)) => out += &format!(", default `{b}`"),
        Some(ParamDefault::Impulses(imps)) => {
            let list: Vec<String> = imps
                .iter()
                .map(|i| format!("({}, {})", num(i.time), num(i.amplitude)))
                .collect();
            out += &format!(", e.g. {}", list.join(", "));
        }
        None => {}
    }
    if p.optional {
        out += ", optional";
    }
    out
}

/// The family table of docs/families.md, from `FAMILIES`.
fn table() -> String {
    let mut out = String::from(
        "| `family` | name | parameters (besides `modes`) | guarantee | solver | source |\n\
         | --- | --- | --- | --- | --- | --- |\n",
    );
    for row in FAMILIES {
        let params: Vec<String> = row.params.iter().map(describe).collect();
        let params = if params.is_empty() {
            "—".to_string()
        } else {
            params.join("; ")
        };
        let solver = match row.solver {
            Solver::Never => "no",
            Solver::Always => "yes",
            Solver::WhenBounded => "with bounds",
        };
        out += &format!(
            "| `{}` | {} | {params} | {} | {solver} | {} |\n",
            row.name, row.title, row.guarantee, row.source
        );
    }
    out
}

/// The README's list of families, from `FAMILIES`.
fn list() -> String {
    let names: Vec<String> = FAMILIES
        .iter()
        .map(|f| format!("`{}` {}", f.name, f.title))
        .collect();
    names.join("; ") + ".\n"
}

/// `text` with what lies between `<!-- generated: name -->` and `<!-- /generated: name -->`
/// replaced by `body`, or `None` without those markers.
fn with_generated(text: &str, name: &str, body: &str) -> Option<String> {
    let begin = format!("<!-- generated: {name} (tests/families.rs, from FAMILIES) -->\n");
    let end = format!("<!-- /generated: {name} -->");
    let a = text.find(&begin)? + begin.len();
    let b = a + text[a..].find(&end)?;
    Some(format!("{}{body}{}", &text[..a], &text[b..]))
}

/// The family tables of the docs are the ones `FAMILIES` makes. With `UPDATE_DOCS=1` they are
/// rewritten instead (then check the diff).
#[test]
fn docs_family_tables_agree_with_families() {
    let root = env!("CARGO_MANIFEST_DIR");
    for (file, name, body) in [
        ("docs/families.md", "family table", table()),
        ("README.md", "family list", list()),
    ] {
        let path = format!("{root}/{file}");
        let text = std::fs::read_to_string(&path).unwrap();
        let want = with_generated(&text, name, &body)
            .unwrap_or_else(|| panic!("{file} has no generated {name} (its markers are gone)"));
        if std::env::var_os("UPDATE_DOCS").is_some() {
            std::fs::write(&path, &want).unwrap();
        } else {
            assert!(
                want == text,
                "{file}: the {name} differs from FAMILIES; run UPDATE_DOCS=1 cargo test --test \
                 families and check the diff"
            );
        }
    }
}

/// Whether `spec` parses as a shaper spec.
fn parses(spec: &Map<String, Value>) -> bool {
    serde_json::from_value::<ShaperSpec>(Value::Object(spec.clone())).is_ok()
}

/// A family's TypeScript interface name: `zvdn` → `ZvdnSpec`.
fn ts_name(family: &str) -> String {
    let mut chars = family.chars();
    let first = chars.next().map(|c| c.to_ascii_uppercase());
    first.into_iter().chain(chars).collect::<String>() + "Spec"
}

/// A parameter's TypeScript type. Its shape comes from the table (`kind`, `options`); whether a
/// list has a fixed length, and whether `null` is read (as "not given"), is asked of the spec
/// parser itself, so the declaration says what the library accepts.
fn ts_type(row: &FamilyInfo, p: &ParamInfo) -> String {
    let with = |v: Value| {
        let mut spec = defaults(row);
        spec.insert(p.name.into(), v);
        parses(&spec)
    };
    let base = match p.kind {
        ParamKind::Number | ParamKind::Integer | ParamKind::Percent => "number".to_string(),
        ParamKind::Numbers if with(json!([1.0, 2.0])) && !with(json!([1.0, 2.0, 3.0])) => {
            "[number, number]".into()
        }
        ParamKind::Numbers => "number[]".into(),
        ParamKind::Select => {
            let options: Vec<String> = p.options.iter().map(|o| format!("\"{o}\"")).collect();
            options.join(" | ")
        }
        ParamKind::Boolean => "boolean".into(),
        ParamKind::Pairs => "Impulse[]".into(),
        ParamKind::Points => "[number, number][]".into(),
    };
    if with(Value::Null) {
        format!("{base} | null")
    } else {
        base
    }
}

/// A parameter's doc comment: its label, kind, limits and default as the table gives them.
fn ts_doc(p: &ParamInfo) -> String {
    let mut doc = format!("{}.", p.label);
    let kind = match p.kind {
        ParamKind::Integer => " An integer.",
        ParamKind::Percent => " A fraction (0.05 = 5 %).",
        _ => "",
    };
    doc += kind;
    match (p.min, p.max) {
        (Some(a), Some(b)) => doc += &format!(" {} … {}.", num(a), num(b)),
        (None, Some(b)) => doc += &format!(" At most {}.", num(b)),
        (Some(a), None) => doc += &format!(" At least {}.", num(a)),
        (None, None) => {}
    }
    match p.default {
        Some(ParamDefault::Number(d)) => doc += &format!(" Editor default {}.", num(d)),
        Some(ParamDefault::Text(t)) => doc += &format!(" Editor default `\"{t}\"`."),
        Some(ParamDefault::Flag(b)) => doc += &format!(" Editor default `{b}`."),
        Some(ParamDefault::Impulses(_)) | None => {}
    }
    doc.replace("*/", "* /")
}

/// The TypeScript declarations of the family specs (`crate/js/families.d.ts`, appended to the
/// generated `.d.ts` of every module): one interface per row, discriminated by `family`, with
/// each parameter typed from the table and required exactly when the spec parser refuses a
/// spec without it.
fn typescript() -> String {
    let mut out = String::from(
        "// Generated from FAMILIES (crate/design/family.rs) by tests/families.rs: do not edit.\n\
         // `UPDATE_DOCS=1 cargo test --test families` rewrites it. docs/js-api.md, *TypeScript*.\n",
    );
    for row in FAMILIES {
        out += &format!(
            "\n/** `{}`: {}. Guarantees: {}. Source: {}. */\nexport interface {} {{\n  family: \"{}\";\n",
            row.name,
            row.title,
            row.guarantee.replace("*/", "* /"),
            row.source,
            ts_name(row.name),
            row.name
        );
        for p in row.params {
            let mut without = defaults(row);
            without.remove(p.name);
            let optional = if parses(&without) { "?" } else { "" };
            out += &format!(
                "  /** {} */\n  {}{optional}: {};\n",
                ts_doc(p),
                p.name,
                ts_type(row, p)
            );
        }
        out += "}\n";
    }
    let names: Vec<String> = FAMILIES.iter().map(|f| ts_name(f.name)).collect();
    out += &format!(
        "\n/** A shaper family and its parameters, discriminated by `family` (docs/families.md). */\n\
         export type ShaperSpec =\n  | {};\n",
        names.join("\n  | ")
    );
    out += "\n/** Every family's name. */\nexport type FamilyName = ShaperSpec[\"family\"];\n";
    out += "\n/** The families that need the optimisation solver (`solver` not `\"never\"`). */\n";
    let solved: Vec<String> = FAMILIES
        .iter()
        .filter(|f| f.solver != Solver::Never)
        .map(|f| format!("\"{}\"", f.name))
        .collect();
    out += &format!("export type SolvedFamilyName = {};\n", solved.join(" | "));
    out
}

/// `crate/js/families.d.ts` is the one [`typescript`] makes from `FAMILIES` (with
/// `UPDATE_DOCS=1`, rewritten instead).
#[test]
fn typescript_family_specs_agree_with_families() {
    let path = format!("{}/crate/js/families.d.ts", env!("CARGO_MANIFEST_DIR"));
    let want = typescript();
    if std::env::var_os("UPDATE_DOCS").is_some() {
        std::fs::write(&path, &want).unwrap();
    } else {
        let text = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            want == text,
            "crate/js/families.d.ts differs from FAMILIES; run UPDATE_DOCS=1 cargo test --test \
             families and check the diff"
        );
    }
}
