"""`python -m kincal`: the same as the `kincal` command."""

import sys

from .cli import main

sys.exit(main())
