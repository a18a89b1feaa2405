"""``python -m mpm_warp.studies.report``: write ``docs/results.md`` and the README's headline block."""

import sys

from . import main

sys.exit(main())
