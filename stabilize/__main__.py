"""``python -m stabilize``: the same as the ``stabilize`` command (where its script is
not on PATH: a user install, a venv not activated)."""

from stabilize.cli import main

main()
