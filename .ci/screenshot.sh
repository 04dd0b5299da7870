#!/usr/bin/env bash
# Take the README's screenshots: the real app in a real (virtual) X window on the built-in
# default study, at 1280x720 and 1920x1080, each saved once the full-resolution results are on
# screen; then the app quits.
#
#   bash .ci/screenshot.sh [OUT_DIR]      (default: assets/)
#
# Writes OUT_DIR/screenshot_1280x720.png and OUT_DIR/screenshot_1920x1080.png, and the same of
# the four-design study (four_designs_lake_hume) as OUT_DIR/screenshot_four_WxH.png.
# Needs Xvfb and Mesa's software OpenGL (Debian/Ubuntu: apt install xvfb libgl1-mesa-dri).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-assets}
if ! command -v xvfb-run >/dev/null; then
    echo "error: xvfb-run not found (apt install xvfb libgl1-mesa-dri)" >&2
    exit 2
fi
cargo build --release --locked
for size in 1280x720 1920x1080; do
    # A throw-away preset library and session, so the screenshot does not depend on this user's.
    home=$(mktemp -d)
    SHOAL_HOME="$home" XDG_DATA_HOME="$home" LIBGL_ALWAYS_SOFTWARE=1 \
        timeout 900 xvfb-run -a -s "-screen 0 ${size}x24" \
        ./target/release/shoal app --size "$size" --screenshot "$out/screenshot_$size.png"
    rm -rf "$home"
    echo "wrote $out/screenshot_$size.png"
    home=$(mktemp -d)
    SHOAL_HOME="$home" XDG_DATA_HOME="$home" LIBGL_ALWAYS_SOFTWARE=1 \
        timeout 900 xvfb-run -a -s "-screen 0 ${size}x24" \
        ./target/release/shoal app --size "$size" --study four_designs_lake_hume \
        --screenshot "$out/screenshot_four_$size.png"
    rm -rf "$home"
    echo "wrote $out/screenshot_four_$size.png"
done

# The review pack of the default study (at 1/4 resolution), rendered by headless Chromium as the
# test renders it: the top of the page, 1280 px wide.
if command -v chromium >/dev/null; then
    work=$(mktemp -d)
    ./target/release/shoal study --decimation 4 --no-cubes --out "$work/study"
    ./target/release/shoal report "$work/study" --out "$work/pack"
    chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
        --disable-background-networking --disable-component-update --disable-sync \
        --hide-scrollbars --user-data-dir="$work/profile" --window-size=1280,1700 \
        --screenshot="$out/review_pack.png" "file://$work/pack/index.html" 2>/dev/null
    rm -rf "$work"
    echo "wrote $out/review_pack.png"
else
    echo "chromium not found: review_pack.png not retaken (apt install chromium)" >&2
fi
