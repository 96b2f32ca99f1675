#!/usr/bin/env bash
# Prints the nightly toolchain that builds the shipped wasm (scripts/build.sh). Pinned to one
# date so every machine builds the same module: rustc 1.101.0-nightly (92b5b8c87 2026-10-29).
# Moving it: change the date, run `npm run build`, compare the size it prints and run `npm test`.
echo nightly-2026-10-30
