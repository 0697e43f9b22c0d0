"""``tcp-pendant grades``: print the class gradebook.

Usage::

    tcp-pendant grades [--class-db PATH|URL] [--csv] [--per-trainee] [--moodle [--moodle-absent 0|empty]]

One row per calibration, finished or still in progress (oldest first): trainee, method, tool,
touches (hand / auto), overwritten touches, crashes, duration, result figures, error against
the true TOOL frame, the grade and the status. Without ``--csv`` a table for the terminal; with
``--csv`` the columns of :data:`tcp_pendant.classroom.grades_csv.CSV_COLUMNS`
(docs/pendant-cli.md, "tcp-pendant grades"). ``--per-trainee``: one row per trainee
(``classroom.lms``: attempts, best and last grade); ``--moodle``: that as the CSV Moodle's
gradebook imports, with ``--moodle-absent`` the grade of a trainee who finished no calibration
(``empty``, the default, or ``0``). Every trainee who joined is in every output, one who has no
calibration with an empty grade and the reason ("joined, no calibration finished"). The
gradebook is read where
the server writes it (``--class-db``, default ``user_data_dir("tcp-pendant")/class.sqlite3``,
or the ``postgresql://`` URL of the class's PostgreSQL database); it may be read while the
servers run. A URL is printed with its password masked.

Exit codes: 0 printed (also when no calibration is finished yet); 2 bad options, or the file
is missing, not a gradebook, damaged or from a newer TCP Pendant, or the PostgreSQL server
cannot be reached (one line on stderr; the file or database is left as it is).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from tcp_pendant.classroom.grade_rows import NO_RESULT_REASON, Attendee, GradeRow
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.gradebook_db import class_db_target
from tcp_pendant.classroom.gradebook_open import default_gradebook_path
from tcp_pendant.classroom.gradebook_store import GradebookError
from tcp_pendant.classroom.grades_csv import to_csv
from tcp_pendant.classroom.lms import MOODLE_ABSENT, TraineeGrade, moodle_csv, per_trainee, per_trainee_csv

__all__ = ["build_parser", "format_table", "main"]

_NAME_WIDTH = 24


def build_parser() -> argparse.ArgumentParser:
    """The parser of ``tcp-pendant grades``."""
    p = argparse.ArgumentParser(
        prog="tcp-pendant grades",
        description="Print the class gradebook: one row per calibration (finished or in progress), "
                    "or one per trainee.")
    p.add_argument("--class-db", type=class_db_target, default=None, metavar="PATH|URL",
                   help=f"the gradebook the server writes: a file (default: {default_gradebook_path()}) "
                        "or the class's postgresql://USER@HOST:PORT/DATABASE URL")
    p.add_argument("--csv", action="store_true",
                   help="print CSV (columns in docs/pendant-cli.md) instead of a table")
    p.add_argument("--per-trainee", action="store_true",
                   help="one row per trainee: attempts, best and last grade and position error")
    p.add_argument("--moodle", action="store_true",
                   help="one row per trainee as CSV for Moodle's grade import (Username, points of the "
                        "best grade out of 100, feedback)")
    p.add_argument("--moodle-absent", choices=tuple(MOODLE_ABSENT), default="empty",
                   help="with --moodle: the grade of a trainee who joined and finished no calibration: "
                        "empty (Moodle keeps the learner's grade as it is; the default) or 0")
    return p


def _terminal_text(text: str, width: int) -> str:
    # The gradebook refuses control characters, but the file may come from elsewhere: nothing a
    # trainee typed may reach the terminal as an escape sequence.
    clean = "".join(ch if ch.isprintable() else "?" for ch in text)
    return clean if len(clean) <= width else clean[: width - 1] + "…"


def _num(value: float | None, fmt: str) -> str:
    return "-" if value is None else format(value, fmt)


def _duration(seconds: float) -> str:
    m, s = divmod(int(round(seconds)), 60)
    h, m = divmod(m, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


def format_table(rows: Sequence[GradeRow], attendees: Sequence[Attendee] = ()) -> str:
    """The rows as a fixed-width table (mm, deg; "-" where a figure does not apply), then a
    line for each of ``attendees`` without a row (status "joined, no calibration finished")."""
    header = ("id", "trainee", "method", "tool", "touches", "hand", "auto", "overwr.", "crashes",
              "duration", "mean mm", "ci95 mm", "pos err mm", "ori err deg", "grade", "status")
    body: list[tuple[str, ...]] = [(str(r.calibration_id), _terminal_text(r.trainee, _NAME_WIDTH), _terminal_text(r.method, 16),
             _terminal_text(r.tool_key, 16), str(r.touches), str(r.hand), str(r.auto), str(r.overwritten),
             str(r.crashes), _duration(r.duration_s), _num(r.figures.get("mean_error_mm"), ".3f"),
             _num(r.figures.get("ci95_mm"), ".3f"), _num(r.position_error_mm, ".3f"),
             _num(r.orientation_error_deg, ".2f"), r.grade or "-", r.status.replace("_", " ")) for r in rows]
    listed = {r.trainee for r in rows}
    body += [("-", _terminal_text(a.trainee, _NAME_WIDTH), *["-"] * (len(header) - 3), NO_RESULT_REASON)
             for a in attendees if a.trainee not in listed]
    widths = [max(len(cells[i]) for cells in (header, *body)) for i in range(len(header))]
    left = {1, 2, 3, 14, 15}

    def line(cells: Sequence[str]) -> str:
        return "  ".join(c.ljust(w) if i in left else c.rjust(w)
                         for i, (c, w) in enumerate(zip(cells, widths))).rstrip()

    return "\n".join([line(header), line(["-" * w for w in widths]), *(line(c) for c in body)])


def format_trainee_table(grades: Sequence[TraineeGrade]) -> str:
    """One line per trainee (mm; "-" where nothing is finished)."""
    header = ("trainee", "attempts", "in progress", "best", "best pos err mm", "last", "last pos err mm", "note")
    body = [(_terminal_text(g.trainee, _NAME_WIDTH), str(g.attempts), str(g.in_progress), g.best_grade or "-",
             _num(g.best_position_error_mm, ".3f"), g.last_grade or "-", _num(g.last_position_error_mm, ".3f"),
             g.note) for g in grades]
    widths = [max(len(cells[i]) for cells in (header, *body)) for i in range(len(header))]

    def line(cells: Sequence[str]) -> str:
        return "  ".join(c.ljust(w) if i in (0, 3, 5, 7) else c.rjust(w)
                         for i, (c, w) in enumerate(zip(cells, widths))).rstrip()

    return "\n".join([line(header), line(["-" * w for w in widths]), *(line(c) for c in body)])


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``tcp-pendant grades`` (``argv``: the arguments after ``grades``).

    Returns:
        0 printed; 2 bad options or an unreadable gradebook (one line on stderr).
    """
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:        # argparse printed its usage line and message
        return 0 if exc.code == 0 else 2
    path = default_gradebook_path() if args.class_db is None else args.class_db
    try:
        with Gradebook(path, create=False) as book:
            where = book.location                  # a URL without its password
            rows = book.grades.rows(include_in_progress=True)
            attendees = book.grades.attendance()
            text = to_csv(rows, attendees) if args.csv else None
    except GradebookError as exc:
        print(f"tcp-pendant grades: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    if args.per_trainee or args.moodle:
        trainees = per_trainee(rows, attendees)
        if args.moodle:
            sys.stdout.write(moodle_csv(trainees, absent=args.moodle_absent))
        elif args.csv:
            sys.stdout.write(per_trainee_csv(trainees))
        elif not trainees:
            print(f"No calibration in {where} yet.")
        else:
            print(f"Gradebook {where}: {len(trainees)} trainee{'s' if len(trainees) != 1 else ''}")
            print(format_trainee_table(trainees))
        return 0
    if args.csv:
        sys.stdout.write(text or "")
        return 0
    if not rows and not attendees:
        print(f"No calibration in {where} yet.")
        return 0
    done = sum(1 for r in rows if r.status == "finished")
    print(f"Gradebook {where}: {done} finished calibration{'s' if done != 1 else ''}, {len(rows) - done} in progress")
    print(format_table(rows, attendees))
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
