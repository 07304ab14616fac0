"""``python -m gridshell``: the same as the ``gridshell`` command."""
import sys

from gridshell.cli.main import main

if __name__ == "__main__":  # not when a tool imports every module of the package
    sys.exit(main())
