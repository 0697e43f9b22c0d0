"""The shape of JSON data as the app reads it (a session record, a wizard's saved parameters or
start options, a gradebook row's JSON column, a browser's message).

What the app writes as JSON is typed ``dict[str, object]`` where it is built. What it reads is a
:data:`JsonRecord`: the keys are strings, a value's type is only known once the reader has checked
it, and every reader checks the keys it uses (``wizards.base.finite_number``,
``wizards.session_record.check_session_record``, ``classroom.gradebook_values``...).
"""

from collections.abc import Mapping
from typing import Any

__all__ = ["JsonRecord"]

JsonRecord = Mapping[str, Any]
"""A JSON object as parsed (``json.loads``) or as a browser sent it, its values not yet checked:
the one place where the app's JSON input is typed ``Any``."""
