"""``python -m wmrkit``: the same as the ``wmrkit`` command."""

import sys

from .cli.main import main

if __name__ == "__main__":
    sys.exit(main())
