"""A class on one machine: press-to-readout latency of K trainees against ``tcp-pendant --workers N``.

What it measures (printed too). For each class size K (default 1, 10, 30, 60, 100) the bench
starts a real server, ``python -m tcp_pendant --class --workers N`` (default 2: one process per
core, one port, SO_REUSEPORT; a gradebook and a tool library in a temporary folder), and K
headless clients (tests/support/async_clients.py: real websockets speaking viser's protocol, all of
a client process's clients on one asyncio loop, ``--client-procs`` processes, default 2). Each
client is a trainee: it joins the class under its own name through the welcome window, picks
the 0.1 mm increment and clicks "X +" 20 times a second (a browser's most) for ``--duration``
seconds (default 30), spread over the period. The latency of a press runs from the client's
click (written to its socket) to the arrival at its socket of the first TCP readout that shows it
(the kernel's receive stamp, SO_TIMESTAMPNS, on the machine's monotonic clock); a press not shown ``ANSWER_WAIT_S`` after the last one is unanswered
(dropped by the server's deadman, or never carried out). Printed per K: p50, p95, p99, max,
presses asked / answered / unanswered, steps/s achieved (shown by the readouts; all trainees,
and per trainee against the 20 asked), the CPU of each server process (cores, over the press
window) and of the load generator, and how many trainees each server process held (the
gradebook's presence, from 1.5 s into the presses until every trainee is present: the
connection balance at work).

The load generator runs on the same two cores as the server (its CPU is printed); a real
class's browsers run elsewhere. It runs at ``--client-nice`` (default 19, the lowest priority):
it takes the CPU the servers leave, as browsers on other machines take none of the server's,
instead of a fair share of its two cores. That cannot flatter the latency: a readout is
stamped when the kernel received it (the stamp of a read's last segment, so never early), a
press when the client wrote it, and a client that waits for a CPU sends a press late rather than
not at all (the presses asked are counted as sent; a burst of late presses is load the server
must serve). How late the clients sent their presses against their plan is printed
("sent late"): the load actually offered. ``--client-nice 0`` gives the clients a fair share.

RESULT: MET when, at the largest K, p99 < 100 ms, every press was answered and at least 95 % of
the steps asked were achieved; else NOT MET. Always printed, whatever the outcome.

    .venv/bin/python tests/bench/bench_class_load.py                        # 1 10 30 60 100, 30 s
    .venv/bin/python tests/bench/bench_class_load.py --counts 30 --duration 10 --workers 1
    .venv/bin/python tests/bench/bench_class_load.py --counts 10,30 --baseline   # and against --workers 1
    .venv/bin/python tests/bench/bench_class_load.py --counts 100 --client-nice 0   # clients at the servers' priority

``--baseline`` runs each K against ``--workers 1`` right after (the same machine in the same
minute: on a shared machine the ratio of steps/s achieved is the figure to trust).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

if __name__ == "__main__":                  # run as a script: tests/ on sys.path (support.*, bench.*)
    import _tests_on_path  # noqa: F401
from support.async_clients import PLUS, PRESS_LEAD_S, connect_all, latencies, percentile, run_presses

ROOT = Path(__file__).resolve().parents[2]

PRESS_HZ = 20.0
PRESS_MM = 0.1
ANSWER_WAIT_S = 3.0
P99_TARGET_MS = 100.0
ACHIEVED_SHARE = 0.95
TOKEN = "bench-class-load-token-0001"


def _cpu_s(pid: int) -> float:
    """User + system CPU seconds of process ``pid`` so far (Linux /proc)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _waited_s(pid: int) -> float:
    """Seconds the threads of process ``pid`` have spent runnable but not running (waiting for a
    CPU; Linux ``/proc/PID/task/TID/schedstat``, second field, ns), summed over its threads."""
    total = 0
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            total += int(Path(f"/proc/{pid}/task/{tid}/schedstat").read_text().split()[1])
        except (OSError, IndexError, ValueError):
            continue
    return total / 1e9


