#!/usr/bin/env bash
# Builds the project the ways a user does, without our Cargo.lock:
#   1. the workspace resolved from scratch in a copy of the tracked files (`cargo generate-lockfile`):
#      one glam in the graph, naming the crates behind each version when there are two;
#   2. `cargo install --path .` (no --locked: cargo install resolves afresh, as `cargo install --git`
#      does), then the installed program runs (`groundtruth --version`, `groundtruth list`);
#   3. `cargo package --workspace`: every crate packs as it would be published (metadata, versions
#      on path dependencies, files). VERIFY=1 also builds each packed crate (several minutes).
#
#   scripts/check-user-builds.sh
#
# CARGO_TARGET_DIR (default ./target) is shared, so crates of the same version as an earlier
# `cargo build --release` are not built again.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "== the workspace resolved from scratch (no Cargo.lock): one glam"
mkdir "$work/fresh"
git ls-files -z | grep -zv '^Cargo.lock$' | xargs -0 tar -cf - | tar -xf - -C "$work/fresh"
(
    cd "$work/fresh"
    cargo generate-lockfile
    glams=$(cargo tree --workspace -d -e normal,build,dev --depth 0 --prefix none --format '{p}' | grep -E '^glam v' | sort -u || true)
    if [ -n "$glams" ]; then
        echo "error: more than one glam after a fresh resolution of the workspace:" >&2
        while read -r _ version _; do
            echo "  glam $version, pulled in by:" >&2
            cargo tree --workspace -e normal,build,dev -i "glam@${version#v}" --depth 1 --prefix none \
                --format '{p}' | tail -n +2 | sed 's/^/    /' >&2
        done <<< "$glams"
        exit 1
    fi
    cargo tree --workspace -e normal -i glam --depth 0 --prefix none --format '{p}'
)

# INSTALL_PROFILE=dev (CI) installs the unoptimised build (`--debug`), reusing the test build's
# dependencies where the fresh resolution agrees; the default is the release build users get.
install_args=()
[ "${INSTALL_PROFILE:-release}" = dev ] && install_args=(--debug)
echo "== cargo install --path . (no --locked) ${install_args[*]}"
cargo install --path . --root "$work/install" "${install_args[@]}"
"$work/install/bin/groundtruth" --version
"$work/install/bin/groundtruth" list >/dev/null
echo "installed and ran: $("$work/install/bin/groundtruth" --version)"

echo "== cargo package --workspace"
verify=(--no-verify)
[ "${VERIFY:-0}" = 1 ] && verify=()
# --allow-dirty: CI's clone is clean; a developer's tree may not be.
cargo package --workspace --allow-dirty "${verify[@]}" 2>&1 | grep -Ev '^ +(Packaging|Updating|Locking|Adding|Archiving)' || {
    echo "error: cargo package --workspace failed" >&2
    exit 1
}
echo "user builds: OK"
