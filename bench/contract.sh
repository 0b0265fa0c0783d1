#!/usr/bin/env bash
# The API contract, checked from outside: openapi-spec-validator on /openapi.json and a
# schemathesis run (all checks, 50 examples per operation) against a fresh server.
#   python3 -m pip install schemathesis openapi-spec-validator
#   bench/contract.sh [path/to/surfmap-server]
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${1:-target/release/surfmap-server}
DIR=$(mktemp -d)
trap 'kill $PID 2>/dev/null || true; rm -rf "$DIR"' EXIT
# With a token, as a deployment runs: the document declares it, and the 401s are checked too.
"$BIN" --listen 127.0.0.1:0 --database-url "sqlite://$DIR/db" --data-dir "$DIR/data" --workers 0 \
  --api-token contract > "$DIR/out" 2> "$DIR/err" &
PID=$!
for _ in $(seq 100); do grep -q "listening on" "$DIR/out" 2>/dev/null && break; sleep 0.1; done
ADDR=$(sed -n 's/^listening on //p' "$DIR/out")
curl -s "http://$ADDR/openapi.json" > "$DIR/openapi.json"
python3 -c "import json,sys; from openapi_spec_validator import validate; validate(json.load(open(sys.argv[1]))); print('openapi-spec-validator: 0 errors')" "$DIR/openapi.json"
schemathesis --config-file bench/schemathesis.toml run "http://$ADDR/openapi.json" \
  --checks all --max-examples 50 --workers 1 --seed 1 -H "Authorization: Bearer contract"
