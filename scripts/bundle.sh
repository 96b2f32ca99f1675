#!/usr/bin/env bash
# Bundles and minifies the page's scripts (esbuild) next to its wasm modules, into pkg/page/:
#   main.js            web/main.js with web/state.js, params.js, measure.js and the
#                      playground module's glue (index.html loads it); the glue of the
#                      module with the solver is a chunk of its own, imported when needed;
#   measure_worker.js  web/measure_worker.js with the recording module's glue and the
#                      playground module's (it ranks shapers with the page's module, which
#                      main.js hands it compiled); started when the first recording is opened.
# Each glue finds its .wasm next to the bundle (new URL(…, import.meta.url)), so the bundles
# live in pkg/page/ with them. Source maps point back to web/. Run by scripts/build.sh after
# the wasm modules; alone (`npm run build:web`) after editing web/.
set -euo pipefail
cd "$(dirname "$0")/.."
common=(--bundle --minify --format=esm --target=es2020 --sourcemap --outdir=pkg/page --log-level=warning)
# main.js imports the solver module's glue dynamically: --splitting makes it a file of its own,
# pkg/page/playground_solver-<hash>.js, fetched with that module only.
node_modules/.bin/esbuild web/main.js "${common[@]}" --splitting --chunk-names='[name]-[hash]'
node_modules/.bin/esbuild web/measure_worker.js "${common[@]}"
