"""``python -m anyplan``: the command-line interface."""

import sys

from anyplan.cli.main import main

sys.exit(main())
