"""``python -m frustum`` runs the ``frustum`` command."""

from frustum.app._program import main

main()
