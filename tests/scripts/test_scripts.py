"""The commands of the README, ``scripts/run-app.sh`` and ``scripts/run-tests.sh`` (``--quick``), run for real
(bash) in a copy of the repository's scripts with a fake ``.venv`` and a fake ``PATH``.

The fake ``.venv/bin/python`` logs every call to ``calls.log`` and answers ``-m pip`` with
``$FAKE_PIP_RC`` (default 1: no package index), ``-m pytest`` with ``$FAKE_PYTEST_RC`` and
``-m mypy`` with ``$FAKE_MYPY_OUT`` on stdout and ``$FAKE_MYPY_RC`` (default 0: no type error),
``-m mkdocs`` with ``$FAKE_MKDOCS_OUT`` on stderr and ``$FAKE_MKDOCS_RC`` (default 0: the site builds);
``.venv/bin/lint-imports`` logs its arguments and answers with ``$FAKE_LINT_OUT`` on stdout and
``$FAKE_LINT_RC`` (default 0: every layer kept); ``.venv/bin/tcp-pendant`` logs its arguments.
``PATH`` holds only the tools the scripts need
(bash, coreutils), a fake ``id`` printing ``$FAKE_UID``, and whatever a test adds (``sudo``,
``apt-get``, ``chromium``): without them the machine has no root, no sudo and no chromium.
``PG_BIN`` and ``NGINX`` point at a fake PostgreSQL and nginx, ``FC_LIST`` at a fake fontconfig
``fc-list`` that finds a font for every language (present unless a test removes them).
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
REAL_TOOLS = ("bash", "sh", "env", "dirname", "cut", "sha256sum", "rm", "touch", "cat", "mkdir", "chmod")


def _write_exe(path: Path, text: str) -> None:
    path.write_text(text)
    path.chmod(0o755)


@pytest.fixture
def repo(tmp_path: Path) -> Path:
    """A copy of scripts/ and pyproject.toml with a complete fake .venv and a bare fake PATH."""
    r = tmp_path / "repo"
    (r / "scripts").mkdir(parents=True)
    for f in (ROOT / "scripts").glob("*.sh"):
        shutil.copy(f, r / "scripts")
    shutil.copy(ROOT / "pyproject.toml", r)
    venv_bin = r / ".venv" / "bin"
    venv_bin.mkdir(parents=True)
    log = r / "calls.log"
    _write_exe(venv_bin / "python", f"""#!/bin/sh
printf 'python' >> {log}; for a in "$@"; do printf ' [%s]' "$a" >> {log}; done; echo >> {log}
if [ "$2" = pip ]; then exit "${{FAKE_PIP_RC:-1}}"; fi
if [ "$2" = pytest ]; then echo "CHROMIUM=${{CHROMIUM:-}}" >> {log}; exit "${{FAKE_PYTEST_RC:-0}}"; fi
if [ "$2" = mypy ]; then echo "${{FAKE_MYPY_OUT:-Success: no issues found}}"; exit "${{FAKE_MYPY_RC:-0}}"; fi
if [ "$2" = mkdocs ]; then printf '%b\n' "${{FAKE_MKDOCS_OUT:-INFO    -  Documentation built}}" >&2; exit "${{FAKE_MKDOCS_RC:-0}}"; fi
exit 0
""")
    _write_exe(venv_bin / "lint-imports", f"""#!/bin/sh
