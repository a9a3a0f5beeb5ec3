"""Headless everywhere; the toy templates in tests/toys.py importable as ``toys``."""

import os
import sys
from pathlib import Path

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("MPLBACKEND", "Agg")
sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parent / "golden"))

ROOT = Path(__file__).resolve().parent.parent

# broken and deliberately failing scenario files are inputs of tests, not tests themselves
collect_ignore_glob = ["fixtures/*", "golden/*.yaml"]
