"""pybullet, imported without the build-time banner its C module prints on stderr.

The banner ("pybullet build time: ...") would otherwise come before every one-line error
of the command-line tools, making it two lines, and into every node's log.
"""

from __future__ import annotations

import os
import sys


def _import_quietly():
    sys.stderr.flush()
    saved = os.dup(2)  # the banner is written by C code to file descriptor 2
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 2)
        import pybullet
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)
    return pybullet


p = _import_quietly()
