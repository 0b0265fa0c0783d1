#!/usr/bin/env bash
# Smoke test of a running surfmap: upload a real mesh pair, submit a job, wait for it, fetch
# its artifacts and check its metrics. Users' CI runs it against a deployment:
#
#   deploy/smoke.sh http://127.0.0.1:8080
#
# Environment: SURFMAP_TOKEN (bearer token, if the server wants one), SURFMAP_SMOKE_SOURCE and
# SURFMAP_SMOKE_TARGET (a registered pair: vertex i of one matches vertex i of the other;
# default: the SMPL man and woman from ../shared/meshes), SURFMAP_SMOKE_TIMEOUT (seconds, 300).
# Needs bash, curl and python3 (for JSON). Exits 0 on success, 1 with the reason otherwise.
set -euo pipefail

BASE="${1:?usage: smoke.sh BASE_URL}"
BASE="${BASE%/}"
HERE="$(cd "$(dirname "$0")" && pwd)"
SOURCE="${SURFMAP_SMOKE_SOURCE:-$HERE/../../shared/meshes/registered/smpl_human/human_man.obj}"
TARGET="${SURFMAP_SMOKE_TARGET:-$HERE/../../shared/meshes/registered/smpl_human/human_woman.obj}"
TIMEOUT="${SURFMAP_SMOKE_TIMEOUT:-300}"
# Twenty farthest-point samples of the SMPL template (identity correspondence).
ANCHORS="${SURFMAP_SMOKE_ANCHORS:-0 6763 5905 2445 1262 4716 1633 1095 1329 4463 4296 732 3385 4599 5432 2913 978 5360 1921 1803}"

WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
AUTH=()
if [[ -n "${SURFMAP_TOKEN:-}" ]]; then AUTH=(-H "Authorization: Bearer $SURFMAP_TOKEN"); fi

fail() { echo "smoke: FAIL: $*" >&2; exit 1; }
# field FILE EXPR: evaluates a Python expression over the JSON document d.
field() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print($2)" "$1"; }
call() { # call METHOD PATH OUT [curl args...] -> prints the HTTP status
  local method="$1" path="$2" out="$3"; shift 3
  curl -sS -o "$out" -w '%{http_code}' -X "$method" "${AUTH[@]}" "$@" "$BASE$path"
}

[[ "$(call GET /healthz "$WORK/h.json")" == 200 ]] || fail "GET /healthz"
[[ "$(call GET /readyz "$WORK/r.json")" == 200 ]] || fail "GET /readyz: $(cat "$WORK/r.json")"

for role in source target; do
  file="$SOURCE"; [[ $role == target ]] && file="$TARGET"
  [[ -f "$file" ]] || fail "no $role mesh at $file"
  st="$(call POST /v1/meshes "$WORK/$role.json" --data-binary "@$file")"
  [[ "$st" == 201 ]] || fail "upload $role: HTTP $st $(cat "$WORK/$role.json")"
done
SRC="$(field "$WORK/source.json" 'd["id"]')"
TGT="$(field "$WORK/target.json" 'd["id"]')"

python3 - "$SRC" "$TGT" "$ANCHORS" > "$WORK/job.json" <<'PY'
import json, sys
src, tgt, anchors = sys.argv[1], sys.argv[2], [int(a) for a in sys.argv[3].split()]
print(json.dumps({"source": src, "target": tgt, "spec": {"method": "voronoi", "anchors": [[a, a] for a in anchors]}}))
PY
st="$(call POST /v1/jobs "$WORK/submitted.json" -H 'Content-Type: application/json' -H "Idempotency-Key: smoke-$$-$RANDOM" --data-binary "@$WORK/job.json")"
[[ "$st" == 202 ]] || fail "submit: HTTP $st $(cat "$WORK/submitted.json")"
JOB="$(field "$WORK/submitted.json" 'd["id"]')"
echo "smoke: job $JOB queued"

deadline=$(( $(date +%s) + TIMEOUT ))
while :; do
  [[ "$(call GET "/v1/jobs/$JOB" "$WORK/job-state.json")" == 200 ]] || fail "GET job"
  state="$(field "$WORK/job-state.json" 'd["state"]')"
  case "$state" in
    succeeded) break ;;
    failed|cancelled) fail "job $state: $(field "$WORK/job-state.json" 'd["error"]')" ;;
  esac
  (( $(date +%s) < deadline )) || fail "job still $state after ${TIMEOUT}s"
  sleep 1
done

for name in source_on_target.obj target_on_source.obj source_to_target.csv target_to_source.csv \
            layout.json layout_source.ply layout_target.ply metrics.json; do
  st="$(call GET "/v1/jobs/$JOB/artifacts/$name" "$WORK/$name")"
  [[ "$st" == 200 && -s "$WORK/$name" ]] || fail "artifact $name: HTTP $st"
done

python3 - "$WORK/metrics.json" <<'PY' || fail "metrics out of bounds"
import json, math, sys
m = json.load(open(sys.argv[1]))
for way in ("source_to_target", "target_to_source"):
    d = m[way]
    checks = {
        "no flipped faces": d["flipped_faces"] == 0,
        "anchors mapped exactly": d["anchor_error_max"] is not None and d["anchor_error_max"] <= 1e-9,
        "on the target surface": d["off_surface_max"] <= 1e-9,
        "finite L2 stretch >= 1": math.isfinite(d["l2_stretch"]) and d["l2_stretch"] >= 1 - 1e-9,
    }
    for what, ok in checks.items():
        print(f"smoke: {way}: {what}: {'ok' if ok else 'FAILED'}")
        if not ok:
            sys.exit(1)
PY
echo "smoke: OK (job $JOB)"