printf 'lint-imports' >> {log}; for a in "$@"; do printf ' [%s]' "$a" >> {log}; done; echo >> {log}
echo "${{FAKE_LINT_OUT:-Contracts: 3 kept, 0 broken.}}"; exit "${{FAKE_LINT_RC:-0}}"
""")
    _write_exe(venv_bin / "tcp-pendant", f"#!/bin/sh\necho tcp-pendant \"$@\" >> {log}\n")
    _write_exe(venv_bin / "tcpcal", "#!/bin/sh\n")
    fake = tmp_path / "bin"
    fake.mkdir()
    for tool in REAL_TOOLS:
        real = shutil.which(tool)
        assert real is not None, tool
        os.symlink(real, fake / tool)
    _write_exe(fake / "id", "#!/bin/sh\necho \"${FAKE_UID:-1000}\"\n")
    # Debian's postgresql and nginx as the tests find them (PG_BIN, NGINX: run() points there)
    (tmp_path / "pg").mkdir()
    _write_exe(tmp_path / "pg" / "pg_ctl", "#!/bin/sh\n")
    _write_exe(tmp_path / "nginx", "#!/bin/sh\n")
    _write_exe(tmp_path / "fc-list", "#!/bin/sh\necho 'Noto Sans CJK JP'\n")     # a font for every :lang=
    return r


def sha(repo: Path) -> str:
    return hashlib.sha256((repo / "pyproject.toml").read_bytes()).hexdigest()


def run(repo: Path, script: str, *args: str, **env: str) -> subprocess.CompletedProcess[str]:
    base = {"PATH": str(repo.parent / "bin"), "HOME": str(repo.parent), "PG_BIN": str(repo.parent / "pg"),
            "NGINX": str(repo.parent / "nginx"), "FC_LIST": str(repo.parent / "fc-list")}
    return subprocess.run(["bash", str(repo / "scripts" / script), *args], env={**base, **env},
                          capture_output=True, text=True, timeout=60)


def calls(repo: Path) -> list[str]:
    log = repo / "calls.log"
    return log.read_text().splitlines() if log.exists() else []


def pip_calls(repo: Path) -> list[str]:
    return [c for c in calls(repo) if c.startswith("python [-m] [pip]")]


# ---------------------------------------------------------------- run-app.sh
def test_run_app_starts_offline_when_the_stamp_matches(repo: Path) -> None:
    """``run-app.sh --help`` starts offline: pip runs only when pyproject.toml changed."""
    (repo / ".venv" / f".installed-app-{sha(repo)}").touch()
    p = run(repo, "run-app.sh", "--help")            # pip would fail (FAKE_PIP_RC=1)
    assert p.returncode == 0, p.stderr
    assert pip_calls(repo) == []
    assert calls(repo) == ["tcp-pendant --help"]


def test_run_app_installs_when_pyproject_changed(repo: Path) -> None:
    old = repo / ".venv" / ".installed-app-0000"     # an install of another pyproject.toml
    old.touch()
    p = run(repo, "run-app.sh", "--port", "8090", FAKE_PIP_RC="0")
    assert p.returncode == 0, p.stderr
    assert pip_calls(repo) == ["python [-m] [pip] [install] [-q] [--disable-pip-version-check] [-e] [.]"]
    assert not old.exists() and (repo / ".venv" / f".installed-app-{sha(repo)}").exists()
    assert calls(repo)[-1] == "tcp-pendant --port 8090"
    assert run(repo, "run-app.sh").returncode == 0 and len(pip_calls(repo)) == 1   # now stamped


def test_run_app_offline_without_stamp_warns_and_uses_the_existing_venv(repo: Path) -> None:
    p = run(repo, "run-app.sh", "--help")
    assert p.returncode == 0, p.stderr
    assert len(pip_calls(repo)) == 1 and calls(repo)[-1] == "tcp-pendant --help"
    assert "WARNING" in p.stderr and "using the existing .venv" in p.stderr
    assert not list((repo / ".venv").glob(".installed-*"))   # retried at the next start


def test_run_app_without_a_venv_and_no_index_fails_with_a_hint(repo: Path) -> None:
    (repo / ".venv" / "bin" / "tcp-pendant").unlink()
    p = run(repo, "run-app.sh", "--help")
    assert p.returncode != 0
    assert "'pip install -e .' failed" in p.stderr and "package index" in p.stderr
    assert not any(c.startswith("tcp-pendant") for c in calls(repo))


def _fake_interpreter(repo: Path, name: str, minor: int) -> None:
    """A ``name`` on PATH that is Python 3.``minor``: it answers the scripts' version check and
    logs ``-m venv``."""
    log = repo / "calls.log"
    _write_exe(repo.parent / "bin" / name, f"""#!/bin/sh
