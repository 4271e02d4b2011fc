#!/usr/bin/env bash
# Checks the README's "Test your own ground segmenter" example the way a user meets it: a fresh
# crate outside the workspace, beside a checkout named `groundtruth` (the README's path), whose
# Cargo.toml is the README's own ```toml snippet and whose tests/ground_scenarios.rs is the
# README's ```rust block, verbatim. Nothing of ours is copied in: no Cargo.lock, so cargo resolves
# every dependency from scratch (`cargo generate-lockfile`), as `cargo add` or a git dependency
# would. Then:
#   1. one glam in the user's dependency graph (`cargo tree -d`), naming the crates behind each
#      version when there are two;
#   2. `cargo test` passes.
#
# Usage: scenario/check_readme_example.sh [README.md]
# Environment: CARGO_TARGET_DIR (default: <workspace>/target-example, removed afterwards unless
# KEEP_TARGET=1; CI passes the workspace's target dir so that dependencies of equal versions are
# not built twice), OFFLINE=1 to pass --offline to cargo, WORKSPACE_PROFILE=1 to build with the
# workspace's per-package `[profile.dev.package]` opt-levels on top of the user's (`--config`; the
# user's Cargo.toml stays verbatim): proc macros and cold crates built alike, so the dependencies
# the workspace's test build compiled are reused instead of compiled again.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
readme="$(cd "$(dirname "${1:-$root/README.md}")" && pwd)/$(basename "${1:-$root/README.md}")"
section="## Test your own ground segmenter"

grep -qF "$section" "$readme" || { echo "error: no section \"$section\" in $readme" >&2; exit 1; }

work="$(mktemp -d)"
target="${CARGO_TARGET_DIR:-$root/target-example}"
cleanup() {
    rm -rf "$work"
    if [ "${KEEP_TARGET:-0}" != 1 ] && [ -z "${CARGO_TARGET_DIR:-}" ]; then rm -rf "$target"; fi
}
trap cleanup EXIT

# The first ```LANG block after the section heading (up to the next "## " heading).
block() {
    awk -v section="$section" -v lang="$1" '
        index($0, section) == 1 { in_section = 1; next }
        in_section && /^## / { exit }
        in_section && !in_block && $0 == "```" lang { in_block = 1; next }
        in_block && /^```/ { exit }
        in_block { print }
    ' "$readme"
}
block toml > "$work/snippet.toml"
block rust > "$work/example.rs"
[ -s "$work/snippet.toml" ] || { echo "error: no \`\`\`toml block in section \"$section\"" >&2; exit 1; }
[ -s "$work/example.rs" ] || { echo "error: no \`\`\`rust block in section \"$section\"" >&2; exit 1; }

# The README's dependency line names the checkout as ../groundtruth: the user's crate sits beside it.
ln -s "$root" "$work/groundtruth"
mkdir -p "$work/user-crate/src" "$work/user-crate/tests"
{
    cat <<TOML
[package]
name = "user-crate"
version = "0.1.0"
edition = "2024"
publish = false

# Not a member of any workspace above it.
[workspace]

TOML
    cat "$work/snippet.toml"
} > "$work/user-crate/Cargo.toml"
echo "//! A user's crate." > "$work/user-crate/src/lib.rs"
cp "$work/example.rs" "$work/user-crate/tests/ground_scenarios.rs"

offline=()
[ "${OFFLINE:-0}" = 1 ] && offline=(--offline)
cd "$work/user-crate"
[ ! -e Cargo.lock ] || { echo "error: the user's crate must start without a lock file" >&2; exit 1; }
echo "== a fresh resolution in the user's crate (no lock file of ours)"
cargo generate-lockfile "${offline[@]}"

echo "== one glam in the user's dependency graph"
glams=$(cargo tree "${offline[@]}" -d -e normal,build,dev --depth 0 --prefix none --format '{p}' | grep -E '^glam v' | sort -u || true)
if [ -n "$glams" ]; then
    echo "error: more than one glam in the user's crate after a fresh resolution:" >&2
    while read -r _ version _; do
        echo "  glam $version, pulled in by:" >&2
        cargo tree "${offline[@]}" -e normal,build,dev -i "glam@${version#v}" --depth 1 --prefix none \
            --format '{p}' | tail -n +2 | sed 's/^/    /' >&2
    done <<< "$glams"
    exit 1
fi
cargo tree "${offline[@]}" -e normal -i glam --depth 0 --prefix none --format '{p}'

config=()
if [ "${WORKSPACE_PROFILE:-0}" = 1 ]; then
    # The `[profile.dev.package]` table of the workspace's Cargo.toml, up to the next table.
    awk '/^\[profile\.dev\.package\]$/ { f = 1; print; next } f && /^\[/ { exit } f' "$root/Cargo.toml" \
        > "$work/workspace-profile.toml"
    grep -q '^"\*"' "$work/workspace-profile.toml" || {
        echo "error: no [profile.dev.package] table with \"*\" in $root/Cargo.toml" >&2; exit 1; }
    config=(--config "$work/workspace-profile.toml")
fi
echo "== cargo test in the user's crate"
CARGO_TARGET_DIR="$target" cargo test "${offline[@]}" "${config[@]}" --test ground_scenarios
echo "README example: OK ($(grep -c '#\[test\]' tests/ground_scenarios.rs) tests, one glam)"
