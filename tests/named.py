"""``raises_named``: ``pytest.raises`` on the error as the user reads it (its knob named by its TOML path).

A stage names a :class:`camcad.knobs.Knob`; the design layer's
:func:`camcad.design.paths.named_error` puts the path in place where errors
leave the core. A test of a stage called directly matches the text after it.
"""

from __future__ import annotations

import contextlib
import re
from collections.abc import Iterator
from typing import Any

import pytest

from camcad.design.paths import named_error


@contextlib.contextmanager
def raises_named(exc: type[BaseException], *, match: str) -> Iterator[Any]:
    """Like ``pytest.raises(exc, match=match)``, matching ``str(named_error(err))``."""
    with pytest.raises(exc) as info:
        yield info
    text = str(named_error(info.value))
    assert re.search(match, text), f"{match!r} not in {text!r}"
