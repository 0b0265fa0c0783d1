#!/usr/bin/env bash
# What the tests need beyond the Rust toolchain (the README's test command runs this first):
# Python packages for the evaluator (numpy, scipy), the OpenAPI check, the S3 test (moto), the
# Python client's tests (pytest, httpx, the client itself) and the dashboard's browser test
# (Playwright for Python, driving Debian's chromium). Idempotent; quick when all is there.
set -euo pipefail
cd "$(dirname "$0")/.."
python3 -m pip install --quiet --disable-pip-version-check \
  numpy scipy openapi-spec-validator "moto[server]" pytest httpx playwright ./clients/python
if ! command -v chromium >/dev/null 2>&1; then
  sudo=""
  [ "$(id -u)" = 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends chromium >/dev/null
fi