# ------------------------------------------------------------------ client process
async def _client_main(port: int, first: int, n: int, names: bool, nice: int) -> None:
    os.nice(nice)
    clients = await connect_all("127.0.0.1", port, n, names="Trainee" if names else None, first=first)
    await asyncio.sleep(1.0)                       # the joins and the increment are carried out
    print("ready", flush=True)
    loop = asyncio.get_running_loop()
    line = await loop.run_in_executor(None, sys.stdin.readline)
    start_at, seconds = (float(v) for v in line.split())
    await asyncio.sleep(max(0.0, start_at - time.monotonic()))
    pressing: dict[str, tuple[float, float]] = {}   # CPU seconds and time at the presses' start and end

    async def mark(name: str, at: float) -> None:
        await asyncio.sleep(max(0.0, at - time.monotonic()))
        t = os.times()
        pressing[name] = (t.user + t.system, time.monotonic())

    marks = [asyncio.create_task(mark("from", start_at + PRESS_LEAD_S)),
             asyncio.create_task(mark("to", start_at + PRESS_LEAD_S + seconds))]
    x0 = await run_presses(clients, PLUS, PRESS_HZ, seconds, ANSWER_WAIT_S)
    await asyncio.gather(*marks)
    figures = latencies(clients, x0, PRESS_MM)
    print(json.dumps({"latencies_ms": figures.latencies_ms, "asked": figures.asked, "answered": figures.answered,
                      "no_readout": sum(x is None for x in x0),
                      "late_ms": [v * 1e3 for c in clients for v in c.late_s],
                      "cores": (pressing["to"][0] - pressing["from"][0]) / (pressing["to"][1] - pressing["from"][1])}),
          flush=True)
    for c in clients:
        await c.close()


# ------------------------------------------------------------------ the bench
def _trainees_per_process(db: Path, pids: list[int]) -> list[int]:
    """How many of the class's connected trainees each server process holds, in the order of
    ``pids``, from the gradebook's presence (its holder names the process's pid)."""
    from tcp_pendant.classroom.gradebook import Gradebook

    book = Gradebook(db)
    try:
        holders = [int(holder.split(":")[-2]) for _, holder, _ in book.presence.present()]
    finally:
        book.close()
    return [holders.count(pid) for pid in pids]


def _start_server(tmp: Path, workers: int) -> tuple[subprocess.Popen[str], int, list[int]]:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT / "src"), str(ROOT / "app"),
                                                       os.environ.get("PYTHONPATH", "")]),
               TCP_PENDANT_TRAINER_TOKEN=TOKEN)
    cmd = [sys.executable, "-m", "tcp_pendant", "--port", "0", "--workers", str(workers), "--class-db",
           str(tmp / "class.sqlite3"), "--tool-library", str(tmp / "tools.json"), "--seed", "1"]
    server = subprocess.Popen(cmd, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, text=True)
    assert server.stdout is not None
    deadline = time.monotonic() + 240
    text = ""
    while time.monotonic() < deadline:
        line = server.stdout.readline()
        if not line:
            raise RuntimeError(f"the server exited before it was ready (code {server.wait()})")
        text += line
        if "Ctrl-C to stop" in line:
            break
    port_m = re.search(r"http://127\.0\.0\.1:(\d+)", text)
    if port_m is None:
        raise RuntimeError(f"no URL in the server's ready message:\n{text}")
    pids_m = re.search(r"\(pids ([\d, ]+)\)", text)
    pids = [int(p) for p in pids_m.group(1).split(",")] if pids_m else [server.pid]
    return server, int(port_m.group(1)), pids


