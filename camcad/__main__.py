"""``python -m camcad`` runs the command line.

Ctrl-C is answered from the first moment: while this package and the command
line's modules import, a SIGINT prints one line and exits 130 (the package
installs that handling when ``python -m`` imports it), as it does at any
later moment, where :func:`camcad.cli.main` turns it into a clean stop.
"""

import sys

if __name__ == "__main__":
    import _signal  # type: ignore[import-not-found]  # the C module: importing ``signal`` takes milliseconds (enum)

    from camcad import _exit_interrupted

    _signal.signal(_signal.SIGINT, _exit_interrupted)
    from camcad.cli import main

    sys.exit(main())
