"""``python -m facadecli`` is the ``facade`` command."""

from facadecli.cli import main

main()
