"""``python3 -m aolab``: the aolab command."""
import sys

from .cli import main

sys.exit(main())
