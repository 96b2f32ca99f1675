#!/usr/bin/env bash
# Builds the release wasm modules and their JS bindings into pkg/ (wasm-bindgen --target web),
# then shrinks each wasm with npm's binaryen (Debian's wasm-opt 108 breaks it; see docs/building.md).
#
# Each wasm is built by the pinned nightly of scripts/nightly.sh, which compiles the standard
# library with the crate (-Z build-std) at the module's opt-level (2 for every module since
# 2026-12-07; build_module's default is "z"; below) and LTO, with panic locations left out (-Z location-detail=none; panic
# messages stay, but for the main thread's module: below): same code, same results, ~24 KB less gzip (docs/page-performance.md, *Shipped size*). std's
# `optimize_for_size` feature would save 7 KB more, but it formats floats (every tick label)
# with Dragon4 only, not Grisu. Without that toolchain (setup could not install it), or with
# STABLE=1, it is built by stable Rust.
#
# Usage: bash scripts/build.sh [--library | --check]
#   --library  only the whole API's module, pkg/input_shaping* (for `npm run pack`);
#   --check    builds nothing: says which modules are up to date (exit 1 if any is not).
set -euo pipefail
what=${1:-all}
cd "$(dirname "$0")/.."
bash scripts/setup.sh
[ -f "$HOME/.cargo/env" ] && . "$HOME/.cargo/env"
export PATH="$HOME/.cargo/bin:$PATH"

nightly=$(bash scripts/nightly.sh)
target=wasm32-unknown-unknown
use_nightly=0
if [ "${STABLE:-0}" != 1 ] && sysroot=$(rustup run "$nightly" rustc --print sysroot 2>/dev/null) \
  && [ -d "$sysroot/lib/rustlib/src/rust/library" ]; then
  use_nightly=1
fi

