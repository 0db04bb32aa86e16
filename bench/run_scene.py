"""``rwall-fem run`` with the fixes of bench/workarounds.py (for the 2-rank runs)."""

import sys

import workarounds

from rwall_fem.cli import main

workarounds.apply()
sys.exit(main(["run", *sys.argv[1:]]))
