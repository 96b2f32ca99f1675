#!/usr/bin/env bash
# What the JS reader's two forks save on a shipped module (issue 21 item 4; docs/page-performance.md,
# *The forks, re-measured*): the module built three times, as scripts/build.sh builds it (the
# pinned nightly with std, LTO, wasm-bindgen, npm's wasm-opt), from three copies of the sources:
#
#   forks     the sources as they are: crate/js/jsde.rs (serde-wasm-bindgen's Deserializer
#             with serde_path_to_error's path folded in) and crate/tagged.rs (tagged specs
#             read tag first from the JS object);
#   tagged    crate/tagged.rs's tag-first read switched off (`is_js` false, the feature
#             any-deserializer on): the tagged specs and flattened structs read by serde's own
#             derive, through its buffered `Content` parser, from the same jsde reader;
#   upstream  that, and jsde's reader replaced by upstream: serde_path_to_error::deserialize
#             over serde_wasm_bindgen::Deserializer (what jsde.rs folds into one type).
#
# forks − tagged is what crate/tagged.rs saves, tagged − upstream what crate/js/jsde.rs saves.
# Prints each module's wasm size and gzip -9 size. Takes a few minutes per build.
#
# Usage: bash scripts/measure-forks.sh [MODULE...]   MODULE: playground (default), designer,
#        recording, library
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
[ -f "$HOME/.cargo/env" ] && . "$HOME/.cargo/env"
export PATH="$HOME/.cargo/bin:$PATH"
nightly=$(bash scripts/nightly.sh)
modules=("$@")
[ ${#modules[@]} -gt 0 ] || modules=(playground)
work=$(mktemp -d /tmp/measure-forks.XXXXXX)
trap 'rm -rf "$work"' EXIT

# copy NAME: the sources (not target/, node_modules/, pkg/) in $work/NAME
copy() {
  mkdir -p "$work/$1"
  tar -C "$root" --exclude=./target --exclude=./node_modules --exclude=./pkg --exclude=./.git -cf - . \
    | tar -C "$work/$1" -xf -
}

copy forks

copy tagged
# is_js answers false: every tagged spec goes through serde's derived (buffered) parser.
perl -0pi -e 's/\n        JS_READER\n            \.get\(\)/\n        false && JS_READER\n            .get()/' \
  "$work/tagged/crate/tagged.rs"
grep -q 'false && JS_READER' "$work/tagged/crate/tagged.rs" || { echo "tagged: edit failed" >&2; exit 1; }

copy upstream
cp "$work/tagged/crate/tagged.rs" "$work/upstream/crate/tagged.rs"
# jsde's entry point hands the value to upstream's pair instead of its own reader.
perl -0pi -e 's/(fn fork<T: DeserializeOwned>\(value: JsValue\) -> std::result::Result<T, \(String, Error\)> \{\n)/$1    if true {\n        return serde_path_to_error::deserialize(serde_wasm_bindgen::Deserializer::from(value))\n            .map_err(|e| (e.path().to_string(), e.into_inner()));\n    }\n/' \
  "$work/upstream/crate/js/jsde.rs"
grep -q 'serde_path_to_error::deserialize(serde_wasm_bindgen' "$work/upstream/crate/js/jsde.rs" \
  || { echo "upstream: edit failed" >&2; exit 1; }
perl -0pi -e 's/(\[target\.\x27cfg\(target_arch = "wasm32"\)\x27\.dependencies\]\n)/$1serde_path_to_error = "0.1.20"\n/' \
  "$work/upstream/Cargo.toml"
grep -q '^serde_path_to_error' "$work/upstream/Cargo.toml" || { echo "upstream: Cargo.toml edit failed" >&2; exit 1; }

# features and opt-levels of scripts/build.sh's modules
spec() {
  case $1 in
    playground) echo "js-playground 2 2" ;;
    designer) echo "js-designer,solver z z" ;;
    recording) echo "js-recording 2 2" ;;
    library) echo "js-api z z" ;;
    *) echo "unknown module $1" >&2; exit 1 ;;
  esac
}

gz() { gzip -9 -c "$1" | wc -c; }
for module in "${modules[@]}"; do
  read -r features opt level < <(spec "$module")
  for variant in forks tagged upstream; do
    f=$features
    [ "$variant" = forks ] || f="$features,any-deserializer"
    CARGO_PROFILE_RELEASE_OPT_LEVEL=$opt RUSTFLAGS="-Z location-detail=none" \
      nice -n 10 cargo "+$nightly" build --quiet --release --lib --target wasm32-unknown-unknown \
      --manifest-path "$work/$variant/Cargo.toml" --no-default-features --features "$f" \
      --target-dir "$root/target/shipped" -Z build-std=std,panic_abort
    out="$work/out-$module-$variant"
    wasm-bindgen --target web --out-dir "$out" --out-name m --remove-producers-section \
      "$root/target/shipped/wasm32-unknown-unknown/release/input_shaping.wasm"
    "$root/node_modules/.bin/wasm-opt" "-O$level" --converge --one-caller-inline-max-function-size 0 \
      "$out/m_bg.wasm" -o "$out/m_bg.wasm"
    printf '%s %s: %d bytes, %d gzip\n' "$module" "$variant" "$(wc -c < "$out/m_bg.wasm")" "$(gz "$out/m_bg.wasm")"
  done
done
