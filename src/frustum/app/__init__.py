"""The ``frustum`` program: the entry point (``_program``), the Typer command line (``cli``), the opt-in resident
render process (``resident``), the work of ``frustum render`` (``work``), the warm-up (``warmup``) and what every
command shares (``runtime``: failure report, interruptible run, garbage-collector pause, compile notice).

The modules import one way, top to bottom in that order (an import-linter contract); importing this package
imports none of them.
"""
