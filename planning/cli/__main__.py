"""``python -m planning.cli``: the same as ``cpr-plan``."""

from planning.cli.app import console_main

console_main()
