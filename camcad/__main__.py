"""``python -m camcad`` runs the command line."""

import sys

from camcad.cli import main

sys.exit(main())
