#!/bin/sh
# Rebuilds vendor/check_channels.mjs, the one file tests/test_lichtblick.py runs with node, from
# the npm packages that package-lock.json pins. Needs node and npm; run it from anywhere.
set -eu
cd "$(dirname "$0")"
npm ci --no-audit --no-fund
node extract_parse_channel.mjs
npx --no-install esbuild check_channels.mjs --bundle --platform=node --format=esm \
  --target=node18 --charset=utf8 --outfile=vendor/check_channels.mjs \
  --banner:js="// Built by tests/lichtblick/build.sh: do not edit. It bundles @mcap/core (MIT), fzstd (MIT), @protobufjs/base64 (BSD-3-Clause) and parseJsonSchema and parseChannel from @foxglove/studio-base@1.48.0 assets/index.js (MPL-2.0, source: that npm package; see tests/lichtblick/README.md)."
