"""``python -m nonsmooth``: the command line (same as the ``nonsmooth`` script)."""

from .cli import main

main()
