"""python3 -m rmslab_launcher ARGS: what scripts/lab runs (docs/sessions.md "The launcher")."""
import sys

from .cli import main

sys.exit(main(sys.argv[1:]))
