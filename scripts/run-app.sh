#!/usr/bin/env bash
# Set up (first run, or after pyproject.toml changed; see scripts/venv.sh) and start the
# pendant: http://127.0.0.1:8080. A set-up machine starts offline (pip does not run).
#   bash scripts/run-app.sh [tcp-pendant options, see --help]
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/venv.sh
ensure_venv app
exec .venv/bin/tcp-pendant "$@"
