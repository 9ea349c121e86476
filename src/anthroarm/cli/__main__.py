"""``python -m anthroarm.cli``: the ``anthroarm`` command."""

import sys

from . import main

if __name__ == "__main__":
    sys.exit(main())
