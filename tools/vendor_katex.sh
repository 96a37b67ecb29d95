#!/usr/bin/env bash
# Vendor KaTeX (the npm package `katex`, pinned below) into docs/assets/vendor/katex/ so that the
# documentation site typesets its mathematics with no CDN. Idempotent: does nothing when the pinned
# version is already there (its VERSION, script and style sheet: a folder missing either is vendored again).
# Needs npm (Node.js); the folder is gitignored.
set -euo pipefail
cd "$(dirname "$0")/.."
KATEX_VERSION=0.16.22
DEST=docs/assets/vendor/katex
if [ -f "$DEST/VERSION" ] && [ "$(cat "$DEST/VERSION")" = "$KATEX_VERSION" ] \
        && [ -f "$DEST/katex.min.js" ] && [ -f "$DEST/katex.min.css" ]; then
    exit 0
fi
if ! command -v npm >/dev/null 2>&1; then
    echo "vendor_katex.sh: npm is needed to fetch KaTeX $KATEX_VERSION (apt-get install -y npm)" >&2
    exit 1
fi
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
# npm pack checks the tarball against the registry's integrity hash.
if ! TARBALL="$(cd "$TMP" && npm pack --silent "katex@$KATEX_VERSION" 2>"$TMP/npm.log" | tail -n 1)" \
        || [ ! -f "$TMP/$TARBALL" ]; then
    echo "vendor_katex.sh: npm pack katex@$KATEX_VERSION failed:" >&2
    tail -n 20 "$TMP/npm.log" >&2
    exit 1
fi
tar -xzf "$TMP/$TARBALL" -C "$TMP"
rm -rf "$DEST.new"
mkdir -p "$DEST.new/fonts"
cp "$TMP/package/dist/katex.min.js" "$TMP/package/dist/katex.min.css" "$TMP/package/LICENSE" "$DEST.new/"
cp "$TMP"/package/dist/fonts/*.woff2 "$TMP"/package/dist/fonts/*.woff "$TMP"/package/dist/fonts/*.ttf "$DEST.new/fonts/"
echo "$KATEX_VERSION" > "$DEST.new/VERSION"
rm -rf "$DEST"
mv "$DEST.new" "$DEST"
echo "KaTeX $KATEX_VERSION vendored into $DEST" >&2
