"""``python -m scara_pin.cli ...``: the ``scara-pin`` command without its installed script."""

import sys

from . import main

sys.exit(main())
