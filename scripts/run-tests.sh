#!/usr/bin/env bash
# Set up everything the test suite needs on a fresh machine, type-check the code (mypy), check
# the import layers (lint-imports), build the documentation site (mkdocs build --strict), then
# run the tests.
#   bash scripts/run-tests.sh            # the checks, then the whole suite (unit, property, CLI, browser)
#   bash scripts/run-tests.sh --quick    # the checks, then all but the tests marked slow: while working
#   bash scripts/run-tests.sh -m browser # only the browser end-to-end tests
# The browser tests drive Debian's chromium (Playwright cannot download its own browser here):
# when it is missing it is installed with apt-get as root (or through sudo). A user who can do
# neither gets a one-line hint, every other test runs, and a last loud line says that the
# browser tests did not run. Under CI=true a missing chromium fails the run (exit 1).
# Debian's fonts for Cyrillic, Devanagari, Chinese and Japanese are installed the same way (the
# pendant's languages; a missing one fails the font test, and under CI=true the run).
# Debian's postgresql and nginx (the PostgreSQL gradebook and front-end tests) are installed
# the same way; their tests are skipped where they are missing, and fail under CI=true.
# Without arguments (the README's command, CI) pytest runs twice: the tests not marked serial on
# two pytest-xdist workers, then the serial ones (tests/app, tests/browser, tests/security:
# servers, chromium, latency and load; tests/conftest.py marks them) alone; every test runs
# once and the exit status is the first failing run's. --quick (the lane to run while working,
# under 5 minutes on two cores): the same two runs without the tests marked slow (benchmarks'
# smoke runs, the 1e5-row CLI runs, Monte Carlo, the other long ones and every browser test:
# tests/conftest.py); arguments after it go to both runs. With other arguments: one pytest run,
# as given.
set -euo pipefail
cd "$(dirname "$0")/.."
quick=""
if [ "${1:-}" = --quick ]; then quick="not slow"; shift; fi
. scripts/venv.sh
ensure_venv test

# The type check first (pyproject.toml [tool.mypy]: strict on src/tcpcal, standard on app/):
# a type error fails the run before any test.
if ! .venv/bin/python -m mypy; then
  echo "run-tests.sh: mypy found the type errors listed above; no test ran." >&2
  exit 1
fi

# The layers next (pyproject.toml [tool.importlinter]: tcpcal imports nothing of the app, each
# package of the app only the layers below it, viser only views and serve): an import that
# breaks one fails the run before any test.
if ! .venv/bin/lint-imports --no-logo; then
  echo "run-tests.sh: lint-imports found the imports listed above that break a layer contract; no test ran." >&2
  exit 1
fi

# Then the documentation site (mkdocs.yml, into a scratch folder, removed after): a broken link
# or anchor, a page left out of the nav, or a docstring the API reference cannot parse or resolve
# fails the run before any test. Quiet when it builds; on failure its warnings, then one line.
site_dir="${TMPDIR:-/tmp}/tcp-pendant-site-$$"
site_rc=0
site_log="$(NO_MKDOCS_2_WARNING=1 .venv/bin/python -m mkdocs build --strict --site-dir "$site_dir" 2>&1)" || site_rc=$?
rm -rf "$site_dir"
if [ "$site_rc" != 0 ]; then
  while IFS= read -r line; do
    case "$line" in INFO*) ;; *) printf '%s\n' "$line" >&2 ;; esac
  done <<< "$site_log"
  echo "run-tests.sh: the documentation site does not build (mkdocs build --strict: the warnings above); no test ran." >&2
  exit 1
fi

apt_install() {                    # apt_install PACKAGE...: as root, or through sudo; 2: neither
  local cmd="apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q $*"
  if [ "$(id -u)" = 0 ]; then
    sh -c "$cmd" >/dev/null
  elif command -v sudo >/dev/null 2>&1; then
    sudo sh -c "$cmd" >/dev/null
  else
    return 2
  fi
}
install_chromium() { apt_install chromium; }

