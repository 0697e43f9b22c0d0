#!/usr/bin/env bash
# Set up everything the test suite needs on a fresh machine, type-check the code (mypy), then run
# the tests.
#   bash scripts/run-tests.sh            # mypy, then the whole suite (unit, property, CLI, browser)
#   bash scripts/run-tests.sh -m browser # only the browser end-to-end tests
# The browser tests drive Debian's chromium (Playwright cannot download its own browser here):
# when it is missing it is installed with apt-get as root (or through sudo). A user who can do
# neither gets a one-line hint, every other test runs, and a last loud line says that the
# browser tests did not run. Under CI=true a missing chromium fails the run (exit 1).
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/venv.sh
ensure_venv test

# The type check first (pyproject.toml [tool.mypy]: strict on src/tcpcal, standard on app/):
# a type error fails the run before any test.
if ! .venv/bin/python -m mypy; then
  echo "run-tests.sh: mypy found the type errors listed above; no test ran." >&2
  exit 1
fi

install_chromium() {
  local cmd='apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium'
  if [ "$(id -u)" = 0 ]; then
    sh -c "$cmd" >/dev/null
  elif command -v sudo >/dev/null 2>&1; then
    sudo sh -c "$cmd" >/dev/null
  else
    return 2
  fi
}

chromium_missing=""
if [ -n "${CHROMIUM:-}" ]; then                    # the browser tests' own override
  [ -x "$CHROMIUM" ] || chromium_missing="CHROMIUM=$CHROMIUM is not an executable file; point it at chromium or unset it"
elif ! command -v chromium >/dev/null 2>&1; then
  rc=0
  install_chromium || rc=$?
  if [ "$rc" = 2 ]; then
    chromium_missing="chromium is missing and this user can neither be root nor use sudo: ask an administrator to run 'apt-get install chromium' (Debian/Ubuntu), or set CHROMIUM=/path/to/chromium"
  elif ! command -v chromium >/dev/null 2>&1; then
    chromium_missing="chromium is missing and 'apt-get install chromium' failed (exit $rc): install it by hand, or set CHROMIUM=/path/to/chromium"
  fi
fi
if [ -z "$chromium_missing" ]; then
  [ -n "${CHROMIUM:-}" ] || export CHROMIUM="$(command -v chromium)"
  exec .venv/bin/python -m pytest "$@"
fi

# No chromium: run everything but the browser tests (AND-ed with a -m the caller gave).
echo "run-tests.sh: $chromium_missing." >&2
marker="not browser"
args=()
while [ $# -gt 0 ]; do
  case "$1" in
    -m) marker="not browser and (${2:-})"; shift; [ $# -eq 0 ] || shift ;;
    -m*) marker="not browser and (${1#-m})"; shift ;;
    *) args+=("$1"); shift ;;
  esac
done
rc=0
.venv/bin/python -m pytest -m "$marker" ${args[@]+"${args[@]}"} || rc=$?
echo "!!!!!!!! THE BROWSER TESTS DID NOT RUN: $chromium_missing. !!!!!!!!" >&2
if [ "${CI:-}" = true ]; then
  echo "run-tests.sh: CI=true: failing the run because the browser tests could not run." >&2
  exit 1
fi
exit "$rc"
