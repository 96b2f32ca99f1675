#!/usr/bin/env bash
# npm run bench: the criterion benchmarks (benches/analysis.rs), then the numpy baseline on the
# same inputs (benches/map_numpy.py), which checks agreement to 1e-9 and prints the comparison.
# Extra arguments go to criterion, e.g. `npm run bench -- sensitivity_map`.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -f "$HOME/.cargo/env" ] && . "$HOME/.cargo/env"
python3 -c 'import numpy' 2>/dev/null || { echo "numpy is missing: pip install numpy"; exit 1; }
cargo bench --bench analysis -- "$@"
echo
python3 benches/map_numpy.py
