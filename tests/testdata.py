"""Where the tests' reference data lives: ``tests/data/`` inside the repository (sources and licences in
``tests/data/README.md``). Every test reads it through ``DATA``; no test names a path outside the repository."""

from pathlib import Path

DATA = Path(__file__).resolve().parent / "data"
