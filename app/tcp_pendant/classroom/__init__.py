"""Classroom support without a GUI: the gradebook (an SQLite file or a PostgreSQL database),
``tcp-pendant grades``, per-trainee mystery tools and trainee names.

Modules (one job each): :mod:`~tcp_pendant.classroom.gradebook` (the database, opened, and its
parts: ``trainees``, ``training_records``, ``run_states``, ``grade_rows``, ``class_board``,
``class_settings``, ``presence``, ``class_pushes``, ``waiting_messages``, ``token_failures``),
:mod:`~tcp_pendant.classroom.gradebook_store` (the guarded connection),
:mod:`~tcp_pendant.classroom.gradebook_open` (opening and its checks),
:mod:`~tcp_pendant.classroom.gradebook_schema` (the tables),
:mod:`~tcp_pendant.classroom.gradebook_values` (the values' checks),
:mod:`~tcp_pendant.classroom.gradebook_db` (its SQLite / PostgreSQL connections),
:mod:`~tcp_pendant.classroom.grades_csv` (the grade rows as CSV),
:mod:`~tcp_pendant.classroom.grades_cli` (the ``grades`` command),
:mod:`~tcp_pendant.classroom.mystery` (mystery tools), :mod:`~tcp_pendant.classroom.names`
(the "Your name" check), :mod:`~tcp_pendant.classroom.class_room` (the class as the server runs
it; its windows come from the views through
:class:`~tcp_pendant.classroom.class_views.ClassViews`), and the class's rules:
:mod:`~tcp_pendant.classroom.exercise_rules`, :mod:`~tcp_pendant.classroom.library_rights`,
:mod:`~tcp_pendant.classroom.class_messages`. Nothing here imports viser or the views.
"""

from __future__ import annotations
