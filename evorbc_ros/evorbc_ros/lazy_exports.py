"""Package-level names that import their module on first use (PEP 562).

``import evorbc_ros`` must stay light on a robot (numpy and PyYAML only), and importing the
search package must not pull numba, PyBullet or pyribs into a command that needs
none of them; so each package lists its public names and where they live, and a name's
module is imported only when the name is first read (docs/design.md section 20).
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable


def lazy_exports(
    package: str, exports: dict[str, str]
) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """``(__getattr__, __dir__)`` for ``package``'s module namespace.

    Args:
        package: the package's ``__name__``.
        exports: public name -> ``"module"`` (the same name there) or ``"module:name"``.

    """

    def getattr_(name: str) -> object:
        where = exports.get(name)
        if where is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, _, attribute = where.partition(":")
        value = getattr(importlib.import_module(module), attribute or name)
        setattr(sys.modules[package], name, value)  # later reads skip __getattr__
        return value

    def dir_() -> list[str]:
        return sorted({*vars(sys.modules[package]), *exports})

    return getattr_, dir_
