"""Every ``$ tcpcal ...`` example pasted in README.md and docs/cli.md prints what tcpcal prints.

The documents paste commands with their output (fenced blocks whose lines start with
``$ tcpcal``). Each block's commands run here, in document order, through ``tcpcal.cli.main``
in a scratch directory holding what the commands name: ``docs/examples/xyz4_poses.csv`` and
the files of the error examples (``tests/data/cli_errors/``: a NaN cell, three rows, an
unknown header, touches that all rotate about flange Z); ``missing.csv`` is absent on
purpose and ``my_tools.json`` is created by the commands themselves.

A pasted output must equal the real one line by line, with one allowance: numbers must agree
to 1e-9 (relative or absolute) rather than to the last printed digit, because the last digits
of full-precision JSON floats depend on the CPU's BLAS kernels. Outputs on stderr (the error
examples, exit status 2) are compared the same way.
"""

from __future__ import annotations

import math
import re
import shlex
import shutil
from pathlib import Path

import pytest

from tcpcal.cli import main

ROOT = Path(__file__).resolve().parents[2]
ERROR_FILES = ROOT / "tests" / "data" / "cli_errors"
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def console_examples(doc: Path) -> list[list[tuple[str, str]]]:
    """Fenced blocks with ``$ tcpcal`` lines: for each, the (command, expected output) pairs."""
    text = doc.read_text(encoding="utf-8")
    blocks = []
    for body in re.findall(r"^```[a-z]*\n(.*?)^```", text, flags=re.DOTALL | re.MULTILINE):
        if not re.search(r"^\$ tcpcal ", body, flags=re.MULTILINE):
            continue
        pairs: list[tuple[str, list[str]]] = []
        for line in body.splitlines():
            if line.startswith("$ "):
                pairs.append((line[2:], []))
            elif pairs:
                pairs[-1][1].append(line)
        blocks.append([(cmd, "\n".join(out)) for cmd, out in pairs])
    return blocks


def same_output(expected: str, actual: str) -> bool:
    """Equal text, numbers equal to 1e-9 (relative or absolute)."""
    if expected == actual:
        return True
    if NUMBER.sub("#", expected) != NUMBER.sub("#", actual):
        return False
    return all(math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-9)
               for a, b in zip(NUMBER.findall(expected), NUMBER.findall(actual)))


def scratch_dir(tmp_path: Path) -> Path:
    (tmp_path / "docs" / "examples").mkdir(parents=True)
    shutil.copy(ROOT / "docs" / "examples" / "xyz4_poses.csv", tmp_path / "docs" / "examples")
    for f in ERROR_FILES.glob("*.csv"):
        shutil.copy(f, tmp_path)
    return tmp_path


def check_document(doc: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str],
                   monkeypatch: pytest.MonkeyPatch) -> int:
    monkeypatch.chdir(scratch_dir(tmp_path))
    n = 0
    for block in console_examples(doc):
        for cmd, expected in block:
            argv = shlex.split(cmd)
            assert argv[0] == "tcpcal", cmd
            code = main(argv[1:])
            out, err = capsys.readouterr()
            actual = (out if code == 0 else err).rstrip("\n")
            assert code in (0, 2), (cmd, code, err)
            assert same_output(expected, actual), (
                f"{doc.name}: `{cmd}` pastes\n{expected}\nbut prints\n{actual}")
            n += 1
    return n


def test_readme_cli_example_is_real(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    assert check_document(ROOT / "README.md", tmp_path, capsys, monkeypatch) >= 1


def test_cli_md_examples_are_real(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                  monkeypatch: pytest.MonkeyPatch) -> None:
    # the solve example (report and JSON), tools, convert and the error examples
    assert check_document(ROOT / "docs" / "cli.md", tmp_path, capsys, monkeypatch) >= 15


def test_examples_write_only_into_the_scratch_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """The ``tcpcal tools`` example must not leave ``my_tools.json`` and its lock in the repo root.

    Run from the repository root, as a reader pasting the example would, the files land in the
    scratch folder the examples run in, never beside README.md."""
    monkeypatch.chdir(ROOT)
    before = sorted(p.name for p in ROOT.iterdir())
    check_document(ROOT / "docs" / "cli.md", tmp_path, capsys, monkeypatch)
    assert sorted(p.name for p in ROOT.iterdir()) == before
    assert (tmp_path / "my_tools.json").is_file()        # the example did write its library ...
    assert (tmp_path / "my_tools.json.lock").exists()    # ... and its lock, here


def test_gitignore_ignores_the_example_library() -> None:
    """A belt: files of the example run by hand in the repository are never committed."""
    import subprocess

    names = ["my_tools.json", "my_tools.json.lock", "docs/my_tools.json"]
    out = subprocess.run(["git", "check-ignore", "--no-index", *names], cwd=ROOT, capture_output=True, text=True)
    if out.returncode == 128:
        pytest.skip(f"not a git checkout: {out.stderr.strip()}")
    assert out.stdout.split() == names


def test_the_comparison_can_fail() -> None:
    assert same_output("TCP X 84.931", "TCP X 84.931")
    assert same_output('"x": 0.14101605264564931', '"x": 0.14101605264554454')
    assert not same_output("TCP X 84.931", "TCP X 84.932")
    assert not same_output("Outliers: none", "Outliers: 3")
    assert not same_output("a 1.0", "b 1.0")