def run_class(k: int, workers: int, seconds: float, client_procs: int, names: bool, nice: int) -> dict[str, Any]:
    """One class of ``k`` trainees for ``seconds`` (module docstring)."""
    with tempfile.TemporaryDirectory(prefix="bench_class_load_") as folder:
        server, port, pids = _start_server(Path(folder), workers)
        procs: list[subprocess.Popen[str]] = []
        try:
            sizes = [k // client_procs + (1 if i < k % client_procs else 0) for i in range(client_procs)]
            first = 0
            for n in sizes:
                if n == 0:
                    continue
                procs.append(subprocess.Popen(
                    [sys.executable, __file__, "--client", str(port), str(first), str(n), "1" if names else "0",
                     str(nice)],
                    stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True))
                first += n
            for p in procs:
                assert p.stdout is not None
                if p.stdout.readline().strip() != "ready":
                    raise RuntimeError("a client process did not connect its clients")
            start_at = time.monotonic() + 0.5
            for p in procs:
                assert p.stdin is not None
                p.stdin.write(f"{start_at} {seconds}\n")
                p.stdin.flush()
            # the servers' CPU over the presses only (not the wait for the last answers after them)
            press_from = start_at + PRESS_LEAD_S
            time.sleep(max(0.0, press_from - time.monotonic()))
            t0, cpu0, wait0 = time.monotonic(), [_cpu_s(pid) for pid in pids], [_waited_s(pid) for pid in pids]
            split: list[int] | None = None
            if names:                                 # each process's presence beats once a second:
                time.sleep(max(0.0, start_at + 1.5 - time.monotonic()))   # read from 1.5 s on, until
                while True:                                              # every trainee is present or
                    split = _trainees_per_process(Path(folder) / "class.sqlite3", pids)   # the presses end
                    if sum(split) >= k or time.monotonic() >= press_from + seconds:
                        break
                    time.sleep(0.2)
            time.sleep(max(0.0, press_from + seconds - time.monotonic()))
            t1, cpu1, wait1 = time.monotonic(), [_cpu_s(pid) for pid in pids], [_waited_s(pid) for pid in pids]
            cpu = [(c1 - c0) / (t1 - t0) for c0, c1 in zip(cpu0, cpu1)]
            waited = [(w1 - w0) / (t1 - t0) for w0, w1 in zip(wait0, wait1)]
            results = []
            for p in procs:
                assert p.stdout is not None
                results.append(json.loads(p.stdout.readline()))
        finally:
            for p in procs:
                try:
                    p.wait(30)
                except subprocess.TimeoutExpired:
                    p.kill()
                    p.wait()
            server.terminate()
            try:
                server.wait(60)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait()
    lat = sorted(v for r in results for v in r["latencies_ms"])
    asked = sum(r["asked"] for r in results)
    answered = sum(r["answered"] for r in results)
    late = sorted(v for r in results for v in r["late_ms"])
    return {"k": k, "p50": percentile(lat, 50), "p95": percentile(lat, 95), "p99": percentile(lat, 99),
            "max": lat[-1] if lat else float("nan"), "late_p50": percentile(late, 50),
            "late_p99": percentile(late, 99),
            "asked": asked, "answered": answered, "unanswered": asked - answered,
            "steps_s": answered / seconds, "asked_s": asked / seconds, "per_trainee": answered / seconds / k,
            "server_cpu": cpu, "server_waited": waited, "clients_cpu": sum(r["cores"] for r in results),
            "no_readout": sum(r["no_readout"] for r in results), "split": split}


def verdict(row: dict[str, Any]) -> bool:
    return bool(row["p99"] < P99_TARGET_MS and row["unanswered"] == 0
                and row["steps_s"] >= ACHIEVED_SHARE * row["asked_s"])


def main(argv: list[str] | None = None) -> int:
    args_in = sys.argv[1:] if argv is None else argv
    if args_in[:1] == ["--client"]:
        port, first, n, names, nice = (int(v) for v in args_in[1:6])
        asyncio.run(_client_main(port, first, n, bool(names), nice))
        return 0
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--counts", default="1,10,30,60,100", help="class sizes K, comma-separated")
    ap.add_argument("--workers", type=int, default=2, help="server processes (tcp-pendant --workers)")
    ap.add_argument("--duration", type=float, default=30.0, help="seconds of pressing per class size")
    ap.add_argument("--client-procs", type=int, default=2, help="processes the headless clients run in")
    ap.add_argument("--client-nice", type=int, default=19, choices=range(20), metavar="0..19",
                    help="the client processes' niceness (19: the lowest priority, 0: the servers' own)")
    ap.add_argument("--no-names", action="store_true", help="clients do not join the class (no recorder)")
    ap.add_argument("--baseline", action="store_true",
                    help="also run each K against --workers 1 right after (same machine, same minute) and "
                         "print the ratio of steps/s achieved")
    args = ap.parse_args(args_in)
    counts = [int(v) for v in args.counts.split(",") if v.strip()]
    load = os.getloadavg()
    print(f"bench_class_load: tcp-pendant --class --workers {args.workers}, K trainees each clicking X + "
          f"{PRESS_HZ:.0f}/s ({PRESS_MM} mm) for {args.duration:g} s; clients in {args.client_procs} processes "
          f"at nice {args.client_nice} on the same {os.cpu_count()} CPUs "
          f"(load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f} at start)")
    print(f"  {'K':>4} {'p50 ms':>8} {'p95 ms':>8} {'p99 ms':>8} {'max ms':>8} {'asked':>7} {'unansw.':>7} "
          f"{'steps/s':>8} {'per K':>6} {'ms/step':>7}  server CPU per process (cores)   clients CPU   "
          "server waiting for a CPU   trainees per process   sent late p50/p99 ms")
    rows = []

    def show(row: dict[str, Any], label: str) -> None:
        cpu = " ".join(f"{c:.2f}" for c in row["server_cpu"])
        ms_step = sum(row["server_cpu"]) / max(row["steps_s"], 1e-9) * 1e3
        print(f"  {label:>4} {row['p50']:8.1f} {row['p95']:8.1f} {row['p99']:8.1f} {row['max']:8.1f} {row['asked']:>7} "
              f"{row['unanswered']:>7} {row['steps_s']:8.1f} {row['per_trainee']:6.1f} {ms_step:7.2f}  {cpu:<31} "
              f"{row['clients_cpu']:<13.2f} " + f"{' '.join(f'{w:.2f}' for w in row['server_waited']):<26}"
              + (" " + "/".join(str(n) for n in row["split"]) if row["split"] is not None else " -").ljust(23)
              + f"{row['late_p50']:.1f}/{row['late_p99']:.1f}"
              + (f"  ({row['no_readout']} clients saw no readout)"
                                              if row["no_readout"] else ""), flush=True)

    for k in counts:
        row = run_class(k, args.workers, args.duration, min(args.client_procs, k), not args.no_names,
                        args.client_nice)
        rows.append(row)
        show(row, str(k))
        if args.baseline and args.workers != 1:
            base = run_class(k, 1, args.duration, min(args.client_procs, k), not args.no_names, args.client_nice)
            show(base, "w=1")
            print(f"       steps/s with --workers {args.workers} / with --workers 1: "
                  f"{row['steps_s'] / max(base['steps_s'], 1e-9):.2f}", flush=True)
    print("  (ms/step: the server processes' CPU per step achieved, all included - the jog, the views, viser's "
          f"sending, the deadman's drops; {os.cpu_count()} cores give at most {os.cpu_count()} / that steps per second "
          "when nothing else runs)")
    print("  (server waiting for a CPU: the share of the time each server process's threads were ready to run "
          "but had no CPU - other programs on the machine had it; a server that waits for a CPU falls behind "
          "and its deadman drops presses, whatever its own cost per step)")
    print("  (trainees per process: the connected trainees each server process held once all were present, "
          "from the gradebook's presence; - without names)")
    print("  (sent late: how long after its planned time each press was sent, the load generator's own "
          "delay; the latency runs from the actual send)")
    print("  (latency: a press is matched to the first readout that shows as many presses; in a row with "
          "unanswered presses the deadman dropped some, so later presses are matched to earlier sends: "
          "those percentiles are upper bounds; rows with none are exact)")
    last = rows[-1]
    ok = verdict(last)
    print(f"RESULT: {last['k']} trainees asked {last['asked_s'] / last['k']:.1f} presses/s each on {args.workers} "
          f"server process(es): achieved {last['per_trainee']:.1f} steps/s each, press to readout p50 "
          f"{last['p50']:.1f} ms, p95 {last['p95']:.1f} ms, p99 {last['p99']:.1f} ms, {last['unanswered']} of "
          f"{last['asked']} presses unanswered. Target: p99 < {P99_TARGET_MS:.0f} ms, every press answered, "
          f">= {ACHIEVED_SHARE:.0%} of the steps achieved: {'MET' if ok else 'NOT MET'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
