"""Classroom support without a GUI: the gradebook (an SQLite file or a PostgreSQL database),
``tcp-pendant grades``, per-trainee mystery tools and trainee names.

Modules (one job each): :mod:`~tcp_pendant.classroom.gradebook` (the database),
:mod:`~tcp_pendant.classroom.gradebook_db` (its SQLite / PostgreSQL connections),
:mod:`~tcp_pendant.classroom.grades_cli` (the ``grades`` command),
:mod:`~tcp_pendant.classroom.mystery` (mystery tools), :mod:`~tcp_pendant.classroom.names`
(the "Your name" check). Nothing here imports viser.
"""

from __future__ import annotations
