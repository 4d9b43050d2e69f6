"""Scene files: load a sweep description from TOML, validate it, and write it back.

(Being split into modules, issue 18; every name is re-exported here.)
"""

from __future__ import annotations

from .values import *  # noqa: F401,F403
from .values import _scenes_dir  # noqa: F401
