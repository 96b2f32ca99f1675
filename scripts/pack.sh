#!/usr/bin/env bash
# npm run pack: the JavaScript library as an npm package, input-shaping-<version>.tgz (issue 21,
# item 3), written to the repository root (or to DIR with --out DIR).
#
# The package is the whole API's module only — pkg/input_shaping.js, its .d.ts, its wasm — with
# npm/node.js (the exports map's `node` entry: loads the wasm with fs when imported), npm/README.md,
# npm/package.json (its exports map; the version is the crate's, from Cargo.toml) and the licences.
# The page's modules (pkg/page/) stay out. It is staged in target/npm-package/ and packed by
# `npm pack`, which reads the files list of npm/package.json. tests/package/ installs it into an
# empty project and runs an example in Node, in an esbuild bundle and in Chromium.
set -euo pipefail
cd "$(dirname "$0")/.."
out=.
if [ "${1:-}" = --out ]; then out=$2; fi

bash scripts/build.sh --library # only pkg/input_shaping*; quick when nothing changed

version=$(awk -F'"' '/^version = / { print $2; exit }' Cargo.toml)
stage=target/npm-package
rm -rf "$stage"
mkdir -p "$stage" "$out"
cp pkg/input_shaping.js pkg/input_shaping.d.ts pkg/input_shaping_bg.wasm pkg/input_shaping_bg.wasm.d.ts \
  npm/node.js npm/README.md LICENSE-MIT LICENSE-APACHE "$stage/"
node -e '
  const fs = require("fs");
  const p = JSON.parse(fs.readFileSync("npm/package.json", "utf8"));
  p.version = process.argv[1];
  fs.writeFileSync(process.argv[2], JSON.stringify(p, null, 2) + "\n");
' "$version" "$stage/package.json"
dest=$(cd "$out" && pwd)
(cd "$stage" && npm pack --quiet --pack-destination "$dest" >/dev/null)
tgz="$dest/input-shaping-$version.tgz"
echo "[pack] $tgz: $(wc -c < "$tgz") bytes ($(tar -tzf "$tgz" | wc -l) files)"
