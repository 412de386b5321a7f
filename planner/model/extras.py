"""Optional libraries, each installed by an extra of the package: a missing one is one line that
names the extra, never a traceback from deep inside the call that needed it.

>>> print(needs("matplotlib"))
needs matplotlib, which the figures extra installs: pip install 'stablepush[figures]'
"""

from __future__ import annotations

import importlib.util
from types import ModuleType

__all__ = ["EXTRAS", "have", "needs", "pyplot"]

#: The extra (pyproject.toml) that installs each optional library.
EXTRAS = {"matplotlib": "figures", "mujoco": "mujoco", "ray": "ray", "ezdxf": "cad", "svgelements": "cad",
          "trimesh": "cad", "mink": "arm"}


def needs(module: str) -> str:
    """The line that says ``module`` is missing and which extra installs it."""
    extra = EXTRAS[module]
    return f"needs {module}, which the {extra} extra installs: pip install 'stablepush[{extra}]'"


def have(module: str) -> bool:
    """Whether ``module`` can be imported, without importing it."""
    try:
        return importlib.util.find_spec(module) is not None
    except ValueError:  # in sys.modules as None: imports of it are refused
        return False


def pyplot() -> ModuleType:
    """:mod:`matplotlib.pyplot`, drawing to files (the Agg back end), for the PNG writers.

    Raises
    ------
    ModuleNotFoundError
        Whose message is :func:`needs`' line, when matplotlib is not installed.
    """
    try:
        import matplotlib
    except ModuleNotFoundError:
        raise ModuleNotFoundError(needs("matplotlib"), name="matplotlib") from None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt
