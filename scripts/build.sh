#!/usr/bin/env bash
# Builds the release wasm and its JS bindings into pkg/ (wasm-bindgen --target web), then
# shrinks the wasm with npm's binaryen (Debian's wasm-opt 108 breaks it; see README).
#
# The wasm is built by the pinned nightly of scripts/nightly.sh, which compiles the standard
# library with the crate (-Z build-std) at the release profile's opt-level "z" and LTO, with
# panic locations left out (-Z location-detail=none; panic messages stay): same code, same
# results, ~24 KB less gzip (README, *Shipped size*). std's `optimize_for_size` feature would
# save 7 KB more, but it formats floats (every tick label) with Dragon4 only, not Grisu. Without
# that toolchain (setup could not install it), or with STABLE=1, it is built by stable Rust.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
[ -f "$HOME/.cargo/env" ] && . "$HOME/.cargo/env"
export PATH="$HOME/.cargo/bin:$PATH"

nightly=$(bash scripts/nightly.sh)
target=wasm32-unknown-unknown
dir=
if [ "${STABLE:-0}" != 1 ] && sysroot=$(rustup run "$nightly" rustc --print sysroot 2>/dev/null) \
  && [ -d "$sysroot/lib/rustlib/src/rust/library" ]; then
  # Its own target directory: other RUSTFLAGS and std would rebuild the stable builds' cache.
  if RUSTFLAGS="-Z location-detail=none" cargo "+$nightly" build --release --lib --target "$target" --no-default-features \
    --target-dir target/shipped -Z build-std=std,panic_abort; then
    dir=target/shipped
    how="$nightly, std built for size"
  else
    echo "[build] the $nightly build failed: building with stable Rust instead (larger wasm)" >&2
  fi
fi
if [ -z "$dir" ]; then
  dir=target
  cargo build --release --lib --target "$target" --no-default-features
  how="stable Rust, prebuilt std: larger"
fi
rm -rf pkg
wasm-bindgen --target web --out-dir pkg --out-name input_shaping --remove-producers-section \
  "$dir/$target/release/input_shaping.wasm"
wasm=pkg/input_shaping_bg.wasm
if [ -x node_modules/.bin/wasm-opt ]; then
  node_modules/.bin/wasm-opt -Oz --converge --one-caller-inline-max-function-size 0 "$wasm" -o "$wasm.opt" && mv "$wasm.opt" "$wasm"
fi
raw=$(wc -c < "$wasm")
gz=$(gzip -9 -c "$wasm" | wc -c)
jsgz=$(gzip -9 -c pkg/input_shaping.js | wc -c)
printf '[build] pkg/input_shaping_bg.wasm (%s): %d bytes (%d gzip); glue JS %d bytes gzip\n' "$how" "$raw" "$gz" "$jsgz"
