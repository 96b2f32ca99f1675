#!/usr/bin/env bash
# Prints one SHA-256 over everything a build step reads, so scripts/build.sh and
# scripts/bundle.sh can skip a step whose inputs and outputs are unchanged (issue 21, item 6).
#
# Usage: bash scripts/stamp.sh [--files PATH...] [--] [WORD...]
#   PATHs: files or directories (every file under a directory, found anew each time, so an
#   added or deleted file changes the stamp too); a missing path counts as "missing".
#   WORDs: anything else the step depends on (features, opt-level, tool versions), in order.
# The stamp hashes contents and paths, never times: `touch` alone does not rebuild, an edit does.
# RUSTFLAGS and CARGO_ENCODED_RUSTFLAGS are always part of it (cargo reads them).
set -euo pipefail
cd "$(dirname "$0")/.."

paths=()
words=()
if [ "${1:-}" = --files ]; then
  shift
  while [ $# -gt 0 ] && [ "$1" != -- ]; do paths+=("$1"); shift; done
  [ "${1:-}" = -- ] && shift
fi
words=("$@")

{
  printf 'word %s\n' "${words[@]+"${words[@]}"}" "RUSTFLAGS=${RUSTFLAGS:-}" \
    "CARGO_ENCODED_RUSTFLAGS=${CARGO_ENCODED_RUSTFLAGS:-}"
  for p in "${paths[@]+"${paths[@]}"}"; do
    if [ -d "$p" ]; then
      find "$p" -type f -print0 | LC_ALL=C sort -z | xargs -0 -r sha256sum
    elif [ -f "$p" ]; then
      sha256sum "$p"
    else
      printf 'missing %s\n' "$p"
    fi
  done
} | sha256sum | cut -d' ' -f1
