"""``python -m mpm_warp.studies.report``: write ``docs/results.md``, its pages under ``docs/results/`` and the
README's headline block."""

import sys

from . import main

sys.exit(main())
