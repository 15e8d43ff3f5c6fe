"""``python -m planning.cli``: the same as ``cpr-plan``."""

import sys

from planning.cli.app import console_main

sys.exit(console_main())
