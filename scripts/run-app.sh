#!/usr/bin/env bash
# Set up (first run only) and start the pendant: http://127.0.0.1:8080
#   bash scripts/run-app.sh [tcp-pendant options, see --help]
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x .venv/bin/python ] || python3 -m venv .venv
.venv/bin/python -m pip install -q --disable-pip-version-check -e .
exec .venv/bin/tcp-pendant "$@"
