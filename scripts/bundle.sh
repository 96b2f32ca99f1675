#!/usr/bin/env bash
# Bundles and minifies the page's scripts (esbuild) next to its wasm modules, into pkg/page/:
#   main.js            web/main.js with the modules it imports (page, state, params, dom,
#                      editors, results, designs, measure) and the
#                      playground module's glue (index.html loads it);
#   measure_view.js    web/measure_view.js (the measured-data view) with the recording module's
#                      glue (it draws the Klipper-style charts); imported by main.js when the
#                      measured-data path is first opened;
#   corner_view.js     web/corner_view.js (the printed-corner view) with the corner module's
#                      glue; imported by main.js when that view is first opened;
#   measure_worker.js  web/measure_worker.js with the recording module's glue and the
#                      playground module's (it ranks shapers with the page's module, which
#                      main.js hands it compiled); started when the first recording is opened;
#   design_worker.js   web/design_worker.js with the designer module's glue; started when the
#                      first solved family (si, direct, bounded sampled) is shown;
#   realise_view.js    web/realise_view.js (what a controller runs, issue 23) with the recording
#                      module's glue; imported by main.js when a shaper is first realised;
#   command_view.js    web/command_view.js (a profile's or a list's fields and the profile's
#                      spectrum with its zeros, issue 23 item 2) with the recording module's
#                      glue; imported by main.js when such a command is first shown.
# Each glue finds its .wasm next to the bundle (new URL(…, import.meta.url)), so the bundles
# live in pkg/page/ with them. Source maps point back to web/. Run by scripts/build.sh after
# the wasm modules; alone (`npm run build:web`) after editing web/.
set -euo pipefail
cd "$(dirname "$0")/.."
common=(--bundle --minify --format=esm --target=es2020 --sourcemap --outdir=pkg/page --log-level=warning)
node_modules/.bin/esbuild web/main.js web/measure_view.js web/corner_view.js web/measure_worker.js web/design_worker.js web/realise_view.js web/command_view.js web/plant_view.js "${common[@]}"
