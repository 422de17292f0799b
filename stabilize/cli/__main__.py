"""``python -m stabilize.cli``: the same as the ``stabilize`` command."""

from stabilize.cli import main

main()