# Five modules from one crate, each with the exports of some Cargo features (Cargo.toml):
#   pkg/input_shaping.js          the whole JavaScript API (docs/js-api.md), for programs of your own;
#   pkg/page/playground.js        what the page calls (js-playground) without the optimisation
#                                 solver: the solved families (si, direct, bounded sampled)
#                                 answer "unavailable" (the measured-data worker ranks shapers
#                                 with it too, handed over compiled);
#   pkg/page/designer.js          `design` and the solver (js-designer + solver), for the page's
#                                 design worker, fetched when a solved family is first shown;
#   pkg/page/recording.js         what its measured-data worker calls (js-recording), fetched
#                                 only when a recording is opened;
#   pkg/page/corner.js            the printed-corner view's `renderCorner` (js-corner), fetched
#                                 when that view is first opened (opt-level 2: it runs per edit).
# The linker keeps only the code an export reaches, so the page's modules are smaller than the
# whole API's (docs/page-performance.md, *Shipped size*). The same sources, the same results.
#
# The main thread's module (playground) runs every update of the page, so it is optimised for
# speed within the size budget: opt-level 2 and `wasm-opt -O2`, not "z" and `-Oz`. In
# alternated runs of the page benchmark a 4-shaper mode edit was faster at "s" than at "z"
# (~17 %, 8 paired runs) and faster again at 2 (5 paired runs), for 17 + 40 KB more gzip:
# the first load is ~5 KB under its 300 KB budget (docs/page-performance.md, *Optimisation
# level*; `shrink … s` and `build_module … s` below give back the 40 KB). Rust's optimisation
# levels do not change floating-point results. The measured-data worker's module (recording) is
# built for speed too (opt-level 2, `wasm-opt -O2`): it is fetched only when a recording is
# opened, outside the first-load budget, and issue 25's optimised shaper must stay under 500 ms
# per axis in that worker. Measured 2026-12-04 (docs/measured-data.md, *Optimised shapers*,
# *Speed*): node CPU time per axis about halved against "z" / `-Oz` (resonances_y_three.csv
# 159 → 79 ms), opt-level 3 / `-O3` no faster, for 66.7 KB more gzip (255.0 → 321.7 KB).
# The whole API's module (pkg/input_shaping) and the design worker's (designer) are built for
# speed as well, opt-level 2 and `wasm-opt -O2`: neither is part of the first load, and the
# solved families' designs run in them (issue 24 item 1: `si` over three modes in Node, with
# `vibration::magnitude`, I 0.3 219 -> 95 ms, I 0.7 1328 -> 736 ms, the same designs;
# opt-level 3 / `-O3` and +simd128 no faster), for 165 KB more gzip in the library's wasm
# (521.5 -> 686.5 KB) and 41 KB in the designer's (165.7 -> 206.7 KB) (docs/benchmarks.md,
# *Solved families*, 2026-12-07).
# The page's main-thread module builds its dependencies that no frame spends time in (std,
# serde, serde-wasm-bindgen, nalgebra, ...) at "s" while the crate and the drawing path
# (plotters, its canvas backend, web-sys, js-sys, wasm-bindgen) stay at 2 (DEPS_OPT below):
# 4.0 KB less gzip (276 286 -> 272 280 B), the page benchmark's updates no slower in
# alternated runs; every dependency at "s" saved the same but its 4-shaper mode edit was
# ~0.2 ms slower at p50, and "z" saved no more (docs/page-performance.md, *Shipped size*, 2026-12-05).
# The main thread's module (playground) is also built with `-C panic=immediate-abort`: a panic
# (a bug: nothing reachable from the API panics) traps as `unreachable` with no message, and the
# panic machinery with every panic message is left out, 12.1 KB gzip (276 068 -> 263 959 B,
# 2026-12-06, docs/page-performance.md, *Shipped size*): the first load's budget. The other
# modules keep their messages; a panic seen on the page is reproduced with the same input
# through pkg/input_shaping.js or natively, which report it.
# build_module FEATURES OUT_DIR OUT_NAME [OPT_LEVEL] [DEPS_OPT_LEVEL] [PANIC]
build_module() {
  local features=$1 out=$2 name=$3 opt=${4:-z} deps=${5:-} panic=${6:-} dir=""
  local flags="-Z location-detail=none"
  [ -n "$panic" ] && flags="$flags -Z unstable-options -C panic=$panic"
  local -x CARGO_PROFILE_RELEASE_OPT_LEVEL=$opt # this module's cargo builds only
  local config=()
  if [ -n "$deps" ]; then
    config=(--config "profile.release.package.\"*\".opt-level=\"$deps\"")
    # The drawing path (every chart's every segment, each frame) stays at the crate's level.
    for hot in plotters plotters-backend plotters-canvas web-sys js-sys wasm-bindgen; do
      config+=(--config "profile.release.package.$hot.opt-level=$opt")
    done
  fi
  if [ "$use_nightly" = 1 ]; then
    # Its own target directory: other RUSTFLAGS and std would rebuild the stable builds' cache
    # (and another panic strategy, the other modules' one).
    if RUSTFLAGS="$flags" cargo "+$nightly" build "${config[@]+"${config[@]}"}" --release --lib --target "$target" \
      --no-default-features --features "$features" --target-dir "target/shipped${panic:+-$panic}" -Z build-std=std,panic_abort; then
      dir=target/shipped${panic:+-$panic}
      how="$nightly, std built with it at opt-level $opt${panic:+, panic=$panic}"
    else
      echo "[build] the $nightly build failed: building with stable Rust instead (larger wasm)" >&2
      use_nightly=0
    fi
  fi
  if [ -z "$dir" ]; then
    dir=target
    cargo build "${config[@]+"${config[@]}"}" --release --lib --target "$target" --no-default-features --features "$features"
    how="stable Rust, prebuilt std: larger"
  fi
  rm -rf "$out/$name.js" "$out/${name}_bg.wasm"
  wasm-bindgen --target web --out-dir "$out" --out-name "$name" --remove-producers-section \
    "$dir/$target/release/input_shaping.wasm"
  # wasm-bindgen types the raw wasm exports' externref arguments `any` (`InitOutput`,
  # `*_bg.wasm.d.ts`). They take any JS value: `unknown` says so without switching type
  # checking off, so no `any` is left in a public signature (docs/js-api.md, *TypeScript*).
  sed -i -E '/^ *(readonly|export const) [A-Za-z0-9_$]+: \(/ s/\bany\b/unknown/g' \
    "$out/$name.d.ts" "$out/${name}_bg.wasm.d.ts"
  # A freed object's methods answer the documented Error, not "null pointer passed to rust".
  node scripts/guard-freed.mjs "$out/$name.js"
  echo "[build] $out/$name.js ($features): built by $how"
}

# shrink WASM [LEVEL]   (wasm-opt's -Oz, or -O2 for the speed-tuned module)
shrink() {
  local wasm=$1 level=${2:-z}
  if [ -x node_modules/.bin/wasm-opt ]; then
    node_modules/.bin/wasm-opt "-O$level" --converge --one-caller-inline-max-function-size 0 "$wasm" -o "$wasm.opt" \
      && mv "$wasm.opt" "$wasm"
  fi
}

# Only what its inputs changed is rebuilt (issue 21, item 6): a second `npm start` with nothing
# changed takes seconds, not minutes. Each module's stamp, pkg/[page/].NAME.stamp, holds the hash
# of everything its build reads (scripts/stamp.sh: crate/, Cargo.toml, Cargo.lock,
# .cargo/config.toml, these scripts, the toolchain's `rustc -vV`, the wasm-bindgen and binaryen
# versions, its features, opt-level and wasm-opt level, RUSTFLAGS) and the SHA-256 of its four
# outputs. A module whose inputs hash the same and whose outputs are intact is kept; any other
# is rebuilt (cargo, wasm-bindgen, wasm-opt), and its stamp is written only after wasm-opt has
# finished, so an interrupted or failed build leaves no stamp and is redone. Contents are hashed,
# not times: `touch` alone rebuilds nothing, an edit rebuilds every module. FORCE=1 rebuilds all.
if [ "$use_nightly" = 1 ]; then rustc_version=$(rustup run "$nightly" rustc -vV); else rustc_version=$(rustc -vV); fi
bindgen_version=$(wasm-bindgen --version)
binaryen_version=none
if [ -x node_modules/.bin/wasm-opt ]; then
  binaryen_version=$(node -p 'require("./node_modules/binaryen/package.json").version')
