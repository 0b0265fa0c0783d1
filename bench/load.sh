#!/usr/bin/env bash
# Load bench: a release surfmap-server (API only) and two release surfmap-worker processes on a
# fresh SQLite store; 500 submissions from 50 clients, then status polling while the workers
# are busy; then the peak RSS of each process. Usage: bench/load.sh [POLL_SECS] [POLLERS]
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-/work/surfmap-target}"
cargo build --release -q -p surfmap-server -p surfmap-worker -p surfmap-e2e --bin surfmap-server --bin surfmap-worker --bin surfmap-load
BIN="$CARGO_TARGET_DIR/release"
WORK="$(mktemp -d)"
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$WORK"' EXIT
DB="sqlite://$WORK/surfmap.db"
"$BIN/surfmap-server" --listen 127.0.0.1:0 --database-url "$DB" --data-dir "$WORK/data" --workers 0 > "$WORK/server.out" 2> "$WORK/server.log" &
SERVER=$!
for _ in $(seq 100); do grep -q listening "$WORK/server.out" 2>/dev/null && break; sleep 0.1; done
ADDR="$(sed -n 's/^listening on //p' "$WORK/server.out")"
# WORKER_NICE=10 runs the workers below the API's CPU priority (the figures in the issue note are at 0).
nice -n "${WORKER_NICE:-0}" "$BIN/surfmap-worker" --database-url "$DB" --data-dir "$WORK/data" --worker-id wa > /dev/null 2> "$WORK/wa.log" &
WA=$!
nice -n "${WORKER_NICE:-0}" "$BIN/surfmap-worker" --database-url "$DB" --data-dir "$WORK/data" --worker-id wb > /dev/null 2> "$WORK/wb.log" &
WB=$!
M=../shared/meshes/registered/smpl_human
"$BIN/surfmap-load" --base "http://$ADDR" --source $M/human_man.obj --target $M/human_woman.obj \
  --anchors "0,6763,5905,2445,1262,4716,1633,1095,1329,4463,4296,732,3385,4599,5432,2913,978,5360,1921,1803" \
  --poll-secs "${1:-10}" --pollers "${2:-32}"
for p in SERVER WA WB; do
  pid="${!p}"
  echo "$p peak RSS: $(awk '/VmHWM/ {print $2, $3}' /proc/$pid/status)"
done
grep -c "completed" "$WORK/wa.log" "$WORK/wb.log" || true
