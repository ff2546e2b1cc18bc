#!/usr/bin/env bash
# The library crates as crates.io would take them (`make test`; `make lint` runs cargo's own
# publish dry run, which builds them): each packaged (`cargo package`: what the .crate
# holds, the shaders inside ferrovol-core), unpacked, and type-checked from the package
# alone: ferrovol-core by itself, ferrovol-io against the ferrovol-core just packaged. A
# check finds what the dry run's build of the package finds (a file the package lacks, a
# feature a crate uses but does not ask for, a dependency resolved differently) without
# generating code. The checks use the workspace's profiles and target folder, so a
# dependency already checked there with the same features (by `cargo doc`) is not checked
# again.
#   scripts/check-packages.sh
set -euo pipefail
cd "$(dirname "$0")/.."
TARGET=${CARGO_TARGET_DIR:-$PWD/target}
OUT=$TARGET/package-check
CRATES=(ferrovol-core ferrovol-io)

# The workspace's version and profiles (Cargo.toml), the profiles as --config arguments: a
# package is a workspace of its own, and its default profile would check every dependency
# again.
mapfile -t SETTINGS < <(python3 - <<'EOF'
import json, tomllib
manifest = tomllib.load(open("Cargo.toml", "rb"))
print(manifest["workspace"]["package"]["version"])
def config(path, value):
    if isinstance(value, dict):
        for k, v in value.items():
            plain = k.replace("-", "").replace("_", "").isalnum()
            config(path + [k if plain else json.dumps(k)], v)
    else:
        print("--config")
        print(".".join(path) + "=" + json.dumps(value))
config(["profile"], manifest.get("profile", {}))
EOF
)
VERSION=${SETTINGS[0]}
PROFILES=("${SETTINGS[@]:1}")

rm -rf "$OUT"
mkdir -p "$OUT"
package_args=()
for c in "${CRATES[@]}"; do package_args+=(-p "$c"); done
cargo package --no-verify --locked --allow-dirty "${package_args[@]}"
# Unpacked inside the target folder, each is its own workspace, as cargo makes it for the
# dry run's build.
for c in "${CRATES[@]}"; do
  tar -xzf "$TARGET/package/$c-$VERSION.crate" -C "$OUT"
  printf '\n[workspace]\n' >>"$OUT/$c-$VERSION/Cargo.toml"
done

core=$OUT/ferrovol-core-$VERSION
echo "check-packages: ferrovol-core $VERSION from its package, alone"
CARGO_TARGET_DIR=$TARGET cargo check --locked "${PROFILES[@]}" --manifest-path "$core/Cargo.toml"
echo "check-packages: ferrovol-io $VERSION from its package, with ferrovol-core's"
CARGO_TARGET_DIR=$TARGET cargo check "${PROFILES[@]}" \
  --config "patch.crates-io.ferrovol-core.path=\"$core\"" \
  --manifest-path "$OUT/ferrovol-io-$VERSION/Cargo.toml"
