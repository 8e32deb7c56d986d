"""``python -m frustum`` runs the ``frustum`` command."""

from frustum._program import main

main()
