"""``python -m stewart``: the ``stewart`` command."""

from .cli import main

main()
