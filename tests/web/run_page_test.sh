#!/bin/sh
# Runs page_test.mjs; exits 77 (CTest: skipped) when node, its npm packages (./ftstack.sh deps) or
# Debian's chromium are missing. Usage: run_page_test.sh FTD SCREENSHOT.png
here=$(dirname "$0")
for need in node /usr/bin/chromium; do
  command -v "$need" >/dev/null 2>&1 || { echo "skipped: no $need"; exit 77; }
done
[ -d "$here/node_modules/puppeteer-core" ] || { echo "skipped: run ./ftstack.sh deps (npm ci in tests/web)"; exit 77; }
exec node "$here/page_test.mjs" "$@"
