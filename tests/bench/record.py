"""Run a benchmark and keep what it printed as the figures of the benchmark pages.

    .venv/bin/python tests/bench/record.py BENCH [BENCH's options ...]
    .venv/bin/python tests/bench/record.py --out DIR BENCH [...]

``BENCH`` is a benchmark of this directory (``bench_solver`` or ``bench_solver.py``) or the path
of a script. It runs with this Python, its output shown as it comes; when it ends with exit
status 0, its standard output is written to ``DIR/BENCH.md`` (default ``docs/benchmarks/``)
under a line that says when (UTC), on what machine (CPU model, cores, memory, the load average
before and after the run), with which Python, at which commit and with which command it was
measured. viser's start banner (a box with the server's ephemeral address) and its "Server
stopped" line are left out: they are not figures and change with every run.
``docs/benchmarks.md`` includes these pages (``--8<--``, pymdownx.snippets), so the
site shows the figures exactly as the bench printed them. A failing run writes nothing and
returns the bench's exit status.

``scripts/bench-pages.sh`` re-measures every page this way.
"""

from __future__ import annotations

import argparse
import os
import platform
import shlex
import subprocess
import sys
from datetime import datetime, timezone
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
DEFAULT_OUT = ROOT / "docs" / "benchmarks"


def bench_script(name: str) -> Path:
    """The script of ``name``: a benchmark of tests/bench (with or without ``.py``) or a path."""
    path = Path(name)
    if path.suffix == ".py" and path.is_file():
        return path.resolve()
    candidate = HERE / (name if name.endswith(".py") else f"{name}.py")
    if not candidate.is_file():
        raise SystemExit(f"record.py: no benchmark {name!r} (looked for {candidate}); "
                         f"name one of tests/bench/bench_*.py or give a script's path.")
    return candidate


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _memory_gib() -> str:
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal:"):
                return f"{int(line.split()[1]) / 2**20:.1f} GiB"
    except (OSError, ValueError, IndexError):
        pass
    return "memory unknown"


def _load() -> str:
    try:
        return "/".join(f"{x:.1f}" for x in os.getloadavg())
    except OSError:
        return "unknown"


def _commit() -> str:
    try:
        out = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                             capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return out.stdout.strip() or "unknown"


def machine_line(load_before: str, load_after: str) -> str:
    """The machine a run measured: CPU, cores, memory, system, Python, the 1/5/15-minute load
    average before and after."""
    return (f"{_cpu_model()}, {os.cpu_count()} cores, {_memory_gib()}, {platform.system()} "
            f"{platform.release()}, Python {platform.python_version()}; load average (1/5/15 min) "
            f"{load_before} before, {load_after} after")


_VISER_BANNER = ("╭", "│", "╰", "(viser) ")


def figures(lines: list[str]) -> str:
    """What a bench printed, without viser's start banner and stop line."""
    return "".join(line for line in lines if not line.lstrip().startswith(_VISER_BANNER))


def page(name: str, command: str, output: str, *, when: datetime, machine: str, commit: str) -> str:
    """The markdown of one recorded run: the heading line and the output as printed."""
    fence = "```"
    while fence in output:
        fence += "`"
    return (f"*Measured {when:%Y-%m-%d %H:%M} UTC* on {machine}, at commit `{commit}`, with "
            f"`{command}`:\n\n{fence}text\n{output.rstrip()}\n{fence}\n")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT, help="where the page goes (default docs/benchmarks)")
    ap.add_argument("bench", help="bench_x (tests/bench/bench_x.py) or a script's path")
    ap.add_argument("args", nargs=argparse.REMAINDER, help="the bench's own options")
    opts = ap.parse_args(argv)
    script = bench_script(opts.bench)
    command = shlex.join(["python", str(script.relative_to(ROOT)) if script.is_relative_to(ROOT) else str(script),
                          *opts.args])
    when, load_before = datetime.now(timezone.utc), _load()
    proc = subprocess.Popen([sys.executable, str(script), *opts.args], stdout=subprocess.PIPE, text=True, cwd=ROOT)
    assert proc.stdout is not None
    lines = []
    for line in proc.stdout:                  # shown as it comes: a long bench is not silent
        sys.stdout.write(line)
        sys.stdout.flush()
        lines.append(line)
    status = proc.wait()
    if status != 0:
        print(f"record.py: {script.name} exited with status {status}: no page written.", file=sys.stderr)
        return status
    opts.out.mkdir(parents=True, exist_ok=True)
    target = opts.out / f"{script.stem}.md"
    target.write_text(page(script.stem, command, figures(lines), when=when,
                           machine=machine_line(load_before, _load()), commit=_commit()))
    print(f"record.py: wrote {target}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
