"""``python -m planning.cli``: the same as ``cpr-plan``."""

import sys

from planning.cli.app import main

sys.exit(main())
