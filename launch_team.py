#!/usr/bin/env python3
"""Run a whole coverage team on this machine: `python launch_team.py --n 4` (see anicov/launch.py)."""

import sys

from anicov.launch import main

if __name__ == "__main__":
    sys.exit(main())
