"""``python -m alica``: the ``alica`` command."""

import sys

from alica.app.cli import main

sys.exit(main())
