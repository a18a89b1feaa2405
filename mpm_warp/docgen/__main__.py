"""``python -m mpm_warp.docgen``: write the generated parts of the docs (:mod:`mpm_warp.docgen.generate`)."""

import sys

from .generate import main

sys.exit(main())
