#!/usr/bin/env bash
# Brings the public SLAM maps of scenarios/real/ (README.md there) from Debian's package registry into
# scenarios/real/maps/, as published, with the package's copyright file beside them. Nothing here is
# committed: the maps are the package's, not ours. Idempotent; exits 0 with a note when this machine has
# no apt (the tests that need the maps then say so and are skipped, or fail under CI=true).
#   scenarios/real/fetch_maps.sh
set -euo pipefail
cd "$(dirname "$0")"
DEST=maps/mrpt-common
PACKAGE=mrpt-common
FILES=(2006-MalagaCampus.gridmap.gz uwb_ro-localization_demo_map.gridmap.gz)

have_all() { for f in "${FILES[@]}"; do [[ -f "$DEST/$f" ]] || return 1; done; [[ -f "$DEST/copyright" ]]; }
have_all && exit 0
if ! command -v apt-get >/dev/null || ! command -v dpkg-deb >/dev/null; then
    echo "fetch_maps: no apt-get/dpkg-deb here; the real maps (Debian package $PACKAGE) are not fetched" >&2
    exit 0
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# apt-get download needs the package lists; refresh them once when the package is not known (needs root).
if ! apt-cache show "$PACKAGE" >/dev/null 2>&1; then
    if [[ $(id -u) -eq 0 ]]; then apt-get update -qq >/dev/null; fi
fi
(cd "$work" && chmod 777 . && apt-get download -qq "$PACKAGE") >&2 || {
    echo "fetch_maps: apt-get download $PACKAGE failed; the real maps are not fetched" >&2
    exit 0
}
dpkg-deb -x "$work"/"$PACKAGE"_*.deb "$work/root"
mkdir -p "$DEST"
for f in "${FILES[@]}"; do cp "$work/root/usr/share/mrpt/datasets/$f" "$DEST/"; done
cp "$work/root/usr/share/doc/$PACKAGE/copyright" "$DEST/copyright"
dpkg-deb -f "$work"/"$PACKAGE"_*.deb Package Version > "$DEST/PACKAGE"
echo "fetch_maps: $(tr '\n' ' ' < "$DEST/PACKAGE")-> scenarios/real/$DEST" >&2