if [ "$1" = -c ]; then [ {minor} -ge 11 ]; exit $?; fi
echo "{name} $*" >> {log}
""")


def test_a_new_venv_is_made_with_the_first_python_of_at_least_3_11(repo: Path) -> None:
    shutil.rmtree(repo / ".venv")
    _fake_interpreter(repo, "python3", 10)                   # Ubuntu 22.04's python3
    _fake_interpreter(repo, "python3.11", 11)                # and its python3.11 package
    run(repo, "run-app.sh", "--help")
    assert "python3.11 -m venv .venv" in calls(repo)
    assert not any(c.startswith("python3 ") for c in calls(repo))


def test_without_python_3_11_the_scripts_say_what_to_install(repo: Path) -> None:
    shutil.rmtree(repo / ".venv")
    _fake_interpreter(repo, "python3", 10)
    p = run(repo, "run-tests.sh")
    assert p.returncode != 0
    assert "needs Python 3.11 or newer" in p.stderr and "apt install python3.11 python3.11-venv" in p.stderr
    assert "PYTHON=" in p.stderr and calls(repo) == []                  # nothing was made or run
    p = run(repo, "run-app.sh", PYTHON="python3")                       # a PYTHON that is too old
    assert p.returncode != 0 and "python3 is older or missing" in p.stderr


def test_the_test_stamp_covers_the_app_but_not_the_reverse(repo: Path) -> None:
    (repo / ".venv" / f".installed-test-{sha(repo)}").touch()
    assert run(repo, "run-app.sh").returncode == 0 and pip_calls(repo) == []
    (repo / ".venv" / f".installed-test-{sha(repo)}").unlink()
    (repo / ".venv" / f".installed-app-{sha(repo)}").touch()
    (repo.parent / "bin" / "chromium").symlink_to(shutil.which("true") or "/bin/true")
    assert run(repo, "run-tests.sh", FAKE_PIP_RC="0").returncode == 0
    assert pip_calls(repo) == ["python [-m] [pip] [install] [-q] [--disable-pip-version-check] [-e] [.[test]]"]
    assert (repo / ".venv" / f".installed-test-{sha(repo)}").exists()


# ---------------------------------------------------------------- run-tests.sh
def pytest_calls(repo: Path) -> list[str]:
    return [c for c in calls(repo) if c.startswith("python [-m] [pytest]")]


@pytest.fixture
def stamped(repo: Path) -> Path:
    (repo / ".venv" / f".installed-test-{sha(repo)}").touch()
    return repo


def test_run_tests_without_root_sudo_or_chromium_runs_the_rest_and_says_so(stamped: Path) -> None:
    """Without root, sudo or chromium the script runs the rest of the suite (it must not stop at
    ``sudo: command not found`` before pytest) and says that the browser tests did not run."""
    p = run(stamped, "run-tests.sh", "-q", "tests/tcpcal")
    assert p.returncode == 0, p.stderr
    assert pytest_calls(stamped) == ["python [-m] [pytest] [-m] [not browser] [-q] [tests/tcpcal]"]
    lines = p.stderr.strip().splitlines()
    assert "apt-get install chromium" in lines[0] and "neither be root nor use sudo" in lines[0]
    assert lines[-1].startswith("!!!") and "BROWSER TESTS DID NOT RUN" in lines[-1]
    assert "command not found" not in p.stderr


def test_run_tests_without_chromium_keeps_a_marker_the_caller_gave(stamped: Path) -> None:
    p = run(stamped, "run-tests.sh", "-m", "slow", "-x", FAKE_PYTEST_RC="1")
    assert p.returncode == 1                             # pytest's own status
    assert pytest_calls(stamped) == ["python [-m] [pytest] [-m] [not browser and (slow)] [-x]"]
    assert "BROWSER TESTS DID NOT RUN" in p.stderr.strip().splitlines()[-1]


def test_run_tests_under_ci_fails_when_chromium_is_missing(stamped: Path) -> None:
    p = run(stamped, "run-tests.sh", CI="true")
    assert p.returncode == 1
    assert pytest_calls(stamped) == [                    # the other tests still ran
        "python [-m] [pytest] [-n] [2] [--durations=25] [-m] [not browser and not serial]",
        "python [-m] [pytest] [--durations=25] [-m] [not browser and serial]"]
    assert "CI=true" in p.stderr and "BROWSER TESTS DID NOT RUN" in p.stderr


def test_run_tests_as_root_installs_chromium_with_apt(stamped: Path) -> None:
    """CI (root): apt-get installs chromium, then the whole suite runs with it."""
    fake = stamped.parent / "bin"
    _write_exe(fake / "apt-get", f"""#!/bin/sh
