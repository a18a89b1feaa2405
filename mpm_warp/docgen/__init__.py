"""The docs that the code is the truth of, generated from it: the command-line reference (from the argument parser)
and the scenario key reference (from the parameter dataclasses), into ``docs/scenarios.md`` and ``README.md``.

``python -m mpm_warp.docgen`` writes them; ``--check`` only says whether the committed files are current
(``tests/test_docs_generated.py``). It sits above the command line, whose parser it reads.
"""

from .generate import generated_files, main

__all__ = ["generated_files", "main"]