# The PostgreSQL gradebook's tests start a real server of Debian's postgresql package (initdb and
# pg_ctl under /usr/lib/postgresql/*/bin, on a free port; tests/conftest.py) and the front-end
# test checks docs/nginx-class.conf with Debian's nginx: both installed here like chromium. (On a
# machine with systemd, Debian also starts both services after installing them; the tests use
# neither: 'systemctl disable --now postgresql nginx' stops them.) Where they cannot be
# installed, those tests are skipped with the reason (not run), and under CI=true they fail.
# PG_BIN (a folder with pg_ctl) and NGINX (the nginx binary) point the tests at other copies.
have_postgres() {
  if [ -n "${PG_BIN:-}" ]; then [ -x "$PG_BIN/pg_ctl" ]; else compgen -G '/usr/lib/postgresql/*/bin/pg_ctl' >/dev/null; fi
}
have_nginx() {
  if [ -n "${NGINX:-}" ]; then [ -x "$NGINX" ]; else command -v nginx >/dev/null 2>&1 || [ -x /usr/sbin/nginx ]; fi
}
servers=()
have_postgres || servers+=(postgresql)
have_nginx || servers+=(nginx)
if [ ${#servers[@]} -gt 0 ]; then
  rc=0
  apt_install "${servers[@]}" || rc=$?
  if ! have_postgres || ! have_nginx; then
    echo "!!!!!!!! run-tests.sh: could not install ${servers[*]} (apt-get exit $rc$([ "$rc" = 2 ] && echo ': neither root nor sudo')):" \
         "the PostgreSQL gradebook and nginx front-end tests will not run (CI=true fails them);" \
         "install them by hand: apt-get install ${servers[*]} !!!!!!!!" >&2
  fi
fi

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
# The fonts of the pendant's scripts: viser draws the panel and the 3D labels (a canvas) with the
# system font stack, so Cyrillic, Devanagari and Chinese/Japanese show only where the machine
# has fonts for them (else boxes: tofu; tests/browser/test_fonts_browser.py fails). Debian's
# packages, installed like chromium: fonts-dejavu-core (Latin, Cyrillic), fonts-lohit-deva
# (Devanagari, 0.2 MB), fonts-noto-cjk (Chinese and Japanese, 90 MB installed; fontconfig picks
# its Japanese or Chinese shapes by the page's language). Where they cannot be installed, a loud
# line says so and the font test fails; under CI=true the run fails here.
# FC_LIST (fontconfig's fc-list, default the one on PATH) points the check at another copy.
font_langs=(ru hi zh-cn ja)
fonts_missing() {                  # the languages (fontconfig :lang=) no installed font covers
  local lang out=() fc="${FC_LIST:-fc-list}"
  command -v "$fc" >/dev/null 2>&1 || { echo "${font_langs[*]}"; return; }
  for lang in "${font_langs[@]}"; do [ -n "$("$fc" ":lang=$lang" family 2>/dev/null)" ] || out+=("$lang"); done
  echo "${out[*]}"
}
if [ -n "$(fonts_missing)" ]; then
  rc=0
  apt_install fontconfig fonts-dejavu-core fonts-lohit-deva fonts-noto-cjk || rc=$?
  missing_fonts="$(fonts_missing)"
  if [ -n "$missing_fonts" ]; then
    echo "!!!!!!!! run-tests.sh: no font for $missing_fonts (apt-get exit $rc$([ "$rc" = 2 ] && echo ': neither root nor sudo')):" \
         "the pendant shows boxes for those scripts and the font test fails;" \
         "install them by hand: apt-get install fonts-dejavu-core fonts-lohit-deva fonts-noto-cjk !!!!!!!!" >&2
    if [ "${CI:-}" = true ]; then
      echo "run-tests.sh: CI=true: failing the run because the fonts are missing; no test ran." >&2
      exit 1
    fi
  fi
fi

# run_suite MARKER [ARGS...]: the whole suite (of MARKER, e.g. "not browser"; empty: all) in two
# runs, each with ARGS: the tests not marked serial on 2 xdist workers, then the serial ones in one
# process (header comment).
run_suite() {
  local only="${1:+$1 and }" rc_parallel=0 rc_serial=0
  shift
  .venv/bin/python -m pytest -n 2 --durations=25 -m "${only}not serial" "$@" || rc_parallel=$?
  .venv/bin/python -m pytest --durations=25 -m "${only}serial" "$@" || rc_serial=$?
  if [ "$rc_parallel" != 0 ] || [ "$rc_serial" != 0 ]; then
    echo "run-tests.sh: pytest exited $rc_parallel (the tests on 2 workers) and $rc_serial (the serial tests)." >&2
  fi
  [ "$rc_parallel" != 0 ] && return "$rc_parallel"
  return "$rc_serial"
}

if [ -z "$chromium_missing" ]; then
  [ -n "${CHROMIUM:-}" ] || export CHROMIUM="$(command -v chromium)"
  if [ $# -eq 0 ] || [ -n "$quick" ]; then
    rc=0
    run_suite "$quick" "$@" || rc=$?
    exit "$rc"
  fi
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
if [ -n "$quick" ]; then
  run_suite "$marker and $quick" ${args[@]+"${args[@]}"} || rc=$?
elif [ ${#args[@]} -eq 0 ] && [ "$marker" = "not browser" ]; then
  run_suite "$marker" || rc=$?
else
  .venv/bin/python -m pytest -m "$marker" ${args[@]+"${args[@]}"} || rc=$?
fi
echo "!!!!!!!! THE BROWSER TESTS DID NOT RUN: $chromium_missing. !!!!!!!!" >&2
if [ "${CI:-}" = true ]; then
  echo "run-tests.sh: CI=true: failing the run because the browser tests could not run." >&2
  exit 1
fi
exit "$rc"
