"""``tests/bench/record.py``: a bench's printed figures become its page of the benchmark site, with
when, where and how they were measured; a failing bench writes nothing. And every page that
``docs/benchmarks.md`` includes exists and states its date and command."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RECORD = ROOT / "tests" / "bench" / "record.py"


def _record(tmp_path: Path, script: str, *args: str) -> subprocess.CompletedProcess[str]:
    bench = tmp_path / "bench_fake.py"
    bench.write_text(script)
    return subprocess.run([sys.executable, str(RECORD), "--out", str(tmp_path / "pages"), str(bench), *args],
                          capture_output=True, text=True, timeout=60)


def test_a_bench_run_becomes_its_page(tmp_path: Path) -> None:
    script = (
        "import sys\n"
        "print('╭──── viser ────╮')\n"
        "print('│  HTTP  │ http://127.0.0.1:40123 │')\n"
        "print('╰───────────────╯')\n"
        "print('(viser) Server stopped')\n"
        "print('solve 12.5 us   ratio 1.07 ' + ' '.join(sys.argv[1:]))\n"
    )
    done = _record(tmp_path, script, "--rounds", "3")
    assert done.returncode == 0, done.stderr
    assert "solve 12.5 us" in done.stdout                      # shown while it runs
    page = (tmp_path / "pages" / "bench_fake.md").read_text()
    head, body = page.split("\n", 1)
    assert re.match(r"\*Measured \d{4}-\d\d-\d\d \d\d:\d\d UTC\* on .+, \d+ cores, .+ GiB", head)
    assert "load average (1/5/15 min)" in head and "bench_fake.py --rounds 3`" in head
    fenced = body.strip().split("\n")
    assert fenced[0] == "```text" and fenced[-1] == "```"
    assert fenced[1:-1] == ["solve 12.5 us   ratio 1.07 --rounds 3"]   # viser's banner left out


def test_a_failing_bench_writes_no_page(tmp_path: Path) -> None:
    done = _record(tmp_path, "print('half a table')\nraise SystemExit(3)\n")
    assert done.returncode == 3
    assert "no page written" in done.stderr
    assert not (tmp_path / "pages" / "bench_fake.md").exists()


def test_an_unknown_bench_is_named() -> None:
    done = subprocess.run([sys.executable, str(RECORD), "bench_nothing"], capture_output=True, text=True, timeout=60)
    assert done.returncode != 0
    assert "no benchmark 'bench_nothing'" in done.stderr


def test_every_included_page_is_recorded() -> None:
    text = (ROOT / "docs" / "benchmarks.md").read_text()
    included = re.findall(r'^--8<-- "benchmarks/(\w+)\.md"$', text, flags=re.M)
    assert included, "docs/benchmarks.md includes no recorded page"
    pages = ROOT / "scripts" / "bench-pages.sh"
    for name in included:
        page = (ROOT / "docs" / "benchmarks" / f"{name}.md").read_text()
        assert page.startswith("*Measured ") and f"tests/bench/{name}.py" in page.split("\n", 1)[0]
        assert f"[{name}]=" in pages.read_text()                  # the command regenerates it
