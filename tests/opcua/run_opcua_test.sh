#!/bin/sh
# Runs opcua_test.mjs; exits 77 (CTest: skipped) when node or its npm packages (./ftstack.sh deps)
# are missing. Usage: run_opcua_test.sh FTD CASE
here=$(dirname "$0")
for need in node mbpoll openssl; do
  command -v "$need" >/dev/null 2>&1 || { echo "skipped: no $need"; exit 77; }
done
[ -d "$here/node_modules/node-opcua-client" ] || { echo "skipped: run ./ftstack.sh deps (npm ci in tests/opcua)"; exit 77; }
exec node "$here/opcua_test.mjs" "$@"
