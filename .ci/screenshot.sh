#!/usr/bin/env bash
# Take the README's screenshot: the real app in a real (virtual) X window, on the built-in
# default study, saved once the full-resolution results are on screen; then the app quits.
#
#   bash .ci/screenshot.sh [OUT.png]      (default: assets/screenshot.png)
#
# Needs Xvfb and Mesa's software OpenGL (Debian/Ubuntu: apt install xvfb libgl1-mesa-dri).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-assets/screenshot.png}
if ! command -v xvfb-run >/dev/null; then
    echo "error: xvfb-run not found (apt install xvfb libgl1-mesa-dri)" >&2
    exit 2
fi
cargo build --release --locked
# A throw-away preset library and session, so the screenshot does not depend on this user's.
home=$(mktemp -d)
trap 'rm -rf "$home"' EXIT
SHOAL_HOME="$home" XDG_DATA_HOME="$home" LIBGL_ALWAYS_SOFTWARE=1 \
    timeout 600 xvfb-run -a -s "-screen 0 1600x1000x24" \
    ./target/release/shoal app --screenshot "$out"
echo "wrote $out"