echo "apt-get $*" >> {stamped / 'calls.log'}
[ "$1" = install ] && printf '#!/bin/sh\\n' > {fake / 'chromium'} && chmod 755 {fake / 'chromium'}
exit 0
""")
    p = run(stamped, "run-tests.sh", "-q", FAKE_UID="0", CI="true")
    assert p.returncode == 0, p.stderr
    assert "apt-get install -y -q chromium" in calls(stamped)
    assert pytest_calls(stamped) == ["python [-m] [pytest] [-q]"]
    assert f"CHROMIUM={fake / 'chromium'}" in calls(stamped)
    assert "DID NOT RUN" not in p.stderr


def test_run_tests_as_root_installs_postgresql_and_nginx_with_apt(stamped: Path) -> None:
    """Without Debian's postgresql and nginx (the PostgreSQL gradebook and front-end tests), apt-get
    installs both in one call, as it does chromium."""
    fake = stamped.parent / "bin"
    (stamped.parent / "pg" / "pg_ctl").unlink()
    (stamped.parent / "nginx").unlink()
    (fake / "chromium").symlink_to(shutil.which("true") or "/bin/true")
    _write_exe(fake / "apt-get", f"""#!/bin/sh
echo "apt-get $*" >> {stamped / 'calls.log'}
if [ "$1" = install ]; then
  printf '#!/bin/sh\\n' > {stamped.parent / 'pg' / 'pg_ctl'}; printf '#!/bin/sh\\n' > {stamped.parent / 'nginx'}
  chmod 755 {stamped.parent / 'pg' / 'pg_ctl'} {stamped.parent / 'nginx'}
