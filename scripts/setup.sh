#!/usr/bin/env bash
# Installs what building and testing need, skipping whatever is already there:
#   the wasm32 target, the wasm-bindgen CLI at exactly the version in Cargo.lock, the pinned
#   nightly toolchain with rust-src (scripts/nightly.sh; for the shipped wasm), wasm-pack,
#   the npm packages, and (with --browser) Debian's chromium + chromium-driver.
# Usage: bash scripts/setup.sh [--browser]
set -euo pipefail
cd "$(dirname "$0")/.."

say() { printf '[setup] %s\n' "$*"; }

[ -f "$HOME/.cargo/env" ] && . "$HOME/.cargo/env"
export PATH="$HOME/.cargo/bin:$PATH"
if ! command -v cargo >/dev/null 2>&1; then
  say "cargo not found: install Rust with rustup (https://rustup.rs) and run again." >&2
  exit 1
fi

if ! rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown; then
  say "adding the wasm32-unknown-unknown target"
  rustup target add wasm32-unknown-unknown
fi

# The CLI must match the wasm-bindgen crate in Cargo.lock exactly.
if [ ! -f Cargo.lock ]; then cargo generate-lockfile; fi
want=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/version = |"/, ""); print; exit }' Cargo.lock)
have=$(wasm-bindgen --version 2>/dev/null | awk '{print $2}' || true)
if [ "$have" != "$want" ]; then
  say "installing wasm-bindgen-cli $want (have: ${have:-none}); takes a few minutes"
  # No --locked: the crates.io mirror lacks a crate its lock file pins.
  cargo install wasm-bindgen-cli --version "$want" --force
fi

# The shipped wasm is built by a pinned nightly that recompiles the standard library for size
# (scripts/build.sh; docs/page-performance.md, *Shipped size*). If it cannot be installed, the build falls back to
# the stable toolchain (same code, ~24 KB gzip larger), so a missing nightly never fails a run.
nightly=$(bash scripts/nightly.sh)
if ! rustup run "$nightly" rustc --print sysroot >/dev/null 2>&1 \
  || [ ! -d "$(rustup run "$nightly" rustc --print sysroot)/lib/rustlib/src/rust/library" ] \
  || ! rustup target list --installed --toolchain "$nightly" 2>/dev/null | grep -qx wasm32-unknown-unknown; then
  say "installing $nightly with rust-src (std built for size for the shipped wasm)"
  rustup toolchain install "$nightly" --profile minimal --component rust-src --target wasm32-unknown-unknown \
    || say "could not install $nightly: the page will be built with stable Rust (larger wasm)" >&2
fi

if ! command -v wasm-pack >/dev/null 2>&1; then
  say "installing wasm-pack; takes a few minutes"
  cargo install wasm-pack --locked || cargo install wasm-pack
fi

if [ ! -d node_modules ] || [ package-lock.json -nt node_modules/.package-lock.json ]; then
  say "installing npm packages (npm ci)"
  npm ci --no-audit --no-fund
fi

if [ "${1:-}" = "--browser" ]; then
  if [ ! -x /usr/bin/chromium ] || [ ! -x /usr/bin/chromedriver ]; then
    say "installing Debian chromium and chromium-driver"
    sudo_cmd=""
    [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
    $sudo_cmd apt-get update
    DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y chromium chromium-driver
  fi
fi
