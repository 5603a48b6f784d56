import sys

from robotwright.cli import main

sys.exit(main())
