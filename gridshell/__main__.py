"""``python -m gridshell``: the same as the ``gridshell`` command."""
import sys

from .cli.main import main

sys.exit(main())