fi
exit 0
""")
    p = run(stamped, "run-tests.sh", "-q", FAKE_UID="0", CI="true")
    assert p.returncode == 0, p.stderr
    assert "apt-get install -y -q postgresql nginx" in calls(stamped)
    assert pytest_calls(stamped) == ["python [-m] [pytest] [-q]"]
    assert p.stderr == ""


def test_run_tests_that_cannot_install_postgresql_says_its_tests_will_not_run(stamped: Path) -> None:
    (stamped.parent / "pg" / "pg_ctl").unlink()
    (stamped.parent / "bin" / "chromium").symlink_to(shutil.which("true") or "/bin/true")
    p = run(stamped, "run-tests.sh", "-q")                   # no root, no sudo
    assert p.returncode == 0
    assert pytest_calls(stamped) == ["python [-m] [pytest] [-q]"]      # the rest still runs
    (line,) = p.stderr.strip().splitlines()
    assert line.startswith("!!!") and "could not install postgresql" in line and "neither root nor sudo" in line
    assert "PostgreSQL gradebook and nginx front-end tests will not run" in line


def test_run_tests_with_chromium_runs_everything(stamped: Path) -> None:
    (stamped.parent / "bin" / "chromium").symlink_to(shutil.which("true") or "/bin/true")
    p = run(stamped, "run-tests.sh", "-m", "browser")
    assert p.returncode == 0, p.stderr
    assert pytest_calls(stamped) == ["python [-m] [pytest] [-m] [browser]"]
    assert p.stderr == ""


def test_run_tests_without_arguments_runs_the_parallel_tests_then_the_serial_ones(stamped: Path) -> None:
    """The README's command: the tests not marked serial on 2 xdist workers, then the serial ones
    (tests/conftest.py marks them) in one process; a failing run fails the command, and the
    serial tests still run after a failure of the parallel ones."""
    (stamped.parent / "bin" / "chromium").symlink_to(shutil.which("true") or "/bin/true")
    both = ["python [-m] [pytest] [-n] [2] [--durations=25] [-m] [not serial]", "python [-m] [pytest] [--durations=25] [-m] [serial]"]
    p = run(stamped, "run-tests.sh")
    assert p.returncode == 0, p.stderr
    assert pytest_calls(stamped) == both
    assert p.stderr == ""
    (stamped / "calls.log").unlink()
    p = run(stamped, "run-tests.sh", FAKE_PYTEST_RC="1")
    assert p.returncode == 1
    assert pytest_calls(stamped) == both
    assert "pytest exited 1 (the tests on 2 workers) and 1 (the serial tests)" in p.stderr


def test_run_tests_quick_runs_both_parts_without_the_slow_tests(stamped: Path) -> None:
    """``--quick``, the lane to run while working: the same checks (mypy, the layers, the site),
    then the same two runs as the README's command without the tests marked slow; arguments
    after it go to both runs."""
    (stamped.parent / "bin" / "chromium").symlink_to(shutil.which("true") or "/bin/true")
    p = run(stamped, "run-tests.sh", "--quick")
    assert p.returncode == 0, p.stderr
    checks = [c for c in calls(stamped) if c.startswith(("python", "lint-imports"))]
    assert checks[:2] == ["python [-m] [mypy]", "lint-imports [--no-logo]"]
    assert checks[2].startswith("python [-m] [mkdocs] [build] [--strict]")
    assert checks[3:] == [
        "python [-m] [pytest] [-n] [2] [--durations=25] [-m] [not slow and not serial]",
        "python [-m] [pytest] [--durations=25] [-m] [not slow and serial]"]
    assert p.stderr == ""
    (stamped / "calls.log").unlink()
    p = run(stamped, "run-tests.sh", "--quick", "-x", FAKE_PYTEST_RC="1")
    assert p.returncode == 1
    assert pytest_calls(stamped) == [
        "python [-m] [pytest] [-n] [2] [--durations=25] [-m] [not slow and not serial] [-x]",
        "python [-m] [pytest] [--durations=25] [-m] [not slow and serial] [-x]"]
    assert "pytest exited 1 (the tests on 2 workers) and 1 (the serial tests)" in p.stderr


def test_run_tests_quick_without_chromium_leaves_out_the_browser_tests_too(stamped: Path) -> None:
    p = run(stamped, "run-tests.sh", "--quick")
    assert p.returncode == 0
    assert pytest_calls(stamped) == [
        "python [-m] [pytest] [-n] [2] [--durations=25] [-m] [not browser and not slow and not serial]",
        "python [-m] [pytest] [--durations=25] [-m] [not browser and not slow and serial]"]
    assert "BROWSER TESTS DID NOT RUN" in p.stderr.strip().splitlines()[-1]


def test_run_tests_with_a_bad_chromium_override_says_so(stamped: Path) -> None:
    p = run(stamped, "run-tests.sh", CHROMIUM="/nowhere/chromium")
    assert p.returncode == 0
    assert "CHROMIUM=/nowhere/chromium is not an executable" in p.stderr
    assert pytest_calls(stamped) == ["python [-m] [pytest] [-n] [2] [--durations=25] [-m] [not browser and not serial]",
                                     "python [-m] [pytest] [--durations=25] [-m] [not browser and serial]"]


# ---------------------------------------------------------------- the type check
def test_run_tests_type_checks_lints_the_layers_and_builds_the_site_before_the_tests(stamped: Path) -> None:
    """mypy, then lint-imports, then ``mkdocs build --strict`` into a scratch folder (quiet when it
    builds), then pytest."""
    (stamped.parent / "bin" / "chromium").symlink_to(shutil.which("true") or "/bin/true")
    p = run(stamped, "run-tests.sh", "-q", TMPDIR=str(stamped.parent))
    assert p.returncode == 0, p.stderr
    checks = [c for c in calls(stamped) if c.startswith(("python", "lint-imports"))]
    assert len(checks) == 4, checks
    assert checks[0] == "python [-m] [mypy]"
    assert checks[1] == "lint-imports [--no-logo]"
    assert checks[2].startswith("python [-m] [mkdocs] [build] [--strict] [--site-dir] "
                                f"[{stamped.parent}/tcp-pendant-site-")
    assert checks[3] == "python [-m] [pytest] [-q]"
    assert "Documentation built" not in p.stdout + p.stderr
    assert not list(stamped.parent.glob("tcp-pendant-site-*"))      # the scratch site is removed


def test_run_tests_fails_when_the_site_does_not_build_and_runs_no_test(stamped: Path) -> None:
    """A broken link (or a docstring reference that does not resolve) fails ``mkdocs build
    --strict``: its warnings are shown without the INFO lines, then one line, exit 1, no pytest."""
    (stamped.parent / "bin" / "chromium").symlink_to(shutil.which("true") or "/bin/true")
    warning = "WARNING -  Doc file 'cli.md' contains a link 'nowhere.md', but the target is not found among documentation files."
    p = run(stamped, "run-tests.sh", "-q", FAKE_MKDOCS_RC="1", TMPDIR=str(stamped.parent),
            FAKE_MKDOCS_OUT=f"INFO    -  Building documentation\\n{warning}\\nAborted with 1 warnings in strict mode!")
    assert p.returncode == 1
    assert warning in p.stderr
    assert "INFO" not in p.stderr
    assert p.stderr.strip().splitlines()[-1] == (
        "run-tests.sh: the documentation site does not build (mkdocs build --strict: the warnings above); no test ran.")
    assert pytest_calls(stamped) == []


def test_run_tests_fails_on_a_type_error_with_mypy_s_output_and_runs_no_test(stamped: Path) -> None:
    (stamped.parent / "bin" / "chromium").symlink_to(shutil.which("true") or "/bin/true")
    error = 'app/tcp_pendant/x.py:3: error: Incompatible return value type (got "str", expected "int")'
    p = run(stamped, "run-tests.sh", "-q", FAKE_MYPY_RC="1", FAKE_MYPY_OUT=error, CI="true")
    assert p.returncode == 1
    assert error in p.stdout
    assert "mypy found the type errors listed above; no test ran" in p.stderr
    assert pytest_calls(stamped) == []


def test_run_tests_fails_on_a_broken_layer_with_lint_imports_output_and_runs_no_test(stamped: Path) -> None:
    (stamped.parent / "bin" / "chromium").symlink_to(shutil.which("true") or "/bin/true")
    broken = "tcp_pendant.controller is not allowed to import tcp_pendant.views:"
    p = run(stamped, "run-tests.sh", "-q", FAKE_LINT_RC="1", FAKE_LINT_OUT=broken, CI="true")
    assert p.returncode == 1
    assert broken in p.stdout
    assert "lint-imports found the imports listed above that break a layer contract; no test ran" in p.stderr
    assert pytest_calls(stamped) == []


# The layers of pyproject.toml's [tool.importlinter], bottom first ("|": siblings that import
# none of each other); lint-imports also wants every module of tcp_pendant in one of them.
APP_LAYERS = (("events", "job_pool", "json_shapes", "message_rate", "refusal_notices", "text_escape", "translation"),
              ("controller",), ("pendant",), ("wizards",), ("calibrate",), ("session_scenario", "session_views"),
              ("session_tools", "session_loop"), ("session_wizard", "session_motion"), ("session",),
              ("classroom",), ("views",), ("serve",), ("__main__",))


def _lint_imports(tree: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": f"{tree / 'src'}{os.pathsep}{tree / 'app'}"}
    return subprocess.run([str(Path(sys.executable).parent / "lint-imports"), "--no-logo", "--no-cache"],
                          cwd=tree, env=env, capture_output=True, text=True, timeout=300)


def test_the_layer_contracts_refuse_an_upward_import_viser_below_the_views_and_a_loose_module(tmp_path: Path) -> None:
    """The real lint-imports with the repository's ``[tool.importlinter]`` on a tree of empty
    layers: kept; an import of a higher layer (even inside a function), viser imported by the
    session (even for types only), tcpcal importing the app, or a module in no layer each break
    a contract, and lint-imports exits 1."""
    shutil.copy(ROOT / "pyproject.toml", tmp_path)
    (tmp_path / "src" / "tcpcal").mkdir(parents=True)
    (tmp_path / "src" / "tcpcal" / "__init__.py").write_text("")
    app = tmp_path / "app" / "tcp_pendant"
    app.mkdir(parents=True)
    (app / "__init__.py").write_text("")
    for layer in APP_LAYERS:
        for name in layer:
            (app / f"{name}.py").write_text("")
    (app / "__main__.py").write_text("import tcp_pendant.serve\n")
    (app / "serve.py").write_text("import viser\nimport tcp_pendant.views\nimport tcp_pendant.controller\n")
    (app / "views.py").write_text("import viser\nimport tcp_pendant.classroom\n")
    (app / "calibrate.py").write_text("import tcp_pendant.wizards\nimport tcp_pendant.text_escape\n")
    kept = _lint_imports(tmp_path)
    assert kept.returncode == 0, kept.stdout + kept.stderr
    assert "3 kept, 0 broken" in kept.stdout

    breaks = {
        app / "controller.py": ("def f():\n    import tcp_pendant.views\n",
                                "tcp_pendant.controller is not allowed to import tcp_pendant.views"),
        app / "session.py": ("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import viser\n",
                             "tcp_pendant.session is not allowed to import viser"),
        app / "events.py": ("import tcp_pendant.job_pool\n",
                            "tcp_pendant.events is not allowed to import tcp_pendant.job_pool"),
        tmp_path / "src" / "tcpcal" / "__init__.py": ("import tcp_pendant.controller\n",
                                                      "tcpcal is not allowed to import tcp_pendant"),
        app / "loose.py": ("", "tcp_pendant.loose"),
    }
    for path, (text, said) in breaks.items():
        before = path.read_text() if path.exists() else None
        path.write_text(text)
        broken = _lint_imports(tmp_path)
        assert broken.returncode == 1, (path, broken.stdout + broken.stderr)
        assert said in broken.stdout, (path, broken.stdout)
        if before is None:
            path.unlink()
        else:
            path.write_text(before)


def test_the_mypy_configuration_is_strict_on_tcpcal_and_typed_on_the_app(tmp_path: Path) -> None:
    """The real mypy with the repository's ``[tool.mypy]`` on a two-module tree: returning
    ``Any`` is an error in tcpcal only (strict there, not leaking to the app); an unannotated
    function, a generic without its type arguments and a wrong return type are errors in the app
    (``disallow_untyped_defs``, ``disallow_any_generics``); mypy exits 1, which fails run-tests.sh."""
    shutil.copy(ROOT / "pyproject.toml", tmp_path)
    returns_any = "import json\n\n\ndef parsed(text: str) -> dict[str, int]:\n    return json.loads(text)\n"
    (tmp_path / "src" / "tcpcal").mkdir(parents=True)
    (tmp_path / "src" / "tcpcal" / "__init__.py").write_text(returns_any)
    (tmp_path / "app" / "tcp_pendant").mkdir(parents=True)
    (tmp_path / "app" / "tcp_pendant" / "__init__.py").write_text(
        returns_any + "\n\ndef scaled(x):\n    return 2 * x\n"
        "\n\ndef first(d: dict) -> int:\n    return 1\n"
        "\n\ndef length_mm() -> float:\n    return \"12.5 mm\"\n")
    p = subprocess.run([sys.executable, "-m", "mypy", "--cache-dir", str(tmp_path / "cache")],
                       cwd=tmp_path, capture_output=True, text=True, timeout=300)
    errors = sorted(line for line in p.stdout.splitlines() if ": error: " in line)
    assert p.returncode == 1, p.stdout + p.stderr
    assert len(errors) == 4, p.stdout
    assert errors[0].startswith("app/tcp_pendant/__init__.py:12: error: Missing type arguments for generic type")
    assert errors[1].startswith("app/tcp_pendant/__init__.py:17: error: Incompatible return value type")
    assert errors[2].startswith("app/tcp_pendant/__init__.py:8: error: Function is missing a type annotation")
    assert errors[3].startswith("src/tcpcal/__init__.py:5: error: Returning Any from function declared to return")


def test_run_tests_as_root_installs_the_fonts_of_the_languages_with_apt(stamped: Path) -> None:
    """Without fonts for Cyrillic, Devanagari and CJK (fc-list finds none), apt-get installs
    Debian's font packages, as it does chromium."""
    fc_list = stamped.parent / "fc-list"
    _write_exe(fc_list, "#!/bin/sh\n")                                   # no font for any language
    (stamped.parent / "bin" / "chromium").symlink_to(shutil.which("true") or "/bin/true")
    _write_exe(stamped.parent / "bin" / "apt-get", f"""#!/bin/sh
echo "apt-get $*" >> {stamped / 'calls.log'}
[ "$1" = install ] && printf '#!/bin/sh\\necho Lohit\\n' > {fc_list}
exit 0
""")
    p = run(stamped, "run-tests.sh", "-q", FAKE_UID="0", CI="true")
    assert p.returncode == 0, p.stderr
    assert "apt-get install -y -q fontconfig fonts-dejavu-core fonts-lohit-deva fonts-noto-cjk" in calls(stamped)
    assert pytest_calls(stamped) == ["python [-m] [pytest] [-q]"]
    assert p.stderr == ""


def test_run_tests_without_the_fonts_says_so_and_fails_under_ci(stamped: Path) -> None:
    (stamped.parent / "fc-list").unlink()                                 # no fontconfig, no root, no sudo
    (stamped.parent / "bin" / "chromium").symlink_to(shutil.which("true") or "/bin/true")
    p = run(stamped, "run-tests.sh", "-q")
    assert p.returncode == 0                                             # the tests run; the font test fails them
    assert pytest_calls(stamped) == ["python [-m] [pytest] [-q]"]
    (line,) = p.stderr.strip().splitlines()
    assert line.startswith("!!!") and "no font for ru hi zh-cn ja" in line and "fonts-noto-cjk" in line
    p = run(stamped, "run-tests.sh", "-q", CI="true")
    assert p.returncode == 1 and "CI=true" in p.stderr and "fonts are missing" in p.stderr
    assert pytest_calls(stamped) == ["python [-m] [pytest] [-q]"]         # no second pytest run
