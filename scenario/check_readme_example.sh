#!/usr/bin/env bash
# Checks the README's "Test your own ground segmenter" example the way a user would run it: the
# first ```rust block of that section becomes tests/ground_scenarios.rs of a fresh crate outside the
# workspace, depending on groundtruth-scenario by path plus proptest, and `cargo test` must pass.
#
# Usage: scenario/check_readme_example.sh [README.md]
# Environment: CARGO_TARGET_DIR (default: <workspace>/target-example, removed afterwards unless
# KEEP_TARGET=1), OFFLINE=1 to pass --offline to cargo.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
readme="${1:-$root/README.md}"
section="## Test your own ground segmenter"

grep -qF "$section" "$readme" || { echo "error: no section \"$section\" in $readme" >&2; exit 1; }

work="$(mktemp -d)"
target="${CARGO_TARGET_DIR:-$root/target-example}"
cleanup() {
    rm -rf "$work"
    if [ "${KEEP_TARGET:-0}" != 1 ] && [ -z "${CARGO_TARGET_DIR:-}" ]; then rm -rf "$target"; fi
}
trap cleanup EXIT

# The first ```rust block after the section heading (up to the next "## " heading).
awk -v section="$section" '
    index($0, section) == 1 { in_section = 1; next }
    in_section && /^## / { exit }
    in_section && !in_block && /^```rust/ { in_block = 1; next }
    in_block && /^```/ { exit }
    in_block { print }
' "$readme" > "$work/example.rs"
[ -s "$work/example.rs" ] || { echo "error: no \`\`\`rust block in section \"$section\"" >&2; exit 1; }

mkdir -p "$work/user-crate/src" "$work/user-crate/tests"
cat > "$work/user-crate/Cargo.toml" <<TOML
[package]
name = "user-crate"
version = "0.1.0"
edition = "2024"
publish = false

[workspace]

[dev-dependencies]
groundtruth-scenario = { path = "$root/scenario" }
proptest = "1.12"

[profile.dev.package."*"]
opt-level = 2
TOML
echo "//! A user's crate." > "$work/user-crate/src/lib.rs"
cp "$work/example.rs" "$work/user-crate/tests/ground_scenarios.rs"
# The workspace's lock file pins the same versions the workspace is tested with.
cp "$root/Cargo.lock" "$work/user-crate/Cargo.lock"

offline=()
[ "${OFFLINE:-0}" = 1 ] && offline=(--offline)
cd "$work/user-crate"
CARGO_TARGET_DIR="$target" cargo test "${offline[@]}" --test ground_scenarios
echo "README example: OK ($(grep -c '#\[test\]' tests/ground_scenarios.rs) tests)"
