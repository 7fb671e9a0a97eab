"""Files shipped inside the package: built-in post-capture scenarios (`scenarios/*.yaml`) and designed joint
trajectories (`trajectories/*.json`). This package only anchors them for `importlib.resources`; the functions to
list and read them live in `freefloat.io.data` and are re-exported here.

    from freefloat import data
    data.names("scenarios")                             # ['zhang2020_2d_large', ...]
    data.read_text("scenarios", "zhang2020_2d_medium")  # the YAML text
"""

from ..io.data import ALIASES, KINDS, exists, names, path, read_text, resolve

__all__ = ["ALIASES", "KINDS", "exists", "names", "path", "read_text", "resolve"]
