"""``python3 -m aolab``: the aolab command."""
import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
