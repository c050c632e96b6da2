"""ezdxf, imported independent of the user's home folder, and a byte-reproducible save.

At import ezdxf reads ``~/.config/ezdxf/ezdxf.ini`` (or under
``$XDG_CONFIG_HOME``) and the file named by ``$EZDXF_CONFIG_FILE``, and
reads or writes a font cache under ``~/.cache/ezdxf`` (or
``$XDG_CACHE_HOME``). A broken config file stops the import, and a missing or
unwritable home folder makes it log warnings that reach stderr. camcad draws
no text through fonts and wants the same file from every account, so this
module imports ezdxf with both folders pointing nowhere, without
``$EZDXF_CONFIG_FILE``, and with ezdxf's logger muted and its stdout (the
font scan prints the font folders it may not read) sent nowhere for the import. ezdxf
then lists the system fonts itself (a few ms here) and saves no cache. When
ezdxf was imported before camcad, it is left as it is.

:func:`save_reproducible` saves a document with fixed creation and update
dates and GUIDs, and the CLASSES section in a fixed order (ezdxf appends the
classes in use in set order, which changes with ``PYTHONHASHSEED``), so the
same drawing gives the same bytes.
"""

from __future__ import annotations

import io
import logging
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager, redirect_stdout
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ezdxf.document import Drawing

__all__ = ["ezdxf", "import_ezdxf", "save_reproducible"]

_NOWHERE = os.path.join(os.devnull, "camcad")  # cannot exist: a path below a device file
_ENVIRONMENT = {"XDG_CONFIG_HOME": _NOWHERE, "XDG_CACHE_HOME": _NOWHERE, "EZDXF_CONFIG_FILE": None}


@contextmanager
def _environment(values: dict[str, str | None]) -> Iterator[None]:
    """Set (or, for ``None``, remove) environment variables while the block runs."""
    saved = {name: os.environ.get(name) for name in values}
    try:
        for name, value in values.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


def import_ezdxf() -> ModuleType:
    """Import ezdxf without the user's config files and font cache; see the module docstring."""
    if "ezdxf" in sys.modules:
        return sys.modules["ezdxf"]
    logger = logging.getLogger("ezdxf")
    muted = logger.disabled
    logger.disabled = True
    try:
        # the font scan at import prints a folder it may not read (``~/.fonts`` of an unreadable home)
        # to stdout, where camcad lists the files it wrote: sent nowhere
        with _environment(_ENVIRONMENT), redirect_stdout(io.StringIO()):
            import ezdxf
    finally:
        logger.disabled = muted
    return ezdxf


ezdxf = import_ezdxf()


def _register_classes_in_order(doc: Drawing) -> None:
    """Register every CLASS entry the save needs now, in a fixed order: the required ones, then by name."""
    from ezdxf.sections.classes import REQ_R2004, REQUIRED_CLASSES

    doc.classes.add_required_classes(doc.dxfversion)  # the save adds nothing after this
    rank = {name: i for i, name in enumerate(REQUIRED_CLASSES.get(doc.dxfversion, REQ_R2004))}
    entries = doc.classes.classes
    ordered = sorted(entries.items(), key=lambda item: (rank.get(item[0][0], len(rank)), item[0]))
    entries.clear()
    entries.update(ordered)


def save_reproducible(doc: Drawing, path: str | os.PathLike[str]) -> None:
    """Save ``doc`` to ``path`` so that the same drawing always gives the same bytes.

    Uses ezdxf's option ``write_fixed_meta_data_for_testing`` for the save
    only: ``$TDCREATE``/``$TDUPDATE`` (and the UTC twins) are 2000-01-01,
    ``$FINGERPRINTGUID`` and ``$VERSIONGUID`` are the nil GUID, and ezdxf's
    "created by" and "written by" stamps carry no time.
    """
    from ezdxf.document import CONST_MARKER_STRING, CREATED_BY_EZDXF

    _register_classes_in_order(doc)
    doc.ezdxf_metadata()[CREATED_BY_EZDXF] = CONST_MARKER_STRING  # stamped with the time by ezdxf.new
    options = ezdxf.options
    before = options.write_fixed_meta_data_for_testing
    options.write_fixed_meta_data_for_testing = True
    try:
        doc.saveas(Path(path))
    finally:
        options.write_fixed_meta_data_for_testing = before
