"""`python -m sweep ...`: the `sweep` console script (sweep.cli.main), for an environment whose
scripts directory is not on PATH."""

import sys

from .cli import main

sys.exit(main())
