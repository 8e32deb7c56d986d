"""``python -m frustum`` runs the ``frustum`` command."""

from frustum.cli import main

main()
