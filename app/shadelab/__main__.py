"""``python -m shadelab`` is the same as the ``shadelab`` command."""

import sys

if __name__ == "__main__":  # spawned worker processes import this module without running it
    from shadelab.cli import main

    sys.exit(main())
