# Sourced by run-app.sh and run-tests.sh (from the repository root): the project's .venv.
#
#   ensure_venv app    # .venv with the package installed (editable)
#   ensure_venv test   # ... and its [test] extra
#
# pip runs only when it has to: when .venv is missing, or when the stamp file
# .venv/.installed-<app|test>-<sha256 of pyproject.toml> of the last install is missing
# (pyproject.toml changed since, or the test extra was never installed). A machine that was
# set up once therefore starts without any package index. The "test" install covers "app".
# If pip fails but .venv already holds the commands (offline, index unreachable), a warning
# says so and the existing .venv is used; the stamp is not written, so the next start retries.

pyproject_sha256() {
  if command -v sha256sum >/dev/null 2>&1; then
    sha256sum pyproject.toml | cut -d' ' -f1
  else
    shasum -a 256 pyproject.toml | cut -d' ' -f1
  fi
}

# The interpreter a new .venv is made with: $PYTHON when set, else the first of python3,
# python3.13, python3.12 and python3.11 on PATH that is Python 3.11 or newer (the oldest the
# whole test suite runs on; Ubuntu 22.04's python3 is 3.10, its python3.11 package is found).
pick_python() {
  local py
  for py in ${PYTHON:-python3 python3.13 python3.12 python3.11}; do
    if command -v "$py" >/dev/null 2>&1 && "$py" -c 'import sys; sys.exit(sys.version_info < (3, 11))' 2>/dev/null; then
      echo "$py"
      return 0
    fi
  done
  echo "error: TCP Pendant needs Python 3.11 or newer with venv, and ${PYTHON:-python3} is older or missing." \
       "On Ubuntu 22.04: sudo apt install python3.11 python3.11-venv (then run this again; it is found" \
       "by itself), or point PYTHON at another interpreter: PYTHON=/path/to/python3.12 bash $0" >&2
  return 1
}

ensure_venv() {
  local extra="$1" sum spec="." py
  if [ ! -x .venv/bin/python ]; then
    py="$(pick_python)" || return 1
    "$py" -m venv .venv
  fi
  sum="$(pyproject_sha256)"
  if [ -e ".venv/.installed-$extra-$sum" ] || [ -e ".venv/.installed-test-$sum" ]; then
    return 0
  fi
  [ "$extra" = app ] || spec=".[$extra]"
  echo "Installing the project and its dependencies into .venv (first run, or pyproject.toml changed):" \
       "about 1-2 minutes on a fresh machine (pinocchio, scipy, viser; run-tests.sh adds the test tools);" \
       "later starts skip this." >&2
  if .venv/bin/python -m pip install -q --disable-pip-version-check -e "$spec"; then
    rm -f .venv/.installed-"$extra"-*
    touch ".venv/.installed-$extra-$sum"
  elif [ -x .venv/bin/tcp-pendant ] && [ -x .venv/bin/tcpcal ]; then
    echo "WARNING: 'pip install -e $spec' failed (no package index reachable?); using the existing .venv," \
         "which may lack what pyproject.toml asks for. It is retried at the next start." >&2
  else
    echo "error: 'pip install -e $spec' failed and .venv is not set up; connect to a package index" \
         "(or set PIP_INDEX_URL) and run again." >&2
    return 1
  fi
}