fi
stamps=1 # 0 once a module fell back to stable Rust: nothing is stamped, the next build retries

# module_key FEATURES OPT_LEVEL WASM_OPT_LEVEL [DEPS_OPT_LEVEL] [PANIC]
module_key() {
  bash scripts/stamp.sh --files crate Cargo.toml Cargo.lock .cargo/config.toml rust-toolchain \
    rust-toolchain.toml scripts/build.sh scripts/stamp.sh scripts/nightly.sh scripts/guard-freed.mjs -- \
    "features=$1" "opt-level=$2" "wasm-opt=$3" "deps-opt-level=${4:-}" "panic=${5:-}" "nightly=$use_nightly" "$rustc_version" \
    "$bindgen_version" "binaryen=$binaryen_version"
}
# outputs OUT_DIR NAME: what wasm-bindgen writes (and wasm-opt rewrites)
outputs() { printf '%s\n' "$1/$2.js" "$1/$2.d.ts" "$1/${2}_bg.wasm" "$1/${2}_bg.wasm.d.ts"; }
# up_to_date KEY STAMP: the stamp's first line is KEY and its checksums match the outputs
up_to_date() {
  [ "${FORCE:-0}" != 1 ] && [ -f "$2" ] && [ "$(head -n 1 "$2")" = "$1" ] \
    && tail -n +2 "$2" | sha256sum --check --status 2>/dev/null
}
# write_stamp KEY STAMP OUT_DIR NAME
write_stamp() {
  { echo "$1"; outputs "$3" "$4" | xargs sha256sum; } > "$2.tmp" && mv "$2.tmp" "$2"
}

# module FEATURES OUT_DIR NAME OPT_LEVEL WASM_OPT_LEVEL [DEPS_OPT_LEVEL] [PANIC]: builds it unless up
# to date; its wasm-opt runs in the background while the next one compiles.
module() {
  local features=$1 out=$2 name=$3 opt=$4 level=$5 deps=${6:-} panic=${7:-} key stamp
  stamp="$out/.$name.stamp"
  key=$(module_key "$features" "$opt" "$level" "$deps" "$panic")
  if up_to_date "$key" "$stamp"; then
    echo "[build] $out/$name.js ($features): up to date, kept (FORCE=1 rebuilds)"
    return
  fi
  if [ "$what" = --check ]; then
    echo "[build] $out/$name.js ($features): to be rebuilt"
    stale=$((stale + 1))
    return
  fi
  rm -f "$stamp"
  local before=$use_nightly
  build_module "$features" "$out" "$name" "$opt" "$deps" "$panic"
  [ "$use_nightly" = "$before" ] || stamps=0
  local write=$stamps
  { shrink "$out/${name}_bg.wasm" "$level" && if [ "$write" = 1 ]; then write_stamp "$key" "$stamp" "$out" "$name"; fi; } &
  pids+=($!)
}

mkdir -p pkg/page
pids=()
stale=0
module js-api pkg input_shaping 2 2
if [ "$what" != --library ]; then
  module js-playground pkg/page playground 2 2 s immediate-abort
  module js-designer,solver pkg/page designer 2 2
  module js-recording pkg/page recording 2 2
  module js-corner pkg/page corner 2 2
fi
for pid in "${pids[@]+"${pids[@]}"}"; do wait "$pid"; done
if [ "$what" = --check ]; then exit $((stale > 0)); fi
if [ "$what" = --library ]; then modules=(pkg/input_shaping); bundles=(); else
  bash scripts/bundle.sh
  modules=(pkg/input_shaping pkg/page/playground pkg/page/designer pkg/page/recording pkg/page/corner)
  bundles=(pkg/page/main.js pkg/page/measure_worker.js pkg/page/design_worker.js pkg/page/corner_view.js)
fi

gz() { gzip -9 -c "$1" | wc -c; }
for m in "${modules[@]}"; do
  printf '[build] %s_bg.wasm: %d bytes (%d gzip); glue JS %d bytes gzip\n' \
    "$m" "$(wc -c < "${m}_bg.wasm")" "$(gz "${m}_bg.wasm")" "$(gz "$m.js")"
done
for b in "${bundles[@]+"${bundles[@]}"}"; do
  printf '[build] %s (esbuild): %d bytes gzip\n' "$b" "$(gz "$b")"
done
