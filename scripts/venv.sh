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

ensure_venv() {
  local extra="$1" sum spec="."
  [ -x .venv/bin/python ] || python3 -m venv .venv
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
