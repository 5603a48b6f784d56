"""``python -m robotwright``: the command line (the working folder is taken off
``sys.path`` when the package is imported, see ``robotwright/__init__.py``)."""

import sys

from robotwright.cli import main

sys.exit(main())
