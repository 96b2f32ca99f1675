#!/usr/bin/env bash
# Builds the release wasm and its JS bindings into pkg/ (wasm-pack build --target web), then
# shrinks the wasm with npm's binaryen (Debian's wasm-opt 108 breaks it; see README).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
[ -f "$HOME/.cargo/env" ] && . "$HOME/.cargo/env"
export PATH="$HOME/.cargo/bin:$PATH"

wasm-pack --log-level warn build --release --target web --out-dir pkg --out-name input_shaping
wasm=pkg/input_shaping_bg.wasm
if [ -x node_modules/.bin/wasm-opt ]; then
  node_modules/.bin/wasm-opt -Oz --converge --one-caller-inline-max-function-size 0 "$wasm" -o "$wasm.opt" && mv "$wasm.opt" "$wasm"
fi
raw=$(wc -c < "$wasm")
gz=$(gzip -9 -c "$wasm" | wc -c)
jsgz=$(gzip -9 -c pkg/input_shaping.js | wc -c)
printf '[build] pkg/input_shaping_bg.wasm: %d bytes (%d gzip); glue JS %d bytes gzip\n' "$raw" "$gz" "$jsgz"
